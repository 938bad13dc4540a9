//! What a forced protocol (`--protocol`, [`super::Stream::forced`]) adds to a stream: a CAN
//! bus's records of the other protocols left out and counted ([`Bus`]), and what the bytes of
//! a serial stream are when the protocol forced finds none of its frames ([`Probe`]).

use hwfoc::format::LinkKind;
use hwfoc::telemetry::AnyFrame;
use hwfoc::{Protocol, detect};

use super::WireKind;
use super::can::{BusPlan, CanLink, CanWire};
use super::decoder::{LinkDecoder, OnFrame};
use super::link::LinkStats;
use crate::input::Batch;

/// How many of a forced stream's first bytes are also read by every format at once, to say
/// what they are when the protocol forced finds nothing in them.
pub(crate) const PROBE_BYTES: u64 = 64 * 1024;

/// Every format read at once over a forced stream's first [`PROBE_BYTES`]: the protocol of the
/// first frame found.
#[derive(Debug, Default)]
pub(crate) struct Probe {
    decoder: detect::Decoder,
    found: Option<Protocol>,
}

impl Probe {
    /// Reads `data`, the stream's next bytes, while nothing is found and within the first
    /// [`PROBE_BYTES`].
    pub(crate) fn feed(&mut self, data: &[u8]) {
        let room = PROBE_BYTES.saturating_sub(self.decoder.bytes());
        if self.found.is_some() || room == 0 {
            return;
        }
        let data = &data[..data.len().min(usize::try_from(room).unwrap_or(usize::MAX))];
        let found = &mut self.found;
        self.decoder.feed(data, |d| {
            found.get_or_insert(d.protocol());
        });
    }

    /// The protocol of the first frame found, if any.
    pub(crate) fn found(&self) -> Option<Protocol> {
        self.found
    }
}

/// Hands a bus's record on unless another protocol than its own is forced (then counts it).
fn keep(
    forced: Option<Protocol>,
    left_out: &mut [u64; Protocol::ALL.len()],
    t: Option<f64>,
    place: Option<u8>,
    frame: &AnyFrame,
    emit: &mut OnFrame<'_>,
) {
    let protocol = match frame {
        AnyFrame::Data(d) => Some(d.protocol()),
        AnyFrame::Info(_) => None,
    };
    match forced.zip(protocol) {
        Some((forced, p)) if p != forced => {
            let i = Protocol::ALL.iter().position(|&q| q == p).unwrap_or(0);
            left_out[i] += 1;
        }
        _ => emit(t, place, frame),
    }
}

/// A CAN bus's stream, its records of protocols other than the one forced (if one is) left
/// out and counted by protocol.
#[derive(Debug)]
pub(crate) struct Bus {
    pub(crate) wire: CanWire,
    forced: Option<Protocol>,
    left_out: [u64; Protocol::ALL.len()],
}

impl Bus {
    /// A bus with nothing decoded, keeping the records of `forced` only (all when `None`).
    pub(crate) fn new(forced: Option<Protocol>) -> Bus {
        Bus {
            wire: CanWire::new(),
            forced,
            left_out: [0; Protocol::ALL.len()],
        }
    }

    /// Decodes `bytes` as [`CanWire::feed`] does, handing on the records kept.
    pub(crate) fn decode(&mut self, bytes: &[u8], times: Option<&[f64]>, emit: &mut OnFrame<'_>) {
        let (forced, left_out) = (self.forced, &mut self.left_out);
        self.wire.feed(bytes, times, &mut |t, place, frame| {
            keep(forced, left_out, t, place, frame, emit)
        });
    }

    /// Ends the stream as [`CanWire::finish`] does, handing on the records kept.
    pub(crate) fn end(&mut self, emit: &mut OnFrame<'_>) {
        let (forced, left_out) = (self.forced, &mut self.left_out);
        self.wire
            .finish(&mut |t, place, frame| keep(forced, left_out, t, place, frame, emit));
    }

    /// The link of the ESC in `slot`: no record where its protocol is not the one forced.
    pub(crate) fn can_link(&self, slot: u8) -> CanLink {
        let mut link = self.wire.link(slot);
        if self.forced.is_some_and(|p| p != link.protocol) {
            link.records = 0;
        }
        link
    }
}

