//! The summary of a run of inputs: what they hold, ESC by ESC, and how good each link was,
//! as text for a person or as JSON (`hwfoc summary`, `--json`).
//!
//! [`Summary`] is a [`Handler`]: give it to [`Sources::run`], then ask it for the
//! [`Summary::report`].
//!
//! Statistics are gathered on the raw integers of each quantity a frame carries
//! ([`Telemetry::raw`]: min, max and sum per quantity, a histogram of each temperature's codes)
//! and converted to physical units once, at the end, through the conversion the ESC's protocol
//! gives under its settings ([`Telemetry::reading`] of a frame of the ESC): every conversion is
//! monotonic, so this is exact, and it keeps the per-frame cost to a few integer operations.
//!
//! Charge, energy and power ([`Energy`]) are integrated per ESC over its data frames' times
//! (each frame's current holding until the next), on the raw voltage and current, converted
//! once at the end; an input without times counts each frame as the nominal period, and the
//! report says so. The duration of an ESC's frames is the time that passed between them: a
//! clock that steps back or jumps forward ([`Step`]) adds nothing, and the report counts such
//! discontinuities. Times of sources with a wall clock (recordings, serial ports) are shown as
//! ISO 8601 dates in UTC; other sources' times as their seconds.
//!
//! A fault episode is a maximal run of consecutive data frames of one ESC whose status word is
//! not zero; it is reported with its first and last frame (times where the input has them,
//! frame indices and packet numbers always) and the fault bits seen during it.

use std::fmt::Write as _;

use hwfoc::telemetry::{Conversion, Data, Frame, Info, Telemetry};
use hwfoc::units::Linear;
use hwfoc::{Fault, Quantity, Settings, Status, Temperature};
use serde_json::{Value, json};

use crate::clock::Step;
use crate::energy::{Energy, NOMINAL_PERIOD_S};
pub use crate::episode::{Episode, Mark};
use crate::escape::Escaped;
use crate::fixed::Fixed;
use crate::input::InputError;
use crate::settings::{self, settings_json};
use crate::sources::{Handler, Sources};
use crate::stream::EscLink;
use crate::time::{self, Clock};
use hwfoc::datalink::LengthByte;

/// What to tell a user whose wire gave bytes but no frame.
pub static NO_FRAMES: std::sync::LazyLock<String> = std::sync::LazyLock::new(|| {
    format!(
        "no valid HW-FOC frames: check the baud rate ({}) and the wiring",
        hwfoc::foc::BAUD_RATE
    )
});

/// Why ESC `esc`'s bytes gave no frame, as every output says it: what its input looks like
/// when that is not telemetry (`text, not telemetry`, `looks like a PNG image, not telemetry`:
/// a file given by mistake), else [`NO_FRAMES`], the advice for a wire (a port, a recording,
/// a raw capture of bytes).
pub fn no_frames(sources: &Sources, esc: usize) -> String {
    sources
        .escs()
        .get(esc)
        .and_then(|e| sources.inputs().get(e.input))
        .and_then(|input| input.looks)
        .map_or_else(|| NO_FRAMES.clone(), |looks| looks.to_string())
}

/// Fault episodes kept per ESC in detail (all are counted).
const MAX_EPISODES: usize = 10_000;

/// Fault episodes listed per ESC in the text output (`--json` lists all those kept).
const TEXT_EPISODES: usize = 20;

/// How an ESC is named in messages: its input, and its stream when the input has several
/// (names from a recording [`Escaped`]).
pub fn esc_label(sources: &Sources, esc: usize) -> String {
    let e = &sources.escs()[esc];
    let input = &sources.names()[e.input];
    let single = sources
        .inputs()
        .get(e.input)
        .is_none_or(|info| info.escs.len() == 1);
    let channel = match e.hub {
        Some((_, channel)) => format!(" channel {channel}"),
        None if sources.is_hub(esc) => " channel 0".to_string(),
        None => String::new(),
    };
    let input = Escaped(input);
    if single && e.name == *input.0 && channel.is_empty() {
        input.to_string()
    } else if e.name == *input.0 {
        format!("{input}{channel} (ESC {esc})")
    } else {
        format!("{input}: {}{channel} (ESC {esc})", Escaped(&e.name))
    }
}

/// What the summary gathers from the frames: one accumulator per ESC.
#[derive(Default)]
pub struct Summary(Vec<Accumulator>);

impl Summary {
    /// Nothing gathered yet.
    pub fn new() -> Summary {
        Summary::default()
    }

    /// The report on what was gathered from `sources` (after [`Sources::run`]): each ESC's
    /// figures converted under its own settings ([`Sources::esc_settings`]).
    pub fn report<'a>(&'a self, sources: &'a Sources) -> Report<'a> {
        Report {
            sources,
            settings: sources.settings(),
            accs: &self.0,
        }
    }
}

impl Handler for Summary {
    type Error = InputError;

