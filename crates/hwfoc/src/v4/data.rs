//! The V4 data frame: its raw fields ([`DataFrame`]), and the frame as the decoder emits it with
//! the scales it was decoded under ([`Data`]).

use crate::status::Status;
use crate::telemetry::{Conversion, Reading, Telemetry};
use crate::units::{Linear, Quantity, Settings};
use crate::wire::SYNC;

use super::info::{InfoFrame, VoltsPerStep, throttle_linear};
use super::layout::{ADC_LIMIT, DATA_FRAME_LEN, DEFAULT_FULL_SCALE, SLOW_DATA_FRAME_LEN, TRAILER};
use crate::ntc::ntc_celsius;

/// One V4 data frame, every field as the raw integer sent.
///
/// Its scales come from the info frame ([`InfoFrame`]); [`Data`] is a data frame with the info
/// frame it was decoded under, and has the conversions.
///
/// ```
/// use hwfoc::v4::DataFrame;
///
/// // The first data frame of the Platinum V4 capture (slow mode: with its trailing B9).
/// let bytes = [0x9B, 0x00, 0x03, 0x31, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x05, 0x4C,
///              0x00, 0x00, 0x0C, 0xB4, 0x00, 0x00, 0xB9];
/// let frame = DataFrame::parse(&bytes).unwrap();
/// assert_eq!((frame.counter, frame.voltage_adc, frame.temp_adc), (817, 1356, 3252));
/// assert_eq!(frame.encode_with_trailer(), bytes);
/// assert_eq!(frame.encode(), bytes[..19]);
/// assert!(frame.is_plausible(1000));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct DataFrame {
    /// Packet counter, +1 per data frame (info frames are not counted); 24 bits (the encoder
    /// writes the low 24).
    pub counter: u32,
    /// Input throttle, 0..=full scale (the info frame's; 1000 before one).
    pub throttle_in_raw: u16,
    /// Output PWM, 0..=full scale.
    pub throttle_out_raw: u16,
    /// Electrical RPM, 24 bits.
    pub erpm: u32,
    /// Voltage ADC value, 12 bits; volts per step from the info frame (or a setting).
    pub voltage_adc: u16,
    /// Current ADC value, 12 bits; always 0 on ESCs without a current sensor.
    pub current_adc: u16,
    /// MOSFET temperature ADC value (NTC), 12 bits; 0 is no reading.
    pub temp_adc: u16,
    /// Second temperature ADC value (called CAP or BEC by different sources), 12 bits; 0 is no
    /// reading (so at idle in the capture). Converted as [`DataFrame::temp_adc`].
    pub temp2_adc: u16,
}

impl DataFrame {
    /// The data frame in `bytes` (its first 19), if they start with `9B`; every field is read
    /// as sent, plausible or not ([`DataFrame::is_plausible`]). A trailing `B9` is not read.
    pub fn parse(bytes: &[u8]) -> Option<DataFrame> {
        let b = bytes.first_chunk::<DATA_FRAME_LEN>()?;
        (b[0] == SYNC).then(|| Self::read(b))
    }

    /// Reads the fields (the first byte is not checked).
    #[inline(always)]
    pub(crate) fn read(b: &[u8; DATA_FRAME_LEN]) -> DataFrame {
        let u16_at = |i: usize| u16::from_be_bytes([b[i], b[i + 1]]);
        DataFrame {
            counter: u32::from_be_bytes([0, b[1], b[2], b[3]]),
            throttle_in_raw: u16_at(4),
            throttle_out_raw: u16_at(6),
            erpm: u32::from_be_bytes([0, b[8], b[9], b[10]]),
            voltage_adc: u16_at(11),
            current_adc: u16_at(13),
            temp_adc: u16_at(15),
            temp2_adc: u16_at(17),
        }
    }

    /// The 19 bytes of the frame as sent in running ("fast") mode.
    pub const fn encode(&self) -> [u8; DATA_FRAME_LEN] {
        let c = self.counter.to_be_bytes();
        let t = self.throttle_in_raw.to_be_bytes();
        let p = self.throttle_out_raw.to_be_bytes();
        let e = self.erpm.to_be_bytes();
        let v = self.voltage_adc.to_be_bytes();
        let i = self.current_adc.to_be_bytes();
        let m = self.temp_adc.to_be_bytes();
        let s = self.temp2_adc.to_be_bytes();
        [
            SYNC, c[1], c[2], c[3], t[0], t[1], p[0], p[1], e[1], e[2], e[3], v[0], v[1], i[0],
            i[1], m[0], m[1], s[0], s[1],
        ]
    }

