//! `hwfoc can` never writes to an ESC it cannot see at rest, against a scriptable stand-in bus
//! (`can_standin/`): ESCs that start turning after the listen phase or during the question,
//! whose StatusMsg1 is off or slow, heard only through StatusMsg2, a standard `esc.Status` ESC
//! turning, a GPS-like node; answers late, twice, from another node, with a wrong transfer
//! id; a read-back that differs; and what `list` says and asks.

#![cfg(unix)]

mod can_standin;
mod common;

use std::io::Write;
use std::process::{Output, Stdio};
use std::time::{Duration, Instant};

use can_standin::{Answers, Bus, Esc, Node};
use common::{hwfoc, run};

/// `hwfoc can` with the arguments of `line` (split at spaces), no terminal.
fn can(line: &str) -> Output {
    run(hwfoc()
        .arg("can")
        .args(line.split_whitespace())
        .stdin(Stdio::null()))
}

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// Prints a command's outcome as a user sees it (the report's figures).
fn show(what: &str, o: &Output) {
    let (out, err) = text(o);
    println!(
        "{what}: exit {:?}\n  stdout: {out:?}\n  stderr: {err:?}",
        o.status.code()
    );
}

/// Asserts a refusal: exit 1, no panic, the last line of standard error (after the plan)
/// `hwfoc: ` and then a message containing `needle`.
fn assert_fails_with(o: &Output, needle: &str) {
    let (_, err) = text(o);
    assert_eq!(o.status.code(), Some(1), "stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
    let last = err.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("hwfoc: ") && last.contains(needle),
        "{needle:?} not in {err:?}"
    );
}

/// Runs `hwfoc can` with `line` (`{spec}` the bus), asserts it is refused with `needle` and
/// that nothing was written to the bus.
fn refused_unwritten(bus: &Bus, line: &str, needle: &str) -> Output {
    let out = can(&line.replace("{spec}", &bus.spec));
    assert_fails_with(&out, needle);
    assert!(bus.writes().is_empty(), "{:?}", bus.writes());
    out
}

/// Asserts that `text` holds `needle`.
fn assert_has(text: &str, needle: &str) {
    assert!(text.contains(needle), "{needle:?} not in {text:?}");
}

fn one(esc: Esc) -> Bus {
    Bus::start(vec![Node::Hobbywing(esc)])
}

#[test]
fn a_node_whose_status_is_off_is_refused_a_direction_but_not_an_led() {
    let bus = one(Esc {
        msg1: None,
        ..Esc::new(10, 1)
    });
    let out = can(&format!("set {} --node 10 --direction ccw --yes", bus.spec));
    show("set --direction ccw, StatusMsg1 off", &out);
    assert_fails_with(&out, "node 10 sends no StatusMsg1");
    assert_fails_with(&out, "--rate msg1=50");
    assert!(bus.writes().is_empty(), "{:?}", bus.writes());
    let out = can(&format!("set {} --node 10 --led red --yes", bus.spec));
    assert!(out.status.success(), "{:?}", text(&out));
    assert_has(&text(&out).0, "node 10 now says: LED red steady");
}

#[test]
fn an_esc_heard_only_through_status_msg2_with_current_is_not_written_to() {
    let bus = one(Esc {
        msg1: None,
        msg2_current: Some(250),
        ..Esc::new(10, 1)
    });
    let out = can(&format!("set {} --node 10 --direction ccw --yes", bus.spec));
    assert_eq!(out.status.code(), Some(1), "{:?}", text(&out));
    assert!(bus.writes().is_empty(), "{:?}", bus.writes());
}

#[test]
fn a_motor_turning_at_1_hz_after_the_listen_phase_is_not_changed() {
    let bus = one(Esc {
        msg1: Some(Duration::from_secs(1)),
        turns_after: Some(Duration::from_millis(2500)),
        ..Esc::new(10, 1)
    });
    let out = refused_unwritten(
        &bus,
        "set {spec} --node 10 --direction ccw --yes",
        "nothing is changed while a motor turns",
    );
    show(
        "set --direction ccw, StatusMsg1 at 1 Hz, turning from 2.5 s",
        &out,
    );
}

