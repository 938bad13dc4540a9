//! Property tests for the codec: encode/decode identity, chunking independence, resynchronisation
//! after garbage, single-bit error detection, and bulk == streaming (checked against a naive
//! reference scanner written here from the protocol description).
//!
//! Case counts are kept modest so that the whole file runs in a few seconds in debug mode.

mod common;

use common::{cut_points, data_frame, streamed_bytewise};
use hwfoc::counters::MAX_PACKET_GAP;
use hwfoc::foc::kinds::data::DATA_FRAME_LEN;
use hwfoc::foc::kinds::info::INFO_FRAME_LEN;
use hwfoc::foc::{
    DataFrame, Decoded, Decoder, FocFrame, FrameError, InfoFrame, Parsed, frames, parse,
};
use hwfoc::{Status, foc};
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::Index;

// ---------------------------------------------------------------------------------------------
// Generators
// ---------------------------------------------------------------------------------------------

/// The real device-information text (XRotor v4 Pro HV 80A).
const REAL_INFO_TEXT: &[u8; 72] =
    b"                XR_FOC_ESC      HW577_KZ1_V1.1  XR-01.0.00      01040443";

/// Any ASCII text (the protocol's text is ASCII; the decoder refuses anything else).
fn info_text() -> impl Strategy<Value = [u8; 72]> {
    vec(0u8..0x80, 72).prop_map(|v| v.try_into().unwrap())
}

fn info_frame() -> impl Strategy<Value = InfoFrame> {
    prop_oneof![
        3 => info_text().prop_map(|t| InfoFrame::from_text(t).unwrap()),
        1 => Just(InfoFrame::from_text(*REAL_INFO_TEXT).unwrap()),
    ]
}

fn frame() -> impl Strategy<Value = FocFrame> {
    prop_oneof![
        3 => data_frame().prop_map(FocFrame::Data),
        1 => info_frame().prop_map(FocFrame::Info),
    ]
}

/// Bytes biased towards the ones that matter to the scanner (sync, length, version, command).
fn noisy_byte() -> impl Strategy<Value = u8> {
    prop_oneof![
        6 => any::<u8>(),
        2 => Just(0x9B),
        1 => Just(0x16),
        1 => Just(0x4C),
        1 => Just(0x01),
        1 => Just(0x02),
    ]
}

