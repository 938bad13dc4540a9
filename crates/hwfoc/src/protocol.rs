//! The protocols hwfoc reads, by name: what a user names to force one
//! (`hwfoc decode --protocol datalink`) instead of letting the bytes tell
//! ([`crate::mixed`] reads every protocol at once).

use core::fmt;

use crate::format::{FormatDescription, SettingDescription};
use crate::scan::{Scanner, StreamDecoder};
use crate::status::Status;
use crate::units::{Quantity, Settings};

/// Declares [`Protocol`] from the list of formats (`formats!` in `lib.rs`), with
/// [`Protocol::ALL`] and [`Protocol::description`].
macro_rules! declare_protocol {
    ($( $(#[$doc:meta])* $arm:ident => $description:path, $kind:ident $data:ty
        $(, info $info:ty)? $(, family $family:ident($scanner:ty) rank $rank:literal)?; )+) => {
        /// A wire protocol the codec reads.
        ///
        /// ```
        /// use hwfoc::Protocol;
        ///
        /// assert_eq!(Protocol::from_name("datalink"), Some(Protocol::DataLink));
        /// assert_eq!(Protocol::HwFoc.to_string(), "hw-foc");
        /// assert_eq!(Protocol::HwFoc.baud_rate(), hwfoc::foc::BAUD_RATE);
        /// ```
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Protocol {
            $( $(#[$doc])* $arm, )+
        }

        impl Protocol {
            /// Every protocol, in the order they are listed to a user.
            pub const ALL: [Protocol; [$(Protocol::$arm),+].len()] = [$(Protocol::$arm),+];

            /// What the protocol says of itself: its module's `DESCRIPTION`.
            #[inline(always)]
            pub const fn description(self) -> &'static FormatDescription {
                match self {
                    $( Protocol::$arm => &$description, )+
                }
            }
        }
    };
}

formats!(declare_protocol);

/// How many of [`Protocol::ALL`] are serial.
const SERIAL_COUNT: usize = {
    let mut n = 0;
    let mut i = 0;
    while i < Protocol::ALL.len() {
        if !Protocol::ALL[i].is_can() {
            n += 1;
        }
        i += 1;
    }
    n
};

impl Protocol {
    /// The protocols of a serial line: all but the CAN protocols. (`--protocol` forces any of
    /// [`Protocol::ALL`]: a serial stream then reads that protocol only, a CAN bus keeps that
    /// protocol's records only.)
    pub const SERIAL: [Protocol; SERIAL_COUNT] = {
        let mut out = [Protocol::ALL[0]; SERIAL_COUNT];
        let (mut i, mut n) = (0, 0);
        while i < Protocol::ALL.len() {
            if !Protocol::ALL[i].is_can() {
                out[n] = Protocol::ALL[i];
                n += 1;
            }
            i += 1;
        }
        out
    };

    /// Its place in [`Protocol::ALL`] (the list of formats), `0..Protocol::ALL.len()`: the
    /// `protocol` column's dictionary key.
    ///
    /// ```
    /// use hwfoc::Protocol;
    ///
    /// for (i, p) in Protocol::ALL.into_iter().enumerate() {
    ///     assert_eq!(p.index(), i);
    /// }
    /// ```
    #[inline(always)]
    pub const fn index(self) -> usize {
        self as usize
    }

    /// Whether the protocol is carried on a CAN bus (`hw-can`, `dronecan`), not a serial line.
    pub const fn is_can(self) -> bool {
        self.description().is_can()
    }

    /// The protocol's name as users give it and outputs show it: `hw-foc`, `datalink`, `hw-v4`,
    /// `hw-v3`, `hw5`.
    pub const fn name(self) -> &'static str {
        self.description().name
    }

    /// The protocol's name in prose: `HW-FOC`, `DataLink V2`, `Hobbywing V4`, `Hobbywing V3`,
    /// `HW5`.
    pub const fn title(self) -> &'static str {
        self.description().title
    }

    /// The baud rate its senders use (8N1); for a CAN protocol, the bus's bit rate as
    /// Hobbywing's ESCs leave the factory ([`HOBBYWING_BITRATE`](crate::dronecan::HOBBYWING_BITRATE)).
    pub const fn baud_rate(self) -> u32 {
        self.description().baud_rate
    }

    /// The baud rate of a serial line carrying it ([`Protocol::baud_rate`]), or `None` for a
    /// CAN protocol: the rate a port is opened at when this protocol is forced.
    ///
    /// ```
    /// use hwfoc::Protocol;
    ///
    /// assert_eq!(Protocol::Hw5.serial_baud_rate(), Some(115_200));
    /// assert_eq!(Protocol::HwCan.serial_baud_rate(), None);
    /// ```
    pub const fn serial_baud_rate(self) -> Option<u32> {
        if self.is_can() {
            None
        } else {
            Some(self.baud_rate())
        }
    }

    /// The interval between two data frames of a running ESC, which raw bytes (without receive
    /// times) are timed at: 50 ms for HW-FOC and DataLink (a hub relays its ESCs' frames), 51 ms
    /// for V4, 19.5 ms for V3, 20 ms for HW5 ([`crate::hw5::FRAME_PERIOD_RUNNING`]); `None` for
    /// the CAN protocols, whose frames always come with times.
    ///
    /// ```
    /// use hwfoc::Protocol;
    /// use core::time::Duration;
    ///
    /// assert_eq!(Protocol::HwV3.frame_period(), Some(Duration::from_micros(19_500)));
    /// ```
    pub const fn frame_period(self) -> Option<core::time::Duration> {
        self.description().frame_period
    }

    /// The width of its packet counter in bits (which it wraps at), or `None` for a protocol
    /// that sends no counter: 16 for HW-FOC and DataLink, 24 for V3 and V4, none for HW5 and the
    /// CAN protocols (a transfer id is the transport's: its gaps are counted per node).
    pub const fn packet_bits(self) -> Option<u32> {
        self.description().counter_bits
    }

    /// How far a packet counter of this protocol advanced from `from` to `to`, wrapping at its
    /// width (`None` for a protocol without counter).
    ///
    /// ```
    /// use hwfoc::Protocol;
    ///
    /// assert_eq!(Protocol::HwFoc.packets_between(65_535, 1), Some(2));
    /// ```
    pub const fn packets_between(self, from: u32, to: u32) -> Option<u32> {
        match self.packet_bits() {
            Some(bits) => Some(to.wrapping_sub(from) & (u32::MAX >> (32 - bits))),
            None => None,
        }
    }

    /// Whether this protocol's data frames carry `quantity` at all (a frame may still have no
    /// value for it: a V3 start-up placeholder, a V4 temperature of 0, a V4 current before its
    /// info frame): the columns and fields shown for an ESC of this protocol.
    ///
    /// ```
    /// use hwfoc::{Protocol, Quantity};
    ///
    /// assert!(Protocol::HwFoc.carries(Quantity::PhaseCurrent));
    /// assert!(!Protocol::HwV3.carries(Quantity::Voltage));
    /// assert!(Protocol::Hw5.carries(Quantity::BecVoltage));
    /// ```
    pub const fn carries(self, quantity: Quantity) -> bool {
        self.description().carries.contains(quantity)
    }

    /// Whether this protocol's data frames carry a fault word (a record's `status` and
    /// `faults`): HW-FOC's and DataLink's sixteen status bits, HW5's eight fault bits. (A
    /// Hobbywing CAN ESC's `status` word is kept raw, but its only known bit is the direction:
    /// no fault bits.)
    pub const fn has_faults(self) -> bool {
        !self.description().faults.is_empty()
    }

    /// The name of bit `bit` of this protocol's fault word ([`Status`] holds it), as every
    /// output names it: HW-FOC's [`Fault`](crate::Fault), HW5's
    /// [`hw5::Fault`](crate::hw5::Fault); `None` for a bit it does not define.
    ///
    /// ```
    /// use hwfoc::Protocol;
    ///
    /// assert_eq!(Protocol::HwFoc.fault_name(14), Some("opamp_phase_a"));
    /// assert_eq!(Protocol::Hw5.fault_name(3), Some("throttle_signal_lost"));
    /// assert_eq!(Protocol::Hw5.fault_name(8), None);
    /// ```
    pub const fn fault_name(self, bit: u8) -> Option<&'static str> {
        match self.description().fault(bit) {
            Some(f) => Some(f.name),
            None => None,
        }
    }

    /// A short English description of bit `bit` of this protocol's fault word (see
    /// [`Protocol::fault_name`]).
    pub const fn fault_description(self, bit: u8) -> Option<&'static str> {
        match self.description().fault(bit) {
            Some(f) => Some(f.description),
            None => None,
        }
    }

    /// The names of the bits set in `status`, a fault word of this protocol, in bit order.
    pub fn fault_names(self, status: Status) -> impl Iterator<Item = &'static str> {
        (0..16u8)
            .filter(move |&bit| status.0 & (1 << bit) != 0)
            .filter_map(move |bit| self.fault_name(bit))
    }

    /// The protocol named `name` (as [`Protocol::name`] spells it, any case).
    pub fn from_name(name: &str) -> Option<Protocol> {
        Protocol::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(name))
    }
}

