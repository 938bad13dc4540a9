//! The heat analyser (`docs/CHECKS.md`).

use super::{EscSeries, Finding};

/// Adds the findings of `series` to `out`.
pub(super) fn analyse(
    series: &EscSeries,
    config: &super::config::HeatConfig,
    out: &mut Vec<Finding>,
) {
    let _ = (series, config, out);
}
