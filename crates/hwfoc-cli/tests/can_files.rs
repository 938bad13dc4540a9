//! The CAN log files of the common tools as inputs, end to end through the `hwfoc` binary:
//! Vector ASC and BLF, PEAK TRC 1.1 and 2.1, python-can CSV and candump's own text, written by
//! python-can from the frames of `testdata/dronecan/can-bus.log` (`scripts/can-files.py`;
//! `.ci/python-can.sh` checks the committed files are what it writes, and runs the check here
//! that needs python-can). Every file decodes to exactly the records of the candump log;
//! a CAN file that is not DroneCAN says so in CAN words; a damaged one is a one-line error.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use common::{Dir, assert_fails_with, hwfoc, records, stdout};

/// The committed files of `scripts/can-files.py`, with the format `summary --json` names.
const FILES: [(&str, &str); 6] = [
    ("can-bus.asc", "asc"),
    ("can-bus.blf", "blf"),
    ("can-bus-v2.1.trc", "trc"),
    ("can-bus-v1.1.trc", "trc"),
    ("can-bus.csv", "can-csv"),
    ("can-bus.candump.txt", "candump-text"),
];

fn dronecan(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../testdata/dronecan")
        .join(name)
}

/// `hwfoc` with the time zone the files' local dates (ASC) were written in.
fn run(args: &[&str]) -> Output {
    hwfoc()
        .env("TZ", "UTC")
        .args(args)
        .output()
        .expect("run hwfoc")
}

#[test]
fn every_python_can_file_decodes_to_the_records_of_the_candump_log() {
    let log = dronecan("can-bus.log");
    let want = records(&stdout(&run(&["decode", log.to_str().unwrap()])));
    assert_eq!(want.len(), 58);
    for (file, format) in FILES {
        let path = dronecan(file);
        let got = records(&stdout(&run(&["decode", path.to_str().unwrap()])));
        assert_eq!(got.len(), want.len(), "{file}");
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g, w, "{file}: record {k}");
        }
        let summary: serde_json::Value = serde_json::from_str(&stdout(&run(&[
            "summary",
            "--json",
            path.to_str().unwrap(),
        ])))
        .unwrap();
        assert_eq!(summary["inputs"][0]["format"], format, "{file}");
        eprintln!("{file}: {} records as the candump log's", got.len());
    }
    // candump's text without times: the same records, without times (nor the ages of the
    // slower messages, which are times).
    let untimed = dronecan("can-bus.candump-untimed.txt");
    let got = records(&stdout(&run(&["decode", untimed.to_str().unwrap()])));
    let timeless = |r: &serde_json::Value| {
        let mut r = r.clone();
        for key in ["t_s", "msg2_age_ms", "msg3_age_ms"] {
            r[key] = serde_json::Value::Null;
        }
        r
    };
    assert_eq!(got, want.iter().map(timeless).collect::<Vec<_>>());
    eprintln!(
        "can-bus.candump-untimed.txt: {} records as the candump log's, untimed",
        got.len()
    );
    // The format is read from the content: on standard input too, as the candump log there
    // (which cannot be read ahead: its ESCs are numbered as they are heard).
    let want = on_stdin("can-bus.log");
    for file in ["can-bus.blf", "can-bus.asc"] {
        assert_eq!(on_stdin(file), want, "{file} on standard input");
    }
}

/// The records of `decode -` given a file of `testdata/dronecan` on standard input.
fn on_stdin(file: &str) -> Vec<serde_json::Value> {
    {
        let bytes = std::fs::read(dronecan(file)).unwrap();
        let mut child = hwfoc()
            .env("TZ", "UTC")
            .args(["decode", "-"])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let mut stdin = child.stdin.take().unwrap();
        std::thread::spawn(move || std::io::Write::write_all(&mut stdin, &bytes));
        let out = child.wait_with_output().unwrap();
        records(&stdout(&out))
    }
}

/// Frames of a bus that is not DroneCAN (11-bit ids, a car's), as each format writes them.
fn not_dronecan(dir: &Dir) -> Vec<PathBuf> {
    let asc = "date Tue Nov 14 22:13:20.000 2023\nbase hex  timestamps absolute\n\
               Begin Triggerblock Tue Nov 14 22:13:20.000 2023\n\
               0.001000 1  123       Rx   d 2 11 22\n0.002000 1  1A0       Rx   d 8 00 01 02 03 04 05 06 07\n\
               End TriggerBlock\n";
    let csv = "timestamp,arbitration_id,extended,remote,error,dlc,data\n\
               1700000000.001,0x123,0,0,0,2,ESI=\n1700000000.002,0x1a0,0,0,0,1,AA==\n";
    let asc_path = dir.path("car.asc");
    let csv_path = dir.path("car.csv");
    std::fs::write(&asc_path, asc).unwrap();
    std::fs::write(&csv_path, csv).unwrap();
    let blf_path = dir.path("car.blf");
    std::fs::write(&blf_path, blf_of_standard_frames()).unwrap();
    vec![asc_path, csv_path, blf_path]
}

