//! `hwfoc can` against the simulator's virtual Hobbywing CAN ESCs on an SLCAN pseudo-terminal
//! (`hwfoc simulate --protocol hw-can --pty`): `list` finds them with their node ids and
//! channels, `set` and `set-id` change them and read the change back, nothing is changed while
//! a motor turns, the factory state is told, a node that does not answer times out.

#![cfg(unix)]

mod common;

use std::process::Stdio;
use std::time::Duration;

use common::{Running, assert_fails_with, hwfoc, run};

/// A bus of `escs` virtual ESCs (`extra` options), and its `slcan:` spec.
fn bus(escs: &str, extra: &[&str]) -> (Running, String) {
    let mut args = vec![
        "simulate",
        "--protocol",
        "hw-can",
        "--escs",
        escs,
        "--pty",
        "-q",
    ];
    args.extend_from_slice(extra);
    let sim = Running::start(&args);
    let line = sim.wait_for_stdout("slcan: ", Duration::from_secs(20));
    let path = line.trim_start_matches("slcan: ").trim().to_string();
    (sim, format!("slcan:{path}"))
}

/// At rest: the throttle profile holds zero for far longer than a test.
const IDLE: &[&str] = &["--lead-in", "1000"];

fn can(args: &[&str]) -> std::process::Output {
    run(hwfoc().arg("can").args(args).stdin(Stdio::null()))
}

fn stdout(o: &std::process::Output) -> String {
    common::stdout(o)
}

fn list_json(spec: &str) -> serde_json::Value {
    serde_json::from_str(&stdout(&can(&["list", spec, "--json"]))).unwrap()
}

#[test]
fn list_then_set_and_set_id_read_back() {
    let (_sim, spec) = bus("4", IDLE);
    let started = std::time::Instant::now();
    let list = list_json(&spec);
    println!(
        "can list: every ESC answered after {:.3} s (the command's own figure), the process \
         ended after {:.3} s",
        list["elapsed_s"].as_f64().unwrap(),
        started.elapsed().as_secs_f64()
    );
    let escs = list["escs"].as_array().unwrap();
    let seen: Vec<(u64, u64, &str)> = escs
        .iter()
        .map(|e| {
            (
                e["node"].as_u64().unwrap(),
                e["config"]["throttle_channel"].as_u64().unwrap(),
                e["direction"].as_str().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        seen,
        [(10, 1, "cw"), (11, 2, "ccw"), (12, 3, "cw"), (13, 4, "ccw")]
    );
    assert_eq!(list["factory_state"], false);
    assert!(
        escs.iter()
            .all(|e| e["maintenance"]["total_rotation_time_min"].is_u64())
    );
    assert!(
        escs.iter()
            .all(|e| e["msg3_rate_hz"] == 10 && e["rpm"] == 0)
    );

    // A direction, an LED and a rate, read back.
    let out = can(&[
        "set",
        &spec,
        "--node",
        "10",
        "--direction",
        "ccw",
        "--led",
        "red,2",
        "--rate",
        "msg1=100",
        "--yes",
    ]);
    let text = stdout(&out);
    for line in [
        "node 10 now says: direction ccw",
        "node 10 now says: LED red blinking 2 Hz",
        "node 10 now says: msg1 rate 100 Hz",
    ] {
        assert!(text.lines().any(|l| l == line), "{line:?} not in {text}");
    }
    // A new node id and channel.
    let out = can(&[
        "set-id",
        &spec,
        "--node",
        "12",
        "--to",
        "40",
        "--channel",
        "7",
        "--yes",
    ]);
    assert_eq!(
        stdout(&out).trim(),
        "node 12 now says: node id 40, throttle channel 7"
    );
    let list = list_json(&spec);
    let nodes: Vec<u64> = list["escs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["node"].as_u64().unwrap())
        .collect();
    assert_eq!(nodes, [10, 11, 13, 40]);
    let e10 = &list["escs"][0];
    assert_eq!(
        (
            &e10["direction"],
            &e10["config"]["msg1_rate_hz"],
            &e10["config"]["led_color"]
        ),
        (&"ccw".into(), &100.into(), &"red".into())
    );

    // No answer: one line naming the bus and the node.
    let out = can(&[
        "set",
        &spec,
        "--node",
        "99",
        "--direction",
        "cw",
        "--yes",
        "--timeout",
        "0.5",
    ]);
    assert_fails_with(
        &out,
        &format!("{spec}: node 99 did not answer SetDirection within 0.5 s"),
    );
    // No terminal and no --yes: nothing changed.
    let out = can(&["set", &spec, "--node", "11", "--direction", "cw"]);
    assert_fails_with(&out, "--yes: no terminal to confirm");
    assert_eq!(list_json(&spec)["escs"][1]["direction"], "ccw");
    // The self test of an ESC at rest passes; a node id in use is refused.
    assert_eq!(
        stdout(&can(&["self-test", &spec, "--node", "11"])).trim(),
        "node 11: self test passed"
    );
    let out = can(&[
        "set-id",
        &spec,
        "--node",
        "13",
        "--to",
        "40",
        "--channel",
        "4",
        "--yes",
    ]);
    assert_fails_with(&out, "node 40 is already on");
}

#[test]
fn nothing_is_changed_while_a_motor_turns() {
    let (_sim, spec) = bus("2", &["--lead-in", "0", "--levels", "30", "--hold", "1000"]);
    std::thread::sleep(Duration::from_millis(1500));
    for args in [
        &["set", &spec, "--node", "10", "--direction", "ccw", "--yes"][..],
        &[
            "set-id",
            &spec,
            "--node",
            "11",
            "--to",
            "20",
            "--channel",
            "2",
            "--yes",
        ],
        &["self-test", &spec, "--node", "10"],
    ] {
        let out = can(args);
        assert_fails_with(&out, "nothing is changed while a motor turns");
    }
    // And the ESCs were not changed (read while they turn: list asks nothing that changes).
    let list = list_json(&spec);
    assert_eq!(list["escs"][0]["direction"], "cw");
    assert_eq!(list["escs"][1]["node"], 11);
    let escs = list["escs"].as_array().unwrap();
    assert!(
        escs.iter().any(|e| e["rpm"].as_u64().unwrap() > 0),
        "{list}"
    );
}

#[test]
fn the_factory_state_is_told_and_set_id_refused() {
    let (_sim, spec) = bus("3", &["--factory", "--lead-in", "1000"]);
    let list = list_json(&spec);
    assert_eq!(list["factory_state"], true, "{list}");
    let escs = list["escs"].as_array().unwrap();
    assert_eq!(escs.len(), 1, "{list}");
    assert_eq!(escs[0]["node"], 1);
    assert!(escs[0]["escs"].as_u64().unwrap() >= 2, "{list}");
    let text = stdout(&can(&["list", &spec]));
    assert!(text.contains("factory state: "), "{text}");
    assert!(text.contains("Connect one ESC at a time"), "{text}");
    let out = can(&[
        "set-id",
        &spec,
        "--node",
        "1",
        "--to",
        "11",
        "--channel",
        "1",
        "--yes",
    ]);
    assert_fails_with(&out, "ESCs answer as node 1 (the factory state)");
}
