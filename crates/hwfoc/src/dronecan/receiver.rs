//! Receiving: CAN frames in, decoded transfers out ([`Receiver`]), counted in [`LinkStats`].

use super::frame::{CanFrame, FrameKind};
use super::id::{Header, TailByte, TransferType};
use super::kind::{Form, Kind, MAX_PAYLOAD_LEN, Message};
use super::stats::{Judged, LinkStats, NODES};
use super::transfer::{FRAME_PAYLOAD, signature_crc};
use crate::counters::MAX_PACKET_GAP;
use crate::wire::crc16_ccitt;

/// The known data types whose transfers take more than one frame (a payload over
/// [`FRAME_PAYLOAD`] bytes): messages all (a test checks it), so a node has one transfer of
/// each in progress at most.
const MULTI_FRAME_TYPES: usize = {
    let mut n = 0;
    let mut i = 0;
    while i < Kind::COUNT {
        if Kind::ALL[i].max_len() > FRAME_PAYLOAD {
            n += 1;
        }
        i += 1;
    }
    n
};

/// Reassembly slots of a [`Receiver`] by default: multi-frame transfers that can be in
/// progress at once. Single-frame transfers take none; every node id can have one transfer of
/// each known multi-frame type in progress (only `uavcan.equipment.esc.Status`), so 128 slots
/// hold every transfer a bus can have in progress (of 40 bytes each: 5 KiB, beside the
/// statistics' 22 KiB). A smaller receiver ([`Receiver::with_slots`]) counts a transfer that
/// finds no slot ([`BusStats::no_slot`](super::BusStats::no_slot)).
pub const DEFAULT_SLOTS: usize = NODES * MULTI_FRAME_TYPES;

/// A silence of the whole bus this long (milliseconds) or longer, between two frames pushed with
/// their times ([`Receiver::push_at`]), is a power cycle: each node's next transfer of every
/// message type is a [restart](super::NodeStats::restarts), not a gap. (As a serial line's
/// silence of a second.)
pub const BUS_SILENCE_MS: u32 = 1000;

/// When a node's message type last completed a transfer (timed), and its period.
#[derive(Debug, Clone, Copy)]
struct Timing {
    /// Milliseconds (wrapping) of the last transfer.
    last_ms: u32,
    /// The mean interval between transfers one id apart, in 1/16 ms (0: not known yet).
    period: u16,
    /// [`Timing::KNOWN`], [`Timing::AFTER_SILENCE`].
    flags: u8,
}

impl Timing {
    const NONE: Timing = Timing {
        last_ms: 0,
        period: 0,
        flags: 0,
    };
    /// `last_ms` holds a time.
    const KNOWN: u8 = 1;
    /// The whole bus was silent since.
    const AFTER_SILENCE: u8 = 2;
}

/// A decoded transfer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Received {
    /// Who sent it, to whom, at what priority.
    pub header: Header,
    /// Its transfer id (a service response carries its request's).
    pub transfer_id: u8,
    /// What it says.
    pub message: Message,
}

/// What identifies a stream of transfers: one transfer at a time is in progress per key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Key {
    source: u8,
    data_type_id: u16,
    form: Form,
    destination: u8,
}

