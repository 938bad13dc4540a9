//! The DroneCAN output: a DroneCAN node on a CAN bus, reached through an SLCAN serial adapter,
//! broadcasting `uavcan.equipment.esc.Status` and `uavcan.equipment.esc.StatusExtended` for each
//! ESC and its own `uavcan.protocol.NodeStatus`: what ArduPilot, PX4 and the DroneCAN GUI tool
//! read from CAN ESCs.
//!
//! `hwfoc bridge --dronecan slcan:PORT[:BITRATE]` ([`SlcanTarget`]), with [`DronecanOptions`].
//!
//! # What is sent
//!
//! - **esc.Status** (data type 1034, priority [`PRIORITY`]): one per new frame of an ESC, at
//!   the next [`Output::poll`]; frames of the same ESC between two polls are coalesced (the
//!   older counted in [`OutputStats::superseded`]). Nothing is invented: an ESC is sent only
//!   when it sent, and a silent one ([`SILENT_AFTER`]) is not sent. Fields:
//!   `esc_index` = the bridge's ESC number (ESCs 32 and above, which `uint5` cannot hold, are
//!   not sent); `voltage` V and `current` A as recorded (float16); `temperature` = MOSFET
//!   temperature + 273.15 K, NaN when the ADC code is out of the table (the DSDL's "unknown");
//!   `rpm` = motor RPM under the bridge's settings, rounded, saturated to `int18`;
//!   `power_rating_pct` = output throttle %, rounded, 0..=127; `error_count` = how many frames
//!   of that ESC had a fault bit set in their status word since the bridge started (the
//!   decoder's checksum failures are not handed to outputs, so they are not in it).
//! - **esc.StatusExtended** (1036), the lower-rate half: right after an ESC's esc.Status, for
//!   its first frame and then for a frame that arrived [`EXTENDED_EVERY`] or more after the
//!   frame of its last one (4 a second at the ESC's 20). Fields: `input_pct` and `output_pct` =
//!   the input and output throttle %, rounded, 0..=100; `status_flags` = the frame's status word
//!   as the ESC sent it (the fault bits of `hwfoc::Fault`); `esc_index` as in esc.Status;
//!   `motor_temperature_degC` = the record's `motor_temp_c`, rounded, where the ESC's protocol
//!   sends it (HW5), else 0, as `motor_angle` always is: HW-FOC and DataLink frames carry
//!   neither, and the DSDL has no "unknown" for them (a receiver logging motor temperature logs
//!   0 °C). A quantity the protocol does not carry is otherwise sent as the DSDL's unknown
//!   where it has one (NaN for the float16 fields), else 0.
//! - **NodeStatus** (341), every second from the first poll: `uptime_sec` since the output was
//!   opened; `mode` OPERATIONAL; `health` OK, or WARNING while an ESC that was heard is silent
//!   or the last frame of a live ESC had a fault bit set; `vendor_specific_status_code` = bit
//!   `i` set while ESC `i` (0..=15) is live.
//!
//! Both are broadcasts from the node id of [`DronecanOptions::node_id`] (default
//! [`DEFAULT_NODE_ID`]), each message type with its own transfer id counter.
//!
//! # The adapter
//!
//! Opened with [`hwfoc_ports::serial::open`] (ptys too) at [`DronecanOptions::baud`] (default
//! [`DEFAULT_BAUD`]; adapters on USB CDC such as CANable ignore it, an adapter on a real UART
//! needs its own: at 115200 baud a link carries about 140 esc.Status a second), then set up
//! with `C`, `S<code>`, `O` (see [`slcan`]). What the adapter answers is read and ignored
//! (refusals, BEL, counted in [`DronecanOutput::refusals`]). A write that fails because the
//! port is gone is [`OutputError::Lost`]; the port is reopened (and set up again) at a later
//! poll, as [`crate::port::Retry`] says. A write that times out (the adapter does not take
//! bytes) is [`OutputError::Send`] and the port is kept. Every error returned is also counted
//! in [`OutputStats::errors`].
//!
//! # Encoding
//!
//! The messages are the codec's ([`hwfoc::dronecan`]: [`EscStatus`], [`EscStatusExtended`],
//! [`NodeStatus`], their data type ids and signatures in [`hwfoc::dronecan::Kind`]) and so are
//! their frames ([`Message::frames`]: CAN id, tail bytes, the signature-seeded transfer CRC),
//! all checked against pydronecan's own frames; only SLCAN ([`slcan`]) is the bridge's.
//! float16 fields are converted as pydronecan and libuavcan convert (what the receivers people
//! use do): rounded to nearest with ties away from zero, ±infinity saturated to ±65504 (DSDL's
//! cast), NaN sent as `0x7FFF`. (The output used the `half` crate before: ties to even,
//! infinity kept, NaN `0x7E00`.)
//!
//! The crates.io crates were read first: `dronecan` 0.2.0 (MPL-2.0) only
//! reassembles received transfers and parses CAN IDs: no transmit-side splitting, no DSDL
//! types. `David-OConnor/dronecan` on GitHub (0.1.0, same name) is tied to STM32's
//! FD-CAN peripheral and has no `esc.Status`. `slcan` 0.1.3 (2020) is built on the unmaintained
//! `serial` crate and `mini-slcan` / `serial-can` are codecs of a few lines of what
//! [`slcan::push_extended`] does. `canadensis` is Cyphal (UAVCAN v1), another transport.

