//! SLCAN (the Lawicel ASCII protocol of serial CAN adapters): the commands a program sends and
//! a streaming parser of what an adapter sends back.
//!
//! Commands end with `\r`. `C` closes the channel, `S0`..`S8` set the bitrate (below), `O`
//! opens it, `t` + 3 hex digits of id + 1 digit of length + 2 hex digits per byte sends a
//! standard data frame, `T` the same with 8 hex digits of id an extended one, `r` and `R` a
//! remote frame (id and length, no data). The adapter answers `\r` (done), `\x07` (BEL:
//! refused), `z\r` / `Z\r` (a standard / extended frame sent), and reports each frame it
//! receives as the same `t`/`T`/`r`/`R` line, some adapters (`Z1`) with 4 more hex digits: a
//! millisecond timestamp that wraps every minute. [`Parser`] reads all of these.
//!
//! Written here: the `slcan` crate (0.1.3, 2020) is built on the unmaintained `serial` crate
//! and reads no timestamps, and `mini-slcan` / `serial-can` are codecs of a few lines.

use hwfoc::dronecan::{CanFrame, FrameKind};

/// The CAN bitrates of the SLCAN `S` command, in bit/s, indexed by their code (`S0` = 10 kbit/s
/// ... `S8` = 1 Mbit/s).
pub const BITRATES: [u32; 9] = [
    10_000, 20_000, 50_000, 100_000, 125_000, 250_000, 500_000, 800_000, 1_000_000,
];

/// The `S` code of `bitrate` (bit/s), if SLCAN has one.
pub fn bitrate_code(bitrate: u32) -> Option<u8> {
    BITRATES.iter().position(|&b| b == bitrate).map(|i| i as u8)
}

/// The commands that set an adapter up at `code`, from whatever state it is in: an empty
/// command (ends a command a previous program left half-written), close, set the bitrate,
/// open. (`C` on a closed channel is refused with BEL by some adapters: harmless.)
pub fn setup(code: u8) -> Vec<u8> {
    format!("\rC\rS{code}\rO\r").into_bytes()
}

/// The command that closes the channel.
pub const CLOSE: &[u8] = b"C\r";

/// The answer of an adapter that refused a command.
pub const BEL: u8 = 0x07;

const HEX: &[u8; 16] = b"0123456789ABCDEF";

/// The longest line an adapter sends: `T`, 8 digits of id, the length, 16 digits of data and
/// 4 of timestamp. A longer line is not SLCAN; it is read to its end and counted as not
/// understood, never held whole.
pub const MAX_LINE: usize = 30;

fn push_hex(out: &mut Vec<u8>, value: u32, digits: u32) {
    for shift in (0..digits).rev() {
        out.push(HEX[((value >> (shift * 4)) & 0xF) as usize]);
    }
}

/// Appends the `T` command sending the extended frame `id` (29 bits) with `data` (0 to 8
/// bytes) to `out`.
pub fn push_extended(out: &mut Vec<u8>, id: u32, data: &[u8]) {
    debug_assert!(data.len() <= 8 && id < 1 << 29);
    out.push(b'T');
    push_hex(out, id, 8);
    out.push(b'0' + data.len() as u8);
    for &b in data {
        push_hex(out, u32::from(b), 2);
    }
    out.push(b'\r');
}

/// Appends the command sending `frame` to `out`: `t`/`T` for a standard/extended data frame,
/// `r`/`R` for a remote one. False, and nothing appended, for an error frame (which an adapter
/// reports but cannot send).
pub fn push_frame(out: &mut Vec<u8>, frame: &CanFrame) -> bool {
    let (letter, digits) = match (frame.kind(), frame.is_extended()) {
        (FrameKind::Error, _) => return false,
        (FrameKind::Data, true) => (b'T', 8),
        (FrameKind::Data, false) => (b't', 3),
        (FrameKind::Remote, true) => (b'R', 8),
        (FrameKind::Remote, false) => (b'r', 3),
    };
    out.push(letter);
    push_hex(out, frame.id(), digits);
    out.push(b'0' + frame.len() as u8);
    for &b in frame.data() {
        push_hex(out, u32::from(b), 2);
    }
    out.push(b'\r');
    true
}

/// What an adapter said, one item at a time ([`Parser::push`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Event {
    /// A frame received from the bus, with the adapter's millisecond timestamp (0..60000,
    /// wrapping) where it appends one.
    Frame(CanFrame, Option<u16>),
    /// `\r`: a command done.
    Ack,
    /// BEL: a command refused.
    Refused,
    /// `z` / `Z`: a frame sent.
    Sent,
    /// A line that is not one of the above (a status reply such as `F00`, a version, garbage).
    NotUnderstood,
}

