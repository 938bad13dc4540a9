//! Raw files (no receive times) are timed at their format's frame period: the summary's charge,
//! duration and its words, and the plot's time axis.

mod common;

use std::process::Output;

use common::{Dir, hwfoc, ok, stdout};

fn run(args: &[&str]) -> Output {
    hwfoc().args(args).output().expect("run hwfoc")
}

/// Each format's raw file: the summary says its frame period, and integrates over frames that
/// far apart; the plot's subtitle says the same.
#[test]
fn raw_files_are_timed_at_their_formats_frame_period() {
    let dir = Dir::new();
    for (protocol, ms, s) in [
        ("hw-foc", "50", "0.05"),
        ("hw-v4", "51", "0.051"),
        ("hw-v3", "19.5", "0.0195"),
        ("hw5", "20", "0.02"),
    ] {
        let raw = dir.arg(&format!("{protocol}.bin"));
        ok(run(&[
            "simulate",
            "--protocol",
            protocol,
            "--duration",
            "6",
            "-o",
            &raw,
            "--quiet",
        ]));
        let text = stdout(&run(&["summary", &raw]));
        let json: serde_json::Value =
            serde_json::from_str(&stdout(&run(&["summary", "--json", &raw]))).unwrap();
        let esc = &json["escs"][0];
        if protocol == "hw-v3" {
            // V3 carries no voltage or current: no charge to integrate.
            assert!(esc["energy"].is_null(), "{esc}");
        } else {
            assert!(
                text.contains(&format!("each frame counted as {ms} ms")),
                "{protocol}: {text}"
            );
            let frames = esc["frames"].as_f64().unwrap();
            let seconds = esc["energy"]["seconds"].as_f64().unwrap();
            let period: f64 = s.parse().unwrap();
            // Every step between frames carrying power is one period (a V4 ESC's first frames,
            // before its info frame is adopted, carry no current).
            let steps = seconds / period;
            assert!(
                (steps - steps.round()).abs() < 1e-6
                    && steps.round() <= frames - 1.0
                    && steps.round() >= (frames - 1.0) * 0.9,
                "{protocol}: {seconds} s for {frames} frames"
            );
        }
        let svg = dir.arg(&format!("{protocol}.svg"));
        ok(run(&["plot", &raw, "-o", &svg]));
        let image = std::fs::read_to_string(&svg).unwrap();
        assert!(
            image.contains(&format!("data frame index × {s} s")),
            "{protocol}: no period {s} in the subtitle"
        );
        assert!(
            image.contains(&format!("frame index × {s} (s)")),
            "{protocol}: no period {s} on the time axis"
        );
    }
}
