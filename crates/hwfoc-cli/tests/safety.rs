//! Nothing a user has is destroyed: an output that is an input is refused, an export is written
//! under a partial name and renamed into place when complete, so that a killed export leaves the
//! earlier file as it was.

mod common;

use std::io::Write;
use std::process::Stdio;
use std::time::{Duration, Instant};

use common::{Dir, XROTOR, assert_fails_with, capture, hwfoc, ok, run, spawn};

/// The bytes of the real capture, as a raw file and as a CSV file in `dir`.
fn inputs(dir: &Dir) -> (String, String) {
    let csv = dir.arg("cap.csv");
    std::fs::copy(capture(XROTOR), &csv).unwrap();
    let raw = dir.arg("cap.bin");
    let out = ok(run(hwfoc().args([
        "simulate",
        "-o",
        &raw,
        "--duration",
        "3",
    ])));
    assert!(out.status.success());
    (csv, raw)
}

#[test]
fn an_output_that_is_an_input_is_refused_and_the_input_kept() {
    let dir = Dir::new();
    let (csv, raw) = inputs(&dir);
    let before_csv = std::fs::read(&csv).unwrap();
    let before_raw = std::fs::read(&raw).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(&raw, dir.path("link.bin")).unwrap();
    let dot = format!("{}/./cap.bin", dir.0.path().display());
    let mut cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["decode".into(), csv.clone(), "-o".into(), csv.clone()],
            &csv,
        ),
        (
            vec![
                "decode".into(),
                "--format".into(),
                "parquet".into(),
                raw.clone(),
                "-o".into(),
                dot.clone(),
            ],
            &raw,
        ),
        (
            vec![
                "decode".into(),
                "--format".into(),
                "csv".into(),
                csv.clone(),
                raw.clone(),
                "-o".into(),
                raw.clone(),
            ],
            &raw,
        ),
        (
            vec!["plot".into(), csv.clone(), "-o".into(), csv.clone()],
            &csv,
        ),
        (
            vec!["summary".into(), raw.clone(), "--plot".into(), raw.clone()],
            &raw,
        ),
    ];
    #[cfg(unix)]
    cases.push((
        vec![
            "decode".into(),
            raw.clone(),
            "-o".into(),
            dir.arg("link.bin"),
        ],
        &raw,
    ));
    for (args, input) in &cases {
        let out = run(hwfoc().args(args));
        assert_fails_with(
            &out,
            &format!("it is the input {input}, which would be destroyed"),
        );
        assert!(!dir.path("cap.bin.partial").exists(), "{args:?}");
    }
    assert_eq!(std::fs::read(&csv).unwrap(), before_csv);
    assert_eq!(std::fs::read(&raw).unwrap(), before_raw);
}

#[test]
fn a_finished_export_replaces_the_file_and_leaves_no_partial_file() {
    let dir = Dir::new();
    let (csv, _) = inputs(&dir);
    let out = dir.arg("out.jsonl");
    std::fs::write(&out, "an earlier export\n").unwrap();
    ok(run(hwfoc().args(["decode", &csv, "-o", &out])));
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(text.lines().count(), 248);
    assert!(!dir.path("out.jsonl.partial").exists());
    // Through a link, the file it points to is replaced and the link stays.
    #[cfg(unix)]
    {
        let link = dir.path("link.jsonl");
        std::os::unix::fs::symlink(&out, &link).unwrap();
        std::fs::write(&out, "old\n").unwrap();
        ok(run(hwfoc().args([
            "decode",
            &csv,
            "-o",
            link.to_str().unwrap(),
        ])));
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read_to_string(&out).unwrap(), text);
    }
    // A device is written as it is (no partial file beside /dev/null).
    ok(run(hwfoc().args(["decode", &csv, "-o", "/dev/null"])));
}

/// An export killed part-way (here: its input still arriving on standard input) has not
/// touched the earlier file at the path; what it wrote is in the partial file.
#[cfg(unix)]
#[test]
fn a_killed_export_leaves_the_earlier_file() {
    let dir = Dir::new();
    let (_, raw) = inputs(&dir);
    let bytes = std::fs::read(&raw).unwrap();
    for format in ["parquet", "csv"] {
        let out = dir.arg(&format!("out.{format}"));
        std::fs::write(&out, "the earlier export").unwrap();
        let mut child = spawn(
            hwfoc()
                .args(["decode", "--format", format, "-", "-o", &out])
                .stdin(Stdio::piped()),
        );
        let mut stdin = child.stdin.take().unwrap();
        stdin.write_all(&bytes).unwrap();
        stdin.flush().unwrap();
        let partial = dir.path(&format!("out.{format}.partial"));
        let start = Instant::now();
        while !partial.exists() && start.elapsed() < Duration::from_secs(30) {
            std::thread::sleep(Duration::from_millis(20));
        }
        assert!(partial.exists(), "no partial file for {format}");
        child.kill().unwrap();
        child.wait().unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "the earlier export");
        drop(stdin);
    }
}

