//! `hwfoc summary`: what the inputs hold, ESC by ESC, and how good each link was (the report
//! itself is `hwfoc_io::summary`'s), optionally plotted alongside.

use clap::Args;
use hwfoc_io::Both;
use hwfoc_io::summary::Summary;
use hwfoc_io::write::WriteError;

use super::plot;
use crate::args::{InputArgs, SettingsArgs};
use crate::error::CliError;
use crate::output::TextSink;

#[derive(Debug, Args)]
pub struct SummaryArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Also plot the inputs to FILE (.png or .svg), as `hwfoc plot` does.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<String>,
    /// Replace the --plot file if it exists.
    #[arg(long, requires = "plot")]
    pub overwrite: bool,
    #[command(flatten)]
    pub settings: SettingsArgs,
}

/// Runs `hwfoc summary`.
pub fn run(args: &SummaryArgs) -> Result<(), CliError> {
    let (config, settings_map) = args.settings.settings_map()?;
    let settings = *settings_map.default_settings();
    // The plot's file is opened first: a wrong name is reported before the inputs are read.
    let mut plot = plot::Alongside::asked(
        args.plot.as_deref(),
        &args.input,
        &config,
        args.overwrite,
        settings,
    )?;
    let mut sources = args.input.sources(settings_map)?;
    let mut summary = Summary::new();
    // On an input error, what was read before it is summarised, then the error reported.
    let result = match &mut plot {
        Some(plot) => sources.run(&mut Both(&mut summary, plot)),
        None => sources.run(&mut summary).map_err(CliError::from),
    };
    crate::args::warn_left_out(&sources);
    let report = summary.report(&sources);
    let text = if args.json {
        let mut s = serde_json::to_string_pretty(&report.json()).unwrap_or_default();
        s.push('\n');
        s
    } else {
        report.text()
    };
    let mut out = TextSink::create(None)?;
    let mut buf = text.into_bytes();
    out.write(&mut buf)?;
    out.flush()?;
    if let Err(e @ CliError::Write(WriteError::Interrupted { .. })) = result {
        // Stopped by a signal: the plot is not drawn (its temporary file goes away).
        return Err(e);
    }
    if result.is_ok()
        && let Some(nothing) = sources.nothing_decoded()
    {
        // The report says why, ESC by ESC; the exit says it failed, as decode and plot do.
        return Err(nothing.into());
    }
    if let Some(plot) = plot {
        plot.finish(&sources)?;
    }
    result
}
