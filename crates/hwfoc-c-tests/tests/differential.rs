//! The differential test: `c/hwfoc.h`'s decoders and the Rust codec's, given the same streams
//! in the same random chunkings (feeds, single pushed bytes, silences of the line, a final
//! flush), hand on the same frames and keep the same statistics after every call. The streams:
//! the three real captures (each read by every decoder, the others' bytes being noise to it),
//! encoder-made streams of every format with frames dropped, cut and corrupted, and random
//! bytes (proptest). The header's encoders write the bytes the Rust encoders write.

use std::sync::atomic::Ordering;

use hwfoc::{datalink, foc, hw5, v3, v4};
use hwfoc_c_tests::ffi::{self, Format};
use hwfoc_c_tests::ops::{Rng, VOLUME, disturb, foc_data_frame};
use hwfoc_c_tests::{Flat, Op, chunked, run_both};
use proptest::prelude::*;

const CAPTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../testdata/captures/");

/// A logic-analyser CSV export (`Time [s],Value,...`, one row per byte written `0xNN`): the
/// operations that replay it as a recorder would, a feed per run of bytes without a pause, a
/// silence for every pause longer than a 19200-baud frame could take, its length in frames.
fn capture_ops(name: &str) -> (Vec<u8>, Vec<Op>) {
    let path = format!("{CAPTURES}{name}");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut bytes = Vec::new();
    let mut ops = Vec::new();
    let mut run = Vec::new();
    let mut last_time = None;
    for line in text.lines().skip(1).filter(|l| !l.is_empty()) {
        let mut fields = line.split(',');
        let time: f64 = fields.next().and_then(|t| t.parse().ok()).expect("time");
        let value = fields
            .next()
            .and_then(|v| u8::from_str_radix(v.trim_start_matches("0x"), 16).ok())
            .unwrap_or_else(|| panic!("{name}: {line}"));
        if let Some(last) = last_time {
            let gap: f64 = time - last;
            if gap > 1.0 {
                ops.push(Op::Feed(std::mem::take(&mut run)));
                ops.push(Op::Silent((gap / 0.0125) as u32));
            }
        }
        last_time = Some(time);
        run.push(value);
        bytes.push(value);
    }
    ops.push(Op::Feed(run));
    ops.push(Op::Flush);
    (bytes, ops)
}

fn all_formats(ops: &[Op]) -> [usize; 5] {
    [
        run_both::<foc::Scanner>(ops).frame_count,
        run_both::<datalink::Scanner>(ops).frame_count,
        run_both::<v3::Scanner>(ops).frame_count,
        run_both::<v4::Scanner>(ops).frame_count,
        run_both::<hw5::Scanner>(ops).frame_count,
    ]
}

/// Every capture through every decoder: as recorded (with its silences), whole, and in 40
/// random chunkings each, the frames of each format's own capture counted.
#[test]
fn the_real_captures_decode_alike() {
    for (name, own, frames) in [
        ("xrotor-v4-pro-hv-80A.csv", 0, None),
        ("platinum-pro-v3.csv", 2, Some(699)),
        ("platinum-v4.csv", 3, Some(297 + 26)),
    ] {
        let (bytes, timed) = capture_ops(name);
        let counts = all_formats(&timed);
        assert!(counts[own] > 0, "{name}: no frame of its own format");
        let whole = all_formats(&[Op::Feed(bytes.clone()), Op::Flush]);
        if let Some(frames) = frames {
            assert_eq!(whole[own], frames, "{name}");
        }
        for seed in 0..40 {
            let chunked_counts = all_formats(&chunked(&bytes, seed, false));
            assert_eq!(chunked_counts, whole, "{name}, seed {seed}");
            all_formats(&chunked(&bytes, seed, true));
        }
    }
}

