//! Fault injection: status bits raised at given times, and a noisy link (bit errors, dropped
//! frames, cut frames, bursts of garbage between frames).

use std::str::FromStr;

use hwfoc::{Fault, Status};

use crate::rng::Rng;

/// One fault, written `[ESC:]NAME@START[-END]` (`hwfoc simulate --fault`): a status bit set
/// from START (inclusive) to END (exclusive; to the end of the run without END), on one ESC or
/// on all of them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaultSpec {
    /// The ESC index, or `None` for every ESC.
    pub esc: Option<usize>,
    /// The status bit.
    pub fault: Fault,
    /// Seconds of simulated time.
    pub start_s: f64,
    /// Seconds of simulated time, if the fault ends.
    pub end_s: Option<f64>,
}

impl FromStr for FaultSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let (head, times) = s.split_once('@').ok_or_else(|| {
            format!("{s:?}: expected [ESC:]NAME@START[-END], e.g. mos_overheat@5-7.5")
        })?;
        let (esc, name) = match head.split_once(':') {
            Some((esc, name)) => {
                let esc = esc
                    .parse::<usize>()
                    .map_err(|_| format!("{s:?}: bad ESC index {esc:?}"))?;
                (Some(esc), name)
            }
            None => (None, head),
        };
        let fault = Fault::from_name(name).ok_or_else(|| {
            let names: Vec<&str> = Fault::ALL.iter().map(|f| f.name()).collect();
            format!(
                "{s:?}: unknown fault {name:?}; the names are {}",
                names.join(", ")
            )
        })?;
        let seconds = |text: &str| {
            text.parse::<f64>()
                .ok()
                .filter(|t| t.is_finite() && *t >= 0.0)
                .ok_or_else(|| format!("{s:?}: bad time {text:?} (seconds, 0 or more)"))
        };
        let (start_s, end_s) = match times.split_once('-') {
            Some((start, end)) => (seconds(start)?, Some(seconds(end)?)),
            None => (seconds(times)?, None),
        };
        if end_s.is_some_and(|end| end <= start_s) {
            return Err(format!("{s:?}: the end must come after the start"));
        }
        Ok(FaultSpec {
            esc,
            fault,
            start_s,
            end_s,
        })
    }
}

/// The injected status bits of one ESC over time.
#[derive(Debug, Clone, Default)]
pub struct FaultSchedule {
    windows: Vec<FaultSpec>,
}

impl FaultSchedule {
    /// The windows of `specs` that apply to ESC `esc`.
    pub fn for_esc(specs: &[FaultSpec], esc: usize) -> FaultSchedule {
        FaultSchedule {
            windows: specs
                .iter()
                .filter(|s| s.esc.is_none_or(|e| e == esc))
                .copied()
                .collect(),
        }
    }

    /// The injected bits at `t` seconds.
    pub fn status_at(&self, t: f64) -> Status {
        let mut status = Status::OK;
        for w in &self.windows {
            if t >= w.start_s && w.end_s.is_none_or(|end| t < end) {
                status = status.with(w.fault);
            }
        }
        status
    }
}

/// Probabilities of the link faults.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LinkRates {
    /// Probability that any one bit on the wire is flipped.
    pub bit_error: f64,
    /// Probability that a frame is not sent at all (its packet number is used all the same).
    pub drop: f64,
    /// Probability that a frame stops part-way (the ESC stops sending mid-frame).
    pub cut: f64,
    /// Probability of a burst of garbage bytes in the gap before a frame.
    pub garbage: f64,
}

/// Longest garbage burst, bytes.
pub const MAX_GARBAGE: usize = 32;

/// What the link did to one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fate {
    /// Sent as is.
    Intact,
    /// Not sent.
    Dropped,
    /// Only its first bytes were sent.
    Cut,
    /// Sent with bits flipped.
    Corrupted,
}

/// The link's random decisions, from one [`Rng`] stream.
#[derive(Debug, Clone)]
pub struct LineFaults {
    rates: LinkRates,
    rng: Rng,
    /// Bits still to go before the next bit error (geometric), if bit errors are on.
    next_error: Option<u64>,
}

impl LineFaults {
    /// A link with these rates.
    pub fn new(rates: LinkRates, mut rng: Rng) -> LineFaults {
        let next_error = geometric(&mut rng, rates.bit_error);
        LineFaults {
            rates,
            rng,
            next_error,
        }
    }

    /// A garbage burst to put in a gap that has room for `room` bytes, if one is due: random
    /// bytes with sync bytes and fake frame headers mixed in, as line noise on a real wire has.
    pub fn garbage(&mut self, room: usize) -> Option<Vec<u8>> {
        if room == 0 || !self.rng.chance(self.rates.garbage) {
            return None;
        }
        let len = 1 + self.rng.below(room.min(MAX_GARBAGE) as u64) as usize;
        let mut bytes = Vec::with_capacity(len);
        while bytes.len() < len {
            match self.rng.below(16) {
                0 => bytes.extend_from_slice(&[0x9B, 0x16, 0x01, 0x02]),
                1 | 2 => bytes.push(0x9B),
                _ => bytes.push(self.rng.next_u64() as u8),
            }
        }
        bytes.truncate(len);
        Some(bytes)
    }

    /// Applies drop, cut and bit errors to a frame's bytes.
    pub fn transmit(&mut self, bytes: &mut Vec<u8>) -> Fate {
        if self.rng.chance(self.rates.drop) {
            bytes.clear();
            return Fate::Dropped;
        }
        let mut fate = Fate::Intact;
        if self.rng.chance(self.rates.cut) {
            let keep = 1 + self.rng.below(bytes.len() as u64 - 1) as usize;
            bytes.truncate(keep);
            fate = Fate::Cut;
        }
        if self.flip_bits(bytes) && fate == Fate::Intact {
            fate = Fate::Corrupted;
        }
        fate
    }

