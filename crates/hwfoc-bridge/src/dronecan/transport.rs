//! The DroneCAN CAN transport (specification chapter 4.1) for message broadcasts: the 29-bit
//! CAN ID, the tail byte, and the splitting of a transfer into frames with its CRC.
//!
//! - CAN ID of a message: priority (5 bits) << 24 | data type id (16 bits) << 8 |
//!   service-not-message (0) << 7 | source node id (7 bits).
//! - Tail byte, last byte of every frame: start of transfer (0x80), end of transfer (0x40),
//!   toggle (0x20: 0 in the first frame, alternating), transfer id (5 bits, +1 per transfer of
//!   the same message type from the same node, wrapping 31 -> 0).
//! - A payload of up to 7 bytes is one frame (start and end set). A longer payload is preceded
//!   by the transfer CRC (CRC-16-CCITT-FALSE: polynomial 0x1021, initial 0xFFFF, fed first the
//!   data type signature's 8 bytes little-endian, then the payload), little-endian, and the
//!   whole cut into frames of 7 bytes plus the tail byte, the last one shorter.
//! - The tail array optimisation concerns only a message's last field when it is an array;
//!   the messages sent here have none.

/// A classic CAN frame with an extended (29-bit) identifier.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CanFrame {
    /// The 29-bit identifier.
    pub id: u32,
    len: u8,
    data: [u8; 8],
}

impl CanFrame {
    /// The frame's data bytes (1 to 8, the tail byte last).
    pub fn data(&self) -> &[u8] {
        &self.data[..usize::from(self.len)]
    }
}

/// The CAN ID of a message broadcast.
pub fn message_id(priority: u8, data_type_id: u16, source_node: u8) -> u32 {
    (u32::from(priority & 0x1F) << 24)
        | (u32::from(data_type_id) << 8)
        | u32::from(source_node & 0x7F)
}

/// The transfer CRC of a multi-frame transfer of `payload` of a data type with `signature`.
pub fn transfer_crc(signature: u64, payload: &[u8]) -> u16 {
    let seeded = hwfoc::wire::crc16_ccitt(0xFFFF, &signature.to_le_bytes());
    hwfoc::wire::crc16_ccitt(seeded, payload)
}

/// The tail byte.
pub fn tail_byte(start: bool, end: bool, toggle: bool, transfer_id: u8) -> u8 {
    (u8::from(start) << 7) | (u8::from(end) << 6) | (u8::from(toggle) << 5) | (transfer_id & 0x1F)
}

/// The frames of one transfer of `payload` with CAN ID `id`, in order.
pub fn frames(id: u32, signature: u64, transfer_id: u8, payload: &[u8]) -> Frames<'_> {
    let crc = (payload.len() > 7).then(|| transfer_crc(signature, payload).to_le_bytes());
    Frames {
        id,
        transfer_id,
        crc,
        payload,
        pos: 0,
        toggle: false,
        first: true,
    }
}

/// The frames of a transfer (see [`frames`]).
#[derive(Debug, Clone)]
pub struct Frames<'a> {
    id: u32,
    transfer_id: u8,
    crc: Option<[u8; 2]>,
    payload: &'a [u8],
    /// Position in the byte stream of CRC (if any) then payload.
    pos: usize,
    toggle: bool,
    first: bool,
}

