//! Several inputs, one decoding [`Stream`] per ESC, their records handed on in time order.
//!
//! Each stream of each input is one ESC, numbered input by input in the order given (a file
//! has one stream, a recording one per interface, a set of serial ports one per port; an
//! input's streams are numbered when its first batch is read, all the interfaces it has
//! declared by then in their order, any declared later when they first appear), with one
//! exception: recordings name the port of each interface, and the interfaces of recordings
//! given together that name the same port are one ESC, one continuous stream, its bytes in the
//! order of their times whatever the order the files are given in (the files of a rotated
//! recording decode exactly as their bytes concatenated in time order: a frame split between
//! two files is whole). Where two inputs hold the same port's bytes of the same time (the same
//! recording given twice, a recording and a copy of part of it), that time is decoded once,
//! from the input that reached it first, and the other is told of it
//! ([`crate::Notice::Overlap`]).
//!
//! # Time order
//!
//! Inputs given one after another whose clocks are alike (see [`crate::time::Clock`]:
//! recordings, or logic-analyser CSV exports) are read together, and their records of every
//! ESC are handed on in time order (`t_s`, then ESC number for equal times): a two-ESC
//! recording gives its ESCs' records interleaved, several recordings are merged by time. Each
//! ESC's own records always keep their stream's order. Raw byte files (no times) and serial
//! ports (live: records are handed on as they arrive, which is their order) are read alone, in
//! the order given, as is each run of inputs of one clock after another run.
//!
//! The files of this module: `numbering.rs` says which stream of which input is which ESC (a
//! hub's channels by `esc_numbers.rs`, as live ports number them); `merge.rs` hands frames on
//! in time order (a heap of the batches read ahead, a queue per ESC, the bytes two inputs hold
//! of one port left out once); `mod.rs` reads the inputs, alone or together.

mod can_plan;
#[cfg(test)]
mod fleet_tests;
mod merge;
mod numbering;
mod split;
#[cfg(test)]
pub(crate) mod tests;

use std::collections::{HashMap, VecDeque};

use hwfoc::datalink;
use hwfoc::foc::DataFrame;
use hwfoc::format::LinkKind;
use hwfoc::telemetry::{AnyFrame, Data};
use hwfoc::{Protocol, Settings};

use crate::esc_table::{EscTable, Recording};
pub use crate::handler::Handler;
use crate::handler::LaterPart;
use crate::input::{Batch, Input, InputError, InputFormat};
use crate::notice::Notice;
use crate::settings::SettingsMap;
use crate::stream::{BusPlan, LinkStats, Stream};
use crate::time::Clock;

pub use self::merge::MAX_QUEUED;
use self::merge::Queue;
use self::numbering::{Deliver, Hub, Pending, route};
use self::split::{Later, SPLIT_MIN};

/// HW-FOC data frames without times held at most before they are handed on together (18
/// bytes each: within the L1 cache).
const HELD: usize = 512;

/// Data frames without times, held to be handed on together ([`feed_runs`]; a `Vec`'s length and
/// capacity checks cost a fifth of the decoder's loop).
struct Held {
    frames: [DataFrame; HELD],
}

/// Batches shorter than this come from a live source: what they produce is passed on at once.
const LIVE_BATCH: usize = 4096;

/// One ESC's decoding: a stream of one input (which ESC it is: [`Sources::esc_table`]).
#[derive(Debug)]
pub struct Esc {
    /// Its decoder and receive times; its link statistics. (Behind a DataLink hub, the hub's
    /// stream is that of the ESC on channel 0; the others' is never fed: see [`Sources::link`].)
    pub stream: Stream,
    /// Behind a DataLink hub: the ESC whose stream carries this one's frames, and its channel.
    pub hub: Option<(usize, u8)>,
}

