//! Link statistics of a CAN bus: what the bus carried that is not DroneCAN ([`BusStats`]) and,
//! per source node, transfers by data type and everything that went wrong ([`NodeStats`]), in
//! one bounded table ([`LinkStats`]: one entry per node id 0..=127).

use core::fmt;

use super::id::MAX_NODE_ID;
use super::kind::Kind;

/// Node ids the table holds: 0..=127, every id a 7-bit field can carry.
pub const NODES: usize = MAX_NODE_ID as usize + 1;

const NO_TRANSFER_ID: u8 = 0xFF;

fn bump(n: &mut u32) {
    *n = n.saturating_add(1);
}

/// What the time since a message type's last transfer from a node says of the step of its
/// transfer ids ([`Receiver::push_at`](super::Receiver::push_at)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Judged {
    /// Nothing: the step modulo 32 (one to 31 ids skipped, or a duplicate).
    ByIds,
    /// About this many transfers were sent since the last (the time over the type's period):
    /// the ids skipped are the count congruent to the step's nearest to it, beyond 31 too.
    Expected(u32),
    /// The whole bus was silent since: the node restarted, no id is missed.
    Restart,
}

/// What the bus carried that no node is named by: frames that are not DroneCAN. Counters are
/// `u32` and saturate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct BusStats {
    pub(crate) frames: u32,
    pub(crate) standard: u32,
    pub(crate) remote: u32,
    pub(crate) error: u32,
    pub(crate) empty: u32,
    pub(crate) bad_ids: u32,
    pub(crate) anonymous: u32,
    pub(crate) no_slot: u32,
}

impl BusStats {
    /// Every frame handed to the receiver.
    pub const fn frames(&self) -> u32 {
        self.frames
    }

    /// Data frames with an 11-bit identifier.
    pub const fn standard_frames(&self) -> u32 {
        self.standard
    }

    /// Remote (RTR) frames.
    pub const fn remote_frames(&self) -> u32 {
        self.remote
    }

    /// Error frames (the adapter's: a bus at the wrong bit rate gives many).
    pub const fn error_frames(&self) -> u32 {
        self.error
    }

    /// Extended data frames without a byte (no tail byte).
    pub const fn empty_frames(&self) -> u32 {
        self.empty
    }

    /// Extended data frames whose identifier DroneCAN does not allow (a service from or to
    /// node 0).
    pub const fn bad_ids(&self) -> u32 {
        self.bad_ids
    }

    /// Anonymous message frames (node 0: dynamic node id allocation): not decoded.
    pub const fn anonymous_frames(&self) -> u32 {
        self.anonymous
    }

    /// Multi-frame transfers dropped for want of a reassembly slot: each also counted as cut
    /// short by its node. (A [`Receiver`](super::Receiver) of the default size has a slot for
    /// every node id's transfer of every known multi-frame type, so none.)
    pub const fn no_slot(&self) -> u32 {
        self.no_slot
    }

    /// Frames that are not DroneCAN: standard, remote, error, empty frames and bad ids.
    pub const fn not_dronecan(&self) -> u32 {
        self.standard
            .saturating_add(self.remote)
            .saturating_add(self.error)
            .saturating_add(self.empty)
            .saturating_add(self.bad_ids)
    }
}

/// What one source node sent. Counters are `u32` and saturate.
///
/// Every DroneCAN frame a node sends is counted in [`NodeStats::frames`]; every transfer it
/// starts ends in exactly one of: decoded ([`NodeStats::transfers`]), a
/// [duplicate](NodeStats::duplicate_packets), a [toggle error](NodeStats::toggle_errors), a
/// [checksum failure](NodeStats::checksum_failures) (a CRC that did not match), [too long](NodeStats::too_long), a
/// [short frame](NodeStats::short_frames), a [bad payload](NodeStats::bad_payloads),
/// [cut short](NodeStats::cut_short), or an [unknown type](NodeStats::unknown_types); a
/// transfer still being received is none of them yet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct NodeStats {
    frames: u32,
    transfers: [u32; Kind::COUNT],
    gaps: u32,
    lost_packets: u32,
    duplicates: u32,
    toggle_errors: u32,
    checksum_failures: u32,
    too_long: u32,
    short_frames: u32,
    bad_payloads: u32,
    cut_short: u32,
    orphan_frames: u32,
    unknown_types: u32,
    restarts: u32,
    last_transfer_id: [u8; Kind::MESSAGES],
}

