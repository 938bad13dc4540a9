//! Timed decoding: the codec's streaming decoders plus the receive time of each frame.
//!
//! [`Stream`] is one input stream's: every command's frames come out of one (through
//! [`crate::Sources`] for inputs read to their end, through [`PortStreams`] for live
//! port events). Whatever carries its ESCs, it is one [`decoder::LinkDecoder`]: a serial line
//! (`serial.rs`: one ESC's wire or a DataLink hub's) or a CAN bus (`can.rs`), which says how its
//! channels are laid out ([`Stream::layout`]) and gives one set of link figures per channel
//! ([`LinkStats`], `link.rs`). [`crate::clock::byte_times`] is the one place where a chunk's
//! receive time becomes the time of each of its bytes.

use hwfoc::format::LinkKind;
use hwfoc::telemetry::AnyFrame;
use hwfoc::{Protocol, Settings, datalink};

mod can;
mod decoder;
mod forced;
mod link;
mod serial;

pub use self::can::CanLink;
pub(crate) use self::can::{BusLearner, BusPlan, no_status};
use self::decoder::LinkDecoder;
use self::forced::Bus;
pub use self::link::{FIGURES, FRAME_FIGURES, Figure, LinkStats};
use self::serial::{Fast, OneEsc, PassOver, Serial};
use crate::clock::byte_times;
use crate::esc_numbers::{UNNUMBERED, channel_number};
use crate::handler::Handler;

use crate::input::Batch;
use crate::notice::Notice;
use crate::serial::PortEvent;
use crate::settings::SettingsMap;

/// A silence of the line longer than this, between two bytes, may hide a restart of the ESC:
/// the decoder is told of it (see [`hwfoc::foc::Decoder::line_silent`]). Real ESCs send a frame at
/// least every 364 ms (idle), and a read may return a little late.
pub const SILENCE_S: f64 = crate::clock::MAX_STEP_S;

/// Which protocols a stream has been heard speaking, from the frames found so far.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WireKind {
    /// No frame yet.
    Unknown,
    /// One ESC's own wire: HW-FOC frames at 19200 baud.
    Esc,
    /// A Hobbywing DataLink V2 hub: frames of up to eight ESCs at 115200 baud.
    Hub,
    /// Both, one after the other (an adapter moved between an ESC and a hub).
    Mixed,
    /// One ESC's own wire of another format (Hobbywing V4, V3 or HW5: the last one found), or
    /// a CAN bus (the protocol of its first slot's ESC).
    Other(Protocol),
}

/// The decoder of a stream: a fast serial line's, monomorphised, or any other link's.
#[derive(Debug)]
#[allow(clippy::large_enum_variant)]
enum Wire {
    /// Every serial protocol at once, HW-FOC only or DataLink only.
    Fast(Serial<Fast>),
    /// A slower format forced (V4, V3, HW5), a serial line forced to a CAN protocol, a CAN bus.
    Other(Box<dyn LinkDecoder>),
}

impl Wire {
    /// The stream's decoder, as the one link abstraction.
    fn decoder(&self) -> &dyn LinkDecoder {
        match self {
            Wire::Fast(s) => s,
            Wire::Other(d) => d.as_ref(),
        }
    }

    /// The stream's decoder, as the one link abstraction.
    fn decoder_mut(&mut self) -> &mut dyn LinkDecoder {
        match self {
            Wire::Fast(s) => s,
            Wire::Other(d) => d.as_mut(),
        }
    }
}

/// The decoder of a serial line forced to read a format of a slow ESC (V4, V3, HW5: its
/// family's decoder alone), or a CAN protocol (which no serial line carries: every byte is
/// skipped).
fn slow_serial(p: Protocol) -> Box<dyn LinkDecoder> {
    match OneEsc::of(p) {
        Some(one) => Box::new(Serial::new(one)),
        None => Box::new(Serial::new(PassOver::new(p))),
    }
}

impl Default for Stream {
    fn default() -> Self {
        Stream::new()
    }
}

/// A decoder that also gives each frame the receive time of its first byte.
///
/// It reads both protocols at once ([`hwfoc::mixed::Decoder`]): the frames of an ESC's own wire
/// and of a DataLink hub, in byte order, whatever the chunking, also when the stream changes from
/// one to the other; bytes in a frame of either are not skipped bytes of the other. Or, made by
/// [`Stream::forced`], it reads one protocol only: the bytes of any other are skipped bytes. Or,
/// made by [`Stream::can`], it reads a CAN bus's frames.
#[derive(Debug)]
pub struct Stream {
    wire: Wire,
}

impl Stream {
    /// A stream with nothing decoded yet, reading every protocol.
    pub fn new() -> Stream {
        Stream::forced(None)
    }

