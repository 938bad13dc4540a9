//! Streams of any Hobbywing serial format, told from their bytes: the [`Decoder`] reads every
//! serial format of the format list (HW-FOC and DataLink V2 in one family, [`mixed`], and each
//! other serial format in a family of its own: [`Family`]) and locks onto the format it finds.
//!
//! Until it has locked, every format's decoder is given every byte, in slices of [`SLICE`]
//! bytes that start at multiples of [`SLICE`] in the stream; at the end of a slice in which
//! one or more of them found a frame, it locks onto the first of those in their rank in the
//! format list ([`Family::ALL`]: checksummed formats before the chained ones). Locked, it gives the
//! bytes to that format's decoder only, so a stream of one format is read at that decoder's
//! speed. After a silence of the line ([`Decoder::line_silent_each`]), and at the end of a
//! block of [`RELOCK_AFTER`] bytes (blocks start at its multiples in the stream) in which the
//! locked format's decoder handed on no frame, it reads every format again (a stream may change format: an adapter moved from one ESC to another). The
//! other formats' decoders then first read the bytes after the locked decoder's last frame,
//! kept while locked ([`HISTORY`]), as they do at a silence and at the end of the stream: the
//! frames of a new format in them are handed on then (late, never lost), and the decoder locks
//! onto it at once. A decoder that was not given some bytes before those passes over them
//! ([`StreamDecoder::pass_over`](crate::StreamDecoder::pass_over)): they are its skipped bytes, so every decoder's offsets and
//! statistics are the stream's.
//!
//! The frames, each format's in the same order, and where it locks, are the same however the
//! stream is cut into chunks: slices and blocks are counted from the stream's start. Frames of two formats found in one slice while detecting come out
//! format by format within each chunk given (the formats' decoders read a chunk one after the
//! other), so how they interleave depends on the chunking: a chunk holding the whole slice
//! gives them format by format, bytes given one at a time give them in the order they were
//! decided. HW-FOC and DataLink frames always come in byte order ([`mixed`]).
//!
//! How soon it locks: on the first checksummed frame (an HW-FOC or HW5 frame), on a chain of
//! a chained format's frames (as its module says), each within a slice more.
//!
//! ```
//! use hwfoc::detect::{Decoder, Decoded, Family};
//! use hwfoc::hw5;
//!
//! let wire: Vec<u8> = (0..5).flat_map(|_| hw5::TelemetryFrame::default().encode()).collect();
//! let mut decoder = Decoder::new();
//! let mut found = Vec::new();
//! decoder.decode_all(&wire, |d| found.push(d));
//! assert_eq!(found.len(), 5);
//! assert!(matches!(found[0], Decoded::Hw5(_)));
//! assert_eq!(decoder.locked(), Some(Family::Hw5));
//! assert_eq!(decoder.stats::<hw5::Scanner>().telemetry_frames(), 5);
//! ```

use crate::family::{Emit, FamilyLink, LinkFigures};
use crate::protocol::{FamilyScanner, FoundFrame};
use crate::scan::{self, Scanner, StreamDecoder};
use crate::{Protocol, mixed};

/// Bytes per slice while detecting (see the module documentation).
pub const SLICE: u64 = 64;

/// The blocks of the stream, at multiples of this many bytes, at whose end every format is read
/// again when the locked format's decoder handed on no frame in the block: more than any
/// format's frame and the gap between two of them on a working wire. (Blocks, not bytes since
/// the last frame: the frames' offsets need not be followed, so the decoder of a locked HW-FOC
/// stream runs as fast as [`mixed`]'s alone.) A new format is found at most two blocks and a
/// slice after the change.
pub const RELOCK_AFTER: u64 = 4096;

/// The bytes kept while locked: two blocks, more than lie between the locked decoder's last
/// frame and the end of the block at which every format is read again. Those after that
/// frame are read by every other format's decoder then, so a format that follows another
/// loses no frame. (8 KiB of each stream's decoder: the price of a change of format without
/// a silence.) Only the bytes after the locked decoder's last frame are copied into it, so on
/// a clean locked stream it costs a few bytes' copy per chunk.
pub const HISTORY: usize = 2 * RELOCK_AFTER as usize;

