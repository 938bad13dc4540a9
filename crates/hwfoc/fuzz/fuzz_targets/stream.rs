//! The streaming `Decoder` fed in chunks whose sizes come from the input itself.
//!
//! Input layout: byte 0 gives the number `n` (1..=8) of schedule bytes that follow; the rest is
//! the stream. The schedule is used cyclically, one byte per step:
//!
//! - `0`: an empty `feed`;
//! - `1..=189`: `feed` that many bytes;
//! - `190..=199`: `flush` now (as on a silent line), then go on;
//! - `200..=254`: `push` 1..=55 bytes one at a time;
//! - `255`: `feed` all the rest.
//!
//! Checked: `buffered() < 77` after every call and 0 after a flush, the byte count after every
//! call, the whole-stream invariants of `check_stream` after the final flush, and, when no flush
//! came mid-stream, exact equality (frames and statistics) with the bulk `frames` iterator.

#![no_main]

use hwfoc::foc::{Decoder, frames};
use hwfoc_fuzz::check_stream;
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

    let mut dec = Decoder::new();
    let mut got = Vec::new();
    let mut at = 0;
    let mut step = 0;
    let mut idle_steps = 0;
    let mut flushed_mid_stream = false;
    while at < input.len() {
        let op = schedule[step % n];
        step += 1;
        let left = input.len() - at;
        match op {
            0 | 190..=199 => {
                if op == 0 {
                    dec.feed(&[], |d| got.push(d));
                } else {
                    dec.flush(|d| got.push(d));
                    assert_eq!(dec.buffered(), 0, "flush leaves nothing held");
                    flushed_mid_stream = true;
                }
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
                    assert!(
                        dec.buffered() < 77,
                        "buffered {} after push",
                        dec.buffered()
                    );
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
            dec.buffered() < 77,
            "buffered {} after a call",
            dec.buffered()
        );
        assert_eq!(dec.stats().bytes(), at as u64, "bytes fed so far");
        if let Some(last) = got.last() {
            assert!(last.offset < at as u64);
        }
    }
    dec.flush(|d| got.push(d));
    assert_eq!(dec.buffered(), 0);
    check_stream(input, &got, dec.stats());

    if !flushed_mid_stream {
        let mut it = frames(input);
        let bulk: Vec<_> = it.by_ref().collect();
        assert_eq!(got, bulk, "chunked Decoder and frames() disagree");
        assert_eq!(
            dec.stats(),
            it.stats(),
            "chunked Decoder and frames() statistics"
        );
    }
});
