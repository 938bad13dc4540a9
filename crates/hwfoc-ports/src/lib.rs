//! Live devices: serial ports that survive being unplugged ([`serial`]: a set of ports read at
//! once, each on a thread of its own, the baud search), CAN buses on SLCAN adapters and
//! SocketCAN interfaces ([`can`]), the clock that stamps what they receive ([`clock`]), and a
//! set of ports as an input ([`Ports`], a [`Source`](hwfoc_records::Source) of
//! `hwfoc-records`). What their bytes become is `hwfoc-records`'; `hwfoc-io` opens them as
//! inputs (`OpenInput::open_ports`).
//!
//! Every loop that waits ends when a stop flag its caller passes in (an `Arc<AtomicBool>`) is
//! set: the library installs no signal handler.

#![forbid(unsafe_op_in_unsafe_fn)]
#![warn(missing_docs)]

pub mod serial;

/// CAN buses: SLCAN adapters' ASCII protocol ([`slcan`](can::slcan)), live buses
/// ([`CanBus`](can::CanBus): an SLCAN adapter or a SocketCAN interface) and the rule of asking
/// the ESCs on a bus for their ids ([`AskIds`](can::AskIds)); `hwfoc-records`' CAN records.
pub mod can {
    mod ask;
    mod bus;
    pub mod slcan;
    #[cfg(target_os = "linux")]
    mod socketcan;

    pub use ask::{ASK_EVERY, ASK_PRIORITY, AskIds, DEFAULT_SOURCE_NODE};
    pub use bus::{CanBus, CanError, CanSpec, DEFAULT_BITRATE, SLCAN_BAUD, is_can_spec};
    pub use hwfoc_records::can::{NOT_CLASSIC_RECORD, candump};
}

/// Receive times: the clock that stamps what is received (`ReceiveClock`, reading the system's
/// clocks) and `hwfoc-records`' timing of a chunk's bytes and steps between frames.
pub mod clock {
    pub use crate::receive::{ReceiveClock, unix_now_ns};
    pub use hwfoc_records::clock::*;
}

mod input;
mod port;
mod receive;

pub use input::Ports;