    /// A stream with nothing decoded yet, reading protocol `forced` only (every protocol when
    /// `None`).
    ///
    /// A CAN protocol forced on a serial stream decodes nothing (its bytes are not CAN
    /// frames): every byte is skipped. A forced stream also reads its first bytes as every
    /// format ([`Stream::found_instead`]).
    pub fn forced(forced: Option<Protocol>) -> Stream {
        let wire = match Fast::of(forced) {
            Ok(fast) => Wire::Fast(Serial::new(fast)),
            Err(slow) => Wire::Other(slow_serial(slow)),
        };
        Stream { wire }
    }

    /// A CAN bus's stream (CAN frames as `LINKTYPE_CAN_SOCKETCAN` records: `can.rs`), nothing
    /// decoded yet.
    pub fn can() -> Stream {
        Stream::can_forced(None)
    }

    /// A CAN bus's stream keeping the records of protocol `forced` only (every record when
    /// `None`): the others, and every record when a serial protocol is forced, are left out
    /// and counted ([`Stream::left_out`]).
    pub fn can_forced(forced: Option<Protocol>) -> Stream {
        Stream {
            wire: Wire::Other(Box::new(Bus::new(forced))),
        }
    }

    /// A new stream of the same layout as this one (a serial line, a CAN bus), reading
    /// protocol `forced` only (every protocol when `None`).
    pub fn renewed(&self, forced: Option<Protocol>) -> Stream {
        match self.layout() {
            LinkKind::Bus => Stream::can_forced(forced),
            LinkKind::OneEsc | LinkKind::Hub { .. } => Stream::forced(forced),
        }
    }

    /// Of a CAN bus's stream read with a protocol forced: the records of other protocols left
    /// out, by protocol (those of which some were).
    pub fn left_out(&self) -> Vec<(Protocol, u64)> {
        self.wire.decoder().left_out()
    }

    /// Fixes the slots of a CAN bus's ESCs ahead (`can.rs`); nothing for any other stream.
    pub(crate) fn plan_can(&mut self, plan: &BusPlan) {
        self.wire.decoder_mut().plan(plan);
    }

    /// A CAN bus's ESCs heard since the last call that claim a throttle channel another holds,
    /// in words (none for any other stream).
    pub(crate) fn take_can_clashes(&mut self) -> Vec<String> {
        self.wire.decoder_mut().take_clashes()
    }

    /// Of a serial stream forced to read one protocol: the protocol of the first frame found
    /// in its first bytes read as every format (64 KiB), when it is not the one forced. What
    /// to tell a user whose forced protocol found nothing.
    pub fn found_instead(&self) -> Option<Protocol> {
        self.wire.decoder().found_instead()
    }

    /// How the stream's channels are laid out: one ESC's wire
    /// ([`OneEsc`](LinkKind::OneEsc)), a line whose channels are a DataLink hub's
    /// ([`Hub`](LinkKind::Hub): read as every format, or as DataLink), or a CAN bus's slots
    /// ([`Bus`](LinkKind::Bus)). What the ESC numbering asks.
    pub fn layout(&self) -> LinkKind {
        self.wire.decoder().layout()
    }

    /// The protocol the stream was made to read only, if any.
    pub fn forced_protocol(&self) -> Option<Protocol> {
        self.wire.decoder().forced()
    }

    /// Decodes a batch; `on_frame(t, channel, frame)` gets each ESC frame with its time
    /// (`None` without timing) and its channel (a DataLink channel, a bus's slot; `None` on
    /// an ESC's own wire).
    #[inline(always)]
    pub fn feed(
        &mut self,
        batch: Batch<'_>,
        mut on_frame: impl FnMut(Option<f64>, Option<u8>, &AnyFrame),
    ) {
        match &mut self.wire {
            Wire::Fast(s) => s.feed_timed(batch, on_frame),
            Wire::Other(d) => d.feed(batch, &mut on_frame),
        }
    }

    /// Decodes bytes without receive times; `on_frame(channel, offset, frame)` gets each ESC
    /// frame with its channel and the stream offset of its first byte.
    pub(crate) fn feed_untimed(
        &mut self,
        bytes: &[u8],
        mut on_frame: impl FnMut(Option<u8>, u64, &AnyFrame),
    ) {
        match &mut self.wire {
            Wire::Fast(s) => s.feed_offsets(bytes, on_frame),
            Wire::Other(d) => d.feed_untimed(bytes, &mut on_frame),
        }
    }

    /// Bytes held for a frame still arriving: none when no byte fed so far waits for a later
    /// one to be decided.
    pub(crate) fn buffered(&self) -> usize {
        self.wire.decoder().buffered()
    }

    /// Every byte fed so far.
    fn bytes(&self) -> u64 {
        self.wire.decoder().bytes()
    }

