//! Timed decoding: the codec's streaming decoder plus the receive time of each frame.
//!
//! [`Stream`] is one ESC's stream: every command's frames come out of one (through
//! [`crate::Sources`] for inputs read to their end, through [`PortStreams`] for live
//! port events). [`crate::clock::byte_times`] is the one place where a chunk's receive time
//! becomes the time of each of its bytes.

use hwfoc::counters::{PacketSequence, PacketSequence24};
use hwfoc::telemetry::{AnyFrame, Data, Info};
use hwfoc::{Protocol, Settings, foc};
use hwfoc::{datalink, detect, hw5, mixed, v3, v4};

mod can;
mod forced;

pub use self::can::CanLink;
pub(crate) use self::can::{BusLearner, BusPlan, no_status};
use self::forced::{Bus, Probe};
use crate::clock::byte_times;
use crate::esc_numbers::{UNNUMBERED, channel_number};
use crate::handler::Handler;

use crate::input::Batch;
use crate::notice::Notice;
use crate::serial::PortEvent;
use crate::settings::SettingsMap;

/// How many receive times to keep from earlier batches: a frame still arriving is shorter than
/// the longest frame (a DataLink frame, 160 bytes), so its first byte is never further back
/// than this.
const TIME_HISTORY: usize = if hwfoc::foc::MAX_FRAME_LEN > datalink::FRAME_LEN {
    hwfoc::foc::MAX_FRAME_LEN
} else {
    datalink::FRAME_LEN
};

/// A silence of the line longer than this, between two bytes, may hide a restart of the ESC:
/// the decoder is told of it (see [`hwfoc::foc::Decoder::line_silent`]). Real ESCs send a frame at
/// least every 364 ms (idle), and a read may return a little late.
pub const SILENCE_S: f64 = crate::clock::MAX_STEP_S;

/// The most data frames of `protocol` a silence of `seconds` can have hidden: one per frame
/// length of byte times at its baud rate, the fastest the line carries them (real ESCs send
/// far fewer).
fn frames_in_of(protocol: Protocol, seconds: f64) -> u32 {
    // (A bus's stream is not told of silences: its record length is never asked here.)
    let len = protocol.description().data_frame_len;
    let frame_s = len as f64 * hwfoc::wire::byte_ns(protocol.baud_rate()) * 1e-9;
    (seconds / frame_s).ceil().min(f64::from(u32::MAX)) as u32
}

/// The most HW-FOC data frames a silence of `seconds` can have hidden (see [`frames_in_of`]).
fn frames_in(seconds: f64) -> u32 {
    frames_in_of(Protocol::HwFoc, seconds)
}

/// The most DataLink frames a silence of `seconds` can have hidden (see [`frames_in_of`]).
fn hub_frames_in(seconds: f64) -> u32 {
    frames_in_of(Protocol::DataLink, seconds)
}

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
    /// One ESC's own wire of another format: Hobbywing V4, V3 or HW5 (the last one found).
    Other(Protocol),
}

/// Hands each ESC frame of a hub frame on as `(channel, offset, frame)`, at the hub frame's
/// offset.
#[inline]
fn hub_records(d: &datalink::Decoded, emit: &mut impl FnMut(Option<u8>, u64, &AnyFrame)) {
    for (channel, frame) in d.frame.escs() {
        emit(
            Some(channel as u8),
            d.offset,
            &AnyFrame::Data(Data::DataLink(*frame)),
        );
    }
}

/// Hands on a frame of any protocol as the protocol-neutral [`AnyFrame`]: `emit(channel, offset,
/// frame)` gets each ESC frame with its DataLink channel (`None` on an ESC's own wire) and the
/// stream offset of its first byte. The one place where the codec's protocol frames become
/// neutral frames.
#[inline(always)]
fn emit_any(d: detect::Decoded, emit: &mut impl FnMut(Option<u8>, u64, &AnyFrame)) {
    match d {
        detect::Decoded::Mixed(mixed::Decoded::Esc(d)) => {
            emit(None, d.offset, &AnyFrame::from(d.frame))
        }
        detect::Decoded::Mixed(mixed::Decoded::Hub(d)) => hub_records(&d, emit),
        other => emit_other(other, emit),
    }
}

/// [`emit_any`] for the formats of ESCs that send at most about 50 frames a second (V4, V3,
/// HW5): out of line, so that the loop of an HW-FOC stream holds none of it.
#[cold]
#[inline(never)]
fn emit_other(d: detect::Decoded, emit: &mut impl FnMut(Option<u8>, u64, &AnyFrame)) {
    match d {
        detect::Decoded::HwV4(d) => emit(None, d.offset, &AnyFrame::from(d.frame)),
        detect::Decoded::HwV3(d) => emit(None, d.offset, &AnyFrame::Data(Data::HwV3(d.frame))),
        detect::Decoded::Hw5(d) => emit(None, d.offset, &AnyFrame::Data(Data::Hw5(d.frame))),
        detect::Decoded::Mixed(d) => match d {
            mixed::Decoded::Esc(d) => emit(None, d.offset, &AnyFrame::from(d.frame)),
            mixed::Decoded::Hub(d) => hub_records(&d, emit),
        },
    }
}

