//! Running a bus of virtual CAN ESCs into its output: a `candump -l` log or a pcapng recording
//! (a file or standard output, as fast as possible or in real time), or a pseudo-terminal that
//! speaks SLCAN like a CANable adapter (always in real time, answering the controller on the
//! other end), with the ground truth of every transfer sent.
//!
//! In a log or a recording a virtual controller (node [`DEFAULT_SOURCE_NODE`], 127) asks the
//! ESCs for their ids as ArduPilot does, by the rule of [`AskIds`] (a GetEscID `[0]` at the
//! start and once a second while no ESC turns), on the simulated clock; its requests are frames
//! of the bus like the ESCs' (not in the ground truth, which lists the ESCs' transfers), and the
//! ESCs answer them. On a pty the controller on the other end asks, or not.

use std::io::{BufWriter, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use hwfoc::dronecan::{CanFrame, Form, Message};
use hwfoc_io::pcapng;
use hwfoc_io::write::WriteError;
use hwfoc_ports::can::{AskIds, DEFAULT_SOURCE_NODE, candump};
use hwfoc_ports::clock::unix_now_ns;

use super::bus::{CanBus, Sent};
use super::slcan::Adapter;
#[cfg(unix)]
use super::slcan::{self, Action};
use crate::error::SimError;
#[cfg(unix)]
use crate::pty::{self, PtyLinks};
#[cfg(unix)]
use crate::session::PTY_LINGER;
use crate::session::TAIL_S;
use crate::sink;

/// The interface name in candump lines.
pub const INTERFACE: &str = "can0";
/// Simulated time handled per step when writing at once, ns.
const STEP_NS: u64 = 100_000_000;
/// How often the real-time loop looks at the pty and the bus.
const TICK: Duration = Duration::from_millis(2);

/// Where a CAN bus goes.
#[derive(Debug, Clone, PartialEq)]
pub enum CanDestination {
    /// A `candump -l` log: `(secs.usecs) can0 ID#DATA` lines, to a file or standard output
    /// (`-`).
    Candump(String),
    /// A pcapng recording with one `LINKTYPE_CAN_SOCKETCAN` interface ([`INTERFACE`], the bus's
    /// bit rate) and a packet per frame, nanosecond timestamps, to a file or standard output
    /// (`-`).
    Pcapng(String),
    /// A pseudo-terminal speaking SLCAN (the controller's adapter), with optional symlinks.
    #[cfg(unix)]
    Pty(PtyLinks),
}

/// How a CAN bus is run.
#[derive(Debug, Clone, PartialEq)]
pub struct CanPlan {
    /// Where the frames go.
    pub destination: CanDestination,
    /// Write a log at the real rate instead of as fast as possible (a pty always is).
    pub realtime: bool,
    /// Unix time (seconds) of the start of a log written at once. Default: now.
    pub start_s: Option<f64>,
    /// Seconds of simulated time. Default: one run of the profile plus 2 s for a log written
    /// at once; until stopped in real time.
    pub duration_s: Option<f64>,
    /// The ground truth's file (`-`: standard output): one JSON object per transfer sent.
    pub truth: Option<String>,
    /// Replace output files that exist.
    pub overwrite: bool,
    /// In a log or a recording, a virtual controller asks the ESCs for their ids ([`AskIds`]).
    pub ask_ids: bool,
}

/// What a run of a CAN bus did.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct CanReport {
    /// The output, as a person would name it (a path, standard output, a pty).
    pub output: String,
    /// Transfers the ESCs sent.
    pub transfers: u64,
    /// Frames on the bus (the controller's included).
    pub frames: u64,
    /// Frames no one received (a pty without a reader, or its channel closed).
    pub undelivered: u64,
    /// Frames the controller sent: the one on the pty, or the virtual controller's requests in
    /// a log.
    pub received: u64,
    /// Answers the ESCs gave to the controller's requests.
    pub answers: u64,
    /// SLCAN commands refused (pty).
    pub refused: u64,
}

/// A CAN bus with its outputs open, ready to run.
pub struct CanSession {
    bus: CanBus,
    out: Out,
    truth: Option<(String, BufWriter<Box<dyn Write>>)>,
    realtime: bool,
    origin_ns: u64,
    duration_ns: Option<u64>,
    ask_ids: bool,
    report: CanReport,
}

/// A pcapng writer over a buffered output.
type RecordingWriter = pcapng::Writer<BufWriter<Box<dyn Write>>>;

