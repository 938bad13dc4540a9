//! Throughput of the bulk and streaming decoders on two ~8 MiB synthetic streams.
//!
//! - `clean`: back-to-back data frames with realistic, varying fields and incrementing packet
//!   numbers (wrapping past 65535), a device-information frame after every 20 data frames.
//! - `noisy`: the same frames with about 30% of the bytes in garbage runs (1..=64 uniformly
//!   random bytes, as line noise is), ~2% of frames with one flipped bit and ~2% cut short.
//! - `hostile`: the same, but the garbage is rich in `0x9B` and fake `9B 16` / `9B 4C` headers:
//!   some 365 000 rejected candidate frames in 8 MiB, one every ~23 bytes, far denser than real
//!   line noise (where a header-like `9B 16` comes once in 65 536 random byte pairs): a worst
//!   case for the scanner.
//!
//! - `datalink_clean`, `datalink_noisy`: the DataLink V2 decoder on ~8 MiB of back-to-back hub
//!   frames (160 bytes, 6 of 8 slots filled from 6 independent ESC profiles, counter +1), then the
//!   same frames with garbage runs as in `noisy` before ~35% of frames, ~2% flipped and ~2% cut.
//!
//! Each stream is measured three ways: the `frames` iterator over the whole buffer, a `Decoder`
//! fed 64 KiB chunks then flushed, and a `Decoder` pushed one byte at a time (the
//! microcontroller path; on a 256 KiB slice only, as it is much slower).
//!
//! Run: `cargo bench -p hwfoc --bench bulk` (about 30 s once built on a 2-core machine; add a
//! filter such as `-- noisy/frames` for one measurement). Before measuring, each stream is
//! decoded once and checked: every intact frame found, `Decoder` and `frames` in agreement.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkGroup, Criterion, Throughput, criterion_group, criterion_main};
use hwfoc::Status;
use hwfoc::datalink::{self, FRAME_LEN};
use hwfoc::foc;
use hwfoc::foc::{DataFrame, Decoded, Decoder, Frame, InfoFrame, frames};
use hwfoc::scan::{Scan, Scanner, StreamDecoder};

/// Size of each generated stream.
const STREAM_LEN: usize = 8 << 20;
/// Chunk size for the `Decoder::feed` benchmark.
const CHUNK: usize = 64 << 10;
/// Prefix decoded by the byte-at-a-time benchmark.
const PUSH_LEN: usize = 256 << 10;
/// A device-information frame follows every this many data frames.
const INFO_EVERY: u32 = 20;

/// xorshift64* (Vigna): deterministic, dependency-free, good enough for test data.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `lo..=hi` (the slight modulo bias does not matter here).
    fn range(&mut self, lo: u32, hi: u32) -> u32 {
        lo + ((self.next_u64() >> 32) % u64::from(hi - lo + 1)) as u32
    }

    /// True with probability `per_mille / 1000`.
    fn chance(&mut self, per_mille: u32) -> bool {
        self.range(0, 999) < per_mille
    }

    fn byte(&mut self) -> u8 {
        (self.next_u64() >> 56) as u8
    }
}

/// Produces the sequence of frames both streams carry: a slowly varying flight profile.
struct Telemetry {
    rng: Rng,
    packet: u16,
    throttle: i32,
    data_since_info: u32,
    infos: [[u8; 77]; 2],
}

impl Telemetry {
    fn new(seed: u64) -> Self {
        let infos = [
            InfoFrame::new("XR_FOC_ESC", "HW577_KZ1_V1.1", "XR-01.0.00", "01040443"),
            InfoFrame::new("X8_FOC", "HW1106_V1.0", "X8-02.1.03", "00731a9f"),
        ]
        .map(|i| i.expect("valid info fields").encode());
        Telemetry {
            rng: Rng(seed),
            // Start close to the wrap so the stream crosses 65535 -> 0.
            packet: 65_000,
            throttle: 0,
            data_since_info: 0,
            infos,
        }
    }

    /// The wire bytes of the next frame (data or info) and whether it is a data frame.
    fn next_frame(&mut self, out: &mut Vec<u8>) -> bool {
        if self.data_since_info == INFO_EVERY {
            self.data_since_info = 0;
            let which = self.rng.range(0, 1) as usize;
            out.extend_from_slice(&self.infos[which]);
            return false;
        }
        self.data_since_info += 1;
        let frame = self.next_data();
        out.extend_from_slice(&frame.encode());
        true
    }

