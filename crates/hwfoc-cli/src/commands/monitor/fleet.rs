//! What the monitor knows about each ESC: the latest frame, peaks, the last minute, the link,
//! alarms and the alarm log. No terminal here: the dashboard and the headless printers only
//! read it.

use std::collections::{BTreeMap, HashMap, VecDeque};

use hwfoc::Settings;
use hwfoc::format::LinkKind;
use hwfoc::telemetry::Info;
use hwfoc_io::{LinkStats, WireKind};
use hwfoc_ports::can::{CanSpec, is_can_spec};

use super::alarms::{Change, FaultBit, Kind, Latch, Level, Threshold};
use super::config::Limits;
use crate::shown::{self, Shown, Values};
use hwfoc_io::Handler;
use hwfoc_io::InputError;
use hwfoc_io::PortStreams;
use hwfoc_io::SettingsMap;
use hwfoc_io::energy::Energy;
use hwfoc_io::record::Record;
use hwfoc_ports::serial::{Baud, PortEvent};

/// Seconds of history kept for the charts.
pub const HISTORY_S: f64 = 60.0;
/// At most this many samples per ESC (a minute at 20 frames/s is 1200).
const HISTORY_MAX: usize = 2048;
/// Alarm log entries kept (the oldest go first).
const LOG_MAX: usize = 1000;
/// The window over which the frame rate is measured, seconds.
const RATE_WINDOW_S: f64 = 2.0;
/// Highest plausible voltage of one LiPo cell, for detecting the number of cells.
const FULL_CELL_V: f64 = 4.35;

/// One point of an ESC's history.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Receive time, Unix seconds.
    pub t: f64,
    /// The values of the quantities shown, by [`Shown::index`] (NaN: none).
    pub values: Values,
}

impl Sample {
    /// The value of `q`, if the frame had one.
    pub fn get(&self, q: Shown) -> Option<f32> {
        let v = self.values[q.index()];
        (!v.is_nan()).then_some(v)
    }
}

/// Extremes since the start or the last reset.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Peaks {
    /// Highest mechanical RPM.
    pub rpm: Option<f32>,
    /// Highest input current, A.
    pub current_a: Option<f32>,
    /// Highest phase current, A.
    pub phase_current_a: Option<f32>,
    /// Lowest input voltage, V.
    pub min_voltage_v: Option<f32>,
    /// Highest MOSFET temperature, degC.
    pub mos_temp_c: Option<f32>,
    /// Highest capacitor temperature, degC.
    pub cap_temp_c: Option<f32>,
}

impl Peaks {
    fn add(&mut self, r: &Record) {
        fn max(slot: &mut Option<f32>, v: Option<f32>) {
            if let Some(v) = v {
                *slot = Some(slot.map_or(v, |s| s.max(v)));
            }
        }
        max(&mut self.rpm, r.rpm);
        max(&mut self.current_a, r.current_a);
        max(&mut self.phase_current_a, r.phase_current_a);
        max(&mut self.mos_temp_c, r.mos_temp_c);
        max(&mut self.cap_temp_c, r.cap_temp_c);
        if let Some(v) = r.voltage_v {
            self.min_voltage_v = Some(self.min_voltage_v.map_or(v, |s| s.min(v)));
        }
    }
}

/// What one port event brought, in order.
#[derive(Default)]
struct Received(Vec<Item>);

enum Item {
    Record(Record),
    Info(Option<f64>, Info),
}

impl Handler for Received {
    type Error = InputError;

    fn record(&mut self, record: &Record) {
        self.0.push(Item::Record(*record));
    }

    fn info(&mut self, _: u8, t: Option<f64>, info: &Info) {
        self.0.push(Item::Info(t, *info));
    }
}

/// Whether the port of an ESC is there.
#[derive(Debug, Clone, PartialEq)]
pub enum Link {
    /// Open (frames may or may not be coming).
    Up,
    /// Gone since this Unix time; the reason the system gave.
    Down {
        /// Unix seconds.
        since: f64,
        /// What the operating system said.
        reason: String,
    },
}

/// The alarms of one ESC.
#[derive(Debug, Clone, Default)]
pub struct Alarms {
    /// One per bit of the fault word, in bit order.
    pub faults: [Latch; 16],
    /// The protocol whose fault word those bits are (that of the last record; HW-FOC's
    /// before one).
    pub protocol: Option<hwfoc::Protocol>,
    /// MOSFET temperature.
    pub mos: Latch,
    /// Capacitor temperature.
    pub cap: Latch,
    /// Low voltage.
    pub voltage: Latch,
    /// No frames.
    pub stale: Latch,
    /// Port gone.
    pub disconnected: Latch,
}

impl Alarms {
    /// The latch of `kind`.
    pub fn latch(&self, kind: Kind) -> &Latch {
        match kind {
            Kind::Fault(f) => &self.faults[usize::from(f.bit) % 16],
            Kind::MosTemp => &self.mos,
            Kind::CapTemp => &self.cap,
            Kind::LowVoltage => &self.voltage,
            Kind::Stale => &self.stale,
            Kind::Disconnected => &self.disconnected,
        }
    }

    /// The active alarms, worst first.
    pub fn active(&self) -> Vec<(Kind, Level)> {
        let protocol = self.protocol.unwrap_or(hwfoc::Protocol::HwFoc);
        let mut all: Vec<(Kind, Level)> = (0..16u8)
            .map(|bit| Kind::Fault(FaultBit { protocol, bit }))
            .chain([
                Kind::Disconnected,
                Kind::Stale,
                Kind::MosTemp,
                Kind::CapTemp,
                Kind::LowVoltage,
            ])
            .filter_map(|k| self.latch(k).level().map(|l| (k, l)))
            .collect();
        all.sort_by_key(|&(_, level)| std::cmp::Reverse(level));
        all
    }
}

