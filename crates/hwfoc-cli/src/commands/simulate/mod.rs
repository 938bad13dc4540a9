//! `hwfoc simulate`: virtual ESCs that speak their protocol as real ones do (HW-FOC by default;
//! `--protocol hw-v4`, `hw-v3` or `hw5`: [`hwfoc_sim::formats`]; `--protocol hw-can`: a CAN
//! bus of Hobbywing DroneCAN ESCs, [`hwfoc_sim::can`], run by the `can` module).
//!
//! The simulator is the `hwfoc_sim` library; this command turns its options into the library's
//! description of a run (a [`FleetSpec`] and a [`Plan`]), refuses options that do not go
//! together, announces the pseudo-terminals and reports on each ESC at the end. The ground
//! truth's clock is described in [`hwfoc_sim::session`].

use std::io::{IsTerminal, Write};

use clap::ValueEnum;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use hwfoc::{Protocol, Settings};

mod can;

use crate::args::SettingsArgs;
use crate::error::CliError;
use hwfoc_io::write::WriteError;
use hwfoc_sim::degrade::DegradeSpec;
use hwfoc_sim::faults::{FaultSpec, LinkRates};
use hwfoc_sim::fleet::MAX_ESCS;
use hwfoc_sim::formats::SIMULATED;
use hwfoc_sim::model::ModelConfig;
use hwfoc_sim::profile::{ProfileSpec, Shape};
#[cfg(unix)]
use hwfoc_sim::pty::PtyLinks;
use hwfoc_sim::template::expand;
use hwfoc_sim::{
    Destination, EscReport, FileFormat, FleetSpec, Plan, Session, SimError, VirtualFleet,
};

/// File formats of `-o`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// The bytes as they were on the wire.
    Raw,
    /// A pcapng recording (one interface per ESC, nanosecond timestamps; hw-can: one
    /// SocketCAN interface, a packet per frame), as `hwfoc record` writes.
    Pcapng,
    /// hw-can: a `candump -l` log, `(secs.usecs) can0 ID#DATA` lines.
    Candump,
}

impl Format {
    /// The serial simulator's file format; `None` for a CAN bus's only ([`Format::Candump`]).
    fn serial(self) -> Option<FileFormat> {
        match self {
            Format::Raw => Some(FileFormat::Raw),
            Format::Pcapng => Some(FileFormat::Pcapng),
            Format::Candump => None,
        }
    }
}

const EXAMPLES: &str = "\
Examples:
  hwfoc simulate --pty                                # one ESC on a pseudo-terminal, until Ctrl-C
  hwfoc simulate --escs 8 --pty --link-dir ~/escs     # ~/escs/esc0 .. esc7 (a directory of your own)
  hwfoc simulate -o run.bin --truth truth.jsonl       # raw bytes, 18 s simulated, at once
  hwfoc simulate --escs 4 -o run.pcapng --profile sine --duration 60
  hwfoc simulate --drop-rate 0.02 --bit-error-rate 1e-4 --fault mos_overheat@5-7 | hwfoc decode -
  hwfoc simulate --port /dev/ttyUSB0 --profile csv:flight.csv
  hwfoc simulate --protocol hw5 --fault motor_blocked@5-6 -o hw5.pcapng  # an HW5 ESC at 115200 baud
  hwfoc simulate --protocol hw-can --escs 4 -o bus.log # a candump log of 4 DroneCAN ESCs
  hwfoc simulate --protocol hw-can --escs 4 -o bus.pcapng --no-ask-ids  # pcapng, no GetEscID
  hwfoc simulate --protocol hw-can --escs 4 --factory --pty  # an SLCAN adapter, all ESCs node 1";