/// Counts of what a [`Parser`] read.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// Frames received.
    pub frames: u64,
    /// Commands done (`\r`).
    pub acks: u64,
    /// Commands refused (BEL).
    pub refused: u64,
    /// Frames sent (`z`/`Z`).
    pub sent: u64,
    /// Lines not understood.
    pub not_understood: u64,
}

/// A streaming parser of an SLCAN adapter's output: bytes in any pieces, [`Event`]s out. Never
/// panics and holds at most [`MAX_LINE`] bytes, whatever it is given.
#[derive(Debug, Clone, Default)]
pub struct Parser {
    line: Vec<u8>,
    /// The line being read is longer than [`MAX_LINE`]: skipped to its end.
    overlong: bool,
    counts: Counts,
}

impl Parser {
    /// A parser at the start of a line.
    pub fn new() -> Parser {
        Parser::default()
    }

    /// What was read so far.
    pub fn counts(&self) -> Counts {
        self.counts
    }

    /// Reads `bytes`, calling `event` for each item they complete.
    pub fn push(&mut self, bytes: &[u8], mut event: impl FnMut(Event)) {
        for &b in bytes {
            match b {
                b'\r' | b'\n' | BEL => {
                    if self.overlong || !self.line.is_empty() {
                        let e = if self.overlong {
                            Event::NotUnderstood
                        } else {
                            parse_line(&self.line)
                        };
                        self.count(e);
                        event(e);
                    } else if b == b'\r' {
                        self.count(Event::Ack);
                        event(Event::Ack);
                    }
                    if b == BEL {
                        self.count(Event::Refused);
                        event(Event::Refused);
                    }
                    self.line.clear();
                    self.overlong = false;
                }
                _ if self.overlong => {}
                _ if self.line.len() >= MAX_LINE => {
                    self.line.clear();
                    self.overlong = true;
                }
                _ => self.line.push(b),
            }
        }
    }

    fn count(&mut self, e: Event) {
        let c = &mut self.counts;
        match e {
            Event::Frame(..) => c.frames += 1,
            Event::Ack => c.acks += 1,
            Event::Refused => c.refused += 1,
            Event::Sent => c.sent += 1,
            Event::NotUnderstood => c.not_understood += 1,
        }
    }
}

/// The value of hex digits (`None` if one is not).
fn hex_value(digits: &[u8]) -> Option<u32> {
    digits.iter().try_fold(0u32, |acc, &d| {
        let v = char::from(d).to_digit(16)?;
        Some(acc << 4 | v)
    })
}

/// One line of an adapter's output, without its `\r`.
fn parse_line(line: &[u8]) -> Event {
    if matches!(line, b"z" | b"Z") {
        return Event::Sent;
    }
    parse_frame(line).map_or(Event::NotUnderstood, |(f, t)| Event::Frame(f, t))
}

