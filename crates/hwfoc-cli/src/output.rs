//! Where a command's text output goes: standard output or a file, with errors that name it.

use std::fs::File;
use std::io::{self, Write};

use crate::error::CliError;
use hwfoc_io::write::WriteError;

/// A text sink: standard output or a file, opened. Text is handed over in whole buffers, so
/// nothing is lost to a later error: whatever was produced before it is written and flushed
/// first.
pub struct TextSink {
    name: String,
    sink: Box<dyn Write>,
}

impl TextSink {
    /// Standard output, or the file at `path` (created or truncated).
    pub fn create(path: Option<&str>) -> Result<TextSink, CliError> {
        match path {
            None | Some("-") => Ok(TextSink {
                name: "standard output".to_string(),
                sink: Box::new(io::stdout().lock()),
            }),
            Some(path) => {
                let file = File::create(path).map_err(|source| WriteError::Write {
                    output: path.to_string(),
                    source,
                })?;
                Ok(TextSink {
                    name: path.to_string(),
                    sink: Box::new(file),
                })
            }
        }
    }

    /// Writes `buf` and empties it.
    pub fn write(&mut self, buf: &mut Vec<u8>) -> Result<(), CliError> {
        let result = self.sink.write_all(buf);
        buf.clear();
        result.map_err(|source| self.error(source))
    }

    /// Pushes everything written so far to the operating system.
    pub fn flush(&mut self) -> Result<(), CliError> {
        self.sink.flush().map_err(|source| self.error(source))
    }

    fn error(&self, source: io::Error) -> CliError {
        WriteError::Write {
            output: self.name.clone(),
            source,
        }
        .into()
    }
}
