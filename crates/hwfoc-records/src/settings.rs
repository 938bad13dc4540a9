//! Conversion settings per ESC: the ESCs of one aircraft can drive different motors (pole pairs,
//! gearing) or measure current differently (scale), so each ESC's frames are converted under
//! its own [`Settings`].
//!
//! A [`SettingsMap`] holds the settings of every ESC not named otherwise, and partial settings
//! ([`SettingsPatch`]) by port name (the stream an ESC is read from: a serial port, a port named
//! in a recording, a file) and by ESC index. An ESC's settings are, field by field: its index's
//! patch, then its port's patch, then the defaults. A map made `From` one [`Settings`] gives
//! every ESC those.
//!
//! ```
//! use hwfoc::Settings;
//! use hwfoc_records::{SettingsMap, SettingsPatch};
//!
//! let mut map = SettingsMap::from(Settings::DEFAULT);
//! map.set_port("/dev/ttyUSB1", SettingsPatch { current_scale: Some(100.0), ..Default::default() });
//! map.set_esc(1, SettingsPatch { pole_pairs: Some(14), ..Default::default() });
//! let one = map.get(1, "/dev/ttyUSB1");
//! assert_eq!((one.current_scale, one.pole_pairs), (100.0, 14));
//! assert_eq!(map.get(0, "/dev/ttyUSB0"), Settings::DEFAULT);
//! ```

use std::collections::BTreeMap;
use std::fmt;

use hwfoc::Protocol;
use hwfoc::protocol::SettingError;
use hwfoc::v4::VoltsPerStep;
use hwfoc::{Settings, SettingsError};

/// The value of one conversion setting, written as every output writes it: in text (a Parquet
/// key-value entry, the CSV comment) by its `Display`, `64` or `2.5`; in JSON as a number,
/// `64.0` or `7`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SettingValue {
    /// A scale or a ratio.
    Real(f32),
    /// A count.
    Count(u16),
    /// A fraction, `8/910` (the V4 volts per step before an info frame).
    Fraction(VoltsPerStep),
}

impl fmt::Display for SettingValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SettingValue::Real(v) => v.fmt(f),
            SettingValue::Count(v) => v.fmt(f),
            SettingValue::Fraction(v) => v.fmt(f),
        }
    }
}

impl From<SettingValue> for serde_json::Value {
    fn from(v: SettingValue) -> serde_json::Value {
        match v {
            SettingValue::Real(v) => v.into(),
            SettingValue::Count(v) => v.into(),
            SettingValue::Fraction(v) => v.to_string().into(),
        }
    }
}

/// The fields of `settings` by their name in every output (Parquet metadata, the CSV comment,
/// the JSON of `summary` and `monitor`, the Python package's keyword arguments), in that
/// order: `current_scale`, `pole_pairs`, `gear_ratio`, `v4_volts_per_step`.
pub fn fields(settings: &Settings) -> [(&'static str, SettingValue); 4] {
    [
        ("current_scale", SettingValue::Real(settings.current_scale)),
        ("pole_pairs", SettingValue::Count(settings.pole_pairs)),
        ("gear_ratio", SettingValue::Real(settings.gear_ratio)),
        (
            "v4_volts_per_step",
            SettingValue::Fraction(settings.v4_volts_per_step),
        ),
    ]
}

/// The fields of `settings` as people read them, each its name in words and its value:
/// `["current scale 64", "pole pairs 7", "gear ratio 1"]` (`hwfoc summary`; the V4 volts per
/// step, which only V4 ESCs read, only where it is not the default 8/910); with `default`, only
/// those that differ from it.
pub(crate) fn words(settings: &Settings, default: Option<&Settings>) -> Vec<String> {
    let defaults = default.map(fields);
    let builtin = fields(&Settings::DEFAULT);
    fields(settings)
        .into_iter()
        .enumerate()
        .filter(|&(i, (_, value))| defaults.is_none_or(|d| d[i].1 != value))
        .filter(|&(i, (name, value))| name != "v4_volts_per_step" || builtin[i].1 != value)
        .map(|(_, (name, value))| format!("{} {value}", name.replace('_', " ")))
        .collect()
}

/// Settings as a JSON object, keyed by their names in every output:
/// `{"current_scale": 64.0, "pole_pairs": 7, "gear_ratio": 1.0}`.
pub fn settings_json(settings: &Settings) -> serde_json::Value {
    serde_json::Value::Object(
        fields(settings)
            .into_iter()
            .map(|(name, value)| (name.to_string(), value.into()))
            .collect(),
    )
}

/// Some of the fields of [`Settings`]; `None` leaves a field to the next level.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SettingsPatch {
    /// Raw current units per ampere.
    pub current_scale: Option<f32>,
    /// Motor pole pairs.
    pub pole_pairs: Option<u16>,
    /// Gear ratio between motor and output shaft.
    pub gear_ratio: Option<f32>,
    /// Volts per voltage step of a V4 ESC before its info frame.
    pub v4_volts_per_step: Option<VoltsPerStep>,
}

