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
//! Charge, energy and power ([`Energy`]) are integrated per ESC over its data frames' times (each
//! frame's current holding until the next), on the raw voltage and current, converted once at the
//! end; an input without times counts each frame as the nominal period, and the report says so. The
//! duration of an ESC's frames is the time that passed between them: a clock that steps back or
//! jumps forward ([`Step`](crate::clock::Step)) adds nothing, and the report counts such
//! discontinuities. Times of sources with a wall clock (recordings, serial ports) are shown as ISO
//! 8601 dates in UTC; other sources' times as their seconds.
//!
//! A fault episode is a maximal run of consecutive data frames of one ESC whose status word is
//! not zero; it is reported with its first and last frame (times where the input has them,
//! frame indices and packet numbers always) and the fault bits seen during it.
//!
//! Here: the handler and the report's parts; `accumulate.rs`, what is gathered per frame;
//! `text.rs` and `json.rs`, the report as text and as JSON.

use std::any::Any;

use hwfoc::foc::DataFrame;
use hwfoc::telemetry::{AnyFrame, Conversion, Data, Info, Telemetry};
use hwfoc::units::Linear;
use hwfoc::{Protocol, Quantity, Settings, Status};
use serde_json::{Value, json};

use crate::energy::Energy;
pub use crate::episode::{Episode, Mark};
use crate::escape::Escaped;
use crate::fixed::Fixed;
use crate::handler::LaterPart;
use crate::input::InputError;
use crate::settings::{self, settings_json};
use crate::sources::{Handler, Sources};
use crate::stream::LinkStats;
use crate::time::{self, Clock};
use hwfoc::datalink::LengthByte;

mod accumulate;
mod json;
#[cfg(test)]
mod tests;
mod text;

use accumulate::{Accumulator, TempStats, is_clean, lane, temp_stats};
pub use json::{device_json, link_json};

/// What to tell a user whose wire gave bytes but no frame of any format: the formats, their
/// baud rates and the wiring.
pub static NO_FRAMES: std::sync::LazyLock<String> = std::sync::LazyLock::new(|| {
    "no valid frame of any Hobbywing format (HW-FOC, DataLink V2, Hobbywing V4, Hobbywing V3, \
     HW5): check the baud rate (19200; 115200 for DataLink and HW5) and the wiring"
        .to_string()
});

/// What to tell a user whose wire gave bytes but no frame of `protocol`, forced: the protocol
/// the bytes are of when they were found to be another's (`found`), else its baud rate and the
/// wiring; of a CAN protocol, that the bytes are no CAN frames.
pub fn no_frames_of(protocol: Protocol, found: Option<Protocol>) -> String {
    let instead = found.map(|p| {
        let name = p.name();
        format!("{name} frames (try --protocol {name}, or leave --protocol out)")
    });
    match instead {
        Some(instead) if protocol.is_can() => format!(
            "no {} records: these bytes are not CAN frames but {instead}",
            protocol.title()
        ),
        None if protocol.is_can() => format!(
            "no {} records: these bytes are not CAN frames (read a candump log, a CAN \
             recording or a slcan:/can: bus)",
            protocol.title()
        ),
        Some(instead) => format!(
            "no valid {} frames: these bytes are {instead}",
            protocol.title()
        ),
        None => format!(
            "no valid {} frames: check the baud rate ({}) and the wiring",
            protocol.title(),
            protocol.baud_rate()
        ),
    }
}

