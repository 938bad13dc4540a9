//! Statistics of one HW5 stream: bytes, frames by kind, rejected candidates.

use core::fmt;

use crate::counters::{ByteCounts, Bytes};

use super::layout::{Direction, Kind};

/// Counters kept per stream by [`Decoder`](super::Decoder) and [`Frames`](super::Frames).
/// Event counters are `u32` and saturate; byte counters hold 48 bits, as
/// [`foc::Stats`](crate::foc::Stats)'.
///
/// Every byte fed ends up either in an accepted frame (of any [`Kind`]) or in
/// [`Stats::bytes_skipped`]: after [`Decoder::flush`](super::Decoder::flush),
/// `bytes == Σ kind.wire_len() * frames(kind) + bytes_skipped` ([`Stats::frame_bytes`] is the sum).
///
/// Every candidate (`FE 01` or `01 FD`) that is not a frame is counted once, as a
/// [bad header](Stats::bad_headers), an [unknown type](Stats::unknown_types), a
/// [checksum failure](Stats::checksum_failures) or [out of range](Stats::out_of_range), except one cut off by the end of the stream, which is
/// only skipped.
///
/// There is no packet counter on the wire, so no loss is counted here: the layers above judge
/// loss from time ([`FRAME_PERIOD_RUNNING`](super::FRAME_PERIOD_RUNNING),
/// [`FRAME_PERIOD_IDLE`](super::FRAME_PERIOD_IDLE)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Stats {
    bytes: ByteCounts,
    frames: [u32; Kind::COUNT],
    checksum_failures: u32,
    bad_headers: u32,
    unknown_types: u32,
    out_of_range: u32,
}

impl Stats {
    /// All counters zero.
    pub const fn new() -> Self {
        Stats {
            bytes: ByteCounts::new(),
            frames: [0; Kind::COUNT],
            checksum_failures: 0,
            bad_headers: 0,
            unknown_types: 0,
            out_of_range: 0,
        }
    }

    /// Bytes fed to the decoder.
    pub const fn bytes(&self) -> u64 {
        self.bytes.get(Bytes::Fed)
    }

    /// Bytes that were not part of an accepted frame: noise, corrupted, cut and unknown frames,
    /// other protocols.
    pub const fn bytes_skipped(&self) -> u64 {
        self.bytes.get(Bytes::Skipped)
    }

    /// Telemetry frames decoded (the frames the decoder hands on).
    pub const fn telemetry_frames(&self) -> u32 {
        self.frames[Kind::Telemetry as usize]
    }

    /// Frames of `kind` taken (verified by their CRC).
    pub const fn frames(&self, kind: Kind) -> u32 {
        self.frames[kind as usize]
    }

    /// Frames of every kind, by kind (indexed by `kind as usize`, as [`Kind::ALL`]).
    pub const fn frames_by_kind(&self) -> &[u32; Kind::COUNT] {
        &self.frames
    }

    /// Verified frames that are not telemetry (answers to a configurator, requests), summed.
    pub fn other_frames(&self) -> u64 {
        Kind::ALL
            .iter()
            .filter(|&&k| k != Kind::Telemetry)
            .map(|&k| u64::from(self.frames(k)))
            .sum()
    }

    /// Verified frames sent to the ESC (requests), summed.
    pub fn requests(&self) -> u64 {
        Kind::ALL
            .iter()
            .filter(|k| k.direction() == Direction::ToEsc)
            .map(|&k| u64::from(self.frames(k)))
            .sum()
    }

    /// The bytes of every verified frame: `Σ kind.wire_len() * frames(kind)`.
    pub fn frame_bytes(&self) -> u64 {
        Kind::ALL
            .iter()
            .map(|&k| k.wire_len() as u64 * u64::from(self.frames(k)))
            .sum()
    }

    /// Whole candidates of a known kind whose CRC did not match (for a type with several
    /// lengths, none of them): corrupted frames, frames cut short and followed by other bytes.
    /// A frame cut off by the end of the stream is not counted.
    pub const fn checksum_failures(&self) -> u32 {
        self.checksum_failures
    }