    /// Takes frames as decoded: statistics are kept on the raw integers (see the module
    /// documentation), converted once at the end.
    ///
    /// The usual frame, a data frame without faults outside a fault episode of a known ESC, is
    /// a few integer operations, inlined into the decoder's loop (its fields go from registers
    /// to the accumulator, not through a `Decoded` in memory); every other frame is taken out of
    /// line.
    #[inline(always)]
    fn frame(&mut self, esc: u8, t: Option<f64>, frame: &Frame, _: &Settings) {
        let esc = usize::from(esc);
        if let Frame::Data(f) = frame
            && let Some(acc) = self.0.get_mut(esc)
            && acc.fast
            && f.status().is_none_or(Status::is_ok)
        {
            acc.add_clean(t, f);
        } else {
            self.add(esc, t, frame);
        }
    }
}

impl Summary {
    /// Any frame of ESC `esc`.
    #[cold]
    #[inline(never)]
    fn add(&mut self, esc: usize, t: Option<f64>, frame: &Frame) {
        if self.0.len() <= esc {
            self.0.resize_with(esc + 1, Accumulator::default);
        }
        self.0[esc].add(t, frame);
    }
}

/// Min, max and sum of one raw integer field.
#[derive(Debug, Clone, Copy)]
struct Range {
    min: i32,
    max: i32,
    sum: i64,
}

/// The raw integers with a [`Range`], in lanes: eight at once, so that a frame's six minima,
/// maxima and sums are a few vector instructions (the summary's per-frame cost).
#[derive(Debug, Clone, Copy)]
struct Ranges {
    min: [i32; LANES],
    max: [i32; LANES],
    sum: [i64; LANES],
    /// Data frames that did not carry the lane's quantity (their protocol lacks it).
    missing: [u64; LANES],
}

/// Lanes of [`Ranges`]: six quantities, and two unused (a seventh, the raw power, made `summary`
/// of a large file 40 % slower: it is summed apart, see [`Accumulator::count`]).
const LANES: usize = 8;
/// The quantity of each lane. RPM is eRPM's lane, converted otherwise.
const LANE_QUANTITIES: [Quantity; 6] = [
    Quantity::ThrottleIn,
    Quantity::ThrottleOut,
    Quantity::Erpm,
    Quantity::Voltage,
    Quantity::Current,
    Quantity::PhaseCurrent,
];
/// The lane of each quantity of [`LANE_QUANTITIES`].
const ERPM: usize = 2;
const CURRENT: usize = 4;