    /// Continues this stream with `later`'s work ([`hwfoc::StreamDecoder::then`]): `later`, a
    /// stream of the same protocols started new where this one has been fed to, was fed the
    /// rest of the stream's bytes, both without receive times; `first_packet` is the packet
    /// number of its first data frame. Its statistics become those of the whole stream. False,
    /// and nothing changes, when this stream holds bytes, either has times, or the decoders
    /// cannot be joined (only the fast lines' can).
    pub(crate) fn then(&mut self, later: &Stream, first_packet: Option<u16>) -> bool {
        match (&mut self.wire, &later.wire) {
            (Wire::Fast(a), Wire::Fast(b)) => a.then(b, first_packet),
            (Wire::Fast(_) | Wire::Other(_), _) => false,
        }
    }

    /// Ends the stream: a frame cut off at the end is dropped, frames inside it are still found.
    pub fn finish(&mut self, mut on_frame: impl FnMut(Option<f64>, Option<u8>, &AnyFrame)) {
        match &mut self.wire {
            Wire::Fast(s) => s.finish_timed(on_frame),
            Wire::Other(d) => d.finish(&mut on_frame),
        }
    }

    /// Which protocols the stream has been heard speaking.
    pub fn kind(&self) -> WireKind {
        self.wire.decoder().kind()
    }

    /// The link statistics of the stream's ESC: of its own wire, of the hub's channel 0 when
    /// the stream has carried hub frames and no ESC frame of its own, of a bus's slot 0.
    pub fn stats(&self) -> LinkStats {
        self.link(0)
    }

    /// The link statistics of the stream's ESC on `channel`: of a bus's slot; else the hub's
    /// channel once hub frames were found (channel 0: unless the stream also carried ESC
    /// frames of its own, whose statistics are then given), else the ESC's own wire (any
    /// channel). A stream forced to read DataLink only gives the hub's channel from its first
    /// byte.
    pub fn link(&self, channel: u8) -> LinkStats {
        self.wire.decoder().link(channel)
    }

    /// The DataLink hub's statistics, once the stream has carried a hub frame.
    pub fn hub(&self) -> Option<&datalink::Stats> {
        self.wire.decoder().hub()
    }

    /// The receive time of the first byte the decoder holds for a frame still arriving, if it
    /// holds any: no frame completed later can be older (later bytes are no older than the
    /// held ones). `None` when nothing is held or the stream has no times.
    pub(crate) fn held_since(&self) -> Option<f64> {
        self.wire.decoder().held_since()
    }
}

/// How a stream's channel `c` is named to a person.
fn channel_words(layout: LinkKind, c: u8) -> String {
    match layout {
        LinkKind::Bus => format!("place {c} of the bus"),
        LinkKind::OneEsc | LinkKind::Hub { .. } => format!("DataLink channel {c}"),
    }
}

/// What numbers a port's frames into ESCs ([`PortStreams`]): the port's own ESC, a hub's
/// channels and a bus's places after every port's.
struct Numbering<'a> {
    port: usize,
    layout: LinkKind,
    hub: &'a mut Vec<usize>,
    esc_settings: &'a mut Vec<Settings>,
    names: &'a [String],
    map: &'a SettingsMap,
    left_out: &'a mut [u64],
    past_last: &'a mut Vec<Notice>,
}

impl Numbering<'_> {
    /// Hands `d` (of the port's `channel`, at `t`) to `handler` with its ESC number.
    fn hand_on<H: Handler>(
        &mut self,
        t: Option<f64>,
        channel: Option<u8>,
        d: &AnyFrame,
        handler: &mut H,
    ) {
        let Numbering {
            port,
            layout,
            hub,
            esc_settings,
            names,
            map,
            left_out,
            past_last,
        } = self;
        let esc = match channel {
            None => *port,
            Some(c) => {
                // A hub's channels all at once, a bus's slots up to the one heard.
                let places = layout.channels_numbered(c);
                while hub.len() < places {
                    let n = channel_number(*port, esc_settings.len(), hub.len());
                    if n != UNNUMBERED && n != *port {
                        esc_settings.push(map.get(n, &names[*port]));
                    }
                    hub.push(n);
                }
                hub[usize::from(c)]
            }
        };
        if let Ok(id) = u8::try_from(esc) {
            handler.frame(id, t, d, &esc_settings[esc]);
        } else if matches!(d, AnyFrame::Data(_)) {
            if left_out[*port] == 0 {
                past_last.push(Notice::PastLastEsc {
                    input: names[*port].clone(),
                    place: channel.map(|c| channel_words(*layout, c)),
                });
            }
            left_out[*port] += 1;
        }
    }
}

