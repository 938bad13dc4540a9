//! Live serial ports as an input.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use hwfoc_records::clock::byte_times;
use hwfoc_records::{InputError, InputFormat, Looks, Notice, Source};

use crate::serial::{PortEvent, PortSet};

/// How long a serial input waits for bytes before checking for Ctrl-C.
const PORT_POLL: Duration = Duration::from_millis(100);

/// Live serial ports.
pub struct Ports {
    set: PortSet,
    /// Each port's byte time, ns: of the rate given, or found ([`PortEvent::Found`]).
    per_byte_ns: Vec<f64>,
    /// Set by the caller (the `hwfoc` command on Ctrl-C or SIGTERM): the input ends.
    interrupted: Arc<AtomicBool>,
}

impl Ports {
    /// Reads `set` until `interrupted` is set.
    pub fn new(set: PortSet, interrupted: Arc<AtomicBool>) -> Ports {
        let per_byte = hwfoc::wire::byte_ns(set.baud().initial());
        Ports {
            // A CAN bus's bytes all have their frame's time.
            per_byte_ns: (0..set.names().len())
                .map(|i| if set.is_can(i) { 0.0 } else { per_byte })
                .collect(),
            set,
            interrupted,
        }
    }

    /// The ports' names, in order.
    pub(super) fn names(&self) -> &[String] {
        self.set.names()
    }

    /// Waits for the next chunk of bytes and puts it, with its receive times, in `bytes` and
    /// `times`; returns its port. Returns with nothing once interrupted. Ports that are lost,
    /// come back or find their rate are told to `notices`.
    pub(super) fn read(
        &mut self,
        bytes: &mut Vec<u8>,
        times: &mut Vec<f64>,
        notices: &mut dyn FnMut(Notice),
    ) -> usize {
        while !self.interrupted.load(Ordering::Relaxed) {
            match self.set.next_event(PORT_POLL) {
                Some(PortEvent::Data {
                    port,
                    t_ns,
                    bytes: data,
                }) => {
                    byte_times(t_ns, self.per_byte_ns[port], data.len(), times);
                    bytes.extend_from_slice(&data);
                    return port;
                }
                Some(event) => {
                    if let PortEvent::Found { port, baud, .. } = event
                        && let Some(per_byte) = self.per_byte_ns.get_mut(port)
                    {
                        *per_byte = hwfoc::wire::byte_ns(baud);
                    }
                    if let Some(notice) = Notice::of_port_event(&event, self.set.names()) {
                        notices(notice);
                    }
                }
                None => {}
            }
        }
        0
    }
}

impl Source for Ports {
    fn format(&self) -> InputFormat {
        InputFormat::SERIAL
    }

    fn fill(
        &mut self,
        _name: &str,
        bytes: &mut Vec<u8>,
        times: &mut Vec<f64>,
        notices: &mut dyn FnMut(Notice),
    ) -> Result<usize, InputError> {
        bytes.clear();
        Ok(self.read(bytes, times, notices))
    }

    fn streams(&self) -> usize {
        self.names().len()
    }

    fn stream_name(&self, i: usize) -> Option<&str> {
        self.names().get(i).map(String::as_str)
    }

    fn is_can(&self, stream: usize) -> bool {
        self.set.is_can(stream)
    }

    fn flagged_bytes(&self) -> u64 {
        // A UART's parity and framing errors do not reach the bytes read.
        0
    }

    fn looks(&self) -> Option<Looks> {
        None
    }
}
