//! The command's errors: each one names what went wrong and where, in one line.

use std::fmt;
use std::io;

/// Everything that makes a command fail. Printed once, by `main`, as `hwfoc: <message>`.
#[derive(Debug)]
pub enum CliError {
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
    /// Writing the output failed.
    Write {
        /// Where the output was going.
        output: String,
        /// Why.
        source: io::Error,
    },
    /// A conversion setting is out of range.
    Settings(hwfoc::SettingsError),
}

impl CliError {
    /// Whether this is the reader of our output going away (`hwfoc decode … | head`): not an
    /// error worth reporting.
    pub fn is_broken_pipe(&self) -> bool {
        matches!(self, CliError::Write { source, .. } if source.kind() == io::ErrorKind::BrokenPipe)
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Open { input, source } => write!(f, "cannot open {input}: {source}"),
            CliError::IsDirectory { input } => {
                write!(f, "{input} is a directory, not a capture file")
            }
            CliError::Read { input, source } => write!(f, "cannot read {input}: {source}"),
            CliError::Empty { input } => write!(f, "{input} is empty: there is nothing to decode"),
            CliError::Csv {
                input,
                line,
                message,
            } => write!(f, "{input}:{line}: {message}"),
            CliError::Write { output, source } => write!(f, "cannot write {output}: {source}"),
            CliError::Settings(e) => write!(f, "invalid setting: {e}"),
        }
    }
}

impl std::error::Error for CliError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            CliError::Open { source, .. }
            | CliError::Read { source, .. }
            | CliError::Write { source, .. } => Some(source),
            CliError::Settings(e) => Some(e),
            _ => None,
        }
    }
}