impl Protocol {
    /// Every format's own settings, in the order of [`Protocol::ALL`].
    pub fn settings() -> impl Iterator<Item = &'static SettingDescription> {
        Protocol::ALL
            .into_iter()
            .flat_map(|p| p.description().settings.iter())
    }

    /// The format setting whose key is `key` (`-` and `_` alike, any case).
    pub fn setting(key: &str) -> Option<&'static SettingDescription> {
        let norm = |c: u8| {
            if c == b'-' {
                b'_'
            } else {
                c.to_ascii_lowercase()
            }
        };
        let same = |a: &str| {
            a.len() == key.len() && a.bytes().zip(key.bytes()).all(|(x, y)| norm(x) == norm(y))
        };
        Self::settings().find(|s| same(s.key))
    }

    /// Sets the format setting `key` to `value` in `settings`.
    ///
    /// ```
    /// use hwfoc::{Protocol, Settings};
    /// use hwfoc::v4::VoltsPerStep;
    ///
    /// let mut s = Settings::default();
    /// Protocol::apply_setting(&mut s, "v4-volts-per-step", "hv")?;
    /// assert_eq!(s.v4_volts_per_step, VoltsPerStep::HIGH_VOLTAGE);
    /// assert!(Protocol::apply_setting(&mut s, "v4_volts_per_step", "8/0").is_err());
    /// assert!(Protocol::apply_setting(&mut s, "nope", "1").is_err());
    /// # Ok::<(), hwfoc::protocol::SettingError>(())
    /// ```
    pub fn apply_setting(
        settings: &mut Settings,
        key: &str,
        value: &str,
    ) -> Result<(), SettingError> {
        let setting = Self::setting(key).ok_or(SettingError::UnknownKey)?;
        (setting.apply)(settings, value).map_err(|reason| SettingError::Value {
            key: setting.key,
            reason,
        })
    }
}

