//! The DataLink V2 frame on the wire: line speed, lengths, header bytes and check bytes.
//!
//! ```text
//!  0    1         2    3    4..5      6 .. 157                             158    159
//!  9B   9E or A0  01   02   counter   8 records of 19 bytes                CRC_L  CRC_H
//!                           (BE)      channel u8, then a data frame's      CRC-16/XMODEM
//!                                     18 payload bytes (BE)                of bytes 0..=157
//! ```

use crate::foc::kinds::data::{CMD_DATA, DATA_PAYLOAD_LEN};
use crate::wire::{Checksum, SYNC, VERSION};

/// Baud rate of the hub's output wire (8N1); byte times come from
/// [`byte_ns`](crate::wire::byte_ns)`(BAUD_RATE)`.
pub const BAUD_RATE: u32 = 115_200;
/// Length of a DataLink V2 frame on the wire, check bytes included.
pub const FRAME_LEN: usize = 160;
/// Number of ESC records in a frame: one per channel, channels `0..CHANNELS`.
pub const CHANNELS: usize = 8;
/// Length of one record: its channel byte and the 18 payload bytes of a HW-FOC data frame
/// ([`DATA_PAYLOAD_LEN`]: packet number to status word, big-endian).
pub const RECORD_LEN: usize = 1 + DATA_PAYLOAD_LEN;
/// Offset of the big-endian frame counter.
pub const COUNTER_AT: usize = 4;
/// Offset of the first record.
pub const RECORDS_AT: usize = 6;
/// The check bytes: CRC-16/XMODEM of bytes 0..=157, low byte first.
pub const CHECKSUM: Checksum = Checksum::Crc16Xmodem;
/// Offset of the check bytes (and the number of bytes they cover).
pub const CHECK_AT: usize = FRAME_LEN - 2;
/// Command byte (byte 3): the data command of the HW-FOC data frame.
pub const COMMAND: u8 = CMD_DATA;

/// The length byte a frame carries (byte 1). Both are accepted; the encoder writes
/// [`LengthByte::Covered`] unless told otherwise.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LengthByte {
    /// 0x9E (158): the bytes before the check bytes, the HW-FOC rule; seen on hardware.
    Covered,
    /// 0xA0 (160): the whole frame; what some drivers write.
    Total,
}

impl LengthByte {
    /// Both, in the order of their values.
    pub const ALL: [LengthByte; 2] = [LengthByte::Covered, LengthByte::Total];

    /// The byte on the wire.
    pub const fn byte(self) -> u8 {
        match self {
            LengthByte::Covered => CHECK_AT as u8,
            LengthByte::Total => FRAME_LEN as u8,
        }
    }

    /// The kind of `byte`, or `None` for any other byte.
    #[inline(always)]
    pub const fn from_byte(byte: u8) -> Option<LengthByte> {
        if byte == LengthByte::Covered.byte() {
            Some(LengthByte::Covered)
        } else if byte == LengthByte::Total.byte() {
            Some(LengthByte::Total)
        } else {
            None
        }
    }
}

/// The header of a frame with `length_byte`.
pub const fn header(length_byte: LengthByte) -> [u8; 4] {
    [SYNC, length_byte.byte(), VERSION, COMMAND]
}

/// Whether bytes 2 and 3 of a candidate are the version and command of a DataLink frame.
#[inline(always)]
pub(crate) const fn is_version_and_command(version: u8, command: u8) -> bool {
    version == VERSION && command == COMMAND
}

const _: () = {
    assert!(RECORDS_AT == COUNTER_AT + 2);
    assert!(RECORDS_AT + CHANNELS * RECORD_LEN == CHECK_AT);
    assert!(CHECK_AT + CHECKSUM.width() == FRAME_LEN);
    assert!(LengthByte::Covered.byte() == 0x9E && LengthByte::Total.byte() == 0xA0);
    // The channel byte fits the decoder's one-byte hold count.
    assert!(FRAME_LEN - 1 <= u8::MAX as usize);
};
