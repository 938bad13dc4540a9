//! The configuration file: every command reads it (from the user's configuration directory,
//! `HWFOC_CONFIG` or `--config`), per-ESC and per-port settings change only their ESC, flags win,
//! and a bad file is an error naming its line.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::{Dir, assert_fails_with, hwfoc, ok};
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
        .output()
        .expect("spawn"));
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
        .output()
        .expect("spawn"));
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
        let out = ok(cmd
            .arg("decode")
            .args(args)
            .arg(&input)
            .output()
            .expect("spawn"));
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

/// A record's (esc, rpm, current_a).
type Row = (u64, f32, f32);

/// (esc, rpm, current_a) of each record, in order.
fn values(records: &[Value]) -> Vec<Row> {
    records
        .iter()
        .map(|r| {
            let f = |k: &str| r[k].as_f64().unwrap() as f32;
            (r["esc"].as_u64().unwrap(), f("rpm"), f("current_a"))
        })
        .collect()
}

/// Checks that `changed` is `plain` (the same records under the defaults) with only ESC 1's
/// values changed: its rpm multiplied by `rpm` and its current by `current` (powers of two,
/// so exact in `f32`), ESC 0's the same.
fn only_esc1_changed(plain: &[Row], changed: &[Row], rpm: f32, current: f32) {
    assert_eq!(plain.len(), changed.len());
    let mut seen = [false; 2];
    for (p, c) in plain.iter().zip(changed) {
        assert_eq!(p.0, c.0, "records in another order");
        let (k_rpm, k_current) = if p.0 == 1 { (rpm, current) } else { (1.0, 1.0) };
        assert_eq!((c.1, c.2), (p.1 * k_rpm, p.2 * k_current), "{p:?} {c:?}");
        // Rows where the change shows.
        seen[p.0 as usize] |= p.1 != 0.0 && p.2 != 0.0;
    }
    assert_eq!(seen, [true, true], "no ESC turning with current");
}

/// The configuration of ESC 1 (twice the pole pairs, twice the current scale): its records
/// have half the rpm and half the current, ESC 0's are the defaults'.
const ESC1: &str = "[settings]\npole_pairs = 7\n[esc.1]\npole_pairs = 14\ncurrent_scale = 128\n";

#[test]
fn decode_converts_each_esc_under_its_own_settings() {
    let dir = Dir::new();
    let input = recording(&dir);
    let none = dir.path("none");
    let plain = |args: &[&str]| {
        ok(clean(&none)
            .arg("decode")
            .args(args)
            .output()
            .expect("spawn"))
    };
    let home = user_config(&dir, ESC1);
    let configured = |args: &[&str]| {
        ok(clean(&home)
            .arg("decode")
            .args(args)
            .output()
            .expect("spawn"))
    };

    // JSON Lines, and nothing said on standard error.
    let defaults = values(&jsonl(&plain(&[&input])));
    let out = configured(&[&input]);
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    only_esc1_changed(&defaults, &values(&jsonl(&out)), 0.5, 0.5);

    // CSV, the settings comment naming ESC 1's.
    let out = configured(&["--format", "csv", "--settings-comment", &input]);
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    let comment = lines.next().unwrap();
    assert!(
        comment.starts_with(
            "# hwfoc decode: current_scale=64 pole_pairs=7 gear_ratio=1 v4_volts_per_step=8/910 \
             esc.1.current_scale=128 esc.1.pole_pairs=14 input="
        ),
        "{comment}"
    );
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|&c| c == name).unwrap();
    let (esc, rpm, current) = (col("esc"), col("rpm"), col("current_a"));
    let csv: Vec<Row> = lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            (
                f[esc].parse().unwrap(),
                f[rpm].parse().unwrap(),
                f[current].parse().unwrap(),
            )
        })
        .collect();
    only_esc1_changed(&defaults, &csv, 0.5, 0.5);

    // Parquet, ESC 1's settings in the metadata.
    let pq = dir.arg("out.parquet");
    configured(&["--format", "parquet", "-o", &pq, &input]);
    let (parquet, metadata) = read_parquet(&pq);
    only_esc1_changed(&defaults, &parquet, 0.5, 0.5);
    assert_eq!(metadata("pole_pairs").as_deref(), Some("7"));
    let escs: Value = serde_json::from_str(&metadata("esc_settings").unwrap()).unwrap();
    assert_eq!(
        escs,
        serde_json::json!({"1": {
            "current_scale": 128.0,
            "pole_pairs": 14,
            "gear_ratio": 1.0,
            "v4_volts_per_step": "8/910"
        }})
    );
    // Without settings of an ESC's own, no such key.
    let pq = dir.arg("plain.parquet");
    plain(&["--format", "parquet", "-o", &pq, &input]);
    let (same, metadata) = read_parquet(&pq);
    assert_eq!(same, defaults);
    assert_eq!(metadata("esc_settings"), None);
}

