//! Several inputs read one after another, one decoding [`Stream`] per ESC.
//!
//! Inputs given together on the command line are read in the order given. Each stream of each
//! input is one ESC, numbered in the order the streams are first seen (a file has one stream,
//! a recording one per interface, a set of serial ports one per port), with one exception:
//! recordings name the port of each interface, and the interfaces of recordings given together
//! that name the same port are one ESC, one continuous stream (the files of a rotated recording
//! decode exactly as their bytes concatenated: a frame split between two files is whole).

use std::collections::HashMap;

use hwfoc::datalink::{CHANNELS, DatalinkStats};
use hwfoc::{Decoded, Settings};

pub use crate::handler::Handler;
use crate::input::{Input, InputError, InputFormat};
use crate::settings::SettingsMap;
use crate::stream::{EscLink, Stream};

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
}

/// The inputs of a command and the ESCs found in them.
pub struct Sources {
    settings: SettingsMap,
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
        let name = self.escs.get(esc).map_or("", |e| e.name.as_str());
        self.settings.get(esc, name)
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

    /// Reads every input to its end, in order, handing each frame and the end of each batch
    /// to `handler`.
    ///
    /// On an input error, the frames of the bytes before it are still decoded (every stream is
    /// finished), and the error is returned without reading further inputs.
    pub fn run<H: Handler>(&mut self, handler: &mut H) -> Result<(), H::Error> {
        let inputs = std::mem::take(&mut self.pending);
        let mut result = Ok(());
        for mut input in inputs {
            let index = self.read.len();
            let mut escs = Vec::new();
            let mut bytes = 0;
            result = self.read_input(&mut input, index, &mut escs, &mut bytes, handler);
            // Streams declared but never heard from are ESCs all the same (as far as an `esc`
            // index can number them: they have no frames).
            for stream in 0..input.streams() {
                if self.esc_of(&input, index, stream, &mut escs).is_err() {
                    break;
                }
            }
            // A recorded port's stream may go on in the next recording: it is finished at the
            // end of the run. Other streams end with their input.
            if input.format() != InputFormat::Recording {
                for &esc in escs.iter().flatten() {
                    self.finish(esc, handler);
                }
            }
            self.read.push(InputInfo {
                name: input.name().to_string(),
                format: input.format(),
                flagged_bytes: input.flagged_bytes(),
                bytes,
                escs: escs.into_iter().flatten().collect(),
            });
            if result.is_err() {
                break;
            }
            result = handler.end_batch(false);
            if result.is_err() {
                break;
            }
        }
        for esc in 0..self.escs.len() {
            self.finish(esc, handler);
        }
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

    /// Ends the stream of ESC `esc`: a frame cut off at the end is dropped, frames inside it
    /// are still found. Harmless on a stream already finished.
    fn finish<H: Handler>(&mut self, esc: usize, handler: &mut H) {
        // Every stream has an index below 256 (checked when it was made).
        let id = u8::try_from(esc).unwrap_or(u8::MAX);
        let settings = &self.esc_settings(esc);
        let hub = self.hubs.get(&esc);
        let mut pending = Vec::new();
        self.escs[esc].stream.finish(
            #[inline(always)]
            |t, channel, d| route(id, hub, t, channel, d, settings, handler, &mut pending),
        );
        self.deliver(esc, pending, handler);
    }

    /// Hands on the frames of a stream just found to come from a DataLink hub, once its
    /// channels have ESCs (made here, in channel order: channel 0 is the stream's own ESC).
    fn deliver<H: Handler>(&mut self, esc: usize, pending: Vec<Pending>, handler: &mut H) {
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
                    self.escs.push(Esc {
                        input: self.escs[esc].input,
                        name: self.escs[esc].name.clone(),
                        stream: Stream::new(),
                        hub: Some((esc, channel as u8)),
                    });
                }
                let settings = escs.map(|e| self.esc_settings(e));
                let hub = Hub { escs, settings };
                self.hubs.insert(esc, hub);
                hub
            }
        };
        for (t, channel, d) in pending {
            let c = usize::from(channel);
            if let Ok(id) = u8::try_from(hub.escs[c]) {
                handler.frame(id, t, &d, &hub.settings[c]);
            }
        }
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
                self.escs.push(Esc {
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
        Ok(esc)
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
                |t, channel, d| route(id, hub, t, channel, d, settings, handler, &mut pending),
            );
            self.deliver(esc, pending, handler);
            handler.end_batch(len < LIVE_BATCH)?;
        }
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

/// Hands a frame of the stream of ESC `id` to `handler`: as that ESC's on its own wire, as its
/// channel's ESC behind a hub whose channels are numbered (`hub`), or else into `pending`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn route<H: Handler>(
    id: u8,
    hub: Option<&Hub>,
    t: Option<f64>,
    channel: Option<u8>,
    d: &Decoded,
    settings: &Settings,
    handler: &mut H,
    pending: &mut Vec<Pending>,
) {
    match (channel, hub) {
        (None, _) => handler.frame(id, t, d, settings),
        (Some(c), Some(hub)) => {
            let c = usize::from(c);
            if let Ok(esc) = u8::try_from(hub.escs[c]) {
                handler.frame(esc, t, d, &hub.settings[c]);
            }
        }
        (Some(c), None) => pending.push((t, c, *d)),
    }
}

#[cfg(test)]
mod tests {
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
    fn wire(packets: std::ops::Range<u16>) -> Vec<u8> {
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
    /// order given; each port's bytes in packets of 7 bytes, 1 ms apart.
    fn recording(ports: &[(&str, &[u8], u64)]) -> Vec<u8> {
        let mut w = pcapng::Writer::new(Vec::new()).unwrap();
        for (port, _, _) in ports {
            w.add_interface(port, 19200).unwrap();
        }
        for (i, (_, bytes, t0)) in ports.iter().enumerate() {
            for (k, piece) in bytes.chunks(7).enumerate() {
                w.write(i as u32, t0 + k as u64 * 1_000_000, piece).unwrap();
            }
        }
        w.into_inner().unwrap()
    }

    fn run(inputs: Vec<Vec<u8>>) -> (ByEsc, Sources) {
        let inputs = inputs
            .into_iter()
            .enumerate()
            .map(|(i, bytes)| Input::from_memory(&format!("rec-{i}.pcapng"), bytes).unwrap())
            .collect();
        let mut sources = Sources::new(inputs, Settings::DEFAULT);
        let mut got = ByEsc::default();
        sources.run(&mut got).unwrap();
        (got, sources)
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
        let ms = 1_000_000;
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

    /// Files other than recordings are one ESC each, as before.
    #[test]
    fn files_without_port_names_are_one_esc_each() {
        let raw = |p| Input::from_memory("a.bin", wire(p)).unwrap();
        let mut sources = Sources::new(vec![raw(0..3), raw(0..3)], Settings::DEFAULT);
        let mut got = ByEsc::default();
        sources.run(&mut got).unwrap();
        assert_eq!(sources.escs().len(), 2);
        assert_eq!((got.0[0].len(), got.0[1].len()), (3, 3));
    }
}