/// What is known about an input once it has been read.
#[derive(Debug, Clone)]
pub struct InputInfo {
    /// The input as named on the command line.
    pub name: String,
    /// Its detected format.
    pub format: InputFormat,
    /// Bytes a logic analyser flagged with a parity or framing error.
    pub flagged_bytes: u64,
    /// Bytes read from it.
    pub bytes: u64,
    /// The ESC index of each of its streams, in stream order.
    pub escs: Vec<usize>,
    /// What its bytes look like, read to its end, when they are not telemetry (a raw input's:
    /// text, zeros, another file format).
    pub looks: Option<crate::input::Looks>,
    /// The earlier input (index) that holds the same bytes, where this one is a copy: it was
    /// not read again.
    pub duplicate_of: Option<usize>,
}

/// The inputs of a command and the ESCs found in them.
pub struct Sources {
    settings: SettingsMap,
    /// The settings of each ESC found, looked up once.
    esc_settings: Vec<Settings>,
    pending: Vec<Input>,
    names: Vec<String>,
    /// The first input with frames of an ESC past the last ESC number, not handed on: the run
    /// fails ([`InputError::TooManyEscs`]) once the others are.
    unnumbered: Option<usize>,
    read: Vec<InputInfo>,
    escs: Vec<Esc>,
    /// Which ESC is which (`esc_table.rs`).
    table: EscTable,
    /// Whether the recordings given are one (`--join`): their ports go on by name.
    join: bool,
    need_timing: bool,
    /// The ESC of each channel of each stream found to come from a DataLink hub, by the ESC
    /// of its stream.
    hubs: HashMap<usize, Hub>,
    /// The slots of the ESCs of each CAN bus read ahead (`can_plan.rs`), by its stream's name.
    buses: HashMap<(Recording, String), BusPlan>,
    /// The ESCs of each input's streams numbered before it is read, by input.
    numbered: Vec<Vec<Option<usize>>>,
    queue: Queue,
    /// By ESC: how many inputs not at their end have a stream of it.
    readers: Vec<u32>,
    /// By ESC: the input (index) whose bytes its stream was fed last, and the time of the last
    /// of them.
    fed: Vec<Option<(usize, f64)>>,
    /// By ESC: the times of the first and the last byte its stream was fed (inputs with
    /// times), to tell of ports named alike in other recordings.
    span: Vec<Option<(f64, f64)>>,
    /// By input: the earlier input that holds the same bytes, where it is a copy.
    duplicates: Vec<Option<usize>>,
    /// The one protocol read, when a user forced one.
    forced: Option<Protocol>,
    /// Data frames without times not handed on yet (see [`HELD`]).
    held: Box<Held>,
    /// The smallest raw file read in two halves at once (`split.rs`).
    split_min: u64,
    /// Raw files read in two halves at once whose halves were joined (for the tests).
    #[cfg(test)]
    joined: u32,
}

impl Sources {
    /// The inputs, opened, in command-line order; data frames become records under
    /// `settings`: one [`Settings`] for every ESC, or a [`SettingsMap`] by ESC and port.
    pub fn new(inputs: Vec<Input>, settings: impl Into<SettingsMap>) -> Sources {
        Sources {
            settings: settings.into(),
            names: inputs.iter().map(|i| i.name().to_string()).collect(),
            unnumbered: None,
            pending: inputs,
            read: Vec::new(),
            escs: Vec::new(),
            table: EscTable::default(),
            join: false,
            need_timing: false,
            hubs: HashMap::new(),
            buses: HashMap::new(),
            numbered: Vec::new(),
            esc_settings: Vec::new(),
            queue: Queue::default(),
            readers: Vec::new(),
            fed: Vec::new(),
            span: Vec::new(),
            duplicates: Vec::new(),
            forced: None,
            split_min: SPLIT_MIN,
            #[cfg(test)]
            joined: 0,
            held: Box::new(Held {
                frames: [DataFrame::default(); HELD],
            }),
        }
    }

