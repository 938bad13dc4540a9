//! The protocols a virtual ESC can speak besides HW-FOC: Platinum V4 (`hw-v4`), Platinum V3
//! (`hw-v3`) and HW5 (`hw5`), their frames made from the model's measurements ([`Measured`])
//! and their schedules' constants (the schedules themselves are in [`crate::esc`]).
//!
//! What each sends (`docs/OLDER-PROTOCOLS.md`, `docs/HW5-AND-CAN.md`):
//!
//! - **V4**, 19200 baud: running ("fast" mode), a 19-byte data frame every 51 ms; idle ("slow"
//!   mode), 20-byte data frames (trailing `B9`) and 13-byte info frames alternating 200 ms apart.
//!   Fast mode starts with the first frame whose input throttle is above 0 (the ESC looks every
//!   51 ms); slow mode resumes 1.5 s after the motor stopped and the throttle went to 0. The
//!   counter goes up by one per data frame (24 bits), from `--start-packet` or 0. The info frame
//!   is [`v4_info`]: full scale 1000, the capture's 8/910 V per step (11/650, an HV model's, for
//!   a pack that could exceed 36 V: more than 8 cells), a current sensor of 0.05 A per step
//!   (I1 = 1, I2 = 20, I3 = 0: up to 204.75 A, as a 120 A model's headroom needs), T1 = T2 =
//!   `0x21` as captured. Throttle and PWM in 1000ths, eRPM as measured, voltage and current ADC
//!   through those constants, temperatures through the inverse of the NTC conversion
//!   ([`ntc_adc`]); the second temperature (the capacitors') is 0 (no reading) in slow mode, as
//!   captured.
//! - **V3**, 19200 baud: a 10-byte frame every 19.5 ms whatever the motor does; the counter from
//!   `--start-packet` or 0 (24 bits); throttle and PWM in 255ths; the period of one electrical
//!   revolution, `60 000 000 / eRPM` us, or the start-up placeholder 35314 while the motor is
//!   stopped (and for speeds too slow for 16 bits).
//! - **HW5**, 115200 baud: a 32-byte telemetry frame every 20 ms while the motor turns, every
//!   400 ms idle (the ESC looks every 20 ms). Throttle in percent, eRPM / 10, voltage and current
//!   in tenths (current not below 0, and while the throttle is 0 the last reading repeated until
//!   the motor has stopped, as the ESC does), ESC temperature (the MOSFETs'), BEC temperature
//!   (ambient plus a third of the MOSFETs' rise plus 3 degC: the model has no BEC), motor
//!   temperature (ambient plus 0.8 of the MOSFETs' rise: nor a winding), BEC 8.4 V at about
//!   0.8 A, and the fault byte from the status bits ([`hw5_fault`]).
//!
//! V3 and V4 carry no fault word: an injected fault shows only through what it does to the
//! model (a lost throttle signal stops the motor; an overheat raises V4's temperature).

use hwfoc::hw5::{Fault as Hw5Fault, FaultCode, TelemetryFrame};
use hwfoc::{Fault, Protocol, Status, v3, v4};

use crate::model::Measured;

/// V4 data frame interval in fast mode, ns.
pub const V4_FAST_NS: u64 = 51_000_000;
/// V4 slow mode: data and info frames alternate this far apart, ns.
pub const V4_SLOW_SLOT_NS: u64 = 200_000_000;
/// V4: slow mode resumes this long after the motor stopped, ns.
pub const V4_SLOW_AFTER_NS: u64 = 1_500_000_000;
/// V3 frame interval, ns.
pub const V3_INTERVAL_NS: u64 = 19_500_000;
/// HW5 frame interval while the motor turns, ns (50 Hz).
pub const HW5_RUN_NS: u64 = 20_000_000;
/// HW5 frame interval while idle, ns (2.5 Hz).
pub const HW5_IDLE_NS: u64 = 400_000_000;

/// The protocols a virtual ESC speaks.
pub const SIMULATED: [Protocol; 4] = [
    Protocol::HwFoc,
    Protocol::HwV4,
    Protocol::HwV3,
    Protocol::Hw5,
];

/// Whether a virtual ESC can speak `protocol` (every one but DataLink, a hub's).
pub fn simulated(protocol: Protocol) -> bool {
    SIMULATED.contains(&protocol)
}