/// Declares [`Family`] and [`Decoded`] from the list of formats (`formats!` in `lib.rs`): one
/// arm for each format there with a `family`.
mod sealed {
    /// A family's scanner: where its decoder's statistics are in a [`super::Decoder`].
    pub trait Family: super::FamilyScanner {
        /// The statistics of this family's decoder in `decoder`.
        fn stats_in(decoder: &super::Decoder) -> &Self::Stats;
    }
}

/// `Some(Family::$family)`, or `None` for a format without a family of its own.
macro_rules! family_of {
    () => {
        None
    };
    ($family:ident) => {
        Some(Family::$family)
    };
}

macro_rules! declare_families {
    ($( $(#[$doc:meta])* $arm:ident => $description:path, $kind:ident $data:ty
        $(, info $info:ty)? $(, family $family:ident($scanner:ty) rank $rank:literal)?; )+) => {
        /// A format the decoder locks onto: HW-FOC and DataLink are read by one decoder
        /// ([`mixed`]), which tells them apart frame by frame.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Family {
            $($(
                #[doc = concat!("The format(s) read by [`", stringify!($scanner), "`].")]
                $family,
            )?)+
        }

        impl Family {
            /// Every family, in the order they are preferred when two find frames in one slice
            /// (their rank in the list of formats).
            pub const ALL: [Family; [$($(Family::$family,)?)+].len()] = {
                let mut ranked = [$($((Family::$family, $rank),)?)+];
                let mut i = 1;
                while i < ranked.len() {
                    let mut j = i;
                    while j > 0 && ranked[j - 1].1 > ranked[j].1 {
                        let t = ranked[j];
                        ranked[j] = ranked[j - 1];
                        ranked[j - 1] = t;
                        j -= 1;
                    }
                    i += 1;
                }
                let mut all = [ranked[0].0; [$($(Family::$family,)?)+].len()];
                let mut k = 0;
                while k < ranked.len() {
                    all[k] = ranked[k].0;
                    k += 1;
                }
                all
            };
        }

        /// A frame of any format, with its stream offset.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Decoded {
            $($(
                #[doc = concat!("A frame of [`Family::", stringify!($family), "`].")]
                $family(<$scanner as Scanner>::Item),
            )?)+
        }

        impl Decoded {
            /// Offset of the frame's first byte in the stream.
            pub fn offset(&self) -> u64 {
                match self {
                    $($( Decoded::$family(d) => FoundFrame::offset(d), )?)+
                }
            }

            /// The protocol the frame came in.
            pub fn protocol(&self) -> Protocol {
                match self {
                    $($( Decoded::$family(d) => FoundFrame::protocol(d), )?)+
                }
            }

            /// The family of its format.
            pub fn family(&self) -> Family {
                match self {
                    $($( Decoded::$family(_) => Family::$family, )?)+
                }
            }
        }

        impl Family {
            /// The family a format's own line of the format list declares: HW-FOC's is
            /// [`Family::Mixed`] (which reads DataLink too); `None` for DataLink and the CAN
            /// formats.
            pub fn of(protocol: Protocol) -> Option<Family> {
                match protocol {
                    $( Protocol::$arm => family_of!($($family)?), )+
                }
            }
        }

        impl Decoded {
            /// Hands the frame on as the ESC frames it holds ([`FamilyLink::hand_on`]):
            /// `emit(channel, offset, frame)`.
            pub fn hand_on(&self, emit: &mut Emit<'_>) {
                match self {
                    $($( Decoded::$family(d) => <$scanner as FamilyLink>::hand_on(d, emit), )?)+
                }
            }
        }

        /// One family's decoder alone, detecting nothing: a format read as the only one (a
        /// protocol forced), its frames as [`Decoded`] and its link's figures in neutral terms.
        #[derive(Debug, Clone)]
        #[allow(clippy::large_enum_variant)]
        pub enum OneFamily {
            $($(
                #[doc = concat!("[`Family::", stringify!($family), "`]'s decoder.")]
                $family(StreamDecoder<$scanner>),
            )?)+
        }

        impl OneFamily {
            /// `family`'s decoder, nothing seen.
            pub fn new(family: Family) -> OneFamily {
                match family {
                    $($( Family::$family => OneFamily::$family(StreamDecoder::default()), )?)+
                }
            }

            /// Its family.
            pub fn family(&self) -> Family {
                match self {
                    $($( OneFamily::$family(_) => Family::$family, )?)+
                }
            }

            /// Feeds a chunk of bytes; `on_frame` gets each frame found.
            pub fn feed(&mut self, data: &[u8], on_frame: &mut dyn FnMut(Decoded)) {
                match self {
                    $($( OneFamily::$family(d) => d.feed(data, |f| on_frame(Decoded::$family(f))), )?)+
                }
            }

            /// The line was silent for a time in which at most `max_frames` of the family's
            /// frames could have been sent ([`StreamDecoder::line_silent`]).
            pub fn line_silent(&mut self, max_frames: u32, on_frame: &mut dyn FnMut(Decoded)) {
                match self {
                    $($( OneFamily::$family(d) => {
                        d.line_silent(max_frames, |f| on_frame(Decoded::$family(f)))
                    } )?)+
                }
            }

            /// Ends the stream, handing on what the held bytes still hold.
            pub fn flush(&mut self, on_frame: &mut dyn FnMut(Decoded)) {
                match self {
                    $($( OneFamily::$family(d) => d.flush(|f| on_frame(Decoded::$family(f))), )?)+
                }
            }

            /// Every byte given or passed over so far.
            pub fn bytes(&self) -> u64 {
                match self {
                    $($( OneFamily::$family(d) => scan::Stats::bytes(d.stats()), )?)+
                }
            }

            /// Bytes held for a frame still arriving.
            pub fn buffered(&self) -> usize {
                match self {
                    $($( OneFamily::$family(d) => d.buffered(), )?)+
                }
            }

            /// The link's figures ([`FamilyLink::figures`]).
            pub fn figures(&self) -> Option<LinkFigures> {
                match self {
                    $($( OneFamily::$family(d) => <$scanner as FamilyLink>::figures(d.stats()), )?)+
                }
            }
        }

        $($(
            impl sealed::Family for $scanner {
                fn stats_in(decoder: &Decoder) -> &<$scanner as Scanner>::Stats {
                    decoder.decoders.$family.stats()
                }
            }
        )?)+

        /// Each family's decoder, a field named as its family.
        #[allow(non_snake_case)]
        #[derive(Debug, Clone, Default)]
        struct Decoders {
            $($( $family: StreamDecoder<$scanner>, )?)+
        }

        impl Decoders {
            /// The link's figures of `family`'s decoder ([`FamilyLink::figures`]).
            fn figures(&self, family: Family) -> Option<LinkFigures> {
                match family {
                    $($( Family::$family => <$scanner as FamilyLink>::figures(self.$family.stats()), )?)+
                }
            }

            /// Bytes `family`'s decoder holds for a frame still arriving.
            fn buffered(&self, family: Family) -> usize {
                match family {
                    $($( Family::$family => self.$family.buffered(), )?)+
                }
            }

            /// Every byte `family`'s decoder was given or passed over.
            fn bytes(&self, family: Family) -> u64 {
                match family {
                    $($( Family::$family => scan::Stats::bytes(self.$family.stats()), )?)+
                }
            }

            /// The frames `family`'s decoder has handed on so far (data and information).
            fn handed_on(&self, family: Family) -> u64 {
                match family {
                    $($( Family::$family => {
                        <$scanner as FamilyScanner>::handed_on(self.$family.stats())
                    } )?)+
                }
            }

            /// `family`'s decoder passes over `n` bytes.
            fn pass_over(&mut self, family: Family, n: u64) {
                match family {
                    $($( Family::$family => self.$family.pass_over(n), )?)+
                }
            }

            /// Gives `family`'s decoder `piece`.
            fn feed(&mut self, family: Family, piece: &[u8], on_frame: &mut dyn FnMut(Decoded)) {
                match family {
                    $($( Family::$family => {
                        self.$family.feed(piece, |d| on_frame(Decoded::$family(d)))
                    } )?)+
                }
            }

            /// `family`'s decoder decides what it holds.
            fn flush(&mut self, family: Family, on_frame: &mut dyn FnMut(Decoded)) {
                match family {
                    $($( Family::$family => self.$family.flush(|d| on_frame(Decoded::$family(d))), )?)+
                }
            }

            /// Tells `family`'s decoder of a silence ([`FamilyScanner::line_silent`]).
            fn line_silent(
                &mut self,
                family: Family,
                esc_frames: u32,
                hub_frames: u32,
                on_frame: &mut dyn FnMut(Decoded),
            ) {
                match family {
                    $($( Family::$family => <$scanner as FamilyScanner>::line_silent(
                        &mut self.$family,
                        esc_frames,
                        hub_frames,
                        &mut |d| on_frame(Decoded::$family(d)),
                    ), )?)+
                }
            }

            /// Brings `family`'s decoder up to `to` ([`replay_into`]).
            fn replay(
                &mut self,
                family: Family,
                history: &History,
                from: u64,
                to: u64,
                on_frame: &mut dyn FnMut(Decoded),
            ) {
                match family {
                    $($( Family::$family => replay_into(
                        &mut self.$family,
                        history,
                        from,
                        to,
                        &mut |d| on_frame(Decoded::$family(d)),
                    ), )?)+
                }
            }
        }
    };
}

