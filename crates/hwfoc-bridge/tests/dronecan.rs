//! The DroneCAN output end to end: SLCAN written to a pseudo-terminal standing in for the
//! adapter, read back and reassembled here; a pty whose far end goes away and comes back; and
//! (ignored unless asked for: it needs a Python with the `dronecan` package, `HWFOC_DRONECAN_PY`
//! or `python3`; `.ci/dronecan.sh` makes one and runs it) pydronecan's own SLCAN driver decoding
//! what the output sends.

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::fd::{AsFd, OwnedFd};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::thread;
use std::time::{Duration, Instant};

use hwfoc::dronecan::{DataType, Kind, MAX_PAYLOAD_LEN, f16_from_f32, saturate_f16, transfer_crc};
use hwfoc::foc::DataFrame;
use hwfoc::telemetry::Data;
use hwfoc::{Settings, Status};
use hwfoc_bridge::dronecan::dsdl::{EscStatus, EscStatusExtended, Health, NodeStatus};
use hwfoc_bridge::dronecan::{DronecanOptions, DronecanOutput, SlcanTarget};
use hwfoc_bridge::{Output, OutputError, SILENT_AFTER, Update};
use hwfoc_io::Record;
use hwfoc_sim::pty::RawPair;
use nix::poll::{PollFd, PollFlags, PollTimeout, poll};

#[path = "py/python.rs"]
mod python;

/// A pty pair: the test holds the master (the adapter's side) and keeps the slave open (so
/// that the master never sees a hang-up while the program under test reopens it).
struct Pty {
    master: File,
    _slave: OwnedFd,
    path: PathBuf,
}

impl Pty {
    fn open() -> Pty {
        // Close-on-exec: pydronecan's Python, started by a test beside this one, must not
        // hold the master open (the slave would never hang up when a test drops it).
        let pair = RawPair::open().unwrap();
        pair.master_nonblocking().unwrap();
        Pty {
            master: pair.master,
            _slave: pair.slave,
            path: pair.path,
        }
    }

    fn path(&self) -> &str {
        self.path.to_str().unwrap()
    }

    /// What was written to the slave so far.
    fn read_now(&mut self) -> Vec<u8> {
        thread::sleep(Duration::from_millis(20));
        let mut out = Vec::new();
        let mut buf = [0u8; 4096];
        while let Ok(n) = self.master.read(&mut buf) {
            if n == 0 {
                break;
            }
            out.extend_from_slice(&buf[..n]);
        }
        out
    }
}

fn data_frame(packet: u16, erpm_raw: u16, voltage_raw: u16, mos_adc: u8, status: u16) -> DataFrame {
    DataFrame {
        packet,
        throttle_in_raw: 600,
        throttle_out_raw: 512 + packet % 300,
        erpm_raw,
        voltage_raw,
        current_raw: -100 + 37 * packet as i16,
        phase_current_raw: 900,
        mos_adc,
        cap_adc: 120,
        status: Status(status),
    }
}

fn record(esc: u8, frame: &DataFrame) -> Record {
    Record::new(Some(0.0), esc, &Data::from(*frame), &Settings::default())
}

fn update(out: &mut DronecanOutput, esc: u8, frame: &DataFrame, arrived: Instant) -> Record {
    let r = record(esc, frame);
    out.update(&Update {
        esc,
        frame: &Data::from(*frame),
        record: &r,
        settings: &Settings::DEFAULT,
        arrived,
    });
    r
}

/// What the output should send for `r` with `error_count`.
fn expected(r: &Record, error_count: u32) -> EscStatus {
    EscStatus {
        error_count,
        voltage: r.voltage_v.unwrap(),
        current: r.current_a.unwrap(),
        temperature: r.mos_temp_c.map_or(f32::NAN, |c| c + 273.15),
        rpm: r.rpm.unwrap().round() as i32,
        power_rating_pct: r.throttle_out_pct.unwrap().round().clamp(0.0, 127.0) as u8,
        esc_index: r.esc,
    }
}