    /// The next data frame's fields.
    fn next_data(&mut self) -> DataFrame {
        let r = &mut self.rng;
        // Throttle random-walks between idle and full; the other fields follow it loosely.
        self.throttle = (self.throttle + r.range(0, 80) as i32 - 40).clamp(0, 1024);
        let thr = self.throttle as u16;
        let thr_out = thr.saturating_sub(r.range(0, 20) as u16).min(1024);
        let erpm = if thr == 0 {
            0
        } else {
            (u32::from(thr) * 12 + r.range(0, 400)) as u16
        };
        let volt = (252 - i32::from(thr) / 40 + r.range(0, 6) as i32 - 3) as u16;
        // Input current, /64 A: regenerative braking sometimes goes negative.
        let current = i32::from(thr) * 6 + r.range(0, 200) as i32 - 120;
        let phase = current * 3 / 2 + r.range(0, 64) as i32;
        let status = if r.chance(5) { 1 << r.range(0, 15) } else { 0 };
        let frame = DataFrame {
            packet: self.packet,
            throttle_in_raw: thr,
            throttle_out_raw: thr_out,
            erpm_raw: erpm,
            voltage_raw: volt,
            current_raw: current.clamp(-32768, 32767) as i16,
            phase_current_raw: phase.clamp(-32768, 32767) as i16,
            mos_adc: r.range(150, 240) as u8,
            cap_adc: r.range(170, 240) as u8,
            status: Status(status),
        };
        // A rare duplicate, as seen on a real ESC; otherwise +1.
        if !r.chance(1) {
            self.packet = self.packet.wrapping_add(1);
        }
        frame
    }
}

/// What a generated stream holds, to check the decoders against.
#[derive(Debug, Default)]
struct Expected {
    /// Offsets of the intact frames, in order.
    offsets: Vec<u64>,
    data_frames: u32,
    info_frames: u32,
    garbage_bytes: usize,
    flipped_frames: u32,
    cut_frames: u32,
}

fn clean_stream() -> (Vec<u8>, Expected) {
    let mut t = Telemetry::new(0x9B16_0102_DEAD_BEEF);
    let mut buf = Vec::with_capacity(STREAM_LEN + 128);
    let mut e = Expected::default();
    while buf.len() < STREAM_LEN {
        e.offsets.push(buf.len() as u64);
        if t.next_frame(&mut buf) {
            e.data_frames += 1;
        } else {
            e.info_frames += 1;
        }
    }
    (buf, e)
}

/// A garbage run of random bytes; `hostile` makes it dense in 0x9B and fake headers.
fn garbage(rng: &mut Rng, out: &mut Vec<u8>, hostile: bool) -> usize {
    let len = rng.range(1, 64) as usize;
    let start = out.len();
    while out.len() - start < len {
        if !hostile {
            out.push(rng.byte());
            continue;
        }
        match rng.range(0, 15) {
            0 | 1 => out.push(0x9B),
            2 => out.extend_from_slice(&[0x9B, 0x16]),
            3 => out.extend_from_slice(&[0x9B, 0x4C]),
            4 => out.extend_from_slice(&[0x9B, 0x16, 0x01, 0x02]),
            _ => out.push(rng.byte()),
        }
    }
    out.truncate(start + len);
    len
}

fn noisy_stream(hostile: bool) -> (Vec<u8>, Expected) {
    let mut t = Telemetry::new(0x9B16_0102_DEAD_BEEF);
    let mut rng = Rng(0x0BAD_5EED_1234_5678);
    let mut buf = Vec::with_capacity(STREAM_LEN + 256);
    let mut frame = Vec::with_capacity(80);
    let mut e = Expected::default();
    while buf.len() < STREAM_LEN {
        // Mean run 32.5 bytes, mean frame ~26.5 bytes: a run before ~35% of frames gives ~30%.
        if rng.chance(350) {
            e.garbage_bytes += garbage(&mut rng, &mut buf, hostile);
        }
        frame.clear();
        let is_data = t.next_frame(&mut frame);
        if rng.chance(20) {
            // One flipped bit: caught by the checksum (or breaks the header).
            let bit = rng.range(0, frame.len() as u32 * 8 - 1) as usize;
            frame[bit / 8] ^= 1 << (bit % 8);
            e.flipped_frames += 1;
            buf.extend_from_slice(&frame);
        } else if rng.chance(20) {
            // Cut short: the line dropped out mid-frame.
            let keep = rng.range(1, frame.len() as u32 - 1) as usize;
            e.cut_frames += 1;
            buf.extend_from_slice(&frame[..keep]);
        } else {
            e.offsets.push(buf.len() as u64);
            buf.extend_from_slice(&frame);
            if is_data {
                e.data_frames += 1;
            } else {
                e.info_frames += 1;
            }
        }
    }
    (buf, e)
}