/// (esc, rpm, current_a) of each row of a Parquet file, and its key-value metadata by key.
fn read_parquet(path: &str) -> (Vec<Row>, impl Fn(&str) -> Option<String>) {
    use arrow_array::cast::AsArray;
    use arrow_array::types::{Float32Type, UInt8Type};
    use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;

    let reader =
        ParquetRecordBatchReaderBuilder::try_new(std::fs::File::open(path).unwrap()).unwrap();
    let kv = reader
        .metadata()
        .file_metadata()
        .key_value_metadata()
        .cloned()
        .unwrap_or_default();
    let mut rows = Vec::new();
    for batch in reader.build().unwrap() {
        let batch = batch.unwrap();
        let column = |name: &str| batch.column(batch.schema().index_of(name).unwrap()).clone();
        let (esc, rpm, current) = (column("esc"), column("rpm"), column("current_a"));
        let (esc, rpm, current) = (
            esc.as_primitive::<UInt8Type>(),
            rpm.as_primitive::<Float32Type>(),
            current.as_primitive::<Float32Type>(),
        );
        for i in 0..batch.num_rows() {
            rows.push((u64::from(esc.value(i)), rpm.value(i), current.value(i)));
        }
    }
    let metadata = move |key: &str| {
        kv.iter()
            .find(|e| e.key == key)
            .and_then(|e| e.value.clone())
    };
    (rows, metadata)
}

#[test]
fn a_ports_settings_apply_in_decode_to_the_esc_read_from_it() {
    let dir = Dir::new();
    let input = recording(&dir);
    // The recording names its ports esc-0 and esc-1.
    let out = ok(clean(&dir.path("none"))
        .args(["summary", "--json", &input])
        .output()
        .expect("spawn"));
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["escs"][1]["stream"], "esc-1", "{report}");
    let defaults = values(&jsonl(&ok(clean(&dir.path("none"))
        .args(["decode", &input])
        .output()
        .expect("spawn"))));
    let home = user_config(
        &dir,
        "[port.\"esc-1\"]\ngear_ratio = 2\ncurrent_scale = 32\n",
    );
    let out = ok(clean(&home)
        .args(["decode", &input])
        .output()
        .expect("spawn"));
    only_esc1_changed(&defaults, &values(&jsonl(&out)), 0.5, 2.0);
}

