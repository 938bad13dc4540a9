//! The MAVLink output: MAVLink 2 frames to a ground station or a flight controller, over UDP or
//! a serial port, or into a telemetry log file.
//!
//! # Messages
//!
//! | message | dialect | when | content |
//! |---|---|---|---|
//! | `HEARTBEAT` | minimal | every [`MavlinkOptions::heartbeat_every`] (1 s), from the first poll | see below |
//! | `ESC_TELEMETRY_1_TO_4` … `_29_TO_32` | ardupilotmega (Mission Planner) | when an ESC of the group has a new frame | temperature degC, voltage cV, current cA, totalcurrent mAh consumed, rpm, count of frames |
//! | `ESC_STATUS` | common (PX4, QGroundControl) | with the group's `ESC_TELEMETRY` | rpm, voltage V, current A |
//! | `ESC_INFO` | common | per group every [`MavlinkOptions::info_every`] (1 s) while an ESC of it is online, and at once when its online set or a failure flag changes | online bitmask, failure flags, error counts, temperature cdegC |
//!
//! Groups are ESCs 1–4, 5–8, …: hwfoc's ESC `n` (0-based) is MAVLink ESC `n + 1`, in group
//! `n / 4` (`index` = `4 * (n / 4)`). `ESC_TELEMETRY` exists for ESCs 1 to 32, `ESC_INFO` and
//! `ESC_STATUS` for 1 to 64; ESCs above are not sent. The units and the failure-flag mapping
//! are in [`messages`].
//!
//! Rates follow the inputs: at most one `ESC_TELEMETRY` and one `ESC_STATUS` per group per
//! [`Output::poll`], carrying each ESC's latest frame (the frames superseded before a poll are
//! counted in [`OutputStats::superseded`]). An ESC without a frame for [`SILENT_AFTER`] is
//! offline: zeros in its slots, its bit cleared in `ESC_INFO.info`, and a group whose ESCs are
//! all offline is no longer sent. "mAh consumed" is integrated by [`hwfoc_io::energy::Energy`]
//! over the records' times (`t_s`), or their arrival times when the input has none.
//!
//! # Times
//!
//! A message's time (`time_usec` of `ESC_STATUS` and `ESC_INFO`, and a telemetry log's
//! timestamps) is the time of the data: the latest record's `t_s` plus the time since its frame
//! arrived, where records have Unix times (live ports, virtual ESCs, recordings replayed: the
//! flight's own times); the system clock where they have none or another clock (a raw byte file,
//! a logic analyser's capture), told by magnitude as MAVLink's `time_usec` is (Unix times are
//! after [`UNIX_TIME_FROM`]). Times never go back: a message is never older than the one
//! before it. A telemetry log starts with the first ESC frame (no HEARTBEAT before it, whose
//! time would be the system clock's rather than the data's).
//!
//! # Identity: system id, component id, heartbeat
//!
//! Ground stations show messages per system (and Mission Planner per system and component, the
//! one it is connected to). The defaults ([`MavlinkOptions::default`]) are system 1, the usual
//! vehicle, and component [`MAV_COMP_ID_PERIPHERAL`] (158, "generic autopilot peripheral"), with
//! a heartbeat of type `MAV_TYPE_ONBOARD_CONTROLLER` and autopilot `MAV_AUTOPILOT_INVALID`: a
//! component beside a flight controller of system 1, which ground stations do not take for a
//! vehicle of its own (QGroundControl ignores such heartbeats, MAVProxy lists it as "CC").
//!
//! With component id [`MAV_COMP_ID_AUTOPILOT1`] (1), hwfoc stands in for the vehicle: its
//! heartbeat says `MAV_TYPE_GENERIC`, `MAV_AUTOPILOT_GENERIC`, so that a ground station with no
//! flight controller connected (a bench) connects to it and shows its ESC messages. **On a bench
//! without a flight controller, use `--mavlink-component 1`** (system id 1, the default); never
//! beside a flight controller of the same system id, whose own component 1 it would shadow.
//!
//! # Targets
//!
//! [`MavlinkTarget::parse`]: `udp` (127.0.0.1:14550, where ground stations listen),
//! `udp:HOST:PORT`, `udp:PORT` (on 127.0.0.1), `udp:[V6ADDR]:PORT`; `serial:PORT` (57600 baud,
//! ArduPilot's telemetry default), `serial:PORT:BAUD`; `file:PATH`, a telemetry log as Mission
//! Planner writes and reads it (`.tlog`: each message after its time, a 64-bit big-endian count of
//! microseconds since the Unix epoch), which is never written over unless
//! [`MavlinkOptions::overwrite`] (`hwfoc_io::write::create_file`).
//!
//! # Errors
//!
//! Sending never stops the output: an unreachable UDP destination (a refused port, reported by
//! ICMP on our connected socket; a network without a route) is an [`OutputError::Send`], counted
//! in [`OutputStats::errors`], and the next poll sends again; a serial port that disappears is an
//! [`OutputError::Lost`], reopened every [`hwfoc_ports::serial::RETRY_EVERY`] from later polls (what
//! would have been sent meanwhile is dropped, not counted). Nothing blocks for long: the UDP
//! socket is non-blocking, a serial write waits at most 50 ms, and after a write that found the
//! link full or timed out the rest of that poll's messages are dropped (each counted as an error).

