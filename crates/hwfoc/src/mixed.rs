//! Streams that may carry either protocol, or both one after the other: the [`Decoder`]
//! reads HW-FOC frames (an ESC's own wire) and DataLink V2 frames (a hub) at once, in byte
//! order.
//!
//! One scanner looks for both: at each `9B` followed by a length byte of either protocol it
//! tries a frame of the protocol that length byte belongs to (the two sets of length bytes are
//! disjoint, so a candidate is of one protocol only). A verified frame of either is taken whole
//! and scanning resumes after it, so the bytes of an intact frame of one protocol are never read
//! as a candidate of the other (a `9B 16` inside a hub frame's records is not a false ESC frame,
//! nor counted as a checksum failure). A rejected candidate costs one byte, as in each
//! protocol's own scanner. So whatever the chunking, and however often a stream changes
//! protocol (an adapter moved from an ESC to a hub), every intact frame of both is found.
//!
//! The statistics ([`Stats`]) are each protocol's: [`foc::Stats`] for the ESC frames,
//! [`datalink::Stats`] for the hub frames. Both count every byte of the stream, and both count as
//! skipped only the bytes in no frame of either protocol.
//!
//! Back-to-back ESC frames are taken in runs, data frames on the HW-FOC scanner's own first
//! guess, so a stream of ESC frames is read as fast as by the
//! [`Decoder`](crate::foc::Decoder). After a run of line noise
//! it searches as the HW-FOC scanner does (a frame at the run's first sync bytes, then whole
//! windows of candidates decided at once), and those searches stop at a DataLink candidate,
//! which DataLink decides. From there, and where less than a window is left, it searches one
//! candidate of either protocol at a time, each word compared with four second bytes instead
//! of two.

use crate::datalink::{self, FRAME_LEN, LengthByte};
use crate::foc::decoder::{
    Guess, Stops, bytes_equal, find_sync_then, is_length_byte, search_after_noise, take_candidate,
};
use crate::foc::frame::{HEADERS, or_length_bytes};
use crate::foc::{self, MAX_FRAME_LEN};
use crate::scan::{self, Candidate, Scan, StreamDecoder};
use crate::wire::SYNC;

/// The longest candidate of either protocol.
const MAX_LEN: usize = if MAX_FRAME_LEN > FRAME_LEN {
    MAX_FRAME_LEN
} else {
    FRAME_LEN
};

/// A frame of either protocol, with its stream offset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Decoded {
    /// A HW-FOC frame (an ESC's own wire).
    Esc(foc::Decoded),
    /// A DataLink V2 hub frame.
    Hub(datalink::Decoded),
}

impl Decoded {
    /// Offset of the frame's first byte in the stream.
    pub fn offset(&self) -> u64 {
        match self {
            Decoded::Esc(d) => d.offset,
            Decoded::Hub(d) => d.offset,
        }
    }
}

impl crate::protocol::FoundFrame for Decoded {
    #[inline]
    fn offset(&self) -> u64 {
        Decoded::offset(self)
    }

    #[inline]
    fn protocol(&self) -> crate::Protocol {
        match self {
            Decoded::Esc(_) => crate::Protocol::HwFoc,
            Decoded::Hub(_) => crate::Protocol::DataLink,
        }
    }
}

/// The statistics of a stream read by the [`Decoder`]: each protocol's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Stats {
    /// The HW-FOC frames' statistics (its bytes and skipped bytes are the stream's).
    pub esc: foc::Stats,
    /// The DataLink frames' statistics (its bytes and skipped bytes are the stream's).
    pub hub: datalink::Stats,
}

impl Stats {
    /// No bytes seen.
    pub const fn new() -> Self {
        Stats {
            esc: foc::Stats::new(),
            hub: datalink::Stats::new(),
        }
    }

    /// Every byte given to the decoder so far.
    #[inline]
    pub const fn bytes(&self) -> u64 {
        self.esc.bytes()
    }

