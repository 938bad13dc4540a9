//! A session: the bytes of one live port (a serial port, or an SLCAN adapter's CAN bus as
//! SocketCAN records) decoded into records as they come, on the path of the command's
//! `monitor` and `record` ([`PortStreams`]: the same streams, ESC numbering and records), with
//! the figures `hwfoc summary --json` gives per ESC: frames, link counters, charge and energy.

use hwfoc::Protocol;
use hwfoc::Settings;
use hwfoc::telemetry::{AnyFrame, Data, Info};
use hwfoc_records::energy::Energy;
use hwfoc_records::serial::PortEvent;
use hwfoc_records::{Handler, InputError, LinkStats, PortStreams, Record};

use crate::columns::Columns;

/// The rate a port is taken to be read at when the page names none (HW-FOC's).
const DEFAULT_BAUD: u32 = hwfoc_records::serial::DEFAULT_BAUD;

/// The characters of an adapter's line of an extended frame of 8 bytes (`T`, 8 id digits,
/// length, 16 data digits, CR): a frame's wire time on the adapter's serial port.
const SLCAN_LINE: usize = 27;

/// What a session knows of one ESC, by number.
#[derive(Default, Clone)]
pub struct EscFigures {
    /// Data frames.
    pub frames: u64,
    /// Device-information frames.
    pub info_frames: u64,
    /// The last device information's text.
    pub info: Option<String>,
    /// Charge and energy over the data frames' times ([`Energy::add`], as `monitor` counts).
    pub energy: Energy,
    /// Whether a data frame gave voltage and current (else no energy is known).
    pub powered: bool,
}

/// A stream's decoding and the records it gave that were not yet taken.
pub struct Session {
    streams: PortStreams,
    baud: u32,
    /// Whether the port is a CAN bus, fed SocketCAN records.
    can: bool,
    columns: Columns,
    escs: Vec<EscFigures>,
    notices: Vec<String>,
    /// The last chunk's first-byte time, ns: a chunk's bytes never come before the last's.
    last_ns: u64,
    bytes: u64,
    finished: bool,
}

/// A session's settings could not be taken.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SessionError {
    /// `--protocol`'s name is not one of [`Protocol::ALL`]'s.
    UnknownProtocol(String),
}

impl core::fmt::Display for SessionError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SessionError::UnknownProtocol(name) => {
                let names: Vec<&str> = Protocol::ALL.iter().map(|p| p.name()).collect();
                write!(f, "unknown protocol '{name}' (one of {})", names.join(", "))
            }
        }
    }
}

/// The Unix time in ns of the first byte of a chunk of `len` bytes whose last byte came at
/// `t_micros` (Unix microseconds), read at `baud` (8N1): the last's less the others' wire time.
pub fn first_byte_ns(t_micros: f64, len: usize, baud: u32) -> u64 {
    let last_ns = (t_micros.max(0.0) * 1000.0) as u64;
    let before = (len.saturating_sub(1) as f64 * hwfoc::wire::byte_ns(baud)) as u64;
    last_ns.saturating_sub(before)
}

impl Session {
    /// A session reading port `name` at `baud` (`None`: HW-FOC's 19200), every format or only
    /// `protocol` (a name `--protocol` takes). A CAN bus (a name `slcan:` or `can:` starts,
    /// or a CAN protocol) is fed SocketCAN records, 16 bytes a frame.
    pub fn new(
        protocol: Option<&str>,
        name: &str,
        baud: Option<u32>,
    ) -> Result<Session, SessionError> {
        let forced = match protocol {
            None | Some("") | Some("auto") => None,
            Some(name) => Some(
                Protocol::from_name(name)
                    .ok_or_else(|| SessionError::UnknownProtocol(name.to_owned()))?,
            ),
        };
        let can = hwfoc_records::can::is_can_spec(name) || forced.is_some_and(Protocol::is_can);
        let port = if can && !hwfoc_records::can::is_can_spec(name) {
            format!("slcan:{name}")
        } else {
            name.to_owned()
        };
        let baud = baud.unwrap_or(DEFAULT_BAUD);
        let mut streams = PortStreams::with_map(baud, vec![port], Settings::DEFAULT.into());
        if let Some(p) = forced {
            streams.force_protocol(p);
        }
        Ok(Session {
            streams,
            baud,
            can,
            columns: Columns::default(),
            escs: Vec::new(),
            notices: Vec::new(),
            last_ns: 0,
            bytes: 0,
            finished: false,
        })
    }

