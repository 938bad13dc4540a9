//! What both implementations are given ([`Op`]: chunks, single bytes, flushes, silences), the
//! random chunkings of a stream ([`chunked`]), and [`run_both`], which gives the same
//! operations to the Rust decoder and the C one and compares their frames and statistics after
//! every operation.

use std::sync::atomic::{AtomicU64, Ordering};

use hwfoc::foc;
use hwfoc::scan::StreamDecoder;

use crate::ffi::{CDecoder, NoInfoDecoder};
use crate::flat::Flat;

/// One call on a decoder.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Op {
    /// `feed` with these bytes.
    Feed(Vec<u8>),
    /// `push` of each of these bytes in turn.
    Push(Vec<u8>),
    /// `flush`.
    Flush,
    /// `line_silent(max_frames)`.
    Silent(u32),
}

/// How much the differential tests compared, over every test of the process.
#[derive(Debug, Default)]
pub struct Volume {
    /// Operation lists run.
    pub streams: AtomicU64,
    /// Bytes given to each implementation.
    pub bytes: AtomicU64,
    /// Frames compared.
    pub frames: AtomicU64,
}

/// The volume of this process's differential runs.
pub static VOLUME: Volume = Volume {
    streams: AtomicU64::new(0),
    bytes: AtomicU64::new(0),
    frames: AtomicU64::new(0),
};

/// What a run of operations gave: the frames (flat) and the final statistics (flat).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Outcome {
    /// Every frame handed on, flat, with a count of them.
    pub frames: Vec<u64>,
    /// Frames handed on.
    pub frame_count: usize,
    /// The statistics at the end.
    pub stats: Vec<u64>,
}

/// A small seeded generator (xorshift64*), so that a chunking is reproduced from its seed.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from `seed` (any value).
    pub fn new(seed: u64) -> Rng {
        Rng(seed ^ 0x9E37_79B9_7F4A_7C15 | 1)
    }
    /// The next 64 random bits.
    pub fn bits(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// A number in `0..n` (`n` > 0).
    pub fn below(&mut self, n: u64) -> u64 {
        self.bits() % n
    }
}

/// `stream` cut at random into feeds of 1 to 300 bytes and runs of pushed bytes, with a
/// silence of the line now and then (when `silences`), and a flush at the end.
pub fn chunked(stream: &[u8], seed: u64, silences: bool) -> Vec<Op> {
    let mut rng = Rng::new(seed);
    let mut ops = Vec::new();
    let mut at = 0;
    while at < stream.len() {
        let most = match rng.below(4) {
            0 => 3,
            1 => 40,
            2 => 300,
            _ => 1,
        };
        let n = (1 + rng.below(most) as usize).min(stream.len() - at);
        let bytes = stream[at..at + n].to_vec();
        ops.push(if rng.below(3) == 0 {
            Op::Push(bytes)
        } else {
            Op::Feed(bytes)
        });
        at += n;
        if silences && rng.below(40) == 0 {
            ops.push(Op::Silent(rng.below(2000) as u32));
        }
    }
    ops.push(Op::Flush);
    ops
}

/// A C decoder as an [`Op`] drives it.
pub trait CSide {
    /// `_feed` (or `_push` byte by byte when `push`).
    fn feed(&mut self, data: &[u8], push: bool);
    /// `_flush`.
    fn flush(&mut self);
    /// `_line_silent`.
    fn line_silent(&mut self, max_frames: u32);
}

macro_rules! c_side {
    ($($t:ty),*) => {$(
        impl CSide for $t {
            fn feed(&mut self, data: &[u8], push: bool) {
                <$t>::feed(self, data, push)
            }
            fn flush(&mut self) {
                <$t>::flush(self)
            }
            fn line_silent(&mut self, max_frames: u32) {
                <$t>::line_silent(self, max_frames)
            }
        }
    )*};
}
c_side!(CDecoder, NoInfoDecoder);

