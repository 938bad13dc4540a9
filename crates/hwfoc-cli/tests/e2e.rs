//! The whole capture pipeline through real pseudo-terminals, as a person without hardware runs
//! it: `hwfoc simulate` drives 8 virtual ESCs in real time, `hwfoc record` captures their ptys for
//! over 20 s, `hwfoc decode` reads the recording, and the records are compared with the
//! simulator's ground truth. (That tshark reads `record`'s recordings packet for packet is
//! `record.rs`'s `tshark_reads_a_pty_recording_packet_for_packet`, ignored unless tshark is asked
//! for.)

#![cfg(unix)]

mod common;

use std::collections::BTreeMap;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

const ESCS: usize = 8;
/// Seconds the recorder runs: the issue asks for at least 20 s of real time.
const RECORD_S: f64 = 21.0;

fn hwfoc() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hwfoc"))
}

fn records(jsonl: &str) -> Vec<Value> {
    jsonl
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON record"))
        .collect()
}

/// (esc, packet) -> record, for the data frames of one side. Packet numbers do not wrap within
/// the test (8 ESCs x 21 s x 20 frames/s is far below 65536 per ESC), unless a start packet is
/// near the wrap, so the key is made unique with a running index of repeats.
fn by_key(records: &[Value]) -> BTreeMap<(u64, u64, usize), Value> {
    let mut seen: BTreeMap<(u64, u64), usize> = BTreeMap::new();
    let mut out = BTreeMap::new();
    for r in records {
        let key = (r["esc"].as_u64().unwrap(), r["packet"].as_u64().unwrap());
        let n = seen.entry(key).or_default();
        out.insert((key.0, key.1, *n), r.clone());
        *n += 1;
    }
    out
}

#[test]
fn eight_virtual_escs_recorded_for_twenty_seconds_match_the_ground_truth() {
    let dir = tempfile::tempdir().unwrap();
    let links = dir.path().join("escs");
    let truth = dir.path().join("truth.jsonl");
    let recording = dir.path().join("bench.pcapng");

    let sim = hwfoc()
        .args([
            "simulate",
            "--escs",
            "8",
            "--pty",
            "--seed",
            "2026",
            "--profile",
            "sine",
        ])
        .args(["--duration", &(RECORD_S + 6.0).to_string()])
        .arg("--link-dir")
        .arg(&links)
        .arg("--truth")
        .arg(&truth)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start simulate");
    let deadline = Instant::now() + Duration::from_secs(10);
    while !(0..ESCS).all(|i| links.join(format!("esc{i}")).exists()) {
        assert!(Instant::now() < deadline, "the simulator made no pty links");
        std::thread::sleep(Duration::from_millis(50));
    }

    let ports: Vec<_> = (0..ESCS).map(|i| links.join(format!("esc{i}"))).collect();
    let rec = hwfoc()
        .arg("record")
        .args(&ports)
        .arg("-o")
        .arg(&recording)
        .args(["--duration", &RECORD_S.to_string()])
        .output()
        .expect("run record");
    assert!(
        rec.status.success(),
        "record failed: {}",
        String::from_utf8_lossy(&rec.stderr)
    );
    let sim = sim.wait_with_output().unwrap();
    assert!(
        sim.status.success(),
        "simulate failed: {}",
        String::from_utf8_lossy(&sim.stderr)
    );

    let decoded = hwfoc().arg("decode").arg(&recording).output().unwrap();
    assert!(
        decoded.status.success(),
        "{}",
        String::from_utf8_lossy(&decoded.stderr)
    );
    let decoded = records(&String::from_utf8(decoded.stdout).unwrap());
    let truth = records(&std::fs::read_to_string(&truth).unwrap());

    // The truth covers the whole simulation; the recording the 21 s in which it had the ports
    // open. Frames half-written when the recorder opened or closed a port are in neither.
    let first_t = decoded
        .iter()
        .map(|r| r["t_s"].as_f64().unwrap())
        .fold(f64::MAX, f64::min);
    let last_t = decoded
        .iter()
        .map(|r| r["t_s"].as_f64().unwrap())
        .fold(f64::MIN, f64::max);
    assert!(
        last_t - first_t > RECORD_S - 1.5,
        "recorded {:.1} s",
        last_t - first_t
    );
    let recorded = by_key(&decoded);
    let expected = by_key(&truth);

    // Every decoded frame was sent, with exactly the values sent; the timestamps agree within
    // the pty's delivery latency.
    for (key, got) in &recorded {
        let sent = expected
            .get(key)
            .unwrap_or_else(|| panic!("decoded a frame that was never sent: {got}"));
        for field in got.as_object().unwrap().keys().filter(|k| *k != "t_s") {
            assert_eq!(
                got[field], sent[field],
                "{field} of esc {} packet {}",
                key.0, key.1
            );
        }
        let dt = got["t_s"].as_f64().unwrap() - sent["t_s"].as_f64().unwrap();
        assert!(dt.abs() < 0.5, "t_s differs by {dt} s for {key:?}");
    }
    // Every frame sent while the recorder was running is in the recording (a margin for the
    // moments the ports were opened and closed).
    for esc in 0..ESCS as u64 {
        let got: Vec<_> = recorded.keys().filter(|k| k.0 == esc).collect();
        let (lo, hi) = (got.first().unwrap(), got.last().unwrap());
        let sent_between = expected
            .keys()
            .filter(|k| k.0 == esc && (k.1, k.2) >= (lo.1, lo.2) && (k.1, k.2) <= (hi.1, hi.2))
            .count();
        assert_eq!(
            got.len(),
            sent_between,
            "esc {esc}: frames missing from the recording"
        );
        assert!(got.len() > 200, "esc {esc}: only {} frames", got.len());
    }
    // Timestamps never go backwards within a port.
    for esc in 0..ESCS as u64 {
        let times: Vec<f64> = decoded
            .iter()
            .filter(|r| r["esc"] == esc)
            .map(|r| r["t_s"].as_f64().unwrap())
            .collect();
        assert!(
            times.windows(2).all(|w| w[0] <= w[1]),
            "esc {esc}: t_s not monotonic"
        );
    }
}
