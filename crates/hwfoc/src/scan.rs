//! The streaming layer every protocol's scanner runs under: [`StreamDecoder`] (bytes in any
//! chunking, each frame out once) and [`Scan`] (the bulk iterator over a slice in memory).
//!
//! A protocol brings a scanner: where a candidate frame may start, how many bytes decide a
//! candidate, and what it is (a frame, or rejected at the cost of one byte). It gets both
//! decoders from here, with the guarantee that they give the same frames and the same
//! statistics for the same bytes, however the stream is cut into chunks: [`Scan`] runs the
//! scanner over the slice; [`StreamDecoder`] runs it over each chunk in place and holds only
//! the undecided tail (a candidate shorter than its longest frame), which it completes with the
//! first bytes of the next chunk.
//!
//! The scanners are [`foc::Scanner`](crate::foc::Scanner) (the ESC wire:
//! [`Decoder`](crate::foc::Decoder), [`frames`](crate::foc::frames)) and
//! [`datalink::Scanner`](crate::datalink::Scanner) (the DataLink hub:
//! [`datalink::Decoder`](crate::datalink::Decoder),
//! [`datalink::frames`](crate::datalink::frames)); [`mixed::Scanner`](crate::mixed::Scanner)
//! reads both at once ([`mixed::Decoder`](crate::mixed::Decoder)), for a stream that may
//! carry either. A new protocol is a module with its scanner
//! and one `impl Scanner`; the trait is sealed (its scanners live in this crate).

use core::fmt;
use core::marker::PhantomData;

/// A protocol's scanner, as the streaming layer drives it (sealed: implemented in this crate).
pub trait Scanner: sealed::Sealed {
    /// A frame found, with its stream offset.
    type Item;
    /// The statistics the scanner keeps of the bytes it is given.
    type Stats: Stats;
    /// Room for a candidate still arriving: `[u8; MAX_LEN - 1]`.
    #[doc(hidden)]
    type Held: AsRef<[u8]> + AsMut<[u8]> + Clone + fmt::Debug;
    /// Room for the held bytes and as many again: `[u8; 2 * MAX_LEN]`.
    #[doc(hidden)]
    type Pair: AsMut<[u8]>;
    /// An empty [`Scanner::Held`].
    #[doc(hidden)]
    const HELD: Self::Held;
    /// An empty [`Scanner::Pair`].
    #[doc(hidden)]
    const PAIR: Self::Pair;
    /// The longest candidate: this many bytes from its start decide any candidate.
    const MAX_LEN: usize;

    /// How many bytes decide the candidate whose first bytes are `held` (at least
    /// `held.len() + 1` while it is undecided).
    #[doc(hidden)]
    fn candidate_len(held: &[u8]) -> usize;

    /// Runs the scanner over `data`, whose first byte is at stream offset `base`, giving every
    /// frame to `on_frame`; returns where it stopped: `data.len()`, or, unless `AT_END`, the
    /// start of a candidate that needs more bytes (none of whose bytes is counted yet).
    #[doc(hidden)]
    fn scan_all<const AT_END: bool>(
        data: &[u8],
        base: u64,
        stats: &mut Self::Stats,
        on_frame: &mut impl FnMut(Self::Item),
    ) -> usize;

    /// The next frame in `data` (a whole stream) from `*pos`, its offset counted from the
    /// start of `data`, with `*pos` just after it; `None` at the end.
    #[doc(hidden)]
    fn scan_next(data: &[u8], pos: &mut usize, stats: &mut Self::Stats) -> Option<Self::Item>;
}

/// What the streaming layer needs of a scanner's statistics (sealed).
pub trait Stats: sealed::Sealed + Clone + fmt::Debug {
    /// No bytes seen.
    #[doc(hidden)]
    const NEW: Self;
    /// Every byte given to the decoder so far.
    fn bytes(&self) -> u64;
    /// Counts `n` more bytes given.
    #[doc(hidden)]
    fn add_bytes(&mut self, n: usize);
    /// The line was silent for a time in which at most `max_frames` frames could have been
    /// sent (see [`StreamDecoder::line_silent`]).
    #[doc(hidden)]
    fn line_silent(&mut self, max_frames: u32);
    /// Counts `n` bytes already given as skipped (in no frame).
    #[doc(hidden)]
    fn skip_bytes(&mut self, n: usize);

