//! The DataLink V2 frame: a frame counter and up to eight ESCs' data, read and written.

use crate::foc::kinds::data::{DATA_PAYLOAD_LEN, DataFrame};
use crate::wire::CheckError;
use crate::wire::SYNC;

use super::error::Error;
use super::layout::{
    CHANNELS, CHECK_AT, CHECKSUM, COUNTER_AT, FRAME_LEN, LengthByte, RECORD_LEN, RECORDS_AT,
    header, is_version_and_command,
};

/// One DataLink V2 frame: the hub's frame counter and the data of up to eight ESCs, indexed by
/// channel (0-based).
///
/// A slot holds the record whose channel byte is its index. On the wire a slot without an ESC
/// is a record of 18 zero bytes after its channel byte, so a slot holding a [`DataFrame`] whose
/// every field is zero encodes as an empty slot and parses back as `None`.
///
/// ```
/// use hwfoc::datalink::{HubFrame, FRAME_LEN};
/// use hwfoc::foc::DataFrame;
///
/// let mut frame = HubFrame::new(41);
/// frame.slots[2] = Some(DataFrame { packet: 7, voltage_raw: 252, ..Default::default() });
/// let bytes = frame.encode();
/// assert_eq!(bytes.len(), FRAME_LEN);
/// assert_eq!(&bytes[..6], &[0x9B, 0x9E, 0x01, 0x02, 0x00, 41]);
/// assert_eq!(bytes[6 + 2 * 19], 2); // the channel byte of slot 2's record
/// assert_eq!(HubFrame::parse(&bytes)?, frame);
/// # Ok::<(), hwfoc::datalink::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct HubFrame {
    /// The hub's frame counter (bytes 4..6, big-endian).
    pub counter: u16,
    /// The ESC records by channel; `None` for an empty slot.
    pub slots: [Option<DataFrame>; CHANNELS],
}

/// What reading a frame's records found besides the ESCs' data, and which length byte the frame
/// carried: the per-frame part of [`Stats`](super::Stats).
///
/// The eight records of a frame are each exactly one of: an ESC's data (in its slot),
/// [empty](FrameReport::empty_slots), a [bad channel](FrameReport::bad_channels) or a
/// [duplicate channel](FrameReport::duplicate_channels).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FrameReport {
    /// The frame's length byte.
    pub length_byte: LengthByte,
    /// Records whose 18 bytes after the channel byte are all zero (whatever the channel byte):
    /// no ESC there. Not an error.
    pub empty_slots: u8,
    /// Records with data whose channel byte is above 7: dropped.
    pub bad_channels: u8,
    /// Records with data for a channel that an earlier record of the frame already filled:
    /// dropped (the first is kept).
    pub duplicate_channels: u8,
}

impl HubFrame {
    /// A frame with counter `counter` and every slot empty.
    pub const fn new(counter: u16) -> Self {
        HubFrame {
            counter,
            slots: [None; CHANNELS],
        }
    }

    /// Encodes the frame as the hub sends it, with the length byte 0x9E (158).
    ///
    /// The record of slot `i` is written at position `i` with channel byte `i`; an empty slot is
    /// its channel byte and 18 zero bytes.
    pub fn encode(&self) -> [u8; FRAME_LEN] {
        self.encode_as(LengthByte::Covered)
    }

    /// Encodes the frame with the given length byte (the bytes differ from [`Self::encode`]'s
    /// only in the length byte and, through it, the CRC).
    pub fn encode_as(&self, length_byte: LengthByte) -> [u8; FRAME_LEN] {
        let mut f = [0u8; FRAME_LEN];
        f[..4].copy_from_slice(&header(length_byte));
        f[COUNTER_AT..RECORDS_AT].copy_from_slice(&self.counter.to_be_bytes());
        let records = f[RECORDS_AT..CHECK_AT].chunks_exact_mut(RECORD_LEN);
        for ((channel, record), slot) in (0u8..).zip(records).zip(&self.slots) {
            let Some((channel_byte, payload)) = record.split_first_mut() else {
                continue;
            };
            *channel_byte = channel;
            if let (Some(esc), Ok(payload)) =
                (slot, <&mut [u8; DATA_PAYLOAD_LEN]>::try_from(payload))
            {
                esc.write_payload(payload);
            }
        }
        CHECKSUM.seal(&mut f);
        f
    }

