//! End-to-end tests of exports (Parquet, CSV, JSON Lines), filters, several inputs, the per-ESC
//! summary with fault episodes, and output errors.

mod common;

use std::fs::File;
use std::path::Path;
use std::process::{Output, Stdio};
use std::sync::Arc;

use common::{SCHEMA, XROTOR, assert_fails_with, capture, hwfoc, stdout};

use arrow_array::cast::AsArray;
use arrow_array::types::{
    Float32Type, Float64Type, Int8Type, TimestampMicrosecondType, UInt8Type, UInt16Type, UInt32Type,
};
use arrow_array::{Array, ArrayRef, RecordBatch};
use arrow_schema::{DataType, TimeUnit};
use hwfoc::foc::{DataFrame, InfoFrame};
use hwfoc::{Fault, Status};
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use serde_json::{Value, json};

fn run(args: &[&str]) -> Output {
    hwfoc().args(args).output().expect("run hwfoc")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A frame whose fields all depend on `i`, so that every column varies.
fn frame(i: u16, status: Status) -> DataFrame {
    DataFrame {
        packet: i,
        throttle_in_raw: i % 1025,
        throttle_out_raw: i.wrapping_mul(7) % 1025,
        erpm_raw: i.wrapping_mul(13),
        voltage_raw: 200 + i % 300,
        current_raw: (i as i16).wrapping_mul(3).wrapping_sub(500),
        phase_current_raw: -(i as i16 % 4000),
        // Codes 20 and 250 are out of the ADC table's range: null temperatures.
        mos_adc: (i % 256) as u8,
        cap_adc: (255 - i % 256) as u8,
        status,
    }
}

/// Raw bytes of `n` frames from packet `first`, with faults on the frames `faulty` selects, an
/// information frame at the start and some line noise.
fn wire(first: u16, n: u16, faulty: impl Fn(u16) -> Status) -> Vec<u8> {
    let mut w = InfoFrame::new("X8_FOC", "HW1", "FW2", "42")
        .unwrap()
        .encode()
        .to_vec();
    for k in 0..n {
        let i = first.wrapping_add(k);
        w.extend_from_slice(&frame(i, faulty(k)).encode());
        if k % 97 == 5 {
            w.extend_from_slice(&[0x00, 0x9B, 0x17]);
        }
    }
    w
}

/// Offset of frame `k` in [`wire`]'s bytes: after the information frame, and after the noise
/// following frame 5.
fn offset(k: usize) -> usize {
    77 + 24 * k + if k > 5 { 3 } else { 0 }
}

/// A logic-analyser CSV of `bytes`, byte `i` received at `t0 + i * dt`.
fn analyser_csv(bytes: &[u8], t0: f64, dt: f64) -> String {
    let mut csv = String::from("Time [s],Value,Parity Error,Framing Error\n");
    for (i, b) in bytes.iter().enumerate() {
        csv.push_str(&format!("{},0x{b:02X},,\n", t0 + i as f64 * dt));
    }
    csv
}

fn jsonl(text: &str) -> Vec<Value> {
    text.lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

fn read_parquet(
    path: &Path,
) -> (
    Arc<arrow_schema::Schema>,
    Vec<(String, String)>,
    RecordBatch,
) {
    let builder = ParquetRecordBatchReaderBuilder::try_new(File::open(path).unwrap()).unwrap();
    let schema = builder.schema().clone();
    let kv = builder
        .metadata()
        .file_metadata()
        .key_value_metadata()
        .cloned()
        .unwrap_or_default()
        .into_iter()
        .map(|kv| (kv.key, kv.value.unwrap_or_default()))
        .collect();
    // One batch for the whole (small) file.
    let mut reader = builder.with_batch_size(1 << 20).build().unwrap();
    let batch = reader.next().unwrap().unwrap();
    assert!(reader.next().is_none());
    (schema, kv, batch)
}

fn kv<'a>(kv: &'a [(String, String)], key: &str) -> &'a str {
    kv.iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
        .unwrap_or_else(|| panic!("no {key} in {kv:?}"))
}