pub mod messages;
mod transport;

use std::fmt;
use std::net::{Ipv4Addr, SocketAddr, ToSocketAddrs};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use ::mavlink::dialects::ardupilotmega::{
    HEARTBEAT_DATA, MavAutopilot, MavMessage, MavModeFlag, MavState, MavType,
};
use ::mavlink::{MavHeader, Message};
use hwfoc_io::Record;
use hwfoc_io::energy::Energy;

use crate::output::{Output, OutputError, OutputStats, SILENT_AFTER, Update};
use messages::{GROUP, InfoContext, STATUS_GROUPS, Slot};
use transport::{Link, LinkError};

/// Where ground stations listen for MAVLink over UDP: 127.0.0.1:14550, the target of `udp`.
pub const DEFAULT_UDP: SocketAddr =
    SocketAddr::new(std::net::IpAddr::V4(Ipv4Addr::LOCALHOST), 14550);

/// The baud rate of `serial:PORT` without one: 57600, the default of ArduPilot's telemetry
/// ports and of SiK radios.
pub const DEFAULT_SERIAL_BAUD: u32 = 57_600;

/// `MAV_COMP_ID_AUTOPILOT1`: the flight controller's component id. Used by hwfoc on a bench
/// without a flight controller (the heartbeat then stands in for a vehicle).
pub const MAV_COMP_ID_AUTOPILOT1: u8 = 1;

/// `MAV_COMP_ID_PERIPHERAL`: "generic autopilot peripheral component ID", hwfoc's default.
pub const MAV_COMP_ID_PERIPHERAL: u8 = 158;

/// Record times from this many seconds on (2001-09-09) are Unix times, and messages take their
/// times from them (see [Times](self#times)); smaller ones are of another clock.
pub const UNIX_TIME_FROM: f64 = 1.0e9;

/// Who the messages come from, and how often the periodic ones are sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MavlinkOptions {
    /// The MAVLink system id (1 to 255; default 1: the vehicle's, so that ground stations show
    /// the ESCs with the vehicle).
    pub system_id: u8,
    /// The MAVLink component id (default [`MAV_COMP_ID_PERIPHERAL`]; [`MAV_COMP_ID_AUTOPILOT1`]
    /// to stand in for the vehicle on a bench without a flight controller).
    pub component_id: u8,
    /// Period of `HEARTBEAT` (default 1 s).
    pub heartbeat_every: Duration,
    /// Period of each group's `ESC_INFO` while an ESC of it is online (default 1 s).
    pub info_every: Duration,
    /// Whether a `file:` target may replace an existing file (default false: an existing file
    /// is an error).
    pub overwrite: bool,
}

impl Default for MavlinkOptions {
    fn default() -> Self {
        MavlinkOptions {
            system_id: 1,
            component_id: MAV_COMP_ID_PERIPHERAL,
            heartbeat_every: Duration::from_secs(1),
            info_every: Duration::from_secs(1),
            overwrite: false,
        }
    }
}

