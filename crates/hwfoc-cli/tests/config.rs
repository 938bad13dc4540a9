//! The configuration file: every command reads it (from the user's configuration directory,
//! `HWFOC_CONFIG` or `--config`), per-ESC and per-port settings change only their ESC, flags win,
//! and a bad file is an error naming its line.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::{Dir, OutputLocked, assert_fails_with, hwfoc, ok};
use serde_json::Value;

/// `hwfoc` with no configuration of the user's: an empty configuration directory, no
/// `HWFOC_CONFIG`.
fn clean(config_home: &Path) -> Command {
    let mut cmd = hwfoc();
    cmd.env("XDG_CONFIG_HOME", config_home)
        .env_remove("HWFOC_CONFIG");
    cmd
}

fn jsonl(out: &Output) -> Vec<Value> {
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect()
}

/// A recording of two virtual ESCs, their motors turning.
fn recording(dir: &Dir) -> String {
    let path = dir.arg("two.pcapng");
    ok(clean(&dir.path("none"))
        .args(["simulate", "--escs", "2", "--seed", "5", "--duration", "6"])
        .args(["--quiet", "--no-config", "-o", &path])
        .output_locked());
    path
}

/// (esc, erpm, rpm, current_a) of the records with the motor turning.
fn turning(records: &[Value]) -> Vec<(u64, f64, f64, f64)> {
    records
        .iter()
        .map(|r| {
            (
                r["esc"].as_u64().unwrap(),
                r["erpm"].as_f64().unwrap(),
                r["rpm"].as_f64().unwrap(),
                r["current_a"].as_f64().unwrap(),
            )
        })
        .filter(|r| r.1 > 0.0)
        .collect()
}

/// Writes `text` as the user's configuration file under a fresh configuration directory.
fn user_config(dir: &Dir, text: &str) -> std::path::PathBuf {
    let home = dir.path("xdg");
    std::fs::create_dir_all(home.join("hwfoc")).unwrap();
    std::fs::write(home.join("hwfoc/config.toml"), text).unwrap();
    home
}

/// The status lines of `hwfoc monitor --sim 2 --json` under the configuration in `home`, by
/// ESC: (pole pairs, gear ratio, current scale, rpm * pole pairs * gear ratio / erpm).
fn monitor_settings(home: &Path, extra: &[&str]) -> Vec<(u64, f64, f64, f64, f64)> {
    let out = ok(clean(home)
        .args([
            "monitor",
            "--sim",
            "2",
            "--json",
            "--interval",
            "0.5",
            "--duration",
            "2.7",
        ])
        .args(extra)
        .output_locked());
    let values = jsonl(&out);
    let last = |esc: u64| {
        values
            .iter()
            .rev()
            .find(|v| v["type"] == "status" && v["esc"] == esc && v["record"].is_object())
            .unwrap_or_else(|| panic!("no status of esc {esc}: {values:#?}"))
    };
    (0..2)
        .map(|esc| {
            let v = last(esc);
            let s = &v["settings"];
            let (pairs, ratio) = (
                s["pole_pairs"].as_f64().unwrap(),
                s["gear_ratio"].as_f64().unwrap(),
            );
            let r = &v["record"];
            let (erpm, rpm) = (r["erpm"].as_f64().unwrap(), r["rpm"].as_f64().unwrap());
            let k = if erpm > 0.0 {
                rpm * pairs * ratio / erpm
            } else {
                1.0
            };
            (esc, pairs, ratio, s["current_scale"].as_f64().unwrap(), k)
        })
        .collect()
}

#[test]
fn per_esc_settings_change_only_that_escs_rpm_and_current() {
    let dir = Dir::new();
    let home = user_config(
        &dir,
        "[settings]
pole_pairs = 7

[esc.1]
pole_pairs = 14
current_scale = 128
",
    );
    let escs = monitor_settings(&home, &[]);
    assert_eq!(escs[0].1..=escs[0].3, 7.0..=64.0, "{escs:?}");
    assert_eq!(escs[1].1..=escs[1].3, 14.0..=128.0, "{escs:?}");
    // Each record's rpm is its erpm under its own ESC's settings.
    assert!(escs.iter().all(|e| (e.4 - 1.0).abs() < 0.01), "{escs:?}");
}

#[test]
fn a_ports_settings_apply_to_the_esc_read_from_it() {
    let dir = Dir::new();
    let home = user_config(&dir, "[port.\"sim:esc1\"]\ngear_ratio = 4\n");
    let escs = monitor_settings(&home, &[]);
    assert_eq!((escs[0].2, escs[1].2), (1.0, 4.0), "{escs:?}");
    assert!(escs.iter().all(|e| (e.4 - 1.0).abs() < 0.01), "{escs:?}");
}

