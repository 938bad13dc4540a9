//! The settings the setup services change, by name: direction, throttle source, LED, the
//! status messages' reporting rates, the bus bit rate ([`Change`]), each with the request
//! that makes it and the words that name it.

use std::fmt;
use std::str::FromStr;

use hwfoc::dronecan::{
    Kind, Message, SetBaudRequest, SetDirectionRequest, SetIdRequest, SetLedRequest,
    SetReportingFrequencyRequest, SetThrottleSourceRequest,
};

/// Which way the motor turns (`SetDirection`: 0 clockwise, 1 counter-clockwise).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum Direction {
    /// Clockwise (`cw`).
    Cw = SetDirectionRequest::CW,
    /// Counter-clockwise (`ccw`).
    Ccw = SetDirectionRequest::CCW,
}

impl Direction {
    /// From the wire's code (0 or 1; `GetMajorConfig`'s `direction` bit).
    pub fn from_ccw(ccw: bool) -> Direction {
        if ccw { Direction::Ccw } else { Direction::Cw }
    }

    /// The wire's code.
    pub fn code(self) -> u8 {
        self as u8
    }

    /// `cw` or `ccw`.
    pub fn name(self) -> &'static str {
        match self {
            Direction::Cw => "cw",
            Direction::Ccw => "ccw",
        }
    }
}

impl FromStr for Direction {
    type Err = String;
    fn from_str(s: &str) -> Result<Direction, String> {
        match s.to_ascii_lowercase().as_str() {
            "cw" => Ok(Direction::Cw),
            "ccw" => Ok(Direction::Ccw),
            _ => Err(format!("{s:?}: expected cw or ccw")),
        }
    }
}

/// Where the ESC takes its throttle from (`SetThrottleSource`: 0 CAN, 1 PWM).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum ThrottleSource {
    /// DroneCAN's `RawCommand` (`can`).
    Can = SetThrottleSourceRequest::CAN,
    /// The PWM signal wire (`pwm`).
    Pwm = SetThrottleSourceRequest::PWM,
}

impl ThrottleSource {
    /// From `GetMajorConfig`'s `throttle_source` bit (set: PWM).
    pub fn from_pwm(pwm: bool) -> ThrottleSource {
        if pwm {
            ThrottleSource::Pwm
        } else {
            ThrottleSource::Can
        }
    }

    /// `can` or `pwm`.
    pub fn name(self) -> &'static str {
        match self {
            ThrottleSource::Can => "can",
            ThrottleSource::Pwm => "pwm",
        }
    }
}

impl FromStr for ThrottleSource {
    type Err = String;
    fn from_str(s: &str) -> Result<ThrottleSource, String> {
        match s.to_ascii_lowercase().as_str() {
            "can" => Ok(ThrottleSource::Can),
            "pwm" => Ok(ThrottleSource::Pwm),
            _ => Err(format!("{s:?}: expected can or pwm")),
        }
    }
}

/// The LED colours by their `SetLED` code (bits R = 4, G = 2, B = 1).
pub const LED_COLORS: [&str; 8] = [
    "off", "blue", "green", "cyan", "red", "magenta", "yellow", "white",
];

/// An LED setting: colour, blink, and whether the ESC keeps it (`SetLED`'s option 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Led {
    /// Colour code 0..=7 ([`LED_COLORS`]).
    pub color: u8,
    /// Blink code ([`SetLedRequest::BLINKS`]): 0 steady, 1, 2 or 5 Hz.
    pub blink: u8,
    /// Saved by the ESC (not read back: `GetMajorConfig` does not say).
    pub save: bool,
}

/// `COLOR[,BLINK][,save]`: `red`, `green,2`, `white,5,save`, `blue,save`.
impl FromStr for Led {
    type Err = String;
    fn from_str(s: &str) -> Result<Led, String> {
        let mut parts = s.split(',');
        let color = parts.next().unwrap_or_default().to_ascii_lowercase();
        let color = LED_COLORS
            .iter()
            .position(|&c| c == color)
            .ok_or_else(|| format!("{s:?}: the colour is one of {}", LED_COLORS.join(", ")))?;
        let mut led = Led {
            color: color as u8,
            blink: 0,
            save: false,
        };
        for part in parts {
            match part {
                "save" => led.save = true,
                n => {
                    led.blink = n
                        .trim_end_matches("Hz")
                        .parse::<u8>()
                        .ok()
                        .filter(|b| SetLedRequest::BLINKS.contains(b))
                        .ok_or_else(|| {
                            format!("{s:?}: expected COLOR[,BLINK][,save], BLINK 0, 1, 2 or 5 (Hz)")
                        })?
                }
            }
        }
        Ok(led)
    }
}

impl fmt::Display for Led {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let color = LED_COLORS.get(usize::from(self.color)).unwrap_or(&"?");
        match self.blink {
            0 => write!(f, "{color} steady")?,
            b => write!(f, "{color} blinking {b} Hz")?,
        }
        if self.save {
            f.write_str(", saved")?;
        }
        Ok(())
    }
}

