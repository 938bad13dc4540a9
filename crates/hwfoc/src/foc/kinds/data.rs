//! The 0x02 real-time data frame: layout, parsing, encoding and the conversions of its fields.
//!
//! ```text
//!  0    1    2    3    4..5   6..7      8..9       10..11  12..13  14..15    16..17     18   19   20..21   22     23
//!  9B   16   01   02   PN     thr_in    thr_out    erpm    volt    i_in      i_phase    MOS  CAP  status   SUM_L  SUM_H
//! ```
//!
//! Payload fields are big-endian; the checksum is the 16-bit wrapping sum of bytes 0..=21, sent low
//! byte first ([`Checksum::Sum16Le`]; see `docs/PROTOCOL-NOTES.md`: real frames do not match
//! CRC-16/MODBUS, the sum does).

use super::{FrameKind, sealed};
use crate::foc::FrameError;
use crate::status::Status;
use crate::units::{ERPM_PER_RAW, Linear, Settings, Temperature};
use crate::wire::{Checksum, VERSION, sum16};

/// Command byte of a real-time data frame.
pub const CMD_DATA: u8 = 0x02;
/// Length byte of a data frame: the number of bytes before the two checksum bytes.
pub const DATA_LENGTH_BYTE: u8 = 0x16;
/// Total length of a data frame on the wire, checksum included.
pub const DATA_FRAME_LEN: usize = 24;
/// Length of a data frame's payload, the fields from the packet number to the status word
/// (bytes 4..22). A DataLink V2 record carries the same bytes after its channel byte.
pub const DATA_PAYLOAD_LEN: usize = 18;

const _: () = assert!(DATA_FRAME_LEN == 4 + DATA_PAYLOAD_LEN + 2);

/// The largest input or output throttle a data frame can carry: 1024, 100 % (the protocol's
/// range is 0..=1024). A frame with a larger one is no frame, whatever its checksum: the
/// 16-bit sum is weak, and corruption that keeps it is counted as a rejected candidate
/// ([`Stats::checksum_failures`](crate::foc::Stats::checksum_failures)), never recorded.
pub const THROTTLE_MAX_RAW: u16 = 1024;

/// One real-time telemetry frame (command 0x02), every field as the raw integer sent on the wire.
///
/// Physical values come from the conversion methods, which take the user's [`Settings`] where a
/// conversion depends on them (current scale, pole pairs, gear ratio).
///
/// ```
/// use hwfoc::Settings;
/// use hwfoc::foc::DataFrame;
///
/// let bytes = [0x9B, 0x16, 0x01, 0x02, 0x05, 0xC2, 0, 0, 0, 0, 0, 0, 0x00, 0xF7,
///              0xFF, 0xFF, 0xFF, 0xFF, 0xCE, 0xD1, 0x00, 0x00, 0x0D, 0x08];
/// let frame = DataFrame::parse(&bytes)?;
/// assert_eq!(frame.packet, 1474);
/// assert_eq!(frame.voltage_v(), 24.7);
/// assert_eq!(frame.current_a(&Settings::default()), -0.015625);
/// assert_eq!(frame.mos_temp().celsius(), Some(28.0));
/// assert_eq!(frame.encode(), bytes);
/// # Ok::<(), hwfoc::foc::FrameError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct DataFrame {
    /// Packet number, +1 per data frame, wrapping 65535 -> 0.
    pub packet: u16,
    /// Input throttle, 0..=1024 (percent = raw * 100 / 1024).
    pub throttle_in_raw: u16,
    /// Output throttle, 0..=1024 (percent = raw * 100 / 1024).
    pub throttle_out_raw: u16,
    /// Electrical RPM divided by 10.
    pub erpm_raw: u16,
    /// Input voltage in units of 0.1 V.
    pub voltage_raw: u16,
    /// Input current, two's complement, in units of 1 / current scale A.
    pub current_raw: i16,
    /// Phase current, two's complement, in units of 1 / current scale A.
    pub phase_current_raw: i16,
    /// MOSFET temperature as an ADC code (see [`Temperature::from_adc`]).
    pub mos_adc: u8,
    /// Capacitor temperature as an ADC code (see [`Temperature::from_adc`]).
    pub cap_adc: u8,
    /// Status word: sixteen fault bits.
    pub status: Status,
}

