//! The telemetry record of `RECORD-SCHEMA.md` and its text encodings (JSON Lines and CSV).
//!
//! Numbers are written as `itoa`/`ryu` write them (the shortest text that reads back to the same
//! value, as `serde_json` writes them), with no allocation per record; see [`TextEncoder`].

use hwfoc::{DataFrame, Settings, Status};

/// Column names in schema order.
pub const COLUMNS: [&str; 14] = [
    "t_s",
    "esc",
    "packet",
    "throttle_in_pct",
    "throttle_out_pct",
    "erpm",
    "rpm",
    "voltage_v",
    "current_a",
    "phase_current_a",
    "mos_temp_c",
    "cap_temp_c",
    "status",
    "faults",
];

/// Unit of each column, in schema order (`-` for a number without unit).
pub const UNITS: [&str; 14] = [
    "s", "-", "-", "%", "%", "rev/min", "rev/min", "V", "A", "A", "degC", "degC", "-", "-",
];

/// One decoded data frame in physical units, as every output presents it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Record {
    /// Receive time of the frame's first byte, in seconds, if the source has timing.
    pub t_s: Option<f64>,
    /// Index of the input the frame came from.
    pub esc: u8,
    /// Packet number.
    pub packet: u16,
    /// Input throttle, %.
    pub throttle_in_pct: f32,
    /// Output throttle, %.
    pub throttle_out_pct: f32,
    /// Electrical RPM.
    pub erpm: u32,
    /// Mechanical RPM under the settings.
    pub rpm: f32,
    /// Input voltage, V.
    pub voltage_v: f32,
    /// Input current, A.
    pub current_a: f32,
    /// Phase current, A.
    pub phase_current_a: f32,
    /// MOSFET temperature, degC, if in the table's range.
    pub mos_temp_c: Option<f32>,
    /// Capacitor temperature, degC, if in the table's range.
    pub cap_temp_c: Option<f32>,
    /// Raw status word (the `faults` column is derived from it).
    pub status: Status,
}

impl Record {
    /// Converts a frame under `settings`.
    pub fn new(t_s: Option<f64>, esc: u8, f: &DataFrame, settings: &Settings) -> Record {
        Record {
            t_s,
            esc,
            packet: f.packet,
            throttle_in_pct: f.throttle_in_pct(),
            throttle_out_pct: f.throttle_out_pct(),
            erpm: f.erpm(),
            rpm: f.rpm(settings),
            voltage_v: f.voltage_v(),
            current_a: f.current_a(settings),
            phase_current_a: f.phase_current_a(settings),
            mos_temp_c: f.mos_temp().celsius(),
            cap_temp_c: f.cap_temp().celsius(),
            status: f.status,
        }
    }

    /// Appends the record as one JSON object and a newline.
    ///
    /// For many records, [`TextEncoder`] is faster: it remembers the text of recent numbers.
    pub fn write_json(&self, out: &mut Vec<u8>) {
        TextEncoder::new().json(self, out);
    }

    /// Appends the CSV header row.
    pub fn write_csv_header(out: &mut Vec<u8>) {
        out.extend_from_slice(COLUMNS.join(",").as_bytes());
        out.push(b'\n');
    }
}

/// Longest text of one record: the keys (about 200 bytes), thirteen numbers of at most 24
/// characters and sixteen fault names, with room to spare for the fixed-size copies below.
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
    cache: Option<Box<[FloatCache; FLOAT_COLUMNS]>>,
}

/// The `f32` columns, each with its own cache, and the raw integer each comes from.
const FLOAT_COLUMNS: usize = 7;
const C_THROTTLE_IN: usize = 0;
const C_THROTTLE_OUT: usize = 1;
const C_RPM: usize = 2;
const C_VOLTAGE: usize = 3;
const C_CURRENT: usize = 4;
const C_PHASE_CURRENT: usize = 5;
const C_TEMP: usize = 6;

/// A direct-mapped cache from a raw integer (the low bits index it) to the text of the value
/// converted from it. Neighbouring raw values share cache lines.
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

/// The raw keys of a record's `f32` columns, in the order of the `C_*` indices (temperatures:
/// MOSFET, then capacitor).
type RawKeys = [u32; 8];

