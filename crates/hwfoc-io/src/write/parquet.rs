//! The Parquet writer: the record schema as an Apache Parquet file, with the Arrow schema
//! embedded so that Arrow readers (pyarrow, arrow-rs, polars, DuckDB) see the exact types.
//!
//! Columns, types and units are those of `docs/RECORD-SCHEMA.md`, from the column table
//! ([`crate::record::columns`]); each Arrow field carries its unit in its metadata (key `unit`,
//! `-` for a number without unit). The file's key-value metadata is that of
//! [`super::metadata`] (settings and provenance).
//!
//! Each column is one Parquet leaf column, encoded by code generic over the column: its values
//! computed from the frames, a block of rows at a time, and stored as its value type says
//! (`ParquetValue`: physical type, definition and repetition levels). Choices that are not
//! the defaults (plain values compressed with LZ4, statistics per row group) are made per column
//! by name, in the lists of this module (a test checks that each name is a column):
//!
//! Speed (figures from `scripts/bench-export.sh`): the decoding thread only collects frames,
//! a row group's worth at a time; the writer thread converts, encodes and compresses the
//! columns of each row group in memory together with a helper thread (each takes the next
//! column not yet done, costliest first (`BY_COST`), so that both end together), and writes
//! the previous row group to the file while the helper starts on the next. Encodings are
//! chosen to keep up with decoding:
//! - data pages of format version 2 (values compressed on their own, levels not, no copy of
//!   the values before compression; a page that does not compress is stored as it is);
//! - plain values compressed with LZ4 (`LZ4_RAW`: faster than Snappy here, and smaller);
//! - `packet`, `erpm` and `time` as bit-packed differences (`DELTA`: `DELTA_BINARY_PACKED`, not
//!   compressed, a bit width per 128 values): they count up or drift, and plain they hardly
//!   compress. (Their bytes split into streams and compressed would be smaller and cheaper
//!   still, but integer columns in that encoding came with Parquet 2.11, in 2024: Spark 3.5
//!   (parquet-java 1.13) and DuckDB releases before mid-2026 cannot read them; the floats'
//!   byte-stream split is older and read everywhere.)
//! - throttles, `rpm` and currents with their bytes split into streams (`SPLIT`:
//!   `BYTE_STREAM_SPLIT`) before compression: slowly varying values then compress to a half or
//!   a third (as fast), where `voltage_v` and the temperatures, which repeat, compress better
//!   plain;
//! - values handed to the column writers `WRITE_BATCH` at a time, and no limit on a page's
//!   rows, so that a page holds a whole column chunk up to the 1 MB page size (fewer, larger
//!   pages: less work per value, better compression);
//! - no dictionaries, except for the protocol and the fault names (`DICTIONARY`);
//! - a row group's `protocol` column, usually of one protocol, put together from the crate's
//!   dictionary page of that name and a data page of one run of index 0
//!   (`repeated_dictionary_chunk`): the crate's dictionary encoder hashes and compares every
//!   row's name;
//! - a nullable column with every value in a row group (each measurement the protocol carries,
//!   the time where the input has one) encoded as a required column, its definition levels
//!   added to each page as one run (`encode_present`): the crate takes levels one per row and
//!   encodes them one by one. Both make the bytes the column writer makes (tests check them
//!   against it, metadata included); a column null throughout goes to the column writer as
//!   levels only.
//! - statistics per row group for every column: minimum, maximum and null count (NaN count
//!   for the floats), so that a reader (DuckDB, pyarrow datasets, polars, Spark) skips the row
//!   groups a filter on any column excludes (`WHERE mos_temp_c > 100`, a range of `t_s` or
//!   `packet`). The list column `faults` has them for its leaf, the fault names (minimum and
//!   maximum name, where a row group has any; null count: the rows without fault, as the
//!   Parquet format counts an empty list). Statistics per page (a column index) are not
//!   written: a column chunk is a single page (see below). The footer gives the float columns
//!   the type-defined order rather than the parquet crate's IEEE 754 total order, which
//!   pyarrow does not know and for which it ignores their minimum and maximum
//!   (`type_defined_float_order`).
//!
//! Row groups hold about [`ROW_GROUP_ROWS`] rows, so that memory stays small, and a filter
//! skips in steps of that many rows.
//!
//! Without the `parquet` feature, only [`ROW_GROUP_ROWS`] remains, and a writer that reports
//! that Parquet output is not built in.

/// Rows per row group, at least (a row group is written once this many rows are collected).
pub const ROW_GROUP_ROWS: usize = 1 << 17;

#[cfg(feature = "parquet")]
pub use encode::ParquetValue;
#[cfg(feature = "parquet")]
pub(super) use encode::write;
#[cfg(not(feature = "parquet"))]
pub use off::ParquetValue;
#[cfg(not(feature = "parquet"))]
pub(super) use off::write;

/// Without the `parquet` feature.
#[cfg(not(feature = "parquet"))]
mod off {
    use std::io;
    use std::sync::mpsc::{Receiver, SyncSender};

    use super::super::{Chunk, Provenance, Sink, ToWriter, WriteError};

    /// How a value type is stored in Parquet: nothing to know without the `parquet` feature.
    pub trait ParquetValue {}

    impl<T> ParquetValue for T {}

    /// Reports that Parquet output is not built in.
    pub(in crate::write) fn write(
        sink: Sink,
        _: &Provenance,
        _: Receiver<ToWriter>,
        _: SyncSender<Chunk>,
    ) -> Result<(), WriteError> {
        Err(WriteError::Write {
            output: sink.name,
            source: io::Error::new(
                io::ErrorKind::Unsupported,
                "Parquet output is not built in (the `parquet` feature of hwfoc-io)",
            ),
        })
    }
}

/// The writer, with the `parquet` feature.
#[cfg(feature = "parquet")]
mod encode {
    use std::io::{self, Write};
    use std::ops::Range;
    use std::sync::Arc;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::mpsc::{Receiver, SyncSender};

    use bytes::Bytes;
    use hwfoc::telemetry::Data;
    use hwfoc::{Protocol, Settings, Status};
    use parquet::arrow::{ArrowSchemaConverter, add_encoded_arrow_schema_to_metadata};
    use parquet::basic::Repetition;
    use parquet::basic::{Compression, Encoding};
    use parquet::column::page::{CompressedPage, Page, PageWriteSpec, PageWriter};
    use parquet::column::writer::{ColumnCloseResult, get_column_writer, get_typed_column_writer};
    use parquet::data_type::{
        ByteArray, ByteArrayType, DataType as ParquetType, DoubleType, FloatType, Int32Type,
        Int64Type,
    };
    use parquet::errors::ParquetError;
    use parquet::file::metadata::{
        ColumnChunkMetaData, ColumnChunkMetaDataBuilder, KeyValue, LevelHistogram,
        OffsetIndexBuilder,
    };
    use parquet::file::properties::WriterPropertiesPtr;
    use parquet::file::properties::{
        DeltaBinaryPackedEncoderOptions, EnabledStatistics, WriterProperties, WriterVersion,
    };
    use parquet::file::writer::{SerializedFileWriter, SerializedPageWriter, TrackedWrite};
    use parquet::schema::types::{ColumnDescPtr, ColumnDescriptor, SchemaDescriptor, Type};

    use super::super::arrow::schema;
    use super::super::metadata::schema_with;
    use super::super::stored::columns::{COLUMNS, COUNT, visit};
    use super::super::stored::{Column, Visitor};
    use super::super::{Chunk, Frames, Provenance, Sink, ToWriter, WriteError};
    use hwfoc_records::record::{FaultList, UtcTime};

    /// Values handed to a column writer at a time (the crate's default, 1024, spends more time
    /// per value and makes pages of 1 MB at most).
    pub const WRITE_BATCH: usize = 1 << 16;