impl FrameKind for DataFrame {
    const LENGTH_BYTE: u8 = DATA_LENGTH_BYTE;
    const VERSION: u8 = VERSION;
    const COMMAND: u8 = CMD_DATA;
    const LEN: usize = DATA_FRAME_LEN;
    const CHECKSUM: Checksum = Checksum::Sum16Le;

    /// One branch decides "valid data frame": the header and the checksum are compared at once,
    /// which stays predictable in line noise (always false) and in a run of frames (always true),
    /// where comparing the header first would branch on every fake `9B 16` header.
    ///
    /// The sum of the header bytes is taken as that of [`FrameKind::HEADER`]: a frame with
    /// another header is rejected whatever its sum, so only the 18 payload bytes are summed.
    #[inline(always)]
    fn accept(candidate: &[u8]) -> Option<Self> {
        let d = candidate.first_chunk::<DATA_FRAME_LEN>()?;
        let header = u32::from_le_bytes([d[0], d[1], d[2], d[3]]);
        let sum = u32::from(HEADER_SUM.wrapping_add(sum16(&d[4..22])));
        let found = u32::from(u16::from_le_bytes([d[22], d[23]]));
        if (sum ^ found) | (header ^ Self::HEADER_WORD) != 0 {
            return None;
        }
        // The throttles' range (bytes 6..10, big-endian) only once the checksum matched: both
        // high bytes under 4 (0..=1023) at once, else each one exactly.
        let throttle = |at: usize| u16::from_be_bytes([d[at], d[at + 1]]);
        let plausible = (d[6] | d[8]) < (THROTTLE_MAX_RAW >> 8) as u8
            || throttle(6).max(throttle(8)) <= THROTTLE_MAX_RAW;
        plausible.then(|| Self::from_verified(d))
    }
}

/// The sum of a data frame's header bytes.
const HEADER_SUM: u16 = sum16(&<DataFrame as FrameKind>::HEADER);

impl sealed::Sealed for DataFrame {
    #[inline]
    fn read(frame: &[u8]) -> Result<Self, FrameError> {
        match frame.first_chunk::<DATA_FRAME_LEN>() {
            Some(f) => Self::from_verified(f).plausible(),
            None => Err(FrameError::Truncated {
                needed: DATA_FRAME_LEN,
                got: frame.len(),
            }),
        }
    }

    fn write(&self, payload: &mut [u8]) {
        // `payload` is bytes 4..22 of the frame.
        if let Ok(payload) = <&mut [u8; DATA_PAYLOAD_LEN]>::try_from(payload) {
            self.write_payload(payload);
        }
    }

    #[inline(always)]
    fn count(&self, stats: &mut crate::foc::Stats) {
        stats.data_frame(self.packet);
    }
}

impl DataFrame {
    /// Decodes a data frame from the first [`DATA_FRAME_LEN`] bytes of `bytes`, checking the
    /// header and the checksum. Bytes after the frame are ignored.
    pub fn parse(bytes: &[u8]) -> Result<DataFrame, FrameError> {
        <Self as FrameKind>::parse(bytes)
    }

    /// The frame, if its values are in the protocol's ranges ([`THROTTLE_MAX_RAW`]).
    fn plausible(self) -> Result<DataFrame, FrameError> {
        for (field, raw) in [
            ("input throttle", self.throttle_in_raw),
            ("output throttle", self.throttle_out_raw),
        ] {
            if raw > THROTTLE_MAX_RAW {
                return Err(FrameError::OutOfRange {
                    field,
                    raw,
                    max: THROTTLE_MAX_RAW,
                });
            }
        }
        Ok(self)
    }