/// A [`Stream`] per port, fed by [`PortEvent`]s: the path from live bytes to timed frames of
/// `monitor`, `record` and the bridges (and of `hwfoc-io`'s `Input::open_ports`, through
/// [`byte_times`]).
///
/// ESC numbers are those [`crate::Sources`] gives a recording of the same ports: port
/// `i` is ESC `i`; a port found to carry a DataLink hub has its channel 0 as that ESC and its
/// channels 1 to 7 as the next numbers after all ports' (in the order the hubs are found), so
/// that a hub read alone numbers its ESCs 0 to 7 by channel and no two ESCs share a number
/// whatever mix of hubs and ESCs is plugged in.
#[derive(Debug)]
pub struct PortStreams {
    streams: Vec<Stream>,
    /// Each port's byte time, ns: at the rate given, or found ([`PortEvent::Found`]).
    per_byte_ns: Vec<f64>,
    /// Each port's rate once known: given, or found.
    bauds: Vec<Option<u32>>,
    /// Bytes each port read at rates an auto-baud search left ([`PortEvent::Searching`]):
    /// skipped bytes that no decoder saw.
    discarded: Vec<u64>,
    times: Vec<f64>,
    /// Each port's name, as the settings know it.
    names: Vec<String>,
    /// The settings by port name and ESC number.
    map: SettingsMap,
    /// The settings of each ESC number given so far (the ports', then hubs' channels): its
    /// length is the next number to give.
    esc_settings: Vec<Settings>,
    /// The ESC number of each channel numbered so far of each port found to be a hub or a CAN
    /// bus (`esc_numbers.rs`).
    hubs: Vec<Vec<usize>>,
    /// Data frames of each port left out, their ESC numbered past 255.
    left_out: Vec<u64>,
    /// Notices of ESCs left out, to be taken ([`PortStreams::take_notices`]).
    past_last: Vec<Notice>,
}

impl PortStreams {
    /// `ports` streams, their bytes arriving at `baud` (8N1), their data frames made records
    /// under `settings`.
    pub fn new(ports: usize, baud: u32, settings: Settings) -> PortStreams {
        PortStreams::with_map(
            baud,
            vec![String::new(); ports],
            SettingsMap::from(settings),
        )
    }

    /// A stream per port of `names`, their bytes arriving at `baud` (8N1), the data frames of
    /// each ESC made records under its settings in `map` (by its number and its port's name,
    /// a hub's channels included).
    pub fn with_map(baud: u32, names: Vec<String>, map: SettingsMap) -> PortStreams {
        PortStreams {
            // A CAN bus (`slcan:`, `can:`) carries CAN frames as records (`can.rs`).
            streams: names
                .iter()
                .map(|n| {
                    if crate::can::is_can_spec(n) {
                        Stream::can()
                    } else {
                        Stream::new()
                    }
                })
                .collect(),
            per_byte_ns: vec![hwfoc::wire::byte_ns(baud); names.len()],
            bauds: names
                .iter()
                .map(|n| (!crate::can::is_can_spec(n)).then_some(baud))
                .collect(),
            discarded: vec![0; names.len()],
            left_out: vec![0; names.len()],
            past_last: Vec::new(),
            times: Vec::new(),
            esc_settings: names
                .iter()
                .enumerate()
                .map(|(esc, name)| map.get(esc, name))
                .collect(),
            hubs: vec![Vec::new(); names.len()],
            names,
            map,
        }
    }

    /// Decodes the bytes of a [`PortEvent::Data`], handing each frame completed to `handler`
    /// with its ESC number (see [`PortStreams`]; records numbered past 255 are not made: the
    /// `esc` column numbers 256). Other events, and ports beyond those made, are ignored.
    /// Returns the port's link statistics after the bytes (of its channel 0, from a hub), or
    /// `None` when there were no bytes for a known port.
    ///
    /// An auto-baud search's events set the port's rate: a [`PortEvent::Searching`] counts the
    /// bytes it left as skipped ([`PortStreams::discarded`]), a [`PortEvent::Found`] sets the
    /// port's byte time and starts its stream again, so that no byte read at another rate is
    /// in a frame.
    pub fn feed<H: Handler>(&mut self, event: &PortEvent, handler: &mut H) -> Option<LinkStats> {
        let (port, t_ns, bytes) = match event {
            PortEvent::Data { port, t_ns, bytes } => (port, t_ns, bytes),
            PortEvent::Searching {
                port, discarded, ..
            } => {
                if let Some(d) = self.discarded.get_mut(*port) {
                    *d += discarded;
                    self.bauds[*port] = None;
                }
                return None;
            }
            PortEvent::Found { port, baud, .. } => {
                self.set_baud(*port, *baud);
                return None;
            }
            PortEvent::Lost { .. } | PortEvent::Back { .. } => return None,
        };
        let (stream, mut numbering, times, per_byte_ns) = self.port(*port)?;
        times.clear();
        byte_times(*t_ns, per_byte_ns, bytes.len(), times);
        stream.feed(
            Batch {
                bytes,
                times: Some(&times[..]),
                stream: *port,
            },
            |t, channel, d| numbering.hand_on(t, channel, d, handler),
        );
        Some(stream.stats())
    }

