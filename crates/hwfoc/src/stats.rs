//! Link statistics for one telemetry stream, and the following of a packet counter they share
//! with the DataLink statistics ([`crate::datalink::DatalinkStats`]).
//!
//! Besides counting bytes and frames, [`LinkStats`] follows the packet numbers of the data frames
//! (a [`PacketSequence`]) and sorts every step from one to the next into one of four events: the next number (nothing to
//! count), the same number again (a [duplicate](LinkStats::duplicate_packets)), a small gap
//! forward ([lost packets](LinkStats::lost_packets): the numbers in between), or a jump that no
//! lost frames explain: a step backwards, or forwards by more than [`MAX_PACKET_GAP`] + 1. Such a
//! jump is a [restart](LinkStats::restarts): the ESC rebooted (its counter starts again), another
//! simulator took over the port, or two sequences are interleaved. It counts as one restart and
//! no loss, and the sequence continues from the new number.
//!
//! A caller that knows when bytes arrived can tighten the rule for the frame after a silence with
//! [`crate::Decoder::line_silent`]: an ESC that rebooted in a second and a half cannot have sent
//! 535 frames in that time, so a step of 536 after it is a restart, not a loss of 535.

use core::fmt;

/// The most data frames one gap in packet numbers is counted as losing: a step forward of more
/// than `MAX_PACKET_GAP + 1` is a [restart](LinkStats::restarts), not a loss.
///
/// Why 1000: a running ESC sends a data frame every 50 to 56 ms, so 1000 lost frames are 50 s
/// without a single frame getting through (six minutes of an idle ESC's frames, one every
/// ~364 ms): longer than any dropout a live link survives unnoticed (such a link was cut). And
/// the larger the gap allowed, the more restarts pass for losses: an ESC whose counter stood
/// within `MAX_PACKET_GAP` below the number it restarts from (a chance of about 1000 in 65536)
/// looks like a gap forward. On a timed source,
/// [`Decoder::line_silent`](crate::Decoder::line_silent) settles both cases from the time that
/// passed.
pub const MAX_PACKET_GAP: u16 = 1000;

/// The largest step forward of a packet number (modulo 65536): a larger one is a step backwards.
const MAX_FORWARD_STEP: u16 = 0x8000;

/// The two byte counters of [`LinkStats`], of 48 bits each: a `u32` and a `u16`. They take 12
/// bytes at an alignment of 4, where two `u64` would take 16 at an alignment of 8: that is what
/// keeps [`LinkStats`], with every event counter a `u32`, at 40 bytes, and the [`Decoder`] at 120.
///
/// 2^48 bytes are 4.6 million years of a 19200-baud wire, or 78 hours of reading a file at
/// 1 GB/s; past that a count wraps to 0. Saturating instead would cost about 110 bytes of
/// Cortex-M code (the counters are added to all through the scanner) for a count that no stream
/// reaches.
///
/// [`Decoder`]: crate::Decoder
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
}

/// The numbers of one counter (an ESC's packet numbers, a DataLink hub's frame counter),
/// followed step by step: each number after the first is sorted into exactly one of the next
/// number, a [duplicate](PacketSequence::duplicates), a gap of [lost](PacketSequence::lost)
/// numbers, or a [restart](PacketSequence::restarts), by the rule of the [module](self)
/// documentation ([`MAX_PACKET_GAP`], and the tighter limit after a silence of the line).
///
/// [`LinkStats`] keeps one for the data frames' packet numbers;
/// [`DatalinkStats`](crate::DatalinkStats) one for the hub's frame counter and one per ESC
/// channel. Counters are `u32` and saturate; 20 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct PacketSequence {
    count: u32,
    lost: u32,
    duplicates: u32,
    restarts: u32,
    last: u16,
    /// The largest step to the next number that counts as a loss, as set by
    /// [`PacketSequence::line_silent`]; 0 (no silence since the last number) means
    /// `MAX_PACKET_GAP + 1`.
    gap_limit: u16,
}

impl PacketSequence {
    /// No number seen yet.
    pub const fn new() -> Self {
        PacketSequence {
            count: 0,
            lost: 0,
            duplicates: 0,
            restarts: 0,
            last: 0,
            gap_limit: 0,
        }
    }

    /// Numbers seen (frames or records counted).
    pub const fn count(&self) -> u32 {
        self.count
    }

    /// Numbers missing between consecutive numbers of one sequence: a step of
    /// `d = (next - last) mod 65536` counts `d - 1` when `2 <= d <= MAX_PACKET_GAP + 1`
    /// (after a silence, the limit it set); a larger step is a restart and loses nothing.
    pub const fn lost(&self) -> u32 {
        self.lost
    }

    /// Numbers equal to the one before (not a loss).
    pub const fn duplicates(&self) -> u32 {
        self.duplicates
    }

    /// Numbers that start a new sequence: a step backwards (`d > 32768` modulo 65536) or
    /// forwards beyond the gap limit. A restart counts no loss and no duplicate.
    pub const fn restarts(&self) -> u32 {
        self.restarts
    }