/// Row `row` of `array` as the JSON Lines record gives it, by the array's type.
fn json_value(array: &ArrayRef, row: usize) -> Value {
    if array.is_null(row) {
        return Value::Null;
    }
    match array.data_type() {
        DataType::Float64 => Value::from(array.as_primitive::<Float64Type>().value(row)),
        DataType::Float32 => Value::from(array.as_primitive::<Float32Type>().value(row)),
        DataType::UInt8 => Value::from(array.as_primitive::<UInt8Type>().value(row)),
        DataType::UInt16 => Value::from(array.as_primitive::<UInt16Type>().value(row)),
        DataType::UInt32 => Value::from(array.as_primitive::<UInt32Type>().value(row)),
        DataType::List(_) => {
            let names = array.as_list::<i32>().value(row);
            let names = names.as_string::<i32>();
            Value::from_iter(names.iter().map(|n| n.unwrap().to_string()))
        }
        DataType::Dictionary(_, _) => {
            let dict = array.as_dictionary::<Int8Type>();
            let key = dict.keys().value(row);
            Value::from(dict.values().as_string::<i32>().value(key as usize))
        }
        // `time` (Parquet only): microseconds since the epoch, UTC.
        DataType::Timestamp(TimeUnit::Microsecond, Some(zone)) if &**zone == "UTC" => {
            Value::from(array.as_primitive::<TimestampMicrosecondType>().value(row))
        }
        other => panic!("a column type this test does not know: {other}"),
    }
}

/// Every value of the Parquet file equals the JSON Lines record of the same row, column by
/// column of the schema (the column table's).
fn assert_same_records(batch: &RecordBatch, records: &[Value]) {
    assert_eq!(batch.num_rows(), records.len());
    let schema = batch.schema();
    let columns: Vec<(&str, &ArrayRef)> = schema
        .fields()
        .iter()
        .map(|f| f.name().as_str())
        .zip(batch.columns())
        .collect();
    assert_eq!(columns.len(), SCHEMA.len());
    for (row, r) in records.iter().enumerate() {
        for &(name, array) in &columns {
            let got = json_value(array, row);
            // `time` (not in JSON Lines): the instant of `t_s`, in whole microseconds.
            let time = |t: &Value| {
                t.as_f64()
                    .map_or(Value::Null, |t| ((t * 1e6).round() as i64).into())
            };
            let expected = &match name {
                "time" => time(&r["t_s"]),
                _ => r[name].clone(),
            };
            if *array.data_type() == DataType::Float32 && !got.is_null() {
                // JSON numbers are the shortest text of the f32: they read back to the same f32.
                let as_f32 = |v: &Value| v.as_f64().map(|v| v as f32);
                assert_eq!(as_f32(&got), as_f32(expected), "{name} row {row}");
            } else {
                assert_eq!(&got, expected, "{name} row {row}");
            }
        }
    }
}