/// The decoder of a stream: of every protocol at once (the bytes tell which), or of the one
/// protocol a user forced. (Its arms' sizes differ, by the 8 KiB `detect` keeps while locked at
/// most: one per stream, held inline, so that the decoder of every byte is not behind a pointer.)
#[derive(Debug)]
#[allow(clippy::large_enum_variant)]
enum Wire {
    /// Every protocol ([`detect::Decoder`]).
    Any(detect::Decoder),
    /// HW-FOC only.
    HwFoc(foc::Decoder),
    /// DataLink V2 only.
    DataLink(datalink::Decoder),
    /// Hobbywing V4 only.
    HwV4(v4::Decoder),
    /// Hobbywing V3 only.
    HwV3(v3::Decoder),
    /// HW5 only.
    Hw5(hw5::Decoder),
    /// A CAN bus (`can.rs`), its records of the protocol forced only when one is
    /// (`forced.rs`).
    Can(Box<Bus>),
    /// A serial line forced to read a CAN protocol: nothing decodes, every byte is passed
    /// over (skipped).
    NotCan(foc::Decoder, Protocol),
}

impl Wire {
    fn new(forced: Option<Protocol>) -> Wire {
        match forced {
            None => Wire::Any(detect::Decoder::new()),
            Some(Protocol::HwFoc) => Wire::HwFoc(foc::Decoder::new()),
            Some(Protocol::DataLink) => Wire::DataLink(datalink::Decoder::new()),
            Some(Protocol::HwV4) => Wire::HwV4(v4::Decoder::new()),
            Some(Protocol::HwV3) => Wire::HwV3(v3::Decoder::new()),
            Some(Protocol::Hw5) => Wire::Hw5(hw5::Decoder::new()),
            Some(p @ (Protocol::HwCan | Protocol::DroneCan)) => {
                Wire::NotCan(foc::Decoder::new(), p)
            }
        }
    }

    /// Decodes `data` (ending with a silence of the line of `silence_s` seconds when given):
    /// `emit(channel, offset, frame)` gets each ESC frame as [`emit_any`] hands it on.
    #[inline(always)]
    fn feed(
        &mut self,
        data: &[u8],
        silence_s: Option<f64>,
        mut emit: impl FnMut(Option<u8>, u64, &AnyFrame),
    ) {
        let emit = &mut emit;
        let silent = |p: Protocol| silence_s.map(|s| frames_in_of(p, s));
        match self {
            // The closures inlined into the scanner's loop, so that the handler may be too: a
            // frame's fields then reach it in registers, not through a frame stored and loaded
            // back.
            Wire::Any(d) => {
                d.feed(
                    data,
                    #[inline(always)]
                    |d| emit_any(d, emit),
                );
                if let Some(s) = silence_s {
                    d.line_silent_each(frames_in(s), hub_frames_in(s), |d| emit_any(d, emit));
                }
            }
            Wire::HwFoc(d) => feed_one(
                d,
                data,
                silent(Protocol::HwFoc),
                |d| detect::Decoded::Mixed(mixed::Decoded::Esc(d)),
                emit,
            ),
            Wire::DataLink(d) => feed_one(
                d,
                data,
                silent(Protocol::DataLink),
                |d| detect::Decoded::Mixed(mixed::Decoded::Hub(d)),
                emit,
            ),
            Wire::HwV4(_) | Wire::HwV3(_) | Wire::Hw5(_) => self.feed_slow(data, silence_s, emit),
            Wire::Can(c) => {
                let at = c.wire.bytes();
                c.feed(data, None, &mut |_, place, f| emit(place, at, f));
            }
            Wire::NotCan(d, _) => d.pass_over(data.len() as u64),
        }
    }

    /// [`Wire::feed`] of a format whose ESCs send at most about 50 frames a second (V4, V3,
    /// HW5), forced: its frames through a `dyn` callback, so that its scanner is compiled once,
    /// not once per handler.
    fn feed_slow(
        &mut self,
        data: &[u8],
        silence_s: Option<f64>,
        mut emit: &mut dyn FnMut(Option<u8>, u64, &AnyFrame),
    ) {
        let forced = self.forced();
        let silent = silence_s.zip(forced).map(|(s, p)| frames_in_of(p, s));
        match self {
            Wire::HwV4(d) => feed_one(d, data, silent, detect::Decoded::HwV4, &mut emit),
            Wire::HwV3(d) => feed_one(d, data, silent, detect::Decoded::HwV3, &mut emit),
            Wire::Hw5(d) => feed_one(d, data, silent, detect::Decoded::Hw5, &mut emit),
            Wire::Any(_) | Wire::HwFoc(_) | Wire::DataLink(_) | Wire::Can(_) | Wire::NotCan(..) => {
            }
        }
    }

