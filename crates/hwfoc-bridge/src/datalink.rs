//! The DataLink role: up to eight ESCs merged into DataLink V2 frames on a 115200-baud serial
//! port, as the Hobbywing hub sends them to a flight controller.
//!
//! # When a frame is sent
//!
//! Each ESC has a slot: a short queue of its frames not yet sent. A DataLink frame carries the
//! oldest waiting frame of each ESC (an ESC with none waiting is sent empty: no stale value is
//! repeated, and an ESC that went silent stops being sent, which is how the DataLink protocol
//! says it). A frame is sent when something is waiting and [`Pacing::period`] has passed since
//! the previous frame (at once, after a pause), or earlier, as soon as [`Pacing::min_gap`] has
//! passed, while some ESC has a second frame waiting. So every frame of ESCs sending at the
//! protocol's 50 ms period gets through, at about the ESCs' own rate, even when a read brings
//! two frames of one ESC at once; only an ESC more than [`QUEUE`] frames ahead of the line
//! loses its oldest (counted as superseded).
//!
//! The gap matters to receivers: ArduPilot's DataLink driver reads only when exactly one
//! frame (160 bytes) is waiting, polling every 10 ms; frames sent back to back would be
//! discarded. [`Pacing::default`] keeps at least 10 ms of silence between frames.
//!
//! # What a frame carries
//!
//! Every format: an HW-FOC frame as received, another format's frame as the HW-FOC frame a hub
//! would have sent for it, its values converted back to HW-FOC's raw fields
//! ([`hub_record`](crate::hub_record), which says how, and what a field is where the format does
//! not carry its quantity).

use std::collections::VecDeque;
use std::io::Write;
use std::time::{Duration, Instant};

use hwfoc::datalink;
use hwfoc::foc::DataFrame;

use crate::hub_record::hub_record;
use crate::output::{Output, OutputError, OutputStats, Update};
use crate::port::{PortOptions, ReopeningPort};

/// When DataLink frames are sent (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pacing {
    /// The usual time from one frame to the next: the ESCs' own frame period.
    pub period: Duration,
    /// The shortest time from one frame's start to the next one's: the frame's own time on the
    /// line (160 bytes at 115200 baud, 13.9 ms) plus a silence receivers can see.
    pub min_gap: Duration,
}

impl Default for Pacing {
    fn default() -> Self {
        let frame_ns = datalink::FRAME_LEN as f64 * hwfoc::wire::byte_ns(datalink::BAUD_RATE);
        Pacing {
            period: Duration::from_millis(50),
            min_gap: Duration::from_nanos(frame_ns as u64) + Duration::from_millis(10),
        }
    }
}

/// The most frames of one ESC waiting to be sent.
pub const QUEUE: usize = 4;

/// Where the frames go.
enum Line {
    /// A serial port (or a pty), reopened when lost.
    Port(ReopeningPort),
    /// Any writer (tests, files).
    Writer(Box<dyn Write + Send>),
}

/// One ESC's slot: its newest frame and when it arrived.
#[derive(Debug, Clone, Copy)]
struct Slot {
    frame: DataFrame,
    arrived: Instant,
}

/// DataLink V2 frames of up to eight ESCs of any format (ESC `n` in channel `n`: an ESC is
/// sent in the channel of its ESC number, a CAN ESC's too; ESCs past 7 are not carried and are
/// counted in [`OutputStats::left_out`]).
pub struct DatalinkOutput {
    name: String,
    line: Line,
    pacing: Pacing,
    slots: [VecDeque<Slot>; datalink::CHANNELS],
    counter: u16,
    /// Each channel's packet counter, for formats without their own.
    packets: [u16; datalink::CHANNELS],
    last_sent: Option<Instant>,
    stats: OutputStats,
}

impl DatalinkOutput {
    /// DataLink frames on serial port `path` at 115200 baud, 8N1.
    pub fn open(path: &str, pacing: Pacing) -> Result<DatalinkOutput, OutputError> {
        let name = format!("datalink {path}");
        let port = ReopeningPort::open(
            path,
            datalink::BAUD_RATE,
            PortOptions {
                setup: None,
                drain: true,
            },
        )
        .map_err(|reason| OutputError::Open {
            output: name.clone(),
            reason,
        })?;
        Ok(DatalinkOutput::with_line(name, Line::Port(port), pacing))
    }