    #[inline(always)]
    fn skip(&mut self, n: usize) {
        self.esc.skip(n);
        self.hub.skip(n);
    }
}

impl Default for Stats {
    fn default() -> Self {
        Self::new()
    }
}

impl crate::scan::sealed::Sealed for Stats {}

impl scan::Stats for Stats {
    const NEW: Self = Stats::new();

    #[inline]
    fn bytes(&self) -> u64 {
        Stats::bytes(self)
    }

    #[inline]
    fn add_bytes(&mut self, n: usize) {
        self.esc.add_bytes(n);
        self.hub.add_bytes(n);
    }

    /// `max_frames` ESC data frames (24 byte times at 19200 baud each) could have been sent:
    /// as many hub frames fit in nine tenths of that time (160 byte times at 115200 baud).
    fn line_silent(&mut self, max_frames: u32) {
        let hub_frames = (u64::from(max_frames) * 9).div_ceil(10);
        self.esc.line_silent(max_frames);
        self.hub
            .line_silent(u32::try_from(hub_frames).unwrap_or(u32::MAX));
    }

    #[inline]
    fn skip_bytes(&mut self, n: usize) {
        self.skip(n);
    }

    /// Joined when `later` found no hub frame: both protocols' statistics, each the sum of the
    /// two parts (the bytes in a frame of either are skipped bytes of neither).
    fn then(&mut self, later: &Self, first_packet: Option<u16>) -> bool {
        let mut joined = *self;
        if joined.esc.then(&later.esc, first_packet) && joined.hub.then(&later.hub) {
            *self = joined;
            return true;
        }
        false
    }
}

/// Whether `b` is a DataLink length byte.
#[inline(always)]
fn is_hub_length_byte(b: u8) -> bool {
    LengthByte::from_byte(b).is_some()
}

/// The HW-FOC searches after noise stop at a DataLink candidate, which this scanner decides.
struct HubCandidates;

impl Stops for HubCandidates {
    const SECONDS: &'static [u8] = &[LengthByte::Covered.byte(), LengthByte::Total.byte()];
}

/// Whether a DataLink candidate starts at `data[at]`: a sync byte and a hub length byte.
#[inline(always)]
fn hub_candidate_at(data: &[u8], at: usize) -> bool {
    matches!(data.get(at..at + 2), Some(&[SYNC, l]) if is_hub_length_byte(l))
}

/// Offset of the first candidate of either protocol in `hay`: a sync byte followed by a length
/// byte of either, or a sync byte that is the last byte of `hay`.
#[inline]
fn find_header(hay: &[u8]) -> Option<usize> {
    find_sync_then(
        hay,
        |b| is_length_byte(b) || is_hub_length_byte(b),
        |word| {
            or_length_bytes(|b| bytes_equal(word, b))
                | bytes_equal(word, LengthByte::Covered.byte())
                | bytes_equal(word, LengthByte::Total.byte())
        },
    )
}

/// How many bytes decide the candidate whose first bytes are `held`.
#[inline(always)]
fn candidate_len(held: &[u8]) -> usize {
    match held.get(1) {
        Some(&b) if is_hub_length_byte(b) => crate::datalink::decoder::candidate_len(held.len()),
        Some(_) => crate::foc::frame::candidate_len(held),
        None => 2,
    }
}

