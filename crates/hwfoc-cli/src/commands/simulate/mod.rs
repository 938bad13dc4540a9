//! `hwfoc simulate`: virtual HW-FOC ESCs that speak the protocol as real ones do.
//!
//! Each ESC runs a small physical model ([`model`]) driven by a throttle profile ([`profile`]),
//! sends its frames on the real schedule ([`esc`]) through a link that can misbehave
//! ([`faults`]), into pseudo-terminals, serial ports, files or standard output ([`sink`],
//! [`pty`]), paced in real time or as fast as possible ([`schedule`]). Every random choice comes
//! from `--seed` ([`rng`]): the same seed and options give the same bytes.
//!
//! The ground truth (`--truth FILE`) has one record per data frame delivered intact, `t_s` being
//! the time its first byte started on the wire, in the clock of the output:
//! - real-time outputs (pseudo-terminals, serial ports, `--realtime`): Unix time;
//! - a pcapng recording: the recording's own timestamps, which start at `--start-time` (Unix
//!   seconds; default now), so that decoding the recording gives exactly the truth's `t_s`;
//! - raw bytes (a file or standard output): raw bytes carry no time, so decoding them gives a
//!   null `t_s`; the truth still has the simulated time, seconds from the start of the run plus
//!   `--start-time` (default 0).

mod esc;
mod faults;
mod model;
mod profile;
#[cfg(unix)]
mod pty;
mod rng;
mod schedule;
pub mod sink;

use std::io::IsTerminal;
use std::rc::Rc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use clap::ValueEnum;

use self::esc::{Setup, VirtualEsc};
use self::faults::{FaultSchedule, FaultSpec, LinkRates};
use self::profile::{Profile, ProfileSpec, Shape};
use self::schedule::{Pace, SimClock, Tally};
use self::sink::{PcapngSink, PortSink, RawSink, Sink, Truth};
use crate::args::SettingsArgs;
use crate::error::CliError;
use hwfoc_io::clock::unix_now_ns;
use hwfoc_io::write::WriteError;

/// Extra seconds after one run of the profile, for file outputs without `--duration`: the
/// motor stops and the idle frames and device information show.
const TAIL_S: f64 = 2.0;
/// How long the ptys stay open after the last write.
const PTY_LINGER: std::time::Duration = std::time::Duration::from_millis(300);
/// Outlet duration of one piece written to a pseudo-terminal, seconds.
const PIECE_S: f64 = 0.004;

/// File formats of `-o`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FileFormat {
    /// The bytes as they were on the wire.
    Raw,
    /// A pcapng recording (one interface per ESC, nanosecond timestamps), as `hwfoc record`
    /// writes.
    Pcapng,
}

const EXAMPLES: &str = "\
Examples:
  hwfoc simulate --pty                                # one ESC on a pseudo-terminal, until Ctrl-C
  hwfoc simulate --escs 8 --pty --link-dir /tmp/escs  # /tmp/escs/esc0 .. esc7
  hwfoc simulate -o run.bin --truth truth.jsonl       # raw bytes, 18 s simulated, at once
  hwfoc simulate --escs 4 -o run.pcapng --profile sine --duration 60
  hwfoc simulate --drop-rate 0.02 --bit-error-rate 1e-4 --fault mos_overheat@5-7 | hwfoc decode -
  hwfoc simulate --port /dev/ttyUSB0 --profile csv:flight.csv";

