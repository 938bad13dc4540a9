//! The text encodings of the records: JSON Lines and CSV.
//!
//! Numbers are written as `itoa`/`ryu` write them (the shortest text that reads back to the same
//! value, as `serde_json` writes them), with no allocation per record; see [`TextEncoder`]. A
//! row is the columns of the table in order, each written as its value type says
//! ([`TextValue`]): through [`columns::visit`], with no dispatch per value.

use std::marker::PhantomData;

use hwfoc::telemetry::Data;
use hwfoc::{Fault, Protocol, Status};

use super::Record;
use super::column::{Column, FaultList, UtcTime, Visitor};
use super::columns::{self, COUNT};

/// Longest text of one record: the keys (about 200 bytes), thirteen numbers of at most 24
/// characters and sixteen fault names, with room to spare for the fixed-size copies below
/// (checked by a test against the columns' [`TextValue::TEXT_MAX`]).
const ROW_MAX: usize = 2048;

/// Entries of each number cache (a power of two).
const CACHE_BITS: u32 = 12;

/// Writes records as JSON Lines or CSV text.
///
/// Numbers are written as `itoa` and `ryu` write them (the shortest text that reads back to the
/// same value, as `serde_json` writes it). A record is assembled in a fixed buffer with
/// fixed-size copies, then appended to the output in one piece.
///
/// An encoder made with [`TextEncoder::cached`] also keeps the text of the `f32` columns, keyed
/// by the raw integer each was converted from ([`TextEncoder::json_frame`],
/// [`TextEncoder::csv_frame`]): telemetry values recur and drift slowly, so the text is almost
/// always at hand, in a nearby cache line, for a few nanoseconds where `ryu` costs twenty or
/// more. The text is the same either way.
pub struct TextEncoder {
    row: [u8; ROW_MAX],
    pos: usize,
    float: ryu::Buffer,
    /// A cache per column, by column index (empty for the columns without text key).
    cache: Option<Box<[FloatCache; COUNT]>>,
}

/// A direct-mapped cache from a raw integer (the low bits index it) to the text of the value
/// converted from it. Neighbouring raw values share cache lines.
#[derive(Default)]
struct FloatCache {
    entries: Vec<CacheEntry>,
}

#[derive(Clone, Copy)]
struct CacheEntry {
    key: u32,
    /// 0 for an empty entry (every text is at least one character long).
    len: u8,
    text: [u8; 27],
}

impl FloatCache {
    fn new() -> FloatCache {
        FloatCache {
            entries: vec![
                CacheEntry {
                    key: 0,
                    len: 0,
                    text: [0; 27],
                };
                1 << CACHE_BITS
            ],
        }
    }
}

impl Default for TextEncoder {
    fn default() -> Self {
        TextEncoder::new()
    }
}

/// A text format: what differs between JSON and CSV.
pub trait Format {
    /// JSON (keys, lists in brackets) rather than CSV (commas, lists joined by `|`).
    const JSON: bool;
    /// The text of a null.
    const NULL: &'static [u8];
}

/// JSON Lines.
pub enum Json {}

/// CSV.
pub enum Csv {}

impl Format for Json {
    const JSON: bool = true;
    const NULL: &'static [u8] = b"null";
}

impl Format for Csv {
    const JSON: bool = false;
    const NULL: &'static [u8] = b"";
}

/// How a value type is written as text, in JSON and in CSV.
pub trait TextValue: Copy {
    /// Bytes a value may take in the row buffer while it is written (fixed-size copies
    /// included).
    const TEXT_MAX: usize;
    /// Whether text formats write values of this type (not [`UtcTime`]: see [`Column::TEXT`]).
    const WRITTEN: bool = true;

    /// Appends the value's text in format `F`; `cache`: the column's index and the raw integer
    /// the value was converted from, for a column with a text key.
    fn text<F: Format>(self, e: &mut TextEncoder, cache: Option<(usize, u32)>);
}

impl TextValue for f32 {
    const TEXT_MAX: usize = 27;

    #[inline(always)]
    fn text<F: Format>(self, e: &mut TextEncoder, cache: Option<(usize, u32)>) {
        e.f32(self, cache);
    }
}

