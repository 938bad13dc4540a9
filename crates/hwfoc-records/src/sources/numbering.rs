//! Which stream of which input is which ESC: an input's streams in the order given, the
//! streams of one port in one recording one ESC (`esc_table.rs`), a hub's channels after all
//! inputs' streams (see [`super`]).

use std::collections::VecDeque;

use hwfoc::Settings;
use hwfoc::format::LinkKind;
use hwfoc::telemetry::AnyFrame;

use super::{Esc, Handler, Sources};
use crate::esc_numbers::{MAX_ESCS, UNNUMBERED, channel_number};
use crate::esc_table::{EscKey, Place, Recording};
use crate::input::{Input, InputError};
use crate::stream::Stream;

impl Sources {
    /// Hands on the frames of a stream found to carry several ESCs (a DataLink hub's channels,
    /// a CAN bus's slots) whose channel has no ESC yet, once it has one (made here, in channel
    /// order: channel 0 is the stream's own ESC): to a handler, or to the time-order queue.
    /// A hub's eight channels are numbered at once; a bus's slots up to the highest one heard
    /// (`esc_numbers.rs`; a bus read ahead had all its slots numbered with its stream).
    pub(super) fn deliver<H: Handler>(
        &mut self,
        esc: usize,
        pending: Vec<Pending>,
        to: &mut Deliver<'_, H>,
    ) {
        if pending.is_empty() {
            return;
        }
        let layout = self.escs[esc].stream.layout();
        let heard = pending.iter().filter_map(|p| p.1).max();
        let places = layout.channels_numbered(heard.unwrap_or(0));
        self.grow_hub(esc, places);
        let own = self.esc_settings(esc);
        let hub = &self.hubs[&esc];
        let mut unnumbered = false;
        for (t, channel, d) in pending {
            // The stream's own frames that came after a hub frame in its batch, in their place.
            let Some(channel) = channel else {
                match to {
                    Deliver::Handler(handler) => handler.frame(esc as u8, t, &d, &own),
                    Deliver::Queue => self.queue.push(esc, t, &d),
                }
                continue;
            };
            let c = usize::from(channel);
            let Some(&id) = hub.escs.get(c).filter(|&&e| e != UNNUMBERED) else {
                unnumbered = true;
                continue;
            };
            match to {
                Deliver::Handler(handler) => {
                    handler.frame(id as u8, t, &d, &hub.settings[c]);
                }
                Deliver::Queue => self.queue.push(id, t, &d),
            }
        }
        // An ESC past the last number: told at the end of the run (`Sources::run`).
        if unnumbered {
            self.unnumbered.get_or_insert(self.table[esc].input);
        }
    }

    /// Numbers the channels of the stream of ESC `esc` up to `places` (see
    /// [`channel_number`]): each a new ESC of the stream's input.
    fn grow_hub(&mut self, esc: usize, places: usize) {
        let mut hub = self.hubs.remove(&esc).unwrap_or_default();
        while hub.escs.len() < places {
            let channel = hub.escs.len();
            let number = channel_number(esc, self.escs.len(), channel);
            if number != UNNUMBERED && number != esc {
                debug_assert_eq!(number, self.escs.len());
                let owner = &self.table[esc];
                let key = EscKey {
                    place: Place::Channel(channel as u8),
                    ..owner.key.clone()
                };
                let input = owner.input;
                self.push_esc(
                    Esc {
                        stream: Stream::forced(self.forced),
                        hub: Some((esc, channel as u8)),
                    },
                    key,
                    input,
                );
            }
            hub.settings.push(self.esc_settings(number));
            hub.escs.push(number);
        }
        self.hubs.insert(esc, hub);
    }

    /// A new ESC, `key` of input `input`, its settings looked up once. A CAN bus read ahead
    /// (`can_plan.rs`) has its ESCs' slots fixed and numbered at once, so that its ESCs'
    /// numbers follow each other whatever is heard on other buses meanwhile.
    fn push_esc(&mut self, mut esc: Esc, key: EscKey, input: usize) {
        let plan = match esc.stream.layout() {
            LinkKind::Bus => self.buses.get(&(key.recording, key.port.clone())).cloned(),
            LinkKind::OneEsc | LinkKind::Hub { .. } => None,
        };
        if let Some(plan) = &plan {
            esc.stream.plan_can(plan);
        }
        let settings = self.settings.get(self.escs.len(), &key.port);
        self.table.push(key, input);
        self.escs.push(esc);
        self.esc_settings.push(settings);
        self.readers.push(0);
        self.fed.push(None);
        self.span.push(None);
        if let Some(plan) = plan.filter(|p| !p.is_empty()) {
            self.grow_hub(self.escs.len() - 1, plan.len());
        }
    }

    /// The recording input `index` is a part of (`esc_table.rs`): one of its own unless it
    /// names one (hwfoc's recordings) or the recordings are joined (`--join`).
    pub(super) fn recording_of(&self, input: &Input, index: usize) -> Recording {
        match (self.join, input.recording_id()) {
            (true, _) if input.format().has_recorded_ports() => Recording::Joined,
            (_, Some(id)) => Recording::Id(id),
            _ => Recording::Input(index),
        }
    }

