//! The configuration file: the settings every command would otherwise be told again and again
//! (current scale, pole pairs, gear ratio: per ESC and per port as well as for all), the
//! monitor's alarm levels, ports and labels.
//!
//! Where it is: `--config FILE`, else the file named by the `HWFOC_CONFIG` environment variable,
//! else `hwfoc/config.toml` in the user's configuration directory (`$XDG_CONFIG_HOME`, by default
//! `~/.config`, on Linux; `~/Library/Application Support` on macOS; `%APPDATA%` on Windows) if it
//! exists. `--no-config` reads none. `hwfoc monitor` also reads the older `hwfoc/monitor.toml`
//! there when there is no `config.toml` (its layout too: see [`File`]).
//!
//! ```toml
//! [settings]              # every ESC, unless said otherwise below
//! current_scale = 64.0
//! pole_pairs = 7
//! gear_ratio = 1.0
//!
//! [port."/dev/ttyUSB1"]   # the ESC read from this port (a serial port, or a port named in a
//! pole_pairs = 14         # recording); `label` names it in the monitor
//! label = "tail"
//!
//! [esc.2]                 # ESC 2 (the `esc` column), whatever it is read from
//! current_scale = 100.0
//!
//! [monitor]
//! ports = ["/dev/ttyUSB0", "/dev/ttyUSB1"]   # watched when none are named
//! baud = 19200
//! protocol = "hw-foc"     # read this protocol only (hw-foc, datalink); default: every one
//! record_dir = "/home/pi/recordings"
//!
//! [alarms]                # the monitor's levels: see `hwfoc monitor --help`
//! mos_warning_c = 90
//! ```
//!
//! Precedence, field by field: a command-line flag, then the ESC's `[esc.N]` entry, then its
//! port's `[port."NAME"]` entry, then `[settings]`, then the built-in defaults. Unknown keys are
//! errors naming the file, the line and the key; so are two entries of one ESC (`[esc.1]` and
//! `[esc.01]`), of one port (`[port."/dev/ttyUSB0"]` and an older `[[esc]]` entry of that port)
//! and a setting both in its table and at the top (the older layout), naming both lines.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use hwfoc::{Protocol, Settings};
use hwfoc_io::InputError;
use hwfoc_io::read_small_file;
use hwfoc_io::{SettingsMap, SettingsPatch};
use serde::Deserialize;
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use toml::Spanned;
use toml::de::{DeString, DeTable, DeValue};

mod entry;

use entry::{Entry, PortEntry};

use crate::args::SettingsArgs;
use crate::error::CliError;

/// The environment variable that names a configuration file (`--config` wins over it).
pub const ENV: &str = "HWFOC_CONFIG";

/// The file's layout. Every key is optional.
///
/// The older `monitor.toml` layout is read too: `baud`, `current_scale`, `pole_pairs`,
/// `gear_ratio` and `record_dir` at the top (in `config.toml`: `[settings]` and `[monitor]`), and
/// `[[esc]]` entries each naming a `port` (a port to watch and its label).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct File {
    /// Settings of every ESC.
    #[serde(default)]
    settings: Entry,
    /// Entries by port name.
    #[serde(default)]
    port: BTreeMap<String, Entry>,
    /// `[esc.N]` entries, or the older `[[esc]]` list.
    #[serde(default)]
    esc: EscSection,
    /// The monitor's own keys.
    #[serde(default)]
    pub monitor: MonitorKeys,
    /// The monitor's alarm levels.
    #[serde(default)]
    pub alarms: AlarmKeys,
    /// `hwfoc check`'s thresholds (`docs/CHECKS.md`).
    #[serde(default)]
    pub check: hwfoc_io::check::CheckConfig,
    // The older layout's top-level keys.
    baud: Option<u32>,
    current_scale: Option<f32>,
    pole_pairs: Option<u16>,
    gear_ratio: Option<f32>,
    record_dir: Option<PathBuf>,
}

/// `esc`: a table of ESC indices (`[esc.3]`), or the older list of ports (`[[esc]]`).
#[derive(Debug, Default)]
enum EscSection {
    #[default]
    None,
    ByIndex(BTreeMap<u8, Entry>),
    Ports(Vec<PortEntry>),
}

