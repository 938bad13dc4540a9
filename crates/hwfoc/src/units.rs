//! Physical units: the user's conversion settings and the ADC-to-temperature table.

use core::fmt;

/// Conversion settings that the frame itself does not carry.
///
/// Defaults: current scale 64 (the vendor document's `/64`), 7 pole pairs, gear ratio 1.
/// Several flight-stack drivers read currents as `x 0.01` A instead (current scale 100); which is
/// right depends on the ESC, so the scale is the user's to set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Raw current units per ampere (input and phase current alike).
    pub current_scale: f32,
    /// Motor pole pairs (magnets / 2).
    pub pole_pairs: u16,
    /// Gear ratio between motor and the shaft whose RPM is wanted (1 for direct drive).
    pub gear_ratio: f32,
}

impl Default for Settings {
    fn default() -> Self {
        Settings::DEFAULT
    }
}

impl Settings {
    /// Current scale 64, 7 pole pairs, gear ratio 1.
    pub const DEFAULT: Settings = Settings {
        current_scale: 64.0,
        pole_pairs: 7,
        gear_ratio: 1.0,
    };

    /// Settings checked for values that would make every conversion meaningless
    /// (a zero, negative or non-finite scale or ratio, zero pole pairs).
    pub fn new(
        current_scale: f32,
        pole_pairs: u16,
        gear_ratio: f32,
    ) -> Result<Self, SettingsError> {
        if !(current_scale.is_finite() && current_scale > 0.0) {
            return Err(SettingsError::CurrentScale(current_scale));
        }
        if pole_pairs == 0 {
            return Err(SettingsError::PolePairs);
        }
        if !(gear_ratio.is_finite() && gear_ratio > 0.0) {
            return Err(SettingsError::GearRatio(gear_ratio));
        }
        Ok(Settings {
            current_scale,
            pole_pairs,
            gear_ratio,
        })
    }

    /// Amperes for a raw current value.
    #[inline]
    pub fn amps(&self, raw: i16) -> f32 {
        f32::from(raw) / self.current_scale
    }

    /// Mechanical RPM for an electrical RPM: erpm / (gear ratio * pole pairs).
    #[inline]
    pub fn rpm_from_erpm(&self, erpm: u32) -> f32 {
        erpm as f32 / (self.gear_ratio * f32::from(self.pole_pairs))
    }
}

/// A setting that [`Settings::new`] refuses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SettingsError {
    /// The current scale must be a positive finite number.
    CurrentScale(f32),
    /// Pole pairs must be at least 1.
    PolePairs,
    /// The gear ratio must be a positive finite number.
    GearRatio(f32),
}

impl fmt::Display for SettingsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SettingsError::CurrentScale(v) => {
                write!(f, "current scale must be a positive number, not {v}")
            }
            SettingsError::PolePairs => f.write_str("pole pairs must be at least 1"),
            SettingsError::GearRatio(v) => {
                write!(f, "gear ratio must be a positive number, not {v}")
            }
        }
    }
}

impl core::error::Error for SettingsError {}

/// ADC code for each temperature 0..=129 degC, from the vendor document's "ADC vs Temp" table.
/// Codes fall as temperature rises; some codes repeat and many are absent.
pub const ADC_TABLE: [u8; 130] = [
    241, 240, 239, 238, 237, 236, 235, 234, 233, 232, // 0..9
    231, 230, 229, 228, 227, 226, 224, 223, 222, 220, // 10..19
    219, 217, 216, 214, 213, 211, 209, 208, 206, 204, // 20..29
    202, 201, 199, 197, 195, 193, 191, 189, 187, 185, // 30..39
    183, 181, 179, 177, 174, 172, 170, 168, 166, 164, // 40..49
    161, 159, 157, 154, 152, 150, 148, 146, 143, 141, // 50..59
    139, 136, 134, 132, 130, 128, 125, 123, 121, 119, // 60..69
    117, 115, 113, 111, 109, 106, 105, 103, 101, 99, // 70..79
    97, 95, 93, 91, 90, 88, 85, 84, 82, 81, // 80..89
    79, 77, 76, 74, 73, 72, 69, 68, 66, 65, // 90..99
    64, 62, 62, 61, 59, 58, 56, 54, 54, 53, // 100..109
    51, 51, 50, 48, 48, 46, 46, 44, 43, 43, // 110..119
    41, 41, 39, 39, 39, 37, 37, 35, 35, 33, // 120..129
];

