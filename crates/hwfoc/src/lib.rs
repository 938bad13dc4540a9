#![doc = include_str!("../README.md")]
#![no_std]
// No `unsafe` but calls of `core::arch` functions that need a target feature (compares and
// movemasks) or are `unsafe` themselves: in `foc/window.rs` the SSE2 search window and sync
// mask (x86_64 always has SSE2), in `foc/map.rs` the candidate map, with AVX2 where `cpuid`
// and `xgetbv` (asked once, also there) say the processor and operating system have it, else
// SSE2.
#![deny(unsafe_code)]
#![warn(missing_docs)]

/// The one list of formats: each line gives a format's arm, its documentation, its
/// [`FormatDescription`](format::FormatDescription), its data frame's type (`data`, or `shares`
/// where another arm's frame type is the same and `From` makes that arm), its
/// device-information frame's type where it sends one (`info`), and for a serial
/// format with its own decoder, the family detection locks onto (its scanner, a
/// [`FamilyScanner`](protocol::FamilyScanner), and its rank when two families find frames in one
/// slice, 0 first).
///
/// `formats!(callback)` hands the list to `callback`, which declares from it
/// [`Protocol`], [`Data`](telemetry::Data), [`Info`](telemetry::Info),
/// [`Family`](detect::Family) and [`Decoded`](detect::Decoded): adding a format is its module,
/// one line here and its `pub mod` line.
macro_rules! formats {
    ($callback:ident) => {
        $callback! {
            /// HW-FOC: an ESC's own wire ([`crate::foc`]).
            HwFoc => crate::foc::DESCRIPTION, data crate::foc::DataFrame, info crate::foc::InfoFrame,
                family Mixed(crate::mixed::Scanner) rank 0;
            /// DataLink V2: a Hobbywing hub's frames of up to eight ESCs ([`crate::datalink`]).
            DataLink => crate::datalink::DESCRIPTION, shares crate::foc::DataFrame;
            /// Platinum V4 (and Platinum Pro V4, FlyFun V5): `9B` data and info frames without
            /// checksum ([`crate::v4`]).
            HwV4 => crate::v4::DESCRIPTION, data crate::v4::Data, info crate::v4::InfoFrame,
                family HwV4(crate::v4::Scanner) rank 2;
            /// Platinum V3 (and Platinum Pro V3): 10-byte `9B` frames without checksum
            /// ([`crate::v3`]).
            HwV3 => crate::v3::DESCRIPTION, data crate::v3::V3Frame,
                family HwV3(crate::v3::Scanner) rank 3;
            /// HW5 (Platinum V5, VBAR firmware): `FE` frames with a CRC-16/MODBUS at 115200 baud
            /// ([`crate::hw5`]).
            Hw5 => crate::hw5::DESCRIPTION, data crate::hw5::TelemetryFrame,
                family Hw5(crate::hw5::Scanner) rank 1;
            /// Hobbywing's DroneCAN ESCs (XRotor X6/X8/X9 and H-series "CAN" versions):
            /// `com.hobbywing.esc.StatusMsg1/2/3` on a CAN bus (`hw-can`).
            HwCan => crate::dronecan::HW_CAN, data crate::dronecan::HwCanEsc;
            /// Standard DroneCAN ESCs: `uavcan.equipment.esc.Status` and `StatusExtended` on a
            /// CAN bus (`dronecan`).
            DroneCan => crate::dronecan::DRONECAN, data crate::dronecan::DroneCanEsc;
        }
    };
}

mod chain;
pub mod counters;
pub mod datalink;
pub mod detect;
pub mod dronecan;
pub mod family;
pub mod foc;
pub mod format;
pub mod hw5;
pub mod mixed;
pub mod ntc;
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
