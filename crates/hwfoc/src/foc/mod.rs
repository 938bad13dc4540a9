//! HW-FOC: the telemetry an ESC sends on its own wire (19200 baud, a 24-byte data frame every
//! 50 ms, a 77-byte device-information frame at start), `docs/PROTOCOL-NOTES.md`.
//!
//! Its layers, each knowing only those below it, over what the protocols share in
//! [`crate::wire`] (byte timing, sync byte, [`Checksum`](crate::wire::Checksum) kinds):
//!
//! | module | holds |
//! |---|---|
//! | [`kinds`] | the [`FrameKind`] trait; one module per kind: [`DataFrame`], [`InfoFrame`] |
//! | `frame` | the list of kinds: [`FocFrame`], [`MAX_FRAME_LEN`], [`parse`], [`Parsed`], [`FrameError`] |
//! | `stats` | the link statistics: [`Stats`] |
//! | `decoder` | the scanner: [`Decoder`], [`frames`], [`Decoded`], under the streaming layer of [`crate::scan`] |
//! | `window` | the scanner's search window: 64 positions' candidates and headers at once |
//! | `map` | the candidate map: 4096 positions' candidates at once, with AVX2 or SSE2 (x86_64) |
//! | `follow` | the bulk scanner after line noise: from a frame to the next candidate of the map (x86_64) |
//!
//! Beside this module, [`crate::datalink`] holds the DataLink V2 hub's frame, scanner and
//! statistics, built on [`crate::wire`], [`DataFrame`]'s payload and the scanner's sync-pair
//! search.
//!
//! The scanner never names a kind: right after a frame it asks the first kind of the list
//! whether another starts there; otherwise it finds a sync byte followed by a known length byte,
//! asks each kind in turn whether a frame starts there ([`FrameKind::accept`]), and otherwise
//! learns from the length byte how many bytes the candidate needs before it can be rejected. Every
//! constant of every kind is known at compile time, so this dispatch compiles to the same
//! compares a hand-written scanner for these two kinds would make.
//!
//! # Adding a frame kind
//!
//! A new HW-FOC frame kind (another command, or the older XRotor-Pro `9B 16 03` frame of
//! `docs/OLDER-PROTOCOLS.md` that should be recognised and reported as unsupported) is:
//!
//! 1. **One new file**, `src/foc/kinds/<name>.rs` (plus its `pub mod` line in
//!    `src/foc/kinds/mod.rs`): the type, with `impl FrameKind` (length byte, version, command,
//!    length, [`Checksum`](crate::wire::Checksum) kind, and optionally a faster
//!    [`FrameKind::accept`]) and `impl Sealed` (read the payload of a verified frame, write it,
//!    count the frame in [`Stats`]).
//! 2. **One arm** in the `frame_kinds!` list of `frame.rs`: `Name(Type)` with its doc comment. That
//!    arm makes the [`FocFrame`] variant, a `From` conversion, its place in [`FocFrame::wire_len`],
//!    [`FocFrame::encode_into`], [`parse`], the scanner's dispatch, the known length bytes of
//!    [`FrameError::UnknownLength`] and [`MAX_FRAME_LEN`]. Arms are tried in order, and only the
//!    first is tried right after a frame: keep the most frequent kind first.
//! 3. If the kind should be counted apart, a counter in [`Stats`]
//!    (`stats.rs`) for its `count` to call.
//!
//! Compile-time checks in `frame.rs` reject a kind whose length byte is not its length minus its
//! check bytes, two kinds with the same header, and two kinds sharing a length byte but not a
//! length (two kinds *may* share a length byte: the `9B 16 03` frame would share the data frame's).
//! A kind longer than 77 bytes raises [`MAX_FRAME_LEN`], and with it the [`Decoder`]'s
//! state (`MAX_FRAME_LEN - 1` bytes of buffer) and the size of [`FocFrame`]: the decoder's
//! `state_is_under_128_bytes` test and the size probe's `DECODER_STATE_BYTES` check catch it.
//!
//! # Another protocol
//!
//! - **DataLink V2** (the hub's aggregate frame, `docs/PROTOCOL-NOTES.md`): `9B 9E 01 02` (or a
//!   length byte 0xA0, which some drivers write), 160 bytes, a frame counter and 8 ESC records,
//!   CRC-16/XMODEM of bytes 0..=157, low byte first, on a 115200-baud wire. It is **not** a kind
//!   of this list but a module family of its own, [`crate::datalink`], with its own scanner
//!   ([`datalink::Decoder`](crate::datalink::Decoder),
//!   [`datalink::frames`](crate::datalink::frames)) and statistics
//!   ([`datalink::Stats`](crate::datalink::Stats)): as a kind it would have made [`MAX_FRAME_LEN`]
//!   160, every [`Decoder`] 200 bytes instead of 120 and [`FocFrame`] the size of 8 records, also in
//!   firmware that reads one ESC's own wire, where a hub frame never comes; and its two length
//!   bytes for one length break this list's rule that the length byte is the length minus the check
//!   bytes. What it shares is shared, not copied: the
//!   [`Checksum::Crc16Xmodem`](crate::wire::Checksum::Crc16Xmodem) arm, [`SYNC`](crate::wire::SYNC)
//!   and the version byte, [`byte_ns`](crate::wire::byte_ns), the data frame's payload layout (a
//!   record is a channel byte and those 18 bytes), the scanner's sync-pair search, and the
//!   following of a counter ([`PacketSequence`](crate::counters::PacketSequence)).
//! - **Hobbywing V3/V4** (`docs/OLDER-PROTOCOLS.md`): same sync byte and baud rate, but no length
//!   byte and no checksum. Frames are recognised by fixed bytes, by chaining (the next header
//!   exactly where the previous frame ended) and by the packet counter, which needs state across
//!   frames. That is a different scanner, not a kind: a protocol module of its own beside
//!   this one and [`crate::datalink`], using [`SYNC`](crate::wire::SYNC) and
//!   [`byte_ns`](crate::wire::byte_ns) from [`crate::wire`], the same baud rate and its own frame
//!   types (only their conversions, not their layout, resemble [`DataFrame`]'s). Auto-detection
//!   would sit above both scanners.

