//! The protocol-neutral reading of a frame: what every layer above the codec works through.
//!
//! Each protocol's data frame implements [`Telemetry`]: for every [`Quantity`] it says whether
//! the frame carries it and, if so, its raw integer as sent and the exact [`Conversion`] of that
//! integer to the quantity's unit (`docs/RECORD-SCHEMA.md`). Statistics are kept on the raw
//! integers and converted once (exact means); records convert each value.
//!
//! [`Data`] is a data frame of any supported protocol and [`Info`] a device-information frame of
//! any, each an enum with one arm per protocol; [`Frame`] is either, as decoders hand them to the
//! layers above. A new protocol adds its arm to each (the compiler names every `match` that
//! must learn it; none exists outside this module).
//!
//! ```
//! use hwfoc::telemetry::{Data, Telemetry};
//! use hwfoc::{Quantity, Settings};
//!
//! let bytes = [0x9B, 0x16, 0x01, 0x02, 0x05, 0xC2, 0, 0, 0, 0, 0, 0, 0x00, 0xF7,
//!              0xFF, 0xFF, 0xFF, 0xFF, 0xCE, 0xD1, 0x00, 0x00, 0x0D, 0x08];
//! let data = Data::from(hwfoc::foc::DataFrame::parse(&bytes)?);
//! let s = Settings::default();
//! assert_eq!(data.packet(), Some(1474));
//! assert_eq!(data.value(Quantity::Voltage, &s), Some(24.7));
//! assert_eq!(data.reading(Quantity::Current, &s).map(|r| r.raw), Some(-1));
//! assert_eq!(data.value(Quantity::MosTemp, &s), Some(28.0));
//! # Ok::<(), hwfoc::foc::FrameError>(())
//! ```

use crate::foc::kinds::data::DataFrame;
use crate::foc::kinds::info::InfoFrame;
use crate::format::InfoValue;
use crate::protocol::Protocol;
use crate::status::Status;
use crate::units::{Linear, Quantity, Settings, Temperature};

/// 0 degC in kelvins.
const KELVIN_AT_0_C: f32 = 273.15;

/// The value of a float16's bits; `None` for NaN (DroneCAN's "unknown").
fn half(raw: i32) -> Option<f32> {
    let v = crate::dronecan::f32_from_f16(u16::try_from(raw).ok()?);
    (!v.is_nan()).then_some(v)
}

/// How a quantity's raw integer becomes its value in the quantity's unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Conversion {
    /// `raw * mul / (div * div2)` ([`Linear`]): every value is defined.
    Linear(Linear),
    /// An ADC code of the ESC's NTC thermistor, through the table of [`Temperature::from_adc`]:
    /// degC inside the table, no value outside it.
    AdcTable,
    /// A 12-bit ADC code of a Hobbywing V4 ESC's NTC thermistor, through its formula
    /// ([`crate::v4::ntc_celsius`]): no value for 0 (no reading).
    Ntc,
    /// A Hobbywing V4 current ADC code through its info frame's constants,
    /// `adc * I1 / I2 - I3`, not below 0 ([`crate::v4::CurrentScale`]).
    V4Current(crate::v4::CurrentScale),
    /// A float16's bits (DroneCAN's `float16`), the value in its unit.
    Half,
    /// A float16's bits holding kelvins, the value in degC (`- 273.15`).
    HalfKelvin,
}

impl Conversion {
    /// The value of `raw` as an `f32`, or `None` where the conversion has none (a temperature
    /// code outside its table).
    #[inline]
    pub fn to_f32(self, raw: i32) -> Option<f32> {
        match self {
            Conversion::Linear(linear) => Some(linear.to_f32(raw as f32)),
            Conversion::AdcTable => u8::try_from(raw)
                .ok()
                .and_then(|code| Temperature::from_adc(code).celsius()),
            Conversion::Ntc => u16::try_from(raw).ok().and_then(crate::v4::ntc_celsius),
            Conversion::V4Current(scale) => u16::try_from(raw).ok().map(|adc| scale.amps(adc)),
            Conversion::Half => half(raw),
            Conversion::HalfKelvin => half(raw).map(|k| k - KELVIN_AT_0_C),
        }
    }