impl Default for NodeStats {
    fn default() -> Self {
        NodeStats::new()
    }
}

impl NodeStats {
    /// All counters zero, no transfer seen.
    pub const fn new() -> Self {
        NodeStats {
            frames: 0,
            transfers: [0; Kind::COUNT],
            gaps: 0,
            lost_packets: 0,
            duplicates: 0,
            toggle_errors: 0,
            checksum_failures: 0,
            too_long: 0,
            short_frames: 0,
            bad_payloads: 0,
            cut_short: 0,
            orphan_frames: 0,
            unknown_types: 0,
            restarts: 0,
            last_transfer_id: [NO_TRANSFER_ID; Kind::MESSAGES],
        }
    }

    /// DroneCAN frames from this node (of any data type, known or not).
    pub const fn frames(&self) -> u32 {
        self.frames
    }

    /// Transfers of `kind` decoded and handed on.
    pub const fn transfers(&self, kind: Kind) -> u32 {
        self.transfers[kind as usize]
    }

    /// Transfers decoded, by kind (indexed by `kind as usize`, as [`Kind::ALL`]).
    pub const fn transfers_by_kind(&self) -> &[u32; Kind::COUNT] {
        &self.transfers
    }

    /// Transfers decoded, every kind.
    pub fn total_transfers(&self) -> u64 {
        self.transfers.iter().map(|&n| u64::from(n)).sum()
    }

    /// Gaps in a message type's transfer ids: a transfer whose id is not the previous one's
    /// plus one (modulo 32) and not the same. Service transfers are not checked (a response
    /// carries its request's id).
    pub const fn gaps(&self) -> u32 {
        self.gaps
    }

    /// Transfers missed in those gaps: the ids skipped. Untimed, at most 30 a gap (a gap of 32
    /// or more cannot be seen in 5-bit ids); timed
    /// ([`Receiver::push_at`](super::Receiver::push_at)), the count of the ids skipped modulo
    /// 32 nearest to the transfers the time since the type's last one held at its period.
    pub const fn lost_packets(&self) -> u32 {
        self.lost_packets
    }

    /// Message transfers that came after a silence of the whole bus of a second or more (timed,
    /// [`Receiver::push_at`](super::Receiver::push_at)): the node, powered again, counts its
    /// transfer ids afresh. Neither a gap nor a duplicate.
    pub const fn restarts(&self) -> u32 {
        self.restarts
    }

    /// Message transfers with the same transfer id as the previous one of their type (a
    /// repeated frame or transfer): not handed on.
    pub const fn duplicate_packets(&self) -> u32 {
        self.duplicates
    }

    /// Transfers dropped for a toggle bit out of turn (a repeated or lost frame; a first frame
    /// with its toggle set).
    pub const fn toggle_errors(&self) -> u32 {
        self.toggle_errors
    }

    /// Multi-frame transfers whose CRC did not match.
    pub const fn checksum_failures(&self) -> u32 {
        self.checksum_failures
    }

    /// Multi-frame transfers longer than their data type can be (more than
    /// [`MAX_PAYLOAD_LEN`](super::MAX_PAYLOAD_LEN) bytes).
    pub const fn too_long(&self) -> u32 {
        self.too_long
    }

    /// Transfers dropped because a frame other than the last was shorter than 8 bytes.
    pub const fn short_frames(&self) -> u32 {
        self.short_frames
    }

    /// Whole transfers (CRC good if multi-frame) whose payload length is not one of their data
    /// type's.
    pub const fn bad_payloads(&self) -> u32 {
        self.bad_payloads
    }

    /// Transfers started and never ended: a new transfer of the same type started before the
    /// end came, or they were dropped by [`Receiver::expire`](super::Receiver::expire),
    /// [`Receiver::reset`](super::Receiver::reset) or for want of a free slot.
    pub const fn cut_short(&self) -> u32 {
        self.cut_short
    }

    /// Frames that continue a transfer whose start was not received (or that follow the end of
    /// one: a repeated last frame).
    pub const fn orphan_frames(&self) -> u32 {
        self.orphan_frames
    }

    /// Transfers (first frames) of data types the codec does not know.
    pub const fn unknown_types(&self) -> u32 {
        self.unknown_types
    }

