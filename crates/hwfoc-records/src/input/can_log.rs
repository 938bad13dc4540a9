//! What every CAN log file input shares: its frames, read one at a time by its format's parser
//! ([`Frames`]: `candump.rs`, `asc.rs`, `blf.rs`, `trc.rs`, `can_csv.rs`), gathered per bus
//! over a window of log time and handed on as one CAN stream per bus (16-byte SocketCAN
//! records, each byte with its frame's time), as a recording's packets are (`recording.rs`).

use std::collections::{HashMap, VecDeque};
use std::io::{BufRead, BufReader, Read};

use hwfoc::dronecan::CanFrame;

use super::end::End;
use super::recording::RECORDING_WINDOW_NS;
use super::{BATCH, InputError, InputFormat, Looks, Source};
use super::{asc, blf, can_csv, candump, candump_text, trc};
use crate::can::candump::Logged;
use crate::clock::byte_times;
use crate::notice::Notice;

/// Most bytes gathered for one bus before the window's batches are handed out.
const MAX_GATHERED: usize = 1 << 18;
/// The longest line a text CAN log is read with: a classic CAN line of any of them is under
/// 100 bytes, a CAN FD one under 300.
pub(super) const MAX_LINE: usize = 1024;

/// The CAN log formats, detected from an input's first line (or magic).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Log {
    /// `candump -l` (and `-L`).
    Candump,
    /// candump's own text, with times or (`timed` false) without.
    CandumpText {
        /// Whether its lines have times.
        timed: bool,
    },
    /// Vector ASC.
    Asc,
    /// Vector BLF.
    Blf,
    /// PEAK TRC.
    Trc,
    /// python-can CSV.
    CanCsv,
}

/// The formats of CAN logs.
pub(super) const FORMATS: [InputFormat; 7] = [
    InputFormat::CANDUMP,
    InputFormat::CANDUMP_TEXT,
    InputFormat::CANDUMP_UNTIMED,
    InputFormat::ASC,
    InputFormat::BLF,
    InputFormat::TRC,
    InputFormat::CAN_CSV,
];

/// Whether `head`, an input's first bytes, may still be the start of a CAN log (format
/// detection reads its first line whole while it may).
pub(super) fn may_start(head: &[u8]) -> bool {
    candump::may_start(head)
        || candump_text::may_start(head)
        || asc::may_start(head)
        || blf::may_start(head)
        || trc::may_start(head)
        || can_csv::may_start(head)
}

impl Log {
    /// The CAN log `head`, an input's first line (or its first bytes), starts.
    pub(super) fn of(head: &[u8]) -> Option<Log> {
        [
            (candump::is_start as fn(&[u8]) -> bool, Log::Candump),
            (
                candump_text::is_timed_start,
                Log::CandumpText { timed: true },
            ),
            (candump_text::is_start, Log::CandumpText { timed: false }),
            (asc::is_start, Log::Asc),
            (blf::is_start, Log::Blf),
            (trc::is_start, Log::Trc),
            (can_csv::is_start, Log::CanCsv),
        ]
        .into_iter()
        .find_map(|(is, log)| is(head).then_some(log))
    }

    /// The reader of a log of this format, from its first byte.
    pub(super) fn source(self, reader: Box<dyn Read>) -> Box<dyn Source> {
        match self {
            Log::Candump => Box::new(candump::CandumpLines::reader(reader)),
            Log::CandumpText { timed } => {
                Box::new(candump_text::CandumpText::reader(reader, timed))
            }
            Log::Asc => Box::new(asc::AscLines::reader(reader)),
            Log::Blf => Box::new(blf::BlfObjects::reader(reader)),
            Log::Trc => Box::new(trc::TrcLines::reader(reader)),
            Log::CanCsv => Box::new(can_csv::CanCsvRows::reader(reader)),
        }
    }
}

