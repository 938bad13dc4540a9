//! Strings from files reach a terminal escaped: a recording whose port name, comment and
//! device-information text hold terminal controls (clear the screen, set the window title,
//! return to the start of the line, ring the bell) is summarised, decoded and plotted without
//! one raw control character in the text a person reads; JSON keeps the exact strings.

mod common;

use std::process::Output;

use common::{Dir, hwfoc, ok};
use serde_json::Value;

/// Clears the screen, sets the window title, fakes a line over the one printed.
const PORT: &str = "/dev/ttyUSB0\x1b[2J\x1b]0;owned\x07\rhwfoc: all fine";
const COMMENT: &str = "gap\x1b[2J\x1b]0;title\x07\r\nhwfoc: fake line\u{9b}31m";

/// A recording of one ESC on the crafted port: data frames, an information frame whose text
/// holds controls, and the crafted comment.
fn crafted(dir: &Dir) -> String {
    let path = dir.arg("crafted.pcapng");
    let file = std::fs::File::create(&path).unwrap();
    let mut w = hwfoc_io::pcapng::Writer::new(file).unwrap();
    let port = w.add_interface(PORT, 19_200).unwrap();
    let t0 = 1_700_000_000_000_000_000u64;
    let info = hwfoc::foc::InfoFrame::new("\x1b[2JXR\x07", "\x1b]0;hw\x07", "\rFAKE\x1b[1A", "id")
        .unwrap()
        .encode();
    w.write(port, t0, &info).unwrap();
    for packet in 0..40u16 {
        let frame = hwfoc::foc::DataFrame {
            packet,
            erpm_raw: 70,
            ..Default::default()
        }
        .encode();
        let t = t0 + 50_000_000 * (u64::from(packet) + 1);
        w.write(port, t, &frame).unwrap();
        if packet == 20 {
            w.comment(port, t + 1, COMMENT).unwrap();
        }
    }
    w.flush().unwrap();
    path
}

/// The first raw control character (other than the line ends) of `text`, with its context.
fn raw_control(text: &[u8]) -> Option<String> {
    let text = String::from_utf8_lossy(text);
    let at = text.find(|c: char| c.is_control() && c != '\n')?;
    Some(format!("{:?}", &text[at.saturating_sub(40)..]))
}

fn run(args: &[&str]) -> Output {
    ok(hwfoc()
        .args(args)
        .arg("--no-config")
        .output()
        .expect("spawn"))
}

fn no_raw_controls(out: &Output, what: &str) {
    for (stream, bytes) in [("stdout", &out.stdout), ("stderr", &out.stderr)] {
        if let Some(found) = raw_control(bytes) {
            panic!("{what}: a raw control character on {stream}: {found}");
        }
    }
}

#[test]
fn strings_from_a_recording_are_shown_with_controls_escaped() {
    let dir = Dir::new();
    let file = crafted(&dir);

    let summary = run(&["summary", &file]);
    no_raw_controls(&summary, "summary");
    let text = String::from_utf8_lossy(&summary.stdout);
    let stderr = String::from_utf8_lossy(&summary.stderr);
    // Shown, escaped, not left out.
    assert!(
        text.contains("/dev/ttyUSB0\\x1b[2J\\x1b]0;owned\\x07\\rhwfoc"),
        "{text}"
    );
    assert!(text.contains("\\x1b[2JXR\\x07"), "{text}");
    assert!(
        stderr.contains("gap\\x1b[2J\\x1b]0;title\\x07\\r\\nhwfoc: fake line\\u{9b}31m"),
        "{stderr}"
    );

    // JSON keeps the exact strings (JSON escapes them).
    let json = run(&["summary", "--json", &file]);
    no_raw_controls(&json, "summary --json");
    let report: Value = serde_json::from_slice(&json.stdout).unwrap();
    assert!(report.to_string().contains("owned"), "{report}");
    let names: Vec<&str> = report["escs"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|e| e["stream"].as_str())
        .collect();
    assert_eq!(names, [PORT], "{report}");

    let decode = run(&["decode", &file]);
    no_raw_controls(&decode, "decode");
    assert!(
        String::from_utf8_lossy(&decode.stderr).contains("fake line"),
        "the comment is shown"
    );

    let svg = dir.arg("p.svg");
    let plot = run(&["plot", &file, "-o", &svg]);
    no_raw_controls(&plot, "plot");
    let image = std::fs::read(&svg).unwrap();
    if let Some(found) = raw_control(&image) {
        panic!("a raw control character in the SVG: {found}");
    }
    let image = String::from_utf8(image).unwrap();
    assert!(image.contains("\\x1b[2J"), "the port is named in the image");
}

#[test]
fn a_configurations_strings_are_shown_with_controls_escaped() {
    let dir = Dir::new();
    // An error quoting a key of the file.
    let bad = dir.path("bad.toml");
    std::fs::write(&bad, "\"\\u001b]0;title\\u0007\" = 1\n").unwrap();
    let out = hwfoc()
        .args(["summary", "--demo", "--config", bad.to_str().unwrap()])
        .output()
        .expect("spawn");
    common::assert_fails_with(&out, "unknown field `\\x1b]0;title\\x07`");
    no_raw_controls(&out, "a configuration error");
    // A label in the monitor's plain lines.
    let labels = dir.path("labels.toml");
    std::fs::write(&labels, "[esc.0]\nlabel = \"front\\u001b[2J\\r\"\n").unwrap();
    let out = ok(hwfoc()
        .args(["monitor", "--sim", "1", "--plain", "--duration", "1.2"])
        .args(["--config", labels.to_str().unwrap()])
        .output()
        .expect("spawn"));
    no_raw_controls(&out, "monitor --plain");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("esc0 front\\x1b[2J\\r: "), "{text}");
}