impl TextValue for f64 {
    const TEXT_MAX: usize = 24;

    #[inline(always)]
    fn text<F: Format>(self, e: &mut TextEncoder, _: Option<(usize, u32)>) {
        e.f64(self);
    }
}

impl<T: TextValue> TextValue for Option<T> {
    const TEXT_MAX: usize = if T::TEXT_MAX > 4 { T::TEXT_MAX } else { 4 };
    const WRITTEN: bool = T::WRITTEN;

    #[inline(always)]
    fn text<F: Format>(self, e: &mut TextEncoder, cache: Option<(usize, u32)>) {
        match self {
            Some(v) => v.text::<F>(e, cache),
            None => e.lit(F::NULL),
        }
    }
}

macro_rules! unsigned_text {
    ($($t:ty),*) => {$(
        impl TextValue for $t {
            const TEXT_MAX: usize = 10;

            #[inline(always)]
            fn text<F: Format>(self, e: &mut TextEncoder, _: Option<(usize, u32)>) {
                e.uint(u32::from(self));
            }
        }
    )*};
}

unsigned_text!(u8, u16, u32);

/// Not written: JSON Lines and CSV carry the instant as `t_s` (and CSV's `--time iso`).
impl TextValue for UtcTime {
    const TEXT_MAX: usize = 0;
    const WRITTEN: bool = false;

    #[inline(always)]
    fn text<F: Format>(self, _: &mut TextEncoder, _: Option<(usize, u32)>) {}
}

impl TextValue for Status {
    const TEXT_MAX: usize = 5;

    #[inline(always)]
    fn text<F: Format>(self, e: &mut TextEncoder, _: Option<(usize, u32)>) {
        e.uint(u32::from(self.0));
    }
}

impl TextValue for Protocol {
    // The longest name, quoted.
    const TEXT_MAX: usize = {
        let mut n = 0;
        let mut i = 0;
        while i < Protocol::ALL.len() {
            if Protocol::ALL[i].name().len() > n {
                n = Protocol::ALL[i].name().len();
            }
            i += 1;
        }
        n + 2
    };

    /// The protocol's name: quoted in JSON (names are plain ASCII: nothing to escape).
    #[inline(always)]
    fn text<F: Format>(self, e: &mut TextEncoder, _: Option<(usize, u32)>) {
        if F::JSON {
            e.lit(b"\"");
            e.lit(self.name().as_bytes());
            e.lit(b"\"");
        } else {
            e.lit(self.name().as_bytes());
        }
    }
}

impl TextValue for FaultList {
    // Every name quoted, with a comma, and the brackets.
    const TEXT_MAX: usize = {
        let mut n = 2;
        let mut i = 0;
        while i < Fault::ALL.len() {
            n += Fault::ALL[i].name().len() + 3;
            i += 1;
        }
        n
    };

    #[inline(always)]
    fn text<F: Format>(self, e: &mut TextEncoder, _: Option<(usize, u32)>) {
        if F::JSON {
            e.lit(b"[");
        }
        if !self.0.is_ok() {
            for (i, name) in self.names().enumerate() {
                if i > 0 {
                    e.lit(if F::JSON { b"," } else { b"|" });
                }
                if F::JSON {
                    // Fault names are plain ASCII identifiers: nothing to escape.
                    e.lit(b"\"");
                    e.lit(name.as_bytes());
                    e.lit(b"\"");
                } else {
                    e.lit(name.as_bytes());
                }
            }
        }
        if F::JSON {
            e.lit(b"]");
        }
    }
}

/// Writes the columns of one record in format `F`: the visitor of [`TextEncoder::row`].
struct Row<'a, F> {
    e: &'a mut TextEncoder,
    record: &'a Record,
    /// The frame the record was converted from, for the caches' keys.
    frame: Option<&'a Data>,
    format: PhantomData<F>,
}

impl<F: Format> Visitor for Row<'_, F> {
    #[inline(always)]
    fn column<C: Column>(&mut self) {
        if !C::TEXT {
            return;
        }
        if F::JSON {
            self.e.lit(C::JSON_KEY.as_bytes());
        } else if C::INDEX > 0 {
            self.e.lit(b",");
        }
        let cache = match self.frame {
            Some(frame) if C::TEXT_CACHED => Some((C::INDEX, C::text_key(frame))),
            _ => None,
        };
        C::from_record(self.record).text::<F>(self.e, cache);
    }
}