    /// Decodes `bytes`, the chunk whose last byte came at `t_micros` (Unix microseconds; None
    /// for bytes without receive times, then taken to follow the last chunk at the port's rate).
    pub fn feed(&mut self, bytes: &[u8], t_micros: Option<f64>) {
        if bytes.is_empty() || self.finished {
            return;
        }
        self.bytes += bytes.len() as u64;
        let mut take = Take {
            columns: &mut self.columns,
            escs: &mut self.escs,
        };
        // A bus's frames go each as its own event (as a bus's reader hands them on), their
        // adapter's lines back to back at the port's rate before the chunk's time; a port's
        // bytes as one event, back to back before its last.
        let size = if self.can {
            hwfoc::dronecan::SOCKETCAN_RECORD_LEN
        } else {
            bytes.len()
        };
        let n = bytes.len().div_ceil(size);
        for (k, piece) in bytes.chunks(size).enumerate() {
            let after = if self.can {
                (n - 1 - k) * SLCAN_LINE
            } else {
                piece.len() - 1
            };
            let t_ns = match t_micros {
                Some(t) => first_byte_ns(t, 1 + after, self.baud),
                None => self.last_ns + (hwfoc::wire::byte_ns(self.baud) * 64.0) as u64,
            }
            .max(self.last_ns);
            self.last_ns = t_ns;
            let event = PortEvent::Data {
                port: 0,
                t_ns,
                bytes: piece.to_vec(),
            };
            self.streams.feed(&event, &mut take);
        }
    }

    /// Ends the stream: the frames held at its end (a CAN node's records awaiting its GetEscID
    /// answer) are handed on, nothing more is decoded; a session that found no frame says so.
    pub fn finish(&mut self) {
        if self.finished {
            return;
        }
        self.finished = true;
        let mut take = Take {
            columns: &mut self.columns,
            escs: &mut self.escs,
        };
        self.streams.finish(&mut take);
        if self.escs.iter().all(|e| e.frames == 0) {
            self.notices
                .push(format!("no telemetry frame found in {} bytes", self.bytes));
        }
    }

    /// The records decoded since the last call.
    pub fn columns(&mut self) -> &mut Columns {
        &mut self.columns
    }

    /// The notices so far, as the command's stderr lines.
    pub fn notices(&self) -> &[String] {
        &self.notices
    }

    /// Per ESC (by number): its figures and its link statistics (as `hwfoc summary` counts
    /// them: its channel's on a hub or a bus, else the port's).
    pub fn escs(&self) -> impl Iterator<Item = (usize, &EscFigures, LinkStats)> {
        self.escs.iter().enumerate().map(|(esc, figures)| {
            let link = u8::try_from(esc)
                .ok()
                .and_then(|e| self.streams.channel_of(0, e))
                .zip(self.streams.stream(0))
                .map(|(channel, stream)| stream.link(channel))
                .or_else(|| self.streams.stats(0))
                .unwrap_or_default();
            (esc, figures, link)
        })
    }
}

/// The frames of a chunk, taken into the session's columns and figures.
struct Take<'a> {
    columns: &'a mut Columns,
    escs: &'a mut Vec<EscFigures>,
}

impl Take<'_> {
    fn esc(&mut self, esc: u8) -> &mut EscFigures {
        let i = usize::from(esc);
        if self.escs.len() <= i {
            self.escs.resize(i + 1, EscFigures::default());
        }
        &mut self.escs[i]
    }
}

impl Handler for Take<'_> {
    type Error = InputError;

    fn info(&mut self, esc: u8, _: Option<f64>, info: &Info) {
        let e = self.esc(esc);
        e.info_frames += 1;
        e.info = Some(info.to_string());
    }

    fn frame(&mut self, esc: u8, t: Option<f64>, frame: &AnyFrame, settings: &Settings) {
        match frame {
            AnyFrame::Data(data) => self.data(esc, t, data, settings),
            AnyFrame::Info(info) => self.info(esc, t, info),
        }
    }
}

impl Take<'_> {
    fn data(&mut self, esc: u8, t: Option<f64>, data: &Data, settings: &Settings) {
        let r = Record::new(t, esc, data, settings);
        self.columns.push_record(&r);
        let e = self.esc(esc);
        e.frames += 1;
        if let (Some(volts), Some(amps)) = (r.voltage_v, r.current_a) {
            e.energy.add(t, f64::from(volts), f64::from(amps));
            e.powered = true;
        }
    }
}

#[cfg(test)]
mod tests;
