//! `hwfoc`: decode and summarise Hobbywing HW-FOC ESC telemetry.
//!
//! A thin binary over the `hwfoc` codec: each subcommand is a module; errors travel up as
//! [`CliError`] and are reported once, here.

mod decode;
mod demo;
mod error;
mod monitor;
mod output;
mod plot;
mod record;
mod simulate;
mod summary;
mod window;

use std::process::ExitCode;

use clap::{Args, Parser, Subcommand, ValueEnum};
use hwfoc::Settings;

use crate::error::CliError;
use hwfoc_io::Input;
use hwfoc_io::serial;

/// Decode and analyse the telemetry of Hobbywing FOC ESCs (HW-FOC protocol, 19200 baud).
#[derive(Debug, Parser)]
#[command(name = "hwfoc", version, about, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Watch ESCs live: a dashboard of every ESC with alarms, charts and recording (or lines
    /// of text with --plain/--json).
    Monitor(Box<monitor::Args>),
    /// Decode telemetry into one record per data frame (JSON Lines, CSV or Parquet).
    Decode(DecodeArgs),
    /// Summarise a stream: frames, link quality, device information, min/max/mean of each field.
    Summary(SummaryArgs),
    /// Plot each ESC's telemetry over time, fault episodes marked (PNG or SVG).
    Plot(plot::Args),
    /// Record serial ports losslessly, with nanosecond receive times, to pcapng (Wireshark opens it).
    Record(record::Args),
    /// Virtual ESCs: the protocol from a physical model, to a pty, serial port, file or stdout.
    Simulate(Box<simulate::Args>),
}

/// Where telemetry comes from.
#[derive(Debug, Args)]
struct InputArgs {
    /// Serial ports (`/dev/ttyUSB0`, `COM3`; one ESC each, in the order given), recordings
    /// (pcapng), raw bytes from the wire or logic-analyser CSV exports (detected); `-` reads
    /// standard input. Files are read one after another.
    #[arg(value_name = "FILE|PORT|-", required_unless_present = "demo", num_args = 1..)]
    inputs: Vec<String>,
    /// Baud rate of serial ports (8N1).
    #[arg(long, value_name = "N", default_value_t = serial::DEFAULT_BAUD,
          value_parser = clap::value_parser!(u32).range(1..))]
    baud: u32,
    /// Use the built-in demo capture of a virtual ESC instead of FILE.
    #[arg(long, conflicts_with = "inputs")]
    demo: bool,
}

impl InputArgs {
    /// Opens every input, in the order given: each file (or standard input) as one [`Input`],
    /// all serial ports together as one [`Input`] with a stream per port. Ports and files
    /// cannot be mixed.
    fn open_all(&self) -> Result<Vec<Input>, CliError> {
        if self.demo || self.inputs.is_empty() {
            return Ok(vec![Input::from_memory(
                "demo capture",
                demo::capture_csv(),
            )?]);
        }
        let (ports, files): (Vec<&String>, Vec<&String>) =
            self.inputs.iter().partition(|spec| serial::is_port(spec));
        match (ports.first(), files.first()) {
            (Some(port), Some(file)) => Err(CliError::MixedInputs {
                port: port.to_string(),
                file: file.to_string(),
            }),
            (Some(_), None) => {
                let ports: Vec<String> = ports.into_iter().cloned().collect();
                Ok(vec![Input::open_ports(&ports, self.baud)?])
            }
            _ => Ok(files
                .into_iter()
                .map(|f| Input::open(f))
                .collect::<Result<_, _>>()?),
        }
    }
}

/// Conversion settings the frames do not carry.
#[derive(Debug, Args)]
struct SettingsArgs {
    /// Raw current units per ampere (the vendor document says 64; some drivers use 100).
    #[arg(long, value_name = "N", default_value_t = Settings::DEFAULT.current_scale)]
    current_scale: f32,
    /// Motor pole pairs (magnets / 2), for `rpm`.
    #[arg(long, value_name = "N", default_value_t = Settings::DEFAULT.pole_pairs)]
    pole_pairs: u16,
    /// Gear ratio between motor and output shaft, for `rpm`.
    #[arg(long, value_name = "X", default_value_t = Settings::DEFAULT.gear_ratio)]
    gear_ratio: f32,
}

impl SettingsArgs {
    fn settings(&self) -> Result<Settings, CliError> {
        Settings::new(self.current_scale, self.pole_pairs, self.gear_ratio)
            .map_err(CliError::Settings)
    }
}

/// Record output formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum RecordFormat {
    /// One JSON object per line, with exactly the schema's keys.
    Jsonl,
    /// Comma-separated, with a header row; faults joined by `|`, nulls empty.
    Csv,
    /// Apache Parquet (needs -o): typed columns, units and settings in the metadata.
    Parquet,
}

#[derive(Debug, Args)]
struct DecodeArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Output format.
    #[arg(long, value_enum, default_value_t = RecordFormat::Jsonl)]
    format: RecordFormat,
    #[command(flatten)]
    settings: SettingsArgs,
    /// CSV only: start with a `#` comment line giving the settings used.
    #[arg(long)]
    settings_comment: bool,
    /// Write to FILE instead of standard output.
    #[arg(short, long, value_name = "FILE", required_if_eq("format", "parquet"))]
    output: Option<String>,
    #[command(flatten)]
    select: window::SelectArgs,
}

#[derive(Debug, Args)]
struct SummaryArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Also plot the inputs to FILE (.png or .svg), as `hwfoc plot` does.
    #[arg(long, value_name = "FILE")]
    plot: Option<String>,
    #[command(flatten)]
    settings: SettingsArgs,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Monitor(args) => monitor::run(args),
        Command::Decode(args) => decode::run(args),
        Command::Summary(args) => summary::run(args),
        Command::Record(args) => record::run(args),
        Command::Simulate(args) => simulate::run(args),
        Command::Plot(args) => plot::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.is_broken_pipe() => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("hwfoc: {e}");
            ExitCode::FAILURE
        }
    }
}
