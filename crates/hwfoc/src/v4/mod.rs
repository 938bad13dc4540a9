//! Hobbywing V4 telemetry (Platinum and Platinum Pro V4, FlyFun V5, Align RCE-BL on AL-4.x):
//! a 19-byte data frame (20 with a trailing `B9` while idle) and, while idle, a 13-byte info
//! frame, on a 19200-baud wire, lead byte `9B`, big-endian, **no checksum**
//! (`docs/OLDER-PROTOCOLS.md`).
//!
//! # What a frame carries
//!
//! A data frame as decoded is a [`Data`]: the raw [`DataFrame`] and the info frame whose
//! constants were adopted when it was decoded (`None` before), so that its conversions need no
//! decoder state.
//!
//! | quantity | field | conversion |
//! |---|---|---|
//! | packet | [`DataFrame::counter`], u24 | [`Data::packet`] (`u32`) |
//! | input throttle, output PWM | [`DataFrame::throttle_in_raw`], [`DataFrame::throttle_out_raw`] | % = raw * 100 / full scale (the info frame's, 1000 before): [`Data::throttle_in_pct`], [`Data::throttle_out_pct`], [`Data::throttle_linear`] |
//! | eRPM | [`DataFrame::erpm`], u24 | as sent |
//! | voltage | [`DataFrame::voltage_adc`] | adc * V1 / (V2 * 10) of the info frame, before one the caller's [`VoltsPerStep`] (default 8/910): [`Data::voltage_v`] |
//! | current | [`DataFrame::current_adc`] | adc * I1 / I2 - I3, not below 0 ([`CurrentScale`]); `None` before an info frame is adopted and when I1 = 0 (no current sensor): [`Data::current_a`] |
//! | MOSFET temperature | [`DataFrame::temp_adc`] | NTC ([`ntc_celsius`]); `None` for 0 |
//! | second temperature (CAP or BEC) | [`DataFrame::temp2_adc`] | the same; `None` for 0 |
//!
//! It does **not** carry phase current or a status word. An info frame ([`InfoFrame`]) carries
//! the full scale, the voltage and current constants and two bytes of unknown meaning (kept
//! raw); no product name or version. RPM is eRPM / pole pairs (/ gear ratio), as for HW-FOC.
//!
//! # Recognition, and its limits
//!
//! With no checksum, frames are recognised by plausibility (throttle and PWM at most full scale,
//! ADC fields below 4096, an info frame's fixed bytes and non-zero divisors), by chaining (the
//! next `9B` exactly where the previous frame ended) and by the counter going up by one. The
//! decoder locks onto a stream after three chained data frames, or a data frame and an info
//! frame chained either way round; it then accepts each data frame that continues the chain
//! (also across up to [`MAX_CHAINED_GAP`] data frames cut out whole, counted lost). An info
//! frame is accepted only with a plausible data frame right after it, or, chained, another info
//! frame (so the last info frame of a stream that ends with it is dropped). Anything else
//! (garbage, a cut or corrupted frame, a counter that jumps further because frames were lost or
//! the ESC restarted) must start a new chain, whose first counter's step from the last accepted
//! one is counted.
//! An info frame's constants are adopted once two identical copies came in a row. The
//! scanner's state (the chain's end, the counter it expects, the info frames) lives in its
//! [`Stats`], which the streaming layer of [`crate::scan`] hands it with every chunk, and a
//! candidate is decided by at most 59 bytes: [`Decoder`] and [`frames`] give the same frames and
//! statistics however the stream is cut into chunks.
//!
//! What it cannot see:
//!
//! - **A corruption that keeps a frame plausible**: eRPM (any value), the low bits of every
//!   field, and any flip leaving a frame plausible go undetected in a chained frame: about half
//!   of all single-bit flips. A flipped info frame is not adopted unless it comes twice. A flip
//!   that moves the counter forward by at most [`MAX_CHAINED_GAP`] (bit 0 or 1 of its low byte
//!   set) leaves the frame taken with a wrong counter, as if frames had been cut before it; the
//!   next frame (whose counter goes back) starts a new chain.
//! - **A chain break near the end of a stream**: after a break, frames are accepted only once a
//!   new chain forms; the last one or two data frames of a running stream after a break are
//!   dropped.
//! - **Before an info frame is adopted, the full scale is taken as 1000**: on an ESC with
//!   another full scale, running frames above 1000 are rejected until an info frame (sent only
//!   while idle) has been adopted twice.
//! - **V3 and V4** share bytes 0-7 while throttle and PWM are below 256; a V3 stream never
//!   forms a V4 chain (V3 frames are 10 bytes apart and their counters go up by one per 10
//!   bytes), so this decoder finds no frame in a V3 stream. On random bytes, even rich in `9B`
//!   and `B9`, no chain forms: no frame in 2 million random bytes.
//!
//! | module | holds |
//! |---|---|
//! | `layout` | lengths, fixed bytes, [`DEFAULT_FULL_SCALE`], [`ADC_LIMIT`] |
//! | `data` | [`DataFrame`] (parse, encode with or without trailer, plausibility), [`Data`] (conversions) |
//! | `info` | [`InfoFrame`] (parse, encode, constants), [`VoltsPerStep`], [`CurrentScale`] |
//! | `temperature` | [`ntc_celsius`] |
//! | `stats` | [`Stats`] (and the scanner's state) |
//! | `decoder` | the scanner: [`Decoder`], [`frames`], [`Decoded`], [`V4Frame`], [`Scanner`] |
//!
//! ```
//! use hwfoc::v4::{self, DataFrame, V4Frame, InfoFrame, VoltsPerStep};
//!
//! let info = InfoFrame { full_scale: 1000, v1: 8, v2: 91, i1: 0, i2: 1, i3: 0, t1: 0x21, t2: 0x21 };
//! let mut wire = Vec::new();
//! for counter in 0..3 {
//!     wire.extend_from_slice(&info.encode());
//!     let frame = DataFrame { counter, throttle_in_raw: 250, voltage_adc: 1365, ..Default::default() };
//!     wire.extend_from_slice(&frame.encode_with_trailer());
//! }
//! let last = v4::frames(&wire).last().unwrap();
//! let V4Frame::Data(data) = last.frame else { panic!() };
//! assert_eq!(data.info, Some(info));
//! assert_eq!(data.throttle_in_pct(), 25.0);
//! assert_eq!(data.voltage_v(VoltsPerStep::DEFAULT), 12.0);
//! assert_eq!(data.current_a(), None); // I1 = 0: no current sensor
//! ```

