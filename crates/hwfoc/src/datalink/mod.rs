//! Hobbywing DataLink V2: the hub that merges up to eight ESCs onto one 115200-baud wire, as one
//! 160-byte frame (`docs/PROTOCOL-NOTES.md`, "The DataLink side").
//!
//! A family of its own beside the HW-FOC decoder ([`crate::foc`]), not a kind of
//! [`crate::foc::FocFrame`]: a hub's wire carries only these frames, an ESC's wire never does, so
//! neither decoder pays for the other (the HW-FOC [`Decoder`](crate::foc::Decoder) keeps its
//! 76-byte buffer; this one holds up to 159 bytes). What the two share is not copied:
//!
//! - the sync byte and version ([`crate::wire::SYNC`], [`crate::wire::VERSION`]), the byte
//!   timing ([`byte_ns`](crate::wire::byte_ns) of this module's [`BAUD_RATE`]) and the check
//!   bytes ([`Checksum::Crc16Xmodem`](crate::wire::Checksum::Crc16Xmodem), a table-driven
//!   [`crc16_xmodem`](crate::wire::crc16_xmodem));
//! - each record's 18 payload bytes, read and written by [`DataFrame`](crate::foc::DataFrame)'s own
//!   code (a record is a channel byte and a data frame's payload);
//! - the sync-pair search of the HW-FOC scanner, with 0x9E / 0xA0 as the second byte;
//! - the following of a counter ([`PacketSequence`](crate::counters::PacketSequence)), for the
//!   hub's frame counter and each channel's packet numbers.
//!
//! | module | holds |
//! |---|---|
//! | `layout` | [`BAUD_RATE`], [`FRAME_LEN`], [`RECORD_LEN`], [`CHANNELS`], offsets, [`LengthByte`] |
//! | `frame` | [`HubFrame`] (encode, parse), [`FrameReport`] |
//! | `error` | [`Error`] |
//! | `stats` | [`Stats`], [`esc_frames_in`] |
//! | `decoder` | the scanner: [`Decoder`], [`frames`], [`Decoded`] |
//!
//! ```
//! use hwfoc::datalink::{self, HubFrame};
//! use hwfoc::foc::DataFrame;
//!
//! let mut frame = HubFrame::new(1);
//! frame.slots[0] = Some(DataFrame { packet: 10, erpm_raw: 900, ..Default::default() });
//! frame.slots[3] = Some(DataFrame { packet: 20, erpm_raw: 950, ..Default::default() });
//! let mut wire = b"noise".to_vec();
//! wire.extend_from_slice(&frame.encode());
//!
//! let decoded: Vec<_> = datalink::frames(&wire).collect();
//! assert_eq!(decoded[0].offset, 5);
//! let escs: Vec<(usize, u16)> = decoded[0].frame.escs().map(|(ch, e)| (ch, e.erpm_raw)).collect();
//! assert_eq!(escs, [(0, 900), (3, 950)]);
//! assert_eq!(decoded[0].report.empty_slots, 6);
//! ```

pub(crate) mod decoder;
mod description;
mod error;
mod frame;
mod layout;
mod stats;

pub use decoder::{Decoded, Decoder, Frames, Scanner, frames};
pub use description::DESCRIPTION;
pub use error::Error;
pub use frame::{FrameReport, HubFrame};
pub use layout::{
    BAUD_RATE, CHANNELS, CHECK_AT, CHECKSUM, COMMAND, COUNTER_AT, FRAME_LEN, LengthByte,
    RECORD_LEN, RECORDS_AT, header,
};
pub use stats::{Stats, esc_frames_in};
