//! The decoder of every serial format at once (`hwfoc::detect`): a `detect::Decoder` fed in
//! chunks whose sizes come from the input itself, fed a byte at a time and through
//! `decode_all`.
//!
//! Input layout: that of `stream.rs` (byte 0 the schedule's length, the schedule, the stream;
//! see `hwfoc_fuzz::feed_scheduled`), with `line_silent_each` beside `flush`.
//!
//! Checked (`hwfoc_fuzz::check_detect`): no panic; the byte count after every call and no frame
//! beyond the bytes given; after the final flush every format's decoder counted every byte,
//! nothing held, and each format's frames pass its whole-stream invariants (`check_v3_stream`
//! and the others); the byte-at-a-time decoder, and the chunked one when nothing settled the
//! stream mid-way, give the frames of `decode_all` (each format's in the same order, the same
//! ones in all) and end in its state (lock and every format's statistics).

#![no_main]

use hwfoc_fuzz::check_detect;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    check_detect(data);
});
