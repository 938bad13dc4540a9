//! The public surface of `hwfoc-io`: this list is the API.
//!
//! Every item a user of the crate may name is imported here by its public path, grouped as
//! `lib.rs` groups them; the test does not compile when one goes missing or moves. An item added
//! to the surface is added here, so that a change of the API is a change of this file, seen in
//! review. Internals are private (`pub(crate)` or in a private module): the `compile_fail`
//! examples in `lib.rs` check a few of them.

#![allow(unused_imports)]

// Inputs.
use hwfoc_io::{Batch, Input, InputError, InputFormat, Looks, OpenInput, read_small_file};

// Decoding.
use hwfoc_io::{
    Both, Esc, Handler, InputInfo, LaterPart, LinkStats, MAX_ESCS, MAX_QUEUED, PortStreams,
};
use hwfoc_io::{SILENCE_S, Sources, Stream, WireKind};

// Settings.
use hwfoc_io::{SettingValue, SettingsMap, SettingsPatch, settings_json};

// Records and their selection.
use hwfoc_io::Record;
use hwfoc_io::record::columns::{self, COUNT, visit};
use hwfoc_io::record::{COLUMNS, Column, FaultList, TextEncoder, UNITS, Value, Visitor};
use hwfoc_io::{EmptyWindow, Selection, Window, filter_text, no_frame_in_window};

// Notices and text helpers.
use hwfoc_io::{Escaped, Fixed, JSON_SCHEMA_VERSION, Notice, RECORD_SCHEMA_VERSION};

// Writers.
use hwfoc_io::write::arrow::{ArrowValue, RecordBatchBuilder, record_batch, schema};
use hwfoc_io::write::metadata::{ESC_SETTINGS, ESCS, RECORD_SCHEMA_VERSION_KEY};
use hwfoc_io::write::metadata::{esc_settings_json, escs_json};
use hwfoc_io::write::{Export, ExportError, OutputFormat, Provenance, WriteError};
use hwfoc_io::write::{FileId, Staging, create_file, same_file};

// Check.
use hwfoc_io::check::{Analyser, EscId, Finding, Severity, Span, Threshold, Value as CheckValue};
use hwfoc_io::check::{
    Baseline, Check, EscBaseline, EscSeries, LinkTotals, Sample, analyse, check,
};
use hwfoc_io::check::{BatteryConfig, CheckConfig, DriftConfig, EscOverride, FaultsConfig};
use hwfoc_io::check::{HeatConfig, ImbalanceConfig, Limits, LinkConfig, RuntimeConfig};

// Summary.
use hwfoc_io::summary::{Episode, Mark, NO_FRAMES, Report, Summary};
use hwfoc_io::summary::{device_json, esc_label, no_frames};

// Recordings.
use hwfoc_io::pcapng::LINKTYPE_CAN_SOCKETCAN;
use hwfoc_io::pcapng::{Damage, Interface, LINKTYPE, MAGIC, MAX_CHUNK, Packet, Reader, Writer};

// Times and energy (the live devices, their clocks included, are hwfoc-ports': its own
// surface test).
use hwfoc_io::energy::{Energy, drawn_w, nominal_period_s, power_w};
use hwfoc_io::time::{Clock, Time, TimeError, iso8601, iso8601_local, parse, span_text};

/// The constants of the surface, against the documents that fix them (`docs/RECORD-SCHEMA.md`,
/// `docs/REFERENCE.md`, the pcapng format, the HW-FOC baud rate).
#[test]
fn the_surface_constants_are_those_of_the_specs() {
    assert_eq!(COLUMNS.len(), COUNT);
    assert_eq!(UNITS.len(), COUNT);
    assert_eq!(COLUMNS[..4], ["t_s", "esc", "protocol", "packet"]);
    // The pcapng section header block's type, and the link type of `docs/REFERENCE.md` (USER0).
    assert_eq!(MAGIC, [0x0A, 0x0D, 0x0D, 0x0A]);
    assert_eq!(LINKTYPE, 147);
    assert_eq!(LINKTYPE_CAN_SOCKETCAN, 227);
    assert_eq!(nominal_period_s(None), 0.05);
    assert_eq!(JSON_SCHEMA_VERSION, 2);
    assert_eq!(RECORD_SCHEMA_VERSION, 4);
    assert_eq!(RECORD_SCHEMA_VERSION_KEY, "record_schema_version");
    // The record's `esc` column is a `u8`: as many ESCs as it can number.
    assert_eq!(MAX_ESCS, usize::from(u8::MAX) + 1);
}
