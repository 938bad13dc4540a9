//! Outputs as users name them: `decode -o NAME` takes its format from the name, a `--format`
//! contradicting it is refused, and every command that writes a file replaces an existing one
//! only with `--overwrite`.

mod common;

use std::process::Output;

use common::{Dir, assert_fails_with, hwfoc, ok};

fn run(args: &[&str]) -> Output {
    hwfoc().args(args).output().expect("run hwfoc")
}

/// Virtual HW-FOC ESCs' telemetry of `seconds` written to `path` (its format from its name).
fn simulate(path: &str, seconds: &str, more: &[&str]) {
    let args = [
        &["simulate", "-o", path, "--duration", seconds, "--quiet"],
        more,
    ]
    .concat();
    ok(run(&args));
}

/// `-o NAME` alone writes the format the name's extension names, in any case.
#[test]
fn decode_takes_the_format_from_the_output_name() {
    let dir = Dir::new();
    for (name, starts) in [
        ("a.parquet", &b"PAR1"[..]),
        ("b.PARQUET", b"PAR1"),
        ("c.csv", b"t_s,"),
        ("d.jsonl", b"{\""),
        ("e.ndjson", b"{\""),
    ] {
        ok(run(&["decode", "--demo", "-o", &dir.arg(name)]));
        let bytes = std::fs::read(dir.path(name)).unwrap();
        assert!(bytes.starts_with(starts), "{name}: {:?}", &bytes[..8]);
    }
}

/// An extension hwfoc does not know, without `--format`, and a `--format` that contradicts
/// the extension, are refused naming both; nothing is written.
#[test]
fn an_unknown_or_contradicted_extension_is_refused_naming_both() {
    let dir = Dir::new();
    let txt = dir.arg("out.txt");
    let o = run(&["decode", "--demo", "-o", &txt]);
    assert_fails_with(&o, "out.txt");
    assert_fails_with(&o, "--format");
    assert!(!dir.path("out.txt").exists());

    let pq = dir.arg("x.parquet");
    let o = run(&["decode", "--demo", "--format", "csv", "-o", &pq]);
    assert_fails_with(&o, "--format csv");
    assert_fails_with(&o, ".parquet");
    assert!(!dir.path("x.parquet").exists());

    // Agreeing, or a name the user chose with --format, is fine.
    ok(run(&[
        "decode",
        "--demo",
        "--format",
        "csv",
        "-o",
        &dir.arg("y.csv"),
    ]));
    ok(run(&["decode", "--demo", "--format", "csv", "-o", &txt]));
    assert!(
        std::fs::read(dir.path("out.txt"))
            .unwrap()
            .starts_with(b"t_s,")
    );
}

/// `decode` and `plot` replace an existing file only with `--overwrite`; the error says how.
#[test]
fn an_existing_output_is_replaced_only_with_overwrite() {
    let dir = Dir::new();
    for (command, name) in [("decode", "old.jsonl"), ("plot", "old.svg")] {
        let path = dir.arg(name);
        std::fs::write(&path, "mine").unwrap();
        let o = run(&[command, "--demo", "-o", &path]);
        assert_fails_with(&o, "--overwrite");
        assert_fails_with(&o, name);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "mine", "{command}");
        let left: Vec<_> = std::fs::read_dir(dir.0.path()).unwrap().collect();
        assert_eq!(left.len(), 1, "{command}: no temporary file left: {left:?}");
        ok(run(&[command, "--demo", "--overwrite", "-o", &path]));
        assert_ne!(std::fs::read_to_string(&path).unwrap(), "mine", "{command}");
        std::fs::remove_file(&path).unwrap();
    }
}

