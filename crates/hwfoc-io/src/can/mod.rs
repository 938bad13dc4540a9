//! CAN frames in and out: SLCAN adapters' ASCII protocol ([`slcan`]), `candump -l` logs
//! ([`candump`]), live buses ([`CanBus`]: an SLCAN adapter or a SocketCAN interface) and the
//! rule of asking the ESCs on a bus for their ids ([`AskIds`]), and setting the ESCs up
//! ([`setup`]).
//!
//! Above this module a CAN bus is carried as a stream of bytes like any port's: each frame as
//! the 16 bytes of [`CanFrame::to_socketcan_record`](hwfoc::dronecan::CanFrame::to_socketcan_record)
//! (pcapng's `LINKTYPE_CAN_SOCKETCAN` layout), every one of its bytes with the frame's receive
//! time. A frame that is no classic CAN frame (CAN FD) is [`NOT_CLASSIC_RECORD`], so that the
//! bus's link figures count it.

mod ask;
mod bus;
pub use hwfoc_records::can::candump;
pub mod setup;
pub mod slcan;
#[cfg(target_os = "linux")]
mod socketcan;

pub use ask::{ASK_EVERY, ASK_PRIORITY, AskIds, DEFAULT_SOURCE_NODE};

pub use bus::{CanBus, CanError, CanSpec, DEFAULT_BITRATE, SLCAN_BAUD, is_can_spec};
pub use hwfoc_records::can::NOT_CLASSIC_RECORD;