/// Finds the next frame of either protocol in `data` from `*pos`, counting what it passes over
/// in `stats`; unless `first_guess` is false, it first tries an ESC data frame right at `*pos`.
/// Returns as the HW-FOC scanner's `scan_next` does, and looks for the next frame as it does
/// (a frame right here, the first look after noise while `guess` holds, then whole windows),
/// with this difference: each of those ways stops at a DataLink candidate, which DataLink then
/// decides (back-to-back hub frames are decided first, with no window). After a hub frame
/// (`after_hub`) it searches one candidate at a time.
#[inline(always)]
fn scan_next(
    data: &[u8],
    pos: &mut usize,
    stats: &mut Stats,
    (at_end, first_guess, after_hub): (bool, bool, bool),
    guess: &mut Guess,
) -> Option<(usize, Found)> {
    if first_guess && let Some((at, frame)) = foc::FocFrame::take_first(data, pos, &mut stats.esc) {
        return Some((at, Found::Esc(frame)));
    }
    // Unless a hub candidate is here (a hub frame after another), or the frame before was a
    // hub's (whose stream goes on with hub frames, where the ESC searches would stop): an ESC
    // frame of any kind right here, else the search after a run of line noise, to the next
    // ESC frame or hub candidate, counted here.
    if !after_hub && !hub_candidate_at(data, *pos) {
        if let Some((at, frame)) = foc::FocFrame::take(data, pos, &mut stats.esc) {
            return Some((at, Found::Esc(frame)));
        }
        search_after_noise!(
            HubCandidates, data, pos, stats, guess,
            esc: &mut stats.esc,
            found: |f| (f.0, Found::Esc(f.1))
        );
    }
    // A hub candidate, where the search stopped, and the last bytes: one candidate at a time.
    // (After a hub candidate that is no frame, the rest of a run of noise is searched so too:
    // in line noise a hub candidate, a sync byte and one of two length bytes, comes once in
    // 32 768 byte pairs.)
    by_candidates(data, pos, stats, at_end)
}

/// The next frame of either protocol from `*pos`, searched one candidate at a time: where
/// less than a window and a frame are left, as a streaming decoder must decide them when a
/// candidate may still be arriving. Returns as [`scan_next`] does.
#[inline(always)]
fn by_candidates(
    data: &[u8],
    pos: &mut usize,
    stats: &mut Stats,
    at_end: bool,
) -> Option<(usize, Found)> {
    loop {
        let Some(k) = find_header(&data[*pos..]) else {
            stats.skip(data.len() - *pos);
            *pos = data.len();
            return None;
        };
        stats.skip(k);
        let i = *pos + k;
        *pos = i;
        // The length byte tells the protocol (their length bytes differ): that protocol
        // decides the candidate (a sync byte that ends `data` is the ESC wire's to decide).
        let decided = match data.get(i + 1) {
            Some(&b) if is_hub_length_byte(b) => {
                match crate::datalink::decoder::take_candidate(data, pos, &mut stats.hub, at_end) {
                    Candidate::Frame((at, frame, report)) => {
                        // Its stream offset is set by `Found::at`.
                        let hub = datalink::Decoded {
                            offset: 0,
                            frame,
                            report,
                        };
                        return Some((at, Found::Hub(hub)));
                    }
                    other => other.is_decided(),
                }
            }
            _ => match take_candidate(data, pos, &mut stats.esc, at_end) {
                Candidate::Frame((at, frame)) => return Some((at, Found::Esc(frame))),
                other => other.is_decided(),
            },
        };
        if !decided {
            return None;
        }
        stats.skip(1);
        *pos = i + 1;
    }
}

/// A frame found, its offset given apart.
enum Found {
    Esc(foc::FocFrame),
    Hub(datalink::Decoded),
}

impl Found {
    #[inline(always)]
    fn at(self, offset: u64) -> Decoded {
        match self {
            Found::Esc(frame) => Decoded::Esc(foc::Decoded { offset, frame }),
            Found::Hub(mut d) => {
                d.offset = offset;
                Decoded::Hub(d)
            }
        }
    }
}

/// The scanner of both protocols, as the streaming layer ([`crate::scan`]) runs it:
/// [`Decoder`] and [`Frames`] are it under [`StreamDecoder`] and [`Scan`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Scanner;

impl crate::scan::sealed::Sealed for Scanner {}

impl scan::Scanner for Scanner {
    type Item = Decoded;
    type Stats = Stats;
    type Held = [u8; MAX_LEN - 1];
    type Pair = [u8; 2 * MAX_LEN];
    const HELD: Self::Held = [0; MAX_LEN - 1];
    const PAIR: Self::Pair = [0; 2 * MAX_LEN];
    const MAX_LEN: usize = MAX_LEN;

