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
//! ([`crate::notice::Notice::Overlap`]).
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
//! How, in bounded memory: each input's first batch is read in the order given (its streams
//! are numbered then); a file is then closed and read again from its start when its turn comes
//! ([`Input::rewind`]), so that a year of rotated recordings holds a few files open, not
//! thousands. Each input being read holds one batch read ahead (an input's batches come in
//! order of their first byte's time: a recording hands out each window's ports in that order);
//! the input whose batch is earliest is decoded next, and its frames wait in a queue per ESC.
//! A frame is handed on once no input can still give an earlier one: once it is earlier than
//! every input's batch read ahead and than the first byte any decoder holds of a frame still
//! arriving. So the queue holds about one batch of each input being read: a recording's batch
//! is at most 10 s of its ports (200 frames per port), a CSV export's 64 KiB of rows. Should
//! the queue grow past [`MAX_QUEUED`] frames (times that go backwards), its earliest frame is
//! handed on at once, so memory stays bounded whatever the inputs hold; order is then kept as
//! far as the queue allows.

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap, VecDeque};

use hwfoc::datalink::{CHANNELS, DatalinkStats};
use hwfoc::{Decoded, Settings};

pub use crate::handler::Handler;
use crate::input::{Batch, Input, InputError, InputFormat};
use crate::notice::Notice;
use crate::settings::SettingsMap;
use crate::stream::{EscLink, Stream};
use crate::time::Clock;

/// Batches shorter than this come from a live source: what they produce is passed on at once.
const LIVE_BATCH: usize = 4096;

/// How many ESCs the record's `esc` column (a `u8`) can number.
const MAX_ESCS: usize = 256;

/// The most frames waiting in the time-order queue: past it, the earliest is handed on at once
/// (about 7 MB of frames; a recording of 256 ports needs at most 51 200).
pub const MAX_QUEUED: usize = 1 << 16;

/// One ESC: a stream of one input.
#[derive(Debug)]
pub struct Esc {
    /// Index of its input in [`Sources::inputs`].
    pub input: usize,
    /// Name of the stream: the port it was recorded from, or the input's name.
    pub name: String,
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
}

/// The inputs of a command and the ESCs found in them.
pub struct Sources {
    settings: SettingsMap,
    /// The settings of each ESC found, looked up once.
    esc_settings: Vec<Settings>,
    pending: Vec<Input>,
    names: Vec<String>,
    read: Vec<InputInfo>,
    escs: Vec<Esc>,
    need_timing: bool,
    /// The ESC of each port named by a recording's interface so far.
    ports: HashMap<String, usize>,
    /// The ESC of each channel of each stream found to come from a DataLink hub, by the ESC
    /// of its stream.
    hubs: HashMap<usize, Hub>,
    /// The ESCs of each input's streams numbered before it is read, by input.
    numbered: Vec<Vec<Option<usize>>>,
    queue: Queue,
    /// By ESC: how many inputs not at their end have a stream of it.
    readers: Vec<u32>,
    /// By ESC: the input (index) whose bytes its stream was fed last, and the time of the last
    /// of them.
    fed: Vec<Option<(usize, f64)>>,
}

/// An input being read in a run of inputs read together.
struct Reading {
    input: Input,
    /// Its index among all inputs.
    index: usize,
    /// The ESC of each of its streams seen so far.
    escs: Vec<Option<usize>>,
    bytes: u64,
    /// Its batch read ahead: the first byte's time and the ESC; `None` once at its end.
    ahead: Option<(f64, usize)>,
    /// The batch read ahead was let go with the file, to be read again when its turn comes
    /// (see [`Input::rewind`]).
    parked: bool,
    /// Bytes not decoded because an earlier input gave the same port's bytes of that time.
    overlaps: Vec<Overlap>,
}

/// Bytes of one ESC of an input that an earlier input of the same port gave already.
struct Overlap {
    esc: usize,
    /// The input that gave them.
    earlier: usize,
    /// The time of the first and of the last.
    from: f64,
    to: f64,
}

impl Sources {
    /// The inputs, opened, in command-line order; data frames become records under
    /// `settings`: one [`Settings`] for every ESC, or a [`SettingsMap`] by ESC and port.
    pub fn new(inputs: Vec<Input>, settings: impl Into<SettingsMap>) -> Sources {
        Sources {
            settings: settings.into(),
            names: inputs.iter().map(|i| i.name().to_string()).collect(),
            pending: inputs,
            read: Vec::new(),
            escs: Vec::new(),
            need_timing: false,
            ports: HashMap::new(),
            hubs: HashMap::new(),
            numbered: Vec::new(),
            esc_settings: Vec::new(),
            queue: Queue::default(),
            readers: Vec::new(),
            fed: Vec::new(),
        }
    }