    /// DataLink frames written to `writer`, named `name` in messages.
    pub fn to_writer(name: &str, writer: Box<dyn Write + Send>, pacing: Pacing) -> Self {
        DatalinkOutput::with_line(name.to_string(), Line::Writer(writer), pacing)
    }

    fn with_line(name: String, line: Line, pacing: Pacing) -> DatalinkOutput {
        DatalinkOutput {
            name,
            line,
            pacing,
            slots: Default::default(),
            counter: 0,
            packets: [0; datalink::CHANNELS],
            last_sent: None,
            stats: OutputStats::default(),
        }
    }

    /// Frames of ESCs numbered 8 or more, which a DataLink frame has no channel for.
    pub fn escs_not_carried(&self) -> u64 {
        self.stats.left_out.frames
    }

    /// Whether the gap since the last frame is at least `gap`.
    fn waited(&self, now: Instant, gap: Duration) -> bool {
        self.last_sent
            .is_none_or(|last| now.saturating_duration_since(last) >= gap)
    }

    /// Sends the oldest waiting frame of each ESC as one DataLink frame.
    fn send(&mut self, now: Instant) -> Result<(), OutputError> {
        // The frames are taken whether or not they get out: a frame that could not be written
        // is lost, as on a real line, and the next one carries the next frames.
        let carried: [Option<Slot>; datalink::CHANNELS] =
            std::array::from_fn(|i| self.slots[i].pop_front());
        let frame = datalink::HubFrame {
            counter: self.counter,
            slots: carried.map(|slot| slot.map(|s| s.frame)),
        };
        let bytes = frame.encode();
        self.last_sent = Some(now);
        self.counter = self.counter.wrapping_add(1);
        self.write(&bytes, now)?;
        let written = Instant::now();
        self.stats.messages += 1;
        self.stats.bytes += bytes.len() as u64;
        for slot in carried.iter().flatten() {
            self.stats
                .latency
                .add(written.saturating_duration_since(slot.arrived));
        }
        Ok(())
    }

    fn write(&mut self, bytes: &[u8], now: Instant) -> Result<(), OutputError> {
        let name = &self.name;
        let failed = |reason: String| OutputError::Send {
            output: name.clone(),
            reason,
        };
        match &mut self.line {
            Line::Writer(w) => w
                .write_all(bytes)
                .and_then(|()| w.flush())
                .map_err(|e| failed(e.to_string())),
            Line::Port(port) => port.write(bytes, now).map_err(|failure| {
                failure
                    .error(name)
                    .unwrap_or_else(|| failed("the port is being reopened".into()))
            }),
        }
    }

    /// Counts a failure of `result`.
    fn count(&mut self, result: Result<(), OutputError>) -> Result<(), OutputError> {
        if result.is_err() {
            self.stats.errors += 1;
        }
        result
    }
}

impl Output for DatalinkOutput {
    fn name(&self) -> &str {
        &self.name
    }

    fn update(&mut self, update: &Update<'_>) {
        let Some(index) = Some(usize::from(update.esc)).filter(|&e| e < datalink::CHANNELS) else {
            self.stats.left_out.add(update.esc);
            return;
        };
        // A hub record is an HW-FOC frame: another format's is converted to one.
        let packet = self.packets[index];
        self.packets[index] = packet.wrapping_add(1);
        let frame = hub_record(update.frame, update.settings, packet);
        let queue = &mut self.slots[index];
        if queue.len() == QUEUE {
            queue.pop_front();
            self.stats.superseded += 1;
        }
        queue.push_back(Slot {
            frame,
            arrived: update.arrived,
        });
        // A second frame of this ESC is waiting: send as soon as the line allows. (A failure
        // here is counted; poll reports the state of the line at its next call.)
        if queue.len() >= 2 && self.waited(Instant::now(), self.pacing.min_gap) {
            let result = self.send(Instant::now());
            let _ = self.count(result);
        }
    }

    fn poll(&mut self, now: Instant) -> Result<(), OutputError> {
        let waiting = self.slots.iter().map(VecDeque::len).max().unwrap_or(0);
        let due = match waiting {
            0 => false,
            1 => self.waited(now, self.pacing.period),
            _ => self.waited(now, self.pacing.min_gap),
        };
        if due {
            let result = self.send(now);
            return self.count(result);
        }
        Ok(())
    }

    fn stats(&self) -> &OutputStats {
        &self.stats
    }

    fn carries(&self) -> usize {
        datalink::CHANNELS
    }
}
