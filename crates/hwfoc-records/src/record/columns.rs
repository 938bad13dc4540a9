//! The column table: every column of `docs/RECORD-SCHEMA.md`, declared once, in schema order.
//!
//! Each entry gives the column's name, the type of its values (which fixes its Arrow type, its
//! nullability, its text and its Parquet storage: see [`Value`](super::Value)), its unit, and
//! how it is computed from a data frame received at `t_s` from ESC `esc` under the settings.
//! Optionally: the raw integer of the frame the value is a function of (`text key`, for `f32`
//! values: text encoders then keep the text of each value instead of formatting it again), and,
//! for a column that is not a field of [`Record`], how it is read from a record.
//!
//! From this table come the [`Record`] struct and `Record::new`, [`COLUMNS`], [`UNITS`] and a
//! zero-sized type per column implementing [`Column`](super::Column) (named as the column),
//! through which the writers derive everything by name: JSON Lines keys and CSV header, the
//! Arrow schema and record batches, the Parquet columns.
//!
//! # Adding a column
//!
//! 1. An entry here, at its place in the schema (and its row in `docs/RECORD-SCHEMA.md`).
//! 2. Its row in the copy of that table in hwfoc-io's `tests/schema.rs` (and the example line
//!    there, which has every column), the test of the schema's order, types and units.
//!
//! A column of a measurement is nullable (`Option`): null where the frame's protocol does not
//! carry the quantity ([`Telemetry::reading`] gives `None`), never 0.
//!
//! That is all the code: the writers and the other tests follow the table. A column with a
//! value type that no column had before (a new [`Value`](super::Value)) also needs that type's
//! text, Arrow and Parquet encodings (the compiler names what is missing). A Parquet column
//! gets the defaults (plain values, LZ4, no statistics, encoded last); choosing otherwise is a
//! line in `write/parquet.rs`, by name. What changes with a column is the output: the `hwfoc`
//! command's golden outputs (`crates/hwfoc-cli/tests/golden/`, the lines written out in
//! `tests/cli.rs`) and the column list of `tests/pyarrow_check.py` follow it.

use hwfoc::telemetry::{Data, Reading, Telemetry};
use hwfoc::{Protocol, Quantity, Settings};

use super::{FaultList, UtcTime};

/// The raw integer of `quantity` (the text cache's key; 0 where it is not carried, where the
/// value is null and no text is cached).
#[inline(always)]
fn raw(frame: &Data, quantity: Quantity) -> u32 {
    frame.raw(quantity).map_or(0, |raw| raw as u32)
}

/// `quantity` of `frame` in its unit under `settings`, as [`Telemetry::value`] gives it, but
/// always inlined: each column's conversion is then specialised to its quantity (a field load
/// and a multiplication per protocol). Out of line, as `Telemetry::value` was left in the release
/// build, every value of every column went through one call matching on the protocol, then on
/// the quantity: a fifth of the Parquet export's instructions (issue 31).
#[inline(always)]
fn value(frame: &Data, quantity: Quantity, settings: &Settings) -> Option<f32> {
    frame.reading(quantity, settings).and_then(Reading::value)
}

