//! Nothing a user has is destroyed: an output that is an input is refused, an export is written
//! under a partial name and renamed into place when complete, so that a killed export leaves the
//! earlier file as it was.

mod common;

use std::io::Write;
use std::process::Stdio;
use std::time::{Duration, Instant};

use common::{Dir, XROTOR, assert_fails_with, capture, hwfoc, ok, run, spawn, stdout};

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
        assert!(partials(&dir).is_empty(), "{args:?}");
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
    ok(run(hwfoc().args([
        "decode",
        &csv,
        "--overwrite",
        "-o",
        &out,
    ])));
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(text.lines().count(), 248);
    assert!(partials(&dir).is_empty());
    // Through a link, the file it points to is replaced and the link stays.
    #[cfg(unix)]
    {
        let link = dir.path("link.jsonl");
        std::os::unix::fs::symlink(&out, &link).unwrap();
        std::fs::write(&out, "old\n").unwrap();
        ok(run(hwfoc().args([
            "decode",
            &csv,
            "--overwrite",
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
                .args(["decode", "--format", format, "-", "--overwrite", "-o", &out])
                .stdin(Stdio::piped()),
        );
        let mut stdin = child.stdin.take().unwrap();
        stdin.write_all(&bytes).unwrap();
        stdin.flush().unwrap();
        let start = Instant::now();
        while partials(&dir).is_empty() && start.elapsed() < Duration::from_secs(30) {
            std::thread::sleep(Duration::from_millis(20));
        }
        let partial = partials(&dir);
        assert!(
            partial.len() == 1 && partial[0].starts_with(&format!("out.{format}.")),
            "no partial file for {format}: {partial:?}"
        );
        child.kill().unwrap();
        child.wait().unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "the earlier export");
        drop(stdin);
        for name in partial {
            std::fs::remove_file(dir.path(&name)).unwrap();
        }
    }
}

/// The names of the temporary files of exports in `dir` (`NAME.XXXXXX.partial`).
fn partials(dir: &Dir) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir.0.path())
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|name| name.ends_with(".partial"))
        .collect();
    names.sort();
    names
}

/// SIGTERM during a long export ends it with a message, removes its temporary file, and leaves
/// the earlier file at the path as it was.
#[cfg(unix)]
#[test]
fn sigterm_during_an_export_removes_the_temporary_file() {
    let dir = Dir::new();
    let big = big_input(&dir);
    let out = dir.arg("out.csv");
    std::fs::write(&out, "the earlier export").unwrap();
    // Signalled once the export has written something to its temporary file.
    let o = terminated(
        &dir,
        &["decode", "--format", "csv", &big, "--overwrite", "-o", &out],
        true,
    );
    assert_fails_with(&o, "interrupted: ");
    assert!(partials(&dir).is_empty(), "{:?}", partials(&dir));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "the earlier export");
}

/// The same for a plot and a summary's plot: the image's temporary file (made before the
/// inputs are read) goes away, the earlier image stays.
#[cfg(unix)]
#[test]
fn sigterm_while_a_plot_reads_removes_its_temporary_file() {
    let dir = Dir::new();
    let big = big_input(&dir);
    let image = dir.arg("old.png");
    for args in [
        vec!["plot", &big, "--overwrite", "-o", &image],
        vec!["summary", &big, "--overwrite", "--plot", &image],
    ] {
        std::fs::write(&image, "the earlier plot").unwrap();
        let o = terminated(&dir, &args, false);
        assert_fails_with(&o, "interrupted: ");
        assert!(partials(&dir).is_empty(), "{args:?}: {:?}", partials(&dir));
        assert_eq!(std::fs::read_to_string(&image).unwrap(), "the earlier plot");
    }
}

/// About 50 MB of telemetry: some tens of seconds of CSV export, a debug build or not.
fn big_input(dir: &Dir) -> String {
    let one = dir.arg("one.bin");
    ok(run(hwfoc().args([
        "simulate",
        "-o",
        &one,
        "--duration",
        "3000",
        "--quiet",
    ])));
    let bytes = std::fs::read(&one).unwrap();
    let big = dir.arg("big.bin");
    let mut file = std::fs::File::create(&big).unwrap();
    for _ in 0..40 {
        file.write_all(&bytes).unwrap();
    }
    big
}

/// `hwfoc ARGS`, sent SIGTERM once its temporary file is there (`written`: and holds
/// something), and what it printed when it ended.
fn terminated(dir: &Dir, args: &[&str], written: bool) -> std::process::Output {
    use nix::sys::signal::{Signal, kill};
    use nix::unistd::Pid;
    let mut child = spawn(hwfoc().args(args));
    let start = Instant::now();
    let staged = || {
        partials(dir)
            .first()
            .and_then(|name| std::fs::metadata(dir.path(name)).ok())
            .is_some_and(|m| !written || m.len() > 0)
    };
    while !staged() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(staged(), "no temporary file: {:?}", partials(dir));
    // Into the reading.
    std::thread::sleep(Duration::from_millis(300));
    assert!(
        child.try_wait().unwrap().is_none(),
        "{args:?} ended before the signal: make the input larger"
    );
    kill(Pid::from_raw(child.id() as i32), Signal::SIGTERM).unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() && start.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let status = child.try_wait().unwrap();
    if status.is_none() {
        child.kill().unwrap();
    }
    let o = child.wait_with_output().unwrap();
    assert!(status.is_some(), "SIGTERM did not end {args:?}");
    o
}

