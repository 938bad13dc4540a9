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
//!
//! How it looks for the next frame after one it took: first a frame of the first kind right
//! there (back-to-back frames), then of any kind; else, while a window of 64 positions and a
//! whole frame's bytes are left, a frame at one of the first sync bytes of the window (after a
//! run of line noise, the usual place: one compare per 16 positions finds them), while that has
//! been right lately ([`Guess`]); else [`crate::foc::window`] finds every candidate and header
//! of the window at once, and the first header whose frame verifies is taken, every candidate
//! before it counted rejected (so line noise and fake headers cost no branch each); near the end
//! of the bytes, a word-at-a-time search for the next candidate decides them one by one, as a
//! [`Decoder`] must when a candidate may still be arriving. Every way counts the same.
//!
//! The bulk scanner (`scan_all`: [`frames`]' `fold`, `for_each` and `sum`, and every
//! [`Decoder::feed`](StreamDecoder::feed)) goes further after a run of line noise: it follows
//! [`crate::foc::follow`]'s candidate maps, from each frame straight to the next candidate,
//! while the noise lasts and holds few fake headers.
//!
//! The scanner names no frame kind: it asks the list of kinds in [`crate::foc::frame`] whether a
//! frame starts at a candidate, and how long a candidate with a given length byte is. Those calls
//! are inlined with every kind's constants: no dynamic dispatch, no function pointer, and no loop
//! over the kinds is left in the scanner.

#[cfg(target_arch = "x86_64")]
use crate::foc::follow::{Follow, follow_maps};
use crate::foc::frame::{FocFrame, MAX_FRAME_LEN, candidate_len, or_length_bytes, wire_len_of};
use crate::foc::stats::Stats;
use crate::foc::window::{WINDOW, WINDOW_BYTES, Window, syncs, window};
use crate::scan::{self, Candidate, Scan, StreamDecoder};
use crate::wire::SYNC;

/// A frame and where it started in the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Decoded {
    /// Offset of the frame's first byte, counting every byte given to the decoder since it was
    /// created (or, for [`frames`], from the start of the slice).
    pub offset: u64,
    /// The frame.
    pub frame: FocFrame,
}

/// Whether `b` is the length byte of a known frame kind.
#[inline(always)]
pub(crate) fn is_length_byte(b: u8) -> bool {
    wire_len_of(b).is_some()
}

/// Offset of the first place in `hay` where a frame may start: a sync byte followed by a known
/// length byte, or a sync byte that is the last byte of `hay` (undecided until more bytes come).
///
/// A sync byte followed by any other byte can never start a frame, so the scanner passes over it
/// like any other skipped byte, without stopping there.
#[inline]
fn find_header(hay: &[u8]) -> Option<usize> {
    find_sync_then(hay, is_length_byte, |l| {
        or_length_bytes(|b| bytes_equal(l, b))
    })
}

/// 0x80 in every byte of `word` that equals `b`, 0 elsewhere (exact: no carry crosses bytes).
#[inline(always)]
pub(crate) fn bytes_equal(word: u64, b: u8) -> u64 {
    const LOW7: u64 = 0x7F7F_7F7F_7F7F_7F7F;
    const ONES: u64 = 0x0101_0101_0101_0101;
    let x = word ^ (ONES * b as u64);
    !(((x & LOW7).wrapping_add(LOW7)) | x | LOW7)
}

/// Offset of the first sync byte in `hay` followed by a byte that `is_second` accepts, or of a
/// sync byte that is the last byte of `hay`: where a scanner's candidate may start.
/// `seconds(word)` is `is_second` on the eight bytes of a word at once (0x80 in each accepted
/// byte, 0 elsewhere, as [`bytes_equal`] gives), a constant expression after inlining.
///
/// The scanner of [`crate::datalink`] shares it, with its own second bytes.
#[inline(always)]
pub(crate) fn find_sync_then(
    hay: &[u8],
    is_second: impl Fn(u8) -> bool,
    seconds: impl Fn(u64) -> u64,
) -> Option<usize> {
    // After a frame the next bytes are usually the next frame's header.
    if let [SYNC, l, ..] = *hay
        && is_second(l)
    {
        return Some(0);
    }
    let mut base = 0;
    // Eight positions at a time: the word at `base` for the sync bytes and the word one byte
    // later for the second bytes that follow them.
    while let Some(w) = hay.get(base..base + 9) {
        let word = |at: usize| u64::from_le_bytes(w[at..at + 8].try_into().unwrap_or([0; 8]));
        let (s, l) = (word(0), word(1));
        let hits = bytes_equal(s, SYNC) & seconds(l);
        if hits != 0 {
            return Some(base + (hits.trailing_zeros() / 8) as usize);
        }
        base += 8;
    }
    let tail = &hay[base..];
    (0..tail.len())
        .find(|&j| tail[j] == SYNC && tail.get(j + 1).is_none_or(|&l| is_second(l)))
        .map(|j| base + j)
}