impl<'de> Deserialize<'de> for EscSection {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = EscSection;

            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("tables [esc.N] by ESC index (or a list [[esc]] of ports)")
            }

            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<EscSection, A::Error> {
                let mut list = Vec::new();
                while let Some(entry) = seq.next_element::<PortEntry>()? {
                    list.push(entry);
                }
                Ok(EscSection::Ports(list))
            }

            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<EscSection, A::Error> {
                let mut by_index = BTreeMap::new();
                while let Some(key) = map.next_key::<String>()? {
                    let index: u8 = key.parse().map_err(|_| {
                        de::Error::custom(format!(
                            "esc.{key}: an ESC is named by its index, 0 to 255 (as in the `esc` \
                             column)"
                        ))
                    })?;
                    by_index.insert(index, map.next_value::<Entry>()?);
                }
                Ok(EscSection::ByIndex(by_index))
            }
        }
        deserializer.deserialize_any(V)
    }
}

/// The `[monitor]` table.
#[derive(Debug, Default, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MonitorKeys {
    /// Ports watched when none are named on the command line.
    #[serde(default)]
    pub ports: Vec<String>,
    /// Baud rate of the ports.
    pub baud: Option<u32>,
    /// The one protocol read, by name (as `--protocol`).
    #[serde(default, deserialize_with = "protocol")]
    pub protocol: Option<Protocol>,
    /// Where the `r` key puts its recordings.
    pub record_dir: Option<PathBuf>,
}

/// A protocol by its name ([`Protocol::from_name`]: as `--protocol`); another name is an
/// error listing the names.
fn protocol<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Option<Protocol>, D::Error> {
    let name = String::deserialize(deserializer)?;
    Protocol::from_name(&name).map(Some).ok_or_else(|| {
        let names: Vec<&str> = Protocol::ALL.iter().map(|p| p.name()).collect();
        de::Error::custom(format!(
            "protocol {name:?} is not one of {}",
            names.join(", ")
        ))
    })
}

/// The `[alarms]` table (and the monitor's matching flags).
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

/// The configuration file read (or none), and what it says.
#[derive(Debug, Default)]
pub struct Config {
    /// Where it was read from; `None` when no file was read.
    pub path: Option<PathBuf>,
    /// What it says (all empty without a file).
    pub file: File,
}

impl SettingsArgs {
    /// The configuration file these flags point to, read (see [`Config::load`]).
    pub fn config(&self) -> Result<Config, CliError> {
        Config::load(self, false)
    }

    /// The configuration file read and every ESC's settings: the file's, and the flags over
    /// them.
    pub fn settings_map(&self) -> Result<(Config, SettingsMap), CliError> {
        let config = self.config()?;
        let map = config.settings_map(self)?;
        Ok((config, map))
    }
}

/// The per-user configuration file, whether or not it exists.
pub fn default_path() -> Option<PathBuf> {
    dirs::config_dir().map(|d| d.join("hwfoc").join("config.toml"))
}

/// The older per-user file of `hwfoc monitor`, read by it when there is no [`default_path`].
pub fn legacy_monitor_path() -> Option<PathBuf> {
    dirs::config_dir().map(|d| d.join("hwfoc").join("monitor.toml"))
}

impl Config {
    /// Reads the configuration file `args` point to (see the module documentation); `monitor`
    /// also looks for the older `monitor.toml`.
    pub fn load(args: &SettingsArgs, monitor: bool) -> Result<Config, CliError> {
        let named = args.config.clone().or_else(|| {
            std::env::var_os(ENV)
                .filter(|v| !v.is_empty())
                .map(PathBuf::from)
        });
        let path = match (args.no_config, named) {
            (true, _) => None,
            (false, Some(path)) => Some(path),
            // Whatever is there is read: one that is not a regular file (a FIFO, a directory)
            // is an error naming it, not a configuration silently ignored.
            (false, None) => default_path()
                .filter(|p| is_there(p))
                .or_else(|| legacy_monitor_path().filter(|p| monitor && is_there(p))),
        };
        let file = match &path {
            Some(path) => read_file(path)?,
            None => File::default(),
        };
        Ok(Config { path, file })
    }

