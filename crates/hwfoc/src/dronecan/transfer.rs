//! Sending: a transfer's payload cut into CAN frames ([`Frames`]), with the transfer CRC of a
//! multi-frame transfer ([`transfer_crc`]), tail bytes and toggles, as pydronecan's
//! `transport.Transfer.to_frames()` does.

use super::frame::CanFrame;
use super::id::{Header, TailByte};
use super::kind::{Form, MAX_PAYLOAD_LEN, Message};
use crate::wire::crc16_ccitt;

/// Payload bytes in a frame beside the tail byte (classic CAN).
pub const FRAME_PAYLOAD: usize = 7;

/// The CRC that seeds a data type's transfer CRCs: CRC-16/CCITT-FALSE (polynomial 0x1021,
/// initial 0xFFFF, no reflection, no final XOR) of the signature's 8 bytes, little-endian
/// (pydronecan's `base_crc`: `crc16_from_bytes(struct.pack("<Q", signature))`).
pub const fn signature_crc(signature: u64) -> u16 {
    crc16_ccitt(0xFFFF, &signature.to_le_bytes())
}

/// The transfer CRC of a multi-frame transfer of `payload` of a data type with `signature`:
/// CRC-16/CCITT-FALSE over the signature (8 bytes, little-endian) then the payload
/// (pydronecan's `crc16_from_bytes(payload, initial=base_crc)`). It is sent little-endian
/// before the payload, in the first frame.
///
/// ```
/// // esc.Status of the bridge's test, as pydronecan computes it.
/// let payload = [0x07, 0, 0, 0, 0x20, 0x4C, 0x80, 0xC0, 0xE5, 0x5C, 0x2E, 0xFB, 0xDB, 0x8C];
/// assert_eq!(hwfoc::dronecan::transfer_crc(0xA9AF_28AE_A2FB_B254, &payload), 0xC75C);
/// ```
pub const fn transfer_crc(signature: u64, payload: &[u8]) -> u16 {
    crc16_ccitt(signature_crc(signature), payload)
}

/// The CAN frames of one transfer, in order (an iterator; see [`Frames::new`]).
#[derive(Debug, Clone)]
pub struct Frames {
    id: u32,
    /// The CRC (if any) then the payload.
    bytes: [u8; MAX_PAYLOAD_LEN + 2],
    total: usize,
    pos: usize,
    toggle: bool,
    first: bool,
    transfer_id: u8,
}

impl Frames {
    /// The frames of a transfer of `payload` with the 29-bit CAN id `can_id`: a payload of up to
    /// 7 bytes is one frame (no CRC, start and end set; an empty payload is a frame of just the
    /// tail byte); a longer one is preceded by its [`transfer_crc`] and cut into frames of 7
    /// bytes and the tail byte, the last one shorter; toggles 0, 1, 0, ... `None` if `payload`
    /// is longer than [`MAX_PAYLOAD_LEN`] or `can_id` wider than 29 bits.
    pub fn new(can_id: u32, signature: u64, transfer_id: u8, payload: &[u8]) -> Option<Frames> {
        if payload.len() > MAX_PAYLOAD_LEN || can_id > super::frame::MAX_EXTENDED_ID {
            return None;
        }
        Some(Frames::build(can_id, signature, transfer_id, payload))
    }

    /// [`Frames::new`] of arguments known to fit (a longer payload is cut to
    /// [`MAX_PAYLOAD_LEN`], the id to 29 bits).
    fn build(can_id: u32, signature: u64, transfer_id: u8, payload: &[u8]) -> Frames {
        let payload = &payload[..payload.len().min(MAX_PAYLOAD_LEN)];
        let mut bytes = [0u8; MAX_PAYLOAD_LEN + 2];
        let total = if payload.len() > FRAME_PAYLOAD {
            bytes[..2].copy_from_slice(&transfer_crc(signature, payload).to_le_bytes());
            bytes[2..2 + payload.len()].copy_from_slice(payload);
            payload.len() + 2
        } else {
            bytes[..payload.len()].copy_from_slice(payload);
            payload.len()
        };
        Frames {
            id: can_id & super::frame::MAX_EXTENDED_ID,
            bytes,
            total,
            pos: 0,
            toggle: false,
            first: true,
            transfer_id,
        }
    }
}

impl Iterator for Frames {
    type Item = CanFrame;

