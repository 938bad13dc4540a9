//! Why bytes are not a DataLink V2 frame.

use core::fmt;

use super::layout::{FRAME_LEN, LengthByte};

/// Why [`HubFrame::parse`](super::HubFrame::parse) refused bytes, in the order it
/// checks them (the streaming decoder rejects candidates in the same order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Error {
    /// Fewer than [`FRAME_LEN`] bytes.
    Truncated {
        /// Bytes given.
        got: usize,
    },
    /// The first byte is not the sync byte 0x9B.
    NoSync {
        /// The byte found instead.
        found: u8,
    },
    /// The length byte is neither 0x9E nor 0xA0.
    UnknownLength {
        /// The length byte found.
        found: u8,
    },
    /// The version and command bytes are not `01 02`.
    UnknownCommand {
        /// Version byte (byte 2).
        version: u8,
        /// Command byte (byte 3).
        command: u8,
    },
    /// The CRC-16/XMODEM does not match the bytes: the frame was corrupted on the wire.
    Crc {
        /// CRC computed over bytes 0..=157.
        expected: u16,
        /// CRC carried by bytes 158 (low) and 159 (high).
        found: u16,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Error::Truncated { got } => {
                write!(f, "truncated DataLink frame: {got} of {FRAME_LEN} bytes")
            }
            Error::NoSync { found } => write!(
                f,
                "DataLink frame starts with 0x{found:02X}, not the sync byte 0x9B"
            ),
            Error::UnknownLength { found } => write!(
                f,
                "unknown DataLink length byte 0x{found:02X} (expected 0x{:02X} or 0x{:02X})",
                LengthByte::Covered.byte(),
                LengthByte::Total.byte()
            ),
            Error::UnknownCommand { version, command } => write!(
                f,
                "unknown DataLink version 0x{version:02X} / command 0x{command:02X} (expected 01 02)"
            ),
            Error::Crc { expected, found } => write!(
                f,
                "DataLink CRC mismatch: bytes give 0x{expected:04X}, frame carries 0x{found:04X}"
            ),
        }
    }
}

impl core::error::Error for Error {}
