//! The HW5 telemetry frame (read, written, converted), its fault byte, and the check of any
//! frame kind ([`identify`]).
//!
//! ```text
//!  0-6                   7-8    9    10-11    12     13-14   15-16   17-18   19   20   21    22     23     24-29  30-31
//!  FE 01 00 03 30 5C 17  06 00  thr  unknown  fault  erpm/10 V*10    A*10    ESC  BEC  motor BEC V  BEC A  FF..   CRC_L CRC_H
//!                                                    (LE)    (LE)    (LE)    degC degC degC  *10    *10
//! ```

use crate::format::FaultDescription;
use crate::format::Severity::{Critical, Warning};
use crate::status::Status;
use crate::telemetry::{Reading, Telemetry};
use crate::units::{Linear, Quantity, Settings};
use crate::wire::CheckError;

use super::error::Error;
use super::layout::{
    AMPS, CHECKSUM, CODE_AT, ERPM, HEADER_LEN, Kind, PAYLOAD_LEN_AT, TELEMETRY_BYTES_7_8,
    TELEMETRY_CHECK_AT, TELEMETRY_HEADER, TELEMETRY_LEN, TELEMETRY_PAYLOAD_LEN, TYPE_AT, VOLTS, at,
    direction_of, kinds_of,
};

/// One bit of a telemetry frame's fault byte (byte 12), as Rotorflight names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum Fault {
    /// Bit 0: motor locked (protection).
    MotorLocked = 0,
    /// Bit 1: over-temperature (protection).
    OverTemperature = 1,
    /// Bit 2: throttle not at zero at start-up.
    ThrottleNotZeroAtStart = 2,
    /// Bit 3: throttle signal lost.
    ThrottleSignalLost = 3,
    /// Bit 4: over-current.
    OverCurrent = 4,
    /// Bit 5: low voltage.
    LowVoltage = 5,
    /// Bit 6: input voltage error.
    InputVoltageError = 6,
    /// Bit 7: motor connection error.
    MotorConnectionError = 7,
}

impl Fault {
    /// All eight flags in bit order.
    pub const ALL: [Fault; 8] = [
        Fault::MotorLocked,
        Fault::OverTemperature,
        Fault::ThrottleNotZeroAtStart,
        Fault::ThrottleSignalLost,
        Fault::OverCurrent,
        Fault::LowVoltage,
        Fault::InputVoltageError,
        Fault::MotorConnectionError,
    ];

    /// The stable machine name, e.g. `throttle_signal_lost`.
    pub const fn name(self) -> &'static str {
        FAULTS[self as usize].name
    }

    /// A short English description, e.g. "throttle signal lost".
    pub const fn description(self) -> &'static str {
        FAULTS[self as usize].description
    }
}

/// The eight bits of HW5's fault byte, bit 0 first: each [`Fault`]'s name, description and
/// severity (throttle-signal and voltage problems are warnings, the rest critical).
pub const FAULTS: [FaultDescription; 8] = [
    FaultDescription::new("motor_locked", "motor locked", Critical),
    FaultDescription::new("over_temperature", "over-temperature", Critical),
    FaultDescription::new(
        "throttle_not_zero_at_start",
        "throttle not at zero at start-up",
        Warning,
    ),
    FaultDescription::new("throttle_signal_lost", "throttle signal lost", Warning),
    FaultDescription::new("over_current", "over-current", Critical),
    FaultDescription::new("low_voltage", "low voltage", Warning),
    FaultDescription::new("input_voltage_error", "input voltage error", Warning),
    FaultDescription::new("motor_connection_error", "motor connection error", Critical),
];

/// The raw fault byte with named access to its flags.
///
/// ```
/// use hwfoc::hw5::{Fault, FaultCode};
///
/// let code = FaultCode(0b1000_1000);
/// assert!(code.contains(Fault::ThrottleSignalLost));
/// let names: Vec<&str> = code.faults().map(|f| f.name()).collect();
/// assert_eq!(names, ["throttle_signal_lost", "motor_connection_error"]);
/// assert_eq!(code.to_string(), "throttle_signal_lost|motor_connection_error");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct FaultCode(pub u8);