    #[inline(always)]
    fn candidate_len(held: &[u8]) -> usize {
        candidate_len(held)
    }

    /// Out of line, as the HW-FOC scanner's: one copy of the scanner per caller.
    #[inline(never)]
    fn scan_all<const AT_END: bool>(
        data: &[u8],
        base: u64,
        stats: &mut Stats,
        on_frame: &mut impl FnMut(Decoded),
    ) -> usize {
        let mut pos = 0;
        let mut guess = Guess::NEW;
        let mut after_hub = false;
        loop {
            // A run of back-to-back ESC frames, where a data frame starts (the first kind's
            // header: not after each hub frame).
            if data.get(pos..pos + 4) == Some(&HEADERS[0]) {
                pos = esc_run(data, pos, base, &mut stats.esc, on_frame);
            }
            let next = scan_next(
                data,
                &mut pos,
                stats,
                (AT_END, false, after_hub),
                &mut guess,
            );
            let Some((at, frame)) = next else {
                return pos;
            };
            after_hub = matches!(frame, Found::Hub(_));
            on_frame(frame.at(base + at as u64));
        }
    }

    #[inline]
    fn scan_next(data: &[u8], pos: &mut usize, stats: &mut Stats) -> Option<Decoded> {
        // One frame at a time (a byte pushed, a held candidate): no noise to learn from.
        let mut guess = Guess::NEW;
        let next = scan_next(data, pos, stats, (true, true, false), &mut guess);
        next.map(|(at, frame)| frame.at(at as u64))
    }
}

/// Takes the back-to-back ESC frames from `pos`, giving each to `on_frame`: data frames on
/// the HW-FOC scanner's first guess, and a frame of another kind (an info frame among them)
/// where that is not one. Returns where they end.
///
/// Out of line, once a run of frames (a run ends at noise, a hub frame or the end of `data`):
/// with the searches after noise in the same function, the compiler (rustc 1.95) loaded and
/// stored the packet counter again for each frame (`hwfoc summary` of a clean stream +3.9 %
/// instructions against the scanner before the searches, this way +2.5 %, its time the same;
/// the bench's `detect_clean` as fast as before or faster). A run of data frames alone, out
/// of line, cost a call at each info frame (one in 21 frames: `detect_clean` 6 % slower).
#[inline(never)]
fn esc_run(
    data: &[u8],
    mut pos: usize,
    base: u64,
    esc: &mut foc::Stats,
    on_frame: &mut impl FnMut(Decoded),
) -> usize {
    loop {
        // Back-to-back data frames have a call site of their own, as in the HW-FOC scanner.
        while let Some((at, frame)) = foc::FocFrame::take_first(data, &mut pos, esc) {
            on_frame(Decoded::Esc(foc::Decoded {
                offset: base + at as u64,
                frame,
            }));
        }
        let Some((at, frame)) = foc::FocFrame::take(data, &mut pos, esc) else {
            return pos;
        };
        on_frame(Decoded::Esc(foc::Decoded {
            offset: base + at as u64,
            frame,
        }));
    }
}