/// Whether the number caches, keyed by raw integers, may give the text of `frame`'s values:
/// for HW-FOC and DataLink frames, whose raw integers convert one way under one set of
/// settings.
#[inline(always)]
fn caches_apply(frame: &Data) -> bool {
    matches!(frame.protocol(), Protocol::HwFoc | Protocol::DataLink)
}

/// Marks the columns with a text key: the visitor of [`TextEncoder::cached`].
struct MakeCaches<'a>(&'a mut [FloatCache; COUNT]);

impl Visitor for MakeCaches<'_> {
    fn column<C: Column>(&mut self) {
        if C::TEXT_CACHED {
            self.0[C::INDEX] = FloatCache::new();
        }
    }
}

impl TextEncoder {
    /// An encoder without number caches, cheap to make: for a few records.
    pub fn new() -> TextEncoder {
        TextEncoder {
            row: [0; ROW_MAX],
            pos: 0,
            float: ryu::Buffer::new(),
            cache: None,
        }
    }

    /// An encoder with number caches (about 1 MB), for long runs of records converted under
    /// one set of settings: the caches hold the text of converted values.
    pub fn cached() -> TextEncoder {
        let mut caches: Box<[FloatCache; COUNT]> = Box::default();
        columns::visit(&mut MakeCaches(&mut caches));
        TextEncoder {
            cache: Some(caches),
            ..TextEncoder::new()
        }
    }

    /// Appends `r` as one JSON object and a newline, with exactly the schema's keys in order.
    pub fn json(&mut self, r: &Record, out: &mut Vec<u8>) {
        self.row::<Json>(r, None, out);
    }

    /// Appends `r`, the record of `frame`, as [`TextEncoder::json`] does; a cached encoder
    /// takes the text of numbers from its caches. Every record given to one cached encoder
    /// must be converted under the same settings. (A frame of a protocol whose raw integers
    /// convert otherwise from frame to frame, V4 before and after its info frame, or otherwise
    /// than HW-FOC's, is written without the caches.)
    pub fn json_frame(&mut self, r: &Record, frame: &Data, out: &mut Vec<u8>) {
        if caches_apply(frame) {
            self.row::<Json>(r, Some(frame), out);
        } else {
            self.row::<Json>(r, None, out);
        }
    }

    /// Appends `r` as one CSV row (the columns of [`COLUMNS`](super::COLUMNS)): empty fields
    /// for nulls, faults joined by `|`.
    pub fn csv(&mut self, r: &Record, out: &mut Vec<u8>) {
        self.row::<Csv>(r, None, out);
    }

    /// Appends `r`, the record of `frame`, as [`TextEncoder::csv`] does. A cached encoder takes
    /// the text of numbers from its caches, as [`TextEncoder::json_frame`] does.
    pub fn csv_frame(&mut self, r: &Record, frame: &Data, out: &mut Vec<u8>) {
        if caches_apply(frame) {
            self.row::<Csv>(r, Some(frame), out);
        } else {
            self.row::<Csv>(r, None, out);
        }
    }

    /// Assembles the row of `r` in format `F` and appends it to `out`. Inlined into each
    /// caller, so that whether there is a frame (cache keys) is known at compile time.
    #[inline(always)]
    fn row<F: Format>(&mut self, r: &Record, frame: Option<&Data>, out: &mut Vec<u8>) {
        self.pos = 0;
        columns::visit(&mut Row::<F> {
            e: self,
            record: r,
            frame,
            format: PhantomData,
        });
        if F::JSON {
            // The first key's comma opens the object.
            self.row[0] = b'{';
            self.lit(b"}\n");
        } else {
            self.lit(b"\n");
        }
        out.extend_from_slice(&self.row[..self.pos]);
    }

    #[inline]
    fn lit(&mut self, text: &[u8]) {
        self.row[self.pos..self.pos + text.len()].copy_from_slice(text);
        self.pos += text.len();
    }

