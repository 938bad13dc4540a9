//! Hobbywing V3 telemetry (Platinum V3, Platinum Pro V3): a 10-byte frame about every 19.5 ms
//! on a 19200-baud wire, lead byte `9B`, big-endian, **no checksum** (`docs/OLDER-PROTOCOLS.md`).
//!
//! # What a frame carries
//!
//! | quantity | field | conversion |
//! |---|---|---|
//! | packet | [`V3Frame::counter`], u24 | [`V3Frame::packet`] (`u32`) |
//! | input throttle | [`V3Frame::throttle_in_raw`], 0..=255 | % = raw * 100 / 255 ([`V3Frame::throttle_in_pct`], [`V3Frame::THROTTLE_PCT`]) |
//! | output throttle (PWM) | [`V3Frame::pwm_out_raw`], 0..=255 | % = raw * 100 / 255 ([`V3Frame::throttle_out_pct`]) |
//! | eRPM | [`V3Frame::period_us`], us per electrical revolution | 60 000 000 / period ([`V3Frame::erpm`]); `None` for the start-up placeholder 35314 and for 0 |
//!
//! It does **not** carry voltage, current, phase current, temperatures or a status word, and
//! there is no device-information frame. RPM is eRPM / pole pairs (/ gear ratio), as for HW-FOC.
//!
//! # Recognition, and its limits
//!
//! With no checksum, a frame is recognised by its plausibility (throttle and PWM at most 255),
//! by chaining (the next `9B` exactly where the previous frame ended) and by its counter going
//! up by one. The decoder locks onto a stream after three chained frames and then accepts each
//! frame that continues the chain (also across up to [`MAX_CHAINED_GAP`] frames cut out whole,
//! counted lost); anything else (garbage, a cut or corrupted frame, a counter that jumps
//! further because frames were lost or the ESC restarted) must start a new chain of three,
//! whose first counter's step from the last accepted one is counted (lost frames, a duplicate,
//! a restart). The scanner's state (where the chain ends, the last counter) lives in its
//! [`Stats`], which the streaming layer of [`crate::scan`] hands it with every chunk, and a
//! candidate is decided by at most three frames of bytes: [`Decoder`] and [`frames`] give the
//! same frames and statistics however the stream is cut into chunks.
//!
//! What it cannot see:
//!
//! - **A corruption that keeps a frame plausible**: the period (any value), the low bytes of
//!   throttle and PWM, and any flip leaving both at most 255 go undetected in a chained frame:
//!   about half of all single-bit flips. Only a flip in the counter or in bytes 4 and 6 is
//!   caught (and then the frame and the next two are needed to lock again, see below), and of
//!   the counter's, not one that moves it forward by at most [`MAX_CHAINED_GAP`] (bit 0 or 1
//!   of its low byte set): that frame is taken with a wrong counter, as if frames had been cut
//!   before it, and the next frame (whose counter goes back) starts a new chain.
//! - **A chain break near the end of a stream**: after a break, the next frames are accepted
//!   only once three chain; the last one or two frames of a stream after a break are dropped.
//! - **V4 frames chaining on a V3 stream**: bytes 0-7 of a V4 data frame read as a plausible
//!   V3 frame while throttle and PWM are below 256. A V4 frame placed exactly where a V3 frame
//!   ended, with the next V3 counter, would be taken for one V3 frame (the next V3 position then
//!   falls inside it, so no more follow); V4 frames never form a V3 chain of three
//!   (a V4 frame is 19 or 20 bytes long, not 10). On random bytes no chain of three forms
//!   (two 24-bit counter matches at exact positions): no frame in 2 million random bytes.
//!
//! | module | holds |
//! |---|---|
//! | `frame` | [`V3Frame`] (parse, encode, plausibility, conversions), [`FRAME_LEN`], [`FULL_SCALE`], [`PLACEHOLDER_PERIOD_US`], [`erpm_of_period`] |
//! | `stats` | [`Stats`] (and the chain's end: the scanner's state) |
//! | `decoder` | the scanner: [`Decoder`], [`frames`], [`Decoded`], [`Scanner`] |
//!
//! ```
//! use hwfoc::v3::{self, V3Frame};
//!
//! let mut wire = b"noise".to_vec();
//! for counter in 100..104 {
//!     let frame = V3Frame { counter, throttle_in_raw: 51, pwm_out_raw: 51, period_us: 1500 };
//!     wire.extend_from_slice(&frame.encode());
//! }
//! let decoded: Vec<_> = v3::frames(&wire).collect();
//! assert_eq!(decoded.len(), 4);
//! assert_eq!(decoded[0].offset, 5);
//! assert_eq!(decoded[3].frame.erpm(), Some(40_000));
//! assert_eq!(decoded[3].frame.throttle_in_pct(), 20.0);
//! ```

pub(crate) mod decoder;
mod description;
mod frame;
mod stats;

/// Baud rate of the V3 telemetry wire (8N1), as HW-FOC's.
pub const BAUD_RATE: u32 = crate::foc::BAUD_RATE;

pub use crate::chain::MAX_CHAINED_GAP;
pub use decoder::{CHAIN_TO_LOCK, Decoded, Decoder, Frames, Scanner, frames};
pub use description::DESCRIPTION;
pub use frame::{
    COUNTER_AT, FRAME_LEN, FULL_SCALE, PLACEHOLDER_PERIOD_US, US_PER_MINUTE, V3Frame,
    erpm_of_period,
};
pub use stats::Stats;

crate::protocol::found_frame!(Decoded, HwV3);

impl crate::protocol::FamilyScanner for Scanner {
    fn handed_on(s: &Stats) -> u64 {
        u64::from(s.frames())
    }

    const SILENCE_FRAME_LEN: usize = FRAME_LEN;
}

impl crate::family::FamilyLink for Scanner {
    fn hand_on(d: &Decoded, emit: &mut crate::family::Emit<'_>) {
        let frame = crate::telemetry::Data::HwV3(d.frame);
        emit(None, d.offset, &crate::telemetry::AnyFrame::Data(frame));
    }

    fn figures(s: &Stats) -> Option<crate::family::LinkFigures> {
        Some(crate::family::LinkFigures {
            protocol: crate::Protocol::HwV3,
            bytes: crate::scan::Stats::bytes(s),
            bytes_skipped: s.bytes_skipped(),
            frames: s.frames(),
            info_frames: 0,
            checksum_failures: 0,
            rejected_candidates: Some(s.rejected()),
            packets: Some(crate::family::PacketCounts::of(s.counter())),
            adopted_info: None,
        })
    }
}