/// A streaming decoder of both protocols (see the [module documentation](self)): feed it bytes
/// in any chunking, get every HW-FOC and DataLink frame once, in byte order.
///
/// ```
/// use hwfoc::datalink;
/// use hwfoc::mixed::{Decoded, Decoder};
/// use hwfoc::foc::DataFrame;
///
/// // An adapter on an ESC, then moved to a hub.
/// let mut wire = DataFrame { packet: 7, ..Default::default() }.encode().to_vec();
/// wire.extend_from_slice(&datalink::HubFrame::new(1).encode());
/// let mut decoder = Decoder::new();
/// let mut got = Vec::new();
/// for chunk in wire.chunks(5) {
///     decoder.feed(chunk, |d| got.push(d));
/// }
/// decoder.flush(|d| got.push(d));
/// assert!(matches!(got[..], [Decoded::Esc(_), Decoded::Hub(_)]));
/// assert_eq!(decoder.stats().esc.bytes_skipped(), 0);
/// assert_eq!(decoder.stats().hub.bytes_skipped(), 0);
/// ```
///
/// # Silences
///
/// [`line_silent_each`](StreamDecoder::line_silent_each) tells it how many frames of each
/// protocol a silence could have hidden (see [`Decoder`](crate::foc::Decoder) and
/// [`datalink::Decoder`]);
/// [`line_silent`](StreamDecoder::line_silent) takes ESC data frames and counts nine tenths of
/// them (rounded up) as hub frames, the hub frames that fit in the same time.
pub type Decoder = StreamDecoder<Scanner>;

impl StreamDecoder<Scanner> {
    /// The line was silent for a time in which at most `esc_frames` ESC data frames, or
    /// `hub_frames` DataLink frames, could have been sent: the held bytes are decided at once,
    /// and each protocol's next number step is judged as its own decoder's `line_silent` says.
    pub fn line_silent_each(
        &mut self,
        esc_frames: u32,
        hub_frames: u32,
        on_frame: impl FnMut(Decoded),
    ) {
        self.flush(on_frame);
        let stats = self.stats_mut();
        stats.esc.line_silent(esc_frames);
        stats.hub.line_silent(hub_frames);
    }
}

/// Decodes every frame of both protocols in a complete buffer, in place: the bulk path. It
/// yields exactly what a [`Decoder`] fed the same bytes and then flushed would.
pub fn frames(data: &[u8]) -> Frames<'_> {
    Scan::new(data)
}

/// Iterator returned by [`frames`].
pub type Frames<'a> = Scan<'a, Scanner>;

impl crate::protocol::FamilyScanner for Scanner {
    fn handed_on(s: &Stats) -> u64 {
        u64::from(s.esc.packets().count())
            + u64::from(s.esc.info_frames())
            + u64::from(s.hub.frames())
    }

    fn line_silent(
        decoder: &mut Decoder,
        esc_frames: u32,
        hub_frames: u32,
        on_frame: &mut dyn FnMut(Decoded),
    ) {
        decoder.line_silent_each(esc_frames, hub_frames, on_frame);
    }
}

impl Decoded {
    /// Hands the frame on as the ESC frames it holds: `emit(channel, offset, frame)` gets an ESC's
    /// frame (channel `None`), or each of a hub frame's ESC frames with its channel, at the hub
    /// frame's offset. Generic, so that a caller's loop over HW-FOC frames keeps it inline
    /// ([`crate::family::FamilyLink::hand_on`] is it behind `dyn`).
    #[inline(always)]
    pub fn each_esc_frame(
        &self,
        mut emit: impl FnMut(Option<u8>, u64, &crate::telemetry::AnyFrame),
    ) {
        match self {
            Decoded::Esc(d) => emit(None, d.offset, &crate::telemetry::AnyFrame::from(d.frame)),
            Decoded::Hub(d) => d.each_esc_frame(emit),
        }
    }
}

impl crate::family::FamilyLink for Scanner {
    fn hand_on(d: &Decoded, emit: &mut crate::family::Emit<'_>) {
        d.each_esc_frame(emit);
    }

    /// None: an ESC's wire and each of a hub's channels has figures of its own.
    fn figures(_: &Stats) -> Option<crate::family::LinkFigures> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foc::DataFrame;
    use crate::{datalink, foc};

    fn esc(packets: core::ops::Range<u16>, out: &mut [u8], at: &mut usize) {
        for packet in packets {
            let f = DataFrame {
                packet,
                voltage_raw: 250,
                ..Default::default()
            }
            .encode();
            out[*at..*at + f.len()].copy_from_slice(&f);
            *at += f.len();
        }
    }

