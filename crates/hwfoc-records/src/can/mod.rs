//! CAN frames as records: `candump -l` logs ([`candump`]), the record of a frame that is no
//! classic CAN frame, the names of CAN buses (opening them is `hwfoc-io`'s).
//!
//! Above this module a CAN bus is carried as a stream of bytes like any port's: each frame as
//! the 16 bytes of [`CanFrame::to_socketcan_record`](hwfoc::dronecan::CanFrame::to_socketcan_record)
//! (pcapng's `LINKTYPE_CAN_SOCKETCAN` layout), every one of its bytes with the frame's receive
//! time. A frame that is no classic CAN frame (CAN FD) is [`NOT_CLASSIC_RECORD`], so that the
//! bus's link figures count it.

pub mod candump;

/// The record that stands for a frame that is no classic CAN frame (a CAN FD frame of a
/// `candump` log or a pcapng): a length byte of 255, which no classic frame has, so that a
/// bus's stream counts it (`CanLink::bad_records`) and decodes nothing of it.
pub const NOT_CLASSIC_RECORD: [u8; hwfoc::dronecan::SOCKETCAN_RECORD_LEN] = {
    let mut record = [0u8; hwfoc::dronecan::SOCKETCAN_RECORD_LEN];
    record[4] = 255;
    record
};
/// The CAN bit rate of an `slcan:` bus unless given: 500 kbit/s, the factory rate of
/// Hobbywing's DroneCAN ESCs.
pub const DEFAULT_BITRATE: u32 = 500_000;
/// Whether `spec` names a CAN bus (`slcan:...`, `can:...`) rather than a serial port or a file.
pub fn is_can_spec(spec: &str) -> bool {
    spec.starts_with("slcan:") || spec.starts_with("can:")
}