impl SettingsPatch {
    /// The fields of `self` that are set, the others from `under`.
    pub fn over(&self, under: &SettingsPatch) -> SettingsPatch {
        SettingsPatch {
            current_scale: self.current_scale.or(under.current_scale),
            pole_pairs: self.pole_pairs.or(under.pole_pairs),
            gear_ratio: self.gear_ratio.or(under.gear_ratio),
            v4_volts_per_step: self.v4_volts_per_step.or(under.v4_volts_per_step),
        }
    }

    /// `base` with the fields of `self` that are set, checked as [`Settings::new`] does.
    pub fn apply(&self, base: &Settings) -> Result<Settings, SettingsError> {
        Ok(Settings {
            v4_volts_per_step: self.v4_volts_per_step.unwrap_or(base.v4_volts_per_step),
            ..Settings::new(
                self.current_scale.unwrap_or(base.current_scale),
                self.pole_pairs.unwrap_or(base.pole_pairs),
                self.gear_ratio.unwrap_or(base.gear_ratio),
            )?
        })
    }

    /// The patch that sets a format's own setting, `key` (a key of a format's description:
    /// [`SettingDescription`](hwfoc::format::SettingDescription), `-` and `_` alike) to `value`: what `--set KEY=VALUE` gives.
    ///
    /// ```
    /// use hwfoc::v4::VoltsPerStep;
    /// use hwfoc_records::SettingsPatch;
    ///
    /// let patch = SettingsPatch::format_setting("v4-volts-per-step", "hv")?;
    /// assert_eq!(patch.v4_volts_per_step, Some(VoltsPerStep::HIGH_VOLTAGE));
    /// assert!(SettingsPatch::format_setting("v4_volts_per_step", "8/0").is_err());
    /// assert!(SettingsPatch::format_setting("no_such_key", "1").is_err());
    /// # Ok::<(), hwfoc::protocol::SettingError>(())
    /// ```
    pub fn format_setting(key: &str, value: &str) -> Result<SettingsPatch, SettingError> {
        let setting = Protocol::setting(key).ok_or(SettingError::UnknownKey)?;
        let mut settings = Settings::DEFAULT;
        Protocol::apply_setting(&mut settings, setting.key, value)?;
        let mut patch = SettingsPatch::default();
        let (_, field) = FORMAT_FIELDS
            .iter()
            .find(|(k, _)| *k == setting.key)
            .ok_or(SettingError::UnknownKey)?;
        field(&settings, &mut patch);
        Ok(patch)
    }

    /// Whether no field is set.
    pub fn is_empty(&self) -> bool {
        *self == SettingsPatch::default()
    }

    /// The fields that are set, named and ordered as in every output
    /// (`current_scale`, `pole_pairs`, `gear_ratio`, `v4_volts_per_step`).
    pub fn fields(&self) -> impl Iterator<Item = (&'static str, SettingValue)> {
        let given = [
            self.current_scale.is_some(),
            self.pole_pairs.is_some(),
            self.gear_ratio.is_some(),
            self.v4_volts_per_step.is_some(),
        ];
        let values = fields(&Settings {
            current_scale: self.current_scale.unwrap_or_default(),
            pole_pairs: self.pole_pairs.unwrap_or_default(),
            gear_ratio: self.gear_ratio.unwrap_or_default(),
            v4_volts_per_step: self.v4_volts_per_step.unwrap_or_default(),
        });
        values
            .into_iter()
            .zip(given)
            .filter_map(|(field, given)| given.then_some(field))
    }
}

/// Sets a patch's field from [`Settings`].
type SetField = fn(&Settings, &mut SettingsPatch);

/// The patch's field of each format setting, by the setting's key
/// ([`SettingDescription::key`](hwfoc::format::SettingDescription::key)): what [`SettingsPatch::format_setting`] sets from the
/// [`Settings`] the description's `apply` wrote (a test checks that every format setting has
/// one).
const FORMAT_FIELDS: [(&str, SetField); 1] = [("v4_volts_per_step", |s, p| {
    p.v4_volts_per_step = Some(s.v4_volts_per_step)
})];

/// The settings of every ESC: defaults, and patches by port name and by ESC index.
#[derive(Debug, Clone, PartialEq)]
pub struct SettingsMap {
    default: Settings,
    ports: BTreeMap<String, (SettingsPatch, Settings)>,
    escs: BTreeMap<usize, SettingsPatch>,
}

impl From<Settings> for SettingsMap {
    fn from(default: Settings) -> SettingsMap {
        SettingsMap {
            default,
            ports: BTreeMap::new(),
            escs: BTreeMap::new(),
        }
    }
}