formats!(declare_families);

/// `on_frame`, noting in `found` the family of each frame while detecting (`all`): for the
/// frames a silence or the end of the stream settles.
fn noting<'a>(
    all: bool,
    found: &'a mut [Option<u64>; Family::ALL.len()],
    on_frame: &'a mut impl FnMut(Decoded),
) -> impl FnMut(Decoded) + 'a {
    move |d: Decoded| {
        if all {
            let i = Family::ALL.iter().position(|&f| f == d.family());
            found[i.unwrap_or(0)] = Some(d.offset());
        }
        on_frame(d)
    }
}

/// The stream's bytes after the locked decoder's last frame (at most the last [`HISTORY`]),
/// kept while locked so that the formats' decoders that were not given them read them when
/// detection starts again. A ring indexed by stream offset: bytes before that frame, never
/// read again, are not written.
#[derive(Clone)]
struct History([u8; HISTORY]);

impl Default for History {
    fn default() -> History {
        History([0; HISTORY])
    }
}

impl core::fmt::Debug for History {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "History({HISTORY} bytes)")
    }
}

impl History {
    /// Keeps `data`, the stream's bytes from offset `at`.
    #[inline(always)]
    fn keep(&mut self, at: u64, data: &[u8]) {
        let skip = data.len().saturating_sub(HISTORY);
        let (at, data) = (at + skip as u64, &data[skip..]);
        let start = (at % HISTORY as u64) as usize;
        let first = data.len().min(HISTORY - start);
        self.0[start..start + first].copy_from_slice(&data[..first]);
        self.0[..data.len() - first].copy_from_slice(&data[first..]);
    }

