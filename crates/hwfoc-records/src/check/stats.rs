//! Small statistics the analysers share: medians, percentiles, curves of medians, windows.

use super::Curve;

/// The `p`th percentile (0..=100) of `values`, by nearest rank; `None` when empty.
pub(super) fn percentile(values: &mut [f64], p: f64) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let rank = ((p / 100.0) * values.len() as f64).ceil() as usize;
    Some(values[rank.clamp(1, values.len()) - 1])
}

/// The median of `values`; `None` when empty.
pub(super) fn median(values: &mut [f64]) -> Option<f64> {
    percentile(values, 50.0)
}

/// The median of `values` as the middle value, or the mean of the two middle values of an
/// even count (where [`median`] takes the lower): a reference drawn from two or four ESCs lies
/// between them, not on the lowest; `None` when empty.
pub(super) fn centre(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    Some((values[(n - 1) / 2] + values[n / 2]) / 2.0)
}

/// The curve of `points` `(x, y)`: in each bin of `x` of width `width` holding at least `min`
/// points, the median `x` and the median `y`, by `x`.
pub(super) fn curve(points: impl Iterator<Item = (f64, f64)>, width: f64, min: usize) -> Curve {
    let mut bins: std::collections::BTreeMap<i64, (Vec<f64>, Vec<f64>)> = Default::default();
    for (x, y) in points {
        if x.is_finite() && y.is_finite() {
            let bin = bins.entry((x / width).floor() as i64).or_default();
            bin.0.push(x);
            bin.1.push(y);
        }
    }
    let mut c = Curve::default();
    for (_, (mut xs, mut ys)) in bins {
        if xs.len() >= min
            && let (Some(x), Some(y)) = (median(&mut xs), median(&mut ys))
        {
            c.x.push(x);
            c.y.push(y);
        }
    }
    c
}

/// Points a window needs for its median to be judged.
const MIN_WINDOW_POINTS: usize = 5;

/// A deviation judged where it holds ([`held`]): the worst, and the span where it was at or
/// above the limit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Sustained {
    /// The worst value held.
    pub worst: f64,
    /// From the start of the first window at or above the limit to the end of the last.
    pub span: Option<super::Span>,
}

/// The rolling median of `points` (in time order) over trailing windows of `window_s`: at
/// each point whose window spans at least half of `window_s` and holds 5 points or more,
/// `(start of the window, t, median)`.
pub(super) fn rolling_median(points: &[(f64, f64)], window_s: f64) -> Vec<(f64, f64, f64)> {
    let mut sorted: Vec<f64> = Vec::new();
    let mut start = 0;
    let mut out = Vec::new();
    for (i, &(t, v)) in points.iter().enumerate() {
        let at = sorted.partition_point(|&x| x < v);
        sorted.insert(at, v);
        while points[start].0 <= t - window_s {
            let old = points[start].1;
            let at = sorted.partition_point(|&x| x < old);
            sorted.remove(at.min(sorted.len() - 1));
            start += 1;
        }
        if i + 1 - start >= MIN_WINDOW_POINTS && t - points[start].0 >= window_s / 2.0 {
            out.push((points[start].0, t, sorted[(sorted.len() - 1) / 2]));
        }
    }
    out
}

/// How long the throttle must have held for a sample to be steady, s: three of the motor's
/// time constants (its rpm lags a moving throttle, its current spikes as it speeds up).
const STEADY_S: f64 = 0.6;

/// How far the throttle may move and still hold, %.
const STEADY_PCT: f32 = 2.5;

/// The samples of `samples` (in time order) taken with the throttle steady: within 2.5 % over
/// the 0.6 s before. Where a throttle moves, rpm and current depend on how fast it moved, which
/// differs from motor to motor and flight to flight; at a steady throttle they do not.
pub(super) fn steady(samples: &[super::Sample]) -> Vec<super::Sample> {
    held_within(samples, STEADY_PCT)
}

/// The samples of `samples` (in time order) whose throttle stayed within `pct` % of theirs
/// over the 0.6 s before ([`steady`] with a bound of its own).
pub(super) fn held_within(samples: &[super::Sample], pct: f32) -> Vec<super::Sample> {
    let mut start = 0;
    let mut out = Vec::new();
    for (i, s) in samples.iter().enumerate() {
        let Some(throttle) = s.throttle_pct else {
            continue;
        };
        while samples[start].t < s.t - STEADY_S {
            start += 1;
        }
        let held = s.t - samples[start].t >= STEADY_S * 0.75
            && samples[start..i]
                .iter()
                .all(|x| x.throttle_pct.is_some_and(|p| (p - throttle).abs() <= pct));
        if held {
            out.push(*s);
        }
    }
    out
}