/// Something from every frame, so that no decoding work can be optimised away.
#[inline(always)]
fn fold(acc: u64, d: &Decoded) -> u64 {
    let v = match d.frame {
        Frame::Data(f) => u64::from(f.packet) ^ u64::from(f.status.0) << 16,
        Frame::Info(i) => u64::from(i.text()[16]),
    };
    acc.wrapping_mul(31).wrapping_add(v ^ d.offset)
}

/// Decodes `buf` once with `frames` and checks the result against what was generated.
///
/// Every intact frame must be found. A few more may be: a cut frame that the following bytes
/// happen to complete, or garbage behind a fake header, whose checksum matches by chance. Those
/// are valid frames on the wire (the checksum cannot tell), counted and shown.
fn check(name: &str, buf: &[u8], e: &Expected) {
    let mut it = frames(buf);
    let decoded: Vec<Decoded> = it.by_ref().collect();
    let s = *it.stats();
    let offsets: Vec<u64> = decoded.iter().map(|d| d.offset).collect();
    let missing = e
        .offsets
        .iter()
        .filter(|o| offsets.binary_search(o).is_err());
    assert_eq!(missing.count(), 0, "{name}: intact frames not decoded");
    let extra: Vec<u64> = offsets
        .iter()
        .filter(|o| e.offsets.binary_search(o).is_err())
        .copied()
        .collect();
    // A checksum is 16 bits (an info frame's only 8), so the ~365 000 rejected candidates
    // of the noisy stream let a handful of chance frames through; more would be a decoder bug.
    assert!(
        extra.len() * 10_000 < decoded.len(),
        "{name}: {} chance frames",
        extra.len()
    );
    eprintln!(
        "{name}: {} bytes, {} data + {} info frames, {} garbage bytes ({:.1}%), \
         {} flipped-bit frames, {} cut frames; decoded {} more formed by chance\n  \
         decoder: {s}",
        buf.len(),
        e.data_frames,
        e.info_frames,
        e.garbage_bytes,
        100.0 * e.garbage_bytes as f64 / buf.len() as f64,
        e.flipped_frames,
        e.cut_frames,
        extra.len(),
    );
    let mut dec = Decoder::new();
    let mut all = Vec::with_capacity(decoded.len());
    dec.decode_all(buf, |d| all.push(d));
    assert_eq!(all, decoded, "{name}: Decoder and frames() disagree");
    assert_eq!(
        *dec.stats(),
        s,
        "{name}: Decoder and frames() statistics disagree"
    );
}

/// The three decoding paths of scanner `S` over `buf`, each decoded frame folded by `fold` (so
/// that nothing is optimised away): `frames` (bulk), `feed_64k` (the streaming decoder fed
/// 64 KiB chunks) and `push_256k` (a byte at a time, over the first 256 KiB).
fn bench_decoder<S: Scanner>(
    g: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>,
    buf: &[u8],
    fold: impl Fn(u64, &S::Item) -> u64 + Copy,
) {
    g.throughput(Throughput::Bytes(buf.len() as u64));
    g.bench_function("frames", |b| {
        b.iter(|| {
            let mut acc = 0u64;
            for d in Scan::<S>::new(black_box(buf)) {
                acc = fold(acc, &d);
            }
            black_box(acc)
        })
    });
    g.bench_function("feed_64k", |b| {
        b.iter(|| {
            let mut acc = 0u64;
            let mut dec = StreamDecoder::<S>::new();
            for chunk in black_box(buf).chunks(CHUNK) {
                dec.feed(chunk, |d| acc = fold(acc, &d));
            }
            dec.flush(|d| acc = fold(acc, &d));
            black_box(dec.stats());
            black_box(acc)
        })
    });
    let small = &buf[..PUSH_LEN];
    g.throughput(Throughput::Bytes(small.len() as u64));
    g.bench_function("push_256k", |b| {
        b.iter(|| {
            let mut acc = 0u64;
            let mut dec = StreamDecoder::<S>::new();
            for &byte in black_box(small) {
                dec.push(byte, |d| acc = fold(acc, &d));
            }
            dec.flush(|d| acc = fold(acc, &d));
            black_box(dec.stats());
            black_box(acc)
        })
    });
}

