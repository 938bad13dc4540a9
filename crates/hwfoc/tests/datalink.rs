//! Property and unit tests of the DataLink V2 codec (`hwfoc::datalink`): encode/parse identity,
//! both length bytes, bad and duplicate channels, chunking independence, resynchronisation after
//! garbage, single-bit error detection, and bulk == streaming, checked against a naive reference
//! scanner written here from the protocol description.

mod common;

use common::{cut_points, data_frame, streamed_bytewise};
use hwfoc::Status;
use hwfoc::counters::MAX_PACKET_GAP;
use hwfoc::datalink::{self, CHANNELS, FRAME_LEN, FrameReport, LengthByte, RECORD_LEN, RECORDS_AT};
use hwfoc::foc::DataFrame;
use hwfoc::wire::{Checksum, crc16_xmodem};
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::Index;

// ---------------------------------------------------------------------------------------------
// Generators
// ---------------------------------------------------------------------------------------------

/// A slot: empty, an ESC, or (rarely) an ESC whose every field is zero, which the wire cannot
/// tell from an empty slot.
fn slot() -> impl Strategy<Value = Option<DataFrame>> {
    prop_oneof![
        3 => Just(None),
        6 => data_frame().prop_map(Some),
        1 => Just(Some(DataFrame::default())),
    ]
}

fn datalink_frame() -> impl Strategy<Value = datalink::HubFrame> {
    (
        any::<u16>(),
        [
            slot(),
            slot(),
            slot(),
            slot(),
            slot(),
            slot(),
            slot(),
            slot(),
        ],
    )
        .prop_map(|(counter, slots)| datalink::HubFrame { counter, slots })
}

/// An ESC whose record is never empty on the wire.
fn non_empty() -> impl Strategy<Value = DataFrame> {
    data_frame().prop_map(|e| DataFrame {
        voltage_raw: e.voltage_raw | 1,
        ..e
    })
}

fn length_byte() -> impl Strategy<Value = LengthByte> {
    prop_oneof![Just(LengthByte::Covered), Just(LengthByte::Total)]
}

/// What a frame reads back as: an all-zero ESC is an empty slot.
fn normalized(f: &datalink::HubFrame) -> datalink::HubFrame {
    let mut f = *f;
    for slot in &mut f.slots {
        if *slot == Some(DataFrame::default()) {
            *slot = None;
        }
    }
    f
}

/// Bytes biased towards the ones that matter to the scanner.
fn noisy_byte() -> impl Strategy<Value = u8> {
    prop_oneof![
        6 => any::<u8>(),
        2 => Just(0x9B),
        1 => Just(0x9E),
        1 => Just(0xA0),
        1 => Just(0x01),
        1 => Just(0x02),
        1 => Just(0x00),
    ]
}

