//! A CAN bus's stream: CAN frames carried as bytes, [`SOCKETCAN_RECORD_LEN`] per frame
//! (pcapng's `LINKTYPE_CAN_SOCKETCAN` layout, [`CanFrame::to_socketcan_record`]), each byte with
//! its frame's receive time: how every CAN input (candump logs, pcapng recordings, SLCAN
//! adapters, SocketCAN interfaces) hands its frames on.
//!
//! The codec's [`Receiver`] reassembles and counts the transfers, [`Escs`] makes a record of
//! each ESC status with its node's slower messages; each record is handed on with its ESC's
//! slot on the bus as its channel, which the ESC numbering gives a number of its own
//! (`esc_numbers.rs`).
//!
//! An ESC on a bus is its node (a standard DroneCAN ESC: its node and `esc_index`: an
//! [`EscKey`]); its place ([`Data::bus_place`]: throttle channel - 1 once a GetEscID answer
//! mapped it, else its node id; a standard ESC's `esc_index`) only orders the slots. The slot
//! of an ESC is fixed when it is first heard: its place, unless another ESC holds that slot
//! already, then the next after the highest slot given (two ESCs that claim one throttle
//! channel stay two). A file's bus is read ahead ([`BusPlan`], `sources/can_plan.rs`), so that
//! each ESC's slot is that of its place at the end of the file: a node that answers GetEscID
//! late keeps one slot for the whole file. Live, a Hobbywing node heard before its GetEscID
//! answer is held (its records kept back) until the answer comes, up to [`HOLD_S`] of the bus's
//! clock ([`HOLD_FRAMES`] CAN frames without receive times, [`HOLD_RECORDS`] records at most),
//! then its records are handed on under the slot of its channel: the slot read ahead gives it.
//! A node that does not answer within the hold is placed by its node id, as read ahead when no
//! answer ever comes; one that answers after that keeps the slot it got.

use hwfoc::Protocol;
use hwfoc::dronecan::{BusStats, CanFrame, Escs, NodeStats, Receiver, SOCKETCAN_RECORD_LEN};
use hwfoc::telemetry::{AnyFrame, Data};

use super::decoder::OnFrame;

/// Slots on a bus: places (node ids 0-127 before a node is mapped to its throttle channel, then
/// its channel - 1, a byte; a standard ESC's `esc_index`), and those after the highest place
/// given to ESCs that claim a place another holds.
pub(crate) const BUS_PLACES: usize = 256;

/// An ESC's identity on a bus: its node, and a standard DroneCAN ESC's `esc_index` (a node may
/// report several ESCs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) struct EscKey {
    /// The sending node.
    pub(crate) node: u8,
    /// A standard ESC's `esc_index`; `None` for a Hobbywing ESC.
    pub(crate) index: Option<u8>,
}

impl EscKey {
    /// The ESC a record is of.
    pub(crate) fn of(data: &Data) -> Option<EscKey> {
        Some(EscKey {
            node: data.node()?,
            index: data.esc_index(),
        })
    }
}

impl std::fmt::Display for EscKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.index {
            None => write!(f, "node {}", self.node),
            Some(i) => write!(f, "node {} (esc_index {i})", self.node),
        }
    }
}

/// An ESC at its place, and whether the place is its node id (a Hobbywing ESC without a
/// GetEscID answer) rather than a throttle channel - 1 (an answer's, a standard ESC's
/// `esc_index`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Claim {
    pub(crate) key: EscKey,
    pub(crate) by_node_id: bool,
}

impl Claim {
    /// The ESC of a record at its place.
    fn of(data: &Data) -> Option<Claim> {
        Some(Claim {
            key: EscKey::of(data)?,
            by_node_id: matches!(data, Data::HwCan(r) if r.throttle_channel.is_none()),
        })
    }
}

impl std::fmt::Display for Claim {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.by_node_id {
            true => write!(f, "{} (no GetEscID answer: by its node id)", self.key),
            false => write!(f, "{}", self.key),
        }
    }
}

/// Two ESCs of a bus that claim one place: the first keeps it, the second is an ESC of its own
/// in a slot after the bus's places.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Clash {
    /// The place both claim.
    pub(crate) place: u8,
    /// The ESC that holds it, and the other.
    pub(crate) first: Claim,
    pub(crate) second: Claim,
}

