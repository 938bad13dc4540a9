//! Charge and energy drawn by an ESC, integrated over the times of its frames: the one place
//! where `summary`, the monitor, the plots and the MAVLink bridge's "mAh consumed" come from.
//!
//! Each frame's input current and voltage are taken to hold until the ESC's next frame (a
//! left Riemann sum over the frame times: an ESC measures, then sends). Only a step that is
//! [`Step::Continuous`] is integrated (at most [`crate::clock::MAX_STEP_S`], not back): a longer
//! silence (a cut line, an ESC that rebooted, a pause between recordings) is not filled with
//! the last current seen, and nothing is integrated across a clock that stepped back or
//! jumped; [`Energy::seconds`] is the sum of the steps integrated. For an input without times
//! (raw bytes), every step is the protocol's frame period ([`nominal_period_s`]), and
//! [`Energy::nominal`] says so.
//!
//! Regenerative braking (negative input current) gives charge back: the charge and energy are
//! net figures, as a battery sees them.

use hwfoc::Protocol;

use crate::clock::Step;

/// The step between two data frames of an input without times, s: the frame period of a running
/// ESC of `protocol` ([`Protocol::frame_period`]), HW-FOC's for none (or a CAN protocol, whose
/// frames always have times).
pub fn nominal_period_s(protocol: Option<Protocol>) -> f64 {
    protocol
        .and_then(Protocol::frame_period)
        .or(Protocol::HwFoc.frame_period())
        .map_or(0.0, |d| d.as_secs_f64())
}

/// Electrical input power, W, of a frame's input voltage and current: the one definition the
/// summary, the plots and [`Energy`] use.
#[inline]
pub fn power_w(voltage_v: f64, current_a: f64) -> f64 {
    voltage_v * current_a
}

/// Power drawn from the battery, W: `power_w` with a negative power (regeneration, or an idle
/// ESC's current sensor reading -1 LSB, -0.016 A) counted as none. What a peak of power is
/// taken over: a peak draw is never below 0 W.
#[inline]
pub fn drawn_w(power_w: f64) -> f64 {
    power_w.max(0.0)
}

/// Charge, energy and power of one ESC (or the sum of several: [`Energy::merge`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Energy {
    /// The last frame: time (s, `None` on an untimed input), volts, amps.
    last: Option<(Option<f64>, f64, f64)>,
    /// Ampere-seconds.
    charge_as: f64,
    /// Joules.
    energy_j: f64,
    /// Seconds integrated.
    seconds: f64,
    /// Largest electrical input power of a frame, W.
    peak_w: Option<f64>,
    /// Whether some step used `period_s` for want of times.
    nominal: bool,
    /// The step between frames without times, s ([`nominal_period_s`]).
    period_s: f64,
}

impl Energy {
    /// Nothing integrated yet; frames without times a step of HW-FOC's frame period apart.
    pub fn new() -> Energy {
        Energy::at_period(nominal_period_s(None))
    }

    /// Nothing integrated yet; frames without times `period_s` apart ([`nominal_period_s`]).
    pub const fn at_period(period_s: f64) -> Energy {
        Energy {
            last: None,
            charge_as: 0.0,
            energy_j: 0.0,
            seconds: 0.0,
            peak_w: None,
            nominal: false,
            period_s,
        }
    }

    /// Adds a frame received at `t_s` (`None` without timing) carrying `voltage_v` and input
    /// `current_a`. A step that is not [`Step::Continuous`] (a silence, a step back, a jump)
    /// adds nothing.
    pub fn add(&mut self, t_s: Option<f64>, voltage_v: f64, current_a: f64) {
        if let Some((last_t, v, i)) = self.last {
            let step = match (last_t, t_s) {
                (Some(a), Some(b)) => match Step::between(a, b, None) {
                    Step::Continuous(dt) => dt,
                    _ => 0.0,
                },
                _ => {
                    self.nominal = true;
                    self.period_s
                }
            };
            self.charge_as += i * step;
            self.energy_j += power_w(v, i) * step;
            self.seconds += step;
        }
        let power = drawn_w(power_w(voltage_v, current_a));
        self.peak_w = Some(self.peak_w.map_or(power, |p| p.max(power)));
        self.last = Some((t_s, voltage_v, current_a));
    }

    /// The figures [`Energy::add`] gives for `frames` frames without receive times, from sums
    /// a caller keeps anyway (the summary's raw lanes): `current_sum` and `power_sum` over
    /// every frame, `last` the last frame's volts and amps, `peak_w` the largest power. Each
    /// frame but the last holds for `period_s` ([`nominal_period_s`]).
    pub fn untimed(
        frames: u64,
        current_sum: f64,
        power_sum: f64,
        last: (f64, f64),
        peak_w: Option<f64>,
        period_s: f64,
    ) -> Energy {
        if frames == 0 {
            return Energy::at_period(period_s);
        }
        let steps = (frames - 1) as f64 * period_s;
        let (v, i) = last;
        Energy {
            last: Some((None, v, i)),
            charge_as: (current_sum - i) * period_s,
            energy_j: (power_sum - power_w(v, i)) * period_s,
            seconds: steps,
            peak_w: peak_w.map(drawn_w),
            nominal: frames > 1,
            period_s,
        }
    }

