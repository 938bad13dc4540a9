//! Telemetry inputs: where bytes come from, in what format, with what timestamps.
//!
//! Every command reads through [`Input`], which hands out [`Batch`]es of received bytes, each
//! byte with its receive time where the source has one, and the index of the stream (port) it
//! came from. The format of a file is detected from its first bytes, so a file and the same
//! bytes on standard input behave identically:
//! - a pcapng recording (`hwfoc record`, or any pcapng of raw UART bytes), whatever the file is
//!   called: one stream per interface, times from the packets' timestamps (Unix seconds);
//!   an interface of link type `LINKTYPE_CAN_SOCKETCAN` is a CAN stream (each frame's 16-byte
//!   record, [`Input::is_can`]);
//! - a CAN log: a `candump -l` log, candump's text with times, Vector ASC or BLF, PEAK TRC
//!   (1.1 to 2.1), python-can CSV (`can_log.rs` and a module per format): one CAN stream per
//!   interface or channel named in it, times its own;
//! - a logic-analyser CSV export (`Time [s],Value,Parity Error,Framing Error`, values as `0xNN`
//!   or decimal), whose times become `t_s`;
//! - otherwise raw bytes as they came off the wire (no timing).
//!
//! Files, standard input and serial ports are opened by `hwfoc-io` (`OpenInput::open`,
//! `OpenInput::open_ports`): a regular file through [`Reopen`] and [`RegularFile`], open only
//! while it is read; live ports as a [`Source`] of their own ([`Input::from_source`]).
//!
//! Each kind of input is a module (`raw.rs`, `csv.rs`, `recording.rs`, `candump.rs`, `asc.rs`,
//! `blf.rs`, `trc.rs`, `can_csv.rs`, `candump_text.rs`; `hwfoc-io`'s `ports.rs`) declaring
//! its [`InputFormat`] (names, clock, whether live, whether its streams are recorded ports:
//! what [`crate::Sources`] and the summary ask of a format) and implementing `Source`
//! (its reading, its streams, its flagged bytes). Standard input and files are read as their
//! content says.

mod asc;
mod blf;
mod can_csv;
mod can_log;
mod candump;
mod candump_text;
mod csv;
mod end;
mod error;
pub(crate) mod file;
mod looks;
mod raw;
mod recording;
mod trc;

use std::fmt;
use std::io::{self, BufReader, Cursor, Read};

use crate::notice::{self, Notice, NoticeSink};
use crate::pcapng;

use self::csv::{CsvRows, may_be_header};
pub use self::error::InputError;
pub use self::file::{Beside, BlockRead, ReadAt, RegularFile, Reopen};
pub use self::looks::Looks;

/// How many bytes of nothing but zeros from its start end the reading of a raw input with
/// [`InputError::OnlyZeros`]: 64 MiB, over an hour of any format's frames, so no recording
/// that starts with a zeroed stretch is cut short, while `/dev/zero` ends in a moment.
pub const ONLY_ZEROS_LIMIT: u64 = 64 << 20;
use self::raw::RawReader;
use self::recording::RecordingReader;
use crate::time::Clock;

/// How many bytes a raw read asks for: small enough that what the kernel copies in is still in
/// the L2 cache when the decoder reads it (1 MiB reads made `summary` 1.6x slower), large enough
/// that system calls cost nothing. Also the read buffer of a CSV input.
pub const BATCH: usize = 64 << 10;
/// The magic numbers of a classic libpcap file, as its first four bytes: microsecond and
/// nanosecond timestamps, either byte order.
const CLASSIC_PCAP: [[u8; 4]; 4] = [
    [0xD4, 0xC3, 0xB2, 0xA1],
    [0xA1, 0xB2, 0xC3, 0xD4],
    [0x4D, 0x3C, 0xB2, 0xA1],
    [0xA1, 0xB2, 0x3C, 0x4D],
];

/// The format of an input, with what follows from it: its names, its clock, whether it is live,
/// and how its streams are numbered. Each input kind's module declares its own (`raw.rs`,
/// `csv.rs`, `recording.rs`, `ports.rs`), and its reader implements the module's `Source`
/// trait: adding an input format is a module declaring both, and its line in
/// [`Input::from_reader`].
///
/// Two formats are equal when their short names are.
#[derive(Debug, Clone, Copy)]
pub struct InputFormat {
    name: &'static str,
    short_name: &'static str,
    clock: Clock,
    live: bool,
    recorded_ports: bool,
}

impl InputFormat {
    /// What a person reads: "raw bytes", "pcapng recording".
    pub fn name(self) -> &'static str {
        self.name
    }

    /// The short name of `summary --json` (`"format"`): "raw", "csv", "pcapng", "serial".
    pub fn short_name(self) -> &'static str {
        self.short_name
    }

    /// What the receive times of an input of this format are: the one place that says which
    /// sources have a wall clock. Inputs of [`Clock::None`] hand out bytes without times.
    pub fn clock(self) -> Clock {
        self.clock
    }

    /// Whether the input is live (serial ports): read as it arrives, alone, its records handed
    /// on in the order they come; its end (Ctrl-C) is not an error even with nothing read.
    pub fn is_live(self) -> bool {
        self.live
    }

    /// Whether each stream is a recorded port, named by the recording (pcapng): the streams
    /// are declared as the input is read, and the streams of inputs read together that name
    /// the same port are one ESC, one stream, its bytes merged in time order.
    pub(crate) fn has_recorded_ports(self) -> bool {
        self.recorded_ports
    }

    /// Whether an input of this format may carry CAN buses that can be read ahead: a CAN log
    /// or a recording (its buses planned before it is read: `sources/can_plan.rs`).
    pub(crate) fn may_carry_can(self) -> bool {
        self == InputFormat::RECORDING || can_log::FORMATS.contains(&self)
    }

    /// Whether inputs of this format are read together with those of the same clock given
    /// next to them, their records handed on in time order: inputs with times that are not
    /// live (recordings, analyser CSVs).
    pub(crate) fn is_merged_in_time(self) -> bool {
        !self.live && self.clock != Clock::None
    }
}