/// One stretch of a generated wire.
#[derive(Debug, Clone)]
enum Piece {
    /// A whole, valid frame.
    Intact(datalink::HubFrame, LengthByte),
    /// Noise.
    Garbage(Vec<u8>),
    /// The first `n` bytes of a frame (`1 <= n < 160`).
    Cut(datalink::HubFrame, LengthByte, usize),
    /// A frame with one bit flipped.
    Flipped(datalink::HubFrame, LengthByte, usize),
    /// A header with nothing of its frame after it.
    Fake(&'static [u8]),
}

fn piece() -> impl Strategy<Value = Piece> {
    prop_oneof![
        4 => (datalink_frame(), length_byte()).prop_map(|(f, l)| Piece::Intact(f, l)),
        2 => vec(noisy_byte(), 0..60).prop_map(Piece::Garbage),
        1 => (datalink_frame(), length_byte(), 1..FRAME_LEN)
            .prop_map(|(f, l, n)| Piece::Cut(f, l, n)),
        1 => (datalink_frame(), length_byte(), 0..FRAME_LEN * 8)
            .prop_map(|(f, l, bit)| Piece::Flipped(f, l, bit)),
        2 => prop_oneof![
            Just(&[0x9B, 0x9E][..]),
            Just(&[0x9B, 0xA0][..]),
            Just(&[0x9B][..]),
            Just(&[0x9B, 0x9E, 0x01, 0x02][..]),
            Just(&[0x9B, 0xA0, 0x01][..]),
            Just(&[0x9B, 0x9E, 0x01, 0x03][..]),
        ]
        .prop_map(Piece::Fake),
    ]
}

fn pieces(max: usize) -> impl Strategy<Value = Vec<Piece>> {
    vec(piece(), 0..max)
}

/// A wire and the intact frames put into it, with their offsets and length bytes.
struct Wire {
    bytes: Vec<u8>,
    intact: Vec<(u64, datalink::HubFrame, LengthByte)>,
}

fn build(pieces: &[Piece]) -> Wire {
    let mut wire = Wire {
        bytes: Vec::new(),
        intact: Vec::new(),
    };
    for p in pieces {
        match p {
            Piece::Intact(f, l) => {
                wire.intact
                    .push((wire.bytes.len() as u64, normalized(f), *l));
                wire.bytes.extend_from_slice(&f.encode_as(*l));
            }
            Piece::Garbage(g) => wire.bytes.extend_from_slice(g),
            Piece::Cut(f, l, n) => wire.bytes.extend_from_slice(&f.encode_as(*l)[..*n]),
            Piece::Flipped(f, l, bit) => {
                let mut b = f.encode_as(*l);
                b[bit / 8] ^= 1 << (bit % 8);
                wire.bytes.extend_from_slice(&b);
            }
            Piece::Fake(h) => wire.bytes.extend_from_slice(h),
        }
    }
    wire
}

/// Whether a valid frame, formed by chance, starts outside the intact frames and overlaps one:
/// a CRC matching by chance (about 1 in 65536 per candidate running into an intact frame). The
/// CRC cannot settle such a wire; the tests that need every intact frame found discard it.
fn ambiguous(bytes: &[u8], intact: &[(u64, datalink::HubFrame, LengthByte)]) -> bool {
    let spans: Vec<(usize, usize)> = intact
        .iter()
        .map(|(o, _, _)| (*o as usize, *o as usize + FRAME_LEN))
        .collect();
    (0..bytes.len())
        .filter(|&p| !spans.iter().any(|&(s, e)| (s..e).contains(&p)))
        .any(|p| {
            datalink::HubFrame::parse(&bytes[p..]).is_ok()
                && spans.iter().any(|&(s, e)| p < e && s < p + FRAME_LEN)
        })
}

// ---------------------------------------------------------------------------------------------
// Decoding paths and the reference scanner
// ---------------------------------------------------------------------------------------------

fn bulk(bytes: &[u8]) -> (Vec<datalink::Decoded>, datalink::Stats) {
    let mut it = datalink::frames(bytes);
    let out: Vec<datalink::Decoded> = it.by_ref().collect();
    assert_eq!(it.next(), None);
    (out, *it.stats())
}

fn streamed_at(bytes: &[u8], cuts: &[usize]) -> (Vec<datalink::Decoded>, datalink::Stats) {
    let mut d = datalink::Decoder::new();
    let mut out = Vec::new();
    for w in cuts.windows(2) {
        d.feed(&bytes[w[0]..w[1]], |x| out.push(x));
        assert_eq!(
            d.buffered(),
            reference_held(&bytes[..w[1]]),
            "after {}",
            w[1]
        );
        let s = d.stats();
        assert_eq!(
            s.bytes(),
            160 * u64::from(s.frames()) + s.bytes_skipped() + d.buffered() as u64
        );
    }
    d.flush(|x| out.push(x));
    assert_eq!(d.buffered(), 0);
    (out, *d.stats())
}

/// A counter followed by the rule of `hwfoc::stats`, written again from its documentation.
#[derive(Debug, Default, PartialEq)]
struct RefSequence {
    count: u32,
    lost: u32,
    duplicates: u32,
    restarts: u32,
    last: Option<u16>,
}

impl RefSequence {
    fn next(&mut self, n: u16) {
        if let Some(last) = self.last {
            let d = n.wrapping_sub(last);
            if d == 0 {
                self.duplicates += 1;
            } else if d <= MAX_PACKET_GAP + 1 {
                self.lost += u32::from(d - 1);
            } else {
                self.restarts += 1;
            }
        }
        self.count += 1;
        self.last = Some(n);
    }

