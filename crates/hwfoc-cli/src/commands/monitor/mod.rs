//! `hwfoc monitor`: live telemetry of one to sixteen ESCs (or more), as a full-screen dashboard
//! ([`dashboard`]) or as lines for a machine without a screen ([`headless`]).
//!
//! Bytes come from serial ports or from virtual ESCs running in this process ([`feed`]); the
//! state of every ESC, its alarms and the alarm log live in [`fleet`] (alarm logic in
//! [`alarms`]); settings come from flags over an optional TOML file ([`config`]). Everything
//! received can be recorded to pcapng as `hwfoc record` does, from the start (`--record`) or
//! with a key.

mod alarms;
mod config;
mod dashboard;
pub(crate) mod feed;
mod fleet;
mod headless;
mod perf;

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use self::config::{AlarmKeys, MonitorSetup, Overrides};
use self::feed::{Feed, Msg};
use self::fleet::Fleet;
use self::perf::Perf;
use super::record::{self, Recorder};
use crate::args::{ProtocolArgs, SettingsArgs};
use crate::commands::simulate::ModelArgs;
use crate::error::CliError;
use hwfoc_ports::serial::{Baud, PortEvent};

/// The most virtual ESCs `--sim` runs.
const MAX_SIM: u16 = 64;

const EXAMPLES: &str = "\
Examples:
  hwfoc monitor --sim 4                           # four virtual ESCs, nothing to plug in
  hwfoc monitor /dev/ttyUSB0 /dev/ttyUSB1         # two ESCs on USB-UART adapters
  hwfoc monitor --sim 4 --fault 1:mos_overheat@20-25
  hwfoc monitor /dev/ttyUSB0 --plain              # one line per second, alarms as they happen
  hwfoc monitor /dev/ttyUSB0 --json --record flight.pcapng

Keys: up/down (or j/k, 0-9) select an ESC, p pause, c reset peaks, r start/stop recording,
? help, q quit.";

/// Arguments of `hwfoc monitor`.
#[derive(Debug, clap::Args)]
#[command(after_help = EXAMPLES)]
pub struct MonitorArgs {
    /// Serial ports to watch, one ESC each, in this order. Default: the ports listed in the
    /// configuration file.
    #[arg(value_name = "PORT", conflicts_with = "sim")]
    ports: Vec<String>,
    /// Watch N virtual ESCs running in this process (see the Throttle, Model and Faults options).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=MAX_SIM as i64))]
    sim: Option<u16>,
    /// No dashboard: print one line per ESC per interval and every alarm as it happens.
    #[arg(long, conflicts_with = "json")]
    plain: bool,
    /// No dashboard: as --plain, in JSON Lines.
    #[arg(long)]
    json: bool,
    /// Seconds between the status lines of --plain and --json (0.05 to 86400: an ESC sends a
    /// frame every 50 ms).
    #[arg(long, value_name = "S", default_value_t = 1.0, value_parser = interval)]
    interval: f64,
    /// Stop after S seconds (otherwise on q, Ctrl-C or SIGTERM).
    #[arg(long, value_name = "S", value_parser = seconds)]
    duration: Option<f64>,
    /// Record everything received to FILE from the start (pcapng, as `hwfoc record` writes).
    #[arg(long, value_name = "FILE")]
    record: Option<String>,
    /// Let --record replace an existing file of that name (never done unasked).
    #[arg(long, requires = "record")]
    overwrite: bool,
    /// Where the r key puts its recordings (hwfoc-DATE-TIME.pcapng), made if need be (mode 0700)
    /// [default: from the configuration file, else hwfoc/recordings in the user's data
    /// directory: ~/.local/share/hwfoc/recordings].
    #[arg(long, value_name = "DIR")]
    record_dir: Option<PathBuf>,
    /// A name for each ESC, in order (repeat the option).
    #[arg(long = "label", value_name = "TEXT")]
    labels: Vec<String>,
    /// Baud rate of the ports (8N1) [default: that of --protocol, else from the configuration
    /// file, else found from the bytes: 19200 and 115200 tried in turn].
    #[arg(long, value_name = "N")]
    baud: Option<u32>,
    #[command(flatten)]
    protocol: ProtocolArgs,
    /// Conversion settings and the configuration file.
    #[command(flatten)]
    settings: SettingsArgs,
    /// Alarm levels.
    #[command(flatten)]
    alarms: AlarmKeys,
    /// On exit, print on standard error how the monitor performed: frames, redraws, the delay
    /// from bytes received to the screen, CPU time.
    #[arg(long)]
    stats: bool,
    /// The virtual ESCs of --sim.
    #[command(flatten)]
    model: ModelArgs,
}

