//! Tests of the HW5 codec (`hwfoc::hw5`) against things written independently of it:
//!
//! - the vectors of `testdata/hw5/vectors.txt`, made by `scripts/hw5-vectors.py` from the spec
//!   with Python's `struct` and `crcmod` (the script is the independent encoder and decoder:
//!   the Rust codec must encode to its bytes and decode to its values);
//! - a bitwise CRC-16/MODBUS and a naive reference scanner, written here from the spec;
//! - property tests: encode/decode identity, chunking independence, garbage, cut frames,
//!   single-bit errors, random bytes, non-telemetry frames.

#[allow(dead_code)]
mod common;

use common::{cut_points, streamed_bytewise};
use hwfoc::hw5::{self, Error, Fault, FaultCode, Kind, TelemetryFrame, identify};
use hwfoc::wire::crc16_modbus;
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::Index;

// ---------------------------------------------------------------------------------------------
// From the spec, independently of the codec
// ---------------------------------------------------------------------------------------------

/// CRC-16/MODBUS one bit at a time: register 0xFFFF, each byte XORed into the low end, shifted
/// out least significant bit first, 0xA001 (0x8005 reversed) fed back on a 1, no final XOR.
fn crc_reference(bytes: &[u8]) -> u16 {
    let mut crc = 0xFFFFu16;
    for &b in bytes {
        crc ^= u16::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xA001
            } else {
                crc >> 1
            };
        }
    }
    crc
}

/// The spec's list of frames: (kind, first three bytes, type, length). Telemetry also needs
/// code `03` and byte 6 `17`.
const KINDS: [(Kind, [u8; 3], u16, usize); 8] = [
    (Kind::Telemetry, [0xFE, 0x01, 0x00], 0x5C30, 32),
    (Kind::Ping, [0xFE, 0x01, 0x00], 0x242C, 11),
    (Kind::DeviceInfo, [0xFE, 0x01, 0x00], 0x252C, 73),
    (Kind::Reset, [0xFE, 0x01, 0x00], 0x022B, 10),
    (Kind::ParametersWriteError, [0xFE, 0x01, 0x00], 0x3835, 9),
    (Kind::ParametersWritten, [0xFE, 0x01, 0x00], 0x3835, 58),
    (Kind::ParametersRead, [0xFE, 0x01, 0x00], 0x3835, 105),
    (Kind::PingRequest, [0x01, 0xFD, 0x03], 0x242C, 10),
];

/// The telemetry fields read from the spec's table.
fn reference_fields(f: &[u8]) -> TelemetryFrame {
    TelemetryFrame {
        throttle: f[9],
        unknown: [f[10], f[11]],
        fault: FaultCode(f[12]),
        erpm_raw: u16::from(f[13]) | u16::from(f[14]) << 8,
        voltage_raw: u16::from(f[15]) | u16::from(f[16]) << 8,
        current_raw: u16::from(f[17]) | u16::from(f[18]) << 8,
        esc_temp: f[19],
        bec_temp: f[20],
        motor_temp: f[21],
        bec_voltage_raw: f[22],
        bec_current_raw: f[23],
    }
}

/// What the reference scanner counted, named as in `hw5::Stats`.
#[derive(Debug, Default, PartialEq, Clone)]
struct RefStats {
    bytes: u64,
    bytes_skipped: u64,
    frames: [u32; 8],
    checksum_failures: u32,
    bad_headers: u32,
    unknown_types: u32,
}

impl From<&hw5::Stats> for RefStats {
    fn from(s: &hw5::Stats) -> Self {
        RefStats {
            bytes: s.bytes(),
            bytes_skipped: s.bytes_skipped(),
            frames: *s.frames_by_kind(),
            checksum_failures: s.checksum_failures(),
            bad_headers: s.bad_headers(),
            unknown_types: s.unknown_types(),
        }
    }
}