    /// Flips bits of `bytes` at the bit error rate; whether any was flipped. Errors are spaced
    /// geometrically across the whole stream, so the rate holds whatever the frame sizes.
    pub fn flip_bits(&mut self, bytes: &mut [u8]) -> bool {
        let mut flipped = false;
        let mut pos = 0u64;
        let bits = bytes.len() as u64 * 8;
        while let Some(gap) = self.next_error {
            if pos + gap >= bits {
                self.next_error = Some(gap - (bits - pos));
                break;
            }
            pos += gap;
            bytes[(pos / 8) as usize] ^= 1 << (pos % 8);
            flipped = true;
            pos += 1;
            self.next_error = geometric(&mut self.rng, self.rates.bit_error);
        }
        flipped
    }
}

/// Number of good bits before the next error at error rate `p` (`None` when `p` is 0).
fn geometric(rng: &mut Rng, p: f64) -> Option<u64> {
    if p <= 0.0 {
        return None;
    }
    if p >= 1.0 {
        return Some(0);
    }
    let u = 1.0 - rng.unit(); // (0, 1]
    Some((u.ln() / (1.0 - p).ln()).floor().min(1e18) as u64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Purpose;

    #[test]
    fn fault_specs() {
        let f: FaultSpec = "mos_overheat@5-7.5".parse().unwrap();
        assert_eq!(
            f,
            FaultSpec {
                esc: None,
                fault: Fault::MosOverheat,
                start_s: 5.0,
                end_s: Some(7.5)
            }
        );
        let f: FaultSpec = "3:throttle_signal_lost@2".parse().unwrap();
        assert_eq!(
            (f.esc, f.fault, f.end_s),
            (Some(3), Fault::ThrottleSignalLost, None)
        );
        for (bad, why) in [
            ("mos_overheat", "expected [ESC:]NAME@START[-END]"),
            (
                "hot@1",
                "unknown fault \"hot\"; the names are input_voltage_high,",
            ),
            ("mos_overheat@x", "bad time \"x\""),
            ("mos_overheat@5-4", "the end must come after the start"),
            ("mos_overheat@-1", "bad time \"\""),
            ("x:mos_overheat@1", "bad ESC index \"x\""),
        ] {
            let e = bad.parse::<FaultSpec>().unwrap_err();
            assert!(e.contains(why), "{bad}: {e}");
        }
    }

    #[test]
    fn schedule_per_esc() {
        let specs: Vec<FaultSpec> = ["over_current@1-2", "1:motor_blocked@1.5"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        let esc0 = FaultSchedule::for_esc(&specs, 0);
        let esc1 = FaultSchedule::for_esc(&specs, 1);
        assert_eq!(esc0.status_at(0.5), Status::OK);
        assert_eq!(esc0.status_at(1.0), Status::OK.with(Fault::OverCurrent));
        assert_eq!(esc0.status_at(1.7), Status::OK.with(Fault::OverCurrent));
        assert_eq!(esc0.status_at(2.0), Status::OK);
        assert_eq!(
            esc1.status_at(1.7),
            Status::OK
                .with(Fault::OverCurrent)
                .with(Fault::MotorBlocked)
        );
        assert_eq!(esc1.status_at(100.0), Status::OK.with(Fault::MotorBlocked));
    }

    #[test]
    fn bit_error_rate_holds() {
        let rates = LinkRates {
            bit_error: 1e-3,
            ..Default::default()
        };
        let mut link = LineFaults::new(rates, Rng::for_esc(3, 0, Purpose::Link));
        let mut flips = 0u32;
        for _ in 0..10_000 {
            let mut frame = [0u8; 24];
            link.flip_bits(&mut frame);
            flips += frame.iter().map(|b| b.count_ones()).sum::<u32>();
        }
        // 1.92 million bits at 1e-3: 1920 expected.
        assert!((1700..2150).contains(&flips), "{flips}");
    }

    #[test]
    fn drops_cuts_and_garbage() {
        let rates = LinkRates {
            drop: 0.25,
            cut: 0.5,
            garbage: 0.5,
            ..Default::default()
        };
        let mut link = LineFaults::new(rates, Rng::for_esc(3, 0, Purpose::Link));
        let (mut dropped, mut cut, mut intact, mut bursts) = (0, 0, 0, 0);
        for _ in 0..4000 {
            let mut bytes = vec![0x55; 24];
            match link.transmit(&mut bytes) {
                Fate::Dropped => {
                    assert!(bytes.is_empty());
                    dropped += 1
                }
                Fate::Cut => {
                    assert!((1..24).contains(&bytes.len()));
                    cut += 1
                }
                Fate::Intact => {
                    assert_eq!(bytes, vec![0x55; 24]);
                    intact += 1
                }
                Fate::Corrupted => unreachable!("no bit errors"),
            }
            if let Some(g) = link.garbage(10) {
                assert!((1..=10).contains(&g.len()));
                bursts += 1;
            }
        }
        assert!((850..1150).contains(&dropped), "{dropped}");
        assert!((1300..1700).contains(&cut), "{cut}");
        assert!((1300..1700).contains(&intact), "{intact}");
        assert!((1800..2200).contains(&bursts), "{bursts}");
        assert_eq!(link.garbage(0), None);
    }
}
