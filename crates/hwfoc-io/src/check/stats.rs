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