pub mod dsdl;
pub use hwfoc_ports::can::slcan;

use std::time::{Duration, Instant};

use hwfoc::Telemetry;
use hwfoc::dronecan::Message;
use serialport::SerialPort;

use crate::output::{Output, OutputError, OutputStats, SILENT_AFTER, Update};
use crate::port::{PortOptions, ReopeningPort, Setup};
use dsdl::{EscStatus, EscStatusExtended, Health, NodeStatus};

/// The default node id: outside the usual flight controller's (10) and the allocator's range
/// of dynamically allocated peripherals (125 down), below the tools' 126 and 127.
pub const DEFAULT_NODE_ID: u8 = 100;
/// The default CAN bitrate, bit/s: what ArduPilot and PX4 use.
pub const DEFAULT_BITRATE: u32 = 1_000_000;
/// The default serial speed of the adapter, baud (ignored by USB CDC adapters).
pub const DEFAULT_BAUD: u32 = 115_200;
/// The transfer priority of every message: 16, DroneCAN's "medium" (0 highest, 31 lowest).
pub const PRIORITY: u8 = 16;
/// How often NodeStatus is sent.
pub const NODE_STATUS_EVERY: Duration = Duration::from_secs(1);
/// The shortest time between the frames of two esc.StatusExtended of one ESC.
pub const EXTENDED_EVERY: Duration = Duration::from_millis(250);
/// How many ESC numbers DroneCAN's `esc_index` (a `uint5`) holds: ESCs 0 to 31 are bridged.
/// A limit of the message, not of the toolkit (which numbers up to [`hwfoc_io::MAX_ESCS`]).
pub const ESC_INDEX_COUNT: usize = 32;

/// The node's settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DronecanOptions {
    /// The node id, 1..=127 (default [`DEFAULT_NODE_ID`]).
    pub node_id: u8,
    /// The serial speed of the adapter (default [`DEFAULT_BAUD`]).
    pub baud: u32,
}

impl Default for DronecanOptions {
    fn default() -> Self {
        DronecanOptions {
            node_id: DEFAULT_NODE_ID,
            baud: DEFAULT_BAUD,
        }
    }
}

/// Where the node's CAN frames go: an SLCAN adapter's serial port, and the bus's bitrate.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SlcanTarget {
    /// The serial port (`/dev/ttyACM0`, `COM5`, `/dev/pts/3`).
    pub port: String,
    /// The CAN bitrate, bit/s: one of [`slcan::BITRATES`].
    pub bitrate: u32,
}

impl SlcanTarget {
    /// Parses `slcan:PORT[:BITRATE]`; BITRATE in bit/s (`500000`), or with `k` or `M`
    /// (`500k`, `1M`); default [`DEFAULT_BITRATE`]. A bitrate SLCAN has no code for is an error
    /// naming those it has.
    pub fn parse(spec: &str) -> Result<SlcanTarget, OutputError> {
        let err = |reason: String| OutputError::Open {
            output: spec.to_string(),
            reason,
        };
        let rest = spec.strip_prefix("slcan:").ok_or_else(|| {
            err("expected slcan:PORT[:BITRATE] (an SLCAN serial CAN adapter)".to_string())
        })?;
        let (port, bitrate) = match rest.rsplit_once(':') {
            Some((port, bitrate)) => (port, parse_bitrate(bitrate).map_err(err)?),
            None => (rest, DEFAULT_BITRATE),
        };
        if port.is_empty() {
            return Err(err("no port: expected slcan:PORT[:BITRATE]".to_string()));
        }
        Ok(SlcanTarget {
            port: port.to_string(),
            bitrate,
        })
    }
}

