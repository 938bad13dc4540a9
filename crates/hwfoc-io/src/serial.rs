//! Serial ports: telling them from files, opening them with errors that say what to do, and
//! reading several at once, each in its own thread, surviving a port that is unplugged.
//!
//! A [`PortSet`] owns one reader thread per port. Each thread hands over every chunk of bytes
//! as soon as a read returns, with the Unix time of its first byte, as a [`PortEvent`] on a
//! channel; a port that fails mid-read (USB unplugged: `EIO`, a hang-up, end of file) becomes a
//! [`PortEvent::Lost`], after which the thread tries to reopen the same path every
//! [`RETRY_EVERY`] and reports [`PortEvent::Back`] when the device has returned.

use std::io::{self, Read};
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::thread::{self, JoinHandle};
use std::time::{Duration, Instant};

use crate::clock::ReceiveClock;

use serialport::{DataBits, FlowControl, Parity, SerialPort, StopBits};

use std::fmt;

/// The HW-FOC telemetry rate, the default of every serial input.
pub const DEFAULT_BAUD: u32 = hwfoc::foc::BAUD_RATE;

/// How long a read waits for bytes before the thread checks whether it should stop.
const READ_TIMEOUT: Duration = Duration::from_millis(50);

/// How often a lost port is tried again.
pub const RETRY_EVERY: Duration = Duration::from_millis(500);

/// Bytes asked for per read (at 19200 baud a read rarely returns more than a frame).
const READ_SIZE: usize = 4096;

/// Why a serial port could not be opened or read. Each names the port as the user gave it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PortError {
    /// A serial port that does not exist.
    NoSuchPort {
        /// The port as named on the command line.
        port: String,
        /// The ports the system does have.
        available: Vec<String>,
    },
    /// A serial port we may not open.
    Permission {
        /// The port as named on the command line.
        port: String,
        /// The group owning the device file, if known.
        group: Option<String>,
    },
    /// A serial port another program has open.
    Busy {
        /// The port as named on the command line.
        port: String,
    },
    /// A serial port that could not be opened or set up for another reason.
    Other {
        /// The port as named on the command line.
        port: String,
        /// Why.
        message: String,
    },
}

impl fmt::Display for PortError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PortError::NoSuchPort { port, available } => {
                write!(f, "no such port {port}")?;
                if available.is_empty() {
                    write!(f, " (no serial ports found: is the adapter plugged in?)")
                } else {
                    write!(f, " (serial ports found: {})", available.join(", "))
                }
            }
            PortError::Permission { port, group } => {
                // A device of group root is not meant for users: give the usual groups.
                let group = group.as_deref().filter(|g| *g != "root");
                let owner = match group {
                    Some(g) => format!(" (owned by group {g})"),
                    None => String::new(),
                };
                let command = match group {
                    Some(g) => format!("`sudo usermod -aG {g} $USER`"),
                    None => "`sudo usermod -aG dialout $USER` on Debian/Ubuntu, `uucp` on Arch"
                        .to_string(),
                };
                write!(
                    f,
                    "permission denied on {port}{owner}: join the group that may use serial \
                     ports ({command}), then log out and in again"
                )
            }
            PortError::Busy { port } => write!(
                f,
                "{port} is busy: another program has it open (a serial monitor, another hwfoc, \
                 ModemManager); close it and try again"
            ),
            PortError::Other { port, message } => write!(f, "cannot open port {port}: {message}"),
        }
    }
}

impl std::error::Error for PortError {}

