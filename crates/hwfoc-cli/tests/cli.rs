//! End-to-end tests of the `hwfoc` binary: real captures, golden outputs, stdin, errors.

mod common;

use std::io::{Read, Write};
use std::path::Path;
use std::process::{Output, Stdio};

use common::{TEXT_SCHEMA, XROTOR, assert_fails_with, capture, check_golden, hwfoc, stdout};
use hwfoc::foc::{DataFrame, InfoFrame};
use hwfoc::{Fault, Status};
use serde_json::Value;

fn run(args: &[&str]) -> Output {
    hwfoc().args(args).output().expect("run hwfoc")
}

fn run_stdin(args: &[&str], stdin: &[u8]) -> Output {
    let mut child = hwfoc()
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn hwfoc");
    let mut pipe = child.stdin.take().unwrap();
    let data = stdin.to_vec();
    let writer = std::thread::spawn(move || {
        // Feed in small pieces, as a live stream would arrive.
        for piece in data.chunks(1000) {
            if pipe.write_all(piece).is_err() {
                break;
            }
        }
    });
    let out = child.wait_with_output().expect("wait hwfoc");
    writer.join().unwrap();
    out
}

/// The bytes of a logic-analyser CSV, as a raw capture would hold them.
fn csv_bytes(path: &Path) -> Vec<u8> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| u8::from_str_radix(&l.split(',').nth(1).unwrap()[2..], 16).unwrap())
        .collect()
}

#[test]
fn decode_real_capture_matches_schema_and_golden() {
    let out = stdout(&run(&["decode", capture(XROTOR).to_str().unwrap()]));
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 248);
    // The schema document's example is the capture's first frame.
    assert_eq!(
        lines[0],
        r#"{"t_s":0.22798,"esc":0,"protocol":"hw-foc","packet":1474,"throttle_in_pct":0.0,"throttle_out_pct":0.0,"erpm":0,"rpm":0.0,"voltage_v":24.7,"current_a":-0.015625,"phase_current_a":-0.015625,"mos_temp_c":28.0,"cap_temp_c":26.0,"motor_temp_c":null,"bec_temp_c":null,"bec_voltage_v":null,"bec_current_a":null,"status":0,"faults":[],"node":null,"msg2_age_ms":null,"msg3_age_ms":null}"#
    );
    let mut last_t = f64::MIN;
    let mut max_v = 0.0f64;
    let mut min_i = 0.0f64;
    for line in &lines {
        // Exactly the schema's keys, in the schema's order.
        let mut at = 0;
        for key in TEXT_SCHEMA {
            let pos = line[at..]
                .find(&format!("\"{key}\":"))
                .unwrap_or_else(|| panic!("{key} missing or out of order in {line}"));
            at += pos;
        }
        let v: Value = serde_json::from_str(line).unwrap();
        assert_eq!(v.as_object().unwrap().len(), TEXT_SCHEMA.len());
        let t = v["t_s"].as_f64().unwrap();
        assert!(t > last_t, "timestamps increase");
        last_t = t;
        max_v = max_v.max(v["voltage_v"].as_f64().unwrap());
        min_i = min_i.min(v["phase_current_a"].as_f64().unwrap());
    }
    // The braking spike on the bench supply, and regenerative (negative) current.
    assert!((max_v - 53.5).abs() < 1e-4, "{max_v}");
    assert!(min_i < -1.0, "{min_i}");
    check_golden("xrotor-v4-pro-hv-80A.jsonl", &out);
}

