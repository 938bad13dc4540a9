//! One virtual Hobbywing DroneCAN ESC: its settings (node id, throttle channel, direction,
//! throttle source, LED, message rates, bit rate), the messages it sends made from the physical
//! model, and its answers to the setup services.

use std::rc::Rc;

use hwfoc::Status;
use hwfoc::dronecan::{
    GetEscId, GetMaintenanceInformationResponse, GetMajorConfigResponse, Kind, Message, NodeStatus,
    SelfTestResponse, SetBaudRequest, SetBaudResponse, SetDirectionResponse, SetIdResponse,
    SetLedResponse, SetReportingFrequencyRequest, SetReportingFrequencyResponse,
    SetThrottleSourceResponse, StatusMsg1, StatusMsg2, StatusMsg3,
};

use crate::esc::{drive, seconds};
use crate::faults::FaultSchedule;
use crate::model::{Model, ModelConfig};
use crate::profile::Profile;
use crate::rng::{Purpose, Rng};

/// The bit rate every ESC leaves the factory with, bit/s.
pub const FACTORY_BITRATE: u32 = 500_000;
/// The node id every ESC leaves the factory with.
pub const FACTORY_NODE: u8 = 1;
/// The node id of ESC 0 when the bus is set up (not `--factory`): ESC `i` is node
/// `FIRST_NODE + i`, throttle channel `i + 1`, so that node and channel never coincide.
pub const FIRST_NODE: u8 = 10;
/// The largest throttle channel: `GetMajorConfig` carries it in 6 bits.
pub const MAX_CHANNEL: u8 = 63;
/// Rate codes (`SetReportingFrequency`: 1..9 = 500, 250, 200, 100, 50, 20, 10, 1, 0 Hz) of
/// StatusMsg1, StatusMsg2 and StatusMsg3 by default: 50 Hz, 50 Hz, 10 Hz.
pub const DEFAULT_RATES: [u8; 3] = [5, 5, 7];
/// `uavcan.protocol.NodeStatus` interval, ns (1 Hz, as DroneCAN asks).
pub const NODE_STATUS_NS: u64 = 1_000_000_000;
/// The start of the run in which an ESC sends no message of its own, ns (5 ms, a choice): a
/// controller's GetEscID request at time zero ([`ANSWER_NS`](super::ANSWER_NS) to answer, up
/// to 63 answers of about 0.2 ms) is answered before any status message, so that a log's ESCs
/// are numbered by their throttle channel from their first record.
pub const QUIET_START_NS: u64 = 5_000_000;
/// Priority of the ESC's broadcasts (status messages, GetEscID answers, NodeStatus): 16,
/// DroneCAN's "medium" (a choice: Hobbywing documents none). A service response has its
/// request's priority.
pub const PRIORITY: u8 = 16;
/// LED colour (`SetLED`'s R=4, G=2, B=1 bits) and blink code (0 off, 1, 2, 5 Hz) by default.
pub const DEFAULT_LED: (u8, u8) = (2, 0);

/// The messages an ESC sends by itself, each on its own schedule and transfer id counter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// `com.hobbywing.esc.StatusMsg1`: rpm, pwm, status.
    Msg1 = 0,
    /// `com.hobbywing.esc.StatusMsg2`: voltage, current, temperature.
    Msg2 = 1,
    /// `com.hobbywing.esc.StatusMsg3`: MOSFET, capacitor, motor temperatures.
    Msg3 = 2,
    /// `uavcan.protocol.NodeStatus`, once a second.
    NodeStatus = 3,
}

impl Stream {
    /// Every stream.
    pub const ALL: [Stream; 4] = [Stream::Msg1, Stream::Msg2, Stream::Msg3, Stream::NodeStatus];

    /// The data type it sends.
    pub const fn kind(self) -> Kind {
        match self {
            Stream::Msg1 => Kind::StatusMsg1,
            Stream::Msg2 => Kind::StatusMsg2,
            Stream::Msg3 => Kind::StatusMsg3,
            Stream::NodeStatus => Kind::NodeStatus,
        }
    }

    /// The status message whose data type id is `msg_id` (`SetReportingFrequency`'s `MSG_ID`).
    pub fn of_msg_id(msg_id: u16) -> Option<Stream> {
        [Stream::Msg1, Stream::Msg2, Stream::Msg3]
            .into_iter()
            .find(|s| s.kind().data_type_id() == msg_id)
    }
}

