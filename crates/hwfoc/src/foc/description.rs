//! What HW-FOC says of itself ([`DESCRIPTION`]).

use core::time::Duration;

use crate::format::{
    Check, DeviceInfo, FormatDescription, InfoValue, LinkKind, MAX_INFO_FIELDS, Quantities, padded,
};
use crate::status::Status;
use crate::telemetry::{Conversion, Reading, Telemetry};
use crate::units::{Linear, Quantity, Quantity as Q, Settings};
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
fn info_values(info: &super::InfoFrame) -> [InfoValue<'_>; 4] {
    [info.product(), info.hardware(), info.firmware(), info.id()].map(InfoValue::Text)
}

impl DeviceInfo for super::InfoFrame {
    fn values(&self) -> [Option<InfoValue<'_>>; MAX_INFO_FIELDS] {
        padded(info_values(self))
    }

    fn product(&self) -> &str {
        super::InfoFrame::product(self)
    }

    fn hardware(&self) -> &str {
        super::InfoFrame::hardware(self)
    }

    fn firmware(&self) -> &str {
        super::InfoFrame::firmware(self)
    }

    fn id(&self) -> &str {
        super::InfoFrame::id(self)
    }
}

impl Telemetry for super::DataFrame {
    #[inline(always)]
    fn packet(&self) -> Option<u32> {
        Some(u32::from(self.packet))
    }

    #[inline(always)]
    fn status(&self) -> Option<Status> {
        Some(self.status)
    }

    fn hwfoc_status(&self) -> Status {
        self.status
    }

    #[inline(always)]
    fn reading(&self, quantity: Quantity, settings: &Settings) -> Option<Reading> {
        let linear = Reading::linear;
        let adc = |code: u8| Reading {
            raw: i32::from(code),
            conversion: Conversion::AdcTable,
        };
        Some(match quantity {
            Quantity::ThrottleIn => linear(self.throttle_in_raw.into(), Linear::THROTTLE_PCT),
            Quantity::ThrottleOut => linear(self.throttle_out_raw.into(), Linear::THROTTLE_PCT),
            Quantity::Erpm => linear(self.erpm_raw.into(), Linear::ERPM),
            Quantity::Rpm => linear(self.erpm_raw.into(), settings.rpm_linear()),
            Quantity::Voltage => linear(self.voltage_raw.into(), Linear::VOLTS),
            Quantity::Current => linear(self.current_raw.into(), settings.amps_linear()),
            Quantity::PhaseCurrent => linear(self.phase_current_raw.into(), settings.amps_linear()),
            Quantity::MosTemp => adc(self.mos_adc),
            Quantity::CapTemp => adc(self.cap_adc),
            Quantity::MotorTemp
            | Quantity::BecTemp
            | Quantity::BecVoltage
            | Quantity::BecCurrent => return None,
        })
    }
}
