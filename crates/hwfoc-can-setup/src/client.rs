//! [`Client`]: hwfoc as a node on the bus, asking the ESCs and calling their services.

use std::collections::HashMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use hwfoc::dronecan::{
    CanFrame, Form, GetEscId, GetMaintenanceInformationRequest, GetMaintenanceInformationResponse,
    GetMajorConfigRequest, GetMajorConfigResponse, Message, Received, SetDirectionRequest,
    SetReportingFrequencyRequest, TransferType,
};

use crate::SetupError;
use crate::heard::{Heard, NodeHeard};
use crate::values::{Change, Direction, Led, StatusMessage, ThrottleSource};
use hwfoc_ports::can::{ASK_EVERY, ASK_PRIORITY, CanBus, CanError};

/// Priority of hwfoc's service requests: 16, DroneCAN's "medium" (pydronecan's and
/// ArduPilot's default).
pub const REQUEST_PRIORITY: u8 = 16;
/// The shortest listen of the first safety check.
const IDLE_MIN: Duration = Duration::from_millis(100);
/// How long [`Client::listen_first`] listens before anything is sent: a NodeStatus period
/// (1 s, DroneCAN's slowest) and a margin, so that every node on the bus is heard.
const LISTEN_FIRST: Duration = Duration::from_millis(1100);
/// How old a target's `StatusMsg1` may be when a change that can turn its motor is sent.
const FRESH: Duration = Duration::from_millis(300);
/// The most frames taken at once from what the bus buffered ([`Client::check_at_rest`]).
const DRAIN_MAX: usize = 10_000;
/// The longest listen of the safety check: two StatusMsg1 at the slowest rate but 0 Hz (1 Hz).
const IDLE_MAX: Duration = Duration::from_millis(2200);
/// How long [`Client::survey`] listens at least, and for how long no new node ends it.
const SURVEY_QUIET: Duration = Duration::from_millis(500);
/// How long the answers to a GetEscID request are collected when reading a node id back.
const ID_ANSWERS: Duration = Duration::from_millis(300);
/// The longest wait of one read of the bus: the stop flag is looked at this often.
const POLL: Duration = Duration::from_millis(50);

/// A CAN bus as a [`Client`] uses it: [`CanBus`], or a stand-in in tests.
pub trait Link {
    /// The bus as given (`slcan:/dev/ttyACM0`), for messages.
    fn name(&self) -> &str;
    /// The next frame, waiting at most `timeout`.
    fn recv(&mut self, timeout: Duration) -> Result<Option<CanFrame>, CanError>;
    /// Sends a frame.
    fn send(&mut self, frame: &CanFrame) -> Result<(), CanError>;
}

impl Link for CanBus {
    fn name(&self) -> &str {
        CanBus::name(self)
    }
    fn recv(&mut self, timeout: Duration) -> Result<Option<CanFrame>, CanError> {
        Ok(CanBus::recv(self, timeout)?.map(|(_, f)| f))
    }
    fn send(&mut self, frame: &CanFrame) -> Result<(), CanError> {
        CanBus::send(self, frame)
    }
}

/// A change made ([`Client::change`]).
#[derive(Debug)]
pub struct Made {
    /// What the ESC now says (`None` for a bit rate, which cannot be read at the old one).
    pub said: Option<Change>,
    /// The write's answer did not come in time, though the read-back agrees
    /// ([`SetupError::Unanswered`]).
    pub late: Option<SetupError>,
}

/// What [`Client::survey`] learnt of one node: what it sent, and its answers (`None` where
/// it did not answer in time).
#[derive(Debug, Clone, PartialEq)]
pub struct EscSurvey {
    /// What it sent.
    pub heard: NodeHeard,
    /// `SetDirection` 255.
    pub direction: Option<Direction>,
    /// `GetMajorConfig`.
    pub config: Option<GetMajorConfigResponse>,
    /// `GetMaintenanceInformation` (option 0: read only).
    pub maintenance: Option<GetMaintenanceInformationResponse>,
    /// StatusMsg3's rate code (`SetReportingFrequency`, option 0: read).
    pub msg3_rate: Option<u8>,
}

/// The ESCs on a bus ([`Client::survey`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Survey {
    /// Each node heard, by id.
    pub escs: Vec<EscSurvey>,
    /// Whether the ESCs were asked their settings (not while a motor turns).
    pub asked: bool,
    /// From the start of the survey to the last answer.
    pub elapsed: Duration,
}

impl Survey {
    /// The nodes several ESCs answer as (the factory state).
    pub fn shared(&self) -> impl Iterator<Item = &EscSurvey> {
        self.escs.iter().filter(|e| e.heard.is_shared())
    }
}

