//! The column table against `RECORD-SCHEMA.md`: names in order, types, nullability and units,
//! and every output's columns (JSON keys, CSV header, Arrow schema) in the table's order.
//!
//! The expected schema is a copy of RECORD-SCHEMA.md's table (the tests do not read the
//! specification's directory): a new column is a row here as well as an entry in the table.

use arrow_schema::{DataType, Field};
use hwfoc::{DataFrame, Settings, Status};
use hwfoc_io::record::{COLUMNS, Record, TextEncoder, UNITS};
use hwfoc_io::write::arrow::schema;
use std::sync::Arc;

/// The column table of RECORD-SCHEMA.md, as it is there.
const RECORD_SCHEMA_MD: &str = "\
| column | type | unit | value |
|---|---|---|---|
| `t_s` | float64, nullable | s | time of the frame's first byte: the source's own clock where it has one (a logic-analyser CSV's or a pcapng capture's timestamps, as they are in the file), Unix time for live input; null where the source has no timing (a raw byte file) |
| `esc` | uint8 | - | which ESC: the index of the input port/stream it came from (0-based), or the DataLink channel |
| `packet` | uint16 | - | packet number from the frame |
| `throttle_in_pct` | float32 | % | input throttle, raw * 100 / 1024 |
| `throttle_out_pct` | float32 | % | output throttle, raw * 100 / 1024 |
| `erpm` | uint32 | rev/min | electrical RPM, raw * 10 |
| `rpm` | float32 | rev/min | motor (or geared output) RPM, raw * 10 / (gear_ratio * pole_pairs) |
| `voltage_v` | float32 | V | input voltage, raw / 10 |
| `current_a` | float32 | A | input current, int16 raw / current scale (default 64) |
| `phase_current_a` | float32 | A | phase current, int16 raw / current scale (default 64) |
| `mos_temp_c` | float32, nullable | degC | MOSFET temperature from the ADC table; null when out of the table's range |
| `cap_temp_c` | float32, nullable | degC | capacitor temperature, likewise |
| `status` | uint16 | - | the raw status word |
| `faults` | list of strings (CSV: `|`-joined) | - | names of the set status bits, from PROTOCOL-NOTES.md, in bit order |
";

/// The example of RECORD-SCHEMA.md: the first frame of the XRotor capture, default settings.
const EXAMPLE: &str = r#"{"t_s":0.22798,"esc":0,"packet":1474,"throttle_in_pct":0.0,"throttle_out_pct":0.0,"erpm":0,"rpm":0.0,"voltage_v":24.7,"current_a":-0.015625,"phase_current_a":-0.015625,"mos_temp_c":28.0,"cap_temp_c":26.0,"status":0,"faults":[]}"#;

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
        other => panic!("a type this test does not know: {other:?}"),
    };
    (data_type, nullable)
}

fn expected() -> Vec<Expected> {
    RECORD_SCHEMA_MD
        .lines()
        .skip(2)
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

/// The first frame of the XRotor capture gives RECORD-SCHEMA.md's example line.
#[test]
fn the_example_record() {
    let bytes = [
        0x9B, 0x16, 0x01, 0x02, 0x05, 0xC2, 0, 0, 0, 0, 0, 0, 0x00, 0xF7, 0xFF, 0xFF, 0xFF, 0xFF,
        0xCE, 0xD1, 0x00, 0x00, 0x0D, 0x08,
    ];
    let frame = DataFrame::parse(&bytes).unwrap();
    let record = Record::new(Some(0.22798), 0, &frame, &Settings::default());
    let mut line = Vec::new();
    record.write_json(&mut line);
    assert_eq!(String::from_utf8(line).unwrap(), format!("{EXAMPLE}\n"));
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
    let record = Record::new(None, 3, &frame, &Settings::default());
    let mut encoder = TextEncoder::cached();
    let mut json = Vec::new();
    encoder.json_frame(&record, &frame, &mut json);
    let object: serde_json::Map<String, serde_json::Value> = serde_json::from_slice(&json).unwrap();
    // serde_json keeps the order of the keys (feature preserve_order).
    let keys: Vec<&str> = object.keys().map(String::as_str).collect();
    assert_eq!(keys, COLUMNS);

    let mut csv = Vec::new();
    Record::write_csv_header(&mut csv);
    encoder.csv_frame(&record, &frame, &mut csv);
    let csv = String::from_utf8(csv).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], COLUMNS.join(","));
    let fields: Vec<&str> = lines[1].split(',').collect();
    assert_eq!(fields.len(), COLUMNS.len());
    for (name, field) in COLUMNS.iter().zip(&fields) {
        let value = &object[*name];
        match value {
            serde_json::Value::Null => assert_eq!(*field, "", "{name}"),
            serde_json::Value::Array(names) => {
                let joined: Vec<&str> = names.iter().map(|n| n.as_str().unwrap()).collect();
                assert_eq!(*field, joined.join("|"), "{name}");
            }
            other => assert_eq!(*field, other.to_string(), "{name}"),
        }
    }
}