    fn matches(&self, s: &hwfoc::counters::PacketSequence) -> bool {
        (s.count(), s.lost(), s.duplicates(), s.restarts(), s.last())
            == (
                self.count,
                self.lost,
                self.duplicates,
                self.restarts,
                self.last,
            )
    }
}

/// Counters of the reference scanner, named as in `datalink::Stats`.
#[derive(Debug, Default)]
struct RefStats {
    bytes_skipped: u64,
    checksum_failures: u32,
    bad_headers: u32,
    length_bytes: [u32; 2],
    empty: u32,
    bad_channels: u32,
    duplicate_channels: u32,
    counter: RefSequence,
    channels: [RefSequence; CHANNELS],
}

/// The naive scanner: at each position, a `9B` and a length byte 0x9E / 0xA0 are a candidate;
/// a candidate whose bytes 2, 3 are not `01 02` is rejected there, else one whose 160 bytes are
/// there is a frame if its CRC matches (its records read by channel byte, one at a time), else
/// rejected; a rejected or cut candidate costs one byte.
fn reference(bytes: &[u8]) -> (Vec<datalink::Decoded>, RefStats) {
    let (out, s, _) = reference_scan(bytes, true);
    (out, s)
}

/// How many bytes a streaming decoder fed `bytes` holds back: those from the first candidate
/// that more bytes could still decide (a `9B` last, `9B` and a length byte short of 4 bytes, or
/// a good header short of 160).
fn reference_held(bytes: &[u8]) -> usize {
    reference_scan(bytes, false).2
}

/// The reference scanner over `bytes`; unless `at_end`, it stops at the first undecided
/// candidate and also returns how many bytes are left from there.
fn reference_scan(bytes: &[u8], at_end: bool) -> (Vec<datalink::Decoded>, RefStats, usize) {
    let mut s = RefStats::default();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let is_candidate = bytes[i] == 0x9B && matches!(bytes.get(i + 1), Some(0x9E | 0xA0) | None);
        let rest = bytes.len() - i;
        let bad_header = rest >= 4 && bytes[i + 2..i + 4] != [0x01, 0x02];
        if is_candidate && !at_end && rest < FRAME_LEN && !bad_header {
            return (out, s, rest);
        }
        if !is_candidate || rest < 2 {
            s.bytes_skipped += 1;
            i += 1;
            continue;
        }
        if bad_header {
            s.bad_headers += 1;
        } else if bytes.len() >= i + FRAME_LEN {
            let f = &bytes[i..i + FRAME_LEN];
            if crc16_xmodem(&f[..158]) == u16::from(f[158]) | u16::from(f[159]) << 8 {
                let (frame, report) = reference_read(f, &mut s);
                out.push(datalink::Decoded {
                    offset: i as u64,
                    frame,
                    report,
                });
                i += FRAME_LEN;
                continue;
            }
            s.checksum_failures += 1;
        }
        s.bytes_skipped += 1;
        i += 1;
    }
    (out, s, 0)
}

fn reference_read(f: &[u8], s: &mut RefStats) -> (datalink::HubFrame, FrameReport) {
    let length_byte = if f[1] == 0x9E {
        LengthByte::Covered
    } else {
        LengthByte::Total
    };
    s.length_bytes[usize::from(f[1] == 0xA0)] += 1;
    let counter = u16::from_be_bytes([f[4], f[5]]);
    s.counter.next(counter);
    let mut frame = datalink::HubFrame::new(counter);
    let mut report = FrameReport {
        length_byte,
        empty_slots: 0,
        bad_channels: 0,
        duplicate_channels: 0,
    };
    for r in 0..8 {
        let rec = &f[6 + 19 * r..6 + 19 * (r + 1)];
        let be = |i: usize| u16::from_be_bytes([rec[i], rec[i + 1]]);
        if rec[1..].iter().all(|&b| b == 0) {
            report.empty_slots += 1;
        } else if rec[0] > 7 {
            report.bad_channels += 1;
        } else if frame.slots[usize::from(rec[0])].is_some() {
            report.duplicate_channels += 1;
        } else {
            frame.slots[usize::from(rec[0])] = Some(DataFrame {
                packet: be(1),
                throttle_in_raw: be(3),
                throttle_out_raw: be(5),
                erpm_raw: be(7),
                voltage_raw: be(9),
                current_raw: be(11) as i16,
                phase_current_raw: be(13) as i16,
                mos_adc: rec[15],
                cap_adc: rec[16],
                status: Status(be(17)),
            });
        }
    }
    s.empty += u32::from(report.empty_slots);
    s.bad_channels += u32::from(report.bad_channels);
    s.duplicate_channels += u32::from(report.duplicate_channels);
    for (ch, slot) in frame.slots.iter().enumerate() {
        if let Some(esc) = slot {
            s.channels[ch].next(esc.packet);
        }
    }
    (frame, report)
}

/// Checks `stats` against the reference's, and the invariants every stream keeps.
fn assert_stats(bytes: &[u8], stats: &datalink::Stats, r: &RefStats) {
    assert_eq!(stats.bytes(), bytes.len() as u64);
    assert_eq!(stats.bytes_skipped(), r.bytes_skipped);
    assert_eq!(stats.checksum_failures(), r.checksum_failures);
    assert_eq!(stats.bad_headers(), r.bad_headers);
    assert_eq!(
        stats.frames_with_length_byte(LengthByte::Covered),
        r.length_bytes[0]
    );
    assert_eq!(
        stats.frames_with_length_byte(LengthByte::Total),
        r.length_bytes[1]
    );
    assert_eq!(stats.empty_slots(), r.empty);
    assert_eq!(stats.bad_channels(), r.bad_channels);
    assert_eq!(stats.duplicate_channels(), r.duplicate_channels);
    assert!(r.counter.matches(stats.counter()), "{stats}");
    assert_eq!(
        (stats.frames(), stats.lost_packets(), stats.last_counter()),
        (r.counter.count, r.counter.lost, r.counter.last)
    );
    for ch in 0..CHANNELS {
        assert!(r.channels[ch].matches(stats.channel(ch).unwrap()), "{ch}");
    }
    // Every byte in a frame or skipped; every record counted once.
    assert_eq!(
        stats.bytes(),
        160 * u64::from(stats.frames()) + stats.bytes_skipped()
    );
    assert_eq!(
        u64::from(stats.frames()),
        LengthByte::ALL
            .iter()
            .map(|&l| u64::from(stats.frames_with_length_byte(l)))
            .sum::<u64>()
    );
    assert_eq!(
        8 * u64::from(stats.frames()),
        stats.records()
            + u64::from(stats.empty_slots())
            + u64::from(stats.bad_channels())
            + u64::from(stats.duplicate_channels())
    );
}

