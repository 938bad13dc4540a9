//! A scriptable stand-in for a CAN bus of Hobbywing DroneCAN ESCs and other nodes, on an SLCAN
//! pseudo-terminal: the simulator's SLCAN [`Adapter`] reads what `hwfoc can` writes, and each
//! node sends its messages and answers its services as the test says, with the codec's
//! DroneCAN encoders (checked against pydronecan's in `testdata/dronecan/vectors.txt`).
//!
//! Behaviours: an ESC that starts turning after a delay, reports StatusMsg1 at any rate or not
//! at all, StatusMsg2 with a current, answers late, twice, from another node or with a wrong
//! transfer id, or reads back otherwise than asked; a standard `esc.Status` node; a node that
//! sends only NodeStatus (a GPS). Every ESC sends NodeStatus at 1 Hz, as a real one does. Every request a node received is logged ([`Bus::requests`]).

use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use hwfoc::dronecan::{
    CanFrame, EscStatus, GetEscId, GetMaintenanceInformationResponse, GetMajorConfigResponse,
    Message, NodeStatus, Receiver, SelfTestResponse, SetDirectionResponse, SetIdResponse,
    SetLedResponse, SetReportingFrequencyResponse, SetThrottleSourceResponse, StatusMsg1,
    StatusMsg2, TransferType,
};
use hwfoc_sim::can::slcan::{Action, Adapter, push_frame};
use hwfoc_sim::pty::RawPair;

/// How an ESC answers its service requests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Answers {
    /// At once.
    Normal,
    /// Twice, at once.
    Twice,
    /// From another node id.
    FromNode(u8),
    /// With a transfer id one past the request's.
    WrongTransferId,
    /// Requests that change something after this long, reads at once.
    LateWrites(Duration),
}

/// One Hobbywing ESC.
#[derive(Debug, Clone)]
pub struct Esc {
    /// Its node id.
    pub node: u8,
    /// Its throttle channel.
    pub channel: u8,
    /// StatusMsg1's period; `None`: off.
    pub msg1: Option<Duration>,
    /// StatusMsg2 every 100 ms with this current (0.1 A); `None`: off.
    pub msg2_current: Option<i16>,
    /// From this long after the start its motor turns (rpm 3000, pwm 400).
    pub turns_after: Option<Duration>,
    /// How it answers.
    pub answers: Answers,
    /// Its direction read back stays what it was (SetDirection's own answer says the new one).
    pub keeps_direction: bool,
    /// SetID is answered but not applied.
    pub ignores_set_id: bool,
    /// SelfTest answers 1 (failed).
    pub self_test_fails: bool,
    /// SetLED is neither applied nor answered.
    pub mutes_led: bool,
}

impl Esc {
    /// An ESC at rest, StatusMsg1 at 50 Hz, answering at once.
    pub fn new(node: u8, channel: u8) -> Esc {
        Esc {
            node,
            channel,
            msg1: Some(Duration::from_millis(20)),
            msg2_current: None,
            turns_after: None,
            answers: Answers::Normal,
            keeps_direction: false,
            ignores_set_id: false,
            self_test_fails: false,
            mutes_led: false,
        }
    }
}

/// A node on the stand-in bus.
#[derive(Debug, Clone)]
pub enum Node {
    /// A Hobbywing ESC.
    Hobbywing(Esc),
    /// A standard DroneCAN ESC sending `esc.Status` at 10 Hz with this rpm and current (A).
    Standard { node: u8, rpm: i32, current: f32 },
    /// A node sending only NodeStatus, at 1 Hz.
    Gps { node: u8 },
}

/// A request a node received.
#[derive(Debug, Clone)]
pub struct Request {
    /// The node it was for (0: a broadcast, GetEscID).
    pub to: u8,
    /// The request.
    pub message: Message,
}

