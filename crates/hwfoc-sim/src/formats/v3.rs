//! Platinum V3 (`hw-v3`), 19200 baud (`docs/OLDER-PROTOCOLS.md`): a 10-byte frame every
//! 19.5 ms whatever the motor does; the counter from `--start-packet` or 0 (24 bits); throttle
//! and PWM in 255ths; the period of one electrical revolution, `60 000 000 / eRPM` us, or the
//! start-up placeholder 35314 while the motor is stopped (and for speeds too slow for 16 bits).
//!
//! V3 carries no fault word: an injected fault shows only through what it does to the model.

use hwfoc::telemetry::Data;
use hwfoc::{Protocol, v3};

use super::{Look, SimulatedFormat, Speaker, Start};
use crate::burst::What;
use crate::model::Measured;
use crate::rng::Rng;

/// V3 as a virtual ESC speaks it.
pub(super) const FORMAT: SimulatedFormat = SimulatedFormat {
    protocol: Protocol::HwV3,
    start: |s: &Start| {
        let speaker = V3 { counter: s.counter };
        (Box::new(speaker), s.phase_ns % INTERVAL_NS)
    },
    fault_word: None,
};

/// Frame interval, ns.
const INTERVAL_NS: u64 = 19_500_000;

/// A V3 ESC's schedule: its counter.
#[derive(Debug, Clone)]
struct V3 {
    counter: u32,
}

impl Speaker for V3 {
    fn look(&mut self, t: u64, m: &Measured, _noise: &mut Rng) -> Look {
        let frame = frame(self.counter, m);
        self.counter = (self.counter + 1) & 0xFF_FFFF;
        let what = What::Telemetry {
            data: Data::HwV3(frame),
        };
        Look {
            send: Some((frame.encode().to_vec(), what)),
            next_ns: t + INTERVAL_NS,
        }
    }
}

/// A V3 frame of the measurements `m`.
fn frame(counter: u32, m: &Measured) -> v3::V3Frame {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::esc::tests::{gaps, other_run};
    use crate::formats::tests::measured;

    #[test]
    fn frames_carry_the_measurements() {
        let f = frame(7, &measured(40_000.0));
        assert_eq!(
            (f.throttle_in_raw, f.pwm_out_raw, f.period_us),
            (102, 97, 1500)
        );
        assert_eq!(f.erpm(), Some(40_000));
        assert_eq!(
            frame(0, &measured(0.0)).period_us,
            v3::PLACEHOLDER_PERIOD_US
        );
        // Too slow for 16 bits of microseconds: no speed either.
        assert_eq!(
            frame(0, &measured(900.0)).period_us,
            v3::PLACEHOLDER_PERIOD_US
        );
        assert_eq!(frame(0, &measured(1699.04)).erpm(), Some(1699));
    }

    #[test]
    fn v3_steady_frames_and_the_placeholder() {
        let (all, data) = other_run(Protocol::HwV3, &[]);
        assert!(all.iter().all(|b| b.bytes.len() == 10));
        let v3 = |d: &Data| match d {
            Data::HwV3(f) => *f,
            _ => panic!("{d:?}"),
        };
        for (k, (_, d)) in data.iter().enumerate() {
            assert_eq!(v3(d).counter, k as u32);
        }
        for (gap, _, _) in gaps(&data, |_| true) {
            assert!((gap - 19.5).abs() < 1e-3, "{gap}");
        }
        assert!((400..412).contains(&data.len()), "{}", data.len());
        for (t, d) in &data {
            let f = v3(d);
            if *t < 2.0 || *t > 5.5 {
                assert_eq!(f.period_us, v3::PLACEHOLDER_PERIOD_US, "at {t}");
            }
            if (2.5..4.0).contains(t) {
                assert!(f.erpm().unwrap() > 10_000, "at {t}");
                assert!((100..105).contains(&f.throttle_in_raw));
            }
        }
        let wire: Vec<u8> = all.iter().flat_map(|b| b.bytes.clone()).collect();
        assert_eq!(v3::frames(&wire).count(), data.len());
    }
}
