//! `hwfoc plot`: one row of time-series panels per ESC (throttle, RPM, currents, voltage,
//! temperatures), fault episodes shaded, as PNG or SVG.
//!
//! Frames are gathered as they are decoded into a fixed number of time buckets per ESC holding
//! the first, lowest, highest and last value of each quantity ([`collect`]): memory stays
//! bounded however long the recording, and drawing one column of pixels from its buckets shows
//! every spike a line through all the frames would. The image is drawn with plotters ([`draw`])
//! and its text with a font compiled into the program, so no system font is needed.

mod collect;
mod draw;
mod target;
mod text;

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use hwfoc::Settings;
use hwfoc::telemetry::Info;

use crate::args::{InputArgs, SelectArgs, SettingsArgs};
use crate::error::CliError;
use hwfoc_io::Selection;
use hwfoc_io::check::{Baseline, Check, analyse};
use hwfoc_io::record::Record;
use hwfoc_io::write::WriteError;
use hwfoc_io::{Both, Handler, Sources};

use collect::Collector;
use target::ImageFile;

/// What the time axis does with a clock that steps back or jumps (`hwfoc plot --help`).
const CLOCK_HELP: &str = "Time axis: seconds from the first frame. Where an ESC's receive clock \
steps back (NTP) or jumps forward further than its packet numbers explain, its time goes on one \
frame period after the frame before and its lines break there; the subtitle counts such \
discontinuities. A silence that the packet numbers explain (a cut line) stays on the axis.";

/// The narrowest and widest image, and the lowest and highest, in pixels.
const MIN_SIZE: u32 = 320;
/// See [`MIN_SIZE`]: 10000 x 10000 pixels are 300 MB of RGB.
const MAX_SIZE: u32 = 10_000;

/// Arguments of `hwfoc plot`.
#[derive(Debug, clap::Args)]
#[command(after_help = CLOCK_HELP)]
pub struct PlotArgs {
    #[command(flatten)]
    input: InputArgs,
    /// The image to write: a name ending in .png or .svg gives the format.
    #[arg(short, long, value_name = "FILE")]
    output: String,
    /// Replace the -o file if it exists.
    #[arg(long)]
    overwrite: bool,
    /// Width of the image in pixels.
    #[arg(long, value_name = "PX", default_value_t = draw::DEFAULT_WIDTH,
          value_parser = clap::value_parser!(u32).range(i64::from(MIN_SIZE)..=i64::from(MAX_SIZE)))]
    width: u32,
    /// Height of the image in pixels. Default: room for a row of panels per ESC.
    #[arg(long, value_name = "PX",
          value_parser = clap::value_parser!(u32).range(i64::from(MIN_SIZE)..=i64::from(MAX_SIZE)))]
    height: Option<u32>,
    /// Title on top of the image. Default: the inputs' names.
    #[arg(long, value_name = "TEXT")]
    title: Option<String>,
    /// Shade the windows of the warnings and critical findings of `hwfoc check` (its analysers,
    /// with the configuration file's check thresholds) in the same reading of the inputs.
    #[arg(long)]
    check: bool,
    /// With --check: judge drift against this baseline (a TOML file written by `hwfoc check
    /// --fit-baseline`).
    #[arg(long, value_name = "FILE", requires = "check")]
    baseline: Option<std::path::PathBuf>,
    #[command(flatten)]
    select: SelectArgs,
    #[command(flatten)]
    settings: SettingsArgs,
}

/// What the image shows besides the frames.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels; `None`: room for every ESC.
    pub height: Option<u32>,
    /// Title; `None`: made from the inputs' names.
    pub title: Option<String>,
    /// The ESCs asked for with `--esc` (empty: all).
    pub escs: Vec<u8>,
}

