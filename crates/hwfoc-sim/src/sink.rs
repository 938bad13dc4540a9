//! Where the virtual ESCs' bytes go, and the ground truth of what they sent.

use std::io::{self, BufWriter, Write};

use hwfoc::Settings;
use hwfoc::foc::DataFrame;
use hwfoc::telemetry::Data;

use hwfoc_io::pcapng;
use hwfoc_io::record::Record;
use hwfoc_io::write::{self, WriteError};
use hwfoc_ports::serial::PortError;

/// The outputs of a simulation, one stream per ESC.
pub trait Sink {
    /// Writes bytes of ESC `esc`; `t_ns` is the time the first of them started on the wire, in
    /// the output's clock (ns). Returns whether they were all delivered.
    fn write(&mut self, esc: usize, t_ns: u64, bytes: &[u8]) -> Result<bool, WriteError>;
    /// Hands buffered bytes to the operating system.
    fn flush(&mut self) -> Result<(), WriteError>;
    /// Bytes of ESC `esc` that could not be delivered (no reader on a pseudo-terminal).
    fn undelivered(&self, _esc: usize) -> u64 {
        0
    }
}

/// Opens `path` for writing (or standard output for `-`), with errors naming it. An existing
/// file is [`WriteError::Exists`] unless `overwrite` (see [`write::create_file`]).
pub fn create(path: &str, overwrite: bool) -> Result<(String, Box<dyn Write>), WriteError> {
    if path == "-" {
        return Ok(("standard output".to_string(), Box::new(io::stdout())));
    }
    let file = write::create_file(path, overwrite)?;
    Ok((path.to_string(), Box::new(file)))
}

/// Refuses, before anything is created, a file of `paths` that exists (unless `overwrite`), so
/// that a run with several outputs fails whole rather than after writing some of them.
pub fn check_new<'a>(
    paths: impl IntoIterator<Item = &'a str>,
    overwrite: bool,
) -> Result<(), WriteError> {
    if overwrite {
        return Ok(());
    }
    match paths
        .into_iter()
        .find(|p| *p != "-" && std::fs::symlink_metadata(p).is_ok())
    {
        Some(file) => Err(WriteError::Exists {
            output: file.to_string(),
        }),
        None => Ok(()),
    }
}

fn write_error(name: &str) -> impl FnOnce(io::Error) -> WriteError + '_ {
    move |source| WriteError::Write {
        output: name.to_string(),
        source,
    }
}

/// Raw bytes as they were on the wire: one file (or standard output) per ESC.
pub struct RawSink {
    outs: Vec<(String, BufWriter<Box<dyn Write>>)>,
}

impl RawSink {
    /// Over already opened outputs, the `i`-th for ESC `i`.
    pub fn new(outs: Vec<(String, Box<dyn Write>)>) -> RawSink {
        RawSink {
            outs: outs
                .into_iter()
                .map(|(name, w)| (name, BufWriter::with_capacity(1 << 16, w)))
                .collect(),
        }
    }
}

impl Sink for RawSink {
    fn write(&mut self, esc: usize, _t_ns: u64, bytes: &[u8]) -> Result<bool, WriteError> {
        let (name, out) = &mut self.outs[esc];
        out.write_all(bytes).map_err(write_error(name))?;
        Ok(true)
    }

    fn flush(&mut self) -> Result<(), WriteError> {
        for (name, out) in &mut self.outs {
            out.flush().map_err(write_error(name))?;
        }
        Ok(())
    }
}

/// A pcapng writer over a buffered output.
type RecordingWriter = pcapng::Writer<BufWriter<Box<dyn Write>>>;

/// pcapng recordings: one interface per ESC, in one file or one file per ESC. Each burst of
/// bytes is one packet, timestamped at its first byte, so a frame always starts a packet and
/// its `t_s` read back is exactly the packet's time.
pub struct PcapngSink {
    files: Vec<(String, RecordingWriter)>,
    /// For each ESC: its file and interface.
    route: Vec<(usize, u32)>,
}

impl PcapngSink {
    /// One recording per output, each ESC an interface named `esc-N` in the file at
    /// `file_of[esc]`, described as carrying `protocol` at `baud`; the files are parts of
    /// recording `recording`.
    pub fn new(
        outs: Vec<(String, Box<dyn Write>)>,
        file_of: &[usize],
        (baud, protocol): (u32, Option<hwfoc::Protocol>),
        recording: pcapng::RecordingId,
    ) -> Result<PcapngSink, WriteError> {
        let mut files = Vec::with_capacity(outs.len());
        for (name, w) in outs {
            let buffered = BufWriter::with_capacity(1 << 16, w);
            let writer =
                pcapng::Writer::continuing(buffered, recording).map_err(write_error(&name))?;
            files.push((name, writer));
        }
        let mut route = Vec::with_capacity(file_of.len());
        for (esc, &file) in file_of.iter().enumerate() {
            let (name, writer) = &mut files[file];
            let iface = writer
                .add_port(&format!("esc-{esc}"), baud, protocol)
                .map_err(write_error(name))?;
            route.push((file, iface));
        }
        Ok(PcapngSink { files, route })
    }
}

