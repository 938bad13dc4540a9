//! Times as people write and read them: the `--from`/`--to` grammar, and ISO 8601 display of
//! receive times where the source has a wall clock.
//!
//! A source's clock ([`Clock`], from its [`InputFormat`](crate::InputFormat)) says what its `t_s`
//! numbers mean: Unix seconds for pcapng recordings and serial ports ([`Clock::Wall`]), seconds
//! from the start of the capture for a logic-analyser CSV export ([`Clock::Capture`]), nothing for
//! raw bytes ([`Clock::None`]). Only wall-clock times are shown as dates. (The clock that stamps
//! what is received is `hwfoc-io`'s `clock::ReceiveClock`.)
//!
//! # The grammar of a time ([`parse`])
//!
//! | written | meaning |
//! |---|---|
//! | `+5`, `+2.5`, `+250ms`, `+2m`, `+1h30m`, `+1m30.5s`, `+PT1H30M` | from the first frame: `+` then seconds, or a duration (`h`, `m`, `s`, `ms`, `us`, `ns` and the longer words, as the `jiff` crate reads them, or ISO 8601) |
//! | `1795470439.16`, `-3`, `12` | seconds of the source's own clock: Unix time for recordings and serial ports, seconds from the capture's start for an analyser CSV |
//! | `2026-11-23T14:03:00Z`, `2026-11-23T14:03:00.250+01:00` | an ISO 8601 (RFC 3339) date-time with its offset |
//! | `2026-11-23 14:03:00`, `2026-11-23T14:03`, `2026-11-23` | a date-time without offset: local time, in the zone of `TZ` or the system's; a time a clock change repeats (`2026-10-25 02:30` in Europe/Berlin) or skips is refused, naming the offsets to give |
//!
//! Dates are those from `-009999-01-02T01:59:59Z` to `9999-12-30T22:00:00Z` (what the `jiff`
//! crate holds); a date beyond is refused in a line of its own.
//!
//! "The first frame" is the first data frame with a receive time among the inputs given
//! together (their records come in time order, so it is the earliest one): see
//! [`crate::Window`].

use std::fmt;

use jiff::civil::DateTime;
use jiff::fmt::temporal::Pieces;
use jiff::tz::{AmbiguousOffset, Offset, TimeZone};
use jiff::{SignedDuration, Timestamp};

/// What a source's receive times (`t_s`) are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clock {
    /// Unix seconds: recordings and serial ports.
    Wall,
    /// Seconds of the source's own clock, not tied to a date: a logic-analyser CSV's seconds
    /// from the start of the capture.
    Capture,
    /// No receive times: raw bytes.
    None,
}

/// A year of 365.25 days, s.
pub const YEAR_S: f64 = 365.25 * 86_400.0;

/// Whether seconds of a source's clock, `s`, lie more than a year before `first`, the data's
/// first receive time: a bare number meant as seconds after the first frame (`5` for `+5`).
pub fn long_before(s: f64, first: f64) -> bool {
    s < first - YEAR_S
}

/// A time as given on the command line ([`parse`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Time {
    /// Seconds after the first frame (`+5`, `+2m`).
    FromFirst(f64),
    /// Seconds of the source's clock (a bare number).
    Seconds(f64),
    /// A date-time, as Unix seconds: only sources with a wall clock have it.
    Date(f64),
}

impl Time {
    /// Whether it is a date-time, which only sources with a [`Clock::Wall`] can have.
    pub fn is_date(&self) -> bool {
        matches!(self, Time::Date(_))
    }
}

impl fmt::Display for Time {
    /// As it can be written back: `+5`, `1795470439.16`, `2026-11-23T14:03:00.250Z`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Time::FromFirst(s) => write!(f, "+{s}"),
            Time::Seconds(s) => write!(f, "{s}"),
            Time::Date(s) => f.write_str(&iso8601(s)),
        }
    }
}

/// A text that is not a time.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum TimeError {
    /// It is none of the forms of the grammar.
    NotATime {
        /// The text given.
        text: String,
    },
    /// `+` followed by something other than a duration, or a negative one.
    BadDuration {
        /// The text given.
        text: String,
    },
    /// A date-time that names no instant (a month 13, a day 31 of November, an offset of
    /// 25 hours) or lies outside the years -9999..=9999.
    BadDate {
        /// The text given.
        text: String,
        /// What is wrong, as `jiff` says it.
        reason: String,
    },
    /// A date-time beyond the dates the `jiff` crate holds.
    OutOfRange {
        /// The text given.
        text: String,
    },
    /// A local date-time that the zone's clocks show twice (they are put back) or skip (they
    /// are put forward): which instant is meant needs an offset.
    AmbiguousLocal {
        /// The text given.
        text: String,
        /// The zone's name.
        zone: String,
        /// Whether the clocks skip it (else they show it twice).
        skipped: bool,
        /// The zone's offsets before and after the change: `+02:00`.
        before: String,
        /// See `before`.
        after: String,
    },
}