/// A DataLink stream: back-to-back hub frames of 6 ESCs, or with noise as in [`noisy_stream`].
fn datalink_stream(noisy: bool) -> (Vec<u8>, Expected) {
    let mut escs: Vec<Telemetry> = (0..6u64)
        .map(|i| Telemetry::new(0x9B9E_0102_0000_0001 + i * 0x1111))
        .collect();
    let mut rng = Rng(0xDA7A_11E4_0000_5EED);
    let mut buf = Vec::with_capacity(STREAM_LEN + 512);
    let mut e = Expected::default();
    let mut counter = 0u16;
    while buf.len() < STREAM_LEN {
        if noisy && rng.chance(350) {
            e.garbage_bytes += garbage(&mut rng, &mut buf, false);
        }
        let mut frame = datalink::Frame::new(counter);
        counter = counter.wrapping_add(1);
        for (slot, esc) in frame.slots.iter_mut().zip(&mut escs) {
            *slot = Some(esc.next_data());
        }
        let mut bytes = frame.encode();
        if noisy && rng.chance(20) {
            let bit = rng.range(0, FRAME_LEN as u32 * 8 - 1) as usize;
            bytes[bit / 8] ^= 1 << (bit % 8);
            e.flipped_frames += 1;
            buf.extend_from_slice(&bytes);
        } else if noisy && rng.chance(20) {
            let keep = rng.range(1, FRAME_LEN as u32 - 1) as usize;
            e.cut_frames += 1;
            buf.extend_from_slice(&bytes[..keep]);
        } else {
            e.offsets.push(buf.len() as u64);
            e.data_frames += 1;
            buf.extend_from_slice(&bytes);
        }
    }
    (buf, e)
}

/// Something from every DataLink frame, so that no decoding work can be optimised away.
#[inline(always)]
fn fold_datalink(acc: u64, d: &datalink::Decoded) -> u64 {
    let v = d.frame.slots[5].map_or(0, |e| u64::from(e.packet) ^ u64::from(e.status.0) << 16);
    acc.wrapping_mul(31)
        .wrapping_add(v ^ d.offset ^ u64::from(d.frame.counter))
}

/// Decodes a DataLink stream once and checks it: every intact frame found, no chance frame,
/// the streaming decoder in agreement.
fn check_datalink(name: &str, buf: &[u8], e: &Expected) {
    let mut it = datalink::frames(buf);
    let decoded: Vec<datalink::Decoded> = it.by_ref().collect();
    let s = *it.stats();
    let offsets: Vec<u64> = decoded.iter().map(|d| d.offset).collect();
    assert_eq!(offsets, e.offsets, "{name}: exactly the intact frames");
    assert!(decoded.iter().all(|d| d.frame.escs().count() == 6));
    eprintln!(
        "{name}: {} bytes, {} frames, {} garbage bytes ({:.1}%), {} flipped-bit frames, {} cut \
         frames\n  decoder: {s}",
        buf.len(),
        e.data_frames,
        e.garbage_bytes,
        100.0 * e.garbage_bytes as f64 / buf.len() as f64,
        e.flipped_frames,
        e.cut_frames,
    );
    let mut dec = datalink::Decoder::new();
    let mut all = Vec::with_capacity(decoded.len());
    dec.decode_all(buf, |d| all.push(d));
    assert_eq!(
        all, decoded,
        "{name}: datalink::Decoder and frames() disagree"
    );
    assert_eq!(*dec.stats(), s, "{name}: statistics disagree");
}

fn bulk(c: &mut Criterion) {
    for (name, noisy) in [("datalink_clean", false), ("datalink_noisy", true)] {
        let (buf, expected) = datalink_stream(noisy);
        check_datalink(name, &buf, &expected);
        let mut g = c.benchmark_group(name);
        bench_decoder::<datalink::Scanner>(&mut g, &buf, fold_datalink);
        g.finish();
    }
    let streams = [
        ("clean", clean_stream()),
        ("noisy", noisy_stream(false)),
        ("hostile", noisy_stream(true)),
    ];
    for (name, (buf, expected)) in streams {
        check(name, &buf, &expected);
        let mut g = c.benchmark_group(name);
        bench_decoder::<foc::Scanner>(&mut g, &buf, fold);
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    targets = bulk
}
criterion_main!(benches);