    /// Makes an input without receive times an error ([`InputError::NoTiming`]): raw-byte inputs
    /// are refused at once, before anything is read, and any other source as soon as it hands
    /// out bytes without times.
    pub fn require_timing(&mut self) -> Result<(), InputError> {
        self.need_timing = true;
        match self.pending.iter().find(|i| i.format() == InputFormat::Raw) {
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
                let name = self.escs.get(esc).map_or("", |e| e.name.as_str());
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

    /// The ESCs found so far, by index.
    pub fn escs(&self) -> &[Esc] {
        &self.escs
    }

    /// The DataLink hubs found: the ESC whose stream each came in (its channel 0), and the
    /// hub link's statistics.
    pub fn hubs(&self) -> impl Iterator<Item = (usize, DatalinkStats)> + '_ {
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
    pub fn link(&self, esc: usize) -> EscLink {
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
        self.number_inputs(&inputs);
        let mut result = Ok(());
        while let Some(first) = inputs.front() {
            let clock = first.format().clock();
            let merged = first.format() != InputFormat::Serial && clock != Clock::None;
            let n = if merged {
                inputs
                    .iter()
                    .take_while(|i| {
                        i.format().clock() == clock && i.format() != InputFormat::Serial
                    })
                    .count()
            } else {
                1
            };
            let run: Vec<Input> = inputs.drain(..n).collect();
            let more_recordings = inputs.iter().any(|i| i.format() == InputFormat::Recording);
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
        // A hub's channels that carried an ESC are ESCs of its input.
        for esc in 0..self.escs.len() {
            if self.escs[esc].hub.is_some() && self.link(esc).frames() > 0 {
                let escs = &mut self.read[self.escs[esc].input].escs;
                escs.push(esc);
                escs.sort_unstable();
            }
        }
        result?;
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

    /// Hands on the queued frames earlier than `bound` (all of them for infinity), and the
    /// earliest ones beyond the queue's bound, in time order.
    fn release<H: Handler>(&mut self, bound: f64, handler: &mut H) {
        while let Some((esc, t, d)) = self.queue.pop_before(bound) {
            let id = u8::try_from(esc).unwrap_or(u8::MAX);
            let settings = self.esc_settings(esc);
            handler.frame(id, t, &d, &settings);
        }
    }

    /// Hands on the frames of a stream just found to come from a DataLink hub, once its
    /// channels have ESCs (made here, in channel order: channel 0 is the stream's own ESC): to
    /// a handler, or to the time-order queue.
    fn deliver<H: Handler>(&mut self, esc: usize, pending: Vec<Pending>, to: &mut Deliver<'_, H>) {
        if pending.is_empty() {
            return;
        }
        let hub = match self.hubs.get(&esc) {
            Some(&hub) => hub,
            None => {
                let mut escs = [esc; CHANNELS];
                for (channel, slot) in escs.iter_mut().enumerate().skip(1) {
                    if self.escs.len() >= MAX_ESCS {
                        // Not numbered: the `esc` column cannot tell it from another.
                        *slot = usize::MAX;
                        continue;
                    }
                    *slot = self.escs.len();
                    let esc = Esc {
                        input: self.escs[esc].input,
                        name: self.escs[esc].name.clone(),
                        stream: Stream::new(),
                        hub: Some((esc, channel as u8)),
                    };
                    self.push_esc(esc);
                }
                let settings = escs.map(|e| self.esc_settings(e));
                let hub = Hub { escs, settings };
                self.hubs.insert(esc, hub);
                hub
            }
        };
        for (t, channel, d) in pending {
            let c = usize::from(channel);
            let Some(&id) = hub.escs.get(c).filter(|&&e| e != usize::MAX) else {
                continue;
            };
            match to {
                Deliver::Handler(handler) => {
                    handler.frame(id as u8, t, &d, &hub.settings[c]);
                }
                Deliver::Queue => self.queue.push(id, t, &d),
            }
        }
    }

    /// A new ESC, its settings looked up once.
    fn push_esc(&mut self, esc: Esc) {
        let settings = self.settings.get(self.escs.len(), &esc.name);
        self.escs.push(esc);
        self.esc_settings.push(settings);
        self.readers.push(0);
        self.fed.push(None);
    }

    /// The ESC of stream `stream` of `input` (number `index`), made when first seen; `escs`
    /// holds the ESCs of the input's streams so far.
    fn esc_of(
        &mut self,
        input: &Input,
        index: usize,
        stream: usize,
        escs: &mut Vec<Option<usize>>,
    ) -> Result<usize, InputError> {
        if let Some(&Some(esc)) = escs.get(stream) {
            return Ok(esc);
        }
        let name = input.stream_name(stream);
        let recorded = input.format() == InputFormat::Recording;
        let earlier = self
            .ports
            .get(&name)
            .copied()
            .filter(|e| recorded && !escs.contains(&Some(*e)));
        let esc = match earlier {
            Some(esc) => esc,
            None => {
                if self.escs.len() >= MAX_ESCS {
                    return Err(InputError::TooManyEscs {
                        input: self.names[index].clone(),
                    });
                }
                if recorded {
                    self.ports.insert(name.clone(), self.escs.len());
                }
                self.push_esc(Esc {
                    input: index,
                    name,
                    stream: Stream::new(),
                    hub: None,
                });
                self.escs.len() - 1
            }
        };
        if escs.len() <= stream {
            escs.resize(stream + 1, None);
        }
        escs[stream] = Some(esc);
        self.readers[esc] += 1;
        Ok(esc)
    }

    /// Numbers every stream `input` has declared so far (streams declared but never heard
    /// from are ESCs all the same, as far as an `esc` index can number them).
    fn number_streams(&mut self, input: &Input, index: usize, escs: &mut Vec<Option<usize>>) {
        for stream in 0..input.streams() {
            if self.esc_of(input, index, stream, escs).is_err() {
                break;
            }
        }
    }

    /// Numbers the streams of the inputs before they are read (one for a file or standard
    /// input, one per port), in the order given up to the first recording (which declares its
    /// ports as it is read: they and the inputs after them are numbered as they are read): the
    /// channels of a DataLink hub, found later in any of them, take numbers after all of these,
    /// as they do live (see [`PortStreams`](crate::stream::PortStreams)).
    fn number_inputs(&mut self, inputs: &VecDeque<Input>) {
        let base = self.read.len();
        self.numbered.resize(base, Vec::new());
        for (k, input) in inputs.iter().enumerate() {
            if input.format() == InputFormat::Recording {
                break;
            }
            let mut escs = Vec::new();
            self.number_streams(input, base + k, &mut escs);
            self.numbered.push(escs);
        }
    }

    /// The ESCs of input `index`'s streams numbered before it was read.
    fn numbered(&mut self, index: usize) -> Vec<Option<usize>> {
        self.numbered
            .get_mut(index)
            .map(std::mem::take)
            .unwrap_or_default()
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

    /// Notes an input as begun, in command-line order.
    fn open(&mut self, input: &Input) -> usize {
        self.read.push(InputInfo {
            name: input.name().to_string(),
            format: input.format(),
            flagged_bytes: 0,
            bytes: 0,
            escs: Vec::new(),
            looks: None,
        });
        self.read.len() - 1
    }

    /// Reads an input without times (or a live one) to its end, its frames handed on as they
    /// are decoded: the path of `summary` on a raw file, kept to the decoder's loop.
    fn read_alone<H: Handler>(
        &mut self,
        mut input: Input,
        handler: &mut H,
    ) -> Result<(), H::Error> {
        let index = self.open(&input);
        let mut escs = self.numbered(index);
        let mut bytes = 0;
        let result = self.read_input(&mut input, index, &mut escs, &mut bytes, handler);
        self.number_streams(&input, index, &mut escs);
        // A recorded port's stream may go on in the next recording: it is finished at the
        // end of the run. Other streams end with their input.
        if input.format() != InputFormat::Recording {
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
            *bytes += len as u64;
            // The batch borrows the input: its stream's ESC is found first, by a second look.
            let _ = batch;
            let esc = self.esc_of(input, index, stream, escs)?;
            let Some(batch) = input.current_batch() else {
                continue;
            };
            let id = u8::try_from(esc).unwrap_or(u8::MAX);
            let settings = &self.esc_settings(esc);
            let hub = self.hubs.get(&esc);
            let mut pending = Vec::new();
            // Inlined into the decoder's loop, so that the handler may be too: a frame's fields
            // then reach it in registers, not through a `Decoded` stored and loaded back.
            self.escs[esc].stream.feed(
                batch,
                #[inline(always)]
                |t, channel, d| match route(esc, hub, t, channel, d, &mut pending) {
                    Some((_, None)) => handler.frame(id, t, d, settings),
                    Some((esc, Some(settings))) => {
                        if let Ok(esc) = u8::try_from(esc) {
                            handler.frame(esc, t, d, settings);
                        }
                    }
                    None => {}
                },
            );
            self.deliver(esc, pending, &mut Deliver::Handler(handler));
            handler.end_batch(len < LIVE_BATCH)?;
        }
    }

    /// Reads inputs with times together, their frames handed on in time order (see the module
    /// documentation). `more_recordings`: recordings follow, which may go on with the ports of
    /// these.
    fn read_together<H: Handler>(
        &mut self,
        inputs: Vec<Input>,
        more_recordings: bool,
        handler: &mut H,
    ) -> Result<(), H::Error> {
        let mut run: Vec<Reading> = Vec::with_capacity(inputs.len());
        // The batches read ahead, earliest first.
        let mut next = BinaryHeap::new();
        // Every input's first batch, in the order given: its streams are numbered then, and a
        // file is closed again until its turn comes. After an error, the inputs not begun are
        // not read.
        let mut result = Ok(());
        for input in inputs {
            let index = self.open(&input);
            let escs = self.numbered(index);
            run.push(Reading {
                input,
                index,
                escs,
                bytes: 0,
                ahead: Some((f64::NEG_INFINITY, 0)),
                parked: false,
                overlaps: Vec::new(),
            });
            let k = run.len() - 1;
            result = self.read_ahead(&mut run, k, more_recordings);
            if result.is_err() {
                break;
            }
            if let Some((t, _)) = run[k].ahead {
                run[k].parked = run[k].input.rewind();
                next.push(Earliest { t, id: k });
            }
        }
        let mut live = false;
        while result.is_ok() {
            // Frames no input can precede any more are handed on.
            self.release(self.bound(&next), handler);
            handler.end_batch(live)?;
            let Some(Earliest { id: k, .. }) = next.pop() else {
                break;
            };
            if std::mem::take(&mut run[k].parked) {
                // Its first batch again, its bytes counted already.
                result = self.read_batch(&mut run, k, more_recordings, false, false);
                if result.is_err() {
                    break;
                }
            }
            let Some((_, esc)) = run[k].ahead else {
                continue;
            };
            let reading = &mut run[k];
            if let Some(batch) = reading.input.current_batch() {
                live = batch.bytes.len() < LIVE_BATCH;
                let batch = self.unheard(reading.index, &mut reading.overlaps, esc, batch);
                let queue = &mut self.queue;
                let hub = self.hubs.get(&esc);
                let mut pending = Vec::new();
                self.escs[esc].stream.feed(batch, |t, channel, d| {
                    if let Some((esc, _)) = route(esc, hub, t, channel, d, &mut pending) {
                        queue.push(esc, t, d);
                    }
                });
                self.deliver(esc, pending, &mut Deliver::<H>::Queue);
            }
            result = self.read_ahead(&mut run, k, more_recordings);
            if let Some((t, _)) = run[k].ahead {
                next.push(Earliest { t, id: k });
            }
        }
        // On an error, the inputs not at their end stop here: their streams are finished too.
        for k in 0..run.len() {
            if run[k].ahead.is_some() {
                run[k].ahead = None;
                self.end_of(&mut run, k, more_recordings);
            }
        }
        self.release(f64::INFINITY, handler);
        Ok(result?)
    }

    /// The part of `batch` (of ESC `esc`, read from input `index`) that no other input gave: when
    /// the ESC's stream was fed last from another input, the bytes up to the time of its last
    /// byte are that input's again (the same recording given twice, or recordings of one port
    /// that overlap), and are noted and left out, so that each moment of a port is decoded
    /// once.
    fn unheard<'b>(
        &mut self,
        index: usize,
        overlaps: &mut Vec<Overlap>,
        esc: usize,
        batch: Batch<'b>,
    ) -> Batch<'b> {
        let Some(times) = batch.times else {
            return batch;
        };
        let skip = match self.fed[esc] {
            Some((earlier, last)) if earlier != index => {
                let skip = times.iter().position(|&t| t > last).unwrap_or(times.len());
                if skip > 0 {
                    let (from, to) = (times[0], times[skip - 1]);
                    match overlaps.iter_mut().find(|o| o.esc == esc) {
                        Some(o) => {
                            o.from = o.from.min(from);
                            o.to = o.to.max(to);
                        }
                        None => overlaps.push(Overlap {
                            esc,
                            earlier,
                            from,
                            to,
                        }),
                    }
                }
                skip
            }
            _ => 0,
        };
        if let Some(&last) = times[skip..].last() {
            self.fed[esc] = Some((index, last));
        }
        Batch {
            bytes: &batch.bytes[skip..],
            times: Some(&times[skip..]),
            stream: batch.stream,
        }
    }

    /// Reads input `k`'s next batch ahead (numbering its streams after its first), or notes
    /// its end.
    fn read_ahead(
        &mut self,
        run: &mut [Reading],
        k: usize,
        more_recordings: bool,
    ) -> Result<(), InputError> {
        let first = run[k].ahead.is_some_and(|(t, _)| t == f64::NEG_INFINITY);
        self.read_batch(run, k, more_recordings, first, true)
    }

    /// Reads input `k`'s next batch: `first`, its streams are numbered; `count`, its bytes are
    /// counted. At its end, notes the end.
    fn read_batch(
        &mut self,
        run: &mut [Reading],
        k: usize,
        more_recordings: bool,
        first: bool,
        count: bool,
    ) -> Result<(), InputError> {
        let reading = &mut run[k];
        let batch = match reading.input.next_batch() {
            Ok(Some(batch)) => batch,
            Ok(None) => {
                reading.ahead = None;
                self.end_of(run, k, more_recordings);
                return Ok(());
            }
            Err(e) => return Err(e),
        };
        let Some(times) = batch.times else {
            return Err(InputError::NoTiming {
                input: self.names[reading.index].clone(),
            });
        };
        let t = times.first().copied().unwrap_or(f64::NEG_INFINITY);
        let stream = batch.stream;
        if count {
            reading.bytes += batch.bytes.len() as u64;
        }
        let (input, index, escs) = (&reading.input, reading.index, &mut reading.escs);
        if first {
            self.number_streams(input, index, escs);
        }
        let esc = self.esc_of(input, index, stream, escs)?;
        reading.ahead = Some((t, esc));
        Ok(())
    }

    /// Input `k` is at its end: its streams are numbered and noted; those no other input can
    /// go on with are finished. What it overlapped of earlier inputs is told.
    fn end_of(&mut self, run: &mut [Reading], k: usize, more_recordings: bool) {
        let reading = &mut run[k];
        let mut escs = std::mem::take(&mut reading.escs);
        self.number_streams(&reading.input, reading.index, &mut escs);
        self.close(&reading.input, reading.index, &escs, reading.bytes);
        for o in std::mem::take(&mut reading.overlaps) {
            reading.input.tell(Notice::Overlap {
                input: self.names[reading.index].clone(),
                port: self.escs[o.esc].name.clone(),
                earlier: self.names[o.earlier].clone(),
                seconds: o.to - o.from,
            });
        }
        let recorded = reading.input.format() == InputFormat::Recording;
        for &esc in escs.iter().flatten() {
            if self.readers[esc] == 0 && !(recorded && more_recordings) {
                self.finish(esc);
            }
        }
        reading.escs = escs;
    }

    /// The time before which no input being read can give a frame any more: the earliest
    /// batch read ahead, and the earliest byte a decoder holds of a frame still arriving on a
    /// stream an input not at its end goes on with.
    fn bound(&self, next: &BinaryHeap<Earliest>) -> f64 {
        let mut bound = next.peek().map_or(f64::INFINITY, |e| e.t);
        for (esc, &readers) in self.readers.iter().enumerate() {
            if readers > 0
                && let Some(t) = self.escs[esc].stream.held_since()
            {
                bound = bound.min(t);
            }
        }
        bound
    }
}

/// Decoded frames waiting to be handed on in time order: a queue per ESC (each in its
/// stream's order) and a heap of their first frames.
#[derive(Default)]
struct Queue {
    escs: Vec<VecDeque<(Option<f64>, Decoded)>>,
    fronts: BinaryHeap<Earliest>,
    len: usize,
    peak: usize,
}

/// A time and what it is of, ordered for a heap of the earliest: the first frame waiting of an
/// ESC (`id` its number), or the batch an input read ahead (`id` its place in the run); the
/// earliest time first, then the lowest `id`.
#[derive(Debug, PartialEq)]
struct Earliest {
    t: f64,
    id: usize,
}

impl Eq for Earliest {}

impl Ord for Earliest {
    fn cmp(&self, other: &Self) -> Ordering {
        // Reversed: the heap's greatest is the earliest.
        other.t.total_cmp(&self.t).then(other.id.cmp(&self.id))
    }
}

impl PartialOrd for Earliest {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// The time a frame is ordered by: one without a time goes first.
fn key(t: Option<f64>) -> f64 {
    t.unwrap_or(f64::NEG_INFINITY)
}

impl Queue {
    fn push(&mut self, esc: usize, t: Option<f64>, d: &Decoded) {
        if self.escs.len() <= esc {
            self.escs.resize_with(esc + 1, VecDeque::new);
        }
        let queue = &mut self.escs[esc];
        if queue.is_empty() {
            self.fronts.push(Earliest { t: key(t), id: esc });
        }
        queue.push_back((t, *d));
        self.len += 1;
        self.peak = self.peak.max(self.len);
    }

    /// The earliest frame, if it is earlier than `bound` or the queue is over its bound.
    fn pop_before(&mut self, bound: f64) -> Option<(usize, Option<f64>, Decoded)> {
        let front = self.fronts.peek()?;
        if front.t >= bound && self.len <= MAX_QUEUED {
            return None;
        }
        let esc = self.fronts.pop()?.id;
        let queue = &mut self.escs[esc];
        let (t, d) = queue.pop_front()?;
        if let Some(&(next, _)) = queue.front() {
            self.fronts.push(Earliest {
                t: key(next),
                id: esc,
            });
        }
        self.len -= 1;
        Some((esc, t, d))
    }
}

/// The ESCs of a DataLink hub's channels, and their settings.
#[derive(Debug, Clone, Copy)]
struct Hub {
    escs: [usize; CHANNELS],
    settings: [Settings; CHANNELS],
}

/// A frame of a DataLink channel that has no ESC yet: its time, channel and frame.
type Pending = (Option<f64>, u8, Decoded);

/// The ESC a frame of the stream of ESC `own` belongs to: `own` on its own wire; behind a hub
/// whose channels are numbered (`hub`), its channel's ESC with that ESC's settings; `None` for a
/// channel the `esc` column cannot number, or when the hub's channels are not numbered yet (the
/// frame then waits in `pending`).
#[inline(always)]
fn route<'h>(
    own: usize,
    hub: Option<&'h Hub>,
    t: Option<f64>,
    channel: Option<u8>,
    d: &Decoded,
    pending: &mut Vec<Pending>,
) -> Option<(usize, Option<&'h Settings>)> {
    match (channel, hub) {
        (None, _) => Some((own, None)),
        (Some(c), Some(hub)) => {
            let c = usize::from(c);
            (hub.escs[c] != usize::MAX).then(|| (hub.escs[c], Some(&hub.settings[c])))
        }
        (Some(c), None) => {
            pending.push((t, c, *d));
            None
        }
    }
}

/// Where [`Sources::deliver`] hands frames: a handler, or the time-order queue.
enum Deliver<'a, H> {
    Handler(&'a mut H),
    Queue,
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::pcapng;
    use crate::record::Record;
    use hwfoc::DataFrame;

    /// Collects the records, by ESC.
    #[derive(Default)]
    struct ByEsc(Vec<Vec<(u16, f64)>>);

    impl Handler for ByEsc {
        type Error = InputError;

        fn record(&mut self, r: &Record) {
            let esc = usize::from(r.esc);
            if self.0.len() <= esc {
                self.0.resize(esc + 1, Vec::new());
            }
            self.0[esc].push((r.packet, r.t_s.unwrap_or(f64::NAN)));
        }
    }

    /// The bytes of data frames `packets`.
    pub(crate) fn wire(packets: std::ops::Range<u16>) -> Vec<u8> {
        packets
            .flat_map(|packet| {
                DataFrame {
                    packet,
                    ..Default::default()
                }
                .encode()
            })
            .collect()
    }

    /// A recording with one interface per `(port, bytes, first byte's time in ns)`, in the
    /// order given; each port's bytes in packets of 7 bytes, 4 ms apart (7 bytes take 3.6 ms
    /// at 19200 baud).
    fn recording(ports: &[(&str, &[u8], u64)]) -> Vec<u8> {
        let mut w = pcapng::Writer::new(Vec::new()).unwrap();
        for (port, _, _) in ports {
            w.add_interface(port, 19200).unwrap();
        }
        for (i, (_, bytes, t0)) in ports.iter().enumerate() {
            for (k, piece) in bytes.chunks(7).enumerate() {
                w.write(i as u32, t0 + k as u64 * 4_000_000, piece).unwrap();
            }
        }
        w.into_inner().unwrap()
    }

    /// Runs recordings `inputs` (named `rec-0.pcapng`, ...) into a new `H`.
    fn run_into<H: Handler + Default>(inputs: Vec<Vec<u8>>) -> (H, Sources)
    where
        H::Error: std::fmt::Debug,
    {
        let inputs = inputs
            .into_iter()
            .enumerate()
            .map(|(i, bytes)| Input::from_memory(&format!("rec-{i}.pcapng"), bytes).unwrap())
            .collect();
        let mut sources = Sources::new(inputs, Settings::DEFAULT);
        let mut got = H::default();
        sources.run(&mut got).unwrap();
        (got, sources)
    }

    fn run(inputs: Vec<Vec<u8>>) -> (ByEsc, Sources) {
        run_into(inputs)
    }

    /// The files of a rotated recording are one stream per port: a frame split between two
    /// files is decoded whole, the ports keep their ESC numbers whatever the order of the
    /// interfaces in each file, and the records are those of one recording holding every byte.
    #[test]
    fn recordings_of_the_same_ports_continue_one_stream_each() {
        let (a, b) = (wire(0..30), wire(100..130));
        let t = 1_700_000_000_000_000_000u64;
        // Cut each port's bytes in the middle of a frame, at different places.
        let (a1, a2) = a.split_at(24 * 10 + 5);
        let (b1, b2) = b.split_at(24 * 20 + 17);
        let ms = 4_000_000;
        let whole = recording(&[("/dev/ttyUSB0", &a, t), ("/dev/ttyUSB1", &b, t)]);
        let first = recording(&[("/dev/ttyUSB0", a1, t), ("/dev/ttyUSB1", b1, t)]);
        let a2_t = t + a1.len().div_ceil(7) as u64 * ms;
        let b2_t = t + b1.len().div_ceil(7) as u64 * ms;
        // The second file declares the ports in the other order.
        let second = recording(&[("/dev/ttyUSB1", b2, b2_t), ("/dev/ttyUSB0", a2, a2_t)]);
        let (one, _) = run(vec![whole]);
        let (split, sources) = run(vec![first, second]);
        assert_eq!(sources.escs().len(), 2);
        assert_eq!(split.0[0].len(), 30);
        assert_eq!(split.0[1].len(), 30);
        let packets: Vec<u16> = split.0[1].iter().map(|r| r.0).collect();
        assert_eq!(packets, (100..130).collect::<Vec<_>>());
        // Times are those of the bytes (the split pieces were timed as in the whole file).
        assert_eq!(split.0[0].len(), one.0[0].len());
        assert_eq!(sources.inputs()[1].escs, [1, 0]);
        assert_eq!(
            sources.inputs()[0].bytes + sources.inputs()[1].bytes,
            (a.len() + b.len()) as u64
        );
        for esc in &sources.escs()[..2] {
            assert_eq!(esc.stream.stats().checksum_failures(), 0);
            assert_eq!(esc.stream.stats().bytes_skipped(), 0);
        }
    }

    /// Hundreds of files of one rotated recording are still one ESC per port.
    #[test]
    fn a_long_rotated_series_is_not_too_many_escs() {
        let t = 1_700_000_000_000_000_000u64;
        let files: Vec<Vec<u8>> = (0..300u16)
            .map(|k| {
                let bytes = wire(2 * k..2 * k + 2);
                recording(&[("/dev/ttyACM0", &bytes, t + u64::from(k) * 1_000_000_000)])
            })
            .collect();
        let (got, sources) = run(files);
        assert_eq!(sources.escs().len(), 1);
        assert_eq!(got.0[0].len(), 600);
        assert_eq!(sources.escs()[0].stream.stats().lost_packets(), 0);
    }

    /// Files other than recordings are one ESC each.
    #[test]
    fn files_without_port_names_are_one_esc_each() {
        let raw = |p| Input::from_memory("a.bin", wire(p)).unwrap();
        let mut sources = Sources::new(vec![raw(0..3), raw(0..3)], Settings::DEFAULT);
        let mut got = ByEsc::default();
        sources.run(&mut got).unwrap();
        assert_eq!(sources.escs().len(), 2);
        assert_eq!((got.0[0].len(), got.0[1].len()), (3, 3));
    }

    /// Collects the records in the order handed on: ESC, packet, time.
    #[derive(Default)]
    struct InOrder(Vec<(u8, u16, f64)>);

    impl Handler for InOrder {
        type Error = InputError;

        fn record(&mut self, r: &Record) {
            self.0.push((r.esc, r.packet, r.t_s.unwrap_or(f64::NAN)));
        }
    }

    /// A recording as `hwfoc record` writes one: packets of every port in time order, a data
    /// frame per packet every 50 ms per port from `t0` (ns), port `p` `p` ms after port 0.
    fn live_recording(ports: &[&str], first_packet: u16, frames: u16, t0: u64) -> Vec<u8> {
        let mut w = pcapng::Writer::new(Vec::new()).unwrap();
        for port in ports {
            w.add_interface(port, 19200).unwrap();
        }
        for k in 0..frames {
            for p in 0..ports.len() {
                let t = t0 + u64::from(k) * 50_000_000 + p as u64 * 1_000_000;
                let packet = first_packet.wrapping_add(k);
                w.write(p as u32, t, &wire(packet..packet + 1)).unwrap();
            }
        }
        w.into_inner().unwrap()
    }

    fn in_order(inputs: Vec<Vec<u8>>) -> (InOrder, Sources) {
        run_into(inputs)
    }

    /// The queue held at most a 10 s window of two ports at 20 frames a second, and a frame or
    /// two more.
    fn assert_one_window_of_two_ports(sources: &Sources) {
        let peak = sources.peak_queued();
        assert!(peak <= 2 * 201, "{peak}");
    }

    fn assert_time_order(records: &[(u8, u16, f64)]) {
        for w in records.windows(2) {
            assert!(
                (w[0].2, w[0].0) < (w[1].2, w[1].0),
                "out of order: {:?} then {:?}",
                w[0],
                w[1]
            );
        }
    }

    /// A two-ESC recording gives its ESCs' records interleaved in time order, not a window of
    /// one ESC then a window of the other.
    #[test]
    fn the_records_of_a_recording_come_in_time_order() {
        let t0 = 1_795_442_580_000_000_000;
        let rec = live_recording(&["/dev/ttyUSB0", "/dev/ttyUSB1"], 0, 400, t0);
        let (got, sources) = in_order(vec![rec]);
        assert_eq!(got.0.len(), 800);
        assert_time_order(&got.0);
        let escs: Vec<u8> = got.0.iter().take(6).map(|r| r.0).collect();
        assert_eq!(escs, [0, 1, 0, 1, 0, 1]);
        assert_one_window_of_two_ports(&sources);
    }

    /// Recordings of different ports that overlap in time are merged by time; their ESCs are
    /// numbered in the order given, whatever their times.
    #[test]
    fn several_recordings_are_merged_by_time() {
        let s = 1_000_000_000u64;
        let t0 = 1_795_442_580 * s;
        let late = live_recording(&["/dev/ttyUSB1"], 500, 300, t0 + 5 * s);
        let early = live_recording(&["/dev/ttyUSB0", "/dev/ttyUSB2"], 0, 300, t0);
        let (got, sources) = in_order(vec![late, early]);
        assert_eq!(got.0.len(), 900);
        assert_time_order(&got.0);
        // The later file was given first: its port is ESC 0.
        assert_eq!(sources.escs()[0].name, "/dev/ttyUSB1");
        assert_eq!(sources.inputs()[1].escs, [1, 2]);
        assert_eq!(got.0[0].0, 1);
        let first_of_late = got.0.iter().position(|r| r.0 == 0).unwrap();
        assert!((got.0[first_of_late].2 - got.0[0].2 - 5.0).abs() < 1e-6);
        // The files of a rotated recording, as in the test above, also come in time order.
        let t = 1_700_000_000_000_000_000u64;
        let whole = live_recording(&["/dev/ttyUSB0", "/dev/ttyUSB1"], 0, 100, t);
        let next = live_recording(&["/dev/ttyUSB1", "/dev/ttyUSB0"], 100, 100, t + 5 * s);
        let (got, sources) = in_order(vec![whole, next]);
        assert_eq!(sources.escs().len(), 2);
        assert_eq!(got.0.len(), 400);
        assert_time_order(&got.0);
    }

    /// Half an hour of two ESCs: the queue holds about one window of the recording, not the file.
    #[test]
    fn a_long_recording_is_merged_in_bounded_memory() {
        let frames = 20 * 1800;
        let rec = live_recording(&["/dev/ttyUSB0", "/dev/ttyUSB1"], 0, frames, 1 << 60);
        let (got, sources) = in_order(vec![rec]);
        assert_eq!(got.0.len(), 2 * usize::from(frames));
        assert_time_order(&got.0);
        assert_one_window_of_two_ports(&sources);
        assert!(sources.peak_queued() >= 200, "{}", sources.peak_queued());
    }

    /// The files of a rotated recording of two ports, given in any order, are one stream per
    /// port in time order: the records of the recording they were cut from.
    #[test]
    fn recordings_of_one_port_are_read_in_time_order_whatever_the_order_given() {
        let s = 1_000_000_000u64;
        let t0 = 1_700_000_000 * s;
        let ports = ["/dev/ttyUSB0", "/dev/ttyUSB1"];
        // Twelve files of 100 frames (5 s) per port, given 3, 10, 5, 0, 7, 2, 9, 4, 11, 6, 1, 8.
        let files: Vec<Vec<u8>> = (0..12u16)
            .map(|k| (k * 7 + 3) % 12)
            .map(|k| live_recording(&ports, 100 * k, 100, t0 + u64::from(k) * 5 * s))
            .collect();
        let (got, sources) = in_order(files);
        assert_eq!(sources.escs().len(), 2);
        assert_eq!(got.0.len(), 2400);
        assert_time_order(&got.0);
        let packets: Vec<u16> = got.0.iter().step_by(2).map(|r| r.1).collect();
        assert_eq!(packets, (0..1200).collect::<Vec<_>>());
        for esc in sources.escs() {
            assert_eq!(esc.stream.stats().lost_packets(), 0);
            assert_eq!(esc.stream.stats().restarts(), 0);
        }
        assert_one_window_of_two_ports(&sources);
    }

    /// A recording given twice, and a file overlapping part of another of the same port, are
    /// decoded once, with a notice saying so; a recording of another port at the same time is
    /// not an overlap.
    #[test]
    fn a_moment_of_a_port_recorded_twice_is_decoded_once() {
        let s = 1_000_000_000u64;
        let t0 = 1_700_000_000 * s;
        let rec = live_recording(&["/dev/ttyUSB0"], 0, 200, t0);
        // Frames 150..250 of the same port: the first half overlaps `rec`.
        let tail = live_recording(&["/dev/ttyUSB0"], 150, 100, t0 + 150 * s / 20);
        let other = live_recording(&["/dev/ttyUSB1"], 0, 200, t0);
        let named = [("a", &rec), ("a", &rec), ("b", &tail), ("c", &other)];
        let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let inputs = named
            .iter()
            .map(|(name, bytes)| {
                let mut input = Input::from_memory(name, bytes.to_vec()).unwrap();
                let sink = std::sync::Arc::clone(&seen);
                input.set_notices(move |n| sink.lock().unwrap().push(n));
                input
            })
            .collect();
        let mut sources = Sources::new(inputs, Settings::DEFAULT);
        let mut got = InOrder::default();
        sources.run(&mut got).unwrap();
        let port0: Vec<u16> = got.0.iter().filter(|r| r.0 == 0).map(|r| r.1).collect();
        assert_eq!(port0, (0..250).collect::<Vec<_>>());
        assert_eq!(got.0.iter().filter(|r| r.0 == 1).count(), 200);
        assert_time_order(&got.0);
        let stats = sources.escs()[0].stream.stats();
        assert_eq!((stats.lost_packets(), stats.duplicate_packets()), (0, 0));
        assert_eq!(stats.bytes_skipped(), 0);
        let seen = seen.lock().unwrap();
        let overlaps: Vec<(&str, &str, f64)> = seen
            .iter()
            .filter_map(|n| match n {
                Notice::Overlap {
                    input,
                    earlier,
                    seconds,
                    port,
                } if port == "/dev/ttyUSB0" => Some((input.as_str(), earlier.as_str(), *seconds)),
                _ => None,
            })
            .collect();
        assert_eq!(overlaps.len(), 2, "{seen:?}");
        assert_eq!(overlaps[0].0, "a");
        assert_eq!(overlaps[0].1, "a");
        assert!((overlaps[0].2 - 9.962).abs() < 0.001, "{overlaps:?}");
        assert_eq!((overlaps[1].0, overlaps[1].1), ("b", "a"));
        assert!((overlaps[1].2 - 2.462).abs() < 0.001, "{overlaps:?}");
        assert_eq!(seen.len(), 2, "{seen:?}");
    }

    /// Raw files (no times) keep the order given, around recordings merged by time.
    #[test]
    fn untimed_inputs_keep_their_place() {
        let t0 = 1_795_442_580_000_000_000;
        let inputs = vec![
            Input::from_memory("a.bin", wire(0..3)).unwrap(),
            Input::from_memory(
                "r.pcapng",
                live_recording(&["/dev/ttyUSB0", "/dev/ttyUSB1"], 10, 2, t0),
            )
            .unwrap(),
            Input::from_memory("b.bin", wire(20..22)).unwrap(),
        ];
        let mut sources = Sources::new(inputs, Settings::DEFAULT);
        let mut got = InOrder::default();
        sources.run(&mut got).unwrap();
        let order: Vec<(u8, u16)> = got.0.iter().map(|r| (r.0, r.1)).collect();
        assert_eq!(
            order,
            [
                (0, 0),
                (0, 1),
                (0, 2),
                (1, 10),
                (2, 10),
                (1, 11),
                (2, 11),
                (3, 20),
                (3, 21)
            ]
        );
    }

    /// Hubs and ESCs plugged in together never share an ESC number: a hub's channel 0 is its
    /// port's number, its other channels the next numbers after all ports', hub by hub in the
    /// order they are found. Live ports ([`PortStreams`](crate::stream::PortStreams)) and a
    /// recording of them number them alike, and convert each under its own settings.
    #[test]
    fn hubs_and_escs_together_number_every_esc_once_live_and_recorded() {
        // Ports 0 and 2 are hubs with all 8 channels (packet = 1000 + 100 * port + channel:
        // an all-zero record would be an empty slot), port 1 an ESC of its own.
        let hub = |port: u16| -> Vec<u8> {
            (0..3)
                .flat_map(|counter| {
                    let mut frame = hwfoc::datalink::DatalinkFrame {
                        counter,
                        slots: [None; CHANNELS],
                    };
                    for (c, slot) in frame.slots.iter_mut().enumerate() {
                        *slot = Some(DataFrame {
                            packet: 1000 + 100 * port + c as u16,
                            ..Default::default()
                        });
                    }
                    frame.encode()
                })
                .collect()
        };
        // Bytes as they arrived: port 2's first, then port 1's, then port 0's.
        let t = 1_700_000_000_000_000_000u64;
        let arrivals = [(2usize, hub(2)), (1, wire(100..103)), (0, hub(0))];
        let by_esc = |records: Vec<(u8, u16)>| {
            let mut m = std::collections::BTreeMap::<u8, Vec<u16>>::new();
            for (esc, packet) in records {
                m.entry(esc).or_default().push(packet);
            }
            m
        };
        // Port 2, found a hub first, takes 3..=9 for its channels 1..7; port 0 then 10..=16.
        let mut expected = std::collections::BTreeMap::new();
        expected.insert(1, vec![100, 101, 102]);
        for c in 0..8u16 {
            let (esc2, esc0) = if c == 0 {
                (2, 0)
            } else {
                (2 + c as u8, 9 + c as u8)
            };
            expected.insert(esc2, vec![1200 + c; 3]);
            expected.insert(esc0, vec![1000 + c; 3]);
        }

        struct Escs(Vec<(u8, u16)>);
        impl Handler for Escs {
            type Error = InputError;
            fn record(&mut self, r: &Record) {
                self.0.push((r.esc, r.packet));
            }
            fn frame(&mut self, esc: u8, t: Option<f64>, d: &Decoded, settings: &Settings) {
                // ESC 12 (port 0's channel 2) has settings of its own; port 2's channels
                // follow the port's.
                let poles = match esc {
                    12 => 7,
                    2..=9 => 14,
                    _ => Settings::DEFAULT.pole_pairs,
                };
                let scale = if esc == 12 { 100.0 } else { 64.0 };
                assert_eq!(
                    (settings.pole_pairs, settings.current_scale),
                    (poles, scale)
                );
                if let hwfoc::Frame::Data(f) = &d.frame {
                    self.record(&Record::new(t, esc, f, settings));
                }
            }
        }
        let names: Vec<String> = (0..3).map(|p| format!("/dev/ttyUSB{p}")).collect();
        let mut map = crate::settings::SettingsMap::from(Settings::DEFAULT);
        let patch = |scale, poles| crate::settings::SettingsPatch {
            current_scale: scale,
            pole_pairs: poles,
            gear_ratio: None,
        };
        map.set_port(&names[2], patch(None, Some(14))).unwrap();
        map.set_esc(12, patch(Some(100.0), None)).unwrap();
        let mut streams = crate::stream::PortStreams::with_map(115_200, names.clone(), map.clone());
        let mut live = Escs(Vec::new());
        for (k, (port, bytes)) in arrivals.iter().enumerate() {
            let event = crate::serial::PortEvent::Data {
                port: *port,
                t_ns: t + k as u64 * 100_000_000,
                bytes: bytes.clone(),
            };
            assert!(streams.feed(&event, &mut live).is_some());
        }
        assert_eq!(by_esc(live.0), expected);
        assert_eq!(streams.channel_of(2, 9), Some(7));
        assert_eq!(streams.channel_of(0, 0), Some(0));
        assert_eq!(streams.channel_of(0, 10), Some(1));
        assert_eq!(streams.channel_of(1, 1), None);
        assert_eq!(streams.channel_of(0, 3), None);

        // The recording `hwfoc record` makes of those ports: an interface per port, packets
        // in the order the bytes arrived.
        let mut w = pcapng::Writer::new(Vec::new()).unwrap();
        for name in &names {
            w.add_interface(name, 115_200).unwrap();
        }
        for (k, (port, bytes)) in arrivals.iter().enumerate() {
            w.write(*port as u32, t + k as u64 * 100_000_000, bytes)
                .unwrap();
        }
        let input = Input::from_memory("rec.pcapng", w.into_inner().unwrap()).unwrap();
        let mut sources = Sources::new(vec![input], map);
        let mut recorded = Escs(Vec::new());
        sources.run(&mut recorded).unwrap();
        assert_eq!(by_esc(recorded.0), expected);
    }

    /// Hub frames `counters` whose `channels` carry an ESC (packet = 1000 + 100 * `id` +
    /// channel: an all-zero record would be an empty slot).
    pub(crate) fn hub_wire(id: u16, counters: std::ops::Range<u16>, channels: &[usize]) -> Vec<u8> {
        counters
            .flat_map(|counter| {
                let mut frame = hwfoc::datalink::DatalinkFrame::new(counter);
                for &c in channels {
                    frame.slots[c] = Some(DataFrame {
                        packet: 1000 + 100 * id + c as u16,
                        ..Default::default()
                    });
                }
                frame.encode()
            })
            .collect()
    }

    /// The README's one rule, alike for files, a recording and live ports: each input (or
    /// port) is numbered in the order given, a hub's channel 0 keeps its input's number, and
    /// its channels 1 to 7 take the next numbers after all inputs', hub by hub as found. So in
    /// `summary dl_clean.bin dl_ch5.bin raw.bin` the raw file is ESC 2 (it was 16: each hub's
    /// channels were numbered before the next file).
    #[test]
    fn files_a_recording_and_ports_number_hubs_alike() {
        let all: Vec<usize> = (0..CHANNELS).collect();
        let inputs = [
            hub_wire(0, 0..3, &all),
            hub_wire(1, 0..3, &[5]),
            wire(100..103),
        ];
        let mut expected = std::collections::BTreeMap::<u8, Vec<u16>>::new();
        expected.insert(0, vec![1000; 3]);
        for c in 1..8u16 {
            expected.insert(2 + c as u8, vec![1000 + c; 3]);
        }
        expected.insert(14, vec![1105; 3]);
        expected.insert(2, vec![100, 101, 102]);

        #[derive(Default)]
        struct Escs(std::collections::BTreeMap<u8, Vec<u16>>);
        impl Handler for Escs {
            type Error = InputError;
            fn record(&mut self, r: &Record) {
                self.0.entry(r.esc).or_default().push(r.packet);
            }
        }

        // Files, read one after another.
        let files = inputs
            .iter()
            .zip(["dl_clean.bin", "dl_ch5.bin", "raw.bin"])
            .map(|(bytes, name)| Input::from_memory(name, bytes.clone()).unwrap())
            .collect();
        let mut sources = Sources::new(files, Settings::DEFAULT);
        let mut got = Escs::default();
        sources.run(&mut got).unwrap();
        assert_eq!(got.0, expected, "files");
        assert_eq!(sources.inputs()[2].escs, [2]);

        // Live ports, their bytes arriving in the same order.
        let names: Vec<String> = (0..3).map(|p| format!("/dev/ttyUSB{p}")).collect();
        let t = 1_700_000_000_000_000_000u64;
        let mut streams = crate::stream::PortStreams::with_map(
            115_200,
            names.clone(),
            SettingsMap::from(Settings::DEFAULT),
        );
        let mut live = Escs::default();
        for (port, bytes) in inputs.iter().enumerate() {
            let event = crate::serial::PortEvent::Data {
                port,
                t_ns: t + port as u64 * 100_000_000,
                bytes: bytes.clone(),
            };
            streams.feed(&event, &mut live);
        }
        assert_eq!(live.0, expected, "ports");

        // The recording of those ports.
        let mut w = pcapng::Writer::new(Vec::new()).unwrap();
        for name in &names {
            w.add_interface(name, 115_200).unwrap();
        }
        for (port, bytes) in inputs.iter().enumerate() {
            w.write(port as u32, t + port as u64 * 100_000_000, bytes)
                .unwrap();
        }
        let (recorded, _) = run_into::<Escs>(vec![w.into_inner().unwrap()]);
        assert_eq!(recorded.0, expected, "recording");
    }
}