    /// Where this file's values came from, for an error: `FILE ([esc.2])`.
    pub fn origin(&self, what: &str) -> String {
        match &self.path {
            Some(p) => format!("{} ({what})", p.display()),
            None => what.to_string(),
        }
    }

    /// The settings of ESCs that no entry names: the flags over `[settings]` over the defaults.
    pub fn settings(&self, flags: &SettingsArgs) -> Result<Settings, CliError> {
        let file = self.defaults_patch();
        let flag = flags.patch();
        flag.apply(
            &file
                .apply(&Settings::DEFAULT)
                .map_err(|e| CliError::Usage {
                    option: self.origin("[settings]"),
                    message: e.to_string(),
                })?,
        )
        .map_err(CliError::Settings)
    }

    /// Every ESC's settings: [`Config::settings`] for all, the entries by port and by ESC over
    /// them, the flags over everything.
    pub fn settings_map(&self, flags: &SettingsArgs) -> Result<SettingsMap, CliError> {
        let mut map = SettingsMap::new(self.settings(flags)?);
        let flag = flags.patch();
        let bad = |what: String, e: hwfoc::SettingsError| CliError::Usage {
            option: self.origin(&what),
            message: e.to_string(),
        };
        for (port, entry) in &self.port_entries() {
            map.set_port(*port, flag.over(&entry.patch()))
                .map_err(|e| bad(format!("port {port:?}"), e))?;
        }
        if let EscSection::ByIndex(escs) = &self.file.esc {
            for (&esc, entry) in escs {
                map.set_esc(usize::from(esc), flag.over(&entry.patch()))
                    .map_err(|e| bad(format!("[esc.{esc}]"), e))?;
            }
        }
        Ok(map)
    }

    /// `[settings]`, with the older layout's top-level keys where it has none.
    fn defaults_patch(&self) -> SettingsPatch {
        let f = &self.file;
        f.settings.patch().over(&SettingsPatch {
            current_scale: f.current_scale,
            pole_pairs: f.pole_pairs,
            gear_ratio: f.gear_ratio,
            v4_volts_per_step: None,
        })
    }

    /// The entries by port: `[port."NAME"]`, then the older `[[esc]]` list.
    fn port_entries(&self) -> Vec<(&str, Entry)> {
        let list = match &self.file.esc {
            EscSection::Ports(list) => list.as_slice(),
            _ => &[],
        };
        self.file
            .port
            .iter()
            .map(|(p, e)| (p.as_str(), e.clone()))
            .chain(list.iter().map(|e| (e.port.as_str(), e.entry.clone())))
            .collect()
    }

    /// The label of ESC `esc` read from `port`: its `[esc.N]` label, else its port's.
    pub fn label(&self, esc: usize, port: &str) -> Option<&str> {
        self.esc_labels()
            .into_iter()
            .find_map(|(n, label)| (n == esc).then_some(label))
            .or_else(|| self.port_label(port))
    }

    /// The `[esc.N]` labels, by ESC number.
    pub fn esc_labels(&self) -> Vec<(usize, &str)> {
        match &self.file.esc {
            EscSection::ByIndex(escs) => escs
                .iter()
                .filter_map(|(&i, e)| Some((usize::from(i), e.label.as_deref()?)))
                .collect(),
            _ => Vec::new(),
        }
    }

    /// The label of port `port`: `[port."NAME"]`'s, else that of its `[[esc]]` entry.
    pub fn port_label(&self, port: &str) -> Option<&str> {
        let from_table = self.file.port.get(port).and_then(|e| e.label.as_deref());
        let from_list = match &self.file.esc {
            EscSection::Ports(list) => list
                .iter()
                .filter(|e| e.port == port)
                .find_map(|e| e.entry.label.as_deref()),
            _ => None,
        };
        from_table.or(from_list)
    }

    /// The ports to watch when none are named: `[monitor] ports`, then those of the older
    /// `[[esc]]` list.
    pub fn ports(&self) -> Vec<String> {
        let mut ports = self.file.monitor.ports.clone();
        if let EscSection::Ports(list) = &self.file.esc {
            ports.extend(list.iter().map(|e| e.port.clone()));
        }
        ports
    }

