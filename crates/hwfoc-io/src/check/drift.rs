//! The drift analyser (`docs/CHECKS.md`).

use super::{Baseline, DriftConfig, EscSeries, Finding};

/// Adds the findings of `series` against `baseline` to `out`.
pub(super) fn analyse(
    series: &[EscSeries],
    baseline: &Baseline,
    config: &DriftConfig,
    out: &mut Vec<Finding>,
) {
    let _ = (series, baseline, config, out);
}
