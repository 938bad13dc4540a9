//! Battery: its internal resistance, estimated from the voltage sag per ampere of each ESC's
//! current steps, and its change against the baseline's (or the first recording's); the lowest
//! voltage per cell under load.

use super::stats::{median, rolling_median};
use super::{Analyser, Baseline, BatteryConfig, EscSeries, Finding, Limits, Severity, Span};

/// The most a cell holds, V: a pack's cells are its highest voltage over this, rounded up.
const FULL_CELL_V: f64 = 4.25;

/// Samples further apart than this are no step, s.
const MAX_STEP_S: f64 = 0.25;

/// The smallest current step read, A (and a twentieth of the ESC's peak current).
const MIN_STEP_A: f64 = 2.0;

/// Steps an estimate needs.
const MIN_STEPS: usize = 3;

/// Current above which the battery is under load, A.
const LOAD_A: f64 = 1.0;

/// The window of the rolling median of the voltage under load, s: a lone low reading is no
/// minimum.
const VOLTAGE_WINDOW_S: f64 = 1.0;

/// Adds a finding per ESC of `series` to `out`.
pub(super) fn analyse(
    series: &[EscSeries],
    config: &BatteryConfig,
    baseline: Option<&Baseline>,
    out: &mut Vec<Finding>,
) {
    let first = series.first().map(|s| s.recording.as_str());
    for s in series {
        let Some(cells) = config.cells.map(f64::from).or_else(|| cells(s)) else {
            continue;
        };
        let resistance = resistance_mohm(s).map(|r| r / cells);
        let reference = baseline
            .and_then(|b| b.resistance_mohm_per_cell)
            .or_else(|| {
                let earlier = series
                    .iter()
                    .find(|e| {
                        Some(e.recording.as_str()) == first && e.esc.position == s.esc.position
                    })
                    .filter(|e| e.recording != s.recording)?;
                resistance_mohm(earlier).map(|r| r / cells)
            });
        let rise = resistance
            .zip(reference)
            .filter(|&(_, r)| r > 0.0)
            .map(|(now, r)| (now - r) / r * 100.0);
        let lowest = lowest_under_load(s).map(|(v, span)| (v / cells, span));
        if resistance.is_none() && lowest.is_none() {
            continue;
        }
        let mut f = Finding::about(Analyser::Battery, s).value("cells", cells, "-");
        let mut judged: Vec<(Severity, &str, f64, Limits, Option<Span>)> = Vec::new();
        if let Some(r) = resistance {
            f = f.value("resistance_per_cell", r, "mohm");
        }
        if let Some(rise) = rise {
            f = f.value("resistance_rise", rise, "%");
            let l = config.resistance_rise_pct;
            judged.push((l.judge(rise), "resistance_rise", rise, l, None));
        }
        if let Some((v, span)) = lowest {
            f = f.value("min_cell_v", v, "V");
            let l = config.min_cell_v;
            judged.push((l.judge(v), "min_cell_v", v, l, Some(span)));
        }
        let worst = judged.iter().max_by_key(|j| j.0);
        if let Some(&(severity, name, value, limits, span)) = worst {
            let unit = if name == "min_cell_v" { "V" } else { "%" };
            f = f.judged(severity, name, limits.crossed(severity), unit);
            if severity > Severity::Ok {
                f.window = span;
                f.message = match name {
                    "min_cell_v" => format!(
                        "{value:.2} V a cell under load, at or below {} V",
                        limits.crossed(severity)
                    ),
                    _ => format!(
                        "internal resistance up {value:.0} % on its reference, at or beyond {} %",
                        limits.crossed(severity)
                    ),
                };
            }
        }
        if f.message.is_empty() {
            f.message = format!(
                "{}lowest {} a cell under load",
                resistance.map_or(String::new(), |r| format!(
                    "{r:.1} milliohm a cell ({cells} cells), "
                )),
                lowest.map_or("-".to_string(), |(v, _)| format!("{v:.2} V")),
            );
        }
        out.push(f);
    }
}

/// The cells of the pack of `series`, from its highest voltage.
fn cells(series: &EscSeries) -> Option<f64> {
    let top = series
        .samples
        .iter()
        .filter_map(|s| s.voltage_v)
        .map(f64::from)
        .reduce(f64::max)?;
    (top > 0.0).then(|| (top / FULL_CELL_V).ceil())
}

