//! Runtime: motor-on hours (time with rpm above zero) in the inputs, with the hours the ESC had
//! run since its last service before them (`hours_before`), against a service interval. A
//! Hobbywing CAN ESC counts its own time since maintenance: where its recording holds its
//! answer to GetMaintenanceInformation (`hwfoc can list`, a DataLink or a GCS asked), that
//! counter is judged instead.

use super::{Analyser, EscSeries, Finding, Limits, RuntimeConfig, Sample};

/// A gap longer than this adds no motor-on time, s.
const MAX_STEP_S: f64 = 1.0;

/// How far past the interval is critical: 1.5 times it.
const CRITICAL_FACTOR: f64 = 1.5;

/// Adds the finding of `series`'s motor-on time to `out`.
pub(super) fn analyse(series: &EscSeries, config: &RuntimeConfig, out: &mut Vec<Finding>) {
    if !series.samples.iter().any(|s| s.rpm.is_some()) && series.maintenance_min.is_none() {
        return;
    }
    let on_s = motor_on_s(&series.samples);
    let counted = series
        .maintenance_min
        .map(|(total, since)| (f64::from(total) / 60.0, f64::from(since) / 60.0));
    let hours = match counted {
        Some((_, since_h)) => since_h,
        None => config.hours_before + on_s / 3600.0,
    };
    let limits = Limits::new(
        config.service_interval_h,
        config.service_interval_h * CRITICAL_FACTOR,
    );
    let severity = limits.judge(hours);
    let mut f = Finding::about(Analyser::Runtime, series)
        .value("motor_on", on_s, "s")
        .value("hours_since_service", hours, "h");
    if let Some((total_h, _)) = counted {
        f = f.value("esc_total_rotation", total_h, "h");
    }
    let mut f = f.judged(
        severity,
        "hours_since_service",
        limits.crossed(severity),
        "h",
    );
    let source = match counted {
        Some((total_h, _)) => format!(
            " by the ESC's own counter ({total_h:.2} h turned in all; GetMaintenanceInformation)"
        ),
        None if config.hours_before > 0.0 => {
            format!(" ({} h before these inputs)", config.hours_before)
        }
        None => String::new(),
    };
    f.message = format!(
        "motor on {on_s:.0} s; {hours:.2} h since its last service{source}, service every {} h",
        config.service_interval_h
    );
    out.push(f);
}

/// Seconds during which the motor turned: each frame with rpm above zero holds until the next
/// (at most a second).
fn motor_on_s(samples: &[Sample]) -> f64 {
    samples
        .windows(2)
        .filter(|w| w[0].rpm.is_some_and(|r| r > 0.0))
        .map(|w| (w[1].t - w[0].t).clamp(0.0, MAX_STEP_S))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::super::Severity;
    use super::super::tests::series_of;
    use super::*;

    #[test]
    fn motor_on_time_counts_turning_frames_and_is_judged_with_the_hours_before() {
        // 60 s, turning from 10 to 40 s.
        let series = series_of(
            0,
            (0..1200).map(|i| {
                let t = i as f64 * 0.05;
                Sample {
                    t,
                    rpm: Some(if (10.0..40.0).contains(&t) {
                        3000.0
                    } else {
                        0.0
                    }),
                    ..Sample::default()
                }
            }),
        );
        let mut out = Vec::new();
        analyse(&series, &RuntimeConfig::default(), &mut out);
        assert!((out[0].values[0].value - 30.0).abs() < 0.06, "{out:?}");
        assert_eq!(out[0].severity, Severity::Ok);
        let due = RuntimeConfig {
            hours_before: 49.995,
            ..RuntimeConfig::default()
        };
        analyse(&series, &due, &mut out);
        assert_eq!(out[1].severity, Severity::Warning, "{out:?}");
    }

    #[test]
    fn a_can_esc_s_own_counter_is_judged_instead_of_the_hours_before() {
        let idle = |maintenance_min| {
            let mut s = series_of(
                0,
                (0..100).map(|i| Sample {
                    t: f64::from(i) * 0.05,
                    rpm: Some(0.0),
                    ..Sample::default()
                }),
            );
            s.maintenance_min = maintenance_min;
            s
        };
        let config = RuntimeConfig {
            hours_before: 49.995,
            ..RuntimeConfig::default()
        };
        let mut out = Vec::new();
        // 55 h since maintenance (3300 min) of 100 h turned: over the 50 h interval.
        analyse(
            &idle(Some((6000, 3300))),
            &RuntimeConfig::default(),
            &mut out,
        );
        // Just serviced (0 min): ok, whatever `hours_before` says.
        analyse(&idle(Some((6000, 0))), &config, &mut out);
        assert_eq!(out[0].severity, Severity::Warning, "{out:?}");
        assert_eq!(out[0].values[1].value, 55.0);
        assert_eq!(out[0].values[2].name, "esc_total_rotation");
        assert_eq!(out[0].values[2].value, 100.0);
        assert!(
            out[0].message.contains("ESC's own counter"),
            "{}",
            out[0].message
        );
        assert_eq!(out[1].severity, Severity::Ok, "{out:?}");
        // 76 h: past 1.5 times the interval.
        analyse(&idle(Some((6000, 76 * 60))), &config, &mut out);
        assert_eq!(out[2].severity, Severity::Critical, "{out:?}");
    }
}