impl std::fmt::Display for Clash {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (first, second) = (self.first, self.second);
        if first.by_node_id || second.by_node_id {
            write!(
                f,
                "{first} and {second} both claim place {} on the bus: read as two ESCs",
                self.place
            )
        } else {
            write!(
                f,
                "{first} and {second} both claim throttle channel {}: read as two ESCs",
                u16::from(self.place) + 1
            )
        }
    }
}

/// The slots of a bus's ESCs, fixed before it is read (a file's bus, read ahead) or as they are
/// first heard (live).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct BusPlan {
    /// Each ESC's slot, in the order they were first heard, with its place when it got it.
    slots: Vec<(Claim, u8)>,
    /// ESCs that claimed a place another held.
    pub(crate) clashes: Vec<Clash>,
}

impl BusPlan {
    /// The slot of `key` at `place`: the one it has, else given now (its place if free, else
    /// the next after the highest slot given; `None` past the last slot).
    fn slot(&mut self, claim: Claim, place: u8) -> Option<u8> {
        if let Some(&(_, slot)) = self.slots.iter().find(|(c, _)| c.key == claim.key) {
            return Some(slot);
        }
        let slot = match self.slots.iter().find(|(_, s)| *s == place) {
            None => place,
            Some(&(first, _)) => {
                self.clashes.push(Clash {
                    place,
                    first,
                    second: claim,
                });
                self.end()?
            }
        };
        self.slots.push((claim, slot));
        Some(slot)
    }

    /// The slot after the highest given.
    fn end(&self) -> Option<u8> {
        u8::try_from(self.len()).ok()
    }

    /// How many slots the bus numbers: up to the highest given.
    pub(crate) fn len(&self) -> usize {
        self.slots
            .iter()
            .map(|&(_, s)| usize::from(s) + 1)
            .max()
            .unwrap_or(0)
    }

    /// Whether `key` has a slot.
    fn has(&self, key: EscKey) -> bool {
        self.slots.iter().any(|(c, _)| c.key == key)
    }

    /// Whether no ESC was heard.
    pub(crate) fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }
}

/// A bus read ahead: the place each ESC had last, in the order they were first heard.
#[derive(Debug)]
pub(crate) struct BusLearner {
    wire: CanWire,
    last: Vec<(Claim, u8)>,
}

impl BusLearner {
    pub(crate) fn new() -> BusLearner {
        let mut wire = CanWire::new();
        // Each record's place as it comes: nothing to wait for.
        wire.hold = false;
        BusLearner {
            wire,
            last: Vec::new(),
        }
    }

    /// Reads `bytes` of the bus (times as [`CanWire::feed`] takes them).
    pub(crate) fn feed(&mut self, bytes: &[u8], times: Option<&[f64]>) {
        let last = &mut self.last;
        self.wire.feed(bytes, times, &mut |_, _, f| {
            let AnyFrame::Data(d) = f else { return };
            let (Some(claim), Some(place)) = (Claim::of(d), d.bus_place()) else {
                return;
            };
            match last.iter_mut().find(|(c, _)| c.key == claim.key) {
                Some(e) => *e = (claim, place),
                None => last.push((claim, place)),
            }
        });
    }

    /// The bus's frame statistics.
    pub(crate) fn bus(&self) -> BusStats {
        *self.wire.rx.stats().bus()
    }

    /// The slots of the bus's ESCs: each at the place it had last, an ESC that claims a place
    /// another had first after the bus's places.
    pub(crate) fn plan(self) -> BusPlan {
        let mut plan = BusPlan::default();
        // The places first, so that an ESC's slot past them cannot be another's place.
        let highest = self.last.iter().map(|&(_, p)| p).max();
        let mut claimed = Vec::new();
        let mut next = highest.map_or(0, |h| u16::from(h) + 1);
        for &(claim, place) in &self.last {
            let slot = match claimed.iter().find(|&&(p, _)| p == place) {
                None => Some(place),
                Some(&(_, first)) => {
                    plan.clashes.push(Clash {
                        place,
                        first,
                        second: claim,
                    });
                    let slot = u8::try_from(next).ok();
                    next += 1;
                    slot
                }
            };
            claimed.push((place, claim));
            if let Some(slot) = slot {
                plan.slots.push((claim, slot));
            }
        }
        plan
    }
}

/// Nodes on a bus.
const NODES: usize = hwfoc::dronecan::NODES;

