//! What a format says of itself: one [`FormatDescription`] per format, declared in its own
//! module (`foc::DESCRIPTION`, `datalink::DESCRIPTION`, ...) and reached through
//! [`Protocol::description`](crate::Protocol::description). Everything that used to match on a
//! protocol for a fact (its name, baud rate, frame period, counter width, what it carries, its
//! faults and their severity, its device-information fields, its settings) reads it here.
//!
//! ```
//! use hwfoc::{Protocol, Quantity};
//! use hwfoc::format::{LinkKind, Severity};
//!
//! let hw5 = Protocol::Hw5.description();
//! assert_eq!(hw5.name, "hw5");
//! assert_eq!(hw5.link, LinkKind::OneEsc);
//! assert!(hw5.carries.contains(Quantity::BecVoltage));
//! assert_eq!(hw5.fault(0).map(|f| f.severity), Some(Severity::Critical));
//! assert_eq!(Protocol::DataLink.description().link, LinkKind::Hub { channels: 8 });
//! ```

use core::time::Duration;

use crate::units::{Quantity, Settings};
use crate::wire::Checksum;

/// Everything the layers above the codec know of a format, in one place.
#[derive(Debug, Clone, Copy)]
pub struct FormatDescription {
    /// The name users give and outputs show: `hw-foc`, `datalink`, `hw-v4`, ...
    pub name: &'static str,
    /// The name in prose: `HW-FOC`, `DataLink V2`, ...
    pub title: &'static str,
    /// The baud rate its senders use (8N1); for a CAN format, the bus's bit rate as Hobbywing's
    /// ESCs leave the factory.
    pub baud_rate: u32,
    /// What sends it: one ESC, a hub of several, or a bus.
    pub link: LinkKind,
    /// The length in bytes of a data frame on its wire (of a CAN format: a CAN frame's 16-byte
    /// record): how many frames a silence of the line can have hidden.
    pub data_frame_len: usize,
    /// The width of its packet counter in bits, or `None` where it sends none.
    pub counter_bits: Option<u32>,
    /// How its frames are checked.
    pub check: Check,
    /// The interval between two data frames of a running ESC (what raw bytes without receive
    /// times are timed at); `None` where frames always come with times (CAN).
    pub frame_period: Option<Duration>,
    /// The interval between two data frames of an idle ESC, where it differs from
    /// [`FormatDescription::frame_period`] (HW5: 400 ms); `None` where it does not.
    pub idle_frame_period: Option<Duration>,
    /// The quantities its data frames carry.
    pub carries: Quantities,
    /// Its fault word's bits, bit 0 first (empty where its frames carry no fault word).
    pub faults: &'static [FaultDescription],
    /// The keys of its device-information fields, in the order
    /// [`Info::fields`](crate::telemetry::Info::fields) gives them (empty where it sends none).
    pub info_keys: &'static [&'static str],
    /// For a format whose info frame, once adopted (two identical copies), sets its
    /// conversions: the name under which outputs give the adopted frame's fields (V4:
    /// `v4_info`); `None` for any other.
    pub adopted_info: Option<&'static str>,
    /// Its own settings (beyond the common pole pairs, gear ratio and current scale).
    pub settings: &'static [SettingDescription],
}

impl FormatDescription {
    /// Bit `bit` of its fault word, or `None` for a bit it does not define.
    pub const fn fault(&self, bit: u8) -> Option<&'static FaultDescription> {
        let faults = self.faults;
        if (bit as usize) < faults.len() {
            Some(&faults[bit as usize])
        } else {
            None
        }
    }

    /// Whether it is carried on a CAN bus, not a serial line.
    pub const fn is_can(&self) -> bool {
        matches!(self.link, LinkKind::Bus)
    }
}

/// What sends a format's frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkKind {
    /// One ESC on its own wire.
    OneEsc,
    /// A hub that relays the frames of up to `channels` ESCs on one wire.
    Hub {
        /// How many ESC channels a frame has.
        channels: u8,
    },
    /// A CAN bus of ESCs, each a node.
    Bus,
}

impl LinkKind {
    /// How many of a stream's channels are numbered once its channel `heard` is heard: a hub's
    /// all at once, a bus's slots up to the one heard (one ESC's wire has no channel but its
    /// own: up to the one heard as well).
    ///
    /// ```
    /// use hwfoc::format::LinkKind;
    ///
    /// assert_eq!(LinkKind::Hub { channels: 8 }.channels_numbered(2), 8);
    /// assert_eq!(LinkKind::Bus.channels_numbered(2), 3);
    /// ```
    pub const fn channels_numbered(self, heard: u8) -> usize {
        match self {
            LinkKind::Hub { channels } => channels as usize,
            LinkKind::OneEsc | LinkKind::Bus => heard as usize + 1,
        }
    }
}