impl PartialEq for InputFormat {
    fn eq(&self, other: &Self) -> bool {
        self.short_name == other.short_name
    }
}

impl Eq for InputFormat {}

impl fmt::Display for InputFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name)
    }
}

impl InputFormat {
    /// Live serial ports: one stream per port, times of reception (Unix seconds), read as the
    /// bytes arrive.
    pub const SERIAL: InputFormat = InputFormat {
        name: "serial port",
        short_name: "serial",
        clock: Clock::Wall,
        live: true,
        recorded_ports: false,
    };
}

/// The reader of one input kind, behind [`Input`]: each kind's module implements it, holding
/// its own policy (its [`InputFormat`], its streams, its flagged bytes); live ports' is
/// `hwfoc-io`'s ([`Input::from_source`]).
pub trait Source {
    /// The format read.
    fn format(&self) -> InputFormat;

    /// Replaces `bytes` (the last batch, its buffer reused) by the next batch and appends
    /// their receive times to `times` (empty; left empty by a format without a clock), and
    /// returns the batch's stream; leaves `bytes` empty at the end. On an error, the bytes
    /// read before it stay in `bytes` (they are handed out first). Notices (a recording's
    /// notes, a port lost) go to `notices`; `name` is the input's, for errors.
    fn fill(
        &mut self,
        name: &str,
        bytes: &mut Vec<u8>,
        times: &mut Vec<f64>,
        notices: &mut dyn FnMut(Notice),
    ) -> Result<usize, InputError>;

    /// The number of streams known so far (see [`Input::streams`]).
    fn streams(&self) -> usize;

    /// The name of stream `i` where the input names its streams (a recording's interface, a
    /// port); `None` for a single-stream input, which is named as the input.
    fn stream_name(&self, i: usize) -> Option<&str>;

    /// Bytes flagged with a parity or framing error by what captured them, so far.
    fn flagged_bytes(&self) -> u64;

    /// Whether stream `i` is a CAN bus: its bytes are frames of 16 bytes each
    /// ([`hwfoc::dronecan::CanFrame::to_socketcan_record`]), every byte at its frame's time.
    fn is_can(&self, _stream: usize) -> bool {
        false
    }

    /// What the first bytes look like when they are not telemetry (raw bytes only).
    fn looks(&self) -> Option<Looks>;

    /// A second handle on the regular file being read, for positional reads of a later part
    /// (`Input::later_half`): raw bytes only.
    fn file(&self) -> Option<&dyn ReadAt> {
        None
    }

    /// The recording the input is a part of, where it names one (an hwfoc pcapng recording:
    /// [`pcapng::RecordingId`]), once its start is read.
    fn recording_id(&self) -> Option<pcapng::RecordingId> {
        None
    }
}

/// What a closed file's [`Source`] knew, asked for after its end.
#[derive(Debug, Default)]
struct Kept {
    streams: usize,
    /// The names of its streams, where it names them.
    names: Vec<String>,
    /// Which of its streams are CAN buses.
    can: Vec<bool>,
    flagged: u64,
    looks: Option<Looks>,
    recording: Option<pcapng::RecordingId>,
}

impl Kept {
    fn of(source: &dyn Source) -> Kept {
        let streams = source.streams();
        Kept {
            streams,
            names: (0..streams)
                .map_while(|i| source.stream_name(i).map(str::to_string))
                .collect(),
            can: (0..streams).map(|i| source.is_can(i)).collect(),
            flagged: source.flagged_bytes(),
            looks: source.looks(),
            recording: source.recording_id(),
        }
    }
}

/// Received bytes of one stream and, where the source has a clock, the time each one arrived.
#[derive(Debug, Clone, Copy)]
pub struct Batch<'a> {
    /// The bytes, in arrival order.
    pub bytes: &'a [u8],
    /// Receive time of each byte in seconds (same length as `bytes`), or `None`.
    pub times: Option<&'a [f64]>,
    /// Which stream of the input the bytes belong to: 0 for a raw or CSV file, the interface
    /// index in a recording, the port's position for serial ports.
    pub stream: usize,
}

/// One opened input.
pub struct Input {
    name: String,
    format: InputFormat,
    /// The reader; `None` for a file not open at the moment (not read yet, rewound, or at its
    /// end), whose reader's answers are then in `kept`.
    source: Option<Box<dyn Source>>,
    kept: Kept,
    bytes: Vec<u8>,
    times: Vec<f64>,
    /// The stream of the current batch.
    stream: usize,
    seen_any: bool,
    done: bool,
    /// An error met after some bytes of a batch: reported on the next call, so that the bytes
    /// before it are decoded first.
    deferred: Option<InputError>,
    /// Where notices go ([`crate::notice`]).
    notices: NoticeSink,
    /// A regular file opened by its path: open only while it is read (see
    /// [`Input::from_file`]).
    path: Option<Box<dyn Reopen>>,
    /// Notices given since the file was opened, and how many of them a reading before a
    /// rewind already gave (those are not given again).
    told: usize,
    muted: usize,
    /// Whether a regular file of raw bytes is read ahead on a thread of its own when it is
    /// opened to be read (see [`Input::read_ahead`]).
    ahead: bool,
}