    /// Reads protocol `protocol` only, instead of every protocol the bytes may hold (the bytes of
    /// any other are skipped bytes): for the streams of the ESCs found from now on, so call it
    /// before [`Sources::run`].
    pub fn force_protocol(&mut self, protocol: Protocol) {
        self.forced = Some(protocol);
    }

    /// Reads the recordings given as one (`--join`): the streams of recordings that name the
    /// same port are one ESC, its bytes in time order, whatever recording each file names
    /// (files another program wrote name none). Without it, only the files of one recording
    /// (the same [`RecordingId`](crate::pcapng::RecordingId), as every file of one `hwfoc
    /// record` run carries) go on from one to the next; other files are ESCs of their own.
    pub fn join_recordings(&mut self) {
        self.join = true;
    }

    /// The protocol forced by [`Sources::force_protocol`], if any.
    pub fn forced_protocol(&self) -> Option<Protocol> {
        self.forced
    }

    /// Makes an input without receive times an error ([`InputError::NoTiming`]): raw-byte inputs
    /// are refused at once, before anything is read, and any other source as soon as it hands
    /// out bytes without times.
    pub fn require_timing(&mut self) -> Result<(), InputError> {
        self.need_timing = true;
        match self
            .pending
            .iter()
            .find(|i| i.format().clock() == Clock::None)
        {
            Some(raw) => Err(InputError::NoTiming {
                input: raw.name().to_string(),
            }),
            None => Ok(()),
        }
    }

    /// The conversion settings of the records of ESCs without settings of their own.
    pub fn settings(&self) -> &Settings {
        self.settings.default_settings()
    }

    /// The conversion settings of ESC `esc` (default settings for an ESC not found yet).
    pub fn esc_settings(&self, esc: usize) -> Settings {
        match self.esc_settings.get(esc) {
            Some(settings) => *settings,
            None => {
                let name = self.table.get(esc).map_or("", |e| e.key.port.as_str());
                self.settings.get(esc, name)
            }
        }
    }

    /// The names of all inputs, in command-line order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The formats of the inputs not read yet (before [`Sources::run`]: all of them), in
    /// command-line order.
    pub fn formats(&self) -> impl Iterator<Item = (&str, InputFormat)> {
        self.pending.iter().map(|i| (i.name(), i.format()))
    }

    /// The inputs read so far, in command-line order.
    pub fn inputs(&self) -> &[InputInfo] {
        &self.read
    }

    /// The clock of the inputs read so far, if they all have the same one (see
    /// [`crate::time::Clock`]): whether their times can be shown as dates.
    pub fn clock(&self) -> Option<Clock> {
        let first = self.read.first()?.format.clock();
        self.read
            .iter()
            .all(|i| i.format.clock() == first)
            .then_some(first)
    }

    /// The ESCs found so far, by index: their decoding.
    pub fn escs(&self) -> &[Esc] {
        &self.escs
    }

    /// Which ESC is which: each ESC's key (recording, port, place) and input, by index.
    pub fn esc_table(&self) -> &EscTable {
        &self.table
    }