/// The search for the next HW-FOC frame after a run of line noise, the byte at `*pos` known to
/// start none, as the scanners' `scan_next` run it (this module's; [`crate::mixed`]'s, whose
/// searches stop at DataLink's candidates): at one of the run's first sync bytes while `guess`
/// holds ([`take_after_noise`]), else a window at a time ([`search_windows`]), what they pass
/// over counted (candidates in `esc`, the bytes by `stats.skip`). Where it finds a frame, the
/// caller returns `Some(found)`, `found` made from the frame and its offset (`|f|`), with `*pos`
/// just after it. Otherwise `*pos` is where the search stopped (a stop, or too few bytes left
/// for a window and a frame), the bytes before it counted, and the caller goes on from there.
///
/// A macro, not a function: with the search as a function, however inlined, the compiler kept
/// the packet counter of the caller's loop over back-to-back frames out of registers in one
/// scanner or the other (+4.4 % instructions in the mixed scanner's noisy stream, −1.7 % in
/// HW-FOC's). Written out in each `scan_next`, it gives the code of the two copies it replaced.
macro_rules! search_after_noise {
    ($stops:ty, $data:ident, $pos:ident, $stats:ident, $guess:ident, esc: $esc:expr,
     found: |$f:ident| $found:expr) => {
        // A frame at one of the run's first sync bytes, while that is what the noise has been
        // giving.
        let guessed = $guess.holds();
        if guessed
            && let Some(looked) =
                $crate::foc::decoder::take_after_noise::<$stops>($data, $pos, $esc)
        {
            $guess.right();
            $esc.checksum_failures_n(looked.rejected);
            $stats.skip(looked.skipped);
            let $f = looked.found;
            return Some($found);
        }
        // Then whole windows, counted here from what the search found.
        let searched = $crate::foc::decoder::search_windows::<$stops>($data, *$pos);
        if searched.found {
            $guess.judged(!guessed && searched.rejected == 0);
        }
        $esc.checksum_failures_n(searched.rejected);
        $stats.skip(searched.skipped);
        *$pos += searched.skipped;
        if searched.found
            && let Some($f) = $crate::foc::FocFrame::take($data, $pos, $esc)
        {
            return Some($found);
        }
    };
}
pub(crate) use search_after_noise;

/// Finds the next frame in `data` from `*pos`, counting what it passes over in `stats`.
/// Unless `first_guess` is false (the caller has just tried it), it first tries a frame of the
/// first kind right at `*pos`. `guess` is the caller's, kept from one call to the next (see
/// [`Guess`]).
///
/// Returns the frame and its start offset, with `*pos` just after it. Returns `None` when no
/// further frame can be decided: `*pos` is then `data.len()`, or, unless `at_end`, the start of
/// a candidate frame that needs more bytes (nothing of it has been counted yet).
#[inline(always)]
fn scan_next(
    data: &[u8],
    pos: &mut usize,
    stats: &mut Stats,
    (at_end, first_guess): (bool, bool),
    guess: &mut Guess,
) -> Option<(usize, FocFrame)> {
    // Back-to-back frames, the usual case: a frame of the most frequent kind starts right here.
    if first_guess && let Some(found) = FocFrame::take_first(data, pos, stats) {
        return Some(found);
    }
    // A frame of any kind right here (a device-information frame among data frames).
    if let Some(found) = FocFrame::take(data, pos, stats) {
        return Some(found);
    }
    // After a run of line noise.
    search_after_noise!(NoStops, data, pos, stats, guess, esc: stats, found: |f| f);
    // The last bytes, one candidate at a time.
    loop {
        let Some(k) = find_header(&data[*pos..]) else {
            stats.skip(data.len() - *pos);
            *pos = data.len();
            return None;
        };
        stats.skip(k);
        let i = *pos + k;
        *pos = i;
        match take_candidate(data, pos, stats, at_end) {
            Candidate::Frame(found) => return Some(found),
            Candidate::Undecided => return None,
            Candidate::Rejected => {}
        }
        stats.skip(1);
        *pos = i + 1;
    }
}

