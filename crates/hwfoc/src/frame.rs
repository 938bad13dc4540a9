//! The list of frame kinds, and what is built from it: [`Frame`] (one arm per kind),
//! [`MAX_FRAME_LEN`], [`parse`] and the dispatch the scanner of [`crate::decoder`] uses.
//!
//! The layers of the codec, each knowing only those below it:
//!
//! | module | holds |
//! |---|---|
//! | [`crate::wire`] | line settings ([`BAUD_RATE`](crate::wire::BAUD_RATE), [`byte_ns`](crate::wire::byte_ns)), sync byte, [`Checksum`](crate::wire::Checksum) kinds, [`FrameError`], the [`FrameKind`] trait |
//! | [`crate::kinds`] | one module per kind: [`DataFrame`], [`InfoFrame`] |
//! | `frame` (here) | the list of kinds: [`Frame`], [`MAX_FRAME_LEN`], [`parse`], [`Parsed`] |
//! | [`crate::decoder`] | the scanner: [`Decoder`](crate::Decoder), [`frames`](crate::frames) |
//!
//! Beside them, [`crate::datalink`] holds the DataLink V2 hub's frame, scanner and statistics,
//! built on [`crate::wire`], [`DataFrame`]'s payload and the scanner's sync-pair search.
//!
//! The scanner never names a kind: right after a frame it asks the first kind of the list
//! whether another starts there; otherwise it finds a sync byte followed by a known length byte,
//! asks each kind in turn whether a frame starts there ([`FrameKind::accept`]), and otherwise learns
//! from the length byte how many bytes the candidate needs before it can be rejected. Every
//! constant of every kind is known at compile time, so this dispatch compiles to the same
//! compares a hand-written scanner for these two kinds would make.
//!
//! # Adding a frame kind
//!
//! A new HW-FOC frame kind (another command, or the older XRotor-Pro `9B 16 03` frame of
//! `docs/OLDER-PROTOCOLS.md` that should be recognised and reported as unsupported) is:
//!
//! 1. **One new file**, `src/kinds/<name>.rs` (plus its `pub mod` line in `src/kinds/mod.rs`):
//!    the type, with `impl FrameKind` (length byte, version, command, length,
//!    [`Checksum`](crate::wire::Checksum) kind, and optionally a faster [`FrameKind::accept`]) and
//!    `impl Sealed` (read the payload of a verified frame, write it, count the frame in
//!    [`LinkStats`]).
//! 2. **One arm** in the `frame_kinds!` list below: `Name(Type)` with its doc comment. That arm
//!    makes the [`Frame`] variant, a `From` conversion, its place in [`Frame::wire_len`],
//!    [`Frame::encode_into`], [`parse`], the scanner's dispatch, the known length bytes of
//!    [`FrameError::UnknownLength`] and [`MAX_FRAME_LEN`]. Arms are tried in order, and only the
//!    first is tried right after a frame: keep the most frequent kind first.
//! 3. If the kind should be counted apart, a counter in [`LinkStats`]
//!    (`stats.rs`) for its `count` to call.
//!
//! Compile-time checks below reject a kind whose length byte is not its length minus its check
//! bytes, two kinds with the same header, and two kinds sharing a length byte but not a length
//! (two kinds *may* share a length byte: the `9B 16 03` frame would share the data frame's).
//! A kind longer than 77 bytes raises [`MAX_FRAME_LEN`], and with it the [`Decoder`](crate::Decoder)'s
//! state (`MAX_FRAME_LEN - 1` bytes of buffer) and the size of [`Frame`]: the decoder's
//! `state_is_under_128_bytes` test and the size probe's `DECODER_STATE_BYTES` check catch it.
//!
//! # Another protocol
//!
//! - **DataLink V2** (the hub's aggregate frame, `docs/PROTOCOL-NOTES.md`): `9B 9E 01 02` (or a
//!   length byte 0xA0, which some drivers write), 160 bytes, a frame counter and 8 ESC records,
//!   CRC-16/XMODEM of bytes 0..=157, low byte first, on a 115200-baud wire. It is **not** a kind
//!   of this list but a module family of its own, [`crate::datalink`], with its own scanner
//!   ([`DatalinkDecoder`](crate::DatalinkDecoder), [`datalink::frames`](crate::datalink::frames))
//!   and statistics ([`DatalinkStats`](crate::DatalinkStats)): as a kind it would have made
//!   [`MAX_FRAME_LEN`] 160, every [`Decoder`](crate::Decoder) 200 bytes instead of 120 and
//!   [`Frame`] the size of 8 records, also in firmware that reads one ESC's own wire, where a
//!   hub frame never comes; and its two length bytes for one length break this list's rule that
//!   the length byte is the length minus the check bytes. What it shares is shared, not copied:
//!   the [`Checksum::Crc16Xmodem`](crate::wire::Checksum::Crc16Xmodem) arm, [`SYNC`] and the
//!   version byte, [`byte_ns`](crate::wire::byte_ns), the data frame's payload layout (a record
//!   is a channel byte and those 18 bytes), the scanner's sync-pair search, and the following of
//!   a counter ([`PacketSequence`](crate::PacketSequence)).
//! - **Hobbywing V3/V4** (`docs/OLDER-PROTOCOLS.md`): same sync byte and baud rate, but no length
//!   byte and no checksum. Frames are recognised by fixed bytes, by chaining (the next header
//!   exactly where the previous frame ended) and by the packet counter, which needs state across
//!   frames. That is a different scanner, not a kind: a module of its own beside
//!   [`crate::decoder`], using [`SYNC`], [`BAUD_RATE`](crate::wire::BAUD_RATE)
//!   and [`byte_ns`](crate::wire::byte_ns) from [`crate::wire`] and its own frame types (only
//!   their conversions, not their layout, resemble [`DataFrame`]'s). Auto-detection would sit
//!   above both scanners.

