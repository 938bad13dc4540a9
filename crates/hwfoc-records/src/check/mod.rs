//! `hwfoc check`: is this propulsion system healthy? Analysers over the records of a run of
//! inputs, each giving [`Finding`]s with their evidence (`docs/CHECKS.md`).
//!
//! [`Check`] is a [`Handler`]: give it to [`Sources::run`], then take each ESC's series
//! ([`Check::series`]) and analyse them ([`analyse`]) under a [`CheckConfig`] and, for drift, a
//! [`Baseline`] fitted from healthy flights ([`Baseline::fit`]). [`check`] does both. The
//! analysers take [`EscSeries`], which a front end may also build itself (the simulator's
//! records, a fleet's).
//!
//! Here: the handler and the series; `finding.rs`, what is found; `config.rs`, the thresholds;
//! `baseline.rs`, the fitted model; one file per analyser.

use hwfoc::Protocol;
use hwfoc::telemetry::Info;

use crate::record::Record;
use crate::sources::{Handler, Sources};
use crate::summary::esc_label;
use crate::{InputError, Selection};

mod baseline;
mod battery;
mod config;
mod drift;
mod faults;
mod finding;
mod heat;
mod imbalance;
mod link;
mod runtime;
mod series;
mod stats;

pub use baseline::{Baseline, Curve, EscBaseline};
pub use config::{
    BatteryConfig, CheckConfig, DriftConfig, EscOverride, FaultsConfig, HeatConfig,
    ImbalanceConfig, Limits, LinkConfig, RuntimeConfig,
};
pub use finding::{Analyser, EscId, Finding, Severity, Span, Threshold, Value};
pub use series::{EscSeries, LinkTotals, Sample};

/// What the check gathers from the records: each ESC's series of samples.
#[derive(Debug, Default)]
pub struct Check {
    samples: Vec<Vec<Sample>>,
    /// The frames taken (`--esc`, `--from`, `--to`); all without one.
    selection: Option<Selection>,
}

impl Check {
    /// Nothing gathered yet.
    pub fn new() -> Check {
        Check::default()
    }

    /// Nothing gathered yet; of the frames to come, only those in `selection`.
    pub fn selecting(selection: Selection) -> Check {
        Check {
            selection: Some(selection),
            ..Check::default()
        }
    }

    /// Each ESC's series of what was gathered from `sources` (after [`Sources::run`]): its
    /// identity, recording and link figures from the sources; ESCs without data frames left
    /// out.
    pub fn series(self, sources: &Sources) -> Vec<EscSeries> {
        let mut samples = self.samples;
        sources
            .esc_table()
            .iter()
            .enumerate()
            .filter_map(|(i, entry)| {
                let samples = std::mem::take(samples.get_mut(i)?);
                if samples.is_empty() {
                    return None;
                }
                let link = sources.link(i);
                let timed = sources
                    .inputs()
                    .get(entry.input)
                    .is_some_and(|info| info.format.clock() != crate::time::Clock::None);
                Some(EscSeries {
                    esc: EscId {
                        number: i,
                        label: esc_label(sources, i),
                        position: match entry.key.place {
                            crate::Place::Own => entry.key.port.clone(),
                            crate::Place::Channel(c) => format!("{}#{c}", entry.key.port),
                        },
                    },
                    recording: recording_name(sources, entry),
                    protocol: link.protocol(),
                    timed,
                    link: Some(LinkTotals::of(&link)),
                    maintenance_min: link.maintenance_min(),
                    samples,
                })
            })
            .collect()
    }
}

/// How a recording is named in findings: its id, its input's name, or `joined`.
fn recording_name(sources: &Sources, entry: &crate::EscEntry) -> String {
    match entry.key.recording {
        crate::Recording::Id(id) => id.to_string(),
        crate::Recording::Input(n) => sources.names().get(n).cloned().unwrap_or_default(),
        crate::Recording::Joined => "joined".to_string(),
    }
}

impl Handler for Check {
    type Error = InputError;

    fn record(&mut self, record: &Record) {
        if let Some(selection) = &mut self.selection
            && !selection.contains(record.esc, record.t_s)
        {
            return;
        }
        let esc = usize::from(record.esc);
        if self.samples.len() <= esc {
            self.samples.resize_with(esc + 1, Vec::new);
        }
        let series = &mut self.samples[esc];
        series.push(Sample::of(record, series.len()));
    }

    fn info(&mut self, _: u8, _: Option<f64>, _: &Info) {}
}

/// Every analyser's findings on `series` (one recording's ESCs, or many recordings'), under
/// `config`, drift judged against `baseline` when one is given: for each ESC and analyser an
/// ok finding with its figures, or the warnings and critical findings.
pub fn analyse(
    series: &[EscSeries],
    config: &CheckConfig,
    baseline: Option<&Baseline>,
) -> Vec<Finding> {
    let mut findings = Vec::new();
    for s in series {
        heat::analyse(s, &config.heat_of(s.esc.number), &mut findings);
    }
    imbalance::analyse(series, &config.imbalance, &mut findings);
    if let Some(baseline) = baseline {
        drift::analyse(series, baseline, &config.drift, &mut findings);
    }
    battery::analyse(series, &config.battery, baseline, &mut findings);
    for s in series {
        faults::analyse(s, &config.faults, &mut findings);
        link::analyse(s, &config.link, &mut findings);
        runtime::analyse(s, &config.runtime_of(s.esc.number), &mut findings);
    }
    findings
}

/// Reads `sources` and analyses what they hold ([`analyse`]).
pub fn check(
    sources: &mut Sources,
    config: &CheckConfig,
    baseline: Option<&Baseline>,
) -> Result<Vec<Finding>, InputError> {
    let mut check = Check::new();
    sources.run(&mut check)?;
    Ok(analyse(&check.series(sources), config, baseline))
}

/// The nominal seconds between frames of `protocol` (what an untimed input's frames are spaced
/// by), 50 ms when it has none.
fn period_s(protocol: Protocol) -> f64 {
    protocol.frame_period().map_or(0.05, |d| d.as_secs_f64())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// ESC `number`'s series of `samples` in recording `flight`, with perfect link figures.
    pub(crate) fn series_of(number: usize, samples: impl Iterator<Item = Sample>) -> EscSeries {
        let samples: Vec<Sample> = samples.collect();
        EscSeries {
            esc: EscId {
                number,
                label: format!("esc {number}"),
                position: format!("esc-{number}"),
            },
            recording: "flight".to_string(),
            protocol: Protocol::HwFoc,
            timed: true,
            link: Some(LinkTotals {
                frames: samples.len() as u64,
                counts_packets: true,
                has_checksum: true,
                ..LinkTotals::default()
            }),
            maintenance_min: None,
            samples,
        }
    }
}
