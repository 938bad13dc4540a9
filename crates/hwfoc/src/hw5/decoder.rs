//! Finding HW5 frames in a byte stream: the streaming [`Decoder`] and the bulk [`frames`]
//! iterator, with the guarantees of the other scanners ([`crate::scan`]).
//!
//! The scanner is content-based. A candidate starts at `FE 01` (a frame from the ESC) or
//! `01 FD` (a request to it), or at an `FE` or `01` that is the last byte so far. It is
//! decided, as soon as its bytes are there, by:
//!
//! 1. its third byte: `00` after `FE 01`, `03` after `01 FD`, else a
//!    [bad header](Stats::bad_headers);
//! 2. its code and type (bytes 3-5): the kinds they allow ([`kinds_of`]), shortest first; none
//!    is an [unknown type](Stats::unknown_types) (its length cannot be known);
//! 3. for telemetry, its payload length byte (byte 6) `17`, else a bad header;
//! 4. the CRC over each allowed length in turn: the first that matches makes it a frame of that
//!    kind; none is a [checksum failure](Stats::checksum_failures).
//!
//! A rejected candidate costs one byte: scanning resumes at the byte after its start, so a
//! fake header, a cut or unknown frame or garbage never hides a following intact frame. A
//! verified frame of any kind is taken whole and counted by kind; only telemetry frames are
//! handed on. Both decoders run the same scanner, so they give the same frames and statistics
//! for the same bytes however the stream is cut into chunks.

use crate::foc::decoder::bytes_equal;
use crate::scan::{self, Candidate, Scan, SkipBytes, StreamDecoder, impl_scanner};

use super::frame::{TelemetryFrame, crc_ok};
use super::layout::{
    CODE_AT, ESC_ADDRESS, ESC_START, HEADER_LEN, Kind, MAX_FRAME_LEN, PAYLOAD_LEN_AT, REQUEST_MARK,
    TELEMETRY_LEN, TELEMETRY_PAYLOAD_LEN, TYPE_AT, direction_of, envelope, kinds_of,
};
use super::stats::Stats;

/// A telemetry frame and where it started in the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Decoded {
    /// Offset of the frame's first byte, counting every byte given to the decoder since it was
    /// created (or, for [`frames`], from the start of the slice).
    pub offset: u64,
    /// The frame.
    pub frame: TelemetryFrame,
}

/// A verified frame taken by [`take_candidate`]: telemetry, decoded, or another kind, counted
/// only.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Taken {
    Telemetry(TelemetryFrame),
    Other(Kind),
}

/// Offset of the first candidate in `hay`: `FE 01` or `01 FD`, or an `FE` or `01` that is the
/// last byte of `hay` (`mixed.rs` can look for HW5 candidates with it).
#[inline]
pub(crate) fn find_start(hay: &[u8]) -> Option<usize> {
    let mut base = 0;
    // Eight positions at a time: the word at `base` for the first bytes and the word one byte
    // later for the second bytes.
    while let Some(w) = hay.get(base..base + 9) {
        let word = |at: usize| u64::from_le_bytes(w[at..at + 8].try_into().unwrap_or([0; 8]));
        let (first, second) = (word(0), word(1));
        let hits = (bytes_equal(first, ESC_START) & bytes_equal(second, ESC_ADDRESS))
            | (bytes_equal(first, ESC_ADDRESS) & bytes_equal(second, REQUEST_MARK));
        if hits != 0 {
            return Some(base + (hits.trailing_zeros() / 8) as usize);
        }
        base += 8;
    }
    let tail = &hay[base..];
    (0..tail.len())
        .find(|&j| match tail.get(j + 1) {
            Some(&second) => direction_of(tail[j], second).is_some(),
            None => tail[j] == ESC_START || tail[j] == ESC_ADDRESS,
        })
        .map(|j| base + j)
}

/// How many bytes of a candidate decide it, once its first `held` bytes are known and do not:
/// 2 (a direction?), 3 (its third byte), 6 (its code and type), 7 for telemetry (its payload
/// length byte), then the next length its type allows.
#[inline(always)]
pub(crate) fn candidate_len(held: &[u8]) -> usize {
    match held.len() {
        0 | 1 => 2,
        2 => 3,
        3..HEADER_LEN => HEADER_LEN,
        n => {
            let kinds = match direction_of(held[0], held[1]) {
                Some(direction) => kinds_of(
                    direction,
                    held[CODE_AT],
                    u16::from_le_bytes([held[TYPE_AT], held[TYPE_AT + 1]]),
                ),
                None => &[],
            };
            if kinds.first() == Some(&Kind::Telemetry) && n == HEADER_LEN {
                return HEADER_LEN + 1;
            }
            kinds
                .iter()
                .map(|k| k.wire_len())
                .find(|&len| len > n)
                .unwrap_or(n + 1)
        }
    }
}

