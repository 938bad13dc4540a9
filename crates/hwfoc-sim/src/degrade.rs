//! Degradations: slow or partial failures of a motor, propeller, battery, telemetry wire or
//! power stage, for testing analysers against a known truth. Each acts on one ESC from a start
//! time on, at a severity from 0 (none) to 1 (the strongest the simulator makes):
//!
//! - `bearing`: the motor needs more current for the same RPM (a worn bearing, a failing
//!   winding): input current × (1 + SEVERITY) while motoring.
//! - `prop`: a damaged propeller, lighter than its siblings': RPM × (1 + 0.2 × SEVERITY) and
//!   input current × (1 − 0.5 × SEVERITY) for the load at that RPM (the load rising with RPM
//!   cubed: about 14 % less current at full severity), at equal throttle, with a
//!   once-per-revolution ripple of ±10 % × SEVERITY on the current (vibration).
//! - `battery`: a weak battery: internal and polarisation resistance × (1 + SEVERITY), so the
//!   voltage sags more per ampere.
//! - `wire`: a loose telemetry wire: bursts of 5 to 20 frames lost on the wire (their packet
//!   numbers used all the same), each frame starting a burst with probability
//!   0.1 × SEVERITY; the model is not affected. HW-FOC only.
//! - `heat`: a slow heat build-up (failing cooling): the MOSFETs' temperature (and, through
//!   their coupling, the capacitors') rises by up to [`HEAT_RISE_K`] × SEVERITY, linearly over
//!   [`HEAT_RAMP_S`] from the start.

use std::fmt;
use std::str::FromStr;

use crate::rng::Rng;

/// Severity when a spec gives none.
pub const DEFAULT_SEVERITY: f64 = 0.5;
/// `prop`: RPM gain at full severity.
pub const PROP_RPM: f64 = 0.2;
/// `prop`: share of the current lost at full severity.
pub const PROP_CURRENT: f64 = 0.5;
/// `prop`: amplitude of the once-per-revolution current ripple at full severity.
pub const PROP_RIPPLE: f64 = 0.1;
/// `wire`: probability per frame of a burst of loss starting, at full severity.
pub const WIRE_BURST: f64 = 0.1;
/// `wire`: shortest and longest burst, frames.
pub const WIRE_BURST_FRAMES: (u64, u64) = (5, 20);
/// `heat`: the MOSFETs' extra temperature rise at full severity, K.
pub const HEAT_RISE_K: f64 = 80.0;
/// `heat`: seconds over which the extra rise builds up.
pub const HEAT_RAMP_S: f64 = 600.0;

/// What degrades.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DegradeKind {
    /// More current for the same RPM.
    Bearing,
    /// A damaged propeller: RPM and current off its siblings', with ripple.
    Prop,
    /// Higher battery resistance: more sag per ampere.
    Battery,
    /// Bursts of frames lost on the telemetry wire.
    Wire,
    /// Temperatures rising over minutes.
    Heat,
}

impl DegradeKind {
    /// Every kind.
    pub const ALL: [DegradeKind; 5] = [
        DegradeKind::Bearing,
        DegradeKind::Prop,
        DegradeKind::Battery,
        DegradeKind::Wire,
        DegradeKind::Heat,
    ];

    /// Its name, as written in a spec and in the truth.
    pub fn name(self) -> &'static str {
        match self {
            DegradeKind::Bearing => "bearing",
            DegradeKind::Prop => "prop",
            DegradeKind::Battery => "battery",
            DegradeKind::Wire => "wire",
            DegradeKind::Heat => "heat",
        }
    }
}

