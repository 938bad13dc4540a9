//! The decoder of every serial format at once (`hwfoc::detect`): on the real captures and on
//! streams made by the codec's encoders it finds exactly what each format's own decoder finds,
//! with the same statistics; it gives the same frames and state however the stream is cut into
//! chunks; it follows a stream that changes format (after a line silence at once, without one
//! within two blocks of `RELOCK_AFTER` and a slice) and loses no frame of either format; it never locks on random bytes; and it
//! locks within the times of `docs/OLDER-PROTOCOLS.md` ("Auto-detection"), measured and printed here.

#[allow(dead_code)] // the HW-FOC generator and the other protocols' paths
mod common;
#[allow(dead_code)] // the V3 and V4 tests' helpers
mod older;

use common::cut_points;
use hwfoc::detect::{Decoded, Decoder, Family, RELOCK_AFTER, SLICE};
use hwfoc::foc::DataFrame;
use hwfoc::{datalink, foc, hw5, mixed, v3, v4};
use older::{PLATINUM_PRO_V3, PLATINUM_V4, Rng, XROTOR, load, load_timed};
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::Index;

// ---------------------------------------------------------------------------------------------
// Decoding paths
// ---------------------------------------------------------------------------------------------

/// Everything a detecting decoder tells of itself.
#[derive(Debug, Clone, PartialEq)]
struct State {
    locked: Option<Family>,
    last_locked: Option<Family>,
    bytes: u64,
    buffered: usize,
    mixed: mixed::Stats,
    hw5: hw5::Stats,
    v4: v4::Stats,
    v3: v3::Stats,
}

fn state(d: &Decoder) -> State {
    State {
        locked: d.locked(),
        last_locked: d.last_locked(),
        bytes: d.bytes(),
        buffered: d.buffered(),
        mixed: *d.mixed_stats(),
        hw5: *d.stats::<hwfoc::hw5::Scanner>(),
        v4: *d.stats::<hwfoc::v4::Scanner>(),
        v3: *d.stats::<hwfoc::v3::Scanner>(),
    }
}

/// `decode_all`: the reference.
fn bulk(bytes: &[u8]) -> (Vec<Decoded>, State) {
    let mut d = Decoder::new();
    let mut out = Vec::new();
    d.decode_all(bytes, |x| out.push(x));
    (out, state(&d))
}

/// Fed in the chunks between consecutive `cuts`, then flushed; the state after each chunk.
fn chunked(bytes: &[u8], cuts: &[usize]) -> (Vec<Decoded>, State, Vec<(usize, State)>) {
    let mut d = Decoder::new();
    let mut out = Vec::new();
    let mut states = Vec::new();
    for w in cuts.windows(2) {
        d.feed(&bytes[w[0]..w[1]], |x| out.push(x));
        assert_eq!(d.bytes(), w[1] as u64);
        states.push((w[1], state(&d)));
    }
    d.flush(|x| out.push(x));
    (out, state(&d), states)
}

/// A byte at a time, then flushed; the state after each byte.
fn bytewise(bytes: &[u8]) -> (Vec<Decoded>, State, Vec<State>) {
    let mut d = Decoder::new();
    let mut out = Vec::new();
    let mut states = Vec::with_capacity(bytes.len());
    for &b in bytes {
        d.feed(&[b], |x| out.push(x));
        states.push(state(&d));
    }
    d.flush(|x| out.push(x));
    (out, state(&d), states)
}

/// The frames of one family, in the order given.
fn of(frames: &[Decoded], family: Family) -> Vec<Decoded> {
    frames
        .iter()
        .filter(|d| d.family() == family)
        .copied()
        .collect()
}

/// The frames in stream order (by offset; frames of different families at the same offset by
/// family).
fn sorted(frames: &[Decoded]) -> Vec<Decoded> {
    let mut v = frames.to_vec();
    v.sort_by_key(|d| {
        let f = Family::ALL.iter().position(|&f| f == d.family());
        (d.offset(), f)
    });
    v
}

/// `frame` moved `by` bytes later in the stream.
fn shifted(frame: Decoded, by: u64) -> Decoded {
    match frame {
        Decoded::Mixed(mixed::Decoded::Esc(mut d)) => {
            d.offset += by;
            Decoded::Mixed(mixed::Decoded::Esc(d))
        }
        Decoded::Mixed(mixed::Decoded::Hub(mut d)) => {
            d.offset += by;
            Decoded::Mixed(mixed::Decoded::Hub(d))
        }
        Decoded::HwV4(mut d) => {
            d.offset += by;
            Decoded::HwV4(d)
        }
        Decoded::HwV3(mut d) => {
            d.offset += by;
            Decoded::HwV3(d)
        }
        Decoded::Hw5(mut d) => {
            d.offset += by;
            Decoded::Hw5(d)
        }
    }
}

/// The frame without the V4 info frame adopted when it was decoded (decoder state).
fn without_info(frame: Decoded) -> Decoded {
    match frame {
        Decoded::HwV4(mut d) => {
            if let v4::V4Frame::Data(x) = &mut d.frame {
                x.info = None;
            }
            Decoded::HwV4(d)
        }
        other => other,
    }
}

/// What the family's own decoder finds in `bytes` (`decode_all`), as `detect` frames.
fn own(family: Family, bytes: &[u8]) -> Vec<Decoded> {
    let mut out = Vec::new();
    match family {
        Family::Mixed => mixed::Decoder::new().decode_all(bytes, |d| out.push(Decoded::Mixed(d))),
        Family::Hw5 => hw5::Decoder::new().decode_all(bytes, |d| out.push(Decoded::Hw5(d))),
        Family::HwV4 => v4::Decoder::new().decode_all(bytes, |d| out.push(Decoded::HwV4(d))),
        Family::HwV3 => v3::Decoder::new().decode_all(bytes, |d| out.push(Decoded::HwV3(d))),
    }
    out
}