impl LinkDecoder for Bus {
    fn feed(&mut self, batch: Batch<'_>, on_frame: &mut OnFrame<'_>) {
        self.decode(batch.bytes, batch.times, on_frame);
    }

    /// Each record at the offset of the bytes fed before it was handed on.
    fn feed_untimed(&mut self, bytes: &[u8], on_frame: &mut dyn FnMut(Option<u8>, u64, &AnyFrame)) {
        let at = self.wire.bytes();
        self.decode(bytes, None, &mut |_, slot, f| on_frame(slot, at, f));
    }

    fn finish(&mut self, on_frame: &mut OnFrame<'_>) {
        self.end(on_frame);
    }

    fn layout(&self) -> LinkKind {
        LinkKind::Bus
    }

    fn forced(&self) -> Option<Protocol> {
        self.forced
    }

    fn bytes(&self) -> u64 {
        self.wire.bytes()
    }

    fn buffered(&self) -> usize {
        self.wire.buffered()
    }

    /// None: a record held for its node's GetEscID answer has its own time.
    fn held_since(&self) -> Option<f64> {
        None
    }

    fn kind(&self) -> WireKind {
        let link = self.can_link(0);
        match link.records {
            0 => WireKind::Unknown,
            _ => WireKind::Other(link.protocol),
        }
    }

    fn link(&self, slot: u8) -> LinkStats {
        LinkStats::bus(self.can_link(slot))
    }

    /// The records left out, by protocol (those of which some were), in
    /// [`Protocol::ALL`]'s order.
    fn left_out(&self) -> Vec<(Protocol, u64)> {
        Protocol::ALL
            .into_iter()
            .zip(self.left_out)
            .filter(|&(_, n)| n > 0)
            .collect()
    }

    fn plan(&mut self, plan: &BusPlan) {
        self.wire.set_plan(plan);
    }

    fn take_clashes(&mut self) -> Vec<String> {
        let clashes = self.wire.take_clashes();
        clashes.iter().map(|c| c.to_string()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::dronecan::{EscStatus, Message, StatusMsg1};

    #[test]
    fn the_probe_finds_a_format_in_the_first_bytes_only() {
        let frame = hwfoc::foc::DataFrame::default().encode();
        let mut probe = Probe::default();
        probe.feed(&vec![0x55; PROBE_BYTES as usize]);
        for _ in 0..20 {
            probe.feed(&frame);
        }
        assert_eq!(probe.found(), None, "past its first bytes");
        let mut probe = Probe::default();
        for _ in 0..20 {
            probe.feed(&frame);
        }
        assert_eq!(probe.found(), Some(Protocol::HwFoc));
    }

    #[test]
    fn a_bus_keeps_the_forced_protocols_records_and_counts_the_others() {
        let hw: Message = StatusMsg1 {
            rpm: 1,
            pwm: 1,
            status: 0,
        }
        .into();
        let std: Message = EscStatus {
            error_count: 0,
            voltage: 24.0,
            current: 1.0,
            temperature: 300.0,
            rpm: 100,
            power_rating_pct: 10,
            esc_index: 1,
        }
        .into();
        let mut bytes = Vec::new();
        for tid in 0..3 {
            for (m, node) in [(hw, 5), (std, 9)] {
                for f in m.frames(16, node, 0, tid) {
                    bytes.extend_from_slice(&f.to_socketcan_record());
                }
            }
        }
        for (forced, kept, left_out) in [
            (None, 6, vec![]),
            (Some(Protocol::HwCan), 3, vec![(Protocol::DroneCan, 3)]),
            (Some(Protocol::DroneCan), 3, vec![(Protocol::HwCan, 3)]),
            (
                Some(Protocol::Hw5),
                0,
                vec![(Protocol::HwCan, 3), (Protocol::DroneCan, 3)],
            ),
        ] {
            let mut bus = Bus::new(forced);
            let mut n = 0;
            let mut count = |_, _, f: &AnyFrame| {
                let AnyFrame::Data(d) = f else { return };
                assert!(forced.is_none_or(|p| p == d.protocol()));
                n += 1;
            };
            bus.decode(&bytes, None, &mut count);
            // (The Hobbywing ESC, which never answers GetEscID, is held to the end.)
            bus.end(&mut count);
            assert_eq!((n, bus.left_out()), (kept, left_out), "{forced:?}");
        }
    }
}
