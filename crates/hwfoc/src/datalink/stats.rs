//! Statistics of one DataLink V2 stream: bytes, frames and rejected candidates, the hub's frame
//! counter, and each ESC channel's packet numbers.

use core::fmt;

use crate::counters::{ByteCounts, Bytes, PacketSequence};
use crate::foc::kinds::data::DATA_FRAME_LEN;

use super::frame::{FrameReport, HubFrame};
use super::layout::{BAUD_RATE, CHANNELS, FRAME_LEN, LengthByte};

/// Counters kept per stream by [`Decoder`](super::Decoder) and
/// [`Frames`](super::Frames). Event counters are `u32` and saturate; byte
/// counters hold 48 bits, as [`foc::Stats`](crate::foc::Stats)'.
///
/// Every byte fed ends up either in an accepted frame or in [`Stats::bytes_skipped`]:
/// after [`Decoder::flush`](super::Decoder::flush),
/// `bytes == 160 * frames + bytes_skipped`, and
/// `frames == frames_with_length_byte(Covered) + frames_with_length_byte(Total)`.
///
/// Every record of an accepted frame is counted once: as its channel's
/// ([`Stats::channel`]), an [empty slot](Stats::empty_slots), a
/// [bad channel](Stats::bad_channels) or a
/// [duplicate channel](Stats::duplicate_channels); so
/// `8 * frames == records + empty_slots + bad_channels + duplicate_channels`.
///
/// The hub's frame counter is followed exactly as [`foc::Stats`](crate::foc::Stats) follows an
/// ESC's packet numbers (a [`PacketSequence`]: [lost packets](Stats::lost_packets),
/// [duplicates](Stats::duplicate_packets), [restarts](Stats::restarts)), and so
/// is each channel's packet number, record after record. A channel's lost packets are the
/// numbers the stream did not carry, whether the ESC's own wire lost them or the hub forwarded
/// its records less often than the ESC sent frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Stats {
    bytes: ByteCounts,
    checksum_failures: u32,
    bad_headers: u32,
    length_bytes: [u32; 2],
    bad_channels: u32,
    duplicate_channels: u32,
    empty_slots: u32,
    counter: PacketSequence,
    channels: [PacketSequence; CHANNELS],
}

impl Stats {
    /// All counters zero.
    pub const fn new() -> Self {
        Stats {
            bytes: ByteCounts::new(),
            checksum_failures: 0,
            bad_headers: 0,
            length_bytes: [0; 2],
            bad_channels: 0,
            duplicate_channels: 0,
            empty_slots: 0,
            counter: PacketSequence::new(),
            channels: [PacketSequence::new(); CHANNELS],
        }
    }

    /// Bytes fed to the decoder.
    pub const fn bytes(&self) -> u64 {
        self.bytes.get(Bytes::Fed)
    }

    /// Bytes that were not part of an accepted frame: noise, corrupted and cut frames, other
    /// protocols.
    pub const fn bytes_skipped(&self) -> u64 {
        self.bytes.get(Bytes::Skipped)
    }

    /// Frames decoded.
    pub const fn frames(&self) -> u32 {
        self.counter.count()
    }

    /// Frames decoded that carried `length_byte`.
    pub const fn frames_with_length_byte(&self, length_byte: LengthByte) -> u32 {
        self.length_bytes[length_byte as usize]
    }

    /// Whole candidates (`9B`, a length byte 0x9E or 0xA0, `01 02`, 160 bytes) whose CRC did not
    /// match: corrupted frames, frames cut short and followed by other bytes. A frame cut off by
    /// the end of the stream is not counted.
    pub const fn checksum_failures(&self) -> u32 {
        self.checksum_failures
    }

    /// Candidates (`9B` and a length byte 0x9E or 0xA0) whose version and command bytes are not
    /// `01 02`: fake headers in noise, or a frame whose byte 2 or 3 was corrupted (decided on
    /// the fourth byte, before the CRC).
    pub const fn bad_headers(&self) -> u32 {
        self.bad_headers
    }

