//! What a virtual ESC puts on its wire: [`Burst`]s, bytes sent back to back, each with
//! [`What`] it is (a frame and what the link did to it, line noise, a glitch): the ground truth
//! a run is checked against.

use hwfoc::foc::DataFrame;
use hwfoc::telemetry::Data;

use crate::faults::Fate;

/// What a burst is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum What {
    /// A data frame, and what the link did to it (dropped: no bytes).
    Data {
        /// The frame as the ESC meant it.
        frame: DataFrame,
        /// What the link did to it.
        fate: Fate,
    },
    /// A data frame of another protocol than HW-FOC (always intact: no link faults there).
    Telemetry {
        /// The frame as the ESC meant it (a V4 frame with the ESC's own info frame).
        data: Data,
    },
    /// A device-information frame (HW-FOC's, or V4's info frame).
    Info {
        /// What the link did to it.
        fate: Fate,
    },
    /// Line noise between frames.
    Garbage,
    /// Zero bytes put before a frame so that a fault stays detectable (see [`crate::esc`]).
    Glitch,
}

/// Bytes sent back to back on one ESC's wire.
#[derive(Debug, Clone, PartialEq)]
pub struct Burst {
    /// Simulated time of the start of the first byte, ns since the start of the run.
    pub t_ns: u64,
    /// The bytes (none for a dropped frame).
    pub bytes: Vec<u8>,
    /// What they are.
    pub what: What,
}

impl Burst {
    /// The data frame it carries intact, if any: what the ground truth records.
    pub fn intact_frame(&self) -> Option<&DataFrame> {
        match &self.what {
            What::Data {
                frame,
                fate: Fate::Intact,
            } => Some(frame),
            _ => None,
        }
    }

    /// The data frame of any protocol it carries intact, if any: what the ground truth records.
    pub fn intact_data(&self) -> Option<Data> {
        match &self.what {
            What::Telemetry { data } => Some(*data),
            _ => self.intact_frame().map(|f| Data::HwFoc(*f)),
        }
    }
}
