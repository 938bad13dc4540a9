//! What the tests of the V3 and V4 decoders share: the logic-analyser CSV loader (as in
//! `captures.rs`), the decoding paths for any scanner of `hwfoc::scan`, and a seeded random
//! byte source.

use std::fmt::Debug;

use hwfoc::counters::PacketSequence24;
use hwfoc::scan::{Scan, Scanner, StreamDecoder};

use crate::common::streamed_bytewise;

const CAPTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../testdata/captures/");
/// The Platinum Pro V3 capture: 699 V3 frames.
pub const PLATINUM_PRO_V3: &str = "platinum-pro-v3.csv";
/// The Platinum V4 capture: 297 data frames and 26 info frames.
pub const PLATINUM_V4: &str = "platinum-v4.csv";
/// The XRotor capture: HW-FOC.
pub const XROTOR: &str = "xrotor-v4-pro-hv-80A.csv";

/// The bytes of a logic-analyser CSV export (see [`load_timed`]).
pub fn load(name: &str) -> Vec<u8> {
    load_timed(name).1
}

/// A logic-analyser CSV export: header `Time [s],Value,Parity Error,Framing Error`, then one
/// row per byte with the value written `0xNN`; the time of each byte and its value, row for
/// row (`captures.rs` reads the HW-FOC captures with it too).
pub fn load_timed(name: &str) -> (Vec<f64>, Vec<u8>) {
    let path = format!("{CAPTURES}{name}");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("Time [s],Value,Parity Error,Framing Error"),
        "{name}: header"
    );
    let (mut times, mut bytes) = (Vec::new(), Vec::new());
    for (i, line) in lines.enumerate() {
        if line.is_empty() {
            continue;
        }
        let cols: Vec<&str> = line.split(',').collect();
        assert_eq!(cols.len(), 4, "{name} row {i}: {line:?}");
        let time: f64 = cols[0]
            .parse()
            .unwrap_or_else(|e| panic!("{name} row {i}: time {:?}: {e}", cols[0]));
        let hex = cols[1]
            .strip_prefix("0x")
            .unwrap_or_else(|| panic!("{name} row {i}: value {:?}", cols[1]));
        let byte = u8::from_str_radix(hex, 16)
            .unwrap_or_else(|e| panic!("{name} row {i}: value {:?}: {e}", cols[1]));
        times.push(time);
        bytes.push(byte);
    }
    (times, bytes)
}

/// The bulk path: every frame of `bytes` and the statistics.
pub fn bulk<S: Scanner>(bytes: &[u8]) -> (Vec<S::Item>, S::Stats) {
    let mut it = Scan::<S>::new(bytes);
    let out: Vec<S::Item> = it.by_ref().collect();
    (out, it.stats().clone())
}

/// `bytes` fed in the chunks between consecutive `cuts` (which start at 0 and end at
/// `bytes.len()`), then flushed; checks that fewer than `MAX_LEN` bytes are ever held.
pub fn streamed_at<S: Scanner>(bytes: &[u8], cuts: &[usize]) -> (Vec<S::Item>, S::Stats) {
    let mut d = StreamDecoder::<S>::new();
    let mut out = Vec::new();
    for w in cuts.windows(2) {
        d.feed(&bytes[w[0]..w[1]], |x| out.push(x));
        assert!(d.buffered() < S::MAX_LEN);
    }
    d.flush(|x| out.push(x));
    assert_eq!(d.buffered(), 0);
    (out, d.stats().clone())
}

/// `bytes` fed in chunks of `size`, then flushed.
pub fn streamed_chunks<S: Scanner>(bytes: &[u8], size: usize) -> (Vec<S::Item>, S::Stats) {
    let mut cuts: Vec<usize> = (0..bytes.len()).step_by(size).collect();
    cuts.push(bytes.len());
    streamed_at::<S>(bytes, &cuts)
}

