//! Receive times: Unix time in nanoseconds, from the wall clock and a monotonic one (the
//! module `clock`, with `hwfoc-records`' timing of a chunk's bytes and steps between frames).

use std::time::{Instant, SystemTime, UNIX_EPOCH};

/// The wall clock now, Unix time in nanoseconds (0 for a clock set before 1970).
pub fn unix_now_ns() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

/// The clock that stamps what is received (ports, the simulator, recordings): Unix time in
/// nanoseconds that never goes backwards, the wall clock when the clock was made advanced by a
/// monotonic clock (so that a clock step during a recording does not reorder it). Not to be
/// confused with [`crate::time::Clock`](hwfoc_records::time::Clock), which says what a source's times mean.
#[derive(Debug, Clone, Copy)]
pub struct ReceiveClock {
    wall_ns: u64,
    start: Instant,
}

impl ReceiveClock {
    /// A clock anchored at the wall-clock time now.
    pub fn new() -> ReceiveClock {
        let wall_ns = unix_now_ns();
        ReceiveClock {
            wall_ns,
            start: Instant::now(),
        }
    }

    /// Unix time now, in nanoseconds.
    pub fn now_ns(&self) -> u64 {
        self.wall_ns + self.start.elapsed().as_nanos() as u64
    }
}

impl Default for ReceiveClock {
    fn default() -> Self {
        ReceiveClock::new()
    }
}
