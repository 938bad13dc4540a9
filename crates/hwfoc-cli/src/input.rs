//! Telemetry inputs: where bytes come from, in what format, with what timestamps.
//!
//! Every command reads through [`Input`], which hands out [`Batch`]es of received bytes, each
//! byte with its receive time where the source has one. The format is detected from the first
//! bytes, so a file and the same bytes on standard input behave identically:
//! - a logic-analyser CSV export (`Time [s],Value,Parity Error,Framing Error`, values as `0xNN`
//!   or decimal), whose times become `t_s`;
//! - otherwise raw bytes as they came off the wire (no timing).

use std::fmt;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Cursor, Read};

use crate::error::CliError;

/// How many bytes a raw read asks for, and how many CSV rows make one batch.
const BATCH: usize = 1 << 20;
const CSV_BATCH_ROWS: usize = 1 << 16;

/// The detected format of an input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Raw bytes from the wire.
    Raw,
    /// A logic-analyser CSV export, one row per byte.
    AnalyzerCsv,
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Raw => "raw bytes",
            Format::AnalyzerCsv => "logic-analyser CSV",
        })
    }
}

/// Received bytes and, where the source has a clock, the time each one arrived.
#[derive(Debug, Clone, Copy)]
pub struct Batch<'a> {
    /// The bytes, in arrival order.
    pub bytes: &'a [u8],
    /// Receive time of each byte in seconds (same length as `bytes`), or `None`.
    pub times: Option<&'a [f64]>,
}

enum Source {
    Raw { reader: Box<dyn Read> },
    Csv(CsvRows),
}

/// The rows of a logic-analyser CSV after its header line.
struct CsvRows {
    reader: BufReader<Box<dyn Read>>,
    value_col: usize,
    error_cols: Vec<usize>,
    /// Number of the last line read (1-based; the header is line 1).
    line: u64,
    row: Vec<u8>,
    /// Rows flagged with a parity or framing error.
    flagged: u64,
}

/// One opened input.
pub struct Input {
    name: String,
    format: Format,
    source: Source,
    bytes: Vec<u8>,
    times: Vec<f64>,
    /// Bytes read during format detection, handed out first (raw inputs only).
    pending: Vec<u8>,
    seen_any: bool,
    done: bool,
    /// An error met after some bytes of a batch: reported on the next call, so that the bytes
    /// before it are decoded first.
    deferred: Option<CliError>,
}

impl Input {
    /// Opens a file, or standard input for `-`, and detects its format.
    pub fn open(spec: &str) -> Result<Input, CliError> {
        if spec == "-" {
            return Input::from_reader("standard input", Box::new(io::stdin().lock()));
        }
        let file = File::open(spec).map_err(|source| CliError::Open {
            input: spec.to_string(),
            source,
        })?;
        let meta = file.metadata().map_err(|source| CliError::Open {
            input: spec.to_string(),
            source,
        })?;
        if meta.is_dir() {
            return Err(CliError::IsDirectory {
                input: spec.to_string(),
            });
        }
        Input::from_reader(spec, Box::new(file))
    }

    /// An input over bytes already in memory (the built-in demo stream).
    pub fn from_memory(name: &str, data: Vec<u8>) -> Result<Input, CliError> {
        Input::from_reader(name, Box::new(Cursor::new(data)))
    }

    /// Detects the format from the first bytes of `reader`.
    pub fn from_reader(name: &str, mut reader: Box<dyn Read>) -> Result<Input, CliError> {
        let read_err = |source| CliError::Read {
            input: name.to_string(),
            source,
        };
        // A CSV export starts with its header line ("Time [s],Value,..."); raw telemetry does not
        // start with 'T' (or a UTF-8 byte-order mark). Read no further than needed to decide, so
        // that a live raw stream is not held up.
        let mut head = Vec::new();
        let mut byte = [0u8; 1];
        loop {
            let n = read_some(&mut reader, &mut byte).map_err(read_err)?;
            if n == 0 {
                break;
            }
            head.push(byte[0]);
            if !may_be_header(&head) || byte[0] == b'\n' || head.len() >= 512 {
                break;
            }
        }
        if head.is_empty() {
            return Err(CliError::Empty {
                input: name.to_string(),
            });
        }
        let is_csv = {
            let text = String::from_utf8_lossy(&head);
            let first = header_columns(&text);
            first[0].starts_with("time") && first.iter().any(|c| c == "value")
        };
        let (format, source, pending) = if is_csv {
            let mut reader = BufReader::with_capacity(BATCH, reader);
            if head.last() != Some(&b'\n') {
                reader.read_until(b'\n', &mut head).map_err(read_err)?;
            }
            let header = header_columns(&String::from_utf8_lossy(&head));
            let value_col = header.iter().position(|c| c == "value").unwrap_or(1);
            let error_cols = header
                .iter()
                .enumerate()
                .filter(|(_, c)| c.contains("error"))
                .map(|(i, _)| i)
                .collect();
            let source = Source::Csv(CsvRows {
                reader,
                value_col,
                error_cols,
                line: 1,
                row: Vec::new(),
                flagged: 0,
            });
            (Format::AnalyzerCsv, source, Vec::new())
        } else {
            (Format::Raw, Source::Raw { reader }, head)
        };
        Ok(Input {
            name: name.to_string(),
            format,
            source,
            bytes: Vec::new(),
            times: Vec::new(),
            pending,
            seen_any: false,
            done: false,
            deferred: None,
        })
    }

