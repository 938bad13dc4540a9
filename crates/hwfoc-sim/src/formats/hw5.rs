//! HW5 (`hw5`), 115200 baud (`docs/HW5-AND-CAN.md`): a 32-byte telemetry frame every 20 ms
//! while the motor turns, every 400 ms idle (the ESC looks every 20 ms).
//!
//! Throttle in percent, eRPM / 10, voltage and current in tenths (current not below 0, and
//! while the throttle is 0 the last reading repeated until the motor has stopped, as the ESC
//! does: [`Current`]), ESC temperature (the MOSFETs'), BEC temperature (ambient plus a third of
//! the MOSFETs' rise plus 3 degC: the model has no BEC), motor temperature (ambient plus 0.8 of
//! the MOSFETs' rise: nor a winding), BEC 8.4 V at about 0.8 A, and the fault byte from the
//! status bits ([`fault`]).

use hwfoc::hw5::{Fault as Hw5Fault, FaultCode, TelemetryFrame};
use hwfoc::telemetry::Data;
use hwfoc::{Fault, Protocol, Status};

use super::{FaultWord, Look, SimulatedFormat, Speaker, Start};
use crate::burst::What;
use crate::model::Measured;
use crate::rng::Rng;

/// HW5 as a virtual ESC speaks it.
pub(super) const FORMAT: SimulatedFormat = SimulatedFormat {
    protocol: Protocol::Hw5,
    start: |s: &Start| {
        let speaker = Hw5 {
            current: Current::default(),
            last_data_ns: None,
        };
        (Box::new(speaker), s.phase_ns % RUN_NS)
    },
    fault_word: Some(FaultWord {
        name: "fault byte",
        flag: |f| fault(f).map(Hw5Fault::name),
    }),
};

/// Frame interval while the motor turns, ns (50 Hz).
const RUN_NS: u64 = 20_000_000;
/// Frame interval while idle, ns (2.5 Hz).
const IDLE_NS: u64 = 400_000_000;

/// An HW5 ESC's schedule: the current it repeats, and when it last sent.
#[derive(Debug, Clone)]
struct Hw5 {
    current: Current,
    last_data_ns: Option<u64>,
}

impl Speaker for Hw5 {
    fn look(&mut self, t: u64, m: &Measured, noise: &mut Rng) -> Look {
        let idle_due = self.last_data_ns.is_none_or(|last| t >= last + IDLE_NS);
        let mut send = None;
        if m.spinning || idle_due {
            let raw = self.current.raw(m);
            let frame = frame(m, raw, noise.noise(1.0));
            self.last_data_ns = Some(t);
            let what = What::Telemetry {
                data: Data::Hw5(frame),
            };
            send = Some((frame.encode().to_vec(), what));
        }
        let last = self.last_data_ns.unwrap_or(t);
        let next_ns = if m.spinning {
            t + RUN_NS
        } else {
            (t + RUN_NS).min(last + IDLE_NS)
        };
        Look { send, next_ns }
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
fn fault(fault: Fault) -> Option<Hw5Fault> {
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
fn fault_code(status: Status) -> FaultCode {
    Fault::ALL
        .iter()
        .filter(|f| status.contains(**f))
        .filter_map(|f| fault(*f))
        .fold(FaultCode::OK, FaultCode::with)
}

/// An HW5 telemetry frame of the measurements `m`; `current_raw` is the current field as the
/// ESC sends it (see [`Current`]).
fn frame(m: &Measured, current_raw: u16, bec_noise: f64) -> TelemetryFrame {
    let byte = |x: f64| x.round().clamp(0.0, 255.0) as u8;
    let rise = m.mos_c - m.ambient_c;
    TelemetryFrame {
        throttle: byte(m.throttle_in_pct),
        unknown: [0, 0],
        fault: fault_code(m.status),
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
struct Current {
    last: u16,
}

impl Current {
    /// The field for the measurements `m`.
    fn raw(&mut self, m: &Measured) -> u16 {
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
    use crate::esc::tests::{gaps, other_run};
    use crate::formats::tests::measured;

    #[test]
    fn every_fault_has_its_hw5_flag_or_none() {
        let mapped: Vec<(&str, Option<&str>)> = Fault::ALL
            .iter()
            .map(|f| (f.name(), fault(*f).map(|h| h.name())))
            .collect();
        assert!(mapped.contains(&("motor_blocked", Some("motor_locked"))));
        assert!(mapped.contains(&("over_current", Some("over_current"))));
        assert!(mapped.contains(&("mos_short", None)));
        let code = fault_code(
            Status::OK
                .with(Fault::MosOverheat)
                .with(Fault::CapOverheat)
                .with(Fault::InputVoltageLow),
        );
        let names: Vec<&str> = code.faults().map(|f| f.name()).collect();
        assert_eq!(names, ["over_temperature", "low_voltage"]);
        let word = FORMAT.fault_word.as_ref().unwrap();
        assert_eq!((word.flag)(Fault::MotorBlocked), Some("motor_locked"));
        assert_eq!((word.flag)(Fault::MosShort), None);
    }

    #[test]
    fn frames_carry_the_measurements() {
        let m = measured(40_000.0);
        let f = frame(&m, 200, 0.0);
        assert_eq!((f.throttle, f.erpm(), f.voltage_raw), (40, 40_000, 242));
        assert_eq!((f.esc_temp, f.bec_temp, f.motor_temp), (40, 33, 37));
        assert_eq!(f.bec_voltage_v(), 8.4);
    }

    #[test]
    fn current_repeats_while_the_throttle_is_zero() {
        let mut c = Current::default();
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

    #[test]
    fn hw5_rates_and_faults() {
        let (all, data) = other_run(Protocol::Hw5, &["motor_blocked@3-3.5", "over_current@6"]);
        assert!(all.iter().all(|b| b.bytes.len() == 32));
        let hw5 = |d: &Data| match d {
            Data::Hw5(f) => *f,
            _ => panic!("{d:?}"),
        };
        let (mut run, mut idle) = (0, 0);
        for (gap, running, t) in gaps(&data, |d| hw5(d).erpm_raw > 0) {
            if running {
                assert!((gap - 20.0).abs() < 1e-3 || t < 2.1, "{gap} at {t}");
                run += 1;
            } else {
                // Idle, and the first frame once the motor has stopped: 400 ms.
                assert!((gap - 400.0).abs() < 1e-3, "{gap} at {t}");
                idle += 1;
            }
        }
        assert!(run > 100 && idle > 6, "{run} {idle}");
        for (t, d) in &data {
            let f = hw5(d);
            let names: Vec<&str> = f.fault.faults().map(|f| f.name()).collect();
            let want: &[&str] = match t {
                t if (3.0..3.5).contains(t) => &["motor_locked"],
                t if *t >= 6.0 => &["over_current"],
                _ => &[],
            };
            assert_eq!(names, want, "at {t}");
        }
        let wire: Vec<u8> = all.iter().flat_map(|b| b.bytes.clone()).collect();
        assert_eq!(hwfoc::hw5::frames(&wire).count(), data.len());
    }
}
