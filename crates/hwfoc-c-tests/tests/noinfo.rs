//! The HW-FOC decoder built with `HWFOC_NO_FOC_INFO` (data frames only, the whole state in
//! 64 B) against the Rust codec's: on a stream without a `4C` byte (so without an info frame or
//! an info candidate) the two are the same decoder, frame for frame and statistic for statistic
//! after every call; on streams with info frames (the real capture, encoder-made ones) the data
//! frames are the same, as are the byte and packet counts, and an info frame's 77 bytes are
//! counted as skipped.

use hwfoc::foc;
use hwfoc::scan::StreamDecoder;
use hwfoc_c_tests::ffi::NoInfoDecoder;
use hwfoc_c_tests::ops::{Rng, apply, disturb, foc_data_frame};
use hwfoc_c_tests::{Flat, Op, chunked};

/// The length byte of an info frame.
const INFO_LENGTH_BYTE: u8 = 0x4C;

/// Runs `ops` through both decoders; after each, `check(op index, rust frames, rust stats, C
/// frames, C stats)`; returns every data frame both found, flat, and the final statistics.
fn run(ops: &[Op], mut check: impl FnMut(usize, &[u64], &[u64], &[u64], &[u64])) -> Outcome {
    let mut rust = StreamDecoder::<foc::Scanner>::new();
    let mut c = NoInfoDecoder::new();
    let mut out = Outcome::default();
    for (i, op) in ops.iter().enumerate() {
        let mut frames = Vec::new();
        apply(op, &mut rust, &mut c, |item: foc::Decoded| {
            if let foc::FocFrame::Data(_) = item.frame {
                foc::Scanner::frame(&item, &mut frames);
            }
        });
        let c_frames = c.take_frames();
        out.rust_stats.clear();
        foc::Scanner::stats(rust.stats(), &mut out.rust_stats);
        out.c_stats = c.stats();
        check(i, &frames, &out.rust_stats, &c_frames, &out.c_stats);
        out.rust_frames.extend(frames);
        out.c_frames.extend(c_frames);
    }
    out
}

#[derive(Default)]
struct Outcome {
    rust_frames: Vec<u64>,
    c_frames: Vec<u64>,
    /// bytes, skipped, info frames, checksum failures, the packet sequence (5).
    rust_stats: Vec<u64>,
    /// bytes, skipped, checksum failures, the packet sequence (5).
    c_stats: Vec<u64>,
}

/// HW-FOC data frames (and info frames when `info`), some corrupted, cut or dropped, with noise.
fn stream(rng: &mut Rng, frames: usize, info: bool) -> Vec<u8> {
    let mut out = Vec::new();
    let mut packet = rng.bits() as u16;
    for _ in 0..frames {
        let mut bytes = foc_data_frame(rng, packet).encode().to_vec();
        if info && rng.below(8) == 0 {
            let text: [u8; 72] = core::array::from_fn(|_| 0x20 + rng.below(0x5F) as u8);
            bytes = foc::InfoFrame::from_text(text)
                .expect("ASCII")
                .encode()
                .to_vec();
        }
        disturb(rng, &mut bytes, &[0x9B, 0x16, INFO_LENGTH_BYTE, 0x01, 0x02]);
        out.extend(bytes);
        packet = packet.wrapping_add(if rng.below(30) == 0 { 3 } else { 1 });
    }
    out
}

#[test]
fn the_data_only_state_fits_64_bytes() {
    assert!(
        NoInfoDecoder::state_size() <= 64,
        "sizeof(hwfoc_foc_decoder) with HWFOC_NO_FOC_INFO: {} B",
        NoInfoDecoder::state_size()
    );
}

#[test]
fn without_info_bytes_the_data_only_build_is_the_rust_decoder() {
    let mut frames = 0;
    for seed in 0..60 {
        let mut rng = Rng::new(seed);
        let mut bytes = stream(&mut rng, 300, false);
        for b in &mut bytes {
            if *b == INFO_LENGTH_BYTE {
                *b = INFO_LENGTH_BYTE + 1;
            }
        }
        let out = run(
            &chunked(&bytes, seed, seed % 2 == 1),
            |i, rf, rs, cf, cs| {
                assert_eq!(cf, rf, "seed {seed}: frames differ at op {i}");
                assert_eq!(rs[2], 0, "seed {seed}: an info frame without a 4C byte");
                let rust_but_info: Vec<u64> = [&rs[..2], &rs[3..]].concat();
                assert_eq!(
                    cs, rust_but_info,
                    "seed {seed}: statistics differ after op {i}"
                );
            },
        );
        frames += out.c_frames.len() / 12;
    }
    assert!(frames > 10_000, "only {frames} data frames compared");
}

/// The HW-FOC capture of a real ESC (data and info frames).
const CAPTURE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../testdata/captures/xrotor-v4-pro-hv-80A.csv"
);

fn capture_bytes() -> Vec<u8> {
    let text = std::fs::read_to_string(CAPTURE).unwrap_or_else(|e| panic!("{CAPTURE}: {e}"));
    text.lines()
        .skip(1)
        .filter(|l| !l.is_empty())
        .map(|l| {
            let v = l
                .split(',')
                .nth(1)
                .unwrap_or_else(|| panic!("{CAPTURE}: {l}"));
            u8::from_str_radix(v.trim_start_matches("0x"), 16)
                .unwrap_or_else(|_| panic!("{CAPTURE}: {l}"))
        })
        .collect()
}

#[test]
fn with_info_frames_the_data_frames_and_counts_are_the_rust_decoders() {
    let mut streams = vec![capture_bytes()];
    for seed in 0..40 {
        streams.push(stream(&mut Rng::new(1000 + seed), 300, true));
    }
    let mut info_frames = 0;
    for (n, bytes) in streams.iter().enumerate() {
        for seed in 0..4 {
            let out = run(&chunked(bytes, seed, seed % 2 == 1), |_, _, _, _, _| {});
            let (r, c) = (&out.rust_stats, &out.c_stats);
            assert_eq!(
                out.c_frames, out.rust_frames,
                "stream {n}, seed {seed}: data frames"
            );
            assert_eq!(c[0], r[0], "stream {n}, seed {seed}: bytes");
            assert_eq!(c[1], r[1] + 77 * r[2], "stream {n}, seed {seed}: skipped");
            assert!(c[2] <= r[3], "stream {n}, seed {seed}: checksum failures");
            assert_eq!(c[3..], r[4..], "stream {n}, seed {seed}: packets");
            info_frames += r[2];
        }
    }
    assert!(info_frames > 100, "only {info_frames} info frames");
}
