//! What the summary gathers of each ESC's frames as they are decoded: raw integers (ranges in
//! lanes, histograms of temperature codes, fault counts, episodes, times, raw energy), the
//! per-frame cost of `hwfoc summary`.

use hwfoc::foc::DataFrame;
use hwfoc::format::FormatDescription;
use hwfoc::telemetry::{AnyFrame, Conversion, Data, Info, Telemetry};
use hwfoc::units::ADC_NO_VALUE;
use hwfoc::{Protocol, Quantity, Settings, Status, Temperature};

use super::MAX_EPISODES;
use crate::clock::Step;
use crate::energy::{Energy, nominal_period_s};
use crate::episode::{Episode, Mark};

/// Min, max and sum of one raw integer field.
#[derive(Debug, Clone, Copy)]
pub(super) struct Range {
    pub(super) min: i32,
    pub(super) max: i32,
    pub(super) sum: i64,
}

/// The raw integers with a [`Range`], in lanes: eight at once, so that a frame's six minima,
/// maxima and sums are a few vector instructions (the summary's per-frame cost).
#[derive(Debug, Clone, Copy)]
pub(super) struct Ranges {
    pub(super) min: [i32; LANES],
    pub(super) max: [i32; LANES],
    pub(super) sum: [i64; LANES],
    /// Data frames that did not carry the lane's quantity (their protocol lacks it).
    pub(super) missing: [u64; LANES],
}

/// Lanes of [`Ranges`]: six quantities, and two unused (a seventh, the raw power, made `summary`
/// of a large file 40 % slower: it is summed apart, see [`Accumulator::count`]).
pub(super) const LANES: usize = 8;

/// The quantity of each lane. RPM is eRPM's lane, converted otherwise.
pub(super) const LANE_QUANTITIES: [Quantity; 6] = [
    Quantity::ThrottleIn,
    Quantity::ThrottleOut,
    Quantity::Erpm,
    Quantity::Voltage,
    Quantity::Current,
    Quantity::PhaseCurrent,
];
/// The lane of each quantity of [`LANE_QUANTITIES`].
pub(super) const ERPM: usize = 2;
pub(super) const CURRENT: usize = 4;

/// The lane of `quantity`, if it has one.
pub(super) const fn lane(quantity: Quantity) -> Option<usize> {
    match quantity {
        Quantity::Rpm => Some(ERPM),
        q => {
            let mut i = 0;
            while i < LANE_QUANTITIES.len() {
                if LANE_QUANTITIES[i] as u8 == q as u8 {
                    return Some(i);
                }
                i += 1;
            }
            None
        }
    }
}

impl Default for Ranges {
    fn default() -> Self {
        Ranges {
            min: [i32::MAX; LANES],
            max: [i32::MIN; LANES],
            sum: [0; LANES],
            missing: [0; LANES],
        }
    }
}

impl Ranges {
    /// Adds a frame's raw integers. A frame that carries every lane's quantity (for a protocol
    /// that carries them all, the compiler knows it) is added as one array, a few vector
    /// instructions; any other goes through [`Ranges::add_some`].
    #[inline(always)]
    pub(super) fn add(&mut self, f: &impl Telemetry) {
        let raw = |lane: usize| f.raw(LANE_QUANTITIES[lane]);
        let (Some(a), Some(b), Some(c), Some(d), Some(e), Some(g)) =
            (raw(0), raw(1), raw(2), raw(3), raw(4), raw(5))
        else {
            return self.add_some(f);
        };
        let mut v = [0i32; LANES];
        (v[0], v[1], v[2], v[3], v[4], v[5]) = (a, b, c, d, e, g);
        self.min = std::array::from_fn(|i| self.min[i].min(v[i]));
        self.max = std::array::from_fn(|i| self.max[i].max(v[i]));
        self.sum = std::array::from_fn(|i| self.sum[i] + i64::from(v[i]));
    }