/// A V4 chain whose third data frame carries an info frame's fixed bytes (counter 0x9B0100, an
/// input throttle of 256, a voltage reading of 0x05B9) but no plausible info frame's constants:
/// both decoders read it as data, and all three frames are found.
#[test]
fn a_v4_data_frame_with_an_info_frames_fixed_bytes_decodes_alike() {
    let mut bytes = vec![0x00];
    for (counter, throttle_in_raw, voltage_adc) in [
        (0x9B_00FE, 0, 0),
        (0x9B_00FF, 0, 0),
        (0x9B_0100, 256, 0x05B9),
    ] {
        let frame = v4::DataFrame {
            counter,
            throttle_in_raw,
            voltage_adc,
            ..Default::default()
        };
        bytes.extend_from_slice(&frame.encode());
    }
    let counts = all_formats(&[Op::Feed(bytes), Op::Flush]);
    assert_eq!(counts[Format::V4 as usize], 3);
}

/// Random HW-FOC data and info frames, some dropped, duplicated, cut or corrupted, with noise.
fn foc_stream(rng: &mut Rng, frames: usize) -> Vec<u8> {
    let mut out = Vec::new();
    let mut packet = rng.bits() as u16;
    for _ in 0..frames {
        let mut bytes = foc_data_frame(rng, packet).encode().to_vec();
        if rng.below(12) == 0 {
            let text: [u8; 72] = core::array::from_fn(|_| 0x20 + rng.below(0x5F) as u8);
            bytes = foc::InfoFrame::from_text(text)
                .expect("ASCII")
                .encode()
                .to_vec();
            if rng.below(3) == 0 {
                // A byte that is not ASCII under a valid check byte: no frame.
                bytes[4 + rng.below(72) as usize] = 0x80 | rng.bits() as u8;
                bytes[76] = hwfoc::wire::sum16(&bytes[..76]) as u8;
            }
        }
        disturb(rng, &mut bytes, &[0x9B, 0x16, 0x4C, 0x01, 0x02]);
        out.extend(bytes);
        packet = packet.wrapping_add(step(rng) as u16);
    }
    out
}

/// A counter's next step: mostly 1, sometimes a repeat, a gap, a restart, or one back (after a
/// gap of one: two adjacent frames swapped).
fn step(rng: &mut Rng) -> u32 {
    match rng.below(30) {
        0 => 0,
        1 => 2 + rng.below(5) as u32,
        2 => rng.bits() as u32,
        3 => 2,
        4 => u32::MAX,
        _ => 1,
    }
}

fn datalink_stream(rng: &mut Rng, frames: usize) -> Vec<u8> {
    let mut out = Vec::new();
    let mut counter = rng.bits() as u16;
    let mut packets = [0u16; 8];
    for _ in 0..frames {
        let mut f = datalink::HubFrame::new(counter);
        for (ch, slot) in f.slots.iter_mut().enumerate() {
            if rng.below(4) != 0 {
                packets[ch] = packets[ch].wrapping_add(step(rng) as u16);
                *slot = Some(foc::DataFrame {
                    packet: packets[ch],
                    erpm_raw: rng.bits() as u16,
                    current_raw: rng.bits() as i16,
                    status: hwfoc::Status(rng.bits() as u16),
                    ..Default::default()
                });
            }
        }
        let length_byte = datalink::LengthByte::ALL[rng.below(2) as usize];
        let mut bytes = f.encode_as(length_byte).to_vec();
        if rng.below(20) == 0 {
            // A record on a channel beyond eight, or twice on one, under a valid CRC.
            bytes[6 + 19 * rng.below(8) as usize] = rng.below(10) as u8;
            let crc = hwfoc::wire::crc16_xmodem(&bytes[..158]);
            bytes[158..].copy_from_slice(&crc.to_le_bytes());
        }
        disturb(rng, &mut bytes, &[0x9B, 0x9E, 0xA0, 0x01, 0x02]);
        out.extend(bytes);
        counter = counter.wrapping_add(step(rng) as u16);
    }
    out
}