/// Whether the frame after a run of line noise starts at one of the run's first sync bytes:
/// a 2-bit counter kept by the caller of [`scan_next`] from one call to the next.
///
/// In line noise a sync byte comes once in 256 bytes, so the next frame usually starts at the
/// run's first or second, and [`take_after_noise`] finds it with one compare per 16 positions
/// and no search; in noise full of sync bytes (fake headers), it hardly ever does, and trying
/// would only add to each search. So it is tried while it has been right more often than not
/// lately: right counts up, wrong (tried and failed, or not tried and the search found the
/// frame after a candidate, as fake headers make it) counts down. It changes what is looked at
/// first, never what is found or counted.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Guess(u8);

impl Guess {
    /// A guess that holds, as at the start of a stream.
    pub(crate) const NEW: Guess = Guess(3);

    #[inline(always)]
    pub(crate) fn holds(self) -> bool {
        self.0 >= 2
    }

    /// The counter after a right guess.
    #[inline(always)]
    fn up(self) -> u8 {
        (self.0 + 1).min(3)
    }

    #[inline(always)]
    pub(crate) fn right(&mut self) {
        self.0 = self.up();
    }

    /// Right or wrong, without a branch.
    #[inline(always)]
    pub(crate) fn judged(&mut self, right: bool) {
        let down = self.0.saturating_sub(1);
        self.0 = if right { self.up() } else { down };
    }
}

/// Sync bytes [`take_after_noise`] tries a frame at.
const TRIES: usize = 2;

/// Where the searches after noise stop undecided: a sync byte followed by one of
/// [`Stops::SECONDS`], another protocol's candidate, which a scanner reading both protocols
/// decides itself ([`crate::mixed`]: DataLink's). The HW-FOC scanner has none ([`NoStops`]),
/// and then nothing of them is computed.
pub(crate) trait Stops {
    /// The second bytes of the other protocol's candidates.
    const SECONDS: &'static [u8];

    /// Whether a sync byte followed by `second` is a stop.
    #[inline(always)]
    fn at(second: u8) -> bool {
        Self::SECONDS.contains(&second)
    }
}

/// No stops: the HW-FOC scanner's searches.
pub(crate) struct NoStops;

impl Stops for NoStops {
    const SECONDS: &'static [u8] = &[];
}

/// What [`take_after_noise`] found.
pub(crate) struct Looked {
    /// Bytes passed over before the frame.
    pub(crate) skipped: usize,
    /// Candidates among them, each a checksum failure.
    pub(crate) rejected: u32,
    /// The frame and its start offset.
    pub(crate) found: (usize, FocFrame),
}

/// The frame at one of the first [`TRIES`] sync bytes after `*pos` within the next 64
/// positions (or just after them, when they hold fewer), taken and counted as
/// [`FocFrame::take`] does, `*pos` just after it. What it passed over is the caller's to
/// count ([`Looked`]). The byte at `*pos` is known to start no frame, and to be no stop.
/// `None`, with nothing counted and `*pos` unmoved, when there is no such frame,
/// or a stop comes first, or fewer than a window and a frame's bytes are left, or the target
/// has no vector unit [`crate::foc::window`] uses.
#[inline(always)]
pub(crate) fn take_after_noise<S: Stops>(
    data: &[u8],
    pos: &mut usize,
    stats: &mut Stats,
) -> Option<Looked> {
    let w = data.get(*pos..*pos + WINDOW + MAX_FRAME_LEN)?;
    let mut syncs = syncs(w.first_chunk::<WINDOW>()?)?;
    // Every position of the window and the frame after it are in `data`.
    let mut rejected = 0;
    if syncs & 1 != 0 {
        rejected += u32::from(is_length_byte(w[1]));
        syncs &= !1;
    }
    for _ in 0..TRIES {
        let k = syncs.trailing_zeros() as usize;
        let mut at = *pos + k;
        if let Some(found) = FocFrame::take(data, &mut at, stats) {
            *pos = at;
            return Some(Looked {
                skipped: k,
                rejected,
                found,
            });
        }
        if k == WINDOW || S::at(w[k + 1]) {
            return None;
        }
        rejected += u32::from(is_length_byte(w[k + 1]));
        syncs &= syncs - 1;
    }
    None
}