/// Whether `spec`, an input named on the command line, is a serial port rather than a file:
/// `COM3` (or `\\.\COM12`); a character device that is a terminal; or a path under `/dev` that
/// looks like a serial device (`/dev/ttyUSB0`, `/dev/ttyACM0`, `/dev/cu.usbserial-1`,
/// `/dev/serial/by-id/…`, `/dev/pts/3`), even when it does not exist, so that a missing adapter
/// is reported as a missing port.
pub fn is_port(spec: &str) -> bool {
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

/// Opens `port` at `baud`, 8N1, no flow control, for exclusive use.
pub fn open(port: &str, baud: u32) -> Result<Box<dyn SerialPort>, PortError> {
    if cfg!(unix) {
        match std::fs::metadata(port) {
            Err(_) => return Err(no_such_port(port)),
            Ok(meta) if meta.is_file() || meta.is_dir() => {
                return Err(PortError::Other {
                    port: port.to_string(),
                    message: format!(
                        "it is a {}, not a serial port (to read a capture file, use `hwfoc \
                         decode {port}`)",
                        if meta.is_dir() { "directory" } else { "file" }
                    ),
                });
            }
            Ok(_) => {}
        }
    }
    serialport::new(port, baud)
        .data_bits(DataBits::Eight)
        .parity(Parity::None)
        .stop_bits(StopBits::One)
        .flow_control(FlowControl::None)
        .timeout(READ_TIMEOUT)
        .open()
        .map_err(|e| open_error(port, e))
}

fn no_such_port(port: &str) -> PortError {
    PortError::NoSuchPort {
        port: port.to_string(),
        available: available_ports(),
    }
}

/// The serial ports the system knows of, with the USB adapter's product name where known.
pub fn available_ports() -> Vec<String> {
    // The sysfs scan of `serialport` panics when /sys/class/tty is missing (some containers).
    if cfg!(target_os = "linux") && !Path::new("/sys/class/tty").is_dir() {
        return Vec::new();
    }
    let mut ports: Vec<String> = serialport::available_ports()
        .unwrap_or_default()
        .into_iter()
        .map(|p| match p.port_type {
            serialport::SerialPortType::UsbPort(usb) => match usb.product {
                Some(product) => format!("{} ({product})", p.port_name),
                None => format!("{} (USB {:04x}:{:04x})", p.port_name, usb.vid, usb.pid),
            },
            _ => p.port_name,
        })
        .collect();
    ports.sort();
    ports
}

fn open_error(port: &str, e: serialport::Error) -> PortError {
    use serialport::ErrorKind as K;
    match e.kind() {
        K::Io(io::ErrorKind::NotFound) => no_such_port(port),
        K::Io(io::ErrorKind::PermissionDenied) => PortError::Permission {
            port: port.to_string(),
            group: owner_group(port),
        },
        // EBUSY from TIOCEXCL, or the lock another program holds.
        K::NoDevice => PortError::Busy {
            port: port.to_string(),
        },
        _ => PortError::Other {
            port: port.to_string(),
            message: e.to_string(),
        },
    }
}

/// The name of the group owning the device file, if it can be found.
#[cfg(unix)]
fn owner_group(port: &str) -> Option<String> {
    use std::os::unix::fs::MetadataExt;
    let gid = std::fs::metadata(port).ok()?.gid();
    let group = nix::unistd::Group::from_gid(nix::unistd::Gid::from_raw(gid)).ok()??;
    Some(group.name)
}

#[cfg(not(unix))]
fn owner_group(_port: &str) -> Option<String> {
    None
}

/// What a port's reader thread reports.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PortEvent {
    /// Bytes received.
    Data {
        /// Index of the port in the set.
        port: usize,
        /// Unix time in nanoseconds of the first byte: the time the read returned less the
        /// wire time of the bytes after the first, never earlier than just after the previous
        /// chunk's last byte.
        t_ns: u64,
        /// The bytes.
        bytes: Vec<u8>,
    },
    /// The port failed mid-read (unplugged); the thread now tries to reopen it.
    Lost {
        /// Index of the port in the set.
        port: usize,
        /// Unix time in nanoseconds when the failure was seen.
        t_ns: u64,
        /// What the operating system said.
        reason: String,
    },
    /// A lost port was reopened.
    Back {
        /// Index of the port in the set.
        port: usize,
        /// Unix time in nanoseconds when it was reopened.
        t_ns: u64,
    },
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
    baud: u32,
    clock: ReceiveClock,
    stop: Arc<AtomicBool>,
    threads: Vec<JoinHandle<()>>,
}

impl Readers {
    /// Opens every port (all of them, before any reading starts, so that a bad name is
    /// reported at once) and starts their reader threads, which send `wrap(event)` on `tx`.
    pub fn start<M: Send + 'static>(
        names: &[String],
        baud: u32,
        tx: Sender<M>,
        wrap: fn(PortEvent) -> M,
    ) -> Result<Readers, PortError> {
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
        let ports = names
            .iter()
            .map(|name| open(name, baud))
            .collect::<Result<Vec<_>, _>>()?;
        let clock = ReceiveClock::new();
        let stop = Arc::new(AtomicBool::new(false));
        let threads = ports
            .into_iter()
            .enumerate()
            .map(|(index, port)| {
                let reader = PortReader {
                    index,
                    name: names[index].clone(),
                    baud,
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
    /// reported at once) and starts their reader threads.
    pub fn open(names: &[String], baud: u32) -> Result<PortSet, PortError> {
        let (tx, events) = mpsc::channel();
        let readers = Readers::start(names, baud, tx, |event| event)?;
        Ok(PortSet { readers, events })
    }

    /// The ports, in the order given.
    pub fn names(&self) -> &[String] {
        self.readers.names()
    }

    /// The baud rate of every port.
    pub fn baud(&self) -> u32 {
        self.readers.baud
    }

    /// The clock the events' times come from.
    pub fn clock(&self) -> ReceiveClock {
        self.readers.clock()
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

/// One port's reader thread.
struct PortReader<M> {
    index: usize,
    name: String,
    baud: u32,
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
        let _ = self.tx.send((self.wrap)(PortEvent::Data {
            port: self.index,
            t_ns,
            bytes: bytes.to_vec(),
        }));
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
    fn missing_port_is_named() {
        let e = open("/dev/ttyUSB_hwfoc_test_missing", 19200).err().unwrap();
        assert!(
            e.to_string()
                .starts_with("no such port /dev/ttyUSB_hwfoc_test_missing"),
            "{e}"
        );
    }

    #[test]
    fn clock_is_unix_time_and_monotonic() {
        let clock = ReceiveClock::new();
        let a = clock.now_ns();
        let b = clock.now_ns();
        assert!(b >= a);
        assert!(a > 1_600_000_000_000_000_000);
    }
}