impl Input {
    /// The input of a regular file opened by its path (`hwfoc-io` opens it: `file`, read from
    /// its start), its format detected. It is closed again once its format is known: it is
    /// open only while it is read, from its first [`Input::next_batch`] to its end (`path`
    /// opens it again), so that any number of inputs can be given together.
    pub fn from_file(
        name: &str,
        path: Box<dyn Reopen>,
        file: Box<dyn RegularFile>,
    ) -> Result<Input, InputError> {
        let mut input = Input::read_file(name, file, false)?;
        // Closed until read: a year of rotated recordings is thousands of inputs, more than a
        // process may hold open. (A pipe or a device cannot be opened again.)
        input.path = Some(path);
        input.close();
        Ok(input)
    }

    /// Opens the file again (from its start) after [`Input::close`]; its format must not have
    /// changed.
    fn reopen(&mut self) -> Result<(), InputError> {
        let Some(path) = &self.path else {
            return Ok(());
        };
        let file = path.open().map_err(|source| InputError::Open {
            input: self.name.clone(),
            source,
        })?;
        let fresh = Input::read_file(&self.name, file, self.ahead)?;
        if fresh.format != self.format {
            return Err(InputError::Changed {
                input: self.name.clone(),
                format: fresh.format,
            });
        }
        self.source = fresh.source;
        self.told = 0;
        Ok(())
    }

    /// Closes the source, keeping what is asked of it after its end, and lets go of the
    /// buffers.
    fn close(&mut self) {
        if let Some(source) = self.source.take() {
            self.kept = Kept::of(&*source);
        }
        self.bytes = Vec::new();
        self.times = Vec::new();
    }

    /// Starts a file opened by its path again from its beginning, closing it until it is read:
    /// what was read of it is read again, without its notices. False (and nothing changes) for
    /// any other input, which cannot be read twice.
    pub fn rewind(&mut self) -> bool {
        if self.path.is_none() {
            return false;
        }
        self.close();
        self.stream = 0;
        self.seen_any = false;
        self.done = false;
        self.deferred = None;
        self.muted = self.told;
        true
    }

    /// The recording this input is a part of, where it names one ([`pcapng::RecordingId`]:
    /// hwfoc's recordings do, in their section header), once its first batch is read.
    pub fn recording_id(&self) -> Option<pcapng::RecordingId> {
        match &self.source {
            Some(source) => source.recording_id(),
            None => self.kept.recording,
        }
    }

    /// The length of a regular file opened by its path, as it is now.
    pub(crate) fn file_len(&self) -> Option<u64> {
        self.path.as_ref()?.file_len()
    }

    /// Whether this input and `other` are regular files holding the same bytes (the same
    /// file given twice, or a copy of it): compared only when their lengths are equal, and
    /// then to the first byte that differs.
    pub(crate) fn same_bytes_as(&self, other: &Input) -> bool {
        let (Some(a), Some(b)) = (&self.path, &other.path) else {
            return false;
        };
        a.same_bytes_as(&**b)
    }

    /// Hands `notice` to the input's notice sink.
    pub(crate) fn tell(&mut self, notice: Notice) {
        (self.notices)(notice);
    }

    /// An input over bytes already in memory (the built-in demo stream).
    pub fn from_memory(name: &str, data: Vec<u8>) -> Result<Input, InputError> {
        Input::from_reader(name, Box::new(Cursor::new(data)))
    }

    /// Detects the format from the first bytes of `reader`: the one place formats are
    /// detected, each format's reader made in a line of its own.
    pub fn from_reader(name: &str, mut reader: Box<dyn Read>) -> Result<Input, InputError> {
        let head = read_head(name, &mut reader)?;
        Input::with_head(name, head, Opened::Reader(reader))
    }

    /// [`Input::from_reader`] of a regular file: raw bytes are read ahead
    /// ([`RegularFile::read_ahead`]) when `ahead`.
    fn read_file(
        name: &str,
        mut file: Box<dyn RegularFile>,
        ahead: bool,
    ) -> Result<Input, InputError> {
        let head = read_head(name, &mut file)?;
        let opened = Opened::File { file, ahead };
        Input::with_head(name, head, opened)
    }

    /// Reads a regular file of raw bytes ahead on a thread of its own, from the next time it is
    /// opened to be read (its first [`Input::next_batch`]): the kernel's copy of its bytes then
    /// runs beside the decoder. Worth it where the decoder's loop is the bottleneck and a core
    /// is free (a summary); [`crate::Sources`] sets it for the handlers that ask
    /// ([`crate::Handler::TAKES_RUNS`]). Other inputs ignore it.
    pub fn read_ahead(&mut self, ahead: bool) {
        self.ahead = ahead;
    }

    /// The length of a raw input that is a regular file, as it is now (before it is read).
    pub(crate) fn raw_file_len(&self) -> Option<u64> {
        self.file_len().filter(|_| self.format == InputFormat::RAW)
    }

    /// A raw input that is a regular file, being read: a second handle on it, for positional
    /// reads of a later part, and its length now.
    pub(crate) fn later_half(&self) -> Option<(Box<dyn ReadAt>, u64)> {
        let file = self.source.as_ref()?.file()?;
        let len = file.file_len()?;
        Some((file.try_clone()?, len))
    }

