//! `hwfoc bridge --mavlink` as ground stations receive it: ESC_STATUS and ESC_INFO within a
//! second of the first frame (QGroundControl shows its ESC indicator only if they are there when
//! it connects); `file:PATH` telemetry logs (their layout and times, never written over an
//! existing file or an input); and (ignored unless asked for: they need a Python with pymavlink,
//! which `.ci/mavlink.sh` makes) the receiver of the README, `scripts/mavlink-receive.py`, run as
//! it is written on stock pymavlink, live and on a telemetry log, with the values `hwfoc decode`
//! gives for the same recording, and pymavlink's `mavlogdump.py` on a 30-minute flight's log,
//! which `bridge` writes as fast as it can.

#![cfg(unix)]

mod common;
#[path = "../../hwfoc-bridge/tests/py/python.rs"]
mod python;

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::net::UdpSocket;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{Dir, by_esc, hwfoc, ok, records, run};
use serde_json::Value;

const HEARTBEAT: u32 = 0;
const ESC_INFO: u32 = 290;
const ESC_STATUS: u32 = 291;
const ESC_TELEMETRY_1_TO_4: u32 = 11030;

/// The length of the MAVLink 2 frame starting `bytes`.
fn frame_len(bytes: &[u8]) -> usize {
    assert_eq!(bytes[0], 0xFD, "a MAVLink 2 frame");
    let signed = bytes[2] & 1 != 0;
    12 + usize::from(bytes[1]) + if signed { 13 } else { 0 }
}

/// A MAVLink 2 frame's message id.
fn message_id(frame: &[u8]) -> u32 {
    assert_eq!(frame.len(), frame_len(frame), "one whole frame");
    u32::from_le_bytes([frame[7], frame[8], frame[9], 0])
}

/// A telemetry log's messages: each one's time (microseconds since the Unix epoch, 64 bits
/// big-endian) and frame.
fn tlog_messages(bytes: &[u8]) -> Vec<(u64, &[u8])> {
    let mut out = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let time = u64::from_be_bytes(bytes[at..at + 8].try_into().unwrap());
        let frame = &bytes[at + 8..];
        let len = frame_len(frame);
        out.push((time, &frame[..len]));
        at += 8 + len;
    }
    out
}

/// The first time of message `id` after the first ESC_TELEMETRY_1_TO_4 (the first ESC frame
/// bridged), in seconds.
fn after_first_frame<T: Copy>(messages: &[(T, u32)], id: u32, secs: impl Fn(T, T) -> f64) -> f64 {
    let first = messages
        .iter()
        .find(|(_, i)| *i == ESC_TELEMETRY_1_TO_4)
        .expect("an ESC_TELEMETRY_1_TO_4")
        .0;
    let at = messages
        .iter()
        .find(|(_, i)| *i == id)
        .unwrap_or_else(|| panic!("no message {id}"))
        .0;
    secs(at, first)
}

/// A recording of `escs` virtual ESCs over `seconds`, and its records as `hwfoc decode` gives
/// them.
fn recording(dir: &Dir, escs: u32, seconds: u32) -> (PathBuf, Vec<Value>) {
    let path = dir.path("run.pcapng");
    ok(run(hwfoc()
        .args(["simulate", "--escs", &escs.to_string()])
        .args(["--duration", &seconds.to_string(), "--lead-in", "0.5"])
        .args(["--profile", "sine", "--no-config", "-o"])
        .arg(&path)));
    let decoded = ok(run(hwfoc().args(["decode", "--no-config"]).arg(&path)));
    (path, records(&String::from_utf8(decoded.stdout).unwrap()))
}