    /// The DataLink hubs found: the ESC whose stream each came in (its channel 0), and the
    /// hub link's statistics.
    pub fn hubs(&self) -> impl Iterator<Item = (usize, datalink::Stats)> + '_ {
        let mut owners: Vec<usize> = self.hubs.keys().copied().collect();
        owners.sort_unstable();
        owners
            .into_iter()
            .filter_map(|esc| Some((esc, *self.escs[esc].stream.hub()?)))
    }

    /// Whether ESC `esc` is a channel of a DataLink hub.
    pub fn is_hub(&self, esc: usize) -> bool {
        self.escs[esc].hub.is_some() || self.hubs.contains_key(&esc)
    }

    /// The link statistics of ESC `esc` (behind a DataLink hub, its channel's and the hub
    /// link's).
    pub fn link(&self, esc: usize) -> LinkStats {
        match self.escs[esc].hub {
            Some((owner, channel)) => self.escs[owner].stream.link(channel),
            None => self.escs[esc].stream.stats(),
        }
    }

    /// Whether any ESC's bytes gave a data frame (`decode`, `summary` and `plot` fail alike
    /// when none did).
    pub fn any_data_frame(&self) -> bool {
        (0..self.escs.len()).any(|esc| self.link(esc).frames() > 0)
    }

    /// The error of a run in which no input held a data frame ([`InputError::NoDataFrames`],
    /// naming the inputs); `None` when one did.
    pub fn nothing_decoded(&self) -> Option<InputError> {
        (!self.any_data_frame()).then(|| InputError::NoDataFrames {
            inputs: self.names().join(", "),
        })
    }

    /// How many raw files were read in two halves at once, their halves joined (`split.rs`).
    #[cfg(test)]
    pub(crate) fn joined_halves(&self) -> u32 {
        self.joined
    }

    /// Reads raw files of at least `bytes` bytes in two halves at once, for a handler that can
    /// be forked (every such file of 64 MiB and more, by default).
    #[cfg(test)]
    pub(crate) fn split_at_least(&mut self, bytes: u64) {
        self.split_min = bytes;
    }

    /// The most frames that waited at once in the time-order queue (at most [`MAX_QUEUED`]).
    pub fn peak_queued(&self) -> usize {
        self.queue.peak
    }

    /// Reads every input to its end, handing each frame (in time order, see the module
    /// documentation) and the end of each batch to `handler`.
    ///
    /// On an input error, the frames of the bytes before it are still decoded (every stream is
    /// finished), and the error is returned without reading further.
    pub fn run<H: Handler>(&mut self, handler: &mut H) -> Result<(), H::Error> {
        let mut inputs: VecDeque<Input> = std::mem::take(&mut self.pending).into();
        let base = self.read.len();
        self.duplicates.resize(base, None);
        self.duplicates.extend(duplicates(&inputs, base));
        self.plan_buses(&mut inputs, base);
        self.number_inputs(&inputs);
        let mut result = Ok(());
        while let Some(first) = inputs.front() {
            let clock = first.format().clock();
            let merged = first.format().is_merged_in_time();
            let n = if merged {
                inputs
                    .iter()
                    .take_while(|i| i.format().is_merged_in_time() && i.format().clock() == clock)
                    .count()
            } else {
                1
            };
            let run: Vec<Input> = inputs.drain(..n).collect();
            let more_recordings = inputs.iter().any(|i| i.format().has_recorded_ports());
            result = if merged {
                self.read_together(run, more_recordings, handler)
            } else {
                run.into_iter()
                    .try_for_each(|input| self.read_alone(input, handler))
            };
            if result.is_err() {
                break;
            }
        }
        for esc in 0..self.escs.len() {
            self.finish(esc);
        }
        self.release(f64::INFINITY, handler);
        // A hub's channels that carried an ESC are ESCs of its input; a CAN bus's stream is
        // one only if an ESC of its own was at its place 0.
        for esc in 0..self.escs.len() {
            let frames = self.link(esc).frames() > 0;
            // (An input whose reading failed has no entry.)
            let Some(read) = self.read.get_mut(self.table[esc].input) else {
                continue;
            };
            if self.escs[esc].hub.is_some() && frames {
                read.escs.push(esc);
                read.escs.sort_unstable();
            } else if self.escs[esc].stream.layout() == LinkKind::Bus && !frames {
                read.escs.retain(|&e| e != esc);
            }
        }
        result?;
        if let Some(input) = self.unnumbered {
            return Err(InputError::TooManyEscs {
                input: self.names[input].clone(),
            }
            .into());
        }
        handler.end_batch(false)
    }

    /// Ends the stream of ESC `esc`, its last frames to the queue: a frame cut off at the end
    /// is dropped, frames inside it are still found. Harmless on a stream already finished.
    fn finish(&mut self, esc: usize) {
        let queue = &mut self.queue;
        let hub = self.hubs.get(&esc);
        let mut pending = Vec::new();
        self.escs[esc].stream.finish(|t, channel, d| {
            if let Some((esc, _)) = route(esc, hub, t, channel, d, &mut pending) {
                queue.push(esc, t, d);
            }
        });
        self.deliver(esc, pending, &mut Deliver::<()>::Queue);
    }

    /// Notes what is known of an input at its end; its ESCs have one reader fewer.
    fn close(&mut self, input: &Input, index: usize, escs: &[Option<usize>], bytes: u64) {
        let info = &mut self.read[index];
        info.flagged_bytes = input.flagged_bytes();
        info.bytes = bytes;
        info.looks = input.looks();
        info.escs = escs.iter().flatten().copied().collect();
        for &esc in escs.iter().flatten() {
            self.readers[esc] -= 1;
        }
    }

    /// Whether input `index` holds the same bytes as an earlier one: then it is noted so and
    /// told, and not read.
    fn skip_duplicate(&mut self, input: &mut Input, index: usize) -> bool {
        let Some(earlier) = self.duplicates.get(index).copied().flatten() else {
            return false;
        };
        self.read[index].duplicate_of = Some(earlier);
        input.tell(Notice::Duplicate {
            input: self.names[index].clone(),
            earlier: self.names[earlier].clone(),
        });
        true
    }

    /// Notes an input as begun, in command-line order.
    fn open(&mut self, input: &Input) -> usize {
        self.read.push(InputInfo {
            name: input.name().to_string(),
            format: input.format(),
            flagged_bytes: 0,
            bytes: 0,
            escs: Vec::new(),
            looks: None,
            duplicate_of: None,
        });
        self.read.len() - 1
    }

    /// Reads an input without times (or a live one) to its end, its frames handed on as they
    /// are decoded: the path of `summary` on a raw file, kept to the decoder's loop. A large
    /// raw file is read in two halves at once for a handler that can be forked
    /// ([`Handler::fork`], `split.rs`), else read ahead for a handler that takes runs.
    fn read_alone<H: Handler>(
        &mut self,
        mut input: Input,
        handler: &mut H,
    ) -> Result<(), H::Error> {
        let index = self.open(&input);
        if self.skip_duplicate(&mut input, index) {
            return Ok(());
        }
        let part = input
            .raw_file_len()
            .is_some_and(|len| split::AVAILABLE && len >= self.split_min)
            .then(|| handler.fork())
            .flatten();
        input.read_ahead(H::TAKES_RUNS && part.is_none());
        let mut escs = self.numbered(index);
        let mut bytes = 0;
        let mut split = Split::Planned(part);
        let result = self.read_input(
            &mut input, index, &mut escs, &mut bytes, handler, &mut split,
        );
        self.number_streams(&input, index, &mut escs);
        // A recorded port's stream may go on in the next recording: it is finished at the
        // end of the run. Other streams end with their input.
        if !input.format().has_recorded_ports() {
            for &esc in escs.iter().flatten() {
                self.finish(esc);
            }
        }
        self.release(f64::INFINITY, handler);
        self.close(&input, index, &escs, bytes);
        result?;
        handler.end_batch(false)
    }

    fn read_input<H: Handler>(
        &mut self,
        input: &mut Input,
        index: usize,
        escs: &mut Vec<Option<usize>>,
        bytes: &mut u64,
        handler: &mut H,
        split: &mut Split,
    ) -> Result<(), H::Error> {
        loop {
            let Some(batch) = input.next_batch()? else {
                return Ok(());
            };
            if self.need_timing && batch.times.is_none() {
                return Err(InputError::NoTiming {
                    input: self.names[index].clone(),
                }
                .into());
            }
            let (stream, len) = (batch.stream, batch.bytes.len());
            let from = *bytes;
            *bytes += len as u64;
            // The batch borrows the input: its stream's ESC is found first, by a second look.
            let _ = batch;
            let esc = self.esc_of(input, index, stream, escs)?;
            if let Split::Planned(part) = split {
                // The file is open once its first batch is read: its later half is read from
                // now on, by a part of the handler.
                let later = part
                    .take()
                    .zip(input.later_half())
                    .and_then(|(part, (file, len))| {
                        let id = u8::try_from(esc).ok()?;
                        let forced = self.escs[esc].stream.forced_protocol();
                        Later::start(file, len, forced, part, id, self.esc_settings(esc))
                    });
                *split = later.map_or(Split::None, Split::Reading);
            }
            let Some(batch) = input.current_batch() else {
                continue;
            };
            let mut pending = Vec::new();
            let cut = match split {
                Split::Reading(later) => later.cut(from, len),
                _ => None,
            };
            let (before, after) = batch.bytes.split_at(cut.unwrap_or(len));
            let times = batch.times.map(|t| t.split_at(before.len()));
            let part = |bytes, times| Batch {
                bytes,
                times,
                stream,
            };
            self.feed(esc, part(before, times.map(|t| t.0)), &mut pending, handler);
            if cut.is_some()
                && let Split::Reading(later) = std::mem::replace(split, Split::None)
                && let Some(later_bytes) = self.join_later(esc, later, handler)
            {
                *bytes = from + before.len() as u64 + later_bytes;
                self.deliver(esc, pending, &mut Deliver::Handler(handler));
                return handler.end_batch(false);
            }
            if !after.is_empty() {
                self.feed(esc, part(after, times.map(|t| t.1)), &mut pending, handler);
            }
            self.deliver(esc, pending, &mut Deliver::Handler(handler));
            self.tell_can_clashes(input, esc);
            handler.end_batch(len < LIVE_BATCH)?;
        }
    }

    /// Decodes a batch of ESC `esc`'s stream, its frames to `handler` (or, for hub channels not
    /// numbered yet, to `pending`).
    #[inline(always)]
    fn feed<H: Handler>(
        &mut self,
        esc: usize,
        batch: Batch<'_>,
        pending: &mut Vec<Pending>,
        handler: &mut H,
    ) {
        let settings = &self.esc_settings(esc);
        let mut to = ToHandler {
            handler,
            own: esc,
            id: u8::try_from(esc).unwrap_or(u8::MAX),
            settings,
            hub: self.hubs.get(&esc),
            pending,
        };
        feed_runs(&mut self.escs[esc].stream, batch, &mut self.held, &mut to);
    }

    /// Joins the later half of ESC `esc`'s raw file, read by `later` from where its stream has
    /// been fed to (`split.rs`): the bytes it read, or `None` (and it is dropped) where it
    /// cannot be joined: the stream holds bytes there, has carried hub frames, or the later
    /// half's reader could not go to the end.
    fn join_later<H: Handler>(&mut self, esc: usize, later: Later, handler: &mut H) -> Option<u64> {
        let stream = &mut self.escs[esc].stream;
        if stream.buffered() > 0 || stream.hub().is_some() {
            return None;
        }
        let done = later.finish()?;
        if !stream.then(&done.stream, done.first_packet) {
            return None;
        }
        handler.join(done.part.into_any());
        #[cfg(test)]
        {
            self.joined += 1;
        }
        Some(done.bytes)
    }
}