fn raw_keys(f: &DataFrame) -> RawKeys {
    [
        u32::from(f.throttle_in_raw),
        u32::from(f.throttle_out_raw),
        u32::from(f.erpm_raw),
        u32::from(f.voltage_raw),
        u32::from(f.current_raw as u16),
        u32::from(f.phase_current_raw as u16),
        u32::from(f.mos_adc),
        u32::from(f.cap_adc),
    ]
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
        TextEncoder {
            cache: Some(Box::new(std::array::from_fn(|_| FloatCache::new()))),
            ..TextEncoder::new()
        }
    }

    /// Appends `r` as one JSON object and a newline, with exactly the schema's keys in order.
    pub fn json(&mut self, r: &Record, out: &mut Vec<u8>) {
        self.json_impl(r, None, out);
    }

    /// Appends `r`, the record of `frame`, as [`TextEncoder::json`] does; a cached encoder
    /// takes the text of numbers from its caches. Every record given to one cached encoder
    /// must be converted under the same settings.
    pub fn json_frame(&mut self, r: &Record, frame: &DataFrame, out: &mut Vec<u8>) {
        self.json_impl(r, Some(raw_keys(frame)), out);
    }

    /// Appends `r`, the record of `frame`, as one CSV row (the columns of [`COLUMNS`]): empty
    /// fields for nulls, faults joined by `|`. A cached encoder takes the text of numbers from
    /// its caches, as [`TextEncoder::json_frame`] does.
    pub fn csv_frame(&mut self, r: &Record, frame: &DataFrame, out: &mut Vec<u8>) {
        self.csv_impl(r, Some(raw_keys(frame)), out);
    }

    #[inline]
    fn json_impl(&mut self, r: &Record, k: Option<RawKeys>, out: &mut Vec<u8>) {
        let key = |i: usize| k.map(|k| k[i]);
        self.pos = 0;
        self.lit(b"{\"t_s\":");
        match r.t_s {
            Some(t) => self.f64(t),
            None => self.lit(b"null"),
        }
        self.lit(b",\"esc\":");
        self.uint(u32::from(r.esc));
        self.lit(b",\"packet\":");
        self.uint(u32::from(r.packet));
        self.lit(b",\"throttle_in_pct\":");
        self.f32(C_THROTTLE_IN, r.throttle_in_pct, key(0));
        self.lit(b",\"throttle_out_pct\":");
        self.f32(C_THROTTLE_OUT, r.throttle_out_pct, key(1));
        self.lit(b",\"erpm\":");
        self.uint(r.erpm);
        self.lit(b",\"rpm\":");
        self.f32(C_RPM, r.rpm, key(2));
        self.lit(b",\"voltage_v\":");
        self.f32(C_VOLTAGE, r.voltage_v, key(3));
        self.lit(b",\"current_a\":");
        self.f32(C_CURRENT, r.current_a, key(4));
        self.lit(b",\"phase_current_a\":");
        self.f32(C_PHASE_CURRENT, r.phase_current_a, key(5));
        self.lit(b",\"mos_temp_c\":");
        self.opt_f32(r.mos_temp_c, key(6), b"null");
        self.lit(b",\"cap_temp_c\":");
        self.opt_f32(r.cap_temp_c, key(7), b"null");
        self.lit(b",\"status\":");
        self.uint(u32::from(r.status.0));
        self.lit(b",\"faults\":[");
        if !r.status.is_ok() {
            for (i, fault) in r.status.faults().enumerate() {
                if i > 0 {
                    self.lit(b",");
                }
                // Fault names are plain ASCII identifiers: nothing to escape.
                self.lit(b"\"");
                self.lit(fault.name().as_bytes());
                self.lit(b"\"");
            }
        }
        self.lit(b"]}\n");
        out.extend_from_slice(&self.row[..self.pos]);
    }

    #[inline]
    fn csv_impl(&mut self, r: &Record, k: Option<RawKeys>, out: &mut Vec<u8>) {
        let key = |i: usize| k.map(|k| k[i]);
        self.pos = 0;
        if let Some(t) = r.t_s {
            self.f64(t);
        }
        self.lit(b",");
        self.uint(u32::from(r.esc));
        self.lit(b",");
        self.uint(u32::from(r.packet));
        self.lit(b",");
        self.f32(C_THROTTLE_IN, r.throttle_in_pct, key(0));
        self.lit(b",");
        self.f32(C_THROTTLE_OUT, r.throttle_out_pct, key(1));
        self.lit(b",");
        self.uint(r.erpm);
        self.lit(b",");
        self.f32(C_RPM, r.rpm, key(2));
        self.lit(b",");
        self.f32(C_VOLTAGE, r.voltage_v, key(3));
        self.lit(b",");
        self.f32(C_CURRENT, r.current_a, key(4));
        self.lit(b",");
        self.f32(C_PHASE_CURRENT, r.phase_current_a, key(5));
        self.lit(b",");
        self.opt_f32(r.mos_temp_c, key(6), b"");
        self.lit(b",");
        self.opt_f32(r.cap_temp_c, key(7), b"");
        self.lit(b",");
        self.uint(u32::from(r.status.0));
        self.lit(b",");
        if !r.status.is_ok() {
            for (i, fault) in r.status.faults().enumerate() {
                if i > 0 {
                    self.lit(b"|");
                }
                self.lit(fault.name().as_bytes());
            }
        }
        self.lit(b"\n");
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

    /// The text of `v`, converted from the raw integer `key`, in column `column`'s cache.
    /// Finite values only: every value written is computed from integers by a finite factor.
    #[inline(always)]
    fn f32(&mut self, column: usize, v: f32, key: Option<u32>) {
        let (Some(cache), Some(key)) = (self.cache.as_mut(), key) else {
            self.f32_uncached(v);
            return;
        };
        let entry = &mut cache[column].entries[key as usize & ((1 << CACHE_BITS) - 1)];
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

    #[inline]
    fn opt_f32(&mut self, v: Option<f32>, key: Option<u32>, null: &[u8]) {
        match v {
            Some(v) => self.f32(C_TEMP, v, key),
            None => self.lit(null),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first frame of the XRotor capture and the JSON line RECORD-SCHEMA.md gives for it.
    #[test]
    fn schema_example_line() {
        let bytes = [
            0x9B, 0x16, 0x01, 0x02, 0x05, 0xC2, 0, 0, 0, 0, 0, 0, 0x00, 0xF7, 0xFF, 0xFF, 0xFF,
            0xFF, 0xCE, 0xD1, 0x00, 0x00, 0x0D, 0x08,
        ];
        let frame = DataFrame::parse(&bytes).unwrap();
        let record = Record::new(Some(0.22798), 0, &frame, &Settings::default());
        let mut out = Vec::new();
        record.write_json(&mut out);
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "{\"t_s\":0.22798,\"esc\":0,\"packet\":1474,\"throttle_in_pct\":0.0,\"throttle_out_pct\":0.0,\"erpm\":0,\"rpm\":0.0,\"voltage_v\":24.7,\"current_a\":-0.015625,\"phase_current_a\":-0.015625,\"mos_temp_c\":28.0,\"cap_temp_c\":26.0,\"status\":0,\"faults\":[]}\n"
        );
    }

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
        let record = Record::new(None, 2, &frame, &Settings::default());
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
        assert_eq!(keys, COLUMNS);

        let mut csv = Vec::new();
        Record::write_csv_header(&mut csv);
        TextEncoder::new().csv_frame(&record, &frame, &mut csv);
        assert_eq!(
            String::from_utf8(csv).unwrap(),
            "t_s,esc,packet,throttle_in_pct,throttle_out_pct,erpm,rpm,voltage_v,current_a,phase_current_a,mos_temp_c,cap_temp_c,status,faults\n\
             ,2,3,0.0,0.0,7000,1000.0,0.0,0.0,0.0,,,65,input_voltage_high|mos_overheat\n"
        );
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
            let record = Record::new(t, (i % 4) as u8, &frame, &settings);
            a.clear();
            b.clear();
            cached.json_frame(&record, &frame, &mut a);
            plain.json(&record, &mut b);
            assert_eq!(a, b);
            a.clear();
            b.clear();
            cached.csv_frame(&record, &frame, &mut a);
            plain.csv_frame(&record, &frame, &mut b);
            assert_eq!(a, b);
            if i % 1000 == 0 {
                // The text reads back to the record's values, as serde_json reads it.
                let mut json = Vec::new();
                record.write_json(&mut json);
                let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
                assert_eq!(
                    v["current_a"].as_f64().map(|c| c as f32),
                    Some(record.current_a)
                );
                assert_eq!(v["rpm"].as_f64().map(|c| c as f32), Some(record.rpm));
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