    /// Ends the stream, handing on what the held bytes still hold.
    fn flush(&mut self, emit: &mut impl FnMut(Option<u8>, u64, &AnyFrame)) {
        match self {
            Wire::Any(d) => d.flush(|d| emit_any(d, emit)),
            Wire::HwFoc(d) => {
                d.flush(|d| emit_any(detect::Decoded::Mixed(mixed::Decoded::Esc(d)), emit))
            }
            Wire::DataLink(d) => {
                d.flush(|d| emit_any(detect::Decoded::Mixed(mixed::Decoded::Hub(d)), emit))
            }
            Wire::HwV4(_) | Wire::HwV3(_) | Wire::Hw5(_) => self.flush_slow(emit),
            // Ended by `Stream::finish`, with the times of the records it held.
            Wire::Can(_) => {}
            Wire::NotCan(..) => {}
        }
    }

    /// [`Wire::flush`] of a forced V4, V3 or HW5 decoder (see [`Wire::feed_slow`]).
    fn flush_slow(&mut self, mut emit: &mut dyn FnMut(Option<u8>, u64, &AnyFrame)) {
        match self {
            Wire::HwV4(d) => d.flush(|d| emit_any(detect::Decoded::HwV4(d), &mut emit)),
            Wire::HwV3(d) => d.flush(|d| emit_any(detect::Decoded::HwV3(d), &mut emit)),
            Wire::Hw5(d) => d.flush(|d| emit_any(detect::Decoded::Hw5(d), &mut emit)),
            Wire::Any(_) | Wire::HwFoc(_) | Wire::DataLink(_) | Wire::Can(_) | Wire::NotCan(..) => {
            }
        }
    }

    /// Every byte fed so far.
    fn bytes(&self) -> u64 {
        match self {
            Wire::Any(d) => d.bytes(),
            Wire::HwFoc(d) => d.stats().bytes(),
            Wire::DataLink(d) => d.stats().bytes(),
            Wire::HwV4(d) => d.stats().bytes(),
            Wire::HwV3(d) => d.stats().bytes(),
            Wire::Hw5(d) => d.stats().bytes(),
            Wire::Can(c) => c.wire.bytes(),
            Wire::NotCan(d, _) => d.stats().bytes(),
        }
    }

    /// Bytes held for a frame still arriving.
    fn buffered(&self) -> usize {
        match self {
            Wire::Any(d) => d.buffered(),
            Wire::HwFoc(d) => d.buffered(),
            Wire::DataLink(d) => d.buffered(),
            Wire::HwV4(d) => d.buffered(),
            Wire::HwV3(d) => d.buffered(),
            Wire::Hw5(d) => d.buffered(),
            Wire::Can(c) => c.wire.buffered(),
            Wire::NotCan(d, _) => d.buffered(),
        }
    }

    /// The HW-FOC statistics, unless another protocol is forced.
    fn esc(&self) -> Option<&foc::Stats> {
        match self {
            Wire::Any(d) => Some(&d.mixed_stats().esc),
            Wire::HwFoc(d) | Wire::NotCan(d, _) => Some(d.stats()),
            Wire::DataLink(_) | Wire::HwV4(_) | Wire::HwV3(_) | Wire::Hw5(_) | Wire::Can(_) => None,
        }
    }

    /// The DataLink statistics, unless another protocol is forced.
    fn hub(&self) -> Option<&datalink::Stats> {
        match self {
            Wire::Any(d) => Some(&d.mixed_stats().hub),
            Wire::DataLink(d) => Some(d.stats()),
            Wire::HwFoc(_)
            | Wire::HwV4(_)
            | Wire::HwV3(_)
            | Wire::Hw5(_)
            | Wire::Can(_)
            | Wire::NotCan(..) => None,
        }
    }

    /// The link of another format (V4, V3, HW5) when the stream is read as it: forced, or
    /// the format last locked onto.
    fn other(&self) -> Option<EscLink> {
        match self {
            Wire::Any(d) => match d.last_locked()? {
                detect::Family::Mixed => None,
                detect::Family::HwV4 => Some(EscLink::HwV4(*d.v4_stats())),
                detect::Family::HwV3 => Some(EscLink::HwV3(*d.v3_stats())),
                detect::Family::Hw5 => Some(EscLink::Hw5(*d.hw5_stats())),
            },
            Wire::HwV4(d) => Some(EscLink::HwV4(*d.stats())),
            Wire::HwV3(d) => Some(EscLink::HwV3(*d.stats())),
            Wire::Hw5(d) => Some(EscLink::Hw5(*d.stats())),
            Wire::Can(c) => Some(EscLink::Can(c.link(0))),
            Wire::HwFoc(_) | Wire::DataLink(_) | Wire::NotCan(..) => None,
        }
    }