/// For each of `inputs` (numbered from `base`), the earlier one that holds the same bytes, if
/// any: only regular files of the same length are compared, block by block up to the first
/// that differs (the files of a rotated series differ in their first block).
fn duplicates(inputs: &VecDeque<Input>, base: usize) -> Vec<Option<usize>> {
    let mut by_len: HashMap<u64, Vec<usize>> = HashMap::new();
    for (k, input) in inputs.iter().enumerate() {
        if let Some(len) = input.file_len() {
            by_len.entry(len).or_default().push(k);
        }
    }
    let mut found = vec![None; inputs.len()];
    for same_len in by_len.values().filter(|v| v.len() > 1) {
        for (i, &k) in same_len.iter().enumerate() {
            found[k] = same_len[..i]
                .iter()
                .find(|&&j| found[j].is_none() && inputs[k].same_bytes_as(&inputs[j]))
                .map(|&j| base + j);
        }
    }
    found
}

/// Where [`feed_runs`] hands a stream's frames.
trait Takes {
    /// Whether the stream's own data frames without times are handed on in runs
    /// ([`Takes::run`]), or each as any other frame ([`Takes::other`]).
    const RUNS: bool;

    /// Data frames of the stream's own ESC without receive times, one after another.
    fn run(&mut self, frames: &[DataFrame]);
    /// Any other frame (with a receive time, of a hub's channel, or device information).
    fn other(&mut self, t: Option<f64>, channel: Option<u8>, frame: &AnyFrame);
}