/// What [`search_windows`] found.
pub(crate) struct Searched {
    /// Bytes passed over, to the frame found, the first stop or the end of the last window.
    pub(crate) skipped: usize,
    /// Candidates among them, each a checksum failure.
    pub(crate) rejected: u32,
    /// Whether a frame starts after the bytes passed over (if not, a stop may: the caller
    /// decides what is there).
    pub(crate) found: bool,
}

/// Searches `data` from `from` a window at a time, where the target has one
/// ([`crate::foc::window`]), while a whole frame's bytes follow the window's last position:
/// then every candidate in it is complete, and its candidates are decided together, the first
/// header that verifies a frame, every candidate before it rejected. It stops at the first
/// stop ([`Stops`]) that comes before such a frame, every candidate before it rejected.
///
/// Out of line, and it counts nothing itself (no statistics pass through it): the loop over
/// back-to-back frames that calls it keeps its counts in registers.
#[inline(never)]
pub(crate) fn search_windows<S: Stops>(data: &[u8], from: usize) -> Searched {
    let mut searched = Searched {
        skipped: 0,
        rejected: 0,
        found: false,
    };
    loop {
        let start = from + searched.skipped;
        let Some(w) = data
            .get(start..start + WINDOW + MAX_FRAME_LEN)
            .and_then(|w| w.first_chunk::<WINDOW_BYTES>())
        else {
            return searched;
        };
        let Some(Window {
            candidates,
            mut headers,
            stops,
        }) = window(w, S::SECONDS)
        else {
            return searched;
        };
        // Only the headers before the first stop are this search's to decide (with no stops,
        // all of them).
        let before_stop = (stops & stops.wrapping_neg()).wrapping_sub(1);
        headers &= before_stop;
        while headers != 0 {
            let k = headers.trailing_zeros() as usize;
            if FocFrame::verifies(data, start + k) {
                let before = candidates & ((1 << k) - 1);
                searched.rejected = searched.rejected.saturating_add(before.count_ones());
                searched.skipped += k;
                searched.found = true;
                return searched;
            }
            headers &= headers - 1;
        }
        if stops != 0 {
            let before = candidates & before_stop;
            searched.rejected = searched.rejected.saturating_add(before.count_ones());
            searched.skipped += stops.trailing_zeros() as usize;
            return searched;
        }
        searched.rejected = searched.rejected.saturating_add(candidates.count_ones());
        searched.skipped += WINDOW;
    }
}

/// Decides the candidate at `*pos` (a sync byte and a known length byte, or a sync byte that
/// ends `data`): a frame is counted and taken, `*pos` just after it; a candidate whose bytes
/// are all there and that is no frame is a checksum failure. Nothing is skipped here, and
/// `*pos` moves only past a frame.
#[inline(always)]
pub(crate) fn take_candidate(
    data: &[u8],
    pos: &mut usize,
    stats: &mut Stats,
    at_end: bool,
) -> Candidate<(usize, FocFrame)> {
    let i = *pos;
    // Each kind decides "valid frame of mine" with as few, as predictable, branches as it can
    // (false all through line noise, true all through a run of frames).
    if let Some(found) = FocFrame::take(data, pos, stats) {
        return Candidate::Frame(found);
    }
    let rest = &data[i..];
    debug_assert!(
        rest.len() == 1 || is_length_byte(rest[1]),
        "find_header's contract"
    );
    // Rejected, or undecided: a candidate is rejected once all its bytes are there. With
    // MAX_FRAME_LEN bytes they are, whatever its length byte, which is then not even read
    // (in line noise, which length byte a fake header carries is unpredictable). Short of
    // that, its length byte (a known one: `find_header` stops at no other) tells.
    let complete = rest.len() >= MAX_FRAME_LEN || rest.len() >= candidate_len(rest);
    if complete {
        stats.checksum_failure();
        Candidate::Rejected
    } else if at_end {
        Candidate::Rejected
    } else {
        Candidate::Undecided
    }
}

