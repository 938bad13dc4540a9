//! The data types the codec knows ([`Kind`]: one per message and per half of a service), their
//! ids and signatures as pydronecan 1.0.27 computes them, and the decoded transfer of any of
//! them ([`Message`]).

use core::fmt;

use super::id::{Header, TransferType};
use super::types::*;

/// The longest payload of any known data type, bytes: `uavcan.equipment.esc.Status` (110
/// bits). The reassembly buffers hold this much (plus the transfer CRC); a longer transfer of a
/// known type is counted ([`NodeStats::too_long`](super::NodeStats::too_long)) and dropped.
pub const MAX_PAYLOAD_LEN: usize = 14;

/// Whether a data type is a message or one half of a service.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Form {
    /// A broadcast message.
    Message,
    /// A service request.
    Request,
    /// A service response.
    Response,
}

/// A DSDL data type the codec encodes and decodes.
pub trait DataType: Sized {
    /// Which one.
    const KIND: Kind;
    /// The shortest payload, bytes.
    const MIN_LEN: usize;
    /// The longest payload, bytes (at most [`MAX_PAYLOAD_LEN`]).
    const MAX_LEN: usize;
    /// Serialises into `out` (tail array optimisation applied: DroneCAN on classic CAN);
    /// returns the number of bytes.
    fn encode_into(&self, out: &mut [u8; MAX_PAYLOAD_LEN]) -> usize;
    /// Deserialises a whole transfer's payload. The payload must have exactly the length the
    /// fields take (padded to a byte): a shorter or longer one is an error, as in ArduPilot's
    /// generated decoders (pydronecan ignores extra bytes of a fixed-size type).
    fn decode(payload: &[u8]) -> Result<Self, PayloadError>;
}

/// A payload whose length is not one its data type can have.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PayloadError {
    /// The data type.
    pub kind: Kind,
    /// The payload's length, bytes.
    pub len: usize,
}

impl fmt::Display for PayloadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "a {} payload cannot be {} bytes long ({} to {})",
            self.kind,
            self.len,
            self.kind.min_len(),
            self.kind.max_len()
        )
    }
}

