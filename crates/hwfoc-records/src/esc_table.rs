//! Which ESC is which: the identity of every ESC found in a command's inputs.
//!
//! An ESC is the stream of one place (a port, or a DataLink hub's channel or a CAN bus's
//! place on it) in one recording: its key is ([`Recording`], port, [`Place`]). Port names
//! (`/dev/ttyUSB0`, `esc-0`) are the same on every drone and laptop, so a port name alone never
//! makes two inputs' streams one ESC:
//! - each input is a recording of its own ([`Recording::Input`]), unless it names the recording
//!   it is part of (hwfoc's pcapng recordings carry a [`RecordingId`] in every file of one run,
//!   rotated files alike: [`Recording::Id`]), or the user joined the recordings given
//!   ([`Recording::Joined`], `--join`);
//! - within one recording, the streams of one port are one ESC, its bytes in time order
//!   (a rotated series), a moment given twice decoded once;
//! - a file given twice (the same bytes) is read once.
//!
//! ESCs are numbered in the order the inputs are given; [`EscTable`] holds each number's key
//! and the input it was first found in, for the outputs that name ESCs (the summary, the
//! Parquet metadata, Python).

use crate::pcapng::RecordingId;

/// The recording an ESC's stream belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Recording {
    /// An hwfoc recording, named by the id every file of it carries.
    Id(RecordingId),
    /// Input number `n` (in the order given), a recording of its own: a file that names no
    /// recording, standard input, or a set of serial ports.
    Input(usize),
    /// The recordings the user joined (`--join`): their ports go on from one to the next by
    /// name, whatever recording each names.
    Joined,
}

/// Where an ESC is on its port.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Place {
    /// The port's own ESC (a DataLink hub's channel 0, a CAN bus's first place).
    Own,
    /// A DataLink hub's channel, or a CAN bus's place, other than the first.
    Channel(u8),
}

/// What makes an ESC the ESC it is.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct EscKey {
    /// The recording.
    pub recording: Recording,
    /// The port (a recording's interface name, a serial port, or the input's name).
    pub port: String,
    /// Its place on the port.
    pub place: Place,
}

/// One ESC of the table.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EscEntry {
    /// Its identity.
    pub key: EscKey,
    /// The input (index, in the order given) it was first found in.
    pub input: usize,
}

/// Every ESC found, by number.
#[derive(Debug, Clone, Default)]
pub struct EscTable {
    escs: Vec<EscEntry>,
}

impl EscTable {
    /// The number of ESCs.
    pub fn len(&self) -> usize {
        self.escs.len()
    }

    /// Whether no ESC was found.
    pub fn is_empty(&self) -> bool {
        self.escs.is_empty()
    }

    /// ESC `esc`'s entry.
    pub fn get(&self, esc: usize) -> Option<&EscEntry> {
        self.escs.get(esc)
    }

    /// The ESCs, by number.
    pub fn iter(&self) -> impl Iterator<Item = &EscEntry> {
        self.escs.iter()
    }

    /// The number of the ESC of `key`, if found.
    pub fn find(&self, key: &EscKey) -> Option<usize> {
        self.escs.iter().position(|e| e.key == *key)
    }

    /// Adds an ESC: its number.
    pub(crate) fn push(&mut self, key: EscKey, input: usize) -> usize {
        self.escs.push(EscEntry { key, input });
        self.escs.len() - 1
    }
}

impl std::ops::Index<usize> for EscTable {
    type Output = EscEntry;

    fn index(&self, esc: usize) -> &EscEntry {
        &self.escs[esc]
    }
}
