//! Golden tests on the three real logic-analyser captures in `testdata/captures/` (copies of
//! `shared/captures/`, kept in the repository so that a clone alone passes; see
//! `testdata/README.md` for their source).

use hwfoc::foc::{DataFrame, Decoded, Decoder, FocFrame, InfoFrame};
use hwfoc::{Settings, foc};

use older::{PLATINUM_PRO_V3, PLATINUM_V4, XROTOR};

#[allow(dead_code)] // the property tests' generators
mod common;
#[allow(dead_code)] // the V3 and V4 tests' helpers
mod older;

const ALL: [&str; 3] = [XROTOR, PLATINUM_V4, PLATINUM_PRO_V3];

/// One capture: the byte values and, row for row, the time of each byte.
struct Capture {
    times: Vec<f64>,
    bytes: Vec<u8>,
}

/// Reads a logic-analyser CSV export (the loader of `older/mod.rs`).
fn load(name: &str) -> Capture {
    let (times, bytes) = older::load_timed(name);
    Capture { times, bytes }
}

/// The bulk path over the HW-FOC scanner (shared with the V3 and V4 tests).
fn bulk(bytes: &[u8]) -> (Vec<Decoded>, foc::Stats) {
    older::bulk::<foc::Scanner>(bytes)
}

fn streamed_bytewise(bytes: &[u8]) -> (Vec<Decoded>, foc::Stats) {
    common::streamed_bytewise::<foc::Scanner>(bytes)
}

fn streamed_chunks(bytes: &[u8], size: usize) -> (Vec<Decoded>, foc::Stats) {
    older::streamed_chunks::<foc::Scanner>(bytes, size)
}

fn data(decoded: &[Decoded]) -> Vec<(u64, DataFrame)> {
    decoded
        .iter()
        .filter_map(|d| match d.frame {
            FocFrame::Data(f) => Some((d.offset, f)),
            FocFrame::Info(_) => None,
        })
        .collect()
}