    /// Columns stored as bit-packed differences (`DELTA_BINARY_PACKED`), not compressed:
    /// packet numbers count up, eRPM drifts, so their differences pack into a few bits, smaller
    /// and cheaper than compressing the plain values (which barely compress).
    /// `time` counts up by about the frame period: 1.34 M rows of 16 ESCs took 23.4 MB of file
    /// so, 27.7 MB with `time` plain and compressed, 21.0 MB without the column.
    pub const DELTA: [&str; 3] = ["packet", "erpm", "time"];

    /// Columns with their bytes split into streams (`BYTE_STREAM_SPLIT`) before compression:
    /// throttles and currents vary slowly, so their high bytes repeat.
    pub const SPLIT: [&str; 5] = [
        "throttle_in_pct",
        "throttle_out_pct",
        "rpm",
        "current_a",
        "phase_current_a",
    ];

    /// Columns with a dictionary: the protocol names and the fault names, few and repeated.
    /// (`protocol` is a dictionary in the Arrow schema too, which readers of the embedded
    /// schema restore.)
    pub const DICTIONARY: [&str; 2] = ["protocol", "faults"];

    /// The columns costliest to encode first: the two threads then end a row group together,
    /// give or take one of the cheap columns at the end (measured on `scripts/bench-export.sh`
    /// input: delta-encoded `packet` and `erpm`, then the byte-stream-split and compressed
    /// floats, down to `esc`, `status` and `t_s`, which compress to nearly nothing). Columns
    /// not named come last, in schema order.
    pub const BY_COST: [&str; 19] = [
        "packet",
        "erpm",
        "rpm",
        "current_a",
        "phase_current_a",
        "throttle_in_pct",
        "throttle_out_pct",
        "mos_temp_c",
        "cap_temp_c",
        "faults",
        "voltage_v",
        "protocol",
        "esc",
        "status",
        "t_s",
        "motor_temp_c",
        "bec_temp_c",
        "bec_voltage_v",
        "bec_current_a",
    ];

    /// The position of column `name` in the schema.
    fn index_of(name: &str) -> Option<usize> {
        COLUMNS.iter().position(|&c| c == name)
    }

    /// The columns (schema indices) in the order of [`BY_COST`], then the others.
    fn cost_order() -> Vec<usize> {
        let named: Vec<usize> = BY_COST.iter().filter_map(|&n| index_of(n)).collect();
        let others = (0..COUNT).filter(|i| !named.contains(i));
        named.iter().copied().chain(others).collect()
    }

    /// The Arrow schema as the `ARROW:schema` key-value entry, its own metadata holding every
    /// other key-value entry of the file: readers that rebuild the Arrow schema from it
    /// (`pyarrow.parquet.read_table(f).schema.metadata`, arrow-rs) show the settings and
    /// provenance there, as readers of the footer see them in its key-value metadata. The
    /// parquet crate encodes the schema only into writer properties, so it is taken from there.
    fn encoded_schema(metadata: &[KeyValue]) -> Option<KeyValue> {
        let entries: Vec<(String, String)> = metadata
            .iter()
            .filter_map(|kv| Some((kv.key.clone(), kv.value.clone()?)))
            .collect();
        let mut props = WriterProperties::builder().build();
        add_encoded_arrow_schema_to_metadata(&schema_with(&entries), &mut props);
        props
            .key_value_metadata()?
            .iter()
            .find(|kv| kv.key == parquet::arrow::ARROW_SCHEMA_META_KEY)
            .cloned()
    }