/// hwfoc as a node (`source`) on a bus: it listens ([`Heard`]), asks the ESCs for their ids
/// (GetEscID `[0]`, at most once a second and only while no ESC turns), checks that no motor
/// turns before a change ([`Client::check_at_rest`]), and calls a service of one node,
/// waiting for the response that matches ([`Client::call`]). Every wait ends when the stop
/// flag is set ([`SetupError::Stopped`]).
pub struct Client<L: Link = CanBus> {
    link: L,
    source: u8,
    stop: Arc<AtomicBool>,
    heard: Heard,
    /// The next transfer id per (service, destination).
    transfer_ids: HashMap<(u16, u8), u8>,
    ask_tid: u8,
    last_ask: Option<Instant>,
    /// Whether the window of motion reports began ([`Client::check_at_rest`]).
    watching: bool,
}

impl<L: Link> Client<L> {
    /// A client sending as node `source` (1..=127).
    pub fn new(link: L, source: u8, stop: Arc<AtomicBool>) -> Client<L> {
        Client {
            link,
            source,
            stop,
            heard: Heard::new(),
            transfer_ids: HashMap::new(),
            ask_tid: first_transfer_id(),
            last_ask: None,
            watching: false,
        }
    }

    /// The bus as given.
    pub fn bus(&self) -> &str {
        self.link.name()
    }

    /// What has been heard.
    pub fn heard(&self) -> &Heard {
        &self.heard
    }

    /// One frame from the bus, taken into [`Heard`]; the transfer it completes.
    fn poll(&mut self, timeout: Duration) -> Result<Option<Received>, SetupError> {
        if self.stop.load(Ordering::Relaxed) {
            return Err(SetupError::Stopped {
                bus: self.bus().to_string(),
            });
        }
        let frame = self.link.recv(timeout.min(POLL))?;
        Ok(frame.and_then(|f| self.heard.take(&f)))
    }

    /// Listens until `done` says so or `deadline`.
    fn listen_until(
        &mut self,
        deadline: Instant,
        mut done: impl FnMut(&Heard, Instant) -> bool,
    ) -> Result<(), SetupError> {
        loop {
            let now = Instant::now();
            if now >= deadline || done(&self.heard, now) {
                return Ok(());
            }
            self.poll(deadline - now)?;
        }
    }

    /// Broadcasts GetEscID `[0]` if no ESC turns and (unless `now_anyway`) a second has
    /// passed since the last; returns whether it did.
    pub fn ask_ids(&mut self, now_anyway: bool) -> Result<bool, SetupError> {
        let now = Instant::now();
        if self.heard.nodes().any(|n| n.turning() || n.turning_now())
            || (!now_anyway && self.last_ask.is_some_and(|t| now - t < ASK_EVERY))
        {
            return Ok(false);
        }
        self.last_ask = Some(now);
        let tid = self.ask_tid;
        self.ask_tid = (tid + 1) & 31;
        self.heard.new_round();
        let request = Message::from(GetEscId::REQUEST);
        for f in request.frames(ASK_PRIORITY, self.source, 0, tid) {
            self.link.send(&f)?;
        }
        Ok(true)
    }

    /// Listens 1.1 s without sending anything, so that every node is heard before
    /// hwfoc speaks: each reported motion is kept from here on ([`Client::check_at_rest`]).
    pub fn listen_first(&mut self) -> Result<(), SetupError> {
        self.watch();
        let until = Instant::now() + LISTEN_FIRST;
        self.listen_until(until, |_, _| false)
    }

    fn watch(&mut self) {
        if !self.watching {
            self.heard.start_window();
            self.watching = true;
        }
    }

    /// Takes what the bus buffered while nothing read it (a question on the terminal).
    fn drain(&mut self) -> Result<(), SetupError> {
        for _ in 0..DRAIN_MAX {
            if self.stop.load(Ordering::Relaxed) {
                return Err(SetupError::Stopped {
                    bus: self.bus().to_string(),
                });
            }
            match self.link.recv(Duration::ZERO)? {
                Some(f) => {
                    self.heard.take(&f);
                }
                None => break,
            }
        }
        Ok(())
    }