    /// These statistics followed by `later`'s ([`StreamDecoder::then`]): true when joined.
    /// False (the default, and nothing changes) for a scanner that keeps state beyond its held
    /// bytes (a chain of frames, a counter it expects), whose later frames depend on the
    /// earlier ones.
    #[doc(hidden)]
    fn then(&mut self, later: &Self, first_packet: Option<u16>) -> bool {
        let _ = (later, first_packet);
        false
    }
}

/// What a protocol's candidate (where its search for a header stopped) comes to, counted in
/// its statistics: each protocol decides its own candidates, for its scanner and for
/// [`mixed::Scanner`](crate::mixed::Scanner).
pub(crate) enum Candidate<T> {
    /// A verified frame, taken whole.
    Frame(T),
    /// Rejected, or cut off by the end of the stream: it costs one byte.
    Rejected,
    /// More bytes are needed.
    Undecided,
}

impl<T> Candidate<T> {
    /// Whether the candidate is decided (a frame, or rejected).
    #[inline(always)]
    pub(crate) fn is_decided(&self) -> bool {
        !matches!(self, Candidate::Undecided)
    }
}

/// Statistics that count the bytes a scanner passes over (as [`next_candidate`] needs).
pub(crate) trait SkipBytes {
    /// Counts `n` bytes skipped.
    fn skip(&mut self, n: usize);
}

/// The search loop of a scanner that stops at candidate starts and decides each (V3, V4,
/// HW5): from `*pos`, `find` gives the offset of the next candidate start in the bytes left
/// (the bytes before it are skipped), and `take` decides the candidate at `*pos`. A frame is
/// returned, with `*pos` where `take` left it (just after the frame); a rejected candidate
/// costs one byte and the search goes on. `None` when no further frame can be decided: `*pos`
/// is then `data.len()`, or the start of a candidate `take` found undecided (nothing of it
/// counted yet).
#[inline(always)]
pub(crate) fn next_candidate<St: SkipBytes, T>(
    data: &[u8],
    pos: &mut usize,
    stats: &mut St,
    find: impl Fn(&[u8]) -> Option<usize>,
    mut take: impl FnMut(&[u8], &mut usize, &mut St) -> Candidate<T>,
) -> Option<T> {
    loop {
        let Some(k) = find(&data[*pos..]) else {
            stats.skip(data.len() - *pos);
            *pos = data.len();
            return None;
        };
        stats.skip(k);
        let i = *pos + k;
        *pos = i;
        match take(data, pos, stats) {
            Candidate::Frame(frame) => return Some(frame),
            Candidate::Undecided => return None,
            Candidate::Rejected => {}
        }
        stats.skip(1);
        *pos = i + 1;
    }
}

/// The streaming layer's traits for a protocol whose scanner is a function
/// `$next(data, pos, base, stats, at_end) -> Option<(usize, Frame)>` (a frame and its start in
/// `data`, whose first byte is at stream offset `base`; see [`next_candidate`]), its items
/// `$item { offset, frame }`: [`Scanner`] for `$scanner`, [`Stats`] for `$stats` (whose
/// `new`, `bytes`, `add_bytes` and `line_silent` it calls), `$max_len` the longest candidate
/// and `$candidate_len(held)` the fewest bytes that may decide one. Used by V3, V4 and HW5.
macro_rules! impl_scanner {
    ($scanner:ty, $stats:ty, $item:ident, $max_len:expr, $candidate_len:expr, $next:path) => {
        impl $crate::scan::sealed::Sealed for $scanner {}
        impl $crate::scan::sealed::Sealed for $stats {}

        impl $crate::scan::Stats for $stats {
            const NEW: Self = <$stats>::new();

            #[inline]
            fn bytes(&self) -> u64 {
                <$stats>::bytes(self)
            }

            #[inline]
            fn add_bytes(&mut self, n: usize) {
                <$stats>::add_bytes(self, n);
            }

            fn line_silent(&mut self, max_frames: u32) {
                <$stats>::line_silent(self, max_frames);
            }

            #[inline]
            fn skip_bytes(&mut self, n: usize) {
                $crate::scan::SkipBytes::skip(self, n);
            }
        }

        impl $crate::scan::Scanner for $scanner {
            type Item = $item;
            type Stats = $stats;
            type Held = [u8; $max_len - 1];
            type Pair = [u8; 2 * $max_len];
            const HELD: Self::Held = [0; $max_len - 1];
            const PAIR: Self::Pair = [0; 2 * $max_len];
            const MAX_LEN: usize = $max_len;

            #[inline(always)]
            fn candidate_len(held: &[u8]) -> usize {
                ($candidate_len)(held)
            }

            #[inline(never)]
            fn scan_all<const AT_END: bool>(
                data: &[u8],
                base: u64,
                stats: &mut $stats,
                on_frame: &mut impl FnMut($item),
            ) -> usize {
                let mut pos = 0;
                while let Some((at, frame)) = $next(data, &mut pos, base, stats, AT_END) {
                    on_frame($item {
                        offset: base + at as u64,
                        frame,
                    });
                }
                pos
            }

            #[inline]
            fn scan_next(data: &[u8], pos: &mut usize, stats: &mut $stats) -> Option<$item> {
                $next(data, pos, 0, stats, true).map(|(at, frame)| $item {
                    offset: at as u64,
                    frame,
                })
            }
        }
    };
}
pub(crate) use impl_scanner;

