//! Heat: the MOSFET's, the capacitor's and the motor's temperature, judged on the peak, the
//! 95th percentile, the time at or above the warning limit and the rate of rise near the limit
//! (never on the mean: a short flight's mean hides its peak).

use super::stats::{percentile, rolling_median};
use super::{Analyser, EscSeries, Finding, HeatConfig, Limits, Sample, Severity, Span};

/// The window of the rate of rise, s.
const RISE_WINDOW_S: f64 = 60.0;

/// The shortest window a rate of rise is judged over, s.
const MIN_RISE_WINDOW_S: f64 = 20.0;

/// How far below the warning limit a rise starts to count, °C: a cold ESC warms fast, and that
/// is no finding.
const RISE_MARGIN_C: f64 = 25.0;

/// The window of the rolling median a rate of rise is computed on, s: a glitch or a peak of a
/// few seconds is no rise.
const SMOOTH_S: f64 = 5.0;

/// A gap longer than this adds no time above a limit, s.
const MAX_STEP_S: f64 = 1.0;

/// A temperature: its name, how it is read, its limits.
type Sensor = (&'static str, fn(&Sample) -> Option<f32>, Limits);

/// Adds a finding per temperature of `series` to `out`.
pub(super) fn analyse(series: &EscSeries, config: &HeatConfig, out: &mut Vec<Finding>) {
    let sensors: [Sensor; 3] = [
        ("mos_temp_c", |s| s.mos_temp_c, config.mos_c),
        ("cap_temp_c", |s| s.cap_temp_c, config.cap_c),
        ("motor_temp_c", |s| s.motor_temp_c, config.motor_c),
    ];
    for (name, get, limits) in sensors {
        let points: Vec<(f64, f64)> = series
            .samples
            .iter()
            .filter_map(|s| Some((s.t, f64::from(get(s)?))))
            .collect();
        if !points.is_empty() {
            out.push(judge(series, name, &points, limits, config));
        }
    }
}

/// The finding of one temperature, `points` `(t, °C)`.
fn judge(
    series: &EscSeries,
    name: &str,
    points: &[(f64, f64)],
    limits: Limits,
    config: &HeatConfig,
) -> Finding {
    let peak = points.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    let p95 = percentile(&mut points.iter().map(|p| p.1).collect::<Vec<_>>(), 95.0).unwrap_or(peak);
    let mut above_s = 0.0;
    for w in points.windows(2) {
        if w[0].1 >= limits.warn {
            above_s += (w[1].0 - w[0].0).clamp(0.0, MAX_STEP_S);
        }
    }
    let smooth: Vec<(f64, f64)> = rolling_median(points, SMOOTH_S)
        .into_iter()
        .map(|(_, t, m)| (t, m))
        .collect();
    let (rise, rise_span) = rise(&smooth, limits.warn - RISE_MARGIN_C);
    let sustained = Limits::new(config.sustained_s, config.sustained_s * 12.0);
    let judged = [
        (
            limits.judge(peak),
            "peak",
            limits.crossed(limits.judge(peak)),
            "degC",
        ),
        (
            limits.judge(p95),
            "p95",
            limits.crossed(limits.judge(p95)),
            "degC",
        ),
        (
            sustained.judge(above_s),
            "time_above_warn",
            sustained.crossed(sustained.judge(above_s)),
            "s",
        ),
        (
            config.rise_c_per_min.judge(rise),
            "rise",
            config
                .rise_c_per_min
                .crossed(config.rise_c_per_min.judge(rise)),
            "degC/min",
        ),
    ];
    // The worst judgement; among equals the first (the peak before the others).
    let worst = judged
        .iter()
        .fold(&judged[0], |w, j| if j.0 > w.0 { j } else { w });
    let (severity, what, limit, unit) = *worst;
    let window = match what {
        "rise" => rise_span,
        _ => span_at_or_above(points, limits.warn),
    };
    let quantity = name.trim_end_matches("_temp_c");
    let message = match severity {
        Severity::Ok => format!(
            "{quantity} temperature peak {peak:.0} °C, within {:.0} °C",
            limits.warn
        ),
        _ => format!(
            "{quantity} temperature: {what} {:.1} {unit} at or beyond {limit} {unit} (peak {peak:.0} °C, 95th percentile {p95:.0} °C, {above_s:.1} s at or above {:.0} °C)",
            match what {
                "peak" => peak,
                "p95" => p95,
                "time_above_warn" => above_s,
                _ => rise,
            },
            limits.warn
        ),
    };
    let mut f = Finding::about(Analyser::Heat, series)
        .value(&format!("{quantity}_peak"), peak, "degC")
        .value(&format!("{quantity}_p95"), p95, "degC")
        .value(&format!("{quantity}_time_above_warn"), above_s, "s")
        .value(&format!("{quantity}_rise"), rise, "degC/min")
        .judged(severity, &format!("{quantity}_{what}"), limit, unit);
    f.window = if severity == Severity::Ok {
        None
    } else {
        window
    };
    f.message = message;
    f
}

/// The fastest rise of `points` (smoothed) over a minute (or, in a shorter series, over all of it, if it
/// spans 20 s), in °C per minute, counted where the temperature reached is `from` or more; and
/// its window.
fn rise(points: &[(f64, f64)], from: f64) -> (f64, Option<Span>) {
    let mut best = (0.0, None);
    let mut start = 0;
    for (i, &(t, v)) in points.iter().enumerate() {
        while points[start].0 < t - RISE_WINDOW_S {
            start += 1;
        }
        let (t0, v0) = points[start];
        if i == start || t - t0 < MIN_RISE_WINDOW_S || v < from {
            continue;
        }
        let rate = (v - v0) / (t - t0) * 60.0;
        if rate > best.0 {
            best = (
                rate,
                Some(Span {
                    start_s: t0,
                    end_s: t,
                }),
            );
        }
    }
    best
}

/// From the first to the last point at or above `limit`.
fn span_at_or_above(points: &[(f64, f64)], limit: f64) -> Option<Span> {
    let first = points.iter().find(|p| p.1 >= limit)?;
    let last = points.iter().rev().find(|p| p.1 >= limit)?;
    Some(Span {
        start_s: first.0,
        end_s: last.0,
    })
}

#[cfg(test)]
mod tests {
    use super::super::tests::series_of;
    use super::*;

    fn temps(f: impl Fn(f64) -> f32) -> EscSeries {
        series_of(
            0,
            (0..2400).map(|i| {
                let t = i as f64 * 0.05;
                Sample {
                    t,
                    mos_temp_c: Some(f(t)),
                    ..Sample::default()
                }
            }),
        )
    }

    fn heat(series: &EscSeries) -> Finding {
        let mut out = Vec::new();
        analyse(series, &HeatConfig::default(), &mut out);
        assert_eq!(out.len(), 1);
        out.remove(0)
    }

    #[test]
    fn a_warm_esc_is_ok_and_a_cold_one_warming_fast_is_no_rise() {
        // 25 °C to 60 °C in the first 30 s, then steady: fast, but far from the limit.
        let f = heat(&temps(|t| (25.0 + 35.0 * (t / 30.0).min(1.0)) as f32));
        assert_eq!(f.severity, Severity::Ok, "{f:?}");
        assert_eq!(f.values[0].value, 60.0);
    }

    #[test]
    fn a_short_peak_above_the_limit_is_a_warning_in_its_window_though_the_mean_is_low() {
        // 40 °C, but 100 °C from 50 to 52 s.
        let f = heat(&temps(|t| {
            if (50.0..52.0).contains(&t) {
                100.0
            } else {
                40.0
            }
        }));
        assert_eq!(f.severity, Severity::Warning, "{f:?}");
        assert_eq!(f.threshold.as_ref().unwrap().name, "mos_peak");
        let w = f.window.unwrap();
        assert!(
            (49.9..=50.1).contains(&w.start_s) && (51.8..=52.0).contains(&w.end_s),
            "{w:?}"
        );
    }

    #[test]
    fn a_peak_beyond_the_critical_limit_is_critical() {
        let f = heat(&temps(|t| if t > 100.0 { 120.0 } else { 50.0 }));
        assert_eq!(f.severity, Severity::Critical, "{f:?}");
    }

    #[test]
    fn a_steep_rise_near_the_limit_is_a_warning() {
        // 40 °C to 90 °C (below the limit) over the last minute: 50 °C a minute.
        let f = heat(&temps(|t| {
            (40.0 + 50.0 * ((t - 60.0) / 60.0).max(0.0)) as f32
        }));
        assert_eq!(f.severity, Severity::Warning, "{f:?}");
        assert_eq!(f.threshold.as_ref().unwrap().name, "mos_rise");
        assert!(f.window.unwrap().end_s > 110.0);
    }
}