/// What the monitor shows of one ESC.
#[derive(Debug, Clone)]
pub struct EscView {
    /// Its port (or `sim:escN`).
    pub name: String,
    /// Its label from the configuration, if any.
    pub label: Option<String>,
    /// The settings its frames are converted under.
    pub settings: Settings,
    /// Whether the port is there.
    pub link: Link,
    /// The latest data frame.
    pub last: Option<Record>,
    /// Receive time of the latest frame of any kind, Unix seconds.
    pub last_frame_t: Option<f64>,
    /// Extremes since the start or the last reset.
    pub peaks: Peaks,
    /// Charge, energy and peak power since the start or the last reset.
    pub energy: Energy,
    /// The last minute.
    pub history: VecDeque<Sample>,
    /// The latest device-information frame.
    pub info: Option<Info>,
    /// Link statistics of its decoder.
    pub stats: LinkStats,
    /// Its port's baud rate: given, or found from the bytes; `None` while it is being found
    /// (and on a CAN bus).
    pub baud: Option<u32>,
    /// Its port, when it is a CAN bus (`slcan:`, `can:`).
    pub can: Option<CanSpec>,
    /// While the port's rate is being found: the rate tried.
    pub trying: Option<u32>,
    /// Bytes its port read at rates the search left (skipped, never decoded).
    pub discarded: u64,
    /// Battery cells: configured, or detected from the first voltage.
    pub cells: Option<u8>,
    /// Whether `cells` was detected rather than configured.
    pub cells_detected: bool,
    /// Its alarms.
    pub alarms: Alarms,
    /// Receive times of the frames of the last [`RATE_WINDOW_S`].
    recent: VecDeque<f64>,
    /// When watching started (for an ESC that never sends: stale from then on).
    started: f64,
    /// Its ESC number, the records' `esc` (a hub channel's, a CAN ESC's place on its bus):
    /// the port's own index until a frame says.
    pub number: usize,
}

impl EscView {
    /// Data frames per second over the last two seconds at time `now`.
    pub fn frame_rate(&self, now: f64) -> f64 {
        let n = self
            .recent
            .iter()
            .filter(|&&t| t > now - RATE_WINDOW_S)
            .count();
        n as f64 / RATE_WINDOW_S
    }

    /// Electrical input power of the latest frame, W.
    pub fn power_w(&self) -> Option<f64> {
        self.last
            .as_ref()
            .and_then(|r| Some(f64::from(r.voltage_v?) * f64::from(r.current_a?)))
    }

    /// Seconds since the latest frame, at `now`.
    pub fn age(&self, now: f64) -> Option<f64> {
        self.last_frame_t.map(|t| (now - t).max(0.0))
    }

    /// What to show for an ESC that has sent no data frame yet: nothing at all (is it powered,
    /// is the wire on RX?), bytes that never make a frame (baud rate? swapped wires?), or just
    /// not yet. On a CAN bus: no CAN frame, or error frames (the bus's bit rate?), or frames but
    /// no ESC status yet.
    pub fn waiting(&self) -> &'static str {
        if self.can.is_some() {
            let bus = self.stats.can().map(|c| c.bus).unwrap_or_default();
            return match (bus.frames(), bus.error_frames()) {
                (0, _) => "no CAN frame yet: bit rate? ESCs powered?",
                (_, 1..) => "error frames, no ESC status: the bus's bit rate?",
                _ => "CAN frames but no ESC status yet",
            };
        }
        match (self.stats.bytes(), self.stats.frames()) {
            (0, _) => "no bytes yet: ESC powered? telemetry wire on RX?",
            (bytes, 0) if bytes >= 64 => "bytes but no valid frame: baud rate? swapped wires?",
            _ => "no frames yet",
        }
    }

    /// The format of its frames: of the latest data frame, else of those its link counted;
    /// `None` before any frame.
    pub fn protocol(&self) -> Option<hwfoc::Protocol> {
        self.last.as_ref().map(|r| r.protocol).or_else(|| {
            (self.stats.frames() + self.stats.info_frames() > 0).then(|| self.stats.protocol())
        })
    }

    /// Its port's rate and format: `115200 baud (HW5)`, `19200 baud` before a frame, or
    /// `finding the baud rate: trying 115200`.
    pub fn rate_text(&self) -> String {
        match &self.can {
            Some(CanSpec::Slcan { bitrate, .. }) => {
                return format!("CAN {} kbit/s", bitrate / 1000);
            }
            Some(CanSpec::SocketCan { .. }) => return "CAN".to_string(),
            None => {}
        }
        match (self.baud, self.trying) {
            (Some(baud), _) => match self.protocol() {
                Some(p) => format!("{baud} baud ({})", p.title()),
                None => format!("{baud} baud"),
            },
            (None, Some(baud)) => format!("finding the baud rate: trying {baud}"),
            (None, None) => "finding the baud rate".to_string(),
        }
    }

    /// Whether its format carries `q` (every one before the format is known).
    pub fn carries(&self, q: Shown) -> bool {
        self.protocol().is_none_or(|p| q.carried_by(p))
    }

    /// Its link's figures as its format has them: packet loss where frames are numbered
    /// (`lost 0 dup 0`; HW5's are not), checksum failures where they have one (`crc 0`), or
    /// candidates rejected by plausibility (`rejected 0`: V3, V4), restarts where numbered.
    pub fn link_text(&self) -> String {
        let s = &self.stats;
        let mut parts = Vec::new();
        if s.counts_packets() {
            parts.push(format!(
                "lost {} dup {}",
                s.lost_packets(),
                s.duplicate_packets()
            ));
        }
        match s.rejected_candidates() {
            Some(rejected) => parts.push(format!("rejected {rejected}")),
            None => parts.push(format!("crc {}", s.checksum_failures())),
        }
        if s.counts_packets() {
            parts.push(format!("restarts {}", s.restarts()));
        }
        parts.join(" ")
    }

    /// The name to show: the label, or the port.
    pub fn title(&self) -> &str {
        self.label.as_deref().unwrap_or(&self.name)
    }
}