pub(crate) mod decoder;
pub(crate) mod description;
#[cfg(target_arch = "x86_64")]
pub(crate) mod follow;
pub(crate) mod frame;
pub mod kinds;
#[cfg(target_arch = "x86_64")]
pub(crate) mod map;
pub(crate) mod stats;
pub(crate) mod window;

/// Baud rate of the HW-FOC telemetry wire (8 data bits, no parity, 1 stop bit: 8N1).
pub const BAUD_RATE: u32 = 19_200;

pub use decoder::{Decoded, Decoder, Frames, Scanner, frames};
pub use description::DESCRIPTION;
pub use frame::{FocFrame, FrameError, MAX_FRAME_LEN, Parsed, parse};
pub use kinds::FrameKind;
pub use kinds::data::{DataFrame, THROTTLE_MAX_RAW};
pub use kinds::info::{InfoFieldError, InfoFrame};
pub use stats::Stats;

impl From<crate::wire::CheckError> for FrameError {
    /// The frame error of check bytes that do not hold.
    #[inline(always)]
    fn from(e: crate::wire::CheckError) -> FrameError {
        match e {
            crate::wire::CheckError::Truncated { needed, got } => {
                FrameError::Truncated { needed, got }
            }
            crate::wire::CheckError::Checksum { expected, found } => {
                FrameError::Checksum { expected, found }
            }
        }
    }
}

impl From<FocFrame> for crate::telemetry::AnyFrame {
    #[inline(always)]
    fn from(frame: FocFrame) -> crate::telemetry::AnyFrame {
        match frame {
            FocFrame::Data(f) => crate::telemetry::AnyFrame::Data(crate::telemetry::Data::HwFoc(f)),
            FocFrame::Info(i) => crate::telemetry::AnyFrame::Info(crate::telemetry::Info::HwFoc(i)),
        }
    }
}

impl crate::telemetry::Data {
    /// The HW-FOC data frame this frame is, for outputs that speak HW-FOC: an HW-FOC frame
    /// itself, or what a DataLink V2 hub record holds (the hub forwards HW-FOC payloads);
    /// `None` for another protocol's frame, whose fields HW-FOC's do not hold as sent.
    #[inline]
    pub fn to_hwfoc(&self) -> Option<DataFrame> {
        match self {
            crate::telemetry::Data::HwFoc(f) | crate::telemetry::Data::DataLink(f) => Some(*f),
            _ => None,
        }
    }
}
