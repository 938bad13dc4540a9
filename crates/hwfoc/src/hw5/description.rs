//! What HW5 says of itself ([`DESCRIPTION`]).

use crate::format::{Check, FormatDescription, LinkKind, Quantities};
use crate::units::Quantity as Q;
use crate::wire::Checksum;

/// HW5: one ESC at 115200 baud, frames checked by a CRC-16/MODBUS, no counter, a telemetry
/// frame every 20 ms running and 400 ms idle, eight fault bits ([`FAULTS`](super::FAULTS)), no
/// device information.
pub const DESCRIPTION: FormatDescription = FormatDescription {
    name: "hw5",
    title: "HW5",
    baud_rate: super::BAUD_RATE,
    link: LinkKind::OneEsc,
    data_frame_len: super::TELEMETRY_LEN,
    counter_bits: None,
    check: Check::Checksum(Checksum::Crc16Modbus),
    frame_period: Some(super::FRAME_PERIOD_RUNNING),
    idle_frame_period: Some(super::FRAME_PERIOD_IDLE),
    carries: Quantities::all_but(&[Q::ThrottleOut, Q::PhaseCurrent, Q::CapTemp]),
    faults: &super::FAULTS,
    adopted_info: None,
    info_keys: &[],
    settings: &[],
};
