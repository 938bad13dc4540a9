//! Small statistics the analysers share: medians, percentiles, binned medians.

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

/// The median of `y` in each bin of `x` of width `width` (bin `k` holds `k*width <= x <
/// (k+1)*width`), for bins holding at least `min` points: `(k, median)`, by `k`.
pub(super) fn binned_medians(
    points: impl Iterator<Item = (f64, f64)>,
    width: f64,
    min: usize,
) -> Vec<(i64, f64)> {
    let mut bins: std::collections::BTreeMap<i64, Vec<f64>> = Default::default();
    for (x, y) in points {
        if x.is_finite() && y.is_finite() {
            bins.entry((x / width).floor() as i64).or_default().push(y);
        }
    }
    bins.into_iter()
        .filter(|(_, ys)| ys.len() >= min)
        .filter_map(|(k, mut ys)| Some((k, median(&mut ys)?)))
        .collect()
}

/// Points a window needs for its median to be judged.
const MIN_WINDOW_POINTS: usize = 5;

/// A quantity `(t, value)` judged over windows of `window_s` seconds: the worst (highest)
/// median of a window, and the span of the windows whose median is at or above `limit`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Sustained {
    /// The highest median of a window.
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

/// `points` judged over windows of `window_s` ([`rolling_median`]); `None` when no window
/// qualifies.
pub(super) fn sustained(points: &[(f64, f64)], window_s: f64, limit: f64) -> Option<Sustained> {
    let medians = rolling_median(points, window_s);
    let worst = medians.iter().map(|m| m.2).reduce(f64::max)?;
    let first = medians.iter().find(|m| m.2 >= limit);
    let last = medians.iter().rev().find(|m| m.2 >= limit);
    let span = first.zip(last).map(|(a, b)| super::Span {
        start_s: a.0,
        end_s: b.1,
    });
    Some(Sustained { worst, span })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sustained_deviation_is_found_in_its_window_and_a_spike_is_not() {
        let mut points: Vec<(f64, f64)> = (0..400).map(|i| (i as f64 * 0.05, 1.0)).collect();
        points[50].1 = 100.0; // a spike at 2.5 s
        for p in &mut points[200..300] {
            p.1 = 40.0; // 10 .. 15 s
        }
        let s = sustained(&points, 2.0, 30.0).unwrap();
        assert_eq!(s.worst, 40.0);
        let span = s.span.unwrap();
        assert!((9.0..=11.0).contains(&span.start_s), "{span:?}");
        assert!((14.5..=16.5).contains(&span.end_s), "{span:?}");
        assert!(sustained(&points[..100], 2.0, 30.0).unwrap().span.is_none());
    }

    #[test]
    fn percentiles_by_nearest_rank() {
        let mut v: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(percentile(&mut v, 95.0), Some(95.0));
        assert_eq!(median(&mut v), Some(50.0));
        assert_eq!(percentile(&mut [], 50.0), None);
    }
}
