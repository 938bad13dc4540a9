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

use super::SetupError;
use super::heard::{Heard, NodeHeard};
use super::values::{Change, Direction, Led, StatusMessage, ThrottleSource};
use crate::can::{ASK_EVERY, ASK_PRIORITY, CanBus, CanError};

/// Priority of hwfoc's service requests: 16, DroneCAN's "medium" (pydronecan's and
/// ArduPilot's default).
pub const REQUEST_PRIORITY: u8 = 16;
/// The shortest listen of the safety check.
const IDLE_MIN: Duration = Duration::from_millis(100);
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
/// turns before a change ([`Client::check_idle`]), and calls a service of one node,
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
        if self.heard.any_turning()
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

    /// The safety check before a change: listens until every node heard has sent two
    /// StatusMsg1 (a whole period; at least 100 ms, at most 2.2 s), then refuses if any of
    /// them said rpm or pwm above 0.
    pub fn check_idle(&mut self) -> Result<(), SetupError> {
        let start = Instant::now();
        self.heard.start_window();
        self.listen_until(start + IDLE_MAX, |h, now| {
            now - start >= IDLE_MIN && h.nodes().all(|n| n.window_status1 >= 2)
        })?;
        match self.heard.nodes().find(|n| n.turning()) {
            Some(n) => Err(SetupError::Turning {
                bus: self.bus().to_string(),
                node: n.node,
                rpm: n.window_max.0,
                pwm: n.window_max.1,
            }),
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
            direction: Direction::QUERY,
        };
        self.ask(node, r, timeout, |m| match m {
            Message::SetDirectionResponse(r) => Some(Direction::from_ccw(r.direction == 1)),
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
        let r = GetMaintenanceInformationRequest { option: 0 };
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
            option: 0,
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
            Change::Led(asked) => {
                let c = self.major_config(node, timeout)?;
                Change::Led(Led {
                    color: c.led_color,
                    blink: c.led_status,
                    save: asked.save,
                })
            }
            Change::Rate { message, .. } => Change::Rate {
                message,
                code: self.rate(node, message, timeout)?,
            },
            Change::Bitrate(_) => return Ok(None),
        }))
    }

    /// Lists the ESCs on the bus: listens (asking for ids) until no new node came for 0.5 s
    /// (at least 0.5 s, at most `listen`), then asks each node heard its direction, major
    /// configuration, maintenance counters and StatusMsg3 rate, `timeout` each.
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
        for node in nodes {
            let direction = answer(self.direction(node, timeout))?;
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