crate::status::fault_flags!(
    Fault,
    FaultCode,
    /// Iterator over the flags set in a fault byte, in bit order.
    Faults,
    u8,
    "fault byte",
    7
);

impl Fault {
    /// The HW-FOC status bit for the same fault, where one clearly is: motor locked is
    /// [`motor_blocked`](crate::Fault::MotorBlocked), throttle not at zero at start-up
    /// [`throttle_not_zeroed`](crate::Fault::ThrottleNotZeroed), throttle signal lost,
    /// over-current, and low voltage [`input_voltage_low`](crate::Fault::InputVoltageLow).
    /// `None` for over-temperature (HW-FOC tells a MOSFET from a capacitor overheat; HW5 does
    /// not say which), input voltage error (too high or too low?) and motor connection error
    /// (HW-FOC names open bridges and shorts, none clearly this).
    pub const fn hwfoc(self) -> Option<crate::Fault> {
        use crate::Fault as Foc;
        match self {
            Fault::MotorLocked => Some(Foc::MotorBlocked),
            Fault::ThrottleNotZeroAtStart => Some(Foc::ThrottleNotZeroed),
            Fault::ThrottleSignalLost => Some(Foc::ThrottleSignalLost),
            Fault::OverCurrent => Some(Foc::OverCurrent),
            Fault::LowVoltage => Some(Foc::InputVoltageLow),
            Fault::OverTemperature | Fault::InputVoltageError | Fault::MotorConnectionError => None,
        }
    }
}

impl FaultCode {
    /// The HW-FOC status word of the same faults ([`Fault::hwfoc`]); a fault without an HW-FOC
    /// bit is left out.
    ///
    /// ```
    /// use hwfoc::hw5::{Fault, FaultCode};
    ///
    /// let code = FaultCode::OK.with(Fault::LowVoltage).with(Fault::OverTemperature);
    /// assert_eq!(code.hwfoc_status(), hwfoc::Status::OK.with(hwfoc::Fault::InputVoltageLow));
    /// ```
    pub fn hwfoc_status(self) -> Status {
        self.faults()
            .filter_map(Fault::hwfoc)
            .fold(Status::OK, Status::with)
    }
}

/// One HW5 telemetry frame (type 0x5C30), every field as the raw integer sent on the wire;
/// physical values come from the conversion methods.
///
/// Bytes 7-8 (`06 00`) and 24-29 (`FF`) are not kept: decoding does not check them,
/// [`TelemetryFrame::encode`] writes the spec's values. Bytes 10-11, of unknown meaning, are
/// kept as [`TelemetryFrame::unknown`] and written back.
///
/// ```
/// use hwfoc::hw5::{Fault, FaultCode, TelemetryFrame};
///
/// let frame = TelemetryFrame {
///     throttle: 42,
///     fault: FaultCode::OK.with(Fault::LowVoltage),
///     erpm_raw: 5000,
///     voltage_raw: 504,
///     current_raw: 123,
///     esc_temp: 45,
///     bec_temp: 40,
///     motor_temp: 60,
///     bec_voltage_raw: 84,
///     bec_current_raw: 15,
///     ..Default::default()
/// };
/// let bytes = frame.encode();
/// assert_eq!(bytes[..7], [0xFE, 0x01, 0x00, 0x03, 0x30, 0x5C, 0x17]);
/// assert_eq!(bytes[13..15], [0x88, 0x13]); // 5000, little-endian
/// assert_eq!(TelemetryFrame::parse(&bytes)?, frame);
/// assert_eq!(frame.erpm(), 50_000);
/// assert_eq!(frame.voltage_v(), 50.4);
/// assert_eq!(frame.current_a(), 12.3);
/// assert_eq!(frame.bec_voltage_v(), 8.4);
/// # Ok::<(), hwfoc::hw5::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct TelemetryFrame {
    /// Throttle in percent (byte 9): one value, no input/output split.
    pub throttle: u8,
    /// Bytes 10-11, meaning unknown.
    pub unknown: [u8; 2],
    /// The fault byte (byte 12): eight named flags.
    pub fault: FaultCode,
    /// Electrical RPM divided by 10 (bytes 13-14).
    pub erpm_raw: u16,
    /// Input voltage in units of 0.1 V (bytes 15-16).
    pub voltage_raw: u16,
    /// Input current in units of 0.1 A (bytes 17-18). While the throttle is 0 the ESC repeats
    /// its last reading until the motor has stopped: this is what the wire says (see
    /// [`TelemetryFrame::driven_current_raw`]).
    pub current_raw: u16,
    /// ESC (MOSFET) temperature in degC (byte 19).
    pub esc_temp: u8,
    /// BEC temperature in degC (byte 20).
    pub bec_temp: u8,
    /// Motor temperature in degC (byte 21).
    pub motor_temp: u8,
    /// BEC voltage in units of 0.1 V (byte 22).
    pub bec_voltage_raw: u8,
    /// BEC current in units of 0.1 A (byte 23).
    pub bec_current_raw: u8,
}

