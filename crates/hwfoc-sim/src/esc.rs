//! One virtual ESC on its wire: when frames go out, what is in them, and what the link does to
//! them.
//!
//! Timing, as real HW-FOC ESCs do it: while the motor turns, a data frame every 50 ms; idle
//! (disarmed or stopped), a data frame every 364 ms, each followed 40 ms after its start by the
//! 77-byte device-information frame. The ESC checks its state every 50 ms, so a motor starting
//! gets its first running frame within 50 ms. Frames never overlap on the wire: one that is due
//! while the previous is still being sent waits for it. The first frame comes at a random phase
//! within the first 50 ms, and every ESC but the first runs the throttle profile a little behind
//! and at a load of its own ([`spread`]), so that several ESCs are not in lockstep.
//!
//! The ESC's output is an endless series of [`Burst`]s, bytes sent back to back, in time
//! order: frames, and the garbage and glitches the link adds between them.
//!
//! The other formats' schedules are their modules' in [`crate::formats`]; they run over the
//! same model and wire, but without link faults (the fleet refuses them: see there).
//!
//! Ground truth stays exact under link faults: the ESC runs a reference decoder over its own
//! wire, and if a fault would make the decoder see a frame that was never sent (a corruption the
//! 16-bit sum cannot catch, or the start of a cut frame completed by the next frame's bytes so
//! that the sum happens to match: about one in 65536), it changes the fault (one more flipped
//! checksum bit; a few glitch bytes of 0x00 before the next frame) until the decoder sees
//! exactly the intact frames, in order.

use std::collections::VecDeque;
use std::rc::Rc;

use hwfoc::foc::{DataFrame, Decoder, FocFrame, InfoFrame};
use hwfoc::{Fault, Protocol};

pub use crate::burst::{Burst, What};
use crate::degrade::{DegradeSpec, ModelDegradations, WireLoss};
use crate::faults::{Fate, FaultSchedule, LineFaults, LinkRates};
use crate::formats::{self, Speaker, Start};
use crate::model::{Model, ModelConfig};
use crate::profile::Profile;
use crate::rng::{Purpose, Rng};

/// Data frame interval while the motor turns, ns.
pub const RUN_INTERVAL_NS: u64 = 50_000_000;
/// Data frame interval while idle, ns.
pub const IDLE_INTERVAL_NS: u64 = 364_000_000;
/// Delay from the start of an idle data frame to the start of its device-information frame, ns.
pub const INFO_DELAY_NS: u64 = 40_000_000;
/// Longest step of the physical model, ns.
const MODEL_STEP_NS: u64 = 5_000_000;
/// Most glitch bytes put before a frame to keep the reference decoder from a false frame.
const MAX_GLITCH: usize = 8;

/// The device-information text every virtual ESC sends (an XRotor's), with its own id.
const PRODUCT: &str = "XR_FOC_ESC";
const HARDWARE: &str = "HW577_KZ1_V1.1";
const FIRMWARE: &str = "XR-01.0.00";

/// Everything one virtual ESC is made from.
#[derive(Debug, Clone)]
pub struct Setup {
    /// Index of the ESC (the `esc` of its records).
    pub index: usize,
    /// The run's seed.
    pub seed: u64,
    /// The protocol it speaks (every one of [`formats::SIMULATED`]).
    pub protocol: Protocol,
    /// Line rate, bits per second (10 bits per byte, 8N1).
    pub baud: u32,
    /// First packet number; random from the seed if `None`.
    pub start_packet: Option<u16>,
    /// Motor, battery, ESC.
    pub model: ModelConfig,
    /// The throttle command.
    pub profile: Rc<Profile>,
    /// How far this ESC runs behind the profile, seconds: it sees the throttle of `t - lag_s`
    /// (see [`spread`]).
    pub lag_s: f64,
    /// This ESC's share of the propeller load, times the model's `full_current_a` (see
    /// [`spread`]).
    pub load: f64,
    /// Injected status bits.
    pub faults: FaultSchedule,
    /// Link fault rates.
    pub link: LinkRates,
    /// Degradations of the run (those of this ESC act on it).
    pub degradations: Vec<DegradeSpec>,
}