/// The lane of `quantity`, if it has one.
const fn lane(quantity: Quantity) -> Option<usize> {
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
    /// Adds a frame's raw integers. A quantity the frame does not carry leaves its lane's
    /// minimum, maximum and sum as they are and is counted as missing (for a protocol that
    /// carries every lane's quantity, the compiler removes that branch).
    #[inline(always)]
    fn add(&mut self, f: &impl Telemetry) {
        let (mut low, mut high, mut add) = ([i32::MAX; LANES], [i32::MIN; LANES], [0i64; LANES]);
        let mut take = |lane: usize| match f.raw(LANE_QUANTITIES[lane]) {
            Some(raw) => (low[lane], high[lane], add[lane]) = (raw, raw, i64::from(raw)),
            None => self.missing[lane] += 1,
        };
        // Written out, not a loop: each call is then a field read.
        take(0);
        take(1);
        take(2);
        take(3);
        take(4);
        take(5);
        self.min = std::array::from_fn(|i| self.min[i].min(low[i]));
        self.max = std::array::from_fn(|i| self.max[i].max(high[i]));
        self.sum = std::array::from_fn(|i| self.sum[i] + add[i]);
    }

    /// The range of the quantity in `lane`, and the number of frames that carried it among
    /// `frames`.
    fn get(&self, lane: usize, frames: u64) -> (Range, u64) {
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
    fn convert(&self, n: u64, f: impl Fn(f64) -> f64) -> Option<[f64; 3]> {
        (n > 0).then(|| {
            [
                f(f64::from(self.min)),
                f(f64::from(self.max)),
                f(self.sum as f64 / n as f64),
            ]
        })
    }
}

/// Everything the summary needs from the frames of one ESC, gathered as they are decoded.
#[derive(Debug)]
struct Accumulator {
    frames: u64,
    /// A data frame of the ESC (its first), whose protocol's conversions the report uses.
    sample: Option<Data>,
    /// Whether the next data frame may take [`Accumulator::add_clean`]: the ESC's sample is
    /// known and no fault episode is open.
    fast: bool,
    ranges: Ranges,
    /// Histograms of each temperature's raw codes (a table's codes, 0..=255), and the frames
    /// whose temperature was not such a code or was not carried.
    mos_codes: [u64; 256],
    cap_codes: [u64; 256],
    uncoded: [u64; 2],
    fault_frames: [u64; 16],
    first_t: Option<f64>,
    last_t: Option<f64>,
    /// The last timed data frame's packet number, where its protocol sends one.
    last_packet: Option<u16>,
    /// Seconds that passed between the timed data frames: the sum of the steps that are not
    /// clock discontinuities.
    elapsed: f64,
    /// Clock discontinuities between timed data frames: steps back, jumps forward.
    steps_back: u64,
    jumps: u64,
    /// Charge and energy of timed frames in raw units (voltage and current as sent); frames
    /// without times are integrated from the lanes' sums at the end (see [`Self::energy`]).
    energy: Energy,
    /// The last data frame's raw voltage and current.
    last: (i32, i32),
    /// Sum and largest of the raw power (voltage times current: for HW-FOC at most 65535 x
    /// 32768 in magnitude, within an `i32`) of every data frame.
    power_sum: i64,
    power_max: i32,
    infos: Vec<(Info, u64)>,
    episode: Option<Episode>,
    episodes: Vec<Episode>,
    episode_count: u64,
}

impl Default for Accumulator {
    fn default() -> Self {
        Accumulator {
            frames: 0,
            sample: None,
            fast: false,
            ranges: Ranges::default(),
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
            last: (0, 0),
            power_sum: 0,
            power_max: i32::MIN,
            infos: Vec::new(),
            episode: None,
            episodes: Vec::new(),
            episode_count: 0,
        }
    }
}

impl Accumulator {
    #[inline]
    fn add(&mut self, t: Option<f64>, frame: &Frame) {
        match frame {
            Frame::Data(f) => self.add_data(t, f),
            Frame::Info(info) => match self.infos.iter_mut().find(|(i, _)| i == info) {
                Some((_, n)) => *n += 1,
                None => self.infos.push((*info, 1)),
            },
        }
    }

    /// A data frame without faults, outside a fault episode, of an ESC whose sample is known:
    /// what [`Self::add_data`] does with it (no fault to count, no episode started or ended).
    #[inline(always)]
    fn add_clean(&mut self, t: Option<f64>, f: &Data) {
        debug_assert!(self.fast && self.sample.is_some() && self.episode.is_none());
        self.count(t, f);
    }

    /// What every data frame adds: its count, ranges, temperature codes and time.
    #[inline(always)]
    fn count(&mut self, t: Option<f64>, f: &Data) {
        self.frames += 1;
        self.ranges.add(f);
        let code = |quantity: Quantity, codes: &mut [u64; 256], uncoded: &mut u64| match f
            .raw(quantity)
            .and_then(|raw| u8::try_from(raw).ok())
        {
            Some(code) => codes[usize::from(code)] += 1,
            None => *uncoded += 1,
        };
        code(Quantity::MosTemp, &mut self.mos_codes, &mut self.uncoded[0]);
        code(Quantity::CapTemp, &mut self.cap_codes, &mut self.uncoded[1]);
        let (Some(volts), Some(amps)) = (f.raw(Quantity::Voltage), f.raw(Quantity::Current)) else {
            return self.untimed_power(t, f);
        };
        self.last = (volts, amps);
        let power = volts * amps;
        self.power_sum += i64::from(power);
        // A branch rarely taken, not a chain of conditional moves from frame to frame.
        if power > self.power_max {
            self.power_max = power;
        }
        if let Some(t) = t {
            self.timed(t, f);
        }
    }

    /// What a frame with a time adds: out of the decoder's loop, which stays as small as it
    /// was for inputs without times (the summary of a large raw file).
    #[inline(never)]
    fn timed(&mut self, t: f64, f: &Data) {
        let (volts, amps) = self.last;
        self.energy.add(Some(t), f64::from(volts), f64::from(amps));
        self.clock(t, f);
    }

    /// The time of a data frame: the duration and the clock's discontinuities.
    #[inline]
    fn clock(&mut self, t: f64, f: &Data) {
        let packet = f.packet();
        if let Some(last) = self.last_t {
            let counted = packet.zip(self.last_packet).map(|(p, l)| p.wrapping_sub(l));
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
    fn untimed_power(&mut self, t: Option<f64>, f: &Data) {
        if let Some(t) = t {
            self.clock(t, f);
        }
    }

    #[inline]
    fn add_data(&mut self, t: Option<f64>, f: &Data) {
        self.sample.get_or_insert(*f);
        let index = self.frames;
        self.count(t, f);
        let status = f.status().unwrap_or_default();
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
    /// Charge, energy and power in raw units: integrated frame by frame over receive times,
    /// or for a stream without times (whose frames all lack them) from the lanes' sums.
    fn energy(&self) -> Energy {
        if self.first_t.is_some() {
            return self.energy;
        }
        let (v, i) = self.last;
        Energy::untimed(
            self.frames,
            self.ranges.sum[CURRENT] as f64,
            self.power_sum as f64,
            (f64::from(v), f64::from(i)),
            (self.frames > 0).then(|| f64::from(self.power_max)),
        )
    }
}

/// Temperature statistics from a histogram of ADC codes.
#[derive(Debug, Default, PartialEq)]
struct TempStats {
    range: Option<[f64; 3]>,
    below: u64,
    above: u64,
}

/// Temperature statistics from a histogram of codes read through `conversion`: a table's, whose
/// codes outside it are counted below or above it, or a linear one.
fn temp_stats(codes: &[u64; 256], conversion: Conversion) -> TempStats {
    let mut s = TempStats::default();
    let (mut min, mut max, mut sum, mut n) = (f64::MAX, f64::MIN, 0.0, 0u64);
    for (code, &count) in codes.iter().enumerate() {
        if count == 0 {
            continue;
        }
        let temperature = match conversion {
            Conversion::AdcTable => Temperature::from_adc(code as u8),
            Conversion::Linear(linear) => Temperature::Celsius(linear.to_f32(code as f32)),
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

/// The summary, ready to be printed: [`Report::text`] or [`Report::json`].
pub struct Report<'a> {
    sources: &'a Sources,
    /// The settings of ESCs without settings of their own.
    settings: &'a Settings,
    accs: &'a [Accumulator],
}

/// One row of the field table: name, unit, and min/max/mean if there were frames.
type FieldRow = (&'static str, &'static str, Option<[f64; 3]>);

/// One ESC's part of the report.
struct EscReport<'a> {
    index: usize,
    label: String,
    stream: &'a str,
    input: &'a str,
    stats: EscLink,
    settings: Settings,
    acc: &'a Accumulator,
    /// The episode still open at the end, closed for the report.
    episodes: Vec<Episode>,
    episode_count: u64,
    /// The clock of its input's times.
    clock: Clock,
    /// Why its bytes gave no frame, if they gave none ([`no_frames`]).
    no_frames: String,
}

impl<'a> Report<'a> {
    fn escs(&self) -> Vec<EscReport<'a>> {
        static EMPTY: std::sync::OnceLock<Accumulator> = std::sync::OnceLock::new();
        let empty = EMPTY.get_or_init(Accumulator::default);
        self.sources
            .escs()
            .iter()
            .enumerate()
            // A hub's channels that carried no ESC are not ESCs.
            .filter(|&(i, _)| !self.sources.is_hub(i) || self.sources.link(i).frames() > 0)
            .map(|(i, esc)| {
                let acc = self.accs.get(i).unwrap_or(empty);
                let mut episodes = acc.episodes.clone();
                let mut episode_count = acc.episode_count;
                if let Some(mut open) = acc.episode {
                    open.ongoing = true;
                    episode_count += 1;
                    if episodes.len() < MAX_EPISODES {
                        episodes.push(open);
                    }
                }
                let clock = self
                    .sources
                    .inputs()
                    .get(esc.input)
                    .map_or(Clock::None, |info| info.format.clock());
                EscReport {
                    clock,
                    no_frames: no_frames(self.sources, i),
                    index: i,
                    label: esc_label(self.sources, i),
                    stream: &esc.name,
                    input: &self.sources.names()[esc.input],
                    stats: self.sources.link(i),
                    settings: self.sources.esc_settings(i),
                    acc,
                    episodes,
                    episode_count,
                }
            })
            .collect()
    }

    /// The summary as text, as `hwfoc summary` prints it.
    pub fn text(&self) -> String {
        let mut o = String::new();
        // Writing to a String cannot fail; the results are ignored below for that reason.
        let escs = self.escs();
        let _ = write!(
            o,
            "settings     {}",
            settings::words(self.settings, None).join(", ")
        );
        for esc in &escs {
            let differing = settings::words(&esc.settings, Some(self.settings));
            if !differing.is_empty() {
                let _ = write!(o, "; ESC {}: {}", esc.index, differing.join(", "));
            }
        }
        o.push('\n');
        for info in self.sources.inputs() {
            let escs = match info.escs.as_slice() {
                [] => "no ESC".to_string(),
                [one] => format!("ESC {one}"),
                [first, .., last] if last - first + 1 == info.escs.len() => {
                    format!("ESCs {first} to {last}")
                }
                many => {
                    let list: Vec<String> = many.iter().map(usize::to_string).collect();
                    format!("ESCs {}", list.join(", "))
                }
            };
            let _ = writeln!(
                o,
                "input        {} ({}, {} bytes, {escs})",
                Escaped(&info.name),
                info.format,
                info.bytes
            );
            if info.flagged_bytes > 0 {
                let _ = writeln!(
                    o,
                    "             {} bytes flagged with parity or framing errors by the analyser",
                    info.flagged_bytes
                );
            }
        }
        for (esc, hub) in self.sources.hubs() {
            let _ = writeln!(
                o,
                "hub          {}: DataLink V2, {hub}",
                Escaped(&self.sources.escs()[esc].name)
            );
        }
        for esc in &escs {
            o.push('\n');
            esc.text(&mut o);
        }
        if let Some(total) = total_energy(&escs) {
            let _ = writeln!(
                o,
                "\ntotal        {} ESCs: {}",
                escs.iter().filter(|e| e.acc.frames > 0).count(),
                energy_text(&total)
            );
            let _ = writeln!(
                o,
                "             (charges and energies added; the peak is the largest of one ESC, \
                 the mean is the total energy over the longest ESC's time)"
            );
        }
        o
    }

    /// The summary as one JSON object, as `hwfoc summary --json` prints it.
    pub fn json(&self) -> Value {
        let inputs: Vec<Value> = self
            .sources
            .inputs()
            .iter()
            .map(|info| {
                json!({
                    "input": info.name,
                    "format": info.format.short_name(),
                    "bytes": info.bytes,
                    "flagged_bytes": info.flagged_bytes,
                    "escs": info.escs,
                })
            })
            .collect();
        let reports = self.escs();
        let escs: Vec<Value> = reports
            .iter()
            .map(|esc| {
                let mut v = esc.json();
                // An ESC's own settings, where they differ from the report's.
                if esc.settings != *self.settings
                    && let Some(object) = v.as_object_mut()
                {
                    object.insert("settings".to_string(), settings_json(&esc.settings));
                }
                v
            })
            .collect();
        let hubs: Vec<Value> = self
            .sources
            .hubs()
            .map(|(esc, h)| {
                json!({
                    "stream": self.sources.escs()[esc].name,
                    "bytes": h.bytes(),
                    "bytes_skipped": h.bytes_skipped(),
                    "frames": h.frames(),
                    "frames_length_byte_158": h.frames_with_length_byte(LengthByte::Covered),
                    "frames_length_byte_160": h.frames_with_length_byte(LengthByte::Total),
                    "crc_failures": h.crc_failures(),
                    "bad_headers": h.bad_headers(),
                    "lost_frames": h.lost_frames(),
                    "duplicate_frames": h.duplicate_frames(),
                    "restarts": h.restarts(),
                    "empty_slots": h.empty_slots(),
                    "bad_channels": h.bad_channels(),
                    "duplicate_channels": h.duplicate_channels(),
                })
            })
            .collect();
        json!({
            "schema_version": crate::JSON_SCHEMA_VERSION,
            "settings": settings_json(self.settings),
            "inputs": inputs,
            "hubs": hubs,
            "escs": escs,
            "energy_total": total_energy(&reports).as_ref().map(energy_json),
        })
    }
}

/// The figures of every ESC with data frames added, when there are two or more.
fn total_energy(escs: &[EscReport]) -> Option<Energy> {
    let with_frames: Vec<Energy> = escs.iter().filter_map(EscReport::energy).collect();
    (with_frames.len() > 1).then(|| {
        let mut total = Energy::new();
        for e in &with_frames {
            total.merge(e);
        }
        total
    })
}

/// Charge, energy and power in one line.
fn energy_text(e: &Energy) -> String {
    let mut s = format!(
        "{} mAh, {} Wh consumed",
        Fixed(e.charge_mah(), 3),
        Fixed(e.energy_wh(), 4)
    );
    if let Some(peak) = e.peak_w() {
        let _ = write!(s, "; input power peak {} W", Fixed(peak, 1));
    }
    if let Some(mean) = e.mean_w() {
        let _ = write!(s, ", mean {} W over {:.3} s", Fixed(mean, 1), e.seconds());
    }
    if e.nominal() {
        let _ = write!(
            s,
            " (no receive times: each frame counted as {} ms)",
            NOMINAL_PERIOD_S * 1000.0
        );
    }
    s
}

/// Charge, energy and power as JSON.
fn energy_json(e: &Energy) -> Value {
    json!({
        "charge_mah": e.charge_mah(),
        "energy_wh": e.energy_wh(),
        "peak_power_w": e.peak_w(),
        "mean_power_w": e.mean_w(),
        "seconds": e.seconds(),
        "nominal_period": e.nominal(),
    })
}

/// The short name of a clock in `--json`.
fn clock_name(clock: Clock) -> &'static str {
    match clock {
        Clock::Wall => "unix",
        Clock::Capture => "capture",
        Clock::None => "none",
    }
}

impl EscReport<'_> {
    /// Charge, energy and power, converted from the raw units under the settings.
    /// `None` for an ESC without data frames, or whose protocol sends no voltage or current.
    fn energy(&self) -> Option<Energy> {
        let volts = self.linear(Quantity::Voltage)?.to_f64(1.0);
        let amps = self.linear(Quantity::Current)?.to_f64(1.0);
        Some(self.acc.energy().scaled(volts, amps))
    }

    /// The conversion of `quantity` in this ESC's protocol under its settings, if the protocol
    /// carries it (and the ESC gave a data frame): through which raw statistics are converted.
    fn conversion(&self, quantity: Quantity) -> Option<Conversion> {
        let sample = self.acc.sample?;
        Some(sample.reading(quantity, &self.settings)?.conversion)
    }

    /// The linear conversion of `quantity` (see [`Self::conversion`]).
    fn linear(&self, quantity: Quantity) -> Option<Linear> {
        self.conversion(quantity)?.linear()
    }

    /// A time as shown: a date on a wall clock, else the source's seconds.
    fn date(&self, t: Option<f64>) -> Option<String> {
        t.filter(|_| self.clock == Clock::Wall).map(time::iso8601)
    }

    /// Seconds that passed between the first and the last timed data frame, not counting
    /// across clock discontinuities.
    fn duration(&self) -> Option<f64> {
        self.acc.first_t.map(|_| self.acc.elapsed)
    }

    /// The clock's discontinuities in words, if there were any.
    fn discontinuities(&self) -> Option<String> {
        let (back, jumps) = (self.acc.steps_back, self.acc.jumps);
        let times = |n: u64| {
            if n == 1 {
                "once".to_string()
            } else {
                format!("{n} times")
            }
        };
        let text = match (back, jumps) {
            (0, 0) => return None,
            (b, 0) => format!("the clock steps back {}", times(b)),
            (0, j) => format!("the clock jumps forward {}", times(j)),
            (b, j) => format!(
                "the clock steps back {} and jumps forward {}",
                times(b),
                times(j)
            ),
        };
        let across = if back + jumps == 1 { "it" } else { "them" };
        Some(format!("{text}: no time counted across {across}"))
    }

    /// Data frames per second between the first and the last frame.
    fn frame_rate(&self) -> Option<f64> {
        let d = self.duration()?;
        (d > 0.0).then(|| (self.acc.frames - 1) as f64 / d)
    }

    fn fields(&self) -> Vec<FieldRow> {
        // The protocol's conversions, applied to the raw min, max and mean.
        let field = |q: Quantity| {
            let stats = match lane(q) {
                Some(lane) => {
                    let (range, n) = self.acc.ranges.get(lane, self.acc.frames);
                    let linear = self.linear(q);
                    linear.and_then(|linear| range.convert(n, |x| linear.to_f64(x)))
                }
                None => self.temperature(q).range,
            };
            (q.name(), q.unit(), stats)
        };
        Quantity::ALL.into_iter().map(field).collect()
    }

    /// The statistics of temperature `quantity` (a histogram of its codes).
    fn temperature(&self, quantity: Quantity) -> TempStats {
        let (codes, uncoded) = match quantity {
            Quantity::CapTemp => (&self.acc.cap_codes, self.acc.uncoded[1]),
            _ => (&self.acc.mos_codes, self.acc.uncoded[0]),
        };
        match self.conversion(quantity) {
            // Every data frame's temperature is in the histogram: its statistics are whole.
            Some(conversion) if uncoded == 0 => temp_stats(codes, conversion),
            // A protocol that does not send it, or not as a code of 0..=255: no statistics
            // rather than those of some frames.
            _ => TempStats::default(),
        }
    }

    fn faults(&self) -> impl Iterator<Item = (Fault, u64)> + '_ {
        Fault::ALL
            .into_iter()
            .map(|f| (f, self.acc.fault_frames[usize::from(f.bit())]))
            .filter(|&(_, n)| n > 0)
    }

    fn text(&self, o: &mut String) {
        let st = self.stats;
        let _ = writeln!(o, "ESC {:<8} {}", self.index, self.label);
        if st.bytes() == 0 {
            let _ = writeln!(o, "frames       none: no bytes from this stream");
            return;
        }
        if st.frames() == 0 && st.info_frames() == 0 {
            let _ = writeln!(o, "frames       none: {}", self.no_frames);
            let _ = writeln!(o, "skipped      {} bytes", st.bytes_skipped());
            return;
        }
        let _ = write!(
            o,
            "frames       {} data, {} info",
            st.frames(),
            st.info_frames()
        );
        if let (Some(d), Some(rate)) = (self.duration(), self.frame_rate()) {
            let _ = write!(o, " over {d:.3} s ({rate:.1} data frames/s)");
        }
        o.push('\n');
        if let (Some(first), Some(last)) = (self.acc.first_t, self.acc.last_t) {
            if self.clock == Clock::Wall {
                let _ = writeln!(
                    o,
                    "time         {} .. {} ({:.3} s)",
                    time::iso8601(first),
                    time::iso8601(last),
                    self.acc.elapsed
                );
            } else {
                let _ = writeln!(o, "time         {first} .. {last} s (the source's clock)");
            }
            if let Some(text) = self.discontinuities() {
                let _ = writeln!(o, "clock        {text}");
            }
        }
        let _ = writeln!(
            o,
            "link         {} checksum failures, {} lost packets, {} duplicate packets, {} restarts, {} bytes skipped ({:.2} %)",
            st.checksum_failures(),
            st.lost_packets(),
            st.duplicate_packets(),
            st.restarts(),
            st.bytes_skipped(),
            percent(st.bytes_skipped(), st.bytes())
        );
        if let Some(ratio) = st.delivery_ratio() {
            let _ = writeln!(o, "delivery     {:.2} % of data frames", ratio * 100.0);
        }
        if st.frames() == 0 {
            let _ = writeln!(o, "             no data frames: {}", self.no_frames);
        }
        for (info, n) in &self.acc.infos {
            let _ = writeln!(o, "device       {}  ({n} info frames)", Escaped(info));
        }
        if self.acc.frames == 0 {
            return;
        }
        let _ = writeln!(
            o,
            "\n{:<18} {:>12} {:>12} {:>12}  unit",
            "field", "min", "max", "mean"
        );
        for (name, unit, range) in self.fields() {
            match range {
                Some([min, max, mean]) => {
                    let _ = writeln!(o, "{name:<18} {min:>12.3} {max:>12.3} {mean:>12.3}  {unit}");
                }
                None => {
                    let _ = writeln!(o, "{name:<18} {:>12} {:>12} {:>12}  {unit}", "-", "-", "-");
                }
            }
        }
        for (name, t) in [
            ("mos_temp_c", self.temperature(Quantity::MosTemp)),
            ("cap_temp_c", self.temperature(Quantity::CapTemp)),
        ] {
            if t.below + t.above > 0 {
                let _ = writeln!(
                    o,
                    "{name:<18} out of the table's range in {} frames (below 0 degC: {}, above 129 degC: {})",
                    t.below + t.above,
                    t.below,
                    t.above
                );
            }
        }
        if let Some(energy) = self.energy() {
            let _ = writeln!(o, "\nenergy       {}", energy_text(&energy));
        }
        o.push('\n');
        if self.episode_count == 0 {
            let _ = writeln!(o, "faults       none");
            return;
        }
        for (fault, n) in self.faults() {
            let _ = writeln!(
                o,
                "fault        {:<22} in {n} frames ({})",
                fault.name(),
                fault.description()
            );
        }
        let _ = writeln!(
            o,
            "episodes     {} (runs of consecutive frames with faults)",
            self.episode_count
        );
        for (i, e) in self.episodes.iter().take(TEXT_EPISODES).enumerate() {
            let _ = writeln!(o, "  {:>4}  {}", i + 1, episode_text(e, self.clock));
        }
        let more = self.episode_count - self.episodes.len().min(TEXT_EPISODES) as u64;
        if more > 0 {
            let _ = writeln!(o, "        ... and {more} more (all listed with --json)");
        }
    }

    fn json(&self) -> Value {
        let st = self.stats;
        let fields: serde_json::Map<String, Value> = self
            .fields()
            .into_iter()
            .map(|(name, unit, range)| {
                let v = match range {
                    Some([min, max, mean]) => {
                        json!({"min": min, "max": max, "mean": mean, "unit": unit})
                    }
                    None => json!({"min": null, "max": null, "mean": null, "unit": unit}),
                };
                (name.to_string(), v)
            })
            .collect();
        let faults: serde_json::Map<String, Value> = self
            .faults()
            .map(|(f, n)| (f.name().to_string(), json!(n)))
            .collect();
        let infos: Vec<Value> = self
            .acc
            .infos
            .iter()
            .map(|(i, n)| {
                let mut info = device_json(i);
                info.insert("text".to_string(), json!(i.to_string()));
                info.insert("frames".to_string(), json!(n));
                Value::Object(info)
            })
            .collect();
        let episodes: Vec<Value> = self
            .episodes
            .iter()
            .map(|e| episode_json(e, self.clock))
            .collect();
        let temps = |t: TempStats| json!({"below_range": t.below, "above_range": t.above});
        let warning = if st.bytes() == 0 {
            Some("no bytes from this stream")
        } else {
            (st.frames() == 0).then_some(self.no_frames.as_str())
        };
        json!({
            "esc": self.index,
            "input": self.input,
            "stream": self.stream,
            "bytes": st.bytes(),
            "frames": st.frames(),
            "info_frames": st.info_frames(),
            "clock": clock_name(self.clock),
            "first_t_s": self.acc.first_t,
            "last_t_s": self.acc.last_t,
            "first_time": self.date(self.acc.first_t),
            "last_time": self.date(self.acc.last_t),
            "duration_s": self.duration(),
            "clock_steps_back": self.acc.steps_back,
            "clock_jumps": self.acc.jumps,
            "frame_rate_hz": self.frame_rate(),
            "link": {
                "checksum_failures": st.checksum_failures(),
                "lost_packets": st.lost_packets(),
                "duplicate_packets": st.duplicate_packets(),
                "restarts": st.restarts(),
                "bytes_skipped": st.bytes_skipped(),
                "delivery_ratio": st.delivery_ratio(),
            },
            "info": infos,
            "fields": fields,
            "temperature_out_of_range": {
                "mos_temp_c": temps(self.temperature(Quantity::MosTemp)),
                "cap_temp_c": temps(self.temperature(Quantity::CapTemp)),
            },
            "energy": self.energy().map(|e| energy_json(&e)),
            "faults": faults,
            "fault_episode_count": self.episode_count,
            "fault_episodes": episodes,
            "warning": warning,
        })
    }
}

/// What an information frame says of the device, as every JSON output names it (`summary
/// --json`, `monitor --json`): `{"product": ..., "hardware": ..., "firmware": ..., "id": ...}`.
pub fn device_json(info: &Info) -> serde_json::Map<String, Value> {
    [
        ("product", info.product()),
        ("hardware", info.hardware()),
        ("firmware", info.firmware()),
        ("id", info.id()),
    ]
    .into_iter()
    .map(|(name, value)| (name.to_string(), json!(value)))
    .collect()
}

/// An episode in one line: when (dates on a wall clock), how long, which faults.
fn episode_text(e: &Episode, clock: Clock) -> String {
    let mut s = format!("{} (", e.when(clock == Clock::Wall));
    if let (Some(a), Some(b)) = (e.first.t, e.last.t) {
        let _ = write!(s, "{:.3} s, ", b - a);
    }
    let _ = write!(s, "{} frames", e.frames);
    if let (Some(a), Some(b)) = (e.first.packet, e.last.packet) {
        let _ = write!(s, ", packets {a} .. {b}");
    }
    let _ = write!(s, ")  {}", fault_names(e.bits).join(", "));
    if e.ongoing {
        s.push_str("  (still on at the end)");
    }
    s
}

fn episode_json(e: &Episode, clock: Clock) -> Value {
    let date = |t: Option<f64>| t.filter(|_| clock == Clock::Wall).map(time::iso8601);
    json!({
        "start_t_s": e.first.t,
        "end_t_s": e.last.t,
        "start_time": date(e.first.t),
        "end_time": date(e.last.t),
        "duration_s": e.first.t.zip(e.last.t).map(|(a, b)| b - a),
        "start_frame": e.first.frame,
        "end_frame": e.last.frame,
        "start_packet": e.first.packet,
        "end_packet": e.last.packet,
        "frames": e.frames,
        "status": e.bits.0,
        "faults": fault_names(e.bits),
        "ongoing": e.ongoing,
    })
}

fn fault_names(status: Status) -> Vec<&'static str> {
    status.faults().map(Fault::name).collect()
}

