//! `hwfoc check`: is this propulsion system healthy? The analysers of `hwfoc_io::check` over
//! the inputs' records, their findings as text or JSON, and an exit status for CI (0 nothing
//! found, 1 a warning, 2 a critical finding); `--fit-baseline` writes the baseline that
//! `--baseline` judges drift against.

use std::path::PathBuf;

use clap::Args;
use hwfoc_io::Sources;
use hwfoc_io::check::{Baseline, Check, EscSeries, Finding, Severity};
use hwfoc_io::time::{self, Clock};
use hwfoc_io::write::{WriteError, create_file};
use serde_json::json;

use super::plot;
use crate::args::{InputArgs, SelectArgs, SettingsArgs};
use crate::error::CliError;
use crate::output::TextSink;

/// How errors and findings are told apart (`hwfoc check --help`).
const EXIT_HELP: &str = "Exit status: 0 when no analyser found anything, 1 when the worst \
finding is a warning, 2 when one is critical. An error (an input that cannot be read, a wrong \
option) also exits 1, with a line starting `hwfoc:` on standard error and no report on standard \
output: a report (text or JSON) on standard output means the check ran. Thresholds: the \
configuration file's [check] table (docs/CHECKS.md).";

#[derive(Debug, Args)]
#[command(after_help = EXIT_HELP)]
pub struct CheckArgs {
    #[command(flatten)]
    pub input: InputArgs,
    #[command(flatten)]
    pub select: SelectArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Judge drift against this baseline (a TOML file written by --fit-baseline).
    #[arg(long, value_name = "FILE", conflicts_with = "fit_baseline")]
    pub baseline: Option<PathBuf>,
    /// Fit a baseline from the inputs, healthy flights of one airframe, and write it to -o FILE
    /// (TOML) instead of checking them.
    #[arg(long, requires = "output")]
    pub fit_baseline: bool,
    /// The file --fit-baseline writes.
    #[arg(short, long, value_name = "FILE", requires = "fit_baseline")]
    pub output: Option<String>,
    /// Also plot the inputs to FILE (.png or .svg), as `hwfoc plot` does, with the windows of
    /// the warnings and critical findings shaded.
    #[arg(long, value_name = "FILE", conflicts_with = "fit_baseline")]
    pub plot: Option<String>,
    /// Replace the -o or --plot file if it exists.
    #[arg(long)]
    pub overwrite: bool,
    #[command(flatten)]
    pub settings: SettingsArgs,
}

/// Runs `hwfoc check`: the worst severity found (the exit status), or an error.
pub fn run(args: &CheckArgs) -> Result<Severity, CliError> {
    let (config, settings_map) = args.settings.settings_map()?;
    let settings = *settings_map.default_settings();
    let selection = args.select.selection()?;
    let baseline = plot::read_baseline(args.baseline.as_deref())?;
    // The output files are opened first: a wrong name is reported before the inputs are read.
    let mut out = match &args.output {
        Some(path) => {
            args.input.refuse_output(path, &config)?;
            Some((
                path,
                create_file(path, args.overwrite).map_err(CliError::Write)?,
            ))
        }
        None => None,
    };
    let mut plot = plot::Alongside::asked(
        args.plot.as_deref(),
        &args.input,
        &config,
        args.overwrite,
        settings,
    )?;
    let mut sources = args.input.sources(settings_map)?;
    if selection.window.is_limited() {
        sources.require_timing()?;
        args.select.check_clocks(&sources)?;
    }
    let mut check = Check::selecting(selection);
    plot::read_checked(&mut sources, Some(&mut check), plot.as_mut())?;
    if let Some(nothing) = sources.nothing_decoded() {
        return Err(nothing.into());
    }
    let series = check.series(&sources);
    let check_config = &config.file.check;
    if let Some((path, file)) = &mut out {
        let fitted = Baseline::fit(&series, check_config.battery.cells);
        let text = toml::to_string(&fitted).map_err(|e| CliError::Config {
            path: path.to_string(),
            line: None,
            message: e.to_string(),
        })?;
        use std::io::Write;
        file.write_all(text.as_bytes()).map_err(|source| {
            CliError::Write(WriteError::Write {
                output: path.to_string(),
                source,
            })
        })?;
        eprintln!(
            "hwfoc: baseline of {} ESCs from {} recordings written to {path}",
            fitted.esc.len(),
            fitted.recordings
        );
        return Ok(Severity::Ok);
    }
    let findings = hwfoc_io::check::analyse(&series, check_config, baseline.as_ref());
    let worst = Finding::worst(&findings);
    let text = if args.json {
        let mut s = serde_json::to_string_pretty(&json!({
            "schema_version": hwfoc_io::JSON_SCHEMA_VERSION,
            "worst": worst,
            "exit_status": worst.exit_code(),
            "baseline": args.baseline.as_ref().map(|p| p.display().to_string()),
            "findings": findings,
        }))
        .unwrap_or_default();
        s.push('\n');
        s
    } else {
        text(&sources, &series, &findings, worst)
    };
    let mut sink = TextSink::create(None)?;
    let mut buf = text.into_bytes();
    sink.write(&mut buf)?;
    sink.flush()?;
    if let Some(plot) = plot {
        plot.finish_with(&sources, &findings)?;
    }
    Ok(worst)
}

/// The findings for a person: ESC by ESC, each finding on a line with its window.
fn text(sources: &Sources, series: &[EscSeries], findings: &[Finding], worst: Severity) -> String {
    let mut s = String::new();
    for esc in series {
        s.push_str(&format!("ESC {:<8} {}\n", esc.esc.number, esc.esc.label));
        let wall = wall_clock(sources, esc.esc.number);
        for f in findings
            .iter()
            .filter(|f| f.esc.as_ref().is_some_and(|e| e.number == esc.esc.number))
            .filter(|f| f.recording == esc.recording)
        {
            let severity = match f.severity {
                Severity::Ok => "ok",
                Severity::Warning => "WARNING",
                Severity::Critical => "CRITICAL",
            };
            let window = f.window.map_or(String::new(), |w| {
                if wall {
                    format!(
                        " [{} .. {}]",
                        time::iso8601(w.start_s),
                        time::iso8601(w.end_s)
                    )
                } else {
                    format!(" [{:.3} .. {:.3} s]", w.start_s, w.end_s)
                }
            });
            s.push_str(&format!(
                "  {severity:<9} {:<10} {}{window}\n",
                f.analyser.name(),
                f.message
            ));
        }
        s.push('\n');
    }
    let count = |sev| findings.iter().filter(|f| f.severity == sev).count();
    let (w, c) = (count(Severity::Warning), count(Severity::Critical));
    s.push_str(&format!(
        "result       {w} warning{}, {c} critical: {worst} (exit {})\n",
        if w == 1 { "" } else { "s" },
        worst.exit_code()
    ));
    s
}

/// Whether ESC `esc`'s input has a wall clock (its windows are shown as dates).
fn wall_clock(sources: &Sources, esc: usize) -> bool {
    sources
        .esc_table()
        .get(esc)
        .and_then(|e| sources.inputs().get(e.input))
        .is_some_and(|info| info.format.clock() == Clock::Wall)
}
