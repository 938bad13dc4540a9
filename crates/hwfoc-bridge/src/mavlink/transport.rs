//! Where the MAVLink frames go: a UDP socket of our own (non-blocking), a serial port (writes
//! with a timeout, reopened when it disappears) or a telemetry log file.

use std::fs::File;
use std::io::{self, Write};
use std::net::{Ipv4Addr, Ipv6Addr, SocketAddr, UdpSocket};
use std::time::Instant;

use crate::port::{Failure, PortOptions, ReopeningPort};

/// Why a frame was not written.
#[derive(Debug)]
pub(crate) enum LinkError {
    /// The write failed; the link stays (the next frame is tried).
    Send(String),
    /// The write failed and the rest of this poll's frames should not be tried (a full buffer, a
    /// serial write that timed out: each would wait or fail the same way).
    Stalled(String),
    /// The serial port is gone; it is reopened from a later poll.
    Lost(String),
    /// The serial port is still gone: nothing was written (already reported as lost).
    Down,
}

/// A UDP destination or a serial port.
pub(crate) enum Link {
    Udp {
        socket: UdpSocket,
        dest: SocketAddr,
        /// Whether `connect` succeeded (a connected socket hears ICMP errors: a refused port
        /// becomes `ECONNREFUSED` on a later send). Retried before each send until it does.
        connected: bool,
    },
    /// A serial port, reopened when lost.
    Serial(ReopeningPort),
    /// A telemetry log (`.tlog`): each frame after its time, microseconds since the Unix epoch
    /// as a 64-bit big-endian integer, as Mission Planner writes and reads them.
    Tlog {
        file: File,
        /// The time and the frame of one message, written by one call.
        record: Vec<u8>,
    },
}

impl Link {
    /// A non-blocking UDP socket sending to `dest`, bound to an ephemeral port of the
    /// unspecified address of `dest`'s family.
    pub(crate) fn udp(dest: SocketAddr) -> io::Result<Link> {
        let local: SocketAddr = if dest.is_ipv4() {
            (Ipv4Addr::UNSPECIFIED, 0).into()
        } else {
            (Ipv6Addr::UNSPECIFIED, 0).into()
        };
        let socket = UdpSocket::bind(local)?;
        socket.set_nonblocking(true)?;
        // A destination without a route fails here; the sends retry it.
        let connected = socket.connect(dest).is_ok();
        Ok(Link::Udp {
            socket,
            dest,
            connected,
        })
    }

    /// The serial port `port` at `baud` (8N1; `hwfoc_ports::serial::open`, whose timeout of 50 ms
    /// bounds each write).
    pub(crate) fn serial(port: &str, baud: u32) -> Result<Link, String> {
        Ok(Link::Serial(ReopeningPort::open(
            port,
            baud,
            PortOptions::default(),
        )?))
    }

    /// A new telemetry log at `path`; an existing file is replaced only if `overwrite`
    /// (`hwfoc_io::write::create_file`).
    pub(crate) fn tlog(path: &str, overwrite: bool) -> Result<Link, hwfoc_io::write::WriteError> {
        let file = hwfoc_io::write::create_file(path, overwrite)?;
        Ok(Link::Tlog {
            file,
            record: Vec::with_capacity(8 + 280),
        })
    }

    /// Writes one frame; `unix_usec` is its time (the time a telemetry log gives it).
    pub(crate) fn send(
        &mut self,
        frame: &[u8],
        now: Instant,
        unix_usec: u64,
    ) -> Result<(), LinkError> {
        match self {
            Link::Tlog { file, record } => {
                record.clear();
                record.extend_from_slice(&unix_usec.to_be_bytes());
                record.extend_from_slice(frame);
                file.write_all(record)
                    .map_err(|e| LinkError::Send(e.to_string()))
            }
            Link::Udp {
                socket,
                dest,
                connected,
            } => {
                if !*connected {
                    socket
                        .connect(*dest)
                        .map_err(|e| LinkError::Send(e.to_string()))?;
                    *connected = true;
                }
                match socket.send(frame) {
                    Ok(n) if n == frame.len() => Ok(()),
                    Ok(n) => Err(LinkError::Send(format!(
                        "short datagram ({n} of {} bytes)",
                        frame.len()
                    ))),
                    Err(e) if e.kind() == io::ErrorKind::WouldBlock => Err(LinkError::Stalled(
                        "the socket's send buffer is full".to_string(),
                    )),
                    Err(e) => Err(LinkError::Send(e.to_string())),
                }
            }
            Link::Serial(port) => port.write(frame, now).map_err(|failure| match failure {
                Failure::Stalled(reason) => LinkError::Stalled(reason),
                Failure::Lost(reason) => LinkError::Lost(reason),
                Failure::Down => LinkError::Down,
            }),
        }
    }

    /// Whether it is a telemetry log.
    pub(crate) fn is_log(&self) -> bool {
        matches!(self, Link::Tlog { .. })
    }

    /// The local address of a UDP link.
    pub(crate) fn local_addr(&self) -> Option<SocketAddr> {
        match self {
            Link::Udp { socket, .. } => socket.local_addr().ok(),
            Link::Serial(_) | Link::Tlog { .. } => None,
        }
    }
}
