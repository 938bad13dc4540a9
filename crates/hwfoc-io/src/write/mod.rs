//! Writing records to a file or standard output: JSON Lines, CSV or Parquet.
//!
//! The command's thread decodes and collects frames, as received, in `Chunk`s; writer
//! threads turn them into the output format and write them, so decoding and encoding run side
//! by side (text: two formatting threads and a writing one, see `text.rs`; Parquet: a writer
//! thread that encodes the columns of each row group with a helper, see `parquet.rs`). Queues
//! between the threads are short (`QUEUE` chunks of about `CHUNK_ROWS` rows for text, one
//! row group for Parquet), so memory stays bounded whatever the size of the input: about 45 MB
//! at most (with the output file's two 4 MiB blocks).
//!
//! Each row is converted under its ESC's settings, those that [`Sources`](crate::sources::Sources)
//! hands to [`Handler::frame`](crate::handler::Handler::frame) with its frames: the export learns them at an ESC's first
//! frame, and a chunk carries a table of them (`EscTable`) only when some ESC's settings
//! differ from [`Provenance::settings`]; otherwise (the usual case) every row of the chunk is
//! converted under those.
//!
//! An output file is written by a thread of its own, a block at a time, and past its first
//! megabytes with direct I/O, bypassing the page cache (see `file.rs`).
//!
//! Nothing already produced is lost to an error: on an input error the command finishes the
//! export normally (text flushed, the Parquet file closed with its footer, so it is readable)
//! before reporting it; on an output error the writers stop and the error names the output.
//!
//! Modules: `export.rs`, the pipeline ([`Export`] and its chunks of frames); `text.rs`,
//! `arrow.rs`, `parquet.rs`, the writers; `staging.rs`, a new file renamed over its target when
//! complete; `file.rs`, the output file's own thread; `safety.rs`, which files may be written
//! ([`create_file`], [`FileId`]); `json.rs`, settings as JSON; here, the formats and the errors.

pub mod arrow;
mod export;
mod file;
mod json;
pub(crate) mod parquet;
mod safety;
mod staging;
mod text;

pub use export::Export;
pub(crate) use export::{Chunk, EscTable, Sink, ToWriter};
pub use json::{esc_settings_json, settings_json};
pub use safety::{FileId, create_file, same_file};
pub use staging::{PARTIAL_SUFFIX, Staging};

use std::fmt;
use std::io;

use hwfoc::Settings;

use crate::input::InputError;
use crate::settings::SettingsPatch;

/// Output formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// JSON Lines.
    Jsonl,
    /// CSV with a header row.
    Csv,
    /// Apache Parquet.
    Parquet,
}

/// What an export records about how it was made (Parquet key-value metadata, the CSV comment).
#[derive(Debug, Clone)]
pub struct Provenance {
    /// The conversion settings of every ESC without settings of its own.
    pub settings: Settings,
    /// The settings configured by port or by ESC, where they differ from `settings`: each
    /// entry's name as the configuration file writes it (`esc.2`, `port."/dev/ttyUSB1"`) and the
    /// fields it sets. For the CSV comment, written before any ESC is found; the settings each
    /// ESC's rows were converted under are in the Parquet metadata (`esc_settings`).
    pub overrides: Vec<(String, SettingsPatch)>,
    /// The inputs, as named on the command line.
    pub inputs: Vec<String>,
    /// The filters applied, as text (`esc=0,2 from=1.5`), empty for none.
    pub filter: String,
    /// CSV only: start with a `#` comment line giving the settings.
    pub csv_comment: bool,
}

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
    /// Ctrl-C or SIGTERM stopped the export before it was complete (see [`Export::stop_on`]).
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
                "{output} exists and is never overwritten unasked: choose another name, or pass \
                 --overwrite"
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
                io::ErrorKind::PermissionDenied => write!(
                    f,
                    "cannot write {output}: permission denied (choose another place with -o)"
                ),
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