/// Arguments of `hwfoc simulate`.
#[derive(Debug, clap::Args)]
#[command(after_help = EXAMPLES)]
pub struct SimulateArgs {
    /// Number of virtual ESCs (esc 0..N-1). With --port: one per port.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=256))]
    escs: Option<u16>,
    /// Seconds of simulated time. Default: one run of the profile plus 2 s for files and
    /// standard output; until Ctrl-C in real time.
    #[arg(long, value_name = "S", value_parser = positive)]
    duration: Option<f64>,
    /// Line rate in baud (8N1).
    #[arg(long, value_name = "BAUD", default_value_t = 19_200,
          value_parser = clap::value_parser!(u32).range(9_600..=4_000_000))]
    baud: u32,
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
    /// File format. Default: pcapng for a name ending in .pcapng, raw otherwise.
    #[arg(long, value_enum, help_heading = "Output")]
    format: Option<FileFormat>,
    /// Write the file or standard output at the real rate instead of as fast as possible.
    #[arg(long, help_heading = "Output")]
    realtime: bool,
    /// Write the ground truth: one JSON Lines record per data frame delivered intact.
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    truth: Option<String>,
    /// Unix time (seconds) of the start, for recordings and the truth of file outputs.
    /// Default: now for pcapng, 0 for raw bytes.
    #[arg(long, value_name = "UNIX_S", value_parser = non_negative, help_heading = "Output")]
    start_time: Option<f64>,
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
    /// by `settings`: checked (fault ESC numbers, the profile file) but not started.
    pub fn fleet(
        &self,
        n: usize,
        baud: u32,
        settings: &hwfoc::Settings,
    ) -> Result<VirtualFleet, CliError> {
        if let Some(bad) = self.faults.iter().find(|f| f.esc.is_some_and(|e| e >= n)) {
            return Err(usage(
                "--fault",
                format!(
                    "ESC {} does not exist: there are {n} (0..{})",
                    bad.esc.unwrap_or(0),
                    n - 1
                ),
            ));
        }
        let shape = Shape {
            lead_in_s: self.lead_in,
            levels: self.levels.clone(),
            hold_s: self.hold,
            period_s: self.period,
            max_pct: self.max_throttle,
        };
        Ok(VirtualFleet {
            n,
            seed: self.seed,
            baud,
            start_packet: self.start_packet,
            profile: Profile::load(&self.profile, &shape)?,
            config: model::ModelConfig {
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
        })
    }
}

/// Virtual ESCs described and checked, not yet started; it can be moved to another thread.
#[derive(Debug)]
pub struct VirtualFleet {
    n: usize,
    seed: u64,
    baud: u32,
    start_packet: Option<u16>,
    profile: Profile,
    config: model::ModelConfig,
    faults: Vec<FaultSpec>,
    link: LinkRates,
}

impl VirtualFleet {
    /// The ESCs, at rest at time zero.
    fn escs(self) -> Vec<VirtualEsc> {
        let profile = Rc::new(self.profile);
        (0..self.n)
            .map(|index| {
                VirtualEsc::new(Setup {
                    index,
                    seed: self.seed,
                    baud: self.baud,
                    start_packet: self.start_packet,
                    model: self.config,
                    profile: Rc::clone(&profile),
                    faults: FaultSchedule::for_esc(&self.faults, index),
                    link: self.link,
                })
            })
            .collect()
    }

