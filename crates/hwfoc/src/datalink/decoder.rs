//! Finding DataLink V2 frames in a byte stream: the streaming [`Decoder`] and the bulk
//! [`frames`] iterator, with the guarantees of the HW-FOC scanner ([`crate::foc::decoder`]).
//!
//! The scanner is content-based: a candidate is a `9B` followed by a length byte 0x9E or 0xA0.
//! It is rejected as soon as its version and command bytes are not `01 02` (a
//! [bad header](Stats::bad_headers)), or once its 160 bytes are there and the CRC does
//! not match (a [checksum failure](Stats::checksum_failures)); a rejected candidate costs one
//! byte: scanning resumes at the byte after its `9B`, so a lone `9B`, a fake header, a cut frame
//! or garbage never hides a following intact frame. A verified frame is taken whole. Both
//! decoders run the same scanner, so they give the same frames and statistics for the same
//! bytes however the stream is cut into chunks.

use crate::foc::decoder::{bytes_equal, find_sync_then};
use crate::scan::{self, Candidate, Scan, StreamDecoder};

use super::frame::{FrameReport, HubFrame};
use super::layout::{FRAME_LEN, LengthByte, is_version_and_command};
use super::stats::Stats;

/// A DataLink frame, where it started in the stream, and what reading its records found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Decoded {
    /// Offset of the frame's first byte, counting every byte given to the decoder since it was
    /// created (or, for [`frames`], from the start of the slice).
    pub offset: u64,
    /// The frame.
    pub frame: HubFrame,
    /// Its length byte, and its empty, bad-channel and duplicate-channel records.
    pub report: FrameReport,
}

impl Decoded {
    /// Hands on each of the frame's ESC frames: `emit(channel, offset, frame)` with its
    /// channel, at the hub frame's offset. (Not forced inline: in a loop over HW-FOC frames, the
    /// hub's eight records would crowd the usual path.)
    #[inline]
    pub fn each_esc_frame(
        &self,
        mut emit: impl FnMut(Option<u8>, u64, &crate::telemetry::AnyFrame),
    ) {
        for (channel, frame) in self.frame.escs() {
            let frame = crate::telemetry::AnyFrame::Data(crate::telemetry::Data::DataLink(*frame));
            emit(Some(channel as u8), self.offset, &frame);
        }
    }
}

/// Offset of the first candidate in `hay`: a `9B` followed by 0x9E or 0xA0, or a `9B` that is
/// the last byte of `hay`.
#[inline]
fn find_header(hay: &[u8]) -> Option<usize> {
    find_sync_then(
        hay,
        |b| LengthByte::from_byte(b).is_some(),
        |word| {
            bytes_equal(word, LengthByte::Covered.byte())
                | bytes_equal(word, LengthByte::Total.byte())
        },
    )
}

/// How many bytes of a candidate decide it: 2 while it is only its `9B` (does a length byte
/// follow?), 4 until its version and command are known, then the whole frame.
#[inline(always)]
pub(crate) fn candidate_len(held: usize) -> usize {
    match held {
        0 | 1 => 2,
        2 | 3 => 4,
        _ => FRAME_LEN,
    }
}

/// What a candidate (a `9B` and a length byte, or a `9B` alone at the end) is.
enum Verdict {
    Frame(HubFrame, FrameReport),
    BadHeader,
    BadCrc,
    /// More bytes are needed.
    Undecided,
}

#[inline(always)]
fn judge(candidate: &[u8]) -> Verdict {
    let (Some(&length_byte), Some(&version), Some(&command)) =
        (candidate.get(1), candidate.get(2), candidate.get(3))
    else {
        return Verdict::Undecided;
    };
    if !is_version_and_command(version, command) {
        return Verdict::BadHeader;
    }
    let Some(frame) = candidate.first_chunk::<FRAME_LEN>() else {
        return Verdict::Undecided;
    };
    if !HubFrame::crc_ok(frame) {
        return Verdict::BadCrc;
    }
    match LengthByte::from_byte(length_byte) {
        Some(length_byte) => {
            let (frame, report) = HubFrame::read(frame, length_byte);
            Verdict::Frame(frame, report)
        }
        // `find_header` stops at no other length byte.
        None => Verdict::BadHeader,
    }
}

/// Finds the next frame in `data` from `*pos`, counting what it passes over in `stats`.
///
/// Returns the frame and its start offset, with `*pos` just after it. Returns `None` when no
/// further frame can be decided: `*pos` is then `data.len()`, or, unless `at_end`, the start of
/// a candidate that needs more bytes (nothing of it counted yet).
#[inline(always)]
fn scan_next(
    data: &[u8],
    pos: &mut usize,
    stats: &mut Stats,
    at_end: bool,
) -> Option<(usize, HubFrame, FrameReport)> {
    loop {
        let Some(k) = find_header(&data[*pos..]) else {
            stats.skip(data.len() - *pos);
            *pos = data.len();
            return None;
        };
        stats.skip(k);
        let i = *pos + k;
        *pos = i;
        match take_candidate(data, pos, stats, at_end) {
            Candidate::Frame(found) => return Some(found),
            Candidate::Undecided => return None,
            Candidate::Rejected => {}
        }
        stats.skip(1);
        *pos = i + 1;
    }
}