#[test]
fn flags_beat_the_file_and_the_file_beats_the_defaults() {
    let dir = Dir::new();
    // Per ESC: a flag wins over [esc.N] for the field it sets, [esc.N] keeps the others.
    let home = user_config(
        &dir,
        "[settings]\npole_pairs = 14\n[esc.1]\npole_pairs = 2\ngear_ratio = 3\n",
    );
    let escs = monitor_settings(&home, &[]);
    assert_eq!(
        (escs[0].1, escs[1].1, escs[1].2),
        (14.0, 2.0, 3.0),
        "{escs:?}"
    );
    let escs = monitor_settings(&home, &["--pole-pairs", "5"]);
    assert_eq!(
        (escs[0].1, escs[1].1, escs[1].2),
        (5.0, 5.0, 3.0),
        "{escs:?}"
    );

    // For every ESC alike (decode): the flag, [settings], the defaults.
    let input = recording(&dir);
    let home = user_config(&dir, "[settings]\npole_pairs = 14\n");
    let ratio = |cmd: &mut Command, args: &[&str]| -> Vec<f64> {
        let out = ok(cmd.arg("decode").args(args).arg(&input).output_locked());
        let mut seen: Vec<f64> = turning(&jsonl(&out))
            .iter()
            .map(|r| (r.1 / r.2 * 1000.0).round() / 1000.0)
            .collect();
        seen.dedup();
        seen
    };
    assert_eq!(ratio(&mut clean(&home), &[]), [14.0]);
    assert_eq!(ratio(&mut clean(&home), &["--pole-pairs", "5"]), [5.0]);
    assert_eq!(ratio(&mut clean(&home), &["--no-config"]), [7.0]);
    // --config and HWFOC_CONFIG name other files; --config wins over HWFOC_CONFIG.
    let other = dir.path("other.toml");
    std::fs::write(&other, "[settings]\npole_pairs = 3\n").unwrap();
    let third = dir.path("third.toml");
    std::fs::write(&third, "[settings]\npole_pairs = 9\n").unwrap();
    let named = ["--config", other.to_str().unwrap()];
    assert_eq!(ratio(&mut clean(&home), &named), [3.0]);
    assert_eq!(ratio(clean(&home).env("HWFOC_CONFIG", &third), &[]), [9.0]);
    assert_eq!(
        ratio(clean(&home).env("HWFOC_CONFIG", &third), &named),
        [3.0]
    );
}

#[test]
fn decode_says_when_it_cannot_apply_per_esc_settings() {
    let dir = Dir::new();
    let input = recording(&dir);
    let home = user_config(
        &dir,
        "[settings]\npole_pairs = 14\n[esc.1]\npole_pairs = 2\n",
    );
    let out = ok(clean(&home).args(["decode", &input]).output_locked());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("[esc.N] and [port] settings"), "{stderr}");
    assert!(
        turning(&jsonl(&out))
            .iter()
            .all(|r| (r.1 / r.2 - 14.0).abs() < 1e-3)
    );
    // Without such entries, nothing is said.
    let home = user_config(&dir, "[settings]\npole_pairs = 14\n");
    let out = ok(clean(&home).args(["decode", &input]).output_locked());
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn summary_plot_and_simulate_read_it_too() {
    let dir = Dir::new();
    let input = recording(&dir);
    let home = user_config(&dir, "[settings]\npole_pairs = 14\ncurrent_scale = 100\n");
    // summary reports the settings it used.
    let out = ok(clean(&home)
        .args(["summary", "--json", &input])
        .output_locked());
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["settings"]["pole_pairs"], 14, "{report}");
    assert_eq!(report["settings"]["current_scale"], 100.0, "{report}");
    // plot names them under its title.
    let svg = dir.arg("plot.svg");
    ok(clean(&home)
        .args(["plot", &input, "-o", &svg])
        .output_locked());
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("14 pole pairs"), "no settings in the plot");
    // simulate encodes under them: its frames decode to its truth under the same file, and to
    // twice the RPM under the defaults.
    let raw = dir.arg("one.bin");
    let truth = dir.arg("truth.jsonl");
    ok(clean(&home)
        .args([
            "simulate",
            "--duration",
            "5",
            "--quiet",
            "-o",
            &raw,
            "--truth",
            &truth,
        ])
        .output_locked());
    let truth: Vec<Value> = std::fs::read_to_string(&truth)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let with = jsonl(&ok(clean(&home).args(["decode", &raw]).output_locked()));
    let rpm = |v: &[Value]| -> Vec<f64> { v.iter().map(|r| r["rpm"].as_f64().unwrap()).collect() };
    assert_eq!(rpm(&with), rpm(&truth));
    assert!(rpm(&truth).iter().any(|&r| r > 100.0));
    let without = jsonl(&ok(clean(&home)
        .args(["decode", "--no-config", &raw])
        .output_locked()));
    for (a, b) in rpm(&without).iter().zip(rpm(&truth)) {
        assert!((a - 2.0 * b).abs() < 0.01, "{a} {b}");
    }
}

