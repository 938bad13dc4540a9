//! Physical units: every conversion from a raw field to a physical value, written once, the
//! user's conversion settings, and the ADC-to-temperature table.
//!
//! Every HW-FOC conversion but temperature is linear: a [`Linear`] (`raw * mul / div`), which a
//! frame gives for each [`Quantity`] it carries
//! ([`Telemetry::reading`](crate::Telemetry::reading)). The same definition converts a raw field
//! to `f32` (what [`DataFrame`]'s methods return) and a statistic of raw values (a minimum, a
//! mean) to `f64`, each bit for bit as the formulas written out by hand did:
//!
//! ```
//! use hwfoc::{Quantity, Settings, Telemetry};
//! use hwfoc::foc::DataFrame;
//!
//! let settings = Settings::default(); // current scale 64, 7 pole pairs, gear ratio 1
//! let frame = DataFrame { erpm_raw: 350, current_raw: -1, ..Default::default() };
//! assert_eq!(frame.rpm(&settings), 500.0);
//! let linear = |q| frame.reading(q, &settings).unwrap().conversion.linear().unwrap();
//! assert_eq!(linear(Quantity::Rpm).to_f32(350.0), 500.0);
//! assert_eq!(linear(Quantity::Current).to_f64(-1.5), -1.5 / 64.0);
//! assert_eq!((Quantity::Current.name(), Quantity::Current.unit()), ("current_a", "A"));
//! ```
//!
//! [`DataFrame`]: crate::foc::DataFrame

use core::fmt;

mod adc_scale;

pub(crate) use adc_scale::VOLTS_PER_STEP_FORM;
pub use adc_scale::{CurrentScale, VoltsPerStep, VoltsPerStepError};

/// Electrical RPM per unit of a data frame's raw eRPM field.
pub const ERPM_PER_RAW: u16 = 10;

/// A linear conversion from a raw value to a physical one: `raw * mul / (div * div2)`, computed
/// in that order, in the precision of the result.
///
/// The divisor is kept as two factors because the RPM divisor, gear ratio times pole pairs, is
/// formed in the result's precision: rounded to `f32` for an `f32` result (as the frame's
/// methods always did), exact for an `f64` one. For the other conversions the second factor is 1
/// and the multiplier often 1, both exact, so e.g. a current is `raw / current_scale`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Linear {
    mul: f32,
    div: f32,
    div2: f32,
}

impl Linear {
    /// Throttle in percent: `raw * 100 / 1024`.
    pub const THROTTLE_PCT: Linear = Linear::new(100.0, 1024.0, 1.0);
    /// Electrical RPM: `raw * 10`.
    pub const ERPM: Linear = Linear::new(ERPM_PER_RAW as f32, 1.0, 1.0);
    /// Input voltage in volts: `raw / 10`.
    pub const VOLTS: Linear = Linear::new(1.0, 10.0, 1.0);
    /// The value as sent: `raw` (a quantity sent in its unit, such as HW5's degC).
    pub const IDENTITY: Linear = Linear::new(1.0, 1.0, 1.0);

    /// The conversion `raw * mul / (div * div2)`.
    pub const fn new(mul: f32, div: f32, div2: f32) -> Linear {
        Linear { mul, div, div2 }
    }

    /// The value of `raw` as an `f32`: `raw * mul / (div * div2)`, all in `f32`.
    #[inline]
    pub fn to_f32(self, raw: f32) -> f32 {
        raw * self.mul / (self.div * self.div2)
    }

    /// The value of `raw` (a raw value or a statistic of raw values, such as a mean) as an `f64`:
    /// `raw * mul / (div * div2)`, all in `f64`.
    #[inline]
    pub fn to_f64(self, raw: f64) -> f64 {
        raw * f64::from(self.mul) / (f64::from(self.div) * f64::from(self.div2))
    }

    /// The raw value whose conversion is nearest `value`: `value * div * div2 / mul` in `f64`,
    /// rounded to the nearest integer (halves away from zero), the inverse of
    /// [`Linear::to_f32`] for every raw integer. Not saturated: the caller's `as` cast to the
    /// field's integer type saturates it to the type's range (and NaN to 0).
    ///
    /// ```
    /// use hwfoc::units::Linear;
    ///
    /// assert_eq!(Linear::VOLTS.raw_of(24.66), 247.0);
    /// assert_eq!(Linear::THROTTLE_PCT.raw_of(50.0), 512.0);
    /// assert_eq!(Linear::VOLTS.raw_of(1e9) as u16, u16::MAX); // saturated by the cast
    /// ```
    #[inline]
    pub fn raw_of(self, value: f32) -> f64 {
        let raw =
            f64::from(value) * f64::from(self.div) * f64::from(self.div2) / f64::from(self.mul);
        round_half_away(raw)
    }
}

