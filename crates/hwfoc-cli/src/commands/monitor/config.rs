//! The monitor's settings: built-in defaults, overridden by the configuration file
//! ([`crate::config`]: `[settings]`, `[port."NAME"]`, `[esc.N]`, `[monitor]`, `[alarms]`),
//! overridden by flags.
//!
//! The older `hwfoc/monitor.toml` is read when there is no `hwfoc/config.toml` (its keys
//! at the top and its `[[esc]]` list of ports and labels: see [`crate::config::File`]):
//!
//! ```toml
//! [monitor]
//! ports = ["/dev/ttyUSB0"]   # watched when none are named on the command line
//! baud = 19200
//! protocol = "hw-foc"        # read this protocol only (hw-foc, datalink); default: every one
//! record_dir = "/home/pi/recordings"
//!
//! [port."/dev/ttyUSB0"]
//! label = "front left"
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
//! ```

use std::path::PathBuf;

use hwfoc::Protocol;
use hwfoc_io::SettingsMap;
use hwfoc_ports::serial;

use super::alarms::Threshold;
use crate::args::SettingsArgs;
pub use crate::config::AlarmKeys;
use crate::error::CliError;

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

/// Everything the monitor is set to: the configuration file read ([`crate::config::Config`])
/// with the flags over it and the defaults under it.
#[derive(Debug)]
pub struct MonitorSetup {
    /// Where the configuration file was read from, if one was.
    pub file: Option<PathBuf>,
    /// Conversion settings, by ESC and port.
    pub settings: SettingsMap,
    /// Baud rate of the ports: given (by a flag or the file, or by the protocol named), or
    /// found by each port from its bytes.
    pub baud: serial::Baud,
    /// The one protocol read, when forced (every protocol otherwise).
    pub protocol: Option<Protocol>,
    /// Ports from the file, when none are named on the command line.
    pub ports: Vec<String>,
    /// Where recordings started with the `r` key go.
    pub record_dir: PathBuf,
    /// Alarm levels.
    pub limits: Limits,
    /// The file, for labels.
    general: crate::config::Config,
}

/// What the command line says (each `None` leaves the file's value or the default).
#[derive(Debug, Default, Clone)]
pub struct Overrides {
    /// `--config`, `--no-config` and the conversion settings.
    pub settings: SettingsArgs,
    /// `--baud`.
    pub baud: Option<u32>,
    /// `--protocol`.
    pub protocol: Option<Protocol>,
    /// `--record-dir`.
    pub record_dir: Option<PathBuf>,
    /// The alarm flags.
    pub alarms: AlarmKeys,
}

/// Where recordings go unless told otherwise: `hwfoc/recordings` in the user's data directory
/// (`~/.local/share/hwfoc/recordings` on Linux), or the current directory if there is none.
pub fn default_record_dir() -> PathBuf {
    dirs::data_local_dir()
        .map(|d| d.join("hwfoc").join("recordings"))
        .unwrap_or_else(|| PathBuf::from("."))
}

impl MonitorSetup {
    /// Reads the configuration file (the one named, or the per-user one if it exists) and
    /// applies the flags over it.
    pub fn load(flags: &Overrides) -> Result<MonitorSetup, CliError> {
        let general = crate::config::Config::load(&flags.settings, true)?;
        MonitorSetup::merge(general, flags)
    }

    fn merge(general: crate::config::Config, flags: &Overrides) -> Result<MonitorSetup, CliError> {
        let origin = |key: &str| match &general.path {
            Some(p) => format!("{} ({key})", p.display()),
            None => format!("--{}", key.replace('_', "-")),
        };
        let settings = general.settings_map(&flags.settings)?;
        // Flags first (a protocol named implies its baud rate), then the file likewise.
        let file_protocol = general.file.monitor.protocol;
        let baud = flags
            .baud
            .or(flags.protocol.and_then(Protocol::serial_baud_rate))
            .or(general.baud())
            .or(file_protocol.and_then(Protocol::serial_baud_rate));
        if baud == Some(0) {
            return Err(invalid(origin("baud"), "the baud rate must be more than 0"));
        }
        // Neither given: each port finds its own.
        let baud = baud.map_or(serial::Baud::Auto, serial::Baud::Fixed);
        let a = &flags.alarms;
        let f = &general.file.alarms;
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
        Ok(MonitorSetup {
            file: general.path.clone(),
            settings,
            baud,
            protocol: flags.protocol.or(file_protocol),
            ports: general.ports(),
            record_dir: flags
                .record_dir
                .clone()
                .or_else(|| general.record_dir())
                .unwrap_or_else(default_record_dir),
            limits,
            general,
        })
    }

    /// The label the file gives ESC `esc` read from `port`, if any.
    pub fn label(&self, esc: usize, port: &str) -> Option<&str> {
        self.general.label(esc, port)
    }

    /// The file's `[esc.N]` labels, by ESC number.
    pub fn esc_labels(&self) -> Vec<(usize, &str)> {
        self.general.esc_labels()
    }

    /// The label the file gives port `port` itself, if any.
    pub fn port_label(&self, port: &str) -> Option<&str> {
        self.general.port_label(port)
    }
}