/// The HW-FOC scanner, as the streaming layer ([`crate::scan`]) runs it: [`Decoder`] and
/// [`Frames`] are it under [`StreamDecoder`] and [`Scan`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Scanner;

impl crate::scan::sealed::Sealed for Scanner {}
impl crate::scan::sealed::Sealed for Stats {}

impl scan::Stats for Stats {
    const NEW: Self = Stats::new();

    #[inline]
    fn bytes(&self) -> u64 {
        Stats::bytes(self)
    }

    #[inline]
    fn add_bytes(&mut self, n: usize) {
        Stats::add_bytes(self, n);
    }

    fn line_silent(&mut self, max_frames: u32) {
        Stats::line_silent(self, max_frames);
    }

    #[inline]
    fn skip_bytes(&mut self, n: usize) {
        self.skip(n);
    }

    fn then(&mut self, later: &Self, first_packet: Option<u16>) -> bool {
        Stats::then(self, later, first_packet)
    }
}

impl scan::Scanner for Scanner {
    type Item = Decoded;
    type Stats = Stats;
    type Held = [u8; MAX_FRAME_LEN - 1];
    type Pair = [u8; 2 * MAX_FRAME_LEN];
    const HELD: Self::Held = [0; MAX_FRAME_LEN - 1];
    const PAIR: Self::Pair = [0; 2 * MAX_FRAME_LEN];
    const MAX_LEN: usize = MAX_FRAME_LEN;

    #[inline(always)]
    fn candidate_len(held: &[u8]) -> usize {
        candidate_len(held)
    }

    /// Runs the scanner over `data`, whose first byte is at stream offset `base`, giving every
    /// frame to `on_frame`; returns where it stopped (as the scanner's `scan_next` leaves `pos`).
    ///
    /// Out of line, so that [`StreamDecoder::feed`] (which scans its held candidate, then the
    /// new bytes) and [`StreamDecoder::flush`] each have one copy of the scanner, not one per
    /// loop: a fixed layout, whose speed does not hang on the compiler's inlining choices.
    #[inline(never)]
    fn scan_all<const AT_END: bool>(
        data: &[u8],
        base: u64,
        stats: &mut Stats,
        on_frame: &mut impl FnMut(Decoded),
    ) -> usize {
        let mut pos = 0;
        let mut guess = Guess::NEW;
        #[cfg(target_arch = "x86_64")]
        let mut follow = Follow::NEW;
        loop {
            // Back-to-back frames of the first kind have a call site of their own, where the frame
            // built is known to be of that kind: only its fields are written, not the bytes of the
            // largest kind that a merged call site would copy for every frame.
            while let Some((at, frame)) = FocFrame::take_first(data, &mut pos, stats) {
                on_frame(Decoded {
                    offset: base + at as u64,
                    frame,
                });
            }
            let (before, failures) = (pos, stats.checksum_failures());
            let Some((at, frame)) = scan_next(data, &mut pos, stats, (AT_END, false), &mut guess)
            else {
                return pos;
            };
            on_frame(Decoded {
                offset: base + at as u64,
                frame,
            });
            // After line noise (bytes passed over, no candidate among them: fake headers are
            // better decided by the search windows), follow the candidate maps while it lasts,
            // unless following has lately met too many rejected candidates (x86_64 only).
            #[cfg(target_arch = "x86_64")]
            if !follow.waits() && at != before && stats.checksum_failures() == failures {
                let on_frame = &mut *on_frame;
                follow_maps(data, &mut pos, stats, &mut follow, &mut move |at, frame| {
                    on_frame(Decoded {
                        offset: base + at as u64,
                        frame,
                    });
                });
            }
            #[cfg(not(target_arch = "x86_64"))]
            let _ = (before, failures);
        }
    }

