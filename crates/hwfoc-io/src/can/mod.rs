//! CAN frames in and out: SLCAN adapters' ASCII protocol ([`slcan`]), `candump -l` logs
//! ([`candump`]).
//!
//! Above this module a CAN bus is carried as a stream of bytes like any port's: each frame as
//! the 16 bytes of [`CanFrame::to_socketcan_record`](hwfoc::dronecan::CanFrame::to_socketcan_record)
//! (pcapng's `LINKTYPE_CAN_SOCKETCAN` layout), every one of its bytes with the frame's receive
//! time.

pub mod candump;
pub mod slcan;
