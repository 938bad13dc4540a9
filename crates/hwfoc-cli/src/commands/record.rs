//! `hwfoc record PORT... -o FILE`: lossless, timestamped capture of serial ports to pcapng.
//!
//! Every byte received is stored, cut at frame boundaries: one packet per frame, timestamped with
//! the Unix time of its first byte in nanoseconds, and the bytes between frames in packets of
//! their own; one pcapng interface per port, in the order given (see [`hwfoc_io::pcapng`]). The
//! bytes of a frame still arriving are held until it completes, or until the port has been
//! silent for [`SETTLE_AFTER`], and are written at the end of every file. The recording is
//! meant to survive the worst:
//! - crash safety: blocks go from a small buffer to the file at least every [`FLUSH_EVERY`],
//!   so after `kill -9` (or a crash) the file reads up to its last complete block and at most
//!   that much data is lost; the file is also synced to the disk every [`SYNC_EVERY`];
//! - a port that disappears (USB unplugged) is noted in the recording as a gap, with a comment,
//!   and recording goes on: the port is tried again every 0.5 s and resumes when it is back;
//! - Ctrl-C or SIGTERM (or `--duration`) ends the recording cleanly;
//! - with `--rotate-size` or `--rotate-time` the recording is a series of numbered files
//!   (`out-0001.pcapng`, `out-0002.pcapng`, …), each complete on its own.
//!
//! Frames are decoded on the fly, only to count them and to warn when a port sends bytes but
//! no valid frame (a wrong baud rate or swapped wires) or nothing at all.
//!
//! Without `--baud` (or `--protocol`, which gives its rate) each port finds its rate from the
//! bytes ([`hwfoc_ports::serial::Baud::Auto`]), and the recording says the rate each port was
//! read at: the file's interfaces are declared, each with its port's rate, once every port has
//! found it. Until then, what the ports found bytes give is held in memory (a port's bytes
//! reach the recorder only once its rate is found: bytes read at a rate that gave no frame
//! are not the wire's bytes and are not recorded, and are counted in the warnings). A port's
//! rate never changes after that, so one interface per port is the whole truth; a port still
//! searching when the recording ends is declared at 19200 with a comment saying that its rate
//! was not found and nothing of it recorded.
//!
//! A CAN bus (`slcan:PORT[:BITRATE]`, `can:IFACE`) has no baud rate to find: it is a
//! `LINKTYPE_CAN_SOCKETCAN` interface from the start, one packet per CAN frame (never an empty
//! one), and the report counts its CAN frames and the DroneCAN nodes heard.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use hwfoc::Protocol;
use hwfoc::dronecan::{CanFrame, Header, SOCKETCAN_RECORD_LEN};
use hwfoc_io::LinkStats;

use crate::args::ProtocolArgs;
use crate::error::CliError;
use hwfoc_io::Escaped;
use hwfoc_io::Notice;
use hwfoc_io::PortStreams;
use hwfoc_io::pcapng;
use hwfoc_io::write::WriteError;
use hwfoc_ports::serial::{Baud, DEFAULT_BAUD, PortEvent, PortSet, SEARCH_BYTES_FOR, SEARCH_RATES};

/// Longest time a received byte stays in this process before it is written to the file.
pub const FLUSH_EVERY: Duration = Duration::from_millis(50);
/// How long a port must be silent before the bytes of a frame that has not completed are written
/// as they are (a frame's bytes come back to back: 77 bytes take 40 ms at 19200 baud).
pub const SETTLE_AFTER: Duration = Duration::from_millis(200);
/// How often the file is synced to the disk (against power loss; a process crash loses only
/// what is not yet written).
pub const SYNC_EVERY: Duration = Duration::from_secs(1);
/// How long bytes may arrive without a valid frame before the warning.
pub const NO_FRAMES_AFTER: Duration = Duration::from_secs(3);
/// How long a port may stay silent before the warning.
pub const SILENT_AFTER: Duration = Duration::from_secs(5);
/// The size of the buffer in front of the file: far more than 50 ms of any number of ports.
const BUFFER: usize = 1 << 16;
/// How many names of a rotated series taken by other files are skipped at one rotation before
/// the recording stops (something is making them as fast as they are tried).
const MAX_TAKEN: usize = 1000;