/// Why ESC `esc`'s bytes gave no frame, as every output says it: what its input looks like
/// when that is not telemetry (`text, not telemetry`, `looks like a PNG image, not telemetry`:
/// a file given by mistake), on a CAN bus its frames in CAN words (a wrong bit rate where it is
/// the likely cause), else the advice of the protocol forced
/// ([`Sources::force_protocol`]), else what the bytes of a raw input hold
/// ([`Looks::Unframed`](crate::Looks::Unframed): its lead bytes, the baud rates and the
/// wiring), else [`NO_FRAMES`], the advice for a wire (a port, a recording).
pub fn no_frames(sources: &Sources, esc: usize) -> String {
    let looks = sources
        .esc_table()
        .get(esc)
        .and_then(|e| sources.inputs().get(e.input))
        .and_then(|input| input.looks);
    if let Some(looks) = looks.filter(|l| l.is_other_than_telemetry()) {
        return looks.to_string();
    }
    if let Some(c) = sources.link(esc).can() {
        return c.no_status();
    }
    if let Some(protocol) = sources.forced_protocol() {
        let stream = sources.escs().get(esc).map(|e| &e.stream);
        if stream.is_some_and(|s| s.layout() == hwfoc::format::LinkKind::Bus) {
            return format!(
                "no {} records on this CAN bus (its records of other protocols left out)",
                protocol.title()
            );
        }
        return no_frames_of(protocol, stream.and_then(|s| s.found_instead()));
    }
    looks.map_or_else(|| NO_FRAMES.clone(), |looks| looks.to_string())
}

/// The notices of the CAN buses whose records of protocols other than the one forced were left
/// out ([`Sources::force_protocol`]): one per bus, with their number by protocol.
pub fn left_out(sources: &Sources) -> Vec<crate::Notice> {
    let Some(forced) = sources.forced_protocol() else {
        return Vec::new();
    };
    sources
        .escs()
        .iter()
        .enumerate()
        .filter_map(|(i, e)| {
            let place = &sources.esc_table()[i];
            let records = e.stream.left_out();
            (!records.is_empty()).then(|| crate::Notice::LeftOut {
                input: sources.names()[place.input].clone(),
                interface: place.key.port.clone(),
                forced,
                records,
            })
        })
        .collect()
}

/// Fault episodes kept per ESC in detail (all are counted).
const MAX_EPISODES: usize = 10_000;

/// Fault episodes listed per ESC in the text output (`--json` lists all those kept).
const TEXT_EPISODES: usize = 20;

/// Where an ESC is on a CAN bus, as its label says it.
fn can_place(c: &crate::stream::CanLink) -> String {
    match (c.node, c.throttle_channel, c.protocol) {
        (Some(node), Some(channel), _) => format!(" throttle channel {channel}, node {node}"),
        (Some(node), None, Protocol::HwCan) => {
            format!(" node {node} (no GetEscID answer: numbered by node id)")
        }
        (Some(node), None, _) => format!(" node {node}"),
        (None, ..) => String::new(),
    }
}