impl MavlinkOptions {
    /// The `HEARTBEAT` sent under these options: a peripheral (`MAV_TYPE_ONBOARD_CONTROLLER`,
    /// `MAV_AUTOPILOT_INVALID`), or with component id 1 a stand-in vehicle (`MAV_TYPE_GENERIC`,
    /// `MAV_AUTOPILOT_GENERIC`); system status `MAV_STATE_ACTIVE`, no mode.
    pub fn heartbeat(&self) -> MavMessage {
        let (mavtype, autopilot) = if self.component_id == MAV_COMP_ID_AUTOPILOT1 {
            (
                MavType::MAV_TYPE_GENERIC,
                MavAutopilot::MAV_AUTOPILOT_GENERIC,
            )
        } else {
            (
                MavType::MAV_TYPE_ONBOARD_CONTROLLER,
                MavAutopilot::MAV_AUTOPILOT_INVALID,
            )
        };
        MavMessage::HEARTBEAT(HEARTBEAT_DATA {
            custom_mode: 0,
            mavtype,
            autopilot,
            base_mode: MavModeFlag::empty(),
            system_status: MavState::MAV_STATE_ACTIVE,
            mavlink_version: 3,
        })
    }
}

/// Where the MAVLink output writes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MavlinkTarget {
    /// UDP datagrams to this address, one message each.
    Udp(SocketAddr),
    /// A serial port (a telemetry radio, a flight controller's telemetry port).
    Serial {
        /// The port, as `hwfoc_ports::serial::open` takes it (`/dev/ttyUSB0`, `COM3`).
        port: String,
        /// Its baud rate.
        baud: u32,
    },
    /// A telemetry log file (`.tlog`), created.
    File(String),
}

impl MavlinkTarget {
    /// Reads a target as given on the command line: `udp` (= `udp:127.0.0.1:14550`),
    /// `udp:PORT` (on 127.0.0.1), `udp:HOST:PORT` (a name is resolved now, IPv4 preferred),
    /// `udp:[IPV6]:PORT`; `serial:PORT` ([`DEFAULT_SERIAL_BAUD`]) or `serial:PORT:BAUD`;
    /// `file:PATH` (a telemetry log).
    ///
    /// ```
    /// use hwfoc_bridge::mavlink::MavlinkTarget;
    ///
    /// assert_eq!(MavlinkTarget::parse("udp")?.to_string(), "udp:127.0.0.1:14550");
    /// assert_eq!(MavlinkTarget::parse("udp:10.0.0.2:14551")?.to_string(), "udp:10.0.0.2:14551");
    /// assert_eq!(
    ///     MavlinkTarget::parse("serial:/dev/ttyUSB0:115200")?,
    ///     MavlinkTarget::Serial { port: "/dev/ttyUSB0".into(), baud: 115200 }
    /// );
    /// assert_eq!(
    ///     MavlinkTarget::parse("file:flight.tlog")?,
    ///     MavlinkTarget::File("flight.tlog".into())
    /// );
    /// assert!(MavlinkTarget::parse("tcp:1.2.3.4:5760").is_err());
    /// # Ok::<(), hwfoc_bridge::OutputError>(())
    /// ```
    pub fn parse(spec: &str) -> Result<MavlinkTarget, OutputError> {
        let bad = |reason: String| OutputError::Open {
            output: format!("mavlink {spec}"),
            reason,
        };
        let (scheme, rest) = match spec.split_once(':') {
            Some((s, r)) => (s, Some(r)),
            None => (spec, None),
        };
        match scheme.to_ascii_lowercase().as_str() {
            "udp" => {
                let Some(rest) = rest else {
                    return Ok(MavlinkTarget::Udp(DEFAULT_UDP));
                };
                let addr = udp_address(rest, &bad)?;
                if addr.port() == 0 {
                    return Err(bad(
                        "port 0 is no destination: give the port the ground station listens \
                         on (14550 usually)"
                            .to_string(),
                    ));
                }
                if addr.ip().is_unspecified() {
                    return Err(bad(format!(
                        "{} is no destination address: give the ground station's address \
                         (127.0.0.1 on this machine)",
                        addr.ip()
                    )));
                }
                Ok(MavlinkTarget::Udp(addr))
            }
            "serial" => {
                let rest = rest
                    .filter(|r| !r.is_empty())
                    .ok_or_else(|| bad("expected serial:PORT or serial:PORT:BAUD".to_string()))?;
                let (port, baud) = match rest.rsplit_once(':') {
                    Some((port, baud))
                        if !port.is_empty() && baud.bytes().all(|b| b.is_ascii_digit()) =>
                    {
                        let baud = baud
                            .parse::<u32>()
                            .ok()
                            .filter(|b| *b > 0)
                            .ok_or_else(|| bad(format!("{baud:?} is not a baud rate")))?;
                        (port, baud)
                    }
                    _ => (rest, DEFAULT_SERIAL_BAUD),
                };
                Ok(MavlinkTarget::Serial {
                    port: port.to_string(),
                    baud,
                })
            }
            "file" => rest
                .filter(|r| !r.is_empty())
                .map(|path| MavlinkTarget::File(path.to_string()))
                .ok_or_else(|| bad("expected file:PATH (a telemetry log, .tlog)".to_string())),
            _ => Err(bad(
                "expected udp, udp:HOST:PORT, serial:PORT, serial:PORT:BAUD or file:PATH"
                    .to_string(),
            )),
        }
    }
}

