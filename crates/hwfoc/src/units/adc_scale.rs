//! The scales of a Hobbywing V4 ESC's ADC codes that outlive a frame: volts per voltage step
//! (a user's setting until an info frame is adopted, [`Settings`](crate::Settings)) and the
//! current scale of an adopted info frame ([`Conversion::V4Current`](crate::Conversion)).
//! Here, not in [`crate::v4`], because the neutral [`Settings`](crate::Settings) and
//! [`crate::telemetry`] hold them; [`crate::v4`] re-exports them.

use super::Linear;

/// Volts per voltage ADC step as a fraction `num / den`: from an adopted info frame
/// ([`InfoFrame::volts_per_step`](crate::v4::InfoFrame::volts_per_step)), or, before one, the user's setting
/// ([`VoltsPerStep::LOW_VOLTAGE`] by default, [`VoltsPerStep::HIGH_VOLTAGE`] for HV models).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct VoltsPerStep {
    /// Numerator.
    pub num: u16,
    /// Denominator (0 gives no value: infinite or NaN volts).
    pub den: u16,
}

impl VoltsPerStep {
    /// 8/910 V per step: low-voltage models, and the Platinum V4 capture's info frame.
    pub const LOW_VOLTAGE: VoltsPerStep = VoltsPerStep { num: 8, den: 910 };
    /// 11/650 V per step: HV models.
    pub const HIGH_VOLTAGE: VoltsPerStep = VoltsPerStep { num: 11, den: 650 };
    /// The default setting before an info frame is adopted: [`VoltsPerStep::LOW_VOLTAGE`].
    pub const DEFAULT: VoltsPerStep = Self::LOW_VOLTAGE;

    /// The conversion: `adc * num / den`.
    pub const fn linear(self) -> Linear {
        Linear::new(self.num as f32, self.den as f32, 1.0)
    }

    /// The voltage in volts for a voltage ADC value.
    pub fn volts(self, adc: u16) -> f32 {
        self.linear().to_f32(f32::from(adc))
    }
}

impl core::fmt::Display for VoltsPerStep {
    /// `8/910`: as [`VoltsPerStep::from_str`](core::str::FromStr) reads it.
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}/{}", self.num, self.den)
    }
}

/// What a [`VoltsPerStep`] is written as, in words (its error's message).
pub(crate) const VOLTS_PER_STEP_FORM: &str = "volts per step must be N/D with whole numbers from 1 \
     to 65535 (8/910 for low-voltage models, 11/650 for HV), or low or hv";

/// Why a text is not a [`VoltsPerStep`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VoltsPerStepError {
    /// Not `N/D` with two whole numbers from 1 to 65535, nor `low` or `hv`.
    Form,
}

impl core::fmt::Display for VoltsPerStepError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(VOLTS_PER_STEP_FORM)
    }
}

impl core::error::Error for VoltsPerStepError {}

impl core::str::FromStr for VoltsPerStep {
    type Err = VoltsPerStepError;

    /// `N/D` (`8/910`), or `low` ([`VoltsPerStep::LOW_VOLTAGE`]) or `hv`
    /// ([`VoltsPerStep::HIGH_VOLTAGE`]).
    ///
    /// ```
    /// use hwfoc::v4::VoltsPerStep;
    ///
    /// assert_eq!("11/650".parse(), Ok(VoltsPerStep::HIGH_VOLTAGE));
    /// assert_eq!("low".parse(), Ok(VoltsPerStep::LOW_VOLTAGE));
    /// assert!("8/0".parse::<VoltsPerStep>().is_err());
    /// assert_eq!(VoltsPerStep::HIGH_VOLTAGE.to_string(), "11/650");
    /// ```
    fn from_str(text: &str) -> Result<VoltsPerStep, VoltsPerStepError> {
        match text.trim() {
            "low" => return Ok(VoltsPerStep::LOW_VOLTAGE),
            "hv" => return Ok(VoltsPerStep::HIGH_VOLTAGE),
            _ => {}
        }
        let (num, den) = text.trim().split_once('/').ok_or(VoltsPerStepError::Form)?;
        let whole = |t: &str| {
            t.trim()
                .parse::<u16>()
                .ok()
                .filter(|&n| n > 0)
                .ok_or(VoltsPerStepError::Form)
        };
        Ok(VoltsPerStep {
            num: whole(num)?,
            den: whole(den)?,
        })
    }
}

impl Default for VoltsPerStep {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The current conversion of an info frame with a current sensor:
/// `amps = adc * mul / div - offset`, not below 0 (I1, I2, I3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct CurrentScale {
    /// I1.
    pub mul: u8,
    /// I2.
    pub div: u8,
    /// I3, in amps.
    pub offset: u8,
}

impl CurrentScale {
    /// The current in amps for a current ADC value: `adc * mul / div - offset`, not below 0.
    pub fn amps(self, adc: u16) -> f32 {
        let amps =
            f32::from(adc) * f32::from(self.mul) / f32::from(self.div) - f32::from(self.offset);
        amps.max(0.0)
    }
}