impl Key {
    fn of(header: &Header, kind: Kind) -> Key {
        Key {
            source: header.source_node,
            data_type_id: header.data_type_id,
            form: kind.form(),
            destination: header.transfer.destination().unwrap_or(0),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Free,
    /// Collecting the frames of a transfer.
    Receiving,
    /// Swallowing the rest of a transfer already counted as lost.
    Discarding,
}

#[derive(Debug, Clone, Copy)]
struct Slot {
    key: Key,
    state: State,
    transfer_id: u8,
    /// The toggle the next frame must have.
    toggle: bool,
    /// A frame came since the last [`Receiver::expire`].
    touched: bool,
    /// The receiver's frame count when last used (least recently used slots go first).
    used: u32,
    /// The CRC carried in the first frame.
    carried_crc: u16,
    /// The CRC of the signature and the payload so far.
    crc: u16,
    len: usize,
    buf: [u8; MAX_PAYLOAD_LEN],
}

impl Slot {
    const FREE: Slot = Slot {
        key: Key {
            source: 0,
            data_type_id: 0,
            form: Form::Message,
            destination: 0,
        },
        state: State::Free,
        transfer_id: 0,
        toggle: false,
        touched: false,
        used: 0,
        carried_crc: 0,
        crc: 0,
        len: 0,
        buf: [0; MAX_PAYLOAD_LEN],
    };
}

/// Reassembles DroneCAN transfers from CAN frames, decodes those of the known data types
/// ([`Kind`]) and counts everything ([`LinkStats`]). `SLOTS` multi-frame transfers can be in
/// progress at once (default [`DEFAULT_SLOTS`]); no allocation, no clock, never a panic.
///
/// # Rules
///
/// - Frames that are not DroneCAN (standard ids, remote, error and empty frames, ids DroneCAN
///   forbids) and anonymous messages are counted in [`BusStats`](super::BusStats) and dropped.
/// - A transfer's first frame of an unknown data type is counted
///   ([`NodeStats::unknown_types`](super::NodeStats::unknown_types)); its frames are dropped.
/// - Transfers are told apart by source node, data type, message/request/response and
///   destination: one transfer of each at a time, frames of different keys interleaving freely.
/// - A single frame (start and end) is a whole transfer, no CRC. A multi-frame transfer starts
///   with a full frame whose first two bytes are the transfer CRC (little-endian,
///   [`transfer_crc`](super::transfer_crc)); every frame but the last is full (8 bytes); the
///   toggle bit is 0 in the first frame and alternates; every frame has the first's transfer
///   id. The CRC is checked at the last frame.
/// - A start frame while a transfer of its key is in progress cuts that one short (counted).
///   A frame of another transfer id than the one in progress, or with none in progress, is an
///   orphan (counted, dropped; the transfer in progress goes on). A toggle out of turn, a short
///   frame or a transfer longer than [`MAX_PAYLOAD_LEN`] drops the transfer (counted once: its
///   later frames are swallowed).
/// - A whole message transfer's id is checked against the previous one of its type from the
///   node: the same id is a duplicate (counted, not handed on), a skip is a gap (counted).
/// - A whole transfer is decoded if its length is one of its type's; otherwise counted as a
///   bad payload.
/// - Without a clock, a transfer whose end never comes stays in its slot until a new transfer
///   of its key starts, its slot is needed (the least recently used goes), or the caller calls
///   [`Receiver::expire`] (say once a second: a transfer silent for a whole period is dropped;
///   DroneCAN's transfer timeout is 2 s) or [`Receiver::reset`].
///
/// ```
/// use hwfoc::dronecan::{Message, Receiver, StatusMsg1};
///
/// let mut rx = Receiver::new();
/// let sent = Message::from(StatusMsg1 { rpm: 1200, pwm: 300, status: 0 });
/// let mut got = None;
/// for frame in sent.frames(16, 1, 0, 3) {
///     got = rx.push(&frame);
/// }
/// let got = got.unwrap();
/// assert_eq!((got.header.source_node, got.transfer_id), (1, 3));
/// assert_eq!(got.message, sent);
/// assert_eq!(rx.stats().node(1).transfers(sent.kind()), 1);
/// ```
#[derive(Debug, Clone)]
pub struct Receiver<const SLOTS: usize = DEFAULT_SLOTS> {
    slots: [Slot; SLOTS],
    stats: LinkStats,
    clock: u32,
    /// Each node's message types' last transfers and periods (timed pushes: 7 KiB).
    timing: [[Timing; Kind::MESSAGES]; NODES],
    /// The time of the last frame pushed with one, milliseconds (wrapping).
    last_frame_ms: Option<u32>,
    /// The time of the frame being pushed, when given.
    now_ms: Option<u32>,
}

impl Default for Receiver {
    fn default() -> Self {
        Receiver::new()
    }
}

impl Receiver {
    /// A receiver with [`DEFAULT_SLOTS`] slots.
    pub const fn new() -> Self {
        Receiver::with_slots()
    }
}

impl<const SLOTS: usize> Receiver<SLOTS> {
    /// A receiver with `SLOTS` slots (`Receiver::<4>::with_slots()`).
    pub const fn with_slots() -> Self {
        Receiver {
            slots: [Slot::FREE; SLOTS],
            stats: LinkStats::new(),
            clock: 0,
            timing: [[Timing::NONE; Kind::MESSAGES]; NODES],
            last_frame_ms: None,
            now_ms: None,
        }
    }

    /// The statistics so far.
    pub const fn stats(&self) -> &LinkStats {
        &self.stats
    }

    /// Sets every counter to zero (transfers in progress and transfer-id history are kept).
    pub fn reset_stats(&mut self) {
        self.stats.bus = LinkStats::new().bus;
        for node in self.stats.nodes.iter_mut() {
            node.clear_counters();
        }
    }

    /// Multi-frame transfers in progress.
    pub fn in_progress(&self) -> usize {
        self.slots
            .iter()
            .filter(|s| s.state == State::Receiving)
            .count()
    }

    /// Drops every transfer that received no frame since the previous call (each counted as
    /// cut short). Called every `T`, a transfer silent for between `T` and `2T` is dropped.
    pub fn expire(&mut self) {
        for i in 0..SLOTS {
            let slot = &mut self.slots[i];
            if slot.state == State::Free {
                continue;
            }
            if slot.touched {
                slot.touched = false;
            } else {
                self.free(i);
            }
        }
    }

    /// Drops every transfer in progress (each counted as cut short) and forgets every node's
    /// transfer ids (the next transfer of each type starts afresh: no gap, no duplicate).
    /// Counters are kept.
    pub fn reset(&mut self) {
        for i in 0..SLOTS {
            self.free(i);
        }
        for node in self.stats.nodes.iter_mut() {
            node.forget_transfer_ids();
        }
        self.timing = [[Timing::NONE; Kind::MESSAGES]; NODES];
        self.last_frame_ms = None;
    }

    /// [`Receiver::push`] of a frame received at `t_us` microseconds (of any clock that does
    /// not step): a message type's transfer-id gap is then judged by time as well as modulo 32
    /// (40 transfers lost at 50 Hz are 40, not 8: the count congruent to the ids' step nearest
    /// to the time since the type's last transfer over its period, the mean interval of
    /// transfers one id apart), and after a silence of the whole bus of [`BUS_SILENCE_MS`] or
    /// more (or a gap over [`MAX_PACKET_GAP`] transfers) each node's next transfer of a type
    /// is a [restart](super::NodeStats::restarts), not a gap. A clock stepping back judges by
    /// ids alone.
    pub fn push_at(&mut self, frame: &CanFrame, t_us: u64) -> Option<Received> {
        let now = (t_us / 1000) as u32;
        if let Some(last) = self.last_frame_ms {
            let quiet = now.wrapping_sub(last);
            if (BUS_SILENCE_MS..1 << 31).contains(&quiet) {
                for t in self.timing.iter_mut().flatten() {
                    if t.flags & Timing::KNOWN != 0 {
                        t.flags |= Timing::AFTER_SILENCE;
                    }
                }
            }
        }
        self.last_frame_ms = Some(now);
        self.now_ms = Some(now);
        let received = self.push(frame);
        self.now_ms = None;
        received
    }

    /// What the time says of the step to `transfer_id` of `kind` from `node` (a timed push's
    /// message transfer), the type's timing brought up to it.
    fn judge(&mut self, node: u8, kind: Kind, transfer_id: u8) -> Judged {
        let (Some(now), Some(i)) = (self.now_ms, kind.message_index()) else {
            return Judged::ByIds;
        };
        let stats = self.stats.node(node);
        let step_one = stats
            .last_transfer_id(kind)
            .is_some_and(|last| transfer_id.wrapping_sub(last) & 0x1F == 1);
        let t = &mut self.timing[usize::from(node) % NODES][i];
        let elapsed = now.wrapping_sub(t.last_ms);
        let known = t.flags & Timing::KNOWN != 0 && elapsed < 1 << 31;
        let judged = if t.flags & Timing::AFTER_SILENCE != 0 {
            Judged::Restart
        } else if !known || t.period == 0 {
            Judged::ByIds
        } else {
            let period = u64::from(t.period);
            let expected = ((u64::from(elapsed) * 16 + period / 2) / period).max(1);
            if expected - 1 > u64::from(MAX_PACKET_GAP) {
                Judged::Restart
            } else {
                Judged::Expected(expected as u32)
            }
        };
        if known && step_one && judged != Judged::Restart {
            // The mean interval of transfers one id apart (an eighth of each new one). One
            // under half the mean is left out, and one over twice the mean counts as twice:
            // frames bunched after a receiver's stall (intervals near 0) say nothing of the
            // sender's period, and the stall itself moves it an eighth at most. A sender that
            // slows down is followed at an eighth a transfer; one that more than doubles its
            // rate at once is not (its period stays long, and a gap's time over it then counts
            // fewer transfers than the gap held).
            let interval = i64::from(elapsed.min(0xFFF)) * 16;
            let period = i64::from(t.period);
            let mean = if period == 0 {
                interval
            } else if interval < period / 2 {
                period
            } else {
                period + (interval.min(period * 2) - period) / 8
            };
            // 0 (a first interval under a millisecond) stays unknown.
            t.period = u16::try_from(mean).unwrap_or(u16::MAX);
        }
        t.last_ms = now;
        t.flags = Timing::KNOWN;
        judged
    }

    /// Frees slot `i`, counting a transfer in progress as cut short.
    fn free(&mut self, i: usize) {
        let slot = &mut self.slots[i];
        if slot.state == State::Receiving {
            self.stats.node_mut(slot.key.source).cut();
        }
        slot.state = State::Free;
    }

    fn find(&self, key: Key) -> Option<usize> {
        self.slots
            .iter()
            .position(|s| s.state != State::Free && s.key == key)
    }

    /// A slot for a new transfer of `key`: a free one, else the least recently used (its
    /// transfer counted as cut short). `None` with no slot at all.
    fn take_slot(&mut self, key: Key, transfer_id: u8, state: State) -> Option<usize> {
        let i = match self.slots.iter().position(|s| s.state == State::Free) {
            Some(i) => i,
            None => {
                let clock = self.clock;
                self.stats.bus.no_slot = self.stats.bus.no_slot.saturating_add(1);
                let (i, _) = self
                    .slots
                    .iter()
                    .enumerate()
                    .max_by_key(|(_, s)| clock.wrapping_sub(s.used))?;
                self.free(i);
                i
            }
        };
        let slot = &mut self.slots[i];
        slot.key = key;
        slot.state = state;
        slot.transfer_id = transfer_id;
        slot.touched = true;
        slot.used = self.clock;
        slot.len = 0;
        Some(i)
    }

    /// Takes one CAN frame; returns the transfer it completes, decoded, if any.
    pub fn push(&mut self, frame: &CanFrame) -> Option<Received> {
        let bus = &mut self.stats.bus;
        bus.frames = bus.frames.saturating_add(1);
        let counter = match (frame.kind(), frame.is_extended()) {
            (FrameKind::Remote, _) => Some(&mut bus.remote),
            (FrameKind::Error, _) => Some(&mut bus.error),
            (FrameKind::Data, false) => Some(&mut bus.standard),
            (FrameKind::Data, true) if frame.is_empty() => Some(&mut bus.empty),
            (FrameKind::Data, true) => None,
        };
        if let Some(n) = counter {
            *n = n.saturating_add(1);
            return None;
        }
        let (&tail, body) = frame.data().split_last()?;
        let header = match Header::parse(frame.id()) {
            Ok(h) => h,
            Err(_) => {
                bus.bad_ids = bus.bad_ids.saturating_add(1);
                return None;
            }
        };
        if let TransferType::Anonymous { .. } = header.transfer {
            bus.anonymous = bus.anonymous.saturating_add(1);
            return None;
        }
        self.clock = self.clock.wrapping_add(1);
        let tail = TailByte::from_byte(tail);
        let source = header.source_node;
        self.stats.node_mut(source).frame();
        let Some(kind) = Kind::of(&header) else {
            if tail.start {
                self.stats.node_mut(source).unknown_type();
            }
            return None;
        };
        let key = Key::of(&header, kind);
        let tid = tail.transfer_id;

        if tail.start {
            if let Some(i) = self.find(key) {
                self.free(i);
            }
            let node = self.stats.node_mut(source);
            if tail.toggle {
                node.toggle_error();
            } else if tail.end {
                return self.complete(header, kind, tid, body);
            } else if body.len() != FRAME_PAYLOAD {
                node.short_frame();
            } else {
                let Some(i) = self.take_slot(key, tid, State::Receiving) else {
                    self.stats.node_mut(source).cut();
                    return None;
                };
                let slot = &mut self.slots[i];
                let (crc, rest) = body.split_at(2);
                slot.carried_crc = u16::from_le_bytes([crc[0], crc[1]]);
                slot.crc = crc16_ccitt(signature_crc(kind.signature()), rest);
                slot.buf[..rest.len()].copy_from_slice(rest);
                slot.len = rest.len();
                slot.toggle = true;
                return None;
            }
            if !tail.end {
                // swallow the rest of the transfer already counted
                self.take_slot(key, tid, State::Discarding);
            }
            return None;
        }

        let Some(i) = self.find(key).filter(|&i| self.slots[i].transfer_id == tid) else {
            self.stats.node_mut(source).orphan();
            return None;
        };
        let clock = self.clock;
        let slot = &mut self.slots[i];
        slot.touched = true;
        slot.used = clock;
        if slot.state == State::Discarding {
            if tail.end {
                slot.state = State::Free;
            }
            return None;
        }
        let node = &mut self.stats.nodes[usize::from(source)];
        let lost = if tail.toggle != slot.toggle {
            node.toggle_error();
            true
        } else if !tail.end && body.len() != FRAME_PAYLOAD {
            node.short_frame();
            true
        } else if slot.len + body.len() > MAX_PAYLOAD_LEN {
            node.too_long_transfer();
            true
        } else {
            false
        };
        if lost {
            slot.state = if tail.end {
                State::Free
            } else {
                State::Discarding
            };
            return None;
        }
        slot.buf[slot.len..slot.len + body.len()].copy_from_slice(body);
        slot.len += body.len();
        slot.crc = crc16_ccitt(slot.crc, body);
        slot.toggle = !slot.toggle;
        if !tail.end {
            return None;
        }
        slot.state = State::Free;
        if slot.crc != slot.carried_crc {
            node.checksum_failure();
            return None;
        }
        let (buf, len) = (slot.buf, slot.len);
        self.complete(header, kind, tid, &buf[..len])
    }

    /// A whole transfer: checks its transfer id, decodes it.
    fn complete(
        &mut self,
        header: Header,
        kind: Kind,
        transfer_id: u8,
        payload: &[u8],
    ) -> Option<Received> {
        let judged = self.judge(header.source_node, kind, transfer_id);
        let node = self.stats.node_mut(header.source_node);
        if !node.next_transfer_id_judged(kind, transfer_id, judged) {
            return None;
        }
        match Message::decode(kind, payload) {
            Ok(message) => {
                node.transfer(kind);
                Some(Received {
                    header,
                    transfer_id,
                    message,
                })
            }
            Err(_) => {
                node.bad_payload();
                None
            }
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::dronecan::{EscStatus, GetEscId, StatusMsg2};
    use std::vec::Vec;

    fn status(i: u8) -> Message {
        Message::from(EscStatus {
            error_count: u32::from(i),
            voltage: 16.5,
            current: -2.25,
            temperature: 300.0,
            rpm: -1234,
            power_rating_pct: 55,
            esc_index: i,
        })
    }

    fn frames(m: &Message, node: u8, tid: u8) -> Vec<CanFrame> {
        m.frames(16, node, 0, tid).collect()
    }

    /// Every known multi-frame type is a message (a node has one transfer of each in progress
    /// at most, which [`DEFAULT_SLOTS`] counts on), and each slot is small.
    #[test]
    fn the_default_slots_hold_every_node_s_transfers() {
        for k in Kind::ALL {
            if k.max_len() > FRAME_PAYLOAD {
                assert_eq!(k.form(), Form::Message, "{k:?}");
            }
        }
        assert_eq!(DEFAULT_SLOTS, 128);
        assert!(core::mem::size_of::<Slot>() <= 40);
    }

    #[test]
    fn multi_frame_and_interleaving() {
        let mut rx: Receiver<2> = Receiver::with_slots();
        let a = frames(&status(1), 5, 0);
        let b = frames(&status(2), 6, 0);
        assert_eq!(a.len(), 3);
        let mut got = Vec::new();
        for (fa, fb) in a.iter().zip(b.iter()) {
            got.extend(rx.push(fa));
            got.extend(rx.push(fb));
        }
        assert_eq!(got.len(), 2);
        assert_eq!(got[0].message, status(1));
        assert_eq!(got[1].message, status(2));
        assert_eq!(rx.in_progress(), 0);
    }

    #[test]
    fn a_third_transfer_evicts_the_oldest() {
        let mut rx: Receiver<2> = Receiver::with_slots();
        for node in [1, 2, 3] {
            rx.push(&frames(&status(node), node, 0)[0]);
        }
        assert_eq!(rx.in_progress(), 2);
        assert_eq!(rx.stats().node(1).cut_short(), 1);
        // node 1's next frame is now an orphan; node 3's transfer completes
        rx.push(&frames(&status(1), 1, 0)[1]);
        assert_eq!(rx.stats().node(1).orphan_frames(), 1);
        let f = frames(&status(3), 3, 0);
        assert!(rx.push(&f[1]).is_none());
        assert_eq!(rx.push(&f[2]).map(|r| r.message), Some(status(3)));
        let mut none: Receiver<0> = Receiver::with_slots();
        assert!(none.push(&f[0]).is_none());
        assert_eq!(none.stats().node(3).cut_short(), 1);
    }

    #[test]
    fn expire_and_reset() {
        let mut rx = Receiver::new();
        let f = frames(&status(1), 5, 0);
        rx.push(&f[0]);
        rx.expire();
        assert_eq!(rx.in_progress(), 1, "touched since the last expire");
        rx.push(&f[1]);
        rx.expire();
        assert_eq!(rx.in_progress(), 1);
        rx.expire();
        assert_eq!(rx.in_progress(), 0);
        assert_eq!(rx.stats().node(5).cut_short(), 1);
        assert!(rx.push(&f[2]).is_none());
        assert_eq!(rx.stats().node(5).orphan_frames(), 1);

        let m = Message::from(GetEscId::answer(5, 2));
        let one = frames(&m, 5, 9);
        assert!(rx.push(&one[0]).is_some());
        assert!(rx.push(&one[0]).is_none(), "duplicate");
        rx.push(&f[0]);
        rx.reset();
        assert_eq!(rx.stats().node(5).cut_short(), 2);
        assert!(rx.push(&one[0]).is_some(), "history forgotten");
        assert_eq!(rx.stats().node(5).duplicate_packets(), 1);
        rx.reset_stats();
        assert_eq!(rx.stats().node(5).frames(), 0);
        assert!(rx.push(&one[0]).is_none(), "history kept by reset_stats");
    }

    #[test]
    fn not_dronecan() {
        let mut rx = Receiver::new();
        let others = [
            CanFrame::standard(0x123, &[1]).unwrap(),
            CanFrame::remote(0x1000, true, 2).unwrap(),
            CanFrame::error(4, &[0; 8]).unwrap(),
            CanFrame::extended(0x1000, &[]).unwrap(),
            CanFrame::extended(0x0000_8180, &[0xC0]).unwrap(),
            CanFrame::extended(0x1000_0D00, &[1, 0xC0]).unwrap(),
        ];
        for f in &others {
            assert!(rx.push(f).is_none());
        }
        let bus = rx.stats().bus();
        assert_eq!(bus.frames(), 6);
        assert_eq!(bus.not_dronecan(), 5);
        assert_eq!(bus.anonymous_frames(), 1);
        assert_eq!(rx.stats().nodes().count(), 0);
        // an unknown type
        rx.push(&CanFrame::extended(0x104E_AA07, &[1, 0xC0]).unwrap());
        assert_eq!(rx.stats().node(7).unknown_types(), 1);
        // a bad payload: StatusMsg2 of 4 bytes
        let m = Message::from(StatusMsg2::default());
        let f = frames(&m, 7, 0);
        let mut short = f[0].data().to_vec();
        short.remove(0);
        assert!(
            rx.push(&CanFrame::extended(f[0].id(), &short).unwrap())
                .is_none()
        );
        assert_eq!(rx.stats().node(7).bad_payloads(), 1);
    }
}