/// Arguments of `hwfoc simulate`.
#[derive(Debug, clap::Args)]
#[command(after_help = EXAMPLES)]
pub struct SimulateArgs {
    /// Number of virtual ESCs (esc 0..N-1). With --port: one per port.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=256))]
    escs: Option<u16>,
    /// Seconds of simulated time. Default: one run of the profile plus 2 s for files and
    /// standard output; until Ctrl-C in real time.
    #[arg(long, value_name = "S", value_parser = crate::args::seconds)]
    duration: Option<f64>,
    /// The protocol the virtual ESCs speak: hw-foc (default), hw-v4 (Platinum V4), hw-v3
    /// (Platinum V3), hw5 (Platinum V5, VBAR) or hw-can (Hobbywing DroneCAN ESCs on a CAN
    /// bus: a candump log or pcapng with -o, an SLCAN adapter with --pty). V3 and V4 carry no
    /// fault word (faults act on the model only); HW5's fault byte carries the faults that map
    /// to its flags; link faults are for hw-foc only. Standard DroneCAN ESCs (dronecan) are not
    /// simulated.
    #[arg(long, value_name = "NAME", value_parser = protocol_parser())]
    protocol: Option<Protocol>,
    /// hw-can: every ESC as it leaves the factory (node 1, throttle channel 1, 500 kbit/s)
    /// instead of set up (node 10 + N, channel N + 1).
    #[arg(long)]
    factory: bool,
    /// hw-can, a log or pcapng: no virtual controller asking the ESCs for their ids (by
    /// default node 127 sends GetEscID `[0]` at the start and once a second while no ESC turns,
    /// as ArduPilot does, and the ESCs answer).
    #[arg(long)]
    no_ask_ids: bool,
    /// Line rate in baud (8N1). Default: the protocol's (19200; 115200 for hw5).
    #[arg(long, value_name = "BAUD",
          value_parser = clap::value_parser!(u32).range(9_600..=4_000_000))]
    baud: Option<u32>,
    /// The virtual ESCs: random seed, throttle profile, physical model, faults.
    #[command(flatten)]
    pub model: ModelArgs,
    /// How the ESC scales currents and which pole pairs it has; the ground truth is converted
    /// with the same settings (and the gear ratio).
    #[command(flatten, next_help_heading = "Model")]
    settings: SettingsArgs,

    /// A pseudo-terminal per ESC: prints `esc N: PATH` per line, then runs in real time.
    #[arg(long, conflicts_with_all = ["port", "output"], help_heading = "Output")]
    pty: bool,
    /// With --pty: a symlink to each ESC's pty (one PATH per ESC, or one with `{esc}` in it),
    /// removed on exit.
    #[arg(long, value_name = "PATH", requires = "pty", help_heading = "Output")]
    link: Vec<String>,
    /// With --pty: symlinks DIR/esc0, DIR/esc1, ... (DIR is created), removed on exit.
    #[arg(
        long,
        value_name = "DIR",
        requires = "pty",
        conflicts_with = "link",
        help_heading = "Output"
    )]
    link_dir: Option<String>,
    /// Real serial ports, one per ESC, in real time.
    #[arg(long, value_name = "PORT", num_args = 1.., conflicts_with = "output",
          help_heading = "Output")]
    port: Vec<String>,
    /// Write to FILE as fast as possible (`{esc}` in the name: one file per ESC). Default:
    /// standard output.
    #[arg(short, long, value_name = "FILE", help_heading = "Output")]
    output: Option<String>,
    /// File format. Default: pcapng for a name ending in .pcapng, else raw (hw-can: candump).
    #[arg(long, value_enum, help_heading = "Output")]
    format: Option<Format>,
    /// Write the file or standard output at the real rate instead of as fast as possible.
    #[arg(long, help_heading = "Output")]
    realtime: bool,
    /// Write the ground truth: one JSON Lines record per data frame delivered intact.
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    truth: Option<String>,
    /// Unix time (seconds) of the start, for recordings and the truth of file outputs.
    /// Default: now for pcapng, 0 for raw bytes.
    #[arg(long, value_name = "UNIX_S", value_parser = start_time, help_heading = "Output")]
    start_time: Option<f64>,
    /// Replace output files (-o, --truth) that exist. Without it, an existing file is an error
    /// and nothing is written.
    #[arg(long, help_heading = "Output")]
    overwrite: bool,
    /// No per-ESC report on standard error at the end.
    #[arg(short, long, help_heading = "Output")]
    quiet: bool,
}

/// What the virtual ESCs do, shared by `hwfoc simulate` and `hwfoc monitor --sim`.
#[derive(Debug, Clone, PartialEq, clap::Args)]
pub struct ModelArgs {
    /// Seed of every random choice: the same seed and options give the same bytes.
    #[arg(long, value_name = "N", default_value_t = 1, help_heading = "Model")]
    seed: u64,
    /// First packet number of every ESC (e.g. 65500 to see the wrap soon). Default: random
    /// per ESC, from the seed.
    #[arg(long, value_name = "N", help_heading = "Model")]
    start_packet: Option<u16>,