/// A virtual ESC: the model, its frame schedule and its link.
pub struct VirtualEsc {
    setup: Setup,
    /// Nanoseconds per byte on the wire.
    byte_ns: f64,
    model: Model,
    /// Simulated time the model has reached, ns.
    model_ns: u64,
    noise: Rng,
    link: LineFaults,
    /// A loose wire's bursts of loss.
    wire: WireLoss,
    packet: u16,
    info: InfoFrame,
    /// Next 50 ms check.
    next_tick_ns: u64,
    /// Start of the last data frame the ESC sent (or meant to).
    last_data_ns: Option<u64>,
    info_due_ns: Option<u64>,
    /// When the wire is free again after the bursts handed out so far.
    wire_free_ns: u64,
    queue: VecDeque<Burst>,
    /// The reference decoder over everything sent, and the intact frames it has not seen yet.
    monitor: Decoder,
    expected: VecDeque<DataFrame>,
    /// The schedule of a format other than HW-FOC ([`crate::formats`]), which then sends
    /// everything.
    speaker: Option<Box<dyn Speaker>>,
}

impl VirtualEsc {
    /// An ESC at rest at time zero.
    pub fn new(setup: Setup) -> VirtualEsc {
        let (model, mut params) = Model::for_esc(setup.model, setup.load, setup.seed, setup.index);
        let model = model.degraded(ModelDegradations::for_esc(&setup.degradations, setup.index));
        let packet = setup
            .start_packet
            .unwrap_or_else(|| params.below(1 << 16) as u16);
        let phase = params.below(RUN_INTERVAL_NS);
        // Eight digits, distinct for each ESC of the run.
        let base = 10_000_000 + Rng::for_esc(setup.seed, 0, Purpose::Run).below(80_000_000);
        let id = base + setup.index as u64 * 7919;
        // Fixed ASCII fields within their lengths: cannot fail.
        let info = InfoFrame::new(PRODUCT, HARDWARE, FIRMWARE, &format!("{id:08}"))
            .expect("valid device information");
        let (speaker, next_tick_ns) = match formats::format(setup.protocol) {
            Some(format) => {
                let start = Start {
                    counter: setup.start_packet.map_or(0, u32::from),
                    cells: setup.model.cells,
                    phase_ns: phase,
                };
                let (speaker, first) = (format.start)(&start);
                (Some(speaker), first)
            }
            None => (None, phase),
        };
        VirtualEsc {
            byte_ns: hwfoc::wire::byte_ns(setup.baud),
            model,
            model_ns: 0,
            noise: Rng::for_esc(setup.seed, setup.index, Purpose::Noise),
            link: LineFaults::new(
                setup.link,
                Rng::for_esc(setup.seed, setup.index, Purpose::Link),
            ),
            wire: WireLoss::for_esc(
                &setup.degradations,
                setup.index,
                Rng::for_esc(setup.seed, setup.index, Purpose::Wire),
            ),
            packet,
            info,
            next_tick_ns,
            last_data_ns: None,
            info_due_ns: None,
            wire_free_ns: 0,
            queue: VecDeque::new(),
            monitor: Decoder::new(),
            expected: VecDeque::new(),
            speaker,
            setup,
        }
    }

    /// The protocol it speaks.
    pub fn protocol(&self) -> Protocol {
        self.setup.protocol
    }

    /// The ESC's index.
    pub fn index(&self) -> usize {
        self.setup.index
    }

    /// The HW-FOC device-information frame it sends (speaking HW-FOC).
    pub fn info(&self) -> &InfoFrame {
        &self.info
    }

    /// Nanoseconds per byte on the wire.
    pub fn byte_ns(&self) -> f64 {
        self.byte_ns
    }

    /// The next burst on the wire. The series is endless and in time order; bursts never
    /// overlap.
    pub fn next_burst(&mut self) -> Burst {
        loop {
            if let Some(burst) = self.queue.pop_front() {
                return burst;
            }
            if self.speaker.is_some() {
                self.other_tick();
                continue;
            }
            match self.info_due_ns {
                Some(due) if due <= self.next_tick_ns => {
                    self.info_due_ns = None;
                    let bytes = self.info.encode().to_vec();
                    self.send(due, bytes, None);
                }
                _ => self.tick(),
            }
        }
    }