/// Asserts that every decoding path of `S` gives what the bulk path gives for `bytes`: a
/// byte at a time, in chunks of each of `sizes`, and `decode_all`.
pub fn assert_every_path_agrees<S: Scanner>(bytes: &[u8], sizes: &[usize])
where
    S::Item: PartialEq + Debug,
    S::Stats: Copy + PartialEq + Debug,
{
    let reference = bulk::<S>(bytes);
    assert_eq!(streamed_bytewise::<S>(bytes), reference, "byte at a time");
    for &size in sizes {
        assert_eq!(
            streamed_chunks::<S>(bytes, size),
            reference,
            "chunks of {size}"
        );
    }
    let mut all_at_once = StreamDecoder::<S>::new();
    let mut out = Vec::new();
    all_at_once.decode_all(bytes, |d| out.push(d));
    assert_eq!((out, *all_at_once.stats()), reference, "decode_all");
}

/// Which of `wanted.len()` frames are sent when those marked in `wanted` are cut out whole:
/// all but the first three (which lock the decoder) and the last (after which a loss would not
/// show), and at most `max_run` in a row (a longer run is an outage, after which a chain of
/// three must lock again).
pub fn sent_frames(wanted: &[bool], max_run: u32) -> Vec<bool> {
    let mut run = 0;
    let last = wanted.len().saturating_sub(1);
    (0..wanted.len())
        .map(|k| {
            let cut = wanted[k] && k >= 3 && k < last && run < max_run;
            run = if cut { run + 1 } else { 0 };
            !cut
        })
        .collect()
}

/// Asserts that the frames `got` (offset and counter) are those `want`ed, first naming the
/// wanted frames missing by their counters' distance from `first`.
pub fn assert_frames(got: &[(u64, u32)], want: &[(u64, u32)], first: u32) {
    let missed: Vec<u32> = want
        .iter()
        .filter(|f| !got.contains(f))
        .map(|(_, c)| c - first)
        .collect();
    assert!(missed.is_empty(), "intact frames lost: {missed:?}");
    assert_eq!(got, want);
}

/// A chained scanner's figures of a link: the counter's lost, duplicate and restarted numbers,
/// bytes skipped, rejected candidates, syncs.
#[derive(Debug, PartialEq, Eq)]
pub struct Figures {
    pub lost: u32,
    pub duplicates: u32,
    pub restarts: u32,
    pub skipped: u64,
    pub rejected: u32,
    pub syncs: u32,
}

impl Figures {
    /// The figures of a scanner's statistics.
    pub fn of(counter: &PacketSequence24, skipped: u64, rejected: u32, syncs: u32) -> Figures {
        Figures {
            lost: counter.lost(),
            duplicates: counter.duplicates(),
            restarts: counter.restarts(),
            skipped,
            rejected,
            syncs,
        }
    }

    /// What a scanner must report of a clean stream from which `cut` frames were cut out whole
    /// (not the first three, nor the last): each counted lost, nothing skipped or rejected, one
    /// sync.
    pub fn after_cuts(cut: usize) -> Figures {
        Figures {
            lost: cut as u32,
            duplicates: 0,
            restarts: 0,
            skipped: 0,
            rejected: 0,
            syncs: 1,
        }
    }
}

/// A seeded xorshift64 generator: the same bytes on every run.
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// `n` uniformly random bytes.
    pub fn uniform(&mut self, n: usize) -> Vec<u8> {
        (0..n).map(|_| self.next() as u8).collect()
    }

    /// `count` distinct indices drawn uniformly from `range`, in increasing order.
    pub fn sample(&mut self, range: std::ops::Range<usize>, count: usize) -> Vec<usize> {
        assert!(count <= range.len());
        let mut picked = std::collections::BTreeSet::new();
        while picked.len() < count {
            picked.insert(range.start + (self.next() % range.len() as u64) as usize);
        }
        picked.into_iter().collect()
    }

    /// `n` random bytes of which about a quarter are `9B` and a quarter `B9`.
    pub fn rich(&mut self, n: usize) -> Vec<u8> {
        (0..n)
            .map(|_| {
                let x = self.next();
                match x >> 62 {
                    0 => 0x9B,
                    1 => 0xB9,
                    _ => x as u8,
                }
            })
            .collect()
    }
}

/// Two million random bytes, uniform or rich in `9B` and `B9`.
pub const RANDOM_LEN: usize = 2_000_000;