#[test]
fn the_monitor_converts_each_esc_under_its_own_settings() {
    let dir = Dir::new();
    let home = user_config(
        &dir,
        "[esc.1]\npole_pairs = 14\nlabel = \"tail\"\n[monitor]\nbaud = 19200\n",
    );
    let out = ok(clean(&home)
        .args([
            "monitor",
            "--sim",
            "2",
            "--json",
            "--interval",
            "0.5",
            "--duration",
            "3.2",
        ])
        .output_locked());
    let values = jsonl(&out);
    let status = |esc: u64| -> Vec<&Value> {
        values
            .iter()
            .filter(|v| v["type"] == "status" && v["esc"] == esc)
            .collect()
    };
    let (zero, one) = (status(0), status(1));
    assert!(!zero.is_empty() && !one.is_empty(), "{values:#?}");
    assert_eq!(zero[0]["settings"]["pole_pairs"], 7);
    assert_eq!(one[0]["settings"]["pole_pairs"], 14);
    assert_eq!(one[0]["label"], "tail");
    for (v, pairs) in [(zero.last().unwrap(), 7.0), (one.last().unwrap(), 14.0)] {
        let r = &v["record"];
        let (erpm, rpm) = (r["erpm"].as_f64().unwrap(), r["rpm"].as_f64().unwrap());
        assert!((rpm * pairs - erpm).abs() < 0.5, "{v}");
    }
}

#[test]
fn the_older_monitor_file_is_still_read_by_the_monitor() {
    let dir = Dir::new();
    let home = dir.path("xdg");
    std::fs::create_dir_all(home.join("hwfoc")).unwrap();
    std::fs::write(
        home.join("hwfoc/monitor.toml"),
        "pole_pairs = 14\n[alarms]\nmos_warning_c = 10\nmos_critical_c = 120\n\
         [[esc]]\nport = \"sim:esc0\"\nlabel = \"tail rotor\"\n",
    )
    .unwrap();
    let out = ok(clean(&home)
        .args([
            "monitor",
            "--sim",
            "1",
            "--json",
            "--interval",
            "0.5",
            "--duration",
            "1.6",
        ])
        .output_locked());
    let values = jsonl(&out);
    let status = values.iter().find(|v| v["type"] == "status").unwrap();
    assert_eq!(status["label"], "tail rotor");
    assert_eq!(status["settings"]["pole_pairs"], 14);
    assert!(
        values
            .iter()
            .any(|v| v["type"] == "alarm" && v["alarm"] == "mos_temp"),
        "{values:#?}"
    );
    // A config.toml beside it is the one read.
    std::fs::write(
        home.join("hwfoc/config.toml"),
        "[settings]\npole_pairs = 3\n",
    )
    .unwrap();
    let out = ok(clean(&home)
        .args([
            "monitor",
            "--sim",
            "1",
            "--json",
            "--interval",
            "0.5",
            "--duration",
            "1.2",
        ])
        .output_locked());
    let values = jsonl(&out);
    let status = values.iter().find(|v| v["type"] == "status").unwrap();
    assert_eq!(status["settings"]["pole_pairs"], 3);
    assert_eq!(status["label"], Value::Null);
}

#[test]
fn a_bad_file_is_an_error_naming_its_line_and_key() {
    let dir = Dir::new();
    let home = user_config(
        &dir,
        "[settings]\npole_pairs = 7\n\n[esc.1]\npole_pairs = 14\ncurent_scale = 100\n",
    );
    for args in [
        &["decode", "--demo"][..],
        &["summary", "--demo"],
        &["plot", "--demo", "-o", &dir.arg("p.svg")],
        &["simulate", "--duration", "1", "-o", &dir.arg("s.bin")],
        &["monitor", "--sim", "1", "--plain", "--duration", "1"],
    ] {
        let out = clean(&home).args(args).output_locked();
        assert_fails_with(&out, "config.toml line 6: unknown field `curent_scale`");
    }
    // Out of range: the entry is named.
    let home = user_config(&dir, "[esc.3]\npole_pairs = 0\n");
    let out = clean(&home).args(["decode", "--demo"]).output_locked();
    assert_fails_with(&out, "config.toml ([esc.3])");
    // A file named and missing.
    let out = clean(&home)
        .args(["decode", "--demo", "--config", "/nonexistent/hwfoc.toml"])
        .output_locked();
    assert_fails_with(&out, "/nonexistent/hwfoc.toml");
    // --no-config reads none of it.
    ok(clean(&home)
        .args(["decode", "--demo", "--no-config"])
        .output_locked());
    // The help says how settings are found.
    let help = ok(hwfoc().args(["decode", "--help"]).output_locked());
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(
        help.contains("[esc.N]") && help.contains("HWFOC_CONFIG"),
        "{help}"
    );
}