impl fmt::Display for DegradeKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One degradation, written `ESC:KIND[@START][=SEVERITY]` (`hwfoc simulate --degrade`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DegradeSpec {
    /// The ESC index.
    pub esc: usize,
    /// What degrades.
    pub kind: DegradeKind,
    /// Seconds of simulated time from which it acts (0 without `@START`).
    pub start_s: f64,
    /// From 0 to 1 ([`DEFAULT_SEVERITY`] without `=SEVERITY`).
    pub severity: f64,
}

impl DegradeSpec {
    /// The record of the ground truth that names it: one JSON object on one line.
    pub fn truth_line(&self) -> String {
        format!(
            "{{\"degradation\":{{\"esc\":{},\"kind\":\"{}\",\"start_s\":{},\"severity\":{}}}}}\n",
            self.esc, self.kind, self.start_s, self.severity
        )
    }
}

impl FromStr for DegradeSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let (rest, severity) = match s.split_once('=') {
            Some((rest, sev)) => {
                let severity = sev
                    .parse::<f64>()
                    .ok()
                    .filter(|v| (0.0..=1.0).contains(v))
                    .ok_or_else(|| format!("{s:?}: bad severity {sev:?} (from 0 to 1)"))?;
                (rest, severity)
            }
            None => (s, DEFAULT_SEVERITY),
        };
        let (head, start_s) = match rest.split_once('@') {
            Some((head, start)) => {
                let start_s = start
                    .parse::<f64>()
                    .ok()
                    .filter(|t| t.is_finite() && *t >= 0.0)
                    .ok_or_else(|| format!("{s:?}: bad start {start:?} (seconds, 0 or more)"))?;
                (head, start_s)
            }
            None => (rest, 0.0),
        };
        let (esc, name) = head.split_once(':').ok_or_else(|| {
            format!("{s:?}: expected ESC:KIND[@START][=SEVERITY], e.g. 1:bearing@30=0.4")
        })?;
        let esc = esc
            .parse::<usize>()
            .map_err(|_| format!("{s:?}: bad ESC index {esc:?}"))?;
        let kind = DegradeKind::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| {
                let names: Vec<&str> = DegradeKind::ALL.iter().map(|k| k.name()).collect();
                format!(
                    "{s:?}: unknown degradation {name:?}; the kinds are {}",
                    names.join(", ")
                )
            })?;
        Ok(DegradeSpec {
            esc,
            kind,
            start_s,
            severity,
        })
    }
}

/// The degradations of one ESC's model, as the model steps through time.
#[derive(Debug, Clone, Default)]
pub struct ModelDegradations {
    specs: Vec<DegradeSpec>,
    /// Simulated seconds so far.
    clock_s: f64,
    /// Rotor angle, revolutions (for the propeller's ripple).
    turns: f64,
}

impl ModelDegradations {
    /// The degradations of `specs` on ESC `esc` that act on the model (all but `wire`).
    pub fn for_esc(specs: &[DegradeSpec], esc: usize) -> ModelDegradations {
        ModelDegradations {
            specs: specs
                .iter()
                .filter(|s| s.esc == esc && s.kind != DegradeKind::Wire)
                .copied()
                .collect(),
            ..Default::default()
        }
    }

    /// Advances the clock by `dt` seconds, the rotor turning at `rpm`.
    pub fn advance(&mut self, dt: f64, rpm: f64) {
        if self.specs.is_empty() {
            return;
        }
        self.clock_s += dt;
        self.turns = (self.turns + rpm / 60.0 * dt).fract();
    }

    /// The severity of `kind` if it acts now (the strongest, if given twice).
    fn active(&self, kind: DegradeKind) -> Option<&DegradeSpec> {
        self.specs
            .iter()
            .filter(|s| s.kind == kind && self.clock_s >= s.start_s)
            .max_by(|a, b| a.severity.total_cmp(&b.severity))
    }

    /// Factor on the target RPM.
    pub fn rpm_factor(&self) -> f64 {
        self.active(DegradeKind::Prop)
            .map_or(1.0, |s| 1.0 + PROP_RPM * s.severity)
    }

    /// Factor on the input current while motoring.
    pub fn current_factor(&self) -> f64 {
        let bearing = self
            .active(DegradeKind::Bearing)
            .map_or(1.0, |s| 1.0 + s.severity);
        let prop = self.active(DegradeKind::Prop).map_or(1.0, |s| {
            let ripple = (self.turns * std::f64::consts::TAU).sin();
            (1.0 - PROP_CURRENT * s.severity) * (1.0 + PROP_RIPPLE * s.severity * ripple)
        });
        bearing * prop
    }

    /// Factor on the battery's resistances.
    pub fn resistance_factor(&self) -> f64 {
        self.active(DegradeKind::Battery)
            .map_or(1.0, |s| 1.0 + s.severity)
    }

    /// Extra MOSFET temperature rise, K.
    pub fn extra_heat_k(&self) -> f64 {
        self.active(DegradeKind::Heat).map_or(0.0, |s| {
            HEAT_RISE_K * s.severity * ((self.clock_s - s.start_s) / HEAT_RAMP_S).min(1.0)
        })
    }
}