/// One frame of a CAN log.
pub(super) struct Entry {
    /// Its time, Unix nanoseconds; `None` in a log without times (candump's text without
    /// `-t`).
    pub t_ns: Option<u64>,
    /// The frame.
    pub frame: Logged,
}

/// A CAN log format's parser: its frames in the file's order.
pub(super) trait Frames {
    /// The format read.
    fn format(&self) -> InputFormat;

    /// The next frame, with the name of its bus in `bus` (left empty by a format that names
    /// no bus: the input is its one bus); `None` at the end. `name` is the input's, for errors.
    fn next(&mut self, name: &str, bus: &mut String) -> Result<Option<Entry>, InputError>;
}

/// A text log's parser, line by line: a [`Frames`] of the log's lines.
pub(super) trait LineFrames {
    /// The format read.
    fn format(&self) -> InputFormat;

    /// The log's lines, and what the log is called in their errors.
    fn lines(&mut self) -> (&mut Lines, &'static str);

    /// The frame of a line (not blank, trimmed), with its bus in `bus`; `None` for a line
    /// that is no frame (a header, an event).
    fn line(
        &mut self,
        name: &str,
        text: &str,
        bus: &mut String,
    ) -> Result<Option<Entry>, InputError>;
}

impl<T: LineFrames> Frames for T {
    fn format(&self) -> InputFormat {
        LineFrames::format(self)
    }

    fn next(&mut self, name: &str, bus: &mut String) -> Result<Option<Entry>, InputError> {
        loop {
            let (lines, what) = self.lines();
            let Some(text) = lines.next(name, what)? else {
                return Ok(None);
            };
            if let Some(entry) = self.line(name, &text, bus)? {
                return Ok(Some(entry));
            }
        }
    }
}

/// A frame as a text log's line describes it (ASC, TRC), before its data bytes are read.
pub(super) struct LineFrame {
    /// The id.
    pub id: u32,
    /// Whether the id is a 29-bit one.
    pub extended: bool,
    /// A remote frame (no data bytes on the line).
    pub remote: bool,
    /// The length (0 to 8).
    pub len: usize,
}

impl LineFrame {
    /// The frame, its data bytes the first `len` of `words` in base `radix` (none for a
    /// remote frame); `bad` makes the error about the line, given what is wrong.
    pub(super) fn read<'a>(
        self,
        mut words: impl Iterator<Item = &'a str>,
        radix: u32,
        bad: impl Fn(&str) -> InputError,
    ) -> Result<Logged, InputError> {
        let mut data = [0u8; 8];
        if !self.remote {
            for byte in data.iter_mut().take(self.len) {
                *byte = words
                    .next()
                    .and_then(|w| u8::from_str_radix(w, radix).ok())
                    .ok_or_else(|| bad("fewer data bytes than its length"))?;
            }
        }
        frame(self.id, self.extended, self.remote, &data[..self.len])
            .ok_or_else(|| bad("the id is too large for its kind"))
    }
}

/// The frame of an id, its kind and data, as a log line or object gives them; `None` where
/// they make no classic CAN frame (an id too large, more than 8 bytes).
pub(super) fn frame(id: u32, extended: bool, remote: bool, data: &[u8]) -> Option<Logged> {
    let frame = match (remote, extended) {
        (true, _) => CanFrame::remote(id, extended, data.len().try_into().ok()?),
        (false, true) => CanFrame::extended(id, data),
        (false, false) => CanFrame::standard(id, data),
    };
    frame.map(Logged::Classic)
}

/// Unix nanoseconds as seconds, as a candump log's `seconds.fraction` is read (whole seconds
/// plus the fraction), so that the same time in any format is the same number.
pub(super) fn seconds(t_ns: u64) -> f64 {
    (t_ns / 1_000_000_000) as f64 + (t_ns % 1_000_000_000) as f64 / 1e9
}

