//! One ESC's link figures, whatever carries it ([`LinkStats`]): its own serial wire, a channel of
//! a DataLink hub or a slot of a CAN bus. Each decoder of a stream gives them for each of its
//! channels ([`super::decoder::LinkDecoder::link`]); every front end reads them here, under one
//! set of names ([`LinkStats::figures`]).

use hwfoc::family::{LinkFigures, PacketCounts};
use hwfoc::format::Check;
use hwfoc::telemetry::Info;
use hwfoc::{Protocol, datalink, foc};

use super::can::CanLink;

/// A link figure's value ([`LinkStats::figures`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Figure {
    /// A count: frames, packets, bytes.
    Count(u64),
    /// A ratio, 0 to 1.
    Ratio(f64),
}

impl Figure {
    /// The value as a number.
    pub fn as_f64(self) -> f64 {
        match self {
            Figure::Count(n) => n as f64,
            Figure::Ratio(r) => r,
        }
    }
}

/// How many figures [`LinkStats::figures`] gives, and how many of them, first, are its frames'
/// and packets' (the rest are its stream's).
pub const FIGURES: usize = 7;
/// See [`FIGURES`].
pub const FRAME_FIGURES: usize = 5;

/// The link figures of one ESC: those of its own wire, of its channel of a DataLink hub (whose
/// bytes, skipped bytes and checksum failures are the hub link's, shared by its channels), or of
/// its node on a CAN bus (with its place there: [`LinkStats::can`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinkStats {
    /// The figures, in the codec's neutral terms (its `packets` `None` where frames carry no
    /// packet number: HW5).
    figures: LinkFigures,
    /// Of an ESC on a CAN bus: its place there.
    can: Option<CanLink>,
}

impl Default for LinkStats {
    fn default() -> Self {
        LinkStats::wire(&foc::Stats::new())
    }
}

impl LinkStats {
    /// The figures of an ESC on its own HW-FOC wire (or of a stream whose protocol is not known
    /// yet).
    pub(crate) fn wire(s: &foc::Stats) -> LinkStats {
        LinkStats::of(LinkFigures {
            protocol: Protocol::HwFoc,
            bytes: s.bytes(),
            bytes_skipped: s.bytes_skipped(),
            frames: s.packets().count(),
            info_frames: s.info_frames(),
            checksum_failures: s.checksum_failures(),
            rejected_candidates: None,
            packets: Some(PacketCounts::of(s.packets())),
            adopted_info: None,
        })
    }

    /// The figures of channel `channel` of a DataLink hub whose link's statistics are `hub`.
    pub(crate) fn hub(hub: &datalink::Stats, channel: u8) -> LinkStats {
        let packets = hub.channel(usize::from(channel)).map(PacketCounts::of);
        LinkStats::of(LinkFigures {
            protocol: Protocol::DataLink,
            bytes: hub.bytes(),
            bytes_skipped: hub.bytes_skipped(),
            frames: packets.map_or(0, |p| p.received as u32),
            info_frames: 0,
            checksum_failures: hub.checksum_failures(),
            rejected_candidates: None,
            packets: Some(packets.unwrap_or_default()),
            adopted_info: None,
        })
    }

    /// The figures of a serial link as the codec gives them (V4, V3 and HW5 through their
    /// [`hwfoc::family::FamilyLink`]).
    pub(crate) fn of(figures: LinkFigures) -> LinkStats {
        LinkStats { figures, can: None }
    }

    /// The figures of an ESC on a CAN bus: its node's transfers, counted from their transfer
    /// ids.
    pub(crate) fn bus(c: CanLink) -> LinkStats {
        let node = &c.node_stats;
        let figures = LinkFigures {
            protocol: c.protocol,
            bytes: c.bytes,
            bytes_skipped: c.bytes_skipped(),
            frames: c.records,
            info_frames: 0,
            checksum_failures: node.checksum_failures(),
            rejected_candidates: None,
            packets: Some(PacketCounts {
                received: node.total_transfers(),
                lost: node.lost_packets(),
                duplicates: node.duplicate_packets(),
                reordered: 0,
                restarts: node.restarts(),
                last: None,
            }),
            adopted_info: None,
        };
        LinkStats {
            figures,
            can: Some(c),
        }
    }