/// What the family's own decoder finds in `bytes` with a line silence of `frames` frames
/// after `at`.
fn own_with_silence(family: Family, bytes: &[u8], at: usize, frames: u32) -> Vec<Decoded> {
    let mut out = Vec::new();
    let (first, second) = bytes.split_at(at);
    match family {
        Family::Mixed => {
            let mut d = mixed::Decoder::new();
            d.feed(first, |x| out.push(Decoded::Mixed(x)));
            d.line_silent_each(frames, frames, |x| out.push(Decoded::Mixed(x)));
            d.decode_all(second, |x| out.push(Decoded::Mixed(x)));
        }
        Family::Hw5 => {
            let mut d = hw5::Decoder::new();
            d.feed(first, |x| out.push(Decoded::Hw5(x)));
            d.line_silent(frames, |x| out.push(Decoded::Hw5(x)));
            d.decode_all(second, |x| out.push(Decoded::Hw5(x)));
        }
        Family::HwV4 => {
            let mut d = v4::Decoder::new();
            d.feed(first, |x| out.push(Decoded::HwV4(x)));
            d.line_silent(frames, |x| out.push(Decoded::HwV4(x)));
            d.decode_all(second, |x| out.push(Decoded::HwV4(x)));
        }
        Family::HwV3 => {
            let mut d = v3::Decoder::new();
            d.feed(first, |x| out.push(Decoded::HwV3(x)));
            d.line_silent(frames, |x| out.push(Decoded::HwV3(x)));
            d.decode_all(second, |x| out.push(Decoded::HwV3(x)));
        }
    }
    out
}

/// Asserts that every other path gives what `decode_all` gives: a byte at a time and in
/// chunks of each of `sizes`, the same frames in the same order and the same final state.
fn assert_every_path_agrees(bytes: &[u8], sizes: &[usize]) -> (Vec<Decoded>, State) {
    let reference = bulk(bytes);
    let (frames, end, _) = bytewise(bytes);
    assert_eq!((frames, end), reference, "byte at a time");
    for &size in sizes {
        let mut cuts: Vec<usize> = (0..bytes.len()).step_by(size).collect();
        cuts.push(bytes.len());
        let (frames, end, _) = chunked(bytes, &cuts);
        assert_eq!((frames, end), reference, "chunks of {size}");
    }
    reference
}

// ---------------------------------------------------------------------------------------------
// Streams made by the codec's encoders
// ---------------------------------------------------------------------------------------------

fn foc_stream(packets: std::ops::Range<u16>) -> Vec<u8> {
    packets
        .flat_map(|packet| {
            DataFrame {
                packet,
                throttle_in_raw: 300 + packet % 50,
                voltage_raw: 250,
                erpm_raw: packet.wrapping_mul(7),
                ..Default::default()
            }
            .encode()
        })
        .collect()
}

fn datalink_stream(counters: std::ops::Range<u16>) -> Vec<u8> {
    counters
        .flat_map(|counter| {
            let mut frame = datalink::HubFrame::new(counter);
            for (c, slot) in frame.slots.iter_mut().enumerate().take(4) {
                *slot = Some(DataFrame {
                    packet: counter.wrapping_mul(4) + c as u16,
                    voltage_raw: 240 + c as u16,
                    ..Default::default()
                });
            }
            frame.encode()
        })
        .collect()
}

fn v3_stream(counters: std::ops::Range<u32>) -> Vec<u8> {
    counters
        .flat_map(|counter| {
            v3::V3Frame {
                counter: counter & 0xFF_FFFF,
                throttle_in_raw: (counter % 200) as u16,
                pwm_out_raw: (counter % 180) as u16,
                period_us: 1500 + (counter % 300) as u16,
            }
            .encode()
        })
        .collect()
}

fn v4_data(counter: u32) -> v4::DataFrame {
    v4::DataFrame {
        counter,
        throttle_in_raw: (counter % 900) as u16,
        throttle_out_raw: (counter % 800) as u16,
        erpm: 9000 + counter % 50_000,
        voltage_adc: 1365,
        current_adc: 120,
        temp_adc: 2200,
        temp2_adc: 2100,
    }
}

const V4_INFO: v4::InfoFrame = v4::InfoFrame {
    full_scale: 1000,
    v1: 8,
    v2: 91,
    i1: 0,
    i2: 1,
    i3: 0,
    t1: 0x21,
    t2: 0x21,
};

/// Running: data frames back to back.
fn v4_running(counters: std::ops::Range<u32>) -> Vec<u8> {
    counters
        .flat_map(|c| v4_data(c & 0xFF_FFFF).encode())
        .collect()
}

/// Idle: an info frame, then a data frame with its trailer, in turn.
fn v4_idle(counters: std::ops::Range<u32>) -> Vec<u8> {
    let mut out = Vec::new();
    for c in counters {
        out.extend_from_slice(&V4_INFO.encode());
        out.extend_from_slice(&v4_data(c & 0xFF_FFFF).encode_with_trailer());
    }
    out
}

const HW5_VECTORS: &str = include_str!("../../../testdata/hw5/vectors.txt");

fn hex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}

/// The bytes of the vector lines tagged `tag` (`telemetry`, `frame`: the other kinds).
fn hw5_vectors(tag: &str) -> Vec<Vec<u8>> {
    HW5_VECTORS
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split(' ').collect::<Vec<_>>())
        .filter(|w| w[0] == tag)
        .map(|w| hex(if tag == "frame" { w[2] } else { w[1] }))
        .collect()
}

