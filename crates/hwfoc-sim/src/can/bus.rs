//! A CAN bus of virtual Hobbywing ESCs: their messages in time order, each frame waiting for
//! the bus, and the controller's requests in.

use std::collections::VecDeque;
use std::rc::Rc;

use hwfoc::dronecan::{CanFrame, Form, Message, Receiver, TransferType};

use super::esc::{CanEsc, CanSetup, EscConfig, FACTORY_BITRATE, MAX_CHANNEL, Outgoing};
use crate::error::SimError;
use crate::esc::spread;
use crate::faults::{FaultSchedule, LinkRates};
use crate::fleet::FleetSpec;
use crate::profile::Profile;

/// The most ESCs on a simulated CAN bus: a throttle channel has 6 bits.
pub const MAX_CAN_ESCS: usize = MAX_CHANNEL as usize;
/// How long an ESC takes to answer a request, ns (1 ms; a choice).
pub const ANSWER_NS: u64 = 1_000_000;

/// The bits an extended data frame of `len` bytes takes on the bus, interframe space included
/// (stuff bits left out): 64 + 8 per byte + 3.
pub const fn frame_bits(len: usize) -> u64 {
    67 + 8 * len as u64
}

/// A transfer an ESC put on the bus: what the ground truth lists.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sent {
    /// Time its first frame started on the bus, ns from the start of the run.
    pub t_ns: u64,
    /// The ESC's index.
    pub esc: usize,
    /// Priority, source, destination, transfer id, message.
    pub out: Outgoing,
}

/// An answer waiting to go out.
#[derive(Debug, Clone, Copy)]
struct Answer {
    due_ns: u64,
    esc: usize,
    /// A response (already complete), or `None` for a GetEscID answer (made when sent, with
    /// the ESC's settings then).
    out: Option<Outgoing>,
    /// The bit rate it goes out at (the ESC's when asked: a SetBaud answer is sent at the old
    /// rate).
    bitrate: u32,
}

/// A bus of virtual Hobbywing CAN ESCs, in simulated time: pure logic, no threads, no clock.
///
/// [`CanBus::frames_until`] hands out the frames of every transfer due before a time, in time
/// order; [`CanBus::receive`] takes a controller's frame (a GetEscID request, a setup service
/// request). Each frame occupies the bus for its bits at the bus's bit rate (stuff bits left
/// out); one due while the bus is busy waits, in the order the transfers fell due (no
/// arbitration by identifier). An ESC whose bit rate is not the bus's (after `SetBaud`) is
/// neither heard nor hears: its transfers still count their transfer ids.
pub struct CanBus {
    escs: Vec<CanEsc>,
    bitrate: u32,
    bus_free_ns: u64,
    answers: VecDeque<Answer>,
    rx: Receiver,
    sent: Vec<Sent>,
    natural_s: f64,
    /// The run's seed.
    seed: u64,
}

impl CanBus {
    /// The bus of `spec`'s ESCs (its count, seed, profile, model and faults; the serial
    /// protocol, baud rate and start packet are not used): every ESC as it leaves the factory
    /// if `factory` (node 1, channel 1), else set up ([`EscConfig::set_up`]). The bus runs at
    /// 500 kbit/s.
    pub fn build(spec: &FleetSpec, factory: bool) -> Result<CanBus, SimError> {
        if spec.n > MAX_CAN_ESCS {
            return Err(SimError::TooManyCanEscs {
                n: spec.n,
                max: MAX_CAN_ESCS,
            });
        }
        if spec.link != LinkRates::default() {
            return Err(SimError::CanLinkFaults);
        }
        if !spec.degradations.is_empty() {
            return Err(SimError::CanDegradations);
        }
        if let Some(esc) = spec
            .faults
            .iter()
            .find_map(|f| f.esc.filter(|&e| e >= spec.n))
        {
            return Err(SimError::NoSuchEsc { esc, n: spec.n });
        }
        let profile = Rc::new(Profile::load(&spec.profile, &spec.shape)?);
        let natural_s = profile.natural_length_s();
        let mut bus = CanBus::new(
            (0..spec.n)
                .map(|index| {
                    let (lag_s, load) = spread(spec.seed, index);
                    CanEsc::new(CanSetup {
                        index,
                        seed: spec.seed,
                        model: spec.model,
                        profile: Rc::clone(&profile),
                        lag_s,
                        load,
                        faults: FaultSchedule::for_esc(&spec.faults, index),
                        config: if factory {
                            EscConfig::FACTORY
                        } else {
                            EscConfig::set_up(index)
                        },
                    })
                })
                .collect(),
        );
        bus.natural_s = natural_s;
        bus.seed = spec.seed;
        Ok(bus)
    }

    /// One run of the throttle profile, seconds (0 for a bus made with [`CanBus::new`]).
    pub fn natural_length_s(&self) -> f64 {
        self.natural_s
    }

    /// A bus of these ESCs at 500 kbit/s.
    pub fn new(escs: Vec<CanEsc>) -> CanBus {
        CanBus {
            escs,
            bitrate: FACTORY_BITRATE,
            bus_free_ns: 0,
            answers: VecDeque::new(),
            rx: Receiver::new(),
            sent: Vec::new(),
            natural_s: 0.0,
            seed: 0,
        }
    }

    /// The ESCs.
    pub fn escs(&self) -> &[CanEsc] {
        &self.escs
    }

    /// The seed of its ESCs' random choices (0 for a bus made with [`CanBus::new`]).
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The bus's bit rate, bit/s.
    pub fn bitrate(&self) -> u32 {
        self.bitrate
    }

