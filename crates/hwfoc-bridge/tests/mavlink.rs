//! The MAVLink output, end to end over a loopback UDP socket: every datagram is decoded by the
//! `mavlink` crate's own parser and its fields compared with the records sent.

use std::net::{SocketAddr, UdpSocket};
use std::time::{Duration, Instant};

use hwfoc::foc::DataFrame;
use hwfoc::telemetry::Data;
use hwfoc::{Fault, Settings, Status};
use hwfoc_bridge::mavlink::{
    MAV_COMP_ID_PERIPHERAL, MavlinkOptions, MavlinkOutput, MavlinkTarget, messages,
};
use hwfoc_bridge::{Output, OutputError, SILENT_AFTER, Update};
use hwfoc_io::Record;
use mavlink::dialects::ardupilotmega::{MavAutopilot, MavMessage, MavType};
use mavlink::{MavHeader, MavlinkReader, MavlinkVersion};

/// A frame with distinct values: 24.7 V, 12.5 A, 3000 eRPM raw (motor RPM 30000/7), MOS 40 degC.
fn frame(packet: u16, status: Status) -> DataFrame {
    DataFrame {
        packet,
        throttle_in_raw: 512,
        throttle_out_raw: 500,
        erpm_raw: 3000,
        voltage_raw: 247,
        current_raw: 800,
        phase_current_raw: 1600,
        mos_adc: 150,
        cap_adc: 160,
        status,
    }
}

struct Rig {
    rx: UdpSocket,
    out: MavlinkOutput,
}

impl Rig {
    fn new(options: MavlinkOptions) -> Rig {
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let out =
            MavlinkOutput::open(MavlinkTarget::Udp(rx.local_addr().unwrap()), options).unwrap();
        Rig { rx, out }
    }

    fn update(&mut self, esc: u8, t_s: Option<f64>, frame: &DataFrame, arrived: Instant) -> Record {
        let record = Record::new(t_s, esc, &Data::from(*frame), &Settings::default());
        self.out.update(&Update {
            esc,
            frame: &Data::from(*frame),
            record: &record,
            settings: &Settings::DEFAULT,
            arrived,
        });
        record
    }

    /// Every message received so far, decoded by the mavlink crate, with its header (a
    /// datagram to 127.0.0.1 is in the receiver's queue when `send` returns).
    fn received(&self) -> Vec<(MavHeader, MavMessage)> {
        let mut got = Vec::new();
        let mut buf = [0u8; 512];
        self.rx.set_nonblocking(true).unwrap();
        while let Ok(n) = self.rx.recv(&mut buf) {
            let mut reader = MavlinkReader::new(&buf[..n]);
            let (header, message) = reader
                .read_message::<MavMessage>(MavlinkVersion::V2)
                .expect("a valid MAVLink 2 frame");
            assert_eq!(buf[0], 0xFD, "MAVLink 2 framing");
            got.push((header, message));
        }
        got
    }
}

fn names(messages: &[(MavHeader, MavMessage)]) -> Vec<String> {
    use mavlink::Message;
    messages
        .iter()
        .map(|(_, m)| match m {
            MavMessage::ESC_INFO(d) => format!("ESC_INFO[{}]", d.index),
            MavMessage::ESC_STATUS(d) => format!("ESC_STATUS[{}]", d.index),
            m => m.message_name().to_string(),
        })
        .collect()
}