/// How often transfers left unfinished are dropped ([`Receiver::expire`]), seconds of the
/// stream's clock (DroneCAN's transfer timeout is 2 s).
const EXPIRE_EVERY_S: f64 = 1.0;

/// Live, how long a Hobbywing node heard before its GetEscID answer has its records held,
/// waiting for the answer that gives its slot, seconds of the bus's clock.
pub(crate) const HOLD_S: f64 = 1.0;

/// The hold without receive times: CAN frames of the bus.
pub(crate) const HOLD_FRAMES: u64 = 1000;

/// The most records held of one node.
pub(crate) const HOLD_RECORDS: usize = 1024;

/// The records of a node waiting for its GetEscID answer, and when the wait began (the bus's
/// clock, and its count of CAN frames).
#[derive(Debug)]
struct Held {
    key: EscKey,
    since: Option<f64>,
    since_frame: u64,
    records: Vec<(Option<f64>, Data)>,
}

/// The decoding state of a CAN bus's stream.
#[derive(Debug)]
pub(crate) struct CanWire {
    rx: Receiver,
    escs: Escs,
    /// A record still arriving, and the time of its first byte.
    held: [u8; SOCKETCAN_RECORD_LEN],
    held_len: usize,
    held_t: Option<f64>,
    /// Every byte fed.
    bytes: u64,
    /// Records that are no classic CAN frame (a length over 8: CAN FD), and bytes of a record
    /// cut off at the end.
    bad_records: u32,
    cut_bytes: u64,
    /// Each ESC's slot on the bus.
    plan: BusPlan,
    /// Per slot on the bus: the node whose records it had, and its records; per node: the
    /// protocol of its last record.
    place_node: [Option<u8>; BUS_PLACES],
    records: [u32; BUS_PLACES],
    protocol: [Option<Protocol>; NODES],
    last_expire: Option<f64>,
    /// Whether records wait for their GetEscID answer (not when read ahead), the nodes whose
    /// records wait, and the CAN frames heard.
    hold: bool,
    waiting: Vec<Held>,
    frames: u64,
}

impl CanWire {
    pub(crate) fn new() -> CanWire {
        CanWire {
            rx: Receiver::new(),
            escs: Escs::new(),
            held: [0; SOCKETCAN_RECORD_LEN],
            held_len: 0,
            held_t: None,
            bytes: 0,
            bad_records: 0,
            cut_bytes: 0,
            plan: BusPlan::default(),
            place_node: [None; BUS_PLACES],
            records: [0; BUS_PLACES],
            protocol: [None; NODES],
            last_expire: None,
            hold: true,
            waiting: Vec::new(),
            frames: 0,
        }
    }

    /// The slots of the bus's ESCs from now on: those of `plan` (a file's bus read ahead), an
    /// ESC not in it given one when first heard.
    pub(crate) fn set_plan(&mut self, plan: &BusPlan) {
        self.plan = plan.clone();
        self.plan.clashes.clear();
    }

    /// The ESCs heard since the last call that claimed a place another held (those of a plan
    /// set were told when it was made).
    pub(crate) fn take_clashes(&mut self) -> Vec<Clash> {
        std::mem::take(&mut self.plan.clashes)
    }

    /// Decodes `bytes` (with each byte's receive time, or none): `emit(t, slot, frame)` gets
    /// each record with the time of its CAN frame and its ESC's slot on the bus.
    pub(crate) fn feed(&mut self, bytes: &[u8], times: Option<&[f64]>, emit: &mut OnFrame<'_>) {
        self.bytes += bytes.len() as u64;
        for (i, &b) in bytes.iter().enumerate() {
            if self.held_len == 0 {
                self.held_t = times.and_then(|t| t.get(i).copied());
            }
            self.held[self.held_len] = b;
            self.held_len += 1;
            if self.held_len == SOCKETCAN_RECORD_LEN {
                self.held_len = 0;
                let record = self.held;
                self.frame(&record, self.held_t, emit);
            }
        }
    }

