//! One module per frame kind, each a type implementing [`FrameKind`] with one
//! arm in [`FocFrame`](crate::foc::FocFrame).
//!
//! | module | type | header | length | check bytes |
//! |---|---|---|---|---|
//! | [`data`] | [`DataFrame`](data::DataFrame) | `9B 16 01 02` | 24 | 16-bit sum, low byte first |
//! | [`info`] | [`InfoFrame`](info::InfoFrame) | `9B 4C 01 01` | 77 | low byte of the 16-bit sum |
//!
//! A kind's module holds everything particular to it (layout, constants, field accessors,
//! conversions) and nothing the other kinds share: that is in [`crate::wire`]. How to add a kind
//! is described in [`crate::foc`].

pub mod data;
pub mod info;

use crate::foc::FrameError;
use crate::wire::{Checksum, SYNC};

/// A kind of frame: its header, length, check bytes and payload layout.
///
/// Each kind lives in its own module under [`crate::foc::kinds`] and has one arm in
/// [`crate::foc::FocFrame`]; the scanner and [`crate::foc::parse`] reach it only through this trait,
/// with every constant known at compile time (no `dyn`, no function pointers: after inlining, the
/// code is what a hand-written check of that one kind would be). See [`crate::foc`] for how to add
/// a kind.
///
/// The trait is sealed: a kind is only useful with its arm in [`crate::foc::FocFrame`], so it is
/// implemented inside this crate. Its constants and provided methods are for everyone.
///
/// ```
/// use hwfoc::foc::{DataFrame, FrameKind, InfoFrame};
///
/// assert_eq!(DataFrame::HEADER, [0x9B, 0x16, 0x01, 0x02]);
/// assert_eq!((DataFrame::LEN, InfoFrame::LEN), (24, 77));
/// let bytes = InfoFrame::new("XR_FOC_ESC", "", "", "")?.encode();
/// assert_eq!(<InfoFrame as FrameKind>::parse(&bytes)?.product(), "XR_FOC_ESC");
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
pub trait FrameKind: Sized + Copy + sealed::Sealed {
    /// Byte 1: the number of bytes before the check bytes (`LEN - CHECKSUM.width()`), from
    /// which the scanner knows a candidate's length. Kinds are told apart by their whole
    /// [`FrameKind::HEADER`]: two may share a length byte if they share a length.
    const LENGTH_BYTE: u8;
    /// Byte 2: the protocol version.
    const VERSION: u8;
    /// Byte 3: the command.
    const COMMAND: u8;
    /// Length of the whole frame on the wire, check bytes included.
    const LEN: usize;
    /// The check bytes that end the frame.
    const CHECKSUM: Checksum;
    /// The first four bytes of every frame of this kind.
    const HEADER: [u8; 4] = [SYNC, Self::LENGTH_BYTE, Self::VERSION, Self::COMMAND];
    /// [`FrameKind::HEADER`] as a little-endian `u32`, to compare four bytes at once.
    const HEADER_WORD: u32 = u32::from_le_bytes(Self::HEADER);

    /// Checks and decodes a candidate whose sync and length bytes already matched, from its
    /// first [`FrameKind::LEN`] bytes: check bytes first, then version and command, then the
    /// kind's own rules (a device-information frame's text must be ASCII).
    #[inline(always)]
    fn verify(candidate: &[u8]) -> Result<Self, FrameError> {
        let Some(frame) = candidate.get(..Self::LEN) else {
            return Err(FrameError::Truncated {
                needed: Self::LEN,
                got: candidate.len(),
            });
        };
        Self::CHECKSUM.verify(frame)?;
        if frame[2] != Self::VERSION || frame[3] != Self::COMMAND {
            return Err(FrameError::UnknownCommand {
                version: frame[2],
                command: frame[3],
            });
        }
        Self::read(frame)
    }

    /// The scanner's verdict on a candidate that starts with the sync byte and a known length
    /// byte: `Some` exactly when [`FrameKind::verify`] would succeed (and `None` when fewer than
    /// [`FrameKind::LEN`] bytes are given).
    ///
    /// It runs at every candidate, for every kind until one accepts, so it is tuned for what it
    /// mostly sees: the default compares the header first and verifies only a match; a kind may
    /// order its checks otherwise (the data frame decides with one branch).
    #[inline(always)]
    fn accept(candidate: &[u8]) -> Option<Self> {
        let frame = candidate.get(..Self::LEN)?;
        let header = u32::from_le_bytes([frame[0], frame[1], frame[2], frame[3]]);
        if header != Self::HEADER_WORD {
            return None;
        }
        Self::verify(frame).ok()
    }

    /// Decodes a frame of this kind from the first [`FrameKind::LEN`] bytes of `bytes`, checking
    /// everything: length, sync byte, length byte, then as [`FrameKind::verify`]. Bytes after the
    /// frame are ignored.
    fn parse(bytes: &[u8]) -> Result<Self, FrameError> {
        let Some(frame) = bytes.get(..Self::LEN) else {
            return Err(FrameError::Truncated {
                needed: Self::LEN,
                got: bytes.len(),
            });
        };
        if frame[0] != SYNC {
            return Err(FrameError::NoSync { found: frame[0] });
        }
        if frame[1] != Self::LENGTH_BYTE {
            return Err(FrameError::UnknownLength { found: frame[1] });
        }
        Self::verify(frame)
    }

    /// Encodes the frame into the start of `out` (header, payload, check bytes) and returns the
    /// number of bytes written, [`FrameKind::LEN`], or `None` when `out` is shorter.
    fn encode_into(&self, out: &mut [u8]) -> Option<usize> {
        let frame = out.get_mut(..Self::LEN)?;
        frame[..4].copy_from_slice(&Self::HEADER);
        self.write(&mut frame[4..Self::LEN - Self::CHECKSUM.width()]);
        Self::CHECKSUM.seal(frame);
        Some(Self::LEN)
    }
}

/// The part of [`FrameKind`] only this crate uses (and the seal: no kind outside the crate).
pub(crate) mod sealed {
    use crate::foc::FrameError;
    use crate::foc::stats::Stats;

    /// Crate-internal methods of a frame kind: reading and writing its payload, counting it.
    pub trait Sealed: Sized {
        /// Reads the fields of `frame`, exactly `LEN` bytes whose header and check bytes are
        /// already verified, and applies the kind's own rules (a device-information frame's
        /// text must be ASCII).
        fn read(frame: &[u8]) -> Result<Self, FrameError>;

        /// Writes the payload into `payload`, exactly bytes `4..LEN - CHECKSUM.width()` of a
        /// frame (it may panic given another length).
        fn write(&self, payload: &mut [u8]);

        /// Counts an accepted frame of this kind in the link statistics.
        fn count(&self, stats: &mut Stats);
    }
}
