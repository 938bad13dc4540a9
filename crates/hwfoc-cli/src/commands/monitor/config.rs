//! The monitor's settings: built-in defaults, overridden by an optional TOML file, overridden by
//! flags.
//!
//! The file is `hwfoc/monitor.toml` in the user's configuration directory
//! (`~/.config/hwfoc/monitor.toml` on Linux, `~/Library/Application Support/hwfoc/monitor.toml`
//! on macOS, `%APPDATA%\hwfoc\monitor.toml` on Windows), or the one named by `--config`. Every
//! key is optional; unknown keys are errors (a misspelt threshold must not be silently ignored):
//!
//! ```toml
//! baud = 19200
//! current_scale = 64.0
//! pole_pairs = 7
//! gear_ratio = 1.0
//! record_dir = "/home/pi/recordings"
//!
//! [alarms]
//! mos_warning_c = 90
//! mos_critical_c = 105
//! cap_warning_c = 85
//! cap_critical_c = 100
//! temp_hysteresis_c = 5
//! battery_cells = 12        # default: detected from the first voltage seen
//! cell_warning_v = 3.5
//! cell_critical_v = 3.3
//! cell_hysteresis_v = 0.1
//! stale_after_s = 1.0
//! fault_hold_s = 0.5
//!
//! [[esc]]
//! port = "/dev/serial/by-id/usb-FTDI_FT232R_USB_UART_A50285BI-if00-port0"
//! label = "front left"
//! ```
//!
//! Ports listed under `[[esc]]` are watched when none are named on the command line; a label
//! belongs to its port wherever that port is named.

use std::path::{Path, PathBuf};

use hwfoc::Settings;
use serde::Deserialize;

use super::alarms::Threshold;
use crate::error::CliError;
use hwfoc_io::InputError;
use hwfoc_io::input::read_small_file;
use hwfoc_io::serial;

/// The file's layout.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct File {
    baud: Option<u32>,
    current_scale: Option<f32>,
    pole_pairs: Option<u16>,
    gear_ratio: Option<f32>,
    record_dir: Option<PathBuf>,
    #[serde(default)]
    alarms: AlarmKeys,
    #[serde(default)]
    esc: Vec<EscEntry>,
}

/// The `[alarms]` table (and the matching flags).
#[derive(Debug, Default, Clone, Deserialize, clap::Args)]
#[serde(deny_unknown_fields)]
pub struct AlarmKeys {
    /// MOSFET temperature warning level, degC [default: 90].
    #[arg(long, value_name = "DEGC", help_heading = "Alarms")]
    pub mos_warning_c: Option<f64>,
    /// MOSFET temperature critical level, degC [default: 105].
    #[arg(long, value_name = "DEGC", help_heading = "Alarms")]
    pub mos_critical_c: Option<f64>,
    /// Capacitor temperature warning level, degC [default: 85].
    #[arg(long, value_name = "DEGC", help_heading = "Alarms")]
    pub cap_warning_c: Option<f64>,
    /// Capacitor temperature critical level, degC [default: 100].
    #[arg(long, value_name = "DEGC", help_heading = "Alarms")]
    pub cap_critical_c: Option<f64>,
    /// How far a temperature must fall below a level to leave it, degC [default: 5].
    #[arg(long, value_name = "DEGC", help_heading = "Alarms")]
    pub temp_hysteresis_c: Option<f64>,
    /// Battery cells in series, for the low-voltage levels [default: detected from the first
    /// voltage seen, as a full LiPo].
    #[arg(long, value_name = "N", help_heading = "Alarms")]
    pub battery_cells: Option<u8>,
    /// Low-voltage warning level per cell, V [default: 3.5].
    #[arg(long, value_name = "V", help_heading = "Alarms")]
    pub cell_warning_v: Option<f64>,
    /// Low-voltage critical level per cell, V [default: 3.3].
    #[arg(long, value_name = "V", help_heading = "Alarms")]
    pub cell_critical_v: Option<f64>,
    /// How far the voltage must rise above a level to leave it, V per cell [default: 0.1].
    #[arg(long, value_name = "V", help_heading = "Alarms")]
    pub cell_hysteresis_v: Option<f64>,
    /// An ESC is stale after this long without a frame, seconds [default: 1].
    #[arg(long, value_name = "S", help_heading = "Alarms")]
    pub stale_after_s: Option<f64>,
    /// A status-bit alarm clears after the bit has been off this long, seconds [default: 0.5].
    #[arg(long, value_name = "S", help_heading = "Alarms")]
    pub fault_hold_s: Option<f64>,
}

