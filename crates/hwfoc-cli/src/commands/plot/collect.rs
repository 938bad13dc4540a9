//! The frames of a plot, gathered as they are decoded, in bounded memory.
//!
//! Each ESC has a fixed number of time buckets. A bucket holds, for each plotted quantity, the
//! first, lowest, highest and last value of its frames: drawn as a line through first, low,
//! high and last, a column of pixels shows exactly what a line through every frame would
//! (the "M4" reduction). When a frame falls past the last bucket, neighbouring buckets are
//! merged in pairs and each covers twice the time: the buckets always span the ESC's frames,
//! at least half of them in use, whatever the length of the recording.
//!
//! Buckets hold the records' values, in physical units: the plot shows exactly what
//! `hwfoc decode` gives.
//!
//! Frames are placed on a clock: their receive time, or for inputs without receive times the
//! data frame's index times its protocol's frame period (`energy::nominal_period_s`: 50 ms for
//! HW-FOC, 20 ms for HW5, ...). The clock of an ESC never goes
//! back: at a discontinuity of its receive times (a step back, or a jump forward its packet
//! numbers do not explain: [`Step`]) it goes on one frame period after the frame before, and
//! the lines break there; the plot's subtitle counts the discontinuities.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use hwfoc::telemetry::Info;
use hwfoc::{Settings, Status};

use crate::error::CliError;
use crate::shown::{COUNT, Shown, Values, values};
use hwfoc_io::Handler;
use hwfoc_io::energy::{self, Energy};
use hwfoc_io::record::Record;
use hwfoc_io::summary::{Episode, Mark};
use hwfoc_io::write::WriteError;
use hwfoc_io::{Selection, Window};
use hwfoc_ports::clock::Step;

/// A pause longer than this between two data frames of an ESC (idle frames come every
/// ~364 ms) is a gap in the recording: lines are not drawn across it.
pub const GAP_S: f64 = 1.0;

/// The width of a bucket before any merging, s.
const FIRST_WIDTH: f64 = 0.001;

/// Fault spans kept per ESC; beyond this, each new one is merged into the last.
const MAX_SPANS: usize = 10_000;

/// The frames of one stretch of time: per quantity the first, lowest, highest and last value
/// (NaN for first and last, lowest above highest, where no frame had a value).
#[derive(Debug, Clone, Copy)]
pub struct Bucket {
    /// Data frames in it.
    pub frames: u32,
    /// Its first frame came after a gap ([`GAP_S`]) or is the first of its ESC.
    pub gap_before: bool,
    first: Values,
    min: Values,
    max: Values,
    last: Values,
}

impl Bucket {
    /// A bucket without frames.
    pub const EMPTY: Bucket = Bucket {
        frames: 0,
        gap_before: false,
        first: [f32::NAN; COUNT],
        min: [f32::INFINITY; COUNT],
        max: [f32::NEG_INFINITY; COUNT],
        last: [f32::NAN; COUNT],
    };

    /// Adds a frame's values.
    #[inline]
    pub(super) fn add(&mut self, v: &Values, gap: bool) {
        if self.frames == 0 {
            self.gap_before = gap;
        }
        self.frames = self.frames.saturating_add(1);
        for (q, &x) in v.iter().enumerate() {
            if !x.is_nan() {
                if self.first[q].is_nan() {
                    self.first[q] = x;
                }
                self.last[q] = x;
                self.min[q] = self.min[q].min(x);
                self.max[q] = self.max[q].max(x);
            }
        }
    }

    /// Adds the frames of `later`, which all came after this bucket's.
    pub fn merge(&mut self, later: &Bucket) {
        if later.frames == 0 {
            return;
        }
        if self.frames == 0 {
            *self = *later;
            return;
        }
        self.frames = self.frames.saturating_add(later.frames);
        for q in 0..COUNT {
            if self.first[q].is_nan() {
                self.first[q] = later.first[q];
            }
            if !later.last[q].is_nan() {
                self.last[q] = later.last[q];
            }
            self.min[q] = self.min[q].min(later.min[q]);
            self.max[q] = self.max[q].max(later.max[q]);
        }
    }

    /// First, lowest, highest and last value of quantity `q`, if any of the frames had one.
    pub fn values(&self, q: Shown) -> Option<[f64; 4]> {
        let i = q.index();
        if self.frames == 0 || self.min[i] > self.max[i] {
            return None;
        }
        Some([self.first[i], self.min[i], self.max[i], self.last[i]].map(f64::from))
    }
}

