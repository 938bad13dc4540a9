//! The HW-FOC data frame a DataLink hub would have sent for an ESC of any format: what the
//! DataLink output carries.
//!
//! An HW-FOC frame (or a DataLink record) is carried exactly as received. A frame of another
//! format (Hobbywing V4, V3, HW5, `hw-can` and `dronecan` records from a CAN bus) is read
//! through the protocol-neutral [`Telemetry`] and each value written back as the HW-FOC field's
//! nearest raw value, saturated to the field's range, through the inverse of the conversion
//! hwfoc reads that field with ([`Linear::raw_of`], [`Temperature::adc_of`]), under the ESC's
//! settings:
//!
//! | field | from | when the format does not carry it |
//! |---|---|---|
//! | packet | the record's own counter, low 16 bits (V4, V3) | a counter per ESC of the output (HW5, CAN) |
//! | throttle in, out | % x 1024 / 100, 0..=1024 | 0 |
//! | eRPM | eRPM / 10; where only `rpm` is sent (CAN), `rpm` x pole pairs x gear ratio / 10; magnitude (the field has no sign) | 0 |
//! | voltage | V x 10 | 0 |
//! | current, phase current | A x current scale | 0 |
//! | MOS, capacitor temperature | the ADC table's nearest code, 33..=241 (129..0 degC) | [`ADC_NO_VALUE`] (255: no degC) |
//! | status | HW5: its faults' HW-FOC bits ([`FaultCode::hwfoc_status`](hwfoc::hw5::FaultCode::hwfoc_status)) | 0 (no fault) |
//!
//! The CAN protocols' `rpm` is used as sent: whether an ESC sends mechanical or electrical RPM is
//! not documented, and hwfoc's `rpm` of an HW-FOC frame is `eRPM / (pole pairs x gear ratio)`,
//! so this is its inverse. Only HW-FOC frames have HW-FOC status bits: HW5's faults are mapped
//! to the HW-FOC bit of the same fault where one clearly is, the others (and every other
//! format's flags) are sent as 0.

use hwfoc::foc::DataFrame;
use hwfoc::telemetry::{Data, Telemetry};
use hwfoc::units::{ADC_NO_VALUE, Linear};
use hwfoc::{Quantity, Settings, Temperature};

/// The largest raw throttle of an HW-FOC frame (100 %).
const THROTTLE_MAX: u16 = 1024;

/// The HW-FOC frame a hub would send for `data` (see the module documentation); `packet` is the
/// output's own counter of this ESC, used where the format has none.
pub fn hub_record(data: &Data, settings: &Settings, packet: u16) -> DataFrame {
    if let Some(frame) = data.to_hwfoc() {
        return frame;
    }
    let value = |q: Quantity| data.value(q, settings);
    // `as` saturates a float to the integer's range (NaN to 0).
    let raw_u16 = |q: Quantity, linear: Linear| value(q).map_or(0, |v| linear.raw_of(v) as u16);
    let raw_i16 = |q: Quantity, linear: Linear| value(q).map_or(0, |v| linear.raw_of(v) as i16);
    let throttle = |q: Quantity| raw_u16(q, Linear::THROTTLE_PCT).min(THROTTLE_MAX);
    let erpm_raw = match (value(Quantity::Erpm), value(Quantity::Rpm)) {
        (Some(erpm), _) => Linear::ERPM.raw_of(erpm.abs()) as u16,
        (None, Some(rpm)) => settings.rpm_linear().raw_of(rpm.abs()) as u16,
        (None, None) => 0,
    };
    let adc = |q: Quantity| value(q).map_or(ADC_NO_VALUE, Temperature::adc_of);
    let amps = settings.amps_linear();
    let status = data.hwfoc_status();
    DataFrame {
        packet: data.packet().map_or(packet, |p| p as u16),
        throttle_in_raw: throttle(Quantity::ThrottleIn),
        throttle_out_raw: throttle(Quantity::ThrottleOut),
        erpm_raw,
        voltage_raw: raw_u16(Quantity::Voltage, Linear::VOLTS),
        current_raw: raw_i16(Quantity::Current, amps),
        phase_current_raw: raw_i16(Quantity::PhaseCurrent, amps),
        mos_adc: adc(Quantity::MosTemp),
        cap_adc: adc(Quantity::CapTemp),
        status,
    }
}
