//! A serial port an output writes to, reopened when it is lost: the one reopening writer of
//! every bridge output on a serial line (DataLink, MAVLink, the DroneCAN adapter).
//!
//! A write that fails because the port is gone (USB unplugged: `EIO`, a hang-up) loses the
//! port ([`Failure::Lost`], worded by [`Failure::error`] as [`OutputError::Lost`]); later writes
//! try to open the same path again as [`Retry`] says, quietly ([`Failure::Down`]: the loss was
//! reported once), and set it up again with the output's hook (the SLCAN adapter's commands). A
//! write that times out or would block ([`Failure::Stalled`]) keeps the port: the other end is
//! there but not taking bytes.

use std::io::{self, Write};
use std::time::{Duration, Instant};

use serialport::SerialPort;

use crate::output::OutputError;

/// Sets a freshly opened port up (after the first opening and after each reopening).
pub type Setup = Box<dyn Fn(&mut dyn SerialPort) -> Result<(), String> + Send>;

/// How an output uses its port.
#[derive(Default)]
pub struct PortOptions {
    /// Run on every port opened, before any write.
    pub setup: Option<Setup>,
    /// Whether each write waits until its bytes are on the line (`tcdrain`): an output pacing
    /// its frames by time (DataLink) or its commands (SLCAN) needs it; an output writing
    /// message after message does not.
    pub drain: bool,
}

/// When a lost port is tried again: [`Retry::FIRST`] after the loss, then twice as long after
/// each failed attempt, up to [`Retry::MAX`].
///
/// Why this policy: a port that comes straight back (an adapter resetting, a pty reopened)
/// is back within a quarter of a second; one unplugged for longer costs at most one failed
/// opening a second, and is back at most a second after it is plugged in again, the pace of
/// the DataLink receiver's own one-second timeout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Retry {
    /// When the next attempt is due.
    at: Instant,
    /// The wait after the next failed attempt, before doubling.
    wait: Duration,
}

impl Retry {
    /// The wait from a loss to the first attempt.
    pub const FIRST: Duration = Duration::from_millis(250);
    /// The longest wait between two attempts.
    pub const MAX: Duration = Duration::from_secs(1);

    /// The port was lost at `now`: the first attempt is [`Retry::FIRST`] later.
    pub fn lost(now: Instant) -> Retry {
        Retry {
            at: now + Retry::FIRST,
            wait: Retry::FIRST,
        }
    }

    /// Whether an attempt is due at `now`.
    pub fn due(&self, now: Instant) -> bool {
        now >= self.at
    }

    /// An attempt at `now` failed: the next one waits twice as long as the last, at most
    /// [`Retry::MAX`].
    pub fn failed(&mut self, now: Instant) {
        self.wait = (self.wait * 2).min(Retry::MAX);
        self.at = now + self.wait;
    }
}

/// Why a write did not get out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Failure {
    /// The port did not take the bytes in time (or would block): it is kept, and the next
    /// write is tried.
    Stalled(String),
    /// The port is gone (what the operating system said): it is reopened by a later write.
    Lost(String),
    /// The port is still away: nothing was written (its loss was already reported).
    Down,
}

impl Failure {
    /// The output's error for this failure (`output` its name): [`OutputError::Send`] for a
    /// stalled port, [`OutputError::Lost`] for a lost one, none while it is away.
    pub fn error(&self, output: &str) -> Option<OutputError> {
        match self {
            Failure::Stalled(reason) => Some(OutputError::Send {
                output: output.to_string(),
                reason: reason.clone(),
            }),
            Failure::Lost(reason) => Some(OutputError::Lost {
                output: output.to_string(),
                reason: reason.clone(),
            }),
            Failure::Down => None,
        }
    }
}

/// A serial port at a path, written to and reopened when lost (see the [module
/// documentation](self)).
pub struct ReopeningPort {
    path: String,
    baud: u32,
    options: PortOptions,
    port: Option<Box<dyn SerialPort>>,
    /// While the port is away: when it is tried again.
    retry: Retry,
    losses: u64,
    reopens: u64,
}

