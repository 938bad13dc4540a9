//! Writing records to a file or standard output: JSON Lines, CSV or Parquet.
//!
//! The command's thread decodes and collects frames, as received, in [`Chunk`]s; writer
//! threads turn them into the output format and write them, so decoding and encoding run side
//! by side (text: two formatting threads and a writing one, see `text.rs`; Parquet: a writer
//! thread that encodes the columns of each row group with a helper, see `parquet.rs`). Queues
//! between the threads are short (`QUEUE` chunks of about [`CHUNK_ROWS`] rows for text, one
//! row group for Parquet), so memory stays bounded whatever the size of the input: about 45 MB
//! at most (with the output file's two 4 MiB blocks).
//!
//! An output file is written by a thread of its own, a block at a time, and past its first
//! megabytes with direct I/O, bypassing the page cache (see `file.rs`).
//!
//! Nothing already produced is lost to an error: on an input error the command finishes the
//! export normally (text flushed, the Parquet file closed with its footer, so it is readable)
//! before reporting it; on an output error the writers stop and the error names the output.

pub mod arrow;
mod file;
pub(crate) mod parquet;
mod text;

use std::fmt;
use std::fs::File;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use hwfoc::{DataFrame, Decoded, Frame, Settings};

use crate::handler::Handler;
use crate::input::InputError;
use crate::select::Selection;

/// Rows per chunk handed to the writer thread (a chunk may exceed it by one input batch).
pub const CHUNK_ROWS: usize = 1 << 16;

/// Chunks of text waiting for the writer thread, at most.
const QUEUE: usize = 2;

/// Parquet row groups waiting for the writer thread, at most (a row group's frames take about
/// 5 MB, its columns as much again while they are encoded).
const PARQUET_QUEUE: usize = 1;

/// Room for a Parquet row group's frames: a row group closes at the end of the input batch
/// that fills it.
const PARQUET_ROWS: usize = parquet::ROW_GROUP_ROWS + CHUNK_ROWS;

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
    /// The conversion settings.
    pub settings: Settings,
    /// The inputs, as named on the command line.
    pub inputs: Vec<String>,
    /// The filters applied, as text (`esc=0,2 from=1.5`), empty for none.
    pub filter: String,
    /// CSV only: start with a `#` comment line giving the settings.
    pub csv_comment: bool,
}

/// Frames on their way to the writer: column by column, as received.
#[derive(Debug, Default)]
pub struct Chunk {
    /// Receive time of each frame's first byte, s; NaN for none.
    pub t: Vec<f64>,
    /// ESC index of each frame.
    pub esc: Vec<u8>,
    /// The frames.
    pub frames: Vec<DataFrame>,
    /// Whether the writer should push everything to the operating system after this chunk
    /// (live input: records appear as frames arrive).
    pub flush: bool,
}

