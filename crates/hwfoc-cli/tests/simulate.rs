//! End-to-end tests of `hwfoc simulate`: what the virtual ESCs send decodes (with `hwfoc decode`
//! or the codec) to exactly the ground truth they write, with and without link faults; the
//! same seed gives the same bytes; frame timing; pseudo-terminals; errors.

#![cfg(unix)]

mod common;

use std::io::{BufRead, BufReader, Read};
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;
use std::process::{Output, Stdio};
use std::time::{Duration, Instant};

use common::{Dir, assert_fails_with, hwfoc, ok};

use hwfoc::foc::{Decoder, FocFrame};
use serde_json::Value;

fn run(args: &[&str]) -> Output {
    hwfoc().args(args).output().expect("run hwfoc")
}

fn jsonl(text: &[u8]) -> Vec<Value> {
    std::str::from_utf8(text)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

fn read_jsonl(path: &Path) -> Vec<Value> {
    jsonl(&std::fs::read(path).unwrap())
}

fn decode(path: &Path) -> Vec<Value> {
    jsonl(&ok(run(&["decode", path.to_str().unwrap()])).stdout)
}

fn without(mut records: Vec<Value>, keys: &[&str]) -> Vec<Value> {
    for r in &mut records {
        for k in keys {
            r.as_object_mut().unwrap().remove(*k);
        }
    }
    records
}

const FAULTY: [&str; 8] = [
    "--bit-error-rate",
    "5e-4",
    "--drop-rate",
    "0.03",
    "--cut-rate",
    "0.03",
    "--garbage-rate",
    "0.1",
];

#[test]
fn raw_file_decodes_to_the_truth() {
    let dir = Dir::new();
    for faulty in [false, true] {
        let mut args = vec![
            "simulate".to_string(),
            "-o".into(),
            dir.arg("run.bin"),
            "--truth".into(),
            dir.arg("truth.jsonl"),
            "--fault".into(),
            "mos_overheat@3-4".into(),
            "--quiet".into(),
            // The second run replaces the first's files.
            "--overwrite".into(),
        ];
        if faulty {
            args.extend(FAULTY.iter().map(|s| s.to_string()));
        }
        let o = ok(hwfoc().args(&args).output().unwrap());
        assert!(o.stderr.is_empty());
        let truth = read_jsonl(&dir.path("truth.jsonl"));
        let decoded = decode(&dir.path("run.bin"));
        // Default: lead-in 2 s + 7 steps of 2 s + 2 s = 18 s.
        assert!(
            truth.len() > if faulty { 180 } else { 220 },
            "{}",
            truth.len()
        );
        // Raw bytes carry no time; the truth has the simulated time.
        assert!(decoded.iter().all(|r| r["t_s"].is_null()));
        let t: Vec<f64> = truth.iter().map(|r| r["t_s"].as_f64().unwrap()).collect();
        assert!(t[0] >= 0.0 && t[0] < 1.0, "{}", t[0]);
        assert!(*t.last().unwrap() < 18.0);
        assert!(t.windows(2).all(|w| w[1] > w[0]));
        let untimed: Vec<Value> = truth
            .iter()
            .cloned()
            .map(|mut r| {
                r["t_s"] = Value::Null;
                r
            })
            .collect();
        assert_eq!(decoded, untimed);
        // The injected fault is there, and the model's values move.
        assert!(
            truth
                .iter()
                .any(|r| r["faults"] == serde_json::json!(["mos_overheat"]))
        );
        assert!(
            truth
                .iter()
                .any(|r| r["current_a"].as_f64().unwrap() < -1.0)
        );
        assert!(truth.iter().any(|r| r["rpm"].as_f64().unwrap() > 8000.0));
    }
}

#[test]
fn recording_decodes_to_the_truth_with_times() {
    let dir = Dir::new();
    let mut args = vec![
        "simulate",
        "--escs",
        "3",
        "--seed",
        "9",
        "--start-time",
        "1700000000.25",
        "--start-packet",
        "65530",
        "--quiet",
    ];
    args.extend(FAULTY);
    // One recording with an interface per ESC, and one recording per ESC.
    let all = dir.arg("all.pcapng");
    let each = dir.arg("esc{esc}.pcapng");
    let truth = dir.arg("truth.jsonl");
    ok(hwfoc()
        .args(&args)
        .args(["-o", &all, "--truth", &truth])
        .output()
        .unwrap());
    let truth = read_jsonl(&dir.path("truth.jsonl"));
    let first = truth[0]["t_s"].as_f64().unwrap();
    assert!((1_700_000_000.25..1_700_000_000.31).contains(&first));
    // Each interface is one ESC: the records match in every field, esc and t_s included.
    let key = |r: &Value| (r["t_s"].as_f64().unwrap().to_bits(), r["esc"].as_u64());
    let mut decoded = decode(&dir.path("all.pcapng"));
    let mut expected = truth.clone();
    decoded.sort_by_key(key);
    expected.sort_by_key(key);
    assert_eq!(decoded, expected);

    ok(hwfoc().args(&args).args(["-o", &each]).output().unwrap());
    for esc in 0..3u64 {
        let decoded = without(decode(&dir.path(&format!("esc{esc}.pcapng"))), &["esc"]);
        let expected: Vec<Value> = truth.iter().filter(|r| r["esc"] == esc).cloned().collect();
        assert_eq!(decoded, without(expected, &["esc"]), "esc {esc}");
        // Packet numbers wrap.
        let packets: Vec<u64> = decoded
            .iter()
            .map(|r| r["packet"].as_u64().unwrap())
            .collect();
        assert!(
            packets[0] >= 65530 && packets.iter().any(|&p| p < 100),
            "{packets:?}"
        );
    }
}

#[test]
fn frame_timing_from_a_recording() {
    let dir = Dir::new();
    let file = dir.arg("t.pcapng");
    // Idle 2 s, 50 % for 2 s, idle 3 s.
    std::fs::write(
        dir.path("p.csv"),
        "time_s,throttle_percent\n0,0\n2,0\n2,50\n4,50\n4,0\n",
    )
    .unwrap();
    let profile = format!("csv:{}", dir.arg("p.csv"));
    ok(run(&[
        "simulate",
        "-o",
        &file,
        "--profile",
        &profile,
        "--duration",
        "7",
        "--start-time",
        "0",
        "--quiet",
    ]));
    let records = decode(&dir.path("t.pcapng"));
    let idle = |r: &Value| r["erpm"] == 0 && r["throttle_out_pct"] == 0.0;
    let (mut runs, mut idles) = (0, 0);
    for w in records.windows(2) {
        let gap_ms = (w[1]["t_s"].as_f64().unwrap() - w[0]["t_s"].as_f64().unwrap()) * 1e3;
        match (idle(&w[0]), idle(&w[1])) {
            (false, false) => {
                assert!((gap_ms - 50.0).abs() < 1e-3, "{gap_ms}");
                runs += 1;
            }
            (_, true) => {
                assert!((gap_ms - 364.0).abs() < 1e-3, "{gap_ms}");
                idles += 1;
            }
            (true, false) => assert!(gap_ms < 364.0),
        }
    }
    assert!(runs >= 40 && idles >= 10, "{runs} {idles}");

    // Device information: 40 ms after each idle data frame, straight from the recording's bytes.
    let bytes = std::fs::read(dir.path("t.pcapng")).unwrap();
    let mut info = 0;
    Decoder::new().decode_all(&bytes, |d| {
        if matches!(d.frame, FocFrame::Info(_)) {
            info += 1;
        }
    });
    let idle_times: Vec<f64> = records
        .iter()
        .filter(|r| idle(r))
        .map(|r| r["t_s"].as_f64().unwrap())
        .collect();
    let cut_off = usize::from(idle_times.last().unwrap() + 0.040 >= 7.0);
    assert_eq!(info, idle_times.len() - cut_off, "one per idle data frame");
}

#[test]
fn same_seed_same_bytes() {
    let dir = Dir::new();
    let go = |seed: &str, name: &str| {
        let mut args = vec![
            "simulate",
            "--escs",
            "2",
            "--seed",
            seed,
            "--duration",
            "6",
            "--start-time",
            "1",
            "--quiet",
        ];
        args.extend(FAULTY);
        let out = dir.arg(name);
        ok(hwfoc().args(&args).args(["-o", &out]).output().unwrap());
        std::fs::read(dir.path(name)).unwrap()
    };
    let a = go("7", "a.pcapng");
    assert!(a.len() > 5000);
    assert_eq!(a, go("7", "b.pcapng"));
    assert_ne!(a, go("8", "c.pcapng"));
    // Standard output carries the same raw bytes as a file.
    let file = dir.arg("one.bin");
    ok(run(&[
        "simulate",
        "--duration",
        "3",
        "-o",
        &file,
        "--quiet",
    ]));
    let piped = ok(run(&["simulate", "--duration", "3", "--quiet"])).stdout;
    assert_eq!(piped, std::fs::read(dir.path("one.bin")).unwrap());
}

/// Reads what arrives on `path` until `until`, without blocking.
fn read_for(path: &str, until: Instant) -> Vec<u8> {
    let mut port = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags((nix::fcntl::OFlag::O_NOCTTY | nix::fcntl::OFlag::O_NONBLOCK).bits())
        .open(path)
        .expect("open the pty");
    let mut got = Vec::new();
    let mut buf = [0u8; 4096];
    while Instant::now() < until {
        match port.read(&mut buf) {
            Ok(n) if n > 0 => got.extend_from_slice(&buf[..n]),
            Ok(_) => break,
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                std::thread::sleep(Duration::from_millis(10))
            }
            Err(_) => break,
        }
    }
    got
}

