//! Drift from a baseline: each ESC's current per rpm and rpm per throttle against the medians
//! its healthy flights gave ([`Baseline`]), judged on the median over a window. More current
//! for the same rpm points to a bearing or a motor going, or a heavier prop; less rpm for the
//! same throttle to a motor losing its grip (or a sagging battery).

use std::collections::BTreeMap;

use super::baseline::{RPM_BIN, THROTTLE_BIN_PCT};
use super::stats::sustained;
use super::{Analyser, Baseline, DriftConfig, EscSeries, Finding, Limits, Severity};

/// A baseline value below this is not compared with, A or rev/min (near idle, a ratio means
/// nothing).
const MIN_REFERENCE: [f64; 2] = [1.0, 100.0];

/// Throttle below which rpm per throttle is not judged, %.
const MIN_THROTTLE_PCT: f64 = 15.0;

/// Adds the findings of `series` against `baseline` to `out`.
pub(super) fn analyse(
    series: &[EscSeries],
    baseline: &Baseline,
    config: &DriftConfig,
    out: &mut Vec<Finding>,
) {
    for s in series {
        let Some(base) = baseline.esc.get(&s.esc.number.to_string()) else {
            continue;
        };
        let current = table(&base.rpm_bin, &base.current_a, RPM_BIN);
        let rpm = table(&base.throttle_pct, &base.rpm, THROTTLE_BIN_PCT);
        let current_points: Vec<(f64, f64)> = s
            .samples
            .iter()
            .filter_map(|x| {
                let r = f64::from(x.rpm?);
                let b = *current.get(&((r / RPM_BIN).floor() as i64))?;
                let i = f64::from(x.current_a?);
                (r > 0.0 && b >= MIN_REFERENCE[0]).then(|| (x.t, (i - b) / b * 100.0))
            })
            .collect();
        let rpm_points: Vec<(f64, f64)> = s
            .samples
            .iter()
            .filter_map(|x| {
                let throttle = f64::from(x.throttle_pct?);
                let b = *rpm.get(&((throttle / THROTTLE_BIN_PCT).floor() as i64))?;
                let r = f64::from(x.rpm?);
                (throttle >= MIN_THROTTLE_PCT && b >= MIN_REFERENCE[1])
                    .then(|| (x.t, (b - r) / b * 100.0))
            })
            .collect();
        for (name, points, limits, what) in [
            (
                "current_per_rpm",
                current_points,
                config.current_per_rpm_pct,
                "current per rpm above the baseline's",
            ),
            (
                "rpm_per_throttle",
                rpm_points,
                config.rpm_per_throttle_pct,
                "rpm per throttle below the baseline's",
            ),
        ] {
            if let Some(f) = judge(s, name, what, &points, limits, config.min_time_s) {
                out.push(f);
            }
        }
    }
}

/// A baseline curve by bin: lower edges `edges` of bins of `width`, and their values.
fn table(edges: &[f64], values: &[f64], width: f64) -> BTreeMap<i64, f64> {
    edges
        .iter()
        .zip(values)
        .map(|(&e, &v)| ((e / width).round() as i64, v))
        .collect()
}

/// The finding of one ESC's drift `points` `(t, %)`.
fn judge(
    series: &EscSeries,
    name: &str,
    what: &str,
    points: &[(f64, f64)],
    limits: Limits,
    window_s: f64,
) -> Option<Finding> {
    let s = sustained(points, window_s, limits.warn)?;
    let severity = limits.judge(s.worst);
    let mut f = Finding::about(Analyser::Drift, series)
        .value(name, s.worst, "%")
        .judged(severity, name, limits.crossed(severity), "%");
    f.window = s.span.filter(|_| severity > Severity::Ok);
    f.message = format!(
        "{what} by {:.0} % (median over {window_s} s){}",
        s.worst,
        match severity {
            Severity::Ok => format!(", within {} %", limits.warn),
            _ => format!(": at or beyond {} %", limits.crossed(severity)),
        }
    );
    Some(f)
}

#[cfg(test)]
mod tests {
    use super::super::tests::series_of;
    use super::super::{CheckConfig, Sample, analyse as analyse_all};
    use super::*;

    /// ESC 1 on a throttle staircase, drawing `factor` times the current from `from_s` on.
    fn flight(factor: f32, from_s: f64) -> Vec<EscSeries> {
        vec![series_of(
            1,
            (0..1200).map(|i| {
                let t = i as f64 * 0.05;
                let throttle = 20.0 + 10.0 * ((t / 6.0).floor() % 6.0) as f32;
                let rpm = 100.0 * throttle;
                let mut current = 0.6e-6 * rpm * rpm;
                if t >= from_s {
                    current *= factor;
                }
                Sample {
                    t,
                    throttle_pct: Some(throttle),
                    rpm: Some(rpm),
                    current_a: Some(current),
                    ..Sample::default()
                }
            }),
        )]
    }

    fn drift(series: &[EscSeries], baseline: &Baseline) -> Vec<Finding> {
        analyse_all(series, &CheckConfig::default(), Some(baseline))
            .into_iter()
            .filter(|f| f.analyser == Analyser::Drift)
            .collect()
    }

    #[test]
    fn a_flight_like_the_baseline_is_ok_and_more_current_per_rpm_is_found_when_it_starts() {
        let baseline = Baseline::fit(&flight(1.0, 0.0), None);
        assert!(!baseline.esc["1"].current_a.is_empty());
        let same = drift(&flight(1.0, 0.0), &baseline);
        assert_eq!(same.len(), 2);
        assert!(same.iter().all(|f| f.severity == Severity::Ok), "{same:?}");
        let worn = drift(&flight(1.25, 40.0), &baseline);
        let bad: Vec<_> = worn.iter().filter(|f| f.severity > Severity::Ok).collect();
        assert_eq!(bad.len(), 1, "{worn:?}");
        assert_eq!(bad[0].threshold.as_ref().unwrap().name, "current_per_rpm");
        let w = bad[0].window.unwrap();
        assert!(
            (38.0..=41.0).contains(&w.start_s) && w.end_s > 59.0,
            "{w:?}"
        );
    }

    #[test]
    fn an_esc_the_baseline_does_not_know_is_not_judged() {
        let mut other = flight(2.0, 0.0);
        other[0].esc.number = 7;
        assert!(drift(&other, &Baseline::fit(&flight(1.0, 0.0), None)).is_empty());
    }
}