#[test]
fn one_esc_decodes_with_its_values_in_the_messages_units() {
    let mut rig = Rig::new(MavlinkOptions::default());
    let now = Instant::now();
    let status = Status::OK.with(Fault::OverCurrent).with(Fault::MosOverheat);
    let record = rig.update(0, Some(100.0), &frame(1, status), now);
    rig.out.poll(now).unwrap();
    let got = rig.received();
    assert_eq!(
        names(&got),
        [
            "HEARTBEAT",
            "ESC_TELEMETRY_1_TO_4",
            "ESC_STATUS[0]",
            "ESC_INFO[0]"
        ]
    );
    for (i, (h, _)) in got.iter().enumerate() {
        assert_eq!((h.system_id, h.component_id), (1, MAV_COMP_ID_PERIPHERAL));
        assert_eq!(h.sequence, i as u8, "sequence numbers increment");
    }
    let MavMessage::HEARTBEAT(hb) = &got[0].1 else {
        panic!()
    };
    assert_eq!(hb.mavtype, MavType::MAV_TYPE_ONBOARD_CONTROLLER);
    assert_eq!(hb.autopilot, MavAutopilot::MAV_AUTOPILOT_INVALID);

    let MavMessage::ESC_TELEMETRY_1_TO_4(t) = &got[1].1 else {
        panic!()
    };
    let temp = record.mos_temp_c.unwrap().max(record.cap_temp_c.unwrap());
    assert_eq!(t.voltage, [2470, 0, 0, 0]);
    assert_eq!(t.current, [1250, 0, 0, 0]);
    assert_eq!(t.rpm, [(30000.0f64 / 7.0).round() as u16, 0, 0, 0]);
    assert_eq!(t.temperature, [temp.round() as u8, 0, 0, 0]);
    assert_eq!(t.totalcurrent, [0; 4], "one frame: nothing integrated yet");
    assert_eq!(t.count, [1, 0, 0, 0]);

    let MavMessage::ESC_STATUS(s) = &got[2].1 else {
        panic!()
    };
    assert_eq!(s.index, 0);
    assert_eq!(s.voltage, [record.voltage_v.unwrap(), 0.0, 0.0, 0.0]);
    assert_eq!(s.current, [12.5, 0.0, 0.0, 0.0]);
    assert_eq!(s.rpm, [4286, 0, 0, 0]);
    assert!(
        s.time_usec > 1_600_000_000_000_000,
        "Unix time in microseconds"
    );

    let MavMessage::ESC_INFO(info) = &got[3].1 else {
        panic!()
    };
    assert_eq!(
        (info.index, info.count, info.info, info.counter),
        (0, 1, 0b1, 1)
    );
    assert_eq!(info.failure_flags, [1 | 4, 0, 0, 0]);
    assert_eq!(info.error_count, [2, 0, 0, 0]);
    assert_eq!(
        info.temperature,
        [(temp * 100.0).round() as i16, i16::MAX, i16::MAX, i16::MAX]
    );
    assert_eq!(
        info.connection_type,
        mavlink::dialects::ardupilotmega::EscConnectionType::ESC_CONNECTION_TYPE_SERIAL
    );
    assert_eq!(rig.out.stats().messages, 4);
    assert_eq!(
        rig.out.stats().latency.count(),
        2,
        "one frame carried by two messages"
    );
}

#[test]
fn total_current_is_the_charge_consumed() {
    let mut rig = Rig::new(MavlinkOptions::default());
    let start = Instant::now();
    // 12.5 A for 0.05 s steps: 36 s of steps = 125 mAh... 72 frames 50 ms apart: 3.55 s.
    let mut last = start;
    for k in 0..=72u16 {
        last = start + Duration::from_millis(50 * u64::from(k));
        rig.update(
            0,
            Some(1000.0 + f64::from(k) * 0.05),
            &frame(k, Status::OK),
            last,
        );
    }
    rig.out.poll(last).unwrap();
    let got = rig.received();
    let t = got
        .iter()
        .find_map(|(_, m)| match m {
            MavMessage::ESC_TELEMETRY_1_TO_4(t) => Some(t.clone()),
            _ => None,
        })
        .unwrap();
    // 12.5 A * 3.6 s = 45 As = 12.5 mAh.
    assert_eq!(t.totalcurrent[0], 13);
    assert_eq!(t.count[0], 73);
    assert_eq!(rig.out.stats().superseded, 72, "coalesced into one message");

    // Without times, the arrival instants are integrated.
    let mut untimed = Rig::new(MavlinkOptions::default());
    for k in 0..=72u16 {
        let at = start + Duration::from_millis(100 * u64::from(k));
        untimed.update(0, None, &frame(k, Status::OK), at);
    }
    untimed
        .out
        .poll(start + Duration::from_millis(7200))
        .unwrap();
    let t = untimed
        .received()
        .iter()
        .find_map(|(_, m)| match m {
            MavMessage::ESC_TELEMETRY_1_TO_4(t) => Some(t.clone()),
            _ => None,
        })
        .unwrap();
    // 12.5 A * 7.2 s = 25 mAh.
    assert_eq!(t.totalcurrent[0], 25);
}

