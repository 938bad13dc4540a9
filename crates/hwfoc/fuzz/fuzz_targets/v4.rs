//! The V4 decoder (a checksum-less format locked on chains of plausible frames, info frames
//! adopted in pairs): a `v4::Decoder` fed in chunks whose sizes come from the input itself,
//! fed a byte at a time and through `decode_all`, all checked against the bulk `v4::frames`
//! iterator.
//!
//! Input layout: that of `stream.rs` (byte 0 the schedule's length, the schedule, the stream;
//! see `hwfoc_fuzz::feed_scheduled`), with `line_silent` beside `flush`.
//!
//! Checked: `buffered() < 60` and the byte count after every call, the whole-stream invariants
//! of `check_v4_stream` for the bulk and the chunked decodings, the iterator staying exhausted,
//! and exact equality (frames and statistics) of the chunked (when nothing settled the stream
//! mid-way), byte-at-a-time and `decode_all` decoders with the bulk iterator.

#![no_main]

use hwfoc::v4;
use hwfoc_fuzz::{check_scheduled, check_v4_stream};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    check_scheduled::<v4::Scanner>(data, |d| d.offset, check_v4_stream);
});