    fn next(&mut self) -> Option<CanFrame> {
        if !self.first && self.pos >= self.total {
            return None;
        }
        let n = (self.total - self.pos).min(FRAME_PAYLOAD);
        let mut data = [0u8; 8];
        data[..n].copy_from_slice(&self.bytes[self.pos..self.pos + n]);
        self.pos += n;
        data[n] = TailByte {
            start: self.first,
            end: self.pos >= self.total,
            toggle: self.toggle,
            transfer_id: self.transfer_id,
        }
        .byte();
        self.first = false;
        self.toggle = !self.toggle;
        CanFrame::extended(self.id, &data[..=n])
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = if self.first {
            self.total.div_ceil(FRAME_PAYLOAD).max(1)
        } else {
            (self.total - self.pos).div_ceil(FRAME_PAYLOAD)
        };
        (left, Some(left))
    }
}

impl ExactSizeIterator for Frames {}

impl Message {
    /// The header of this message sent by `source_node` at `priority`: a broadcast for a
    /// message (`destination_node` is not used), a request or response to `destination_node`
    /// for a service's half.
    pub fn header(&self, priority: u8, source_node: u8, destination_node: u8) -> Header {
        let kind = self.kind();
        let id = kind.data_type_id();
        match kind.form() {
            Form::Message => Header::message(priority, id, source_node),
            Form::Request => Header::request(priority, id as u8, source_node, destination_node),
            Form::Response => Header::response(priority, id as u8, source_node, destination_node),
        }
    }

    /// The CAN frames of this message as one transfer with [`Message::header`] and
    /// `transfer_id`.
    ///
    /// ```
    /// use hwfoc::dronecan::{Message, StatusMsg1};
    /// let m = Message::from(StatusMsg1 { rpm: 1200, pwm: 300, status: 0 });
    /// let frames: Vec<_> = m.frames(16, 1, 0, 3).collect();
    /// assert_eq!(frames.len(), 1);
    /// assert_eq!(frames[0].id(), 0x104E_5201);
    /// assert_eq!(frames[0].data(), [0xB0, 0x04, 0x2C, 0x01, 0, 0, 0xC3]);
    /// ```
    pub fn frames(
        &self,
        priority: u8,
        source_node: u8,
        destination_node: u8,
        transfer_id: u8,
    ) -> Frames {
        let mut payload = [0u8; MAX_PAYLOAD_LEN];
        let n = self.encode_into(&mut payload);
        let id = self
            .header(priority, source_node, destination_node)
            .can_id();
        Frames::build(id, self.kind().signature(), transfer_id, &payload[..n])
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    /// The frames pydronecan 1.0.27 makes of the bridge's esc.Status (node 100, transfer id 5,
    /// priority 16), from the bridge's test.
    #[test]
    fn esc_status_three_frames_as_pydronecan() {
        let payload = [
            0x07, 0x00, 0x00, 0x00, 0x20, 0x4C, 0x80, 0xC0, 0xE5, 0x5C, 0x2E, 0xFB, 0xDB, 0x8C,
        ];
        let f: Vec<CanFrame> = Frames::new(0x1004_0A64, 0xA9AF_28AE_A2FB_B254, 5, &payload)
            .unwrap()
            .collect();
        assert_eq!(f.len(), 3);
        assert_eq!(
            f[0].data(),
            [0x5C, 0xC7, 0x07, 0x00, 0x00, 0x00, 0x20, 0x85]
        );
        assert_eq!(
            f[1].data(),
            [0x4C, 0x80, 0xC0, 0xE5, 0x5C, 0x2E, 0xFB, 0x25]
        );
        assert_eq!(f[2].data(), [0xDB, 0x8C, 0x45]);
    }

    #[test]
    fn lengths_and_tails() {
        let f: Vec<CanFrame> = Frames::new(1, 0, 0, &[]).unwrap().collect();
        assert_eq!(f.len(), 1);
        assert_eq!(f[0].data(), [0xC0]);
        let f: Vec<CanFrame> = Frames::new(1, 0, 2, &[0; 8]).unwrap().collect();
        assert_eq!(f.len(), 2);
        assert_eq!(f[0].data()[7], 0x82);
        assert_eq!(f[1].data(), [0, 0, 0, 0x62]);
        let f: Vec<CanFrame> = Frames::new(1, 0, 31, &[0; 12]).unwrap().collect();
        assert_eq!(f.len(), 2);
        assert_eq!(f[1].data().len(), 8);
        let frames = Frames::new(1, 0, 7, &[0; 14]).unwrap();
        assert_eq!(frames.len(), 3);
        assert!(Frames::new(1, 0, 7, &[0; 15]).is_none());
        assert!(Frames::new(0x2000_0000, 0, 7, &[]).is_none());
    }
}