#[test]
fn groups_follow_the_number_of_escs() {
    for (escs, expected) in [
        (
            1,
            vec!["ESC_TELEMETRY_1_TO_4", "ESC_STATUS[0]", "ESC_INFO[0]"],
        ),
        (
            4,
            vec!["ESC_TELEMETRY_1_TO_4", "ESC_STATUS[0]", "ESC_INFO[0]"],
        ),
        (
            5,
            vec![
                "ESC_TELEMETRY_1_TO_4",
                "ESC_STATUS[0]",
                "ESC_INFO[0]",
                "ESC_TELEMETRY_5_TO_8",
                "ESC_STATUS[4]",
                "ESC_INFO[4]",
            ],
        ),
        (
            16,
            vec![
                "ESC_TELEMETRY_1_TO_4",
                "ESC_STATUS[0]",
                "ESC_INFO[0]",
                "ESC_TELEMETRY_5_TO_8",
                "ESC_STATUS[4]",
                "ESC_INFO[4]",
                "ESC_TELEMETRY_9_TO_12",
                "ESC_STATUS[8]",
                "ESC_INFO[8]",
                "ESC_TELEMETRY_13_TO_16",
                "ESC_STATUS[12]",
                "ESC_INFO[12]",
            ],
        ),
    ] {
        let mut rig = Rig::new(MavlinkOptions::default());
        let now = Instant::now();
        for esc in 0..escs {
            rig.update(esc, None, &frame(u16::from(esc), Status::OK), now);
        }
        rig.out.poll(now).unwrap();
        let got = rig.received();
        assert_eq!(names(&got)[1..], expected, "{escs} ESCs");
        for (_, m) in &got {
            if let MavMessage::ESC_INFO(info) = m {
                assert_eq!(info.count, escs);
                let in_group = (escs - info.index).min(4);
                assert_eq!(info.info, (1u8 << in_group) - 1);
            }
        }
        // Only the group with a new frame is sent again.
        rig.update(escs - 1, None, &frame(99, Status::OK), now);
        rig.out.poll(now + Duration::from_millis(20)).unwrap();
        let again = names(&rig.received());
        let index = (escs - 1) / 4 * 4;
        assert_eq!(again.len(), 2, "{again:?}");
        assert_eq!(again[1], format!("ESC_STATUS[{index}]"));
    }
}

#[test]
fn escs_past_64_are_not_sent_and_told() {
    let mut rig = Rig::new(MavlinkOptions::default());
    let now = Instant::now();
    for esc in [63, 64, 65, 200] {
        rig.update(esc, None, &frame(1, Status::OK), now);
    }
    rig.out.poll(now).unwrap();
    let got = names(&rig.received());
    assert!(got.contains(&"ESC_STATUS[60]".to_string()), "{got:?}");
    assert!(got.iter().all(|m| !m.ends_with("[64]")), "{got:?}");
    let error = hwfoc_bridge::output::left_out(&rig.out).expect("ESCs 64 and up left out");
    assert!(
        error
            .to_string()
            .ends_with(": 3 frames of ESCs 64, 65, 200 not sent: it carries ESCs 0 to 63"),
        "{error}"
    );
}

