//! `hwfoc bridge` end to end, through real pseudo-terminals and sockets: virtual ESCs on ptys ->
//! `hwfoc bridge --datalink` -> a pty read back by `hwfoc decode` (every frame of every ESC, in
//! its channel); DataLink inputs with bad frames; outputs that fail (an unreachable UDP
//! destination, an SLCAN adapter unplugged) while the others go on. MAVLink as ground stations
//! receive it is in `ground_stations.rs`.

#![cfg(unix)]

mod common;

use std::io::{Read, Write};
use std::os::fd::AsFd;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;
use std::time::{Duration, Instant};

use common::{Dir, by_esc, hwfoc, ok, records, run};
use common::{Pty, Running, pty};
use hwfoc::Status;
use hwfoc::datalink::{self, LengthByte};
use hwfoc::foc::DataFrame;
use nix::poll::{PollFd, PollFlags, PollTimeout, poll};
use nix::sys::signal::Signal;
use serde_json::Value;

const ESCS: usize = 8;

/// Copies what arrives on `from`'s master to `to` (a pty's master, or a buffer) until `stop`.
fn pump(mut from: std::fs::File, mut to: impl Write + Send + 'static, stop: Arc<AtomicBool>) {
    thread::spawn(move || {
        let mut buf = [0u8; 4096];
        while !stop.load(Ordering::Relaxed) {
            let mut fds = [PollFd::new(from.as_fd(), PollFlags::POLLIN)];
            if poll(&mut fds, PollTimeout::from(50u16)).unwrap_or(0) == 0 {
                continue;
            }
            match from.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(n) => {
                    if to.write_all(&buf[..n]).is_err() {
                        break;
                    }
                }
            }
        }
    });
}

/// A pty whose output is drained (so that a writer never blocks on a full buffer).
fn drained() -> (Pty, Arc<AtomicBool>) {
    let pty = pty();
    let stop = Arc::new(AtomicBool::new(false));
    pump(
        pty.master.try_clone().unwrap(),
        std::io::sink(),
        Arc::clone(&stop),
    );
    (pty, stop)
}

#[test]
fn eight_virtual_escs_through_the_datalink_bridge_decode_whole_in_their_channels() {
    let dir = Dir::new();
    let links = dir.path("escs");
    let truth = dir.path("truth.jsonl");
    let decoded_path = dir.path("decoded.jsonl");

    let mut sim = Running::start(&[
        "simulate",
        "--escs",
        "8",
        "--pty",
        "--seed",
        "11",
        "--profile",
        "sine",
        "--lead-in",
        "0.5",
        "--duration",
        "16",
        "--link-dir",
        &links.to_string_lossy(),
        "--truth",
        &truth.to_string_lossy(),
    ]);
    let deadline = Instant::now() + Duration::from_secs(10);
    while !(0..ESCS).all(|i| links.join(format!("esc{i}")).exists()) {
        assert!(Instant::now() < deadline, "the simulator made no pty links");
        thread::sleep(Duration::from_millis(50));
    }

    // The bridge writes DataLink frames into pty A; what comes out of A goes into pty B, which
    // `hwfoc decode` reads as a 115200-baud port.
    let a = pty();
    let b = pty();
    let stop = Arc::new(AtomicBool::new(false));
    pump(
        a.master.try_clone().unwrap(),
        b.master.try_clone().unwrap(),
        Arc::clone(&stop),
    );
    let mut decode = Running::start(&[
        "decode",
        &b.path.to_string_lossy(),
        "--baud",
        "115200",
        "-o",
        &decoded_path.to_string_lossy(),
    ]);
    thread::sleep(Duration::from_millis(300));

    let mut args: Vec<String> = vec!["bridge".into()];
    args.extend((0..ESCS).map(|i| links.join(format!("esc{i}")).to_string_lossy().into_owned()));
    args.extend([
        "--datalink".into(),
        a.path.to_string_lossy().into_owned(),
        "--duration".into(),
        "10".into(),
    ]);
    let bridge = run(hwfoc().args(&args));
    let report = String::from_utf8_lossy(&bridge.stderr).into_owned();
    assert!(bridge.status.success(), "bridge failed: {report}");
    assert!(
        report.contains(" 0 failed, 0 superseded"),
        "the DataLink output lost frames: {report}"
    );

    thread::sleep(Duration::from_millis(500));
    decode.signal(Signal::SIGINT);
    assert!(decode.wait(Duration::from_secs(10)), "{}", decode.stderr());
    stop.store(true, Ordering::Relaxed);
    assert!(sim.wait(Duration::from_secs(20)), "{}", sim.stderr());

    let decoded = records(&std::fs::read_to_string(&decoded_path).unwrap());
    let truth = records(&std::fs::read_to_string(&truth).unwrap());
    let sent = by_esc(&truth);
    let got = by_esc(&decoded);
    assert_eq!(
        got.keys().copied().collect::<Vec<_>>(),
        (0..ESCS as u64).collect::<Vec<_>>(),
        "every ESC, each in its own channel"
    );
    for (esc, frames) in &got {
        let sent = &sent[esc];
        assert!(
            frames.len() > 120,
            "esc {esc}: only {} frames",
            frames.len()
        );
        // The frames came through in order and without a gap: they are exactly a run of the
        // frames the simulator sent that ESC, value for value.
        let first = frames[0]["packet"].clone();
        let start = sent
            .iter()
            .position(|s| s["packet"] == first)
            .unwrap_or_else(|| panic!("esc {esc}: packet {first} was never sent"));
        for (k, got) in frames.iter().enumerate() {
            let want = sent
                .get(start + k)
                .unwrap_or_else(|| panic!("esc {esc}: more frames than were sent"));
            // Sent on the ESCs' own wires, received as the hub's channels.
            assert_eq!(want["protocol"], "hw-foc", "esc {esc}: frame {k} as sent");
            assert_eq!(
                got["protocol"], "datalink",
                "esc {esc}: frame {k} as received"
            );
            let compared = |k: &&String| *k != "t_s" && *k != "protocol";
            for field in got.as_object().unwrap().keys().filter(compared) {
                assert_eq!(
                    got[field], want[field],
                    "esc {esc}: {field} of frame {k} (packet {})",
                    want["packet"]
                );
            }
        }
    }
}

