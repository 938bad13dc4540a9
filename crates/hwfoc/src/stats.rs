//! Link statistics for one telemetry stream.

use core::fmt;

/// Counters kept per stream by [`crate::Decoder`] and [`crate::Frames`].
///
/// Byte counters are `u64`; event counters are `u32` and saturate (at the ESC's 20 frames a
/// second a `u32` lasts more than six years), which keeps the whole decoder small enough for a
/// microcontroller.
///
/// Every byte fed ends up either in an accepted frame or in [`LinkStats::bytes_skipped`]: after
/// [`crate::Decoder::flush`], `bytes == 24 * frames + 77 * info_frames + bytes_skipped`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct LinkStats {
    bytes: u64,
    bytes_skipped: u64,
    frames: u32,
    info_frames: u32,
    checksum_failures: u32,
    lost_packets: u32,
    duplicate_packets: u32,
    last_packet: u16,
}

impl LinkStats {
    /// All counters zero.
    pub const fn new() -> Self {
        LinkStats {
            bytes: 0,
            bytes_skipped: 0,
            frames: 0,
            info_frames: 0,
            checksum_failures: 0,
            lost_packets: 0,
            duplicate_packets: 0,
            last_packet: 0,
        }
    }

    /// Bytes fed to the decoder.
    pub const fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Bytes that were not part of an accepted frame: noise, corrupted and cut frames, frames of
    /// other protocols.
    pub const fn bytes_skipped(&self) -> u64 {
        self.bytes_skipped
    }

    /// Data frames (command 0x02) decoded.
    pub const fn frames(&self) -> u32 {
        self.frames
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

    /// Packets missing between consecutive data frames, from packet-number gaps modulo 65536.
    ///
    /// A step of `d = (next - last) mod 65536` counts `d - 1` lost packets when `2 <= d <= 32768`;
    /// a larger step is a counter that went backwards (an ESC restart, or a repeated old frame)
    /// and counts as neither loss nor duplicate.
    pub const fn lost_packets(&self) -> u32 {
        self.lost_packets
    }

    /// Data frames whose packet number equals the previous frame's (seen on real ESCs; not a loss).
    pub const fn duplicate_packets(&self) -> u32 {
        self.duplicate_packets
    }

    /// Packet number of the last data frame, if any.
    pub const fn last_packet(&self) -> Option<u16> {
        if self.frames == 0 {
            None
        } else {
            Some(self.last_packet)
        }
    }

    /// Fraction of expected data frames that arrived: `frames / (frames + lost)`, or `None`
    /// before the first frame.
    pub fn delivery_ratio(&self) -> Option<f64> {
        if self.frames == 0 {
            return None;
        }
        let frames = f64::from(self.frames);
        Some(frames / (frames + f64::from(self.lost_packets)))
    }

    #[inline]
    pub(crate) fn add_bytes(&mut self, n: usize) {
        self.bytes += n as u64;
    }

    #[inline]
    pub(crate) fn skip(&mut self, n: usize) {
        self.bytes_skipped += n as u64;
    }

    #[inline]
    pub(crate) fn checksum_failure(&mut self) {
        self.checksum_failures = self.checksum_failures.saturating_add(1);
    }

    #[inline]
    pub(crate) fn info_frame(&mut self) {
        self.info_frames = self.info_frames.saturating_add(1);
    }

    #[inline]
    pub(crate) fn data_frame(&mut self, packet: u16) {
        if self.frames != 0 {
            let step = packet.wrapping_sub(self.last_packet);
            if step == 0 {
                self.duplicate_packets = self.duplicate_packets.saturating_add(1);
            } else if step <= 0x8000 {
                self.lost_packets = self.lost_packets.saturating_add(u32::from(step - 1));
            }
        }
        self.frames = self.frames.saturating_add(1);
        self.last_packet = packet;
    }
}

impl fmt::Display for LinkStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} bytes, {} frames, {} info frames, {} checksum failures, {} bytes skipped, \
             {} lost packets, {} duplicate packets",
            self.bytes,
            self.frames,
            self.info_frames,
            self.checksum_failures,
            self.bytes_skipped,
            self.lost_packets,
            self.duplicate_packets
        )
    }
}
