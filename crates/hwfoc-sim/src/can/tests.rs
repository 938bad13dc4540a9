//! The CAN bus of virtual ESCs: rates, transfer ids, every service, SetID renumbering, the
//! factory state, faults, the outputs.

use std::collections::HashMap;

use hwfoc::dronecan::*;

use super::*;
use crate::fleet::tests::spec;

const S: u64 = 1_000_000_000;
/// The controller's node.
const ME: u8 = 100;

fn bus(n: usize, factory: bool) -> CanBus {
    CanBus::build(&spec(n), factory).unwrap()
}

/// Every transfer the bus sends until `t_ns`, decoded by the codec's receiver, with the
/// frames' times. Each is one frame; each frame is decoded on its own too (in the factory
/// state, ESCs of one node send the same transfer ids, which one receiver takes for
/// duplicates): that is what is returned.
fn decode(bus: &mut CanBus, t_ns: u64, rx: &mut Receiver) -> Vec<(u64, Received)> {
    let mut out = Vec::new();
    for (t, f) in bus.frames_until(t_ns) {
        let tail = TailByte::from_byte(*f.data().last().unwrap());
        assert!(tail.start && tail.end && !tail.toggle, "{f}");
        let header = Header::parse(f.id()).unwrap();
        let kind = Kind::of(&header).unwrap();
        let message = Message::decode(kind, &f.data()[..f.len() - 1]).unwrap();
        rx.push(&f);
        out.push((
            t,
            Received {
                header,
                transfer_id: tail.transfer_id,
                message,
            },
        ));
    }
    out
}

/// Sends `m` from the controller (a request to `dest`, or a broadcast) at `t_ns` with
/// transfer id `tid` and priority 20.
fn send(bus: &mut CanBus, t_ns: u64, m: impl Into<Message>, dest: u8, tid: u8) -> usize {
    let m = m.into();
    let mut n = 0;
    for f in m.frames(20, ME, dest, tid) {
        n += bus.receive(t_ns, &f);
    }
    n
}

/// The responses to the controller among `got`.
fn responses(got: &[(u64, Received)]) -> Vec<(u8, u8, Message)> {
    got.iter()
        .filter(|(_, r)| r.header.transfer == TransferType::Response { destination: ME })
        .map(|(_, r)| {
            assert_eq!(r.header.priority, 20);
            (r.header.source_node, r.transfer_id, r.message)
        })
        .collect()
}

#[test]
fn rates_transfer_ids_and_time_order() {
    let mut b = bus(4, false);
    let mut rx = Receiver::new();
    let got = decode(&mut b, 10 * S, &mut rx);
    // In time order, never two frames at once on the bus.
    assert!(got.windows(2).all(|w| w[1].0 >= w[0].0 + 99 * 2000));
    let mut count: HashMap<(u8, Kind), Vec<(u64, u8)>> = HashMap::new();
    for (t, r) in &got {
        assert_eq!(r.header.priority, PRIORITY);
        count
            .entry((r.header.source_node, r.message.kind()))
            .or_default()
            .push((*t, r.transfer_id));
    }
    for node in 10..14 {
        for (kind, hz) in [
            (Kind::StatusMsg1, 50),
            (Kind::StatusMsg2, 50),
            (Kind::StatusMsg3, 10),
            (Kind::NodeStatus, 1),
        ] {
            let v = &count[&(node, kind)];
            assert!(
                (v.len() as i64 - 10 * hz).abs() <= 1,
                "{node} {kind}: {}",
                v.len()
            );
            // Each stream counts its own transfer ids, from 0, wrapping at 32.
            for (k, (_, tid)) in v.iter().enumerate() {
                assert_eq!(usize::from(*tid), k % 32);
            }
            // Regular intervals (a frame may wait for the bus a little).
            let period = S / hz as u64;
            for w in v.windows(2) {
                let gap = w[1].0 - w[0].0;
                assert!(gap.abs_diff(period) < 2_000_000, "{gap} {period}");
            }
        }
    }
    // The codec's receiver saw no error.
    assert!(rx.stats().nodes().all(|(_, n)| n.total_transfers() > 0));
    assert_eq!(got.len(), 4 * (500 + 500 + 100 + 10));
    // The same seed gives the same bus.
    let again: Vec<(u64, CanFrame)> = bus(4, false).frames_until(3 * S);
    assert_eq!(again, bus(4, false).frames_until(3 * S));
}