/// The esc.StatusExtended the output should send for `r` (frame `f`).
fn expected_extended(r: &Record, f: &DataFrame) -> EscStatusExtended {
    EscStatusExtended {
        input_pct: r.throttle_in_pct.unwrap().round() as u8,
        output_pct: r.throttle_out_pct.unwrap().round() as u8,
        motor_temperature_deg_c: 0,
        motor_angle: 0,
        status_flags: u32::from(f.status.0),
        esc_index: r.esc,
    }
}

/// The DSDL serialisation of `m` (the codec's, which the output sends).
fn bytes<T: DataType>(m: &T) -> Vec<u8> {
    let mut out = [0u8; MAX_PAYLOAD_LEN];
    let n = m.encode_into(&mut out);
    out[..n].to_vec()
}

/// The data type of a transfer's CAN id.
fn data_type(t: &Transfer) -> u32 {
    t.id >> 8 & 0xFFFF
}

/// One reassembled transfer.
#[derive(Debug, PartialEq)]
struct Transfer {
    id: u32,
    transfer_id: u8,
    payload: Vec<u8>,
}

/// The SLCAN lines in `bytes`: commands other than `T` as text, `T` frames reassembled into
/// transfers (checking tail bits, toggles and the CRC of multi-frame ones).
fn parse(bytes: &[u8]) -> (Vec<String>, Vec<Transfer>) {
    let mut commands = Vec::new();
    let mut transfers = Vec::new();
    let mut open: Option<(u32, u8, bool, Vec<u8>)> = None;
    for line in bytes.split(|&b| b == b'\r') {
        if line.first() != Some(&b'T') {
            commands.push(String::from_utf8(line.to_vec()).unwrap());
            continue;
        }
        let text = std::str::from_utf8(line).unwrap();
        let id = u32::from_str_radix(&text[1..9], 16).unwrap();
        let len = text[9..10].parse::<usize>().unwrap();
        assert_eq!(text.len(), 10 + 2 * len, "{text}");
        assert_eq!(text, text.to_ascii_uppercase());
        let data: Vec<u8> = (0..len)
            .map(|i| u8::from_str_radix(&text[10 + 2 * i..12 + 2 * i], 16).unwrap())
            .collect();
        let tail = *data.last().unwrap();
        let (start, end, toggle, tid) = (
            tail & 0x80 != 0,
            tail & 0x40 != 0,
            tail & 0x20 != 0,
            tail & 0x1F,
        );
        let body = &data[..len - 1];
        if start {
            assert!(open.is_none(), "a transfer started inside another");
            assert!(!toggle, "first frame with the toggle set");
            open = Some((id, tid, toggle, body.to_vec()));
        } else {
            let o = open.as_mut().expect("a frame outside a transfer");
            assert_eq!((o.0, o.1), (id, tid));
            assert_ne!(o.2, toggle, "toggle did not alternate");
            assert_eq!(len, if end { len } else { 8 });
            o.2 = toggle;
            o.3.extend_from_slice(body);
        }
        if end {
            let (id, tid, _, mut payload) = open.take().unwrap();
            if !start {
                let signature = match (id >> 8) & 0xFFFF {
                    1034 => Kind::EscStatus.signature(),
                    341 => Kind::NodeStatus.signature(),
                    other => panic!("data type {other}"),
                };
                let crc = u16::from_le_bytes([payload[0], payload[1]]);
                payload.drain(..2);
                assert_eq!(crc, transfer_crc(signature, &payload));
            }
            transfers.push(Transfer {
                id,
                transfer_id: tid,
                payload,
            });
        }
    }
    assert!(open.is_none(), "a transfer left unfinished");
    (commands, transfers)
}

fn open_on(pty: &Pty, node_id: u8) -> DronecanOutput {
    let target = SlcanTarget::parse(&format!("slcan:{}", pty.path())).unwrap();
    DronecanOutput::open(
        target,
        DronecanOptions {
            node_id,
            ..DronecanOptions::default()
        },
    )
    .unwrap()
}