/// The largest throttle a telemetry frame carries: 100 (percent).
pub const THROTTLE_MAX_PCT: u8 = 100;

/// The largest input voltage a telemetry frame is believed: 100.0 V (raw, in 0.1 V). HW5 ESCs
/// are rated up to 14S (61 V charged, LiHV); the margin takes a regenerative-braking spike. A
/// frame over it is counted as [out of range](super::Stats::out_of_range), never handed on.
pub const VOLTAGE_MAX_RAW: u16 = 1000;

impl TelemetryFrame {
    /// Decodes a telemetry frame from the first [`TELEMETRY_LEN`] bytes of `bytes` (bytes
    /// after it are ignored), checking in this order: length, envelope (`FE 01 00`), code and
    /// type (`03`, 0x5C30), payload length (`17`), CRC, the values' ranges.
    pub fn parse(bytes: &[u8]) -> Result<TelemetryFrame, Error> {
        let Some(f) = bytes.first_chunk::<TELEMETRY_LEN>() else {
            return Err(Error::Truncated {
                needed: TELEMETRY_LEN,
                got: bytes.len(),
            });
        };
        if f[..3] != TELEMETRY_HEADER[..3] {
            return Err(Error::Envelope {
                found: [f[0], f[1], f[2]],
            });
        }
        if f[CODE_AT..HEADER_LEN] != TELEMETRY_HEADER[CODE_AT..HEADER_LEN] {
            return Err(Error::NotTelemetry {
                code: f[CODE_AT],
                frame_type: u16::from_le_bytes([f[TYPE_AT], f[TYPE_AT + 1]]),
            });
        }
        if f[PAYLOAD_LEN_AT] != TELEMETRY_PAYLOAD_LEN {
            return Err(Error::PayloadLength {
                found: f[PAYLOAD_LEN_AT],
            });
        }
        check(f)?;
        let frame = Self::from_verified(f);
        match frame.out_of_range() {
            Some((field, raw, max)) => Err(Error::OutOfRange { field, raw, max }),
            None => Ok(frame),
        }
    }

    /// The first field outside the range the protocol allows ([`THROTTLE_MAX_PCT`],
    /// [`VOLTAGE_MAX_RAW`]), with its raw value and the largest allowed, if any.
    pub(crate) fn out_of_range(&self) -> Option<(&'static str, u16, u16)> {
        let throttle = (self.throttle > THROTTLE_MAX_PCT).then_some((
            "throttle",
            u16::from(self.throttle),
            u16::from(THROTTLE_MAX_PCT),
        ));
        throttle.or((self.voltage_raw > VOLTAGE_MAX_RAW).then_some((
            "input voltage",
            self.voltage_raw,
            VOLTAGE_MAX_RAW,
        )))
    }