/// The scanning rule of the spec, written the obvious (slow) way: at every byte, a candidate is
/// `FE 01` or `01 FD`; its third byte, its type and (telemetry) its code and byte 6 must fit,
/// then the CRC of one of its type's lengths, shortest first. A frame is taken whole; anything
/// else moves on by one byte. With `at_end` false, stops at the first candidate that needs
/// more bytes and returns how many bytes it left (what a streaming decoder holds).
fn reference_scan(
    bytes: &[u8],
    base: u64,
    at_end: bool,
    s: &mut RefStats,
    out: &mut Vec<hw5::Decoded>,
) -> usize {
    s.bytes += bytes.len() as u64;
    let mut i = 0;
    'scan: while i < bytes.len() {
        let rest = &bytes[i..];
        let envelope: [u8; 3] = match rest {
            [0xFE, 0x01, ..] | [0xFE] => [0xFE, 0x01, 0x00],
            [0x01, 0xFD, ..] | [0x01] => [0x01, 0xFD, 0x03],
            _ => {
                s.bytes_skipped += 1;
                i += 1;
                continue;
            }
        };
        // Each check needs its bytes: short of them, the candidate waits (or, at the end of
        // the stream, is skipped uncounted).
        let undecided = |s: &mut RefStats, i: &mut usize| {
            if at_end {
                s.bytes_skipped += 1;
                *i += 1;
                false
            } else {
                true
            }
        };
        if rest.len() < 3 {
            if undecided(s, &mut i) {
                return bytes.len() - i;
            }
            continue;
        }
        if rest[2] != envelope[2] {
            s.bad_headers += 1;
            s.bytes_skipped += 1;
            i += 1;
            continue;
        }
        if rest.len() < 6 {
            if undecided(s, &mut i) {
                return bytes.len() - i;
            }
            continue;
        }
        let frame_type = u16::from_le_bytes([rest[4], rest[5]]);
        let mut lengths: Vec<(Kind, usize)> = KINDS
            .iter()
            .filter(|(kind, env, t, _)| {
                *env == envelope
                    && *t == frame_type
                    && (*kind != Kind::Telemetry || rest[3] == 0x03)
            })
            .map(|&(kind, _, _, len)| (kind, len))
            .collect();
        lengths.sort_by_key(|&(_, len)| len);
        if lengths.is_empty() {
            s.unknown_types += 1;
            s.bytes_skipped += 1;
            i += 1;
            continue;
        }
        if lengths[0].0 == Kind::Telemetry {
            if rest.len() < 7 {
                if undecided(s, &mut i) {
                    return bytes.len() - i;
                }
                continue;
            }
            if rest[6] != 0x17 {
                s.bad_headers += 1;
                s.bytes_skipped += 1;
                i += 1;
                continue;
            }
        }
        for &(kind, len) in &lengths {
            if rest.len() < len {
                if undecided(s, &mut i) {
                    return bytes.len() - i;
                }
                continue 'scan;
            }
            let crc = u16::from_le_bytes([rest[len - 2], rest[len - 1]]);
            if crc_reference(&rest[..len - 2]) == crc {
                if kind == Kind::Telemetry {
                    // A value past the protocol's range (THROTTLE_MAX_PCT, VOLTAGE_MAX_RAW):
                    // a corrupted frame whose CRC still matches, rejected as one byte.
                    let f = reference_fields(rest);
                    if f.throttle > hw5::THROTTLE_MAX_PCT || f.voltage_raw > hw5::VOLTAGE_MAX_RAW {
                        s.bytes_skipped += 1;
                        i += 1;
                        continue 'scan;
                    }
                }
                s.frames[kind as usize] += 1;
                if kind == Kind::Telemetry {
                    out.push(hw5::Decoded {
                        offset: base + i as u64,
                        frame: reference_fields(rest),
                    });
                }
                i += len;
                continue 'scan;
            }
        }
        s.checksum_failures += 1;
        s.bytes_skipped += 1;
        i += 1;
    }
    0
}

fn reference(bytes: &[u8]) -> (Vec<hw5::Decoded>, RefStats) {
    let mut s = RefStats::default();
    let mut out = Vec::new();
    reference_scan(bytes, 0, true, &mut s, &mut out);
    (out, s)
}

/// The bytes a streaming decoder fed `bytes` (and not flushed) still holds.
fn reference_held(bytes: &[u8]) -> usize {
    reference_scan(bytes, 0, false, &mut RefStats::default(), &mut Vec::new())
}

// ---------------------------------------------------------------------------------------------
// Decoding paths
// ---------------------------------------------------------------------------------------------

fn bulk(bytes: &[u8]) -> (Vec<hw5::Decoded>, hw5::Stats) {
    let mut it = hw5::frames(bytes);
    let out: Vec<hw5::Decoded> = it.by_ref().collect();
    assert_eq!(it.next(), None);
    (out, *it.stats())
}

fn streamed_at(bytes: &[u8], cuts: &[usize]) -> (Vec<hw5::Decoded>, hw5::Stats) {
    let mut d = hw5::Decoder::new();
    let mut out = Vec::new();
    for w in cuts.windows(2) {
        d.feed(&bytes[w[0]..w[1]], |x| out.push(x));
        assert!(d.buffered() < hw5::MAX_FRAME_LEN);
    }
    d.flush(|x| out.push(x));
    assert_eq!(d.buffered(), 0);
    (out, *d.stats())
}

// ---------------------------------------------------------------------------------------------
// The vectors of scripts/hw5-vectors.py
// ---------------------------------------------------------------------------------------------

const VECTORS: &str = include_str!("../../../testdata/hw5/vectors.txt");

fn hex(s: &str) -> Vec<u8> {
    if s == "-" {
        return Vec::new();
    }
    assert!(s.len().is_multiple_of(2), "odd hex {s}");
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}

/// The vector lines of one kind (`crc`, `telemetry`, `frame`, `corrupt`), split on spaces.
fn vectors(tag: &str) -> Vec<Vec<&'static str>> {
    VECTORS
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| l.split(' ').collect::<Vec<_>>())
        .filter(|w| w[0] == tag)
        .collect()
}

