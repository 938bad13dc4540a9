//! Finding V3 frames in a byte stream: the streaming [`Decoder`] and the bulk [`frames`]
//! iterator, one scanner under the streaming layer of [`crate::scan`].
//!
//! With no checksum, a candidate (a `9B` not inside an accepted frame) is judged by its own
//! fields and by the frames around it, in this order:
//!
//! 1. **Plausible**: throttle and PWM at most 255 ([`V3Frame::is_plausible`]); otherwise it is
//!    rejected ([implausible](Stats::implausible)).
//! 2. **Chained**: it starts exactly where the last accepted frame ended
//!    ([`Stats::chain_end`]) and its counter is that frame's + 1, or skips at most
//!    [`MAX_CHAINED_GAP`](super::MAX_CHAINED_GAP) counters (frames cut out whole, counted
//!    [lost](Stats::lost_packets)): accepted on its own, decided on its tenth byte. So a frame
//!    between two cut frames, with no consecutive neighbour, is not lost.
//! 3. **Confirmed**: otherwise (the first frame of a stream, after garbage, a cut or corrupted
//!    frame, a counter that jumped further) it is accepted only as the first of three chained
//!    plausible frames with counters +1: decided on at most 30 bytes, each byte looked at once
//!    more. The frames after it are then accepted as chained, so a chain loses none of its
//!    frames; its first counter's step from the last accepted one counts
//!    [lost packets](Stats::lost_packets), a [duplicate](Stats::duplicate_packets) or a
//!    [restart](Stats::restarts).
//! 4. Otherwise it is rejected ([unconfirmed](Stats::unconfirmed)) and costs one byte: scanning
//!    resumes at the byte after its `9B`.
//!
//! Everything the rule reads of the past (where the chain ends, the last counter) lives in the
//! [`Stats`], which the streaming layer hands to the scanner with every chunk; a candidate is
//! decided by at most [`Scanner::MAX_LEN`](crate::scan::Scanner::MAX_LEN) = 30 bytes from its
//! start (the held bytes of a [`Decoder`]), and each decision reads only bytes that are there.
//! So both decoders give the same frames and statistics however the stream is cut into chunks.

use crate::chain::{self, Verdict};
use crate::counters::COUNTER24_MAX;
use crate::scan::{Scan, StreamDecoder, impl_scanner};
use crate::wire::SYNC;

use super::frame::{FRAME_LEN, V3Frame};
use super::stats::Stats;

/// How many chained frames lock the decoder onto a stream.
pub const CHAIN_TO_LOCK: usize = 3;

/// The most bytes that decide a candidate: three frames.
const MAX_LEN: usize = CHAIN_TO_LOCK * FRAME_LEN;

/// A V3 frame and where it started in the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Decoded {
    /// Offset of the frame's first byte, counting every byte given to the decoder since it was
    /// created (or, for [`frames`], from the start of the slice).
    pub offset: u64,
    /// The frame.
    pub frame: V3Frame,
}

/// Judges the candidate at the start of `c` (a `9B` at stream offset `at`) from the bytes
/// there; decided by at most [`MAX_LEN`] bytes.
#[inline(always)]
fn judge(c: &[u8], at: u64, stats: &Stats) -> Verdict<V3Frame> {
    let Some(first) = c.first_chunk::<FRAME_LEN>() else {
        return Verdict::Undecided;
    };
    let frame = V3Frame::read(first);
    if !frame.is_plausible() {
        return Verdict::Implausible;
    }
    if stats.continues_chain(at, frame.counter) {
        return Verdict::Frame(frame, false);
    }
    let mut counter = frame.counter;
    for k in 1..CHAIN_TO_LOCK {
        let rest = &c[(k * FRAME_LEN).min(c.len())..];
        match rest.first() {
            None => return Verdict::Undecided,
            Some(&b) if b != SYNC => return Verdict::Unconfirmed,
            Some(_) => {}
        }
        let Some(next) = rest.first_chunk::<FRAME_LEN>() else {
            return Verdict::Undecided;
        };
        let next = V3Frame::read(next);
        counter = (counter + 1) & COUNTER24_MAX;
        if !next.is_plausible() || next.counter != counter {
            return Verdict::Unconfirmed;
        }
    }
    Verdict::Frame(frame, true)
}

