//! The battery analyser (`docs/CHECKS.md`).

use super::{Baseline, BatteryConfig, EscSeries, Finding};

/// Adds the findings of each recording in `series` to `out`.
pub(super) fn analyse(
    series: &[EscSeries],
    config: &BatteryConfig,
    baseline: Option<&Baseline>,
    out: &mut Vec<Finding>,
) {
    let _ = (series, config, baseline, out);
}

/// The median over the recordings of `series` of the internal resistance per cell, milliohm.
pub(super) fn median_resistance(series: &[EscSeries], cells: Option<u32>) -> Option<f64> {
    let _ = (series, cells);
    None
}