#[test]
fn status_messages_follow_the_model_and_the_direction() {
    // The steps profile of `spec`: 0 until 1.5 s, then 50 % for 1 s, every 2 s.
    let mut b = bus(2, false);
    let mut rx = Receiver::new();
    let got = decode(&mut b, 5 * S / 2, &mut rx);
    let last = |node: u8, kind: Kind| {
        got.iter()
            .rev()
            .find(|(t, r)| {
                *t < 2_400_000_000 && r.header.source_node == node && r.message.kind() == kind
            })
            .map(|(_, r)| r.message)
            .unwrap()
    };
    for node in [10, 11] {
        let Message::StatusMsg1(m1) = last(node, Kind::StatusMsg1) else {
            panic!()
        };
        // 500 KV, 6 cells, 50 %: around 5000 rpm; pwm 500 of 1000 (ESC 1 lags the profile
        // by up to a second).
        assert_eq!(m1.counter_clockwise(), node == 11);
        assert_eq!(m1.status & !StatusMsg1::STATUS_CCW, 0);
        if node == 10 {
            assert!((4000..6000).contains(&m1.rpm), "{m1:?}");
            assert!((480..=520).contains(&m1.pwm), "{m1:?}");
            let Message::StatusMsg2(m2) = last(node, Kind::StatusMsg2) else {
                panic!()
            };
            assert!((230..260).contains(&m2.input_voltage), "{m2:?}");
            assert!(m2.current > 20, "{m2:?}");
            assert!((20..60).contains(&m2.temperature), "{m2:?}");
            let Message::StatusMsg3(m3) = last(node, Kind::StatusMsg3) else {
                panic!()
            };
            assert!(m3.mos_t >= m3.motor_t && m3.motor_t >= 20, "{m3:?}");
        }
    }
    // Before the throttle: stopped.
    let Some((_, first)) = got
        .iter()
        .find(|(_, r)| r.message.kind() == Kind::StatusMsg1)
    else {
        panic!()
    };
    assert_eq!(
        first.message,
        Message::from(StatusMsg1 {
            rpm: 0,
            pwm: 0,
            status: 0
        })
    );
}

#[test]
fn get_esc_id_answers_from_every_esc() {
    let mut b = bus(3, false);
    b.frames_until(S);
    assert_eq!(send(&mut b, S, GetEscId::REQUEST, 0, 7), 3);
    // An answer, or any other payload, is not a request.
    assert_eq!(send(&mut b, S, GetEscId::answer(5, 1), 0, 8), 0);
    let got = decode(&mut b, S + 5_000_000, &mut Receiver::new());
    let answers: Vec<(u8, GetEscId)> = got
        .iter()
        .filter_map(|(t, r)| match r.message {
            Message::GetEscId(m) => {
                assert!(*t >= S + ANSWER_NS);
                Some((r.header.source_node, m))
            }
            _ => None,
        })
        .collect();
    assert_eq!(
        answers,
        [
            (10, GetEscId::answer(10, 1)),
            (11, GetEscId::answer(11, 2)),
            (12, GetEscId::answer(12, 3))
        ]
    );
}