impl std::fmt::Display for SlcanTarget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "slcan:{}:{}", self.port, self.bitrate)
    }
}

/// A CAN bitrate with an SLCAN code, from `1000000`, `1000k` or `1M`.
fn parse_bitrate(text: &str) -> Result<u32, String> {
    let (digits, unit) = match text.as_bytes().last() {
        Some(b'k' | b'K') => (&text[..text.len() - 1], 1_000),
        Some(b'M' | b'm') => (&text[..text.len() - 1], 1_000_000),
        _ => (text, 1),
    };
    let supported = || {
        slcan::BITRATES
            .iter()
            .map(u32::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    };
    let bitrate = digits
        .parse::<u32>()
        .ok()
        .and_then(|n| n.checked_mul(unit))
        .ok_or_else(|| {
            format!(
                "bad CAN bitrate {text:?}: SLCAN takes {} bit/s",
                supported()
            )
        })?;
    match slcan::bitrate_code(bitrate) {
        Some(_) => Ok(bitrate),
        None => Err(format!(
            "CAN bitrate {bitrate} bit/s has no SLCAN code: SLCAN takes {} bit/s",
            supported()
        )),
    }
}

/// One ESC as the node knows it.
#[derive(Debug, Clone, Default)]
struct Esc {
    /// When its last frame arrived.
    heard: Option<Instant>,
    /// Its last frame had a fault bit set.
    fault: bool,
    /// Frames with a fault bit set so far.
    error_count: u32,
    /// The esc.Status and esc.StatusExtended of the frame to send at the next poll, and when
    /// that frame arrived.
    pending: Option<(EscStatus, EscStatusExtended, Instant)>,
    /// The arrival of the frame of the last esc.StatusExtended sent.
    extended_sent: Option<Instant>,
}

/// The DroneCAN output (see the [module documentation](self)).
pub struct DronecanOutput {
    name: String,
    target: SlcanTarget,
    options: DronecanOptions,
    port: ReopeningPort,
    opened: Instant,
    next_node_status: Option<Instant>,
    escs: Vec<Esc>,
    esc_transfer_id: u8,
    extended_transfer_id: u8,
    node_transfer_id: u8,
    stats: OutputStats,
    frames: u64,
    refusals: u64,
    not_sent: u64,
    out: Vec<u8>,
}

impl std::fmt::Debug for DronecanOutput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DronecanOutput")
            .field("name", &self.name)
            .field("options", &self.options)
            .field("connected", &self.port.is_open())
            .finish_non_exhaustive()
    }
}

impl DronecanOutput {
    /// Opens the adapter and sets it up. An error if the node id is not 1..=127 or the port
    /// cannot be opened now ([`OutputError::Open`]); later losses are reopened.
    pub fn open(
        target: SlcanTarget,
        options: DronecanOptions,
    ) -> Result<DronecanOutput, OutputError> {
        let name = format!("dronecan {target}");
        let open_err = |reason: String| OutputError::Open {
            output: target.to_string(),
            reason,
        };
        if !(1..=127).contains(&options.node_id) {
            return Err(open_err(format!(
                "node id {} out of range: a DroneCAN node id is 1 to 127",
                options.node_id
            )));
        }
        let code = slcan::bitrate_code(target.bitrate).ok_or_else(|| {
            open_err(format!(
                "CAN bitrate {} bit/s has no SLCAN code",
                target.bitrate
            ))
        })?;
        let setup: Setup = Box::new(move |port| set_up_adapter(port, code));
        let port = ReopeningPort::open(
            &target.port,
            options.baud,
            PortOptions {
                setup: Some(setup),
                drain: true,
            },
        )
        .map_err(open_err)?;
        let now = Instant::now();
        Ok(DronecanOutput {
            name,
            target,
            options,
            port,
            opened: now,
            next_node_status: None,
            escs: vec![Esc::default(); ESC_INDEX_COUNT],
            esc_transfer_id: 0,
            extended_transfer_id: 0,
            node_transfer_id: 0,
            stats: OutputStats::default(),
            frames: 0,
            refusals: 0,
            not_sent: 0,
            out: Vec::with_capacity(256),
        })
    }

    /// The adapter as given.
    pub fn target(&self) -> &SlcanTarget {
        &self.target
    }

    /// Whether the adapter is open now (false between a loss and its reopening).
    pub fn connected(&self) -> bool {
        self.port.is_open()
    }

    /// CAN frames written so far ([`OutputStats::messages`] counts transfers: an esc.Status is
    /// three frames, an esc.StatusExtended and a NodeStatus one each).
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// How many times a lost adapter was opened again.
    pub fn reopens(&self) -> u64 {
        self.port.reopens()
    }

