//! `candump -l` log lines (can-utils): `(1700000000.123456) can0 1C4E2D01#0102C0`.
//!
//! A line is a timestamp in parentheses (Unix seconds and a fraction), an interface name and a
//! frame in candump's compact form ([`CanFrame`]'s `Display`): 3 hex digits of a standard id
//! or 8 of an extended one (with SocketCAN's flags: an error frame's id has
//! [`SOCKETCAN_ERR_FLAG`]), `#`, the data in hex (can-utils'
//! `parse_canframe` also takes `.` between bytes), or `R` and an optional length for a remote
//! frame. A CAN FD frame (`123##1...`) is read as [`Logged::Fd`]: not classic CAN, counted by
//! the caller, not an error. Newer candump may end a line with ` T` or ` R` (sent or received):
//! ignored.
//!
//! Written here: no crate reads candump's log format (`socketcan` reads frames from sockets).

use std::fmt;

use hwfoc::dronecan::{
    CanFrame, MAX_STANDARD_ID, SOCKETCAN_EFF_FLAG, SOCKETCAN_ERR_FLAG, SOCKETCAN_RTR_FLAG,
};

/// What a log line holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Logged {
    /// A classic CAN frame (data, remote or error).
    Classic(CanFrame),
    /// A CAN FD frame: not read.
    Fd,
}

/// One line of a `candump -l` log.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line<'a> {
    /// The receive time, Unix seconds.
    pub t_s: f64,
    /// The interface (`can0`, `vcan1`).
    pub interface: &'a str,
    /// The frame.
    pub frame: Logged,
}

/// A line that is not a candump log line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LineError {
    /// 1-based line number.
    pub line: u64,
    /// What is wrong with it.
    pub reason: &'static str,
}

impl fmt::Display for LineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "line {}: not a candump -l line: {}",
            self.line, self.reason
        )
    }
}

impl std::error::Error for LineError {}

/// Whether `line` starts like a candump log line: `(` then a digit. (What format detection
/// asks of an input's first bytes.)
pub fn looks_like_line(line: &[u8]) -> bool {
    matches!(line, [b'(', d, ..] if d.is_ascii_digit())
}

/// Parses `line` (without its line end; `number` is its 1-based line number, for the error).
pub fn parse_line(line: &str, number: u64) -> Result<Line<'_>, LineError> {
    let err = |reason| LineError {
        line: number,
        reason,
    };
    let rest = line
        .trim_end_matches(['\r', '\n'])
        .strip_prefix('(')
        .ok_or(err("it does not start with a timestamp in parentheses"))?;
    let (stamp, rest) = rest
        .split_once(')')
        .ok_or(err("the timestamp has no closing parenthesis"))?;
    let t_s = parse_stamp(stamp).ok_or(err("the timestamp is not seconds.fraction"))?;
    let mut fields = rest.split_ascii_whitespace();
    let interface = fields.next().ok_or(err("no interface"))?;
    let frame = fields.next().ok_or(err("no frame"))?;
    match fields.next() {
        None | Some("T" | "R") if fields.next().is_none() => {}
        _ => return Err(err("more than a frame after the interface")),
    }
    let frame = parse_frame(frame).ok_or(err("the frame is not ID#DATA"))?;
    Ok(Line {
        t_s,
        interface,
        frame,
    })
}

/// `1700000000.123456` as seconds.
fn parse_stamp(stamp: &str) -> Option<f64> {
    let (secs, frac) = stamp.split_once('.').unwrap_or((stamp, ""));
    let digits = |s: &str| !s.is_empty() && s.len() <= 18 && s.bytes().all(|b| b.is_ascii_digit());
    if !digits(secs) || !(frac.is_empty() || digits(frac)) || frac.len() > 9 {
        return None;
    }
    let secs: u64 = secs.parse().ok()?;
    let frac = match frac {
        "" => 0.0,
        f => f.parse::<u64>().ok()? as f64 / 10f64.powi(f.len() as i32),
    };
    Some(secs as f64 + frac)
}

fn hex(digits: &str) -> Option<u32> {
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    u32::from_str_radix(digits, 16).ok()
}

/// A frame in candump's compact form.
fn parse_frame(text: &str) -> Option<Logged> {
    let (id, body) = text.split_once('#')?;
    let can_id = match id.len() {
        3 => hex(id).filter(|&v| v <= MAX_STANDARD_ID)?,
        8 => {
            let v = hex(id)?;
            if v & SOCKETCAN_ERR_FLAG != 0 {
                v
            } else {
                v | SOCKETCAN_EFF_FLAG
            }
        }
        _ => return None,
    };
    if body.starts_with('#') {
        // CAN FD: `##`, a flags digit, then data.
        return Some(Logged::Fd);
    }
    if let Some(len) = body.strip_prefix('R') {
        let len = match len {
            "" => 0,
            l if l.len() == 1 => l.parse::<u8>().ok()?,
            _ => return None,
        };
        let frame = CanFrame::from_socketcan(
            can_id | SOCKETCAN_RTR_FLAG,
            &[0; 8][..usize::from(len.min(8))],
        );
        return frame.filter(|_| len <= 8).map(Logged::Classic);
    }
    // Data, with `.` allowed between bytes; a len8_dlc suffix (`_X`) is not read.
    let mut data = [0u8; 8];
    let mut len = 0;
    let bytes = body.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'.' {
            i += 1;
            continue;
        }
        let pair = body.get(i..i + 2)?;
        *data.get_mut(len)? = hex(pair)? as u8;
        len += 1;
        i += 2;
    }
    CanFrame::from_socketcan(can_id, &data[..len]).map(Logged::Classic)
}