#[test]
fn the_factory_state_and_set_id_renumbering() {
    let mut b = bus(3, true);
    assert!(b.escs().iter().all(|e| *e.config() == EscConfig::FACTORY));
    let mut rx = Receiver::new();
    let got = decode(&mut b, S, &mut rx);
    assert!(got.iter().all(|(_, r)| r.header.source_node == 1));
    // All three answer GetEscID as node 1, channel 1.
    send(&mut b, S, GetEscId::REQUEST, 0, 0);
    let got = decode(&mut b, S + 5_000_000, &mut Receiver::new());
    let ids: Vec<_> = got
        .iter()
        .filter_map(|(_, r)| match r.message {
            Message::GetEscId(m) => m.as_answer(),
            _ => None,
        })
        .collect();
    assert_eq!(ids, [(1, 1); 3]);
    // A SetID to node 1 renumbers them all (what the setup guide must warn of); the answers
    // come from node 1 with the request's transfer id.
    let set = SetIdRequest {
        node_id: 20,
        throttle_channel: 4,
    };
    assert_eq!(send(&mut b, 2 * S, set, 1, 9), 3);
    let got = decode(&mut b, 3 * S, &mut Receiver::new());
    let want = Message::from(SetIdResponse {
        node_id: 20,
        throttle_channel: 4,
    });
    assert_eq!(responses(&got), [(1, 9, want); 3]);
    // From then on they send as node 20.
    let after: Vec<u8> = got
        .iter()
        .filter(|(t, _)| *t > 2 * S + 2 * ANSWER_NS)
        .map(|(_, r)| r.header.source_node)
        .collect();
    assert!(!after.is_empty() && after.iter().all(|&n| n == 20));
    // One ESC of a set-up bus: only node 11 changes; out-of-range values change nothing.
    let mut b = bus(3, false);
    assert_eq!(
        send(
            &mut b,
            S,
            SetIdRequest {
                node_id: 30,
                throttle_channel: 7
            },
            11,
            3
        ),
        1
    );
    for (node, channel) in [(0, 1), (128, 1), (30, 0), (30, 64)] {
        let bad = SetIdRequest {
            node_id: node,
            throttle_channel: channel,
        };
        assert_eq!(send(&mut b, S, bad, 30, 4), 1);
    }
    assert_eq!(send(&mut b, S, GetEscId::REQUEST, 0, 1), 3);
    let got = decode(&mut b, 2 * S, &mut Receiver::new());
    let r = responses(&got);
    assert_eq!(r.len(), 5);
    assert_eq!(r[0].0, 11);
    assert!(r[1..].iter().all(|x| x.0 == 30
        && x.2
            == Message::from(SetIdResponse {
                node_id: 30,
                throttle_channel: 7
            })));
    let ids: Vec<_> = got
        .iter()
        .filter_map(|(_, r)| match r.message {
            Message::GetEscId(m) => m.as_answer(),
            _ => None,
        })
        .collect();
    assert_eq!(ids, [(10, 1), (30, 7), (12, 3)]);
}

/// ESC node 10 of a one-ESC bus, after `request` at 1 s: its response.
fn ask(b: &mut CanBus, t_ns: u64, request: impl Into<Message>) -> Message {
    assert_eq!(send(b, t_ns, request, 10, 17), 1);
    let got = decode(b, t_ns + 3_000_000, &mut Receiver::new());
    let r = responses(&got);
    assert_eq!(r.len(), 1, "{r:?}");
    assert_eq!((r[0].0, r[0].1), (10, 17));
    r[0].2
}

