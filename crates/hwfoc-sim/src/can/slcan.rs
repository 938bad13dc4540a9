//! The adapter end of SLCAN (Lawicel ASCII over a serial line, as a CANable with slcan
//! firmware speaks it): what a virtual CAN adapter on a pseudo-terminal answers to the
//! commands a program sends, and how it hands the bus's frames on.
//!
//! Commands end in `\r` (a `\n` is ignored). Answered: `C` (close), `S0`..`S8` (bit rate, while
//! closed), `O` (open), `F` (status flags: `F00`), `V`/`v`/`N` (versions, serial number), `Z`,
//! `M`, `m`, `X`, `W` (accepted, no effect) with `\r`; `T`/`t` (send an extended/standard
//! frame, while open) with `Z\r`/`z\r`; `R`/`r` (remote frames) likewise; an empty command with
//! `\r`; anything else, a command while the channel is in the wrong state, or a line that does
//! not parse, with BEL (`\x07`). Frames from the bus go out as `T` lines while the channel is
//! open, without timestamps.
//!
//! Written here because no crate of the workspace speaks the adapter's side of SLCAN: the io
//! crate's [`hwfoc_ports::can::slcan`] speaks the host's. Its [`Parser`] reads the frames of the
//! `T`/`t`/`R`/`r` commands (a host's send command has the layout of an adapter's received
//! frame) and its [`push_frame`] writes the frames handed on; the commands `C`, `S0`..`S8`,
//! `O`, `F`, `V`, `v`, `N`, `Z`, `M`, `m`, `X`, `W` are handled here, as that parser, made for
//! an adapter's output, does not know them.

use hwfoc::dronecan::CanFrame;
pub use hwfoc_ports::can::slcan::{BEL, BITRATES, push_frame};
use hwfoc_ports::can::slcan::{Event, Parser};

/// The longest command kept; a longer line is refused whole (BEL).
pub const MAX_LINE: usize = 64;

/// What a command asks of the bus.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Action {
    /// The channel's bit rate, bit/s.
    Bitrate(u32),
    /// A frame to send on the bus.
    Frame(CanFrame),
}

/// The adapter's state: channel open or closed, and the command being read.
#[derive(Debug, Clone, Default)]
pub struct Adapter {
    open: bool,
    /// Reads the frame of a `T`/`t`/`R`/`r` command.
    frames: Parser,
    line: Vec<u8>,
    overlong: bool,
    refused: u64,
}

impl Adapter {
    /// A closed adapter.
    pub fn new() -> Adapter {
        Adapter::default()
    }

    /// Whether the channel is open (frames are handed on only then).
    pub fn is_open(&self) -> bool {
        self.open
    }

    /// Commands refused so far.
    pub fn refused(&self) -> u64 {
        self.refused
    }

    /// Reads `bytes` a program wrote: answers go to `reply`, what the bus must do to
    /// `actions`.
    pub fn feed(&mut self, bytes: &[u8], reply: &mut Vec<u8>, actions: &mut Vec<Action>) {
        for &b in bytes {
            match b {
                b'\r' => {
                    let line = std::mem::take(&mut self.line);
                    if std::mem::take(&mut self.overlong) {
                        self.refuse(reply);
                    } else {
                        self.command(&line, reply, actions);
                    }
                }
                b'\n' => {}
                _ if self.line.len() >= MAX_LINE => self.overlong = true,
                _ => self.line.push(b),
            }
        }
    }

    /// The frame of a `T`/`t`/`R`/`r` command (the whole line, without its `\r`): identifier
    /// (8 or 3 hex digits), length, data (2 hex digits a byte; none for a remote frame), and an
    /// optional timestamp (4 hex digits) that is ignored; `None` unless the line is exactly that.
    fn parse_frame(&mut self, line: &[u8]) -> Option<CanFrame> {
        let mut events = 0;
        let mut frame = None;
        let mut take = |e: Event| {
            events += 1;
            if let Event::Frame(f, _) = e {
                frame = Some(f);
            }
        };
        self.frames.push(line, &mut take);
        self.frames.push(b"\r", &mut take);
        frame.filter(|_| events == 1)
    }