    /// Throttle profile: steps, ramp, sine, or csv:FILE with rows time_s,throttle_percent.
    #[arg(
        long,
        value_name = "NAME",
        default_value = "steps",
        help_heading = "Throttle"
    )]
    profile: ProfileSpec,
    /// Seconds at zero throttle before the built-in profiles start (the ESC arms, idles).
    #[arg(long, value_name = "S", default_value_t = 2.0, value_parser = non_negative,
          help_heading = "Throttle")]
    lead_in: f64,
    /// steps: the levels in percent, held in turn.
    #[arg(long, value_name = "PCT,..", value_delimiter = ',', value_parser = percent,
          default_value = "0,25,50,75,100,50,0", help_heading = "Throttle")]
    levels: Vec<f64>,
    /// steps: seconds per level.
    #[arg(long, value_name = "S", default_value_t = 2.0, value_parser = positive,
          help_heading = "Throttle")]
    hold: f64,
    /// ramp, sine: seconds per cycle.
    #[arg(long, value_name = "S", default_value_t = 10.0, value_parser = positive,
          help_heading = "Throttle")]
    period: f64,
    /// ramp, sine: highest throttle, percent.
    #[arg(long, value_name = "PCT", default_value_t = 80.0, value_parser = percent,
          help_heading = "Throttle")]
    max_throttle: f64,

    /// Motor KV (RPM per volt).
    #[arg(long, value_name = "KV", default_value_t = 500.0, value_parser = positive,
          help_heading = "Model")]
    kv: f64,
    /// Input current at full throttle on a full battery, A: sets the propeller's load.
    #[arg(long, value_name = "A", default_value_t = 60.0, value_parser = positive,
          help_heading = "Model")]
    full_current: f64,
    /// Battery cells in series (LiPo).
    #[arg(long, value_name = "N", default_value_t = 6,
          value_parser = clap::value_parser!(u8).range(1..=24), help_heading = "Model")]
    cells: u8,
    /// Battery internal resistance, ohm.
    #[arg(long, value_name = "OHM", default_value_t = 0.02, value_parser = non_negative,
          help_heading = "Model")]
    battery_r: f64,
    /// Battery capacity, mAh.
    #[arg(long, value_name = "MAH", default_value_t = 5000.0, value_parser = positive,
          help_heading = "Model")]
    capacity: f64,
    /// Ambient temperature, degC.
    #[arg(long, value_name = "DEGC", default_value_t = 25.0, value_parser = ambient,
          help_heading = "Model")]
    ambient: f64,
    /// Raise a status bit from START to END seconds (to the end without END), on every ESC or
    /// on ESC number ESC. Repeatable.
    #[arg(
        long = "fault",
        value_name = "[ESC:]NAME@START[-END]",
        help_heading = "Faults"
    )]
    faults: Vec<FaultSpec>,
    /// Degrade ESC number ESC from START seconds on (0 without it) at SEVERITY from 0 to 1
    /// (0.5 without it). KIND: bearing (current x (1 + SEVERITY) for the same RPM), prop (a
    /// damaged propeller: RPM +20 % x SEVERITY, load -50 % x SEVERITY, with a ripple),
    /// battery (resistance x (1 + SEVERITY): more sag per ampere), wire (bursts of 5-20 frames
    /// lost, hw-foc only), heat (MOSFET temperature rising by up to 80 K x SEVERITY over 10
    /// minutes). The truth (--truth) starts with one line per degradation. Repeatable.
    #[arg(
        long = "degrade",
        value_name = "ESC:KIND[@START][=SEVERITY]",
        help_heading = "Faults"
    )]
    degradations: Vec<DegradeSpec>,
    /// Probability that a bit on the wire is flipped.
    #[arg(long, value_name = "P", default_value_t = 0.0, value_parser = probability,
          help_heading = "Faults")]
    bit_error_rate: f64,
    /// Probability that a frame is not sent (its packet number is still used).
    #[arg(long, value_name = "P", default_value_t = 0.0, value_parser = probability,
          help_heading = "Faults")]
    drop_rate: f64,
    /// Probability that a frame stops part-way.
    #[arg(long, value_name = "P", default_value_t = 0.0, value_parser = probability,
          help_heading = "Faults")]
    cut_rate: f64,
    /// Probability of a burst of garbage (up to 32 bytes of line noise) before a frame.
    #[arg(long, value_name = "P", default_value_t = 0.0, value_parser = probability,
          help_heading = "Faults")]
    garbage_rate: f64,
}