    /// The stream of `port`, its numbering, the byte times' buffer and its byte time (ns).
    fn port(&mut self, port: usize) -> Option<(&mut Stream, Numbering<'_>, &mut Vec<f64>, f64)> {
        let PortStreams {
            streams,
            per_byte_ns,
            times,
            names,
            map,
            esc_settings,
            hubs,
            left_out,
            past_last,
            ..
        } = self;
        let stream = streams.get_mut(port)?;
        let numbering = Numbering {
            port,
            layout: stream.layout(),
            hub: &mut hubs[port],
            esc_settings,
            names,
            map,
            left_out,
            past_last,
        };
        Some((stream, numbering, times, per_byte_ns[port]))
    }

    /// Ends every port's stream, handing on to `handler` the frames it held (a frame cut off at
    /// the end is dropped; a CAN node's records held for its GetEscID answer come out,
    /// numbered as a recording of the same bytes numbers them).
    pub fn finish<H: Handler>(&mut self, handler: &mut H) {
        for port in 0..self.streams.len() {
            let Some((stream, mut numbering, ..)) = self.port(port) else {
                continue;
            };
            stream.finish(|t, channel, d| numbering.hand_on(t, channel, d, handler));
        }
    }

    /// Makes every port's stream read protocol `protocol` only (see [`Stream::forced`]; a
    /// CAN bus's keeps the records of `protocol` only, [`Stream::can_forced`]); what the
    /// streams decoded before is forgotten, so call it before the first event.
    pub fn force_protocol(&mut self, protocol: Protocol) {
        for stream in self.streams.iter_mut() {
            *stream = stream.renewed(Some(protocol));
        }
    }

    /// Reads `port` at `baud` from now on (its rate found): its byte time changes, and its
    /// stream starts again (reading the same protocols), so that what it held of bytes at
    /// another rate makes no frame.
    pub fn set_baud(&mut self, port: usize, baud: u32) {
        let serial = |s: &&mut Stream| s.layout() != LinkKind::Bus;
        let Some(stream) = self.streams.get_mut(port).filter(serial) else {
            return;
        };
        if self.bauds[port].is_some_and(|b| b != baud) && stream.bytes() > 0 {
            // Bytes fed at another rate: what the decoder holds of a frame still arriving is
            // skipped, never completed by bytes at this rate.
            self.discarded[port] += stream.buffered() as u64;
            *stream = stream.renewed(stream.forced_protocol());
        }
        self.per_byte_ns[port] = hwfoc::wire::byte_ns(baud);
        self.bauds[port] = Some(baud);
    }

    /// Every port's rate is to be found (`hwfoc-io`'s `serial::Baud::Auto`): unknown until its
    /// [`PortEvent::Found`].
    pub fn auto_baud(&mut self) {
        self.bauds.fill(None);
    }

    /// The rate `port` is read at: given, or found; `None` while an auto-baud search goes on.
    pub fn baud(&self, port: usize) -> Option<u32> {
        self.bauds.get(port).copied().flatten()
    }

    /// Bytes of `port` read at rates an auto-baud search left: never decoded, so in none of
    /// [`PortStreams::stats`]'s counts; skipped bytes all the same.
    pub fn discarded(&self, port: usize) -> u64 {
        self.discarded.get(port).copied().unwrap_or(0)
    }

    /// The link statistics of `port`'s stream (of its channel 0, from a hub).
    pub fn stats(&self, port: usize) -> Option<LinkStats> {
        self.streams.get(port).map(Stream::stats)
    }

    /// The stream of `port`.
    pub fn stream(&self, port: usize) -> Option<&Stream> {
        self.streams.get(port)
    }

    /// What the ports' streams found since the last call that a person should be told: on a
    /// live CAN bus, two ESCs that claim one throttle channel (each stays an ESC of its own;
    /// [`Notice::CanBus`] names both nodes); ESCs past number 255, left out
    /// ([`Notice::PastLastEsc`], once per port).
    pub fn take_notices(&mut self) -> Vec<Notice> {
        let mut notices = std::mem::take(&mut self.past_last);
        for (stream, name) in self.streams.iter_mut().zip(&self.names) {
            for message in stream.take_can_clashes() {
                notices.push(Notice::CanBus {
                    input: name.clone(),
                    interface: name.clone(),
                    message,
                });
            }
        }
        notices
    }

    /// Data frames of `port` left out because their ESC would be numbered past 255 (told
    /// once by a [`Notice::PastLastEsc`]).
    pub fn left_out(&self, port: usize) -> u64 {
        self.left_out.get(port).copied().unwrap_or(0)
    }

    /// The settings the records of ESC `esc` are made under, once it has a number.
    pub fn settings_of(&self, esc: u8) -> Option<&Settings> {
        self.esc_settings.get(usize::from(esc))
    }