/// QGroundControl shows its ESC indicator only when ESC_INFO and ESC_STATUS are there as it
/// connects: both come within a second of the first ESC frame, and ESC_INFO at least every
/// second after.
#[test]
fn esc_status_and_esc_info_within_a_second_of_the_first_frame() {
    let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
    socket
        .set_read_timeout(Some(Duration::from_millis(100)))
        .unwrap();
    let port = socket.local_addr().unwrap().port();
    let mut bridge = hwfoc()
        .args(["bridge", "--sim", "2", "--duration", "3", "--no-config"])
        .args(["--mavlink", &format!("udp:127.0.0.1:{port}")])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    let mut messages = Vec::new();
    let mut buf = [0u8; 512];
    while started.elapsed() < Duration::from_secs(20) {
        match socket.recv(&mut buf) {
            Ok(n) => messages.push((Instant::now(), message_id(&buf[..n]))),
            Err(_) if bridge.try_wait().unwrap().is_some() => break,
            Err(_) => {}
        }
    }
    let status = bridge.wait().unwrap();
    assert!(status.success(), "{status}");
    let secs = |a: Instant, b: Instant| a.saturating_duration_since(b).as_secs_f64();
    for id in [ESC_STATUS, ESC_INFO] {
        let after = after_first_frame(&messages, id, secs);
        assert!(after < 1.0, "message {id} {after} s after the first frame");
    }
    let infos: Vec<Instant> = messages
        .iter()
        .filter(|(_, id)| *id == ESC_INFO)
        .map(|(t, _)| *t)
        .collect();
    assert!(infos.len() >= 2, "{infos:?}");
    for w in infos.windows(2) {
        assert!(
            secs(w[1], w[0]) < 1.2,
            "ESC_INFO {} s apart",
            secs(w[1], w[0])
        );
    }
}

/// `--mavlink file:PATH`: a telemetry log, each message after its time, the recording's own
/// (Unix) times; ESC_STATUS's `time_usec` is its message's time. An existing file is never
/// written over unless `--overwrite`, and never an input.
#[test]
fn a_telemetry_log_has_the_recordings_times_and_never_overwrites() {
    let dir = Dir::new();
    let (rec, decoded) = recording(&dir, 2, 2);
    let tlog = dir.path("run.tlog");
    let spec = format!("file:{}", tlog.display());
    ok(run(hwfoc()
        .args(["bridge", "--no-config"])
        .arg(&rec)
        .args(["--mavlink", &spec])));
    let bytes = std::fs::read(&tlog).unwrap();
    let messages = tlog_messages(&bytes);
    let ids: Vec<(u64, u32)> = messages.iter().map(|(t, f)| (*t, message_id(f))).collect();
    for id in [HEARTBEAT, ESC_TELEMETRY_1_TO_4, ESC_STATUS, ESC_INFO] {
        assert!(ids.iter().any(|(_, i)| *i == id), "no message {id}");
    }
    // The recording's times: from its first frame to a second after its last.
    let t = |r: &Value| r["t_s"].as_f64().unwrap();
    let (first, last) = (t(&decoded[0]), t(decoded.last().unwrap()));
    assert!(first > 1.6e9, "a recording with Unix times: {first}");
    for w in ids.windows(2) {
        assert!(w[0].0 <= w[1].0, "times in order: {w:?}");
    }
    let secs = |usec: u64| usec as f64 / 1e6;
    let (t0, t1) = (secs(ids[0].0), secs(ids.last().unwrap().0));
    assert!(
        // Times in whole microseconds: the last message may be at the last frame's time,
        // rounded down.
        (first - 0.01..first + 0.5).contains(&t0) && (last - 1e-6..last + 1.0).contains(&t1),
        "log {t0}..{t1}, recording {first}..{last}"
    );
    for (time, frame) in &messages {
        if message_id(frame) == ESC_STATUS {
            // time_usec: the first field of the payload (MAVLink orders fields by size).
            let time_usec = u64::from_le_bytes(frame[10..18].try_into().unwrap());
            assert_eq!(time_usec, *time);
        }
    }
    for id in [ESC_STATUS, ESC_INFO] {
        let after = after_first_frame(&ids, id, |a, b| secs(a) - secs(b));
        assert!((0.0..1.0).contains(&after), "message {id} {after} s after");
    }

    // Never over an existing file, unasked; never over an input.
    let again = run(hwfoc()
        .args(["bridge", "--no-config"])
        .arg(&rec)
        .args(["--mavlink", &spec]));
    common::assert_fails_with(&again, "exists");
    assert_eq!(std::fs::read(&tlog).unwrap(), bytes);
    let recorded = std::fs::read(&rec).unwrap();
    let onto_input = run(hwfoc()
        .args(["bridge", "--no-config"])
        .arg(&rec)
        .args(["--mavlink", &format!("file:{}", rec.display())]));
    common::assert_fails_with(&onto_input, "it is the input");
    let onto_input = run(hwfoc()
        .args(["bridge", "--no-config", "--overwrite"])
        .arg(&rec)
        .args(["--mavlink", &format!("file:{}", rec.display())]));
    common::assert_fails_with(&onto_input, "it is the input");
    assert_eq!(std::fs::read(&rec).unwrap(), recorded);
    // Asked: replaced (by half a second of the recording, paced: another file than the
    // whole one written as fast as it can be).
    ok(run(hwfoc()
        .args([
            "bridge",
            "--no-config",
            "--overwrite",
            "--realtime",
            "--duration",
            "0.5",
        ])
        .arg(&rec)
        .args(["--mavlink", &spec])));
    assert_ne!(std::fs::read(&tlog).unwrap(), bytes);
}

