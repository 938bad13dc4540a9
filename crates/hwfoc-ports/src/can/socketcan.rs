//! A raw SocketCAN socket (Linux): bound to an interface by name, classic frames in and out.
//!
//! Through `libc` directly: the `socketcan` crate (3.x) pulls in `nix`'s socket features,
//! `embedded-can` and `itertools` for the few calls this takes.

use std::io;
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::time::Duration;

use hwfoc::dronecan::{CanFrame, SOCKETCAN_RECORD_LEN};

use super::bus::CanError;

/// A raw CAN socket bound to one interface.
#[derive(Debug)]
pub(crate) struct Socket {
    fd: OwnedFd,
}

impl Socket {
    /// Opens a raw CAN socket on `interface`, error frames included.
    pub(crate) fn open(interface: &str) -> Result<Socket, CanError> {
        let bus = format!("can:{interface}");
        let name = std::ffi::CString::new(interface).map_err(|_| CanError::NoSuchInterface {
            interface: interface.to_string(),
        })?;
        // SAFETY: `name` is a NUL-terminated string.
        let index = unsafe { libc::if_nametoindex(name.as_ptr()) };
        if index == 0 {
            return Err(CanError::NoSuchInterface {
                interface: interface.to_string(),
            });
        }
        // SAFETY: plain system call; the descriptor is owned at once.
        let raw = unsafe { libc::socket(libc::PF_CAN, libc::SOCK_RAW, libc::CAN_RAW) };
        if raw < 0 {
            return Err(open_error(&bus, interface, io::Error::last_os_error()));
        }
        // SAFETY: `raw` is a descriptor just opened and owned by nothing else.
        let fd = unsafe { OwnedFd::from_raw_fd(raw) };
        let errors: libc::can_err_mask_t = libc::CAN_ERR_MASK;
        // SAFETY: the option's value is a `can_err_mask_t` of the size given.
        unsafe {
            libc::setsockopt(
                fd.as_raw_fd(),
                libc::SOL_CAN_RAW,
                libc::CAN_RAW_ERR_FILTER,
                (&raw const errors).cast(),
                size_of::<libc::can_err_mask_t>() as libc::socklen_t,
            )
        };
        // SAFETY: an all-zero sockaddr_can is valid; the fields set are plain integers.
        let mut addr: libc::sockaddr_can = unsafe { std::mem::zeroed() };
        addr.can_family = libc::AF_CAN as libc::sa_family_t;
        addr.can_ifindex = index as libc::c_int;
        // SAFETY: `addr` is a sockaddr_can of the size given.
        let bound = unsafe {
            libc::bind(
                fd.as_raw_fd(),
                (&raw const addr).cast(),
                size_of::<libc::sockaddr_can>() as libc::socklen_t,
            )
        };
        if bound < 0 {
            return Err(open_error(&bus, interface, io::Error::last_os_error()));
        }
        Ok(Socket { fd })
    }

    /// The next classic frame, waiting at most `timeout`; `None` if none came. (CAN FD
    /// frames are not received: the socket does not ask for them.)
    pub(crate) fn recv(&mut self, timeout: Duration) -> io::Result<Option<CanFrame>> {
        let mut poll = libc::pollfd {
            fd: self.fd.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        let ms = timeout.as_millis().min(i32::MAX as u128) as libc::c_int;
        // SAFETY: one pollfd.
        let n = unsafe { libc::poll(&mut poll, 1, ms) };
        if n < 0 {
            let e = io::Error::last_os_error();
            return if e.kind() == io::ErrorKind::Interrupted {
                Ok(None)
            } else {
                Err(e)
            };
        }
        if n == 0 {
            return Ok(None);
        }
        if poll.revents & (libc::POLLERR | libc::POLLHUP | libc::POLLNVAL) != 0
            && poll.revents & libc::POLLIN == 0
        {
            return Err(io::Error::other("the interface went down"));
        }
        let mut raw = [0u8; SOCKETCAN_RECORD_LEN];
        // SAFETY: reads at most `raw.len()` bytes into `raw`.
        let got = unsafe { libc::read(self.fd.as_raw_fd(), raw.as_mut_ptr().cast(), raw.len()) };
        if got < 0 {
            let e = io::Error::last_os_error();
            return match e.kind() {
                io::ErrorKind::Interrupted | io::ErrorKind::WouldBlock => Ok(None),
                _ => Err(e),
            };
        }
        if got as usize != SOCKETCAN_RECORD_LEN {
            return Ok(None);
        }
        // `struct can_frame`: can_id in the host's byte order, then the length.
        let can_id = u32::from_ne_bytes([raw[0], raw[1], raw[2], raw[3]]);
        let len = usize::from(raw[4]).min(8);
        Ok(CanFrame::from_socketcan(can_id, &raw[8..8 + len]))
    }

    /// Sends `frame`.
    pub(crate) fn send(&mut self, frame: &CanFrame) -> io::Result<()> {
        let mut raw = frame.to_socketcan_record();
        raw[..4].copy_from_slice(&frame.socketcan_id().to_ne_bytes());
        // SAFETY: writes `raw.len()` bytes of `raw`.
        let n = unsafe { libc::write(self.fd.as_raw_fd(), raw.as_ptr().cast(), raw.len()) };
        if n < 0 {
            return Err(io::Error::last_os_error());
        }
        Ok(())
    }
}

fn open_error(bus: &str, interface: &str, e: io::Error) -> CanError {
    match e.raw_os_error() {
        Some(libc::EACCES | libc::EPERM) => CanError::Permission {
            bus: bus.to_string(),
        },
        // Binding a CAN socket to an interface of another kind.
        Some(libc::EINVAL | libc::ENODEV | libc::EAFNOSUPPORT | libc::EPROTONOSUPPORT) => {
            CanError::NotCan {
                interface: interface.to_string(),
            }
        }
        _ => CanError::Lost {
            bus: bus.to_string(),
            reason: e.to_string(),
        },
    }
}