/// The battery's internal resistance seen by the ESC of `series`, milliohm: the least-squares
/// sag per ampere over its current steps (consecutive frames; the open-circuit voltage and the
/// slow polarisation barely move in between).
pub(super) fn resistance_mohm(series: &EscSeries) -> Option<f64> {
    let peak = series
        .samples
        .iter()
        .filter_map(|s| s.current_a)
        .map(f64::from)
        .fold(0.0, f64::max);
    let min_step = MIN_STEP_A.max(peak / 20.0);
    let (mut vi, mut ii, mut steps) = (0.0, 0.0, 0);
    for w in series.samples.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let (Some(va), Some(vb), Some(ia), Some(ib)) =
            (a.voltage_v, b.voltage_v, a.current_a, b.current_a)
        else {
            continue;
        };
        let di = f64::from(ib - ia);
        if b.t - a.t > MAX_STEP_S || di.abs() < min_step {
            continue;
        }
        vi += f64::from(vb - va) * di;
        ii += di * di;
        steps += 1;
    }
    (steps >= MIN_STEPS && ii > 0.0).then(|| (-vi / ii * 1000.0).max(0.0))
}

/// The lowest voltage under load of `series` (the lowest rolling median), and its window.
fn lowest_under_load(series: &EscSeries) -> Option<(f64, Span)> {
    let loaded: Vec<(f64, f64)> = series
        .samples
        .iter()
        .filter(|s| s.current_a.is_some_and(|i| f64::from(i) > LOAD_A))
        .filter_map(|s| Some((s.t, f64::from(s.voltage_v?))))
        .collect();
    rolling_median(&loaded, VOLTAGE_WINDOW_S)
        .into_iter()
        .min_by(|a, b| a.2.total_cmp(&b.2))
        .map(|(from, to, v)| {
            (
                v,
                Span {
                    start_s: from,
                    end_s: to,
                },
            )
        })
}

/// The median over the recordings of `series` of their ESCs' median internal resistance per
/// cell, milliohm.
pub(super) fn median_resistance(series: &[EscSeries], cells_given: Option<u32>) -> Option<f64> {
    let mut by_recording: std::collections::BTreeMap<&str, Vec<f64>> = Default::default();
    for s in series {
        let Some(cells) = cells_given.map(f64::from).or_else(|| cells(s)) else {
            continue;
        };
        if let Some(r) = resistance_mohm(s) {
            by_recording
                .entry(&s.recording)
                .or_default()
                .push(r / cells);
        }
    }
    let mut medians: Vec<f64> = by_recording
        .into_values()
        .filter_map(|mut v| median(&mut v))
        .collect();
    median(&mut medians)
}

#[cfg(test)]
mod tests {
    use super::super::Sample;
    use super::super::tests::series_of;
    use super::*;

    /// A 6-cell pack of `r_ohm` under a current stepping between 5 and 40 A every 2 s, its
    /// open-circuit voltage falling from `from_v` to `to_v` a cell, in 0.1 V steps as ESCs
    /// send them.
    fn pack(r_ohm: f64, from_v: f64, to_v: f64) -> EscSeries {
        series_of(
            0,
            (0..1200).map(|i| {
                let t = i as f64 * 0.05;
                let current = if (t / 2.0).floor() as i64 % 2 == 0 {
                    5.0
                } else {
                    40.0
                };
                let ocv = 6.0 * (from_v + (to_v - from_v) * t / 60.0);
                let v = ((ocv - r_ohm * current) * 10.0).round() / 10.0;
                Sample {
                    t,
                    voltage_v: Some(v as f32),
                    current_a: Some(current as f32),
                    ..Sample::default()
                }
            }),
        )
    }

    fn battery(series: &[EscSeries], baseline: Option<&Baseline>) -> Vec<Finding> {
        let mut out = Vec::new();
        analyse(series, &BatteryConfig::default(), baseline, &mut out);
        out
    }

    #[test]
    fn the_resistance_is_the_sag_per_ampere() {
        let r = resistance_mohm(&pack(0.02, 4.1, 3.9)).unwrap();
        assert!((18.0..=22.0).contains(&r), "{r}");
        let f = &battery(&[pack(0.02, 4.1, 3.9)], None)[0];
        assert_eq!(f.severity, Severity::Ok, "{f:?}");
        assert_eq!(f.values[0].value, 6.0);
    }

    #[test]
    fn a_pack_sagging_below_the_limit_under_load_is_found_when_it_does() {
        // Open circuit 3.9 to 3.4 V a cell; under 40 A it drops 0.6 V more (0.1 V a cell).
        let f = &battery(&[pack(0.015, 3.9, 3.4)], None)[0];
        assert_eq!(f.severity, Severity::Warning, "{f:?}");
        assert_eq!(f.threshold.as_ref().unwrap().name, "min_cell_v");
        assert!(f.window.unwrap().start_s > 40.0, "{f:?}");
    }

    #[test]
    fn a_resistance_risen_on_the_baseline_is_found() {
        let baseline = Baseline {
            resistance_mohm_per_cell: Some(0.02 * 1000.0 / 6.0),
            ..Baseline::default()
        };
        let f = &battery(&[pack(0.035, 4.1, 3.9)], Some(&baseline))[0];
        assert_eq!(f.severity, Severity::Critical, "{f:?}");
        assert_eq!(f.threshold.as_ref().unwrap().name, "resistance_rise");
    }
}