impl Chunk {
    fn with_capacity(n: usize) -> Chunk {
        Chunk {
            t: Vec::with_capacity(n),
            esc: Vec::with_capacity(n),
            frames: Vec::with_capacity(n),
            flush: false,
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    fn clear(&mut self) {
        self.t.clear();
        self.esc.clear();
        self.frames.clear();
        self.flush = false;
    }
}

/// A message to the writer thread.
enum ToWriter {
    /// Rows to write: some text, or a Parquet row group.
    Rows(Chunk),
    /// The end: metadata known only now (the ESCs found), as key-value pairs.
    End(#[cfg_attr(not(feature = "parquet"), allow(dead_code))] Vec<(String, String)>),
}

/// An export in progress.
pub struct Export {
    chunk: Chunk,
    tx: Option<SyncSender<ToWriter>>,
    worker: Option<JoinHandle<Result<(), WriteError>>>,
    mode: Pipeline,
    selection: Selection,
    /// Records written.
    kept: u64,
    /// Earliest and latest `t_s` of the selected ESCs' data frames, in the window or not.
    span: Option<(f64, f64)>,
    /// The output file while it is written under its partial name.
    staged: Option<Staged>,
}

/// What the decoding thread prepares for the writer.
enum Pipeline {
    /// Text: chunks of frames, formatted by the writer. Chunks it is done with come back.
    Text { spare: Receiver<Chunk> },
    /// Parquet: a row group's frames at a time, converted, encoded and written by the writer.
    /// Chunks it is done with come back.
    Parquet { spare: Receiver<Chunk> },
}

/// Where the output goes.
pub(crate) struct Destination {
    /// The output as named on the command line, or "standard output".
    pub name: String,
    /// The open file or standard output.
    pub writer: Box<dyn Write + Send>,
}

/// A file written under a temporary name beside its final one, renamed into place when
/// complete: an export cut short (killed, or the machine lost) leaves the earlier file at the
/// path untouched, and at most the clearly named partial file.
#[derive(Debug, Clone)]
struct Staged {
    partial: PathBuf,
    path: PathBuf,
}

/// The suffix of an export's file while it is being written.
pub const PARTIAL_SUFFIX: &str = ".partial";

impl Destination {
    /// Opens the output: standard output for `None` or `-`; a new or regular file under its
    /// partial name (returned, to be renamed once complete); anything else (a device such as
    /// `/dev/null`, a pipe) as it is.
    fn open(path: Option<&str>) -> Result<(Destination, Option<Staged>), WriteError> {
        let Some(path) = path.filter(|&p| p != "-") else {
            let stdout = Destination {
                name: "standard output".to_string(),
                writer: Box::new(io::stdout()),
            };
            return Ok((stdout, None));
        };
        let create = |target: &Path| {
            File::create(target).map_err(|source| WriteError::Create {
                output: path.to_string(),
                source,
            })
        };
        let special = std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir());
        let (file, staged) = if special {
            (create(Path::new(path))?, None)
        } else {
            if Path::new(path).is_dir() {
                return Err(WriteError::Create {
                    output: path.to_string(),
                    source: io::ErrorKind::IsADirectory.into(),
                });
            }
            // Through a link, the file it points to is replaced, not the link.
            let target = match std::fs::symlink_metadata(path) {
                Ok(m) if m.file_type().is_symlink() => {
                    std::fs::canonicalize(path).unwrap_or_else(|_| PathBuf::from(path))
                }
                _ => PathBuf::from(path),
            };
            let mut partial = target.clone().into_os_string();
            partial.push(PARTIAL_SUFFIX);
            let staged = Staged {
                partial: PathBuf::from(partial),
                path: target,
            };
            (create(&staged.partial)?, Some(staged))
        };
        let destination = Destination {
            name: path.to_string(),
            writer: Box::new(file::OutputFile::new(file)),
        };
        Ok((destination, staged))
    }

    /// A write error, naming the output.
    pub fn error(&self, source: io::Error) -> WriteError {
        WriteError::Write {
            output: self.name.clone(),
            source,
        }
    }
}

impl Export {
    /// Creates the output (standard output for `None` or `-`) and starts the writer thread.
    pub fn create(
        format: OutputFormat,
        path: Option<&str>,
        provenance: Provenance,
    ) -> Result<Export, WriteError> {
        let (sink, staged) = Destination::open(path)?;
        type Work = Box<dyn FnOnce() -> Result<(), WriteError> + Send>;
        let (tx, mode, work): (SyncSender<ToWriter>, Pipeline, Work) = match format {
            OutputFormat::Jsonl | OutputFormat::Csv => {
                let (tx, rx) = sync_channel::<ToWriter>(QUEUE);
                let (spare_tx, spare) = sync_channel::<Chunk>(QUEUE + 2);
                let csv = format == OutputFormat::Csv;
                (
                    tx,
                    Pipeline::Text { spare },
                    Box::new(move || text::write(csv, sink, &provenance, rx, spare_tx)),
                )
            }
            OutputFormat::Parquet => {
                let (tx, rx) = sync_channel::<ToWriter>(PARQUET_QUEUE);
                let (spare_tx, spare) = sync_channel::<Chunk>(PARQUET_QUEUE + 2);
                (
                    tx,
                    Pipeline::Parquet { spare },
                    Box::new(move || parquet::write(sink, &provenance, rx, spare_tx)),
                )
            }
        };
        let worker = std::thread::Builder::new()
            .name("hwfoc-writer".to_string())
            .spawn(work)
            .map_err(|source| WriteError::Write {
                output: path.unwrap_or("standard output").to_string(),
                source,
            })?;
        let rows = match mode {
            Pipeline::Text { .. } => CHUNK_ROWS,
            Pipeline::Parquet { .. } => PARQUET_ROWS,
        };
        Ok(Export {
            chunk: Chunk::with_capacity(rows),
            tx: Some(tx),
            worker: Some(worker),
            mode,
            selection: Selection::default(),
            kept: 0,
            span: None,
            staged,
        })
    }

    /// Keeps only the records of `selection` when the export is a [`Handler`] (every record
    /// otherwise).
    pub fn select(mut self, selection: Selection) -> Export {
        self.selection = selection;
        self
    }

    /// Records written so far.
    pub fn kept(&self) -> u64 {
        self.kept
    }

    /// The earliest and latest receive time of the selected ESCs' data frames, whether in the
    /// selection's time window or not (to tell a user whose window held no frame what times
    /// the frames have).
    pub fn span(&self) -> Option<(f64, f64)> {
        self.span
    }

    /// Adds a record: a data frame, its ESC and its receive time.
    #[inline]
    pub fn push(&mut self, esc: u8, t: Option<f64>, frame: &DataFrame) {
        self.chunk.t.push(t.unwrap_or(f64::NAN));
        self.chunk.esc.push(esc);
        self.chunk.frames.push(*frame);
    }

    /// Hands the rows collected so far to the writer once there are enough of them, or at once
    /// when `live` (the rows are then written and flushed without waiting for more).
    pub fn end_batch(&mut self, live: bool) -> Result<(), WriteError> {
        if self.chunk.len() >= CHUNK_ROWS || (live && !self.chunk.is_empty()) {
            self.send(live, false)?;
        }
        Ok(())
    }

    /// Hands the current chunk on; `flush`: text is to reach the output at once; `last`: the
    /// end of the export.
    fn send(&mut self, flush: bool, last: bool) -> Result<(), WriteError> {
        let msg = match &mut self.mode {
            Pipeline::Text { spare } => {
                let next = match spare.try_recv() {
                    Ok(mut c) => {
                        c.clear();
                        c
                    }
                    Err(_) => Chunk::with_capacity(CHUNK_ROWS),
                };
                let mut chunk = std::mem::replace(&mut self.chunk, next);
                chunk.flush = flush;
                ToWriter::Rows(chunk)
            }
            Pipeline::Parquet { spare } => {
                // A Parquet file is readable only once closed (its footer comes last), so live
                // input gains nothing from early writes: rows gather into full row groups.
                if self.chunk.is_empty() || (self.chunk.len() < parquet::ROW_GROUP_ROWS && !last) {
                    return Ok(());
                }
                let next = match spare.try_recv() {
                    Ok(mut c) => {
                        c.clear();
                        c
                    }
                    Err(_) => Chunk::with_capacity(PARQUET_ROWS),
                };
                ToWriter::Rows(std::mem::replace(&mut self.chunk, next))
            }
        };
        self.post(msg)
    }

    fn post(&mut self, msg: ToWriter) -> Result<(), WriteError> {
        let sent = self.tx.as_ref().is_some_and(|tx| tx.send(msg).is_ok());
        if sent {
            Ok(())
        } else {
            // The writer has stopped: its error says why.
            self.tx = None;
            Err(self.join().err().unwrap_or_else(|| WriteError::Write {
                output: "the output".to_string(),
                source: io::Error::other("the writer stopped"),
            }))
        }
    }

    /// Writes the remaining rows and ends the output: flushes text, closes a Parquet file
    /// (adding `metadata` to its key-value metadata), and renames a file written under its
    /// partial name into place. On a write error the partial file is removed.
    pub fn finish(mut self, metadata: Vec<(String, String)>) -> Result<(), WriteError> {
        let written = self
            .send(true, true)
            .and_then(|()| self.post(ToWriter::End(metadata)))
            .and_then(|()| {
                self.tx = None;
                self.join()
            });
        let Some(staged) = self.staged.take() else {
            return written;
        };
        if written.is_err() {
            let _ = std::fs::remove_file(&staged.partial);
            return written;
        }
        std::fs::rename(&staged.partial, &staged.path).map_err(|source| WriteError::Write {
            output: staged.path.display().to_string(),
            source,
        })
    }

    fn join(&mut self) -> Result<(), WriteError> {
        match self.worker.take() {
            Some(worker) => worker.join().unwrap_or_else(|_| {
                Err(WriteError::Write {
                    output: "the output".to_string(),
                    source: io::Error::other("the writer thread failed"),
                })
            }),
            None => Ok(()),
        }
    }
}

/// An export is what `hwfoc decode` hands the frames to: it takes them as decoded, and its
/// writers convert them a block at a time on their own threads.
impl Handler for Export {
    type Error = ExportError;

    #[inline]
    fn frame(&mut self, esc: u8, t: Option<f64>, decoded: &Decoded, _: &Settings) {
        if let Frame::Data(frame) = decoded.frame {
            // The first frame of any ESC resolves a window given after the first frame.
            self.selection.window.observe(t);
            if !self.selection.esc(esc) {
                return;
            }
            if let Some(t) = t {
                let (first, last) = self.span.get_or_insert((t, t));
                *first = first.min(t);
                *last = last.max(t);
            }
            if self.selection.window.contains(t) {
                self.push(esc, t, &frame);
                self.kept += 1;
            }
        }
    }

    fn end_batch(&mut self, live: bool) -> Result<(), ExportError> {
        Ok(Export::end_batch(self, live)?)
    }
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

impl Drop for Export {
    fn drop(&mut self) {
        // Dropped without `finish` (an error elsewhere): let the writer end what it has.
        self.tx = None;
        let _ = self.join();
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
    /// The output is one of the inputs (the same file, by whatever path): writing it would
    /// destroy the input.
    IsInput {
        /// The output as named on the command line.
        output: String,
        /// The input it is, as named on the command line.
        input: String,
    },
}

/// Refuses an output file that is one of `inputs` (the same file, by device and inode: the
/// same path, `./` before it, a link to it), before anything is opened for writing.
pub fn refuse_input<'a>(
    output: &str,
    inputs: impl IntoIterator<Item = &'a str>,
) -> Result<(), WriteError> {
    if output == "-" {
        return Ok(());
    }
    match inputs.into_iter().find(|&input| same_file(output, input)) {
        Some(input) => Err(WriteError::IsInput {
            output: output.to_string(),
            input: input.to_string(),
        }),
        None => Ok(()),
    }
}

/// Whether two paths name one existing file (by device and inode, on Unix).
pub fn same_file(a: &str, b: &str) -> bool {
    let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        ma.dev() == mb.dev() && ma.ino() == mb.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (ma, mb);
        matches!(
            (std::fs::canonicalize(a), std::fs::canonicalize(b)),
            (Ok(x), Ok(y)) if x == y
        )
    }
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
            WriteError::IsInput { output, input } => write!(
                f,
                "cannot write {output}: it is the input {input}, which would be destroyed; \
                 choose another output file"
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
            WriteError::IsInput { .. } => None,
        }
    }
}
