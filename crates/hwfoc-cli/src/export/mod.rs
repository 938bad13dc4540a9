//! Writing records to a file or standard output: JSON Lines, CSV or Parquet.
//!
//! The command's thread decodes and collects frames, as received, in [`Chunk`]s; writer
//! threads turn them into the output format and write them, so decoding and encoding run side
//! by side (text: two formatting threads and a writing one, see `text.rs`; Parquet: a writer
//! thread that encodes the columns of each row group with a helper, see `parquet.rs`). Queues
//! between the threads are short ([`QUEUE`] chunks of about [`CHUNK_ROWS`] rows for text, one
//! row group for Parquet), so memory stays bounded whatever the size of the input: about 45 MB
//! at most (with the output file's two 4 MiB blocks).
//!
//! An output file is written by a thread of its own, a block at a time, and past its first
//! megabytes with direct I/O, bypassing the page cache (see `file.rs`).
//!
//! Nothing already produced is lost to an error: on an input error the command finishes the
//! export normally (text flushed, the Parquet file closed with its footer, so it is readable)
//! before reporting it; on an output error the writers stop and the error names the output.

mod file;
mod parquet;
mod text;

use std::fs::File;
use std::io::{self, Write};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use hwfoc::{DataFrame, Settings};

use crate::error::CliError;

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
pub enum Format {
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
enum Msg {
    /// Rows to write: some text, or a Parquet row group.
    Rows(Chunk),
    /// The end: metadata known only now (the ESCs found), as key-value pairs.
    End(Vec<(String, String)>),
}

/// An export in progress.
pub struct Export {
    chunk: Chunk,
    tx: Option<SyncSender<Msg>>,
    worker: Option<JoinHandle<Result<(), CliError>>>,
    mode: Mode,
}

/// What the decoding thread prepares for the writer.
enum Mode {
    /// Text: chunks of frames, formatted by the writer. Chunks it is done with come back.
    Text { spare: Receiver<Chunk> },
    /// Parquet: a row group's frames at a time, converted, encoded and written by the writer.
    /// Chunks it is done with come back.
    Parquet { spare: Receiver<Chunk> },
}

/// Where the output goes.
pub(crate) struct Sink {
    /// The output as named on the command line, or "standard output".
    pub name: String,
    /// The open file or standard output.
    pub writer: Box<dyn Write + Send>,
}

impl Sink {
    fn open(path: Option<&str>) -> Result<Sink, CliError> {
        match path {
            None | Some("-") => Ok(Sink {
                name: "standard output".to_string(),
                writer: Box::new(io::stdout()),
            }),
            Some(path) => {
                let file = File::create(path).map_err(|source| CliError::Create {
                    output: path.to_string(),
                    source,
                })?;
                Ok(Sink {
                    name: path.to_string(),
                    writer: Box::new(file::OutputFile::new(file)),
                })
            }
        }
    }

    /// A write error, naming the output.
    pub fn error(&self, source: io::Error) -> CliError {
        CliError::Write {
            output: self.name.clone(),
            source,
        }
    }
}

impl Export {
    /// Creates the output (standard output for `None` or `-`) and starts the writer thread.
    pub fn create(
        format: Format,
        path: Option<&str>,
        provenance: Provenance,
    ) -> Result<Export, CliError> {
        let sink = Sink::open(path)?;
        keep_freed_memory();
        type Work = Box<dyn FnOnce() -> Result<(), CliError> + Send>;
        let (tx, mode, work): (SyncSender<Msg>, Mode, Work) = match format {
            Format::Jsonl | Format::Csv => {
                let (tx, rx) = sync_channel::<Msg>(QUEUE);
                let (spare_tx, spare) = sync_channel::<Chunk>(QUEUE + 2);
                let csv = format == Format::Csv;
                (
                    tx,
                    Mode::Text { spare },
                    Box::new(move || text::write(csv, sink, &provenance, rx, spare_tx)),
                )
            }
            Format::Parquet => {
                let (tx, rx) = sync_channel::<Msg>(PARQUET_QUEUE);
                let (spare_tx, spare) = sync_channel::<Chunk>(PARQUET_QUEUE + 2);
                (
                    tx,
                    Mode::Parquet { spare },
                    Box::new(move || parquet::write(sink, &provenance, rx, spare_tx)),
                )
            }
        };
        let worker = std::thread::Builder::new()
            .name("hwfoc-writer".to_string())
            .spawn(work)
            .map_err(|source| CliError::Write {
                output: path.unwrap_or("standard output").to_string(),
                source,
            })?;
        let rows = match mode {
            Mode::Text { .. } => CHUNK_ROWS,
            Mode::Parquet { .. } => PARQUET_ROWS,
        };
        Ok(Export {
            chunk: Chunk::with_capacity(rows),
            tx: Some(tx),
            worker: Some(worker),
            mode,
        })
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
    pub fn end_batch(&mut self, live: bool) -> Result<(), CliError> {
        if self.chunk.len() >= CHUNK_ROWS || (live && !self.chunk.is_empty()) {
            self.send(live, false)?;
        }
        Ok(())
    }

    /// Hands the current chunk on; `flush`: text is to reach the output at once; `last`: the
    /// end of the export.
    fn send(&mut self, flush: bool, last: bool) -> Result<(), CliError> {
        let msg = match &mut self.mode {
            Mode::Text { spare } => {
                let next = match spare.try_recv() {
                    Ok(mut c) => {
                        c.clear();
                        c
                    }
                    Err(_) => Chunk::with_capacity(CHUNK_ROWS),
                };
                let mut chunk = std::mem::replace(&mut self.chunk, next);
                chunk.flush = flush;
                Msg::Rows(chunk)
            }
            Mode::Parquet { spare } => {
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
                Msg::Rows(std::mem::replace(&mut self.chunk, next))
            }
        };
        self.post(msg)
    }

    fn post(&mut self, msg: Msg) -> Result<(), CliError> {
        let sent = self.tx.as_ref().is_some_and(|tx| tx.send(msg).is_ok());
        if sent {
            Ok(())
        } else {
            // The writer has stopped: its error says why.
            self.tx = None;
            Err(self.join().err().unwrap_or_else(|| CliError::Write {
                output: "the output".to_string(),
                source: io::Error::other("the writer stopped"),
            }))
        }
    }

    /// Writes the remaining rows and ends the output: flushes text, closes a Parquet file
    /// (adding `metadata` to its key-value metadata).
    pub fn finish(mut self, metadata: Vec<(String, String)>) -> Result<(), CliError> {
        self.send(true, true)?;
        self.post(Msg::End(metadata))?;
        self.tx = None;
        self.join()
    }

    fn join(&mut self) -> Result<(), CliError> {
        match self.worker.take() {
            Some(worker) => worker.join().unwrap_or_else(|_| {
                Err(CliError::Write {
                    output: "the output".to_string(),
                    source: io::Error::other("the writer thread failed"),
                })
            }),
            None => Ok(()),
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

/// Asks the C library's allocator to keep freed memory for reuse rather than hand it back to
/// the operating system at once. Encoding allocates and frees large buffers all the time (a
/// compressed page, a row group's columns); by default glibc unmaps or trims them on every
/// free, and faulting the pages in again took more time than compressing them. The export's
/// memory is bounded (see the module documentation), so keeping it costs nothing.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn keep_freed_memory() {
    // SAFETY: mallopt only changes allocator tuning parameters; it is called before the writer
    // thread starts, and glibc serialises it with allocations in any case.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 256 << 20);
    }
}

/// Other C libraries keep their defaults.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn keep_freed_memory() {}
