//! Every frame of every ESC to every output: the bridge's [`Handler`].

use std::collections::BTreeSet;
use std::time::Instant;

use hwfoc::Settings;
use hwfoc::telemetry::AnyFrame;
use hwfoc_io::{Handler, InputError, Record};

use crate::output::{Output, OutputError, Update};

/// The outputs of a bridge, fed by [`hwfoc_io::PortStreams::feed`] (live ports, virtual
/// ESCs) or [`hwfoc_io::Sources::run`] (recordings, through [`crate::replay::Replay`]).
pub struct Fanout {
    outputs: Vec<Box<dyn Output>>,
    arrived: Instant,
    frames: u64,
    /// The ESCs heard, by number.
    escs: BTreeSet<u8>,
}

impl Fanout {
    /// Hands frames to `outputs`.
    pub fn new(outputs: Vec<Box<dyn Output>>) -> Fanout {
        Fanout {
            outputs,
            arrived: Instant::now(),
            frames: 0,
            escs: BTreeSet::new(),
        }
    }

    /// The frames fed next were completed by a read that returned at `arrived`.
    pub fn arrived(&mut self, arrived: Instant) {
        self.arrived = arrived;
    }

    /// Asks every output to send what is due at `now`; `on_error` gets each output's failure
    /// (the others are polled all the same).
    pub fn poll(&mut self, now: Instant, mut on_error: impl FnMut(OutputError)) {
        for output in &mut self.outputs {
            if let Err(e) = output.poll(now) {
                on_error(e);
            }
        }
    }

    /// The outputs, for their names and counters.
    pub fn outputs(&self) -> &[Box<dyn Output>] {
        &self.outputs
    }

    /// Data frames handed on.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// The ESCs heard, by number (CAN ESCs numbered by node id may start at 10).
    pub fn escs(&self) -> &BTreeSet<u8> {
        &self.escs
    }
}

impl Handler for Fanout {
    type Error = InputError;

    fn frame(&mut self, esc: u8, t: Option<f64>, frame: &AnyFrame, settings: &Settings) {
        let AnyFrame::Data(frame) = frame else {
            return;
        };
        let record = Record::new(t, esc, frame, settings);
        let update = Update {
            esc,
            frame,
            record: &record,
            settings,
            arrived: self.arrived,
        };
        for output in &mut self.outputs {
            output.update(&update);
        }
        self.frames += 1;
        self.escs.insert(esc);
    }
}
