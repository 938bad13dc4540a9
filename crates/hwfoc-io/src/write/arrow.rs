//! The records in Apache Arrow: the schema (the names, types, nullability and units of
//! `docs/RECORD-SCHEMA.md`, for the Parquet writer and for Arrow consumers) and record batches.
//!
//! Both are derived from the column table ([`crate::record::columns`]): a column's Arrow type
//! and nullability are those of its value type ([`ArrowValue`]), its unit goes in its field's
//! metadata (key `unit`). A [`RecordBatchBuilder`] makes batches with exactly [`schema`]: each
//! column's array is built at once, from all the rows, by code generic over the column.

use std::collections::HashMap;
use std::sync::Arc;

use arrow_array::builder::OffsetBufferBuilder;
use arrow_array::types::{
    Float32Type, Float64Type, Int8Type, TimestampMicrosecondType, UInt8Type, UInt16Type, UInt32Type,
};
use arrow_array::{ArrayRef, DictionaryArray, ListArray, PrimitiveArray, RecordBatch, StringArray};
use arrow_buffer::{NullBufferBuilder, OffsetBuffer, ScalarBuffer};
use arrow_schema::{DataType, Field, FieldRef, Schema, SchemaRef, TimeUnit};
use hwfoc::telemetry::Data;
use hwfoc::{Protocol, Settings, Status};

use super::stored::{Column, Visitor, columns};
use hwfoc_records::record::{FaultList, Record, UtcTime};

/// Name of the `faults` list's item field (Arrow's default).
pub(crate) const ITEM: &str = "item";

/// How a value type is stored in Arrow: its type, whether it may be null, and an array of
/// values.
pub trait ArrowValue: Sized {
    /// Whether values may be null (an `Option`).
    const NULLABLE: bool;

    /// The Arrow type.
    fn data_type() -> DataType;

    /// An array of `values`, of type [`ArrowValue::data_type`].
    fn array(values: impl ExactSizeIterator<Item = Self>) -> ArrayRef;

    /// Whether the value is null (`None`): a column whose values all are is made as an array
    /// of nulls (`arrow_array::new_null_array`: zeroed memory, no value written).
    #[inline(always)]
    fn is_null(&self) -> bool {
        false
    }
}

/// Value types stored as an Arrow primitive, never null, and as one, nullable, in an `Option`.
macro_rules! primitive {
    ($($value:ty => $arrow:ty, $data_type:expr;)*) => {$(
        impl ArrowValue for $value {
            const NULLABLE: bool = false;

            fn data_type() -> DataType {
                $data_type
            }

            fn array(values: impl ExactSizeIterator<Item = Self>) -> ArrayRef {
                Arc::new(PrimitiveArray::<$arrow>::from_iter_values(values))
            }
        }

        impl ArrowValue for Option<$value> {
            const NULLABLE: bool = true;

            fn data_type() -> DataType {
                $data_type
            }

            fn array(values: impl ExactSizeIterator<Item = Self>) -> ArrayRef {
                Arc::new(values.collect::<PrimitiveArray<$arrow>>())
            }

            #[inline(always)]
            fn is_null(&self) -> bool {
                self.is_none()
            }
        }
    )*};
}

primitive! {
    f32 => Float32Type, DataType::Float32;
    f64 => Float64Type, DataType::Float64;
    u8 => UInt8Type, DataType::UInt8;
    u16 => UInt16Type, DataType::UInt16;
    u32 => UInt32Type, DataType::UInt32;
}

impl ArrowValue for Status {
    const NULLABLE: bool = false;

    fn data_type() -> DataType {
        DataType::UInt16
    }

    fn array(values: impl ExactSizeIterator<Item = Self>) -> ArrayRef {
        u16::array(values.map(|s| s.0))
    }
}

impl ArrowValue for Option<Status> {
    const NULLABLE: bool = true;

    fn data_type() -> DataType {
        DataType::UInt16
    }

    fn array(values: impl ExactSizeIterator<Item = Self>) -> ArrayRef {
        Option::<u16>::array(values.map(|s| s.map(|s| s.0)))
    }

    #[inline(always)]
    fn is_null(&self) -> bool {
        self.is_none()
    }
}

