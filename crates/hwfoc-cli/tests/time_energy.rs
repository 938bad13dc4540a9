//! End-to-end tests of times as people write them (`--from`/`--to`), dates shown where the
//! source has a wall clock, records of several ESCs in time order, and charge, energy and
//! power in `summary` and `plot`: on recordings made here by the project's encoder and pcapng
//! writer, with known times and currents.

mod common;

use std::fs::File;
use std::path::Path;
use std::process::Output;

use arrow_array::{Array, Float64Array, UInt8Array};
use common::{Dir, assert_fails_with, capture, hwfoc, ok, stdout};
use hwfoc::foc::DataFrame;
use hwfoc_io::pcapng;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use serde_json::Value;

/// 2026-11-23T14:03:00Z.
const T0: u64 = 1_795_442_580;
const NS: u64 = 1_000_000_000;

fn run(args: &[&str]) -> Output {
    hwfoc().args(args).output().expect("run hwfoc")
}

/// The data frame every packet carries: `amps` of input current at 25.0 V.
fn frame(packet: u16, amps: i16) -> [u8; 24] {
    DataFrame {
        packet,
        voltage_raw: 250,
        current_raw: amps * 64,
        ..Default::default()
    }
    .encode()
}

/// A recording of one ESC per `(port, amps)`: a data frame every 50 ms for `seconds`, from
/// `start` ns; port `p` `p` ms after port 0. Packets in time order, one frame each.
fn recording(ports: &[(&str, i16)], start: u64, seconds: u64) -> Vec<u8> {
    let mut w = pcapng::Writer::new(Vec::new()).unwrap();
    for (port, _) in ports {
        w.add_interface(port, 19200).unwrap();
    }
    for k in 0..seconds * 20 {
        for (p, &(_, amps)) in ports.iter().enumerate() {
            let t = start + k * 50_000_000 + p as u64 * 1_000_000;
            w.write(p as u32, t, &frame(k as u16, amps)).unwrap();
        }
    }
    w.into_inner().unwrap()
}

/// Two ESCs (36 A and 18 A at 25 V) for 20 s from T0.
fn two_escs(dir: &Dir) -> String {
    let path = dir.arg("two.pcapng");
    let rec = recording(&[("/dev/ttyUSB0", 36), ("/dev/ttyUSB1", 18)], T0 * NS, 20);
    std::fs::write(&path, rec).unwrap();
    path
}