/// A fixed number of buckets of equal width from the clock value of an ESC's first frame.
#[derive(Debug)]
pub struct Buckets {
    /// Clock value where bucket 0 starts.
    pub origin: f64,
    /// Width of a bucket, s.
    pub width: f64,
    /// Its inverse: buckets per second.
    per_width: f64,
    /// The buckets; those past the last frame are empty.
    pub cells: Vec<Bucket>,
}

impl Buckets {
    fn new(count: usize) -> Buckets {
        Buckets {
            origin: f64::NAN,
            width: FIRST_WIDTH,
            per_width: 1.0 / FIRST_WIDTH,
            cells: vec![Bucket::EMPTY; count],
        }
    }

    /// Adds a frame at clock value `c`.
    #[inline]
    fn add(&mut self, c: f64, v: &Values, gap: bool) {
        if self.origin.is_nan() {
            self.origin = c;
        }
        // An ESC's clock never goes back (see the module documentation); a frame before the
        // origin would be a frame of the first bucket.
        let mut i = ((c - self.origin) * self.per_width).max(0.0);
        while i >= self.cells.len() as f64 {
            self.halve();
            i = ((c - self.origin) * self.per_width).max(0.0);
        }
        self.cells[i as usize].add(v, gap);
    }

    /// Merges the buckets in pairs: twice the time each, the second half left empty.
    fn halve(&mut self) {
        let n = self.cells.len();
        for i in 0..n / 2 {
            let mut b = self.cells[2 * i];
            b.merge(&self.cells[2 * i + 1]);
            self.cells[i] = b;
        }
        for cell in &mut self.cells[n / 2..] {
            *cell = Bucket::EMPTY;
        }
        self.width *= 2.0;
        self.per_width = 1.0 / self.width;
    }
}

/// A stretch of time with faults: one fault episode, or several too close to tell apart.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    /// Clock value of its first faulty frame.
    pub start: f64,
    /// Clock value of its last faulty frame plus one frame period.
    pub end: f64,
    /// Every status bit seen in it.
    pub bits: Status,
    /// Fault episodes in it.
    pub episodes: u64,
    /// Still going on at the end of the input.
    pub ongoing: bool,
}

/// The window of a finding of `hwfoc check` (a warning or a critical one), on the clock.
#[derive(Debug, Clone, PartialEq)]
pub struct Shade {
    /// Its start.
    pub start: f64,
    /// Its end.
    pub end: f64,
    /// How bad.
    pub severity: hwfoc_io::check::Severity,
    /// The analyser's name.
    pub label: &'static str,
}

/// Everything plotted of one ESC.
#[derive(Debug)]
pub struct EscData {
    /// Data frames read (in the time window or not).
    pub frames: u64,
    /// Data frames plotted.
    pub plotted: u64,
    /// Whether its frames have receive times.
    pub timed: bool,
    /// Earliest and latest receive time of its data frames, in the window or not.
    pub times: Option<(f64, f64)>,
    /// Clock value of its first and last plotted frame.
    pub clock: Option<(f64, f64)>,
    /// Its first device-information frame.
    pub info: Option<Info>,
    /// The protocol of its first data frame (which names its fault bits).
    pub protocol: Option<hwfoc::Protocol>,
    /// Its plotted frames.
    pub buckets: Buckets,
    /// Its fault spans, in time order.
    pub spans: Vec<Span>,
    /// Fault episodes seen.
    pub episodes: u64,
    /// The windows of the findings shaded ([`Collector::shade`]).
    pub shades: Vec<Shade>,
    /// Charge and energy of its plotted frames.
    pub energy: Energy,
    /// Discontinuities of its receive times ([`Step`]): the clock goes on across them.
    pub discontinuities: u64,
    /// The last timed data frame's receive time and packet number.
    last_timed: Option<(f64, Option<u32>)>,
    /// What is added to a receive time to place it on the clock: it changes at each
    /// discontinuity, so that the clock goes on one frame period after the frame before.
    shift: f64,
    /// The fault episode going on.
    open: Option<Episode>,
    /// The first fault episode with the frames' own receive times (not the plot's clock),
    /// for the header, and the one going on until it ends.
    pub first_episode: Option<Episode>,
    first_open: Option<Episode>,
}