/// A loose telemetry wire: which frames are lost, from its own random stream.
#[derive(Debug, Clone)]
pub struct WireLoss {
    spec: Option<DegradeSpec>,
    rng: Rng,
    /// Frames still to lose in the current burst.
    remaining: u64,
}

impl WireLoss {
    /// The `wire` degradation of `specs` on ESC `esc` (the strongest, if given twice), drawing
    /// from `rng`.
    pub fn for_esc(specs: &[DegradeSpec], esc: usize, rng: Rng) -> WireLoss {
        WireLoss {
            spec: specs
                .iter()
                .filter(|s| s.esc == esc && s.kind == DegradeKind::Wire)
                .max_by(|a, b| a.severity.total_cmp(&b.severity))
                .copied(),
            rng,
            remaining: 0,
        }
    }

    /// Whether the frame due at `t_s` seconds is lost.
    pub fn lost(&mut self, t_s: f64) -> bool {
        let Some(spec) = self.spec.filter(|s| t_s >= s.start_s) else {
            return false;
        };
        if self.remaining == 0 && self.rng.chance(WIRE_BURST * spec.severity) {
            let (short, long) = WIRE_BURST_FRAMES;
            self.remaining = short + self.rng.below(long - short + 1);
        }
        if self.remaining > 0 {
            self.remaining -= 1;
            return true;
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Purpose;

    #[test]
    fn degrade_specs() {
        let d: DegradeSpec = "1:bearing@30=0.4".parse().unwrap();
        assert_eq!(
            d,
            DegradeSpec {
                esc: 1,
                kind: DegradeKind::Bearing,
                start_s: 30.0,
                severity: 0.4
            }
        );
        let d: DegradeSpec = "0:heat".parse().unwrap();
        assert_eq!((d.start_s, d.severity), (0.0, DEFAULT_SEVERITY));
        let d: DegradeSpec = "2:wire=1".parse().unwrap();
        assert_eq!(
            (d.kind, d.start_s, d.severity),
            (DegradeKind::Wire, 0.0, 1.0)
        );
        assert_eq!(
            d.truth_line(),
            "{\"degradation\":{\"esc\":2,\"kind\":\"wire\",\"start_s\":0,\"severity\":1}}\n"
        );
        for (bad, why) in [
            ("bearing", "expected ESC:KIND[@START][=SEVERITY]"),
            ("x:bearing", "bad ESC index \"x\""),
            (
                "0:rust",
                "unknown degradation \"rust\"; the kinds are bearing, prop,",
            ),
            ("0:prop@-1", "bad start \"-1\""),
            ("0:prop@x=0.5", "bad start \"x\""),
            ("0:prop=1.5", "bad severity \"1.5\" (from 0 to 1)"),
            ("0:prop=NaN", "bad severity \"NaN\""),
        ] {
            let e = bad.parse::<DegradeSpec>().unwrap_err();
            assert!(e.contains(why), "{bad}: {e}");
            assert!(e.starts_with(&format!("{bad:?}")), "{e}");
        }
    }

    #[test]
    fn wire_loss_comes_in_bursts_after_the_start() {
        let specs = ["0:wire@10=0.5".parse::<DegradeSpec>().unwrap()];
        let mut wire = WireLoss::for_esc(&specs, 0, Rng::for_esc(1, 0, Purpose::Wire));
        let lost: Vec<bool> = (0..4000).map(|i| wire.lost(f64::from(i) * 0.05)).collect();
        assert!(lost[..200].iter().all(|l| !l), "nothing lost before 10 s");
        let after = &lost[200..];
        let n_lost = after.iter().filter(|l| **l).count();
        let bursts = after.windows(2).filter(|w| !w[0] && w[1]).count();
        // Per frame 0.05 to start a burst of 12.5 on average: about 38 % lost.
        assert!((1000..1800).contains(&n_lost), "{n_lost}");
        assert!(n_lost / bursts >= 5, "{n_lost} in {bursts} bursts");
        let mut other = WireLoss::for_esc(&specs, 1, Rng::for_esc(1, 1, Purpose::Wire));
        assert!((0..4000).all(|i| !other.lost(f64::from(i) * 0.05)));
    }
}