/// Decimal seconds (`12.345678`, a sign not allowed) as nanoseconds; `None` for anything
/// else, or more than 9 digits of fraction.
pub(super) fn decimal_ns(text: &str, scale_ns: u64) -> Option<u64> {
    let (whole, frac) = text.split_once('.').unwrap_or((text, ""));
    let digits = |s: &str| s.len() <= 18 && s.bytes().all(|b| b.is_ascii_digit());
    if whole.is_empty() && frac.is_empty() || !digits(whole) || !digits(frac) || frac.len() > 9 {
        return None;
    }
    let whole: u64 = if whole.is_empty() {
        0
    } else {
        whole.parse().ok()?
    };
    let mut f: u64 = if frac.is_empty() {
        0
    } else {
        frac.parse().ok()?
    };
    for _ in frac.len()..9 {
        f *= 10;
    }
    // `f` is in 1e-9 units of `scale_ns`.
    whole
        .checked_mul(scale_ns)?
        .checked_add(((f as u128 * scale_ns as u128) / 1_000_000_000) as u64)
}

/// The lines of a text log, each at most [`MAX_LINE`] bytes.
pub(super) struct Lines {
    reader: BufReader<Box<dyn Read>>,
    /// Number of the last line read (1-based).
    pub number: u64,
    row: Vec<u8>,
}

impl Lines {
    /// The lines `reader` gives.
    pub(super) fn new(reader: Box<dyn Read>) -> Lines {
        Lines {
            reader: BufReader::with_capacity(BATCH, reader),
            number: 0,
            row: Vec::new(),
        }
    }

    /// The next line that is not blank, without the white space around it; `None` at the
    /// end. `format` names the log in the error of a line too long or not text.
    pub(super) fn next(&mut self, name: &str, format: &str) -> Result<Option<String>, InputError> {
        loop {
            self.row.clear();
            let n = (&mut self.reader)
                .take(MAX_LINE as u64 + 1)
                .read_until(b'\n', &mut self.row)
                .map_err(|source| InputError::Read {
                    input: name.to_string(),
                    source,
                })?;
            if n == 0 {
                return Ok(None);
            }
            self.number += 1;
            if self.row.len() > MAX_LINE {
                let e = format!("the line is longer than {MAX_LINE} bytes: not {format}");
                return Err(self.error(name, e));
            }
            let text = std::str::from_utf8(&self.row)
                .map_err(|_| self.error(name, format!("the line is not text: not {format}")))?
                .trim();
            if !text.is_empty() {
                return Ok(Some(text.to_string()));
            }
        }
    }

    /// An error about the last line read.
    pub(super) fn error(&self, name: &str, message: String) -> InputError {
        InputError::Csv {
            input: name.to_string(),
            line: self.number,
            message,
        }
    }
}

/// One bus's frames of a window.
struct Gathered {
    stream: usize,
    bytes: Vec<u8>,
    times: Vec<f64>,
}

/// A CAN log being read: its frames gathered per bus over a window of log time, each bus's
/// frames of the window handed out as one batch, in the order of their first frame's time.
pub(super) struct CanLogReader<F> {
    frames: F,
    bus: String,
    names: Vec<String>,
    index: HashMap<String, usize>,
    /// CAN FD frames, by stream.
    not_classic: Vec<u64>,
    ready: VecDeque<Gathered>,
    end: End,
    /// Classic frames, those of them with 11-bit ids, and the source nodes (the id's low 7
    /// bits) of the 29-bit ones, for what the log looks like without ESCs.
    classic: u64,
    standard: u64,
    nodes: u128,
}

impl<F: Frames> CanLogReader<F> {
    /// Reads the frames `frames` gives.
    pub(super) fn new(frames: F) -> CanLogReader<F> {
        CanLogReader {
            frames,
            bus: String::new(),
            names: Vec::new(),
            index: HashMap::new(),
            not_classic: Vec::new(),
            ready: VecDeque::new(),
            end: End::default(),
            classic: 0,
            standard: 0,
            nodes: 0,
        }
    }

