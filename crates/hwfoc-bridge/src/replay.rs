//! Recordings replayed in real time: each frame is handed on when as much time has passed since
//! the first frame as passed between them on the wire.

use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use hwfoc::{Decoded, Settings};
use hwfoc_io::energy::NOMINAL_PERIOD_S;
use hwfoc_io::{Handler, InputError};

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

/// A [`Handler`] that holds each frame back until its time has come, then hands it to the
/// [`Fanout`]; the outputs are polled meanwhile. Frames with receive times keep their spacing
/// (their times are taken in the order the inputs give them: a frame due earlier than the one
/// before it goes at once); frames of an input without times come one per ESC every
/// [`NOMINAL_PERIOD_S`], the protocol's frame period.
pub struct Replay<'a, E> {
    fanout: &'a mut Fanout,
    stop: &'a AtomicBool,
    on_error: E,
    /// The first timed frame's time and when it was handed on.
    origin: Option<(f64, Instant)>,
    /// When the replay started, for untimed frames.
    start: Instant,
    /// Untimed frames handed on so far, per ESC.
    untimed: Vec<u32>,
}

impl<'a, E: FnMut(OutputError)> Replay<'a, E> {
    /// Replays into `fanout` until the inputs end or `stop` is set; `on_error` gets the
    /// outputs' failures.
    pub fn new(fanout: &'a mut Fanout, stop: &'a AtomicBool, on_error: E) -> Self {
        Replay {
            fanout,
            stop,
            on_error,
            origin: None,
            start: Instant::now(),
            untimed: Vec::new(),
        }
    }

    /// When a frame of `esc` received at `t` is due.
    fn due(&mut self, esc: u8, t: Option<f64>) -> Instant {
        match t {
            Some(t) => {
                let (t0, at) = *self.origin.get_or_insert((t, Instant::now()));
                at + Duration::from_secs_f64((t - t0).clamp(0.0, 1e9))
            }
            None => {
                let esc = usize::from(esc);
                if self.untimed.len() <= esc {
                    self.untimed.resize(esc + 1, 0);
                }
                let k = self.untimed[esc];
                self.untimed[esc] += 1;
                self.start + Duration::from_secs_f64(f64::from(k) * NOMINAL_PERIOD_S)
            }
        }
    }

    /// Polls the outputs until `due` (or a stop).
    fn wait(&mut self, due: Instant) {
        loop {
            let now = Instant::now();
            self.fanout.poll(now, &mut self.on_error);
            if now >= due || self.stop.load(Ordering::Relaxed) {
                return;
            }
            std::thread::sleep((due - now).min(POLL));
        }
    }
}

impl<E: FnMut(OutputError)> Handler for Replay<'_, E> {
    type Error = ReplayError;

    fn frame(&mut self, esc: u8, t: Option<f64>, decoded: &Decoded, settings: &Settings) {
        if self.stop.load(Ordering::Relaxed) {
            return;
        }
        let due = self.due(esc, t);
        self.wait(due);
        self.fanout.arrived(Instant::now());
        self.fanout.frame(esc, t, decoded, settings);
        self.fanout.poll(Instant::now(), &mut self.on_error);
    }

    fn end_batch(&mut self, _live: bool) -> Result<(), ReplayError> {
        if self.stop.load(Ordering::Relaxed) {
            return Err(ReplayError::Stopped);
        }
        Ok(())
    }
}
