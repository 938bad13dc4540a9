//! Throughput of the DroneCAN receiver (`dronecan::Receiver::push`) on a realistic bus: CAN
//! frames in, transfers reassembled, CRC-checked and decoded, per-node statistics kept.
//!
//! The bus: 16 Hobbywing ESCs (nodes 1-16), each sending `StatusMsg1` at 100 Hz, `StatusMsg2`
//! at 50 Hz, `StatusMsg3` at 10 Hz and `uavcan.protocol.NodeStatus` at 1 Hz (single frames);
//! 4 of them (nodes 1-4) also send `uavcan.equipment.esc.Status` at 50 Hz, a 3-frame transfer
//! whose frames interleave with the other nodes' (the Hobbywing types' rates are configurable,
//! `SetReportingFrequency`: 500 to 1 Hz; these are a plausible mix, not a measured one). Each
//! node's messages start at its own phase; a frame takes 130 us at 1 Mbit/s, so the frames of a
//! multi-frame transfer are 130 us apart and other nodes' frames fall between them. Ten seconds
//! of that bus: 3 176 frames a second (41 % of a 1 Mbit/s bus), 31 760 frames, made by the
//! codec's encoder (`Message::frames`) with field values that change from message to message.
//!
//! Measured: frames per second through `Receiver::push` (criterion's elements/s), every frame
//! of the ten seconds once per iteration, into one receiver kept across iterations (at each
//! pass's start a stream's transfer id jumps back, counted as a gap: the same work). Before
//! measuring, one pass into a new receiver is checked: every transfer received, no error and no
//! gap counted.
//!
//! Run: `cargo bench -p hwfoc --bench dronecan`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use hwfoc::dronecan::{
    CanFrame, EscStatus, Kind, Message, NodeStatus, Receiver, StatusMsg1, StatusMsg2, StatusMsg3,
};

/// Seconds of bus traffic measured.
const SECONDS: u64 = 10;
/// Nodes on the bus.
const NODES: u8 = 16;
/// Nodes that also send esc.Status.
const ESC_STATUS_NODES: u8 = 4;
/// Time a CAN frame takes at 1 Mbit/s, us (an 8-byte extended frame with stuffing).
const FRAME_US: u64 = 130;

/// xorshift64* (Vigna), as in `bulk.rs`.
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

    fn range(&mut self, lo: u32, hi: u32) -> u32 {
        lo + ((self.next_u64() >> 32) % u64::from(hi - lo + 1)) as u32
    }
}

/// One message stream of a node: what it sends and how often.
#[derive(Clone, Copy)]
enum Stream {
    Msg1,
    Msg2,
    Msg3,
    NodeStatus,
    EscStatus,
}

impl Stream {
    fn hz(self) -> u64 {
        match self {
            Stream::Msg1 => 100,
            Stream::Msg2 => 50,
            Stream::Msg3 => 10,
            Stream::NodeStatus => 1,
            Stream::EscStatus => 50,
        }
    }

    fn message(self, rng: &mut Rng, node: u8, n: u64) -> Message {
        let r = |rng: &mut Rng, lo, hi| rng.range(lo, hi);
        match self {
            Stream::Msg1 => StatusMsg1 {
                rpm: r(rng, 3000, 9000) as u16,
                pwm: r(rng, 300, 900) as u16,
                status: 0,
            }
            .into(),
            Stream::Msg2 => StatusMsg2 {
                input_voltage: r(rng, 480, 504) as i16,
                current: r(rng, 50, 600) as i16,
                temperature: r(rng, 40, 70) as u8,
            }
            .into(),
            Stream::Msg3 => StatusMsg3 {
                mos_t: r(rng, 40, 70) as u8,
                cap_t: r(rng, 35, 60) as u8,
                motor_t: r(rng, 45, 90) as u8,
            }
            .into(),
            Stream::NodeStatus => NodeStatus {
                uptime_sec: n as u32,
                health: 0,
                mode: 0,
                sub_mode: 0,
                vendor_specific_status_code: 0,
            }
            .into(),
            Stream::EscStatus => EscStatus {
                error_count: 0,
                voltage: 48.0 + r(rng, 0, 24) as f32 / 10.0,
                current: r(rng, 5, 60) as f32,
                temperature: 273.15 + r(rng, 40, 70) as f32,
                rpm: r(rng, 3000, 9000) as i32,
                power_rating_pct: r(rng, 30, 90) as u8,
                esc_index: node - 1,
            }
            .into(),
        }
    }
}

/// The bus's frames in time order, and the number of transfers they carry.
fn bus() -> (Vec<CanFrame>, usize) {
    let mut rng = Rng(0xD20_5CA4_0000_0016);
    let mut timed: Vec<(u64, u32, CanFrame)> = Vec::new();
    let mut transfers = 0;
    let mut order = 0u32;
    for node in 1..=NODES {
        let mut streams = vec![Stream::Msg1, Stream::Msg2, Stream::Msg3, Stream::NodeStatus];
        if node <= ESC_STATUS_NODES {
            streams.push(Stream::EscStatus);
        }
        for stream in streams {
            let period = 1_000_000 / stream.hz();
            let phase = u64::from(rng.range(0, period as u32 - 1));
            for n in 0..SECONDS * stream.hz() {
                let m = stream.message(&mut rng, node, n);
                let t = phase + n * period;
                for (k, f) in m.frames(16, node, 0, (n % 32) as u8).enumerate() {
                    timed.push((t + k as u64 * FRAME_US, order, f));
                    order += 1;
                }
                transfers += 1;
            }
        }
    }
    // By time; a transfer's frames keep their order (`order` breaks ties).
    timed.sort_by_key(|&(t, o, _)| (t, o));
    (timed.into_iter().map(|(_, _, f)| f).collect(), transfers)
}

fn receive(c: &mut Criterion) {
    let (frames, transfers) = bus();
    let mut rx = Receiver::new();
    let got = frames.iter().filter_map(|f| rx.push(f)).count();
    assert_eq!(got, transfers, "every transfer received");
    let mut esc_status = 0;
    for (node, s) in rx.stats().nodes() {
        assert_eq!(s.errors(), 0, "node {node}: {s:?}");
        assert_eq!(s.gaps(), 0, "node {node}");
        esc_status += s.transfers(Kind::EscStatus);
    }
    eprintln!(
        "dronecan bus: {} frames, {} transfers ({esc_status} esc.Status of 3 frames) in {SECONDS} \
         s of a {NODES}-node bus",
        frames.len(),
        transfers,
    );

    let mut g = c.benchmark_group("dronecan");
    g.throughput(Throughput::Elements(frames.len() as u64));
    g.bench_function("receiver_push", |b| {
        let mut rx = Receiver::new();
        b.iter(|| {
            let mut acc = 0u64;
            for f in black_box(&frames) {
                if let Some(r) = rx.push(f) {
                    acc = acc
                        .wrapping_add(u64::from(r.transfer_id) ^ u64::from(r.header.source_node));
                }
            }
            black_box(acc)
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    targets = receive
}
criterion_main!(benches);