    /// Reads the fields of a frame whose header and CRC were already verified.
    #[inline]
    pub(crate) fn from_verified(f: &[u8; TELEMETRY_LEN]) -> TelemetryFrame {
        let le = |i: usize| u16::from_le_bytes([f[i], f[i + 1]]);
        TelemetryFrame {
            throttle: f[at::THROTTLE],
            unknown: [f[at::UNKNOWN], f[at::UNKNOWN + 1]],
            fault: FaultCode(f[at::FAULT]),
            erpm_raw: le(at::ERPM),
            voltage_raw: le(at::VOLTAGE),
            current_raw: le(at::CURRENT),
            esc_temp: f[at::ESC_TEMP],
            bec_temp: f[at::BEC_TEMP],
            motor_temp: f[at::MOTOR_TEMP],
            bec_voltage_raw: f[at::BEC_VOLTAGE],
            bec_current_raw: f[at::BEC_CURRENT],
        }
    }

    /// Encodes the frame as the 32 bytes an ESC sends: header, `06 00`, the fields, six `FF`
    /// and the CRC.
    pub fn encode(&self) -> [u8; TELEMETRY_LEN] {
        let mut f = [0u8; TELEMETRY_LEN];
        f[..TELEMETRY_HEADER.len()].copy_from_slice(&TELEMETRY_HEADER);
        f[7..9].copy_from_slice(&TELEMETRY_BYTES_7_8);
        f[at::THROTTLE] = self.throttle;
        f[at::UNKNOWN..at::UNKNOWN + 2].copy_from_slice(&self.unknown);
        f[at::FAULT] = self.fault.0;
        f[at::ERPM..at::ERPM + 2].copy_from_slice(&self.erpm_raw.to_le_bytes());
        f[at::VOLTAGE..at::VOLTAGE + 2].copy_from_slice(&self.voltage_raw.to_le_bytes());
        f[at::CURRENT..at::CURRENT + 2].copy_from_slice(&self.current_raw.to_le_bytes());
        f[at::ESC_TEMP] = self.esc_temp;
        f[at::BEC_TEMP] = self.bec_temp;
        f[at::MOTOR_TEMP] = self.motor_temp;
        f[at::BEC_VOLTAGE] = self.bec_voltage_raw;
        f[at::BEC_CURRENT] = self.bec_current_raw;
        f[at::UNUSED..TELEMETRY_CHECK_AT].fill(0xFF);
        CHECKSUM.seal(&mut f);
        f
    }

    /// Throttle in percent, as sent (0..=100 on a working ESC).
    pub fn throttle_pct(&self) -> f32 {
        f32::from(self.throttle)
    }

    /// Electrical RPM (raw * 10).
    pub fn erpm(&self) -> u32 {
        u32::from(self.erpm_raw) * 10
    }

    /// Input voltage in volts (raw / 10).
    pub fn voltage_v(&self) -> f32 {
        VOLTS.to_f32(f32::from(self.voltage_raw))
    }

    /// Input current in amperes (raw / 10), as the wire says it: while the throttle is 0 this
    /// is the ESC's last reading repeated until the motor has stopped.
    pub fn current_a(&self) -> f32 {
        AMPS.to_f32(f32::from(self.current_raw))
    }

    /// The current Rotorflight integrates into consumption: [`current_raw`](Self::current_raw),
    /// or 0 while the throttle is 0 (where the ESC repeats a stale reading). An energy
    /// integration that follows Rotorflight's rule uses this; the record keeps the wire's value.
    pub const fn driven_current_raw(&self) -> u16 {
        if self.throttle == 0 {
            0
        } else {
            self.current_raw
        }
    }

    /// ESC (MOSFET) temperature in degC.
    pub fn esc_temp_c(&self) -> f32 {
        f32::from(self.esc_temp)
    }

    /// BEC temperature in degC.
    pub fn bec_temp_c(&self) -> f32 {
        f32::from(self.bec_temp)
    }

    /// Motor temperature in degC.
    pub fn motor_temp_c(&self) -> f32 {
        f32::from(self.motor_temp)
    }

    /// BEC voltage in volts (raw / 10).
    pub fn bec_voltage_v(&self) -> f32 {
        VOLTS.to_f32(f32::from(self.bec_voltage_raw))
    }