    #[inline(always)]
    fn scan_next(data: &[u8], pos: &mut usize, stats: &mut Stats) -> Option<Decoded> {
        // One frame at a time (a byte pushed, a held candidate): no noise to learn from.
        let mut guess = Guess::NEW;
        scan_next(data, pos, stats, (true, true), &mut guess).map(|(at, frame)| Decoded {
            offset: at as u64,
            frame,
        })
    }
}

/// A streaming decoder of the ESC wire: feed it bytes in any chunking, get every frame once
/// (the streaming layer's [`StreamDecoder`] over the HW-FOC scanner).
///
/// Its whole state is a 76-byte buffer for a frame still arriving plus the [`Stats`]:
/// 124 bytes (`size_of::<Decoder>()`, checked by a test), no allocation, no timing.
/// Large chunks are scanned in place (the bulk path); only the unfinished tail is copied. One
/// byte pushed completes at most three frames (when a rejected device-information candidate
/// turns out to hold data frames).
///
/// ```
/// use hwfoc::foc::{DataFrame, Decoder, FocFrame};
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
/// assert_eq!(got[0].frame, FocFrame::Data(frame));
/// assert_eq!(decoder.stats().bytes_skipped(), 3);
/// ```
///
/// # Silences
///
/// [`line_silent`](StreamDecoder::line_silent)`(max_frames, ..)` tells the decoder that the
/// line has just been silent for a time in which at most `max_frames` data frames could have
/// been sent. The held bytes are decided at once, and the next data frame (the first one after
/// the silence, whatever its bytes' chunking) counts as a loss of `step - 1` packets only if
/// its packet-number step is from 2 to `max_frames + 1`; a larger step is a
/// [restart](Stats::restarts). A step of 0 is still a duplicate and 1 the next frame. The
/// rule replaces the [`MAX_PACKET_GAP`](crate::counters::MAX_PACKET_GAP) rule for that one frame,
/// then the default returns. Several calls before that frame add up (their silences could each
/// have hidden frames); a step beyond 32768 is a step backwards, a restart whatever
/// `max_frames` says. Before the first data frame there is no step, and the call only decides
/// the held bytes.
///
/// So an ESC that rebooted within a second and a half is seen restarting even when its new
/// packet number happens to lie a few hundred past the old one, while a frame lost in a short
/// silence is still a loss. `max_frames` is the caller's bound from the time that passed: a
/// data frame takes 24 byte times on the line (12.5 ms at 19200 baud), and a real ESC sends one
/// every 50 ms or more. Frames hidden in bytes that arrived but were rejected (corrupted) are
/// not the silence's: do not count them in `max_frames`. Host-side read latency is not a
/// silence of the line; call it only for gaps longer than the receiving path can introduce.
///
/// ```
/// use hwfoc::foc::BAUD_RATE;
/// use hwfoc::wire::byte_ns;
/// use hwfoc::foc::{DataFrame, Decoder};
///
/// let frame = |packet| DataFrame { packet, ..Default::default() }.encode();
/// let mut decoder = Decoder::new();
/// decoder.feed(&frame(65000), |_| {});
/// // 1.5 s without a byte: at most 1.5 s / 24 byte times = 120 frames could have been sent.
/// let max_frames = (1.5e9 / (24.0 * byte_ns(BAUD_RATE))) as u32;
/// assert_eq!(max_frames, 120);
/// decoder.line_silent(max_frames, |_| {});
/// decoder.feed(&frame(0), |_| {}); // a step of 536: the ESC restarted
/// decoder.feed(&frame(3), |_| {}); // no silence: 2 frames lost
/// assert_eq!(decoder.stats().restarts(), 1);
/// assert_eq!(decoder.stats().lost_packets(), 2);
/// ```
pub type Decoder = StreamDecoder<Scanner>;