/// `x` rounded to the nearest integer, halves away from zero (`f64::round`, which `core` lacks
/// without `std`; the codec takes no `libm` for one function). NaN and infinities are returned
/// as they are.
fn round_half_away(x: f64) -> f64 {
    // From 2^52 on every f64 is an integer; below, the truncation fits an i64.
    if x.is_nan() || x.abs() >= 4_503_599_627_370_496.0 {
        return x;
    }
    let whole = x as i64 as f64;
    let frac = x - whole;
    if frac >= 0.5 {
        whole + 1.0
    } else if frac <= -0.5 {
        whole - 1.0
    } else {
        whole
    }
}

/// A quantity a data frame may carry, with its name and unit in every output of the project
/// (`docs/RECORD-SCHEMA.md`). Which protocol carries which, and how its raw integer converts, is
/// said by each protocol's frame ([`Telemetry`](crate::telemetry::Telemetry)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// Input throttle, % (`throttle_in_pct`).
    ThrottleIn,
    /// Output throttle, % (`throttle_out_pct`).
    ThrottleOut,
    /// Electrical RPM (`erpm`).
    Erpm,
    /// Motor (or geared output) RPM (`rpm`).
    Rpm,
    /// Input voltage, V (`voltage_v`).
    Voltage,
    /// Input current, A (`current_a`).
    Current,
    /// Phase current, A (`phase_current_a`).
    PhaseCurrent,
    /// MOSFET temperature, degC (`mos_temp_c`).
    MosTemp,
    /// Capacitor temperature, degC (`cap_temp_c`).
    CapTemp,
    /// Motor temperature, degC (`motor_temp_c`): HW5; no protocol read today carries it.
    MotorTemp,
    /// BEC temperature, degC (`bec_temp_c`): HW5; no protocol read today carries it.
    BecTemp,
    /// BEC output voltage, V (`bec_voltage_v`): HW5; no protocol read today carries it.
    BecVoltage,
    /// BEC output current, A (`bec_current_a`): HW5; no protocol read today carries it.
    BecCurrent,
}

impl Quantity {
    /// Every quantity, in the order of the telemetry record.
    pub const ALL: [Quantity; 13] = [
        Quantity::ThrottleIn,
        Quantity::ThrottleOut,
        Quantity::Erpm,
        Quantity::Rpm,
        Quantity::Voltage,
        Quantity::Current,
        Quantity::PhaseCurrent,
        Quantity::MosTemp,
        Quantity::CapTemp,
        Quantity::MotorTemp,
        Quantity::BecTemp,
        Quantity::BecVoltage,
        Quantity::BecCurrent,
    ];

