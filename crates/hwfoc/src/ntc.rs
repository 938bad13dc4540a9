//! The V4 temperature conversion: an NTC thermistor read by a 12-bit ADC. Here, not in
//! [`crate::v4`], because the neutral [`Conversion::Ntc`](crate::Conversion) computes it;
//! [`crate::v4`] re-exports it.
//!
//! Beta 3950, 47 kOhm at 25 degC, against a 10 kOhm reference (every source agrees):
//! `T = 1 / (ln(adc / (4096 - adc) * 10 / 47) / 3950 + 1 / 298.15) - 273.15` degC. An ADC
//! value of 0 is no reading. `core` has no logarithm, so the one this needs is here.

/// One more than the largest code of a 12-bit ADC (V4's voltage, current and temperature codes).
pub const ADC_LIMIT: u16 = 4096;

/// Beta of the NTC thermistor, in kelvin.
pub const NTC_BETA: f64 = 3950.0;
/// Resistance of the thermistor at 25 degC over the reference resistor: 47 kOhm / 10 kOhm.
pub const NTC_R25_OVER_REFERENCE: f64 = 4.7;

/// The temperature in degC for a temperature ADC value, or `None` for 0 (no reading) and for
/// values of 4096 or more (not a 12-bit reading; the decoder never accepts such a frame).
///
/// ```
/// use hwfoc::v4::ntc_celsius;
///
/// assert_eq!(ntc_celsius(0), None);
/// let t = ntc_celsius(3244).unwrap(); // the Platinum V4 capture at rest
/// assert!((t - 29.8).abs() < 0.1, "{t}");
/// // 25 degC where the thermistor is 4.7 times the reference: adc / (4096 - adc) = 4.7.
/// assert!((ntc_celsius(3377).unwrap() - 25.0).abs() < 0.05);
/// ```
pub fn ntc_celsius(adc: u16) -> Option<f32> {
    if adc == 0 || adc >= ADC_LIMIT {
        return None;
    }
    let adc = f64::from(adc);
    let ratio = adc / (f64::from(ADC_LIMIT) - adc) / NTC_R25_OVER_REFERENCE;
    let kelvin = 1.0 / (ln(ratio) / NTC_BETA + 1.0 / 298.15);
    Some((kelvin - 273.15) as f32)
}

/// The natural logarithm of a positive, finite, normal `x`, to about 1e-15 relative:
/// `x = m * 2^e` with `m` in [sqrt(1/2), sqrt(2)), `ln m = 2 atanh((m - 1) / (m + 1))` by its
/// series (|z| < 0.172, so 12 terms leave less than 1e-19).
fn ln(x: f64) -> f64 {
    const LN_2: f64 = core::f64::consts::LN_2;
    const SQRT_2: f64 = core::f64::consts::SQRT_2;
    let bits = x.to_bits();
    let mut exponent = ((bits >> 52) & 0x7FF) as i32 - 1023;
    let mut m = f64::from_bits((bits & 0x000F_FFFF_FFFF_FFFF) | 0x3FF0_0000_0000_0000);
    if m >= SQRT_2 {
        m /= 2.0;
        exponent += 1;
    }
    let z = (m - 1.0) / (m + 1.0);
    let z2 = z * z;
    let mut term = z;
    let mut sum = 0.0;
    let mut k = 1.0;
    for _ in 0..12 {
        sum += term / k;
        term *= z2;
        k += 2.0;
    }
    2.0 * sum + f64::from(exponent) * LN_2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln_of_known_values() {
        assert_eq!(ln(1.0), 0.0);
        for (x, want) in [
            (core::f64::consts::E, 1.0),
            (2.0, core::f64::consts::LN_2),
            (10.0, core::f64::consts::LN_10),
            (0.5, -core::f64::consts::LN_2),
            (1e-3, -6.907_755_278_982_137),
            (872.5, 6.771_362_654_076_582),
        ] {
            assert!(
                (ln(x) - want).abs() < 1e-13,
                "ln({x}) = {} not {want}",
                ln(x)
            );
        }
    }

    #[test]
    fn no_reading_and_range() {
        assert_eq!(ntc_celsius(0), None);
        assert_eq!(ntc_celsius(4096), None);
        // Colder as the ADC value rises.
        let mut last = f32::INFINITY;
        for adc in 1..4096 {
            let t = ntc_celsius(adc).unwrap();
            assert!(t < last, "{adc}");
            last = t;
        }
    }
}