/// The interval of rate code `code` (1..9), ns; `None` for 0 Hz (and codes outside 1..9).
pub fn rate_interval_ns(code: u8) -> Option<u64> {
    let hz = *SetReportingFrequencyRequest::RATES_HZ.get(usize::from(code).checked_sub(1)?)?;
    (hz > 0).then(|| 1_000_000_000 / u64::from(hz))
}

/// What an ESC is set to: what the setup services change.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EscConfig {
    /// DroneCAN node id (1..127).
    pub node_id: u8,
    /// Throttle channel, 1-based (1..[`MAX_CHANNEL`]).
    pub throttle_channel: u8,
    /// Turning counter-clockwise (`SetDirection` 1; StatusMsg1's status bit 14).
    pub ccw: bool,
    /// Throttle source: 0 CAN, 1 PWM (the simulator's throttle is the profile either way).
    pub throttle_source: u8,
    /// LED colour bits (R=4, G=2, B=1).
    pub led_color: u8,
    /// LED blink code (0 off, 1, 2, 5 Hz).
    pub led_blink: u8,
    /// Rate codes of StatusMsg1, StatusMsg2, StatusMsg3 (1..9).
    pub rates: [u8; 3],
    /// CAN bit rate, bit/s.
    pub bitrate: u32,
}

impl EscConfig {
    /// As it leaves the factory: node 1, throttle channel 1, clockwise, CAN throttle,
    /// 500 kbit/s, the default rates and LED.
    pub const FACTORY: EscConfig = EscConfig {
        node_id: FACTORY_NODE,
        throttle_channel: 1,
        ccw: false,
        throttle_source: 0,
        led_color: DEFAULT_LED.0,
        led_blink: DEFAULT_LED.1,
        rates: DEFAULT_RATES,
        bitrate: FACTORY_BITRATE,
    };

    /// ESC `index` of a bus already set up: node [`FIRST_NODE`]` + index`, throttle channel
    /// `index + 1`, directions alternating as on a multirotor (even ESCs clockwise).
    pub fn set_up(index: usize) -> EscConfig {
        EscConfig {
            node_id: FIRST_NODE.saturating_add(index.min(117) as u8),
            throttle_channel: (index + 1).min(usize::from(MAX_CHANNEL)) as u8,
            ccw: index % 2 == 1,
            ..EscConfig::FACTORY
        }
    }
}

/// A message the ESC sends now, with its priority, transfer id, and destination (for a
/// service response).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outgoing {
    /// Priority (0 highest .. 31).
    pub priority: u8,
    /// Source node.
    pub source: u8,
    /// Destination node of a response (0 for a broadcast).
    pub destination: u8,
    /// Transfer id (5 bits).
    pub transfer_id: u8,
    /// The message.
    pub message: Message,
}

/// Everything a CAN ESC is made from, besides its settings.
#[derive(Debug, Clone)]
pub struct CanSetup {
    /// Index of the ESC on the bus.
    pub index: usize,
    /// The run's seed.
    pub seed: u64,
    /// Motor, battery, ESC.
    pub model: ModelConfig,
    /// The throttle command.
    pub profile: Rc<Profile>,
    /// How far it runs behind the profile, seconds ([`crate::esc::spread`]).
    pub lag_s: f64,
    /// Its share of the load ([`crate::esc::spread`]).
    pub load: f64,
    /// Injected faults.
    pub faults: FaultSchedule,
    /// Its settings at time zero.
    pub config: EscConfig,
}

/// One virtual Hobbywing CAN ESC.
#[derive(Debug, Clone)]
pub struct CanEsc {
    setup: CanSetup,
    config: EscConfig,
    model: Model,
    model_ns: u64,
    noise: Rng,
    /// Next transfer id of each [`Stream`], then of its GetEscID answers.
    transfer_ids: [u8; 5],
    /// When each [`Stream`] is next due, ns (`None`: not sent).
    due_ns: [Option<u64>; 4],
    /// Minutes of rotation before the run, and since the last maintenance.
    total_min0: u32,
    since_min0: u32,
    /// Nanoseconds the motor turned during the run, in all and since a clear.
    turned_ns: u64,
    turned_since_clear_ns: u64,
    cleared: bool,
}