/// Decodes `batch` with `stream`: for a handler that takes runs ([`Takes::RUNS`]), the
/// stream's own data frames without times are held in `held` and handed on together
/// ([`Takes::run`]), in order with every other frame ([`Takes::other`]); the decoder's loop
/// only copies a frame's fields, the handler's loop takes them. How many are held is a local,
/// kept in a register: a count stored with the frames was loaded back for every frame.
#[inline(always)]
fn feed_runs<T: Takes>(stream: &mut Stream, batch: Batch<'_>, held: &mut Held, to: &mut T) {
    let held = &mut held.frames;
    let mut n = 0;
    stream.feed(
        batch,
        #[inline(always)]
        |t, channel, d| {
            if let (true, None, None, AnyFrame::Data(Data::HwFoc(f))) = (T::RUNS, t, channel, d) {
                if n == HELD {
                    to.run(held);
                    n = 0;
                }
                if let Some(slot) = held.get_mut(n) {
                    *slot = *f;
                    n += 1;
                }
                return;
            }
            if n > 0 {
                to.run(&held[..n]);
                n = 0;
            }
            to.other(t, channel, d);
        },
    );
    if n > 0 {
        to.run(&held[..n]);
    }
}

/// A handler as [`feed_runs`] hands it frames: those of hub channels routed to their ESCs.
struct ToHandler<'a, 'h, H> {
    handler: &'a mut H,
    /// The stream's ESC, and its number as handlers take it.
    own: usize,
    id: u8,
    settings: &'a Settings,
    hub: Option<&'h Hub>,
    pending: &'a mut Vec<Pending>,
}

