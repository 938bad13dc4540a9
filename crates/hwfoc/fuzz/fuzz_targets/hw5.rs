//! The HW5 decoder (CRC-16/MODBUS frames of several kinds, telemetry handed on): an
//! `hw5::Decoder` fed in chunks whose sizes come from the input itself, fed a byte at a time
//! and through `decode_all`, all checked against the bulk `hw5::frames` iterator.
//!
//! Input layout: that of `stream.rs` (byte 0 the schedule's length, the schedule, the stream;
//! see `hwfoc_fuzz::feed_scheduled`), with `line_silent` beside `flush`.
//!
//! Checked: `buffered() < 105` and the byte count after every call, the whole-stream
//! invariants of `check_hw5_stream` for the bulk and the chunked decodings, the iterator staying
//! exhausted, and exact equality (frames and statistics) of the chunked (when nothing settled
//! the stream mid-way), byte-at-a-time and `decode_all` decoders with the bulk iterator.

#![no_main]

use hwfoc::hw5;
use hwfoc_fuzz::{check_hw5_stream, check_scheduled};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    check_scheduled::<hw5::Scanner>(data, |d| d.offset, check_hw5_stream);
});
