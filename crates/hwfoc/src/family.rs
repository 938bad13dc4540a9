//! What a detection family's format says of its decoded frames and its statistics, in neutral
//! terms ([`FamilyLink`]): each frame found as [`AnyFrame`]s with their channel, and the link's
//! figures ([`LinkFigures`]). Each family's module implements it beside its scanner, so that
//! the layers above the codec read every format alike ([`crate::detect::Decoded::hand_on`],
//! [`crate::detect::OneFamily`]).
//!
//! ```
//! use hwfoc::detect::{Family, OneFamily};
//! use hwfoc::Protocol;
//!
//! let mut decoder = OneFamily::new(Family::of(Protocol::Hw5).unwrap());
//! decoder.feed(&[0x55; 40], &mut |_| {});
//! decoder.flush(&mut |_| {});
//! let figures = decoder.figures().unwrap();
//! assert_eq!((figures.protocol, figures.bytes, figures.bytes_skipped), (Protocol::Hw5, 40, 40));
//! assert_eq!(figures.packets, None, "HW5 sends no packet counter");
//! ```

use crate::counters::{Sequence, Width};
use crate::protocol::{FamilyScanner, Protocol};
use crate::telemetry::{AnyFrame, Info};

/// A link's figures as its format's statistics count them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinkFigures {
    /// The format of its frames.
    pub protocol: Protocol,
    /// Every byte of the stream.
    pub bytes: u64,
    /// Bytes in no accepted frame of the format.
    pub bytes_skipped: u64,
    /// Data frames.
    pub frames: u32,
    /// Device-information frames.
    pub info_frames: u32,
    /// Frames whose checksum failed, or whose checksum matched but whose values are out of the
    /// format's range (0 for a format without checksum).
    pub checksum_failures: u32,
    /// Of a format without checksum: candidates not taken (implausible, or not confirmed by a
    /// chain); `None` for a checksummed format.
    pub rejected_candidates: Option<u32>,
    /// Of a format whose frames are numbered: the counts of their numbers (`None` where they
    /// are not, as HW5's).
    pub packets: Option<PacketCounts>,
    /// The info frame whose constants were adopted, for a format that adopts one (V4).
    pub adopted_info: Option<Info>,
}

/// The counts of a link's packet numbers (see [`crate::counters`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PacketCounts {
    /// Numbers received.
    pub received: u64,
    /// Numbers skipped.
    pub lost: u32,
    /// Numbers received twice in a row.
    pub duplicates: u32,
    /// Numbers that came right after the next one.
    pub reordered: u32,
    /// Jumps that no loss explains.
    pub restarts: u32,
    /// The last number received.
    pub last: Option<u32>,
}

impl PacketCounts {
    /// The counts of a packet counter's numbers.
    pub fn of<W: Width>(s: &Sequence<W>) -> PacketCounts {
        PacketCounts {
            received: u64::from(s.count()),
            lost: s.lost(),
            duplicates: s.duplicates(),
            reordered: s.reordered(),
            restarts: s.restarts(),
            last: s.last().map(Into::into),
        }
    }
}

/// Where a family hands its frames: `emit(channel, offset, frame)`, each ESC frame with its
/// DataLink channel (`None` on an ESC's own wire) and the stream offset of its first byte.
pub type Emit<'a> = dyn FnMut(Option<u8>, u64, &AnyFrame) + 'a;

/// A detection family's frames and figures in neutral terms.
pub trait FamilyLink: FamilyScanner {
    /// Hands on a frame found as the ESC frames it holds.
    fn hand_on(item: &Self::Item, emit: &mut Emit<'_>);

    /// The link's figures of a decoder with statistics `stats`; `None` for a family whose
    /// figures are per channel ([`crate::mixed`]: an ESC's wire and a hub's channels).
    fn figures(stats: &Self::Stats) -> Option<LinkFigures>;
}
