//! A Vector ASC log (CANoe, CANalyzer, python-can's `ASCWriter`, can-utils' `log2asc`) as an
//! input: one CAN stream per channel, named `channel N` as the file numbers it.
//!
//! A header (`date <date>`, `base hex|dec  timestamps absolute|relative`, `[no] internal events
//! logged`, `Begin Triggerblock <date>`), then a line per event: `<seconds> <channel> <id>[x]
//! Rx|Tx d <dlc> <data bytes>` for a data frame, `... r [dlc]` for a remote frame, `<seconds>
//! CANFD <channel> ...` for a CAN FD frame; other events (`Start of measurement`, error frames,
//! statistics) are passed over. Times are seconds after the trigger block's date (else the
//! file's), a local time of the machine that wrote it (as python-can and Vector's tools read
//! it), or the delta to the previous event under `timestamps relative`.
//!
//! Written here: the crates that read ASC (`blf_asc`) read it into their own message type
//! with a dependency on `chrono`, without relative times, `base dec` or local dates.

use std::io::Read;

use jiff::civil::DateTime;
use jiff::fmt::strtime;
use jiff::tz::TimeZone;

use super::can_log::{CanLogReader, Entry, LineFrame, LineFrames, Lines, decimal_ns};
use super::{InputError, InputFormat};
use crate::can::candump::Logged;
use crate::time::Clock;

impl InputFormat {
    /// A Vector ASC log: one CAN stream per channel, times its own (Unix seconds).
    pub const ASC: InputFormat = InputFormat {
        name: "Vector ASC log",
        short_name: "asc",
        clock: Clock::Wall,
        live: false,
        recorded_ports: true,
    };
}

/// What the log is called in its errors.
const WHAT: &str = "a Vector ASC log";

/// Whether `head`, an input's first bytes, may still be the start of an ASC log.
pub(super) fn may_start(head: &[u8]) -> bool {
    ["date ", "base "]
        .iter()
        .any(|s| head.len() <= s.len() && s.as_bytes()[..head.len()].eq_ignore_ascii_case(head))
        || is_start(head)
}

/// Whether `head`, an input's first line, starts an ASC log: its `date` or `base` line.
pub(super) fn is_start(head: &[u8]) -> bool {
    let lower = head.to_ascii_lowercase();
    lower.starts_with(b"date ") || lower.starts_with(b"base hex") || lower.starts_with(b"base dec")
}

/// The lines of an ASC log, read as frames.
pub(super) struct AscLines {
    lines: Lines,
    /// Numbers in decimal (`base dec`).
    decimal: bool,
    /// Times are deltas to the previous event (`timestamps relative`).
    relative: bool,
    /// The time the events' times count from, Unix nanoseconds.
    start_ns: Option<u64>,
    /// The last event's time after the start (for relative times).
    last_ns: u64,
}

impl AscLines {
    /// Reads the log `reader` gives, from its first line.
    pub(super) fn reader(reader: Box<dyn Read>) -> CanLogReader<AscLines> {
        CanLogReader::new(AscLines {
            lines: Lines::new(reader),
            decimal: false,
            relative: false,
            start_ns: None,
            last_ns: 0,
        })
    }

    /// Reads a header line; false if `text` is not one.
    fn header(&mut self, name: &str, text: &str) -> Result<bool, InputError> {
        let lower = text.to_ascii_lowercase();
        if let Some(date) = lower
            .strip_prefix("begin triggerblock")
            .map(|_| text["begin triggerblock".len()..].trim())
            .or_else(|| lower.strip_prefix("date ").map(|_| text[5..].trim()))
        {
            if date.is_empty() {
                return Ok(true);
            }
            let t = unix_ns(date).ok_or_else(|| {
                self.lines.error(
                    name,
                    format!("the date {date:?} is not an ASC date: not {WHAT}"),
                )
            })?;
            self.start_ns = Some(t);
            self.last_ns = 0;
            return Ok(true);
        }
        if lower.starts_with("base ") {
            self.decimal = lower.contains(" dec");
            self.relative = lower.contains("timestamps relative");
            return Ok(true);
        }
        Ok(lower.starts_with("internal events")
            || lower.starts_with("no internal events")
            || lower.starts_with("end triggerblock")
            || lower.starts_with("//")
            || lower.is_empty())
    }