fn seconds(text: &str) -> Result<f64, String> {
    crate::args::seconds(text)
}

/// Seconds between status lines: from [`MIN_INTERVAL_S`] to a day.
fn interval(text: &str) -> Result<f64, String> {
    let s = seconds(text)?;
    if !(MIN_INTERVAL_S..=86_400.0).contains(&s) {
        return Err(format!(
            "{text:?}: the interval must be from {MIN_INTERVAL_S} to 86400 seconds"
        ));
    }
    Ok(s)
}

/// The shortest interval between status lines: the period of an ESC's frames.
const MIN_INTERVAL_S: f64 = 0.05;

/// Runs `hwfoc monitor`.
pub fn run(args: &MonitorArgs) -> Result<(), CliError> {
    let config = MonitorSetup::load(&Overrides {
        settings: args.settings.clone(),
        baud: args.baud,
        protocol: args.protocol.protocol,
        record_dir: args.record_dir.clone(),
        alarms: args.alarms.clone(),
    })?;
    if args.sim.is_none() && !args.model.is_default() {
        return Err(CliError::Usage {
            option: "monitor".into(),
            message: "the Throttle, Model and Faults options drive virtual ESCs: add --sim N, or \
                      leave them out to watch ports"
                .into(),
        });
    }
    let mut session = Session::start(args, config)?;
    let headless = args.plain || args.json;
    if !headless && !std::io::IsTerminal::is_terminal(&std::io::stdout()) {
        return Err(CliError::Usage {
            option: "monitor".into(),
            message: "standard output is not a terminal: use --plain or --json for lines of text"
                .into(),
        });
    }
    let result = if headless {
        headless::run(&mut session, args.json, args.interval)
    } else {
        dashboard::run(&mut session)
    };
    let closed = session.close();
    if args.stats {
        eprintln!("hwfoc: {}", session.perf.report(session.fleet.frames));
    }
    result.and(closed)
}

/// A running monitor: its source, what it knows, its recording.
pub struct Session {
    /// Every ESC watched.
    pub fleet: Fleet,
    /// The recording being written, if any.
    pub recorder: Option<Recorder>,
    /// The last recording problem or success, for the status line.
    pub notice: Option<String>,
    /// How the monitor itself is doing.
    pub perf: Perf,
    /// Whether the source is virtual.
    pub simulated: bool,
    /// The configuration file read, if any.
    pub config_file: Option<PathBuf>,
    rx: Receiver<Msg>,
    tx: mpsc::Sender<Msg>,
    feed: Option<Feed>,
    clock: hwfoc_ports::clock::ReceiveClock,
    names: Vec<String>,
    baud: Baud,
    /// The ports' rates found from their bytes (and what the streams found to tell, such as two
    /// CAN ESCs on one throttle channel) since the headless monitor last printed them.
    pub found: Vec<hwfoc_io::Notice>,
    /// The one protocol read, when forced.
    protocol: Option<hwfoc::Protocol>,
    record_dir: PathBuf,
    /// Whether `--record` may replace an existing file.
    overwrite: bool,
    /// The recordings finished so far, to name on exit.
    recorded: Vec<String>,
    interrupted: Arc<AtomicBool>,
    stop_at: Option<Instant>,
}

