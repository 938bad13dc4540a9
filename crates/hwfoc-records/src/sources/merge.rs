//! The time-ordered merge of inputs read together (see [`super`]).
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
use std::collections::{BTreeMap, BinaryHeap, VecDeque};

use hwfoc::telemetry::AnyFrame;

use super::numbering::{Deliver, route};
use super::{Handler, LIVE_BATCH, Sources};
use crate::esc_table::{Place, Recording};
use crate::input::{Batch, Input, InputError};
use crate::notice::Notice;

/// The most frames waiting in the time-order queue: past it, the earliest is handed on at once
/// (about 7 MB of frames; a recording of 256 ports needs at most 51 200).
pub const MAX_QUEUED: usize = 1 << 16;

/// The longest silence between the end of one file's port and the start of another's named
/// alike for the two to look like one recording cut in files (a rotated series has none; a
/// recorder restarted on the same machine, a few seconds).
const LINED_UP_S: f64 = 10.0;

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
    /// Hands on the queued frames earlier than `bound` (all of them for infinity), and the
    /// earliest ones beyond the queue's bound, in time order.
    pub(super) fn release<H: Handler>(&mut self, bound: f64, handler: &mut H) {
        while let Some((esc, t, d)) = self.queue.pop_before(bound) {
            let id = u8::try_from(esc).unwrap_or(u8::MAX);
            let settings = self.esc_settings(esc);
            handler.frame(id, t, &d, &settings);
        }
    }

    /// Reads inputs with times together, their frames handed on in time order (see the module
    /// documentation). `more_recordings`: recordings follow, which may go on with the ports of
    /// these.
    pub(super) fn read_together<H: Handler>(
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
        for mut input in inputs {
            let index = self.open(&input);
            if self.skip_duplicate(&mut input, index) {
                continue;
            }
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
                self.tell_can_clashes(&mut run[k].input, esc);
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
        self.tell_alike_ports(&mut run);
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
        if let (Some(&first), Some(&last)) = (times[skip..].first(), times[skip..].last()) {
            self.fed[esc] = Some((index, last));
            let span = self.span[esc].get_or_insert((first, last));
            *span = (span.0.min(first), span.1.max(last));
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
        loop {
            let (stream, len) = match reading.input.next_batch() {
                Ok(Some(batch)) => (batch.stream, batch.bytes.len()),
                Ok(None) => {
                    reading.ahead = None;
                    self.end_of(run, k, more_recordings);
                    return Ok(());
                }
                Err(e) => return Err(e),
            };
            // A CAN bus without ESCs is no ESC (`can_plan.rs`): its bytes are counted only.
            if !self.is_silent_bus(&reading.input, reading.index, stream) {
                break;
            }
            if count {
                reading.bytes += len as u64;
            }
        }
        let Some(batch) = reading.input.current_batch() else {
            return Ok(());
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
                port: self.table[o.esc].key.port.clone(),
                earlier: self.names[o.earlier].clone(),
                seconds: o.to - o.from,
            });
        }
        let recorded = reading.input.format().has_recorded_ports();
        for &esc in escs.iter().flatten() {
            if self.readers[esc] == 0 && !(recorded && more_recordings) {
                self.finish(esc);
            }
        }
        reading.escs = escs;
    }

    /// Tells, through the later input of each pair, of the ports of inputs of `run` that are
    /// named alike in different recordings (see `esc_table.rs`): at the same time, they are
    /// other ESCs ([`Notice::SamePortNames`]); one beginning where the other ends, in files
    /// that name no recording, they may be one recording the user can join
    /// ([`Notice::MayContinue`]). Each ESC is told of with the first earlier ESC named alike.
    fn tell_alike_ports(&self, run: &mut [Reading]) {
        // By (later input, earlier input): the ports at the same time (with this ESC and the
        // earlier one), and those lined up (with the shortest gap).
        type Pair = (usize, usize);
        let mut same: BTreeMap<Pair, Vec<(String, usize, usize)>> = BTreeMap::new();
        let mut lined: BTreeMap<Pair, (Vec<String>, f64)> = BTreeMap::new();
        for (esc, entry) in self.table.iter().enumerate() {
            let (Place::Own, Some(span)) = (entry.key.place, self.span[esc]) else {
                continue;
            };
            let earlier = (0..esc).find_map(|e| {
                let other = &self.table[e];
                let alike = other.key.place == Place::Own
                    && other.key.port == entry.key.port
                    && other.key.recording != entry.key.recording
                    && other.input != entry.input;
                Some((e, other, self.span[e]?)).filter(|_| alike)
            });
            let Some((e, other, before)) = earlier else {
                continue;
            };
            let pair = (entry.input, other.input);
            if span.0 <= before.1 && before.0 <= span.1 {
                same.entry(pair)
                    .or_default()
                    .push((entry.key.port.clone(), esc, e));
            } else if let (Recording::Input(_), Recording::Input(_)) =
                (entry.key.recording, other.key.recording)
            {
                let gap = (span.0 - before.1).max(before.0 - span.1);
                if gap <= LINED_UP_S {
                    let (ports, g) = lined.entry(pair).or_insert((Vec::new(), gap));
                    ports.push(entry.key.port.clone());
                    *g = g.min(gap);
                }
            }
        }
        let mut tell = |input: usize, notice: Notice| {
            if let Some(r) = run.iter_mut().find(|r| r.index == input) {
                r.input.tell(notice);
            }
        };
        for ((input, earlier), ports) in same {
            let notice = Notice::SamePortNames {
                input: self.names[input].clone(),
                earlier: self.names[earlier].clone(),
                ports,
            };
            tell(input, notice);
        }
        for ((input, earlier), (ports, gap)) in lined {
            let notice = Notice::MayContinue {
                input: self.names[input].clone(),
                earlier: self.names[earlier].clone(),
                ports,
                gap,
            };
            tell(input, notice);
        }
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
pub(super) struct Queue {
    escs: Vec<VecDeque<(Option<f64>, AnyFrame)>>,
    fronts: BinaryHeap<Earliest>,
    len: usize,
    pub(super) peak: usize,
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
    pub(super) fn push(&mut self, esc: usize, t: Option<f64>, d: &AnyFrame) {
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
    pub(super) fn pop_before(&mut self, bound: f64) -> Option<(usize, Option<f64>, AnyFrame)> {
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
