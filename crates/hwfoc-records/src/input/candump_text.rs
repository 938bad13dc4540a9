//! `candump`'s own text (can-utils, without `-l`) as an input: one CAN stream per interface,
//! times its own (`-ta`, `-tA`), or none (without `-t`: the records have no `t_s`).
//!
//! A line is an optional time in parentheses (`-ta`: Unix seconds; `-tA`: a local date and
//! time, `2023-11-14 22:13:20.007000`), the interface, the id (3 hex digits standard, 8
//! extended), the length in brackets and the data bytes in hex (`  can0  123   [3]  11 22 33`),
//! or `remote request` for a remote frame. CAN FD frames have their length in brackets of two
//! digits (`[64]`). Every line has a time, or none does (as the first line).
//!
//! Written here: no crate reads candump's text.

use std::io::Read;

use jiff::civil::DateTime;
use jiff::tz::TimeZone;

use super::can_log::{CanLogReader, Entry, Frames, Lines, decimal_ns, frame};
use super::{InputError, InputFormat};
use crate::can::candump::Logged;
use crate::time::Clock;

impl InputFormat {
    /// `candump`'s text with times: one CAN stream per interface, times its own.
    pub const CANDUMP_TEXT: InputFormat = InputFormat {
        name: "candump text",
        short_name: "candump-text",
        clock: Clock::Wall,
        live: false,
        recorded_ports: true,
    };

    /// `candump`'s text without times (`candump can0`): one CAN stream per interface, no times.
    pub const CANDUMP_UNTIMED: InputFormat = InputFormat {
        name: "candump text without times",
        short_name: "candump-untimed",
        clock: Clock::None,
        live: false,
        recorded_ports: true,
    };
}

/// What the log is called in its errors.
const WHAT: &str = "candump's text";

/// Whether `head`, an input's first bytes, may still be the start of candump's text: spaces,
/// or a time in parentheses, then more.
pub(super) fn may_start(head: &[u8]) -> bool {
    matches!(head, [b' ', ..] | [b'(']) || matches!(head, [b'(', d, ..] if d.is_ascii_digit())
}

/// Whether `head`, an input's first line, is a line of candump's text.
pub(super) fn is_start(head: &[u8]) -> bool {
    std::str::from_utf8(head).is_ok_and(|line| parse(line.trim_end()).is_some())
}

/// Whether `head`, an input's first line, is a line of candump's text with a time.
pub(super) fn is_timed_start(head: &[u8]) -> bool {
    std::str::from_utf8(head)
        .is_ok_and(|line| parse(line.trim_end()).is_some_and(|l| l.0.is_some()))
}

/// A line's time (`None` where it has none), interface and frame.
fn parse(line: &str) -> Option<(Option<u64>, &str, Logged)> {
    let line = line.trim_start();
    let (t_ns, rest) = match line.strip_prefix('(') {
        Some(rest) => {
            let (stamp, rest) = rest.split_once(')')?;
            (Some(stamp_ns(stamp.trim())?), rest)
        }
        None => (None, line),
    };
    let mut words = rest.split_ascii_whitespace();
    let interface = words.next()?;
    let id = words.next()?;
    let len = words.next()?.strip_prefix('[')?.strip_suffix(']')?;
    let extended = match id.len() {
        3 => false,
        8 => true,
        _ => return None,
    };
    let id = u32::from_str_radix(id, 16).ok()?;
    let len: usize = len.parse().ok()?;
    if len > 8 {
        return Some((t_ns, interface, Logged::Fd));
    }
    let rest: Vec<&str> = words.collect();
    if rest.starts_with(&["remote", "request"]) {
        return Some((t_ns, interface, frame(id, extended, true, &[0; 8][..len])?));
    }
    let data: Vec<u8> = rest
        .iter()
        .take(len)
        .map(|w| u8::from_str_radix(w, 16).ok())
        .collect::<Option<_>>()?;
    if data.len() != len {
        return None;
    }
    Some((t_ns, interface, frame(id, extended, false, &data)?))
}

/// A time of `-ta` (Unix seconds) or `-tA` (a local date and time) as Unix nanoseconds.
fn stamp_ns(stamp: &str) -> Option<u64> {
    if let Some(t) = decimal_ns(stamp, 1_000_000_000) {
        return Some(t);
    }
    let civil: DateTime = stamp.parse().ok()?;
    let zoned = civil.to_zoned(TimeZone::system()).ok()?;
    u64::try_from(zoned.timestamp().as_nanosecond()).ok()
}

/// The lines of candump's text, read as frames: with times, or (`.1` false) without.
pub(super) struct CandumpText(Lines, bool);

impl CandumpText {
    /// Reads the text `reader` gives, from its first line; `timed`: whether it has times.
    pub(super) fn reader(reader: Box<dyn Read>, timed: bool) -> CanLogReader<CandumpText> {
        CanLogReader::new(CandumpText(Lines::new(reader), timed))
    }
}

impl Frames for CandumpText {
    fn format(&self) -> InputFormat {
        if self.1 {
            InputFormat::CANDUMP_TEXT
        } else {
            InputFormat::CANDUMP_UNTIMED
        }
    }

    fn next(&mut self, name: &str, bus: &mut String) -> Result<Option<Entry>, InputError> {
        let Some(text) = self.0.next(name, WHAT)? else {
            return Ok(None);
        };
        let Some((t_ns, interface, frame)) = parse(&text) else {
            return Err(self.0.error(
                name,
                format!("not a line of {WHAT} (`  can0  123   [2]  11 22`)"),
            ));
        };
        if t_ns.is_some() != self.1 {
            let (has, others) = match self.1 {
                true => ("no time", "with times"),
                false => ("a time", "without times"),
            };
            let e = format!("a line with {has} among lines {others}: not one {WHAT}");
            return Err(self.0.error(name, e));
        }
        bus.push_str(interface);
        Ok(Some(Entry { t_ns, frame }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_with_and_without_times_are_read() {
        let (t, interface, frame) =
            parse(" (1700000000.007000)  can0  10040A28   [3]  00 0C 40").unwrap();
        assert_eq!((t, interface), (Some(1_700_000_000_007_000_000), "can0"));
        assert_eq!(
            frame,
            Logged::Classic(
                hwfoc::dronecan::CanFrame::extended(0x1004_0A28, &[0, 0x0C, 0x40]).unwrap()
            )
        );
        let (t, _, frame) = parse("  vcan1  123   [2]  remote request").unwrap();
        assert_eq!(t, None);
        assert_eq!(
            frame,
            Logged::Classic(hwfoc::dronecan::CanFrame::remote(0x123, false, 2).unwrap())
        );
        assert_eq!(parse("  can0  123  [12]  00").unwrap().2, Logged::Fd);
        assert!(parse("  can0  123   [3]  00 01").is_none());
        assert!(parse("hello world").is_none());
    }
}
