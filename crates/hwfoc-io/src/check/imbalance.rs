//! The imbalance analyser (`docs/CHECKS.md`).

use super::{EscSeries, Finding, ImbalanceConfig};

/// Adds the findings of each recording's ESCs in `series` to `out`.
pub(super) fn analyse(series: &[EscSeries], config: &ImbalanceConfig, out: &mut Vec<Finding>) {
    let _ = (series, config, out);
}
