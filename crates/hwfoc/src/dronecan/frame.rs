//! A classic CAN frame as a bus adapter reports it: data frames with a 29-bit (DroneCAN) or
//! 11-bit identifier, remote (RTR) frames and error frames, so that the layers above can hand
//! every frame to the receiver and have what is not DroneCAN counted.

use core::fmt;

/// The largest 29-bit (extended) identifier.
pub const MAX_EXTENDED_ID: u32 = 0x1FFF_FFFF;
/// The largest 11-bit (standard) identifier.
pub const MAX_STANDARD_ID: u32 = 0x7FF;

/// The bytes of a frame in pcapng's `LINKTYPE_CAN_SOCKETCAN` layout
/// ([`CanFrame::to_socketcan_record`]).
pub const SOCKETCAN_RECORD_LEN: usize = 16;

/// SocketCAN's flag for an extended identifier in `can_id` (`CAN_EFF_FLAG`).
pub const SOCKETCAN_EFF_FLAG: u32 = 0x8000_0000;
/// SocketCAN's flag for a remote transmission request (`CAN_RTR_FLAG`).
pub const SOCKETCAN_RTR_FLAG: u32 = 0x4000_0000;
/// SocketCAN's flag for an error frame (`CAN_ERR_FLAG`).
pub const SOCKETCAN_ERR_FLAG: u32 = 0x2000_0000;

/// What kind of frame the bus carried.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FrameKind {
    /// A data frame: the only kind DroneCAN sends.
    Data,
    /// A remote transmission request (RTR): an identifier and a length, no data.
    Remote,
    /// An error frame as the adapter reports it (SocketCAN's `CAN_ERR_FLAG`; a bus at the wrong
    /// bit rate gives many): the identifier holds the adapter's error class bits.
    Error,
}

/// A classic CAN frame: identifier (11 or 29 bits), kind, up to 8 data bytes.
///
/// ```
/// use hwfoc::dronecan::{CanFrame, FrameKind};
///
/// let f = CanFrame::extended(0x104E_5201, &[1, 2, 3, 0xC0]).unwrap();
/// assert!(f.is_extended());
/// assert_eq!((f.id(), f.data()), (0x104E_5201, &[1, 2, 3, 0xC0][..]));
/// assert_eq!(f.kind(), FrameKind::Data);
/// assert!(CanFrame::extended(0x2000_0000, &[]).is_none()); // more than 29 bits
/// assert!(CanFrame::extended(1, &[0; 9]).is_none()); // more than 8 bytes
/// ```
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct CanFrame {
    id: u32,
    extended: bool,
    kind: FrameKind,
    len: u8,
    data: [u8; 8],
}

impl CanFrame {
    fn new(id: u32, extended: bool, kind: FrameKind, data: &[u8]) -> Option<CanFrame> {
        let max = if extended {
            MAX_EXTENDED_ID
        } else {
            MAX_STANDARD_ID
        };
        if id > max || data.len() > 8 {
            return None;
        }
        let mut bytes = [0u8; 8];
        bytes[..data.len()].copy_from_slice(data);
        Some(CanFrame {
            id,
            extended,
            kind,
            len: data.len() as u8,
            data: bytes,
        })
    }

    /// A data frame with a 29-bit identifier: what DroneCAN sends. `None` if `id` has more than
    /// 29 bits or `data` more than 8 bytes.
    pub fn extended(id: u32, data: &[u8]) -> Option<CanFrame> {
        CanFrame::new(id, true, FrameKind::Data, data)
    }

    /// A data frame with an 11-bit identifier (not DroneCAN). `None` if `id` has more than 11
    /// bits or `data` more than 8 bytes.
    pub fn standard(id: u32, data: &[u8]) -> Option<CanFrame> {
        CanFrame::new(id, false, FrameKind::Data, data)
    }

