//! The column table against `RECORD-SCHEMA.md`: names in order, types, nullability and units,
//! and every output's columns (JSON keys, CSV header, Arrow schema) in the table's order.
//!
//! The expected schema is read from `docs/RECORD-SCHEMA.md` at test time (the document itself,
//! not a copy of it): a new column is a row of that table as well as an entry in the column table.

use arrow_schema::{DataType, Field, TimeUnit};
use hwfoc::foc::DataFrame;
use hwfoc::{Settings, Status};
use hwfoc_io::record::{
    COLUMNS, Column, Record, TEXT_COLUMNS, TextEncoder, UNITS, Visitor, columns,
};
use hwfoc_io::write::arrow::schema;
use std::sync::Arc;

/// The record schema document of the repository.
const RECORD_SCHEMA_MD: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/RECORD-SCHEMA.md");

/// The text of `docs/RECORD-SCHEMA.md`.
fn record_schema_md() -> String {
    std::fs::read_to_string(RECORD_SCHEMA_MD).unwrap_or_else(|e| panic!("{RECORD_SCHEMA_MD}: {e}"))
}

/// The rows of the document's column table (below its header and separator line).
fn table_rows(document: &str) -> Vec<&str> {
    let mut lines = document.lines();
    lines
        .by_ref()
        .find(|line| line.starts_with("| column | type | unit | value |"))
        .unwrap_or_else(|| panic!("{RECORD_SCHEMA_MD}: no column table"));
    lines
        .skip(1)
        .take_while(|line| line.starts_with('|'))
        .collect()
}

/// The document's example record: the first frame of the XRotor capture, default settings.
fn example(document: &str) -> &str {
    document
        .lines()
        .find(|line| line.starts_with("{\"t_s\":"))
        .unwrap_or_else(|| panic!("{RECORD_SCHEMA_MD}: no example record"))
}

/// A column of RECORD-SCHEMA.md: name, Arrow type, nullability, unit.
struct Expected {
    name: String,
    data_type: DataType,
    nullable: bool,
    unit: String,
}

/// The Arrow type the specification's words mean.
fn arrow_type(words: &str) -> (DataType, bool) {
    let (base, nullable) = match words.strip_suffix(", nullable") {
        Some(base) => (base, true),
        None => (words, false),
    };
    let data_type = match base {
        "float64" => DataType::Float64,
        "float32" => DataType::Float32,
        "uint8" => DataType::UInt8,
        "uint16" => DataType::UInt16,
        "uint32" => DataType::UInt32,
        "list of strings (CSV: `|`-joined)" => {
            DataType::List(Arc::new(Field::new("item", DataType::Utf8, false)))
        }
        "timestamp[us, UTC]" => DataType::Timestamp(TimeUnit::Microsecond, Some("UTC".into())),
        "dictionary of strings (int8 keys)" => {
            DataType::Dictionary(Box::new(DataType::Int8), Box::new(DataType::Utf8))
        }
        other => panic!("a type this test does not know: {other:?}"),
    };
    (data_type, nullable)
}

fn expected() -> Vec<Expected> {
    table_rows(&record_schema_md())
        .into_iter()
        .map(|row| {
            // Cells are separated by " | " (a `|` inside a cell has no spaces around it).
            let cells: Vec<&str> = row
                .trim_start_matches("| ")
                .trim_end_matches(" |")
                .split(" | ")
                .collect();
            assert_eq!(cells.len(), 4, "{row}");
            let (data_type, nullable) = arrow_type(cells[1]);
            Expected {
                name: cells[0].trim_matches('`').to_string(),
                data_type,
                nullable,
                unit: cells[2].to_string(),
            }
        })
        .collect()
}

#[test]
fn the_table_is_record_schema_md() {
    let expected = expected();
    let names: Vec<&str> = expected.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(COLUMNS.to_vec(), names, "names in schema order");
    let units: Vec<&str> = expected.iter().map(|c| c.unit.as_str()).collect();
    assert_eq!(UNITS.to_vec(), units, "units");
    let schema = schema();
    assert_eq!(schema.fields().len(), expected.len());
    for (field, column) in schema.fields().iter().zip(&expected) {
        assert_eq!(field.name(), &column.name);
        assert_eq!(field.data_type(), &column.data_type, "{}", column.name);
        assert_eq!(field.is_nullable(), column.nullable, "{}", column.name);
        assert_eq!(
            field.metadata().get("unit"),
            Some(&column.unit),
            "{}",
            column.name
        );
        assert_eq!(field.metadata().len(), 1, "{}: only the unit", column.name);
    }
}

