//! Figures that stay true: an ESC that restarts (or a simulator restarted on the same port)
//! and interleaved packet sequences count restarts, not lost packets.

mod common;

use serde_json::Value;

use common::{Dir, hwfoc, ok, run};

/// The summary's JSON of `inputs`.
fn summary(inputs: &[&str]) -> Value {
    let mut args = vec!["summary", "--json"];
    args.extend_from_slice(inputs);
    serde_json::from_slice(&ok(run(hwfoc().args(&args))).stdout).unwrap()
}

/// `hwfoc simulate` of one ESC for `seconds` from packet `start`, with `extra` options.
fn simulate(dir: &Dir, name: &str, start: &str, extra: &[&str]) -> Vec<u8> {
    let out = dir.arg(name);
    let mut args = vec![
        "simulate",
        "-o",
        &out,
        "--duration",
        "4",
        "--start-packet",
        start,
    ];
    args.extend_from_slice(extra);
    ok(run(hwfoc().args(&args)));
    std::fs::read(&out).unwrap()
}

#[test]
fn a_restarted_esc_counts_a_restart_not_lost_packets() {
    let dir = Dir::new();
    // The ESC runs from packet 20000, restarts, and counts again from 0: one raw stream.
    let mut wire = simulate(&dir, "a.bin", "20000", &[]);
    wire.extend(simulate(&dir, "b.bin", "0", &[]));
    let both = dir.arg("restart.bin");
    std::fs::write(&both, &wire).unwrap();
    let v = summary(&[&both]);
    let link = &v["escs"][0]["link"];
    assert_eq!(link["restarts"], 1, "{link}");
    assert_eq!(link["lost_packets"], 0, "{link}");
    assert_eq!(link["delivery_ratio"], 1.0, "{link}");
    let text = String::from_utf8(ok(run(hwfoc().args(["summary", &both]))).stdout).unwrap();
    assert!(
        text.contains("0 lost packets, 0 duplicate packets, 1 restarts"),
        "{text}"
    );
}

#[test]
fn interleaved_packet_sequences_count_no_loss() {
    let dir = Dir::new();
    let a = simulate(&dir, "a.bin", "100", &["--seed", "1"]);
    let b = simulate(&dir, "b.bin", "30000", &["--seed", "2"]);
    // Two ESCs on one wire: their data frames in turn.
    let frames = |w: &[u8]| -> Vec<Vec<u8>> {
        let mut out = Vec::new();
        let mut i = 0;
        while i + 24 <= w.len() {
            if w[i] == 0x9B && w[i + 1] == 0x16 {
                out.push(w[i..i + 24].to_vec());
                i += 24;
            } else {
                i += 1;
            }
        }
        out
    };
    let (fa, fb) = (frames(&a), frames(&b));
    let mut wire = Vec::new();
    for (x, y) in fa.iter().zip(&fb) {
        wire.extend_from_slice(x);
        wire.extend_from_slice(y);
    }
    let mixed = dir.arg("mixed.bin");
    std::fs::write(&mixed, &wire).unwrap();
    let v = summary(&[&mixed]);
    let link = &v["escs"][0]["link"];
    assert_eq!(link["lost_packets"], 0, "{link}");
    assert!(link["restarts"].as_u64().unwrap() > 10, "{link}");
}