#[test]
fn pseudo_terminals_carry_the_frames_in_real_time() {
    let dir = Dir::new();
    let links = dir.path("links");
    let truth = dir.arg("truth.jsonl");
    let started = Instant::now();
    let mut child = hwfoc()
        .args([
            "simulate",
            "--pty",
            "--escs",
            "2",
            "--seed",
            "3",
            "--start-packet",
            "100",
        ])
        .args([
            "--lead-in",
            "0.5",
            "--levels",
            "30,60",
            "--truth",
            &truth,
            "--link-dir",
        ])
        .arg(&links)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let mut paths = Vec::new();
    for esc in 0..2 {
        let line = lines.next().unwrap().unwrap();
        let path = line
            .strip_prefix(&format!("esc {esc}: "))
            .unwrap_or_else(|| panic!("{line:?}"));
        assert!(path.starts_with("/dev/"), "{path}");
        assert_eq!(
            std::fs::read_link(links.join(format!("esc{esc}"))).unwrap(),
            Path::new(path)
        );
        paths.push(path.to_string());
    }
    // ESC 1 through its link, ESC 0 by its path; both while the simulation runs.
    let link1 = links.join("esc1").to_str().unwrap().to_string();
    let until = started + Duration::from_millis(2500);
    let reader1 = std::thread::spawn(move || read_for(&link1, until));
    let got0 = read_for(&paths[0], until);
    let got1 = reader1.join().unwrap();
    // Ctrl-C: a clean stop that removes the links.
    nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(child.id() as i32),
        nix::sys::signal::Signal::SIGINT,
    )
    .unwrap();
    let status = child.wait().unwrap();
    assert!(status.success());
    assert!(!links.join("esc0").exists() && !links.join("esc1").exists());
    let elapsed = started.elapsed();
    assert!(elapsed < Duration::from_secs(5), "{elapsed:?}");

    let truth = read_jsonl(&dir.path("truth.jsonl"));
    for (esc, got) in [got0, got1].iter().enumerate() {
        let mut frames = Vec::new();
        Decoder::new().decode_all(got, |d| {
            if let FocFrame::Data(f) = d.frame {
                frames.push(f);
            }
        });
        // About 2.4 s: idle frames, then 50 ms frames once the steps start at 0.5 s.
        assert!(frames.len() >= 25, "esc {esc}: {} frames", frames.len());
        // Every frame received is in the truth with the same values, and frames arrived in
        // real time: the run took as long as the frames say.
        for f in &frames {
            let r = truth
                .iter()
                .find(|r| r["esc"] == esc && r["packet"] == f.packet)
                .unwrap_or_else(|| panic!("esc {esc} packet {} not in the truth", f.packet));
            assert_eq!(r["erpm"], f.erpm());
            assert_eq!(r["voltage_v"].as_f64().unwrap() as f32, f.voltage_v());
        }
        let first = truth.iter().find(|r| r["esc"] == esc).unwrap();
        let last = truth.iter().rev().find(|r| r["esc"] == esc).unwrap();
        let span = last["t_s"].as_f64().unwrap() - first["t_s"].as_f64().unwrap();
        assert!((1.8..3.0).contains(&span), "{span}");
    }
}

