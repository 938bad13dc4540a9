//! The V3 decoder: golden results on the real Platinum Pro V3 capture, properties (encode/decode
//! identity, chunking independence, garbage and cut frames between chains, random bytes), and
//! the lock rule's edges.

#[allow(dead_code)] // `data_frame` is the HW-FOC generator
mod common;
mod older;

use common::{cut_points, streamed_bytewise};
use hwfoc::counters::PacketSequence24;
use hwfoc::v3::{self, Decoded, Decoder, FRAME_LEN, Scanner, V3Frame};
use older::{Figures, PLATINUM_PRO_V3, PLATINUM_V4, RANDOM_LEN, Rng, XROTOR, bulk, load};
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::Index;

// ---------------------------------------------------------------------------------------------
// The real capture
// ---------------------------------------------------------------------------------------------

#[test]
fn capture_decodes_completely() {
    let bytes = load(PLATINUM_PRO_V3);
    assert_eq!(bytes.len(), 6990);
    let (decoded, stats) = bulk::<Scanner>(&bytes);
    assert_eq!(decoded.len(), 699);
    for (k, d) in decoded.iter().enumerate() {
        assert_eq!(d.offset, (k * FRAME_LEN) as u64, "frame {k}");
        assert_eq!(d.frame.counter, k as u32, "frame {k}");
    }
    assert_eq!(stats.frames(), 699);
    assert_eq!(stats.bytes(), 6990);
    assert_eq!(stats.bytes_skipped(), 0);
    assert_eq!(stats.rejected(), 0);
    assert_eq!(stats.syncs(), 1);
    let c = stats.counter();
    assert_eq!((c.lost(), c.duplicates(), c.restarts()), (0, 0, 0));
    assert_eq!(stats.last_counter(), Some(698));
    // The five `9B` inside payloads were never taken for candidates.
    assert_eq!(bytes.iter().filter(|&&b| b == 0x9B).count(), 699 + 5);
}

#[test]
fn capture_values() {
    let (decoded, _) = bulk::<Scanner>(&load(PLATINUM_PRO_V3));
    let frames: Vec<V3Frame> = decoded.iter().map(|d| d.frame).collect();
    assert_eq!(
        frames[0],
        V3Frame {
            counter: 0,
            throttle_in_raw: 107,
            pwm_out_raw: 10,
            period_us: v3::PLACEHOLDER_PERIOD_US
        }
    );
    // 28 frames hold the start-up placeholder: no speed.
    let no_speed = frames.iter().filter(|f| f.erpm().is_none()).count();
    assert_eq!(no_speed, 28);
    let max_erpm = frames.iter().filter_map(V3Frame::erpm).max();
    assert_eq!(max_erpm, Some(60_000_000 / 1538));
    let throttle = |f: &V3Frame| f.throttle_in_raw;
    assert_eq!(frames.iter().map(throttle).min(), Some(10));
    assert_eq!(frames.iter().map(throttle).max(), Some(107));
    assert!(frames.iter().all(|f| f.pwm_out_raw <= 116));
}

#[test]
fn capture_in_any_chunking() {
    let bytes = load(PLATINUM_PRO_V3);
    older::assert_every_path_agrees::<Scanner>(
        &bytes,
        &[2, 3, 9, 10, 11, 19, 20, 21, 29, 30, 31, 1000, 7000],
    );
}

#[test]
fn other_captures_give_no_v3_frame() {
    // The V4 capture: bytes 0-7 of its data frames would read as V3 frames, but they never
    // chain 10 bytes apart.
    for name in [PLATINUM_V4, XROTOR] {
        let bytes = load(name);
        let (decoded, stats) = bulk::<Scanner>(&bytes);
        assert!(decoded.is_empty(), "{name}: {:?}", &decoded[..1]);
        assert_eq!(stats.bytes_skipped(), bytes.len() as u64, "{name}");
        assert!(stats.rejected() > 20, "{name}: {stats}");
    }
}

// ---------------------------------------------------------------------------------------------
// Random bytes
// ---------------------------------------------------------------------------------------------

#[test]
fn two_million_random_bytes_give_no_frame() {
    let mut rng = Rng(0x5EED_0003);
    for (kind, bytes) in [
        ("uniform", rng.uniform(RANDOM_LEN)),
        ("rich in 9B and B9", rng.rich(RANDOM_LEN)),
    ] {
        let (decoded, stats) = bulk::<Scanner>(&bytes);
        assert!(decoded.is_empty(), "{kind}: {:?}", &decoded[..1]);
        assert_eq!(stats.bytes_skipped(), RANDOM_LEN as u64, "{kind}");
        // Every 9B was a candidate, and was rejected (or cut off at the very end).
        let syncs = bytes.iter().filter(|&&b| b == 0x9B).count() as u64;
        assert!(u64::from(stats.rejected()) + 3 >= syncs, "{kind}: {stats}");
        assert!(stats.implausible() > 0, "{kind}");
    }
}