    /// The protocol forced, if one is.
    fn forced(&self) -> Option<Protocol> {
        match self {
            Wire::Any(_) => None,
            Wire::HwFoc(_) => Some(Protocol::HwFoc),
            Wire::DataLink(_) => Some(Protocol::DataLink),
            Wire::HwV4(_) => Some(Protocol::HwV4),
            Wire::HwV3(_) => Some(Protocol::HwV3),
            Wire::Hw5(_) => Some(Protocol::Hw5),
            Wire::Can(c) => c.forced(),
            Wire::NotCan(_, p) => Some(*p),
        }
    }
}

/// Decodes `data` with one protocol's decoder (ending with a silence of the line in which at
/// most `silent` of its frames fit, when given): each frame, made a [`detect::Decoded`] by
/// `wrap`, is handed on as [`emit_any`] does.
#[inline(always)]
fn feed_one<S: hwfoc::scan::Scanner>(
    decoder: &mut hwfoc::StreamDecoder<S>,
    data: &[u8],
    silent: Option<u32>,
    wrap: impl Fn(S::Item) -> detect::Decoded,
    emit: &mut impl FnMut(Option<u8>, u64, &AnyFrame),
) {
    decoder.feed(
        data,
        #[inline(always)]
        |d| emit_any(wrap(d), emit),
    );
    if let Some(frames) = silent {
        decoder.line_silent(frames, |d| emit_any(wrap(d), emit));
    }
}

/// The link statistics of one ESC: those of its own wire, or of its channel of a DataLink hub
/// (whose bytes, skipped bytes and CRC failures are the hub link's, shared by its channels).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EscLink {
    /// An ESC on its own HW-FOC wire (or a stream whose protocol is not known yet).
    Wire(foc::Stats),
    /// Channel `channel` of a DataLink hub.
    Hub {
        /// The hub link's statistics.
        hub: datalink::Stats,
        /// The ESC's channel.
        channel: usize,
    },
    /// A Hobbywing V4 ESC's wire.
    HwV4(v4::Stats),
    /// A Hobbywing V3 ESC's wire.
    HwV3(v3::Stats),
    /// An HW5 ESC's wire.
    Hw5(hw5::Stats),
    /// An ESC on a CAN bus (its node's and the bus's statistics).
    Can(CanLink),
}

impl Default for Stream {
    fn default() -> Self {
        Stream::new()
    }
}

impl Default for EscLink {
    fn default() -> Self {
        EscLink::Wire(foc::Stats::new())
    }
}

