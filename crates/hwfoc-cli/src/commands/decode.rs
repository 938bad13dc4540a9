//! `hwfoc decode`: one record per data frame, as JSON Lines, CSV or Parquet.
//!
//! Inputs are read by [`Sources`], records of inputs with times in time order; records can be
//! limited to some ESCs (`--esc`) and to a window of receive times (`--from` inclusive, `--to`
//! exclusive, so that consecutive windows never share a frame; times as `hwfoc_io::time`
//! reads them: after the first frame, seconds of the source's clock, or dates). A time window
//! needs inputs with receive times: raw bytes have none, and are refused rather than silently
//! giving no records; a date for an input without a wall clock is refused likewise.

use clap::{Args, ValueEnum};

use crate::args::{InputArgs, SelectArgs, SettingsArgs};
use crate::error::CliError;
use hwfoc_io::Sources;
use hwfoc_io::time::Clock;
use hwfoc_io::write::{Export, OutputFormat, Provenance, metadata};
use hwfoc_io::{SettingsMap, SettingsPatch};

/// Record output formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RecordFormat {
    /// One JSON object per line, with exactly the schema's keys.
    Jsonl,
    /// Comma-separated, with a header row; faults joined by `|`, nulls empty.
    Csv,
    /// Apache Parquet (needs -o): typed columns, units and settings in the metadata.
    Parquet,
}

/// How CSV gives receive times.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CsvTime {
    /// Unix seconds, `t_s` (the source's own seconds for an analyser's export).
    Seconds,
    /// ISO 8601 dates in UTC, `time`: `2026-11-23T14:03:00.160123Z`.
    Iso,
}

#[derive(Debug, Args)]
pub struct DecodeArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Output format: by default the one the -o file's name ends in (.jsonl or .ndjson, .csv,
    /// .parquet), JSON Lines on standard output.
    #[arg(long, value_enum)]
    pub format: Option<RecordFormat>,
    #[command(flatten)]
    pub settings: SettingsArgs,
    /// CSV only: start with a `#` comment line giving the settings used.
    #[arg(long)]
    pub settings_comment: bool,
    /// CSV only: receive times as Unix seconds (`t_s`), or as ISO 8601 dates in UTC to the
    /// microsecond (a `time` column, which spreadsheets read as dates; recordings and ports).
    #[arg(long, value_enum, default_value_t = CsvTime::Seconds)]
    pub time: CsvTime,
    /// Write to FILE instead of standard output, in the format its name ends in.
    #[arg(short, long, value_name = "FILE", required_if_eq("format", "parquet"))]
    pub output: Option<String>,
    /// Replace the -o file if it exists.
    #[arg(long, requires = "output")]
    pub overwrite: bool,
    #[command(flatten)]
    pub select: SelectArgs,
}

/// Runs `hwfoc decode`.
pub fn run(args: &DecodeArgs) -> Result<(), CliError> {
    let (config, settings_map) = args.settings.settings_map()?;
    let settings = *settings_map.default_settings();
    let overrides = overrides(&settings_map);
    let selection = args.select.selection()?;
    args.input
        .refuse_output(args.output.as_deref().unwrap_or("-"), &config)?;
    let format = output_format(args.format, args.output.as_deref())?;
    if args.time == CsvTime::Iso && format != OutputFormat::Csv {
        return Err(CliError::Usage {
            option: "--time iso".to_string(),
            message: "CSV only (Parquet and JSON Lines keep t_s): add --format csv or name the \
                      output .csv"
                .to_string(),
        });
    }
    // Ctrl-C and SIGTERM abandon an export of files read to their end, or of standard input
    // to a file, leaving any earlier file at the output as it was (standard input's at its next
    // bytes or its end: the Ctrl-C that stops a pipe's writer ends it too). Serial ports end
    // their input on them, and what they gave is written.
    let to_file = args.output.as_deref().is_some_and(|p| p != "-");
    let stdin = args.input.inputs.iter().any(|i| i == "-");
    let stop = args
        .input
        .stop_if_read_to_end()
        .or_else(|| (to_file && stdin).then(crate::stop::interrupted));
    let mut sources = args.input.sources(settings_map)?;
    if selection.window.is_limited() {
        sources.require_timing()?;
        args.select.check_clocks(&sources)?;
    }
    if args.time == CsvTime::Iso
        && let Some((input, format)) = sources.formats().find(|(_, f)| f.clock() == Clock::Capture)
    {
        return Err(CliError::Usage {
            option: "--time iso".to_string(),
            message: format!(
                "{input} ({format}) has no wall clock, its times count from the start of its \
                 capture: leave out --time iso"
            ),
        });
    }
    let provenance = Provenance {
        settings,
        overrides,
        inputs: sources.names().to_vec(),
        filter: args.select.text(),
        csv_comment: args.settings_comment,
        csv_time_iso: args.time == CsvTime::Iso,
    };
    keep_freed_memory();
    let output = args.output.as_deref();
    let mut export =
        Export::create(format, output, args.overwrite, provenance)?.select(selection.clone());
    if let Some(stop) = stop {
        export = export.stop_on(stop);
    }
    let result = sources.run(&mut export);
    if result.is_ok()
        && let Some(nothing) = sources.nothing_decoded()
    {
        // Nothing decoded: no output is written (a file of that name stays as it was).
        drop(export);
        warn(&sources, &args.select.esc);
        return Err(nothing.into());
    }
    let (kept, span) = (export.kept(), export.span());
    if let Some((first, _)) = span {
        // A bare time long before the data: nothing is written.
        args.select.check_bare_seconds(first)?;
    }
    // Whatever was decoded before an input error is still written out.
    let metadata = vec![(metadata::ESCS.to_string(), metadata::escs_json(&sources))];
    let finished = export.finish(metadata);
    result?;
    finished?;
    warn(&sources, &args.select.esc);
    if let (true, 0, Some((first, last))) = (selection.window.is_limited(), kept, span) {
        eprintln!(
            "hwfoc: warning: {}",
            hwfoc_io::no_frame_in_window(
                &args.select.text(),
                first,
                last,
                sources.clock() == Some(Clock::Wall)
            )
        );
    }
    Ok(())
}

