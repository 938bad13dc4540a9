//! Live CAN buses: an SLCAN adapter on a serial port (`slcan:PORT[:BITRATE]`) or, on Linux, a
//! SocketCAN interface (`can:IFACE`), opened as a [`CanBus`] that receives and sends frames.

use std::collections::VecDeque;
use std::fmt;
use std::io::{self, Read, Write};
use std::time::{Duration, Instant};

use hwfoc::dronecan::CanFrame;
use serialport::SerialPort;

use super::ask::{AskIds, DEFAULT_SOURCE_NODE};
use super::slcan::{self, Event, Parser};
use crate::clock::ReceiveClock;
use crate::port::PortError;
pub use hwfoc_records::can::{DEFAULT_BITRATE, is_can_spec};

/// The serial speed an SLCAN adapter is opened at (USB CDC adapters ignore it).
pub const SLCAN_BAUD: u32 = 115_200;
/// How long an adapter is given to answer a setup command.
const ANSWER_WITHIN: Duration = Duration::from_millis(300);

/// Why a CAN bus could not be opened or read. Each names the bus as given.
#[derive(Debug)]
pub enum CanError {
    /// The spec is not `slcan:PORT[:BITRATE]` or `can:IFACE`.
    Spec {
        /// The bus as given.
        bus: String,
        /// What is wrong.
        reason: String,
    },
    /// The adapter's serial port could not be opened.
    Port(PortError),
    /// No network interface of that name.
    NoSuchInterface {
        /// The interface.
        interface: String,
    },
    /// The interface is not a CAN interface.
    NotCan {
        /// The interface.
        interface: String,
    },
    /// The system refused access.
    Permission {
        /// The bus as given.
        bus: String,
    },
    /// The SLCAN adapter refused the bit rate.
    BitrateRefused {
        /// The bus as given.
        bus: String,
        /// The bit rate, bit/s.
        bitrate: u32,
    },
    /// SocketCAN is Linux's.
    Unsupported {
        /// The bus as given.
        bus: String,
    },
    /// Reading or writing failed (the adapter unplugged, the interface down).
    Lost {
        /// The bus as given.
        bus: String,
        /// What the system said.
        reason: String,
    },
}

impl fmt::Display for CanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CanError::Spec { bus, reason } => write!(f, "{bus}: {reason}"),
            CanError::Port(e) => e.fmt(f),
            CanError::NoSuchInterface { interface } => write!(
                f,
                "can:{interface}: no such network interface (`ip link` lists them)"
            ),
            CanError::NotCan { interface } => {
                write!(f, "can:{interface}: not a CAN interface")
            }
            CanError::Permission { bus } => {
                write!(f, "{bus}: permission denied")
            }
            CanError::BitrateRefused { bus, bitrate } => {
                write!(f, "{bus}: the adapter refused the bit rate {bitrate} bit/s")
            }
            CanError::Unsupported { bus } => {
                write!(f, "{bus}: SocketCAN interfaces are read on Linux only")
            }
            CanError::Lost { bus, reason } => write!(f, "{bus}: lost ({reason})"),
        }
    }
}

impl std::error::Error for CanError {}

impl CanError {
    /// The error as a port's that could not be opened ([`PortError`]), for a bus opened among
    /// serial ports (the port set of `serial.rs`).
    pub fn into_port_error(self) -> PortError {
        let other = |port: String, message: &str| PortError::Other {
            port,
            message: message.to_string(),
        };
        match self {
            CanError::Port(e) => e,
            CanError::Permission { bus } => PortError::Permission {
                port: bus,
                group: None,
            },
            CanError::Spec { bus, reason } => other(bus, &reason),
            CanError::NoSuchInterface { interface } => other(
                format!("can:{interface}"),
                "no such network interface (`ip link` lists them)",
            ),
            CanError::NotCan { interface } => {
                other(format!("can:{interface}"), "not a CAN interface")
            }
            CanError::BitrateRefused { bus, bitrate } => other(
                bus,
                &format!("the adapter refused the bit rate {bitrate} bit/s"),
            ),
            CanError::Unsupported { bus } => {
                other(bus, "SocketCAN interfaces are read on Linux only")
            }
            CanError::Lost { bus, reason } => other(bus, &reason),
        }
    }
}