/// How an ESC is named in messages: its input, and its stream when the input has several
/// (names from a recording [`Escaped`]).
pub fn esc_label(sources: &Sources, esc: usize) -> String {
    let e = &sources.esc_table()[esc];
    let input = &sources.names()[e.input];
    let single = sources
        .inputs()
        .get(e.input)
        .is_none_or(|info| info.escs.len() == 1);
    let channel = match (sources.link(esc).can(), sources.escs()[esc].hub) {
        (Some(c), _) => can_place(c),
        (_, Some((_, channel))) => format!(" channel {channel}"),
        _ if sources.is_hub(esc) => " channel 0".to_string(),
        _ => String::new(),
    };
    let input = Escaped(input);
    let port = &e.key.port;
    if single && *port == *input.0 && channel.is_empty() {
        input.to_string()
    } else if *port == *input.0 {
        format!("{input}{channel} (ESC {esc})")
    } else {
        format!("{input}: {}{channel} (ESC {esc})", Escaped(port))
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

    const TAKES_RUNS: bool = true;

    /// Takes frames as decoded: statistics are kept on the raw integers (see the module
    /// documentation), converted once at the end.
    ///
    /// The usual frame, a data frame without faults outside a fault episode of a known ESC, is
    /// a few integer operations, inlined into the decoder's loop (its fields go from registers
    /// to the accumulator, not through a `Decoded` in memory); every other frame is taken out of
    /// line.
    #[inline(always)]
    fn frame(&mut self, esc: u8, t: Option<f64>, frame: &AnyFrame, settings: &Settings) {
        let esc = usize::from(esc);
        if let AnyFrame::Data(f) = frame
            && let Some(acc) = self.0.get_mut(esc)
            && acc.fast
            && is_clean(f)
            && accumulate::keeps_raw(f.protocol())
        {
            acc.add_clean(t, f);
        } else {
            self.add(esc, t, frame, settings);
        }
    }

    /// The frames of a raw input: the clean ones (as in [`Summary::frame`]) in a loop that
    /// holds the ESC's accumulator, any other out of line.
    #[inline]
    fn untimed_data(&mut self, esc: u8, frames: &[DataFrame], settings: &Settings) {
        let esc = usize::from(esc);
        let mut i = 0;
        while i < frames.len() {
            if let Some(acc) = self.0.get_mut(esc)
                && acc.fast
            {
                i += acc.add_clean_run(&frames[i..]);
            }
            if let Some(f) = frames.get(i) {
                self.add(esc, None, &AnyFrame::Data(Data::HwFoc(*f)), settings);
                i += 1;
            }
        }
    }

    /// A summary of its own for the later half of a large raw file: what it gathers adds up
    /// with this one's exactly ([`Summary::join`]).
    fn fork(&self) -> Option<Box<dyn LaterPart>> {
        Some(Box::new(Part(Summary::new())))
    }

    /// Takes what the summary made by [`Summary::fork`] gathered (anything else is ignored).
    fn join(&mut self, later: Box<dyn Any + Send>) {
        let Ok(later) = later.downcast::<Part>() else {
            return;
        };
        for (esc, acc) in later.0.0.into_iter().enumerate() {
            if self.0.len() <= esc {
                self.0.resize_with(esc + 1, Accumulator::default);
            }
            self.0[esc].join(acc);
        }
    }
}

/// The summary of the later half of a raw file ([`Summary::fork`]).
struct Part(Summary);

impl LaterPart for Part {
    fn frame(&mut self, esc: u8, frame: &AnyFrame, settings: &Settings) {
        self.0.frame(esc, None, frame, settings);
    }

    fn untimed_data(&mut self, esc: u8, frames: &[DataFrame], settings: &Settings) {
        self.0.untimed_data(esc, frames, settings);
    }

    fn into_any(self: Box<Self>) -> Box<dyn Any + Send> {
        self
    }
}

impl Summary {
    /// Any frame of ESC `esc`.
    #[cold]
    #[inline(never)]
    fn add(&mut self, esc: usize, t: Option<f64>, frame: &AnyFrame, settings: &Settings) {
        if self.0.len() <= esc {
            self.0.resize_with(esc + 1, Accumulator::default);
        }
        self.0[esc].add(t, frame, settings);
    }
}

/// The summary, ready to be printed: [`Report::text`] or [`Report::json`].
pub struct Report<'a> {
    sources: &'a Sources,
    /// The settings of ESCs without settings of their own.
    settings: &'a Settings,
    accs: &'a [Accumulator],
}

/// One row of the field table: name, unit, min/max/mean if there were frames, and whether the
/// ESC's protocol carries the quantity at all.
type FieldRow = (&'static str, &'static str, Option<[f64; 3]>, bool);

/// One ESC's part of the report.
struct EscReport<'a> {
    index: usize,
    label: String,
    stream: &'a str,
    input: &'a str,
    stats: LinkStats,
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
            .esc_table()
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
                    stream: &esc.key.port,
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

