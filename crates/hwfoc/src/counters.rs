//! The counters both protocols' statistics keep ([`crate::foc::Stats`],
//! [`crate::datalink::Stats`]): byte counts of 48 bits, and the following of a packet counter.
//!
//! A [`PacketSequence`] sorts every step from one number to the next into one of five events:
//! the next number (nothing to count), the same number again (a
//! [duplicate](PacketSequence::duplicates)), a small gap forward ([lost](PacketSequence::lost):
//! the numbers in between), the number a gap of one skipped, right after it (two adjacent
//! frames [swapped](PacketSequence::reordered): the loss that gap counted is taken back), or a
//! jump that no lost frames explain: a step backwards, or forwards by more than
//! [`MAX_PACKET_GAP`] + 1. Such a jump is a [restart](PacketSequence::restarts): the ESC
//! rebooted (its counter starts again), another simulator took over the port, or two
//! sequences are interleaved. It counts as one restart and no loss, and the sequence continues
//! from the new number.
//!
//! A caller that knows when bytes arrived can tighten the rule for the number after a silence
//! with [`crate::foc::Decoder::line_silent`]: an ESC that rebooted in a second and a half cannot
//! have sent 535 frames in that time, so a step of 536 after it is a restart, not a loss of 535.

use core::fmt;
use core::hash::Hash;

/// The most data frames one gap in packet numbers is counted as losing: a step forward of more
/// than `MAX_PACKET_GAP + 1` is a [restart](crate::foc::Stats::restarts), not a loss.
///
/// Why 1000: a running ESC sends a data frame every 50 to 56 ms, so 1000 lost frames are 50 s
/// without a single frame getting through (six minutes of an idle ESC's frames, one every
/// ~364 ms): longer than any dropout a live link survives unnoticed (such a link was cut). And
/// the larger the gap allowed, the more restarts pass for losses: an ESC whose counter stood
/// within `MAX_PACKET_GAP` below the number it restarts from (a chance of about 1000 in 65536)
/// looks like a gap forward. On a timed source,
/// [`Decoder::line_silent`](crate::foc::Decoder::line_silent) settles both cases from the time
/// that passed.
pub const MAX_PACKET_GAP: u16 = 1000;

/// The two byte counters of a protocol's statistics ([`foc::Stats`](crate::foc::Stats),
/// [`datalink::Stats`](crate::datalink::Stats)), of 48 bits each: a `u32` and a `u16`. They take
/// 12 bytes at an alignment of 4, where two `u64` would take 16 at an alignment of 8: that is
/// what keeps [`foc::Stats`](crate::foc::Stats), with every event counter a `u32`, at 44 bytes,
/// and the HW-FOC [`Decoder`] at 124.
///
/// 2^48 bytes are 4.6 million years of a 19200-baud wire, or 78 hours of reading a file at
/// 1 GB/s; past that a count wraps to 0. Saturating instead would cost about 110 bytes of
/// Cortex-M code (the counters are added to all through the scanner) for a count that no stream
/// reaches.
///
/// [`Decoder`]: crate::foc::Decoder
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub(crate) struct ByteCounts {
    low: [u32; 2],
    high: [u16; 2],
}

/// Which of the [`ByteCounts`].
#[derive(Clone, Copy)]
pub(crate) enum Bytes {
    /// Bytes fed.
    Fed = 0,
    /// Bytes skipped.
    Skipped = 1,
}

impl ByteCounts {
    pub(crate) const fn new() -> Self {
        ByteCounts {
            low: [0; 2],
            high: [0; 2],
        }
    }

    pub(crate) const fn get(&self, which: Bytes) -> u64 {
        self.low[which as usize] as u64 + ((self.high[which as usize] as u64) << 32)
    }

    #[inline]
    pub(crate) fn add(&mut self, which: Bytes, n: usize) {
        let sum = self.get(which).wrapping_add(n as u64);
        self.low[which as usize] = sum as u32;
        self.high[which as usize] = (sum >> 32) as u16;
    }