/// A parsed bus spec.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CanSpec {
    /// An SLCAN adapter: its serial port and the bus's bit rate.
    Slcan {
        /// The serial port.
        port: String,
        /// The bit rate, bit/s (one of [`slcan::BITRATES`]).
        bitrate: u32,
    },
    /// A SocketCAN interface.
    SocketCan {
        /// The interface (`can0`, `vcan0`).
        interface: String,
    },
}

/// The longest network interface name plus its NUL: Linux's `IFNAMSIZ` (SocketCAN is
/// Linux's; elsewhere `can:` names are checked alike, then refused when opened).
#[cfg(target_os = "linux")]
const IFNAMSIZ: usize = libc::IFNAMSIZ;
#[cfg(not(target_os = "linux"))]
const IFNAMSIZ: usize = 16;

impl CanSpec {
    /// Parses `slcan:PORT[:BITRATE]` (BITRATE in bit/s, or with `k` or `M`: `500k`, `1M`;
    /// default [`DEFAULT_BITRATE`]) or `can:IFACE`.
    pub fn parse(spec: &str) -> Result<CanSpec, CanError> {
        let err = |reason: String| CanError::Spec {
            bus: spec.to_string(),
            reason,
        };
        if let Some(interface) = spec.strip_prefix("can:") {
            if interface.is_empty() || interface.len() >= IFNAMSIZ || interface.contains('\0') {
                return Err(err("expected can:IFACE, a network interface name".into()));
            }
            return Ok(CanSpec::SocketCan {
                interface: interface.to_string(),
            });
        }
        let rest = spec
            .strip_prefix("slcan:")
            .ok_or_else(|| err("expected slcan:PORT[:BITRATE] or can:IFACE".into()))?;
        let (port, bitrate) = match rest.rsplit_once(':') {
            Some((port, b)) if b.chars().next().is_some_and(|c| c.is_ascii_digit()) => {
                (port, parse_bitrate(b).map_err(err)?)
            }
            _ => (rest, DEFAULT_BITRATE),
        };
        if port.is_empty() {
            return Err(err("no port: expected slcan:PORT[:BITRATE]".into()));
        }
        Ok(CanSpec::Slcan {
            port: port.to_string(),
            bitrate,
        })
    }
}

/// A bit rate SLCAN has a code for, from `500000`, `500k` or `1M`.
fn parse_bitrate(text: &str) -> Result<u32, String> {
    let (digits, unit) = match text.as_bytes().last() {
        Some(b'k' | b'K') => (&text[..text.len() - 1], 1_000),
        Some(b'M' | b'm') => (&text[..text.len() - 1], 1_000_000),
        _ => (text, 1),
    };
    let supported = slcan::BITRATES.map(|b| b.to_string()).join(", ");
    digits
        .parse::<u32>()
        .ok()
        .and_then(|n| n.checked_mul(unit))
        .filter(|&b| slcan::bitrate_code(b).is_some())
        .ok_or_else(|| format!("bad CAN bit rate {text:?}: SLCAN takes {supported} bit/s"))
}

/// An open CAN bus.
pub struct CanBus {
    name: String,
    link: Link,
    bitrate: Option<u32>,
    asker: Option<AskIds>,
    /// When the bus was opened: the start of the asker's clock.
    opened: Instant,
    clock: ReceiveClock,
}

enum Link {
    Slcan {
        port: Box<dyn SerialPort>,
        parser: Parser,
        queue: VecDeque<CanFrame>,
        buf: Vec<u8>,
    },
    #[cfg(target_os = "linux")]
    Socket(super::socketcan::Socket),
}

impl fmt::Debug for CanBus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "CanBus({})", self.name)
    }
}

impl CanBus {
    /// Opens the bus `spec` names (`slcan:PORT[:BITRATE]`: the adapter's serial port at
    /// [`SLCAN_BAUD`], closed, set to the bit rate and opened; `can:IFACE`: a raw SocketCAN
    /// socket bound to the interface). With `ask_ids`, [`CanBus::recv`] also sends the ESCs'
    /// id request when due ([`AskIds`], from node [`DEFAULT_SOURCE_NODE`]).
    pub fn open(spec: &str, ask_ids: bool) -> Result<CanBus, CanError> {
        CanBus::open_with_clock(spec, ask_ids, ReceiveClock::new())
    }