/// The row name of a CAN ESC: its bus (a SocketCAN interface; an SLCAN adapter's device), its
/// node and the throttle channel a GetEscID answer gave it (`can0 node 10 ch 2`). Its ESC number
/// stays the one it was first heard at.
fn can_name(spec: &CanSpec, node: Option<u8>, channel: Option<u8>) -> String {
    let bus = match spec {
        CanSpec::SocketCan { interface } => interface.as_str(),
        CanSpec::Slcan { port, .. } => port.strip_prefix("/dev/").unwrap_or(port),
    };
    let mut name = bus.to_string();
    if let Some(node) = node {
        name.push_str(&format!(" node {node}"));
    }
    if let Some(channel) = channel {
        name.push_str(&format!(" ch {channel}"));
    }
    name
}

/// One line of the alarm log.
#[derive(Debug, Clone, PartialEq)]
pub struct LogEntry {
    /// Unix seconds.
    pub t: f64,
    /// ESC index.
    pub esc: usize,
    /// The alarm.
    pub kind: Kind,
    /// What happened.
    pub change: Change,
    /// The alarm's level after the change (the level it had, for a clear).
    pub level: Level,
    /// The value that raised it (temperature, voltage), if any.
    pub value: Option<f64>,
}

impl LogEntry {
    /// What happened, in words: `mos_temp warning raised at 91.0 degC`,
    /// `mos_overheat critical raised`, `low_voltage escalated to critical at 19.7 V`,
    /// `stale warning cleared after 3.2 s` (a clear names the highest level of its episode).
    pub fn text(&self) -> String {
        let name = self.kind.name();
        let unit = match self.kind {
            Kind::MosTemp | Kind::CapTemp => " degC",
            Kind::LowVoltage => " V",
            _ => "",
        };
        let at = |v: Option<f64>| v.map_or(String::new(), |v| format!(" at {v:.1}{unit}"));
        match self.change {
            Change::Raised(level) => format!("{name} {level} raised{}", at(self.value)),
            Change::Escalated => format!("{name} escalated to critical{}", at(self.value)),
            Change::Cleared {
                level,
                duration_s,
                worst,
            } => {
                let worst = match (worst, self.kind) {
                    (Some(w), Kind::LowVoltage) => format!(" (lowest {w:.1}{unit})"),
                    (Some(w), _) => format!(" (highest {w:.1}{unit})"),
                    (None, _) => String::new(),
                };
                format!("{name} {level} cleared after {duration_s:.1} s{worst}")
            }
        }
    }

    /// `raised`, `escalated` or `cleared`.
    pub fn event(&self) -> &'static str {
        match self.change {
            Change::Raised(_) => "raised",
            Change::Escalated => "escalated",
            Change::Cleared { .. } => "cleared",
        }
    }
}

/// Charge and energy of `escs` together (and the largest peak power of one of them).
pub fn total_energy(escs: &[EscView]) -> Energy {
    let mut total = Energy::new();
    for esc in escs {
        total.merge(&esc.energy);
    }
    total
}

/// Electrical input power of the connected ones of `escs` together now, W: the sum of their
/// latest frames (`None` before any frame).
pub fn total_power_w(escs: &[EscView]) -> Option<f64> {
    escs.iter()
        .filter(|e| e.link == Link::Up)
        .filter_map(EscView::power_w)
        .fold(None, |sum, p| Some(sum.unwrap_or(0.0) + p))
}

/// Every ESC watched, their decoders and the alarm log.
pub struct Fleet {
    /// What is shown of each ESC.
    pub escs: Vec<EscView>,
    /// The alarm log, oldest first.
    pub log: VecDeque<LogEntry>,
    /// What the ports' streams found that a person should be told (two CAN ESCs on one
    /// throttle channel), not shown yet.
    pub notices: Vec<hwfoc_io::Notice>,
    /// How many entries were ever logged (the log keeps the last [`LOG_MAX`]).
    pub logged: u64,
    /// Data frames decoded in all.
    pub frames: u64,
    /// Highest power of all ESCs together (the sum of their latest frames), W, since the start
    /// or the last reset.
    pub peak_total_w: Option<f64>,
    streams: PortStreams,
    limits: Limits,
    /// The port each ESC is read from (a DataLink hub's port has an ESC per channel heard).
    ports: Vec<usize>,
    /// The ESC shown for each channel heard of each port that turned out to be a DataLink hub.
    channels: HashMap<(usize, usize), usize>,
    /// Labels by ESC number (`[esc.N]`), for a hub's channels and a bus's ESCs.
    esc_labels: BTreeMap<usize, String>,
    /// Each port's own label (by flag or port name), for its channels with no label by number.
    port_labels: Vec<Option<String>>,
}

impl Fleet {
    /// ESCs read from the ports `names` (labels beside them), their frames converted under
    /// `settings` (by port name and ESC number, a hub's channels included), watched from Unix
    /// time `now`, their bytes arriving at `baud` (at [`Baud::Auto`], found by each port).
    pub fn new(
        names: Vec<(String, Option<String>)>,
        settings: SettingsMap,
        limits: Limits,
        baud: Baud,
        now: f64,
    ) -> Fleet {
        let mut streams = PortStreams::with_map(
            baud.initial(),
            names.iter().map(|(name, _)| name.clone()).collect(),
            settings,
        );
        if baud == Baud::Auto {
            streams.auto_baud();
        }
        let escs = names
            .into_iter()
            .enumerate()
            .map(|(i, (name, label))| EscView {
                can: is_can_spec(&name)
                    .then(|| CanSpec::parse(&name).ok())
                    .flatten(),
                name,
                label,
                settings: u8::try_from(i)
                    .ok()
                    .and_then(|i| streams.settings_of(i))
                    .copied()
                    .unwrap_or(Settings::DEFAULT),
                link: Link::Up,
                last: None,
                last_frame_t: None,
                peaks: Peaks::default(),
                energy: Energy::new(),
                history: VecDeque::new(),
                info: None,
                stats: LinkStats::default(),
                baud: baud.fixed(),
                trying: (baud == Baud::Auto).then_some(baud.initial()),
                discarded: 0,
                cells: limits.cells,
                cells_detected: false,
                alarms: Alarms::default(),
                recent: VecDeque::new(),
                started: now,
                number: i,
            })
            .collect::<Vec<_>>();
        Fleet {
            streams,
            ports: (0..escs.len()).collect(),
            channels: HashMap::new(),
            esc_labels: BTreeMap::new(),
            port_labels: Vec::new(),
            escs,
            log: VecDeque::new(),
            notices: Vec::new(),
            logged: 0,
            frames: 0,
            peak_total_w: None,
            limits,
        }
    }

