//! The baseline an airframe's healthy flights give (`hwfoc check --fit-baseline`): per ESC, its
//! rpm per throttle and current per rpm (medians in bins), and the battery's internal
//! resistance, against which [`super::drift`] and [`super::battery`] judge later flights.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::EscSeries;
use super::stats::binned_medians;

/// Width of a throttle bin, %.
pub(super) const THROTTLE_BIN_PCT: f64 = 5.0;

/// Width of an rpm bin, rev/min.
pub(super) const RPM_BIN: f64 = 500.0;

/// Samples a bin needs to be kept.
pub(super) const MIN_BIN_SAMPLES: usize = 20;

/// One ESC's healthy behaviour.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EscBaseline {
    /// Lower edges of the throttle bins, % (of width 5).
    pub throttle_pct: Vec<f64>,
    /// The median rpm in each throttle bin.
    pub rpm: Vec<f64>,
    /// Lower edges of the rpm bins, rev/min (of width 500).
    pub rpm_bin: Vec<f64>,
    /// The median current in each rpm bin, A.
    pub current_a: Vec<f64>,
}

/// An airframe's baseline: each ESC's (by ESC number), and its battery's internal resistance.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Baseline {
    /// How many recordings it was fitted from.
    pub recordings: usize,
    /// The battery's internal resistance per cell, milliohm (median over the recordings).
    pub resistance_mohm_per_cell: Option<f64>,
    /// Each ESC's, by its number.
    pub esc: BTreeMap<String, EscBaseline>,
}

impl Baseline {
    /// The baseline of `series`, healthy flights: each ESC's samples of every recording
    /// together.
    pub fn fit(series: &[EscSeries], cells: Option<u32>) -> Baseline {
        let mut by_esc: BTreeMap<usize, Vec<&EscSeries>> = BTreeMap::new();
        for s in series {
            by_esc.entry(s.esc.number).or_default().push(s);
        }
        let esc = by_esc
            .into_iter()
            .map(|(n, list)| {
                let samples = || list.iter().flat_map(|s| s.samples.iter());
                let rpm = binned_medians(
                    samples().filter_map(|s| Some((f64::from(s.throttle_pct?), f64::from(s.rpm?)))),
                    THROTTLE_BIN_PCT,
                    MIN_BIN_SAMPLES,
                );
                let current = binned_medians(
                    samples()
                        .filter(|s| s.rpm.is_some_and(|r| r > 0.0))
                        .filter_map(|s| Some((f64::from(s.rpm?), f64::from(s.current_a?)))),
                    RPM_BIN,
                    MIN_BIN_SAMPLES,
                );
                let b = EscBaseline {
                    throttle_pct: rpm
                        .iter()
                        .map(|&(k, _)| k as f64 * THROTTLE_BIN_PCT)
                        .collect(),
                    rpm: rpm.iter().map(|&(_, v)| v).collect(),
                    rpm_bin: current.iter().map(|&(k, _)| k as f64 * RPM_BIN).collect(),
                    current_a: current.iter().map(|&(_, v)| v).collect(),
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
