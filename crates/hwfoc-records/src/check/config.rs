//! The analysers' thresholds: [`CheckConfig`], the configuration file's `[check]` table, with
//! documented defaults (`docs/CHECKS.md` says why each is what it is) and per-ESC overrides
//! (`[check.esc.N]`).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// A warning and a critical limit of one quantity.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Limits {
    /// At or beyond this, a warning.
    pub warn: f64,
    /// At or beyond this, critical.
    pub critical: f64,
}

impl Limits {
    /// `warn` and `critical`.
    pub const fn new(warn: f64, critical: f64) -> Limits {
        Limits { warn, critical }
    }

    /// How bad `value` is: limits whose critical value is below the warning one (a minimum
    /// voltage) judge values below them, others values above them.
    pub fn judge(&self, value: f64) -> super::Severity {
        let beyond = |limit: f64| {
            if self.critical < self.warn {
                value <= limit
            } else {
                value >= limit
            }
        };
        if beyond(self.critical) {
            super::Severity::Critical
        } else if beyond(self.warn) {
            super::Severity::Warning
        } else {
            super::Severity::Ok
        }
    }

    /// The limit a value judged `severity` crossed (the warning one for an ok value).
    pub fn crossed(&self, severity: super::Severity) -> f64 {
        match severity {
            super::Severity::Critical => self.critical,
            _ => self.warn,
        }
    }
}

/// `[check.heat]`: temperatures, judged on their peak and on sustained heat.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HeatConfig {
    /// MOSFET temperature, °C (default 95 / 115).
    pub mos_c: Limits,
    /// Capacitor temperature, °C (default 85 / 105: the capacitors' rating).
    pub cap_c: Limits,
    /// Motor temperature, °C (default 100 / 120).
    pub motor_c: Limits,
    /// Time a temperature may spend at or above its warning limit before that alone is a
    /// warning, s (default 5); twelve times as long is critical.
    pub sustained_s: f64,
    /// Rate of rise, °C per minute over a minute (default 30 / 60).
    pub rise_c_per_min: Limits,
}

impl Default for HeatConfig {
    fn default() -> HeatConfig {
        HeatConfig {
            mos_c: Limits::new(95.0, 115.0),
            cap_c: Limits::new(85.0, 105.0),
            motor_c: Limits::new(100.0, 120.0),
            sustained_s: 5.0,
            rise_c_per_min: Limits::new(30.0, 60.0),
        }
    }
}

/// `[check.imbalance]`: one ESC against its siblings at equal throttle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ImbalanceConfig {
    /// Throttle below which motors are not compared, % (default 15).
    pub min_throttle_pct: f64,
    /// Current above the siblings' median at the same throttle, % (default 40 / 70).
    pub current_pct: Limits,
    /// Rpm away from the siblings' median at the same throttle, % (default 10 / 20).
    pub rpm_pct: Limits,
    /// The window each ESC's curve is compared in, s (default 10; windows overlap by half, a
    /// deviation must hold in two in a row).
    pub window_s: f64,
}

impl Default for ImbalanceConfig {
    fn default() -> ImbalanceConfig {
        ImbalanceConfig {
            min_throttle_pct: 15.0,
            current_pct: Limits::new(40.0, 70.0),
            rpm_pct: Limits::new(10.0, 20.0),
            window_s: 10.0,
        }
    }
}

/// `[check.drift]`: against the baseline of `--baseline`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DriftConfig {
    /// Current per rpm above the baseline's, % (default 15 / 30).
    pub current_per_rpm_pct: Limits,
    /// Rpm per throttle away from the baseline's, either way, % (default 8 / 15).
    pub rpm_per_throttle_pct: Limits,
    /// The window the ESC's curve is compared in, s (default 10; windows overlap by half, a
    /// drift must hold in two in a row).
    pub window_s: f64,
}

impl Default for DriftConfig {
    fn default() -> DriftConfig {
        DriftConfig {
            current_per_rpm_pct: Limits::new(15.0, 30.0),
            rpm_per_throttle_pct: Limits::new(8.0, 15.0),
            window_s: 10.0,
        }
    }
}

/// `[check.battery]`: sag per ampere and voltage per cell under load.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BatteryConfig {
    /// Cells in series; `None` (the default) estimates them from the highest voltage (4.25 V a
    /// cell at most).
    pub cells: Option<u32>,
    /// Lowest voltage per cell under load, V (default 3.3 / 3.0: below it, read as `warn` >
    /// value).
    pub min_cell_v: Limits,
    /// Rise of the internal resistance against the baseline's or the first recording's, %
    /// (default 30 / 60).
    pub resistance_rise_pct: Limits,
}

