//! The 0x02 real-time data frame: layout, checksum, parsing and encoding.
//!
//! ```text
//!  0    1    2    3    4..5   6..7      8..9       10..11  12..13  14..15    16..17     18   19   20..21   22     23
//!  9B   16   01   02   PN     thr_in    thr_out    erpm    volt    i_in      i_phase    MOS  CAP  status   SUM_L  SUM_H
//! ```
//!
//! Payload fields are big-endian; the checksum is the 16-bit wrapping sum of bytes 0..=21, sent low
//! byte first (see `PROTOCOL-NOTES.md`: real frames do not match CRC-16/MODBUS, the sum does).

use core::fmt;

use crate::info::{INFO_FRAME_LEN, INFO_LENGTH_BYTE, InfoFrame};
use crate::status::Status;
use crate::units::{Settings, Temperature};
use crate::wire::{Checksum, SYNC, VERSION};
/// Command byte of a real-time data frame.
pub const CMD_DATA: u8 = 0x02;
/// Length byte of a data frame: the number of bytes before the two checksum bytes.
pub const DATA_LENGTH_BYTE: u8 = 0x16;
/// Total length of a data frame on the wire, checksum included.
pub const DATA_FRAME_LEN: usize = 24;
/// Length of the longest frame on the wire (the device-information frame).
pub const MAX_FRAME_LEN: usize = INFO_FRAME_LEN;

/// One real-time telemetry frame (command 0x02), every field as the raw integer sent on the wire.
///
/// Physical values come from the conversion methods, which take the user's [`Settings`] where a
/// conversion depends on them (current scale, pole pairs, gear ratio).
///
/// ```
/// use hwfoc::{DataFrame, Settings};
///
/// let bytes = [0x9B, 0x16, 0x01, 0x02, 0x05, 0xC2, 0, 0, 0, 0, 0, 0, 0x00, 0xF7,
///              0xFF, 0xFF, 0xFF, 0xFF, 0xCE, 0xD1, 0x00, 0x00, 0x0D, 0x08];
/// let frame = DataFrame::parse(&bytes)?;
/// assert_eq!(frame.packet, 1474);
/// assert_eq!(frame.voltage_v(), 24.7);
/// assert_eq!(frame.current_a(&Settings::default()), -0.015625);
/// assert_eq!(frame.mos_temp().celsius(), Some(28.0));
/// assert_eq!(frame.encode(), bytes);
/// # Ok::<(), hwfoc::FrameError>(())
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

impl DataFrame {
    /// Decodes a data frame from the first [`DATA_FRAME_LEN`] bytes of `bytes`, checking the
    /// header and the checksum. Bytes after the frame are ignored.
    pub fn parse(bytes: &[u8]) -> Result<DataFrame, FrameError> {
        let Some(frame) = bytes.first_chunk::<DATA_FRAME_LEN>() else {
            return Err(FrameError::Truncated {
                needed: DATA_FRAME_LEN,
                got: bytes.len(),
            });
        };
        if frame[0] != SYNC {
            return Err(FrameError::NoSync { found: frame[0] });
        }
        if frame[1] != DATA_LENGTH_BYTE {
            return Err(FrameError::UnknownLength { found: frame[1] });
        }
        check_data(frame)?;
        Ok(Self::from_verified(frame))
    }

    /// Reads the fields of a frame whose header and checksum were already verified.
    #[inline]
    pub(crate) fn from_verified(f: &[u8; DATA_FRAME_LEN]) -> DataFrame {
        let be = |i: usize| u16::from_be_bytes([f[i], f[i + 1]]);
        DataFrame {
            packet: be(4),
            throttle_in_raw: be(6),
            throttle_out_raw: be(8),
            erpm_raw: be(10),
            voltage_raw: be(12),
            current_raw: be(14) as i16,
            phase_current_raw: be(16) as i16,
            mos_adc: f[18],
            cap_adc: f[19],
            status: Status(be(20)),
        }
    }

    /// Encodes the frame as the 24 bytes an ESC sends, header and checksum included.
    pub fn encode(&self) -> [u8; DATA_FRAME_LEN] {
        let mut f = [0u8; DATA_FRAME_LEN];
        f[..4].copy_from_slice(&[SYNC, DATA_LENGTH_BYTE, VERSION, CMD_DATA]);
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
            f[4 + 2 * i..6 + 2 * i].copy_from_slice(&w.to_be_bytes());
        }
        f[18] = self.mos_adc;
        f[19] = self.cap_adc;
        f[20..22].copy_from_slice(&self.status.0.to_be_bytes());
        Checksum::Sum16Le.seal(&mut f);
        f
    }

    /// Input throttle in percent (raw * 100 / 1024).
    pub fn throttle_in_pct(&self) -> f32 {
        f32::from(self.throttle_in_raw) * 100.0 / 1024.0
    }

    /// Output throttle in percent (raw * 100 / 1024).
    pub fn throttle_out_pct(&self) -> f32 {
        f32::from(self.throttle_out_raw) * 100.0 / 1024.0
    }

    /// Electrical RPM (raw * 10).
    pub fn erpm(&self) -> u32 {
        u32::from(self.erpm_raw) * 10
    }

    /// Motor (or, with a gear ratio, output shaft) RPM: raw * 10 / (gear ratio * pole pairs).
    pub fn rpm(&self, settings: &Settings) -> f32 {
        settings.rpm_from_erpm(self.erpm())
    }

    /// Input voltage in volts (raw / 10).
    pub fn voltage_v(&self) -> f32 {
        f32::from(self.voltage_raw) / 10.0
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

/// Verifies the checksum, version and command of a candidate data frame (sync and length byte
/// already matched).
#[inline]
pub(crate) fn check_data(f: &[u8; DATA_FRAME_LEN]) -> Result<(), FrameError> {
    Checksum::Sum16Le.verify(f)?;
    if f[2] != VERSION || f[3] != CMD_DATA {
        return Err(FrameError::UnknownCommand {
            version: f[2],
            command: f[3],
        });
    }
    Ok(())
}

/// A frame of either kind found on the telemetry wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Frame {
    /// A real-time data frame (command 0x02, 24 bytes).
    Data(DataFrame),
    /// A device-information frame (command 0x01, 77 bytes).
    Info(InfoFrame),
}

