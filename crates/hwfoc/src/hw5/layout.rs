//! HW5 frames on the wire: line speed, frame periods, the envelope, the frame kinds and their
//! lengths, the telemetry frame's offsets.
//!
//! ```text
//!  an ESC's frame:   FE  01  00  code  type_L type_H  payload ...  CRC_L CRC_H
//!  a request:        01  FD  03  code  type_L type_H  payload ...  CRC_L CRC_H
//!                    0   1   2   3     4      5                    CRC-16/MODBUS of every byte
//!                                                                  before it, low byte first
//! ```
//!
//! The length of a frame is not on the wire: it is known from its direction (the first two
//! bytes), its type (bytes 4-5, little-endian) and, for telemetry, its code (byte 3): see
//! [`Kind`] and [`kinds_of`].

use core::time::Duration;

use crate::units::Linear;
use crate::wire::Checksum;

/// Baud rate of an HW5 ESC's telemetry wire (8N1); byte times come from
/// [`byte_ns`](crate::wire::byte_ns)`(BAUD_RATE)` (a telemetry frame lasts 2.78 ms).
pub const BAUD_RATE: u32 = 115_200;

/// Nominal time from one telemetry frame to the next while the motor runs: 20 ms (50 Hz).
///
/// HW5 frames carry no packet counter, so the layers above judge loss from time: frames
/// expected in a stretch of running are its duration over this period.
pub const FRAME_PERIOD_RUNNING: Duration = Duration::from_millis(20);

/// Nominal time from one telemetry frame to the next while idle: 400 ms (2.5 Hz). An ESC that
/// has sent nothing for longer than this (Rotorflight allows 500 ms) has stopped sending.
pub const FRAME_PERIOD_IDLE: Duration = Duration::from_millis(400);

/// Byte 0 of every frame an ESC sends.
pub const ESC_START: u8 = 0xFE;
/// Byte 1 of a frame an ESC sends (and byte 0 of a request: the ESC's address).
pub const ESC_ADDRESS: u8 = 0x01;
/// Byte 2 of a frame an ESC sends.
pub const ESC_BYTE2: u8 = 0x00;
/// Byte 1 of a request sent to the ESC (the spec's "requests start `FD`").
pub const REQUEST_MARK: u8 = 0xFD;
/// Byte 2 of a request (as Rotorflight writes every request).
pub const REQUEST_BYTE2: u8 = 0x03;

/// The check bytes of every frame: CRC-16/MODBUS of the bytes before them, low byte first.
pub const CHECKSUM: Checksum = Checksum::Crc16Modbus;

/// Offset of the version/length code.
pub const CODE_AT: usize = 3;
/// Offset of the little-endian frame type.
pub const TYPE_AT: usize = 4;
/// Bytes that decide a candidate's kind: the envelope, the code and the type.
pub const HEADER_LEN: usize = 6;

/// Frame type of telemetry (bytes `30 5C`).
pub const TYPE_TELEMETRY: u16 = 0x5C30;
/// Frame type of a ping and its answer (bytes `2C 24`).
pub const TYPE_PING: u16 = 0x242C;
/// Frame type of device information (bytes `2C 25`).
pub const TYPE_DEVICE_INFO: u16 = 0x252C;
/// Frame type of a reset (bytes `2B 02`).
pub const TYPE_RESET: u16 = 0x022B;
/// Frame type of parameters (bytes `35 38`).
pub const TYPE_PARAMETERS: u16 = 0x3835;

/// Length of a telemetry frame, CRC included.
pub const TELEMETRY_LEN: usize = 32;
/// The code (byte 3) of a telemetry frame.
pub const TELEMETRY_CODE: u8 = 0x03;
/// Offset of a telemetry frame's payload length byte.
pub const PAYLOAD_LEN_AT: usize = 6;
/// A telemetry frame's payload length (byte 6): 23.
pub const TELEMETRY_PAYLOAD_LEN: u8 = 0x17;
/// The first seven bytes of every telemetry frame: `FE 01 00 03 30 5C 17`.
pub const TELEMETRY_HEADER: [u8; 7] = [
    ESC_START,
    ESC_ADDRESS,
    ESC_BYTE2,
    TELEMETRY_CODE,
    TYPE_TELEMETRY as u8,
    (TYPE_TELEMETRY >> 8) as u8,
    TELEMETRY_PAYLOAD_LEN,
];
/// Bytes 7-8 of a telemetry frame as the spec gives them (`06 00`); not checked when decoding.
pub const TELEMETRY_BYTES_7_8: [u8; 2] = [0x06, 0x00];
/// Offsets of a telemetry frame's fields.
pub(crate) mod at {
    pub const THROTTLE: usize = 9;
    pub const UNKNOWN: usize = 10;
    pub const FAULT: usize = 12;
    pub const ERPM: usize = 13;
    pub const VOLTAGE: usize = 15;
    pub const CURRENT: usize = 17;
    pub const ESC_TEMP: usize = 19;
    pub const BEC_TEMP: usize = 20;
    pub const MOTOR_TEMP: usize = 21;
    pub const BEC_VOLTAGE: usize = 22;
    pub const BEC_CURRENT: usize = 23;
    /// Bytes 24..30 are unused, `FF`.
    pub const UNUSED: usize = 24;
}
/// Offset of a telemetry frame's CRC (and the number of bytes it covers).
pub const TELEMETRY_CHECK_AT: usize = TELEMETRY_LEN - 2;