/// One `[[esc]]` entry.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct EscEntry {
    port: String,
    label: Option<String>,
}

/// The alarm levels in force.
#[derive(Debug, Clone, PartialEq)]
pub struct Limits {
    /// MOSFET temperature, degC.
    pub mos: Threshold,
    /// Capacitor temperature, degC.
    pub cap: Threshold,
    /// Cells in series, if known (otherwise detected per ESC).
    pub cells: Option<u8>,
    /// Low-voltage levels per cell, V (hysteresis per cell too).
    pub cell: Threshold,
    /// Seconds without a frame before an ESC is stale.
    pub stale_after_s: f64,
    /// Seconds a status bit must stay off before its alarm clears.
    pub fault_hold_s: f64,
}

impl Limits {
    /// The low-voltage levels for a battery of `cells` cells.
    pub fn voltage(&self, cells: u8) -> Threshold {
        let n = f64::from(cells);
        Threshold::low(
            self.cell.warning * n,
            self.cell.critical * n,
            self.cell.hysteresis * n,
        )
    }
}

/// Everything the monitor is set to.
#[derive(Debug, Clone)]
pub struct Config {
    /// Where the configuration file was read from, if one was.
    pub file: Option<PathBuf>,
    /// Conversion settings.
    pub settings: Settings,
    /// Baud rate of the ports.
    pub baud: u32,
    /// Ports from the file, when none are named on the command line.
    pub ports: Vec<String>,
    /// Labels by port name, from the file.
    labels: Vec<(String, String)>,
    /// Where recordings started with the `r` key go.
    pub record_dir: PathBuf,
    /// Alarm levels.
    pub limits: Limits,
}

/// What the command line says (each `None` leaves the file's value or the default).
#[derive(Debug, Default, Clone)]
pub struct Overrides {
    /// `--config FILE`.
    pub config: Option<PathBuf>,
    /// `--no-config`.
    pub no_config: bool,
    /// `--baud`.
    pub baud: Option<u32>,
    /// `--current-scale`.
    pub current_scale: Option<f32>,
    /// `--pole-pairs`.
    pub pole_pairs: Option<u16>,
    /// `--gear-ratio`.
    pub gear_ratio: Option<f32>,
    /// `--record-dir`.
    pub record_dir: Option<PathBuf>,
    /// The alarm flags.
    pub alarms: AlarmKeys,
}

/// The per-user configuration file, whether or not it exists.
pub fn default_path() -> Option<PathBuf> {
    dirs::config_dir().map(|d| d.join("hwfoc").join("monitor.toml"))
}

impl Config {
    /// Reads the configuration file (the one named, or the per-user one if it exists) and
    /// applies the flags over it.
    pub fn load(flags: &Overrides) -> Result<Config, CliError> {
        let path = match (&flags.config, flags.no_config) {
            (_, true) => None,
            (Some(path), false) => Some(path.clone()),
            (None, false) => default_path().filter(|p| p.is_file()),
        };
        let file = match &path {
            Some(path) => read_file(path)?,
            None => File::default(),
        };
        Config::merge(path, file, flags)
    }