    /// The column name in every output, e.g. `voltage_v`.
    pub const fn name(self) -> &'static str {
        match self {
            Quantity::ThrottleIn => "throttle_in_pct",
            Quantity::ThrottleOut => "throttle_out_pct",
            Quantity::Erpm => "erpm",
            Quantity::Rpm => "rpm",
            Quantity::Voltage => "voltage_v",
            Quantity::Current => "current_a",
            Quantity::PhaseCurrent => "phase_current_a",
            Quantity::MosTemp => "mos_temp_c",
            Quantity::CapTemp => "cap_temp_c",
            Quantity::MotorTemp => "motor_temp_c",
            Quantity::BecTemp => "bec_temp_c",
            Quantity::BecVoltage => "bec_voltage_v",
            Quantity::BecCurrent => "bec_current_a",
        }
    }

    /// The unit: `%`, `rev/min`, `V`, `A` or `degC`.
    pub const fn unit(self) -> &'static str {
        match self {
            Quantity::ThrottleIn | Quantity::ThrottleOut => "%",
            Quantity::Erpm | Quantity::Rpm => "rev/min",
            Quantity::Voltage | Quantity::BecVoltage => "V",
            Quantity::Current | Quantity::PhaseCurrent | Quantity::BecCurrent => "A",
            Quantity::MosTemp | Quantity::CapTemp | Quantity::MotorTemp | Quantity::BecTemp => {
                "degC"
            }
        }
    }
}

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
    /// Volts per voltage ADC step of a Hobbywing V4 ESC until its first info frame is adopted
    /// (which then gives its own): [`VoltsPerStep::LOW_VOLTAGE`], 8/910, by default,
    /// [`VoltsPerStep::HIGH_VOLTAGE`], 11/650, for HV models.
    pub v4_volts_per_step: VoltsPerStep,
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
        v4_volts_per_step: VoltsPerStep::DEFAULT,
    };

    /// The smallest current scale [`Settings::new`] accepts, `1e-34`: the largest current,
    /// `i16::MIN / scale`, must be a finite `f32` (below `f32::MAX`, about 3.4e38), so the scale
    /// must exceed `32768 / f32::MAX`, about 9.6e-35. (At `1e-35` that current is infinite.)
    pub const CURRENT_SCALE_MIN: f32 = 1e-34;
    /// The largest current scale [`Settings::new`] accepts, `1e37`: the smallest current,
    /// `1 / scale`, must be a normal `f32` (at least `f32::MIN_POSITIVE`, about 1.2e-38: below
    /// it an `f32` keeps fewer digits, down to none at 0), so the scale must be at most about
    /// 8.5e37. (At `1e38` that current has lost precision.)
    pub const CURRENT_SCALE_MAX: f32 = 1e37;
    /// The smallest gear ratio [`Settings::new`] accepts, `1e-28`: the largest RPM, of the largest
    /// eRPM [`Settings::rpm_from_erpm`] takes (`u32::MAX`, about 4.3e9) with one pole pair, must
    /// be finite, so the ratio must exceed `u32::MAX / f32::MAX`, about 1.3e-29. (At `1e-29`
    /// that RPM is infinite.) A frame's largest eRPM, 655350, needs far less.
    pub const GEAR_RATIO_MIN: f32 = 1e-28;
    /// The largest gear ratio [`Settings::new`] accepts, `1e33`: the divisor of the RPM,
    /// `gear ratio * pole pairs`, must be finite with 65535 pole pairs, and the smallest RPM,
    /// `1 / divisor`, a normal `f32`, so the ratio must be at most about
    /// `1 / (f32::MIN_POSITIVE * 65535)`, 1.3e33. (At `1e34` the divisor is infinite and every
    /// RPM 0.)
    pub const GEAR_RATIO_MAX: f32 = 1e33;

    /// Settings checked so that every conversion they make is a finite number, a nonzero raw
    /// value giving a nonzero (and normal, full-precision) one: the current scale must be from
    /// [`Settings::CURRENT_SCALE_MIN`] to [`Settings::CURRENT_SCALE_MAX`] (`1e-34` to `1e37`),
    /// pole pairs at least 1 (any `u16` but 0), the gear ratio from
    /// [`Settings::GEAR_RATIO_MIN`] to [`Settings::GEAR_RATIO_MAX`] (`1e-28` to `1e33`).
    /// NaN is refused. The bounds are the arithmetic's (see each), rounded inwards to a power of
    /// ten: real scales and ratios lie far inside them.
    ///
    /// ```
    /// use hwfoc::Settings;
    ///
    /// assert!(Settings::new(100.0, 14, 2.5).is_ok());
    /// let error = Settings::new(1e-38, 7, 1.0).unwrap_err();
    /// assert_eq!(error.to_string(), "current scale must be from 1e-34 to 1e37, not 1e-38");
    /// ```
    pub fn new(
        current_scale: f32,
        pole_pairs: u16,
        gear_ratio: f32,
    ) -> Result<Self, SettingsError> {
        if !(Self::CURRENT_SCALE_MIN..=Self::CURRENT_SCALE_MAX).contains(&current_scale) {
            return Err(SettingsError::CurrentScale(current_scale));
        }
        if pole_pairs == 0 {
            return Err(SettingsError::PolePairs);
        }
        if !(Self::GEAR_RATIO_MIN..=Self::GEAR_RATIO_MAX).contains(&gear_ratio) {
            return Err(SettingsError::GearRatio(gear_ratio));
        }
        Ok(Settings {
            current_scale,
            pole_pairs,
            gear_ratio,
            ..Settings::DEFAULT
        })
    }

    /// Amperes for a raw current value (input or phase): `raw / current scale`.
    #[inline]
    pub fn amps(&self, raw: i16) -> f32 {
        self.amps_linear().to_f32(f32::from(raw))
    }

    /// Mechanical RPM for an electrical RPM: `erpm / (gear ratio * pole pairs)`.
    #[inline]
    pub fn rpm_from_erpm(&self, erpm: u32) -> f32 {
        self.erpm_to_rpm().to_f32(erpm as f32)
    }

    /// The conversion of a raw current (input or phase) to amperes: `raw / current scale`.
    #[inline]
    pub const fn amps_linear(&self) -> Linear {
        Linear::new(1.0, self.current_scale, 1.0)
    }

    /// The conversion of an electrical RPM to mechanical RPM: `erpm / (gear ratio * pole pairs)`.
    #[inline]
    pub const fn erpm_to_rpm(&self) -> Linear {
        Linear::new(1.0, self.gear_ratio, self.pole_pairs as f32)
    }

    /// The conversion of a raw eRPM field to mechanical RPM:
    /// `raw * 10 / (gear ratio * pole pairs)`, [`Linear::ERPM`] and
    /// [`Settings::erpm_to_rpm`] in one step (exact: `raw * 10` is an integer below 2^24).
    #[inline]
    pub const fn rpm_linear(&self) -> Linear {
        Linear {
            mul: Linear::ERPM.mul,
            ..self.erpm_to_rpm()
        }
    }
}

