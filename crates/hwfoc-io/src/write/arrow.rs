//! The Arrow schema of the records: the names, types, nullability and units of
//! `RECORD-SCHEMA.md`, for the Parquet writer and for Arrow consumers.

use std::collections::HashMap;
use std::sync::Arc;

use arrow_schema::{DataType, Field, FieldRef, Schema};

use crate::record::{COLUMNS, UNITS};

/// Name of the `faults` list's item field (Arrow's default).
pub(crate) const ITEM: &str = "item";

/// The Arrow schema of the records: names, types, nullability and units of RECORD-SCHEMA.md.
pub fn schema() -> Schema {
    let types = [
        (DataType::Float64, true),
        (DataType::UInt8, false),
        (DataType::UInt16, false),
        (DataType::Float32, false),
        (DataType::Float32, false),
        (DataType::UInt32, false),
        (DataType::Float32, false),
        (DataType::Float32, false),
        (DataType::Float32, false),
        (DataType::Float32, false),
        (DataType::Float32, true),
        (DataType::Float32, true),
        (DataType::UInt16, false),
        (DataType::List(fault_item()), false),
    ];
    let fields: Vec<Field> = COLUMNS
        .iter()
        .zip(UNITS)
        .zip(types)
        .map(|((name, unit), (data_type, nullable))| {
            let metadata = HashMap::from([("unit".to_string(), unit.to_string())]);
            Field::new(*name, data_type, nullable).with_metadata(metadata)
        })
        .collect();
    Schema::new(fields)
}

/// The item field of the `faults` list: a fault name, never null.
fn fault_item() -> FieldRef {
    Arc::new(Field::new(ITEM, DataType::Utf8, false))
}