macro_rules! kinds {
    ($(
        $(#[$doc:meta])*
        $v:ident = $form:ident $id:literal $sig:literal $name:literal;
    )*) => {
        /// A known data type, one per message and one per half of a service (request,
        /// response). Messages come first (`Kind::ALL[..Kind::MESSAGES]`).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Kind {
            $( $(#[$doc])* $v, )*
        }

        impl Kind {
            /// How many.
            pub const COUNT: usize = [$(stringify!($v)),*].len();
            /// Every kind, in order (`kind as usize` is its index).
            pub const ALL: [Kind; Kind::COUNT] = [$(Kind::$v),*];

            /// The data type id (a service's for both halves).
            pub const fn data_type_id(self) -> u16 {
                match self { $(Kind::$v => $id,)* }
            }

            /// The data type signature: what seeds a multi-frame transfer's CRC (a service's
            /// for both halves).
            pub const fn signature(self) -> u64 {
                match self { $(Kind::$v => $sig,)* }
            }

            /// Message, request or response.
            pub const fn form(self) -> Form {
                match self { $(Kind::$v => Form::$form,)* }
            }

            /// The DSDL full name (`com.hobbywing.esc.StatusMsg1`; a service's for both
            /// halves).
            pub const fn full_name(self) -> &'static str {
                match self { $(Kind::$v => $name,)* }
            }

            /// The shortest payload, bytes.
            pub const fn min_len(self) -> usize {
                match self { $(Kind::$v => <$v as DataType>::MIN_LEN,)* }
            }

            /// The longest payload, bytes.
            pub const fn max_len(self) -> usize {
                match self { $(Kind::$v => <$v as DataType>::MAX_LEN,)* }
            }
        }

        /// A decoded transfer of any known data type.
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub enum Message {
            $( $(#[$doc])* $v($v), )*
        }

        impl Message {
            /// Its data type.
            pub const fn kind(&self) -> Kind {
                match self { $(Message::$v(_) => Kind::$v,)* }
            }

            /// Serialises into `out`; returns the number of bytes.
            pub fn encode_into(&self, out: &mut [u8; MAX_PAYLOAD_LEN]) -> usize {
                match self { $(Message::$v(m) => m.encode_into(out),)* }
            }

            /// Deserialises a payload of `kind` (see [`DataType::decode`]).
            pub fn decode(kind: Kind, payload: &[u8]) -> Result<Message, PayloadError> {
                match kind { $(Kind::$v => $v::decode(payload).map(Message::$v),)* }
            }
        }

        $(
            impl From<$v> for Message {
                fn from(m: $v) -> Message {
                    Message::$v(m)
                }
            }
        )*
    };
}

kinds! {
    /// `com.hobbywing.esc.StatusMsg1` (20050).
    StatusMsg1 = Message 20050 0x0813_B3E2_C4AD_670E "com.hobbywing.esc.StatusMsg1";
    /// `com.hobbywing.esc.StatusMsg2` (20051).
    StatusMsg2 = Message 20051 0x1675_DA01_C3B9_1297 "com.hobbywing.esc.StatusMsg2";
    /// `com.hobbywing.esc.StatusMsg3` (20052).
    StatusMsg3 = Message 20052 0x2491_9CD1_EB34_ECE9 "com.hobbywing.esc.StatusMsg3";
    /// `com.hobbywing.esc.GetEscID` (20013).
    GetEscId = Message 20013 0x4E2D "com.hobbywing.esc.GetEscID";
    /// `uavcan.protocol.NodeStatus` (341).
    NodeStatus = Message 341 0x0F08_68D0_C1A7_C6F1 "uavcan.protocol.NodeStatus";
    /// `uavcan.equipment.esc.Status` (1034).
    EscStatus = Message 1034 0xA9AF_28AE_A2FB_B254 "uavcan.equipment.esc.Status";
    /// `uavcan.equipment.esc.StatusExtended` (1036).
    EscStatusExtended = Message 1036 0x02DC_203C_5096_0EDC "uavcan.equipment.esc.StatusExtended";
    /// `com.hobbywing.esc.SetID` (210) request.
    SetIdRequest = Request 210 0xC323_CB5E_9EC2_B6F7 "com.hobbywing.esc.SetID";
    /// `com.hobbywing.esc.SetID` (210) response.
    SetIdResponse = Response 210 0xC323_CB5E_9EC2_B6F7 "com.hobbywing.esc.SetID";
    /// `com.hobbywing.esc.SetBaud` (211) request.
    SetBaudRequest = Request 211 0xADA9_8653_B52D_E435 "com.hobbywing.esc.SetBaud";
    /// `com.hobbywing.esc.SetBaud` (211) response.
    SetBaudResponse = Response 211 0xADA9_8653_B52D_E435 "com.hobbywing.esc.SetBaud";
    /// `com.hobbywing.esc.SetLED` (212) request.
    SetLedRequest = Request 212 0xB493_BD48_C085_3EE5 "com.hobbywing.esc.SetLED";
    /// `com.hobbywing.esc.SetLED` (212) response.
    SetLedResponse = Response 212 0xB493_BD48_C085_3EE5 "com.hobbywing.esc.SetLED";
    /// `com.hobbywing.esc.SetDirection` (213) request.
    SetDirectionRequest = Request 213 0x9D79_3111_D262_BA68 "com.hobbywing.esc.SetDirection";
    /// `com.hobbywing.esc.SetDirection` (213) response.
    SetDirectionResponse = Response 213 0x9D79_3111_D262_BA68 "com.hobbywing.esc.SetDirection";
    /// `com.hobbywing.esc.SetReportingFrequency` (214) request.
    SetReportingFrequencyRequest = Request 214 0x1FD0_4044_2098_3DEB "com.hobbywing.esc.SetReportingFrequency";
    /// `com.hobbywing.esc.SetReportingFrequency` (214) response.
    SetReportingFrequencyResponse = Response 214 0x1FD0_4044_2098_3DEB "com.hobbywing.esc.SetReportingFrequency";
    /// `com.hobbywing.esc.SetThrottleSource` (215) request.
    SetThrottleSourceRequest = Request 215 0x0C24_8FAA_EFE5_E29A "com.hobbywing.esc.SetThrottleSource";
    /// `com.hobbywing.esc.SetThrottleSource` (215) response.
    SetThrottleSourceResponse = Response 215 0x0C24_8FAA_EFE5_E29A "com.hobbywing.esc.SetThrottleSource";
    /// `com.hobbywing.esc.SelfTest` (216) request.
    SelfTestRequest = Request 216 0xC48D_4DE6_1C52_95DF "com.hobbywing.esc.SelfTest";
    /// `com.hobbywing.esc.SelfTest` (216) response.
    SelfTestResponse = Response 216 0xC48D_4DE6_1C52_95DF "com.hobbywing.esc.SelfTest";
    /// `com.hobbywing.esc.SetAngle` (217) request.
    SetAngleRequest = Request 217 0x81D9_B107_61C2_8E0A "com.hobbywing.esc.SetAngle";
    /// `com.hobbywing.esc.SetAngle` (217) response.
    SetAngleResponse = Response 217 0x81D9_B107_61C2_8E0A "com.hobbywing.esc.SetAngle";
    /// `com.hobbywing.esc.GetMaintenanceInformation` (241) request.
    GetMaintenanceInformationRequest = Request 241 0xB81D_BD4E_C9A5_977D "com.hobbywing.esc.GetMaintenanceInformation";
    /// `com.hobbywing.esc.GetMaintenanceInformation` (241) response.
    GetMaintenanceInformationResponse = Response 241 0xB81D_BD4E_C9A5_977D "com.hobbywing.esc.GetMaintenanceInformation";
    /// `com.hobbywing.esc.GetMajorConfig` (242) request.
    GetMajorConfigRequest = Request 242 0x1506_774D_A393_0BFD "com.hobbywing.esc.GetMajorConfig";
    /// `com.hobbywing.esc.GetMajorConfig` (242) response.
    GetMajorConfigResponse = Response 242 0x1506_774D_A393_0BFD "com.hobbywing.esc.GetMajorConfig";
}

impl Kind {
    /// How many kinds are messages: `Kind::ALL[..MESSAGES]`.
    pub const MESSAGES: usize = 7;

    /// The kind of a transfer with `header`, if known (an anonymous message never is).
    pub fn of(header: &Header) -> Option<Kind> {
        let form = match header.transfer {
            TransferType::Message => Form::Message,
            TransferType::Request { .. } => Form::Request,
            TransferType::Response { .. } => Form::Response,
            TransferType::Anonymous { .. } => return None,
        };
        Kind::ALL
            .into_iter()
            .find(|k| k.form() == form && k.data_type_id() == header.data_type_id)
    }

    /// The index of a message kind among messages (`None` for a service's half).
    pub const fn message_index(self) -> Option<usize> {
        let i = self as usize;
        if i < Kind::MESSAGES { Some(i) } else { None }
    }
}

/// The full name, and `request`/`response` after a service's.
impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.full_name())?;
        match self.form() {
            Form::Message => Ok(()),
            Form::Request => f.write_str(" request"),
            Form::Response => f.write_str(" response"),
        }
    }
}