    fn hub(counters: core::ops::Range<u16>, out: &mut [u8], at: &mut usize) {
        for counter in counters {
            let mut frame = datalink::HubFrame::new(counter);
            for (c, slot) in frame.slots.iter_mut().enumerate() {
                *slot = Some(DataFrame {
                    packet: 1000 + counter * 8 + c as u16,
                    ..Default::default()
                });
            }
            let f = frame.encode();
            out[*at..*at + f.len()].copy_from_slice(&f);
            *at += f.len();
        }
    }

    /// The searches that stop at hub candidates (the first look after noise and whole
    /// windows) find and count what a search one candidate at a time finds, over phases of
    /// plain noise (with a hub candidate now and then), of noise full of sync bytes, fake ESC
    /// headers and hub candidates, and of plain noise again, with runs of up to 200 bytes
    /// (past a window), ESC data and info frames and hub frames, whole, cut short or with one
    /// bit flipped.
    #[test]
    fn the_searches_after_noise_find_and_count_as_one_candidate_at_a_time() {
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let info = foc::InfoFrame::new("XR_FOC_ESC", "HW577", "01.0.00", "12345678");
        let info = info.map(|i| i.encode()).unwrap_or([0; 77]);
        let mut wire = [0u8; 160_000];
        let mut n = 0;
        let put = |wire: &mut [u8], n: &mut usize, bytes: &[u8]| {
            wire[*n..*n + bytes.len()].copy_from_slice(bytes);
            *n += bytes.len();
        };
        let (mut packet, mut counter) = (0u16, 0u16);
        for phase in 0..6 {
            let hostile = phase % 2 == 1;
            for _ in 0..250 {
                let r = next();
                if r % 3 == 0 {
                    let len = (next() % if r % 7 == 0 { 200 } else { 64 }) as usize + 1;
                    for _ in 0..len {
                        let b = next();
                        let token: Option<&[u8]> = match (hostile, b % 14) {
                            (true, 0) => Some(&[0x9B]),
                            (true, 1) => Some(&[0x9B, 0x16]),
                            (true, 2) => Some(&[0x9B, 0x16, 0x01, 0x02]),
                            (true, 3) => Some(&[0x9B, 0x4C]),
                            (true, 4) => Some(&[0x9B, 0x9E]),
                            (true, 5) => Some(&[0x9B, 0xA0]),
                            // Now and then a hub candidate in plain noise too, where the
                            // first look must stop.
                            (false, 6) if (b >> 20) % 4 == 0 => Some(&[0x9B, 0x9E]),
                            _ => None,
                        };
                        match token {
                            Some(t) => put(&mut wire, &mut n, t),
                            None => put(&mut wire, &mut n, &[(b >> 8) as u8]),
                        }
                    }
                }
                let mut frame = [0u8; FRAME_LEN];
                let len = match next() % 10 {
                    0..7 => {
                        packet = packet.wrapping_add(1);
                        esc(packet..packet + 1, &mut frame, &mut 0);
                        24
                    }
                    7 => {
                        frame[..77].copy_from_slice(&info);
                        77
                    }
                    _ => {
                        counter = counter.wrapping_add(1);
                        hub(counter..counter + 1, &mut frame, &mut 0);
                        FRAME_LEN
                    }
                };
                match next() % 25 {
                    0 => frame[(next() as usize) % len] ^= 1 << (next() % 8),
                    1 => {
                        let keep = (next() as usize) % (len - 1) + 1;
                        put(&mut wire, &mut n, &frame[..keep]);
                        continue;
                    }
                    _ => {}
                }
                put(&mut wire, &mut n, &frame[..len]);
            }
        }
        let wire = &wire[..n];
        let mut one_at_a_time = Stats::new();
        scan::Stats::add_bytes(&mut one_at_a_time, wire.len());
        let mut it = frames(wire);
        let (mut pos, mut found, mut hubs) = (0, 0, 0);
        while let Some((at, frame)) = by_candidates(wire, &mut pos, &mut one_at_a_time, true) {
            let frame = frame.at(at as u64);
            assert_eq!(it.next(), Some(frame), "frame {found}");
            found += 1;
            hubs += usize::from(matches!(frame, Decoded::Hub(_)));
        }
        assert_eq!(it.next(), None);
        assert_eq!(*it.stats(), one_at_a_time);
        let s = one_at_a_time;
        assert!(
            found > 1000 && hubs > 200,
            "{found} frames, {hubs} hub frames"
        );
        let failures = (s.esc.checksum_failures(), s.hub.checksum_failures());
        assert!(failures.0 > 300 && failures.1 > 20, "{failures:?}");
    }

