//! Recordings replayed in real time: each frame is handed on when as much time has passed since
//! the first frame as passed between them on the wire; or, for outputs that are files
//! ([`Replay::as_fast_as_possible`]), at once, on a clock of the recording's own times (the
//! outputs are polled as the clock passes, so they send what they would have sent, timed as
//! they would have timed it). A discontinuity of an ESC's receive
//! clock ([`Step`]: a step back, or a jump forward its packet numbers do not explain, such as
//! a computer that booted in 1970 and then synced) is replayed as one frame period: the replay
//! never waits for a clock that jumped years ahead. Each ESC's clock is followed on its own: a
//! step back seen on one ESC moves that ESC's origin only, so the frames of the others still
//! before the step are not held back by it. An ESC's first frame is measured from the
//! frame before it of any ESC: more than a second after it (every ESC silent, or a jump) is
//! one frame period.

use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use hwfoc::telemetry::{AnyFrame, Telemetry};
use hwfoc::{Protocol, Settings};
use hwfoc_io::energy::nominal_period_s;
use hwfoc_io::{Handler, InputError};
use hwfoc_ports::clock::Step;

use crate::fanout::Fanout;
use crate::output::OutputError;

/// How often the outputs are polled while a frame waits for its time.
pub const POLL: Duration = Duration::from_millis(10);

/// Why a replay ended early.
#[derive(Debug)]
pub enum ReplayError {
    /// An input could not be read.
    Input(InputError),
    /// Ctrl-C or SIGTERM.
    Stopped,
}

impl From<InputError> for ReplayError {
    fn from(e: InputError) -> Self {
        ReplayError::Input(e)
    }
}

impl fmt::Display for ReplayError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReplayError::Input(e) => e.fmt(f),
            ReplayError::Stopped => f.write_str("stopped"),
        }
    }
}

impl std::error::Error for ReplayError {}

/// An ESC's last timed frame, as replayed.
#[derive(Debug, Clone, Copy)]
struct Timed {
    /// Its receive time.
    t: f64,
    /// Its packet number, of a data frame.
    packet: Option<u32>,
    /// Seconds after the replay's first instant it was due.
    after: f64,
    /// The receive time replayed at the replay's first instant, for this ESC: a frame at `t`
    /// is due `t - origin` seconds after it.
    origin: f64,
}

/// A [`Handler`] that holds each frame back until its time has come, then hands it to the
/// [`Fanout`]; the outputs are polled meanwhile. Frames with receive times keep their spacing
/// (their times are taken in the order the inputs give them: a frame due earlier than the one
/// before it goes at once); frames of an input without times come one per ESC every frame
/// period of its protocol ([`nominal_period_s`]).
pub struct Replay<'a, E> {
    fanout: &'a mut Fanout,
    stop: &'a AtomicBool,
    on_error: E,
    /// The instant the first timed frame was replayed at: every due time is counted from it.
    at: Option<Instant>,
    /// Per ESC, its last timed frame ([`Timed`]). Each ESC has its own origin, moved at each
    /// discontinuity of its own clock only: a clock that steps back on every ESC, one ESC
    /// after another, never holds the other ESCs back by the step.
    last: Vec<Option<Timed>>,
    /// The last timed frame of any ESC: what an ESC's first frame is measured from (without a
    /// packet number in common, a step over [`hwfoc_ports::clock::MAX_STEP_S`] is a jump).
    latest: Option<Timed>,
    /// When the replay started, for untimed frames.
    start: Instant,
    /// Untimed frames handed on so far, per ESC.
    untimed: Vec<u32>,
    /// Without pacing, the instant the replay's clock shows (see
    /// [`Replay::as_fast_as_possible`]); `None`: real time.
    clock: Option<Instant>,
}

impl<'a, E: FnMut(OutputError)> Replay<'a, E> {
    /// Replays into `fanout` until the inputs end or `stop` is set; `on_error` gets the
    /// outputs' failures.
    pub fn new(fanout: &'a mut Fanout, stop: &'a AtomicBool, on_error: E) -> Self {
        Replay {
            fanout,
            stop,
            on_error,
            at: None,
            last: Vec::new(),
            latest: None,
            start: Instant::now(),
            untimed: Vec::new(),
            clock: None,
        }
    }