    /// The stream of the bus in `self.bus`, declared when first met.
    fn stream(&mut self) -> usize {
        if let Some(&i) = self.index.get(&self.bus) {
            return i;
        }
        let i = self.names.len();
        self.names.push(self.bus.clone());
        self.index.insert(self.bus.clone(), i);
        self.not_classic.push(0);
        i
    }

    /// Reads frames into per-bus batches until the window is over, a batch is full, or the log
    /// ends (or an error, kept for after the batches).
    fn read_window(&mut self, name: &str, notices: &mut dyn FnMut(Notice)) {
        let mut pending: Vec<Gathered> = Vec::new();
        let mut slot: HashMap<usize, usize> = HashMap::new();
        let mut start = None;
        loop {
            self.bus.clear();
            let entry = match self.frames.next(name, &mut self.bus) {
                Ok(Some(entry)) => entry,
                Ok(None) => {
                    self.end.reach();
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
                    self.end.fail(e);
                    break;
                }
            };
            let stream = self.stream();
            // A CAN FD frame: told once at the end, and counted by the bus's stream.
            let record = match entry.frame {
                Logged::Classic(frame) => {
                    self.classic += 1;
                    if frame.is_extended() {
                        self.nodes |= 1 << (frame.id() & 0x7F);
                    } else {
                        self.standard += 1;
                    }
                    frame.to_socketcan_record()
                }
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
            g.bytes.extend_from_slice(&record);
            let full = g.bytes.len() >= MAX_GATHERED;
            let Some(t_ns) = entry.t_ns else {
                if full {
                    break;
                }
                continue;
            };
            // The time as a candump log's is read, whatever the format: the same frames are
            // the same records.
            let t_ns = (seconds(t_ns) * 1e9).round() as u64;
            byte_times(t_ns, 0.0, record.len(), &mut g.times);
            let start = *start.get_or_insert(t_ns);
            if full || t_ns.saturating_sub(start) >= RECORDING_WINDOW_NS {
                break;
            }
        }
        // In the order of their first frame's time (untimed: as first met).
        pending.sort_by(|a, b| match (a.times.first(), b.times.first()) {
            (Some(x), Some(y)) => x.total_cmp(y).then(a.stream.cmp(&b.stream)),
            _ => std::cmp::Ordering::Equal,
        });
        self.ready.extend(pending);
    }
}

impl<F: Frames> Source for CanLogReader<F> {
    fn format(&self) -> InputFormat {
        self.frames.format()
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
            if let Some(result) = self.end.result() {
                return result;
            }
            self.read_window(name, notices);
        }
    }

    fn streams(&self) -> usize {
        self.names.len()
    }

    fn stream_name(&self, i: usize) -> Option<&str> {
        self.names
            .get(i)
            .map(String::as_str)
            .filter(|n| !n.is_empty())
    }

    fn is_can(&self, stream: usize) -> bool {
        stream < self.names.len()
    }

    fn flagged_bytes(&self) -> u64 {
        0
    }

    /// The log's frames in CAN words, said where none was an ESC's status.
    fn looks(&self) -> Option<Looks> {
        Some(Looks::Can {
            frames: self.classic,
            standard: self.standard,
            nodes: self.nodes.count_ones(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_times_are_exact_nanoseconds() {
        assert_eq!(decimal_ns("0.000100", 1_000_000_000), Some(100_000));
        assert_eq!(decimal_ns("12.5", 1_000_000), Some(12_500_000));
        assert_eq!(
            decimal_ns("1700000000.0071", 1_000_000_000),
            Some(1_700_000_000_007_100_000)
        );
        for bad in ["", ".", "-1", "1e3", "1.0000000001", "a"] {
            assert_eq!(decimal_ns(bad, 1), None, "{bad}");
        }
        assert_eq!(seconds(1_700_000_000_007_400_000), 1_700_000_000.0 + 0.0074);
    }
}
