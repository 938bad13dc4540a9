//! Hobbywing ESC telemetry from bytes held in memory to records: no operating system in it (no
//! files, ports, threads, signals or clocks read), so that it builds for
//! `wasm32-unknown-unknown` as for the `hwfoc` command. The codec (`hwfoc`) turns bytes into
//! frames; this crate does what lies around it, for every front end alike. `hwfoc-io` adds
//! files, standard input, serial ports, CAN sockets and the writers' threads above it. Its
//! surface, by role (the items at the crate root, the rest in the public modules named):
//!
//! - inputs: bytes in memory or any reader (raw bytes, logic-analyser CSV exports, pcapng
//!   recordings, CAN logs) as an [`Input`] whose [`InputFormat`] is detected from the content,
//!   read as [`Batch`]es of bytes with their receive times where the source has a clock; a
//!   file, which the input opens again when it is read, is a [`Reopen`] of the crate above;
//! - decoding: [`Sources`] and [`Stream`] ([`PortStreams`] for live ports), the one path from
//!   timed bytes to frames, a decoding stream per ESC, each converted under its own settings
//!   ([`SettingsMap`]); the [`Handler`] seam through which records reach a front end;
//! - [`record`]: the [`Record`] of `docs/RECORD-SCHEMA.md` (one row per data frame, physical
//!   units), its columns declared once in one table, and its text encodings; [`Selection`]: the
//!   records kept, by ESC and time [`Window`];
//! - [`summary`]: what a run of inputs contained, as text or JSON; [`check`]: the health checks;
//! - [`pcapng`]: the recording format (writer over any `std::io::Write` and
//!   truncation-tolerant reader);
//! - [`time`]: times as people write them (`--from +5`, ISO 8601) and dates shown where the
//!   source has a wall clock; [`energy`]: charge and energy integrated over frame times;
//!   [`clock`]: a chunk's bytes timed from its receive time;
//! - [`can`]: CAN frames as records (`candump` logs); [`serial`]: what serial ports hand over, as data.
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
//! use hwfoc_records::{Handler, Input, InputError, Record, Sources};
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

#![forbid(unsafe_op_in_unsafe_fn)]
#![warn(missing_docs)]

// Modules whose names are a namespace for their items (`time::parse`, `pcapng::Reader`,
// `record::columns`): public, each exporting only its public items.
pub mod can;
pub mod check;
pub mod clock;
pub mod energy;
pub mod pcapng;
pub mod record;
pub mod serial;
pub mod summary;
pub mod time;

// Modules whose public items are re-exported below, by role.
mod episode;
mod esc_numbers;
mod esc_table;
mod escape;
mod fixed;
mod handler;
mod input;
mod notice;
mod select;
mod settings;
mod sources;
mod stream;

/// The version of the layout of the JSON objects the project prints (`hwfoc summary --json`,
/// the status and alarm lines of `hwfoc monitor --json`), as their `"schema_version"` key: it
/// goes up when a key is renamed or removed or its meaning or unit changes, not when a key is
/// added. The records of `docs/RECORD-SCHEMA.md` (JSON Lines) carry no such key: they have exactly
/// the schema's keys.
///
/// Version 2 gave a link's figures one set of names everywhere (`checksum_failures`,
/// `lost_packets`, `duplicate_packets`, `rejected_candidates`): the summary's `hubs` had
/// `crc_failures`, `lost_frames` and `duplicate_frames`; its `link.can` repeated the link's
/// figures as `missed_transfers`, `duplicates` and `crc_errors` (gone); a status line of
/// `monitor --json` had `lost`, `duplicates` and `rejected_frames`, and now has every figure of
/// the summary's `link` object; the link finding of `hwfoc check --json` gives its share of
/// packets lost (%) as `lost_packets`, not `lost`.
pub const JSON_SCHEMA_VERSION: u32 = 2;

/// The version of the record schema of `docs/RECORD-SCHEMA.md` (its columns, their types and
/// nullability), recorded with the outputs that carry metadata: the Parquet export's key-value
/// metadata and the Python package's Arrow schema, key `record_schema_version`. Version 2 added
/// `protocol`, the BEC and motor columns, a 32-bit nullable `packet` and null for what a format
/// does not carry; version 3 the CAN bus's `node`, `msg2_age_ms` and `msg3_age_ms` (the
/// document's "Changes").
pub const RECORD_SCHEMA_VERSION: u32 = 4;

// The crate-root items, by role (a comment, not a doc comment: rustdoc would prepend a doc
// comment on a re-export to the docs of each item it names).

// Inputs: where bytes come from, each opened as an `Input` whose format is detected from its
// content, read as `Batch`es of bytes with their receive times.
pub use input::{
    BATCH, Batch, Beside, BlockRead, Input, InputError, InputFormat, Looks, ONLY_ZEROS_LIMIT,
    ReadAt, RegularFile, Reopen, Source, read_some,
};

// Decoding: `Sources` reads inputs, merges them in time order and decodes each ESC's bytes
// with a `Stream` (`PortStreams` for live ports), handing frames to a `Handler`.
pub use esc_numbers::MAX_ESCS;
pub use esc_table::{EscEntry, EscKey, EscTable, Place, Recording};
pub use handler::{Both, Handler, LaterPart};
pub use sources::{Esc, InputInfo, MAX_QUEUED, Sources};
pub use stream::{
    CanLink, FIGURES, FRAME_FIGURES, Figure, LinkStats, PortStreams, SILENCE_S, Stream, WireKind,
};

// Settings: each ESC's conversion settings (`hwfoc::Settings`), as given per ESC and shown.
pub use settings::{
    SettingValue, SettingsMap, SettingsPatch, fields as settings_fields, settings_json,
};

// Records: the record of `docs/RECORD-SCHEMA.md` (`record` has its columns and text
// encodings).
pub use record::Record;

// Selection of records by ESC and time window.
pub use select::{EmptyWindow, Selection, Window, filter_text, no_frame_in_window};

// What an input tells a person while it is read (a port unplugged, a damaged recording).
pub use notice::Notice;

// Text helpers: a name shown safely (`Escaped`), a number with fixed decimals (`Fixed`).
pub use escape::Escaped;
pub use fixed::Fixed;
