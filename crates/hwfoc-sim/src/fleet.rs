//! A fleet of virtual ESCs: described in plain data ([`FleetSpec`]), then checked and made ready
//! to run ([`VirtualFleet`]).

use std::rc::Rc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use hwfoc::Protocol;
use hwfoc_ports::clock::unix_now_ns;

use crate::degrade::{DegradeKind, DegradeSpec};
use crate::error::SimError;
use crate::esc::{Setup, VirtualEsc, spread};
use crate::faults::{FaultSchedule, FaultSpec, LinkRates};
use crate::formats;
use crate::model::ModelConfig;
use crate::profile::{Profile, ProfileSpec, Shape};
use crate::schedule::{self, Pace, SimClock};
use crate::sink::Sink;

/// The most ESCs a fleet can have: as many as a record can number.
pub use hwfoc_io::MAX_ESCS;

/// Everything the virtual ESCs of a run are made from, as plain data.
#[derive(Debug, Clone, PartialEq)]
pub struct FleetSpec {
    /// Number of ESCs (ESC 0 to `n - 1`), at most [`MAX_ESCS`].
    pub n: usize,
    /// Seed of every random choice: the same seed and description give the same bytes.
    pub seed: u64,
    /// The protocol every ESC speaks (one of [`formats::SIMULATED`]).
    pub protocol: Protocol,
    /// Line rate, baud (8N1).
    pub baud: u32,
    /// First packet number of every ESC; random per ESC (from the seed) if `None`.
    pub start_packet: Option<u16>,
    /// The throttle profile.
    pub profile: ProfileSpec,
    /// The parameters of the built-in profiles.
    pub shape: Shape,
    /// Motor, battery, ESC.
    pub model: ModelConfig,
    /// Status bits raised at given times.
    pub faults: Vec<FaultSpec>,
    /// How often the link misbehaves.
    pub link: LinkRates,
    /// Degradations of motors, propellers, batteries, wires, power stages
    /// ([`crate::degrade`]).
    pub degradations: Vec<DegradeSpec>,
}

impl FleetSpec {
    /// `n` HW-FOC ESCs at 19200 baud of seed `seed` (random first packet numbers) flying a
    /// staircase of `shape` on `model`, with no fault, no link error and `degradations`: the
    /// flight the tests of the degradations and of `hwfoc check` start from (set `profile` or
    /// the rest after).
    pub fn steps(
        n: usize,
        seed: u64,
        shape: Shape,
        model: ModelConfig,
        degradations: Vec<DegradeSpec>,
    ) -> FleetSpec {
        FleetSpec {
            n,
            seed,
            protocol: Protocol::HwFoc,
            baud: 19200,
            start_packet: None,
            profile: ProfileSpec::Steps,
            shape,
            model,
            faults: Vec::new(),
            link: LinkRates::default(),
            degradations,
        }
    }

    /// The fleet, checked (at most [`MAX_ESCS`] ESCs, every fault's ESC exists, the protocol is
    /// one a virtual ESC speaks, link faults only on HW-FOC, every fault has a flag in the
    /// format's fault word where it has one) and its profile loaded (a CSV file read), but not started.
    pub fn build(self) -> Result<VirtualFleet, SimError> {
        if self.n > MAX_ESCS {
            return Err(SimError::TooManyEscs {
                n: self.n,
                max: MAX_ESCS,
            });
        }
        if !formats::simulated(self.protocol) {
            return Err(SimError::Protocol {
                protocol: self.protocol,
            });
        }
        if self.protocol != Protocol::HwFoc && self.link != LinkRates::default() {
            return Err(SimError::LinkFaults {
                protocol: self.protocol,
            });
        }
        if self.protocol != Protocol::HwFoc
            && self
                .degradations
                .iter()
                .any(|d| d.kind == DegradeKind::Wire)
        {
            return Err(SimError::WireDegradation {
                protocol: self.protocol,
            });
        }
        if let Some(d) = self.degradations.iter().find(|d| d.esc >= self.n) {
            return Err(SimError::NoSuchDegradedEsc {
                spec: *d,
                n: self.n,
            });
        }
        let fault_word = formats::format(self.protocol).and_then(|f| f.fault_word.as_ref());
        if let Some(word) = fault_word
            && let Some(f) = self.faults.iter().find(|f| (word.flag)(f.fault).is_none())
        {
            return Err(SimError::NoFaultFlag {
                protocol: self.protocol,
                fault: f.fault,
            });
        }
        if let Some(esc) = self
            .faults
            .iter()
            .find_map(|f| f.esc.filter(|&e| e >= self.n))
        {
            return Err(SimError::NoSuchEsc { esc, n: self.n });
        }
        let profile = Profile::load(&self.profile, &self.shape)?;
        Ok(VirtualFleet {
            spec: self,
            profile,
        })
    }
}

/// Virtual ESCs described and checked, not yet started; it can be moved to another thread.
#[derive(Debug)]
pub struct VirtualFleet {
    spec: FleetSpec,
    profile: Profile,
}

impl VirtualFleet {
    /// What the fleet was built from.
    pub fn spec(&self) -> &FleetSpec {
        &self.spec
    }