impl Session {
    fn start(args: &MonitorArgs, config: MonitorSetup) -> Result<Session, CliError> {
        let interrupted = crate::stop::interrupted();
        let (tx, rx) = mpsc::channel();
        let ports: Vec<String> = if args.ports.is_empty() {
            config.ports.clone()
        } else {
            args.ports.clone()
        };
        let (names, feed) = match args.sim {
            Some(n) => {
                let feed = Feed::simulated(
                    &args.model,
                    usize::from(n),
                    config.baud.initial(),
                    config.settings.default_settings(),
                    tx.clone(),
                )?;
                let names = (0..n).map(|i| format!("sim:esc{i}")).collect();
                (names, feed)
            }
            None if ports.is_empty() => {
                return Err(CliError::Usage {
                    option: "monitor".into(),
                    message: format!(
                        "no ports to watch: name them (e.g. `hwfoc monitor /dev/ttyUSB0`), list \
                         them in {}, or try the virtual ESCs: `hwfoc monitor --sim 4`",
                        crate::config::default_path()
                            .map_or("the configuration file".into(), |p| p.display().to_string())
                    ),
                });
            }
            None => {
                let forced = crate::args::ProtocolArgs {
                    protocol: config.protocol,
                };
                forced.check_ports(ports.iter().map(String::as_str))?;
                let feed = Feed::ports(&ports, config.baud, tx.clone())?;
                (ports, feed)
            }
        };
        // A port's own label: its flag, else the file's for its name (a bus's ESCs and a
        // hub's channels are labelled by ESC number first).
        let port_labels: Vec<Option<String>> = names
            .iter()
            .enumerate()
            .map(|(i, name)| {
                args.labels
                    .get(i)
                    .cloned()
                    .or_else(|| config.port_label(name).map(str::to_string))
            })
            .collect();
        let labelled = names
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let label = args
                    .labels
                    .get(i)
                    .cloned()
                    .or_else(|| config.label(i, name).map(str::to_string));
                (name.clone(), label)
            })
            .collect();
        // The ports' own clock, so that ages and recordings agree with their timestamps.
        let clock = match &feed {
            Feed::Ports(readers) => readers.clock(),
            Feed::Simulated { .. } => hwfoc_ports::clock::ReceiveClock::new(),
        };
        let now = clock.now_ns() as f64 / 1e9;
        // Virtual ESCs send at the rate they are given: nothing to find.
        let baud = match args.sim {
            Some(_) => Baud::Fixed(config.baud.initial()),
            None => config.baud,
        };
        let mut fleet = Fleet::new(
            labelled,
            config.settings.clone(),
            config.limits.clone(),
            baud,
            now,
        );
        fleet.set_labels(
            config
                .esc_labels()
                .into_iter()
                .map(|(esc, label)| (esc, label.to_string()))
                .collect(),
            port_labels,
        );
        if let Some(protocol) = config.protocol {
            fleet.force_protocol(protocol);
        }
        let mut session = Session {
            fleet,
            recorder: None,
            notice: None,
            perf: Perf::new(),
            simulated: args.sim.is_some(),
            config_file: config.file.clone(),
            rx,
            tx,
            feed: Some(feed),
            clock,
            names,
            baud,
            found: Vec::new(),
            protocol: config.protocol,
            record_dir: config.record_dir,
            overwrite: args.overwrite,
            recorded: Vec::new(),
            interrupted,
            stop_at: args
                .duration
                .map(|s| Instant::now() + Duration::from_secs_f64(s)),
        };
        if let Some(path) = &args.record {
            session.start_recording(path.clone())?;
        }
        Ok(session)
    }

    /// Unix time now, seconds.
    pub fn now(&self) -> f64 {
        self.clock.now_ns() as f64 / 1e9
    }

    /// A sender for terminal events (the dashboard's keyboard thread).
    pub fn sender(&self) -> mpsc::Sender<Msg> {
        self.tx.clone()
    }

    /// Whether it is time to stop: Ctrl-C or SIGTERM, or the end of `--duration`.
    pub fn should_stop(&self) -> bool {
        self.interrupted.load(Ordering::Relaxed)
            || self.stop_at.is_some_and(|t| Instant::now() >= t)
    }

    /// Waits at most `timeout` for something to happen and takes in all that came; returns the
    /// terminal events among it. Stale ESCs are checked and the recording flushed.
    pub fn pump(
        &mut self,
        timeout: Duration,
    ) -> Result<Vec<ratatui::crossterm::event::Event>, CliError> {
        let timeout = match self.stop_at {
            Some(t) => timeout.min(t.saturating_duration_since(Instant::now())),
            None => timeout,
        };
        let mut terminal = Vec::new();
        let first = match self.rx.recv_timeout(timeout) {
            Ok(msg) => Some(msg),
            Err(RecvTimeoutError::Timeout) => None,
            Err(RecvTimeoutError::Disconnected) => None,
        };
        let mut next = first;
        while let Some(msg) = next {
            match msg {
                Msg::Port(event) => self.take(event),
                Msg::Term(event) => terminal.push(event),
                Msg::Failed(e) => return Err(e),
            }
            next = self.rx.try_recv().ok();
        }
        let now = self.now();
        self.fleet.tick(now);
        if let Some(recorder) = &mut self.recorder
            && let Err(e) = recorder.tick()
        {
            self.recording_failed(e);
        }
        Ok(terminal)
    }

    fn take(&mut self, event: PortEvent) {
        let received = self.received_at(&event);
        if let Some(notice @ hwfoc_io::Notice::PortBaud { .. }) =
            hwfoc_io::Notice::of_port_event(&event, &self.names)
        {
            self.found.push(notice);
        }
        if self.fleet.on_event(&event) > 0 {
            self.perf.arrived(received);
        }
        // Told once: printed by the headless monitor, shown on the dashboard's status line.
        self.found.append(&mut self.fleet.notices);
        if let Some(recorder) = &mut self.recorder
            && let Err(e) = recorder.handle(event)
        {
            self.recording_failed(e);
        }
    }

    /// When the bytes of `event` were handed over: the end of the read that returned them (its
    /// first byte's time plus the wire time of the rest), or for a virtual ESC the moment it
    /// sent them (a whole burst at once). Events may wait in the channel until the next redraw;
    /// the screen's delay is counted from here.
    fn received_at(&self, event: &PortEvent) -> Instant {
        let now = Instant::now();
        let PortEvent::Data { port, t_ns, bytes } = event else {
            return now;
        };
        let span = if self.simulated {
            0
        } else {
            let baud = self.fleet.port_baud(*port).unwrap_or(self.baud.initial());
            (bytes.len().saturating_sub(1) as f64 * hwfoc::wire::byte_ns(baud)) as u64
        };
        let ago = self.clock.now_ns().saturating_sub(t_ns + span);
        now.checked_sub(Duration::from_nanos(ago)).unwrap_or(now)
    }

    /// A recording that cannot go on is closed with what it has; the monitor goes on.
    fn recording_failed(&mut self, e: CliError) {
        if let Some(mut recorder) = self.recorder.take() {
            let _ = recorder.close();
        }
        self.notice = Some(format!("recording stopped: {e}"));
    }

    /// Starts recording to `path` (never the configuration file read, even with
    /// `--overwrite`).
    pub fn start_recording(&mut self, path: String) -> Result<(), CliError> {
        crate::safety::refuse_input(&path, self.config_file.as_deref())?;
        let plan = record::Plan {
            output: path.clone(),
            rotate_size: None,
            rotate_time: None,
            bauds: (0..self.names.len())
                .map(|port| self.fleet.port_baud(port))
                .collect(),
            protocol: self.protocol,
            warn: false,
            overwrite: self.overwrite,
        };
        self.recorder = Some(Recorder::new(plan, &self.names, self.clock)?);
        self.notice = None;
        Ok(())
    }

    /// Starts a recording in the recording directory, or stops the one running. Problems go
    /// to the status line.
    pub fn toggle_recording(&mut self) {
        if let Some(mut recorder) = self.recorder.take() {
            let file = recorder.current().to_string();
            self.notice = Some(match recorder.close() {
                Ok(()) => format!("recorded to {}", display_path(&file)),
                Err(e) => format!("recording stopped: {e}"),
            });
            self.recorded.push(file);
            return;
        }
        if let Err(e) = make_private_dir(&self.record_dir) {
            self.notice = Some(format!(
                "cannot record: cannot make {}: {e}",
                display_path(&self.record_dir.display().to_string())
            ));
            return;
        }
        let stamp = jiff::Zoned::now().strftime("%Y%m%d-%H%M%S").to_string();
        let Some(path) = free_name(&self.record_dir, &stamp) else {
            self.notice = Some("cannot record: no free file name".to_string());
            return;
        };
        let path = path.display().to_string();
        if let Err(e) = self.start_recording(path) {
            self.notice = Some(format!("cannot record: {e}"));
        }
    }

    /// Stops the source and closes the recording with everything received.
    fn close(&mut self) -> Result<(), CliError> {
        self.feed.take();
        while let Ok(msg) = self.rx.try_recv() {
            if let Msg::Port(event) = msg {
                self.take(event);
            }
        }
        let closed = match self.recorder.take() {
            Some(mut recorder) => {
                let file = recorder.current().to_string();
                let closed = recorder.close();
                self.recorded.push(file);
                closed
            }
            None => Ok(()),
        };
        for file in &self.recorded {
            eprintln!("hwfoc: recorded to {file}");
        }
        closed
    }
}

