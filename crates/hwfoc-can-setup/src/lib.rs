//! Setting up Hobbywing's DroneCAN ESCs, as the DataLink's CAN tab does (`docs/HW5-AND-CAN.md`,
//! "Hobbywing DroneCAN ESCs", services 210-217, 241, 242): hwfoc as a node on the bus
//! ([`Client`]) listens before it speaks ([`Client::listen_first`]), lists the ESCs
//! ([`Client::survey`]), checks before each change that every motor is seen at rest
//! ([`Client::check_at_rest`]) and that a node is one ESC ([`Client::check_alone`]), makes a
//! [`Change`] and reads it back ([`Client::change`]).
//!
//! **The factory state**: every ESC leaves the factory as node 1, throttle channel 1, so a
//! request to node 1 reaches them all. [`NodeHeard::escs`] tells it from the bus: several
//! GetEscID answers from one node to one request, or StatusMsg1 transfer ids that interleave
//! (each ESC counts its own).
//!
//! | module | holds |
//! |---|---|
//! | `client` | [`Client`], [`Link`], [`Survey`], [`EscSurvey`], [`Made`] |
//! | `heard` | [`Heard`], [`NodeHeard`]: what each node sent; [`Motion`]: what says a motor turns |
//! | `values` | [`Change`] and its values by name |

#![forbid(unsafe_op_in_unsafe_fn)]
#![warn(missing_docs)]

mod client;
mod heard;
mod values;

use std::fmt;
use std::time::Duration;

use hwfoc::dronecan::Kind;

pub use client::{Client, EscSurvey, Link, Made, REQUEST_PRIORITY, Survey};
pub use heard::{Heard, Motion, NodeHeard};
pub use values::{
    Change, Direction, LED_COLORS, Led, StatusMessage, ThrottleSource, baud_code, parse_rate,
    rate_code, rate_hz, rate_text,
};

use hwfoc_ports::can::CanError;

/// Why a setup step failed. Each names the bus, and the node where there is one.
#[derive(Debug)]
pub enum SetupError {
    /// The bus could not be opened, read or written.
    Can(CanError),
    /// The node did not answer in time.
    NoAnswer {
        /// The bus as given.
        bus: String,
        /// The node asked.
        node: u8,
        /// The request (or GetEscID).
        service: Kind,
        /// How long it was given.
        timeout: Duration,
    },
    /// A motor turns: nothing is changed.
    Turning {
        /// The bus as given.
        bus: String,
        /// The node that said so.
        node: u8,
        /// What it reported first.
        motion: Motion,
    },
    /// A change that can turn a motor, and its node (or another that reported so) was not
    /// seen at rest: its `StatusMsg1` (rpm and pwm) is off, never came or stopped.
    Unseen {
        /// The bus as given.
        bus: String,
        /// The node.
        node: u8,
        /// Whether anything was heard from it.
        heard: bool,
    },
    /// A write was not answered in time: it may have been made.
    Unanswered {
        /// The bus as given.
        bus: String,
        /// The node.
        node: u8,
        /// The request.
        service: Kind,
        /// How long it was given.
        timeout: Duration,
        /// What the ESC said when read back (`None`: no read-back).
        said: Option<Change>,
    },
    /// After SetID the node still answers at its old id, and not at the new one.
    IdNotTaken {
        /// The bus as given.
        bus: String,
        /// The old id.
        node: u8,
        /// The id asked.
        to: u8,
    },
    /// After an answered SetID neither the old id nor the new one answers.
    IdLost {
        /// The bus as given.
        bus: String,
        /// The old id.
        node: u8,
        /// The id asked.
        to: u8,
    },
    /// Several ESCs answer as the node: a request would reach them all.
    Shared {
        /// The bus as given.
        bus: String,
        /// The node.
        node: u8,
        /// How many ESCs at least.
        escs: usize,
    },
    /// A change no service request can make (a bit rate `SetBaud` has no code for).
    Unsupported {
        /// The change.
        change: Change,
    },
    /// The ESC answered, but read back says otherwise than asked.
    NotTaken {
        /// The bus as given.
        bus: String,
        /// The node.
        node: u8,
        /// What was asked.
        asked: Change,
        /// What the ESC says.
        said: Change,
    },
    /// The ESC's self test failed (`SelfTest` answered 1).
    SelfTestFailed {
        /// The bus as given.
        bus: String,
        /// The node.
        node: u8,
    },
    /// The stop flag was set (Ctrl-C).
    Stopped {
        /// The bus as given.
        bus: String,
    },
}