#[test]
fn summary_of_real_capture() {
    let out = stdout(&run(&[
        "summary",
        "--json",
        capture(XROTOR).to_str().unwrap(),
    ]));
    let top: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(top["inputs"][0]["bytes"], 7002);
    assert_eq!(top["inputs"][0]["escs"], serde_json::json!([0]));
    assert_eq!(top["escs"].as_array().unwrap().len(), 1);
    let v = &top["escs"][0];
    assert_eq!(v["esc"], 0);
    assert_eq!(v["frames"], 248);
    assert_eq!(v["info_frames"], 12);
    assert_eq!(v["bytes"], 7002);
    assert_eq!(v["link"]["checksum_failures"], 2);
    assert_eq!(v["link"]["lost_packets"], 2);
    assert_eq!(v["link"]["duplicate_packets"], 1);
    assert_eq!(v["link"]["bytes_skipped"], 7002 - 248 * 24 - 12 * 77);
    assert_eq!(v["info"][0]["product"], "XR_FOC_ESC");
    assert_eq!(v["info"][0]["hardware"], "HW577_KZ1_V1.1");
    assert_eq!(v["info"][0]["firmware"], "XR-01.0.00");
    assert_eq!(v["info"][0]["id"], "01040443");
    assert_eq!(v["info"][0]["frames"], 12);
    assert_eq!(v["fields"]["voltage_v"]["max"], 53.5);
    assert_eq!(v["fields"]["mos_temp_c"]["min"], 28.0);
    assert_eq!(v["first_t_s"], 0.22798);
    assert_eq!(v["warning"], Value::Null);
    assert_eq!(v["faults"], serde_json::json!({}));
    assert_eq!(v["fault_episode_count"], 0);
    // The input is named as given on the command line, which differs between checkouts.
    let portable = out.replace(
        &serde_json::to_string(capture(XROTOR).to_str().unwrap()).unwrap(),
        "\"xrotor-v4-pro-hv-80A.csv\"",
    );
    check_golden("xrotor-v4-pro-hv-80A.summary.json", &portable);

    let text = stdout(&run(&["summary", capture(XROTOR).to_str().unwrap()]));
    assert!(text.contains("248 data, 12 info"), "{text}");
    assert!(
        text.contains("XR_FOC_ESC HW577_KZ1_V1.1 XR-01.0.00 01040443"),
        "{text}"
    );
    assert!(text.contains("2 checksum failures, 2 lost packets, 1 duplicate packets"));
}

