//! The settings tables of the configuration file (`[settings]`, `[port."NAME"]`, `[esc.N]` and
//! the older `[[esc]]` list): the common settings, a label, and each format's own settings by
//! the keys of the formats' descriptions (`v4_volts_per_step = "hv"`), read as `--set
//! KEY=VALUE` reads them.

use std::fmt;
use std::sync::LazyLock;

use hwfoc::Protocol;
use hwfoc::format::SettingDescription;
use hwfoc::protocol::SettingError;
use hwfoc_io::SettingsPatch;
use serde::Deserialize;
use serde::de::{self, DeserializeSeed, Deserializer, MapAccess, Visitor};

/// The keys of a settings table besides the formats' own settings.
const COMMON_KEYS: [&str; 4] = ["current_scale", "pole_pairs", "gear_ratio", "label"];

/// Every key a settings table takes: [`COMMON_KEYS`], then every format setting's key (what
/// an unknown key's error lists).
static KEYS: LazyLock<Vec<&'static str>> = LazyLock::new(|| {
    COMMON_KEYS
        .into_iter()
        .chain(Protocol::settings().map(|s| s.key))
        .collect()
});

/// Settings of every ESC, of a port's or of one ESC.
#[derive(Debug, Default, Clone, PartialEq)]
pub(super) struct Entry {
    pub current_scale: Option<f32>,
    pub pole_pairs: Option<u16>,
    pub gear_ratio: Option<f32>,
    /// The formats' own settings the table gives (each as [`SettingsPatch::format_setting`]).
    pub formats: SettingsPatch,
    /// A name shown by the monitor (not in `[settings]`).
    pub label: Option<String>,
}

impl Entry {
    /// The settings the entry gives.
    pub fn patch(&self) -> SettingsPatch {
        SettingsPatch {
            current_scale: self.current_scale,
            pole_pairs: self.pole_pairs,
            gear_ratio: self.gear_ratio,
            ..SettingsPatch::default()
        }
        .over(&self.formats)
    }
}

/// An entry of the older `[[esc]]` list: a port, and settings for it.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct PortEntry {
    pub port: String,
    pub entry: Entry,
}

impl<'de> Deserialize<'de> for Entry {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let (port, entry) = deserializer.deserialize_map(Table { with_port: false })?;
        debug_assert!(port.is_none());
        Ok(entry)
    }
}

impl<'de> Deserialize<'de> for PortEntry {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let (port, entry) = deserializer.deserialize_map(Table { with_port: true })?;
        let port = port.ok_or_else(|| de::Error::missing_field("port"))?;
        Ok(PortEntry { port, entry })
    }
}

/// Reads a settings table (and, as a key's seed, one of its keys); `with_port`: the `[[esc]]`
/// list's, which has a `port` key too.
#[derive(Debug, Clone, Copy)]
struct Table {
    with_port: bool,
}

impl<'de> Visitor<'de> for Table {
    type Value = (Option<String>, Entry);

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a table of settings")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let mut entry = Entry::default();
        let mut port = None;
        // The key is checked as it is read, so that an unknown one's error names its line.
        while let Some(key) = map.next_key_seed(self)? {
            match key {
                Key::CurrentScale => entry.current_scale = Some(map.next_value()?),
                Key::PolePairs => entry.pole_pairs = Some(map.next_value()?),
                Key::GearRatio => entry.gear_ratio = Some(map.next_value()?),
                Key::Label => entry.label = Some(map.next_value()?),
                Key::Port => port = Some(map.next_value()?),
                Key::Format(setting) => {
                    let patch = map.next_value_seed(FormatValue(setting))?;
                    entry.formats = patch.over(&entry.formats);
                }
            }
        }
        Ok((port, entry))
    }
}

/// A key of a settings table.
enum Key {
    CurrentScale,
    PolePairs,
    GearRatio,
    Label,
    Port,
    /// A format's own setting.
    Format(&'static SettingDescription),
}

impl<'de> DeserializeSeed<'de> for Table {
    type Value = Key;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<Key, D::Error> {
        let key = String::deserialize(deserializer)?;
        Ok(match key.as_str() {
            "current_scale" => Key::CurrentScale,
            "pole_pairs" => Key::PolePairs,
            "gear_ratio" => Key::GearRatio,
            "label" => Key::Label,
            "port" if self.with_port => Key::Port,
            key => Key::Format(
                Protocol::settings()
                    .find(|s| s.key == key)
                    .ok_or_else(|| de::Error::unknown_field(key, &KEYS))?,
            ),
        })
    }
}

/// The value of a format setting, checked by its description (so that a bad one's error names
/// its line): its [`SettingsPatch`].
struct FormatValue(&'static SettingDescription);

impl<'de> DeserializeSeed<'de> for FormatValue {
    type Value = SettingsPatch;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<SettingsPatch, D::Error> {
        let text = String::deserialize(deserializer)?;
        SettingsPatch::format_setting(self.0.key, &text).map_err(|e| match e {
            SettingError::Value { reason, .. } => de::Error::custom(reason),
            SettingError::UnknownKey => de::Error::custom(e),
        })
    }
}
