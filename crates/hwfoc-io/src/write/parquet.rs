//! The Parquet writer: the record schema as an Apache Parquet file, with the Arrow schema
//! embedded so that Arrow readers (pyarrow, arrow-rs, polars, DuckDB) see the exact types.
//!
//! Columns, types and units are those of `RECORD-SCHEMA.md`; each Arrow field carries its unit
//! in its metadata (key `unit`, `-` for a number without unit). The file's key-value metadata
//! holds `hwfoc_version`, the settings (`current_scale`, `pole_pairs`, `gear_ratio`), `inputs`
//! (a JSON array of the input names), `escs` (a JSON array of `{"esc", "input", "stream"}`)
//! and, when records were filtered, `filter`.
//!
//! Speed (figures from `scripts/bench-export.sh`): the decoding thread only collects frames,
//! a row group's worth at a time; the writer thread converts, encodes and compresses the
//! columns of each row group in memory together with a helper thread (each takes the next
//! column not yet done, costliest first, so that both end together), and writes the previous
//! row group to the file while the helper starts on the next. Encodings are chosen to keep up
//! with decoding:
//! - data pages of format version 2 (values compressed on their own, levels not, no copy of
//!   the values before compression; a page that does not compress is stored as it is);
//! - plain values compressed with LZ4 (`LZ4_RAW`: faster than Snappy here, and smaller);
//! - `packet` and `erpm` as bit-packed differences (`DELTA_BINARY_PACKED`, not compressed,
//!   a bit width per 128 values): they count up or drift, and plain they hardly compress. (Their bytes split into streams
//!   and compressed would be smaller and cheaper still, but integer columns in that encoding
//!   came with Parquet 2.11, in 2024: Spark 3.5 (parquet-java 1.13) and DuckDB releases
//!   before mid-2026 cannot read them; the floats' byte-stream split is older and read
//!   everywhere.)
//! - throttles, `rpm` and currents with their bytes split into streams (`BYTE_STREAM_SPLIT`)
//!   before compression: slowly varying values then compress to a half or a third (as fast),
//!   where `voltage_v` and the temperatures, which repeat, compress better plain;
//! - values handed to the column writers [`WRITE_BATCH`] at a time, and no limit on a page's
//!   rows, so that a page holds a whole column chunk up to the 1 MB page size (fewer, larger
//!   pages: less work per value, better compression);
//! - no dictionaries, except for the fault names;
//! - minimum and maximum per row group for `t_s`, `esc` and `status` only (what a reader needs
//!   to skip row groups by time, ESC or fault).
//!
//! Row groups hold about [`ROW_GROUP_ROWS`] rows, so that memory stays small.

use std::io;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, SyncSender};

use arrow_schema::Schema;
use bytes::Bytes;
use hwfoc::{DataFrame, Fault, Settings, Temperature};
use parquet::arrow::{ArrowSchemaConverter, add_encoded_arrow_schema_to_metadata};
use parquet::basic::{Compression, Encoding};
use parquet::column::writer::{ColumnCloseResult, get_column_writer, get_typed_column_writer};
use parquet::data_type::{
    ByteArray, ByteArrayType, DataType as ParquetType, DoubleType, FloatType, Int32Type,
};
use parquet::errors::ParquetError;
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterPropertiesPtr;
use parquet::file::properties::{
    DeltaBinaryPackedEncoderOptions, EnabledStatistics, WriterProperties, WriterVersion,
};
use parquet::file::writer::{SerializedFileWriter, SerializedPageWriter, TrackedWrite};
use parquet::schema::types::{ColumnDescPtr, ColumnPath, SchemaDescriptor};

use super::arrow::{ITEM, schema};

use super::{Chunk, Destination, Provenance, ToWriter, WriteError};

/// Rows per row group, at least (a row group is written once this many rows are collected).
pub const ROW_GROUP_ROWS: usize = 1 << 17;

/// Values handed to a column writer at a time (the crate's default, 1024, spends more time per
/// value and makes pages of 1 MB at most).
const WRITE_BATCH: usize = 1 << 16;