    /// Hands every frame on at once, without waiting for its time: for outputs that are files
    /// (a telemetry log), which take what a real-time replay would have given them, with the
    /// same times, in a fraction of it. The outputs see a clock that moves from frame to frame
    /// as the recording's times do, and are polled every [`POLL`] of it.
    pub fn as_fast_as_possible(mut self) -> Self {
        self.clock = Some(self.start);
        self
    }

    /// When a frame of `esc` received at `t` is due; `protocol` is a data frame's, `packet` its
    /// packet number.
    fn due(
        &mut self,
        esc: u8,
        t: Option<f64>,
        protocol: Option<Protocol>,
        packet: Option<u32>,
    ) -> Instant {
        match t {
            Some(t) => {
                let esc = usize::from(esc);
                if self.last.len() <= esc {
                    self.last.resize(esc + 1, None);
                }
                let now = self.clock.unwrap_or_else(Instant::now);
                let at = *self.at.get_or_insert(now);
                let before = match self.last[esc] {
                    Some(own) => Some(own),
                    None => self.latest.map(|latest| Timed {
                        packet: None,
                        ..latest
                    }),
                };
                let origin = match before {
                    None => t,
                    Some(before) => {
                        let packets = before
                            .packet
                            .zip(packet)
                            .zip(protocol)
                            .and_then(|((a, b), p)| p.packets_between(a, b));
                        if Step::between(before.t, t, packets).is_discontinuity() {
                            // One frame period after the ESC's frame before.
                            t - (before.after + nominal_period_s(protocol))
                        } else {
                            before.origin
                        }
                    }
                };
                let after = (t - origin).clamp(0.0, 1e9);
                let timed = Timed {
                    t,
                    packet,
                    after,
                    origin,
                };
                self.last[esc] = Some(timed);
                self.latest = Some(timed);
                at + Duration::from_secs_f64(after)
            }
            None => {
                let esc = usize::from(esc);
                if self.untimed.len() <= esc {
                    self.untimed.resize(esc + 1, 0);
                }
                let k = self.untimed[esc];
                self.untimed[esc] += 1;
                self.start + Duration::from_secs_f64(f64::from(k) * nominal_period_s(protocol))
            }
        }
    }

    /// Polls the outputs until `due` (or a stop), and returns the instant: in real time, or on
    /// the replay's own clock, moved on to `due` (never back) and the outputs polled every
    /// [`POLL`] of it on the way.
    fn wait(&mut self, due: Instant) -> Instant {
        if let Some(clock) = self.clock {
            let mut now = clock;
            while now + POLL < due && !self.stop.load(Ordering::Relaxed) {
                now += POLL;
                self.fanout.poll(now, &mut self.on_error);
            }
            let now = now.max(due);
            self.clock = Some(now);
            return now;
        }
        loop {
            let now = Instant::now();
            self.fanout.poll(now, &mut self.on_error);
            if now >= due || self.stop.load(Ordering::Relaxed) {
                return now;
            }
            std::thread::sleep((due - now).min(POLL));
        }
    }
}

