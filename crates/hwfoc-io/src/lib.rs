//! Everything between the bytes on an ESC's telemetry wire and the records every output shows.
//!
//! The codec (`hwfoc`) turns bytes into frames; this library does what lies around it, for every
//! front end alike (the `hwfoc` command, bridges, bindings). What needs no operating system
//! (formats, streams, ESC numbering, the record, the summary, the checks) is `hwfoc-records`,
//! re-exported here at the same paths; this crate adds files, standard input, live ports (read
//! through `hwfoc-ports`, whose serial ports, CAN adapters and clocks are named from that
//! crate) and the writers' threads. Its surface, by role (the items at the crate root, the rest
//! in the public modules named):
//!
//! - inputs: where bytes come from (raw files, logic-analyser CSV exports, pcapng recordings,
//!   serial ports, standard input), an [`Input`] whose [`InputFormat`] is detected from the
//!   content, read as [`Batch`]es of bytes with their receive times where the source has a
//!   clock; files, standard input and ports are opened through [`OpenInput`];
//! - decoding: [`Sources`] and [`Stream`] ([`PortStreams`] for live ports), the one path from
//!   timed bytes to frames, a decoding stream per ESC, each converted under its own settings
//!   ([`SettingsMap`]); the [`Handler`] seam through which records reach a front end;
//! - [`record`]: the [`Record`] of `docs/RECORD-SCHEMA.md` (one row per data frame, physical
//!   units), its columns declared once in one table, and its text encodings; [`Selection`]: the
//!   records kept, by ESC and time [`Window`];
//! - [`write`](mod@write): writers of records (JSON Lines, CSV, Parquet with the `parquet`
//!   feature), each on a thread of its own, and Arrow record batches;
//! - [`summary`]: what a run of inputs contained, as text or JSON;
//! - [`pcapng`]: the recording format (writer and truncation-tolerant reader);
//! - [`time`]: times as people write them (`--from +5`, ISO 8601) and dates shown where the
//!   source has a wall clock; [`energy`]: charge and energy integrated over frame times;
//! - every loop that waits (a port input, an export's [`stop_on`](write::Export::stop_on))
//!   ends when a stop flag its caller passes in (an `Arc<AtomicBool>`) is set: the library
//!   installs no signal handler, so that a program embedding it keeps its own (the `hwfoc`
//!   command sets the flag on Ctrl-C and SIGTERM; the Python package's own loops check for
//!   `KeyboardInterrupt`).
//!
//! Each part has its own error type, an enum carrying what went wrong and where, whose
//! `Display` is the one-line message a person reads.
//!
//! # Reading records
//!
//! An input (here bytes in memory: three HW-FOC data frames) read by [`Sources`], whose records
//! a [`Handler`] collects:
//!
//! ```
//! use hwfoc::Settings;
//! use hwfoc::foc::DataFrame;
//! use hwfoc_io::{Handler, Input, InputError, Record, Sources};
//!
//! let mut bytes = Vec::new();
//! for packet in 0..3 {
//!     let frame = DataFrame { packet, voltage_raw: 247, ..DataFrame::default() };
//!     bytes.extend_from_slice(&frame.encode());
//! }
//!
//! /// Keeps every record.
//! struct Collect(Vec<Record>);
//!
//! impl Handler for Collect {
//!     type Error = InputError;
//!     fn record(&mut self, record: &Record) {
//!         self.0.push(*record);
//!     }
//! }
//!
//! let input = Input::from_memory("example", bytes)?;
//! let mut sources = Sources::new(vec![input], Settings::default());
//! let mut records = Collect(Vec::new());
//! sources.run(&mut records)?;
//!
//! assert_eq!(records.0.len(), 3);
//! assert_eq!(records.0[0].esc, 0);
//! assert_eq!(records.0[2].voltage_v, Some(24.7));
//! assert_eq!(records.0[2].protocol, hwfoc::Protocol::HwFoc);
//! # Ok::<(), InputError>(())
//! ```
//!
//! # Writing records
//!
//! An [`Export`](write::Export) is a [`Handler`] too: the same run written to a CSV file, which
//! appears under its name when the export finishes.
//!
//! ```
//! use hwfoc::Settings;
//! use hwfoc::foc::DataFrame;
//! use hwfoc_io::write::{Export, ExportError, OutputFormat, Provenance};
//! use hwfoc_io::{Input, Sources};
//!
//! let frame = DataFrame { voltage_raw: 247, ..DataFrame::default() };
//! let input = Input::from_memory("example", frame.encode().repeat(2))?;
//! let mut sources = Sources::new(vec![input], Settings::default());
//!
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("records.csv");
//! let provenance = Provenance {
//!     settings: Settings::default(),
//!     overrides: Vec::new(),
//!     inputs: vec!["example".to_string()],
//!     filter: String::new(),
//!     csv_comment: false,
//!     csv_time_iso: false,
//! };
//! let mut export = Export::create(OutputFormat::Csv, path.to_str(), false, provenance)?;
//! sources.run(&mut export)?;
//! export.finish(Vec::new())?;
//!
//! let text = std::fs::read_to_string(&path).unwrap();
//! assert!(text.starts_with("t_s,esc,"));
//! assert_eq!(text.lines().count(), 3); // the header and two records
//! # Ok::<(), ExportError>(())
//! ```
//!
//! # Paths
//!
//! Each item has one public path: those above. The modules behind the crate-root items are
//! private, and so are the helpers the public modules use among themselves
//! (`tests/surface.rs` lists the whole surface):
//!
//! ```compile_fail,E0603
//! use hwfoc_io::sources::Sources;
//! ```
//!
//! ```compile_fail,E0603
//! use hwfoc_io::write::metadata::schema_with;
//! ```