    /// [`CanBus::open`] with the receive times taken from `clock` (a port set's).
    pub(crate) fn open_with_clock(
        spec: &str,
        ask_ids: bool,
        clock: ReceiveClock,
    ) -> Result<CanBus, CanError> {
        let (link, bitrate) = match CanSpec::parse(spec)? {
            CanSpec::Slcan { port, bitrate } => (open_slcan(spec, &port, bitrate)?, Some(bitrate)),
            #[cfg(target_os = "linux")]
            CanSpec::SocketCan { interface } => (
                Link::Socket(super::socketcan::Socket::open(&interface)?),
                None,
            ),
            #[cfg(not(target_os = "linux"))]
            CanSpec::SocketCan { .. } => {
                return Err(CanError::Unsupported {
                    bus: spec.to_string(),
                });
            }
        };
        Ok(CanBus {
            name: spec.to_string(),
            link,
            bitrate,
            asker: ask_ids.then(|| AskIds::new(DEFAULT_SOURCE_NODE)),
            opened: Instant::now(),
            clock,
        })
    }

    /// The bus as given.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The bit rate where known (an SLCAN adapter's, as set).
    pub fn bitrate(&self) -> Option<u32> {
        self.bitrate
    }

    /// The next frame the bus carried, with its receive time (Unix seconds), waiting at most
    /// `timeout`; `None` if none came. Sends the ESCs' id request first when it is due.
    pub fn recv(&mut self, timeout: Duration) -> Result<Option<(f64, CanFrame)>, CanError> {
        if let Some(frames) = self
            .asker
            .as_mut()
            .and_then(|a| a.due(self.opened.elapsed()))
        {
            for frame in frames {
                self.send(&frame)?;
            }
        }
        let got = self.recv_frame(timeout)?;
        if let (Some((_, frame)), Some(asker)) = (&got, &mut self.asker) {
            asker.heard(frame);
        }
        Ok(got)
    }

    fn recv_frame(&mut self, timeout: Duration) -> Result<Option<(f64, CanFrame)>, CanError> {
        let lost = |bus: &str, e: io::Error| CanError::Lost {
            bus: bus.to_string(),
            reason: e.to_string(),
        };
        match &mut self.link {
            Link::Slcan {
                port,
                parser,
                queue,
                buf,
            } => {
                if queue.is_empty() {
                    let _ = port.set_timeout(timeout);
                    match port.read(buf) {
                        Ok(0) => {
                            return Err(CanError::Lost {
                                bus: self.name.clone(),
                                reason: "the device reported end of file".into(),
                            });
                        }
                        Ok(n) => parser.push(&buf[..n], |e| {
                            if let Event::Frame(f, _) = e {
                                queue.push_back(f);
                            }
                        }),
                        Err(e) if is_timeout(&e) => {}
                        Err(e) => return Err(lost(&self.name, e)),
                    }
                }
                // The adapter's millisecond timestamps wrap every minute: the time of the read
                // is the frame's.
                let t = self.clock.now_ns() as f64 * 1e-9;
                Ok(queue.pop_front().map(|f| (t, f)))
            }
            #[cfg(target_os = "linux")]
            Link::Socket(socket) => {
                let got = socket.recv(timeout).map_err(|e| lost(&self.name, e))?;
                Ok(got.map(|f| (self.clock.now_ns() as f64 * 1e-9, f)))
            }
        }
    }

    /// Sends `frame` (an error frame cannot be sent: ignored).
    pub fn send(&mut self, frame: &CanFrame) -> Result<(), CanError> {
        let result = match &mut self.link {
            Link::Slcan { port, .. } => {
                let mut out = Vec::with_capacity(32);
                if !slcan::push_frame(&mut out, frame) {
                    return Ok(());
                }
                port.write_all(&out).and_then(|()| port.flush())
            }
            #[cfg(target_os = "linux")]
            Link::Socket(socket) => socket.send(frame),
        };
        result.map_err(|e| CanError::Lost {
            bus: self.name.clone(),
            reason: e.to_string(),
        })
    }
}

fn is_timeout(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}