/// Why a format setting was not set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SettingError {
    /// No format has a setting of that key.
    UnknownKey,
    /// The value is not one the setting takes.
    Value {
        /// The setting's key.
        key: &'static str,
        /// Why, in words.
        reason: &'static str,
    },
}

impl core::fmt::Display for SettingError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SettingError::UnknownKey => {
                f.write_str("no format has this setting; the settings are:")?;
                for s in Protocol::settings() {
                    write!(f, " {}", s.key)?;
                }
                Ok(())
            }
            SettingError::Value { key, reason } => write!(f, "{key}: {reason}"),
        }
    }
}

impl core::error::Error for SettingError {}

impl fmt::Display for Protocol {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A frame a serial format's decoder found: where it starts in the stream and which protocol
/// it came in (what [`Decoded`](crate::detect::Decoded) asks each family's frames).
pub trait FoundFrame {
    /// Offset of the frame's first byte in the stream.
    fn offset(&self) -> u64;
    /// The protocol the frame came in.
    fn protocol(&self) -> Protocol;
}

/// The scanner of a serial family that [`detect::Decoder`](crate::detect::Decoder) reads
/// (its line of the list of formats names it): what differs between the families' decoders.
pub trait FamilyScanner: Scanner<Item: FoundFrame> + Sized {
    /// The frames (data and information) a decoder with statistics `stats` has handed on.
    fn handed_on(stats: &Self::Stats) -> u64;

