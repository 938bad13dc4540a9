//! The one link abstraction: a decoder of an input stream ([`LinkDecoder`]), whatever carries its
//! ESCs (a serial wire, a DataLink hub, a CAN bus). It says how its channels are laid out, hands
//! on frames with their channel and time, and gives one set of link figures per channel
//! ([`LinkStats`]).
//!
//! The fast lines (HW-FOC, DataLink, every format at once) are read through the same
//! implementation monomorphised ([`super::serial::Serial`] of [`super::serial::Fast`]); every
//! other link is a `Box<dyn LinkDecoder>`.

use hwfoc::format::LinkKind;
use hwfoc::telemetry::AnyFrame;
use hwfoc::{Protocol, datalink};

use super::WireKind;
use super::can::BusPlan;
use super::link::LinkStats;
use crate::input::Batch;

/// Where a stream's frames go: `emit(t, channel, frame)`, each with its receive time (`None`
/// without timing) and its channel (`None`: the stream's own ESC).
pub(crate) type OnFrame<'a> = dyn FnMut(Option<f64>, Option<u8>, &AnyFrame) + 'a;

/// The decoder of one input stream.
pub(crate) trait LinkDecoder: std::fmt::Debug + Send {
    /// Decodes a batch: `on_frame(t, channel, frame)` gets each frame completed.
    fn feed(&mut self, batch: Batch<'_>, on_frame: &mut OnFrame<'_>);
    /// Decodes bytes without receive times: `on_frame(channel, offset, frame)` gets each frame
    /// with the stream offset where it was handed on.
    fn feed_untimed(&mut self, bytes: &[u8], on_frame: &mut dyn FnMut(Option<u8>, u64, &AnyFrame));
    /// Ends the stream, handing on what it held.
    fn finish(&mut self, on_frame: &mut OnFrame<'_>);
    /// How its channels are laid out: one ESC, a hub's channels, a bus's slots.
    fn layout(&self) -> LinkKind;
    /// The protocol it was made to read only, if any.
    fn forced(&self) -> Option<Protocol>;
    /// Every byte fed so far.
    fn bytes(&self) -> u64;
    /// Bytes held for a frame still arriving.
    fn buffered(&self) -> usize;
    /// The receive time of the first byte held for a frame still arriving, where it knows it.
    fn held_since(&self) -> Option<f64>;
    /// Which protocols it has been heard speaking.
    fn kind(&self) -> WireKind;
    /// The link figures of its ESC on `channel`.
    fn link(&self, channel: u8) -> LinkStats;
    /// The DataLink hub's statistics, once it has carried a hub frame.
    fn hub(&self) -> Option<&datalink::Stats> {
        None
    }
    /// With a protocol forced: what its first bytes are instead, when not that protocol.
    fn found_instead(&self) -> Option<Protocol> {
        None
    }
    /// The records left out because another protocol is forced, by protocol.
    fn left_out(&self) -> Vec<(Protocol, u64)> {
        Vec::new()
    }
    /// Fixes the slots of a bus's ESCs ahead.
    fn plan(&mut self, _plan: &BusPlan) {}
    /// ESCs heard since the last call that claim a channel another holds, in words.
    fn take_clashes(&mut self) -> Vec<String> {
        Vec::new()
    }
}