    /// BEC current in amperes (raw / 10).
    pub fn bec_current_a(&self) -> f32 {
        AMPS.to_f32(f32::from(self.bec_current_raw))
    }
}

impl Telemetry for TelemetryFrame {
    /// None: HW5 sends no packet counter.
    #[inline]
    fn packet(&self) -> Option<u32> {
        None
    }

    /// The fault byte as a fault word of eight bits ([`Fault`]'s, named through
    /// [`Protocol::Hw5`](crate::Protocol::fault_name)).
    #[inline]
    fn status(&self) -> Option<Status> {
        Some(Status(u16::from(self.fault.0)))
    }

    /// Its faults mapped to HW-FOC's bits ([`FaultCode::hwfoc_status`]).
    fn hwfoc_status(&self) -> Status {
        self.fault.hwfoc_status()
    }

    /// Throttle (one value: the input throttle's column) in percent as sent, eRPM / 10,
    /// voltages and currents in tenths, temperatures in degC; no output throttle, phase current
    /// or capacitor temperature. Current is the wire's (see [`TelemetryFrame::current_raw`]).
    #[inline]
    fn reading(&self, quantity: Quantity, settings: &Settings) -> Option<Reading> {
        let linear = |raw: u16, linear| Reading::linear(i32::from(raw), linear);
        Some(match quantity {
            Quantity::ThrottleIn => linear(self.throttle.into(), Linear::IDENTITY),
            Quantity::Erpm => linear(self.erpm_raw, ERPM),
            Quantity::Rpm => linear(self.erpm_raw, settings.rpm_linear()),
            Quantity::Voltage => linear(self.voltage_raw, VOLTS),
            Quantity::Current => linear(self.current_raw, AMPS),
            Quantity::MosTemp => linear(self.esc_temp.into(), Linear::IDENTITY),
            Quantity::MotorTemp => linear(self.motor_temp.into(), Linear::IDENTITY),
            Quantity::BecTemp => linear(self.bec_temp.into(), Linear::IDENTITY),
            Quantity::BecVoltage => linear(self.bec_voltage_raw.into(), VOLTS),
            Quantity::BecCurrent => linear(self.bec_current_raw.into(), AMPS),
            Quantity::ThrottleOut | Quantity::PhaseCurrent | Quantity::CapTemp => return None,
        })
    }
}

/// Checks the CRC at the end of `frame` (a whole frame).
fn check(frame: &[u8]) -> Result<(), Error> {
    match CHECKSUM.verify(frame) {
        Ok(()) => Ok(()),
        Err(CheckError::Checksum { expected, found }) => Err(Error::Crc { expected, found }),
        Err(_) => Err(Error::Truncated {
            needed: 2,
            got: frame.len(),
        }),
    }
}

/// Whether the CRC of a whole candidate of `len` bytes at the start of `candidate` matches
/// (`candidate` holds at least `len` bytes).
#[inline(always)]
pub(crate) fn crc_ok(candidate: &[u8], len: usize) -> bool {
    candidate
        .get(..len)
        .is_some_and(|f| CHECKSUM.verify(f).is_ok())
}