/// Five ESCs: every ESC message, both groups of ESC_TELEMETRY, was received.
fn assert_every_esc_message(counts: &BTreeMap<String, usize>) {
    for kind in [
        "ESC_TELEMETRY_1_TO_4",
        "ESC_TELEMETRY_5_TO_8",
        "ESC_STATUS",
        "ESC_INFO",
    ] {
        assert!(counts.contains_key(kind), "no {kind}: {counts:?}");
    }
}

/// The receiver of the README, as it is written, on the Python that has pymavlink.
fn receiver(python: &str) -> Command {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/mavlink-receive.py");
    let mut cmd = Command::new(python);
    cmd.arg(script);
    cmd
}

/// A recording bridged into a telemetry log, read back by the README's receiver (stock
/// pymavlink, `mavutil.mavlink_connection("x.tlog")`): every ESC message decoded, with the
/// values `hwfoc decode` gives for the recording and the recording's times.
#[test]
#[ignore = "needs a Python with pymavlink (HWFOC_PYMAVLINK or python3): .ci/mavlink.sh runs it"]
fn the_receiver_reads_a_telemetry_log_with_decodes_values_and_times() {
    let python = python::python_with("HWFOC_PYMAVLINK", "pymavlink", ".ci/mavlink.sh");
    let dir = Dir::new();
    let (rec, decoded) = recording(&dir, 5, 3);
    let per_esc = by_esc(&decoded);
    let tlog = dir.path("flight.tlog");
    ok(run(hwfoc()
        .args(["bridge", "--no-config"])
        .arg(&rec)
        .args(["--mavlink", &format!("file:{}", tlog.display())])));
    let out = ok(run(receiver(&python).arg(&tlog)));
    let lines = records(&String::from_utf8(out.stdout).unwrap());

    // Every ESC message of the log, decoded.
    let in_log = tlog_messages(&std::fs::read(&tlog).unwrap())
        .iter()
        .filter(|(_, f)| message_id(f) != HEARTBEAT)
        .count();
    assert_eq!(lines.len(), in_log, "every ESC message of the log");

    let mut counts = BTreeMap::<String, usize>::new();
    let mut values = 0;
    let mut escs_heard = 0;
    for m in &lines {
        let kind = m["type"].as_str().unwrap().to_string();
        let time = m["time"].as_f64().unwrap();
        assert_eq!(
            (m["sysid"].as_u64(), m["compid"].as_u64()),
            (Some(1), Some(158))
        );
        match kind.as_str() {
            "ESC_TELEMETRY_1_TO_4" | "ESC_TELEMETRY_5_TO_8" => {
                let mut newest = 0.0f64;
                for record in telemetry_records(&kind, m, &per_esc) {
                    let t_s = record["t_s"].as_f64().unwrap();
                    // A log's times are whole microseconds: at most half of one before the frame.
                    assert!((-1e-6..1.0).contains(&(time - t_s)), "{m} vs {record}");
                    newest = newest.max(t_s);
                    values += 1;
                }
                // Sent as the newest frame it carries was handed on: at that frame's time.
                assert!(time - newest < 0.05, "{m}: {time} for a frame of {newest}");
            }
            "ESC_STATUS" | "ESC_INFO" => {
                let time_usec = m["time_usec"].as_f64().unwrap();
                assert!((time_usec / 1e6 - time).abs() < 1e-5, "{m}");
                if kind == "ESC_INFO" {
                    // The ESCs heard so far: all five once each has sent a frame.
                    let count = m["count"].as_u64().unwrap();
                    assert!((1..=5).contains(&count), "{m}");
                    escs_heard = escs_heard.max(count);
                    assert_ne!(m["info"], 0, "{m}");
                }
            }
            other => panic!("unexpected {other}: {m}"),
        }
        *counts.entry(kind).or_default() += 1;
    }
    assert_eq!(escs_heard, 5);
    let frames: usize = per_esc.values().map(Vec::len).sum();
    assert!(
        values >= frames * 9 / 10,
        "{values} ESC values in ESC_TELEMETRY for {frames} frames"
    );
    assert_every_esc_message(&counts);
    eprintln!("the receiver read from the telemetry log: {counts:?}");
}