/// What a candidate is.
enum Verdict {
    Frame(Kind),
    /// Its first two bytes are no envelope's (not counted: the scanner never stops there).
    NoCandidate,
    BadHeader,
    UnknownType,
    BadCrc,
    /// A telemetry frame whose CRC matched with a value out of range.
    OutOfRange,
    /// More bytes are needed.
    Undecided,
}

#[inline(always)]
fn judge(c: &[u8]) -> Verdict {
    let (Some(&first), Some(&second)) = (c.first(), c.get(1)) else {
        return Verdict::Undecided;
    };
    let Some(direction) = direction_of(first, second) else {
        return Verdict::NoCandidate;
    };
    let Some(&third) = c.get(2) else {
        return Verdict::Undecided;
    };
    if third != envelope(direction)[2] {
        return Verdict::BadHeader;
    }
    let Some(h) = c.first_chunk::<HEADER_LEN>() else {
        return Verdict::Undecided;
    };
    let kinds = kinds_of(
        direction,
        h[CODE_AT],
        u16::from_le_bytes([h[TYPE_AT], h[TYPE_AT + 1]]),
    );
    match kinds.first() {
        None => return Verdict::UnknownType,
        Some(Kind::Telemetry) => match c.get(PAYLOAD_LEN_AT) {
            None => return Verdict::Undecided,
            Some(&b) if b != TELEMETRY_PAYLOAD_LEN => return Verdict::BadHeader,
            Some(_) => {}
        },
        Some(_) => {}
    }
    for &kind in kinds {
        if c.len() < kind.wire_len() {
            return Verdict::Undecided;
        }
        if crc_ok(c, kind.wire_len()) {
            return match c.first_chunk::<TELEMETRY_LEN>() {
                Some(f) if kind == Kind::Telemetry => {
                    match TelemetryFrame::from_verified(f).out_of_range() {
                        Some(_) => Verdict::OutOfRange,
                        None => Verdict::Frame(kind),
                    }
                }
                _ => Verdict::Frame(kind),
            };
        }
    }
    Verdict::BadCrc
}

/// Decides the candidate at `*pos` (an envelope's first two bytes, or an `FE` or `01` that
/// ends `data`): a frame of any kind is counted and taken, `*pos` just after it; a bad header,
/// unknown type or bad CRC is counted. Nothing is skipped here, and `*pos` moves only past a
/// frame.
#[inline(always)]
pub(crate) fn take_candidate(
    data: &[u8],
    pos: &mut usize,
    stats: &mut Stats,
    at_end: bool,
) -> Candidate<(usize, Taken)> {
    let i = *pos;
    let c = &data[i..];
    match judge(c) {
        Verdict::Frame(kind) => {
            stats.frame(kind);
            *pos = i + kind.wire_len();
            let taken = match c.first_chunk::<TELEMETRY_LEN>() {
                Some(f) if kind == Kind::Telemetry => {
                    Taken::Telemetry(TelemetryFrame::from_verified(f))
                }
                _ => Taken::Other(kind),
            };
            Candidate::Frame((i, taken))
        }
        Verdict::NoCandidate => Candidate::Rejected,
        Verdict::BadHeader => {
            stats.bad_header();
            Candidate::Rejected
        }
        Verdict::UnknownType => {
            stats.unknown_type();
            Candidate::Rejected
        }
        Verdict::BadCrc => {
            stats.crc_failure();
            Candidate::Rejected
        }
        Verdict::OutOfRange => {
            stats.out_of_range_frame();
            Candidate::Rejected
        }
        Verdict::Undecided if !at_end => Candidate::Undecided,
        // Cut off by the end of the stream: skipped, not counted as an error.
        Verdict::Undecided => Candidate::Rejected,
    }
}

/// Finds the next telemetry frame in `data` from `*pos`, counting what it passes over in
/// `stats` (frames of other kinds are taken and counted on the way): the search loop of
/// [`scan::next_candidate`] over [`find_start`] and [`take_candidate`]. Offsets are in `data`
/// (`_base`, the stream offset of its first byte, is not needed).
#[inline(always)]
fn scan_next(
    data: &[u8],
    pos: &mut usize,
    _base: u64,
    stats: &mut Stats,
    at_end: bool,
) -> Option<(usize, TelemetryFrame)> {
    loop {
        let take = |data: &[u8], pos: &mut usize, stats: &mut Stats| {
            take_candidate(data, pos, stats, at_end)
        };
        match scan::next_candidate(data, pos, stats, find_start, take)? {
            (at, Taken::Telemetry(frame)) => return Some((at, frame)),
            (_, Taken::Other(_)) => {}
        }
    }
}