impl Iterator for Frames<'_> {
    type Item = CanFrame;

    fn next(&mut self) -> Option<CanFrame> {
        let prefix = if self.crc.is_some() { 2 } else { 0 };
        let total = prefix + self.payload.len();
        if !self.first && self.pos >= total {
            return None;
        }
        let mut data = [0u8; 8];
        let n = (total - self.pos).min(7);
        for (i, d) in data[..n].iter_mut().enumerate() {
            let at = self.pos + i;
            *d = match self.crc {
                Some(crc) if at < 2 => crc[at],
                _ => self.payload[at - prefix],
            };
        }
        self.pos += n;
        let end = self.pos >= total;
        data[n] = tail_byte(self.first, end, self.toggle, self.transfer_id);
        self.first = false;
        self.toggle = !self.toggle;
        Some(CanFrame {
            id: self.id,
            len: (n + 1) as u8,
            data,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dronecan::dsdl::{ESC_STATUS_ID, ESC_STATUS_SIGNATURE, NODE_STATUS_SIGNATURE};

    #[test]
    fn crc_check_value() {
        // CRC-16-CCITT-FALSE of "123456789" is 0x29B1; the signature goes first, low byte first.
        assert_eq!(hwfoc::wire::crc16_ccitt(0xFFFF, b"123456789"), 0x29B1);
        let signature = 0x0102_0304_0506_0708_u64;
        let mut all = signature.to_le_bytes().to_vec();
        all.extend_from_slice(b"abc");
        assert_eq!(
            transfer_crc(signature, b"abc"),
            hwfoc::wire::crc16_ccitt(0xFFFF, &all)
        );
    }

    #[test]
    fn ids() {
        assert_eq!(message_id(16, ESC_STATUS_ID, 100), 0x1004_0A64);
        assert_eq!(message_id(16, 341, 100), 0x1001_5564);
        assert_eq!(message_id(31, 0xFFFF, 127), 0x1FFF_FF7F);
    }

    /// The frames pydronecan 1.0.27 makes of the same esc.Status (node 100, transfer id 5,
    /// priority 16).
    #[test]
    fn esc_status_three_frames_as_pydronecan() {
        let payload = [
            0x07, 0x00, 0x00, 0x00, 0x20, 0x4C, 0x80, 0xC0, 0xE5, 0x5C, 0x2E, 0xFB, 0xDB, 0x8C,
        ];
        assert_eq!(transfer_crc(ESC_STATUS_SIGNATURE, &payload), 0xC75C);
        let f: Vec<CanFrame> = frames(0x1004_0A64, ESC_STATUS_SIGNATURE, 5, &payload).collect();
        assert_eq!(f.len(), 3);
        assert!(f.iter().all(|f| f.id == 0x1004_0A64));
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
    fn single_frame_has_no_crc() {
        let payload = [0x40, 0xE2, 0x01, 0x00, 0x40, 0xCD, 0xAB];
        let f: Vec<CanFrame> = frames(1, NODE_STATUS_SIGNATURE, 31, &payload).collect();
        assert_eq!(f.len(), 1);
        assert_eq!(
            f[0].data(),
            [0x40, 0xE2, 0x01, 0x00, 0x40, 0xCD, 0xAB, 0xDF]
        );
        // An empty payload is one frame of just the tail byte.
        let f: Vec<CanFrame> = frames(1, 0, 0, &[]).collect();
        assert_eq!(f.len(), 1);
        assert_eq!(f[0].data(), [0xC0]);
    }

    #[test]
    fn multi_frame_tails() {
        // 8 bytes: CRC + 5, then 3 + tail. 12 bytes: 7 + 7 (exactly full), no empty frame.
        let f: Vec<CanFrame> = frames(1, 0, 2, &[0; 8]).collect();
        assert_eq!(f.len(), 2);
        assert_eq!(f[0].data()[7], 0x82);
        assert_eq!(f[1].data().len(), 4);
        assert_eq!(f[1].data()[3], 0x62);
        let f: Vec<CanFrame> = frames(1, 0, 31, &[0; 12]).collect();
        assert_eq!(f.len(), 2);
        assert_eq!(f[1].data().len(), 8);
        let f: Vec<CanFrame> = frames(1, 0, 7, &[0; 30]).collect();
        // 32 bytes in 7s: 5 frames, toggles 0 1 0 1 0, start only first, end only last.
        let tails: Vec<u8> = f.iter().map(|f| *f.data().last().unwrap()).collect();
        assert_eq!(tails, [0x87, 0x27, 0x07, 0x27, 0x47]);
        assert_eq!(tail_byte(true, true, false, 33), 0xC1);
    }
}
