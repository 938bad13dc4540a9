#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod chain;
pub mod counters;
pub mod datalink;
pub mod detect;
pub mod dronecan;
pub mod foc;
pub mod format;
pub mod hw5;
pub mod mixed;
pub mod protocol;
pub mod scan;
pub mod status;
pub mod telemetry;
pub mod units;
pub mod v3;
pub mod v4;
pub mod wire;

pub use protocol::Protocol;
pub use scan::{Scan, StreamDecoder};
pub use status::{Fault, Faults, Status};
pub use telemetry::{Conversion, Reading, Telemetry};
pub use units::{Quantity, Settings, SettingsError, Temperature};
