//! A file's CAN buses read ahead, before it is read for its records: where each ESC of each bus
//! is at the end of the file, so that its number is fixed for the whole file (a node that
//! answers GetEscID late keeps one number) and two ESCs that claim one throttle channel are
//! told of once (`stream/can.rs`'s [`BusPlan`]).

use std::collections::VecDeque;

use super::Sources;
use crate::input::{Input, InputFormat};
use crate::notice::Notice;
use crate::stream::{BusLearner, BusPlan, no_status};

impl Sources {
    /// Reads ahead the CAN buses of the inputs that can be read twice (candump logs and
    /// recordings given as files), bus by bus as their streams are named (the interfaces of
    /// recordings given together that name one bus are one bus), and tells of the ESCs that
    /// claim a throttle channel another ESC of their bus holds.
    pub(super) fn plan_buses(&mut self, inputs: &mut VecDeque<Input>) {
        // Each bus by name, in the order first met, with the input that last carried it.
        let mut buses: Vec<(String, BusLearner, usize)> = Vec::new();
        for (k, input) in inputs.iter_mut().enumerate() {
            let format = input.format();
            if !(format == InputFormat::CANDUMP || format == InputFormat::RECORDING)
                || !input.rewind()
            {
                continue;
            }
            let mut first = true;
            // An error is met again when the input is read, and reported then.
            while let Ok(Some(batch)) = input.next_batch() {
                let stream = batch.stream;
                if first && !(0..input.streams()).any(|s| input.is_can(s)) {
                    // A recording of serial ports only.
                    break;
                }
                first = false;
                if !input.is_can(stream) {
                    continue;
                }
                let name = input.stream_name(stream);
                let bus = match buses.iter().position(|(n, ..)| *n == name) {
                    Some(i) => i,
                    None => {
                        buses.push((name, BusLearner::new(), k));
                        buses.len() - 1
                    }
                };
                let Some(batch) = input.current_batch() else {
                    continue;
                };
                buses[bus].1.feed(batch.bytes, batch.times);
                buses[bus].2 = k;
            }
            input.rewind();
        }
        for (name, learner, k) in buses {
            let bus = learner.bus();
            let plan = learner.plan();
            let mut messages: Vec<String> = plan.clashes.iter().map(|c| c.to_string()).collect();
            // A bus of stray frames says nothing; one of error frames, its likely cause.
            if plan.is_empty() && bus.error_frames() > 0 {
                messages.push(no_status(&bus));
            }
            let input = &mut inputs[k];
            for message in messages {
                let notice = Notice::CanBus {
                    input: input.name().to_string(),
                    interface: name.clone(),
                    message,
                };
                input.tell(notice);
            }
            self.buses.insert(name, plan);
        }
    }

    /// Tells of the ESCs of ESC `esc`'s CAN bus that claimed a throttle channel another holds,
    /// heard since the last call (on a bus not read ahead: standard input, live ports).
    pub(super) fn tell_can_clashes(&mut self, input: &mut Input, esc: usize) {
        for message in self.escs[esc].stream.take_can_clashes() {
            input.tell(Notice::CanBus {
                input: input.name().to_string(),
                interface: self.escs[esc].name.clone(),
                message,
            });
        }
    }

    /// Whether stream `stream` of `input` is a CAN bus read ahead that carries no ESC status
    /// (an interface of stray frames): it is no ESC, takes no number and moves none.
    pub(super) fn is_silent_bus(&self, input: &Input, stream: usize) -> bool {
        input.is_can(stream)
            && self
                .buses
                .get(&input.stream_name(stream))
                .is_some_and(BusPlan::is_empty)
    }
}
