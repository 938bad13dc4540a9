//! A `candump -l` log as an input: one CAN stream per interface named in it.

use std::collections::{HashMap, VecDeque};
use std::io::{BufRead, BufReader, Read};

use super::recording::RECORDING_WINDOW_NS;
use super::{BATCH, InputError, InputFormat, Looks, Source};
use crate::can::candump::{self, Logged};
use crate::clock::byte_times;
use crate::notice::Notice;
use crate::time::Clock;

impl InputFormat {
    /// A `candump -l` log: one CAN stream per interface, named by it, times the log's own
    /// timestamps (Unix seconds).
    pub const CANDUMP: InputFormat = InputFormat {
        name: "candump log",
        short_name: "candump",
        clock: Clock::Wall,
        live: false,
        recorded_ports: true,
    };
}

/// The longest line read: a classic CAN line is under 60 bytes, a CAN FD one under 200.
const MAX_LINE: usize = 1024;
/// Most bytes gathered for one interface before the window's batches are handed out.
const MAX_GATHERED: usize = 1 << 18;

/// Whether `head`, an input's first bytes, may still be the start of a candump log (format
/// detection reads its first line whole while it may).
pub(super) fn may_start(head: &[u8]) -> bool {
    head == b"(" || candump::looks_like_line(head)
}

/// Whether `head`, an input's first line, is a candump log line.
pub(super) fn is_start(head: &[u8]) -> bool {
    std::str::from_utf8(head).is_ok_and(|line| candump::parse_line(line.trim_end(), 1).is_ok())
}

/// One interface's frames of a window.
struct Gathered {
    stream: usize,
    bytes: Vec<u8>,
    times: Vec<f64>,
}

/// A candump log being read. Lines of the interfaces interleave; as a recording's packets
/// (`recording.rs`), they are gathered per interface over a window of log time and each
/// interface's frames of the window handed out as one batch, in the order of their first
/// frame's time.
pub(super) struct CandumpReader {
    reader: BufReader<Box<dyn Read>>,
    /// Number of the last line read (1-based).
    line: u64,
    row: Vec<u8>,
    names: Vec<String>,
    index: HashMap<String, usize>,
    /// CAN FD lines, by stream.
    not_classic: Vec<u64>,
    ready: VecDeque<Gathered>,
    ended: bool,
    error: Option<InputError>,
}

impl CandumpReader {
    /// Reads the log `reader` gives, from its first line.
    pub(super) fn new(reader: Box<dyn Read>) -> CandumpReader {
        CandumpReader {
            reader: BufReader::with_capacity(BATCH, reader),
            line: 0,
            row: Vec::new(),
            names: Vec::new(),
            index: HashMap::new(),
            not_classic: Vec::new(),
            ready: VecDeque::new(),
            ended: false,
            error: None,
        }
    }

    /// The stream of `interface`, declared when first met.
    fn stream(&mut self, interface: &str) -> usize {
        if let Some(&i) = self.index.get(interface) {
            return i;
        }
        let i = self.names.len();
        self.names.push(interface.to_string());
        self.index.insert(interface.to_string(), i);
        self.not_classic.push(0);
        i
    }

