//! A serial line's decoding ([`Serial`]): the codec's streaming decoders, the receive time of
//! each frame from its bytes' times, and the silences of the line told to the decoder.
//!
//! What decodes the line is a [`SerialDecoder`]: the formats of fast lines, read in one
//! monomorphised loop ([`Fast`]: every format at once, HW-FOC or DataLink), one slower format
//! forced ([`OneEsc`]: V4, V3, HW5), or nothing ([`PassOver`]: a serial line forced to read a
//! CAN protocol).

use hwfoc::format::LinkKind;
use hwfoc::scan::Scanner;
use hwfoc::telemetry::AnyFrame;
use hwfoc::{Protocol, StreamDecoder, datalink, detect, foc, mixed};

use super::decoder::{LinkDecoder, OnFrame};
use super::forced::Probe;
use super::link::LinkStats;
use super::{SILENCE_S, WireKind};
use crate::input::Batch;

/// How many receive times to keep from earlier batches: a frame still arriving is shorter than
/// the longest frame (a DataLink frame, 160 bytes), so its first byte is never further back
/// than this.
const TIME_HISTORY: usize = if foc::MAX_FRAME_LEN > datalink::FRAME_LEN {
    foc::MAX_FRAME_LEN
} else {
    datalink::FRAME_LEN
};

/// The most data frames of `protocol` a silence of `seconds` can have hidden: one per frame
/// length of byte times at its baud rate, the fastest the line carries them (real ESCs send
/// far fewer).
fn frames_in(protocol: Protocol, seconds: f64) -> u32 {
    let len = protocol.description().data_frame_len;
    let frame_s = len as f64 * hwfoc::wire::byte_ns(protocol.baud_rate()) * 1e-9;
    (seconds / frame_s).ceil().min(f64::from(u32::MAX)) as u32
}

/// Hands on a frame of any protocol as the protocol-neutral [`AnyFrame`]s its format's module
/// makes of it: `emit(channel, offset, frame)` gets each ESC frame with its DataLink channel
/// (`None` on an ESC's own wire) and the stream offset of its first byte. HW-FOC's inline,
/// DataLink's records through [`hwfoc::datalink::Decoded::each_esc_frame`], every other
/// format's out of line.
#[inline(always)]
fn emit_any(d: detect::Decoded, emit: &mut impl FnMut(Option<u8>, u64, &AnyFrame)) {
    match d {
        // (By value: `mixed::Decoded::each_esc_frame`, which takes the frame by reference, costs
        // the summary's loop a quarter more instructions.)
        detect::Decoded::Mixed(mixed::Decoded::Esc(d)) => {
            emit(None, d.offset, &AnyFrame::from(d.frame))
        }
        detect::Decoded::Mixed(mixed::Decoded::Hub(d)) => d.each_esc_frame(emit),
        other => emit_other(other, emit),
    }
}

/// [`emit_any`] for the formats of ESCs that send at most about 50 frames a second (V4, V3,
/// HW5): out of line, so that the loop of an HW-FOC stream holds none of it, each format's
/// frames made neutral frames by its own module ([`detect::Decoded::hand_on`]).
#[cold]
#[inline(never)]
fn emit_other(d: detect::Decoded, emit: &mut impl FnMut(Option<u8>, u64, &AnyFrame)) {
    d.hand_on(&mut |channel, offset, frame| emit(channel, offset, frame));
}