impl EscData {
    fn new(buckets: usize) -> EscData {
        EscData {
            frames: 0,
            plotted: 0,
            timed: false,
            times: None,
            clock: None,
            info: None,
            buckets: Buckets::new(buckets),
            spans: Vec::new(),
            episodes: 0,
            shades: Vec::new(),
            energy: Energy::new(),
            discontinuities: 0,
            last_timed: None,
            shift: 0.0,
            open: None,
            first_episode: None,
            protocol: None,
            first_open: None,
        }
    }

    /// The time between two data frames of its protocol when running, s: the clock of inputs
    /// without receive times, and the width given to a fault episode's last frame.
    pub fn period(&self) -> f64 {
        energy::nominal_period_s(self.protocol)
    }

    #[inline]
    fn add(&mut self, r: &Record, window: &mut Window) {
        if self.protocol.is_none() {
            self.protocol = Some(r.protocol);
            self.energy = Energy::at_period(self.period());
        }
        let t = r.t_s;
        let index = self.frames;
        self.frames += 1;
        let mut jumped = false;
        if let Some(t) = t {
            let (first, last) = self.times.get_or_insert((t, t));
            *first = first.min(t);
            *last = last.max(t);
            if let Some((last_t, last_packet)) = self.last_timed {
                let packets = r
                    .packet
                    .zip(last_packet)
                    .and_then(|(p, l)| r.protocol.packets_between(l, p));
                if Step::between(last_t, t, packets).is_discontinuity() {
                    self.discontinuities += 1;
                    self.shift = last_t + self.shift + self.period() - t;
                    jumped = true;
                }
            }
            self.last_timed = Some((t, r.packet));
        }
        if !window.contains(t) {
            return;
        }
        let c = t.map_or_else(|| clock(None, index, self.period()), |t| t + self.shift);
        if !c.is_finite() {
            return;
        }
        self.timed = t.is_some();
        self.plotted += 1;
        let gap = match &mut self.clock {
            Some((_, last)) => {
                let gap = jumped || c - *last > GAP_S;
                *last = c;
                gap
            }
            None => {
                self.clock = Some((c, c));
                true
            }
        };
        self.buckets.add(c, &values(r), gap);
        if let (Some(volts), Some(amps)) = (r.voltage_v, r.current_a) {
            self.energy.add(t, f64::from(volts), f64::from(amps));
        }
        // Episodes are placed on the clock too.
        let mark = Mark {
            t: t.map(|_| c),
            frame: index,
            packet: r.packet,
        };
        // A protocol without status word shows no fault episode.
        let status = r.fault_word().unwrap_or_default();
        if let Some(ended) = Episode::track(&mut self.open, mark, status) {
            self.keep(&ended);
        }
        if self.first_episode.is_none() {
            let own = Mark { t, ..mark };
            self.first_episode = Episode::track(&mut self.first_open, own, status);
        }
    }

    /// Adds an ended fault episode to the spans, merged into the last one when the plot could
    /// not show the space between them (less than a bucket).
    fn keep(&mut self, e: &Episode) {
        self.episodes += 1;
        let span = Span {
            start: clock(e.first.t, e.first.frame, self.period()),
            end: clock(e.last.t, e.last.frame, self.period()) + self.period(),
            bits: e.bits,
            episodes: 1,
            ongoing: e.ongoing,
        };
        let full = self.spans.len() >= MAX_SPANS;
        match self.spans.last_mut() {
            Some(last) if full || span.start - last.end < self.buckets.width => {
                last.end = last.end.max(span.end);
                last.bits = Status(last.bits.0 | span.bits.0);
                last.episodes += 1;
                last.ongoing = span.ongoing;
            }
            _ => self.spans.push(span),
        }
    }

    /// Closes the episode still going on at the end of the input.
    fn finish(&mut self) {
        if let Some(mut open) = self.open.take() {
            open.ongoing = true;
            self.keep(&open);
        }
        if let Some(mut open) = self.first_open.take() {
            open.ongoing = true;
            self.first_episode.get_or_insert(open);
        }
    }
}

/// The clock value of a data frame: its receive time, or its index times the frame period.
fn clock(t: Option<f64>, index: u64, period: f64) -> f64 {
    t.unwrap_or(index as f64 * period)
}

/// The [`Handler`] of a plot: the frames of the chosen ESCs, by ESC.
#[derive(Debug)]
pub struct Collector {
    settings: Settings,
    selection: Selection,
    buckets: usize,
    escs: Vec<EscData>,
    /// When set (Ctrl-C, SIGTERM), reading ends with [`WriteError::Interrupted`] for the
    /// image named: see [`Collector::stop_on`].
    stop: Option<(Arc<AtomicBool>, String)>,
}

