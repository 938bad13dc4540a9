//! HW-FOC link statistics for one telemetry stream: [`Stats`].
//!
//! Besides counting bytes and frames, [`Stats`] follows the packet numbers of the data frames
//! (a [`PacketSequence`], by the rule of [`crate::counters`]): every step from one number to the
//! next is the next number, a [duplicate](Stats::duplicate_packets), a gap of
//! [lost packets](Stats::lost_packets), or a [restart](Stats::restarts).

use core::fmt;

use crate::counters::{ByteCounts, Bytes, PacketSequence};

/// Counters kept per stream by [`crate::foc::Decoder`] and [`crate::foc::Frames`].
///
/// Event counters are `u32` and saturate (at the ESC's 20 frames a second a `u32` lasts more than
/// six years); byte counters hold 48 bits (4.6 million years of the wire; they wrap past 2^48).
/// That keeps the whole decoder small enough for a microcontroller: 44 bytes here.
///
/// Every byte fed ends up either in an accepted frame or in [`Stats::bytes_skipped`]: after
/// [`crate::foc::Decoder::flush`], `bytes == 24 * frames + 77 * info_frames + bytes_skipped`.
///
/// Every data frame but the first is one step of the packet numbers (a [`PacketSequence`]),
/// counted as exactly one of: the next number, a [duplicate](Stats::duplicate_packets), a
/// gap of [lost packets](Stats::lost_packets), or a [restart](Stats::restarts); so
/// `duplicates + restarts <= frames - 1` (while no counter saturates), and the loss counted in
/// one step is at most [`MAX_PACKET_GAP`](crate::counters::MAX_PACKET_GAP) (or what
/// [`crate::foc::Decoder::line_silent`] allowed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Stats {
    bytes: ByteCounts,
    info_frames: u32,
    checksum_failures: u32,
    packets: PacketSequence,
}

impl Stats {
    /// All counters zero.
    pub const fn new() -> Self {
        Stats {
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
    /// checksum mismatch, or a correct checksum with an unknown version or command or a value
    /// outside the protocol's range (a throttle over 100 %,
    /// [`THROTTLE_MAX_RAW`](crate::foc::THROTTLE_MAX_RAW): the 16-bit sum is weak), or a
    /// device-information candidate whose text is not ASCII. Corrupted and cut frames, and fake
    /// headers in noise, all count here; a frame cut off by the end of the stream does not.
    pub const fn checksum_failures(&self) -> u32 {
        self.checksum_failures
    }

    /// Packets missing between consecutive data frames of one sequence, from packet-number gaps
    /// modulo 65536.
    ///
    /// A step of `d = (next - last) mod 65536` counts `d - 1` lost packets when
    /// `2 <= d <= MAX_PACKET_GAP + 1` ([`MAX_PACKET_GAP`](crate::counters::MAX_PACKET_GAP); after
    /// [`crate::foc::Decoder::line_silent`], the limit it set); a larger step, forwards or
    /// backwards, is a [restart](Stats::restarts) and loses nothing.
    pub const fn lost_packets(&self) -> u32 {
        self.packets.lost()
    }

    /// Data frames whose packet number equals the previous frame's (seen on real ESCs; not a loss).
    pub const fn duplicate_packets(&self) -> u32 {
        self.packets.duplicates()
    }

    /// Data frames whose packet number does not continue the sequence, but starts a new one: a
    /// step backwards (`d > 32768` modulo 65536), or forwards by more than
    /// [`MAX_PACKET_GAP`](crate::counters::MAX_PACKET_GAP) + 1 (after
    /// [`crate::foc::Decoder::line_silent`], by more than it allowed). An ESC that rebooted, a
    /// simulator restarted on the same port, two interleaved sequences (each switch from one to the
    /// other is a restart).
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

    /// These statistics followed by `later`'s: those of a decoder started new where this
    /// one's stream stopped with nothing held ([`StreamDecoder::then`](crate::StreamDecoder::then)),
    /// whose first data frame's packet number is `first_packet`. False, and nothing changes,
    /// when `later` counted data frames but `first_packet` is `None`.
    pub(crate) fn then(&mut self, later: &Stats, first_packet: Option<u16>) -> bool {
        let first = match first_packet {
            Some(first) => first,
            None if later.packets.count() == 0 => 0,
            None => return false,
        };
        self.bytes.then(&later.bytes);
        self.info_frames = self.info_frames.saturating_add(later.info_frames);
        self.checksum_failures = self
            .checksum_failures
            .saturating_add(later.checksum_failures);
        self.packets.then(first, &later.packets);
        true
    }

    #[inline]
    pub(crate) fn checksum_failure(&mut self) {
        self.checksum_failures = self.checksum_failures.saturating_add(1);
    }

    /// Counts `n` checksum failures at once (the rejected candidates of a search window).
    #[inline]
    pub(crate) fn checksum_failures_n(&mut self, n: u32) {
        self.checksum_failures = self.checksum_failures.saturating_add(n);
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

impl fmt::Display for Stats {
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
    fn bytes_are_counted_past_32_bits() {
        let mut s = Stats::new();
        s.add_bytes(1 << 40);
        s.skip(3 << 32);
        assert_eq!((s.bytes(), s.bytes_skipped()), (1 << 40, 3 << 32));
    }

    #[test]
    fn every_counter_fits_in_44_bytes() {
        assert_eq!(size_of::<Stats>(), 44);
    }

    /// Two interleaved sequences far apart for a million frames: the loss stays at 0 (it never
    /// runs up to 4294967295); every frame but the first is a restart.
    #[test]
    fn interleaved_sequences_never_saturate_the_loss() {
        let mut s = Stats::new();
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
        let mut s = Stats {
            packets: PacketSequence {
                count: u32::MAX,
                lost: u32::MAX - 1,
                duplicates: u32::MAX,
                restarts: u32::MAX,
                ..PacketSequence::new()
            },
            info_frames: u32::MAX,
            checksum_failures: u32::MAX,
            ..Stats::new()
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
        let mut s = Stats::new();
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