/// The writer's properties: fast encodings, the settings and the Arrow schema in the key-value
/// metadata.
fn properties(schema: &Schema, provenance: &Provenance) -> WriterProperties {
    let s = provenance.settings;
    let mut kv = vec![
        KeyValue::new(
            "hwfoc_version".to_string(),
            env!("CARGO_PKG_VERSION").to_string(),
        ),
        KeyValue::new("current_scale".to_string(), s.current_scale.to_string()),
        KeyValue::new("pole_pairs".to_string(), s.pole_pairs.to_string()),
        KeyValue::new("gear_ratio".to_string(), s.gear_ratio.to_string()),
        KeyValue::new(
            "inputs".to_string(),
            serde_json::Value::from(provenance.inputs.clone()).to_string(),
        ),
    ];
    if !provenance.filter.is_empty() {
        kv.push(KeyValue::new(
            "filter".to_string(),
            provenance.filter.clone(),
        ));
    }
    let mut builder = WriterProperties::builder()
        .set_writer_version(WriterVersion::PARQUET_2_0)
        .set_compression(Compression::LZ4_RAW)
        .set_dictionary_enabled(false)
        .set_encoding(Encoding::PLAIN)
        .set_column_dictionary_enabled(
            ColumnPath::from(vec![
                "faults".to_string(),
                "list".to_string(),
                ITEM.to_string(),
            ]),
            true,
        )
        .set_statistics_enabled(EnabledStatistics::None)
        .set_write_batch_size(WRITE_BATCH)
        // A page per column chunk (up to the 1 MB page size): fewer pages to encode and
        // compress, and longer runs for LZ4 to find repeats in (3 % less CPU, a file a
        // third smaller on the benchmark's input). Row groups are small enough for readers
        // to skip by their statistics.
        .set_data_page_row_count_limit(usize::MAX)
        .set_key_value_metadata(Some(kv));
    // Packet numbers count up, eRPM drifts: their differences pack into a few bits, smaller
    // and cheaper than compressing the plain values (which barely compress). One bit width per
    // 128 differences rather than per 32 (the crate's default, and the format's smallest):
    // 2 % less CPU for the whole export, 6 % more for `erpm`, `packet` smaller.
    builder = builder.set_delta_binary_packed_encoder_options(
        DeltaBinaryPackedEncoderOptions::try_new(128, 1).expect("a valid block layout"),
    );
    for column in ["packet", "erpm"] {
        builder = builder
            .set_column_encoding(ColumnPath::from(column), Encoding::DELTA_BINARY_PACKED)
            .set_column_compression(ColumnPath::from(column), Compression::UNCOMPRESSED);
    }
    // Throttles and currents vary slowly: split into byte streams, their high bytes repeat.
    for column in [
        "throttle_in_pct",
        "throttle_out_pct",
        "rpm",
        "current_a",
        "phase_current_a",
    ] {
        builder =
            builder.set_column_encoding(ColumnPath::from(column), Encoding::BYTE_STREAM_SPLIT);
    }
    for column in ["t_s", "esc", "status"] {
        builder = builder
            .set_column_statistics_enabled(ColumnPath::from(column), EnabledStatistics::Chunk);
    }
    let mut props = builder.build();
    add_encoded_arrow_schema_to_metadata(schema, &mut props);
    props
}

/// Converts frames to Parquet columns under fixed settings and encodes them.
pub struct Converter {
    settings: Settings,
    /// The temperature of each ADC code, and whether it is in the table's range.
    celsius: [(f32, bool); 256],
    /// Each fault's name, ready to be stored.
    names: [ByteArray; 16],
}

impl Converter {
    /// A converter for `settings`.
    pub fn new(settings: Settings) -> Converter {
        Converter {
            settings,
            celsius: std::array::from_fn(|code| {
                match Temperature::from_adc(code as u8).celsius() {
                    Some(c) => (c, true),
                    None => (0.0, false),
                }
            }),
            names: std::array::from_fn(|bit| {
                let name = Fault::from_bit(bit as u8).map_or("", Fault::name);
                ByteArray::from(name)
            }),
        }
    }