    /// Adds the quantities a frame carries; one it does not carry leaves its lane's minimum,
    /// maximum and sum as they are and is counted as missing.
    #[cold]
    fn add_some(&mut self, f: &impl Telemetry) {
        for (lane, &quantity) in LANE_QUANTITIES.iter().enumerate() {
            match f.raw(quantity) {
                Some(raw) => {
                    self.min[lane] = self.min[lane].min(raw);
                    self.max[lane] = self.max[lane].max(raw);
                    self.sum[lane] += i64::from(raw);
                }
                None => self.missing[lane] += 1,
            }
        }
    }

    /// Adds the ranges of the frames that came after these.
    fn join(&mut self, later: &Ranges) {
        for lane in 0..LANES {
            self.min[lane] = self.min[lane].min(later.min[lane]);
            self.max[lane] = self.max[lane].max(later.max[lane]);
            self.sum[lane] += later.sum[lane];
            self.missing[lane] += later.missing[lane];
        }
    }

    /// The range of the quantity in `lane`, and the number of frames that carried it among
    /// `frames`.
    pub(super) fn get(&self, lane: usize, frames: u64) -> (Range, u64) {
        let range = Range {
            min: self.min[lane],
            max: self.max[lane],
            sum: self.sum[lane],
        };
        (range, frames - self.missing[lane])
    }
}

impl Range {
    /// Min, max and mean after applying a monotonic increasing conversion.
    pub(super) fn convert(&self, n: u64, f: impl Fn(f64) -> f64) -> Option<[f64; 3]> {
        (n > 0).then(|| {
            [
                f(f64::from(self.min)),
                f(f64::from(self.max)),
                f(self.sum as f64 / n as f64),
            ]
        })
    }
}

/// The count, ranges and power of an ESC's data frames: what every data frame adds, apart from
/// the rest of the [`Accumulator`] so that a run of frames is added in registers
/// ([`Accumulator::add_clean_run`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Tally {
    pub(super) frames: u64,
    pub(super) ranges: Ranges,
    /// The raw voltage and current of the last data frame that carried both.
    pub(super) last: Option<(i32, i32)>,
    /// Sum and largest of the raw power (voltage times current: for HW-FOC at most 65535 x
    /// 32768 in magnitude, within an `i32`) of every data frame.
    pub(super) power_sum: i64,
    pub(super) power_max: i32,
}

impl Default for Tally {
    fn default() -> Self {
        Tally {
            frames: 0,
            ranges: Ranges::default(),
            last: None,
            power_sum: 0,
            power_max: i32::MIN,
        }
    }
}

impl Tally {
    /// Adds a data frame: its count and ranges, and its power when it carries voltage and
    /// current (whether it does).
    #[inline(always)]
    fn add(&mut self, f: &Data) -> bool {
        self.ranges.add(f);
        self.count(f)
    }

    /// Adds the tally of the frames that came after these.
    fn join(&mut self, later: &Tally) {
        self.frames += later.frames;
        self.ranges.join(&later.ranges);
        self.last = later.last.or(self.last);
        self.power_sum += later.power_sum;
        self.power_max = self.power_max.max(later.power_max);
    }

    /// Adds a run of untimed data frames: what [`Tally::add`] adds for each, in two passes over
    /// the run (in the L1 cache), each of whose running values are locals, kept in registers and
    /// stored once (a running value in memory is stored and loaded back every frame).
    #[inline(always)]
    fn add_run(&mut self, run: &[DataFrame]) {
        let powered = |f: &DataFrame| Some((f.raw(Quantity::Voltage)?, f.raw(Quantity::Current)?));
        let (mut power_sum, mut power_max) = (self.power_sum, self.power_max);
        for (volts, amps) in run.iter().filter_map(powered) {
            let power = volts * amps;
            power_sum += i64::from(power);
            // A branch rarely taken, not a chain of conditional moves from frame to frame.
            if power > power_max {
                power_max = power;
            }
        }
        (self.power_sum, self.power_max) = (power_sum, power_max);
        if let Some(last) = run.iter().rev().find_map(powered) {
            self.last = Some(last);
        }
        let mut ranges = self.ranges;
        for f in run {
            ranges.add(f);
        }
        self.ranges = ranges;
        self.frames += run.len() as u64;
    }