    /// The throttle profile, loaded.
    pub fn profile(&self) -> &Profile {
        &self.profile
    }

    /// The ESCs, at rest at time zero. Each but the first runs behind the profile and at a
    /// load of its own ([`spread`]), so that they are not in lockstep.
    pub fn escs(self) -> Vec<VirtualEsc> {
        let spec = self.spec;
        let profile = Rc::new(self.profile);
        (0..spec.n)
            .map(|index| {
                let (lag_s, load) = spread(spec.seed, index);
                VirtualEsc::new(Setup {
                    index,
                    seed: spec.seed,
                    protocol: spec.protocol,
                    baud: spec.baud,
                    start_packet: spec.start_packet,
                    model: spec.model,
                    profile: Rc::clone(&profile),
                    lag_s,
                    load,
                    faults: FaultSchedule::for_esc(&spec.faults, index),
                    link: spec.link,
                    degradations: spec.degradations.clone(),
                })
            })
            .collect()
    }

    /// Runs the ESCs in real time from now until `stop` is set, each burst handed whole to
    /// `sink` when its first byte is due (Unix time in ns), as a UART's reader would get it.
    pub fn run_live(self, sink: &mut dyn Sink, stop: &AtomicBool) -> Result<(), SimError> {
        let clock = SimClock {
            origin_ns: unix_now_ns(),
            real: Some(Instant::now()),
        };
        schedule::run(self.escs(), sink, None, Pace::Whole, clock, None, stop)?;
        Ok(())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::model::tests::config;

    /// `n` ESCs with the command line's model, a short steps profile, no faults.
    pub(crate) fn spec(n: usize) -> FleetSpec {
        FleetSpec {
            n,
            seed: 1,
            protocol: Protocol::HwFoc,
            baud: 19200,
            start_packet: None,
            profile: ProfileSpec::Steps,
            shape: Shape {
                lead_in_s: 0.5,
                levels: vec![0.0, 50.0],
                hold_s: 1.0,
                period_s: 10.0,
                max_pct: 80.0,
            },
            model: config(),
            faults: Vec::new(),
            link: LinkRates::default(),
            degradations: Vec::new(),
        }
    }

    #[test]
    fn building_checks_the_esc_numbers() {
        let mut s = spec(2);
        s.faults = vec!["2:mos_short@1".parse().unwrap()];
        assert_eq!(
            s.build().unwrap_err().to_string(),
            "a fault is scheduled on ESC 2, which does not exist: there are 2 (0..1)"
        );
        assert!(matches!(
            spec(MAX_ESCS + 1).build(),
            Err(SimError::TooManyEscs {
                n: 257,
                max: MAX_ESCS
            })
        ));
        let fleet = spec(3).build().unwrap();
        assert_eq!(fleet.profile().natural_length_s(), 2.5);
        let escs = fleet.escs();
        assert_eq!(
            escs.iter().map(VirtualEsc::index).collect::<Vec<_>>(),
            [0, 1, 2]
        );
    }

    #[test]
    fn building_checks_the_protocol() {
        let with = |protocol: Protocol| FleetSpec {
            protocol,
            ..spec(1)
        };
        assert_eq!(
            with(Protocol::DataLink).build().unwrap_err().to_string(),
            "virtual ESCs do not speak DataLink V2 (datalink): they speak hw-foc, hw-v4, hw-v3, hw5"
        );
        let mut s = with(Protocol::HwV3);
        s.link.drop = 0.1;
        assert_eq!(
            s.build().unwrap_err().to_string(),
            "link faults (bit errors, drops, cuts, garbage) are simulated for HW-FOC only, not \
             for Hobbywing V3 (hw-v3)"
        );
        // V3 and V4 carry no fault word: faults act on the model only.
        let mut s = with(Protocol::HwV4);
        s.faults = vec!["mos_short@2".parse().unwrap()];
        assert!(s.build().is_ok());
        // Every format: the same, from its own description.
        for format in formats::FORMATS.iter().copied() {
            let mut s = with(format.protocol);
            s.link.drop = 0.1;
            assert_eq!(
                s.build().unwrap_err().to_string(),
                format!(
                    "link faults (bit errors, drops, cuts, garbage) are simulated for HW-FOC \
                     only, not for {} ({})",
                    format.protocol.title(),
                    format.protocol
                )
            );
            // Without a fault word, faults act on the model only.
            if format.fault_word.is_none() {
                let mut s = with(format.protocol);
                s.faults = vec!["mos_short@2".parse().unwrap()];
                assert!(s.build().is_ok());
            }
        }
        let mut s = with(Protocol::Hw5);
        s.faults = vec!["over_current@1".parse().unwrap()];
        assert!(s.clone().build().is_ok());
        s.faults.push("mos_short@2".parse().unwrap());
        let e = s.build().unwrap_err().to_string();
        assert!(
            e.starts_with(
                "the fault mos_short has no flag in HW5's fault byte; HW5 carries \
                 input_voltage_high (as input_voltage_error), input_voltage_low (as low_voltage), "
            ),
            "{e}"
        );
    }
}
