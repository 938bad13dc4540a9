//! What the two CAN formats say of themselves ([`HW_CAN`], [`DRONECAN`]).

use crate::format::{Check, FormatDescription, LinkKind, Quantities};
use crate::units::Quantity as Q;

/// Hobbywing's DroneCAN ESCs: `com.hobbywing.esc.StatusMsg1/2/3` on a bus at
/// [`HOBBYWING_BITRATE`](super::HOBBYWING_BITRATE); frames always come timed; no counter (a
/// transfer id is the transport's), no fault bits.
pub const HW_CAN: FormatDescription = FormatDescription {
    name: "hw-can",
    title: "Hobbywing DroneCAN",
    baud_rate: super::HOBBYWING_BITRATE,
    link: LinkKind::Bus,
    data_frame_len: super::SOCKETCAN_RECORD_LEN,
    counter_bits: None,
    check: Check::CanTransfer,
    frame_period: None,
    idle_frame_period: None,
    carries: Quantities::of(&[
        Q::ThrottleOut,
        Q::Rpm,
        Q::Voltage,
        Q::Current,
        Q::MosTemp,
        Q::CapTemp,
        Q::MotorTemp,
    ]),
    faults: &[],
    adopted_info: None,
    info_keys: &[],
    settings: &[],
};

/// Standard DroneCAN ESCs: `uavcan.equipment.esc.Status` and `StatusExtended`.
pub const DRONECAN: FormatDescription = FormatDescription {
    name: "dronecan",
    title: "DroneCAN ESC",
    carries: Quantities::of(&[
        Q::ThrottleIn,
        Q::ThrottleOut,
        Q::Rpm,
        Q::Voltage,
        Q::Current,
        Q::MosTemp,
        Q::MotorTemp,
    ]),
    ..HW_CAN
};
