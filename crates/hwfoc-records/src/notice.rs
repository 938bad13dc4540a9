//! What an input has to tell besides its bytes: a serial port lost or back, a note written in a
//! recording, a part of a recording that is damaged or not serial bytes and was skipped.
//!
//! None of these stops reading, so none is an [`InputError`](crate::InputError). An
//! [`Input`](crate::Input) hands each to its notice sink as it is met: by default
//! [`to_stderr`], which writes the line the `hwfoc` command prints; a front end that has a
//! channel of its own for them (Python's `warnings`, a dashboard's log) sets another with
//! [`Input::set_notices`](crate::Input::set_notices).

use std::fmt;

use crate::escape::Escaped;
use crate::pcapng::Damage;
use crate::serial::PortEvent;

/// Something an input met that the reader should know.
#[derive(Debug, Clone, PartialEq)]
pub enum Notice {
    /// A serial port disappeared (unplugged); it is reopened when it comes back.
    PortLost {
        /// The port as named.
        port: String,
        /// Why reading failed.
        reason: String,
    },
    /// A lost serial port is open again.
    PortBack {
        /// The port as named.
        port: String,
    },
    /// A serial port read without a rate given found its rate from the bytes (auto-baud).
    PortBaud {
        /// The port as named.
        port: String,
        /// The rate found.
        baud: u32,
        /// The protocol of the first frames found at it.
        protocol: hwfoc::Protocol,
    },
    /// A comment written in a recording (`hwfoc record` notes gaps and restarts there).
    Comment {
        /// The input as named.
        input: String,
        /// The interface (port) the comment is attached to.
        interface: String,
        /// The comment.
        text: String,
    },
    /// An interface of a recording that does not carry serial bytes: its packets are skipped.
    ForeignInterface {
        /// The input as named.
        input: String,
        /// The interface's name.
        interface: String,
        /// Its pcapng link type.
        link_type: u16,
    },
    /// Frames of a CAN interface or log that are not classic CAN (CAN FD), skipped: told once
    /// per interface, with their number, at the end of the input.
    NotClassicCan {
        /// The input as named.
        input: String,
        /// The interface (bus).
        interface: String,
        /// How many were skipped.
        frames: u64,
    },
    /// Records of a CAN bus whose protocol is not the one forced, left out: told once per bus,
    /// with their number by protocol, at the end of the input.
    LeftOut {
        /// The input as named.
        input: String,
        /// The interface (bus).
        interface: String,
        /// The protocol forced.
        forced: hwfoc::Protocol,
        /// The records left out, by protocol.
        records: Vec<(hwfoc::Protocol, u64)>,
    },
    /// Something amiss on a CAN bus of a file, found when it was read ahead: two ESCs that
    /// claim one throttle channel (two nodes answering GetEscID with one channel, a Hobbywing
    /// ESC beside a standard one of that `esc_index`: read as two ESCs, the second numbered
    /// after the bus's channels), or error frames and no ESC status (a wrong bit rate).
    CanBus {
        /// The input as named.
        input: String,
        /// The interface (bus).
        interface: String,
        /// What, in words (`node 10 and node 11 both claim throttle channel 1: read as two
        /// ESCs`).
        message: String,
    },
    /// A live port's ESCs past the last number records have (255): their frames are left out
    /// (counted by [`crate::PortStreams::left_out`]), told once per port.
    PastLastEsc {
        /// The port or bus, as named.
        input: String,
        /// Where the first ESC left out is on the port (`DataLink channel 7`, `place 300 of
        /// the bus`), if not the port itself.
        place: Option<String>,
    },
    /// A damaged place in a recording, skipped.
    Damage {
        /// The input as named.
        input: String,
        /// Where and what.
        damage: Damage,
    },
    /// Recordings of one port that overlap in time (the same recording given twice, say): the
    /// later input's bytes of that time are left out, each moment decoded once.
    Overlap {
        /// The input as named whose bytes were left out.
        input: String,
        /// The port.
        port: String,
        /// The input that gave the port's bytes of that time.
        earlier: String,
        /// How long the overlap lasts, in seconds.
        seconds: f64,
    },
    /// An input that holds the same bytes as an earlier one (the same file given twice, or a
    /// copy): it was not read again.
    Duplicate {
        /// The input as named that was not read.
        input: String,
        /// The earlier input with the same bytes.
        earlier: String,
    },
    /// Ports of an input named as an earlier input's, at the same time, in another recording
    /// (the port names of every drone and laptop are alike): other ESCs, numbered apart.
    SamePortNames {
        /// The input as named.
        input: String,
        /// The earlier input.
        earlier: String,
        /// The ports named alike, with this input's ESC number and the earlier input's.
        ports: Vec<(String, usize, usize)>,
    },
    /// Ports of an input named as an earlier input's whose bytes begin where the earlier
    /// one's end, in files that name no recording (another program wrote them): read as other
    /// ESCs, since only the user can say that they are one recording (`--join`).
    MayContinue {
        /// The input as named.
        input: String,
        /// The earlier input.
        earlier: String,
        /// The ports named alike.
        ports: Vec<String>,
        /// Seconds from the end of the earlier input's bytes to the start of this one's.
        gap: f64,
    },
}