/// Standard input and the configuration file are inputs too: an output that is the file
/// behind standard input, or the configuration read, is refused and the file kept; so is
/// standard output appended to an input.
#[cfg(unix)]
#[test]
fn an_output_that_is_standard_input_or_the_configuration_is_refused() {
    let dir = Dir::new();
    let (csv, raw) = inputs(&dir);
    let before = std::fs::read(&raw).unwrap();
    let stdin = || std::fs::File::open(&raw).unwrap();
    let o = run(hwfoc().args(["decode", "-o", &raw, "-"]).stdin(stdin()));
    assert_fails_with(
        &o,
        &format!("cannot write {raw}: it is the input standard input"),
    );
    let append = std::fs::OpenOptions::new().append(true).open(&raw).unwrap();
    let o = hwfoc()
        .args(["decode", &raw])
        .stdout(append)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert_fails_with(&o, "cannot write standard output: it is the input ");
    assert_eq!(std::fs::read(&raw).unwrap(), before);

    // A configuration file (valid TOML, whatever its name) as the output of every command
    // that reads one.
    let toml = "[settings]\npole_pairs = 7\n";
    for (name, args) in [
        (
            "my.toml",
            vec!["decode", "-o", "CONFIG", "--config", "CONFIG", &csv],
        ),
        (
            "my.png",
            vec!["plot", &csv, "-o", "CONFIG", "--config", "CONFIG"],
        ),
        (
            "my.svg",
            vec!["summary", &csv, "--plot", "CONFIG", "--config", "CONFIG"],
        ),
        (
            "rec.toml",
            vec![
                "monitor",
                "--sim",
                "1",
                "--plain",
                "--duration",
                "0.3",
                "--record",
                "CONFIG",
                "--overwrite",
                "--config",
                "CONFIG",
            ],
        ),
        (
            "log.toml",
            vec![
                "bridge",
                &csv,
                "--mavlink",
                "file:CONFIG",
                "--overwrite",
                "--config",
                "CONFIG",
            ],
        ),
    ] {
        let config = dir.arg(name);
        std::fs::write(&config, toml).unwrap();
        let args: Vec<String> = args
            .iter()
            .map(|a| match *a {
                "CONFIG" => config.clone(),
                "file:CONFIG" => format!("file:{config}"),
                a => a.to_string(),
            })
            .collect();
        let o = run(hwfoc().args(&args));
        assert_fails_with(
            &o,
            &format!("it is the input {config}, which would be destroyed"),
        );
        assert_eq!(std::fs::read_to_string(&config).unwrap(), toml, "{args:?}");
    }
}

/// The temporary file is a new file of its own: an input named as the target plus `.partial`
/// is read whole, a link placed at that name is not followed, and the replaced file keeps
/// its mode.
#[cfg(unix)]
#[test]
fn the_temporary_file_is_never_a_file_that_is_there() {
    use std::os::unix::fs::PermissionsExt;
    let dir = Dir::new();
    let (csv, raw) = inputs(&dir);
    let expected = stdout(&run(hwfoc().args(["decode", "--format", "csv", &raw])));
    let out = dir.arg("out.csv");
    let staged_input = dir.arg("out.csv.partial");
    std::fs::copy(&raw, &staged_input).unwrap();
    ok(run(hwfoc().args([
        "decode",
        "--format",
        "csv",
        "-o",
        &out,
        &staged_input,
    ])));
    assert_eq!(
        std::fs::read(&staged_input).unwrap(),
        std::fs::read(&raw).unwrap()
    );
    assert_eq!(std::fs::read_to_string(&out).unwrap(), expected);

    std::fs::remove_file(&staged_input).unwrap();
    let victim = dir.arg("victim.txt");
    std::fs::write(&victim, "mine").unwrap();
    std::os::unix::fs::symlink(&victim, &staged_input).unwrap();
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o640)).unwrap();
    ok(run(hwfoc().args([
        "decode",
        "--overwrite",
        "-o",
        &out,
        &csv,
    ])));
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "mine");
    assert!(std::fs::read_to_string(&out).unwrap().starts_with("t_s,"));
    let mode = std::fs::metadata(&out).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o640);
    // A plot likewise.
    let png = dir.arg("p.png");
    std::os::unix::fs::symlink(&victim, dir.path("p.png.partial")).unwrap();
    ok(run(hwfoc().args(["plot", &csv, "-o", &png])));
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "mine");
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
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
    assert_fails_with(
        &again,
        "rec.pcapng exists and is never overwritten unasked: choose another name, or pass --overwrite",
    );
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
    ok(run(hwfoc().args(["plot", &csv, "--overwrite", "-o", &png])));
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    assert!(partials(&dir).is_empty());
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
    assert!(partials(&dir).is_empty());
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
            "/nonexistent-hwfoc/x.parquet",
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