/// DataLink frames as a hub sends them, with the faults of the issue among them.
fn hub_bytes() -> Vec<u8> {
    let esc = |channel: u16, k: u16| DataFrame {
        packet: 100 + k,
        throttle_in_raw: 512,
        throttle_out_raw: 500,
        erpm_raw: 1000 + channel * 100 + k,
        voltage_raw: 250 - channel,
        current_raw: 64 * (channel as i16 + 1),
        phase_current_raw: 128,
        mos_adc: 120,
        cap_adc: 130,
        status: Status(0),
    };
    let mut bytes = Vec::new();
    for k in 0..10u16 {
        let mut frame = datalink::HubFrame::new(k);
        for channel in 0..3 {
            frame.slots[usize::from(channel)] = Some(esc(channel, k));
        }
        let mut wire = match k {
            // Some drivers write a length byte of 160.
            4 => frame.encode_as(LengthByte::Total),
            _ => frame.encode(),
        };
        match k {
            // A flipped bit: the CRC rejects the frame.
            2 => wire[40] ^= 0x10,
            // A wrong length byte: not a DataLink frame at all.
            3 => wire[1] = 0x9F,
            // Channel 2's record says channel 9: dropped, the others kept. (The CRC is made
            // again, as a hub with that fault would send it.)
            6 => {
                wire[6 + 2 * 19] = 9;
                let crc = hwfoc::wire::crc16_xmodem(&wire[..158]);
                wire[158..].copy_from_slice(&crc.to_le_bytes());
            }
            _ => {}
        }
        bytes.extend_from_slice(&wire);
    }
    bytes
}

#[test]
fn datalink_inputs_with_bad_frames_are_counted_and_the_other_escs_kept() {
    let dir = Dir::new();
    let input = dir.path("hub.bin");
    std::fs::write(&input, hub_bytes()).unwrap();

    let out = ok(run(hwfoc().arg("decode").arg(&input)));
    let decoded = records(&String::from_utf8(out.stdout).unwrap());
    let per_esc = by_esc(&decoded);
    // Frames 2 (CRC) and 3 (length byte) are lost whole; channel 2 also misses frame 6.
    let packets = |esc: u64| -> Vec<u64> {
        per_esc[&esc]
            .iter()
            .map(|r| r["packet"].as_u64().unwrap())
            .collect()
    };
    assert_eq!(packets(0), [100, 101, 104, 105, 106, 107, 108, 109]);
    assert_eq!(packets(1), packets(0));
    assert_eq!(packets(2), [100, 101, 104, 105, 107, 108, 109]);
    assert_eq!(per_esc.len(), 3);
    assert_eq!(per_esc[&2][0]["voltage_v"], 24.8);

    let out = ok(run(hwfoc().args(["summary", "--json"]).arg(&input)));
    let summary: Value = serde_json::from_slice(&out.stdout).unwrap();
    let hub = &summary["hubs"][0];
    assert_eq!(hub["frames"], 8);
    assert_eq!(hub["frames_length_byte_158"], 7);
    assert_eq!(hub["frames_length_byte_160"], 1);
    assert_eq!(hub["checksum_failures"], 1);
    assert_eq!(hub["bad_channels"], 1);
    assert_eq!(hub["lost_packets"], 2);
    assert_eq!(hub["bytes_skipped"], 320);
    let escs = summary["escs"].as_array().unwrap();
    assert_eq!(escs.len(), 3, "only the channels that carried an ESC");
    // Channel 2 lost packets 102, 103 and 106.
    assert_eq!(escs[2]["link"]["lost_packets"], 3, "{}", escs[2]);
    let text = String::from_utf8(ok(run(hwfoc().arg("summary").arg(&input))).stdout).unwrap();
    assert!(
        text.contains("DataLink V2") && text.contains("1 checksum failures"),
        "{text}"
    );
}

