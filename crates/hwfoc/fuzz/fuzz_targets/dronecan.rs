//! The DroneCAN receiver: arbitrary CAN frames (any id, flags and length, malformed ones
//! included), frames shaped like the known data types, and whole transfers of the known types
//! made by the encoder, through a `dronecan::Receiver` with the default 16 slots and one with 2
//! (so that slots are taken back), with `expire` and `reset` between them.
//!
//! Input layout: a sequence of records, each starting with an op byte:
//!
//! - `0xF0..=0xF7`: `expire()` both receivers; `0xF8..=0xFB`: `reset()`; `0xFC..=0xFF`:
//!   `reset_stats()`;
//! - otherwise `op % 4` says how a frame is made and `(op >> 2) % 16` its data length `len`
//!   (0..=15: above 8 no frame can be made, which the constructors must say):
//!   - `0`: 4 bytes `can_id` (little-endian) and `len` data bytes: `CanFrame::from_socketcan`
//!     (extended, remote and error flags, ids wider than 29 bits cut by the flags' masks);
//!   - `1`: the same through `CanFrame::extended`, `2` through `CanFrame::standard` (the raw
//!     id, so ids too wide for either are given);
//!   - `3`: a transfer of a known type: 1 byte kind (`Kind::ALL[b % COUNT]`), 1 byte priority,
//!     source and destination node (each taken as given: the encoder cuts them to their bits),
//!     1 byte transfer id, then `len` payload bytes; when they are a payload of the kind
//!     (`Message::decode`), the encoder's frames of that message are pushed, one of them left
//!     out when the priority byte's top bit is set (a frame lost on the bus).
//!
//! Checked: never a panic; every frame counted by the bus statistics; no more transfers in
//! progress than slots; a constructor returns `None` exactly for more than 8 bytes or an id too
//! wide; and every transfer a receiver hands on is of the kind its id says, from the header and
//! transfer id its last frame carries, and re-encodes (`Message::frames` with its header's
//! priority, nodes and transfer id) to frames that a new receiver reassembles into the same
//! header, transfer id and message (floats compared by their bits; an infinite float16 comes
//! back as ±65504, DSDL's saturated cast, as pydronecan sends it).

#![no_main]

use hwfoc::dronecan::{
    CanFrame, Form, FrameKind, Header, Kind, MAX_EXTENDED_ID, MAX_STANDARD_ID, Message, Received,
    Receiver, TailByte, saturate_f16,
};
use libfuzzer_sys::fuzz_target;

/// The message as it comes back after encoding: float16 infinities saturated.
fn saturated(m: &Message) -> Message {
    match *m {
        Message::EscStatus(mut s) => {
            s.voltage = saturate_f16(s.voltage);
            s.current = saturate_f16(s.current);
            s.temperature = saturate_f16(s.temperature);
            Message::EscStatus(s)
        }
        other => other,
    }
}

/// Messages compared by their Debug text: NaN equals NaN, -0.0 differs from 0.0.
fn same(a: &Message, b: &Message) -> bool {
    format!("{a:?}") == format!("{b:?}")
}

/// Checks a transfer handed on for `frame` (its last frame).
fn check_received(r: &Received, frame: &CanFrame) {
    let header = Header::parse(frame.id()).expect("a transfer's frame has a DroneCAN id");
    assert_eq!(r.header, header, "header of the last frame");
    assert_eq!(Kind::of(&header), Some(r.message.kind()), "kind of the id");
    let tail = TailByte::from_byte(*frame.data().last().expect("a tail byte"));
    assert_eq!(
        r.transfer_id, tail.transfer_id,
        "transfer id of the tail byte"
    );
    assert!(tail.end, "handed on at a transfer's last frame");

    let destination = r.header.transfer.destination().unwrap_or(0);
    let again: Vec<CanFrame> = r
        .message
        .frames(
            r.header.priority,
            r.header.source_node,
            destination,
            r.transfer_id,
        )
        .collect();
    let mut rx = Receiver::new();
    let back: Vec<Received> = again.iter().filter_map(|f| rx.push(f)).collect();
    assert_eq!(back.len(), 1, "{r:?} re-encoded to {again:?}");
    assert_eq!(back[0].header, r.header, "header after re-encoding");
    assert_eq!(
        back[0].transfer_id, r.transfer_id,
        "transfer id after re-encoding"
    );
    let expected = saturated(&r.message);
    assert!(
        same(&back[0].message, &expected),
        "{:?} came back as {:?}",
        r.message,
        back[0].message
    );
}