    /// Adds a data frame but for its ranges: its count, and its power when it carries voltage
    /// and current (whether it does).
    #[inline(always)]
    fn count(&mut self, f: &Data) -> bool {
        self.frames += 1;
        let (Some(volts), Some(amps)) = (f.raw(Quantity::Voltage), f.raw(Quantity::Current)) else {
            return false;
        };
        self.last = Some((volts, amps));
        let power = volts * amps;
        self.power_sum += i64::from(power);
        // A branch rarely taken, not a chain of conditional moves from frame to frame.
        if power > self.power_max {
            self.power_max = power;
        }
        true
    }
}

/// Min, max and sum of one quantity's converted values.
#[derive(Debug, Clone, Copy)]
pub(super) struct ValueRange {
    pub(super) min: f64,
    pub(super) max: f64,
    pub(super) sum: f64,
    pub(super) n: u64,
}

impl Default for ValueRange {
    fn default() -> Self {
        ValueRange {
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            sum: 0.0,
            n: 0,
        }
    }
}

impl ValueRange {
    #[inline]
    fn add(&mut self, v: f64) {
        self.min = self.min.min(v);
        self.max = self.max.max(v);
        self.sum += v;
        self.n += 1;
    }

    fn join(&mut self, later: &ValueRange) {
        self.min = self.min.min(later.min);
        self.max = self.max.max(later.max);
        self.sum += later.sum;
        self.n += later.n;
    }

    /// Min, max and mean, if any value was added.
    pub(super) fn stats(&self) -> Option<[f64; 3]> {
        (self.n > 0).then(|| [self.min, self.max, self.sum / self.n as f64])
    }
}

/// What the summary keeps of the frames of a protocol whose conversions are not one linear
/// conversion per ESC for the whole stream (V4: its constants change when an info frame is
/// adopted, its temperatures and current are not linear; V3: eRPM from a period; HW5: the
/// quantities HW-FOC has no lane or histogram for): every quantity's converted values, and the
/// power in watts. Such ESCs send at most about 50 frames a second, so converting each frame
/// costs nothing that matters, and the means are those of the values shown.
#[derive(Debug, Clone, Default)]
pub(super) struct Values {
    pub(super) ranges: [ValueRange; Quantity::ALL.len()],
    /// Frames with both voltage and current values: their count, the sums of current and
    /// power, the largest power and the last values.
    pub(super) powered: u64,
    pub(super) current_sum: f64,
    pub(super) power_sum: f64,
    pub(super) power_max: f64,
    pub(super) last: Option<(f64, f64)>,
    /// Charge and energy over receive times, in amperes and volts.
    pub(super) energy: Energy,
    /// Frames lost, judged from the times of a format without packet counter (HW5).
    pub(super) loss: TimedLoss,
}

/// Frames of a format without packet counter (HW5) lost, judged from their receive times: a
/// step between two frames longer than one and a half of the nominal period counts the frames
/// that would have come in it (the period of a running ESC, 20 ms, between two frames of a
/// turning motor; else the idle one, 400 ms, so that a change of rate is never a loss). A step
/// over a second (the ESC may have been off) is not judged, only counted.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct TimedLoss {
    /// The last timed frame's time and whether its motor turned.
    last: Option<(f64, bool)>,
    /// Frames judged lost.
    pub(super) lost: u64,
    /// Steps over a second, not judged.
    pub(super) unjudged: u64,
    /// Steps judged.
    pub(super) judged: u64,
}

