//! A logic-analyser CSV export as an input: one row per byte, its time in the first column.

use std::io::{self, BufRead, BufReader, Read};

use super::{InputError, InputFormat, Looks, Source};
use crate::notice::Notice;
use crate::time::Clock;

/// How many CSV rows make one batch.
pub(super) const CSV_BATCH_ROWS: usize = 1 << 16;

/// The rows of a logic-analyser CSV after its header line.
pub(super) struct CsvRows {
    reader: BufReader<Box<dyn Read>>,
    value_col: usize,
    /// Whether each column is a parity or framing error flag.
    error_cols: Vec<bool>,
    /// Number of the last line read (1-based; the header is line 1).
    line: u64,
    row: Vec<u8>,
    /// Rows flagged with a parity or framing error.
    flagged: u64,
}

/// Whether `head`, the first line (or the first bytes of it) of an input, is the header of a
/// logic-analyser export: a first column `Time...` and a column `Value`.
pub(super) fn is_header(head: &[u8]) -> bool {
    let first = header_columns(&String::from_utf8_lossy(head));
    first[0].starts_with("time") && first.iter().any(|c| c == "value")
}

impl CsvRows {
    /// Rows flagged with a parity or framing error so far.
    pub(super) fn flagged(&self) -> u64 {
        self.flagged
    }

    /// The rows after the header, of which `head` holds the beginning (the rest of the header
    /// line is read from `reader`).
    pub(super) fn open(
        name: &str,
        mut reader: BufReader<Box<dyn Read>>,
        mut head: Vec<u8>,
    ) -> Result<CsvRows, InputError> {
        if head.last() != Some(&b'\n') {
            read_line(&mut reader, &mut head).map_err(|source| InputError::Read {
                input: name.to_string(),
                source,
            })?;
            if head.last() != Some(&b'\n') && head.len() > MAX_LINE {
                return Err(InputError::Csv {
                    input: name.to_string(),
                    line: 1,
                    message: format!(
                        "the header line is longer than {MAX_LINE} bytes: not a \
                         logic-analyser export"
                    ),
                });
            }
        }
        let header = header_columns(&String::from_utf8_lossy(&head));
        Ok(CsvRows {
            reader,
            value_col: header.iter().position(|c| c == "value").unwrap_or(1),
            error_cols: header.iter().map(|c| c.contains("error")).collect(),
            line: 1,
            row: Vec::new(),
            flagged: 0,
        })
    }

    /// Reads rows into `bytes` and `times` until a batch is full or the input ends. On an error,
    /// the rows before it stay in `bytes` and `times`.
    pub(super) fn read(
        &mut self,
        name: &str,
        bytes: &mut Vec<u8>,
        times: &mut Vec<f64>,
    ) -> Result<(), InputError> {
        let CsvRows {
            reader,
            value_col,
            error_cols,
            line,
            row,
            flagged,
        } = self;
        let value_col = *value_col;
        while bytes.len() < CSV_BATCH_ROWS {
            row.clear();
            let n = read_line(reader, row).map_err(|source| InputError::Read {
                input: name.to_string(),
                source,
            })?;
            if n == 0 {
                break;
            }
            *line += 1;
            let bad = |message: String| InputError::Csv {
                input: name.to_string(),
                line: *line,
                message,
            };
            if row.last() != Some(&b'\n') && row.len() > MAX_LINE {
                return Err(bad(format!(
                    "the line is longer than {MAX_LINE} bytes: not a logic-analyser export"
                )));
            }
            let text = std::str::from_utf8(row)
                .map_err(|_| bad("not valid UTF-8 text".to_string()))?
                .trim_end_matches(['\n', '\r']);
            if text.trim().is_empty() {
                continue; // a blank line
            }
            // One pass over the fields, whatever their number.
            let (mut time, mut value, mut flag) = (None, None, false);
            for (i, field) in text.split(',').enumerate() {
                let field = unquote(field);
                if i == 0 {
                    time = Some(field);
                }
                if i == value_col {
                    value = Some(field);
                }
                flag |= !field.is_empty() && error_cols.get(i).copied().unwrap_or(false);
            }
            let time = time
                .and_then(|t| t.parse::<f64>().ok())
                .filter(|t| t.is_finite())
                .ok_or_else(|| bad(format!("bad time {}", field_text(time))))?;
            let value = value.and_then(parse_byte).ok_or_else(|| {
                bad(format!(
                    "bad byte value {} (expected 0x00..0xFF or 0..255)",
                    field_text(value)
                ))
            })?;
            if flag {
                *flagged += 1;
            }
            bytes.push(value);
            times.push(time);
        }
        Ok(())
    }
}