fn v3_stream(rng: &mut Rng, frames: usize) -> Vec<u8> {
    let mut out = Vec::new();
    let mut counter = rng.bits() as u32 & 0xFF_FFFF;
    for _ in 0..frames {
        let f = v3::V3Frame {
            counter,
            throttle_in_raw: rng.below(270) as u16,
            pwm_out_raw: rng.below(270) as u16,
            period_us: if rng.below(3) == 0 {
                v3::PLACEHOLDER_PERIOD_US
            } else {
                rng.bits() as u16
            },
        };
        let mut bytes = f.encode().to_vec();
        disturb(rng, &mut bytes, &[0x9B, 0x00]);
        out.extend(bytes);
        counter = counter.wrapping_add(step(rng)) & 0xFF_FFFF;
    }
    out
}

fn v4_stream(rng: &mut Rng, frames: usize) -> Vec<u8> {
    let mut out = Vec::new();
    let mut counter = rng.bits() as u32 & 0xFF_FFFF;
    let infos = [
        v4::InfoFrame {
            full_scale: 1000,
            v1: 8,
            v2: 91,
            i1: 0,
            i2: 0,
            i3: 0,
            t1: 0x10,
            t2: 0x20,
        },
        v4::InfoFrame {
            full_scale: 800,
            v1: 11,
            v2: 65,
            i1: 3,
            i2: 4,
            i3: 1,
            t1: 1,
            t2: 2,
        },
    ];
    let trailer = rng.below(2) == 0;
    for _ in 0..frames {
        if rng.below(8) == 0 {
            let mut info = infos[rng.below(2) as usize].encode().to_vec();
            disturb(rng, &mut info, &[0x9B, 0xB9, 0x01]);
            out.extend(info);
        }
        let f = v4::DataFrame {
            counter,
            throttle_in_raw: rng.below(1100) as u16,
            throttle_out_raw: rng.below(1100) as u16,
            erpm: rng.bits() as u32 & 0xFF_FFFF,
            voltage_adc: rng.below(4200) as u16,
            current_adc: rng.below(4200) as u16,
            temp_adc: rng.below(4200) as u16,
            temp2_adc: rng.below(4200) as u16,
        };
        let mut bytes = if trailer {
            f.encode_with_trailer().to_vec()
        } else {
            f.encode().to_vec()
        };
        disturb(rng, &mut bytes, &[0x9B, 0xB9, 0x01]);
        out.extend(bytes);
        counter = counter.wrapping_add(step(rng)) & 0xFF_FFFF;
    }
    out
}

fn hw5_stream(rng: &mut Rng, frames: usize) -> Vec<u8> {
    let mut out = Vec::new();
    for _ in 0..frames {
        let f = hw5::TelemetryFrame {
            // Mostly in range, a few over (rejected as out of range by both decoders).
            throttle: rng.below(110) as u8,
            unknown: [rng.bits() as u8, rng.bits() as u8],
            fault: hw5::FaultCode(rng.bits() as u8),
            erpm_raw: rng.bits() as u16,
            voltage_raw: rng.below(1100) as u16,
            current_raw: rng.bits() as u16,
            esc_temp: rng.bits() as u8,
            bec_temp: rng.bits() as u8,
            motor_temp: rng.bits() as u8,
            bec_voltage_raw: rng.bits() as u8,
            bec_current_raw: rng.bits() as u8,
        };
        let mut bytes = f.encode().to_vec();
        if rng.below(10) == 0 {
            // Another kind's frame: the header of a ping, a parameter frame, a request.
            let kind = hw5::Kind::ALL[1 + rng.below(7) as usize];
            let mut other = vec![0u8; kind.wire_len()];
            other[..3].copy_from_slice(&kind.envelope());
            other[hw5::TYPE_AT..hw5::TYPE_AT + 2].copy_from_slice(&kind.frame_type().to_le_bytes());
            hw5::CHECKSUM.seal(&mut other);
            bytes = other;
        }
        disturb(rng, &mut bytes, &[0xFE, 0x01, 0xFD, 0x00, 0x03]);
        out.extend(bytes);
    }
    out
}