/// Arguments of `hwfoc record`.
#[derive(Debug, clap::Args)]
pub struct RecordArgs {
    /// Serial ports to record (`/dev/ttyUSB0`, `/dev/serial/by-id/…`, `COM3`): one pcapng
    /// interface each, in the order given.
    #[arg(value_name = "PORT", required = true, num_args = 1..)]
    pub ports: Vec<String>,
    /// The recording to write (pcapng; Wireshark and tshark open it). With rotation, files are
    /// numbered: FILE `out.pcapng` gives `out-0001.pcapng`, `out-0002.pcapng`, …
    #[arg(short, long, value_name = "FILE")]
    pub output: String,
    /// Baud rate of the ports (8N1) [default: that of --protocol, else found from the bytes:
    /// 19200 and 115200 tried in turn].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub baud: Option<u32>,
    /// The protocol whose frames are counted (every byte is recorded whatever it is).
    #[command(flatten)]
    pub protocol: ProtocolArgs,
    /// Start a new file before one would grow past BYTES (suffixes k, M, G, or KiB, MiB, GiB).
    #[arg(long, value_name = "BYTES", value_parser = parse_size, conflicts_with = "rotate_time")]
    pub rotate_size: Option<u64>,
    /// Start a new file every SECONDS (at least 1).
    #[arg(long, value_name = "SECONDS", value_parser = parse_rotate_time)]
    pub rotate_time: Option<f64>,
    /// Stop after S seconds (otherwise on Ctrl-C or SIGTERM).
    #[arg(long, value_name = "S", value_parser = parse_seconds)]
    pub duration: Option<f64>,
    /// Replace an existing recording of that name (with rotation: remove every file of the
    /// earlier series first). Without it, an existing recording is never touched.
    #[arg(long)]
    pub overwrite: bool,
}

/// A size in bytes: `1000000`, `500k`, `100M`, `2G` (powers of 1000) or `64KiB`, `1MiB`, `1GiB`.
fn parse_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let split = t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let unit_bytes: u64 = match unit.trim() {
        "" | "B" => 1,
        "k" | "K" | "kB" | "KB" => 1000,
        "M" | "MB" => 1_000_000,
        "G" | "GB" => 1_000_000_000,
        "KiB" => 1 << 10,
        "MiB" => 1 << 20,
        "GiB" => 1 << 30,
        other => {
            return Err(format!(
                "unknown unit {other:?} (use k, M, G, KiB, MiB or GiB)"
            ));
        }
    };
    let n: u64 = number
        .parse()
        .map_err(|_| format!("{text:?} is not a size in bytes"))?;
    n.checked_mul(unit_bytes)
        .filter(|&b| b >= 1000)
        .ok_or_else(|| format!("{text:?}: the size must be at least 1k (1000 bytes)"))
}

/// A positive number of seconds (see [`crate::args::seconds`]).
fn parse_seconds(text: &str) -> Result<f64, String> {
    crate::args::seconds(text)
}

/// The shortest `--rotate-time`, s: a file a second at most.
pub const MIN_ROTATE_S: f64 = 1.0;

/// `--rotate-time`: seconds, at least [`MIN_ROTATE_S`].
fn parse_rotate_time(text: &str) -> Result<f64, String> {
    let s = crate::args::seconds(text)?;
    if s < MIN_ROTATE_S {
        return Err(format!(
            "{text:?}: --rotate-time is at least {MIN_ROTATE_S} second (a new file a second at most)"
        ));
    }
    Ok(s)
}

/// The name of file number `n` of a rotated recording: `out.pcapng` → `out-0001.pcapng`.
pub fn numbered(path: &str, n: u32) -> String {
    let p = Path::new(path);
    let stem = p
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let name = match p.extension() {
        Some(ext) => format!("{stem}-{n:04}.{}", ext.to_string_lossy()),
        None => format!("{stem}-{n:04}"),
    };
    match p.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.join(name).to_string_lossy().into_owned(),
        _ => name,
    }
}

/// What is known about one port during the recording.
struct PortState {
    name: String,
    /// When the first byte not yet followed by a valid frame arrived, and how many bytes since.
    unframed_since: Option<Instant>,
    unframed_bytes: u64,
    warned_unframed: bool,
    /// When the port was opened (or came back) with no byte since; `None` once bytes came.
    silent_since: Option<Instant>,
    /// Unix time (ns) at which the port was lost, while it is.
    lost_at: Option<u64>,
    /// A CAN bus's bit rate where named (`None` for a serial port, `Some(None)` for a SocketCAN
    /// interface): a bus has no baud rate to find.
    can: Option<Option<u32>>,
    /// A CAN bus's frames recorded.
    can_frames: u64,
    /// The DroneCAN source nodes heard on a CAN bus (bit `n` for node `n`).
    can_nodes: u128,
}

/// Whether port `name` is a CAN bus, and its bit rate where its name gives it.
fn can_bus(name: &str) -> Option<Option<u32>> {
    if !hwfoc_ports::can::is_can_spec(name) {
        return None;
    }
    match hwfoc_ports::can::CanSpec::parse(name) {
        Ok(hwfoc_ports::can::CanSpec::Slcan { bitrate, .. }) => Some(Some(bitrate)),
        _ => Some(None),
    }
}

/// Frames of either kind a port's stream has decoded.
fn frames(stats: LinkStats) -> u64 {
    u64::from(stats.frames()) + u64::from(stats.info_frames())
}

