//! `hwfoc`: decode, record, plot and bridge the telemetry of Hobbywing ESCs.
//!
//! A thin binary over the `hwfoc` codec and the `hwfoc-io` library: argument parsing and
//! presentation only. Each subcommand is a module of [`commands`]; errors travel up as
//! [`CliError`] and are reported once, here.

mod args;
mod commands;
mod config;
mod demo;
mod error;
mod output;
mod safety;
mod shown;
mod stop;

use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};

use crate::commands::{
    bridge, can, check, completions, decode, man, monitor, plot, record, simulate, summary, web,
};
use crate::error::CliError;

/// Decode, record, plot and bridge the telemetry of Hobbywing ESCs: HW-FOC (an XRotor FOC
/// ESC's own wire), DataLink V2 hubs, Platinum V4 and V3, HW5 and DroneCAN (CAN buses).
#[derive(Debug, Parser)]
#[command(name = "hwfoc", version = env!("HWFOC_VERSION"), about, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Watch ESCs live: a dashboard of every ESC with alarms, charts and recording (or lines
    /// of text with --plain/--json).
    Monitor(Box<monitor::MonitorArgs>),
    /// Decode telemetry into one record per data frame (JSON Lines, CSV or Parquet).
    Decode(decode::DecodeArgs),
    /// Summarise a stream: frames, link quality, device information, min/max/mean of each field.
    Summary(summary::SummaryArgs),
    /// Is this propulsion system healthy? Findings per ESC with their evidence (heat,
    /// imbalance, drift from a baseline, battery, faults, link, runtime); exit 0, 1 or 2.
    Check(check::CheckArgs),
    /// Plot each ESC's telemetry over time, fault episodes marked (PNG or SVG).
    Plot(plot::PlotArgs),
    /// Record serial ports and CAN buses (slcan:, can:) losslessly, with nanosecond receive
    /// times, to pcapng (Wireshark opens it).
    Record(record::RecordArgs),
    /// Virtual ESCs: the protocol from a physical model, to a pty, serial port, file or stdout.
    Simulate(Box<simulate::SimulateArgs>),
    /// Bridge ESC telemetry (ports, recordings, virtual ESCs) to flight controllers and ground
    /// stations: DataLink V2 frames, MAVLink, DroneCAN.
    Bridge(Box<bridge::BridgeArgs>),
    /// Set up Hobbywing DroneCAN ESCs on a CAN bus: list them, give each a node id and
    /// throttle channel, change direction, LED, rates, throttle source, run the self test.
    Can(can::CanArgs),
    /// The Wireshark dissector for recordings: install it, print where it goes, or print it.
    Wireshark(commands::wireshark::WiresharkArgs),
    /// The browser app: serve it on this computer (files and live ports in the browser).
    Web(web::WebArgs),
    /// Print the completion script for a shell (bash, zsh, fish, powershell, elvish).
    Completions(completions::CompletionsArgs),
    /// Write the manual pages (hwfoc.1 and one per subcommand), or print hwfoc.1.
    Man(man::ManArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // What a command that judges (`hwfoc check`) exits with when it ran.
    let mut code = 0u8;
    let result: Result<(), CliError> = match &cli.command {
        Command::Check(args) => check::run(args).map(|worst| code = worst.exit_code()),
        Command::Monitor(args) => monitor::run(args),
        Command::Decode(args) => decode::run(args),
        Command::Summary(args) => summary::run(args),
        Command::Record(args) => record::run(args),
        Command::Simulate(args) => simulate::run(args),
        Command::Plot(args) => plot::run(args),
        Command::Bridge(args) => bridge::run(args),
        Command::Can(args) => can::run(args),
        Command::Wireshark(args) => commands::wireshark::run(args),
        Command::Web(args) => web::run(args),
        Command::Completions(args) => completions::run(args, Cli::command()),
        Command::Man(args) => man::run(args, Cli::command()),
    };
    match result {
        Ok(()) => ExitCode::from(code),
        Err(e) if e.is_broken_pipe() => ExitCode::SUCCESS,
        Err(e) => {
            // Errors quote file content (a key, a name): shown escaped, and on one line.
            eprintln!("hwfoc: {}", hwfoc_io::Escaped(&e));
            ExitCode::FAILURE
        }
    }
}
