//! The V3 frame on the wire (`docs/OLDER-PROTOCOLS.md`), big-endian, no checksum:
//!
//! ```text
//!  0    1..3      4..5           6..7          8..9
//!  9B   counter   throttle in    PWM out       period of one electrical revolution, us
//!       u24       u16, 0..=255   u16, 0..=255  (35314 before the motor turns: no speed)
//! ```

use crate::status::Status;
use crate::telemetry::{Reading, Telemetry};
use crate::units::{Linear, Quantity, Settings};
use crate::wire::SYNC;

/// Length of a V3 frame (the only frame type).
pub const FRAME_LEN: usize = 10;
/// Full scale of the throttle and PWM fields: a frame with either above it is implausible.
pub const FULL_SCALE: u16 = 255;
/// The period the ESC sends before the motor turns (it would read 1699 eRPM): no speed.
pub const PLACEHOLDER_PERIOD_US: u16 = 35_314;
/// Microseconds per minute: eRPM = this / period in microseconds.
pub const US_PER_MINUTE: u32 = 60_000_000;
/// Offset of the big-endian u24 packet counter.
pub const COUNTER_AT: usize = 1;

/// One V3 frame, every field as the raw integer sent.
///
/// It carries a packet counter, the input throttle, the output PWM and the motor's electrical
/// period; **not** voltage, current, temperatures or a status word.
///
/// ```
/// use hwfoc::v3::V3Frame;
///
/// // The first frame of the Platinum Pro V3 capture.
/// let bytes = [0x9B, 0x00, 0x00, 0x00, 0x00, 0x6B, 0x00, 0x0A, 0x89, 0xF2];
/// let frame = V3Frame::parse(&bytes).unwrap();
/// assert_eq!((frame.counter, frame.throttle_in_raw, frame.pwm_out_raw), (0, 107, 10));
/// assert_eq!(frame.erpm(), None); // 35314 us: the ESC's placeholder before the motor turns
/// assert_eq!(frame.encode(), bytes);
/// let turning = V3Frame { period_us: 1554, ..frame };
/// assert_eq!(turning.erpm(), Some(38_610));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct V3Frame {
    /// Packet counter, +1 per frame from 0 at power-up; 24 bits (the top byte of the `u32` is 0
    /// in a decoded frame; the encoder writes the low 24 bits).
    pub counter: u32,
    /// Input throttle, 0..=[`FULL_SCALE`].
    pub throttle_in_raw: u16,
    /// Output PWM, 0..=[`FULL_SCALE`] (10 at idle in the capture).
    pub pwm_out_raw: u16,
    /// Period of one electrical revolution in microseconds ([`PLACEHOLDER_PERIOD_US`] while
    /// the motor does not turn).
    pub period_us: u16,
}

impl V3Frame {
    /// The frame in `bytes` (its first [`FRAME_LEN`] bytes), if they start with `9B`; every
    /// field value is read as sent, plausible or not ([`V3Frame::is_plausible`]).
    pub fn parse(bytes: &[u8]) -> Option<V3Frame> {
        let b = bytes.first_chunk::<FRAME_LEN>()?;
        (b[0] == SYNC).then(|| V3Frame::read(b))
    }

    /// Reads the fields of a frame's bytes (the first is not checked).
    #[inline(always)]
    pub(crate) fn read(b: &[u8; FRAME_LEN]) -> V3Frame {
        V3Frame {
            counter: u32::from_be_bytes([0, b[1], b[2], b[3]]),
            throttle_in_raw: u16::from_be_bytes([b[4], b[5]]),
            pwm_out_raw: u16::from_be_bytes([b[6], b[7]]),
            period_us: u16::from_be_bytes([b[8], b[9]]),
        }
    }

    /// The 10 bytes an ESC sends for this frame (the counter's low 24 bits).
    pub fn encode(&self) -> [u8; FRAME_LEN] {
        let c = self.counter.to_be_bytes();
        let t = self.throttle_in_raw.to_be_bytes();
        let p = self.pwm_out_raw.to_be_bytes();
        let e = self.period_us.to_be_bytes();
        [SYNC, c[1], c[2], c[3], t[0], t[1], p[0], p[1], e[0], e[1]]
    }

    /// Whether the frame passes the format's plausibility test, which stands in for a checksum:
    /// throttle and PWM at most [`FULL_SCALE`]. (The counter is tested against the frames around
    /// it by the decoder; the period can hold any value.)
    #[inline(always)]
    pub const fn is_plausible(&self) -> bool {
        self.throttle_in_raw <= FULL_SCALE && self.pwm_out_raw <= FULL_SCALE
    }

    /// The packet counter (24 bits).
    pub const fn packet(&self) -> u32 {
        self.counter
    }