impl fmt::Display for TimeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TimeError::NotATime { text } => write!(
                f,
                "{text:?} is not a time: give +S from the first frame (+5, +2m, +1h30m, \
                 +250ms), seconds of the source's clock (1795470439.16) or an ISO 8601 \
                 date-time (2026-11-23T14:03:00Z, 2026-11-23 14:03:00 for local time)"
            ),
            TimeError::BadDuration { text } => write!(
                f,
                "{text:?} is not a time after the first frame: give + and seconds or a \
                 duration (+5, +2.5, +250ms, +2m, +1h30m)"
            ),
            TimeError::BadDate { text, reason } => {
                write!(f, "{text:?} is not a valid date-time: {reason}")
            }
            TimeError::OutOfRange { text } => write!(
                f,
                "{text:?} is beyond the dates hwfoc reads ({:.0} to {:.0})",
                Timestamp::MIN,
                Timestamp::MAX
            ),
            TimeError::AmbiguousLocal {
                text,
                zone,
                skipped: false,
                before,
                after,
            } => write!(
                f,
                "{text:?} happens twice in {zone} (the clocks go back): give its offset, \
                 {text}{before} or {text}{after}"
            ),
            TimeError::AmbiguousLocal {
                text,
                zone,
                skipped: true,
                before,
                after,
            } => write!(
                f,
                "{text:?} does not happen in {zone} (the clocks go forward over it): give an \
                 offset, {text}{before} or {text}{after}"
            ),
        }
    }
}

impl std::error::Error for TimeError {}

/// Reads a time written as the module documentation says; local date-times are in the zone
/// of `TZ` or the system's.
pub fn parse(text: &str) -> Result<Time, TimeError> {
    parse_in(text, &TimeZone::system())
}

/// [`parse`], with local date-times in `zone`.
pub(crate) fn parse_in(text: &str, zone: &TimeZone) -> Result<Time, TimeError> {
    let s = text.trim();
    if let Some(rest) = s.strip_prefix('+') {
        return after_first(rest)
            .map(Time::FromFirst)
            .ok_or_else(|| TimeError::BadDuration {
                text: text.to_string(),
            });
    }
    if let Some(seconds) = number(s) {
        return Ok(Time::Seconds(seconds));
    }
    // A date starts with its year's digits and a dash; anything else is no time at all.
    let dated =
        s.len() >= 5 && s.as_bytes()[..4].iter().all(u8::is_ascii_digit) && s.as_bytes()[4] == b'-';
    if !dated {
        return Err(TimeError::NotATime {
            text: text.to_string(),
        });
    }
    // A date that reads but names no instant jiff holds is beyond its range: said in a line
    // of our own (jiff's message names its internal limits).
    let bad = |e: jiff::Error| match Pieces::parse(s) {
        Ok(_) => TimeError::OutOfRange {
            text: text.to_string(),
        },
        Err(_) => TimeError::BadDate {
            text: text.to_string(),
            reason: e.to_string(),
        },
    };
    let has_offset =
        s.ends_with(['Z', 'z']) || s.get(10..).is_some_and(|time| time.contains(['+', '-']));
    let instant = if has_offset {
        s.parse::<Timestamp>().map_err(bad)?
    } else {
        let civil = s.parse::<DateTime>().map_err(bad)?;
        let local = zone.to_ambiguous_zoned(civil);
        let (skipped, before, after) = match local.offset() {
            AmbiguousOffset::Unambiguous { .. } => (false, None, None),
            AmbiguousOffset::Gap { before, after } => (true, Some(before), Some(after)),
            AmbiguousOffset::Fold { before, after } => (false, Some(before), Some(after)),
        };
        if let (Some(before), Some(after)) = (before, after) {
            return Err(TimeError::AmbiguousLocal {
                text: text.trim().to_string(),
                zone: zone
                    .iana_name()
                    .unwrap_or("the local time zone")
                    .to_string(),
                skipped,
                before: offset_text(before),
                after: offset_text(after),
            });
        }
        local
            .compatible()
            .map_err(|_| TimeError::OutOfRange {
                text: text.to_string(),
            })?
            .timestamp()
    };
    Ok(Time::Date(unix_seconds(instant)))
}