/// Where and how a recording is written.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The file (with rotation, the base of the numbered names).
    pub output: String,
    /// Rotate before a file would grow past this many bytes.
    pub rotate_size: Option<u64>,
    /// Rotate after this long.
    pub rotate_time: Option<Duration>,
    /// Each port's baud rate (in its interface's description): given or found already, or
    /// `None` while it is being found (the file's interfaces then wait for it).
    pub bauds: Vec<Option<u32>>,
    /// The one protocol whose frames are counted, when forced (every protocol otherwise).
    pub protocol: Option<Protocol>,
    /// Print gaps and link warnings on standard error (not under a full-screen display).
    pub warn: bool,
    /// Replace an existing recording (and, with rotation, the earlier series' files).
    pub overwrite: bool,
}

/// A recording being written: the file, its rotation, and what is known of each port.
pub struct Recorder {
    warn: bool,
    base: String,
    rotate_size: Option<u64>,
    rotate_time: Option<Duration>,
    /// Each port's rate, once known.
    bauds: Vec<Option<u32>>,
    /// Each port's format, in its interface's description: the one forced, or the one its rate
    /// was found by (`None` for a rate given with `--baud`: no frame waited for).
    formats: Vec<Option<Protocol>>,
    /// The file, created, before its headers are written: while a port's rate is not known.
    pending: Option<File>,
    /// What the ports reported while the file waits for its headers.
    held: Vec<PortEvent>,
    /// The protocol forced, if one is: the one the warnings name.
    protocol: Option<Protocol>,
    /// Files written, the current one last.
    files: Vec<String>,
    /// The number of the next file of a rotated recording.
    next_number: u32,
    /// The recording's identity, in every file of it (rotated files alike).
    recording: pcapng::RecordingId,
    /// The file being written; `None` after a rotation until there is something to write, so
    /// that a recording never ends with a file holding nothing.
    writer: Option<pcapng::Writer<BufWriter<File>>>,
    /// Whether the current file holds any packet yet.
    file_has_packets: bool,
    file_started: Instant,
    last_flush: Instant,
    last_sync: Instant,
    /// The clock of the ports' timestamps.
    clock: hwfoc_ports::clock::ReceiveClock,
    ports: Vec<PortState>,
    /// The ports' decoding streams (frames are counted, not kept).
    streams: PortStreams,
}

/// Runs `hwfoc record`.
pub fn run(args: &RecordArgs) -> Result<(), CliError> {
    // Install the Ctrl-C / SIGTERM handler first, so that no signal is lost once ports are open.
    let interrupted = crate::stop::interrupted();
    // A port is an input: a recording is never written over one (a device node replaced by a
    // file, or a file named as a port), whatever --overwrite says.
    crate::safety::refuse_input(&args.output, args.ports.iter().map(Path::new))?;
    let baud = args.protocol.baud(args.baud);
    let set = PortSet::open(&args.ports, baud)?;
    let started = Instant::now();
    let plan = Plan {
        output: args.output.clone(),
        rotate_size: args.rotate_size,
        rotate_time: args.rotate_time.map(Duration::from_secs_f64),
        bauds: vec![baud.fixed(); args.ports.len()],
        protocol: args.protocol.protocol,
        warn: true,
        overwrite: args.overwrite,
    };
    let mut recorder = Recorder::new(plan, set.names(), set.clock())?;
    let rate = match baud {
        // A CAN bus has no baud rate: its bit rate is in the report.
        _ if args.ports.iter().all(|p| can_bus(p).is_some()) => "(CAN)".to_string(),
        Baud::Fixed(baud) => format!("at {baud} baud"),
        Baud::Auto => format!("(baud rate found from the bytes: {} in turn)", rates_text()),
    };
    eprintln!(
        "hwfoc: recording {} {rate} to {}; Ctrl-C stops",
        Escaped(set.names().join(", ")),
        recorder.current()
    );
    let stop_at = args.duration.map(|s| started + Duration::from_secs_f64(s));
    let result = (|| {
        loop {
            let now = Instant::now();
            if interrupted.load(Ordering::Relaxed) || stop_at.is_some_and(|t| now >= t) {
                return Ok(());
            }
            let mut wait = FLUSH_EVERY.saturating_sub(recorder.last_flush.elapsed());
            if let Some(t) = stop_at {
                wait = wait.min(t.saturating_duration_since(now));
            }
            if let Some(event) = set.next_event(wait) {
                recorder.handle(event)?;
                while let Some(event) = set.try_event() {
                    recorder.handle(event)?;
                }
            }
            recorder.tick()?;
        }
    })();
    // Stop the readers and keep what they received up to the end, even after an error.
    let last = set.close();
    let result = result.and_then(|()| {
        for event in last {
            recorder.handle(event)?;
        }
        recorder.close()
    });
    eprintln!("hwfoc: {}", Escaped(recorder.status(started.elapsed())));
    result
}

