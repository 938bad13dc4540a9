//! Recordings whose receive clock steps back (NTP) or jumps forward (a computer that booted
//! in 1970 and then synced): `summary`, `plot` and the bridge's replay treat each as a
//! discontinuity (`hwfoc_ports::clock::Step`), never as a negative or a centuries-long span.

mod common;

use std::process::Output;
use std::time::Duration;

use common::{Dir, Running, hwfoc, ok, stdout};
use hwfoc::foc::DataFrame;
use hwfoc_io::pcapng;
use serde_json::Value;

/// 2026-11-23T14:03:00Z.
const T0: u64 = 1_795_442_580;
const NS: u64 = 1_000_000_000;

fn run(args: &[&str]) -> Output {
    hwfoc().args(args).output().expect("run hwfoc")
}

/// A recording of one ESC drawing 36 A at 25 V: a frame every 50 ms, packets counting up,
/// each stamped by `time(k)` ns.
fn recording(dir: &Dir, name: &str, frames: u64, time: impl Fn(u64) -> u64) -> String {
    let mut w = pcapng::Writer::new(Vec::new()).unwrap();
    w.add_interface("/dev/ttyUSB0", 19200).unwrap();
    for k in 0..frames {
        let frame = DataFrame {
            packet: k as u16,
            voltage_raw: 250,
            current_raw: 36 * 64,
            ..Default::default()
        }
        .encode();
        w.write(0, time(k), &frame).unwrap();
    }
    let path = dir.arg(name);
    std::fs::write(&path, w.into_inner().unwrap()).unwrap();
    path
}

/// 200 frames over 9.95 s, the 101st stamped in the year 2226.
fn jumped(dir: &Dir) -> String {
    recording(dir, "jumped.pcapng", 200, |k| match k {
        100 => 8_000_000_000 * NS,
        _ => T0 * NS + k * 50_000_000,
    })
}

/// 200 frames, the clock set back an hour after the 100th.
fn stepped_back(dir: &Dir) -> String {
    recording(dir, "back.pcapng", 200, |k| {
        T0 * NS + k * 50_000_000 - if k >= 100 { 3600 * NS } else { 0 }
    })
}

fn summary_json(path: &str) -> Value {
    let o = ok(run(&["summary", "--json", path]));
    serde_json::from_str(&stdout(&o)).unwrap()
}

#[test]
fn energy_is_never_integrated_across_a_jumped_timestamp() {
    let dir = Dir::new();
    let s = summary_json(&jumped(&dir));
    let esc = &s["escs"][0];
    // 199 steps of 50 ms, two of them (to and from the late frame) discontinuities.
    let seconds = esc["energy"]["seconds"].as_f64().unwrap();
    assert!((seconds - 9.85).abs() < 1e-6, "{esc}");
    assert!(
        (esc["duration_s"].as_f64().unwrap() - 9.85).abs() < 1e-6,
        "{esc}"
    );
    assert_eq!(esc["clock_jumps"], 1, "{esc}");
    assert_eq!(esc["clock_steps_back"], 1, "{esc}");
    let text = stdout(&ok(run(&["summary", &jumped(&dir)])));
    assert!(text.contains("over 9.850 s"), "{text}");
    assert!(
        text.contains("the clock steps back once and jumps forward once"),
        "{text}"
    );
}

#[test]
fn a_clock_set_back_gives_no_negative_duration() {
    let dir = Dir::new();
    let path = stepped_back(&dir);
    let text = stdout(&ok(run(&["summary", &path])));
    assert!(!text.contains("(-"), "{text}");
    assert!(text.contains("(9.900 s)"), "{text}");
    assert!(
        text.contains("clock        the clock steps back once"),
        "{text}"
    );
    let esc = &summary_json(&path)["escs"][0];
    assert!(
        (esc["duration_s"].as_f64().unwrap() - 9.9).abs() < 1e-6,
        "{esc}"
    );
}

#[test]
fn plots_of_a_clock_that_steps_back_or_jumps_are_drawn() {
    let dir = Dir::new();
    for path in [stepped_back(&dir), jumped(&dir)] {
        let png = format!("{path}.png");
        ok(run(&["plot", &path, "-o", &png]));
        assert!(std::fs::metadata(&png).unwrap().len() > 0);
        let svg = format!("{path}.svg");
        ok(run(&["summary", &path, "--plot", &svg]));
        let image = std::fs::read_to_string(&svg).unwrap();
        assert!(image.contains("clock discontinuit"), "{path}");
    }
    let help = stdout(&ok(run(&["plot", "--help"])));
    assert!(help.contains("steps back"), "{help}");
}

/// `hwfoc bridge` replaying `frames` frames 50 ms apart, frame `late` stamped in 2226, to
/// MAVLink on a local UDP socket (returned, so that it stays open).
fn replay_jumped(dir: &Dir, frames: u64, late: u64) -> (Running, std::net::UdpSocket) {
    let path = recording(dir, "replay.pcapng", frames, |k| match k {
        k if k == late => 8_000_000_000 * NS,
        _ => T0 * NS + k * 50_000_000,
    });
    let sink = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let port = sink.local_addr().unwrap().port();
    let bridge = Running::start(&[
        "bridge",
        &path,
        "--mavlink",
        &format!("udp:127.0.0.1:{port}"),
    ]);
    (bridge, sink)
}

#[test]
fn a_replay_goes_on_past_a_packet_stamped_in_2226() {
    let dir = Dir::new();
    let (mut bridge, _sink) = replay_jumped(&dir, 60, 30);
    // 60 frames 50 ms apart: 3 s.
    assert!(bridge.wait(Duration::from_secs(30)), "{}", bridge.stderr());
    assert!(
        bridge.stderr().contains(" 60 frames of 1 ESC"),
        "{}",
        bridge.stderr()
    );
}

#[test]
fn ctrl_c_ends_a_replay_past_a_jump() {
    use nix::sys::signal::Signal;
    let dir = Dir::new();
    // Ten minutes of frames; the 21st stamped in 2226.
    let (mut bridge, _sink) = replay_jumped(&dir, 12_000, 20);
    // 50 ms a frame: three seconds: past the jump at 1 s, frames keep coming.
    std::thread::sleep(Duration::from_secs(3));
    bridge.signal(Signal::SIGINT);
    assert!(bridge.wait(Duration::from_secs(10)), "{}", bridge.stderr());
    let err = bridge.stderr();
    let line = err
        .lines()
        .find(|l| l.starts_with("hwfoc bridge: "))
        .unwrap_or_else(|| panic!("{err}"));
    let frames: u64 = line
        .split(", ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(frames > 40, "{line}");
}