use core::fmt;

use crate::kinds::data::DataFrame;
use crate::kinds::info::InfoFrame;
use crate::stats::LinkStats;
use crate::wire::sealed::Sealed;
use crate::wire::{FrameError, FrameKind, SYNC};

/// Declares the frame kinds: one arm per kind, `Variant(Type)`, in the order the scanner tries
/// them. Everything that lists the kinds is generated from this one list.
macro_rules! frame_kinds {
    (
        $(#[$first_attr:meta])* $first_arm:ident($first_kind:ty)
        $(, $(#[$attr:meta])* $arm:ident($kind:ty))* $(,)?
    ) => {
        frame_kinds!(@expand $first_arm($first_kind);
            [$(#[$first_attr])* $first_arm($first_kind)] $([$(#[$attr])* $arm($kind)])*);
    };
    (@expand $first_arm:ident($first_kind:ty); $([$(#[$attr:meta])* $arm:ident($kind:ty)])+) => {
        /// A frame of any kind found on the telemetry wire: one arm per [`FrameKind`].
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Frame {
            $( $(#[$attr])* $arm($kind), )+
        }

        $(
            impl From<$kind> for Frame {
                #[inline]
                fn from(frame: $kind) -> Frame {
                    Frame::$arm(frame)
                }
            }
        )+

        /// What the compile-time checks and [`MAX_FRAME_LEN`] need of every kind, in list order.
        const KINDS: &[Kind] = &[$(Kind::of::<$kind>()),+];

        /// The length byte of every kind, in list order.
        const LENGTH_BYTES: [u8; KINDS.len()] = [$(<$kind as FrameKind>::LENGTH_BYTE),+];

        /// `f` of every kind's length byte, ORed: one expression with constants, never a loop
        /// (which LLVM does not always unroll).
        #[inline(always)]
        pub(crate) fn or_length_bytes(f: impl Fn(u8) -> u64) -> u64 {
            0 $( | f(<$kind as FrameKind>::LENGTH_BYTE) )+
        }

        /// The wire length of a frame whose length byte is `length_byte`, or `None` when no kind
        /// has that length byte.
        #[inline(always)]
        pub(crate) fn wire_len_of(length_byte: u8) -> Option<usize> {
            $(
                if length_byte == <$kind as FrameKind>::LENGTH_BYTE {
                    return Some(<$kind as FrameKind>::LEN);
                }
            )+
            None
        }

        /// How many bytes a candidate needs before it can be decided: 2 while it is only its
        /// sync byte, else the wire length of its length byte's kind.
        ///
        /// The scanner's candidates start with a sync byte followed, if there is a second byte,
        /// by a known length byte (`find_header` stops at no other), so there is no "unknown"
        /// answer: a byte no kind has gives [`MAX_FRAME_LEN`], the length after which any
        /// candidate is decided.
        #[inline(always)]
        pub(crate) fn candidate_len(candidate: &[u8]) -> usize {
            let Some(&length_byte) = candidate.get(1) else {
                return 2;
            };
            $(
                if length_byte == <$kind as FrameKind>::LENGTH_BYTE {
                    return <$kind as FrameKind>::LEN;
                }
            )+
            MAX_FRAME_LEN
        }

        impl Frame {
            /// The frame's length on the wire.
            pub fn wire_len(&self) -> usize {
                match self {
                    $( Frame::$arm(_) => <$kind as FrameKind>::LEN, )+
                }
            }

            /// Encodes the frame into the start of `out` and returns the number of bytes written,
            /// or `None` when `out` is shorter than [`Frame::wire_len`].
            pub fn encode_into(&self, out: &mut [u8]) -> Option<usize> {
                match self {
                    $( Frame::$arm(frame) => frame.encode_into(out), )+
                }
            }

            /// The frame at `data[*pos..]`, if it is of the first (most frequent) kind: the
            /// scanner's first guess, right after a frame. A frame is counted in `stats` and
            /// returned with its offset, `*pos` moved past it.
            #[inline(always)]
            pub(crate) fn take_first(
                data: &[u8],
                pos: &mut usize,
                stats: &mut LinkStats,
            ) -> Option<(usize, Frame)> {
                let at = *pos;
                let frame = <$first_kind as FrameKind>::accept(&data[at..])?;
                frame.count(stats);
                *pos = at + <$first_kind as FrameKind>::LEN;
                Some((at, Frame::$first_arm(frame)))
            }

            /// The frame at `data[*pos..]` (a sync byte and a known length byte), if a kind
            /// accepts it: counted and returned as by [`Frame::take_first`].
            #[inline(always)]
            pub(crate) fn take(
                data: &[u8],
                pos: &mut usize,
                stats: &mut LinkStats,
            ) -> Option<(usize, Frame)> {
                let at = *pos;
                $(
                    if let Some(frame) = <$kind as FrameKind>::accept(&data[at..]) {
                        frame.count(stats);
                        *pos = at + <$kind as FrameKind>::LEN;
                        return Some((at, Frame::$arm(frame)));
                    }
                )+
                None
            }

            /// Checks and decodes `candidate`, at least as long as the kinds with its length
            /// byte `length_byte`: as the kind whose header it carries, else as the first kind
            /// with that length byte (whose error then says what is wrong).
            fn verify(candidate: &[u8], length_byte: u8) -> Result<Frame, FrameError> {
                let header = candidate.first_chunk::<4>();
                $(
                    if header == Some(&<$kind as FrameKind>::HEADER) {
                        return <$kind as FrameKind>::verify(candidate).map(Frame::$arm);
                    }
                )+
                $(
                    if length_byte == <$kind as FrameKind>::LENGTH_BYTE {
                        return <$kind as FrameKind>::verify(candidate).map(Frame::$arm);
                    }
                )+
                Err(FrameError::UnknownLength { found: length_byte })
            }
        }
    };
}

frame_kinds! {
    /// A real-time data frame (command 0x02, 24 bytes).
    Data(DataFrame),
    /// A device-information frame (command 0x01, 77 bytes).
    Info(InfoFrame),
}

/// Length of the longest frame on the wire (the device-information frame).
pub const MAX_FRAME_LEN: usize = {
    let mut max = 0;
    let mut i = 0;
    while i < KINDS.len() {
        if KINDS[i].len > max {
            max = KINDS[i].len;
        }
        i += 1;
    }
    max
};

/// The constants of one kind, for the compile-time checks.
struct Kind {
    header: [u8; 4],
    len: usize,
    check_bytes: usize,
}

impl Kind {
    const fn of<K: FrameKind>() -> Kind {
        Kind {
            header: K::HEADER,
            len: K::LEN,
            check_bytes: K::CHECKSUM.width(),
        }
    }
}

// Every kind follows the HW-FOC outline, and the length byte decides a candidate's length.
const _: () = {
    let mut i = 0;
    while i < KINDS.len() {
        let k = &KINDS[i];
        assert!(k.header[0] == SYNC);
        assert!(
            k.len > 4 + k.check_bytes,
            "a frame holds a header, payload and check bytes"
        );
        assert!(
            k.header[1] as usize == k.len - k.check_bytes,
            "the length byte counts the bytes before the check bytes"
        );
        let mut j = i + 1;
        while j < KINDS.len() {
            let o = &KINDS[j];
            assert!(
                !(o.header[0] == k.header[0]
                    && o.header[1] == k.header[1]
                    && o.header[2] == k.header[2]
                    && o.header[3] == k.header[3]),
                "two kinds with the same header"
            );
            assert!(
                o.header[1] != k.header[1] || o.len == k.len,
                "kinds sharing a length byte must share a length"
            );
            j += 1;
        }
        i += 1;
    }
};

/// Writes the known length bytes, each once, as "0x16 or 0x4C" (for [`FrameError`]'s message).
fn write_length_bytes(f: &mut fmt::Formatter<'_>) -> fmt::Result {
    let distinct = |i: usize| !LENGTH_BYTES[..i].contains(&LENGTH_BYTES[i]);
    let count = (0..LENGTH_BYTES.len()).filter(|&i| distinct(i)).count();
    let mut written = 0;
    for (i, b) in LENGTH_BYTES.iter().enumerate() {
        if !distinct(i) {
            continue;
        }
        if written > 0 {
            f.write_str(if written + 1 == count { " or " } else { ", " })?;
        }
        write!(f, "0x{b:02X}")?;
        written += 1;
    }
    Ok(())
}

/// The outcome of [`parse`]: a whole frame, or the start of one that needs more bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parsed {
    /// A verified frame and the number of bytes it occupies at the start of the input.
    Complete(Frame, usize),
    /// The input is a valid beginning of a frame; at least this many bytes in total are needed.
    Partial(usize),
}

/// Parses one frame (data or device-information) at the very start of `bytes`.
///
/// Like `httparse`, it never allocates and reports a valid but incomplete prefix as
/// [`Parsed::Partial`] instead of an error. It does not search for a frame: use
/// [`crate::Decoder`] or [`crate::frames`] for a stream.
///
/// ```
/// use hwfoc::{parse, Parsed, FrameError};
///
/// assert_eq!(parse(&[0x9B, 0x16, 0x01]), Ok(Parsed::Partial(24)));
/// assert_eq!(parse(&[0x9B, 0x42]), Err(FrameError::UnknownLength { found: 0x42 }));
/// ```
pub fn parse(bytes: &[u8]) -> Result<Parsed, FrameError> {
    let Some(&first) = bytes.first() else {
        return Ok(Parsed::Partial(1));
    };
    if first != SYNC {
        return Err(FrameError::NoSync { found: first });
    }
    let Some(&length_byte) = bytes.get(1) else {
        return Ok(Parsed::Partial(2));
    };
    let Some(len) = wire_len_of(length_byte) else {
        return Err(FrameError::UnknownLength { found: length_byte });
    };
    if bytes.len() < len {
        return Ok(Parsed::Partial(len));
    }
    Ok(Parsed::Complete(Frame::verify(bytes, length_byte)?, len))
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            FrameError::NoSync { found } => {
                write!(f, "frame starts with 0x{found:02X}, not the sync byte 0x9B")
            }
            FrameError::UnknownLength { found } => {
                write!(f, "unknown length byte 0x{found:02X} (expected ")?;
                write_length_bytes(f)?;
                f.write_str(")")
            }
            FrameError::Truncated { needed, got } => {
                write!(f, "truncated frame: {got} of {needed} bytes")
            }
            FrameError::Checksum { expected, found } => write!(
                f,
                "checksum mismatch: bytes sum to 0x{expected:04X}, frame carries 0x{found:04X}"
            ),
            FrameError::UnknownCommand { version, command } => write!(
                f,
                "unknown version 0x{version:02X} / command 0x{command:02X}"
            ),
            FrameError::NotText { offset, found } => write!(
                f,
                "device-information text holds byte 0x{found:02X} at offset {offset}, which is not ASCII"
            ),
        }
    }
}

impl core::error::Error for FrameError {}