/// Each column's zero-sized type (what the writers are generic over) has the place, name and
/// unit of its row of the table, and its JSON key is its name quoted.
#[test]
fn column_types_are_record_schema_md() {
    struct Seen(Vec<(usize, &'static str, &'static str, &'static str)>);
    impl Visitor for Seen {
        fn column<C: Column>(&mut self) {
            self.0.push((C::INDEX, C::NAME, C::UNIT, C::JSON_KEY));
        }
    }
    let mut seen = Seen(Vec::new());
    columns::visit(&mut seen);
    let expected = expected();
    assert_eq!(seen.0.len(), expected.len(), "one type per row");
    assert_eq!(columns::COUNT, expected.len());
    for (i, ((index, name, unit, json_key), row)) in seen.0.iter().zip(&expected).enumerate() {
        assert_eq!(
            (*index, *name, *unit),
            (i, row.name.as_str(), row.unit.as_str())
        );
        assert_eq!(*json_key, format!(",\"{}\":", row.name), "{name}");
    }
}

/// The first frame of the XRotor capture gives docs/RECORD-SCHEMA.md's example line.
#[test]
fn the_example_record() {
    let bytes = [
        0x9B, 0x16, 0x01, 0x02, 0x05, 0xC2, 0, 0, 0, 0, 0, 0, 0x00, 0xF7, 0xFF, 0xFF, 0xFF, 0xFF,
        0xCE, 0xD1, 0x00, 0x00, 0x0D, 0x08,
    ];
    let frame = DataFrame::parse(&bytes).unwrap();
    let record = Record::new(
        Some(0.22798),
        0,
        &hwfoc::telemetry::Data::from(frame),
        &Settings::default(),
    );
    let mut line = Vec::new();
    record.write_json(&mut line);
    let document = record_schema_md();
    assert_eq!(
        String::from_utf8(line).unwrap(),
        format!("{}\n", example(&document))
    );
}

/// JSON keys and CSV header and fields in the table's order, nulls and faults included.
#[test]
fn text_follows_the_table() {
    let frame = DataFrame {
        packet: 9,
        mos_adc: 250,
        cap_adc: 20,
        status: Status(0x8001),
        ..Default::default()
    };
    let record = Record::new(
        None,
        3,
        &hwfoc::telemetry::Data::from(frame),
        &Settings::default(),
    );
    let mut encoder = TextEncoder::cached();
    let mut json = Vec::new();
    encoder.json_frame(&record, &hwfoc::telemetry::Data::from(frame), &mut json);
    let object: serde_json::Map<String, serde_json::Value> = serde_json::from_slice(&json).unwrap();
    // serde_json keeps the order of the keys (feature preserve_order).
    let keys: Vec<&str> = object.keys().map(String::as_str).collect();
    // Every column but `time` (Parquet and Arrow only), in order.
    assert_eq!(TEXT_COLUMNS.as_slice(), &COLUMNS[..COLUMNS.len() - 1]);
    assert_eq!(keys, TEXT_COLUMNS);

    let mut csv = Vec::new();
    Record::write_csv_header(&mut csv);
    encoder.csv_frame(&record, &hwfoc::telemetry::Data::from(frame), &mut csv);
    let csv = String::from_utf8(csv).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], TEXT_COLUMNS.join(","));
    let fields: Vec<&str> = lines[1].split(',').collect();
    assert_eq!(fields.len(), TEXT_COLUMNS.len());
    for (name, field) in TEXT_COLUMNS.iter().zip(&fields) {
        let value = &object[*name];
        match value {
            serde_json::Value::Null => assert_eq!(*field, "", "{name}"),
            serde_json::Value::Array(names) => {
                let joined: Vec<&str> = names.iter().map(|n| n.as_str().unwrap()).collect();
                assert_eq!(*field, joined.join("|"), "{name}");
            }
            serde_json::Value::String(text) => assert_eq!(field, text, "{name}"),
            other => assert_eq!(*field, other.to_string(), "{name}"),
        }
    }
}