/// The zone of the `time` column: a UTC instant, which engines show as a time with zone
/// (DuckDB `TIMESTAMP WITH TIME ZONE`, Spark `TimestampType`, pandas `datetime64[us, UTC]`).
pub const TIME_ZONE: &str = "UTC";

impl ArrowValue for Option<UtcTime> {
    const NULLABLE: bool = true;

    fn data_type() -> DataType {
        DataType::Timestamp(TimeUnit::Microsecond, Some(TIME_ZONE.into()))
    }

    fn array(values: impl ExactSizeIterator<Item = Self>) -> ArrayRef {
        let times: PrimitiveArray<TimestampMicrosecondType> =
            values.map(|t| t.map(|t| t.0)).collect();
        Arc::new(times.with_timezone(TIME_ZONE))
    }

    #[inline(always)]
    fn is_null(&self) -> bool {
        self.is_none()
    }
}

/// The fault lists of `values` (`None`: a null list), as one list array.
///
/// Most rows have no fault: an empty list, which is only its offset repeated. So the lists'
/// offsets are written by one `extend` (no capacity check or overflow check per row, as
/// `OffsetBufferBuilder::push_length` makes), a row's names looked up only where its fault word
/// is not 0, and a null buffer made only where a list is null (from the first).
fn fault_lists(values: impl ExactSizeIterator<Item = Option<FaultList>>) -> ArrayRef {
    let mut offsets: Vec<i32> = Vec::with_capacity(values.len() + 1);
    offsets.push(0);
    let mut names = OffsetBufferBuilder::<i32>::new(0);
    let mut bytes: Vec<u8> = Vec::new();
    // Its bitmap is made at the first null list only.
    let mut nulls = NullBufferBuilder::new(values.len());
    let mut count: usize = 0;
    offsets.extend(values.map(|faults| {
        match faults {
            None => nulls.append_null(),
            Some(faults) => {
                nulls.append_non_null();
                if faults.0.0 != 0 {
                    for name in faults.names() {
                        bytes.extend_from_slice(name.as_bytes());
                        names.push_length(name.len());
                        count += 1;
                    }
                }
            }
        }
        // At most 16 names a row, in a block of rows held in memory.
        i32::try_from(count).expect("fewer than 2^31 fault names in a block")
    }));
    let names = StringArray::new(names.finish(), bytes.into(), None);
    Arc::new(ListArray::new(
        fault_item(),
        OffsetBuffer::new(ScalarBuffer::from(offsets)),
        Arc::new(names),
        nulls.finish(),
    ))
}

impl ArrowValue for FaultList {
    const NULLABLE: bool = false;

    fn data_type() -> DataType {
        DataType::List(fault_item())
    }

    fn array(values: impl ExactSizeIterator<Item = Self>) -> ArrayRef {
        fault_lists(values.map(Some))
    }
}

impl ArrowValue for Option<FaultList> {
    const NULLABLE: bool = true;

    fn data_type() -> DataType {
        DataType::List(fault_item())
    }

    fn array(values: impl ExactSizeIterator<Item = Self>) -> ArrayRef {
        fault_lists(values)
    }

    #[inline(always)]
    fn is_null(&self) -> bool {
        self.is_none()
    }
}

/// The Arrow type of the `protocol` column's dictionary keys.
type ProtocolKey = Int8Type;

impl ArrowValue for Protocol {
    const NULLABLE: bool = false;

    /// A dictionary of the protocols' names ([`Protocol::ALL`], in that order), by an `int8`
    /// key: each record stores one byte, and readers see a categorical column.
    fn data_type() -> DataType {
        DataType::Dictionary(Box::new(DataType::Int8), Box::new(DataType::Utf8))
    }

    fn array(values: impl ExactSizeIterator<Item = Self>) -> ArrayRef {
        // Each protocol's key: its place in `Protocol::ALL`.
        let keys = PrimitiveArray::<ProtocolKey>::from_iter_values(values.map(|p| p.index() as i8));
        let names = StringArray::from_iter_values(Protocol::ALL.map(Protocol::name));
        Arc::new(
            DictionaryArray::<ProtocolKey>::try_new(keys, Arc::new(names))
                .expect("every key is an index of the names"),
        )
    }
}

/// The item field of the `faults` list: a fault name, never null.
fn fault_item() -> FieldRef {
    Arc::new(Field::new(ITEM, DataType::Utf8, false))
}