/// Gives `op` to the Rust decoder (its frames to `take`) and to the C one.
pub fn apply<S: Flat>(
    op: &Op,
    rust: &mut StreamDecoder<S>,
    c: &mut impl CSide,
    mut take: impl FnMut(S::Item),
) {
    match op {
        Op::Feed(bytes) => {
            rust.feed(bytes, &mut take);
            c.feed(bytes, false);
        }
        Op::Push(bytes) => {
            for &b in bytes {
                rust.push(b, &mut take);
            }
            c.feed(bytes, true);
        }
        Op::Flush => {
            rust.flush(&mut take);
            c.flush();
        }
        Op::Silent(max) => {
            rust.line_silent(*max, &mut take);
            c.line_silent(*max);
        }
    }
}

/// An HW-FOC data frame numbered `packet`, its other fields random.
pub fn foc_data_frame(rng: &mut Rng, packet: u16) -> foc::DataFrame {
    foc::DataFrame {
        packet,
        throttle_in_raw: rng.below(1100) as u16,
        throttle_out_raw: rng.below(1100) as u16,
        erpm_raw: rng.bits() as u16,
        voltage_raw: rng.bits() as u16,
        current_raw: rng.bits() as i16,
        phase_current_raw: rng.bits() as i16,
        mos_adc: rng.bits() as u8,
        cap_adc: rng.bits() as u8,
        status: hwfoc::Status(rng.bits() as u16),
    }
}

/// Now and then: drops the frame, cuts it short, flips a byte, or adds noise (biased towards
/// the bytes a scanner looks for) before it.
pub fn disturb(rng: &mut Rng, bytes: &mut Vec<u8>, special: &[u8]) {
    match rng.below(25) {
        0 => bytes.clear(),
        1 => bytes.truncate(rng.below(bytes.len() as u64) as usize),
        2 => {
            let at = rng.below(bytes.len() as u64) as usize;
            bytes[at] ^= 1 << rng.below(8);
        }
        3 => {
            let noise: Vec<u8> = (0..rng.below(30))
                .map(|_| match rng.below(2) {
                    0 => special[rng.below(special.len() as u64) as usize],
                    _ => rng.bits() as u8,
                })
                .collect();
            bytes.splice(0..0, noise);
        }
        _ => {}
    }
}

/// Gives `ops` to the Rust decoder of `S` and to the C decoder of the same format, and checks
/// that after every operation both handed on the same frames and hold the same statistics.
/// Returns the common outcome; panics, naming the operation, where they differ.
pub fn run_both<S: Flat>(ops: &[Op]) -> Outcome {
    let mut rust = StreamDecoder::<S>::new();
    let mut c = CDecoder::new(S::FORMAT);
    let mut all = Vec::new();
    let mut frame_count = 0;
    let mut stats = Vec::new();
    for (i, op) in ops.iter().enumerate() {
        let mut frames = Vec::new();
        let mut n = 0usize;
        apply(op, &mut rust, &mut c, |item: S::Item| {
            S::frame(&item, &mut frames);
            n += 1;
        });
        let c_frames = c.take_frames();
        assert_eq!(
            c_frames,
            frames,
            "{:?}: frames differ at op {i} ({op:?})",
            S::FORMAT
        );
        stats.clear();
        S::stats(rust.stats(), &mut stats);
        assert_eq!(
            c.stats(),
            stats,
            "{:?}: statistics differ after op {i}",
            S::FORMAT
        );
        all.extend(frames);
        frame_count += n;
        if let Op::Feed(b) | Op::Push(b) = op {
            VOLUME.bytes.fetch_add(b.len() as u64, Ordering::Relaxed);
        }
    }
    VOLUME.streams.fetch_add(1, Ordering::Relaxed);
    VOLUME
        .frames
        .fetch_add(frame_count as u64, Ordering::Relaxed);
    Outcome {
        frames: all,
        frame_count,
        stats,
    }
}