    fn frame(
        &mut self,
        record: &[u8; SOCKETCAN_RECORD_LEN],
        t: Option<f64>,
        emit: &mut OnFrame<'_>,
    ) {
        let Some(frame) = CanFrame::from_socketcan_record(record) else {
            self.bad_records += 1;
            return;
        };
        self.frames += 1;
        self.release_expired(t, emit);
        if let Some(t) = t {
            match self.last_expire {
                Some(last) if t - last < EXPIRE_EVERY_S && t >= last => {}
                Some(_) => {
                    self.rx.expire();
                    self.last_expire = Some(t);
                }
                None => self.last_expire = Some(t),
            }
        }
        let t_us = t.filter(|t| *t >= 0.0).map(|t| (t * 1e6).round() as u64);
        let received = match t_us {
            Some(t_us) => self.rx.push_at(&frame, t_us),
            None => self.rx.push(&frame),
        };
        let Some(received) = received else {
            return;
        };
        let Some(data) = self.escs.push(&received, t_us) else {
            return;
        };
        let node = received.header.source_node;
        self.protocol[usize::from(node) % NODES] = Some(data.protocol());
        let (Some(claim), Some(place)) = (Claim::of(&data), data.bus_place()) else {
            return;
        };
        let waiting = self.waiting.iter().position(|h| h.key == claim.key);
        if self.hold && claim.by_node_id && !self.plan.has(claim.key) {
            // No slot yet, no answer yet: held until one comes or the hold runs out.
            let i = waiting.unwrap_or_else(|| {
                self.waiting.push(Held {
                    key: claim.key,
                    since: t,
                    since_frame: self.frames,
                    records: Vec::new(),
                });
                self.waiting.len() - 1
            });
            self.waiting[i].records.push((t, data));
            if self.waiting[i].records.len() >= HOLD_RECORDS {
                self.release(i, emit);
            }
            return;
        }
        if let Some(i) = waiting {
            // The answer came in time: the records held go to its channel's slot.
            for (t, d) in std::mem::take(&mut self.waiting.remove(i).records) {
                self.place(claim, place, t, d, emit);
            }
        }
        self.place(claim, place, t, data, emit);
    }

    /// Hands on a record of ESC `claim` at `place` under its slot.
    fn place(
        &mut self,
        claim: Claim,
        place: u8,
        t: Option<f64>,
        data: Data,
        emit: &mut OnFrame<'_>,
    ) {
        let Some(slot) = self.plan.slot(claim, place) else {
            return;
        };
        self.place_node[usize::from(slot)] = Some(claim.key.node);
        self.records[usize::from(slot)] += 1;
        emit(t, Some(slot), &AnyFrame::Data(data));
    }

    /// Hands on the records held of the node `i` of those waiting, placed by its node id (no
    /// answer came in time).
    fn release(&mut self, i: usize, emit: &mut OnFrame<'_>) {
        let held = self.waiting.remove(i);
        let claim = Claim {
            key: held.key,
            by_node_id: true,
        };
        for (t, d) in held.records {
            if let Some(place) = d.bus_place() {
                self.place(claim, place, t, d, emit);
            }
        }
    }

    /// Releases the nodes whose hold ran out by the frame at `t` (or by the frames heard,
    /// without times; a clock that stepped back ends every hold).
    fn release_expired(&mut self, t: Option<f64>, emit: &mut OnFrame<'_>) {
        let mut i = 0;
        while i < self.waiting.len() {
            let h = &self.waiting[i];
            let over = match h.since.zip(t) {
                Some((since, t)) => t - since >= HOLD_S || t < since,
                None => self.frames - h.since_frame >= HOLD_FRAMES,
            };
            if over {
                self.release(i, emit);
            } else {
                i += 1;
            }
        }
    }

    /// Ends the stream: a record cut off is counted; the records held are handed on, placed
    /// by their node ids.
    pub(crate) fn finish(&mut self, emit: &mut OnFrame<'_>) {
        self.cut_bytes += self.held_len as u64;
        self.held_len = 0;
        while !self.waiting.is_empty() {
            self.release(0, emit);
        }
    }

    /// Every byte fed.
    pub(crate) fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Bytes held of a record still arriving.
    pub(crate) fn buffered(&self) -> usize {
        self.held_len
    }

