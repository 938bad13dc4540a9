//! A PEAK TRC trace (PCAN-View, python-can's `TRCWriter`), versions 1.1 to 2.1, as an input:
//! one CAN stream per bus, named `bus N` (`bus 1` where the version has no bus column).
//!
//! Header lines start with `;`: `;$FILEVERSION=x.y`, `;$STARTTIME=<days since 1899-12-30,
//! UTC>`, and from 2.0 `;$COLUMNS=N,O,T,B,I,d,R,L,D` naming the columns of the message lines.
//! Versions 1.x have their columns by version: 1.1 `N) O Rx|Tx I L D`, 1.2 adds the bus
//! before the direction, 1.3 a reserved column after the id. A message's time is the start plus
//! its offset `O` in milliseconds; an id of more than 4 hex digits is extended; `RTR` as data
//! (1.x) or type `RR` (2.x) is a remote frame, types `FD`, `FB`, `FE`, `BI` are CAN FD, other
//! types and directions (errors, warnings, events) are passed over. Version 1.0 has no start
//! time, and is refused as such.
//!
//! Written here: no crate reads TRC files.

use std::io::Read;

use super::can_log::{CanLogReader, Entry, LineFrame, LineFrames, Lines, decimal_ns};
use super::{InputError, InputFormat};
use crate::can::candump::Logged;
use crate::time::Clock;

impl InputFormat {
    /// A PEAK TRC trace: one CAN stream per bus, times its own (Unix seconds).
    pub const TRC: InputFormat = InputFormat {
        name: "PEAK TRC trace",
        short_name: "trc",
        clock: Clock::Wall,
        live: false,
        recorded_ports: true,
    };
}

/// What the trace is called in its errors.
const WHAT: &str = "a PEAK TRC trace";
/// Its first line's start.
const VERSION: &str = ";$FILEVERSION=";
/// Days from 1899-12-30 (the trace's epoch) to 1970-01-01.
const EPOCH_DAYS: f64 = 25_569.0;

/// Whether `head`, an input's first bytes, may still be the start of a TRC trace.
pub(super) fn may_start(head: &[u8]) -> bool {
    VERSION.as_bytes().starts_with(head) || is_start(head)
}

/// Whether `head`, an input's first line, starts a TRC trace (its file version).
pub(super) fn is_start(head: &[u8]) -> bool {
    head.starts_with(VERSION.as_bytes())
}

/// The lines of a TRC trace, read as frames.
pub(super) struct TrcLines {
    lines: Lines,
    version: String,
    start_ns: Option<u64>,
    /// The columns of a message line, by their letters.
    columns: Vec<char>,
}

impl TrcLines {
    /// Reads the trace `reader` gives, from its first line.
    pub(super) fn reader(reader: Box<dyn Read>) -> CanLogReader<TrcLines> {
        CanLogReader::new(TrcLines {
            lines: Lines::new(reader),
            version: String::new(),
            start_ns: None,
            columns: Vec::new(),
        })
    }

    /// Reads a header line.
    fn header(&mut self, name: &str, text: &str) -> Result<(), InputError> {
        if let Some(v) = text.strip_prefix(VERSION) {
            self.version = v.trim().to_string();
            self.columns = match self.version.as_str() {
                "1.1" => "NOdILD",
                "1.2" => "NOBdILD",
                "1.3" => "NOBdIRLD",
                "2.0" | "2.1" => "NOTIdlD",
                _ => {
                    let e = format!("version {} is not read (1.1 to 2.1 are)", self.version);
                    return Err(self
                        .lines
                        .error(name, format!("{e}: not {WHAT} this reads")));
                }
            }
            .chars()
            .collect();
        } else if let Some(days) = text.strip_prefix(";$STARTTIME=") {
            let days: f64 = days.trim().parse().map_err(|_| {
                self.lines.error(
                    name,
                    format!("the start time is not a number of days: not {WHAT}"),
                )
            })?;
            let seconds = (days - EPOCH_DAYS) * 86_400.0;
            if !(0.0..4e9).contains(&seconds) {
                return Err(self.lines.error(
                    name,
                    format!("the start time is not a date after 1970: not {WHAT}"),
                ));
            }
            // The day's fraction holds microseconds at best: the trace's resolution.
            self.start_ns = Some((seconds * 1e6).round() as u64 * 1000);
        } else if let Some(columns) = text.strip_prefix(";$COLUMNS=") {
            self.columns = columns
                .split(',')
                .filter_map(|c| c.trim().chars().next())
                .collect();
        }
        Ok(())
    }