/// The packet counting of a link: 16 bits (HW-FOC, DataLink) or 24 (V3, V4).
enum Counting<'a> {
    Bits16(&'a PacketSequence),
    Bits24(&'a PacketSequence24),
}

impl EscLink {
    fn counting(&self) -> Option<Counting<'_>> {
        match self {
            EscLink::Wire(s) => Some(Counting::Bits16(s.packets())),
            EscLink::Hub { hub, channel } => hub.channel(*channel).map(Counting::Bits16),
            EscLink::HwV4(s) => Some(Counting::Bits24(s.counter())),
            EscLink::HwV3(s) => Some(Counting::Bits24(s.counter())),
            EscLink::Hw5(_) | EscLink::Can(_) => None,
        }
    }

    /// The protocol of the link's frames.
    pub fn protocol(&self) -> Protocol {
        match self {
            EscLink::Wire(_) => Protocol::HwFoc,
            EscLink::Hub { .. } => Protocol::DataLink,
            EscLink::HwV4(_) => Protocol::HwV4,
            EscLink::HwV3(_) => Protocol::HwV3,
            EscLink::Hw5(_) => Protocol::Hw5,
            EscLink::Can(c) => c.protocol,
        }
    }

    /// Bytes of the stream the ESC's frames came in.
    pub fn bytes(&self) -> u64 {
        match self {
            EscLink::Wire(s) => s.bytes(),
            EscLink::Hub { hub, .. } => hub.bytes(),
            EscLink::HwV4(s) => s.bytes(),
            EscLink::HwV3(s) => s.bytes(),
            EscLink::Hw5(s) => s.bytes(),
            EscLink::Can(c) => c.bytes,
        }
    }

    /// Bytes of that stream that were in no accepted frame (of the link's protocol; an HW5
    /// wire's other frame kinds, requests and answers, are not skipped).
    pub fn bytes_skipped(&self) -> u64 {
        match self {
            EscLink::Wire(s) => s.bytes_skipped(),
            EscLink::Hub { hub, .. } => hub.bytes_skipped(),
            EscLink::HwV4(s) => s.bytes_skipped(),
            EscLink::HwV3(s) => s.bytes_skipped(),
            EscLink::Hw5(s) => s.bytes_skipped(),
            EscLink::Can(c) => c.bytes_skipped(),
        }
    }

    /// Data frames of the ESC (records of its channel, behind a hub).
    pub fn frames(&self) -> u32 {
        match self {
            EscLink::HwV4(s) => s.frames(),
            EscLink::HwV3(s) => s.frames(),
            EscLink::Hw5(s) => s.telemetry_frames(),
            EscLink::Can(c) => c.records,
            EscLink::Wire(_) | EscLink::Hub { .. } => match self.counting() {
                Some(Counting::Bits16(c)) => c.count(),
                Some(Counting::Bits24(c)) => c.count(),
                None => 0,
            },
        }
    }

    /// Device-information frames (V4: info frames; a hub forwards none).
    pub fn info_frames(&self) -> u32 {
        match self {
            EscLink::Wire(s) => s.info_frames(),
            EscLink::HwV4(s) => s.info_frames(),
            EscLink::Hub { .. } | EscLink::HwV3(_) | EscLink::Hw5(_) | EscLink::Can(_) => 0,
        }
    }

    /// Whether the link's frames are checked (its format's description: V3 and V4 are not,
    /// their frames are recognised by plausibility and chaining, see
    /// [`EscLink::rejected_candidates`]).
    pub fn has_checksum(&self) -> bool {
        self.protocol().description().check != hwfoc::format::Check::None
    }

    /// A Hobbywing CAN ESC's own maintenance counters, minutes (total rotation time, time since
    /// maintenance), where its bus's recording holds its answer to GetMaintenanceInformation;
    /// `None` otherwise.
    pub fn maintenance_min(&self) -> Option<(u32, u32)> {
        match self {
            EscLink::Can(c) => c.maintenance_min,
            EscLink::Wire(_)
            | EscLink::Hub { .. }
            | EscLink::HwV4(_)
            | EscLink::HwV3(_)
            | EscLink::Hw5(_) => None,
        }
    }

    /// Frames rejected by their checksum, or whose checksum matched but whose values are out of
    /// their protocol's range (behind a hub: the hub frames' CRC failures; 0 for a format
    /// without checksum).
    pub fn checksum_failures(&self) -> u32 {
        match self {
            EscLink::Wire(s) => s.checksum_failures(),
            EscLink::Hub { hub, .. } => hub.checksum_failures(),
            EscLink::Hw5(s) => s.checksum_failures().saturating_add(s.out_of_range()),
            EscLink::Can(c) => c.node_stats.checksum_failures(),
            EscLink::HwV4(_) | EscLink::HwV3(_) => 0,
        }
    }

    /// Candidates of a format without checksum that were not taken: implausible, or not
    /// confirmed by a chain (`None` for a checksummed format).
    pub fn rejected_candidates(&self) -> Option<u32> {
        match self {
            EscLink::HwV4(s) => Some(s.rejected()),
            EscLink::HwV3(s) => Some(s.rejected()),
            EscLink::Wire(_) | EscLink::Hub { .. } | EscLink::Hw5(_) | EscLink::Can(_) => None,
        }
    }

    /// Whether the link's frames carry a packet counter, from which loss is counted (HW5's
    /// do not: its lost, duplicate and restart counts are 0 and say nothing). On a CAN bus,
    /// the transfer ids of every transfer of the ESC's node are counted.
    pub fn counts_packets(&self) -> bool {
        matches!(self, EscLink::Can(_)) || self.protocol().packet_bits().is_some()
    }

    /// Packet numbers skipped (on a CAN bus: transfers of the node missed, from the gaps in
    /// their transfer ids).
    pub fn lost_packets(&self) -> u32 {
        if let EscLink::Can(c) = self {
            return c.node_stats.lost_packets();
        }
        match self.counting() {
            Some(Counting::Bits16(c)) => c.lost(),
            Some(Counting::Bits24(c)) => c.lost(),
            None => 0,
        }
    }

    /// Packet numbers received twice in a row (on a CAN bus: transfers of the node).
    pub fn duplicate_packets(&self) -> u32 {
        if let EscLink::Can(c) = self {
            return c.node_stats.duplicates();
        }
        match self.counting() {
            Some(Counting::Bits16(c)) => c.duplicates(),
            Some(Counting::Bits24(c)) => c.duplicates(),
            None => 0,
        }
    }

    /// Packet numbers that came right after the next one (two adjacent frames swapped): not
    /// lost, no restart.
    pub fn reordered_packets(&self) -> u32 {
        match self.counting() {
            Some(Counting::Bits16(c)) => c.reordered(),
            Some(Counting::Bits24(c)) => c.reordered(),
            None => 0,
        }
    }

    /// Jumps of the packet numbers that no loss explains (on a CAN bus: the node's transfers
    /// after a silence of the whole bus).
    pub fn restarts(&self) -> u32 {
        if let EscLink::Can(c) = self {
            return c.node_stats.restarts();
        }
        match self.counting() {
            Some(Counting::Bits16(c)) => c.restarts(),
            Some(Counting::Bits24(c)) => c.restarts(),
            None => 0,
        }
    }

    /// The last packet number received.
    pub fn last_packet(&self) -> Option<u32> {
        match self.counting()? {
            Counting::Bits16(c) => c.last().map(u32::from),
            Counting::Bits24(c) => c.last(),
        }
    }

    /// Frames received over frames sent, from the packet numbers (on a CAN bus: the node's
    /// transfers, from their transfer ids).
    pub fn delivery_ratio(&self) -> Option<f64> {
        if let EscLink::Can(c) = self {
            return c.delivery_ratio();
        }
        match self.counting()? {
            Counting::Bits16(c) => c.delivery_ratio(),
            Counting::Bits24(c) => c.delivery_ratio(),
        }
    }

    /// The info frame whose constants were adopted (two identical copies in a row), if any: a
    /// format whose description has [`adopted_info`](hwfoc::format::FormatDescription) (V4).
    pub fn adopted_info(&self) -> Option<Info> {
        match self {
            EscLink::HwV4(s) => s.adopted().map(Info::HwV4),
            EscLink::Wire(_)
            | EscLink::Hub { .. }
            | EscLink::HwV3(_)
            | EscLink::Hw5(_)
            | EscLink::Can(_) => None,
        }
    }
}

