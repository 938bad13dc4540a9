//! What Hobbywing V3 says of itself ([`DESCRIPTION`]).

use core::time::Duration;

use crate::format::{Check, FormatDescription, LinkKind, Quantities};
use crate::units::Quantity as Q;

/// Hobbywing V3: 10-byte frames without checksum every 19.5 ms from one ESC, a 24-bit counter,
/// throttles and RPM only; no faults, no device information, no settings.
pub const DESCRIPTION: FormatDescription = FormatDescription {
    name: "hw-v3",
    title: "Hobbywing V3",
    baud_rate: super::BAUD_RATE,
    link: LinkKind::OneEsc,
    data_frame_len: super::FRAME_LEN,
    counter_bits: Some(24),
    check: Check::None,
    frame_period: Some(Duration::from_micros(19_500)),
    idle_frame_period: None,
    carries: Quantities::of(&[Q::ThrottleIn, Q::ThrottleOut, Q::Erpm, Q::Rpm]),
    faults: &[],
    adopted_info: None,
    info_keys: &[],
    settings: &[],
};