    /// The frame of a message line, with its bus in `bus`; `None` for a line that is no frame.
    fn message(
        &mut self,
        name: &str,
        text: &str,
        bus: &mut String,
    ) -> Result<Option<Entry>, InputError> {
        let bad = |lines: &Lines, what: &str| lines.error(name, format!("{what}: not {WHAT}"));
        let Some(start) = self.start_ns else {
            return Err(bad(
                &self.lines,
                "a message before the start time (`;$STARTTIME=`)",
            ));
        };
        let words: Vec<&str> = text.split_ascii_whitespace().collect();
        let column = |c: char| {
            self.columns
                .iter()
                .position(|&k| k == c)
                .and_then(|i| words.get(i).copied())
        };
        let offset = column('O')
            .and_then(|o| decimal_ns(o, 1_000_000))
            .ok_or_else(|| bad(&self.lines, "the time offset is not milliseconds"))?;
        let mut remote = false;
        if let Some(kind) = column('T') {
            match kind {
                "DT" => {}
                "RR" => remote = true,
                "FD" | "FB" | "FE" | "BI" => {
                    push_bus(bus, column('B'));
                    return Ok(Some(Entry {
                        t_ns: Some(start + offset),
                        frame: Logged::Fd,
                    }));
                }
                _ => return Ok(None),
            }
        }
        if let Some(direction) = column('d')
            && !matches!(direction, "Rx" | "Tx")
        {
            return Ok(None);
        }
        let id_text = column('I').ok_or_else(|| bad(&self.lines, "the line has no id"))?;
        let id =
            u32::from_str_radix(id_text, 16).map_err(|_| bad(&self.lines, "the id is not hex"))?;
        let len_at = self.columns.iter().position(|&k| k == 'L' || k == 'l');
        let len: usize = len_at
            .and_then(|i| words.get(i))
            .and_then(|l| l.parse().ok())
            .filter(|&l| l <= 8)
            .ok_or_else(|| bad(&self.lines, "the length is not 0 to 8"))?;
        let data_at = self
            .columns
            .iter()
            .position(|&k| k == 'D')
            .unwrap_or(words.len());
        let rest = words.get(data_at..).unwrap_or_default();
        if rest.first() == Some(&"RTR") {
            remote = true;
        }
        let line = LineFrame {
            id,
            extended: id_text.len() > 4,
            remote,
            len,
        };
        let frame = line.read(rest.iter().copied(), 16, |what| bad(&self.lines, what))?;
        push_bus(bus, column('B'));
        Ok(Some(Entry {
            t_ns: Some(start + offset),
            frame,
        }))
    }
}

/// Names the bus: `bus N` as the trace numbers it, `bus 1` where it has no bus column.
fn push_bus(bus: &mut String, number: Option<&str>) {
    bus.push_str("bus ");
    bus.push_str(number.filter(|n| n.parse::<u16>().is_ok()).unwrap_or("1"));
}

impl LineFrames for TrcLines {
    fn format(&self) -> InputFormat {
        InputFormat::TRC
    }

    fn lines(&mut self) -> (&mut Lines, &'static str) {
        (&mut self.lines, WHAT)
    }

    fn line(
        &mut self,
        name: &str,
        text: &str,
        bus: &mut String,
    ) -> Result<Option<Entry>, InputError> {
        if text.starts_with(';') {
            self.header(name, text)?;
            return Ok(None);
        }
        self.message(name, text, bus)
    }
}