    /// Converts and encodes column `index` (in schema order) of `rows` into memory: the
    /// column chunk's bytes and the metadata that goes with them.
    fn encode(
        &self,
        index: usize,
        rows: &Chunk,
        descr: &SchemaDescriptor,
        props: &WriterPropertiesPtr,
    ) -> Encoded {
        let frames = &rows.frames;
        let s = &self.settings;
        let descr = descr.column(index);
        match index {
            // A receive time where there is one, null where not (NaN in the chunk).
            0 => encode_blocks::<DoubleType, _>(descr, props, &rows.t, |block, levels| {
                let timed = block.iter().filter(|t| !t.is_nan()).count();
                if timed == block.len() {
                    levels.values.extend_from_slice(block);
                    levels.def.resize(block.len(), 1);
                } else if timed == 0 {
                    levels.def.resize(block.len(), 0);
                } else {
                    for &t in block {
                        if !t.is_nan() {
                            levels.values.push(t);
                        }
                        levels.def.push(i16::from(!t.is_nan()));
                    }
                }
            }),
            1 => encode_converted::<Int32Type, _>(descr, props, &rows.esc, |&e| i32::from(e)),
            2 => encode_converted::<Int32Type, _>(descr, props, frames, |f| i32::from(f.packet)),
            3 => encode_converted::<FloatType, _>(descr, props, frames, DataFrame::throttle_in_pct),
            4 => {
                encode_converted::<FloatType, _>(descr, props, frames, DataFrame::throttle_out_pct)
            }
            // UINT_32 is stored in an INT32 column with the same bits.
            5 => encode_converted::<Int32Type, _>(descr, props, frames, |f| f.erpm() as i32),
            6 => encode_converted::<FloatType, _>(descr, props, frames, |f| f.rpm(s)),
            7 => encode_converted::<FloatType, _>(descr, props, frames, DataFrame::voltage_v),
            8 => encode_converted::<FloatType, _>(descr, props, frames, |f| f.current_a(s)),
            9 => encode_converted::<FloatType, _>(descr, props, frames, |f| f.phase_current_a(s)),
            // Temperatures from ADC codes: null where a code is outside the table.
            10 | 11 => {
                let code = if index == 10 {
                    |f: &DataFrame| f.mos_adc
                } else {
                    |f: &DataFrame| f.cap_adc
                };
                encode_blocks::<FloatType, _>(descr, props, frames, |block, levels| {
                    // Usually every code is in the table: no branch per row then.
                    let mut all_valid = true;
                    levels.values.extend(block.iter().map(|f| {
                        let (c, valid) = self.celsius[usize::from(code(f))];
                        all_valid &= valid;
                        c
                    }));
                    if all_valid {
                        levels.def.resize(block.len(), 1);
                        return;
                    }
                    levels.values.clear();
                    for f in block {
                        let (c, valid) = self.celsius[usize::from(code(f))];
                        if valid {
                            levels.values.push(c);
                        }
                        levels.def.push(i16::from(valid));
                    }
                })
            }
            12 => encode_converted::<Int32Type, _>(descr, props, frames, |f| i32::from(f.status.0)),
            // The fault names of each row: a list, so each name has a repetition level (0 for
            // a row's first) and an empty list is one level pair and no value.
            // Mostly levels and few values: one batch for the whole row group (in blocks of
            // BLOCK rows this column cost 0.3 s more CPU on the 2 GiB benchmark input).
            _ => encode_in::<ByteArrayType, _>(
                frames.len(),
                descr,
                props,
                frames,
                |block, levels| {
                    if block.iter().all(|f| f.status.is_ok()) {
                        // The usual row group: no fault at all.
                        levels.def.resize(block.len(), 0);
                        levels.rep.resize(block.len(), 0);
                        return;
                    }
                    for f in block {
                        if f.status.is_ok() {
                            levels.push(0, 0);
                            continue;
                        }
                        for (i, fault) in f.status.faults().enumerate() {
                            levels
                                .values
                                .push(self.names[usize::from(fault.bit())].clone());
                            levels.push(1, i16::from(i > 0));
                        }
                    }
                },
            ),
        }
    }

    /// Converts, encodes and compresses the columns of `rows` in memory, by this thread and a
    /// helper, each taking the next column not yet taken (on two cores, the decoding thread
    /// leaves time to spare). `meanwhile` runs on this thread first, while the helper starts
    /// on the columns: writing the previous row group to the file overlaps with encoding this
    /// one. Returns the column chunks in schema order, and what `meanwhile` returned.
    fn encode_row_group<R>(
        &self,
        rows: &Chunk,
        descr: &SchemaDescriptor,
        props: &WriterPropertiesPtr,
        meanwhile: impl FnOnce() -> R,
    ) -> (Result<Vec<EncodedColumn>, ParquetError>, R) {
        let leaves = descr.num_columns();
        let next = AtomicUsize::new(0);
        let work = || {
            let mut done = Vec::new();
            while let Some(&index) = BY_COST.get(next.fetch_add(1, Ordering::Relaxed)) {
                done.push((index, self.encode(index, rows, descr, props)));
            }
            done
        };
        let (mut chunks, other) = std::thread::scope(|s| {
            let helper = s.spawn(work);
            let other = meanwhile();
            let mut mine = work();
            // A helper that panicked has encoded nothing more: its columns are missing below.
            mine.extend(helper.join().unwrap_or_default());
            (mine, other)
        });
        if chunks.len() != leaves {
            let e = ParquetError::General("a column could not be encoded".to_string());
            return (Err(e), other);
        }
        chunks.sort_by_key(|(index, _)| *index);
        (chunks.into_iter().map(|(_, chunk)| chunk).collect(), other)
    }
}

