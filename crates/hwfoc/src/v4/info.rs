//! The V4 info frame: the ESC's scales (throttle full scale, volts per ADC step, current), and
//! the voltage setting used before one is adopted.

use crate::units::Linear;
pub(crate) use crate::units::VOLTS_PER_STEP_FORM;
pub use crate::units::{CurrentScale, VoltsPerStep, VoltsPerStepError};
use crate::wire::SYNC;

use super::layout::{INFO_FRAME_LEN, INFO_MARK, TRAILER};

/// A V4 info frame (`9B 9B | full scale | 01 | V1 V2 | I1 I2 I3 | T1 T2 | B9`), every field as
/// sent. Sent while the ESC idles, alternating with data frames; it carries no counter.
///
/// The decoder adopts its constants for the data frames that follow only once two identical
/// copies have come in a row ([`Stats::adopted`](super::Stats::adopted)): with no checksum, a
/// flipped bit would otherwise change every later value.
///
/// ```
/// use hwfoc::v4::{InfoFrame, VoltsPerStep};
///
/// // The info frame of the Platinum V4 capture.
/// let bytes = [0x9B, 0x9B, 0x03, 0xE8, 0x01, 0x08, 0x5B, 0x00, 0x01, 0x00, 0x21, 0x21, 0xB9];
/// let info = InfoFrame::parse(&bytes).unwrap();
/// assert_eq!(info.full_scale, 1000);
/// assert_eq!(info.volts_per_step(), VoltsPerStep { num: 8, den: 910 });
/// assert!(!info.has_current_sensor());
/// assert_eq!(info.current_a(2000), None);
/// assert_eq!(info.encode(), bytes);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct InfoFrame {
    /// Full scale of the data frames' throttle and PWM fields (bytes 2-3; 1000 in the capture).
    pub full_scale: u16,
    /// V1: volts per voltage ADC step = V1 / (V2 * 10).
    pub v1: u8,
    /// V2 (see [`InfoFrame::v1`]); 0 is implausible.
    pub v2: u8,
    /// I1: amps = adc * I1 / I2 - I3, not below 0; 0 means no current sensor.
    pub i1: u8,
    /// I2 (see [`InfoFrame::i1`]); 0 with a current sensor is implausible.
    pub i2: u8,
    /// I3, an offset in amps (see [`InfoFrame::i1`]).
    pub i3: u8,
    /// T1: meaning unknown, kept raw.
    pub t1: u8,
    /// T2: meaning unknown, kept raw.
    pub t2: u8,
}

impl InfoFrame {
    /// The info frame in `bytes` (its first 13), if they have its fixed bytes (`9B 9B` at 0,
    /// `01` at 4, `B9` at 12); its fields are read as sent, plausible or not
    /// ([`InfoFrame::is_plausible`]).
    pub fn parse(bytes: &[u8]) -> Option<InfoFrame> {
        let b = bytes.first_chunk::<INFO_FRAME_LEN>()?;
        Self::has_fixed_bytes(b).then(|| Self::read(b))
    }

    /// Whether `b` has the fixed bytes of an info frame.
    #[inline(always)]
    pub(crate) const fn has_fixed_bytes(b: &[u8; INFO_FRAME_LEN]) -> bool {
        b[0] == SYNC && b[1] == SYNC && b[4] == INFO_MARK && b[12] == TRAILER
    }

    /// Reads the fields (the fixed bytes are not checked).
    #[inline(always)]
    pub(crate) const fn read(b: &[u8; INFO_FRAME_LEN]) -> InfoFrame {
        InfoFrame {
            full_scale: u16::from_be_bytes([b[2], b[3]]),
            v1: b[5],
            v2: b[6],
            i1: b[7],
            i2: b[8],
            i3: b[9],
            t1: b[10],
            t2: b[11],
        }
    }

    /// The 13 bytes an ESC sends for this frame.
    pub const fn encode(&self) -> [u8; INFO_FRAME_LEN] {
        let f = self.full_scale.to_be_bytes();
        [
            SYNC, SYNC, f[0], f[1], INFO_MARK, self.v1, self.v2, self.i1, self.i2, self.i3,
            self.t1, self.t2, TRAILER,
        ]
    }

    /// Whether its constants can be used: a full scale above 0, V2 above 0, and I2 above 0
    /// when there is a current sensor (no division by zero). An implausible info frame is
    /// rejected by the decoder.
    #[inline(always)]
    pub const fn is_plausible(&self) -> bool {
        self.full_scale != 0 && self.v2 != 0 && (self.i1 == 0 || self.i2 != 0)
    }