    /// Candidates whose third byte is not that of their envelope (`00` after `FE 01`, `03` after
    /// `01 FD`), or telemetry frames whose payload length byte is not `17`: fake headers in
    /// noise, or a corrupted header (decided before the CRC).
    pub const fn bad_headers(&self) -> u32 {
        self.bad_headers
    }

    /// Candidates with a good envelope whose length cannot be known: no kind of their
    /// direction has their type (or, for telemetry, their code). Each costs one byte, and the
    /// bytes of an unknown frame are skipped.
    pub const fn unknown_types(&self) -> u32 {
        self.unknown_types
    }

    /// Telemetry frames whose CRC matched but that carry a value outside the range the
    /// protocol allows ([`THROTTLE_MAX_PCT`](super::THROTTLE_MAX_PCT),
    /// [`VOLTAGE_MAX_RAW`](super::VOLTAGE_MAX_RAW)): corrupted frames, rejected, never handed on.
    pub const fn out_of_range(&self) -> u32 {
        self.out_of_range
    }

    /// Candidates rejected: bad headers, unknown types, CRC failures and frames out of range.
    pub const fn rejected(&self) -> u32 {
        self.bad_headers
            .saturating_add(self.unknown_types)
            .saturating_add(self.checksum_failures)
            .saturating_add(self.out_of_range)
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
    pub(crate) fn frame(&mut self, kind: Kind) {
        let n = &mut self.frames[kind as usize];
        *n = n.saturating_add(1);
    }

    #[inline]
    pub(crate) fn crc_failure(&mut self) {
        self.checksum_failures = self.checksum_failures.saturating_add(1);
    }

    #[inline]
    pub(crate) fn out_of_range_frame(&mut self) {
        self.out_of_range = self.out_of_range.saturating_add(1);
    }

    #[inline]
    pub(crate) fn bad_header(&mut self) {
        self.bad_headers = self.bad_headers.saturating_add(1);
    }

    #[inline]
    pub(crate) fn unknown_type(&mut self) {
        self.unknown_types = self.unknown_types.saturating_add(1);
    }

    /// The line was silent: nothing to count (no packet counter to judge the next frame by).
    /// The decoder has already decided the bytes it held, as
    /// [`StreamDecoder::line_silent`](crate::scan::StreamDecoder::line_silent) does for every
    /// protocol.
    pub(crate) fn line_silent(&mut self, _max_frames: u32) {}
}

impl fmt::Display for Stats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} bytes, {} telemetry frames",
            self.bytes(),
            self.telemetry_frames()
        )?;
        for kind in Kind::ALL {
            if kind != Kind::Telemetry && self.frames(kind) != 0 {
                write!(f, ", {} {}", self.frames(kind), kind.name())?;
            }
        }
        write!(
            f,
            ", {} CRC failures, {} out of range, {} bad headers, {} unknown types, {} bytes skipped",
            self.checksum_failures,
            self.out_of_range,
            self.bad_headers,
            self.unknown_types,
            self.bytes_skipped(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_by_kind() {
        let mut s = Stats::new();
        s.add_bytes(32 + 10 + 105 + 3);
        s.frame(Kind::Telemetry);
        s.frame(Kind::PingRequest);
        s.frame(Kind::ParametersRead);
        s.skip(3);
        s.crc_failure();
        s.bad_header();
        s.unknown_type();
        s.unknown_type();
        assert_eq!(s.telemetry_frames(), 1);
        assert_eq!(s.other_frames(), 2);
        assert_eq!(s.requests(), 1);
        assert_eq!(s.frame_bytes(), 147);
        assert_eq!(s.bytes(), s.frame_bytes() + s.bytes_skipped());
        assert_eq!(s.rejected(), 4);
        assert_eq!(s.frames_by_kind(), &[1, 0, 0, 0, 1, 0, 0, 1]);
        let before = s;
        s.line_silent(7);
        assert_eq!(s, before);
    }

    #[test]
    fn size() {
        assert_eq!(size_of::<Stats>(), 60);
    }
}