#![forbid(unsafe_op_in_unsafe_fn)]
#![warn(missing_docs)]

// Modules whose names are a namespace for their items (`time::parse`, `summary::Summary`,
// `pcapng::Reader`, `write::arrow::schema`): public, each exporting only its public items.
pub mod record;
pub mod write;
pub use hwfoc_records::{check, energy, pcapng, summary, time};

// Modules whose public items are re-exported below, by role.
mod input;

// `hwfoc-records`' modules as this crate's own modules name them.
mod handler {
    pub use hwfoc_records::Handler;
}
mod select {
    pub use hwfoc_records::Selection;
    #[cfg(test)]
    pub use hwfoc_records::Window;
}
mod settings {
    #[cfg(test)]
    pub use hwfoc_records::SettingsMap;
    pub use hwfoc_records::{SettingsPatch, settings_fields as fields, settings_json};
}
mod sources {
    pub use hwfoc_records::Sources;
}

/// The versions of the JSON objects' layout and of the record schema (`hwfoc-records`').
pub use hwfoc_records::{JSON_SCHEMA_VERSION, RECORD_SCHEMA_VERSION};

// The crate-root items, by role (a comment, not a doc comment: rustdoc would prepend a doc
// comment on a re-export to the docs of each item it names).

// Inputs: where bytes come from, each opened as an `Input` whose format is detected from its
// content, read as `Batch`es of bytes with their receive times; files, standard input and
// ports opened by `OpenInput`.
pub use hwfoc_records::{Batch, Input, InputError, InputFormat, Looks, ONLY_ZEROS_LIMIT};
pub use input::{OpenInput, read_small_file};

// Decoding: `Sources` reads inputs, merges them in time order and decodes each ESC's bytes
// with a `Stream` (`PortStreams` for live ports), handing frames to a `Handler`.
pub use hwfoc_records::{
    Both, CanLink, Esc, EscEntry, EscKey, EscTable, Figure, Handler, InputInfo, LaterPart,
    LinkStats, MAX_ESCS, MAX_QUEUED, Place, PortStreams, Recording, SILENCE_S, Sources, Stream,
    WireKind,
};

// Settings: each ESC's conversion settings (`hwfoc::Settings`), as given per ESC and shown.
pub use hwfoc_records::{SettingValue, SettingsMap, SettingsPatch, settings_json};

// Records: the record of `docs/RECORD-SCHEMA.md` (`record` has its columns and text
// encodings).
pub use hwfoc_records::Record;

// Selection of records by ESC and time window.
pub use hwfoc_records::{EmptyWindow, Selection, Window, filter_text, no_frame_in_window};

// What an input tells a person while it is read (a port unplugged, a damaged recording).
pub use hwfoc_records::Notice;

// Text helpers: a name shown safely (`Escaped`), a number with fixed decimals (`Fixed`).
pub use hwfoc_records::{Escaped, Fixed};