impl SkipBytes for Stats {
    #[inline]
    fn skip(&mut self, n: usize) {
        Stats::skip(self, n);
    }
}

/// The HW5 scanner, as the streaming layer ([`crate::scan`]) runs it: [`Decoder`] and
/// [`Frames`] are it under [`StreamDecoder`] and [`Scan`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Scanner;

impl_scanner!(
    Scanner,
    Stats,
    Decoded,
    MAX_FRAME_LEN,
    candidate_len,
    scan_next
);

/// A streaming HW5 decoder: feed it bytes in any chunking, get every telemetry frame once (the
/// streaming layer's [`StreamDecoder`] over the HW5 scanner).
///
/// Its state is a 104-byte buffer for a frame still arriving plus the [`Stats`]: 164 bytes
/// (`size_of::<Decoder>()`, checked by a test), no allocation, no timing.
///
/// ```
/// use hwfoc::hw5::{Decoder, Kind, TelemetryFrame};
///
/// let frame = TelemetryFrame { throttle: 30, voltage_raw: 480, ..Default::default() };
/// let ping = [0x01, 0xFD, 0x03, 0x03, 0x2C, 0x24, 0x00, 0x01, 0x60, 0x60];
/// let mut wire = vec![0x00, 0xFE, 0x01, 0x07]; // noise and a fake header
/// wire.extend_from_slice(&ping);
/// wire.extend_from_slice(&frame.encode());
///
/// let mut decoder = Decoder::new();
/// let mut got = Vec::new();
/// for &byte in &wire {
///     decoder.push(byte, |d| got.push(d));
/// }
/// decoder.flush(|d| got.push(d));
/// assert_eq!(got.len(), 1);
/// assert_eq!((got[0].offset, got[0].frame), (14, frame));
/// let stats = decoder.stats();
/// assert_eq!((stats.bytes_skipped(), stats.bad_headers()), (4, 1));
/// assert_eq!(stats.frames(Kind::PingRequest), 1);
/// ```
///
/// # Silences
///
/// HW5 frames carry no packet counter, so [`line_silent`](StreamDecoder::line_silent)`(_, ..)`
/// only decides the held bytes at once (a frame cut by the silence is dropped, its bytes
/// skipped), as [`flush`](StreamDecoder::flush) does; its `max_frames` is not used. Loss is
/// judged from time by the layers above, against [`FRAME_PERIOD_RUNNING`](super::FRAME_PERIOD_RUNNING)
/// and [`FRAME_PERIOD_IDLE`](super::FRAME_PERIOD_IDLE).
///
/// ```
/// use hwfoc::hw5::{Decoder, TelemetryFrame};
///
/// let bytes = TelemetryFrame::default().encode();
/// let mut decoder = Decoder::new();
/// let mut n = 0;
/// decoder.feed(&bytes[..20], |_| n += 1);
/// decoder.line_silent(50, |_| n += 1); // the rest of the frame never came
/// decoder.feed(&bytes, |_| n += 1);
/// assert_eq!(n, 1);
/// assert_eq!(decoder.stats().bytes_skipped(), 20);
/// ```
pub type Decoder = StreamDecoder<Scanner>;

/// Decodes every HW5 telemetry frame in a complete buffer, in place: the bulk path.
///
/// The iterator borrows the slice and allocates nothing; a frame cut off by the end of the
/// slice is skipped. It yields exactly what a [`Decoder`] fed the same bytes and then flushed
/// would, with the same statistics.
///
/// ```
/// use hwfoc::hw5::{self, TelemetryFrame};
///
/// let mut wire = Vec::new();
/// for throttle in 0..3u8 {
///     wire.extend_from_slice(&TelemetryFrame { throttle, ..Default::default() }.encode());
/// }
/// wire[40] ^= 0x04; // corrupt the second frame
/// let mut it = hw5::frames(&wire);
/// let throttles: Vec<u8> = it.by_ref().map(|d| d.frame.throttle).collect();
/// assert_eq!(throttles, [0, 2]);
/// assert_eq!(it.stats().checksum_failures(), 1);
/// assert_eq!(it.stats().bytes_skipped(), 32);
/// ```
pub fn frames(data: &[u8]) -> Frames<'_> {
    Scan::new(data)
}