    /// Decodes a frame from the first [`FRAME_LEN`] bytes of `bytes` (bytes after it are
    /// ignored), checking in this order: length, sync byte, length byte (0x9E or 0xA0), version
    /// and command (`01 02`), CRC. The records are read as the decoder reads them (see
    /// [`FrameReport`]): a bad or duplicate channel drops that record, not the frame.
    pub fn parse(bytes: &[u8]) -> Result<HubFrame, Error> {
        Self::parse_with_report(bytes).map(|(frame, _)| frame)
    }

    /// [`Self::parse`], with what reading the records found.
    pub fn parse_with_report(bytes: &[u8]) -> Result<(HubFrame, FrameReport), Error> {
        let Some(f) = bytes.first_chunk::<FRAME_LEN>() else {
            return Err(Error::Truncated { got: bytes.len() });
        };
        if f[0] != SYNC {
            return Err(Error::NoSync { found: f[0] });
        }
        let Some(length_byte) = LengthByte::from_byte(f[1]) else {
            return Err(Error::UnknownLength { found: f[1] });
        };
        if !is_version_and_command(f[2], f[3]) {
            return Err(Error::UnknownCommand {
                version: f[2],
                command: f[3],
            });
        }
        match CHECKSUM.verify(f) {
            Ok(()) => Ok(Self::read(f, length_byte)),
            Err(CheckError::Checksum { expected, found }) => Err(Error::Crc { expected, found }),
            // A 160-byte frame always holds its check bytes.
            Err(_) => Err(Error::Truncated { got: bytes.len() }),
        }
    }

    /// Whether the CRC of a whole candidate matches (its header already checked).
    #[inline(always)]
    pub(crate) fn crc_ok(f: &[u8; FRAME_LEN]) -> bool {
        CHECKSUM.verify(f).is_ok()
    }

    /// Reads the counter and records of a frame whose header and CRC are verified.
    #[inline]
    pub(crate) fn read(f: &[u8; FRAME_LEN], length_byte: LengthByte) -> (HubFrame, FrameReport) {
        let mut frame = HubFrame::new(u16::from_be_bytes([f[COUNTER_AT], f[COUNTER_AT + 1]]));
        let mut report = FrameReport {
            length_byte,
            empty_slots: 0,
            bad_channels: 0,
            duplicate_channels: 0,
        };
        for record in f[RECORDS_AT..CHECK_AT].chunks_exact(RECORD_LEN) {
            let Some((&channel, payload)) = record.split_first() else {
                continue;
            };
            let Ok(payload) = <&[u8; DATA_PAYLOAD_LEN]>::try_from(payload) else {
                continue;
            };
            if *payload == [0; DATA_PAYLOAD_LEN] {
                report.empty_slots += 1;
                continue;
            }
            match frame.slots.get_mut(usize::from(channel)) {
                None => report.bad_channels += 1,
                Some(Some(_)) => report.duplicate_channels += 1,
                Some(slot) => *slot = Some(DataFrame::read_payload(payload)),
            }
        }
        (frame, report)
    }