columns! {
    /// Receive time of the frame's first byte, in seconds: the source's own clock where it has
    /// one (a logic-analyser CSV's or a pcapng capture's timestamps), Unix time for live input;
    /// null where the source has no timing (a raw byte file).
    t_s: Option<f64>, "s", |t_s, _, _, _| t_s;
    /// Which ESC: the index of the input port or stream the frame came from (0-based); behind
    /// a DataLink hub or on a CAN bus, numbered by channel or place on the bus
    /// (`esc_numbers.rs`).
    esc: u8, "-", |_, esc, _, _| esc;
    /// The protocol the frame came in (`hw-foc`, `datalink`: [`Protocol::name`]),
    /// dictionary-encoded in Arrow and Parquet.
    protocol: Protocol, "-", |_, _, f, _| f.protocol();
    /// Packet number from the frame (16 bits in HW-FOC and DataLink, 24 in the older formats);
    /// null where the protocol sends none.
    packet: Option<u32>, "-", |_, _, f, _| f.packet();
    /// Input throttle, %: raw * 100 / 1024.
    throttle_in_pct: Option<f32>, "%", |_, _, f, s| value(f, Quantity::ThrottleIn, s),
        text key |f| raw(f, Quantity::ThrottleIn);
    /// Output throttle, %: raw * 100 / 1024.
    throttle_out_pct: Option<f32>, "%", |_, _, f, s| value(f, Quantity::ThrottleOut, s),
        text key |f| raw(f, Quantity::ThrottleOut);
    /// Electrical RPM: raw * 10.
    erpm: Option<u32>, "rev/min", |_, _, f, s| value(f, Quantity::Erpm, s).map(|v| v as u32);
    /// Motor (or geared output) RPM under the settings: raw * 10 / (gear ratio * pole pairs).
    rpm: Option<f32>, "rev/min", |_, _, f, s| value(f, Quantity::Rpm, s),
        text key |f| raw(f, Quantity::Rpm);
    /// Input voltage, V: raw / 10.
    voltage_v: Option<f32>, "V", |_, _, f, s| value(f, Quantity::Voltage, s),
        text key |f| raw(f, Quantity::Voltage);
    /// Input current, A: raw (signed) / current scale; negative while braking regeneratively.
    current_a: Option<f32>, "A", |_, _, f, s| value(f, Quantity::Current, s),
        text key |f| raw(f, Quantity::Current);
    /// Phase current, A: raw (signed) / current scale.
    phase_current_a: Option<f32>, "A", |_, _, f, s| value(f, Quantity::PhaseCurrent, s),
        text key |f| raw(f, Quantity::PhaseCurrent);
    /// MOSFET temperature, degC, from the ADC table; null when out of the table's range.
    mos_temp_c: Option<f32>, "degC", |_, _, f, s| value(f, Quantity::MosTemp, s),
        text key |f| raw(f, Quantity::MosTemp);
    /// Capacitor temperature, degC, from the ADC table; null when out of the table's range.
    cap_temp_c: Option<f32>, "degC", |_, _, f, s| value(f, Quantity::CapTemp, s),
        text key |f| raw(f, Quantity::CapTemp);
    /// Motor temperature, degC (HW5; null in HW-FOC and DataLink).
    motor_temp_c: Option<f32>, "degC", |_, _, f, s| value(f, Quantity::MotorTemp, s),
        text key |f| raw(f, Quantity::MotorTemp);
    /// BEC temperature, degC (HW5; null in HW-FOC and DataLink).
    bec_temp_c: Option<f32>, "degC", |_, _, f, s| value(f, Quantity::BecTemp, s),
        text key |f| raw(f, Quantity::BecTemp);
    /// BEC output voltage, V (HW5; null in HW-FOC and DataLink).
    bec_voltage_v: Option<f32>, "V", |_, _, f, s| value(f, Quantity::BecVoltage, s),
        text key |f| raw(f, Quantity::BecVoltage);
    /// BEC output current, A (HW5; null in HW-FOC and DataLink).
    bec_current_a: Option<f32>, "A", |_, _, f, s| value(f, Quantity::BecCurrent, s),
        text key |f| raw(f, Quantity::BecCurrent);
    /// The raw fault word (an unsigned 16-bit integer: HW-FOC's and DataLink's status word,
    /// HW5's fault byte, a Hobbywing CAN ESC's `status`, whose bit 14 is the direction); null
    /// where the protocol sends none (V4, V3, standard DroneCAN).
    status: Option<hwfoc::Status>, "-", |_, _, f, _| f.status();
    /// Names of the set fault bits, in bit order, as the frame's protocol names them (HW-FOC:
    /// `docs/PROTOCOL-NOTES.md`; HW5: `docs/HW5-AND-CAN.md`); derived from `status`, not a
    /// field of the record; null where `status` is.
    faults: Option<FaultList>, "-", |_, _, f, _| f.fault_word().map(|s| FaultList(s, f.protocol())),
        record |r| r.fault_word().map(|s| FaultList(s, r.protocol));
    /// The CAN node that sent the record (`hw-can`, `dronecan`); null for a serial format.
    node: Option<u8>, "-", |_, _, f, _| f.node();
    /// Age of the record's values from its ESC's second message, ms: a Hobbywing CAN ESC's
    /// `StatusMsg2` (voltage, current; its temperature until a `StatusMsg3` comes), a standard
    /// DroneCAN ESC's `StatusExtended` (throttles, motor temperature); null otherwise, and
    /// where no such message came yet.
    msg2_age_ms: Option<u32>, "ms", |_, _, f, _| f.msg2_age_ms();
    /// Age of a Hobbywing CAN ESC's `StatusMsg3` values (MOSFET, capacitor, motor
    /// temperatures), ms; null otherwise.
    msg3_age_ms: Option<u32>, "ms", |_, _, f, _| f.msg3_age_ms();
    /// `t_s` as a UTC timestamp to the microsecond, which DuckDB, polars, pandas and Spark read
    /// as a time; in Arrow and Parquet only (JSON Lines and CSV carry `t_s`; CSV's
    /// `--time iso` writes it as a date); derived from `t_s`, not a field of the record.
    time: Option<UtcTime>, "-", |t_s, _, _, _| UtcTime::from_seconds(t_s),
        record |r| UtcTime::from_seconds(r.t_s);
}
