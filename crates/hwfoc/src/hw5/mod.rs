//! HW5: the telemetry wire of Hobbywing Platinum V5 ESCs, ESCs on VBAR firmware and newer
//! XeRun/FlyFun lines (`docs/HW5-AND-CAN.md`, "HW5"; source: Rotorflight's `esc_sensor.c`,
//! "Hobbywing V5 Telemetry"). 115200 baud 8N1 ([`BAUD_RATE`]), multi-byte fields
//! little-endian (unlike every 0x9B format), every frame checked by a CRC-16/MODBUS
//! ([`Checksum::Crc16Modbus`](crate::wire::Checksum::Crc16Modbus),
//! [`crc16_modbus`](crate::wire::crc16_modbus)) over the bytes before it, low byte first.
//!
//! # What a telemetry frame carries
//!
//! A [`TelemetryFrame`] (32 bytes, type 0x5C30) every 20 ms while the motor runs and every
//! 400 ms idle ([`FRAME_PERIOD_RUNNING`], [`FRAME_PERIOD_IDLE`]): throttle in percent, a fault
//! byte of eight named flags ([`Fault`], [`FaultCode`]), eRPM / 10, input voltage and current
//! (0.1 V, 0.1 A), ESC (MOSFET), BEC and motor temperatures (degC, one byte each), BEC voltage
//! and current (0.1 V, 0.1 A).
//!
//! What it does **not** carry:
//!
//! - **No packet counter**: loss cannot be counted from the frames. The layers above judge it
//!   from time, against the nominal periods; [`Stats`] counts no loss, and
//!   [`line_silent`](crate::scan::StreamDecoder::line_silent) only settles a frame cut by the
//!   silence.
//! - **No phase current**, only the input current.
//! - **No input/output throttle split**: throttle is one percent value.
//! - **No battery consumption**: the ESC sends no mAh.
//!
//! **Current at zero throttle**: when the throttle drops to 0 the ESC keeps repeating its last
//! current reading until the motor has stopped. The codec records what the wire says
//! ([`TelemetryFrame::current_raw`]); Rotorflight reports 0 A while the throttle is 0, and an
//! energy integration that follows its rule can take
//! [`TelemetryFrame::driven_current_raw`].
//!
//! # The other frames on the wire
//!
//! On a half-duplex wire a flight controller or configurator also sends requests and the ESC
//! answers them. These frames are recognised ([`Kind`]), verified by their CRC, taken whole
//! and counted by kind ([`Stats::frames`]); they are not decoded and never handed on as
//! telemetry. A frame's length is not on the wire, so the scanner knows it from the frame's
//! direction and type ([`kinds_of`]), per the spec's list:
//!
//! | direction (bytes 0-2) | type (bytes 4-5) | length | kind |
//! |---|---|---|---|
//! | from the ESC, `FE 01 00` | 0x5C30, with code (byte 3) `03` and byte 6 `17` | 32 | [`Kind::Telemetry`] |
//! | from the ESC | 0x242C | 11 | [`Kind::Ping`] |
//! | from the ESC | 0x252C | 73 | [`Kind::DeviceInfo`] |
//! | from the ESC | 0x022B | 10 | [`Kind::Reset`] |
//! | from the ESC | 0x3835 | 9, 58 or 105: the first whose CRC matches | [`Kind::ParametersWriteError`], [`Kind::ParametersWritten`], [`Kind::ParametersRead`] |
//! | to the ESC, `01 FD 03` | 0x242C | 10 | [`Kind::PingRequest`] |
//!
//! Requests: the spec says they "start `FD`", and gives as its example the ping that
//! Rotorflight writes, `01 FD 03 03 2C 24 00 01 60 60`, "with a leading `01`". That `01` is
//! part of the frame: the CRC covers it (CRC-16/MODBUS of `01 FD 03 03 2C 24 00 01` is 0x6060,
//! as carried; from `FD` on it would be 0xA7FA), and the bytes after it line up with an ESC
//! frame's (code at 3, type at 4-5). So a request's envelope is `01 FD 03`: the ESC's address,
//! the `FD` mark, and `03`. The spec gives the length of no other request, so any other
//! request type is an unknown type.
//!
//! Any other candidate (an `FE 01` or `01 FD` whose third byte, type or CRC does not fit)
//! costs one byte and is counted ([`Stats::bad_headers`], [`Stats::unknown_types`],
//! [`Stats::checksum_failures`]); the scan goes on at the next byte, so nothing hides a following
//! intact frame.
//!
//! | module | holds |
//! |---|---|
//! | `layout` | [`BAUD_RATE`], [`FRAME_PERIOD_RUNNING`], [`FRAME_PERIOD_IDLE`], [`TELEMETRY_LEN`], [`MAX_FRAME_LEN`], the envelope bytes and offsets, types, [`Kind`], [`Direction`], [`kinds_of`], the conversions [`VOLTS`], [`AMPS`], [`ERPM`] |
//! | `frame` | [`TelemetryFrame`] (encode, parse, conversions), [`Fault`], [`FaultCode`], [`Faults`], [`identify`] |
//! | `error` | [`Error`] |
//! | `stats` | [`Stats`] |
//! | `decoder` | the scanner: [`Decoder`], [`frames`], [`Decoded`] |
//!
//! ```
//! use hwfoc::hw5::{self, Kind, TelemetryFrame};
//!
//! let frame = TelemetryFrame { throttle: 55, erpm_raw: 4200, voltage_raw: 504, ..Default::default() };
//! let ping_request = [0x01, 0xFD, 0x03, 0x03, 0x2C, 0x24, 0x00, 0x01, 0x60, 0x60];
//! let mut wire = b"noise".to_vec();
//! wire.extend_from_slice(&frame.encode());
//! wire.extend_from_slice(&ping_request);
//! wire.extend_from_slice(&frame.encode());
//!
//! let mut it = hw5::frames(&wire);
//! let decoded: Vec<_> = it.by_ref().collect();
//! assert_eq!(decoded.len(), 2);
//! assert_eq!((decoded[0].offset, decoded[1].offset), (5, 47));
//! assert_eq!(decoded[0].frame.erpm(), 42_000);
//! assert_eq!(it.stats().telemetry_frames(), 2);
//! assert_eq!(it.stats().frames(Kind::PingRequest), 1);
//! assert_eq!(it.stats().bytes_skipped(), 5);
//! ```

