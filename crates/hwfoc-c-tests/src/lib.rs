//! Test-only: the C decoders of `c/hwfoc.h` (compiled by `build.rs` through `shim/shim.c`)
//! beside the Rust codec's, fed the same operations, with their frames and statistics laid out
//! as the same flat lists of integers ([`flat`]) so that a test compares them whole.
//!
//! Nothing in the workspace depends on this crate; its tests are the differential test
//! (`tests/differential.rs`, and `tests/noinfo.rs` for the `HWFOC_NO_FOC_INFO` build), the
//! golden vectors (`tests/vectors.rs`) and the DroneCAN payloads (`tests/dronecan.rs`);
//! `examples/ipb.rs` is the Rust side of `c/bench/ipb.sh`.

pub mod ffi;
pub mod flat;
pub mod ops;

pub use flat::Flat;
pub use ops::{Op, Outcome, Volume, chunked, run_both};