    /// The monitor's baud rate: `[monitor] baud`, or the older top-level `baud`.
    pub fn baud(&self) -> Option<u32> {
        self.file.monitor.baud.or(self.file.baud)
    }

    /// The monitor's recording directory: `[monitor] record_dir`, or the older top-level key.
    pub fn record_dir(&self) -> Option<PathBuf> {
        let f = &self.file;
        f.monitor
            .record_dir
            .clone()
            .or_else(|| f.record_dir.clone())
    }
}

/// Whether anything (a file, a directory, a FIFO, a link even to nothing) is at `path`.
fn is_there(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok()
}

/// The largest configuration file read (a real one is a few hundred bytes).
const MAX_CONFIG: u64 = 1 << 20;

/// Reads and parses a configuration file; errors name the file and the line.
fn read_file(path: &Path) -> Result<File, CliError> {
    let text = read_text(path)?;
    let doc = DeTable::parse(&text).map_err(|e| toml_error(path, &text, e))?;
    if let Some((line, message)) = same_names(doc.get_ref(), &text) {
        return Err(CliError::Config {
            path: path.display().to_string(),
            line: Some(line),
            message,
        });
    }
    File::deserialize(toml::de::Deserializer::from(doc)).map_err(|e| toml_error(path, &text, e))
}

/// Reads and parses another TOML file the command takes (`hwfoc check --baseline`); errors
/// name the file and the line, as the configuration file's do.
pub fn read_toml<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, CliError> {
    let text = read_text(path)?;
    toml::from_str(&text).map_err(|e| toml_error(path, &text, e))
}

/// The text of a TOML file of at most [`MAX_CONFIG`] bytes.
fn read_text(path: &Path) -> Result<String, CliError> {
    let open_error = |source| InputError::Open {
        input: path.display().to_string(),
        source,
    };
    let bytes = read_small_file(path, MAX_CONFIG).map_err(open_error)?;
    Ok(String::from_utf8(bytes).map_err(|_| {
        open_error(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "it is not UTF-8 text",
        ))
    })?)
}

/// A TOML error of file `path`, holding `text`: its line and message.
fn toml_error(path: &Path, text: &str, e: toml::de::Error) -> CliError {
    CliError::Config {
        path: path.display().to_string(),
        line: e.span().map(|span| line_of(text, span.start)),
        message: e.message().trim().replace('\n', " "),
    }
}

/// The 1-based line of byte `offset` of `text`.
fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// One name of an ESC, a port or a setting in the file: where it is, how it is written, and
/// what it names (the same `key` for two names is one ESC, port or setting).
#[derive(Clone)]
struct Name<K> {
    offset: usize,
    shown: String,
    key: K,
}