#[test]
fn a_directory_as_output_is_refused() {
    let dir = Dir::new();
    let (csv, _) = inputs(&dir);
    let out = run(hwfoc().args(["decode", &csv, "-o", &dir.arg("")]));
    assert_fails_with(&out, "it is a directory, not a file");
}

/// `hwfoc record` of a pty for `seconds`, with `extra` options; its output.
#[cfg(unix)]
fn record(port: &str, out: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["record", port, "-o", out, "--duration", "0.3"];
    args.extend_from_slice(extra);
    run(hwfoc().args(&args))
}

#[cfg(unix)]
#[test]
fn a_recording_is_never_overwritten_unasked() {
    let dir = Dir::new();
    let port = common::pty();
    let port = port.path.to_str().unwrap().to_string();
    let out = dir.arg("rec.pcapng");
    ok(record(&port, &out, &[]));
    let first = std::fs::read(&out).unwrap();
    let again = record(&port, &out, &[]);
    assert_fails_with(&again, "rec.pcapng exists and is never overwritten unasked");
    assert_eq!(std::fs::read(&out).unwrap(), first);
    std::fs::write(&out, "stale").unwrap();
    ok(record(&port, &out, &["--overwrite"]));
    assert!(
        std::fs::read(&out)
            .unwrap()
            .starts_with(&[0x0A, 0x0D, 0x0D, 0x0A])
    );

    // A rotated series: a second run is refused while any file of the first is there; with
    // --overwrite the earlier series goes first, so no series mixes two runs.
    let base = dir.arg("run.pcapng");
    ok(record(&port, &base, &["--rotate-time", "10"]));
    assert!(dir.path("run-0001.pcapng").exists());
    std::fs::rename(dir.path("run-0001.pcapng"), dir.path("run-0003.pcapng")).unwrap();
    std::fs::write(dir.path("run-notes.txt"), "mine").unwrap();
    assert_fails_with(
        &record(&port, &base, &["--rotate-time", "10"]),
        "run-0003.pcapng exists and is never overwritten unasked",
    );
    ok(record(
        &port,
        &base,
        &["--rotate-time", "10", "--overwrite"],
    ));
    assert!(dir.path("run-0001.pcapng").exists());
    assert!(!dir.path("run-0003.pcapng").exists());
    assert_eq!(
        std::fs::read_to_string(dir.path("run-notes.txt")).unwrap(),
        "mine"
    );

    // The monitor's --record likewise.
    let monitor = |extra: &[&str]| {
        let mut args = vec![
            "monitor",
            "--sim",
            "1",
            "--plain",
            "--no-config",
            "--duration",
            "0.3",
        ];
        args.extend_from_slice(&["--record", &out]);
        args.extend_from_slice(extra);
        run(hwfoc().args(&args))
    };
    let before = std::fs::read(&out).unwrap();
    assert_fails_with(
        &monitor(&[]),
        "rec.pcapng exists and is never overwritten unasked",
    );
    assert_eq!(std::fs::read(&out).unwrap(), before);
    std::fs::write(&out, "stale").unwrap();
    ok(monitor(&["--overwrite"]));
    assert!(
        std::fs::read(&out)
            .unwrap()
            .starts_with(&[0x0A, 0x0D, 0x0D, 0x0A])
    );
}

#[test]
fn the_ground_truth_never_lands_on_the_recording() {
    let dir = Dir::new();
    let out = dir.arg("run.pcapng");
    std::fs::write(&out, "keep me").unwrap();
    let o = run(hwfoc().args(["simulate", "-o", &out, "--truth", &out]));
    assert_fails_with(&o, "is also the output -o");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "keep me");
    // Through another path to the same file, and with one file per ESC.
    let dot = format!("{}/./run.pcapng", dir.0.path().display());
    let o = run(hwfoc().args(["simulate", "-o", &dot, "--truth", &out]));
    assert_fails_with(&o, "is also the output -o");
    let per_esc = dir.arg("esc{esc}.bin");
    let o = run(hwfoc().args([
        "simulate",
        "--escs",
        "3",
        "-o",
        &per_esc,
        "--truth",
        &dir.arg("esc2.bin"),
    ]));
    assert_fails_with(&o, "is also the output -o");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "keep me");
}

