//! Ctrl-C while an input is read whole (`hwfoc.read`, `hwfoc.summary`): a handler that looks
//! for signals between batches, so that an endless input (`/dev/zero`, a FIFO) can be stopped.

use std::any::Any;
use std::time::{Duration, Instant};

use hwfoc::Settings;
use hwfoc::foc::DataFrame;
use hwfoc::telemetry::AnyFrame;
use hwfoc_io::{Handler, InputError, LaterPart, Record};
use pyo3::Python;

use crate::source::Raised;

/// How often signals are looked for, at most.
const EVERY: Duration = Duration::from_millis(50);

/// `H`, stopping with the exception a signal handler raised (`KeyboardInterrupt`), which
/// [`crate::errors::input`] raises again as itself.
pub struct Interruptible<H> {
    /// The handler within.
    pub inner: H,
    next: Instant,
}

impl<H> Interruptible<H> {
    /// `inner`, interruptible.
    pub fn new(inner: H) -> Self {
        Interruptible {
            inner,
            next: Instant::now() + EVERY,
        }
    }
}

impl<H: Handler> Handler for Interruptible<H> {
    type Error = H::Error;
    const TAKES_RUNS: bool = H::TAKES_RUNS;

    #[inline]
    fn record(&mut self, record: &Record) {
        self.inner.record(record);
    }

    #[inline]
    fn info(&mut self, esc: u8, t: Option<f64>, info: &hwfoc::telemetry::Info) {
        self.inner.info(esc, t, info);
    }

    #[inline]
    fn frame(&mut self, esc: u8, t: Option<f64>, frame: &AnyFrame, settings: &Settings) {
        self.inner.frame(esc, t, frame, settings);
    }

    #[inline]
    fn untimed_data(&mut self, esc: u8, frames: &[DataFrame], settings: &Settings) {
        self.inner.untimed_data(esc, frames, settings);
    }

    fn end_batch(&mut self, live: bool) -> Result<(), Self::Error> {
        self.inner.end_batch(live)?;
        let now = Instant::now();
        if now < self.next {
            return Ok(());
        }
        self.next = now + EVERY;
        // Signal handlers run on the main thread only: elsewhere this finds nothing.
        match Python::attach(|py| py.check_signals()) {
            Ok(()) => Ok(()),
            Err(e) => Err(InputError::Read {
                input: "the inputs".to_string(),
                source: std::io::Error::other(Raised(e)),
            }
            .into()),
        }
    }

    fn fork(&self) -> Option<Box<dyn LaterPart>> {
        self.inner.fork()
    }

    fn join(&mut self, later: Box<dyn Any + Send>) {
        self.inner.join(later);
    }
}