    /// The length of the frames whose count a silence is told in (HW-FOC's 24 bytes unless the
    /// family's frames are shorter).
    const SILENCE_FRAME_LEN: usize = 24;

    /// Tells `decoder` that the line was silent for a time in which at most `esc_frames`
    /// HW-FOC frames (24 byte times each) and `hub_frames` DataLink frames could have been sent:
    /// as many of its frames of [`FamilyScanner::SILENCE_FRAME_LEN`] as fit in that time.
    fn line_silent(
        decoder: &mut StreamDecoder<Self>,
        esc_frames: u32,
        hub_frames: u32,
        on_frame: &mut dyn FnMut(Self::Item),
    ) {
        let _ = hub_frames;
        let n = frames_in_silence(esc_frames, Self::SILENCE_FRAME_LEN);
        decoder.line_silent(n, on_frame);
    }
}

/// As many frames of `len` bytes as fit in the time of `esc_frames` HW-FOC frames (24 byte
/// times each).
pub fn frames_in_silence(esc_frames: u32, len: usize) -> u32 {
    u32::try_from((u64::from(esc_frames) * 24).div_ceil(len as u64)).unwrap_or(u32::MAX)
}

/// `impl FoundFrame for $decoded`, a decoder's frame with its `offset` field, all of protocol
/// `$protocol`.
macro_rules! found_frame {
    ($decoded:ty, $protocol:ident) => {
        impl $crate::protocol::FoundFrame for $decoded {
            #[inline]
            fn offset(&self) -> u64 {
                self.offset
            }

            #[inline]
            fn protocol(&self) -> $crate::Protocol {
                $crate::Protocol::$protocol
            }
        }
    };
}
pub(crate) use found_frame;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_reads_back_and_names_differ() {
        for p in Protocol::ALL {
            assert_eq!(Protocol::from_name(p.name()), Some(p));
            assert_eq!(
                Protocol::ALL
                    .iter()
                    .filter(|q| q.name() == p.name())
                    .count(),
                1
            );
        }
        assert_eq!(Protocol::from_name("HW-FOC"), Some(Protocol::HwFoc));
        assert_eq!(Protocol::from_name("hwfoc"), None);
        assert_eq!(Protocol::DataLink.baud_rate(), 115_200);
        assert_eq!(Protocol::Hw5.baud_rate(), 115_200);
        assert_eq!(Protocol::HwV4.baud_rate(), 19_200);
        assert_eq!(Protocol::HwV3.packets_between(0xFF_FFFF, 0), Some(1));
        assert_eq!(Protocol::Hw5.packets_between(1, 2), None);
    }

    #[test]
    fn the_list_makes_the_serial_protocols_and_each_description_is_its_own() {
        use Protocol as P;
        assert_eq!(
            Protocol::SERIAL,
            [P::HwFoc, P::DataLink, P::HwV4, P::HwV3, P::Hw5]
        );
        for p in Protocol::ALL {
            let d = p.description();
            assert_eq!(d.is_can(), !Protocol::SERIAL.contains(&p));
            // A format with fault bits names each of them once.
            assert!(d.faults.len() <= 16);
            for (bit, f) in d.faults.iter().enumerate() {
                assert_eq!(p.fault_name(bit as u8), Some(f.name));
                assert_eq!(d.faults.iter().filter(|g| g.name == f.name).count(), 1);
            }
            // Frames of a serial format are timed at its period; a bus's come with times.
            assert_eq!(d.frame_period.is_some(), !d.is_can(), "{p}");
        }
    }
}
