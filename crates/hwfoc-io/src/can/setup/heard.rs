//! What a bus said of each node: its latest status messages, its answers to GetEscID, and the
//! signs that several ESCs share its node id (the factory state).

use std::collections::BTreeMap;

use hwfoc::dronecan::{
    CanFrame, FrameKind, Header, Kind, Message, NodeStatus, Received, Receiver, StatusMsg1,
    StatusMsg2, StatusMsg3, TailByte,
};

/// StatusMsg1 transfers a node must have sent before its transfer ids are judged.
const JUDGED_AFTER: u64 = 8;

/// What was heard from one node.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeHeard {
    /// The node id.
    pub node: u8,
    /// The latest `StatusMsg1`.
    pub status1: Option<StatusMsg1>,
    /// The latest `StatusMsg2`.
    pub status2: Option<StatusMsg2>,
    /// The latest `StatusMsg3`.
    pub status3: Option<StatusMsg3>,
    /// The latest `NodeStatus`.
    pub node_status: Option<NodeStatus>,
    /// `StatusMsg1` transfers heard.
    pub status1_count: u64,
    /// `StatusMsg1` transfers whose transfer id was not the previous one's plus one: a node
    /// that is one ESC has almost none; several ESCs under one node id, each counting on its
    /// own, make about every other one so.
    pub out_of_sequence: u64,
    last_tid: Option<u8>,
    /// Throttle channels of the GetEscID answers to the latest request (one per ESC that
    /// answered as this node).
    pub channels: Vec<u8>,
    /// The most GetEscID answers to one request.
    pub most_answers: usize,
    /// `StatusMsg1` transfers since the window began ([`Heard::start_window`]).
    pub window_status1: u64,
    /// The highest rpm and pwm of a `StatusMsg1` in the window.
    pub window_max: (u16, u16),
}

impl NodeHeard {
    fn new(node: u8) -> NodeHeard {
        NodeHeard {
            node,
            status1: None,
            status2: None,
            status3: None,
            node_status: None,
            status1_count: 0,
            out_of_sequence: 0,
            last_tid: None,
            channels: Vec::new(),
            most_answers: 0,
            window_status1: 0,
            window_max: (0, 0),
        }
    }

    /// How many ESCs answer as this node, at least: the most GetEscID answers to one request,
    /// or 2 when its StatusMsg1 transfer ids interleave (at least a quarter out of sequence
    /// after the first 8), else 1.
    pub fn escs(&self) -> usize {
        let interleaved =
            self.status1_count >= JUDGED_AFTER && self.out_of_sequence * 4 >= self.status1_count;
        self.most_answers.max(if interleaved { 2 } else { 1 })
    }

    /// Whether several ESCs answer as this node (the factory state: every ESC node 1).
    pub fn is_shared(&self) -> bool {
        self.escs() > 1
    }

    /// Whether a StatusMsg1 of the window said the motor turns (rpm or pwm above 0).
    pub fn turning(&self) -> bool {
        self.window_max != (0, 0)
    }
}

/// Every node heard on a bus, by node id.
#[derive(Debug, Default)]
pub struct Heard {
    nodes: BTreeMap<u8, NodeHeard>,
    receiver: Receiver,
}

impl Heard {
    /// Nothing heard yet.
    pub fn new() -> Heard {
        Heard::default()
    }

    /// Takes a frame the bus carried; the transfer it completes, if any.
    ///
    /// Single-frame transfers (all of Hobbywing's) are decoded here one by one: the codec's
    /// [`Receiver`], which takes the rest, drops a message with the transfer id of its node's
    /// previous one as a duplicate, and several ESCs under one node id send the same ids
    /// (which is what shows them).
    pub fn take(&mut self, frame: &CanFrame) -> Option<Received> {
        let received = single_frame(frame).or_else(|| self.receiver.push(frame))?;
        let header = received.header;
        if header.transfer.is_service() || header.source_node == 0 {
            return Some(received);
        }
        let node = self
            .nodes
            .entry(header.source_node)
            .or_insert_with(|| NodeHeard::new(header.source_node));
        match received.message {
            Message::StatusMsg1(s) => {
                node.status1 = Some(s);
                node.status1_count += 1;
                node.window_status1 += 1;
                node.window_max = (node.window_max.0.max(s.rpm), node.window_max.1.max(s.pwm));
                if node
                    .last_tid
                    .is_some_and(|t| (t + 1) & 31 != received.transfer_id)
                {
                    node.out_of_sequence += 1;
                }
                node.last_tid = Some(received.transfer_id);
            }
            Message::StatusMsg2(s) => node.status2 = Some(s),
            Message::StatusMsg3(s) => node.status3 = Some(s),
            Message::NodeStatus(s) => node.node_status = Some(s),
            Message::GetEscId(g) => {
                if let Some((_, channel)) = g.as_answer() {
                    node.channels.push(channel);
                    node.most_answers = node.most_answers.max(node.channels.len());
                }
            }
            _ => {}
        }
        Some(received)
    }

