//! Link: packets lost and checksum failures over the whole input (the summary's link figures),
//! the worst burst of loss in a window (from the packet numbers), and the longest dropout
//! while the motor turned (from the times). A loose telemetry wire shows here first.

use super::{Analyser, EscSeries, Finding, Limits, LinkConfig, Sample, Severity, Span};

/// A jump of the packet counter larger than this is a restart, not a loss.
const MAX_GAP_PACKETS: u64 = 1000;

/// A figure judged: severity, name, value, limits, unit, window.
type Judgement = (
    Severity,
    &'static str,
    f64,
    Limits,
    &'static str,
    Option<Span>,
);

/// Adds the finding of `series`'s link to `out`.
pub(super) fn analyse(series: &EscSeries, config: &LinkConfig, out: &mut Vec<Finding>) {
    let mut f = Finding::about(Analyser::Link, series);
    // (severity, value name, value, limits, unit, window)
    let mut judged: Vec<Judgement> = Vec::new();
    if let Some(link) = series.link {
        if link.counts_packets {
            let lost = percent(link.lost_packets, link.frames + link.lost_packets);
            f = f.value("lost_packets", lost, "%");
            judged.push((
                config.lost_pct.judge(lost),
                "lost_packets",
                lost,
                config.lost_pct,
                "%",
                None,
            ));
        }
        if link.has_checksum {
            let bad = percent(link.checksum_failures, link.frames + link.checksum_failures);
            f = f.value("checksum_failures", bad, "%");
            let l = config.checksum_pct;
            judged.push((l.judge(bad), "checksum_failures", bad, l, "%", None));
        }
    }
    if let Some((burst, span)) = worst_burst(series, config.window_s, config.burst_pct.warn) {
        f = f.value("burst", burst, "%");
        let l = config.burst_pct;
        judged.push((l.judge(burst), "burst", burst, l, "%", Some(span)));
    }
    if series.timed
        && let Some((gap, span)) = longest_dropout(&series.samples)
    {
        f = f.value("dropout", gap, "s");
        let l = config.dropout_s;
        judged.push((l.judge(gap), "dropout", gap, l, "s", Some(span)));
    }
    let Some(&(severity, name, value, limits, unit, window)) =
        judged
            .iter()
            .fold(None, |w: Option<&Judgement>, j| match w {
                // The worst; of equals, one with a window (a burst, a dropout) first.
                Some(w) if w.0 > j.0 || (w.0 == j.0 && (w.5.is_some() || j.5.is_none())) => Some(w),
                _ => Some(j),
            })
    else {
        return;
    };
    let limit = limits.crossed(severity);
    f = f.judged(severity, name, limit, unit);
    f.window = window.filter(|_| severity > Severity::Ok);
    let words = match name {
        "lost_packets" => "packets lost",
        "checksum_failures" => "frames failing their checksum",
        "burst" => "packets lost in the worst window",
        _ => "longest dropout while the motor turned",
    };
    f.message = match severity {
        Severity::Ok => {
            let all: Vec<String> = f
                .values
                .iter()
                .map(|v| format!("{} {:.2} {}", v.name, v.value, v.unit))
                .collect();
            format!("link figures within their limits ({})", all.join(", "))
        }
        _ => format!("{value:.2} {unit} {words}, at or beyond {limit} {unit}"),
    };
    out.push(f);
}

fn percent(part: u64, whole: u64) -> f64 {
    if whole == 0 {
        0.0
    } else {
        part as f64 * 100.0 / whole as f64
    }
}