    /// Labels a hub's channels and a bus's ESCs by their ESC number (`by_esc`), else by their
    /// port's own label (`by_port`, one per port).
    pub fn set_labels(&mut self, by_esc: BTreeMap<usize, String>, by_port: Vec<Option<String>>) {
        self.esc_labels = by_esc;
        self.port_labels = by_port;
    }

    /// Reads protocol `protocol` only, on every port (call it before the first event).
    pub fn force_protocol(&mut self, protocol: hwfoc::Protocol) {
        self.streams.force_protocol(protocol);
    }

    /// The alarm levels in force.
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// The baud rate of port `port`: given, or found; `None` while it is being found.
    pub fn port_baud(&self, port: usize) -> Option<u32> {
        self.streams.baud(port)
    }

    /// Takes in what a port (or a virtual ESC) reported; returns the number of data frames it
    /// completed.
    pub fn on_event(&mut self, event: &PortEvent) -> usize {
        match event {
            PortEvent::Data { port, .. } => {
                let port = *port;
                let mut got = Received::default();
                let Some(stats) = self.streams.feed(event, &mut got) else {
                    return 0;
                };
                self.notices.extend(self.streams.take_notices());
                // A hub's channels and a CAN bus's ESCs each have a view of their own.
                let hub = self.streams.stream(port).is_some_and(|s| {
                    s.layout() == LinkKind::Bus
                        || matches!(s.kind(), WireKind::Hub | WireKind::Mixed)
                });
                let mut data = 0;
                for item in got.0 {
                    match item {
                        Item::Record(r) => {
                            let i = if hub {
                                let channel = self.streams.channel_of(port, r.esc).unwrap_or(0);
                                self.channel_view(port, usize::from(channel), &r)
                            } else {
                                port
                            };
                            // Every frame of a port event has its receive time.
                            self.on_data(i, r.t_s.unwrap_or(0.0), r);
                            data += 1;
                        }
                        Item::Info(t, info) => {
                            let esc = &mut self.escs[port];
                            esc.info = Some(info);
                            esc.last_frame_t = t;
                        }
                    }
                }
                if hub {
                    if let Some(stream) = self.streams.stream(port) {
                        for (&(p, channel), &i) in &self.channels {
                            if p == port {
                                let view = &mut self.escs[i];
                                view.stats = stream.link(channel as u8);
                                if let (Some(spec), Some(c)) = (&view.can, view.stats.can()) {
                                    view.name = can_name(spec, c.node, c.throttle_channel);
                                }
                            }
                        }
                    }
                } else {
                    self.escs[port].stats = stats;
                }
                self.frames += data as u64;
                if data > 0 {
                    self.note_total_power();
                }
                data
            }
            PortEvent::Searching { port, baud, .. } => {
                self.streams.feed(event, &mut ());
                let discarded = self.streams.discarded(*port);
                for i in self.views_of(*port) {
                    let esc = &mut self.escs[i];
                    (esc.baud, esc.trying, esc.discarded) = (None, Some(*baud), discarded);
                }
                0
            }
            PortEvent::Found { port, baud, .. } => {
                self.streams.feed(event, &mut ());
                for i in self.views_of(*port) {
                    let esc = &mut self.escs[i];
                    (esc.baud, esc.trying) = (Some(*baud), None);
                }
                0
            }
            PortEvent::Lost { port, t_ns, reason } => {
                let t = *t_ns as f64 / 1e9;
                for port in self.views_of(*port) {
                    let port = &port;
                    let Some(esc) = self.escs.get_mut(*port) else {
                        continue;
                    };
                    // No current is assumed over the time the port was away.
                    esc.energy.break_here();
                    esc.link = Link::Down {
                        since: t,
                        reason: reason.clone(),
                    };
                    let change = esc.alarms.stale.clear(t);
                    self.note(*port, Kind::Stale, change, t, None);
                    let change =
                        self.escs[*port]
                            .alarms
                            .disconnected
                            .set(true, Level::Critical, 0.0, t);
                    self.note(*port, Kind::Disconnected, change, t, None);
                }
                0
            }
            PortEvent::Back { port, t_ns } => {
                let t = *t_ns as f64 / 1e9;
                for port in self.views_of(*port) {
                    let port = &port;
                    let Some(esc) = self.escs.get_mut(*port) else {
                        continue;
                    };
                    esc.link = Link::Up;
                    // Stale counts again from now: the ESC has a second to speak.
                    esc.started = t;
                    esc.last_frame_t = None;
                    let change = esc.alarms.disconnected.clear(t);
                    self.note(*port, Kind::Disconnected, change, t, None);
                }
                0
            }
        }
    }

    /// The ESCs shown for port `port`: the port's own, and one per DataLink channel heard.
    fn views_of(&self, port: usize) -> Vec<usize> {
        (0..self.escs.len())
            .filter(|&i| self.ports[i] == port)
            .collect()
    }

    /// The ESC shown for channel `channel` (ESC number `esc`) of the DataLink hub on `port`:
    /// the port's own ESC for the first channel heard, a new one (after all others) for each
    /// next channel; made with that ESC's settings.
    fn channel_view(&mut self, port: usize, channel: usize, r: &Record) -> usize {
        let esc = r.esc;
        if let Some(&i) = self.channels.get(&(port, channel)) {
            return i;
        }
        let taken = self.channels.keys().any(|&(p, _)| p == port);
        let name = self.escs[port]
            .name
            .split(" channel ")
            .next()
            .and_then(|n| n.split(" node ").next())
            .unwrap_or_default()
            .to_string();
        let i = if taken {
            let mut view = self.escs[port].clone();
            view.last = None;
            view.last_frame_t = None;
            view.peaks = Peaks::default();
            view.energy = Energy::new();
            view.history.clear();
            view.info = None;
            view.alarms = Alarms::default();
            view.recent.clear();
            self.escs.push(view);
            self.ports.push(port);
            self.escs.len() - 1
        } else {
            port
        };
        // A CAN ESC by its bus and node (named in full from its link: `can_name`).
        self.escs[i].label = self
            .esc_labels
            .get(&usize::from(esc))
            .or_else(|| self.port_labels.get(port).and_then(Option::as_ref))
            .cloned();
        self.escs[i].name = match r.node {
            Some(node) => format!("{name} node {node}"),
            None => format!("{name} channel {channel}"),
        };
        if let Some(settings) = self.streams.settings_of(esc) {
            self.escs[i].settings = *settings;
        }
        self.channels.insert((port, channel), i);
        i
    }