/// Buckets per ESC for an image `width` pixels wide: at least two per pixel of a panel.
pub fn buckets_for(width: u32) -> usize {
    (width as usize / 2).max(256)
}

impl Collector {
    /// A collector for an image `width` pixels wide, of the frames in `selection`, whose
    /// records were converted under `settings`.
    pub fn new(settings: Settings, selection: Selection, width: u32) -> Collector {
        Collector {
            settings,
            selection,
            buckets: buckets_for(width),
            escs: Vec::new(),
            stop: None,
        }
    }

    /// Ends the reading at the next batch once `flag` is set (by Ctrl-C or SIGTERM: see
    /// [`crate::args::InputArgs::stop_if_read_to_end`]), with an error saying that `image` is
    /// left as it was: nothing is drawn, and the temporary file goes away with its target.
    pub fn stop_on(mut self, flag: Option<Arc<AtomicBool>>, image: &str) -> Collector {
        self.stop = flag.map(|f| (f, image.to_string()));
        self
    }

    /// The settings values were converted with.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The window frames were chosen by.
    pub fn window(&self) -> &Window {
        &self.selection.window
    }

    /// The receive time of the first data frame with one, of any ESC: the time axis counts
    /// from it, as `--from +S` does.
    pub fn origin(&self) -> Option<f64> {
        self.selection.window.origin()
    }

    /// Whether ESC `esc` was asked for.
    pub fn wanted(&self, esc: usize) -> bool {
        u8::try_from(esc).is_ok_and(|e| self.selection.esc(e))
    }

    /// The data of ESC `esc`, if it had any frame.
    pub fn esc(&self, esc: usize) -> Option<&EscData> {
        self.escs.get(esc)
    }

    /// Shades the windows of `findings` (those of `hwfoc check`: warnings and critical ones
    /// with a window) on their ESCs' panels.
    pub fn shade(&mut self, findings: &[hwfoc_io::check::Finding]) {
        for f in findings {
            let (Some(esc), Some(w)) = (&f.esc, f.window) else {
                continue;
            };
            if f.severity == hwfoc_io::check::Severity::Ok {
                continue;
            }
            if let Some(data) = self.escs.get_mut(esc.number) {
                data.shades.push(Shade {
                    start: w.start_s,
                    end: w.end_s,
                    severity: f.severity,
                    label: f.analyser.name(),
                });
            }
        }
    }

    /// Ends every ESC's data: what was read is then ready to be drawn.
    pub fn finish(&mut self) {
        for esc in &mut self.escs {
            esc.finish();
        }
    }
}

impl Handler for Collector {
    type Error = CliError;

    #[inline]
    fn record(&mut self, r: &Record) {
        // Every ESC's first frame counts for the window and the time axis.
        self.selection.window.observe(r.t_s);
        if let Some(esc) = esc_data(&mut self.escs, self.buckets, &self.selection, r.esc) {
            esc.add(r, &mut self.selection.window);
        }
    }

    fn info(&mut self, esc: u8, _: Option<f64>, info: &Info) {
        if let Some(esc) = esc_data(&mut self.escs, self.buckets, &self.selection, esc) {
            esc.info.get_or_insert(*info);
        }
    }

    fn end_batch(&mut self, _live: bool) -> Result<(), CliError> {
        match &self.stop {
            Some((flag, image)) if flag.load(Ordering::Relaxed) => {
                Err(CliError::Write(WriteError::Interrupted {
                    output: Some(image.clone()),
                }))
            }
            _ => Ok(()),
        }
    }
}

