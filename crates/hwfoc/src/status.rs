//! The 16-bit status word: named fault flags.
//!
//! Bytes 20 (high) and 21 (low) of a data frame. Bit 0 is the least significant bit of the low
//! byte, bit 8 of the high byte. Names are those of `docs/PROTOCOL-NOTES.md` and are stable across every
//! output of the project.

use crate::format::FaultDescription;
use crate::format::Severity::{Critical, Warning};

/// One bit of the status word.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum Fault {
    /// Bit 0: input voltage is too high.
    InputVoltageHigh = 0,
    /// Bit 1: input voltage is too low.
    InputVoltageLow = 1,
    /// Bit 2: over current.
    OverCurrent = 2,
    /// Bit 3: not assigned by the vendor.
    Reserved3 = 3,
    /// Bit 4: the throttle signal is lost.
    ThrottleSignalLost = 4,
    /// Bit 5: the throttle is not returned to zero.
    ThrottleNotZeroed = 5,
    /// Bit 6: MOSFET overheat.
    MosOverheat = 6,
    /// Bit 7: capacitor overheat.
    CapOverheat = 7,
    /// Bit 8: motor is blocked.
    MotorBlocked = 8,
    /// Bit 9: open circuit of the upper bridge (MOSFET).
    UpperBridgeOpen = 9,
    /// Bit 10: MOSFET short circuit.
    MosShort = 10,
    /// Bit 11: open circuit of the lower bridge (MOSFET).
    LowerBridgeOpen = 11,
    /// Bit 12: operational amplifier abnormal, phase C.
    OpampPhaseC = 12,
    /// Bit 13: operational amplifier abnormal, phase B.
    OpampPhaseB = 13,
    /// Bit 14: operational amplifier abnormal, phase A.
    OpampPhaseA = 14,
    /// Bit 15: not assigned by the vendor.
    Reserved15 = 15,
}

impl Fault {
    /// All sixteen flags in bit order.
    pub const ALL: [Fault; 16] = [
        Fault::InputVoltageHigh,
        Fault::InputVoltageLow,
        Fault::OverCurrent,
        Fault::Reserved3,
        Fault::ThrottleSignalLost,
        Fault::ThrottleNotZeroed,
        Fault::MosOverheat,
        Fault::CapOverheat,
        Fault::MotorBlocked,
        Fault::UpperBridgeOpen,
        Fault::MosShort,
        Fault::LowerBridgeOpen,
        Fault::OpampPhaseC,
        Fault::OpampPhaseB,
        Fault::OpampPhaseA,
        Fault::Reserved15,
    ];

    /// The stable machine name used in every output, e.g. `mos_overheat`.
    pub const fn name(self) -> &'static str {
        FAULTS[self as usize].name
    }

    /// A short English description, e.g. "MOSFET overheat".
    pub const fn description(self) -> &'static str {
        FAULTS[self as usize].description
    }
}

/// The sixteen bits of HW-FOC's status word, bit 0 first: each [`Fault`]'s name, description and
/// severity (faults that damage hardware or stop the motor are critical; voltage limits,
/// throttle-signal problems and unassigned bits are warnings).
pub const FAULTS: [FaultDescription; 16] = [
    FaultDescription::new("input_voltage_high", "input voltage is too high", Warning),
    FaultDescription::new("input_voltage_low", "input voltage is too low", Warning),
    FaultDescription::new("over_current", "over current", Critical),
    FaultDescription::new("reserved_3", "not assigned (bit 3)", Warning),
    FaultDescription::new(
        "throttle_signal_lost",
        "the throttle signal is lost",
        Warning,
    ),
    FaultDescription::new(
        "throttle_not_zeroed",
        "the throttle is not returned to zero",
        Warning,
    ),
    FaultDescription::new("mos_overheat", "MOSFET overheat", Critical),
    FaultDescription::new("cap_overheat", "capacitor overheat", Critical),
    FaultDescription::new("motor_blocked", "motor is blocked", Critical),
    FaultDescription::new(
        "upper_bridge_open",
        "open circuit of upper bridge (MOSFET)",
        Critical,
    ),
    FaultDescription::new("mos_short", "MOSFET short circuit", Critical),
    FaultDescription::new(
        "lower_bridge_open",
        "open circuit of lower bridge (MOSFET)",
        Critical,
    ),
    FaultDescription::new(
        "opamp_phase_c",
        "operational amplifier abnormal, phase C",
        Critical,
    ),
    FaultDescription::new(
        "opamp_phase_b",
        "operational amplifier abnormal, phase B",
        Critical,
    ),
    FaultDescription::new(
        "opamp_phase_a",
        "operational amplifier abnormal, phase A",
        Critical,
    ),
    FaultDescription::new("reserved_15", "not assigned (bit 15)", Warning),
];