#[test]
fn parquet_has_the_schema_units_and_metadata_and_the_jsonl_values() {
    let dir = tempfile::tempdir().unwrap();
    // A real capture (with receive times) and a synthetic raw stream (with faults and
    // out-of-range temperatures, no times) read together: ESC 0 and ESC 1.
    let raw = dir.path().join("faults.bin");
    let status: Status = [Fault::OverCurrent, Fault::MosOverheat]
        .into_iter()
        .collect();
    std::fs::write(
        &raw,
        wire(
            65000,
            1500,
            |k| if k % 50 < 7 { status } else { Status::OK },
        ),
    )
    .unwrap();
    let real = capture(XROTOR);
    let pq = dir.path().join("out.parquet");
    let settings = [
        "--current-scale",
        "100",
        "--pole-pairs",
        "14",
        "--gear-ratio",
        "2.5",
    ];
    let inputs = [s(&real), s(&raw)];
    let base: Vec<&str> = [&["decode"][..], &settings, &inputs].concat();
    let parquet_args = [&base[..], &["--format", "parquet", "-o", s(&pq)]].concat();
    stdout(&run(&parquet_args));
    let records = jsonl(&stdout(&run(&base)));
    assert_eq!(records.len(), 248 + 1500);

    let (schema, meta, batch) = read_parquet(&pq);
    // The schema of the column table (checked against docs/RECORD-SCHEMA.md by hwfoc-io's tests),
    // units in the fields' metadata.
    assert_eq!(schema.fields(), hwfoc_io::write::arrow::schema().fields());
    let names: Vec<&str> = schema.fields().iter().map(|f| f.name().as_str()).collect();
    assert_eq!(names, SCHEMA);
    assert_eq!(kv(&meta, "current_scale"), "100");
    assert_eq!(kv(&meta, "pole_pairs"), "14");
    assert_eq!(kv(&meta, "gear_ratio"), "2.5");
    assert_eq!(kv(&meta, "hwfoc_version"), env!("CARGO_PKG_VERSION"));
    let inputs: Value = serde_json::from_str(kv(&meta, "inputs")).unwrap();
    assert_eq!(inputs, json!([s(&real), s(&raw)]));
    let escs: Value = serde_json::from_str(kv(&meta, "escs")).unwrap();
    assert_eq!(
        escs,
        json!([
            {"esc": 0, "input": s(&real), "stream": s(&real), "protocol": "hw-foc"},
            {"esc": 1, "input": s(&raw), "stream": s(&raw), "protocol": "hw-foc"},
        ])
    );
    assert_same_records(&batch, &records);
    // The raw stream has no times, nulls where the ADC codes are out of range, faults.
    let last = &records[records.len() - 1];
    assert_eq!(last["esc"], 1);
    assert_eq!(last["t_s"], Value::Null);
    assert!(records.iter().any(|r| r["mos_temp_c"].is_null()));
    assert!(
        records
            .iter()
            .any(|r| r["faults"] == json!(["over_current", "mos_overheat"]))
    );
    assert!(batch.column_by_name("t_s").unwrap().null_count() == 1500);
}

/// A long recording of healthy ESCs: blocks of rows that all have times and temperatures in
/// range (the writer's fast paths), then a raw stream of the same ESCs without times.
#[test]
fn parquet_of_long_runs_matches_jsonl() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("run.pcapng");
    let raw = dir.path().join("run.bin");
    let sim = ["simulate", "--duration", "300"];
    stdout(&run(&[&sim[..], &["--escs", "2", "-o", s(&rec)]].concat()));
    stdout(&run(&[&sim[..], &["--escs", "1", "-o", s(&raw)]].concat()));
    let pq = dir.path().join("out.parquet");
    let inputs = ["decode", s(&rec), s(&raw)];
    stdout(&run(
        &[&inputs[..], &["--format", "parquet", "-o", s(&pq)]].concat()
    ));
    let records = jsonl(&stdout(&run(&inputs)));
    assert!(records.len() > 12_000, "{} records", records.len());
    assert!(records.iter().all(|r| !r["mos_temp_c"].is_null()));
    let (_, _, batch) = read_parquet(&pq);
    assert_same_records(&batch, &records);
    let t = batch.column_by_name("t_s").unwrap();
    assert_eq!(
        t.null_count(),
        records.iter().filter(|r| r["t_s"].is_null()).count()
    );
    assert!(t.null_count() > 4000 && t.null_count() < records.len());
}

