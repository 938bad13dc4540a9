//! The baseline an airframe's healthy flights give (`hwfoc check --fit-baseline`): per ESC, its
//! rpm per throttle and current per rpm (medians in bins), and the battery's internal
//! resistance, against which [`super::drift`] and [`super::battery`] judge later flights.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::EscSeries;
use super::stats::curve;

/// Width of a throttle bin, %.
pub(super) const THROTTLE_BIN_PCT: f64 = 5.0;

/// Width of an rpm bin, rev/min.
pub(super) const RPM_BIN: f64 = 500.0;

/// Samples a bin needs to be kept.
pub(super) const MIN_BIN_SAMPLES: usize = 20;

/// A curve of medians: `y` against `x`, by `x` (each point the medians of a bin of `x`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Curve {
    /// The points' `x`, rising.
    pub x: Vec<f64>,
    /// The points' `y`.
    pub y: Vec<f64>,
}

impl Curve {
    /// Its value at `x`: between two points at most `span` apart, on the line between them;
    /// else at a point within a tenth of `span`; else none.
    pub fn at(&self, x: f64, span: f64) -> Option<f64> {
        let i = self.x.partition_point(|&p| p < x);
        if i < self.x.len() && i > 0 {
            let (x0, x1) = (self.x[i - 1], self.x[i]);
            if x1 - x0 <= span {
                let f = if x1 > x0 { (x - x0) / (x1 - x0) } else { 0.0 };
                return Some(self.y[i - 1] + f * (self.y[i] - self.y[i - 1]));
            }
        }
        [i.checked_sub(1), Some(i)]
            .into_iter()
            .flatten()
            .filter(|&j| j < self.x.len() && (self.x[j] - x).abs() <= span / 10.0)
            .map(|j| self.y[j])
            .next()
    }
}

/// One ESC's healthy behaviour, at a steady throttle.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EscBaseline {
    /// Rpm against throttle (%), in bins of 5 %.
    pub rpm_by_throttle: Curve,
    /// Current (A) against rpm, in bins of 500 rev/min.
    pub current_by_rpm: Curve,
}

/// An airframe's baseline: each ESC's (by its position: [`super::EscId::position`]), and its
/// battery's internal resistance.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Baseline {
    /// How many recordings it was fitted from.
    pub recordings: usize,
    /// The battery's internal resistance per cell, milliohm (median over the recordings).
    pub resistance_mohm_per_cell: Option<f64>,
    /// Each ESC's, by its position (its port, and its place on a hub or bus).
    pub esc: BTreeMap<String, EscBaseline>,
}

impl Baseline {
    /// The baseline of `series`, healthy flights: each ESC's samples at a steady throttle, of
    /// every recording together.
    pub fn fit(series: &[EscSeries], cells: Option<u32>) -> Baseline {
        let mut by_esc: BTreeMap<&str, Vec<&EscSeries>> = BTreeMap::new();
        for s in series {
            by_esc.entry(s.esc.position.as_str()).or_default().push(s);
        }
        let esc = by_esc
            .into_iter()
            .map(|(n, list)| {
                let steady: Vec<Vec<super::Sample>> = list
                    .iter()
                    .map(|s| super::stats::steady(&s.samples))
                    .collect();
                let samples = || steady.iter().flatten();
                let b = EscBaseline {
                    rpm_by_throttle: curve(
                        samples()
                            .filter_map(|s| Some((f64::from(s.throttle_pct?), f64::from(s.rpm?)))),
                        THROTTLE_BIN_PCT,
                        MIN_BIN_SAMPLES,
                    ),
                    current_by_rpm: curve(
                        samples()
                            .filter(|s| s.rpm.is_some_and(|r| r > 0.0))
                            .filter_map(|s| Some((f64::from(s.rpm?), f64::from(s.current_a?)))),
                        RPM_BIN,
                        MIN_BIN_SAMPLES,
                    ),
                };
                (n.to_string(), b)
            })
            .collect();
        let recordings: std::collections::BTreeSet<&str> =
            series.iter().map(|s| s.recording.as_str()).collect();
        Baseline {
            recordings: recordings.len(),
            resistance_mohm_per_cell: super::battery::median_resistance(series, cells),
            esc,
        }
    }
}
