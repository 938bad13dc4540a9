//! A `candump -l` log as an input: one CAN stream per interface named in it.

use std::io::Read;

use super::can_log::{CanLogReader, Entry, Frames, Lines, decimal_ns};
use super::{InputError, InputFormat};
use crate::can::candump;
use crate::time::Clock;

impl InputFormat {
    /// A `candump -l` log: one CAN stream per interface, named by it, times the log's own
    /// timestamps (Unix seconds).
    pub const CANDUMP: InputFormat = InputFormat {
        name: "candump log",
        short_name: "candump",
        clock: Clock::Wall,
        live: false,
        recorded_ports: true,
    };
}

/// Whether `head`, an input's first bytes, may still be the start of a candump log (format
/// detection reads its first line whole while it may).
pub(super) fn may_start(head: &[u8]) -> bool {
    head == b"(" || candump::looks_like_line(head)
}

/// Whether `head`, an input's first line, is a candump log line.
pub(super) fn is_start(head: &[u8]) -> bool {
    std::str::from_utf8(head).is_ok_and(|line| candump::parse_line(line.trim_end(), 1).is_ok())
}

/// The lines of a candump log, read as frames ([`CanLogReader`]: one stream per interface).
pub(super) struct CandumpLines(Lines);

impl CandumpLines {
    /// Reads the log `reader` gives, from its first line.
    pub(super) fn reader(reader: Box<dyn Read>) -> CanLogReader<CandumpLines> {
        CanLogReader::new(CandumpLines(Lines::new(reader)))
    }
}

impl Frames for CandumpLines {
    fn format(&self) -> InputFormat {
        InputFormat::CANDUMP
    }

    fn next(&mut self, name: &str, bus: &mut String) -> Result<Option<Entry>, InputError> {
        let Some(text) = self.0.next(name, "a candump -l log")? else {
            return Ok(None);
        };
        match candump::parse_line(&text, self.0.number) {
            Ok(l) => {
                bus.push_str(l.interface);
                // The stamp as written, exactly (`parse_line` took it for seconds).
                let stamp = text[1..].split_once(')').map_or("", |s| s.0);
                Ok(Some(Entry {
                    t_ns: Some(decimal_ns(stamp, 1_000_000_000).unwrap_or(u64::MAX)),
                    frame: l.frame,
                }))
            }
            Err(e) => Err(InputError::Csv {
                input: name.to_string(),
                line: e.line,
                message: format!("not a candump -l line: {}", e.reason),
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::{Input, InputFormat, Notice};
    use hwfoc::dronecan::CanFrame;

    const LOG: &str = "(1700000000.100000) can0 1C4E2D01#0102C0\n\
                       (1700000000.150000) vcan1 123#R4\n\
                       (1700000000.200000) can0 123##1112233\n\
                       \n\
                       (1700000000.250000) can0 20000004#0004000000000000\n";

    #[test]
    fn a_log_is_detected_and_gives_a_can_stream_per_interface() {
        let mut input = Input::from_memory("bus.log", LOG.as_bytes().to_vec()).unwrap();
        assert_eq!(input.format(), InputFormat::CANDUMP);
        assert_eq!(input.format().short_name(), "candump");
        let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let sink = std::sync::Arc::clone(&seen);
        input.set_notices(move |n| sink.lock().unwrap().push(n));
        let mut got = Vec::new();
        let mut fd = 0;
        while let Some(b) = input.next_batch().unwrap() {
            let times = b.times.unwrap();
            assert_eq!(b.bytes.len() % 16, 0);
            for (k, record) in b.bytes.chunks(16).enumerate() {
                let record: &[u8; 16] = record.try_into().unwrap();
                assert!(
                    times[16 * k..16 * k + 16]
                        .iter()
                        .all(|&t| t == times[16 * k])
                );
                // A CAN FD line: the record that stands for one, counted by the stream.
                if *record == crate::can::NOT_CLASSIC_RECORD {
                    fd += 1;
                    continue;
                }
                got.push((
                    b.stream,
                    times[16 * k],
                    CanFrame::from_socketcan_record(record).unwrap(),
                ));
            }
        }
        assert_eq!(input.streams(), 2);
        assert_eq!(
            (input.stream_name(0), input.stream_name(1)),
            ("can0".into(), "vcan1".into())
        );
        assert!(input.is_can(0) && input.is_can(1) && !input.is_can(2));
        assert_eq!(fd, 1);
        let frames: Vec<(usize, String)> = got.iter().map(|g| (g.0, g.2.to_string())).collect();
        assert_eq!(
            frames,
            [
                (0, "1C4E2D01#0102C0".to_string()),
                (0, "20000004#0004000000000000".to_string()),
                (1, "123#R4".to_string()),
            ]
        );
        assert!((got[0].1 - 1_700_000_000.1).abs() < 1e-6);
        assert!((got[1].1 - 1_700_000_000.25).abs() < 1e-6);
        assert_eq!(
            *seen.lock().unwrap(),
            [Notice::NotClassicCan {
                input: "bus.log".into(),
                interface: "can0".into(),
                frames: 1
            }]
        );
    }

    #[test]
    fn a_bad_line_is_an_error_naming_its_number_after_the_frames_before_it() {
        let log = format!("{LOG}(1700000001.0) can0 XYZ\n");
        let mut input = Input::from_memory("bus.log", log.into_bytes()).unwrap();
        input.set_notices(|_| {});
        let mut frames = 0;
        let e = loop {
            match input.next_batch() {
                Ok(Some(b)) => frames += b.bytes.len() / 16,
                Ok(None) => panic!("no error"),
                Err(e) => break e,
            }
        };
        // Three frames and the record of a CAN FD frame.
        assert_eq!(frames, 4);
        assert_eq!(
            e.to_string(),
            "bus.log:6: not a candump -l line: the frame is not ID#DATA"
        );
        // A first line that is not candump's: not a log.
        let input = Input::from_memory("x", b"(1700000000.1) can0\n".to_vec()).unwrap();
        assert_eq!(input.format(), InputFormat::RAW);
    }

    #[test]
    fn a_closed_file_keeps_which_streams_are_can() {
        let file = crate::input::file::memory::MemoryFile::new("bus.log", LOG.as_bytes().to_vec());
        let mut input = file.input().unwrap();
        input.set_notices(|_| {});
        while input.next_batch().unwrap().is_some() {}
        assert!(input.is_can(1) && !input.is_can(2));
        assert_eq!(input.stream_name(1), "vcan1");
    }
}