    /// Reads lines into per-interface batches until the window is over, a batch is full, or
    /// the log ends (or an error, kept for after the batches).
    fn read_window(&mut self, name: &str, notices: &mut dyn FnMut(Notice)) {
        let mut pending: Vec<Gathered> = Vec::new();
        let mut slot: HashMap<usize, usize> = HashMap::new();
        let mut start = None;
        loop {
            match self.next_line(name) {
                Ok(true) => {}
                Ok(false) => {
                    self.ended = true;
                    for (i, &frames) in self.not_classic.iter().enumerate() {
                        if frames > 0 {
                            notices(Notice::NotClassicCan {
                                input: name.to_string(),
                                interface: self.names[i].clone(),
                                frames,
                            });
                        }
                    }
                    break;
                }
                Err(e) => {
                    self.error = Some(e);
                    self.ended = true;
                    break;
                }
            }
            let text = String::from_utf8_lossy(&self.row);
            let text = text.trim_end();
            if text.is_empty() {
                continue;
            }
            let parsed = match candump::parse_line(text, self.line) {
                Ok(l) => (l.t_s, l.interface.to_string(), l.frame),
                Err(e) => {
                    self.error = Some(InputError::Csv {
                        input: name.to_string(),
                        line: e.line,
                        message: format!("not a candump -l line: {}", e.reason),
                    });
                    self.ended = true;
                    break;
                }
            };
            let (t_s, interface, frame) = parsed;
            let stream = self.stream(&interface);
            // A CAN FD frame: told once at the end, and counted by the bus's stream.
            let record = match frame {
                Logged::Classic(frame) => frame.to_socketcan_record(),
                Logged::Fd => {
                    self.not_classic[stream] += 1;
                    crate::can::NOT_CLASSIC_RECORD
                }
            };
            let i = *slot.entry(stream).or_insert_with(|| {
                pending.push(Gathered {
                    stream,
                    bytes: Vec::new(),
                    times: Vec::new(),
                });
                pending.len() - 1
            });
            let g = &mut pending[i];
            let t_ns = (t_s * 1e9).round() as u64;
            byte_times(t_ns, 0.0, record.len(), &mut g.times);
            g.bytes.extend_from_slice(&record);
            let start = *start.get_or_insert(t_ns);
            if g.bytes.len() >= MAX_GATHERED || t_ns.saturating_sub(start) >= RECORDING_WINDOW_NS {
                break;
            }
        }
        pending.sort_by(|a, b| {
            a.times[0]
                .total_cmp(&b.times[0])
                .then(a.stream.cmp(&b.stream))
        });
        self.ready.extend(pending);
    }

    /// Reads the next line into `row`; false at the end.
    fn next_line(&mut self, name: &str) -> Result<bool, InputError> {
        self.row.clear();
        let n = (&mut self.reader)
            .take(MAX_LINE as u64 + 1)
            .read_until(b'\n', &mut self.row)
            .map_err(|source| InputError::Read {
                input: name.to_string(),
                source,
            })?;
        if n == 0 {
            return Ok(false);
        }
        self.line += 1;
        if self.row.len() > MAX_LINE {
            return Err(InputError::Csv {
                input: name.to_string(),
                line: self.line,
                message: format!("the line is longer than {MAX_LINE} bytes: not a candump -l log"),
            });
        }
        Ok(true)
    }
}

impl Source for CandumpReader {
    fn format(&self) -> InputFormat {
        InputFormat::CANDUMP
    }

    fn fill(
        &mut self,
        name: &str,
        bytes: &mut Vec<u8>,
        times: &mut Vec<f64>,
        notices: &mut dyn FnMut(Notice),
    ) -> Result<usize, InputError> {
        bytes.clear();
        loop {
            if let Some(next) = self.ready.pop_front() {
                *bytes = next.bytes;
                *times = next.times;
                return Ok(next.stream);
            }
            if self.ended {
                return self.error.take().map_or(Ok(0), Err);
            }
            self.read_window(name, notices);
        }
    }

    fn streams(&self) -> usize {
        self.names.len()
    }

    fn stream_name(&self, i: usize) -> Option<&str> {
        self.names.get(i).map(String::as_str)
    }

    fn is_can(&self, stream: usize) -> bool {
        stream < self.names.len()
    }

    fn flagged_bytes(&self) -> u64 {
        0
    }

    fn looks(&self) -> Option<Looks> {
        None
    }
}

#[cfg(test)]
mod tests {
    use crate::{Input, InputFormat, Notice};
    use hwfoc::dronecan::CanFrame;

