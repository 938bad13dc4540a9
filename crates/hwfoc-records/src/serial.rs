//! What serial ports hand over, as plain data (reading them is `hwfoc-io`'s): the events
//! of a port set ([`PortEvent`]), the rates and retry time they are read with, and why a port
//! could not be opened ([`PortError`]).

use std::fmt;
use std::time::Duration;

use hwfoc::Protocol;

/// The HW-FOC telemetry rate, the default of every serial input.
pub const DEFAULT_BAUD: u32 = hwfoc::foc::BAUD_RATE;

/// How often a lost port is tried again.
pub const RETRY_EVERY: Duration = Duration::from_millis(500);

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
    /// Auto-baud (`hwfoc-io`'s `Baud::Auto`): the port is now read at `baud`, the next rate tried. The
    /// bytes read at the rate before gave no frame and were not handed on.
    Searching {
        /// Index of the port in the set.
        port: usize,
        /// Unix time in nanoseconds of the change.
        t_ns: u64,
        /// The rate now tried.
        baud: u32,
        /// How many bytes the rate before gave (read at a wrong rate: not the wire's bytes).
        discarded: u64,
    },
    /// Auto-baud (`hwfoc-io`'s `Baud::Auto`): the bytes read at `baud` gave frames of `protocol`, and the
    /// port stays at that rate. The bytes read at it since it was tried follow as
    /// [`PortEvent::Data`] (with their own times), then every later byte.
    Found {
        /// Index of the port in the set.
        port: usize,
        /// Unix time in nanoseconds of the lock.
        t_ns: u64,
        /// The port's rate.
        baud: u32,
        /// The protocol of the first frame found.
        protocol: Protocol,
    },
}

impl PortEvent {
    /// The index of the port that reported it.
    pub fn port(&self) -> usize {
        match self {
            PortEvent::Data { port, .. }
            | PortEvent::Lost { port, .. }
            | PortEvent::Back { port, .. }
            | PortEvent::Searching { port, .. }
            | PortEvent::Found { port, .. } => *port,
        }
    }
}

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