/// Writes encoded columns to the file as its next row group.
fn append_row_group<W: io::Write + Send>(
    writer: &mut SerializedFileWriter<W>,
    columns: Vec<EncodedColumn>,
) -> Result<(), ParquetError> {
    let mut rg = writer.next_row_group()?;
    for (bytes, close) in columns {
        rg.append_column(&bytes, close)?;
    }
    rg.close()?;
    Ok(())
}

/// The columns (schema indices), costliest to encode first: the two threads then end a row
/// group together, give or take one of the cheap columns at the end (measured on
/// `scripts/bench-export.sh` input: delta-encoded `packet` and `erpm`, then the byte-stream-split
/// and compressed floats, down to `esc`, `status` and `t_s`, which compress to nearly nothing).
const BY_COST: [usize; 14] = [2, 5, 6, 8, 9, 3, 4, 10, 11, 13, 7, 1, 12, 0];

/// Rows converted at a time by [`encode_blocks`]: their values are still in the processor's
/// first-level cache when the column writer copies them.
const BLOCK: usize = 4096;

/// A block's values (nulls left out) and, for a column that has them, its definition and
/// repetition levels.
struct Levels<T> {
    values: Vec<T>,
    def: Vec<i16>,
    rep: Vec<i16>,
}

impl<T> Levels<T> {
    /// Adds a level pair: `def` 0 for a null or an empty list, the column's maximum for a
    /// value; `rep` 0 for a row's first value (columns that repeat only).
    fn push(&mut self, def: i16, rep: i16) {
        self.def.push(def);
        self.rep.push(rep);
    }
}

/// Encodes one column chunk into memory, [`BLOCK`] rows at a time: `fill` appends the values,
/// and the levels if the column has them, of a block of rows to the empty buffers it is given.
fn encode_blocks<T: ParquetType, R>(
    descr: ColumnDescPtr,
    props: &WriterPropertiesPtr,
    rows: &[R],
    fill: impl Fn(&[R], &mut Levels<T::T>),
) -> Encoded {
    encode_in::<T, R>(BLOCK, descr, props, rows, fill)
}

/// [`encode_blocks`] with blocks of `block_rows` rows.
fn encode_in<T: ParquetType, R>(
    block_rows: usize,
    descr: ColumnDescPtr,
    props: &WriterPropertiesPtr,
    rows: &[R],
    fill: impl Fn(&[R], &mut Levels<T::T>),
) -> Encoded {
    let nullable = descr.max_def_level() > 0;
    let repeated = descr.max_rep_level() > 0;
    let mut buf = TrackedWrite::new(Vec::new());
    let close = {
        let pages = SerializedPageWriter::new(&mut buf);
        let mut writer =
            get_typed_column_writer::<T>(get_column_writer(descr, props.clone(), Box::new(pages)));
        let mut block = Levels {
            values: Vec::with_capacity(block_rows),
            def: Vec::with_capacity(block_rows),
            rep: Vec::with_capacity(block_rows),
        };
        for rows in rows.chunks(block_rows.max(1)) {
            block.values.clear();
            block.def.clear();
            block.rep.clear();
            fill(rows, &mut block);
            writer.write_batch(
                &block.values,
                nullable.then_some(&block.def[..]),
                repeated.then_some(&block.rep[..]),
            )?;
        }
        writer.close()?
    };
    Ok((Bytes::from(buf.into_inner()?), close))
}

/// Encodes one column chunk of values that are never null: `value` of each row.
fn encode_converted<T: ParquetType, R>(
    descr: ColumnDescPtr,
    props: &WriterPropertiesPtr,
    rows: &[R],
    value: impl Fn(&R) -> T::T,
) -> Encoded {
    encode_blocks::<T, R>(descr, props, rows, |block, levels| {
        levels.values.extend(block.iter().map(&value))
    })
}

/// A column chunk encoded in memory: its bytes and the metadata that goes with them.
type EncodedColumn = (Bytes, ColumnCloseResult);