    /// Adds the counts of the bytes that came after these (see [`PacketSequence::then`]).
    pub(crate) fn then(&mut self, later: &ByteCounts) {
        for which in [Bytes::Fed, Bytes::Skipped] {
            let sum = self.get(which).wrapping_add(later.get(which));
            self.low[which as usize] = sum as u32;
            self.high[which as usize] = (sum >> 32) as u16;
        }
    }
}

/// The numbers of one counter (an ESC's packet numbers, a DataLink hub's frame counter, the
/// 24-bit counter of a Hobbywing V3 or V4 ESC), followed step by step: each number after the
/// first is sorted into exactly one of the next number, a [duplicate](Sequence::duplicates), a
/// gap of [lost](Sequence::lost) numbers, or a [restart](Sequence::restarts), by the rule of
/// the [module](self) documentation ([`MAX_PACKET_GAP`], and the tighter limit after a silence
/// of the line), with steps taken modulo the counter's width `W`: [`PacketSequence`] (16 bits)
/// and [`PacketSequence24`] (24 bits) are its two instances.
///
/// Counters are `u32` and saturate; the last number and the gap limit are kept in the width's
/// own type ([`Width::Number`]), so a [`PacketSequence`] takes 24 bytes and a
/// [`PacketSequence24`] 28.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Sequence<W: Width> {
    pub(crate) count: u32,
    pub(crate) lost: u32,
    pub(crate) duplicates: u32,
    pub(crate) restarts: u32,
    pub(crate) reordered: u32,
    pub(crate) last: W::Number,
    /// The largest step to the next number that counts as a loss, as set by
    /// [`Sequence::line_silent`]; 0 (no silence since the last number) means
    /// `MAX_PACKET_GAP + 1`, and [`Width::MAX`] the same after a gap of one number (which the
    /// next number may fill: a swap).
    pub(crate) gap_limit: W::Number,
}

/// The width of the counter a [`Sequence`] follows (sealed: [`Bits16`], [`Bits24`]).
pub trait Width: sealed::Sealed + Copy + fmt::Debug + PartialEq + Eq + Hash + Default {
    /// The type a number is given in and kept in.
    type Number: Copy + fmt::Debug + PartialEq + Eq + Hash + Default + Into<u32>;
    /// Number 0.
    #[doc(hidden)]
    const ZERO: Self::Number;
    /// The largest number; numbers wrap to 0 after it.
    const MAX: u32;
    /// `n` (at most [`Width::MAX`]) as a number.
    #[doc(hidden)]
    fn number(n: u32) -> Self::Number;
}

/// A 16-bit counter: an HW-FOC ESC's packet numbers, a DataLink hub's frame counter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Bits16;

/// A 24-bit counter: the packet counters of Hobbywing V3 and V4 ([`crate::v3`], [`crate::v4`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Bits24;

mod sealed {
    /// Keeps [`Width`](super::Width) to this crate.
    pub trait Sealed {}
    impl Sealed for super::Bits16 {}
    impl Sealed for super::Bits24 {}
}

impl Width for Bits16 {
    type Number = u16;
    const ZERO: u16 = 0;
    const MAX: u32 = 0xFFFF;

    #[inline(always)]
    fn number(n: u32) -> u16 {
        n as u16
    }
}

impl Width for Bits24 {
    type Number = u32;
    const ZERO: u32 = 0;
    const MAX: u32 = COUNTER24_MAX;

    #[inline(always)]
    fn number(n: u32) -> u32 {
        n
    }
}

/// The numbers of one 16-bit counter (an ESC's packet numbers, a DataLink hub's frame counter):
/// a [`Sequence`] of [`Bits16`].
///
/// [`foc::Stats`](crate::foc::Stats) keeps one for the data frames' packet numbers;
/// [`datalink::Stats`](crate::datalink::Stats) one for the hub's frame counter and one per ESC
/// channel. Counters are `u32` and saturate; 24 bytes.
pub type PacketSequence = Sequence<Bits16>;