    /// Forgets the last frame, so that the next one starts a new integration (the charge and
    /// energy so far are kept): for a stream known to have been cut.
    pub fn break_here(&mut self) {
        self.last = None;
    }

    /// Consumed charge, mAh.
    pub fn charge_mah(&self) -> f64 {
        self.charge_as / 3.6
    }

    /// Consumed energy, Wh.
    pub fn energy_wh(&self) -> f64 {
        self.energy_j / 3600.0
    }

    /// Seconds integrated.
    pub fn seconds(&self) -> f64 {
        self.seconds
    }

    /// Mean electrical input power over the time integrated, W (`None` before two frames).
    pub fn mean_w(&self) -> Option<f64> {
        (self.seconds > 0.0).then(|| self.energy_j / self.seconds)
    }

    /// Largest electrical input power drawn in a single frame, W ([`drawn_w`]: never below 0;
    /// `None` before a frame).
    pub fn peak_w(&self) -> Option<f64> {
        self.peak_w
    }

    /// Whether steps were taken as [`Energy::period_s`] for want of receive times.
    pub fn nominal(&self) -> bool {
        self.nominal
    }

    /// The step between frames without receive times, s.
    pub fn period_s(&self) -> f64 {
        self.period_s
    }

    /// These figures with every voltage multiplied by `volts` and every current by `amps`
    /// (both positive): for an integration over raw integers, converted once at the end, as
    /// the summary does (the conversions are linear, so this is what integrating the converted
    /// values gives).
    pub fn scaled(&self, volts: f64, amps: f64) -> Energy {
        Energy {
            last: self.last.map(|(t, v, i)| (t, v * volts, i * amps)),
            charge_as: self.charge_as * amps,
            energy_j: self.energy_j * volts * amps,
            seconds: self.seconds,
            peak_w: self.peak_w.map(|p| p * volts * amps),
            nominal: self.nominal,
            period_s: self.period_s,
        }
    }

    /// Adds another ESC's figures to these, for a total over ESCs that ran at the same time:
    /// charges and energies add, the time integrated is the longer of the two (so the mean
    /// power is the total energy over it), the peak is the largest single-ESC peak (peaks of
    /// different ESCs need not be simultaneous). The last frames are not combined.
    pub fn merge(&mut self, other: &Energy) {
        self.charge_as += other.charge_as;
        self.energy_j += other.energy_j;
        self.seconds = self.seconds.max(other.seconds);
        self.peak_w = match (self.peak_w, other.peak_w) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        };
        if !self.nominal {
            self.period_s = other.period_s;
        }
        self.nominal |= other.nominal;
        self.last = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_draw_integrates_exactly() {
        let mut e = Energy::new();
        // 10 A at 20 V for 3.6 s, a frame every 50 ms: 10 mAh, 0.2 Wh.
        for k in 0..=72 {
            e.add(Some(100.0 + k as f64 * 0.05), 20.0, 10.0);
        }
        assert!((e.charge_mah() - 10.0).abs() < 1e-9, "{}", e.charge_mah());
        assert!((e.energy_wh() - 0.2).abs() < 1e-9);
        assert!((e.seconds() - 3.6).abs() < 1e-9);
        assert_eq!(e.peak_w(), Some(200.0));
        assert!((e.mean_w().unwrap() - 200.0).abs() < 1e-9);
        assert!(!e.nominal());
    }

    #[test]
    fn each_current_holds_until_the_next_frame() {
        let mut e = Energy::new();
        e.add(Some(0.0), 10.0, 36.0); // 36 A for 0.1 s = 1 mAh
        e.add(Some(0.1), 10.0, 0.0); // then nothing for 0.2 s
        e.add(Some(0.3), 10.0, 72.0); // the last frame's current has no step yet
        assert!((e.charge_mah() - 1.0).abs() < 1e-12);
        assert_eq!(e.peak_w(), Some(720.0));
    }

    #[test]
    fn a_silence_is_not_filled_with_the_last_current() {
        let mut e = Energy::new();
        e.add(Some(0.0), 10.0, 3.6);
        e.add(Some(60.0), 10.0, 3.6); // a minute of silence counts nothing
        e.add(Some(61.0), 10.0, 3.6); // one second at 3.6 A
        assert!((e.charge_mah() - 1.0).abs() < 1e-12);
        assert!((e.seconds() - crate::clock::MAX_STEP_S).abs() < 1e-12);
        let mut back = Energy::new();
        back.add(Some(5.0), 10.0, 3.6);
        back.add(Some(4.0), 10.0, 3.6); // a step back in time adds nothing
        assert_eq!(back.charge_mah(), 0.0);
    }