impl ModelArgs {
    /// Whether any option differs from its default (so that `monitor` can refuse them
    /// without `--sim`).
    pub fn is_default(&self) -> bool {
        use clap::{Args, FromArgMatches};
        let command = ModelArgs::augment_args(clap::Command::new("defaults"));
        command
            .try_get_matches_from(["defaults"])
            .ok()
            .and_then(|m| ModelArgs::from_arg_matches(&m).ok())
            .is_some_and(|defaults| defaults == *self)
    }

    /// The `n` virtual ESCs these arguments describe, at `baud`, their currents and RPM scaled
    /// by `settings`.
    pub fn spec(&self, n: usize, baud: u32, settings: &Settings) -> FleetSpec {
        FleetSpec {
            n,
            seed: self.seed,
            protocol: hwfoc::Protocol::HwFoc,
            baud,
            start_packet: self.start_packet,
            profile: self.profile.clone(),
            shape: Shape {
                lead_in_s: self.lead_in,
                levels: self.levels.clone(),
                hold_s: self.hold,
                period_s: self.period,
                max_pct: self.max_throttle,
            },
            model: ModelConfig {
                kv: self.kv,
                pole_pairs: settings.pole_pairs,
                full_current_a: self.full_current,
                cells: self.cells,
                battery_r_ohm: self.battery_r,
                capacity_mah: self.capacity,
                ambient_c: self.ambient,
                current_scale: settings.current_scale,
            },
            faults: self.faults.clone(),
            link: LinkRates {
                bit_error: self.bit_error_rate,
                drop: self.drop_rate,
                cut: self.cut_rate,
                garbage: self.garbage_rate,
            },
            degradations: self.degradations.clone(),
        }
    }

    /// The fleet of [`ModelArgs::spec`], checked (fault ESC numbers, the profile file) but not
    /// started.
    pub fn fleet(
        &self,
        n: usize,
        baud: u32,
        settings: &Settings,
    ) -> Result<VirtualFleet, CliError> {
        Ok(self.spec(n, baud, settings).build()?)
    }
}

/// The names of the protocols a virtual ESC speaks, each with its title and rate: the serial
/// protocols of [`SIMULATED`] and `hw-can`; `dronecan` is taken (hidden) to be refused with a
/// line of its own.
fn protocol_parser() -> impl TypedValueParser<Value = Protocol> {
    let names = SIMULATED
        .into_iter()
        .chain([Protocol::HwCan])
        .map(|p| {
            let unit = if p.is_can() { "bit/s" } else { "baud" };
            PossibleValue::new(p.name()).help(format!("{}, {} {unit}", p.title(), p.baud_rate()))
        })
        .chain([PossibleValue::new(Protocol::DroneCan.name()).hide(true)]);
    // Every possible value is a protocol's name: the mapping finds it.
    PossibleValuesParser::new(names)
        .map(|name| Protocol::from_name(&name).unwrap_or(Protocol::HwFoc))
}

fn number(s: &str) -> Result<f64, String> {
    s.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| format!("{s:?} is not a number"))
}

fn positive(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if v <= 0.0 {
        return Err(format!("{s} must be more than 0"));
    }
    Ok(v)
}

/// The latest start time, Unix seconds (the year 2286): timestamps are nanoseconds in a
/// `u64`, which this and the longest run (`crate::args::MAX_SECONDS`) leave room for.
const MAX_START_S: f64 = 1e10;

fn start_time(s: &str) -> Result<f64, String> {
    let v = non_negative(s)?;
    if v > MAX_START_S {
        return Err(format!(
            "{s}: the start time must be from 0 to {MAX_START_S} Unix seconds (the year 2286)"
        ));
    }
    Ok(v)
}

fn non_negative(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if v < 0.0 {
        return Err(format!("{s} must be 0 or more"));
    }
    Ok(v)
}

fn percent(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if !(0.0..=100.0).contains(&v) {
        return Err(format!("{s} is not a percentage from 0 to 100"));
    }
    Ok(v)
}

fn probability(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if !(0.0..=1.0).contains(&v) {
        return Err(format!("{s} is not a probability from 0 to 1"));
    }
    Ok(v)
}

fn ambient(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if !(-40.0..=85.0).contains(&v) {
        return Err(format!("{s} degC is outside -40..85"));
    }
    Ok(v)
}

fn usage(option: &str, message: impl Into<String>) -> CliError {
    CliError::Usage {
        option: option.to_string(),
        message: message.into(),
    }
}

