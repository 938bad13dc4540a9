//! What the V3 and V4 scanners share ([`crate::v3`], [`crate::v4`]): with no checksum, a
//! candidate (a `9B` not inside an accepted frame) is a frame that continues the chain of
//! accepted frames, or one that starts a new chain, or a rejected candidate (implausible, or
//! unconfirmed) that costs one byte. Each protocol judges its candidates and keeps its chain
//! (where it ends, what continues it); the counting of candidates and of the 24-bit counter,
//! and the search loop, are here.

use core::fmt;

use crate::counters::{ByteCounts, Bytes, COUNTER24_MAX, PacketSequence24};
use crate::scan::{self, Candidate, SkipBytes};
use crate::wire::SYNC;

/// The most frames that may be missing right before a plausible frame that starts exactly where
/// the chain of accepted frames ends for it to continue the chain on its own (its counter the
/// one the chain expects, or up to this many after it), with no consecutive neighbour to
/// confirm it.
///
/// Frames cut out whole (by a link or a sender that drops whole frames) leave the next frame
/// exactly where the chain ends, its counter advanced by the frames missing; a frame between
/// two such cuts has no consecutive neighbour to start a chain of three with, yet its place and
/// its counter are evidence. Why 3:
///
/// - Frames lost one by one come alone or in short runs: at a loss of 5 % of frames, a run of
///   four or more is one in 160 000 frames. A longer run is an outage, after which a chain of
///   three locks again, as before (losing only a frame with no two consecutive ones after it).
/// - It bounds what a corrupted counter gets past: a single bit flipped from 0 to 1 moves a
///   counter forward by 1 or 2 only in the low byte's two lowest bits (steps of 2 and 3); the
///   frame then comes with its own fields and a wrong counter, the next frame (whose counter
///   goes back) starts a new chain. A larger bound lets more such frames through.
/// - Random bytes: a `9B` exactly at the chain's end, plausible fields and a counter among 4
///   of 2^24 values come by chance less than once in 2^30 chain ends, and a chain end needs a
///   frame confirmed before it: random bytes alone still give no frame.
pub const MAX_CHAINED_GAP: u32 = 3;

/// Whether a frame carrying `counter`, starting where the chain ends, continues a chain that
/// expects `next`: the next counter, or at most [`MAX_CHAINED_GAP`] after it (in 24 bits).
#[inline(always)]
pub(crate) fn continues(next: u32, counter: u32) -> bool {
    (counter.wrapping_sub(next) & COUNTER24_MAX) <= MAX_CHAINED_GAP
}

/// What a candidate is, as a chained scanner judges it.
pub(crate) enum Verdict<F> {
    /// A frame: continuing the chain (`false`), or starting a new one (`true`).
    Frame(F, bool),
    /// Its own fields are impossible.
    Implausible,
    /// Plausible, but it neither continues the chain nor starts one.
    Unconfirmed,
    /// More bytes are needed.
    Undecided,
}

/// The counts a chained scanner's statistics keep: bytes, rejected candidates, chains started,
/// and the 24-bit counter of the accepted (data) frames. Event counters are `u32` and
/// saturate; byte counters hold 48 bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub(crate) struct Counts {
    bytes: ByteCounts,
    pub(crate) implausible: u32,
    pub(crate) unconfirmed: u32,
    pub(crate) syncs: u32,
    pub(crate) counter: PacketSequence24,
}

impl Counts {
    /// All zero.
    pub(crate) const fn new() -> Self {
        Counts {
            bytes: ByteCounts::new(),
            implausible: 0,
            unconfirmed: 0,
            syncs: 0,
            counter: PacketSequence24::new(),
        }
    }

    /// Bytes fed.
    pub(crate) const fn bytes(&self) -> u64 {
        self.bytes.get(Bytes::Fed)
    }

    /// Bytes in no accepted frame.
    pub(crate) const fn bytes_skipped(&self) -> u64 {
        self.bytes.get(Bytes::Skipped)
    }

    /// Implausible and unconfirmed candidates.
    pub(crate) const fn rejected(&self) -> u32 {
        self.implausible.saturating_add(self.unconfirmed)
    }

    #[inline]
    pub(crate) fn add_bytes(&mut self, n: usize) {
        self.bytes.add(Bytes::Fed, n);
    }

    #[inline]
    pub(crate) fn skip(&mut self, n: usize) {
        self.bytes.add(Bytes::Skipped, n);
    }

    /// Counts a frame accepted; `synced`: it started a new chain.
    #[inline]
    pub(crate) fn sync(&mut self, synced: bool) {
        if synced {
            self.syncs = self.syncs.saturating_add(1);
        }
    }

    pub(crate) fn line_silent(&mut self, max_frames: u32) {
        self.counter.line_silent(max_frames);
    }
}

impl fmt::Display for Counts {
    /// The counts after the frames': bytes skipped, candidates, syncs and the counter's steps.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} bytes skipped, {} implausible and {} unconfirmed candidates, {} syncs, {} lost \
             packets, {} duplicate packets, {} restarts",
            self.bytes_skipped(),
            self.implausible,
            self.unconfirmed,
            self.syncs,
            self.counter.lost(),
            self.counter.duplicates(),
            self.counter.restarts(),
        )
    }
}

/// A chained scanner's statistics: its [`Counts`].
pub(crate) trait ChainStats: SkipBytes {
    fn counts(&mut self) -> &mut Counts;
}

/// Finds the next frame in `data` (its first byte at stream offset `base`) from `*pos`,
/// stopping at every `9B`: `judge(candidate, at, stats)` judges the candidate at stream offset
/// `at`, `accept(stats, at, frame, synced)` counts a frame accepted there and returns its
/// length and what is handed on. Returns that and the frame's start in `data`, with `*pos`
/// just after it; `None` when no further frame can be decided: `*pos` is then `data.len()`,
/// or, unless `at_end`, the start of a candidate that needs more bytes (nothing of it counted
/// yet). A candidate cut off by the end of the stream is skipped, not counted as rejected.
#[inline(always)]
pub(crate) fn scan_next<St: ChainStats, F, T>(
    data: &[u8],
    pos: &mut usize,
    base: u64,
    stats: &mut St,
    at_end: bool,
    judge: impl Fn(&[u8], u64, &St) -> Verdict<F>,
    accept: impl Fn(&mut St, u64, F, bool) -> (usize, T),
) -> Option<(usize, T)> {
    let find = |hay: &[u8]| hay.iter().position(|&b| b == SYNC);
    scan::next_candidate(data, pos, stats, find, |data, pos, stats| {
        let i = *pos;
        let at = base + i as u64;
        match judge(&data[i..], at, stats) {
            Verdict::Frame(frame, synced) => {
                let (len, item) = accept(stats, at, frame, synced);
                *pos = i + len;
                Candidate::Frame((i, item))
            }
            Verdict::Implausible => {
                let c = stats.counts();
                c.implausible = c.implausible.saturating_add(1);
                Candidate::Rejected
            }
            Verdict::Unconfirmed => {
                let c = stats.counts();
                c.unconfirmed = c.unconfirmed.saturating_add(1);
                Candidate::Rejected
            }
            Verdict::Undecided if !at_end => Candidate::Undecided,
            Verdict::Undecided => Candidate::Rejected,
        }
    })
}