/// Ctrl-C while `decode -o` reads standard input (a pipe, its writer stopped by the same
/// Ctrl-C) leaves no temporary file, and the earlier file as it was.
#[cfg(unix)]
#[test]
fn ctrl_c_with_standard_input_leaves_no_partial_file() {
    use nix::sys::signal::{Signal, kill};
    use nix::unistd::Pid;
    use std::io::Write;
    use std::process::Stdio;
    use std::time::{Duration, Instant};
    let dir = Dir::new();
    let raw = dir.arg("run.bin");
    simulate(&raw, "20", &[]);
    let bytes = std::fs::read(&raw).unwrap();
    let out = dir.arg("out.csv");
    std::fs::write(&out, "the earlier export").unwrap();
    let mut child = common::spawn(
        hwfoc()
            .args(["decode", "-", "--overwrite", "-o", &out])
            .stdin(Stdio::piped()),
    );
    let mut stdin = child.stdin.take().unwrap();
    stdin.write_all(&bytes).unwrap();
    stdin.flush().unwrap();
    let partial = || {
        std::fs::read_dir(dir.0.path())
            .unwrap()
            .filter_map(|e| e.ok()?.file_name().into_string().ok())
            .filter(|n| n.ends_with(".partial"))
            .count()
    };
    let start = Instant::now();
    while partial() == 0 && start.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(200));
    kill(Pid::from_raw(child.id() as i32), Signal::SIGINT).unwrap();
    std::thread::sleep(Duration::from_millis(100));
    drop(stdin);
    let o = child.wait_with_output().unwrap();
    assert_fails_with(&o, "interrupted");
    assert_eq!(partial(), 0);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "the earlier export");
}

/// A bare `--from`/`--to` number more than a year before the data (`--from 5` meant as five
/// seconds in) is refused, suggesting `+N`; nothing is written.
#[test]
fn a_bare_number_long_before_the_data_suggests_plus() {
    let dir = Dir::new();
    let rec = dir.arg("run.pcapng");
    simulate(&rec, "3", &[]);
    let out = dir.arg("out.csv");
    for (option, value) in [("--from", "5"), ("--to", "10")] {
        let o = run(&["decode", &rec, option, value, "-o", &out]);
        assert_fails_with(&o, &format!("{option} {value}"));
        assert_fails_with(&o, &format!("+{value}"));
        assert!(!dir.path("out.csv").exists());
    }
    // Seconds of the data's own clock are fine.
    let first = run(&["decode", &rec, "--format", "csv"]);
    let t: f64 = String::from_utf8(first.stdout)
        .unwrap()
        .lines()
        .nth(1)
        .unwrap()[..17]
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    ok(run(&[
        "decode",
        &rec,
        "--from",
        &format!("{}", t.floor()),
        "-o",
        &out,
    ]));
}

/// `--time iso` writes CSV's receive times as ISO 8601 dates in UTC (a `time` column, to the
/// microsecond) for spreadsheets; for other formats, or inputs without a wall clock, it is
/// refused.
#[test]
fn csv_times_as_iso_dates() {
    let dir = Dir::new();
    let rec = dir.arg("run.pcapng");
    simulate(&rec, "2", &["--start-time", "1795442580"]);
    let seconds = String::from_utf8(ok(run(&["decode", &rec, "--format", "csv"])).stdout).unwrap();
    let iso =
        String::from_utf8(ok(run(&["decode", &rec, "--format", "csv", "--time", "iso"])).stdout)
            .unwrap();
    assert!(iso.starts_with("time,esc,protocol,"), "{iso}");
    assert_eq!(seconds.lines().count(), iso.lines().count());
    for (s, i) in seconds.lines().zip(iso.lines()).skip(1) {
        let (t, rest) = s.split_once(',').unwrap();
        let (date, same) = i.split_once(',').unwrap();
        assert_eq!(rest, same);
        // Microseconds after 2026-11-23T14:03:00Z.
        let t: f64 = t.parse().unwrap();
        let m = (t * 1e6).round() as i64 - 1_795_442_580_000_000;
        let expected = format!(
            "2026-11-23T14:{:02}:{:02}.{:06}Z",
            3 + m / 60_000_000,
            m / 1_000_000 % 60,
            m % 1_000_000
        );
        assert_eq!(date, expected, "{s}");
    }
    let o = run(&["decode", &rec, "--time", "iso", "-o", &dir.arg("x.parquet")]);
    assert_fails_with(&o, "--time iso");
    let o = run(&["decode", "--demo", "--format", "csv", "--time", "iso"]);
    assert_fails_with(&o, "no wall clock");
}
