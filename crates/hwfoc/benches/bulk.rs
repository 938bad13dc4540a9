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
//! - `v3_clean`, `v3_noisy`, `v4_clean`, `v4_noisy`, `hw5_clean`, `hw5_noisy`: the older
//!   protocols' decoders on ~8 MiB of their frames, with fields from the same flight profile:
//!   V3 (10-byte frames, no checksum), V4 (19-byte data frames back to back while running, and
//!   every 400 frames 20 idle ones, each after an info frame and with its `B9` trailer), HW5
//!   (32-byte telemetry frames with a CRC, after every 50 a ping request and the ESC's answer);
//!   the noisy streams as `noisy` (garbage runs, ~2% flipped, ~2% cut). V3 and V4 have no
//!   checksum: they lock on chains of frames, so after each break the frames until a new chain
//!   is confirmed are lost (the share found is printed before measuring).
//!
//! Each stream is measured four ways: the `frames` iterator over the whole buffer in a `for`
//! loop (`frames`: `Iterator::next` per frame), the same iterator consumed by `fold`
//! (`frames_fold`: the scanner's whole-buffer loop, what `scripts/instructions.sh` counts and
//! what `for_each`, `sum` and `count` run; `collect` into a `Vec` takes `next`), a `Decoder`
//! fed 64 KiB chunks then flushed, and a
//! `Decoder` pushed one byte at a time (the microcontroller path; on a 256 KiB slice only, as it
//! is much slower).
//!
//! Run: `cargo bench -p hwfoc --bench bulk` (about 30 s for the HW-FOC and DataLink streams,
//! 70 s more for V3, V4 and HW5, once built on a 2-core machine; add a filter such as
//! `-- noisy/frames` or `-- v4_` for some measurements). Before measuring, each stream is
//! decoded once and checked: every intact frame found (of the noisy V3 and V4 streams, the share
//! found is shown), `Decoder` and `frames` in agreement.
//!
//! Each HW-FOC and DataLink stream is also read the default way (`detect_clean`, ...,
//! `detect_datalink_noisy`): a `detect::Decoder` fed the whole buffer, as every reader does
//! unless a protocol is forced, which locks both onto the mixed scanner ([`detect_once`]).
//!
//! With `HWFOC_BULK_ONCE=clean` (or `noisy`, `hostile`) in the environment, the bench instead
//! makes that stream, checks it, decodes it once with `frames` in [`decode_once`] and exits
//! (with `HWFOC_BULK_DECODES=N`, N times, 0 included): what `scripts/instructions.sh` counts the
//! instructions of (cachegrind: a run with one decode less one with none). With `detect_`
//! before the stream's name (`HWFOC_BULK_ONCE=detect_noisy`), the decode is [`detect_once`]'s.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkGroup, Criterion, Throughput, criterion_group};
use hwfoc::Status;
use hwfoc::datalink::{self, FRAME_LEN};
use hwfoc::foc;
use hwfoc::foc::{DataFrame, Decoded, Decoder, FocFrame, InfoFrame, frames};
use hwfoc::scan::{Scan, Scanner, StreamDecoder};
use hwfoc::wire::Checksum;
use hwfoc::{detect, hw5, mixed, v3, v4};

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
    /// Offsets of the flipped and of the cut frames (kept by [`stream_of`] only).
    flipped: Vec<u64>,
    cut: Vec<u64>,
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
        FocFrame::Data(f) => u64::from(f.packet) ^ u64::from(f.status.0) << 16,
        FocFrame::Info(i) => u64::from(i.text()[16]),
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