fn percent(part: u64, whole: u64) -> f64 {
    if whole == 0 {
        0.0
    } else {
        part as f64 * 100.0 / whole as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::foc::DataFrame;

    #[test]
    fn the_device_is_named_field_by_field() {
        let info = Info::from(hwfoc::foc::InfoFrame::new("HW1", "V2", "XR-01.0.00", "42").unwrap());
        assert_eq!(
            Value::Object(device_json(&info)).to_string(),
            r#"{"product":"HW1","hardware":"V2","firmware":"XR-01.0.00","id":"42"}"#
        );
    }

    #[test]
    fn temperature_stats_come_from_the_histogram() {
        let mut codes = [0u64; 256];
        codes[206] = 3; // 28 degC
        codes[183] = 1; // 40 degC
        codes[250] = 2; // below range
        codes[10] = 1; // above range
        let t = temp_stats(&codes, Conversion::AdcTable);
        assert_eq!(t.range, Some([28.0, 40.0, (3.0 * 28.0 + 40.0) / 4.0]));
        assert_eq!((t.below, t.above), (2, 1));
    }

    #[test]
    fn ranges_convert_monotonically() {
        let mut r = Ranges::default();
        for v in [-64, 128, 0] {
            r.add(&DataFrame {
                current_raw: v,
                voltage_raw: (v + 64) as u16,
                ..Default::default()
            });
        }
        let voltage = lane(Quantity::Voltage).unwrap();
        let (current, n) = r.get(CURRENT, 3);
        assert_eq!(n, 3);
        assert_eq!(
            current.convert(n, |x| x / 64.0),
            Some([-1.0, 2.0, 64.0 / 3.0 / 64.0])
        );
        assert_eq!(
            r.get(voltage, 3).0.convert(3, |x| x),
            Some([0.0, 192.0, 256.0 / 3.0])
        );
        assert_eq!(Ranges::default().get(ERPM, 0).0.convert(0, |x| x), None);
    }

    #[test]
    fn episodes_are_maximal_runs_of_faulty_frames() {
        let mut acc = Accumulator::default();
        let statuses = [
            0u16, 0x0001, 0x0040, 0x0001, 0, 0, 0x8000, 0, 0x0002, 0x0002,
        ];
        for (i, &s) in statuses.iter().enumerate() {
            let frame = DataFrame {
                packet: 100 + i as u16,
                status: Status(s),
                ..Default::default()
            };
            acc.add(Some(i as f64 * 0.05), &Frame::Data(frame.into()));
        }
        assert_eq!(acc.episode_count, 2);
        let first = acc.episodes[0];
        assert_eq!(
            (first.first.frame, first.last.frame, first.frames),
            (1, 3, 3)
        );
        assert_eq!(
            (first.first.packet, first.last.packet),
            (Some(101), Some(103))
        );
        assert_eq!(first.first.t, Some(0.05));
        assert_eq!(
            fault_names(first.bits),
            ["input_voltage_high", "mos_overheat"]
        );
        assert!(!first.ongoing);
        assert_eq!(acc.episodes[1].frames, 1);
        // The last run is still open at the end of the stream.
        let open = acc.episode.unwrap();
        assert_eq!((open.first.frame, open.last.frame, open.frames), (8, 9, 2));
    }
}