impl Default for BatteryConfig {
    fn default() -> BatteryConfig {
        BatteryConfig {
            cells: None,
            min_cell_v: Limits::new(3.3, 3.0),
            resistance_rise_pct: Limits::new(30.0, 60.0),
        }
    }
}

/// `[check.faults]`: fault episodes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FaultsConfig {
    /// Episodes: any is a warning at 1 (the default); critical at 10.
    pub episodes: Limits,
    /// Total time in fault episodes, s (default: a warning at any, critical at 2).
    pub fault_s: Limits,
}

impl Default for FaultsConfig {
    fn default() -> FaultsConfig {
        FaultsConfig {
            episodes: Limits::new(1.0, 10.0),
            fault_s: Limits::new(f64::MIN_POSITIVE, 2.0),
        }
    }
}

/// `[check.link]`: the telemetry link.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LinkConfig {
    /// Packets lost, % of those sent (default 2 / 10).
    pub lost_pct: Limits,
    /// Checksum failures, % of frames (default 1 / 5).
    pub checksum_pct: Limits,
    /// Longest silence between two frames of a stream, s (default 0.5 / 3).
    pub dropout_s: Limits,
    /// Packets lost in any window of `window_s`, % (default 20 / 50): a burst.
    pub burst_pct: Limits,
    /// The window of a burst, s (default 5).
    pub window_s: f64,
}

impl Default for LinkConfig {
    fn default() -> LinkConfig {
        LinkConfig {
            lost_pct: Limits::new(2.0, 10.0),
            checksum_pct: Limits::new(1.0, 5.0),
            dropout_s: Limits::new(0.5, 3.0),
            burst_pct: Limits::new(20.0, 50.0),
            window_s: 5.0,
        }
    }
}

/// `[check.runtime]`: motor-on hours against a service interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RuntimeConfig {
    /// Motor-on hours between services (default 50); 1.5 times it is critical.
    pub service_interval_h: f64,
    /// Motor-on hours since the last service before these inputs (default 0; per ESC in
    /// `[check.esc.N]`).
    pub hours_before: f64,
}

impl Default for RuntimeConfig {
    fn default() -> RuntimeConfig {
        RuntimeConfig {
            service_interval_h: 50.0,
            hours_before: 0.0,
        }
    }
}

/// `[check.esc.N]`: what differs for ESC `N`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EscOverride {
    /// Its MOSFET limits.
    pub mos_c: Option<Limits>,
    /// Its capacitor limits.
    pub cap_c: Option<Limits>,
    /// Its motor's limits.
    pub motor_c: Option<Limits>,
    /// Its service interval.
    pub service_interval_h: Option<f64>,
    /// Its motor-on hours since its last service before these inputs.
    pub hours_before: Option<f64>,
}

/// The `[check]` table: every analyser's thresholds.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CheckConfig {
    /// Heat.
    pub heat: HeatConfig,
    /// Imbalance between motors.
    pub imbalance: ImbalanceConfig,
    /// Drift from the baseline.
    pub drift: DriftConfig,
    /// Battery.
    pub battery: BatteryConfig,
    /// Faults.
    pub faults: FaultsConfig,
    /// Link.
    pub link: LinkConfig,
    /// Runtime.
    pub runtime: RuntimeConfig,
    /// Per-ESC overrides, by ESC number.
    pub esc: BTreeMap<String, EscOverride>,
}

impl CheckConfig {
    /// The heat limits of ESC `esc`: its overrides over `[check.heat]`.
    pub fn heat_of(&self, esc: usize) -> HeatConfig {
        let mut heat = self.heat;
        if let Some(o) = self.esc.get(&esc.to_string()) {
            heat.mos_c = o.mos_c.unwrap_or(heat.mos_c);
            heat.cap_c = o.cap_c.unwrap_or(heat.cap_c);
            heat.motor_c = o.motor_c.unwrap_or(heat.motor_c);
        }
        heat
    }

    /// The runtime limits of ESC `esc`: its overrides over `[check.runtime]`.
    pub fn runtime_of(&self, esc: usize) -> RuntimeConfig {
        let mut runtime = self.runtime;
        if let Some(o) = self.esc.get(&esc.to_string()) {
            runtime.service_interval_h = o.service_interval_h.unwrap_or(runtime.service_interval_h);
            runtime.hours_before = o.hours_before.unwrap_or(runtime.hours_before);
        }
        runtime
    }
}
