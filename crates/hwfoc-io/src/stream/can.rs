//! A CAN bus's stream: CAN frames carried as bytes, [`SOCKETCAN_RECORD_LEN`] per frame
//! (pcapng's `LINKTYPE_CAN_SOCKETCAN` layout, [`CanFrame::to_socketcan_record`]), each byte with
//! its frame's receive time: how every CAN input (candump logs, pcapng recordings, SLCAN
//! adapters, SocketCAN interfaces) hands its frames on.
//!
//! The codec's [`Receiver`] reassembles and counts the transfers, [`Escs`] makes a record of
//! each ESC status with its node's slower messages; each record is handed on with its ESC's
//! place on the bus ([`Data::bus_index`]) as its channel, which the ESC numbering gives a
//! number of its own (`esc_numbers.rs`).

use hwfoc::Protocol;
use hwfoc::dronecan::{BusStats, CanFrame, Escs, NodeStats, Receiver, SOCKETCAN_RECORD_LEN};
#[cfg(test)]
use hwfoc::telemetry::Data;
use hwfoc::telemetry::Frame;

/// Places on a bus: node ids (0-127) before a node is mapped to its throttle channel, then its
/// channel - 1 (a byte).
pub(crate) const BUS_PLACES: usize = 256;

/// Nodes on a bus.
const NODES: usize = hwfoc::dronecan::NODES;

/// How often transfers left unfinished are dropped ([`Receiver::expire`]), seconds of the
/// stream's clock (DroneCAN's transfer timeout is 2 s).
const EXPIRE_EVERY_S: f64 = 1.0;

/// Where a bus's records go: `emit(t, place, frame)`.
pub(crate) type Emit<'a> = dyn FnMut(Option<f64>, Option<u8>, &Frame) + 'a;

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
    /// Per place on the bus: the node whose records it had last, and its records; per node:
    /// the protocol of its last record.
    place_node: [Option<u8>; BUS_PLACES],
    records: [u32; BUS_PLACES],
    protocol: [Option<Protocol>; NODES],
    last_expire: Option<f64>,
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
            place_node: [None; BUS_PLACES],
            records: [0; BUS_PLACES],
            protocol: [None; NODES],
            last_expire: None,
        }
    }

    /// Decodes `bytes` (with each byte's receive time, or none): `emit(t, place, frame)` gets
    /// each record with the time of its CAN frame and its ESC's place on the bus.
    pub(crate) fn feed(&mut self, bytes: &[u8], times: Option<&[f64]>, emit: &mut Emit<'_>) {
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

    fn frame(&mut self, record: &[u8; SOCKETCAN_RECORD_LEN], t: Option<f64>, emit: &mut Emit<'_>) {
        let Some(frame) = CanFrame::from_socketcan_record(record) else {
            self.bad_records += 1;
            return;
        };
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
        let place = data.bus_index().unwrap_or(node);
        self.place_node[usize::from(place)] = Some(node);
        self.records[usize::from(place)] += 1;
        emit(t, Some(place), &Frame::Data(data));
    }

    /// Ends the stream: a record cut off is counted.
    pub(crate) fn finish(&mut self) {
        self.cut_bytes += self.held_len as u64;
        self.held_len = 0;
    }

    /// Every byte fed.
    pub(crate) fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Bytes held of a record still arriving.
    pub(crate) fn buffered(&self) -> usize {
        self.held_len
    }

    /// The link of the ESC at `place` on the bus.
    pub(crate) fn link(&self, place: u8) -> CanLink {
        let node = self.place_node.get(usize::from(place)).copied().flatten();
        let stats = self.rx.stats();
        CanLink {
            node,
            channel: node.and_then(|n| self.escs.channel(n)),
            protocol: node
                .and_then(|n| self.protocol[usize::from(n) % NODES])
                .unwrap_or(Protocol::HwCan),
            records: self.records[usize::from(place)],
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
    /// The node whose records the ESC's place on the bus had last (`None` before any).
    pub node: Option<u8>,
    /// Its node's throttle channel (1-based) from a GetEscID answer, if one came.
    pub channel: Option<u8>,
    /// The protocol of its records: `hw-can` or `dronecan`.
    pub protocol: Protocol,
    /// The records at its place on the bus (StatusMsg1 or Status transfers decoded).
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

impl CanLink {
    /// Bytes of frames that were not DroneCAN, or no classic CAN frame.
    pub fn bytes_skipped(&self) -> u64 {
        (u64::from(self.bus.not_dronecan()) + u64::from(self.bad_records))
            * SOCKETCAN_RECORD_LEN as u64
    }

    /// Transfers of the node received over those sent, from the gaps in its transfer ids.
    pub fn delivery_ratio(&self) -> Option<f64> {
        let got = self.node_stats.total_transfers();
        let sent = got + u64::from(self.node_stats.missed());
        (sent > 0).then(|| got as f64 / sent as f64)
    }
}

/// A record's place on the bus and its data, for tests and callers that decode a bus alone.
#[cfg(test)]
pub(crate) fn decode_all(bytes: &[u8], times: Option<&[f64]>) -> Vec<(Option<f64>, u8, Data)> {
    let mut wire = CanWire::new();
    let mut out = Vec::new();
    wire.feed(bytes, times, &mut |t, place, f| {
        if let Frame::Data(d) = f {
            out.push((t, place.unwrap_or(0), *d));
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::dronecan::{GetEscId, Message, StatusMsg1, StatusMsg2};

    fn records(messages: &[(Message, u8, u8)]) -> Vec<u8> {
        let mut out = Vec::new();
        for &(m, node, tid) in messages {
            for f in m.frames(16, node, 0, tid) {
                out.extend_from_slice(&f.to_socketcan_record());
            }
        }
        out
    }

    #[test]
    fn records_come_with_their_frame_times_and_places_whatever_the_chunking() {
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
        assert_eq!((whole[0].0, whole[0].1), (Some(0.01), 3));
        assert_eq!((whole[1].0, whole[1].1), (Some(0.03), 1));
        let Data::HwCan(r) = whole[1].2 else { panic!() };
        assert_eq!((r.node, r.channel, r.msg2_age_ms), (3, Some(2), Some(30)));
        for chunk in [1, 5, 16, 17] {
            let mut wire = CanWire::new();
            let mut got = Vec::new();
            for (b, t) in bytes.chunks(chunk).zip(times.chunks(chunk)) {
                wire.feed(b, Some(t), &mut |t, p, f| {
                    if let Frame::Data(d) = f {
                        got.push((t, p.unwrap(), *d));
                    }
                });
            }
            assert_eq!(got, whole, "chunks of {chunk}");
            let link = wire.link(1);
            assert_eq!(
                (link.node, link.records, link.protocol),
                (Some(3), 1, Protocol::HwCan)
            );
            assert_eq!(wire.link(3).records, 1);
        }
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
        wire.finish();
        assert_eq!(n, 1);
        let link = wire.link(1);
        assert_eq!((link.bad_records, link.bus.standard_frames()), (1, 1));
        assert_eq!(link.bytes_skipped(), 32);
        assert_eq!(wire.cut_bytes, 3);
        assert_eq!(link.delivery_ratio(), Some(1.0));
    }
}