    /// The input whose first bytes, `head`, were read of `opened`.
    fn with_head(name: &str, head: Vec<u8>, opened: Opened) -> Result<Input, InputError> {
        if CLASSIC_PCAP.iter().any(|m| head.starts_with(m)) {
            return Err(InputError::ClassicPcap {
                input: name.to_string(),
            });
        }
        let source: Box<dyn Source> = if recording::is_start(&head) {
            let reader = Box::new(Cursor::new(head).chain(opened.reader()));
            Box::new(RecordingReader::new(reader))
        } else if let Some(log) = can_log::Log::of(&head) {
            log.source(Box::new(Cursor::new(head).chain(opened.reader())))
        } else if csv::is_header(&head) {
            let reader = BufReader::with_capacity(BATCH, opened.reader());
            Box::new(CsvRows::open(name, reader, head)?)
        } else {
            let (reader, file) = opened.raw();
            Box::new(RawReader::new(reader, file, head))
        };
        Ok(Input::from_source(name, source))
    }

    /// What a raw input's first bytes look like when they are not telemetry (text, zeros, a
    /// known file format); `None` for other inputs and for bytes that may be telemetry.
    pub fn looks(&self) -> Option<Looks> {
        self.source.as_ref().map_or(self.kept.looks, |s| s.looks())
    }

    /// The input read by `source` (live ports: `hwfoc-io`'s), named `name`.
    pub fn from_source(name: &str, source: Box<dyn Source>) -> Input {
        Input {
            name: name.to_string(),
            format: source.format(),
            source: Some(source),
            kept: Kept::default(),
            bytes: Vec::new(),
            times: Vec::new(),
            stream: 0,
            seen_any: false,
            done: false,
            deferred: None,
            notices: notice::to_stderr(),
            path: None,
            told: 0,
            muted: 0,
            ahead: false,
        }
    }

    /// Hands the input's notices (a port lost or back, a recording's notes and skipped parts)
    /// to `sink` as they are met, instead of standard error.
    pub fn set_notices(&mut self, sink: impl FnMut(Notice) + Send + 'static) {
        self.notices = Box::new(sink);
    }

    /// The input's name as the user gave it.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The detected format.
    pub fn format(&self) -> InputFormat {
        self.format
    }

    /// Bytes the logic analyser flagged with a parity or framing error (passed on all the same:
    /// the frame checksum decides).
    pub fn flagged_bytes(&self) -> u64 {
        self.source
            .as_ref()
            .map_or(self.kept.flagged, |s| s.flagged_bytes())
    }

    /// The number of streams known so far: 1 for a raw or CSV file, the number of ports, or the
    /// number of interfaces a recording has declared up to the point read (it may grow).
    pub fn streams(&self) -> usize {
        self.source
            .as_ref()
            .map_or(self.kept.streams, |s| s.streams())
    }

    /// The name of stream `i`: the port (a recording's interface name, which is the port it
    /// was recorded from), or the input's name for a single-stream input.
    pub fn stream_name(&self, i: usize) -> String {
        let name = match &self.source {
            Some(source) => source.stream_name(i),
            None => self.kept.names.get(i).map(String::as_str),
        };
        name.unwrap_or(&self.name).to_string()
    }

    /// Whether stream `i` is a CAN bus (a `candump` log's interface, a recording's CAN
    /// interface, a CAN adapter): its bytes are frames of
    /// [`SOCKETCAN_RECORD_LEN`](hwfoc::dronecan::SOCKETCAN_RECORD_LEN) bytes each, in
    /// [`CanFrame::to_socketcan_record`](hwfoc::dronecan::CanFrame::to_socketcan_record)'s
    /// layout, every byte with its frame's receive time.
    pub fn is_can(&self, i: usize) -> bool {
        match &self.source {
            Some(source) => source.is_can(i),
            None => self.kept.can.get(i).copied().unwrap_or(false),
        }
    }

    /// The next batch of bytes, or `None` at the end of the input.
    pub fn next_batch(&mut self) -> Result<Option<Batch<'_>>, InputError> {
        if let Some(e) = self.deferred.take() {
            self.end();
            return Err(e);
        }
        if self.done {
            return Ok(None);
        }
        if self.source.is_none()
            && let Err(e) = self.reopen()
        {
            self.done = true;
            return Err(e);
        }
        self.times.clear();
        self.stream = 0;
        // Notices are counted, and those a reading before a rewind gave are not given again.
        let (sink, told, muted) = (&mut self.notices, &mut self.told, self.muted);
        let mut notices = |notice: Notice| {
            *told += 1;
            if *told > muted {
                sink(notice);
            }
        };
        let read = match &mut self.source {
            Some(source) => source.fill(&self.name, &mut self.bytes, &mut self.times, &mut notices),
            None => {
                self.bytes.clear();
                Ok(0)
            }
        };
        match read {
            Ok(stream) => self.stream = stream,
            Err(e) if self.bytes.is_empty() => {
                self.end();
                return Err(e);
            }
            Err(e) => self.deferred = Some(e),
        }
        if self.bytes.is_empty() {
            self.end();
            // A live input ends when it is stopped: not an error even with no bytes.
            if !self.seen_any && !self.format.is_live() {
                return Err(InputError::Empty {
                    input: self.name.clone(),
                });
            }
            return Ok(None);
        }
        self.seen_any = true;
        Ok(self.current_batch())
    }

    /// At the end (or at an error): a file is closed, its buffers let go.
    fn end(&mut self) {
        self.done = true;
        if self.path.is_some() {
            self.close();
        }
    }

    /// The batch [`Input::next_batch`] returned last, again (`None` before the first and at
    /// the end).
    pub(crate) fn current_batch(&self) -> Option<Batch<'_>> {
        if self.bytes.is_empty() || self.done {
            return None;
        }
        Some(Batch {
            bytes: &self.bytes,
            times: (self.format.clock() != Clock::None).then_some(&self.times[..]),
            stream: self.stream,
        })
    }
}