/// A decoder that also gives each frame the receive time of its first byte.
///
/// It reads both protocols at once ([`mixed::Decoder`]): the frames of an ESC's own wire and of
/// a DataLink hub, in byte order, whatever the chunking, also when the stream changes from one
/// to the other; bytes in a frame of either are not skipped bytes of the other. Or, made by
/// [`Stream::forced`], it reads one protocol only: the bytes of any other are skipped bytes.
#[derive(Debug)]
pub struct Stream {
    wire: Wire,
    /// Receive times of the last bytes of earlier batches, oldest first.
    history: Vec<f64>,
    /// Of a serial stream forced to read one protocol: every format read over its first bytes.
    probe: Option<Box<Probe>>,
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
        Stream {
            wire: Wire::new(forced),
            history: Vec::new(),
            probe: forced.map(|_| Box::default()),
        }
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
            wire: Wire::Can(Box::new(Bus::new(forced))),
            history: Vec::new(),
            probe: None,
        }
    }

    /// Of a CAN bus's stream read with a protocol forced: the records of other protocols left
    /// out, by protocol (those of which some were).
    pub fn left_out(&self) -> Vec<(Protocol, u64)> {
        match &self.wire {
            Wire::Can(c) => c.left_out(),
            Wire::Any(_)
            | Wire::HwFoc(_)
            | Wire::DataLink(_)
            | Wire::HwV4(_)
            | Wire::HwV3(_)
            | Wire::Hw5(_)
            | Wire::NotCan(..) => Vec::new(),
        }
    }

    /// Fixes the slots of a CAN bus's ESCs ahead (`can.rs`); nothing for any other stream.
    pub(crate) fn plan_can(&mut self, plan: &BusPlan) {
        if let Wire::Can(c) = &mut self.wire {
            c.wire.set_plan(plan);
        }
    }

    /// A CAN bus's ESCs heard since the last call that claim a throttle channel another holds,
    /// in words (none for any other stream).
    pub(crate) fn take_can_clashes(&mut self) -> Vec<String> {
        let Wire::Can(c) = &mut self.wire else {
            return Vec::new();
        };
        c.wire
            .take_clashes()
            .iter()
            .map(|c| c.to_string())
            .collect()
    }

    /// Of a serial stream forced to read one protocol: the protocol of the first frame found
    /// in its first bytes read as every format (64 KiB), when it is not the one forced. What
    /// to tell a user whose forced protocol found nothing.
    pub fn found_instead(&self) -> Option<Protocol> {
        let found = self.probe.as_ref()?.found()?;
        (Some(found) != self.forced_protocol()).then_some(found)
    }

    /// Whether the stream is a CAN bus's.
    pub fn is_can(&self) -> bool {
        matches!(self.wire, Wire::Can(_))
    }

    /// The protocol the stream was made to read only, if any.
    pub fn forced_protocol(&self) -> Option<Protocol> {
        self.wire.forced()
    }

    /// Decodes a batch; `on_frame(t, channel, frame)` gets each ESC frame with its time
    /// (`None` without timing) and its DataLink channel (`None` on an ESC's own wire).
    #[inline(always)]
    pub fn feed(
        &mut self,
        batch: Batch<'_>,
        mut on_frame: impl FnMut(Option<f64>, Option<u8>, &AnyFrame),
    ) {
        if let Wire::Can(c) = &mut self.wire {
            return c.feed(batch.bytes, batch.times, &mut on_frame);
        }
        if let Some(probe) = &mut self.probe {
            probe.feed(batch.bytes);
        }
        let start = self.wire.bytes();
        match batch.times {
            None => {
                self.history.clear();
                self.wire.feed(
                    batch.bytes,
                    None,
                    #[inline(always)]
                    |channel, _, f| on_frame(None, channel, f),
                );
            }
            Some(times) => {
                let history = &self.history;
                let mut emit = |channel: Option<u8>, offset: u64, f: &AnyFrame| {
                    on_frame(Some(time_at(history, times, start, offset)), channel, f)
                };
                // The batch in pieces at each silence of the line: the decoder is told how many
                // frames the silence could have hidden, so that an ESC that restarted in it is
                // counted as a restart, not as thousands of lost packets.
                let mut from = 0;
                let mut last = history.last().copied();
                for (i, &t) in times.iter().enumerate() {
                    if let Some(before) = last
                        && t - before > SILENCE_S
                    {
                        self.wire
                            .feed(&batch.bytes[from..i], Some(t - before), &mut emit);
                        from = i;
                    }
                    last = Some(t);
                }
                self.wire.feed(&batch.bytes[from..], None, &mut emit);
                let keep = TIME_HISTORY.min(self.history.len() + times.len());
                let from_times = keep.min(times.len());
                let from_history = keep - from_times;
                self.history.drain(..self.history.len() - from_history);
                self.history
                    .extend_from_slice(&times[times.len() - from_times..]);
            }
        }
    }

    /// Decodes bytes without receive times; `on_frame(offset, channel, frame)` gets each ESC
    /// frame with the stream offset of its first byte and its DataLink channel (`None` on an
    /// ESC's own wire).
    pub(crate) fn feed_untimed(
        &mut self,
        bytes: &[u8],
        on_frame: impl FnMut(Option<u8>, u64, &AnyFrame),
    ) {
        self.history.clear();
        if let Some(probe) = &mut self.probe {
            probe.feed(bytes);
        }
        self.wire.feed(bytes, None, on_frame);
    }

    /// Bytes held for a frame still arriving: none when no byte fed so far waits for a later
    /// one to be decided.
    pub(crate) fn buffered(&self) -> usize {
        self.wire.buffered()
    }

    /// Continues this stream with `later`'s work ([`hwfoc::StreamDecoder::then`]): `later`, a
    /// stream of the same protocols started new where this one has been fed to, was fed the
    /// rest of the stream's bytes, both without receive times; `first_packet` is the packet
    /// number of its first data frame. Its statistics become those of the whole stream. False,
    /// and nothing changes, when this stream holds bytes, either has times, or the decoders
    /// cannot be joined.
    pub(crate) fn then(&mut self, later: &Stream, first_packet: Option<u16>) -> bool {
        if !self.history.is_empty() || !later.history.is_empty() {
            return false;
        }
        match (&mut self.wire, &later.wire) {
            (Wire::Any(a), Wire::Any(b)) => a.then(b, first_packet),
            // V3 and V4 chains are state beyond the held bytes; HW5 is read in one too (the
            // summary of an HW5 file does not need two cores).
            (Wire::HwFoc(a), Wire::HwFoc(b)) => a.then(b, first_packet),
            (Wire::DataLink(a), Wire::DataLink(b)) => a.then(b, first_packet),
            (
                Wire::Any(_)
                | Wire::HwFoc(_)
                | Wire::DataLink(_)
                | Wire::HwV4(_)
                | Wire::HwV3(_)
                | Wire::Hw5(_)
                | Wire::Can(_)
                | Wire::NotCan(..),
                _,
            ) => false,
        }
    }

    /// Ends the stream: a frame cut off at the end is dropped, frames inside it are still found.
    pub fn finish(&mut self, mut on_frame: impl FnMut(Option<f64>, Option<u8>, &AnyFrame)) {
        if let Wire::Can(c) = &mut self.wire {
            return c.finish(&mut on_frame);
        }
        let end = self.wire.bytes();
        let history = &self.history;
        let timed = !history.is_empty();
        let mut emit = |channel: Option<u8>, offset: u64, f: &AnyFrame| {
            let t = timed.then(|| time_at(history, &[], end, offset));
            on_frame(t, channel, f)
        };
        self.wire.flush(&mut emit);
    }

    /// Which protocols the stream has been heard speaking.
    pub fn kind(&self) -> WireKind {
        if let Some(link) = self
            .wire
            .other()
            .filter(|l| l.frames() + l.info_frames() > 0)
        {
            return WireKind::Other(link.protocol());
        }
        match (self.esc_frames(), self.hub_frames()) {
            (false, false) => WireKind::Unknown,
            (true, false) => WireKind::Esc,
            (false, true) => WireKind::Hub,
            (true, true) => WireKind::Mixed,
        }
    }

    /// Whether an ESC frame (data or device information) has been found.
    fn esc_frames(&self) -> bool {
        self.wire
            .esc()
            .is_some_and(|s| s.packets().count() > 0 || s.info_frames() > 0)
    }

    /// Whether a DataLink frame has been found.
    fn hub_frames(&self) -> bool {
        self.hub().is_some()
    }

    /// The link statistics of the stream's ESC: of its own wire, or of the hub's channel 0
    /// when the stream has carried hub frames and no ESC frame of its own.
    pub fn stats(&self) -> EscLink {
        self.link(0)
    }

    /// The link statistics of the stream's ESC on `channel`: the hub's channel once hub frames
    /// were found (channel 0: unless the stream also carried ESC frames of its own, whose
    /// statistics are then given), else the ESC's own wire (any channel). A stream forced to
    /// read DataLink only gives the hub's channel from its first byte.
    pub fn link(&self, channel: u8) -> EscLink {
        if let Wire::Can(c) = &self.wire {
            return EscLink::Can(c.link(channel));
        }
        if let Some(link) = self.wire.other() {
            return link;
        }
        let esc = self.wire.esc();
        let from_hub = esc.is_none() || self.hub_frames() && (channel != 0 || !self.esc_frames());
        match self.wire.hub().filter(|_| from_hub) {
            Some(hub) => EscLink::Hub {
                hub: *hub,
                channel: usize::from(channel),
            },
            None => EscLink::Wire(esc.copied().unwrap_or_default()),
        }
    }

    /// The DataLink hub's statistics, once the stream has carried a hub frame.
    pub fn hub(&self) -> Option<&datalink::Stats> {
        self.wire.hub().filter(|s| s.frames() > 0)
    }

    /// The receive time of the first byte the decoder holds for a frame still arriving, if it
    /// holds any: no frame completed later can be older (later bytes are no older than the
    /// held ones). `None` when nothing is held or the stream has no times.
    pub(crate) fn held_since(&self) -> Option<f64> {
        let held = self.wire.buffered();
        (held > 0 && held <= self.history.len()).then(|| self.history[self.history.len() - held])
    }
}

