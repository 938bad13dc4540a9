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
        &format!("{spec}: node 99 is not heard (is it on the bus, at this bit rate?)"),
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
    // And the ESCs were not changed; list asks nothing while they turn.
    let list = list_json(&spec);
    assert_eq!(list["asked"], false, "{list}");
    assert_eq!(list["escs"][0]["direction"], serde_json::Value::Null);
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

#[path = "../../hwfoc-bridge/tests/py/python.rs"]
mod python;

/// A CAN bus between two SLCAN programs: a pseudo-terminal for each, whose master side an
/// SLCAN adapter (the simulator's [`Adapter`](hwfoc_sim::can::slcan::Adapter)) answers, the
/// frames each sends handed to the other while its channel is open.
fn slcan_bus(stop: std::sync::Arc<std::sync::atomic::AtomicBool>) -> (String, String) {
    use hwfoc_sim::can::slcan::{Action, Adapter, push_frame};
    use hwfoc_sim::pty::RawPair;
    use std::io::{Read, Write};
    let pairs = [RawPair::open().unwrap(), RawPair::open().unwrap()];
    let paths = pairs.each_ref().map(|p| p.path.display().to_string());
    for p in &pairs {
        p.master_nonblocking().unwrap();
    }
    std::thread::spawn(move || {
        let mut pairs = pairs;
        let mut adapters = [Adapter::new(), Adapter::new()];
        let mut buf = [0u8; 4096];
        while !stop.load(std::sync::atomic::Ordering::Relaxed) {
            let mut idle = true;
            for i in 0..2 {
                let Ok(n) = pairs[i].master.read(&mut buf) else {
                    continue;
                };
                idle = false;
                let (mut reply, mut actions) = (Vec::new(), Vec::new());
                adapters[i].feed(&buf[..n], &mut reply, &mut actions);
                let _ = pairs[i].master.write_all(&reply);
                let mut out = Vec::new();
                for a in actions {
                    if let Action::Frame(f) = a
                        && adapters[1 - i].is_open()
                    {
                        push_frame(&mut out, &f);
                    }
                }
                let _ = pairs[1 - i].master.write_all(&out);
            }
            if idle {
                std::thread::sleep(Duration::from_millis(2));
            }
        }
    });
    let [a, b] = paths;
    (a, b)
}

/// `hwfoc can` against an ESC stand-in written with pydronecan's node
/// (`tests/py/esc_standin.py`): `list` reads what it says, `set --direction` and `set-id`
/// change it and read it back, and the stand-in's own state agrees.
#[test]
#[ignore = "needs pydronecan with pyserial (HWFOC_DRONECAN_PY, or python3 with the dronecan package; .ci/dronecan.sh)"]
fn pydronecan_esc_standin_is_listed_and_set_up() {
    use std::io::BufRead;
    let python = python::python_with("HWFOC_DRONECAN_PY", "dronecan", ".ci/dronecan.sh");
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/py/esc_standin.py");
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let (ours, theirs) = slcan_bus(std::sync::Arc::clone(&stop));
    let mut standin = std::process::Command::new(&python)
        .args([script, &theirs, "7", "3", "12"])
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = std::io::BufReader::new(standin.stdout.take().unwrap()).lines();
    assert_eq!(lines.next().unwrap().unwrap(), "stand-in ready");
    let spec = format!("slcan:{ours}");
    let list = list_json(&spec);
    let e = &list["escs"][0];
    assert_eq!(list["escs"].as_array().unwrap().len(), 1, "{list}");
    assert_eq!(
        (
            &e["node"],
            &e["channels"],
            &e["direction"],
            &e["config"]["throttle_channel"]
        ),
        (&7.into(), &serde_json::json!([3]), &"cw".into(), &3.into()),
        "{list}"
    );
    assert_eq!(e["maintenance"]["total_rotation_time_min"], 1234);
    let out = can(&[
        "set",
        &spec,
        "--node",
        "7",
        "--direction",
        "ccw",
        "--throttle-source",
        "pwm",
        "--yes",
    ]);
    let text = stdout(&out);
    assert!(text.contains("node 7 now says: direction ccw"), "{text}");
    assert!(
        text.contains("node 7 now says: throttle source pwm"),
        "{text}"
    );
    let out = can(&[
        "set-id",
        &spec,
        "--node",
        "7",
        "--to",
        "21",
        "--channel",
        "5",
        "--yes",
    ]);
    assert_eq!(
        stdout(&out).trim(),
        "node 7 now says: node id 21, throttle channel 5"
    );
    let list = list_json(&spec);
    assert_eq!(list["escs"][0]["node"], 21, "{list}");
    assert_eq!(list["escs"][0]["direction"], "ccw", "{list}");
    let state: serde_json::Value = serde_json::from_str(&lines.next().unwrap().unwrap()).unwrap();
    let _ = standin.wait();
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    println!("pydronecan ESC stand-in set up by hwfoc can: {state}");
    assert_eq!(
        (
            &state["node_id"],
            &state["channel"],
            &state["direction"],
            &state["source"]
        ),
        (&21.into(), &5.into(), &1.into(), &1.into())
    );
}