// ---------------------------------------------------------------------------------------------
// The lock rule's edges
// ---------------------------------------------------------------------------------------------

fn frame(counter: u32) -> V3Frame {
    V3Frame {
        counter,
        throttle_in_raw: 120,
        pwm_out_raw: 60,
        period_us: 2000,
    }
}

fn encode_all(counters: impl IntoIterator<Item = u32>) -> Vec<u8> {
    counters
        .into_iter()
        .flat_map(|c| frame(c).encode())
        .collect()
}

fn counters(decoded: &[Decoded]) -> Vec<u32> {
    decoded.iter().map(|d| d.frame.counter).collect()
}

#[test]
fn two_chained_frames_are_not_enough() {
    let (decoded, stats) = bulk::<Scanner>(&encode_all([4, 5]));
    assert!(decoded.is_empty());
    assert_eq!((stats.bytes_skipped(), stats.rejected()), (20, 0));
    // Three are, and so are all after them.
    let (decoded, _) = bulk::<Scanner>(&encode_all(4..7));
    assert_eq!(counters(&decoded), [4, 5, 6]);
}

#[test]
fn an_esc_restart_starts_a_new_chain() {
    let mut wire = encode_all(500..510);
    wire.extend(encode_all(0..5)); // rebooted: the counter starts again at 0
    let (decoded, stats) = bulk::<Scanner>(&wire);
    assert_eq!(decoded.len(), 15);
    assert_eq!(
        (stats.restarts(), stats.lost_packets(), stats.syncs()),
        (1, 0, 2)
    );
    assert_eq!(stats.bytes_skipped(), 0);
}

#[test]
fn lost_frames_are_counted_across_a_gap() {
    let mut wire = encode_all(0..4);
    wire.extend_from_slice(&frame(4).encode()[..6]); // frame 4 cut short
    wire.extend(encode_all(7..10)); // 5 and 6 never sent
    let (decoded, stats) = bulk::<Scanner>(&wire);
    assert_eq!(counters(&decoded), [0, 1, 2, 3, 7, 8, 9]);
    assert_eq!((stats.lost_packets(), stats.bytes_skipped()), (3, 6));
}

#[test]
fn a_corrupted_counter_costs_that_frame() {
    let mut wire = encode_all(0..8);
    wire[4 * FRAME_LEN + 2] ^= 0x10; // frame 4's counter
    let (decoded, stats) = bulk::<Scanner>(&wire);
    assert_eq!(counters(&decoded), [0, 1, 2, 3, 5, 6, 7]);
    assert_eq!(
        (stats.unconfirmed(), stats.lost_packets(), stats.syncs()),
        (1, 1, 2)
    );
}

#[test]
fn a_frame_between_two_cut_frames_continues_the_chain_up_to_the_bound() {
    // 3 and 5 cut out whole: 4 and 6 have no consecutive neighbour, yet each starts where the
    // chain ends with its counter advanced by two.
    let (decoded, stats) = bulk::<Scanner>(&encode_all([0, 1, 2, 4, 6]));
    assert_eq!(counters(&decoded), [0, 1, 2, 4, 6]);
    assert_eq!((stats.lost_packets(), stats.syncs()), (2, 1));
    // Up to MAX_CHAINED_GAP frames missing; one more, and the frame needs a chain of three.
    let last = 2 + v3::MAX_CHAINED_GAP + 1;
    let (decoded, _) = bulk::<Scanner>(&encode_all([0, 1, 2, last, last + 2]));
    assert_eq!(counters(&decoded), [0, 1, 2, last, last + 2]);
    let (decoded, stats) = bulk::<Scanner>(&encode_all([0, 1, 2, last + 1, last + 3]));
    assert_eq!(counters(&decoded), [0, 1, 2]);
    assert_eq!(stats.unconfirmed(), 1);
    // Not a step back, nor the same counter again.
    for repeated in [0, 2] {
        let (decoded, _) = bulk::<Scanner>(&encode_all([0, 1, 2, repeated, 9]));
        assert_eq!(counters(&decoded), [0, 1, 2]);
    }
}

