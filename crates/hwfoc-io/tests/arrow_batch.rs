//! Arrow record batches: exactly the schema, and every value of every column equal to the
//! record's (as its JSON line gives it), nulls and fault lists included.

use std::sync::Arc;

use arrow_array::cast::AsArray;
use arrow_array::types::{
    Float32Type, Float64Type, Int8Type, TimestampMicrosecondType, UInt8Type, UInt16Type, UInt32Type,
};
use arrow_array::{Array, ArrayRef, RecordBatch};
use arrow_schema::{DataType, TimeUnit};
use hwfoc::foc::DataFrame;
use hwfoc::{Fault, Settings, Status};
use hwfoc_io::record::{COLUMNS, Record};
use hwfoc_io::write::arrow::{RecordBatchBuilder, record_batch, schema};
use serde_json::Value;

/// Frames that give every kind of value: times and none, temperatures in and out of the
/// table's range (both sides), no fault, some, all sixteen; extreme raw values.
fn frames() -> Vec<(Option<f64>, u8, DataFrame)> {
    let mut rows = Vec::new();
    for i in 0..300u32 {
        let word = |shift: u32| (i.wrapping_mul(2_654_435_761) >> shift) as u16;
        let status = match i % 10 {
            0 => 0xFFFF,
            1 | 2 => word(3),
            3 => Fault::MosOverheat.mask() | Fault::OverCurrent.mask(),
            _ => 0,
        };
        let frame = DataFrame {
            packet: word(0),
            throttle_in_raw: word(1) % 1100,
            throttle_out_raw: word(2) % 1100,
            erpm_raw: if i == 7 { u16::MAX } else { word(5) },
            voltage_raw: word(7) % 600,
            current_raw: if i == 8 { i16::MIN } else { word(9) as i16 },
            phase_current_raw: word(11) as i16,
            // 20: above the table's range (hot), 250: below it (cold), 206: 28 degC.
            mos_adc: [206, 250, 20, word(4) as u8][i as usize % 4],
            cap_adc: [word(6) as u8, 206, 250, 20][i as usize % 4],
            status: Status(status),
        };
        let t = (i % 3 != 0).then_some(1.7e9 + f64::from(i) * 0.012_5);
        rows.push((t, (i % 4) as u8, frame));
    }
    rows
}

/// The JSON value of each column of `r`, as `hwfoc decode` writes it.
fn json(r: &Record) -> serde_json::Map<String, Value> {
    let mut line = Vec::new();
    r.write_json(&mut line);
    serde_json::from_slice(&line).unwrap()
}

/// Row `row` of `array` as the JSON value the text writers give, by the array's type.
fn value(array: &ArrayRef, row: usize) -> Value {
    if array.is_null(row) {
        return Value::Null;
    }
    match array.data_type() {
        DataType::Float64 => Value::from(array.as_primitive::<Float64Type>().value(row)),
        // JSON numbers are the shortest text of the f32: they read back to the same f32,
        // compared below as f32.
        DataType::Float32 => Value::from(array.as_primitive::<Float32Type>().value(row)),
        DataType::UInt8 => Value::from(array.as_primitive::<UInt8Type>().value(row)),
        DataType::UInt16 => Value::from(array.as_primitive::<UInt16Type>().value(row)),
        DataType::UInt32 => Value::from(array.as_primitive::<UInt32Type>().value(row)),
        DataType::List(_) => {
            let list = array.as_list::<i32>().value(row);
            let names = list.as_string::<i32>();
            assert_eq!(names.null_count(), 0);
            Value::from_iter(names.iter().map(|n| n.unwrap().to_string()))
        }
        DataType::Dictionary(_, _) => {
            let dict = array.as_dictionary::<Int8Type>();
            let key = dict.keys().value(row);
            Value::from(dict.values().as_string::<i32>().value(key as usize))
        }
        // Microseconds since the epoch, in UTC only.
        DataType::Timestamp(TimeUnit::Microsecond, Some(zone)) if &**zone == "UTC" => {
            Value::from(array.as_primitive::<TimestampMicrosecondType>().value(row))
        }
        other => panic!("a type this test does not know: {other}"),
    }
}

/// Every column of `batch` holds the values of `records`.
fn assert_same(batch: &RecordBatch, records: &[Record]) {
    assert_eq!(batch.num_rows(), records.len());
    assert_eq!(batch.num_columns(), COLUMNS.len());
    for (row, record) in records.iter().enumerate() {
        let expected = json(record);
        for (name, array) in COLUMNS.iter().zip(batch.columns()) {
            let got = value(array, row);
            // `time` (not in JSON): the instant of `t_s`, in whole microseconds.
            let time = |t: &Value| {
                t.as_f64()
                    .map_or(Value::Null, |t| ((t * 1e6).round() as i64).into())
            };
            let want = &match *name {
                "time" => time(&expected["t_s"]),
                _ => expected[*name].clone(),
            };
            if *array.data_type() == DataType::Float32 && !got.is_null() {
                let as_f32 = |v: &Value| v.as_f64().map(|x| x as f32);
                assert_eq!(as_f32(&got), as_f32(want), "{name} row {row}");
            } else {
                assert_eq!(&got, want, "{name} row {row}");
            }
        }
    }
}