fn jsonl(text: &str) -> Vec<Value> {
    text.lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// ESC and time of each record of a JSON Lines decode.
fn esc_times(records: &[Value]) -> Vec<(u64, f64)> {
    records
        .iter()
        .map(|r| (r["esc"].as_u64().unwrap(), r["t_s"].as_f64().unwrap()))
        .collect()
}

fn assert_time_order(rows: &[(u64, f64)]) {
    assert!(!rows.is_empty());
    for w in rows.windows(2) {
        assert!(
            (w[0].1, w[0].0) < (w[1].1, w[1].0),
            "out of order: {:?} then {:?}",
            w[0],
            w[1]
        );
    }
}

fn decode(input: &str, window: &[&str]) -> Vec<Value> {
    jsonl(&stdout(&ok(
        run(&[&["decode", input][..], window].concat()),
    )))
}

#[test]
fn times_after_the_first_frame_select_exactly_their_frames() {
    let dir = Dir::new();
    let input = two_escs(&dir);
    let window = decode(&input, &["--from", "+5", "--to", "+10"]);
    // ESC 0's frames at +5.000 .. +9.950 s, ESC 1's at +5.001 .. +9.951 s.
    assert_eq!(window.len(), 200);
    let rows = esc_times(&window);
    assert_time_order(&rows);
    let t0 = T0 as f64;
    for (esc, t) in &rows {
        assert!(*t >= t0 + 5.0 && *t < t0 + 10.0, "ESC {esc} at {t}");
    }
    assert_eq!(rows[0], (0, t0 + 5.0));
    assert_eq!(rows.iter().filter(|r| r.0 == 1).count(), 100);
    // The same window written every other way.
    let same = |from: &str, to: &str| {
        assert_eq!(
            decode(&input, &["--from", from, "--to", to]),
            window,
            "{from} {to}"
        );
    };
    same("+5s", "+10000ms");
    same("+PT5S", "+PT10S");
    same("1795442585", "1795442590");
    same("2026-11-23T14:03:05Z", "2026-11-23T14:03:10Z");
    same("2026-11-23T14:03:05.000+00:00", "2026-11-23T15:03:10+01:00");
    same("2026-11-23T09:33:05-04:30", "2026-11-23T14:03:10.000Z");
    // Consecutive windows share no frame and miss none.
    let before = decode(&input, &["--to", "+5"]);
    let after = decode(&input, &["--from", "+5"]);
    assert_eq!((before.len(), after.len()), (200, 600));
    // A window after the first frame counts from the first frame of the inputs, whichever
    // ESC is kept.
    let esc1 = decode(&input, &["--esc", "1", "--from", "+5", "--to", "+10"]);
    assert_eq!(esc1.len(), 100);
    same_time(&esc1[0]["t_s"], t0 + 5.001);
}

#[test]
fn local_times_are_read_in_the_zone_of_tz() {
    let dir = Dir::new();
    let input = two_escs(&dir);
    let expected = decode(&input, &["--from", "+5", "--to", "+10"]);
    for (zone, from, to) in [
        (
            "Europe/Berlin",
            "2026-11-23 15:03:05",
            "2026-11-23T15:03:10",
        ),
        (
            "America/New_York",
            "2026-11-23T09:03:05",
            "2026-11-23 09:03:10.000",
        ),
        ("UTC", "2026-11-23T14:03:05", "2026-11-23 14:03:10"),
    ] {
        let o = ok(hwfoc()
            .env("TZ", zone)
            .args(["decode", &input, "--from", from, "--to", to])
            .output()
            .unwrap());
        assert_eq!(jsonl(&stdout(&o)), expected, "{zone}");
    }
}

#[test]
fn bad_times_are_one_line_naming_the_option_and_the_value() {
    let dir = Dir::new();
    let input = two_escs(&dir);
    for (args, needle) in [
        (
            ["--from", "5x"],
            "invalid value '5x' for '--from <TIME>': \"5x\" is not a time",
        ),
        (
            ["--to", "+-3"],
            "invalid value '+-3' for '--to <TIME>': \"+-3\" is not a time after the first frame",
        ),
        (
            ["--from", "2026-02-30T00:00Z"],
            "invalid value '2026-02-30T00:00Z' for '--from <TIME>': \"2026-02-30T00:00Z\" is not a valid date-time",
        ),
    ] {
        let o = run(&["decode", &input, args[0], args[1]]);
        assert!(!o.status.success());
        let err = String::from_utf8_lossy(&o.stderr);
        let first = err.lines().next().unwrap_or_default();
        assert!(first.contains(needle), "{needle:?} not in {err}");
    }
    assert_fails_with(
        &run(&["decode", &input, "--from", "+10", "--to", "+5"]),
        "--from +10 is not before --to +5",
    );
    // A date for an input without a wall clock could select nothing: refused.
    let csv = capture("xrotor-v4-pro-hv-80A.csv");
    let o = run(&[
        "decode",
        csv.to_str().unwrap(),
        "--from",
        "2026-11-23T14:03:00Z",
    ]);
    assert_fails_with(&o, "--from 2026-11-23T14:03:00.000Z: ");
    assert_fails_with(&o, "(logic-analyser CSV) has no wall clock");
    // Seconds after the first frame, and the analyser's own seconds, work on it.
    let csv = csv.to_str().unwrap();
    let relative = decode(csv, &["--from", "+1", "--to", "+2"]);
    let seconds = decode(csv, &["--from", "1.22798", "--to", "2.22798"]);
    assert!(!relative.is_empty());
    assert_eq!(relative, seconds);
}

/// Reads a Parquet file's `esc` and `t_s` columns.
fn parquet_esc_times(path: &Path) -> Vec<(u64, f64)> {
    let reader = ParquetRecordBatchReaderBuilder::try_new(File::open(path).unwrap())
        .unwrap()
        .build()
        .unwrap();
    let mut rows = Vec::new();
    for batch in reader {
        let batch = batch.unwrap();
        let esc = batch.column_by_name("esc").unwrap();
        let esc = esc.as_any().downcast_ref::<UInt8Array>().unwrap();
        let t = batch.column_by_name("t_s").unwrap();
        let t = t.as_any().downcast_ref::<Float64Array>().unwrap();
        for i in 0..batch.num_rows() {
            rows.push((u64::from(esc.value(i)), t.value(i)));
        }
    }
    rows
}

#[test]
fn records_of_several_escs_come_in_time_order_in_every_format() {
    let dir = Dir::new();
    let input = two_escs(&dir);
    let jsonl_rows = esc_times(&decode(&input, &[]));
    assert_eq!(jsonl_rows.len(), 800);
    assert_time_order(&jsonl_rows);
    assert_eq!(
        jsonl_rows[..4].iter().map(|r| r.0).collect::<Vec<_>>(),
        [0, 1, 0, 1]
    );

    let csv = stdout(&ok(run(&["decode", "--format", "csv", &input])));
    let csv_rows: Vec<(u64, f64)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let mut cells = l.split(',');
            let t = cells.next().unwrap().parse().unwrap();
            let esc = cells.next().unwrap().parse().unwrap();
            (esc, t)
        })
        .collect();
    assert_eq!(csv_rows, jsonl_rows);

    let pq = dir.path("two.parquet");
    ok(run(&[
        "decode",
        "--format",
        "parquet",
        "-o",
        pq.to_str().unwrap(),
        &input,
    ]));
    assert_eq!(parquet_esc_times(&pq), jsonl_rows);

    // Several recordings, of other ports, merged by time: the one given first starts later.
    let late = dir.arg("late.pcapng");
    let early = dir.arg("early.pcapng");
    std::fs::write(&late, recording(&[("/dev/ttyACM0", 5)], (T0 + 3) * NS, 6)).unwrap();
    std::fs::write(&early, recording(&[("/dev/ttyACM1", 7)], T0 * NS, 6)).unwrap();
    let rows = esc_times(&decode(&late, &[early.as_str()]));
    assert_eq!(rows.len(), 240);
    assert_time_order(&rows);
    assert_eq!(rows[0], (1, T0 as f64));
    let merged_pq = dir.path("merged.parquet");
    ok(run(&[
        "decode",
        "--format",
        "parquet",
        "-o",
        merged_pq.to_str().unwrap(),
        &late,
        &early,
    ]));
    assert_eq!(parquet_esc_times(&merged_pq), rows);
}