/// Runs `hwfoc simulate`.
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    let config = args.settings.config()?;
    let settings = config.settings(&args.settings)?;
    let protocol = args.protocol.unwrap_or(Protocol::HwFoc);
    // The serial formats are simulated alike (`hwfoc-sim`'s protocols); of the CAN formats,
    // Hobbywing's only.
    if protocol == Protocol::HwCan {
        return can::run(args, &config, settings);
    }
    if protocol == Protocol::DroneCan {
        return Err(usage(
            "--protocol",
            "standard DroneCAN ESCs (dronecan) are not simulated: --protocol hw-can \
             simulates Hobbywing's DroneCAN ESCs",
        ));
    }
    if args.factory {
        return Err(usage("--factory", "only for --protocol hw-can"));
    }
    if args.no_ask_ids {
        return Err(usage("--no-ask-ids", "only for --protocol hw-can"));
    }
    let n = count_escs(args)?;
    let plan = plan(args, n, settings)?;
    // The files read: the profile and the configuration.
    let profile = match &args.model.profile {
        ProfileSpec::Csv(path) => Some(std::path::PathBuf::from(path)),
        _ => None,
    };
    let reads: Vec<std::path::PathBuf> = profile
        .into_iter()
        .chain(crate::safety::config_read(&config))
        .collect();
    refuse_clashes(&plan, n, &reads)?;
    let baud = args.baud.unwrap_or(protocol.baud_rate());
    let spec = FleetSpec {
        protocol,
        ..args.model.spec(n, baud, &settings)
    };
    let fleet = spec.build().map_err(|e| match e {
        e @ SimError::NoFaultFlag { .. } => usage("--fault", e.to_string()),
        e @ (SimError::NoSuchDegradedEsc { .. } | SimError::WireDegradation { .. }) => {
            usage("--degrade", e.to_string())
        }
        e => CliError::from(e),
    })?;
    let session = Session::open(fleet, &plan)?;
    if args.pty {
        announce(session.outputs())?;
    }
    let reports = session.run(&crate::stop::interrupted())?;
    if !args.quiet {
        for (esc, r) in reports.iter().enumerate() {
            eprintln!("{}", report(esc, r));
        }
    }
    Ok(())
}

/// How many ESCs: `--escs`, or one per `--port`.
fn count_escs(args: &SimulateArgs) -> Result<usize, CliError> {
    let n = match (args.escs, args.port.len()) {
        (Some(n), 0) => usize::from(n),
        (None, 0) => 1,
        (None, ports) => ports,
        (Some(n), ports) if usize::from(n) == ports => ports,
        (Some(n), ports) => {
            return Err(usage(
                "--port",
                format!("{ports} ports for {n} ESCs: name one port per ESC"),
            ));
        }
    };
    if n > MAX_ESCS {
        return Err(usage("--port", format!("at most {MAX_ESCS} ESCs")));
    }
    Ok(n)
}

/// The run the options describe for `n` ESCs, refusing options that do not go together.
fn plan(args: &SimulateArgs, n: usize, settings: Settings) -> Result<Plan, CliError> {
    if (args.pty || !args.port.is_empty()) && args.format.is_some() {
        return Err(usage(
            "--format",
            "only for -o FILE or standard output: ptys and ports carry raw bytes",
        ));
    }
    let destination = if args.pty {
        #[cfg(unix)]
        {
            Destination::Ptys(match &args.link_dir {
                Some(dir) => PtyLinks::Dir(dir.clone()),
                None => PtyLinks::Paths(args.link.clone()),
            })
        }
        #[cfg(not(unix))]
        return Err(usage("--pty", "pseudo-terminals need a Unix system"));
    } else if !args.port.is_empty() {
        Destination::Ports(args.port.clone())
    } else {
        let format = match args.format {
            Some(f) => Some(f.serial().ok_or_else(|| {
                usage("--format", "candump is for a CAN bus (--protocol hw-can)")
            })?),
            None => None,
        };
        match args.output.as_deref() {
            None | Some("-") => Destination::Stdout(format.unwrap_or(FileFormat::Raw)),
            Some(path) => Destination::File {
                path: path.to_string(),
                format: format.unwrap_or_else(|| FileFormat::for_path(path)),
            },
        }
    };
    let plan = Plan {
        destination,
        realtime: args.realtime,
        start_s: args.start_time,
        duration_s: args.duration,
        truth: args.truth.clone(),
        settings,
        overwrite: args.overwrite,
    };
    if plan.is_realtime() && args.start_time.is_some() {
        return Err(usage(
            "--start-time",
            "real-time outputs use the time now; --start-time is for files written at once",
        ));
    }
    match &plan.destination {
        Destination::Stdout(FileFormat::Raw) if n > 1 => {
            return Err(usage(
                "--escs",
                "raw bytes on standard output can carry only one ESC: use --format pcapng, \
                 or -o FILE with {esc} in the name",
            ));
        }
        Destination::Stdout(_) if std::io::stdout().is_terminal() => {
            return Err(usage(
                "-o",
                "not writing binary telemetry to a terminal: give -o FILE or --pty, or pipe \
                 the output (e.g. into `hwfoc decode -`)",
            ));
        }
        Destination::File {
            path,
            format: FileFormat::Raw,
        } if n > 1 && !path.contains("{esc}") => {
            return Err(usage(
                "-o",
                format!(
                    "raw bytes of {n} ESCs cannot share one file: put {{esc}} in the name \
                     (e.g. esc{{esc}}.bin) or write a recording (--format pcapng)"
                ),
            ));
        }
        _ => {}
    }
    Ok(plan)
}