/// Decodes `bytes` every way and checks them all against the reference; returns the frames.
fn decode_checked(bytes: &[u8], picks: &[Index]) -> (Vec<datalink::Decoded>, datalink::Stats) {
    let (frames, stats) = bulk(bytes);
    let (ref_frames, ref_stats) = reference(bytes);
    assert_eq!(frames, ref_frames, "frames() and the reference scanner");
    assert_stats(bytes, &stats, &ref_stats);
    let cuts = cut_points(bytes.len(), picks);
    assert_eq!(
        streamed_at(bytes, &cuts),
        (frames.clone(), stats),
        "chunked"
    );
    assert_eq!(
        streamed_bytewise::<datalink::Scanner>(bytes),
        (frames.clone(), stats),
        "bytewise"
    );
    let mut all = datalink::Decoder::new();
    let mut got = Vec::new();
    all.decode_all(bytes, |d| got.push(d));
    assert_eq!((got, *all.stats()), (frames.clone(), stats), "decode_all");
    for d in &frames {
        let at = d.offset as usize;
        assert_eq!(
            datalink::HubFrame::parse_with_report(&bytes[at..]),
            Ok((d.frame, d.report))
        );
    }
    (frames, stats)
}

// ---------------------------------------------------------------------------------------------
// Encode / parse
// ---------------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// encode -> parse is the identity (an all-zero ESC reads back as an empty slot), with
    /// either length byte, and the bytes follow the documented layout.
    #[test]
    fn encode_parse_identity(f in datalink_frame(), l in length_byte()) {
        let bytes = f.encode_as(l);
        prop_assert_eq!(&bytes[..6], &[0x9B, l.byte(), 0x01, 0x02, (f.counter >> 8) as u8, f.counter as u8]);
        prop_assert_eq!(
            u16::from_le_bytes([bytes[158], bytes[159]]),
            crc16_xmodem(&bytes[..158])
        );
        for (ch, slot) in f.slots.iter().enumerate() {
            let rec = &bytes[RECORDS_AT + ch * RECORD_LEN..RECORDS_AT + (ch + 1) * RECORD_LEN];
            prop_assert_eq!(usize::from(rec[0]), ch);
            // A record's payload is the data frame's bytes 4..22.
            let esc_bytes = slot.unwrap_or_default().encode();
            prop_assert_eq!(&rec[1..], &esc_bytes[4..22]);
        }
        let back = normalized(&f);
        let empties = back.slots.iter().filter(|s| s.is_none()).count() as u8;
        prop_assert_eq!(
            datalink::HubFrame::parse_with_report(&bytes),
            Ok((back, FrameReport {
                length_byte: l,
                empty_slots: empties,
                bad_channels: 0,
                duplicate_channels: 0,
            }))
        );
        if l == LengthByte::Covered {
            prop_assert_eq!(f.encode(), bytes);
        }
        let (decoded, stats) = decode_checked(&bytes, &[]);
        prop_assert_eq!(decoded.len(), 1);
        prop_assert_eq!(decoded[0].frame, back);
        prop_assert_eq!(stats.frames_with_length_byte(l), 1);
        prop_assert_eq!(stats.bytes_skipped(), 0);
        prop_assert_eq!(stats.records(), u64::from(8 - empties));
    }

    /// A record with data and a channel byte above 7 is dropped and counted; the rest of the
    /// frame is kept, by `parse` and by the decoder.
    #[test]
    fn bad_channel_drops_only_its_record(
        f in datalink_frame(),
        esc in non_empty(),
        which in 0..CHANNELS,
        channel in 8u8..=255,
        l in length_byte(),
    ) {
        let mut f = normalized(&f);
        f.slots[which] = Some(esc);
        let mut bytes = f.encode_as(l);
        bytes[RECORDS_AT + which * RECORD_LEN] = channel;
        Checksum::Crc16Xmodem.seal(&mut bytes);
        let mut expected = f;
        expected.slots[which] = None;
        let empties = f.slots.iter().filter(|s| s.is_none()).count() as u8;
        prop_assert_eq!(
            datalink::HubFrame::parse_with_report(&bytes),
            Ok((expected, FrameReport {
                length_byte: l,
                empty_slots: empties,
                bad_channels: 1,
                duplicate_channels: 0,
            }))
        );
        let (decoded, stats) = decode_checked(&bytes, &[]);
        prop_assert_eq!(decoded[0].frame, expected);
        prop_assert_eq!(stats.bad_channels(), 1);
        prop_assert_eq!(stats.channel(which).unwrap().count(), 0);
    }

    /// Two records with data for one channel: the first is kept, the other dropped and counted.
    #[test]
    fn duplicate_channel_keeps_the_first(
        f in datalink_frame(),
        escs in [non_empty(), non_empty()],
        first in 0..CHANNELS - 1,
        apart in 1..CHANNELS,
        l in length_byte(),
    ) {
        let second = (first + apart).min(CHANNELS - 1);
        prop_assume!(second != first);
        let mut f = normalized(&f);
        f.slots[first] = Some(escs[0]);
        f.slots[second] = Some(escs[1]);
        let mut bytes = f.encode_as(l);
        // The later record claims the earlier one's channel.
        bytes[RECORDS_AT + second * RECORD_LEN] = first as u8;
        Checksum::Crc16Xmodem.seal(&mut bytes);
        let mut expected = f;
        expected.slots[second] = None;
        let (frame, report) = datalink::HubFrame::parse_with_report(&bytes).unwrap();
        prop_assert_eq!(frame, expected);
        prop_assert_eq!((report.duplicate_channels, report.bad_channels), (1, 0));
        // And the other way round: the earlier record claims the later one's channel, which
        // then arrives second.
        let mut bytes = f.encode_as(l);
        bytes[RECORDS_AT + first * RECORD_LEN] = second as u8;
        Checksum::Crc16Xmodem.seal(&mut bytes);
        let mut expected = f;
        expected.slots[second] = f.slots[first];
        expected.slots[first] = None;
        let (decoded, stats) = decode_checked(&bytes, &[]);
        prop_assert_eq!(decoded[0].frame, expected);
        prop_assert_eq!(stats.duplicate_channels(), 1);
    }

    /// One flipped bit anywhere in a frame is always rejected: neither `parse` nor the decoder
    /// finds any frame in it (never a different valid frame), with either length byte.
    #[test]
    fn single_bit_flip_is_always_rejected(
        f in datalink_frame(),
        l in length_byte(),
        bit in 0..FRAME_LEN * 8,
    ) {
        let mut bytes = f.encode_as(l);
        bytes[bit / 8] ^= 1 << (bit % 8);
        prop_assert!(datalink::HubFrame::parse(&bytes).is_err());
        let (decoded, stats) = decode_checked(&bytes, &[]);
        prop_assert!(decoded.is_empty());
        prop_assert_eq!(stats.bytes_skipped(), 160);
    }
}