/// The largest value of a 24-bit counter (the packet counters of Hobbywing V3 and V4,
/// [`crate::v3`], [`crate::v4`]); it wraps to 0 after this.
pub const COUNTER24_MAX: u32 = 0xFF_FFFF;

/// [`PacketSequence`] for a 24-bit counter (the packet counters of Hobbywing V3 and V4): a
/// [`Sequence`] of [`Bits24`], the same four events by the same rule ([`MAX_PACKET_GAP`], the
/// tighter limit after a silence), with steps taken modulo 2^24 and a step backwards being one
/// of more than 2^23.
///
/// A separate instance rather than a wider [`PacketSequence`], so that the HW-FOC and DataLink
/// statistics keep their sizes. Counters are `u32` and saturate; 28 bytes.
///
/// ```
/// use hwfoc::counters::PacketSequence24;
///
/// let mut s = PacketSequence24::new();
/// for n in [0xFF_FFFE, 0xFF_FFFF, 0, 3, 3, 100_000] {
///     s.next(n);
/// }
/// assert_eq!((s.count(), s.lost(), s.duplicates(), s.restarts()), (6, 2, 1, 1));
/// assert_eq!(s.last(), Some(100_000));
/// ```
pub type PacketSequence24 = Sequence<Bits24>;

impl<W: Width> Sequence<W> {
    /// The largest step forward (modulo the width): a larger one is a step backwards.
    const MAX_FORWARD_STEP: u32 = W::MAX / 2 + 1;

    /// No number seen yet.
    pub const fn new() -> Self {
        Sequence {
            count: 0,
            lost: 0,
            duplicates: 0,
            restarts: 0,
            reordered: 0,
            last: W::ZERO,
            gap_limit: W::ZERO,
        }
    }

    /// The gap limit's mark of a gap of one number just counted (a swap may follow).
    fn swap_mark() -> W::Number {
        W::number(W::MAX)
    }

    /// Numbers seen (frames or records counted).
    pub const fn count(&self) -> u32 {
        self.count
    }

    /// Numbers missing between consecutive numbers of one sequence: a step of
    /// `d = (next - last)` modulo the width (65536, 2^24) counts `d - 1` when
    /// `2 <= d <= MAX_PACKET_GAP + 1` (after a silence, the limit it set); a larger step is a
    /// restart and loses nothing.
    pub const fn lost(&self) -> u32 {
        self.lost
    }

    /// Numbers equal to the one before (not a loss).
    pub const fn duplicates(&self) -> u32 {
        self.duplicates
    }

    /// Numbers that came right after the next one: the number a gap of one skipped, right after
    /// that gap (`5, 7, 6, 8`: two adjacent frames swapped on the way). Not a loss (the gap's
    /// loss is taken back) and not a restart.
    pub const fn reordered(&self) -> u32 {
        self.reordered
    }

    /// Numbers that start a new sequence: a step backwards (`d` above half the modulus: 32768,
    /// 2^23) or forwards beyond the gap limit. A restart counts no loss and no duplicate.
    pub const fn restarts(&self) -> u32 {
        self.restarts
    }

    /// The last number seen, if any.
    pub const fn last(&self) -> Option<W::Number> {
        if self.count == 0 {
            None
        } else {
            Some(self.last)
        }
    }

    /// Fraction of expected numbers that arrived: `count / (count + lost)`, or `None` before
    /// the first. Restarts expect nothing.
    pub fn delivery_ratio(&self) -> Option<f64> {
        if self.count == 0 {
            return None;
        }
        let count = f64::from(self.count);
        Some(count / (count + f64::from(self.lost)))
    }