/// The kind of the frame at the start of `bytes` (any kind the scanner knows; bytes after it
/// are ignored), checked as the scanner checks a candidate: envelope, code and type, a
/// telemetry frame's payload length byte, then the CRC of each length its type allows,
/// shortest first.
///
/// ```
/// use hwfoc::hw5::{Kind, TelemetryFrame, identify};
///
/// let ping = [0x01, 0xFD, 0x03, 0x03, 0x2C, 0x24, 0x00, 0x01, 0x60, 0x60];
/// assert_eq!(identify(&ping), Ok(Kind::PingRequest));
/// assert_eq!(identify(&TelemetryFrame::default().encode()), Ok(Kind::Telemetry));
/// ```
pub fn identify(bytes: &[u8]) -> Result<Kind, Error> {
    let Some(h) = bytes.first_chunk::<HEADER_LEN>() else {
        return Err(Error::Truncated {
            needed: HEADER_LEN,
            got: bytes.len(),
        });
    };
    let found = [h[0], h[1], h[2]];
    let Some(direction) = direction_of(h[0], h[1]) else {
        return Err(Error::Envelope { found });
    };
    if found != super::layout::envelope(direction) {
        return Err(Error::Envelope { found });
    }
    let code = h[CODE_AT];
    let frame_type = u16::from_le_bytes([h[TYPE_AT], h[TYPE_AT + 1]]);
    let kinds = kinds_of(direction, code, frame_type);
    let Some(&first) = kinds.first() else {
        return Err(Error::UnknownType {
            direction,
            code,
            frame_type,
        });
    };
    if first == Kind::Telemetry
        && let Some(&b) = bytes.get(PAYLOAD_LEN_AT)
        && b != TELEMETRY_PAYLOAD_LEN
    {
        return Err(Error::PayloadLength { found: b });
    }
    let mut last = Err(Error::Truncated {
        needed: first.wire_len(),
        got: bytes.len(),
    });
    for &kind in kinds {
        let Some(frame) = bytes.get(..kind.wire_len()) else {
            // A longer kind cannot be checked: report the shortest failure, or the truncation.
            return match last {
                Err(Error::Crc { .. }) | Ok(_) => Err(Error::Truncated {
                    needed: kind.wire_len(),
                    got: bytes.len(),
                }),
                e => e,
            };
        };
        match check(frame) {
            Ok(()) => return Ok(kind),
            Err(e) => last = Err(e),
        }
    }
    last
}

#[cfg(test)]
mod tests {
    use super::super::layout::{Direction, ERPM};
    use super::*;
    use crate::wire::crc16_modbus;

    fn sample() -> TelemetryFrame {
        TelemetryFrame {
            throttle: 57,
            unknown: [0x12, 0x34],
            fault: FaultCode(0b0010_0001),
            erpm_raw: 0xABCD,
            voltage_raw: 252,
            current_raw: 0x0102,
            esc_temp: 61,
            bec_temp: 48,
            motor_temp: 75,
            bec_voltage_raw: 84,
            bec_current_raw: 23,
        }
    }

    /// The bytes of `encode`, checked one by one against the spec's table.
    #[test]
    fn encode_writes_the_spec_layout() {
        let b = sample().encode();
        assert_eq!(
            b[..9],
            [0xFE, 0x01, 0x00, 0x03, 0x30, 0x5C, 0x17, 0x06, 0x00]
        );
        assert_eq!(b[9], 57);
        assert_eq!(b[10..12], [0x12, 0x34]);
        assert_eq!(b[12], 0x21);
        assert_eq!(b[13..15], [0xCD, 0xAB]);
        assert_eq!(b[15..17], [252, 0]);
        assert_eq!(b[17..19], [0x02, 0x01]);
        assert_eq!(b[19..24], [61, 48, 75, 84, 23]);
        assert_eq!(b[24..30], [0xFF; 6]);
        let crc = crc16_modbus(&b[..30]);
        assert_eq!(b[30..], [crc as u8, (crc >> 8) as u8]);
        assert_eq!(TelemetryFrame::parse(&b), Ok(sample()));
    }

    #[test]
    fn conversions() {
        let f = sample();
        assert_eq!(f.erpm(), 0xABCD * 10);
        assert_eq!(ERPM.to_f32(f32::from(f.erpm_raw)), (0xABCD * 10) as f32);
        assert_eq!(f.voltage_v(), 25.2);
        assert_eq!(f.current_a(), 25.8);
        assert_eq!(f.driven_current_raw(), 258);
        let idle = TelemetryFrame { throttle: 0, ..f };
        assert_eq!((idle.current_raw, idle.driven_current_raw()), (258, 0));
        assert_eq!(idle.current_a(), 25.8);
        assert_eq!(f.esc_temp_c(), 61.0);
        assert_eq!(f.bec_temp_c(), 48.0);
        assert_eq!(f.motor_temp_c(), 75.0);
        assert_eq!(f.bec_voltage_v(), 8.4);
        assert_eq!(f.bec_current_a(), 2.3);
        assert_eq!(f.throttle_pct(), 57.0);
        let faults: [Fault; 2] = [Fault::MotorLocked, Fault::LowVoltage];
        assert!(f.fault.faults().eq(faults));
    }

