//! Statistics of one V4 stream, and the state the scanner keeps between frames: where the chain
//! of accepted frames ends, and the info frames seen and adopted.

use core::fmt;

use crate::chain::{self, ChainStats, Counts};
use crate::counters::{COUNTER24_MAX, PacketSequence24};
use crate::scan::SkipBytes;

use super::data::DataFrame;
use super::info::InfoFrame;
use super::layout::{DATA_FRAME_LEN, DEFAULT_FULL_SCALE, INFO_FRAME_LEN};

/// Where the chain of accepted frames ends, and what continues it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct Chain {
    /// Stream offset just after the last accepted frame (and its trailer, once taken).
    end: u64,
    /// The counter a data frame at `end` must carry to continue the chain; `None` (just after
    /// an info frame that started a chain): any.
    next: Option<u32>,
    /// Whether a `B9` at `end` is the trailer of the data frame before it.
    trailer: bool,
}

/// Counters kept per stream by [`Decoder`](super::Decoder) and [`Frames`](super::Frames), and
/// the scanner's state: where the chain of accepted frames ends, and the info frames (the one
/// last seen, the one adopted). Event counters are `u32` and saturate; byte counters hold 48
/// bits, as [`foc::Stats`](crate::foc::Stats)'.
///
/// Every byte fed ends up in an accepted frame, in a data frame's trailer, or in
/// [`Stats::bytes_skipped`]: after [`Decoder::flush`](super::Decoder::flush),
/// `bytes == 19 * frames + 13 * info_frames + trailers + bytes_skipped`.
///
/// Every `9B` the scanner stops at (one not inside an accepted frame) is the start of an
/// accepted frame, a rejected candidate ([`Stats::rejected`]: [implausible](Stats::implausible)
/// or [unconfirmed](Stats::unconfirmed)), or, at the very end of the stream, cut off (skipped,
/// not counted).
///
/// The data frames' counter is followed in 24 bits ([`PacketSequence24`]): the step to the
/// first frame of each new chain tells [lost packets](Stats::lost_packets), a
/// [duplicate](Stats::duplicate_packets) or a [restart](Stats::restarts).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Stats {
    counts: Counts,
    info_frames: u32,
    adoptions: u32,
    disagreements: u32,
    trailers: u32,
    chain: Option<Chain>,
    last_info: Option<InfoFrame>,
    adopted: Option<InfoFrame>,
    /// Whether the last info frame differs from the adopted one (not yet confirmed): then no
    /// constants are in use ([`Stats::in_use`]). Set where an info frame is accepted, the only
    /// place the two above change, since every candidate reads it (as the C header's flag).
    unconfirmed_info: bool,
}

impl Default for Stats {
    fn default() -> Self {
        Self::new()
    }
}

impl Stats {
    /// All counters zero, not locked, no info frame.
    pub const fn new() -> Self {
        Stats {
            counts: Counts::new(),
            info_frames: 0,
            adoptions: 0,
            disagreements: 0,
            trailers: 0,
            chain: None,
            last_info: None,
            adopted: None,
            unconfirmed_info: false,
        }
    }

    /// Bytes fed to the decoder.
    pub const fn bytes(&self) -> u64 {
        self.counts.bytes()
    }

    /// Bytes that were not part of an accepted frame or trailer: noise, rejected and cut
    /// frames, other formats.
    pub const fn bytes_skipped(&self) -> u64 {
        self.counts.bytes_skipped()
    }

    /// Data frames accepted.
    pub const fn frames(&self) -> u32 {
        self.counts.counter.count()
    }

    /// Accepted data frames followed by their trailing `B9` (slow, idle mode).
    pub const fn trailers(&self) -> u32 {
        self.trailers
    }

    /// Info frames accepted (each copy).
    pub const fn info_frames(&self) -> u32 {
        self.info_frames
    }

    /// Times an info frame's constants were adopted: a copy identical to the info frame just
    /// before it, and different from the constants in use.
    pub const fn info_adoptions(&self) -> u32 {
        self.adoptions
    }

    /// Info frames that differ from the info frame before them (a corrupted copy, or new
    /// constants): they are not adopted until a second identical copy follows.
    pub const fn info_disagreements(&self) -> u32 {
        self.disagreements
    }

    /// The info frame whose constants are in use, if one has been adopted.
    pub const fn adopted(&self) -> Option<InfoFrame> {
        self.adopted
    }

    /// The info frame a data frame is decoded under now: the adopted one, unless the last info
    /// frame accepted differs from it (another ESC's constants not yet confirmed by a second
    /// copy, as after a swap, or a corrupted copy): then none, as before any info frame, so that
    /// no frame of a new ESC is scaled by the old one's constants.
    #[inline]
    pub const fn in_use(&self) -> Option<InfoFrame> {
        if self.unconfirmed_info {
            None
        } else {
            self.adopted
        }
    }

    /// The last info frame accepted, adopted or not.
    pub const fn last_info(&self) -> Option<InfoFrame> {
        self.last_info
    }

    /// Full scale of throttle and PWM in use (for the plausibility test too): that of the info
    /// frame data frames are decoded under now ([`Stats::in_use`]), else 1000. A candidate is
    /// judged by the scale it would be decoded under, so an accepted frame is never above 100 %
    /// (after a swap, a frame above 1000 before the new constants are confirmed is rejected).
    #[inline]
    pub const fn full_scale(&self) -> u16 {
        match self.in_use() {
            Some(info) => info.full_scale,
            None => DEFAULT_FULL_SCALE,
        }
    }