    /// Volts per voltage ADC step: V1 / (V2 * 10).
    pub const fn volts_per_step(&self) -> VoltsPerStep {
        VoltsPerStep {
            num: self.v1 as u16,
            den: self.v2 as u16 * 10,
        }
    }

    /// Whether the ESC has a current sensor (I1 is not 0).
    pub const fn has_current_sensor(&self) -> bool {
        self.i1 != 0
    }

    /// The current conversion, or `None` without a current sensor.
    pub const fn current_scale(&self) -> Option<CurrentScale> {
        if self.has_current_sensor() {
            Some(CurrentScale {
                mul: self.i1,
                div: self.i2,
                offset: self.i3,
            })
        } else {
            None
        }
    }

    /// The current in amps for a current ADC value, or `None` without a current sensor.
    pub fn current_a(&self, adc: u16) -> Option<f32> {
        self.current_scale().map(|s| s.amps(adc))
    }

    /// The conversion of throttle and PWM to percent: `raw * 100 / full scale`.
    pub const fn throttle_linear(&self) -> Linear {
        throttle_linear(self.full_scale)
    }
}

impl core::fmt::Display for InfoFrame {
    /// The constants in words: `full scale 1000, 8/910 V per step, no current sensor, T1 0x21
    /// T2 0x21` (with a sensor: `current adc * 1 / 2 - 0 A`).
    ///
    /// ```
    /// use hwfoc::v4::InfoFrame;
    ///
    /// let info = InfoFrame { full_scale: 1000, v1: 8, v2: 91, i1: 0, i2: 1, i3: 0, t1: 0x21, t2: 0x21 };
    /// assert_eq!(info.to_string(), "full scale 1000, 8/910 V per step, no current sensor, T1 0x21 T2 0x21");
    /// ```
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let v = self.volts_per_step();
        write!(
            f,
            "full scale {}, {}/{} V per step, ",
            self.full_scale, v.num, v.den
        )?;
        match self.current_scale() {
            Some(c) => write!(f, "current adc * {} / {} - {} A", c.mul, c.div, c.offset)?,
            None => f.write_str("no current sensor")?,
        }
        write!(f, ", T1 0x{:02X} T2 0x{:02X}", self.t1, self.t2)
    }
}

/// The conversion of throttle and PWM to percent under `full_scale`: `raw * 100 / full_scale`.
pub const fn throttle_linear(full_scale: u16) -> Linear {
    Linear::new(100.0, full_scale as f32, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_bytes_and_plausibility() {
        let info = InfoFrame {
            full_scale: 2000,
            v1: 11,
            v2: 65,
            i1: 3,
            i2: 2,
            i3: 5,
            t1: 7,
            t2: 9,
        };
        let b = info.encode();
        assert_eq!(InfoFrame::parse(&b), Some(info));
        for at in [0, 1, 4, 12] {
            let mut bad = b;
            bad[at] ^= 0x40;
            assert_eq!(InfoFrame::parse(&bad), None, "byte {at}");
        }
        assert_eq!(InfoFrame::parse(&b[..12]), None);
        assert!(info.is_plausible());
        assert!(
            !InfoFrame {
                full_scale: 0,
                ..info
            }
            .is_plausible()
        );
        assert!(!InfoFrame { v2: 0, ..info }.is_plausible());
        assert!(!InfoFrame { i2: 0, ..info }.is_plausible());
        assert!(
            InfoFrame {
                i1: 0,
                i2: 0,
                ..info
            }
            .is_plausible()
        );
    }

    #[test]
    fn conversions() {
        let info = InfoFrame {
            full_scale: 2000,
            v1: 11,
            v2: 65,
            i1: 3,
            i2: 2,
            i3: 5,
            ..Default::default()
        };
        assert_eq!(info.volts_per_step(), VoltsPerStep::HIGH_VOLTAGE);
        assert_eq!(info.current_a(10), Some(10.0));
        assert_eq!(info.current_a(2), Some(0.0)); // 3 - 5: not below 0
        assert_eq!(info.throttle_linear().to_f32(500.0), 25.0);
        assert_eq!(VoltsPerStep::DEFAULT.volts(910), 8.0);
        assert_eq!(InfoFrame { i1: 0, ..info }.current_a(10), None);
    }
}
