//! Everything between the bytes on an ESC's telemetry wire and the records every output shows.
//!
//! The codec (`hwfoc`) turns bytes into frames; this library does what lies around it, for every
//! front end alike (the `hwfoc` command, bridges, bindings):
//!
//! - [`input`]: where bytes come from (raw files, logic-analyser CSV exports, pcapng recordings,
//!   serial ports, standard input), the format detected from the content, each byte with its
//!   receive time where the source has a clock;
//! - [`stream`] and [`sources`]: the one path from timed bytes to frames, a decoding stream per
//!   ESC, each converted under its own [`settings`]; [`handler`]: the [`Handler`] seam through which records reach a front end;
//! - [`record`]: the record of `docs/RECORD-SCHEMA.md` (one row per data frame, physical units), its
//!   columns declared once in one table, and its text encodings;
//! - [`write`](mod@write): writers of records (JSON Lines, CSV, Parquet with the `parquet`
//!   feature), each on a thread of its own, and Arrow record batches;
//! - [`pcapng`]: the recording format (writer and truncation-tolerant reader);
//! - [`time`]: times as people write them (`--from +5`, ISO 8601) and dates shown where the
//!   source has a wall clock; [`energy`]: charge and energy integrated over frame times;
//! - [`serial`]: serial ports that survive being unplugged; [`clock`]: receive times;
//!   every loop that waits (a port input, an export's [`stop_on`](write::Export::stop_on))
//!   ends when a stop flag its caller passes in (an `Arc<AtomicBool>`) is set: the library
//!   installs no signal handler, so that a program embedding it keeps its own (the `hwfoc`
//!   command sets the flag on Ctrl-C and SIGTERM; the Python package's own loops check for
//!   `KeyboardInterrupt`).
//!
//! Each module has its own error type, an enum carrying what went wrong and where, whose
//! `Display` is the one-line message a person reads.

#![forbid(unsafe_op_in_unsafe_fn)]
#![warn(missing_docs)]

pub mod clock;
pub mod energy;
pub mod episode;
mod esc_numbers;
pub mod escape;
pub mod fixed;
pub mod handler;
pub mod input;
pub mod notice;
pub mod pcapng;
pub mod record;
pub mod select;
pub mod serial;
pub mod settings;
pub mod sources;
pub mod stream;
pub mod summary;
pub mod time;
pub mod write;

/// The version of the layout of the JSON objects the project prints (`hwfoc summary --json`,
/// the status and alarm lines of `hwfoc monitor --json`), as their `"schema_version"` key: it
/// goes up when a key is renamed or removed or its meaning or unit changes, not when a key is
/// added. The records of `docs/RECORD-SCHEMA.md` (JSON Lines) carry no such key: they have exactly
/// the schema's keys.
pub const JSON_SCHEMA_VERSION: u32 = 1;

pub use handler::Handler;
pub use input::{Batch, Input, InputError, InputFormat};
pub use record::Record;
pub use sources::Sources;
pub use stream::Stream;