/// Decodes `data` with one protocol's decoder (ending with a silence of the line in which at
/// most `silent` of its frames fit, when given): each frame, made a [`detect::Decoded`] by
/// `wrap`, is handed on as [`emit_any`] does.
#[inline(always)]
fn feed_one<S: Scanner>(
    decoder: &mut StreamDecoder<S>,
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

/// What decodes a serial line's bytes, stream offsets in, frames out.
pub(super) trait SerialDecoder: std::fmt::Debug + Send {
    /// Decodes `data` (ending with a silence of the line of `silence_s` seconds when given):
    /// `emit(channel, offset, frame)` gets each ESC frame with its DataLink channel (`None` on
    /// an ESC's own wire) and the stream offset of its first byte.
    fn feed(
        &mut self,
        data: &[u8],
        silence_s: Option<f64>,
        emit: impl FnMut(Option<u8>, u64, &AnyFrame),
    );
    /// Ends the stream, handing on what the held bytes still hold.
    fn flush(&mut self, emit: &mut impl FnMut(Option<u8>, u64, &AnyFrame));
    /// Every byte fed so far.
    fn bytes(&self) -> u64;
    /// Bytes held for a frame still arriving.
    fn buffered(&self) -> usize;
    /// The HW-FOC statistics, where it reads HW-FOC.
    fn esc(&self) -> Option<&foc::Stats>;
    /// The DataLink statistics, where it reads DataLink.
    fn hub(&self) -> Option<&datalink::Stats>;
    /// The link of another format (V4, V3, HW5) when the line is read as it: forced, or the
    /// format last locked onto.
    fn other(&self) -> Option<LinkStats>;
    /// The protocol forced, if one is.
    fn forced(&self) -> Option<Protocol>;
    /// How its channels are laid out: one ESC, or a hub's channels where it reads DataLink.
    fn layout(&self) -> LinkKind;
}

/// The decoders of the fast lines, in one monomorphised loop: every format at once (the bytes
/// tell which), HW-FOC only or DataLink only. (Its arms' sizes differ, by the 8 KiB `detect`
/// keeps while locked at most: one per stream, held inline, so that the decoder of every byte
/// is not behind a pointer.)
#[derive(Debug)]
#[allow(clippy::large_enum_variant)]
pub(super) enum Fast {
    /// Every protocol ([`detect::Decoder`]).
    Any(detect::Decoder),
    /// HW-FOC only.
    HwFoc(foc::Decoder),
    /// DataLink V2 only.
    DataLink(datalink::Decoder),
}

impl SerialDecoder for Fast {
    #[inline(always)]
    fn feed(
        &mut self,
        data: &[u8],
        silence_s: Option<f64>,
        mut emit: impl FnMut(Option<u8>, u64, &AnyFrame),
    ) {
        let emit = &mut emit;
        let silent = |p: Protocol| silence_s.map(|s| frames_in(p, s));
        match self {
            // The closures inlined into the scanner's loop, so that the handler may be too: a
            // frame's fields then reach it in registers, not through a frame stored and loaded
            // back.
            Fast::Any(d) => {
                d.feed(
                    data,
                    #[inline(always)]
                    |d| emit_any(d, emit),
                );
                if let Some(s) = silence_s {
                    let (esc, hub) = (Protocol::HwFoc, Protocol::DataLink);
                    d.line_silent_each(frames_in(esc, s), frames_in(hub, s), |d| emit_any(d, emit));
                }
            }
            Fast::HwFoc(d) => feed_one(
                d,
                data,
                silent(Protocol::HwFoc),
                |d| detect::Decoded::Mixed(mixed::Decoded::Esc(d)),
                emit,
            ),
            Fast::DataLink(d) => feed_one(
                d,
                data,
                silent(Protocol::DataLink),
                |d| detect::Decoded::Mixed(mixed::Decoded::Hub(d)),
                emit,
            ),
        }
    }

    fn flush(&mut self, emit: &mut impl FnMut(Option<u8>, u64, &AnyFrame)) {
        match self {
            Fast::Any(d) => d.flush(|d| emit_any(d, emit)),
            Fast::HwFoc(d) => {
                d.flush(|d| emit_any(detect::Decoded::Mixed(mixed::Decoded::Esc(d)), emit))
            }
            Fast::DataLink(d) => {
                d.flush(|d| emit_any(detect::Decoded::Mixed(mixed::Decoded::Hub(d)), emit))
            }
        }
    }

    fn bytes(&self) -> u64 {
        match self {
            Fast::Any(d) => d.bytes(),
            Fast::HwFoc(d) => d.stats().bytes(),
            Fast::DataLink(d) => d.stats().bytes(),
        }
    }

    fn buffered(&self) -> usize {
        match self {
            Fast::Any(d) => d.buffered(),
            Fast::HwFoc(d) => d.buffered(),
            Fast::DataLink(d) => d.buffered(),
        }
    }

    fn esc(&self) -> Option<&foc::Stats> {
        match self {
            Fast::Any(d) => Some(&d.mixed_stats().esc),
            Fast::HwFoc(d) => Some(d.stats()),
            Fast::DataLink(_) => None,
        }
    }

    fn hub(&self) -> Option<&datalink::Stats> {
        match self {
            Fast::Any(d) => Some(&d.mixed_stats().hub),
            Fast::DataLink(d) => Some(d.stats()),
            Fast::HwFoc(_) => None,
        }
    }

    fn other(&self) -> Option<LinkStats> {
        let Fast::Any(d) = self else { return None };
        d.last_locked_figures().map(LinkStats::of)
    }

    fn forced(&self) -> Option<Protocol> {
        match self {
            Fast::Any(_) => None,
            Fast::HwFoc(_) => Some(Protocol::HwFoc),
            Fast::DataLink(_) => Some(Protocol::DataLink),
        }
    }

    fn layout(&self) -> LinkKind {
        match self {
            Fast::Any(_) | Fast::DataLink(_) => Protocol::DataLink.description().link,
            Fast::HwFoc(_) => LinkKind::OneEsc,
        }
    }
}

impl Fast {
    /// The fast decoder of `forced` (every format when `None`), if it has one.
    pub(super) fn of(forced: Option<Protocol>) -> Result<Fast, Protocol> {
        match forced {
            None => Ok(Fast::Any(detect::Decoder::new())),
            Some(Protocol::HwFoc) => Ok(Fast::HwFoc(foc::Decoder::new())),
            Some(Protocol::DataLink) => Ok(Fast::DataLink(datalink::Decoder::new())),
            Some(slow) => Err(slow),
        }
    }

    /// Continues this decoder with `later`'s work ([`hwfoc::StreamDecoder::then`]); false when
    /// they cannot be joined. V3 and V4 chains are state beyond the held bytes; HW5 is read in
    /// one too (the summary of an HW5 file does not need two cores).
    fn then(&mut self, later: &Fast, first_packet: Option<u16>) -> bool {
        match (self, later) {
            (Fast::Any(a), Fast::Any(b)) => a.then(b, first_packet),
            (Fast::HwFoc(a), Fast::HwFoc(b)) => a.then(b, first_packet),
            (Fast::DataLink(a), Fast::DataLink(b)) => a.then(b, first_packet),
            (Fast::Any(_) | Fast::HwFoc(_) | Fast::DataLink(_), _) => false,
        }
    }
}

/// One format of an ESC that sends at most about 50 frames a second (V4, V3, HW5), forced:
/// its family's decoder alone ([`detect::OneFamily`]), behind [`LinkDecoder`]'s `dyn`, so that
/// its scanner is compiled once, not once per handler.
#[derive(Debug)]
pub(super) struct OneEsc {
    decoder: detect::OneFamily,
    protocol: Protocol,
}

impl OneEsc {
    /// The decoder of `protocol`, read by its own family alone; `None` for a protocol without
    /// a family of its own, or read with DataLink's ([`detect::Family::Mixed`]).
    pub(super) fn of(protocol: Protocol) -> Option<OneEsc> {
        let family = detect::Family::of(protocol).filter(|&f| f != detect::Family::Mixed)?;
        Some(OneEsc {
            decoder: detect::OneFamily::new(family),
            protocol,
        })
    }
}

impl SerialDecoder for OneEsc {
    fn feed(
        &mut self,
        data: &[u8],
        silence_s: Option<f64>,
        mut emit: impl FnMut(Option<u8>, u64, &AnyFrame),
    ) {
        let emit = &mut emit;
        self.decoder.feed(data, &mut |d| emit_any(d, emit));
        if let Some(s) = silence_s {
            let frames = frames_in(self.protocol, s);
            self.decoder.line_silent(frames, &mut |d| emit_any(d, emit));
        }
    }

    fn flush(&mut self, emit: &mut impl FnMut(Option<u8>, u64, &AnyFrame)) {
        self.decoder.flush(&mut |d| emit_any(d, emit));
    }

    fn bytes(&self) -> u64 {
        self.decoder.bytes()
    }

    fn buffered(&self) -> usize {
        self.decoder.buffered()
    }

    fn esc(&self) -> Option<&foc::Stats> {
        None
    }

    fn hub(&self) -> Option<&datalink::Stats> {
        None
    }

    fn other(&self) -> Option<LinkStats> {
        self.decoder.figures().map(LinkStats::of)
    }

    fn forced(&self) -> Option<Protocol> {
        Some(self.protocol)
    }

    fn layout(&self) -> LinkKind {
        self.protocol.description().link
    }
}

/// A serial line forced to read a CAN protocol: nothing decodes, every byte is passed over
/// (skipped).
#[derive(Debug)]
pub(super) struct PassOver {
    decoder: foc::Decoder,
    protocol: Protocol,
}

impl PassOver {
    /// A line forced to read `protocol`, which no serial line carries.
    pub(super) fn new(protocol: Protocol) -> PassOver {
        PassOver {
            decoder: foc::Decoder::new(),
            protocol,
        }
    }
}

impl SerialDecoder for PassOver {
    fn feed(&mut self, data: &[u8], _: Option<f64>, _: impl FnMut(Option<u8>, u64, &AnyFrame)) {
        self.decoder.pass_over(data.len() as u64);
    }

    fn flush(&mut self, _: &mut impl FnMut(Option<u8>, u64, &AnyFrame)) {}

    fn bytes(&self) -> u64 {
        self.decoder.stats().bytes()
    }

    fn buffered(&self) -> usize {
        self.decoder.buffered()
    }

    fn esc(&self) -> Option<&foc::Stats> {
        Some(self.decoder.stats())
    }

    fn hub(&self) -> Option<&datalink::Stats> {
        None
    }

    fn other(&self) -> Option<LinkStats> {
        None
    }

    fn forced(&self) -> Option<Protocol> {
        Some(self.protocol)
    }

    fn layout(&self) -> LinkKind {
        LinkKind::OneEsc
    }
}

/// A serial line's stream: its decoder, the receive times of its last bytes and, when a
/// protocol is forced, every format read over its first bytes.
#[derive(Debug)]
pub(super) struct Serial<D> {
    pub(super) decoder: D,
    /// Receive times of the last bytes of earlier batches, oldest first.
    history: Vec<f64>,
    /// Of a stream forced to read one protocol: every format read over its first bytes.
    probe: Option<Box<Probe>>,
}

impl<D: SerialDecoder> Serial<D> {
    /// The stream of `decoder`; when it reads one protocol only, every format is read over
    /// its first bytes too.
    pub(super) fn new(decoder: D) -> Serial<D> {
        Serial {
            probe: decoder.forced().map(|_| Box::default()),
            decoder,
            history: Vec::new(),
        }
    }

    /// Decodes a batch; `on_frame(t, channel, frame)` gets each ESC frame with its time
    /// (`None` without timing) and its DataLink channel (`None` on an ESC's own wire).
    #[inline(always)]
    pub(super) fn feed_timed(
        &mut self,
        batch: Batch<'_>,
        mut on_frame: impl FnMut(Option<f64>, Option<u8>, &AnyFrame),
    ) {
        if let Some(probe) = &mut self.probe {
            probe.feed(batch.bytes);
        }
        let start = self.decoder.bytes();
        match batch.times {
            None => {
                self.history.clear();
                self.decoder.feed(
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
                        self.decoder
                            .feed(&batch.bytes[from..i], Some(t - before), &mut emit);
                        from = i;
                    }
                    last = Some(t);
                }
                self.decoder.feed(&batch.bytes[from..], None, &mut emit);
                let keep = TIME_HISTORY.min(self.history.len() + times.len());
                let from_times = keep.min(times.len());
                let from_history = keep - from_times;
                self.history.drain(..self.history.len() - from_history);
                self.history
                    .extend_from_slice(&times[times.len() - from_times..]);
            }
        }
    }

    /// Decodes bytes without receive times; `on_frame(channel, offset, frame)` gets each ESC
    /// frame with its DataLink channel and the stream offset of its first byte.
    pub(super) fn feed_offsets(
        &mut self,
        bytes: &[u8],
        on_frame: impl FnMut(Option<u8>, u64, &AnyFrame),
    ) {
        self.history.clear();
        if let Some(probe) = &mut self.probe {
            probe.feed(bytes);
        }
        self.decoder.feed(bytes, None, on_frame);
    }

    /// Ends the stream: a frame cut off at the end is dropped, frames inside it are still
    /// found.
    pub(super) fn finish_timed(
        &mut self,
        mut on_frame: impl FnMut(Option<f64>, Option<u8>, &AnyFrame),
    ) {
        let end = self.decoder.bytes();
        let history = &self.history;
        let timed = !history.is_empty();
        let mut emit = |channel: Option<u8>, offset: u64, f: &AnyFrame| {
            let t = timed.then(|| time_at(history, &[], end, offset));
            on_frame(t, channel, f)
        };
        self.decoder.flush(&mut emit);
    }

    /// Whether an ESC frame (data or device information) has been found.
    fn esc_frames(&self) -> bool {
        self.decoder
            .esc()
            .is_some_and(|s| s.packets().count() > 0 || s.info_frames() > 0)
    }

    /// The DataLink hub's statistics, once the line has carried a hub frame.
    fn hub_found(&self) -> Option<&datalink::Stats> {
        self.decoder.hub().filter(|s| s.frames() > 0)
    }
}