impl TimedLoss {
    /// The frame of a format described by `format` received at `t`, whose motor turned or
    /// not: judged against the format's frame periods, running and idle (a format without
    /// one, whose frames are not periodic, is not judged).
    fn add(&mut self, format: &FormatDescription, t: f64, turning: bool) {
        let Some(running) = format.frame_period else {
            return;
        };
        if let Some((last, was_turning)) = self.last {
            let dt = t - last;
            if dt > crate::clock::MAX_STEP_S {
                self.unjudged += 1;
            } else if dt > 0.0 {
                let period = if turning && was_turning {
                    running
                } else {
                    format.idle_frame_period.unwrap_or(running)
                }
                .as_secs_f64();
                if dt > 1.5 * period {
                    self.lost += (dt / period).round() as u64 - 1;
                }
                self.judged += 1;
            }
        }
        if t >= self.last.map_or(f64::MIN, |(last, _)| last) {
            self.last = Some((t, turning));
        }
    }
}

impl Values {
    /// Adds a data frame's values under `settings`; the voltage and current it carried.
    fn add(&mut self, f: &Data, settings: &Settings) -> Option<(f64, f64)> {
        for (i, &q) in Quantity::ALL.iter().enumerate() {
            if let Some(v) = f.value(q, settings) {
                self.ranges[i].add(f64::from(v));
            }
        }
        let volts = f64::from(f.value(Quantity::Voltage, settings)?);
        let amps = f64::from(f.value(Quantity::Current, settings)?);
        let power = volts * amps;
        self.powered += 1;
        self.current_sum += amps;
        self.power_sum += power;
        self.power_max = if self.powered == 1 {
            power
        } else {
            self.power_max.max(power)
        };
        self.last = Some((volts, amps));
        Some((volts, amps))
    }

    fn join(&mut self, later: &Values) {
        for (r, l) in self.ranges.iter_mut().zip(&later.ranges) {
            r.join(l);
        }
        if later.powered > 0 {
            self.power_max = if self.powered == 0 {
                later.power_max
            } else {
                self.power_max.max(later.power_max)
            };
            self.last = later.last;
        }
        // (Halves are joined only without times: nothing was judged from them.)
        self.powered += later.powered;
        self.current_sum += later.current_sum;
        self.power_sum += later.power_sum;
    }

    /// The range of `quantity`'s values.
    pub(super) fn range(&self, quantity: Quantity) -> &ValueRange {
        let i = Quantity::ALL.iter().position(|&q| q == quantity);
        &self.ranges[i.unwrap_or(0)]
    }

    /// Charge, energy and power in amperes and volts: over receive times, or for frames
    /// without times from the sums (each frame `period_s` apart).
    fn energy(&self, timed: bool, period_s: f64) -> Option<Energy> {
        if self.powered == 0 {
            return None;
        }
        if timed {
            return Some(self.energy);
        }
        Some(Energy::untimed(
            self.powered,
            self.current_sum,
            self.power_sum,
            self.last.unwrap_or_default(),
            Some(self.power_max),
            period_s,
        ))
    }
}

/// `protocol`'s place in [`Protocol::ALL`]: its discriminant (a search per frame cost the
/// summary instructions).
#[inline(always)]
const fn protocol_index(protocol: Protocol) -> usize {
    protocol as usize
}

// [`Protocol::ALL`] lists the protocols in their declaration order.
const _: () = {
    let mut i = 0;
    while i < Protocol::ALL.len() {
        assert!(Protocol::ALL[i] as usize == i);
        i += 1;
    }
};

/// Whether the summary keeps the raw integers of `protocol`'s frames (HW-FOC, DataLink: one
/// linear conversion per ESC, the fast path) rather than their values ([`Values`]).
#[inline(always)]
pub(super) const fn keeps_raw(protocol: Protocol) -> bool {
    matches!(protocol, Protocol::HwFoc | Protocol::DataLink)
}

/// Whether a data frame carries no fault: what [`Accumulator::add_clean`] and
/// [`Accumulator::add_clean_run`] take (a protocol without a status word has none).
#[inline(always)]
pub(super) fn is_clean(f: &Data) -> bool {
    f.fault_word().is_none_or(Status::is_ok)
}

/// The code of temperature `quantity` in a data frame: its raw value when that is a table's
/// code (0..=255), `None` when it is not or the frame does not carry it.
#[inline(always)]
fn code(f: &impl Telemetry, quantity: Quantity) -> Option<u8> {
    f.raw(quantity).and_then(|raw| u8::try_from(raw).ok())
}

