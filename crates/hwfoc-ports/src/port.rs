//! One serial port opened ([`open`]: 8N1, no flow control, for exclusive use), why it could not
//! be ([`PortError`], naming the port and what to do), and the ports there are
//! ([`available_ports`]). Beneath both the port set ([`crate::serial`]) and the CAN buses on an
//! SLCAN adapter ([`crate::can`]), which depend on it and not on each other's modules.

use std::io;
use std::path::Path;
use std::time::Duration;

pub use hwfoc_records::serial::PortError;
use serialport::{DataBits, FlowControl, Parity, SerialPort, StopBits};

/// How long a read waits for bytes before the thread checks whether it should stop.
pub(crate) const READ_TIMEOUT: Duration = Duration::from_millis(50);

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_port_is_named() {
        let e = open("/dev/ttyUSB_hwfoc_test_missing", 19200).err().unwrap();
        assert!(
            e.to_string()
                .starts_with("no such port /dev/ttyUSB_hwfoc_test_missing"),
            "{e}"
        );
    }
}
