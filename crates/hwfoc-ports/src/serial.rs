//! Serial ports: telling them from files, opening them with errors that say what to do ([`open`],
//! [`PortError`]: `port.rs`, which the CAN buses use too), and reading several at once, each in its own thread, surviving a port that is unplugged.
//!
//! A [`PortSet`] owns one reader thread per port. Each thread hands over every chunk of bytes
//! as soon as a read returns, with the Unix time of its first byte, as a [`PortEvent`] on a
//! channel; a port that fails mid-read (USB unplugged: `EIO`, a hang-up, end of file) becomes a
//! [`PortEvent::Lost`], after which the thread tries to reopen the same path every
//! [`RETRY_EVERY`] and reports [`PortEvent::Back`] when the device has returned.
//!
//! A port opened at [`Baud::Auto`] finds its rate itself ([`Search`]): it is read at 19200
//! baud (HW-FOC, V4, V3), then at 115200 (DataLink, HW5), and back, in turn, until the bytes
//! read at one rate give frames; it then stays at that rate ([`PortEvent::Found`]). Bytes read
//! at a rate that gave no frame are not handed on (read at the wrong rate they are not the
//! wire's bytes: [`PortEvent::Searching`] counts them), so that nothing downstream, a decoder
//! or a recording, ever takes them for telemetry.
//!
//! A port named `slcan:PORT[:BITRATE]` or `can:IFACE` ([`crate::can::is_can_spec`]) is a CAN
//! bus ([`crate::can::CanBus`]), read by a thread of its own that hands on each frame as a
//! [`PortEvent::Data`] of its 16-byte record at the frame's time ([`PortSet::is_can`]), asks
//! the bus's ESCs for their ids ([`crate::can::AskIds`]), and is lost and back as a serial port
//! is; no rate is searched on it.

use std::io::{self, Read};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::thread::{self, JoinHandle};
use std::time::{Duration, Instant};

use crate::can::{CanBus, CanError};
use crate::clock::ReceiveClock;
use crate::port::READ_TIMEOUT;
pub use crate::port::{PortError, available_ports, open};
pub use hwfoc_records::serial::{DEFAULT_BAUD, PortEvent, RETRY_EVERY};

use hwfoc::Protocol;
use hwfoc::detect;
use serialport::{ClearBuffer, SerialPort};

/// Bytes asked for per read (at 19200 baud a read rarely returns more than a frame).
const READ_SIZE: usize = 4096;

/// The rates an auto-baud search tries, in turn, from the first: the ESCs' own wires (HW-FOC,
/// V4, V3) and then DataLink hubs and HW5 ESCs.
pub const SEARCH_RATES: [u32; 2] = [19_200, 115_200];

/// How long bytes may arrive at one rate without a frame before the next rate is tried.
///
/// Every format's ESC sends frames at least every 364 ms (HW-FOC idle; V3, V4 and HW5 every 20
/// to 50 ms) and detection locks after one checksummed frame or three chained ones, so at the
/// right rate 1.5 s holds four frames at the slowest; at a wrong one a UART makes garbage of
/// the line's edges, which gives no frame. 1.5 s is thus a loss of a few frames at worst, and
/// a port is found within 1.5 s of bytes at the wrong rate plus the lock at the right one.
pub const SEARCH_BYTES_FOR: Duration = Duration::from_millis(1500);

/// How long a rate is kept when no byte at all arrives: long enough that an ESC being powered
/// is not missed by switching under it too often, short enough that an ESC whose bytes a UART
/// at the wrong rate drops as framing errors is found within a few seconds.
pub const SEARCH_SILENT_FOR: Duration = Duration::from_millis(3000);

/// Frames that lock a rate: two, so that a frame whose checksum a run of garbage happened to
/// match (one in 65536 candidates) does not (V3 and V4 frames come only from chains of three).
pub const SEARCH_LOCK_FRAMES: u32 = 2;

/// The baud rate a port is read at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Baud {
    /// This rate, as given.
    Fixed(u32),
    /// Found from the bytes: [`SEARCH_RATES`] in turn until one gives frames (see [`Search`]).
    Auto,
}

impl From<u32> for Baud {
    fn from(baud: u32) -> Baud {
        Baud::Fixed(baud)
    }
}

