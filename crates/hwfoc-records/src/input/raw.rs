//! Raw bytes as they came off the wire: no timing, one stream.

use std::io::Read;

use super::{BATCH, BlockRead, InputError, InputFormat, Looks, ReadAt, Source, looks, read_some};
use crate::notice::Notice;
use crate::time::Clock;

impl InputFormat {
    /// Raw bytes from the wire: one stream, no receive times.
    pub const RAW: InputFormat = InputFormat {
        name: "raw bytes",
        short_name: "raw",
        clock: Clock::None,
        live: false,
        recorded_ports: false,
    };
}

/// What raw bytes are read from.
pub(super) enum Reader {
    /// Any reader, read in turn.
    Plain(Box<dyn Read>),
    /// A regular file read ahead.
    Ahead(Box<dyn BlockRead>),
}

/// A raw input being read.
pub(super) struct RawReader {
    reader: Reader,
    /// Bytes read during format detection, handed out first.
    pending: Vec<u8>,
    /// The first bytes (up to [`looks::SAMPLE`]), to say what they look like if they hold no
    /// frame.
    sample: Vec<u8>,
    /// A second handle on a regular file read, for positional reads of a later part.
    file: Option<Box<dyn ReadAt>>,
    /// The bytes read so far while every one was zero; `None` once one was not.
    zeros: Option<u64>,
}

impl RawReader {
    /// Reads `reader` (a regular file when `file`, a second handle on it, is given), after
    /// `head`, the bytes format detection read of it.
    pub(super) fn new(reader: Reader, file: Option<Box<dyn ReadAt>>, head: Vec<u8>) -> RawReader {
        RawReader {
            reader,
            pending: head,
            sample: Vec::new(),
            file,
            zeros: Some(0),
        }
    }
}

impl Source for RawReader {
    fn format(&self) -> InputFormat {
        InputFormat::RAW
    }

    fn fill(
        &mut self,
        name: &str,
        bytes: &mut Vec<u8>,
        _times: &mut Vec<f64>,
        _notices: &mut dyn FnMut(Notice),
    ) -> Result<usize, InputError> {
        if !self.pending.is_empty() {
            std::mem::swap(bytes, &mut self.pending);
            self.pending.clear();
        } else {
            let read = match &mut self.reader {
                Reader::Plain(reader) => {
                    // The buffer keeps its length from the last read: only bytes never read
                    // into are zeroed here (zeroing all of it every time cost more than the
                    // read).
                    bytes.resize(BATCH, 0);
                    read_some(reader, bytes)
                }
                Reader::Ahead(ahead) => ahead.read(bytes),
            };
            match read {
                Ok(n) => bytes.truncate(n),
                Err(source) => {
                    bytes.clear();
                    return Err(InputError::Read {
                        input: name.to_string(),
                        source,
                    });
                }
            }
        }
        if let Some(zeros) = &mut self.zeros {
            if bytes.iter().all(|&b| b == 0) {
                *zeros += bytes.len() as u64;
                // An endless device of zeros (`/dev/zero`) would be read for ever.
                if *zeros >= super::ONLY_ZEROS_LIMIT {
                    return Err(InputError::OnlyZeros {
                        input: name.to_string(),
                        bytes: *zeros,
                    });
                }
            } else {
                self.zeros = None;
            }
        }
        let room = looks::SAMPLE.saturating_sub(self.sample.len());
        self.sample
            .extend_from_slice(&bytes[..room.min(bytes.len())]);
        Ok(0)
    }

    fn streams(&self) -> usize {
        1
    }

    fn stream_name(&self, _: usize) -> Option<&str> {
        None
    }

    fn flagged_bytes(&self) -> u64 {
        // Nothing between the wire and the file flags bytes.
        0
    }

    fn looks(&self) -> Option<Looks> {
        Looks::of(&self.sample)
    }

    fn file(&self) -> Option<&dyn ReadAt> {
        self.file.as_deref()
    }
}