/// One stretch of a generated wire.
#[derive(Debug, Clone)]
enum Piece {
    /// A whole, valid frame.
    Intact(FocFrame),
    /// Noise.
    Garbage(Vec<u8>),
    /// The first `n` bytes of a frame (`1 <= n < wire_len`).
    Cut(FocFrame, usize),
    /// A header with nothing of its frame after it: `9B 16`, `9B 4C`, a lone `9B`, or a kind's
    /// whole header (which the scanner's search windows must verify and reject).
    Fake(&'static [u8]),
}

fn piece() -> impl Strategy<Value = Piece> {
    prop_oneof![
        4 => frame().prop_map(Piece::Intact),
        2 => vec(noisy_byte(), 0..40).prop_map(Piece::Garbage),
        2 => (frame(), any::<Index>())
            .prop_map(|(f, i)| Piece::Cut(f, 1 + i.index(f.wire_len() - 1))),
        2 => prop_oneof![
            Just(&[0x9B, 0x16][..]),
            Just(&[0x9B, 0x4C][..]),
            Just(&[0x9B][..]),
            Just(&[0x9B, 0x16, 0x01, 0x02][..]),
            Just(&[0x9B, 0x4C, 0x01, 0x01][..]),
        ]
        .prop_map(Piece::Fake),
    ]
}

/// A stretch of a wire with line noise as it comes: runs of random bytes (up to 150, longer
/// than the 57 positions the bulk scanner's candidate map gives at once) between frames, few
/// cut frames, a rare fake header.
fn line_noise_piece() -> impl Strategy<Value = Piece> {
    prop_oneof![
        12 => frame().prop_map(Piece::Intact),
        4 => vec(any::<u8>(), 1..150).prop_map(Piece::Garbage),
        1 => (frame(), any::<Index>())
            .prop_map(|(f, i)| Piece::Cut(f, 1 + i.index(f.wire_len() - 1))),
        1 => Just(Piece::Fake(&[0x9B, 0x16, 0x01, 0x02][..])),
    ]
}

fn pieces(max: usize) -> impl Strategy<Value = Vec<Piece>> {
    vec(piece(), 0..max)
}

fn encode(frame: &FocFrame) -> Vec<u8> {
    match frame {
        FocFrame::Data(d) => d.encode().to_vec(),
        FocFrame::Info(i) => i.encode().to_vec(),
    }
}

/// A wire and the intact frames put into it, with their offsets.
struct Wire {
    bytes: Vec<u8>,
    intact: Vec<(u64, FocFrame)>,
}

fn build(pieces: &[Piece]) -> Wire {
    let mut wire = Wire {
        bytes: Vec::new(),
        intact: Vec::new(),
    };
    for p in pieces {
        match p {
            Piece::Intact(f) => {
                wire.intact.push((wire.bytes.len() as u64, *f));
                wire.bytes.extend_from_slice(&encode(f));
            }
            Piece::Garbage(g) => wire.bytes.extend_from_slice(g),
            Piece::Cut(f, n) => wire.bytes.extend_from_slice(&encode(f)[..*n]),
            Piece::Fake(h) => wire.bytes.extend_from_slice(h),
        }
    }
    wire
}

// ---------------------------------------------------------------------------------------------
// Decoding paths
// ---------------------------------------------------------------------------------------------

fn bulk(bytes: &[u8]) -> (Vec<Decoded>, foc::Stats) {
    let mut it = frames(bytes);
    let out: Vec<Decoded> = it.by_ref().collect();
    (out, *it.stats())
}

fn streamed_at(bytes: &[u8], cuts: &[usize]) -> (Vec<Decoded>, foc::Stats) {
    let mut d = Decoder::new();
    let mut out = Vec::new();
    for w in cuts.windows(2) {
        d.feed(&bytes[w[0]..w[1]], |x| out.push(x));
        assert!(d.buffered() < INFO_FRAME_LEN);
    }
    d.flush(|x| out.push(x));
    assert_eq!(d.buffered(), 0);
    (out, *d.stats())
}

/// Counters of the naive reference scanner, named as in [`foc::Stats`].
#[derive(Debug, Default, PartialEq)]
struct RefStats {
    bytes: u64,
    bytes_skipped: u64,
    frames: u32,
    info_frames: u32,
    checksum_failures: u32,
    lost_packets: u32,
    duplicate_packets: u32,
    restarts: u32,
    last_packet: Option<u16>,
    /// Frames the silences since the last data frame could have hidden, if there was one.
    silent_frames: Option<u64>,
}

impl From<&foc::Stats> for RefStats {
    fn from(s: &foc::Stats) -> Self {
        RefStats {
            bytes: s.bytes(),
            bytes_skipped: s.bytes_skipped(),
            frames: s.frames(),
            info_frames: s.info_frames(),
            checksum_failures: s.checksum_failures(),
            lost_packets: s.lost_packets(),
            duplicate_packets: s.duplicate_packets(),
            restarts: s.restarts(),
            last_packet: s.last_packet(),
            silent_frames: None,
        }
    }
}

impl RefStats {
    /// Counts a data frame's packet number by the rule of the issue: a step of 0 is a duplicate,
    /// 1 the next frame, 2 up to the limit a loss of `step - 1`, anything else (a jump forwards
    /// beyond the limit, or backwards: past half the counter) a restart. The limit is
    /// `MAX_PACKET_GAP + 1`, or after silences `1 +` the frames they could have hidden.
    fn packet(&mut self, packet: u16) {
        if let Some(last) = self.last_packet {
            let step = u64::from(packet.wrapping_sub(last));
            let limit = match self.silent_frames {
                Some(frames) => 1 + frames,
                None => u64::from(MAX_PACKET_GAP) + 1,
            };
            match step {
                0 => self.duplicate_packets += 1,
                1 => {}
                _ if step <= limit && step <= 32768 => self.lost_packets += step as u32 - 1,
                _ => self.restarts += 1,
            }
        }
        self.silent_frames = None;
        self.last_packet = Some(packet);
        self.frames += 1;
    }
}

/// The scanning rule of the protocol notes, written the obvious (slow) way and independently of
/// the codec's checks: at each `9B` with a known length byte and enough bytes, verify the sum,
/// version and command; take a valid frame whole, otherwise move on by one byte.
fn reference(bytes: &[u8]) -> (Vec<Decoded>, RefStats) {
    let mut out = Vec::new();
    let mut s = RefStats::default();
    reference_scan(bytes, 0, &mut s, &mut out);
    (out, s)
}

/// [`reference`] over stretches of bytes separated by silences: a silence of `silences[i]`
/// frames between `parts[i]` and `parts[i + 1]` ends the stream of frames (no frame spans it)
/// and widens or narrows what the next data frame's step may lose.
fn reference_with_silences(parts: &[Vec<u8>], silences: &[u32]) -> (Vec<Decoded>, RefStats) {
    let mut out = Vec::new();
    let mut s = RefStats::default();
    let mut base = 0;
    for (i, part) in parts.iter().enumerate() {
        if i > 0 {
            let before = s.silent_frames.unwrap_or(0);
            s.silent_frames = Some(before + u64::from(silences[i - 1]));
        }
        reference_scan(part, base, &mut s, &mut out);
        base += part.len() as u64;
    }
    (out, s)
}

/// Scans `bytes`, whose first byte is at stream offset `base`, to their end.
fn reference_scan(bytes: &[u8], base: u64, s: &mut RefStats, out: &mut Vec<Decoded>) {
    s.bytes += bytes.len() as u64;
    let mut i = 0;
    while i < bytes.len() {
        let rest = &bytes[i..];
        let (len, command) = match rest.get(1) {
            Some(0x16) if rest[0] == 0x9B => (DATA_FRAME_LEN, 0x02),
            Some(0x4C) if rest[0] == 0x9B => (INFO_FRAME_LEN, 0x01),
            _ => {
                s.bytes_skipped += 1;
                i += 1;
                continue;
            }
        };
        if rest.len() < len {
            // Cut off by the end of the stream.
            s.bytes_skipped += 1;
            i += 1;
            continue;
        }
        let f = &rest[..len];
        // The length byte counts the bytes before the check bytes: they are the ones summed.
        let sum: u32 = f[..usize::from(f[1])].iter().map(|&b| u32::from(b)).sum();
        let sum_ok = if len == DATA_FRAME_LEN {
            sum as u16 == u16::from_le_bytes([f[22], f[23]])
        } else {
            sum as u8 == f[76]
        };
        // Device-information text is ASCII: this keeps a cut info frame from hiding the frames
        // behind it, which its 8-bit check alone would do once in 256 times.
        let text_ok = len == DATA_FRAME_LEN || f[4..76].is_ascii();
        // A throttle over 100 % (1024) is out of the protocol's range: no frame.
        let throttle = |i: usize| u16::from_be_bytes([f[i], f[i + 1]]);
        let in_range = len != DATA_FRAME_LEN || (throttle(6) <= 1024 && throttle(8) <= 1024);
        if !(sum_ok && f[2] == 0x01 && f[3] == command && text_ok && in_range) {
            s.checksum_failures += 1;
            s.bytes_skipped += 1;
            i += 1;
            continue;
        }
        let frame = if len == DATA_FRAME_LEN {
            let d = DataFrame {
                packet: u16::from_be_bytes([f[4], f[5]]),
                throttle_in_raw: u16::from_be_bytes([f[6], f[7]]),
                throttle_out_raw: u16::from_be_bytes([f[8], f[9]]),
                erpm_raw: u16::from_be_bytes([f[10], f[11]]),
                voltage_raw: u16::from_be_bytes([f[12], f[13]]),
                current_raw: i16::from_be_bytes([f[14], f[15]]),
                phase_current_raw: i16::from_be_bytes([f[16], f[17]]),
                mos_adc: f[18],
                cap_adc: f[19],
                status: Status(u16::from_be_bytes([f[20], f[21]])),
            };
            s.packet(d.packet);
            FocFrame::Data(d)
        } else {
            s.info_frames += 1;
            FocFrame::Info(InfoFrame::from_text(f[4..76].try_into().unwrap()).unwrap())
        };
        out.push(Decoded {
            offset: base + i as u64,
            frame,
        });
        i += len;
    }
}

/// How many bytes at the end of `bytes` a streaming decoder fed them (and not flushed) still
/// holds: from the first candidate (a `9B` that is the last byte, or a `9B` and a known length
/// byte) that has fewer bytes than its frame, once the frames before it are taken.
fn reference_held(bytes: &[u8]) -> usize {
    let mut i = 0;
    while i < bytes.len() {
        let rest = &bytes[i..];
        let len = match rest {
            [0x9B] => return rest.len(),
            [0x9B, 0x16, ..] => DATA_FRAME_LEN,
            [0x9B, 0x4C, ..] => INFO_FRAME_LEN,
            _ => {
                i += 1;
                continue;
            }
        };
        if rest.len() < len {
            return rest.len();
        }
        i += match parse(rest) {
            Ok(Parsed::Complete(_, n)) => n,
            _ => 1,
        };
    }
    0
}

/// Whether some candidate that is not an intact frame's own start is itself a valid frame
/// overlapping an intact frame. Such a wire is ambiguous: the checksums cannot tell the
/// candidate from the intact frame, and a decoder that trusts them takes the first one.
fn ambiguous(bytes: &[u8], intact: &[(u64, FocFrame)]) -> bool {
    let spans: Vec<(usize, usize)> = intact
        .iter()
        .map(|(o, f)| (*o as usize, *o as usize + f.wire_len()))
        .collect();
    (0..bytes.len())
        .filter(|&p| !spans.iter().any(|&(s, e)| (s..e).contains(&p)))
        .any(|p| match parse(&bytes[p..]) {
            Ok(Parsed::Complete(_, n)) => spans.iter().any(|&(s, e)| p < e && s < p + n),
            _ => false,
        })
}

// ---------------------------------------------------------------------------------------------
// (a) Encode/decode identity
// ---------------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn data_frame_encode_decode_identity(f in data_frame()) {
        let bytes = f.encode();
        prop_assert_eq!(&bytes[..4], &[0x9B, 0x16, 0x01, 0x02]);
        prop_assert_eq!(&bytes[4..6], &f.packet.to_be_bytes());
        prop_assert_eq!(&bytes[14..16], &f.current_raw.to_be_bytes());
        prop_assert_eq!(&bytes[20..22], &f.status.0.to_be_bytes());
        let sum: u32 = bytes[..22].iter().map(|&b| u32::from(b)).sum();
        prop_assert_eq!(u16::from_le_bytes([bytes[22], bytes[23]]), sum as u16);
        prop_assert_eq!(DataFrame::parse(&bytes), Ok(f));
        prop_assert_eq!(parse(&bytes), Ok(Parsed::Complete(FocFrame::Data(f), 24)));
        let (decoded, stats) = bulk(&bytes);
        prop_assert_eq!(decoded, vec![Decoded { offset: 0, frame: FocFrame::Data(f) }]);
        prop_assert_eq!(stats.bytes_skipped(), 0);
        prop_assert_eq!(stats.last_packet(), Some(f.packet));
    }

    #[test]
    fn info_frame_encode_decode_identity(text in info_text()) {
        let info = InfoFrame::from_text(text).unwrap();
        let bytes = info.encode();
        prop_assert_eq!(&bytes[..4], &[0x9B, 0x4C, 0x01, 0x01]);
        prop_assert_eq!(&bytes[4..76], &text[..]);
        let sum: u32 = bytes[..76].iter().map(|&b| u32::from(b)).sum();
        prop_assert_eq!(bytes[76], sum as u8);
        let back = InfoFrame::parse(&bytes).unwrap();
        prop_assert_eq!(back, info);
        prop_assert_eq!(back.text(), &text);
        prop_assert_eq!(parse(&bytes), Ok(Parsed::Complete(FocFrame::Info(info), 77)));
        let (decoded, stats) = bulk(&bytes);
        prop_assert_eq!(decoded, vec![Decoded { offset: 0, frame: FocFrame::Info(info) }]);
        prop_assert_eq!(stats.info_frames(), 1);
        prop_assert_eq!(stats.checksum_failures(), 0);
    }

    #[test]
    fn info_frame_fields_round_trip(
        product in "[A-Za-z0-9_.-]{0,16}",
        hardware in "[A-Za-z0-9_.-]{0,16}",
        firmware in "[A-Za-z0-9_.-]{0,16}",
        id in "[0-9A-F]{0,8}",
    ) {
        let info = InfoFrame::new(&product, &hardware, &firmware, &id).unwrap();
        let back = InfoFrame::parse(&info.encode()).unwrap();
        prop_assert_eq!(back.product(), product.as_str());
        prop_assert_eq!(back.hardware(), hardware.as_str());
        prop_assert_eq!(back.firmware(), firmware.as_str());
        prop_assert_eq!(back.id(), id.as_str());
        // A field that fills its width runs into the next one, so words() can only split
        // fields that leave at least one blank.
        if [&product, &hardware, &firmware].iter().all(|f| f.len() < 16) {
            let words: Vec<&str> = [&product, &hardware, &firmware, &id]
                .into_iter()
                .map(String::as_str)
                .filter(|w| !w.is_empty())
                .collect();
            prop_assert_eq!(back.words().collect::<Vec<_>>(), words);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// (b) Chunking independence, (c) resynchronisation, (d) single-bit errors, (e) bulk == streaming
// ---------------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// (b) However the wire is cut into chunks, the same frames and the same statistics.
    #[test]
    fn any_chunking_gives_the_same_frames(
        ps in pieces(24),
        picks in vec(any::<Index>(), 0..30),
    ) {
        let wire = build(&ps);
        let cuts = cut_points(wire.bytes.len(), &picks);
        let whole = streamed_at(&wire.bytes, &[0, wire.bytes.len()]);
        let chunked = streamed_at(&wire.bytes, &cuts);
        prop_assert_eq!(&chunked.0, &whole.0);
        prop_assert_eq!(&chunked.1, &whole.1);
        prop_assert_eq!(&streamed_bytewise::<foc::Scanner>(&wire.bytes), &whole);
    }

    /// (b) The streaming decoder holds back only an undecided candidate: after every chunk, the
    /// bytes it holds are those from the first candidate still short of its frame's length, and
    /// every other byte is already in a frame or counted as skipped.
    #[test]
    fn only_an_undecided_candidate_is_held(
        ps in pieces(16),
        picks in vec(any::<Index>(), 0..30),
        bytewise in any::<bool>(),
    ) {
        let wire = build(&ps);
        let cuts = if bytewise {
            (0..=wire.bytes.len()).collect()
        } else {
            cut_points(wire.bytes.len(), &picks)
        };
        let mut d = Decoder::new();
        for w in cuts.windows(2) {
            d.feed(&wire.bytes[w[0]..w[1]], |_| {});
            prop_assert_eq!(d.buffered(), reference_held(&wire.bytes[..w[1]]), "after {}", w[1]);
            let s = d.stats();
            prop_assert_eq!(
                s.bytes(),
                24 * u64::from(s.frames())
                    + 77 * u64::from(s.info_frames())
                    + s.bytes_skipped()
                    + d.buffered() as u64
            );
        }
    }

    /// (c) Garbage, cut frames and fake headers between frames never lose an intact frame:
    /// every intact frame is decoded, in order, at its offset; any extra frame (one formed by
    /// chance inside garbage) lies wholly outside the intact frames.
    ///
    /// Choice made: garbage is not constrained (it may hold `9B 16`, `9B 4C`, whole headers), and
    /// cut frames and fake headers necessarily hold them. A candidate starting in such bytes and
    /// running into an intact frame can be valid by chance: about 1 in 65536 for a data frame.
    /// An info frame's check is a single byte, but its text must be ASCII, and any intact frame
    /// overlapping it brings a `9B` into that text; what remains is a cut info frame missing
    /// only its check byte with a frame behind it whose `9B` matches the check by chance. The
    /// checksums cannot settle such a wire, so the case is discarded by `prop_assume!` after an
    /// exact check with `parse` at every candidate position (`ambiguous`); it is so rare
    /// that no case in a run is expected to be discarded. The real-byte tests
    /// `cut_info_frame_*` in `real_frames.rs` pin the behaviour down without any discarding.
    #[test]
    fn garbage_never_loses_an_intact_frame(ps in pieces(24)) {
        let wire = build(&ps);
        prop_assume!(!ambiguous(&wire.bytes, &wire.intact));
        let (decoded, stats) = bulk(&wire.bytes);

        let found: Vec<(u64, FocFrame)> = decoded
            .iter()
            .filter(|d| wire.intact.iter().any(|(o, _)| *o == d.offset))
            .map(|d| (d.offset, d.frame))
            .collect();
        prop_assert_eq!(&found, &wire.intact);

        for d in decoded.iter().filter(|d| !wire.intact.iter().any(|(o, _)| *o == d.offset)) {
            let (s, e) = (d.offset, d.offset + d.frame.wire_len() as u64);
            for (o, f) in &wire.intact {
                prop_assert!(
                    e <= *o || *o + f.wire_len() as u64 <= s,
                    "extra frame at {} overlaps the intact frame at {}", s, o
                );
            }
        }
        let intact_data = wire.intact.iter().filter(|(_, f)| matches!(f, FocFrame::Data(_))).count();
        prop_assert!(stats.frames() as usize >= intact_data);
        prop_assert!(stats.info_frames() as usize >= wire.intact.len() - intact_data);
        prop_assert_eq!(
            stats.bytes(),
            24 * u64::from(stats.frames())
                + 77 * u64::from(stats.info_frames())
                + stats.bytes_skipped()
        );
        prop_assert_eq!(&streamed_bytewise::<foc::Scanner>(&wire.bytes), &(decoded, stats));
    }

    /// (d) One flipped bit anywhere in a frame is always caught, whatever surrounds it.
    #[test]
    fn single_bit_flip_is_always_rejected(
        before in pieces(6),
        f in frame(),
        bit in any::<Index>(),
        after in pieces(6),
        picks in vec(any::<Index>(), 0..8),
    ) {
        let mut bytes = encode(&f);
        let bit = bit.index(8 * bytes.len());
        bytes[bit / 8] ^= 1 << (bit % 8);

        let expected = match bit / 8 {
            0 => FrameError::NoSync { found: bytes[0] },
            1 => FrameError::UnknownLength { found: bytes[1] },
            _ => match parse(&bytes) {
                Err(e @ FrameError::Checksum { .. }) => e,
                other => return Err(TestCaseError::fail(format!(
                    "bit {bit}: expected a checksum error, got {other:?}"
                ))),
            },
        };
        prop_assert_eq!(parse(&bytes), Err(expected));
        match f {
            FocFrame::Data(_) => prop_assert!(DataFrame::parse(&bytes).is_err()),
            FocFrame::Info(_) => prop_assert!(InfoFrame::parse(&bytes).is_err()),
        }

        let head = build(&before).bytes;
        let at = head.len() as u64;
        let wire = [head, bytes, build(&after).bytes].concat();
        let (decoded, stats) = bulk(&wire);
        prop_assert!(
            decoded.iter().all(|d| d.offset != at),
            "corrupted frame decoded at {}", at
        );
        let cuts = cut_points(wire.len(), &picks);
        prop_assert_eq!(&streamed_at(&wire, &cuts), &(decoded, stats));
    }

    /// (e) The bulk iterator and the streaming decoder agree on arbitrary bytes, and both agree
    /// with the naive reference scanner.
    #[test]
    fn bulk_equals_streaming_on_arbitrary_bytes(
        bytes in prop_oneof![vec(any::<u8>(), 0..600), vec(noisy_byte(), 0..600)],
        picks in vec(any::<Index>(), 0..20),
    ) {
        let (decoded, stats) = bulk(&bytes);
        let cuts = cut_points(bytes.len(), &picks);
        let streamed = streamed_at(&bytes, &cuts);
        prop_assert_eq!(&streamed.0, &decoded);
        prop_assert_eq!(&streamed.1, &stats);
        let (ref_decoded, ref_stats) = reference(&bytes);
        prop_assert_eq!(&decoded, &ref_decoded);
        prop_assert_eq!(RefStats::from(&stats), ref_stats);
    }

    /// (e) The same on mixtures of valid frames, cut frames, fake headers and garbage.
    #[test]
    fn bulk_equals_streaming_on_frame_mixtures(
        ps in pieces(24),
        picks in vec(any::<Index>(), 0..20),
    ) {
        let wire = build(&ps);
        let (decoded, stats) = bulk(&wire.bytes);
        let cuts = cut_points(wire.bytes.len(), &picks);
        let streamed = streamed_at(&wire.bytes, &cuts);
        prop_assert_eq!(&streamed.0, &decoded);
        prop_assert_eq!(&streamed.1, &stats);
        prop_assert_eq!(&streamed_bytewise::<foc::Scanner>(&wire.bytes), &(decoded.clone(), stats));
        let mut all = Decoder::new();
        let mut out = Vec::new();
        all.decode_all(&wire.bytes, |d| out.push(d));
        prop_assert_eq!(&out, &decoded);
        prop_assert_eq!(all.stats(), &stats);
        let (ref_decoded, ref_stats) = reference(&wire.bytes);
        prop_assert_eq!(&decoded, &ref_decoded);
        prop_assert_eq!(RefStats::from(&stats), ref_stats);
    }

    /// Packet accounting over arbitrary packet sequences matches the rule of `foc::Stats` (steps
    /// modulo 65536: 0 is a duplicate, 2..=MAX_PACKET_GAP + 1 a loss of step - 1, anything else
    /// but 1 a restart), and every step is counted as exactly one event.
    #[test]
    fn packet_accounting(packet_numbers in vec(any::<u16>(), 1..40), start in any::<u16>()) {
        // Half of the numbers are small steps from the previous one, to exercise the counting.
        let mut last = start;
        let numbers: Vec<u16> = packet_numbers
            .iter()
            .enumerate()
            .map(|(i, &n)| {
                last = if i % 2 == 0 { last.wrapping_add(n % 4) } else { n };
                last
            })
            .collect();
        let (_, stats) = bulk(&packet_wire(&numbers));
        // The rule of `counters`, written out: a step of 2 then the number it skipped is two
        // adjacent frames swapped (a reordering: the loss the 2 counted is taken back and the
        // number stays).
        let (mut lost, mut duplicates, mut restarts, mut reordered, mut next) = (0, 0, 0, 0, 0);
        let mut last = numbers[0];
        let mut swap = false;
        for &n in &numbers[1..] {
            let step = u32::from(n.wrapping_sub(last));
            if swap && step == 0xFFFF {
                lost -= 1;
                reordered += 1;
                swap = false;
                continue;
            }
            swap = false;
            match step {
                0 => duplicates += 1,
                1 => next += 1,
                2 => {
                    lost += 1;
                    swap = true;
                }
                _ if step <= u32::from(MAX_PACKET_GAP) + 1 => lost += step - 1,
                _ => restarts += 1,
            }
            last = n;
        }
        prop_assert_eq!(stats.frames() as usize, numbers.len());
        prop_assert_eq!(stats.lost_packets(), lost);
        prop_assert_eq!(stats.duplicate_packets(), duplicates);
        prop_assert_eq!(stats.restarts(), restarts);
        prop_assert_eq!(stats.packets().reordered(), reordered);
        prop_assert_eq!(stats.last_packet(), Some(last));
        // Each step after the first frame is one event: next, duplicate, loss, restart, or a
        // swap's two steps.
        let steps = stats.frames() - 1;
        let lossy_steps = steps - next - duplicates - restarts - 2 * reordered;
        prop_assert!(stats.lost_packets() >= lossy_steps);
        prop_assert!(stats.lost_packets() <= u32::from(MAX_PACKET_GAP) * lossy_steps);
    }

    /// A sequence that only loses frames (never more than MAX_PACKET_GAP in a row) is counted
    /// exactly: no restart, no duplicate, and `frames + lost` is the span of its numbers.
    #[test]
    fn lossy_sequence_counts_its_true_loss(
        start in any::<u16>(),
        gaps in vec(prop_oneof![4 => Just(0u16), 2 => 0u16..5, 1 => 0..=MAX_PACKET_GAP], 0..60),
    ) {
        let numbers = run(start, &gaps);
        let (_, stats) = bulk(&packet_wire(&numbers));
        let true_loss: u32 = gaps.iter().map(|&g| u32::from(g)).sum();
        prop_assert_eq!(stats.restarts(), 0);
        prop_assert_eq!(stats.duplicate_packets(), 0);
        prop_assert_eq!(stats.lost_packets(), true_loss);
        prop_assert_eq!(u64::from(stats.frames()) + u64::from(stats.lost_packets()),
            1 + gaps.iter().map(|&g| 1 + u64::from(g)).sum::<u64>());
    }

    /// A sequence restarted in the middle (a new one from any number, with or without a silence
    /// before it, whatever the chunking) counts exactly one restart and the true loss of both
    /// runs, unless the new number plausibly continues the old run: then it is what it looks
    /// like (a duplicate, the next frame, or a loss within the limit).
    #[test]
    fn restart_in_the_middle_counts_one_restart(
        start in any::<u16>(),
        gaps_a in vec(prop_oneof![3 => Just(0u16), 1 => 0u16..50], 1..20),
        restart in prop_oneof![3 => any::<u16>(), 1 => (0u16..1100).prop_map(|d| d.wrapping_sub(50))],
        gaps_b in vec(prop_oneof![3 => Just(0u16), 1 => 0u16..50], 0..20),
        silence in prop_oneof![Just(None), (0u32..2000).prop_map(Some), any::<u32>().prop_map(Some)],
        picks in vec(any::<Index>(), 0..10),
    ) {
        let a = run(start, &gaps_a);
        let b_start = a.last().unwrap().wrapping_add(restart);
        let b = run(b_start, &gaps_b);
        let loss_a: u32 = gaps_a.iter().map(|&g| u32::from(g)).sum();
        let loss_b: u32 = gaps_b.iter().map(|&g| u32::from(g)).sum();
        let parts = [packet_wire(&a), packet_wire(&b)];
        let silences = [silence.unwrap_or(0)];

        let stats = match silence {
            None => bulk(&parts.concat()).1,
            Some(_) => {
                let (decoded, stats) = streamed_with_silences(&parts, &silences, Chunks::At(&picks));
                prop_assert_eq!(decoded.len(), a.len() + b.len());
                stats
            }
        };
        let limit = match silence {
            None => u32::from(MAX_PACKET_GAP) + 1,
            Some(frames) => frames.saturating_add(1).min(32768),
        };
        let step = u32::from(restart);
        let (lost, duplicates, restarts) = match step {
            0 => (0, 1, 0),
            1 => (0, 0, 0),
            _ if step <= limit => (step - 1, 0, 0),
            _ => (0, 0, 1),
        };
        prop_assert_eq!(stats.restarts(), restarts);
        prop_assert_eq!(stats.duplicate_packets(), duplicates);
        prop_assert_eq!(stats.lost_packets(), loss_a + loss_b + lost);
        prop_assert_eq!(stats.frames() as usize, a.len() + b.len());
    }

    /// Two sequences interleaved in any order, their numbers far apart (as two ESCs' are, or a
    /// replayed recording's and a live one's): every switch from one to the other is a restart,
    /// and the loss counted never exceeds the true loss of the two sequences.
    #[test]
    fn interleaved_sequences_never_count_more_than_the_true_loss(
        start in any::<u16>(),
        apart in 0x2000u16..=0xE000,
        gaps_a in vec(prop_oneof![3 => Just(0u16), 1 => 0u16..50], 1..40),
        gaps_b in vec(prop_oneof![3 => Just(0u16), 1 => 0u16..50], 1..40),
        order in vec(any::<bool>(), 2..80),
    ) {
        // Each run spans at most 40 * 50 = 2000 < 0x1000 numbers, so the two stay apart by at
        // least 0x1000 either way round the counter: no step between them looks like a loss.
        let a = run(start, &gaps_a);
        let b = run(start.wrapping_add(apart), &gaps_b);
        let (mut ia, mut ib) = (0, 0);
        let mut numbers = Vec::new();
        let mut from = Vec::new();
        for &take_a in &order {
            if take_a && ia < a.len() {
                numbers.push(a[ia]);
                from.push(true);
                ia += 1;
            } else if ib < b.len() {
                numbers.push(b[ib]);
                from.push(false);
                ib += 1;
            }
        }
        prop_assume!(!numbers.is_empty());
        let (_, stats) = bulk(&packet_wire(&numbers));
        let switches = from.windows(2).filter(|w| w[0] != w[1]).count() as u32;
        let true_loss: u32 = gaps_a[..ia.saturating_sub(1)]
            .iter()
            .chain(&gaps_b[..ib.saturating_sub(1)])
            .map(|&g| u32::from(g))
            .sum();
        prop_assert_eq!(stats.restarts(), switches);
        prop_assert_eq!(stats.duplicate_packets(), 0);
        prop_assert!(stats.lost_packets() <= true_loss);
        if switches == 0 {
            prop_assert_eq!(stats.lost_packets(), true_loss);
        }
    }

    /// Silences anywhere in a stream of frames, noise and cut frames, told to the decoder between
    /// chunks: the same frames and statistics whatever the chunking in between (byte at a time,
    /// whole stretches, random cuts), and the same as the reference scanner's.
    #[test]
    fn line_silent_in_any_chunking(
        stretches in vec((pieces(6), any::<u32>()), 1..6),
        steps in vec(prop_oneof![4 => Just(1u16), 2 => 0u16..4, 1 => any::<u16>()], 40),
        start in any::<u16>(),
        picks in vec(any::<Index>(), 0..20),
    ) {
        // Data frames numbered as a sequence with drops, duplicates and jumps.
        let mut packet = start;
        let mut steps = steps.iter().cycle();
        let mut parts = Vec::new();
        let mut silences = Vec::new();
        for (ps, silence) in &stretches {
            let ps: Vec<Piece> = ps
                .iter()
                .cloned()
                .map(|p| match p {
                    Piece::Intact(FocFrame::Data(d)) => {
                        packet = packet.wrapping_add(*steps.next().unwrap());
                        Piece::Intact(FocFrame::Data(DataFrame { packet, ..d }))
                    }
                    p => p,
                })
                .collect();
            parts.push(build(&ps).bytes);
            // Small silences mostly, so that they decide something.
            silences.push(silence % 8);
        }
        silences.pop();
        let whole = streamed_with_silences(&parts, &silences, Chunks::Whole);
        let chunked = streamed_with_silences(&parts, &silences, Chunks::At(&picks));
        prop_assert_eq!(&chunked, &whole);
        let bytewise = streamed_with_silences(&parts, &silences, Chunks::Bytewise);
        prop_assert_eq!(&bytewise, &whole);
        let (ref_decoded, mut ref_stats) = reference_with_silences(&parts, &silences);
        ref_stats.silent_frames = None;
        prop_assert_eq!(&whole.0, &ref_decoded);
        prop_assert_eq!(RefStats::from(&whole.1), ref_stats);
    }
}

/// Packet numbers from `start` on, each the previous plus 1 plus the next of `gaps` (frames lost).
fn run(start: u16, gaps: &[u16]) -> Vec<u16> {
    let mut n = start;
    let mut out = vec![n];
    for &g in gaps {
        n = n.wrapping_add(1).wrapping_add(g);
        out.push(n);
    }
    out
}

/// A wire of data frames with these packet numbers.
fn packet_wire(numbers: &[u16]) -> Vec<u8> {
    numbers
        .iter()
        .flat_map(|&packet| {
            DataFrame {
                packet,
                ..Default::default()
            }
            .encode()
        })
        .collect()
}

/// How [`streamed_with_silences`] cuts each part into chunks.
#[derive(Clone, Copy)]
enum Chunks<'a> {
    /// The part in one chunk.
    Whole,
    /// One byte at a time.
    Bytewise,
    /// Cut at these picks (as [`cut_points`]).
    At(&'a [Index]),
}

/// Streams `parts` into a decoder, telling it before each part but the first that the line was
/// silent (`silences[i - 1]` frames), each part cut into chunks as `chunks` says.
fn streamed_with_silences(
    parts: &[Vec<u8>],
    silences: &[u32],
    chunks: Chunks<'_>,
) -> (Vec<Decoded>, foc::Stats) {
    let mut d = Decoder::new();
    let mut out = Vec::new();
    for (i, part) in parts.iter().enumerate() {
        if i > 0 {
            d.line_silent(silences[i - 1], |x| out.push(x));
            assert_eq!(d.buffered(), 0);
        }
        let cuts: Vec<usize> = match chunks {
            Chunks::Whole => vec![0, part.len()],
            Chunks::Bytewise => (0..=part.len()).collect(),
            Chunks::At(picks) => cut_points(part.len(), picks),
        };
        for w in cuts.windows(2) {
            d.feed(&part[w[0]..w[1]], |x| out.push(x));
        }
    }
    d.flush(|x| out.push(x));
    (out, *d.stats())
}

/// The bulk scanner's first look after a run of noise (a frame at one of the run's first sync
/// bytes, tried while that has been right lately) changes what it looks at first, never what
/// it finds or counts: over phases of plain line noise (where that look is right), noise full
/// of sync bytes, fake headers and whole fake frames (where it is wrong, and stops being
/// tried), then plain noise again, with runs up to 200 bytes (past a 64-position window), cut
/// and flipped frames, and info frames, it gives what the streaming decoder gives a byte at a
/// time, which never looks that way.
#[test]
fn the_first_look_after_noise_finds_and_counts_as_a_byte_at_a_time() {
    let mut x = 0x2545_F491_4F6C_DD1Du64;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let info = InfoFrame::new("XR_FOC_ESC", "HW577", "01.0.00", "12345678")
        .unwrap()
        .encode();
    let mut wire = Vec::new();
    let mut packet = 0u16;
    for phase in 0..6 {
        let hostile = phase % 2 == 1;
        for _ in 0..400 {
            let r = next();
            if r % 3 == 0 {
                let len = (next() % if r % 7 == 0 { 200 } else { 64 }) as usize + 1;
                for _ in 0..len {
                    let b = next();
                    match (hostile, b % 12) {
                        (true, 0) => wire.push(0x9B),
                        (true, 1) => wire.extend_from_slice(&[0x9B, 0x16]),
                        (true, 2) => wire.extend_from_slice(&[0x9B, 0x16, 0x01, 0x02]),
                        (true, 3) => wire.extend_from_slice(&[0x9B, 0x4C]),
                        _ => wire.push((b >> 8) as u8),
                    }
                }
            }
            let mut frame = DataFrame {
                packet,
                ..Default::default()
            }
            .encode();
            packet = packet.wrapping_add(1);
            match next() % 25 {
                0 => frame[(next() % 24) as usize] ^= 1 << (next() % 8),
                1 => {
                    wire.extend_from_slice(&frame[..(next() % 23) as usize + 1]);
                    continue;
                }
                2 => wire.extend_from_slice(&info),
                _ => {}
            }
            wire.extend_from_slice(&frame);
        }
    }
    let (found, stats) = bulk(&wire);
    assert!(found.len() > 2000, "{}", found.len());
    assert!(stats.checksum_failures() > 100, "{stats:?}");
    assert_eq!((found, stats), streamed_bytewise::<foc::Scanner>(&wire));
}

proptest! {
    // Each case is a wire of about 60 kB, checked against the byte-by-byte reference.
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// (e) The same on wires long enough for the bulk scanner's candidate maps (a block of
    /// 4096 positions and a frame's bytes after it, `foc::follow`): line noise, a run of frames
    /// long enough to stop following, noise full of fake headers (which stops it too), line
    /// noise again.
    #[test]
    fn bulk_equals_streaming_and_the_reference_on_long_noisy_wires(
        line in vec(line_noise_piece(), 300..600),
        quiet in vec(frame(), 300..400),
        fakes in vec(piece(), 400..800),
        again in vec(line_noise_piece(), 300..600),
        picks in vec(any::<Index>(), 0..8),
    ) {
        let ps: Vec<Piece> = line
            .into_iter()
            .chain(quiet.into_iter().map(Piece::Intact))
            .chain(fakes)
            .chain(again)
            .collect();
        let wire = build(&ps);
        let whole = streamed_at(&wire.bytes, &[0, wire.bytes.len()]);
        let cuts = cut_points(wire.bytes.len(), &picks);
        prop_assert_eq!(&streamed_at(&wire.bytes, &cuts), &whole);
        prop_assert_eq!(&bulk(&wire.bytes), &whole);
        let (ref_decoded, ref_stats) = reference(&wire.bytes);
        prop_assert_eq!(&whole.0, &ref_decoded);
        prop_assert_eq!(RefStats::from(&whole.1), ref_stats);
    }
}