    fn merge(path: Option<PathBuf>, file: File, flags: &Overrides) -> Result<Config, CliError> {
        let origin = |key: &str| match &path {
            Some(p) => format!("{} ({key})", p.display()),
            None => format!("--{}", key.replace('_', "-")),
        };
        let settings = Settings::new(
            flags
                .current_scale
                .or(file.current_scale)
                .unwrap_or(Settings::DEFAULT.current_scale),
            flags
                .pole_pairs
                .or(file.pole_pairs)
                .unwrap_or(Settings::DEFAULT.pole_pairs),
            flags
                .gear_ratio
                .or(file.gear_ratio)
                .unwrap_or(Settings::DEFAULT.gear_ratio),
        )
        .map_err(CliError::Settings)?;
        let baud = flags.baud.or(file.baud).unwrap_or(serial::DEFAULT_BAUD);
        if baud == 0 {
            return Err(invalid(origin("baud"), "the baud rate must be more than 0"));
        }
        let a = &flags.alarms;
        let f = &file.alarms;
        let pick =
            |flag: Option<f64>, file: Option<f64>, default: f64| flag.or(file).unwrap_or(default);
        let mos = Threshold::high(
            pick(a.mos_warning_c, f.mos_warning_c, 90.0),
            pick(a.mos_critical_c, f.mos_critical_c, 105.0),
            pick(a.temp_hysteresis_c, f.temp_hysteresis_c, 5.0),
        );
        let cap = Threshold::high(
            pick(a.cap_warning_c, f.cap_warning_c, 85.0),
            pick(a.cap_critical_c, f.cap_critical_c, 100.0),
            mos.hysteresis,
        );
        let cell = Threshold::low(
            pick(a.cell_warning_v, f.cell_warning_v, 3.5),
            pick(a.cell_critical_v, f.cell_critical_v, 3.3),
            pick(a.cell_hysteresis_v, f.cell_hysteresis_v, 0.1),
        );
        let limits = Limits {
            mos,
            cap,
            cells: a.battery_cells.or(f.battery_cells),
            cell,
            stale_after_s: pick(a.stale_after_s, f.stale_after_s, 1.0),
            fault_hold_s: pick(a.fault_hold_s, f.fault_hold_s, 0.5),
        };
        for (key, th) in [("mos", &limits.mos), ("cap", &limits.cap)] {
            if !(th.warning.is_finite() && th.critical.is_finite() && th.warning < th.critical) {
                return Err(invalid(
                    origin(&format!("{key}_critical_c")),
                    format!(
                        "the critical level ({} degC) must be above the warning level ({} degC)",
                        th.critical, th.warning
                    ),
                ));
            }
        }
        if !(limits.cell.critical > 0.0 && limits.cell.critical < limits.cell.warning) {
            return Err(invalid(
                origin("cell_critical_v"),
                format!(
                    "the critical level ({} V) must be above 0 and below the warning level ({} V)",
                    limits.cell.critical, limits.cell.warning
                ),
            ));
        }
        for (key, value) in [
            ("temp_hysteresis_c", limits.mos.hysteresis),
            ("cell_hysteresis_v", limits.cell.hysteresis),
            ("fault_hold_s", limits.fault_hold_s),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(invalid(origin(key), format!("{value} must be 0 or more")));
            }
        }
        if !(limits.stale_after_s.is_finite() && limits.stale_after_s > 0.0) {
            return Err(invalid(
                origin("stale_after_s"),
                format!("{} must be more than 0", limits.stale_after_s),
            ));
        }
        if limits.cells == Some(0) {
            return Err(invalid(
                origin("battery_cells"),
                "there must be at least one cell",
            ));
        }
        Ok(Config {
            file: path,
            settings,
            baud,
            ports: file.esc.iter().map(|e| e.port.clone()).collect(),
            labels: file
                .esc
                .into_iter()
                .filter_map(|e| Some((e.port, e.label?)))
                .collect(),
            record_dir: flags
                .record_dir
                .clone()
                .or(file.record_dir)
                .unwrap_or_else(|| PathBuf::from(".")),
            limits,
        })
    }

    /// The label the file gives `port`, if any.
    pub fn label(&self, port: &str) -> Option<&str> {
        self.labels
            .iter()
            .find(|(p, _)| p == port)
            .map(|(_, l)| l.as_str())
    }
}

fn invalid(origin: String, message: impl Into<String>) -> CliError {
    CliError::Usage {
        option: origin,
        message: message.into(),
    }
}

/// The largest configuration file read (a real one is a few hundred bytes).
const MAX_CONFIG: u64 = 1 << 20;