impl CanEsc {
    /// An ESC at rest at time zero; its first messages come at a random phase within their
    /// first interval, past [`QUIET_START_NS`].
    pub fn new(setup: CanSetup) -> CanEsc {
        let (model, mut params) = Model::for_esc(setup.model, setup.load, setup.seed, setup.index);
        let mut due_ns = [None; 4];
        for s in Stream::ALL {
            let interval = match s {
                Stream::NodeStatus => Some(NODE_STATUS_NS),
                s => rate_interval_ns(setup.config.rates[s as usize]),
            };
            due_ns[s as usize] = interval.map(|i| match i.checked_sub(QUIET_START_NS) {
                Some(rest) if rest > 0 => QUIET_START_NS + params.below(rest),
                _ => params.below(i),
            });
        }
        let total_min0 = 100 + params.below(20_000) as u32;
        let since_min0 = params.below(u64::from(total_min0)) as u32;
        CanEsc {
            noise: Rng::for_esc(setup.seed, setup.index, Purpose::Noise),
            config: setup.config,
            model,
            model_ns: 0,
            transfer_ids: [0; 5],
            due_ns,
            total_min0,
            since_min0,
            turned_ns: 0,
            turned_since_clear_ns: 0,
            cleared: false,
            setup,
        }
    }

    /// The ESC's index on the bus.
    pub fn index(&self) -> usize {
        self.setup.index
    }

    /// What it is set to now.
    pub fn config(&self) -> &EscConfig {
        &self.config
    }

    /// When its next own message is due, ns, and which.
    pub fn next_due(&self) -> Option<(u64, Stream)> {
        Stream::ALL
            .into_iter()
            .filter_map(|s| self.due_ns[s as usize].map(|t| (t, s)))
            .min_by_key(|&(t, s)| (t, s as usize))
    }

    /// Runs the model to `t_ns`, counting the time the motor turned.
    fn advance_to(&mut self, t_ns: u64) {
        if t_ns <= self.model_ns {
            return;
        }
        let from = self.model_ns;
        let s = &self.setup;
        drive(
            &mut self.model,
            &mut self.model_ns,
            t_ns,
            (&s.profile, s.lag_s, &s.faults),
        );
        if self.model.spinning() {
            self.turned_ns += t_ns - from;
            self.turned_since_clear_ns += t_ns - from;
        }
    }

    fn next_transfer_id(&mut self, slot: usize) -> u8 {
        let t = self.transfer_ids[slot];
        self.transfer_ids[slot] = (t + 1) & 31;
        t
    }

    fn broadcast(&mut self, slot: usize, message: Message) -> Outgoing {
        Outgoing {
            priority: PRIORITY,
            source: self.config.node_id,
            destination: 0,
            transfer_id: self.next_transfer_id(slot),
            message,
        }
    }

    /// Sends `stream`'s message due at `t_ns` (the time [`CanEsc::next_due`] gave) and
    /// schedules the next.
    pub fn emit(&mut self, stream: Stream, t_ns: u64) -> Outgoing {
        self.advance_to(t_ns);
        let injected = self.setup.faults.status_at(seconds(t_ns));
        let m = self.model.measure(injected, &mut self.noise);
        let byte = |x: f64| x.round().clamp(0.0, 255.0) as u8;
        let tenths = |x: f64| (x * 10.0).round().clamp(-32768.0, 32767.0) as i16;
        let message = match stream {
            Stream::Msg1 => Message::from(StatusMsg1 {
                rpm: (m.erpm / f64::from(self.setup.model.pole_pairs.max(1)))
                    .round()
                    .clamp(0.0, 65535.0) as u16,
                pwm: (m.throttle_out_pct * 10.0).round().clamp(0.0, 1000.0) as u16,
                status: if self.config.ccw {
                    StatusMsg1::STATUS_CCW
                } else {
                    0
                },
            }),
            Stream::Msg2 => Message::from(StatusMsg2 {
                input_voltage: tenths(m.voltage_v),
                current: tenths(m.current_a),
                temperature: byte(m.mos_c),
            }),
            Stream::Msg3 => Message::from(StatusMsg3 {
                mos_t: byte(m.mos_c),
                cap_t: byte(m.cap_c),
                motor_t: byte(motor_c(m.ambient_c, m.mos_c)),
            }),
            Stream::NodeStatus => Message::from(NodeStatus {
                uptime_sec: (t_ns / 1_000_000_000) as u32,
                health: if m.status == Status::OK { 0 } else { 1 },
                mode: 0,
                sub_mode: 0,
                vendor_specific_status_code: 0,
            }),
        };
        let interval = match stream {
            Stream::NodeStatus => Some(NODE_STATUS_NS),
            s => rate_interval_ns(self.config.rates[s as usize]),
        };
        self.due_ns[stream as usize] = interval.map(|i| t_ns + i);
        self.broadcast(stream as usize, message)
    }