/// A setting that [`Settings::new`] refuses; its message gives the range accepted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SettingsError {
    /// The current scale is not from [`Settings::CURRENT_SCALE_MIN`] to
    /// [`Settings::CURRENT_SCALE_MAX`] (or is NaN).
    CurrentScale(f32),
    /// Pole pairs must be at least 1.
    PolePairs,
    /// The gear ratio is not from [`Settings::GEAR_RATIO_MIN`] to [`Settings::GEAR_RATIO_MAX`]
    /// (or is NaN).
    GearRatio(f32),
}

impl fmt::Display for SettingsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            SettingsError::CurrentScale(v) => write!(
                f,
                "current scale must be from {:e} to {:e}, not {}",
                Settings::CURRENT_SCALE_MIN,
                Settings::CURRENT_SCALE_MAX,
                Number(v)
            ),
            SettingsError::PolePairs => f.write_str("pole pairs must be at least 1, not 0"),
            SettingsError::GearRatio(v) => write!(
                f,
                "gear ratio must be from {:e} to {:e}, not {}",
                Settings::GEAR_RATIO_MIN,
                Settings::GEAR_RATIO_MAX,
                Number(v)
            ),
        }
    }
}

/// A number as a user would write it: `64`, `0.5`, but `1e-38` and `3.4028235e38` rather than
/// forty digits.
struct Number(f32);