/// The fewest bytes that may decide a candidate whose first `held` bytes are there (the
/// points where [`judge`] reads a new byte): a lower bound, as the streaming layer needs.
#[inline(always)]
const fn candidate_len(held: usize) -> usize {
    match held {
        0..10 => 10,
        10 => 11,
        11..20 => 20,
        20 => 21,
        _ => MAX_LEN,
    }
}

/// Finds the next frame in `data` (its first byte at stream offset `base`) from `*pos`, as
/// [`chain::scan_next`] does with V3's [`judge`].
#[inline(always)]
fn scan_next(
    data: &[u8],
    pos: &mut usize,
    base: u64,
    stats: &mut Stats,
    at_end: bool,
) -> Option<(usize, V3Frame)> {
    chain::scan_next(
        data,
        pos,
        base,
        stats,
        at_end,
        judge,
        |stats, at, frame, synced| {
            stats.accept(at, &frame, synced);
            (FRAME_LEN, frame)
        },
    )
}

/// The V3 scanner, as the streaming layer ([`crate::scan`]) runs it: [`Decoder`] and
/// [`Frames`] are it under [`StreamDecoder`] and [`Scan`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Scanner;

impl_scanner!(
    Scanner,
    Stats,
    Decoded,
    MAX_LEN,
    |held: &[u8]| candidate_len(held.len()),
    scan_next
);

/// A streaming V3 decoder: feed it bytes in any chunking, get every frame once (the streaming
/// layer's [`StreamDecoder`] over the V3 scanner).
///
/// Its state is a 29-byte buffer for a candidate still being decided plus the [`Stats`] (which
/// hold where the chain of accepted frames ends): 104 bytes (`size_of::<Decoder>()`, checked by
/// a test), no allocation, no timing. A chained frame comes out on its tenth byte; the first
/// frame of a stream (or after a break) once two more have confirmed it.
///
/// ```
/// use hwfoc::v3::{Decoder, V3Frame};
///
/// let mut wire = vec![0x00, 0x9B, 0x13]; // noise and a lone sync byte
/// for counter in 5..9 {
///     wire.extend_from_slice(&V3Frame { counter, pwm_out_raw: 10, ..Default::default() }.encode());
/// }
/// let mut decoder = Decoder::new();
/// let mut got = Vec::new();
/// for &byte in &wire {
///     decoder.push(byte, |d| got.push((d.offset, d.frame.counter)));
/// }
/// decoder.flush(|d| got.push((d.offset, d.frame.counter)));
/// assert_eq!(got, [(3, 5), (13, 6), (23, 7), (33, 8)]);
/// let stats = decoder.stats();
/// assert_eq!((stats.bytes_skipped(), stats.unconfirmed(), stats.syncs()), (3, 1, 1));
/// ```
///
/// # Silences
///
/// [`line_silent`](StreamDecoder::line_silent)`(max_frames, ..)` decides the held bytes at
/// once (as the end of a stream) and bounds the next counter step counted as a loss by
/// `max_frames + 1`, as for the HW-FOC [`Decoder`](crate::foc::Decoder). A V3 ESC stalls in
/// the middle of frames for up to 128 ms at motor start: a silence shorter than that must not
/// be reported, or the frame it interrupts is dropped.
pub type Decoder = StreamDecoder<Scanner>;

/// Decodes every V3 frame in a complete buffer, in place: the bulk path.
///
/// The iterator borrows the slice and allocates nothing; it yields exactly what a [`Decoder`]
/// fed the same bytes and then flushed would, with the same statistics.
///
/// ```
/// use hwfoc::v3::{self, V3Frame};
///
/// let mut wire = Vec::new();
/// for counter in 0..6 {
///     wire.extend_from_slice(&V3Frame { counter, ..Default::default() }.encode());
/// }
/// wire[34] = 0x01; // frame 3's throttle becomes 256: implausible
/// let mut it = v3::frames(&wire);
/// let counters: Vec<u32> = it.by_ref().map(|d| d.frame.counter).collect();
/// // Frames 4 and 5 would start a new chain, but no third frame follows: the stream ends, and
/// // they are dropped (cut off, not counted as rejected).
/// assert_eq!(counters, [0, 1, 2]);
/// assert_eq!((it.stats().implausible(), it.stats().bytes_skipped()), (1, 30));
/// ```
pub fn frames(data: &[u8]) -> Frames<'_> {
    Scan::new(data)
}