impl std::fmt::Debug for ReopeningPort {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ReopeningPort")
            .field("path", &self.path)
            .field("baud", &self.baud)
            .field("open", &self.port.is_some())
            .field("losses", &self.losses)
            .field("reopens", &self.reopens)
            .finish_non_exhaustive()
    }
}

impl ReopeningPort {
    /// Opens `path` at `baud` (8N1, [`hwfoc_ports::serial::open`], whose timeout bounds each
    /// write) and sets it up as `options` say; the error says why it cannot be used now.
    pub fn open(path: &str, baud: u32, options: PortOptions) -> Result<ReopeningPort, String> {
        let port = open_set_up(path, baud, options.setup.as_ref())?;
        Ok(ReopeningPort {
            path: path.to_string(),
            baud,
            options,
            port: Some(port),
            retry: Retry::lost(Instant::now()),
            losses: 0,
            reopens: 0,
        })
    }

    /// The path as given.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// Whether the port is open now (false between a loss and its reopening).
    pub fn is_open(&self) -> bool {
        self.port.is_some()
    }

    /// How many times the port was lost.
    pub fn losses(&self) -> u64 {
        self.losses
    }

    /// How many times a lost port was opened again.
    pub fn reopens(&self) -> u64 {
        self.reopens
    }

    /// The open port, to read what the other end answered.
    pub fn port(&mut self) -> Option<&mut (dyn SerialPort + 'static)> {
        self.port.as_deref_mut()
    }

    /// If the port is away and an attempt is due at `now`, tries to open it again (and set it
    /// up); true if it was reopened by this call.
    pub fn reopen_if_due(&mut self, now: Instant) -> bool {
        if self.port.is_some() || !self.retry.due(now) {
            return false;
        }
        match open_set_up(&self.path, self.baud, self.options.setup.as_ref()) {
            Ok(port) => {
                self.port = Some(port);
                self.reopens += 1;
                true
            }
            Err(_) => {
                self.retry.failed(now);
                false
            }
        }
    }

    /// Writes all of `bytes` (and waits until they are on the line if the options say
    /// [`drain`](PortOptions::drain)), reopening the port first if it is away and an attempt is
    /// due at `now`.
    pub fn write(&mut self, bytes: &[u8], now: Instant) -> Result<(), Failure> {
        self.reopen_if_due(now);
        let Some(port) = self.port.as_mut() else {
            return Err(Failure::Down);
        };
        let drain = self.options.drain;
        let written = port
            .write_all(bytes)
            .and_then(|()| if drain { port.flush() } else { Ok(()) });
        match written {
            Ok(()) => Ok(()),
            Err(e) if e.kind() == io::ErrorKind::TimedOut => Err(Failure::Stalled(
                "write timed out (is the other end reading?)".to_string(),
            )),
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
                ) =>
            {
                Err(Failure::Stalled(e.to_string()))
            }
            Err(e) => {
                self.port = None;
                self.losses += 1;
                self.retry = Retry::lost(now);
                Err(Failure::Lost(e.to_string()))
            }
        }
    }
}