    /// The bytes of the stream from offset `from` to `to` (at most [`HISTORY`] bytes back from
    /// the last kept, `to`), in at most two slices.
    fn between(&self, from: u64, to: u64) -> (&[u8], &[u8]) {
        let n = (to - from) as usize;
        let start = (from % HISTORY as u64) as usize;
        let first = n.min(HISTORY - start);
        (&self.0[start..start + first], &self.0[..n - first])
    }
}

/// Brings `decoder`, if it is behind the stream's end `to`, up to it: it passes over the bytes
/// before `from` it was not given, then reads those from `from` on out of `history`.
fn replay_into<S: Scanner>(
    decoder: &mut StreamDecoder<S>,
    history: &History,
    from: u64,
    to: u64,
    on_frame: &mut dyn FnMut(S::Item),
) {
    let at = scan::Stats::bytes(decoder.stats());
    if at >= to {
        return;
    }
    if from > at {
        decoder.pass_over(from.min(to) - at);
    }
    let (a, b) = history.between(at.max(from).min(to), to);
    decoder.feed(a, &mut *on_frame);
    decoder.feed(b, &mut *on_frame);
}

/// A decoder of every Hobbywing serial format at once (see the module documentation).
#[derive(Debug, Clone, Default)]
pub struct Decoder {
    /// Each family's decoder.
    decoders: Decoders,
    /// Every byte given so far.
    bytes: u64,
    /// The format locked onto, if any.
    locked: Option<Family>,
    /// The format locked onto last (it stays when detection starts again, until another is).
    last_locked: Option<Family>,
    /// Locked: the locked decoder's frames handed on by the start of the current block, or
    /// `None` for the block it locked in (not judged: it is only partly locked).
    block_start: Option<u64>,
    /// Detecting: which families found a frame in the current slice, and the last one's offset.
    found: [Option<u64>; Family::ALL.len()],
    /// Locked: the offset of the locked decoder's last frame.
    last_frame: u64,
    /// The stream's last bytes (kept while locked).
    history: History,
}

