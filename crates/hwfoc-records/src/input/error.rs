//! Why an input could not be read.

use std::fmt;
use std::io;

use crate::serial::PortError;

/// Why an input could not be read. Each names the input as the user gave it.
#[derive(Debug)]
pub enum InputError {
    /// An input could not be opened.
    Open {
        /// The input as named on the command line.
        input: String,
        /// Why.
        source: io::Error,
    },
    /// An input is a directory.
    IsDirectory {
        /// The input as named on the command line.
        input: String,
    },
    /// Reading an input failed part-way.
    Read {
        /// The input as named on the command line.
        input: String,
        /// Why.
        source: io::Error,
    },
    /// An input has no bytes at all.
    Empty {
        /// The input as named on the command line.
        input: String,
    },
    /// A row of a logic-analyser CSV could not be read.
    Csv {
        /// The input as named on the command line.
        input: String,
        /// 1-based line number in the file.
        line: u64,
        /// What is wrong with it.
        message: String,
    },
    /// A binary log (a BLF file) could not be read at a byte of it.
    Binary {
        /// The input as named on the command line.
        input: String,
        /// Where in the file, in bytes from its start.
        offset: u64,
        /// What is wrong there.
        message: String,
    },
    /// Frames were to be selected by time, but the input has no receive times.
    NoTiming {
        /// The input as named on the command line.
        input: String,
    },
    /// More streams than the record's `esc` column can number (0..=255).
    TooManyEscs {
        /// The input whose stream, hub channel or CAN ESC would be ESC 256 or more.
        input: String,
    },
    /// A classic libpcap file: recordings are read in pcapng.
    ClassicPcap {
        /// The input as named on the command line.
        input: String,
    },
    /// A file read in two goes (closed meanwhile: see [`Input::from_file`](crate::Input::from_file))
    /// was no longer of the format it was first.
    Changed {
        /// The input as named on the command line.
        input: String,
        /// The format it has now.
        format: crate::input::InputFormat,
    },
    /// An input gave nothing but zero bytes for [`ONLY_ZEROS_LIMIT`](crate::ONLY_ZEROS_LIMIT)
    /// bytes from its start (a device such as `/dev/zero`, which never ends): reading stops.
    OnlyZeros {
        /// The input as named on the command line.
        input: String,
        /// How many bytes it gave.
        bytes: u64,
    },
    /// No input gave a data frame (`decode`, `summary`, `check` and Python fail with this; why,
    /// input by input, is said before): see [`Sources::nothing_decoded`](crate::Sources::nothing_decoded).
    NoDataFrames {
        /// The inputs, as named, joined by `, `.
        inputs: String,
    },
    /// A serial port could not be opened.
    Port(PortError),
}

impl From<PortError> for InputError {
    fn from(e: PortError) -> Self {
        InputError::Port(e)
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InputError::Open { input, source } => write!(f, "cannot open {input}: {source}"),
            InputError::IsDirectory { input } => {
                write!(f, "{input} is a directory, not a capture file")
            }
            InputError::Read { input, source } => write!(f, "cannot read {input}: {source}"),
            InputError::Empty { input } => {
                write!(f, "{input} is empty: there is nothing to decode")
            }
            InputError::OnlyZeros { input, bytes } => write!(
                f,
                "{input}: only zero bytes, not telemetry (the first {} MiB; reading stopped)",
                bytes >> 20
            ),
            InputError::Csv {
                input,
                line,
                message,
            } => write!(f, "{input}:{line}: {message}"),
            InputError::Binary {
                input,
                offset,
                message,
            } => write!(f, "{input}: at byte {offset}: {message}"),
            InputError::NoTiming { input } => write!(
                f,
                "a time window selects frames by their receive times, but {input} is raw bytes \
                 without receive times: read a recording or a logic-analyser CSV, or select no \
                 time window"
            ),
            InputError::TooManyEscs { input } => write!(
                f,
                "{input}: too many ESCs: records number ESCs 0 to 255; read fewer inputs or buses at once"
            ),
            InputError::ClassicPcap { input } => {
                let converted = match input.strip_suffix(".pcap") {
                    Some(stem) => format!("{stem}.pcapng"),
                    None => format!("{input}.pcapng"),
                };
                write!(
                    f,
                    "{input} is a classic libpcap file, not pcapng: convert it with \
                     `editcap -F pcapng {input} {converted}`, then decode that"
                )
            }
            InputError::Changed { input, format } => write!(
                f,
                "{input} changed while it was being read: it is now {format}"
            ),
            InputError::NoDataFrames { inputs } => {
                write!(f, "no data frame in any input ({inputs})")
            }
            InputError::Port(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for InputError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            InputError::Open { source, .. } | InputError::Read { source, .. } => Some(source),
            InputError::Port(e) => Some(e),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_window_on_raw_bytes_is_worded_without_a_front_ends_options() {
        let e = InputError::NoTiming {
            input: "run.bin".into(),
        };
        assert_eq!(
            e.to_string(),
            "a time window selects frames by their receive times, but run.bin is raw bytes \
             without receive times: read a recording or a logic-analyser CSV, or select no time \
             window"
        );
    }
}