    /// The 20 bytes of the frame as sent in idle ("slow") mode: with the trailing `B9`.
    pub const fn encode_with_trailer(&self) -> [u8; SLOW_DATA_FRAME_LEN] {
        let mut out = [TRAILER; SLOW_DATA_FRAME_LEN];
        let f = self.encode();
        let mut k = 0;
        while k < DATA_FRAME_LEN {
            out[k] = f[k];
            k += 1;
        }
        out
    }

    /// Whether the frame passes the format's plausibility test, which stands in for a checksum:
    /// throttle and PWM at most `full_scale`, and the four ADC fields below 4096. (The counter
    /// is tested against the frames around it by the decoder; the eRPM can hold any value.)
    #[inline(always)]
    pub const fn is_plausible(&self, full_scale: u16) -> bool {
        self.throttle_in_raw <= full_scale
            && self.throttle_out_raw <= full_scale
            && (self.voltage_adc | self.current_adc | self.temp_adc | self.temp2_adc) < ADC_LIMIT
    }

    /// MOSFET temperature in degC, or `None` for no reading ([`ntc_celsius`]).
    pub fn temp_c(&self) -> Option<f32> {
        ntc_celsius(self.temp_adc)
    }

    /// Second temperature in degC, or `None` for no reading ([`ntc_celsius`]).
    pub fn temp2_c(&self) -> Option<f32> {
        ntc_celsius(self.temp2_adc)
    }
}

/// A data frame as the decoder emits it: its raw fields and the info frame whose constants were
/// adopted when it was decoded (`None` before the first adoption). Its conversions need no
/// decoder state.
///
/// | quantity | conversion |
/// |---|---|
/// | packet | [`Data::packet`], the 24-bit counter |
/// | throttle in / out | raw * 100 / full scale ([`Data::full_scale`]: the info frame's, else 1000) |
/// | eRPM | as sent |
/// | voltage | adc * volts per step: the info frame's V1 / (V2 * 10), else the caller's setting |
/// | current | `None` before an info frame and without a current sensor; else adc * I1 / I2 - I3, not below 0 |
/// | MOSFET and second temperature | [`ntc_celsius`]; `None` for 0 |
///
/// It carries no phase current and no status word.
///
/// ```
/// use hwfoc::v4::{Data, DataFrame, InfoFrame, VoltsPerStep};
///
/// let frame = DataFrame { throttle_in_raw: 500, voltage_adc: 1365, current_adc: 40, ..Default::default() };
/// let before = Data { frame, info: None };
/// assert_eq!(before.throttle_in_pct(), 50.0);
/// assert_eq!(before.voltage_v(VoltsPerStep::DEFAULT), 12.0);
/// assert_eq!(before.current_a(), None);
/// let info = InfoFrame { full_scale: 2000, v1: 11, v2: 65, i1: 1, i2: 2, i3: 0, ..Default::default() };
/// let after = Data { frame, info: Some(info) };
/// assert_eq!(after.throttle_in_pct(), 25.0);
/// assert_eq!(after.voltage_v(VoltsPerStep::DEFAULT), 1365.0 * 11.0 / 650.0);
/// assert_eq!(after.current_a(), Some(20.0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Data {
    /// The raw fields.
    pub frame: DataFrame,
    /// The adopted info frame it was decoded under, if any.
    pub info: Option<InfoFrame>,
}

impl Data {
    /// The packet counter (24 bits).
    pub const fn packet(&self) -> u32 {
        self.frame.counter
    }

    /// Full scale of throttle and PWM: the info frame's, else 1000.
    pub const fn full_scale(&self) -> u16 {
        match self.info {
            Some(info) => info.full_scale,
            None => DEFAULT_FULL_SCALE,
        }
    }

    /// The conversion of throttle and PWM to percent: `raw * 100 / full scale`.
    pub const fn throttle_linear(&self) -> Linear {
        throttle_linear(self.full_scale())
    }

    /// Input throttle in percent.
    pub fn throttle_in_pct(&self) -> f32 {
        self.throttle_linear()
            .to_f32(f32::from(self.frame.throttle_in_raw))
    }

    /// Output PWM in percent.
    pub fn throttle_out_pct(&self) -> f32 {
        self.throttle_linear()
            .to_f32(f32::from(self.frame.throttle_out_raw))
    }

    /// Electrical RPM.
    pub const fn erpm(&self) -> u32 {
        self.frame.erpm
    }

    /// Volts per voltage ADC step: the info frame's, else `before_info` (the user's setting).
    pub const fn volts_per_step(&self, before_info: VoltsPerStep) -> VoltsPerStep {
        match self.info {
            Some(info) => info.volts_per_step(),
            None => before_info,
        }
    }