/// `--overwrite` is for earlier outputs, never for what `simulate` reads: an output (by name,
/// through a link, `--truth`, or an `{esc}` name expanding to it) that is the profile or the
/// configuration is refused, and outputs that are one file (a link between two ESCs' names)
/// are an error rather than one ESC's bytes lost.
#[cfg(unix)]
#[test]
fn simulate_never_writes_over_what_it_reads_or_its_own_outputs() {
    let dir = Dir::new();
    let profile = dir.arg("prof.csv");
    let rows = "time_s,throttle_percent\n0,0\n1,50\n2,0\n";
    std::fs::write(&profile, rows).unwrap();
    let link = dir.arg("link.csv");
    std::os::unix::fs::symlink(&profile, &link).unwrap();
    let config = dir.arg("my.toml");
    let toml = "[settings]\npole_pairs = 7\n";
    std::fs::write(&config, toml).unwrap();
    let csv_profile = format!("csv:{profile}");
    let esc_name = dir.arg("prof{esc}.csv");
    std::fs::copy(&profile, dir.path("prof1.csv")).unwrap();
    let prof1 = dir.arg("prof1.csv");
    let profile1 = format!("csv:{prof1}");
    let cases: [(&[&str], &str); 5] = [
        (&["-o", &profile, "--profile", &csv_profile], &profile),
        (&["-o", &link, "--profile", &csv_profile], &profile),
        (
            &["-o", "-", "--truth", &profile, "--profile", &csv_profile],
            &profile,
        ),
        (
            &["--escs", "2", "-o", &esc_name, "--profile", &profile1],
            &prof1,
        ),
        (&["-o", &config, "--config", &config], &config),
    ];
    for (args, read) in cases {
        let o = run(hwfoc()
            .arg("simulate")
            .args(args)
            .args(["--overwrite", "--duration", "1"])
            .stdout(Stdio::null()));
        assert_fails_with(&o, &format!("it is the input {read}"));
    }
    assert_eq!(std::fs::read_to_string(&profile).unwrap(), rows);
    assert_eq!(
        std::fs::read_to_string(dir.path("prof1.csv")).unwrap(),
        rows
    );
    assert_eq!(std::fs::read_to_string(&config).unwrap(), toml);

    // o1.bin is a link to o0.bin: ESC 1's bytes would replace ESC 0's.
    let o0 = dir.arg("o0.bin");
    std::fs::write(&o0, "earlier").unwrap();
    std::os::unix::fs::symlink(&o0, dir.path("o1.bin")).unwrap();
    let o = run(hwfoc().args([
        "simulate",
        "--escs",
        "2",
        "-o",
        &dir.arg("o{esc}.bin"),
        "--overwrite",
        "--duration",
        "1",
    ]));
    assert_fails_with(
        &o,
        &format!("{o0} and {} are the same file", dir.arg("o1.bin")),
    );
    assert_eq!(std::fs::read_to_string(&o0).unwrap(), "earlier");
}

/// `hwfoc record` never writes its recording over a port it reads, even with --overwrite: the
/// port named as the output is refused before anything is opened, and left as it was.
#[test]
fn a_recording_is_never_written_over_a_port_it_reads() {
    let dir = Dir::new();
    let port = dir.arg("ttyUSB9");
    std::fs::write(&port, b"not to be destroyed").unwrap();
    let o = run(hwfoc().args([
        "record",
        &port,
        "-o",
        &port,
        "--overwrite",
        "--duration",
        "0.2",
    ]));
    assert_fails_with(&o, &format!("cannot write {port}: it is the input {port}"));
    assert_eq!(std::fs::read(&port).unwrap(), b"not to be destroyed");
}

/// `--truth` through a dangling link to the recording `-o` is about to write (serial pcapng,
/// CAN candump and pcapng alike) is refused, as the same command is when the recording exists:
/// written through, the truth would replace the recording.
#[cfg(unix)]
#[test]
fn the_ground_truth_never_lands_on_the_recording_through_a_dangling_link() {
    let cases: [&[&str]; 3] = [
        &["--duration", "1"],
        &["--protocol", "hw-can", "--escs", "2", "--duration", "1"],
        &[
            "--protocol",
            "hw-can",
            "--escs",
            "2",
            "--duration",
            "1",
            "--format",
            "candump",
        ],
    ];
    for extra in cases {
        let dir = Dir::new();
        let rec = dir.arg("rec.pcapng");
        let link = dir.arg("link.jsonl");
        std::os::unix::fs::symlink("rec.pcapng", &link).unwrap();
        for (o, truth) in [(&rec, &link), (&link, &rec)] {
            let out = run(hwfoc()
                .arg("simulate")
                .args(["-o", o, "--truth", truth, "--overwrite"])
                .args(extra));
            assert_fails_with(&out, "is also the output -o");
            assert!(
                !dir.path("rec.pcapng").exists(),
                "{extra:?}: nothing written"
            );
        }
    }
}