    const LOG: &str = "(1700000000.100000) can0 1C4E2D01#0102C0\n\
                       (1700000000.150000) vcan1 123#R4\n\
                       (1700000000.200000) can0 123##1112233\n\
                       \n\
                       (1700000000.250000) can0 20000004#0004000000000000\n";

    #[test]
    fn a_log_is_detected_and_gives_a_can_stream_per_interface() {
        let mut input = Input::from_memory("bus.log", LOG.as_bytes().to_vec()).unwrap();
        assert_eq!(input.format(), InputFormat::CANDUMP);
        assert_eq!(input.format().short_name(), "candump");
        let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let sink = std::sync::Arc::clone(&seen);
        input.set_notices(move |n| sink.lock().unwrap().push(n));
        let mut got = Vec::new();
        let mut fd = 0;
        while let Some(b) = input.next_batch().unwrap() {
            let times = b.times.unwrap();
            assert_eq!(b.bytes.len() % 16, 0);
            for (k, record) in b.bytes.chunks(16).enumerate() {
                let record: &[u8; 16] = record.try_into().unwrap();
                assert!(
                    times[16 * k..16 * k + 16]
                        .iter()
                        .all(|&t| t == times[16 * k])
                );
                // A CAN FD line: the record that stands for one, counted by the stream.
                if *record == crate::can::NOT_CLASSIC_RECORD {
                    fd += 1;
                    continue;
                }
                got.push((
                    b.stream,
                    times[16 * k],
                    CanFrame::from_socketcan_record(record).unwrap(),
                ));
            }
        }
        assert_eq!(input.streams(), 2);
        assert_eq!(
            (input.stream_name(0), input.stream_name(1)),
            ("can0".into(), "vcan1".into())
        );
        assert!(input.is_can(0) && input.is_can(1) && !input.is_can(2));
        assert_eq!(fd, 1);
        let frames: Vec<(usize, String)> = got.iter().map(|g| (g.0, g.2.to_string())).collect();
        assert_eq!(
            frames,
            [
                (0, "1C4E2D01#0102C0".to_string()),
                (0, "20000004#0004000000000000".to_string()),
                (1, "123#R4".to_string()),
            ]
        );
        assert!((got[0].1 - 1_700_000_000.1).abs() < 1e-6);
        assert!((got[1].1 - 1_700_000_000.25).abs() < 1e-6);
        assert_eq!(
            *seen.lock().unwrap(),
            [Notice::NotClassicCan {
                input: "bus.log".into(),
                interface: "can0".into(),
                frames: 1
            }]
        );
    }

    #[test]
    fn a_bad_line_is_an_error_naming_its_number_after_the_frames_before_it() {
        let log = format!("{LOG}(1700000001.0) can0 XYZ\n");
        let mut input = Input::from_memory("bus.log", log.into_bytes()).unwrap();
        input.set_notices(|_| {});
        let mut frames = 0;
        let e = loop {
            match input.next_batch() {
                Ok(Some(b)) => frames += b.bytes.len() / 16,
                Ok(None) => panic!("no error"),
                Err(e) => break e,
            }
        };
        // Three frames and the record of a CAN FD frame.
        assert_eq!(frames, 4);
        assert_eq!(
            e.to_string(),
            "bus.log:6: not a candump -l line: the frame is not ID#DATA"
        );
        // A first line that is not candump's: not a log.
        let input = Input::from_memory("x", b"(1700000000.1) can0\n".to_vec()).unwrap();
        assert_eq!(input.format(), InputFormat::RAW);
    }

    #[test]
    fn a_closed_file_keeps_which_streams_are_can() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bus.log");
        std::fs::write(&path, LOG).unwrap();
        let mut input = Input::open(path.to_str().unwrap()).unwrap();
        input.set_notices(|_| {});
        while input.next_batch().unwrap().is_some() {}
        assert!(input.is_can(1) && !input.is_can(2));
        assert_eq!(input.stream_name(1), "vcan1");
    }
}