/// A run of frames with one temperature code, counted in the histogram when the code changes.
#[derive(Default)]
struct CodeRun {
    code: u8,
    frames: u64,
}

impl CodeRun {
    /// A frame's code (`None`: not a code, counted in `uncoded` at once).
    #[inline(always)]
    fn add(&mut self, code: Option<u8>, codes: &mut [u64; 256], uncoded: &mut u64) {
        match code {
            Some(code) if code == self.code => self.frames += 1,
            Some(code) => {
                codes[usize::from(self.code)] += self.frames;
                *self = CodeRun { code, frames: 1 };
            }
            None => *uncoded += 1,
        }
    }

    /// Counts the temperature codes `codes` of frames, a run of one code at a time.
    #[inline(always)]
    fn count(frames: impl Iterator<Item = Option<u8>>, codes: &mut [u64; 256], uncoded: &mut u64) {
        let mut run = CodeRun::default();
        for code in frames {
            run.add(code, codes, uncoded);
        }
        run.end(codes);
    }

    /// Counts the run in the histogram.
    #[inline(always)]
    fn end(self, codes: &mut [u64; 256]) {
        codes[usize::from(self.code)] += self.frames;
    }
}

/// Everything the summary needs from the frames of one ESC, gathered as they are decoded.
#[derive(Debug)]
pub(super) struct Accumulator {
    /// The count, ranges and power of the data frames.
    pub(super) tally: Tally,
    /// A data frame of the ESC (its first), whose protocol's conversions the report uses.
    pub(super) sample: Option<Data>,
    /// Data frames by protocol (as [`Protocol::ALL`]): see [`Accumulator::formats`].
    pub(super) by_protocol: [u64; Protocol::ALL.len()],
    /// Whether the next data frame may take [`Accumulator::add_clean`]: the ESC's sample is
    /// known and no fault episode is open.
    pub(super) fast: bool,
    /// Histograms of each temperature's raw codes (a table's codes, 0..=255), and the frames
    /// whose temperature was not such a code or was not carried.
    pub(super) mos_codes: [u64; 256],
    pub(super) cap_codes: [u64; 256],
    pub(super) uncoded: [u64; 2],
    pub(super) fault_frames: [u64; 16],
    pub(super) first_t: Option<f64>,
    pub(super) last_t: Option<f64>,
    /// The last timed data frame's packet number, where its protocol sends one.
    pub(super) last_packet: Option<u32>,
    /// Seconds that passed between the timed data frames: the sum of the steps that are not
    /// clock discontinuities.
    pub(super) elapsed: f64,
    /// Clock discontinuities between timed data frames: steps back, jumps forward.
    pub(super) steps_back: u64,
    pub(super) jumps: u64,
    /// Charge and energy of timed frames in raw units (voltage and current as sent); frames
    /// without times are integrated from the lanes' sums at the end (see [`Self::energy`]).
    pub(super) energy: Energy,
    pub(super) infos: Vec<(Info, u64)>,
    /// The values of frames of a protocol [`keeps_raw`] is false for.
    pub(super) values: Option<Box<Values>>,
    pub(super) episode: Option<Episode>,
    pub(super) episodes: Vec<Episode>,
    pub(super) episode_count: u64,
}

impl Default for Accumulator {
    fn default() -> Self {
        Accumulator {
            tally: Tally::default(),
            sample: None,
            by_protocol: [0; Protocol::ALL.len()],
            fast: false,
            mos_codes: [0; 256],
            cap_codes: [0; 256],
            uncoded: [0; 2],
            fault_frames: [0; 16],
            first_t: None,
            last_t: None,
            last_packet: None,
            elapsed: 0.0,
            steps_back: 0,
            jumps: 0,
            energy: Energy::new(),
            infos: Vec::new(),
            values: None,
            episode: None,
            episodes: Vec::new(),
            episode_count: 0,
        }
    }
}