    /// The link of the ESC in `slot` on the bus.
    pub(crate) fn link(&self, slot: u8) -> CanLink {
        let node = self.place_node.get(usize::from(slot)).copied().flatten();
        let stats = self.rx.stats();
        CanLink {
            node,
            throttle_channel: node.and_then(|n| self.escs.throttle_channel(n)),
            maintenance_min: node.and_then(|n| self.escs.maintenance_min(n)),
            protocol: node
                .and_then(|n| self.protocol[usize::from(n) % NODES])
                .unwrap_or(Protocol::HwCan),
            records: self.records[usize::from(slot)],
            node_stats: node.map(|n| *stats.node(n)).unwrap_or_default(),
            bus: *stats.bus(),
            bytes: self.bytes,
            bad_records: self.bad_records,
        }
    }
}

/// The link statistics of one ESC on a CAN bus: its node's (transfers, gaps in transfer ids,
/// CRC and toggle errors) and the bus's (frames that are not DroneCAN).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CanLink {
    /// The node of the ESC's slot on the bus (`None` before any record).
    pub node: Option<u8>,
    /// Its node's throttle channel (1-based) from a GetEscID answer, if one came.
    pub throttle_channel: Option<u8>,
    /// Its node's maintenance counters from the last GetMaintenanceInformation answer on the
    /// bus, if one came, minutes: (total rotation time, time since maintenance).
    pub maintenance_min: Option<(u32, u32)>,
    /// The protocol of its records: `hw-can` or `dronecan`.
    pub protocol: Protocol,
    /// The ESC's records (StatusMsg1 or Status transfers decoded).
    pub records: u32,
    /// Its node's transfer statistics.
    pub node_stats: NodeStats,
    /// The bus's frame statistics.
    pub bus: BusStats,
    /// Bytes of the bus's stream ([`SOCKETCAN_RECORD_LEN`] per frame).
    pub bytes: u64,
    /// Records of the stream that were no classic CAN frame (CAN FD frames of a log or a
    /// recording: [`crate::can::NOT_CLASSIC_RECORD`]).
    pub bad_records: u32,
}

/// Why a bus gave no ESC status, in CAN words: its frames, and a wrong bit rate where it is the
/// likely cause (no frame at all, or error frames).
pub(crate) fn no_status(bus: &BusStats) -> String {
    let rate = format!(
        "check the bit rate the bus is read at (Hobbywing's DroneCAN ESCs are {} kbit/s from \
         the factory)",
        crate::can::DEFAULT_BITRATE / 1000
    );
    match (bus.frames(), bus.error_frames()) {
        (0, _) => format!("no CAN frame: {rate}, and that the ESCs are powered"),
        (n, 0) => format!("{n} CAN frames but no ESC status from any node"),
        (n, e) => format!("{n} CAN frames, {e} of them error frames, and no ESC status: {rate}"),
    }
}

impl CanLink {
    /// Why the ESC's bus gave no ESC status (see [`CanLink::records`]), in CAN words: its
    /// frames, and a wrong bit rate where it is the likely cause.
    pub fn no_status(&self) -> String {
        no_status(&self.bus)
    }

    /// Bytes of frames that were not DroneCAN, or no classic CAN frame.
    pub fn bytes_skipped(&self) -> u64 {
        (u64::from(self.bus.not_dronecan()) + u64::from(self.bad_records))
            * SOCKETCAN_RECORD_LEN as u64
    }

    /// Transfers of the node received over those sent, from the gaps in its transfer ids.
    pub fn delivery_ratio(&self) -> Option<f64> {
        let got = self.node_stats.total_transfers();
        let sent = got + u64::from(self.node_stats.lost_packets());
        (sent > 0).then(|| got as f64 / sent as f64)
    }
}

