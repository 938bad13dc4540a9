//! Values that cannot be represented are refused with their valid range, and nothing spins:
//! every loop ends on time, on --duration and on SIGTERM.

mod common;

use std::time::{Duration, Instant};

use common::{hwfoc, ok, run};

/// A clap refusal: exit code 2, the option's name and the reason on standard error.
fn refused(args: &[&str], needle: &str) {
    let o = run(hwfoc().args(args));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.contains(needle), "{args:?}: {needle:?} not in {err}");
}

#[test]
fn intervals_and_durations_have_a_range() {
    refused(
        &["monitor", "--sim", "1", "--plain", "--interval", "1e-8"],
        "the interval must be from 0.05 to 86400 seconds",
    );
    refused(
        &["monitor", "--sim", "1", "--plain", "--duration", "1e300"],
        "at most 1000000000 seconds",
    );
    refused(
        &[
            "record",
            "/dev/ttyUSB9",
            "-o",
            "x.pcapng",
            "--duration",
            "1e300",
        ],
        "at most",
    );
    // A file a second at most: --rotate-time 0.001 wrote about 38 files a second.
    for (seconds, needle) in [
        ("inf", "not a positive"),
        ("0.001", "--rotate-time is at least 1 second"),
    ] {
        let record = ["record", "/dev/ttyUSB9", "-o", "x.pcapng"];
        refused(&[&record[..], &["--rotate-time", seconds]].concat(), needle);
    }
}

#[test]
fn simulated_times_fit_the_recording_clock() {
    let dir = common::Dir::new();
    let out = dir.arg("x.pcapng");
    refused(
        &["simulate", "-o", &out, "--start-time", "1e11"],
        "the start time must be from 0 to 10000000000 Unix seconds",
    );
    refused(&["simulate", "-o", &out, "--duration", "1e300"], "at most");
    // The latest start and a long run still give increasing, exact times.
    ok(run(hwfoc().args([
        "simulate",
        "-o",
        &out,
        "--start-time",
        "1e10",
        "--duration",
        "3",
    ])));
    let o = ok(run(hwfoc().args(["decode", &out, "--format", "csv"])));
    let text = String::from_utf8_lossy(&o.stdout);
    let t: Vec<f64> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert!(t.len() > 5 && t.windows(2).all(|w| w[1] > w[0]), "{t:?}");
    assert!(t[0] >= 1e10 && t[t.len() - 1] < 1e10 + 3.0, "{t:?}");
}

/// The shortest interval prints a line per ESC about every 50 ms and stops on --duration.
#[test]
fn the_shortest_interval_stops_on_time() {
    let start = Instant::now();
    let o = ok(run(hwfoc().args([
        "monitor",
        "--sim",
        "1",
        "--plain",
        "--no-config",
        "--interval",
        "0.05",
        "--duration",
        "1",
    ])));
    assert!(start.elapsed() < Duration::from_secs(20));
    let lines = String::from_utf8_lossy(&o.stdout).lines().count();
    assert!((5..=25).contains(&lines), "{lines} lines");
}

/// SIGTERM ends the headless monitor at its shortest interval, with the usual exit.
#[cfg(unix)]
#[test]
fn sigterm_stops_the_shortest_interval() {
    use nix::sys::signal::Signal;
    let mut m = common::Running::start(&[
        "monitor",
        "--sim",
        "2",
        "--plain",
        "--no-config",
        "--interval",
        "0.05",
    ]);
    m.wait_for_stdout("esc1", Duration::from_secs(20));
    m.signal(Signal::SIGTERM);
    assert!(
        m.wait(Duration::from_secs(10)),
        "still running: {}",
        m.stderr()
    );
}

/// A configuration file or a throttle profile that is endless (a device) or too large is an
/// error, not all the memory there is.
#[cfg(unix)]
#[test]
fn endless_files_are_refused() {
    let dir = common::Dir::new();
    let o = run(hwfoc().args(["monitor", "--sim", "1", "--plain", "--config", "/dev/zero"]));
    common::assert_fails_with(
        &o,
        "cannot open /dev/zero: it is a device, not a regular file",
    );
    let out = dir.arg("x.bin");
    let o = run(hwfoc().args(["simulate", "--profile", "csv:/dev/zero", "-o", &out]));
    common::assert_fails_with(
        &o,
        "cannot open /dev/zero: it is a device, not a regular file",
    );
    // A regular file larger than such a file is (sparse: nothing is written).
    let big = dir.path("big.toml");
    std::fs::File::create(&big)
        .and_then(|f| f.set_len((1 << 20) + 1))
        .unwrap();
    let o = run(hwfoc().args(["summary", "--demo", "--config", big.to_str().unwrap()]));
    common::assert_fails_with(&o, "big.toml: it is larger than 1024 KiB");
}

/// Settings whose conversions cannot be represented are refused with their range, by every
/// command that converts.
#[test]
fn settings_out_of_range_are_refused_with_the_range() {
    for args in [
        &["simulate", "--current-scale", "1e-38", "-o", "-"][..],
        &["decode", "--demo", "--current-scale", "1e-38"],
        &["summary", "--demo", "--gear-ratio", "1e-30"],
    ] {
        let o = run(hwfoc().args(args));
        common::assert_fails_with(&o, "invalid setting:");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(" from ") && err.contains(" to "), "{err}");
    }
}