#[test]
fn parquet_row_groups_and_standard_input() {
    let dir = tempfile::tempdir().unwrap();
    // More rows than one row group holds, from standard input in small pieces.
    let bytes: Vec<u8> = (0..300_000u32)
        .flat_map(|i| frame(i as u16, Status::OK).encode())
        .collect();
    let pq = dir.path().join("big.parquet");
    let mut child = hwfoc()
        .args(["decode", "--format", "parquet", "-o", s(&pq), "-"])
        .stdin(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut pipe = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || {
        use std::io::Write;
        for piece in bytes.chunks(5000) {
            pipe.write_all(piece).unwrap();
        }
    });
    writer.join().unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let reader = ParquetRecordBatchReaderBuilder::try_new(File::open(&pq).unwrap()).unwrap();
    let meta = reader.metadata().clone();
    assert!(
        meta.num_row_groups() >= 2,
        "{} row groups",
        meta.num_row_groups()
    );
    assert_eq!(meta.file_metadata().num_rows(), 300_000);
    let mut next = 0u32;
    for batch in reader.build().unwrap() {
        let batch = batch.unwrap();
        let packets = batch
            .column_by_name("packet")
            .unwrap()
            .as_primitive::<UInt32Type>();
        for p in packets.values() {
            assert_eq!(*p, next % 65_536, "a 16-bit counter in a uint32 column");
            next += 1;
        }
    }
    assert_eq!(next, 300_000);
}

