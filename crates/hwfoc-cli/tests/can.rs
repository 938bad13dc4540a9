//! DroneCAN ESC telemetry read from CAN inputs, end to end through the `hwfoc` binary.
//!
//! - pydronecan (PyPI `dronecan`, an implementation hwfoc did not write) is the oracle:
//!   `tests/py/can_frames.py` encodes a bus of Hobbywing and standard DroneCAN ESCs and says
//!   which records docs/RECORD-SCHEMA.md makes of it; hwfoc's records of its candump log, and
//!   of its SLCAN lines on a pseudo-terminal (`slcan:PTY`), are compared field by field
//!   (ignored unless asked: they need a Python with `dronecan`, `HWFOC_DRONECAN_PY` or
//!   `python3`; `.ci/dronecan.sh` makes one and runs them).
//! - Golden outputs of the committed log of that bus (`testdata/dronecan/can-bus.log`).
//! - Bad input: broken transfers, frames that are not DroneCAN, error frames, CAN FD lines and
//!   garbage in a candump log; a CAN pcapng cut in the middle of a block. Counted or named in
//!   one line, never a panic.

mod common;

#[path = "../../hwfoc-bridge/tests/py/python.rs"]
mod python;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::Duration;

use common::{Dir, assert_fails_with, check_golden, hwfoc, ok, records, stdout};
use hwfoc::dronecan::{
    CanFrame, EscStatus, GetEscId, Message, SOCKETCAN_ERR_FLAG, StatusMsg1, StatusMsg2,
};
use serde_json::Value;

const SCRIPT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/py/can_frames.py");

/// The committed candump log of pydronecan's bus (`testdata/dronecan/README.md`).
fn bus_log() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testdata/dronecan/can-bus.log")
}

/// The committed CAN capture of pydronecan's frames.
fn frames_pcapng() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testdata/dronecan/pydronecan-frames.pcapng")
}

fn run(args: &[&str]) -> Output {
    hwfoc().args(args).output().expect("run hwfoc")
}

fn python() -> String {
    python::python_with("HWFOC_DRONECAN_PY", "dronecan", ".ci/dronecan.sh")
}

/// How closely an age must match: exactly for a file; on a live bus, within the scheduling of
/// the script's writes and of hwfoc's reader.
#[derive(Clone, Copy)]
enum Ages {
    Exact,
    Within(u64),
}

/// Compares hwfoc's records with the script's, every column: floats as their f32 value,
/// `t_s` to the microsecond (null in `expected`: only present), ages as `ages` says. Returns
/// the number of values compared.
fn compare(got: &[Value], expected: &[Value], ages: Ages) -> usize {
    assert_eq!(
        got.len(),
        expected.len(),
        "records: hwfoc made {}, pydronecan's bus makes {}",
        got.len(),
        expected.len()
    );
    let mut compared = 0;
    for (i, (g, e)) in got.iter().zip(expected).enumerate() {
        let (g, e) = (g.as_object().unwrap(), e.as_object().unwrap());
        assert_eq!(
            g.keys().collect::<Vec<_>>(),
            e.keys().collect::<Vec<_>>(),
            "record {i}: the schema's columns"
        );
        for (key, want) in e {
            let have = &g[key];
            let same = match (key.as_str(), want, have) {
                ("t_s", Value::Null, h) => h.is_f64(),
                ("t_s", w, h) => {
                    (w.as_f64().unwrap() - h.as_f64().unwrap_or(f64::NAN)).abs() < 1e-6
                }
                ("msg2_age_ms" | "msg3_age_ms", Value::Number(w), Value::Number(h)) => {
                    let (w, h) = (w.as_u64().unwrap(), h.as_u64().unwrap());
                    match ages {
                        Ages::Exact => w == h,
                        Ages::Within(ms) => w.abs_diff(h) <= ms,
                    }
                }
                (_, Value::Number(w), Value::Number(h)) if w.is_f64() || h.is_f64() => {
                    w.as_f64().unwrap() as f32 == h.as_f64().unwrap() as f32
                }
                _ => want == have,
            };
            assert!(
                same,
                "record {i} ({} of node {}): {key} is {have}, pydronecan's values make {want}\n\
                 hwfoc: {g:?}\nexpected: {e:?}",
                e["protocol"], e["node"]
            );
            compared += 1;
        }
    }
    compared
}

