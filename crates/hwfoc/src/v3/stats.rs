//! Statistics of one V3 stream, and the state the scanner keeps between frames (where the chain
//! of accepted frames ends).

use core::fmt;

use crate::chain::{self, ChainStats, Counts};
use crate::counters::{COUNTER24_MAX, PacketSequence24};
use crate::scan::SkipBytes;

use super::frame::{FRAME_LEN, V3Frame};

/// Counters kept per stream by [`Decoder`](super::Decoder) and [`Frames`](super::Frames), and
/// where the last accepted frame ended (the scanner's lock). Event counters are `u32` and
/// saturate; byte counters hold 48 bits, as [`foc::Stats`](crate::foc::Stats)'.
///
/// Every byte fed ends up either in an accepted frame or in [`Stats::bytes_skipped`]: after
/// [`Decoder::flush`](super::Decoder::flush), `bytes == 10 * frames + bytes_skipped`.
///
/// Every `9B` the scanner stops at (one that is not inside an accepted frame) is either the
/// start of an accepted frame, or a rejected candidate ([`Stats::rejected`]: an
/// [implausible](Stats::implausible) one or an [unconfirmed](Stats::unconfirmed) one), or,
/// at the very end of the stream, cut off (skipped, not counted).
///
/// The counter of accepted frames is followed as [`foc::Stats`](crate::foc::Stats) follows an
/// ESC's packet numbers, in 24 bits ([`PacketSequence24`]): the step to the first frame of each
/// new chain tells [lost packets](Stats::lost_packets), a [duplicate](Stats::duplicate_packets) or
/// a [restart](Stats::restarts).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Stats {
    counts: Counts,
    /// Stream offset just after the last accepted frame: where a chained frame starts.
    chain_end: Option<u64>,
}

impl Stats {
    /// All counters zero, not locked.
    pub const fn new() -> Self {
        Stats {
            counts: Counts::new(),
            chain_end: None,
        }
    }

    /// Bytes fed to the decoder.
    pub const fn bytes(&self) -> u64 {
        self.counts.bytes()
    }

    /// Bytes that were not part of an accepted frame: noise, rejected and cut frames, other
    /// formats.
    pub const fn bytes_skipped(&self) -> u64 {
        self.counts.bytes_skipped()
    }

    /// Frames accepted.
    pub const fn frames(&self) -> u32 {
        self.counts.counter.count()
    }

    /// Rejected candidates: [`Stats::implausible`] + [`Stats::unconfirmed`].
    pub const fn rejected(&self) -> u32 {
        self.counts.rejected()
    }

    /// Candidates whose own fields are impossible (throttle or PWM above 255): noise, corrupted
    /// frames, other formats.
    pub const fn implausible(&self) -> u32 {
        self.counts.implausible
    }

    /// Plausible candidates that neither continue the chain of accepted frames (right where
    /// the last one ended, with the next counter) nor start a chain of three: noise, a frame
    /// whose counter does not follow, frames around a corrupted one.
    pub const fn unconfirmed(&self) -> u32 {
        self.counts.unconfirmed
    }

    /// Frames accepted by a chain of three (the decoder locked, or locked again after a break):
    /// 1 for a clean stream.
    pub const fn syncs(&self) -> u32 {
        self.counts.syncs
    }

    /// Counter values missing between accepted frames (as
    /// [`foc::Stats::lost_packets`](crate::foc::Stats::lost_packets), in 24 bits).
    pub const fn lost_packets(&self) -> u32 {
        self.counts.counter.lost()
    }

    /// Accepted frames whose counter equals the previous one's.
    pub const fn duplicate_packets(&self) -> u32 {
        self.counts.counter.duplicates()
    }

    /// Accepted frames whose counter starts a new sequence (the ESC restarted).
    pub const fn restarts(&self) -> u32 {
        self.counts.counter.restarts()
    }

    /// The counter of the last accepted frame, if any.
    pub const fn last_counter(&self) -> Option<u32> {
        self.counts.counter.last()
    }

    /// The counters of the accepted frames, followed step by step.
    pub const fn counter(&self) -> &PacketSequence24 {
        &self.counts.counter
    }

    /// Stream offset just after the last accepted frame, if any: a frame starting there with
    /// the next counter is accepted on its own.
    pub const fn chain_end(&self) -> Option<u64> {
        self.chain_end
    }

    /// Whether a frame at stream offset `at` with `counter` continues the chain: it starts
    /// where the chain ends, its counter the last one's + 1 or up to
    /// [`MAX_CHAINED_GAP`](super::MAX_CHAINED_GAP) after that.
    #[inline(always)]
    pub(crate) fn continues_chain(&self, at: u64, counter: u32) -> bool {
        match (self.chain_end, self.counts.counter.last()) {
            (Some(end), Some(last)) => {
                end == at && chain::continues((last + 1) & COUNTER24_MAX, counter)
            }
            _ => false,
        }
    }

    #[inline]
    pub(crate) fn add_bytes(&mut self, n: usize) {
        self.counts.add_bytes(n);
    }

    /// Counts a frame accepted at stream offset `at`; `synced`: by a chain of three.
    #[inline]
    pub(crate) fn accept(&mut self, at: u64, frame: &V3Frame, synced: bool) {
        self.counts.sync(synced);
        self.counts.counter.next(frame.counter);
        self.chain_end = Some(at + FRAME_LEN as u64);
    }

    pub(crate) fn line_silent(&mut self, max_frames: u32) {
        self.counts.line_silent(max_frames);
    }
}

impl SkipBytes for Stats {
    #[inline]
    fn skip(&mut self, n: usize) {
        self.counts.skip(n);
    }
}

impl ChainStats for Stats {
    #[inline(always)]
    fn counts(&mut self) -> &mut Counts {
        &mut self.counts
    }
}

impl fmt::Display for Stats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} bytes, {} frames, {}",
            self.bytes(),
            self.frames(),
            self.counts
        )
    }
}
