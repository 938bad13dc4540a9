//! The Rust side of `c/bench/ipb.sh`: the codec's HW-FOC decoder on a file written by `ipb
//! write`, so that cachegrind counts its instructions per byte beside the C header's.
//!
//! `cargo run --release -p hwfoc-c-tests --example ipb -- feed|push|none FILE`

use std::hint::black_box;

use hwfoc::foc;
use hwfoc::scan::StreamDecoder;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(mode), Some(path)) = (args.get(1), args.get(2)) else {
        eprintln!("usage: ipb feed|push|none FILE");
        std::process::exit(2);
    };
    let buf = std::fs::read(path).unwrap_or_else(|e| {
        eprintln!("ipb: {path}: {e}");
        std::process::exit(1)
    });
    let mut frames = 0u64;
    let mut dec = StreamDecoder::<foc::Scanner>::new();
    match mode.as_str() {
        "feed" => {
            for chunk in black_box(&buf[..]).chunks(64 << 10) {
                dec.feed(chunk, |_| frames += 1);
            }
        }
        "push" => {
            for &b in black_box(&buf[..]) {
                dec.push(b, |_| frames += 1);
            }
        }
        "none" => {}
        _ => {
            eprintln!("ipb: {mode}: not feed, push or none");
            std::process::exit(2);
        }
    }
    dec.flush(|_| frames += 1);
    println!("{} bytes, {frames} frames", buf.len());
}