/// The V4 info frame of a virtual ESC on a pack of `cells` cells (see the module doc).
pub fn v4_info(cells: u8) -> v4::InfoFrame {
    let hv = f64::from(cells) * 4.35 > f64::from(v4::ADC_LIMIT - 1) * 8.0 / 910.0;
    let (v1, v2) = if hv { (11, 65) } else { (8, 91) };
    v4::InfoFrame {
        full_scale: v4::DEFAULT_FULL_SCALE,
        v1,
        v2,
        i1: 1,
        i2: 20,
        i3: 0,
        t1: 0x21,
        t2: 0x21,
    }
}

/// The 12-bit ADC value a V4 ESC's NTC reads at `celsius`: the inverse of
/// [`hwfoc::v4::ntc_celsius`] (beta 3950, 47 kOhm at 25 degC against 10 kOhm), rounded, within
/// 1..=4095 (0 would be no reading).
pub fn ntc_adc(celsius: f64) -> u16 {
    let kelvin = celsius + 273.15;
    let ratio = v4::NTC_R25_OVER_REFERENCE * (v4::NTC_BETA * (1.0 / kelvin - 1.0 / 298.15)).exp();
    let adc = f64::from(v4::ADC_LIMIT) * ratio / (1.0 + ratio);
    if adc.is_nan() {
        return 1;
    }
    adc.round().clamp(1.0, f64::from(v4::ADC_LIMIT - 1)) as u16
}

/// A V4 data frame of the measurements `m`; `slow`: in slow mode (no second temperature).
pub fn v4_frame(counter: u32, m: &Measured, info: &v4::InfoFrame, slow: bool) -> v4::DataFrame {
    let scale = f64::from(info.full_scale) / 100.0;
    let throttle = |pct: f64| (pct * scale).round().clamp(0.0, f64::from(info.full_scale)) as u16;
    let adc = |x: f64| x.round().clamp(0.0, f64::from(v4::ADC_LIMIT - 1)) as u16;
    let volts_per_step = f64::from(info.v1) / (f64::from(info.v2) * 10.0);
    // amps = adc * I1 / I2 - I3
    let current_adc =
        (m.current_a + f64::from(info.i3)) * f64::from(info.i2) / f64::from(info.i1.max(1));
    v4::DataFrame {
        counter: counter & 0xFF_FFFF,
        throttle_in_raw: throttle(m.throttle_in_pct),
        throttle_out_raw: throttle(m.throttle_out_pct),
        erpm: m.erpm.round().clamp(0.0, f64::from(0xFF_FFFFu32)) as u32,
        voltage_adc: adc(m.voltage_v / volts_per_step),
        current_adc: if m.spinning { adc(current_adc) } else { 0 },
        temp_adc: ntc_adc(m.mos_c),
        temp2_adc: if slow { 0 } else { ntc_adc(m.cap_c) },
    }
}

/// A V3 frame of the measurements `m`.
pub fn v3_frame(counter: u32, m: &Measured) -> v3::V3Frame {
    let throttle = |pct: f64| {
        (pct * f64::from(v3::FULL_SCALE) / 100.0)
            .round()
            .clamp(0.0, f64::from(v3::FULL_SCALE)) as u16
    };
    let period = f64::from(v3::US_PER_MINUTE) / m.erpm;
    let period_us = if m.erpm > 0.0 && period < 65535.5 {
        // A period that rounds to the placeholder would read as no speed: one off.
        match period.round().max(1.0) as u16 {
            v3::PLACEHOLDER_PERIOD_US => v3::PLACEHOLDER_PERIOD_US - 1,
            p => p,
        }
    } else {
        v3::PLACEHOLDER_PERIOD_US
    };
    v3::V3Frame {
        counter: counter & 0xFF_FFFF,
        throttle_in_raw: throttle(m.throttle_in_pct),
        pwm_out_raw: throttle(m.throttle_out_pct),
        period_us,
    }
}