pub(crate) mod sealed {
    /// Keeps [`Scanner`](super::Scanner) and [`Stats`](super::Stats) to this crate.
    pub trait Sealed {}
}

/// A streaming decoder of the protocol `S`: feed it bytes in any chunking, get every frame
/// once, as [`Scan`] gives them from the whole stream.
///
/// Its state is a buffer for a candidate still arriving (shorter than the longest frame) and
/// the statistics: no allocation, no timing. Large chunks are scanned in place; only an
/// unfinished tail is copied. See [`Decoder`](crate::foc::Decoder) and
/// [`datalink::Decoder`](crate::datalink::Decoder) for each protocol's.
pub struct StreamDecoder<S: Scanner> {
    buf: S::Held,
    len: u8,
    stats: S::Stats,
    scanner: PhantomData<S>,
}

impl<S: Scanner> Clone for StreamDecoder<S> {
    fn clone(&self) -> Self {
        StreamDecoder {
            buf: self.buf.clone(),
            len: self.len,
            stats: self.stats.clone(),
            scanner: PhantomData,
        }
    }
}

impl<S: Scanner> fmt::Debug for StreamDecoder<S> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("StreamDecoder")
            .field("held", &&self.buf.as_ref()[..usize::from(self.len)])
            .field("stats", &self.stats)
            .finish()
    }
}

impl<S: Scanner> Default for StreamDecoder<S> {
    fn default() -> Self {
        Self::new()
    }
}

impl<S: Scanner> StreamDecoder<S> {
    /// A decoder with an empty buffer and zero statistics.
    pub const fn new() -> Self {
        StreamDecoder {
            buf: S::HELD,
            len: 0,
            stats: S::Stats::NEW,
            scanner: PhantomData,
        }
    }

    /// Feeds one byte (as from a UART interrupt); `on_frame` is called for each frame it
    /// completes.
    #[inline]
    pub fn push(&mut self, byte: u8, on_frame: impl FnMut(S::Item)) {
        self.feed(&[byte], on_frame);
    }