/// The README's receiver, as written, decodes the bridge live over UDP: ESC_TELEMETRY, and
/// ESC_STATUS and ESC_INFO (which stock pymavlink alone shows as UNKNOWN_291 and UNKNOWN_290).
#[test]
#[ignore = "needs a Python with pymavlink (HWFOC_PYMAVLINK or python3): .ci/mavlink.sh runs it"]
fn the_receiver_decodes_the_bridge_live() {
    let python = python::python_with("HWFOC_PYMAVLINK", "pymavlink", ".ci/mavlink.sh");
    // A free port for the receiver.
    let port = UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let mut receiver = receiver(&python)
        .arg(format!("udpin:127.0.0.1:{port}"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(receiver.stderr.take().unwrap());
    let mut line = String::new();
    err.read_line(&mut line).unwrap();
    assert!(line.starts_with("receiving from udpin:"), "{line}");
    ok(run(hwfoc()
        .args(["bridge", "--sim", "5", "--duration", "2", "--no-config"])
        .args(["--mavlink", &format!("udp:127.0.0.1:{port}")])));
    std::thread::sleep(Duration::from_millis(500));
    nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(receiver.id() as i32),
        nix::sys::signal::Signal::SIGINT,
    )
    .unwrap();
    let out = receiver.wait_with_output().unwrap();
    assert!(out.status.success(), "{}", out.status);
    let lines = records(&String::from_utf8(out.stdout).unwrap());
    let mut counts = BTreeMap::<String, usize>::new();
    let mut escs_heard = 0;
    for m in &lines {
        let kind = m["type"].as_str().unwrap();
        if kind == "ESC_STATUS" {
            let rpm = m["rpm"].as_array().unwrap();
            assert_eq!(rpm.len(), 4, "{m}");
        }
        if kind == "ESC_INFO" {
            escs_heard = escs_heard.max(m["count"].as_u64().unwrap());
        }
        *counts.entry(kind.to_string()).or_default() += 1;
    }
    assert_every_esc_message(&counts);
    assert_eq!(escs_heard, 5, "ESC_INFO.count");
    eprintln!("the receiver decoded live: {counts:?}");
}

/// The MAVLink fields of ESC_TELEMETRY that carry a record's values, in the message's units.
fn telemetry_of(record: &Value) -> (u64, u64, u64) {
    let cv = (record["voltage_v"].as_f64().unwrap() * 100.0).round() as u64;
    let ca = (record["current_a"].as_f64().unwrap().max(0.0) * 100.0).round() as u64;
    let rpm = record["rpm"].as_f64().unwrap().round() as u64;
    (cv, ca, rpm)
}

/// The records an ESC_TELEMETRY_1_TO_4 or _5_TO_8 (`fields`, as pymavlink decodes them)
/// carries, checked: each ESC's `count`-th record, with its voltage, current and rpm in the
/// message's units.
fn telemetry_records<'a>(
    kind: &str,
    fields: &Value,
    per_esc: &'a BTreeMap<u64, Vec<Value>>,
) -> Vec<&'a Value> {
    let first = if kind == "ESC_TELEMETRY_1_TO_4" { 0 } else { 4 };
    let mut carried = Vec::new();
    for i in 0..4 {
        let count = fields["count"][i].as_u64().unwrap();
        let esc = (first + i) as u64;
        if count == 0 || !per_esc.contains_key(&esc) {
            continue;
        }
        // `count` frames of this ESC had been bridged: the message carries the count-th.
        let record = &per_esc[&esc][count as usize - 1];
        let (cv, ca, rpm) = telemetry_of(record);
        let m = fields;
        assert_eq!(m["voltage"][i].as_u64().unwrap(), cv, "{m} vs {record}");
        assert_eq!(m["current"][i].as_u64().unwrap(), ca, "{m} vs {record}");
        assert_eq!(m["rpm"][i].as_u64().unwrap(), rpm, "{m} vs {record}");
        carried.push(record);
    }
    carried
}

