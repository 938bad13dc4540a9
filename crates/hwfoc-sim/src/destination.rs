//! Where a run's bytes go: files or standard output (raw bytes or a pcapng recording),
//! pseudo-terminals, serial ports; and how they are paced into each.

use crate::error::SimError;
#[cfg(unix)]
use crate::pty::{self, PtyLinks};
use crate::schedule::Pace;
use crate::sink::{self, PcapngSink, PortSink, RawSink, Sink};
use crate::template;

/// Duration of one piece written to a pseudo-terminal or a pipe in real time, seconds.
const PIECE_S: f64 = 0.004;

/// Formats of files (and standard output).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileFormat {
    /// The bytes as they were on the wire; one ESC per file.
    Raw,
    /// A pcapng recording (one interface per ESC, nanosecond timestamps), as `hwfoc record`
    /// writes.
    Pcapng,
}

impl FileFormat {
    /// The format a file's name suggests: pcapng for a name ending in `.pcapng`, raw otherwise.
    pub fn for_path(path: &str) -> FileFormat {
        if path.ends_with(".pcapng") {
            FileFormat::Pcapng
        } else {
            FileFormat::Raw
        }
    }
}

/// Where a run's bytes go.
#[derive(Debug, Clone, PartialEq)]
pub enum Destination {
    /// Standard output: raw bytes of a single ESC, or a recording of them all.
    Stdout(FileFormat),
    /// A file, or one per ESC with `{esc}` in the path (raw bytes of several ESCs need one
    /// each).
    File {
        /// The path, `{esc}` standing for the ESC's number.
        path: String,
        /// Its format.
        format: FileFormat,
    },
    /// A pseudo-terminal per ESC, always in real time, with symlinks to them.
    #[cfg(unix)]
    Ptys(PtyLinks),
    /// Real serial ports, one per ESC, always in real time.
    Ports(Vec<String>),
}

/// A destination opened: the sink, and what each ESC's output is called.
pub(crate) struct Opened {
    /// Where the bytes go.
    pub sink: Box<dyn Sink>,
    /// Each ESC's output, as a person would name it (a path, a port, standard output).
    pub names: Vec<String>,
    /// Whether to keep the outputs open a moment after the end (pseudo-terminals, whose
    /// readers lose what they have not read when the master closes).
    pub linger: bool,
    /// Symlinks to the pseudo-terminals, kept for as long as the outputs are open and removed
    /// when dropped.
    #[cfg(unix)]
    pub _links: pty::Links,
}

impl Destination {
    /// Whether the destination is a live one, always written in real time (pseudo-terminals and
    /// serial ports).
    pub fn is_live(&self) -> bool {
        match self {
            Destination::Stdout(_) | Destination::File { .. } => false,
            #[cfg(unix)]
            Destination::Ptys(_) => true,
            Destination::Ports(_) => true,
        }
    }

    /// The format of a file or standard output; `None` for live destinations (raw bytes).
    pub fn file_format(&self) -> Option<FileFormat> {
        match self {
            Destination::Stdout(format) | Destination::File { format, .. } => Some(*format),
            _ => None,
        }
    }

    /// How bytes are handed over at `baud`, in real time or not: live destinations and real-time
    /// files get bursts whole at their start, pseudo-terminals and real-time standard output
    /// (a pipe) in pieces that never run ahead of the wire.
    pub(crate) fn pace(&self, realtime: bool, baud: u32) -> Pace {
        let pieces = Pace::Pieces((PIECE_S * f64::from(baud) / 10.0).round().max(1.0) as usize);
        match self {
            #[cfg(unix)]
            Destination::Ptys(_) => pieces,
            Destination::Ports(_) => Pace::Whole,
            _ if !realtime => Pace::Fast,
            Destination::Stdout(_) => pieces,
            Destination::File { .. } => Pace::Whole,
        }
    }

    /// The files `n` ESCs are written to (`-` for standard output): one, or one per ESC with
    /// `{esc}` in the name; none for live destinations.
    pub fn files(&self, n: usize) -> Vec<String> {
        match self {
            Destination::File { path, .. } if path.contains("{esc}") => {
                (0..n).map(|i| template::expand(path, i)).collect()
            }
            Destination::File { path, .. } => vec![path.clone()],
            Destination::Stdout(_) => vec!["-".to_string()],
            _ => Vec::new(),
        }
    }

    /// Opens the destination for `n` ESCs at `baud`, speaking `protocol` (which a recording's
    /// interfaces name); existing files are replaced only if `overwrite`
    /// ([`Session::open`](crate::Session::open) has refused them all before any is created;
    /// each creation still refuses a file that appeared since).
    pub(crate) fn open(
        &self,
        n: usize,
        (baud, protocol): (u32, Option<hwfoc::Protocol>),
        overwrite: bool,
        recording: hwfoc_io::pcapng::RecordingId,
    ) -> Result<Opened, SimError> {
        #[cfg(unix)]
        let mut links = pty::Links::default();
        let (sink, names, linger): (Box<dyn Sink>, Vec<String>, bool) = match self {
            #[cfg(unix)]
            Destination::Ptys(asked) => {
                let (ptys, made) = pty::open_all(n, asked)?;
                links = made;
                let names = ptys
                    .iter()
                    .map(|p| p.path().display().to_string())
                    .collect();
                (Box::new(sink::PtySink::new(ptys)), names, true)
            }
            Destination::Ports(ports) => {
                (Box::new(PortSink::open(ports, baud)?), ports.clone(), false)
            }
            Destination::Stdout(format) | Destination::File { format, .. } => {
                let paths = self.files(n);
                let file_of: Vec<usize> = match paths.len() {
                    1 => vec![0; n],
                    _ => (0..n).collect(),
                };
                if *format == FileFormat::Raw && paths.len() < n {
                    return Err(SimError::SharedRaw { n });
                }
                let mut outs = Vec::with_capacity(paths.len());
                for path in &paths {
                    outs.push(sink::create(path, overwrite)?);
                }
                let names = file_of.iter().map(|&f| outs[f].0.clone()).collect();
                let sink: Box<dyn Sink> = match format {
                    FileFormat::Raw => Box::new(RawSink::new(outs)),
                    FileFormat::Pcapng => Box::new(PcapngSink::new(
                        outs,
                        &file_of,
                        (baud, protocol),
                        recording,
                    )?),
                };
                (sink, names, false)
            }
        };
        Ok(Opened {
            sink,
            names,
            linger,
            #[cfg(unix)]
            _links: links,
        })
    }
}