/// Equal to within what `t_s` resolves: Unix seconds as an `f64` are 0.24 us apart, so the
/// 19.95 s integrated are known to about 1e-8 of themselves.
fn close(a: &Value, b: f64) {
    let a = a.as_f64().unwrap_or_else(|| panic!("{a} is not a number"));
    assert!((a - b).abs() < 5e-8 * b.abs().max(1.0), "{a} != {b}");
}

/// Equal to the microsecond.
fn same_time(a: &Value, b: f64) {
    let a = a.as_f64().unwrap_or_else(|| panic!("{a} is not a number"));
    assert!((a - b).abs() < 1e-6, "{a} != {b}");
}

#[test]
fn summary_gives_charge_energy_and_power_per_esc_and_in_total() {
    let dir = Dir::new();
    let input = two_escs(&dir);
    let top: Value =
        serde_json::from_str(&stdout(&ok(run(&["summary", "--json", &input])))).unwrap();
    // 400 frames 50 ms apart: 399 steps, 19.95 s. 36 A for 19.95 s is 199.5 mAh; at 25 V,
    // 900 W, 4.9875 Wh.
    let e0 = &top["escs"][0]["energy"];
    close(&e0["charge_mah"], 199.5);
    close(&e0["energy_wh"], 4.9875);
    close(&e0["peak_power_w"], 900.0);
    close(&e0["mean_power_w"], 900.0);
    close(&e0["seconds"], 19.95);
    assert_eq!(e0["nominal_period"], false);
    let e1 = &top["escs"][1]["energy"];
    close(&e1["charge_mah"], 99.75);
    close(&e1["peak_power_w"], 450.0);
    let total = &top["energy_total"];
    close(&total["charge_mah"], 299.25);
    close(&total["energy_wh"], 4.9875 * 1.5);
    close(&total["mean_power_w"], 1350.0);
    close(&total["peak_power_w"], 900.0);
    // A current scale of 100: the same raw currents are fewer amperes.
    let scaled: Value = serde_json::from_str(&stdout(&ok(run(&[
        "summary",
        "--json",
        "--current-scale",
        "100",
        &input,
    ]))))
    .unwrap();
    close(&scaled["escs"][0]["energy"]["charge_mah"], 199.5 * 0.64);

    let text = stdout(&ok(run(&["summary", &input])));
    for needle in [
        "energy       199.500 mAh, 4.9875 Wh consumed; input power peak 900.0 W, mean 900.0 W \
         over 19.950 s\n",
        "total        2 ESCs: 299.250 mAh, 7.4813 Wh consumed; input power peak 900.0 W, mean \
         1350.0 W over 19.950 s\n",
    ] {
        assert!(text.contains(needle), "{needle:?} not in\n{text}");
    }

    // The same frames without times: each counts the nominal 50 ms, and the report says so.
    let raw = dir.path("esc0.bin");
    let bytes: Vec<u8> = (0..400u16).flat_map(|k| frame(k, 36)).collect();
    std::fs::write(&raw, bytes).unwrap();
    let raw = raw.to_str().unwrap();
    let top: Value = serde_json::from_str(&stdout(&ok(run(&["summary", "--json", raw])))).unwrap();
    let e = &top["escs"][0]["energy"];
    assert_eq!(e["charge_mah"].as_f64(), Some(199.5));
    assert_eq!(e["energy_wh"].as_f64(), Some(4.9875));
    assert_eq!(e["nominal_period"], true);
    assert_eq!(top["energy_total"], Value::Null);
    let text = stdout(&ok(run(&["summary", raw])));
    assert!(
        text.contains(
            "199.500 mAh, 4.9875 Wh consumed; input power peak 900.0 W, mean 900.0 W \
             over 19.950 s (no receive times: each frame counted as 50 ms)"
        ),
        "{text}"
    );
}

