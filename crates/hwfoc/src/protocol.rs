//! The protocols hwfoc reads, by name: what a user names to force one
//! (`hwfoc decode --protocol datalink`) instead of letting the bytes tell
//! ([`crate::mixed`] reads every protocol at once).

use core::fmt;

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
    /// HW-FOC: an ESC's own wire ([`crate::foc`]).
    HwFoc,
    /// DataLink V2: a Hobbywing hub's frames of up to eight ESCs ([`crate::datalink`]).
    DataLink,
}

impl Protocol {
    /// Every protocol, in the order they are listed to a user.
    pub const ALL: [Protocol; 2] = [Protocol::HwFoc, Protocol::DataLink];

    /// The protocol's name as users give it and outputs show it: `hw-foc`, `datalink`.
    pub const fn name(self) -> &'static str {
        match self {
            Protocol::HwFoc => "hw-foc",
            Protocol::DataLink => "datalink",
        }
    }

    /// The protocol's name in prose: `HW-FOC`, `DataLink V2`.
    pub const fn title(self) -> &'static str {
        match self {
            Protocol::HwFoc => "HW-FOC",
            Protocol::DataLink => "DataLink V2",
        }
    }

    /// The baud rate its senders use (8N1).
    pub const fn baud_rate(self) -> u32 {
        match self {
            Protocol::HwFoc => crate::foc::BAUD_RATE,
            Protocol::DataLink => crate::datalink::BAUD_RATE,
        }
    }

    /// The width of its packet counter in bits (which it wraps at), or `None` for a protocol
    /// that sends no counter: 16 for HW-FOC and DataLink.
    pub const fn packet_bits(self) -> Option<u32> {
        match self {
            Protocol::HwFoc | Protocol::DataLink => Some(16),
        }
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

    /// The protocol named `name` (as [`Protocol::name`] spells it, any case).
    pub fn from_name(name: &str) -> Option<Protocol> {
        Protocol::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(name))
    }
}

impl fmt::Display for Protocol {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

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
    }
}
