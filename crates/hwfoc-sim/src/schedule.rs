//! Running the virtual ESCs into a sink, in simulated time (as fast as possible) or at the real
//! rate, and keeping count of what went out.
//!
//! One loop serves every ESC: it always handles the earliest pending write over all of them and,
//! in real time, sleeps until it is due (sleeping in slices of at most 100 ms to notice a stop
//! request; no busy waiting). Buffered output and the ground truth are flushed whenever the loop
//! is about to sleep, so a reader sees each frame as soon as it is written.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use crate::burst::{Burst, What};
use crate::esc::VirtualEsc;
use crate::faults::Fate;
use crate::sink::{Sink, Truth};
use hwfoc_io::write::WriteError;

/// Longest single sleep, so that a stop request is seen promptly.
const SLEEP_SLICE: Duration = Duration::from_millis(100);

/// How bytes are handed to the sink.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pace {
    /// No waiting: simulated time only.
    Fast,
    /// In real time, each burst whole at the time its first byte starts (files, and serial ports,
    /// whose UART spreads the bytes over the wire itself).
    Whole,
    /// In real time, each burst in pieces of this many bytes, each written when its last byte
    /// has fully arrived at the baud rate (pseudo-terminals, pipes).
    ///
    /// A pty hands a write to the reader at once: writing a 24-byte frame whole would deliver
    /// it 12.5 ms (at 19200 baud) before a real wire could, and a recorder would see all its
    /// bytes arrive together. Writing byte by byte would be exact but costs a wake-up per
    /// byte. Pieces of about 4 ms (8 bytes at 19200 baud) are what a reader of a real UART
    /// sees anyway (a USB adapter hands bytes over in small bursts): no byte is ever
    /// available before it was complete on the wire, a frame never arrives faster than the
    /// baud rate allows, and the error on any byte's arrival time stays under 4.2 ms, a tenth
    /// of the shortest gap between frames, at three writes per data frame.
    Pieces(usize),
}

/// What one ESC sent.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Tally {
    /// Data frames the ESC sent or meant to (dropped ones included).
    pub data: u64,
    /// Data frames that went out intact and were delivered: the ground truth's records.
    pub intact: u64,
    /// Frames (data and information) the link dropped.
    pub dropped: u64,
    /// Frames the link cut short.
    pub cut: u64,
    /// Frames with flipped bits.
    pub corrupted: u64,
    /// Device-information frames.
    pub info: u64,
    /// Garbage bursts.
    pub garbage: u64,
    /// Bursts of glitch bytes.
    pub glitches: u64,
    /// Intact data frames that found no reader.
    pub undelivered: u64,
}

impl Tally {
    fn count(&mut self, burst: &Burst, delivered: bool) {
        let fate = match &burst.what {
            What::Data { fate, .. } => {
                self.data += 1;
                if *fate == Fate::Intact {
                    if delivered {
                        self.intact += 1;
                    } else {
                        self.undelivered += 1;
                    }
                }
                fate
            }
            What::Telemetry { .. } => {
                self.data += 1;
                if delivered {
                    self.intact += 1;
                } else {
                    self.undelivered += 1;
                }
                return;
            }
            What::Info { fate } => {
                self.info += 1;
                fate
            }
            What::Garbage => {
                self.garbage += 1;
                return;
            }
            What::Glitch => {
                self.glitches += 1;
                return;
            }
        };
        match fate {
            Fate::Intact => {}
            Fate::Dropped => self.dropped += 1,
            Fate::Cut => self.cut += 1,
            Fate::Corrupted => self.corrupted += 1,
        }
    }
}

/// The clock of a run.
#[derive(Debug, Clone, Copy)]
pub struct SimClock {
    /// The output clock's reading at simulated time zero, ns (Unix time, or a chosen start).
    pub origin_ns: u64,
    /// In real time: the instant of simulated time zero.
    pub real: Option<Instant>,
}

/// One ESC and the burst it is sending.
struct Lane {
    esc: VirtualEsc,
    burst: Burst,
    /// Bytes of the burst written so far.
    written: usize,
    delivered: bool,
    done: bool,
    tally: Tally,
}

