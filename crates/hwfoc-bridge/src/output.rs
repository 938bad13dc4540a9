//! The seam between the bridge's inputs and its outputs: the [`Output`] trait.

use std::collections::BTreeSet;
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

    /// How many ESCs its protocol can carry: ESCs numbered this or more are not sent (counted
    /// in [`OutputStats::left_out`]).
    fn carries(&self) -> usize;
}

/// The frames an output could not send because their ESC's number is past what its protocol
/// carries ([`Output::carries`]).
#[derive(Debug, Clone, Default)]
pub struct LeftOut {
    /// Frames not sent.
    pub frames: u64,
    /// The ESCs they were of.
    pub escs: BTreeSet<u8>,
}

impl LeftOut {
    /// A frame of ESC `esc`, not sent.
    pub fn add(&mut self, esc: u8) {
        self.frames += 1;
        self.escs.insert(esc);
    }
}

/// ESC numbers as people read a list of them: `10 to 13`, `8, 9, 12`.
pub fn esc_list(escs: &BTreeSet<u8>) -> String {
    let mut runs: Vec<(u8, u8)> = Vec::new();
    for &esc in escs {
        match runs.last_mut() {
            Some((_, last)) if u16::from(*last) + 1 == u16::from(esc) => *last = esc,
            _ => runs.push((esc, esc)),
        }
    }
    let runs: Vec<String> = runs
        .iter()
        .map(|&(a, b)| match b - a {
            0 => a.to_string(),
            1 => format!("{a}, {b}"),
            _ => format!("{a} to {b}"),
        })
        .collect();
    runs.join(", ")
}

/// The error of an output that left ESCs out ([`OutputError::NotCarried`]), if it did.
pub fn left_out(output: &dyn Output) -> Option<OutputError> {
    let left = &output.stats().left_out;
    (left.frames > 0).then(|| OutputError::NotCarried {
        output: output.name().to_string(),
        escs: esc_list(&left.escs),
        frames: left.frames,
        carries: output.carries(),
    })
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
    /// Frames of ESCs numbered past what the output's protocol carries.
    pub left_out: LeftOut,
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
    /// Frames of ESCs numbered past what the output's protocol carries were not sent.
    NotCarried {
        /// The output ([`Output::name`]).
        output: String,
        /// The ESCs left out, as [`esc_list`] words them.
        escs: String,
        /// How many frames.
        frames: u64,
        /// How many ESCs the output carries ([`Output::carries`]).
        carries: usize,
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
            OutputError::NotCarried {
                output,
                escs,
                frames,
                carries,
            } => write!(
                f,
                "{output}: {frames} frames of ESC{} {escs} not sent: it carries ESCs 0 to {}",
                if escs.contains(|c: char| !c.is_ascii_digit()) {
                    "s"
                } else {
                    ""
                },
                carries.saturating_sub(1)
            ),
        }
    }
}

impl std::error::Error for OutputError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn esc_lists_join_runs() {
        let list = |escs: &[u8]| esc_list(&escs.iter().copied().collect());
        assert_eq!(list(&[10, 11, 12, 13]), "10 to 13");
        assert_eq!(list(&[8, 9, 12]), "8, 9, 12");
        assert_eq!(list(&[254, 255]), "254, 255");
        assert_eq!(list(&[]), "");
    }
}