#[test]
fn summary_converts_each_esc_under_its_own_settings() {
    let dir = Dir::new();
    let input = recording(&dir);
    let none = dir.path("none");
    let home = user_config(&dir, ESC1);
    let json = |home: &Path| -> Value {
        let out = ok(clean(home)
            .args(["summary", "--json", &input])
            .output()
            .expect("spawn"));
        assert!(
            out.stderr.is_empty(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let (plain, configured) = (json(&none), json(&home));
    let field = |report: &Value, esc: usize, name: &str, stat: &str| {
        report["escs"][esc]["fields"][name][stat].as_f64().unwrap()
    };
    for stat in ["min", "max", "mean"] {
        for name in ["rpm", "current_a", "phase_current_a"] {
            assert_eq!(
                field(&configured, 0, name, stat),
                field(&plain, 0, name, stat)
            );
            assert_eq!(
                field(&configured, 1, name, stat),
                field(&plain, 1, name, stat) / 2.0,
                "{name} {stat}"
            );
        }
        // What does not depend on the settings is the same.
        for esc in 0..2 {
            let name = "erpm";
            assert_eq!(
                field(&configured, esc, name, stat),
                field(&plain, esc, name, stat)
            );
        }
    }
    assert!(field(&plain, 1, "rpm", "max") > 0.0 && field(&plain, 1, "current_a", "max") > 0.0);
    // Charge and energy follow the current.
    let energy = |report: &Value, esc: usize, key: &str| {
        report["escs"][esc]["energy"][key].as_f64().unwrap()
    };
    for key in ["charge_mah", "energy_wh"] {
        assert_eq!(energy(&configured, 0, key), energy(&plain, 0, key));
        let (half, whole) = (energy(&configured, 1, key), energy(&plain, 1, key));
        assert!(
            whole > 0.0 && (half * 2.0 - whole).abs() <= whole * 1e-12,
            "{key}"
        );
    }
    // ESC 1's settings in its object; the others' are the report's.
    assert_eq!(
        configured["escs"][1]["settings"],
        serde_json::json!({
            "current_scale": 128.0,
            "pole_pairs": 14,
            "gear_ratio": 1.0,
            "v4_volts_per_step": "8/910"
        })
    );
    assert!(configured["escs"][0].get("settings").is_none());
    assert!(plain["escs"][1].get("settings").is_none());
    assert_eq!(configured["settings"], plain["settings"]);

    // The text: the settings line names ESC 1's, the figures are converted under them.
    let text = |home: &Path| {
        let out = ok(clean(home)
            .args(["summary", &input])
            .output()
            .expect("spawn"));
        assert!(
            out.stderr.is_empty(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let (plain_text, configured_text) = (text(&none), text(&home));
    assert_eq!(
        configured_text.lines().next(),
        Some(
            "settings     current scale 64, pole pairs 7, gear ratio 1; \
             ESC 1: current scale 128, pole pairs 14"
        )
    );
    assert_eq!(
        plain_text.lines().next(),
        Some("settings     current scale 64, pole pairs 7, gear ratio 1")
    );
    // ESC 0's part is the same; ESC 1's differs (its rpm and currents).
    let part = |text: &str, esc: usize| -> String {
        let start = text.find(&format!("\nESC {esc} ")).unwrap();
        let rest = &text[start + 1..];
        let end = rest.find("\nESC ").map_or(rest.len(), |e| e + 1);
        rest[..end].to_string()
    };
    assert_eq!(part(&configured_text, 0), part(&plain_text, 0));
    assert_ne!(part(&configured_text, 1), part(&plain_text, 1));
    let row = |text: &str, name: &str| -> String {
        part(text, 1)
            .lines()
            .find(|l| l.starts_with(&format!("{name} ")))
            .unwrap_or_else(|| panic!("no {name} in {text}"))
            .to_string()
    };
    assert_ne!(row(&configured_text, "rpm"), row(&plain_text, "rpm"));
    assert_eq!(row(&configured_text, "erpm"), row(&plain_text, "erpm"));
}

#[test]
fn summary_plot_and_simulate_read_it_too() {
    let dir = Dir::new();
    let input = recording(&dir);
    let home = user_config(&dir, "[settings]\npole_pairs = 14\ncurrent_scale = 100\n");
    // summary reports the settings it used.
    let out = ok(clean(&home)
        .args(["summary", "--json", &input])
        .output()
        .expect("spawn"));
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["settings"]["pole_pairs"], 14, "{report}");
    assert_eq!(report["settings"]["current_scale"], 100.0, "{report}");
    // plot names them under its title.
    let svg = dir.arg("plot.svg");
    ok(clean(&home)
        .args(["plot", &input, "-o", &svg])
        .output()
        .expect("spawn"));
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
        .output()
        .expect("spawn"));
    let truth: Vec<Value> = std::fs::read_to_string(&truth)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let with = jsonl(&ok(clean(&home)
        .args(["decode", &raw])
        .output()
        .expect("spawn")));
    let rpm = |v: &[Value]| -> Vec<f64> { v.iter().map(|r| r["rpm"].as_f64().unwrap()).collect() };
    assert_eq!(rpm(&with), rpm(&truth));
    assert!(rpm(&truth).iter().any(|&r| r > 100.0));
    let without = jsonl(&ok(clean(&home)
        .args(["decode", "--no-config", &raw])
        .output()
        .expect("spawn")));
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
        .output()
        .expect("spawn"));
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
        .output()
        .expect("spawn"));
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
        .output()
        .expect("spawn"));
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
        let out = clean(&home).args(args).output().expect("spawn");
        assert_fails_with(&out, "config.toml line 6: unknown field `curent_scale`");
    }
    // Two entries of one ESC: both lines are named.
    let home = user_config(
        &dir,
        "[esc.1]\npole_pairs = 14\n\n[esc.01]\npole_pairs = 7\n",
    );
    let out = clean(&home)
        .args(["summary", "--demo"])
        .output()
        .expect("spawn");
    assert_fails_with(
        &out,
        "config.toml line 4: [esc.01] names the same ESC as [esc.1] on line 1",
    );
    // Out of range: the entry is named.
    let home = user_config(&dir, "[esc.3]\npole_pairs = 0\n");
    let out = clean(&home)
        .args(["decode", "--demo"])
        .output()
        .expect("spawn");
    assert_fails_with(&out, "config.toml ([esc.3])");
    // A file named and missing.
    let out = clean(&home)
        .args(["decode", "--demo", "--config", "/nonexistent/hwfoc.toml"])
        .output()
        .expect("spawn");
    assert_fails_with(&out, "/nonexistent/hwfoc.toml");
    // --no-config reads none of it.
    ok(clean(&home)
        .args(["decode", "--demo", "--no-config"])
        .output()
        .expect("spawn"));
    // The help says how settings are found.
    let help = ok(hwfoc().args(["decode", "--help"]).output().expect("spawn"));
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(
        help.contains("[esc.N]") && help.contains("HWFOC_CONFIG"),
        "{help}"
    );
}

