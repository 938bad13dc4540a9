//! The V4 decoder: golden results on the real Platinum V4 capture, the info frame's adoption,
//! properties (encode/decode identity, chunking independence, garbage and cut frames between
//! chains, random bytes rich in `9B` and `B9`), and a stream that switches from V3 to V4.

#[allow(dead_code)] // `data_frame` is the HW-FOC generator
mod common;
mod older;

use common::{cut_points, streamed_bytewise};
use hwfoc::counters::PacketSequence24;
use hwfoc::v4::{
    self, DATA_FRAME_LEN, Data, DataFrame, Decoded, INFO_FRAME_LEN, InfoFrame, Scanner, V4Frame,
    VoltsPerStep,
};
use hwfoc::{foc, v3};
use older::{Figures, PLATINUM_PRO_V3, PLATINUM_V4, RANDOM_LEN, Rng, XROTOR, bulk, load};
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::Index;

/// The info frame of the Platinum V4 capture.
const CAPTURE_INFO: [u8; 13] = [
    0x9B, 0x9B, 0x03, 0xE8, 0x01, 0x08, 0x5B, 0x00, 0x01, 0x00, 0x21, 0x21, 0xB9,
];

fn data_of(decoded: &[Decoded]) -> Vec<(u64, Data)> {
    decoded
        .iter()
        .filter_map(|d| match d.frame {
            V4Frame::Data(x) => Some((d.offset, x)),
            V4Frame::Info(_) => None,
        })
        .collect()
}