/// Makes `dir` and its missing parents, readable by the user alone (mode 0700 on Unix: a
/// recording may say where and when a vehicle flew); a directory already there is left as it is.
fn make_private_dir(dir: &std::path::Path) -> std::io::Result<()> {
    let mut builder = std::fs::DirBuilder::new();
    builder.recursive(true);
    #[cfg(unix)]
    std::os::unix::fs::DirBuilderExt::mode(&mut builder, 0o700);
    builder.create(dir)
}

/// `path` with the user's home directory written `~`, for a line that has little room.
pub fn display_path(path: &str) -> String {
    match dirs::home_dir().and_then(|h| h.to_str().map(str::to_string)) {
        Some(home) if home.len() > 1 && path.starts_with(&format!("{home}/")) => {
            format!("~{}", &path[home.len()..])
        }
        _ => path.to_string(),
    }
}

/// A name for a recording started at `stamp` in `dir` that no file has: `hwfoc-STAMP.pcapng`,
/// or for a second one within the same second `hwfoc-STAMP-2.pcapng`, and so on.
fn free_name(dir: &std::path::Path, stamp: &str) -> Option<PathBuf> {
    let name = |n: u32| match n {
        1 => format!("hwfoc-{stamp}.pcapng"),
        n => format!("hwfoc-{stamp}-{n}.pcapng"),
    };
    (1..1000)
        .map(|n| dir.join(name(n)))
        .find(|p| std::fs::symlink_metadata(p).is_err())
}

