//! A pcapng recording as an input: packets gathered per port into batches.

use std::io::Read;

use super::end::End;
use super::{InputError, InputFormat, Looks, Source};
use crate::clock::byte_times;
use crate::notice::Notice;
use crate::pcapng;
use crate::time::Clock;

/// A pcapng recording being read.
///
/// Packets of the ports of a recording interleave, a few bytes each. They are gathered per
/// port over a window of [`RECORDING_WINDOW_NS`] of recording time (or until a port has
/// [`RECORDING_BATCH`] bytes), and each port's bytes of the window are handed out as one
/// batch, in the order of their first byte's time: so batches are kilobytes rather than a
/// frame (decoding an 8-port recording is ten times faster), and come in order of their first
/// byte's time (packets of a recording are in time order), which is what
/// [`crate::Sources`] needs to hand records of every port on in time order.
pub(super) struct RecordingReader {
    reader: pcapng::Reader<Box<dyn Read>>,
    /// The interfaces with bytes in the current window, in the order of their first packet,
    /// each with its bytes and their receive times; once the window is read, in the order of
    /// their first byte's time, `handed` of them handed out.
    pending: Vec<Gathered>,
    /// The place in `pending` of each interface with bytes in the current window. (Only those:
    /// a recording declaring a million interfaces costs nothing per window for the silent.)
    slot: std::collections::HashMap<u32, usize>,
    /// How many of `pending` were handed out.
    handed: usize,
    /// Buffers of earlier windows, to be filled again.
    spare: Vec<(Vec<u8>, Vec<f64>)>,
    /// Whether the window's batches are being handed out.
    draining: bool,
    /// Time of the first packet of the current window.
    window_start: Option<u64>,
    /// The file is read to its end (or to a read error, kept there until handed out).
    end: End,
    /// Interfaces whose link type is not telemetry, already warned about.
    skipped: std::collections::HashSet<u32>,
    /// Packets of CAN interfaces that are not classic CAN frames (CAN FD), by interface: told
    /// at the end.
    not_classic: std::collections::BTreeMap<u32, u64>,
}

/// One interface's bytes of a window.
struct Gathered {
    iface: u32,
    bytes: Vec<u8>,
    times: Vec<f64>,
}

/// Recording time gathered per port before its bytes are handed out (10 s: 4.8 kB of frames
/// per port at 20 frames a second).
pub(super) const RECORDING_WINDOW_NS: u64 = 10_000_000_000;
/// Most bytes gathered for one port before the window's batches are handed out.
const RECORDING_BATCH: usize = 1 << 18;

impl RecordingReader {
    /// Reads the recording `reader` gives.
    pub(super) fn new(reader: Box<dyn Read>) -> RecordingReader {
        RecordingReader {
            reader: pcapng::Reader::new(reader),
            pending: Vec::new(),
            slot: Default::default(),
            handed: 0,
            spare: Vec::new(),
            draining: false,
            window_start: None,
            end: End::default(),
            skipped: Default::default(),
            not_classic: Default::default(),
        }
    }

    /// The interfaces (ports) the recording has declared so far.
    pub(super) fn interfaces(&self) -> &[pcapng::Interface] {
        self.reader.interfaces()
    }

    /// Reads packets into the per-interface buffers until the window is over, a buffer is
    /// full, or the file ends.
    fn read_window(
        &mut self,
        name: &str,
        notices: &mut dyn FnMut(Notice),
    ) -> Result<(), InputError> {
        self.window_start = None;
        loop {
            let packet = self
                .reader
                .next_packet()
                .map_err(|source| InputError::Read {
                    input: name.to_string(),
                    source,
                });
            let packet = match packet {
                Ok(Some(p)) => p,
                Ok(None) => {
                    self.end.reach();
                    self.report_damage(name, notices);
                    for (&iface, &frames) in &self.not_classic {
                        notices(Notice::NotClassicCan {
                            input: name.to_string(),
                            interface: self.reader.interfaces()[iface as usize].name.clone(),
                            frames,
                        });
                    }
                    return Ok(());
                }
                Err(e) => {
                    self.report_damage(name, notices);
                    return Err(e);
                }
            };
            let (iface, t_ns, interface) = (packet.iface, packet.t_ns, packet.interface);
            if let Some(text) = packet.comment {
                notices(Notice::Comment {
                    input: name.to_string(),
                    interface: interface.name.clone(),
                    text: text.to_string(),
                });
            }
            let mut full = false;
            let mut data = packet.data;
            let record;
            if interface.is_can() && !data.is_empty() {
                // A CAN frame: its record, each byte at the frame's time.
                match packet.can_frame() {
                    Some(frame) => {
                        record = frame.to_socketcan_record();
                        data = &record;
                    }
                    None => {
                        *self.not_classic.entry(iface).or_default() += 1;
                        data = &crate::can::NOT_CLASSIC_RECORD;
                    }
                }
            }
            let per_byte_ns = if interface.is_can() {
                0.0
            } else {
                interface.byte_ns()
            };
            if data.is_empty() {
                // A note only (or a CAN frame not read).
            } else if !interface.is_user_link_type() && !interface.is_can() {
                if self.skipped.insert(iface) {
                    notices(Notice::ForeignInterface {
                        input: name.to_string(),
                        interface: interface.name.clone(),
                        link_type: interface.link_type,
                    });
                }
            } else {
                let i = *self.slot.entry(iface).or_insert_with(|| {
                    let (bytes, times) = self.spare.pop().unwrap_or_default();
                    self.pending.push(Gathered {
                        iface,
                        bytes,
                        times,
                    });
                    self.pending.len() - 1
                });
                let Gathered { bytes, times, .. } = &mut self.pending[i];
                byte_times(t_ns, per_byte_ns, data.len(), times);
                bytes.extend_from_slice(data);
                let start = *self.window_start.get_or_insert(t_ns);
                full = bytes.len() >= RECORDING_BATCH
                    || t_ns.saturating_sub(start) >= RECORDING_WINDOW_NS;
            }
            self.report_damage(name, notices);
            if full {
                return Ok(());
            }
        }
    }