/// The HW5 flag a status bit of the simulator's (HW-FOC's) is sent as, or `None` for a bit HW5
/// has no flag for:
///
/// | simulator | HW5 |
/// |---|---|
/// | `motor_blocked` | `motor_locked` |
/// | `mos_overheat`, `cap_overheat` | `over_temperature` |
/// | `throttle_not_zeroed` | `throttle_not_zero_at_start` |
/// | `throttle_signal_lost` | `throttle_signal_lost` |
/// | `over_current` | `over_current` |
/// | `input_voltage_low` | `low_voltage` |
/// | `input_voltage_high` | `input_voltage_error` |
/// | `upper_bridge_open`, `lower_bridge_open` | `motor_connection_error` (an open bridge looks like an open phase) |
/// | `mos_short`, `opamp_phase_a/b/c`, `reserved_3`, `reserved_15` | none |
pub fn hw5_fault(fault: Fault) -> Option<Hw5Fault> {
    Some(match fault {
        Fault::MotorBlocked => Hw5Fault::MotorLocked,
        Fault::MosOverheat | Fault::CapOverheat => Hw5Fault::OverTemperature,
        Fault::ThrottleNotZeroed => Hw5Fault::ThrottleNotZeroAtStart,
        Fault::ThrottleSignalLost => Hw5Fault::ThrottleSignalLost,
        Fault::OverCurrent => Hw5Fault::OverCurrent,
        Fault::InputVoltageLow => Hw5Fault::LowVoltage,
        Fault::InputVoltageHigh => Hw5Fault::InputVoltageError,
        Fault::UpperBridgeOpen | Fault::LowerBridgeOpen => Hw5Fault::MotorConnectionError,
        Fault::MosShort
        | Fault::OpampPhaseA
        | Fault::OpampPhaseB
        | Fault::OpampPhaseC
        | Fault::Reserved3
        | Fault::Reserved15 => return None,
    })
}

/// The HW5 fault byte of a status word (bits without an HW5 flag are left out: the fleet
/// refuses to inject them, and the model raises none).
pub fn hw5_fault_code(status: Status) -> FaultCode {
    Fault::ALL
        .iter()
        .filter(|f| status.contains(**f))
        .filter_map(|f| hw5_fault(*f))
        .fold(FaultCode::OK, FaultCode::with)
}

/// An HW5 telemetry frame of the measurements `m`; `current_raw` is the current field as the
/// ESC sends it (see [`Hw5Current`]).
pub fn hw5_frame(m: &Measured, current_raw: u16, bec_noise: f64) -> TelemetryFrame {
    let byte = |x: f64| x.round().clamp(0.0, 255.0) as u8;
    let rise = m.mos_c - m.ambient_c;
    TelemetryFrame {
        throttle: byte(m.throttle_in_pct),
        unknown: [0, 0],
        fault: hw5_fault_code(m.status),
        erpm_raw: (m.erpm / 10.0).round().clamp(0.0, 65535.0) as u16,
        voltage_raw: (m.voltage_v * 10.0).round().clamp(0.0, 65535.0) as u16,
        current_raw,
        esc_temp: byte(m.mos_c),
        bec_temp: byte(m.ambient_c + rise / 3.0 + 3.0),
        motor_temp: byte(m.ambient_c + 0.8 * rise),
        bec_voltage_raw: byte(84.0 + bec_noise),
        bec_current_raw: byte(8.0 + 2.0 * bec_noise),
    }
}

/// HW5's current field: the measurement in tenths (not below 0), but while the throttle is 0
/// and the motor still turns, the last reading sent with throttle repeated.
#[derive(Debug, Clone, Copy, Default)]
pub struct Hw5Current {
    last: u16,
}

