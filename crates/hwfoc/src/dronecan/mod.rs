//! DroneCAN on a classic CAN bus: the receiving side (frames in, transfers reassembled and
//! decoded, link statistics per node) and the encoders of the same data types (transfers cut
//! into frames), for Hobbywing's CAN ESCs (XRotor X6/X8/X9 and H-series "CAN" versions) and the
//! standard ESC messages other ESCs on the same bus send (`docs/HW5-AND-CAN.md`, "Hobbywing
//! DroneCAN ESCs").
//!
//! The truth is pydronecan (PyPI `dronecan` 1.0.27): its DSDL definitions (field lists, data
//! type ids, signatures) and its transport (`transport.Transfer.to_frames()`/`from_frames()`).
//! `testdata/dronecan/vectors.txt`, written by `scripts/dronecan-vectors.py` with it, is what
//! the tests decode and encode byte for byte.
//!
//! # Transport
//!
//! - **CAN id** (29 bits, [`Header`]): priority (5 bits), then for a message its data type id
//!   (16 bits), a 0 bit and the source node (7 bits); for an anonymous message (node 0) a
//!   14-bit discriminator and a 2-bit data type id; for a service its type id (8 bits), the
//!   request bit, the destination node (7 bits), a 1 bit and the source node.
//! - **Tail byte** ([`TailByte`]), the last byte of every frame: start of transfer, end of
//!   transfer, toggle, 5-bit transfer id.
//! - **Transfers**: up to 7 payload bytes are one frame, without CRC. A longer payload is
//!   preceded by the **transfer CRC**, CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF; the
//!   codec's [`crc16_ccitt`](crate::wire::crc16_ccitt)) computed over the data type signature's
//!   8 bytes little-endian and then the payload, sent little-endian ([`transfer_crc`]). This
//!   is pydronecan's rule: `base_crc = crc16_from_bytes(struct.pack("<Q", signature))`, then
//!   `crc16_from_bytes(payload, initial=base_crc)` in `to_frames()` and `from_frames()`; the
//!   vectors' `crc` lines check it. Frames carry 7 bytes and the tail byte, the last one fewer.
//! - **DSDL** bit packing: little-endian fields, each byte most significant bit first, no
//!   padding between fields, the last byte padded with zeros; a last field that is an array of
//!   elements of 8 bits or more has no length prefix (tail array optimisation: `GetEscID`,
//!   `SetAngle`'s response). float16 as libuavcan/pydronecan convert ([`f16_from_f32`],
//!   [`f32_from_f16`]), saturated to ±65504 (infinities too) as DSDL's default cast.
//!
//! # The data types ([`Kind`], [`Message`])
//!
//! | id | type | length | |
//! |---|---|---|---|
//! | 20050 | `com.hobbywing.esc.StatusMsg1` ([`StatusMsg1`]) | 6 | rpm, pwm, status |
//! | 20051 | `com.hobbywing.esc.StatusMsg2` ([`StatusMsg2`]) | 5 | voltage, current (0.1 V, 0.1 A), temperature |
//! | 20052 | `com.hobbywing.esc.StatusMsg3` ([`StatusMsg3`]) | 3 | MOSFET, capacitor, motor temperatures |
//! | 20013 | `com.hobbywing.esc.GetEscID` ([`GetEscId`]) | 0-3 | `[0]` asks, `[node, channel]` answers |
//! | 341 | `uavcan.protocol.NodeStatus` ([`NodeStatus`]) | 7 | |
//! | 1034 | `uavcan.equipment.esc.Status` ([`EscStatus`]) | 14 | the one multi-frame type |
//! | 1036 | `uavcan.equipment.esc.StatusExtended` ([`EscStatusExtended`]) | 7 | |
//! | 210-217, 241, 242 | Hobbywing's setup services, request and response each ([`SetIdRequest`] ... [`GetMajorConfigResponse`]) | 0-7 | |
//!
//! Signatures: [`Kind::signature`] (pydronecan's `get_data_type_signature()`: the DSDL's
//! `OVERRIDE_SIGNATURE` for Hobbywing's types).
//!
//! # Receiving
//!
//! [`Receiver::push`] takes every frame the bus carried ([`CanFrame`]: data, remote, error,
//! standard or extended) and returns a [`Received`] transfer when one is complete; its rules
//! and its bounds (a fixed number of reassembly slots, [`MAX_PAYLOAD_LEN`], no clock: an
//! explicit [`Receiver::expire`]) are on [`Receiver`]. What happened is counted in
//! [`LinkStats`]: per bus ([`BusStats`]: frames that are not DroneCAN) and per source node
//! ([`NodeStats`]: transfers by type, gaps in transfer ids, toggle and CRC errors, transfers
//! cut short, unknown types...).
//!
//! # Sending
//!
//! [`Message::frames`] (or [`Frames::new`] for any payload): the frames pydronecan's
//! `to_frames()` makes.
//!
//! | module | holds |
//! |---|---|
//! | `frame` | [`CanFrame`], [`FrameKind`], SocketCAN flags |
//! | `id` | [`Header`], [`TransferType`], [`TailByte`], [`IdError`] |
//! | `bits` | DSDL bit packing, float16 ([`f16_from_f32`], [`f32_from_f16`]) |
//! | `kind` | [`Kind`], [`Form`], [`Message`], [`DataType`], [`PayloadError`], [`MAX_PAYLOAD_LEN`] |
//! | `types` | the data types' structs |
//! | `setup_codes` | the codes in Hobbywing's set-up requests (`SetDirectionRequest::QUERY`, ...) |
//! | `transfer` | [`transfer_crc`], [`signature_crc`], [`Frames`] |
//! | `receiver` | [`Receiver`], [`Received`], [`DEFAULT_SLOTS`] |
//! | `stats` | [`LinkStats`], [`BusStats`], [`NodeStats`] |
//! | `escs` | [`Escs`] (which node is which ESC), the records [`HwCanEsc`], [`DroneCanEsc`] |

