//! Option groups that several commands share: where telemetry comes from, the conversion
//! settings the frames do not carry, and which frames to keep.

use std::path::PathBuf;

use clap::Args;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use hwfoc::Protocol;
use hwfoc::v4::VoltsPerStep;
use hwfoc_io::Sources;
use hwfoc_io::time::{Clock, Time, TimeError};
use hwfoc_io::{Input, InputError, OpenInput};
use hwfoc_io::{Selection, Window};
use hwfoc_io::{SettingsMap, SettingsPatch};
use hwfoc_ports::serial;

use crate::demo;
use crate::error::CliError;

/// Where telemetry comes from.
#[derive(Debug, Args)]
pub struct InputArgs {
    /// Serial ports (`/dev/ttyUSB0`, `COM3`; one ESC each, in the order given), CAN buses
    /// (`slcan:/dev/ttyACM0`, `can:can0`), recordings (pcapng, serial or CAN), `candump -l`
    /// logs, raw bytes from the wire (HW-FOC, DataLink V2, V4, V3, HW5) or logic-analyser CSV
    /// exports (the format detected); `-` reads standard input. Each input's ESCs are its own, numbered in the order given. Recordings
    /// and analyser CSV exports given together are merged in time order (the files of one
    /// recording, such as a rotated one, continue each port's stream; a file given twice is
    /// read once); raw files and standard input, which have no receive times, are read one
    /// after another.
    #[arg(value_name = "FILE|PORT|-", required_unless_present = "demo", num_args = 1..)]
    pub inputs: Vec<String>,
    /// Baud rate of serial ports (8N1) [default: that of --protocol, else found from the
    /// bytes: 19200 and 115200 tried in turn].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub baud: Option<u32>,
    /// Use the built-in demo capture of a virtual ESC (HW-FOC) instead of FILE.
    #[arg(long, conflicts_with = "inputs")]
    pub demo: bool,
    /// Read the recordings given as one: their ports go on from file to file by name. Without
    /// it, only the files of one `hwfoc record` run (rotated files: they carry its recording
    /// id) are one recording; every other file is ESCs of its own, however its ports are
    /// named (port names such as /dev/ttyUSB0 are the same on every drone). Give it for the
    /// parts of one recording that another program wrote or cut.
    #[arg(long)]
    pub join: bool,

    #[command(flatten)]
    pub protocol: ProtocolArgs,
}

/// `--protocol`: one protocol read instead of every one the bytes may hold.
#[derive(Debug, Default, Clone, Copy, Args)]
pub struct ProtocolArgs {
    /// Read only this protocol's frames; the bytes of any other are skipped, and a CAN bus's
    /// records of any other left out (counted in a warning). A CAN protocol reads CAN inputs
    /// only: serial bytes then decode to nothing, and serial ports are an error. Without it,
    /// every protocol is recognised from the bytes.
    #[arg(long, value_name = "NAME", value_parser = protocol_parser())]
    pub protocol: Option<Protocol>,
}

/// The names of [`Protocol::ALL`] as `--protocol` takes them (shown by `--help` and
/// completed by the shells), each with its title and baud rate (a CAN protocol's: on a CAN
/// bus).
fn protocol_parser() -> impl TypedValueParser<Value = Protocol> {
    let names = Protocol::ALL.map(|p| {
        let help = if p.is_can() {
            format!("{}, on a CAN bus", p.title())
        } else {
            format!("{}, {} baud", p.title(), p.baud_rate())
        };
        PossibleValue::new(p.name()).help(help)
    });
    // Every possible value is a protocol's name: the mapping finds it.
    PossibleValuesParser::new(names)
        .map(|name| Protocol::from_name(&name).unwrap_or(Protocol::ALL[0]))
}

impl ProtocolArgs {
    /// The baud rate of serial ports: `baud` (`--baud`) when given, else the forced serial
    /// protocol's, else found by each port from its bytes ([`serial::Baud::Auto`]).
    pub fn baud(&self, baud: Option<u32>) -> serial::Baud {
        match baud.or(self.protocol.and_then(Protocol::serial_baud_rate)) {
            Some(baud) => serial::Baud::Fixed(baud),
            None => serial::Baud::Auto,
        }
    }

    /// An error when a CAN protocol is forced on a serial port of `ports` (not a CAN bus,
    /// `slcan:`/`can:`): its bytes could never be CAN frames.
    pub fn check_ports<'a>(
        &self,
        ports: impl IntoIterator<Item = &'a str>,
    ) -> Result<(), CliError> {
        let Some(protocol) = self.protocol.filter(|p| p.is_can()) else {
            return Ok(());
        };
        match ports
            .into_iter()
            .find(|p| !hwfoc_ports::can::is_can_spec(p))
        {
            Some(port) => Err(CliError::Usage {
                option: format!("--protocol {protocol}"),
                message: format!(
                    "a CAN protocol reads CAN buses (slcan:PORT, can:INTERFACE), not the serial \
                     port {port}"
                ),
            }),
            None => Ok(()),
        }
    }
}