    /// The ESC of stream `stream` of `input` (number `index`), made when first seen; `escs`
    /// holds the ESCs of the input's streams so far.
    pub(super) fn esc_of(
        &mut self,
        input: &Input,
        index: usize,
        stream: usize,
        escs: &mut Vec<Option<usize>>,
    ) -> Result<usize, InputError> {
        if let Some(&Some(esc)) = escs.get(stream) {
            return Ok(esc);
        }
        let key = EscKey {
            recording: self.recording_of(input, index),
            port: input.stream_name(stream),
            place: Place::Own,
        };
        // A port's stream in a recording that an earlier input of it had (a rotated series).
        let earlier = self.table.find(&key).filter(|e| !escs.contains(&Some(*e)));
        let esc = match earlier {
            Some(esc) => esc,
            None => {
                if self.escs.len() >= MAX_ESCS {
                    return Err(InputError::TooManyEscs {
                        input: self.names[index].clone(),
                    });
                }
                // A CAN bus's stream reads CAN frames, keeping the forced protocol's records.
                let stream = if input.is_can(stream) {
                    Stream::can_forced(self.forced)
                } else {
                    Stream::forced(self.forced)
                };
                // (A CAN bus read ahead numbers its ESCs after its own at once.)
                let esc = self.escs.len();
                self.push_esc(Esc { stream, hub: None }, key, index);
                esc
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
    pub(super) fn number_streams(
        &mut self,
        input: &Input,
        index: usize,
        escs: &mut Vec<Option<usize>>,
    ) {
        for stream in 0..input.streams() {
            if self.is_silent_bus(input, index, stream) {
                continue;
            }
            if self.esc_of(input, index, stream, escs).is_err() {
                break;
            }
        }
    }

    /// Numbers the streams of the inputs before they are read (one for a file or standard
    /// input, one per port), in the order given up to the first recording (which declares its
    /// ports as it is read: they and the inputs after them are numbered as they are read): the
    /// channels of a DataLink hub, found later in any of them, take numbers after all of these,
    /// as they do live (see [`PortStreams`](crate::PortStreams)).
    pub(super) fn number_inputs(&mut self, inputs: &VecDeque<Input>) {
        let base = self.read.len();
        self.numbered.resize(base, Vec::new());
        for (k, input) in inputs.iter().enumerate() {
            if input.format().has_recorded_ports() {
                break;
            }
            let mut escs = Vec::new();
            // A copy of an earlier input is not read: it has no ESC.
            if self.duplicates.get(base + k).copied().flatten().is_some() {
                self.numbered.push(escs);
                continue;
            }
            self.number_streams(input, base + k, &mut escs);
            self.numbered.push(escs);
        }
    }

    /// The ESCs of input `index`'s streams numbered before it was read.
    pub(super) fn numbered(&mut self, index: usize) -> Vec<Option<usize>> {
        self.numbered
            .get_mut(index)
            .map(std::mem::take)
            .unwrap_or_default()
    }
}

/// The ESCs of the channels numbered so far of a DataLink hub or a CAN bus, and their
/// settings.
#[derive(Debug, Clone, Default)]
pub(super) struct Hub {
    escs: Vec<usize>,
    settings: Vec<Settings>,
}

/// A frame of a channel that has no ESC yet (its time, channel and frame), or of the stream's
/// own ESC (channel `None`) that came after one in its batch, kept in its place.
pub(super) type Pending = (Option<f64>, Option<u8>, AnyFrame);

/// The ESC a frame of the stream of ESC `own` belongs to: `own` on its own wire; behind a hub
/// whose channels are numbered (`hub`), its channel's ESC with that ESC's settings; `None` for a
/// channel the `esc` column cannot number, or when the channel is not numbered yet (the frame
/// then waits in `pending`).
#[inline(always)]
pub(super) fn route<'h>(
    own: usize,
    hub: Option<&'h Hub>,
    t: Option<f64>,
    channel: Option<u8>,
    d: &AnyFrame,
    pending: &mut Vec<Pending>,
) -> Option<(usize, Option<&'h Settings>)> {
    match (channel, hub) {
        (None, _) => Some((own, None)),
        (Some(c), Some(hub)) if usize::from(c) < hub.escs.len() => {
            let c = usize::from(c);
            if hub.escs[c] == UNNUMBERED {
                // To `Sources::deliver`, which tells of it.
                pending.push((t, Some(c as u8), *d));
                return None;
            }
            Some((hub.escs[c], Some(&hub.settings[c])))
        }
        (Some(c), _) => {
            pending.push((t, Some(c), *d));
            None
        }
    }
}

/// Where [`Sources::deliver`] hands frames: a handler, or the time-order queue.
pub(super) enum Deliver<'a, H> {
    Handler(&'a mut H),
    Queue,
}
