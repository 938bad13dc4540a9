//! The formats a virtual ESC speaks besides HW-FOC, one module each: what it sends, when, and
//! what its fault word carries, made from the model's measurements ([`Measured`]).
//!
//! HW-FOC's own schedule, with its link faults and the reference decoder that keeps the ground
//! truth exact under them, is [`crate::esc`]'s. The formats here run over the same model and
//! wire without link faults (the fleet refuses them: V3 and V4 have no checksum and cannot
//! tell every corruption, so the ground truth could not stay exact).
//!
//! A format's simulator is one module here, which gives a [`SimulatedFormat`] named `FORMAT`
//! and a [`Speaker`], and its `mod` line and entry in [`FORMATS`] here.

use hwfoc::{Fault, Protocol};

use crate::burst::What;
use crate::model::Measured;
use crate::rng::Rng;

mod hw5;
mod v3;
mod v4;

/// The formats of this module, in the order they are listed to a user.
pub const FORMATS: &[&SimulatedFormat] = &[&v4::FORMAT, &v3::FORMAT, &hw5::FORMAT];

/// The protocols a virtual ESC speaks: HW-FOC, then [`FORMATS`]'.
pub const SIMULATED: [Protocol; 1 + FORMATS.len()] = {
    let mut all = [Protocol::HwFoc; 1 + FORMATS.len()];
    let mut i = 0;
    while i < FORMATS.len() {
        all[i + 1] = FORMATS[i].protocol;
        i += 1;
    }
    all
};

/// A format a virtual ESC speaks besides HW-FOC: how it starts, and what its fault word carries.
#[derive(Debug)]
pub struct SimulatedFormat {
    /// The protocol.
    pub protocol: Protocol,
    /// Its schedule's state at time zero, and the time of its first look, ns.
    pub start: fn(&Start) -> (Box<dyn Speaker>, u64),
    /// Its fault word, where it has one: an injected fault it has no flag for is refused.
    /// Without one, an injected fault shows only through what it does to the model (a lost
    /// throttle signal stops the motor, an overheat raises the temperature).
    pub fault_word: Option<FaultWord>,
}

/// A format's fault word as the simulator sends it.
#[derive(Debug)]
pub struct FaultWord {
    /// What the format calls it, for messages ("fault byte").
    pub name: &'static str,
    /// The name of the flag a simulator fault (HW-FOC's status bit) is sent as, or `None` for
    /// a fault the word has no flag for.
    pub flag: fn(Fault) -> Option<&'static str>,
}

/// What a format's schedule starts from.
#[derive(Debug, Clone, Copy)]
pub struct Start {
    /// The first packet counter (`--start-packet`, or 0).
    pub counter: u32,
    /// Battery cells in series.
    pub cells: u8,
    /// The ESC's random phase, ns, below 50 ms: when an ESC that looks every 50 ms would look
    /// first.
    pub phase_ns: u64,
}

/// A format's schedule: at each of its looks, what it sends and when it looks again.
pub trait Speaker: std::fmt::Debug {
    /// The look at `t_ns`, with the model's measurements `m` and the ESC's noise source.
    fn look(&mut self, t_ns: u64, m: &Measured, noise: &mut Rng) -> Look;
}

/// What a [`Speaker`] does at one look.
#[derive(Debug, Clone, PartialEq)]
pub struct Look {
    /// A frame's bytes and what they are, sent now (after whatever is still on the wire), or
    /// nothing.
    pub send: Option<(Vec<u8>, What)>,
    /// The time of the next look, ns.
    pub next_ns: u64,
}

/// The format a virtual ESC speaking `protocol` runs, if it is one of [`FORMATS`].
pub fn format(protocol: Protocol) -> Option<&'static SimulatedFormat> {
    FORMATS.iter().copied().find(|f| f.protocol == protocol)
}

/// Whether a virtual ESC can speak `protocol`.
pub fn simulated(protocol: Protocol) -> bool {
    SIMULATED.contains(&protocol)
}

#[cfg(test)]
pub(crate) mod tests {
    use hwfoc::Status;

    use super::*;

    /// Measurements of a motor turning at `erpm` (stopped at 0).
    pub(crate) fn measured(erpm: f64) -> Measured {
        Measured {
            throttle_in_pct: 40.0,
            throttle_out_pct: 38.0,
            erpm,
            voltage_v: 24.2,
            current_a: 20.0,
            mos_c: 40.0,
            cap_c: 35.0,
            ambient_c: 25.0,
            status: Status::OK,
            spinning: erpm > 0.0,
        }
    }

    #[test]
    fn every_format_is_listed_once_and_found_by_its_protocol() {
        assert_eq!(SIMULATED[0], Protocol::HwFoc);
        for (i, f) in FORMATS.iter().enumerate() {
            assert_eq!(SIMULATED[i + 1], f.protocol);
            assert!(
                !SIMULATED[..=i].contains(&f.protocol),
                "{} twice",
                f.protocol
            );
            assert_eq!(format(f.protocol).map(|g| g.protocol), Some(f.protocol));
            assert!(simulated(f.protocol));
        }
        assert!(format(Protocol::HwFoc).is_none() && simulated(Protocol::HwFoc));
        assert!(!simulated(Protocol::DataLink));
    }
}