impl InputArgs {
    /// The flag Ctrl-C and SIGTERM set ([`crate::stop::interrupted`], whose handlers it
    /// installs), when every input is read to its end: an export or a plot of files is then
    /// abandoned on the signal, its temporary file removed. `None` for serial ports, pipes and
    /// terminals, which end their input on the signal instead (what they gave is kept), or
    /// keep the signal's default action.
    pub fn stop_if_read_to_end(&self) -> Option<std::sync::Arc<std::sync::atomic::AtomicBool>> {
        let read_to_end = self.inputs.iter().all(|spec| {
            let meta = if spec == "-" {
                stdin_metadata()
            } else {
                std::fs::metadata(spec).ok()
            };
            meta.is_some_and(|m| m.is_file())
        });
        read_to_end.then(crate::stop::interrupted)
    }

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
                self.protocol
                    .check_ports(ports.iter().map(|p| p.as_str()))?;
                let ports: Vec<String> = ports.into_iter().cloned().collect();
                Ok(vec![Input::open_ports(
                    &ports,
                    self.protocol.baud(self.baud),
                    crate::stop::interrupted(),
                )?])
            }
            _ => Ok(files
                .into_iter()
                .map(|f| Input::open(f))
                .collect::<Result<_, InputError>>()?),
        }
    }

    /// Every input opened ([`InputArgs::open_all`]) as the [`Sources`] read with `settings`,
    /// forced to read the protocol of `--protocol` only when it is given.
    pub fn sources(&self, settings: SettingsMap) -> Result<Sources, CliError> {
        let mut sources = Sources::new(self.open_all()?, settings);
        if let Some(protocol) = self.protocol.protocol {
            sources.force_protocol(protocol);
        }
        if self.join {
            sources.join_recordings();
        }
        Ok(sources)
    }
}

/// Warns on standard error of what `--protocol` left out of the CAN buses read
/// ([`hwfoc_io::summary::left_out`]): one line per bus.
pub fn warn_left_out(sources: &Sources) {
    for notice in hwfoc_io::summary::left_out(sources) {
        eprintln!("{}", notice.line());
    }
}

/// What standard input is.
#[cfg(unix)]
fn stdin_metadata() -> Option<std::fs::Metadata> {
    use std::os::fd::AsFd;
    let fd = std::io::stdin().as_fd().try_clone_to_owned().ok()?;
    std::fs::File::from(fd).metadata().ok()
}

/// What standard input is (not looked at elsewhere: taken as live).
#[cfg(not(unix))]
fn stdin_metadata() -> Option<std::fs::Metadata> {
    None
}

/// How the configuration file and the flags combine, for `--help`.
pub const SETTINGS_HELP: &str = "Configuration file (TOML). Settings come from, first to last \
(field by field): these flags; the ESC's [esc.N] entry in the configuration file; its port's \
[port.\"NAME\"] entry; the file's [settings]; the defaults (current scale 64, 7 pole pairs, gear \
ratio 1). The file: --config FILE, else $HWFOC_CONFIG, else hwfoc/config.toml in the user's \
configuration directory ($XDG_CONFIG_HOME or ~/.config) if it exists; --no-config reads none. \
See the README (Configuration).";

/// Conversion settings the frames do not carry, and the configuration file that sets them.
#[derive(Debug, Default, Clone, Args)]
pub struct SettingsArgs {
    /// Raw current units per ampere, for every ESC (the vendor document says 64; some drivers
    /// use 100) [default: from the configuration file, else 64].
    #[arg(long, value_name = "N", help_heading = "Settings")]
    pub current_scale: Option<f32>,
    /// Motor pole pairs (magnets / 2), for `rpm`, for every ESC [default: from the
    /// configuration file, else 7].
    #[arg(long, value_name = "N", help_heading = "Settings")]
    pub pole_pairs: Option<u16>,
    /// Gear ratio between motor and output shaft, for `rpm`, for every ESC [default: from the
    /// configuration file, else 1].
    #[arg(long, value_name = "X", help_heading = "Settings")]
    pub gear_ratio: Option<f32>,
    /// Volts per voltage step of Hobbywing V4 ESCs until their first info frame is adopted
    /// (which gives its own): N/D, or low (8/910, low-voltage models) or hv (11/650, HV
    /// models) [default: from the configuration file, else 8/910].
    #[arg(long, value_name = "N/D", help_heading = "Settings")]
    pub v4_volts_per_step: Option<VoltsPerStep>,
    /// A format's own setting, for every ESC (repeat for several): KEY=VALUE, the keys those of
    /// the formats' descriptions (v4_volts_per_step=N/D, low or hv; its flag
    /// --v4-volts-per-step, which wins, is an alias) [default: from the configuration file, else
    /// the format's].
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = format_setting, help_heading = "Settings")]
    pub set: Vec<SettingsPatch>,
    /// Configuration file (TOML) [default: $HWFOC_CONFIG, else hwfoc/config.toml in the user's
    /// configuration directory, if it exists].
    #[arg(long, value_name = "FILE", help_heading = "Settings", long_help = SETTINGS_HELP)]
    pub config: Option<PathBuf>,
    /// Read no configuration file.
    #[arg(long, conflicts_with = "config", help_heading = "Settings")]
    pub no_config: bool,
}