    fn refuse(&mut self, reply: &mut Vec<u8>) {
        self.refused += 1;
        reply.push(BEL);
    }

    fn command(&mut self, line: &[u8], reply: &mut Vec<u8>, actions: &mut Vec<Action>) {
        let ok: &[u8] = match line {
            [] => b"\r",
            [b'C'] => {
                self.open = false;
                b"\r"
            }
            [b'O'] if !self.open => {
                self.open = true;
                b"\r"
            }
            [b'S', code] if !self.open && (b'0'..=b'8').contains(code) => {
                actions.push(Action::Bitrate(BITRATES[usize::from(code - b'0')]));
                b"\r"
            }
            [b'F'] => b"F00\r",
            [b'V'] => b"V1013\r",
            [b'v'] => b"v1013\r",
            [b'N'] => b"NHWFC\r",
            [b'Z' | b'M' | b'm' | b'X' | b'W', ..] => b"\r",
            [kind @ (b'T' | b't' | b'R' | b'r'), ..] if self.open => match self.parse_frame(line) {
                Some(frame) => {
                    actions.push(Action::Frame(frame));
                    if kind.is_ascii_uppercase() {
                        b"Z\r"
                    } else {
                        b"z\r"
                    }
                }
                None => return self.refuse(reply),
            },
            _ => return self.refuse(reply),
        };
        reply.extend_from_slice(ok);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn feed(a: &mut Adapter, s: &[u8]) -> (Vec<u8>, Vec<Action>) {
        let (mut reply, mut actions) = (Vec::new(), Vec::new());
        a.feed(s, &mut reply, &mut actions);
        (reply, actions)
    }

    #[test]
    fn pydronecan_setup_then_frames_both_ways() {
        let mut a = Adapter::new();
        // pydronecan's driver: empty command, C, S6, O, F.
        let (reply, actions) = feed(&mut a, b"\rC\rS6\rO\rF\r");
        assert_eq!(reply, b"\r\r\r\rF00\r");
        assert_eq!(actions, [Action::Bitrate(500_000)]);
        assert!(a.is_open());
        // The bit rate cannot change while open; a frame can be sent only while open.
        let (reply, actions) = feed(&mut a, b"S8\rT1E4E2D7F30100C0\r");
        let frame = CanFrame::extended(0x1E4E_2D7F, &[0x01, 0x00, 0xC0]).unwrap();
        assert_eq!(reply, b"\x07Z\r");
        assert_eq!(actions, [Action::Frame(frame)]);
        // Split across writes, lower-case hex, with a timestamp; then a standard frame.
        let (r1, a1) = feed(&mut a, b"T1e4e2d7f301");
        assert!(r1.is_empty() && a1.is_empty());
        let (reply, actions) = feed(&mut a, b"00C01234\r\nt12320102\r");
        assert_eq!(reply, b"Z\rz\r");
        assert_eq!(
            actions,
            [
                Action::Frame(CanFrame::extended(0x1E4E_2D7F, &[1, 0, 0xC0]).unwrap()),
                Action::Frame(CanFrame::standard(0x123, &[1, 2]).unwrap())
            ]
        );
        // Bad lines: refused, never a panic.
        for bad in [
            &b"T1E4E2D7F9"[..],
            b"T1E4E2D7F2010",
            b"T1E4E2D7",
            b"TZZZZZZZZ0",
            b"T3FFFFFFF0",
            b"Q",
            b"O",
        ] {
            let mut line = bad.to_vec();
            line.push(b'\r');
            let (reply, actions) = feed(&mut a, &line);
            assert_eq!(reply, [BEL], "{bad:?}");
            assert!(actions.is_empty());
        }
        let (reply, _) = feed(&mut a, &[b'T'; 200]);
        assert!(reply.is_empty());
        assert_eq!(feed(&mut a, b"\rC\rT1E4E2D7F0\r").0, b"\x07\r\x07");
        assert_eq!(a.refused(), 10);
    }
}