    /// Its answer to a GetEscID request (`[0]`): a GetEscID broadcast of
    /// `[node_id, throttle_channel]`.
    pub fn answer_get_esc_id(&mut self) -> Outgoing {
        let answer = GetEscId::answer(self.config.node_id, self.config.throttle_channel);
        self.broadcast(4, answer.into())
    }

    /// Serves a setup service request received at `t_ns` (the ESC is its destination): the
    /// response, and the settings changed. `None` for a request it does not answer (SetAngle,
    /// and any response or message).
    pub fn serve(&mut self, t_ns: u64, request: &Message) -> Option<Message> {
        self.advance_to(t_ns);
        let c = &mut self.config;
        Some(match *request {
            Message::SetIdRequest(r) => {
                if (1..=127).contains(&r.node_id) && (1..=MAX_CHANNEL).contains(&r.throttle_channel)
                {
                    c.node_id = r.node_id;
                    c.throttle_channel = r.throttle_channel;
                }
                SetIdResponse {
                    node_id: c.node_id,
                    throttle_channel: c.throttle_channel,
                }
                .into()
            }
            Message::SetBaudRequest(r) => {
                if let Some(&b) = SetBaudRequest::BITRATES.get(usize::from(r.baud)) {
                    c.bitrate = b;
                }
                SetBaudResponse {}.into()
            }
            Message::SetLedRequest(r) => {
                if r.color <= 7 && matches!(r.blink, 0 | 1 | 2 | 5) {
                    (c.led_color, c.led_blink) = (r.color, r.blink);
                }
                SetLedResponse {
                    option: r.option,
                    color: c.led_color,
                    blink: c.led_blink,
                }
                .into()
            }
            Message::SetDirectionRequest(r) => {
                if r.direction <= 1 {
                    c.ccw = r.direction == 1;
                }
                SetDirectionResponse {
                    direction: u8::from(c.ccw),
                }
                .into()
            }
            Message::SetReportingFrequencyRequest(r) => {
                let stream = Stream::of_msg_id(r.msg_id);
                let rate = match stream {
                    Some(s) => {
                        if r.option == 1 && (1..=9).contains(&r.rate) {
                            c.rates[s as usize] = r.rate;
                            self.due_ns[s as usize] = rate_interval_ns(r.rate).map(|i| t_ns + i);
                        }
                        self.config.rates[s as usize]
                    }
                    None => 9,
                };
                SetReportingFrequencyResponse {
                    option: r.option,
                    msg_id: r.msg_id,
                    rate,
                }
                .into()
            }
            Message::SetThrottleSourceRequest(r) => {
                if r.source <= 1 {
                    c.throttle_source = r.source;
                }
                SetThrottleSourceResponse {
                    source: c.throttle_source,
                }
                .into()
            }
            Message::SelfTestRequest(_) => {
                let injected = self.setup.faults.status_at(seconds(t_ns));
                let fail = self.model.spinning() || injected != Status::OK;
                SelfTestResponse {
                    status: u8::from(fail),
                }
                .into()
            }
            Message::GetMaintenanceInformationRequest(r) => {
                if r.option == 1 {
                    self.cleared = true;
                    self.turned_since_clear_ns = 0;
                }
                let (total, since) = self.maintenance_min();
                GetMaintenanceInformationResponse {
                    total_rotation_time_min: total,
                    time_since_maintenance_min: since,
                }
                .into()
            }
            Message::GetMajorConfigRequest(_) => GetMajorConfigResponse {
                direction: c.ccw,
                throttle_source: c.throttle_source == 1,
                throttle_channel: c.throttle_channel,
                led_status: c.led_blink,
                led_color: c.led_color,
                msg2_rate: c.rates[1],
                msg1_rate: c.rates[0],
                positioning_angle: 0,
                reserved: [0, 0],
            }
            .into(),
            _ => return None,
        })
    }

    /// Total minutes of rotation and minutes since the last maintenance (a clear), counting
    /// the minutes before the run (drawn from the seed) and the time the motor turned since.
    pub fn maintenance_min(&self) -> (u32, u32) {
        let min = |ns: u64| (ns / 60_000_000_000) as u32;
        let total = self.total_min0.saturating_add(min(self.turned_ns));
        let since = if self.cleared {
            min(self.turned_since_clear_ns)
        } else {
            self.since_min0.saturating_add(min(self.turned_ns))
        };
        (total, since.min((1 << 24) - 1))
    }
}

/// The motor's temperature, degC: ambient plus 0.8 of the MOSFETs' rise (the model has no
/// winding; as the HW5 simulation does).
fn motor_c(ambient_c: f64, mos_c: f64) -> f64 {
    ambient_c + 0.8 * (mos_c - ambient_c)
}