    #[test]
    fn find_header_matches_a_plain_search() {
        let near = [0x16, 0x4C, 0x9E, 0xA0, 0x9F, 0x17];
        crate::foc::decoder::tests::assert_matches_a_plain_search(
            find_header,
            &[0x16, 0x4C, 0x9E, 0xA0],
            near,
        );
    }

    /// Streams that change protocol, with a frame of each cut short where it changes and a
    /// lone sync byte: every intact frame of both is found, in byte order, whatever the
    /// chunking, and no byte of a frame of one protocol counts as skipped or as a failed
    /// candidate of the other.
    #[test]
    fn every_frame_of_both_protocols_whatever_the_chunking() {
        let mut wire = [0u8; 12_000];
        let mut n = 0;
        hub(0..3, &mut wire, &mut n);
        // The first 100 bytes of a hub frame: a CRC failure once 160 bytes are there.
        let mut cut = [0u8; FRAME_LEN];
        hub(99..100, &mut cut, &mut 0);
        wire[n..n + 100].copy_from_slice(&cut[..100]);
        n += 100;
        esc(0..40, &mut wire, &mut n);
        wire[n] = 0x9B; // a lone sync byte
        n += 1;
        // The first 10 bytes of an ESC frame: a checksum failure.
        esc(500..501, &mut wire, &mut n);
        n -= 14;
        hub(3..6, &mut wire, &mut n);
        esc(40..80, &mut wire, &mut n);
        let wire = &wire[..n];
        let (mut escs, mut hubs) = (0, 0);
        let bulk: usize = frames(wire)
            .map(|d| match d {
                Decoded::Esc(_) => escs += 1,
                Decoded::Hub(_) => hubs += 1,
            })
            .count();
        assert_eq!((bulk, escs, hubs), (86, 80, 6));
        for chunk in [1, 2, 3, 5, 24, 77, 159, 160, 161, 1000, n] {
            let mut d = Decoder::new();
            let mut offsets = [0u64; 86];
            let mut k = 0;
            for c in wire.chunks(chunk) {
                d.feed(c, |f| {
                    offsets[k] = f.offset();
                    k += 1;
                });
            }
            d.flush(|f| {
                offsets[k] = f.offset();
                k += 1;
            });
            assert_eq!(k, 86, "chunk {chunk}");
            assert!(offsets.windows(2).all(|w| w[0] < w[1]), "byte order");
            let s = d.stats();
            assert_eq!((s.esc.bytes_skipped(), s.hub.bytes_skipped()), (111, 111));
            assert_eq!((s.esc.checksum_failures(), s.esc.lost_packets()), (1, 0));
            assert_eq!((s.hub.checksum_failures(), s.hub.bad_headers()), (1, 0));
            assert_eq!((s.esc.packets().count(), s.hub.frames()), (80, 6));
            assert_eq!(s.hub.lost_packets(), 0);
        }
        // Each protocol's own decoder sees only its own frames in the same bytes.
        let mut own = foc::Decoder::new();
        let mut n_esc = 0;
        own.decode_all(wire, |_| n_esc += 1);
        let mut own_hub = datalink::Decoder::new();
        let mut n_hub = 0;
        own_hub.decode_all(wire, |_| n_hub += 1);
        assert_eq!((n_esc, n_hub), (80, 6));
    }
}