/// Windows of `window_s` overlapping by half, on a grid of absolute time (so that the windows
/// of two ESCs are the same), over `samples` (in time order): each window's span and the
/// samples in it.
pub(super) fn windows(
    samples: &[super::Sample],
    window_s: f64,
) -> impl Iterator<Item = (super::Span, &[super::Sample])> {
    let step = window_s / 2.0;
    let first = samples
        .first()
        .map_or(0, |s| (s.t / step).floor() as i64 - 1);
    let last = samples.last().map_or(-1, |s| (s.t / step).floor() as i64);
    (first..=last).filter_map(move |k| {
        let start = k as f64 * step;
        let end = start + window_s;
        let a = samples.partition_point(|s| s.t < start);
        let b = samples.partition_point(|s| s.t < end);
        (b > a).then(|| {
            (
                super::Span {
                    start_s: start,
                    end_s: end,
                },
                &samples[a..b],
            )
        })
    })
}

/// The finding of `analyser` on deviations by window `(window, %)` of `series`, judged where
/// they hold ([`held`]) against `limits`, as value `name`; its message `what` says of the
/// worst deviation held, followed by the windows' length and the limit.
pub(super) fn held_finding(
    analyser: super::Analyser,
    series: &super::EscSeries,
    name: &str,
    deviations: &[(super::Span, f64)],
    limits: super::Limits,
    window_s: f64,
    what: impl FnOnce(f64) -> String,
) -> Option<super::Finding> {
    let s = held(deviations, limits.warn)?;
    let severity = limits.judge(s.worst);
    let mut f = super::Finding::about(analyser, series)
        .value(name, s.worst, "%")
        .judged(severity, name, limits.crossed(severity), "%");
    f.window = s.span.filter(|_| severity > super::Severity::Ok);
    f.message = format!(
        "{} (held over windows of {window_s} s){}",
        what(s.worst),
        match severity {
            super::Severity::Ok => format!(", within {} %", limits.warn),
            _ => format!(": at or beyond {} %", limits.crossed(severity)),
        }
    );
    Some(f)
}

/// Deviations by window `(window, %)`, in time order, judged where they hold: the worst of
/// the lesser deviation of two windows in a row (overlapping), and the span of the pairs at or
/// above `limit` (each pair's two windows together: the span holds where it began). One window alone (a short flight) is judged by itself.
pub(super) fn held(windows: &[(super::Span, f64)], limit: f64) -> Option<Sustained> {
    let pairs: Vec<(f64, f64, f64)> = if windows.len() == 1 {
        vec![(windows[0].0.start_s, windows[0].0.end_s, windows[0].1)]
    } else {
        windows
            .windows(2)
            .filter(|w| w[1].0.start_s < w[0].0.end_s)
            .map(|w| (w[0].0.start_s, w[1].0.end_s, w[0].1.min(w[1].1)))
            .collect()
    };
    let worst = pairs.iter().map(|p| p.2).reduce(f64::max)?;
    let first = pairs.iter().find(|p| p.2 >= limit);
    let last = pairs.iter().rev().find(|p| p.2 >= limit);
    let span = first.zip(last).map(|(a, b)| super::Span {
        start_s: a.0,
        end_s: b.1,
    });
    Some(Sustained { worst, span })
}

#[cfg(test)]
mod tests {
    use super::super::{Sample, Span};
    use super::*;

    #[test]
    fn a_deviation_held_in_two_windows_is_found_in_them_and_one_in_a_single_window_is_not() {
        let w = |k: usize| Span {
            start_s: k as f64 * 5.0,
            end_s: k as f64 * 5.0 + 10.0,
        };
        let devs: Vec<(Span, f64)> = [1.0, 50.0, 2.0, 1.0, 40.0, 45.0, 1.0]
            .into_iter()
            .enumerate()
            .map(|(k, d)| (w(k), d))
            .collect();
        let s = held(&devs, 30.0).unwrap();
        assert_eq!(s.worst, 40.0);
        assert_eq!(
            s.span,
            Some(Span {
                start_s: 20.0,
                end_s: 35.0
            })
        );
        assert!(held(&devs[..4], 30.0).unwrap().span.is_none());
    }

    #[test]
    fn windows_lie_on_a_grid_of_absolute_time() {
        let samples: Vec<Sample> = (0..100)
            .map(|i| Sample {
                t: 3.0 + i as f64 * 0.1,
                ..Sample::default()
            })
            .collect();
        let spans: Vec<(f64, usize)> = windows(&samples, 4.0)
            .map(|(s, x)| (s.start_s, x.len()))
            .collect();
        assert_eq!(
            spans,
            [
                (0.0, 10),
                (2.0, 30),
                (4.0, 40),
                (6.0, 40),
                (8.0, 40),
                (10.0, 30),
                (12.0, 10)
            ]
        );
    }

    #[test]
    fn a_rolling_median_ignores_a_spike() {
        let mut points: Vec<(f64, f64)> = (0..100).map(|i| (i as f64 * 0.1, 1.0)).collect();
        points[50].1 = 100.0;
        assert!(rolling_median(&points, 1.0).iter().all(|m| m.2 == 1.0));
    }

    #[test]
    fn a_centre_of_an_even_count_lies_between_the_two_middle_values() {
        assert_eq!(centre(&mut [4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(centre(&mut [3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(centre(&mut []), None);
    }

    #[test]
    fn percentiles_by_nearest_rank() {
        let mut v: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(percentile(&mut v, 95.0), Some(95.0));
        assert_eq!(median(&mut v), Some(50.0));
        assert_eq!(percentile(&mut [], 50.0), None);
    }
}