/// One of the three status messages whose rate `SetReportingFrequency` sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum StatusMessage {
    /// `StatusMsg1` (20050): rpm, pwm, status (`msg1`).
    Msg1,
    /// `StatusMsg2` (20051): voltage, current, temperature (`msg2`).
    Msg2,
    /// `StatusMsg3` (20052): temperatures (`msg3`).
    Msg3,
}

impl StatusMessage {
    /// The three, in order.
    pub const ALL: [StatusMessage; 3] = [
        StatusMessage::Msg1,
        StatusMessage::Msg2,
        StatusMessage::Msg3,
    ];

    /// Its data type: `SetReportingFrequency`'s `MSG_ID` is its id.
    pub fn kind(self) -> Kind {
        match self {
            StatusMessage::Msg1 => Kind::StatusMsg1,
            StatusMessage::Msg2 => Kind::StatusMsg2,
            StatusMessage::Msg3 => Kind::StatusMsg3,
        }
    }

    /// `msg1`, `msg2`, `msg3`.
    pub fn name(self) -> &'static str {
        match self {
            StatusMessage::Msg1 => "msg1",
            StatusMessage::Msg2 => "msg2",
            StatusMessage::Msg3 => "msg3",
        }
    }
}

impl FromStr for StatusMessage {
    type Err = String;
    fn from_str(s: &str) -> Result<StatusMessage, String> {
        match s.to_ascii_lowercase().as_str() {
            "msg1" | "statusmsg1" => Ok(StatusMessage::Msg1),
            "msg2" | "statusmsg2" => Ok(StatusMessage::Msg2),
            "msg3" | "statusmsg3" => Ok(StatusMessage::Msg3),
            // Or its data type id (20050-20052).
            id => StatusMessage::ALL
                .into_iter()
                .find(|m| id.parse() == Ok(m.kind().data_type_id()))
                .ok_or_else(|| format!("{s:?}: expected msg1, msg2 or msg3")),
        }
    }
}

/// The rate of a `SetReportingFrequency` code (1..=9), Hz.
pub fn rate_hz(code: u8) -> Option<u16> {
    SetReportingFrequencyRequest::RATES_HZ
        .get(usize::from(code).checked_sub(1)?)
        .copied()
}

/// The `SetReportingFrequency` code of a rate in Hz (500, 250, 200, 100, 50, 20, 10, 1, 0).
pub fn rate_code(hz: u16) -> Option<u8> {
    SetReportingFrequencyRequest::RATES_HZ
        .iter()
        .position(|&r| r == hz)
        .map(|i| i as u8 + 1)
}

/// A rate code as text: `50 Hz`, or the code where it has no rate.
pub fn rate_text(code: u8) -> String {
    match rate_hz(code) {
        Some(hz) => format!("{hz} Hz"),
        None => format!("code {code}"),
    }
}

/// `MSG=HZ` (`msg1=100`): a status message's reporting rate, as [`Change::Rate`].
pub fn parse_rate(text: &str) -> Result<Change, String> {
    let (msg, hz) = text
        .split_once('=')
        .ok_or_else(|| format!("{text:?}: expected MSG=HZ, e.g. msg1=100"))?;
    let message = msg.parse::<StatusMessage>()?;
    let rates = SetReportingFrequencyRequest::RATES_HZ.map(|r| r.to_string());
    let code = hz
        .trim_end_matches("Hz")
        .parse::<u16>()
        .ok()
        .and_then(rate_code)
        .ok_or_else(|| format!("{text:?}: the rate is one of {} Hz", rates.join(", ")))?;
    Ok(Change::Rate { message, code })
}

/// The `SetBaud` code of a bit rate (1 M, 500 k, 250 k, 200 k, 100 k, 50 k).
pub fn baud_code(bitrate: u32) -> Option<u8> {
    SetBaudRequest::BITRATES
        .iter()
        .position(|&b| b == bitrate)
        .map(|i| i as u8)
}

/// One setting a setup service changes, with its value. Also what the ESC says it has (read
/// back: [`Client::read`](crate::Client::read)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Change {
    /// Node id and throttle channel (`SetID`).
    NodeId {
        /// The new node id, 1..=127.
        node_id: u8,
        /// The throttle channel, 1-based.
        channel: u8,
    },
    /// Direction (`SetDirection`).
    Direction(Direction),
    /// Throttle source (`SetThrottleSource`).
    ThrottleSource(ThrottleSource),
    /// LED (`SetLED`).
    Led(Led),
    /// A status message's reporting rate code (`SetReportingFrequency`, option 1 = write).
    Rate {
        /// Which message.
        message: StatusMessage,
        /// The rate code, 1..=9 ([`rate_hz`]).
        code: u8,
    },
    /// The CAN bit rate, bit/s (`SetBaud`).
    Bitrate(u32),
}