    /// Rejected candidates: [`Stats::implausible`] + [`Stats::unconfirmed`].
    pub const fn rejected(&self) -> u32 {
        self.counts.rejected()
    }

    /// Candidates whose own fields are impossible: a data frame with throttle or PWM above full
    /// scale or an ADC field of 4096 or more, an info frame with a zero divisor.
    pub const fn implausible(&self) -> u32 {
        self.counts.implausible
    }

    /// Plausible candidates that neither continue the chain of accepted frames nor start a new
    /// one (three chained data frames with counters +1, or a data frame and an info frame
    /// chained): noise, a frame whose counter does not follow, frames around a corrupted one.
    pub const fn unconfirmed(&self) -> u32 {
        self.counts.unconfirmed
    }

    /// Frames accepted by starting a new chain (the decoder locked, or locked again after a
    /// break): 1 for a clean stream.
    pub const fn syncs(&self) -> u32 {
        self.counts.syncs
    }

    /// Counter values missing between accepted data frames (in 24 bits).
    pub const fn lost_packets(&self) -> u32 {
        self.counts.counter.lost()
    }

    /// Accepted data frames whose counter equals the previous one's.
    pub const fn duplicate_packets(&self) -> u32 {
        self.counts.counter.duplicates()
    }

    /// Accepted data frames whose counter starts a new sequence (the ESC restarted).
    pub const fn restarts(&self) -> u32 {
        self.counts.counter.restarts()
    }

    /// The counter of the last accepted data frame, if any.
    pub const fn last_counter(&self) -> Option<u32> {
        self.counts.counter.last()
    }

    /// The data frames' counters, followed step by step.
    pub const fn counter(&self) -> &PacketSequence24 {
        &self.counts.counter
    }

    /// Stream offset just after the last accepted frame (and its trailer, once taken), if any:
    /// where a frame continuing the chain starts.
    pub const fn chain_end(&self) -> Option<u64> {
        match self.chain {
            Some(chain) => Some(chain.end),
            None => None,
        }
    }

    /// Whether a frame at stream offset `at` is chained to the last accepted frame.
    #[inline(always)]
    pub(crate) fn chained(&self, at: u64) -> bool {
        self.chain.is_some_and(|c| c.end == at)
    }

    /// Whether a data frame at `at` with `counter` continues the chain: it starts where the
    /// chain ends, its counter the one expected or up to
    /// [`MAX_CHAINED_GAP`](super::MAX_CHAINED_GAP) after it.
    #[inline(always)]
    pub(crate) fn continues_chain(&self, at: u64, counter: u32) -> bool {
        self.chain.is_some_and(|c| {
            c.end == at && c.next.is_none_or(|next| chain::continues(next, counter))
        })
    }

    /// Whether a `B9` at `at` is the trailer of the data frame just accepted.
    #[inline(always)]
    pub(crate) fn trailer_at(&self, at: u64) -> bool {
        self.chain.is_some_and(|c| c.trailer && c.end == at)
    }

    /// Takes the trailer at the chain's end.
    #[inline]
    pub(crate) fn take_trailer(&mut self) {
        if let Some(c) = &mut self.chain {
            c.end += 1;
            c.trailer = false;
            self.trailers = self.trailers.saturating_add(1);
        }
    }

    #[inline]
    pub(crate) fn add_bytes(&mut self, n: usize) {
        self.counts.add_bytes(n);
    }

    /// Counts a data frame accepted at stream offset `at`; `synced`: it started a new chain.
    #[inline]
    pub(crate) fn accept_data(&mut self, at: u64, frame: &DataFrame, synced: bool) {
        self.counts.sync(synced);
        self.counts.counter.next(frame.counter);
        self.chain = Some(Chain {
            end: at + DATA_FRAME_LEN as u64,
            next: Some((frame.counter + 1) & COUNTER24_MAX),
            trailer: true,
        });
    }

    /// Counts an info frame accepted at stream offset `at` (`synced`: it started a new chain)
    /// and adopts its constants if it is the second identical copy in a row.
    pub(crate) fn accept_info(&mut self, at: u64, info: &InfoFrame, synced: bool) {
        self.counts.sync(synced);
        self.info_frames = self.info_frames.saturating_add(1);
        let same_as_last = self.last_info == Some(*info);
        if same_as_last && self.adopted != Some(*info) {
            // The second identical copy in a row, and not the constants in use: adopted.
            self.adopted = Some(*info);
            self.adoptions = self.adoptions.saturating_add(1);
        } else if !same_as_last && self.last_info.is_some() {
            self.disagreements = self.disagreements.saturating_add(1);
        }
        self.last_info = Some(*info);
        self.unconfirmed_info = self.adopted.is_some_and(|adopted| adopted != *info);
        // A chained info frame keeps the counter the chain expects next; one that starts a
        // chain (confirmed by the data frame after it) lets that frame bring any counter.
        let next = match self.chain {
            Some(c) if !synced => c.next,
            _ => None,
        };
        self.chain = Some(Chain {
            end: at + INFO_FRAME_LEN as u64,
            next,
            trailer: false,
        });
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
            "{} bytes, {} data frames ({} with trailer), {} info frames ({} adoptions, {} \
             disagreeing), {}",
            self.bytes(),
            self.frames(),
            self.trailers,
            self.info_frames,
            self.adoptions,
            self.disagreements,
            self.counts,
        )
    }
}