/// How a format's frames are checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Check {
    /// Not at all: frames are recognised by their fixed bytes and chains (V3, V4).
    None,
    /// By check bytes of the frame ([`Checksum`]).
    Checksum(Checksum),
    /// By the CAN controller's CRC of each CAN frame and a multi-frame transfer's CRC.
    CanTransfer,
}

/// A set of [`Quantity`]s, as a const bit set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Quantities(u16);

impl Quantities {
    /// The set of `quantities`.
    pub const fn of(quantities: &[Quantity]) -> Quantities {
        let mut bits = 0u16;
        let mut i = 0;
        while i < quantities.len() {
            bits |= 1 << quantities[i] as u16;
            i += 1;
        }
        Quantities(bits)
    }

    /// Every quantity but `quantities`.
    pub const fn all_but(quantities: &[Quantity]) -> Quantities {
        let all = Quantities::of(&Quantity::ALL).0;
        Quantities(all & !Quantities::of(quantities).0)
    }

    /// Whether `quantity` is in the set.
    #[inline(always)]
    pub const fn contains(self, quantity: Quantity) -> bool {
        self.0 & (1 << quantity as u16) != 0
    }
}

/// How bad a fault bit is, for alarms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    /// Worth watching: voltage limits, throttle-signal problems, unassigned bits.
    Warning,
    /// Act now: faults that damage hardware or stop the motor.
    Critical,
}

impl Severity {
    /// The severity of a bit no format defines.
    pub const UNKNOWN: Severity = Severity::Warning;
}

/// One bit of a format's fault word.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultDescription {
    /// The stable machine name every output uses, e.g. `mos_overheat`.
    pub name: &'static str,
    /// A short English description, e.g. `MOSFET overheat`.
    pub description: &'static str,
    /// How bad it is.
    pub severity: Severity,
}

impl FaultDescription {
    /// A fault named `name`, described by `description`, of `severity`.
    pub const fn new(
        name: &'static str,
        description: &'static str,
        severity: Severity,
    ) -> FaultDescription {
        FaultDescription {
            name,
            description,
            severity,
        }
    }
}

/// A value of a device-information field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InfoValue<'a> {
    /// Text, e.g. a product name.
    Text(&'a str),
    /// A whole number, e.g. a V4 scale constant.
    Number(u32),
}

/// What a format's device-information frame says of the device, as
/// [`Info`](crate::telemetry::Info) asks it of each format's frame: implemented in each format's
/// module that sends one.
pub trait DeviceInfo: core::fmt::Display {
    /// The values of its fields, in the order of its description's
    /// [`info_keys`](FormatDescription::info_keys), the rest `None`.
    fn values(&self) -> [Option<InfoValue<'_>>; MAX_INFO_FIELDS];

    /// The product name, e.g. `X6` (empty where the frame names none).
    fn product(&self) -> &str {
        ""
    }

    /// The hardware version (empty where the frame names none).
    fn hardware(&self) -> &str {
        ""
    }

    /// The firmware version (empty where the frame names none).
    fn firmware(&self) -> &str {
        ""
    }

    /// The device's identifier (empty where the frame names none).
    fn id(&self) -> &str {
        ""
    }
}

/// The largest number of device-information fields of any format (V4's eight constants).
pub const MAX_INFO_FIELDS: usize = 8;

/// `values` in an array of [`MAX_INFO_FIELDS`], the rest `None`.
pub(crate) fn padded<'a, const N: usize>(
    values: [InfoValue<'a>; N],
) -> [Option<InfoValue<'a>>; MAX_INFO_FIELDS] {
    let mut out = [None; MAX_INFO_FIELDS];
    for (slot, v) in out.iter_mut().zip(values) {
        *slot = Some(v);
    }
    out
}

/// A format's own setting: what `--set KEY=VALUE`, a configuration key and Python's
/// `settings={...}` take.
#[derive(Debug, Clone, Copy)]
pub struct SettingDescription {
    /// The key, e.g. `v4_volts_per_step`.
    pub key: &'static str,
    /// The value's form in words, e.g. `N/D`.
    pub form: &'static str,
    /// The default, written as the setting takes it.
    pub default: &'static str,
    /// One line of help.
    pub help: &'static str,
    /// Sets it in `settings` from its text, or says why the text is not a value.
    pub apply: fn(&mut Settings, &str) -> Result<(), &'static str>,
}