#[test]
fn targets() {
    let t = SlcanTarget::parse("slcan:/dev/ttyACM0").unwrap();
    assert_eq!((t.port.as_str(), t.bitrate), ("/dev/ttyACM0", 1_000_000));
    let t = SlcanTarget::parse("slcan:COM5:500000").unwrap();
    assert_eq!((t.port.as_str(), t.bitrate), ("COM5", 500_000));
    assert_eq!(
        SlcanTarget::parse("slcan:/dev/x:250k").unwrap().bitrate,
        250_000
    );
    assert_eq!(
        SlcanTarget::parse("slcan:/dev/x:1M").unwrap().bitrate,
        1_000_000
    );
    let e = SlcanTarget::parse("slcan:/dev/x:333333")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("333333 bit/s has no SLCAN code") && e.contains("800000"),
        "{e}"
    );
    let e = SlcanTarget::parse("slcan:/dev/x:fast")
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad CAN bitrate \"fast\""), "{e}");
    let e = SlcanTarget::parse("/dev/ttyACM0").unwrap_err().to_string();
    assert!(e.contains("expected slcan:PORT[:BITRATE]"), "{e}");
    assert!(SlcanTarget::parse("slcan:").is_err());
    assert!(matches!(
        DronecanOutput::open(
            SlcanTarget::parse("slcan:/dev/ttyNOSUCH9").unwrap(),
            DronecanOptions::default()
        ),
        Err(OutputError::Open { .. })
    ));
    let pty = Pty::open();
    for node_id in [0, 128] {
        let e = DronecanOutput::open(
            SlcanTarget::parse(&format!("slcan:{}", pty.path())).unwrap(),
            DronecanOptions {
                node_id,
                ..DronecanOptions::default()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("node id"), "{e}");
    }
}

