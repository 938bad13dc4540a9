//! Finding V4 frames in a byte stream: the streaming [`Decoder`] and the bulk [`frames`]
//! iterator, one scanner under the streaming layer of [`crate::scan`].
//!
//! With no checksum, a candidate (a `9B` not inside an accepted frame) is judged by its own
//! fields and by the frames around it, in this order:
//!
//! 1. **Kind**: an info frame if it has the info frame's fixed bytes (`9B 9B` at 0, `01` at 4,
//!    `B9` at 12) and plausible constants, else a data frame (whose counter, throttle and voltage
//!    may put the same bytes there).
//! 2. **Plausible** ([`DataFrame::is_plausible`] under the full scale in use,
//!    [`InfoFrame::is_plausible`]); otherwise rejected ([implausible](Stats::implausible)).
//! 3. **An info frame** is accepted when a plausible data frame (any counter) starts right
//!    after it, chained to the last accepted frame or not (in slow mode every info frame has
//!    one; decided on the 32nd byte), or, chained, when another plausible info frame does (the
//!    data frame between them was cut out whole). Its fixed bytes alone would come by chance in
//!    bytes rich in `9B` and `B9` (about one in 30 000 positions when a quarter of the bytes are
//!    each), and a cut info frame completed by the next frame's bytes would pass for one.
//! 4. **A chained data frame**: it starts exactly where the last accepted frame (with its
//!    trailer, if one came) ended ([`Stats::chain_end`]) and carries the counter after the last
//!    data frame's, or one at most [`MAX_CHAINED_GAP`](super::MAX_CHAINED_GAP) further (frames
//!    cut out whole, counted [lost](Stats::lost_packets); any counter right after an info frame
//!    that started a chain): accepted on its own, on its 19th byte. So a frame between two cut
//!    frames, with no consecutive neighbour, is not lost.
//! 5. **A confirmed data frame**: otherwise (the first frame of a stream, after garbage or a cut
//!    or corrupted frame, a counter that jumped further) it must start a new chain: followed by
//!    two chained plausible data frames with counters +1 (fast mode), or by an info frame, after
//!    it or after the next data frame (slow mode, where they alternate). At most 59 bytes decide
//!    it. The frames after it are then accepted as chained, so a chain loses none of its
//!    frames; its first counter's step from the last accepted one counts
//!    [lost packets](Stats::lost_packets), a [duplicate](Stats::duplicate_packets) or a
//!    [restart](Stats::restarts).
//! 6. Otherwise it is rejected ([unconfirmed](Stats::unconfirmed)) and costs one byte: scanning
//!    resumes at the byte after its `9B`.
//!
//! A `B9` right where an accepted data frame ended is its trailer ([`Stats::trailers`]), taken
//! as part of it: a data frame is accepted on its 19th byte without waiting for the next byte
//! (in fast mode, the next frame's first, 40 ms later).
//!
//! Everything the rule reads of the past (the chain's end and expected counter, the adopted
//! full scale) lives in the [`Stats`], which the streaming layer hands to the scanner with
//! every chunk; each decision reads only bytes that are there, and 60 bytes from a candidate's
//! start always decide it (the [`Decoder`]'s held bytes). So both decoders give the same frames
//! and statistics however the stream is cut into chunks.

use crate::chain::{self, Verdict};
use crate::counters::COUNTER24_MAX;
use crate::scan::{Scan, StreamDecoder, impl_scanner};
use crate::wire::SYNC;

use super::data::{Data, DataFrame};
use super::info::InfoFrame;
use super::layout::{DATA_FRAME_LEN, INFO_FRAME_LEN, SLOW_DATA_FRAME_LEN, TRAILER};
use super::stats::Stats;

/// How many chained data frames start a chain on their own (without an info frame).
pub const CHAIN_TO_LOCK: usize = 3;

/// The most bytes that decide a candidate: three data frames with their trailers.
const MAX_LEN: usize = CHAIN_TO_LOCK * SLOW_DATA_FRAME_LEN;

