//! CAN frames in and out: SLCAN adapters' ASCII protocol ([`slcan`]), `candump -l` logs
//! ([`candump`]), live buses ([`CanBus`]: an SLCAN adapter or a SocketCAN interface) and the
//! rule of asking the ESCs on a bus for their ids ([`AskIds`]) (`hwfoc-ports`' and
//! `hwfoc-records`'). Setting Hobbywing's ESCs up is the `hwfoc-can-setup` crate's.
//!
//! Above this module a CAN bus is carried as a stream of bytes like any port's: each frame as
//! the 16 bytes of [`CanFrame::to_socketcan_record`](hwfoc::dronecan::CanFrame::to_socketcan_record)
//! (pcapng's `LINKTYPE_CAN_SOCKETCAN` layout), every one of its bytes with the frame's receive
//! time. A frame that is no classic CAN frame (CAN FD) is [`NOT_CLASSIC_RECORD`], so that the
//! bus's link figures count it.

pub use hwfoc_ports::can::*;