impl SettingsArgs {
    /// The settings set by flags.
    pub fn patch(&self) -> SettingsPatch {
        let flags = SettingsPatch {
            current_scale: self.current_scale,
            pole_pairs: self.pole_pairs,
            gear_ratio: self.gear_ratio,
            v4_volts_per_step: self.v4_volts_per_step,
        };
        // The last --set of a key wins; a flag of its own wins over --set.
        let set = self
            .set
            .iter()
            .fold(SettingsPatch::default(), |under, set| set.over(&under));
        flags.over(&set)
    }
}

/// `--set KEY=VALUE`: a format's own setting ([`SettingsPatch::format_setting`]).
fn format_setting(text: &str) -> Result<SettingsPatch, String> {
    let (key, value) = text
        .split_once('=')
        .ok_or_else(|| format!("{text:?} is not KEY=VALUE"))?;
    SettingsPatch::format_setting(key.trim(), value.trim()).map_err(|e| e.to_string())
}

/// The selection options that `decode` and `plot` share.
#[derive(Debug, Args)]
pub struct SelectArgs {
    /// Only these ESCs (indices as in the `esc` column; repeat or separate with commas).
    #[arg(long, value_name = "N", value_delimiter = ',')]
    pub esc: Vec<u8>,
    /// Only frames received at or after TIME: +S after the first frame (+5, +2m, +1h30m,
    /// +250ms), seconds of the inputs' clock (Unix time for recordings and serial ports, the
    /// analyser's clock for a CSV export), or an ISO 8601 date-time (2026-11-23T14:03:00Z,
    /// 2026-11-23T14:03:00.250+01:00; without an offset, local time: 2026-11-23 14:03).
    /// Needs inputs with receive times.
    #[arg(long, value_name = "TIME", allow_negative_numbers = true, value_parser = time)]
    pub from: Option<Time>,
    /// Only frames received before TIME (as for --from).
    #[arg(long, value_name = "TIME", allow_negative_numbers = true, value_parser = time)]
    pub to: Option<Time>,
}

/// A `--from`/`--to` time (see [`hwfoc_io::time`] for the grammar).
fn time(text: &str) -> Result<Time, TimeError> {
    hwfoc_io::time::parse(text)
}

impl SelectArgs {
    /// The ESCs and the window of receive times; an empty window is an error.
    pub fn selection(&self) -> Result<Selection, CliError> {
        let window = Window::from_times(self.from, self.to).map_err(CliError::Window)?;
        Ok(Selection::new(&self.esc, window))
    }

    /// Refuses a date-time for inputs without a wall clock (a logic-analyser CSV counts from
    /// the start of its capture): it could select nothing. Call it before reading.
    pub fn check_clocks(&self, sources: &Sources) -> Result<(), CliError> {
        for (option, time) in [("--from", self.from), ("--to", self.to)] {
            let Some(time) = time.filter(Time::is_date) else {
                continue;
            };
            if let Some((input, format)) = sources.formats().find(|(_, f)| f.clock() != Clock::Wall)
            {
                return Err(CliError::Usage {
                    option: format!("{option} {time}"),
                    message: format!(
                        "{input} ({format}) has no wall clock, its times count from the start \
                         of its capture: give seconds of its clock or +S after the first frame"
                    ),
                });
            }
        }
        Ok(())
    }

    /// Refuses a bare number of seconds more than a year before the data's first receive time
    /// `first` (`--from 5` meant as five seconds in: it would select everything, or nothing),
    /// suggesting `+N`. Call it once the first time is known.
    pub fn check_bare_seconds(&self, first: f64) -> Result<(), CliError> {
        for (option, time) in [("--from", self.from), ("--to", self.to)] {
            if let Some(Time::Seconds(s)) = time
                && hwfoc_io::time::long_before(s, first)
            {
                return Err(CliError::Usage {
                    option: format!("{option} {time}", time = Time::Seconds(s)),
                    message: format!(
                        "that is more than a year before the data (from {}): for seconds after \
                         the first frame, give +{s}",
                        hwfoc_io::time::iso8601(first)
                    ),
                });
            }
        }
        Ok(())
    }

    /// The filters, as recorded with an output: `esc=0,2 from=+1.5 to=1795442580`, or empty.
    pub fn text(&self) -> String {
        hwfoc_io::filter_text(&self.esc, self.from, self.to)
    }
}

/// The longest time any option takes, s (about 31 years): longer would overflow the clocks.
pub const MAX_SECONDS: f64 = 1e9;

/// A positive, finite number of seconds, at most [`MAX_SECONDS`] (`--duration`, `--interval`,
/// `--rotate-time`).
pub fn seconds(text: &str) -> Result<f64, String> {
    let s = text
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|s| s.is_finite() && *s > 0.0)
        .ok_or_else(|| format!("{text:?} is not a positive number of seconds"))?;
    if s > MAX_SECONDS {
        return Err(format!("{text:?}: at most {MAX_SECONDS} seconds"));
    }
    Ok(s)
}