    /// Feeds a chunk of bytes; `on_frame` is called for each frame found, in stream order.
    ///
    /// (`#[inline]`: without it the call is not folded into `push`, and the byte-at-a-time path
    /// of the ESC decoder runs 40 % slower in the benchmarks.)
    #[inline]
    pub fn feed(&mut self, data: &[u8], mut on_frame: impl FnMut(S::Item)) {
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
            // bytes, so just keep them.
            if held + data.len() < S::candidate_len(&self.buf.as_ref()[..held]) {
                self.buf.as_mut()[held..held + data.len()].copy_from_slice(data);
                self.len += data.len() as u8;
                return;
            }
            // Finish the held candidate with the first bytes of `data`. A candidate starting in
            // the held bytes is decided by at most MAX_LEN bytes from its start, so appending
            // that many decides every one of them whenever `data` is long enough.
            let take = data.len().min(S::MAX_LEN);
            let mut pair = S::PAIR;
            let tmp = pair.as_mut();
            tmp[..held].copy_from_slice(&self.buf.as_ref()[..held]);
            tmp[held..held + take].copy_from_slice(&data[..take]);
            let n = held + take;
            let tmp_base = start.wrapping_sub(held as u64);
            let pos = S::scan_all::<false>(&tmp[..n], tmp_base, &mut self.stats, &mut on_frame);
            let Some(used) = pos.checked_sub(held) else {
                // `data` ran out before the held candidate was decided.
                self.hold(&tmp[pos..n]);
                return;
            };
            // The scan stopped in `data`, after `used` of its bytes: go on from there.
            data = &data[used..];
            base += used as u64;
        }
        let pos = S::scan_all::<false>(data, base, &mut self.stats, &mut on_frame);
        self.hold(&data[pos..]);
    }

    /// Keeps an undecided candidate (always shorter than a whole frame) for the next call.
    /// Out of line: the byte-at-a-time path stays small.
    #[inline(never)]
    fn hold(&mut self, tail: &[u8]) {
        self.buf.as_mut()[..tail.len()].copy_from_slice(tail);
        self.len = tail.len() as u8;
    }

    /// Decides the held bytes now, as if the stream ended here: a frame cut short is dropped
    /// (its bytes counted as skipped) and any frame inside it is still found.
    ///
    /// Call it at the end of a stream. A caller that sees the line fall silent for longer than a
    /// few byte times (a "gap": a sender writes each frame back to back) may call it then too,
    /// so that a cut frame is settled at once rather than when the next bytes arrive
    /// ([`StreamDecoder::line_silent`] does, and also tells the counting how long the silence
    /// was). Statistics carry on across the call.
    pub fn flush(&mut self, mut on_frame: impl FnMut(S::Item)) {
        let held = usize::from(self.len);
        let base = self.stats.bytes().wrapping_sub(held as u64);
        S::scan_all::<true>(
            &self.buf.as_ref()[..held],
            base,
            &mut self.stats,
            &mut on_frame,
        );
        self.len = 0;
    }

    /// Tells the decoder that the line has just been silent for a time in which at most
    /// `max_frames` frames could have been sent; `on_frame` gets the frames still found in the
    /// bytes held back before the silence.
    ///
    /// The silence ends whatever frame was arriving, so the held bytes are decided at once, as
    /// by [`StreamDecoder::flush`]; and the next frame's number step (an ESC's packet number,
    /// a hub's frame counter) counts as a loss only up to `max_frames + 1`: a larger step is a
    /// restart. Each protocol's decoder says more ([`Decoder`](crate::foc::Decoder),
    /// [`datalink::Decoder`](crate::datalink::Decoder)).
    pub fn line_silent(&mut self, max_frames: u32, on_frame: impl FnMut(S::Item)) {
        self.flush(on_frame);
        self.stats.line_silent(max_frames);
    }

    /// Passes over `n` bytes of the stream that this decoder is not given (another protocol's,
    /// while [`crate::detect`] reads that one only): the bytes it holds and those `n` are
    /// counted as skipped, so that its offsets and statistics stay the stream's. Whatever it
    /// held is dropped (a frame of it cannot continue across bytes it did not see).
    pub fn pass_over(&mut self, n: u64) {
        let held = usize::from(self.len);
        self.len = 0;
        self.stats.skip_bytes(held);
        let mut left = n;
        while left > 0 {
            let k = usize::try_from(left).unwrap_or(usize::MAX);
            self.stats.add_bytes(k);
            self.stats.skip_bytes(k);
            left -= k as u64;
        }
    }

    /// Continues this decoder with the work of `later`, a decoder started new at the stream
    /// offset where this one has been fed to, and fed the rest of the stream: for a stream read
    /// in two parts at once. Where this decoder holds nothing ([`StreamDecoder::buffered`] is
    /// 0), no byte before that offset waits for a later one, so the frames `later` found are
    /// exactly those this decoder would have found in the same bytes; its statistics become
    /// those of the whole stream, and it holds what `later` holds. `first_packet` is the packet
    /// number of `later`'s first data frame, whose step from this decoder's last one is
    /// counted as usual.
    ///
    /// False, and nothing changes, when this decoder holds bytes (the two parts must be read
    /// as one), when `later` counted data frames but `first_packet` is `None`, or when the
    /// protocol's decoding depends on more than the held bytes (V3, V4: chains of frames) or
    /// `later` found frames whose counters' first numbers are not known here (DataLink hub
    /// frames).
    ///
    /// ```
    /// use hwfoc::foc::{self, DataFrame};
    ///
    /// let frame = |packet| DataFrame { packet, ..Default::default() }.encode();
    /// let mut stream = Vec::new();
    /// for packet in [5, 6, 8, 9, 10] {
    ///     stream.extend_from_slice(&frame(packet));
    /// }
    /// let seam = 3 * 24; // where the frame of packet 9 starts
    /// let mut whole = foc::Decoder::new();
    /// whole.decode_all(&stream, |_| {});
    /// let (mut first, mut later) = (foc::Decoder::new(), foc::Decoder::new());
    /// first.feed(&stream[..seam], |_| {});
    /// later.decode_all(&stream[seam..], |_| {});
    /// assert!(first.then(&later, Some(9)));
    /// assert_eq!(first.stats(), whole.stats());
    /// assert_eq!(first.stats().lost_packets(), 1);
    /// ```
    pub fn then(&mut self, later: &StreamDecoder<S>, first_packet: Option<u16>) -> bool {
        if self.len != 0 {
            return false;
        }
        let mut stats = self.stats.clone();
        if !stats.then(&later.stats, first_packet) {
            return false;
        }
        *self = StreamDecoder {
            buf: later.buf.clone(),
            len: later.len,
            stats,
            scanner: PhantomData,
        };
        true
    }

    /// Feeds a whole stream and flushes it: the bulk path for a buffer in memory.
    pub fn decode_all(&mut self, data: &[u8], mut on_frame: impl FnMut(S::Item)) {
        self.feed(data, &mut on_frame);
        self.flush(on_frame);
    }

    /// Bytes held for a frame that has not finished arriving (always fewer than
    /// [`Scanner::MAX_LEN`]).
    pub fn buffered(&self) -> usize {
        usize::from(self.len)
    }

    /// The statistics so far.
    pub fn stats(&self) -> &S::Stats {
        &self.stats
    }

    /// The statistics, for a protocol's own silence rule (see
    /// [`mixed::Decoder`](crate::mixed::Decoder)).
    pub(crate) fn stats_mut(&mut self) -> &mut S::Stats {
        &mut self.stats
    }

    /// Forgets held bytes and statistics, as new.
    pub fn reset(&mut self) {
        *self = Self::new();
    }
}