/// The address of `udp:REST`: `PORT` (on 127.0.0.1), `HOST:PORT` (a name resolved, IPv4
/// preferred) or `[IPV6]:PORT`; `bad` makes the error.
fn udp_address(
    rest: &str,
    bad: &impl Fn(String) -> OutputError,
) -> Result<SocketAddr, OutputError> {
    if let Ok(port) = rest.parse::<u16>() {
        return Ok(SocketAddr::new(Ipv4Addr::LOCALHOST.into(), port));
    }
    if let Ok(addr) = rest.parse::<SocketAddr>() {
        return Ok(addr);
    }
    let Some((host, port)) = rest.rsplit_once(':') else {
        return Err(bad("expected udp:HOST:PORT".to_string()));
    };
    let port: u16 = port
        .parse()
        .map_err(|_| bad(format!("{port:?} is not a UDP port number")))?;
    let addrs: Vec<SocketAddr> = (host, port)
        .to_socket_addrs()
        .map_err(|e| bad(format!("cannot resolve {host}: {e}")))?
        .collect();
    addrs
        .iter()
        .find(|a| a.is_ipv4())
        .or(addrs.first())
        .copied()
        .ok_or_else(|| bad(format!("{host} has no address")))
}

impl fmt::Display for MavlinkTarget {
    /// The canonical spec: `udp:127.0.0.1:14550`, `serial:/dev/ttyUSB0:57600`, `file:x.tlog`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MavlinkTarget::Udp(addr) => write!(f, "udp:{addr}"),
            MavlinkTarget::Serial { port, baud } => write!(f, "serial:{port}:{baud}"),
            MavlinkTarget::File(path) => write!(f, "file:{path}"),
        }
    }
}

/// What the output knows of one ESC.
#[derive(Debug, Default)]
struct EscState {
    /// The latest frame and when its bytes arrived.
    latest: Option<(Record, Instant)>,
    /// The arrival of a frame not yet sent.
    fresh: Option<Instant>,
    frames: u64,
    energy: Energy,
    /// Fault onsets.
    errors: u32,
}

impl EscState {
    fn online(&self, now: Instant) -> bool {
        self.latest
            .is_some_and(|(_, at)| now.saturating_duration_since(at) < SILENT_AFTER)
    }
}

/// What was last said of a group in `ESC_INFO`.
#[derive(Debug, Default, Clone, Copy)]
struct InfoSent {
    state: Option<(u8, [u16; 4])>,
    due: Option<Instant>,
}

/// The MAVLink output (see the [module documentation](self)).
pub struct MavlinkOutput {
    name: String,
    options: MavlinkOptions,
    link: Link,
    stats: OutputStats,
    sequence: u8,
    escs: Vec<EscState>,
    infos: [InfoSent; STATUS_GROUPS],
    next_heartbeat: Option<Instant>,
    /// The zero of arrival times, for the charge of inputs without times.
    opened: Instant,
    /// The latest record with a Unix time: its `t_s` and its frame's arrival.
    clock: Option<(f64, Instant)>,
    /// The time of the last poll's messages.
    last_usec: u64,
    frame: Vec<u8>,
}

impl fmt::Debug for MavlinkOutput {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("MavlinkOutput")
            .field("name", &self.name)
            .field("options", &self.options)
            .field("stats", &self.stats)
            .finish_non_exhaustive()
    }
}