    /// The 50 ms check: send a data frame if running, or if the idle interval is up.
    fn tick(&mut self) {
        let t = self.next_tick_ns;
        self.advance_to(t);
        let running = self.model.spinning();
        let idle_due = self
            .last_data_ns
            .is_none_or(|last| t >= last + IDLE_INTERVAL_NS);
        if running || idle_due {
            let injected = self.setup.faults.status_at(seconds(t));
            let frame = self.model.frame(self.packet, injected, &mut self.noise);
            self.packet = self.packet.wrapping_add(1);
            self.last_data_ns = Some(t);
            if !running {
                self.info_due_ns = Some(t + INFO_DELAY_NS);
            }
            self.send(t, frame.encode().to_vec(), Some(frame));
        }
        self.next_tick_ns = match self.last_data_ns {
            Some(last) if !running => (t + RUN_INTERVAL_NS).min(last + IDLE_INTERVAL_NS),
            _ => t + RUN_INTERVAL_NS,
        };
    }

    /// The next look of another format's schedule: what it sends at that moment, and when it
    /// looks again (see [`crate::formats`]).
    fn other_tick(&mut self) {
        let t = self.next_tick_ns;
        self.advance_to(t);
        let injected = self.setup.faults.status_at(seconds(t));
        let m = self.model.measure(injected, &mut self.noise);
        let Some(speaker) = self.speaker.as_mut() else {
            return;
        };
        let look = speaker.look(t, &m, &mut self.noise);
        self.next_tick_ns = look.next_ns;
        if let Some((bytes, what)) = look.send {
            self.send_plain(t, bytes, what);
        }
    }

    /// Puts a frame due at `due_ns` on the wire as it is (no link faults), after whatever is
    /// still being sent.
    fn send_plain(&mut self, due_ns: u64, bytes: Vec<u8>, what: What) {
        let start = due_ns.max(self.wire_free_ns);
        self.wire_free_ns = start + self.duration_ns(bytes.len());
        self.queue.push_back(Burst {
            t_ns: start,
            bytes,
            what,
        });
    }

    /// Runs the model up to `t_ns`.
    fn advance_to(&mut self, t_ns: u64) {
        let s = &self.setup;
        drive(
            &mut self.model,
            &mut self.model_ns,
            t_ns,
            (&s.profile, s.lag_s, &s.faults),
        );
    }

    /// Puts a frame due at `due_ns` on the wire, through the link's faults.
    fn send(&mut self, due_ns: u64, mut bytes: Vec<u8>, data: Option<DataFrame>) {
        let free = self.wire_free_ns;
        let start = due_ns.max(free);
        // Garbage in the gap before the frame, a byte time clear of both ends.
        let room = ((start - free) as f64 / self.byte_ns) as usize;
        let garbage = self.link.garbage(room.saturating_sub(2)).map(|g| {
            let len_ns = self.duration_ns(g.len());
            let t_ns = free + (start - free - len_ns) / 2;
            Burst {
                t_ns,
                bytes: g,
                what: What::Garbage,
            }
        });
        let fate = if self.wire.lost(seconds(start)) {
            bytes.clear();
            Fate::Dropped
        } else {
            self.link.transmit(&mut bytes)
        };
        let intact = (fate == Fate::Intact).then_some(data).flatten();
        let mut glitch = 0;
        let committed = loop {
            let mut monitor = self.monitor.clone();
            let mut expected = self.expected.clone();
            let glitch_bytes = vec![0u8; glitch];
            let mut ok = true;
            let garbage_bytes = garbage.as_ref().map_or(&[][..], |g| &g.bytes[..]);
            for (i, part) in [garbage_bytes, &glitch_bytes, &bytes]
                .into_iter()
                .enumerate()
            {
                if i == 2
                    && let Some(frame) = intact
                {
                    expected.push_back(frame);
                }
                monitor.feed(part, |d| {
                    if let FocFrame::Data(f) = d.frame {
                        if expected.front() == Some(&f) {
                            expected.pop_front();
                        } else {
                            ok = false;
                        }
                    }
                });
            }
            if ok || glitch == MAX_GLITCH {
                break (monitor, expected, glitch_bytes);
            }
            if fate == Fate::Corrupted && DataFrame::parse(&bytes).is_ok() {
                // The flips left a valid frame: one more in the checksum makes it detectable.
                bytes[22] ^= 0x01;
            } else {
                glitch += 1;
            }
        };
        (self.monitor, self.expected) = (committed.0, committed.1);
        let mut earliest = free;
        if let Some(g) = garbage {
            earliest = g.t_ns + self.duration_ns(g.bytes.len());
            self.queue.push_back(g);
        }
        let mut start = start;
        if glitch > 0 {
            let len_ns = self.duration_ns(glitch);
            start = start.max(earliest + len_ns);
            self.queue.push_back(Burst {
                t_ns: start - len_ns,
                bytes: committed.2,
                what: What::Glitch,
            });
        }
        self.wire_free_ns = start + self.duration_ns(bytes.len());
        let what = match data {
            Some(frame) => What::Data { frame, fate },
            None => What::Info { fate },
        };
        self.queue.push_back(Burst {
            t_ns: start,
            bytes,
            what,
        });
    }

