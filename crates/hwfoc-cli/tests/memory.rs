//! The Parquet export's memory stays bounded whatever the frames hold: a row group of frames
//! that all carry faults (up to sixteen names a row) is encoded a block at a time.
//!
//! Alone in its file: the peak memory read is that of every child this test process waited
//! for.

#![cfg(target_os = "linux")]

mod common;

use hwfoc::Status;
use hwfoc::foc::DataFrame;

use common::{Dir, hwfoc, ok, run};

/// The largest resident set of the children waited for so far, in MB.
fn children_peak_mb() -> f64 {
    let usage = nix::sys::resource::getrusage(nix::sys::resource::UsageWho::RUSAGE_CHILDREN)
        .expect("getrusage");
    usage.max_rss() as f64 / 1024.0
}

#[test]
fn faults_in_every_frame_do_not_grow_the_parquet_export() {
    let dir = Dir::new();
    let input = dir.path("faults.bin");
    // Three row groups of frames with every status bit set.
    let frames = 3 * (1 << 17);
    let mut wire = Vec::with_capacity(frames * 24);
    for i in 0..frames {
        let frame = DataFrame {
            packet: i as u16,
            voltage_raw: 240,
            status: Status(0xFFFF),
            ..Default::default()
        };
        wire.extend_from_slice(&frame.encode());
    }
    std::fs::write(&input, &wire).unwrap();
    let out = dir.arg("out.parquet");
    ok(run(hwfoc().args([
        "decode",
        "--format",
        "parquet",
        input.to_str().unwrap(),
        "-o",
        &out,
    ])));
    let peak = children_peak_mb();
    // About 40 MB (debug build); a row group's fault names held at once took 120 MB more.
    assert!(peak < 90.0, "peak resident memory {peak:.0} MB");
    assert!(std::fs::metadata(&out).unwrap().len() > 0);
}