    /// Input throttle in percent: raw * 100 / 255 ([`V3Frame::THROTTLE_PCT`]).
    pub fn throttle_in_pct(&self) -> f32 {
        Self::THROTTLE_PCT.to_f32(f32::from(self.throttle_in_raw))
    }

    /// Output PWM in percent: raw * 100 / 255.
    pub fn throttle_out_pct(&self) -> f32 {
        Self::THROTTLE_PCT.to_f32(f32::from(self.pwm_out_raw))
    }

    /// The conversion of both throttle fields to percent: `raw * 100 / 255`.
    pub const THROTTLE_PCT: Linear = Linear::new(100.0, FULL_SCALE as f32, 1.0);

    /// Electrical RPM, `60 000 000 / period` (rounded down), or `None` for no speed: the
    /// start-up placeholder [`PLACEHOLDER_PERIOD_US`] and a period of 0.
    pub const fn erpm(&self) -> Option<u32> {
        erpm_of_period(self.period_us)
    }
}

impl Telemetry for V3Frame {
    #[inline]
    fn packet(&self) -> Option<u32> {
        Some(self.counter)
    }

    /// None: V3 sends no status word.
    #[inline]
    fn status(&self) -> Option<Status> {
        None
    }

    /// Throttle and PWM in 255ths; eRPM (and RPM) from the period, its raw integer the eRPM
    /// rounded down ([`V3Frame::erpm`]), not carried by the start-up placeholder or a period of
    /// 0. V3 carries nothing else.
    #[inline]
    fn reading(&self, quantity: Quantity, settings: &Settings) -> Option<Reading> {
        let linear = |raw: u32, linear| Reading::linear(raw as i32, linear);
        Some(match quantity {
            Quantity::ThrottleIn => linear(self.throttle_in_raw.into(), Self::THROTTLE_PCT),
            Quantity::ThrottleOut => linear(self.pwm_out_raw.into(), Self::THROTTLE_PCT),
            Quantity::Erpm => linear(self.erpm()?, Linear::IDENTITY),
            Quantity::Rpm => linear(self.erpm()?, settings.erpm_to_rpm()),
            _ => return None,
        })
    }
}

/// Electrical RPM for a period in microseconds, `60 000 000 / period` rounded down, or `None` for
/// no speed: the placeholder [`PLACEHOLDER_PERIOD_US`] and 0.
pub const fn erpm_of_period(period_us: u16) -> Option<u32> {
    if period_us == 0 || period_us == PLACEHOLDER_PERIOD_US {
        None
    } else {
        Some(US_PER_MINUTE / period_us as u32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_big_endian_and_encode_inverts_parse() {
        let f = V3Frame {
            counter: 0x12_3456,
            throttle_in_raw: 0x00FE,
            pwm_out_raw: 0x0001,
            period_us: 0xA1B2,
        };
        let b = f.encode();
        assert_eq!(
            b,
            [0x9B, 0x12, 0x34, 0x56, 0x00, 0xFE, 0x00, 0x01, 0xA1, 0xB2]
        );
        assert_eq!(V3Frame::parse(&b), Some(f));
        assert_eq!(V3Frame::parse(&b[..9]), None);
        let mut not_sync = b;
        not_sync[0] = 0x9C;
        assert_eq!(V3Frame::parse(&not_sync), None);
        // The encoder writes the low 24 bits of the counter.
        let wide = V3Frame {
            counter: 0xAB12_3456,
            ..f
        };
        assert_eq!(wide.encode(), b);
    }

    #[test]
    fn plausibility_is_throttle_and_pwm_at_most_255() {
        let ok = V3Frame {
            throttle_in_raw: 255,
            pwm_out_raw: 255,
            ..Default::default()
        };
        assert!(ok.is_plausible());
        assert!(
            !V3Frame {
                throttle_in_raw: 256,
                ..ok
            }
            .is_plausible()
        );
        assert!(
            !V3Frame {
                pwm_out_raw: 256,
                ..ok
            }
            .is_plausible()
        );
    }

    #[test]
    fn erpm_and_percent() {
        assert_eq!(erpm_of_period(0), None);
        assert_eq!(erpm_of_period(PLACEHOLDER_PERIOD_US), None);
        assert_eq!(erpm_of_period(35_313), Some(1699));
        assert_eq!(erpm_of_period(1), Some(60_000_000));
        assert_eq!(erpm_of_period(40_843), Some(1469));
        let f = V3Frame {
            throttle_in_raw: 255,
            pwm_out_raw: 51,
            ..Default::default()
        };
        assert_eq!(f.throttle_in_pct(), 100.0);
        assert_eq!(f.throttle_out_pct(), 20.0);
    }
}