impl Notice {
    /// The notice of a port's [`PortEvent::Lost`], [`PortEvent::Back`] or
    /// [`PortEvent::Found`], the port named as in `names` (the set's names); `None` for bytes,
    /// a rate tried, or a port `names` does not hold.
    pub fn of_port_event(event: &PortEvent, names: &[String]) -> Option<Notice> {
        match event {
            PortEvent::Data { .. } | PortEvent::Searching { .. } => None,
            PortEvent::Found {
                port,
                baud,
                protocol,
                ..
            } => Some(Notice::PortBaud {
                port: names.get(*port)?.clone(),
                baud: *baud,
                protocol: *protocol,
            }),
            PortEvent::Lost { port, reason, .. } => Some(Notice::PortLost {
                port: names.get(*port)?.clone(),
                reason: reason.clone(),
            }),
            PortEvent::Back { port, .. } => Some(Notice::PortBack {
                port: names.get(*port)?.clone(),
            }),
        }
    }

    /// Whether it warns of something lost or skipped (rather than only informing).
    pub fn is_warning(&self) -> bool {
        matches!(
            self,
            Notice::PortLost { .. }
                | Notice::ForeignInterface { .. }
                | Notice::NotClassicCan { .. }
                | Notice::LeftOut { .. }
                | Notice::CanBus { .. }
                | Notice::PastLastEsc { .. }
                | Notice::Damage { .. }
                | Notice::Overlap { .. }
                | Notice::Duplicate { .. }
        )
    }

    /// The line the `hwfoc` command prints for it: `hwfoc: warning: ...`, `hwfoc: note: ...`
    /// or `hwfoc: ...`.
    pub fn line(&self) -> String {
        let level = match self {
            _ if self.is_warning() => "warning: ",
            Notice::Comment { .. } | Notice::SamePortNames { .. } | Notice::MayContinue { .. } => {
                "note: "
            }
            _ => "",
        };
        format!("hwfoc: {level}{self}")
    }
}

impl fmt::Display for Notice {
    /// The notice for a person: its names and texts (a recording's, a port's) [`Escaped`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Notice::PortLost { port, reason } => write!(
                f,
                "{} lost ({}); retrying every {} ms",
                Escaped(port),
                Escaped(reason),
                crate::serial::RETRY_EVERY.as_millis()
            ),
            Notice::PortBack { port } => write!(f, "{} is back", Escaped(port)),
            Notice::PortBaud {
                port,
                baud,
                protocol,
            } => write!(f, "{}: {baud} baud ({})", Escaped(port), protocol.title()),
            Notice::Comment {
                input,
                interface,
                text,
            } => write!(
                f,
                "{}: {}: {}",
                Escaped(input),
                Escaped(interface),
                Escaped(text)
            ),
            Notice::ForeignInterface {
                input,
                interface,
                link_type,
            } => write!(
                f,
                "{}: interface {} has link type {link_type}, not serial bytes: its packets are \
                 skipped",
                Escaped(input),
                Escaped(interface)
            ),
            Notice::NotClassicCan {
                input,
                interface,
                frames,
            } => write!(
                f,
                "{}: {}: {frames} CAN FD frames skipped (only classic CAN is read)",
                Escaped(input),
                Escaped(interface)
            ),
            Notice::LeftOut {
                input,
                interface,
                forced,
                records,
            } => {
                let counts: Vec<String> = records
                    .iter()
                    .map(|(p, n)| format!("{n} {} records", p.name()))
                    .collect();
                write!(
                    f,
                    "{}: {}: {} left out (not {forced}, the protocol forced)",
                    Escaped(input),
                    Escaped(interface),
                    counts.join(" and ")
                )
            }
            Notice::CanBus {
                input,
                interface,
                message,
            } if input == interface => write!(f, "{}: {message}", Escaped(input)),
            Notice::CanBus {
                input,
                interface,
                message,
            } => write!(f, "{}: {}: {message}", Escaped(input), Escaped(interface)),
            Notice::PastLastEsc { input, place } => write!(
                f,
                "{}: ESCs past number {} left out{}: records number ESCs 0 to {} only",
                Escaped(input),
                u8::MAX,
                place
                    .as_ref()
                    .map(|p| format!(" (the first: {p})"))
                    .unwrap_or_default(),
                u8::MAX
            ),
            Notice::Damage { input, damage } => write!(f, "{}: {damage}", Escaped(input)),
            Notice::Duplicate { input, earlier } => write!(
                f,
                "{} holds the same bytes as {}: read once",
                Escaped(input),
                Escaped(earlier)
            ),
            Notice::SamePortNames {
                input,
                earlier,
                ports,
            } => {
                write!(
                    f,
                    "{}: its ports named as {}'s at the same time are of another recording, so \
                     other ESCs: ",
                    Escaped(input),
                    Escaped(earlier)
                )?;
                for (k, (port, esc, other)) in ports.iter().enumerate() {
                    let sep = if k == 0 { "" } else { ", " };
                    write!(f, "{sep}{} is ESC {esc} (not ESC {other})", Escaped(port))?;
                }
                Ok(())
            }
            Notice::MayContinue {
                input,
                earlier,
                ports,
                gap,
            } => {
                write!(f, "{}: ", Escaped(input))?;
                for (k, port) in ports.iter().enumerate() {
                    let sep = if k == 0 { "" } else { ", " };
                    write!(f, "{sep}{}", Escaped(port))?;
                }
                write!(
                    f,
                    " begin{} {gap:.3} s after {} ends, with the same port names: read as other \
                     ESCs; if the files are one recording, read them joined (hwfoc --join, \
                     Python join=True)",
                    if ports.len() == 1 { "s" } else { "" },
                    Escaped(earlier)
                )
            }
            Notice::Overlap {
                input,
                port,
                earlier,
                seconds,
            } => write!(
                f,
                "{}: {} overlaps {} by {seconds:.3} s (the same port at the same time): its \
                 bytes of that time were decoded once, from {}",
                Escaped(input),
                Escaped(port),
                Escaped(earlier),
                Escaped(earlier)
            ),
        }
    }
}