/// Decides the candidate at `*pos` (a `9B` and a DataLink length byte, or a `9B` that ends
/// `data`): a frame is counted and taken, `*pos` just after it; a bad header or CRC is
/// counted. Nothing is skipped here, and `*pos` moves only past a frame.
#[inline(always)]
pub(crate) fn take_candidate(
    data: &[u8],
    pos: &mut usize,
    stats: &mut Stats,
    at_end: bool,
) -> Candidate<(usize, HubFrame, FrameReport)> {
    let i = *pos;
    match judge(&data[i..]) {
        Verdict::Frame(frame, report) => {
            stats.frame(&frame, &report);
            *pos = i + FRAME_LEN;
            Candidate::Frame((i, frame, report))
        }
        Verdict::BadHeader => {
            stats.bad_header();
            Candidate::Rejected
        }
        Verdict::BadCrc => {
            stats.crc_failure();
            Candidate::Rejected
        }
        Verdict::Undecided if !at_end => Candidate::Undecided,
        // Cut off by the end of the stream: skipped, not counted as an error.
        Verdict::Undecided => Candidate::Rejected,
    }
}

/// The DataLink V2 scanner, as the streaming layer ([`crate::scan`]) runs it:
/// [`Decoder`] and [`Frames`] are it under [`StreamDecoder`] and [`Scan`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Scanner;

impl crate::scan::sealed::Sealed for Scanner {}
impl crate::scan::sealed::Sealed for Stats {}

impl scan::Stats for Stats {
    const NEW: Self = Stats::new();

    #[inline]
    fn bytes(&self) -> u64 {
        Stats::bytes(self)
    }

    #[inline]
    fn add_bytes(&mut self, n: usize) {
        Stats::add_bytes(self, n);
    }

    fn line_silent(&mut self, max_frames: u32) {
        Stats::line_silent(self, max_frames);
    }

    #[inline]
    fn skip_bytes(&mut self, n: usize) {
        self.skip(n);
    }

    /// Joined when `later` found no hub frame (`first_packet` is an ESC's, not the hub's).
    fn then(&mut self, later: &Self, _: Option<u16>) -> bool {
        Stats::then(self, later)
    }
}

impl scan::Scanner for Scanner {
    type Item = Decoded;
    type Stats = Stats;
    type Held = [u8; FRAME_LEN - 1];
    type Pair = [u8; 2 * FRAME_LEN];
    const HELD: Self::Held = [0; FRAME_LEN - 1];
    const PAIR: Self::Pair = [0; 2 * FRAME_LEN];
    const MAX_LEN: usize = FRAME_LEN;

    #[inline(always)]
    fn candidate_len(held: &[u8]) -> usize {
        candidate_len(held.len())
    }

    /// Runs the scanner over `data`, whose first byte is at stream offset `base`, giving every
    /// frame to `on_frame`; returns where it stopped (as the scanner's `scan_next` leaves `pos`).
    #[inline(never)]
    fn scan_all<const AT_END: bool>(
        data: &[u8],
        base: u64,
        stats: &mut Stats,
        on_frame: &mut impl FnMut(Decoded),
    ) -> usize {
        let mut pos = 0;
        while let Some((at, frame, report)) = scan_next(data, &mut pos, stats, AT_END) {
            on_frame(Decoded {
                offset: base + at as u64,
                frame,
                report,
            });
        }
        pos
    }

    #[inline]
    fn scan_next(data: &[u8], pos: &mut usize, stats: &mut Stats) -> Option<Decoded> {
        scan_next(data, pos, stats, true).map(|(at, frame, report)| Decoded {
            offset: at as u64,
            frame,
            report,
        })
    }
}