    /// Records of accepted frames whose channel byte is above 7 (dropped).
    pub const fn bad_channels(&self) -> u32 {
        self.bad_channels
    }

    /// Records of accepted frames for a channel already filled earlier in the same frame
    /// (dropped; the first is kept).
    pub const fn duplicate_channels(&self) -> u32 {
        self.duplicate_channels
    }

    /// Records of accepted frames whose 18 bytes after the channel byte are all zero: no ESC.
    pub const fn empty_slots(&self) -> u32 {
        self.empty_slots
    }

    /// ESC records delivered, over all channels.
    pub fn records(&self) -> u64 {
        self.channels.iter().map(|c| u64::from(c.count())).sum()
    }

    /// Frame-counter values missing between consecutive frames (as
    /// [`foc::Stats::lost_packets`](crate::foc::Stats::lost_packets)).
    pub const fn lost_packets(&self) -> u32 {
        self.counter.lost()
    }

    /// Frames whose counter equals the previous frame's.
    pub const fn duplicate_packets(&self) -> u32 {
        self.counter.duplicates()
    }

    /// Frames whose counter starts a new sequence (the hub restarted, or two streams are
    /// interleaved), as [`foc::Stats::restarts`](crate::foc::Stats::restarts).
    pub const fn restarts(&self) -> u32 {
        self.counter.restarts()
    }

    /// The frame counter of the last frame, if any.
    pub const fn last_counter(&self) -> Option<u16> {
        self.counter.last()
    }

    /// The hub's frame counter, followed step by step.
    pub const fn counter(&self) -> &PacketSequence {
        &self.counter
    }

    /// The packet numbers of the ESC on `channel` (0-based), followed record by record
    /// ([`PacketSequence::count`] is its records delivered); `None` for a channel above 7.
    pub fn channel(&self, channel: usize) -> Option<&PacketSequence> {
        self.channels.get(channel)
    }

    /// Every channel's packet numbers, by channel.
    pub const fn channels(&self) -> &[PacketSequence; CHANNELS] {
        &self.channels
    }

    #[inline]
    pub(crate) fn add_bytes(&mut self, n: usize) {
        self.bytes.add(Bytes::Fed, n);
    }

    #[inline]
    pub(crate) fn skip(&mut self, n: usize) {
        self.bytes.add(Bytes::Skipped, n);
    }

    /// These statistics followed by `later`'s (see [`crate::foc::Stats`]'s `then`), when
    /// `later` found no hub frame: its bytes, skipped bytes, CRC failures and bad headers are
    /// added. False, and nothing changes, when it found one (its counters' first numbers are
    /// not known here).
    pub(crate) fn then(&mut self, later: &Stats) -> bool {
        if later.counter.count() > 0 {
            return false;
        }
        self.bytes.then(&later.bytes);
        self.checksum_failures = self
            .checksum_failures
            .saturating_add(later.checksum_failures);
        self.bad_headers = self.bad_headers.saturating_add(later.bad_headers);
        true
    }

    #[inline]
    pub(crate) fn crc_failure(&mut self) {
        self.checksum_failures = self.checksum_failures.saturating_add(1);
    }

    #[inline]
    pub(crate) fn bad_header(&mut self) {
        self.bad_headers = self.bad_headers.saturating_add(1);
    }

    /// Counts an accepted frame.
    #[inline]
    pub(crate) fn frame(&mut self, frame: &HubFrame, report: &FrameReport) {
        self.counter.next(frame.counter);
        let n = &mut self.length_bytes[report.length_byte as usize];
        *n = n.saturating_add(1);
        let add = |n: &mut u32, k: u8| *n = n.saturating_add(u32::from(k));
        add(&mut self.empty_slots, report.empty_slots);
        add(&mut self.bad_channels, report.bad_channels);
        add(&mut self.duplicate_channels, report.duplicate_channels);
        for (sequence, slot) in self.channels.iter_mut().zip(&frame.slots) {
            if let Some(esc) = slot {
                sequence.next(esc.packet);
            }
        }
    }