    /// The input's name as the user gave it.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The detected format.
    pub fn format(&self) -> Format {
        self.format
    }

    /// Bytes the logic analyser flagged with a parity or framing error (passed on all the same:
    /// the frame checksum decides).
    pub fn flagged_bytes(&self) -> u64 {
        match &self.source {
            Source::Csv(rows) => rows.flagged,
            Source::Raw { .. } => 0,
        }
    }

    /// The next batch of bytes, or `None` at the end of the input.
    pub fn next_batch(&mut self) -> Result<Option<Batch<'_>>, CliError> {
        if let Some(e) = self.deferred.take() {
            self.done = true;
            return Err(e);
        }
        if self.done {
            return Ok(None);
        }
        self.bytes.clear();
        self.times.clear();
        match &mut self.source {
            Source::Raw { reader } => {
                if !self.pending.is_empty() {
                    std::mem::swap(&mut self.bytes, &mut self.pending);
                } else {
                    self.bytes.resize(BATCH, 0);
                    let n =
                        read_some(reader, &mut self.bytes).map_err(|source| CliError::Read {
                            input: self.name.clone(),
                            source,
                        })?;
                    self.bytes.truncate(n);
                }
            }
            Source::Csv(rows) => {
                if let Err(e) = rows.read(&self.name, &mut self.bytes, &mut self.times) {
                    if self.bytes.is_empty() {
                        self.done = true;
                        return Err(e);
                    }
                    self.deferred = Some(e);
                }
            }
        }
        if self.bytes.is_empty() {
            self.done = true;
            if !self.seen_any {
                return Err(CliError::Empty {
                    input: self.name.clone(),
                });
            }
            return Ok(None);
        }
        self.seen_any = true;
        let times = match self.format {
            Format::AnalyzerCsv => Some(&self.times[..]),
            Format::Raw => None,
        };
        Ok(Some(Batch {
            bytes: &self.bytes,
            times,
        }))
    }
}

