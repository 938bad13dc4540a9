//! What Hobbywing V4 says of itself ([`DESCRIPTION`]).

use core::time::Duration;

use crate::format::{
    Check, DeviceInfo, FormatDescription, InfoValue, LinkKind, MAX_INFO_FIELDS, Quantities,
    SettingDescription, padded,
};
use crate::units::{Quantity as Q, Settings};

use super::info::{InfoFrame, VOLTS_PER_STEP_FORM, VoltsPerStep};

/// Hobbywing V4: data and info frames without checksum every 51 ms from one ESC, a 24-bit
/// counter, no fault bits; its info frame's eight constants; one setting, the volts per voltage
/// step until an info frame is adopted.
pub const DESCRIPTION: FormatDescription = FormatDescription {
    name: "hw-v4",
    title: "Hobbywing V4",
    baud_rate: super::BAUD_RATE,
    link: LinkKind::OneEsc,
    data_frame_len: super::DATA_FRAME_LEN,
    counter_bits: Some(24),
    check: Check::None,
    frame_period: Some(Duration::from_millis(51)),
    idle_frame_period: None,
    carries: Quantities::all_but(&[
        Q::PhaseCurrent,
        Q::MotorTemp,
        Q::BecTemp,
        Q::BecVoltage,
        Q::BecCurrent,
    ]),
    faults: &[],
    adopted_info: Some("v4_info"),
    info_keys: &["full_scale", "v1", "v2", "i1", "i2", "i3", "t1", "t2"],
    settings: &[SettingDescription {
        key: "v4_volts_per_step",
        form: "N/D, low or hv",
        default: "8/910",
        help: "volts per voltage ADC step of a V4 ESC until its info frame is adopted: 8/910 \
               (low) for low-voltage models, 11/650 (hv) for HV models",
        apply: set_volts_per_step,
    }],
};

/// The values of an info frame's constants, in the order of [`DESCRIPTION`]'s `info_keys`.
fn info_values(i: &InfoFrame) -> [InfoValue<'static>; 8] {
    [
        i.full_scale,
        i.v1.into(),
        i.v2.into(),
        i.i1.into(),
        i.i2.into(),
        i.i3.into(),
        i.t1.into(),
        i.t2.into(),
    ]
    .map(|v: u16| InfoValue::Number(v.into()))
}

impl DeviceInfo for InfoFrame {
    fn values(&self) -> [Option<InfoValue<'_>>; MAX_INFO_FIELDS] {
        padded(info_values(self))
    }
}

/// The setting `v4_volts_per_step` from its text.
fn set_volts_per_step(settings: &mut Settings, text: &str) -> Result<(), &'static str> {
    settings.v4_volts_per_step = text
        .parse::<VoltsPerStep>()
        .map_err(|_| VOLTS_PER_STEP_FORM)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_setting_default_is_the_settings_default() {
        let mut s = Settings::default();
        let setting = &DESCRIPTION.settings[0];
        (setting.apply)(&mut s, "hv").unwrap();
        (setting.apply)(&mut s, setting.default).unwrap();
        assert_eq!(s, Settings::DEFAULT);
    }
}