/// The longest frame the scanner knows ([`Kind::ParametersRead`], 105 bytes): this many bytes
/// from its start decide any candidate.
pub const MAX_FRAME_LEN: usize = 105;

/// Input voltage and BEC voltage in volts: `raw / 10`.
pub const VOLTS: Linear = Linear::new(1.0, 10.0, 1.0);
/// Input current and BEC current in amperes: `raw / 10`.
pub const AMPS: Linear = Linear::new(1.0, 10.0, 1.0);
/// Electrical RPM: `raw * 10`.
pub const ERPM: Linear = Linear::new(10.0, 1.0, 1.0);

/// Who sent a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Direction {
    /// From the ESC: `FE 01 00 …`.
    FromEsc,
    /// A request to the ESC (from a flight controller or configurator on the half-duplex
    /// wire): `01 FD 03 …`.
    ToEsc,
}

/// Every kind of frame the scanner recognises, with its direction, type and length.
///
/// The lengths are the spec's (`docs/HW5-AND-CAN.md`, "HW5"). Only [`Kind::Telemetry`] is
/// decoded; the others are verified by their CRC, taken whole and counted
/// ([`Stats::frames`](super::Stats::frames)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum Kind {
    /// Telemetry, type 0x5C30, code 03, 32 bytes.
    Telemetry = 0,
    /// The ESC's answer to a ping, type 0x242C, 11 bytes.
    Ping = 1,
    /// Device information, type 0x252C, 73 bytes.
    DeviceInfo = 2,
    /// Reset, type 0x022B, 10 bytes.
    Reset = 3,
    /// Parameters read, type 0x3835, 105 bytes.
    ParametersRead = 4,
    /// Parameters written, type 0x3835, 58 bytes.
    ParametersWritten = 5,
    /// Parameters not written (a write error), type 0x3835, 9 bytes.
    ParametersWriteError = 6,
    /// A ping request to the ESC, type 0x242C, 10 bytes: `01 FD 03 03 2C 24 00 01 60 60` as
    /// Rotorflight writes it.
    PingRequest = 7,
}

impl Kind {
    /// Number of kinds.
    pub const COUNT: usize = 8;

    /// Every kind, in the order of their values.
    pub const ALL: [Kind; Kind::COUNT] = [
        Kind::Telemetry,
        Kind::Ping,
        Kind::DeviceInfo,
        Kind::Reset,
        Kind::ParametersRead,
        Kind::ParametersWritten,
        Kind::ParametersWriteError,
        Kind::PingRequest,
    ];

    /// The frame's length on the wire, CRC included.
    pub const fn wire_len(self) -> usize {
        match self {
            Kind::Telemetry => TELEMETRY_LEN,
            Kind::Ping => 11,
            Kind::DeviceInfo => 73,
            Kind::Reset => 10,
            Kind::ParametersRead => MAX_FRAME_LEN,
            Kind::ParametersWritten => 58,
            Kind::ParametersWriteError => 9,
            Kind::PingRequest => 10,
        }
    }

    /// The frame type (bytes 4-5, little-endian).
    pub const fn frame_type(self) -> u16 {
        match self {
            Kind::Telemetry => TYPE_TELEMETRY,
            Kind::Ping | Kind::PingRequest => TYPE_PING,
            Kind::DeviceInfo => TYPE_DEVICE_INFO,
            Kind::Reset => TYPE_RESET,
            Kind::ParametersRead | Kind::ParametersWritten | Kind::ParametersWriteError => {
                TYPE_PARAMETERS
            }
        }
    }

    /// Who sends it.
    pub const fn direction(self) -> Direction {
        match self {
            Kind::PingRequest => Direction::ToEsc,
            _ => Direction::FromEsc,
        }
    }

    /// The first three bytes of a frame of this kind.
    pub const fn envelope(self) -> [u8; 3] {
        envelope(self.direction())
    }