impl Frame {
    /// The frame's length on the wire.
    pub fn wire_len(&self) -> usize {
        match self {
            Frame::Data(_) => DATA_FRAME_LEN,
            Frame::Info(_) => INFO_FRAME_LEN,
        }
    }

    /// Encodes the frame into the start of `out` and returns the number of bytes written, or
    /// `None` when `out` is shorter than [`Frame::wire_len`].
    pub fn encode_into(&self, out: &mut [u8]) -> Option<usize> {
        let n = self.wire_len();
        let dst = out.get_mut(..n)?;
        match self {
            Frame::Data(d) => dst.copy_from_slice(&d.encode()),
            Frame::Info(i) => dst.copy_from_slice(&i.encode()),
        }
        Some(n)
    }
}

/// The outcome of [`parse`]: a whole frame, or the start of one that needs more bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parsed {
    /// A verified frame and the number of bytes it occupies at the start of the input.
    Complete(Frame, usize),
    /// The input is a valid beginning of a frame; at least this many bytes in total are needed.
    Partial(usize),
}

/// Parses one frame (data or device-information) at the very start of `bytes`.
///
/// Like `httparse`, it never allocates and reports a valid but incomplete prefix as
/// [`Parsed::Partial`] instead of an error. It does not search for a frame: use
/// [`crate::Decoder`] or [`crate::frames`] for a stream.
///
/// ```
/// use hwfoc::{parse, Parsed, FrameError};
///
/// assert_eq!(parse(&[0x9B, 0x16, 0x01]), Ok(Parsed::Partial(24)));
/// assert_eq!(parse(&[0x9B, 0x42]), Err(FrameError::UnknownLength { found: 0x42 }));
/// ```
pub fn parse(bytes: &[u8]) -> Result<Parsed, FrameError> {
    let Some(&first) = bytes.first() else {
        return Ok(Parsed::Partial(1));
    };
    if first != SYNC {
        return Err(FrameError::NoSync { found: first });
    }
    let Some(&len_byte) = bytes.get(1) else {
        return Ok(Parsed::Partial(2));
    };
    match len_byte {
        DATA_LENGTH_BYTE => match bytes.first_chunk::<DATA_FRAME_LEN>() {
            Some(f) => {
                check_data(f)?;
                Ok(Parsed::Complete(
                    Frame::Data(DataFrame::from_verified(f)),
                    DATA_FRAME_LEN,
                ))
            }
            None => Ok(Parsed::Partial(DATA_FRAME_LEN)),
        },
        INFO_LENGTH_BYTE => match bytes.first_chunk::<INFO_FRAME_LEN>() {
            Some(f) => Ok(Parsed::Complete(
                Frame::Info(InfoFrame::parse_exact(f)?),
                INFO_FRAME_LEN,
            )),
            None => Ok(Parsed::Partial(INFO_FRAME_LEN)),
        },
        found => Err(FrameError::UnknownLength { found }),
    }
}

/// Why bytes are not a valid frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FrameError {
    /// The first byte is not the sync byte 0x9B.
    NoSync {
        /// The byte found instead.
        found: u8,
    },
    /// The length byte is neither 0x16 (data) nor 0x4C (device information).
    UnknownLength {
        /// The length byte found.
        found: u8,
    },
    /// Fewer bytes than a whole frame.
    Truncated {
        /// Bytes a whole frame has.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
    /// The checksum does not match the bytes: the frame was corrupted on the wire.
    Checksum {
        /// Checksum computed over the received bytes.
        expected: u16,
        /// Checksum carried by the frame.
        found: u16,
    },
    /// Checksum correct, but a version or command this decoder does not know.
    UnknownCommand {
        /// Version byte (byte 2).
        version: u8,
        /// Command byte (byte 3).
        command: u8,
    },
    /// A device-information candidate whose text holds a byte that is not ASCII: not a real
    /// frame (typically a cut one with another frame behind it).
    NotText {
        /// Offset of the first such byte in the frame.
        offset: usize,
        /// The byte.
        found: u8,
    },
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            FrameError::NoSync { found } => {
                write!(f, "frame starts with 0x{found:02X}, not the sync byte 0x9B")
            }
            FrameError::UnknownLength { found } => write!(
                f,
                "unknown length byte 0x{found:02X} (expected 0x16 or 0x4C)"
            ),
            FrameError::Truncated { needed, got } => {
                write!(f, "truncated frame: {got} of {needed} bytes")
            }
            FrameError::Checksum { expected, found } => write!(
                f,
                "checksum mismatch: bytes sum to 0x{expected:04X}, frame carries 0x{found:04X}"
            ),
            FrameError::UnknownCommand { version, command } => write!(
                f,
                "unknown version 0x{version:02X} / command 0x{command:02X}"
            ),
            FrameError::NotText { offset, found } => write!(
                f,
                "device-information text holds byte 0x{found:02X} at offset {offset}, which is not ASCII"
            ),
        }
    }
}

impl core::error::Error for FrameError {}