    /// The line was silent for a time in which at most `max_frames` numbers could have been
    /// sent: the next step counts as a loss only up to `max_frames + 1` (at most half the
    /// modulus: 32768, 2^23). Silences before one number add up.
    pub fn line_silent(&mut self, max_frames: u32) {
        let limit = match self.gap_limit.into() {
            0 => 1,
            // A silence after a gap of one: the number after it is no swap.
            limit if limit == W::MAX => 1,
            limit => limit,
        };
        let limit = limit.saturating_add(max_frames);
        self.gap_limit = W::number(limit.min(Self::MAX_FORWARD_STEP));
    }

    /// This sequence followed by `later`, which followed the numbers that came right after this
    /// one's, from its first number `first` on: afterwards this is the sequence one follower of
    /// every number would have kept. The step from this sequence's last number to `first` is
    /// sorted by the usual rule (`later` began with no silence of the line before `first`); the
    /// steps after it are `later`'s. Nothing changes when `later` has no number.
    pub fn then(&mut self, first: W::Number, later: &Sequence<W>) {
        if later.count == 0 {
            return;
        }
        self.next(first);
        self.count = self.count.saturating_add(later.count - 1);
        self.lost = self.lost.saturating_add(later.lost);
        self.duplicates = self.duplicates.saturating_add(later.duplicates);
        self.restarts = self.restarts.saturating_add(later.restarts);
        self.reordered = self.reordered.saturating_add(later.reordered);
        self.last = later.last;
        self.gap_limit = later.gap_limit;
    }

    /// Takes the next number (its low bits of the width) and classifies its step from the last
    /// one.
    #[inline]
    pub fn next(&mut self, number: W::Number) {
        let number = number.into() & W::MAX;
        let last = self.last.into();
        let gap_limit = self.gap_limit.into();
        // The usual step: the next number, nothing lost, no silence before it.
        if number == (last.wrapping_add(1) & W::MAX) && gap_limit == 0 && self.count != 0 {
            self.count = self.count.saturating_add(1);
            self.last = W::number(number);
            return;
        }
        rare();
        let mut mark = W::ZERO;
        if self.count != 0 {
            let swap = gap_limit == W::MAX;
            let limit = if gap_limit == 0 || swap {
                u32::from(MAX_PACKET_GAP) + 1
            } else {
                gap_limit
            };
            match number.wrapping_sub(last) & W::MAX {
                0 => self.duplicates = self.duplicates.saturating_add(1),
                // The number the gap of one before skipped: a swap, the number stays.
                step if swap && step == W::MAX => {
                    self.lost = self.lost.saturating_sub(1);
                    self.reordered = self.reordered.saturating_add(1);
                    self.gap_limit = W::ZERO;
                    self.count = self.count.saturating_add(1);
                    return;
                }
                2 if limit >= 2 => {
                    self.lost = self.lost.saturating_add(1);
                    mark = Self::swap_mark();
                }
                // The next number (a step of 1) loses nothing; the limit is at least 1.
                step if step <= limit => self.lost = self.lost.saturating_add(step - 1),
                _ => self.restarts = self.restarts.saturating_add(1),
            }
        }
        self.gap_limit = mark;
        self.count = self.count.saturating_add(1);
        self.last = W::number(number);
    }
}