    /// The ESCs present: `(channel, data)` of every filled slot, in channel order.
    pub fn escs(&self) -> impl Iterator<Item = (usize, &DataFrame)> {
        self.slots
            .iter()
            .enumerate()
            .filter_map(|(channel, slot)| slot.as_ref().map(|esc| (channel, esc)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Status;

    fn esc(packet: u16) -> DataFrame {
        DataFrame {
            packet,
            throttle_in_raw: 512,
            throttle_out_raw: 500,
            erpm_raw: 1234,
            voltage_raw: 252,
            current_raw: -16,
            phase_current_raw: 300,
            mos_adc: 200,
            cap_adc: 210,
            status: Status(0x0102),
        }
    }

    /// The frame of `encode`, checked byte by byte against the layout of `docs/PROTOCOL-NOTES.md`,
    /// and its CRC against Python's `binascii.crc_hqx(bytes[:158], 0)` (CRC-16/XMODEM).
    #[test]
    fn encode_writes_the_documented_layout() {
        let mut frame = HubFrame::new(0x1234);
        frame.slots[0] = Some(esc(0xABCD));
        frame.slots[7] = Some(esc(1));
        let b = frame.encode();
        assert_eq!(b[..6], [0x9B, 0x9E, 0x01, 0x02, 0x12, 0x34]);
        let rec0 = [
            0, 0xAB, 0xCD, 0x02, 0x00, 0x01, 0xF4, 0x04, 0xD2, 0x00, 0xFC, 0xFF, 0xF0, 0x01, 0x2C,
            200, 210, 0x01, 0x02,
        ];
        assert_eq!(b[6..25], rec0);
        for ch in 1..7 {
            let at = 6 + 19 * ch;
            assert_eq!(b[at], ch as u8);
            assert_eq!(b[at + 1..at + 19], [0; 18]);
        }
        assert_eq!(b[6 + 19 * 7], 7);
        assert_eq!(b[6 + 19 * 7 + 1..6 + 19 * 7 + 3], [0, 1]);
        // python3 -c "import binascii; ..." over these 158 bytes gives 0x09D1.
        assert_eq!(u16::from_le_bytes([b[158], b[159]]), 0x09D1);
        let total = frame.encode_as(LengthByte::Total);
        assert_eq!(total[1], 0xA0);
        assert_eq!(total[2..158], b[2..158]);
        assert_ne!(total[158..], b[158..]);
    }

    #[test]
    fn records_by_channel_byte_not_position() {
        let mut b = HubFrame::new(3).encode();
        // Record 0 for channel 5, record 1 for channel 9, record 2 again for channel 5,
        // record 3 empty with a channel byte of 200.
        let r = |i: usize| 6 + 19 * i;
        b[r(0)] = 5;
        b[r(0) + 2] = 1;
        b[r(1)] = 9;
        b[r(1) + 2] = 2;
        b[r(2)] = 5;
        b[r(2) + 2] = 3;
        b[r(3)] = 200;
        CHECKSUM.seal(&mut b);
        let (frame, report) = HubFrame::parse_with_report(&b).unwrap();
        assert_eq!(frame.slots[5].map(|e| e.packet), Some(1));
        assert_eq!(frame.escs().count(), 1);
        assert_eq!(
            report,
            FrameReport {
                length_byte: LengthByte::Covered,
                empty_slots: 5,
                bad_channels: 1,
                duplicate_channels: 1
            }
        );
    }

    #[test]
    fn parse_errors_in_order() {
        let good = HubFrame::new(1).encode();
        assert_eq!(
            HubFrame::parse(&good[..159]),
            Err(Error::Truncated { got: 159 })
        );
        let mut b = good;
        b[0] = 0x9C;
        b[1] = 0x16;
        assert_eq!(HubFrame::parse(&b), Err(Error::NoSync { found: 0x9C }));
        b[0] = 0x9B;
        assert_eq!(
            HubFrame::parse(&b),
            Err(Error::UnknownLength { found: 0x16 })
        );
        b[1] = 0xA0;
        b[3] = 0x01;
        assert_eq!(
            HubFrame::parse(&b),
            Err(Error::UnknownCommand {
                version: 1,
                command: 1
            })
        );
        b[3] = 0x02;
        let carried = u16::from_le_bytes([b[158], b[159]]);
        let Err(Error::Crc { expected, found }) = HubFrame::parse(&b) else {
            panic!("a changed length byte breaks the CRC");
        };
        assert_eq!(
            (found, expected),
            (carried, crate::wire::crc16_xmodem(&b[..158]))
        );
        assert_ne!(expected, found);
        let mut longer = [0u8; 200];
        longer[..160].copy_from_slice(&good);
        assert_eq!(HubFrame::parse(&longer), Ok(HubFrame::new(1)));
    }

    #[test]
    fn error_messages() {
        use core::fmt::Write;
        let mut s = heapless_string();
        write!(s, "{}", Error::UnknownLength { found: 0x9F }).unwrap();
        assert_eq!(
            s.as_str(),
            "unknown DataLink length byte 0x9F (expected 0x9E or 0xA0)"
        );
    }

    /// A fixed-capacity string for `Display` tests in this `no_std` crate.
    struct Buf {
        bytes: [u8; 96],
        len: usize,
    }
    fn heapless_string() -> Buf {
        Buf {
            bytes: [0; 96],
            len: 0,
        }
    }
    impl Buf {
        fn as_str(&self) -> &str {
            core::str::from_utf8(&self.bytes[..self.len]).unwrap()
        }
    }
    impl core::fmt::Write for Buf {
        fn write_str(&mut self, s: &str) -> core::fmt::Result {
            let end = self.len + s.len();
            self.bytes
                .get_mut(self.len..end)
                .ok_or(core::fmt::Error)?
                .copy_from_slice(s.as_bytes());
            self.len = end;
            Ok(())
        }
    }
}