/// A BLF file of two CAN messages (type 1) with 11-bit ids in an uncompressed log container,
/// laid out as python-can's `BLFWriter` lays its objects.
fn blf_of_standard_frames() -> Vec<u8> {
    let mut objects = Vec::new();
    for (k, id) in [0x123u32, 0x1A0].into_iter().enumerate() {
        objects.extend_from_slice(b"LOBJ");
        objects.extend_from_slice(&32u16.to_le_bytes());
        objects.extend_from_slice(&1u16.to_le_bytes());
        objects.extend_from_slice(&48u32.to_le_bytes());
        objects.extend_from_slice(&1u32.to_le_bytes());
        objects.extend_from_slice(&2u32.to_le_bytes()); // nanoseconds
        objects.extend_from_slice(&[0; 4]);
        objects.extend_from_slice(&(k as u64 * 1_000_000).to_le_bytes());
        objects.extend_from_slice(&1u16.to_le_bytes()); // channel
        objects.extend_from_slice(&[0, 2]); // flags, dlc
        objects.extend_from_slice(&id.to_le_bytes());
        objects.extend_from_slice(&[0x11, 0x22, 0, 0, 0, 0, 0, 0]);
    }
    let mut file = b"LOGG".to_vec();
    file.extend_from_slice(&144u32.to_le_bytes());
    file.resize(40, 0);
    for w in [2023u16, 11, 2, 14, 22, 13, 20, 0] {
        file.extend_from_slice(&w.to_le_bytes());
    }
    file.resize(144, 0);
    file.extend_from_slice(b"LOBJ");
    file.extend_from_slice(&16u16.to_le_bytes());
    file.extend_from_slice(&1u16.to_le_bytes());
    file.extend_from_slice(&(32 + objects.len() as u32).to_le_bytes());
    file.extend_from_slice(&10u32.to_le_bytes());
    file.extend_from_slice(&0u16.to_le_bytes());
    file.extend_from_slice(&[0; 6]);
    file.extend_from_slice(&(objects.len() as u32).to_le_bytes());
    file.extend_from_slice(&[0; 4]);
    file.extend_from_slice(&objects);
    file
}

#[test]
fn a_can_file_that_is_not_dronecan_says_so_in_can_words() {
    let dir = Dir::new();
    for path in not_dronecan(&dir) {
        let name = path.to_str().unwrap();
        for command in ["decode", "summary"] {
            let out = run(&[command, name]);
            let err = String::from_utf8_lossy(&out.stderr);
            let text = format!("{}{err}", String::from_utf8_lossy(&out.stdout));
            assert_eq!(out.status.code(), Some(1), "{command} {name}: {text}");
            assert!(
                text.contains("2 CAN frames") && text.contains("11-bit ids"),
                "{command} {name}: {text}"
            );
            assert!(
                !text.contains("baud rate") && !text.contains("not telemetry"),
                "{text}"
            );
            assert!(!text.contains("panicked"), "{text}");
        }
    }
}

#[test]
fn damaged_can_files_are_one_line_errors_naming_them() {
    let dir = Dir::new();
    let blf = std::fs::read(dronecan("can-bus.blf")).unwrap();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("cut.blf", blf[..blf.len() - 100].to_vec(), "cut.blf: at byte "),
        (
            "zlib.blf",
            {
                let mut b = blf.clone();
                for x in &mut b[200..260] {
                    *x ^= 0x5A;
                }
                b
            },
            "zlib.blf: at byte ",
        ),
        (
            "bad.asc",
            b"date Tue Nov 14 22:13:20.000 2023\nbase hex  timestamps absolute\n 0.1 1 123 Rx d 9 00\n"
                .to_vec(),
            "bad.asc:3: the length is not 0 to 8: not a Vector ASC log",
        ),
        (
            "old.trc",
            b";$FILEVERSION=3.0\n".to_vec(),
            "old.trc:1: version 3.0 is not read (1.1 to 2.1 are)",
        ),
        (
            "mixed.txt",
            b" (1700000000.000000)  can0  123   [2]  11 22\n  can0  123   [2]  11 22\n".to_vec(),
            "mixed.txt:2: a line with no time among lines with times: not one candump's text",
        ),
    ];
    for (name, bytes, needle) in cases {
        let path = dir.path(name);
        std::fs::write(&path, bytes).unwrap();
        let out = run(&["decode", path.to_str().unwrap()]);
        assert_fails_with(&out, needle);
    }
}

/// `scripts/can-files.py --check`: the committed files are what python-can writes from the
/// candump log's frames, and python-can reads each back as those frames.
#[test]
#[ignore = "needs python-can (HWFOC_PYTHON_CAN_PY, or python3 with `can`): .ci/python-can.sh runs it"]
fn the_committed_files_are_what_python_can_writes() {
    let python = std::env::var("HWFOC_PYTHON_CAN_PY").unwrap_or_else(|_| "python3".into());
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/can-files.py");
    let out = Command::new(&python)
        .arg(script)
        .arg("--check")
        .output()
        .unwrap_or_else(|e| panic!("{python}: {e} (install python-can in a venv)"));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!("{}", text.trim());
}
