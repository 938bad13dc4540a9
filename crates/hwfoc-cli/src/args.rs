//! Option groups that several commands share: where telemetry comes from, and the conversion
//! settings the frames do not carry.

use clap::Args;
use hwfoc::Settings;
use hwfoc_io::serial;
use hwfoc_io::{Input, InputError};

use crate::demo;
use crate::error::CliError;

/// Where telemetry comes from.
#[derive(Debug, Args)]
pub struct InputArgs {
    /// Serial ports (`/dev/ttyUSB0`, `COM3`; one ESC each, in the order given), recordings
    /// (pcapng), raw bytes from the wire or logic-analyser CSV exports (detected); `-` reads
    /// standard input. Files are read one after another.
    #[arg(value_name = "FILE|PORT|-", required_unless_present = "demo", num_args = 1..)]
    pub inputs: Vec<String>,
    /// Baud rate of serial ports (8N1).
    #[arg(long, value_name = "N", default_value_t = serial::DEFAULT_BAUD,
          value_parser = clap::value_parser!(u32).range(1..))]
    pub baud: u32,
    /// Use the built-in demo capture of a virtual ESC instead of FILE.
    #[arg(long, conflicts_with = "inputs")]
    pub demo: bool,
}

impl InputArgs {
    /// Opens every input, in the order given: each file (or standard input) as one [`Input`],
    /// all serial ports together as one [`Input`] with a stream per port. Ports and files
    /// cannot be mixed.
    pub fn open_all(&self) -> Result<Vec<Input>, CliError> {
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
                .collect::<Result<_, InputError>>()?),
        }
    }
}

/// Conversion settings the frames do not carry.
#[derive(Debug, Args)]
pub struct SettingsArgs {
    /// Raw current units per ampere (the vendor document says 64; some drivers use 100).
    #[arg(long, value_name = "N", default_value_t = Settings::DEFAULT.current_scale)]
    pub current_scale: f32,
    /// Motor pole pairs (magnets / 2), for `rpm`.
    #[arg(long, value_name = "N", default_value_t = Settings::DEFAULT.pole_pairs)]
    pub pole_pairs: u16,
    /// Gear ratio between motor and output shaft, for `rpm`.
    #[arg(long, value_name = "X", default_value_t = Settings::DEFAULT.gear_ratio)]
    pub gear_ratio: f32,
}

impl SettingsArgs {
    pub fn settings(&self) -> Result<Settings, CliError> {
        Settings::new(self.current_scale, self.pole_pairs, self.gear_ratio)
            .map_err(CliError::Settings)
    }
}