impl Recorder {
    /// Creates the (first) file, with one interface per port, timestamps from `clock`.
    pub fn new(
        plan: Plan,
        ports: &[String],
        clock: hwfoc_ports::clock::ReceiveClock,
    ) -> Result<Recorder, CliError> {
        let rotating = plan.rotate_size.is_some() || plan.rotate_time.is_some();
        let first = if rotating {
            numbered(&plan.output, 1)
        } else {
            plan.output.clone()
        };
        if rotating {
            // Never a series mixing two runs: the files of an earlier one are refused, or with
            // --overwrite removed, before the first file is written.
            let earlier = series(&plan.output);
            match earlier.first() {
                Some(file) if !plan.overwrite => {
                    return Err(WriteError::Exists {
                        output: file.clone(),
                    }
                    .into());
                }
                _ => {
                    for file in &earlier {
                        std::fs::remove_file(file).map_err(|source| WriteError::Write {
                            output: file.clone(),
                            source,
                        })?;
                    }
                }
            }
        }
        let file = hwfoc_io::write::create_file(&first, plan.overwrite)?;
        let now = Instant::now();
        // Frames are only counted: the conversion settings do not matter.
        let initial = plan.bauds.iter().flatten().next().copied();
        let mut streams = PortStreams::new(
            ports.len(),
            initial.unwrap_or(DEFAULT_BAUD),
            hwfoc::Settings::DEFAULT,
        );
        for (port, baud) in plan.bauds.iter().enumerate() {
            if let Some(baud) = baud {
                streams.set_baud(port, *baud);
            }
        }
        if let Some(protocol) = plan.protocol {
            streams.force_protocol(protocol);
        }
        let mut recorder = Recorder {
            warn: plan.warn,
            base: plan.output,
            rotate_size: plan.rotate_size,
            rotate_time: plan.rotate_time,
            formats: vec![plan.protocol; plan.bauds.len()],
            bauds: plan.bauds,
            pending: Some(file),
            held: Vec::new(),
            protocol: plan.protocol,
            files: vec![first],
            next_number: 2,
            recording: pcapng::RecordingId::new(),
            writer: None,
            file_has_packets: false,
            file_started: now,
            last_flush: now,
            last_sync: now,
            clock,
            streams,
            ports: ports
                .iter()
                .map(|name| PortState {
                    name: name.clone(),
                    unframed_since: None,
                    unframed_bytes: 0,
                    warned_unframed: false,
                    silent_since: Some(now),
                    lost_at: None,
                    can: can_bus(name),
                    can_frames: 0,
                    can_nodes: 0,
                })
                .collect(),
        };
        if recorder.rates_known() {
            recorder.begin()?;
        }
        Ok(recorder)
    }

    /// Whether every serial port's baud rate is known (a CAN bus has none to find).
    fn rates_known(&self) -> bool {
        self.ports
            .iter()
            .zip(&self.bauds)
            .all(|(port, baud)| port.can.is_some() || baud.is_some())
    }

    /// Writes the file's headers, an interface per port at its rate (a serial port whose rate
    /// was not found at 19200, with a comment saying so), then what was held for them.
    fn begin(&mut self) -> Result<(), CliError> {
        let Some(file) = self.pending.take() else {
            return Ok(());
        };
        let names: Vec<String> = self.ports.iter().map(|p| p.name.clone()).collect();
        let interfaces = (&names[..], &self.bauds[..], &self.formats[..]);
        let mut writer = headers(self.current(), file, interfaces, self.recording)?;
        let now_ns = self.clock.now_ns();
        for (port, baud) in self.bauds.iter().enumerate() {
            if baud.is_none() && self.ports[port].can.is_none() {
                let text = format!(
                    "{}: no baud rate found ({} tried in turn): nothing of it was recorded",
                    names[port],
                    rates_text()
                );
                writer
                    .comment(port as u32, now_ns, &text)
                    .map_err(|e| self.write_error(e))?;
                self.file_has_packets = true;
            }
        }
        self.writer = Some(writer);
        self.file_started = Instant::now();
        for event in std::mem::take(&mut self.held) {
            self.write_event(event)?;
        }
        Ok(())
    }

    /// The file being written.
    pub fn current(&self) -> &str {
        self.files.last().map_or("", String::as_str)
    }

    fn write_error(&self, source: std::io::Error) -> CliError {
        WriteError::Write {
            output: self.current().to_string(),
            source,
        }
        .into()
    }

    /// Writes what a port reported: bytes as a packet, a loss or return as a note (a rate
    /// found is its interface's). While a port's rate is being found, it is held (see the module's documentation).
    pub fn handle(&mut self, event: PortEvent) -> Result<(), CliError> {
        match &event {
            PortEvent::Data { port, .. } => self.decode(*port, &event),
            PortEvent::Searching {
                port, discarded, ..
            } => {
                self.streams.feed(&event, &mut ());
                let state = &mut self.ports[*port];
                if *discarded > 0 {
                    // The rate left was read for at least SEARCH_BYTES_FOR since its first
                    // byte: that is when the bytes without a frame began.
                    let now = Instant::now();
                    let began = now.checked_sub(SEARCH_BYTES_FOR).unwrap_or(now);
                    state.silent_since = None;
                    state.unframed_since.get_or_insert(began);
                    state.unframed_bytes += discarded;
                }
                // No bytes to record, nothing the file must say.
                return Ok(());
            }
            PortEvent::Found {
                port,
                baud,
                protocol,
                ..
            } => {
                self.streams.feed(&event, &mut ());
                self.bauds[*port] = Some(*baud);
                self.formats[*port] = Some(*protocol);
                if self.warn {
                    let found = Notice::PortBaud {
                        port: self.ports[*port].name.clone(),
                        baud: *baud,
                        protocol: *protocol,
                    };
                    eprintln!("{}", found.line());
                }
            }
            PortEvent::Lost { .. } | PortEvent::Back { .. } => {}
        }
        if self.pending.is_some() {
            if !self.rates_known() {
                self.held.push(event);
                return Ok(());
            }
            self.begin()?;
        }
        self.write_event(event)
    }

