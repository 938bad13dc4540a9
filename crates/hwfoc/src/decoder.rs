//! Finding frames in a byte stream: the streaming [`Decoder`] and the bulk [`frames`] iterator.
//!
//! Both run the same scanner, so they give the same frames and the same statistics for the same
//! bytes, however the stream is cut into chunks.
//!
//! The scanner is content-based and needs no timing: at each `0x9B` it tries a frame. A verified
//! frame is taken whole and scanning resumes after it (so a `0x9B` inside its payload is never
//! mistaken for a frame start). A rejected candidate (wrong length byte, bad checksum) costs one
//! byte: scanning resumes at the byte after the rejected `0x9B`, so a lone `0x9B`, a fake header,
//! a cut frame or a run of garbage never hides a following intact frame.

use crate::frame::{
    DATA_FRAME_LEN, DATA_LENGTH_BYTE, DataFrame, Frame, MAX_FRAME_LEN, SYNC, check_data,
};
use crate::info::{INFO_FRAME_LEN, INFO_LENGTH_BYTE, InfoFrame};
use crate::stats::LinkStats;

/// A frame and where it started in the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Decoded {
    /// Offset of the frame's first byte, counting every byte given to the decoder since it was
    /// created (or, for [`frames`], from the start of the slice).
    pub offset: u64,
    /// The frame.
    pub frame: Frame,
}

/// Offset of the first sync byte in `hay`.
#[inline]
fn find_sync(hay: &[u8]) -> Option<usize> {
    const LO: u64 = 0x0101_0101_0101_0101;
    const HI: u64 = 0x8080_8080_8080_8080;
    const PAT: u64 = LO * SYNC as u64;
    // After a frame the next byte is usually the next frame's sync byte.
    if hay.first() == Some(&SYNC) {
        return Some(0);
    }
    let mut chunks = hay.chunks_exact(16);
    let mut base = 0;
    for chunk in &mut chunks {
        let (a, b) = chunk.split_at(8);
        // A byte equal to SYNC becomes zero after the XOR; the classic "has zero byte" test
        // marks the first such byte exactly (later marks may be false, the first never is).
        let a = u64::from_le_bytes(a.try_into().unwrap_or([0; 8])) ^ PAT;
        let b = u64::from_le_bytes(b.try_into().unwrap_or([0; 8])) ^ PAT;
        let za = a.wrapping_sub(LO) & !a & HI;
        let zb = b.wrapping_sub(LO) & !b & HI;
        if za | zb != 0 {
            return Some(if za != 0 {
                base + (za.trailing_zeros() / 8) as usize
            } else {
                base + 8 + (zb.trailing_zeros() / 8) as usize
            });
        }
        base += 16;
    }
    chunks
        .remainder()
        .iter()
        .position(|&b| b == SYNC)
        .map(|i| base + i)
}

/// Finds the next frame in `data` from `*pos`, counting what it passes over in `stats`.
///
/// Returns the frame and its start offset, with `*pos` just after it. Returns `None` when no
/// further frame can be decided: `*pos` is then `data.len()`, or, unless `at_end`, the start of
/// a candidate frame that needs more bytes (nothing of it has been counted yet).
#[inline]
fn scan_next(
    data: &[u8],
    pos: &mut usize,
    stats: &mut LinkStats,
    at_end: bool,
) -> Option<(usize, Frame)> {
    loop {
        let Some(k) = find_sync(&data[*pos..]) else {
            stats.skip(data.len() - *pos);
            *pos = data.len();
            return None;
        };
        stats.skip(k);
        let i = *pos + k;
        *pos = i;
        let rest = &data[i..];
        let complete = match rest.get(1) {
            Some(&DATA_LENGTH_BYTE) => match rest.first_chunk::<DATA_FRAME_LEN>() {
                Some(f) => {
                    if check_data(f).is_ok() {
                        let d = DataFrame::from_verified(f);
                        stats.data_frame(d.packet);
                        *pos = i + DATA_FRAME_LEN;
                        return Some((i, Frame::Data(d)));
                    }
                    true
                }
                None => false,
            },
            Some(&INFO_LENGTH_BYTE) => match rest.first_chunk::<INFO_FRAME_LEN>() {
                Some(f) => {
                    if let Ok(info) = InfoFrame::parse_exact(f) {
                        stats.info_frame();
                        *pos = i + INFO_FRAME_LEN;
                        return Some((i, Frame::Info(info)));
                    }
                    true
                }
                None => false,
            },
            // Not a frame header: skip the sync byte without calling it a failure.
            Some(_) => {
                stats.skip(1);
                *pos = i + 1;
                continue;
            }
            None => false,
        };
        if complete {
            stats.checksum_failure();
        } else if !at_end {
            return None;
        }
        stats.skip(1);
        *pos = i + 1;
    }
}