enum Out {
    Log(String, BufWriter<Box<dyn Write>>),
    /// The recording, and its CAN interface.
    Pcapng(String, Box<RecordingWriter>, u32),
    /// The pty, and its symlinks (removed when dropped).
    #[cfg(unix)]
    Pty(pty::Pty, #[allow(dead_code)] pty::Links),
}

impl CanSession {
    /// Opens `plan`'s outputs for `bus` (every file checked before any is created).
    pub fn open(bus: CanBus, plan: &CanPlan) -> Result<CanSession, SimError> {
        let live = !matches!(
            plan.destination,
            CanDestination::Candump(_) | CanDestination::Pcapng(_)
        );
        let realtime = plan.realtime || live;
        let mut files: Vec<String> = plan.truth.iter().cloned().collect();
        match &plan.destination {
            CanDestination::Candump(path) | CanDestination::Pcapng(path) => {
                files.push(path.clone())
            }
            #[cfg(unix)]
            CanDestination::Pty(_) => {}
        }
        sink::check_new(files.iter().map(String::as_str), plan.overwrite)?;
        let truth = match &plan.truth {
            Some(path) => {
                let (name, w) = sink::create(path, plan.overwrite)?;
                Some((name, BufWriter::with_capacity(1 << 16, w)))
            }
            None => None,
        };
        let origin_ns = match (realtime, plan.start_s) {
            (false, Some(s)) => (s * 1e9).round() as u64,
            _ => unix_now_ns(),
        };
        let out = match &plan.destination {
            CanDestination::Candump(path) => {
                let (name, w) = sink::create(path, plan.overwrite)?;
                Out::Log(name, BufWriter::with_capacity(1 << 16, w))
            }
            CanDestination::Pcapng(path) => {
                let (name, w) = sink::create(path, plan.overwrite)?;
                // The recording's id, from what makes its bytes: the same seed and start,
                // the same id.
                let recording = pcapng::RecordingId::derived(&[bus.seed(), origin_ns]);
                let buffered = BufWriter::with_capacity(1 << 16, w);
                let mut writer =
                    pcapng::Writer::continuing(buffered, recording).map_err(write_error(&name))?;
                let iface = writer
                    .add_can_interface(INTERFACE, Some(bus.bitrate()))
                    .map_err(write_error(&name))?;
                Out::Pcapng(name, Box::new(writer), iface)
            }
            #[cfg(unix)]
            CanDestination::Pty(links) => {
                let (mut ptys, links) = pty::open_all(1, links)?;
                let mut p = ptys.remove(0);
                p.keep_input();
                Out::Pty(p, links)
            }
        };
        let duration_s = match plan.duration_s {
            Some(d) => Some(d),
            None if realtime => None,
            None => Some(bus.natural_length_s() + TAIL_S),
        };
        let output = match &out {
            Out::Log(name, _) | Out::Pcapng(name, ..) => name.clone(),
            #[cfg(unix)]
            Out::Pty(p, _) => p.path().display().to_string(),
        };
        Ok(CanSession {
            bus,
            out,
            truth,
            realtime,
            origin_ns,
            duration_ns: duration_s.map(|s| (s * 1e9).round() as u64),
            ask_ids: plan.ask_ids && !live,
            report: CanReport {
                output,
                ..CanReport::default()
            },
        })
    }

    /// The output, as a person would name it: for a pty, the path to open.
    pub fn output(&self) -> &str {
        &self.report.output
    }