/// The Platinum captures, told from their bytes (no `--protocol`): every frame decoded, as the
/// golden files hold them (`UPDATE_GOLDEN=1` rewrites them), and their summaries' figures.
#[test]
fn platinum_captures_decode_exactly() {
    for (name, protocol, frames, info, first, last) in [
        ("platinum-v4.csv", "hw-v4", 297, 26, 817, 1113),
        ("platinum-pro-v3.csv", "hw-v3", 699, 0, 0, 698),
    ] {
        let path = capture(name);
        let path = path.to_str().unwrap();
        let out = run(&["decode", path]);
        assert!(out.status.success(), "{name}");
        let jsonl = stdout(&out);
        let records: Vec<Value> = jsonl
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(records.len(), frames, "{name}");
        assert!(records.iter().all(|r| r["protocol"] == protocol), "{name}");
        let packets: Vec<u64> = records
            .iter()
            .map(|r| r["packet"].as_u64().unwrap())
            .collect();
        assert_eq!(packets, (first..=last).collect::<Vec<u64>>(), "{name}");
        let peak = records
            .iter()
            .filter_map(|r| r["throttle_in_pct"].as_f64())
            .fold(0.0, f64::max);
        check_golden(&name.replace(".csv", ".jsonl"), &jsonl);

        let out = run(&["summary", "--json", path]);
        assert!(out.status.success(), "{name}");
        let text = stdout(&out);
        let v: Value = serde_json::from_str(&text).unwrap();
        let esc = &v["escs"][0];
        assert_eq!(esc["protocol"], protocol, "{name}");
        assert_eq!(esc["frames"], frames, "{name}");
        assert_eq!(esc["info_frames"], info, "{name}");
        assert_eq!(esc["link"]["bytes_skipped"], 0, "{name}");
        assert_eq!(esc["link"]["rejected_candidates"], 0, "{name}");
        assert_eq!(esc["link"]["checksum_failures"], Value::Null, "{name}");
        assert_eq!(esc["link"]["lost_packets"], 0, "{name}");
        assert_eq!(esc["warning"], Value::Null, "{name}");
        if protocol == "hw-v4" {
            // A 3S pack; throttle peaks at exactly full scale (1000 of 1000).
            assert_eq!(peak, 100.0);
            let volts = &esc["fields"]["voltage_v"];
            let (min, max) = (
                volts["min"].as_f64().unwrap(),
                volts["max"].as_f64().unwrap(),
            );
            assert!(
                (11.865..11.875).contains(&min) && (12.015..12.025).contains(&max),
                "{volts}"
            );
            assert_eq!(esc["fields"]["current_a"]["min"], Value::Null);
            assert_eq!(esc["fields"]["phase_current_a"]["min"], Value::Null);
        } else {
            assert_eq!(esc["fields"]["voltage_v"]["min"], Value::Null);
        }
        let portable = text.replace(
            &serde_json::to_string(path).unwrap(),
            &format!("\"{name}\""),
        );
        check_golden(&name.replace(".csv", ".summary.json"), &portable);
    }
    // The Parquet export says which format each ESC spoke and the V4 constants adopted.
    let dir = tempfile::tempdir().unwrap();
    let pq = dir.path().join("v4.parquet");
    let path = capture("platinum-v4.csv");
    let out = run(&[
        "decode",
        "--format",
        "parquet",
        "-o",
        pq.to_str().unwrap(),
        path.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let reader =
        parquet::file::reader::SerializedFileReader::new(std::fs::File::open(&pq).unwrap())
            .unwrap();
    let kv = parquet::file::reader::FileReader::metadata(&reader)
        .file_metadata()
        .key_value_metadata()
        .cloned()
        .unwrap_or_default();
    let value = |key: &str| {
        kv.iter()
            .find(|e| e.key == key)
            .and_then(|e| e.value.clone())
    };
    let escs: Value = serde_json::from_str(&value("escs").unwrap()).unwrap();
    assert_eq!(escs[0]["protocol"], "hw-v4");
    assert_eq!(
        escs[0]["v4_info"],
        serde_json::json!({"full_scale": 1000, "v1": 8, "v2": 91, "i1": 0, "i2": 1, "i3": 0, "t1": 33, "t2": 33})
    );
    assert_eq!(value("v4_volts_per_step").as_deref(), Some("8/910"));
    // Forced to read HW-FOC, the V4 capture has no frame of it, and says what it has.
    let path = capture("platinum-v4.csv");
    let out = run(&["decode", "--protocol", "hw-foc", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(
            "no valid HW-FOC frames: these bytes are hw-v4 frames (try --protocol hw-v4, or \
             leave --protocol out)"
        ),
        "{err}"
    );
}

/// A file that is not telemetry is named as such, not blamed on the baud rate and the wiring
/// (advice for a wire, not for a README given by mistake); `decode`, `summary` and `plot` all
/// fail (exit 1) when no input gave a data frame, and `decode -o` leaves an existing file as
/// it was.
#[test]
fn files_that_are_not_telemetry_are_named_and_every_command_fails_alike() {
    let dir = tempfile::tempdir().unwrap();
    let readme = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../README.md");
    let zeros = dir.path().join("zeros.bin");
    std::fs::write(&zeros, [0u8; 5000]).unwrap();
    let png = dir.path().join("image.png");
    let mut png_bytes = b"\x89PNG\r\n\x1a\n".to_vec();
    png_bytes.extend((0..3000u32).map(|i| (i * 7919 % 251) as u8));
    std::fs::write(&png, png_bytes).unwrap();
    let out_file = dir.path().join("out.csv");
    for (input, reason) in [
        (readme.as_path(), "text, not telemetry"),
        (zeros.as_path(), "only zero bytes, not telemetry"),
        (png.as_path(), "looks like a PNG image, not telemetry"),
    ] {
        let input = input.to_str().unwrap();
        std::fs::write(&out_file, "earlier\n").unwrap();
        let runs = [
            run(&[
                "decode",
                "--format",
                "csv",
                input,
                "--overwrite",
                "-o",
                out_file.to_str().unwrap(),
            ]),
            run(&["summary", input]),
            run(&[
                "plot",
                input,
                "-o",
                dir.path().join("p.png").to_str().unwrap(),
            ]),
        ];
        for out in &runs {
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{input}: {err}");
            let said = err.to_string() + &String::from_utf8_lossy(&out.stdout);
            assert!(said.contains(reason), "{input}: {said}");
            assert!(!said.contains("baud rate"), "{input}: {said}");
        }
        assert!(
            String::from_utf8_lossy(&runs[0].stderr).contains("no data frame in any input"),
            "{input}"
        );
        assert_eq!(std::fs::read_to_string(&out_file).unwrap(), "earlier\n");
        assert!(!dir.path().join("p.png").exists());
    }
}

#[test]
fn stdin_gives_the_same_output_as_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let csv_path = capture(XROTOR);
    let raw_path = dir.path().join("xrotor.bin");
    std::fs::write(&raw_path, csv_bytes(&csv_path)).unwrap();
    for path in [&csv_path, &raw_path] {
        let data = std::fs::read(path).unwrap();
        for args in [
            &["decode"][..],
            &["decode", "--format", "csv"],
            &["summary", "--json"],
        ] {
            let from_file = stdout(&run(&[args, &[path.to_str().unwrap()]].concat()));
            let from_stdin = stdout(&run_stdin(&[args, &["-"]].concat(), &data));
            let from_stdin = from_stdin.replace("\"standard input\"", "INPUT");
            let from_file = from_file.replace(&format!("{:?}", path.to_str().unwrap()), "INPUT");
            assert_eq!(from_file, from_stdin, "{args:?} {}", path.display());
        }
    }
}

#[test]
fn raw_bytes_decode_to_the_same_records_without_time() {
    let dir = tempfile::tempdir().unwrap();
    let raw_path = dir.path().join("xrotor.bin");
    std::fs::write(&raw_path, csv_bytes(&capture(XROTOR))).unwrap();
    let raw = stdout(&run(&["decode", raw_path.to_str().unwrap()]));
    let csv = stdout(&run(&["decode", capture(XROTOR).to_str().unwrap()]));
    assert_eq!(raw.lines().count(), 248);
    for (r, c) in raw.lines().zip(csv.lines()) {
        let mut r: Value = serde_json::from_str(r).unwrap();
        let mut c: Value = serde_json::from_str(c).unwrap();
        assert_eq!(r["t_s"], Value::Null);
        r["t_s"] = Value::Null;
        c["t_s"] = Value::Null;
        assert_eq!(r, c);
    }
}

#[test]
fn csv_output_has_header_and_joined_faults() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("faults.bin");
    let mut wire = Vec::new();
    let status: Status = [Fault::OverCurrent, Fault::OpampPhaseA]
        .into_iter()
        .collect();
    for packet in 0..3u16 {
        let frame = DataFrame {
            packet,
            status: if packet == 1 { status } else { Status::OK },
            mos_adc: 250,
            current_raw: -128,
            ..Default::default()
        };
        wire.extend_from_slice(&frame.encode());
    }
    std::fs::write(&path, &wire).unwrap();
    let out = stdout(&run(&[
        "decode",
        "--format",
        "csv",
        "--settings-comment",
        "--current-scale",
        "100",
        path.to_str().unwrap(),
    ]));
    let lines: Vec<&str> = out.lines().collect();
    assert!(lines[0].starts_with("# hwfoc decode: current_scale=100 pole_pairs=7 gear_ratio=1"));
    assert_eq!(lines[1], TEXT_SCHEMA.join(","));
    assert_eq!(lines.len(), 5);
    // No time in a raw file; MOSFET code 250 is below the table's range, capacitor code 0 above.
    assert_eq!(
        lines[3],
        ",0,hw-foc,1,0.0,0.0,0,0.0,0.0,-1.28,0.0,,,,,,,16388,over_current|opamp_phase_a,,,"
    );
}

#[test]
fn settings_change_the_values() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("one.bin");
    let frame = DataFrame {
        erpm_raw: 1400,
        current_raw: 640,
        phase_current_raw: -320,
        ..Default::default()
    };
    std::fs::write(&path, frame.encode()).unwrap();
    let p = path.to_str().unwrap();
    let get = |extra: &[&str]| -> Value {
        let out = stdout(&run(&[&["decode"][..], extra, &[p]].concat()));
        serde_json::from_str(out.trim()).unwrap()
    };
    let v = get(&[]);
    assert_eq!(
        (v["erpm"].as_u64(), v["rpm"].as_f64()),
        (Some(14000), Some(2000.0))
    );
    assert_eq!(v["current_a"], 10.0);
    assert_eq!(v["phase_current_a"], -5.0);
    let v = get(&[
        "--current-scale",
        "100",
        "--pole-pairs",
        "14",
        "--gear-ratio",
        "2.5",
    ]);
    assert_eq!(v["current_a"], 6.4);
    assert_eq!(v["phase_current_a"], -3.2);
    assert_eq!(v["rpm"], 400.0);
    assert_eq!(v["erpm"], 14000);
}