/// A plain decimal number of seconds (no `inf`, `nan` or hexadecimal: what `f64` parses beyond
/// digits, a sign, a point and an exponent is no time).
fn number(s: &str) -> Option<f64> {
    let plain = !s.is_empty()
        && s.bytes()
            .all(|b| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E'))
        && s.bytes().any(|b| b.is_ascii_digit());
    s.parse::<f64>().ok().filter(|x| plain && x.is_finite())
}

/// The seconds of a duration after `+`: a number, or a duration `jiff` reads; not negative.
fn after_first(rest: &str) -> Option<f64> {
    if rest.starts_with(['-', '+']) {
        return None;
    }
    let seconds = match number(rest) {
        Some(s) => s,
        None => rest.parse::<SignedDuration>().ok()?.as_secs_f64(),
    };
    (seconds >= 0.0 && seconds.is_finite()).then_some(seconds)
}

/// An offset as RFC 3339 writes it, `+02:00` (jiff's `Display` leaves out zero minutes:
/// `+02`, which RFC 3339 does not read).
fn offset_text(offset: Offset) -> String {
    let s = offset.seconds();
    let (sign, s) = if s < 0 { ('-', -s) } else { ('+', s) };
    format!("{sign}{:02}:{:02}", s / 3600, s / 60 % 60)
}

/// Unix seconds of an instant.
fn unix_seconds(t: Timestamp) -> f64 {
    t.as_second() as f64 + f64::from(t.subsec_nanosecond()) * 1e-9
}

/// The instant of `t_s` Unix seconds, to the millisecond (`None` outside the years
/// -9999..=9999, or not a number).
fn instant(t_s: f64) -> Option<Timestamp> {
    let ms = (t_s * 1000.0).round();
    if !ms.is_finite() || ms.abs() > 1e15 {
        return None;
    }
    Timestamp::from_millisecond(ms as i64).ok()
}

/// Unix time `t_s` as an ISO 8601 (RFC 3339) date-time in UTC, to the millisecond:
/// `2026-11-23T14:03:00.160Z`. The form `summary` and `plot` show: the same on every machine,
/// and sorting as text sorts in time. A number no date can be (beyond the year 9999, NaN) is
/// shown as the number and `s`.
pub fn iso8601(t_s: f64) -> String {
    match instant(t_s) {
        Some(t) => format!("{t:.3}"),
        None => format!("{t_s} s"),
    }
}

/// Unix time `t_s` as an ISO 8601 date-time in UTC to the microsecond,
/// `2026-11-23T14:03:00.160123Z`: a CSV export's `time` column (`--time iso`), which
/// spreadsheets read as a date. Beyond the year 9999 or NaN it is [`iso8601`]'s text.
pub fn iso8601_us(t_s: f64) -> String {
    match unix_us(t_s).and_then(|us| Timestamp::from_microsecond(us).ok()) {
        Some(t) => format!("{t:.6}"),
        None => iso8601(t_s),
    }
}

/// Unix time `t_s` in whole microseconds (rounded), the unit of the binary formats' `time`
/// column and of [`iso8601_us`]; `None` for NaN, infinities and beyond about 31,700 years.
pub fn unix_us(t_s: f64) -> Option<i64> {
    let us = (t_s * 1e6).round();
    (us.is_finite() && us.abs() < 1e18).then_some(us as i64)
}

/// Unix time `t_s` as an ISO 8601 date-time in the local zone (`TZ` or the system's), with its
/// offset, to the millisecond: `2026-11-23T15:03:00.160+01:00`. For a person watching live
/// (the monitor); beyond the year 9999 or NaN it is shown as [`iso8601`] shows it.
pub fn iso8601_local(t_s: f64) -> String {
    iso8601_in(t_s, &TimeZone::system())
}

/// [`iso8601_local`] in `zone`.
pub(crate) fn iso8601_in(t_s: f64, zone: &TimeZone) -> String {
    match instant(t_s) {
        Some(t) => t
            .to_zoned(zone.clone())
            .strftime("%Y-%m-%dT%H:%M:%S%.3f%:z")
            .to_string(),
        None => iso8601(t_s),
    }
}

/// The receive times of some frames, from `first` to `last`, as a person reads them: as
/// dates too where the clock is a wall clock (`wall`), for a message about a window that
/// held no frame.
pub fn span_text(first: f64, last: f64, wall: bool) -> String {
    if wall {
        format!(
            "the frames' t_s run from {first} to {last} s ({} to {})",
            iso8601(first),
            iso8601(last)
        )
    } else {
        format!("the frames' t_s run from {first} to {last} s (the source's own clock)")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn utc(text: &str) -> Result<Time, TimeError> {
        parse_in(text, &TimeZone::UTC)
    }

    #[test]
    fn relative_times() {
        for (text, s) in [
            ("+5", 5.0),
            ("+0", 0.0),
            ("+2.5", 2.5),
            ("+250ms", 0.25),
            ("+2m", 120.0),
            ("+1h30m", 5400.0),
            ("+1m30.5s", 90.5),
            ("+1h 30m", 5400.0),
            ("+PT1H30M", 5400.0),
            (" +90s ", 90.0),
        ] {
            assert_eq!(utc(text), Ok(Time::FromFirst(s)), "{text}");
        }
        for text in [
            "+",
            "+-5",
            "+5x",
            "+1h ago",
            "++5",
            "+nan",
            "+inf",
            "+5 apples",
        ] {
            assert_eq!(
                utc(text),
                Err(TimeError::BadDuration {
                    text: text.to_string()
                }),
                "{text}"
            );
        }
    }

    #[test]
    fn seconds_of_the_source_clock() {
        assert_eq!(utc("1795470439.16"), Ok(Time::Seconds(1795470439.16)));
        assert_eq!(utc("-3"), Ok(Time::Seconds(-3.0)));
        assert_eq!(utc("1e9"), Ok(Time::Seconds(1e9)));
        for text in [
            "inf",
            "NaN",
            "0x10",
            "",
            "5s",
            "1e999",
            "yesterday",
            "12:00",
        ] {
            assert!(
                matches!(utc(text), Err(TimeError::NotATime { .. })),
                "{text}: {:?}",
                utc(text)
            );
        }
    }

    #[test]
    fn date_times_with_offsets() {
        // 2026-11-23T14:03:00Z is 1795442580.
        let t = 1_795_442_580.0;
        assert_eq!(utc("2026-11-23T14:03:00Z"), Ok(Time::Date(t)));
        assert_eq!(utc("2026-11-23t14:03:00z"), Ok(Time::Date(t)));
        assert_eq!(utc("2026-11-23T14:03Z"), Ok(Time::Date(t)));
        assert_eq!(
            utc("2026-11-23T14:03:00.250+01:00"),
            Ok(Time::Date(t - 3600.0 + 0.25))
        );
        assert_eq!(
            utc("2026-11-23T14:03:00-05:30"),
            Ok(Time::Date(t + 5.5 * 3600.0))
        );
        for text in [
            "2026-13-01T00:00:00Z",
            "2026-11-31T00:00Z",
            "2026-11-23T25:00Z",
            "2026-11-23T14:03+26:00",
        ] {
            let e = utc(text).unwrap_err();
            assert!(matches!(e, TimeError::BadDate { .. }), "{text}: {e:?}");
            assert!(
                e.to_string()
                    .starts_with(&format!("{text:?} is not a valid date-time: ")),
                "{e}"
            );
        }
    }

    #[test]
    fn local_date_times_take_the_zone() {
        let t = 1_795_442_580.0;
        let berlin = TimeZone::get("Europe/Berlin").unwrap();
        let local = |text| parse_in(text, &berlin);
        assert_eq!(local("2026-11-23 15:03:00"), Ok(Time::Date(t)));
        assert_eq!(local("2026-11-23T15:03"), Ok(Time::Date(t)));
        assert_eq!(local("2026-11-23T15:03:00.5"), Ok(Time::Date(t + 0.5)));
        assert_eq!(
            utc("2026-11-23"),
            Ok(Time::Date(t - (14 * 3600 + 180) as f64))
        );
        // Summer time: two hours ahead of UTC.
        assert_eq!(
            local("2026-07-01 02:00"),
            Ok(Time::Date(unix_seconds(
                "2026-07-01T00:00Z".parse().unwrap()
            )))
        );
        // An offset given wins over the zone.
        assert_eq!(local("2026-11-23T14:03:00Z"), Ok(Time::Date(t)));
    }

    #[test]
    fn local_times_a_clock_change_repeats_or_skips_ask_for_an_offset() {
        let berlin = TimeZone::get("Europe/Berlin").unwrap();
        let twice = parse_in("2026-10-25 02:30", &berlin).unwrap_err();
        assert_eq!(
            twice.to_string(),
            "\"2026-10-25 02:30\" happens twice in Europe/Berlin (the clocks go back): give its \
             offset, 2026-10-25 02:30+02:00 or 2026-10-25 02:30+01:00"
        );
        let skipped = parse_in("2026-03-29T02:30", &berlin).unwrap_err();
        assert!(
            matches!(skipped, TimeError::AmbiguousLocal { skipped: true, .. }),
            "{skipped:?}"
        );
        // Each offset suggested reads, as the instant it says.
        for (text, utc_text) in [
            ("2026-10-25 02:30+02:00", "2026-10-25T00:30Z"),
            ("2026-10-25 02:30+01:00", "2026-10-25T01:30Z"),
        ] {
            let want = unix_seconds(utc_text.parse().unwrap());
            assert_eq!(parse_in(text, &berlin), Ok(Time::Date(want)), "{text}");
        }
    }

    #[test]
    fn dates_beyond_the_range_are_refused_in_our_words() {
        for text in ["9999-12-31T23:59:59Z", "9999-12-31 23:59:59"] {
            let e = utc(text).unwrap_err();
            assert_eq!(
                e.to_string(),
                format!(
                    "{text:?} is beyond the dates hwfoc reads \
                     (-009999-01-02T01:59:59Z to 9999-12-30T22:00:00Z)"
                )
            );
        }
    }

    #[test]
    fn iso_display() {
        assert_eq!(iso8601(1_795_442_580.16), "2026-11-23T14:03:00.160Z");
        assert_eq!(iso8601(1_795_442_580.0), "2026-11-23T14:03:00.000Z");
        assert_eq!(iso8601(0.0005), "1970-01-01T00:00:00.001Z");
        assert_eq!(iso8601(f64::NAN), "NaN s");
        assert_eq!(iso8601(1e15), "1000000000000000 s");
        let berlin = TimeZone::get("Europe/Berlin").unwrap();
        assert_eq!(
            iso8601_in(1_795_442_580.16, &berlin),
            "2026-11-23T15:03:00.160+01:00"
        );
        assert_eq!(iso8601_in(f64::INFINITY, &berlin), "inf s");
        // What is shown reads back as the same instant, to the millisecond.
        let shown = iso8601(1_795_470_439.16);
        assert_eq!(utc(&shown), Ok(Time::Date(1_795_470_439.16)));
        assert_eq!(
            Time::Date(1_795_442_580.25).to_string(),
            "2026-11-23T14:03:00.250Z"
        );
        assert_eq!(Time::FromFirst(90.0).to_string(), "+90");
    }

    #[test]
    fn spans_show_dates_on_a_wall_clock() {
        assert_eq!(
            span_text(1_795_442_580.0, 1_795_442_581.5, true),
            "the frames' t_s run from 1795442580 to 1795442581.5 s \
             (2026-11-23T14:03:00.000Z to 2026-11-23T14:03:01.500Z)"
        );
        assert_eq!(
            span_text(0.5, 2.0, false),
            "the frames' t_s run from 0.5 to 2 s (the source's own clock)"
        );
    }

    /// The clock each format says it has is what its input gives: a recording's Unix time of
    /// receipt, an analyser export's seconds of its own capture, no time for raw bytes. (Serial
    /// ports, which need a port, give the same Unix times as the recordings made of them.)
    #[test]
    fn the_clock_of_a_format_is_the_times_its_input_gives() {
        use crate::input::Input;
        let first_time = |name: &str, data: Vec<u8>| {
            let mut input = Input::from_memory(name, data).unwrap();
            let format = input.format();
            let batch = input.next_batch().unwrap().unwrap();
            (format.clock(), batch.times.map(|t| t[0]))
        };
        // 2026-11-23T14:03:00Z, as the recorder stamps it.
        let t_ns = 1_795_442_580_000_000_000;
        let mut recording = crate::pcapng::Writer::new(Vec::new()).unwrap();
        recording.add_interface("/dev/ttyUSB0", 19200).unwrap();
        recording.write_packet(0, t_ns, &[0x55; 8]).unwrap();
        let recording = recording.into_inner().unwrap();
        assert_eq!(
            first_time("r.pcapng", recording),
            (Clock::Wall, Some(1_795_442_580.0))
        );
        let csv = b"Time [s],Value\n0.5,0x55\n0.75,0x55\n".to_vec();
        assert_eq!(first_time("a.csv", csv), (Clock::Capture, Some(0.5)));
        assert_eq!(first_time("a.bin", vec![0x55; 8]), (Clock::None, None));
    }
}