struct Bus {
    wide: Receiver,
    narrow: Receiver<2>,
    frames: u64,
}

impl Bus {
    fn push(&mut self, frame: &CanFrame) {
        self.frames += 1;
        if let Some(r) = self.wide.push(frame) {
            check_received(&r, frame);
        }
        if let Some(r) = self.narrow.push(frame) {
            check_received(&r, frame);
        }
        assert!(self.wide.in_progress() <= 16);
        assert!(self.narrow.in_progress() <= 2);
    }
}

/// Takes `n` bytes from the front of `data`, if there are that many.
fn take<'a>(data: &mut &'a [u8], n: usize) -> Option<&'a [u8]> {
    if data.len() < n {
        return None;
    }
    let (head, rest) = data.split_at(n);
    *data = rest;
    Some(head)
}

fuzz_target!(|data: &[u8]| {
    let mut data = data;
    let mut bus = Bus {
        wide: Receiver::new(),
        narrow: Receiver::with_slots(),
        frames: 0,
    };
    let mut counted_since_reset = 0u64;
    while let Some(&[op]) = take(&mut data, 1) {
        match op {
            0xF0..=0xF7 => {
                bus.wide.expire();
                bus.narrow.expire();
                continue;
            }
            0xF8..=0xFB => {
                bus.wide.reset();
                bus.narrow.reset();
                assert_eq!((bus.wide.in_progress(), bus.narrow.in_progress()), (0, 0));
                continue;
            }
            0xFC..=0xFF => {
                bus.wide.reset_stats();
                bus.narrow.reset_stats();
                counted_since_reset = bus.frames;
                continue;
            }
            _ => {}
        }
        let len = usize::from(op >> 2) % 16;
        if op % 4 == 3 {
            let Some(&[k, priority, source, destination, tid]) = take(&mut data, 5) else {
                break;
            };
            let Some(payload) = take(&mut data, len) else {
                break;
            };
            let kind = Kind::ALL[usize::from(k) % Kind::COUNT];
            let Ok(message) = Message::decode(kind, payload) else {
                continue;
            };
            let frames: Vec<CanFrame> =
                message.frames(priority, source, destination, tid).collect();
            assert!(!frames.is_empty() && frames.len() <= 3, "{frames:?}");
            let header = Header::parse(frames[0].id());
            if source & 0x7F != 0 && (kind.form() == Form::Message || destination & 0x7F != 0) {
                assert_eq!(
                    header.map(|h| h.can_id()),
                    Ok(frames[0].id()),
                    "the encoder's id parses back"
                );
            }
            let lost = (priority & 0x80 != 0).then(|| usize::from(tid) % frames.len());
            for (i, f) in frames.iter().enumerate() {
                if Some(i) != lost {
                    bus.push(f);
                }
            }
            continue;
        }
        let Some(id) = take(&mut data, 4) else {
            break;
        };
        let id = u32::from_le_bytes(id.try_into().expect("4 bytes"));
        // The data, or what is left of the input when it is shorter.
        let bytes = take(&mut data, len).unwrap_or_else(|| std::mem::take(&mut data));
        let frame = match op % 4 {
            0 => CanFrame::from_socketcan(id, bytes),
            1 => {
                let f = CanFrame::extended(id, bytes);
                assert_eq!(f.is_some(), id <= MAX_EXTENDED_ID && bytes.len() <= 8);
                f
            }
            _ => {
                let f = CanFrame::standard(id, bytes);
                assert_eq!(f.is_some(), id <= MAX_STANDARD_ID && bytes.len() <= 8);
                f
            }
        };
        if bytes.len() > 8 {
            assert!(frame.is_none(), "a frame of {} bytes", bytes.len());
        }
        if let Some(frame) = frame {
            assert!(frame.len() <= 8);
            if op % 4 == 0 {
                // A remote frame's length is given as that many data bytes.
                let data = match frame.kind() {
                    FrameKind::Remote => &[0u8; 8][..frame.len()],
                    _ => frame.data(),
                };
                assert_eq!(
                    CanFrame::from_socketcan(frame.socketcan_id(), data),
                    Some(frame),
                    "SocketCAN id round trip"
                );
            }
            bus.push(&frame);
        }
    }
    let counted = bus.frames - counted_since_reset;
    assert_eq!(
        u64::from(bus.wide.stats().bus().frames()),
        counted,
        "frames counted"
    );
    assert_eq!(u64::from(bus.narrow.stats().bus().frames()), counted);
});