/// The first name (in the file's order) that names what an earlier one does, as the line of the
/// later one and a message naming both: TOML refuses a key written twice, but `[esc.1]` and
/// `[esc.01]`, or `[port."/dev/ttyUSB0"]` and an older `[[esc]]` entry of that port, are
/// different keys naming one ESC or port, and one entry would be silently ignored.
fn same_names(doc: &DeTable, text: &str) -> Option<(usize, String)> {
    let name = |key: &Spanned<DeString>, shown: String| (key.span().start, shown);
    let esc = doc.get("esc").map(|v| v.get_ref());

    // [esc.N]: keys that are one index.
    let escs = esc.and_then(DeValue::as_table).into_iter().flatten();
    let escs = escs.filter_map(|(key, _)| {
        let index = key.get_ref().parse::<u8>().ok()?;
        let (offset, shown) = name(key, format!("[esc.{}]", &text[key.span()]));
        Some(Name {
            offset,
            shown,
            key: index,
        })
    });
    let mut found = first_twice(escs.collect(), text, "names the same ESC as");

    // Ports: [port."NAME"] and the older [[esc]] entries give settings; [monitor] ports and
    // those entries are the ports watched.
    let list_ports: Vec<Name<PathBuf>> = esc
        .and_then(DeValue::as_array)
        .into_iter()
        .flat_map(|list| list.iter())
        .filter_map(|entry| {
            let port = entry.get_ref().as_table()?.get("port")?;
            let named = port.get_ref().as_str()?;
            Some(Name {
                offset: port.span().start,
                shown: format!("[[esc]] port = {named:?}"),
                key: port_key(named),
            })
        })
        .collect();
    let table_ports = table(doc.get("port"))
        .into_iter()
        .flatten()
        .map(|(key, _)| {
            let (offset, shown) = name(key, format!("[port.{}]", &text[key.span()]));
            Name {
                offset,
                shown,
                key: port_key(key.get_ref()),
            }
        });
    let watched = table(doc.get("monitor"))
        .and_then(|m| m.get("ports"))
        .and_then(|p| p.get_ref().as_array())
        .into_iter()
        .flat_map(|list| list.iter())
        .filter_map(|port| {
            let named = port.get_ref().as_str()?;
            Some(Name {
                offset: port.span().start,
                shown: format!("[monitor] ports {named:?}"),
                key: port_key(named),
            })
        });
    let settings_by_port = table_ports.chain(list_ports.iter().cloned()).collect();
    let watched = watched.chain(list_ports.iter().cloned()).collect();
    found = found
        .or_else(|| first_twice(settings_by_port, text, "names the same port as"))
        .or_else(|| first_twice(watched, text, "names the same port to watch as"));

    // The older layout's top-level keys and the tables that hold them in `config.toml`.
    for (key, now) in [
        ("current_scale", "settings"),
        ("pole_pairs", "settings"),
        ("gear_ratio", "settings"),
        ("baud", "monitor"),
        ("record_dir", "monitor"),
    ] {
        let old = doc.get_key_value(key);
        let new = table(doc.get(now)).and_then(|t| t.get_key_value(key));
        if found.is_none()
            && let (Some((old, _)), Some((new, _))) = (old, new)
        {
            let names = vec![
                Name {
                    offset: old.span().start,
                    shown: format!("{key} (the older layout's, at the top)"),
                    key: (),
                },
                Name {
                    offset: new.span().start,
                    shown: format!("[{now}] {key}"),
                    key: (),
                },
            ];
            found = first_twice(names, text, "is the same setting as");
        }
    }
    found
}

/// The table `value` holds, if it is one.
fn table<'a, 'i>(value: Option<&'a Spanned<DeValue<'i>>>) -> Option<&'a DeTable<'i>> {
    value.and_then(|v| v.get_ref().as_table())
}

/// The later of the first two `names` with one key, as its line and "`A` `says` `B` on line
/// N: keep one".
fn first_twice<K: PartialEq>(
    mut names: Vec<Name<K>>,
    text: &str,
    says: &str,
) -> Option<(usize, String)> {
    names.sort_by_key(|n| n.offset);
    names.iter().enumerate().find_map(|(i, later)| {
        let earlier = names[..i].iter().find(|n| n.key == later.key)?;
        Some((
            line_of(text, later.offset),
            format!(
                "{} {says} {} on line {}: keep one (one of them would be ignored)",
                later.shown,
                earlier.shown,
                line_of(text, earlier.offset)
            ),
        ))
    })
}