/// The CAN bit rate Hobbywing's DroneCAN ESCs leave the factory with, bit/s (every one as
/// node 1: `docs/HW5-AND-CAN.md`).
pub const HOBBYWING_BITRATE: u32 = 500_000;

mod bits;
mod description;
mod escs;
mod frame;
mod id;
mod kind;
mod receiver;
mod setup_codes;
mod stats;
mod transfer;
mod types;

pub use bits::{F16_MAX, f16_from_f32, f32_from_f16, saturate_f16};
pub use description::{DRONECAN, HW_CAN};
pub use escs::{DroneCanEsc, Escs, Extended, HwCanEsc, Power, Temperatures};
pub use frame::{
    CanFrame, FrameKind, MAX_EXTENDED_ID, MAX_STANDARD_ID, SOCKETCAN_EFF_FLAG, SOCKETCAN_ERR_FLAG,
    SOCKETCAN_RECORD_LEN, SOCKETCAN_RTR_FLAG,
};
pub use id::{Header, IdError, MAX_NODE_ID, MAX_PRIORITY, TailByte, TransferType};
pub use kind::{DataType, Form, Kind, MAX_PAYLOAD_LEN, Message, PayloadError};
pub use receiver::{BUS_SILENCE_MS, DEFAULT_SLOTS, Received, Receiver};
pub use stats::{BusStats, LinkStats, NODES, NodeStats};
pub use transfer::{FRAME_PAYLOAD, Frames, signature_crc, transfer_crc};
pub use types::{
    EscStatus, EscStatusExtended, GetEscId, GetMaintenanceInformationRequest,
    GetMaintenanceInformationResponse, GetMajorConfigRequest, GetMajorConfigResponse, NodeStatus,
    SelfTestRequest, SelfTestResponse, SetAngleRequest, SetAngleResponse, SetBaudRequest,
    SetBaudResponse, SetDirectionRequest, SetDirectionResponse, SetIdRequest, SetIdResponse,
    SetLedRequest, SetLedResponse, SetReportingFrequencyRequest, SetReportingFrequencyResponse,
    SetThrottleSourceRequest, SetThrottleSourceResponse, StatusMsg1, StatusMsg2, StatusMsg3,
};