#[test]
fn setup_then_one_transfer_per_esc_frame_and_node_status() {
    let mut pty = Pty::open();
    let mut out = open_on(&pty, 42);
    assert_eq!(out.name(), format!("dronecan slcan:{}:1000000", pty.path()));
    let t0 = Instant::now();
    // ESC 0 twice before a poll (coalesced), ESC 2 once with a fault and a temperature out of
    // the table.
    let f0a = data_frame(1, 1000, 252, 100, 0);
    let f0b = data_frame(2, 1200, 251, 100, 0);
    let f2 = data_frame(7, 3000, 160, 255, 0x0004);
    update(&mut out, 0, &f0a, t0);
    let r0 = update(&mut out, 0, &f0b, t0);
    let r2 = update(&mut out, 2, &f2, t0);
    assert!(r2.mos_temp_c.is_none() && r0.mos_temp_c.is_some());
    out.poll(t0).unwrap();
    let (commands, transfers) = parse(&pty.read_now());
    // The setup: an empty command, close, 1 Mbit/s, open.
    assert_eq!(commands[..4], ["", "C", "S8", "O"]);
    assert!(commands[4..].iter().all(String::is_empty), "{commands:?}");
    // Each ESC's esc.Status then (its first frame) its esc.StatusExtended, then NodeStatus.
    assert_eq!(transfers.len(), 5, "{transfers:?}");
    assert_eq!(transfers[0].id, 0x1004_0A2A);
    assert_eq!(transfers[0].transfer_id, 0);
    assert_eq!(transfers[0].payload, bytes(&expected(&r0, 0)));
    assert_eq!(transfers[1].id, 0x1004_0C2A);
    assert_eq!(transfers[1].transfer_id, 0);
    assert_eq!(transfers[1].payload, bytes(&expected_extended(&r0, &f0b)));
    assert_eq!(transfers[2].transfer_id, 1);
    let s2 = expected(&r2, 1);
    assert!(s2.temperature.is_nan());
    assert_eq!(transfers[2].payload, bytes(&s2));
    let x2 = expected_extended(&r2, &f2);
    assert_eq!((x2.status_flags, x2.input_pct), (0x0004, 59));
    assert_eq!(
        (transfers[3].transfer_id, data_type(&transfers[3])),
        (1, 1036)
    );
    assert_eq!(transfers[3].payload, bytes(&x2));
    let transfers = &transfers[2..];
    // NodeStatus: node 42, its own transfer id, WARNING (ESC 2's fault), ESCs 0 and 2 live.
    assert_eq!(transfers[2].id, 0x1001_552A);
    assert_eq!(transfers[2].transfer_id, 0);
    let node = NodeStatus {
        uptime_sec: 0,
        health: Health::Warning as u8,
        mode: 0,
        sub_mode: 0,
        vendor_specific_status_code: 0b101,
    };
    assert_eq!(transfers[2].payload, bytes(&node));
    let s = out.stats();
    assert_eq!((s.messages, s.superseded, s.errors), (5, 1, 0));
    assert_eq!(s.latency.count(), 2);
    assert_eq!(out.frames(), 9);
    // Nothing new: nothing sent, not even NodeStatus before its second.
    out.poll(t0 + Duration::from_millis(500)).unwrap();
    assert!(parse(&pty.read_now()).1.is_empty());
    // A frame of ESC 2 less than EXTENDED_EVERY after its first: esc.Status alone.
    let f2 = data_frame(8, 2900, 160, 100, 0);
    let r2 = update(&mut out, 2, &f2, t0 + Duration::from_millis(100));
    out.poll(t0 + Duration::from_millis(600)).unwrap();
    let (_, transfers) = parse(&pty.read_now());
    assert_eq!(transfers.len(), 1, "{transfers:?}");
    assert_eq!(transfers[0].payload, bytes(&expected(&r2, 1)));
    // A second later: NodeStatus, uptime 1; ESC 2 is fine now (its esc.StatusExtended due
    // again, with status flags 0) and ESC 0 silent (health WARNING: heard, then silent) and not
    // sent.
    let f2 = data_frame(9, 3000, 160, 100, 0);
    let r2 = update(&mut out, 2, &f2, t0 + Duration::from_millis(900));
    let later = t0 + SILENT_AFTER + Duration::from_millis(10);
    out.poll(later).unwrap();
    let (_, transfers) = parse(&pty.read_now());
    assert_eq!(transfers.len(), 3, "{transfers:?}");
    assert_eq!(transfers[0].payload, bytes(&expected(&r2, 1)));
    assert_eq!(transfers[0].transfer_id, 3);
    assert_eq!(transfers[1].payload, bytes(&expected_extended(&r2, &f2)));
    assert_eq!(transfers[1].transfer_id, 2);
    let transfers = &transfers[1..];
    let node = NodeStatus {
        uptime_sec: 1,
        health: Health::Warning as u8,
        mode: 0,
        sub_mode: 0,
        vendor_specific_status_code: 0b100,
    };
    assert_eq!(transfers[1].payload, bytes(&node));
    assert_eq!(transfers[1].transfer_id, 1);
}

#[test]
fn transfer_ids_wrap_and_stale_or_unnumbered_escs_are_not_sent() {
    let mut pty = Pty::open();
    let mut out = open_on(&pty, 100);
    let t0 = Instant::now();
    let mut tids = Vec::new();
    for i in 0..40u16 {
        update(&mut out, 1, &data_frame(i, 1000 + i, 250, 100, 0), t0);
        out.poll(t0).unwrap();
        let (_, transfers) = parse(&pty.read_now());
        tids.extend(
            transfers
                .iter()
                .filter(|t| data_type(t) == 1034)
                .map(|t| t.transfer_id),
        );
    }
    let want: Vec<u8> = (0..40).map(|i| i % 32).collect();
    assert_eq!(tids, want);
    // A frame older than SILENT_AFTER when polled, and ESC 32 (no esc_index for it).
    update(&mut out, 3, &data_frame(1, 1000, 250, 100, 0), t0);
    update(&mut out, 32, &data_frame(1, 1000, 250, 100, 0), t0);
    out.poll(t0 + SILENT_AFTER).unwrap();
    let (_, transfers) = parse(&pty.read_now());
    assert!(
        transfers.iter().all(|t| data_type(t) == 341),
        "{transfers:?}"
    );
    assert_eq!(out.not_sent(), 2);
    // ESC 32 is told, the stale frame (not a limit) is not.
    let error = hwfoc_bridge::output::left_out(&out).expect("ESC 32 left out");
    assert!(
        error
            .to_string()
            .ends_with(": 1 frames of ESC 32 not sent: it carries ESCs 0 to 31"),
        "{error}"
    );
}