/// The data of ESC `esc` in `escs`, made (with `buckets` buckets) on its first frame, if the
/// selection has it.
#[inline]
fn esc_data<'a>(
    escs: &'a mut Vec<EscData>,
    buckets: usize,
    selection: &Selection,
    esc: u8,
) -> Option<&'a mut EscData> {
    if !selection.esc(esc) {
        return None;
    }
    let i = usize::from(esc);
    if escs.len() <= i {
        escs.resize_with(i + 1, || EscData::new(buckets));
    }
    Some(&mut escs[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    use hwfoc::foc::DataFrame;
    use hwfoc::{Quantity, Temperature};

    /// HW-FOC's frame period, s.
    const FRAME_PERIOD: f64 = 0.05;

    /// The record of a frame at `t` with this throttle and status word.
    fn frame(t: f64, throttle: u16, status: u16) -> Record {
        let f = DataFrame {
            packet: (t / FRAME_PERIOD).round() as u16,
            throttle_in_raw: throttle,
            status: Status(status),
            ..Default::default()
        };
        Record::new(Some(t), 0, &f.into(), &Settings::DEFAULT)
    }

    /// Every quantity at the value of a throttle of `raw` (temperatures 79.0 degC).
    fn values_of(raw: u16) -> Values {
        let pct = raw as f32 * 100.0 / 1024.0;
        std::array::from_fn(|i| if i < 7 { pct } else { 79.0 })
    }

    fn all() -> Window {
        Window::ALL
    }

    #[test]
    fn buckets_keep_first_min_max_last_and_halve_to_fit() {
        let mut b = Buckets::new(4);
        b.add(0.0, &values_of(512), true);
        b.add(0.0005, &values_of(256), false);
        b.add(0.0009, &values_of(768), false);
        assert_eq!(b.cells[0].frames, 3);
        assert_eq!(
            b.cells[0].values(Shown::Carried(Quantity::ThrottleIn)),
            Some([50.0, 25.0, 75.0, 75.0])
        );
        assert!(b.cells[0].gap_before);
        // 10 ms is past 4 buckets of 1 ms: two halvings make them 4 ms wide.
        b.add(0.010, &values_of(1024), false);
        assert_eq!(b.width, 0.004);
        assert_eq!(b.cells[0].frames, 3);
        assert_eq!(
            b.cells[0].values(Shown::Carried(Quantity::ThrottleIn)),
            Some([50.0, 25.0, 75.0, 75.0])
        );
        assert_eq!(b.cells[2].frames, 1);
        assert_eq!(
            b.cells[2].values(Shown::Carried(Quantity::Voltage)),
            Some([100.0; 4])
        );
        assert!(!b.cells[2].gap_before);
        assert_eq!(b.cells[1].frames + b.cells[3].frames, 0);
        assert_eq!(b.cells[1].values(Shown::Carried(Quantity::Rpm)), None);
    }

    #[test]
    fn values_convert_as_the_record_does() {
        let s = Settings::new(100.0, 7, 2.0).unwrap();
        let f = DataFrame {
            throttle_in_raw: 300,
            throttle_out_raw: 280,
            erpm_raw: 1234,
            voltage_raw: 251,
            current_raw: -150,
            phase_current_raw: 420,
            mos_adc: 206,
            cap_adc: 183,
            ..Default::default()
        };
        let mut b = Bucket::EMPTY;
        b.add(&values(&Record::new(None, 0, &f.into(), &s)), false);
        let v = |q| b.values(q).unwrap()[0];
        // docs/RECORD-SCHEMA.md's formulas, to f32's precision.
        let near = |q, expected: f64| {
            let got = v(q);
            assert!(
                (got - expected).abs() <= 1e-6 * expected.abs(),
                "{q:?}: {got} {expected}"
            );
        };
        near(Shown::Carried(Quantity::ThrottleIn), 300.0 * 100.0 / 1024.0);
        near(
            Shown::Carried(Quantity::ThrottleOut),
            280.0 * 100.0 / 1024.0,
        );
        near(Shown::Carried(Quantity::Rpm), 1234.0 * 10.0 / (2.0 * 7.0));
        near(Shown::Carried(Quantity::Voltage), 25.1);
        // 25.1 V times -1.5 A.
        assert!(
            (v(Shown::Power) - 25.1 * -1.5).abs() < 1e-4,
            "{}",
            v(Shown::Power)
        );
        near(Shown::Carried(Quantity::Current), -150.0 / 100.0);
        near(Shown::Carried(Quantity::PhaseCurrent), 420.0 / 100.0);
        assert_eq!(v(Shown::Carried(Quantity::MosTemp)), 28.0);
        assert_eq!(v(Shown::Carried(Quantity::CapTemp)), 40.0);
    }

    #[test]
    fn out_of_range_temperatures_are_no_value() {
        assert_eq!(Temperature::from_adc(250).celsius(), None);
        let mut b = Bucket::EMPTY;
        let with = |mos: u8| {
            let f = DataFrame {
                mos_adc: mos,
                ..Default::default()
            };
            values(&Record::new(None, 0, &f.into(), &Settings::DEFAULT))
        };
        b.add(&with(250), false); // below range: no value
        assert_eq!(b.values(Shown::Carried(Quantity::MosTemp)), None);
        b.add(&with(206), false); // 28 degC
        b.add(&with(183), false); // 40 degC
        b.add(&with(10), false); // above range: no value
        assert_eq!(
            b.values(Shown::Carried(Quantity::MosTemp)),
            Some([28.0, 28.0, 40.0, 40.0])
        );
        let mut later = Bucket::EMPTY;
        later.add(&with(250), false);
        b.merge(&later);
        assert_eq!(b.frames, 5);
        assert_eq!(
            b.values(Shown::Carried(Quantity::MosTemp)).unwrap()[3],
            40.0
        );
    }

    #[test]
    fn episodes_become_spans_and_gaps_are_found() {
        let mut esc = EscData::new(1024);
        let statuses = [0u16, 0x40, 0x40, 0, 0, 0x1, 0];
        for (i, &s) in statuses.iter().enumerate() {
            esc.add(&frame(100.0 + i as f64 * 0.05, 0, s), &mut all());
        }
        // A pause of 5 s, then a fault to the end.
        esc.add(&frame(105.3, 0, 0x2), &mut all());
        esc.finish();
        assert_eq!(esc.episodes, 3);
        let s: Vec<(f64, f64, u16, bool)> = esc
            .spans
            .iter()
            .map(|s| (s.start, s.end, s.bits.0, s.ongoing))
            .collect();
        assert_eq!(s.len(), 3, "{s:?}");
        assert!((s[0].0 - 100.05).abs() < 1e-9 && (s[0].1 - 100.15).abs() < 1e-9);
        assert_eq!((s[0].2, s[1].2, s[2].2), (0x40, 0x1, 0x2));
        assert!(s[2].3 && !s[1].3);
        let gaps: Vec<bool> = esc
            .buckets
            .cells
            .iter()
            .filter(|b| b.frames > 0)
            .map(|b| b.gap_before)
            .collect();
        assert_eq!(gaps.iter().filter(|&&g| g).count(), 2, "{gaps:?}");
        assert!(gaps[0] && *gaps.last().unwrap());
    }

    #[test]
    fn episodes_closer_than_a_bucket_share_a_span() {
        let mut esc = EscData::new(4);
        // 4 buckets over 20 s of frames: 8.192 s each; faults every other frame.
        for i in 0..400u16 {
            esc.add(&frame(f64::from(i) * 0.05, 0, i % 2), &mut all());
        }
        esc.finish();
        assert_eq!(esc.episodes, 200);
        assert!(esc.spans.len() <= 4, "{:?}", esc.spans.len());
        assert_eq!(esc.spans.iter().map(|s| s.episodes).sum::<u64>(), 200);
    }

    #[test]
    fn the_clock_goes_on_across_a_step_back_and_a_jump() {
        let mut esc = EscData::new(1024);
        // 2 s of frames, an NTP step back of an hour, 2 s more, a jump to the year 2226
        // (packet numbers go on by one), 2 s more back in 2026.
        let start = 1_795_442_580.0;
        let mut times: Vec<f64> = (0..40).map(|k| start + k as f64 * 0.05).collect();
        times.extend((0..40).map(|k| start - 3600.0 + k as f64 * 0.05));
        times.push(8_000_000_000.0);
        times.extend((0..40).map(|k| start - 3598.0 + k as f64 * 0.05));
        for (k, &t) in times.iter().enumerate() {
            let mut r = frame(t, 0, 0);
            r.packet = Some(k as u32);
            esc.add(&r, &mut all());
        }
        assert_eq!(esc.discontinuities, 3);
        let (first, last) = esc.clock.unwrap();
        // 121 frames a frame period apart.
        assert!(
            (last - first - 120.0 * FRAME_PERIOD).abs() < 1e-6,
            "{first} .. {last}"
        );
        let gaps = esc.buckets.cells.iter().filter(|b| b.gap_before).count();
        assert_eq!(
            gaps, 4,
            "the first frame and each discontinuity start a line"
        );
    }

    #[test]
    fn frames_outside_the_window_are_not_plotted() {
        let mut window = Window::new(Some(1.0), Some(2.0)).unwrap();
        let mut esc = EscData::new(64);
        for i in 0..60 {
            esc.add(&frame(i as f64 * 0.05, 100, 0), &mut window);
        }
        assert_eq!((esc.frames, esc.plotted), (60, 20));
        assert_eq!(esc.times, Some((0.0, 59.0 * 0.05)));
        let (first, last) = esc.clock.unwrap();
        assert!((first - 1.0).abs() < 1e-9 && (last - 1.95).abs() < 1e-9);
    }
}