#[test]
fn a_silent_esc_is_zeros_offline_and_then_not_sent() {
    let mut rig = Rig::new(MavlinkOptions::default());
    let t0 = Instant::now();
    rig.update(0, None, &frame(1, Status::OK), t0);
    rig.update(1, None, &frame(1, Status::OK.with(Fault::MotorBlocked)), t0);
    rig.out.poll(t0).unwrap();
    rig.received();
    // ESC 1 goes silent; ESC 0 goes on.
    let t1 = t0 + SILENT_AFTER + Duration::from_millis(100);
    rig.update(0, None, &frame(2, Status::OK), t1);
    rig.out.poll(t1).unwrap();
    let got = rig.received();
    assert_eq!(
        names(&got),
        [
            "HEARTBEAT",
            "ESC_TELEMETRY_1_TO_4",
            "ESC_STATUS[0]",
            "ESC_INFO[0]"
        ]
    );
    let MavMessage::ESC_TELEMETRY_1_TO_4(t) = &got[1].1 else {
        panic!()
    };
    assert_eq!(t.voltage, [2470, 0, 0, 0], "the silent ESC is zeros");
    assert_eq!(t.count, [2, 0, 0, 0]);
    let MavMessage::ESC_INFO(info) = &got[3].1 else {
        panic!()
    };
    assert_eq!(info.info, 0b01, "offline");
    assert_eq!(info.failure_flags, [0; 4]);
    assert_eq!(info.error_count[1], 1, "its fault onset is still counted");
    assert_eq!(info.temperature[1], i16::MAX);

    // Both silent: one last ESC_INFO saying so, then nothing but heartbeats.
    let t2 = t1 + SILENT_AFTER + Duration::from_millis(100);
    rig.out.poll(t2).unwrap();
    let got = rig.received();
    assert_eq!(names(&got), ["HEARTBEAT", "ESC_INFO[0]"]);
    let MavMessage::ESC_INFO(info) = &got[1].1 else {
        panic!()
    };
    assert_eq!(info.info, 0);
    rig.out.poll(t2 + Duration::from_secs(5)).unwrap();
    assert_eq!(names(&rig.received()), ["HEARTBEAT"]);
}

#[test]
fn esc_info_is_periodic_and_immediate_on_a_new_failure() {
    let mut rig = Rig::new(MavlinkOptions::default());
    let t0 = Instant::now();
    rig.update(0, None, &frame(1, Status::OK), t0);
    rig.out.poll(t0).unwrap();
    rig.received();
    // A new frame 100 ms later, same state: no ESC_INFO, no heartbeat.
    let t1 = t0 + Duration::from_millis(100);
    rig.update(0, None, &frame(2, Status::OK), t1);
    rig.out.poll(t1).unwrap();
    assert_eq!(
        names(&rig.received()),
        ["ESC_TELEMETRY_1_TO_4", "ESC_STATUS[0]"]
    );
    // A failure: ESC_INFO at once.
    let t2 = t0 + Duration::from_millis(200);
    rig.update(
        0,
        None,
        &frame(3, Status::OK.with(Fault::InputVoltageHigh)),
        t2,
    );
    rig.out.poll(t2).unwrap();
    let got = rig.received();
    assert_eq!(
        names(&got),
        ["ESC_TELEMETRY_1_TO_4", "ESC_STATUS[0]", "ESC_INFO[0]"]
    );
    let MavMessage::ESC_INFO(info) = &got[2].1 else {
        panic!()
    };
    assert_eq!(info.failure_flags[0], 2);
    // No new frame, a second later: heartbeat and the periodic ESC_INFO only.
    let t3 = t2 + Duration::from_millis(1000);
    rig.out.poll(t3).unwrap();
    assert_eq!(names(&rig.received()), ["HEARTBEAT", "ESC_INFO[0]"]);
}

#[test]
fn sequence_numbers_wrap() {
    let mut rig = Rig::new(MavlinkOptions {
        system_id: 42,
        component_id: 1,
        ..MavlinkOptions::default()
    });
    let t0 = Instant::now();
    let mut seqs = Vec::new();
    for k in 0..150u16 {
        let at = t0 + Duration::from_millis(u64::from(k) * 10);
        rig.update(0, None, &frame(k, Status::OK), at);
        rig.out.poll(at).unwrap();
        for (h, m) in rig.received() {
            assert_eq!((h.system_id, h.component_id), (42, 1));
            if let MavMessage::HEARTBEAT(hb) = m {
                assert_eq!(
                    hb.mavtype,
                    MavType::MAV_TYPE_GENERIC,
                    "component 1: a stand-in vehicle"
                );
                assert_eq!(hb.autopilot, MavAutopilot::MAV_AUTOPILOT_GENERIC);
            }
            seqs.push(h.sequence);
        }
    }
    assert!(seqs.len() > 256);
    for w in seqs.windows(2) {
        assert_eq!(w[1], w[0].wrapping_add(1));
    }
}

