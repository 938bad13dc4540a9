//! The seam between the bridge's inputs and its outputs: the [`Output`] trait.

use std::fmt;
use std::time::{Duration, Instant};

use hwfoc::Settings;
use hwfoc::telemetry::Data;
use hwfoc_io::Record;

use crate::latency::Latency;

/// An ESC without a frame for this long is silent: outputs stop sending it, and say so where
/// their protocol can (an idle ESC sends a frame every ~364 ms).
pub const SILENT_AFTER: Duration = Duration::from_secs(1);

/// One frame of one ESC, as handed to every output.
#[derive(Debug, Clone, Copy)]
pub struct Update<'a> {
    /// The ESC: the index of its input stream, or its DataLink channel.
    pub esc: u8,
    /// The data frame as decoded, of any protocol, read through [`hwfoc::Telemetry`] (an output
    /// re-encoding raw fields takes these: no unit conversion to undo).
    pub frame: &'a Data,
    /// The frame in physical units, under the bridge's settings.
    pub record: &'a Record,
    /// The ESC's settings, under which `record` was converted (an output converting values
    /// back to another protocol's raw fields takes these).
    pub settings: &'a Settings,
    /// When the read that completed the frame returned: where the bridge's latency starts.
    pub arrived: Instant,
}

/// A bridge output: a protocol written to a port or a socket.
///
/// The bridge calls [`Output::update`] for every frame of every ESC, in arrival order, and
/// [`Output::poll`] after each batch of updates and at least every 10 ms, with the time now.
/// An output sends only what its inputs gave it: no invented frames, and an ESC silent for
/// [`SILENT_AFTER`] is no longer sent.
pub trait Output {
    /// What and where, for messages: `mavlink udp:127.0.0.1:14550`.
    fn name(&self) -> &str;

    /// A new frame of an ESC. Sending may wait for [`Output::poll`].
    fn update(&mut self, update: &Update<'_>);

    /// Sends what is due at `now`. An error is reported and counted by the caller, and the
    /// output carries on at the next call (a lost port is reopened by the output itself).
    fn poll(&mut self, now: Instant) -> Result<(), OutputError>;

    /// The output's counters so far.
    fn stats(&self) -> &OutputStats;
}

/// What an output has done.
#[derive(Debug, Clone, Default)]
pub struct OutputStats {
    /// Messages (or frames) written.
    pub messages: u64,
    /// Bytes written.
    pub bytes: u64,
    /// Failed sends and lost ports.
    pub errors: u64,
    /// ESC frames superseded by a newer frame of the same ESC before they could be sent.
    pub superseded: u64,
    /// From the read that completed an ESC frame to the write of the message carrying it.
    pub latency: Latency,
}

/// Why an output could not send.
#[derive(Debug)]
#[non_exhaustive]
pub enum OutputError {
    /// Writing to the port, socket or adapter failed.
    Send {
        /// The output ([`Output::name`]).
        output: String,
        /// What the operating system said.
        reason: String,
    },
    /// The port or adapter is gone (unplugged); it is being reopened.
    Lost {
        /// The output ([`Output::name`]).
        output: String,
        /// What the operating system said.
        reason: String,
    },
    /// The output cannot be opened at all: a bad address, a port that does not exist.
    Open {
        /// The output as the user named it.
        output: String,
        /// Why.
        reason: String,
    },
}

impl fmt::Display for OutputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OutputError::Send { output, reason } => write!(f, "{output}: cannot send: {reason}"),
            OutputError::Lost { output, reason } => {
                write!(f, "{output}: lost ({reason}); reopening")
            }
            OutputError::Open { output, reason } => write!(f, "{output}: cannot open: {reason}"),
        }
    }
}

impl std::error::Error for OutputError {}
