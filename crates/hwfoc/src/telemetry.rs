//! The protocol-neutral reading of a frame: what every layer above the codec works through.
//!
//! Each protocol's data frame implements [`Telemetry`]: for every [`Quantity`] it says whether
//! the frame carries it and, if so, its raw integer as sent and the exact [`Conversion`] of that
//! integer to the quantity's unit (`docs/RECORD-SCHEMA.md`). Statistics are kept on the raw
//! integers and converted once (exact means); records convert each value.
//!
//! [`Data`] is a data frame of any supported protocol and [`Info`] a device-information frame of
//! any, each an enum with one arm per protocol; [`AnyFrame`] is either, as decoders hand them to the
//! layers above. Both are declared from the list of formats (`formats!` in `lib.rs`): a new
//! protocol's line there gives it its `Data` arm (and `Info` arm, where it sends an information
//! frame, through [`DeviceInfo`]); its own module implements
//! [`Telemetry`] for its data frame. This module names no protocol's module.
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

use crate::format::{DeviceInfo, InfoValue};
use crate::protocol::Protocol;
use crate::status::Status;
use crate::units::{Linear, Quantity, Settings, Temperature};

/// 0 degC in kelvins.
const KELVIN_AT_0_C: f32 = 273.15;

/// The value of a float16's bits; `None` for NaN (DroneCAN's "unknown").
fn half(raw: i32) -> Option<f32> {
    let v = crate::wire::f32_from_f16(u16::try_from(raw).ok()?);
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
    V4Current(crate::units::CurrentScale),
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
            Conversion::Ntc => u16::try_from(raw).ok().and_then(crate::ntc::ntc_celsius),
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

    /// The frame's faults as HW-FOC's sixteen status bits, for a frame sent on in HW-FOC's
    /// layout (a DataLink hub's record): HW-FOC's own word; another format's faults mapped to
    /// the HW-FOC bit of the same fault where one clearly is (HW5); [`Status::OK`] where a
    /// format's flags have no HW-FOC meaning (the default).
    fn hwfoc_status(&self) -> Status {
        Status::OK
    }

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

/// `From<$data> for Data`, for a format whose data frame is its own (`data`), not one it
/// shares with a format listed before it (`shares`).
macro_rules! data_from {
    (data, $arm:ident, $data:ty) => {
        impl From<$data> for Data {
            #[inline]
            fn from(frame: $data) -> Data {
                Data::$arm(frame)
            }
        }
    };
    (shares, $arm:ident, $data:ty) => {};
}

/// Declares [`Data`] from the list of formats (`formats!` in `lib.rs`): its arms, their
/// `From` conversions, its [`Telemetry`] and [`Data::protocol`].
macro_rules! declare_data {
    ($( $(#[$doc:meta])* $arm:ident => $description:path, $kind:ident $data:ty
        $(, info $info:ty)? $(, family $family:ident($scanner:ty) rank $rank:literal)?; )+) => {
        /// A data frame of any supported protocol: one arm per protocol (its data frame, as
        /// the list of formats names it), so that what a record says of its source
        /// ([`Data::protocol`]) is a property of the frame, as its readings are.
        ///
        /// `From<foc::DataFrame>` gives the HW-FOC arm (an ESC's own wire); a DataLink V2
        /// hub's record, which carries the same payload, is made as `Data::DataLink(frame)`.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Data {
            $( $(#[$doc])* $arm($data), )+
        }

        $( data_from!($kind, $arm, $data); )+

        impl Telemetry for Data {
            #[inline(always)]
            fn packet(&self) -> Option<u32> {
                match self {
                    $( Data::$arm(f) => Telemetry::packet(f), )+
                }
            }

            #[inline(always)]
            fn status(&self) -> Option<Status> {
                match self {
                    $( Data::$arm(f) => Telemetry::status(f), )+
                }
            }

            fn hwfoc_status(&self) -> Status {
                match self {
                    $( Data::$arm(f) => Telemetry::hwfoc_status(f), )+
                }
            }

            #[inline(always)]
            fn reading(&self, quantity: Quantity, settings: &Settings) -> Option<Reading> {
                match self {
                    $( Data::$arm(f) => f.reading(quantity, settings), )+
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
                    $( Data::$arm(_) => Protocol::$arm, )+
                }
            }
        }
    };
}

formats!(declare_data);

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

    /// A standard DroneCAN ESC's `esc_index` (which of its node's ESCs it is); `None` for a
    /// Hobbywing CAN ESC (one per node) and a serial format.
    #[inline]
    pub const fn esc_index(&self) -> Option<u8> {
        match self {
            Data::DroneCan(e) => Some(e.esc_index),
            _ => None,
        }
    }

    /// Where the ESC is on its CAN bus: a Hobbywing ESC's throttle channel - 1 once a GetEscID
    /// answer mapped its node, until then its node id; a standard ESC's `esc_index`. `None` for
    /// a serial format.
    #[inline]
    pub fn bus_place(&self) -> Option<u8> {
        match self {
            Data::HwCan(e) => Some(e.bus_place()),
            Data::DroneCan(e) => Some(e.bus_place()),
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

/// Declares [`Info`] from the list of formats (`formats!` in `lib.rs`): one arm for each
/// format there with an `info` frame, its `From` conversions and its dispatch to
/// [`DeviceInfo`].
macro_rules! declare_info {
    ($( $(#[$doc:meta])* $arm:ident => $description:path, $kind:ident $data:ty
        $(, info $info:ty)? $(, family $family:ident($scanner:ty) rank $rank:literal)?; )+) => {
        /// A device-information frame of any supported protocol.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Info {
            $($(
                #[doc = concat!("A device-information frame of [`Protocol::", stringify!($arm), "`].")]
                $arm($info),
            )?)+
        }

        $($(
            impl From<$info> for Info {
                #[inline]
                fn from(info: $info) -> Info {
                    Info::$arm(info)
                }
            }
        )?)+

        impl Info {
            /// The protocol the frame was received in.
            #[inline]
            pub const fn protocol(&self) -> Protocol {
                match self {
                    $($( Info::$arm(i) => { let _: &$info = i; Protocol::$arm } )?)+
                }
            }

            /// The frame's [`DeviceInfo`].
            #[inline]
            fn device(&self) -> &dyn DeviceInfo {
                match self {
                    $($( Info::$arm(i) => { let i: &$info = i; i } )?)+
                }
            }
        }
    };
}

formats!(declare_info);

impl Info {
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
        keys.zip(self.device().values().into_iter().flatten())
    }

    /// The product name, e.g. `X6`.
    pub fn product(&self) -> &str {
        self.device().product()
    }

    /// The hardware version.
    pub fn hardware(&self) -> &str {
        self.device().hardware()
    }

    /// The firmware version.
    pub fn firmware(&self) -> &str {
        self.device().firmware()
    }

    /// The device's identifier.
    pub fn id(&self) -> &str {
        self.device().id()
    }
}

impl core::fmt::Display for Info {
    /// The device's text as each protocol shows it (HW-FOC: its words joined by single spaces;
    /// V4: its constants).
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.device().fmt(f)
    }
}

/// A frame of any supported protocol as the layers above the codec take it: data, or device
/// information.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AnyFrame {
    /// A data frame.
    Data(Data),
    /// A device-information frame.
    Info(Info),
}