/// Runs `escs` until `duration_ns` of simulated time (bursts starting before it are sent
/// whole), forever if `None`, or until `stop` is set. Returns each ESC's tally.
pub fn run(
    escs: Vec<VirtualEsc>,
    sink: &mut dyn Sink,
    mut truth: Option<&mut Truth>,
    pace: Pace,
    clock: SimClock,
    duration_ns: Option<u64>,
    stop: &AtomicBool,
) -> Result<Vec<Tally>, WriteError> {
    let byte_ns = escs.first().map_or(1.0, VirtualEsc::byte_ns);
    let mut lanes: Vec<Lane> = escs
        .into_iter()
        .map(|mut esc| {
            let burst = esc.next_burst();
            Lane {
                done: duration_ns.is_some_and(|d| burst.t_ns >= d),
                esc,
                burst,
                written: 0,
                delivered: true,
                tally: Tally::default(),
            }
        })
        .collect();
    let mut dirty = false;
    while !stop.load(Ordering::Relaxed) {
        // The earliest pending write over all ESCs.
        let mut next: Option<(usize, u64, usize)> = None;
        for (i, lane) in lanes.iter().enumerate() {
            if lane.done {
                continue;
            }
            let len = lane.burst.bytes.len();
            let (to, due) = match pace {
                Pace::Fast | Pace::Whole => (len, lane.burst.t_ns),
                Pace::Pieces(n) => {
                    let to = (lane.written + n).min(len);
                    (to, lane.burst.t_ns + (to as f64 * byte_ns).ceil() as u64)
                }
            };
            if next.is_none_or(|(_, best, _)| due < best) {
                next = Some((i, due, to));
            }
        }
        let Some((i, due, to)) = next else { break };
        if let Some(start) = clock.real {
            loop {
                let now = start.elapsed().as_nanos() as u64;
                if now >= due || stop.load(Ordering::Relaxed) {
                    break;
                }
                if dirty {
                    sink.flush()?;
                    if let Some(truth) = truth.as_deref_mut() {
                        truth.flush()?;
                    }
                    dirty = false;
                }
                std::thread::sleep(SLEEP_SLICE.min(Duration::from_nanos(due - now)));
            }
            if stop.load(Ordering::Relaxed) {
                break;
            }
        }
        let lane = &mut lanes[i];
        let index = lane.esc.index();
        let from = lane.written;
        if to > from {
            let offset = (from as f64 * byte_ns).round() as u64;
            let t_ns = clock.origin_ns + lane.burst.t_ns + offset;
            let ok = sink.write(index, t_ns, &lane.burst.bytes[from..to])?;
            lane.delivered &= ok;
            dirty = true;
        }
        lane.written = to;
        if to < lane.burst.bytes.len() {
            continue;
        }
        lane.tally.count(&lane.burst, lane.delivered);
        if lane.delivered
            && let Some(data) = lane.burst.intact_data()
            && let Some(truth) = truth.as_deref_mut()
        {
            // Seconds exactly as the recording's reader computes them for a packet's first
            // byte, so that decoding a recording gives the same `t_s`.
            let t_ns = clock.origin_ns + lane.burst.t_ns;
            truth.record_data(hwfoc_ports::clock::byte_time_s(t_ns, 0, 0.0), index, &data)?;
        }
        lane.burst = lane.esc.next_burst();
        lane.written = 0;
        lane.delivered = true;
        lane.done = duration_ns.is_some_and(|d| lane.burst.t_ns >= d);
    }
    sink.flush()?;
    if let Some(truth) = truth {
        truth.flush()?;
    }
    Ok(lanes.into_iter().map(|lane| lane.tally).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::esc::VirtualEsc;
    use crate::esc::tests::{decode, setup};
    use crate::faults::LinkRates;
    use crate::profile::Profile;
    use hwfoc::Settings;

    /// Keeps every write with the time it was made.
    struct Memory {
        writes: Vec<(usize, u64, Vec<u8>, Duration)>,
        start: Instant,
    }

    impl Sink for Memory {
        fn write(&mut self, esc: usize, t_ns: u64, bytes: &[u8]) -> Result<bool, WriteError> {
            let at = self.start.elapsed();
            self.writes.push((esc, t_ns, bytes.to_vec(), at));
            Ok(true)
        }

        fn flush(&mut self) -> Result<(), WriteError> {
            Ok(())
        }
    }

    fn escs(n: usize, link: LinkRates) -> Vec<VirtualEsc> {
        (0..n)
            .map(|index| {
                let mut s = setup(
                    Profile::Points(vec![(0.0, 0.0), (0.5, 0.0), (0.5, 60.0), (2.0, 0.0)]),
                    link,
                );
                s.index = index;
                VirtualEsc::new(s)
            })
            .collect()
    }

    #[test]
    fn fast_run_interleaves_escs_in_time_and_writes_the_truth() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("truth.jsonl");
        let file = std::fs::File::create(&path).unwrap();
        let mut truth = Truth::new("truth".into(), Box::new(file), Settings::default());
        let mut sink = Memory {
            writes: Vec::new(),
            start: Instant::now(),
        };
        let link = LinkRates {
            bit_error: 1e-3,
            drop: 0.05,
            cut: 0.05,
            garbage: 0.2,
        };
        let origin_ns = 1_000_000_000_000;
        let clock = SimClock {
            origin_ns,
            real: None,
        };
        let stop = AtomicBool::new(false);
        let tallies = run(
            escs(3, link),
            &mut sink,
            Some(&mut truth),
            Pace::Fast,
            clock,
            Some(3_000_000_000),
            &stop,
        )
        .unwrap();
        drop(truth);
        // One write per burst, in time order over all ESCs, all before the end.
        assert!(sink.writes.windows(2).all(|w| w[0].1 <= w[1].1));
        assert!(
            sink.writes
                .iter()
                .all(|w| w.1 >= origin_ns && w.1 < origin_ns + 3_000_000_000)
        );
        let text = std::fs::read_to_string(&path).unwrap();
        let records: Vec<serde_json::Value> = text
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        for (esc, t) in tallies.iter().enumerate() {
            let wire: Vec<u8> = sink
                .writes
                .iter()
                .filter(|w| w.0 == esc)
                .flat_map(|w| w.2.clone())
                .collect();
            let frames = decode(&wire);
            let mine: Vec<&serde_json::Value> =
                records.iter().filter(|r| r["esc"] == esc).collect();
            assert_eq!(frames.len(), mine.len());
            assert_eq!(t.intact as usize, mine.len());
            for (f, r) in frames.iter().zip(mine) {
                assert_eq!(r["packet"], f.packet);
                // t_s is the time of the frame's first byte: a write starting there.
                let t_ns = (r["t_s"].as_f64().unwrap() * 1e9).round() as u64;
                assert!(
                    sink.writes.iter().any(|w| w.0 == esc
                        && w.1.abs_diff(t_ns) < 1000
                        && w.2[..2] == [0x9B, 0x16])
                );
            }
            assert!(t.data > 40 && t.info > 2 && t.dropped + t.cut + t.corrupted > 0);
        }
    }

    #[test]
    fn real_time_pieces_never_run_ahead_of_the_wire() {
        let mut sink = Memory {
            writes: Vec::new(),
            start: Instant::now(),
        };
        let start = sink.start;
        let stop = AtomicBool::new(false);
        let clock = SimClock {
            origin_ns: 0,
            real: Some(start),
        };
        run(
            escs(2, LinkRates::default()),
            &mut sink,
            None,
            Pace::Pieces(8),
            clock,
            Some(700_000_000),
            &stop,
        )
        .unwrap();
        let byte_ns = 10e9 / 19200.0;
        assert!(sink.writes.len() > 30);
        let mut late = Vec::new();
        for (_, t_ns, bytes, at) in &sink.writes {
            assert!(bytes.len() <= 8);
            // Written once its last byte has fully arrived, not before.
            let due = *t_ns as f64 + bytes.len() as f64 * byte_ns;
            let at = at.as_nanos() as f64;
            assert!(at + 2.0 >= due, "{at} < {due}");
            late.push(at - due);
        }
        late.sort_by(f64::total_cmp);
        // Typically well under a millisecond late (a loaded machine may add some).
        assert!(
            late[late.len() / 2] < 5e6,
            "median {} ns late",
            late[late.len() / 2]
        );
        assert!(start.elapsed() >= Duration::from_millis(650));
    }

    #[test]
    fn a_stop_request_ends_the_run() {
        let mut sink = Memory {
            writes: Vec::new(),
            start: Instant::now(),
        };
        let stop = AtomicBool::new(true);
        let clock = SimClock {
            origin_ns: 0,
            real: Some(Instant::now()),
        };
        let tallies = run(
            escs(1, LinkRates::default()),
            &mut sink,
            None,
            Pace::Whole,
            clock,
            None,
            &stop,
        )
        .unwrap();
        assert!(sink.writes.is_empty());
        assert_eq!(tallies, vec![Tally::default()]);
    }
}
