//! `c/hwfoc.h` against the Rust codec: every serial format's C decoder and Rust decoder given the
//! same stream in the same chunking (feeds, pushed bytes, silences of the line, a flush), their
//! frames and statistics compared after every call (`hwfoc_c_tests::run_both`, which panics on
//! the first difference).
//!
//! Input layout: byte 0 seeds the chunking (odd: with silences of the line); the rest is the
//! stream.

#![no_main]

use hwfoc::{datalink, foc, hw5, v3, v4};
use hwfoc_c_tests::{chunked, run_both};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&seed, stream)) = data.split_first() else {
        return;
    };
    let ops = chunked(stream, u64::from(seed), seed & 1 == 1);
    run_both::<foc::Scanner>(&ops);
    run_both::<datalink::Scanner>(&ops);
    run_both::<v3::Scanner>(&ops);
    run_both::<v4::Scanner>(&ops);
    run_both::<hw5::Scanner>(&ops);
});