/// `key=value` of a telemetry line.
fn value<'a>(words: &[&'a str], key: &str) -> &'a str {
    words
        .iter()
        .find_map(|w| w.strip_prefix(key).and_then(|r| r.strip_prefix('=')))
        .unwrap_or_else(|| panic!("no {key} in {words:?}"))
}

#[test]
fn crc_check_value() {
    assert_eq!(crc16_modbus(b"123456789"), 0x4B37);
    assert_eq!(crc_reference(b"123456789"), 0x4B37);
}

#[test]
fn vectors_crc_matches_crcmod() {
    let lines = vectors("crc");
    assert_eq!(lines.len(), 12);
    assert_eq!(lines[0][1..], ["313233343536373839", "4B37"]);
    for w in lines {
        let data = hex(w[1]);
        let expected = u16::from_str_radix(w[2], 16).unwrap();
        assert_eq!(crc16_modbus(&data), expected, "{}", w[1]);
        assert_eq!(crc_reference(&data), expected, "{}", w[1]);
    }
}

#[test]
fn vectors_telemetry_decode_and_encode_match_the_script() {
    let lines = vectors("telemetry");
    assert_eq!(lines.len(), 52);
    let mut wire = Vec::new();
    let mut expected = Vec::new();
    let mut out_of_range = 0;
    for w in &lines {
        let bytes = hex(w[1]);
        assert_eq!(bytes.len(), hw5::TELEMETRY_LEN);
        let n = |key: &str| value(w, key).parse::<u32>().unwrap();
        // Rust decode == the script's values.
        let script = TelemetryFrame {
            throttle: n("throttle") as u8,
            unknown: hex(value(w, "unknown")).try_into().unwrap(),
            fault: FaultCode(n("fault") as u8),
            erpm_raw: n("erpm_raw") as u16,
            voltage_raw: n("voltage_raw") as u16,
            current_raw: n("current_raw") as u16,
            esc_temp: n("esc_temp") as u8,
            bec_temp: n("bec_temp") as u8,
            motor_temp: n("motor_temp") as u8,
            bec_voltage_raw: n("bec_voltage_raw") as u8,
            bec_current_raw: n("bec_current_raw") as u8,
        };
        // Rust encode == the script's bytes (for every vector: the layout).
        assert_eq!(script.encode().as_slice(), bytes.as_slice());
        // A vector with a value out of the protocol's range (the script draws any voltage) is
        // rejected, never decoded.
        if script.throttle > hw5::THROTTLE_MAX_PCT || script.voltage_raw > hw5::VOLTAGE_MAX_RAW {
            assert!(
                matches!(
                    TelemetryFrame::parse(&bytes),
                    Err(hw5::Error::OutOfRange { .. })
                ),
                "{}",
                w[1]
            );
            out_of_range += 1;
            wire.extend_from_slice(&bytes);
            continue;
        }
        let f = TelemetryFrame::parse(&bytes).unwrap_or_else(|e| panic!("{}: {e}", w[1]));
        assert_eq!(f, script, "{}", w[1]);
        let float = |key: &str| value(w, key).parse::<f32>().unwrap();
        assert_eq!(f.erpm(), n("erpm"));
        assert_eq!(f.voltage_v(), float("volts"));
        assert_eq!(f.current_a(), float("amps"));
        assert_eq!(f.bec_voltage_v(), float("bec_volts"));
        assert_eq!(f.bec_current_a(), float("bec_amps"));
        assert_eq!(f.esc_temp_c(), n("esc_temp") as f32);
        assert_eq!(f.motor_temp_c(), n("motor_temp") as f32);
        let faults = match value(w, "faults") {
            "-" => String::new(),
            names => names.to_string(),
        };
        assert_eq!(f.fault.to_string(), faults);

        // The CRC: crcmod's, the bytes', the codec's and the reference's.
        let crc = u16::from_str_radix(value(w, "crc"), 16).unwrap();
        assert_eq!(u16::from_le_bytes([bytes[30], bytes[31]]), crc);
        assert_eq!(crc16_modbus(&bytes[..30]), crc);
        assert_eq!(crc_reference(&bytes[..30]), crc);

        assert_eq!(identify(&bytes), Ok(Kind::Telemetry));

        expected.push(hw5::Decoded {
            offset: wire.len() as u64,
            frame: script,
        });
        wire.extend_from_slice(&bytes);
    }
    let (decoded, stats) = bulk(&wire);
    assert_eq!(decoded, expected);
    assert_eq!((expected.len(), out_of_range), (12, 40));
    assert_eq!(stats.telemetry_frames(), 12);
    assert_eq!(stats.out_of_range(), 40);
    assert_eq!(stats.bytes_skipped(), 40 * hw5::TELEMETRY_LEN as u64);
    assert_eq!(streamed_bytewise::<hw5::Scanner>(&wire), (decoded, stats));
}