impl EscReport<'_> {
    /// Charge, energy and power, converted from the raw units under the settings.
    /// `None` for an ESC without data frames, or whose protocol sends no voltage or current.
    fn energy(&self) -> Option<Energy> {
        if let Some(values) = &self.acc.values {
            return (values.powered > 0).then(|| self.acc.energy());
        }
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

    /// Data frames of the ESC: its link's, or when its stream changed format, every format's
    /// (the link counts the format read last).
    fn data_frames(&self) -> u64 {
        let formats = self.acc.formats();
        match formats.len() {
            0 | 1 => u64::from(self.stats.frames()),
            _ => formats.iter().map(|(_, n)| n).sum(),
        }
    }

    /// Data frames per second between the first and the last frame.
    fn frame_rate(&self) -> Option<f64> {
        let d = self.duration()?;
        (d > 0.0).then(|| (self.acc.tally.frames - 1) as f64 / d)
    }

    /// Frames lost judged from their times, for a format without packet counter whose frames
    /// have times (HW5).
    fn timed_loss(&self) -> Option<accumulate::TimedLoss> {
        let values = self.acc.values.as_ref()?;
        (!self.stats.counts_packets() && self.acc.first_t.is_some()).then_some(values.loss)
    }

    /// The protocol of the ESC's frames (of its first data frame), if it sent one.
    fn protocol(&self) -> Option<Protocol> {
        self.acc.sample.map(|s| s.protocol())
    }

    fn fields(&self) -> Vec<FieldRow> {
        if let (Some(values), Some(protocol)) = (&self.acc.values, self.protocol()) {
            return Quantity::ALL
                .into_iter()
                .map(|q| {
                    let carried = protocol.carries(q);
                    let stats = values.range(q).stats().filter(|_| carried);
                    (q.name(), q.unit(), stats, carried)
                })
                .collect();
        }
        // The protocol's conversions, applied to the raw min, max and mean.
        let field = |q: Quantity| {
            let stats = match lane(q) {
                Some(lane) => {
                    let (range, n) = self.acc.tally.ranges.get(lane, self.acc.tally.frames);
                    let linear = self.linear(q);
                    linear.and_then(|linear| range.convert(n, |x| linear.to_f64(x)))
                }
                None => self.temperature(q).range,
            };
            (q.name(), q.unit(), stats, self.conversion(q).is_some())
        };
        Quantity::ALL.into_iter().map(field).collect()
    }

    /// The statistics of `quantity` from the histogram of its codes: the MOSFET's and the
    /// capacitor's temperatures; none for a quantity the summary keeps no histogram of.
    fn temperature(&self, quantity: Quantity) -> TempStats {
        let (codes, uncoded) = match quantity {
            Quantity::MosTemp => (&self.acc.mos_codes, self.acc.uncoded[0]),
            Quantity::CapTemp => (&self.acc.cap_codes, self.acc.uncoded[1]),
            _ => return TempStats::default(),
        };
        match self.conversion(quantity) {
            // Every data frame's temperature is in the histogram: its statistics are whole.
            Some(conversion) if uncoded == 0 => temp_stats(codes, conversion),
            // A protocol that does not send it, or not as a code of 0..=255: no statistics
            // rather than those of some frames.
            _ => TempStats::default(),
        }
    }

    /// Each fault of the ESC's protocol seen: its name, description and frames.
    fn faults(&self) -> impl Iterator<Item = (&'static str, &'static str, u64)> + '_ {
        let protocol = self.protocol().unwrap_or(Protocol::HwFoc);
        (0..16u8).filter_map(move |bit| {
            let n = self.acc.fault_frames[usize::from(bit)];
            let name = protocol.fault_name(bit)?;
            (n > 0).then(|| (name, protocol.fault_description(bit).unwrap_or(name), n))
        })
    }

    /// The names of the faults set in `status`, a fault word of the ESC's protocol.
    fn fault_names(&self, status: Status) -> Vec<&'static str> {
        let protocol = self.protocol().unwrap_or(Protocol::HwFoc);
        protocol.fault_names(status).collect()
    }
}

fn percent(part: u64, whole: u64) -> f64 {
    if whole == 0 {
        0.0
    } else {
        part as f64 * 100.0 / whole as f64
    }
}