    /// The last number seen, if any.
    pub const fn last(&self) -> Option<u16> {
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
    /// sent: the next step counts as a loss only up to `max_frames + 1` (at most 32768).
    /// Silences before one number add up.
    pub(crate) fn line_silent(&mut self, max_frames: u32) {
        let limit = if self.gap_limit == 0 {
            1
        } else {
            u32::from(self.gap_limit)
        };
        let limit = limit.saturating_add(max_frames);
        self.gap_limit = limit.min(u32::from(MAX_FORWARD_STEP)) as u16;
    }

    /// Takes the next number and classifies its step from the last one.
    #[inline]
    pub(crate) fn next(&mut self, number: u16) {
        if self.count != 0 {
            let limit = if self.gap_limit == 0 {
                MAX_PACKET_GAP + 1
            } else {
                self.gap_limit
            };
            match number.wrapping_sub(self.last) {
                0 => self.duplicates = self.duplicates.saturating_add(1),
                // The next number (a step of 1) loses nothing; the limit is at least 1.
                step if step <= limit => {
                    self.lost = self.lost.saturating_add(u32::from(step - 1));
                }
                _ => self.restarts = self.restarts.saturating_add(1),
            }
        }
        self.gap_limit = 0;
        self.count = self.count.saturating_add(1);
        self.last = number;
    }
}

/// Counters kept per stream by [`crate::Decoder`] and [`crate::Frames`].
///
/// Event counters are `u32` and saturate (at the ESC's 20 frames a second a `u32` lasts more than
/// six years); byte counters hold 48 bits (4.6 million years of the wire; they wrap past 2^48).
/// That keeps the whole decoder small enough for a microcontroller: 40 bytes here.
///
/// Every byte fed ends up either in an accepted frame or in [`LinkStats::bytes_skipped`]: after
/// [`crate::Decoder::flush`], `bytes == 24 * frames + 77 * info_frames + bytes_skipped`.
///
/// Every data frame but the first is one step of the packet numbers (a [`PacketSequence`]),
/// counted as exactly one of: the next number, a [duplicate](LinkStats::duplicate_packets), a
/// gap of [lost packets](LinkStats::lost_packets), or a [restart](LinkStats::restarts); so
/// `duplicates + restarts <= frames - 1` (while no counter saturates), and the loss counted in
/// one step is at most [`MAX_PACKET_GAP`] (or what [`crate::Decoder::line_silent`] allowed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct LinkStats {
    bytes: ByteCounts,
    info_frames: u32,
    checksum_failures: u32,
    packets: PacketSequence,
}

impl LinkStats {
    /// All counters zero.
    pub const fn new() -> Self {
        LinkStats {
            bytes: ByteCounts::new(),
            info_frames: 0,
            checksum_failures: 0,
            packets: PacketSequence::new(),
        }
    }

    /// Bytes fed to the decoder.
    pub const fn bytes(&self) -> u64 {
        self.bytes.get(Bytes::Fed)
    }

    /// Bytes that were not part of an accepted frame: noise, corrupted and cut frames, frames of
    /// other protocols.
    pub const fn bytes_skipped(&self) -> u64 {
        self.bytes.get(Bytes::Skipped)
    }

    /// Data frames (command 0x02) decoded.
    pub const fn frames(&self) -> u32 {
        self.packets.count()
    }

    /// Device-information frames decoded. They are never counted as errors.
    pub const fn info_frames(&self) -> u32 {
        self.info_frames
    }

    /// Candidate frames (0x9B followed by a known length byte, long enough) that were rejected:
    /// checksum mismatch, or a correct checksum with an unknown version or command, or a
    /// device-information candidate whose text is not ASCII. Corrupted and cut frames, and fake
    /// headers in noise, all count here; a frame cut off by the end of the stream does not.
    pub const fn checksum_failures(&self) -> u32 {
        self.checksum_failures
    }

    /// Packets missing between consecutive data frames of one sequence, from packet-number gaps
    /// modulo 65536.
    ///
    /// A step of `d = (next - last) mod 65536` counts `d - 1` lost packets when
    /// `2 <= d <= MAX_PACKET_GAP + 1` ([`MAX_PACKET_GAP`]; after
    /// [`crate::Decoder::line_silent`], the limit it set); a larger step, forwards or backwards,
    /// is a [restart](LinkStats::restarts) and loses nothing.
    pub const fn lost_packets(&self) -> u32 {
        self.packets.lost()
    }

    /// Data frames whose packet number equals the previous frame's (seen on real ESCs; not a loss).
    pub const fn duplicate_packets(&self) -> u32 {
        self.packets.duplicates()
    }