    fn report_damage(&mut self, name: &str, notices: &mut dyn FnMut(Notice)) {
        for damage in self.reader.take_damage() {
            notices(Notice::Damage {
                input: name.to_string(),
                damage,
            });
        }
    }
}

impl InputFormat {
    /// A pcapng recording: one stream per interface, each the port it names, times from the
    /// packets' timestamps (Unix seconds).
    pub const RECORDING: InputFormat = InputFormat {
        name: "pcapng recording",
        short_name: "pcapng",
        clock: Clock::Wall,
        live: false,
        recorded_ports: true,
    };
}

/// Whether `head`, an input's first bytes (12 of them, or all there are), starts a pcapng
/// recording: the section header's type, 0A 0D 0D 0A, and its byte-order magic at bytes 8..12.
pub(super) fn is_start(head: &[u8]) -> bool {
    head.starts_with(&pcapng::MAGIC)
        && (head.len() < 12
            || matches!(
                head[8..12],
                [0x4D, 0x3C, 0x2B, 0x1A] | [0x1A, 0x2B, 0x3C, 0x4D]
            ))
}

impl Source for RecordingReader {
    fn recording_id(&self) -> Option<pcapng::RecordingId> {
        self.reader.recording_id()
    }

    fn format(&self) -> InputFormat {
        InputFormat::RECORDING
    }

    /// Hands out the next batch of the current window into `bytes` and `times` and returns
    /// its interface, reading the next window when this one is done;
    /// leaves `bytes` empty at the end of the file. A read error is returned after the
    /// bytes before it. Damage and notes in the file are told to `notices` as they are met.
    fn fill(
        &mut self,
        name: &str,
        bytes: &mut Vec<u8>,
        times: &mut Vec<f64>,
        notices: &mut dyn FnMut(Notice),
    ) -> Result<usize, InputError> {
        bytes.clear();
        loop {
            if self.draining {
                // The window's ports in the order of their first byte: batches of a recording
                // come in order of their first byte's time (what `Sources` merges by).
                if let Some(next) = self.pending.get_mut(self.handed) {
                    self.handed += 1;
                    std::mem::swap(bytes, &mut next.bytes);
                    std::mem::swap(times, &mut next.times);
                    return Ok(next.iface as usize);
                }
                self.draining = false;
            }
            if let Some(result) = self.end.result() {
                return result;
            }
            for mut done in self.pending.drain(..) {
                done.bytes.clear();
                done.times.clear();
                self.spare.push((done.bytes, done.times));
            }
            self.slot.clear();
            self.handed = 0;
            if let Err(e) = self.read_window(name, notices) {
                self.end.fail(e);
            }
            self.pending
                .sort_by(|a, b| (a.times[0].total_cmp(&b.times[0])).then(a.iface.cmp(&b.iface)));
            self.draining = true;
        }
    }

    fn streams(&self) -> usize {
        self.interfaces().len()
    }

    fn stream_name(&self, i: usize) -> Option<&str> {
        self.interfaces().get(i).map(|f| f.name.as_str())
    }

    fn is_can(&self, stream: usize) -> bool {
        self.interfaces().get(stream).is_some_and(|f| f.is_can())
    }

    fn flagged_bytes(&self) -> u64 {
        // A recording holds the bytes as read from the port, unflagged.
        0
    }

    fn looks(&self) -> Option<Looks> {
        None
    }
}
