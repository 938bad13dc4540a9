//! A small deterministic random number generator (SplitMix64), so that a seed gives the same
//! bytes on every machine and with every version of every dependency.

/// SplitMix64: 64 bits of state, passes BigCrush, plenty for noise and fault injection.
#[derive(Debug, Clone)]
pub struct Rng(u64);

/// Streams of random numbers that must not disturb each other: changing a fault rate does not
/// change the model's noise, and so on.
#[derive(Debug, Clone, Copy)]
pub enum Purpose {
    /// Per-ESC variation of the model's parameters, start packet, phase.
    Params = 1,
    /// Measurement noise.
    Noise = 2,
    /// Link faults: dropped, cut and corrupted frames, garbage.
    Link = 3,
    /// Choices shared by the whole run (drawn with ESC 0's index).
    Run = 4,
    /// A loose telemetry wire's bursts of loss ([`crate::degrade::WireLoss`]).
    Wire = 5,
}

impl Rng {
    /// A generator for `purpose` of ESC `esc`, from the run's seed.
    pub fn for_esc(seed: u64, esc: usize, purpose: Purpose) -> Rng {
        let mut mix = Rng(seed);
        let a = mix.next_u64();
        let mut mix = Rng(a ^ (esc as u64 + 1).wrapping_mul(0xA24B_AED4_963E_E407));
        let b = mix.next_u64();
        Rng(b ^ (purpose as u64).wrapping_mul(0x9FB2_1C65_1E98_DF25))
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [-1, 1).
    pub fn signed(&mut self) -> f64 {
        2.0 * self.unit() - 1.0
    }

    /// Triangular noise in (-amplitude, amplitude), most often near zero.
    pub fn noise(&mut self, amplitude: f64) -> f64 {
        (self.unit() - self.unit()) * amplitude
    }

    /// Uniform in `0..n` (`n` > 0).
    pub fn below(&mut self, n: u64) -> u64 {
        // Multiply-shift: unbiased enough for n far below 2^64.
        ((u128::from(self.next_u64()) * u128::from(n)) >> 64) as u64
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        p > 0.0 && self.unit() < p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_deterministic_and_distinct() {
        let a: Vec<u64> = {
            let mut r = Rng::for_esc(7, 0, Purpose::Noise);
            (0..4).map(|_| r.next_u64()).collect()
        };
        let mut r = Rng::for_esc(7, 0, Purpose::Noise);
        assert_eq!(a, (0..4).map(|_| r.next_u64()).collect::<Vec<_>>());
        assert_ne!(
            Rng::for_esc(7, 1, Purpose::Noise).next_u64(),
            Rng::for_esc(7, 0, Purpose::Noise).next_u64()
        );
        assert_ne!(
            Rng::for_esc(7, 0, Purpose::Link).next_u64(),
            Rng::for_esc(7, 0, Purpose::Noise).next_u64()
        );
        assert_ne!(
            Rng::for_esc(8, 0, Purpose::Noise).next_u64(),
            Rng::for_esc(7, 0, Purpose::Noise).next_u64()
        );
    }

    #[test]
    fn ranges() {
        let mut r = Rng::for_esc(1, 0, Purpose::Params);
        let mut sum = 0.0;
        for _ in 0..10_000 {
            let u = r.unit();
            assert!((0.0..1.0).contains(&u));
            sum += u;
            assert!(r.below(10) < 10);
            assert!(r.noise(0.5).abs() < 0.5);
        }
        assert!((sum / 10_000.0 - 0.5).abs() < 0.02);
        assert!(!r.chance(0.0));
        assert!(r.chance(1.0));
    }
}