/// The frames of the protocol `S` in a complete buffer, decoded in place: the bulk path.
///
/// It borrows the slice and allocates nothing; a frame cut off by the end of the slice is
/// skipped. It yields exactly what a [`StreamDecoder`] fed the same bytes and then flushed
/// would, with the same statistics. Made by [`frames`](crate::foc::frames) and
/// [`datalink::frames`](crate::datalink::frames).
pub struct Scan<'a, S: Scanner> {
    data: &'a [u8],
    pos: usize,
    stats: S::Stats,
}

impl<'a, S: Scanner> Scan<'a, S> {
    /// Scans `data`, a whole stream.
    pub fn new(data: &'a [u8]) -> Self {
        let mut stats = S::Stats::NEW;
        stats.add_bytes(data.len());
        Scan {
            data,
            pos: 0,
            stats,
        }
    }

    /// Statistics of the bytes scanned so far (complete once the iterator has returned `None`;
    /// the byte count is the whole slice from the start).
    pub fn stats(&self) -> &S::Stats {
        &self.stats
    }
}

impl<S: Scanner> Clone for Scan<'_, S> {
    fn clone(&self) -> Self {
        Scan {
            data: self.data,
            pos: self.pos,
            stats: self.stats.clone(),
        }
    }
}

impl<S: Scanner> fmt::Debug for Scan<'_, S> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Scan")
            .field("len", &self.data.len())
            .field("pos", &self.pos)
            .field("stats", &self.stats)
            .finish()
    }
}