/// The decoding paths of scanner `S` over `buf`, each decoded frame folded by `fold` (so that
/// nothing is optimised away): `frames` (bulk, a `for` loop: `Iterator::next`), `frames_fold`
/// (bulk, `Iterator::fold`: the loop [`decode_once`] runs for the instruction guard),
/// `feed_64k` (the streaming decoder fed 64 KiB chunks) and `push_256k` (a byte at a time, over
/// the first 256 KiB).
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
    g.bench_function("frames_fold", |b| {
        b.iter(|| black_box(Scan::<S>::new(black_box(buf)).fold(0u64, |acc, d| fold(acc, &d))))
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
        let mut frame = datalink::HubFrame::new(counter);
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

/// What a frame of a generated stream is: one the decoder hands on, or one it only counts (an
/// HW5 ping and its answer).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Made {
    Data,
    Info,
    Counted,
}

/// A stream of frames from `next` (which appends one frame's bytes and says what it is), back
/// to back up to [`STREAM_LEN`] and on until a data frame ends it; with `noisy`, garbage runs
/// before ~35% of frames, ~2% flipped and ~2% cut, as in [`noisy_stream`].
fn stream_of(
    noisy: bool,
    seed: u64,
    mut next: impl FnMut(&mut Vec<u8>) -> Made,
) -> (Vec<u8>, Expected) {
    let mut rng = Rng(seed);
    let mut buf = Vec::with_capacity(STREAM_LEN + 256);
    let mut frame = Vec::with_capacity(128);
    let mut e = Expected::default();
    let mut last = Made::Info;
    while buf.len() < STREAM_LEN || last != Made::Data {
        if noisy && rng.chance(350) {
            e.garbage_bytes += garbage(&mut rng, &mut buf, false);
        }
        frame.clear();
        last = next(&mut frame);
        if noisy && rng.chance(20) {
            let bit = rng.range(0, frame.len() as u32 * 8 - 1) as usize;
            frame[bit / 8] ^= 1 << (bit % 8);
            e.flipped_frames += 1;
            e.flipped.push(buf.len() as u64);
        } else if noisy && rng.chance(20) {
            let keep = rng.range(1, frame.len() as u32 - 1) as usize;
            frame.truncate(keep);
            e.cut_frames += 1;
            e.cut.push(buf.len() as u64);
        } else {
            match last {
                Made::Data => e.data_frames += 1,
                Made::Info => e.info_frames += 1,
                Made::Counted => {}
            }
            if last != Made::Counted {
                e.offsets.push(buf.len() as u64);
            }
        }
        buf.extend_from_slice(&frame);
    }
    (buf, e)
}

/// V3 frames (10 bytes, no checksum) following the same flight profile as HW-FOC's: throttle
/// and PWM scaled to 0..=255, the period of the eRPM (the start-up placeholder when stopped),
/// the 24-bit counter starting just before its wrap.
fn v3_stream(noisy: bool) -> (Vec<u8>, Expected) {
    let mut t = Telemetry::new(0x9B00_0064_0028_0026);
    let mut counter = 0xFF_FF00u32;
    stream_of(noisy, 0x0BAD_5EED_0000_0003, move |out| {
        let f = t.next_data();
        let erpm = u32::from(f.erpm_raw) * 10;
        let frame = v3::V3Frame {
            counter,
            throttle_in_raw: (u32::from(f.throttle_in_raw) * 255 / 1024) as u16,
            pwm_out_raw: (u32::from(f.throttle_out_raw) * 255 / 1024) as u16,
            period_us: match erpm {
                0 => v3::PLACEHOLDER_PERIOD_US,
                e => (v3::US_PER_MINUTE / e).min(65_535) as u16,
            },
        };
        counter = (counter + 1) & 0xFF_FFFF;
        out.extend_from_slice(&frame.encode());
        Made::Data
    })
}

/// V4 frames: running (19-byte data frames back to back), and every 400 frames 20 frames of
/// idle (an info frame before each data frame, which carries its `B9` trailer), the fields from
/// the HW-FOC flight profile within their 12-bit ADC ranges.
fn v4_stream(noisy: bool) -> (Vec<u8>, Expected) {
    let mut t = Telemetry::new(0x9B9B_03E8_0108_5B0B);
    let info = v4::InfoFrame {
        full_scale: 1000,
        v1: 8,
        v2: 91,
        i1: 11,
        i2: 2,
        i3: 1,
        t1: 0x21,
        t2: 0x21,
    };
    let mut counter = 0xFF_FF00u32;
    let mut step = 0u32;
    let mut info_next = false;
    stream_of(noisy, 0x0BAD_5EED_0000_0004, move |out| {
        let idle = step % 400 < 20;
        if idle && info_next {
            info_next = false;
            out.extend_from_slice(&info.encode());
            return Made::Info;
        }
        step += 1;
        info_next = true;
        let f = t.next_data();
        let mut frame = v4::DataFrame {
            counter,
            throttle_in_raw: f.throttle_in_raw.min(1000),
            throttle_out_raw: f.throttle_out_raw.min(1000),
            erpm: u32::from(f.erpm_raw) * 10,
            voltage_adc: (u32::from(f.voltage_raw) * 91 / 8).min(4095) as u16,
            current_adc: (f.current_raw.max(0) / 4).min(4095) as u16,
            temp_adc: u16::from(f.mos_adc) * 16,
            temp2_adc: u16::from(f.cap_adc) * 16,
        };
        counter = (counter + 1) & 0xFF_FFFF;
        if idle {
            frame.throttle_in_raw = 0;
            frame.throttle_out_raw = 0;
            frame.erpm = 0;
            out.extend_from_slice(&frame.encode_with_trailer());
        } else {
            out.extend_from_slice(&frame.encode());
        }
        Made::Data
    })
}

/// HW5 telemetry frames (32 bytes, CRC-16/MODBUS) from the HW-FOC flight profile, and after
/// every 50 a flight controller's ping request and the ESC's 11-byte answer (counted, not
/// handed on), as on a half-duplex wire.
fn hw5_stream(noisy: bool) -> (Vec<u8>, Expected) {
    let mut t = Telemetry::new(0xFE01_0003_305C_1706);
    let mut ping = [0u8; 11];
    ping[..6].copy_from_slice(&[0xFE, 0x01, 0x00, 0x03, 0x2C, 0x24]);
    ping[6..9].copy_from_slice(&[0x00, 0x01, 0x02]);
    Checksum::Crc16Modbus.seal(&mut ping);
    let request = [0x01, 0xFD, 0x03, 0x03, 0x2C, 0x24, 0x00, 0x01, 0x60, 0x60];
    let mut n = 0u32;
    stream_of(noisy, 0x0BAD_5EED_0000_0005, move |out| {
        n += 1;
        match n % 52 {
            50 => {
                out.extend_from_slice(&request);
                return Made::Counted;
            }
            51 => {
                out.extend_from_slice(&ping);
                return Made::Counted;
            }
            _ => {}
        }
        let f = t.next_data();
        let frame = hw5::TelemetryFrame {
            throttle: (u32::from(f.throttle_in_raw) * 100 / 1024) as u8,
            fault: hw5::FaultCode(if f.status.0 != 0 {
                1 << (f.status.0.trailing_zeros() % 8)
            } else {
                0
            }),
            erpm_raw: f.erpm_raw,
            voltage_raw: f.voltage_raw * 2,
            current_raw: (f.current_raw.max(0) / 6) as u16,
            esc_temp: f.mos_adc / 4,
            bec_temp: f.cap_adc / 5,
            motor_temp: f.mos_adc / 3,
            bec_voltage_raw: 84,
            bec_current_raw: 12,
            ..Default::default()
        };
        out.extend_from_slice(&frame.encode());
        Made::Data
    })
}

/// Decodes a V3, V4 or HW5 stream once with the bulk iterator and checks it against the
/// streaming decoder (the same frames and statistics) and against what was made: on a clean
/// stream exactly the frames made; on a noisy one, for HW5 (a CRC) exactly the intact frames,
/// for V3 and V4 (no checksum, frames taken by chains) the share of intact frames found is
/// shown, and so are the frames found elsewhere: flipped frames that stayed plausible and
/// chained (about half of all single-bit flips, as `v3`'s and `v4`'s documentation says), cut
/// frames completed by the next frame's bytes into a plausible chained frame (as `v3`'s test
/// `a_cut_frame_that_stays_plausible_is_taken` shows), and anything else (garbage), which must
/// be rare.
fn check_scanner<S: Scanner>(
    name: &str,
    buf: &[u8],
    e: &Expected,
    noisy: bool,
    exact: bool,
    offset: impl Fn(&S::Item) -> u64,
) where
    S::Item: PartialEq + std::fmt::Debug,
    S::Stats: PartialEq + std::fmt::Display,
{
    let mut it = Scan::<S>::new(buf);
    let decoded: Vec<S::Item> = it.by_ref().collect();
    let s = it.stats().clone();
    let offsets: Vec<u64> = decoded.iter().map(&offset).collect();
    let found = e
        .offsets
        .iter()
        .filter(|o| offsets.binary_search(o).is_ok())
        .count();
    let elsewhere: Vec<u64> = offsets
        .iter()
        .filter(|o| e.offsets.binary_search(o).is_err())
        .copied()
        .collect();
    let flipped = elsewhere
        .iter()
        .filter(|o| e.flipped.binary_search(o).is_ok())
        .count();
    let cut = elsewhere
        .iter()
        .filter(|o| e.cut.binary_search(o).is_ok())
        .count();
    let extra = elsewhere.len() - flipped - cut;
    if !noisy || exact {
        assert_eq!(offsets, e.offsets, "{name}: exactly the intact frames");
    } else {
        assert!(
            extra * 1000 < decoded.len(),
            "{name}: {extra} frames not made"
        );
    }
    eprintln!(
        "{name}: {} bytes, {} data + {} info frames, {} garbage bytes ({:.1}%), {} flipped-bit \
         frames, {} cut frames; found {found} of the intact frames ({:.1}%), {flipped} flipped \
         ones, {cut} cut ones and {extra} more\n  \
         decoder: {s}",
        buf.len(),
        e.data_frames,
        e.info_frames,
        e.garbage_bytes,
        100.0 * e.garbage_bytes as f64 / buf.len() as f64,
        e.flipped_frames,
        e.cut_frames,
        100.0 * found as f64 / e.offsets.len() as f64,
    );
    let mut dec = StreamDecoder::<S>::new();
    let mut all = Vec::with_capacity(decoded.len());
    for chunk in buf.chunks(CHUNK) {
        dec.feed(chunk, |d| all.push(d));
    }
    dec.flush(|d| all.push(d));
    assert!(all == decoded, "{name}: Decoder and frames() disagree");
    assert!(*dec.stats() == s, "{name}: statistics disagree");
}

/// Something from every V3 frame, so that no decoding work can be optimised away.
#[inline(always)]
fn fold_v3(acc: u64, d: &v3::Decoded) -> u64 {
    acc.wrapping_mul(31)
        .wrapping_add(u64::from(d.frame.counter) ^ u64::from(d.frame.period_us) << 24 ^ d.offset)
}

/// Something from every V4 frame.
#[inline(always)]
fn fold_v4(acc: u64, d: &v4::Decoded) -> u64 {
    let v = match d.frame {
        v4::V4Frame::Data(f) => u64::from(f.frame.counter) ^ u64::from(f.frame.voltage_adc) << 24,
        v4::V4Frame::Info(i) => u64::from(i.full_scale),
    };
    acc.wrapping_mul(31).wrapping_add(v ^ d.offset)
}

/// Something from every HW5 telemetry frame.
#[inline(always)]
fn fold_hw5(acc: u64, d: &hw5::Decoded) -> u64 {
    acc.wrapping_mul(31)
        .wrapping_add(u64::from(d.frame.erpm_raw) ^ u64::from(d.frame.voltage_raw) << 16 ^ d.offset)
}

/// The V3, V4 and HW5 decoders, each on a clean and a noisy stream.
fn older(c: &mut Criterion) {
    for noisy in [false, true] {
        let kind = if noisy { "noisy" } else { "clean" };

        let name = format!("v3_{kind}");
        let (buf, e) = v3_stream(noisy);
        check_scanner::<v3::Scanner>(&name, &buf, &e, noisy, false, |d| d.offset);
        let mut g = c.benchmark_group(&name);
        bench_decoder::<v3::Scanner>(&mut g, &buf, fold_v3);
        g.finish();

        let name = format!("v4_{kind}");
        let (buf, e) = v4_stream(noisy);
        check_scanner::<v4::Scanner>(&name, &buf, &e, noisy, false, |d| d.offset);
        let mut g = c.benchmark_group(&name);
        bench_decoder::<v4::Scanner>(&mut g, &buf, fold_v4);
        g.finish();

        let name = format!("hw5_{kind}");
        let (buf, e) = hw5_stream(noisy);
        check_scanner::<hw5::Scanner>(&name, &buf, &e, noisy, true, |d| d.offset);
        let mut g = c.benchmark_group(&name);
        bench_decoder::<hw5::Scanner>(&mut g, &buf, fold_hw5);
        g.finish();
    }
}

/// Something from every frame `detect` hands on (an ESC's or a hub's, as [`fold`] and
/// [`fold_datalink`] take them), so that no decoding work can be optimised away.
#[inline(always)]
fn fold_detected(acc: u64, d: &detect::Decoded) -> u64 {
    match d {
        detect::Decoded::Mixed(mixed::Decoded::Esc(d)) => fold(acc, d),
        detect::Decoded::Mixed(mixed::Decoded::Hub(d)) => fold_datalink(acc, d),
        other => acc.wrapping_mul(31).wrapping_add(other.offset()),
    }
}

/// One decode of `buf` by a `detect::Decoder` fed the whole buffer: the default path.
#[inline(never)]
fn detect_once(buf: &[u8]) -> u64 {
    let mut acc = 0;
    let mut d = detect::Decoder::new();
    d.feed(black_box(buf), |x| acc = fold_detected(acc, &x));
    d.flush(|x| acc = fold_detected(acc, &x));
    acc
}

/// The default path over `buf` as group `name`: a `detect::Decoder` fed the whole buffer, as
/// every reader does unless a protocol is forced (HW-FOC and DataLink locked onto
/// [`mixed`]'s scanner), once checked to find the frames at `offsets` (the format's own
/// decoder's).
fn bench_detect(c: &mut Criterion, name: &str, buf: &[u8], offsets: &[u64]) {
    let mut found = Vec::with_capacity(offsets.len());
    let mut d = detect::Decoder::new();
    d.feed(buf, |x| found.push(x.offset()));
    d.flush(|x| found.push(x.offset()));
    assert_eq!(
        found, offsets,
        "{name}: detect and the format's own decoder disagree"
    );
    let mut g = c.benchmark_group(name);
    g.throughput(Throughput::Bytes(buf.len() as u64));
    g.bench_function("feed", |b| b.iter(|| black_box(detect_once(buf))));
    g.finish();
}

fn bulk(c: &mut Criterion) {
    for (name, noisy) in [("datalink_clean", false), ("datalink_noisy", true)] {
        let (buf, expected) = datalink_stream(noisy);
        check_datalink(name, &buf, &expected);
        let mut g = c.benchmark_group(name);
        bench_decoder::<datalink::Scanner>(&mut g, &buf, fold_datalink);
        g.finish();
        let offsets: Vec<u64> = datalink::frames(&buf).map(|d| d.offset).collect();
        bench_detect(c, &format!("detect_{name}"), &buf, &offsets);
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
        let offsets: Vec<u64> = frames(&buf).map(|d| d.offset).collect();
        bench_detect(c, &format!("detect_{name}"), &buf, &offsets);
    }
}

/// One bulk decode of `buf` (the function whose instructions `scripts/instructions.sh` counts):
/// `Iterator::fold`, the loop the criterion bench's `frames_fold` measurement times.
#[inline(never)]
fn decode_once(buf: &[u8]) -> u64 {
    frames(black_box(buf)).fold(0, |acc, d| fold(acc, &d))
}

/// The `HWFOC_BULK_ONCE` mode (see the module's documentation): one stream decoded once.
fn once(name: &str) {
    let (stream, detected) = match name.strip_prefix("detect_") {
        Some(stream) => (stream, true),
        None => (name, false),
    };
    let (buf, expected) = match stream {
        "clean" => clean_stream(),
        "noisy" => noisy_stream(false),
        "hostile" => noisy_stream(true),
        _ => {
            eprintln!(
                "HWFOC_BULK_ONCE={name}: not a stream (clean, noisy, hostile, each also with \
                 detect_ before it)"
            );
            std::process::exit(2);
        }
    };
    check(name, &buf, &expected);
    let decodes: u32 = match std::env::var("HWFOC_BULK_DECODES").map(|n| n.parse()) {
        Err(_) => 1,
        Ok(Ok(n)) => n,
        Ok(Err(e)) => {
            eprintln!("HWFOC_BULK_DECODES: not a count ({e})");
            std::process::exit(2);
        }
    };
    for _ in 0..decodes {
        let fold = if detected {
            detect_once(&buf)
        } else {
            decode_once(&buf)
        };
        println!("{name}: {} bytes, fold {fold:x}", buf.len());
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    targets = bulk, older
}
fn main() {
    if let Ok(name) = std::env::var("HWFOC_BULK_ONCE") {
        once(&name);
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