#[test]
fn a_motor_that_starts_during_the_question_is_not_changed() {
    let bus = one(Esc {
        turns_after: Some(Duration::from_millis(5000)),
        ..Esc::new(10, 1)
    });
    let started = Instant::now();
    let terminal = hwfoc_sim::pty::RawPair::open().unwrap();
    let child = hwfoc()
        .args([
            "can",
            "set",
            &bus.spec,
            "--node",
            "10",
            "--direction",
            "ccw",
        ])
        .stdin(Stdio::from(terminal.slave))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The question is on the terminal before the motor starts; answered after.
    std::thread::sleep(Duration::from_millis(5600).saturating_sub(started.elapsed()));
    let mut master = terminal.master;
    master.write_all(b"y\n").unwrap();
    let out = child.wait_with_output().unwrap();
    show(
        "set --direction ccw, motor starting during the question",
        &out,
    );
    let (_, err) = text(&out);
    assert_has(&err, "Make the change? [y/N]");
    assert_has(&err, "nothing is changed while a motor turns");
    assert_eq!(out.status.code(), Some(1));
    assert!(bus.writes().is_empty(), "{:?}", bus.writes());
}

/// set-id is not sent to an ESC turning from the start, nor to one that starts after the
/// first listen.
#[test]
fn set_id_is_refused_while_its_esc_turns() {
    for ms in [0, 1300] {
        let bus = one(Esc {
            turns_after: Some(Duration::from_millis(ms)),
            ..Esc::new(12, 2)
        });
        refused_unwritten(
            &bus,
            "set-id {spec} --node 12 --to 40 --channel 2 --yes",
            "node 12 reports rpm 3000, pwm 400",
        );
    }
}

#[test]
fn a_standard_esc_turning_stops_set_set_id_and_self_test() {
    let bus = Bus::start(vec![
        Node::Hobbywing(Esc::new(10, 1)),
        Node::Standard {
            node: 30,
            rpm: 5000,
            current: 10.0,
        },
    ]);
    for args in [
        "set {spec} --node 10 --direction ccw --yes",
        "set-id {spec} --node 10 --to 20 --channel 2 --yes",
        "self-test {spec} --node 10",
    ] {
        refused_unwritten(&bus, args, "node 30 reports rpm 5000, 10.0 A");
    }
}

#[test]
fn set_id_hears_a_node_sending_node_status_at_1_hz_and_source_is_refused_as_it() {
    let bus = Bus::start(vec![
        Node::Hobbywing(Esc::new(10, 1)),
        Node::Gps { node: 20 },
    ]);
    let out = can(&format!(
        "set-id {} --node 10 --to 20 --channel 1 --yes",
        bus.spec
    ));
    assert_fails_with(&out, "node 20 is already on");
    refused_unwritten(&bus, "list {spec} --source 20", "node 20 is on the bus");
    assert!(
        bus.requests()
            .iter()
            .all(|r| !matches!(r.message, hwfoc::dronecan::Message::GetEscId(_))),
        "GetEscID sent as node 20"
    );
}

#[test]
fn a_write_answered_late_is_read_back() {
    let bus = one(Esc {
        answers: Answers::LateWrites(Duration::from_millis(1500)),
        ..Esc::new(10, 1)
    });
    let out = can(&format!(
        "set {} --node 10 --direction ccw --timeout 1 --yes",
        bus.spec
    ));
    show(
        "set --direction ccw, SetDirection answered 1.5 s late, --timeout 1",
        &out,
    );
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}{stderr}");
    assert_has(
        &stderr,
        "node 10 did not answer SetDirection within 1 s: the change may have been made",
    );
    assert_has(&stdout, "node 10 now says: direction ccw");
}

#[test]
fn a_later_failure_lists_the_changes_made_before_it() {
    let bus = one(Esc {
        mutes_led: true,
        ..Esc::new(10, 1)
    });
    let out = can(&format!(
        "set {} --node 10 --direction ccw --led red --timeout 0.5 --yes",
        bus.spec
    ));
    show("set --direction ccw --led red, SetLED unanswered", &out);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stdout}{stderr}");
    assert_has(&stdout, "node 10 now says: direction ccw");
    assert_has(&stderr, "did not answer SetLED within 0.5 s");
    assert_has(&stderr, "read back, it says LED green steady");
}

#[test]
fn a_read_back_that_differs_stops_the_changes() {
    let bus = one(Esc {
        keeps_direction: true,
        ..Esc::new(10, 1)
    });
    let out = can(&format!(
        "set {} --node 10 --direction ccw --led red --yes",
        bus.spec
    ));
    show(
        "set --direction ccw --led red, direction read back cw",
        &out,
    );
    assert_fails_with(
        &out,
        "node 10 was asked direction ccw but says direction cw",
    );
    // The LED was not sent after the failed read-back.
    let writes = bus.writes();
    assert_eq!(writes.len(), 1, "{writes:?}");
    assert_eq!(writes[0].to, 10);
}

