//! Faults: the ESC's fault episodes (maximal runs of frames whose fault word is not zero, as
//! the summary counts them: `episode.rs`), by kind, with their times.

use hwfoc::Status;

use super::{Analyser, EscSeries, FaultsConfig, Finding, Severity, Span};
use crate::episode::{Episode, Mark};

/// Episodes named in a finding's message.
const LISTED: usize = 5;

/// Adds a finding per kind of fault of `series` to `out` (an ok one without faults).
pub(super) fn analyse(series: &EscSeries, config: &FaultsConfig, out: &mut Vec<Finding>) {
    if !series.protocol.has_faults() {
        return;
    }
    let episodes = episodes(series);
    let period = super::period_s(series.protocol);
    let mut any = false;
    for bit in 0..16u8 {
        let mask = 1u16 << bit;
        let of_kind: Vec<&Episode> = episodes.iter().filter(|e| e.bits.0 & mask != 0).collect();
        let (Some(first), Some(last)) = (of_kind.first(), of_kind.last()) else {
            continue;
        };
        any = true;
        let name = series.protocol.fault_name(bit).unwrap_or("unknown");
        let seconds: f64 = of_kind.iter().map(|e| length_s(e, period)).sum();
        let count = of_kind.len() as f64;
        let by_count = config.episodes.judge(count);
        let by_time = config.fault_s.judge(seconds);
        let (severity, what, limit, unit) = if by_time > by_count {
            (by_time, "fault_time", config.fault_s.crossed(by_time), "s")
        } else {
            (by_count, "episodes", config.episodes.crossed(by_count), "-")
        };
        let times: Vec<String> = of_kind.iter().take(LISTED).map(|e| e.when(false)).collect();
        let mut f = Finding::about(Analyser::Faults, series)
            .value("episodes", count, "-")
            .value("fault_time", seconds, "s")
            .judged(severity, what, limit, unit);
        f.window = Some(Span {
            start_s: first.first.t.unwrap_or(0.0),
            end_s: last.last.t.unwrap_or(0.0),
        });
        f.message = format!(
            "{name}: {count} episode{} over {seconds:.2} s ({}{})",
            if of_kind.len() == 1 { "" } else { "s" },
            times.join(", "),
            if of_kind.len() > LISTED { ", ..." } else { "" }
        );
        out.push(f);
    }
    if !any {
        let mut f = Finding::about(Analyser::Faults, series).value("episodes", 0.0, "-");
        f.message = "no fault episodes".to_string();
        out.push(f);
    }
    debug_assert!(out.iter().all(|f| f.severity >= Severity::Ok));
}

/// The fault episodes of `series`, the last one closed at the end.
fn episodes(series: &EscSeries) -> Vec<Episode> {
    let mut open = None;
    let mut done = Vec::new();
    for (i, s) in series.samples.iter().enumerate() {
        let mark = Mark {
            t: Some(s.t),
            frame: i as u64,
            packet: s.packet,
        };
        if let Some(e) = Episode::track(&mut open, mark, s.status.unwrap_or(Status::OK)) {
            done.push(e);
        }
    }
    if let Some(mut e) = open {
        e.ongoing = true;
        done.push(e);
    }
    done
}

/// How long episode `e` lasted: from its first frame to the one after its last.
fn length_s(e: &Episode, period: f64) -> f64 {
    e.last.t.unwrap_or(0.0) - e.first.t.unwrap_or(0.0) + period
}

#[cfg(test)]
mod tests {
    use super::super::Sample;
    use super::super::tests::series_of;
    use super::*;

    #[test]
    fn episodes_are_found_by_kind_with_their_times() {
        // mos_overheat (bit 1 of HW-FOC's word) from 10 to 11 s and 20 to 24 s.
        let series = series_of(
            0,
            (0..600).map(|i| {
                let t = i as f64 * 0.05;
                let hot = (10.0..11.0).contains(&t) || (20.0..24.0).contains(&t);
                Sample {
                    t,
                    status: Some(Status(if hot { 0x0002 } else { 0 })),
                    ..Sample::default()
                }
            }),
        );
        let mut out = Vec::new();
        analyse(&series, &FaultsConfig::default(), &mut out);
        assert_eq!(out.len(), 1, "{out:?}");
        let f = &out[0];
        assert_eq!(f.values[0].value, 2.0);
        assert!((f.values[1].value - 5.0).abs() < 0.11, "{f:?}");
        assert_eq!(f.severity, Severity::Critical, "5 s of faults: {f:?}");
        let w = f.window.unwrap();
        assert!(
            (w.start_s - 10.0).abs() < 0.06 && (w.end_s - 23.95).abs() < 0.06,
            "{w:?}"
        );
        assert!(
            f.message.contains(series.protocol.fault_name(1).unwrap()),
            "{}",
            f.message
        );
    }

    #[test]
    fn no_fault_is_ok() {
        let series = series_of(
            0,
            (0..100).map(|i| Sample {
                t: i as f64 * 0.05,
                status: Some(Status::OK),
                ..Sample::default()
            }),
        );
        let mut out = Vec::new();
        analyse(&series, &FaultsConfig::default(), &mut out);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].severity, Severity::Ok);
    }
}