#[test]
fn errors_name_what_is_wrong() {
    let dir = Dir::new();
    assert_fails_with(
        &run(&["simulate", "-o", "/nonexistent/dir/x.bin"]),
        "cannot write /nonexistent/dir/x.bin",
    );
    assert_fails_with(
        &run(&[
            "simulate",
            "-o",
            &dir.arg("x.bin"),
            "--truth",
            "/nonexistent/t.jsonl",
        ]),
        "cannot write /nonexistent/t.jsonl",
    );
    assert_fails_with(
        &run(&["simulate", "--port", "/dev/ttyUSB-hwfoc-missing"]),
        "no such port /dev/ttyUSB-hwfoc-missing",
    );
    std::fs::write(dir.path("p.csv"), "time,throttle\n0,0\n1,50\n2,lots\n").unwrap();
    let profile = format!("csv:{}", dir.arg("p.csv"));
    assert_fails_with(
        &run(&["simulate", "--profile", &profile, "-o", &dir.arg("x.bin")]),
        &format!("{}:4: bad throttle \"lots\"", dir.arg("p.csv")),
    );
    assert_fails_with(
        &run(&[
            "simulate",
            "--profile",
            "csv:/nonexistent.csv",
            "-o",
            &dir.arg("x.bin"),
        ]),
        "cannot open /nonexistent.csv",
    );
    assert_fails_with(
        &run(&["simulate", "--escs", "2", "-o", &dir.arg("x.bin")]),
        "put {esc} in the name",
    );
    assert_fails_with(
        &run(&[
            "simulate",
            "--escs",
            "2",
            "--fault",
            "2:mos_short@1",
            "-o",
            &dir.arg("{esc}"),
        ]),
        "ESC 2 does not exist",
    );
    // Usage errors from the argument parser.
    let o = run(&["simulate", "--fault", "overheat@1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("the names are input_voltage_high"));
}

/// `--link-dir` replaces only a link a killed run left (to a pseudo-terminal that is gone): a
/// user's dangling link is refused and kept, and the links made before it are removed.
#[test]
fn link_dir_never_replaces_a_users_link() {
    let dir = Dir::new();
    let links = dir.path("links");
    std::fs::create_dir(&links).unwrap();
    std::os::unix::fs::symlink("/nonexistent", links.join("esc2")).unwrap();
    let o = run(&[
        "simulate",
        "--pty",
        "--escs",
        "3",
        "--duration",
        "1",
        "--link-dir",
        links.to_str().unwrap(),
    ]);
    assert_fails_with(
        &o,
        &format!(
            "hwfoc: cannot create the link {}: a link of someone else's is there (not to a \
             pseudo-terminal of an earlier run): choose another path, or a directory of your own \
             with --link-dir\n",
            links.join("esc2").display()
        ),
    );
    assert_eq!(
        std::fs::read_link(links.join("esc2")).unwrap(),
        Path::new("/nonexistent")
    );
    assert!(std::fs::symlink_metadata(links.join("esc0")).is_err());
    assert!(std::fs::symlink_metadata(links.join("esc1")).is_err());
}

/// The simulator's library names no option; the command's messages name `--fault` and
/// `--link` from what its errors carry.
#[test]
fn a_fault_or_links_for_escs_that_do_not_exist_name_their_option() {
    let dir = Dir::new();
    let o = run(&[
        "simulate",
        "--escs",
        "2",
        "--duration",
        "1",
        "--fault",
        "2:mos_short@0.5",
        "-o",
        &dir.arg("x.pcapng"),
    ]);
    assert_fails_with(
        &o,
        "hwfoc: --fault: ESC 2 does not exist: there are 2 (0..1)\n",
    );
    let o = run(&[
        "simulate",
        "--pty",
        "--escs",
        "3",
        "--duration",
        "1",
        "--link",
        &dir.arg("a"),
        "--link",
        &dir.arg("b"),
    ]);
    assert_fails_with(
        &o,
        "hwfoc: --link: 2 links for 3 ESCs: give one per ESC, or one with {esc} in it\n",
    );
}

/// Simulates 7 s of one ESC speaking `protocol` (idle 2 s, 40 % for 2 s, then idle) to a
/// recording, with `extra` options and its ground truth; returns the records `hwfoc decode`
/// finds by itself (checked equal to those it finds told the protocol), the truth, and the
/// summary's JSON.
fn simulate_protocol(protocol: &str, extra: &[&str]) -> (Vec<Value>, Vec<Value>, Value) {
    let dir = Dir::new();
    std::fs::write(
        dir.path("p.csv"),
        "time_s,throttle_percent\n0,0\n2,0\n2,40\n4,40\n4,0\n",
    )
    .unwrap();
    let profile = format!("csv:{}", dir.arg("p.csv"));
    let file = dir.arg("run.pcapng");
    let truth = dir.arg("truth.jsonl");
    let o = ok(hwfoc()
        .args(["simulate", "--protocol", protocol, "--profile", &profile])
        .args(["--duration", "7", "--start-time", "0", "-o", &file])
        .args(["--truth", &truth])
        .args(extra)
        .output()
        .unwrap());
    // The report: no device id but HW-FOC's.
    let report = String::from_utf8(o.stderr).unwrap();
    assert!(report.starts_with(&format!("esc 0 ({file}): ")), "{report}");
    let detected = decode(&dir.path("run.pcapng"));
    let forced = jsonl(&ok(run(&["decode", "--protocol", protocol, &file])).stdout);
    assert_eq!(detected, forced);
    assert!(detected.iter().all(|r| r["protocol"] == protocol));
    let summary = ok(run(&["summary", "--json", &file])).stdout;
    (
        detected,
        read_jsonl(&dir.path("truth.jsonl")),
        serde_json::from_slice(&summary).unwrap(),
    )
}

fn t_s(r: &Value) -> f64 {
    r["t_s"].as_f64().unwrap()
}

fn f(r: &Value, key: &str) -> f64 {
    r[key].as_f64().unwrap_or_else(|| panic!("{key} in {r}"))
}

/// Packet counters from 0, +1 per data frame.
fn assert_counts_from_zero(records: &[Value]) {
    for (k, r) in records.iter().enumerate() {
        assert_eq!(r["packet"], k as u64, "{r}");
    }
}

#[test]
fn protocol_hw_v4_fast_and_slow_modes_with_info_frames() {
    let (records, truth, summary) = simulate_protocol("hw-v4", &[]);
    assert_counts_from_zero(&records);
    // Idle ("slow"): no second temperature, a data frame every 400 ms (an info frame between);
    // running ("fast"): 51 ms.
    let fast = |r: &Value| !r["cap_temp_c"].is_null();
    let (mut fast_gaps, mut slow_gaps) = (0, 0);
    for w in records.windows(2) {
        let gap_ms = (t_s(&w[1]) - t_s(&w[0])) * 1e3;
        match (fast(&w[0]), fast(&w[1])) {
            (true, true) => {
                assert!((gap_ms - 51.0).abs() < 1e-3, "{gap_ms} at {}", t_s(&w[0]));
                fast_gaps += 1;
            }
            (false, false) => {
                assert!((gap_ms - 400.0).abs() < 1e-3, "{gap_ms} at {}", t_s(&w[0]));
                slow_gaps += 1;
            }
            _ => assert!(gap_ms < 400.0),
        }
    }
    assert!(fast_gaps > 70 && slow_gaps >= 5, "{fast_gaps} {slow_gaps}");
    // Fast from the first frame with throttle; slow again 1.5 s after the motor stopped.
    let first_fast = records.iter().find(|r| fast(r)).map(t_s).unwrap();
    assert!((2.0..2.06).contains(&first_fast), "{first_fast}");
    let last_fast = records.iter().rev().find(|r| fast(r)).map(t_s).unwrap();
    assert!((5.7..6.5).contains(&last_fast), "{last_fast}");
    // The info frames are there, adopted: full scale 1000, the capture's 8/910 V per step,
    // 0.05 A per step.
    let esc = &summary["escs"][0];
    assert_eq!(esc["protocol"], "hw-v4");
    assert!(esc["info_frames"].as_u64().unwrap() >= 5, "{esc}");
    let info = &esc["info"][0];
    assert_eq!(info["adopted"], true);
    assert_eq!(
        (&info["full_scale"], &info["v1"], &info["v2"]),
        (&Value::from(1000), &Value::from(8), &Value::from(91))
    );
    assert_eq!(
        (&info["i1"], &info["i2"]),
        (&Value::from(1), &Value::from(20))
    );
    // Values: a 6S pack, 40 % throttle, current while running (once the info frame is adopted).
    for r in &records {
        assert!((23.5..25.7).contains(&f(r, "voltage_v")), "{r}");
        assert!((15.0..40.0).contains(&f(r, "mos_temp_c")), "{r}");
        if (2.5..4.0).contains(&t_s(r)) {
            assert!((38.0..42.0).contains(&f(r, "throttle_in_pct")), "{r}");
            assert!(f(r, "current_a") > 2.0 && f(r, "erpm") > 10_000.0, "{r}");
        }
    }
    // The truth is each frame as its ESC meant it, under its own info frame: the records from
    // the adoption on are exactly the truth's.
    assert_eq!(truth.len(), records.len());
    let adopted = records
        .iter()
        .position(|r| !r["current_a"].is_null())
        .unwrap();
    assert!(adopted <= 3, "{adopted}");
    assert_eq!(records[adopted..], truth[adopted..]);
}

#[test]
fn protocol_hw_v3_steady_frames_and_the_start_up_placeholder() {
    let (records, truth, _) = simulate_protocol("hw-v3", &[]);
    assert_eq!(records, truth);
    assert_counts_from_zero(&records);
    for w in records.windows(2) {
        let gap_ms = (t_s(&w[1]) - t_s(&w[0])) * 1e3;
        assert!((gap_ms - 19.5).abs() < 1e-3, "{gap_ms}");
    }
    assert!((355..360).contains(&records.len()), "{}", records.len());
    for r in &records {
        let t = t_s(r);
        // Stopped: the placeholder period, no speed.
        if !(2.0..5.5).contains(&t) {
            assert!(r["erpm"].is_null() && r["rpm"].is_null(), "{r}");
            assert_eq!(f(r, "throttle_in_pct"), 0.0);
        }
        if (2.5..4.0).contains(&t) {
            assert!((38.0..42.0).contains(&f(r, "throttle_in_pct")), "{r}");
            assert!((10_000.0..40_000.0).contains(&f(r, "erpm")), "{r}");
        }
        assert!(r["voltage_v"].is_null());
    }
}

#[test]
fn protocol_hw5_rates_values_and_faults() {
    let (records, truth, summary) = simulate_protocol(
        "hw5",
        &[
            "--fault",
            "motor_blocked@3-3.5",
            "--fault",
            "over_current@6",
        ],
    );
    assert_eq!(records, truth);
    assert_eq!(summary["escs"][0]["protocol"], "hw5");
    let running = |r: &Value| f(r, "erpm") > 0.0;
    let (mut run_gaps, mut idle_gaps) = (0, 0);
    for w in records.windows(2) {
        let gap_ms = (t_s(&w[1]) - t_s(&w[0])) * 1e3;
        match (running(&w[0]), running(&w[1])) {
            (true, true) => {
                assert!((gap_ms - 20.0).abs() < 1e-3, "{gap_ms}");
                run_gaps += 1;
            }
            // Idle, and the first frame once the motor has stopped.
            (_, false) => {
                assert!((gap_ms - 400.0).abs() < 1e-3, "{gap_ms}");
                idle_gaps += 1;
            }
            // Starting: the next 20 ms check.
            (false, true) => assert!(gap_ms < 400.0),
        }
    }
    // 50 Hz for about 2.8 s, 2.5 Hz for about 4 s.
    assert!((120..150).contains(&run_gaps), "{run_gaps}");
    assert!((7..12).contains(&idle_gaps), "{idle_gaps}");
    for r in &records {
        let t = t_s(r);
        assert!((24.0..25.7).contains(&f(r, "voltage_v")), "{r}");
        assert!((8.25..8.55).contains(&f(r, "bec_voltage_v")), "{r}");
        if (2.5..4.0).contains(&t) {
            assert!((38.0..42.0).contains(&f(r, "throttle_in_pct")), "{r}");
            assert!(f(r, "current_a") > 2.0, "{r}");
        }
        let faults: &[&str] = if (3.0..3.5).contains(&t) {
            &["motor_locked"]
        } else if t >= 6.0 {
            &["over_current"]
        } else {
            &[]
        };
        assert_eq!(r["faults"], serde_json::json!(faults), "{r}");
    }
}

#[test]
fn protocol_errors_name_what_is_wrong() {
    let dir = Dir::new();
    let out = dir.arg("x.bin");
    assert_fails_with(
        &run(&[
            "simulate",
            "--protocol",
            "hw5",
            "--fault",
            "mos_short@1",
            "-o",
            &out,
        ]),
        "hwfoc: --fault: the fault mos_short has no flag in HW5's fault byte; HW5 carries ",
    );
    assert_fails_with(
        &run(&[
            "simulate",
            "--protocol",
            "hw-v4",
            "--drop-rate",
            "0.1",
            "-o",
            &out,
        ]),
        "link faults (bit errors, drops, cuts, garbage) are simulated for HW-FOC only, not for \
         Hobbywing V4 (hw-v4)",
    );
    let o = run(&["simulate", "--protocol", "datalink", "-o", &out]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr)
            .contains("[possible values: hw-foc, hw-v4, hw-v3, hw5, hw-can]")
    );
    assert!(!dir.path("x.bin").exists());
}
