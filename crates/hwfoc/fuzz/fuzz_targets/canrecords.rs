//! A CAN bus's record stream, as hwfoc-io's CAN stream reads one: `LINKTYPE_CAN_SOCKETCAN`
//! records of arbitrary bytes (`CanFrame::from_socketcan_record`), and transfers of the ESC
//! messages made by the encoder, through a `dronecan::Receiver` into the `dronecan::Escs`
//! tracker, each with a receive time.
//!
//! Input layout: byte 0 says whether times are given (odd: none); then records, each starting
//! with an op byte:
//!
//! - `0xFF`: `Escs::reset()`; `0xFE`: `Receiver::expire()`;
//! - `0xFD`: a transfer of an ESC message: 1 byte kind (StatusMsg1/2/3, GetEscID, esc.Status,
//!   StatusExtended, NodeStatus, by the byte modulo 7), 1 byte source node, 1 byte transfer id,
//!   1 byte payload length (modulo 16), the payload; when it decodes (`Message::decode`), the
//!   encoder's frames are pushed as SocketCAN records;
//! - otherwise the op is the time since the last record (in units of 997 us), then a 16-byte
//!   SocketCAN record (any id, flags and length byte).
//!
//! Checked: never a panic; a record whose length byte is over 8 is no frame, any other frame
//! comes back from its record; every record the tracker makes is of the node that sent its
//! transfer, numbered by its throttle channel when the tracker knows one (else its node id), a
//! standard ESC by its `esc_index`; its ages come only with times and a slower message, and
//! are no older than the stream; each value read is finite (a float16 NaN read as none).

#![no_main]

use hwfoc::dronecan::{CanFrame, Escs, Kind, Message, Receiver, SOCKETCAN_RECORD_LEN};
use hwfoc::telemetry::{Data, Telemetry};
use hwfoc::{Quantity, Settings};
use libfuzzer_sys::fuzz_target;

/// The kinds the tracker keeps or makes records of.
const ESC_KINDS: [Kind; 7] = [
    Kind::StatusMsg1,
    Kind::StatusMsg2,
    Kind::StatusMsg3,
    Kind::GetEscId,
    Kind::EscStatus,
    Kind::EscStatusExtended,
    Kind::NodeStatus,
];

/// Takes `n` bytes from the front of `data`, if there are that many.
fn take<'a>(data: &mut &'a [u8], n: usize) -> Option<&'a [u8]> {
    if data.len() < n {
        return None;
    }
    let (head, rest) = data.split_at(n);
    *data = rest;
    Some(head)
}

struct Bus {
    rx: Receiver,
    escs: Escs,
    /// Microseconds since the stream began, and whether they are given.
    now_us: u64,
    timed: bool,
}

impl Bus {
    fn record(&mut self, record: &[u8; SOCKETCAN_RECORD_LEN]) {
        let frame = CanFrame::from_socketcan_record(record);
        if record[4] > 8 {
            assert!(frame.is_none(), "a CAN FD length read as classic CAN");
        }
        let Some(frame) = frame else { return };
        assert_eq!(
            CanFrame::from_socketcan_record(&frame.to_socketcan_record()),
            Some(frame),
            "record round trip"
        );
        let Some(received) = self.rx.push(&frame) else {
            return;
        };
        let t = self.timed.then_some(self.now_us);
        let Some(data) = self.escs.push(&received, t) else {
            return;
        };
        let node = received.header.source_node;
        let settings = Settings::default();
        for q in Quantity::ALL {
            if let Some(v) = data.value(q, &settings) {
                assert!(v.is_finite(), "{q:?} = {v} in {data:?}");
            }
        }
        let max_age = u32::try_from(self.now_us / 1000).unwrap_or(u32::MAX);
        let age_ok = |age: Option<u32>, kept: bool| match age {
            Some(a) => self.timed && kept && a <= max_age,
            None => !self.timed || !kept,
        };
        match data {
            Data::HwCan(r) => {
                assert_eq!(r.node, node);
                assert_eq!(r.throttle_channel, self.escs.throttle_channel(node));
                let place = r.throttle_channel.map_or(node, |c| c.saturating_sub(1));
                assert_eq!(r.bus_place(), place);
                assert!(age_ok(r.msg2_age_ms, r.power.is_some()), "{r:?}");
                assert!(age_ok(r.msg3_age_ms, r.temperatures.is_some()), "{r:?}");
                if r.rpm > 0 || r.pwm > 0 {
                    assert!(self.escs.any_turning());
                }
            }
            Data::DroneCan(r) => {
                assert_eq!(r.node, node);
                assert!(r.esc_index < 32 && r.bus_place() == r.esc_index);
                assert!(age_ok(r.ext_age_ms, r.extended.is_some()), "{r:?}");
                if r.rpm != 0 {
                    assert!(self.escs.any_turning());
                }
            }
            other => panic!("a CAN bus made {other:?}"),
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let mut data = data;
    let Some(&[mode]) = take(&mut data, 1) else {
        return;
    };
    let mut bus = Bus {
        rx: Receiver::new(),
        escs: Escs::new(),
        now_us: 0,
        timed: mode % 2 == 0,
    };
    while let Some(&[op]) = take(&mut data, 1) {
        match op {
            0xFF => bus.escs.reset(),
            0xFE => bus.rx.expire(),
            0xFD => {
                let Some(&[k, node, tid, len]) = take(&mut data, 4) else {
                    break;
                };
                let Some(payload) = take(&mut data, usize::from(len % 16)) else {
                    break;
                };
                let kind = ESC_KINDS[usize::from(k) % ESC_KINDS.len()];
                let Ok(message) = Message::decode(kind, payload) else {
                    continue;
                };
                for f in message.frames(16, node, 0, tid) {
                    bus.record(&f.to_socketcan_record());
                }
            }
            _ => {
                bus.now_us += u64::from(op) * 997;
                let Some(record) = take(&mut data, SOCKETCAN_RECORD_LEN) else {
                    break;
                };
                bus.record(record.try_into().expect("a record's length"));
            }
        }
    }
});