/// Runs the script with `args`; its expected records.
fn script(python: &str, args: &[&str], expected: &Path, stdout: Stdio) -> std::process::Child {
    Command::new(python)
        .arg(SCRIPT)
        .args(args)
        .arg(expected)
        .stdout(stdout)
        .stderr(Stdio::inherit())
        .spawn()
        .expect("cannot run HWFOC_DRONECAN_PY")
}

fn expected_records(path: &Path) -> Vec<Value> {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// pydronecan's frames of every message above, as a candump log: hwfoc decodes them to exactly
/// the values pydronecan encoded, numbered as the schema says (the throttle channel minus 1 a
/// GetEscID answer maps the node to, for the whole file; node id for a node never mapped; a
/// standard ESC's esc_index), with the ages of
/// the slower messages the script's own times give.
#[test]
#[ignore = "needs pydronecan (HWFOC_DRONECAN_PY, or python3 with the dronecan package; .ci/dronecan.sh)"]
fn pydronecan_candump_log_decodes_to_the_values_encoded() {
    let python = python();
    let dir = Dir::new();
    let (log, expected) = (dir.path("bus.log"), dir.path("expected.json"));
    let log_arg = log.to_str().unwrap();
    let status = script(&python, &["log", log_arg], &expected, Stdio::null())
        .wait()
        .unwrap();
    assert!(status.success(), "{SCRIPT} failed");
    let expected = expected_records(&expected);
    let got = records(&stdout(&run(&["decode", log_arg])));
    let n = compare(&got, &expected, Ages::Exact);
    // Both protocols, nodes 11 and 12 numbered by the channel they answer for the whole file, a
    // NaN read as null.
    let escs: std::collections::BTreeSet<(u64, u64)> = got
        .iter()
        .map(|r| (r["esc"].as_u64().unwrap(), r["node"].as_u64().unwrap()))
        .collect();
    assert_eq!(
        escs.into_iter().collect::<Vec<_>>(),
        [(0, 11), (1, 12), (3, 40), (4, 41), (13, 13)]
    );
    assert!(
        got.iter()
            .any(|r| r["protocol"] == "dronecan" && r["voltage_v"].is_null())
    );
    println!(
        "pydronecan candump log: {} records, {n} values compared",
        got.len()
    );
}

/// The same bus as SLCAN lines written by the script on a pseudo-terminal in real time, read
/// live by `hwfoc decode slcan:PTY`: the same records, values and numbering; the ages within
/// 80 ms of the script's (receive times are hwfoc's; the margin is for a loaded machine).
#[cfg(unix)]
#[test]
#[ignore = "needs pydronecan (HWFOC_DRONECAN_PY, or python3 with the dronecan package; .ci/dronecan.sh)"]
fn pydronecan_slcan_lines_on_a_pty_decode_live() {
    use nix::sys::signal::{Signal, kill};
    use nix::unistd::Pid;

    let python = python();
    let dir = Dir::new();
    let expected = dir.path("expected.json");
    let pty = common::pty();
    let port = format!("slcan:{}", pty.path.display());
    let before = common::unix_now();
    let child = hwfoc()
        .args(["decode", &port])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Time to open the adapter and set it up (what hwfoc writes to it is not read back: the
    // pseudo-terminal's buffer holds it).
    std::thread::sleep(Duration::from_millis(700));
    let master = pty.master.try_clone().unwrap();
    let status = script(&python, &["slcan"], &expected, Stdio::from(master))
        .wait()
        .unwrap();
    assert!(status.success(), "{SCRIPT} failed");
    std::thread::sleep(Duration::from_millis(400));
    kill(Pid::from_raw(child.id() as i32), Signal::SIGINT).unwrap();
    let out = child.wait_with_output().unwrap();
    let after = common::unix_now();
    // A live bus holds a node's records until its GetEscID answer places it (up to 1 s), so
    // they come out later than the file's order: compare node by node, each node's records in
    // the order it sent them.
    let by_node = |mut records: Vec<Value>| {
        records.sort_by_key(|r| r["node"].as_u64());
        records
    };
    let got = by_node(records(&stdout(&out)));
    let n = compare(
        &got,
        &by_node(expected_records(&expected)),
        Ages::Within(80),
    );
    for r in &got {
        let t = r["t_s"].as_f64().unwrap();
        assert!(t >= before && t <= after, "t_s {t} is no receive time");
    }
    println!(
        "pydronecan SLCAN on a pty: {} records, {n} values compared",
        got.len()
    );
}

/// The committed log of pydronecan's bus, decoded and summarised as the golden files hold them
/// (`UPDATE_GOLDEN=1` rewrites them).
#[test]
fn can_bus_log_decodes_and_summarises_as_the_golden_files() {
    let log = bus_log();
    let path = log.to_str().unwrap();
    let jsonl = stdout(&run(&["decode", path]));
    let got = records(&jsonl);
    assert_eq!(got.len(), 58);
    check_golden("can-bus.jsonl", &jsonl);
    let out = stdout(&run(&["summary", "--json", path]));
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["inputs"][0]["format"], "candump");
    let escs = v["escs"].as_array().unwrap();
    let esc = |n: u64| escs.iter().find(|e| e["esc"] == n).unwrap();
    assert_eq!(esc(0)["protocol"], "hw-can");
    assert_eq!(esc(3)["protocol"], "dronecan");
    assert_eq!(esc(0)["link"]["can"]["node"], 11);
    assert_eq!(esc(0)["link"]["can"]["unknown_types"], 1);
    // The transfer whose CRC failed is the link's checksum failure, named once.
    assert_eq!(esc(4)["link"]["checksum_failures"], 1);
    assert_eq!(esc(4)["link"]["can"]["crc_errors"], Value::Null);
    assert_eq!(esc(4)["frames"], 9);
    let portable = out.replace(
        &serde_json::to_string(path).unwrap(),
        "\"testdata/dronecan/can-bus.log\"",
    );
    check_golden("can-bus.summary.json", &portable);
}

/// A candump log line of `frame` at `t` seconds.
fn line(t: f64, frame: &CanFrame) -> String {
    let us = (t * 1e6).round() as u64;
    format!("({}.{:06}) can0 {frame}\n", us / 1_000_000, us % 1_000_000)
}

/// The frames of `m` from `node` with transfer id `tid`.
fn frames(m: impl Into<Message>, node: u8, tid: u8) -> Vec<CanFrame> {
    m.into().frames(16, node, 0, tid).collect()
}

fn status(index: u8, rpm: i32) -> EscStatus {
    EscStatus {
        error_count: 0,
        voltage: 24.0,
        current: -2.5,
        temperature: 300.0,
        rpm,
        power_rating_pct: 10,
        esc_index: index,
    }
}

const M1: StatusMsg1 = StatusMsg1 {
    rpm: 1000,
    pwm: 300,
    status: 0,
};

/// A log of a Hobbywing ESC (node 5) and a standard one (node 9, esc_index 1) whose transfers
/// are broken every way a bus breaks them, among frames that are not DroneCAN, error frames
/// (a bus at the wrong bit rate), CAN FD frames, and lines candump writes otherwise (`.`
/// between bytes, a trailing direction).
fn bad_bus_log() -> String {
    let mut t = 1_700_000_100.0;
    let mut out = String::new();
    let mut put = |out: &mut String, f: &CanFrame| {
        t += 0.001;
        out.push_str(&line(t, f));
    };
    for f in frames(M1, 5, 0) {
        put(&mut out, &f);
    }
    for f in frames(status(1, 500), 9, 0) {
        put(&mut out, &f);
    }
    // Cut short: tid 1's first two frames, then tid 2 whole.
    for f in &frames(status(1, 600), 9, 1)[..2] {
        put(&mut out, f);
    }
    for f in frames(status(1, 700), 9, 2) {
        put(&mut out, &f);
    }
    // A wrong toggle: tid 3 without its middle frame.
    let three = frames(status(1, 800), 9, 3);
    put(&mut out, &three[0]);
    put(&mut out, &three[2]);
    // A CRC error: tid 4's first byte changed.
    let four = frames(status(1, 900), 9, 4);
    let mut first = four[0].data().to_vec();
    first[0] ^= 0xFF;
    put(&mut out, &CanFrame::extended(four[0].id(), &first).unwrap());
    put(&mut out, &four[1]);
    put(&mut out, &four[2]);
    // An unknown data type (12345) from each node.
    for node in [5u32, 9] {
        let id = (16 << 24) | (12345 << 8) | node;
        put(&mut out, &CanFrame::extended(id, &[1, 2, 0xC0]).unwrap());
    }
    // Not DroneCAN: a standard frame, standard and extended remote frames.
    put(&mut out, &CanFrame::standard(0x123, &[1, 2]).unwrap());
    out.push_str("(1700000100.050000) can0 123#R\n");
    out.push_str("(1700000100.050100) can0 1C4E2D01#R2\n");
    // Error frames, as a bus at the wrong bit rate makes them (CAN_ERR_FLAG | CAN_ERR_PROT).
    let error = CanFrame::from_socketcan(SOCKETCAN_ERR_FLAG | 0x08, &[0, 0, 0x08, 0, 0, 0, 0, 0]);
    out.push_str(&line(1_700_000_100.050_2, &error.unwrap()));
    out.push_str("(1700000100.050300) can0 20000004#0004000000000000\n");
    // CAN FD frames.
    out.push_str("(1700000100.050400) can0 1C4E5205##10102C0\n");
    out.push_str("(1700000100.050500) can0 123##0\n");
    // A StatusMsg2 with `.` between its bytes and candump's direction at the end; then the
    // ESCs' last records.
    let m2 = frames(
        StatusMsg2 {
            input_voltage: 240,
            current: -30,
            temperature: 33,
        },
        5,
        0,
    );
    let dotted: Vec<String> = m2[0].data().iter().map(|b| format!("{b:02X}")).collect();
    out.push_str(&format!(
        "(1700000100.060000) can0 {:08X}#{} R\n",
        m2[0].id(),
        dotted.join(".")
    ));
    out.push_str(&line(1_700_000_100.07, &frames(M1, 5, 1)[0]));
    for (k, f) in frames(status(1, 1000), 9, 5).iter().enumerate() {
        out.push_str(&line(1_700_000_100.08 + k as f64 * 1e-4, f));
    }
    out
}

/// Every kind of bad input in a candump log is counted in the summary's `link.can` of the ESC
/// whose node sent it (or the bus's counts, on every ESC of it), the good transfers decoded,
/// and nothing panics.
#[test]
fn a_candump_log_of_broken_transfers_and_foreign_frames_is_counted() {
    let dir = Dir::new();
    let log = dir.path("bad.log");
    std::fs::write(&log, bad_bus_log()).unwrap();
    let log = log.to_str().unwrap();
    let out = run(&["decode", log]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
    let got = records(&stdout(&out));
    let rpms = |node: u64| -> Vec<f64> {
        got.iter()
            .filter(|r| r["node"] == node)
            .map(|r| r["rpm"].as_f64().unwrap())
            .collect()
    };
    // Node 9: tids 0, 2 and 5 whole; 1 cut short, 3 toggled wrong, 4 with a bad CRC.
    assert_eq!(rpms(9), [500.0, 700.0, 1000.0]);
    assert_eq!(rpms(5), [1000.0, 1000.0]);
    let last5 = got.iter().rfind(|r| r["node"] == 5).unwrap();
    assert_eq!(last5["esc"], 5);
    assert_eq!(last5["voltage_v"], 24.0);
    assert_eq!(last5["current_a"], -3.0);
    assert_eq!(last5["msg2_age_ms"], 10);
    assert!(got.iter().filter(|r| r["node"] == 9).all(|r| r["esc"] == 1));

    let out = run(&["summary", "--json", log]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    let escs = v["escs"].as_array().unwrap();
    let link = |n: u64| escs.iter().find(|e| e["esc"] == n).unwrap()["link"].clone();
    let can = |n: u64| link(n)["can"].clone();
    let (hw, std) = (can(5), can(1));
    assert_eq!(std["node"], 9);
    assert_eq!(std["cut_short"], 1, "{std}");
    assert_eq!(std["toggle_errors"], 1, "{std}");
    assert_eq!(link(1)["checksum_failures"], 1, "{std}");
    assert_eq!(std["unknown_types"], 1, "{std}");
    assert_eq!(hw["node"], 5);
    assert_eq!(hw["unknown_types"], 1, "{hw}");
    assert_eq!(
        (
            hw["toggle_errors"].as_u64(),
            link(5)["checksum_failures"].as_u64()
        ),
        (Some(0), Some(0)),
        "{hw}"
    );
    for c in [&hw, &std] {
        // 3 foreign frames (a standard and two remote frames) and 2 error frames.
        assert_eq!(c["not_dronecan"], 5, "{c}");
        assert_eq!(c["error_frames"], 2, "{c}");
        assert_eq!(c["bus_frames"], 26, "{c}");
    }
    // A candump log's CAN FD lines: counted by the bus's stream (not decoded), and told on
    // standard error, once per interface, with their number.
    for c in [&hw, &std] {
        assert_eq!(c["bad_records"], 2, "{c}");
    }
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        err.trim_end(),
        format!("hwfoc: warning: {log}: can0: 2 CAN FD frames skipped (only classic CAN is read)")
    );
}

/// A garbage line: a one-line error naming the file and the line, exit code 1, the records
/// before it decoded.
#[test]
fn a_garbage_line_is_named_with_its_file_and_line() {
    let dir = Dir::new();
    let mut text = String::new();
    for (k, f) in frames(M1, 5, 0).iter().chain(&frames(M1, 5, 1)).enumerate() {
        text.push_str(&line(1_700_000_000.0 + k as f64 * 0.01, f));
    }
    text.push_str("(1700000000.100000) can0 1C4E5205#zz\n");
    text.push_str(&line(1_700_000_000.2, &frames(M1, 5, 2)[0]));
    for bad in [
        "(1700000000.100000) can0 1C4E5205#zz",
        "this is not candump",
        "(1700000000.1 can0 123#00",
        "(1700000000.100000) can0 123#000102030405060708",
        "(1700000000.100000) can0 12345#00",
    ] {
        let text = text.replace("(1700000000.100000) can0 1C4E5205#zz", bad);
        let path = dir.path("garbage.log");
        std::fs::write(&path, &text).unwrap();
        let o = run(&["decode", path.to_str().unwrap()]);
        assert_fails_with(&o, "garbage.log:3: not a candump -l line");
        let got = records(&String::from_utf8(o.stdout.clone()).unwrap());
        assert_eq!(got.len(), 2, "{bad}: the records before the line");
        let o = run(&["summary", "--json", path.to_str().unwrap()]);
        assert_fails_with(&o, "garbage.log:3: not a candump -l line");
    }
}

/// A CAN pcapng cut in the middle of a block decodes what is there, with a warning; cut in
/// its headers, the warning and a one-line error that nothing is left to decode.
#[test]
fn a_can_pcapng_cut_in_a_block_decodes_what_is_there() {
    let file = std::fs::read(frames_pcapng()).unwrap();
    let whole = records(&stdout(&run(&[
        "decode",
        frames_pcapng().to_str().unwrap(),
    ])));
    assert!(whole.len() >= 4, "{whole:?}");
    let dir = Dir::new();
    for cut in [file.len() - 1, file.len() - 20, file.len() / 2] {
        let path = dir.path(&format!("cut-{cut}.pcapng"));
        std::fs::write(&path, &file[..cut]).unwrap();
        let o = run(&["decode", path.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!err.contains("panicked"), "{err}");
        assert!(o.status.success(), "cut at {cut}: {err}");
        assert!(err.contains("stopped at byte"), "cut at {cut}: {err}");
        let got = records(&String::from_utf8(o.stdout).unwrap());
        assert!(!got.is_empty() && got.len() <= whole.len(), "cut at {cut}");
        assert_eq!(got[..], whole[..got.len()], "cut at {cut}");
    }
    for cut in [30, 45] {
        let path = dir.path(&format!("cut-{cut}.pcapng"));
        std::fs::write(&path, &file[..cut]).unwrap();
        let o = run(&["decode", path.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        let lines: Vec<&str> = err.lines().collect();
        assert_eq!(lines.len(), 2, "{err}");
        assert!(lines[0].starts_with("hwfoc: warning: ") && lines[0].contains("stopped at byte"));
        assert!(lines[1].ends_with(&format!(
            "cut-{cut}.pcapng is empty: there is nothing to decode"
        )));
    }
}

/// GetEscID: a request ([0]) maps nothing; an answer [node, channel] maps its node, whoever
/// sends it. A file is read ahead: the node keeps the number of the channel it learned for the
/// whole file, its records before the answer included (it was split into two ESCs, ESC 7 and
/// ESC 3, before).
#[test]
fn a_late_get_esc_id_answer_numbers_its_node_for_the_whole_file() {
    let dir = Dir::new();
    let mut text = String::new();
    let mut t = 1_700_000_000.0;
    let mut put = |f: &CanFrame| {
        t += 0.01;
        text.push_str(&line(t, f));
    };
    put(&frames(M1, 7, 0)[0]);
    put(&frames(GetEscId::new(&[0]).unwrap(), 127, 0)[0]);
    put(&frames(M1, 7, 1)[0]);
    put(&frames(GetEscId::new(&[7, 4]).unwrap(), 7, 0)[0]);
    put(&frames(M1, 7, 2)[0]);
    let path = dir.path("ids.log");
    std::fs::write(&path, &text).unwrap();
    let got = records(&stdout(&run(&["decode", path.to_str().unwrap()])));
    let escs: Vec<u64> = got.iter().map(|r| r["esc"].as_u64().unwrap()).collect();
    assert_eq!(escs, [3, 3, 3]);
    assert!(got.iter().all(|r| r["node"] == 7));
    // Not read ahead (standard input, as live): the node's records are held until its answer
    // (within 1 s), so they get the file's number too.
    let (pairs, ..) = decode_stdin(&text);
    assert_eq!(pairs, [(7, 3); 3]);
}

/// A candump log line of `frame` at `t` seconds on `interface`.
fn line_on(t: f64, interface: &str, frame: &CanFrame) -> String {
    line(t, frame).replacen(" can0 ", &format!(" {interface} "), 1)
}

/// A log of `(interface, node, message)` sent one after another, 10 ms apart, each transfer
/// with the next transfer id of its node.
fn bus(sent: &[(&str, u8, Message)]) -> String {
    let mut tids = [0u8; 128];
    let mut out = String::new();
    for (k, (interface, node, m)) in sent.iter().enumerate() {
        let tid = &mut tids[usize::from(*node)];
        for f in m.frames(16, *node, 0, *tid) {
            out.push_str(&line_on(1_700_000_000.0 + k as f64 * 0.01, interface, &f));
        }
        *tid = (*tid + 1) % 32;
    }
    out
}

/// A Hobbywing status of `rpm` and a StatusMsg2 of `decivolts`.
fn hw(rpm: u16) -> Message {
    StatusMsg1 {
        rpm,
        pwm: 300,
        status: 0,
    }
    .into()
}

fn volts(decivolts: i16) -> Message {
    StatusMsg2 {
        input_voltage: decivolts,
        current: 10,
        temperature: 30,
    }
    .into()
}

fn esc_id(node: u8, channel: u8) -> Message {
    GetEscId::new(&[node, channel]).unwrap().into()
}

/// Decodes `log`: its records' `(node, esc)` pairs in order, its records, and standard error.
fn decode_log(log: &str) -> (Vec<(u64, u64)>, Vec<Value>, String) {
    let dir = Dir::new();
    let path = dir.path("bus.log");
    std::fs::write(&path, log).unwrap();
    outcome(run(&["decode", path.to_str().unwrap()]))
}

/// Decodes `log` from standard input (which is not read ahead), as [`decode_log`].
fn decode_stdin(log: &str) -> (Vec<(u64, u64)>, Vec<Value>, String) {
    let dir = Dir::new();
    let path = dir.path("bus.log");
    std::fs::write(&path, log).unwrap();
    let out = hwfoc()
        .args(["decode", "-"])
        .stdin(std::fs::File::open(&path).unwrap())
        .output()
        .unwrap();
    outcome(out)
}

/// A decoding's records' `(node, esc)` pairs in order, its records, and standard error.
fn outcome(out: Output) -> (Vec<(u64, u64)>, Vec<Value>, String) {
    let got = records(&String::from_utf8(out.stdout).unwrap());
    let pairs = got
        .iter()
        .map(|r| (r["node"].as_u64().unwrap(), r["esc"].as_u64().unwrap()))
        .collect();
    (
        pairs,
        got,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The ESC of each node, in order of node.
fn esc_of_nodes(pairs: &[(u64, u64)]) -> Vec<(u64, u64)> {
    let set: std::collections::BTreeSet<(u64, u64)> = pairs.iter().copied().collect();
    set.into_iter().collect()
}

/// Two Hobbywing nodes that both answer GetEscID with channel 1 are two ESCs (they were one,
/// its rpm alternating 1000/3000 and its voltage 20/24 V): the first at the channel's number,
/// the second after the bus's places; a warning names both nodes and the channel.
#[test]
fn two_nodes_claiming_one_channel_stay_two_escs() {
    let mut sent = vec![("can0", 10, esc_id(10, 1)), ("can0", 11, esc_id(11, 1))];
    for _ in 0..5 {
        sent.extend([
            ("can0", 10, volts(200)),
            ("can0", 10, hw(1000)),
            ("can0", 11, volts(240)),
            ("can0", 11, hw(3000)),
        ]);
    }
    let (pairs, got, err) = decode_log(&bus(&sent));
    assert_eq!(got.len(), 10);
    assert_eq!(esc_of_nodes(&pairs), [(10, 0), (11, 1)]);
    for r in &got {
        let (rpm, v) = if r["node"] == 10 {
            (1000.0, 20.0)
        } else {
            (3000.0, 24.0)
        };
        assert_eq!(
            (r["rpm"].as_f64(), r["voltage_v"].as_f64()),
            (Some(rpm), Some(v))
        );
    }
    assert!(
        err.contains("warning") && err.contains("node 10") && err.contains("node 11"),
        "{err}"
    );
    assert!(err.contains("throttle channel 1"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    // Not read ahead (standard input, as live): the same ESCs and the same warning, once.
    let (stdin_pairs, _, stdin_err) = decode_stdin(&bus(&sent));
    assert_eq!(stdin_pairs, pairs);
    assert_eq!(
        stdin_err.trim_end(),
        "hwfoc: warning: standard input: can0: node 10 and node 11 both claim throttle channel 1: \
         read as two ESCs"
    );
}

/// A Hobbywing ESC on channel 1 beside a standard DroneCAN ESC of `esc_index` 0 (the mixed bus
/// the README shows): two ESCs, a warning naming both nodes.
#[test]
fn a_hobbywing_and_a_standard_esc_at_one_place_stay_two_escs() {
    let mut sent = vec![("can0", 10, esc_id(10, 1))];
    for k in 0..4 {
        sent.extend([
            ("can0", 10, hw(1000 + k)),
            ("can0", 20, status(0, 3000).into()),
        ]);
    }
    let (pairs, got, err) = decode_log(&bus(&sent));
    assert_eq!(got.len(), 8);
    assert_eq!(esc_of_nodes(&pairs), [(10, 0), (20, 1)]);
    assert!(
        got.iter()
            .all(|r| (r["node"] == 10) == (r["protocol"] == "hw-can"))
    );
    assert!(err.contains("node 10") && err.contains("node 20"), "{err}");
}

/// Two buses of a log are numbered one after the other, can0's ESCs before can1's, whatever
/// order their ESCs are first heard in (they were numbered in order of arrival, interleaved).
#[test]
fn two_buses_are_numbered_one_after_the_other() {
    let mut sent = vec![
        ("can0", 1, esc_id(1, 1)),
        ("can0", 2, esc_id(2, 2)),
        ("can1", 3, esc_id(3, 1)),
        ("can1", 4, esc_id(4, 2)),
        ("can0", 1, hw(100)),
        ("can1", 3, hw(300)),
        ("can1", 4, hw(400)),
    ];
    // can0's channel-2 ESC heard last.
    for _ in 0..300 {
        sent.push(("can0", 1, hw(100)));
    }
    sent.push(("can0", 2, hw(200)));
    let (pairs, _, err) = decode_log(&bus(&sent));
    assert_eq!(
        esc_of_nodes(&pairs),
        [(1, 0), (2, 1), (3, 2), (4, 3)],
        "{err}"
    );
}

/// A stray frame on an interface that carries no ESC takes no number and moves none (it made
/// can0's channel-2 ESC ESC 2 instead of ESC 1).
#[test]
fn a_stray_frame_on_another_interface_moves_no_esc() {
    let mut sent = vec![
        ("can0", 1, esc_id(1, 1)),
        ("can0", 2, esc_id(2, 2)),
        ("can0", 1, hw(100)),
    ];
    for _ in 0..300 {
        sent.push(("can0", 1, hw(100)));
    }
    sent.push(("can0", 2, hw(200)));
    let mut log = bus(&sent);
    let stray = CanFrame::standard(0x123, &[1]).unwrap();
    // After can0's first window, before its channel-2 ESC is heard.
    let at = log.match_indices('\n').nth(150).unwrap().0 + 1;
    log.insert_str(at, &line_on(1_700_000_001.505, "vcan1", &stray));
    let (pairs, _, err) = decode_log(&log);
    assert_eq!(esc_of_nodes(&pairs), [(1, 0), (2, 1)], "{err}");
    assert_eq!(err, "", "a bus without ESCs is no ESC to warn of");
    // The stray frame first in the log: it took ESC 0, can0's ESCs 1 and 2.
    let log = format!("{}{log}", line_on(1_699_999_999.0, "vcan1", &stray));
    let (pairs, _, err) = decode_log(&log);
    assert_eq!(esc_of_nodes(&pairs), [(1, 0), (2, 1)], "{err}");
    assert_eq!(err, "");
}

/// A bus of error frames and no ESC status is told of in CAN words, with a wrong bit rate as
/// its likely cause (it was told to check the baud rate and the wiring of an ESC's serial
/// wire): read ahead from a file, or read once from standard input.
#[test]
fn a_bus_of_error_frames_suggests_a_wrong_bit_rate_in_can_words() {
    let error = CanFrame::from_socketcan(SOCKETCAN_ERR_FLAG | 0x08, &[0, 0, 0x08, 0, 0, 0, 0, 0]);
    let mut log = String::new();
    for k in 0..3 {
        log.push_str(&line(
            1_700_000_000.0 + f64::from(k) * 0.01,
            error.as_ref().unwrap(),
        ));
    }
    log.push_str(&line(
        1_700_000_000.5,
        &CanFrame::standard(0x123, &[1]).unwrap(),
    ));
    let (_, got, err) = decode_log(&log);
    assert!(got.is_empty());
    // Standard input cannot be read ahead: the bus is an ESC without records, which says why.
    let (_, _, from_stdin) = decode_stdin(&log);
    for err in [&err, &from_stdin] {
        assert!(
            err.contains(
                "4 CAN frames, 3 of them error frames, and no ESC status: check the bit rate"
            ),
            "{err}"
        );
        for word in ["baud", "wiring", "RX"] {
            assert!(!err.contains(word), "{word}: {err}");
        }
    }
}

/// Four buses of 63 ESCs never asked for their ids (nodes 10 to 72: 73 places a bus) need 292
/// ESC numbers; records number 256. The ESCs past them are not dropped without a word: the
/// command fails, naming the input.
#[test]
fn can_escs_past_the_last_esc_number_fail_the_command() {
    let dir = Dir::new();
    let one = dir.arg("bus.log");
    ok(run(&[
        "simulate",
        "--protocol",
        "hw-can",
        "--escs",
        "63",
        "--no-ask-ids",
        "--duration",
        "1",
        "-o",
        &one,
    ]));
    let log = std::fs::read_to_string(&one).unwrap();
    let four: String = (0..4)
        .map(|bus| log.replace(" can0 ", &format!(" can{bus} ")))
        .collect();
    let buses = dir.arg("buses.log");
    std::fs::write(&buses, four).unwrap();
    for command in ["decode", "summary"] {
        let out = run(&[command, &buses]);
        assert_fails_with(&out, "buses.log: too many ESCs");
    }
}
