//! `hwfoc simulate --degrade`: the truth names each degradation, a loose wire's bursts of loss
//! are counted by the summary as lost packets on that ESC alone, a bad spec is refused naming
//! the option and the spec.

#![cfg(unix)]

mod common;

use common::{Dir, assert_fails_with, hwfoc, ok};
use serde_json::Value;

fn run(args: &[&str]) -> std::process::Output {
    hwfoc().args(args).output().expect("run hwfoc")
}

#[test]
fn a_loose_wire_shows_as_lost_packets_and_the_truth_names_it() {
    let dir = Dir::new();
    let (rec, truth) = (dir.arg("w.pcapng"), dir.arg("w.jsonl"));
    ok(run(&[
        "simulate",
        "--escs",
        "2",
        "--seed",
        "4",
        "--degrade",
        "1:wire@5=0.5",
        "--degrade",
        "0:battery=0.25",
        "-o",
        &rec,
        "--truth",
        &truth,
    ]));
    let text = std::fs::read_to_string(&truth).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(r#"{"degradation":{"esc":1,"kind":"wire","start_s":5,"severity":0.5}}"#)
    );
    assert_eq!(
        lines.next(),
        Some(r#"{"degradation":{"esc":0,"kind":"battery","start_s":0,"severity":0.25}}"#)
    );
    assert!(lines.next().unwrap().starts_with(r#"{"t_s":"#));
    let summary: Value =
        serde_json::from_slice(&ok(run(&["summary", &rec, "--json"])).stdout).unwrap();
    let lost: Vec<u64> = summary["escs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["link"]["lost_packets"].as_u64().unwrap())
        .collect();
    assert_eq!(lost[0], 0, "{lost:?}");
    assert!(lost[1] >= 20, "{lost:?}");
}

#[test]
fn a_bad_degradation_names_the_option_and_the_spec() {
    let dir = Dir::new();
    let out = dir.arg("x.pcapng");
    for (spec, why) in [
        (
            "1:rust",
            "\"1:rust\": unknown degradation \"rust\"; the kinds are bearing, prop",
        ),
        ("0:heat=2", "\"0:heat=2\": bad severity \"2\" (from 0 to 1)"),
        ("heat", "\"heat\": expected ESC:KIND[@START][=SEVERITY]"),
    ] {
        let o = run(&["simulate", "--degrade", spec, "-o", &out]);
        assert_eq!(o.status.code(), Some(2), "{spec}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("--degrade") && err.contains(why), "{err}");
    }
    assert_fails_with(
        &run(&["simulate", "--degrade", "1:bearing", "-o", &out]),
        "hwfoc: --degrade: a degradation (bearing) is on ESC 1, which does not exist: there are 1 \
         (0..0)\n",
    );
    assert_fails_with(
        &run(&[
            "simulate",
            "--protocol",
            "hw5",
            "--degrade",
            "0:wire",
            "-o",
            &out,
        ]),
        "--degrade: a loose wire (bursts of lost frames) is simulated for HW-FOC only",
    );
}