    /// The safety check before each change of `node`, and after the confirmation: takes what
    /// the bus buffered, then listens until every node that sends `StatusMsg1` has sent one
    /// anew (at least 100 ms the first time, at most 2.2 s: two periods at 1 Hz) and `node`'s
    /// latest is at most 0.3 s old. Refuses if any node reported its motor turning since
    /// the first check (or [`Client::listen_first`]): rpm or pwm above 0, 1 A or more, a
    /// standard `esc.Status` rpm. For a change that can turn a motor (`motor`), refuses too if
    /// `node` was not seen at rest in the last 0.3 s (its `StatusMsg1` off, never sent or
    /// stopped), or another node's `StatusMsg1` stopped.
    pub fn check_at_rest(&mut self, node: u8, motor: bool) -> Result<(), SetupError> {
        let first = !self.watching;
        self.watch();
        self.drain()?;
        let since = Instant::now();
        let least = if first { IDLE_MIN } else { Duration::ZERO };
        let reporting: Vec<u8> = self
            .heard
            .nodes()
            .filter(|n| n.status1.is_some())
            .map(|n| n.node)
            .collect();
        let anew = |n: &NodeHeard| n.status1_at.is_some_and(|t| t >= since);
        let fresh =
            |n: &NodeHeard, now: Instant| anew(n) && n.status1_at.is_some_and(|t| now - t <= FRESH);
        self.listen_until(since + IDLE_MAX, |h, now| {
            h.nodes().any(NodeHeard::turning)
                || (now - since >= least
                    && reporting.iter().all(|&r| h.node(r).is_some_and(anew))
                    && h.node(node)
                        .is_none_or(|n| n.status1.is_none() || fresh(n, now)))
        })?;
        let turned = self
            .heard
            .nodes()
            .find_map(|n| n.window_motion.map(|m| (n.node, m)));
        if let Some((node, motion)) = turned {
            return Err(SetupError::Turning {
                bus: self.bus().to_string(),
                node,
                motion,
            });
        }
        if !motor {
            return Ok(());
        }
        let now = Instant::now();
        let unseen = |node: u8, heard: bool| SetupError::Unseen {
            bus: self.bus().to_string(),
            node,
            heard,
        };
        match self.heard.node(node) {
            Some(n) if fresh(n, now) => {}
            // Heard, but not its rpm and pwm of late.
            Some(_) => return Err(unseen(node, true)),
            None => return Err(unseen(node, false)),
        }
        match reporting
            .iter()
            .find(|&&r| !self.heard.node(r).is_some_and(anew))
        {
            Some(&r) => Err(unseen(r, true)),
            None => Ok(()),
        }
    }

    /// Refuses a request to `node` if several ESCs answer as it (asking for their ids first
    /// if no one has yet).
    pub fn check_alone(&mut self, node: u8) -> Result<(), SetupError> {
        if self.last_ask.is_none() && self.ask_ids(true)? {
            let until = Instant::now() + ID_ANSWERS;
            self.listen_until(until, |_, _| false)?;
        }
        match self.heard.node(node) {
            Some(n) if n.is_shared() => Err(SetupError::Shared {
                bus: self.bus().to_string(),
                node,
                escs: n.escs(),
            }),
            _ => Ok(()),
        }
    }

    /// Calls service `request` of `node` and waits at most `timeout` for its response (from
    /// `node`, to this client, of the same service and transfer id).
    pub fn call(
        &mut self,
        node: u8,
        request: Message,
        timeout: Duration,
    ) -> Result<Message, SetupError> {
        let kind = request.kind();
        debug_assert_eq!(kind.form(), Form::Request);
        let service = kind.data_type_id();
        let tid = {
            let t = self
                .transfer_ids
                .entry((service, node))
                .or_insert_with(first_transfer_id);
            let tid = *t;
            *t = (tid + 1) & 31;
            tid
        };
        for f in request.frames(REQUEST_PRIORITY, self.source, node, tid) {
            self.link.send(&f)?;
        }
        let deadline = Instant::now() + timeout;
        loop {
            let now = Instant::now();
            if now >= deadline {
                return Err(SetupError::NoAnswer {
                    bus: self.bus().to_string(),
                    node,
                    service: kind,
                    timeout,
                });
            }
            if let Some(r) = self.poll(deadline - now)?
                && r.header.source_node == node
                && r.header.data_type_id == service
                && r.header.transfer
                    == (TransferType::Response {
                        destination: self.source,
                    })
                && r.transfer_id == tid
            {
                return Ok(r.message);
            }
        }
    }

    /// The response to `request`, of the type `pick` takes (a response of another type is
    /// not possible after [`Client::call`]'s matching, but told if it came).
    fn ask<T>(
        &mut self,
        node: u8,
        request: impl Into<Message>,
        timeout: Duration,
        pick: impl Fn(Message) -> Option<T>,
    ) -> Result<T, SetupError> {
        let request = request.into();
        let kind = request.kind();
        let m = self.call(node, request, timeout)?;
        pick(m).ok_or_else(|| SetupError::NoAnswer {
            bus: self.bus().to_string(),
            node,
            service: kind,
            timeout,
        })
    }