    #[test]
    fn parse_errors_in_order() {
        let good = sample().encode();
        assert_eq!(
            TelemetryFrame::parse(&good[..31]),
            Err(Error::Truncated {
                needed: 32,
                got: 31
            })
        );
        let mut b = good;
        b[2] = 0x03;
        b[3] = 0x04;
        assert_eq!(
            TelemetryFrame::parse(&b),
            Err(Error::Envelope {
                found: [0xFE, 0x01, 0x03]
            })
        );
        b[2] = 0x00;
        assert_eq!(
            TelemetryFrame::parse(&b),
            Err(Error::NotTelemetry {
                code: 4,
                frame_type: 0x5C30
            })
        );
        b[3] = 0x03;
        b[6] = 0x18;
        assert_eq!(
            TelemetryFrame::parse(&b),
            Err(Error::PayloadLength { found: 0x18 })
        );
        b[6] = 0x17;
        b[20] ^= 0x40;
        assert_eq!(
            TelemetryFrame::parse(&b),
            Err(Error::Crc {
                expected: crc16_modbus(&b[..30]),
                found: u16::from_le_bytes([b[30], b[31]])
            })
        );
    }

    #[test]
    fn fault_names_in_bit_order() {
        let names: [&str; 8] = Fault::ALL.map(Fault::name);
        assert_eq!(
            names,
            [
                "motor_locked",
                "over_temperature",
                "throttle_not_zero_at_start",
                "throttle_signal_lost",
                "over_current",
                "low_voltage",
                "input_voltage_error",
                "motor_connection_error"
            ]
        );
        for (i, f) in Fault::ALL.into_iter().enumerate() {
            assert_eq!((f.bit(), f.mask()), (i as u8, 1 << i));
            assert_eq!(Fault::from_bit(i as u8), Some(f));
            assert_eq!(Fault::from_name(f.name()), Some(f));
        }
        assert_eq!(Fault::from_bit(8), None);
        let all: FaultCode = Fault::ALL.into_iter().collect();
        assert_eq!(all, FaultCode(0xFF));
        assert_eq!(all.faults().len(), 8);
        assert!(FaultCode::OK.is_ok() && FaultCode::OK.faults().next().is_none());
    }

    #[test]
    fn identify_every_kind_and_the_shortest_parameters_first() {
        for kind in Kind::ALL {
            let mut f = [0x77u8; 105];
            f[..3].copy_from_slice(&kind.envelope());
            f[3] = 0x03;
            f[4..6].copy_from_slice(&kind.frame_type().to_le_bytes());
            f[6] = 0x17;
            CHECKSUM.seal(&mut f[..kind.wire_len()]);
            assert_eq!(identify(&f[..kind.wire_len()]), Ok(kind), "{kind}");
            // Whatever follows: the kind's own length decides (the parameters variants
            // shorter than it fail their CRC).
            assert_eq!(identify(&f), Ok(kind), "{kind}");
            let mut bad = f;
            bad[kind.wire_len() - 3] ^= 0x01;
            assert!(identify(&bad[..kind.wire_len()]).is_err(), "{kind}");
        }
        assert_eq!(
            identify(&[0x01, 0xFD, 0x03, 0x03, 0x2C, 0x25, 0x00, 0x20, 0xF1, 0xB8]),
            Err(Error::UnknownType {
                direction: Direction::ToEsc,
                code: 3,
                frame_type: 0x252C
            })
        );
        assert_eq!(
            identify(&[0xFD, 0x01, 0x00, 0x03, 0x2C, 0x24]),
            Err(Error::Envelope {
                found: [0xFD, 0x01, 0x00]
            })
        );
    }
}