#[test]
fn parquet_needs_an_output_file() {
    let o = run(&["decode", "--demo", "--format", "parquet"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--output"), "{err}");
}

#[test]
fn several_inputs_are_numbered_escs_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.bin");
    let b = dir.path().join("b.csv");
    let c = dir.path().join("c.bin");
    std::fs::write(&a, wire(0, 40, |_| Status::OK)).unwrap();
    std::fs::write(
        &b,
        analyser_csv(&wire(100, 30, |_| Status::OK), 10.0, 0.0005),
    )
    .unwrap();
    std::fs::write(&c, wire(200, 20, |_| Status::OK)).unwrap();
    for format in ["jsonl", "csv"] {
        let out = stdout(&run(&["decode", "--format", format, s(&a), s(&b), s(&c)]));
        let rows: Vec<(u64, u64)> = if format == "jsonl" {
            jsonl(&out)
                .iter()
                .map(|r| (r["esc"].as_u64().unwrap(), r["packet"].as_u64().unwrap()))
                .collect()
        } else {
            let mut lines = out.lines();
            assert!(
                lines
                    .next()
                    .unwrap()
                    .starts_with("t_s,esc,protocol,packet,")
            );
            lines
                .map(|l| {
                    let f: Vec<&str> = l.split(',').collect();
                    assert_eq!(f[2], "hw-foc");
                    (f[1].parse().unwrap(), f[3].parse().unwrap())
                })
                .collect()
        };
        let expected: Vec<(u64, u64)> = (0..40)
            .map(|p| (0, p))
            .chain((100..130).map(|p| (1, p)))
            .chain((200..220).map(|p| (2, p)))
            .collect();
        assert_eq!(rows, expected, "{format}");
    }

    let v: Value =
        serde_json::from_str(&stdout(&run(&["summary", "--json", s(&a), s(&b), s(&c)]))).unwrap();
    let inputs = v["inputs"].as_array().unwrap();
    assert_eq!(inputs.len(), 3);
    assert_eq!(inputs[1]["format"], "csv");
    assert_eq!(inputs[1]["escs"], json!([1]));
    let escs = v["escs"].as_array().unwrap();
    assert_eq!(escs.len(), 3);
    for (i, (esc, frames)) in escs.iter().zip([40, 30, 20]).enumerate() {
        assert_eq!(esc["esc"], i);
        assert_eq!(esc["frames"], frames);
        assert_eq!(esc["info"][0]["text"], "X8_FOC HW1 FW2 42");
        assert_eq!(esc["link"]["lost_packets"], 0);
    }
    // Only the CSV has times.
    assert_eq!(escs[0]["first_t_s"], Value::Null);
    assert_eq!(escs[1]["first_t_s"], 10.0 + 77.0 * 0.0005);
    let text = stdout(&run(&["summary", s(&a), s(&b), s(&c)]));
    for needle in [
        "ESC 0 ",
        "ESC 1 ",
        "ESC 2 ",
        "(logic-analyser CSV, ",
        "ESC 1)",
        "40 data, 1 info",
    ] {
        assert!(text.contains(needle), "{needle:?} not in\n{text}");
    }
}

#[test]
fn esc_and_time_filters() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.csv");
    let b = dir.path().join("b.csv");
    // 24 bytes per frame at 1 ms per byte: a frame every 24 ms after the 77-byte info frame.
    std::fs::write(&a, analyser_csv(&wire(0, 100, |_| Status::OK), 0.0, 0.001)).unwrap();
    std::fs::write(
        &b,
        analyser_csv(&wire(500, 100, |_| Status::OK), 0.0, 0.001),
    )
    .unwrap();
    let records = |extra: &[&str]| {
        jsonl(&stdout(&run(
            &[&["decode", s(&a), s(&b)][..], extra].concat()
        )))
    };
    let all = records(&[]);
    assert_eq!(all.len(), 200);

    let only_1 = records(&["--esc", "1"]);
    assert_eq!(only_1.len(), 100);
    assert!(only_1.iter().all(|r| r["esc"] == 1));
    assert_eq!(records(&["--esc", "0,1"]).len(), 200);
    assert_eq!(records(&["--esc", "1", "--esc", "0"]).len(), 200);

    // --from is inclusive, --to exclusive: consecutive windows share no frame.
    let t_of = |k: usize| 0.0 + offset(k) as f64 * 0.001;
    let from = format!("{}", t_of(10));
    let to = format!("{}", t_of(20));
    let window = records(&["--from", &from, "--to", &to]);
    assert_eq!(window.len(), 20);
    for r in &window {
        let t = r["t_s"].as_f64().unwrap();
        assert!(t >= t_of(10) && t < t_of(20), "{t}");
    }
    let before = records(&["--to", &from]);
    let after = records(&["--from", &from]);
    assert_eq!(before.len() + after.len(), 200);
    let both = records(&["--esc", "0", "--from", &from, "--to", &to]);
    assert_eq!(both.len(), 10);

    // The filters are recorded with a Parquet export.
    let pq = dir.path().join("f.parquet");
    stdout(&run(&[
        "decode",
        s(&a),
        s(&b),
        "--esc",
        "0",
        "--from",
        &from,
        "--format",
        "parquet",
        "-o",
        s(&pq),
    ]));
    let (_, meta, batch) = read_parquet(&pq);
    assert_eq!(batch.num_rows(), 90);
    assert_eq!(kv(&meta, "filter"), format!("esc=0 from={from}"));

    // No time in raw bytes: a time filter is refused before anything is written.
    let raw = dir.path().join("raw.bin");
    std::fs::write(&raw, wire(0, 10, |_| Status::OK)).unwrap();
    let out = dir.path().join("never.jsonl");
    let o = run(&["decode", s(&a), s(&raw), "--from", "1", "-o", s(&out)]);
    assert_fails_with(
        &o,
        &format!(
            "hwfoc: --from/--to select frames by time, but {} is raw bytes without receive \
             times: use a recording (`hwfoc record`) or a logic-analyser CSV, or leave out \
             --from/--to\n",
            s(&raw)
        ),
    );
    assert!(!out.exists());
    assert_fails_with(
        &run(&["decode", s(&a), "--from", "2", "--to", "1"]),
        "--from 2 is not before --to 1",
    );
    // A window that holds no frame (say, seconds from the start given for a recording whose
    // t_s are Unix times): no records, and a warning giving the times the frames have.
    let o = run(&["decode", s(&a), "--from", "1000", "--to", "1001"]);
    assert!(stdout(&o).is_empty());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(
            "no frame in the time window (from=1000 to=1001): the frames' t_s run from 0.077 to"
        ),
        "{err}"
    );
    // An ESC that is not there: no records, and a warning.
    let o = run(&["decode", s(&a), "--esc", "3"]);
    assert!(stdout(&o).is_empty());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--esc 3: the inputs have only ESC 0"), "{err}");
}