    /// Writes what a port reported, the file's headers written.
    fn write_event(&mut self, event: PortEvent) -> Result<(), CliError> {
        match event {
            PortEvent::Searching { .. } => {}
            // The interface's rate says it (a note at the lock would come after the bytes it
            // precedes in time).
            PortEvent::Found { .. } => {}
            PortEvent::Data { port, t_ns, bytes } => {
                if let (Some(limit), Some(writer)) = (self.rotate_size, &self.writer) {
                    // What the file would be were it closed after these bytes (held bytes
                    // included): so every file, closed at any moment, stays under the limit.
                    let cost = writer.cost(port as u32, &bytes);
                    let cost = cost.map_err(|e| self.write_error(e))?;
                    if self.file_has_packets && writer.bytes_written() + cost > limit {
                        self.rotate()?;
                    }
                }
                let written = self.writer()?.write(port as u32, t_ns, &bytes);
                written.map_err(|e| self.write_error(e))?;
                self.file_has_packets = true;
            }
            PortEvent::Lost { port, t_ns, reason } => {
                let state = &mut self.ports[port];
                state.lost_at = Some(t_ns);
                state.silent_since = None;
                state.unframed_since = None;
                let lost = Notice::PortLost {
                    port: state.name.clone(),
                    reason,
                };
                let note = format!("gap: {lost}");
                if self.warn {
                    eprintln!("hwfoc: warning: {}; the recording goes on", Escaped(&note));
                }
                self.note(port, t_ns, &note)?;
            }
            PortEvent::Back { port, t_ns } => {
                let state = &mut self.ports[port];
                let gap = state
                    .lost_at
                    .take()
                    .map_or(0.0, |lost| t_ns.saturating_sub(lost) as f64 * 1e-9);
                state.silent_since = Some(Instant::now());
                let note = format!("resumed: {} is back after a gap of {gap:.1} s", state.name);
                if self.warn {
                    eprintln!("hwfoc: {}", Escaped(&note));
                }
                self.note(port, t_ns, &note)?;
            }
        }
        Ok(())
    }

    fn note(&mut self, port: usize, t_ns: u64, text: &str) -> Result<(), CliError> {
        let written = self.writer()?.comment(port as u32, t_ns, text);
        written.map_err(|e| self.write_error(e))?;
        self.file_has_packets = true;
        // A note is rare and worth having on disk at once.
        self.flush()
    }

    /// Decodes a chunk to count frames and to notice a port that sends no valid frame.
    fn decode(&mut self, port: usize, event: &PortEvent) {
        let state = &mut self.ports[port];
        if state.can.is_some() {
            // A CAN bus's frame records: counted, never given to the serial formats' detection.
            state.silent_since = None;
            if let PortEvent::Data { bytes, .. } = event {
                let (records, _) = bytes.as_chunks::<SOCKETCAN_RECORD_LEN>();
                for record in records {
                    state.can_frames += 1;
                    let frame = CanFrame::from_socketcan_record(record);
                    if let Some(header) = frame
                        .filter(CanFrame::is_dronecan_shaped)
                        .and_then(|f| Header::parse(f.id()).ok())
                    {
                        state.can_nodes |= 1 << (header.source_node & 0x7F);
                    }
                }
            }
            return;
        }
        let before = self.streams.stats(port).map_or(0, frames);
        let after = self.streams.feed(event, &mut ()).map_or(0, frames);
        let bytes = match event {
            PortEvent::Data { bytes, .. } => bytes.len(),
            _ => 0,
        };
        let state = &mut self.ports[port];
        state.silent_since = None;
        if after > before {
            state.unframed_since = None;
            state.unframed_bytes = 0;
            state.warned_unframed = false;
        } else {
            state.unframed_since.get_or_insert_with(Instant::now);
            state.unframed_bytes += bytes as u64;
        }
    }