/// A streaming decoder: feed it bytes in any chunking, get every frame once.
///
/// Its whole state is a 76-byte buffer for a frame still arriving plus the [`LinkStats`]:
/// 120 bytes (`size_of::<Decoder>()`, checked by a test), no allocation, no timing.
/// Large chunks are scanned in place (the bulk path); only the unfinished tail is copied.
///
/// ```
/// use hwfoc::{Decoder, DataFrame, Frame};
///
/// let frame = DataFrame { packet: 7, voltage_raw: 252, ..Default::default() };
/// let mut wire = vec![0x00, 0x9B, 0x13]; // noise and a lone sync byte
/// wire.extend_from_slice(&frame.encode());
///
/// let mut decoder = Decoder::new();
/// let mut got = Vec::new();
/// for &byte in &wire {
///     // one byte at a time, as from a UART interrupt
///     decoder.push(byte, |d| got.push(d));
/// }
/// decoder.flush(|d| got.push(d));
/// assert_eq!(got.len(), 1);
/// assert_eq!(got[0].offset, 3);
/// assert_eq!(got[0].frame, Frame::Data(frame));
/// assert_eq!(decoder.stats().bytes_skipped(), 3);
/// ```
#[derive(Debug, Clone)]
pub struct Decoder {
    buf: [u8; MAX_FRAME_LEN - 1],
    len: u8,
    stats: LinkStats,
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Decoder {
    /// A decoder with an empty buffer and zero statistics.
    pub const fn new() -> Self {
        Decoder {
            buf: [0; MAX_FRAME_LEN - 1],
            len: 0,
            stats: LinkStats::new(),
        }
    }

    /// Feeds one byte; `on_frame` is called for each frame it completes (at most three, when
    /// a rejected device-information candidate turns out to hold data frames).
    #[inline]
    pub fn push(&mut self, byte: u8, on_frame: impl FnMut(Decoded)) {
        self.feed(&[byte], on_frame);
    }

    /// Feeds a chunk of bytes; `on_frame` is called for each frame found, in stream order.
    pub fn feed(&mut self, data: &[u8], mut on_frame: impl FnMut(Decoded)) {
        if data.is_empty() {
            return;
        }
        let start = self.stats.bytes();
        self.stats.add_bytes(data.len());
        let mut data = data;
        let mut base = start;
        if self.len > 0 {
            let held = usize::from(self.len);
            // Common byte-at-a-time case: the held candidate still cannot be decided with these
            // bytes (a frame's length is known from its second byte), so just keep them.
            let needed = match self.buf[..held] {
                [_] => 2,
                [_, DATA_LENGTH_BYTE, ..] => DATA_FRAME_LEN,
                [_, INFO_LENGTH_BYTE, ..] => INFO_FRAME_LEN,
                _ => 0,
            };
            if held + data.len() < needed {
                self.buf[held..held + data.len()].copy_from_slice(data);
                self.len += data.len() as u8;
                return;
            }
            // Finish the held candidate with the first bytes of `data`. A candidate starting in
            // the held bytes needs at most MAX_FRAME_LEN bytes from its start, so appending that
            // many decides every one of them whenever `data` is long enough.
            let take = data.len().min(MAX_FRAME_LEN);
            let mut tmp = [0u8; 2 * MAX_FRAME_LEN - 1];
            tmp[..held].copy_from_slice(&self.buf[..held]);
            tmp[held..held + take].copy_from_slice(&data[..take]);
            let n = held + take;
            let tmp_base = start - held as u64;
            let mut pos = 0;
            while let Some((at, frame)) = scan_next(&tmp[..n], &mut pos, &mut self.stats, false) {
                on_frame(Decoded {
                    offset: tmp_base + at as u64,
                    frame,
                });
            }
            if pos < held {
                // `data` ran out before the held candidate was decided.
                self.hold(&tmp[pos..n]);
                return;
            }
            data = &data[pos - held..];
            base += (pos - held) as u64;
        }
        let mut pos = 0;
        while let Some((at, frame)) = scan_next(data, &mut pos, &mut self.stats, false) {
            on_frame(Decoded {
                offset: base + at as u64,
                frame,
            });
        }
        self.hold(&data[pos..]);
    }

    /// Keeps an undecided candidate (always shorter than a whole frame) for the next call.
    fn hold(&mut self, tail: &[u8]) {
        self.buf[..tail.len()].copy_from_slice(tail);
        self.len = tail.len() as u8;
    }

    /// Decides the held bytes now, as if the stream ended here: a frame cut short is dropped
    /// (its bytes counted as skipped) and any frame inside it is still found.
    ///
    /// Call it at the end of a stream. A caller that sees the line fall silent for longer than a
    /// few byte times (a "gap": real ESCs send each frame back to back) may call it then too, so
    /// that a cut frame is settled at once rather than when the next bytes arrive. Statistics and
    /// packet tracking carry on across the call.
    pub fn flush(&mut self, mut on_frame: impl FnMut(Decoded)) {
        let held = usize::from(self.len);
        let base = self.stats.bytes() - held as u64;
        let mut pos = 0;
        while let Some((at, frame)) = scan_next(&self.buf[..held], &mut pos, &mut self.stats, true)
        {
            on_frame(Decoded {
                offset: base + at as u64,
                frame,
            });
        }
        self.len = 0;
    }

    /// Feeds a whole stream and flushes it: the bulk path for a buffer in memory.
    pub fn decode_all(&mut self, data: &[u8], mut on_frame: impl FnMut(Decoded)) {
        self.feed(data, &mut on_frame);
        self.flush(on_frame);
    }

    /// Bytes held for a frame that has not finished arriving (always fewer than 77).
    pub fn buffered(&self) -> usize {
        usize::from(self.len)
    }

    /// The link statistics so far.
    pub fn stats(&self) -> &LinkStats {
        &self.stats
    }

    /// Forgets held bytes and statistics, as new.
    pub fn reset(&mut self) {
        *self = Self::new();
    }
}

/// Decodes every frame in a complete buffer, in place: the bulk path.
///
/// The iterator borrows the slice and allocates nothing; a frame cut off by the end of the
/// slice is skipped. It yields exactly what a [`Decoder`] fed the same bytes and then flushed
/// would, with the same statistics.
///
/// ```
/// use hwfoc::{frames, DataFrame, Frame};
///
/// let mut wire = Vec::new();
/// for packet in 0..3u16 {
///     wire.extend_from_slice(&DataFrame { packet, ..Default::default() }.encode());
/// }
/// wire[30] ^= 0x04; // corrupt the second frame
/// let mut it = frames(&wire);
/// let packets: Vec<u16> = it
///     .by_ref()
///     .filter_map(|d| match d.frame { Frame::Data(f) => Some(f.packet), _ => None })
///     .collect();
/// assert_eq!(packets, [0, 2]);
/// assert_eq!(it.stats().checksum_failures(), 1);
/// assert_eq!(it.stats().lost_packets(), 1);
/// ```
pub fn frames(data: &[u8]) -> Frames<'_> {
    let mut stats = LinkStats::new();
    stats.add_bytes(data.len());
    Frames {
        data,
        pos: 0,
        stats,
    }
}