impl Hw5Current {
    /// The field for the measurements `m`.
    pub fn raw(&mut self, m: &Measured) -> u16 {
        let now = (m.current_a * 10.0).round().clamp(0.0, 65535.0) as u16;
        if !m.spinning {
            self.last = 0;
            0
        } else if m.throttle_in_pct.round() < 1.0 {
            self.last
        } else {
            self.last = now;
            now
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ntc_adc_inverts_ntc_celsius() {
        for tenth in -200..=1500 {
            let t = f64::from(tenth) / 10.0;
            let adc = ntc_adc(t);
            let back = f64::from(v4::ntc_celsius(adc).unwrap());
            // One ADC step is well under 0.3 degC over this range.
            assert!((back - t).abs() < 0.3, "{t} -> {adc} -> {back}");
        }
        // The capture's idle reading: 3244 is 29.8 degC.
        assert!(ntc_adc(29.8).abs_diff(3244) <= 2);
        assert_eq!(ntc_adc(25.0), 3377);
        // Never 0 (no reading) nor beyond 12 bits.
        assert_eq!(ntc_adc(-100.0), 4095);
        assert_eq!(ntc_adc(2000.0), 1);
        assert_eq!(ntc_adc(f64::NAN), 1);
    }

    #[test]
    fn every_fault_has_its_hw5_flag_or_none() {
        let mapped: Vec<(&str, Option<&str>)> = Fault::ALL
            .iter()
            .map(|f| (f.name(), hw5_fault(*f).map(|h| h.name())))
            .collect();
        assert!(mapped.contains(&("motor_blocked", Some("motor_locked"))));
        assert!(mapped.contains(&("over_current", Some("over_current"))));
        assert!(mapped.contains(&("mos_short", None)));
        let code = hw5_fault_code(
            Status::OK
                .with(Fault::MosOverheat)
                .with(Fault::CapOverheat)
                .with(Fault::InputVoltageLow),
        );
        let names: Vec<&str> = code.faults().map(|f| f.name()).collect();
        assert_eq!(names, ["over_temperature", "low_voltage"]);
    }

    #[test]
    fn v4_info_is_the_captures_or_an_hv_models() {
        let info = v4_info(6);
        assert_eq!(
            info.encode()[..7],
            [0x9B, 0x9B, 0x03, 0xE8, 0x01, 0x08, 0x5B]
        );
        assert!(info.is_plausible() && info.has_current_sensor());
        assert_eq!(info.current_a(1200), Some(60.0));
        assert_eq!(v4_info(12).volts_per_step(), v4::VoltsPerStep::HIGH_VOLTAGE);
    }

    fn measured(erpm: f64) -> Measured {
        Measured {
            throttle_in_pct: 40.0,
            throttle_out_pct: 38.0,
            erpm,
            voltage_v: 24.2,
            current_a: 20.0,
            mos_c: 40.0,
            cap_c: 35.0,
            ambient_c: 25.0,
            status: Status::OK,
            spinning: erpm > 0.0,
        }
    }

    #[test]
    fn frames_carry_the_measurements() {
        let m = measured(40_000.0);
        let info = v4_info(6);
        let f = v4_frame(0x1_000_005, &m, &info, false);
        let d = v4::Data {
            frame: f,
            info: Some(info),
        };
        assert_eq!(f.counter, 5);
        assert_eq!((d.throttle_in_pct(), d.erpm()), (40.0, 40_000));
        assert!((d.voltage_v(v4::VoltsPerStep::DEFAULT) - 24.2).abs() < 0.01);
        assert_eq!(d.current_a(), Some(20.0));
        assert!((d.temp_c().unwrap() - 40.0).abs() < 0.2);
        assert!(d.temp2_c().is_some());
        assert_eq!(v4_frame(0, &m, &info, true).temp2_adc, 0);

        let f = v3_frame(7, &m);
        assert_eq!(
            (f.throttle_in_raw, f.pwm_out_raw, f.period_us),
            (102, 97, 1500)
        );
        assert_eq!(f.erpm(), Some(40_000));
        assert_eq!(
            v3_frame(0, &measured(0.0)).period_us,
            v3::PLACEHOLDER_PERIOD_US
        );
        // Too slow for 16 bits of microseconds: no speed either.
        assert_eq!(
            v3_frame(0, &measured(900.0)).period_us,
            v3::PLACEHOLDER_PERIOD_US
        );
        assert_eq!(v3_frame(0, &measured(1699.04)).erpm(), Some(1699));

        let f = hw5_frame(&m, 200, 0.0);
        assert_eq!((f.throttle, f.erpm(), f.voltage_raw), (40, 40_000, 242));
        assert_eq!((f.esc_temp, f.bec_temp, f.motor_temp), (40, 33, 37));
        assert_eq!(f.bec_voltage_v(), 8.4);
    }

    #[test]
    fn hw5_current_repeats_while_the_throttle_is_zero() {
        let mut c = Hw5Current::default();
        let mut m = measured(40_000.0);
        assert_eq!(c.raw(&m), 200);
        m.throttle_in_pct = 0.0;
        m.current_a = -5.0;
        assert_eq!(c.raw(&m), 200);
        m.spinning = false;
        assert_eq!(c.raw(&m), 0);
        m.spinning = true;
        m.throttle_in_pct = 10.0;
        assert_eq!(c.raw(&m), 0, "not below 0");
    }
}