/// A port name as compared for sameness: its path's components (`/dev//ttyUSB0` and
/// `/dev/./ttyUSB0` are `/dev/ttyUSB0`), without regard to case on Windows (`com3` is `COM3`).
fn port_key(name: &str) -> PathBuf {
    let path: PathBuf = Path::new(name).components().collect();
    if cfg!(windows) {
        PathBuf::from(path.to_string_lossy().to_lowercase())
    } else {
        path
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The flags of a command line, without a file of the user's.
    fn flags(config: Option<&Path>) -> SettingsArgs {
        SettingsArgs {
            current_scale: None,
            pole_pairs: None,
            gear_ratio: None,
            v4_volts_per_step: None,
            set: Vec::new(),
            config: config.map(Path::to_path_buf),
            no_config: config.is_none(),
        }
    }

    fn load(text: &str) -> (tempfile::TempDir, Result<Config, CliError>) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("config.toml");
        std::fs::write(&path, text).unwrap();
        let config = Config::load(&flags(Some(&path)), false);
        (dir, config)
    }

    const FILE: &str = "[settings]\ncurrent_scale = 100\npole_pairs = 12\n\n\
                        [port.\"/dev/ttyUSB1\"]\npole_pairs = 14\nlabel = \"tail\"\n\n\
                        [esc.1]\ngear_ratio = 2.5\n\n[esc.3]\nlabel = \"rear\"\ncurrent_scale = 64\n";

    #[test]
    fn flags_beat_entries_beat_settings_beat_defaults() {
        let (_dir, config) = load(FILE);
        let config = config.unwrap();
        let map = config.settings_map(&flags(None)).unwrap();
        let s = |esc, port| {
            let s = map.get(esc, port);
            (s.current_scale, s.pole_pairs, s.gear_ratio)
        };
        assert_eq!(s(0, "/dev/ttyUSB0"), (100.0, 12, 1.0));
        assert_eq!(s(0, "/dev/ttyUSB1"), (100.0, 14, 1.0));
        assert_eq!(s(1, "/dev/ttyUSB1"), (100.0, 14, 2.5));
        assert_eq!(s(3, "/dev/ttyUSB1"), (64.0, 14, 1.0));
        assert_eq!(config.label(1, "/dev/ttyUSB1"), Some("tail"));
        assert_eq!(config.label(3, "/dev/ttyUSB1"), Some("rear"));
        assert_eq!(config.label(0, "/dev/ttyUSB0"), None);

        let mut flag = flags(None);
        flag.pole_pairs = Some(2);
        let map = config.settings_map(&flag).unwrap();
        for (esc, port) in [(0, "x"), (1, "/dev/ttyUSB1"), (3, "/dev/ttyUSB1")] {
            assert_eq!(map.get(esc, port).pole_pairs, 2, "esc {esc}");
        }
        // The fields no flag sets still come from the entries.
        assert_eq!(map.get(1, "/dev/ttyUSB1").gear_ratio, 2.5);
        assert_eq!(map.get(3, "/dev/ttyUSB1").current_scale, 64.0);
        assert_eq!(config.settings(&flag).unwrap().current_scale, 100.0);

        let none = Config::load(&flags(None), false).unwrap();
        assert_eq!(none.path, None);
        assert_eq!(none.settings(&flags(None)).unwrap(), Settings::DEFAULT);
    }

    #[test]
    fn the_older_monitor_layout_is_read_as_before() {
        let (_dir, config) = load(
            "baud = 115200\npole_pairs = 14\nrecord_dir = \"/tmp/r\"\n[alarms]\n\
             mos_warning_c = 80\n[[esc]]\nport = \"/dev/ttyUSB0\"\nlabel = \"front left\"\n\
             [[esc]]\nport = \"/dev/ttyUSB1\"\ncurrent_scale = 100\n",
        );
        let config = config.unwrap();
        assert_eq!(config.baud(), Some(115_200));
        assert_eq!(config.record_dir(), Some(PathBuf::from("/tmp/r")));
        assert_eq!(config.ports(), ["/dev/ttyUSB0", "/dev/ttyUSB1"]);
        assert_eq!(config.label(0, "/dev/ttyUSB0"), Some("front left"));
        assert_eq!(config.file.alarms.mos_warning_c, Some(80.0));
        let map = config.settings_map(&flags(None)).unwrap();
        assert_eq!(map.get(0, "/dev/ttyUSB0").pole_pairs, 14);
        assert_eq!(map.get(1, "/dev/ttyUSB1").current_scale, 100.0);
        assert_eq!(map.get(1, "/dev/ttyUSB1").pole_pairs, 14);
    }

    #[test]
    fn errors_name_the_file_line_and_key() {
        let cases = [
            (
                "[settings]\npole_pairs = 7\npole_pair = 7\n",
                3,
                "pole_pair",
            ),
            (
                "[esc.2]\nlabel = \"x\"\ncurrent_sale = 1\n",
                3,
                "current_sale",
            ),
            ("[port.\"a\"]\n\n\nlable = \"x\"\n", 4, "lable"),
            ("[[esc]]\nport = \"a\"\nlabels = \"x\"\n", 3, "labels"),
            ("[monitor]\nport = []\n", 2, "port"),
            ("[esc.front]\nlabel = \"x\"\n", 1, "esc.front"),
            ("[settings]\n\npole_pairs = \"seven\"\n", 3, "string"),
            ("speed = 3\n", 1, "speed"),
        ];
        for (text, line, key) in cases {
            let (_dir, config) = load(text);
            let err = config.unwrap_err().to_string();
            assert!(
                err.contains(&format!("config.toml line {line}")),
                "{text}: {err}"
            );
            assert!(err.contains(key), "{text}: {err}");
            assert!(!err.contains('\n'), "{err}");
        }
        // Values out of range name the file and the entry.
        let (_dir, config) = load("[esc.4]\npole_pairs = 0\n");
        let err = config
            .unwrap()
            .settings_map(&flags(None))
            .unwrap_err()
            .to_string();
        assert!(err.contains("config.toml ([esc.4])"), "{err}");
        let (_dir, config) = load("[settings]\ncurrent_scale = -1\n");
        let err = config
            .unwrap()
            .settings(&flags(None))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("([settings])") && err.contains("current scale"),
            "{err}"
        );
    }

    #[test]
    fn two_names_of_one_esc_port_or_setting_are_an_error_naming_both_lines() {
        let cases = [
            (
                "[esc.1]\npole_pairs = 7\n\n[esc.01]\npole_pairs = 14\n",
                4,
                "[esc.01]",
                1,
                "[esc.1]",
            ),
            (
                "[esc.\"+2\"]\nlabel = \"a\"\n[esc.2]\nlabel = \"b\"\n",
                3,
                "[esc.2]",
                1,
                "[esc.\"+2\"]",
            ),
            (
                "esc.1.pole_pairs = 3\n[esc.001]\n",
                2,
                "[esc.001]",
                1,
                "[esc.1]",
            ),
            (
                "[port.\"/dev/ttyUSB1\"]\npole_pairs = 14\n[[esc]]\nport = \"/dev/ttyUSB1\"\n",
                4,
                "[[esc]] port = \"/dev/ttyUSB1\"",
                1,
                "[port.\"/dev/ttyUSB1\"]",
            ),
            (
                "[port.\"/dev/ttyUSB1\"]\nlabel = \"a\"\n[port.\"/dev//ttyUSB1\"]\nlabel = \"b\"\n",
                3,
                "[port.\"/dev//ttyUSB1\"]",
                1,
                "[port.\"/dev/ttyUSB1\"]",
            ),
            (
                "[[esc]]\nport = \"a\"\n[[esc]]\nport = \"a\"\nlabel = \"b\"\n",
                4,
                "[[esc]] port = \"a\"",
                2,
                "[[esc]] port = \"a\"",
            ),
            (
                "[monitor]\nports = [\"a\"]\n[[esc]]\nport = \"a\"\n",
                4,
                "[[esc]] port = \"a\"",
                2,
                "[monitor] ports \"a\"",
            ),
            (
                "pole_pairs = 7\n[settings]\npole_pairs = 14\n",
                3,
                "[settings] pole_pairs",
                1,
                "pole_pairs (the older layout's",
            ),
            ("[monitor]\nbaud = 9600\n", 0, "", 0, ""),
            (
                "record_dir = \"/a\"\n[monitor]\nrecord_dir = \"/b\"\n",
                3,
                "[monitor] record_dir",
                1,
                "record_dir (the older",
            ),
        ];
        for (text, line, later, earlier_line, earlier) in cases {
            let (_dir, config) = load(text);
            if line == 0 {
                assert!(config.is_ok(), "{text}");
                continue;
            }
            let err = config.unwrap_err().to_string();
            assert!(
                err.contains(&format!("config.toml line {line}: {later} ")),
                "{text}: {err}"
            );
            assert!(
                err.contains(&format!("as {earlier}"))
                    && err.contains(&format!("on line {earlier_line}:")),
                "{text}: {err}"
            );
            assert!(!err.contains('\n'), "{err}");
        }
        // Two ports or ESCs that differ are two entries.
        let (_dir, config) = load(
            "[esc.1]\n[esc.10]\n[port.\"/dev/ttyUSB1\"]\n[port.\"/dev/ttyUSB10\"]\n\
             [monitor]\nports = [\"/dev/ttyUSB1\"]\n",
        );
        config.unwrap();
    }

    /// `[monitor] protocol` names a protocol; another name is an error naming the line and
    /// the names.
    #[test]
    fn the_monitor_protocol_is_a_name() {
        let (_dir, config) = load("[monitor]\nprotocol = \"datalink\"\n");
        assert_eq!(
            config.unwrap().file.monitor.protocol,
            Some(Protocol::DataLink)
        );
        let (_dir, config) = load("[monitor]\nprotocol = \"hw5\"\n");
        assert_eq!(config.unwrap().file.monitor.protocol, Some(Protocol::Hw5));
        let (_dir, config) = load("[monitor]\nbaud = 9600\nprotocol = \"hw6\"\n");
        let err = config.unwrap_err().to_string();
        assert!(err.contains("config.toml line 3"), "{err}");
        assert!(
            err.contains("\"hw6\" is not one of hw-foc, datalink, hw-v4, hw-v3, hw5"),
            "{err}"
        );
        assert!(!err.contains('\n'), "{err}");
    }

    /// `v4_volts_per_step` is a fraction in every settings table; a bad one names the line.
    #[test]
    fn the_v4_volts_per_step_is_a_fraction() {
        let (_dir, config) = load(
            "[settings]\nv4_volts_per_step = \"hv\"\n[esc.1]\nv4_volts_per_step = \"9/700\"\n",
        );
        let config = config.unwrap();
        let map = config.settings_map(&flags(None)).unwrap();
        let v = |esc| map.get(esc, "x").v4_volts_per_step.to_string();
        assert_eq!((v(0), v(1)), ("11/650".to_string(), "9/700".to_string()));
        let (_dir, config) = load("[settings]\nv4_volts_per_step = \"9/0\"\n");
        let err = config.unwrap_err().to_string();
        assert!(err.contains("config.toml line 2"), "{err}");
        assert!(err.contains("volts per step must be N/D"), "{err}");
    }

    /// Every format's own setting is a key of every settings table, by its description's key;
    /// an unknown key's error lists them.
    #[test]
    fn the_formats_settings_are_keys_of_every_table() {
        for setting in Protocol::settings() {
            let (key, value) = (setting.key, setting.default);
            let text = format!(
                "[settings]\n{key} = \"{value}\"\n[port.\"p\"]\n{key} = \"{value}\"\n\
                 [esc.1]\n{key} = \"{value}\"\n"
            );
            let (_dir, config) = load(&text);
            let map = config.unwrap().settings_map(&flags(None)).unwrap();
            assert_eq!(map.get(1, "p"), Settings::DEFAULT, "{key}");
            let (_dir, config) = load(&format!("[[esc]]\nport = \"p\"\n{key} = \"{value}\"\n"));
            let map = config.unwrap().settings_map(&flags(None)).unwrap();
            assert_eq!(map.get(0, "p"), Settings::DEFAULT, "{key}");
        }
        let (_dir, config) = load("[esc.1]\nv4_volts = \"hv\"\n");
        let err = config.unwrap_err().to_string();
        assert!(
            err.contains("config.toml line 2: unknown field `v4_volts`"),
            "{err}"
        );
        for setting in Protocol::settings() {
            assert!(err.contains(&format!("`{}`", setting.key)), "{err}");
        }
        let (_dir, config) = load("[[esc]]\nv4_volts_per_step = \"hv\"\n");
        let err = config.unwrap_err().to_string();
        assert!(err.contains("missing field `port`"), "{err}");
    }

    #[test]
    fn a_missing_named_file_is_an_error() {
        let err = Config::load(&flags(Some(Path::new("/nonexistent/c.toml"))), false)
            .unwrap_err()
            .to_string();
        assert!(err.contains("/nonexistent/c.toml"), "{err}");
    }
}