#[test]
fn an_unreachable_destination_is_counted_and_survived() {
    // A port nobody listens on: the kernel answers with ICMP port unreachable, which the
    // connected socket reports as ECONNREFUSED on a later send.
    let dead = UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr: SocketAddr = dead.local_addr().unwrap();
    drop(dead);
    let mut out = MavlinkOutput::open(MavlinkTarget::Udp(addr), MavlinkOptions::default()).unwrap();
    let t0 = Instant::now();
    let mut errors = Vec::new();
    for k in 0..20u16 {
        let at = t0 + Duration::from_millis(u64::from(k) * 50);
        let f = frame(k, Status::OK);
        let record = Record::new(None, 0, &Data::from(f), &Settings::default());
        out.update(&Update {
            esc: 0,
            frame: &Data::from(f),
            record: &record,
            settings: &Settings::DEFAULT,
            arrived: at,
        });
        if let Err(e) = out.poll(at) {
            errors.push(e);
        }
    }
    assert!(!errors.is_empty());
    assert!(
        errors.iter().all(|e| matches!(e, OutputError::Send { .. })),
        "{errors:?}"
    );
    assert!(
        errors[0]
            .to_string()
            .starts_with(&format!("mavlink udp:{addr}: cannot send"))
    );
    assert!(out.stats().errors >= errors.len() as u64);
    assert!(
        out.stats().messages > 0,
        "sends between the refusals went out"
    );
    // Someone listens now: the output carries on.
    let Ok(rx) = UdpSocket::bind(addr) else {
        return; // the port was taken meanwhile
    };
    rx.set_read_timeout(Some(Duration::from_secs(1))).unwrap();
    let at = t0 + Duration::from_secs(5);
    let f = frame(100, Status::OK);
    let record = Record::new(None, 0, &Data::from(f), &Settings::default());
    out.update(&Update {
        esc: 0,
        frame: &Data::from(f),
        record: &record,
        settings: &Settings::DEFAULT,
        arrived: at,
    });
    out.poll(at).unwrap();
    let mut buf = [0u8; 512];
    assert!(rx.recv(&mut buf).unwrap() > 0);
}

#[test]
fn a_network_without_a_route_is_a_send_error() {
    // The documentation range 192.0.2.0/24 has no route in a sandbox without a default route;
    // where there is one, the datagram goes out to nobody (only in that case is nothing
    // checked): either way nothing blocks or panics.
    let target = MavlinkTarget::parse("udp:192.0.2.1:14550").unwrap();
    let mut out = MavlinkOutput::open(target, MavlinkOptions::default()).unwrap();
    let start = Instant::now();
    let result = out.poll(start);
    assert!(start.elapsed() < Duration::from_millis(500));
    if let Err(e) = result {
        assert!(matches!(e, OutputError::Send { .. }), "{e}");
        assert_eq!(out.stats().errors, 1);
    }
}

#[test]
fn targets_parse() {
    let udp = |s: &str| match MavlinkTarget::parse(s).unwrap() {
        MavlinkTarget::Udp(a) => a.to_string(),
        other => panic!("{other:?}"),
    };
    assert_eq!(udp("udp"), "127.0.0.1:14550");
    assert_eq!(udp("UDP:14551"), "127.0.0.1:14551");
    assert_eq!(udp("udp:192.168.1.10:14550"), "192.168.1.10:14550");
    assert_eq!(udp("udp:[::1]:14550"), "[::1]:14550");
    assert_eq!(udp("udp:localhost:14555"), "127.0.0.1:14555");
    assert_eq!(
        MavlinkTarget::parse("serial:/dev/ttyACM0").unwrap(),
        MavlinkTarget::Serial {
            port: "/dev/ttyACM0".into(),
            baud: 57600
        }
    );
    assert_eq!(
        MavlinkTarget::parse("serial:COM3:921600")
            .unwrap()
            .to_string(),
        "serial:COM3:921600"
    );
    for bad in [
        "udp:host",
        "udp:1.2.3.4:99999",
        "serial",
        "serial:",
        "tcp:1.2.3.4:1",
        "serial:/dev/x:0",
        "file",
        "file:",
    ] {
        let e = MavlinkTarget::parse(bad).unwrap_err();
        assert!(matches!(e, OutputError::Open { .. }), "{bad}");
        assert!(
            e.to_string()
                .starts_with(&format!("mavlink {bad}: cannot open")),
            "{e}"
        );
    }
    assert_eq!(
        MavlinkTarget::parse("file:logs/a b.tlog").unwrap(),
        MavlinkTarget::File("logs/a b.tlog".into())
    );
    assert_eq!(
        MavlinkTarget::File("x.tlog".into()).to_string(),
        "file:x.tlog"
    );
    let missing = MavlinkOutput::open(
        MavlinkTarget::parse("serial:/dev/ttyUSB_no_such_port").unwrap(),
        MavlinkOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(missing, OutputError::Open { .. }), "{missing}");
}