    /// The DataLink channel that ESC `esc` is on, if `port` is a hub that has handed on
    /// frames and `esc` is one of its channels' numbers.
    pub fn channel_of(&self, port: usize, esc: u8) -> Option<u8> {
        let escs = self.hubs.get(port)?;
        let channel = escs.iter().position(|&e| e == usize::from(esc))?;
        u8::try_from(channel).ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::foc::DataFrame;

    #[test]
    fn frame_times_survive_any_batching() {
        let mut wire = vec![0x9B, 0x00];
        for packet in 0..6u16 {
            wire.extend_from_slice(
                &DataFrame {
                    packet,
                    ..Default::default()
                }
                .encode(),
            );
            wire.push(0x42);
        }
        let times: Vec<f64> = (0..wire.len()).map(|i| i as f64 * 0.5).collect();
        let expected: Vec<f64> = (0..6).map(|k| (2 + 25 * k) as f64 * 0.5).collect();
        for batch in [1, 2, 7, 23, 24, 25, 76, 77, 1000] {
            let mut stream = Stream::new();
            let mut got = Vec::new();
            for (b, t) in wire.chunks(batch).zip(times.chunks(batch)) {
                stream.feed(
                    Batch {
                        bytes: b,
                        times: Some(t),
                        stream: 0,
                    },
                    |t, _, _| got.push(t.unwrap()),
                );
            }
            stream.finish(|t, _, _| got.push(t.unwrap()));
            assert_eq!(got, expected, "batches of {batch}");
        }
    }

    /// Frames `packets`, each 50 ms after the last from `t0`, their bytes timed as on the wire.
    fn timed(packets: &[u16], t0: f64) -> (Vec<u8>, Vec<f64>) {
        let (mut bytes, mut times) = (Vec::new(), Vec::new());
        for (k, &packet) in packets.iter().enumerate() {
            let f = DataFrame {
                packet,
                ..Default::default()
            }
            .encode();
            for (j, &b) in f.iter().enumerate() {
                bytes.push(b);
                times.push(t0 + k as f64 * 0.05 + j as f64 / 1920.0);
            }
        }
        (bytes, times)
    }

    /// The statistics of a stream fed `parts`, each a batch, in batches of `chunk` bytes.
    fn run(parts: &[(Vec<u8>, Vec<f64>)], chunk: usize) -> LinkStats {
        let mut stream = Stream::new();
        for (bytes, times) in parts {
            for (b, t) in bytes.chunks(chunk).zip(times.chunks(chunk)) {
                let batch = Batch {
                    bytes: b,
                    times: Some(t),
                    stream: 0,
                };
                stream.feed(batch, |_, _, _| {});
            }
        }
        stream.finish(|_, _, _| {});
        stream.stats()
    }

    /// A frame begun in bytes without times and ended in timed ones takes the earliest time
    /// known, without a panic.
    #[test]
    fn a_stream_that_becomes_timed_mid_frame() {
        let (bytes, times) = timed(&[7], 100.0);
        let mut stream = Stream::new();
        stream.feed(
            Batch {
                bytes: &bytes[..10],
                times: None,
                stream: 0,
            },
            |_, _, _| panic!("no frame yet"),
        );
        let mut got = Vec::new();
        stream.feed(
            Batch {
                bytes: &bytes[10..],
                times: Some(&times[10..]),
                stream: 0,
            },
            |t, _, _| got.push(t),
        );
        assert_eq!(got, [Some(times[10])]);
    }

    /// The first byte held of a frame still arriving bounds the time of any frame to come.
    #[test]
    fn held_bytes_give_their_first_time() {
        let (bytes, times) = timed(&[7, 8], 100.0);
        let mut stream = Stream::new();
        assert_eq!(stream.held_since(), None);
        // The first frame whole and 10 bytes of the second: those 10 are held.
        let cut = 24 + 10;
        stream.feed(
            Batch {
                bytes: &bytes[..cut],
                times: Some(&times[..cut]),
                stream: 0,
            },
            |_, _, _| {},
        );
        assert_eq!(stream.held_since(), Some(times[24]));
        let mut got = Vec::new();
        stream.feed(
            Batch {
                bytes: &bytes[cut..],
                times: Some(&times[cut..]),
                stream: 0,
            },
            |t, _, _| got.push(t.unwrap()),
        );
        assert_eq!(got, [times[24]]);
        assert_eq!(stream.held_since(), None);
    }

    /// Two adjacent frames swapped on the way: one reordering, no loss, no restart, every
    /// frame delivered (they counted a restart and 2 lost packets, 96 %: issue 29).
    #[test]
    fn two_swapped_frames_are_a_reordering() {
        let s = run(&[timed(&[1, 2, 4, 3, 5, 6], 10.0)], 7);
        assert_eq!(s.frames(), 6);
        assert_eq!((s.lost_packets(), s.restarts()), (0, 0));
        assert_eq!(s.reordered_packets(), 1);
        assert_eq!(s.delivery_ratio(), Some(1.0));
    }

    /// An ESC that restarts after a silence counts a restart, not the packets its new numbers
    /// skip; a silence that only hid frames counts them as lost.
    #[test]
    fn a_silence_tells_a_restart_from_a_loss() {
        let before = timed(&[64_990, 64_991, 64_992], 10.0);
        // 1.5 s later the ESC counts again 536 numbers on (wrapping): a restart, as at most 120
        // frames fit in the silence.
        let restarted = timed(&[65_528, 65_529], 11.6);
        // 2 s later, 30 numbers on: frames lost in the silence.
        let resumed = timed(&[23, 24], 13.7);
        for chunk in [1, 7, 24, 100, 10_000] {
            let s = run(&[before.clone(), restarted.clone(), resumed.clone()], chunk);
            assert_eq!(s.frames(), 7, "chunk {chunk}");
            assert_eq!(s.restarts(), 1, "chunk {chunk}");
            assert_eq!(s.lost_packets(), 29, "chunk {chunk}");
        }
        // The same numbers without the silence: a step of 536 is a loss (the rule for raw
        // bytes), so the silence is what told the restart.
        let close = timed(&[65_528, 65_529], 10.2);
        let s = run(&[before, close], 24);
        assert_eq!((s.restarts(), s.lost_packets()), (0, 535));
    }
}

#[cfg(test)]
mod port_tests {
    use super::*;

