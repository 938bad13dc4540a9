//! What a bus said of each node: its latest status messages, its answers to GetEscID, and the
//! signs that several ESCs share its node id (the factory state).

use std::collections::BTreeMap;
use std::fmt;
use std::time::{Duration, Instant};

use hwfoc::dronecan::{
    CanFrame, EscStatus, FrameKind, Header, Kind, Message, NodeStatus, Received, Receiver,
    StatusMsg1, StatusMsg2, StatusMsg3, TailByte,
};

/// StatusMsg1 transfers a node must have sent before its transfer ids are judged.
const JUDGED_AFTER: u64 = 8;
/// A current at or above this, in 0.1 A (StatusMsg2) or A (`esc.Status`), means a motor
/// turns: 1 A, above an idle ESC's own draw.
const TURNING_CURRENT_A: f32 = 1.0;

/// What a node reported that says its motor turns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// A Hobbywing `StatusMsg1`'s rpm and pwm.
    RpmPwm {
        /// rpm.
        rpm: u16,
        /// pwm.
        pwm: u16,
    },
    /// A Hobbywing `StatusMsg2`'s current, A.
    Current(f32),
    /// A standard `esc.Status`'s rpm and current, A.
    RpmCurrent {
        /// rpm (negative: reversed).
        rpm: i32,
        /// A.
        current: f32,
    },
}

/// `rpm 3000, pwm 400`, `25.0 A`, `rpm 5000, 10.0 A`.
impl fmt::Display for Motion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Motion::RpmPwm { rpm, pwm } => write!(f, "rpm {rpm}, pwm {pwm}"),
            Motion::Current(a) => write!(f, "{a:.1} A"),
            Motion::RpmCurrent { rpm, current } => write!(f, "rpm {rpm}, {current:.1} A"),
        }
    }
}

/// What a message says of a node's motor: `Some` if it turns.
fn motion(message: &Message) -> Option<Motion> {
    match *message {
        Message::StatusMsg1(s) if s.rpm > 0 || s.pwm > 0 => Some(Motion::RpmPwm {
            rpm: s.rpm,
            pwm: s.pwm,
        }),
        Message::StatusMsg2(s) if f32::from(s.current) / 10.0 >= TURNING_CURRENT_A => {
            Some(Motion::Current(f32::from(s.current) / 10.0))
        }
        Message::EscStatus(s) if s.rpm != 0 || s.current.abs() >= TURNING_CURRENT_A => {
            Some(Motion::RpmCurrent {
                rpm: s.rpm,
                current: s.current,
            })
        }
        _ => None,
    }
}

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
    /// The latest standard `esc.Status`.
    pub esc_status: Option<EscStatus>,
    /// When the latest `StatusMsg1` was received.
    pub status1_at: Option<Instant>,
    /// The time between its latest two `StatusMsg1`.
    pub status1_period: Option<Duration>,
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
    /// The first report of the window that said its motor turns (a `StatusMsg1`'s rpm or pwm
    /// above 0, a current of 1 A or more, an `esc.Status` rpm).
    pub window_motion: Option<Motion>,
}

impl NodeHeard {
    fn new(node: u8) -> NodeHeard {
        NodeHeard {
            node,
            status1: None,
            status2: None,
            status3: None,
            node_status: None,
            esc_status: None,
            status1_at: None,
            status1_period: None,
            status1_count: 0,
            out_of_sequence: 0,
            last_tid: None,
            channels: Vec::new(),
            most_answers: 0,
            window_status1: 0,
            window_max: (0, 0),
            window_motion: None,
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

    /// Whether a report of the window said the motor turns ([`NodeHeard::window_motion`]).
    pub fn turning(&self) -> bool {
        self.window_motion.is_some()
    }

    /// Whether its latest report says its motor turns.
    pub fn turning_now(&self) -> bool {
        let msg1 = self.status1.map(Message::from);
        let msg2 = self.status2.map(Message::from);
        let esc = self.esc_status.map(Message::from);
        [msg1, msg2, esc]
            .iter()
            .flatten()
            .any(|m| motion(m).is_some())
    }

    /// Whether it reports as an ESC (a Hobbywing status message or `esc.Status`).
    pub fn is_esc(&self) -> bool {
        self.status1.is_some()
            || self.status2.is_some()
            || self.status3.is_some()
            || self.esc_status.is_some()
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
        self.take_at(frame, Instant::now())
    }

    /// [`Heard::take`] of a frame received at `at`.
    pub fn take_at(&mut self, frame: &CanFrame, at: Instant) -> Option<Received> {
        let received = single_frame(frame).or_else(|| self.receiver.push(frame))?;
        let header = received.header;
        if header.transfer.is_service() || header.source_node == 0 {
            return Some(received);
        }
        let node = self
            .nodes
            .entry(header.source_node)
            .or_insert_with(|| NodeHeard::new(header.source_node));
        if node.window_motion.is_none() {
            node.window_motion = motion(&received.message);
        }
        match received.message {
            Message::StatusMsg1(s) => {
                node.status1_period = node.status1_at.map(|t| at.saturating_duration_since(t));
                node.status1_at = Some(at);
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
            Message::EscStatus(s) => node.esc_status = Some(s),
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
            n.window_motion = None;
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

    /// Whether a node's latest report says its motor turns ([`NodeHeard::turning_now`]).
    pub fn any_turning(&self) -> bool {
        self.nodes.values().any(NodeHeard::turning_now)
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
        assert_eq!(n.window_motion, Some(Motion::RpmPwm { rpm: 800, pwm: 0 }));
        // Frames that are not DroneCAN, and service transfers, add no node.
        h.take(&CanFrame::standard(0x10, &[1, 2]).unwrap());
        assert_eq!(h.nodes().count(), 1);
    }

    #[test]
    fn current_and_a_standard_esc_status_say_a_motor_turns() {
        let mut h = Heard::new();
        h.start_window();
        let msg2 = |current| StatusMsg2 {
            input_voltage: 160,
            current,
            temperature: 30,
        };
        // An idle ESC's own draw is not a turning motor; 25 A is.
        feed(&mut h, 10, msg2(5), 0);
        assert!(!h.any_turning() && h.node(10).unwrap().is_esc());
        feed(&mut h, 10, msg2(250), 1);
        assert_eq!(
            h.node(10).unwrap().window_motion,
            Some(Motion::Current(25.0))
        );
        assert!(h.any_turning());
        let status = |rpm, current| EscStatus {
            current,
            rpm,
            ..EscStatus::default()
        };
        feed(&mut h, 30, status(0, 0.25), 0);
        assert!(!h.node(30).unwrap().turning());
        feed(&mut h, 30, status(5000, 10.0), 1);
        let n = h.node(30).unwrap();
        assert!(n.turning_now() && n.is_esc());
        assert_eq!(n.window_motion.unwrap().to_string(), "rpm 5000, 10.0 A");
        // A node sending NodeStatus only is no ESC.
        feed(&mut h, 20, NodeStatus::default(), 0);
        assert!(!h.node(20).unwrap().is_esc());
    }

    #[test]
    fn the_time_of_each_status_msg1_is_kept() {
        let mut h = Heard::new();
        let t0 = Instant::now();
        for (i, ms) in [0u64, 1000].into_iter().enumerate() {
            for f in Message::from(status(0)).frames(16, 10, 0, i as u8) {
                h.take_at(&f, t0 + Duration::from_millis(ms));
            }
        }
        let n = h.node(10).unwrap();
        assert_eq!(n.status1_at, Some(t0 + Duration::from_secs(1)));
        assert_eq!(n.status1_period, Some(Duration::from_secs(1)));
    }
}