/// The raw status word with named access to its flags.
///
/// ```
/// use hwfoc::{Fault, Status};
///
/// let status = Status(0x1000 | 0x0040);
/// assert!(status.contains(Fault::MosOverheat));
/// let names: Vec<&str> = status.faults().map(|f| f.name()).collect();
/// assert_eq!(names, ["mos_overheat", "opamp_phase_c"]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Status(pub u16);

fault_flags!(
    Fault,
    Status,
    /// Iterator over the flags set in a status word, in bit order.
    Faults,
    u16,
    "status word",
    15
);

/// The flag-set behaviour shared by HW-FOC's status word and HW5's fault byte: for a
/// `#[repr(u8)]` enum `$fault` of the bits of a `$word` (with its own `ALL` in bit order and
/// `name`), its `bit`, `mask`, `from_bit`, `from_name` and `Display` (the name); for the
/// tuple struct `$flags($word)`, named access to its flags (`OK`, `contains`, `is_ok`, `with`,
/// `faults`, `From<$word>`, `FromIterator<$fault>`, `IntoIterator`, and `Display`: the set
/// flags' names joined by `|`, the CSV form); and `$faults`, the iterator over the flags set,
/// in bit order. `$what` names the word in the docs; `$max` is its highest bit.
macro_rules! fault_flags {
    ($fault:ident, $flags:ident, $(#[$faults_doc:meta])* $faults:ident, $word:ty, $what:literal, $max:literal) => {
        impl $fault {
            #[doc = concat!("The bit number, 0..=", $max, ".")]
            pub const fn bit(self) -> u8 {
                self as u8
            }

            #[doc = concat!("The flag's mask in the ", $what, ".")]
            pub const fn mask(self) -> $word {
                1 << (self as u8)
            }

            #[doc = concat!("The flag for bit `bit`, or `None` above ", $max, ".")]
            pub const fn from_bit(bit: u8) -> Option<$fault> {
                if bit <= $max {
                    Some(Self::ALL[bit as usize])
                } else {
                    None
                }
            }

            #[doc = concat!("The flag whose [`", stringify!($fault), "::name`] is `name`.")]
            pub fn from_name(name: &str) -> Option<$fault> {
                Self::ALL.into_iter().find(|f| f.name() == name)
            }
        }

        impl core::fmt::Display for $fault {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl $flags {
            /// No flag set.
            pub const OK: $flags = $flags(0);

            /// Whether `fault` is set.
            pub const fn contains(self, fault: $fault) -> bool {
                self.0 & fault.mask() != 0
            }

            /// Whether no flag is set.
            pub const fn is_ok(self) -> bool {
                self.0 == 0
            }

            #[doc = concat!("The ", $what, " with `fault` set as well.")]
            #[must_use]
            pub const fn with(self, fault: $fault) -> $flags {
                $flags(self.0 | fault.mask())
            }

            /// The set flags, in bit order (bit 0 first).
            pub fn faults(self) -> $faults {
                $faults(self.0)
            }
        }

        impl From<$word> for $flags {
            fn from(word: $word) -> Self {
                $flags(word)
            }
        }

        impl FromIterator<$fault> for $flags {
            fn from_iter<I: IntoIterator<Item = $fault>>(iter: I) -> Self {
                $flags(iter.into_iter().fold(0, |w, f| w | f.mask()))
            }
        }

        impl IntoIterator for $flags {
            type Item = $fault;
            type IntoIter = $faults;
            fn into_iter(self) -> $faults {
                self.faults()
            }
        }

        impl core::fmt::Display for $flags {
            /// The set flags' names joined by `|` (the CSV form), or nothing when no flag is
            /// set.
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                for (i, fault) in self.faults().enumerate() {
                    if i > 0 {
                        f.write_str("|")?;
                    }
                    f.write_str(fault.name())?;
                }
                Ok(())
            }
        }

        $(#[$faults_doc])*
        #[derive(Debug, Clone)]
        pub struct $faults($word);

        impl Iterator for $faults {
            type Item = $fault;

            fn next(&mut self) -> Option<$fault> {
                if self.0 == 0 {
                    return None;
                }
                let bit = self.0.trailing_zeros() as u8;
                self.0 &= self.0 - 1;
                $fault::from_bit(bit)
            }

            fn size_hint(&self) -> (usize, Option<usize>) {
                let n = self.0.count_ones() as usize;
                (n, Some(n))
            }
        }

        impl ExactSizeIterator for $faults {}
    };
}
pub(crate) use fault_flags;