#[test]
fn summary_lists_fault_episodes_per_esc() {
    let dir = tempfile::tempdir().unwrap();
    let over = Status::OK.with(Fault::OverCurrent);
    let both = over.with(Fault::MosOverheat);
    // Episodes: frames 10..=19 (over_current, then also mos_overheat), 30..=34, and 95..=99
    // still going on at the end.
    let faulty = move |k: u16| match k {
        10..=14 => over,
        15..=19 => both,
        30..=34 => Status::OK.with(Fault::ThrottleSignalLost),
        95.. => over,
        _ => Status::OK,
    };
    let raw = dir.path().join("raw.bin");
    std::fs::write(&raw, wire(1000, 100, faulty)).unwrap();
    let csv = dir.path().join("timed.csv");
    std::fs::write(&csv, analyser_csv(&wire(0, 100, faulty), 5.0, 0.001)).unwrap();
    let v: Value =
        serde_json::from_str(&stdout(&run(&["summary", "--json", s(&raw), s(&csv)]))).unwrap();
    for (i, esc) in v["escs"].as_array().unwrap().iter().enumerate() {
        assert_eq!(esc["fault_episode_count"], 3);
        let e = esc["fault_episodes"].as_array().unwrap();
        assert_eq!(e.len(), 3);
        assert_eq!(
            (e[0]["start_frame"].as_u64(), e[0]["end_frame"].as_u64()),
            (Some(10), Some(19))
        );
        assert_eq!(e[0]["frames"], 10);
        assert_eq!(e[0]["faults"], json!(["over_current", "mos_overheat"]));
        assert_eq!(e[0]["ongoing"], false);
        assert_eq!(e[1]["faults"], json!(["throttle_signal_lost"]));
        assert_eq!(e[1]["frames"], 5);
        assert_eq!(e[2]["ongoing"], true);
        assert_eq!(e[2]["end_frame"], 99);
        assert_eq!(esc["faults"]["over_current"], 15);
        assert_eq!(esc["faults"]["mos_overheat"], 5);
        let first_packet = if i == 0 { 1010 } else { 10 };
        assert_eq!(e[0]["start_packet"], first_packet);
        assert_eq!(e[0]["end_packet"], first_packet + 9);
        if i == 0 {
            assert_eq!(e[0]["start_t_s"], Value::Null);
        } else {
            let t = |k: usize| 5.0 + offset(k) as f64 * 0.001;
            assert!((e[0]["start_t_s"].as_f64().unwrap() - t(10)).abs() < 1e-9);
            assert!((e[0]["end_t_s"].as_f64().unwrap() - t(19)).abs() < 1e-9);
            assert!((e[0]["duration_s"].as_f64().unwrap() - 9.0 * 0.024).abs() < 1e-9);
        }
    }
    let text = stdout(&run(&["summary", s(&raw), s(&csv)]));
    for needle in [
        "episodes     3 (runs of consecutive frames with faults)",
        "frames 10 .. 19 (10 frames, packets 1010 .. 1019)  over_current, mos_overheat",
        "5.320 .. 5.536 s (0.216 s, 10 frames, packets 10 .. 19)  over_current, mos_overheat",
        "(still on at the end)",
        "device       X8_FOC HW1 FW2 42",
    ] {
        assert!(text.contains(needle), "{needle:?} not in\n{text}");
    }
}

#[test]
fn output_that_cannot_be_written() {
    let dir = tempfile::tempdir().unwrap();
    for format in ["jsonl", "csv", "parquet"] {
        let missing = dir.path().join(format!("no/such/dir/out.{format}"));
        assert_fails_with(
            &run(&["decode", "--demo", "--format", format, "-o", s(&missing)]),
            &format!(
                "cannot write {}: the directory {} does not exist",
                s(&missing),
                missing.parent().unwrap().display()
            ),
        );
        assert_fails_with(
            &run(&["decode", "--demo", "--format", format, "-o", s(dir.path())]),
            "it is a directory, not a file",
        );
    }
    #[cfg(target_os = "linux")]
    for format in ["jsonl", "csv", "parquet"] {
        // A full disk, part-way through: /dev/full fails every write.
        assert_fails_with(
            &run(&["decode", "--demo", "--format", format, "-o", "/dev/full"]),
            "cannot write /dev/full: No space left on device",
        );
    }
    // A directory the user may not write: tests/safety.rs (as another user when root).
}