    /// Decimal digits of `v`, as `itoa` writes them.
    #[inline]
    fn uint(&mut self, mut v: u32) {
        let mut digits = 1;
        let mut rest = v / 10;
        while rest > 0 {
            digits += 1;
            rest /= 10;
        }
        let end = self.pos + digits;
        for slot in self.row[self.pos..end].iter_mut().rev() {
            *slot = b'0' + (v % 10) as u8;
            v /= 10;
        }
        self.pos = end;
    }

    /// The text of `v`; `cache`: the column whose cache keeps it and the raw integer `v` was
    /// converted from. Finite values only: every value written is computed from integers by
    /// a finite factor.
    #[inline(always)]
    fn f32(&mut self, v: f32, cache: Option<(usize, u32)>) {
        let (Some(caches), Some((column, key))) = (self.cache.as_mut(), cache) else {
            self.f32_uncached(v);
            return;
        };
        let entry = &mut caches[column].entries[key as usize & ((1 << CACHE_BITS) - 1)];
        if entry.len == 0 || entry.key != key {
            let text = self.float.format_finite(v).as_bytes();
            if text.len() > entry.text.len() {
                // Longer than any f32 text ryu writes; handled all the same.
                self.f32_uncached(v);
                return;
            }
            entry.text[..text.len()].copy_from_slice(text);
            entry.len = text.len() as u8;
            entry.key = key;
        }
        // A fixed-size copy (no call to memcpy); only `len` bytes of it count.
        self.row[self.pos..self.pos + 27].copy_from_slice(&entry.text);
        self.pos += usize::from(entry.len);
    }

    #[inline(never)]
    fn f32_uncached(&mut self, v: f32) {
        let text = self.float.format_finite(v).as_bytes();
        self.row[self.pos..self.pos + text.len()].copy_from_slice(text);
        self.pos += text.len();
    }

    fn f64(&mut self, v: f64) {
        let text = self.float.format_finite(v).as_bytes();
        let mut fixed = [0u8; 24];
        fixed[..text.len()].copy_from_slice(text);
        self.row[self.pos..self.pos + 24].copy_from_slice(&fixed);
        self.pos += text.len();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::TEXT_COLUMNS;
    use hwfoc::Settings;
    use hwfoc::foc::DataFrame;

    /// The longest row of the table fits the row buffer, fixed-size copies included.
    #[test]
    fn the_longest_row_fits() {
        struct Longest(usize);
        impl Visitor for Longest {
            fn column<C: Column>(&mut self) {
                self.0 += C::JSON_KEY.len() + <C::Value as TextValue>::TEXT_MAX;
            }
        }
        let mut longest = Longest("}\n".len());
        columns::visit(&mut longest);
        assert!(longest.0 <= ROW_MAX, "{} bytes", longest.0);
        // Every fault set: the longest list.
        let mut e = TextEncoder::new();
        e.pos = 0;
        FaultList(Status(0xFFFF), Protocol::HwFoc).text::<Json>(&mut e, None);
        // Sixteen names and fifteen commas between them: room for one more comma.
        assert_eq!(e.pos + 1, FaultList::TEXT_MAX);
    }

    /// Nulls, numbers and fault lists in JSON and in CSV (docs/RECORD-SCHEMA.md's example line is
    /// in `tests/schema.rs`). Fields are found by name: a new column changes nothing here.
    #[test]
    fn nulls_faults_and_csv() {
        let frame = DataFrame {
            packet: 3,
            mos_adc: 250,
            cap_adc: 10,
            erpm_raw: 700,
            status: Status(0x0041),
            ..Default::default()
        };
        let record = Record::new(
            None,
            2,
            &hwfoc::telemetry::Data::from(frame),
            &Settings::default(),
        );
        let mut json = Vec::new();
        record.write_json(&mut json);
        let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
        assert_eq!(v["t_s"], serde_json::Value::Null);
        assert_eq!(v["mos_temp_c"], serde_json::Value::Null);
        assert_eq!(v["rpm"], 1000.0);
        assert_eq!(
            v["faults"],
            serde_json::json!(["input_voltage_high", "mos_overheat"])
        );
        // serde_json keeps the order of the keys (feature preserve_order): the schema's order.
        let keys: Vec<&str> = v.as_object().unwrap().keys().map(|k| k.as_str()).collect();
        assert_eq!(keys, TEXT_COLUMNS);

        let mut csv = Vec::new();
        Record::write_csv_header(&mut csv);
        TextEncoder::new().csv_frame(&record, &hwfoc::telemetry::Data::from(frame), &mut csv);
        let csv = String::from_utf8(csv).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[0], TEXT_COLUMNS.join(","));
        let fields: Vec<&str> = lines[1].split(',').collect();
        assert_eq!(fields.len(), TEXT_COLUMNS.len());
        let field = |name: &str| fields[TEXT_COLUMNS.iter().position(|&c| c == name).unwrap()];
        for (name, text) in [
            ("t_s", ""),
            ("esc", "2"),
            ("packet", "3"),
            ("throttle_in_pct", "0.0"),
            ("erpm", "7000"),
            ("rpm", "1000.0"),
            ("current_a", "0.0"),
            ("mos_temp_c", ""),
            ("cap_temp_c", ""),
            ("status", "65"),
            ("faults", "input_voltage_high|mos_overheat"),
        ] {
            assert_eq!(field(name), text, "{name}");
        }
    }