impl Decoder {
    /// A decoder with nothing seen, detecting.
    pub fn new() -> Decoder {
        Decoder::default()
    }

    /// The format locked onto, if it is locked.
    pub fn locked(&self) -> Option<Family> {
        self.locked
    }

    /// The format it last locked onto (while it detects again too), if it ever locked.
    pub fn last_locked(&self) -> Option<Family> {
        self.last_locked
    }

    /// Every byte given so far.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Bytes held for a frame still arriving: the locked decoder's, or while detecting, the
    /// most any decoder holds.
    pub fn buffered(&self) -> usize {
        match self.locked {
            Some(family) => self.decoders.buffered(family),
            None => Family::ALL
                .iter()
                .map(|&f| self.decoders.buffered(f))
                .max()
                .unwrap_or(0),
        }
    }

    /// HW-FOC's and DataLink's statistics (of the bytes given to their decoder so far: all
    /// of them after [`Decoder::flush`]).
    pub fn mixed_stats(&self) -> &mixed::Stats {
        self.decoders.Mixed.stats()
    }

    /// The statistics of the family whose scanner is `S` (of the bytes given to its decoder so
    /// far: all of them after [`Decoder::flush`]): `decoder.stats::<hwfoc::v4::Scanner>()`.
    pub fn stats<S: sealed::Family>(&self) -> &S::Stats {
        S::stats_in(self)
    }

    /// The link's figures of the format it last locked onto, in neutral terms
    /// ([`FamilyLink::figures`]): `None` before any lock, and for HW-FOC and DataLink, whose
    /// figures are per channel ([`Decoder::mixed_stats`]).
    pub fn last_locked_figures(&self) -> Option<LinkFigures> {
        self.decoders.figures(self.last_locked?)
    }

    /// Feeds a chunk of bytes; `on_frame` gets each frame found.
    #[inline]
    pub fn feed(&mut self, mut data: &[u8], mut on_frame: impl FnMut(Decoded)) {
        while !data.is_empty() {
            let n = match self.locked {
                Some(family) => self.feed_locked(family, data, &mut on_frame),
                None => self.feed_detecting(data, &mut on_frame),
            };
            data = &data[n..];
        }
    }

    /// Gives the locked family's decoder the bytes of `data` to the end of the current block;
    /// at its end, reads every format again if the decoder handed on no frame in the block.
    /// Returns how many it took.
    #[inline(always)]
    fn feed_locked(
        &mut self,
        family: Family,
        data: &[u8],
        on_frame: &mut impl FnMut(Decoded),
    ) -> usize {
        let to_end = RELOCK_AFTER - self.bytes % RELOCK_AFTER;
        let n = usize::try_from(to_end).map_or(data.len(), |k| k.min(data.len()));
        let piece = &data[..n];
        let last = &mut self.last_frame;
        match family {
            Family::Mixed => self.decoders.Mixed.feed(
                piece,
                #[inline(always)]
                |d| {
                    *last = d.offset();
                    on_frame(Decoded::Mixed(d))
                },
            ),
            other => self.feed_slow(other, piece, on_frame),
        }
        // Only the bytes after the last frame are ever read again (on a clean stream, less
        // than a frame of each piece): the history is nearly free while frames keep coming.
        let after = self.last_frame.saturating_add(1).saturating_sub(self.bytes);
        let skip = usize::try_from(after).map_or(n, |k| k.min(n));
        self.history.keep(self.bytes + skip as u64, &piece[skip..]);
        self.bytes += n as u64;
        if self.bytes.is_multiple_of(RELOCK_AFTER) {
            self.end_block(family, on_frame);
        }
        n
    }