/// Decodes every frame in a complete buffer, in place: the bulk path.
///
/// The iterator borrows the slice and allocates nothing; a frame cut off by the end of the
/// slice is skipped. It yields exactly what a [`Decoder`] fed the same bytes and then flushed
/// would, with the same statistics.
///
/// ```
/// use hwfoc::foc::{DataFrame, FocFrame, frames};
///
/// let mut wire = Vec::new();
/// for packet in 0..3u16 {
///     wire.extend_from_slice(&DataFrame { packet, ..Default::default() }.encode());
/// }
/// wire[30] ^= 0x04; // corrupt the second frame
/// let mut it = frames(&wire);
/// let packets: Vec<u16> = it
///     .by_ref()
///     .filter_map(|d| match d.frame { FocFrame::Data(f) => Some(f.packet), _ => None })
///     .collect();
/// assert_eq!(packets, [0, 2]);
/// assert_eq!(it.stats().checksum_failures(), 1);
/// assert_eq!(it.stats().lost_packets(), 1);
/// ```
pub fn frames(data: &[u8]) -> Frames<'_> {
    Scan::new(data)
}

/// Iterator returned by [`frames`].
pub type Frames<'a> = Scan<'a, Scanner>;

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::foc::DataFrame;

    /// Asserts that `find_header` (a scanner's word-at-a-time search for a sync byte followed
    /// by one of `seconds`) finds what a plain byte-by-byte search finds, over 20 000 random
    /// slices dense in sync bytes and in `near` (the accepted second bytes and their
    /// neighbours), at every alignment.
    pub(crate) fn assert_matches_a_plain_search(
        find_header: fn(&[u8]) -> Option<usize>,
        seconds: &[u8],
        near: [u8; 6],
    ) {
        let plain = |h: &[u8]| {
            (0..h.len()).find(|&j| h[j] == SYNC && h.get(j + 1).is_none_or(|l| seconds.contains(l)))
        };
        let mut x = 0x1234_5678_9abc_def0u64;
        let mut hay = [0u8; 150];
        for round in 0..20_000 {
            let density = round % 7;
            for b in hay.iter_mut() {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                *b = match (x >> 60) as usize % (density + 2) {
                    0 => SYNC,
                    1 => near[(x >> 8) as usize % 6],
                    _ => x as u8,
                };
            }
            let len = (x >> 16) as usize % (hay.len() + 1);
            for start in [0, 1, 5, 31, 33].into_iter().filter(|&s| s <= len) {
                let h = &hay[start..len];
                assert_eq!(find_header(h), plain(h), "{h:02X?}");
            }
        }
    }

    #[test]
    fn find_header_matches_a_plain_search() {
        let near = [0x16, 0x4C, 0x9A, 0x9C, 0x15, 0x17];
        assert_matches_a_plain_search(find_header, &[0x16, 0x4C], near);
    }

    /// A candidate is tried only as the kind whose whole header it carries: one with the data
    /// frame's length byte but another command, its sum sealed as a data frame's, is rejected
    /// (and costs one byte), and the frames after it are found.
    #[test]
    fn a_candidate_is_tried_as_the_kind_of_its_whole_header() {
        use crate::foc::InfoFrame;
        use crate::wire::Checksum;
        let data = DataFrame::default().encode();
        let mut fake = data;
        fake[3] = 0x01; // the info frame's command after the data frame's length byte
        Checksum::Sum16Le.seal(&mut fake);
        let info = InfoFrame::new("XR_FOC_ESC", "", "", "").map(|i| i.encode());
        let info = info.unwrap_or([0; 77]);
        let mut wire = [0u8; 24 + 77 + 24];
        wire[..24].copy_from_slice(&fake);
        wire[24..24 + 77].copy_from_slice(&info);
        wire[24 + 77..].copy_from_slice(&data);
        let mut it = frames(&wire);
        let mut offsets = [0u64; 3];
        let found = it
            .by_ref()
            .zip(&mut offsets)
            .map(|(d, o)| *o = d.offset)
            .count();
        assert_eq!(&offsets[..found], [24, 24 + 77]);
        assert_eq!(it.stats().checksum_failures(), 1);
        assert_eq!(it.stats().bytes_skipped(), 24);
    }

    #[test]
    fn state_is_under_128_bytes() {
        assert_eq!(core::mem::size_of::<Decoder>(), 124);
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