    /// Voltage in volts, through [`Data::volts_per_step`].
    pub fn voltage_v(&self, before_info: VoltsPerStep) -> f32 {
        self.volts_per_step(before_info)
            .volts(self.frame.voltage_adc)
    }

    /// Current in amps, or `None` before an info frame is adopted and on an ESC without a
    /// current sensor.
    pub fn current_a(&self) -> Option<f32> {
        self.info?.current_a(self.frame.current_adc)
    }

    /// MOSFET temperature in degC, or `None` for no reading.
    pub fn temp_c(&self) -> Option<f32> {
        self.frame.temp_c()
    }

    /// Second temperature in degC, or `None` for no reading.
    pub fn temp2_c(&self) -> Option<f32> {
        self.frame.temp2_c()
    }
}

impl Telemetry for Data {
    #[inline]
    fn packet(&self) -> Option<u32> {
        Some(self.frame.counter)
    }

    /// None: V4 sends no status word.
    #[inline]
    fn status(&self) -> Option<Status> {
        None
    }

    /// Throttle and PWM through the full scale, voltage through the info frame's volts per step
    /// (before one, `settings.v4_volts_per_step`), current through its constants (not carried
    /// before one, nor without a current sensor), temperatures through the NTC formula.
    #[inline]
    fn reading(&self, quantity: Quantity, settings: &Settings) -> Option<Reading> {
        let linear = |raw: u32, linear| Reading::linear(raw as i32, linear);
        let f = &self.frame;
        Some(match quantity {
            Quantity::ThrottleIn => linear(f.throttle_in_raw.into(), self.throttle_linear()),
            Quantity::ThrottleOut => linear(f.throttle_out_raw.into(), self.throttle_linear()),
            Quantity::Erpm => linear(f.erpm, Linear::IDENTITY),
            Quantity::Rpm => linear(f.erpm, settings.erpm_to_rpm()),
            Quantity::Voltage => linear(
                f.voltage_adc.into(),
                self.volts_per_step(settings.v4_volts_per_step).linear(),
            ),
            Quantity::Current => Reading {
                raw: f.current_adc.into(),
                conversion: Conversion::V4Current(self.info?.current_scale()?),
            },
            Quantity::MosTemp => Reading {
                raw: f.temp_adc.into(),
                conversion: Conversion::Ntc,
            },
            Quantity::CapTemp => Reading {
                raw: f.temp2_adc.into(),
                conversion: Conversion::Ntc,
            },
            Quantity::PhaseCurrent
            | Quantity::MotorTemp
            | Quantity::BecTemp
            | Quantity::BecVoltage
            | Quantity::BecCurrent => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_field_at_its_offset() {
        let f = DataFrame {
            counter: 0x01_0203,
            throttle_in_raw: 0x0405,
            throttle_out_raw: 0x0607,
            erpm: 0x08_090A,
            voltage_adc: 0x0B0C,
            current_adc: 0x0D0E,
            temp_adc: 0x0F10,
            temp2_adc: 0x1112,
        };
        let b = f.encode();
        let mut want = [0u8; 19];
        want[0] = 0x9B;
        for (k, w) in want.iter_mut().enumerate().skip(1) {
            *w = k as u8;
        }
        assert_eq!(b, want);
        assert_eq!(DataFrame::parse(&b), Some(f));
        assert_eq!(DataFrame::parse(&b[..18]), None);
        assert_eq!(f.encode_with_trailer()[19], 0xB9);
    }

    #[test]
    fn plausibility() {
        let ok = DataFrame {
            throttle_in_raw: 1000,
            throttle_out_raw: 1000,
            voltage_adc: 4095,
            current_adc: 4095,
            temp_adc: 4095,
            temp2_adc: 4095,
            ..Default::default()
        };
        assert!(ok.is_plausible(1000));
        assert!(!ok.is_plausible(999));
        let bad = [
            DataFrame {
                throttle_in_raw: 1001,
                ..ok
            },
            DataFrame {
                throttle_out_raw: 1001,
                ..ok
            },
            DataFrame {
                voltage_adc: 4096,
                ..ok
            },
            DataFrame {
                current_adc: 4096,
                ..ok
            },
            DataFrame {
                temp_adc: 4096,
                ..ok
            },
            DataFrame {
                temp2_adc: 0x8000,
                ..ok
            },
        ];
        for f in bad {
            assert!(!f.is_plausible(1000), "{f:?}");
        }
    }
}