    /// At the end of a block while locked: detection starts again when the locked decoder
    /// handed on no frame since the block's start, every other decoder reading the bytes
    /// after its last frame first (the frames found there lock at once).
    #[cold]
    fn end_block(&mut self, family: Family, on_frame: &mut dyn FnMut(Decoded)) {
        let now = self.decoders.handed_on(family);
        if self.block_start == Some(now) {
            self.locked = None;
            self.found = [None; Family::ALL.len()];
            self.replay(on_frame);
            self.end_slice();
        }
        self.block_start = Some(now);
    }

    /// Gives every decoder that is behind the bytes after the locked decoder's last frame
    /// (kept in the history), after passing over those before them; `on_frame` gets the frames
    /// they find, noted in `found`.
    fn replay(&mut self, on_frame: &mut dyn FnMut(Decoded)) {
        let to = self.bytes;
        let from = (self.last_frame + 1).max(to.saturating_sub(HISTORY as u64));
        let (history, found) = (&self.history, &mut self.found);
        let mut on_frame = on_frame;
        let mut take = noting(true, found, &mut on_frame);
        for family in Family::ALL {
            self.decoders
                .replay(family, history, from, to, &mut |d| take(d));
        }
    }

    /// Gives every decoder the bytes of `data` to the end of the current slice; at its end,
    /// locks onto the first family that found a frame in it. Returns how many it took.
    /// The locked decoder of a format whose ESCs send at most about 50 frames a second (V4,
    /// V3, HW5) given `piece`: its frames through a `dyn` callback, so that its scanner is
    /// compiled once, not once per caller (every handler's, which made the binary 10 % larger).
    fn feed_slow(&mut self, family: Family, piece: &[u8], on_frame: &mut dyn FnMut(Decoded)) {
        let last = &mut self.last_frame;
        self.decoders.feed(family, piece, &mut |d: Decoded| {
            *last = d.offset();
            on_frame(d)
        });
    }

    /// (Through a `dyn` callback, as [`Decoder::feed_slow`]: detection reads a few slices.)
    fn feed_detecting(&mut self, data: &[u8], on_frame: &mut dyn FnMut(Decoded)) -> usize {
        self.catch_up(false);
        let to_end = SLICE - self.bytes % SLICE;
        let n = usize::try_from(to_end).map_or(data.len(), |k| k.min(data.len()));
        let piece = &data[..n];
        for (i, family) in Family::ALL.into_iter().enumerate() {
            let found = &mut self.found[i];
            self.decoders.feed(family, piece, &mut |d| {
                *found = Some(d.offset());
                on_frame(d)
            });
        }
        self.bytes += n as u64;
        if self.bytes.is_multiple_of(SLICE) {
            self.end_slice();
        }
        n
    }

    /// At the end of a slice while detecting: locks onto the first family that found a frame.
    fn end_slice(&mut self) {
        if let Some(i) = self.found.iter().position(Option::is_some) {
            let family = Family::ALL[i];
            self.locked = Some(family);
            self.last_locked = Some(family);
            self.block_start = None;
            self.last_frame = self.found[i].unwrap_or(self.bytes);
        }
        self.found = [None; Family::ALL.len()];
    }

    /// Brings every decoder to the stream's end: each passes over the bytes it was not given.
    /// With `settle` (at a flush), a decoder that was given every byte but is not being given
    /// bytes now (one other than the locked one) also drops what it holds (its skipped bytes):
    /// it was not flushed, and its statistics must count every byte.
    fn catch_up(&mut self, settle: bool) {
        let bytes = self.bytes;
        let behind = |b: u64, held: usize| {
            let n = bytes - b;
            (n > 0 || (settle && held > 0)).then_some(n)
        };
        for family in Family::ALL {
            let held = self.decoders.buffered(family);
            if let Some(n) = behind(self.decoders.bytes(family), held) {
                self.decoders.pass_over(family, n);
            }
        }
    }