    /// Nanoseconds that `n` bytes take on the wire, rounded up.
    fn duration_ns(&self, n: usize) -> u64 {
        (n as f64 * self.byte_ns).ceil() as u64
    }
}

/// Runs `model`, which has reached `model_ns`, up to `t_ns` in steps of at most 5 ms, under
/// the throttle of `profile` seen `lag_s` late and the injected `faults` (a lost throttle
/// signal): every virtual ESC, serial or CAN, is driven this way.
pub(crate) fn drive(
    model: &mut Model,
    model_ns: &mut u64,
    t_ns: u64,
    (profile, lag_s, faults): (&Profile, f64, &FaultSchedule),
) {
    while *model_ns < t_ns {
        let dt = MODEL_STEP_NS.min(t_ns - *model_ns);
        let now = seconds(*model_ns);
        let lost = faults.status_at(now).contains(Fault::ThrottleSignalLost);
        model.step(dt as f64 * 1e-9, profile.throttle(now - lag_s), lost);
        *model_ns += dt;
    }
}

/// The longest an ESC runs behind the profile, seconds (see [`spread`]).
pub const MAX_LAG_S: f64 = 1.0;
/// How far an ESC's load is from the model's, as a fraction (see [`spread`]).
pub const LOAD_SPREAD: f64 = 0.15;

/// The lag (seconds) and load factor of ESC `index` of a run seeded `seed`, so that the ESCs of
/// one run are not in lockstep: ESC 0 runs the profile as given at the model's load (a run of one
/// ESC is as it always was); every other one lags it by a lag from 0 to [`MAX_LAG_S`] and draws
/// a load from `1 - LOAD_SPREAD` to `1 + LOAD_SPREAD` of the model's (its propeller, its motor's
/// share of the aircraft's weight), both drawn from the seed and the index alone: the same seed
/// gives the same run.
pub fn spread(seed: u64, index: usize) -> (f64, f64) {
    if index == 0 {
        return (0.0, 1.0);
    }
    // A stream of its own (the seed turned), so that no other draw of the ESC moves with it.
    let mut rng = Rng::for_esc(seed.rotate_left(17) ^ SPREAD_SALT, index, Purpose::Params);
    let lag_s = MAX_LAG_S * rng.unit();
    let load = 1.0 + LOAD_SPREAD * rng.signed();
    (lag_s, load)
}

/// Turns the seed for [`spread`]'s draws.
const SPREAD_SALT: u64 = 0x5350_5245_4144_2d31;

/// Simulated seconds for simulated nanoseconds.
pub(crate) fn seconds(t_ns: u64) -> f64 {
    t_ns as f64 * 1e-9
}

#[cfg(test)]
pub(crate) mod tests {
    use hwfoc::telemetry::Data;

    use super::*;
    use crate::model::tests::config;
    use hwfoc::Status;