#[test]
fn each_setup_service() {
    let mut b = bus(1, false);
    b.frames_until(S);
    // SetLED: taken and echoed; a bad blink is not taken.
    let led = SetLedRequest {
        option: 1,
        color: 5,
        blink: 2,
    };
    assert_eq!(
        ask(&mut b, S, led),
        SetLedResponse {
            option: 1,
            color: 5,
            blink: 2
        }
        .into()
    );
    let bad = SetLedRequest { blink: 3, ..led };
    assert_eq!(
        ask(&mut b, S + 10_000_000, bad),
        SetLedResponse {
            option: 1,
            color: 5,
            blink: 2
        }
        .into()
    );
    // SetDirection: query, set, and bit 14 follows.
    let dir = |d| SetDirectionRequest { direction: d };
    assert_eq!(
        ask(&mut b, S + 20_000_000, dir(255)),
        SetDirectionResponse { direction: 0 }.into()
    );
    assert_eq!(
        ask(&mut b, S + 30_000_000, dir(1)),
        SetDirectionResponse { direction: 1 }.into()
    );
    let got = decode(&mut b, S + 200_000_000, &mut Receiver::new());
    assert!(got.iter().any(|(_, r)| matches!(r.message,
        Message::StatusMsg1(m) if m.counter_clockwise())));
    // SetThrottleSource.
    assert_eq!(
        ask(
            &mut b,
            S + 300_000_000,
            SetThrottleSourceRequest { source: 1 }
        ),
        SetThrottleSourceResponse { source: 1 }.into()
    );
    assert_eq!(
        ask(
            &mut b,
            S + 310_000_000,
            SetThrottleSourceRequest { source: 7 }
        ),
        SetThrottleSourceResponse { source: 1 }.into()
    );
    // SetReportingFrequency: read, write StatusMsg1 to 10 Hz (code 7), another id.
    let freq = |option, msg_id, rate| SetReportingFrequencyRequest {
        option,
        msg_id,
        rate,
    };
    let answer = |option, msg_id, rate| -> Message {
        SetReportingFrequencyResponse {
            option,
            msg_id,
            rate,
        }
        .into()
    };
    assert_eq!(ask(&mut b, 2 * S, freq(0, 20052, 0)), answer(0, 20052, 7));
    assert_eq!(
        ask(&mut b, 2 * S + 10_000_000, freq(1, 20050, 7)),
        answer(1, 20050, 7)
    );
    assert_eq!(
        ask(&mut b, 2 * S + 20_000_000, freq(1, 20050, 10)),
        answer(1, 20050, 7)
    );
    assert_eq!(
        ask(&mut b, 2 * S + 30_000_000, freq(0, 1034, 0)),
        answer(0, 1034, 9)
    );
    let got = decode(&mut b, 4 * S + 40_000_000, &mut Receiver::new());
    let msg1 = got
        .iter()
        .filter(|(_, r)| r.message.kind() == Kind::StatusMsg1)
        .count();
    assert!((20..=21).contains(&msg1), "{msg1}");
    // StatusMsg2 off (code 9, 0 Hz).
    assert_eq!(ask(&mut b, 5 * S, freq(1, 20051, 9)), answer(1, 20051, 9));
    let got = decode(&mut b, 6 * S, &mut Receiver::new());
    assert!(
        !got.iter()
            .any(|(_, r)| r.message.kind() == Kind::StatusMsg2)
    );
    // GetMajorConfig: all of the above.
    assert_eq!(
        ask(&mut b, 6 * S, GetMajorConfigRequest { option: 0 }),
        GetMajorConfigResponse {
            direction: true,
            throttle_source: true,
            throttle_channel: 1,
            led_status: 2,
            led_color: 5,
            msg2_rate: 9,
            msg1_rate: 7,
            positioning_angle: 0,
            reserved: [0, 0],
        }
        .into()
    );
    // SelfTest: fails while the motor turns (50 % from 5.5 s).
    let Message::SelfTestResponse(r) = ask(&mut b, 6 * S + 100_000_000, SelfTestRequest {}) else {
        panic!()
    };
    assert_eq!(r.status, 1);
    // GetMaintenanceInformation: counts, and clears the time since maintenance.
    let Message::GetMaintenanceInformationResponse(before) = ask(
        &mut b,
        7 * S,
        GetMaintenanceInformationRequest { option: 0 },
    ) else {
        panic!()
    };
    assert!(before.total_rotation_time_min >= before.time_since_maintenance_min);
    let Message::GetMaintenanceInformationResponse(cleared) = ask(
        &mut b,
        7 * S + 10_000_000,
        GetMaintenanceInformationRequest { option: 1 },
    ) else {
        panic!()
    };
    assert_eq!(cleared.time_since_maintenance_min, 0);
    assert_eq!(
        cleared.total_rotation_time_min,
        before.total_rotation_time_min
    );
    // SetAngle is not answered; nor a request to another node.
    let angle = SetAngleRequest {
        option: 0,
        angle: 0,
    };
    assert_eq!(send(&mut b, 8 * S, angle, 10, 1), 0);
    assert_eq!(send(&mut b, 8 * S, SelfTestRequest {}, 11, 1), 0);
    // SetBaud: answered at the old rate, then silent on this bus until it runs at 250 k.
    assert_eq!(
        ask(&mut b, 9 * S, SetBaudRequest { baud: 2 }),
        SetBaudResponse {}.into()
    );
    assert_eq!(b.escs()[0].config().bitrate, 250_000);
    assert!(b.frames_until(10 * S).is_empty());
    assert_eq!(send(&mut b, 10 * S, GetEscId::REQUEST, 0, 2), 0);
    b.set_bitrate(250_000);
    assert!(!b.frames_until(11 * S).is_empty());
    assert_eq!(send(&mut b, 11 * S, GetEscId::REQUEST, 0, 3), 1);
}

