//! Several inputs read one after another, one decoding [`Stream`] per ESC.
//!
//! Inputs given together on the command line are read in the order given. Each stream of each
//! input is one ESC: its `esc` index is the number of streams of the earlier inputs plus the
//! stream's index within its input (0 for a file, the interface of a recording, the port's
//! position in a set of serial ports).

use std::ops::Range;

use hwfoc::Settings;

pub use crate::handler::Handler;
use crate::input::{Input, InputError, InputFormat};
use crate::stream::Stream;

/// Batches shorter than this come from a live source: what they produce is passed on at once.
const LIVE_BATCH: usize = 4096;

/// How many ESCs the record's `esc` column (a `u8`) can number.
const MAX_ESCS: usize = 256;

/// One ESC: a stream of one input.
#[derive(Debug)]
pub struct Esc {
    /// Index of its input in [`Sources::inputs`].
    pub input: usize,
    /// Name of the stream: the port it was recorded from, or the input's name.
    pub name: String,
    /// Its decoder and receive times; its link statistics.
    pub stream: Stream,
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
    /// The ESC indices of its streams.
    pub escs: Range<usize>,
}

/// The inputs of a command and the ESCs found in them.
pub struct Sources {
    settings: Settings,
    pending: Vec<Input>,
    names: Vec<String>,
    read: Vec<InputInfo>,
    escs: Vec<Esc>,
    need_timing: bool,
}

impl Sources {
    /// The inputs, opened, in command-line order; data frames become records under
    /// `settings`.
    pub fn new(inputs: Vec<Input>, settings: Settings) -> Sources {
        Sources {
            settings,
            names: inputs.iter().map(|i| i.name().to_string()).collect(),
            pending: inputs,
            read: Vec::new(),
            escs: Vec::new(),
            need_timing: false,
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

    /// The conversion settings of the records.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The names of all inputs, in command-line order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The inputs read so far.
    pub fn inputs(&self) -> &[InputInfo] {
        &self.read
    }

    /// The ESCs found so far, by index.
    pub fn escs(&self) -> &[Esc] {
        &self.escs
    }

    /// Reads every input to its end, in order, handing each frame and the end of each batch
    /// to `handler`.
    ///
    /// On an input error, the frames of the bytes before it are still decoded (each stream of
    /// that input is finished), and the error is returned without reading further inputs.
    pub fn run<H: Handler>(&mut self, handler: &mut H) -> Result<(), H::Error> {
        let inputs = std::mem::take(&mut self.pending);
        for mut input in inputs {
            let base = self.escs.len();
            let index = self.read.len();
            let result = self.read_input(&mut input, index, handler);
            // Streams declared but never heard from are ESCs all the same (as far as an `esc`
            // index can number them: they have no frames).
            let streams = input.streams().min(MAX_ESCS - base.min(MAX_ESCS));
            while self.escs.len() < base + streams {
                self.escs.push(Esc {
                    input: index,
                    name: String::new(),
                    stream: Stream::new(),
                });
            }
            for (i, esc) in self.escs.iter_mut().enumerate().skip(base) {
                if esc.name.is_empty() {
                    esc.name = input.stream_name(i - base);
                }
                // Every stream with bytes has an index below 256 (checked when first seen).
                let id = u8::try_from(i).unwrap_or(u8::MAX);
                esc.stream
                    .finish(|t, d| handler.frame(id, t, d, &self.settings));
            }
            self.read.push(InputInfo {
                name: input.name().to_string(),
                format: input.format(),
                flagged_bytes: input.flagged_bytes(),
                escs: base..self.escs.len(),
            });
            result?;
            handler.end_batch(false)?;
        }
        Ok(())
    }

    fn read_input<H: Handler>(
        &mut self,
        input: &mut Input,
        index: usize,
        handler: &mut H,
    ) -> Result<(), H::Error> {
        let base = self.escs.len();
        loop {
            let batch = match input.next_batch()? {
                Some(batch) => batch,
                None => return Ok(()),
            };
            if self.need_timing && batch.times.is_none() {
                return Err(InputError::NoTiming {
                    input: self.names[index].clone(),
                }
                .into());
            }
            let stream = batch.stream;
            let Ok(id) = u8::try_from(base + stream) else {
                return Err(InputError::TooManyEscs {
                    input: self.names[index].clone(),
                }
                .into());
            };
            while self.escs.len() <= base + stream {
                self.escs.push(Esc {
                    input: index,
                    name: String::new(),
                    stream: Stream::new(),
                });
            }
            let live = batch.bytes.len() < LIVE_BATCH;
            let esc = &mut self.escs[base + stream];
            let settings = &self.settings;
            esc.stream
                .feed(batch, |t, d| handler.frame(id, t, d, settings));
            if esc.name.is_empty() {
                esc.name = input.stream_name(stream);
            }
            handler.end_batch(live)?;
        }
    }
}