/// A V4 frame as the decoder emits it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum V4Frame {
    /// A data frame, with the info frame adopted when it was decoded.
    Data(Data),
    /// An info frame (each copy, adopted or not: see [`Stats::adopted`]).
    Info(InfoFrame),
}

/// A V4 frame and where it started in the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Decoded {
    /// Offset of the frame's first byte, counting every byte given to the decoder since it was
    /// created (or, for [`frames`], from the start of the slice).
    pub offset: u64,
    /// The frame.
    pub frame: V4Frame,
}

/// The frame a candidate is found to be (in a [`Verdict`]).
enum Judged {
    Data(DataFrame),
    Info(InfoFrame),
}

/// What starts at an offset of a candidate's bytes.
enum Found {
    /// A plausible data frame.
    Data(DataFrame),
    /// A plausible info frame.
    Info(InfoFrame),
    /// Anything else: no `9B` there, or an implausible frame.
    Nothing,
    /// More bytes are needed.
    Undecided,
}

/// What starts at `c[at..]`, read with `full_scale`.
#[inline(always)]
fn found_at(c: &[u8], at: usize, full_scale: u16) -> Found {
    let rest = c.get(at..).unwrap_or(&[]);
    match rest.first() {
        None => return Found::Undecided,
        Some(&b) if b != SYNC => return Found::Nothing,
        Some(_) => {}
    }
    let Some(head) = rest.first_chunk::<INFO_FRAME_LEN>() else {
        return Found::Undecided;
    };
    if InfoFrame::has_fixed_bytes(head) {
        let info = InfoFrame::read(head);
        if info.is_plausible() {
            return Found::Info(info);
        }
        // Not an info frame, but maybe a data frame with the same bytes there: a counter
        // 0x9Bxxxx, an input throttle of 256 to 511 and a voltage reading whose low byte is B9.
    }
    let Some(bytes) = rest.first_chunk::<DATA_FRAME_LEN>() else {
        return Found::Undecided;
    };
    let frame = DataFrame::read(bytes);
    if frame.is_plausible(full_scale) {
        Found::Data(frame)
    } else {
        Found::Nothing
    }
}

/// Where the frame after a data frame at `c[at..]` starts: after its trailer if byte 19 is
/// `B9`, right after it if byte 19 is `9B`; `Err` with the verdict otherwise.
#[inline(always)]
fn after_data(c: &[u8], at: usize) -> Result<usize, Verdict<Judged>> {
    match c.get(at + DATA_FRAME_LEN) {
        None => Err(Verdict::Undecided),
        Some(&TRAILER) => Ok(at + SLOW_DATA_FRAME_LEN),
        Some(&SYNC) => Ok(at + DATA_FRAME_LEN),
        Some(_) => Err(Verdict::Unconfirmed),
    }
}

/// Judges the candidate at the start of `c` (a `9B` at stream offset `at`) from the bytes
/// there; decided by at most [`MAX_LEN`] bytes.
#[inline(always)]
fn judge(c: &[u8], at: u64, stats: &Stats) -> Verdict<Judged> {
    let full_scale = stats.full_scale();
    let first = match found_at(c, 0, full_scale) {
        Found::Undecided => return Verdict::Undecided,
        Found::Nothing => return Verdict::Implausible,
        // An info frame needs a plausible data frame right after it, or, where the chain ends,
        // another info frame (the data frame between them was cut out whole).
        Found::Info(info) => {
            let chained = stats.chained(at);
            return match found_at(c, INFO_FRAME_LEN, full_scale) {
                Found::Data(_) => Verdict::Frame(Judged::Info(info), !chained),
                Found::Info(_) if chained => Verdict::Frame(Judged::Info(info), false),
                Found::Undecided => Verdict::Undecided,
                Found::Info(_) | Found::Nothing => Verdict::Unconfirmed,
            };
        }
        Found::Data(frame) => frame,
    };
    if stats.continues_chain(at, first.counter) {
        return Verdict::Frame(Judged::Data(first), false);
    }
    // A new chain: data + info, or three data frames with counters +1 (an info frame after the
    // second also does).
    let mut frame_at = 0;
    let mut counter = first.counter;
    for _ in 1..CHAIN_TO_LOCK {
        frame_at = match after_data(c, frame_at) {
            Ok(next) => next,
            Err(verdict) => return verdict,
        };
        counter = (counter + 1) & COUNTER24_MAX;
        match found_at(c, frame_at, full_scale) {
            Found::Undecided => return Verdict::Undecided,
            Found::Nothing => return Verdict::Unconfirmed,
            Found::Info(_) => return Verdict::Frame(Judged::Data(first), true),
            Found::Data(next) if next.counter != counter => return Verdict::Unconfirmed,
            Found::Data(_) => {}
        }
    }
    Verdict::Frame(Judged::Data(first), true)
}