impl Baud {
    /// The rate a port is opened at: the one given, or the first one searched.
    pub fn initial(self) -> u32 {
        match self {
            Baud::Fixed(baud) => baud,
            Baud::Auto => SEARCH_RATES[0],
        }
    }

    /// The rate given, `None` when it is to be found.
    pub fn fixed(self) -> Option<u32> {
        match self {
            Baud::Fixed(baud) => Some(baud),
            Baud::Auto => None,
        }
    }
}

/// What the bytes read at the rate being tried said, for [`Search::bytes`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Nothing decided yet.
    Undecided,
    /// The rate gives frames of this protocol (the first found): it is the port's.
    Locked(Protocol),
}

/// The auto-baud search of one port: the rate being tried, and whether its bytes give frames.
///
/// Fed the bytes read ([`Search::bytes`]) and asked at every read or timeout whether to try the
/// next rate ([`Search::due`], then [`Search::next`]), it tries [`SEARCH_RATES`] in turn: a
/// rate is left after [`SEARCH_BYTES_FOR`] of bytes without a frame, or [`SEARCH_SILENT_FOR`]
/// without any byte, and kept once [`SEARCH_LOCK_FRAMES`] frames of any format were found in
/// its bytes. Each rate starts with a new decoder: bytes read at another rate never reach it.
/// Times are the caller's (`Instant`s), so that a test drives it without a port.
#[derive(Debug, Clone)]
pub struct Search {
    index: usize,
    /// When the rate began to be tried.
    since: Instant,
    /// When the first byte at this rate arrived.
    first_byte: Option<Instant>,
    /// Bytes read at this rate.
    bytes: u64,
    decoder: detect::Decoder,
    frames: u32,
    protocol: Option<Protocol>,
}

impl Search {
    /// A search starting now, at the first of [`SEARCH_RATES`].
    pub fn new(now: Instant) -> Search {
        Search {
            index: 0,
            since: now,
            first_byte: None,
            bytes: 0,
            decoder: detect::Decoder::new(),
            frames: 0,
            protocol: None,
        }
    }

    /// The rate being tried.
    pub fn baud(&self) -> u32 {
        SEARCH_RATES[self.index]
    }

    /// Bytes read at the rate being tried so far.
    pub fn bytes_read(&self) -> u64 {
        self.bytes
    }

    /// Takes bytes read at the rate being tried, at `now`.
    pub fn bytes(&mut self, bytes: &[u8], now: Instant) -> Verdict {
        if bytes.is_empty() {
            return self.verdict();
        }
        self.first_byte.get_or_insert(now);
        self.bytes += bytes.len() as u64;
        let (frames, protocol) = (&mut self.frames, &mut self.protocol);
        self.decoder.feed(bytes, |d| {
            *frames += 1;
            protocol.get_or_insert(d.protocol());
        });
        self.verdict()
    }

    fn verdict(&self) -> Verdict {
        match self.protocol {
            Some(p) if self.frames >= SEARCH_LOCK_FRAMES => Verdict::Locked(p),
            _ => Verdict::Undecided,
        }
    }

    /// Whether, at `now`, the next rate is to be tried: bytes for [`SEARCH_BYTES_FOR`]
    /// without a lock, or none for [`SEARCH_SILENT_FOR`].
    pub fn due(&self, now: Instant) -> bool {
        if self.verdict() != Verdict::Undecided {
            return false;
        }
        match self.first_byte {
            Some(first) => now.saturating_duration_since(first) >= SEARCH_BYTES_FOR,
            None => now.saturating_duration_since(self.since) >= SEARCH_SILENT_FOR,
        }
    }

    /// Starts trying the next rate at `now`, with a new decoder; returns it and how many
    /// bytes the rate left gave (none of them in a frame that counted).
    pub fn next(&mut self, now: Instant) -> (u32, u64) {
        let discarded = self.bytes;
        *self = Search {
            index: (self.index + 1) % SEARCH_RATES.len(),
            ..Search::new(now)
        };
        (self.baud(), discarded)
    }

    /// Starts the rate being tried again at `now` (the port was reopened).
    pub fn restart(&mut self, now: Instant) {
        *self = Search {
            index: self.index,
            ..Search::new(now)
        };
    }
}