impl fmt::Display for SetupError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SetupError::Can(e) => e.fmt(f),
            SetupError::NoAnswer {
                bus,
                node,
                service,
                timeout,
            } => write!(
                f,
                "{bus}: node {node} did not answer {} within {} s (is it on the bus, at this bit rate?)",
                short_name(*service),
                timeout.as_secs_f64()
            ),
            SetupError::Turning { bus, node, motion } => write!(
                f,
                "{bus}: node {node} reports {motion}: nothing is changed while a motor turns"
            ),
            SetupError::Unseen {
                bus,
                node,
                heard: false,
            } => write!(
                f,
                "{bus}: node {node} is not heard (is it on the bus, at this bit rate?): nothing that \
                 can turn a motor is sent to an ESC not seen at rest; if its StatusMsg1 is off, \
                 turn it on first: `hwfoc can set {bus} --node {node} --rate msg1=50`"
            ),
            SetupError::Unseen {
                bus,
                node,
                heard: true,
            } => write!(
                f,
                "{bus}: node {node} sends no StatusMsg1 (its rpm and pwm): nothing that can turn a \
                 motor is sent while it cannot be seen at rest; turn its status on first: \
                 `hwfoc can set {bus} --node {node} --rate msg1=50`"
            ),
            SetupError::Unanswered {
                bus,
                node,
                service,
                timeout,
                said,
            } => {
                write!(
                    f,
                    "{bus}: node {node} did not answer {} within {} s: the change may have been made; ",
                    short_name(*service),
                    timeout.as_secs_f64()
                )?;
                match said {
                    Some(said) => write!(f, "read back, it says {said}"),
                    None => write!(f, "it was not read back"),
                }
            }
            SetupError::IdNotTaken { bus, node, to } => write!(
                f,
                "{bus}: node {node} still answers as node {node}: SetID was not applied (node {to} \
                 is not heard)"
            ),
            SetupError::IdLost { bus, node, to } => write!(
                f,
                "{bus}: node {node} answered SetID, but neither node {node} nor node {to} answers \
                 now (see `hwfoc can list`)"
            ),
            SetupError::Shared { bus, node, escs } => write!(
                f,
                "{bus}: {escs} ESCs answer as node {node} (the factory state): a request to it \
                 reaches them all; connect one ESC at a time (see `hwfoc can list`)"
            ),
            SetupError::Unsupported { change } => {
                write!(f, "{change}: no setup service sets that")
            }
            SetupError::NotTaken {
                bus,
                node,
                asked,
                said,
            } => write!(f, "{bus}: node {node} was asked {asked} but says {said}"),
            SetupError::SelfTestFailed { bus, node } => {
                write!(f, "{bus}: node {node}: the self test failed")
            }
            SetupError::Stopped { bus } => write!(f, "{bus}: interrupted"),
        }
    }
}

impl std::error::Error for SetupError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SetupError::Can(e) => Some(e),
            _ => None,
        }
    }
}

impl From<CanError> for SetupError {
    fn from(e: CanError) -> SetupError {
        SetupError::Can(e)
    }
}

/// A data type's name without its package and half: `SetDirection`.
pub fn short_name(kind: Kind) -> &'static str {
    let name = kind.full_name();
    name.rsplit('.').next().unwrap_or(name)
}