#[test]
fn failing_outputs_are_reported_once_counted_and_the_others_keep_going() {
    // A UDP port nobody listens on: each send is refused (ICMP port unreachable).
    let closed = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let port = closed.local_addr().unwrap().port();
    drop(closed);
    let (datalink, stop_datalink) = drained();
    let (slcan, stop_slcan) = drained();
    let mut bridge = Running::start(&[
        "bridge",
        "--sim",
        "3",
        "--datalink",
        &datalink.path.to_string_lossy(),
        "--mavlink",
        &format!("udp:127.0.0.1:{port}"),
        "--dronecan",
        &format!("slcan:{}", slcan.path.to_string_lossy()),
        "--duration",
        "5",
    ]);
    thread::sleep(Duration::from_secs(2));
    // The SLCAN adapter is unplugged.
    stop_slcan.store(true, Ordering::Relaxed);
    drop(slcan);
    assert!(bridge.wait(Duration::from_secs(20)), "{}", bridge.stderr());
    stop_datalink.store(true, Ordering::Relaxed);
    let err = bridge.stderr();
    assert!(!err.contains("panicked"), "{err}");
    let refused: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("hwfoc: mavlink udp:127.0.0.1"))
        .collect();
    assert_eq!(refused.len(), 1, "reported once, not per message: {err}");
    assert!(
        err.lines()
            .any(|l| l.starts_with("hwfoc: dronecan slcan:") && l.contains("lost")),
        "{err}"
    );
    // The report: every output named, the failures counted, the DataLink frames all sent.
    let line = |name: &str| {
        err.lines()
            .find(|l| l.trim_start().starts_with(name))
            .unwrap_or_else(|| panic!("no report of {name}: {err}"))
            .to_string()
    };
    let datalink = line("datalink");
    assert!(datalink.contains(" 0 failed"), "{datalink}");
    let sent: u64 = datalink
        .split(": ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap();
    assert!(sent > 40, "{datalink}");
    assert!(!line("mavlink").contains(" 0 failed"), "{err}");
    assert!(!line("dronecan").contains(" 0 failed"), "{err}");
}

#[test]
fn a_bridge_needs_an_output_and_refuses_bad_ones_in_one_line() {
    let o = run(hwfoc().args(["bridge", "--sim", "1"]));
    common::assert_fails_with(&o, "name an output");
    let o = run(hwfoc().args(["bridge", "--sim", "1", "--mavlink", "tcp:1.2.3.4:5"]));
    common::assert_fails_with(&o, "tcp:1.2.3.4:5");
    let o = run(hwfoc().args([
        "bridge",
        "--sim",
        "1",
        "--dronecan",
        "slcan:/dev/ttyNOPE:123",
    ]));
    common::assert_fails_with(&o, "123");
    let o = run(hwfoc().args(["bridge", "--sim", "1", "--datalink", "/dev/ttyNOPE-hwfoc"]));
    common::assert_fails_with(&o, "/dev/ttyNOPE-hwfoc");
}

/// Port 0 and the unspecified address are nowhere to send to: refused, not silently accepted.
#[test]
fn a_udp_destination_needs_a_port_and_an_address() {
    for (spec, needle) in [
        ("udp:1.2.3.4:0", "port 0 is no destination"),
        ("udp:0", "port 0 is no destination"),
        ("udp:0.0.0.0:14550", "0.0.0.0 is no destination address"),
        ("udp:[::]:14550", ":: is no destination address"),
    ] {
        let o = run(hwfoc().args([
            "bridge",
            "--sim",
            "1",
            "--duration",
            "0.2",
            "--mavlink",
            spec,
        ]));
        common::assert_fails_with(&o, &format!("mavlink {spec}: cannot open: {needle}"));
    }
}