/// Opens `path` at `baud` and runs `setup` on it.
fn open_set_up(
    path: &str,
    baud: u32,
    setup: Option<&Setup>,
) -> Result<Box<dyn SerialPort>, String> {
    let mut port = hwfoc_ports::serial::open(path, baud).map_err(|e| e.to_string())?;
    if let Some(setup) = setup {
        setup(port.as_mut())?;
    }
    Ok(port)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lost_port_is_tried_after_a_quarter_second_then_doubling_to_a_second() {
        let t0 = Instant::now();
        let mut retry = Retry::lost(t0);
        assert!(!retry.due(t0));
        assert!(!retry.due(t0 + Duration::from_millis(249)));
        assert!(retry.due(t0 + Duration::from_millis(250)));
        // Each failure waits twice as long as the one before, never more than a second.
        let mut now = t0 + Duration::from_millis(250);
        let mut waits = Vec::new();
        for _ in 0..5 {
            retry.failed(now);
            let mut wait = Duration::ZERO;
            while !retry.due(now + wait) {
                wait += Duration::from_millis(1);
            }
            waits.push(wait.as_millis());
            now += wait;
        }
        assert_eq!(waits, [500, 1000, 1000, 1000, 1000]);
        // A new loss starts again at a quarter second.
        let again = Retry::lost(now);
        assert!(!again.due(now + Duration::from_millis(249)));
        assert!(again.due(now + Duration::from_millis(250)));
    }

    #[test]
    fn the_failures_are_worded_as_the_outputs_errors() {
        let lost = Failure::Lost("Input/output error".into()).error("datalink /dev/x");
        assert_eq!(
            lost.unwrap().to_string(),
            "datalink /dev/x: lost (Input/output error); reopening"
        );
        assert!(matches!(
            Failure::Stalled("slow".into()).error("x"),
            Some(OutputError::Send { .. })
        ));
        assert!(Failure::Down.error("x").is_none());
    }

    /// A pty behind a symlink stands in for a USB adapter unplugged and plugged in again.
    #[cfg(unix)]
    #[test]
    fn a_lost_port_is_reopened_at_its_path_as_the_policy_says_and_set_up_again() {
        use std::sync::Arc;
        use std::sync::atomic::{AtomicU32, Ordering};

        use hwfoc_sim::pty::RawPair;

        let dir = tempfile::tempdir().unwrap();
        let link = dir.path().join("port");
        let first = RawPair::open().unwrap();
        std::os::unix::fs::symlink(&first.path, &link).unwrap();
        let setups = Arc::new(AtomicU32::new(0));
        let counted = Arc::clone(&setups);
        let options = PortOptions {
            setup: Some(Box::new(move |_| {
                counted.fetch_add(1, Ordering::Relaxed);
                Ok(())
            })),
            drain: false,
        };
        let mut port = ReopeningPort::open(link.to_str().unwrap(), 115_200, options).unwrap();
        assert_eq!(setups.load(Ordering::Relaxed), 1);
        let t0 = Instant::now();
        port.write(b"x", t0).unwrap();
        // Unplugged: the kernel hangs the port up a moment after the other side closes.
        drop(first);
        let mut lost = None;
        for _ in 0..100 {
            match port.write(b"x", t0) {
                Err(Failure::Lost(reason)) => {
                    lost = Some(reason);
                    break;
                }
                Ok(()) => std::thread::sleep(Duration::from_millis(10)),
                Err(other) => panic!("{other:?}"),
            }
        }
        assert!(lost.is_some(), "the loss was never noticed");
        assert!(!port.is_open());
        assert_eq!(port.losses(), 1);
        let ms = |n: u64| t0 + Duration::from_millis(n);
        // Away: no attempt before a quarter second; the attempt then finds nothing there.
        assert_eq!(port.write(b"x", ms(249)), Err(Failure::Down));
        assert_eq!(port.write(b"x", ms(250)), Err(Failure::Down));
        // Plugged in again: found at the next attempt, half a second after the failed one.
        let second = RawPair::open().unwrap();
        std::fs::remove_file(&link).unwrap();
        std::os::unix::fs::symlink(&second.path, &link).unwrap();
        assert_eq!(port.write(b"x", ms(749)), Err(Failure::Down));
        assert_eq!(port.reopens(), 0);
        assert_eq!(port.write(b"x", ms(750)), Ok(()));
        assert!(port.is_open());
        assert_eq!(port.reopens(), 1);
        assert_eq!(setups.load(Ordering::Relaxed), 2);
    }

    #[test]
    fn a_port_that_does_not_exist_is_not_opened() {
        let err =
            ReopeningPort::open("/dev/ttyNOPE-hwfoc", 115_200, PortOptions::default()).unwrap_err();
        assert!(err.contains("/dev/ttyNOPE-hwfoc"), "{err}");
    }
}