impl SettingsMap {
    /// Every ESC under `default`, until patches are set.
    pub fn new(default: Settings) -> SettingsMap {
        SettingsMap::from(default)
    }

    /// The settings of ESCs that no patch names.
    pub fn default_settings(&self) -> &Settings {
        &self.default
    }

    /// Sets the patch of the ESCs read from port `name`. A patch that [`Settings::new`]
    /// refuses over the defaults is an error (and not set).
    pub fn set_port(
        &mut self,
        name: impl Into<String>,
        patch: SettingsPatch,
    ) -> Result<(), SettingsError> {
        let settings = patch.apply(&self.default)?;
        self.ports.insert(name.into(), (patch, settings));
        Ok(())
    }

    /// Sets the patch of ESC `esc`. A patch that [`Settings::new`] refuses over the defaults is
    /// an error (and not set).
    pub fn set_esc(&mut self, esc: usize, patch: SettingsPatch) -> Result<(), SettingsError> {
        patch.apply(&self.default)?;
        self.escs.insert(esc, patch);
        Ok(())
    }

    /// The settings of ESC `esc`, read from port (or stream) `name`: field by field, the ESC's
    /// patch, the port's patch, the defaults.
    pub fn get(&self, esc: usize, name: &str) -> Settings {
        let port = self.ports.get(name);
        match (self.escs.get(&esc), port) {
            (None, None) => self.default,
            (None, Some((_, settings))) => *settings,
            (Some(patch), port) => {
                let under = port.map(|(p, _)| *p).unwrap_or_default();
                // Each field was checked on its own, and the checks are field by field.
                patch
                    .over(&under)
                    .apply(&self.default)
                    .unwrap_or(self.default)
            }
        }
    }

    /// The patches by port name, in name order.
    pub fn port_patches(&self) -> impl Iterator<Item = (&str, &SettingsPatch)> {
        self.ports
            .iter()
            .map(|(name, (patch, _))| (name.as_str(), patch))
    }

    /// The patches by ESC index, in index order.
    pub fn esc_patches(&self) -> impl Iterator<Item = (usize, &SettingsPatch)> {
        self.escs.iter().map(|(&esc, patch)| (esc, patch))
    }