    /// Sets the bus's bit rate (an adapter's `S` command): ESCs at another rate fall silent.
    pub fn set_bitrate(&mut self, bitrate: u32) {
        self.bitrate = bitrate;
    }

    /// What the controller's frames did so far ([`Receiver`]'s counts).
    pub fn receiver(&self) -> &Receiver {
        &self.rx
    }

    /// The transfers sent since the last call: the ground truth.
    pub fn take_sent(&mut self) -> Vec<Sent> {
        std::mem::take(&mut self.sent)
    }

    /// The frames of every transfer due before `t_ns`, each with the time it starts on the
    /// bus (ns from the start of the run; a frame waits for the bus, so its time can be a
    /// little past `t_ns`), in time order.
    pub fn frames_until(&mut self, t_ns: u64) -> Vec<(u64, CanFrame)> {
        let mut out = Vec::new();
        loop {
            let own = self
                .escs
                .iter()
                .enumerate()
                .filter_map(|(i, e)| e.next_due().map(|(t, s)| (t, i, s)))
                .min_by_key(|&(t, i, _)| (t, i));
            let answer = self.answers.front().map(|a| a.due_ns);
            match (own, answer) {
                (_, Some(due)) if due < t_ns && own.is_none_or(|o| due <= o.0) => {
                    let Some(a) = self.answers.pop_front() else {
                        break;
                    };
                    let out_msg = match a.out {
                        Some(o) => o,
                        None => self.escs[a.esc].answer_get_esc_id(),
                    };
                    self.put(a.due_ns, a.bitrate, a.esc, out_msg, &mut out);
                }
                (Some((due, esc, stream)), _) if due < t_ns => {
                    let o = self.escs[esc].emit(stream, due);
                    let rate = self.escs[esc].config().bitrate;
                    self.put(due, rate, esc, o, &mut out);
                }
                _ => break,
            }
        }
        out
    }

    /// Puts ESC `esc`'s transfer due at `due_ns`, sent at `bitrate`, on the bus (heard only
    /// at the bus's rate).
    fn put(
        &mut self,
        due_ns: u64,
        bitrate: u32,
        esc: usize,
        o: Outgoing,
        out: &mut Vec<(u64, CanFrame)>,
    ) {
        if bitrate != self.bitrate {
            return;
        }
        let mut t = due_ns.max(self.bus_free_ns);
        self.sent.push(Sent {
            t_ns: t,
            esc,
            out: o,
        });
        for frame in o
            .message
            .frames(o.priority, o.source, o.destination, o.transfer_id)
        {
            out.push((t, frame));
            t += frame_bits(frame.len()) * 1_000_000_000 / u64::from(self.bitrate);
        }
        self.bus_free_ns = t;
    }

    /// Puts a controller's `frames` (a transfer) on the bus from `t_ns` on, each waiting for the
    /// bus and occupying it as the ESCs' do, and has the ESCs take them ([`CanBus::receive`]).
    /// Returns the frames with the times they start on the bus, and how many ESCs will answer.
    pub fn transmit(&mut self, t_ns: u64, frames: &[CanFrame]) -> (Vec<(u64, CanFrame)>, usize) {
        let mut out = Vec::with_capacity(frames.len());
        let mut answers = 0;
        let mut t = t_ns.max(self.bus_free_ns);
        for frame in frames {
            out.push((t, *frame));
            answers += self.receive(t, frame);
            t += frame_bits(frame.len()) * 1_000_000_000 / u64::from(self.bitrate);
        }
        self.bus_free_ns = t;
        (out, answers)
    }

    /// Takes a frame a controller sent at `t_ns`: a whole GetEscID request (`[0]`) has every
    /// ESC answer; a whole service request to a node has every ESC of that node answer (in the
    /// factory state, all of them), [`ANSWER_NS`] later, as a response to the requester with
    /// the request's priority and transfer id, after changing its settings. Returns how many
    /// ESCs will answer.
    pub fn receive(&mut self, t_ns: u64, frame: &CanFrame) -> usize {
        let Some(got) = self.rx.push(frame) else {
            return 0;
        };
        let due_ns = (t_ns + ANSWER_NS).max(self.answers.back().map_or(0, |a| a.due_ns));
        let mut n = 0;
        let bitrate = self.bitrate;
        match (got.message, got.header.transfer) {
            (Message::GetEscId(m), TransferType::Message) if m.payload() == [0] => {
                for esc in self.escs.iter().filter(|e| e.config().bitrate == bitrate) {
                    self.answers.push_back(Answer {
                        due_ns,
                        esc: esc.index(),
                        out: None,
                        bitrate,
                    });
                    n += 1;
                }
            }
            (request, TransferType::Request { destination })
                if request.kind().form() == Form::Request =>
            {
                for esc in self.escs.iter_mut() {
                    let c = *esc.config();
                    if c.node_id != destination || c.bitrate != bitrate {
                        continue;
                    }
                    if let Some(response) = esc.serve(t_ns, &request) {
                        // The answer comes from the node that was asked (SetID's new id
                        // holds from then on), at the bit rate it had (SetBaud's new rate
                        // holds from then on).
                        let out = Outgoing {
                            priority: got.header.priority,
                            source: c.node_id,
                            destination: got.header.source_node,
                            transfer_id: got.transfer_id,
                            message: response,
                        };
                        let index = esc.index();
                        self.answers.push_back(Answer {
                            due_ns,
                            esc: index,
                            out: Some(out),
                            bitrate,
                        });
                        n += 1;
                    }
                }
            }
            _ => {}
        }
        n
    }
}