impl Serial<Fast> {
    /// Continues this stream with `later`'s work (see [`super::Stream::then`]).
    pub(super) fn then(&mut self, later: &Serial<Fast>, first_packet: Option<u16>) -> bool {
        self.history.is_empty()
            && later.history.is_empty()
            && self.decoder.then(&later.decoder, first_packet)
    }
}

impl<D: SerialDecoder> LinkDecoder for Serial<D> {
    fn feed(&mut self, batch: Batch<'_>, on_frame: &mut OnFrame<'_>) {
        self.feed_timed(batch, on_frame)
    }

    fn feed_untimed(&mut self, bytes: &[u8], on_frame: &mut dyn FnMut(Option<u8>, u64, &AnyFrame)) {
        self.feed_offsets(bytes, on_frame)
    }

    fn finish(&mut self, on_frame: &mut OnFrame<'_>) {
        self.finish_timed(on_frame)
    }

    fn layout(&self) -> LinkKind {
        self.decoder.layout()
    }

    fn forced(&self) -> Option<Protocol> {
        self.decoder.forced()
    }

    fn bytes(&self) -> u64 {
        self.decoder.bytes()
    }

    fn buffered(&self) -> usize {
        self.decoder.buffered()
    }

    fn held_since(&self) -> Option<f64> {
        let held = self.decoder.buffered();
        let history = &self.history;
        (held > 0 && held <= history.len()).then(|| history[history.len() - held])
    }

    fn kind(&self) -> WireKind {
        if let Some(link) = self
            .decoder
            .other()
            .filter(|l| l.frames() + l.info_frames() > 0)
        {
            return WireKind::Other(link.protocol());
        }
        match (self.esc_frames(), self.hub_found().is_some()) {
            (false, false) => WireKind::Unknown,
            (true, false) => WireKind::Esc,
            (false, true) => WireKind::Hub,
            (true, true) => WireKind::Mixed,
        }
    }

    fn link(&self, channel: u8) -> LinkStats {
        if let Some(link) = self.decoder.other() {
            return link;
        }
        let esc = self.decoder.esc();
        let hub_found = self.hub_found().is_some();
        let from_hub = esc.is_none() || hub_found && (channel != 0 || !self.esc_frames());
        match self.decoder.hub().filter(|_| from_hub) {
            Some(hub) => LinkStats::hub(hub, channel),
            None => esc.map_or_else(LinkStats::default, LinkStats::wire),
        }
    }

    fn hub(&self) -> Option<&datalink::Stats> {
        self.hub_found()
    }

    fn found_instead(&self) -> Option<Protocol> {
        let found = self.probe.as_ref()?.found()?;
        (Some(found) != self.decoder.forced()).then_some(found)
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