/// Marks the path that calls it as rare (what `core::hint::cold_path` does from Rust 1.95,
/// above the codec's minimum Rust version): the usual step of [`Sequence::next`] then
/// stays the straight path through a decoder's loop however the code around it is laid out,
/// which keeps the clean stream's decoding speed from hanging on the scanner's other paths.
#[cold]
#[inline(always)]
fn rare() {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_counters_hold_48_bits() {
        let mut c = ByteCounts::default();
        for n in [1, 0xFFFF, 1, 0xFFFF_0000, 0x1234_5678_9ABC] {
            let before = c.get(Bytes::Fed);
            c.add(Bytes::Fed, n);
            assert_eq!(c.get(Bytes::Fed), before + n as u64);
            assert_eq!(c.get(Bytes::Skipped), 0);
        }
        assert_eq!(c.get(Bytes::Fed), 0x1235_5678_9ABD);
        c.add(Bytes::Skipped, 0xFFFF_FFFF);
        c.add(Bytes::Skipped, 2);
        assert_eq!(c.get(Bytes::Skipped), 0x1_0000_0001);
        c.add(Bytes::Fed, (1 << 48) - 0x1235_5678_9ABD + 5);
        assert_eq!(c.get(Bytes::Fed), 5);
        assert_eq!(c.get(Bytes::Skipped), 0x1_0000_0001);
    }

    /// A sequence split anywhere and joined with [`PacketSequence::then`] is the sequence of
    /// the whole: every kind of step at the seam (next, gap, duplicate, restart) and inside
    /// either part, and a part with no number.
    #[test]
    fn a_sequence_split_and_joined_is_the_whole() {
        let numbers = [7u16, 8, 10, 10, 11, 3, 4, 4, 900, 65535, 0, 1, 5];
        let mut whole = PacketSequence::new();
        for &n in &numbers {
            whole.next(n);
        }
        assert_eq!(
            (whole.lost(), whole.duplicates(), whole.restarts()),
            (899, 2, 2)
        );
        for seam in 0..=numbers.len() {
            let (mut first, mut later) = (PacketSequence::new(), PacketSequence::new());
            numbers[..seam].iter().for_each(|&n| first.next(n));
            numbers[seam..].iter().for_each(|&n| later.next(n));
            first.then(numbers.get(seam).copied().unwrap_or(0), &later);
            assert_eq!(first, whole, "seam before number {seam}");
        }
    }

    #[test]
    fn a_sequence_fits_in_24_bytes() {
        assert_eq!(size_of::<PacketSequence>(), 24);
    }

    /// Two adjacent frames swapped (`5, 7, 6, 8`) are one reordering: no loss, no restart
    /// (they counted a restart and two lost packets). A gap of one that stays one is a loss;
    /// a silence between the gap and the number is no swap.
    #[test]
    fn two_adjacent_frames_swapped_are_a_reordering() {
        let mut s = PacketSequence::new();
        for n in [4, 5, 7, 6, 8, 9, 11, 12, 13, 65535] {
            s.next(n);
        }
        assert_eq!(
            (
                s.count(),
                s.lost(),
                s.restarts(),
                s.duplicates(),
                s.reordered()
            ),
            (10, 1, 1, 0, 1)
        );
        assert_eq!(s.delivery_ratio(), Some(10.0 / 11.0));
        for n in [1, 0, 2] {
            s.next(n); // across the wrap
        }
        assert_eq!((s.lost(), s.restarts(), s.reordered()), (1, 1, 2));
        assert_eq!(s.last(), Some(2));
        let mut t = PacketSequence24::new();
        for n in [0xFF_FFFE, 0, 0xFF_FFFF, 1] {
            t.next(n);
        }
        assert_eq!((t.lost(), t.restarts(), t.reordered()), (0, 0, 1));
        let mut u = PacketSequence::new();
        u.next(5);
        u.next(7);
        u.line_silent(3);
        u.next(6);
        assert_eq!((u.lost(), u.restarts(), u.reordered()), (1, 1, 0));
    }

    #[test]
    fn sequence24_follows_the_16_bit_rule_in_24_bits() {
        let mut s = PacketSequence24::new();
        s.next(0xFF_FFFF);
        s.next(0x1_0000); // 0x10001 steps: beyond the gap limit, a restart
        s.next(0x1_0000 + 1001); // step 1001: 1000 lost
        s.next(0x1_0000 + 2003); // step 1002: a restart
        s.next(5); // backwards: a restart
        assert_eq!((s.lost(), s.restarts(), s.duplicates()), (1000, 3, 0));
        s.line_silent(2);
        s.next(9); // step 4 > 2 + 1 after the silence: a restart
        s.line_silent(2);
        s.next(12); // step 3: 2 lost
        assert_eq!((s.count(), s.lost(), s.restarts()), (7, 1002, 4));
        assert_eq!(size_of::<PacketSequence24>(), 28);
    }
}