    /// Data frames whose packet number does not continue the sequence, but starts a new one: a
    /// step backwards (`d > 32768` modulo 65536), or forwards by more than
    /// [`MAX_PACKET_GAP`] + 1 (after [`crate::Decoder::line_silent`], by more than it allowed).
    /// An ESC that rebooted, a simulator restarted on the same port, two interleaved sequences
    /// (each switch from one to the other is a restart).
    ///
    /// A restart counts no loss and no duplicate; the sequence continues from its number.
    pub const fn restarts(&self) -> u32 {
        self.packets.restarts()
    }

    /// Packet number of the last data frame, if any.
    pub const fn last_packet(&self) -> Option<u16> {
        self.packets.last()
    }

    /// Fraction of expected data frames that arrived: `frames / (frames + lost)`, or `None`
    /// before the first frame. Restarts expect nothing: the frames a restarted ESC did not send
    /// are not missing.
    pub fn delivery_ratio(&self) -> Option<f64> {
        self.packets.delivery_ratio()
    }

    /// The data frames' packet numbers, followed step by step.
    pub const fn packets(&self) -> &PacketSequence {
        &self.packets
    }

    #[inline]
    pub(crate) fn add_bytes(&mut self, n: usize) {
        self.bytes.add(Bytes::Fed, n);
    }

    #[inline]
    pub(crate) fn skip(&mut self, n: usize) {
        self.bytes.add(Bytes::Skipped, n);
    }

    #[inline]
    pub(crate) fn checksum_failure(&mut self) {
        self.checksum_failures = self.checksum_failures.saturating_add(1);
    }

    #[inline]
    pub(crate) fn info_frame(&mut self) {
        self.info_frames = self.info_frames.saturating_add(1);
    }

    /// The line was silent for a time in which at most `max_frames` data frames could have been
    /// sent: the next data frame's step counts as a loss only up to `max_frames + 1` (at most
    /// 32768). Silences before one data frame add up.
    pub(crate) fn line_silent(&mut self, max_frames: u32) {
        self.packets.line_silent(max_frames);
    }

    #[inline]
    pub(crate) fn data_frame(&mut self, packet: u16) {
        self.packets.next(packet);
    }
}

impl fmt::Display for LinkStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} bytes, {} frames, {} info frames, {} checksum failures, {} bytes skipped, \
             {} lost packets, {} duplicate packets, {} restarts",
            self.bytes(),
            self.frames(),
            self.info_frames,
            self.checksum_failures,
            self.bytes_skipped(),
            self.lost_packets(),
            self.duplicate_packets(),
            self.restarts()
        )
    }
}

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
        let mut s = LinkStats::new();
        s.add_bytes(1 << 40);
        s.skip(3 << 32);
        assert_eq!((s.bytes(), s.bytes_skipped()), (1 << 40, 3 << 32));
    }

    #[test]
    fn every_counter_fits_in_40_bytes() {
        assert_eq!(size_of::<LinkStats>(), 40);
        assert_eq!(size_of::<PacketSequence>(), 20);
    }

    /// Two interleaved sequences far apart for a million frames: the loss stays at 0 (it never
    /// runs up to 4294967295); every frame but the first is a restart.
    #[test]
    fn interleaved_sequences_never_saturate_the_loss() {
        let mut s = LinkStats::new();
        for i in 0..1_000_000u32 {
            let n = (i / 2) as u16;
            s.data_frame(if i % 2 == 0 {
                n.wrapping_add(100)
            } else {
                n.wrapping_add(20000)
            });
        }
        assert_eq!(s.lost_packets(), 0);
        assert_eq!(s.restarts(), 999_999);
        assert_eq!(s.duplicate_packets(), 0);
    }

    #[test]
    fn counters_saturate() {
        let mut s = LinkStats {
            packets: PacketSequence {
                count: u32::MAX,
                lost: u32::MAX - 1,
                duplicates: u32::MAX,
                restarts: u32::MAX,
                ..PacketSequence::new()
            },
            info_frames: u32::MAX,
            checksum_failures: u32::MAX,
            ..LinkStats::new()
        };
        for packet in [0, 0, 5, 3, 40000] {
            s.data_frame(packet);
        }
        s.info_frame();
        s.checksum_failure();
        assert_eq!(s.frames(), u32::MAX);
        assert_eq!(s.lost_packets(), u32::MAX);
        assert_eq!(s.duplicate_packets(), u32::MAX);
        assert_eq!(s.restarts(), u32::MAX);
        assert_eq!(
            (s.info_frames(), s.checksum_failures()),
            (u32::MAX, u32::MAX)
        );
    }

    #[test]
    fn silences_add_up_to_at_most_half_the_counter() {
        let mut s = LinkStats::new();
        s.line_silent(0);
        assert_eq!(s.packets.gap_limit, 1);
        s.line_silent(9);
        s.line_silent(20);
        assert_eq!(s.packets.gap_limit, 30);
        s.line_silent(u32::MAX);
        assert_eq!(s.packets.gap_limit, 0x8000);
        s.data_frame(1);
        assert_eq!(s.packets.gap_limit, 0);
        s.line_silent(u32::MAX - 1);
        assert_eq!(s.packets.gap_limit, 0x8000);
    }
}