// Messages first, and the buffers large enough for every kind.
const _: () = {
    let mut i = 0;
    let mut longest = 0;
    while i < Kind::COUNT {
        let k = Kind::ALL[i];
        assert!(k as usize == i);
        assert!(matches!(k.form(), Form::Message) == (i < Kind::MESSAGES));
        assert!(k.min_len() <= k.max_len());
        if k.max_len() > longest {
            longest = k.max_len();
        }
        i += 1;
    }
    assert!(longest == MAX_PAYLOAD_LEN);
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_by_header() {
        for k in Kind::ALL {
            let h = match k.form() {
                Form::Message => Header::message(16, k.data_type_id(), 5),
                Form::Request => Header::request(16, k.data_type_id() as u8, 5, 9),
                Form::Response => Header::response(16, k.data_type_id() as u8, 5, 9),
            };
            assert_eq!(Kind::of(&h), Some(k));
        }
        assert_eq!(Kind::of(&Header::message(16, 20100, 5)), None);
        assert_eq!(Kind::of(&Header::request(16, 20, 5, 9)), None);
        // a message id that is a service's (and the reverse) is not known
        assert_eq!(Kind::of(&Header::message(16, 210, 5)), None);
        assert_eq!(Kind::of(&Header::request(16, 341u16 as u8, 5, 9)), None);
    }

    #[test]
    fn lengths() {
        let lens: [(usize, usize); Kind::COUNT] = Kind::ALL.map(|k| (k.min_len(), k.max_len()));
        assert_eq!(
            lens,
            [
                (6, 6),
                (5, 5),
                (3, 3),
                (0, 3),
                (7, 7),
                (14, 14),
                (7, 7),
                (2, 2),
                (2, 2),
                (1, 1),
                (0, 0),
                (3, 3),
                (3, 3),
                (1, 1),
                (1, 1),
                (4, 4),
                (4, 4),
                (1, 1),
                (1, 1),
                (0, 0),
                (1, 1),
                (3, 3),
                (1, 5),
                (1, 1),
                (7, 7),
                (1, 1),
                (7, 7),
            ]
        );
    }
}