    /// The link's figures under their one set of names, as every output gives them (the
    /// summary's `link` object, the browser's summary, Python's `stats`): `None` where the link
    /// does not count the figure (checksum failures without a checksum, rejected candidates
    /// with one, packets without a packet counter, a ratio of nothing). Its frames' and
    /// packets' figures first ([`FRAME_FIGURES`] of them), then its stream's.
    pub fn figures(&self) -> [(&'static str, Option<Figure>); FIGURES] {
        let count = |n: u32| Some(Figure::Count(u64::from(n)));
        let packets = |n: u32| {
            if self.counts_packets() {
                count(n)
            } else {
                None
            }
        };
        [
            (
                "checksum_failures",
                self.has_checksum()
                    .then_some(self.figures.checksum_failures)
                    .and_then(count),
            ),
            (
                "rejected_candidates",
                self.figures.rejected_candidates.and_then(count),
            ),
            ("lost_packets", packets(self.lost_packets())),
            ("duplicate_packets", packets(self.duplicate_packets())),
            ("restarts", packets(self.restarts())),
            (
                "bytes_skipped",
                Some(Figure::Count(self.figures.bytes_skipped)),
            ),
            ("delivery_ratio", self.delivery_ratio().map(Figure::Ratio)),
        ]
    }

    /// The protocol of the link's frames.
    pub fn protocol(&self) -> Protocol {
        self.figures.protocol
    }

    /// Bytes of the stream the ESC's frames came in.
    pub fn bytes(&self) -> u64 {
        self.figures.bytes
    }

    /// Bytes of that stream that were in no accepted frame (of the link's protocol; an HW5
    /// wire's other frame kinds, requests and answers, are not skipped).
    pub fn bytes_skipped(&self) -> u64 {
        self.figures.bytes_skipped
    }

    /// Data frames of the ESC (records of its channel, behind a hub; of its node, on a bus).
    pub fn frames(&self) -> u32 {
        self.figures.frames
    }

    /// Device-information frames (V4: info frames; a hub forwards none).
    pub fn info_frames(&self) -> u32 {
        self.figures.info_frames
    }

    /// Whether the link's frames are checked (its format's description: V3 and V4 are not,
    /// their frames are recognised by plausibility and chaining, see
    /// [`LinkStats::rejected_candidates`]).
    pub fn has_checksum(&self) -> bool {
        self.figures.protocol.description().check != Check::None
    }

    /// Frames rejected by their checksum, or whose checksum matched but whose values are out of
    /// their protocol's range (behind a hub: the hub frames' CRC failures; 0 for a format
    /// without checksum).
    pub fn checksum_failures(&self) -> u32 {
        self.figures.checksum_failures
    }

    /// Candidates of a format without checksum that were not taken: implausible, or not
    /// confirmed by a chain (`None` for a checksummed format).
    pub fn rejected_candidates(&self) -> Option<u32> {
        self.figures.rejected_candidates
    }

    /// Whether the link's frames carry a packet counter, from which loss is counted (HW5's
    /// do not: its lost, duplicate and restart counts are 0 and say nothing). On a CAN bus,
    /// the transfer ids of every transfer of the ESC's node are counted.
    pub fn counts_packets(&self) -> bool {
        self.figures.packets.is_some()
    }

    /// Packet numbers skipped (on a CAN bus: transfers of the node missed, from the gaps in
    /// their transfer ids).
    pub fn lost_packets(&self) -> u32 {
        self.figures.packets.map_or(0, |p| p.lost)
    }

    /// Packet numbers received twice in a row (on a CAN bus: transfers of the node).
    pub fn duplicate_packets(&self) -> u32 {
        self.figures.packets.map_or(0, |p| p.duplicates)
    }

    /// Packet numbers that came right after the next one (two adjacent frames swapped): not
    /// lost, no restart.
    pub fn reordered_packets(&self) -> u32 {
        self.figures.packets.map_or(0, |p| p.reordered)
    }

    /// Jumps of the packet numbers that no loss explains (on a CAN bus: the node's transfers
    /// after a silence of the whole bus).
    pub fn restarts(&self) -> u32 {
        self.figures.packets.map_or(0, |p| p.restarts)
    }

    /// The last packet number received.
    pub fn last_packet(&self) -> Option<u32> {
        self.figures.packets?.last
    }

    /// Frames received over frames sent, from the packet numbers (on a CAN bus: the node's
    /// transfers, from their transfer ids).
    pub fn delivery_ratio(&self) -> Option<f64> {
        let p = self.figures.packets?;
        let received = p.received as f64;
        (p.received > 0).then(|| received / (received + f64::from(p.lost)))
    }

    /// The info frame whose constants were adopted (two identical copies in a row), if any: a
    /// format whose description has [`adopted_info`](hwfoc::format::FormatDescription) (V4).
    pub fn adopted_info(&self) -> Option<Info> {
        self.figures.adopted_info
    }

    /// Of an ESC on a CAN bus: its node, throttle channel, maintenance counters and its bus's
    /// frame statistics; `None` for a serial link.
    pub fn can(&self) -> Option<&CanLink> {
        self.can.as_ref()
    }

    /// A Hobbywing CAN ESC's own maintenance counters, minutes (total rotation time, time since
    /// maintenance), where its bus's recording holds its answer to GetMaintenanceInformation;
    /// `None` otherwise.
    pub fn maintenance_min(&self) -> Option<(u32, u32)> {
        self.can?.maintenance_min
    }
}