    /// The stable machine name, e.g. `device_info`.
    pub const fn name(self) -> &'static str {
        match self {
            Kind::Telemetry => "telemetry",
            Kind::Ping => "ping",
            Kind::DeviceInfo => "device_info",
            Kind::Reset => "reset",
            Kind::ParametersRead => "parameters_read",
            Kind::ParametersWritten => "parameters_written",
            Kind::ParametersWriteError => "parameters_write_error",
            Kind::PingRequest => "ping_request",
        }
    }
}

impl core::fmt::Display for Kind {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// The first three bytes of a frame sent in `direction`.
pub const fn envelope(direction: Direction) -> [u8; 3] {
    match direction {
        Direction::FromEsc => [ESC_START, ESC_ADDRESS, ESC_BYTE2],
        Direction::ToEsc => [ESC_ADDRESS, REQUEST_MARK, REQUEST_BYTE2],
    }
}

/// The direction of a frame whose first two bytes are `first`, `second`, if either.
#[inline(always)]
pub(crate) const fn direction_of(first: u8, second: u8) -> Option<Direction> {
    match (first, second) {
        (ESC_START, ESC_ADDRESS) => Some(Direction::FromEsc),
        (ESC_ADDRESS, REQUEST_MARK) => Some(Direction::ToEsc),
        _ => None,
    }
}

/// The kinds a frame of this direction, code (byte 3) and type (bytes 4-5) can be, shortest
/// first; empty when its length cannot be known.
///
/// Only telemetry depends on the code (it must be 03); for the other kinds the spec gives no
/// code, so any is taken. Parameters come in three lengths under one type: the CRC decides,
/// the shortest that verifies is taken.
pub const fn kinds_of(direction: Direction, code: u8, frame_type: u16) -> &'static [Kind] {
    match (direction, frame_type) {
        (Direction::FromEsc, TYPE_TELEMETRY) if code == TELEMETRY_CODE => &[Kind::Telemetry],
        (Direction::FromEsc, TYPE_PING) => &[Kind::Ping],
        (Direction::FromEsc, TYPE_DEVICE_INFO) => &[Kind::DeviceInfo],
        (Direction::FromEsc, TYPE_RESET) => &[Kind::Reset],
        (Direction::FromEsc, TYPE_PARAMETERS) => &[
            Kind::ParametersWriteError,
            Kind::ParametersWritten,
            Kind::ParametersRead,
        ],
        (Direction::ToEsc, TYPE_PING) => &[Kind::PingRequest],
        _ => &[],
    }
}

const _: () = {
    assert!(TELEMETRY_CHECK_AT + CHECKSUM.width() == TELEMETRY_LEN);
    assert!(at::UNUSED + 6 == TELEMETRY_CHECK_AT);
    assert!(at::BEC_CURRENT + 1 == at::UNUSED);
    assert!(PAYLOAD_LEN_AT + 1 + TELEMETRY_PAYLOAD_LEN as usize == TELEMETRY_CHECK_AT);
    // The decoder holds up to MAX_FRAME_LEN - 1 bytes with a one-byte count.
    assert!(MAX_FRAME_LEN - 1 <= u8::MAX as usize);
    let mut i = 0;
    while i < Kind::COUNT {
        let kind = Kind::ALL[i];
        assert!(kind as usize == i);
        assert!(kind.wire_len() <= MAX_FRAME_LEN && kind.wire_len() > HEADER_LEN);
        i += 1;
    }
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_is_found_from_its_header_and_only_there() {
        for kind in Kind::ALL {
            let code = if kind == Kind::Telemetry {
                TELEMETRY_CODE
            } else {
                0x5A
            };
            let kinds = kinds_of(kind.direction(), code, kind.frame_type());
            assert!(kinds.contains(&kind), "{kind}");
            assert!(kinds.windows(2).all(|w| w[0].wire_len() < w[1].wire_len()));
            let other = match kind.direction() {
                Direction::FromEsc => Direction::ToEsc,
                Direction::ToEsc => Direction::FromEsc,
            };
            assert!(!kinds_of(other, code, kind.frame_type()).contains(&kind));
        }
        assert!(kinds_of(Direction::FromEsc, 0x04, TYPE_TELEMETRY).is_empty());
        assert!(kinds_of(Direction::FromEsc, 0x03, 0x0C30).is_empty());
        assert_eq!(
            Kind::ALL.iter().map(|k| k.wire_len()).max(),
            Some(MAX_FRAME_LEN)
        );
        assert_eq!(TELEMETRY_HEADER, [0xFE, 0x01, 0x00, 0x03, 0x30, 0x5C, 0x17]);
        assert_eq!(direction_of(0xFE, 0x01), Some(Direction::FromEsc));
        assert_eq!(direction_of(0x01, 0xFD), Some(Direction::ToEsc));
        assert_eq!(direction_of(0xFD, 0x01), None);
    }
}