impl MavlinkOutput {
    /// Opens the socket, the port or the file. Fails ([`OutputError::Open`]) only when it
    /// cannot be opened at all (no UDP socket, a serial port that does not exist or may not be
    /// opened, a file that exists or cannot be created): an unreachable UDP destination is
    /// reported by the sends.
    pub fn open(
        target: MavlinkTarget,
        options: MavlinkOptions,
    ) -> Result<MavlinkOutput, OutputError> {
        let name = format!("mavlink {target}");
        let link = match &target {
            MavlinkTarget::Udp(addr) => Link::udp(*addr).map_err(|e| e.to_string()),
            MavlinkTarget::Serial { port, baud } => Link::serial(port, *baud),
            MavlinkTarget::File(path) => {
                Link::tlog(path, options.overwrite).map_err(|e| e.to_string())
            }
        }
        .map_err(|reason| OutputError::Open {
            output: name.clone(),
            reason,
        })?;
        Ok(MavlinkOutput {
            name,
            options,
            link,
            stats: OutputStats::default(),
            sequence: 0,
            escs: Vec::new(),
            infos: [InfoSent::default(); STATUS_GROUPS],
            next_heartbeat: None,
            opened: Instant::now(),
            clock: None,
            last_usec: 0,
            frame: Vec::with_capacity(280),
        })
    }

    /// The options it was opened with.
    pub fn options(&self) -> &MavlinkOptions {
        &self.options
    }

    /// The local address of a UDP output's socket (`None` for a serial port).
    pub fn local_addr(&self) -> Option<SocketAddr> {
        self.link.local_addr()
    }

    /// The group's slots at `now`: each online ESC's latest frame.
    fn slots(&self, group: usize, now: Instant) -> [Option<Slot>; GROUP] {
        std::array::from_fn(|i| {
            let esc = self.escs.get(group * GROUP + i)?;
            if !esc.online(now) {
                return None;
            }
            let (record, _) = esc.latest?;
            Some(Slot {
                record,
                frames: esc.frames,
                consumed_mah: esc.energy.charge_mah(),
            })
        })
    }

    /// The time of messages sent at `now`, microseconds since the Unix epoch (see
    /// [Times](self#times)), never before the last.
    fn time_usec(&mut self, now: Instant) -> u64 {
        let t = match self.clock {
            Some((t_s, arrived)) => {
                let t = t_s + now.saturating_duration_since(arrived).as_secs_f64();
                (t * 1e6).round() as u64
            }
            None => unix_usec(),
        };
        self.last_usec = self.last_usec.max(t);
        self.last_usec
    }

    /// Encodes and writes one message, of time `time_usec`; `carried` are the arrivals of the
    /// new frames it carries (their latencies are added once written).
    fn send(
        &mut self,
        message: &MavMessage,
        carried: &[Instant],
        now: Instant,
        time_usec: u64,
        first_error: &mut Option<OutputError>,
        stalled: &mut bool,
    ) {
        let header = MavHeader {
            system_id: u32::from(self.options.system_id),
            component_id: self.options.component_id,
            sequence: self.sequence,
        };
        self.sequence = self.sequence.wrapping_add(1);
        self.frame.clear();
        if let Err(e) = ::mavlink::write_v2_msg(&mut self.frame, header, message) {
            // Every message of the dialect fits a frame: this cannot happen.
            self.fail(
                OutputError::Send {
                    output: self.name.clone(),
                    reason: format!("cannot encode {}: {e}", message.message_name()),
                },
                first_error,
            );
            return;
        }
        if *stalled {
            self.stats.errors += 1;
            return;
        }
        match self.link.send(&self.frame, now, time_usec) {
            Ok(()) => {
                self.stats.messages += 1;
                self.stats.bytes += self.frame.len() as u64;
                let written = Instant::now();
                for at in carried {
                    self.stats
                        .latency
                        .add(written.saturating_duration_since(*at));
                }
            }
            Err(LinkError::Down) => {}
            Err(LinkError::Send(reason)) => {
                let output = self.name.clone();
                self.fail(OutputError::Send { output, reason }, first_error);
            }
            Err(LinkError::Stalled(reason)) => {
                *stalled = true;
                let output = self.name.clone();
                self.fail(OutputError::Send { output, reason }, first_error);
            }
            Err(LinkError::Lost(reason)) => {
                let output = self.name.clone();
                self.fail(OutputError::Lost { output, reason }, first_error);
            }
        }
    }

    fn fail(&mut self, error: OutputError, first_error: &mut Option<OutputError>) {
        self.stats.errors += 1;
        first_error.get_or_insert(error);
    }
}