impl Change {
    /// The service request that makes the change (`None` for a bit rate `SetBaud` has no
    /// code for).
    pub fn request(&self) -> Option<Message> {
        Some(match *self {
            Change::NodeId { node_id, channel } => SetIdRequest {
                node_id,
                throttle_channel: channel,
            }
            .into(),
            Change::Direction(d) => SetDirectionRequest {
                direction: d.code(),
            }
            .into(),
            Change::ThrottleSource(s) => SetThrottleSourceRequest { source: s as u8 }.into(),
            Change::Led(l) => SetLedRequest {
                option: if l.save { SetLedRequest::SAVE } else { 0 },
                color: l.color,
                blink: l.blink,
            }
            .into(),
            Change::Rate { message, code } => SetReportingFrequencyRequest {
                option: SetReportingFrequencyRequest::WRITE,
                msg_id: message.kind().data_type_id(),
                rate: code,
            }
            .into(),
            Change::Bitrate(b) => SetBaudRequest {
                baud: baud_code(b)?,
            }
            .into(),
        })
    }

    /// Whether the change can make a motor turn, or turn otherwise: direction, throttle source,
    /// node id or channel, bit rate (not the LED nor a reporting rate).
    pub fn affects_motor(&self) -> bool {
        !matches!(self, Change::Led(_) | Change::Rate { .. })
    }

    /// Whether the ESC says what was asked: equal, the LED's save flag aside (it cannot be
    /// read back).
    pub fn agrees(&self, said: &Change) -> bool {
        match (self, said) {
            (Change::Led(a), Change::Led(b)) => (a.color, a.blink) == (b.color, b.blink),
            (a, b) => a == b,
        }
    }
}

/// `direction ccw`, `node id 12, throttle channel 3`, `LED red blinking 2 Hz`, `msg1 rate
/// 100 Hz`, `throttle source pwm`, `bit rate 250000 bit/s`.
impl fmt::Display for Change {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Change::NodeId { node_id, channel } => {
                write!(f, "node id {node_id}, throttle channel {channel}")
            }
            Change::Direction(d) => write!(f, "direction {}", d.name()),
            Change::ThrottleSource(s) => write!(f, "throttle source {}", s.name()),
            Change::Led(l) => write!(f, "LED {l}"),
            Change::Rate { message, code } => {
                write!(f, "{} rate {}", message.name(), rate_text(*code))
            }
            Change::Bitrate(b) => write!(f, "bit rate {b} bit/s"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_can_turn_a_motor() {
        let led = Change::Led("red".parse().unwrap());
        let rate = parse_rate("msg1=0").unwrap();
        assert!(!led.affects_motor() && !rate.affects_motor());
        for c in [
            Change::Direction(Direction::from_ccw(true)),
            Change::ThrottleSource(ThrottleSource::from_pwm(true)),
            Change::NodeId {
                node_id: 12,
                channel: 2,
            },
            Change::Bitrate(250_000),
        ] {
            assert!(c.affects_motor(), "{c}");
        }
    }

    #[test]
    fn names_parse_and_print() {
        assert_eq!("CCW".parse(), Ok(Direction::Ccw));
        assert_eq!("StatusMsg2".parse(), Ok(StatusMessage::Msg2));
        assert_eq!("20052".parse(), Ok(StatusMessage::Msg3));
        assert!("20053".parse::<StatusMessage>().is_err());
        assert_eq!(Direction::Ccw.code(), 1);
        assert_eq!(ThrottleSource::Pwm as u8, 1);
        assert!("left".parse::<Direction>().is_err());
        assert_eq!("pwm".parse(), Ok(ThrottleSource::Pwm));
        let led: Led = "red,2,save".parse().unwrap();
        assert_eq!(
            led,
            Led {
                color: 4,
                blink: 2,
                save: true
            }
        );
        assert_eq!(led.to_string(), "red blinking 2 Hz, saved");
        assert_eq!("green".parse::<Led>().unwrap().to_string(), "green steady");
        assert!("green,3".parse::<Led>().is_err() && "pink".parse::<Led>().is_err());
        assert_eq!(
            parse_rate("msg1=100"),
            Ok(Change::Rate {
                message: StatusMessage::Msg1,
                code: 4
            })
        );
        assert!(parse_rate("msg1=99").is_err() && parse_rate("msg4=10").is_err());
        assert_eq!(rate_text(9), "0 Hz");
        assert_eq!(rate_text(15), "code 15");
        assert_eq!(baud_code(250_000), Some(2));
        assert_eq!(Change::Bitrate(125_000).request(), None);
    }

    #[test]
    fn requests() {
        let m = Change::Rate {
            message: StatusMessage::Msg3,
            code: 6,
        }
        .request();
        assert_eq!(
            m,
            Some(Message::from(SetReportingFrequencyRequest {
                option: 1,
                msg_id: 20052,
                rate: 6
            }))
        );
        let a = Change::Led("white,5,save".parse().unwrap());
        let b = Change::Led("white,5".parse().unwrap());
        assert!(a.agrees(&b) && a != b);
        assert!(!Change::Direction(Direction::Cw).agrees(&Change::Direction(Direction::Ccw)));
    }
}
