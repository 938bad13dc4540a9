//! Why bytes are not an HW5 frame.

use core::fmt;

use super::layout::Direction;

/// Why [`TelemetryFrame::parse`](super::TelemetryFrame::parse) or [`identify`](super::identify)
/// refused bytes, in the order they check them (the scanner rejects candidates in the same
/// order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Error {
    /// Fewer bytes than the frame needs.
    Truncated {
        /// Bytes needed.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
    /// The first three bytes are not an envelope: `FE 01 00` (from the ESC) or `01 FD 03` (a
    /// request).
    Envelope {
        /// The three bytes found.
        found: [u8; 3],
    },
    /// Not a telemetry frame: its code (byte 3) and type (bytes 4-5) are not `03` and 0x5C30.
    NotTelemetry {
        /// Byte 3.
        code: u8,
        /// Bytes 4-5, little-endian.
        frame_type: u16,
    },
    /// A frame whose length cannot be known: no kind of its direction has this type (or, for
    /// telemetry, this code).
    UnknownType {
        /// Who sent it (from its envelope).
        direction: Direction,
        /// Byte 3.
        code: u8,
        /// Bytes 4-5, little-endian.
        frame_type: u16,
    },
    /// A telemetry frame whose payload length byte (byte 6) is not 23 (`17`).
    PayloadLength {
        /// The byte found.
        found: u8,
    },
    /// The CRC matches, but a value is outside the range the protocol allows: a corrupted
    /// frame whose CRC still matches.
    OutOfRange {
        /// The field.
        field: &'static str,
        /// Its raw value.
        raw: u16,
        /// The largest the protocol allows.
        max: u16,
    },
    /// The CRC-16/MODBUS does not match the bytes: the frame was corrupted on the wire.
    Crc {
        /// CRC computed over the bytes before the check bytes.
        expected: u16,
        /// CRC carried by the last two bytes (low byte first).
        found: u16,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Error::Truncated { needed, got } => {
                write!(f, "truncated HW5 frame: {got} of {needed} bytes")
            }
            Error::Envelope { found: [a, b, c] } => write!(
                f,
                "HW5 frame starts with {a:02X} {b:02X} {c:02X}, not FE 01 00 or 01 FD 03"
            ),
            Error::NotTelemetry { code, frame_type } => write!(
                f,
                "not an HW5 telemetry frame: code 0x{code:02X}, type 0x{frame_type:04X} \
                 (expected 0x03, 0x5C30)"
            ),
            Error::UnknownType {
                direction,
                code,
                frame_type,
            } => write!(
                f,
                "unknown HW5 frame {}: code 0x{code:02X}, type 0x{frame_type:04X}",
                match direction {
                    Direction::FromEsc => "from the ESC",
                    Direction::ToEsc => "to the ESC",
                }
            ),
            Error::PayloadLength { found } => write!(
                f,
                "HW5 telemetry payload length 0x{found:02X} (expected 0x17)"
            ),
            Error::OutOfRange { field, raw, max } => write!(
                f,
                "HW5 {field} {raw} out of the protocol's range 0..={max}: a corrupted frame whose CRC still matches"
            ),
            Error::Crc { expected, found } => write!(
                f,
                "HW5 CRC mismatch: bytes give 0x{expected:04X}, frame carries 0x{found:04X}"
            ),
        }
    }
}

impl core::error::Error for Error {}