#[test]
fn an_input_error_leaves_a_readable_parquet_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut csv = analyser_csv(&wire(0, 50, |_| Status::OK), 0.0, 0.001);
    csv.push_str("9.0,garbage,,\n");
    let bad = dir.path().join("cut.csv");
    std::fs::write(&bad, csv).unwrap();
    let good = dir.path().join("later.bin");
    std::fs::write(&good, wire(0, 10, |_| Status::OK)).unwrap();
    let pq = dir.path().join("partial.parquet");
    let o = run(&[
        "decode",
        s(&bad),
        s(&good),
        "--format",
        "parquet",
        "-o",
        s(&pq),
    ]);
    assert_fails_with(&o, "cut.csv:");
    // What was decoded before the error is in a complete, readable file; the input after the
    // bad one is not read.
    let (_, _, batch) = read_parquet(&pq);
    assert_eq!(batch.num_rows(), 50);
    let packets = batch
        .column_by_name("packet")
        .unwrap()
        .as_primitive::<UInt32Type>();
    assert_eq!(packets.value(49), 49);
}

#[test]
fn text_output_keeps_the_input_order() {
    let dir = tempfile::tempdir().unwrap();
    // Many slices of rows, formatted by several threads: the output is in input order.
    let raw = dir.path().join("long.bin");
    std::fs::write(
        &raw,
        wire(0, 60_000, |k| {
            if k % 1000 == 0 { Status(1) } else { Status::OK }
        }),
    )
    .unwrap();
    for format in ["jsonl", "csv"] {
        let out = dir.path().join(format!("long.{format}"));
        stdout(&run(&[
            "decode",
            "--format",
            format,
            s(&raw),
            "-o",
            s(&out),
        ]));
        let text = std::fs::read_to_string(&out).unwrap();
        let packets: Vec<u64> = if format == "jsonl" {
            jsonl(&text)
                .iter()
                .map(|r| r["packet"].as_u64().unwrap())
                .collect()
        } else {
            text.lines()
                .skip(1)
                .map(|l| l.split(',').nth(3).unwrap().parse().unwrap())
                .collect()
        };
        assert_eq!(packets, (0..60_000).collect::<Vec<u64>>(), "{format}");
    }
}

#[test]
fn live_input_is_written_as_it_arrives() {
    use std::io::{BufRead, BufReader, Write};
    for format in ["jsonl", "csv"] {
        let mut child = hwfoc()
            .args(["decode", "--format", format, "-"])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let mut stdin = child.stdin.take().unwrap();
        let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
        if format == "csv" {
            // A raw stream starts with its first byte: send one so that the header comes out.
            stdin.write_all(&frame(0, Status::OK).encode()).unwrap();
            stdin.flush().unwrap();
            assert!(
                lines
                    .next()
                    .unwrap()
                    .unwrap()
                    .starts_with("t_s,esc,protocol,packet")
            );
            assert!(lines.next().unwrap().unwrap().starts_with(",0,hw-foc,0,"));
        }
        // Each frame's record comes out while the input is still open.
        for packet in 1..4u16 {
            stdin
                .write_all(&frame(packet, Status::OK).encode())
                .unwrap();
            stdin.flush().unwrap();
            let line = lines.next().unwrap().unwrap();
            let expected = if format == "csv" {
                format!(",0,hw-foc,{packet},")
            } else {
                format!("\"packet\":{packet},")
            };
            assert!(line.contains(&expected), "{line}");
        }
        drop(stdin);
        assert!(lines.next().is_none());
        assert!(child.wait().unwrap().success());
    }
}