#[test]
fn vectors_fault_bits_one_by_one() {
    // The script sets each fault bit alone on one frame: the names come back in bit order.
    let names: Vec<String> = vectors("telemetry")
        .iter()
        .map(|w| value(w, "faults").to_string())
        .skip(4)
        .take(8)
        .collect();
    let ours: Vec<String> = Fault::ALL.iter().map(|f| f.name().to_string()).collect();
    assert_eq!(names, ours);
}

#[test]
fn vectors_other_frames_are_recognised_counted_and_not_returned() {
    let lines = vectors("frame");
    assert_eq!(lines.len(), 22);
    let mut wire = Vec::new();
    let mut counts = [0u32; Kind::COUNT];
    let telemetry = hex(vectors("telemetry")[2][1]);
    for w in &lines {
        let kind = *Kind::ALL.iter().find(|k| k.name() == w[1]).unwrap();
        let bytes = hex(w[2]);
        assert_eq!(bytes.len(), kind.wire_len(), "{}", w[1]);
        assert_eq!(identify(&bytes), Ok(kind), "{}", w[2]);
        let (decoded, stats) = bulk(&bytes);
        assert!(decoded.is_empty());
        assert_eq!(stats.frames(kind), 1);
        assert_eq!((stats.telemetry_frames(), stats.bytes_skipped()), (0, 0));
        counts[kind as usize] += 1;
        // Interleaved with telemetry, as a configurator's session is.
        wire.extend_from_slice(&bytes);
        wire.extend_from_slice(&telemetry);
    }
    let (decoded, stats) = bulk(&wire);
    assert_eq!(decoded.len(), lines.len());
    assert!(
        decoded
            .iter()
            .all(|d| d.frame == TelemetryFrame::parse(&telemetry).unwrap())
    );
    counts[Kind::Telemetry as usize] = lines.len() as u32;
    assert_eq!(stats.frames_by_kind(), &counts);
    assert_eq!(stats.requests(), 4);
    assert_eq!(stats.other_frames(), 22);
    assert_eq!(stats.bytes(), stats.frame_bytes());
    assert_eq!(stats.rejected(), 0);
    let cuts = cut_points(wire.len(), &[]);
    assert_eq!(streamed_at(&wire, &cuts), (decoded, stats));
}

#[test]
fn vectors_corrupted_frames_are_rejected() {
    let lines = vectors("corrupt");
    assert_eq!(lines.len(), 14);
    for w in lines {
        let bytes = hex(w[1]);
        assert!(TelemetryFrame::parse(&bytes).is_err(), "{}", w[2]);
        assert!(identify(&bytes).is_err(), "{}", w[2]);
        let (decoded, stats) = bulk(&bytes);
        assert!(decoded.is_empty(), "{}", w[2]);
        assert_eq!(stats.frames_by_kind(), &[0; Kind::COUNT]);
        assert_eq!(stats.bytes_skipped(), 32);
    }
}

// ---------------------------------------------------------------------------------------------
// Generators
// ---------------------------------------------------------------------------------------------

/// Any telemetry frame in the protocol's ranges (throttle and input voltage).
fn telemetry() -> impl Strategy<Value = TelemetryFrame> {
    (
        (0..=hw5::THROTTLE_MAX_PCT, any::<[u8; 2]>(), any::<u8>()),
        (any::<u16>(), 0..=hw5::VOLTAGE_MAX_RAW, any::<u16>()),
        (
            any::<u8>(),
            any::<u8>(),
            any::<u8>(),
            any::<u8>(),
            any::<u8>(),
        ),
    )
        .prop_map(
            |(
                (throttle, unknown, fault),
                (erpm_raw, voltage_raw, current_raw),
                (esc_temp, bec_temp, motor_temp, bec_voltage_raw, bec_current_raw),
            )| TelemetryFrame {
                throttle,
                unknown,
                fault: FaultCode(fault),
                erpm_raw,
                voltage_raw,
                current_raw,
                esc_temp,
                bec_temp,
                motor_temp,
                bec_voltage_raw,
                bec_current_raw,
            },
        )
}

/// A frame of a kind other than telemetry: its envelope, any code, its type, a random payload,
/// its CRC (built here, from the spec's list). A parameters frame whose shorter lengths' CRC
/// also matches by chance would read as the shorter kind: those are filtered out.
fn other_frame() -> impl Strategy<Value = (Kind, Vec<u8>)> {
    (1..KINDS.len(), any::<u8>(), vec(any::<u8>(), 105)).prop_filter_map(
        "a shorter parameters frame's CRC matches by chance",
        |(k, code, payload)| {
            let (kind, envelope, frame_type, len) = KINDS[k];
            let mut f = envelope.to_vec();
            f.push(code);
            f.extend_from_slice(&frame_type.to_le_bytes());
            f.extend_from_slice(&payload[..len - 8]);
            let crc = crc_reference(&f);
            f.extend_from_slice(&crc.to_le_bytes());
            (reference(&f).1.frames[kind as usize] == 1).then_some((kind, f))
        },
    )
}