fn invalid(origin: String, message: impl Into<String>) -> CliError {
    CliError::Usage {
        option: origin,
        message: message.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::Settings;
    use hwfoc_ports::serial::Baud;

    fn parse(text: &str) -> Result<MonitorSetup, CliError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("monitor.toml");
        std::fs::write(&path, text).unwrap();
        MonitorSetup::load(&Overrides {
            settings: SettingsArgs {
                config: Some(path),
                ..SettingsArgs::default()
            },
            ..Overrides::default()
        })
    }

    #[test]
    fn defaults_without_a_file() {
        let config = MonitorSetup::load(&Overrides {
            settings: SettingsArgs {
                no_config: true,
                ..SettingsArgs::default()
            },
            ..Overrides::default()
        })
        .unwrap();
        assert_eq!(config.limits.mos, Threshold::high(90.0, 105.0, 5.0));
        assert_eq!(config.limits.cap, Threshold::high(85.0, 100.0, 5.0));
        let six = config.limits.voltage(6);
        assert_eq!((six.warning, six.hysteresis), (3.5 * 6.0, 0.1 * 6.0));
        assert!((six.critical - 19.8).abs() < 1e-9 && six.low_is_bad);
        assert_eq!(config.baud, hwfoc_ports::serial::Baud::Auto);
        assert_eq!(config.settings, SettingsMap::from(Settings::DEFAULT));
        assert!(config.ports.is_empty());
        assert_eq!(config.record_dir, default_record_dir());
        assert!(config.record_dir.ends_with("hwfoc/recordings"));
    }

    #[test]
    fn the_file_sets_values_and_flags_win_over_it() {
        let text = "baud = 115200\npole_pairs = 14\n[alarms]\nmos_warning_c = 80\n\
                    mos_critical_c = 95\nbattery_cells = 12\n[[esc]]\nport = \"/dev/ttyUSB0\"\n\
                    label = \"front left\"\n[[esc]]\nport = \"/dev/ttyUSB1\"\n";
        let config = parse(text).unwrap();
        assert_eq!(config.baud, Baud::Fixed(115_200));
        assert_eq!(config.settings.get(0, "/dev/ttyUSB0").pole_pairs, 14);
        assert_eq!(config.limits.mos.warning, 80.0);
        assert_eq!(config.limits.cells, Some(12));
        assert_eq!(config.ports, ["/dev/ttyUSB0", "/dev/ttyUSB1"]);
        assert_eq!(config.label(0, "/dev/ttyUSB0"), Some("front left"));
        assert_eq!(config.label(1, "/dev/ttyUSB1"), None);

        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.toml");
        std::fs::write(&path, text).unwrap();
        let mut flags = Overrides {
            settings: SettingsArgs {
                config: Some(path),
                ..SettingsArgs::default()
            },
            baud: Some(9600),
            ..Overrides::default()
        };
        flags.alarms.mos_warning_c = Some(70.0);
        let config = MonitorSetup::load(&flags).unwrap();
        assert_eq!(config.baud, Baud::Fixed(9600));
        assert_eq!(config.limits.mos.warning, 70.0);
        assert_eq!(config.limits.mos.critical, 95.0);
    }

    /// `--protocol` over `[monitor] protocol`; each implies its baud rate where no baud rate
    /// is given at its level (flags, then the file).
    #[test]
    fn a_protocol_sets_the_baud_rate_a_flag_or_the_file_leaves_open() {
        let none = parse("").unwrap();
        assert_eq!((none.protocol, none.baud), (None, Baud::Auto));
        let file = parse("[monitor]\nprotocol = \"datalink\"\n").unwrap();
        assert_eq!(
            (file.protocol, file.baud),
            (Some(Protocol::DataLink), Baud::Fixed(115_200))
        );
        let file = parse("[monitor]\nprotocol = \"datalink\"\nbaud = 57600\n").unwrap();
        assert_eq!(file.baud, Baud::Fixed(57_600));
        // A CAN protocol is taken, and sets no serial rate (a CAN bus has its own).
        let file = parse("[monitor]\nprotocol = \"hw-can\"\n").unwrap();
        assert_eq!(
            (file.protocol, file.baud),
            (Some(Protocol::HwCan), Baud::Auto)
        );

        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.toml");
        std::fs::write(&path, "[monitor]\nbaud = 57600\nprotocol = \"datalink\"\n").unwrap();
        let mut flags = Overrides {
            settings: SettingsArgs {
                config: Some(path),
                ..SettingsArgs::default()
            },
            protocol: Some(Protocol::HwFoc),
            ..Overrides::default()
        };
        let config = MonitorSetup::load(&flags).unwrap();
        assert_eq!(
            (config.protocol, config.baud),
            (Some(Protocol::HwFoc), Baud::Fixed(19_200))
        );
        flags.baud = Some(38_400);
        assert_eq!(
            MonitorSetup::load(&flags).unwrap().baud,
            Baud::Fixed(38_400)
        );
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
        let err = MonitorSetup::load(&Overrides {
            settings: SettingsArgs {
                config: Some(PathBuf::from("/nonexistent/monitor.toml")),
                ..SettingsArgs::default()
            },
            ..Overrides::default()
        })
        .unwrap_err()
        .to_string();
        assert!(err.contains("/nonexistent/monitor.toml"), "{err}");
    }
}