/// The first bytes of an input, as many as detecting its format takes; an empty input is an
/// error naming it.
fn read_head(name: &str, reader: &mut dyn Read) -> Result<Vec<u8>, InputError> {
    let read_err = |source| InputError::Read {
        input: name.to_string(),
        source,
    };
    // A CSV export starts with its header line ("Time [s],Value,..."); raw telemetry does not
    // start with 'T' (or a UTF-8 byte-order mark). Read no further than needed to decide, so
    // that a live raw stream is not held up.
    let mut head = Vec::new();
    let mut byte = [0u8; 1];
    loop {
        let n = read_some(reader, &mut byte).map_err(read_err)?;
        if n == 0 {
            break;
        }
        head.push(byte[0]);
        // A CAN log starts with its first line, read whole (a candump log's `(` and a
        // timestamp, an ASC log's date), or its magic (BLF).
        let may_be = may_be_header(&head) || can_log::may_start(&head);
        if !may_be || byte[0] == b'\n' || head.len() >= 512 {
            break;
        }
    }
    if head.is_empty() {
        return Err(InputError::Empty {
            input: name.to_string(),
        });
    }
    // A classic libpcap file (Wireshark's older format) starts with its magic number.
    while head.len() < 4 && CLASSIC_PCAP.iter().any(|m| m.starts_with(&head)) {
        let n = read_some(reader, &mut byte).map_err(read_err)?;
        if n == 0 {
            break;
        }
        head.push(byte[0]);
    }
    // A pcapng recording starts with the section header's type, 0A 0D 0D 0A, and its
    // byte-order magic follows at bytes 8..12.
    while head.len() < 12 && pcapng::MAGIC.starts_with(&head[..head.len().min(4)]) {
        let n = read_some(reader, &mut byte).map_err(read_err)?;
        if n == 0 {
            break;
        }
        head.push(byte[0]);
    }
    Ok(head)
}

/// What an input is read from once its first bytes are known.
enum Opened {
    /// Any reader.
    Reader(Box<dyn Read>),
    /// A regular file: raw bytes of it are read ahead when `ahead`.
    File {
        file: Box<dyn RegularFile>,
        ahead: bool,
    },
}

impl Opened {
    fn reader(self) -> Box<dyn Read> {
        match self {
            Opened::Reader(reader) => reader,
            Opened::File { file, .. } => file,
        }
    }

    /// The reader of raw bytes, and a second handle on a regular file (for positional reads
    /// of a later part: [`Input::later_half`]).
    fn raw(self) -> (raw::Reader, Option<Box<dyn ReadAt>>) {
        match self {
            Opened::Reader(reader) => (raw::Reader::Plain(reader), None),
            Opened::File { file, ahead } => {
                let second = file.second();
                let reader = match ahead {
                    true => match file.read_ahead() {
                        Ok(ahead) => raw::Reader::Ahead(ahead),
                        Err(file) => raw::Reader::Plain(file),
                    },
                    false => raw::Reader::Plain(file),
                };
                (reader, second)
            }
        }
    }
}