/// `hwfoc plot`: reads the inputs and writes the image.
pub fn run(args: &PlotArgs) -> Result<(), CliError> {
    let (config, settings_map) = args.settings.settings_map()?;
    let settings = *settings_map.default_settings();
    let selection = args.select.selection()?;
    // Opened first, so that a wrong name is reported before the inputs are read; a file
    // created here is removed again if the plot is not written.
    args.input.refuse_output(&args.output, &config)?;
    let mut target = ImageFile::open(&args.output, args.overwrite)?;
    let baseline = read_baseline(args.baseline.as_deref())?;
    let options = Options {
        width: args.width,
        height: args.height,
        title: args.title.clone(),
        escs: args.select.esc.clone(),
    };
    let mut sources = args.input.sources(settings_map)?;
    if selection.window.is_limited() {
        sources.require_timing()?;
        args.select.check_clocks(&sources)?;
    }
    let mut check = args.check.then(|| Check::selecting(selection.clone()));
    let mut collector = Collector::new(settings, selection, options.width)
        .stop_on(args.input.stop_if_read_to_end(), &args.output);
    let result = read_checked(&mut sources, check.as_mut(), Some(&mut collector));
    if let Some(check) = check {
        let series = check.series(&sources);
        collector.shade(&analyse(&series, &config.file.check, baseline.as_ref()));
    }
    if let Err(e @ CliError::Write(WriteError::Interrupted { .. })) = result {
        return Err(e);
    }
    // On an input error, what was read before it is still plotted, then the error reported.
    let written = collector.write(&sources, &options, &mut target);
    result?;
    written
}

/// The baseline TOML file of `--baseline` (`hwfoc check`, `hwfoc plot --check`), if given.
pub(crate) fn read_baseline(path: Option<&Path>) -> Result<Option<Baseline>, CliError> {
    path.map(crate::config::read_toml).transpose()
}

/// Reads `sources` in one go into `check` and `other`, each where given (`hwfoc check --plot`,
/// `hwfoc plot --check`), then warns of the records left out; the reading's error, if any.
pub(crate) fn read_checked<H: Handler<Error = CliError>>(
    sources: &mut Sources,
    check: Option<&mut Check>,
    other: Option<&mut H>,
) -> Result<(), CliError> {
    let result = match (check, other) {
        (Some(check), Some(other)) => sources.run(&mut Both(check, other)),
        (Some(check), None) => sources.run(check).map_err(CliError::from),
        (None, Some(other)) => sources.run(other),
        (None, None) => Ok(()),
    };
    crate::args::warn_left_out(sources);
    result
}

/// `hwfoc summary --plot FILE`: a plot with the defaults of `hwfoc plot`, of the frames the
/// summary reads.
pub struct Alongside {
    target: ImageFile,
    options: Options,
    collector: Collector,
}

impl Alongside {
    /// Opens the image file (see [`ImageFile::open`]); `stop` as [`Collector::stop_on`].
    pub fn open(
        path: &str,
        overwrite: bool,
        settings: Settings,
        stop: Option<Arc<AtomicBool>>,
    ) -> Result<Alongside, CliError> {
        let target = ImageFile::open(path, overwrite)?;
        let options = Options {
            width: draw::DEFAULT_WIDTH,
            ..Options::default()
        };
        let collector =
            Collector::new(settings, Selection::default(), options.width).stop_on(stop, path);
        Ok(Alongside {
            target,
            options,
            collector,
        })
    }

    /// The plot asked for with `--plot FILE` (`path`) beside a command reading `input`, if
    /// asked: refused when it would be one of the files read (an input, the configuration file
    /// `config`), else opened as [`Alongside::open`] does.
    pub fn asked(
        path: Option<&str>,
        input: &InputArgs,
        config: &crate::config::Config,
        overwrite: bool,
        settings: Settings,
    ) -> Result<Option<Alongside>, CliError> {
        let Some(path) = path else {
            return Ok(None);
        };
        input.refuse_output(path, config)?;
        let stop = input.stop_if_read_to_end();
        Alongside::open(path, overwrite, settings, stop).map(Some)
    }

    /// Draws the plot of what was read from `sources` and writes it.
    pub fn finish(mut self, sources: &Sources) -> Result<(), CliError> {
        self.collector
            .write(sources, &self.options, &mut self.target)
    }

    /// As [`Alongside::finish`], the windows of `findings` (`hwfoc check --plot`) shaded.
    pub fn finish_with(
        mut self,
        sources: &Sources,
        findings: &[hwfoc_io::check::Finding],
    ) -> Result<(), CliError> {
        self.collector.shade(findings);
        self.finish(sources)
    }
}

impl Handler for Alongside {
    type Error = CliError;

    #[inline]
    fn record(&mut self, r: &Record) {
        self.collector.record(r);
    }

    fn info(&mut self, esc: u8, t: Option<f64>, info: &Info) {
        self.collector.info(esc, t, info);
    }

    fn end_batch(&mut self, live: bool) -> Result<(), CliError> {
        self.collector.end_batch(live)
    }
}