#[test]
fn self_test_fails_while_turning_or_faulted() {
    let mut s = spec(1);
    s.faults = vec!["mos_overheat@3-4".parse().unwrap()];
    let mut b = CanBus::build(&s, false).unwrap();
    let status = |b: &mut CanBus, t| match ask(b, t, SelfTestRequest {}) {
        Message::SelfTestResponse(r) => r.status,
        m => panic!("{m:?}"),
    };
    // The profile: 50 % from 1.5 s to 2.5 s, every 2 s.
    assert_eq!(status(&mut b, 200_000_000), 0);
    assert_eq!(status(&mut b, 2 * S), 1); // turning
    assert_eq!(status(&mut b, 3 * S + 450_000_000), 1); // faulted, stopped
    // The fault shows through the model: NodeStatus warns and the temperatures are high.
    let got = decode(&mut b, 3 * S + 900_000_000, &mut Receiver::new());
    assert_eq!(status(&mut b, 5 * S + 450_000_000), 0); // at rest again
    assert!(got.iter().any(|(_, r)| matches!(r.message,
        Message::NodeStatus(m) if m.health == 1)));
    assert!(got.iter().any(|(_, r)| matches!(r.message,
        Message::StatusMsg3(m) if m.mos_t >= 110)));
}

#[test]
fn building_checks() {
    assert_eq!(
        CanBus::build(&spec(64), false).err().unwrap().to_string(),
        "64 ESCs on a CAN bus: at most 63 (a throttle channel has 6 bits)"
    );
    let mut s = spec(1);
    s.link.drop = 0.1;
    assert!(matches!(
        CanBus::build(&s, false),
        Err(crate::SimError::CanLinkFaults)
    ));
    let mut s = spec(1);
    s.faults = vec!["1:mos_short@1".parse().unwrap()];
    assert!(matches!(
        CanBus::build(&s, false),
        Err(crate::SimError::NoSuchEsc { esc: 1, n: 1 })
    ));
    assert_eq!(rate_interval_ns(1), Some(2_000_000));
    assert_eq!(rate_interval_ns(8), Some(S));
    assert_eq!(rate_interval_ns(9), None);
    assert_eq!(rate_interval_ns(0), None);
    assert_eq!(rate_interval_ns(10), None);
}

#[test]
fn a_candump_log_and_its_truth() {
    let dir = tempfile::tempdir().unwrap();
    let path = |n: &str| dir.path().join(n).display().to_string();
    let plan = CanPlan {
        destination: CanDestination::Candump(path("bus.log")),
        realtime: false,
        start_s: Some(1.7e9),
        duration_s: Some(2.0),
        truth: Some(path("truth.jsonl")),
        overwrite: false,
        ask_ids: false,
    };
    let session = CanSession::open(bus(2, false), &plan).unwrap();
    assert_eq!(session.output(), path("bus.log"));
    let report = session
        .run(&std::sync::atomic::AtomicBool::new(false))
        .unwrap();
    let log = std::fs::read_to_string(path("bus.log")).unwrap();
    let truth = std::fs::read_to_string(path("truth.jsonl")).unwrap();
    assert_eq!(log.lines().count() as u64, report.frames);
    assert_eq!(truth.lines().count() as u64, report.transfers);
    assert_eq!(report.frames, 2 * (100 + 100 + 20 + 2));
    let first = log.lines().next().unwrap();
    assert!(first.starts_with("(1700000000.0"), "{first}");
    let (_, rest) = first.split_once(") can0 ").unwrap();
    let (id, data) = rest.split_once('#').unwrap();
    assert_eq!((id.len(), data.len() % 2), (8, 0));
    let t: serde_json::Value = serde_json::from_str(truth.lines().next().unwrap()).unwrap();
    assert!(t["t_s"].as_f64().unwrap() >= 1.7e9);
    assert_eq!(t["priority"], 16);
    // Asked again: the file exists.
    assert!(CanSession::open(bus(2, false), &plan).is_err());
}