    /// Runs to the end of the duration, or until `stop` is set.
    pub fn run(mut self, stop: &AtomicBool) -> Result<CanReport, SimError> {
        let start = Instant::now();
        // Fed only by a pty's controller (a pty is Unix's).
        #[cfg_attr(not(unix), allow(unused_mut))]
        let mut adapter = Adapter::new();
        let mut t_ns = 0u64;
        // What the pty's controller sends and is answered (a pty is Unix's).
        #[cfg(unix)]
        let (mut reply, mut actions) = (Vec::new(), Vec::new());
        let mut lines = Vec::new();
        let mut asker = self.ask_ids.then(|| AskIds::new(DEFAULT_SOURCE_NODE));
        while !stop.load(Ordering::Relaxed) {
            if self.duration_ns.is_some_and(|d| t_ns >= d) {
                break;
            }
            // The virtual controller asks at the time reached, having heard the frames before.
            if let Some(request) = asker
                .as_mut()
                .and_then(|a| a.due(Duration::from_nanos(t_ns)))
            {
                let (frames, answers) = self.bus.transmit(t_ns, &request);
                self.report.received += frames.len() as u64;
                self.report.answers += answers as u64;
                self.report.frames += frames.len() as u64;
                self.write_frames(&frames, adapter.is_open(), &mut lines)?;
            }
            t_ns = if self.realtime {
                start.elapsed().as_nanos() as u64
            } else {
                t_ns + STEP_NS
            };
            if let Some(d) = self.duration_ns {
                t_ns = t_ns.min(d);
            }
            #[cfg(unix)]
            if let Out::Pty(p, _) = &mut self.out {
                let mut buf = [0u8; 1024];
                loop {
                    let n = p.read(&mut buf);
                    if n == 0 {
                        break;
                    }
                    adapter.feed(&buf[..n], &mut reply, &mut actions);
                }
                for a in actions.drain(..) {
                    match a {
                        Action::Bitrate(b) => self.bus.set_bitrate(b),
                        Action::Frame(f) => {
                            self.report.received += 1;
                            self.report.answers += self.bus.receive(t_ns, &f) as u64;
                        }
                    }
                }
                self.report.refused = adapter.refused();
                if !reply.is_empty() {
                    p.write(&reply);
                    reply.clear();
                }
            }
            let frames = self.bus.frames_until(t_ns);
            if let Some(a) = asker.as_mut() {
                for (_, f) in &frames {
                    a.heard(f);
                }
            }
            self.report.frames += frames.len() as u64;
            self.write_frames(&frames, adapter.is_open(), &mut lines)?;
            self.write_truth()?;
            if self.realtime {
                self.flush()?;
                std::thread::sleep(TICK);
            }
        }
        self.flush()?;
        #[cfg(unix)]
        if matches!(self.out, Out::Pty(..)) {
            std::thread::sleep(PTY_LINGER);
        }
        Ok(self.report)
    }

    fn write_frames(
        &mut self,
        frames: &[(u64, CanFrame)],
        open: bool,
        lines: &mut Vec<u8>,
    ) -> Result<(), WriteError> {
        lines.clear();
        match &mut self.out {
            Out::Log(name, w) => {
                let mut text = String::new();
                for (t, f) in frames {
                    candump::push_line(&mut text, log_seconds(self.origin_ns + t), INTERFACE, f);
                }
                w.write_all(text.as_bytes()).map_err(write_error(name))?;
            }
            Out::Pcapng(name, w, iface) => {
                for (t, f) in frames {
                    w.write_can(*iface, self.origin_ns + t, &f.to_socketcan_record())
                        .map_err(write_error(name))?;
                }
            }
            #[cfg(unix)]
            Out::Pty(p, _) => {
                if !open {
                    self.report.undelivered += frames.len() as u64;
                    return Ok(());
                }
                for (_, f) in frames {
                    slcan::push_frame(lines, f);
                }
                if !lines.is_empty() && !p.write(lines) {
                    self.report.undelivered += frames.len() as u64;
                }
            }
        }
        let _ = open;
        Ok(())
    }

    fn write_truth(&mut self) -> Result<(), WriteError> {
        let sent = self.bus.take_sent();
        self.report.transfers += sent.len() as u64;
        if let Some((name, w)) = &mut self.truth {
            let mut line = String::new();
            for s in &sent {
                line.clear();
                truth_json(&mut line, self.origin_ns, s);
                w.write_all(line.as_bytes()).map_err(write_error(name))?;
            }
        }
        Ok(())
    }

    fn flush(&mut self) -> Result<(), WriteError> {
        match &mut self.out {
            Out::Log(name, w) => w.flush().map_err(write_error(name))?,
            Out::Pcapng(name, w, _) => w.flush().map_err(write_error(name))?,
            #[cfg(unix)]
            Out::Pty(..) => {}
        }
        if let Some((name, w)) = &mut self.truth {
            w.flush().map_err(write_error(name))?;
        }
        Ok(())
    }
}

/// Unix nanoseconds as the seconds of a candump line: whole microseconds (as candump writes
/// them, the rest dropped), which an `f64` holds exactly enough for `push_line` to write them
/// back as they were.
fn log_seconds(ns: u64) -> f64 {
    (ns / 1000) as f64 / 1e6
}

fn write_error(name: &str) -> impl FnOnce(std::io::Error) -> WriteError + '_ {
    move |source| WriteError::Write {
        output: name.to_string(),
        source,
    }
}