/// Schema version 4: the columns' order, types and nullability as written out here (the
/// document and the code are both checked against this list: a change to either shows).
#[test]
fn version_4_order_types_and_nullability() {
    let dict = DataType::Dictionary(Box::new(DataType::Int8), Box::new(DataType::Utf8));
    let faults = DataType::List(Arc::new(Field::new("item", DataType::Utf8, false)));
    let f32n = (DataType::Float32, true);
    let want: Vec<(&str, (DataType, bool))> = vec![
        ("t_s", (DataType::Float64, true)),
        ("esc", (DataType::UInt8, false)),
        ("protocol", (dict, false)),
        ("packet", (DataType::UInt32, true)),
        ("throttle_in_pct", f32n.clone()),
        ("throttle_out_pct", f32n.clone()),
        ("erpm", (DataType::UInt32, true)),
        ("rpm", f32n.clone()),
        ("voltage_v", f32n.clone()),
        ("current_a", f32n.clone()),
        ("phase_current_a", f32n.clone()),
        ("mos_temp_c", f32n.clone()),
        ("cap_temp_c", f32n.clone()),
        ("motor_temp_c", f32n.clone()),
        ("bec_temp_c", f32n.clone()),
        ("bec_voltage_v", f32n.clone()),
        ("bec_current_a", f32n),
        ("status", (DataType::UInt16, true)),
        ("faults", (faults, true)),
        ("node", (DataType::UInt8, true)),
        ("msg2_age_ms", (DataType::UInt32, true)),
        ("msg3_age_ms", (DataType::UInt32, true)),
        (
            "time",
            (
                DataType::Timestamp(TimeUnit::Microsecond, Some("UTC".into())),
                true,
            ),
        ),
    ];
    let schema = schema();
    let got: Vec<(&str, (DataType, bool))> = schema
        .fields()
        .iter()
        .map(|f| (f.name().as_str(), (f.data_type().clone(), f.is_nullable())))
        .collect();
    assert_eq!(got, want);
    let documented: Vec<(String, (DataType, bool))> = expected()
        .into_iter()
        .map(|c| (c.name, (c.data_type, c.nullable)))
        .collect();
    let want: Vec<(String, (DataType, bool))> =
        want.into_iter().map(|(n, t)| (n.to_string(), t)).collect();
    assert_eq!(documented, want);
    assert!(record_schema_md().contains("Record schema **version 4**"));
    assert_eq!(hwfoc_io::RECORD_SCHEMA_VERSION, 4);
}

/// The `protocol` column of an ESC's own frame and of a DataLink hub's, and the columns no
/// protocol read today carries, in every format: JSON `null`, an empty CSV cell, an Arrow null.
#[test]
fn protocol_and_the_columns_not_carried_in_every_format() {
    use arrow_array::cast::AsArray;
    use arrow_array::types::Int8Type;
    use hwfoc::telemetry::Data;
    use hwfoc_io::write::arrow::RecordBatchBuilder;

    const NOT_CARRIED: [&str; 4] = [
        "motor_temp_c",
        "bec_temp_c",
        "bec_voltage_v",
        "bec_current_a",
    ];
    let frame = DataFrame {
        packet: 70_00,
        voltage_raw: 247,
        mos_adc: 206,
        cap_adc: 206,
        ..Default::default()
    };
    let s = Settings::default();
    let mut builder = RecordBatchBuilder::new();
    for (data, name) in [
        (Data::from(frame), "hw-foc"),
        (Data::DataLink(frame), "datalink"),
    ] {
        let record = Record::new(Some(1.0), 2, &data, &s);
        builder.push(record);
        let mut json = Vec::new();
        TextEncoder::cached().json_frame(&record, &data, &mut json);
        let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
        assert_eq!(v["protocol"], name);
        assert_eq!(v["packet"], 7000);
        assert_eq!(v["voltage_v"].as_f64().map(|x| x as f32), Some(24.7));
        for column in NOT_CARRIED {
            assert!(v[column].is_null(), "{column}: {v}");
        }
        let mut csv = Vec::new();
        TextEncoder::new().csv(&record, &mut csv);
        let csv = String::from_utf8(csv).unwrap();
        let fields: Vec<&str> = csv.trim_end().split(',').collect();
        let at = |c: &str| COLUMNS.iter().position(|n| *n == c).unwrap();
        assert_eq!(fields[at("protocol")], name);
        assert_eq!(fields[at("packet")], "7000");
        for column in NOT_CARRIED {
            assert_eq!(fields[at(column)], "", "{column}: {csv}");
        }
    }
    let batch = builder.finish();
    let protocol = batch
        .column_by_name("protocol")
        .unwrap()
        .as_dictionary::<Int8Type>();
    let names = protocol.values().as_string::<i32>();
    let values: Vec<&str> = protocol
        .keys()
        .values()
        .iter()
        .map(|&k| names.value(k as usize))
        .collect();
    assert_eq!(values, ["hw-foc", "datalink"]);
    for column in NOT_CARRIED {
        assert_eq!(
            batch.column_by_name(column).unwrap().null_count(),
            2,
            "{column}"
        );
    }
    for column in ["packet", "voltage_v", "status", "faults"] {
        assert_eq!(
            batch.column_by_name(column).unwrap().null_count(),
            0,
            "{column}"
        );
    }
}
