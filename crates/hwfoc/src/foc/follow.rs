//! The bulk scanner after line noise: from one candidate to the next of a
//! [candidate map](crate::foc::map), with no branch on the noise between them.
//!
//! Right after a frame the scanner tries the next frame at the very next byte, which is right in
//! a run of back-to-back frames. Where line noise often comes between frames, that guess fails
//! at every run of noise, in a branch the processor cannot predict, and the search after it
//! costs as much again. There the bulk scanner ([`crate::foc::decoder`]'s `scan_all`, which
//! [`frames`](crate::foc::frames)' `fold`, `for_each` and `sum`, and every
//! [`Decoder::feed`](crate::foc::Decoder) of a large chunk run) instead makes the map of the
//! next [`MAP_BLOCK`] positions and, after each frame, goes to the first candidate of the map
//! from there: the next frame, wherever the noise let it start. What it finds and counts is
//! what the byte-by-byte rule gives: a frame is taken whole; any other position is skipped,
//! a candidate (a sync byte and a length byte) counted as a checksum failure.
//!
//! [`Follow`] decides when: after a run of noise, until a block without noise; not in noise
//! full of fake headers, where the scanner's search windows decide many candidates at once.

use crate::foc::frame::{FocFrame, MAX_FRAME_LEN, wire_len_of};
use crate::foc::map::{MAP_BLOCK, MAP_BYTES, MAP_POSITIONS, MAP_READ, candidate_map};
use crate::foc::stats::Stats;

/// Whether the bulk scanner follows candidate maps, kept through its run. It starts after a
/// run of line noise in which the search found no candidate (fake headers are better decided
/// by the search windows, many at once), and follows them until a block without noise, or
/// until it meets more than [`Follow::MAX_REJECTED`] rejected candidates in a block (noise full
/// of fake headers); then it lets 256 frames that the search after noise finds pass before
/// trying again, twice as many each time in a row (at most 4096). It changes how the next
/// frame is looked for, never what is found or counted.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Follow {
    /// Frames found after noise, or other than the first kind, to let pass before following
    /// again.
    wait: u32,
    /// The wait after the next block with too many rejected candidates.
    backoff: u32,
}

impl Follow {
    /// Following at the next run of noise, as at the start of a stream.
    pub(crate) const NEW: Follow = Follow {
        wait: 0,
        backoff: Self::FIRST_BACKOFF,
    };

    /// Rejected candidates in a block after which following stops: one per 256 positions,
    /// which corrupted frames seldom reach (a link losing one frame in ten gives about 14 in a
    /// block of data frames; the bench's noisy stream about 4) but fake headers soon do.
    pub(crate) const MAX_REJECTED: u32 = 16;

    /// Frames to wait after the first block with too many rejected candidates.
    const FIRST_BACKOFF: u32 = 256;

    /// The longest wait.
    const MAX_BACKOFF: u32 = 4096;

    /// Whether to let this frame found by the search after noise pass without following
    /// (counting it as passed).
    #[inline(always)]
    pub(crate) fn waits(&mut self) -> bool {
        let waits = self.wait > 0;
        self.wait = self.wait.saturating_sub(1);
        waits
    }

    /// Whether to go on following after a block that skipped `skipped` bytes and rejected
    /// `rejected` candidates.
    #[inline(always)]
    fn goes_on(&mut self, skipped: usize, rejected: u32) -> bool {
        if rejected > Self::MAX_REJECTED {
            self.wait = self.backoff;
            self.backoff = (self.backoff * 2).min(Self::MAX_BACKOFF);
            return false;
        }
        self.backoff = Self::FIRST_BACKOFF;
        skipped != 0
    }
}