impl CsvRows {
    /// Reads rows into `bytes` and `times` until a batch is full or the input ends. On an error,
    /// the rows before it stay in `bytes` and `times`.
    fn read(
        &mut self,
        name: &str,
        bytes: &mut Vec<u8>,
        times: &mut Vec<f64>,
    ) -> Result<(), CliError> {
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
            let n = reader
                .read_until(b'\n', row)
                .map_err(|source| CliError::Read {
                    input: name.to_string(),
                    source,
                })?;
            if n == 0 {
                break;
            }
            *line += 1;
            let bad = |message: String| CliError::Csv {
                input: name.to_string(),
                line: *line,
                message,
            };
            let text = std::str::from_utf8(row)
                .map_err(|_| bad("not valid UTF-8 text".to_string()))?
                .trim_end_matches(['\n', '\r']);
            if text.trim().is_empty() {
                continue; // a blank line
            }
            let field = |i: usize| text.split(',').nth(i).map(unquote);
            let time = field(0)
                .and_then(|t| t.parse::<f64>().ok())
                .filter(|t| t.is_finite())
                .ok_or_else(|| bad(format!("bad time {}", field_text(field(0)))))?;
            let value = field(value_col).and_then(parse_byte).ok_or_else(|| {
                bad(format!(
                    "bad byte value {} (expected 0x00..0xFF or 0..255)",
                    field_text(field(value_col))
                ))
            })?;
            if error_cols
                .iter()
                .any(|&c| field(c).is_some_and(|f| !f.is_empty()))
            {
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
fn may_be_header(head: &[u8]) -> bool {
    const BOM: &[u8] = b"\xEF\xBB\xBF";
    if head.len() < BOM.len() && BOM.starts_with(head) {
        return true;
    }
    let body = head.strip_prefix(BOM).unwrap_or(head);
    body.first().is_none_or(|b| b.eq_ignore_ascii_case(&b'T'))
}

/// `read` that retries when interrupted by a signal.
fn read_some(reader: &mut dyn Read, buf: &mut [u8]) -> io::Result<usize> {
    loop {
        match reader.read(buf) {
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            other => return other,
        }
    }
}

/// The lower-cased, trimmed column names of a CSV header line.
fn header_columns(line: &str) -> Vec<String> {
    line.trim_start_matches('\u{FEFF}')
        .trim_end()
        .split(',')
        .map(|c| unquote(c).to_ascii_lowercase())
        .collect()
}

/// A CSV field without surrounding blanks and quotes.
fn unquote(field: &str) -> &str {
    let f = field.trim();
    f.strip_prefix('"')
        .and_then(|f| f.strip_suffix('"'))
        .unwrap_or(f)
        .trim()
}

/// A byte value as a logic analyser exports it: `0x9B`, `0X9b` or `155`.
fn parse_byte(text: &str) -> Option<u8> {
    match text.strip_prefix("0x").or_else(|| text.strip_prefix("0X")) {
        Some(hex) if !hex.is_empty() && hex.len() <= 2 => u8::from_str_radix(hex, 16).ok(),
        Some(_) => None,
        None => text.parse().ok(),
    }
}

/// A CSV field quoted for an error message.
fn field_text(field: Option<&str>) -> String {
    match field {
        None => "(missing)".to_string(),
        Some(f) => format!("{f:?}"),
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

    fn read_all(input: &mut Input) -> (Vec<u8>, Option<Vec<f64>>) {
        let (mut bytes, mut times) = (Vec::new(), None::<Vec<f64>>);
        while let Some(b) = input.next_batch().unwrap() {
            bytes.extend_from_slice(b.bytes);
            if let Some(t) = b.times {
                times.get_or_insert_with(Vec::new).extend_from_slice(t);
            }
        }
        (bytes, times)
    }

    #[test]
    fn detects_csv_and_raw() {
        let csv = b"Time [s],Value,Parity Error,Framing Error\n0.5,0x9B,,\n0.75,0x16,,x\n".to_vec();
        let mut input = Input::from_memory("a.csv", csv).unwrap();
        assert_eq!(input.format(), Format::AnalyzerCsv);
        assert_eq!(
            read_all(&mut input),
            (vec![0x9B, 0x16], Some(vec![0.5, 0.75]))
        );
        assert_eq!(input.flagged_bytes(), 1);

        let raw = b"\x9B\x16\x01Time".to_vec();
        let mut input = Input::from_memory("a.bin", raw.clone()).unwrap();
        assert_eq!(input.format(), Format::Raw);
        assert_eq!(read_all(&mut input), (raw, None));

        // Text that is not a logic-analyser export is raw bytes too.
        let input = Input::from_memory("t", b"Tea,time\n".to_vec()).unwrap();
        assert_eq!(input.format(), Format::Raw);
    }

    #[test]
    fn bad_csv_row_names_its_line() {
        let csv = b"Time [s],Value\r\n0.5,0x9B\r\n0.6,\"0x9B\"\r\n\r\n0.7,nope\r\n".to_vec();
        let mut input = Input::from_memory("cap.csv", csv).unwrap();
        let err = loop {
            match input.next_batch() {
                Ok(Some(_)) => {}
                Ok(None) => panic!("no error"),
                Err(e) => break e,
            }
        };
        assert_eq!(
            err.to_string(),
            "cap.csv:5: bad byte value \"nope\" (expected 0x00..0xFF or 0..255)"
        );
    }

    #[test]
    fn empty_inputs_are_errors() {
        let e = Input::from_memory("x", Vec::new()).err().unwrap();
        assert_eq!(e.to_string(), "x is empty: there is nothing to decode");
        let mut input = Input::from_memory("h.csv", b"Time [s],Value\n".to_vec()).unwrap();
        assert!(matches!(input.next_batch(), Err(CliError::Empty { .. })));
    }
}