    /// Commands the adapter refused (BEL answers), e.g. frames it could not send on the bus.
    pub fn refusals(&self) -> u64 {
        self.refusals
    }

    /// ESC frames not sent: their ESC number is 32 or more, or they were still waiting when the
    /// adapter was lost and too old ([`SILENT_AFTER`]) once it was back.
    pub fn not_sent(&self) -> u64 {
        self.not_sent
    }

    /// The NodeStatus at `now`.
    fn node_status(&self, now: Instant) -> NodeStatus {
        let mut live_mask = 0u16;
        let mut warning = false;
        for (i, esc) in self.escs.iter().enumerate() {
            let Some(heard) = esc.heard else { continue };
            let live = now.saturating_duration_since(heard) < SILENT_AFTER;
            if live {
                if i < 16 {
                    live_mask |= 1 << i;
                }
                warning |= esc.fault;
            } else {
                warning = true;
            }
        }
        NodeStatus {
            uptime_sec: u32::try_from(now.saturating_duration_since(self.opened).as_secs())
                .unwrap_or(u32::MAX),
            health: if warning { Health::Warning } else { Health::Ok } as u8,
            mode: dsdl::MODE_OPERATIONAL,
            sub_mode: 0,
            vendor_specific_status_code: live_mask,
        }
    }

    /// Writes `self.out` (the lines of whole transfers); an error makes the port lost or not.
    fn write_out(&mut self, now: Instant) -> Result<(), OutputError> {
        match self.port.write(&self.out, now) {
            Ok(()) => {
                self.stats.bytes += self.out.len() as u64;
                Ok(())
            }
            Err(failure) => match failure.error(&self.name) {
                Some(error) => {
                    self.stats.errors += 1;
                    Err(error)
                }
                None => Ok(()),
            },
        }
    }

    /// Appends the SLCAN lines of one transfer of `message` (a broadcast from the node at
    /// [`PRIORITY`]) to `self.out`.
    fn push_transfer(&mut self, message: impl Into<Message>, transfer_id: u8) {
        let message = message.into();
        for frame in message.frames(PRIORITY, self.options.node_id, 0, transfer_id) {
            slcan::push_extended(&mut self.out, frame.id(), frame.data());
            self.frames += 1;
        }
    }

    /// Reads and drops what the adapter answered, counting refusals.
    fn drain(&mut self) {
        let Some(port) = self.port.port() else {
            return;
        };
        let mut buf = [0u8; 256];
        for _ in 0..16 {
            let waiting = port.bytes_to_read().unwrap_or(0) as usize;
            if waiting == 0 {
                break;
            }
            let n = waiting.min(buf.len());
            match port.read(&mut buf[..n]) {
                Ok(n) if n > 0 => {
                    self.refusals += buf[..n].iter().filter(|&&b| b == slcan::BEL).count() as u64
                }
                _ => break,
            }
        }
    }
}

/// The transfer id to use from a message type's counter, which moves on (5 bits, wrapping).
fn next_transfer_id(counter: &mut u8) -> u8 {
    let tid = *counter;
    *counter = (tid + 1) & 0x1F;
    tid
}

/// Sets an SLCAN adapter just opened up, at the CAN bitrate of SLCAN `code`.
fn set_up_adapter(port: &mut dyn SerialPort, code: u8) -> Result<(), String> {
    // Whatever was waiting is from before us.
    let _ = port.clear(serialport::ClearBuffer::Input);
    port.write_all(&slcan::setup(code))
        .and_then(|()| port.flush())
        .map_err(|e| format!("cannot set the SLCAN adapter up: {e}"))
}

impl Output for DronecanOutput {
    fn name(&self) -> &str {
        &self.name
    }

