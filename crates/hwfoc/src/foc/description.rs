//! What HW-FOC says of itself ([`DESCRIPTION`]).

use core::time::Duration;

use crate::format::{Check, FormatDescription, InfoValue, LinkKind, Quantities};
use crate::units::Quantity as Q;
use crate::wire::Checksum;

/// HW-FOC: an ESC's own wire at 19200 baud, a 16-bit packet counter, frames checked by a 16-bit
/// sum, a data frame every 50 ms, sixteen status bits ([`crate::status::FAULTS`]), and an
/// information frame of four words.
pub const DESCRIPTION: FormatDescription = FormatDescription {
    name: "hw-foc",
    title: "HW-FOC",
    baud_rate: super::BAUD_RATE,
    link: LinkKind::OneEsc,
    data_frame_len: super::kinds::data::DATA_FRAME_LEN,
    counter_bits: Some(16),
    check: Check::Checksum(Checksum::Sum16Le),
    frame_period: Some(Duration::from_millis(50)),
    idle_frame_period: None,
    carries: Quantities::all_but(&[Q::MotorTemp, Q::BecTemp, Q::BecVoltage, Q::BecCurrent]),
    faults: &crate::status::FAULTS,
    adopted_info: None,
    info_keys: &["product", "hardware", "firmware", "id"],
    settings: &[],
};

/// The values of an information frame's fields, in the order of [`DESCRIPTION`]'s `info_keys`.
pub(crate) fn info_values(info: &super::InfoFrame) -> [InfoValue<'_>; 4] {
    [info.product(), info.hardware(), info.firmware(), info.id()].map(InfoValue::Text)
}
