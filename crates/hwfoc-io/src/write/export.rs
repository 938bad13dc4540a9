//! The pipeline of an export: frames gathered in [`Chunk`]s on the command's thread, handed
//! to the writer threads (see the module `write`).

use std::fs::File;
use std::io::{self, Write};
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use std::ops::Range;

use hwfoc::Settings;
use hwfoc::telemetry::{AnyFrame, Data};
use hwfoc_records::record::DataFrames;
#[cfg(feature = "parquet")]
use hwfoc_records::record::FrameSlice;

use super::{
    ExportError, OutputFormat, Provenance, Staging, WriteError, esc_settings_json, file, parquet,
    text,
};
use crate::handler::Handler;
use crate::select::Selection;

/// Rows per chunk handed to the writer thread (a chunk may exceed it by one input batch).
pub(crate) const CHUNK_ROWS: usize = 1 << 16;

/// Chunks of text waiting for the writer thread, at most.
const QUEUE: usize = 2;

/// Parquet row groups waiting for the writer thread, at most (a row group's frames take about
/// 5 MB, its columns as much again while they are encoded).
const PARQUET_QUEUE: usize = 1;

/// Room for a Parquet row group's frames: a row group closes at the end of the input batch
/// that fills it.
const PARQUET_ROWS: usize = parquet::ROW_GROUP_ROWS + CHUNK_ROWS;

/// Frames on their way to the writer: column by column, as received.
#[derive(Debug, Default)]
pub(crate) struct Chunk {
    /// Receive time of each frame's first byte, s; NaN for none.
    pub t: Vec<f64>,
    /// ESC index of each frame.
    pub esc: Vec<u8>,
    /// The frames (HW-FOC's kept as the codec's while every frame is one: each Parquet column
    /// reads a row group's frames again).
    frames: DataFrames,
    /// Whether the writer should push everything to the operating system after this chunk
    /// (live input: records appear as frames arrive).
    pub flush: bool,
    /// The settings of each ESC, by index, when some ESC's differ from
    /// [`Provenance::settings`]; `None`: every row is converted under those.
    pub settings: Option<Arc<EscTable>>,
}

/// The conversion settings of each ESC index (every `u8`), for an export in which some ESC's
/// settings differ from the others'.
pub(crate) type EscTable = [Settings; 256];

impl Chunk {
    fn with_capacity(n: usize) -> Chunk {
        Chunk {
            t: Vec::with_capacity(n),
            esc: Vec::with_capacity(n),
            frames: DataFrames::with_capacity(n),
            flush: false,
            settings: None,
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Adds a row.
    #[inline]
    pub(super) fn push(&mut self, esc: u8, t: Option<f64>, frame: &Data) {
        self.t.push(t.unwrap_or(f64::NAN));
        self.esc.push(esc);
        self.frames.push(frame);
    }

    /// The frames of the rows in `rows` (the Parquet writer's: by column, a block at a time).
    #[cfg(feature = "parquet")]
    #[inline]
    pub(super) fn frames(&self, rows: Range<usize>) -> FrameSlice<'_> {
        self.frames.slice(rows)
    }

    /// The frame of row `i`.
    #[inline]
    pub(super) fn frame(&self, i: usize) -> Data {
        self.frames.get(i)
    }

    /// The rows in `rows`, as a chunk of their own (with the same settings).
    pub(super) fn slice(&self, rows: Range<usize>, flush: bool) -> Chunk {
        Chunk {
            t: self.t[rows.clone()].to_vec(),
            esc: self.esc[rows.clone()].to_vec(),
            frames: self.frames.to_owned_range(rows),
            flush,
            settings: self.settings.clone(),
        }
    }

    pub(super) fn clear(&mut self) {
        self.t.clear();
        self.esc.clear();
        self.frames.clear();
        self.flush = false;
        self.settings = None;
    }
}

/// A message to the writer thread.
pub(crate) enum ToWriter {
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
    /// The output file while it is written under its temporary name.
    staged: Option<Staging>,
    /// When set (Ctrl-C, SIGTERM), the export is abandoned: see [`Export::stop_on`].
    stop: Option<Arc<AtomicBool>>,
    /// The settings of ESCs without settings of their own ([`Provenance::settings`]).
    default: Settings,
    /// The settings of each ESC, once one ESC's differ from `default`.
    table: Option<Arc<EscTable>>,
    /// Each ESC: not selected, or selected and whether its settings were taken yet (at its
    /// first frame). One look per frame tells both.
    escs: [EscState; 256],
}

/// What an export knows of an ESC.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum EscState {
    /// Selected; no frame of it seen yet.
    New,
    /// Selected, its settings taken.
    Known,
    /// Not selected.
    Skipped,
}