/// The documented limit of the gap rule: a flip that moves a counter forward by at most
/// `MAX_CHAINED_GAP` (bit 0 or 1 of its low byte) passes for frames cut before it; the frame is
/// taken with its wrong counter and the next one, whose counter goes back, starts a new chain.
#[test]
fn a_counter_flipped_forward_within_the_gap_passes_for_cut_frames() {
    let mut wire = encode_all(0..8);
    wire[4 * FRAME_LEN + 3] ^= 0x02; // frame 4's counter becomes 6
    let (decoded, stats) = bulk::<Scanner>(&wire);
    assert_eq!(counters(&decoded), [0, 1, 2, 3, 6, 5, 6, 7]);
    assert_eq!(
        (stats.lost_packets(), stats.restarts(), stats.syncs()),
        (2, 1, 2)
    );
}

/// The documented limit: a chained frame that is cut short, whose counter follows and which
/// the next frame's bytes complete into a plausible one, cannot be told from a real frame; the
/// frame whose start it swallowed is lost, and the chain resumes three frames later.
#[test]
fn a_cut_frame_that_stays_plausible_is_taken() {
    let mut wire = encode_all(0..3);
    wire.extend_from_slice(&frame(3).encode()[..8]); // its period missing
    wire.extend(encode_all(4..10));
    let (decoded, stats) = bulk::<Scanner>(&wire);
    let got = counters(&decoded);
    assert_eq!(got, [0, 1, 2, 3, 5, 6, 7, 8, 9]);
    // V3Frame "3" took the first two bytes of frame 4 as its period.
    assert_eq!(decoded[3].frame.period_us, 0x9B00);
    assert_eq!(stats.lost_packets(), 1);
}

/// The stream for V3: 120 s of a V3 ESC as `hwfoc simulate --protocol hw-v3
/// --duration 120` sends them (6154 frames back to back) with 5 % of them (308) cut out whole.
/// Every frame left intact is decoded, also one that lies between two cut frames (and so has
/// no consecutive neighbour to confirm it), and exactly the frames cut are counted lost.
#[test]
fn no_intact_frame_is_lost_between_frames_cut_out_whole() {
    let mut rng = Rng(0x5EED_0120);
    let sent: Vec<V3Frame> = (0..6154u32)
        .map(|k| V3Frame {
            counter: 0xAB_0000 + k,
            throttle_in_raw: (rng.next() % 256) as u16,
            pwm_out_raw: (rng.next() % 256) as u16,
            period_us: rng.next() as u16,
        })
        .collect();
    // The first and the last frame are kept, so that every frame cut is a visible loss.
    let cut = rng.sample(1..sent.len() - 1, 308);
    let mut wire = Vec::new();
    let mut want = Vec::new();
    for (k, f) in sent.iter().enumerate() {
        if cut.binary_search(&k).is_err() {
            want.push((wire.len() as u64, f.counter));
            wire.extend_from_slice(&f.encode());
        }
    }
    let (decoded, stats) = bulk::<Scanner>(&wire);
    let got: Vec<(u64, u32)> = decoded
        .iter()
        .map(|d| (d.offset, d.frame.counter))
        .collect();
    older::assert_frames(&got, &want, 0xAB_0000);
    assert_eq!(figures(&stats), Figures::after_cuts(cut.len()));
    older::assert_every_path_agrees::<Scanner>(&wire, &[10, 11, 64]);
}

#[test]
fn a_silence_decides_the_held_bytes() {
    let wire = encode_all(0..4);
    let mut d = Decoder::new();
    let mut got = Vec::new();
    d.feed(&wire[..35], |x| got.push(x.frame.counter));
    assert_eq!(got, [0, 1, 2]);
    // A silence in the middle of frame 3 ends it: reported, the frame is dropped.
    d.line_silent(10, |x| got.push(x.frame.counter));
    d.feed(&wire[35..], |x| got.push(x.frame.counter));
    d.flush(|x| got.push(x.frame.counter));
    assert_eq!(got, [0, 1, 2]);
    assert_eq!(d.stats().bytes_skipped(), 10);
}

// ---------------------------------------------------------------------------------------------
// Properties
// ---------------------------------------------------------------------------------------------

fn any_frame() -> impl Strategy<Value = V3Frame> {
    (0u32..1 << 24, any::<u16>(), any::<u16>(), any::<u16>()).prop_map(|(c, t, p, e)| V3Frame {
        counter: c,
        throttle_in_raw: t,
        pwm_out_raw: p,
        period_us: e,
    })
}

/// A chain: its first counter (random, so that chains do not continue each other) and the
/// plausible fields of at least three frames.
fn chain() -> impl Strategy<Value = (u32, Vec<(u16, u16, u16)>)> {
    (
        0u32..1 << 24,
        vec((0u16..=255, 0u16..=255, any::<u16>()), 3..8),
    )
}