#[test]
fn answers_twice_from_another_node_or_with_a_wrong_transfer_id() {
    let bus = one(Esc {
        answers: Answers::Twice,
        ..Esc::new(10, 1)
    });
    let out = can(&format!(
        "set {} --node 10 --direction ccw --led red,save --yes",
        bus.spec
    ));
    let (stdout, _) = text(&out);
    assert!(out.status.success(), "{:?}", text(&out));
    assert_has(&stdout, "node 10 now says: direction ccw");
    // "saved" is not what the ESC said: it cannot report it.
    assert_has(&stdout, "node 10 now says: LED red steady\n");
    assert_has(&stdout, "cannot be read back");
    for answers in [Answers::FromNode(30), Answers::WrongTransferId] {
        let bus = one(Esc {
            answers,
            ..Esc::new(10, 1)
        });
        refused_unwritten(
            &bus,
            "set {spec} --node 10 --led blue --timeout 0.5 --yes",
            "node 10 did not answer GetMajorConfig within 0.5 s",
        );
    }
}

#[test]
fn a_set_id_not_applied_says_so() {
    let bus = one(Esc {
        ignores_set_id: true,
        ..Esc::new(12, 2)
    });
    let out = can(&format!(
        "set-id {} --node 12 --to 40 --channel 2 --yes",
        bus.spec
    ));
    assert_fails_with(
        &out,
        "node 12 still answers as node 12: SetID was not applied",
    );
}

#[test]
fn set_id_answered_late_is_read_back_at_the_new_node() {
    let bus = one(Esc {
        answers: Answers::LateWrites(Duration::from_millis(1500)),
        ..Esc::new(12, 2)
    });
    let out = can(&format!(
        "set-id {} --node 12 --to 40 --channel 3 --yes",
        bus.spec
    ));
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}{stderr}");
    assert_has(&stdout, "node 12 now says: node id 40, throttle channel 3");
    assert_has(&stderr, "the change may have been made");
}

#[test]
fn self_test_is_refused_on_a_factory_bus() {
    let bus = Bus::start(vec![
        Node::Hobbywing(Esc::new(1, 1)),
        Node::Hobbywing(Esc {
            self_test_fails: true,
            ..Esc::new(1, 1)
        }),
        Node::Hobbywing(Esc {
            self_test_fails: true,
            ..Esc::new(1, 1)
        }),
    ]);
    refused_unwritten(
        &bus,
        "self-test {spec} --node 1",
        "ESCs answer as node 1 (the factory state)",
    );
}

#[test]
fn list_asks_nothing_while_an_esc_turns() {
    let bus = Bus::start(vec![
        Node::Hobbywing(Esc::new(10, 1)),
        Node::Hobbywing(Esc {
            turns_after: Some(Duration::ZERO),
            ..Esc::new(11, 2)
        }),
    ]);
    let out = can(&format!("list {}", bus.spec));
    let (stdout, _) = text(&out);
    assert!(out.status.success(), "{stdout}");
    assert!(bus.requests().is_empty(), "{:?}", bus.requests());
    assert_has(&stdout, "a motor turns: nothing asked");
}

#[test]
fn list_flags_two_escs_on_one_throttle_channel_and_names_the_bit_rate_when_empty() {
    let bus = Bus::start(vec![
        Node::Hobbywing(Esc::new(10, 1)),
        Node::Hobbywing(Esc::new(11, 1)),
    ]);
    let (stdout, _) = text(&can(&format!("list {}", bus.spec)));
    assert_has(
        &stdout,
        "nodes 10 and 11 both say throttle channel 1: both would take the same throttle",
    );
    let empty = Bus::start(vec![]);
    let out = can(&format!("list {} --listen 0.5", empty.spec));
    let (stdout, stderr) = text(&out);
    show("list, no node", &out);
    assert_has(
        &stdout,
        "no node heard at 500000 bit/s (the ESCs' factory bit rate is 500 kbit/s",
    );
    assert!(!(stdout + &stderr).to_lowercase().contains("baud"));
}

#[test]
fn nothing_is_sent_before_a_refusal_for_lack_of_a_terminal() {
    let bus = one(Esc::new(10, 1));
    let out = can(&format!("set {} --node 10 --direction ccw", bus.spec));
    assert_fails_with(&out, "--yes: no terminal to confirm");
    assert!(bus.requests().is_empty(), "{:?}", bus.requests());
}