fn infos_of(decoded: &[Decoded]) -> Vec<(u64, InfoFrame)> {
    decoded
        .iter()
        .filter_map(|d| match d.frame {
            V4Frame::Info(i) => Some((d.offset, i)),
            V4Frame::Data(_) => None,
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// The real capture
// ---------------------------------------------------------------------------------------------

#[test]
fn capture_decodes_completely() {
    let bytes = load(PLATINUM_V4);
    assert_eq!(bytes.len(), 6007);
    let (decoded, stats) = bulk::<Scanner>(&bytes);
    let data = data_of(&decoded);
    let infos = infos_of(&decoded);
    assert_eq!((data.len(), infos.len()), (297, 26));
    let counters: Vec<u32> = data.iter().map(|(_, d)| d.packet()).collect();
    assert_eq!(counters, (817..=1113).collect::<Vec<u32>>());
    assert_eq!(stats.frames(), 297);
    assert_eq!(stats.info_frames(), 26);
    assert_eq!(stats.bytes_skipped(), 0);
    assert_eq!(stats.rejected(), 0);
    assert_eq!(stats.syncs(), 1);
    // One trailing B9 per slow-mode data frame: every byte is in a frame or a trailer.
    assert_eq!(stats.trailers(), 26);
    assert_eq!(stats.bytes(), 19 * 297 + 13 * 26 + 26);
    let c = stats.counter();
    assert_eq!((c.lost(), c.duplicates(), c.restarts()), (0, 0, 0));
    // The stream opens with an info frame; frames follow back to back.
    assert_eq!(infos[0].0, 0);
    assert_eq!(data[0].0, 13);
}

#[test]
fn capture_info_frame_is_adopted_from_its_second_copy() {
    let (decoded, stats) = bulk::<Scanner>(&load(PLATINUM_V4));
    let info = InfoFrame::parse(&CAPTURE_INFO).unwrap();
    assert_eq!(info.full_scale, 1000);
    assert_eq!(info.volts_per_step(), VoltsPerStep { num: 8, den: 910 });
    assert!(!info.has_current_sensor());
    assert!(infos_of(&decoded).iter().all(|(_, i)| *i == info));
    assert_eq!(stats.adopted(), Some(info));
    assert_eq!((stats.info_adoptions(), stats.info_disagreements()), (1, 0));
    let data = data_of(&decoded);
    // The first data frame came after one copy: not adopted yet; every later one under it.
    assert_eq!(data[0].1.info, None);
    assert!(data[1..].iter().all(|(_, d)| d.info == Some(info)));
}

#[test]
fn capture_values() {
    let (decoded, _) = bulk::<Scanner>(&load(PLATINUM_V4));
    let data: Vec<Data> = data_of(&decoded).into_iter().map(|(_, d)| d).collect();
    // Voltage 11.87-12.02 V (a 3S pack), under the adopted 8/910 V per step (and, before it,
    // the default setting, also 8/910).
    let volts: Vec<f32> = data
        .iter()
        .map(|d| d.voltage_v(VoltsPerStep::DEFAULT))
        .collect();
    let min = volts.iter().copied().fold(f32::INFINITY, f32::min);
    let max = volts.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    assert_eq!(
        (format!("{min:.2}"), format!("{max:.2}")),
        ("11.87".into(), "12.02".into())
    );
    assert_eq!(max, 1367.0 * 8.0 / 910.0);
    // Under the HV setting, only the frame before adoption would change.
    let hv: Vec<f32> = data
        .iter()
        .map(|d| d.voltage_v(VoltsPerStep::HIGH_VOLTAGE))
        .collect();
    assert_ne!(hv[0], volts[0]);
    assert_eq!(hv[1..], volts[1..]);
    // No current sensor: no current, before or after adoption.
    assert!(data.iter().all(|d| d.current_a().is_none()));
    // Throttle peaks at exactly 100 %.
    let peak = data.iter().map(Data::throttle_in_pct).fold(0.0, f32::max);
    assert_eq!(peak, 100.0);
    assert!(data.iter().all(|d| d.throttle_out_pct() <= 100.0));
    // MOSFET temperature about 30 degC throughout; the second sensor reads 0 (no reading) at
    // idle and a temperature while running.
    assert!(
        data.iter()
            .all(|d| d.temp_c().is_some_and(|t| (25.0..35.0).contains(&t)))
    );
    let second: Vec<Option<f32>> = data.iter().map(Data::temp2_c).collect();
    assert!(second.iter().any(Option::is_none));
    assert!(second.iter().flatten().all(|t| (25.0..35.0).contains(t)));
    assert!(second.iter().any(Option::is_some));
    assert!(data.iter().any(|d| d.erpm() > 0));
}

#[test]
fn capture_in_any_chunking() {
    let bytes = load(PLATINUM_V4);
    older::assert_every_path_agrees::<Scanner>(
        &bytes,
        &[
            2, 3, 12, 13, 14, 18, 19, 20, 21, 32, 33, 59, 60, 61, 1000, 7000,
        ],
    );
}

#[test]
fn other_captures_give_no_v4_frame() {
    // The V3 capture's frames are 10 bytes apart: no V4 chain forms.
    for name in [PLATINUM_PRO_V3, XROTOR] {
        let bytes = load(name);
        let (decoded, stats) = bulk::<Scanner>(&bytes);
        assert!(decoded.is_empty(), "{name}: {:?}", &decoded[..1]);
        assert_eq!(stats.bytes_skipped(), bytes.len() as u64, "{name}");
        assert!(stats.rejected() > 20, "{name}: {stats}");
    }
}

#[test]
fn hwfoc_decoder_still_finds_nothing_in_the_platinum_captures() {
    for name in [PLATINUM_V4, PLATINUM_PRO_V3] {
        let bytes = load(name);
        let mut it = foc::frames(&bytes);
        assert_eq!(it.by_ref().count(), 0, "{name}");
        assert_eq!(it.stats().bytes_skipped(), bytes.len() as u64, "{name}");
    }
}

// ---------------------------------------------------------------------------------------------
// Random bytes, temperature
// ---------------------------------------------------------------------------------------------

#[test]
fn two_million_random_bytes_give_no_frame() {
    let mut rng = Rng(0x5EED_0004);
    for (kind, bytes) in [
        ("uniform", rng.uniform(RANDOM_LEN)),
        ("rich in 9B and B9", rng.rich(RANDOM_LEN)),
    ] {
        let (decoded, stats) = bulk::<Scanner>(&bytes);
        assert!(decoded.is_empty(), "{kind}: {:?}", &decoded[..1]);
        assert_eq!(stats.bytes_skipped(), RANDOM_LEN as u64, "{kind}");
        assert_eq!((stats.trailers(), stats.info_frames()), (0, 0), "{kind}");
        assert!(stats.implausible() > 0, "{kind}");
        // The V3 decoder finds none either.
        assert_eq!(v3::frames(&bytes).count(), 0, "{kind}");
    }
}

#[test]
fn rich_random_bytes_hold_info_shapes_that_are_not_taken() {
    // The test above is not vacuous: the rich bytes hold many info frames' fixed bytes (one in
    // about 25 000 positions), none accepted without a plausible data frame after it.
    let bytes = Rng(0x5EED_0004 ^ 1).rich(RANDOM_LEN);
    let shapes = bytes
        .windows(INFO_FRAME_LEN)
        .filter(|w| InfoFrame::parse(w).is_some_and(|i| i.is_plausible()))
        .count();
    assert!(shapes > 20, "{shapes}");
    assert_eq!(v4::frames(&bytes).count(), 0);
}

/// A data frame can carry an info frame's fixed bytes (`9B 9B` at 0, `01` at 4, `B9` at 12):
/// counter 0x9B0100, an input throttle of 256 and a voltage reading of 0x05B9. Where those
/// bytes' constants are not a plausible info frame, it is read as the data frame it is, and
/// the chain it confirms is not lost (found by `chains_decode_exactly`: before, none of the
/// three frames was decoded).
#[test]
fn a_data_frame_with_an_info_frames_fixed_bytes_is_data() {
    let frames = [
        DataFrame {
            counter: 0x9B_00FE,
            ..Default::default()
        },
        DataFrame {
            counter: 0x9B_00FF,
            ..Default::default()
        },
        DataFrame {
            counter: 0x9B_0100,
            throttle_in_raw: 256,
            voltage_adc: 0x05B9,
            ..Default::default()
        },
    ];
    let third = frames[2].encode();
    assert_eq!(
        [third[0], third[1], third[4], third[12]],
        [0x9B, 0x9B, 0x01, 0xB9]
    );
    let mut wire = vec![0x00];
    for f in &frames {
        wire.extend_from_slice(&f.encode());
    }
    let (decoded, stats) = bulk::<Scanner>(&wire);
    let counters: Vec<u32> = data_of(&decoded)
        .iter()
        .map(|(_, d)| d.frame.counter)
        .collect();
    assert_eq!(counters, [0x9B_00FE, 0x9B_00FF, 0x9B_0100]);
    assert_eq!(stats.bytes_skipped(), 1);
}

#[test]
fn temperature_matches_the_formula() {
    for adc in 1u16..4096 {
        let a = f64::from(adc);
        let want = 1.0 / ((a / (4096.0 - a) * 10.0 / 47.0).ln() / 3950.0 + 1.0 / 298.15) - 273.15;
        let got = f64::from(v4::ntc_celsius(adc).unwrap());
        assert!(
            (got - want).abs() < 1e-4 * want.abs().max(1.0),
            "{adc}: {got} {want}"
        );
    }
    assert_eq!(v4::ntc_celsius(0), None);
}

// ---------------------------------------------------------------------------------------------
// Edges of the lock rule and of adoption
// ---------------------------------------------------------------------------------------------

fn data(counter: u32) -> DataFrame {
    DataFrame {
        counter,
        throttle_in_raw: 420,
        throttle_out_raw: 400,
        erpm: 30_000,
        voltage_adc: 1360,
        current_adc: 0,
        temp_adc: 3240,
        temp2_adc: 3200,
    }
}

fn counters(decoded: &[Decoded]) -> Vec<u32> {
    data_of(decoded).iter().map(|(_, d)| d.packet()).collect()
}

#[test]
fn a_corrupted_info_copy_is_not_adopted() {
    let info = InfoFrame::parse(&CAPTURE_INFO).unwrap();
    let flipped = InfoFrame { v1: 9, ..info };
    let mut wire = Vec::new();
    for (k, i) in [info, info, flipped, info, info].iter().enumerate() {
        wire.extend_from_slice(&i.encode());
        wire.extend_from_slice(&data(k as u32).encode_with_trailer());
    }
    let (decoded, stats) = bulk::<Scanner>(&wire);
    let used: Vec<Option<InfoFrame>> = data_of(&decoded).iter().map(|(_, d)| d.info).collect();
    // The frame after the corrupted copy is decoded under none (as after a swap to an ESC of
    // other constants, which one copy cannot be told from), then the adopted one again.
    assert_eq!(used, [None, Some(info), None, Some(info), Some(info)]);
    assert_eq!((stats.info_adoptions(), stats.info_disagreements()), (1, 2));
}

#[test]
fn a_plausible_running_stream_with_a_restart_and_a_gap() {
    let mut wire = Vec::new();
    for c in (900..905).chain(0..4).chain(7..10) {
        wire.extend_from_slice(&data(c).encode());
    }
    let (decoded, stats) = bulk::<Scanner>(&wire);
    assert_eq!(counters(&decoded).len(), 12);
    // The restart starts a new chain; the gap of three frames (3 to 7) continues it.
    assert_eq!(
        (stats.restarts(), stats.lost_packets(), stats.syncs()),
        (1, 3, 2)
    );
    assert_eq!((stats.bytes_skipped(), stats.trailers()), (0, 0));
}

#[test]
fn a_frame_between_two_cut_frames_continues_the_chain_up_to_the_bound() {
    let wire =
        |counters: &[u32]| -> Vec<u8> { counters.iter().flat_map(|&c| data(c).encode()).collect() };
    // 3 and 5 cut out whole: 4 and 6 have no consecutive neighbour, yet each starts where the
    // chain ends with its counter advanced by two.
    let (decoded, stats) = bulk::<Scanner>(&wire(&[0, 1, 2, 4, 6]));
    assert_eq!(counters(&decoded), [0, 1, 2, 4, 6]);
    assert_eq!((stats.lost_packets(), stats.syncs()), (2, 1));
    // Up to MAX_CHAINED_GAP frames missing; one more, and the frame needs a chain of three.
    let last = 2 + v4::MAX_CHAINED_GAP + 1;
    let (decoded, _) = bulk::<Scanner>(&wire(&[0, 1, 2, last, last + 2]));
    assert_eq!(counters(&decoded), [0, 1, 2, last, last + 2]);
    let (decoded, stats) = bulk::<Scanner>(&wire(&[0, 1, 2, last + 1, last + 3]));
    assert_eq!(counters(&decoded), [0, 1, 2]);
    assert_eq!(stats.unconfirmed(), 1);
    // In slow mode: the info frame before a cut data frame is confirmed by the next info frame.
    let info = InfoFrame::parse(&CAPTURE_INFO).unwrap();
    let mut slow = Vec::new();
    for c in [0, 2, 3] {
        if c != 2 {
            slow.extend_from_slice(&data(c).encode_with_trailer());
        }
        slow.extend_from_slice(&info.encode());
    }
    slow.extend_from_slice(&data(4).encode_with_trailer());
    let (decoded, stats) = bulk::<Scanner>(&slow);
    assert_eq!(counters(&decoded), [0, 3, 4]);
    assert_eq!(infos_of(&decoded).len(), 3);
    assert_eq!(
        (stats.lost_packets(), stats.syncs(), stats.bytes_skipped()),
        (2, 1, 0)
    );
}

/// One frame of a V4 ESC's stream as sent: a data frame (with its trailer while idle) or an
/// info frame (`data` is `None`), and its bytes.
struct Sent {
    data: Option<DataFrame>,
    bytes: Vec<u8>,
}

/// 120 s of a V4 ESC as `hwfoc simulate --protocol hw-v4 --duration 120` sends them (2060 data
/// frames, 42 info frames): idle (an info frame and a data frame with its trailer,
/// alternating), running (data frames back to back), idle again; counters from 0x12_3400,
/// fields from `rng`.
fn simulated_v4(rng: &mut Rng) -> Vec<Sent> {
    let info = InfoFrame::parse(&CAPTURE_INFO).unwrap();
    let mut counter = 0x12_3400;
    let mut next_data = |rng: &mut Rng, running: bool| {
        let mut random = |below: u64| (rng.next() % below) as u16;
        let f = DataFrame {
            counter,
            throttle_in_raw: if running { random(1001) } else { 0 },
            throttle_out_raw: if running { random(1001) } else { 0 },
            erpm: if running {
                u32::from(random(60_000))
            } else {
                0
            },
            voltage_adc: 2600 + random(200),
            current_adc: if running { random(4096) } else { 0 },
            temp_adc: 3000 + random(300),
            temp2_adc: if running { 3000 + random(300) } else { 0 },
        };
        counter += 1;
        f
    };
    let mut sent = Vec::new();
    for (frames, running) in [(21, false), (2018, true), (21, false)] {
        for _ in 0..frames {
            let f = next_data(rng, running);
            if running {
                sent.push(Sent {
                    data: Some(f),
                    bytes: f.encode().to_vec(),
                });
            } else {
                sent.push(Sent {
                    data: None,
                    bytes: info.encode().to_vec(),
                });
                sent.push(Sent {
                    data: Some(f),
                    bytes: f.encode_with_trailer().to_vec(),
                });
            }
        }
    }
    sent
}

/// The stream: 120 s of a V4 ESC with 5 % of its data frames (103 of 2060) cut out
/// whole, each with its trailer. Every frame left intact is decoded, also one that lies between
/// two cut frames (and so has no consecutive neighbour to confirm it), and exactly the frames
/// cut are counted lost.
#[test]
fn no_intact_frame_is_lost_between_data_frames_cut_out_whole() {
    let mut rng = Rng(0x5EED_0120);
    let sent = simulated_v4(&mut rng);
    let data_at: Vec<usize> = (0..sent.len())
        .filter(|&k| sent[k].data.is_some())
        .collect();
    assert_eq!((data_at.len(), sent.len() - data_at.len()), (2060, 42));
    // The first and the last data frame are kept, so that every frame cut is a visible loss.
    let cut: Vec<usize> = rng
        .sample(1..data_at.len() - 1, 103)
        .into_iter()
        .map(|k| data_at[k])
        .collect();
    let mut wire = Vec::new();
    let (mut want_data, mut want_info) = (Vec::new(), Vec::new());
    for (k, s) in sent.iter().enumerate() {
        if cut.binary_search(&k).is_ok() {
            continue;
        }
        match s.data {
            Some(f) => want_data.push((wire.len() as u64, f.counter)),
            None => want_info.push(wire.len() as u64),
        }
        wire.extend_from_slice(&s.bytes);
    }
    let (decoded, stats) = bulk::<Scanner>(&wire);
    let got_data: Vec<(u64, u32)> = data_of(&decoded)
        .iter()
        .map(|(at, d)| (*at, d.packet()))
        .collect();
    let got_info: Vec<u64> = infos_of(&decoded).iter().map(|(at, _)| *at).collect();
    older::assert_frames(&got_data, &want_data, 0x12_3400);
    assert_eq!(got_info, want_info, "info frames");
    assert_eq!(figures(&stats), Figures::after_cuts(cut.len()));
    older::assert_every_path_agrees::<Scanner>(&wire, &[19, 20, 33, 64]);
}

#[test]
fn plausible_chained_frames_whose_counters_do_not_follow_never_lock() {
    let mut wire = Vec::new();
    for c in [10, 20, 30, 31, 50, 70, 71] {
        wire.extend_from_slice(&data(c).encode());
    }
    let (decoded, stats) = bulk::<Scanner>(&wire);
    assert!(decoded.is_empty(), "{decoded:?}");
    // Each one that could be judged is unconfirmed; the last two are cut off by the end.
    assert_eq!(stats.unconfirmed(), 5);
    // The same frames with counters +1 lock at once.
    let mut wire = Vec::new();
    for c in 10..17 {
        wire.extend_from_slice(&data(c).encode());
    }
    assert_eq!(v4::frames(&wire).count(), 7);
}

#[test]
fn implausible_fields_are_rejected() {
    for corrupt in [
        |f: &mut DataFrame| f.throttle_in_raw = 1001,
        |f: &mut DataFrame| f.throttle_out_raw = 5000,
        |f: &mut DataFrame| f.voltage_adc = 4096,
        |f: &mut DataFrame| f.current_adc = 0xFFFF,
        |f: &mut DataFrame| f.temp_adc = 4096,
        |f: &mut DataFrame| f.temp2_adc = 4096,
    ] {
        let mut wire = Vec::new();
        for c in 0..6 {
            let mut f = data(c);
            if c == 3 {
                corrupt(&mut f);
            }
            wire.extend_from_slice(&f.encode());
        }
        let (decoded, stats) = bulk::<Scanner>(&wire);
        // V4Frame 3 is rejected; 4 and 5 cannot form a chain of three before the end.
        assert_eq!(counters(&decoded), [0, 1, 2]);
        assert_eq!(stats.implausible(), 1);
    }
}

#[test]
fn the_adopted_full_scale_is_the_plausibility_limit() {
    let info = InfoFrame {
        full_scale: 2000,
        ..InfoFrame::parse(&CAPTURE_INFO).unwrap()
    };
    let high = |c| DataFrame {
        throttle_in_raw: 1500,
        ..data(c)
    };
    let mut wire = Vec::new();
    wire.extend_from_slice(&high(0).encode()); // above 1000 before adoption: rejected
    for c in 1..3 {
        wire.extend_from_slice(&info.encode());
        wire.extend_from_slice(&data(c).encode_with_trailer());
    }
    for c in 3..6 {
        wire.extend_from_slice(&high(c).encode()); // within 2000 after adoption
    }
    let (decoded, stats) = bulk::<Scanner>(&wire);
    assert_eq!(counters(&decoded), [1, 2, 3, 4, 5]);
    let last = data_of(&decoded)[4].1;
    assert_eq!(last.throttle_in_pct(), 75.0);
    assert_eq!(stats.implausible(), 1);
}

/// Found by the v4 fuzz target: after the constants of another ESC appear (one copy, not yet
/// adopted), a data frame is decoded as before any info frame (full scale 1000), so it must be
/// judged by that scale too, not by the adopted one; else a frame of 1500 steps was accepted
/// and read as 150 %.
#[test]
fn a_candidate_is_judged_by_the_scale_it_would_be_decoded_under() {
    let wide = InfoFrame {
        full_scale: 2000,
        ..InfoFrame::parse(&CAPTURE_INFO).unwrap()
    };
    let other = InfoFrame {
        full_scale: 1000,
        ..wide
    };
    let high = |c| DataFrame {
        throttle_in_raw: 1500,
        ..data(c)
    };
    let mut wire = Vec::new();
    for c in 0..2 {
        wire.extend_from_slice(&wide.encode());
        wire.extend_from_slice(&data(c).encode_with_trailer());
    }
    wire.extend_from_slice(&high(2).encode()); // 75 % under the adopted constants
    wire.extend_from_slice(&other.encode());
    wire.extend_from_slice(&high(3).encode_with_trailer()); // above 1000 under none: rejected
    let (decoded, stats) = bulk::<Scanner>(&wire);
    for (at, d) in data_of(&decoded) {
        assert!(
            d.frame.is_plausible(d.full_scale()),
            "data frame at {at} accepted at {} %",
            d.throttle_in_pct()
        );
    }
    assert_eq!(counters(&decoded), [0, 1, 2]);
    assert_eq!(data_of(&decoded)[2].1.throttle_in_pct(), 75.0);
    assert_eq!(stats.implausible(), 1);
}

// ---------------------------------------------------------------------------------------------
// Properties
// ---------------------------------------------------------------------------------------------

fn any_data_frame() -> impl Strategy<Value = DataFrame> {
    (
        (0u32..1 << 24, any::<u16>(), any::<u16>(), 0u32..1 << 24),
        (any::<u16>(), any::<u16>(), any::<u16>(), any::<u16>()),
    )
        .prop_map(|((counter, t, p, erpm), (v, i, m, s))| DataFrame {
            counter,
            throttle_in_raw: t,
            throttle_out_raw: p,
            erpm,
            voltage_adc: v,
            current_adc: i,
            temp_adc: m,
            temp2_adc: s,
        })
}

fn any_info_frame() -> impl Strategy<Value = InfoFrame> {
    (any::<u16>(), any::<[u8; 7]>()).prop_map(|(full_scale, b)| InfoFrame {
        full_scale,
        v1: b[0],
        v2: b[1],
        i1: b[2],
        i2: b[3],
        i3: b[4],
        t1: b[5],
        t2: b[6],
    })
}

/// The fields of a data frame plausible under any full scale of [`plausible_info`].
fn plausible_fields() -> impl Strategy<Value = DataFrame> {
    (
        (0u16..=1000, 0u16..=1000, 0u32..1 << 24),
        (0u16..4096, 0u16..4096, 0u16..4096, 0u16..4096),
    )
        .prop_map(|((t, p, erpm), (v, i, m, s))| DataFrame {
            counter: 0,
            throttle_in_raw: t,
            throttle_out_raw: p,
            erpm,
            voltage_adc: v,
            current_adc: i,
            temp_adc: m,
            temp2_adc: s,
        })
}

/// A plausible info frame with a full scale of at least 1000; mostly the capture's, so that
/// copies repeat and get adopted.
fn plausible_info() -> impl Strategy<Value = InfoFrame> {
    prop_oneof![
        2 => Just(InfoFrame::parse(&CAPTURE_INFO).unwrap()),
        1 => (1000u16..=4000, 1u8..=255, any::<u8>(), 1u8..=255)
            .prop_map(|(full_scale, v2, i1, i2)| InfoFrame {
                full_scale,
                v1: 11,
                v2,
                i1,
                i2,
                i3: 3,
                t1: 0x21,
                t2: 0x21,
            }),
    ]
}

#[derive(Debug, Clone)]
enum Piece {
    /// Running mode: at least three data frames, no trailers, counters from the first.
    Fast(u32, Vec<DataFrame>),
    /// Idle mode: pairs of an info frame and a data frame with its trailer.
    Slow(u32, Vec<(InfoFrame, DataFrame)>),
    /// Noise (never starting with `B9`, which would be the trailer of a running data frame).
    Garbage(Vec<u8>),
    /// The first `n` bytes of a frame.
    Cut(Vec<u8>, usize),
}

fn noisy_byte() -> impl Strategy<Value = u8> {
    prop_oneof![6 => any::<u8>(), 2 => Just(0x9B), 2 => Just(0xB9), 1 => Just(0x01)]
}

fn fast() -> impl Strategy<Value = Piece> {
    (0u32..1 << 24, vec(plausible_fields(), 3..7)).prop_map(|(s, f)| Piece::Fast(s, f))
}

fn slow() -> impl Strategy<Value = Piece> {
    (
        0u32..1 << 24,
        vec((plausible_info(), plausible_fields()), 1..5),
    )
        .prop_map(|(s, f)| Piece::Slow(s, f))
}

fn chain() -> impl Strategy<Value = Piece> {
    prop_oneof![fast(), slow()]
}

fn gap() -> impl Strategy<Value = Piece> {
    prop_oneof![
        vec(noisy_byte(), 1..40).prop_map(Piece::Garbage),
        (any_data_frame(), any::<Index>())
            .prop_map(|(f, n)| Piece::Cut(f.encode().to_vec(), 1 + n.index(DATA_FRAME_LEN - 1))),
        (any_info_frame(), any::<Index>())
            .prop_map(|(f, n)| Piece::Cut(f.encode().to_vec(), 1 + n.index(INFO_FRAME_LEN - 1))),
    ]
}

/// A wire, and what a decoder must find in it.
#[derive(Debug)]
struct Wire {
    bytes: Vec<u8>,
    frames: Vec<(u64, V4Frame)>,
    /// Where the info frames really are (any other info-shaped bytes are a fake).
    info_at: Vec<usize>,
    skipped: u64,
    trailers: u32,
    syncs: u32,
    sequence: PacketSequence24,
    adoptions: u32,
    disagreements: u32,
}

/// The info frame a data frame is decoded under: the adopted one, none while the last info
/// frame differs from it.
fn in_use(adopted: Option<InfoFrame>, last_info: Option<InfoFrame>) -> Option<InfoFrame> {
    match (adopted, last_info) {
        (Some(a), Some(l)) if a != l => None,
        _ => adopted,
    }
}

/// Lays out `pieces`, a chain after every gap, and computes what the decoder must find: every
/// frame of every chain (each chain starts a new one), the info frames adopted by the rule of
/// `docs/OLDER-PROTOCOLS.md` (two identical copies in a row; a data frame after an info frame
/// that differs from the adopted one is decoded under none).
fn build(pieces: &[Piece]) -> Wire {
    let mut w = Wire {
        bytes: Vec::new(),
        frames: Vec::new(),
        info_at: Vec::new(),
        skipped: 0,
        trailers: 0,
        syncs: 0,
        sequence: PacketSequence24::new(),
        adoptions: 0,
        disagreements: 0,
    };
    let mut last_info: Option<InfoFrame> = None;
    let mut adopted: Option<InfoFrame> = None;
    for p in pieces {
        match p {
            Piece::Fast(start, fields) => {
                w.syncs += 1;
                let mut counter = *start;
                for f in fields {
                    let f = push_data(&mut w, &mut counter, f, in_use(adopted, last_info));
                    w.bytes.extend_from_slice(&f.encode());
                }
            }
            Piece::Slow(start, pairs) => {
                w.syncs += 1;
                let mut counter = *start;
                for (info, f) in pairs {
                    if last_info == Some(*info) && adopted != Some(*info) {
                        adopted = Some(*info);
                        w.adoptions += 1;
                    } else if last_info.is_some() && last_info != Some(*info) {
                        w.disagreements += 1;
                    }
                    last_info = Some(*info);
                    w.info_at.push(w.bytes.len());
                    w.frames.push((w.bytes.len() as u64, V4Frame::Info(*info)));
                    w.bytes.extend_from_slice(&info.encode());
                    let f = push_data(&mut w, &mut counter, f, in_use(adopted, last_info));
                    w.bytes.extend_from_slice(&f.encode_with_trailer());
                    w.trailers += 1;
                }
            }
            Piece::Garbage(g) => {
                let mut g = g.clone();
                if g[0] == 0xB9 {
                    g[0] = 0x00;
                }
                w.bytes.extend_from_slice(&g);
                w.skipped += g.len() as u64;
            }
            Piece::Cut(bytes, n) => {
                w.bytes.extend_from_slice(&bytes[..*n]);
                w.skipped += *n as u64;
            }
        }
    }
    w
}

/// Records a data frame of a chain with the next counter, as decoded under `adopted`.
fn push_data(
    w: &mut Wire,
    counter: &mut u32,
    f: &DataFrame,
    adopted: Option<InfoFrame>,
) -> DataFrame {
    let f = DataFrame {
        counter: *counter,
        ..*f
    };
    w.frames.push((
        w.bytes.len() as u64,
        V4Frame::Data(Data {
            frame: f,
            info: adopted,
        }),
    ));
    w.sequence.next(*counter);
    *counter = (*counter + 1) & 0xFF_FFFF;
    f
}

/// Whether the wire holds an info frame's fixed bytes (with plausible divisors) anywhere but
/// where the real ones are: noise that is an info frame as far as any decoder can tell.
fn has_fake_info(w: &Wire) -> bool {
    fake_info_outside(&w.bytes, &w.info_at)
}

/// Whether `bytes` hold an info frame's fixed bytes (with plausible divisors) anywhere but at
/// `info_at`.
fn fake_info_outside(bytes: &[u8], info_at: &[usize]) -> bool {
    bytes
        .windows(INFO_FRAME_LEN)
        .enumerate()
        .any(|(at, window)| {
            InfoFrame::parse(window).is_some_and(|i| i.is_plausible()) && !info_at.contains(&at)
        })
}

fn assert_finds_exactly(w: &Wire) -> Result<(), TestCaseError> {
    let (decoded, stats) = bulk::<Scanner>(&w.bytes);
    let got: Vec<(u64, V4Frame)> = decoded.iter().map(|d| (d.offset, d.frame)).collect();
    prop_assert_eq!(&got, &w.frames);
    prop_assert_eq!(stats.bytes_skipped(), w.skipped);
    prop_assert_eq!(stats.trailers(), w.trailers);
    prop_assert_eq!(stats.syncs(), w.syncs);
    prop_assert_eq!(stats.counter(), &w.sequence);
    prop_assert_eq!(stats.info_adoptions(), w.adoptions);
    prop_assert_eq!(stats.info_disagreements(), w.disagreements);
    Ok(())
}

/// Gaps and chains, alternating (a gap first).
fn gaps_and_chains(gap: impl Strategy<Value = Piece>) -> impl Strategy<Value = Vec<Piece>> {
    vec((gap, chain()), 1..5).prop_map(|v| v.into_iter().flat_map(|(g, c)| [g, c]).collect())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn data_frame_encode_decode_identity(f in any_data_frame()) {
        let bytes = f.encode();
        prop_assert_eq!(DataFrame::parse(&bytes), Some(f));
        let slow = f.encode_with_trailer();
        prop_assert_eq!(&slow[..19], &bytes[..]);
        prop_assert_eq!(slow[19], 0xB9);
        prop_assert_eq!(DataFrame::parse(&slow), Some(f));
    }

    #[test]
    fn info_frame_encode_decode_identity(i in any_info_frame()) {
        let bytes = i.encode();
        prop_assert_eq!(InfoFrame::parse(&bytes), Some(i));
        prop_assert_eq!(i.is_plausible(), i.full_scale > 0 && i.v2 > 0 && (i.i1 == 0 || i.i2 > 0));
    }

    #[test]
    fn chains_decode_exactly(pieces in gaps_and_chains(vec(any::<u8>(), 1..3).prop_map(Piece::Garbage))) {
        let w = build(&pieces);
        prop_assume!(!has_fake_info(&w));
        assert_finds_exactly(&w)?;
    }

    #[test]
    fn garbage_between_chains_is_skipped_and_counted(
        pieces in gaps_and_chains(vec(noisy_byte(), 1..40).prop_map(Piece::Garbage)),
    ) {
        let w = build(&pieces);
        prop_assume!(!has_fake_info(&w));
        assert_finds_exactly(&w)?;
        let (_, stats) = bulk::<Scanner>(&w.bytes);
        // The garbage is rich in 9B: candidates were rejected.
        let garbage_syncs = pieces.iter().map(|p| match p {
            Piece::Garbage(g) => g.iter().filter(|&&b| b == 0x9B).count(),
            _ => 0,
        }).sum::<usize>();
        prop_assert!(stats.rejected() as usize <= garbage_syncs);
    }

    #[test]
    fn cut_frames_between_chains_are_skipped(pieces in gaps_and_chains(gap())) {
        let w = build(&pieces);
        prop_assume!(!has_fake_info(&w));
        assert_finds_exactly(&w)?;
    }

    #[test]
    fn any_chunking_gives_the_same_frames_and_stats(
        pieces in vec(prop_oneof![chain(), gap()], 0..10),
        picks in vec(any::<Index>(), 0..20),
    ) {
        // Chains may follow each other here, and garbage may start with B9: whatever the
        // decoder makes of it, every chunking must agree.
        let w = build(&pieces);
        let reference = bulk::<Scanner>(&w.bytes);
        let cuts = cut_points(w.bytes.len(), &picks);
        prop_assert_eq!(&older::streamed_at::<Scanner>(&w.bytes, &cuts), &reference);
        prop_assert_eq!(&streamed_bytewise::<Scanner>(&w.bytes), &reference);
        let (_, s) = &reference;
        prop_assert_eq!(
            s.bytes(),
            19 * u64::from(s.frames()) + 13 * u64::from(s.info_frames())
                + u64::from(s.trailers()) + s.bytes_skipped()
        );
    }

    #[test]
    fn every_frame_left_between_data_frames_cut_out_whole_is_decoded(
        start in 0u32..1 << 24,
        frames in vec((plausible_fields(), any::<bool>()), 4..60),
        cuts in vec(prop::bool::weighted(0.3), 60),
    ) {
        // Each data frame in fast mode, or in slow mode after an info frame, with its trailer; a
        // data frame cut out whole takes its trailer with it, not the info frame before it.
        let info = InfoFrame::parse(&CAPTURE_INFO).unwrap();
        let sent = older::sent_frames(&cuts[..frames.len()], v4::MAX_CHAINED_GAP);
        let mut wire = Vec::new();
        let (mut want_data, mut want_info) = (Vec::new(), Vec::new());
        for (k, (f, slow)) in frames.iter().enumerate() {
            let f = DataFrame { counter: (start + k as u32) & 0xFF_FFFF, ..*f };
            if *slow {
                want_info.push(wire.len());
                wire.extend_from_slice(&info.encode());
            }
            if sent[k] {
                want_data.push((wire.len() as u64, f.counter));
                match slow {
                    true => wire.extend_from_slice(&f.encode_with_trailer()),
                    false => wire.extend_from_slice(&f.encode()),
                }
            }
        }
        prop_assume!(!fake_info_outside(&wire, &want_info));
        let (decoded, stats) = bulk::<Scanner>(&wire);
        let got_data: Vec<(u64, u32)> =
            data_of(&decoded).iter().map(|(at, d)| (*at, d.packet())).collect();
        let got_info: Vec<usize> = infos_of(&decoded).iter().map(|(at, _)| *at as usize).collect();
        prop_assert_eq!(got_data, want_data);
        prop_assert_eq!(got_info, want_info);
        prop_assert_eq!(figures(&stats), Figures::after_cuts(sent.iter().filter(|&&s| !s).count()));
        prop_assert_eq!(streamed_bytewise::<Scanner>(&wire), (decoded, stats));
    }

    #[test]
    fn random_bytes_after_a_chain_give_no_frame(
        chain in chain(),
        bytes in vec(noisy_byte(), 1..300),
    ) {
        // The bytes start where the chain ends: any `9B` there is judged against the chain.
        let w = build(&[chain, Piece::Garbage(bytes)]);
        prop_assume!(!has_fake_info(&w));
        assert_finds_exactly(&w)?;
    }

    #[test]
    fn random_bytes_rich_in_9b_and_b9_give_no_frame(bytes in vec(noisy_byte(), 0..3000)) {
        let (decoded, stats) = bulk::<Scanner>(&bytes);
        prop_assert!(decoded.is_empty());
        prop_assert_eq!(stats.bytes_skipped(), bytes.len() as u64);
    }

    #[test]
    fn a_stream_switching_from_v3_to_v4(
        v3_start in 0u32..1 << 24,
        v3_fields in vec((0u16..=255, 0u16..=255, any::<u16>()), 3..8),
        v4 in chain(),
    ) {
        // V4 frames with throttle and PWM below 256 share bytes 0-7 with V3 frames.
        let v4 = match v4 {
            Piece::Fast(s, f) => Piece::Fast(s, f.into_iter().map(|f| DataFrame {
                throttle_in_raw: f.throttle_in_raw % 256,
                throttle_out_raw: f.throttle_out_raw % 256,
                ..f
            }).collect()),
            other => other,
        };
        let mut bytes = Vec::new();
        let mut v3_frames = Vec::new();
        for (k, &(t, p, e)) in v3_fields.iter().enumerate() {
            let f = v3::V3Frame {
                counter: (v3_start + k as u32) & 0xFF_FFFF,
                throttle_in_raw: t,
                pwm_out_raw: p,
                period_us: e,
            };
            v3_frames.push((bytes.len() as u64, f));
            bytes.extend_from_slice(&f.encode());
        }
        let v4_part = build(&[v4]);
        prop_assume!(!has_fake_info(&v4_part));
        let base = bytes.len() as u64;
        bytes.extend_from_slice(&v4_part.bytes);

        let got3: Vec<(u64, v3::V3Frame)> = v3::frames(&bytes).map(|d| (d.offset, d.frame)).collect();
        prop_assert_eq!(got3, v3_frames);
        let got4: Vec<(u64, V4Frame)> = v4::frames(&bytes).map(|d| (d.offset, d.frame)).collect();
        let want4: Vec<(u64, V4Frame)> = v4_part.frames.iter().map(|(at, f)| (at + base, *f)).collect();
        prop_assert_eq!(got4, want4);
    }
}

/// The figures of a link that [`Figures`] compares.
fn figures(stats: &v4::Stats) -> Figures {
    Figures::of(
        stats.counter(),
        stats.bytes_skipped(),
        stats.rejected(),
        stats.syncs(),
    )
}

#[test]
fn stats_display_names_every_counter() {
    let mut wire = Vec::new();
    for c in 0..3 {
        wire.extend_from_slice(&data(c).encode_with_trailer());
    }
    let (_, stats) = bulk::<Scanner>(&wire);
    assert_eq!(
        stats.to_string(),
        "60 bytes, 3 data frames (3 with trailer), 0 info frames (0 adoptions, 0 disagreeing), \
         0 bytes skipped, 0 implausible and 0 unconfirmed candidates, 1 syncs, 0 lost packets, \
         0 duplicate packets, 0 restarts"
    );
}