/// Iterator returned by [`frames`].
pub type Frames<'a> = Scan<'a, Scanner>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw5::layout::CHECKSUM;

    #[test]
    fn find_start_matches_a_plain_search() {
        let plain = |hay: &[u8]| {
            (0..hay.len()).find(|&j| match hay.get(j + 1) {
                Some(&b) => (hay[j], b) == (0xFE, 0x01) || (hay[j], b) == (0x01, 0xFD),
                None => hay[j] == 0xFE || hay[j] == 0x01,
            })
        };
        let alphabet = [0xFE, 0x01, 0xFD, 0x00, 0xFF, 0x02, 0x7E, 0x81];
        let mut x = 0x1234_5678_9ABC_DEF1u64;
        let mut buf = [0u8; 40];
        for round in 0..20_000 {
            let len = round % buf.len();
            for b in buf.iter_mut() {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                *b = alphabet[(x % 8) as usize];
            }
            // Mostly other bytes, so that the hits fall anywhere in a word.
            for b in buf.iter_mut().take(len) {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                if !x.is_multiple_of(5) {
                    *b = 0x55;
                }
            }
            let hay = &buf[..len];
            for start in 0..=hay.len() {
                assert_eq!(
                    find_start(&hay[start..]),
                    plain(&hay[start..]),
                    "{hay:02X?}"
                );
            }
        }
    }

    #[test]
    fn state_size() {
        assert_eq!(size_of::<Decoder>(), 168);
    }

    /// A frame of `kind` with its CRC.
    fn frame_of(kind: Kind) -> [u8; MAX_FRAME_LEN] {
        let mut f = [0x55u8; MAX_FRAME_LEN];
        f[..3].copy_from_slice(&kind.envelope());
        f[3] = 0x03;
        f[4..6].copy_from_slice(&kind.frame_type().to_le_bytes());
        f[6] = 0x17;
        if kind == Kind::Telemetry {
            // A voltage in range (50.4 V).
            f[15..17].copy_from_slice(&504u16.to_le_bytes());
        }
        CHECKSUM.seal(&mut f[..kind.wire_len()]);
        f
    }

    #[test]
    fn candidate_len_is_where_the_candidate_is_decided() {
        // For every prefix of every kind's frame (followed by other bytes), the verdict is
        // undecided exactly while the prefix is shorter than `candidate_len` says.
        for kind in Kind::ALL {
            let f = frame_of(kind);
            let mut n = 1;
            while n <= kind.wire_len() {
                let undecided = matches!(judge(&f[..n]), Verdict::Undecided);
                if undecided {
                    let need = candidate_len(&f[..n]);
                    assert!(need > n, "{kind} at {n}");
                    // Nothing is decided before `need` bytes.
                    for m in n..need {
                        assert!(
                            matches!(judge(&f[..m]), Verdict::Undecided),
                            "{kind} {n} {m}"
                        );
                    }
                } else {
                    assert_eq!(n, kind.wire_len(), "{kind}");
                }
                n += 1;
            }
            assert!(matches!(judge(&f[..kind.wire_len()]), Verdict::Frame(k) if k == kind));
        }
    }

    #[test]
    fn held_candidate_resolves_across_calls() {
        let f = TelemetryFrame::default().encode();
        let mut d = Decoder::new();
        let mut n = 0;
        for (i, chunk) in [&f[..1], &f[1..3], &f[3..6], &f[6..7], &f[7..31]]
            .iter()
            .enumerate()
        {
            d.feed(chunk, |_| n += 1);
            assert_eq!((n, d.buffered()), (0, [1, 3, 6, 7, 31][i]));
        }
        d.feed(&f[31..], |x| {
            assert_eq!(x.offset, 0);
            n += 1
        });
        assert_eq!((n, d.buffered()), (1, 0));
        // A bad payload length is decided on the seventh byte, without waiting for 32.
        d.feed(&f[..6], |_| n += 1);
        assert_eq!(d.buffered(), 6);
        d.feed(&[0x18], |_| n += 1);
        assert_eq!((d.buffered(), d.stats().bad_headers()), (0, 1));
        // An unknown type on the sixth byte.
        d.feed(&[0xFE, 0x01, 0x00, 0x03, 0x30], |_| n += 1);
        assert_eq!(d.buffered(), 5);
        d.feed(&[0x0C], |_| n += 1);
        assert_eq!((d.buffered(), d.stats().unknown_types()), (0, 1));
    }

    #[test]
    fn parameters_wait_for_each_length_in_turn() {
        let read = frame_of(Kind::ParametersRead);
        let mut d = Decoder::new();
        d.feed(&read[..9], |_| {});
        assert_eq!(d.buffered(), 9);
        d.feed(&read[9..58], |_| {});
        assert_eq!(d.buffered(), 58);
        d.feed(&read[58..104], |_| {});
        assert_eq!(d.buffered(), 104);
        d.feed(&read[104..], |_| {});
        assert_eq!(d.buffered(), 0);
        assert_eq!(d.stats().frames(Kind::ParametersRead), 1);
        assert_eq!(d.stats().bytes_skipped(), 0);
    }
}