/// A stand-in bus running on a thread until dropped.
pub struct Bus {
    /// The `slcan:` spec of its pseudo-terminal.
    pub spec: String,
    stop: Arc<AtomicBool>,
    log: Arc<Mutex<Vec<Request>>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Bus {
    /// Starts the nodes.
    pub fn start(nodes: Vec<Node>) -> Bus {
        let pair = RawPair::open().unwrap();
        pair.master_nonblocking().unwrap();
        let spec = format!("slcan:{}", pair.path.display());
        let stop = Arc::new(AtomicBool::new(false));
        let log = Arc::new(Mutex::new(Vec::new()));
        let (s, l) = (Arc::clone(&stop), Arc::clone(&log));
        let thread = std::thread::spawn(move || run(pair, nodes, &s, &l));
        Bus {
            spec,
            stop,
            log,
            thread: Some(thread),
        }
    }

    /// Every request received so far.
    pub fn requests(&self) -> Vec<Request> {
        self.log.lock().unwrap().clone()
    }

    /// The requests received that change something (not GetEscID, not a read).
    pub fn writes(&self) -> Vec<Request> {
        self.requests()
            .into_iter()
            .filter(|r| is_write(&r.message))
            .collect()
    }
}

impl Drop for Bus {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// Whether a request changes something.
pub fn is_write(m: &Message) -> bool {
    match m {
        Message::SetDirectionRequest(r) => r.direction != 255,
        Message::SetReportingFrequencyRequest(r) => r.option != 0,
        Message::GetMaintenanceInformationRequest(r) => r.option != 0,
        Message::SetIdRequest(_)
        | Message::SetThrottleSourceRequest(_)
        | Message::SetLedRequest(_)
        | Message::SetBaudRequest(_)
        | Message::SelfTestRequest(_) => true,
        _ => false,
    }
}

/// An ESC's state.
struct State {
    esc: Esc,
    ccw: bool,
    source: u8,
    led: (u8, u8),
    rates: [u8; 3],
    next_msg1: Instant,
    next_msg2: Instant,
    next_node_status: Instant,
    tid: u8,
    node_status_tid: u8,
}

fn run(mut pair: RawPair, nodes: Vec<Node>, stop: &AtomicBool, log: &Mutex<Vec<Request>>) {
    let start = Instant::now();
    let mut adapter = Adapter::new();
    let mut receiver = Receiver::default();
    let mut escs: Vec<State> = Vec::new();
    let mut others = Vec::new();
    for n in nodes {
        match n {
            Node::Hobbywing(esc) => escs.push(State {
                rates: [if esc.msg1.is_some() { 5 } else { 9 }, 5, 7],
                esc,
                ccw: false,
                source: 0,
                led: (2, 0),
                next_msg1: start,
                next_msg2: start,
                next_node_status: start,
                tid: 0,
                node_status_tid: 0,
            }),
            other => others.push((other, start, 0u8)),
        }
    }
    // Frames to send at a time.
    let mut pending: Vec<(Instant, CanFrame)> = Vec::new();
    let mut buf = [0u8; 4096];
    while !stop.load(Ordering::Relaxed) {
        let now = Instant::now();
        if let Ok(n) = pair.master.read(&mut buf) {
            let (mut reply, mut actions) = (Vec::new(), Vec::new());
            adapter.feed(&buf[..n], &mut reply, &mut actions);
            let _ = pair.master.write_all(&reply);
            for a in actions {
                let Action::Frame(f) = a else { continue };
                let Some(r) = receiver.push(&f) else { continue };
                let to = match r.header.transfer {
                    TransferType::Request { destination } => destination,
                    TransferType::Message => 0,
                    _ => continue,
                };
                log.lock().unwrap().push(Request {
                    to,
                    message: r.message,
                });
                for s in &mut escs {
                    serve(s, start, now, &r, to, &mut pending);
                }
            }
        }
        let mut out = Vec::new();
        for s in &mut escs {
            broadcast(s, start, now, &mut pending);
        }
        for (node, next, tid) in &mut others {
            if now < *next {
                continue;
            }
            let (id, m, every): (u8, Message, u64) = match *node {
                Node::Standard { node, rpm, current } => (
                    node,
                    EscStatus {
                        current,
                        rpm,
                        ..EscStatus::default()
                    }
                    .into(),
                    100,
                ),
                Node::Gps { node } => (node, node_status(start), 1000),
                Node::Hobbywing(_) => unreachable!(),
            };
            pending.extend(m.frames(16, id, 0, *tid).map(|f| (now, f)));
            *tid = (*tid + 1) & 31;
            *next += Duration::from_millis(every);
        }
        pending.sort_by_key(|p| p.0);
        let due = pending.iter().take_while(|p| p.0 <= now).count();
        for (_, f) in pending.drain(..due) {
            if adapter.is_open() {
                push_frame(&mut out, &f);
            }
        }
        let _ = pair.master.write_all(&out);
        std::thread::sleep(Duration::from_millis(1));
    }
}

fn node_status(start: Instant) -> Message {
    NodeStatus {
        uptime_sec: start.elapsed().as_secs() as u32,
        ..NodeStatus::default()
    }
    .into()
}

fn turning(s: &State, start: Instant, now: Instant) -> bool {
    s.esc.turns_after.is_some_and(|d| now - start >= d)
}

/// An ESC's periodic messages.
fn broadcast(s: &mut State, start: Instant, now: Instant, pending: &mut Vec<(Instant, CanFrame)>) {
    let node = s.esc.node;
    let (rpm, pwm) = if turning(s, start, now) {
        (3000, 400)
    } else {
        (0, 0)
    };
    let mut send = |m: Message, tid: &mut u8| {
        pending.extend(m.frames(16, node, 0, *tid).map(|f| (now, f)));
        *tid = (*tid + 1) & 31;
    };
    if let Some(every) = s.esc.msg1
        && now >= s.next_msg1
    {
        let m = StatusMsg1 {
            rpm,
            pwm,
            status: u16::from(s.ccw) << 14,
        };
        send(m.into(), &mut s.tid);
        s.next_msg1 += every;
    }
    if now >= s.next_node_status {
        send(node_status(start), &mut s.node_status_tid);
        s.next_node_status += Duration::from_secs(1);
    }
    if let Some(current) = s.esc.msg2_current
        && now >= s.next_msg2
    {
        let m = StatusMsg2 {
            input_voltage: 160,
            current,
            temperature: 30,
        };
        let mut tid = s.tid;
        send(m.into(), &mut tid);
        s.next_msg2 += Duration::from_millis(100);
    }
}

/// An ESC's answer to a request for it (or to GetEscID), queued as its behaviour says.
fn serve(
    s: &mut State,
    start: Instant,
    now: Instant,
    r: &hwfoc::dronecan::Received,
    to: u8,
    pending: &mut Vec<(Instant, CanFrame)>,
) {
    let node = s.esc.node;
    if to == 0 {
        if let Message::GetEscId(g) = r.message
            && g.payload() == [0]
        {
            let m = Message::from(GetEscId::answer(node, s.esc.channel));
            pending.extend(m.frames(4, node, 0, s.tid).map(|f| (now, f)));
        }
        return;
    }
    if to != node {
        return;
    }
    let mut new_id = None;
    let answer: Message = match r.message {
        Message::SetIdRequest(q) => {
            if !s.esc.ignores_set_id {
                new_id = Some((q.node_id, q.throttle_channel));
            }
            SetIdResponse {
                node_id: q.node_id,
                throttle_channel: q.throttle_channel,
            }
            .into()
        }
        Message::SetDirectionRequest(q) => {
            if q.direction <= 1 {
                let asked = q.direction == 1;
                if !s.esc.keeps_direction {
                    s.ccw = asked;
                }
                SetDirectionResponse {
                    direction: u8::from(asked),
                }
                .into()
            } else {
                SetDirectionResponse {
                    direction: u8::from(s.ccw),
                }
                .into()
            }
        }
        Message::SetThrottleSourceRequest(q) => {
            if q.source <= 1 {
                s.source = q.source;
            }
            SetThrottleSourceResponse { source: s.source }.into()
        }
        Message::SetLedRequest(_) if s.esc.mutes_led => return,
        Message::SetLedRequest(q) => {
            s.led = (q.color, q.blink);
            SetLedResponse {
                option: q.option,
                color: q.color,
                blink: q.blink,
            }
            .into()
        }
        Message::SetReportingFrequencyRequest(q) => {
            let i = q
                .msg_id
                .checked_sub(20050)
                .map(usize::from)
                .filter(|&i| i < 3);
            if let Some(i) = i
                && q.option == 1
            {
                s.rates[i] = q.rate;
                if i == 0 {
                    s.esc.msg1 = match q.rate {
                        1..=8 => Some(Duration::from_millis(
                            [2, 4, 5, 10, 20, 50, 100, 1000][usize::from(q.rate) - 1],
                        )),
                        _ => None,
                    };
                    s.next_msg1 = now;
                }
            }
            SetReportingFrequencyResponse {
                option: q.option,
                msg_id: q.msg_id,
                rate: i.map_or(9, |i| s.rates[i]),
            }
            .into()
        }
        Message::GetMajorConfigRequest(_) => GetMajorConfigResponse {
            direction: s.ccw,
            throttle_source: s.source == 1,
            throttle_channel: s.esc.channel,
            led_status: s.led.1,
            led_color: s.led.0,
            msg2_rate: s.rates[1],
            msg1_rate: s.rates[0],
            positioning_angle: 0,
            reserved: [0, 0],
        }
        .into(),
        Message::GetMaintenanceInformationRequest(_) => GetMaintenanceInformationResponse {
            total_rotation_time_min: 12,
            time_since_maintenance_min: 3,
        }
        .into(),
        Message::SelfTestRequest(_) => SelfTestResponse {
            status: u8::from(s.esc.self_test_fails || turning(s, start, now)),
        }
        .into(),
        _ => return,
    };
    let TransferType::Request { .. } = r.header.transfer else {
        return;
    };
    let asker = r.header.source_node;
    let (from, tid, at, times) = match s.esc.answers {
        Answers::Normal => (node, r.transfer_id, now, 1),
        Answers::Twice => (node, r.transfer_id, now, 2),
        Answers::FromNode(n) => (n, r.transfer_id, now, 1),
        Answers::WrongTransferId => (node, (r.transfer_id + 1) & 31, now, 1),
        Answers::LateWrites(d) if is_write(&r.message) => (node, r.transfer_id, now + d, 1),
        Answers::LateWrites(_) => (node, r.transfer_id, now, 1),
    };
    for _ in 0..times {
        pending.extend(answer.frames(16, from, asker, tid).map(|f| (at, f)));
    }
    if let Some((id, channel)) = new_id {
        s.esc.node = id;
        s.esc.channel = channel;
    }
}