/// A recording replayed to UDP, decoded by pymavlink (tests/py/mavlink_check.py of
/// hwfoc-bridge) with the values `hwfoc decode` gives; the bridge converts each ESC under its
/// own settings of the configuration file, as `decode` does (ESC 2's motor has 14 pole pairs
/// and its current another scale).
#[test]
#[ignore = "needs a Python with pymavlink (HWFOC_PYMAVLINK or python3): .ci/mavlink.sh runs it"]
fn pymavlink_reads_a_replayed_recording_with_the_values_decode_gives() {
    let python = python::python_with("HWFOC_PYMAVLINK", "pymavlink", ".ci/mavlink.sh");
    let dir = Dir::new();
    let recording = dir.path("run.pcapng");
    ok(run(hwfoc()
        .args([
            "simulate",
            "--escs",
            "5",
            "--duration",
            "4",
            "--lead-in",
            "0.5",
        ])
        .args(["--profile", "sine", "--no-config", "-o"])
        .arg(&recording)));
    let config = dir.path("config.toml");
    std::fs::write(&config, "[esc.2]\npole_pairs = 14\ncurrent_scale = 100\n").unwrap();
    let decoded = records(
        &String::from_utf8(
            ok(run(hwfoc()
                .arg("decode")
                .arg("--config")
                .arg(&config)
                .arg(&recording)))
            .stdout,
        )
        .unwrap(),
    );
    let per_esc = by_esc(&decoded);
    // ESC 2's records are under its own settings (half the rpm of the same erpm at 7 pairs).
    let turning = per_esc[&2]
        .iter()
        .find(|r| r["erpm"].as_f64().unwrap() > 0.0);
    let r = turning.expect("ESC 2 turns");
    let (rpm, erpm) = (r["rpm"].as_f64().unwrap(), r["erpm"].as_f64().unwrap());
    assert!((rpm - erpm / 14.0).abs() < 1e-3 * erpm, "{r}");

    let xml = Path::new(env!("CARGO_MANIFEST_DIR")).join("../hwfoc-bridge/tests/mavlink-xml");
    let script =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../hwfoc-bridge/tests/py/mavlink_check.py");
    let mut receiver = Command::new(python)
        .arg(script)
        .arg(xml)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("start the pymavlink receiver");
    let mut lines = BufReader::new(receiver.stdout.take().unwrap()).lines();
    let ready = lines.next().unwrap().unwrap();
    let port = ready
        .strip_prefix("READY ")
        .expect("READY line")
        .trim()
        .to_string();

    let bridge = run(hwfoc()
        .arg("bridge")
        .arg("--config")
        .arg(&config)
        .arg(&recording)
        .args(["--mavlink", &format!("udp:127.0.0.1:{port}")]));
    assert!(
        bridge.status.success(),
        "{}",
        String::from_utf8_lossy(&bridge.stderr)
    );
    drop(receiver.stdin.take());
    let messages: Vec<Value> = lines
        .map(|l| serde_json::from_str(&l.unwrap()).unwrap())
        .collect();
    receiver.wait().unwrap();

    let mut telemetry = 0;
    for m in &messages {
        assert!(m.get("error").is_none(), "{m}");
        let kind = m["name"].as_str().unwrap();
        if kind.starts_with("ESC_TELEMETRY_") {
            telemetry += telemetry_records(kind, &m["fields"], &per_esc).len();
        }
    }
    let frames: usize = per_esc.values().map(Vec::len).sum();
    assert!(
        telemetry >= frames * 9 / 10,
        "{telemetry} ESC values in ESC_TELEMETRY for {frames} frames"
    );
    for name in ["HEARTBEAT", "ESC_STATUS", "ESC_INFO"] {
        assert!(messages.iter().any(|m| m["name"] == name), "no {name}");
    }
}

/// A 30-minute recording of two ESCs, and the tlog `bridge --mavlink file:` makes of it, with
/// the time it took.
fn half_hour_tlog(dir: &Dir) -> (PathBuf, PathBuf, Duration) {
    let rec = dir.path("flight.pcapng");
    ok(run(hwfoc()
        .args([
            "simulate",
            "--escs",
            "2",
            "--duration",
            "1800",
            "--quiet",
            "--no-config",
        ])
        .arg("-o")
        .arg(&rec)));
    let tlog = dir.path("flight.tlog");
    let start = Instant::now();
    ok(run(hwfoc()
        .args(["bridge", "--no-config", "--quiet"])
        .arg(&rec)
        .args(["--mavlink", &format!("file:{}", tlog.display())])));
    (rec, tlog, start.elapsed())
}