#[test]
fn a_lost_adapter_is_reopened_and_set_up_again() {
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("slcan0");
    let first = Pty::open();
    std::os::unix::fs::symlink(first.path(), &link).unwrap();
    let target = SlcanTarget::parse(&format!("slcan:{}:500k", link.display())).unwrap();
    let mut out = DronecanOutput::open(target, DronecanOptions::default()).unwrap();
    let t0 = Instant::now();
    out.poll(t0).unwrap();
    // Unplugged: the pty's master side goes away.
    drop(first);
    let mut now = t0;
    let mut lost = None;
    for i in 0..50u16 {
        // The kernel hangs the slave up a moment after the master closes.
        thread::sleep(Duration::from_millis(20));
        now += Duration::from_millis(100);
        update(&mut out, 0, &data_frame(i, 1000, 250, 100, 0), now);
        if let Err(e) = out.poll(now) {
            lost = Some(e);
            break;
        }
    }
    let lost = lost.expect("the loss was never noticed");
    assert!(matches!(lost, OutputError::Lost { .. }), "{lost}");
    assert!(lost.to_string().contains("reopening"), "{lost}");
    assert!(!out.connected());
    assert_eq!(out.stats().errors, 1);
    // Gone for a while: polls carry on quietly (no error per failed reopening).
    for _ in 0..5 {
        now += Duration::from_millis(300);
        out.poll(now).unwrap();
    }
    // Plugged in again (a new pty behind the same path).
    let mut second = Pty::open();
    std::fs::remove_file(&link).unwrap();
    std::os::unix::fs::symlink(second.path(), &link).unwrap();
    let mut back = false;
    for i in 0..40u16 {
        now += Duration::from_millis(250);
        update(&mut out, 0, &data_frame(100 + i, 1000, 250, 100, 0), now);
        out.poll(now).unwrap();
        if out.connected() {
            back = true;
            break;
        }
    }
    assert!(back, "never reopened");
    assert_eq!(out.reopens(), 1);
    let (commands, transfers) = parse(&second.read_now());
    assert_eq!(commands[..4], ["", "C", "S6", "O"]);
    // The ESC frame of this poll and a NodeStatus straight away.
    let transfers: Vec<_> = transfers.iter().filter(|t| data_type(t) != 1036).collect();
    assert_eq!(transfers.len(), 2, "{transfers:?}");
    assert_eq!(out.stats().errors, 1);
}

/// Relays between two ptys as an SLCAN adapter would sit between two programs: what the output
/// writes to A goes to B's reader; B's commands (pydronecan setting the adapter up) are
/// answered with `\r` (done) and kept; B's own frames are dropped.
fn relay(a: Pty, b: Pty, stop: Arc<AtomicBool>, b_commands: Arc<Mutex<Vec<String>>>) {
    let (mut a, mut b) = (a, b);
    let mut line = Vec::new();
    let mut buf = [0u8; 4096];
    while !stop.load(Ordering::Relaxed) {
        let mut fds = [
            PollFd::new(a.master.as_fd(), PollFlags::POLLIN),
            PollFd::new(b.master.as_fd(), PollFlags::POLLIN),
        ];
        let _ = poll(&mut fds, PollTimeout::from(20u16));
        let (ra, rb) = (fds[0].revents(), fds[1].revents());
        if ra.is_some_and(|r| r.contains(PollFlags::POLLIN))
            && let Ok(n) = a.master.read(&mut buf)
        {
            let _ = b.master.write_all(&buf[..n]);
        }
        if rb.is_some_and(|r| r.contains(PollFlags::POLLIN))
            && let Ok(n) = b.master.read(&mut buf)
        {
            for &byte in &buf[..n] {
                if byte != b'\r' {
                    line.push(byte);
                    continue;
                }
                if !matches!(line.first(), Some(b'T' | b't')) {
                    b_commands
                        .lock()
                        .unwrap()
                        .push(String::from_utf8_lossy(&line).into_owned());
                    let _ = b.master.write_all(b"\r");
                }
                line.clear();
            }
        }
        if ra.is_none() && rb.is_none() {
            thread::sleep(Duration::from_millis(5));
        }
    }
}