impl Accumulator {
    #[inline]
    pub(super) fn add(&mut self, t: Option<f64>, frame: &AnyFrame, settings: &Settings) {
        match frame {
            AnyFrame::Data(f) if !keeps_raw(f.protocol()) => self.add_values(t, f, settings),
            AnyFrame::Data(f) => self.add_data(t, f),
            AnyFrame::Info(info) => match self.infos.iter_mut().find(|(i, _)| i == info) {
                Some((_, n)) => *n += 1,
                None => self.infos.push((*info, 1)),
            },
        }
    }

    /// A data frame without faults, outside a fault episode, of an ESC whose sample is known:
    /// what [`Self::add_data`] does with it (no fault to count, no episode started or ended).
    #[inline(always)]
    pub(super) fn add_clean(&mut self, t: Option<f64>, f: &Data) {
        debug_assert!(self.fast && self.sample.is_some() && self.episode.is_none());
        self.by_protocol[protocol_index(f.protocol())] += 1;
        self.count(t, f);
    }

    /// What every data frame adds: its count, ranges, temperature codes and time.
    #[inline(always)]
    pub(super) fn count(&mut self, t: Option<f64>, f: &Data) {
        let powered = self.tally.add(f);
        self.count_codes(
            std::iter::once(code(f, Quantity::MosTemp)),
            std::iter::once(code(f, Quantity::CapTemp)),
        );
        if !powered {
            return self.untimed_power(t, f);
        }
        if let Some(t) = t {
            self.timed(t, f);
        }
    }

    /// Adds the HW-FOC data frames without times at the start of `frames` that [`Self::add_clean`]
    /// would take (no fault), up to the first that it would not: how many. Their tally is added
    /// in passes over the run ([`Tally::add_run`]) and their temperature codes counted a run of
    /// one code at a time (adding one to the same count frame after frame waits for the
    /// previous store each time).
    #[inline(always)]
    pub(super) fn add_clean_run(&mut self, frames: &[DataFrame]) -> usize {
        debug_assert!(self.fast && self.sample.is_some() && self.episode.is_none());
        let n = frames
            .iter()
            .position(|f| !f.status.is_ok())
            .unwrap_or(frames.len());
        let run = &frames[..n];
        self.by_protocol[protocol_index(Protocol::HwFoc)] += n as u64;
        self.tally.add_run(run);
        let codes = |q| run.iter().map(move |f| code(f, q));
        self.count_codes(codes(Quantity::MosTemp), codes(Quantity::CapTemp));
        n
    }

    /// Counts the MOSFET's and the capacitor's temperature codes of frames, each a run of one
    /// code at a time.
    #[inline(always)]
    fn count_codes(
        &mut self,
        mos: impl Iterator<Item = Option<u8>>,
        cap: impl Iterator<Item = Option<u8>>,
    ) {
        CodeRun::count(mos, &mut self.mos_codes, &mut self.uncoded[0]);
        CodeRun::count(cap, &mut self.cap_codes, &mut self.uncoded[1]);
    }

    /// What a frame with a time adds: out of the decoder's loop, which stays as small as it
    /// was for inputs without times (the summary of a large raw file).
    #[inline(never)]
    pub(super) fn timed(&mut self, t: f64, f: &Data) {
        let (volts, amps) = self.tally.last.unwrap_or_default();
        self.energy.add(Some(t), f64::from(volts), f64::from(amps));
        self.clock(t, f);
    }

    /// The time of a data frame: the duration and the clock's discontinuities.
    #[inline]
    pub(super) fn clock(&mut self, t: f64, f: &Data) {
        let packet = f.packet();
        if let Some(last) = self.last_t {
            let counted = packet
                .zip(self.last_packet)
                .and_then(|(p, l)| f.protocol().packets_between(l, p));
            match Step::between(last, t, counted) {
                Step::Back => self.steps_back += 1,
                Step::Jump => self.jumps += 1,
                step => self.elapsed += step.elapsed().unwrap_or(0.0),
            }
        }
        self.first_t.get_or_insert(t);
        self.last_t = Some(t);
        self.last_packet = packet;
    }

