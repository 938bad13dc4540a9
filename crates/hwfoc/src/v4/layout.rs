//! The V4 frames on the wire (`docs/OLDER-PROTOCOLS.md`), big-endian, no checksum.
//!
//! ```text
//! data frame, 19 bytes (+ B9 in slow mode):
//!  0    1..3      4..5       6..7      8..10   11..12     13..14     15..16       17..18        (19)
//!  9B   counter   throttle   PWM       eRPM    voltage    current    MOSFET temp  2nd temp      (B9)
//!       u24       u16        u16       u24     ADC u16    ADC u16    ADC u16      ADC u16
//!
//! info frame, 13 bytes (idle only):
//!  0    1    2..3         4    5    6    7    8    9    10   11   12
//!  9B   9B   full scale   01   V1   V2   I1   I2   I3   T1   T2   B9
//! ```

/// Length of a data frame without its trailer (running, "fast" mode).
pub const DATA_FRAME_LEN: usize = 19;
/// Length of a data frame with its trailing [`TRAILER`] (idle, "slow" mode).
pub const SLOW_DATA_FRAME_LEN: usize = DATA_FRAME_LEN + 1;
/// Length of an info frame.
pub const INFO_FRAME_LEN: usize = 13;
/// The byte after a data frame in slow mode, and the last byte of an info frame. It also occurs
/// inside frames: it is not a delimiter.
pub const TRAILER: u8 = 0xB9;
/// Byte 4 of an info frame.
pub const INFO_MARK: u8 = 0x01;
/// Offset of the big-endian u24 packet counter in a data frame.
pub const COUNTER_AT: usize = 1;
/// Full scale of throttle and PWM until an info frame is adopted.
pub const DEFAULT_FULL_SCALE: u16 = 1000;
pub use crate::ntc::ADC_LIMIT;