    /// Periodic work: flushing, syncing, rotating by time, warnings. Call it at least every
    /// [`FLUSH_EVERY`].
    pub fn tick(&mut self) -> Result<(), CliError> {
        if self.last_flush.elapsed() >= FLUSH_EVERY {
            self.flush()?;
        }
        if self.last_sync.elapsed() >= SYNC_EVERY {
            self.last_sync = Instant::now();
            if let Some(writer) = &self.writer {
                let synced = writer.get_ref().get_ref().sync_data();
                synced.map_err(|e| self.write_error(e))?;
            }
        }
        if self.writer.is_some()
            && self
                .rotate_time
                .is_some_and(|every| self.file_started.elapsed() >= every)
        {
            self.rotate()?;
        }
        if !self.warn {
            return Ok(());
        }
        let protocol = self.protocol;
        for (port, state) in self.ports.iter_mut().enumerate() {
            let baud = self.bauds[port];
            if !state.warned_unframed
                && state
                    .unframed_since
                    .is_some_and(|t| t.elapsed() >= NO_FRAMES_AFTER)
                && state.unframed_bytes >= 64
            {
                state.warned_unframed = true;
                eprintln!(
                    "hwfoc: warning: {}",
                    no_frame_warning(&state.name, state.unframed_bytes, baud, protocol)
                );
            }
            if state
                .silent_since
                .is_some_and(|t| t.elapsed() >= SILENT_AFTER)
            {
                state.silent_since = None;
                eprintln!("hwfoc: warning: {}", silent_warning(state));
            }
        }
        Ok(())
    }

    /// Writes the bytes held for ports silent for [`SETTLE_AFTER`] and flushes the file; the
    /// bytes of frames still arriving stay held, so that no frame is cut in two by a flush.
    fn flush(&mut self) -> Result<(), CliError> {
        self.last_flush = Instant::now();
        let now_ns = self.clock.now_ns();
        match &mut self.writer {
            Some(writer) => {
                let flushed = writer
                    .settle(now_ns, SETTLE_AFTER.as_nanos() as u64)
                    .and_then(|()| writer.flush_written());
                flushed.map_err(|e| self.write_error(e))
            }
            None => Ok(()),
        }
    }

    /// The file to write to, starting the next file of a rotated recording if need be.
    fn writer(&mut self) -> Result<&mut pcapng::Writer<BufWriter<File>>, CliError> {
        let writer = match self.writer.take() {
            Some(writer) => writer,
            None => self.next_file()?,
        };
        Ok(self.writer.insert(writer))
    }

    /// Creates the next file of a rotated recording, with the headers again and a note for
    /// each port that is lost at the moment. A file of the next name that is there already
    /// (the series' files were checked at the start: it is another program's) is left alone
    /// and the recording goes on under the next free name, with a warning.
    fn next_file(&mut self) -> Result<pcapng::Writer<BufWriter<File>>, CliError> {
        let names: Vec<String> = self.ports.iter().map(|p| p.name.clone()).collect();
        let mut taken = Vec::new();
        let (next, mut writer) = loop {
            let next = numbered(&self.base, self.next_number);
            self.next_number += 1;
            let interfaces = (&names[..], &self.bauds[..], &self.formats[..]);
            match create(&next, interfaces, self.recording) {
                Ok(writer) => break (next, writer),
                Err(CliError::Write(WriteError::Exists { .. })) if taken.len() < MAX_TAKEN => {
                    taken.push(next);
                }
                Err(e) => return Err(e),
            }
        };
        if !taken.is_empty() && self.warn {
            eprintln!(
                "hwfoc: warning: {} appeared meanwhile and {} left alone; the recording goes on \
                 in {next}",
                taken.join(", "),
                if taken.len() == 1 { "is" } else { "are" }
            );
        }
        self.files.push(next);
        self.file_started = Instant::now();
        self.file_has_packets = false;
        let now_ns = self.clock.now_ns();
        for (port, state) in self.ports.iter().enumerate() {
            if let Some(since) = state.lost_at {
                let text = format!(
                    "gap: {} is still lost (since {:.1} s before this file began)",
                    state.name,
                    now_ns.saturating_sub(since) as f64 * 1e-9
                );
                writer
                    .comment(port as u32, now_ns, &text)
                    .map_err(|e| self.write_error(e))?;
                self.file_has_packets = true;
            }
        }
        Ok(writer)
    }

    /// Closes the current file; the next one starts with the next thing to write.
    fn rotate(&mut self) -> Result<(), CliError> {
        if let Some(old) = self.writer.take() {
            finish(old).map_err(|e| self.write_error(e))?;
        }
        Ok(())
    }

    /// Writes everything out and syncs the file (its headers first, if they still waited for a
    /// port's rate).
    pub fn close(&mut self) -> Result<(), CliError> {
        self.begin()?;
        self.rotate()
    }

    /// One line: how long, where, and bytes and frames per port.
    pub fn status(&self, elapsed: Duration) -> String {
        let files = match self.files.as_slice() {
            [one] => one.clone(),
            [first, .., last] => format!("{first} … {last} ({} files)", self.files.len()),
            [] => String::new(),
        };
        let ports: Vec<String> = self
            .ports
            .iter()
            .enumerate()
            .map(|(i, p)| {
                if let Some(bitrate) = p.can {
                    return can_status(&p.name, bitrate, p.can_nodes.count_ones(), p.can_frames);
                }
                let stats = self.streams.stats(i).unwrap_or_default();
                format!(
                    "{} {} bytes, {} frames",
                    p.name,
                    stats.bytes(),
                    frames(stats)
                )
            })
            .collect();
        format!(
            "recorded {:.1} s to {files}: {}",
            elapsed.as_secs_f64(),
            ports.join("; ")
        )
    }
}