/// `bridge` to a file runs as fast as it can, with the recording's own times: a 30-minute
/// flight becomes a tlog spanning its 30 minutes in seconds; `--realtime` paces it.
#[test]
fn a_telemetry_log_is_written_as_fast_as_it_can_be() {
    let dir = Dir::new();
    let (rec, tlog, took) = half_hour_tlog(&dir);
    assert!(took < Duration::from_secs(120), "took {took:?}");
    let bytes = std::fs::read(&tlog).unwrap();
    let messages = tlog_messages(&bytes);
    let secs = |usec: u64| usec as f64 / 1e6;
    let span = secs(messages.last().unwrap().0) - secs(messages[0].0);
    assert!((1799.0..1801.5).contains(&span), "the log spans {span} s");
    // As often as in real time: ESC_STATUS at least once a second of the flight.
    let status = messages
        .iter()
        .filter(|(_, f)| message_id(f) == ESC_STATUS)
        .count();
    assert!(status >= 1790, "{status} ESC_STATUS messages");

    let paced = dir.path("paced.tlog");
    let start = Instant::now();
    ok(run(hwfoc()
        .args([
            "bridge",
            "--no-config",
            "--quiet",
            "--realtime",
            "--duration",
            "2",
        ])
        .arg(&rec)
        .args(["--mavlink", &format!("file:{}", paced.display())])));
    assert!(start.elapsed() >= Duration::from_millis(1900));
    let bytes = std::fs::read(&paced).unwrap();
    let messages = tlog_messages(&bytes);
    let span = secs(messages.last().unwrap().0) - secs(messages[0].0);
    assert!(span < 3.0, "a paced replay of 2 s spans {span} s");
}

/// The 30-minute tlog read by pymavlink's own `mavlogdump.py`: every message of it, the ESC
/// messages among them, in order of time.
#[test]
#[ignore = "needs a Python with pymavlink (HWFOC_PYMAVLINK or python3): .ci/mavlink.sh runs it"]
fn mavlogdump_reads_a_half_hour_telemetry_log() {
    let python = python::python_with("HWFOC_PYMAVLINK", "pymavlink", ".ci/mavlink.sh");
    let dir = Dir::new();
    let (_, tlog, took) = half_hour_tlog(&dir);
    eprintln!("a 30-minute recording to a tlog: {took:?}");
    // pymavlink's mavlogdump.py, as installed with it (`mavlogdump.py` in the environment's bin).
    let out = ok(run(Command::new(&python)
        .args(["-m", "pymavlink.tools.mavlogdump", "--format", "json"])
        .arg(&tlog)));
    let lines = records(&String::from_utf8(out.stdout).unwrap());
    let in_log = tlog_messages(&std::fs::read(&tlog).unwrap()).len();
    assert_eq!(lines.len(), in_log, "mavlogdump read every message");
    let mut counts = BTreeMap::<String, usize>::new();
    let mut last = 0.0;
    for m in &lines {
        let kind = m["meta"]["type"].as_str().unwrap().to_string();
        let t = m["meta"]["timestamp"].as_f64().unwrap();
        assert!(t >= last, "in order of time: {t} after {last}");
        last = t;
        *counts.entry(kind).or_default() += 1;
    }
    eprintln!("mavlogdump: {counts:?}");
    // ESC_STATUS (291) and ESC_INFO (290) are in no dialect bundled with pymavlink: it reads
    // them as UNKNOWN_291 and UNKNOWN_290 (scripts/mavlink-receive.py adds them).
    for kind in [
        "ESC_TELEMETRY_1_TO_4",
        "UNKNOWN_291",
        "UNKNOWN_290",
        "HEARTBEAT",
    ] {
        assert!(
            counts.get(kind).is_some_and(|&n| n >= 1790),
            "{kind}: {counts:?}"
        );
    }
}

/// `scripts/mavlink-receive.py --help` prints its help (on any Python, pymavlink or not),
/// rather than taking `--help` for a connection to open.
#[test]
#[ignore = "needs python3: .ci/mavlink.sh runs it"]
fn the_receiver_prints_its_help() {
    let found = Command::new("python3")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    common::need(found, "python3 (the MAVLink receiver's help)");
    for arg in ["--help", "-h"] {
        let out = ok(run(receiver("python3").arg(arg)));
        let help = String::from_utf8(out.stdout).unwrap();
        assert!(help.starts_with("usage: "), "{help}");
        assert!(
            help.contains("flight.tlog") && help.contains("SOURCE"),
            "{help}"
        );
    }
}
