//! The simulator's errors: each one names what went wrong and where, in one line.
//!
//! Outputs and serial ports fail with the I/O library's own errors, wrapped as they are; the
//! rest are the simulator's: a throttle profile that cannot be read, a fault or a link for an
//! ESC that does not exist, a pseudo-terminal or a link to one that cannot be made. The
//! messages name no option of a front end: each variant carries what a front end needs to
//! name its own (the `hwfoc` command's `CliError` adds `--fault`, `--link`, `--link-dir`).

use std::fmt;
use std::io;

use hwfoc_io::write::WriteError;
use hwfoc_ports::serial::PortError;

/// Everything that makes a simulation fail to start or stop early.
#[derive(Debug)]
pub enum SimError {
    /// An output (a file, standard output, the ground truth) could not be created or written.
    Write(WriteError),
    /// A serial port could not be opened or set up.
    Port(PortError),
    /// A throttle profile CSV file could not be read.
    ProfileRead {
        /// The file as named.
        file: String,
        /// Why.
        source: io::Error,
    },
    /// A row of a throttle profile CSV could not be read.
    Profile {
        /// The file as named.
        file: String,
        /// 1-based line number, or 0 for the file as a whole.
        line: u64,
        /// What is wrong with it.
        message: String,
    },
    /// More ESCs than a fleet can have ([`MAX_ESCS`](crate::fleet::MAX_ESCS)).
    TooManyEscs {
        /// How many were asked for.
        n: usize,
        /// The most there may be.
        max: usize,
    },
    /// More ESCs on a simulated CAN bus than it can have
    /// ([`MAX_CAN_ESCS`](crate::can::MAX_CAN_ESCS)).
    TooManyCanEscs {
        /// How many were asked for.
        n: usize,
        /// The most there may be.
        max: usize,
    },
    /// Link faults (bit errors, drops, cuts, garbage) asked of a CAN bus.
    CanLinkFaults,
    /// A degradation on an ESC the fleet does not have.
    NoSuchDegradedEsc {
        /// The degradation.
        spec: crate::degrade::DegradeSpec,
        /// How many ESCs there are.
        n: usize,
    },
    /// A loose wire asked of ESCs speaking another protocol than HW-FOC.
    WireDegradation {
        /// The protocol.
        protocol: hwfoc::Protocol,
    },
    /// Degradations asked of a CAN bus.
    CanDegradations,
    /// A fault was scheduled on an ESC the fleet does not have.
    NoSuchEsc {
        /// The ESC named.
        esc: usize,
        /// How many ESCs there are.
        n: usize,
    },
    /// Raw bytes of several ESCs sent to one file or standard output (the front ends refuse
    /// this with messages of their own before starting anything).
    SharedRaw {
        /// How many ESCs there are.
        n: usize,
    },
    /// A protocol no virtual ESC speaks (DataLink: a hub's).
    Protocol {
        /// The protocol asked for.
        protocol: hwfoc::Protocol,
    },
    /// Link faults (bit errors, drops, cuts, garbage) asked of a protocol other than HW-FOC.
    LinkFaults {
        /// The protocol.
        protocol: hwfoc::Protocol,
    },
    /// A fault injected on ESCs speaking a format whose fault word has no flag for it.
    NoFaultFlag {
        /// The protocol.
        protocol: hwfoc::Protocol,
        /// The fault.
        fault: hwfoc::Fault,
    },
    /// Symlinks to pseudo-terminals, neither one per ESC nor one template.
    LinkCount {
        /// How many links were given.
        links: usize,
        /// How many ESCs there are.
        n: usize,
    },
    /// A pseudo-terminal could not be created.
    Pty {
        /// Why.
        source: io::Error,
    },
    /// Something other than a link left by an earlier run is where a symlink to a
    /// pseudo-terminal was to be made: it is left as it is.
    LinkTaken {
        /// The link's path.
        path: String,
        /// Whether what is there is a dangling link (of someone else's).
        dangling: bool,
    },
    /// A symlink to a pseudo-terminal (or its directory) could not be made.
    Link {
        /// The link's path.
        path: String,
        /// Why.
        source: io::Error,
    },
}

impl From<WriteError> for SimError {
    fn from(e: WriteError) -> Self {
        SimError::Write(e)
    }
}