/// Iterator returned by [`frames`].
pub type Frames<'a> = Scan<'a, Scanner>;

#[cfg(test)]
mod tests {
    use super::*;

    fn wire(counters: impl IntoIterator<Item = u32>) -> ([u8; 200], usize) {
        let mut out = [0u8; 200];
        let mut n = 0;
        for counter in counters {
            let f = V3Frame {
                counter,
                throttle_in_raw: 100,
                pwm_out_raw: 10,
                period_us: 1554,
            }
            .encode();
            out[n..n + FRAME_LEN].copy_from_slice(&f);
            n += FRAME_LEN;
        }
        (out, n)
    }

    #[test]
    fn state_size() {
        assert_eq!(size_of::<Decoder>(), 104);
    }

    #[test]
    fn candidate_len_is_a_lower_bound_below_max_len() {
        for held in 0..MAX_LEN {
            assert!(candidate_len(held) > held);
            assert!(candidate_len(held) <= MAX_LEN);
        }
    }

    #[test]
    fn a_chained_frame_comes_out_on_its_last_byte() {
        let (w, n) = wire(0..4);
        let mut d = Decoder::new();
        let mut got = 0;
        // The first frame waits for its two confirmations.
        d.feed(&w[..29], |_| got += 1);
        assert_eq!((got, d.buffered()), (0, 29));
        d.feed(&w[29..30], |_| got += 1);
        assert_eq!((got, d.buffered()), (3, 0));
        d.feed(&w[30..n - 1], |_| got += 1);
        assert_eq!((got, d.buffered()), (3, 9));
        d.feed(&w[n - 1..n], |_| got += 1);
        assert_eq!((got, d.buffered()), (4, 0));
    }

    #[test]
    fn counter_wraps_at_24_bits() {
        let (w, n) = wire([0xFF_FFFE, 0xFF_FFFF, 0, 1]);
        let mut it = frames(&w[..n]);
        assert_eq!(it.by_ref().count(), 4);
        assert_eq!((it.stats().lost_packets(), it.stats().restarts()), (0, 0));
    }

    #[test]
    fn a_counter_jump_needs_a_new_chain() {
        // 0 1 2 | 10 11 12: the jump is confirmed by its own chain of three: 7 lost.
        let (w, n) = wire([0, 1, 2, 10, 11, 12]);
        let mut it = frames(&w[..n]);
        assert_eq!(it.by_ref().count(), 6);
        let s = it.stats();
        assert_eq!((s.lost_packets(), s.syncs(), s.unconfirmed()), (7, 2, 0));
        // 0 1 2 | 10 11 at the end of the stream: no chain of three after the jump, both
        // dropped (cut off by the end, not counted as rejected).
        let (w, n) = wire([0, 1, 2, 10, 11]);
        let mut it = frames(&w[..n]);
        assert_eq!(it.by_ref().count(), 3);
        assert_eq!(
            (it.stats().unconfirmed(), it.stats().bytes_skipped()),
            (0, 20)
        );
        // 0 1 2 | 10 11 | 20 21 22: 10 and 11 are followed by a frame that does not chain on
        // (counter 20): both rejected; 20 starts a new chain.
        let (w, n) = wire([0, 1, 2, 10, 11, 20, 21, 22]);
        let mut it = frames(&w[..n]);
        assert_eq!(it.by_ref().count(), 6);
        let s = it.stats();
        assert_eq!(
            (s.unconfirmed(), s.bytes_skipped(), s.lost_packets()),
            (2, 20, 17)
        );
    }
}