/// A telemetry log's messages: each one's time (64-bit big-endian microseconds) and message.
fn tlog(bytes: &[u8]) -> Vec<(u64, MavMessage)> {
    let mut out = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let time = u64::from_be_bytes(bytes[at..at + 8].try_into().unwrap());
        let frame = &bytes[at + 8..];
        assert_eq!(frame[0], 0xFD, "a MAVLink 2 frame after each time");
        let len = 12 + usize::from(frame[1]);
        let mut reader = MavlinkReader::new(&frame[..len]);
        let (_, message) = reader
            .read_message::<MavMessage>(MavlinkVersion::V2)
            .expect("a valid MAVLink 2 frame");
        out.push((time, message));
        at += 8 + len;
    }
    out
}

/// `file:PATH`: a telemetry log starting with the first frame, each message after the time of
/// its data (the records' Unix times), never going back, ESC_STATUS's `time_usec` the same;
/// records without a Unix time take the system clock; an existing file is refused unless
/// `overwrite`.
#[test]
fn a_telemetry_log_has_each_message_after_the_time_of_its_data() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flight.tlog");
    let target = MavlinkTarget::File(path.to_str().unwrap().to_string());
    let mut out = MavlinkOutput::open(target.clone(), MavlinkOptions::default()).unwrap();
    let t0 = Instant::now();
    out.poll(t0).unwrap();
    assert_eq!(out.stats().messages, 0, "nothing before the first frame");
    let unix0 = 1_700_000_000.0;
    // Two ESCs, one frame each every 50 ms; ESC 1's frames arrive 10 ms late.
    for k in 0..30u32 {
        for esc in 0..2u8 {
            let arrived = t0 + Duration::from_millis(u64::from(50 * k + 10 * u32::from(esc)));
            let record = Record::new(
                Some(unix0 + f64::from(k) * 0.05),
                esc,
                &Data::from(frame(k as u16, Status::OK)),
                &Settings::default(),
            );
            out.update(&Update {
                esc,
                frame: &Data::from(frame(k as u16, Status::OK)),
                record: &record,
                settings: &Settings::DEFAULT,
                arrived,
            });
            out.poll(arrived + Duration::from_millis(3)).unwrap();
        }
    }
    drop(out);
    let messages = tlog(&std::fs::read(&path).unwrap());
    assert!(matches!(messages[0].1, MavMessage::HEARTBEAT(_)));
    let usec = |s: f64| (s * 1e6).round() as u64;
    // The first poll with a frame: its time plus the 3 ms since it arrived.
    assert_eq!(messages[0].0, usec(unix0 + 0.003));
    for w in messages.windows(2) {
        assert!(w[0].0 <= w[1].0, "times never go back");
    }
    let last = messages.last().unwrap().0;
    assert!(
        (usec(unix0 + 1.45)..usec(unix0 + 1.47)).contains(&last),
        "{last}"
    );
    let mut statuses = 0;
    for (time, m) in &messages {
        if let MavMessage::ESC_STATUS(d) = m {
            assert_eq!(d.time_usec, *time);
            statuses += 1;
        }
    }
    assert_eq!(statuses, 60);

    // An existing file: refused, unchanged; replaced when asked.
    let before = std::fs::read(&path).unwrap();
    let e = MavlinkOutput::open(target.clone(), MavlinkOptions::default()).unwrap_err();
    assert!(matches!(e, OutputError::Open { .. }), "{e}");
    assert!(e.to_string().contains("exists"), "{e}");
    assert_eq!(std::fs::read(&path).unwrap(), before);
    let options = MavlinkOptions {
        overwrite: true,
        ..MavlinkOptions::default()
    };
    let mut out = MavlinkOutput::open(target, options).unwrap();
    assert!(std::fs::read(&path).unwrap().is_empty());
    // Records without a Unix time (a capture's own clock): the system clock.
    let now = Instant::now();
    let record = Record::new(
        Some(12.5),
        0,
        &Data::from(frame(1, Status::OK)),
        &Settings::default(),
    );
    out.update(&Update {
        esc: 0,
        frame: &Data::from(frame(1, Status::OK)),
        record: &record,
        settings: &Settings::DEFAULT,
        arrived: now,
    });
    out.poll(now).unwrap();
    let unix_now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_secs_f64();
    for (time, _) in tlog(&std::fs::read(&path).unwrap()) {
        assert!(
            (usec(unix_now - 5.0)..=usec(unix_now)).contains(&time),
            "{time}"
        );
    }
}

