//! The command's errors: each one names what went wrong and where, in one line.
//!
//! The libraries' errors (inputs, ports, outputs, the simulator) are wrapped as they are, so their
//! messages are the libraries', except where a library's error is about what an option of the
//! command gave: the libraries name no option, and the message here names it (`--from`/`--to`,
//! `--fault`, `--link`, `--link-dir`) from the data the error carries. The variants of its own
//! are the command line's: options, configuration files, the terminal, plots.

use std::fmt;
use std::io;

use hwfoc_io::EmptyWindow;
use hwfoc_io::InputError;
use hwfoc_io::write::{ExportError, WriteError};
use hwfoc_ports::serial::PortError;
use hwfoc_sim::SimError;

/// Everything that makes a command fail. Printed once, by `main`, as `hwfoc: <message>`.
#[derive(Debug)]
pub enum CliError {
    /// An input could not be opened or read.
    Input(InputError),
    /// A serial port could not be opened.
    Port(PortError),
    /// An output could not be created or written.
    Write(WriteError),
    /// A bridge output could not be opened.
    Output(hwfoc_bridge::OutputError),
    /// A CAN bus could not be used, or an ESC on it did not do what was asked (`hwfoc can`).
    Can(hwfoc_can_setup::SetupError),
    /// The user did not confirm a change (`hwfoc can`).
    Declined,
    /// The virtual ESCs could not be set up or run (`hwfoc simulate`, `hwfoc monitor --sim`).
    Sim(SimError),
    /// `--from` is not before `--to`.
    Window(EmptyWindow),
    /// A conversion setting is out of range.
    Settings(hwfoc::SettingsError),
    /// The output is a file the command reads (the same file, by whatever path): writing it
    /// would destroy it.
    IsInput {
        /// The output as named on the command line.
        output: String,
        /// The input it is, as named on the command line.
        input: String,
    },
    /// Serial ports and files named together as inputs.
    MixedInputs {
        /// The first port named.
        port: String,
        /// The first file named.
        file: String,
    },
    /// Options that do not go together.
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
    /// `hwfoc plot`: the inputs hold nothing to plot.
    NothingToPlot {
        /// What is missing, and where.
        message: String,
    },
    /// `hwfoc web`: the address could not be listened on.
    Listen {
        /// The address, as given.
        listen: String,
        /// Why.
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
        matches!(self, CliError::Write(e) if e.is_broken_pipe())
    }
}

impl From<InputError> for CliError {
    fn from(e: InputError) -> Self {
        match e {
            InputError::Port(e) => CliError::Port(e),
            e => CliError::Input(e),
        }
    }
}

impl From<ExportError> for CliError {
    fn from(e: ExportError) -> Self {
        match e {
            ExportError::Input(e) => e.into(),
            ExportError::Write(e) => CliError::Write(e),
        }
    }
}

impl From<hwfoc_can_setup::SetupError> for CliError {
    fn from(e: hwfoc_can_setup::SetupError) -> Self {
        CliError::Can(e)
    }
}

impl From<hwfoc_ports::can::CanError> for CliError {
    fn from(e: hwfoc_ports::can::CanError) -> Self {
        CliError::Can(e.into())
    }
}

impl From<PortError> for CliError {
    fn from(e: PortError) -> Self {
        CliError::Port(e)
    }
}

impl From<WriteError> for CliError {
    fn from(e: WriteError) -> Self {
        CliError::Write(e)
    }
}

/// Output and port errors of the simulator are the command's own kinds, as those of inputs are
/// (so that a reader of standard output going away is not reported, whoever wrote to it).
impl From<SimError> for CliError {
    fn from(e: SimError) -> Self {
        match e {
            SimError::Write(e) => CliError::Write(e),
            SimError::Port(e) => CliError::Port(e),
            e => CliError::Sim(e),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Input(InputError::NoTiming { input }) => write!(
                f,
                "--from/--to select frames by time, but {input} is raw bytes without receive \
                 times: use a recording (`hwfoc record`) or a logic-analyser CSV, or leave out \
                 --from/--to"
            ),
            CliError::Input(e) => e.fmt(f),
            CliError::Port(e) => e.fmt(f),
            // The library's message, and the option that answers it.
            CliError::Write(e @ WriteError::Exists { .. }) => write!(f, "{e}, or pass --overwrite"),
            CliError::Write(e @ WriteError::Create { source, .. })
                if source.kind() == std::io::ErrorKind::PermissionDenied =>
            {
                write!(f, "{e} (choose another place with -o)")
            }
            CliError::Write(e) => e.fmt(f),
            CliError::Sim(SimError::NoSuchEsc { esc, n }) => write!(
                f,
                "--fault: ESC {esc} does not exist: there are {n} (0..{})",
                n.saturating_sub(1)
            ),
            CliError::Sim(SimError::LinkCount { links, n }) => write!(
                f,
                "--link: {links} links for {n} ESCs: give one per ESC, or one with {{esc}} in it"
            ),
            CliError::Sim(e @ SimError::LinkTaken { .. }) => {
                write!(f, "{e}, or a directory of your own with --link-dir")
            }
            CliError::Sim(e) => e.fmt(f),
            CliError::Output(e) => e.fmt(f),
            CliError::Can(e) => e.fmt(f),
            CliError::Declined => f.write_str("not confirmed: nothing was changed"),
            CliError::Window(e) => e.between("--from", "--to").fmt(f),
            CliError::Settings(e) => write!(f, "invalid setting: {e}"),
            CliError::IsInput { output, input } => write!(
                f,
                "cannot write {output}: it is the input {input}, which would be destroyed; \
                 choose another output file"
            ),
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
            CliError::NothingToPlot { message } => write!(f, "nothing to plot: {message}"),
            CliError::Render { output, message } => write!(f, "cannot draw {output}: {message}"),
            CliError::Listen { listen, message } => {
                write!(f, "cannot listen on {listen}: {message}")
            }
        }
    }
}

impl std::error::Error for CliError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            CliError::Input(e) => Some(e),
            CliError::Port(e) => Some(e),
            CliError::Write(e) => Some(e),
            CliError::Sim(e) => Some(e),
            CliError::Output(e) => Some(e),
            CliError::Can(e) => Some(e),
            CliError::Window(e) => Some(e),
            CliError::Terminal { source } => Some(source),
            CliError::Settings(e) => Some(e),
            _ => None,
        }
    }
}