/// Bytes rich in `9B` and in the bytes of small fields.
fn noisy_byte() -> impl Strategy<Value = u8> {
    prop_oneof![6 => any::<u8>(), 3 => Just(0x9B), 1 => Just(0x00)]
}

#[derive(Debug, Clone)]
enum Piece {
    Chain(u32, Vec<(u16, u16, u16)>),
    Garbage(Vec<u8>),
    /// The first `n` bytes (1..10) of a frame.
    Cut(V3Frame, usize),
}

/// A wire, and what a decoder must find in it.
struct Wire {
    bytes: Vec<u8>,
    frames: Vec<(u64, V3Frame)>,
    skipped: u64,
    syncs: u32,
    sequence: PacketSequence24,
}

fn build(pieces: &[Piece]) -> Wire {
    let mut w = Wire {
        bytes: Vec::new(),
        frames: Vec::new(),
        skipped: 0,
        syncs: 0,
        sequence: PacketSequence24::new(),
    };
    // Where the last chain ended and its next counter: a chain starting right there with that
    // counter continues it.
    let mut chain_end: Option<(usize, u32)> = None;
    for p in pieces {
        match p {
            Piece::Chain(start, fields) => {
                if chain_end != Some((w.bytes.len(), *start)) {
                    w.syncs += 1;
                }
                let mut counter = *start;
                for &(t, p, e) in fields {
                    let f = V3Frame {
                        counter,
                        throttle_in_raw: t,
                        pwm_out_raw: p,
                        period_us: e,
                    };
                    w.frames.push((w.bytes.len() as u64, f));
                    w.sequence.next(counter);
                    w.bytes.extend_from_slice(&f.encode());
                    counter = (counter + 1) & 0xFF_FFFF;
                }
                chain_end = Some((w.bytes.len(), counter));
            }
            Piece::Garbage(g) => {
                w.bytes.extend_from_slice(g);
                w.skipped += g.len() as u64;
            }
            Piece::Cut(f, n) => {
                w.bytes.extend_from_slice(&f.encode()[..*n]);
                w.skipped += *n as u64;
            }
        }
    }
    w
}