/// What the decoding thread prepares for the writer.
enum Pipeline {
    /// Text: chunks of frames, formatted by the writer. Chunks it is done with come back.
    Text { spare: Receiver<Chunk> },
    /// Parquet: a row group's frames at a time, converted, encoded and written by the writer.
    /// Chunks it is done with come back.
    Parquet { spare: Receiver<Chunk> },
}

/// An opened output: its name, for errors, and its writer.
pub(crate) struct Sink {
    /// The output as named on the command line, or "standard output".
    pub name: String,
    /// The open file or standard output.
    pub writer: Box<dyn Write + Send>,
}

impl Sink {
    /// Opens the output: standard output for `None` or `-`; a new or regular file under a
    /// temporary name (see [`Staging`]), renamed over it once complete (an existing file only
    /// if `overwrite`, else [`WriteError::Exists`]); anything else (a device such as
    /// `/dev/null`, a pipe) as it is.
    fn open(path: Option<&str>, overwrite: bool) -> Result<(Sink, Option<Staging>), WriteError> {
        let Some(path) = path.filter(|&p| p != "-") else {
            let stdout = Sink {
                name: "standard output".to_string(),
                writer: Box::new(io::stdout()),
            };
            return Ok((stdout, None));
        };
        let create_error = |source| WriteError::Create {
            output: path.to_string(),
            source,
        };
        let special = std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir());
        let (file, staged) = if special {
            (File::create(path).map_err(create_error)?, None)
        } else {
            if Path::new(path).is_dir() {
                return Err(create_error(io::ErrorKind::IsADirectory.into()));
            }
            let (staging, file) =
                Staging::create_new(Path::new(path), overwrite).map_err(|source| {
                    match source.kind() {
                        io::ErrorKind::AlreadyExists => WriteError::Exists {
                            output: path.to_string(),
                        },
                        _ => create_error(source),
                    }
                })?;
            (file, Some(staging))
        };
        let sink = Sink {
            name: path.to_string(),
            writer: Box::new(file::OutputFile::new(file)),
        };
        Ok((sink, staged))
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
    /// Creates the output (standard output for `None` or `-`) and starts the writer thread. An
    /// existing file is replaced only if `overwrite` ([`WriteError::Exists`] otherwise).
    pub fn create(
        format: OutputFormat,
        path: Option<&str>,
        overwrite: bool,
        provenance: Provenance,
    ) -> Result<Export, WriteError> {
        let (sink, staged) = Sink::open(path, overwrite)?;
        let default = provenance.settings;
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
            stop: None,
            default,
            table: None,
            escs: [EscState::New; 256],
        })
    }

    /// Keeps only the records of `selection` when the export is a [`Handler`] (every record
    /// otherwise).
    pub fn select(mut self, selection: Selection) -> Export {
        for (esc, state) in (0..=u8::MAX).zip(self.escs.iter_mut()) {
            *state = match (selection.esc(esc), *state) {
                (false, _) => EscState::Skipped,
                (true, EscState::Known) => EscState::Known,
                (true, _) => EscState::New,
            };
        }
        self.selection = selection;
        self
    }

    /// Abandons the export once `flag` is set (the `hwfoc` command sets it on Ctrl-C or
    /// SIGTERM): the next batch's end fails with
    /// [`WriteError::Interrupted`], and [`Export::finish`] then removes the temporary file,
    /// leaving any earlier file at the path as it was. For inputs that are read to their end;
    /// live ports end their input on the signal, and what they gave is kept.
    pub fn stop_on(mut self, flag: Arc<AtomicBool>) -> Export {
        self.stop = Some(flag);
        self
    }

    /// Whether the export was asked to stop (see [`Export::stop_on`]).
    fn stopped(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// The error of an abandoned export.
    fn interrupted(&self) -> WriteError {
        WriteError::Interrupted {
            output: self
                .staged
                .as_ref()
                .map(|s| s.target().display().to_string()),
        }
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

    /// The settings that the rows of ESC `esc` are converted under from now on (the export's
    /// default settings until set; an ESC's settings are meant to stay the same for the whole
    /// export: rows already pushed but not yet handed to the writer convert under these too).
    pub fn set_esc_settings(&mut self, esc: u8, settings: &Settings) {
        let state = &mut self.escs[usize::from(esc)];
        if *state == EscState::New {
            *state = EscState::Known;
        }
        let current = match &self.table {
            Some(table) => &table[usize::from(esc)],
            None => &self.default,
        };
        if current == settings {
            return;
        }
        let mut table = match &self.table {
            Some(table) => **table,
            None => [self.default; 256],
        };
        table[usize::from(esc)] = *settings;
        self.table = Some(Arc::new(table));
    }

    /// The ESCs whose rows are converted under settings other than the export's default, with
    /// those settings, by index.
    pub fn esc_settings(&self) -> Vec<(u8, Settings)> {
        let Some(table) = &self.table else {
            return Vec::new();
        };
        (0..=u8::MAX)
            .zip(table.iter())
            .filter(|(_, s)| **s != self.default)
            .map(|(esc, s)| (esc, *s))
            .collect()
    }

    /// Adds a record: a data frame, its ESC and its receive time.
    #[inline]
    pub fn push(&mut self, esc: u8, t: Option<f64>, frame: &Data) {
        self.chunk.push(esc, t, frame);
    }

    /// Hands the rows collected so far to the writer once there are enough of them, or at once
    /// when `live` (the rows are then written and flushed without waiting for more).
    pub fn end_batch(&mut self, live: bool) -> Result<(), WriteError> {
        if self.stopped() {
            return Err(self.interrupted());
        }
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
                chunk.settings = self.table.clone();
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
                let mut chunk = std::mem::replace(&mut self.chunk, next);
                chunk.settings = self.table.clone();
                ToWriter::Rows(chunk)
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

    /// Writes the remaining rows and ends the output: flushes text, closes a Parquet file (adding
    /// `metadata` to its key-value metadata, and `esc_settings` when some ESC's rows were converted
    /// under settings of their own: see [`esc_settings_json`]),
    /// and renames a file written under its temporary name into place. On a write error, or when
    /// the export was asked to stop ([`Export::stop_on`]), the temporary file is removed instead.
    pub fn finish(mut self, mut metadata: Vec<(String, String)>) -> Result<(), WriteError> {
        if self.stopped() {
            return Err(self.interrupted());
        }
        let escs = self.esc_settings();
        if !escs.is_empty() {
            metadata.push((
                super::metadata::ESC_SETTINGS.to_string(),
                esc_settings_json(&escs),
            ));
        }
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
        written?;
        if self.stopped() {
            return Err(self.interrupted());
        }
        let output = staged.target().display().to_string();
        staged.commit().map_err(|source| match source.kind() {
            io::ErrorKind::AlreadyExists => WriteError::Exists { output },
            _ => WriteError::Write { output, source },
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
/// writers convert them a block at a time on their own threads, each under the settings given
/// with its ESC's first frame (see [`Export::set_esc_settings`]).
impl Handler for Export {
    type Error = ExportError;

    #[inline]
    fn frame(&mut self, esc: u8, t: Option<f64>, frame: &AnyFrame, settings: &Settings) {
        if let AnyFrame::Data(frame) = *frame {
            // The first frame of any ESC resolves a window given after the first frame.
            self.selection.window.observe(t);
            let state = self.escs[usize::from(esc)];
            if state != EscState::Known {
                if state == EscState::Skipped {
                    return;
                }
                self.learn(esc, settings);
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

impl Export {
    /// Takes the settings of an ESC at its first frame (`Sources` looks them up once per ESC).
    /// Out of line: the usual frame only checks that its ESC is known.
    #[cold]
    #[inline(never)]
    fn learn(&mut self, esc: u8, settings: &Settings) {
        self.set_esc_settings(esc, settings);
    }
}

impl Drop for Export {
    fn drop(&mut self) {
        // Dropped without `finish` (an error elsewhere): let the writer end what it has.
        self.tx = None;
        let _ = self.join();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::Input;
    use crate::settings::SettingsMap;
    use crate::settings::SettingsPatch;
    use crate::sources::Sources;
    use hwfoc::foc::DataFrame;
    use hwfoc_records::record::FrameSlice;
    use std::path::PathBuf;

    #[test]
    fn a_chunk_keeps_its_rows_in_order_when_a_frame_of_another_protocol_comes() {
        let foc = |packet| {
            Data::HwFoc(DataFrame {
                packet,
                ..Default::default()
            })
        };
        let v3 = Data::HwV3(hwfoc::v3::V3Frame::default());
        let pushed = [foc(1), foc(2), v3, foc(3)];
        let mut chunk = Chunk::with_capacity(4);
        chunk.push(0, None, &pushed[0]);
        chunk.push(1, Some(2.5), &pushed[1]);
        // HW-FOC frames only so far: held as such.
        assert!(matches!(chunk.frames.slice(0..2), FrameSlice::HwFoc(f) if f.len() == 2));
        chunk.push(2, None, &pushed[2]);
        chunk.push(3, None, &pushed[3]);
        assert!(matches!(chunk.frames.slice(0..4), FrameSlice::Any(f) if f == pushed));
        assert_eq!(chunk.len(), 4);
        assert_eq!((0..4).map(|i| chunk.frame(i)).collect::<Vec<_>>(), pushed);
        assert_eq!(chunk.esc, [0, 1, 2, 3]);
        assert!(chunk.t[1] == 2.5 && chunk.t[0].is_nan());
        let slice = chunk.slice(1..3, true);
        assert_eq!(
            (slice.len(), slice.frame(0), slice.frame(1)),
            (2, pushed[1], pushed[2])
        );
        assert!(slice.flush);
        let slice = chunk.slice(0..1, false);
        chunk.clear();
        assert!(chunk.is_empty());
        assert_eq!(slice.frame(0), pushed[0]);
    }

    /// Ports named `p0`, `p1`, ...: frames of raw eRPM 70 (700 eRPM) and raw current 819 each.
    fn inputs(ports: usize, frames: u16) -> Vec<Input> {
        (0..ports)
            .map(|port| {
                let wire: Vec<u8> = (0..frames)
                    .flat_map(|packet| {
                        DataFrame {
                            packet,
                            erpm_raw: 70,
                            current_raw: 819,
                            ..Default::default()
                        }
                        .encode()
                    })
                    .collect();
                Input::from_memory(&format!("p{port}"), wire).unwrap()
            })
            .collect()
    }

    /// The settings of ESC `esc` in [`exported`]: every third ESC under the defaults, the
    /// others each under a current scale and pole pairs of its own.
    fn settings_of(esc: usize) -> Settings {
        if esc.is_multiple_of(3) {
            Settings::DEFAULT
        } else {
            Settings::new(10.0 + esc as f32, 2 + esc as u16, 1.0).unwrap()
        }
    }

    /// Exports `ports` ports of `frames` frames each in `format`, each port's ESC under
    /// [`settings_of`] (set by port); returns the output file's path.
    fn exported(dir: &Path, format: OutputFormat, ports: usize, frames: u16) -> PathBuf {
        let mut map = SettingsMap::from(Settings::DEFAULT);
        for esc in (0..ports).filter(|esc| !esc.is_multiple_of(3)) {
            let s = settings_of(esc);
            let patch = SettingsPatch {
                current_scale: Some(s.current_scale),
                pole_pairs: Some(s.pole_pairs),
                gear_ratio: None,
                v4_volts_per_step: None,
            };
            map.set_port(format!("p{esc}"), patch).unwrap();
        }
        let path = dir.join(format!("out.{format:?}"));
        let provenance = Provenance {
            settings: Settings::DEFAULT,
            overrides: vec![(
                "esc.1".to_string(),
                SettingsPatch {
                    pole_pairs: Some(3),
                    ..Default::default()
                },
            )],
            inputs: vec!["p0".to_string()],
            filter: String::new(),
            csv_comment: true,
            csv_time_iso: false,
        };
        let mut export = Export::create(format, path.to_str(), false, provenance).unwrap();
        Sources::new(inputs(ports, frames), map)
            .run(&mut export)
            .unwrap();
        let expected: Vec<(u8, Settings)> = (0..ports)
            .filter(|esc| !esc.is_multiple_of(3))
            .map(|esc| (esc as u8, settings_of(esc)))
            .collect();
        assert_eq!(export.esc_settings(), expected);
        export.finish(Vec::new()).unwrap();
        path
    }

    /// Checks (esc, rpm, current_a) of every row: each under its ESC's settings.
    fn check_rows(rows: &[(u8, f32, f32)], ports: usize, frames: u16) {
        assert_eq!(rows.len(), ports * usize::from(frames));
        for &(esc, rpm, amps) in rows {
            let s = settings_of(usize::from(esc));
            let frame = DataFrame {
                erpm_raw: 70,
                current_raw: 819,
                ..Default::default()
            };
            assert_eq!(
                (rpm, amps),
                (frame.rpm(&s), frame.current_a(&s)),
                "ESC {esc}"
            );
        }
        for esc in 0..ports as u8 {
            assert!(rows.iter().any(|r| r.0 == esc), "no row of ESC {esc}");
        }
    }

    /// Rows of many ESCs under many settings (more sets than a formatter keeps cached encoders
    /// for), in more than one chunk: each row under its ESC's, in JSON Lines and CSV.
    #[test]
    fn text_rows_are_converted_under_their_escs_settings() {
        let dir = tempfile::tempdir().unwrap();
        let (ports, frames) = (14, 12_000);
        assert!(ports - ports / 3 > super::text::CACHED_SETTINGS);
        let jsonl =
            std::fs::read_to_string(exported(dir.path(), OutputFormat::Jsonl, ports, frames))
                .unwrap();
        let rows: Vec<(u8, f32, f32)> = jsonl
            .lines()
            .map(|line| {
                let v: serde_json::Value = serde_json::from_str(line).unwrap();
                let f = |k: &str| v[k].as_f64().unwrap() as f32;
                (v["esc"].as_u64().unwrap() as u8, f("rpm"), f("current_a"))
            })
            .collect();
        check_rows(&rows, ports, frames);

        let csv = std::fs::read_to_string(exported(dir.path(), OutputFormat::Csv, ports, frames))
            .unwrap();
        let mut lines = csv.lines();
        let comment = lines.next().unwrap();
        assert!(
            comment.starts_with(
                "# hwfoc decode: current_scale=64 pole_pairs=7 gear_ratio=1 v4_volts_per_step=8/910 \
                 esc.1.pole_pairs=3 input=p0"
            ),
            "{comment}"
        );
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let col = |name: &str| header.iter().position(|&c| c == name).unwrap();
        let (esc, rpm, amps) = (col("esc"), col("rpm"), col("current_a"));
        let rows: Vec<(u8, f32, f32)> = lines
            .map(|line| {
                let fields: Vec<&str> = line.split(',').collect();
                (
                    fields[esc].parse().unwrap(),
                    fields[rpm].parse().unwrap(),
                    fields[amps].parse().unwrap(),
                )
            })
            .collect();
        check_rows(&rows, ports, frames);
    }

    /// The same in Parquet, with the settings of each ESC that has its own in the metadata.
    #[cfg(feature = "parquet")]
    #[test]
    fn parquet_rows_are_converted_under_their_escs_settings() {
        use ::parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
        use arrow_array::cast::AsArray;
        use arrow_array::types::{Float32Type, UInt8Type};

        let dir = tempfile::tempdir().unwrap();
        // Two row groups at least, each with ESCs under settings of their own.
        let (ports, frames) = (5, 40_000);
        let path = exported(dir.path(), OutputFormat::Parquet, ports, frames);
        let reader = ParquetRecordBatchReaderBuilder::try_new(File::open(&path).unwrap()).unwrap();
        let kv = reader
            .metadata()
            .file_metadata()
            .key_value_metadata()
            .unwrap()
            .clone();
        assert!(reader.metadata().num_row_groups() >= 2);
        let value = |key: &str| {
            kv.iter()
                .find(|e| e.key == key)
                .and_then(|e| e.value.clone())
        };
        assert_eq!(value("pole_pairs").as_deref(), Some("7"));
        let escs: serde_json::Value =
            serde_json::from_str(&value("esc_settings").unwrap()).unwrap();
        assert_eq!(
            escs,
            serde_json::json!({
                "1": {"current_scale": 11.0, "pole_pairs": 3, "gear_ratio": 1.0, "v4_volts_per_step": "8/910"},
                "2": {"current_scale": 12.0, "pole_pairs": 4, "gear_ratio": 1.0, "v4_volts_per_step": "8/910"},
                "4": {"current_scale": 14.0, "pole_pairs": 6, "gear_ratio": 1.0, "v4_volts_per_step": "8/910"},
            })
        );
        let mut rows = Vec::new();
        for batch in reader.build().unwrap() {
            let batch = batch.unwrap();
            let column = |name: &str| batch.column(batch.schema().index_of(name).unwrap()).clone();
            let (esc, rpm, amps) = (column("esc"), column("rpm"), column("current_a"));
            let (esc, rpm, amps) = (
                esc.as_primitive::<UInt8Type>(),
                rpm.as_primitive::<Float32Type>(),
                amps.as_primitive::<Float32Type>(),
            );
            for i in 0..batch.num_rows() {
                rows.push((esc.value(i), rpm.value(i), amps.value(i)));
            }
        }
        check_rows(&rows, ports, frames);
    }

    /// Only the selected ESCs' settings are taken: a skipped ESC under settings of its own is
    /// neither written nor named among the ESCs with their own settings.
    #[test]
    fn skipped_escs_settings_are_not_taken() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("some.jsonl");
        let mut map = SettingsMap::from(Settings::DEFAULT);
        for esc in [1, 2] {
            let patch = SettingsPatch {
                pole_pairs: Some(settings_of(esc).pole_pairs),
                current_scale: Some(settings_of(esc).current_scale),
                gear_ratio: None,
                v4_volts_per_step: None,
            };
            map.set_port(format!("p{esc}"), patch).unwrap();
        }
        let provenance = Provenance {
            settings: Settings::DEFAULT,
            overrides: Vec::new(),
            inputs: Vec::new(),
            filter: String::new(),
            csv_comment: false,
            csv_time_iso: false,
        };
        let selection = Selection::new(&[0, 2], crate::select::Window::ALL);
        let mut export = Export::create(OutputFormat::Jsonl, path.to_str(), false, provenance)
            .unwrap()
            .select(selection);
        Sources::new(inputs(3, 100), map).run(&mut export).unwrap();
        assert_eq!(export.esc_settings(), [(2, settings_of(2))]);
        assert_eq!(export.kept(), 200);
        export.finish(Vec::new()).unwrap();
        let rows: Vec<(u8, f32, f32)> = std::fs::read_to_string(&path)
            .unwrap()
            .lines()
            .map(|line| {
                let v: serde_json::Value = serde_json::from_str(line).unwrap();
                let f = |k: &str| v[k].as_f64().unwrap() as f32;
                (v["esc"].as_u64().unwrap() as u8, f("rpm"), f("current_a"))
            })
            .collect();
        assert_eq!(rows.len(), 200);
        assert!(rows.iter().all(|r| r.0 != 1));
        let frame = DataFrame {
            erpm_raw: 70,
            current_raw: 819,
            ..Default::default()
        };
        for &(esc, rpm, amps) in &rows {
            let s = settings_of(usize::from(esc));
            assert_eq!(
                (rpm, amps),
                (frame.rpm(&s), frame.current_a(&s)),
                "ESC {esc}"
            );
        }
        assert!(rows.iter().any(|r| r.0 == 2));
    }

    /// An export whose ESCs all have the default settings carries no table and no
    /// `esc_settings`; settings equal to the default, said for an ESC, change nothing.
    #[test]
    fn uniform_settings_carry_no_table() {
        let provenance = Provenance {
            settings: Settings::DEFAULT,
            overrides: Vec::new(),
            inputs: Vec::new(),
            filter: String::new(),
            csv_comment: false,
            csv_time_iso: false,
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.jsonl");
        let mut export =
            Export::create(OutputFormat::Jsonl, path.to_str(), false, provenance).unwrap();
        export.set_esc_settings(3, &Settings::DEFAULT);
        assert!(export.table.is_none() && export.esc_settings().is_empty());
        let other = Settings::new(100.0, 7, 1.0).unwrap();
        export.set_esc_settings(3, &other);
        export.set_esc_settings(5, &Settings::DEFAULT);
        assert_eq!(export.esc_settings(), [(3, other)]);
        export.finish(Vec::new()).unwrap();
    }
}
