//! Drift from a baseline: each ESC's current per rpm and rpm per throttle against the medians
//! its healthy flights gave ([`Baseline`]), at a steady throttle. In each window of time the ESC's medians per bin
//! are compared with the baseline's; the window's drift is the median over its bins, and it
//! must hold in two windows in a row. More current for the same rpm points to a bearing or a
//! motor going, or a heavier prop; rpm per throttle away from the baseline's to a damaged
//! (lighter) prop, or a motor losing its grip (or a sagging battery).

use super::baseline::{RPM_BIN, THROTTLE_BIN_PCT};
use super::stats::{curve, held_finding, median, steady, windows};
use super::{Analyser, Baseline, DriftConfig, EscSeries, Finding, Sample, Span};

/// A baseline value below this is not compared with, A or rev/min (near idle, a ratio means
/// nothing).
const MIN_REFERENCE: [f64; 2] = [1.0, 100.0];

/// Throttle below which rpm per throttle is not judged, %.
const MIN_THROTTLE_PCT: f64 = 15.0;

/// Samples a bin of a window needs.
const MIN_BIN_SAMPLES: usize = 5;

/// How one curve is read from a sample: `(x, y)`.
type Point = fn(&Sample) -> Option<(f64, f64)>;

/// Adds the findings of `series` against `baseline` to `out`.
pub(super) fn analyse(
    series: &[EscSeries],
    baseline: &Baseline,
    config: &DriftConfig,
    out: &mut Vec<Finding>,
) {
    for s in series {
        let Some(base) = baseline.esc.get(&s.esc.position) else {
            continue;
        };
        let steady = steady(&s.samples);
        let current_per_rpm: Point = |x| {
            let rpm = f64::from(x.rpm?);
            (rpm > 0.0).then_some((rpm, f64::from(x.current_a?)))
        };
        let rpm_per_throttle: Point = |x| {
            let throttle = f64::from(x.throttle_pct?);
            (throttle >= MIN_THROTTLE_PCT).then_some((throttle, f64::from(x.rpm?)))
        };
        for (name, point, reference, width, min_ref, both_ways, limits, what) in [
            (
                "current_per_rpm",
                current_per_rpm,
                &base.current_by_rpm,
                RPM_BIN,
                MIN_REFERENCE[0],
                false,
                config.current_per_rpm_pct,
                "current per rpm above the baseline's",
            ),
            (
                "rpm_per_throttle",
                rpm_per_throttle,
                &base.rpm_by_throttle,
                THROTTLE_BIN_PCT,
                MIN_REFERENCE[1],
                true,
                config.rpm_per_throttle_pct,
                "rpm per throttle away from the baseline's",
            ),
        ] {
            let drifts: Vec<(Span, f64)> = windows(&steady, config.window_s)
                .filter_map(|(span, samples)| {
                    let mine = curve(samples.iter().filter_map(point), width, MIN_BIN_SAMPLES);
                    let mut devs: Vec<f64> = mine
                        .x
                        .iter()
                        .zip(&mine.y)
                        .filter_map(|(&x, &v)| {
                            let r = reference.at(x, 2.0 * width)?;
                            let d = (v - r) / r * 100.0;
                            (r >= min_ref).then_some(if both_ways { d.abs() } else { d })
                        })
                        .collect();
                    Some((span, median(&mut devs)?))
                })
                .collect();
            let f = held_finding(
                Analyser::Drift,
                s,
                name,
                &drifts,
                limits,
                config.window_s,
                |d| format!("{what} by {d:.0} %"),
            );
            if let Some(f) = f {
                out.push(f);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::series_of;
    use super::super::{CheckConfig, Severity, analyse as analyse_all};
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
        assert!(!baseline.esc["esc-1"].current_by_rpm.y.is_empty());
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
        other[0].esc.position = "esc-7".to_string();
        assert!(drift(&other, &Baseline::fit(&flight(1.0, 0.0), None)).is_empty());
    }
}