/// What numbers a port's frames into ESCs ([`PortStreams`]): the port's own ESC, a hub's
/// channels and a bus's places after every port's.
struct Numbering<'a> {
    port: usize,
    can: bool,
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
            can,
            hub,
            esc_settings,
            names,
            map,
            left_out,
            past_last,
        } = self;
        let can = *can;
        let esc = match channel {
            None => *port,
            Some(c) => {
                // A hub's channels all at once, a bus's places up to the one heard.
                let places = if can {
                    usize::from(c) + 1
                } else {
                    datalink::CHANNELS
                };
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
                    place: channel.map(|c| {
                        if can {
                            format!("place {c} of the bus")
                        } else {
                            format!("DataLink channel {c}")
                        }
                    }),
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
    pub fn feed<H: Handler>(&mut self, event: &PortEvent, handler: &mut H) -> Option<EscLink> {
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
            can: stream.is_can(),
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
            *stream = if stream.is_can() {
                Stream::can_forced(Some(protocol))
            } else {
                Stream::forced(Some(protocol))
            };
        }
    }

    /// Reads `port` at `baud` from now on (its rate found): its byte time changes, and its
    /// stream starts again (reading the same protocols), so that what it held of bytes at
    /// another rate makes no frame.
    pub fn set_baud(&mut self, port: usize, baud: u32) {
        let Some(stream) = self.streams.get_mut(port).filter(|s| !s.is_can()) else {
            return;
        };
        if self.bauds[port].is_some_and(|b| b != baud) && stream.wire.bytes() > 0 {
            // Bytes fed at another rate: what the decoder holds of a frame still arriving is
            // skipped, never completed by bytes at this rate.
            self.discarded[port] += stream.buffered() as u64;
            *stream = Stream::forced(stream.forced_protocol());
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
    pub fn stats(&self, port: usize) -> Option<EscLink> {
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

/// Receive time of stream offset `offset`, where `times` holds the times of the bytes from
/// offset `start` on and `history` those just before `start`.
///
/// A frame that began in bytes fed without times (a stream that became timed mid-frame) has no
/// time of its own: it gets the earliest time known.
fn time_at(history: &[f64], times: &[f64], start: u64, offset: u64) -> f64 {
    if offset >= start {
        times[(offset - start) as usize]
    } else {
        let back = (start - offset) as usize;
        match history.len().checked_sub(back) {
            Some(i) => history[i],
            None => history
                .first()
                .or(times.first())
                .copied()
                .unwrap_or(f64::NAN),
        }
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
    fn run(parts: &[(Vec<u8>, Vec<f64>)], chunk: usize) -> EscLink {
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
            .flat_map(|_| hw5::TelemetryFrame::default().encode())
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
            assert!(matches!(s, EscLink::Hub { channel: 0, .. }));
            assert_eq!(s.bytes_skipped(), 30 * 24, "chunk {chunk}");
            assert_eq!(stream.hub().map(|h| h.frames()), Some(3));
        }
        // Forced to DataLink, a stream of ESC frames only is a hub link that found nothing.
        let (got, stream) = decode(&esc(0..10), 24, Protocol::DataLink);
        assert!(got.is_empty());
        assert!(matches!(stream.stats(), EscLink::Hub { .. }));
        assert_eq!(stream.stats().bytes_skipped(), 240);
        assert_eq!(stream.kind(), WireKind::Unknown);
    }
}