/// The Arrow field of column `C`: name, type, nullability, and the unit in the metadata.
pub(crate) fn field<C: Column>() -> Field {
    let metadata = HashMap::from([("unit".to_string(), C::UNIT.to_string())]);
    Field::new(C::NAME, <C::Value as ArrowValue>::data_type(), C::NULLABLE).with_metadata(metadata)
}

/// The Arrow schema of the records: names, types, nullability and units of docs/RECORD-SCHEMA.md.
pub fn schema() -> Schema {
    struct Fields(Vec<Field>);
    impl Visitor for Fields {
        fn column<C: Column>(&mut self) {
            self.0.push(field::<C>());
        }
    }
    let mut fields = Fields(Vec::with_capacity(columns::COUNT));
    columns::visit(&mut fields);
    Schema::new(fields.0)
}

/// The Arrow record batch of `records`, with exactly the schema of [`schema`] (a
/// [`RecordBatchBuilder`] keeps the schema from batch to batch).
pub fn record_batch(records: &[Record]) -> RecordBatch {
    batch(Arc::new(schema()), records)
}

/// Makes each column's array from all of `records`, one column at a time.
fn batch(schema: SchemaRef, records: &[Record]) -> RecordBatch {
    struct Arrays<'a> {
        records: &'a [Record],
        arrays: Vec<ArrayRef>,
    }
    impl Visitor for Arrays<'_> {
        fn column<C: Column>(&mut self) {
            let values = self.records.iter().map(C::from_record);
            self.arrays.push(<C::Value as ArrowValue>::array(values));
        }
    }
    let mut arrays = Arrays {
        records,
        arrays: Vec::with_capacity(columns::COUNT),
    };
    columns::visit(&mut arrays);
    // Each array has its field's type (both come from the column's value type), the same
    // length, and nulls only where the field is nullable.
    RecordBatch::try_new(schema, arrays.arrays).expect("the arrays follow the schema")
}

/// Gathers records, or frames converted to records, and makes Arrow record batches of them
/// with exactly the schema of [`schema`] (units in the fields' metadata).
///
/// ```
/// use hwfoc::Settings;
/// use hwfoc::foc::DataFrame;
/// use hwfoc_io::write::arrow::RecordBatchBuilder;
///
/// let mut builder = RecordBatchBuilder::new();
/// let frame = DataFrame { packet: 1, voltage_raw: 247, ..Default::default() };
/// builder.push_frame(Some(0.5), 0, &frame.into(), &Settings::default());
/// let batch = builder.finish();
/// assert_eq!(batch.num_rows(), 1);
/// assert_eq!(batch.schema().field(0).name(), "t_s");
/// assert!(builder.is_empty());
/// ```
#[derive(Debug, Clone)]
pub struct RecordBatchBuilder {
    schema: SchemaRef,
    records: Vec<Record>,
}

impl Default for RecordBatchBuilder {
    fn default() -> Self {
        RecordBatchBuilder::new()
    }
}

impl RecordBatchBuilder {
    /// An empty builder.
    pub fn new() -> RecordBatchBuilder {
        RecordBatchBuilder::with_capacity(0)
    }

    /// An empty builder with room for `rows` records.
    pub fn with_capacity(rows: usize) -> RecordBatchBuilder {
        RecordBatchBuilder {
            schema: Arc::new(schema()),
            records: Vec::with_capacity(rows),
        }
    }

    /// Adds a record.
    pub fn push(&mut self, record: Record) {
        self.records.push(record);
    }

    /// Adds the record of a data frame received at `t_s` (if the source has timing) from ESC
    /// `esc`, converted under `settings`.
    pub fn push_frame(&mut self, t_s: Option<f64>, esc: u8, frame: &Data, settings: &Settings) {
        self.records.push(Record::new(t_s, esc, frame, settings));
    }

    /// Number of records gathered.
    pub fn len(&self) -> usize {
        self.records.len()
    }

    /// Whether no record is gathered.
    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }

    /// The schema of the batches.
    pub fn schema(&self) -> SchemaRef {
        self.schema.clone()
    }

    /// The record batch of the records gathered since the last one; the builder is then empty.
    pub fn finish(&mut self) -> RecordBatch {
        let rows = batch(self.schema.clone(), &self.records);
        self.records.clear();
        rows
    }
}