/// Iterator returned by [`frames`].
#[derive(Debug, Clone)]
pub struct Frames<'a> {
    data: &'a [u8],
    pos: usize,
    stats: LinkStats,
}

impl Frames<'_> {
    /// Statistics of the bytes scanned so far (complete once the iterator has returned `None`;
    /// [`LinkStats::bytes`] is the whole slice from the start).
    pub fn stats(&self) -> &LinkStats {
        &self.stats
    }
}

impl Iterator for Frames<'_> {
    type Item = Decoded;

    #[inline]
    fn next(&mut self) -> Option<Decoded> {
        scan_next(self.data, &mut self.pos, &mut self.stats, true).map(|(at, frame)| Decoded {
            offset: at as u64,
            frame,
        })
    }
}

impl core::iter::FusedIterator for Frames<'_> {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn find_sync_matches_a_plain_search() {
        let mut hay = [0u8; 70];
        for (i, b) in hay.iter_mut().enumerate() {
            *b = (i as u8).wrapping_mul(37) | 1;
            if *b == SYNC {
                *b = 0;
            }
        }
        assert_eq!(find_sync(&hay), None);
        for at in 0..hay.len() {
            let mut h = hay;
            h[at] = SYNC;
            // Bytes just above and below the pattern must not confuse the bit trick.
            if at + 1 < h.len() {
                h[at + 1] = SYNC + 1;
            }
            if at > 0 {
                h[at - 1] = SYNC - 1;
            }
            assert_eq!(find_sync(&h), Some(at), "sync at {at}");
            for start in 0..=at {
                assert_eq!(find_sync(&h[start..]), Some(at - start));
            }
        }
    }

    #[test]
    fn state_is_under_128_bytes() {
        assert_eq!(core::mem::size_of::<Decoder>(), 120);
    }

    #[test]
    fn held_candidate_resolves_across_calls() {
        let f = DataFrame {
            packet: 9,
            ..Default::default()
        }
        .encode();
        let mut d = Decoder::new();
        let mut n = 0;
        d.feed(&f[..10], |_| n += 1);
        assert_eq!((n, d.buffered()), (0, 10));
        d.feed(&f[10..], |x| {
            assert_eq!(x.offset, 0);
            n += 1
        });
        assert_eq!((n, d.buffered()), (1, 0));
    }
}