/// Every single-bit flip of a few frames, exhaustively (1280 flips each).
#[test]
fn every_single_bit_flip_is_rejected() {
    let mut full = datalink::HubFrame::new(0xFFFF);
    for (ch, slot) in full.slots.iter_mut().enumerate() {
        *slot = Some(DataFrame {
            packet: 100 * ch as u16,
            voltage_raw: 252,
            erpm_raw: 0x9B9E,
            status: Status(0x9BA0),
            ..Default::default()
        });
    }
    for frame in [datalink::HubFrame::new(0), full] {
        for l in LengthByte::ALL {
            let good = frame.encode_as(l);
            for bit in 0..FRAME_LEN * 8 {
                let mut bytes = good;
                bytes[bit / 8] ^= 1 << (bit % 8);
                assert!(datalink::HubFrame::parse(&bytes).is_err(), "bit {bit}");
                let (decoded, _) = bulk(&bytes);
                assert!(decoded.is_empty(), "bit {bit}");
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Streams
// ---------------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// However the wire is cut into chunks (or fed a byte at a time), the same frames and the
    /// same statistics as `frames()` and the reference scanner.
    #[test]
    fn any_chunking_gives_the_same_frames(
        ps in pieces(16),
        picks in vec(any::<Index>(), 0..30),
    ) {
        let wire = build(&ps);
        decode_checked(&wire.bytes, &picks);
    }

    /// The streaming decoder holds back only an undecided candidate, after every chunk and after
    /// every byte pushed: the bytes from the first candidate that more bytes could decide.
    #[test]
    fn only_an_undecided_candidate_is_held(
        ps in pieces(8),
        picks in vec(any::<Index>(), 0..30),
        bytewise in any::<bool>(),
    ) {
        let wire = build(&ps);
        let cuts = if bytewise {
            (0..=wire.bytes.len()).collect()
        } else {
            cut_points(wire.bytes.len(), &picks)
        };
        streamed_at(&wire.bytes, &cuts);
    }

    /// Garbage, cut and corrupted frames and fake headers around and between frames never lose
    /// an intact frame: every one is decoded, in order, at its offset, with its length byte;
    /// any extra frame (formed by chance) lies wholly outside them.
    #[test]
    fn garbage_never_loses_an_intact_frame(ps in pieces(16)) {
        let wire = build(&ps);
        prop_assume!(!ambiguous(&wire.bytes, &wire.intact));
        let (decoded, stats) = decode_checked(&wire.bytes, &[]);
        let found: Vec<(u64, datalink::HubFrame, LengthByte)> = decoded
            .iter()
            .filter(|d| wire.intact.iter().any(|(o, _, _)| *o == d.offset))
            .map(|d| (d.offset, d.frame, d.report.length_byte))
            .collect();
        prop_assert_eq!(&found, &wire.intact);
        for d in decoded.iter().filter(|d| !wire.intact.iter().any(|(o, _, _)| *o == d.offset)) {
            for (o, _, _) in &wire.intact {
                prop_assert!(d.offset + 160 <= *o || *o + 160 <= d.offset);
            }
        }
        for l in LengthByte::ALL {
            let n = wire.intact.iter().filter(|(_, _, x)| *x == l).count() as u32;
            prop_assert!(stats.frames_with_length_byte(l) >= n);
        }
    }

    /// A run of frames from a hub: counters and per-channel packet numbers followed, with
    /// frames dropped by corruption counted as lost.
    #[test]
    fn counters_and_channels_are_followed(
        start in any::<u16>(),
        packets in [any::<u16>(), any::<u16>(), any::<u16>()],
        n in 2usize..30,
        corrupt in vec(any::<bool>(), 30),
        picks in vec(any::<Index>(), 0..10),
    ) {
        let mut bytes = Vec::new();
        let mut sent = 0u32;
        let mut dropped_inside = 0u32;
        for (i, &corrupt) in corrupt.iter().enumerate().take(n) {
            let mut f = datalink::HubFrame::new(start.wrapping_add(i as u16));
            for (ch, &p) in packets.iter().enumerate() {
                f.slots[2 * ch] = Some(DataFrame { packet: p.wrapping_add(i as u16), voltage_raw: 1, ..Default::default() });
            }
            let mut b = f.encode();
            if corrupt && i != 0 && i != n - 1 {
                b[100] ^= 0x10;
                dropped_inside += 1;
            } else {
                sent += 1;
            }
            bytes.extend_from_slice(&b);
        }
        let (decoded, stats) = decode_checked(&bytes, &picks);
        prop_assert_eq!(decoded.len() as u32, sent);
        prop_assert_eq!(stats.frames(), sent);
        prop_assert_eq!(stats.checksum_failures(), dropped_inside);
        prop_assert_eq!(stats.lost_packets(), dropped_inside);
        prop_assert_eq!((stats.restarts(), stats.duplicate_packets()), (0, 0));
        for ch in 0..CHANNELS {
            let s = stats.channel(ch).unwrap();
            if ch % 2 == 0 && ch < 6 {
                prop_assert_eq!((s.count(), s.lost(), s.restarts()), (sent, dropped_inside, 0));
                prop_assert_eq!(s.last(), Some(packets[ch / 2].wrapping_add(n as u16 - 1)));
            } else {
                prop_assert_eq!((s.count(), s.last()), (0, None));
            }
        }
        prop_assert_eq!(stats.empty_slots(), 5 * sent);
    }
}

// ---------------------------------------------------------------------------------------------
// Unit tests on encoder-made bytes
// ---------------------------------------------------------------------------------------------

/// The frame of `fuzz/run.sh`'s seeds: the first data frame of the XRotor capture in slot 0,
/// every other slot empty. Its CRCs come from Python's `binascii.crc_hqx(frame[:158], 0)`
/// (CRC-16/XMODEM), not from this crate.
#[test]
fn encoder_matches_an_independent_crc() {
    let esc = DataFrame::parse(&[
        0x9B, 0x16, 0x01, 0x02, 0x05, 0xC2, 0, 0, 0, 0, 0, 0, 0x00, 0xF7, 0xFF, 0xFF, 0xFF, 0xFF,
        0xCE, 0xD1, 0x00, 0x00, 0x0D, 0x08,
    ])
    .unwrap();
    let mut f = datalink::HubFrame::new(1);
    f.slots[0] = Some(esc);
    let b = f.encode();
    assert_eq!(b[..7], [0x9B, 0x9E, 0x01, 0x02, 0x00, 0x01, 0x00]);
    assert_eq!(
        b[7..25],
        [
            0x05, 0xC2, 0, 0, 0, 0, 0, 0, 0x00, 0xF7, 0xFF, 0xFF, 0xFF, 0xFF, 0xCE, 0xD1, 0x00,
            0x00
        ]
    );
    assert_eq!(b[158..], [0x61, 0x34]);
    f.counter = 2;
    assert_eq!(f.encode_as(LengthByte::Total)[158..], [0xC9, 0x15]);
}

/// A stream with both length bytes: each frame counted under its own.
#[test]
fn both_length_bytes_are_counted() {
    let mut wire = Vec::new();
    for (i, l) in [
        LengthByte::Covered,
        LengthByte::Total,
        LengthByte::Total,
        LengthByte::Covered,
        LengthByte::Total,
    ]
    .into_iter()
    .enumerate()
    {
        wire.extend_from_slice(&datalink::HubFrame::new(i as u16).encode_as(l));
    }
    let (decoded, stats) = decode_checked(&wire, &[]);
    assert_eq!(decoded.len(), 5);
    assert_eq!(stats.frames_with_length_byte(LengthByte::Covered), 2);
    assert_eq!(stats.frames_with_length_byte(LengthByte::Total), 3);
    assert_eq!(decoded[1].report.length_byte, LengthByte::Total);
    assert_eq!(stats.lost_packets(), 0);
}

/// A record is empty only when all 18 bytes after its channel byte are zero: one non-zero byte
/// anywhere makes it an ESC's.
#[test]
fn one_non_zero_byte_makes_a_record() {
    for at in 0..18 {
        let mut b = datalink::HubFrame::new(5).encode();
        b[RECORDS_AT + 2 * RECORD_LEN + 1 + at] = 0x80;
        Checksum::Crc16Xmodem.seal(&mut b);
        let (frame, report) = datalink::HubFrame::parse_with_report(&b).unwrap();
        assert!(frame.slots[2].is_some(), "{at}");
        assert_eq!(frame.escs().count(), 1);
        assert_eq!(report.empty_slots, 7);
        assert_eq!(decode_checked(&b, &[]).1.records(), 1);
    }
}

/// Any other length byte is not a DataLink frame, even with a correct CRC.
#[test]
fn other_length_bytes_are_not_frames() {
    for length in [0x9D, 0x9F, 0xA1, 0x16, 0x4C] {
        let mut b = datalink::HubFrame::new(5).encode();
        b[1] = length;
        Checksum::Crc16Xmodem.seal(&mut b);
        assert_eq!(
            datalink::HubFrame::parse(&b),
            Err(datalink::Error::UnknownLength { found: length })
        );
        let (decoded, stats) = decode_checked(&b, &[]);
        assert!(decoded.is_empty());
        assert_eq!((stats.checksum_failures(), stats.bad_headers()), (0, 0));
    }
}

/// A wrong version or command, even under a correct CRC, is a bad header, decided at the fourth
/// byte: the frame right behind the fake header's `9B` is still found.
#[test]
fn bad_header_costs_one_byte() {
    let good = datalink::HubFrame::new(77).encode();
    let mut bad = good;
    bad[3] = 0x01;
    Checksum::Crc16Xmodem.seal(&mut bad);
    assert_eq!(
        datalink::HubFrame::parse(&bad),
        Err(datalink::Error::UnknownCommand {
            version: 1,
            command: 1
        })
    );
    let mut wire = vec![0x9B, 0x9E, 0x01];
    wire.extend_from_slice(&good);
    wire.extend_from_slice(&bad);
    let (decoded, stats) = decode_checked(&wire, &[]);
    assert_eq!(decoded.len(), 1);
    assert_eq!(decoded[0].offset, 3);
    assert_eq!(stats.bad_headers(), 2); // `9B 9E 01 9B` and the bad frame
    assert_eq!(stats.bytes_skipped(), 3 + 160);
}

/// A frame cut short and followed by a whole one: the whole one is found, the cut one counted
/// as a CRC failure; a frame cut by the end of the stream is skipped and not counted.
#[test]
fn cut_frames() {
    let a = datalink::HubFrame::new(1).encode();
    let mut b = datalink::HubFrame::new(2);
    b.slots[4] = Some(DataFrame {
        packet: 9,
        ..Default::default()
    });
    let b = b.encode();
    let mut wire = a[..100].to_vec();
    wire.extend_from_slice(&b);
    wire.extend_from_slice(&a[..150]);
    let (decoded, stats) = decode_checked(&wire, &[]);
    assert_eq!(decoded.len(), 1);
    assert_eq!(decoded[0].offset, 100);
    assert_eq!(decoded[0].frame.slots[4].map(|e| e.packet), Some(9));
    assert_eq!(stats.checksum_failures(), 1);
    assert_eq!(stats.bytes_skipped(), 250);
    let mut d = datalink::Decoder::new();
    d.feed(&wire, |_| {});
    assert_eq!(d.buffered(), 150);
    d.flush(|_| {});
    assert_eq!(d.stats(), &stats);
}

/// A lone sync byte right before a frame, and `9B 9E` / `9B A0` pairs inside frames' records
/// (a field of 0x9B9E), never hide or split a frame.
#[test]
fn sync_bytes_inside_records() {
    let mut f = datalink::HubFrame::new(0x9B9E);
    for slot in &mut f.slots {
        *slot = Some(DataFrame {
            packet: 0x9BA0,
            throttle_in_raw: 0x9B9E,
            throttle_out_raw: 0x0102,
            status: Status(0x9B9E),
            ..Default::default()
        });
    }
    let mut wire = vec![0x9B];
    for _ in 0..3 {
        wire.extend_from_slice(&f.encode());
    }
    let (decoded, stats) = decode_checked(&wire, &[]);
    assert_eq!(
        decoded.iter().map(|d| d.offset).collect::<Vec<_>>(),
        [1, 161, 321]
    );
    assert_eq!(stats.duplicate_packets(), 2);
    assert_eq!(stats.channel(7).unwrap().duplicates(), 2);
    assert_eq!(stats.bytes_skipped(), 1);
}

/// The HW-FOC decoder finds nothing in a DataLink stream, and the DataLink decoder nothing in
/// an ESC's stream: each wire's bytes are all skipped by the other.
#[test]
fn the_two_decoders_do_not_see_each_others_frames() {
    let mut f = datalink::HubFrame::new(1);
    f.slots[0] = Some(DataFrame {
        packet: 5,
        voltage_raw: 252,
        ..Default::default()
    });
    let hub: Vec<u8> = (0..4).flat_map(|_| f.encode()).collect();
    let mut esc = Vec::new();
    for packet in 0..40u16 {
        esc.extend_from_slice(
            &DataFrame {
                packet,
                ..Default::default()
            }
            .encode(),
        );
    }
    assert_eq!(hwfoc::foc::frames(&hub).count(), 0);
    let (decoded, stats) = decode_checked(&esc, &[]);
    assert!(decoded.is_empty());
    assert_eq!(stats.bytes_skipped(), esc.len() as u64);
}

/// `line_silent` on the DataLink decoder: the held bytes are decided, and both the counter and
/// each channel get the silence's limit (a channel's from the ESC's own wire speed).
#[test]
fn line_silent_limits_counter_and_channels() {
    let frame = |counter: u16, packet: u16| {
        let mut f = datalink::HubFrame::new(counter);
        f.slots[6] = Some(DataFrame {
            packet,
            ..Default::default()
        });
        f.encode()
    };
    let mut d = datalink::Decoder::new();
    let mut n = 0;
    d.feed(&frame(10, 500), |_| n += 1);
    d.feed(&frame(11, 501)[..90], |_| n += 1);
    d.line_silent(8, |_| n += 1);
    assert_eq!((n, d.buffered()), (1, 0));
    // Counter step 10 > 8 + 1: restart. Packet step 10 <= esc_frames_in(8) + 1 = 9 + 1: loss.
    assert_eq!(datalink::esc_frames_in(8), 9);
    d.feed(&frame(20, 510), |_| n += 1);
    let s = d.stats();
    assert_eq!((s.restarts(), s.lost_packets()), (1, 0));
    let ch = s.channel(6).unwrap();
    assert_eq!((ch.lost(), ch.restarts()), (9, 0));
    assert_eq!(s.bytes_skipped(), 90);
    d.reset();
    assert_eq!(d.stats(), &datalink::Stats::new());
}

#[test]
fn error_messages() {
    let cases = [
        (
            datalink::Error::Truncated { got: 3 },
            "truncated DataLink frame: 3 of 160 bytes",
        ),
        (
            datalink::Error::NoSync { found: 0 },
            "DataLink frame starts with 0x00, not the sync byte 0x9B",
        ),
        (
            datalink::Error::UnknownCommand {
                version: 1,
                command: 3,
            },
            "unknown DataLink version 0x01 / command 0x03 (expected 01 02)",
        ),
        (
            datalink::Error::Crc {
                expected: 0x31C3,
                found: 0xC331,
            },
            "DataLink CRC mismatch: bytes give 0x31C3, frame carries 0xC331",
        ),
    ];
    for (e, text) in cases {
        assert_eq!(e.to_string(), text);
    }
}

#[test]
fn stats_display_names_every_counter() {
    let (_, stats) = bulk(&datalink::HubFrame::new(1).encode_as(LengthByte::Total));
    assert_eq!(
        stats.to_string(),
        "160 bytes, 1 frames (0 with length byte 0x9E, 1 with 0xA0), 0 checksum \
         failures, 0 bad headers, 0 bytes skipped, 0 lost packets, 0 duplicate packets, 0 restarts, \
         0 records, 8 empty slots, 0 bad channels, 0 duplicate channels"
    );
}