#[test]
fn dates_are_shown_where_the_source_has_a_wall_clock() {
    let dir = Dir::new();
    let input = two_escs(&dir);
    let text = stdout(&ok(run(&["summary", &input])));
    assert!(
        text.contains(
            "time         2026-11-23T14:03:00.000Z .. 2026-11-23T14:03:19.950Z (19.950 s)\n"
        ),
        "{text}"
    );
    let top: Value =
        serde_json::from_str(&stdout(&ok(run(&["summary", "--json", &input])))).unwrap();
    let esc1 = &top["escs"][1];
    assert_eq!(esc1["clock"], "unix");
    assert_eq!(esc1["first_time"], "2026-11-23T14:03:00.001Z");
    assert_eq!(esc1["last_time"], "2026-11-23T14:03:19.951Z");
    same_time(&esc1["first_t_s"], T0 as f64 + 0.001);

    // An analyser's capture has its own seconds, not dates.
    let csv = capture("xrotor-v4-pro-hv-80A.csv");
    let text = stdout(&ok(run(&["summary", csv.to_str().unwrap()])));
    assert!(
        text.contains("time         0.22798 .. 18.25539344 s (the source's clock)\n"),
        "{text}"
    );
    assert!(!text.contains("1970-") && !text.contains("Z .."), "{text}");

    // Plots: the start as a date in the subtitle, and a power panel.
    let svg = dir.path("two.svg");
    ok(run(&["plot", &input, "-o", svg.to_str().unwrap()]));
    let svg = std::fs::read_to_string(&svg).unwrap();
    let texts = plot_texts(&svg);
    assert!(
        texts
            .iter()
            .any(|t| t.contains("time in seconds from the first frame, 2026-11-23T14:03:00.000Z")),
        "{texts:?}"
    );
    for needle in ["Power", "power (W)"] {
        assert_eq!(
            texts.iter().filter(|t| *t == needle).count(),
            2,
            "{needle} once per ESC in {texts:?}"
        );
    }
    assert!(
        texts.iter().any(|t| t.contains("199.5 mAh, 4.99 Wh")),
        "{texts:?}"
    );
    let svg = dir.path("csv.svg");
    ok(run(&[
        "plot",
        csv.to_str().unwrap(),
        "-o",
        svg.to_str().unwrap(),
    ]));
    let texts = plot_texts(&std::fs::read_to_string(&svg).unwrap());
    assert!(
        texts.iter().any(|t| t
            .contains("time in seconds from the first frame (t_s = 0.228, the source's clock)")),
        "{texts:?}"
    );
    assert!(!texts.iter().any(|t| t.contains("1970-")), "{texts:?}");
    assert!(texts.iter().any(|t| t == "power (W)"), "{texts:?}");
}

#[test]
fn a_plot_window_after_the_first_frame_keeps_its_seconds() {
    let dir = Dir::new();
    let input = two_escs(&dir);
    let svg = dir.path("w.svg");
    ok(run(&[
        "plot",
        &input,
        "-o",
        svg.to_str().unwrap(),
        "--from",
        "+5",
        "--to",
        "+10",
    ]));
    let texts = plot_texts(&std::fs::read_to_string(&svg).unwrap());
    let subtitle = texts
        .iter()
        .find(|t| t.starts_with("2 ESCs · "))
        .unwrap_or_else(|| panic!("no subtitle in {texts:?}"));
    assert!(
        subtitle.contains("window from +5.000 s to +10.000 s"),
        "{subtitle}"
    );
    // The time axis is labelled in seconds from the first frame: 5 to 10, not 0 to 5.
    let ticks = |from: usize| -> Vec<String> { (from..from + 6).map(|s| s.to_string()).collect() };
    let has = |ticks: &[String]| texts.windows(6).filter(|w| w == &ticks).count();
    assert_eq!(has(&ticks(5)), 12, "{texts:?}");
    assert_eq!(has(&ticks(0)), 0, "{texts:?}");
}

/// The texts of an SVG image, in order.
fn plot_texts(svg: &str) -> Vec<String> {
    let doc = roxmltree::Document::parse(svg).expect("the SVG is well-formed XML");
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| {
            n.children()
                .filter_map(|c| c.text())
                .collect::<String>()
                .trim()
                .to_string()
        })
        .collect()
}