/// Bytes biased towards the ones that matter to the scanner.
fn noisy_byte() -> impl Strategy<Value = u8> {
    prop_oneof![
        6 => any::<u8>(),
        2 => Just(0xFE),
        2 => Just(0x01),
        1 => Just(0x00),
        1 => Just(0xFD),
        1 => Just(0x03),
        1 => Just(0x30),
        1 => Just(0x5C),
        1 => Just(0x17),
        1 => Just(0x2C),
        1 => Just(0x35),
    ]
}

/// Headers with nothing of their frame after them.
const FAKES: [&[u8]; 10] = [
    &[0xFE],
    &[0x01],
    &[0xFE, 0x01],
    &[0xFE, 0x01, 0x00],
    &[0xFE, 0x01, 0x00, 0x03, 0x30, 0x5C],
    &[0xFE, 0x01, 0x00, 0x03, 0x30, 0x5C, 0x17],
    &[0xFE, 0x01, 0x00, 0x03, 0x35, 0x38],
    &[0xFE, 0x01, 0x00, 0x03, 0x30, 0x0C],
    &[0x01, 0xFD, 0x03, 0x03, 0x2C, 0x24],
    &[0x01, 0xFD, 0x03, 0x03, 0x2C, 0x25],
];

/// One stretch of a generated wire.
#[derive(Debug, Clone)]
enum Piece {
    /// A whole telemetry frame.
    Telemetry(TelemetryFrame),
    /// A whole frame of another kind.
    Other(Kind, Vec<u8>),
    /// Noise.
    Garbage(Vec<u8>),
    /// The first `n` bytes of a telemetry frame (`1 <= n < 32`).
    Cut(TelemetryFrame, usize),
    /// A telemetry frame with one bit flipped.
    Flipped(TelemetryFrame, usize),
    /// A header alone.
    Fake(&'static [u8]),
}

fn piece() -> impl Strategy<Value = Piece> {
    prop_oneof![
        4 => telemetry().prop_map(Piece::Telemetry),
        2 => other_frame().prop_map(|(k, f)| Piece::Other(k, f)),
        2 => vec(noisy_byte(), 0..50).prop_map(Piece::Garbage),
        1 => (telemetry(), 1..32usize).prop_map(|(f, n)| Piece::Cut(f, n)),
        1 => (telemetry(), 0..256usize).prop_map(|(f, bit)| Piece::Flipped(f, bit)),
        2 => (0..FAKES.len()).prop_map(|i| Piece::Fake(FAKES[i])),
    ]
}

fn pieces(max: usize) -> impl Strategy<Value = Vec<Piece>> {
    vec(piece(), 0..max)
}

/// A wire and the whole frames put into it: (offset, kind, telemetry if it is).
struct Wire {
    bytes: Vec<u8>,
    intact: Vec<(u64, Kind, Option<TelemetryFrame>)>,
}

fn build(pieces: &[Piece]) -> Wire {
    let mut wire = Wire {
        bytes: Vec::new(),
        intact: Vec::new(),
    };
    for p in pieces {
        let at = wire.bytes.len() as u64;
        match p {
            Piece::Telemetry(f) => {
                wire.intact.push((at, Kind::Telemetry, Some(*f)));
                wire.bytes.extend_from_slice(&f.encode());
            }
            Piece::Other(kind, f) => {
                wire.intact.push((at, *kind, None));
                wire.bytes.extend_from_slice(f);
            }
            Piece::Garbage(g) => wire.bytes.extend_from_slice(g),
            Piece::Cut(f, n) => wire.bytes.extend_from_slice(&f.encode()[..*n]),
            Piece::Flipped(f, bit) => {
                let mut b = f.encode();
                b[bit / 8] ^= 1 << (bit % 8);
                wire.bytes.extend_from_slice(&b);
            }
            Piece::Fake(h) => wire.bytes.extend_from_slice(h),
        }
    }
    wire
}

/// Whether a frame formed by chance starts outside the whole frames and overlaps one (a CRC
/// matching by chance, about 1 in 65536 per candidate that runs into a frame): the CRC cannot
/// settle such a wire, and the tests that need every whole frame found discard it.
fn ambiguous(wire: &Wire) -> bool {
    let spans: Vec<(usize, usize)> = wire
        .intact
        .iter()
        .map(|&(o, k, _)| (o as usize, o as usize + k.wire_len()))
        .collect();
    (0..wire.bytes.len())
        .filter(|&p| !spans.iter().any(|&(s, e)| (s..e).contains(&p)))
        .any(|p| match identify(&wire.bytes[p..]) {
            Ok(kind) => spans.iter().any(|&(s, e)| p < e && s < p + kind.wire_len()),
            Err(_) => false,
        })
}

// ---------------------------------------------------------------------------------------------
// Properties
// ---------------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// encode -> decode is the identity, and the bytes are the spec's (read back here by the
    /// test's own field reader and CRC).
    #[test]
    fn encode_decode_identity(f in telemetry()) {
        let bytes = f.encode();
        prop_assert_eq!(&bytes[..9], &[0xFE, 0x01, 0x00, 0x03, 0x30, 0x5C, 0x17, 0x06, 0x00]);
        prop_assert_eq!(&bytes[24..30], &[0xFF; 6]);
        prop_assert_eq!(u16::from_le_bytes([bytes[30], bytes[31]]), crc_reference(&bytes[..30]));
        prop_assert_eq!(reference_fields(&bytes), f);
        prop_assert_eq!(TelemetryFrame::parse(&bytes), Ok(f));
        prop_assert_eq!(identify(&bytes), Ok(Kind::Telemetry));
        let (decoded, stats) = bulk(&bytes);
        prop_assert_eq!(decoded, vec![hw5::Decoded { offset: 0, frame: f }]);
        prop_assert_eq!(stats.bytes_skipped(), 0);
    }