#[test]
fn the_virtual_controller_asks_for_ids_while_no_motor_turns() {
    let dir = tempfile::tempdir().unwrap();
    let path = |n: &str| dir.path().join(n).display().to_string();
    let run = |name: &str, ask_ids: bool, seconds: f64| {
        let plan = CanPlan {
            destination: CanDestination::Candump(path(name)),
            realtime: false,
            start_s: Some(1.7e9),
            duration_s: Some(seconds),
            truth: None,
            overwrite: false,
            ask_ids,
        };
        let report = CanSession::open(bus(3, false), &plan)
            .unwrap()
            .run(&std::sync::atomic::AtomicBool::new(false))
            .unwrap();
        let log = std::fs::read_to_string(path(name)).unwrap();
        assert_eq!(log.lines().count() as u64, report.frames);
        let frames: Vec<CanFrame> = log
            .lines()
            .map(|l| {
                let (_, frame) = l.split_once(") can0 ").unwrap();
                let (id, data) = frame.split_once('#').unwrap();
                let bytes: Vec<u8> = (0..data.len() / 2)
                    .map(|i| u8::from_str_radix(&data[2 * i..2 * i + 2], 16).unwrap())
                    .collect();
                CanFrame::extended(u32::from_str_radix(id, 16).unwrap(), &bytes).unwrap()
            })
            .collect();
        (report, frames)
    };
    let kind = |f: &CanFrame| {
        let h = Header::parse(f.id()).unwrap();
        (h.source_node, Kind::of(&h).unwrap())
    };
    // Idle for the first 1.5 s (the lead-in, then the level 0): asked at 0 and 1 s; at 1.5 s
    // the motors start, and an ESC that turns stops the requests.
    let (report, frames) = run("ask.log", true, 2.5);
    let asked: Vec<usize> = (0..frames.len())
        .filter(|&i| kind(&frames[i]).0 == hwfoc_ports::can::DEFAULT_SOURCE_NODE)
        .collect();
    assert_eq!(report.received, asked.len() as u64);
    assert_eq!(asked.len(), 2, "{asked:?}");
    assert_eq!(report.answers, 3 * report.received);
    // The log starts with the request, then the three answers [node, channel], before any
    // status message.
    assert_eq!(asked[0], 0);
    assert_eq!(frames[0].data(), &[0x00, 0xC0]);
    for (esc, f) in frames[1..4].iter().enumerate() {
        assert_eq!(kind(f), (FIRST_NODE + esc as u8, Kind::GetEscId));
        assert_eq!(&f.data()[..2], &[FIRST_NODE + esc as u8, esc as u8 + 1]);
    }
    // Without the controller: no request, no answer, and the ESCs' own frames are the same.
    let (quiet, alone) = run("quiet.log", false, 2.5);
    assert_eq!((quiet.received, quiet.answers), (0, 0));
    let own = |fs: &[CanFrame]| -> Vec<CanFrame> {
        fs.iter()
            .filter(|f| kind(f).1 != Kind::GetEscId)
            .copied()
            .collect()
    };
    assert_eq!(own(&frames), own(&alone));
}

#[test]
fn a_pcapng_recording_of_the_bus() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bus.pcapng").display().to_string();
    let plan = CanPlan {
        destination: CanDestination::Pcapng(path.clone()),
        realtime: false,
        start_s: Some(1.7e9),
        duration_s: Some(1.0),
        truth: None,
        overwrite: false,
        ask_ids: true,
    };
    let report = CanSession::open(bus(2, false), &plan)
        .unwrap()
        .run(&std::sync::atomic::AtomicBool::new(false))
        .unwrap();
    let bytes = std::fs::read(&path).unwrap();
    // A section header, then an interface of LINKTYPE_CAN_SOCKETCAN (227).
    assert_eq!(&bytes[..4], &[0x0A, 0x0D, 0x0D, 0x0A]);
    let shb_len = u32::from_le_bytes(bytes[4..8].try_into().unwrap()) as usize;
    let idb = &bytes[shb_len..];
    assert_eq!(u32::from_le_bytes(idb[..4].try_into().unwrap()), 1);
    assert_eq!(u16::from_le_bytes(idb[8..10].try_into().unwrap()), 227);
    // One enhanced packet block (type 6) per frame, each holding a 16-byte record.
    let mut at = shb_len;
    let mut packets = 0u64;
    while at < bytes.len() {
        let kind = u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        let len = u32::from_le_bytes(bytes[at + 4..at + 8].try_into().unwrap()) as usize;
        if kind == 6 {
            packets += 1;
            assert_eq!(
                u32::from_le_bytes(bytes[at + 20..at + 24].try_into().unwrap()),
                16
            );
        }
        at += len;
    }
    assert_eq!(packets, report.frames);
    assert!(report.received >= 1);
}