/// A record's place on the bus and its data, for tests and callers that decode a bus alone.
#[cfg(test)]
pub(crate) fn decode_all(bytes: &[u8], times: Option<&[f64]>) -> Vec<(Option<f64>, u8, Data)> {
    let mut wire = CanWire::new();
    let mut out = Vec::new();
    wire.feed(bytes, times, &mut |t, place, f| {
        if let AnyFrame::Data(d) = f {
            out.push((t, place.unwrap_or(0), *d));
        }
    });
    wire.finish(&mut |t, place, f| {
        if let AnyFrame::Data(d) = f {
            out.push((t, place.unwrap_or(0), *d));
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::dronecan::{EscStatus, GetEscId, Message, StatusMsg1, StatusMsg2};

    fn records(messages: &[(Message, u8, u8)]) -> Vec<u8> {
        let mut out = Vec::new();
        for &(m, node, tid) in messages {
            for f in m.frames(16, node, 0, tid) {
                out.extend_from_slice(&f.to_socketcan_record());
            }
        }
        out
    }

    /// Live (no plan), a node heard before its GetEscID answer is held until the answer maps
    /// it: all its records go to its channel's slot; the channel learned is in its records
    /// after the answer.
    #[test]
    fn records_come_with_their_frame_times_and_answered_slots_whatever_the_chunking() {
        let m1 = StatusMsg1 {
            rpm: 100,
            pwm: 200,
            status: 0,
        };
        let m2 = StatusMsg2 {
            input_voltage: 240,
            current: 12,
            temperature: 30,
        };
        let bytes = records(&[
            (m2.into(), 3, 0),
            (m1.into(), 3, 0),
            (GetEscId::new(&[3, 2]).unwrap().into(), 3, 0),
            (m1.into(), 3, 1),
        ]);
        let times: Vec<f64> = (0..bytes.len()).map(|i| (i / 16) as f64 * 0.01).collect();
        let whole = decode_all(&bytes, Some(&times));
        assert_eq!(whole.len(), 2);
        assert_eq!((whole[0].0, whole[0].1), (Some(0.01), 1));
        assert_eq!((whole[1].0, whole[1].1), (Some(0.03), 1));
        let Data::HwCan(r) = whole[1].2 else { panic!() };
        assert_eq!(
            (r.node, r.throttle_channel, r.msg2_age_ms),
            (3, Some(2), Some(30))
        );
        for chunk in [1, 5, 16, 17] {
            let mut wire = CanWire::new();
            let mut got = Vec::new();
            for (b, t) in bytes.chunks(chunk).zip(times.chunks(chunk)) {
                wire.feed(b, Some(t), &mut |t, p, f| {
                    if let AnyFrame::Data(d) = f {
                        got.push((t, p.unwrap(), *d));
                    }
                });
            }
            assert_eq!(got, whole, "chunks of {chunk}");
            let link = wire.link(1);
            assert_eq!(
                (
                    link.node,
                    link.throttle_channel,
                    link.records,
                    link.protocol
                ),
                (Some(3), Some(2), 2, Protocol::HwCan)
            );
            assert_eq!(wire.link(3).records, 0);
        }
    }

    /// Read ahead, each ESC's slot is its last place; an ESC that claims a place another
    /// claimed first takes a slot after the bus's places, and the clash is named.
    #[test]
    fn a_plan_gives_each_esc_its_last_place_and_a_clash_a_slot_after_the_places() {
        let m1 = StatusMsg1 {
            rpm: 1,
            pwm: 1,
            status: 0,
        };
        let status = |index| EscStatus {
            error_count: 0,
            voltage: 24.0,
            current: 1.0,
            temperature: 300.0,
            rpm: 0,
            power_rating_pct: 0,
            esc_index: index,
        };
        let bytes = records(&[
            (m1.into(), 10, 0),
            (status(0).into(), 20, 0),
            (GetEscId::new(&[10, 1]).unwrap().into(), 10, 1),
            (m1.into(), 10, 2),
            (status(2).into(), 21, 0),
        ]);
        let mut learner = BusLearner::new();
        learner.feed(&bytes, None);
        let plan = learner.plan();
        let (hw, std, other) = (
            EscKey {
                node: 10,
                index: None,
            },
            EscKey {
                node: 20,
                index: Some(0),
            },
            EscKey {
                node: 21,
                index: Some(2),
            },
        );
        let slots: Vec<(EscKey, u8)> = plan.slots.iter().map(|&(c, s)| (c.key, s)).collect();
        assert_eq!(slots, [(hw, 0), (std, 3), (other, 2)]);
        assert_eq!(plan.len(), 4);
        assert_eq!(
            plan.clashes
                .iter()
                .map(Clash::to_string)
                .collect::<Vec<_>>(),
            ["node 10 and node 20 (esc_index 0) both claim throttle channel 1: read as two ESCs"]
        );
        // A node without a GetEscID answer claims its node id, not a channel.
        let clash = Clash {
            place: 0,
            first: Claim {
                key: std,
                by_node_id: false,
            },
            second: Claim {
                key: EscKey {
                    node: 0,
                    index: None,
                },
                by_node_id: true,
            },
        };
        assert_eq!(
            clash.to_string(),
            "node 20 (esc_index 0) and node 0 (no GetEscID answer: by its node id) both claim \
             place 0 on the bus: read as two ESCs"
        );
        // Decoded with the plan: node 10's records in slot 0 from the first.
        let mut wire = CanWire::new();
        wire.set_plan(&plan);
        let mut slots = Vec::new();
        wire.feed(&bytes, None, &mut |_, slot, _| slots.push(slot.unwrap()));
        assert_eq!(slots, [0, 3, 0, 2]);
    }

    /// Live, a node heard before its GetEscID answer is held until it answers (within
    /// [`HOLD_S`]): every record gets the slot the file's read-ahead plan gives it; a node that
    /// never answers is placed by its node id once the hold runs out, as read ahead.
    #[test]
    fn live_slots_equal_the_read_ahead_ones_when_a_node_answers_late() {
        let m1 = StatusMsg1 {
            rpm: 1,
            pwm: 1,
            status: 0,
        };
        let answer = |node, channel| GetEscId::new(&[node, channel]).unwrap().into();
        let mut messages = vec![
            (m1.into(), 10, 0),
            (m1.into(), 10, 1),
            (answer(11, 2), 11, 0),
            (m1.into(), 11, 1),
            (answer(12, 3), 12, 0),
            (m1.into(), 12, 1),
            (m1.into(), 40, 0),
            (answer(10, 1), 10, 2),
        ];
        for k in 0..150u8 {
            for node in [10, 11, 12, 40] {
                messages.push((m1.into(), node, (k + 3) % 32));
            }
        }
        let bytes = records(&messages);
        // 10 ms a transfer: the answer of node 10 comes in time, node 40 never answers.
        let times: Vec<f64> = (0..bytes.len()).map(|i| (i / 16) as f64 * 0.01).collect();
        let mut learner = BusLearner::new();
        learner.feed(&bytes, Some(&times));
        let plan = learner.plan();
        let by_record = |mut wire: CanWire, chunk: usize| {
            let mut got = Vec::new();
            for (b, t) in bytes.chunks(chunk).zip(times.chunks(chunk)) {
                wire.feed(b, Some(t), &mut |t, slot, f| {
                    if let AnyFrame::Data(Data::HwCan(r)) = f {
                        got.push((t.map(|t| (t * 1e3).round() as u64), r.node, slot.unwrap()));
                    }
                });
            }
            wire.finish(&mut |t, slot, f| {
                if let AnyFrame::Data(Data::HwCan(r)) = f {
                    got.push((t.map(|t| (t * 1e3).round() as u64), r.node, slot.unwrap()));
                }
            });
            got.sort();
            got
        };
        let mut planned = CanWire::new();
        planned.set_plan(&plan);
        let read_ahead = by_record(planned, bytes.len());
        assert_eq!(read_ahead.len(), 5 + 150 * 4);
        for chunk in [1, 16, 100] {
            assert_eq!(
                by_record(CanWire::new(), chunk),
                read_ahead,
                "chunks of {chunk}"
            );
        }
        let slot_of = |node| read_ahead.iter().find(|r| r.1 == node).unwrap().2;
        assert_eq!([10, 11, 12, 40].map(slot_of), [0, 1, 2, 40]);
    }

    #[test]
    fn bad_records_and_cut_ones_are_counted_not_decoded() {
        let mut bytes = records(&[(
            StatusMsg1 {
                rpm: 1,
                pwm: 1,
                status: 0,
            }
            .into(),
            1,
            0,
        )]);
        let mut fd = [0u8; SOCKETCAN_RECORD_LEN];
        fd[4] = 12;
        bytes.extend_from_slice(&fd);
        bytes.extend_from_slice(
            &CanFrame::standard(0x123, &[1])
                .unwrap()
                .to_socketcan_record(),
        );
        bytes.extend_from_slice(&[1, 2, 3]);
        let mut wire = CanWire::new();
        let mut n = 0;
        wire.feed(&bytes, None, &mut |t, _, _| {
            assert_eq!(t, None);
            n += 1
        });
        wire.finish(&mut |_, _, _| n += 1);
        assert_eq!(n, 1);
        let link = wire.link(1);
        assert_eq!((link.bad_records, link.bus.standard_frames()), (1, 1));
        assert_eq!(link.bytes_skipped(), 32);
        assert_eq!(wire.cut_bytes, 3);
        assert_eq!(link.delivery_ratio(), Some(1.0));
    }
}