#[test]
fn failure_flags_of_every_fault() {
    assert_eq!(
        messages::failure_flags(Status::OK.with(Fault::OverCurrent)),
        1
    );
    assert_eq!(
        messages::failure_flags(Status::OK.with(Fault::MotorBlocked)),
        32
    );
}

/// The serial target, on a pseudo-terminal: the same messages, back to back on the line, read
/// back by the mavlink crate's parser; a port that goes away is lost and reopened.
#[cfg(unix)]
#[test]
fn a_serial_port_carries_the_same_messages() {
    use std::io::Read;
    use std::os::fd::AsFd;

    // Close-on-exec: pymavlink's Python, started by a test beside this one, must not hold it.
    let pair = hwfoc_sim::pty::RawPair::open().unwrap();
    let path = pair.path;
    let target =
        MavlinkTarget::parse(&format!("serial:{}:115200", path.to_string_lossy())).unwrap();
    let mut out = MavlinkOutput::open(target, MavlinkOptions::default()).unwrap();
    let now = Instant::now();
    for (packet, esc) in [(1u16, 0u8), (1, 1), (2, 0)] {
        let f = frame(packet, Status::OK);
        let record = Record::new(None, esc, &Data::from(f), &Settings::default());
        out.update(&Update {
            esc,
            frame: &Data::from(f),
            record: &record,
            settings: &Settings::DEFAULT,
            arrived: now,
        });
        out.poll(Instant::now()).unwrap();
    }
    assert_eq!(out.stats().errors, 0);
    // The messages may come through the pseudo-terminal in several reads: read until the line
    // has been quiet for 200 ms (the messages were all written above).
    let master = pair.master;
    let mut bytes = Vec::new();
    let mut chunk = [0u8; 4096];
    loop {
        let mut fds = [nix::poll::PollFd::new(
            master.as_fd(),
            nix::poll::PollFlags::POLLIN,
        )];
        if nix::poll::poll(&mut fds, nix::poll::PollTimeout::from(200u16)).unwrap() == 0 {
            break;
        }
        let n = (&master).read(&mut chunk).unwrap();
        bytes.extend_from_slice(&chunk[..n]);
    }
    let mut reader = MavlinkReader::new(&bytes[..]);
    let mut got = Vec::new();
    while let Ok((_, message)) = reader.read_message::<MavMessage>(MavlinkVersion::V2) {
        got.push(message);
    }
    let names = names(
        &got.into_iter()
            .map(|m| (MavHeader::default(), m))
            .collect::<Vec<_>>(),
    );
    assert!(names.iter().any(|n| n == "HEARTBEAT"), "{names:?}");
    assert!(
        names.iter().any(|n| n.starts_with("ESC_TELEMETRY_1_TO_4")),
        "{names:?}"
    );
    assert!(
        names.iter().any(|n| n.starts_with("ESC_STATUS")),
        "{names:?}"
    );
}