    /// The line was silent for a time in which at most `max_frames` hub frames could have been
    /// sent: the next frame counter's step is a loss only up to `max_frames + 1`, and each
    /// channel's next packet number's only up to [`esc_frames_in`]`(max_frames) + 1`.
    pub(crate) fn line_silent(&mut self, max_frames: u32) {
        self.counter.line_silent(max_frames);
        let esc_frames = esc_frames_in(max_frames);
        for sequence in &mut self.channels {
            sequence.line_silent(esc_frames);
        }
    }
}

/// The most data frames an ESC can send on its own 19200-baud wire (24 bytes each) in the time
/// of `hub_frames` DataLink frames (160 bytes each at 115200 baud): `ceil(hub_frames * 10 / 9)`.
pub const fn esc_frames_in(hub_frames: u32) -> u32 {
    let hub_bits = hub_frames as u64 * FRAME_LEN as u64 * crate::foc::BAUD_RATE as u64;
    let esc_bits = DATA_FRAME_LEN as u64 * BAUD_RATE as u64;
    let n = hub_bits.div_ceil(esc_bits);
    if n > u32::MAX as u64 {
        u32::MAX
    } else {
        n as u32
    }
}

impl fmt::Display for Stats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} bytes, {} frames ({} with length byte 0x9E, {} with 0xA0), {} checksum \
             failures, {} bad headers, {} bytes skipped, {} lost packets, {} duplicate packets, \
             {} restarts, {} records, {} empty slots, {} bad channels, {} duplicate channels",
            self.bytes(),
            self.frames(),
            self.frames_with_length_byte(LengthByte::Covered),
            self.frames_with_length_byte(LengthByte::Total),
            self.checksum_failures,
            self.bad_headers,
            self.bytes_skipped(),
            self.lost_packets(),
            self.duplicate_packets(),
            self.restarts(),
            self.records(),
            self.empty_slots,
            self.bad_channels,
            self.duplicate_channels,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foc::DataFrame;

    #[test]
    fn esc_frames_in_a_silence() {
        assert_eq!(esc_frames_in(0), 0);
        assert_eq!(esc_frames_in(1), 2); // 13.9 ms holds 1.11 ESC frames: at most 2 begin
        assert_eq!(esc_frames_in(9), 10);
        assert_eq!(esc_frames_in(10), 12);
        assert_eq!(esc_frames_in(u32::MAX), u32::MAX);
    }

    #[test]
    fn size() {
        assert_eq!(size_of::<Stats>(), 256);
    }

    #[test]
    fn silence_reaches_the_counter_and_every_channel() {
        let mut s = Stats::new();
        let report = FrameReport {
            length_byte: LengthByte::Total,
            empty_slots: 7,
            bad_channels: 0,
            duplicate_channels: 0,
        };
        let frame = |counter: u16, packet: u16| {
            let mut f = HubFrame::new(counter);
            f.slots[3] = Some(DataFrame {
                packet,
                ..Default::default()
            });
            f
        };
        s.frame(&frame(100, 1000), &report);
        s.line_silent(9);
        // Counter step 10 (<= 9 + 1): 9 lost; packet step 11 (<= 10 + 1): 10 lost.
        s.frame(&frame(110, 1011), &report);
        assert_eq!((s.lost_packets(), s.restarts()), (9, 0));
        let ch = s.channel(3).unwrap();
        assert_eq!((ch.count(), ch.lost(), ch.restarts()), (2, 10, 0));
        s.line_silent(9);
        // Counter step 11 and packet step 12: both restarts.
        s.frame(&frame(121, 1023), &report);
        assert_eq!((s.lost_packets(), s.restarts()), (9, 1));
        assert_eq!(s.channel(3).unwrap().restarts(), 1);
        assert_eq!(s.frames_with_length_byte(LengthByte::Total), 3);
        assert_eq!(s.empty_slots(), 21);
        assert_eq!(s.records(), 3);
    }
}