#[test]
fn a_simulated_recording_never_overwrites_a_file_unasked() {
    let dir = Dir::new();
    let out = dir.arg("run.pcapng");
    std::fs::write(&out, "keep me").unwrap();
    let o = run(hwfoc().args(["simulate", "-o", &out, "--duration", "1"]));
    assert_fails_with(&o, "run.pcapng exists and is never overwritten unasked");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "keep me");
    // One file per ESC: the third exists, so none is written (nor the truth).
    let per_esc = dir.arg("esc{esc}.bin");
    std::fs::write(dir.path("esc2.bin"), "keep me too").unwrap();
    let truth = dir.arg("truth.jsonl");
    let args = [
        "simulate",
        "--escs",
        "3",
        "-o",
        &per_esc,
        "--truth",
        &truth,
        "--duration",
        "1",
    ];
    let o = run(hwfoc().args(args));
    assert_fails_with(&o, "esc2.bin exists and is never overwritten unasked");
    assert_eq!(
        std::fs::read_to_string(dir.path("esc2.bin")).unwrap(),
        "keep me too"
    );
    assert!(!dir.path("esc0.bin").exists() && !dir.path("truth.jsonl").exists());
    // Asked: written over.
    ok(run(hwfoc().args(args).arg("--overwrite")));
    let bytes = std::fs::read(dir.path("esc2.bin")).unwrap();
    assert!(
        bytes.len() >= 24 && !bytes.starts_with(b"keep me"),
        "{bytes:?}"
    );
    ok(run(hwfoc().args([
        "simulate",
        "-o",
        &out,
        "--duration",
        "1",
        "--overwrite",
    ])));
    assert!(
        std::fs::read(&out)
            .unwrap()
            .starts_with(&[0x0A, 0x0D, 0x0D, 0x0A])
    );
}

#[test]
fn a_plot_is_written_whole_to_a_file_and_not_to_a_device() {
    let dir = Dir::new();
    let (csv, _) = inputs(&dir);
    let png = dir.arg("p.png");
    std::fs::write(&png, "an earlier plot").unwrap();
    ok(run(hwfoc().args(["plot", &csv, "-o", &png])));
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    assert!(!dir.path("p.png.partial").exists());
    #[cfg(unix)]
    {
        let link = dir.path("dev.svg");
        std::os::unix::fs::symlink("/dev/null", &link).unwrap();
        let o = run(hwfoc().args(["plot", &csv, "-o", link.to_str().unwrap()]));
        assert_fails_with(&o, "it is a device or a pipe, not a file");
    }
    // A plot that fails (nothing to plot) leaves the earlier file and no partial file.
    let empty = dir.arg("empty.bin");
    std::fs::write(&empty, [0u8; 100]).unwrap();
    let o = run(hwfoc().args(["plot", &empty, "-o", &png]));
    assert!(!o.status.success());
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    assert!(!dir.path("p.png.partial").exists());
}

/// A directory the user may not write: the error says so and where to write instead. As root
/// (CI), the command runs as `nobody`, who may not write there either.
#[cfg(unix)]
#[test]
fn permission_denied_on_an_output_says_so() {
    use std::os::unix::fs::PermissionsExt;
    let dir = Dir::new();
    // The directory must be reachable by `nobody`, and not writable.
    std::fs::set_permissions(dir.0.path(), std::fs::Permissions::from_mode(0o755)).unwrap();
    let locked = dir.path("locked");
    std::fs::create_dir(&locked).unwrap();
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).unwrap();
    let target = locked.join("out.csv");
    let target = target.to_str().unwrap();
    let o = common::run(
        common::hwfoc_unprivileged().args(["decode", "--demo", "--format", "csv", "-o", target]),
    );
    assert_fails_with(
        &o,
        &format!("cannot write {target}: permission denied (choose another place with -o)"),
    );
}

/// Every command words a missing output directory the same way.
#[test]
fn a_missing_output_directory_is_worded_once() {
    let csv = capture(XROTOR);
    let csv = csv.to_str().unwrap();
    let cases: [&[&str]; 7] = [
        &["decode", csv, "-o", "/nonexistent-hwfoc/x.csv"],
        &[
            "decode",
            "--format",
            "parquet",
            csv,
            "-o",
            "/nonexistent-hwfoc/x.csv",
        ],
        &["plot", csv, "-o", "/nonexistent-hwfoc/x.png"],
        &["summary", csv, "--plot", "/nonexistent-hwfoc/x.svg"],
        &["simulate", "-o", "/nonexistent-hwfoc/x.csv"],
        &["simulate", "-o", "-", "--truth", "/nonexistent-hwfoc/x.csv"],
        &[
            "monitor",
            "--sim",
            "1",
            "--plain",
            "--duration",
            "1",
            "--record",
            "/nonexistent-hwfoc/x.csv",
        ],
    ];
    for args in cases {
        let o = run(hwfoc().args(args).stdout(Stdio::null()));
        assert_fails_with(&o, "the directory /nonexistent-hwfoc does not exist");
    }
}
