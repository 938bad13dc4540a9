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
    /// An output file could not be created.
    Create {
        /// The file as named on the command line.
        output: String,
        /// Why.
        source: io::Error,
    },
    /// `--from`/`--to` given for an input that has no receive times.
    NoTiming {
        /// The input as named on the command line.
        input: String,
    },
    /// `--from` is not before `--to`.
    EmptyWindow {
        /// Start of the window, s.
        from: f64,
        /// End of the window, s.
        to: f64,
    },
    /// More streams than the record's `esc` column can number (0..=255).
    TooManyEscs {
        /// The input whose stream would be ESC 256 or more.
        input: String,
    },
    /// A conversion setting is out of range.
    Settings(hwfoc::SettingsError),
    /// A serial port that does not exist.
    NoSuchPort {
        /// The port as named on the command line.
        port: String,
        /// The ports the system does have.
        available: Vec<String>,
    },
    /// A serial port we may not open.
    PortPermission {
        /// The port as named on the command line.
        port: String,
        /// The group owning the device file, if known.
        group: Option<String>,
    },
    /// A serial port another program has open.
    PortBusy {
        /// The port as named on the command line.
        port: String,
    },
    /// A serial port that could not be opened or set up for another reason.
    Port {
        /// The port as named on the command line.
        port: String,
        /// Why.
        message: String,
    },
    /// Serial ports and files named together as inputs.
    MixedInputs {
        /// The first port named.
        port: String,
        /// The first file named.
        file: String,
    },
    /// Options that do not go together (`hwfoc simulate`).
    Usage {
        /// The option at fault.
        option: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// A configuration file could not be read.
    Config {
        /// The file.
        path: String,
        /// 1-based line of the mistake, where known.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// The terminal could not be set up or drawn on.
    Terminal {
        /// Why.
        source: io::Error,
    },
    /// A row of a throttle profile CSV could not be read.
    Profile {
        /// The file as named on the command line.
        file: String,
        /// 1-based line number, or 0 for the file as a whole.
        line: u64,
        /// What is wrong with it.
        message: String,
    },
    /// A pseudo-terminal could not be created.
    Pty {
        /// Why.
        source: io::Error,
    },
    /// A symlink to a pseudo-terminal could not be made.
    Link {
        /// The link's path.
        path: String,
        /// Why.
        source: io::Error,
    },
    /// `hwfoc plot`: the inputs hold nothing to plot.
    NothingToPlot {
        /// What is missing, and where.
        message: String,
    },
    /// `hwfoc plot`: the image could not be drawn.
    Render {
        /// The image file.
        output: String,
        /// Why.
        message: String,
    },
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
            CliError::Create { output, source } => match source.kind() {
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
            CliError::NoTiming { input } => write!(
                f,
                "--from/--to select frames by time, but {input} is raw bytes without receive \
                 times: use a recording (`hwfoc record`) or a logic-analyser CSV, or leave out \
                 --from/--to"
            ),
            CliError::EmptyWindow { from, to } => {
                write!(
                    f,
                    "--from {from} is not before --to {to}: no frame can be selected"
                )
            }
            CliError::TooManyEscs { input } => write!(
                f,
                "{input}: too many streams: records number ESCs 0 to 255; read fewer inputs at once"
            ),
            CliError::Settings(e) => write!(f, "invalid setting: {e}"),
            CliError::NoSuchPort { port, available } => {
                write!(f, "no such port {port}")?;
                if available.is_empty() {
                    write!(f, " (no serial ports found: is the adapter plugged in?)")
                } else {
                    write!(f, " (serial ports found: {})", available.join(", "))
                }
            }
            CliError::PortPermission { port, group } => {
                // A device of group root is not meant for users: give the usual groups.
                let group = group.as_deref().filter(|g| *g != "root");
                let owner = match group {
                    Some(g) => format!(" (owned by group {g})"),
                    None => String::new(),
                };
                let command = match group {
                    Some(g) => format!("`sudo usermod -aG {g} $USER`"),
                    None => "`sudo usermod -aG dialout $USER` on Debian/Ubuntu, `uucp` on Arch"
                        .to_string(),
                };
                write!(
                    f,
                    "permission denied on {port}{owner}: join the group that may use serial \
                     ports ({command}), then log out and in again"
                )
            }
            CliError::PortBusy { port } => write!(
                f,
                "{port} is busy: another program has it open (a serial monitor, another hwfoc, \
                 ModemManager); close it and try again"
            ),
            CliError::Port { port, message } => write!(f, "cannot open port {port}: {message}"),
            CliError::MixedInputs { port, file } => write!(
                f,
                "cannot read the serial port {port} and the file {file} together: record the \
                 ports with `hwfoc record`, then read the recording with the files"
            ),
            CliError::Usage { option, message } => write!(f, "{option}: {message}"),
            CliError::Config {
                path,
                line: Some(line),
                message,
            } => write!(f, "{path} line {line}: {message}"),
            CliError::Config {
                path,
                line: None,
                message,
            } => write!(f, "{path}: {message}"),
            CliError::Terminal { source } => write!(f, "terminal: {source}"),
            CliError::Profile {
                file,
                line: 0,
                message,
            } => write!(f, "{file}: {message}"),
            CliError::Profile {
                file,
                line,
                message,
            } => write!(f, "{file}:{line}: {message}"),
            CliError::Pty { source } => write!(f, "cannot create a pseudo-terminal: {source}"),
            CliError::Link { path, source } => write!(f, "cannot create the link {path}: {source}"),
            CliError::NothingToPlot { message } => write!(f, "nothing to plot: {message}"),
            CliError::Render { output, message } => write!(f, "cannot draw {output}: {message}"),
        }
    }
}

impl std::error::Error for CliError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            CliError::Open { source, .. }
            | CliError::Read { source, .. }
            | CliError::Write { source, .. }
            | CliError::Create { source, .. }
            | CliError::Pty { source }
            | CliError::Terminal { source }
            | CliError::Link { source, .. } => Some(source),
            CliError::Settings(e) => Some(e),
            _ => None,
        }
    }
}