    /// The codec's CRC is the bitwise reference's on any bytes.
    #[test]
    fn crc_matches_the_bitwise_reference(data in vec(any::<u8>(), 0..300)) {
        prop_assert_eq!(crc16_modbus(&data), crc_reference(&data));
    }

    /// One flipped bit in a frame of any kind is always caught: the frame is not taken as its
    /// kind, at its place, by `identify` or by the scanner.
    #[test]
    fn one_flipped_bit_is_always_rejected(
        f in telemetry(),
        other in other_frame(),
        bit in any::<Index>(),
        use_other in any::<bool>(),
        before in pieces(4),
        after in pieces(4),
        picks in vec(any::<Index>(), 0..8),
    ) {
        let (kind, mut bytes) = if use_other { other } else { (Kind::Telemetry, f.encode().to_vec()) };
        let bit = bit.index(8 * bytes.len());
        bytes[bit / 8] ^= 1 << (bit % 8);
        prop_assert_ne!(identify(&bytes), Ok(kind));
        if kind == Kind::Telemetry {
            prop_assert!(TelemetryFrame::parse(&bytes).is_err());
            prop_assert!(identify(&bytes).is_err());
        }
        let head = build(&before).bytes;
        let at = head.len() as u64;
        let wire = [head, bytes.clone(), build(&after).bytes].concat();
        let (decoded, stats) = bulk(&wire);
        prop_assert!(decoded.iter().all(|d| d.offset != at), "corrupted frame decoded at {}", at);
        // Alone, no frame of its kind is counted.
        prop_assert_eq!(bulk(&bytes).1.frames(kind), 0);
        let cuts = cut_points(wire.len(), &picks);
        prop_assert_eq!(streamed_at(&wire, &cuts), (decoded, stats));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// However the wire is cut into chunks, the same frames and the same statistics as the
    /// bulk path, and both the same as the reference scanner's.
    #[test]
    fn any_chunking_gives_the_same_frames_and_stats(
        ps in pieces(20),
        picks in vec(any::<Index>(), 0..30),
    ) {
        let wire = build(&ps);
        let whole = bulk(&wire.bytes);
        let cuts = cut_points(wire.bytes.len(), &picks);
        prop_assert_eq!(&streamed_at(&wire.bytes, &cuts), &whole);
        prop_assert_eq!(&streamed_at(&wire.bytes, &[0, wire.bytes.len()]), &whole);
        prop_assert_eq!(&streamed_bytewise::<hw5::Scanner>(&wire.bytes), &whole);
        let mut all = hw5::Decoder::new();
        let mut out = Vec::new();
        all.decode_all(&wire.bytes, |d| out.push(d));
        prop_assert_eq!(&(out, *all.stats()), &whole);
        let (ref_decoded, ref_stats) = reference(&wire.bytes);
        prop_assert_eq!(&whole.0, &ref_decoded);
        prop_assert_eq!(RefStats::from(&whole.1), ref_stats);
    }

    /// The streaming decoder holds back only an undecided candidate, and every other byte is
    /// already in a frame or counted as skipped.
    #[test]
    fn only_an_undecided_candidate_is_held(
        ps in pieces(12),
        picks in vec(any::<Index>(), 0..30),
        bytewise in any::<bool>(),
    ) {
        let wire = build(&ps);
        let cuts = if bytewise {
            (0..=wire.bytes.len()).collect()
        } else {
            cut_points(wire.bytes.len(), &picks)
        };
        let mut d = hw5::Decoder::new();
        for w in cuts.windows(2) {
            d.feed(&wire.bytes[w[0]..w[1]], |_| {});
            prop_assert_eq!(d.buffered(), reference_held(&wire.bytes[..w[1]]), "after {}", w[1]);
            let s = d.stats();
            prop_assert_eq!(s.bytes(), s.frame_bytes() + s.bytes_skipped() + d.buffered() as u64);
        }
    }

    /// Garbage, cut frames, flipped frames and fake headers between frames are skipped and
    /// counted, and never lose a whole frame: every telemetry frame is decoded at its offset,
    /// every other frame counted by kind; what else is found lies outside them.
    #[test]
    fn garbage_between_frames_is_skipped_and_counted(ps in pieces(24)) {
        let wire = build(&ps);
        prop_assume!(!ambiguous(&wire));
        let (decoded, stats) = bulk(&wire.bytes);
        let found: Vec<(u64, TelemetryFrame)> = decoded.iter().map(|d| (d.offset, d.frame)).collect();
        let intact: Vec<(u64, TelemetryFrame)> =
            wire.intact.iter().filter_map(|&(o, _, f)| f.map(|f| (o, f))).collect();
        let mut it = found.iter();
        for want in &intact {
            prop_assert!(it.any(|got| got == want), "lost {:?}", want);
        }
        for kind in Kind::ALL {
            let n = wire.intact.iter().filter(|&&(_, k, _)| k == kind).count();
            prop_assert!(stats.frames(kind) as usize >= n, "{}", kind);
        }
        prop_assert_eq!(stats.bytes(), stats.frame_bytes() + stats.bytes_skipped());
        let intact_bytes: u64 = wire.intact.iter().map(|&(_, k, _)| k.wire_len() as u64).sum();
        prop_assert!(stats.bytes_skipped() <= wire.bytes.len() as u64 - intact_bytes);
        // Anything that is not a whole frame is skipped: with no frame formed by chance, exactly.
        if stats.frame_bytes() == intact_bytes {
            prop_assert_eq!(stats.bytes_skipped(), wire.bytes.len() as u64 - intact_bytes);
            prop_assert_eq!(found, intact);
        }
        let garbage = ps.iter().any(|p| matches!(p, Piece::Flipped(..) | Piece::Fake(_)));
        if garbage {
            prop_assert!(stats.bytes_skipped() > 0);
        }
    }

    /// A frame cut short and followed by a whole frame costs exactly its own bytes, and the
    /// frame after it is found; one cut off by the end of the stream is skipped, not an error.
    #[test]
    fn cut_frames_are_skipped_and_never_hide_the_next(
        cut in telemetry(),
        n in 1..32usize,
        next in telemetry(),
        other in other_frame(),
        cut_other in any::<bool>(),
    ) {
        let whole: Vec<u8> = if cut_other { other.1 } else { cut.encode().to_vec() };
        let n = n.min(whole.len() - 1);
        let mut wire = whole[..n].to_vec();
        wire.extend_from_slice(&next.encode());
        let w = Wire { bytes: wire.clone(), intact: vec![(n as u64, Kind::Telemetry, Some(next))] };
        prop_assume!(!ambiguous(&w));
        let (decoded, stats) = bulk(&wire);
        let want = hw5::Decoded { offset: n as u64, frame: next };
        prop_assert!(decoded.contains(&want), "lost the frame after the cut one");
        if stats.frame_bytes() == 32 {
            prop_assert_eq!(stats.bytes_skipped(), n as u64);
        }

        let (decoded, stats) = bulk(&whole[..n]);
        let (ref_decoded, ref_stats) = reference(&whole[..n]);
        prop_assert_eq!(&decoded, &ref_decoded);
        prop_assert_eq!(RefStats::from(&stats), ref_stats);
        if stats.frame_bytes() == 0 {
            prop_assert_eq!(stats.bytes_skipped(), n as u64);
        }
        prop_assert_eq!(stats.telemetry_frames(), 0);
    }

    /// Frames of other kinds are counted by kind and never handed on as telemetry.
    #[test]
    fn other_frames_are_counted_and_never_returned(
        frames in vec(other_frame(), 1..12),
        picks in vec(any::<Index>(), 0..10),
    ) {
        let mut bytes = Vec::new();
        let mut counts = [0u32; Kind::COUNT];
        for (kind, f) in &frames {
            bytes.extend_from_slice(f);
            counts[*kind as usize] += 1;
        }
        let (decoded, stats) = bulk(&bytes);
        prop_assert!(decoded.is_empty());
        prop_assert_eq!(stats.telemetry_frames(), 0);
        prop_assert_eq!(stats.frames_by_kind(), &counts);
        prop_assert_eq!(stats.other_frames(), frames.len() as u64);
        prop_assert_eq!(stats.bytes_skipped(), 0);
        prop_assert_eq!(stats.rejected(), 0);
        let cuts = cut_points(bytes.len(), &picks);
        prop_assert_eq!(streamed_at(&bytes, &cuts), (decoded, stats));
    }

    /// The bulk path, the streaming path and the reference agree on arbitrary bytes.
    #[test]
    fn bulk_equals_streaming_and_reference_on_arbitrary_bytes(
        bytes in prop_oneof![vec(any::<u8>(), 0..600), vec(noisy_byte(), 0..600)],
        picks in vec(any::<Index>(), 0..20),
    ) {
        let whole = bulk(&bytes);
        let cuts = cut_points(bytes.len(), &picks);
        prop_assert_eq!(&streamed_at(&bytes, &cuts), &whole);
        let (ref_decoded, ref_stats) = reference(&bytes);
        prop_assert_eq!(&whole.0, &ref_decoded);
        prop_assert_eq!(RefStats::from(&whole.1), ref_stats);
    }

    /// Silences told to the decoder between stretches: each ends whatever frame was arriving
    /// (as if the stream ended), whatever the chunking; the same as the reference run over each
    /// stretch on its own.
    #[test]
    fn line_silent_in_any_chunking(
        stretches in vec((pieces(6), any::<u32>()), 1..5),
        picks in vec(any::<Index>(), 0..20),
        bytewise in any::<bool>(),
    ) {
        let parts: Vec<Vec<u8>> = stretches.iter().map(|(ps, _)| build(ps).bytes).collect();
        let mut d = hw5::Decoder::new();
        let mut out = Vec::new();
        let mut s = RefStats::default();
        let mut ref_out = Vec::new();
        let mut base = 0;
        for (i, part) in parts.iter().enumerate() {
            if i > 0 {
                d.line_silent(stretches[i].1, |x| out.push(x));
                prop_assert_eq!(d.buffered(), 0);
            }
            let cuts = if bytewise { (0..=part.len()).collect() } else { cut_points(part.len(), &picks) };
            for w in cuts.windows(2) {
                d.feed(&part[w[0]..w[1]], |x| out.push(x));
            }
            reference_scan(part, base, true, &mut s, &mut ref_out);
            base += part.len() as u64;
        }
        d.flush(|x| out.push(x));
        prop_assert_eq!(&out, &ref_out);
        prop_assert_eq!(RefStats::from(d.stats()), s);
    }
}

// ---------------------------------------------------------------------------------------------
// Random bytes never make a frame
// ---------------------------------------------------------------------------------------------

/// A xorshift generator: the same bytes on every run.
struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
}