    /// The linear conversion, if this is one (what statistics of raw values, such as a mean,
    /// convert through: [`Linear::to_f64`]).
    #[inline]
    pub fn linear(self) -> Option<Linear> {
        match self {
            Conversion::Linear(linear) => Some(linear),
            Conversion::AdcTable
            | Conversion::Ntc
            | Conversion::V4Current(_)
            | Conversion::Half
            | Conversion::HalfKelvin => None,
        }
    }
}

/// A quantity as a frame carries it: the raw integer sent, and its conversion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reading {
    /// The integer on the wire (sign-extended where the field is signed).
    pub raw: i32,
    /// How `raw` becomes the quantity's value.
    pub conversion: Conversion,
}

impl Reading {
    /// `raw` under the linear conversion `linear` (every protocol's most common reading).
    #[inline(always)]
    pub const fn linear(raw: i32, linear: Linear) -> Reading {
        Reading {
            raw,
            conversion: Conversion::Linear(linear),
        }
    }

    /// The value in the quantity's unit, or `None` where the conversion has none.
    #[inline]
    pub fn value(self) -> Option<f32> {
        self.conversion.to_f32(self.raw)
    }
}

/// The protocol-neutral reading of a data frame: which quantities it carries, as sent and
/// converted. Implemented by every protocol's data frame, and by [`Data`].
pub trait Telemetry {
    /// The frame's packet counter, where the protocol sends one (16 bits in HW-FOC and
    /// DataLink, 24 in the older formats; HW5 has none).
    fn packet(&self) -> Option<u32>;

    /// The frame's status word (sixteen fault bits, [`Status`]), where the protocol sends one.
    fn status(&self) -> Option<Status>;

    /// `quantity` as this frame carries it under `settings` (which only conversions that depend
    /// on the user's setup read: pole pairs, gear ratio, current scale), or `None` when the
    /// frame's protocol does not carry it.
    fn reading(&self, quantity: Quantity, settings: &Settings) -> Option<Reading>;

    /// The raw integer of `quantity`, or `None` when the frame's protocol does not carry it. The
    /// integer is what was sent: it does not depend on the settings (only its conversion may).
    #[inline(always)]
    fn raw(&self, quantity: Quantity) -> Option<i32> {
        self.reading(quantity, &Settings::DEFAULT).map(|r| r.raw)
    }

    /// `quantity` in its unit, or `None` when it is not carried or has no value.
    #[inline]
    fn value(&self, quantity: Quantity, settings: &Settings) -> Option<f32> {
        self.reading(quantity, settings).and_then(Reading::value)
    }
}

impl Telemetry for DataFrame {
    #[inline(always)]
    fn packet(&self) -> Option<u32> {
        Some(u32::from(self.packet))
    }

    #[inline(always)]
    fn status(&self) -> Option<Status> {
        Some(self.status)
    }

    #[inline(always)]
    fn reading(&self, quantity: Quantity, settings: &Settings) -> Option<Reading> {
        let linear = Reading::linear;
        let adc = |code: u8| Reading {
            raw: i32::from(code),
            conversion: Conversion::AdcTable,
        };
        Some(match quantity {
            Quantity::ThrottleIn => linear(self.throttle_in_raw.into(), Linear::THROTTLE_PCT),
            Quantity::ThrottleOut => linear(self.throttle_out_raw.into(), Linear::THROTTLE_PCT),
            Quantity::Erpm => linear(self.erpm_raw.into(), Linear::ERPM),
            Quantity::Rpm => linear(self.erpm_raw.into(), settings.rpm_linear()),
            Quantity::Voltage => linear(self.voltage_raw.into(), Linear::VOLTS),
            Quantity::Current => linear(self.current_raw.into(), settings.amps_linear()),
            Quantity::PhaseCurrent => linear(self.phase_current_raw.into(), settings.amps_linear()),
            Quantity::MosTemp => adc(self.mos_adc),
            Quantity::CapTemp => adc(self.cap_adc),
            Quantity::MotorTemp
            | Quantity::BecTemp
            | Quantity::BecVoltage
            | Quantity::BecCurrent => return None,
        })
    }
}

