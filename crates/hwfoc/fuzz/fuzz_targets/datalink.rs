//! The DataLink V2 decoder: `datalink::Decoder` fed in chunks whose sizes come from the input
//! itself, fed a byte at a time, and through `decode_all`, all checked against the bulk
//! `datalink::frames` iterator.
//!
//! Input layout: byte 0 gives the number `n` (1..=8) of schedule bytes that follow; the rest is
//! the stream. The schedule is used cyclically, one byte per step:
//!
//! - `0`: an empty `feed`;
//! - `1..=199`: `feed` that many bytes;
//! - `200..=254`: `push` 1..=55 bytes one at a time;
//! - `255`: `feed` all the rest.
//!
//! Checked: `buffered() < 160` and the byte count after every call, the whole-stream invariants
//! of `check_datalink_stream`, the iterator staying exhausted, and exact equality (frames and
//! statistics) of all four ways of decoding.

#![no_main]

use hwfoc::datalink;
use hwfoc_fuzz::check_datalink_stream;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&n, rest)) = data.split_first() else {
        return;
    };
    let n = usize::from(n % 8) + 1;
    if rest.len() < n {
        return;
    }
    let (schedule, input) = rest.split_at(n);

    let mut it = datalink::frames(input);
    let bulk: Vec<_> = it.by_ref().collect();
    assert_eq!(it.next(), None, "frames() is fused");
    let stats = *it.stats();
    check_datalink_stream(input, &bulk, &stats);

    let mut dec = datalink::Decoder::new();
    let mut got = Vec::new();
    let mut at = 0;
    let mut step = 0;
    let mut idle_steps = 0;
    while at < input.len() {
        let op = schedule[step % n];
        step += 1;
        let left = input.len() - at;
        match op {
            0 => {
                dec.feed(&[], |d| got.push(d));
                // A schedule that never consumes a byte still has to end.
                idle_steps += 1;
                if idle_steps >= n {
                    dec.push(input[at], |d| got.push(d));
                    at += 1;
                    idle_steps = 0;
                }
            }
            200..=254 => {
                for &b in &input[at..at + usize::from(op - 199).min(left)] {
                    dec.push(b, |d| got.push(d));
                    assert!(dec.buffered() < 160);
                    at += 1;
                }
                idle_steps = 0;
            }
            _ => {
                let len = if op == 255 {
                    left
                } else {
                    usize::from(op).min(left)
                };
                dec.feed(&input[at..at + len], |d| got.push(d));
                at += len;
                idle_steps = 0;
            }
        }
        assert!(
            dec.buffered() < 160,
            "buffered {} after a call",
            dec.buffered()
        );
        assert_eq!(dec.stats().bytes(), at as u64, "bytes fed so far");
        let s = dec.stats();
        assert_eq!(
            s.bytes(),
            160 * u64::from(s.frames()) + s.bytes_skipped() + dec.buffered() as u64
        );
    }
    dec.flush(|d| got.push(d));
    assert_eq!(dec.buffered(), 0);
    assert_eq!(got, bulk, "chunked datalink::Decoder and frames() disagree");
    assert_eq!(
        dec.stats(),
        &stats,
        "chunked datalink::Decoder and frames() statistics"
    );

    let mut bytewise = datalink::Decoder::new();
    got.clear();
    for &b in input {
        bytewise.push(b, |d| got.push(d));
    }
    bytewise.flush(|d| got.push(d));
    assert_eq!(
        got, bulk,
        "byte-at-a-time datalink::Decoder and frames() disagree"
    );
    assert_eq!(bytewise.stats(), &stats);

    let mut all = datalink::Decoder::new();
    got.clear();
    all.decode_all(input, |d| got.push(d));
    assert_eq!(got, bulk, "decode_all and frames() disagree");
    assert_eq!(all.stats(), &stats);
});