/// A streaming DataLink V2 decoder: feed it bytes in any chunking, get every frame once (the
/// streaming layer's [`StreamDecoder`] over the DataLink scanner).
///
/// Its state is a 159-byte buffer for a frame still arriving plus the [`Stats`]:
/// 416 bytes (`size_of::<Decoder>()`, checked by a test), no allocation, no timing.
/// Large chunks are scanned in place; only an unfinished tail is copied. One byte pushed
/// completes at most one frame.
///
/// ```
/// use hwfoc::datalink::{Decoder, HubFrame, LengthByte};
/// use hwfoc::foc::DataFrame;
///
/// let mut frame = HubFrame::new(7);
/// frame.slots[1] = Some(DataFrame { packet: 300, voltage_raw: 252, ..Default::default() });
/// let mut wire = vec![0x00, 0x9B, 0x9E]; // noise and a fake header
/// wire.extend_from_slice(&frame.encode_as(LengthByte::Total));
///
/// let mut decoder = Decoder::new();
/// let mut got = Vec::new();
/// for &byte in &wire {
///     decoder.push(byte, |d| got.push(d));
/// }
/// decoder.flush(|d| got.push(d));
/// assert_eq!(got.len(), 1);
/// assert_eq!((got[0].offset, got[0].frame), (3, frame));
/// let stats = decoder.stats();
/// assert_eq!((stats.bytes_skipped(), stats.bad_headers()), (3, 1));
/// assert_eq!(stats.frames_with_length_byte(LengthByte::Total), 1);
/// assert_eq!(stats.channel(1).unwrap().last(), Some(300));
/// ```
///
/// # Silences
///
/// [`line_silent`](StreamDecoder::line_silent)`(max_frames, ..)`: at most `max_frames`
/// DataLink frames could have been sent in the silence (160 byte times each at
/// [`BAUD_RATE`](super::BAUD_RATE), about 13.9 ms). As for the ESC
/// [`Decoder`](crate::foc::Decoder), the held bytes are decided at once and the next frame's
/// counter step counts as a loss only up to `max_frames + 1` (a larger step is a restart). Each
/// channel's next packet-number step counts as a loss only up to
/// [`esc_frames_in`](super::esc_frames_in)`(max_frames) + 1`, the most frames that ESC could have
/// sent on its own 19200-baud wire in that time.
///
/// ```
/// use hwfoc::datalink::{BAUD_RATE, Decoder, HubFrame, FRAME_LEN};
/// use hwfoc::wire::byte_ns;
///
/// let mut decoder = Decoder::new();
/// decoder.feed(&HubFrame::new(1000).encode(), |_| {});
/// // 1 s without a byte: at most 1 s / 160 byte times = 72 frames could have been sent.
/// let max_frames = (1e9 / (FRAME_LEN as f64 * byte_ns(BAUD_RATE))) as u32;
/// assert_eq!(max_frames, 72);
/// decoder.line_silent(max_frames, |_| {});
/// decoder.feed(&HubFrame::new(1200).encode(), |_| {}); // the hub restarted
/// decoder.feed(&HubFrame::new(1203).encode(), |_| {}); // 2 frames lost
/// assert_eq!(decoder.stats().restarts(), 1);
/// assert_eq!(decoder.stats().lost_packets(), 2);
/// ```
pub type Decoder = StreamDecoder<Scanner>;

/// Decodes every DataLink frame in a complete buffer, in place: the bulk path.
///
/// The iterator borrows the slice and allocates nothing; a frame cut off by the end of the
/// slice is skipped. It yields exactly what a [`Decoder`] fed the same bytes and then
/// flushed would, with the same statistics.
///
/// ```
/// use hwfoc::datalink::{self, HubFrame};
///
/// let mut wire = Vec::new();
/// for counter in 0..3u16 {
///     wire.extend_from_slice(&HubFrame::new(counter).encode());
/// }
/// wire[200] ^= 0x04; // corrupt the second frame
/// let mut it = datalink::frames(&wire);
/// let counters: Vec<u16> = it.by_ref().map(|d| d.frame.counter).collect();
/// assert_eq!(counters, [0, 2]);
/// assert_eq!(it.stats().checksum_failures(), 1);
/// assert_eq!(it.stats().lost_packets(), 1);
/// ```
pub fn frames(data: &[u8]) -> Frames<'_> {
    Scan::new(data)
}

/// Iterator returned by [`frames`].
pub type Frames<'a> = Scan<'a, Scanner>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::SYNC;

    #[test]
    fn find_header_matches_a_plain_search() {
        let near = [0x9E, 0xA0, 0x9D, 0x9F, 0xA1, 0x16];
        crate::foc::decoder::tests::assert_matches_a_plain_search(find_header, &[0x9E, 0xA0], near);
    }

    #[test]
    fn state_size() {
        assert_eq!(size_of::<Decoder>(), 416);
        assert!(size_of::<Decoder>() <= 416);
    }

    #[test]
    fn held_candidate_resolves_across_calls() {
        let f = HubFrame::new(9).encode();
        let mut d = Decoder::new();
        let mut n = 0;
        for (i, chunk) in [&f[..1], &f[1..3], &f[3..4], &f[4..159]].iter().enumerate() {
            d.feed(chunk, |_| n += 1);
            assert_eq!((n, d.buffered()), (0, [1, 3, 4, 159][i]));
        }
        d.feed(&f[159..], |x| {
            assert_eq!(x.offset, 0);
            n += 1
        });
        assert_eq!((n, d.buffered()), (1, 0));
        // A bad header is decided on its fourth byte, without waiting for 160 bytes.
        d.feed(&[SYNC, 0x9E, 0x01], |_| n += 1);
        assert_eq!(d.buffered(), 3);
        d.feed(&[0x03], |_| n += 1);
        assert_eq!((d.buffered(), d.stats().bad_headers()), (0, 1));
    }
}