#[test]
fn the_monitor_shows_a_datalink_port_as_its_escs() {
    let hub = pty();
    let mut writer = hub.master.try_clone().unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let writing = Arc::clone(&stop);
    thread::spawn(move || {
        let mut k = 0u16;
        while !writing.load(Ordering::Relaxed) {
            let mut frame = datalink::HubFrame::new(k);
            for channel in [0usize, 1, 5] {
                frame.slots[channel] = Some(DataFrame {
                    packet: k,
                    voltage_raw: 240 + channel as u16,
                    ..Default::default()
                });
            }
            if writer.write_all(&frame.encode()).is_err() {
                break;
            }
            k = k.wrapping_add(1);
            thread::sleep(Duration::from_millis(50));
        }
    });
    let mut monitor = Running::start(&[
        "monitor",
        &hub.path.to_string_lossy(),
        "--baud",
        "115200",
        "--plain",
        "--no-config",
        "--interval",
        "0.5",
    ]);
    let line = monitor.wait_for_stdout("channel 5", Duration::from_secs(10));
    assert!(line.contains("24.5 V"), "{line}");
    monitor.wait_for_stdout("channel 1", Duration::from_secs(5));
    monitor.signal(Signal::SIGINT);
    assert!(
        monitor.wait(Duration::from_secs(10)),
        "{}",
        monitor.stderr()
    );
    stop.store(true, Ordering::Relaxed);
    let out = monitor.stdout();
    assert!(out.contains("channel 0"), "{out}");
    assert!(
        !out.contains("channel 2"),
        "an empty slot is not an ESC: {out}"
    );
}

/// A buffer the pump fills and the test reads.
#[derive(Clone, Default)]
struct Buffer(Arc<std::sync::Mutex<Vec<u8>>>);

impl Write for Buffer {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.lock().unwrap().extend_from_slice(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[test]
fn a_candump_log_of_can_escs_goes_out_on_datalink_with_their_voltages_and_currents() {
    let dir = Dir::new();
    let log = dir.path("bus.log");
    let log = log.to_string_lossy();
    ok(run(hwfoc().args([
        "simulate",
        "--protocol",
        "hw-can",
        "--profile",
        "sine",
        "--escs",
        "4",
        "--duration",
        "3",
        "-o",
        &log,
    ])));
    let line = pty();
    let stop = Arc::new(AtomicBool::new(false));
    let got = Buffer::default();
    pump(
        line.master.try_clone().unwrap(),
        got.clone(),
        Arc::clone(&stop),
    );
    let bridge = run(hwfoc().args(["bridge", &log, "--datalink", &line.path.to_string_lossy()]));
    let report = String::from_utf8_lossy(&bridge.stderr).into_owned();
    assert!(bridge.status.success(), "bridge failed: {report}");
    thread::sleep(Duration::from_millis(300));
    stop.store(true, Ordering::Relaxed);

    let bytes = got.0.lock().unwrap().clone();
    let mut decoder = datalink::Decoder::new();
    let mut slots: Vec<Vec<DataFrame>> = vec![Vec::new(); datalink::CHANNELS];
    decoder.decode_all(&bytes, |d| {
        for (channel, slot) in d.frame.slots.iter().enumerate() {
            slots[channel].extend(*slot);
        }
    });
    assert_eq!(decoder.stats().bytes_skipped(), 0, "{report}");
    let carried: Vec<usize> = (0..datalink::CHANNELS)
        .filter(|&c| !slots[c].is_empty())
        .collect();
    assert_eq!(carried.len(), 4, "four ESCs, each in a channel: {report}");
    for c in carried {
        let frames = &slots[c];
        assert!(frames.len() > 10, "channel {c}: {} frames", frames.len());
        assert!(
            frames.iter().any(|f| f.voltage_raw > 0),
            "channel {c}: no voltage"
        );
        assert!(
            frames.iter().any(|f| f.current_raw != 0),
            "channel {c}: no current"
        );
    }
}

#[test]
fn can_escs_numbered_by_node_id_past_the_datalink_channels_are_told_and_fail_the_bridge() {
    // Four ESCs never asked for their ids: nodes 10 to 13, ESCs 10 to 13, which DataLink's
    // eight channels cannot carry.
    let dir = Dir::new();
    let log = dir.arg("bus.log");
    ok(run(hwfoc().args([
        "simulate",
        "--protocol",
        "hw-can",
        "--escs",
        "4",
        "--no-ask-ids",
        "--duration",
        "1",
        "-o",
        &log,
    ])));
    let (line, stop) = drained();
    let bridge = run(hwfoc().args(["bridge", &log, "--datalink", &line.path.to_string_lossy()]));
    stop.store(true, Ordering::Relaxed);
    let report = String::from_utf8_lossy(&bridge.stderr).into_owned();
    assert!(!bridge.status.success(), "output was lost: {report}");
    assert!(
        report.contains(" frames of 4 ESCs (10 to 13), "),
        "{report}"
    );
    assert!(
        report.contains("frames of ESCs 10 to 13 not sent: it carries ESCs 0 to 7"),
        "{report}"
    );
}
