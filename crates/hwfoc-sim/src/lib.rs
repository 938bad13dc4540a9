//! Virtual Hobbywing ESCs that speak their protocol as real ones do (HW-FOC, and the formats of
//! [`formats`]), for every front end alike (the
//! `hwfoc simulate` command, `hwfoc monitor --sim`, bridges, bindings, tests that need
//! recordings).
//!
//! Each ESC runs a small physical model ([`model`]) driven by a throttle profile ([`profile`]),
//! sends its frames on the real schedule ([`esc`]) through a link that can misbehave
//! ([`faults`]), into pseudo-terminals, serial ports, files or standard output ([`destination`],
//! [`sink`], `pty` on Unix; [`template`]: one name for every ESC), paced in real time or as
//! fast as possible ([`schedule`]). Every random choice comes from the seed ([`rng`]): the same
//! seed and description give the same bytes.
//!
//! A run is described in plain data: the ESCs by a [`FleetSpec`], built (checked, its profile
//! loaded) into a [`VirtualFleet`]; where and how they run by a [`Plan`]. A [`Session`] opens
//! the plan's outputs and runs it to a report per ESC; [`VirtualFleet::run_live`] runs the ESCs
//! in real time into any [`Sink`] instead (a front end's own, in-process).
//!
//! Errors are one enum, [`SimError`], whose `Display` is the one-line message a person reads.

#![forbid(unsafe_op_in_unsafe_fn)]
#![warn(missing_docs)]

pub mod burst;
pub mod can;
pub mod degrade;
pub mod destination;
pub mod error;
pub mod esc;
pub mod faults;
pub mod fleet;
pub mod formats;
pub mod model;
pub mod profile;
#[cfg(unix)]
pub mod pty;
pub mod rng;
pub mod schedule;
pub mod session;
pub mod sink;
pub mod template;

pub use destination::{Destination, FileFormat};
pub use error::SimError;
pub use fleet::{FleetSpec, VirtualFleet};
pub use session::{EscReport, Plan, Session};
pub use sink::Sink;
