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
//! Each row is converted under its ESC's settings, those that [`Sources`](crate::Sources) hands to
//! [`Handler::frame`](crate::Handler::frame) with its frames: the export learns them at an ESC's
//! first frame, and a chunk carries a table of them (`EscTable`) only when some ESC's settings
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
//! ([`create_file`], [`FileId`]); `metadata.rs`, what every export records (settings as JSON among it); `error.rs`, the errors
//! ([`WriteError`], [`ExportError`]); here, the formats.

pub mod arrow;
mod error;
mod export;
mod file;
pub mod metadata;
pub(crate) mod parquet;
mod safety;
mod staging;
pub(crate) mod stored;
mod text;

pub use error::{ExportError, WriteError};
pub use export::Export;
#[cfg(feature = "parquet")]
pub(crate) use export::Frames;
pub(crate) use export::{Chunk, EscTable, Sink, ToWriter};
pub(crate) use metadata::esc_settings_json;
pub use safety::{FileId, create_file, same_file};
pub use staging::Staging;

use hwfoc::Settings;

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

impl OutputFormat {
    /// Each format's file name extensions, the first its usual one.
    pub const EXTENSIONS: [(OutputFormat, &'static [&'static str]); 3] = [
        (OutputFormat::Jsonl, &["jsonl", "ndjson"]),
        (OutputFormat::Csv, &["csv"]),
        (OutputFormat::Parquet, &["parquet"]),
    ];

    /// The format a file name's extension names (in any case), if any.
    pub fn from_name(name: &str) -> Option<OutputFormat> {
        let ext = std::path::Path::new(name).extension()?.to_str()?;
        Self::EXTENSIONS
            .iter()
            .find(|(_, exts)| exts.iter().any(|e| ext.eq_ignore_ascii_case(e)))
            .map(|&(format, _)| format)
    }

    /// The format's usual extension, without its dot (`csv`).
    pub fn extension(self) -> &'static str {
        Self::EXTENSIONS
            .iter()
            .find(|&&(format, _)| format == self)
            .map_or("", |(_, exts)| exts[0])
    }
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
    /// CSV only: receive times as ISO 8601 dates in UTC, to the microsecond, in a `time`
    /// column ([`time::iso8601_us`](crate::time::iso8601_us)), rather than Unix seconds in `t_s`.
    pub csv_time_iso: bool,
}
