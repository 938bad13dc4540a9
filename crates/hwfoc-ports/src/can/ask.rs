//! Asking a bus's Hobbywing ESCs for their ids (`com.hobbywing.esc.GetEscID`), as ArduPilot
//! does: a broadcast of payload `[0]` once a second, only while no ESC turns (the request can
//! make some ESCs stutter: `docs/HW5-AND-CAN.md`).
//!
//! Its clock is a monotonic time given as a [`Duration`] since any fixed start, so that a live
//! bus (the time since it was opened) and the simulator's virtual controller (simulated time)
//! ask by the same rule.

use std::time::Duration;

use hwfoc::dronecan::{CanFrame, GetEscId, Message, NODES, Receiver};

/// How often the request is sent.
pub const ASK_EVERY: Duration = Duration::from_secs(1);
/// The node id the request is sent from by default: 127, the highest, which an ESC's own
/// never is by default.
pub const DEFAULT_SOURCE_NODE: u8 = 127;
/// The request's priority: 16, DroneCAN's "medium", the default of ArduPilot's (libcanard's)
/// publishers, which send it.
pub const ASK_PRIORITY: u8 = 16;

/// When to ask: keeps the latest `StatusMsg1` of each node seen (decoded with the codec's
/// [`Receiver`]) and says a request is due once [`ASK_EVERY`] has passed since the last and
/// no ESC turns (no node's latest rpm or pwm above 0).
#[derive(Debug)]
pub struct AskIds {
    receiver: Receiver,
    /// Whether each node's latest `StatusMsg1` had rpm or pwm above 0.
    turning: [bool; NODES],
    /// When the last request was sent.
    last: Option<Duration>,
    transfer_id: u8,
    source: u8,
}

impl AskIds {
    /// Asks from node `source` (1..=127).
    pub fn new(source: u8) -> AskIds {
        AskIds {
            receiver: Receiver::new(),
            turning: [false; NODES],
            last: None,
            transfer_id: 0,
            source,
        }
    }

    /// Takes a frame the bus carried.
    pub fn heard(&mut self, frame: &CanFrame) {
        if let Some(received) = self.receiver.push(frame)
            && let Message::StatusMsg1(s) = received.message
            && let Some(turning) = self
                .turning
                .get_mut(usize::from(received.header.source_node))
        {
            *turning = s.rpm > 0 || s.pwm > 0;
        }
    }

    /// Whether some node's latest `StatusMsg1` says its motor turns.
    pub fn any_turning(&self) -> bool {
        self.turning.iter().any(|&t| t)
    }

    /// The request's frames if one is due at `now` (a monotonic time since any fixed start,
    /// the same for every call; each call that returns some counts as sent: the next is due
    /// [`ASK_EVERY`] later, with the next transfer id). A time before the last request's asks
    /// nothing.
    pub fn due(&mut self, now: Duration) -> Option<Vec<CanFrame>> {
        if self.any_turning()
            || self
                .last
                .is_some_and(|l| now.checked_sub(l).is_none_or(|d| d < ASK_EVERY))
        {
            return None;
        }
        self.last = Some(now);
        let id = self.transfer_id;
        self.transfer_id = (id + 1) & 31;
        let request = Message::from(GetEscId::REQUEST);
        Some(request.frames(ASK_PRIORITY, self.source, 0, id).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::dronecan::{Header, Kind, StatusMsg1};

    fn status(node: u8, rpm: u16, pwm: u16, transfer_id: u8) -> Vec<CanFrame> {
        let s = StatusMsg1 {
            rpm,
            pwm,
            status: 0,
        };
        Message::from(s).frames(16, node, 0, transfer_id).collect()
    }

    #[test]
    fn asks_once_a_second_while_no_esc_turns() {
        let t0 = Duration::from_secs(1000);
        let mut ask = AskIds::new(DEFAULT_SOURCE_NODE);
        let first = ask.due(t0).expect("due at once");
        assert_eq!(first.len(), 1);
        let header = Header::parse(first[0].id()).unwrap();
        assert_eq!(header.source_node, 127);
        assert_eq!(header.priority, ASK_PRIORITY);
        assert_eq!(Kind::of(&header), Some(Kind::GetEscId));
        // Payload [0] and a tail byte (start, end, transfer id 0).
        assert_eq!(first[0].data(), &[0x00, 0xC0]);
        assert!(ask.due(t0 + Duration::from_millis(999)).is_none());
        let second = ask.due(t0 + ASK_EVERY).unwrap();
        assert_eq!(second[0].data(), &[0x00, 0xC1], "the next transfer id");
        assert!(
            ask.due(t0).is_none(),
            "a time before the last request asks nothing"
        );
        // An ESC turns: no request; an ESC stopped at 0 rpm but pwm > 0 still counts.
        for f in status(5, 1200, 300, 0) {
            ask.heard(&f);
        }
        assert!(ask.any_turning());
        assert!(ask.due(t0 + 3 * ASK_EVERY).is_none());
        for f in status(5, 0, 10, 1) {
            ask.heard(&f);
        }
        assert!(ask.due(t0 + 4 * ASK_EVERY).is_none());
        // Another node idle does not change that; node 5 stopped does.
        for f in status(6, 0, 0, 0) {
            ask.heard(&f);
        }
        assert!(ask.due(t0 + 5 * ASK_EVERY).is_none());
        for f in status(5, 0, 0, 2) {
            ask.heard(&f);
        }
        assert!(!ask.any_turning());
        assert_eq!(
            ask.due(t0 + 6 * ASK_EVERY).unwrap()[0].data(),
            &[0x00, 0xC2]
        );
        // Frames that are not DroneCAN change nothing.
        ask.heard(&CanFrame::standard(0x123, &[1]).unwrap());
        assert!(!ask.any_turning());
    }

    #[test]
    fn transfer_ids_wrap_at_32() {
        let t0 = Duration::from_secs(1000);
        let mut ask = AskIds::new(100);
        for k in 0..40u32 {
            let f = ask.due(t0 + k * ASK_EVERY).unwrap();
            assert_eq!(f[0].data()[1] & 31, (k % 32) as u8);
        }
    }
}
