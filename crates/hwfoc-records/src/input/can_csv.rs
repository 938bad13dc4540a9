//! A python-can CSV log (`CSVWriter`) as an input: one CAN stream, times its own.
//!
//! The header `timestamp,arbitration_id,extended,remote,error,dlc,data`, then a row per frame:
//! Unix seconds, the id in hex (`0x...`), the flags as `0`/`1`, the length and the data in
//! base64. Error frames are passed over.
//!
//! Written here: the lines are python-can's own; base64 by the `base64` crate.

use std::io::Read;

use base64::Engine;
use base64::engine::general_purpose::STANDARD;

use super::can_log::{CanLogReader, Entry, Frames, Lines, decimal_ns, frame};
use super::{InputError, InputFormat};
use crate::time::Clock;

impl InputFormat {
    /// A python-can CSV log: one CAN stream, times its own (Unix seconds).
    pub const CAN_CSV: InputFormat = InputFormat {
        name: "python-can CSV log",
        short_name: "can-csv",
        clock: Clock::Wall,
        live: false,
        recorded_ports: true,
    };
}

/// What the log is called in its errors.
const WHAT: &str = "a python-can CSV log";
/// Its header line.
const HEADER: &str = "timestamp,arbitration_id,extended,remote,error,dlc,data";

/// Whether `head`, an input's first bytes, may still be the start of a python-can CSV log.
pub(super) fn may_start(head: &[u8]) -> bool {
    HEADER.as_bytes().starts_with(head) || is_start(head)
}

/// Whether `head`, an input's first line, is a python-can CSV log's header.
pub(super) fn is_start(head: &[u8]) -> bool {
    head.strip_suffix(b"\n").unwrap_or(head).trim_ascii_end() == HEADER.as_bytes()
}

/// The rows of a python-can CSV log, read as frames.
pub(super) struct CanCsvRows(Lines);

impl CanCsvRows {
    /// Reads the log `reader` gives, from its header.
    pub(super) fn reader(reader: Box<dyn Read>) -> CanLogReader<CanCsvRows> {
        CanLogReader::new(CanCsvRows(Lines::new(reader)))
    }
}

impl Frames for CanCsvRows {
    fn format(&self) -> InputFormat {
        InputFormat::CAN_CSV
    }

    fn next(&mut self, name: &str, _bus: &mut String) -> Result<Option<Entry>, InputError> {
        loop {
            let Some(text) = self.0.next(name, WHAT)? else {
                return Ok(None);
            };
            if text == HEADER {
                continue;
            }
            let fields: Vec<&str> = text.split(',').collect();
            let [time, id, extended, remote, error, dlc, data] = fields[..] else {
                return Err(self
                    .0
                    .error(name, format!("the row has not the 7 fields of {WHAT}")));
            };
            let flag = |f: &str| match f {
                "0" => Some(false),
                "1" => Some(true),
                _ => None,
            };
            let parsed = (|| {
                let t_ns = decimal_ns(time, 1_000_000_000)?;
                let id = u32::from_str_radix(id.strip_prefix("0x")?, 16).ok()?;
                let (extended, remote, error) = (flag(extended)?, flag(remote)?, flag(error)?);
                let dlc: usize = dlc.parse().ok().filter(|&d| d <= 8)?;
                let data = STANDARD.decode(data).ok()?;
                Some((t_ns, id, extended, remote, error, dlc, data))
            })();
            let Some((t_ns, id, extended, remote, error, dlc, data)) = parsed else {
                return Err(self
                    .0
                    .error(name, format!("the row is not a frame: not {WHAT}")));
            };
            if error {
                continue;
            }
            let bytes = if remote { vec![0; dlc] } else { data };
            let Some(frame) = frame(id, extended, remote, &bytes) else {
                return Err(self.0.error(
                    name,
                    format!("the row is not a classic CAN frame: not {WHAT}"),
                ));
            };
            return Ok(Some(Entry {
                t_ns: Some(t_ns),
                frame,
            }));
        }
    }
}