/// The window of `window_s` with the most packets lost, in % of those sent in it, and the span
/// from the first window with `limit` % lost or more to the last (the worst window's if none);
/// `None` for a protocol without packet numbers or a series shorter than the window.
fn worst_burst(series: &EscSeries, window_s: f64, limit: f64) -> Option<(f64, Span)> {
    let bits = series.protocol.packet_bits()?;
    let modulo = 1u64 << bits;
    // (t, packets lost just before this frame)
    let lost: Vec<(f64, u64)> = series
        .samples
        .windows(2)
        .filter_map(|w| {
            let (a, b) = (u64::from(w[0].packet?), u64::from(w[1].packet?));
            let step = (b + modulo - a) % modulo;
            Some((
                w[1].t,
                if (1..=MAX_GAP_PACKETS).contains(&step) {
                    step - 1
                } else {
                    0
                },
            ))
        })
        .collect();
    let last = lost.last()?.0;
    if last - lost.first()?.0 < window_s {
        return None;
    }
    let (mut start, mut in_window, mut best) = (0, 0u64, None);
    let mut above: Option<Span> = None;
    for (i, &(t, n)) in lost.iter().enumerate() {
        in_window += n;
        while lost[start].0 <= t - window_s {
            in_window -= lost[start].1;
            start += 1;
        }
        let received = (i + 1 - start) as u64;
        let p = percent(in_window, in_window + received);
        if p >= limit {
            let from = above.map_or(lost[start].0, |a| a.start_s);
            above = Some(Span {
                start_s: from,
                end_s: t,
            });
        }
        if best.is_none_or(|(b, _)| p > b) {
            best = Some((
                p,
                Span {
                    start_s: lost[start].0,
                    end_s: t,
                },
            ));
        }
    }
    best.map(|(p, span)| (p, above.unwrap_or(span)))
}

/// The longest silence between two frames while the motor turned (at either end), and its
/// span: an ESC idling may send slowly (V4's slow mode), one turning may not.
fn longest_dropout(samples: &[Sample]) -> Option<(f64, Span)> {
    let turning = |s: &Sample| s.rpm.is_some_and(|r| r > 0.0);
    samples
        .windows(2)
        .filter(|w| turning(&w[0]) || turning(&w[1]))
        .map(|w| {
            (
                w[1].t - w[0].t,
                Span {
                    start_s: w[0].t,
                    end_s: w[1].t,
                },
            )
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
}

#[cfg(test)]
mod tests {
    use super::super::tests::series_of;
    use super::*;

    /// 60 s of a turning motor at 20 frames a second; the frames of `lost` (by index) not
    /// received.
    fn flight(lost: impl Fn(usize) -> bool) -> EscSeries {
        let mut s = series_of(
            0,
            (0..1200).filter(|&i| !lost(i)).map(|i| Sample {
                t: i as f64 * 0.05,
                packet: Some((i as u32 + 65000) % 65536),
                rpm: Some(5000.0),
                ..Sample::default()
            }),
        );
        let link = s.link.as_mut().unwrap();
        link.lost_packets = 1200 - s.samples.len() as u64;
        s
    }

    fn link(series: &EscSeries) -> Finding {
        let mut out = Vec::new();
        analyse(series, &LinkConfig::default(), &mut out);
        assert_eq!(out.len(), 1);
        out.remove(0)
    }

    #[test]
    fn a_clean_link_is_ok_across_the_counter_wrap() {
        let f = link(&flight(|_| false));
        assert_eq!(f.severity, Severity::Ok, "{f:?}");
    }

    #[test]
    fn a_burst_of_loss_is_found_in_its_window() {
        // Every other frame lost from 30 to 35 s: 1.7 % overall, 50 % in the window.
        let f = link(&flight(|i| (600..700).contains(&i) && i % 2 == 1));
        assert_eq!(f.severity, Severity::Critical, "{f:?}");
        assert_eq!(f.threshold.as_ref().unwrap().name, "burst");
        let w = f.window.unwrap();
        assert!(
            w.start_s < 31.0 && w.end_s > 34.0 && w.end_s < 41.0,
            "{w:?}"
        );
    }

    #[test]
    fn loss_spread_over_the_flight_is_judged_under_the_summary_s_name() {
        // Every 20th frame lost: 5 % (a warning from 2 %), never 20 % in a window.
        let f = link(&flight(|i| i % 20 == 7));
        assert_eq!(f.severity, Severity::Warning, "{f:?}");
        let threshold = f.threshold.as_ref().unwrap();
        assert_eq!(
            (threshold.name.as_str(), threshold.value),
            ("lost_packets", 2.0)
        );
        let lost = f.values.iter().find(|v| v.name == "lost_packets").unwrap();
        assert!((lost.value - 5.0).abs() < 1e-9 && lost.unit == "%", "{f:?}");
    }

    #[test]
    fn a_dropout_while_turning_is_found() {
        // 0.8 s of silence at 20 s.
        let f = link(&flight(|i| (400..416).contains(&i)));
        assert!(f.severity >= Severity::Warning, "{f:?}");
        assert!(
            f.values
                .iter()
                .any(|v| v.name == "dropout" && v.value > 0.8),
            "{f:?}"
        );
    }
}