impl fmt::Display for Number {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        if v == 0.0 || !v.is_finite() || (1e-4..1e16).contains(&v.abs()) {
            write!(f, "{v}")
        } else {
            write!(f, "{v:e}")
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

/// The ADC code an HW-FOC frame carries for "no temperature": 255, above the table (what a
/// disconnected sensor reads), which [`Temperature::from_adc`] gives no degC for.
pub const ADC_NO_VALUE: u8 = u8::MAX;

const _: () = assert!(ADC_NO_VALUE > ADC_MAX);

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
            // From `code` itself, which has no temperature: the nearest that have.
            let mut lo = code; // hotter neighbour (lower code)
            while exact[lo].is_nan() {
                lo -= 1;
            }
            let mut hi = code; // colder neighbour (higher code)
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

    /// The ADC code whose temperature is nearest `celsius`, the inverse of
    /// [`Temperature::from_adc`] for every code in the table's range ([`ADC_MIN`]..=[`ADC_MAX`]):
    /// saturated to that range (below 0 degC gives [`ADC_MAX`], above 129 degC [`ADC_MIN`]);
    /// NaN gives [`ADC_NO_VALUE`].
    ///
    /// ```
    /// use hwfoc::Temperature;
    ///
    /// assert_eq!(Temperature::adc_of(28.0), 206);
    /// assert_eq!(Temperature::adc_of(15.4), 225); // 15.5 degC, between 226 and 224
    /// assert_eq!(Temperature::adc_of(-40.0), 241); // saturated to 0 degC
    /// assert_eq!(Temperature::adc_of(300.0), 33); // saturated to 129 degC
    /// ```
    pub fn adc_of(celsius: f32) -> u8 {
        if celsius.is_nan() {
            return ADC_NO_VALUE;
        }
        // The table's temperatures fall strictly as codes rise: the nearest is one of the two
        // codes around `celsius`. (A linear scan of 209 codes: this runs once per frame.)
        let mut best = ADC_MAX;
        let mut best_gap = f32::INFINITY;
        for code in ADC_MIN..=ADC_MAX {
            let gap = (CELSIUS[code as usize] - celsius).abs();
            if gap < best_gap {
                best = code;
                best_gap = gap;
            }
        }
        best
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

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;

    /// The linear conversions of the HW-FOC fields, and RPM under two settings.
    fn conversions() -> [(&'static str, Linear); 8] {
        let odd = Settings::new(100.0, 14, 2.5).unwrap();
        [
            ("throttle", Linear::THROTTLE_PCT),
            ("erpm", Linear::ERPM),
            ("volts", Linear::VOLTS),
            ("identity", Linear::IDENTITY),
            ("amps /64", Settings::DEFAULT.amps_linear()),
            ("amps /100", odd.amps_linear()),
            ("rpm", Settings::DEFAULT.rpm_linear()),
            ("rpm 14 pp x2.5", odd.rpm_linear()),
        ]
    }

    #[test]
    fn round_half_away_is_std_round() {
        for x in [
            0.0,
            0.49,
            0.5,
            1.5,
            2.5,
            -0.5,
            -2.5,
            -2.49,
            1e300,
            4503599627370495.5,
        ] {
            assert_eq!(round_half_away(x), x.round(), "{x}");
            assert_eq!(round_half_away(-x), (-x).round(), "{}", -x);
        }
        assert!(round_half_away(f64::NAN).is_nan());
        assert_eq!(round_half_away(f64::INFINITY), f64::INFINITY);
    }

    #[test]
    fn raw_of_inverts_to_f32_for_every_raw_value() {
        for (name, linear) in conversions() {
            for raw in i32::from(i16::MIN)..=i32::from(u16::MAX) {
                let value = linear.to_f32(raw as f32);
                assert_eq!(linear.raw_of(value), f64::from(raw), "{name}: raw {raw}");
            }
        }
    }

    #[test]
    fn to_f32_of_raw_of_is_within_half_a_step() {
        for (name, linear) in conversions() {
            let step = f64::from(linear.to_f32(1.0));
            let (lo, hi) = (linear.to_f64(-32768.0), linear.to_f64(65535.0));
            // 100 001 values over the range, none of them on a raw step.
            for i in 0..=100_000 {
                let x = (lo + (hi - lo) * (f64::from(i) + 0.37) / 100_001.0) as f32;
                let back = f64::from(linear.to_f32(linear.raw_of(x) as f32));
                let x = f64::from(x);
                let error = (back - x).abs();
                // Half a step, plus the rounding of the forward conversion's `f32` result.
                let rounding = x.abs() * f64::from(f32::EPSILON);
                assert!(error <= step / 2.0 + rounding, "{name}: {x} -> {back}");
            }
        }
    }

    #[test]
    fn adc_of_inverts_from_adc_for_every_code_in_the_table() {
        for code in ADC_MIN..=ADC_MAX {
            let celsius = Temperature::from_adc(code).celsius().unwrap();
            assert_eq!(Temperature::adc_of(celsius), code, "{celsius} degC");
        }
        assert_eq!(Temperature::adc_of(f32::NAN), ADC_NO_VALUE);
        assert_eq!(Temperature::from_adc(ADC_NO_VALUE).celsius(), None);
    }

    #[test]
    fn from_adc_of_adc_of_is_within_half_a_step() {
        let t = |code: u8| Temperature::from_adc(code).celsius().unwrap();
        for i in 0..12_900 {
            let celsius = i as f32 / 100.0 + 0.003;
            let code = Temperature::adc_of(celsius);
            let error = (t(code) - celsius).abs();
            // The step to the neighbouring code on the side of `celsius` (codes rise as it
            // falls).
            let step = if t(code) > celsius {
                t(code) - t(code + 1)
            } else {
                t(code - 1) - t(code)
            };
            assert!(error <= step / 2.0 + 1e-4, "{celsius} degC -> {code}");
        }
        assert_eq!(Temperature::adc_of(-5.0), ADC_MAX);
        assert_eq!(Temperature::adc_of(135.0), ADC_MIN);
    }
}
