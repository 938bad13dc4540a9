//! Which ESC is which across inputs, as a user sees it: drones recorded at the same time on
//! ports named alike, CAN logs of other buses, a file given twice, `--join`.

mod common;

use common::{Dir, hwfoc, ok, stdout};

/// Runs `hwfoc ARGS`, which must succeed: standard output and standard error.
fn run(args: &[&str]) -> (String, String) {
    let o = ok(hwfoc().args(args).output().unwrap());
    (
        String::from_utf8(o.stdout.clone()).unwrap(),
        String::from_utf8(o.stderr).unwrap(),
    )
}

/// The README's fleet: three drones of two ESCs each, recorded at the same time (the simulator
/// names their ports esc-0 and esc-1, as every drone would), summarised and decoded together,
/// give the six ESCs of the three files read alone.
#[test]
fn three_drones_recorded_together_are_six_escs() {
    let dir = Dir::new();
    let files: Vec<String> = (1..=3)
        .map(|i| simulate(&dir, &format!("drone-{i}.pcapng"), i, &["--duration", "10"]))
        .collect();
    let alone: Vec<Vec<String>> = files
        .iter()
        .map(|f| run(&["decode", f]).0.lines().map(str::to_string).collect())
        .collect();
    let mut args = vec!["decode"];
    args.extend(files.iter().map(String::as_str));
    let (together, err) = run(&args);
    let together: Vec<&str> = together.lines().collect();
    assert_eq!(together.len(), alone.iter().map(Vec::len).sum::<usize>());
    // ESC for ESC, the records of the file alone: drone k's ESC e is ESC 2k + e.
    for (k, lines) in alone.iter().enumerate() {
        for e in 0..2 {
            let mine: Vec<String> = records_of(&together, 2 * k + e);
            let theirs: Vec<String> = records_of(lines, e);
            assert_eq!(mine.len(), theirs.len(), "drone {k} ESC {e}");
            for (a, b) in mine.iter().zip(&theirs) {
                assert_eq!(without_esc(a), without_esc(b));
            }
        }
    }
    assert!(!err.contains("overlaps"), "{err}");
    assert_eq!(
        err.matches("are of another recording, so other ESCs")
            .count(),
        2,
        "{err}"
    );
    let mut args = vec!["summary"];
    args.extend(files.iter().map(String::as_str));
    let (summary, _) = run(&args);
    for k in 0..6 {
        let header = format!("ESC {k}        ");
        assert!(summary.contains(&header), "{summary}");
    }
    assert!(
        summary.contains("drone-2.pcapng: esc-0 (ESC 2)"),
        "{summary}"
    );
    // --join reads them as one recording, as asked: two ESCs.
    args.insert(1, "--join");
    let (joined, _) = run(&args);
    assert!(
        joined.contains("ESC 1 ") && !joined.contains("ESC 2 "),
        "{joined}"
    );
}

/// Simulates two ESCs with seed `seed` and `args` into `name` in `dir`: its path.
fn simulate(dir: &Dir, name: &str, seed: u32, args: &[&str]) -> String {
    let path = dir.arg(name);
    let seed = seed.to_string();
    ok(hwfoc()
        .args(["simulate", "--escs", "2", "--seed", &seed])
        .args(args)
        .args(["-o", &path])
        .output()
        .unwrap());
    path
}

/// The records of ESC `esc` among JSON Lines `lines`.
fn records_of<S: AsRef<str>>(lines: &[S], esc: usize) -> Vec<String> {
    let key = format!("\"esc\":{esc},");
    lines
        .iter()
        .map(AsRef::as_ref)
        .filter(|l| l.contains(&key))
        .map(str::to_string)
        .collect()
}

/// A JSON Lines record without its `esc` field.
fn without_esc(line: &str) -> String {
    let v: serde_json::Value = serde_json::from_str(line).unwrap();
    let mut o = v.as_object().unwrap().clone();
    o.remove("esc");
    serde_json::Value::Object(o).to_string()
}

/// Two CAN buses logged apart (candump logs name no recording) give each bus's records; the
/// same log given twice is read once, with a warning.
#[test]
fn two_can_logs_are_two_buses_and_a_copy_is_read_once() {
    let dir = Dir::new();
    let logs: Vec<String> = (1..=2)
        .map(|i| {
            let args = ["--protocol", "hw-can", "--duration", "5"];
            simulate(&dir, &format!("bus-{i}.log"), i, &args)
        })
        .collect();
    let count = |args: &[&str]| run(args).0.lines().count();
    let (a, b) = (count(&["decode", &logs[0]]), count(&["decode", &logs[1]]));
    assert_eq!(count(&["decode", &logs[0], &logs[1]]), a + b);
    let copy = dir.arg("copy.log");
    std::fs::copy(&logs[0], &copy).unwrap();
    let (out, err) = run(&["decode", &logs[0], &copy]);
    assert_eq!(out.lines().count(), a);
    assert!(err.contains("copy.log holds the same bytes as"), "{err}");
    let summary = stdout(&hwfoc().args(["summary", &logs[0], &copy]).output().unwrap());
    assert!(summary.contains("the same bytes as"), "{summary}");
}

/// A raw file (no times) given twice is read once too, and takes no second ESC.
#[test]
fn a_raw_file_given_twice_is_one_esc() {
    let dir = Dir::new();
    let raw = dir.arg("flight.bin");
    ok(hwfoc()
        .args(["simulate", "--duration", "5", "-o", &raw])
        .output()
        .unwrap());
    let (alone, _) = run(&["decode", &raw]);
    let (twice, err) = run(&["decode", &raw, &raw]);
    assert_eq!(twice, alone);
    assert!(err.contains("holds the same bytes as"), "{err}");
    let (summary, _) = run(&["summary", &raw, &raw]);
    assert!(!summary.contains("ESC 1"), "{summary}");
}