impl Sink for PcapngSink {
    fn write(&mut self, esc: usize, t_ns: u64, bytes: &[u8]) -> Result<bool, WriteError> {
        let (file, iface) = self.route[esc];
        let (name, writer) = &mut self.files[file];
        writer
            .write(iface, t_ns, bytes)
            .map_err(write_error(name))?;
        Ok(true)
    }

    fn flush(&mut self) -> Result<(), WriteError> {
        for (name, writer) in &mut self.files {
            writer.flush().map_err(write_error(name))?;
        }
        Ok(())
    }
}

/// Real serial ports, one per ESC. The UART sends at the baud rate, so each burst is written
/// whole at its start time: the hardware spreads its bytes over the wire as a real ESC's are.
pub struct PortSink {
    ports: Vec<(String, Box<dyn serialport::SerialPort>)>,
    undelivered: Vec<u64>,
}

impl PortSink {
    /// Opens each port at `baud`, 8N1.
    pub fn open(names: &[String], baud: u32) -> Result<PortSink, PortError> {
        let mut ports = Vec::with_capacity(names.len());
        for name in names {
            let mut port = hwfoc_ports::serial::open(name, baud)?;
            // A write waits at most this long for room in the driver's buffer.
            port.set_timeout(std::time::Duration::from_millis(500))
                .map_err(|e| PortError::Other {
                    port: name.clone(),
                    message: e.to_string(),
                })?;
            ports.push((name.clone(), port));
        }
        Ok(PortSink {
            undelivered: vec![0; ports.len()],
            ports,
        })
    }
}

impl Sink for PortSink {
    fn write(&mut self, esc: usize, _t_ns: u64, bytes: &[u8]) -> Result<bool, WriteError> {
        let (name, port) = &mut self.ports[esc];
        match port.write_all(bytes) {
            Ok(()) => Ok(true),
            Err(e) if e.kind() == io::ErrorKind::TimedOut => {
                self.undelivered[esc] += bytes.len() as u64;
                Ok(false)
            }
            Err(source) => Err(WriteError::Write {
                output: name.clone(),
                source,
            }),
        }
    }

    fn flush(&mut self) -> Result<(), WriteError> {
        Ok(())
    }

    fn undelivered(&self, esc: usize) -> u64 {
        self.undelivered[esc]
    }
}

/// Pseudo-terminals, one per ESC.
#[cfg(unix)]
pub struct PtySink {
    ptys: Vec<crate::pty::Pty>,
}

#[cfg(unix)]
impl PtySink {
    /// Over created ptys, the `i`-th for ESC `i`.
    pub fn new(ptys: Vec<crate::pty::Pty>) -> PtySink {
        PtySink { ptys }
    }
}

#[cfg(unix)]
impl Sink for PtySink {
    fn write(&mut self, esc: usize, _t_ns: u64, bytes: &[u8]) -> Result<bool, WriteError> {
        Ok(self.ptys[esc].write(bytes))
    }

    fn flush(&mut self) -> Result<(), WriteError> {
        Ok(())
    }

    fn undelivered(&self, esc: usize) -> u64 {
        self.ptys[esc].undelivered()
    }
}

/// The ground truth: one JSON Lines record per data frame delivered intact.
pub struct Truth {
    name: String,
    out: BufWriter<Box<dyn Write>>,
    settings: Settings,
    line: Vec<u8>,
}

impl Truth {
    /// Writes records to `out`, converted under `settings`.
    pub fn new(name: String, out: Box<dyn Write>, settings: Settings) -> Truth {
        Truth {
            name,
            out: BufWriter::with_capacity(1 << 16, out),
            settings,
            line: Vec::with_capacity(512),
        }
    }

    /// Records `frame` of ESC `esc`, whose first byte started at `t_s`.
    pub fn record(&mut self, t_s: f64, esc: usize, frame: &DataFrame) -> Result<(), WriteError> {
        self.record_data(t_s, esc, &(*frame).into())
    }

    /// Records `data`, a data frame of any protocol, of ESC `esc`, whose first byte started at
    /// `t_s` (a V4 frame converted under the info frame it carries).
    pub fn record_data(&mut self, t_s: f64, esc: usize, data: &Data) -> Result<(), WriteError> {
        self.line.clear();
        // ESC indices are below 256 (checked when the fleet is built).
        Record::new(Some(t_s), esc as u8, data, &self.settings).write_json(&mut self.line);
        self.out
            .write_all(&self.line)
            .map_err(write_error(&self.name))
    }

    /// Writes one line of its own (a JSON object and its newline) before the records: what a
    /// degradation is, for instance ([`crate::degrade::DegradeSpec::truth_line`]).
    pub fn note(&mut self, line: &str) -> Result<(), WriteError> {
        self.out
            .write_all(line.as_bytes())
            .map_err(write_error(&self.name))
    }

    /// Hands buffered records to the operating system.
    pub fn flush(&mut self) -> Result<(), WriteError> {
        self.out.flush().map_err(write_error(&self.name))
    }
}