    /// The rest of a data frame that does not carry both voltage and current: its time, and no
    /// power (a protocol without them has no energy to integrate).
    #[cold]
    pub(super) fn untimed_power(&mut self, t: Option<f64>, f: &Data) {
        if let Some(t) = t {
            self.clock(t, f);
        }
    }

    /// A data frame of a protocol whose values are kept ([`Values`]): its values, and what
    /// [`Self::add_data`] adds but its raw energy.
    #[cold]
    #[inline(never)]
    fn add_values(&mut self, t: Option<f64>, f: &Data, settings: &Settings) {
        let values = self.values.get_or_insert_with(Default::default);
        let powered = values.add(f, settings);
        if let (Some(t), None) = (t, f.packet()) {
            let turning = [Quantity::Erpm, Quantity::ThrottleIn]
                .into_iter()
                .any(|q| f.raw(q).is_some_and(|raw| raw > 0));
            values.loss.add(f.protocol().description(), t, turning);
        }
        if let (Some(t), Some((volts, amps))) = (t, powered) {
            values.energy.add(Some(t), volts, amps);
        }
        self.add_data(t, f);
        // Never the fast path, which keeps raw integers only.
        self.fast = false;
    }

    #[inline]
    pub(super) fn add_data(&mut self, t: Option<f64>, f: &Data) {
        self.sample.get_or_insert(*f);
        self.by_protocol[protocol_index(f.protocol())] += 1;
        let index = self.tally.frames;
        self.count(t, f);
        let status = f.fault_word().unwrap_or_default();
        if !status.is_ok() {
            for fault in status.faults() {
                self.fault_frames[usize::from(fault.bit())] += 1;
            }
        }
        let mark = Mark {
            t,
            frame: index,
            packet: f.packet(),
        };
        if let Some(ended) = Episode::track(&mut self.episode, mark, status) {
            self.episode_count += 1;
            if self.episodes.len() < MAX_EPISODES {
                self.episodes.push(ended);
            }
        }
        self.fast = self.episode.is_none();
    }
}

impl Accumulator {
    /// The protocols of the ESC's data frames with their counts, in the order of
    /// [`Protocol::ALL`] (a stream that changed format: more than one).
    pub(super) fn formats(&self) -> Vec<(Protocol, u64)> {
        Protocol::ALL
            .into_iter()
            .zip(self.by_protocol)
            .filter(|&(_, n)| n > 0)
            .collect()
    }

    /// Takes what `later` gathered of the frames of the ESC that came right after every frame
    /// this one took, both without receive times (the two halves of a raw file read at once):
    /// afterwards this is what one accumulator given every frame in order would hold. Counts,
    /// ranges and histograms add up; device-information frames keep the order they were first
    /// seen in; `later`'s frame indices follow this one's; a fault episode open at the end of
    /// this part goes on into `later`'s first frame when that one has a fault too, and ends
    /// there otherwise.
    pub(super) fn join(&mut self, later: Accumulator) {
        debug_assert!(self.first_t.is_none() && later.first_t.is_none());
        for (info, n) in later.infos {
            match self.infos.iter_mut().find(|(i, _)| *i == info) {
                Some((_, m)) => *m += n,
                None => self.infos.push((info, n)),
            }
        }
        if later.tally.frames == 0 {
            return;
        }
        let base = self.tally.frames;
        self.sample = self.sample.or(later.sample);
        for (n, m) in self.by_protocol.iter_mut().zip(later.by_protocol) {
            *n += m;
        }
        match (&mut self.values, later.values) {
            (Some(v), Some(l)) => v.join(&l),
            (v @ None, l) => *v = l,
            (Some(_), None) => {}
        }
        self.tally.join(&later.tally);
        for (codes, more) in [
            (&mut self.mos_codes, &later.mos_codes),
            (&mut self.cap_codes, &later.cap_codes),
        ] {
            codes.iter_mut().zip(more).for_each(|(n, m)| *n += m);
        }
        self.uncoded[0] += later.uncoded[0];
        self.uncoded[1] += later.uncoded[1];
        for (n, m) in self.fault_frames.iter_mut().zip(later.fault_frames) {
            *n += m;
        }
        let rebase = |mut e: Episode| {
            e.first.frame += base;
            e.last.frame += base;
            e
        };
        let mut ended: Vec<Episode> = later.episodes.into_iter().map(rebase).collect();
        let mut open = later.episode.map(rebase);
        if let Some(before) = self.episode.take() {
            // `later`'s first episode, if its first frame has a fault: the one open here goes on.
            let first = match ended.first_mut() {
                Some(e) => Some(e),
                None => open.as_mut(),
            }
            .filter(|e| e.first.frame == base);
            match first {
                Some(e) => {
                    e.first = before.first;
                    e.frames += before.frames;
                    e.bits = Status(e.bits.0 | before.bits.0);
                }
                None => {
                    self.episode_count += 1;
                    if self.episodes.len() < MAX_EPISODES {
                        self.episodes.push(before);
                    }
                }
            }
        }
        let room = MAX_EPISODES.saturating_sub(self.episodes.len());
        ended.truncate(room);
        self.episodes.append(&mut ended);
        self.episode_count += later.episode_count;
        self.episode = open;
        self.fast = self.sample.is_some() && self.episode.is_none() && self.values.is_none();
    }