    fn on_data(&mut self, i: usize, t: f64, r: Record) {
        let limits = &self.limits;
        let esc = &mut self.escs[i];
        esc.number = usize::from(r.esc);
        esc.last = Some(r);
        esc.last_frame_t = Some(t);
        esc.peaks.add(&r);
        if let (Some(volts), Some(amps)) = (r.voltage_v, r.current_a) {
            esc.energy.add(Some(t), f64::from(volts), f64::from(amps));
        }
        esc.recent.push_back(t);
        while esc.recent.front().is_some_and(|&f| f <= t - RATE_WINDOW_S) {
            esc.recent.pop_front();
        }
        esc.history.push_back(Sample {
            t,
            values: shown::values(&r),
        });
        while esc.history.len() > HISTORY_MAX
            || esc.history.front().is_some_and(|s| s.t < t - HISTORY_S)
        {
            esc.history.pop_front();
        }
        if let Some(volts) = r.voltage_v.filter(|&v| esc.cells.is_none() && v > 2.0) {
            esc.cells = Some((f64::from(volts) / FULL_CELL_V).ceil().clamp(1.0, 255.0) as u8);
            esc.cells_detected = true;
        }

        let mut changes: Vec<(Kind, Option<Change>, Option<f64>)> = Vec::with_capacity(4);
        let a = &mut esc.alarms;
        changes.push((
            Kind::Stale,
            a.stale.set(false, Level::Warning, 0.0, t),
            None,
        ));
        // The bits of the record's fault word, named by its protocol (a Hobbywing CAN ESC's
        // status is no fault word).
        a.protocol = Some(r.protocol);
        let word = r.fault_word().unwrap_or_default();
        for bit in 0..16u8 {
            let fault = FaultBit {
                protocol: r.protocol,
                bit,
            };
            let on = word.0 & (1 << bit) != 0;
            let latch = &mut a.faults[usize::from(bit)];
            if on || latch.level().is_some() {
                let change = latch.set(on, Kind::fault_level(fault), limits.fault_hold_s, t);
                changes.push((Kind::Fault(fault), change, None));
            }
        }
        let mut threshold = |kind, latch: &mut Latch, th: &Threshold, v: Option<f32>| {
            if let Some(v) = v {
                let v = f64::from(v);
                changes.push((kind, latch.update(th, v, t), Some(v)));
            }
        };
        threshold(Kind::MosTemp, &mut a.mos, &limits.mos, r.mos_temp_c);
        threshold(Kind::CapTemp, &mut a.cap, &limits.cap, r.cap_temp_c);
        if let Some(cells) = esc.cells {
            let th = limits.voltage(cells);
            threshold(Kind::LowVoltage, &mut a.voltage, &th, r.voltage_v);
        }
        for (kind, change, value) in changes {
            self.note(i, kind, change, t, value);
        }
    }

    /// Checks the clocks at Unix time `now`: ESCs that went silent become stale.
    pub fn tick(&mut self, now: f64) {
        let stale_after = self.limits.stale_after_s;
        for i in 0..self.escs.len() {
            let esc = &mut self.escs[i];
            if esc.link != Link::Up {
                continue;
            }
            let since = esc.last_frame_t.unwrap_or(esc.started);
            if now - since > stale_after {
                let change = esc.alarms.stale.set(true, Level::Warning, 0.0, now);
                self.note(i, Kind::Stale, change, now, None);
            }
        }
    }

    fn note_total_power(&mut self) {
        if let Some(p) = self.total_power_w().map(hwfoc_io::energy::drawn_w) {
            self.peak_total_w = Some(self.peak_total_w.map_or(p, |peak| peak.max(p)));
        }
    }

    /// Forgets the peaks, the charge and the energy of every ESC (counting starts again from
    /// the latest frame).
    pub fn reset_peaks(&mut self) {
        self.peak_total_w = None;
        for esc in &mut self.escs {
            esc.peaks = Peaks::default();
            esc.energy = Energy::new();
            if let Some(r) = &esc.last {
                esc.peaks.add(r);
                let t = esc.last_frame_t.or(r.t_s);
                if let (Some(volts), Some(amps)) = (r.voltage_v, r.current_a) {
                    esc.energy.add(t, f64::from(volts), f64::from(amps));
                }
            }
        }
        self.note_total_power();
    }

    /// Charge and energy of all ESCs together.
    pub fn total_energy(&self) -> Energy {
        total_energy(&self.escs)
    }

    /// Electrical input power of all ESCs now, W: the sum of each one's latest frame (`None`
    /// before any frame).
    pub fn total_power_w(&self) -> Option<f64> {
        total_power_w(&self.escs)
    }

    fn note(&mut self, esc: usize, kind: Kind, change: Option<Change>, t: f64, value: Option<f64>) {
        let Some(change) = change else { return };
        let level = match change {
            Change::Raised(level) => level,
            Change::Escalated => Level::Critical,
            Change::Cleared { level, .. } => level,
        };
        if self.log.len() == LOG_MAX {
            self.log.pop_front();
        }
        self.log.push_back(LogEntry {
            t,
            esc,
            kind,
            change,
            level,
            value,
        });
        self.logged += 1;
    }