/// Appends the log line of `frame` received at `t_s` (Unix seconds, written to the
/// microsecond as candump does) on `interface` to `out`, with its `\n`.
pub fn push_line(out: &mut String, t_s: f64, interface: &str, frame: &CanFrame) {
    use std::fmt::Write;
    let micros = (t_s.max(0.0) * 1e6).round() as u64;
    let _ = writeln!(
        out,
        "({:010}.{:06}) {interface} {frame}",
        micros / 1_000_000,
        micros % 1_000_000
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::dronecan::FrameKind;

    fn classic(line: &str) -> CanFrame {
        match parse_line(line, 1).unwrap().frame {
            Logged::Classic(f) => f,
            Logged::Fd => panic!("FD"),
        }
    }

    #[test]
    fn lines_are_read() {
        let l = parse_line("(1700000000.123456) can0 1C4E2D01#0102C0", 1).unwrap();
        assert_eq!(l.interface, "can0");
        assert!((l.t_s - 1_700_000_000.123456).abs() < 1e-6);
        assert_eq!(
            l.frame,
            Logged::Classic(CanFrame::extended(0x1C4E_2D01, &[1, 2, 0xC0]).unwrap())
        );
        let r = classic("(1.5) vcan1 123#R");
        assert_eq!((r.kind(), r.len(), r.id()), (FrameKind::Remote, 0, 0x123));
        let r = classic("(1.5) vcan1 123#R4");
        assert_eq!((r.kind(), r.len()), (FrameKind::Remote, 4));
        let e = classic("(1.5) can0 20000004#0004000000000000");
        assert_eq!((e.kind(), e.id()), (FrameKind::Error, 4));
        let s = classic("(1.5) can0 7FF#11.22.33 R");
        assert_eq!(
            (s.is_extended(), s.data()),
            (false, &[0x11, 0x22, 0x33][..])
        );
        assert_eq!(classic("(2) can0 123#").len(), 0);
        assert_eq!(
            parse_line("(1.5) can0 123##1112233", 1).unwrap().frame,
            Logged::Fd
        );
        assert!(looks_like_line(b"(1700000000.1) can0"));
        assert!(!looks_like_line(b"(x") && !looks_like_line(b"Time"));
    }

    #[test]
    fn other_lines_are_errors_naming_their_number() {
        for bad in [
            "",
            "can0 123#00",
            "(1.5 can0 123#00",
            "(1.x) can0 123#00",
            "(1.5) can0",
            "(1.5) can0 12#00",
            "(1.5) can0 123#0",
            "(1.5) can0 123#001122334455667788",
            "(1.5) can0 800#00",
            "(1.5) can0 123#R9",
            "(1.5) can0 123#00 extra words",
            "(1.5) can0 123#GG",
        ] {
            let e = parse_line(bad, 7)
                .err()
                .unwrap_or_else(|| panic!("{bad:?}"));
            assert!(
                e.to_string().starts_with("line 7: not a candump -l line"),
                "{e}"
            );
        }
    }

    #[test]
    fn lines_written_are_read_back_as_written() {
        let frames = [
            CanFrame::extended(0x1C4E_2D01, &[1, 2, 0xC0]).unwrap(),
            CanFrame::standard(0x123, &[]).unwrap(),
            CanFrame::remote(0x123, false, 4).unwrap(),
            CanFrame::remote(0x1234_5678, true, 8).unwrap(),
            CanFrame::error(4, &[0, 4, 0, 0, 0, 0, 0, 0]).unwrap(),
            CanFrame::extended(0, &[0xFF; 8]).unwrap(),
        ];
        for (k, f) in frames.iter().enumerate() {
            let t = 1_700_000_000.000_001 + k as f64 * 0.25;
            let mut text = String::new();
            push_line(&mut text, t, "vcan0", f);
            let l = parse_line(text.trim_end(), 1).unwrap();
            assert_eq!(l.frame, Logged::Classic(*f), "{text}");
            assert_eq!(l.interface, "vcan0");
            assert!((l.t_s - t).abs() < 5e-7, "{text}");
            let mut again = String::new();
            push_line(&mut again, l.t_s, l.interface, f);
            assert_eq!(again, text);
        }
        let mut text = String::new();
        push_line(&mut text, 1_700_000_000.5, "can0", &frames[0]);
        assert_eq!(text, "(1700000000.500000) can0 1C4E2D01#0102C0\n");
    }
}