impl From<PortError> for SimError {
    fn from(e: PortError) -> Self {
        SimError::Port(e)
    }
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::Write(e) => e.fmt(f),
            SimError::Port(e) => e.fmt(f),
            SimError::ProfileRead { file, source } => write!(f, "cannot open {file}: {source}"),
            SimError::Profile {
                file,
                line: 0,
                message,
            } => write!(f, "{file}: {message}"),
            SimError::Profile {
                file,
                line,
                message,
            } => write!(f, "{file}:{line}: {message}"),
            SimError::TooManyEscs { n, max } => {
                write!(f, "{n} ESCs: at most {max} (an ESC's number is a byte)")
            }
            SimError::TooManyCanEscs { n, max } => write!(
                f,
                "{n} ESCs on a CAN bus: at most {max} (a throttle channel has 6 bits)"
            ),
            SimError::CanLinkFaults => f.write_str(
                "link faults (bit errors, drops, cuts, garbage) are simulated for HW-FOC only, \
                 not on a CAN bus",
            ),
            SimError::NoSuchDegradedEsc { spec, n } => write!(
                f,
                "a degradation ({}) is on ESC {}, which does not exist: there are {n} (0..{})",
                spec.kind,
                spec.esc,
                n.saturating_sub(1)
            ),
            SimError::WireDegradation { protocol } => write!(
                f,
                "a loose wire (bursts of lost frames) is simulated for HW-FOC only, not for {} \
                 ({protocol})",
                protocol.title()
            ),
            SimError::CanDegradations => {
                f.write_str("degradations are simulated for serial ESCs only, not on a CAN bus")
            }
            SimError::NoSuchEsc { esc, n } => write!(
                f,
                "a fault is scheduled on ESC {esc}, which does not exist: there are {n} (0..{})",
                n.saturating_sub(1)
            ),
            SimError::SharedRaw { n } => write!(
                f,
                "raw bytes of {n} ESCs cannot share one output: give each its own file \
                 ({{esc}} in the name) or write a recording (pcapng)"
            ),
            SimError::Protocol { protocol } => write!(
                f,
                "virtual ESCs do not speak {} ({protocol}): they speak {}",
                protocol.title(),
                crate::formats::SIMULATED.map(|p| p.name()).join(", ")
            ),
            SimError::LinkFaults { protocol } => write!(
                f,
                "link faults (bit errors, drops, cuts, garbage) are simulated for HW-FOC only, \
                 not for {} ({protocol})",
                protocol.title()
            ),
            SimError::NoFaultFlag { protocol, fault } => {
                let title = protocol.title();
                let word = crate::formats::format(*protocol).and_then(|f| f.fault_word.as_ref());
                let carried: Vec<String> = word.map_or_else(Vec::new, |word| {
                    hwfoc::Fault::ALL
                        .iter()
                        .filter_map(|f| (word.flag)(*f).map(|h| format!("{} (as {h})", f.name())))
                        .collect()
                });
                write!(
                    f,
                    "the fault {} has no flag in {title}'s {}; {title} carries {}",
                    fault.name(),
                    word.map_or("fault word", |w| w.name),
                    carried.join(", ")
                )
            }
            SimError::LinkCount { links, n } => write!(
                f,
                "{links} links to pseudo-terminals for {n} ESCs: give one per ESC, or one with \
                 {{esc}} in it"
            ),
            SimError::LinkTaken { path, dangling } => {
                let what = if *dangling {
                    "a link of someone else's is there (not to a pseudo-terminal of an earlier \
                     run)"
                } else {
                    "something is there already (not a link left by an earlier run)"
                };
                write!(
                    f,
                    "cannot create the link {path}: {what}: choose another path"
                )
            }
            SimError::Pty { source } => write!(f, "cannot create a pseudo-terminal: {source}"),
            SimError::Link { path, source } => write!(f, "cannot create the link {path}: {source}"),
        }
    }
}

impl std::error::Error for SimError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SimError::Write(e) => Some(e),
            SimError::Port(e) => Some(e),
            SimError::ProfileRead { source, .. }
            | SimError::Pty { source }
            | SimError::Link { source, .. } => Some(source),
            _ => None,
        }
    }
}