    /// ESC 0 with the default model, seed 42, starting at packet 65530.
    pub(crate) fn setup(profile: Profile, link: LinkRates) -> Setup {
        Setup {
            index: 0,
            seed: 42,
            protocol: Protocol::HwFoc,
            baud: 19200,
            start_packet: Some(65530),
            model: config(),
            profile: Rc::new(profile),
            lag_s: 0.0,
            load: 1.0,
            faults: FaultSchedule::default(),
            link,
            degradations: Vec::new(),
        }
    }

    #[test]
    fn escs_other_than_the_first_lag_the_profile_and_carry_their_own_load() {
        assert_eq!(spread(42, 0), (0.0, 1.0));
        let all: Vec<(f64, f64)> = (1..16).map(|i| spread(42, i)).collect();
        assert_eq!(all, (1..16).map(|i| spread(42, i)).collect::<Vec<_>>());
        for &(lag, load) in &all {
            assert!((0.0..MAX_LAG_S).contains(&lag), "{lag}");
            assert!(
                (1.0 - LOAD_SPREAD..1.0 + LOAD_SPREAD).contains(&load),
                "{load}"
            );
        }
        // Not in lockstep: the lags differ, and so do the loads.
        let lags: Vec<u64> = all.iter().map(|p| (p.0 * 1e6) as u64).collect();
        assert!(lags.windows(2).all(|w| w[0] != w[1]), "{lags:?}");
        assert_ne!(spread(42, 1), spread(43, 1));

        // An ESC lagging by a second starts its motor a second later, and a heavier load draws
        // more current at the same throttle.
        let steps = || Profile::Points(vec![(0.0, 0.0), (1.0, 0.0), (1.0, 60.0), (9.0, 60.0)]);
        let first_spin = |lag_s: f64, load: f64| {
            let mut s = setup(steps(), LinkRates::default());
            (s.lag_s, s.load) = (lag_s, load);
            let mut esc = VirtualEsc::new(s);
            let mut spin = None;
            let mut amps = 0.0;
            for _ in 0..400 {
                let burst = esc.next_burst();
                if let Some(f) = burst.intact_frame() {
                    if spin.is_none() && f.erpm_raw > 0 {
                        spin = Some(burst.t_ns as f64 * 1e-9);
                    }
                    if burst.t_ns > 6_000_000_000 {
                        amps = f64::from(f.current_raw) / 64.0;
                        break;
                    }
                }
            }
            (spin.unwrap(), amps)
        };
        let (t0, a0) = first_spin(0.0, 1.0);
        let (t1, _) = first_spin(1.0, 1.0);
        assert!((t1 - t0 - 1.0).abs() < 0.1, "{t0} {t1}");
        let (_, heavy) = first_spin(0.0, 1.15);
        assert!(heavy > a0 * 1.08, "{a0} A, heavier {heavy} A");
    }