/// Reads and parses a configuration file; errors name the file and the line.
fn read_file(path: &Path) -> Result<File, CliError> {
    let open_error = |source| InputError::Open {
        input: path.display().to_string(),
        source,
    };
    let bytes = read_small_file(path, MAX_CONFIG).map_err(open_error)?;
    let text = String::from_utf8(bytes).map_err(|_| {
        open_error(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "it is not UTF-8 text",
        ))
    })?;
    toml::from_str(&text).map_err(|e| {
        let line = e.span().map(|span| {
            text.as_bytes()[..span.start.min(text.len())]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
                + 1
        });
        CliError::Config {
            path: path.display().to_string(),
            line,
            message: e.message().trim().replace('\n', " "),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Config, CliError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("monitor.toml");
        std::fs::write(&path, text).unwrap();
        Config::load(&Overrides {
            config: Some(path),
            ..Overrides::default()
        })
    }

    #[test]
    fn defaults_without_a_file() {
        let config = Config::load(&Overrides {
            no_config: true,
            ..Overrides::default()
        })
        .unwrap();
        assert_eq!(config.limits.mos, Threshold::high(90.0, 105.0, 5.0));
        assert_eq!(config.limits.cap, Threshold::high(85.0, 100.0, 5.0));
        let six = config.limits.voltage(6);
        assert_eq!((six.warning, six.hysteresis), (3.5 * 6.0, 0.1 * 6.0));
        assert!((six.critical - 19.8).abs() < 1e-9 && six.low_is_bad);
        assert_eq!(config.baud, 19_200);
        assert_eq!(config.settings, Settings::DEFAULT);
        assert!(config.ports.is_empty());
    }

    #[test]
    fn the_file_sets_values_and_flags_win_over_it() {
        let text = "baud = 115200\npole_pairs = 14\n[alarms]\nmos_warning_c = 80\n\
                    mos_critical_c = 95\nbattery_cells = 12\n[[esc]]\nport = \"/dev/ttyUSB0\"\n\
                    label = \"front left\"\n[[esc]]\nport = \"/dev/ttyUSB1\"\n";
        let config = parse(text).unwrap();
        assert_eq!(config.baud, 115_200);
        assert_eq!(config.settings.pole_pairs, 14);
        assert_eq!(config.limits.mos.warning, 80.0);
        assert_eq!(config.limits.cells, Some(12));
        assert_eq!(config.ports, ["/dev/ttyUSB0", "/dev/ttyUSB1"]);
        assert_eq!(config.label("/dev/ttyUSB0"), Some("front left"));
        assert_eq!(config.label("/dev/ttyUSB1"), None);

        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.toml");
        std::fs::write(&path, text).unwrap();
        let mut flags = Overrides {
            config: Some(path),
            baud: Some(9600),
            ..Overrides::default()
        };
        flags.alarms.mos_warning_c = Some(70.0);
        let config = Config::load(&flags).unwrap();
        assert_eq!(config.baud, 9600);
        assert_eq!(config.limits.mos.warning, 70.0);
        assert_eq!(config.limits.mos.critical, 95.0);
    }

    #[test]
    fn errors_name_the_file_and_line() {
        let err = parse("baud = 19200\n[alarms]\nmos_warn = 80\n")
            .unwrap_err()
            .to_string();
        assert!(err.contains("monitor.toml line 3"), "{err}");
        assert!(err.contains("mos_warn"), "{err}");
        assert!(!err.contains('\n'), "{err}");

        let err = parse("[alarms]\nmos_warning_c = 110\n")
            .unwrap_err()
            .to_string();
        assert!(err.contains("mos_critical_c"), "{err}");
        assert!(err.contains("must be above the warning level"), "{err}");

        let err = parse("pole_pairs = \"seven\"\n").unwrap_err().to_string();
        assert!(err.contains("line 1"), "{err}");
    }

    #[test]
    fn a_missing_named_file_is_an_error() {
        let err = Config::load(&Overrides {
            config: Some(PathBuf::from("/nonexistent/monitor.toml")),
            ..Overrides::default()
        })
        .unwrap_err()
        .to_string();
        assert!(err.contains("/nonexistent/monitor.toml"), "{err}");
    }
}