    /// Whether every ESC has the defaults.
    pub fn is_uniform(&self) -> bool {
        self.ports.is_empty() && self.escs.is_empty()
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_format_setting_has_a_patch_field_and_its_default() {
        let keys: Vec<&str> = Protocol::settings().map(|s| s.key).collect();
        assert!(!keys.is_empty());
        for setting in Protocol::settings() {
            let patch = SettingsPatch::format_setting(setting.key, setting.default)
                .unwrap_or_else(|e| panic!("{}: {e}", setting.key));
            assert!(!patch.is_empty(), "{}", setting.key);
            // The description's default is the settings' default, named as every output does.
            let applied = patch.apply(&Settings::DEFAULT).unwrap();
            assert_eq!(applied, Settings::DEFAULT, "{}", setting.key);
            let (name, _) = patch.fields().next().unwrap();
            assert_eq!(name, setting.key);
        }
        assert_eq!(FORMAT_FIELDS.len(), keys.len());
    }

    use super::*;

    fn patch(scale: Option<f32>, pairs: Option<u16>, ratio: Option<f32>) -> SettingsPatch {
        SettingsPatch {
            current_scale: scale,
            pole_pairs: pairs,
            gear_ratio: ratio,
            v4_volts_per_step: None,
        }
    }

    #[test]
    fn the_esc_beats_the_port_beats_the_defaults_field_by_field() {
        let base = Settings::new(64.0, 7, 1.0).unwrap();
        let mut map = SettingsMap::new(base);
        assert!(map.is_uniform());
        map.set_port("a", patch(Some(100.0), Some(12), None))
            .unwrap();
        map.set_esc(2, patch(None, Some(14), Some(2.0))).unwrap();
        assert!(!map.is_uniform());
        assert_eq!(map.get(0, "b"), base);
        assert_eq!(map.get(0, "a"), Settings::new(100.0, 12, 1.0).unwrap());
        assert_eq!(map.get(2, "a"), Settings::new(100.0, 14, 2.0).unwrap());
        assert_eq!(map.get(2, "b"), Settings::new(64.0, 14, 2.0).unwrap());
        assert_eq!(map.default_settings(), &base);
        let ports: Vec<_> = map.port_patches().map(|(n, p)| (n, p.pole_pairs)).collect();
        assert_eq!(ports, [("a", Some(12))]);
        let escs: Vec<_> = map.esc_patches().map(|(e, p)| (e, p.gear_ratio)).collect();
        assert_eq!(escs, [(2, Some(2.0))]);
    }

    /// Collects (esc, rpm, current) of each record.
    #[derive(Default)]
    struct Rows(Vec<(u8, f32, f32)>);

    impl crate::Handler for Rows {
        type Error = crate::InputError;

        fn record(&mut self, r: &crate::Record) {
            self.0.push((r.esc, r.rpm.unwrap(), r.current_a.unwrap()));
        }
    }

    /// Three frames of 700 eRPM (raw 70, in 10 eRPM units) and 12.8 A at scale 64 (raw 819).
    fn wire() -> Vec<u8> {
        (0..3u16)
            .flat_map(|packet| {
                hwfoc::foc::DataFrame {
                    packet,
                    erpm_raw: 70,
                    current_raw: 819,
                    ..Default::default()
                }
                .encode()
            })
            .collect()
    }

    #[test]
    fn sources_convert_each_escs_frames_under_its_own_settings() {
        let inputs = ["front", "rear", "tail"]
            .map(|name| crate::Input::from_memory(name, wire()).unwrap())
            .into();
        let mut map = SettingsMap::from(Settings::DEFAULT);
        map.set_esc(1, patch(None, Some(14), None)).unwrap();
        map.set_port("tail", patch(Some(100.0), None, None))
            .unwrap();
        let mut sources = crate::Sources::new(inputs, map);
        let mut rows = Rows::default();
        sources.run(&mut rows).unwrap();
        let first = |esc: u8| *rows.0.iter().find(|r| r.0 == esc).unwrap();
        let (_, rpm0, amps0) = first(0);
        let (_, rpm1, amps1) = first(1);
        let (_, rpm2, amps2) = first(2);
        assert_eq!(rpm0, 100.0);
        assert_eq!(rpm1, 50.0);
        assert_eq!(rpm2, 100.0);
        assert!((amps0 - 819.0 / 64.0).abs() < 1e-4 && amps1 == amps0);
        assert!((amps2 - 8.19).abs() < 1e-4);
        assert_eq!(rows.0.len(), 9);
        assert_eq!(sources.esc_settings(2).current_scale, 100.0);
        assert_eq!(sources.settings(), &Settings::DEFAULT);
    }

    #[test]
    fn port_streams_convert_each_port_under_its_settings() {
        let mut map = SettingsMap::from(Settings::DEFAULT);
        map.set_port("/dev/ttyUSB1", patch(None, Some(14), None))
            .unwrap();
        let names = vec!["/dev/ttyUSB0".to_string(), "/dev/ttyUSB1".to_string()];
        let mut streams = crate::stream::PortStreams::with_map(19_200, names, map);
        let mut rows = Rows::default();
        for port in 0..2 {
            let event = crate::serial::PortEvent::Data {
                port,
                t_ns: 1_000_000_000,
                bytes: wire(),
            };
            assert!(streams.feed(&event, &mut rows).is_some());
        }
        let rpm: Vec<(u8, f32)> = rows.0.iter().map(|r| (r.0, r.1)).collect();
        assert!(
            rpm.contains(&(0, 100.0)) && rpm.contains(&(1, 50.0)),
            "{rpm:?}"
        );
        assert!(!rpm.contains(&(1, 100.0)), "{rpm:?}");
    }

    #[test]
    fn settings_are_written_under_their_names() {
        let s = Settings::new(100.0, 14, 2.5).unwrap();
        let text: Vec<String> = fields(&s).iter().map(|(n, v)| format!("{n}={v}")).collect();
        assert_eq!(
            text,
            [
                "current_scale=100",
                "pole_pairs=14",
                "gear_ratio=2.5",
                "v4_volts_per_step=8/910"
            ]
        );
        assert_eq!(
            settings_json(&Settings::DEFAULT).to_string(),
            r#"{"current_scale":64.0,"pole_pairs":7,"gear_ratio":1.0,"v4_volts_per_step":"8/910"}"#
        );
        let set: Vec<String> = patch(None, Some(3), Some(0.5))
            .fields()
            .map(|(n, v)| format!("{n}={v}"))
            .collect();
        assert_eq!(set, ["pole_pairs=3", "gear_ratio=0.5"]);
        assert_eq!(patch(None, None, None).fields().count(), 0);
        assert_eq!(
            words(&s, None),
            ["current scale 100", "pole pairs 14", "gear ratio 2.5"]
        );
        let other = Settings::new(100.0, 7, 2.5).unwrap();
        assert_eq!(words(&s, Some(&other)), ["pole pairs 14"]);
        assert!(words(&s, Some(&s)).is_empty());
    }

    #[test]
    fn a_patch_that_makes_bad_settings_is_refused() {
        let mut map = SettingsMap::from(Settings::DEFAULT);
        assert!(map.set_esc(0, patch(None, Some(0), None)).is_err());
        assert!(map.set_port("p", patch(Some(-1.0), None, None)).is_err());
        assert!(map.is_uniform());
        assert!(patch(None, None, None).is_empty());
    }
}
