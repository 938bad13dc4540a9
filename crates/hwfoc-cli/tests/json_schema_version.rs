//! Every JSON object the command prints, other than the records, carries `"schema_version"`
//! (`hwfoc_io::JSON_SCHEMA_VERSION`) as its first key; the records (JSON Lines) carry exactly
//! the schema's keys.

mod common;

use common::{TEXT_SCHEMA, XROTOR, capture, hwfoc, ok, stdout};
use serde_json::Value;

/// The first key of `v` and its value.
fn first(v: &Value) -> (&str, &Value) {
    let (k, v) = v
        .as_object()
        .expect("an object")
        .iter()
        .next()
        .expect("a key");
    (k.as_str(), v)
}

#[test]
fn summary_json_starts_with_the_schema_version() {
    let path = capture(XROTOR);
    let out = stdout(
        &hwfoc()
            .args(["summary", "--json", path.to_str().unwrap()])
            .output()
            .unwrap(),
    );
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(hwfoc_io::JSON_SCHEMA_VERSION, 2);
    assert_eq!(first(&v), ("schema_version", &Value::from(2)));
}

#[test]
fn monitor_json_status_alarm_and_total_lines_carry_the_schema_version() {
    let out = ok(hwfoc()
        .args([
            "monitor",
            "--sim",
            "2",
            "--json",
            "--no-config",
            "--interval",
            "0.5",
            "--duration",
            "3.2",
            "--fault",
            "throttle_signal_lost@1-1.2",
        ])
        .output()
        .expect("spawn"));
    let lines: Vec<Value> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect();
    let kinds: Vec<&str> = lines.iter().map(|v| v["type"].as_str().unwrap()).collect();
    assert!(
        kinds.contains(&"status") && kinds.contains(&"alarm") && kinds.contains(&"total"),
        "{kinds:?}"
    );
    for v in &lines {
        assert_eq!(first(v), ("schema_version", &Value::from(2)), "{v}");
        // The record inside a status line is the schema's, without a version of its own.
        if let Some(record) = v["record"].as_object() {
            let keys: Vec<&str> = record.keys().map(String::as_str).collect();
            assert_eq!(keys, TEXT_SCHEMA);
        }
    }
}

#[test]
fn records_have_exactly_the_schema_keys() {
    let path = capture(XROTOR);
    let out = stdout(
        &hwfoc()
            .args(["decode", path.to_str().unwrap()])
            .output()
            .unwrap(),
    );
    for line in out.lines() {
        let v: Value = serde_json::from_str(line).unwrap();
        let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
        assert_eq!(keys, TEXT_SCHEMA, "{line}");
    }
}
