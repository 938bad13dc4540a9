//! The bulk `frames` iterator over the whole input, checked against `Decoder` fed the same
//! bytes in one chunk, one byte at a time, and through `decode_all`.
//!
//! Checked: the whole-stream invariants of `check_stream`, the iterator staying exhausted, and
//! exact equality (frames and statistics) of all four ways of decoding, and the frames of the
//! iterator's `fold` (one run of the scanner) against its `next`. Then the same of the input
//! repeated to 24 kB: the scanner's whole-buffer run follows candidate maps where a map's
//! block and a frame's bytes are left (over 4 kB), which `next` never does.

#![no_main]

use hwfoc::foc::{Decoder, frames};
use hwfoc_fuzz::check_stream;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut it = frames(data);
    let bulk: Vec<_> = it.by_ref().collect();
    assert_eq!(it.next(), None, "frames() is fused");
    let stats = *it.stats();
    check_stream(data, &bulk, &stats);

    let mut one = Decoder::new();
    let mut got = Vec::new();
    one.feed(data, |d| got.push(d));
    assert!(one.buffered() < 77);
    one.flush(|d| got.push(d));
    assert_eq!(got, bulk, "one-chunk Decoder and frames() disagree");
    assert_eq!(*one.stats(), stats);

    let mut bytewise = Decoder::new();
    got.clear();
    for &b in data {
        bytewise.push(b, |d| got.push(d));
        assert!(bytewise.buffered() < 77);
    }
    bytewise.flush(|d| got.push(d));
    assert_eq!(got, bulk, "byte-at-a-time Decoder and frames() disagree");
    assert_eq!(*bytewise.stats(), stats);

    let mut all = Decoder::new();
    got.clear();
    all.decode_all(data, |d| got.push(d));
    assert_eq!(got, bulk, "decode_all and frames() disagree");
    assert_eq!(*all.stats(), stats);

    // `fold` (one run of the scanner over the rest), from the start and after a few frames
    // taken by `next`.
    for k in [0, 1, bulk.len() / 2] {
        let mut it = frames(data);
        let head: Vec<_> = it.by_ref().take(k).collect();
        let folded = it.fold(head, |mut v, d| {
            v.push(d);
            v
        });
        assert_eq!(
            folded, bulk,
            "frames().fold and next() disagree after {k} frames"
        );
    }

    // Long enough for the candidate maps of the whole-buffer run (`foc::follow`).
    if !data.is_empty() {
        let long: Vec<u8> = data.iter().copied().cycle().take(24 * 1024).collect();
        let mut it = frames(&long);
        let one_at_a_time: Vec<_> = it.by_ref().collect();
        let mut whole = Decoder::new();
        got.clear();
        whole.decode_all(&long, |d| got.push(d));
        assert_eq!(got, one_at_a_time, "repeated input: decode_all and next() disagree");
        assert_eq!(whole.stats(), it.stats(), "repeated input: statistics disagree");
    }
});