impl<E: FnMut(OutputError)> Handler for Replay<'_, E> {
    type Error = ReplayError;

    fn frame(&mut self, esc: u8, t: Option<f64>, frame: &AnyFrame, settings: &Settings) {
        if self.stop.load(Ordering::Relaxed) {
            return;
        }
        let (protocol, packet) = match frame {
            AnyFrame::Data(f) => (Some(f.protocol()), f.packet()),
            AnyFrame::Info(_) => (None, None),
        };
        let due = self.due(esc, t, protocol, packet);
        let now = self.wait(due);
        self.fanout.arrived(now);
        self.fanout.frame(esc, t, frame, settings);
        let now = self.clock.unwrap_or_else(Instant::now);
        self.fanout.poll(now, &mut self.on_error);
    }

    fn end_batch(&mut self, _live: bool) -> Result<(), ReplayError> {
        if self.stop.load(Ordering::Relaxed) {
            return Err(ReplayError::Stopped);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_jumped_clock_replays_as_one_frame_period() {
        let mut fanout = Fanout::new(Vec::new());
        let stop = AtomicBool::new(false);
        let mut replay = Replay::new(&mut fanout, &stop, |_| {});
        // 101 frames from 2026, one stamped in 2226, 98 more in 2026, then the clock set back
        // an hour (NTP): every frame comes a frame period after the one before.
        let start = 1_795_442_580.0;
        let mut times: Vec<f64> = (0..101).map(|k| start + f64::from(k) * 0.05).collect();
        times.push(8_000_000_000.0);
        times.extend((102..200).map(|k| start + f64::from(k) * 0.05));
        times.push(start - 3600.0);
        let dues: Vec<Instant> = times
            .iter()
            .enumerate()
            .map(|(k, &t)| replay.due(0, Some(t), Some(Protocol::HwFoc), Some(k as u32)))
            .collect();
        let first = dues[0];
        for (k, due) in dues.iter().enumerate() {
            let after = due.duration_since(first).as_secs_f64();
            assert!(
                (after - k as f64 * nominal_period_s(Some(Protocol::HwFoc))).abs() < 1e-6,
                "frame {k} due {after} s after the first"
            );
        }
    }

    #[test]
    fn a_new_esc_after_a_jump_waits_one_frame_period() {
        let mut fanout = Fanout::new(Vec::new());
        let stop = AtomicBool::new(false);
        let mut replay = Replay::new(&mut fanout, &stop, |_| {});
        let start = 1_795_442_580.0;
        let first = replay.due(0, Some(start), Some(Protocol::HwFoc), Some(0));
        let then = replay.due(0, Some(start + 0.05), Some(Protocol::HwFoc), Some(1));
        // ESC 1's first frame, stamped in 2226.
        let late = replay.due(1, Some(8_000_000_000.0), Some(Protocol::HwFoc), Some(0));
        let after = |due: Instant, first| due.duration_since(first).as_secs_f64();
        assert!((after(then, first) - 0.05).abs() < 1e-6);
        assert!(
            (after(late, first) - 0.1).abs() < 1e-6,
            "{}",
            after(late, first)
        );
        // ESC 1 heard half a second after ESC 0: its own time.
        let mut fanout = Fanout::new(Vec::new());
        let mut replay = Replay::new(&mut fanout, &stop, |_| {});
        let first = replay.due(0, Some(start), Some(Protocol::HwFoc), Some(0));
        let other = replay.due(1, Some(start + 0.5), Some(Protocol::HwFoc), Some(9));
        assert!((after(other, first) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn a_clock_stepping_back_on_every_esc_holds_none_back() {
        // 4 ESCs, 74 frames each 50 ms apart (3.7 s), the clock set back 10 s after frame 36,
        // ESC 0's first frame after the step handed on before the other ESCs' last ones
        // before it (the merge hands on the earliest time first).
        let mut fanout = Fanout::new(Vec::new());
        let stop = AtomicBool::new(false);
        let mut replay = Replay::new(&mut fanout, &stop, |_| {});
        let start = 1_795_442_580.0;
        let time = |k: u32| {
            let t = start + f64::from(k) * 0.05;
            if k >= 37 { t - 10.0 } else { t }
        };
        let mut order: Vec<(u8, u32)> = Vec::new();
        for k in 0..74 {
            for esc in 0..4 {
                order.push((esc, k));
            }
        }
        let first_after = order.iter().position(|&f| f == (0, 37)).unwrap();
        let moved = order.remove(first_after);
        order.insert(first_after - 3, moved);
        let dues: Vec<Instant> = order
            .iter()
            .map(|&(esc, k)| replay.due(esc, Some(time(k)), Some(Protocol::HwFoc), Some(k)))
            .collect();
        let first = dues[0];
        let last = dues
            .iter()
            .max()
            .unwrap()
            .duration_since(first)
            .as_secs_f64();
        assert!(
            last < 3.8,
            "the replay lasts {last} s for a 3.7 s recording"
        );
        // Each ESC keeps its own spacing across the step.
        for esc in 0..4 {
            let own: Vec<f64> = order
                .iter()
                .zip(&dues)
                .filter(|((e, _), _)| *e == esc)
                .map(|(_, due)| due.duration_since(first).as_secs_f64())
                .collect();
            for pair in own.windows(2) {
                assert!(
                    (pair[1] - pair[0] - 0.05).abs() < 1e-6,
                    "ESC {esc}: {pair:?}"
                );
            }
        }
    }
}