pub(crate) mod decoder;
mod description;
mod error;
mod frame;
mod layout;
mod stats;

pub use decoder::{Decoded, Decoder, Frames, Scanner, frames};
pub use description::DESCRIPTION;
pub use error::Error;
pub use frame::{
    FAULTS, Fault, FaultCode, Faults, THROTTLE_MAX_PCT, TelemetryFrame, VOLTAGE_MAX_RAW, identify,
};
pub use layout::{
    AMPS, BAUD_RATE, CHECKSUM, CODE_AT, Direction, ERPM, ESC_ADDRESS, ESC_BYTE2, ESC_START,
    FRAME_PERIOD_IDLE, FRAME_PERIOD_RUNNING, HEADER_LEN, Kind, MAX_FRAME_LEN, PAYLOAD_LEN_AT,
    REQUEST_BYTE2, REQUEST_MARK, TELEMETRY_HEADER, TELEMETRY_LEN, TYPE_AT, TYPE_DEVICE_INFO,
    TYPE_PARAMETERS, TYPE_PING, TYPE_RESET, TYPE_TELEMETRY, VOLTS, envelope, kinds_of,
};
pub use stats::Stats;

crate::protocol::found_frame!(Decoded, Hw5);

impl crate::protocol::FamilyScanner for Scanner {
    fn handed_on(s: &Stats) -> u64 {
        u64::from(s.telemetry_frames())
    }
}

impl crate::family::FamilyLink for Scanner {
    fn hand_on(d: &Decoded, emit: &mut crate::family::Emit<'_>) {
        let frame = crate::telemetry::Data::Hw5(d.frame);
        emit(None, d.offset, &crate::telemetry::AnyFrame::Data(frame));
    }

    /// Its frames carry no packet number: no packet counts. Values out of range count as
    /// checksum failures.
    fn figures(s: &Stats) -> Option<crate::family::LinkFigures> {
        Some(crate::family::LinkFigures {
            protocol: crate::Protocol::Hw5,
            bytes: crate::scan::Stats::bytes(s),
            bytes_skipped: s.bytes_skipped(),
            frames: s.telemetry_frames(),
            info_frames: 0,
            checksum_failures: s.checksum_failures().saturating_add(s.out_of_range()),
            rejected_candidates: None,
            packets: None,
            adopted_info: None,
        })
    }
}