/// Appends the ground truth's line for a transfer sent: `t_s` (Unix seconds of its first
/// frame, `origin_ns` being the run's start), `esc`, `source`, `destination` (0: a
/// broadcast), `priority`, `transfer_id`, `type` (the DSDL name), `form` (`message` or
/// `response`) and `fields`, named as in the DSDL (pydronecan's attribute names).
pub fn truth_json(out: &mut String, origin_ns: u64, s: &Sent) {
    use std::fmt::Write as _;
    let o = &s.out;
    let kind = o.message.kind();
    let form = match kind.form() {
        Form::Message => "message",
        Form::Request => "request",
        Form::Response => "response",
    };
    let ns = origin_ns + s.t_ns;
    let _ = write!(
        out,
        "{{\"t_s\":{}.{:09},\"esc\":{},\"source\":{},\"destination\":{},\"priority\":{},\
         \"transfer_id\":{},\"type\":\"{}\",\"form\":\"{form}\",\"fields\":{{",
        ns / 1_000_000_000,
        ns % 1_000_000_000,
        s.esc,
        o.source,
        o.destination,
        o.priority,
        o.transfer_id,
        kind.full_name()
    );
    let fields: Vec<(&str, String)> = match o.message {
        Message::StatusMsg1(m) => vec![
            ("rpm", m.rpm.to_string()),
            ("pwm", m.pwm.to_string()),
            ("status", m.status.to_string()),
        ],
        Message::StatusMsg2(m) => vec![
            ("input_voltage", m.input_voltage.to_string()),
            ("current", m.current.to_string()),
            ("temperature", m.temperature.to_string()),
        ],
        Message::StatusMsg3(m) => vec![
            ("MOS_T", m.mos_t.to_string()),
            ("CAP_T", m.cap_t.to_string()),
            ("Motor_T", m.motor_t.to_string()),
        ],
        Message::NodeStatus(m) => vec![
            ("uptime_sec", m.uptime_sec.to_string()),
            ("health", m.health.to_string()),
            ("mode", m.mode.to_string()),
            ("sub_mode", m.sub_mode.to_string()),
            (
                "vendor_specific_status_code",
                m.vendor_specific_status_code.to_string(),
            ),
        ],
        Message::GetEscId(m) => vec![("payload", format!("{:?}", m.payload()))],
        Message::SetIdResponse(m) => vec![
            ("node_id", m.node_id.to_string()),
            ("throttle_channel", m.throttle_channel.to_string()),
        ],
        Message::SetLedResponse(m) => vec![
            ("option", m.option.to_string()),
            ("color", m.color.to_string()),
            ("blink", m.blink.to_string()),
        ],
        Message::SetDirectionResponse(m) => vec![("direction", m.direction.to_string())],
        Message::SetReportingFrequencyResponse(m) => vec![
            ("option", m.option.to_string()),
            ("MSG_ID", m.msg_id.to_string()),
            ("rate", m.rate.to_string()),
        ],
        Message::SetThrottleSourceResponse(m) => vec![("source", m.source.to_string())],
        Message::SelfTestResponse(m) => vec![("status", m.status.to_string())],
        Message::GetMaintenanceInformationResponse(m) => vec![
            (
                "total_rotation_time_min",
                m.total_rotation_time_min.to_string(),
            ),
            (
                "time_since_maintainence_min",
                m.time_since_maintenance_min.to_string(),
            ),
        ],
        Message::GetMajorConfigResponse(m) => vec![
            ("direction", u8::from(m.direction).to_string()),
            ("throttle_source", u8::from(m.throttle_source).to_string()),
            ("throttle_channel", m.throttle_channel.to_string()),
            ("led_status", m.led_status.to_string()),
            ("led_color", m.led_color.to_string()),
            ("MSG2_rate", m.msg2_rate.to_string()),
            ("MSG1_rate", m.msg1_rate.to_string()),
            ("positioning_angle", m.positioning_angle.to_string()),
            ("reserved", format!("{:?}", m.reserved)),
        ],
        // SetBaud's response is empty; the ESCs send nothing else.
        _ => Vec::new(),
    };
    for (i, (name, value)) in fields.iter().enumerate() {
        let comma = if i > 0 { "," } else { "" };
        let _ = write!(out, "{comma}\"{name}\":{value}");
    }
    out.push_str("}}\n");
}