/// The fewest bytes that may decide a candidate whose first `held` bytes are there: 13 (an
/// info frame), then one more byte at a time (a lower bound, as the streaming layer needs).
#[inline(always)]
const fn candidate_len(held: usize) -> usize {
    if held < INFO_FRAME_LEN {
        INFO_FRAME_LEN
    } else {
        held + 1
    }
}

/// Finds the next frame in `data` (its first byte at stream offset `base`) from `*pos`, as
/// [`chain::scan_next`] does with V4's [`judge`], after taking a trailer at `*pos` (a `B9`
/// where the data frame just accepted ended: only ever at the start of a call, as that frame
/// ends a call).
#[inline(always)]
fn scan_next(
    data: &[u8],
    pos: &mut usize,
    base: u64,
    stats: &mut Stats,
    at_end: bool,
) -> Option<(usize, V4Frame)> {
    if data.get(*pos) == Some(&TRAILER) && stats.trailer_at(base + *pos as u64) {
        stats.take_trailer();
        *pos += 1;
    }
    chain::scan_next(
        data,
        pos,
        base,
        stats,
        at_end,
        judge,
        |stats, at, judged, synced| match judged {
            Judged::Data(frame) => {
                stats.accept_data(at, &frame, synced);
                let data = Data {
                    frame,
                    info: stats.in_use(),
                };
                (DATA_FRAME_LEN, V4Frame::Data(data))
            }
            Judged::Info(info) => {
                stats.accept_info(at, &info, synced);
                (INFO_FRAME_LEN, V4Frame::Info(info))
            }
        },
    )
}

/// The V4 scanner, as the streaming layer ([`crate::scan`]) runs it: [`Decoder`] and
/// [`Frames`] are it under [`StreamDecoder`] and [`Scan`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Scanner;

impl_scanner!(
    Scanner,
    Stats,
    Decoded,
    MAX_LEN,
    |held: &[u8]| candidate_len(held.len()),
    scan_next
);

/// A streaming V4 decoder: feed it bytes in any chunking, get every frame once (the streaming
/// layer's [`StreamDecoder`] over the V4 scanner).
///
/// Its state is a 59-byte buffer for a candidate still being decided plus the [`Stats`] (which
/// hold the chain's end and the info frames seen and adopted): 184 bytes
/// (`size_of::<Decoder>()`, checked by a test), no allocation, no timing.
///
/// ```
/// use hwfoc::v4::{Decoder, DataFrame, V4Frame, InfoFrame};
///
/// let info = InfoFrame { full_scale: 1000, v1: 8, v2: 91, ..Default::default() };
/// let data = |counter| DataFrame { counter, voltage_adc: 1365, ..Default::default() };
/// // Slow mode: info and data frames alternate, each data frame with its trailing B9.
/// let mut wire = vec![0x9B, 0x00]; // noise
/// for counter in 0..3 {
///     wire.extend_from_slice(&info.encode());
///     wire.extend_from_slice(&data(counter).encode_with_trailer());
/// }
/// let mut decoder = Decoder::new();
/// let mut got = Vec::new();
/// for &byte in &wire {
///     decoder.push(byte, |d| got.push(d.frame));
/// }
/// decoder.flush(|d| got.push(d.frame));
/// assert_eq!(got.len(), 6);
/// // Constants adopted from the second copy on.
/// let adopted: Vec<bool> = got
///     .iter()
///     .filter_map(|f| match f { V4Frame::Data(d) => Some(d.info.is_some()), _ => None })
///     .collect();
/// assert_eq!(adopted, [false, true, true]);
/// let stats = decoder.stats();
/// assert_eq!((stats.info_frames(), stats.info_adoptions(), stats.trailers()), (3, 1, 3));
/// assert_eq!(stats.bytes_skipped(), 2);
/// ```
///
/// # Silences
///
/// [`line_silent`](StreamDecoder::line_silent)`(max_frames, ..)` decides the held bytes at
/// once (as the end of a stream) and bounds the next counter step counted as a loss by
/// `max_frames + 1`, as for the HW-FOC [`Decoder`](crate::foc::Decoder).
pub type Decoder = StreamDecoder<Scanner>;

