//! The DroneCAN fields of a 29-bit CAN identifier ([`Header`]) and of a frame's tail byte
//! ([`TailByte`]) (DroneCAN specification, "CAN bus transport layer"; pydronecan's
//! `transport.Transfer.message_id`).
//!
//! ```text
//!  bits      28..24    23..8                       7   6..0
//!  message   priority  data type id (16)           0   source node (1..=127)
//!  anonymous priority  discriminator (14) | dtid(2) 0   0
//!  service   priority  type id (8) | request (1) | destination (7)   1   source node
//! ```

use core::fmt;

/// The highest (least urgent) priority, 5 bits: 0 is the most urgent.
pub const MAX_PRIORITY: u8 = 31;
/// The highest node id; 0 is no node (anonymous).
pub const MAX_NODE_ID: u8 = 127;

/// How a transfer is addressed: a broadcast message, an anonymous message, or one half of a
/// service call.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TransferType {
    /// A message broadcast by a node (source node 1..=127).
    Message,
    /// A message from a node without an id (source node 0): single-frame only, 2 bits of data
    /// type id and a 14-bit discriminator (dynamic node id allocation).
    Anonymous {
        /// The discriminator, 14 bits (the sender's random value).
        discriminator: u16,
    },
    /// A service request to `destination`.
    Request {
        /// The node the request is for, 1..=127.
        destination: u8,
    },
    /// A service response to `destination` (the node that asked).
    Response {
        /// The node the response is for, 1..=127.
        destination: u8,
    },
}

impl TransferType {
    /// Whether this is a service request or response.
    pub const fn is_service(&self) -> bool {
        matches!(
            self,
            TransferType::Request { .. } | TransferType::Response { .. }
        )
    }

    /// The destination node of a service transfer (`None` for messages).
    pub const fn destination(&self) -> Option<u8> {
        match *self {
            TransferType::Request { destination } | TransferType::Response { destination } => {
                Some(destination)
            }
            _ => None,
        }
    }
}

/// The DroneCAN fields of a CAN identifier.
///
/// ```
/// use hwfoc::dronecan::{Header, TransferType};
///
/// // StatusMsg1 (20050) from node 1 at priority 16.
/// let h = Header::message(16, 20050, 1);
/// assert_eq!(h.can_id(), 0x104E_5201);
/// assert_eq!(Header::parse(0x104E_5201), Ok(h));
/// // A SetID request (210) from node 10 to node 1.
/// let h = Header::parse(0x1ED2_818A).unwrap();
/// assert_eq!((h.data_type_id, h.source_node), (210, 10));
/// assert_eq!(h.transfer, TransferType::Request { destination: 1 });
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Header {
    /// Priority, 0 (most urgent) to 31.
    pub priority: u8,
    /// Data type id: 16 bits for a message, 8 for a service, 2 for an anonymous message.
    pub data_type_id: u16,
    /// The sending node, 1..=127 (0 for an anonymous message).
    pub source_node: u8,
    /// Message, anonymous message, request or response.
    pub transfer: TransferType,
}

/// Why a 29-bit identifier is not a DroneCAN one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum IdError {
    /// More than 29 bits.
    TooWide,
    /// A service transfer from node 0 (services need a node id).
    AnonymousService,
    /// A service transfer to node 0.
    NoDestination,
}

impl fmt::Display for IdError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            IdError::TooWide => "CAN identifier wider than 29 bits",
            IdError::AnonymousService => "service transfer from node 0",
            IdError::NoDestination => "service transfer to node 0",
        })
    }
}

impl Header {
    /// A message broadcast by `source_node`.
    pub const fn message(priority: u8, data_type_id: u16, source_node: u8) -> Header {
        Header {
            priority,
            data_type_id,
            source_node,
            transfer: TransferType::Message,
        }
    }

    /// A service request from `source_node` to `destination`.
    pub const fn request(
        priority: u8,
        data_type_id: u8,
        source_node: u8,
        destination: u8,
    ) -> Header {
        Header {
            priority,
            data_type_id: data_type_id as u16,
            source_node,
            transfer: TransferType::Request { destination },
        }
    }

    /// A service response from `source_node` to `destination`.
    pub const fn response(
        priority: u8,
        data_type_id: u8,
        source_node: u8,
        destination: u8,
    ) -> Header {
        Header {
            priority,
            data_type_id: data_type_id as u16,
            source_node,
            transfer: TransferType::Response { destination },
        }
    }

