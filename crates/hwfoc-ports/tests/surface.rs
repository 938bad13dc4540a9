//! The public surface of `hwfoc-ports` (live devices: serial ports, CAN adapters and buses,
//! the receive clock): every item a user may name, imported by its public path, so that the
//! test does not compile when one goes missing or moves (as `hwfoc-io`'s `tests/surface.rs`).

#![allow(unused_imports)]

// Serial ports.
use hwfoc_ports::serial::{
    Baud, SEARCH_BYTES_FOR, SEARCH_RATES, SEARCH_SILENT_FOR, Search, Verdict,
};
use hwfoc_ports::serial::{DEFAULT_BAUD, PortError, PortEvent, PortSet, RETRY_EVERY, Readers};
use hwfoc_ports::serial::{available_ports, is_port, open};

// CAN frames: SLCAN adapters, candump logs.
use hwfoc_ports::can::candump::{Line, LineError, Logged, looks_like_line, parse_line, push_line};
use hwfoc_ports::can::slcan::{BEL, BITRATES, CLOSE, Counts, Event, MAX_LINE, Parser};
use hwfoc_ports::can::slcan::{bitrate_code, push_extended, push_frame, setup};
use hwfoc_ports::can::{ASK_EVERY, ASK_PRIORITY, AskIds, DEFAULT_SOURCE_NODE};
use hwfoc_ports::can::{CanBus, CanError, CanSpec, DEFAULT_BITRATE, SLCAN_BAUD, is_can_spec};

// Receive times and clocks.
use hwfoc_ports::clock::{MAX_FRAME_SPACING_S, MAX_STEP_S, ReceiveClock, Step};
use hwfoc_ports::clock::{byte_time_s, byte_times, unix_now_ns};

/// The constants the documents fix (`docs/REFERENCE.md`: the HW-FOC baud rate, SLCAN at
/// 115200 baud, CAN at 500 kbit/s).
#[test]
fn the_surface_constants_are_those_of_the_specs() {
    assert_eq!(DEFAULT_BAUD, 19_200);
    assert_eq!(SLCAN_BAUD, 115_200);
    assert_eq!(DEFAULT_BITRATE, 500_000);
}