/// What the report says of CAN bus `name`: its bit rate where known, the DroneCAN nodes heard
/// and the CAN frames recorded (`slcan:/dev/ttyACM0 500000 bit/s, 4 nodes, 1341 CAN frames`).
fn can_status(name: &str, bitrate: Option<u32>, nodes: u32, frames: u64) -> String {
    let rate = bitrate.map_or_else(String::new, |b| format!(" {b} bit/s,"));
    let plural = |n: u64, what: &str| format!("{n} {what}{}", if n == 1 { "" } else { "s" });
    format!(
        "{name}{rate} {}, {}",
        plural(u64::from(nodes), "node"),
        plural(frames, "CAN frame")
    )
}

/// The rates an auto-baud search tries: `19200 and 115200`.
fn rates_text() -> String {
    let rates: Vec<String> = SEARCH_RATES.iter().map(u32::to_string).collect();
    rates.join(" and ")
}

/// The warning for a port that received nothing in [`SILENT_AFTER`]: in CAN words for a bus.
fn silent_warning(state: &PortState) -> String {
    let name = Escaped(&state.name);
    let secs = SILENT_AFTER.as_secs();
    match state.can {
        Some(bitrate) => format!(
            "{name}: no CAN frame in {secs} s{}: is the adapter on the bus and are the ESCs \
             powered, at the bus's bit rate (Hobbywing's DroneCAN ESCs are 500 kbit/s from the \
             factory)?",
            bitrate.map_or(String::new(), |b| format!(" at {b} bit/s"))
        ),
        None => format!(
            "{name}: nothing received in {secs} s: is the ESC powered, and its telemetry wire \
             on the adapter's RX pin (not TX)?"
        ),
    }
}

/// The warning for port `name`, read at `baud` (`None`: at every rate searched), whose `bytes`
/// in [`NO_FRAMES_AFTER`] held no valid frame of `protocol` (without one forced, of any
/// format).
fn no_frame_warning(
    name: &str,
    bytes: u64,
    baud: Option<u32>,
    protocol: Option<Protocol>,
) -> String {
    let read_at = match baud {
        Some(baud) => format!("read at {baud}"),
        None => format!("read at {} in turn", rates_text()),
    };
    let (what, rates) = match protocol {
        Some(p) => (
            format!("{} frame", p.title()),
            format!("{} telemetry is {}", p.title(), p.baud_rate()),
        ),
        None => (
            "frame of any Hobbywing format".to_string(),
            "HW-FOC, V4 and V3 telemetry is 19200, DataLink and HW5 115200".to_string(),
        ),
    };
    format!(
        "{}: {bytes} bytes in {} s but no valid {what}: likely a wrong baud rate ({read_at}; \
         {rates}, see --baud) or swapped TX/RX wires (the adapter's RX must be on the \
         ESC's telemetry wire)",
        Escaped(name),
        NO_FRAMES_AFTER.as_secs(),
    )
}

/// Each port's name, rate (`None`: not found) and format (`None`: not known), in port order:
/// what its interface says.
type Interfaces<'a> = (&'a [String], &'a [Option<u32>], &'a [Option<Protocol>]);

/// Creates a recording file with its headers, one interface per port at its rate. An
/// existing file is an error. The file is part of recording `recording`.
fn create(
    path: &str,
    interfaces: Interfaces,
    recording: pcapng::RecordingId,
) -> Result<pcapng::Writer<BufWriter<File>>, CliError> {
    let file = hwfoc_io::write::create_file(path, false)?;
    headers(path, file, interfaces, recording)
}

/// Writes the headers of the file `path` of recording `recording` into `file`: one interface
/// per port at its rate (19200 for a rate not known), naming its format where known.
fn headers(
    path: &str,
    file: File,
    (ports, bauds, formats): Interfaces,
    recording: pcapng::RecordingId,
) -> Result<pcapng::Writer<BufWriter<File>>, CliError> {
    let err = |source| WriteError::Write {
        output: path.to_string(),
        source,
    };
    let buffered = BufWriter::with_capacity(BUFFER, file);
    let mut writer = pcapng::Writer::continuing(buffered, recording).map_err(err)?;
    for (i, port) in ports.iter().enumerate() {
        if let Some(bitrate) = can_bus(port) {
            // A CAN bus: one packet per frame (`pcapng::Writer::write` takes its records).
            writer.add_can_interface(port, bitrate).map_err(err)?;
            continue;
        }
        let baud = bauds.get(i).copied().flatten().unwrap_or(DEFAULT_BAUD);
        let format = formats.get(i).copied().flatten();
        writer.add_port(port, baud, format).map_err(err)?;
    }
    writer.flush().map_err(err)?;
    Ok(writer)
}