/// The output of `cmd`, which must end within 20 s (it is killed and the test fails otherwise).
#[cfg(unix)]
fn within_deadline(cmd: &mut Command) -> Output {
    let mut child = common::spawn(cmd);
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
    while child.try_wait().expect("wait").is_none() {
        if std::time::Instant::now() > deadline {
            child.kill().ok();
            child.wait().ok();
            panic!("hwfoc still running after 20 s: {cmd:?}");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.wait_with_output().expect("wait")
}

#[cfg(unix)]
#[test]
fn a_configuration_that_is_not_a_regular_file_is_an_error_naming_it() {
    use nix::sys::stat::Mode;
    let dir = Dir::new();
    let fifo = dir.path("fifo.toml");
    nix::unistd::mkfifo(&fifo, Mode::S_IRUSR | Mode::S_IWUSR).unwrap();
    let fifo_arg = fifo.to_str().unwrap();
    let none = dir.path("none");
    // Named with --config, and with HWFOC_CONFIG: nothing ever writes to the FIFO.
    let out = within_deadline(clean(&none).args(["summary", "--demo", "--config", fifo_arg]));
    assert_fails_with(
        &out,
        &format!("{fifo_arg}: it is a FIFO, not a regular file"),
    );
    let out = within_deadline(
        clean(&none)
            .env("HWFOC_CONFIG", &fifo)
            .args(["decode", "--demo"]),
    );
    assert_fails_with(&out, &format!("{fifo_arg}: it is a FIFO"));
    // At the default place: a FIFO, then a directory, are errors too (not a file skipped).
    let home = dir.path("xdg");
    std::fs::create_dir_all(home.join("hwfoc")).unwrap();
    let default = home.join("hwfoc/config.toml");
    nix::unistd::mkfifo(&default, Mode::S_IRUSR | Mode::S_IWUSR).unwrap();
    let out = within_deadline(clean(&home).args(["summary", "--demo"]));
    assert_fails_with(
        &out,
        &format!("{}: it is a FIFO", default.to_str().unwrap()),
    );
    std::fs::remove_file(&default).unwrap();
    std::fs::create_dir(&default).unwrap();
    let out = within_deadline(clean(&home).args(["summary", "--demo"]));
    assert_fails_with(&out, "config.toml: it is a directory, not a regular file");
    // --no-config reads nothing there.
    ok(within_deadline(clean(&home).args([
        "summary",
        "--demo",
        "--no-config",
    ])));
}

/// `--set KEY=VALUE` sets a format's own setting by its description's key (`-` or `_`), as its
/// flag does (`--v4-volts-per-step`, an alias that wins); each key is a configuration key too;
/// an unknown key or a bad value is a usage error naming the keys or the value's form.
#[test]
fn set_key_value_sets_the_formats_own_settings_by_their_descriptions_keys() {
    let dir = Dir::new();
    let input = recording(&dir);
    let home = dir.path("none");
    let comment = |args: &[&str]| {
        let out = ok(clean(&home)
            .args(["decode", "--format", "csv", "--settings-comment"])
            .args(args)
            .arg(&input)
            .output()
            .expect("spawn"));
        let text = String::from_utf8(out.stdout).unwrap();
        text.lines().next().unwrap().to_string()
    };
    let hv = comment(&["--v4-volts-per-step", "hv"]);
    assert!(hv.contains(" v4_volts_per_step=11/650 "), "{hv}");
    for setting in hwfoc::Protocol::settings() {
        let key = setting.key;
        assert_eq!(comment(&["--set", &format!("{key}=hv")]), hv);
        assert_eq!(
            comment(&["--set", &format!("{}=hv", key.replace('_', "-"))]),
            hv
        );
        // The flag wins over --set; the last --set wins.
        let both = [
            "--set",
            &format!("{key}=8/900"),
            "--v4-volts-per-step",
            "hv",
        ];
        assert_eq!(comment(&both), hv);
        let twice = [
            "--set",
            &format!("{key}=8/900"),
            "--set",
            &format!("{key}=hv"),
        ];
        assert_eq!(comment(&twice), hv);
        // A configuration key of the same name, its description's default a value it takes.
        let configured = user_config(&dir, &format!("[settings]\n{key} = \"hv\"\n"));
        let out = ok(clean(&configured)
            .args(["decode", "--format", "csv", "--settings-comment", &input])
            .output()
            .expect("spawn"));
        let first = String::from_utf8(out.stdout).unwrap();
        assert_eq!(first.lines().next(), Some(hv.as_str()));
        let default = user_config(
            &dir,
            &format!("[settings]\n{key} = \"{}\"\n", setting.default),
        );
        ok(clean(&default)
            .args(["decode", &input])
            .output()
            .expect("spawn"));
    }
    let bad = |set: &str, needle: &str| {
        let out = clean(&home)
            .args(["decode", "--set", set, &input])
            .output()
            .expect("spawn");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(needle), "{needle:?} not in {err}");
        assert!(!err.contains("panicked"), "{err}");
    };
    bad(
        "nope=1",
        "no format has this setting; the settings are: v4_volts_per_step",
    );
    bad(
        "v4_volts_per_step=8/0",
        "v4_volts_per_step: volts per step must be N/D",
    );
    bad("v4_volts_per_step", "is not KEY=VALUE");
}