    /// Runs the ESCs in real time from now until `stop` is set, each burst handed whole to
    /// `sink` when its first byte is due (Unix time in ns), as a UART's reader would get it.
    pub fn run_live(self, sink: &mut dyn Sink, stop: &AtomicBool) -> Result<(), CliError> {
        let clock = SimClock {
            origin_ns: unix_now_ns(),
            real: Some(Instant::now()),
        };
        schedule::run(self.escs(), sink, None, Pace::Whole, clock, None, stop).map(|_| ())
    }
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

/// Where the bytes go.
enum Outlet {
    Stdout,
    File(String),
    Pty,
    Ports,
}

fn usage(option: &str, message: impl Into<String>) -> CliError {
    CliError::Usage {
        option: option.to_string(),
        message: message.into(),
    }
}

/// Runs `hwfoc simulate`.
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    let settings = args.settings.settings()?;
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
    if n > 256 {
        return Err(usage("--port", "at most 256 ESCs"));
    }
    let target = if args.pty {
        Outlet::Pty
    } else if !args.port.is_empty() {
        Outlet::Ports
    } else {
        match args.output.as_deref() {
            None | Some("-") => Outlet::Stdout,
            Some(path) => Outlet::File(path.to_string()),
        }
    };
    let format = match (&target, args.format) {
        (Outlet::Pty | Outlet::Ports, Some(_)) => {
            return Err(usage(
                "--format",
                "only for -o FILE or standard output: ptys and ports carry raw bytes",
            ));
        }
        (_, Some(format)) => format,
        (Outlet::File(path), None) if path.ends_with(".pcapng") => FileFormat::Pcapng,
        _ => FileFormat::Raw,
    };
    let realtime = args.realtime || matches!(target, Outlet::Pty | Outlet::Ports);
    if realtime && args.start_time.is_some() {
        return Err(usage(
            "--start-time",
            "real-time outputs use the time now; --start-time is for files written at once",
        ));
    }
    match &target {
        Outlet::Stdout if format == FileFormat::Raw && n > 1 => {
            return Err(usage(
                "--escs",
                "raw bytes on standard output can carry only one ESC: use --format pcapng, \
                 or -o FILE with {esc} in the name",
            ));
        }
        Outlet::Stdout if std::io::stdout().is_terminal() => {
            return Err(usage(
                "-o",
                "not writing binary telemetry to a terminal: give -o FILE or --pty, or pipe \
                 the output (e.g. into `hwfoc decode -`)",
            ));
        }
        Outlet::File(path) if format == FileFormat::Raw && n > 1 && !path.contains("{esc}") => {
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

    let fleet = args.model.fleet(n, args.baud, &settings)?;
    let duration_s = match args.duration {
        Some(d) => Some(d),
        None if realtime => None,
        None => Some(fleet.profile.natural_length_s() + TAIL_S),
    };
    let escs = fleet.escs();

    // The truth file is opened before the outputs, so that a path that cannot be written is
    // reported before any pseudo-terminal is announced.
    let mut truth = match &args.truth {
        Some(path) => {
            let (name, out) = sink::create(path)?;
            Some(Truth::new(name, out, settings))
        }
        None => None,
    };
    let start_ns = args.start_time.map(|s| (s * 1e9).round() as u64);
    let origin_ns = match (realtime, format) {
        (true, _) => unix_now_ns(),
        (false, FileFormat::Pcapng) => start_ns.unwrap_or_else(unix_now_ns),
        (false, FileFormat::Raw) => start_ns.unwrap_or(0),
    };
    let pieces = Pace::Pieces((PIECE_S * f64::from(args.baud) / 10.0).round().max(1.0) as usize);

    #[cfg(unix)]
    let mut _links = pty::Links::default();
    let (mut out, pace, names): (Box<dyn Sink>, Pace, Vec<String>) = match &target {
        Outlet::Pty => {
            #[cfg(unix)]
            {
                let (sink, names) = open_ptys(args, n, &mut _links)?;
                (Box::new(sink), pieces, names)
            }
            #[cfg(not(unix))]
            return Err(usage("--pty", "pseudo-terminals need a Unix system"));
        }
        Outlet::Ports => (
            Box::new(PortSink::open(&args.port, args.baud)?),
            Pace::Whole,
            args.port.clone(),
        ),
        Outlet::Stdout | Outlet::File(_) => {
            let (paths, file_of): (Vec<String>, Vec<usize>) = match &target {
                Outlet::File(path) if path.contains("{esc}") => (
                    (0..n).map(|i| sink::expand(path, i)).collect(),
                    (0..n).collect(),
                ),
                Outlet::File(path) => (vec![path.clone()], vec![0; n]),
                _ => (vec!["-".to_string()], vec![0; n]),
            };
            let mut outs = Vec::with_capacity(paths.len());
            for path in &paths {
                outs.push(sink::create(path)?);
            }
            let names = file_of.iter().map(|&f| outs[f].0.clone()).collect();
            let sink: Box<dyn Sink> = match format {
                FileFormat::Raw => Box::new(RawSink::new(outs)),
                FileFormat::Pcapng => Box::new(PcapngSink::new(outs, &file_of, args.baud)?),
            };
            let pace = match (&target, realtime) {
                (_, false) => Pace::Fast,
                (Outlet::Stdout, true) => pieces,
                (_, true) => Pace::Whole,
            };
            (sink, pace, names)
        }
    };

    let infos: Vec<hwfoc::InfoFrame> = escs.iter().map(|e| *e.info()).collect();
    let stop: std::sync::Arc<AtomicBool> = hwfoc_io::stop::interrupted();
    let clock = SimClock {
        origin_ns,
        real: realtime.then(Instant::now),
    };
    let duration_ns = duration_s.map(|s| (s * 1e9).round() as u64);
    let tallies = schedule::run(
        escs,
        out.as_mut(),
        truth.as_mut(),
        pace,
        clock,
        duration_ns,
        &stop,
    )?;
    if matches!(target, Outlet::Pty) {
        // Closing a pty's master hangs up the reader and discards what it has not read yet:
        // give readers a moment to take the last frames, which the truth lists as delivered.
        std::thread::sleep(PTY_LINGER);
    }
    if !args.quiet {
        for (esc, tally) in tallies.iter().enumerate() {
            let id = infos[esc].id();
            eprintln!(
                "{}",
                report(esc, &names[esc], id, tally, out.undelivered(esc))
            );
        }
    }
    Ok(())
}

/// Creates a pty per ESC, prints their paths and makes the links asked for.
#[cfg(unix)]
fn open_ptys(
    args: &SimulateArgs,
    n: usize,
    links: &mut pty::Links,
) -> Result<(sink::PtySink, Vec<String>), CliError> {
    use std::io::Write;
    use std::path::PathBuf;

    let link_paths: Vec<PathBuf> = match (&args.link_dir, args.link.as_slice()) {
        (Some(dir), _) => {
            std::fs::create_dir_all(dir).map_err(|source| CliError::Link {
                path: dir.clone(),
                source,
            })?;
            (0..n)
                .map(|i| PathBuf::from(dir).join(format!("esc{i}")))
                .collect()
        }
        (None, []) => Vec::new(),
        (None, [one]) if n == 1 || one.contains("{esc}") => (0..n)
            .map(|i| PathBuf::from(sink::expand(one, i)))
            .collect(),
        (None, many) if many.len() == n => many.iter().map(PathBuf::from).collect(),
        (None, many) => {
            return Err(usage(
                "--link",
                format!(
                    "{} links for {n} ESCs: give one per ESC, or one with {{esc}} in it",
                    many.len()
                ),
            ));
        }
    };
    let mut ptys = Vec::with_capacity(n);
    for _ in 0..n {
        ptys.push(pty::Pty::open()?);
    }
    for (link, p) in link_paths.iter().zip(&ptys) {
        links.add(link, p.path())?;
    }
    let names: Vec<String> = ptys
        .iter()
        .map(|p| p.path().display().to_string())
        .collect();
    let mut stdout = std::io::stdout().lock();
    for (i, name) in names.iter().enumerate() {
        writeln!(stdout, "esc {i}: {name}")
            .and_then(|()| stdout.flush())
            .map_err(|source| WriteError::Write {
                output: "standard output".to_string(),
                source,
            })?;
    }
    Ok((sink::PtySink::new(ptys), names))
}

/// The end-of-run line for one ESC.
fn report(esc: usize, name: &str, id: &str, t: &Tally, undelivered_bytes: u64) -> String {
    let mut line = format!(
        "esc {esc} ({name}, id {id}): {} data frames, {} intact",
        t.data, t.intact
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
    line.push_str(&format!("; {} device-information frames", t.info));
    if t.garbage > 0 {
        line.push_str(&format!("; {} garbage bursts", t.garbage));
    }
    if t.glitches > 0 {
        line.push_str(&format!("; {} glitches", t.glitches));
    }
    if undelivered_bytes > 0 {
        line.push_str(&format!(
            "; {undelivered_bytes} bytes ({} intact data frames) not delivered: no reader",
            t.undelivered
        ));
    }
    line
}