fn infos(decoded: &[Decoded]) -> Vec<(u64, InfoFrame)> {
    decoded
        .iter()
        .filter_map(|d| match d.frame {
            FocFrame::Info(f) => Some((d.offset, f)),
            FocFrame::Data(_) => None,
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// The CSV reader itself
// ---------------------------------------------------------------------------------------------

#[test]
fn csv_reader_reads_every_row() {
    let x = load(XROTOR);
    assert_eq!(x.bytes.len(), 7002);
    assert_eq!(x.times.len(), 7002);
    assert_eq!(x.times[0], 0.22798);
    assert_eq!(&x.bytes[..4], &[0x9B, 0x16, 0x01, 0x02]);
    assert!(x.times.windows(2).all(|w| w[0] < w[1]), "times increase");
    assert_eq!(load(PLATINUM_V4).bytes.len(), 6007);
    assert_eq!(load(PLATINUM_PRO_V3).bytes.len(), 6990);
}

// ---------------------------------------------------------------------------------------------
// XRotor v4 Pro HV 80A
// ---------------------------------------------------------------------------------------------

#[test]
fn xrotor_frame_counts_and_link_stats() {
    let x = load(XROTOR);
    let (decoded, stats) = bulk(&x.bytes);
    assert_eq!(data(&decoded).len(), 248);
    assert_eq!(infos(&decoded).len(), 12);
    assert_eq!(stats.frames(), 248);
    assert_eq!(stats.info_frames(), 12);
    assert_eq!(stats.checksum_failures(), 2);
    assert_eq!(stats.lost_packets(), 2);
    assert_eq!(stats.duplicate_packets(), 1);
    assert_eq!(stats.bytes(), 7002);
    // 1 lone 9B + 2 corrupted data frames + 1 info frame with a zeroed header.
    assert_eq!(stats.bytes_skipped(), 1 + 2 * 24 + 77);
    assert_eq!(stats.bytes(), 24 * 248 + 77 * 12 + stats.bytes_skipped());
    assert_eq!(stats.last_packet(), Some(1722));
    assert_eq!(stats.delivery_ratio(), Some(248.0 / 250.0));
}

#[test]
fn xrotor_packet_sequence() {
    let x = load(XROTOR);
    let (decoded, _) = bulk(&x.bytes);
    let packets: Vec<u16> = data(&decoded).iter().map(|(_, f)| f.packet).collect();
    assert_eq!(packets.first(), Some(&1474));
    assert_eq!(packets.last(), Some(&1722));
    let mut missing = Vec::new();
    let mut repeated = Vec::new();
    for w in packets.windows(2) {
        match w[1].wrapping_sub(w[0]) {
            0 => repeated.push(w[0]),
            1 => {}
            step => missing.extend((1..step).map(|k| w[0] + k)),
        }
    }
    assert_eq!(missing, [1562, 1631]);
    assert_eq!(repeated, [1719]);
    // 1474..=1722 is 249 numbers; two are missing and one is sent twice.
    assert_eq!(packets.len(), 249 - 2 + 1);
}

#[test]
fn xrotor_first_and_last_frames_with_times() {
    let x = load(XROTOR);
    let (decoded, _) = bulk(&x.bytes);
    let frames = data(&decoded);
    let (offset, first) = frames[0];
    assert_eq!(offset, 0);
    assert_eq!(x.times[offset as usize], 0.22798);
    assert_eq!(first.packet, 1474);
    let s = Settings::default();
    assert_eq!(first.voltage_v(), 24.7);
    assert_eq!(first.current_a(&s), -0.015625);
    assert_eq!(first.phase_current_a(&s), -0.015625);
    assert_eq!(first.mos_temp().celsius(), Some(28.0));
    assert_eq!(first.cap_temp().celsius(), Some(26.0));
    assert!(first.status.is_ok());

    let (offset, last) = *frames.last().unwrap();
    assert_eq!(last.packet, 1722);
    assert_eq!(offset, 6901);
    assert!((x.times[offset as usize] - 18.25539344).abs() < 1e-9);
    // The capture ends with an info frame after the last data frame.
    let (info_at, _) = *infos(&decoded).last().unwrap();
    assert_eq!(info_at, 6925);
    assert_eq!(info_at + 77, 7002);
}

#[test]
fn xrotor_corrupted_frames_are_not_decoded() {
    let x = load(XROTOR);
    let (decoded, _) = bulk(&x.bytes);
    // The two frames that only the checksum catches (see real_frames.rs).
    assert_eq!(x.bytes[2806..2810], [0x9b, 0x16, 0x01, 0x0a]);
    assert_eq!(x.bytes[4462 + 20..4462 + 22], [0x10, 0x00]);
    for bad in [2806, 4462] {
        assert!(DataFrame::parse(&x.bytes[bad..]).is_err());
        assert!(
            decoded.iter().all(|d| d.offset != bad as u64),
            "frame decoded at {bad}"
        );
    }
    // Every frame starts where the previous one (or a skipped region) ended: none overlap.
    for w in decoded.windows(2) {
        assert!(w[0].offset + w[0].frame.wire_len() as u64 <= w[1].offset);
    }
    // No decoded frame carries a fault flag: the corrupted status word was refused.
    assert!(data(&decoded).iter().all(|(_, f)| f.status.is_ok()));
}

#[test]
fn xrotor_lone_sync_byte_before_a_silence() {
    let x = load(XROTOR);
    let (decoded, _) = bulk(&x.bytes);
    assert_eq!(x.bytes[909], 0x9B);
    let gap = x.times[910] - x.times[909];
    assert!((0.54..0.545).contains(&gap), "{gap}");
    let next = decoded.iter().find(|d| d.offset > 909).unwrap();
    assert_eq!(next.offset, 910);
    assert!(matches!(next.frame, FocFrame::Data(f) if f.packet == 1483));
}

#[test]
fn xrotor_sync_byte_inside_a_payload() {
    let x = load(XROTOR);
    let (decoded, _) = bulk(&x.bytes);
    let frames = data(&decoded);
    let i = frames.iter().position(|(_, f)| f.packet == 0x069B).unwrap();
    assert_eq!(frames[i].0, 5902);
    assert_eq!(frames[i - 1].1.packet, 0x069A);
    assert_eq!(frames[i + 1].1.packet, 0x069C);
    assert_eq!(frames[i + 1].0, 5926);
}

#[test]
fn xrotor_voltage_jumps_during_braking() {
    let x = load(XROTOR);
    let (decoded, _) = bulk(&x.bytes);
    let frames = data(&decoded);
    let jump = frames
        .windows(2)
        .position(|w| w[1].1.voltage_raw > w[0].1.voltage_raw + 100)
        .expect("a voltage jump");
    let (before, after) = (frames[jump].1, frames[jump + 1].1);
    assert_eq!(before.voltage_v(), 24.7);
    assert_eq!(after.voltage_v(), 53.5);
    assert_eq!((before.packet, after.packet), (1650, 1651));
    let max = frames
        .iter()
        .map(|(_, f)| f.voltage_v())
        .fold(0.0, f32::max);
    assert_eq!(max, 53.5);
    // Elevated for about 0.3 s: from the jump to the first frame back at the supply voltage.
    let back = frames[jump + 1..]
        .iter()
        .find(|(_, f)| f.voltage_v() <= 24.8)
        .unwrap();
    let t_jump = x.times[frames[jump + 1].0 as usize];
    let t_back = x.times[back.0 as usize];
    let elevated = t_back - t_jump;
    assert!((0.25..0.4).contains(&elevated), "{elevated} s");
    // The braking frame carries the regenerative currents FF C2 and FE 4B.
    assert_eq!(after.current_raw, -62);
    assert_eq!(after.phase_current_raw, -437);
}

#[test]
fn xrotor_negative_currents_are_present() {
    let x = load(XROTOR);
    let (decoded, _) = bulk(&x.bytes);
    let frames = data(&decoded);
    let s = Settings::default();
    let negative = frames.iter().filter(|(_, f)| f.current_a(&s) < 0.0).count();
    assert!(negative > 100, "{negative}");
    let min_in = frames.iter().map(|(_, f)| f.current_raw).min().unwrap();
    let min_phase = frames
        .iter()
        .map(|(_, f)| f.phase_current_raw)
        .min()
        .unwrap();
    assert_eq!(min_in, -62);
    assert_eq!(min_phase, -437);
    // Read as int16, idle currents are small: never below -1 A or above 100 A at 1/64 A.
    for (_, f) in &frames {
        let a = f.current_a(&s);
        assert!((-1.0..100.0).contains(&a), "packet {}: {a} A", f.packet);
    }
}

#[test]
fn xrotor_info_frames() {
    let x = load(XROTOR);
    let (decoded, _) = bulk(&x.bytes);
    let infos = infos(&decoded);
    assert_eq!(infos.len(), 12);
    for &(offset, info) in &infos {
        assert_eq!(info.product(), "XR_FOC_ESC");
        assert_eq!(info.hardware(), "HW577_KZ1_V1.1");
        assert_eq!(info.firmware(), "XR-01.0.00");
        assert_eq!(info.id(), "01040443");
        let o = offset as usize;
        assert_eq!(info.encode()[..], x.bytes[o..o + 77]);
        assert_eq!(x.bytes[o + 76], 0x34);
    }
    assert_eq!(infos[0].0, 24);
    // The info frame whose header arrived as 00 00 00 00 (offset 6622) is not among them.
    assert_eq!(x.bytes[6622..6626], [0, 0, 0, 0]);
    assert!(infos.iter().all(|&(o, _)| o != 6622));
}

#[test]
fn xrotor_timing_matches_the_notes() {
    let x = load(XROTOR);
    let (decoded, _) = bulk(&x.bytes);
    let frames = data(&decoded);
    // Bytes back to back at 19200 baud: 23 byte times of 520.8 us from first to last byte.
    for &(o, f) in &frames {
        let o = o as usize;
        let span = x.times[o + 23] - x.times[o];
        assert!(
            (span - 23.0 / 1920.0).abs() < 1e-4,
            "packet {}: {span}",
            f.packet
        );
    }
    // Each info frame follows its data frame by ~40 ms.
    for (o, _) in infos(&decoded) {
        let prev = frames.iter().rev().find(|&&(p, _)| p < o).unwrap();
        let delay = x.times[o as usize] - x.times[prev.0 as usize];
        assert!((0.035..0.045).contains(&delay), "info at {o}: {delay}");
    }
    // Running: a frame every ~56 ms.
    let mut running: Vec<f64> = frames
        .windows(2)
        .filter(|w| {
            w[0].1.throttle_out_raw > 0
                && w[1].1.throttle_out_raw > 0
                && w[1].1.packet == w[0].1.packet + 1
        })
        .map(|w| x.times[w[1].0 as usize] - x.times[w[0].0 as usize])
        .collect();
    running.sort_by(f64::total_cmp);
    assert!(running.len() > 100);
    let median = running[running.len() / 2];
    assert!((0.054..0.058).contains(&median), "{median}");
}

// ---------------------------------------------------------------------------------------------
// Platinum captures: other protocols, no HW-FOC frame
// ---------------------------------------------------------------------------------------------

#[test]
fn platinum_captures_give_no_frames() {
    for name in [PLATINUM_V4, PLATINUM_PRO_V3] {
        let c = load(name);
        assert!(c.bytes.contains(&0x9B), "{name} has sync bytes");
        let (decoded, stats) = bulk(&c.bytes);
        assert!(decoded.is_empty(), "{name}: {decoded:?}");
        assert_eq!(stats.frames(), 0, "{name}");
        assert_eq!(stats.info_frames(), 0, "{name}");
        assert_eq!(stats.bytes_skipped(), c.bytes.len() as u64, "{name}");
        assert_eq!(stats.last_packet(), None);
    }
}

// ---------------------------------------------------------------------------------------------
// Every path gives the same result
// ---------------------------------------------------------------------------------------------

#[test]
fn streaming_and_bulk_agree_on_every_capture() {
    for name in ALL {
        let c = load(name);
        let reference = bulk(&c.bytes);
        assert_eq!(
            streamed_bytewise(&c.bytes),
            reference,
            "{name}: byte at a time"
        );
        assert_eq!(
            streamed_chunks(&c.bytes, 4096),
            reference,
            "{name}: 4096-byte chunks"
        );
        let mut all_at_once = Decoder::new();
        let mut out = Vec::new();
        all_at_once.decode_all(&c.bytes, |d| out.push(d));
        assert_eq!((out, *all_at_once.stats()), reference, "{name}: decode_all");
    }
}

#[test]
fn streaming_agrees_at_awkward_chunk_sizes() {
    let c = load(XROTOR);
    let reference = bulk(&c.bytes);
    for size in [2, 3, 23, 24, 25, 76, 77, 78, 100, 153, 1000] {
        assert_eq!(
            streamed_chunks(&c.bytes, size),
            reference,
            "chunks of {size}"
        );
    }
}
