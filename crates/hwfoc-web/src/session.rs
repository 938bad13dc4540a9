//! A session: the bytes of one stream (a port, or a file's contents) decoded into records as
//! they come.
//!
//! Until the OS-free readers of `hwfoc-records` are in the workspace, a session reads one serial
//! stream with the codec's [`Decoder`] (every Hobbywing serial format, told from the bytes), one
//! ESC (number 0); DataLink hub channels are numbered from 1.

use crate::columns::Columns;
use hwfoc::detect::{Decoded, Decoder};
use hwfoc::mixed;
use hwfoc::telemetry::{Data, Frame};
use hwfoc::{Protocol, Settings};

/// A stream's decoding and the records it gave that were not yet taken.
pub struct Session {
    decoder: Decoder,
    settings: Settings,
    forced: Option<Protocol>,
    columns: Columns,
    /// Data frames per ESC, by number.
    frames: Vec<u64>,
    /// Device-information frames per ESC, by number.
    info_frames: Vec<u64>,
    /// The last device information's text per ESC.
    info: Vec<Option<String>>,
    notices: Vec<String>,
    finished: bool,
}

/// A session's settings could not be taken.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SessionError {
    /// `--protocol`'s name is not one of [`Protocol::ALL`]'s.
    UnknownProtocol(String),
}

impl core::fmt::Display for SessionError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SessionError::UnknownProtocol(name) => {
                let names: Vec<&str> = Protocol::ALL.iter().map(|p| p.name()).collect();
                write!(f, "unknown protocol '{name}' (one of {})", names.join(", "))
            }
        }
    }
}

impl Session {
    /// A session reading every serial format, or only `protocol` (a name `--protocol` takes).
    pub fn new(protocol: Option<&str>) -> Result<Session, SessionError> {
        let forced = match protocol {
            None | Some("") | Some("auto") => None,
            Some(name) => Some(
                Protocol::from_name(name)
                    .ok_or_else(|| SessionError::UnknownProtocol(name.to_owned()))?,
            ),
        };
        Ok(Session {
            decoder: Decoder::new(),
            settings: Settings::DEFAULT,
            forced,
            columns: Columns::default(),
            frames: Vec::new(),
            info_frames: Vec::new(),
            info: Vec::new(),
            notices: Vec::new(),
            finished: false,
        })
    }

    /// Decodes `bytes`, the chunk whose last byte came at `t_s` (seconds; None in a file
    /// without receive times).
    pub fn feed(&mut self, bytes: &[u8], t_s: Option<f64>) {
        let mut found = Vec::new();
        self.decoder.feed(bytes, |d| found.push(d));
        for d in found {
            self.take(d, t_s);
        }
    }

    /// Ends the stream: the frames held at its end are handed on.
    pub fn finish(&mut self) {
        if self.finished {
            return;
        }
        self.finished = true;
        let mut found = Vec::new();
        self.decoder.flush(|d| found.push(d));
        for d in found {
            self.take(d, None);
        }
        if self.frames.iter().all(|n| *n == 0) {
            self.notices.push(format!(
                "no telemetry frame found in {} bytes",
                self.decoder.bytes()
            ));
        }
    }

    /// The records decoded since the last call.
    pub fn columns(&mut self) -> &mut Columns {
        &mut self.columns
    }

    /// The notices so far, as the command's stderr lines.
    pub fn notices(&self) -> &[String] {
        &self.notices
    }

    /// Per ESC (by number): data frames, info frames and its last device information.
    pub fn escs(&self) -> impl Iterator<Item = (usize, u64, u64, Option<&str>)> {
        (0..self.frames.len()).map(|esc| {
            (
                esc,
                self.frames[esc],
                self.info_frames[esc],
                self.info[esc].as_deref(),
            )
        })
    }

    fn take(&mut self, d: Decoded, t_s: Option<f64>) {
        match d {
            Decoded::Mixed(mixed::Decoded::Hub(hub)) => {
                for (channel, frame) in hub.frame.escs() {
                    self.frame(1 + channel as u8, &Frame::Data(Data::DataLink(*frame)), t_s);
                }
            }
            Decoded::Mixed(mixed::Decoded::Esc(d)) => self.frame(0, &Frame::from(d.frame), t_s),
            Decoded::HwV4(d) => self.frame(0, &Frame::from(d.frame), t_s),
            Decoded::HwV3(d) => self.frame(0, &Frame::Data(Data::HwV3(d.frame)), t_s),
            Decoded::Hw5(d) => self.frame(0, &Frame::Data(Data::Hw5(d.frame)), t_s),
        }
    }

    fn frame(&mut self, esc: u8, frame: &Frame, t_s: Option<f64>) {
        let i = usize::from(esc);
        if self.frames.len() <= i {
            self.frames.resize(i + 1, 0);
            self.info_frames.resize(i + 1, 0);
            self.info.resize(i + 1, None);
        }
        match frame {
            Frame::Data(data) => {
                if self.forced.is_some_and(|p| p != data.protocol()) {
                    return;
                }
                self.frames[i] += 1;
                self.columns.push(t_s, esc, data, &self.settings);
            }
            Frame::Info(info) => {
                self.info_frames[i] += 1;
                self.info[i] = Some(info.to_string());
            }
        }
    }
}