    /// The log entries after the first `seen` ever logged (those still kept).
    pub fn log_since(&self, seen: u64) -> impl Iterator<Item = &LogEntry> {
        let first_kept = self.logged - self.log.len() as u64;
        let skip = seen.saturating_sub(first_kept) as usize;
        self.log.iter().skip(skip)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commands::monitor::config::{MonitorSetup, Overrides};
    use hwfoc::Status;
    use hwfoc::foc::DataFrame;

    fn fleet(n: usize) -> Fleet {
        fleet_of((0..n).map(|i| format!("esc{i}")).collect())
    }

    /// A fleet of the ports `names`.
    fn fleet_of(names: Vec<String>) -> Fleet {
        let config = MonitorSetup::load(&Overrides {
            settings: crate::args::SettingsArgs {
                no_config: true,
                ..Default::default()
            },
            ..Overrides::default()
        })
        .unwrap();
        let names = names.into_iter().map(|n| (n, None)).collect();
        Fleet::new(
            names,
            config.settings,
            config.limits,
            Baud::Fixed(19_200),
            1000.0,
        )
    }

    fn frame(packet: u16, status: Status, mos_code: u8, volt_raw: u16) -> Vec<u8> {
        DataFrame {
            packet,
            status,
            mos_adc: mos_code,
            cap_adc: hwfoc::units::ADC_TABLE[30],
            voltage_raw: volt_raw,
            ..Default::default()
        }
        .encode()
        .to_vec()
    }

    fn data(port: usize, t: f64, bytes: Vec<u8>) -> PortEvent {
        PortEvent::Data {
            port,
            t_ns: (t * 1e9) as u64,
            bytes,
        }
    }

    fn names(fleet: &Fleet) -> Vec<String> {
        fleet
            .log
            .iter()
            .map(|e| {
                let what = match e.change {
                    Change::Raised(l) => format!("raised {l}"),
                    Change::Escalated => "escalated".to_string(),
                    Change::Cleared { .. } => "cleared".to_string(),
                };
                format!("esc{} {} {what}", e.esc, e.kind.name())
            })
            .collect()
    }

    #[test]
    fn frames_update_the_view_peaks_and_rate() {
        let mut f = fleet(2);
        let cool = hwfoc::units::ADC_TABLE[40];
        for k in 0..40u16 {
            let t = 1000.0 + f64::from(k) * 0.05;
            // 25.2 V is raw 252 (0.1 V units).
            assert_eq!(f.on_event(&data(1, t, frame(k, Status::OK, cool, 252))), 1);
        }
        let esc = &f.escs[1];
        assert_eq!(esc.last.unwrap().packet, Some(39));
        assert_eq!(esc.cells, Some(6));
        assert!(esc.cells_detected);
        assert!((esc.frame_rate(1001.95) - 20.0).abs() < 0.6);
        assert_eq!(esc.peaks.mos_temp_c, Some(40.0));
        assert_eq!(esc.history.len(), 40);
        assert!(f.escs[0].last.is_none());
        assert_eq!(f.frames, 40);
        assert!(f.log.is_empty(), "{:?}", names(&f));
    }

    #[test]
    fn a_fault_bit_is_logged_once_by_name_and_clears_after_the_hold() {
        let mut f = fleet(1);
        let cool = hwfoc::units::ADC_TABLE[40];
        let hot = Status::OK.with(hwfoc::Fault::MosOverheat);
        for k in 0..60u16 {
            let t = 1000.0 + f64::from(k) * 0.05;
            // On for frames 10..30, flickering off on every third.
            let status = if (10..30).contains(&k) && k % 3 != 0 {
                hot
            } else {
                Status::OK
            };
            f.on_event(&data(0, t, frame(k, status, cool, 252)));
        }
        assert_eq!(
            names(&f),
            [
                "esc0 mos_overheat raised critical",
                "esc0 mos_overheat cleared"
            ]
        );
        // The clear names the level the alarm had (critical), not a warning.
        assert_eq!(f.log[1].level, Level::Critical);
        assert!(
            f.log[1]
                .text()
                .starts_with("mos_overheat critical cleared after 1.4"),
            "{}",
            f.log[1].text()
        );
        // On from frame 10 (0.5 s), last on at frame 29 (1.45 s), cleared 0.5 s later.
        match f.log[1].change {
            Change::Cleared { duration_s, .. } => assert!((duration_s - 1.45).abs() < 1e-6),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn temperature_and_voltage_thresholds_raise_alarms() {
        let mut f = fleet(1);
        let temps = [40u8, 95, 110, 96, 80];
        for (k, &c) in temps.iter().enumerate() {
            let code = hwfoc::units::ADC_TABLE[usize::from(c)];
            // Voltage drops to 3.2 V per cell on the last frame (6S: 19.2 V).
            let volt = if k == 4 { 192 } else { 252 };
            f.on_event(&data(
                0,
                1000.0 + k as f64 * 0.05,
                frame(k as u16, Status::OK, code, volt),
            ));
        }
        assert_eq!(
            names(&f),
            [
                "esc0 mos_temp raised warning",
                "esc0 mos_temp escalated",
                "esc0 mos_temp cleared",
                "esc0 low_voltage raised critical"
            ]
        );
        assert_eq!(f.log[0].value, Some(95.0));
    }

    #[test]
    fn silence_makes_an_esc_stale_and_a_lost_port_disconnected() {
        let mut f = fleet(2);
        let cool = hwfoc::units::ADC_TABLE[40];
        f.on_event(&data(0, 1000.1, frame(0, Status::OK, cool, 252)));
        f.tick(1000.9);
        assert!(f.log.is_empty());
        f.tick(1001.2);
        // ESC 1 never sent anything: stale a second after the start; ESC 0 at 1.1 s.
        assert_eq!(
            names(&f),
            ["esc0 stale raised warning", "esc1 stale raised warning"]
        );
        f.tick(1001.5);
        assert_eq!(f.log.len(), 2, "stale is logged once");
        f.on_event(&data(0, 1001.6, frame(1, Status::OK, cool, 252)));
        assert_eq!(names(&f)[2], "esc0 stale cleared");

        f.on_event(&PortEvent::Lost {
            port: 1,
            t_ns: 1_002_000_000_000,
            reason: "EIO".into(),
        });
        assert!(matches!(f.escs[1].link, Link::Down { .. }));
        f.tick(1005.0);
        f.on_event(&PortEvent::Back {
            port: 1,
            t_ns: 1_006_000_000_000,
        });
        // Meanwhile ESC 0 went silent too (its last frame was at 1001.6).
        assert_eq!(
            names(&f)[3..],
            [
                "esc1 stale cleared",
                "esc1 disconnected raised critical",
                "esc0 stale raised warning",
                "esc1 disconnected cleared"
            ]
        );
        assert_eq!(f.escs[1].link, Link::Up);
        assert_eq!(f.log_since(5).count(), 2);
        assert_eq!(f.log_since(0).count(), 7);
    }

    /// The SocketCAN records of message `m` from node `node`, transfer id `tid`.
    fn can_bytes(m: hwfoc::dronecan::Message, node: u8, tid: u8) -> Vec<u8> {
        m.frames(16, node, 0, tid)
            .flat_map(|fr| fr.to_socketcan_record())
            .collect()
    }

    /// A Hobbywing StatusMsg1 of a motor turning slowly.
    fn status1() -> hwfoc::dronecan::StatusMsg1 {
        hwfoc::dronecan::StatusMsg1 {
            rpm: 100,
            pwm: 100,
            status: 0,
        }
    }

    /// A CAN ESC's row names its bus and node, and the channel it learns; it keeps its ESC
    /// number and its view when a GetEscID answer maps it. A bus says what it lacks in CAN
    /// words (it was "finding the baud rate").
    #[test]
    fn a_can_esc_is_named_by_bus_node_and_channel_and_keeps_its_number() {
        use hwfoc::dronecan::{GetEscId, Message};
        let mut f = fleet_of(vec![
            "can:vcan0".to_string(),
            "slcan:/dev/ttyACM0:1M".to_string(),
        ]);
        assert_eq!(
            f.escs[0].waiting(),
            "no CAN frame yet: bit rate? ESCs powered?"
        );
        assert_eq!(
            (f.escs[0].rate_text(), f.escs[1].rate_text()),
            ("CAN".to_string(), "CAN 1000 kbit/s".to_string())
        );
        let bytes = |m: Message, tid: u8| can_bytes(m, 10, tid);
        let m1 = status1();
        // No GetEscID answer within the hold (1 s of the bus's clock): placed by its node id.
        f.on_event(&data(0, 1000.0, bytes(m1.into(), 0)));
        f.on_event(&data(0, 1001.1, bytes(m1.into(), 1)));
        let esc = f.escs[0].last.unwrap().esc;
        assert_eq!(f.escs[0].name, "vcan0 node 10");
        f.on_event(&data(
            0,
            1001.2,
            bytes(GetEscId::new(&[10, 2]).unwrap().into(), 2),
        ));
        f.on_event(&data(0, 1001.3, bytes(m1.into(), 3)));
        let views: Vec<&str> = f.escs.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(views, ["vcan0 node 10 ch 2", "slcan:/dev/ttyACM0:1M"]);
        assert_eq!(f.escs[0].last.unwrap().esc, esc);
    }

    /// Two live CAN ESCs that claim one throttle channel stay two views, and the monitor is told
    /// once, naming both nodes (the headless monitor prints it, the dashboard shows it).
    #[test]
    fn two_live_can_escs_on_one_channel_are_told_of_once() {
        use hwfoc::dronecan::{GetEscId, Message};
        let mut f = fleet_of(vec!["can:vcan0".to_string()]);
        let send = |f: &mut Fleet, t: f64, m: Message, node: u8, tid: u8| {
            f.on_event(&data(0, t, can_bytes(m, node, tid)));
        };
        for (k, node) in [10u8, 11].into_iter().enumerate() {
            let t = 1000.0 + k as f64 * 0.01;
            send(&mut f, t, GetEscId::answer(node, 1).into(), node, 0);
            send(&mut f, t + 0.1, status1().into(), node, 1);
            send(&mut f, t + 0.2, status1().into(), node, 2);
        }
        assert_eq!(f.escs.len(), 2, "two views");
        let told: Vec<String> = f.notices.iter().map(|n| n.line()).collect();
        assert_eq!(told.len(), 1, "{told:?}");
        assert!(
            told[0].starts_with(
                "hwfoc: warning: can:vcan0: node 10 and node 11 both claim throttle channel 1"
            ),
            "{told:?}"
        );
        send(&mut f, 1000.5, status1().into(), 11, 3);
        assert_eq!(f.notices.len(), 1, "told once");
    }

    /// A CAN ESC's view wears the label of its ESC number, else its port's own, whichever ESC
    /// was heard first (the first heard takes the port's view).
    #[test]
    fn can_escs_are_labelled_by_number_else_by_port() {
        let mut f = fleet_of(vec!["can:vcan0".to_string()]);
        let by_esc = BTreeMap::from([(11, "left".to_string()), (0, "port zero".to_string())]);
        f.set_labels(by_esc, vec![Some("bus".to_string())]);
        f.on_event(&data(0, 1000.0, can_bytes(status1().into(), 13, 0)));
        f.on_event(&data(0, 1000.1, can_bytes(status1().into(), 11, 0)));
        // Neither answers a GetEscID within the hold (1 s): each is placed by its node id.
        f.on_event(&data(0, 1001.2, can_bytes(status1().into(), 13, 1)));
        f.on_event(&data(0, 1001.3, can_bytes(status1().into(), 11, 1)));
        let got: Vec<(usize, Option<&str>)> = f
            .escs
            .iter()
            .map(|e| (e.number, e.label.as_deref()))
            .collect();
        assert_eq!(got, [(13, Some("bus")), (11, Some("left"))]);
    }

    /// A CAN ESC's view carries the records' ESC number (its place: node id before a GetEscID
    /// answer), whatever order the ESCs were heard in: the monitor's `esc` is the records'.
    #[test]
    fn a_can_escs_view_is_numbered_as_its_records() {
        let mut f = fleet_of(vec!["can:vcan0".to_string()]);
        f.on_event(&data(0, 1000.0, can_bytes(status1().into(), 13, 0)));
        f.on_event(&data(0, 1000.1, can_bytes(status1().into(), 11, 0)));
        // Neither answers a GetEscID within the hold (1 s): each is placed by its node id.
        f.on_event(&data(0, 1001.2, can_bytes(status1().into(), 13, 1)));
        f.on_event(&data(0, 1001.3, can_bytes(status1().into(), 11, 1)));
        let got: Vec<(usize, u8)> = f
            .escs
            .iter()
            .map(|e| (e.number, e.last.unwrap().esc))
            .collect();
        assert_eq!(got, [(13, 13), (11, 11)]);
        // --json and --plain say so.
        let json = super::super::headless::status_json(&f.escs[1], 1001.4);
        assert_eq!(json["esc"], 11, "{json}");
        let line = super::super::headless::status_line(&f.escs[1], 1001.4);
        assert!(line.contains(" esc11 "), "{line}");
        // `[esc.11]` applies to node 11's view, whatever order the ESCs were heard in.
        let mut settings = hwfoc_io::SettingsMap::new(Settings::DEFAULT);
        let patch = hwfoc_io::SettingsPatch {
            pole_pairs: Some(14),
            ..Default::default()
        };
        settings.set_esc(11, patch).unwrap();
        let limits = f.limits.clone();
        let names = vec![("can:vcan0".to_string(), None)];
        let mut f = Fleet::new(names, settings, limits, Baud::Fixed(19_200), 1000.0);
        f.on_event(&data(0, 1000.0, can_bytes(status1().into(), 13, 0)));
        f.on_event(&data(0, 1000.1, can_bytes(status1().into(), 11, 0)));
        // Neither answers a GetEscID within the hold (1 s): each is placed by its node id.
        f.on_event(&data(0, 1001.2, can_bytes(status1().into(), 13, 1)));
        f.on_event(&data(0, 1001.3, can_bytes(status1().into(), 11, 1)));
        let pole_pairs: Vec<(usize, u16)> = f
            .escs
            .iter()
            .map(|e| (e.number, e.settings.pole_pairs))
            .collect();
        assert_eq!(pole_pairs, [(13, 7), (11, 14)]);
    }

    #[test]
    fn an_esc_without_frames_says_why() {
        let mut f = fleet(2);
        assert!(f.escs[0].waiting().starts_with("no bytes yet"));
        // What a wrong baud rate gives: bytes, never a frame.
        f.on_event(&data(0, 1000.0, vec![0x55; 100]));
        assert!(
            f.escs[0].waiting().contains("baud rate"),
            "{}",
            f.escs[0].waiting()
        );
        f.on_event(&data(1, 1000.0, vec![0x55; 10]));
        assert_eq!(f.escs[1].waiting(), "no frames yet");
    }

    #[test]
    fn charge_energy_and_power_per_esc_and_in_total_reset_with_the_peaks() {
        let mut f = fleet(2);
        // 12.8 A (raw 819 at scale 64) at 25.0 V on ESC 0, half that on ESC 1, for 3.6 s.
        let frame = |packet: u16, amps_raw: i16| {
            DataFrame {
                packet,
                current_raw: amps_raw,
                voltage_raw: 250,
                ..Default::default()
            }
            .encode()
            .to_vec()
        };
        for k in 0..=72u16 {
            let t = 1000.0 + f64::from(k) * 0.05;
            f.on_event(&data(0, t, frame(k, 819)));
            f.on_event(&data(1, t + 0.01, frame(k, 410)));
        }
        let amps0 = 819.0 / 64.0;
        let amps1 = 410.0 / 64.0;
        let e0 = &f.escs[0].energy;
        assert!(
            (e0.charge_mah() - amps0 * 1000.0 / 1000.0).abs() < 0.01,
            "{}",
            e0.charge_mah()
        );
        assert!((e0.energy_wh() - amps0 * 25.0 * 3.6 / 3600.0).abs() < 1e-3);
        let p0 = f.escs[0].power_w().unwrap();
        assert!((p0 - amps0 * 25.0).abs() < 0.01, "{p0}");
        let total = f.total_energy();
        assert!(
            (total.charge_mah() - (amps0 + amps1)).abs() < 0.02,
            "{}",
            total.charge_mah()
        );
        let sum = f.total_power_w().unwrap();
        assert!((sum - (amps0 + amps1) * 25.0).abs() < 0.1, "{sum}");
        assert!((f.peak_total_w.unwrap() - sum).abs() < 0.1);
        // A burst on ESC 0 raises the total's peak; reset forgets it, and the charge.
        f.on_event(&data(0, 1003.65, frame(73, 3276)));
        let peak = f.peak_total_w.unwrap();
        // 51.2 A at 25 V plus ESC 1's 160 W.
        assert!(
            (peak - (3276.0 / 64.0 + amps1) * 25.0).abs() < 0.1,
            "{peak}"
        );
        f.on_event(&data(0, 1003.70, frame(74, 819)));
        assert_eq!(f.peak_total_w, Some(peak));
        f.reset_peaks();
        assert_eq!(f.escs[0].energy.charge_mah(), 0.0);
        assert!((f.peak_total_w.unwrap() - sum).abs() < 0.1);
        assert_eq!(f.escs[0].energy.peak_w(), f.escs[0].power_w());
        // A port that goes away adds nothing for the time it was away, nor counts in the total.
        f.on_event(&PortEvent::Lost {
            port: 1,
            t_ns: 1_004_000_000_000,
            reason: "unplugged".into(),
        });
        assert_eq!(f.total_power_w(), f.escs[0].power_w());
    }

    #[test]
    fn reset_peaks_keeps_only_the_latest_frame() {
        let mut f = fleet(1);
        let code = |c: usize| hwfoc::units::ADC_TABLE[c];
        f.on_event(&data(0, 1000.0, frame(0, Status::OK, code(70), 252)));
        f.on_event(&data(0, 1000.05, frame(1, Status::OK, code(50), 240)));
        assert_eq!(f.escs[0].peaks.mos_temp_c, Some(70.0));
        assert_eq!(f.escs[0].peaks.min_voltage_v, Some(24.0));
        f.reset_peaks();
        assert_eq!(f.escs[0].peaks.mos_temp_c, Some(50.0));
    }
}