/// Unix time `t` (seconds) as ISO 8601 local time with its UTC offset:
/// `2026-11-22T14:03:22+01:00`, or with milliseconds `2026-11-22T14:03:22.150+01:00`.
///
/// The one place the monitor writes a date and time (with `jiff`); when `hwfoc_io` formats
/// times itself, this calls it.
pub fn iso8601(t: f64, millis: bool) -> String {
    let pattern = if millis {
        "%Y-%m-%dT%H:%M:%S%.3f%:z"
    } else {
        "%Y-%m-%dT%H:%M:%S%:z"
    };
    local_time(t, pattern)
}

/// Unix time `t` (seconds) as local time, formatted with the strftime `pattern`.
pub fn local_time(t: f64, pattern: &str) -> String {
    match jiff::Timestamp::from_nanosecond((t * 1e9) as i128) {
        Ok(ts) => ts
            .to_zoned(jiff::tz::TimeZone::system())
            .strftime(pattern)
            .to_string(),
        Err(_) => format!("{t:.3}"),
    }
}

/// `v` with `decimals` decimals, without the sign of a value that rounds to zero (`-0.0`).
pub fn number(v: f32, decimals: usize) -> String {
    hwfoc_io::Fixed(f64::from(v), decimals).to_string()
}

/// A record's value as [`number`] writes it, or `-` where the record has none (a quantity
/// the ESC's protocol does not carry).
pub fn reading(v: Option<f32>, decimals: usize) -> String {
    v.map_or_else(|| "-".to_string(), |v| number(v, decimals))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_recording_directory_is_made_private_on_demand() {
        let dir = tempfile::tempdir().unwrap();
        let deep = dir.path().join("share/hwfoc/recordings");
        make_private_dir(&deep).unwrap();
        assert!(deep.is_dir());
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(&deep).unwrap().permissions().mode();
            assert_eq!(mode & 0o777, 0o700, "{mode:o}");
        }
        // Again: nothing changes, nothing fails.
        std::fs::write(deep.join("kept.pcapng"), "a recording").unwrap();
        make_private_dir(&deep).unwrap();
        assert!(deep.join("kept.pcapng").is_file());
        // A file in the way is an error, not replaced.
        let file = dir.path().join("file");
        std::fs::write(&file, "x").unwrap();
        assert!(make_private_dir(&file).is_err());
        assert_eq!(std::fs::read(&file).unwrap(), b"x");
    }

    #[test]
    fn paths_under_home_are_shown_short() {
        let Some(home) = dirs::home_dir() else { return };
        let home = home.display().to_string();
        if home.len() <= 1 {
            return;
        }
        assert_eq!(display_path(&format!("{home}/a/b.pcapng")), "~/a/b.pcapng");
        assert_eq!(display_path("/elsewhere/b.pcapng"), "/elsewhere/b.pcapng");
        assert_eq!(display_path(&format!("{home}x/b")), format!("{home}x/b"));
    }

    #[test]
    fn recordings_started_within_a_second_get_their_own_names() {
        let dir = tempfile::tempdir().unwrap();
        let first = free_name(dir.path(), "20261123-140322").unwrap();
        assert_eq!(first, dir.path().join("hwfoc-20261123-140322.pcapng"));
        std::fs::write(&first, "a recording").unwrap();
        let second = free_name(dir.path(), "20261123-140322").unwrap();
        assert_eq!(second, dir.path().join("hwfoc-20261123-140322-2.pcapng"));
        std::fs::write(&second, "another").unwrap();
        let third = free_name(dir.path(), "20261123-140322").unwrap();
        assert_eq!(third, dir.path().join("hwfoc-20261123-140322-3.pcapng"));
    }
}