    /// Reads the fields of a frame whose header and checksum were already verified.
    #[inline]
    fn from_verified(f: &[u8; DATA_FRAME_LEN]) -> DataFrame {
        let payload = f[4..4 + DATA_PAYLOAD_LEN].try_into();
        // Always `Ok`: 18 bytes of a 24-byte array (the `Err` arm is compiled away).
        Self::read_payload(payload.unwrap_or(&[0; DATA_PAYLOAD_LEN]))
    }

    /// Reads the fields from a payload (the packet number to the status word, big-endian):
    /// bytes 4..22 of a data frame, or a DataLink record after its channel byte.
    #[inline]
    pub(crate) fn read_payload(p: &[u8; DATA_PAYLOAD_LEN]) -> DataFrame {
        let be = |i: usize| u16::from_be_bytes([p[i], p[i + 1]]);
        DataFrame {
            packet: be(0),
            throttle_in_raw: be(2),
            throttle_out_raw: be(4),
            erpm_raw: be(6),
            voltage_raw: be(8),
            current_raw: be(10) as i16,
            phase_current_raw: be(12) as i16,
            mos_adc: p[14],
            cap_adc: p[15],
            status: Status(be(16)),
        }
    }

    /// Writes the fields as a payload, the inverse of [`DataFrame::read_payload`].
    pub(crate) fn write_payload(&self, payload: &mut [u8; DATA_PAYLOAD_LEN]) {
        let words = [
            self.packet,
            self.throttle_in_raw,
            self.throttle_out_raw,
            self.erpm_raw,
            self.voltage_raw,
            self.current_raw as u16,
            self.phase_current_raw as u16,
        ];
        for (i, w) in words.iter().enumerate() {
            payload[2 * i..2 * i + 2].copy_from_slice(&w.to_be_bytes());
        }
        payload[14] = self.mos_adc;
        payload[15] = self.cap_adc;
        payload[16..18].copy_from_slice(&self.status.0.to_be_bytes());
    }

    /// Encodes the frame as the 24 bytes an ESC sends, header and checksum included.
    pub fn encode(&self) -> [u8; DATA_FRAME_LEN] {
        let mut f = [0u8; DATA_FRAME_LEN];
        self.encode_into(&mut f);
        f
    }

    /// Input throttle in percent (raw * 100 / 1024).
    pub fn throttle_in_pct(&self) -> f32 {
        Linear::THROTTLE_PCT.to_f32(f32::from(self.throttle_in_raw))
    }

    /// Output throttle in percent (raw * 100 / 1024).
    pub fn throttle_out_pct(&self) -> f32 {
        Linear::THROTTLE_PCT.to_f32(f32::from(self.throttle_out_raw))
    }

    /// Electrical RPM (raw * 10).
    pub fn erpm(&self) -> u32 {
        u32::from(self.erpm_raw) * u32::from(ERPM_PER_RAW)
    }

    /// Motor (or, with a gear ratio, output shaft) RPM: raw * 10 / (gear ratio * pole pairs).
    pub fn rpm(&self, settings: &Settings) -> f32 {
        settings.rpm_linear().to_f32(f32::from(self.erpm_raw))
    }

    /// Input voltage in volts (raw / 10).
    pub fn voltage_v(&self) -> f32 {
        Linear::VOLTS.to_f32(f32::from(self.voltage_raw))
    }

    /// Input current in amperes (raw / current scale); negative while braking regeneratively.
    pub fn current_a(&self, settings: &Settings) -> f32 {
        settings.amps(self.current_raw)
    }

    /// Phase current in amperes (raw / current scale).
    pub fn phase_current_a(&self, settings: &Settings) -> f32 {
        settings.amps(self.phase_current_raw)
    }

    /// MOSFET temperature from the ADC table.
    pub fn mos_temp(&self) -> Temperature {
        Temperature::from_adc(self.mos_adc)
    }

    /// Capacitor temperature from the ADC table.
    pub fn cap_temp(&self) -> Temperature {
        Temperature::from_adc(self.cap_adc)
    }
}