#[test]
fn output_file_and_demo() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.jsonl");
    let o = run(&["decode", "--demo", "-o", path.to_str().unwrap()]);
    assert!(stdout(&o).is_empty());
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.lines().count() > 100);
    assert!(text.contains("throttle_signal_lost"));
    let summary = stdout(&run(&["summary", "--demo"]));
    assert!(summary.contains("XR_FOC_ESC"), "{summary}");
}

#[test]
fn info_frames_are_summarised_not_recorded() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("info.bin");
    let info = InfoFrame::new("X8_FOC", "HW1", "FW2", "42").unwrap();
    let mut wire = info.encode().to_vec();
    wire.extend_from_slice(&DataFrame::default().encode());
    std::fs::write(&path, &wire).unwrap();
    let p = path.to_str().unwrap();
    assert_eq!(stdout(&run(&["decode", p])).lines().count(), 1);
    let v: Value = serde_json::from_str(&stdout(&run(&["summary", "--json", p]))).unwrap();
    let v = &v["escs"][0];
    assert_eq!(v["info"][0]["text"], "X8_FOC HW1 FW2 42");
    assert_eq!(v["link"]["checksum_failures"], 0);
}

#[test]
fn bad_inputs_fail_with_one_clear_line() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.bin");
    assert_fails_with(
        &run(&["decode", missing.to_str().unwrap()]),
        &format!("cannot open {}", missing.display()),
    );
    assert_fails_with(
        &run(&["summary", dir.path().to_str().unwrap()]),
        "is a directory",
    );
    let empty = dir.path().join("empty.bin");
    std::fs::write(&empty, b"").unwrap();
    assert_fails_with(
        &run(&["decode", empty.to_str().unwrap()]),
        "empty.bin is empty",
    );
    assert_fails_with(
        &run_stdin(&["summary", "-"], b""),
        "standard input is empty",
    );

    let bad = dir.path().join("bad.csv");
    std::fs::write(
        &bad,
        "Time [s],Value,Parity Error,Framing Error\n0.1,0x9B,,\n0.2,0xZZ,,\n",
    )
    .unwrap();
    assert_fails_with(
        &run(&["decode", bad.to_str().unwrap()]),
        &format!("{}:3: bad byte value \"0xZZ\"", bad.display()),
    );
    let bad_time = dir.path().join("bad_time.csv");
    std::fs::write(&bad_time, "Time [s],Value\n0.1,0x9B\nsoon,0x16\n").unwrap();
    assert_fails_with(
        &run(&["summary", bad_time.to_str().unwrap()]),
        "bad_time.csv:3: bad time \"soon\"",
    );
    assert_fails_with(
        &run(&["decode", "--pole-pairs", "0", "--demo"]),
        "pole pairs must be at least 1",
    );
    assert_fails_with(
        &run(&[
            "decode",
            "--demo",
            "-o",
            dir.path().join("no/such/dir/x.jsonl").to_str().unwrap(),
        ]),
        "cannot write",
    );
}