/// The existing files of the rotated series `base` (`out.pcapng`: `out-0001.pcapng`, ...), in
/// order.
fn series(base: &str) -> Vec<String> {
    let first = PathBuf::from(numbered(base, 1));
    let dir = match first.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return Vec::new();
    };
    // A file is of the series when its name is `numbered(base, n)` for its own number n.
    let mut files: Vec<(u32, String)> = entries
        .filter_map(Result::ok)
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            let n = series_number(base, &name)?;
            let path = numbered(base, n);
            (Path::new(&path).file_name() == Some(e.file_name().as_os_str())).then_some((n, path))
        })
        .collect();
    files.sort();
    files.into_iter().map(|(_, path)| path).collect()
}

/// The number `n` of a file name that may be `numbered(base, n)`: the digits before the
/// extension, after the last `-`.
fn series_number(base: &str, name: &str) -> Option<u32> {
    let ext = Path::new(base)
        .extension()
        .map(|e| e.to_string_lossy().into_owned());
    let body = match &ext {
        Some(ext) => name.strip_suffix(&format!(".{ext}"))?,
        None => name,
    };
    let digits = body.rsplit_once('-')?.1;
    (digits.len() >= 4 && digits.bytes().all(|b| b.is_ascii_digit()))
        .then(|| digits.parse().ok())
        .flatten()
}

/// Flushes and syncs a finished file.
fn finish(writer: pcapng::Writer<BufWriter<File>>) -> std::io::Result<()> {
    let buffered = writer.into_inner()?;
    let file = buffered.into_inner().map_err(|e| e.into_error())?;
    file.sync_all()?;
    drop(file);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_size("100000"), Ok(100_000));
        assert_eq!(parse_size("100M"), Ok(100_000_000));
        assert_eq!(parse_size("64KiB"), Ok(65_536));
        assert_eq!(parse_size("2G"), Ok(2_000_000_000));
        assert!(parse_size("10").is_err());
        assert_eq!(parse_size("1k"), Ok(1000));
        assert!(parse_size("999").is_err());
        assert!(parse_size("x").is_err());
        assert!(parse_size("5 parsecs").is_err());
        assert!(parse_size("99999999999999999999G").is_err());
    }

    #[test]
    fn seconds() {
        assert_eq!(parse_seconds("2.5"), Ok(2.5));
        assert!(parse_seconds("0").is_err());
        assert!(parse_seconds("-1").is_err());
        assert!(parse_seconds("inf").is_err());
        assert!(parse_seconds("1e300").is_err());
    }

    /// Without a protocol forced the warning names every format's baud rate; forced, the
    /// protocol's title and baud rate.
    #[test]
    fn the_no_frame_warning_names_the_protocol_forced() {
        assert_eq!(
            no_frame_warning("/dev/ttyUSB0", 640, Some(115_200), None),
            "/dev/ttyUSB0: 640 bytes in 3 s but no valid frame of any Hobbywing format: likely a \
             wrong baud rate (read at 115200; HW-FOC, V4 and V3 telemetry is 19200, DataLink and \
             HW5 115200, see --baud) or swapped TX/RX wires (the adapter's RX must be on the \
             ESC's telemetry wire)"
        );
        let forced = no_frame_warning("/dev/ttyUSB0", 640, Some(19_200), Some(Protocol::DataLink));
        let searched = no_frame_warning("/dev/ttyUSB0", 640, None, None);
        assert!(
            searched.contains("likely a wrong baud rate (read at 19200 and 115200 in turn; "),
            "{searched}"
        );
        assert!(
            forced.contains(
                "no valid DataLink V2 frame: likely a wrong baud rate (read at 19200; DataLink \
                 V2 telemetry is 115200, see --baud)"
            ),
            "{forced}"
        );
    }

    /// A silent CAN bus is told of in CAN words (bit rates, frames), a serial port in serial
    /// ones (the RX wire).
    #[test]
    fn a_silent_bus_is_told_of_in_can_words() {
        let state = |name: &str| PortState {
            name: name.to_string(),
            unframed_since: None,
            unframed_bytes: 0,
            warned_unframed: false,
            silent_since: None,
            lost_at: None,
            can: can_bus(name),
            can_frames: 0,
            can_nodes: 0,
        };
        let bus = silent_warning(&state("slcan:/dev/ttyACM0:250000"));
        assert!(bus.contains("no CAN frame in 5 s at 250000 bit/s"), "{bus}");
        assert!(bus.contains("500 kbit/s") && !bus.contains("baud") && !bus.contains("RX"));
        let port = silent_warning(&state("/dev/ttyUSB0"));
        assert!(port.contains("RX pin"), "{port}");
    }

    #[test]
    fn numbered_names() {
        assert_eq!(numbered("out.pcapng", 1), "out-0001.pcapng");
        assert_eq!(
            numbered("/tmp/a.b/run.pcapng", 12),
            "/tmp/a.b/run-0012.pcapng"
        );
        assert_eq!(numbered("capture", 3), "capture-0003");
    }
}