    /// A cached encoder writes exactly what an uncached one writes, whatever the values: over
    /// every raw value of each field, in an order that makes the caches hit and miss, under
    /// settings whose conversions give long fractions.
    #[test]
    fn cached_text_is_the_same_text() {
        let settings = Settings::new(100.0, 14, 2.5).unwrap();
        let mut cached = TextEncoder::cached();
        let mut plain = TextEncoder::new();
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let mut x = 0x1234_5678u32;
        for i in 0..200_000u32 {
            // A mix of slowly changing values and random jumps.
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let r = if i % 3 == 0 {
                x
            } else {
                i.wrapping_mul(40_503)
            };
            let word = |shift: u32| (r >> shift) as u16;
            let frame = DataFrame {
                packet: i as u16,
                throttle_in_raw: word(0),
                throttle_out_raw: word(3) % 1100,
                erpm_raw: word(5),
                voltage_raw: word(7),
                current_raw: word(9) as i16,
                phase_current_raw: word(11) as i16,
                mos_adc: word(2) as u8,
                cap_adc: word(13) as u8,
                status: Status(if i % 7 == 0 { word(4) } else { 0 }),
            };
            let t = (i % 5 != 0).then_some(f64::from(i) * 0.05 + 1.7e9);
            let record = Record::new(
                t,
                (i % 4) as u8,
                &hwfoc::telemetry::Data::from(frame),
                &settings,
            );
            a.clear();
            b.clear();
            cached.json_frame(&record, &hwfoc::telemetry::Data::from(frame), &mut a);
            plain.json(&record, &mut b);
            assert_eq!(a, b);
            a.clear();
            b.clear();
            cached.csv_frame(&record, &hwfoc::telemetry::Data::from(frame), &mut a);
            plain.csv_frame(&record, &hwfoc::telemetry::Data::from(frame), &mut b);
            assert_eq!(a, b);
            if i % 1000 == 0 {
                // The text reads back to the record's values, as serde_json reads it.
                let mut json = Vec::new();
                record.write_json(&mut json);
                let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
                assert_eq!(v["current_a"].as_f64().map(|c| c as f32), record.current_a);
                assert_eq!(v["rpm"].as_f64().map(|c| c as f32), record.rpm);
                assert_eq!(v["packet"], i as u16);
                assert_eq!(v["t_s"].as_f64(), record.t_s);
            }
        }
    }

    #[test]
    fn integers_as_itoa_writes_them() {
        let mut e = TextEncoder::new();
        for v in [
            0u32,
            1,
            9,
            10,
            99,
            100,
            65_535,
            655_350,
            999_999,
            1_000_000,
            u32::MAX,
        ] {
            e.pos = 0;
            e.uint(v);
            assert_eq!(&e.row[..e.pos], itoa::Buffer::new().format(v).as_bytes());
        }
    }
}
