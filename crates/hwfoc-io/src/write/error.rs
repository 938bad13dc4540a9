//! Why an export or a write failed: each error names the output (or the input) at fault.

use std::fmt;
use std::io;

use crate::input::InputError;

/// Why an export stopped: an input it was reading, or its output.
#[derive(Debug)]
pub enum ExportError {
    /// An input could not be read.
    Input(InputError),
    /// The output could not be written.
    Write(WriteError),
}

impl From<InputError> for ExportError {
    fn from(e: InputError) -> Self {
        ExportError::Input(e)
    }
}

impl From<WriteError> for ExportError {
    fn from(e: WriteError) -> Self {
        ExportError::Write(e)
    }
}

impl fmt::Display for ExportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ExportError::Input(e) => e.fmt(f),
            ExportError::Write(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for ExportError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ExportError::Input(e) => Some(e),
            ExportError::Write(e) => Some(e),
        }
    }
}

/// Why records could not be written. Each names the output.
#[derive(Debug)]
pub enum WriteError {
    /// Writing the output failed.
    Write {
        /// Where the output was going.
        output: String,
        /// Why.
        source: io::Error,
    },
    /// An output file could not be created.
    Create {
        /// The file as named on the command line.
        output: String,
        /// Why.
        source: io::Error,
    },
    /// A file of that name exists, and replacing it was not asked for (`--overwrite`).
    Exists {
        /// The file as named.
        output: String,
    },
    /// Ctrl-C or SIGTERM stopped the export before it was complete (see
    /// [`Export::stop_on`](super::Export::stop_on)).
    Interrupted {
        /// The file left as it was, if the output is one.
        output: Option<String>,
    },
}

impl WriteError {
    /// Whether this is the reader of the output going away (`hwfoc decode … | head`): not an
    /// error worth reporting.
    pub fn is_broken_pipe(&self) -> bool {
        matches!(self, WriteError::Write { source, .. } if source.kind() == io::ErrorKind::BrokenPipe)
    }
}

impl fmt::Display for WriteError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WriteError::Write { output, source } => write!(f, "cannot write {output}: {source}"),
            WriteError::Exists { output } => write!(
                f,
                "{output} exists and is never overwritten unasked: choose another name"
            ),
            WriteError::Interrupted { output: None } => write!(f, "interrupted"),
            WriteError::Interrupted {
                output: Some(output),
            } => write!(
                f,
                "interrupted: {output} is left as it was (the incomplete export is removed)"
            ),
            WriteError::Create { output, source } => match source.kind() {
                io::ErrorKind::NotFound => {
                    let dir = std::path::Path::new(output)
                        .parent()
                        .map(|d| d.display().to_string())
                        .filter(|d| !d.is_empty())
                        .unwrap_or_else(|| ".".to_string());
                    write!(
                        f,
                        "cannot write {output}: the directory {dir} does not exist"
                    )
                }
                io::ErrorKind::PermissionDenied => {
                    write!(f, "cannot write {output}: permission denied")
                }
                io::ErrorKind::IsADirectory => {
                    write!(f, "cannot write {output}: it is a directory, not a file")
                }
                _ => write!(f, "cannot write {output}: {source}"),
            },
        }
    }
}

impl std::error::Error for WriteError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            WriteError::Write { source, .. } | WriteError::Create { source, .. } => Some(source),
            WriteError::Exists { .. } | WriteError::Interrupted { .. } => None,
        }
    }
}