    /// Tells the decoders that the line was silent for a time in which at most `esc_frames`
    /// HW-FOC frames (24 byte times each) and `hub_frames` DataLink frames could have been
    /// sent (see [`StreamDecoder::line_silent`](crate::StreamDecoder::line_silent)); `on_frame`
    /// gets the frames still found in the bytes they held. Locked, the other formats' decoders
    /// first read the bytes after the locked decoder's last frame (another format may have
    /// begun there). Every format is read again after it.
    pub fn line_silent_each(
        &mut self,
        esc_frames: u32,
        hub_frames: u32,
        mut on_frame: impl FnMut(Decoded),
    ) {
        self.line_silent_dyn(esc_frames, hub_frames, &mut on_frame);
    }

    /// [`Decoder::line_silent_each`], compiled once (as [`Decoder::feed_slow`]).
    fn line_silent_dyn(
        &mut self,
        esc_frames: u32,
        hub_frames: u32,
        mut on_frame: &mut dyn FnMut(Decoded),
    ) {
        if self.locked.is_some() {
            self.replay(on_frame);
        }
        let mut take = noting(true, &mut self.found, &mut on_frame);
        for family in Family::ALL {
            self.decoders
                .line_silent(family, esc_frames, hub_frames, &mut take);
        }
        drop(take);
        self.end_slice();
        // A silence may be a change of ESC: every format is read again from here.
        self.locked = None;
        self.found = [None; Family::ALL.len()];
    }

    /// Ends the stream: every decoder decides what it holds (as each protocol's `flush`),
    /// those not given the bytes after the locked decoder's last frame having read them first
    /// (another format may have begun there), and passes over the bytes it was not given, so
    /// that each one's statistics count the whole stream. A decoder still detecting locks onto
    /// what the last slice found; a locked one onto a format found in those last bytes.
    pub fn flush(&mut self, mut on_frame: impl FnMut(Decoded)) {
        self.flush_dyn(&mut on_frame);
    }

    /// [`Decoder::flush`], compiled once (as [`Decoder::feed_slow`]).
    fn flush_dyn(&mut self, mut on_frame: &mut dyn FnMut(Decoded)) {
        if self.locked.is_some() {
            self.replay(on_frame);
        }
        let mut take = noting(true, &mut self.found, &mut on_frame);
        for family in Family::ALL {
            self.decoders.flush(family, &mut take);
        }
        drop(take);
        self.end_slice();
        self.catch_up(true);
    }

    /// Feeds a whole stream and flushes it.
    pub fn decode_all(&mut self, data: &[u8], mut on_frame: impl FnMut(Decoded)) {
        self.feed(data, &mut on_frame);
        self.flush(on_frame);
    }

    /// Continues this decoder with `later`'s work, as [`StreamDecoder::then`] does: when both
    /// read HW-FOC and DataLink only (no other format's frame in either) and nothing is held
    /// here. Its HW-FOC and DataLink statistics are then the whole stream's; the other formats'
    /// decoders pass over `later`'s bytes. False, and nothing changes, otherwise.
    ///
    /// [`StreamDecoder::then`]: crate::StreamDecoder::then
    pub fn then(&mut self, later: &Decoder, first_packet: Option<u16>) -> bool {
        let only_mixed = |d: &Decoder| {
            d.last_locked.is_none_or(|f| f == Family::Mixed)
                && Family::ALL
                    .iter()
                    .all(|&f| f == Family::Mixed || d.decoders.handed_on(f) == 0)
        };
        if self.buffered() != 0 || !only_mixed(self) || !only_mixed(later) {
            return false;
        }
        self.catch_up(false);
        if !self
            .decoders
            .Mixed
            .then(&later.decoders.Mixed, first_packet)
        {
            return false;
        }
        let n = later.bytes;
        for family in Family::ALL {
            if family != Family::Mixed {
                self.decoders.pass_over(family, n);
            }
        }
        self.bytes += n;
        self.locked = later.locked;
        self.last_locked = later.last_locked.or(self.last_locked);
        let base = self.bytes - n;
        // Its frame count is the whole stream's now: the block it is in is not judged.
        self.block_start = None;
        self.found = later.found.map(|at| at.map(|at| at + base));
        true
    }
}

#[cfg(test)]
mod family_tests {
    use super::*;

    #[test]
    fn families_are_preferred_checksummed_first() {
        assert_eq!(
            Family::ALL,
            [Family::Mixed, Family::Hw5, Family::HwV4, Family::HwV3]
        );
    }
}