fn hw5_frame(k: u32) -> [u8; hw5::TELEMETRY_LEN] {
    hw5::TelemetryFrame {
        throttle: (k % 101) as u8,
        erpm_raw: (k.wrapping_mul(3) % 60_000) as u16,
        voltage_raw: 504,
        current_raw: (k % 400) as u16,
        esc_temp: 48,
        bec_temp: 41,
        motor_temp: 55,
        bec_voltage_raw: 84,
        bec_current_raw: 12,
        ..Default::default()
    }
    .encode()
}

/// HW5: `n` telemetry frames made by the encoder.
fn hw5_stream(n: u32) -> Vec<u8> {
    (0..n).flat_map(hw5_frame).collect()
}

/// HW5 as a configurator's session: encoder frames, then the telemetry vectors, with the
/// vectors of the other kinds (requests and answers) between them.
fn hw5_session() -> Vec<u8> {
    let mut out = hw5_stream(40);
    let others = hw5_vectors("frame");
    for (k, t) in hw5_vectors("telemetry").iter().enumerate() {
        out.extend_from_slice(t);
        if let Some(o) = others.get(k) {
            out.extend_from_slice(o);
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// 1. Each format alone: what its own decoder finds
// ---------------------------------------------------------------------------------------------

/// Asserts that `detect` finds in `bytes` exactly what `family`'s own decoder finds, locks onto
/// `family`, and ends with that decoder's statistics (the others' counting every byte as
/// skipped, with no frame); returns the frames.
fn assert_as_own_decoder(name: &str, bytes: &[u8], family: Family) -> Vec<Decoded> {
    let (frames, end) = assert_every_path_agrees(bytes, &[2, 7, 24, 63, 64, 65, 1000]);
    assert_eq!(frames, own(family, bytes), "{name}: frames");
    assert_eq!(end.locked, Some(family), "{name}");
    assert_eq!(end.last_locked, Some(family), "{name}");
    assert_eq!(end.bytes, bytes.len() as u64, "{name}");
    assert_eq!(end.buffered, 0, "{name}");
    let len = bytes.len() as u64;
    if family == Family::Mixed {
        let mut d = mixed::Decoder::new();
        d.decode_all(bytes, |_| {});
        assert_eq!(
            &end.mixed,
            d.stats(),
            "{name}: HW-FOC and DataLink statistics"
        );
    } else {
        assert_eq!(end.mixed.esc.bytes_skipped(), len, "{name}");
        assert_eq!(end.mixed.hub.bytes_skipped(), len, "{name}");
        assert_eq!((end.mixed.esc.frames(), end.mixed.hub.frames()), (0, 0));
    }
    if family == Family::Hw5 {
        let mut d = hw5::Decoder::new();
        d.decode_all(bytes, |_| {});
        assert_eq!(&end.hw5, d.stats(), "{name}: HW5 statistics");
    } else {
        assert_eq!(end.hw5.bytes(), len, "{name}");
        assert_eq!(end.hw5.bytes_skipped(), len, "{name}");
    }
    if family == Family::HwV4 {
        let mut d = v4::Decoder::new();
        d.decode_all(bytes, |_| {});
        assert_eq!(&end.v4, d.stats(), "{name}: V4 statistics");
    } else {
        assert_eq!(
            (end.v4.bytes(), end.v4.bytes_skipped()),
            (len, len),
            "{name}"
        );
        assert_eq!((end.v4.frames(), end.v4.info_frames()), (0, 0), "{name}");
    }
    if family == Family::HwV3 {
        let mut d = v3::Decoder::new();
        d.decode_all(bytes, |_| {});
        assert_eq!(&end.v3, d.stats(), "{name}: V3 statistics");
    } else {
        assert_eq!(
            (end.v3.bytes(), end.v3.bytes_skipped()),
            (len, len),
            "{name}"
        );
        assert_eq!(end.v3.frames(), 0, "{name}");
    }
    frames
}

#[test]
fn xrotor_capture_as_the_hwfoc_decoder() {
    let bytes = load(XROTOR);
    let frames = assert_as_own_decoder("XRotor", &bytes, Family::Mixed);
    // HW-FOC's own decoder (not the mixed one) finds the same frames, with the same statistics.
    let mut d = foc::Decoder::new();
    let mut esc = Vec::new();
    d.decode_all(&bytes, |x| esc.push(Decoded::Mixed(mixed::Decoded::Esc(x))));
    assert_eq!(frames, esc);
    assert_eq!(frames.len(), 248 + 12);
    let mut detect = Decoder::new();
    detect.decode_all(&bytes, |_| {});
    let s = detect.mixed_stats();
    assert_eq!(&s.esc, d.stats());
    assert_eq!((s.esc.frames(), s.esc.info_frames()), (248, 12));
    assert_eq!((s.esc.checksum_failures(), s.esc.lost_packets()), (2, 2));
    assert_eq!(s.esc.bytes_skipped(), 1 + 2 * 24 + 77);
    assert_eq!(s.hub.frames(), 0);
}

#[test]
fn platinum_pro_v3_capture_as_the_v3_decoder() {
    let bytes = load(PLATINUM_PRO_V3);
    let frames = assert_as_own_decoder("Platinum Pro V3", &bytes, Family::HwV3);
    assert_eq!(frames.len(), 699);
    for (k, d) in frames.iter().enumerate() {
        let Decoded::HwV3(d) = d else {
            panic!("frame {k}: {d:?}")
        };
        assert_eq!((d.offset, d.frame.counter), (10 * k as u64, k as u32));
    }
    let mut detect = Decoder::new();
    detect.decode_all(&bytes, |_| {});
    let s = detect.stats::<hwfoc::v3::Scanner>();
    assert_eq!((s.frames(), s.bytes(), s.bytes_skipped()), (699, 6990, 0));
    assert_eq!(
        (s.syncs(), s.rejected(), s.last_counter()),
        (1, 0, Some(698))
    );
    let c = s.counter();
    assert_eq!((c.lost(), c.duplicates(), c.restarts()), (0, 0, 0));
}

#[test]
fn platinum_v4_capture_as_the_v4_decoder() {
    let bytes = load(PLATINUM_V4);
    let frames = assert_as_own_decoder("Platinum V4", &bytes, Family::HwV4);
    let mut counters = Vec::new();
    let mut infos = 0;
    for d in &frames {
        match d {
            Decoded::HwV4(v4::Decoded {
                frame: v4::V4Frame::Data(x),
                ..
            }) => counters.push(x.packet()),
            Decoded::HwV4(v4::Decoded {
                frame: v4::V4Frame::Info(_),
                ..
            }) => infos += 1,
            other => panic!("{other:?}"),
        }
    }
    assert_eq!(counters, (817..=1113).collect::<Vec<u32>>());
    assert_eq!(infos, 26);
    let mut detect = Decoder::new();
    detect.decode_all(&bytes, |_| {});
    let s = detect.stats::<hwfoc::v4::Scanner>();
    assert_eq!((s.frames(), s.info_frames(), s.trailers()), (297, 26, 26));
    assert_eq!((s.bytes(), s.bytes_skipped(), s.syncs()), (6007, 0, 1));
    let c = s.counter();
    assert_eq!((c.lost(), c.duplicates(), c.restarts()), (0, 0, 0));
}

#[test]
fn hw5_stream_as_the_hw5_decoder() {
    let bytes = hw5_session();
    let frames = assert_as_own_decoder("HW5", &bytes, Family::Hw5);
    // The 52 telemetry vectors: 40 with a voltage out of HW5's range, rejected.
    assert_eq!(frames.len(), 40 + 12);
    let mut detect = Decoder::new();
    detect.decode_all(&bytes, |_| {});
    let s = detect.stats::<hwfoc::hw5::Scanner>();
    assert_eq!((s.telemetry_frames(), s.other_frames()), (52, 22));
    let rejected = 40 * hw5::TELEMETRY_LEN as u64;
    assert_eq!((s.bytes_skipped(), s.rejected()), (rejected, 40));
}

#[test]
fn datalink_stream_as_the_datalink_decoder() {
    let bytes = datalink_stream(100..160);
    let frames = assert_as_own_decoder("DataLink", &bytes, Family::Mixed);
    let mut d = datalink::Decoder::new();
    let mut hub = Vec::new();
    d.decode_all(&bytes, |x| hub.push(Decoded::Mixed(mixed::Decoded::Hub(x))));
    assert_eq!(frames, hub);
    assert_eq!(frames.len(), 60);
    let mut detect = Decoder::new();
    detect.decode_all(&bytes, |_| {});
    assert_eq!(&detect.mixed_stats().hub, d.stats());
    assert_eq!(detect.mixed_stats().hub.bytes_skipped(), 0);
}

// ---------------------------------------------------------------------------------------------
// 2. Any chunking
// ---------------------------------------------------------------------------------------------

/// A piece of a test stream.
#[derive(Debug, Clone)]
enum Piece {
    Foc(u16, u8),
    DataLink(u16, u8),
    V3(u32, u8),
    V4Running(u32, u8),
    V4Idle(u32, u8),
    Hw5(u32, u8),
    /// Bytes rich in the formats' marks (`9B`, `FE`, `01`, `B9`, `FD`, `16`, `9E`).
    Garbage(Vec<u8>),
    /// The first `cut` bytes of the next piece's first frame (of the kind given).
    Cut(u8, usize),
}

fn piece() -> impl Strategy<Value = Piece> {
    let mark = prop_oneof![
        Just(0x9Bu8),
        Just(0xFE),
        Just(0x01),
        Just(0xB9),
        Just(0xFD),
        Just(0x16),
        Just(0x9E),
        Just(0x00),
        any::<u8>()
    ];
    prop_oneof![
        (any::<u16>(), 1..12u8).prop_map(|(a, n)| Piece::Foc(a, n)),
        (any::<u16>(), 1..4u8).prop_map(|(a, n)| Piece::DataLink(a, n)),
        (0..0xFF_FFFFu32, 1..14u8).prop_map(|(a, n)| Piece::V3(a, n)),
        (0..0xFF_FFFFu32, 1..10u8).prop_map(|(a, n)| Piece::V4Running(a, n)),
        (0..0xFF_FFFFu32, 1..6u8).prop_map(|(a, n)| Piece::V4Idle(a, n)),
        (any::<u32>(), 1..6u8).prop_map(|(a, n)| Piece::Hw5(a, n)),
        vec(mark, 0..300).prop_map(Piece::Garbage),
        (0..6u8, 1..40usize).prop_map(|(k, n)| Piece::Cut(k, n)),
    ]
}

fn build(pieces: &[Piece]) -> Vec<u8> {
    let mut out = Vec::new();
    for p in pieces {
        match p {
            Piece::Foc(a, n) => out.extend(foc_stream(*a..a.saturating_add(u16::from(*n)))),
            Piece::DataLink(a, n) => {
                out.extend(datalink_stream(*a..a.saturating_add(u16::from(*n))))
            }
            Piece::V3(a, n) => out.extend(v3_stream(*a..a + u32::from(*n))),
            Piece::V4Running(a, n) => out.extend(v4_running(*a..a + u32::from(*n))),
            Piece::V4Idle(a, n) => out.extend(v4_idle(*a..a + u32::from(*n))),
            Piece::Hw5(a, n) => {
                out.extend((*a..a.saturating_add(u32::from(*n))).flat_map(hw5_frame))
            }
            Piece::Garbage(g) => out.extend_from_slice(g),
            Piece::Cut(k, n) => {
                let frame = match k {
                    0 => foc_stream(7..8),
                    1 => datalink_stream(7..8),
                    2 => v3_stream(7..8),
                    3 => v4_running(7..8),
                    4 => V4_INFO.encode().to_vec(),
                    _ => hw5_stream(1),
                };
                out.extend_from_slice(&frame[..(*n).min(frame.len() - 1)]);
            }
        }
    }
    out
}

/// The same frames: each family's in the same order, and the same ones in all. (Frames of two
/// families found in one slice while detecting come out family by family within each chunk
/// given: their interleaving depends on the chunking, see `hwfoc::detect`.)
fn assert_same_frames(
    got: &[Decoded],
    expected: &[Decoded],
    what: &str,
) -> Result<(), TestCaseError> {
    for family in Family::ALL {
        prop_assert_eq!(
            of(got, family),
            of(expected, family),
            "{}: {:?}",
            what,
            family
        );
    }
    prop_assert_eq!(sorted(got), sorted(expected), "{}", what);
    Ok(())
}

/// Asserts that each format's statistics account for every byte (in a frame, or skipped) and
/// count the frames given; HW-FOC's and DataLink's when only one of them was found.
fn assert_every_byte_counted(frames: &[Decoded], end: &State, len: usize) {
    let len = len as u64;
    let count = |f: Family| frames.iter().filter(|d| d.family() == f).count() as u64;
    let s = &end.v3;
    assert_eq!(s.bytes(), len);
    assert_eq!(
        10 * u64::from(s.frames()) + s.bytes_skipped(),
        len,
        "V3: {s}"
    );
    assert_eq!(u64::from(s.frames()), count(Family::HwV3));
    let s = &end.v4;
    let in_frames = 19 * u64::from(s.frames()) + 13 * u64::from(s.info_frames());
    assert_eq!(
        in_frames + u64::from(s.trailers()) + s.bytes_skipped(),
        len,
        "V4: {s}"
    );
    assert_eq!(u64::from(s.frames() + s.info_frames()), count(Family::HwV4));
    let s = &end.hw5;
    assert_eq!(s.frame_bytes() + s.bytes_skipped(), len, "HW5: {s}");
    assert_eq!(u64::from(s.telemetry_frames()), count(Family::Hw5));
    let (esc, hub) = (&end.mixed.esc, &end.mixed.hub);
    assert_eq!((esc.bytes(), hub.bytes()), (len, len));
    if hub.frames() == 0 {
        let in_frames = 24 * u64::from(esc.frames()) + 77 * u64::from(esc.info_frames());
        assert_eq!(in_frames + esc.bytes_skipped(), len, "HW-FOC: {esc}");
    }
    if esc.frames() + esc.info_frames() == 0 {
        let in_frames = datalink::FRAME_LEN as u64 * u64::from(hub.frames());
        assert_eq!(in_frames + hub.bytes_skipped(), len, "DataLink: {hub}");
    }
}

/// A decoder that locks at a slice's end while another holds a candidate, the stream ending
/// there: at the flush the other drops it, counted as skipped (it held 6 bytes that no
/// statistic counted, found by the fuzz target `detect`).
#[test]
fn a_flush_when_locked_counts_every_byte_of_every_format() {
    let mut bytes = foc_stream(3..4);
    bytes.resize(SLICE as usize - 6, 0);
    // The first 6 bytes of a plausible V3 frame: V3's decoder holds them.
    bytes.extend_from_slice(&v3_stream(9..10)[..6]);
    let (frames, end) = assert_every_path_agrees(&bytes, &[1, 7]);
    assert_eq!(end.locked, Some(Family::Mixed));
    assert_eq!(frames.len(), 1);
    assert_eq!(end.v3.bytes_skipped(), SLICE);
    assert_every_byte_counted(&frames, &end, bytes.len());
    // Fed on after the flush, the decoder goes on as it was.
    let mut d = Decoder::new();
    d.decode_all(&bytes, |_| {});
    let mut n = 0;
    d.decode_all(&foc_stream(4..6), |_| n += 1);
    assert_eq!((n, d.locked()), (2, Some(Family::Mixed)));
    assert_eq!(d.stats::<hwfoc::v3::Scanner>().bytes_skipped(), SLICE + 48);
}

/// Frames of two formats in one slice while detecting: format by format in a chunk holding
/// the slice, in the order decided a byte at a time (each format's in the same order).
#[test]
fn two_formats_in_one_slice_interleave_as_the_chunks_say() {
    // A V3 chain (decided on byte 30) and an HW-FOC frame after it (decided on byte 54).
    let mut bytes = v3_stream(0..3);
    bytes.extend(foc_stream(9..10));
    let (frames, end) = bulk(&bytes);
    let families: Vec<Family> = frames.iter().map(Decoded::family).collect();
    use Family::{HwV3, Mixed};
    assert_eq!(families, [Mixed, HwV3, HwV3, HwV3]);
    let (by_byte, by_byte_end, _) = bytewise(&bytes);
    let families: Vec<Family> = by_byte.iter().map(Decoded::family).collect();
    assert_eq!(families, [HwV3, HwV3, HwV3, Mixed]);
    assert_same_frames(&by_byte, &frames, "byte at a time").unwrap();
    // The lock is the same: HW-FOC first among the formats found in the slice.
    assert_eq!((end.locked, by_byte_end), (Some(Mixed), end));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Any mix of formats, garbage and cut frames, fed in random chunks and a byte at a time:
    /// the frames of `decode_all` (each family's in the same order), the same final state,
    /// and after every chunk the state the byte-at-a-time decoder had after the same byte.
    #[test]
    fn any_stream_in_any_chunking(
        pieces in vec(piece(), 1..40),
        picks in vec(any::<Index>(), 0..60),
    ) {
        let bytes = build(&pieces);
        let (frames, end) = bulk(&bytes);
        let (by_byte, by_byte_end, states) = bytewise(&bytes);
        assert_same_frames(&by_byte, &frames, "byte at a time")?;
        prop_assert_eq!(&by_byte_end, &end);
        let cuts = cut_points(bytes.len(), &picks);
        let (got, got_end, got_states) = chunked(&bytes, &cuts);
        assert_same_frames(&got, &frames, &format!("cuts {cuts:?}"))?;
        prop_assert_eq!(&got_end, &end);
        assert_every_byte_counted(&frames, &end, bytes.len());
        for (at, s) in got_states {
            if at > 0 {
                prop_assert_eq!(&s, &states[at - 1], "after byte {}", at);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// 3. A stream that changes format
// ---------------------------------------------------------------------------------------------

/// A format as a stream of a given number of frames.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Format {
    Foc,
    DataLink,
    V3,
    V4Running,
    V4Idle,
    Hw5,
}

impl Format {
    const ALL: [Format; 6] = [
        Format::Foc,
        Format::DataLink,
        Format::V3,
        Format::V4Running,
        Format::V4Idle,
        Format::Hw5,
    ];

    fn family(self) -> Family {
        match self {
            Format::Foc | Format::DataLink => Family::Mixed,
            Format::V3 => Family::HwV3,
            Format::V4Running | Format::V4Idle => Family::HwV4,
            Format::Hw5 => Family::Hw5,
        }
    }

    /// A stream of about `len` bytes, its first counter `start`.
    fn stream(self, start: u32, len: usize) -> Vec<u8> {
        let per = self.period();
        let n = len.div_ceil(per) as u32;
        let s16 = start as u16;
        match self {
            Format::Foc => foc_stream(s16..s16 + n as u16),
            Format::DataLink => datalink_stream(s16..s16 + n as u16),
            Format::V3 => v3_stream(start..start + n),
            Format::V4Running => v4_running(start..start + n),
            Format::V4Idle => v4_idle(start..start + n),
            Format::Hw5 => hw5_stream(n),
        }
    }

    /// Bytes per frame (per pair for V4 idle).
    fn period(self) -> usize {
        match self {
            Format::Foc => 24,
            Format::DataLink => datalink::FRAME_LEN,
            Format::V3 => v3::FRAME_LEN,
            Format::V4Running => v4::DATA_FRAME_LEN,
            Format::V4Idle => v4::INFO_FRAME_LEN + v4::SLOW_DATA_FRAME_LEN,
            Format::Hw5 => hw5::TELEMETRY_LEN,
        }
    }
}

/// Format `a` for 3000 bytes, then `b` for three blocks and 1000 bytes (with other counters), with a line silence
/// between them or not: the stream, where `b` starts, and what each one's own decoder finds
/// in its part (offsets in the whole stream).
fn switch(a: Format, b: Format) -> (Vec<u8>, usize, Vec<Decoded>, Vec<Decoded>) {
    let first = a.stream(100, 3000);
    let second = b.stream(5000, 3 * RELOCK_AFTER as usize + 1000);
    let at = first.len();
    let mine = own(a.family(), &first);
    let theirs: Vec<Decoded> = own(b.family(), &second)
        .into_iter()
        .map(|d| shifted(d, at as u64))
        .collect();
    assert!(!mine.is_empty() && !theirs.is_empty(), "{a:?} {b:?}");
    let mut bytes = first;
    bytes.extend_from_slice(&second);
    (bytes, at, mine, theirs)
}

#[test]
fn after_a_line_silence_every_frame_of_both_formats() {
    for a in Format::ALL {
        for b in Format::ALL {
            let (bytes, at, mine, theirs) = switch(a, b);
            for silence in [0, 3] {
                let mut d = Decoder::new();
                let mut got = Vec::new();
                d.feed(&bytes[..at], |x| got.push(x));
                assert_eq!(d.locked(), Some(a.family()), "{a:?}");
                d.line_silent_each(silence, silence, |x| got.push(x));
                assert_eq!(d.locked(), None, "{a:?} {b:?}: detecting after a silence");
                // A chunking that does not meet the slices.
                for c in bytes[at..].chunks(37) {
                    d.feed(c, |x| got.push(x));
                }
                d.flush(|x| got.push(x));
                let expected: Vec<Decoded> = if a.family() == b.family() {
                    // One decoder reads both, its state (a V4 info frame adopted) carried on.
                    own_with_silence(a.family(), &bytes, at, silence)
                } else {
                    mine.iter().chain(&theirs).copied().collect()
                };
                assert_eq!(got, expected, "{a:?} then {b:?}, silence {silence}");
                assert_eq!(d.locked(), Some(b.family()), "{a:?} then {b:?}");
            }
        }
    }
}

#[test]
fn without_a_silence_the_new_format_is_found_within_two_blocks_and_a_slice() {
    let mut worst = 0;
    for a in Format::ALL {
        for b in Format::ALL {
            if a.family() == b.family() {
                continue; // one decoder reads both: nothing to detect again
            }
            let (bytes, at, mine, theirs) = switch(a, b);
            let (got, end) = assert_every_path_agrees(&bytes, &[1, 64, 1000]);
            let before: Vec<Decoded> = got
                .iter()
                .filter(|d| d.offset() < at as u64)
                .copied()
                .collect();
            assert_eq!(before, mine, "{a:?} then {b:?}: every frame of the first");
            let after: Vec<Decoded> = got
                .iter()
                .filter(|d| d.offset() >= at as u64)
                .copied()
                .collect();
            // The second format's frames: from some point on, every one its own decoder finds
            // (a V4 data frame without the info frame adopted: the decoder started later).
            let after: Vec<Decoded> = after.into_iter().map(without_info).collect();
            let theirs: Vec<Decoded> = theirs.into_iter().map(without_info).collect();
            let Some(first) = after.first() else {
                panic!("{a:?} then {b:?}: nothing of the second found")
            };
            let k = theirs
                .iter()
                .position(|d| d == first)
                .unwrap_or_else(|| panic!("{a:?} then {b:?}: {first:?} is not the second's"));
            assert_eq!(after, theirs[k..], "{a:?} then {b:?}");
            let late = first.offset() - at as u64;
            let bound = 2 * RELOCK_AFTER + 3 * b.period() as u64 + SLICE;
            assert!(
                late <= bound,
                "{a:?} then {b:?}: first frame {late} bytes after the switch (> {bound})"
            );
            // Every frame starting two blocks after the switch is found.
            assert!(
                theirs[..k]
                    .iter()
                    .all(|d| d.offset() < at as u64 + 2 * RELOCK_AFTER),
                "{a:?} then {b:?}: a frame lost two blocks after the switch"
            );
            assert_eq!(end.locked, Some(b.family()));
            worst = worst.max(late);
        }
    }
    println!(
        "without a silence, the new format's first frame at most {worst} bytes after the switch"
    );
}

/// What every frame of a stream of format `a` for about `first` bytes, then `b` for about
/// `second` (other counters), is when each format's own decoder reads its part: one decoder
/// reads the whole stream when both are of its family.
fn truth(a: Format, b: Format, first: usize, second: usize) -> (Vec<u8>, Vec<Decoded>) {
    let mut bytes = a.stream(100, first);
    let at = bytes.len();
    let later = b.stream(5000, second);
    bytes.extend_from_slice(&later);
    if a.family() == b.family() {
        return (bytes.clone(), own(a.family(), &bytes));
    }
    let mut frames = own(a.family(), &bytes[..at]);
    frames.extend(
        own(b.family(), &later)
            .into_iter()
            .map(|d| shifted(d, at as u64)),
    );
    (bytes, frames)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// Every pair of formats, in both orders, the change at a random offset, fed in random
    /// chunks, without a silence: every frame of both formats (each format's own decoder's, in
    /// its order) and no other.
    #[test]
    fn a_change_of_format_loses_no_frame(
        a in 0..Format::ALL.len(),
        b in 0..Format::ALL.len(),
        first in 60..3 * RELOCK_AFTER as usize,
        second in 60..3 * RELOCK_AFTER as usize,
        picks in vec(any::<Index>(), 0..40),
    ) {
        let (a, b) = (Format::ALL[a], Format::ALL[b]);
        let (bytes, expected) = truth(a, b, first, second);
        let cuts = cut_points(bytes.len(), &picks);
        let (got, _, _) = chunked(&bytes, &cuts);
        let got: Vec<Decoded> = got.into_iter().map(without_info).collect();
        let expected: Vec<Decoded> = expected.into_iter().map(without_info).collect();
        assert_same_frames(&got, &expected, &format!("{a:?} then {b:?} at {first}"))?;
    }
}

// ---------------------------------------------------------------------------------------------
// 4. Random bytes
// ---------------------------------------------------------------------------------------------

/// Random bytes of which about one in eight is each of `9B`, `FE`, `01`, `B9`.
fn rich(rng: &mut Rng, n: usize) -> Vec<u8> {
    (0..n)
        .map(|_| {
            let x = rng.next();
            match x >> 61 {
                0 => 0x9B,
                1 => 0xFE,
                2 => 0x01,
                3 => 0xB9,
                _ => x as u8,
            }
        })
        .collect()
}

#[test]
fn random_bytes_never_lock() {
    const LEN: usize = 8_000_000;
    let mut rng = Rng(0x5EED_DE7E);
    for (kind, bytes) in [
        ("uniform", rng.uniform(LEN)),
        ("rich in 9B, FE, 01 and B9", rich(&mut rng, LEN)),
    ] {
        let mut d = Decoder::new();
        let mut frames = 0;
        let mut ever_locked = false;
        for c in bytes.chunks(4096) {
            d.feed(c, |_| frames += 1);
            ever_locked |= d.locked().is_some();
        }
        d.flush(|_| frames += 1);
        assert_eq!(frames, 0, "{kind}");
        assert!(!ever_locked && d.last_locked().is_none(), "{kind}");
        let n = LEN as u64;
        assert_eq!(d.mixed_stats().esc.bytes_skipped(), n, "{kind}");
        assert_eq!(d.mixed_stats().hub.bytes_skipped(), n, "{kind}");
        assert_eq!(
            d.stats::<hwfoc::hw5::Scanner>().bytes_skipped(),
            n,
            "{kind}"
        );
        assert_eq!(d.stats::<hwfoc::v4::Scanner>().bytes_skipped(), n, "{kind}");
        assert_eq!(d.stats::<hwfoc::v3::Scanner>().bytes_skipped(), n, "{kind}");
    }
}

// ---------------------------------------------------------------------------------------------
// 5. How soon it locks
// ---------------------------------------------------------------------------------------------

/// Bytes from the first one to the first frame handed on and to the lock (`None`: never).
fn detection(bytes: &[u8]) -> (Option<usize>, Option<usize>, Option<Family>) {
    let mut d = Decoder::new();
    let mut first = None;
    for (i, &b) in bytes.iter().enumerate() {
        let mut found = false;
        d.feed(&[b], |_| found = true);
        if found && first.is_none() {
            first = Some(i + 1);
        }
        if let Some(f) = d.locked() {
            return (first, Some(i + 1), Some(f));
        }
    }
    (first, None, None)
}

fn ms_at(bytes: usize, baud: u32) -> f64 {
    bytes as f64 * 10_000.0 / f64::from(baud)
}

/// What the spec says of a format's detection, and the format's figures.
struct Spec {
    family: Family,
    baud: u32,
    /// The bytes of the frames the spec names.
    spec_bytes: usize,
    /// The spec's time (0 for "one frame").
    spec_ms: f64,
    /// Bytes per frame (or per pair of frames).
    period: usize,
    /// The longest frame.
    longest: usize,
}

/// One stream's detection: from its start and the worst over starts in its first `period`
/// bytes; asserted within `spec_bytes` (the frames the spec names) plus a slice from the
/// start, and from a start in the middle of a frame within the `period` to reach a frame's
/// start, the spec's frames or the `longest` frame that may come first, and a slice; for the
/// real captures, within the spec's time plus the time the slice after those frames took on
/// the wire.
fn measure(name: &str, bytes: &[u8], times: Option<&[f64]>, spec: Spec) {
    let Spec {
        family,
        baud,
        spec_bytes,
        spec_ms,
        period,
        longest,
    } = spec;
    let (first, lock, f) = detection(bytes);
    let (first, lock) = (first.unwrap(), lock.unwrap());
    assert_eq!(f, Some(family), "{name}");
    assert!(first <= lock, "{name}");
    assert!(
        lock <= spec_bytes + SLICE as usize,
        "{name}: locked after {lock} bytes"
    );
    let real = |n: usize, from: usize| times.map(|t| (t[from + n - 1] - t[from]) * 1000.0);
    println!(
        "{name}: first frame after {first} bytes ({:.1} ms at {baud} baud{}), locked after {lock} \
         bytes ({:.1} ms{})",
        ms_at(first, baud),
        real(first, 0).map_or(String::new(), |m| format!(
            ", {m:.1} ms on the capture's wire"
        )),
        ms_at(lock, baud),
        real(lock, 0).map_or(String::new(), |m| format!(", {m:.1} ms on the wire")),
    );
    if let (Some(lock_ms), Some(t)) = (real(lock, 0), times) {
        // A checksummed format's spec is one frame: the time its bytes took.
        let spec_ms = spec_ms.max(real(spec_bytes, 0).unwrap_or(0.0));
        let slice_ms = (t[spec_bytes + SLICE as usize - 1] - t[spec_bytes - 1]) * 1000.0;
        assert!(
            lock_ms <= spec_ms + slice_ms,
            "{name}: {lock_ms:.1} ms > {spec_ms:.1} + {slice_ms:.1} ms"
        );
    }
    // Worst over every start in the first period (a receiver connected mid-frame).
    let (mut worst_first, mut worst_lock, mut worst_ms) = ((0, 0), (0, 0), 0.0f64);
    for start in 0..period.min(bytes.len()) {
        let (first, lock, f) = detection(&bytes[start..]);
        let (first, lock) = (first.unwrap(), lock.unwrap());
        assert_eq!(f, Some(family), "{name} from byte {start}");
        assert!(
            lock <= period + spec_bytes.max(longest) + SLICE as usize,
            "{name} from byte {start}: locked after {lock} bytes"
        );
        worst_first = worst_first.max((first, start));
        worst_lock = worst_lock.max((lock, start));
        if let Some(ms) = real(lock, start) {
            worst_ms = worst_ms.max(ms);
        }
    }
    println!(
        "{name}, from any of its first {period} bytes: first frame after at most {} bytes \
         ({:.1} ms at {baud} baud), locked after at most {} bytes ({:.1} ms{})",
        worst_first.0,
        ms_at(worst_first.0, baud),
        worst_lock.0,
        ms_at(worst_lock.0, baud),
        times.map_or(String::new(), |_| format!(
            ", {worst_ms:.1} ms on the capture's wire"
        )),
    );
}

#[test]
fn detection_times() {
    let (times, bytes) = load_timed(XROTOR);
    measure(
        "XRotor (HW-FOC)",
        &bytes,
        Some(&times),
        Spec {
            family: Family::Mixed,
            baud: 19_200,
            spec_bytes: 24,
            spec_ms: 0.0,
            period: 24 + 77,
            longest: 77,
        },
    );
    let (times, bytes) = load_timed(PLATINUM_PRO_V3);
    measure(
        "Platinum Pro V3",
        &bytes,
        Some(&times),
        Spec {
            family: Family::HwV3,
            baud: 19_200,
            spec_bytes: 30,
            spec_ms: 60.0,
            period: 10,
            longest: 10,
        },
    );
    let (times, bytes) = load_timed(PLATINUM_V4);
    // Idle: an info frame and the data frame after it (1 s), running: three data frames.
    measure(
        "Platinum V4 (idle)",
        &bytes,
        Some(&times),
        Spec {
            family: Family::HwV4,
            baud: 19_200,
            spec_bytes: 13 + 19,
            spec_ms: 1000.0,
            period: 33,
            longest: 20,
        },
    );
    let running = v4_running(500..600);
    measure(
        "V4 running (encoder)",
        &running,
        None,
        Spec {
            family: Family::HwV4,
            baud: 19_200,
            spec_bytes: 57,
            spec_ms: 150.0,
            period: 19,
            longest: 19,
        },
    );
    let hw5 = hw5_session();
    measure(
        "HW5 (encoder)",
        &hw5,
        None,
        Spec {
            family: Family::Hw5,
            baud: 115_200,
            spec_bytes: 32,
            spec_ms: 0.0,
            period: 32,
            longest: 32,
        },
    );
    let hub = datalink_stream(0..20);
    measure(
        "DataLink (encoder)",
        &hub,
        None,
        Spec {
            family: Family::Mixed,
            baud: 115_200,
            spec_bytes: 160,
            spec_ms: 0.0,
            period: 160,
            longest: 160,
        },
    );
}