    #[test]
    fn nothing_is_integrated_across_a_jumped_timestamp() {
        // 9.95 s of frames, one of them stamped an hour late: 9.85 s integrated (the steps
        // to and from the late frame are discontinuities), never more than the recording.
        let mut e = Energy::new();
        for k in 0..200 {
            let t = k as f64 * 0.05 + if k == 100 { 3600.0 } else { 0.0 };
            e.add(Some(t), 10.0, 3.6);
        }
        assert!((e.seconds() - 9.85).abs() < 1e-9, "{}", e.seconds());
        assert!((e.charge_mah() - 9.85).abs() < 1e-9);
    }

    #[test]
    fn untimed_frames_step_the_nominal_period_and_say_so() {
        let mut e = Energy::new();
        for _ in 0..=20 {
            e.add(None, 10.0, 36.0);
        }
        // 20 steps of 50 ms at 36 A: 10 mAh.
        assert!((e.charge_mah() - 10.0).abs() < 1e-9);
        assert!(e.nominal());
    }

    #[test]
    fn sums_give_what_adding_untimed_frames_gives() {
        let frames = [(25.0, 10.0), (24.5, -2.0), (24.0, 30.5), (24.8, 7.25)];
        let mut added = Energy::new();
        for &(v, i) in &frames {
            added.add(None, v, i);
        }
        let sum = |f: fn(&(f64, f64)) -> f64| frames.iter().map(f).sum::<f64>();
        let from_sums = Energy::untimed(
            4,
            sum(|&(_, i)| i),
            sum(|&(v, i)| power_w(v, i)),
            (24.8, 7.25),
            Some(24.0 * 30.5),
            nominal_period_s(None),
        );
        assert!((from_sums.charge_mah() - added.charge_mah()).abs() < 1e-12);
        assert!((from_sums.energy_wh() - added.energy_wh()).abs() < 1e-12);
        assert!((from_sums.seconds() - added.seconds()).abs() < 1e-12);
        assert_eq!(from_sums.peak_w(), added.peak_w());
        assert!(from_sums.nominal() && added.nominal());
        assert_eq!(
            Energy::untimed(0, 0.0, 0.0, (0.0, 0.0), None, nominal_period_s(None)),
            Energy::new()
        );
        let one = Energy::untimed(1, 5.0, 50.0, (10.0, 5.0), Some(50.0), 0.02);
        assert_eq!(
            (one.seconds(), one.charge_mah(), one.nominal()),
            (0.0, 0.0, false)
        );
    }

    #[test]
    fn regenerative_current_gives_charge_back() {
        let mut e = Energy::new();
        e.add(Some(0.0), 10.0, 36.0);
        e.add(Some(0.1), 10.0, -36.0);
        e.add(Some(0.2), 10.0, 0.0);
        assert!(e.charge_mah().abs() < 1e-12);
        assert_eq!(e.peak_w(), Some(360.0));
    }

    #[test]
    fn raw_figures_scale_to_physical_ones() {
        let (mut raw, mut physical) = (Energy::new(), Energy::new());
        for (k, (v, i)) in [(251, 640), (250, -64), (249, 1280), (252, 0)]
            .iter()
            .enumerate()
        {
            let t = Some(k as f64 * 0.05);
            raw.add(t, f64::from(*v), f64::from(*i));
            physical.add(t, f64::from(*v) / 10.0, f64::from(*i) / 64.0);
        }
        let scaled = raw.scaled(0.1, 1.0 / 64.0);
        assert!((scaled.charge_mah() - physical.charge_mah()).abs() < 1e-12);
        assert!((scaled.energy_wh() - physical.energy_wh()).abs() < 1e-12);
        assert!((scaled.peak_w().unwrap() - physical.peak_w().unwrap()).abs() < 1e-9);
        assert!((scaled.mean_w().unwrap() - physical.mean_w().unwrap()).abs() < 1e-9);
        assert_eq!(scaled.seconds(), physical.seconds());
    }

    #[test]
    fn a_total_adds_charges_and_means() {
        let mut a = Energy::new();
        let mut b = Energy::new();
        for k in 0..=20 {
            a.add(Some(k as f64 * 0.05), 20.0, 10.0); // 200 W for 1 s
            b.add(Some(k as f64 * 0.05), 20.0, 5.0); // 100 W for 1 s
        }
        let mut total = Energy::new();
        total.merge(&a);
        total.merge(&b);
        assert!((total.charge_mah() - (a.charge_mah() + b.charge_mah())).abs() < 1e-9);
        assert!((total.mean_w().unwrap() - 300.0).abs() < 1e-9);
        assert!((total.energy_wh() - 300.0 / 3600.0).abs() < 1e-12);
        assert_eq!(total.peak_w(), Some(200.0));
        let empty = Energy::new();
        assert_eq!((empty.mean_w(), empty.peak_w()), (None, None));
    }
}