impl<H: Handler> Takes for ToHandler<'_, '_, H> {
    const RUNS: bool = H::TAKES_RUNS;

    #[inline(always)]
    fn run(&mut self, frames: &[DataFrame]) {
        // After a hub frame waiting for its channel's number: in order, behind it.
        if !self.pending.is_empty() {
            let frames = frames.iter().map(|f| AnyFrame::Data(Data::HwFoc(*f)));
            self.pending.extend(frames.map(|f| (None, None, f)));
            return;
        }
        self.handler.untimed_data(self.id, frames, self.settings);
    }

    #[inline(always)]
    fn other(&mut self, t: Option<f64>, channel: Option<u8>, d: &AnyFrame) {
        // After a hub frame waiting for its channel's number: in order, behind it (a file read
        // in one batch gave the hub's frames after every later ESC frame of the batch).
        if !self.pending.is_empty() {
            self.pending.push((t, channel, *d));
            return;
        }
        match route(self.own, self.hub, t, channel, d, self.pending) {
            Some((_, None)) => self.handler.frame(self.id, t, d, self.settings),
            Some((esc, Some(settings))) => {
                if let Ok(esc) = u8::try_from(esc) {
                    self.handler.frame(esc, t, d, settings);
                }
            }
            None => {}
        }
    }
}

/// Whether and how an input is read in two halves at once (`split.rs`).
enum Split {
    /// Not.
    None,
    /// Once its file is open, by this part of the handler.
    Planned(Option<Box<dyn LaterPart>>),
    /// The later half being read.
    Reading(Later),
}