/// Highest ADC code in the table (0 degC); higher codes are colder than the table covers.
pub const ADC_MAX: u8 = ADC_TABLE[0];
/// Lowest ADC code in the table (129 degC); lower codes are hotter than the table covers.
pub const ADC_MIN: u8 = ADC_TABLE[129];

/// Temperature for every code in `ADC_MIN..=ADC_MAX`, built at compile time (index = code).
static CELSIUS: [f32; 256] = build_celsius();

const fn build_celsius() -> [f32; 256] {
    let mut out = [f32::NAN; 256];
    // Exact codes: the mean of the temperatures the table gives them (one, or a run of repeats).
    let mut t = 0;
    while t < ADC_TABLE.len() {
        let code = ADC_TABLE[t];
        let mut end = t;
        while end + 1 < ADC_TABLE.len() && ADC_TABLE[end + 1] == code {
            end += 1;
        }
        out[code as usize] = (t + end) as f32 / 2.0;
        t = end + 1;
    }
    // Codes between two entries: linear between the temperatures of the nearest exact codes.
    let exact = out;
    let mut code = ADC_MIN as usize;
    while code <= ADC_MAX as usize {
        if exact[code].is_nan() {
            let mut lo = code - 1; // hotter neighbour (lower code)
            while exact[lo].is_nan() {
                lo -= 1;
            }
            let mut hi = code + 1; // colder neighbour (higher code)
            while exact[hi].is_nan() {
                hi += 1;
            }
            let frac = (code - lo) as f32 / (hi - lo) as f32;
            out[code] = exact[lo] + (exact[hi] - exact[lo]) * frac;
        }
        code += 1;
    }
    out
}

/// A temperature read through the ADC table, or the side of the table an out-of-range code is on.
///
/// ```
/// use hwfoc::Temperature;
///
/// assert_eq!(Temperature::from_adc(206), Temperature::Celsius(28.0));
/// assert_eq!(Temperature::from_adc(225), Temperature::Celsius(15.5)); // between 226 and 224
/// assert_eq!(Temperature::from_adc(39), Temperature::Celsius(123.0)); // 122, 123 and 124
/// assert_eq!(Temperature::from_adc(250), Temperature::BelowRange);    // colder than 0 degC
/// assert_eq!(Temperature::from_adc(20).celsius(), None);              // hotter than 129 degC
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Temperature {
    /// A reading inside the table, in degC.
    Celsius(f32),
    /// The code is above the table's highest (241): colder than 0 degC, or a disconnected sensor.
    BelowRange,
    /// The code is below the table's lowest (33): hotter than 129 degC, or a shorted sensor.
    AboveRange,
}

impl Temperature {
    /// Converts an ADC code.
    ///
    /// Codes in the table give its temperature (the middle one where a code repeats); a code
    /// between two entries gives a value linearly between theirs.
    #[inline]
    pub fn from_adc(code: u8) -> Temperature {
        if code > ADC_MAX {
            Temperature::BelowRange
        } else if code < ADC_MIN {
            Temperature::AboveRange
        } else {
            Temperature::Celsius(CELSIUS[code as usize])
        }
    }

    /// The reading in degC, or `None` when out of the table's range.
    pub fn celsius(self) -> Option<f32> {
        match self {
            Temperature::Celsius(c) => Some(c),
            _ => None,
        }
    }
}

impl fmt::Display for Temperature {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Temperature::Celsius(c) => write!(f, "{c} degC"),
            Temperature::BelowRange => f.write_str("below 0 degC (out of range)"),
            Temperature::AboveRange => f.write_str("above 129 degC (out of range)"),
        }
    }
}