/// Opens an SLCAN adapter and sets it up: an empty command and `C` (their answers ignored: a
/// closed channel refuses `C`), `S<code>` (a refusal is an error), `O`.
fn open_slcan(spec: &str, port: &str, bitrate: u32) -> Result<Link, CanError> {
    let code = slcan::bitrate_code(bitrate).ok_or_else(|| CanError::Spec {
        bus: spec.to_string(),
        reason: format!("no SLCAN code for {bitrate} bit/s"),
    })?;
    let mut serial = crate::port::open(port, SLCAN_BAUD).map_err(|e| match e {
        PortError::Permission { .. } => CanError::Permission {
            bus: spec.to_string(),
        },
        e => CanError::Port(e),
    })?;
    let lost = |e: io::Error| CanError::Lost {
        bus: spec.to_string(),
        reason: e.to_string(),
    };
    let mut parser = Parser::new();
    serial.write_all(b"\rC\r").map_err(lost)?;
    answers(&mut *serial, &mut parser, 2, ANSWER_WITHIN);
    serial
        .write_all(format!("S{code}\r").as_bytes())
        .map_err(lost)?;
    if answers(&mut *serial, &mut parser, 1, ANSWER_WITHIN).contains(&Event::Refused) {
        return Err(CanError::BitrateRefused {
            bus: spec.to_string(),
            bitrate,
        });
    }
    serial.write_all(b"O\r").map_err(lost)?;
    Ok(Link::Slcan {
        port: serial,
        parser,
        queue: VecDeque::new(),
        buf: vec![0; 4096],
    })
}

/// Reads the adapter's answers until `n` acks or refusals came or `within` passed. (An adapter
/// that does not answer is not held against it: a pseudo-terminal in tests, some clones.)
fn answers(
    port: &mut dyn SerialPort,
    parser: &mut Parser,
    n: usize,
    within: Duration,
) -> Vec<Event> {
    let until = Instant::now() + within;
    let mut got = Vec::new();
    let mut buf = [0u8; 256];
    while got.len() < n {
        let left = until.saturating_duration_since(Instant::now());
        if left.is_zero() {
            break;
        }
        let _ = port.set_timeout(left);
        match port.read(&mut buf) {
            Ok(k) if k > 0 => parser.push(&buf[..k], |e| {
                if matches!(e, Event::Ack | Event::Refused) {
                    got.push(e);
                }
            }),
            _ => break,
        }
    }
    got
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs() {
        assert!(is_can_spec("slcan:/dev/ttyACM0") && is_can_spec("can:vcan0"));
        assert!(!is_can_spec("/dev/ttyUSB0") && !is_can_spec("run.pcapng"));
        assert_eq!(
            CanSpec::parse("slcan:/dev/ttyACM0").unwrap(),
            CanSpec::Slcan {
                port: "/dev/ttyACM0".into(),
                bitrate: 500_000
            }
        );
        assert_eq!(
            CanSpec::parse("slcan:COM5:1M").unwrap(),
            CanSpec::Slcan {
                port: "COM5".into(),
                bitrate: 1_000_000
            }
        );
        assert_eq!(
            CanSpec::parse("can:vcan0").unwrap(),
            CanSpec::SocketCan {
                interface: "vcan0".into()
            }
        );
        let e = CanSpec::parse("slcan:/dev/x:333333")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("slcan:/dev/x:333333: bad CAN bit rate"),
            "{e}"
        );
        assert!(CanSpec::parse("slcan:").is_err() && CanSpec::parse("can:").is_err());
        assert!(CanSpec::parse("can:averyveryverylongname").is_err());
    }

    #[test]
    fn errors_name_the_bus() {
        let e = CanBus::open("slcan:/dev/ttyNOSUCH9", false).unwrap_err();
        assert!(e.to_string().contains("/dev/ttyNOSUCH9"), "{e}");
        #[cfg(target_os = "linux")]
        {
            let e = CanBus::open("can:nosuch9", false).unwrap_err();
            assert_eq!(
                e.to_string(),
                "can:nosuch9: no such network interface (`ip link` lists them)"
            );
            let e = CanBus::open("can:lo", false).unwrap_err();
            assert!(
                matches!(&e, CanError::NotCan { .. } | CanError::Permission { .. }),
                "{e}"
            );
        }
    }
}