    /// A remote frame (RTR) of `len` (at most 8) requested bytes.
    pub fn remote(id: u32, extended: bool, len: u8) -> Option<CanFrame> {
        let mut f = CanFrame::new(id, extended, FrameKind::Remote, &[])?;
        if len > 8 {
            return None;
        }
        f.len = len;
        Some(f)
    }

    /// An error frame as an adapter reports it: `class` the error class bits (SocketCAN's
    /// `can_id` without its flags, at most 29 bits), `data` its details.
    pub fn error(class: u32, data: &[u8]) -> Option<CanFrame> {
        CanFrame::new(class, true, FrameKind::Error, data)
    }

    /// The frame from SocketCAN's `can_id` (identifier and the flags [`SOCKETCAN_EFF_FLAG`],
    /// [`SOCKETCAN_RTR_FLAG`], [`SOCKETCAN_ERR_FLAG`]) and data (for an RTR frame, its length
    /// is the requested length and its bytes are ignored): how `candump` logs and pcapng's
    /// `LINKTYPE_CAN_SOCKETCAN` carry frames. `None` if the data has more than 8 bytes.
    pub fn from_socketcan(can_id: u32, data: &[u8]) -> Option<CanFrame> {
        let extended = can_id & SOCKETCAN_EFF_FLAG != 0;
        if can_id & SOCKETCAN_ERR_FLAG != 0 {
            return CanFrame::error(can_id & MAX_EXTENDED_ID, data);
        }
        let id = can_id
            & if extended {
                MAX_EXTENDED_ID
            } else {
                MAX_STANDARD_ID
            };
        if can_id & SOCKETCAN_RTR_FLAG != 0 {
            return CanFrame::remote(id, extended, u8::try_from(data.len()).ok()?);
        }
        CanFrame::new(id, extended, FrameKind::Data, data)
    }

    /// SocketCAN's `can_id` of the frame: the identifier with its flags.
    pub fn socketcan_id(&self) -> u32 {
        let mut id = self.id;
        if self.extended && self.kind != FrameKind::Error {
            id |= SOCKETCAN_EFF_FLAG;
        }
        match self.kind {
            FrameKind::Data => {}
            FrameKind::Remote => id |= SOCKETCAN_RTR_FLAG,
            FrameKind::Error => id |= SOCKETCAN_ERR_FLAG,
        }
        id
    }

    /// The frame as pcapng's `LINKTYPE_CAN_SOCKETCAN` carries it, SocketCAN's `struct can_frame`
    /// with its identifier in network byte order: `can_id` (4 bytes, big-endian, with its
    /// flags), the data length (1 byte), 3 bytes of zeros (padding and reserved), then 8 data
    /// bytes (zeros past the length). This is also how the layers above hwfoc's codec carry CAN
    /// frames in a stream of bytes: [`SOCKETCAN_RECORD_LEN`] bytes a frame.
    ///
    /// ```
    /// use hwfoc::dronecan::CanFrame;
    ///
    /// let f = CanFrame::extended(0x104E_5201, &[1, 2, 0xC0]).unwrap();
    /// let record = f.to_socketcan_record();
    /// assert_eq!(&record[..8], &[0x90, 0x4E, 0x52, 0x01, 3, 0, 0, 0]);
    /// assert_eq!(CanFrame::from_socketcan_record(&record), Some(f));
    /// ```
    pub fn to_socketcan_record(&self) -> [u8; SOCKETCAN_RECORD_LEN] {
        let mut out = [0u8; SOCKETCAN_RECORD_LEN];
        out[..4].copy_from_slice(&self.socketcan_id().to_be_bytes());
        out[4] = self.len;
        out[8..].copy_from_slice(&self.data);
        if self.kind == FrameKind::Remote {
            out[8..].fill(0);
        }
        out
    }