    /// An auto-baud search's events: the bytes it left are counted, the rate found sets the
    /// port's byte time, and the frames read at it are decoded.
    #[test]
    fn a_found_rate_is_the_ports_and_the_bytes_left_are_skipped() {
        let names = vec!["a".to_string(), "b".to_string()];
        let map = SettingsMap::from(Settings::DEFAULT);
        let mut streams = PortStreams::with_map(19_200, names, map);
        streams.auto_baud();
        assert_eq!(streams.baud(1), None);
        let searching = PortEvent::Searching {
            port: 1,
            t_ns: 1,
            baud: 115_200,
            discarded: 500,
        };
        assert_eq!(streams.feed(&searching, &mut ()), None);
        let found = PortEvent::Found {
            port: 1,
            t_ns: 2,
            baud: 115_200,
            protocol: Protocol::Hw5,
        };
        assert_eq!(streams.feed(&found, &mut ()), None);
        assert_eq!((streams.baud(0), streams.baud(1)), (None, Some(115_200)));
        let bytes: Vec<u8> = (0..3)
            .flat_map(|_| hwfoc::hw5::TelemetryFrame::default().encode())
            .collect();
        let data = PortEvent::Data {
            port: 1,
            t_ns: 1_000_000_000,
            bytes,
        };
        let link = streams.feed(&data, &mut ()).unwrap();
        assert_eq!((link.protocol(), link.frames()), (Protocol::Hw5, 3));
        assert_eq!(link.bytes_skipped(), 0);
        assert_eq!((streams.discarded(1), streams.discarded(0)), (500, 0));
        assert_eq!(streams.per_byte_ns[1], hwfoc::wire::byte_ns(115_200));
    }
}

#[cfg(test)]
mod mixed_tests {
    use super::*;
    use crate::sources::tests::{hub_wire, wire as esc};

    /// Hub frames `counters`, each with all eight channels.
    fn hub(counters: std::ops::Range<u16>) -> Vec<u8> {
        hub_wire(0, counters, &[0, 1, 2, 3, 4, 5, 6, 7])
    }

    /// The records of `wire` fed to one stream in batches of `chunk` bytes, as `(channel,
    /// packet)`, and the stream.
    fn decode(wire: &[u8], chunk: usize) -> (Vec<(Option<u8>, u16)>, Stream) {
        decode_forced(wire, chunk, None)
    }

    /// [`decode`] by a stream reading `forced` only (every protocol when `None`).
    pub(super) fn decode_forced(
        wire: &[u8],
        chunk: usize,
        forced: Option<Protocol>,
    ) -> (Vec<(Option<u8>, u16)>, Stream) {
        let mut stream = Stream::forced(forced);
        let mut got = Vec::new();
        let mut on = |_: Option<f64>, channel: Option<u8>, frame: &AnyFrame| {
            if let AnyFrame::Data(f) = frame {
                got.push((
                    channel,
                    hwfoc::Telemetry::packet(f).unwrap_or_default() as u16,
                ));
            }
        };
        for b in wire.chunks(chunk) {
            let batch = Batch {
                bytes: b,
                times: None,
                stream: 0,
            };
            stream.feed(batch, &mut on);
        }
        stream.finish(&mut on);
        (got, stream)
    }