#[test]
fn two_million_random_bytes_never_make_a_frame() {
    let mut rng = XorShift(0x4857_3500_DEAD_BEEF);
    let bytes: Vec<u8> = (0..2_000_000).map(|_| rng.next() as u8).collect();
    let (decoded, stats) = bulk(&bytes);
    assert!(decoded.is_empty());
    assert_eq!(stats.frames_by_kind(), &[0; Kind::COUNT]);
    assert_eq!(stats.bytes_skipped(), 2_000_000);
    // Chance candidates (`FE 01`, `01 FD`: about 61 in 2 MB) were there, and rejected.
    assert!(stats.rejected() > 20, "{stats}");
    let mut d = hw5::Decoder::new();
    let mut n = 0;
    for chunk in bytes.chunks(4093) {
        d.feed(chunk, |_| n += 1);
    }
    d.flush(|_| n += 1);
    assert_eq!((n, d.stats()), (0, &stats));
}

#[test]
fn random_bytes_rich_in_headers_never_make_a_frame() {
    // Headers of every kind (telemetry's whole seven bytes, the others' six) followed by random
    // bytes, and random bytes between them: every candidate is whole and decided by its CRC.
    let mut rng = XorShift(0x0123_4567_89AB_CDEF);
    let mut bytes = Vec::new();
    let mut headers = 0;
    while bytes.len() < 200_000 {
        match rng.next() % 4 {
            0 => bytes.extend_from_slice(&hw5::TELEMETRY_HEADER),
            1 => {
                let (_, envelope, frame_type, _) = KINDS[(rng.next() % 8) as usize];
                bytes.extend_from_slice(&envelope);
                bytes.push(0x03);
                bytes.extend_from_slice(&frame_type.to_le_bytes());
                if frame_type == hw5::TYPE_TELEMETRY {
                    bytes.push(0x17);
                }
            }
            2 => bytes.extend_from_slice(&[0xFE, 0x01, 0x00]),
            _ => {
                let n = rng.next() % 120;
                bytes.extend((0..n).map(|_| rng.next() as u8));
                continue;
            }
        }
        headers += 1;
        let n = rng.next() % 40;
        bytes.extend((0..n).map(|_| rng.next() as u8));
    }
    let (decoded, stats) = bulk(&bytes);
    assert!(decoded.is_empty(), "{:?}", decoded.first());
    assert_eq!(stats.frames_by_kind(), &[0; Kind::COUNT], "{stats}");
    assert_eq!(stats.bytes_skipped(), bytes.len() as u64);
    assert!(headers > 2_500);
    assert!(stats.checksum_failures() > 1_500, "{stats}");
    assert!(
        stats.bad_headers() > 0 && stats.unknown_types() > 0,
        "{stats}"
    );
    let (_, ref_stats) = reference(&bytes);
    assert_eq!(RefStats::from(&stats), ref_stats);
}

#[test]
fn error_messages() {
    assert_eq!(
        Error::Envelope {
            found: [0xFD, 0x01, 0x00]
        }
        .to_string(),
        "HW5 frame starts with FD 01 00, not FE 01 00 or 01 FD 03"
    );
    assert_eq!(
        Error::Crc {
            expected: 0x1234,
            found: 0xABCD
        }
        .to_string(),
        "HW5 CRC mismatch: bytes give 0x1234, frame carries 0xABCD"
    );
}