/// Follows candidate maps from `*at_pos` (just after a frame found after line noise) while
/// `follow` says so and a map's bytes and a frame's are left, giving each frame found to
/// `on_frame` with its place in `data`, and counting in `at_stats` what it passes over.
/// `*at_pos` is left where it stopped, at a place the caller's loop takes on from (nothing
/// there counted yet).
///
/// Out of line, with local copies of the position and the statistics: the caller's loop over
/// back-to-back frames keeps its own registers, and this one keeps its counts in registers
/// (`on_frame` cannot see the copies).
#[inline(never)]
pub(crate) fn follow_maps(
    data: &[u8],
    at_pos: &mut usize,
    at_stats: &mut Stats,
    follow: &mut Follow,
    on_frame: &mut impl FnMut(usize, FocFrame),
) {
    let (mut position, mut counts) = (*at_pos, *at_stats);
    let (pos, stats) = (&mut position, &mut counts);
    let mut map = [0; MAP_BYTES];
    // A map's positions, and a whole frame after each (so a candidate the map holds is decided
    // here: rejected once it is no frame).
    while let Some(w) = data
        .get(*pos..*pos + MAP_POSITIONS + MAX_FRAME_LEN)
        .and_then(|b| b.first_chunk::<MAP_READ>())
    {
        candidate_map(w, &mut map);
        let start = *pos;
        let mut skipped = 0;
        let mut rejected = 0;
        while *pos < start + MAP_BLOCK {
            // The map from here: 64 positions, of which the first 57 at least are in it.
            let rel = *pos - start;
            let at = (rel / 8) % (MAP_BLOCK / 8);
            let word = map[at..at + 8].try_into().unwrap_or([0; 8]);
            let bits = u64::from_le_bytes(word) >> (rel % 8);
            if bits == 0 {
                skipped += 57;
                *pos += 57;
                continue;
            }
            let k = bits.trailing_zeros() as usize;
            skipped += k;
            *pos += k;
            if let Some((at, frame)) = FocFrame::take_first(data, pos, stats) {
                on_frame(at, frame);
                continue;
            }
            if let Some((at, frame)) = FocFrame::take(data, pos, stats) {
                on_frame(at, frame);
                continue;
            }
            // A sync byte whose second byte passed the map's test: a candidate if that is a
            // length byte.
            rejected += u32::from(wire_len_of(data[*pos + 1]).is_some());
            skipped += 1;
            *pos += 1;
            if rejected > Follow::MAX_REJECTED {
                break;
            }
        }
        stats.skip(skipped);
        stats.checksum_failures_n(rejected);
        #[cfg(test)]
        tests::seen(skipped, rejected);
        if !follow.goes_on(skipped, rejected) {
            break;
        }
    }
    *at_pos = position;
    *at_stats = counts;
}

#[cfg(test)]
mod tests {
    extern crate std;
    use core::cell::Cell;
    use std::vec::Vec;

    use crate::foc::{self, frames};
    use crate::scan::tests::{foc_frame, noisy};
    use crate::wire::SYNC;

    std::thread_local! {
        /// Blocks followed on this thread: with noise, without (following stops), and with too
        /// many rejected candidates (following stops and waits).
        static BLOCKS: Cell<[u32; 3]> = const { Cell::new([0; 3]) };
    }

    /// Counts a block followed (see [`BLOCKS`]).
    pub(super) fn seen(skipped: usize, rejected: u32) {
        let which = if rejected > super::Follow::MAX_REJECTED {
            2
        } else {
            usize::from(skipped == 0)
        };
        BLOCKS.with(|b| {
            let mut n = b.get();
            n[which] += 1;
            b.set(n);
        });
    }

    /// Line noise, then a long run of frames, then noise full of fake headers, then line noise
    /// again: the bulk scanner follows maps through the first, stops in the run of frames,
    /// stops and waits in the fake headers, and follows again; its frames and statistics are
    /// those of the scan a frame at a time (`next`, which follows no map), and of the streaming
    /// decoder fed the bytes in pieces of any size.
    #[test]
    fn following_maps_finds_and_counts_what_the_byte_by_byte_scan_does() {
        let frame = foc_frame;
        // Line noise: random bytes and sync bytes between frames, one frame in 25 cut or
        // flipped; fake headers: as many again of whole headers, one frame in 6.
        let mut wire = noisy(0x0123_4567, (1500, 50), &[], frame);
        (0..600).for_each(|i| wire.extend_from_slice(&frame(2000 + i)));
        wire.extend(noisy(
            0x89AB_CDEF,
            (1500, 12),
            &[SYNC, 0x16, 0x01, 0x02],
            frame,
        ));
        wire.extend(noisy(0x0F1E_2D3C, (1500, 50), &[], frame));
        // A run of noise longer than a read of the map (57 positions).
        wire.extend((0..200u32).map(|i| (i * 37 % 251) as u8 | 1));
        wire.extend(noisy(0x4B5A_6978, (600, 50), &[], frame));

        BLOCKS.with(|b| b.set([0; 3]));
        let mut folded = Vec::new();
        let mut decoder = foc::Decoder::new();
        decoder.decode_all(&wire, |d| folded.push(d));
        let [noisy_blocks, quiet_blocks, fake_blocks] = BLOCKS.with(Cell::get);
        assert!(
            noisy_blocks >= 4,
            "{noisy_blocks} blocks with noise followed"
        );
        assert!(quiet_blocks >= 1, "{quiet_blocks} blocks without noise");
        assert!(fake_blocks >= 1, "{fake_blocks} blocks of fake headers");

        let mut it = frames(&wire);
        let one_at_a_time: Vec<_> = it.by_ref().collect();
        assert!(one_at_a_time.len() > 4000, "{} frames", one_at_a_time.len());
        assert_eq!(folded, one_at_a_time);
        assert_eq!(decoder.stats(), it.stats());
        assert!(it.stats().checksum_failures() > 100);

        for piece in [1000, 9000, 20_000] {
            let mut pieces = foc::Decoder::new();
            let mut fed = Vec::new();
            for chunk in wire.chunks(piece) {
                pieces.feed(chunk, |d| fed.push(d));
            }
            pieces.flush(|d| fed.push(d));
            assert_eq!(fed, one_at_a_time, "pieces of {piece}");
            assert_eq!(pieces.stats(), it.stats(), "pieces of {piece}");
        }
    }
}
