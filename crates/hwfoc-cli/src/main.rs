//! `hwfoc`: decode and summarise Hobbywing HW-FOC ESC telemetry.
//!
//! A thin binary over the `hwfoc` codec: each subcommand is a module; errors travel up as
//! [`CliError`] and are reported once, here.

mod decode;
mod demo;
mod error;
mod input;
mod output;
mod schema;
mod stream;
mod summary;

use std::process::ExitCode;

use clap::{Args, Parser, Subcommand, ValueEnum};
use hwfoc::Settings;

use crate::error::CliError;
use crate::input::Input;

/// Decode and analyse the telemetry of Hobbywing FOC ESCs (HW-FOC protocol, 19200 baud).
#[derive(Debug, Parser)]
#[command(name = "hwfoc", version, about, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Decode telemetry into one record per data frame (JSON Lines or CSV).
    Decode(DecodeArgs),
    /// Summarise a stream: frames, link quality, device information, min/max/mean of each field.
    Summary(SummaryArgs),
}

/// Where telemetry comes from.
#[derive(Debug, Args)]
struct InputArgs {
    /// Raw bytes from the wire or a logic-analyser CSV export (detected); `-` reads standard input.
    #[arg(value_name = "FILE|-", required_unless_present = "demo")]
    input: Option<String>,
    /// Use the built-in demo capture of a virtual ESC instead of FILE.
    #[arg(long, conflicts_with = "input")]
    demo: bool,
}

impl InputArgs {
    fn open(&self) -> Result<Input, CliError> {
        match &self.input {
            Some(path) if !self.demo => Input::open(path),
            _ => Input::from_memory("demo capture", demo::capture_csv()),
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

/// Record text formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum RecordFormat {
    /// One JSON object per line, with exactly the schema's keys.
    Jsonl,
    /// Comma-separated, with a header row; faults joined by `|`, nulls empty.
    Csv,
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
    #[arg(short, long, value_name = "FILE")]
    output: Option<String>,
}

#[derive(Debug, Args)]
struct SummaryArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    settings: SettingsArgs,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Decode(args) => decode::run(args),
        Command::Summary(args) => summary::run(args),
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