/// Whether `spec`, an input named on the command line, is a serial port rather than a file:
/// `COM3` (or `\\.\COM12`); a character device that is a terminal; or a path under `/dev` that
/// looks like a serial device (`/dev/ttyUSB0`, `/dev/ttyACM0`, `/dev/cu.usbserial-1`,
/// `/dev/serial/by-id/…`, `/dev/pts/3`), even when it does not exist, so that a missing adapter
/// is reported as a missing port. A CAN bus (`slcan:PORT[:BITRATE]`, `can:IFACE`) is a port.
pub fn is_port(spec: &str) -> bool {
    if crate::can::is_can_spec(spec) {
        return true;
    }
    let upper = spec.to_ascii_uppercase();
    let com = upper.strip_prefix(r"\\.\").unwrap_or(&upper);
    if com
        .strip_prefix("COM")
        .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
    {
        return true;
    }
    if ["/dev/stdin", "/dev/tty", "/dev/console"].contains(&spec)
        || spec.starts_with("/dev/fd/")
        || spec.starts_with("/proc/")
    {
        return false;
    }
    #[cfg(unix)]
    if let Ok(meta) = std::fs::metadata(spec) {
        use std::os::unix::fs::FileTypeExt;
        return meta.file_type().is_char_device() && is_terminal(spec);
    }
    [
        "/dev/tty",
        "/dev/cu.",
        "/dev/serial/",
        "/dev/pts/",
        "/dev/rfcomm",
    ]
    .iter()
    .any(|prefix| spec.starts_with(prefix))
}

/// Whether the character device at `path` is a terminal (opened without waiting for a carrier
/// and without becoming our controlling terminal).
#[cfg(unix)]
fn is_terminal(path: &str) -> bool {
    use std::io::IsTerminal;
    use std::os::unix::fs::OpenOptionsExt;
    let flags = nix::fcntl::OFlag::O_NONBLOCK | nix::fcntl::OFlag::O_NOCTTY;
    match std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(flags.bits())
        .open(path)
    {
        Ok(file) => file.is_terminal(),
        // Not allowed to open it: say so when it is opened as a port.
        Err(e) => e.kind() == io::ErrorKind::PermissionDenied,
    }
}

/// Several serial ports read at once, one thread per port, events on one channel.
pub struct PortSet {
    readers: Readers,
    events: Receiver<PortEvent>,
}

/// The reader threads of several ports, sending their events into a channel of the caller's
/// (wrapped in the caller's message type); dropping it stops them.
pub struct Readers {
    names: Vec<String>,
    /// Whether each port is a CAN bus.
    can: Vec<bool>,
    baud: Baud,
    clock: ReceiveClock,
    stop: Arc<AtomicBool>,
    threads: Vec<JoinHandle<()>>,
}

impl Readers {
    /// Opens every port (all of them, before any reading starts, so that a bad name is
    /// reported at once) and starts their reader threads, which send `wrap(event)` on `tx`.
    /// At [`Baud::Auto`] each port finds its own rate.
    pub fn start<M: Send + 'static>(
        names: &[String],
        baud: impl Into<Baud>,
        tx: Sender<M>,
        wrap: fn(PortEvent) -> M,
    ) -> Result<Readers, PortError> {
        let baud = baud.into();
        if let Some((i, name)) = names
            .iter()
            .enumerate()
            .find(|(i, name)| names[..*i].contains(name))
        {
            return Err(PortError::Other {
                port: name.clone(),
                message: format!(
                    "it is named twice (as port {} and port {})",
                    names.iter().position(|n| n == name).unwrap_or(0) + 1,
                    i + 1
                ),
            });
        }
        let clock = ReceiveClock::new();
        let ports = names
            .iter()
            .map(|name| match crate::can::is_can_spec(name) {
                true => CanBus::open_with_clock(name, true, clock)
                    .map(|bus| Opened::Can(Box::new(bus)))
                    .map_err(CanError::into_port_error),
                false => open(name, baud.initial()).map(Opened::Serial),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let can: Vec<bool> = ports.iter().map(|p| matches!(p, Opened::Can(_))).collect();
        let stop = Arc::new(AtomicBool::new(false));
        let threads = ports
            .into_iter()
            .enumerate()
            .map(|(index, port)| {
                let port = match port {
                    Opened::Serial(port) => port,
                    Opened::Can(bus) => {
                        let reader = CanReader {
                            index,
                            name: names[index].clone(),
                            clock,
                            stop: Arc::clone(&stop),
                            tx: tx.clone(),
                            wrap,
                        };
                        return thread::Builder::new()
                            .name(format!("read {}", names[index]))
                            .spawn(move || reader.run(*bus))
                            .map_err(|e| PortError::Other {
                                port: names[index].clone(),
                                message: format!("cannot start its reader thread: {e}"),
                            });
                    }
                };
                let reader = PortReader {
                    index,
                    name: names[index].clone(),
                    baud: baud.initial(),
                    search: (baud == Baud::Auto).then(|| Search::new(Instant::now())),
                    held: Vec::new(),
                    clock,
                    stop: Arc::clone(&stop),
                    tx: tx.clone(),
                    wrap,
                    last_ns: None,
                };
                thread::Builder::new()
                    .name(format!("read {}", names[index]))
                    .spawn(move || reader.run(port))
                    .map_err(|e| PortError::Other {
                        port: names[index].clone(),
                        message: format!("cannot start its reader thread: {e}"),
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Readers {
            names: names.to_vec(),
            can,
            baud,
            clock,
            stop,
            threads,
        })
    }

    /// The ports, in the order given.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The rate the ports were opened with: given, or [`Baud::Auto`].
    pub fn baud(&self) -> Baud {
        self.baud
    }

    /// Whether port `port` is a CAN bus (`slcan:...`, `can:...`): its bytes are frame records
    /// of 16 bytes ([`hwfoc::dronecan::CanFrame::to_socketcan_record`]), one
    /// [`PortEvent::Data`] per frame.
    pub fn is_can(&self, port: usize) -> bool {
        self.can.get(port).copied().unwrap_or(false)
    }

    /// The clock the events' times come from.
    pub fn clock(&self) -> ReceiveClock {
        self.clock
    }

    fn shut_down(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for thread in self.threads.drain(..) {
            let _ = thread.join();
        }
    }
}

impl Drop for Readers {
    fn drop(&mut self) {
        self.shut_down();
    }
}

impl PortSet {
    /// Opens every port (all of them, before any reading starts, so that a bad name is
    /// reported at once) and starts their reader threads. At [`Baud::Auto`] each port finds
    /// its own rate.
    pub fn open(names: &[String], baud: impl Into<Baud>) -> Result<PortSet, PortError> {
        let (tx, events) = mpsc::channel();
        let readers = Readers::start(names, baud, tx, |event| event)?;
        Ok(PortSet { readers, events })
    }

    /// The ports, in the order given.
    pub fn names(&self) -> &[String] {
        self.readers.names()
    }

    /// The baud rate the ports were opened with: given, or [`Baud::Auto`] (each port's is then
    /// told by its [`PortEvent::Found`]).
    pub fn baud(&self) -> Baud {
        self.readers.baud
    }

    /// The clock the events' times come from.
    pub fn clock(&self) -> ReceiveClock {
        self.readers.clock()
    }

    /// Whether port `port` is a CAN bus ([`Readers::is_can`]).
    pub fn is_can(&self, port: usize) -> bool {
        self.readers.is_can(port)
    }

    /// The next event, waiting at most `timeout`; `None` if none came.
    pub fn next_event(&self, timeout: Duration) -> Option<PortEvent> {
        self.events.recv_timeout(timeout).ok()
    }

    /// The next event if one is waiting.
    pub fn try_event(&self) -> Option<PortEvent> {
        self.events.try_recv().ok()
    }

    /// Stops the reader threads, waits for them, and returns the events they sent before
    /// stopping (bytes received up to the end are not lost).
    pub fn close(mut self) -> Vec<PortEvent> {
        self.readers.shut_down();
        self.events.try_iter().collect()
    }
}

/// A port as opened: a serial port or a CAN bus.
enum Opened {
    Serial(Box<dyn SerialPort>),
    Can(Box<CanBus>),
}

/// A CAN bus's reader thread: a [`PortEvent::Data`] per frame, lost and back as a port.
struct CanReader<M> {
    index: usize,
    name: String,
    clock: ReceiveClock,
    stop: Arc<AtomicBool>,
    tx: Sender<M>,
    wrap: fn(PortEvent) -> M,
}

impl<M> CanReader<M> {
    fn run(self, bus: CanBus) {
        let mut bus = Some(bus);
        while !self.stop.load(Ordering::Relaxed) {
            let Some(b) = bus.as_mut() else {
                bus = self.reopen();
                continue;
            };
            let event = match b.recv(READ_TIMEOUT) {
                Ok(None) => continue,
                Ok(Some((t_s, frame))) => PortEvent::Data {
                    port: self.index,
                    t_ns: (t_s * 1e9).round() as u64,
                    bytes: frame.to_socketcan_record().to_vec(),
                },
                Err(e) => {
                    bus = None;
                    PortEvent::Lost {
                        port: self.index,
                        t_ns: self.clock.now_ns(),
                        reason: match e {
                            CanError::Lost { reason, .. } => reason,
                            e => e.to_string(),
                        },
                    }
                }
            };
            if self.tx.send((self.wrap)(event)).is_err() {
                return;
            }
        }
    }

    /// Waits [`RETRY_EVERY`] (or until asked to stop) and tries to open the bus again.
    fn reopen(&self) -> Option<CanBus> {
        let until = Instant::now() + RETRY_EVERY;
        while Instant::now() < until {
            if self.stop.load(Ordering::Relaxed) {
                return None;
            }
            thread::sleep(Duration::from_millis(20));
        }
        let bus = CanBus::open_with_clock(&self.name, true, self.clock).ok()?;
        let event = PortEvent::Back {
            port: self.index,
            t_ns: self.clock.now_ns(),
        };
        self.tx.send((self.wrap)(event)).ok()?;
        Some(bus)
    }
}

/// One port's reader thread.
struct PortReader<M> {
    index: usize,
    name: String,
    /// The rate the port is read at (while searching: the rate tried).
    baud: u32,
    /// The auto-baud search, until it has found the rate.
    search: Option<Search>,
    /// While searching: the chunks read at the rate tried, handed on if it is found.
    held: Vec<(u64, Vec<u8>)>,
    clock: ReceiveClock,
    stop: Arc<AtomicBool>,
    tx: Sender<M>,
    wrap: fn(PortEvent) -> M,
    /// Time of the previous chunk's last byte.
    last_ns: Option<u64>,
}

impl<M> PortReader<M> {
    fn run(mut self, port: Box<dyn SerialPort>) {
        let mut port = Some(port);
        let mut buf = vec![0u8; READ_SIZE];
        while !self.stop.load(Ordering::Relaxed) {
            let Some(p) = port.as_mut() else {
                port = self.reopen();
                continue;
            };
            let failure = match p.read(&mut buf) {
                Ok(0) => Some("the device reported end of file".to_string()),
                Ok(n) => {
                    self.received(&buf[..n]);
                    self.search_step(p.as_mut());
                    None
                }
                Err(e)
                    if matches!(
                        e.kind(),
                        io::ErrorKind::TimedOut
                            | io::ErrorKind::WouldBlock
                            | io::ErrorKind::Interrupted
                    ) =>
                {
                    self.search_step(p.as_mut());
                    None
                }
                Err(e) => Some(e.to_string()),
            };
            if let Some(reason) = failure {
                port = None;
                let event = PortEvent::Lost {
                    port: self.index,
                    t_ns: self.clock.now_ns(),
                    reason,
                };
                if self.tx.send((self.wrap)(event)).is_err() {
                    return;
                }
            }
        }
    }

    fn received(&mut self, bytes: &[u8]) {
        let per_byte = hwfoc::wire::byte_ns(self.baud);
        let now = self.clock.now_ns();
        let span = ((bytes.len() - 1) as f64 * per_byte) as u64;
        let mut t_ns = now.saturating_sub(span);
        if let Some(last) = self.last_ns {
            t_ns = t_ns.max(last + per_byte as u64);
        }
        self.last_ns = Some(t_ns + span);
        if let Some(search) = &mut self.search {
            // Held until the rate is known to be the port's; handed on at the lock.
            self.held.push((t_ns, bytes.to_vec()));
            if let Verdict::Locked(protocol) = search.bytes(bytes, Instant::now()) {
                self.found(protocol);
            }
            return;
        }
        let _ = self.tx.send((self.wrap)(PortEvent::Data {
            port: self.index,
            t_ns,
            bytes: bytes.to_vec(),
        }));
    }

    /// The search has found the rate: says so, then hands on the bytes read at it.
    fn found(&mut self, protocol: Protocol) {
        self.search = None;
        let event = PortEvent::Found {
            port: self.index,
            t_ns: self.clock.now_ns(),
            baud: self.baud,
            protocol,
        };
        let _ = self.tx.send((self.wrap)(event));
        for (t_ns, bytes) in std::mem::take(&mut self.held) {
            let event = PortEvent::Data {
                port: self.index,
                t_ns,
                bytes,
            };
            let _ = self.tx.send((self.wrap)(event));
        }
    }

    /// While searching: tries the next rate when the one tried is due to be left. The bytes
    /// read at the one left are dropped, and so is what the port's buffer still holds of them.
    fn search_step(&mut self, port: &mut dyn SerialPort) {
        let now = Instant::now();
        let Some(search) = self.search.as_mut().filter(|s| s.due(now)) else {
            return;
        };
        let (baud, discarded) = search.next(now);
        self.held.clear();
        // A rate the driver refuses gives no frame: it is left in turn like any other.
        let _ = port.set_baud_rate(baud);
        let _ = port.clear(ClearBuffer::Input);
        self.baud = baud;
        self.last_ns = None;
        let event = PortEvent::Searching {
            port: self.index,
            t_ns: self.clock.now_ns(),
            baud,
            discarded,
        };
        let _ = self.tx.send((self.wrap)(event));
    }

    /// Waits [`RETRY_EVERY`] (or until asked to stop) and tries to open the port again.
    fn reopen(&mut self) -> Option<Box<dyn SerialPort>> {
        let until = Instant::now() + RETRY_EVERY;
        while Instant::now() < until {
            if self.stop.load(Ordering::Relaxed) {
                return None;
            }
            thread::sleep(Duration::from_millis(20));
        }
        let port = open(&self.name, self.baud).ok()?;
        if let Some(search) = &mut self.search {
            // What was read before the loss is not followed by what comes now.
            self.held.clear();
            search.restart(Instant::now());
        }
        let event = PortEvent::Back {
            port: self.index,
            t_ns: self.clock.now_ns(),
        };
        self.tx.send((self.wrap)(event)).ok()?;
        Some(port)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn port_names() {
        for port in [
            "COM3",
            "com12",
            r"\\.\COM10",
            "/dev/ttyUSB9",
            "/dev/serial/by-id/x",
            "slcan:/dev/ttyACM0",
            "slcan:/dev/ttyACM0:1000000",
            "can:can0",
        ] {
            assert!(is_port(port), "{port}");
        }
        for file in [
            "COM",
            "COMX",
            "capture.bin",
            "-",
            "/dev/null",
            "/dev/stdin",
            "/tmp",
        ] {
            assert!(!is_port(file), "{file}");
        }
    }

    #[test]
    fn clock_is_unix_time_and_monotonic() {
        let clock = ReceiveClock::new();
        let a = clock.now_ns();
        let b = clock.now_ns();
        assert!(b >= a);
        assert!(a > 1_600_000_000_000_000_000);
    }

    /// Bytes a UART makes of a line at another rate: no frame of any format in them.
    fn garbage(n: usize, seed: &mut u32) -> Vec<u8> {
        (0..n)
            .map(|_| {
                *seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (*seed >> 24) as u8
            })
            .collect()
    }

    fn hw5_frames(n: usize) -> Vec<u8> {
        (0..n)
            .flat_map(|i| {
                hwfoc::hw5::TelemetryFrame {
                    voltage_raw: 252,
                    erpm_raw: i as u16,
                    bec_voltage_raw: 84,
                    ..Default::default()
                }
                .encode()
            })
            .collect()
    }

    fn foc_frames(packets: std::ops::Range<u16>) -> Vec<u8> {
        packets
            .flat_map(|packet| {
                hwfoc::foc::DataFrame {
                    packet,
                    ..Default::default()
                }
                .encode()
            })
            .collect()
    }

    /// The search with a fake port: garbage at 19200 for 1.5 s, then HW5 frames at 115200
    /// lock at once; a silent port changes rate every 3 s; frames at 19200 lock it there; a
    /// single frame does not lock.
    #[test]
    fn the_search_tries_each_rate_in_turn_until_one_gives_frames() {
        let t0 = Instant::now();
        let ms = |ms: u64| t0 + Duration::from_millis(ms);
        let mut seed = 7;
        let mut search = Search::new(t0);
        assert_eq!(search.baud(), 19_200);
        // Garbage every 50 ms: the rate is due 1.5 s after the first byte, not before.
        let mut t = 100;
        while !search.due(ms(t)) {
            let verdict = search.bytes(&garbage(96, &mut seed), ms(t));
            assert_eq!(verdict, Verdict::Undecided);
            t += 50;
        }
        assert_eq!(t, 1600);
        let read = search.bytes_read();
        assert_eq!(search.next(ms(t)), (115_200, read));
        // At 115200, HW5 frames: the second one locks.
        let frames = hw5_frames(2);
        assert_eq!(search.bytes(&frames[..32], ms(t + 20)), Verdict::Undecided);
        assert_eq!(
            search.bytes(&frames[32..], ms(t + 40)),
            Verdict::Locked(Protocol::Hw5)
        );
        assert!(!search.due(ms(t + 60_000)), "a locked rate stays");

        // Nothing at all: the next rate every 3 s, round and round.
        let mut silent = Search::new(t0);
        assert!(!silent.due(ms(2999)));
        assert!(silent.due(ms(3000)));
        assert_eq!(silent.next(ms(3000)), (115_200, 0));
        assert!(!silent.due(ms(5999)));
        assert_eq!(silent.next(ms(6000)), (19_200, 0));

        // HW-FOC frames at 19200 lock at once, behind garbage read from the middle of a frame.
        let mut esc = Search::new(t0);
        let mut wire = garbage(13, &mut seed);
        wire.extend(foc_frames(0..2));
        assert_eq!(esc.bytes(&wire, ms(10)), Verdict::Locked(Protocol::HwFoc));
        // One frame alone does not (its checksum may be chance).
        let mut one = Search::new(t0);
        assert_eq!(one.bytes(&foc_frames(0..1), ms(10)), Verdict::Undecided);
        // Bytes read at the rate left never reach the next rate's decoder: half a frame
        // there and half after the change make no frame.
        let frame = foc_frames(5..6);
        one.next(ms(3000));
        one.next(ms(6000));
        assert_eq!(one.bytes(&frame[..10], ms(6010)), Verdict::Undecided);
        one.next(ms(9000));
        one.next(ms(12000));
        assert_eq!(one.bytes(&frame[10..], ms(12010)), Verdict::Undecided);
        assert_eq!(one.bytes(&foc_frames(6..7), ms(12060)), Verdict::Undecided);
    }

    /// The speed a pseudo-terminal is set to (`c_ospeed` of its `termios2`).
    #[cfg(target_os = "linux")]
    fn pty_speed(fd: &std::os::fd::OwnedFd) -> u32 {
        use nix::libc;
        use std::os::fd::AsRawFd;
        let mut t: libc::termios2 = unsafe { std::mem::zeroed() };
        // SAFETY: TCGETS2 fills a termios2 of a terminal's fd; the fd is open.
        let r = unsafe { libc::ioctl(fd.as_raw_fd(), libc::TCGETS2, &mut t) };
        assert_eq!(r, 0, "TCGETS2");
        t.c_ospeed
    }

    /// A virtual ESC that speaks at `baud` only: on a pseudo-terminal (which passes bytes at any
    /// speed) it writes `frame(i)` every 20 ms while the terminal is set to `baud`, and what a
    /// UART at another rate would make of them, garbage, otherwise. Runs until `stop`.
    #[cfg(target_os = "linux")]
    fn esc_at(
        baud: u32,
        frame: fn(u16) -> Vec<u8>,
        stop: Arc<AtomicBool>,
    ) -> (String, thread::JoinHandle<()>) {
        use std::io::Write;
        use std::os::fd::AsFd;
        let pty = nix::pty::openpty(None, None).unwrap();
        let mut mode = nix::sys::termios::tcgetattr(pty.slave.as_fd()).unwrap();
        nix::sys::termios::cfmakeraw(&mut mode);
        let now = nix::sys::termios::SetArg::TCSANOW;
        nix::sys::termios::tcsetattr(pty.slave.as_fd(), now, &mode).unwrap();
        let name = nix::unistd::ttyname(pty.slave.as_fd()).unwrap();
        let thread = thread::spawn(move || {
            let mut master = std::fs::File::from(pty.master);
            let mut seed = 1;
            let mut i = 0u16;
            while !stop.load(Ordering::Relaxed) {
                let bytes = if pty_speed(&pty.slave) == baud {
                    frame(i)
                } else {
                    garbage(40, &mut seed)
                };
                i = i.wrapping_add(1);
                // Nobody reading yet (or any more): the bytes wait or are dropped.
                let _ = master.write_all(&bytes);
                thread::sleep(Duration::from_millis(20));
            }
        });
        (name.to_string_lossy().into_owned(), thread)
    }

    /// Reads `port` at [`Baud::Auto`] until its rate is found: returns the rate, the protocol,
    /// the time it took, and the bytes handed on before and after.
    #[cfg(target_os = "linux")]
    fn find(port: &str) -> (u32, Protocol, Duration, Vec<PortEvent>) {
        let start = Instant::now();
        let set = PortSet::open(&[port.to_string()], Baud::Auto).unwrap();
        assert_eq!(set.baud(), Baud::Auto);
        let mut events = Vec::new();
        let (baud, protocol, took) = loop {
            assert!(start.elapsed() < Duration::from_secs(10), "{events:?}");
            match set.next_event(Duration::from_millis(100)) {
                Some(PortEvent::Found { baud, protocol, .. }) => {
                    break (baud, protocol, start.elapsed());
                }
                Some(event) => events.push(event),
                None => {}
            }
        };
        // What follows: the bytes read at the rate found, frames of it.
        let mut after = Vec::new();
        let until = Instant::now() + Duration::from_millis(300);
        while Instant::now() < until {
            if let Some(PortEvent::Data { bytes, .. }) = set.next_event(Duration::from_millis(50)) {
                after.extend(bytes);
            }
        }
        let mut decoder = detect::Decoder::new();
        let mut frames = 0;
        decoder.feed(&after, |_| frames += 1);
        assert!(
            frames >= 2,
            "{} bytes after the lock, {frames} frames",
            after.len()
        );
        // Nothing read at a wrong rate was handed on.
        assert!(
            events
                .iter()
                .all(|e| matches!(e, PortEvent::Searching { .. })),
            "{events:?}"
        );
        (baud, protocol, took, events)
    }

    /// An HW5 ESC (115200 baud) is found after one round at 19200, an HW-FOC ESC (19200) at
    /// once; the locking time is measured and bounded.
    #[cfg(target_os = "linux")]
    #[test]
    fn auto_baud_finds_each_rate_on_a_pseudo_terminal() {
        let stop = Arc::new(AtomicBool::new(false));
        let hw5 = |i: u16| hw5_frames(1 + usize::from(i % 2));
        let foc = |i: u16| foc_frames(i..i + 1);
        let (hw5_port, hw5_esc) = esc_at(115_200, hw5, Arc::clone(&stop));
        let (foc_port, foc_esc) = esc_at(19_200, foc, Arc::clone(&stop));

        let (baud, protocol, took, events) = find(&hw5_port);
        eprintln!("HW5 at 115200 found in {took:?}");
        assert_eq!((baud, protocol), (115_200, Protocol::Hw5));
        match events.as_slice() {
            [
                PortEvent::Searching {
                    baud: 115_200,
                    discarded,
                    ..
                },
            ] => assert!(*discarded > 0),
            other => panic!("{other:?}"),
        }
        assert!(took >= SEARCH_BYTES_FOR, "{took:?}");
        assert!(took < SEARCH_BYTES_FOR + Duration::from_secs(1), "{took:?}");

        let (baud, protocol, took, events) = find(&foc_port);
        eprintln!("HW-FOC at 19200 found in {took:?}");
        assert_eq!((baud, protocol), (19_200, Protocol::HwFoc));
        assert!(events.is_empty(), "{events:?}");
        assert!(took < Duration::from_secs(1), "{took:?}");

        stop.store(true, Ordering::Relaxed);
        hw5_esc.join().unwrap();
        foc_esc.join().unwrap();
    }
}
