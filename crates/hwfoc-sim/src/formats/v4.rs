//! Platinum V4 (`hw-v4`), 19200 baud (`docs/OLDER-PROTOCOLS.md`).
//!
//! Running ("fast" mode), a 19-byte data frame every 51 ms; idle ("slow" mode), 20-byte data
//! frames (trailing `B9`) and 13-byte info frames alternating 200 ms apart. Fast mode starts
//! with the first frame whose input throttle is above 0 (the ESC looks every 51 ms); slow mode
//! resumes 1.5 s after the motor stopped and the throttle went to 0. The counter goes up by one
//! per data frame (24 bits), from `--start-packet` or 0.
//!
//! The info frame is [`info`]: full scale 1000, the capture's 8/910 V per step (11/650, an HV
//! model's, for a pack that could exceed 36 V: more than 8 cells), a current sensor of 0.05 A
//! per step (I1 = 1, I2 = 20, I3 = 0: up to 204.75 A, as a 120 A model's headroom needs),
//! T1 = T2 = `0x21` as captured. Throttle and PWM in 1000ths, eRPM as measured, voltage and
//! current ADC through those constants, temperatures through the inverse of the NTC conversion
//! ([`ntc_adc`]); the second temperature (the capacitors') is 0 (no reading) in slow mode, as
//! captured.
//!
//! V4 carries no fault word: an injected fault shows only through what it does to the model.

use hwfoc::telemetry::Data;
use hwfoc::{Protocol, v4};

use super::{Look, SimulatedFormat, Speaker, Start};
use crate::burst::What;
use crate::faults::Fate;
use crate::model::Measured;
use crate::rng::Rng;

/// V4 as a virtual ESC speaks it.
pub(super) const FORMAT: SimulatedFormat = SimulatedFormat {
    protocol: Protocol::HwV4,
    start: |s: &Start| {
        let speaker = V4 {
            counter: s.counter,
            info: info(s.cells),
            fast: false,
            active_ns: 0,
            slot_ns: s.phase_ns,
            info_next: false,
        };
        (Box::new(speaker), s.phase_ns)
    },
    fault_word: None,
};

/// Data frame interval in fast mode, ns.
pub(crate) const FAST_NS: u64 = 51_000_000;
/// Slow mode: data and info frames alternate this far apart, ns.
pub(crate) const SLOW_SLOT_NS: u64 = 200_000_000;
/// Slow mode resumes this long after the motor stopped, ns.
const SLOW_AFTER_NS: u64 = 1_500_000_000;

/// Where a V4 ESC's schedule is: fast or slow mode.
#[derive(Debug, Clone)]
struct V4 {
    counter: u32,
    info: v4::InfoFrame,
    fast: bool,
    /// Last time (fast mode) the throttle was above 0 or the motor turned.
    active_ns: u64,
    /// Slow mode: the next slot, and whether it is an info frame's.
    slot_ns: u64,
    info_next: bool,
}

impl V4 {
    /// The next data frame, its counter taken.
    fn data(&mut self, m: &Measured, slow: bool) -> (v4::DataFrame, What) {
        let frame = frame(self.counter, m, &self.info, slow);
        self.counter = (self.counter + 1) & 0xFF_FFFF;
        let data = Data::HwV4(v4::Data {
            frame,
            info: Some(self.info),
        });
        (frame, What::Telemetry { data })
    }
}

impl Speaker for V4 {
    fn look(&mut self, t: u64, m: &Measured, _noise: &mut Rng) -> Look {
        let throttle = m.throttle_in_pct * f64::from(self.info.full_scale) / 100.0;
        let active = throttle.round() >= 1.0 || m.spinning;
        if self.fast && !active && t >= self.active_ns + SLOW_AFTER_NS {
            // Back to slow mode: its first slot now, a data frame.
            self.fast = false;
            self.slot_ns = t;
            self.info_next = false;
        } else if !self.fast && throttle.round() >= 1.0 {
            self.fast = true;
        }
        if active {
            self.active_ns = t;
        }
        if self.fast {
            let (frame, what) = self.data(m, false);
            return Look {
                send: Some((frame.encode().to_vec(), what)),
                next_ns: t + FAST_NS,
            };
        }
        // The ESC looks at the throttle between slots, as often as it sends in fast mode.
        if t < self.slot_ns {
            return Look {
                send: None,
                next_ns: (t + FAST_NS).min(self.slot_ns),
            };
        }
        let send = if self.info_next {
            (
                self.info.encode().to_vec(),
                What::Info { fate: Fate::Intact },
            )
        } else {
            let (frame, what) = self.data(m, true);
            (frame.encode_with_trailer().to_vec(), what)
        };
        self.info_next = !self.info_next;
        self.slot_ns = t + SLOW_SLOT_NS;
        Look {
            send: Some(send),
            next_ns: (t + FAST_NS).min(self.slot_ns),
        }
    }
}