    /// Charge, energy and power in raw units: integrated frame by frame over receive times,
    /// or for a stream without times (whose frames all lack them) from the lanes' sums.
    pub(super) fn energy(&self) -> Energy {
        // Frames without times are their protocol's frame period apart.
        let period_s = nominal_period_s(self.sample.as_ref().map(Data::protocol));
        if let Some(values) = &self.values {
            return values
                .energy(self.first_t.is_some(), period_s)
                .unwrap_or_else(|| Energy::at_period(period_s));
        }
        if self.first_t.is_some() {
            return self.energy;
        }
        let Tally {
            frames,
            ranges,
            last,
            power_sum,
            power_max,
        } = self.tally;
        let (v, i) = last.unwrap_or_default();
        Energy::untimed(
            frames,
            ranges.sum[CURRENT] as f64,
            power_sum as f64,
            (f64::from(v), f64::from(i)),
            (frames > 0).then(|| f64::from(power_max)),
            period_s,
        )
    }
}

/// Temperature statistics from a histogram of ADC codes.
#[derive(Debug, Default, PartialEq)]
pub(super) struct TempStats {
    pub(super) range: Option<[f64; 3]>,
    pub(super) below: u64,
    pub(super) above: u64,
}

/// Temperature statistics from a histogram of codes read through `conversion`: a table's, whose
/// codes outside it are counted below or above it, or a linear one.
pub(super) fn temp_stats(codes: &[u64; 256], conversion: Conversion) -> TempStats {
    let mut s = TempStats::default();
    let (mut min, mut max, mut sum, mut n) = (f64::MAX, f64::MIN, 0.0, 0u64);
    for (code, &count) in codes.iter().enumerate() {
        if count == 0 {
            continue;
        }
        let temperature = match conversion {
            // No value (the code of no sensor, what a hub or the bridge sends for a temperature
            // not carried): no reading, neither below nor above the table.
            Conversion::AdcTable if code == usize::from(ADC_NO_VALUE) => continue,
            Conversion::AdcTable => Temperature::from_adc(code as u8),
            other => match other.to_f32(code as i32) {
                Some(c) => Temperature::Celsius(c),
                // No value (a V4 code of 0): no reading, neither below nor above a range.
                None => continue,
            },
        };
        match temperature {
            Temperature::Celsius(c) => {
                let c = f64::from(c);
                min = min.min(c);
                max = max.max(c);
                sum += c * count as f64;
                n += count;
            }
            Temperature::BelowRange => s.below += count,
            Temperature::AboveRange => s.above += count,
        }
    }
    if n > 0 {
        s.range = Some([min, max, sum / n as f64]);
    }
    s
}