    /// Idle for 2 s, then 40 % for 2 s, then idle.
    fn idle_run_idle() -> Profile {
        Profile::Points(vec![
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 40.0),
            (4.0, 40.0),
            (4.0, 0.0),
        ])
    }

    fn bursts(esc: &mut VirtualEsc, until_s: f64) -> Vec<Burst> {
        let mut out = Vec::new();
        loop {
            let b = esc.next_burst();
            if seconds(b.t_ns) >= until_s {
                return out;
            }
            out.push(b);
        }
    }

    #[test]
    fn frame_timing_and_packet_wrap() {
        let mut esc = VirtualEsc::new(setup(idle_run_idle(), LinkRates::default()));
        let all = bursts(&mut esc, 8.0);
        // Bursts are in order and never overlap.
        for w in all.windows(2) {
            assert!(w[1].t_ns >= w[0].t_ns + (w[0].bytes.len() as f64 * esc.byte_ns) as u64);
        }
        let data: Vec<(u64, DataFrame)> = all
            .iter()
            .filter_map(|b| b.intact_frame().map(|f| (b.t_ns, *f)))
            .collect();
        let infos: Vec<u64> = all
            .iter()
            .filter(|b| matches!(b.what, What::Info { .. }))
            .map(|b| b.t_ns)
            .collect();
        assert_eq!(data.len() + infos.len(), all.len());
        // Packets count up by one and wrap.
        let packets: Vec<u16> = data.iter().map(|d| d.1.packet).collect();
        assert_eq!(
            &packets[..8],
            &[65530, 65531, 65532, 65533, 65534, 65535, 0, 1]
        );
        assert!(packets.windows(2).all(|w| w[1] == w[0].wrapping_add(1)));
        // First frame within the first 50 ms.
        assert!(data[0].0 < RUN_INTERVAL_NS);
        let mut idle_gaps = 0;
        let mut run_gaps = 0;
        let is_idle = |f: &DataFrame| f.erpm_raw == 0 && f.throttle_out_raw == 0;
        for w in data.windows(2) {
            let gap = w[1].0 - w[0].0;
            match (is_idle(&w[0].1), is_idle(&w[1].1)) {
                (false, false) => {
                    assert_eq!(gap, RUN_INTERVAL_NS, "at {}", w[0].0);
                    run_gaps += 1;
                }
                (_, true) => {
                    assert_eq!(gap, IDLE_INTERVAL_NS, "at {}", w[0].0);
                    idle_gaps += 1;
                }
                // Starting: the next 50 ms check, after the information frame if it is on.
                (true, false) => assert!(gap < IDLE_INTERVAL_NS, "at {}", w[0].0),
            }
        }
        assert!(idle_gaps >= 8 && run_gaps >= 40, "{idle_gaps} {run_gaps}");
        // Each idle data frame is followed 40 ms later by device information, and only those.
        let idle: Vec<u64> = data.iter().filter(|d| is_idle(&d.1)).map(|d| d.0).collect();
        assert_eq!(
            infos,
            idle.iter().map(|t| t + INFO_DELAY_NS).collect::<Vec<_>>()
        );
        // The motor ran between 2 and 4 s plus spin-down, nowhere else.
        for (t, f) in &data {
            let s = seconds(*t);
            if f.erpm_raw > 0 {
                assert!((2.0..5.0).contains(&s), "{s}");
            }
            if (2.1..4.0).contains(&s) {
                assert!(f.erpm_raw > 0, "{s}");
            }
        }
    }

    #[test]
    fn same_seed_same_bytes_other_seed_other_bytes() {
        let link = LinkRates {
            bit_error: 1e-3,
            drop: 0.05,
            cut: 0.05,
            garbage: 0.1,
        };
        let run = |seed: u64| {
            let mut s = setup(idle_run_idle(), link);
            s.seed = seed;
            s.start_packet = None;
            bursts(&mut VirtualEsc::new(s), 6.0)
        };
        assert_eq!(run(5), run(5));
        assert_ne!(run(5), run(6));
    }

    #[test]
    fn esc_units_differ() {
        let mut frames = Vec::new();
        for index in 0..3 {
            let mut s = setup(idle_run_idle(), LinkRates::default());
            s.index = index;
            s.start_packet = None;
            let mut esc = VirtualEsc::new(s);
            let all = bursts(&mut esc, 3.5);
            let last = *all.iter().rev().find_map(|b| b.intact_frame()).unwrap();
            frames.push((last, esc.info().id().to_string(), all[0].t_ns));
        }
        for i in 0..3 {
            for j in i + 1..3 {
                assert_ne!(frames[i].0.erpm_raw, frames[j].0.erpm_raw);
                assert_ne!(frames[i].0.packet, frames[j].0.packet);
                assert_ne!(frames[i].1, frames[j].1);
                assert_ne!(frames[i].2, frames[j].2);
            }
            assert_eq!(frames[i].1.len(), 8);
            assert!(frames[i].1.bytes().all(|b| b.is_ascii_digit()));
        }
    }

    /// Decodes a wire with the codec and returns its data frames.
    pub(crate) fn decode(wire: &[u8]) -> Vec<DataFrame> {
        let mut out = Vec::new();
        Decoder::new().decode_all(wire, |d| {
            if let FocFrame::Data(f) = d.frame {
                out.push(f);
            }
        });
        out
    }

    #[test]
    fn decoder_sees_exactly_the_intact_frames_under_heavy_faults() {
        for seed in 0..6 {
            let mut s = setup(
                idle_run_idle(),
                LinkRates {
                    bit_error: 2e-3,
                    drop: 0.1,
                    cut: 0.2,
                    garbage: 0.5,
                },
            );
            s.seed = seed;
            let all = bursts(&mut VirtualEsc::new(s), 6.0);
            let wire: Vec<u8> = all.iter().flat_map(|b| b.bytes.clone()).collect();
            let intact: Vec<DataFrame> = all
                .iter()
                .filter_map(|b| b.intact_frame())
                .copied()
                .collect();
            let count = |f: fn(&What) -> bool| all.iter().filter(|b| f(&b.what)).count();
            assert!(
                count(|w| matches!(
                    w,
                    What::Data {
                        fate: Fate::Cut,
                        ..
                    }
                )) > 3
            );
            assert!(
                count(|w| matches!(
                    w,
                    What::Data {
                        fate: Fate::Dropped,
                        ..
                    }
                )) > 1
            );
            assert!(
                count(|w| matches!(
                    w,
                    What::Data {
                        fate: Fate::Corrupted,
                        ..
                    }
                )) > 3
            );
            assert!(count(|w| matches!(w, What::Garbage)) > 15);
            assert!(intact.len() > 15);
            assert_eq!(decode(&wire), intact, "seed {seed}");
        }
    }

    #[test]
    fn injected_faults_and_signal_loss() {
        let mut s = setup(
            Profile::Points(vec![(0.0, 0.0), (1.0, 0.0), (1.0, 50.0)]),
            LinkRates::default(),
        );
        s.faults = FaultSchedule::for_esc(
            &[
                "throttle_signal_lost@2-3".parse().unwrap(),
                "0:opamp_phase_a@2.5".parse().unwrap(),
                "1:mos_short@0".parse().unwrap(),
            ],
            0,
        );
        let all = bursts(&mut VirtualEsc::new(s), 5.0);
        for b in &all {
            let Some(f) = b.intact_frame() else { continue };
            let t = seconds(b.t_ns);
            assert_eq!(
                f.status.contains(Fault::ThrottleSignalLost),
                (2.0..3.0).contains(&t)
            );
            assert_eq!(f.status.contains(Fault::OpampPhaseA), t >= 2.5);
            assert!(!f.status.contains(Fault::MosShort));
            if (2.0..3.0).contains(&t) {
                assert_eq!(f.throttle_in_raw, 0);
            }
            if (2.9..3.0).contains(&t) {
                assert_eq!(f.erpm_raw, 0, "stopped without a signal at {t}");
            }
            if t > 4.0 {
                assert!(f.erpm_raw > 0);
                assert_eq!(f.status, Status::OK.with(Fault::OpampPhaseA));
            }
        }
    }

    /// The bursts of 8 s of `idle_run_idle` on ESC 0 speaking `protocol` at its baud rate,
    /// with the times of its data frames.
    pub(crate) fn other_run(protocol: Protocol, faults: &[&str]) -> (Vec<Burst>, Vec<(f64, Data)>) {
        let mut s = setup(idle_run_idle(), LinkRates::default());
        s.protocol = protocol;
        s.baud = protocol.baud_rate();
        s.start_packet = None;
        let specs: Vec<crate::faults::FaultSpec> =
            faults.iter().map(|f| f.parse().unwrap()).collect();
        s.faults = FaultSchedule::for_esc(&specs, 0);
        let mut esc = VirtualEsc::new(s);
        let all = bursts(&mut esc, 8.0);
        for w in all.windows(2) {
            assert!(w[1].t_ns >= w[0].t_ns + (w[0].bytes.len() as f64 * esc.byte_ns) as u64);
        }
        let data = all
            .iter()
            .filter_map(|b| b.intact_data().map(|d| (seconds(b.t_ns), d)))
            .collect();
        (all, data)
    }

    /// Gaps between successive data frames, ms, with whether the later one is running.
    pub(crate) fn gaps(
        data: &[(f64, Data)],
        running: impl Fn(&Data) -> bool,
    ) -> Vec<(f64, bool, f64)> {
        data.windows(2)
            .map(|w| ((w[1].0 - w[0].0) * 1e3, running(&w[1].1), w[1].0))
            .collect()
    }
}