/// The V4 info frame of a virtual ESC on a pack of `cells` cells (see the module doc).
pub(crate) fn info(cells: u8) -> v4::InfoFrame {
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
pub(crate) fn ntc_adc(celsius: f64) -> u16 {
    let kelvin = celsius + 273.15;
    let ratio = v4::NTC_R25_OVER_REFERENCE * (v4::NTC_BETA * (1.0 / kelvin - 1.0 / 298.15)).exp();
    let adc = f64::from(v4::ADC_LIMIT) * ratio / (1.0 + ratio);
    if adc.is_nan() {
        return 1;
    }
    adc.round().clamp(1.0, f64::from(v4::ADC_LIMIT - 1)) as u16
}

/// A V4 data frame of the measurements `m`; `slow`: in slow mode (no second temperature).
fn frame(counter: u32, m: &Measured, info: &v4::InfoFrame, slow: bool) -> v4::DataFrame {
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

#[cfg(test)]
mod tests {
    use hwfoc::telemetry::Data;

    use super::*;
    use crate::esc::tests::{gaps, other_run};
    use crate::formats::tests::measured;

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
    fn info_is_the_captures_or_an_hv_models() {
        let i = info(6);
        assert_eq!(i.encode()[..7], [0x9B, 0x9B, 0x03, 0xE8, 0x01, 0x08, 0x5B]);
        assert!(i.is_plausible() && i.has_current_sensor());
        assert_eq!(i.current_a(1200), Some(60.0));
        assert_eq!(info(12).volts_per_step(), v4::VoltsPerStep::HIGH_VOLTAGE);
    }

    #[test]
    fn frames_carry_the_measurements() {
        let m = measured(40_000.0);
        let info = info(6);
        let f = frame(0x1_000_005, &m, &info, false);
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
        assert_eq!(frame(0, &m, &info, true).temp2_adc, 0);
    }

    #[test]
    fn v4_fast_and_slow_modes() {
        let (all, data) = other_run(Protocol::HwV4, &[]);
        let v4 = |d: &Data| match d {
            Data::HwV4(d) => *d,
            _ => panic!("{d:?}"),
        };
        // Counters from 0, +1 per data frame; the wire decodes to the same frames, the info
        // frame adopted.
        for (k, (_, d)) in data.iter().enumerate() {
            assert_eq!(v4(d).frame.counter, k as u32);
        }
        let wire: Vec<u8> = all.iter().flat_map(|b| b.bytes.clone()).collect();
        let decoded: Vec<v4::Data> = v4::frames(&wire)
            .filter_map(|f| match f.frame {
                v4::V4Frame::Data(d) => Some(d),
                v4::V4Frame::Info(_) => None,
            })
            .collect();
        assert_eq!(decoded.len(), data.len());
        assert_eq!(decoded.last().unwrap(), &v4(&data.last().unwrap().1));
        let fast = |d: &Data| v4(d).frame.temp2_adc != 0;
        let (mut fast_gaps, mut slow_gaps) = (0, 0);
        for (gap, running, t) in gaps(&data, fast) {
            if running {
                assert!((gap - 51.0).abs() < 1e-3 || t < 2.1, "{gap} at {t}");
                fast_gaps += 1;
            } else {
                // A data frame every 400 ms: an info frame between.
                assert!((gap - 400.0).abs() < 1e-3 || t > 5.0, "{gap} at {t}");
                slow_gaps += 1;
            }
        }
        assert!(fast_gaps > 60 && slow_gaps > 8, "{fast_gaps} {slow_gaps}");
        // Fast from the first frame with throttle (2 s), slow 1.5 s after the motor stopped
        // (spun down by about 4.8 s).
        let first_fast = data.iter().find(|d| fast(&d.1)).unwrap().0;
        assert!((2.0..2.06).contains(&first_fast), "{first_fast}");
        let last_fast = data.iter().rev().find(|d| fast(&d.1)).unwrap().0;
        assert!((5.7..6.5).contains(&last_fast), "{last_fast}");
        // Slow data frames have the trailer, and info frames come 200 ms after each.
        for (i, b) in all.iter().enumerate() {
            match &b.what {
                What::Info { .. } => {
                    assert_eq!(b.bytes.len(), 13);
                    let prev = &all[i - 1];
                    assert_eq!(prev.bytes.len(), 20);
                    assert_eq!(b.t_ns - prev.t_ns, SLOW_SLOT_NS);
                }
                What::Telemetry { data } if fast(data) => assert_eq!(b.bytes.len(), 19),
                What::Telemetry { .. } => assert_eq!(b.bytes.len(), 20),
                other => panic!("{other:?}"),
            }
        }
        // Values: throttle in 1000ths, current while running.
        let mid = data.iter().find(|d| d.0 > 3.5).unwrap().1;
        let mid = v4(&mid);
        assert!((39.0..41.0).contains(&mid.throttle_in_pct()));
        assert!(mid.current_a().unwrap() > 3.0);
        assert!((24.0..25.5).contains(&mid.voltage_v(v4::VoltsPerStep::DEFAULT)));
        assert!((15.0..40.0).contains(&mid.temp_c().unwrap()));
    }
}