#[test]
fn records_before_a_bad_csv_row_are_kept() {
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from("Time [s],Value,Parity Error,Framing Error\n");
    for (i, b) in DataFrame::default().encode().iter().enumerate() {
        csv.push_str(&format!("{},0x{b:02X},,\n", i as f64 * 0.001));
    }
    csv.push_str("1.0,garbage,,\n");
    let path = dir.path().join("cut.csv");
    std::fs::write(&path, csv).unwrap();
    let o = run(&["decode", path.to_str().unwrap()]);
    assert_fails_with(&o, "cut.csv:26: bad byte value");
    assert_eq!(String::from_utf8_lossy(&o.stdout).lines().count(), 1);
}

#[test]
fn a_closed_pipe_is_not_an_error() {
    // Far more output than a pipe buffers, so that writing fails once the reader has gone.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("long.bin");
    let wire: Vec<u8> = (0..50_000u16)
        .flat_map(|packet| {
            DataFrame {
                packet,
                ..Default::default()
            }
            .encode()
        })
        .collect();
    std::fs::write(&path, wire).unwrap();
    let mut child = hwfoc()
        .args(["decode", path.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = [0u8; 10];
    child
        .stdout
        .as_mut()
        .unwrap()
        .read_exact(&mut first)
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Every command's `--help` is wrapped by clap alone: a paragraph has no line broken short
/// inside it (a hard line break in a help text gave `entry in the` / `(current` / `it` lines).
#[test]
fn help_paragraphs_have_no_broken_lines() {
    let top = stdout(&run(&["--help"]));
    let commands: Vec<&str> = top
        .split("Commands:")
        .nth(1)
        .and_then(|s| s.split("Options:").next())
        .expect("a command list")
        .lines()
        .filter_map(|l| l.strip_prefix("  "))
        .filter(|l| !l.starts_with(' '))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert!(commands.contains(&"decode"), "{top}");
    let indent = |l: &str| l.len() - l.trim_start().len();
    let listed = |l: &str| l.trim_start().starts_with(['-', '[']);
    for command in commands {
        let help = stdout(&run(&[command, "--help"]));
        let lines: Vec<&str> = help.lines().collect();
        for pair in lines.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            let continued = indent(a) >= 10
                && indent(a) == indent(b)
                && !a.trim().is_empty()
                && !b.trim().is_empty()
                && !listed(a)
                && !listed(b);
            assert!(
                !continued || a.len() >= 60,
                "`hwfoc {command} --help` breaks a paragraph after {a:?}"
            );
        }
    }
}