    /// The fields of a 29-bit CAN identifier.
    pub const fn parse(id: u32) -> Result<Header, IdError> {
        if id > super::frame::MAX_EXTENDED_ID {
            return Err(IdError::TooWide);
        }
        let priority = ((id >> 24) & 0x1F) as u8;
        let source_node = (id & 0x7F) as u8;
        if id & 0x80 != 0 {
            let destination = ((id >> 8) & 0x7F) as u8;
            if source_node == 0 {
                return Err(IdError::AnonymousService);
            }
            if destination == 0 {
                return Err(IdError::NoDestination);
            }
            let data_type_id = ((id >> 16) & 0xFF) as u16;
            let transfer = if id & 0x8000 != 0 {
                TransferType::Request { destination }
            } else {
                TransferType::Response { destination }
            };
            return Ok(Header {
                priority,
                data_type_id,
                source_node,
                transfer,
            });
        }
        if source_node == 0 {
            return Ok(Header {
                priority,
                data_type_id: ((id >> 8) & 0x3) as u16,
                source_node,
                transfer: TransferType::Anonymous {
                    discriminator: ((id >> 10) & 0x3FFF) as u16,
                },
            });
        }
        Ok(Header {
            priority,
            data_type_id: ((id >> 8) & 0xFFFF) as u16,
            source_node,
            transfer: TransferType::Message,
        })
    }

    /// The 29-bit CAN identifier. Fields wider than their bits are cut to them (priority 5
    /// bits, node ids 7, a service's type id 8, an anonymous message's type id 2 and
    /// discriminator 14).
    pub const fn can_id(&self) -> u32 {
        let common = ((self.priority as u32 & 0x1F) << 24) | (self.source_node as u32 & 0x7F);
        match self.transfer {
            TransferType::Message => common | ((self.data_type_id as u32) << 8),
            TransferType::Anonymous { discriminator } => {
                common
                    | ((discriminator as u32 & 0x3FFF) << 10)
                    | ((self.data_type_id as u32 & 0x3) << 8)
            }
            TransferType::Request { destination } | TransferType::Response { destination } => {
                let request = matches!(self.transfer, TransferType::Request { .. }) as u32;
                common
                    | 0x80
                    | ((self.data_type_id as u32 & 0xFF) << 16)
                    | (request << 15)
                    | ((destination as u32 & 0x7F) << 8)
            }
        }
    }
}

/// The last byte of every DroneCAN frame.
///
/// ```
/// use hwfoc::dronecan::TailByte;
/// let t = TailByte::from_byte(0x85);
/// assert_eq!((t.start, t.end, t.toggle, t.transfer_id), (true, false, false, 5));
/// assert_eq!(t.byte(), 0x85);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TailByte {
    /// Start of transfer (bit 7): the first frame.
    pub start: bool,
    /// End of transfer (bit 6): the last frame.
    pub end: bool,
    /// Toggle (bit 5): 0 in the first frame, alternating.
    pub toggle: bool,
    /// Transfer id (bits 4..0): +1 per transfer of a data type from a node, wrapping 31 to 0.
    pub transfer_id: u8,
}

impl TailByte {
    /// The fields of a tail byte.
    pub const fn from_byte(b: u8) -> TailByte {
        TailByte {
            start: b & 0x80 != 0,
            end: b & 0x40 != 0,
            toggle: b & 0x20 != 0,
            transfer_id: b & 0x1F,
        }
    }

    /// The byte (the transfer id cut to 5 bits).
    pub const fn byte(&self) -> u8 {
        ((self.start as u8) << 7)
            | ((self.end as u8) << 6)
            | ((self.toggle as u8) << 5)
            | (self.transfer_id & 0x1F)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_as_pydronecan() {
        // From testdata/dronecan/vectors.txt: GetMajorConfig response from 127 to 1 at
        // priority 0; esc.Status from node 1 at 30; SelfTest request 2 -> 7.
        let h = Header::parse(0x00F2_01FF).unwrap();
        assert_eq!(h, Header::response(0, 242, 127, 1));
        assert_eq!(Header::parse(0x1E04_0A01), Ok(Header::message(30, 1034, 1)));
        let h = Header::request(0, 216, 2, 7);
        assert_eq!(h.can_id(), 0x00D8_8782);
        assert_eq!(Header::parse(0x00D8_8782), Ok(h));
        assert_eq!(h.transfer.destination(), Some(7));
        assert!(h.transfer.is_service());
        let a = Header::parse(0x1000_0100 | (0x1234 << 10)).unwrap();
        assert_eq!(a.data_type_id, 1);
        assert_eq!(a.source_node, 0);
        assert_eq!(
            a.transfer,
            TransferType::Anonymous {
                discriminator: 0x1234 & 0x3FFF
            }
        );
        assert_eq!(Header::parse(a.can_id()), Ok(a));
        assert_eq!(Header::parse(0x0000_8180), Err(IdError::AnonymousService));
        assert_eq!(Header::parse(0x0000_8081), Err(IdError::NoDestination));
        assert_eq!(Header::parse(0x2000_0000), Err(IdError::TooWide));
    }

    #[test]
    fn every_id_round_trips() {
        let mut id = 0u32;
        while id <= super::super::frame::MAX_EXTENDED_ID {
            if let Ok(h) = Header::parse(id) {
                assert_eq!(h.can_id(), id, "{id:08X}");
            }
            id += 0x3F1; // a prime-ish stride through every bit pattern's neighbourhood
        }
        for b in 0..=255u8 {
            assert_eq!(TailByte::from_byte(b).byte(), b);
        }
    }
}