    /// The writer's properties: fast encodings, and the settings and provenance in the
    /// key-value metadata (the Arrow schema is added at the end, with all the metadata).
    fn properties(descr: &SchemaDescriptor, kv: Vec<KeyValue>) -> WriterProperties {
        // The leaf column of each column named (`faults.list.item` for the list).
        let leaves = |names: &'static [&'static str]| {
            names
                .iter()
                .filter_map(|&n| index_of(n))
                .map(|i| descr.column(i).path().clone())
        };
        let mut builder = WriterProperties::builder()
            .set_writer_version(WriterVersion::PARQUET_2_0)
            .set_compression(Compression::LZ4_RAW)
            .set_dictionary_enabled(false)
            .set_encoding(Encoding::PLAIN)
            // Minimum, maximum and null count of every column chunk, computed by the parquet
            // crate's kernels a batch at a time: 12 % of the export's CPU time on the 2 GiB
            // benchmark input (0.5 s more user time than without; a hand-written lane-wise
            // minimum and maximum per block, in the same sitting, was no cheaper).
            .set_statistics_enabled(EnabledStatistics::Chunk)
            .set_write_batch_size(WRITE_BATCH)
            // A page per column chunk (up to the 1 MB page size): fewer pages to encode and
            // compress, and longer runs for LZ4 to find repeats in (3 % less CPU, a file a
            // third smaller on the benchmark's input). Row groups are small enough for readers
            // to skip by their statistics.
            .set_data_page_row_count_limit(usize::MAX)
            .set_key_value_metadata(Some(kv));
        for path in leaves(&DICTIONARY) {
            builder = builder.set_column_dictionary_enabled(path, true);
        }
        // One bit width per 128 differences rather than per 32 (the crate's default, and the
        // format's smallest): 2 % less CPU for the whole export, 6 % more for `erpm`, `packet`
        // smaller.
        builder = builder.set_delta_binary_packed_encoder_options(
            DeltaBinaryPackedEncoderOptions::try_new(128, 1).expect("a valid block layout"),
        );
        for path in leaves(&DELTA) {
            builder = builder
                .set_column_encoding(path.clone(), Encoding::DELTA_BINARY_PACKED)
                .set_column_compression(path, Compression::UNCOMPRESSED);
        }
        for path in leaves(&SPLIT) {
            builder = builder.set_column_encoding(path, Encoding::BYTE_STREAM_SPLIT);
        }
        builder.build()
    }

    /// How a value type is stored in a Parquet leaf column: its physical type, its levels, and
    /// how a block of values becomes the column writer's input.
    pub trait ParquetValue: Sized {
        /// The physical type (with the logical type, the Arrow schema's conversion decides).
        type Physical: ParquetType;
        /// The highest definition level: 0 for a value never null, 1 for an optional value or
        /// a list of required items.
        const MAX_DEF: i16 = 0;
        /// The highest repetition level: 1 for a list, else 0.
        const MAX_REP: i16 = 0;
        /// Whether a column chunk whose every value is [`ParquetValue::is_bare`] goes to the
        /// column writer in one batch rather than [`BLOCK`] rows at a time.
        const ONE_BATCH: bool = false;

        /// Whether the value stores levels only (an empty list): chunks of such values alone
        /// may go in one batch (see [`ParquetValue::ONE_BATCH`]).
        #[inline(always)]
        fn is_bare(&self) -> bool {
            false
        }

        /// Appends the values of a block of rows, nulls left out, and their levels if the
        /// column has them, to the empty buffers of `levels`.
        fn fill(
            values: impl ExactSizeIterator<Item = Self> + Clone,
            levels: &mut Levels<<Self::Physical as ParquetType>::T>,
        );

        /// The column chunk of `rows` rows (row `i`'s value: `value(i)`) encoded in one go,
        /// where this value type has a faster way than the column writer's, value by value,
        /// for these rows; `None` where not (the column writer then takes them, a block at a
        /// time). The bytes and metadata must be those the column writer would give.
        #[inline(always)]
        fn encode_whole(
            _value: impl Fn(usize) -> Self,
            _rows: usize,
            _descr: &ColumnDescPtr,
            _props: &WriterPropertiesPtr,
        ) -> Option<Encoded> {
            None
        }
    }

    /// A value type stored as one physical value, never null (and, in an `Option`, nullable).
    pub trait Plain: ParquetValue {
        /// The physical value.
        fn physical(self) -> <Self::Physical as ParquetType>::T;
    }

    macro_rules! plain {
        ($($value:ty => $physical:ty, |$v:ident| $to:expr;)*) => {$(
            impl ParquetValue for $value {
                type Physical = $physical;

                #[inline(always)]
                fn fill(
                    values: impl ExactSizeIterator<Item = Self> + Clone,
                    levels: &mut Levels<<Self::Physical as ParquetType>::T>,
                ) {
                    levels.values.extend(values.map(Plain::physical));
                }
            }

            impl Plain for $value {
                #[inline(always)]
                fn physical(self) -> <Self::Physical as ParquetType>::T {
                    let $v = self;
                    $to
                }
            }
        )*};
    }

    plain! {
        f32 => FloatType, |v| v;
        f64 => DoubleType, |v| v;
        u8 => Int32Type, |v| i32::from(v);
        u16 => Int32Type, |v| i32::from(v);
        // UINT_32 is stored in an INT32 column with the same bits.
        u32 => Int32Type, |v| v as i32;
        Status => Int32Type, |v| i32::from(v.0);
        // TIMESTAMP(MICROS, UTC) is an INT64 (the logical type from the Arrow field).
        UtcTime => Int64Type, |v| v.0;
    }

    impl<T: Plain> ParquetValue for Option<T>
    where
        <T::Physical as ParquetType>::T: Default,
    {
        type Physical = T::Physical;
        const MAX_DEF: i16 = 1;

        /// Usually every value of a block is there (temperatures in range, times), or none is
        /// (input without timing): no branch per row then.
        #[inline(always)]
        fn fill(
            values: impl ExactSizeIterator<Item = Self> + Clone,
            levels: &mut Levels<<Self::Physical as ParquetType>::T>,
        ) {
            let rows = values.len();
            if let Some(None) = values.clone().next() {
                // Likely none at all (counted without a branch per row).
                if values
                    .clone()
                    .map(|v| usize::from(v.is_some()))
                    .sum::<usize>()
                    == 0
                {
                    levels.def.resize(rows, 0);
                    return;
                }
            } else {
                // Likely all.
                let mut valid = 0;
                levels.values.extend(values.clone().map(|v| {
                    valid += usize::from(v.is_some());
                    v.map_or_else(Default::default, T::physical)
                }));
                if valid == rows {
                    levels.def.resize(rows, 1);
                    return;
                }
                levels.values.clear();
            }
            for v in values {
                levels.def.push(i16::from(v.is_some()));
                if let Some(v) = v {
                    levels.values.push(v.physical());
                }
            }
        }
    }

    impl ParquetValue for FaultList {
        type Physical = ByteArrayType;
        const MAX_DEF: i16 = 1;
        const MAX_REP: i16 = 1;
        /// A row group without any fault (the usual one) is levels only: one batch for it (in
        /// blocks of [`BLOCK`] rows this column cost 0.3 s more CPU on the 2 GiB benchmark
        /// input). A row group with faults goes in blocks: a batch of a whole row group of
        /// faulty frames held up to 16 names a row, over 100 MB.
        const ONE_BATCH: bool = true;

        #[inline(always)]
        fn is_bare(&self) -> bool {
            self.0.is_ok()
        }

        fn fill(
            values: impl ExactSizeIterator<Item = Self> + Clone,
            levels: &mut Levels<ByteArray>,
        ) {
            fill_fault_lists(values.map(Some), 0, levels);
        }
    }

    impl ParquetValue for Option<FaultList> {
        type Physical = ByteArrayType;
        /// 0: a null list; 1: an empty list; 2: a name.
        const MAX_DEF: i16 = 2;
        const MAX_REP: i16 = 1;
        /// As for [`FaultList`]: a row group without fault and without null is levels only.
        const ONE_BATCH: bool = true;

        #[inline(always)]
        fn is_bare(&self) -> bool {
            self.is_some_and(|f| f.0.is_ok())
        }

        fn fill(
            values: impl ExactSizeIterator<Item = Self> + Clone,
            levels: &mut Levels<ByteArray>,
        ) {
            fill_fault_lists(values, 1, levels);
        }
    }

    /// The fault names of each row (`None`: a null list, level 0): each name has a repetition
    /// level (0 for a row's first) and the definition level `empty + 1`; an empty list is one
    /// level pair (`empty`, 0) and no value. Rows without fault come in long runs (a whole row
    /// group, usually): a run's levels are added at once, at its end, so that such a row costs
    /// a test and an increment.
    #[inline(always)]
    fn fill_fault_lists(
        values: impl Iterator<Item = Option<FaultList>>,
        empty: i16,
        levels: &mut Levels<ByteArray>,
    ) {
        // Rows without fault whose levels are still to be added.
        let mut run = 0;
        for faults in values {
            let Some(faults) = faults else {
                levels.push_empty(run, empty);
                run = 0;
                levels.push(0, 0);
                continue;
            };
            if faults.0.is_ok() {
                run += 1;
                continue;
            }
            levels.push_empty(run, empty);
            run = 0;
            for (i, name) in faults.names().enumerate() {
                levels
                    .values
                    .push(ByteArray::from(Bytes::from_static(name.as_bytes())));
                levels.push(empty + 1, i16::from(i > 0));
            }
        }
        levels.push_empty(run, empty);
    }

    impl ParquetValue for Protocol {
        type Physical = ByteArrayType;

        /// The protocol's name (the column is dictionary-encoded: [`DICTIONARY`]).
        #[inline(always)]
        fn fill(
            values: impl ExactSizeIterator<Item = Self> + Clone,
            levels: &mut Levels<ByteArray>,
        ) {
            levels.values.extend(values.map(protocol_name));
        }

        /// A row group of one protocol (the usual one): its chunk made from the dictionary
        /// page of that one name and a data page of one run of index 0
        /// ([`repeated_dictionary_chunk`]), rather than by the column writer's dictionary
        /// encoder, which hashes and compares every row's name, after a byte array was made of
        /// it and compared for the statistics (in all about 1.8 s of the 7.3 s of user time of
        /// the export of the 2 GiB benchmark input).
        fn encode_whole(
            value: impl Fn(usize) -> Self,
            rows: usize,
            descr: &ColumnDescPtr,
            props: &WriterPropertiesPtr,
        ) -> Option<Encoded> {
            let first = value(0);
            if rows == 0 || (1..rows).any(|i| value(i) != first) {
                return None;
            }
            repeated_dictionary_chunk(&protocol_name(first), rows, descr, props).transpose()
        }
    }

    /// The protocol's name as a byte array.
    #[inline(always)]
    fn protocol_name(p: Protocol) -> ByteArray {
        ByteArray::from(Bytes::from_static(p.name().as_bytes()))
    }

    /// The column chunk of a required, dictionary-encoded byte-array column whose `rows` rows
    /// all hold `value`, byte for byte as the parquet crate's column writer makes it; `None`
    /// where this cannot be sure of that (then the column writer encodes the rows).
    ///
    /// The crate has no way to hand its dictionary encoder indices rather than values (its
    /// `DictEncoder` interns each value; the Arrow writer's dictionary arrays too), nor to
    /// write a data page of levels given as runs, so the chunk is put together here from the
    /// crate's own parts: the dictionary page and the metadata of the chunk of the value once,
    /// encoded by the crate, and a data page written by the crate's page writer, whose values
    /// are written here: the dictionary's bit width (0: one entry) and one RLE run of index 0
    /// (the run's length as a ULEB128 varint shifted left by one, and no value bytes at bit
    /// width 0), as the crate's `RleEncoder` writes a run of equal values. Five bytes at most,
    /// which LZ4 cannot make smaller: the page is stored uncompressed, as the crate stores a
    /// page that does not compress. The metadata differ from the template's only in counts,
    /// sizes and the data page's offset-index entry.
    fn repeated_dictionary_chunk(
        value: &ByteArray,
        rows: usize,
        descr: &ColumnDescPtr,
        props: &WriterPropertiesPtr,
    ) -> Result<Option<EncodedColumn>, ParquetError> {
        let (Ok(count), false, 0, 0) = (
            u32::try_from(rows),
            rows == 0,
            descr.max_def_level(),
            descr.max_rep_level(),
        ) else {
            return Ok(None);
        };
        let (once, template) = encode_in::<ByteArrayType>(1, descr.clone(), props, 1, |_, l| {
            l.values.push(value.clone())
        })?;
        let meta = &template.metadata;
        let Some(index) = template.offset_index.as_ref() else {
            return Ok(None);
        };
        // The dictionary page first, then one data page of one index.
        let (Some(0), [page], 1, true, WriterVersion::PARQUET_2_0) = (
            meta.dictionary_page_offset(),
            index.page_locations().as_slice(),
            meta.num_values(),
            props.dictionary_enabled(descr.path()),
            props.writer_version(),
        ) else {
            return Ok(None);
        };
        let dictionary = meta.data_page_offset();
        if page.offset != dictionary || page.first_row_index != 0 {
            return Ok(None);
        }
        // The template's data page (two bytes of values) is stored uncompressed too: the
        // dictionary page's sizes are the chunk's less the data page's.
        let dictionary_uncompressed =
            meta.uncompressed_size() - i64::from(page.compressed_page_size);
        let unencoded = i64::try_from(value.len() * rows).ok();

        let mut values = vec![0u8];
        push_varint(&mut values, u64::from(count) << 1);
        let mut buf = TrackedWrite::new(Vec::with_capacity(dictionary as usize + 32));
        buf.write_all(&once[..dictionary as usize])?;
        let spec = {
            let mut pages = SerializedPageWriter::new(&mut buf);
            let size = values.len();
            let page = Page::DataPageV2 {
                buf: Bytes::from(values),
                num_values: count,
                encoding: Encoding::RLE_DICTIONARY,
                num_nulls: 0,
                num_rows: count,
                def_levels_byte_len: 0,
                rep_levels_byte_len: 0,
                is_compressed: false,
                statistics: None,
            };
            let spec = pages.write_page(CompressedPage::new(page, size))?;
            pages.close()?;
            spec
        };
        let metadata = ColumnChunkMetaDataBuilder::from(meta.clone())
            .set_num_values(i64::from(count))
            .set_total_compressed_size(dictionary + spec.compressed_size as i64)
            .set_total_uncompressed_size(dictionary_uncompressed + spec.uncompressed_size as i64)
            .set_unencoded_byte_array_data_bytes(unencoded)
            .build()?;
        let mut offsets = OffsetIndexBuilder::new();
        offsets.append_offset_and_size(spec.offset as i64, spec.compressed_size as i32);
        offsets.append_row_count(i64::from(count));
        offsets.append_unencoded_byte_array_data_bytes(unencoded);
        let bytes_written = buf.bytes_written() as u64;
        let close = ColumnCloseResult {
            bytes_written,
            rows_written: u64::from(count),
            metadata,
            bloom_filter: None,
            column_index: template.column_index.clone(),
            offset_index: Some(offsets.build()),
        };
        Ok(Some((Bytes::from(buf.into_inner()?), close)))
    }

    /// Converts frames to Parquet columns under fixed settings and encodes them.
    struct Encoder {
        settings: Settings,
        /// The columns' schema indices, costliest first.
        order: Vec<usize>,
    }

    /// Encodes the column whose index is `index`: the visitor of [`Encoder::encode`].
    struct EncodeColumn<'a> {
        index: usize,
        rows: &'a Chunk,
        descr: &'a SchemaDescriptor,
        props: &'a WriterPropertiesPtr,
        settings: &'a Settings,
        encoded: Option<Encoded>,
    }

    impl Visitor for EncodeColumn<'_> {
        fn column<C: Column>(&mut self) {
            if C::INDEX == self.index {
                let descr = self.descr.column(C::INDEX);
                let encoded = encode_column::<C>(self.rows, descr, self.props, self.settings);
                self.encoded = Some(encoded);
            }
        }
    }

    /// Converts and encodes column `C` of `rows` into memory: the column chunk's bytes and the
    /// metadata that goes with them. Rows are converted under `settings`, or under their ESC's
    /// where the rows carry a table of settings by ESC.
    fn encode_column<C: Column>(
        rows: &Chunk,
        descr: ColumnDescPtr,
        props: &WriterPropertiesPtr,
        settings: &Settings,
    ) -> Encoded {
        match rows.settings.as_deref() {
            None => encode_column_by::<C>(rows, descr, props, |_| settings),
            Some(table) => {
                encode_column_by::<C>(rows, descr, props, |esc| &table[usize::from(esc)])
            }
        }
    }

    /// [`encode_column`] with the settings of each row's ESC given by `settings`.
    ///
    /// Out of line: each column's conversion and encoding is a function of its own, optimised
    /// on its own, not one body of every column's loops.
    #[inline(never)]
    fn encode_column_by<'s, C: Column>(
        rows: &Chunk,
        descr: ColumnDescPtr,
        props: &WriterPropertiesPtr,
        settings: impl Fn(u8) -> &'s Settings + Copy,
    ) -> Encoded {
        let n = rows.len();
        let value = |i: usize| {
            let t = rows.t[i];
            let esc = rows.esc[i];
            C::from_frame(
                (!t.is_nan()).then_some(t),
                esc,
                &rows.frame(i),
                settings(esc),
            )
        };
        if let Some(encoded) = <C::Value as ParquetValue>::encode_whole(value, n, &descr, props) {
            return encoded;
        }
        let block_rows =
            if <C::Value as ParquetValue>::ONE_BATCH && (0..n).all(|i| value(i).is_bare()) {
                n
            } else {
                BLOCK
            };
        type Physical<C> = <<C as hwfoc_records::record::Column>::Value as ParquetValue>::Physical;
        encode_in::<Physical<C>>(block_rows, descr, props, n, |block, levels| {
            // A receive time where there is one (NaN in the chunk where not).
            let (t, esc) = (&rows.t[block.clone()], &rows.esc[block.clone()]);
            let rows_in = t.iter().zip(esc);
            match rows.frames(block) {
                // HW-FOC frames (nearly every block of a large file): each frame's protocol
                // known here, its values read by field without a match on the protocol per
                // value.
                Frames::HwFoc(frames) => {
                    let values = rows_in.zip(frames).map(|((&t, &esc), frame)| {
                        let frame = Data::HwFoc(*frame);
                        C::from_frame((!t.is_nan()).then_some(t), esc, &frame, settings(esc))
                    });
                    <C::Value as ParquetValue>::fill(values, levels);
                }
                Frames::Any(frames) => {
                    let values = rows_in.zip(frames).map(|((&t, &esc), frame)| {
                        C::from_frame((!t.is_nan()).then_some(t), esc, frame, settings(esc))
                    });
                    <C::Value as ParquetValue>::fill(values, levels);
                }
            }
        })
    }

    impl Encoder {
        /// An encoder for `settings`.
        fn new(settings: Settings) -> Encoder {
            Encoder {
                settings,
                order: cost_order(),
            }
        }

        /// Converts and encodes column `index` (in schema order) of `rows` into memory.
        fn encode(
            &self,
            index: usize,
            rows: &Chunk,
            descr: &SchemaDescriptor,
            props: &WriterPropertiesPtr,
        ) -> Encoded {
            let mut column = EncodeColumn {
                index,
                rows,
                descr,
                props,
                settings: &self.settings,
                encoded: None,
            };
            visit(&mut column);
            column
                .encoded
                .unwrap_or_else(|| Err(ParquetError::General(format!("no column {index}"))))
        }

        /// Converts, encodes and compresses the columns of `rows` in memory, by this thread and
        /// a helper, each taking the next column not yet taken (on two cores, the decoding
        /// thread leaves time to spare). `meanwhile` runs on this thread first, while the
        /// helper starts on the columns: writing the previous row group to the file overlaps
        /// with encoding this one. Returns the column chunks in schema order, and what
        /// `meanwhile` returned.
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
                while let Some(&index) = self.order.get(next.fetch_add(1, Ordering::Relaxed)) {
                    done.push((index, self.encode(index, rows, descr, props)));
                }
                done
            };
            let (mut chunks, other) = std::thread::scope(|s| {
                let helper = s.spawn(work);
                let other = meanwhile();
                let mut mine = work();
                // A helper that panicked has encoded nothing more: its columns are missing
                // below.
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

    /// Rows converted at a time: their values are still in the processor's first-level cache
    /// when the column writer copies them.
    const BLOCK: usize = 4096;

    /// A block's values (nulls left out) and, for a column that has them, its definition and
    /// repetition levels.
    pub struct Levels<T> {
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

        /// Adds the level pairs (`def`, 0) of `rows` empty lists (`def`: the list's level of
        /// an empty list).
        fn push_empty(&mut self, rows: usize, def: i16) {
            self.def.resize(self.def.len() + rows, def);
            self.rep.resize(self.rep.len() + rows, 0);
        }
    }

    /// Encodes one column chunk of `rows` rows into memory, `block_rows` rows at a time:
    /// `fill` appends the values, and the levels if the column has them, of a block of rows
    /// to the empty buffers it is given.
    ///
    /// A nullable column (not a list) whose first block has every value is encoded as if
    /// it were required, its definition levels added to each page as one run
    /// ([`encode_present`]), until a block has a null: then by the column writer, levels and
    /// all, from the start.
    fn encode_in<T: ParquetType>(
        block_rows: usize,
        descr: ColumnDescPtr,
        props: &WriterPropertiesPtr,
        rows: usize,
        fill: impl Fn(Range<usize>, &mut Levels<T::T>),
    ) -> Encoded {
        if descr.max_def_level() == 1
            && descr.max_rep_level() == 0
            && rows > 0
            && let Some(encoded) = encode_present::<T>(block_rows, &descr, props, rows, &fill)?
        {
            return Ok(encoded);
        }
        encode_levels::<T>(block_rows, descr, props, rows, fill)
    }

    /// [`encode_in`] by the column writer, levels and all.
    fn encode_levels<T: ParquetType>(
        block_rows: usize,
        descr: ColumnDescPtr,
        props: &WriterPropertiesPtr,
        rows: usize,
        fill: impl Fn(Range<usize>, &mut Levels<T::T>),
    ) -> Encoded {
        let nullable = descr.max_def_level() > 0;
        let repeated = descr.max_rep_level() > 0;
        let block_rows = block_rows.max(1);
        let mut buf = TrackedWrite::new(Vec::new());
        let close = {
            let pages = SerializedPageWriter::new(&mut buf);
            let mut writer = get_typed_column_writer::<T>(get_column_writer(
                descr,
                props.clone(),
                Box::new(pages),
            ));
            let mut block = Levels {
                values: Vec::with_capacity(block_rows),
                def: Vec::with_capacity(block_rows),
                rep: Vec::with_capacity(block_rows),
            };
            let mut start = 0;
            while start < rows {
                let end = rows.min(start + block_rows);
                block.values.clear();
                block.def.clear();
                block.rep.clear();
                fill(start..end, &mut block);
                writer.write_batch(
                    &block.values,
                    nullable.then_some(&block.def[..]),
                    repeated.then_some(&block.rep[..]),
                )?;
                start = end;
            }
            writer.close()?
        };
        Ok((Bytes::from(buf.into_inner()?), close))
    }

    /// The chunk of a nullable column (not a list) whose every value is there, byte for byte
    /// as the column writer makes it, or `None` at the first block that has a null (or if the
    /// first block has none at all).
    ///
    /// The column writer takes definition levels only as a slice of one level per row, which
    /// it encodes, and counts into its histogram, row by row: for the 15 nullable columns
    /// that are there in every row of a HW-FOC frame, that was about a tenth of the export's
    /// CPU time (0.3-0.8 s of 5.2-6.0 s of user time on the 2 GiB benchmark input). (Its own run-length path, `LevelDataRef::Uniform`, is open only to the
    /// crate's Arrow writer, which hands it the values by index, a copy of each.) So the
    /// values go to a column writer of the same column declared required, which writes no
    /// levels, through a page writer ([`AddLevels`]) that puts the run of definition levels
    /// 1 in front of each data page's values as the column writer would; the metadata are
    /// then the required column's (whose sizes are those of the pages written, levels
    /// included) with the nullable column's descriptor and the histogram of definition levels
    /// (no null, every value defined).
    ///
    /// The column writer stores a data page compressed where its compressed values are
    /// smaller than the page's levels and values together (times a threshold, 1 here): a
    /// page that the required column stores compressed is compressed with levels too, but
    /// one that it stores as it is might have been compressed with the levels' few bytes
    /// more, and the compressed size is not known here; such a chunk (one of a few rows,
    /// which LZ4 does not shrink; none on the benchmark input) is encoded again by the column
    /// writer, levels and all.
    fn encode_present<T: ParquetType>(
        block_rows: usize,
        descr: &ColumnDescPtr,
        props: &WriterPropertiesPtr,
        rows: usize,
        fill: &impl Fn(Range<usize>, &mut Levels<T::T>),
    ) -> Result<Option<EncodedColumn>, ParquetError> {
        let block_rows = block_rows.max(1);
        let mut buf = TrackedWrite::new(Vec::new());
        let mut pages = Vec::new();
        let required = {
            let page_writer = AddLevels {
                pages: SerializedPageWriter::new(&mut buf),
                written: &mut pages,
                compressing: props.compression(descr.path()) != Compression::UNCOMPRESSED,
            };
            let mut writer = get_typed_column_writer::<T>(get_column_writer(
                required_twin(descr)?,
                props.clone(),
                Box::new(page_writer),
            ));
            let mut block = Levels {
                values: Vec::with_capacity(block_rows),
                def: Vec::with_capacity(block_rows),
                rep: Vec::new(),
            };
            let mut start = 0;
            while start < rows {
                let end = rows.min(start + block_rows);
                block.values.clear();
                block.def.clear();
                fill(start..end, &mut block);
                if block.values.len() != end - start {
                    return Ok(None);
                }
                writer.write_batch(&block.values, None, None)?;
                start = end;
            }
            writer.close()?
        };
        if pages.iter().any(|p| p.undecided) {
            return Ok(None);
        }
        let meta = &required.metadata;
        let mut builder = ColumnChunkMetaData::builder(descr.clone())
            .set_compression(meta.compression())
            .set_encodings_mask(*meta.encodings_mask())
            .set_total_compressed_size(meta.compressed_size())
            .set_total_uncompressed_size(meta.uncompressed_size())
            .set_num_values(meta.num_values())
            .set_data_page_offset(meta.data_page_offset())
            .set_dictionary_page_offset(meta.dictionary_page_offset())
            .set_unencoded_byte_array_data_bytes(meta.unencoded_byte_array_data_bytes())
            .set_repetition_level_histogram(None)
            .set_definition_level_histogram(Some(LevelHistogram::from(vec![0, meta.num_values()])));
        if let Some(stats) = meta.page_encoding_stats() {
            builder = builder.set_page_encoding_stats(stats.clone());
        }
        if let Some(stats) = meta.statistics() {
            builder = builder.set_statistics(stats.clone());
        }
        let offset_index = required.offset_index.as_ref().map(|_| {
            let mut index = OffsetIndexBuilder::new();
            for page in &pages {
                index.append_offset_and_size(page.offset as i64, page.size as i32);
                index.append_row_count(i64::from(page.rows));
            }
            index.build()
        });
        let close = ColumnCloseResult {
            bytes_written: buf.bytes_written() as u64,
            rows_written: required.rows_written,
            metadata: builder.build()?,
            bloom_filter: required.bloom_filter,
            column_index: required.column_index,
            offset_index,
        };
        Ok(Some((Bytes::from(buf.into_inner()?), close)))
    }

    /// The column `descr` (a nullable one) declared required: the same name, path and types.
    fn required_twin(descr: &ColumnDescPtr) -> Result<ColumnDescPtr, ParquetError> {
        let info = descr.self_type().get_basic_info();
        let twin = Type::primitive_type_builder(descr.name(), descr.physical_type())
            .with_repetition(Repetition::REQUIRED)
            .with_converted_type(descr.converted_type())
            .with_logical_type(descr.logical_type_ref().cloned())
            .with_length(descr.type_length())
            .with_precision(descr.type_precision())
            .with_scale(descr.type_scale())
            .with_id(info.has_id().then(|| info.id()))
            .build()?;
        Ok(Arc::new(ColumnDescriptor::new(
            Arc::new(twin),
            0,
            0,
            descr.path().clone(),
        )))
    }

    /// A data page as written by [`AddLevels`]: its offset and size in the column chunk (header
    /// included), its rows, and whether it is stored as it is where the column writer might
    /// have compressed it (see [`encode_present`]).
    struct WrittenPage {
        offset: u64,
        size: usize,
        rows: u32,
        undecided: bool,
    }

    /// The page writer of [`encode_present`]: puts in front of each data page's values the
    /// definition levels of its rows, all 1 (every value defined), as the column writer's
    /// level encoder writes them (`LevelEncoder::v2_streaming` of maximum level 1: the
    /// RLE/bit-packing hybrid at bit width 1, without a length prefix in a page of format 2).
    struct AddLevels<'a, 'b> {
        pages: SerializedPageWriter<'a, Vec<u8>>,
        written: &'b mut Vec<WrittenPage>,
        /// Whether the column is compressed.
        compressing: bool,
    }

    impl PageWriter for AddLevels<'_, '_> {
        fn write_page(&mut self, page: CompressedPage) -> Result<PageWriteSpec, ParquetError> {
            let uncompressed = page.uncompressed_size();
            let Page::DataPageV2 {
                buf,
                num_values,
                encoding,
                num_nulls: 0,
                num_rows,
                def_levels_byte_len: 0,
                rep_levels_byte_len: 0,
                is_compressed,
                statistics,
            } = page.compressed_page().clone()
            else {
                return Err(ParquetError::General(
                    "a page of a required column other than a data page of format 2".to_string(),
                ));
            };
            let mut levels = level_run(1, num_values as usize);
            let added = levels.len();
            levels.extend_from_slice(&buf);
            let page = Page::DataPageV2 {
                buf: Bytes::from(levels),
                num_values,
                encoding,
                num_nulls: 0,
                num_rows,
                def_levels_byte_len: added as u32,
                rep_levels_byte_len: 0,
                is_compressed,
                statistics,
            };
            let spec = self
                .pages
                .write_page(CompressedPage::new(page, uncompressed + added))?;
            self.written.push(WrittenPage {
                offset: spec.offset,
                size: spec.compressed_size,
                rows: num_rows,
                undecided: self.compressing && !is_compressed,
            });
            Ok(spec)
        }

        fn close(&mut self) -> Result<(), ParquetError> {
            self.pages.close()
        }
    }

    /// `count` levels `level` (0 or 1) at bit width 1 as the parquet crate's `RleEncoder`
    /// writes them: one RLE run (its length shifted left by one as a ULEB128 varint, then the
    /// level in a byte), for any count (it ends a run of fewer than 8 equal values as a run).
    fn level_run(level: u8, count: usize) -> Vec<u8> {
        let mut bytes = Vec::with_capacity(6);
        push_varint(&mut bytes, (count as u64) << 1);
        bytes.push(level);
        bytes
    }

    /// Appends `value` as a ULEB128 varint.
    fn push_varint(bytes: &mut Vec<u8>, mut value: u64) {
        while value >= 0x80 {
            bytes.push((value as u8 & 0x7F) | 0x80);
            value >>= 7;
        }
        bytes.push(value as u8);
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

    /// Writes the rows received on `rx` as one Parquet file, a row group per message, and
    /// returns them on `spare` for reuse. At the end message, or when the sender goes away,
    /// the file is closed properly: footer and metadata, so it is readable.
    pub(in crate::write) fn write(
        sink: Sink,
        provenance: &Provenance,
        rx: Receiver<ToWriter>,
        spare: SyncSender<Chunk>,
    ) -> Result<(), WriteError> {
        let schema = schema();
        let name = sink.name;
        let fail = |e| write_error(&name, e);
        let parquet_schema = ArrowSchemaConverter::new().convert(&schema).map_err(fail)?;
        let mut metadata: Vec<KeyValue> = provenance
            .key_values()
            .into_iter()
            .map(|(key, value)| KeyValue::new(key, value))
            .collect();
        let props = Arc::new(properties(&parquet_schema, metadata.clone()));
        let mut writer = SerializedFileWriter::new(
            HoldFooter::new(sink.writer),
            parquet_schema.root_schema_ptr(),
            props.clone(),
        )
        .map_err(fail)?;
        let encoder = Encoder::new(provenance.settings);
        // The row group encoded last, written to the file while the next one is encoded.
        let mut previous: Option<Vec<EncodedColumn>> = None;
        for msg in rx {
            match msg {
                ToWriter::Rows(rows) => {
                    let (encoded, written) =
                        encoder.encode_row_group(&rows, &parquet_schema, &props, || {
                            previous
                                .take()
                                .map_or(Ok(()), |columns| append_row_group(&mut writer, columns))
                        });
                    written.map_err(fail)?;
                    previous = Some(encoded.map_err(fail)?);
                    // The command may have stopped listening; the rows are then dropped.
                    let _ = spare.try_send(rows);
                }
                ToWriter::End(at_end) => {
                    for (key, value) in at_end {
                        let kv = KeyValue::new(key, value);
                        metadata.push(kv.clone());
                        writer.append_key_value_metadata(kv);
                    }
                    break;
                }
            }
        }
        if let Some(columns) = previous {
            append_row_group(&mut writer, columns).map_err(fail)?;
        }
        if let Some(kv) = encoded_schema(&metadata) {
            writer.append_key_value_metadata(kv);
        }
        // The footer is held back, its float columns' order made the one every reader knows,
        // then written.
        writer.inner_mut().hold();
        let mut file = writer.into_inner().map_err(fail)?;
        file.release(parquet_schema.num_columns())
            .map_err(|e| fail(ParquetError::External(Box::new(e))))?;
        Ok(())
    }

    /// The file's writer, which holds back what is written after [`HoldFooter::hold`] (the
    /// footer) so that [`type_defined_float_order`] can rewrite it before it is written.
    struct HoldFooter<W> {
        inner: W,
        held: Option<Vec<u8>>,
    }

    impl<W: io::Write> HoldFooter<W> {
        fn new(inner: W) -> Self {
            HoldFooter { inner, held: None }
        }

        /// Holds back everything written from now on.
        fn hold(&mut self) {
            self.held.get_or_insert_with(Vec::new);
        }

        /// Writes what was held back, the footer's column orders rewritten, and flushes.
        fn release(&mut self, leaves: usize) -> io::Result<()> {
            if let Some(mut tail) = self.held.take() {
                // A footer of another layout (a later parquet crate) is written as it is: its
                // float statistics are then read by DuckDB and polars, not by pyarrow.
                type_defined_float_order(&mut tail, leaves);
                self.inner.write_all(&tail)?;
            }
            self.inner.flush()
        }
    }

    impl<W: io::Write> io::Write for HoldFooter<W> {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            match &mut self.held {
                Some(held) => {
                    held.extend_from_slice(buf);
                    Ok(buf.len())
                }
                None => self.inner.write(buf),
            }
        }

        fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
            match &mut self.held {
                Some(held) => {
                    held.extend_from_slice(buf);
                    Ok(())
                }
                None => self.inner.write_all(buf),
            }
        }

        fn flush(&mut self) -> io::Result<()> {
            match self.held {
                Some(_) => Ok(()),
                None => self.inner.flush(),
            }
        }
    }

    /// Thrift compact protocol: the header of field 7 after field 6 (a delta of 1), a list.
    const COLUMN_ORDERS_FIELD: u8 = 0x19;
    /// Thrift compact protocol: the element type of a list of structs.
    const STRUCT_ELEMENTS: u8 = 0x0C;
    /// A `ColumnOrder` union with its field 1 (`TYPE_DEFINED_ORDER`, an empty struct).
    const TYPE_DEFINED_ORDER: u8 = 0x1C;
    /// A `ColumnOrder` union with its field 2 (`IEEE_754_TOTAL_ORDER`, an empty struct).
    const IEEE_754_TOTAL_ORDER: u8 = 0x2C;

    /// Rewrites the column orders of the footer at the end of `tail` (which ends with the
    /// footer, its length and `PAR1`) from `IEEE_754_TOTAL_ORDER` to `TYPE_DEFINED_ORDER`, and
    /// returns whether it did.
    ///
    /// The parquet crate marks float and double columns with the total order of IEEE 754 (its
    /// statistics are computed with `total_cmp`), an order added to the format in 2025 that
    /// pyarrow does not know yet: it then ignores the minimum and maximum of every float
    /// column. The orders differ only for NaN (the total order's maximum may be a NaN, the
    /// type-defined order's readers ignore a NaN maximum or minimum) and for -0/+0 (which
    /// readers of the type-defined order treat as equal); the records hold no NaN (a value
    /// that is not there is a null), so the statistics are the same under either.
    ///
    /// The column orders are the footer's last field (no encryption): `0x19` (field 7, a list),
    /// the list's header, one 3-byte union per leaf column, then the footer's stop byte. Any
    /// other layout is left as it is (and `false` returned).
    pub fn type_defined_float_order(tail: &mut [u8], leaves: usize) -> bool {
        let Some(footer_end) = tail.len().checked_sub(8) else {
            return false;
        };
        if &tail[footer_end + 4..] != b"PAR1" {
            return false;
        }
        let len = u32::from_le_bytes(
            tail[footer_end..footer_end + 4]
                .try_into()
                .expect("4 bytes"),
        );
        let Some(footer_start) = footer_end.checked_sub(len as usize) else {
            return false;
        };
        let footer = &mut tail[footer_start..footer_end];
        // The list's header: the size in the high nibble below 15, else 0xF and a varint.
        let mut header = vec![COLUMN_ORDERS_FIELD];
        if leaves < 15 {
            header.push(((leaves as u8) << 4) | STRUCT_ELEMENTS);
        } else {
            header.push(0xF0 | STRUCT_ELEMENTS);
            let mut n = leaves;
            while n >= 0x80 {
                header.push((n as u8 & 0x7F) | 0x80);
                n >>= 7;
            }
            header.push(n as u8);
        }
        let Some(start) = footer.len().checked_sub(1 + 3 * leaves + header.len()) else {
            return false;
        };
        let (head, orders) = footer[start..].split_at_mut(header.len());
        if head != header.as_slice() || orders.last() != Some(&0) {
            return false;
        }
        let unions = &mut orders[..3 * leaves];
        let known = unions
            .chunks(3)
            .all(|u| matches!(u, [TYPE_DEFINED_ORDER | IEEE_754_TOTAL_ORDER, 0, 0]));
        if !known {
            return false;
        }
        for union in unions.chunks_mut(3) {
            union[0] = TYPE_DEFINED_ORDER;
        }
        true
    }

    #[cfg(test)]
    mod tests {
        use super::*;
        use parquet::basic::Type as PhysicalType;

        /// Every name the per-column choices give is a column's.
        #[test]
        fn the_choices_name_only_columns() {
            let lists: [(&str, &[&str]); 4] = [
                ("DELTA", &DELTA),
                ("SPLIT", &SPLIT),
                ("DICTIONARY", &DICTIONARY),
                ("BY_COST", &BY_COST),
            ];
            for (list, names) in lists {
                for name in names {
                    assert!(
                        COLUMNS.contains(name),
                        "{list} names {name}: no such column"
                    );
                }
                let mut unique = names.to_vec();
                unique.sort_unstable();
                unique.dedup();
                assert_eq!(unique.len(), names.len(), "{list} names a column twice");
            }
        }

        /// A file of `columns` float, double and integer columns with statistics, written by
        /// the parquet crate: its bytes.
        fn small_file(columns: usize) -> Vec<u8> {
            use parquet::schema::types::Type;
            let fields = (0..columns)
                .map(|i| {
                    let physical = [
                        PhysicalType::FLOAT,
                        PhysicalType::DOUBLE,
                        PhysicalType::INT32,
                    ];
                    let t = Type::primitive_type_builder(&format!("c{i}"), physical[i % 3])
                        .with_repetition(parquet::basic::Repetition::REQUIRED)
                        .build()
                        .unwrap();
                    Arc::new(t)
                })
                .collect();
            let schema = Type::group_type_builder("schema")
                .with_fields(fields)
                .build()
                .unwrap();
            let props = WriterProperties::builder()
                .set_statistics_enabled(EnabledStatistics::Chunk)
                .build();
            let mut writer =
                SerializedFileWriter::new(Vec::new(), Arc::new(schema), Arc::new(props)).unwrap();
            let mut rg = writer.next_row_group().unwrap();
            while let Some(mut column) = rg.next_column().unwrap() {
                use parquet::column::writer::ColumnWriter;
                match column.untyped() {
                    ColumnWriter::FloatColumnWriter(w) => {
                        w.write_batch(&[-1.5, 0.25, 7.0], None, None).unwrap();
                    }
                    ColumnWriter::DoubleColumnWriter(w) => {
                        w.write_batch(&[-3.0, 1e9, 2.5], None, None).unwrap();
                    }
                    ColumnWriter::Int32ColumnWriter(w) => {
                        w.write_batch(&[5, -2, 9], None, None).unwrap();
                    }
                    _ => unreachable!(),
                }
                column.close().unwrap();
            }
            rg.close().unwrap();
            writer.into_inner().unwrap()
        }

        /// The column orders and statistics of a file as the parquet crate reads them.
        fn orders_and_ranges(
            bytes: Vec<u8>,
        ) -> (Vec<parquet::basic::ColumnOrder>, Vec<(String, String)>) {
            use parquet::file::reader::{FileReader, SerializedFileReader};
            let reader = SerializedFileReader::new(Bytes::from(bytes)).unwrap();
            let meta = reader.metadata();
            let orders = meta.file_metadata().column_orders().unwrap().clone();
            let ranges = meta
                .row_group(0)
                .columns()
                .iter()
                .map(|c| {
                    let s = c.statistics().unwrap();
                    (
                        format!("{:?}", s.min_bytes_opt()),
                        format!("{:?}", s.max_bytes_opt()),
                    )
                })
                .collect();
            (orders, ranges)
        }

        /// The float columns' total order becomes the type-defined order (with a list header
        /// of either form: below 15 columns and above), the statistics stay as they were, and
        /// the file stays readable.
        #[test]
        fn float_columns_get_the_type_defined_order() {
            use parquet::basic::{ColumnOrder, SortOrder};
            for columns in [3, 14, 15, 200] {
                let mut bytes = small_file(columns);
                let (before, ranges) = orders_and_ranges(bytes.clone());
                assert!(before.contains(&ColumnOrder::IEEE_754_TOTAL_ORDER));
                assert!(
                    type_defined_float_order(&mut bytes, columns),
                    "{columns} columns"
                );
                let (after, patched_ranges) = orders_and_ranges(bytes);
                assert_eq!(patched_ranges, ranges);
                for (i, order) in after.iter().enumerate() {
                    // Floats compared as numbers, integers signed: the type-defined order.
                    assert_eq!(
                        *order,
                        ColumnOrder::TYPE_DEFINED_ORDER(SortOrder::SIGNED),
                        "column {i}"
                    );
                }
            }
        }

        /// A tail that is not a footer of the expected layout is left as it is.
        #[test]
        fn an_unknown_footer_is_left_alone() {
            let file = small_file(3);
            // The wrong number of columns, a damaged magic, a truncated tail, an unknown order.
            let mut wrong_count = file.clone();
            assert!(!type_defined_float_order(&mut wrong_count, 4));
            assert_eq!(wrong_count, file);
            let mut magic = file.clone();
            *magic.last_mut().unwrap() = b'X';
            assert!(!type_defined_float_order(&mut magic, 3));
            let mut short = file[file.len() - 6..].to_vec();
            assert!(!type_defined_float_order(&mut short, 3));
            let mut unknown = file.clone();
            let at = unknown.len() - 8 - 1 - 3;
            assert_eq!(unknown[at], TYPE_DEFINED_ORDER);
            unknown[at] = 0x3C;
            let copy = unknown.clone();
            assert!(!type_defined_float_order(&mut unknown, 3));
            assert_eq!(unknown, copy);
        }

        /// What is written before `hold` goes through; what after is held until `release`.
        #[test]
        fn the_footer_is_held_then_written() {
            use std::io::Write;
            let mut w = HoldFooter::new(Vec::new());
            w.write_all(b"data").unwrap();
            w.hold();
            w.write_all(b"tail").unwrap();
            assert_eq!(w.inner, b"data");
            w.release(3).unwrap();
            assert_eq!(w.inner, b"datatail");
        }

        /// The writer's schema and properties.
        fn schema_and_properties() -> (SchemaDescriptor, WriterPropertiesPtr) {
            let descr = ArrowSchemaConverter::new().convert(&schema()).unwrap();
            let props = Arc::new(properties(&descr, Vec::new()));
            (descr, props)
        }

        /// A column chunk as the column writer encodes it, `BLOCK` rows at a time: its bytes
        /// and its metadata as text (`ColumnCloseResult` has no `PartialEq`).
        fn by_the_column_writer<T: ParquetType>(
            descr: ColumnDescPtr,
            props: &WriterPropertiesPtr,
            rows: usize,
            fill: impl Fn(Range<usize>, &mut Levels<T::T>),
        ) -> (Bytes, String) {
            let (bytes, close) = encode_levels::<T>(BLOCK, descr, props, rows, fill).unwrap();
            (bytes, format!("{close:?}"))
        }

        /// The protocol column of a row group of one protocol is byte for byte what the column
        /// writer makes of it, metadata included; of two protocols, the column writer encodes
        /// it.
        #[test]
        fn one_protocol_is_encoded_as_the_column_writer_would() {
            let (descr, props) = schema_and_properties();
            let column = descr.column(index_of("protocol").unwrap());
            for protocol in [Protocol::HwFoc, Protocol::DataLink] {
                for rows in [
                    8,
                    9,
                    127,
                    128,
                    4096,
                    16_383,
                    16_384,
                    super::super::ROW_GROUP_ROWS + 4321,
                ] {
                    let (bytes, close) =
                        Protocol::encode_whole(|_| protocol, rows, &column, &props)
                            .expect("one protocol")
                            .unwrap();
                    let expected = by_the_column_writer::<ByteArrayType>(
                        column.clone(),
                        &props,
                        rows,
                        |block, levels| {
                            levels.values.extend(block.map(|_| protocol_name(protocol)))
                        },
                    );
                    assert_eq!(bytes, expected.0, "{protocol:?}, {rows} rows");
                    assert_eq!(
                        format!("{close:?}"),
                        expected.1,
                        "{protocol:?}, {rows} rows"
                    );
                }
            }
            let mixed = |i: usize| [Protocol::HwFoc, Protocol::DataLink][usize::from(i == 500)];
            assert!(Protocol::encode_whole(mixed, 1000, &column, &props).is_none());
            assert!(Protocol::encode_whole(|_| Protocol::HwFoc, 0, &column, &props).is_none());
        }

        /// A nullable column's chunk with every value there is byte for byte what the column
        /// writer makes of it, metadata included, whatever its type and encoding, in one page or
        /// several (a page holds up to 1 MB of values), of fewer rows than a run of levels or
        /// more; with a null after the first block, or none there at all, the column writer
        /// encodes it.
        #[test]
        fn a_column_with_every_value_is_encoded_as_the_column_writer_would() {
            fn check<T: ParquetType>(
                column: &ColumnDescPtr,
                props: &WriterPropertiesPtr,
                value: impl Fn(usize) -> T::T + Copy,
            ) {
                let name = column.path().string();
                for rows in [1, 7, 8, 9, 4096, 4097, 100_000, 300_000] {
                    let every = |_: usize| true;
                    let later_null = |i: usize| i != BLOCK + 3;
                    let none = |_: usize| false;
                    for present in [&every as &dyn Fn(usize) -> bool, &later_null, &none] {
                        let fill = |block: Range<usize>, levels: &mut Levels<T::T>| {
                            for i in block {
                                levels.def.push(i16::from(present(i)));
                                if present(i) {
                                    levels.values.push(value(i));
                                }
                            }
                        };
                        let (bytes, close) =
                            encode_in::<T>(BLOCK, column.clone(), props, rows, fill).unwrap();
                        let expected = by_the_column_writer::<T>(column.clone(), props, rows, fill);
                        assert!(
                            bytes == expected.0,
                            "{name}, {rows} rows: bytes differ: {bytes:?} {:?}",
                            expected.0
                        );
                        assert_eq!(format!("{close:?}"), expected.1, "{name}, {rows} rows");
                    }
                }
            }
            let (descr, props) = schema_and_properties();
            let mut checked = Vec::new();
            for column in descr.columns() {
                if column.max_def_level() != 1 || column.max_rep_level() != 0 {
                    continue;
                }
                match column.physical_type() {
                    PhysicalType::FLOAT => {
                        check::<FloatType>(column, &props, |i| (i % 1000) as f32 * 0.37 - 20.0)
                    }
                    PhysicalType::DOUBLE => {
                        check::<DoubleType>(column, &props, |i| 1.7e9 + i as f64 / 7.0)
                    }
                    // Unsigned columns among them: values above i32::MAX as negative numbers.
                    PhysicalType::INT32 => check::<Int32Type>(column, &props, |i| {
                        (i as u32).wrapping_mul(2_654_435_761) as i32
                    }),
                    // Microseconds of the 2020s, 7 ms apart.
                    PhysicalType::INT64 => check::<Int64Type>(column, &props, |i| {
                        1_795_847_934_682_325 + 7_000 * i as i64
                    }),
                    other => panic!("{}: no test values of {other}", column.path()),
                }
                checked.push(column.name().to_string());
            }
            assert!(checked.len() >= 15, "{checked:?}");
        }

        /// Every column is encoded, once.
        #[test]
        fn the_cost_order_names_every_column_once() {
            let mut order = cost_order();
            let named: Vec<&str> = order[..BY_COST.len()].iter().map(|&i| COLUMNS[i]).collect();
            assert_eq!(named, BY_COST);
            order.sort_unstable();
            let leaves = ArrowSchemaConverter::new()
                .convert(&schema())
                .unwrap()
                .num_columns();
            assert_eq!(order, (0..leaves).collect::<Vec<_>>());
        }

        /// The Parquet leaf columns of the Arrow schema, one per column in order, have the
        /// physical types and levels that the value types fill in.
        #[test]
        fn parquet_schema_matches_the_columns_written() {
            struct Expected(Vec<(String, PhysicalType, i16, i16)>);
            impl Visitor for Expected {
                fn column<C: Column>(&mut self) {
                    type V<C> = <C as hwfoc_records::record::Column>::Value;
                    self.0.push((
                        C::NAME.to_string(),
                        <<V<C> as ParquetValue>::Physical as ParquetType>::get_physical_type(),
                        <V<C> as ParquetValue>::MAX_DEF,
                        <V<C> as ParquetValue>::MAX_REP,
                    ));
                }
            }
            let mut expected = Expected(Vec::new());
            visit(&mut expected);
            let descr = ArrowSchemaConverter::new().convert(&schema()).unwrap();
            let leaves: Vec<(String, PhysicalType, i16, i16)> = descr
                .columns()
                .iter()
                .map(|c| {
                    (
                        c.path().parts()[0].clone(),
                        c.physical_type(),
                        c.max_def_level(),
                        c.max_rep_level(),
                    )
                })
                .collect();
            assert_eq!(leaves, expected.0);
            // The list's leaf, as the dictionary setting names it.
            let faults = index_of("faults").unwrap();
            assert_eq!(descr.column(faults).path().string(), "faults.list.item");
        }
    }
}