/// Decodes every V4 frame in a complete buffer, in place: the bulk path.
///
/// The iterator borrows the slice and allocates nothing; it yields exactly what a [`Decoder`]
/// fed the same bytes and then flushed would, with the same statistics.
///
/// ```
/// use hwfoc::v4::{self, DataFrame, V4Frame};
///
/// let mut wire = Vec::new();
/// for counter in 40..44 {
///     wire.extend_from_slice(&DataFrame { counter, throttle_in_raw: 500, ..Default::default() }.encode());
/// }
/// let mut it = v4::frames(&wire);
/// let counters: Vec<u32> = it
///     .by_ref()
///     .filter_map(|d| match d.frame { V4Frame::Data(d) => Some(d.packet()), _ => None })
///     .collect();
/// assert_eq!(counters, [40, 41, 42, 43]);
/// assert_eq!(it.stats().bytes_skipped(), 0);
/// ```
pub fn frames(data: &[u8]) -> Frames<'_> {
    Scan::new(data)
}

/// Iterator returned by [`frames`].
pub type Frames<'a> = Scan<'a, Scanner>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::v4::info::VoltsPerStep;

    fn data(counter: u32) -> DataFrame {
        DataFrame {
            counter,
            throttle_in_raw: 300,
            throttle_out_raw: 280,
            erpm: 12_000,
            voltage_adc: 1360,
            current_adc: 0,
            temp_adc: 3240,
            temp2_adc: 0,
        }
    }

    const INFO: InfoFrame = InfoFrame {
        full_scale: 1000,
        v1: 8,
        v2: 91,
        i1: 0,
        i2: 1,
        i3: 0,
        t1: 0x21,
        t2: 0x21,
    };

    #[test]
    fn state_size() {
        assert_eq!(size_of::<Decoder>(), 184);
    }

    #[test]
    fn candidate_len_is_a_lower_bound_below_max_len() {
        for held in 0..MAX_LEN {
            assert!(candidate_len(held) > held);
            assert!(candidate_len(held) <= MAX_LEN);
        }
    }

    #[test]
    fn a_chained_data_frame_comes_out_on_its_19th_byte() {
        let mut w = [0u8; 80];
        for k in 0..4 {
            w[k * 19..k * 19 + 19].copy_from_slice(&data(k as u32).encode());
        }
        let mut d = Decoder::new();
        let mut got = 0;
        d.feed(&w[..56], |_| got += 1);
        assert_eq!(got, 0);
        d.feed(&w[56..57], |_| got += 1);
        assert_eq!((got, d.buffered()), (3, 0));
        d.feed(&w[57..75], |_| got += 1);
        assert_eq!(got, 3);
        d.feed(&w[75..76], |_| got += 1);
        assert_eq!((got, d.buffered()), (4, 0));
    }

    #[test]
    fn trailer_after_the_last_frame_of_a_chunk() {
        let mut w = [0u8; 60];
        for k in 0..3 {
            w[k * 20..k * 20 + 20].copy_from_slice(&data(k as u32).encode_with_trailer());
        }
        let mut d = Decoder::new();
        d.feed(&w[..59], |_| {});
        assert_eq!((d.stats().frames(), d.stats().trailers()), (3, 2));
        d.feed(&w[59..], |_| {});
        d.flush(|_| {});
        let s = d.stats();
        assert_eq!((s.trailers(), s.bytes_skipped()), (3, 0));
    }

    #[test]
    fn an_info_frame_needs_a_data_frame_beside_it() {
        let mut w = [0u8; 40];
        w[..13].copy_from_slice(&INFO.encode());
        w[13..32].copy_from_slice(&data(7).encode());
        let mut it = frames(&w[..32]);
        assert_eq!(it.by_ref().count(), 2);
        assert_eq!(it.stats().syncs(), 1);
        // Alone, or followed by noise: not accepted, even chained to a data frame.
        let mut it = frames(&w[..13]);
        assert_eq!(it.by_ref().count(), 0);
        let mut chained = [0u8; 33];
        chained[..20].copy_from_slice(&data(7).encode_with_trailer());
        chained[20..].copy_from_slice(&INFO.encode());
        let mut it = frames(&chained);
        assert_eq!(it.by_ref().count(), 1); // the data frame, confirmed by the info frame
        assert_eq!(it.stats().info_frames(), 0);
        w[13] = 0;
        let mut it = frames(&w[..32]);
        assert_eq!(it.by_ref().count(), 0);
        assert_eq!(it.stats().unconfirmed(), 1);
        // A data frame, an info frame and a data frame: all three.
        let mut w = [0u8; 52];
        w[..20].copy_from_slice(&data(7).encode_with_trailer());
        w[20..33].copy_from_slice(&INFO.encode());
        w[33..].copy_from_slice(&data(8).encode());
        let mut it = frames(&w);
        assert_eq!(it.by_ref().count(), 3);
        let s = it.stats();
        assert_eq!((s.trailers(), s.syncs(), s.bytes_skipped()), (1, 1, 0));
    }

    #[test]
    fn adoption_needs_two_identical_copies_in_a_row() {
        let other = InfoFrame {
            full_scale: 2000,
            ..INFO
        };
        let mut w = [0u8; 6 * 33];
        for (k, info) in [INFO, other, INFO, INFO, other, other].iter().enumerate() {
            w[33 * k..33 * k + 13].copy_from_slice(&info.encode());
            w[33 * k + 13..33 * k + 33].copy_from_slice(&data(k as u32).encode_with_trailer());
        }
        let mut it = frames(&w);
        let mut scales = [Some(0); 6];
        let mut n = 0;
        for d in it.by_ref() {
            if let V4Frame::Data(d) = d.frame {
                scales[n] = d.info.map(|i| i.full_scale);
                n += 1;
            }
        }
        assert_eq!(n, 6);
        assert_eq!(scales, [None, None, None, Some(1000), None, Some(2000)]);
        let s = it.stats();
        assert_eq!((s.info_adoptions(), s.info_disagreements()), (2, 3));
        assert_eq!(s.adopted(), Some(other));
    }

    /// A 6S ESC swapped for a 12S one (slow mode: info and data frames alternate; the new ESC's
    /// counter starts again): no data frame after the first info frame of the new ESC is scaled
    /// by the old ESC's volts per step; those before its constants are adopted (two identical
    /// copies) are scaled as before any info frame.
    #[test]
    fn a_swapped_esc_frame_never_uses_the_old_scale() {
        let hv = InfoFrame {
            v1: 11,
            v2: 65,
            ..INFO
        };
        let mut w = [0u8; 7 * 33];
        for (k, info) in [INFO, INFO, INFO, hv, hv, hv, hv].iter().enumerate() {
            let counter = if k < 3 { 100 + k as u32 } else { k as u32 - 3 };
            w[33 * k..33 * k + 13].copy_from_slice(&info.encode());
            w[33 * k + 13..33 * k + 33].copy_from_slice(&data(counter).encode_with_trailer());
        }
        let mut scales: [Option<VoltsPerStep>; 7] = [Some(VoltsPerStep::DEFAULT); 7];
        let mut n = 0;
        for d in frames(&w) {
            if let V4Frame::Data(d) = d.frame {
                scales[n] = d.info.map(|i| i.volts_per_step());
                n += 1;
            }
        }
        assert_eq!(n, 7);
        let (lv, hv) = (Some(INFO.volts_per_step()), Some(hv.volts_per_step()));
        assert_eq!(scales, [None, lv, lv, None, hv, hv, hv]);
    }
}