    /// One hub frame and then 2000 ESC frames: every frame is decoded, in byte order, and no
    /// byte is skipped (the first frame once decided the protocol: 8 records, 48 000 bytes
    /// skipped).
    #[test]
    fn a_hub_frame_then_esc_frames_are_all_decoded() {
        let mut wire = hub(0..1);
        wire.extend(esc(0..2000));
        let mut expected: Vec<(Option<u8>, u16)> =
            (0..8).map(|c| (Some(c), 1000 + u16::from(c))).collect();
        expected.extend((0..2000).map(|p| (None, p)));
        for chunk in [1, 7, 24, 100, 160, 4096, wire.len()] {
            let (got, stream) = decode(&wire, chunk);
            assert_eq!(got, expected, "chunk {chunk}");
            assert_eq!(stream.kind(), WireKind::Mixed);
            assert_eq!(stream.stats().bytes_skipped(), 0, "chunk {chunk}");
            assert_eq!(stream.stats().frames(), 2000);
            assert_eq!(stream.link(3).frames(), 1);
            assert_eq!(stream.hub().map(|h| h.bytes_skipped()), Some(0));
        }
    }

    /// ESC frames, then hub frames (an adapter moved from an ESC to a hub), then ESC frames
    /// again: none is lost whatever the chunking, and each protocol's packet and frame
    /// numbers run on without a loss.
    #[test]
    fn a_stream_that_changes_protocol_loses_no_frame() {
        let mut wire = esc(0..200);
        wire.extend(hub(0..200));
        wire.extend(esc(200..210));
        for chunk in [1, 5, 24, 159, 161, 1000, 4800, wire.len()] {
            let (got, stream) = decode(&wire, chunk);
            assert_eq!(got.len(), 200 + 200 * 8 + 10, "chunk {chunk}");
            assert_eq!(got[199], (None, 199));
            assert_eq!(got[200], (Some(0), 1000));
            assert_eq!(got[200 + 1600], (None, 200));
            let s = stream.stats();
            assert_eq!(
                (s.frames(), s.lost_packets(), s.bytes_skipped()),
                (210, 0, 0)
            );
            let hub = stream.hub().unwrap();
            assert_eq!(
                (hub.frames(), hub.lost_packets(), hub.checksum_failures()),
                (200, 0, 0)
            );
            assert_eq!(s.checksum_failures(), 0);
        }
    }
}

#[cfg(test)]
mod forced_tests {
    use super::*;
    use crate::sources::tests::{hub_wire, wire as esc};

    /// The records of `wire` read by a stream forced to `protocol`, fed in `chunk`-byte
    /// batches, as `(channel, packet)`, and the stream.
    fn decode(wire: &[u8], chunk: usize, protocol: Protocol) -> (Vec<(Option<u8>, u16)>, Stream) {
        super::mixed_tests::decode_forced(wire, chunk, Some(protocol))
    }

    /// ESC frames, hub frames, ESC frames: a stream forced to one protocol hands on that
    /// protocol's frames only and counts the other's bytes as skipped.
    #[test]
    fn a_forced_protocol_reads_its_frames_only() {
        let mut wire = esc(0..20);
        let hub = hub_wire(0, 0..3, &[0, 1, 2, 3, 4, 5, 6, 7]);
        wire.extend(&hub);
        wire.extend(esc(20..30));
        for chunk in [1, 24, 161, wire.len()] {
            let (got, stream) = decode(&wire, chunk, Protocol::HwFoc);
            assert_eq!(got, (0..30).map(|p| (None, p)).collect::<Vec<_>>());
            assert_eq!(stream.forced_protocol(), Some(Protocol::HwFoc));
            assert_eq!(stream.kind(), WireKind::Esc);
            assert_eq!(stream.hub(), None);
            let s = stream.stats();
            assert_eq!((s.frames(), s.bytes_skipped()), (30, hub.len() as u64));

            let (got, stream) = decode(&wire, chunk, Protocol::DataLink);
            assert_eq!(got.len(), 3 * 8, "chunk {chunk}");
            assert!(got.iter().all(|(c, _)| c.is_some()));
            assert_eq!(stream.kind(), WireKind::Hub);
            let s = stream.stats();
            assert_eq!(s.protocol(), Protocol::DataLink);
            assert_eq!(s.bytes_skipped(), 30 * 24, "chunk {chunk}");
            assert_eq!(stream.hub().map(|h| h.frames()), Some(3));
        }
        // Forced to DataLink, a stream of ESC frames only is a hub link that found nothing.
        let (got, stream) = decode(&esc(0..10), 24, Protocol::DataLink);
        assert!(got.is_empty());
        assert_eq!(stream.stats().protocol(), Protocol::DataLink);
        assert_eq!(stream.stats().bytes_skipped(), 240);
        assert_eq!(stream.kind(), WireKind::Unknown);
    }
}