    /// The direction (`SetDirection` 255, which only asks).
    pub fn direction(&mut self, node: u8, timeout: Duration) -> Result<Direction, SetupError> {
        let r = SetDirectionRequest {
            direction: SetDirectionRequest::QUERY,
        };
        self.ask(node, r, timeout, |m| match m {
            Message::SetDirectionResponse(r) => {
                Some(Direction::from_ccw(r.direction == SetDirectionRequest::CCW))
            }
            _ => None,
        })
    }

    /// `GetMajorConfig`.
    pub fn major_config(
        &mut self,
        node: u8,
        timeout: Duration,
    ) -> Result<GetMajorConfigResponse, SetupError> {
        self.ask(
            node,
            GetMajorConfigRequest { option: 0 },
            timeout,
            |m| match m {
                Message::GetMajorConfigResponse(r) => Some(r),
                _ => None,
            },
        )
    }

    /// `GetMaintenanceInformation` with option 0: read, never clear.
    pub fn maintenance(
        &mut self,
        node: u8,
        timeout: Duration,
    ) -> Result<GetMaintenanceInformationResponse, SetupError> {
        let r = GetMaintenanceInformationRequest {
            option: GetMaintenanceInformationRequest::READ,
        };
        self.ask(node, r, timeout, |m| match m {
            Message::GetMaintenanceInformationResponse(r) => Some(r),
            _ => None,
        })
    }

    /// A status message's rate code (`SetReportingFrequency` option 0: read).
    pub fn rate(
        &mut self,
        node: u8,
        message: StatusMessage,
        timeout: Duration,
    ) -> Result<u8, SetupError> {
        let r = SetReportingFrequencyRequest {
            option: SetReportingFrequencyRequest::READ,
            msg_id: message.kind().data_type_id(),
            rate: 0,
        };
        self.ask(node, r, timeout, |m| match m {
            Message::SetReportingFrequencyResponse(r) => Some(r.rate),
            _ => None,
        })
    }

    /// Makes `change` on `node`: the service's response.
    pub fn apply(
        &mut self,
        node: u8,
        change: &Change,
        timeout: Duration,
    ) -> Result<Message, SetupError> {
        let request = change
            .request()
            .ok_or(SetupError::Unsupported { change: *change })?;
        self.call(node, request, timeout)
    }

    /// Makes `change` on `node` and reads it back. A write whose answer did not come in
    /// time may have been made: it is read back all the same, and [`Made::late`] says so
    /// (an error if the read-back fails or differs). A new node id is read back at the new id;
    /// if that is not heard and the old id still answers, [`SetupError::IdNotTaken`].
    pub fn change(
        &mut self,
        node: u8,
        change: &Change,
        timeout: Duration,
    ) -> Result<Made, SetupError> {
        let late = match self.apply(node, change, timeout) {
            Ok(_) => None,
            Err(e @ SetupError::NoAnswer { .. }) => Some(e),
            Err(e) => return Err(e),
        };
        let unanswered = |said: Option<Change>| match &late {
            Some(SetupError::NoAnswer {
                bus,
                service,
                timeout,
                ..
            }) => Some(SetupError::Unanswered {
                bus: bus.clone(),
                node,
                service: *service,
                timeout: *timeout,
                said,
            }),
            _ => None,
        };
        let read_at = match *change {
            Change::NodeId { node_id, .. } => node_id,
            _ => node,
        };
        let said = match self.read(read_at, change, timeout) {
            Ok(said) => said,
            Err(SetupError::NoAnswer { .. }) if read_at != node => {
                return Err(if answer(self.direction(node, timeout))?.is_some() {
                    SetupError::IdNotTaken {
                        bus: self.bus().to_string(),
                        node,
                        to: read_at,
                    }
                } else {
                    unanswered(None).unwrap_or(SetupError::IdLost {
                        bus: self.bus().to_string(),
                        node,
                        to: read_at,
                    })
                });
            }
            Err(e @ SetupError::NoAnswer { .. }) => return Err(unanswered(None).unwrap_or(e)),
            Err(e) => return Err(e),
        };
        if let Some(s) = said
            && !change.agrees(&s)
        {
            return Err(unanswered(said).unwrap_or(SetupError::NotTaken {
                bus: self.bus().to_string(),
                node,
                asked: *change,
                said: s,
            }));
        }
        Ok(Made {
            said,
            late: unanswered(said),
        })
    }