    /// The frame of an event line, with its channel in `bus`; `None` for an event other than
    /// a frame.
    fn event(
        &mut self,
        name: &str,
        text: &str,
        bus: &mut String,
    ) -> Result<Option<Entry>, InputError> {
        let bad = |lines: &Lines, what: &str| lines.error(name, format!("{what}: not {WHAT}"));
        let mut words = text.split_ascii_whitespace();
        let Some(time) = words.next() else {
            return Ok(None);
        };
        let Some(t) = decimal_ns(time, 1_000_000_000) else {
            return Err(bad(
                &self.lines,
                "the line does not start with a time in seconds",
            ));
        };
        let Some(start) = self.start_ns else {
            return Err(bad(&self.lines, "a frame before the log's date"));
        };
        let after = if self.relative { self.last_ns + t } else { t };
        self.last_ns = after;
        let t_ns = start + after;
        let Some(channel) = words.next() else {
            return Ok(None);
        };
        if channel.eq_ignore_ascii_case("CANFD") {
            let Some(channel) = words.next().filter(|c| c.parse::<u16>().is_ok()) else {
                return Ok(None);
            };
            bus.push_str("channel ");
            bus.push_str(channel);
            return Ok(Some(Entry {
                t_ns: Some(t_ns),
                frame: Logged::Fd,
            }));
        }
        if channel.parse::<u16>().is_err() {
            // An event of the measurement (`Start of measurement`, a comment): no frame.
            return Ok(None);
        }
        let Some(id) = words.next() else {
            return Ok(None);
        };
        let (digits, extended) = match id.strip_suffix(['x', 'X']) {
            Some(d) => (d, true),
            None => (id, false),
        };
        let radix = if self.decimal { 10 } else { 16 };
        let Ok(id) = u32::from_str_radix(digits, radix) else {
            // An error frame, a statistic, a bus event: no frame.
            return Ok(None);
        };
        let _direction = words.next();
        let kind = words.next();
        let remote = match kind {
            Some("d" | "D") => false,
            Some("r" | "R") => true,
            _ => {
                return Err(bad(
                    &self.lines,
                    "the frame is neither `d` (data) nor `r` (remote)",
                ));
            }
        };
        let dlc: usize = match words.next() {
            Some(d) => match u8::from_str_radix(d, 16) {
                Ok(d) if d <= 8 => d.into(),
                _ => return Err(bad(&self.lines, "the length is not 0 to 8")),
            },
            None if remote => 0,
            None => return Err(bad(&self.lines, "the data frame has no length")),
        };
        let line = LineFrame {
            id,
            extended,
            remote,
            len: dlc,
        };
        let frame = line.read(words, radix, |what| bad(&self.lines, what))?;
        bus.push_str("channel ");
        bus.push_str(channel);
        Ok(Some(Entry {
            t_ns: Some(t_ns),
            frame,
        }))
    }
}

impl LineFrames for AscLines {
    fn format(&self) -> InputFormat {
        InputFormat::ASC
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
        if self.header(name, text)? {
            return Ok(None);
        }
        self.event(name, text, bus)
    }
}

/// An ASC date (`Tue Nov 14 22:13:20.007 2023`, with or without milliseconds, in 24 or 12
/// hours with `am`/`pm`), a local time of the system, as Unix nanoseconds.
fn unix_ns(date: &str) -> Option<u64> {
    const FORMATS: [&str; 4] = [
        "%a %b %d %I:%M:%S%.f %p %Y",
        "%a %b %d %I:%M:%S %p %Y",
        "%a %b %d %H:%M:%S%.f %Y",
        "%a %b %d %H:%M:%S %Y",
    ];
    let civil: DateTime = FORMATS
        .iter()
        .find_map(|f| strtime::parse(f, date).ok()?.to_datetime().ok())?;
    let zoned = civil.to_zoned(TimeZone::system()).ok()?;
    u64::try_from(zoned.timestamp().as_nanosecond()).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_are_read_in_every_form() {
        let utc = |s: &str| {
            let civil: DateTime = strtime::parse("%Y-%m-%d %H:%M:%S%.f", s)
                .unwrap()
                .to_datetime()
                .unwrap();
            let local = civil.to_zoned(TimeZone::system()).unwrap();
            local.timestamp().as_nanosecond() as u64
        };
        assert_eq!(
            unix_ns("Tue Nov 14 22:13:20.007 2023"),
            Some(utc("2023-11-14 22:13:20.007"))
        );
        assert_eq!(
            unix_ns("Tue Nov 14 10:13:20.7 pm 2023"),
            Some(utc("2023-11-14 22:13:20.7"))
        );
        assert_eq!(
            unix_ns("Tue Nov 14 22:13:20 2023"),
            Some(utc("2023-11-14 22:13:20"))
        );
        assert_eq!(unix_ns("yesterday"), None);
    }
}