fn parse_frame(line: &[u8]) -> Option<(CanFrame, Option<u16>)> {
    let (&letter, rest) = line.split_first()?;
    let (extended, remote) = match letter {
        b't' => (false, false),
        b'T' => (true, false),
        b'r' => (false, true),
        b'R' => (true, true),
        _ => return None,
    };
    let digits = if extended { 8 } else { 3 };
    let id = hex_value(rest.get(..digits)?)?;
    let len = char::from(*rest.get(digits)?).to_digit(10)? as usize;
    if len > 8 {
        return None;
    }
    let rest = &rest[digits + 1..];
    let data_digits = if remote { 0 } else { 2 * len };
    let stamp = match rest.len().checked_sub(data_digits)? {
        0 => None,
        4 => Some(hex_value(&rest[data_digits..])? as u16),
        _ => return None,
    };
    let frame = if remote {
        CanFrame::remote(id, extended, len as u8)?
    } else {
        let mut data = [0u8; 8];
        for (i, byte) in data[..len].iter_mut().enumerate() {
            *byte = hex_value(&rest[2 * i..2 * i + 2])? as u8;
        }
        if extended {
            CanFrame::extended(id, &data[..len])?
        } else {
            CanFrame::standard(id, &data[..len])?
        }
    };
    Some((frame, stamp))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes() {
        assert_eq!(bitrate_code(1_000_000), Some(8));
        assert_eq!(bitrate_code(500_000), Some(6));
        assert_eq!(bitrate_code(10_000), Some(0));
        assert_eq!(bitrate_code(800_000), Some(7));
        assert_eq!(bitrate_code(83_333), None);
        assert_eq!(setup(8), b"\rC\rS8\rO\r");
    }

    #[test]
    fn lines() {
        let mut out = Vec::new();
        push_extended(
            &mut out,
            0x1004_0A64,
            &[0x5C, 0xC7, 0x07, 0x00, 0x00, 0x00, 0x20, 0x85],
        );
        push_extended(&mut out, 0x1F, &[]);
        assert_eq!(out, b"T10040A6485CC7070000002085\rT0000001F0\r");
    }

    fn frames() -> Vec<CanFrame> {
        vec![
            CanFrame::extended(0x1004_0A64, &[1, 2, 0xC5]).unwrap(),
            CanFrame::extended(0x1FFF_FFFF, &[0xFF; 8]).unwrap(),
            CanFrame::standard(0x7FF, &[]).unwrap(),
            CanFrame::standard(0x123, &[0xAB]).unwrap(),
            CanFrame::remote(0x123, false, 4).unwrap(),
            CanFrame::remote(0x1234_5678, true, 0).unwrap(),
        ]
    }

    fn events(bytes: &[u8]) -> Vec<Event> {
        let mut p = Parser::new();
        let mut out = Vec::new();
        p.push(bytes, |e| out.push(e));
        out
    }

    #[test]
    fn every_frame_kind_is_written_and_read_back() {
        let mut out = Vec::new();
        for f in frames() {
            assert!(push_frame(&mut out, &f));
        }
        assert!(!push_frame(&mut out, &CanFrame::error(4, &[0; 8]).unwrap()));
        assert_eq!(
            String::from_utf8_lossy(&out),
            "T10040A6430102C5\rT1FFFFFFF8FFFFFFFFFFFFFFFF\rt7FF0\rt1231AB\rr1234\rR123456780\r"
        );
        let got = events(&out);
        let want: Vec<Event> = frames()
            .into_iter()
            .map(|f| Event::Frame(f, None))
            .collect();
        assert_eq!(got, want);
        // Any split gives the same.
        for cut in 0..out.len() {
            let mut p = Parser::new();
            let mut got = Vec::new();
            p.push(&out[..cut], |e| got.push(e));
            p.push(&out[cut..], |e| got.push(e));
            assert_eq!(got, want, "cut at {cut}");
        }
    }

    #[test]
    fn answers_timestamps_and_garbage() {
        let got = events(b"\r\x07z\rZ\rt1231AB1234\rT1004050A0C0EA\rF00\rt12\rt1239\rhello\n\r\n");
        assert_eq!(
            got,
            [
                Event::Ack,
                Event::Refused,
                Event::Sent,
                Event::Sent,
                Event::Frame(CanFrame::standard(0x123, &[0xAB]).unwrap(), Some(0x1234)),
                Event::Frame(CanFrame::extended(0x1004_050A, &[]).unwrap(), Some(0xC0EA)),
                Event::NotUnderstood,
                Event::NotUnderstood,
                Event::NotUnderstood,
                Event::NotUnderstood,
                Event::Ack,
            ]
        );
        // A frame's line cut by a refusal is not understood, then the refusal counts.
        let mut p = Parser::new();
        p.push(b"T100\x07", |_| {});
        let c = p.counts();
        assert_eq!((c.not_understood, c.refused, c.frames), (1, 1, 0));
        // An endless line is one line not understood, and holds no memory.
        let mut p = Parser::new();
        p.push(&[b'T'; 100_000], |_| panic!("nothing yet"));
        assert!(p.line.len() <= MAX_LINE);
        p.push(b"\rt1230\r", |_| {});
        assert_eq!((p.counts().not_understood, p.counts().frames), (1, 1));
        // Ids past their width, lengths over 8, non-hex digits.
        for bad in [
            &b"t8000\r"[..],
            b"T200000000\r",
            b"t1239\r",
            b"t12G0\r",
            b"t123x\r",
        ] {
            assert_eq!(events(bad), [Event::NotUnderstood], "{bad:?}");
        }
    }

    proptest::proptest! {
        #[test]
        fn any_bytes_parse_without_panic(bytes in proptest::collection::vec(proptest::num::u8::ANY, 0..400), cut in 0usize..400) {
            let mut p = Parser::new();
            let cut = cut.min(bytes.len());
            let mut n = 0u64;
            p.push(&bytes[..cut], |_| n += 1);
            p.push(&bytes[cut..], |_| n += 1);
            let c = p.counts();
            proptest::prop_assert_eq!(n, c.frames + c.acks + c.refused + c.sent + c.not_understood);
            proptest::prop_assert!(p.line.len() <= MAX_LINE);
        }
    }
}