impl<S: Scanner> Iterator for Scan<'_, S> {
    type Item = S::Item;

    #[inline]
    fn next(&mut self) -> Option<S::Item> {
        S::scan_next(self.data, &mut self.pos, &mut self.stats)
    }

    /// The rest of the stream in one run of the scanner, as [`StreamDecoder`] runs it: the
    /// position and statistics stay in registers from frame to frame, where [`Iterator::next`]
    /// stores them in the iterator after each frame. So `fold` and what is built on it
    /// (`for_each`, `count`, `sum`, `last`...) decode faster than a `for` loop: the same
    /// frames, the same statistics (the scan stops after a frame, every byte before it decided,
    /// as a streaming decoder fed the rest in one chunk and flushed would).
    #[inline]
    fn fold<B, F: FnMut(B, S::Item) -> B>(mut self, init: B, mut f: F) -> B {
        let rest = self.data.get(self.pos..).unwrap_or_default();
        let mut acc = Some(init);
        S::scan_all::<true>(rest, self.pos as u64, &mut self.stats, &mut |item| {
            acc = acc.take().map(|a| f(a, item));
        });
        // Taken and put back for each frame: never left empty.
        acc.unwrap_or_else(|| unreachable!("the fold's accumulator is put back after each frame"))
    }
}

impl<S: Scanner> core::iter::FusedIterator for Scan<'_, S> {}

#[cfg(test)]
pub(crate) mod tests {
    extern crate std;
    use std::vec::Vec;

    use crate::foc::{DataFrame, InfoFrame};
    use crate::scan::{Scan, Scanner};
    use crate::wire::SYNC;
    use crate::{datalink, foc, v3};

    /// A stream of `frames` `frame(i)`s among garbage dense in sync bytes and `header`s, one
    /// frame in `dirt` cut and one in `dirt` with a flipped bit, from the seed `x`.
    pub(crate) fn noisy(
        mut x: u64,
        (frames, dirt): (u32, u64),
        header: &[u8],
        frame: impl Fn(u32) -> Vec<u8>,
    ) -> Vec<u8> {
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mut out = Vec::new();
        for i in 0..frames {
            for _ in 0..next() % 4 * (next() % 9) {
                match next() % 6 {
                    0 => out.push(SYNC),
                    1 => out.extend_from_slice(header),
                    _ => out.push(next() as u8),
                }
            }
            let mut f = frame(i);
            match next() % dirt {
                0 => f.truncate(1 + next() as usize % (f.len() - 1)),
                1 => {
                    let bit = next() as usize % (f.len() * 8);
                    f[bit / 8] ^= 1 << (bit % 8);
                }
                _ => {}
            }
            out.extend_from_slice(&f);
        }
        out
    }

    /// `fold` over the rest of a scan, after `k` frames taken by `next`, gives the frames that
    /// `next` gives, for every `k`.
    fn assert_fold_is_next<S: Scanner>(stream: &[u8])
    where
        S::Item: PartialEq + core::fmt::Debug,
    {
        let items: Vec<S::Item> = Scan::<S>::new(stream).collect();
        assert!(items.len() > 50, "{} frames", items.len());
        for k in [0, 1, 2, items.len() / 3, items.len() - 1, items.len()] {
            let mut scan = Scan::<S>::new(stream);
            let head: Vec<S::Item> = scan.by_ref().take(k).collect();
            let folded = scan.fold(head, |mut v, item| {
                v.push(item);
                v
            });
            assert_eq!(folded, items, "after {k} frames");
        }
    }

    /// HW-FOC frame `i`: a data frame with packet number `i`, every 20th a device-information
    /// frame instead.
    pub(crate) fn foc_frame(i: u32) -> Vec<u8> {
        if i % 20 == 19 {
            let info = InfoFrame::new("XR_FOC_ESC", "HW1", "FW2", "ID").map(|i| i.encode());
            info.unwrap_or([0; 77]).to_vec()
        } else {
            let packet = i as u16;
            DataFrame {
                packet,
                ..Default::default()
            }
            .encode()
            .to_vec()
        }
    }

    #[test]
    fn fold_gives_what_next_gives() {
        let foc_stream = noisy(0x9B16_0102, (300, 12), &[SYNC, 0x16, 0x01, 0x02], foc_frame);
        assert_fold_is_next::<foc::Scanner>(&foc_stream);
        let hub = noisy(0x9B9E_0102, (300, 12), &[SYNC, 0x9E, 0x01, 0x02], |i| {
            datalink::HubFrame::new(i as u16).encode().to_vec()
        });
        assert_fold_is_next::<datalink::Scanner>(&hub);
        let older = noisy(0x9B00_0003, (300, 12), &[SYNC], |i| {
            let counter = i + 7;
            v3::V3Frame {
                counter,
                ..Default::default()
            }
            .encode()
            .to_vec()
        });
        assert_fold_is_next::<v3::Scanner>(&older);
    }
}