    /// The frame of a `LINKTYPE_CAN_SOCKETCAN` record ([`CanFrame::to_socketcan_record`]);
    /// `None` where its length byte is over 8 (a CAN FD frame, not read).
    pub fn from_socketcan_record(record: &[u8; SOCKETCAN_RECORD_LEN]) -> Option<CanFrame> {
        let can_id = u32::from_be_bytes([record[0], record[1], record[2], record[3]]);
        let len = usize::from(record[4]);
        if len > 8 {
            return None;
        }
        CanFrame::from_socketcan(can_id, &record[8..8 + len])
    }

    /// The identifier (11 or 29 bits; an error frame's class bits).
    pub const fn id(&self) -> u32 {
        self.id
    }

    /// Whether the identifier has 29 bits.
    pub const fn is_extended(&self) -> bool {
        self.extended
    }

    /// The kind of frame.
    pub const fn kind(&self) -> FrameKind {
        self.kind
    }

    /// The data length code: the number of data bytes (for a remote frame, the requested
    /// length).
    pub const fn len(&self) -> usize {
        self.len as usize
    }

    /// Whether the frame carries no data byte.
    pub const fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The data bytes (none for a remote frame).
    pub fn data(&self) -> &[u8] {
        match self.kind {
            FrameKind::Remote => &[],
            _ => &self.data[..self.len as usize],
        }
    }

    /// Whether the frame can be DroneCAN: a data frame with a 29-bit identifier and at least
    /// one byte (the tail byte).
    pub fn is_dronecan_shaped(&self) -> bool {
        self.kind == FrameKind::Data && self.extended && self.len > 0
    }
}

impl fmt::Debug for CanFrame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "CanFrame({self})")
    }
}

/// `candump`'s compact form: `1C4E5201#0102C0` (an extended id has 8 hex digits, a standard
/// one 3), `123#R` for a remote frame, `20000004#…` for an error frame (its SocketCAN id).
impl fmt::Display for CanFrame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.kind, self.extended) {
            (FrameKind::Error, _) => write!(f, "{:08X}#", self.socketcan_id())?,
            (_, true) => write!(f, "{:08X}#", self.id)?,
            (_, false) => write!(f, "{:03X}#", self.id)?,
        }
        if self.kind == FrameKind::Remote {
            return write!(f, "R{}", self.len);
        }
        for b in self.data() {
            write!(f, "{b:02X}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::format;

    #[test]
    fn socketcan_round_trip() {
        let d = CanFrame::extended(0x1004_0A64, &[1, 2, 0xC5]).unwrap();
        assert_eq!(d.socketcan_id(), 0x9004_0A64);
        assert_eq!(
            CanFrame::from_socketcan(d.socketcan_id(), d.data()),
            Some(d)
        );
        let s = CanFrame::standard(0x123, &[9]).unwrap();
        assert_eq!(s.socketcan_id(), 0x123);
        assert_eq!(CanFrame::from_socketcan(0x123, &[9]), Some(s));
        let r = CanFrame::from_socketcan(0x4000_0123, &[0; 4]).unwrap();
        assert_eq!(
            (r.kind(), r.len(), r.data()),
            (FrameKind::Remote, 4, &[][..])
        );
        assert_eq!(r.socketcan_id(), 0x4000_0123);
        let e = CanFrame::from_socketcan(0x2000_0004, &[0, 4, 0, 0, 0, 0, 0, 0]).unwrap();
        assert_eq!(e.kind(), FrameKind::Error);
        assert_eq!(e.socketcan_id(), 0x2000_0004);
        assert!(!e.is_dronecan_shaped() && !r.is_dronecan_shaped() && !s.is_dronecan_shaped());
        assert!(d.is_dronecan_shaped());
        assert!(!CanFrame::extended(1, &[]).unwrap().is_dronecan_shaped());
        assert_eq!(format!("{d}"), "10040A64#0102C5");
        assert_eq!(format!("{s} {r}"), "123#09 123#R4");
        assert_eq!(format!("{e}"), "20000004#0004000000000000");
        assert!(CanFrame::standard(0x800, &[]).is_none());
        assert!(CanFrame::remote(1, true, 9).is_none());
    }
}