/// Whether `head`, the first bytes of an input, can still be the start of a CSV header line
/// (which begins with "Time", possibly after a UTF-8 byte-order mark).
pub(super) fn may_be_header(head: &[u8]) -> bool {
    const BOM: &[u8] = b"\xEF\xBB\xBF";
    if head.len() < BOM.len() && BOM.starts_with(head) {
        return true;
    }
    let body = head.strip_prefix(BOM).unwrap_or(head);
    body.first().is_none_or(|b| b.eq_ignore_ascii_case(&b'T'))
}

/// The lower-cased, trimmed column names of a CSV header line.
pub(super) fn header_columns(line: &str) -> Vec<String> {
    line.trim_start_matches('\u{FEFF}')
        .trim_end()
        .split(',')
        .map(|c| unquote(c).to_ascii_lowercase())
        .collect()
}

/// A CSV field without surrounding blanks and quotes.
pub(super) fn unquote(field: &str) -> &str {
    let f = field.trim();
    f.strip_prefix('"')
        .and_then(|f| f.strip_suffix('"'))
        .unwrap_or(f)
        .trim()
}

/// A byte value as a logic analyser exports it: `0x9B`, `0X9b` or `155`.
pub(super) fn parse_byte(text: &str) -> Option<u8> {
    match text.strip_prefix("0x").or_else(|| text.strip_prefix("0X")) {
        Some(hex) if !hex.is_empty() && hex.len() <= 2 => u8::from_str_radix(hex, 16).ok(),
        Some(_) => None,
        None => text.parse().ok(),
    }
}

/// A CSV field quoted for an error message, cut after [`QUOTED`] characters.
pub(super) fn field_text(field: Option<&str>) -> String {
    match field {
        None => "(missing)".to_string(),
        Some(f) if f.chars().count() > QUOTED => {
            let cut: String = f.chars().take(QUOTED).collect();
            format!("{cut:?}... ({} bytes)", f.len())
        }
        Some(f) => format!("{f:?}"),
    }
}

/// Characters of a field quoted in an error message, at most.
const QUOTED: usize = 40;

/// Longest line of a logic-analyser CSV (a real one is under 100 bytes): a longer one is an
/// error rather than memory for whatever the file holds.
pub(super) const MAX_LINE: usize = 64 << 10;

/// Reads a line into `row` (which is empty), newline included, but no more than
/// [`MAX_LINE`] + 1 bytes: a longer line is left cut, without its newline.
pub(super) fn read_line(reader: &mut impl BufRead, row: &mut Vec<u8>) -> io::Result<usize> {
    reader.take(MAX_LINE as u64 + 1).read_until(b'\n', row)
}

impl InputFormat {
    /// A logic-analyser CSV export, one row per byte: one stream, times of the capture's clock.
    pub const ANALYZER_CSV: InputFormat = InputFormat {
        name: "logic-analyser CSV",
        short_name: "csv",
        clock: Clock::Capture,
        live: false,
        recorded_ports: false,
    };
}

impl Source for CsvRows {
    fn format(&self) -> InputFormat {
        InputFormat::ANALYZER_CSV
    }

    fn fill(
        &mut self,
        name: &str,
        bytes: &mut Vec<u8>,
        times: &mut Vec<f64>,
        _notices: &mut dyn FnMut(Notice),
    ) -> Result<usize, InputError> {
        bytes.clear();
        self.read(name, bytes, times).map(|()| 0)
    }

    fn streams(&self) -> usize {
        1
    }

    fn stream_name(&self, _: usize) -> Option<&str> {
        None
    }

    fn flagged_bytes(&self) -> u64 {
        self.flagged()
    }

    fn looks(&self) -> Option<Looks> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_values_in_hex_and_decimal() {
        assert_eq!(parse_byte("0x9B"), Some(0x9B));
        assert_eq!(parse_byte("0X0a"), Some(0x0A));
        assert_eq!(parse_byte("155"), Some(155));
        assert_eq!(parse_byte("0x"), None);
        assert_eq!(parse_byte("0x100"), None);
        assert_eq!(parse_byte("256"), None);
        assert_eq!(parse_byte("zz"), None);
    }
}