    /// What `node` now says of the setting `change` is about (`None` for the bit rate, which
    /// cannot be read at the old one). For a new node id: GetEscID answers from the new node
    /// (`node` is the new id); else `SetDirection` 255, `GetMajorConfig` or
    /// `SetReportingFrequency` read.
    pub fn read(
        &mut self,
        node: u8,
        change: &Change,
        timeout: Duration,
    ) -> Result<Option<Change>, SetupError> {
        Ok(Some(match *change {
            Change::NodeId { .. } => {
                self.ask_ids(true)?;
                let deadline = Instant::now() + timeout.max(ID_ANSWERS);
                self.listen_until(deadline, |h, _| {
                    h.node(node).is_some_and(|n| !n.channels.is_empty())
                })?;
                // GetMajorConfig's channel if no GetEscID answer came (a receiver may take
                // the request for a repeat of an earlier run's, whose transfer id it had).
                let channel = match self.heard.node(node).and_then(|n| n.channels.last()) {
                    Some(&c) => c,
                    None => self.major_config(node, timeout)?.throttle_channel,
                };
                Change::NodeId {
                    node_id: node,
                    channel,
                }
            }
            Change::Direction(_) => Change::Direction(self.direction(node, timeout)?),
            Change::ThrottleSource(_) => {
                let c = self.major_config(node, timeout)?;
                Change::ThrottleSource(ThrottleSource::from_pwm(c.throttle_source))
            }
            Change::Led(_) => {
                let c = self.major_config(node, timeout)?;
                // Whether it was saved, the ESC cannot say.
                Change::Led(Led {
                    color: c.led_color,
                    blink: c.led_status,
                    save: false,
                })
            }
            Change::Rate { message, .. } => Change::Rate {
                message,
                code: self.rate(node, message, timeout)?,
            },
            Change::Bitrate(_) => return Ok(None),
        }))
    }

    /// Lists the ESCs on the bus (after [`Client::listen_first`]): listens (asking for ids
    /// while no motor turns) until no new node came for 0.5 s
    /// (at least 0.5 s, at most `listen`), then asks each node heard its direction, major
    /// configuration, maintenance counters and StatusMsg3 rate, `timeout` each, unless a motor
    /// turns ([`Survey::asked`]).
    pub fn survey(&mut self, listen: Duration, timeout: Duration) -> Result<Survey, SetupError> {
        let start = Instant::now();
        self.ask_ids(true)?;
        let mut known = 0;
        let mut last_new = start;
        loop {
            let now = Instant::now();
            let n = self.heard.nodes().count();
            if n != known {
                (known, last_new) = (n, now);
            }
            if now - start >= listen
                || (now - start >= SURVEY_QUIET && now - last_new >= SURVEY_QUIET)
            {
                break;
            }
            self.ask_ids(false)?;
            self.poll((start + listen).saturating_duration_since(now))?;
        }
        let nodes: Vec<u8> = self.heard.nodes().map(|n| n.node).collect();
        let mut escs = Vec::new();
        let mut asked = true;
        for node in nodes {
            // Nothing is asked while a motor turns (GetEscID and queries can make ESCs
            // stutter), nor of a node that is no ESC.
            asked &= !self.heard.nodes().any(|n| n.turning() || n.turning_now());
            let esc = self
                .heard
                .node(node)
                .is_some_and(|n| n.is_esc() || !n.channels.is_empty());
            let direction = if asked && esc {
                answer(self.direction(node, timeout))?
            } else {
                None
            };
            // A node that does not answer one does not answer the others: not asked again.
            let (config, maintenance, msg3_rate) = if direction.is_some() {
                (
                    answer(self.major_config(node, timeout))?,
                    answer(self.maintenance(node, timeout))?,
                    answer(self.rate(node, StatusMessage::Msg3, timeout))?,
                )
            } else {
                (None, None, None)
            };
            let Some(heard) = self.heard.node(node).cloned() else {
                continue;
            };
            escs.push(EscSurvey {
                heard,
                direction,
                config,
                maintenance,
                msg3_rate,
            });
        }
        Ok(Survey {
            escs,
            asked,
            elapsed: start.elapsed(),
        })
    }
}

/// A transfer id to start from, from the clock: a receiver that drops a message whose
/// transfer id is its sender's previous one (as a repeat) would otherwise drop the first
/// request of every run after one that sent a single request.
fn first_transfer_id() -> u8 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| (d.subsec_nanos() >> 10) as u8 & 31)
}

/// An answer, `None` if the node did not give one in time; other errors as they are.
fn answer<T>(r: Result<T, SetupError>) -> Result<Option<T>, SetupError> {
    match r {
        Ok(v) => Ok(Some(v)),
        Err(SetupError::NoAnswer { .. }) => Ok(None),
        Err(e) => Err(e),
    }
}