/// The format of the output: `--format`, the one the -o file's name names, JSON Lines for
/// standard output, a device or a directory (refused as the output is created); a name naming none without `--format`, or another than
/// `--format`, is refused naming both.
fn output_format(
    format: Option<RecordFormat>,
    output: Option<&str>,
) -> Result<OutputFormat, CliError> {
    let given = format.map(|f| match f {
        RecordFormat::Jsonl => OutputFormat::Jsonl,
        RecordFormat::Csv => OutputFormat::Csv,
        RecordFormat::Parquet => OutputFormat::Parquet,
    });
    let Some(path) = output.filter(|&p| p != "-") else {
        return Ok(given.unwrap_or(OutputFormat::Jsonl));
    };
    let named = OutputFormat::from_name(path);
    // A device or a pipe is written as it is; a directory is refused when created.
    let device = std::fs::metadata(path).is_ok_and(|m| !m.is_file());
    match (given, named) {
        (Some(g), Some(n)) if g != n => Err(CliError::Usage {
            option: format!("--format {} -o {path}", g.extension()),
            message: format!(
                "the file's name says {}: name it .{} or leave out --format",
                n.extension(),
                g.extension()
            ),
        }),
        (Some(g), _) => Ok(g),
        (None, Some(n)) => Ok(n),
        (None, None) if device => Ok(OutputFormat::Jsonl),
        (None, None) => Err(CliError::Usage {
            option: format!("-o {path}"),
            message: "the format follows the file name: end it in .jsonl (or .ndjson), .csv \
                      or .parquet, or give --format"
                .to_string(),
        }),
    }
}

/// The entries by port and by ESC of `map`, named as in the configuration file (`port."NAME"`,
/// `esc.2`), with the fields that differ from the default settings (entries without any left
/// out).
fn overrides(map: &SettingsMap) -> Vec<(String, SettingsPatch)> {
    let default = map.default_settings();
    let differing = |p: &SettingsPatch| SettingsPatch {
        current_scale: p.current_scale.filter(|&v| v != default.current_scale),
        pole_pairs: p.pole_pairs.filter(|&v| v != default.pole_pairs),
        gear_ratio: p.gear_ratio.filter(|&v| v != default.gear_ratio),
        v4_volts_per_step: p
            .v4_volts_per_step
            .filter(|&v| v != default.v4_volts_per_step),
    };
    let ports = map.port_patches().map(|(name, p)| {
        let quoted = serde_json::Value::from(name).to_string();
        (format!("port.{quoted}"), differing(p))
    });
    let escs = map
        .esc_patches()
        .map(|(esc, p)| (format!("esc.{esc}"), differing(p)));
    ports.chain(escs).filter(|(_, p)| !p.is_empty()).collect()
}

/// Warnings on standard error: ESCs whose bytes held no frame, ESCs asked for but not found.
fn warn(sources: &Sources, wanted: &[u8]) {
    crate::args::warn_left_out(sources);
    // A CAN log in which no ESC was heard: its frames in CAN words.
    for info in sources.inputs() {
        if let (true, Some(looks @ hwfoc_io::Looks::Can { .. })) =
            (info.escs.is_empty(), info.looks)
        {
            eprintln!("hwfoc: warning: {}: {looks}", hwfoc_io::Escaped(&info.name));
        }
    }
    for i in 0..sources.escs().len() {
        let stats = sources.link(i);
        if stats.bytes() > 0 && stats.frames() == 0 && !sources.is_hub(i) {
            eprintln!(
                "hwfoc: warning: {}: {}",
                hwfoc_io::summary::esc_label(sources, i),
                hwfoc_io::summary::no_frames(sources, i)
            );
        }
    }
    let found = sources.escs().len();
    for &esc in wanted {
        if usize::from(esc) >= found {
            eprintln!(
                "hwfoc: warning: --esc {esc}: the inputs have {}",
                match found {
                    0 => "no ESC".to_string(),
                    1 => "only ESC 0".to_string(),
                    n => format!("only ESCs 0 to {}", n - 1),
                }
            );
        }
    }
}

/// Asks the C library's allocator to keep freed memory for reuse rather than hand it back to
/// the operating system at once. Encoding allocates and frees large buffers all the time (a
/// compressed page, a row group's columns); by default glibc unmaps or trims them on every
/// free, and faulting the pages in again took more time than compressing them. The export's
/// memory is bounded (see `hwfoc_io::write`), so keeping it costs nothing. A process-wide
/// setting: the command's to make, not the library's.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn keep_freed_memory() {
    // SAFETY: mallopt only changes allocator tuning parameters; it is called before the writer
    // threads start, and glibc serialises it with allocations in any case.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 256 << 20);
    }
}

/// Other C libraries keep their defaults.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn keep_freed_memory() {}