/// `read` that retries when interrupted by a signal.
pub fn read_some(reader: &mut dyn Read, buf: &mut [u8]) -> io::Result<usize> {
    loop {
        match reader.read(buf) {
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            other => return other,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::recording::RECORDING_WINDOW_NS;
    use super::*;

    fn read_all(input: &mut Input) -> (Vec<u8>, Option<Vec<f64>>) {
        let (mut bytes, mut times) = (Vec::new(), None::<Vec<f64>>);
        while let Some(b) = input.next_batch().unwrap() {
            bytes.extend_from_slice(b.bytes);
            if let Some(t) = b.times {
                times.get_or_insert_with(Vec::new).extend_from_slice(t);
            }
        }
        (bytes, times)
    }

    /// Each format's policy, as the summary, the `--from`/`--to` check and `Sources` read it:
    /// names, clock, live, recorded ports, and so whether it is merged in time.
    #[test]
    fn every_format_says_its_own_policy() {
        let table = [
            (
                InputFormat::RAW,
                "raw bytes",
                "raw",
                Clock::None,
                false,
                false,
                false,
            ),
            (
                InputFormat::ANALYZER_CSV,
                "logic-analyser CSV",
                "csv",
                Clock::Capture,
                false,
                false,
                true,
            ),
            (
                InputFormat::RECORDING,
                "pcapng recording",
                "pcapng",
                Clock::Wall,
                false,
                true,
                true,
            ),
            (
                InputFormat::SERIAL,
                "serial port",
                "serial",
                Clock::Wall,
                true,
                false,
                false,
            ),
        ];
        for (format, name, short, clock, live, ports, merged) in table {
            assert_eq!(format.to_string(), name);
            assert_eq!(format.short_name(), short);
            assert_eq!(format.clock(), clock, "{name}");
            assert_eq!(format.is_live(), live, "{name}");
            assert_eq!(format.has_recorded_ports(), ports, "{name}");
            assert_eq!(format.is_merged_in_time(), merged, "{name}");
        }
        for (i, a) in table.iter().enumerate() {
            for (j, b) in table.iter().enumerate() {
                assert_eq!(a.0 == b.0, i == j);
            }
        }
    }

    #[test]
    fn detects_csv_and_raw() {
        let csv = b"Time [s],Value,Parity Error,Framing Error\n0.5,0x9B,,\n0.75,0x16,,x\n".to_vec();
        let mut input = Input::from_memory("a.csv", csv).unwrap();
        assert_eq!(input.format(), InputFormat::ANALYZER_CSV);
        assert_eq!(
            read_all(&mut input),
            (vec![0x9B, 0x16], Some(vec![0.5, 0.75]))
        );
        assert_eq!(input.flagged_bytes(), 1);

        let raw = b"\x9B\x16\x01Time".to_vec();
        let mut input = Input::from_memory("a.bin", raw.clone()).unwrap();
        assert_eq!(input.format(), InputFormat::RAW);
        assert_eq!(read_all(&mut input), (raw, None));

        // Text that is not a logic-analyser export is raw bytes too.
        let input = Input::from_memory("t", b"Tea,time\n".to_vec()).unwrap();
        assert_eq!(input.format(), InputFormat::RAW);
    }

    #[test]
    fn bad_csv_row_names_its_line() {
        let csv = b"Time [s],Value\r\n0.5,0x9B\r\n0.6,\"0x9B\"\r\n\r\n0.7,nope\r\n".to_vec();
        let mut input = Input::from_memory("cap.csv", csv).unwrap();
        let err = loop {
            match input.next_batch() {
                Ok(Some(_)) => {}
                Ok(None) => panic!("no error"),
                Err(e) => break e,
            }
        };
        assert_eq!(
            err.to_string(),
            "cap.csv:5: bad byte value \"nope\" (expected 0x00..0xFF or 0..255)"
        );
    }

    #[test]
    fn an_endless_stream_of_zeros_ends_with_an_error() {
        // `/dev/zero` as a reader: endless zeros stop at the limit, naming the input.
        let mut input = Input::from_reader("/dev/zero", Box::new(std::io::repeat(0))).unwrap();
        let err = loop {
            match input.next_batch() {
                Ok(Some(_)) => {}
                Ok(None) => panic!("an endless input ended"),
                Err(e) => break e,
            }
        };
        assert!(
            matches!(err, InputError::OnlyZeros { bytes, .. } if bytes >= ONLY_ZEROS_LIMIT),
            "{err}"
        );
        assert_eq!(
            err.to_string(),
            "/dev/zero: only zero bytes, not telemetry (the first 64 MiB; reading stopped)"
        );
        // One byte that is not zero, and the zeros after it are read to the end.
        let mut bytes = vec![0u8; (ONLY_ZEROS_LIMIT + (1 << 20)) as usize];
        bytes[10] = 0x9B;
        let mut input = Input::from_reader("x", Box::new(std::io::Cursor::new(bytes))).unwrap();
        while input.next_batch().unwrap().is_some() {}
    }

    #[test]
    fn empty_inputs_are_errors() {
        let e = Input::from_memory("x", Vec::new()).err().unwrap();
        assert_eq!(e.to_string(), "x is empty: there is nothing to decode");
        let mut input = Input::from_memory("h.csv", b"Time [s],Value\n".to_vec()).unwrap();
        assert!(matches!(input.next_batch(), Err(InputError::Empty { .. })));
    }

    /// Batches as (stream, bytes, times), owned.
    fn batches(input: &mut Input) -> Vec<(usize, Vec<u8>, Vec<f64>)> {
        let mut out = Vec::new();
        while let Some(b) = input.next_batch().unwrap() {
            out.push((b.stream, b.bytes.to_vec(), b.times.unwrap().to_vec()));
        }
        out
    }

    #[test]
    fn recordings_are_detected_and_give_a_stream_per_port() {
        let mut w = pcapng::Writer::new(Vec::new()).unwrap();
        w.add_interface("/dev/ttyUSB0", 19200).unwrap();
        w.add_interface("/dev/ttyUSB1", 9600).unwrap();
        let t0 = 1_700_000_000_000_000_000u64;
        w.write(0, t0, &[1, 2]).unwrap();
        w.write(0, t0 + 10_000_000, &[3]).unwrap();
        w.comment(1, t0 + 15_000_000, "gap: /dev/ttyUSB1 lost")
            .unwrap();
        w.write(1, t0 + 20_000_000, &[4, 5]).unwrap();
        w.write(0, t0 + 30_000_000, &[6]).unwrap();
        let file = w.into_inner().unwrap();

        // Whatever the name: the content decides.
        let mut input = Input::from_memory("capture.bin", file).unwrap();
        assert_eq!(input.format(), InputFormat::RECORDING);
        let got = batches(&mut input);
        assert_eq!(input.streams(), 2);
        assert_eq!(input.stream_name(1), "/dev/ttyUSB1");
        assert_eq!(input.stream_name(7), "capture.bin");
        // One window (all within 30 ms): each port's bytes in one batch, in port order.
        let streams: Vec<usize> = got.iter().map(|b| b.0).collect();
        assert_eq!(streams, [0, 1]);
        assert_eq!(got[0].1, [1, 2, 3, 6]);
        assert_eq!(got[1].1, [4, 5]);
        let t = t0 as f64 * 1e-9;
        let close = |a: f64, b: f64| (a - b).abs() < 1e-6;
        // Byte 2 of a chunk at 19200 baud: 1/1920 s after the first.
        assert!(close(got[0].2[0], t) && close(got[0].2[1], t + 1.0 / 1920.0));
        assert!(close(got[0].2[2], t + 0.010));
        assert!(close(got[0].2[3], t + 0.030));
        assert!(close(got[1].2[1], t + 0.020 + 1.0 / 960.0));
    }

    /// A recording's notes and damage go to the input's notice sink (a front end's own
    /// channel), not to standard error, and do not stop reading.
    #[test]
    fn notices_go_to_the_sink_set() {
        let mut w = pcapng::Writer::new(Vec::new()).unwrap();
        w.add_interface("/dev/ttyUSB0", 19200).unwrap();
        let t0 = 1_700_000_000_000_000_000u64;
        w.write(0, t0, &[1, 2]).unwrap();
        w.comment(0, t0 + 1, "gap: 3 bytes lost").unwrap();
        w.write(0, t0 + 2, &[3]).unwrap();
        let mut file = w.into_inner().unwrap();
        let end = file.len() as u64;
        file.extend_from_slice(&[0xEE; 40]);
        let mut input = Input::from_memory("cut.pcapng", file).unwrap();
        let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let sink = std::sync::Arc::clone(&seen);
        input.set_notices(move |n| sink.lock().unwrap().push(n));
        assert_eq!(read_all(&mut input).0, [1, 2, 3]);
        let seen = seen.lock().unwrap();
        assert_eq!(seen.len(), 2, "{seen:?}");
        assert_eq!(
            seen[0],
            Notice::Comment {
                input: "cut.pcapng".into(),
                interface: "/dev/ttyUSB0".into(),
                text: "gap: 3 bytes lost".into(),
            }
        );
        assert!(
            matches!(&seen[1], Notice::Damage { input, damage }
                if input == "cut.pcapng" && damage.offset == end),
            "{seen:?}"
        );
        assert!(
            seen[1]
                .line()
                .starts_with("hwfoc: warning: cut.pcapng: stopped at byte")
        );
    }

    #[test]
    fn recording_batches_follow_time_windows() {
        let mut w = pcapng::Writer::new(Vec::new()).unwrap();
        w.add_interface("a", 19200).unwrap();
        w.add_interface("b", 19200).unwrap();
        let s = RECORDING_WINDOW_NS;
        for (iface, t, byte) in [
            (0, 0, 1),
            (1, s / 2, 2),
            (0, 2 * s, 3),
            (1, 2 * s, 4),
            (1, 5 * s, 5),
        ] {
            w.write(iface, 10 * s + t, &[byte]).unwrap();
        }
        let mut input = Input::from_memory("r.pcapng", w.into_inner().unwrap()).unwrap();
        let got: Vec<(usize, Vec<u8>)> = batches(&mut input)
            .into_iter()
            .map(|b| (b.0, b.1))
            .collect();
        // A window ends with the first packet RECORDING_WINDOW_NS or more after its first.
        assert_eq!(got, [(0, vec![1, 3]), (1, vec![2]), (1, vec![4, 5])]);
    }

    /// A read error ends a raw input: it is returned once, naming the input, and no batch is
    /// left behind it (not the read buffer, nor bytes the reader gives after the error).
    #[test]
    fn a_read_error_ends_a_raw_input_and_leaves_no_batch() {
        /// One byte, then an error, then bytes again.
        struct Flaky(u32);
        impl Read for Flaky {
            fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
                self.0 += 1;
                match self.0 {
                    2 => Err(io::Error::other("cable pulled")),
                    _ => {
                        buf[0] = 0x9B;
                        Ok(1)
                    }
                }
            }
        }
        let mut input = Input::from_reader("flaky", Box::new(Flaky(0))).unwrap();
        assert_eq!(input.next_batch().unwrap().unwrap().bytes, [0x9B]);
        let e = input.next_batch().err().unwrap();
        assert_eq!(e.to_string(), "cannot read flaky: cable pulled");
        assert!(input.current_batch().is_none());
        assert!(input.next_batch().unwrap().is_none());
    }

    #[test]
    fn raw_bytes_starting_like_a_recording_stay_raw() {
        let raw = vec![0x0A, 0x0D, 0x0D, 0x0A, 0, 0, 0, 0, 1, 2, 3, 4, 0x9B];
        let mut input = Input::from_memory("odd.bin", raw.clone()).unwrap();
        assert_eq!(input.format(), InputFormat::RAW);
        assert_eq!(read_all(&mut input), (raw, None));
        let raw = vec![0x0A, 0x9B, 0x16];
        let mut input = Input::from_memory("nl.bin", raw.clone()).unwrap();
        assert_eq!(read_all(&mut input), (raw, None));
    }

    /// The first error of reading `input` to its end.
    fn first_error(mut input: Input) -> InputError {
        loop {
            match input.next_batch() {
                Ok(Some(_)) => {}
                Ok(None) => panic!("no error"),
                Err(e) => break e,
            }
        }
    }

    #[test]
    fn an_endless_line_is_an_error_not_memory_and_messages_quote_little() {
        let mut csv = b"Time [s],Value\n0.5,0x9B\n".to_vec();
        csv.extend(std::iter::repeat_n(b'7', 10 << 20));
        let e = first_error(Input::from_memory("big.csv", csv).unwrap());
        assert_eq!(
            e.to_string(),
            "big.csv:3: the line is longer than 65536 bytes: not a logic-analyser export"
        );
        let mut csv = b"Time [s],Value\n0.5,".to_vec();
        csv.extend(std::iter::repeat_n(b'x', 5000));
        csv.push(b'\n');
        let e = first_error(Input::from_memory("long.csv", csv).unwrap()).to_string();
        assert!(e.starts_with("long.csv:2: bad byte value \"xxxx"), "{e}");
        assert!(
            e.ends_with("\"... (5000 bytes) (expected 0x00..0xFF or 0..255)"),
            "{e}"
        );
        assert!(e.len() < 150, "{e}");
        let mut header = b"Time [s],Value,".to_vec();
        header.extend(std::iter::repeat_n(b'x', 200 << 10));
        let e = Input::from_memory("h.csv", header).err().unwrap();
        assert!(
            e.to_string()
                .starts_with("h.csv:1: the header line is longer"),
            "{e}"
        );
    }

    #[test]
    fn thousands_of_error_columns_are_read_in_one_pass() {
        let columns = 4000;
        let mut csv = "Time [s],Value".to_string();
        for i in 0..columns {
            csv.push_str(&format!(",Error {i}"));
        }
        csv.push('\n');
        for row in 0..50 {
            csv.push_str(&format!("{}.0,0x{:02X}", row, row));
            for i in 0..columns {
                // Row 7 has a flag in its last column only.
                csv.push_str(if row == 7 && i == columns - 1 {
                    ",x"
                } else {
                    ","
                });
            }
            csv.push('\n');
        }
        let mut input = Input::from_memory("wide.csv", csv.into_bytes()).unwrap();
        let (bytes, times) = read_all(&mut input);
        assert_eq!(bytes, (0..50u8).collect::<Vec<_>>());
        assert_eq!(times.unwrap()[49], 49.0);
        assert_eq!(input.flagged_bytes(), 1);
    }

    /// A recording of 50 000 interface blocks for the same two ports, as concatenated
    /// sections give: the ports are found once each. (Interfaces are looked up by port, so
    /// that any number of interface blocks is read in linear time.)
    #[test]
    fn many_interface_blocks_name_few_ports() {
        let mut file = Vec::new();
        for section in 0..25_000u64 {
            let mut w = pcapng::Writer::new(Vec::new()).unwrap();
            w.add_interface("/dev/ttyUSB0", 19200).unwrap();
            w.add_interface("/dev/ttyUSB1", 19200).unwrap();
            w.write(1, 1_700_000_000_000_000_000 + section, &[0x55])
                .unwrap();
            file.extend(w.into_inner().unwrap());
        }
        let mut input = Input::from_memory("many.pcapng", file).unwrap();
        let (bytes, _) = read_all(&mut input);
        assert_eq!(bytes.len(), 25_000);
        assert_eq!(input.streams(), 2);
    }

    /// A section declaring one port in 200 000 interface blocks (each a stream of its own, as
    /// a section's interfaces are), with bytes on the first and the last: read in linear time.
    /// (A search of the port's interfaces for each block took minutes; the bound is generous
    /// for a loaded machine and a debug build, where the linear read takes about a second.)
    #[test]
    fn one_section_of_many_interfaces_of_one_port_reads_in_linear_time() {
        let n = 200_000u32;
        let mut w = pcapng::Writer::new(Vec::new()).unwrap();
        for _ in 0..n {
            w.add_interface("/dev/ttyUSB0", 19200).unwrap();
        }
        let t = 1_700_000_000_000_000_000;
        w.write(0, t, &[1]).unwrap();
        w.write(n - 1, t + 1_000_000, &[2]).unwrap();
        let file = w.into_inner().unwrap();
        let started = std::time::Instant::now();
        let mut input = Input::from_memory("many.pcapng", file).unwrap();
        let got = batches(&mut input);
        let elapsed = started.elapsed();
        assert_eq!(input.streams(), n as usize);
        let streams: Vec<(usize, Vec<u8>)> = got.into_iter().map(|b| (b.0, b.1)).collect();
        assert_eq!(streams, [(0, vec![1]), (n as usize - 1, vec![2])]);
        assert!(elapsed.as_secs() < 30, "{elapsed:?}");
    }

    /// A file is open only while it is read, and read again from its start after a rewind,
    /// without telling its notices twice; a file that is no longer of its format when it is
    /// opened again is an error naming it.
    #[test]
    fn files_are_opened_when_read_and_can_be_read_again() {
        let mut w = pcapng::Writer::new(Vec::new()).unwrap();
        w.add_interface("/dev/ttyUSB0", 19200).unwrap();
        w.comment(0, 1, "a note").unwrap();
        w.write(0, 2, &[7, 8]).unwrap();
        let name = "r.pcapng";
        let file = file::memory::MemoryFile::new(name, w.into_inner().unwrap());
        let mut input = file.input().unwrap();
        assert!(input.source.is_none());
        let seen = std::sync::Arc::new(std::sync::Mutex::new(0));
        let count = std::sync::Arc::clone(&seen);
        input.set_notices(move |_| *count.lock().unwrap() += 1);
        assert_eq!(input.next_batch().unwrap().unwrap().bytes, [7, 8]);
        assert!(input.rewind());
        assert!(input.source.is_none());
        assert_eq!(read_all(&mut input).0, [7, 8]);
        assert!(input.source.is_none());
        assert_eq!(input.stream_name(0), "/dev/ttyUSB0");
        assert_eq!(*seen.lock().unwrap(), 1);
        assert!(input.rewind());
        *file.bytes.lock().unwrap() = std::sync::Arc::new(b"raw bytes now".to_vec());
        let e = input.next_batch().err().unwrap();
        assert_eq!(
            e.to_string(),
            format!("{name} changed while it was being read: it is now raw bytes")
        );
        let mut memory = Input::from_memory("m.bin", vec![1]).unwrap();
        assert!(!memory.rewind());
    }

    #[test]
    fn classic_pcap_files_are_named_as_such() {
        for magic in CLASSIC_PCAP {
            let mut file = magic.to_vec();
            file.extend_from_slice(&[2, 0, 4, 0, 0, 0, 0, 0]);
            let e = Input::from_memory("old.pcap", file).err().unwrap();
            assert_eq!(
                e.to_string(),
                "old.pcap is a classic libpcap file, not pcapng: convert it with \
                 `editcap -F pcapng old.pcap old.pcapng`, then decode that"
            );
        }
        // Raw bytes that merely start like one stay raw.
        let raw = vec![0xD4, 0xC3, 0x9B, 0x16];
        let mut input = Input::from_memory("r.bin", raw.clone()).unwrap();
        assert_eq!(read_all(&mut input), (raw, None));
    }
}
