//! The list of frame kinds, and what is built from it: [`FocFrame`] (one arm per kind),
//! [`MAX_FRAME_LEN`], [`parse`] and the dispatch the scanner of [`crate::foc::decoder`] uses.

use core::fmt;

use crate::foc::kinds::FrameKind;
use crate::foc::kinds::data::DataFrame;
use crate::foc::kinds::info::InfoFrame;
use crate::foc::kinds::sealed::Sealed;
use crate::foc::stats::Stats;
use crate::wire::SYNC;

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
        pub enum FocFrame {
            $( $(#[$attr])* $arm($kind), )+
        }

        $(
            impl From<$kind> for FocFrame {
                #[inline]
                fn from(frame: $kind) -> FocFrame {
                    FocFrame::$arm(frame)
                }
            }
        )+

        /// What the compile-time checks and [`MAX_FRAME_LEN`] need of every kind, in list order.
        const KINDS: &[Kind] = &[$(Kind::of::<$kind>()),+];

        /// The length byte of every kind, in list order.
        pub(crate) const LENGTH_BYTES: [u8; KINDS.len()] =
            [$(<$kind as FrameKind>::LENGTH_BYTE),+];

        /// The header of every kind, in list order: for the search window (on x86_64), and
        /// where the mixed scanner starts a run of ESC frames.
        pub(crate) const HEADERS: [[u8; 4]; KINDS.len()] = [$(<$kind as FrameKind>::HEADER),+];

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

        impl FocFrame {
            /// The frame's length on the wire.
            pub fn wire_len(&self) -> usize {
                match self {
                    $( FocFrame::$arm(_) => <$kind as FrameKind>::LEN, )+
                }
            }

            /// Encodes the frame into the start of `out` and returns the number of bytes written,
            /// or `None` when `out` is shorter than [`FocFrame::wire_len`].
            pub fn encode_into(&self, out: &mut [u8]) -> Option<usize> {
                match self {
                    $( FocFrame::$arm(frame) => frame.encode_into(out), )+
                }
            }

            /// The frame at `data[*pos..]`, if it is of the first (most frequent) kind: the
            /// scanner's first guess, right after a frame. A frame is counted in `stats` and
            /// returned with its offset, `*pos` moved past it.
            #[inline(always)]
            pub(crate) fn take_first(
                data: &[u8],
                pos: &mut usize,
                stats: &mut Stats,
            ) -> Option<(usize, FocFrame)> {
                let at = *pos;
                let frame = <$first_kind as FrameKind>::accept(&data[at..])?;
                frame.count(stats);
                *pos = at + <$first_kind as FrameKind>::LEN;
                Some((at, FocFrame::$first_arm(frame)))
            }

            /// The frame at `data[*pos..]` (a sync byte and a known length byte), if a kind
            /// accepts it: counted and returned as by [`FocFrame::take_first`].
            #[inline(always)]
            pub(crate) fn take(
                data: &[u8],
                pos: &mut usize,
                stats: &mut Stats,
            ) -> Option<(usize, FocFrame)> {
                let at = *pos;
                // One load and one compare per kind: only the kind whose whole header the
                // candidate carries checks it further (kinds' headers differ), so a fake header
                // costs no checksum, and a kind's frame none of another kind's checks.
                let header = data[at..].first_chunk::<4>().map(|h| u32::from_le_bytes(*h));
                $(
                    if header == Some(<$kind as FrameKind>::HEADER_WORD) {
                        let frame = <$kind as FrameKind>::accept(&data[at..])?;
                        frame.count(stats);
                        *pos = at + <$kind as FrameKind>::LEN;
                        return Some((at, FocFrame::$arm(frame)));
                    }
                )+
                None
            }

            /// Whether a frame of some kind starts at `data[at..]` ([`FocFrame::take`] without
            /// counting it or building it).
            #[inline(always)]
            pub(crate) fn verifies(data: &[u8], at: usize) -> bool {
                let header = data[at..].first_chunk::<4>().map(|h| u32::from_le_bytes(*h));
                $(
                    if header == Some(<$kind as FrameKind>::HEADER_WORD) {
                        return <$kind as FrameKind>::accept(&data[at..]).is_some();
                    }
                )+
                false
            }

            /// Checks and decodes `candidate`, at least as long as the kinds with its length
            /// byte `length_byte`: as the kind whose header it carries, else as the first kind
            /// with that length byte (whose error then says what is wrong).
            fn verify(candidate: &[u8], length_byte: u8) -> Result<FocFrame, FrameError> {
                let header = candidate.first_chunk::<4>();
                $(
                    if header == Some(&<$kind as FrameKind>::HEADER) {
                        return <$kind as FrameKind>::verify(candidate).map(FocFrame::$arm);
                    }
                )+
                $(
                    if length_byte == <$kind as FrameKind>::LENGTH_BYTE {
                        return <$kind as FrameKind>::verify(candidate).map(FocFrame::$arm);
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
    Complete(FocFrame, usize),
    /// The input is a valid beginning of a frame; at least this many bytes in total are needed.
    Partial(usize),
}

/// Parses one frame (data or device-information) at the very start of `bytes`.
///
/// Like `httparse`, it never allocates and reports a valid but incomplete prefix as
/// [`Parsed::Partial`] instead of an error. It does not search for a frame: use
/// [`crate::foc::Decoder`] or [`crate::foc::frames`] for a stream.
///
/// ```
/// use hwfoc::foc::{FrameError, Parsed, parse};
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
    Ok(Parsed::Complete(FocFrame::verify(bytes, length_byte)?, len))
}

/// Why bytes are not a valid frame.
///
/// Its [`Display`](core::fmt::Display) is implemented in `frame.rs`, beside the list of kinds,
/// because the message for an unknown length byte names every kind's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FrameError {
    /// The first byte is not the sync byte 0x9B.
    NoSync {
        /// The byte found instead.
        found: u8,
    },
    /// The length byte is not that of any known frame kind (0x16 data, 0x4C device information).
    UnknownLength {
        /// The length byte found.
        found: u8,
    },
    /// Fewer bytes than a whole frame.
    Truncated {
        /// Bytes a whole frame has.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
    /// The checksum does not match the bytes: the frame was corrupted on the wire.
    Checksum {
        /// Checksum computed over the received bytes.
        expected: u16,
        /// Checksum carried by the frame.
        found: u16,
    },
    /// Checksum correct, but a version or command this decoder does not know.
    UnknownCommand {
        /// Version byte (byte 2).
        version: u8,
        /// Command byte (byte 3).
        command: u8,
    },
    /// Checksum correct, but a value outside the range the protocol allows (a throttle over
    /// [`THROTTLE_MAX_RAW`](crate::foc::THROTTLE_MAX_RAW)): a corrupted frame whose weak
    /// checksum still matches.
    OutOfRange {
        /// The field.
        field: &'static str,
        /// Its raw value.
        raw: u16,
        /// The largest the protocol allows.
        max: u16,
    },
    /// A device-information candidate whose text holds a byte that is not ASCII: not a real
    /// frame (typically a cut one with another frame behind it).
    NotText {
        /// Offset of the first such byte in the frame.
        offset: usize,
        /// The byte.
        found: u8,
    },
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
            FrameError::OutOfRange { field, raw, max } => write!(
                f,
                "{field} {raw} out of the protocol's range 0..={max}: a corrupted frame whose checksum still matches"
            ),
            FrameError::NotText { offset, found } => write!(
                f,
                "device-information text holds byte 0x{found:02X} at offset {offset}, which is not ASCII"
            ),
        }
    }
}

impl core::error::Error for FrameError {}