/// Every format's encoder-made streams, disturbed, through every decoder in random chunkings.
#[test]
fn encoder_made_streams_decode_alike() {
    type Make = fn(&mut Rng, usize) -> Vec<u8>;
    let makers: [(Format, Make); 5] = [
        (Format::Foc, foc_stream),
        (Format::DataLink, datalink_stream),
        (Format::V3, v3_stream),
        (Format::V4, v4_stream),
        (Format::Hw5, hw5_stream),
    ];
    for (format, make) in makers {
        let mut own = 0;
        for seed in 0..60 {
            let mut rng = Rng::new(seed * 7919 + format as u64);
            let stream = make(&mut rng, 200);
            own += all_formats(&chunked(&stream, seed, seed % 2 == 0))[format as usize];
        }
        assert!(own > 60 * 50, "{format:?}: only {own} frames of its own");
    }
}

/// The header's encoders write what the Rust encoders write, for every frame the decoders
/// find in the encoder-made streams.
#[test]
fn the_encoders_write_the_same_bytes() {
    fn check<S: Flat>(stream: &[u8]) -> usize {
        let outcome = run_both::<S>(&[Op::Feed(stream.to_vec()), Op::Flush]);
        let mut n = 0;
        let mut frames = Vec::new();
        hwfoc::scan::Scan::<S>::new(stream).for_each(|item| {
            frames.clear();
            S::frame(&item, &mut frames);
            let c = ffi::encode(S::FORMAT, &frames);
            assert_eq!(c, S::encode(&item), "{:?} at {}", S::FORMAT, frames[0]);
            n += 1;
        });
        assert_eq!(n, outcome.frame_count);
        n
    }
    let mut rng = Rng::new(33);
    assert!(check::<foc::Scanner>(&foc_stream(&mut rng, 500)) > 100);
    assert!(check::<datalink::Scanner>(&datalink_stream(&mut rng, 500)) > 100);
    assert!(check::<v3::Scanner>(&v3_stream(&mut rng, 500)) > 100);
    assert!(check::<v4::Scanner>(&v4_stream(&mut rng, 500)) > 100);
    assert!(check::<hw5::Scanner>(&hw5_stream(&mut rng, 500)) > 100);
}

/// Bytes from an alphabet of the bytes the scanners look for, where random bytes would
/// rarely make a candidate.
fn adversarial_byte() -> impl Strategy<Value = u8> {
    prop_oneof![
        3 => prop::sample::select(vec![
            0x9B, 0x16, 0x4C, 0x01, 0x02, 0x9E, 0xA0, 0xB9, 0x00, 0xFE, 0xFD, 0x03, 0x30, 0x5C,
            0x17, 0x2C, 0x24, 0x35, 0x38,
        ]),
        1 => any::<u8>(),
    ]
}

proptest! {
    // No regression files: the project keeps none.
    #![proptest_config(ProptestConfig {
        cases: 400,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Random and adversarial bytes, and frames spliced into them, in random chunkings.
    #[test]
    fn random_bytes_decode_alike(
        noise in prop::collection::vec(adversarial_byte(), 0..600),
        random in prop::collection::vec(any::<u8>(), 0..300),
        seed in any::<u64>(),
        silences in any::<bool>(),
    ) {
        let mut rng = Rng::new(seed);
        let mut stream = noise;
        let splices = [
            foc_stream(&mut rng, 3),
            datalink_stream(&mut rng, 1),
            v3_stream(&mut rng, 4),
            v4_stream(&mut rng, 4),
            hw5_stream(&mut rng, 2),
            random,
        ];
        for splice in splices {
            let at = rng.below(stream.len() as u64 + 1) as usize;
            stream.splice(at..at, splice);
        }
        all_formats(&chunked(&stream, seed, silences));
    }
}

/// Printed at the end of the run (`--nocapture`): how much was compared.
#[test]
fn zz_volume() {
    // Runs with the others in parallel; it reports what has been compared when it runs, and
    // compares a little of its own so that the figure is never empty.
    all_formats(&[Op::Feed(vec![0x9B; 100]), Op::Flush]);
    eprintln!(
        "differential volume so far: {} streams, {} bytes, {} frames compared",
        VOLUME.streams.load(Ordering::Relaxed),
        VOLUME.bytes.load(Ordering::Relaxed),
        VOLUME.frames.load(Ordering::Relaxed),
    );
}
