//! What an analyser finds: a [`Finding`], with its [`Severity`], the ESC or vehicle it is about,
//! the time window, the values that are its evidence and the threshold they crossed.

use std::fmt;

use serde::{Deserialize, Serialize};

/// How bad a finding is. Ordered: `Ok < Warning < Critical`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    /// Measured, and within its limits: the figure is shown as evidence that it was looked at.
    Ok,
    /// Beyond the warning threshold: look at it before the next flight.
    Warning,
    /// Beyond the critical threshold: do not fly until it is understood.
    Critical,
}

impl Severity {
    /// `ok`, `warning` or `critical`: as the text and the JSON say it.
    pub fn name(self) -> &'static str {
        match self {
            Severity::Ok => "ok",
            Severity::Warning => "warning",
            Severity::Critical => "critical",
        }
    }

    /// The exit status of `hwfoc check` when this is the worst finding: 0, 1 or 2.
    pub fn exit_code(self) -> u8 {
        match self {
            Severity::Ok => 0,
            Severity::Warning => 1,
            Severity::Critical => 2,
        }
    }
}

impl fmt::Display for Severity {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Which analyser made a finding (one file each under `check/`; `docs/CHECKS.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Analyser {
    /// MOSFET, capacitor and motor temperatures: peak, 95th percentile, time above the
    /// warning limit, rate of rise.
    Heat,
    /// One ESC's current or rpm far from its siblings' at equal throttle.
    Imbalance,
    /// Rpm per throttle and current per rpm against a fitted baseline.
    Drift,
    /// Voltage sag per ampere (internal resistance) and minimum voltage per cell under load.
    Battery,
    /// Fault episodes by kind.
    Faults,
    /// Lost packets, checksum failures, dropouts.
    Link,
    /// Motor-on hours against a service interval.
    Runtime,
}

impl Analyser {
    /// Every analyser, in the order they run and are reported.
    pub const ALL: [Analyser; 7] = [
        Analyser::Heat,
        Analyser::Imbalance,
        Analyser::Drift,
        Analyser::Battery,
        Analyser::Faults,
        Analyser::Link,
        Analyser::Runtime,
    ];

    /// Its name, as the text and the JSON say it (`heat`, `imbalance`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Analyser::Heat => "heat",
            Analyser::Imbalance => "imbalance",
            Analyser::Drift => "drift",
            Analyser::Battery => "battery",
            Analyser::Faults => "faults",
            Analyser::Link => "link",
            Analyser::Runtime => "runtime",
        }
    }
}

impl fmt::Display for Analyser {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The ESC a finding is about.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EscId {
    /// Its number in the inputs' ESC table (as `hwfoc summary` numbers it).
    pub number: usize,
    /// Its label, as every command names it (`flight.pcapng: ttyUSB1 (ESC 1)`).
    pub label: String,
    /// Where it is on the vehicle, the same in every recording of it: its port (a
    /// recording's interface name, a serial port) and, on a hub or a CAN bus, its place
    /// (`ttyUSB1`, `can0#2`). A baseline is kept by position.
    pub position: String,
}

/// When a finding happened, in seconds on its input's clock (the nominal frame period times the
/// frame index for an input without receive times).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Span {
    /// Its first moment.
    pub start_s: f64,
    /// Its last moment.
    pub end_s: f64,
}

/// One figure of a finding's evidence.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Value {
    /// What it is (`peak`, `p95`, `time_above`, ...).
    pub name: String,
    /// Its value.
    pub value: f64,
    /// Its unit (`degC`, `s`, `A`, `%`, ...).
    pub unit: String,
}

impl Value {
    /// A value named `name` in `unit`.
    pub fn new(name: &str, value: f64, unit: &str) -> Value {
        Value {
            name: name.to_string(),
            value,
            unit: unit.to_string(),
        }
    }
}

/// A threshold a value was judged against.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Threshold {
    /// The value it limits (one of the finding's [`Value`] names).
    pub name: String,
    /// The limit.
    pub value: f64,
    /// Its unit.
    pub unit: String,
}

/// What an analyser found about one ESC, or a vehicle (a recording's ESCs together), with its
/// evidence.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Finding {
    /// The analyser that made it.
    pub analyser: Analyser,
    /// How bad it is.
    pub severity: Severity,
    /// The ESC it is about; `None` for a finding about a whole vehicle.
    pub esc: Option<EscId>,
    /// The recording (vehicle and flight) it is in, as its inputs name it.
    pub recording: String,
    /// When it happened, where it has a time.
    pub window: Option<Span>,
    /// Its evidence.
    pub values: Vec<Value>,
    /// The threshold crossed (for a warning or a critical finding), or the warning threshold
    /// the values were judged against (for an ok one).
    pub threshold: Option<Threshold>,
    /// One line for a person.
    pub message: String,
}

impl Finding {
    /// An ok finding of `analyser` about the ESC of `series`, without evidence yet.
    pub fn about(analyser: Analyser, series: &super::EscSeries) -> Finding {
        Finding {
            analyser,
            severity: Severity::Ok,
            esc: Some(series.esc.clone()),
            recording: series.recording.clone(),
            window: None,
            values: Vec::new(),
            threshold: None,
            message: String::new(),
        }
    }

    /// With the value `name` in `unit`.
    pub fn value(mut self, name: &str, value: f64, unit: &str) -> Finding {
        self.values.push(Value::new(name, value, unit));
        self
    }

    /// Judged `severity` against the limit `limit` of value `name`.
    pub fn judged(mut self, severity: Severity, name: &str, limit: f64, unit: &str) -> Finding {
        self.severity = severity;
        self.threshold = Some(Threshold {
            name: name.to_string(),
            value: limit,
            unit: unit.to_string(),
        });
        self
    }

    /// The worst severity of `findings` ([`Severity::Ok`] when there are none).
    pub fn worst(findings: &[Finding]) -> Severity {
        findings
            .iter()
            .map(|f| f.severity)
            .max()
            .unwrap_or(Severity::Ok)
    }
}