/// A column chunk encoded in memory, or why it could not be.
type Encoded = Result<EncodedColumn, ParquetError>;

/// A Parquet error as a write error naming the output (an I/O error as itself).
fn write_error(output: &str, e: ParquetError) -> WriteError {
    let source = match e {
        ParquetError::External(inner) => match inner.downcast::<io::Error>() {
            Ok(io) => *io,
            Err(other) => io::Error::other(other.to_string()),
        },
        other => io::Error::other(other.to_string()),
    };
    WriteError::Write {
        output: output.to_string(),
        source,
    }
}

/// Writes the rows received on `rx` as one Parquet file, a row group per message, and returns
/// them on `spare` for reuse. At the end message, or when the sender goes away, the
/// file is closed properly: footer and metadata, so it is readable.
pub(super) fn write(
    sink: Destination,
    provenance: &Provenance,
    rx: Receiver<ToWriter>,
    spare: SyncSender<Chunk>,
) -> Result<(), WriteError> {
    let schema = schema();
    let name = sink.name;
    let fail = |e| write_error(&name, e);
    let parquet_schema = ArrowSchemaConverter::new().convert(&schema).map_err(fail)?;
    let props = Arc::new(properties(&schema, provenance));
    let mut writer =
        SerializedFileWriter::new(sink.writer, parquet_schema.root_schema_ptr(), props.clone())
            .map_err(fail)?;
    let converter = Converter::new(provenance.settings);
    // The row group encoded last, written to the file while the next one is encoded.
    let mut previous: Option<Vec<EncodedColumn>> = None;
    for msg in rx {
        match msg {
            ToWriter::Rows(rows) => {
                let (encoded, written) =
                    converter.encode_row_group(&rows, &parquet_schema, &props, || {
                        previous
                            .take()
                            .map_or(Ok(()), |columns| append_row_group(&mut writer, columns))
                    });
                written.map_err(fail)?;
                previous = Some(encoded.map_err(fail)?);
                // The command may have stopped listening; the rows are then dropped.
                let _ = spare.try_send(rows);
            }
            ToWriter::End(metadata) => {
                for (key, value) in metadata {
                    writer.append_key_value_metadata(KeyValue::new(key, value));
                }
                break;
            }
        }
    }
    if let Some(columns) = previous {
        append_row_group(&mut writer, columns).map_err(fail)?;
    }
    writer.close().map_err(fail)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use parquet::basic::Type as PhysicalType;

    /// Every column is encoded, once.
    #[test]
    fn the_cost_order_names_every_column_once() {
        let mut order = BY_COST.to_vec();
        order.sort_unstable();
        let leaves = ArrowSchemaConverter::new()
            .convert(&schema())
            .unwrap()
            .num_columns();
        assert_eq!(order, (0..leaves).collect::<Vec<_>>());
    }

    /// The Parquet leaf columns that `Converter::encode` fills, in order, with their levels.
    #[test]
    fn parquet_schema_matches_the_columns_written() {
        let descr = ArrowSchemaConverter::new().convert(&schema()).unwrap();
        let leaves: Vec<(String, PhysicalType, i16, i16)> = descr
            .columns()
            .iter()
            .map(|c| {
                (
                    c.path().string(),
                    c.physical_type(),
                    c.max_def_level(),
                    c.max_rep_level(),
                )
            })
            .collect();
        use PhysicalType::*;
        let expected = [
            ("t_s", DOUBLE, 1, 0),
            ("esc", INT32, 0, 0),
            ("packet", INT32, 0, 0),
            ("throttle_in_pct", FLOAT, 0, 0),
            ("throttle_out_pct", FLOAT, 0, 0),
            ("erpm", INT32, 0, 0),
            ("rpm", FLOAT, 0, 0),
            ("voltage_v", FLOAT, 0, 0),
            ("current_a", FLOAT, 0, 0),
            ("phase_current_a", FLOAT, 0, 0),
            ("mos_temp_c", FLOAT, 1, 0),
            ("cap_temp_c", FLOAT, 1, 0),
            ("status", INT32, 0, 0),
            ("faults.list.item", BYTE_ARRAY, 1, 1),
        ];
        let expected: Vec<(String, PhysicalType, i16, i16)> = expected
            .into_iter()
            .map(|(p, t, d, r)| (p.to_string(), t, d, r))
            .collect();
        assert_eq!(leaves, expected);
    }
}
