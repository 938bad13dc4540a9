//! Numbers in text meant for people: a fixed number of decimals, and never `-0`.

use std::fmt;

/// `value` with `decimals` decimals, without the sign of a value that rounds to zero: an idle
/// ESC's current sensor reads -1 LSB (-0.016 A), which is a true reading, but `-0.0 A`,
/// `-0 W` or `-0.00 Wh` on a screen says nothing the unsigned zero does not. The one way every
/// text output (summary, monitor, plot labels) writes a measured number.
///
/// ```
/// use hwfoc_records::Fixed;
/// assert_eq!(Fixed(-0.389, 0).to_string(), "0");
/// assert_eq!(Fixed(-0.0079, 1).to_string(), "0.0");
/// assert_eq!(Fixed(-0.05, 1).to_string(), "-0.1");
/// assert_eq!(Fixed(24.9, 1).to_string(), "24.9");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fixed(pub f64, pub usize);

impl fmt::Display for Fixed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Fixed(value, decimals) = *self;
        let text = format!("{value:.decimals$}");
        match text.strip_prefix('-') {
            Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => f.pad(rest),
            _ => f.pad(&text),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Fixed;

    #[test]
    fn values_that_round_to_zero_lose_their_sign() {
        for (v, d, want) in [
            (-0.0, 0, "0"),
            (-0.0, 2, "0.00"),
            (-0.4999, 0, "0"),
            (-0.5001, 0, "-1"),
            (-0.00019669, 2, "0.00"),
            (-0.004, 3, "-0.004"),
            (0.0, 1, "0.0"),
            (1234.5678, 2, "1234.57"),
            (-12.25, 1, "-12.2"),
        ] {
            assert_eq!(Fixed(v, d).to_string(), want, "{v} with {d} decimals");
        }
    }

    #[test]
    fn width_and_alignment_apply() {
        assert_eq!(format!("{:>6}", Fixed(-0.01, 1)), "   0.0");
    }
}