/// The `time` column is a UTC timestamp to the microsecond holding the instant of `t_s` (a
/// pcapng capture's receive time), and null where `t_s` is.
#[test]
fn time_is_a_utc_timestamp_of_t_s() {
    let frame = hwfoc::telemetry::Data::from(DataFrame::default());
    let settings = Settings::default();
    let batch = record_batch(&[
        Record::new(Some(1_795_847_934.682_325), 0, &frame, &settings),
        Record::new(None, 0, &frame, &settings),
    ]);
    let time = batch.column_by_name("time").expect("a time column");
    let time = time.as_primitive::<TimestampMicrosecondType>();
    assert_eq!(time.timezone(), Some("UTC"));
    assert_eq!(time.value(0), 1_795_847_934_682_325);
    assert_eq!(
        time.value_as_datetime(0).unwrap().to_string(),
        "2026-11-28 06:38:54.682325"
    );
    assert!(time.is_null(1));
}

#[test]
fn a_batch_has_exactly_the_schema_and_the_records_values() {
    let settings = Settings::new(100.0, 14, 2.5).unwrap();
    let mut builder = RecordBatchBuilder::new();
    let mut records = Vec::new();
    for (i, (t, esc, frame)) in frames().iter().enumerate() {
        let record = Record::new(*t, *esc, &hwfoc::telemetry::Data::from(*frame), &settings);
        // Frames and records alike.
        if i % 2 == 0 {
            builder.push_frame(*t, *esc, &hwfoc::telemetry::Data::from(*frame), &settings);
        } else {
            builder.push(record);
        }
        records.push(record);
    }
    assert_eq!(builder.len(), records.len());
    let batch = builder.finish();
    assert!(builder.is_empty());
    // The schema itself, units in the metadata included.
    assert_eq!(batch.schema(), Arc::new(schema()));
    assert_eq!(batch.schema(), builder.schema());
    assert_same(&batch, &records);
    assert_eq!(record_batch(&records), batch);

    // Every kind of value occurred.
    let column = |name: &str| batch.column_by_name(name).unwrap().clone();
    assert_eq!(column("t_s").null_count(), 100);
    assert!(column("mos_temp_c").null_count() > 0);
    assert!(column("cap_temp_c").null_count() > 0);
    assert_eq!(column("esc").null_count(), 0);
    let faults = column("faults");
    let all = value(&faults, 0);
    let names: Vec<&str> = Fault::ALL.iter().map(|f| f.name()).collect();
    assert_eq!(all, Value::from(names), "all sixteen, in bit order");
    assert_eq!(
        value(&faults, 3),
        Value::from(vec!["over_current", "mos_overheat"])
    );
    assert_eq!(value(&faults, 4), Value::Array(Vec::new()));
}

#[test]
fn the_record_fields_are_the_batch_columns() {
    let settings = Settings::default();
    let records: Vec<Record> = frames()
        .iter()
        .map(|(t, esc, frame)| {
            Record::new(*t, *esc, &hwfoc::telemetry::Data::from(*frame), &settings)
        })
        .collect();
    let batch = record_batch(&records);
    let f32s = |name: &str| {
        batch
            .column_by_name(name)
            .unwrap()
            .as_primitive::<Float32Type>()
            .clone()
    };
    let t = batch
        .column_by_name("t_s")
        .unwrap()
        .as_primitive::<Float64Type>()
        .clone();
    let mos = f32s("mos_temp_c");
    let rpm = f32s("rpm");
    let current = f32s("current_a");
    let status = batch
        .column_by_name("status")
        .unwrap()
        .as_primitive::<UInt16Type>()
        .clone();
    let erpm = batch
        .column_by_name("erpm")
        .unwrap()
        .as_primitive::<UInt32Type>()
        .clone();
    for (row, r) in records.iter().enumerate() {
        assert_eq!(t.is_valid(row).then(|| t.value(row)), r.t_s);
        assert_eq!(mos.is_valid(row).then(|| mos.value(row)), r.mos_temp_c);
        assert_eq!(Some(rpm.value(row)), r.rpm);
        assert_eq!(Some(current.value(row)), r.current_a);
        assert_eq!(Some(status.value(row)), r.status.map(|s| s.0));
        assert_eq!(Some(erpm.value(row)), r.erpm);
    }
    // The extremes: the largest eRPM and the most negative current.
    assert_eq!(erpm.value(7), u32::from(u16::MAX) * 10);
    assert_eq!(current.value(8), -512.0);
}

#[test]
fn batches_one_after_another_and_empty() {
    let mut builder = RecordBatchBuilder::with_capacity(10);
    let empty = builder.finish();
    assert_eq!(empty.num_rows(), 0);
    assert_eq!(empty.schema(), Arc::new(schema()));
    let settings = Settings::default();
    let rows = frames();
    let mut records = Vec::new();
    for (t, esc, frame) in &rows[..10] {
        builder.push_frame(*t, *esc, &hwfoc::telemetry::Data::from(*frame), &settings);
        records.push(Record::new(
            *t,
            *esc,
            &hwfoc::telemetry::Data::from(*frame),
            &settings,
        ));
    }
    let first = builder.finish();
    assert_same(&first, &records);
    records.clear();
    for (t, esc, frame) in &rows[10..25] {
        builder.push_frame(*t, *esc, &hwfoc::telemetry::Data::from(*frame), &settings);
        records.push(Record::new(
            *t,
            *esc,
            &hwfoc::telemetry::Data::from(*frame),
            &settings,
        ));
    }
    let second = builder.finish();
    assert_same(&second, &records);
}