/// Where an input's notices go.
pub(crate) type NoticeSink = Box<dyn FnMut(Notice) + Send>;

/// The default sink: each notice's [`Notice::line`] on standard error.
pub(crate) fn to_stderr() -> NoticeSink {
    Box::new(|notice| eprintln!("{}", notice.line()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_those_the_command_printed() {
        let lost = Notice::PortLost {
            port: "/dev/ttyUSB0".into(),
            reason: "No such device".into(),
        };
        assert_eq!(
            lost.line(),
            "hwfoc: warning: /dev/ttyUSB0 lost (No such device); retrying every 500 ms"
        );
        let back = Notice::PortBack {
            port: "/dev/ttyUSB0".into(),
        };
        assert_eq!(back.line(), "hwfoc: /dev/ttyUSB0 is back");
        let note = Notice::Comment {
            input: "a.pcapng".into(),
            interface: "/dev/ttyUSB1".into(),
            text: "gap".into(),
        };
        assert_eq!(note.line(), "hwfoc: note: a.pcapng: /dev/ttyUSB1: gap");
        let crafted = Notice::Comment {
            input: "a.pcapng".into(),
            interface: "\x1b]0;title\x07".into(),
            text: "gap\r\x1b[2Jhwfoc: fake".into(),
        };
        assert_eq!(
            crafted.line(),
            "hwfoc: note: a.pcapng: \\x1b]0;title\\x07: gap\\r\\x1b[2Jhwfoc: fake"
        );
        assert!(lost.is_warning() && !back.is_warning() && !note.is_warning());
        let names = ["/dev/ttyUSB0".to_string()];
        let event = |port| PortEvent::Lost {
            port,
            t_ns: 0,
            reason: "No such device".into(),
        };
        assert_eq!(Notice::of_port_event(&event(0), &names), Some(lost));
        assert_eq!(Notice::of_port_event(&event(1), &names), None);
        let event = PortEvent::Back { port: 0, t_ns: 0 };
        assert_eq!(Notice::of_port_event(&event, &names), Some(back));
        let event = PortEvent::Data {
            port: 0,
            t_ns: 0,
            bytes: vec![1],
        };
        assert_eq!(Notice::of_port_event(&event, &names), None);
        let event = PortEvent::Found {
            port: 0,
            t_ns: 0,
            baud: 115_200,
            protocol: hwfoc::Protocol::Hw5,
        };
        let left_out = Notice::LeftOut {
            input: "bus.log".into(),
            interface: "can0".into(),
            forced: hwfoc::Protocol::Hw5,
            records: vec![
                (hwfoc::Protocol::HwCan, 39),
                (hwfoc::Protocol::DroneCan, 19),
            ],
        };
        assert_eq!(
            left_out.line(),
            "hwfoc: warning: bus.log: can0: 39 hw-can records and 19 dronecan records left out \
             (not hw5, the protocol forced)"
        );
        let found = Notice::of_port_event(&event, &names).unwrap();
        assert_eq!(
            found.line(),
            format!("hwfoc: {}: 115200 baud (HW5)", names[0])
        );
    }
}