    /// Transfers lost to errors: toggle, CRC, too long, short frames, bad payloads, cut short.
    pub const fn errors(&self) -> u32 {
        self.toggle_errors
            .saturating_add(self.checksum_failures)
            .saturating_add(self.too_long)
            .saturating_add(self.short_frames)
            .saturating_add(self.bad_payloads)
            .saturating_add(self.cut_short)
    }

    /// Whether nothing was heard from this node.
    pub const fn is_silent(&self) -> bool {
        self.frames == 0
    }

    pub(crate) fn frame(&mut self) {
        bump(&mut self.frames);
    }

    pub(crate) fn transfer(&mut self, kind: Kind) {
        bump(&mut self.transfers[kind as usize]);
    }

    /// A whole message transfer with `transfer_id`: whether it is new (not a duplicate), after
    /// counting a gap if ids were skipped.
    #[cfg(test)]
    pub(crate) fn next_transfer_id(&mut self, kind: Kind, transfer_id: u8) -> bool {
        self.next_transfer_id_judged(kind, transfer_id, Judged::ByIds)
    }

    /// A whole message transfer with `transfer_id`: whether it is new (not a duplicate), after
    /// counting a gap if ids were skipped, with what time says of the step (see [`Judged`]).
    pub(crate) fn next_transfer_id_judged(
        &mut self,
        kind: Kind,
        transfer_id: u8,
        judged: Judged,
    ) -> bool {
        let Some(i) = kind.message_index() else {
            return true;
        };
        let last = self.last_transfer_id[i];
        self.last_transfer_id[i] = transfer_id & 0x1F;
        if last == NO_TRANSFER_ID {
            return true;
        }
        let step = u32::from(transfer_id.wrapping_sub(last) & 0x1F);
        // The ids skipped modulo 32.
        let base = step.wrapping_sub(1) & 0x1F;
        let (duplicate, missed) = match judged {
            Judged::Restart => {
                bump(&mut self.restarts);
                return true;
            }
            Judged::ByIds => (step == 0, base),
            // The count of ids skipped congruent to `base`, nearest to what the time held; a
            // step of 0 is a duplicate when fewer than half a round of ids fit in it. A step
            // of 1 (the next id) skipped none, however long it took: a receiver that stalled
            // and got the frames late and bunched, or a sender that slowed down, is far more
            // likely than exactly 32, 64, ... transfers lost, which it would then not count.
            Judged::Expected(expected) => {
                let skipped = expected.saturating_sub(1);
                let rounds = if step == 1 {
                    0
                } else {
                    (skipped + 16).saturating_sub(base) / 32
                };
                (
                    step == 0 && skipped < 16,
                    base.saturating_add(rounds.saturating_mul(32)),
                )
            }
        };
        if duplicate {
            bump(&mut self.duplicates);
            return false;
        }
        if missed > 0 {
            bump(&mut self.gaps);
            self.lost_packets = self.lost_packets.saturating_add(missed);
        }
        true
    }

    /// The transfer id of the last message transfer of `kind` taken, if any.
    pub(crate) fn last_transfer_id(&self, kind: Kind) -> Option<u8> {
        let id = self.last_transfer_id[kind.message_index()?];
        (id != NO_TRANSFER_ID).then_some(id)
    }

    /// Every counter to zero, the transfer-id history kept.
    pub(crate) fn clear_counters(&mut self) {
        *self = NodeStats {
            last_transfer_id: self.last_transfer_id,
            ..NodeStats::new()
        };
    }

    pub(crate) fn forget_transfer_ids(&mut self) {
        self.last_transfer_id = [NO_TRANSFER_ID; Kind::MESSAGES];
    }

    pub(crate) fn toggle_error(&mut self) {
        bump(&mut self.toggle_errors);
    }
    pub(crate) fn checksum_failure(&mut self) {
        bump(&mut self.checksum_failures);
    }
    pub(crate) fn too_long_transfer(&mut self) {
        bump(&mut self.too_long);
    }
    pub(crate) fn short_frame(&mut self) {
        bump(&mut self.short_frames);
    }
    pub(crate) fn bad_payload(&mut self) {
        bump(&mut self.bad_payloads);
    }
    pub(crate) fn cut(&mut self) {
        bump(&mut self.cut_short);
    }
    pub(crate) fn orphan(&mut self) {
        bump(&mut self.orphan_frames);
    }
    pub(crate) fn unknown_type(&mut self) {
        bump(&mut self.unknown_types);
    }
}