/// Refuses output files that would destroy a file read (`reads`: the profile, the
/// configuration) or each other's data: `--overwrite` is for earlier outputs, never for
/// inputs, and two outputs that are one file (the same name, or a link) would mix or lose
/// an ESC's bytes.
fn refuse_clashes(plan: &Plan, n: usize, reads: &[std::path::PathBuf]) -> Result<(), CliError> {
    let mut outputs: Vec<(&str, String)> = Vec::new();
    if let Destination::File { path, .. } = &plan.destination {
        if path.contains("{esc}") {
            outputs.extend((0..n).map(|esc| ("-o", expand(path, esc))));
        } else {
            outputs.push(("-o", path.clone()));
        }
    }
    if let Some(truth) = &plan.truth {
        outputs.push(("--truth", truth.clone()));
    }
    for (i, (option, out)) in outputs.iter().enumerate() {
        crate::safety::refuse_input(out, reads.iter().map(std::path::PathBuf::as_path))?;
        let earlier = outputs[..i]
            .iter()
            .find(|(_, o)| crate::safety::same_output(o, out));
        match earlier {
            // The ground truth must not land on (and destroy) one of the recordings.
            Some((_, first)) if *option == "--truth" => {
                return Err(usage(
                    "--truth",
                    format!("{out} is also the output -o {first}: choose another file for either"),
                ));
            }
            Some((_, first)) => {
                return Err(usage(
                    "-o",
                    format!(
                        "{first} and {out} are the same file: each ESC needs a file of its own"
                    ),
                ));
            }
            None => {}
        }
    }
    Ok(())
}

/// Prints `esc N: PATH` for each pseudo-terminal.
fn announce(paths: &[String]) -> Result<(), CliError> {
    let mut stdout = std::io::stdout().lock();
    for (i, path) in paths.iter().enumerate() {
        writeln!(stdout, "esc {i}: {path}")
            .and_then(|()| stdout.flush())
            .map_err(|source| WriteError::Write {
                output: "standard output".to_string(),
                source,
            })?;
    }
    Ok(())
}

/// The end-of-run line for one ESC.
fn report(esc: usize, r: &EscReport) -> String {
    let t = &r.tally;
    let id = if r.id.is_empty() {
        String::new()
    } else {
        format!(", id {}", r.id)
    };
    let mut line = format!(
        "esc {esc} ({}{id}): {} data frames, {} intact",
        r.output, t.data, t.intact
    );
    for (count, what) in [
        (t.dropped, "dropped"),
        (t.cut, "cut"),
        (t.corrupted, "corrupted"),
    ] {
        if count > 0 {
            line.push_str(&format!(", {count} {what}"));
        }
    }
    if t.info > 0 || !r.id.is_empty() {
        line.push_str(&format!("; {} device-information frames", t.info));
    }
    if t.garbage > 0 {
        line.push_str(&format!("; {} garbage bursts", t.garbage));
    }
    if t.glitches > 0 {
        line.push_str(&format!("; {} glitches", t.glitches));
    }
    if r.undelivered_bytes > 0 {
        line.push_str(&format!(
            "; {} bytes ({} intact data frames) not delivered: no reader",
            r.undelivered_bytes, t.undelivered
        ));
    }
    line
}