/// Declares an enum with one arm per protocol and its `From` conversions.
macro_rules! per_protocol {
    (
        $(#[$attr:meta])* pub enum $name:ident {
            $( $(#[$arm_attr:meta])* $arm:ident($inner:ty), )+
        }
    ) => {
        $(#[$attr])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum $name {
            $( $(#[$arm_attr])* $arm($inner), )+
        }

        $(
            impl From<$inner> for $name {
                #[inline]
                fn from(inner: $inner) -> $name {
                    $name::$arm(inner)
                }
            }
        )+
    };
}

/// A data frame of any supported protocol: one arm per protocol, so that what a record says
/// of its source ([`Data::protocol`]) is a property of the frame, as its readings are.
///
/// `From<foc::DataFrame>` gives the HW-FOC arm (an ESC's own wire); a DataLink V2 hub's record,
/// which carries the same payload, is made as `Data::DataLink(frame)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Data {
    /// An HW-FOC data frame, from an ESC's own wire.
    HwFoc(DataFrame),
    /// A DataLink V2 hub's record of one ESC channel: the HW-FOC payload the hub forwards.
    DataLink(DataFrame),
    /// A Hobbywing V4 data frame, with the info frame adopted when it was decoded.
    HwV4(crate::v4::Data),
    /// A Hobbywing V3 frame.
    HwV3(crate::v3::Frame),
    /// An HW5 telemetry frame.
    Hw5(crate::hw5::TelemetryFrame),
    /// A Hobbywing CAN ESC's record at a `StatusMsg1` (with its node's slower messages).
    HwCan(crate::dronecan::HwCanEsc),
    /// A standard DroneCAN ESC's record at a `uavcan.equipment.esc.Status`.
    DroneCan(crate::dronecan::DroneCanEsc),
}

impl From<crate::dronecan::HwCanEsc> for Data {
    #[inline]
    fn from(esc: crate::dronecan::HwCanEsc) -> Data {
        Data::HwCan(esc)
    }
}

impl From<crate::dronecan::DroneCanEsc> for Data {
    #[inline]
    fn from(esc: crate::dronecan::DroneCanEsc) -> Data {
        Data::DroneCan(esc)
    }
}

impl From<crate::v4::Data> for Data {
    #[inline]
    fn from(data: crate::v4::Data) -> Data {
        Data::HwV4(data)
    }
}

impl From<crate::v3::Frame> for Data {
    #[inline]
    fn from(frame: crate::v3::Frame) -> Data {
        Data::HwV3(frame)
    }
}

impl From<crate::hw5::TelemetryFrame> for Data {
    #[inline]
    fn from(frame: crate::hw5::TelemetryFrame) -> Data {
        Data::Hw5(frame)
    }
}

impl From<DataFrame> for Data {
    /// The HW-FOC arm: a frame from an ESC's own wire.
    #[inline]
    fn from(frame: DataFrame) -> Data {
        Data::HwFoc(frame)
    }
}

impl Telemetry for Data {
    #[inline(always)]
    fn packet(&self) -> Option<u32> {
        match self {
            Data::HwFoc(f) | Data::DataLink(f) => f.packet(),
            Data::HwV4(f) => Telemetry::packet(f),
            Data::HwV3(f) => Telemetry::packet(f),
            Data::Hw5(f) => Telemetry::packet(f),
            Data::HwCan(f) => Telemetry::packet(f),
            Data::DroneCan(f) => Telemetry::packet(f),
        }
    }

    #[inline(always)]
    fn status(&self) -> Option<Status> {
        match self {
            Data::HwFoc(f) | Data::DataLink(f) => Telemetry::status(f),
            Data::HwV4(f) => Telemetry::status(f),
            Data::HwV3(f) => Telemetry::status(f),
            Data::Hw5(f) => Telemetry::status(f),
            Data::HwCan(f) => Telemetry::status(f),
            Data::DroneCan(f) => Telemetry::status(f),
        }
    }

    #[inline(always)]
    fn reading(&self, quantity: Quantity, settings: &Settings) -> Option<Reading> {
        match self {
            Data::HwFoc(f) | Data::DataLink(f) => f.reading(quantity, settings),
            Data::HwV4(f) => f.reading(quantity, settings),
            Data::HwV3(f) => f.reading(quantity, settings),
            Data::Hw5(f) => f.reading(quantity, settings),
            Data::HwCan(f) => f.reading(quantity, settings),
            Data::DroneCan(f) => f.reading(quantity, settings),
        }
    }
}

impl Data {
    /// The protocol the frame was received in (the record's `protocol` column).
    ///
    /// ```
    /// use hwfoc::Protocol;
    /// use hwfoc::foc::DataFrame;
    /// use hwfoc::telemetry::Data;
    ///
    /// assert_eq!(Data::from(DataFrame::default()).protocol(), Protocol::HwFoc);
    /// assert_eq!(Data::DataLink(DataFrame::default()).protocol(), Protocol::DataLink);
    /// ```
    #[inline(always)]
    pub const fn protocol(&self) -> Protocol {
        match self {
            Data::HwFoc(_) => Protocol::HwFoc,
            Data::DataLink(_) => Protocol::DataLink,
            Data::HwV4(_) => Protocol::HwV4,
            Data::HwV3(_) => Protocol::HwV3,
            Data::Hw5(_) => Protocol::Hw5,
            Data::HwCan(_) => Protocol::HwCan,
            Data::DroneCan(_) => Protocol::DroneCan,
        }
    }

    /// The HW-FOC data frame this frame is, for outputs that speak HW-FOC: an HW-FOC frame
    /// itself, or what a DataLink V2 hub record holds (the hub forwards HW-FOC payloads);
    /// `None` for another protocol's frame, whose fields HW-FOC's do not hold as sent.
    #[inline]
    pub fn to_hwfoc(&self) -> Option<DataFrame> {
        match self {
            Data::HwFoc(f) | Data::DataLink(f) => Some(*f),
            Data::HwV4(_) | Data::HwV3(_) | Data::Hw5(_) | Data::HwCan(_) | Data::DroneCan(_) => {
                None
            }
        }
    }
}

impl Data {
    /// The frame's fault word: its [`Telemetry::status`] where its protocol has fault bits
    /// ([`Protocol::has_faults`]; a Hobbywing CAN ESC's `status` word is kept raw but is no
    /// fault word).
    #[inline(always)]
    pub fn fault_word(&self) -> Option<Status> {
        self.status().filter(|_| self.protocol().has_faults())
    }

    /// The CAN node that sent the record (`hw-can`, `dronecan`); `None` for a serial format.
    #[inline]
    pub const fn node(&self) -> Option<u8> {
        match self {
            Data::HwCan(e) => Some(e.node),
            Data::DroneCan(e) => Some(e.node),
            _ => None,
        }
    }

    /// Where the ESC is on its CAN bus: a Hobbywing ESC's throttle channel - 1 once a GetEscID
    /// answer mapped its node, until then its node id; a standard ESC's `esc_index`. `None` for
    /// a serial format.
    #[inline]
    pub fn bus_index(&self) -> Option<u8> {
        match self {
            Data::HwCan(e) => Some(e.bus_index()),
            Data::DroneCan(e) => Some(e.bus_index()),
            _ => None,
        }
    }

    /// The age in milliseconds of the record's values from the second message of its ESC: a
    /// Hobbywing CAN ESC's `StatusMsg2` (voltage, current), a standard ESC's `StatusExtended`
    /// (throttles, motor temperature); `None` otherwise or where times are unknown.
    #[inline]
    pub const fn msg2_age_ms(&self) -> Option<u32> {
        match self {
            Data::HwCan(e) => e.msg2_age_ms,
            Data::DroneCan(e) => e.ext_age_ms,
            _ => None,
        }
    }

    /// The age in milliseconds of a Hobbywing CAN ESC's `StatusMsg3` values (temperatures) at
    /// the record; `None` otherwise or where times are unknown.
    #[inline]
    pub const fn msg3_age_ms(&self) -> Option<u32> {
        match self {
            Data::HwCan(e) => e.msg3_age_ms,
            _ => None,
        }
    }
}

per_protocol! {
    /// A device-information frame of any supported protocol.
    pub enum Info {
        /// An HW-FOC device-information frame.
        HwFoc(InfoFrame),
        /// A Hobbywing V4 info frame: the ESC's scales, no names.
        HwV4(crate::v4::InfoFrame),
    }
}

impl Info {
    /// The protocol the frame was received in.
    #[inline]
    pub const fn protocol(&self) -> Protocol {
        match self {
            Info::HwFoc(_) => Protocol::HwFoc,
            Info::HwV4(_) => Protocol::HwV4,
        }
    }

    /// What the frame says of the device, as key/value pairs: the keys of its protocol's
    /// description ([`FormatDescription::info_keys`](crate::format::FormatDescription)) with
    /// this frame's values.
    ///
    /// ```
    /// use hwfoc::format::InfoValue;
    /// use hwfoc::telemetry::Info;
    /// use hwfoc::v4::InfoFrame;
    ///
    /// let v4 = InfoFrame { full_scale: 1000, v1: 8, v2: 91, i1: 0, i2: 1, i3: 0, t1: 0x21, t2: 0x21 };
    /// let info = Info::HwV4(v4);
    /// let fields: Vec<_> = info.fields().collect();
    /// assert_eq!(fields[0], ("full_scale", InfoValue::Number(1000)));
    /// assert_eq!(fields.len(), 8);
    /// ```
    pub fn fields(&self) -> impl Iterator<Item = (&'static str, InfoValue<'_>)> {
        let keys = self.protocol().description().info_keys.iter().copied();
        let values: [Option<InfoValue<'_>>; 8] = match self {
            Info::HwFoc(i) => padded(crate::foc::description::info_values(i)),
            Info::HwV4(i) => padded(crate::v4::description::info_values(i)),
        };
        keys.zip(values.into_iter().flatten())
    }

    /// The product name, e.g. `X6`.
    pub fn product(&self) -> &str {
        match self {
            Info::HwFoc(i) => i.product(),
            Info::HwV4(_) => "",
        }
    }

    /// The hardware version.
    pub fn hardware(&self) -> &str {
        match self {
            Info::HwFoc(i) => i.hardware(),
            Info::HwV4(_) => "",
        }
    }

    /// The firmware version.
    pub fn firmware(&self) -> &str {
        match self {
            Info::HwFoc(i) => i.firmware(),
            Info::HwV4(_) => "",
        }
    }

    /// The device's identifier.
    pub fn id(&self) -> &str {
        match self {
            Info::HwFoc(i) => i.id(),
            Info::HwV4(_) => "",
        }
    }
}

impl core::fmt::Display for Info {
    /// The device's text as each protocol shows it (HW-FOC: its words joined by single spaces;
    /// V4: its constants).
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Info::HwFoc(i) => i.fmt(f),
            Info::HwV4(i) => i.fmt(f),
        }
    }
}

/// `values` in an array of the largest number of information fields (8), the rest `None`.
fn padded<'a, const N: usize>(values: [InfoValue<'a>; N]) -> [Option<InfoValue<'a>>; 8] {
    let mut out = [None; 8];
    for (slot, v) in out.iter_mut().zip(values) {
        *slot = Some(v);
    }
    out
}

/// A frame of any supported protocol as the layers above the codec take it: data, or device
/// information.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Frame {
    /// A data frame.
    Data(Data),
    /// A device-information frame.
    Info(Info),
}

impl From<crate::v4::Frame> for Frame {
    #[inline(always)]
    fn from(frame: crate::v4::Frame) -> Frame {
        match frame {
            crate::v4::Frame::Data(d) => Frame::Data(Data::HwV4(d)),
            crate::v4::Frame::Info(i) => Frame::Info(Info::HwV4(i)),
        }
    }
}

impl From<crate::foc::frame::Frame> for Frame {
    #[inline(always)]
    fn from(frame: crate::foc::frame::Frame) -> Frame {
        match frame {
            crate::foc::frame::Frame::Data(f) => Frame::Data(Data::HwFoc(f)),
            crate::foc::frame::Frame::Info(i) => Frame::Info(Info::HwFoc(i)),
        }
    }
}