/// Link statistics of a bus: [`BusStats`] and a [`NodeStats`] for every node id 0..=127
/// (about 22 KiB: a fixed table, no allocation).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct LinkStats {
    pub(crate) bus: BusStats,
    pub(crate) nodes: [NodeStats; NODES],
}

impl Default for LinkStats {
    fn default() -> Self {
        LinkStats::new()
    }
}

impl LinkStats {
    /// All counters zero.
    pub const fn new() -> Self {
        LinkStats {
            bus: BusStats {
                frames: 0,
                standard: 0,
                remote: 0,
                error: 0,
                empty: 0,
                bad_ids: 0,
                anonymous: 0,
                no_slot: 0,
            },
            nodes: [NodeStats::new(); NODES],
        }
    }

    /// The bus's counters.
    pub const fn bus(&self) -> &BusStats {
        &self.bus
    }

    /// Node `id`'s counters (an id above 127 is taken modulo 128).
    pub const fn node(&self, id: u8) -> &NodeStats {
        &self.nodes[(id & MAX_NODE_ID) as usize]
    }

    /// The nodes heard from, by id.
    pub fn nodes(&self) -> impl Iterator<Item = (u8, &NodeStats)> {
        self.nodes
            .iter()
            .enumerate()
            .filter(|(_, n)| !n.is_silent())
            .map(|(i, n)| (i as u8, n))
    }

    /// A node's counters to change.
    pub(crate) fn node_mut(&mut self, id: u8) -> &mut NodeStats {
        &mut self.nodes[usize::from(id & MAX_NODE_ID)]
    }
}

impl fmt::Display for NodeStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} frames, {} transfers",
            self.frames,
            self.total_transfers()
        )?;
        for kind in Kind::ALL {
            if self.transfers(kind) != 0 {
                write!(f, ", {} {}", self.transfers(kind), kind)?;
            }
        }
        write!(
            f,
            "; {} gaps ({} missed), {} duplicates, {} toggle errors, {} CRC errors, {} too long, \
             {} short frames, {} bad payloads, {} cut short, {} orphan frames, {} unknown types",
            self.gaps,
            self.lost_packets,
            self.duplicates,
            self.toggle_errors,
            self.checksum_failures,
            self.too_long,
            self.short_frames,
            self.bad_payloads,
            self.cut_short,
            self.orphan_frames,
            self.unknown_types
        )
    }
}

impl fmt::Display for BusStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} frames, {} not DroneCAN ({} standard, {} remote, {} error, {} empty, {} bad ids), \
             {} anonymous, {} transfers without a reassembly slot",
            self.frames,
            self.not_dronecan(),
            self.standard,
            self.remote,
            self.error,
            self.empty,
            self.bad_ids,
            self.anonymous,
            self.no_slot
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transfer_id_continuity() {
        let mut n = NodeStats::new();
        assert!(n.next_transfer_id(Kind::StatusMsg1, 30));
        assert!(n.next_transfer_id(Kind::StatusMsg1, 31));
        assert!(n.next_transfer_id(Kind::StatusMsg1, 0)); // wraps
        assert!(!n.next_transfer_id(Kind::StatusMsg1, 0)); // duplicate
        assert!(n.next_transfer_id(Kind::StatusMsg1, 4)); // 1, 2, 3 missed
        assert!(n.next_transfer_id(Kind::StatusMsg2, 9)); // another type: its own ids
        assert!(n.next_transfer_id(Kind::SetIdRequest, 9));
        assert!(n.next_transfer_id(Kind::SetIdRequest, 9)); // services: not checked
        assert_eq!(
            (n.gaps(), n.lost_packets(), n.duplicate_packets()),
            (1, 3, 1)
        );
        n.forget_transfer_ids();
        assert!(n.next_transfer_id(Kind::StatusMsg1, 20));
        assert_eq!(n.gaps(), 1);
    }

    #[test]
    fn sizes() {
        assert_eq!(size_of::<NodeStats>(), 4 * (Kind::COUNT + 13) + 8);
        assert!(size_of::<LinkStats>() <= 22 * 1024);
    }
}