/// pydronecan, the receiver people use, decodes what the output sends: esc.Status,
/// esc.StatusExtended and NodeStatus.
#[test]
#[ignore = "needs a Python with dronecan (HWFOC_DRONECAN_PY or python3): .ci/dronecan.sh runs it"]
fn pydronecan_decodes_esc_status_extended_and_node_status() {
    let python = python::python_with("HWFOC_DRONECAN_PY", "dronecan", ".ci/dronecan.sh");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/py/dronecan_check.py");
    let (a, b) = (Pty::open(), Pty::open());
    let (a_path, b_path) = (a.path().to_string(), b.path().to_string());
    let stop = Arc::new(AtomicBool::new(false));
    let b_commands = Arc::new(Mutex::new(Vec::new()));
    let relay_thread = {
        let (stop, b_commands) = (stop.clone(), b_commands.clone());
        thread::spawn(move || relay(a, b, stop, b_commands))
    };
    let target = SlcanTarget::parse(&format!("slcan:{a_path}:1000000")).unwrap();
    let mut out = DronecanOutput::open(target, DronecanOptions::default()).unwrap();

    const WANT_ESC: usize = 24;
    let mut child = std::process::Command::new(&python)
        .arg(&script)
        .args([&b_path, "1000000", &WANT_ESC.to_string(), "2", "60"])
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("cannot run HWFOC_DRONECAN_PY");
    let (tx, rx) = mpsc::channel();
    let stdout = child.stdout.take().unwrap();
    thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });

    // Until pydronecan has set its adapter up: NodeStatus only (its `\r`s end the driver's
    // waits for acknowledgements too, as a real adapter's would).
    let deadline = Instant::now() + Duration::from_secs(60);
    let mut lines = Vec::new();
    loop {
        assert!(Instant::now() < deadline, "pydronecan never became ready");
        if let Some(status) = child.try_wait().unwrap() {
            panic!("pydronecan's check ended before it was ready ({status}): {lines:?}");
        }
        out.poll(Instant::now()).unwrap();
        match rx.recv_timeout(Duration::from_millis(10)) {
            Ok(line) if line == "READY" => break,
            Ok(line) => lines.push(line),
            Err(_) => {}
        }
    }
    // Rounds of frames of four ESCs until pydronecan has what it wants. Each frame's rpm is
    // unique: a decoded esc.Status is matched to the record it came from by (esc, rpm).
    let mut sent: Vec<(Record, u32, DataFrame)> = Vec::new();
    let mut faults = [0u32; 4];
    let mut round = 0u16;
    let mut done = false;
    while !done {
        assert!(Instant::now() < deadline, "pydronecan did not get enough");
        let now = Instant::now();
        for esc in 0..4u8 {
            let status = if (round + u16::from(esc)).is_multiple_of(5) {
                0x0010
            } else {
                0
            };
            let f = data_frame(
                round,
                2000 + 7 * (round * 4 + u16::from(esc)),
                150 + round + 13 * u16::from(esc),
                if esc == 3 { 0 } else { 60 + esc * 20 },
                status,
            );
            if status != 0 {
                faults[usize::from(esc)] += 1;
            }
            let r = update(&mut out, esc, &f, now);
            sent.push((r, faults[usize::from(esc)], f));
        }
        out.poll(now).unwrap();
        round += 1;
        let until = Instant::now() + Duration::from_millis(50);
        while let Ok(line) = rx.recv_timeout(until.saturating_duration_since(Instant::now())) {
            lines.push(line);
        }
        done = child.try_wait().unwrap().is_some();
    }
    let status = child.wait().unwrap();
    lines.extend(rx.try_iter());
    stop.store(true, Ordering::Relaxed);
    relay_thread.join().unwrap();
    assert!(status.success(), "{status}: {lines:?}");
    // pydronecan set its adapter to 1 Mbit/s like ours.
    assert!(b_commands.lock().unwrap().iter().any(|c| c == "S8"));

    let f16 = |v: f32| -> Option<f64> {
        let h = f16_from_f32(saturate_f16(v));
        let x = f64::from(half_to_f32(h));
        (!x.is_nan()).then_some(x)
    };
    let (mut escs, mut nodes) = (0, 0);
    let mut extended = [0; 4];
    for line in &lines {
        let v: serde_json::Value = serde_json::from_str(line).unwrap_or_else(|_| panic!("{line}"));
        assert_eq!(v["source"], 100, "{line}");
        match v["type"].as_str().unwrap() {
            "esc" => {
                let esc = v["esc_index"].as_u64().unwrap() as u8;
                let rpm = v["rpm"].as_i64().unwrap() as i32;
                let (r, error_count, _) = sent
                    .iter()
                    .find(|(r, _, _)| r.esc == esc && r.rpm.unwrap().round() as i32 == rpm)
                    .unwrap_or_else(|| panic!("decoded but never sent: {line}"));
                let want = expected(r, *error_count);
                assert_eq!(v["error_count"], want.error_count, "{line}");
                assert_eq!(v["power_rating_pct"], want.power_rating_pct, "{line}");
                assert_eq!(v["voltage"].as_f64(), f16(want.voltage), "{line}");
                assert_eq!(v["current"].as_f64(), f16(want.current), "{line}");
                assert_eq!(v["temperature"].as_f64(), f16(want.temperature), "{line}");
                // Within float16 precision of the record itself.
                let close =
                    |got: f64, x: f32| (got - f64::from(x)).abs() <= f64::from(x).abs() / 1024.0;
                assert!(
                    close(v["voltage"].as_f64().unwrap(), r.voltage_v.unwrap()),
                    "{line}"
                );
                assert!(
                    close(v["current"].as_f64().unwrap(), r.current_a.unwrap()),
                    "{line}"
                );
                if esc == 3 {
                    assert!(v["temperature"].is_null(), "{line}");
                }
                escs += 1;
            }
            "ext" => {
                let esc = v["esc_index"].as_u64().unwrap() as u8;
                let decoded = EscStatusExtended {
                    input_pct: v["input_pct"].as_u64().unwrap() as u8,
                    output_pct: v["output_pct"].as_u64().unwrap() as u8,
                    motor_temperature_deg_c: v["motor_temperature_degC"].as_i64().unwrap() as i16,
                    motor_angle: v["motor_angle"].as_u64().unwrap() as u16,
                    status_flags: v["status_flags"].as_u64().unwrap() as u32,
                    esc_index: esc,
                };
                assert!(
                    sent.iter()
                        .any(|(r, _, f)| r.esc == esc && expected_extended(r, f) == decoded),
                    "decoded but never sent: {line}"
                );
                extended[usize::from(esc)] += 1;
            }
            "node" => {
                assert_eq!(v["mode"], 0, "{line}");
                assert!(v["health"] == 0 || v["health"] == 1, "{line}");
                nodes += 1;
            }
            other => panic!("{other}: {line}"),
        }
    }
    assert!(
        escs >= WANT_ESC && nodes >= 2 && extended.iter().all(|&n| n > 0),
        "{escs} esc.Status, {extended:?} esc.StatusExtended, {nodes} NodeStatus"
    );
    eprintln!(
        "pydronecan decoded {escs} esc.Status, {extended:?} esc.StatusExtended and {nodes} \
         NodeStatus ({round} rounds sent)"
    );
}

/// binary16 bits to f32 (the test's own conversion, independent of the output's).
fn half_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = i32::from((h >> 10) & 0x1F);
    let mant = f32::from(h & 0x3FF);
    sign * match exp {
        0 => mant * 2f32.powi(-24),
        31 if mant == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        e => (1.0 + mant / 1024.0) * 2f32.powi(e - 15),
    }
}