    /// A new GetEscID request goes out: each node's answers are counted afresh.
    pub fn new_round(&mut self) {
        for n in self.nodes.values_mut() {
            n.channels.clear();
        }
    }

    /// Starts a window of StatusMsg1 counts and highest rpm and pwm (the safety check).
    pub fn start_window(&mut self) {
        for n in self.nodes.values_mut() {
            n.window_status1 = 0;
            n.window_max = (0, 0);
        }
    }

    /// Every node heard, by id.
    pub fn nodes(&self) -> impl Iterator<Item = &NodeHeard> {
        self.nodes.values()
    }

    /// Node `node`, if heard.
    pub fn node(&self, node: u8) -> Option<&NodeHeard> {
        self.nodes.get(&node)
    }

    /// Whether a node's latest StatusMsg1 says its motor turns.
    pub fn any_turning(&self) -> bool {
        self.nodes
            .values()
            .any(|n| n.status1.is_some_and(|s| s.rpm > 0 || s.pwm > 0))
    }
}

/// A single-frame transfer of a known type, decoded.
fn single_frame(frame: &CanFrame) -> Option<Received> {
    if frame.kind() != FrameKind::Data || !frame.is_extended() {
        return None;
    }
    let (&tail, payload) = frame.data().split_last()?;
    let tail = TailByte::from_byte(tail);
    if !(tail.start && tail.end) {
        return None;
    }
    let header = Header::parse(frame.id()).ok()?;
    let message = Message::decode(Kind::of(&header)?, payload).ok()?;
    Some(Received {
        header,
        transfer_id: tail.transfer_id,
        message,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::dronecan::GetEscId;

    fn feed(heard: &mut Heard, node: u8, m: impl Into<Message>, tid: u8) {
        for f in m.into().frames(16, node, 0, tid) {
            heard.take(&f);
        }
    }

    fn status(rpm: u16) -> StatusMsg1 {
        StatusMsg1 {
            rpm,
            pwm: 0,
            status: 0,
        }
    }

    #[test]
    fn one_esc_per_node() {
        let mut h = Heard::new();
        h.new_round();
        for tid in 0..40u8 {
            feed(&mut h, 10, status(0), tid & 31);
        }
        feed(&mut h, 10, GetEscId::answer(10, 1), 0);
        let n = h.node(10).unwrap();
        assert_eq!((n.status1_count, n.out_of_sequence), (40, 0));
        assert_eq!((n.escs(), n.channels.as_slice()), (1, &[1u8][..]));
        assert!(!h.any_turning());
    }

    #[test]
    fn several_escs_as_node_1() {
        // Three ESCs at node 1, each with its own transfer ids, in lockstep: every transfer
        // heard (the Receiver alone would drop the repeated ids as duplicates).
        let mut h = Heard::new();
        for tid in 0..10u8 {
            for _ in 0..3 {
                feed(&mut h, 1, status(0), tid);
            }
        }
        let n = h.node(1).unwrap();
        assert_eq!(n.status1_count, 30);
        assert!(n.is_shared() && n.escs() == 2, "{n:?}");
        h.new_round();
        for _ in 0..3 {
            feed(&mut h, 1, GetEscId::answer(1, 1), 0);
        }
        assert_eq!(h.node(1).unwrap().escs(), 3);
        h.new_round();
        assert_eq!(h.node(1).unwrap().channels, Vec::<u8>::new());
        assert_eq!(h.node(1).unwrap().escs(), 3, "the most answers kept");
    }

    #[test]
    fn the_window_sees_a_motor_turning() {
        let mut h = Heard::new();
        feed(&mut h, 11, status(1500), 0);
        h.start_window();
        assert!(!h.node(11).unwrap().turning());
        assert!(h.any_turning());
        feed(&mut h, 11, status(800), 1);
        feed(&mut h, 11, status(0), 2);
        let n = h.node(11).unwrap();
        assert!(n.turning() && n.window_max == (800, 0) && n.window_status1 == 2);
        assert!(!h.any_turning());
        // Frames that are not DroneCAN, and service transfers, add no node.
        h.take(&CanFrame::standard(0x10, &[1, 2]).unwrap());
        assert_eq!(h.nodes().count(), 1);
    }
}