    fn update(&mut self, update: &Update<'_>) {
        let Some(esc) = self.escs.get_mut(usize::from(update.esc)) else {
            self.not_sent += 1;
            self.stats.left_out.add(update.esc);
            return;
        };
        let r = update.record;
        let fault = r.status.is_some_and(|s| s.0 != 0);
        esc.heard = Some(update.arrived);
        esc.fault = fault;
        if fault {
            esc.error_count = esc.error_count.wrapping_add(1);
        }
        let status = EscStatus {
            error_count: esc.error_count,
            voltage: r.voltage_v.unwrap_or(f32::NAN),
            current: r.current_a.unwrap_or(f32::NAN),
            temperature: r.mos_temp_c.map_or(f32::NAN, |c| c + 273.15),
            rpm: r.rpm.map_or(0, |rpm| rpm.round() as i32),
            power_rating_pct: r
                .throttle_out_pct
                .map_or(0, |pct| pct.round().clamp(0.0, 127.0) as u8),
            esc_index: update.esc,
        };
        let percent = |pct: Option<f32>| pct.map_or(0, |pct| pct.round().clamp(0.0, 100.0) as u8);
        let extended = EscStatusExtended {
            input_pct: percent(r.throttle_in_pct),
            output_pct: percent(r.throttle_out_pct),
            motor_temperature_deg_c: r
                .motor_temp_c
                .map_or(0, |c| c.round().clamp(-256.0, 255.0) as i16),
            motor_angle: 0,
            status_flags: u32::from(update.frame.status().unwrap_or_default().0),
            esc_index: update.esc,
        };
        if esc
            .pending
            .replace((status, extended, update.arrived))
            .is_some()
        {
            self.stats.superseded += 1;
        }
    }

    fn poll(&mut self, now: Instant) -> Result<(), OutputError> {
        if !self.port.is_open() {
            if !self.port.reopen_if_due(now) {
                return Ok(());
            }
            // A NodeStatus straight away: the bus learns the node is back.
            self.next_node_status = Some(now);
        }
        self.drain();
        for i in 0..self.escs.len() {
            let Some((status, extended, arrived)) = self.escs[i].pending.take() else {
                continue;
            };
            if now.saturating_duration_since(arrived) >= SILENT_AFTER {
                self.not_sent += 1;
                continue;
            }
            self.out.clear();
            let tid = next_transfer_id(&mut self.esc_transfer_id);
            self.push_transfer(status, tid);
            let extended_due = self.escs[i]
                .extended_sent
                .is_none_or(|sent| arrived.saturating_duration_since(sent) >= EXTENDED_EVERY);
            if extended_due {
                self.escs[i].extended_sent = Some(arrived);
                let tid = next_transfer_id(&mut self.extended_transfer_id);
                self.push_transfer(extended, tid);
            }
            self.write_out(now)?;
            self.stats.messages += 1 + u64::from(extended_due);
            self.stats.latency.add(Instant::now() - arrived);
        }
        if self.next_node_status.is_none_or(|t| now >= t) {
            let node_status = self.node_status(now);
            self.out.clear();
            let tid = next_transfer_id(&mut self.node_transfer_id);
            self.push_transfer(node_status, tid);
            // A second after this one was due; a second after now if far behind.
            let next = self.next_node_status.unwrap_or(now) + NODE_STATUS_EVERY;
            self.next_node_status = Some(if next <= now {
                now + NODE_STATUS_EVERY
            } else {
                next
            });
            self.write_out(now)?;
            self.stats.messages += 1;
        }
        Ok(())
    }

    fn stats(&self) -> &OutputStats {
        &self.stats
    }

    fn carries(&self) -> usize {
        ESC_INDEX_COUNT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What `push_transfer` writes for an esc.Status from node 100 with transfer id 5: the CAN
    /// id of a broadcast at [`PRIORITY`] and the three frames pydronecan 1.0.27 makes of the
    /// same message (the transfer CRC 0xC75C first), as SLCAN lines. (These were the tests of
    /// the bridge's own transport before it used the codec's.)
    #[test]
    fn esc_status_lines_as_pydronecan() {
        // esc.Status of dsdl.rs's test: 7, 16.5 V, -2.25 A, 313.15 K, -1234 rpm, 55 %, ESC 3.
        let status = dsdl::tests::example_esc_status();
        let mut out = Vec::new();
        for frame in Message::from(status).frames(PRIORITY, 100, 0, 5) {
            slcan::push_extended(&mut out, frame.id(), frame.data());
        }
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "T10040A6485CC7070000002085\r\
             T10040A6484C80C0E55C2EFB25\r\
             T10040A643DB8C45\r"
        );
        // NodeStatus fits one frame: no CRC, start and end set.
        let node = NodeStatus {
            uptime_sec: 123_456,
            health: Health::Warning as u8,
            mode: dsdl::MODE_OPERATIONAL,
            sub_mode: 0,
            vendor_specific_status_code: 0xABCD,
        };
        let frames: Vec<_> = Message::from(node).frames(PRIORITY, 100, 0, 31).collect();
        assert_eq!(frames.len(), 1);
        assert_eq!(frames[0].id(), 0x1001_5564);
        assert_eq!(
            frames[0].data(),
            [0x40, 0xE2, 0x01, 0x00, 0x40, 0xCD, 0xAB, 0xDF]
        );
    }
}
