#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod datalink;
pub mod decoder;
pub mod frame;
pub mod kinds;
pub mod mixed;
pub mod scan;
pub mod stats;
pub mod status;
pub mod telemetry;
pub mod units;
pub mod wire;

pub use datalink::{
    DatalinkDecoded, DatalinkDecoder, DatalinkError, DatalinkFrame, DatalinkFrames, DatalinkStats,
};
pub use decoder::{Decoded, Decoder, Frames, frames};
pub use frame::{Frame, Parsed, parse};
pub use kinds::data::DataFrame;
pub use kinds::info::{InfoFieldError, InfoFrame};
pub use scan::{Scan, StreamDecoder};
pub use stats::{LinkStats, PacketSequence};
pub use status::{Fault, Faults, Status};
pub use telemetry::{Conversion, Reading, Telemetry};
pub use units::{Quantity, Settings, SettingsError, Temperature};
pub use wire::{FrameError, FrameKind};