pub(crate) mod data;
pub(crate) mod decoder;
pub(crate) mod description;
pub(crate) mod info;
mod layout;
mod stats;

/// Baud rate of the V4 telemetry wire (8N1), as HW-FOC's.
pub const BAUD_RATE: u32 = crate::foc::BAUD_RATE;

pub use crate::chain::MAX_CHAINED_GAP;
pub use crate::ntc::{NTC_BETA, NTC_R25_OVER_REFERENCE, ntc_celsius};
pub use data::{Data, DataFrame};
pub use decoder::{CHAIN_TO_LOCK, Decoded, Decoder, Frames, Scanner, V4Frame, frames};
pub use description::DESCRIPTION;
pub use info::{CurrentScale, InfoFrame, VoltsPerStep, VoltsPerStepError, throttle_linear};
pub use layout::{
    ADC_LIMIT, COUNTER_AT, DATA_FRAME_LEN, DEFAULT_FULL_SCALE, INFO_FRAME_LEN, INFO_MARK,
    SLOW_DATA_FRAME_LEN, TRAILER,
};
pub use stats::Stats;

crate::protocol::found_frame!(Decoded, HwV4);

impl From<V4Frame> for crate::telemetry::AnyFrame {
    #[inline(always)]
    fn from(frame: V4Frame) -> crate::telemetry::AnyFrame {
        match frame {
            V4Frame::Data(d) => crate::telemetry::AnyFrame::Data(crate::telemetry::Data::HwV4(d)),
            V4Frame::Info(i) => crate::telemetry::AnyFrame::Info(crate::telemetry::Info::HwV4(i)),
        }
    }
}

impl crate::protocol::FamilyScanner for Scanner {
    fn handed_on(s: &Stats) -> u64 {
        u64::from(s.frames()) + u64::from(s.info_frames())
    }

    const SILENCE_FRAME_LEN: usize = DATA_FRAME_LEN;
}

impl crate::family::FamilyLink for Scanner {
    fn hand_on(d: &Decoded, emit: &mut crate::family::Emit<'_>) {
        emit(None, d.offset, &crate::telemetry::AnyFrame::from(d.frame));
    }

    fn figures(s: &Stats) -> Option<crate::family::LinkFigures> {
        Some(crate::family::LinkFigures {
            protocol: crate::Protocol::HwV4,
            bytes: crate::scan::Stats::bytes(s),
            bytes_skipped: s.bytes_skipped(),
            frames: s.frames(),
            info_frames: s.info_frames(),
            checksum_failures: 0,
            rejected_candidates: Some(s.rejected()),
            packets: Some(crate::family::PacketCounts::of(s.counter())),
            adopted_info: s.adopted().map(crate::telemetry::Info::HwV4),
        })
    }
}