/// Unix time now, microseconds.
fn unix_usec() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_micros() as u64)
}

impl Output for MavlinkOutput {
    fn name(&self) -> &str {
        &self.name
    }

    fn update(&mut self, update: &Update<'_>) {
        let index = usize::from(update.esc);
        if index >= STATUS_GROUPS * GROUP {
            self.stats.left_out.add(update.esc);
            return;
        }
        if self.escs.len() <= index {
            self.escs.resize_with(index + 1, EscState::default);
        }
        let opened = self.opened;
        let esc = &mut self.escs[index];
        if esc.fresh.is_some() {
            self.stats.superseded += 1;
        }
        let record = update.record;
        let t_s = record.t_s.unwrap_or_else(|| {
            update
                .arrived
                .saturating_duration_since(opened)
                .as_secs_f64()
        });
        if let (Some(volts), Some(amps)) = (record.voltage_v, record.current_a) {
            esc.energy.add(Some(t_s), f64::from(volts), f64::from(amps));
        }
        let bits = |r: &Record| r.status.map_or(0, |s| s.0);
        let before = esc.latest.map_or(0, |(r, _)| bits(&r));
        esc.errors = esc
            .errors
            .saturating_add((bits(record) & !before).count_ones());
        esc.frames += 1;
        esc.latest = Some((*record, update.arrived));
        esc.fresh = Some(update.arrived);
        if let Some(t_s) = record.t_s.filter(|t| *t >= UNIX_TIME_FROM) {
            self.clock = Some((t_s, update.arrived));
        }
    }

    fn poll(&mut self, now: Instant) -> Result<(), OutputError> {
        if self.link.is_log() && self.escs.is_empty() {
            return Ok(());
        }
        let mut first_error = None;
        let mut stalled = false;
        let time_usec = self.time_usec(now);
        if self.next_heartbeat.is_none_or(|due| now >= due) {
            self.next_heartbeat = Some(now + self.options.heartbeat_every);
            let heartbeat = self.options.heartbeat();
            self.send(
                &heartbeat,
                &[],
                now,
                time_usec,
                &mut first_error,
                &mut stalled,
            );
        }
        let groups = self.escs.len().div_ceil(GROUP);
        let count = self.escs.len() as u8;
        for group in 0..groups {
            let slots = self.slots(group, now);
            let mut carried = Vec::new();
            for esc in &mut self.escs[group * GROUP..(group * GROUP + GROUP).min(count as usize)] {
                if let Some(at) = esc.fresh.take()
                    && esc.online(now)
                {
                    carried.push(at);
                }
            }
            if !carried.is_empty() {
                if let Some(telemetry) = messages::esc_telemetry(group, &slots) {
                    let (t, e, s) = (time_usec, &mut first_error, &mut stalled);
                    self.send(&telemetry, &carried, now, t, e, s);
                }
                let status = messages::esc_status(group, time_usec, &slots);
                let (t, e, s) = (time_usec, &mut first_error, &mut stalled);
                self.send(&status, &carried, now, t, e, s);
            }
            let state = messages::info_state(&slots);
            let sent = self.infos[group];
            let changed =
                sent.state.is_some_and(|s| s != state) || (sent.state.is_none() && state.0 != 0);
            let periodic = state.0 != 0 && sent.due.is_none_or(|due| now >= due);
            if changed || periodic {
                let first = group * GROUP;
                let escs = &self.escs[first..(first + GROUP).min(self.escs.len())];
                let counter = escs.iter().map(|e| e.frames).sum::<u64>() as u16;
                let error_count = std::array::from_fn(|i| escs.get(i).map_or(0, |e| e.errors));
                let context = InfoContext {
                    time_usec,
                    count,
                    counter,
                    error_count,
                };
                let info = messages::esc_info(group, &context, &slots);
                self.infos[group] = InfoSent {
                    state: Some(state),
                    due: Some(now + self.options.info_every),
                };
                let (t, e, s) = (time_usec, &mut first_error, &mut stalled);
                self.send(&info, &[], now, t, e, s);
            }
        }
        first_error.map_or(Ok(()), Err)
    }

    fn stats(&self) -> &OutputStats {
        &self.stats
    }

    fn carries(&self) -> usize {
        STATUS_GROUPS * GROUP
    }
}
