//! A file's CAN buses read ahead, before it is read for its records: where each ESC of each bus
//! is at the end of the file, so that its number is fixed for the whole file (a node that
//! answers GetEscID late keeps one number) and two ESCs that claim one throttle channel are
//! told of once (`stream/can.rs`'s [`BusPlan`]).

use std::collections::VecDeque;

use super::Sources;
use crate::esc_table::Recording;
use crate::input::Input;
use crate::notice::Notice;
use crate::stream::{BusLearner, BusPlan, no_status};

impl Sources {
    /// Reads ahead the CAN buses of the inputs that can be read twice (CAN logs and
    /// recordings given as files; not copies of an earlier input, which are not read), bus by
    /// bus as their streams are named in their recording (the interfaces of the files of one
    /// recording that name one bus are one bus: `esc_table.rs`), and tells of the ESCs that
    /// claim a throttle channel another ESC of their bus holds. `base`: the index of the
    /// first of `inputs` among all inputs.
    pub(super) fn plan_buses(&mut self, inputs: &mut VecDeque<Input>, base: usize) {
        // Each bus by recording and name, in the order first met, with the input that last
        // carried it.
        type Bus = ((Recording, String), BusLearner, usize);
        let mut buses: Vec<Bus> = Vec::new();
        for (k, input) in inputs.iter_mut().enumerate() {
            let format = input.format();
            let copy = self.duplicates.get(base + k).copied().flatten().is_some();
            if copy || !format.may_carry_can() || !input.rewind() {
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
                let name = (
                    self.recording_of(input, base + k),
                    input.stream_name(stream),
                );
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
                    interface: name.1.clone(),
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
                interface: self.table[esc].key.port.clone(),
                message,
            });
        }
    }

    /// Whether stream `stream` of `input` (input number `index`) is a CAN bus read ahead that
    /// carries no ESC status (an interface of stray frames): it is no ESC, takes no number and
    /// moves none.
    pub(super) fn is_silent_bus(&self, input: &Input, index: usize, stream: usize) -> bool {
        input.is_can(stream)
            && self
                .buses
                .get(&(self.recording_of(input, index), input.stream_name(stream)))
                .is_some_and(BusPlan::is_empty)
    }
}