fn assert_finds_exactly(w: &Wire) -> Result<(), TestCaseError> {
    let (decoded, stats) = bulk::<Scanner>(&w.bytes);
    let got: Vec<(u64, V3Frame)> = decoded.iter().map(|d| (d.offset, d.frame)).collect();
    prop_assert_eq!(&got, &w.frames);
    prop_assert_eq!(stats.bytes_skipped(), w.skipped);
    prop_assert_eq!(stats.bytes(), w.bytes.len() as u64);
    prop_assert_eq!(stats.syncs(), w.syncs);
    prop_assert_eq!(stats.counter(), &w.sequence);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn encode_decode_identity(f in any_frame()) {
        let bytes = f.encode();
        prop_assert_eq!(bytes[0], 0x9B);
        prop_assert_eq!(V3Frame::parse(&bytes), Some(f));
        prop_assert_eq!(f.is_plausible(), f.throttle_in_raw <= 255 && f.pwm_out_raw <= 255);
    }

    #[test]
    fn chains_decode_exactly(chains in vec(chain(), 1..5)) {
        let pieces: Vec<Piece> = chains.into_iter().map(|(s, f)| Piece::Chain(s, f)).collect();
        assert_finds_exactly(&build(&pieces))?;
    }

    #[test]
    fn garbage_between_chains_is_skipped_and_counted(
        parts in vec((vec(noisy_byte(), 0..40), chain()), 1..5),
        tail in vec(noisy_byte(), 0..40),
    ) {
        let mut pieces = Vec::new();
        for (garbage, (start, fields)) in parts {
            pieces.push(Piece::Garbage(garbage));
            pieces.push(Piece::Chain(start, fields));
        }
        pieces.push(Piece::Garbage(tail));
        let w = build(&pieces);
        assert_finds_exactly(&w)?;
        // Every 9B outside the frames was a candidate: rejected, or cut off by the end.
        let (_, stats) = bulk::<Scanner>(&w.bytes);
        let (outside, near_end) = syncs_outside(&w.bytes, w.frames.iter().map(|(at, _)| *at));
        prop_assert!(stats.rejected() <= outside && outside - near_end <= stats.rejected());
    }

    #[test]
    fn cut_frames_between_chains_are_skipped(
        parts in vec(((any_frame(), any::<Index>()), chain()), 1..5),
    ) {
        let mut pieces = Vec::new();
        for ((cut, n), (start, fields)) in parts {
            pieces.push(Piece::Chain(start, fields));
            pieces.push(Piece::Cut(cut, 1 + n.index(FRAME_LEN - 1)));
        }
        assert_finds_exactly(&build(&pieces))?;
    }

    #[test]
    fn any_chunking_gives_the_same_frames_and_stats(
        pieces in vec(prop_oneof![
            3 => chain().prop_map(|(s, f)| Piece::Chain(s, f)),
            2 => vec(noisy_byte(), 0..30).prop_map(Piece::Garbage),
            2 => (any_frame(), 1..FRAME_LEN).prop_map(|(f, n)| Piece::Cut(f, n)),
        ], 0..10),
        picks in vec(any::<Index>(), 0..20),
    ) {
        let w = build(&pieces);
        let reference = bulk::<Scanner>(&w.bytes);
        let cuts = cut_points(w.bytes.len(), &picks);
        prop_assert_eq!(&older::streamed_at::<Scanner>(&w.bytes, &cuts), &reference);
        prop_assert_eq!(&streamed_bytewise::<Scanner>(&w.bytes), &reference);
        let (_, stats) = &reference;
        prop_assert_eq!(stats.bytes(), 10 * u64::from(stats.frames()) + stats.bytes_skipped());
    }

    #[test]
    fn every_frame_left_between_frames_cut_out_whole_is_decoded(
        (start, fields) in (0u32..1 << 24, vec((0u16..=255, 0u16..=255, any::<u16>()), 4..60)),
        cuts in vec(prop::bool::weighted(0.3), 60),
    ) {
        let sent = older::sent_frames(&cuts[..fields.len()], v3::MAX_CHAINED_GAP);
        let mut wire = Vec::new();
        let mut want = Vec::new();
        for (k, &(t, p, e)) in fields.iter().enumerate() {
            let f = V3Frame {
                counter: (start + k as u32) & 0xFF_FFFF,
                throttle_in_raw: t,
                pwm_out_raw: p,
                period_us: e,
            };
            if sent[k] {
                want.push((wire.len() as u64, f));
                wire.extend_from_slice(&f.encode());
            }
        }
        let (decoded, stats) = bulk::<Scanner>(&wire);
        let got: Vec<(u64, V3Frame)> = decoded.iter().map(|d| (d.offset, d.frame)).collect();
        prop_assert_eq!(got, want);
        prop_assert_eq!(figures(&stats), Figures::after_cuts(sent.iter().filter(|&&s| !s).count()));
        prop_assert_eq!(streamed_bytewise::<Scanner>(&wire), (decoded, stats));
    }

    #[test]
    fn random_bytes_after_a_chain_give_no_frame(
        (start, fields) in chain(),
        bytes in vec(noisy_byte(), 0..300),
    ) {
        // The bytes start where the chain ends: any `9B` there is judged against the chain.
        let w = build(&[Piece::Chain(start, fields), Piece::Garbage(bytes)]);
        assert_finds_exactly(&w)?;
    }

    #[test]
    fn random_bytes_give_no_frame(bytes in vec(noisy_byte(), 0..3000)) {
        let (decoded, stats) = bulk::<Scanner>(&bytes);
        prop_assert!(decoded.is_empty());
        prop_assert_eq!(stats.bytes_skipped(), bytes.len() as u64);
    }
}

/// The `9B` bytes outside the frames at `starts`, and how many of them lie in the last 29
/// bytes (where a candidate may be cut off by the end rather than rejected).
fn syncs_outside(bytes: &[u8], starts: impl Iterator<Item = u64>) -> (u32, u32) {
    let mut inside = vec![false; bytes.len()];
    for at in starts {
        inside[at as usize..at as usize + FRAME_LEN].fill(true);
    }
    let mut outside = 0;
    let mut near_end = 0;
    for (i, &b) in bytes.iter().enumerate() {
        if b == 0x9B && !inside[i] {
            outside += 1;
            if i + 3 * FRAME_LEN > bytes.len() {
                near_end += 1;
            }
        }
    }
    (outside, near_end)
}

/// The figures of a link that [`Figures`] compares.
fn figures(stats: &v3::Stats) -> Figures {
    Figures::of(
        stats.counter(),
        stats.bytes_skipped(),
        stats.rejected(),
        stats.syncs(),
    )
}

#[test]
fn stats_display_names_every_counter() {
    let (_, stats) = bulk::<Scanner>(&encode_all(0..3));
    assert_eq!(
        stats.to_string(),
        "30 bytes, 3 frames, 0 bytes skipped, 0 implausible and 0 unconfirmed candidates, \
         1 syncs, 0 lost packets, 0 duplicate packets, 0 restarts"
    );
}
