//! What records were made from, as key-value metadata: the one definition of the entries of the
//! Parquet export's footer (and of its `ARROW:schema`, whose own metadata repeats them) and of
//! the metadata of the Python package's Arrow schema (`hwfoc.read`, `scan`, `record_schema`).
//!
//! The entries: `hwfoc_version`; `record_schema_version` ([`crate::RECORD_SCHEMA_VERSION`]);
//! the settings (`current_scale`, `pole_pairs`, `gear_ratio`,
//! named as in every output); `inputs`, a JSON array of the input names; `filter` when records
//! were selected ([`crate::filter_text`]); and, once every input is read,
//! [`ESCS`] ([`escs_json`]) and, for the Parquet export when some ESC had settings of its own,
//! [`ESC_SETTINGS`] ([`esc_settings_json`]).

use std::sync::Arc;

use arrow_schema::{Schema, SchemaRef};

use super::Provenance;
use super::arrow::schema;
use hwfoc::Settings;

use crate::settings;
use crate::sources::Sources;

/// The key of the record schema's version ([`crate::RECORD_SCHEMA_VERSION`]).
pub const RECORD_SCHEMA_VERSION_KEY: &str = "record_schema_version";

/// The key of which ESC is which ([`escs_json`]).
pub const ESCS: &str = "escs";

/// The key of the settings of ESCs that had their own ([`esc_settings_json`]).
pub const ESC_SETTINGS: &str = "esc_settings";

impl Provenance {
    /// What records made under `settings` from `inputs` (their names), selected as `filter`
    /// says ([`crate::filter_text`], empty for all), record: for a reader of records
    /// that writes no CSV (no settings by port or ESC, no CSV comment).
    pub fn new(settings: hwfoc::Settings, inputs: Vec<String>, filter: String) -> Provenance {
        Provenance {
            settings,
            overrides: Vec::new(),
            inputs,
            filter,
            csv_comment: false,
            csv_time_iso: false,
        }
    }

    /// The key-value entries known before the first record, in this order: `hwfoc_version`,
    /// `record_schema_version`, the settings, `inputs`, and `filter` when records were
    /// selected.
    pub fn key_values(&self) -> Vec<(String, String)> {
        let mut kv = vec![
            (
                "hwfoc_version".to_string(),
                env!("CARGO_PKG_VERSION").to_string(),
            ),
            (
                RECORD_SCHEMA_VERSION_KEY.to_string(),
                crate::RECORD_SCHEMA_VERSION.to_string(),
            ),
        ];
        kv.extend(
            settings::fields(&self.settings)
                .into_iter()
                .map(|(name, value)| (name.to_string(), value.to_string())),
        );
        kv.push((
            "inputs".to_string(),
            serde_json::Value::from(self.inputs.clone()).to_string(),
        ));
        if !self.filter.is_empty() {
            kv.push(("filter".to_string(), self.filter.clone()));
        }
        kv
    }
}

impl Provenance {
    /// The record schema ([`schema`]) with [`Provenance::key_values`] and, when given, which
    /// ESC is which (`escs`, see [`escs_json`]) as its metadata: the schema of the Python
    /// package's records.
    pub fn schema(&self, escs: Option<String>) -> SchemaRef {
        let mut kv = self.key_values();
        kv.extend(escs.map(|escs| (ESCS.to_string(), escs)));
        Arc::new(schema_with(&kv))
    }
}

/// The settings of some ESCs as one JSON object by ESC index:
/// `{"2": {"current_scale": 100.0, "pole_pairs": 14, "gear_ratio": 1.0}}` (the Parquet
/// metadata key [`ESC_SETTINGS`]).
pub fn esc_settings_json(escs: &[(u8, Settings)]) -> String {
    let map: serde_json::Map<String, serde_json::Value> = escs
        .iter()
        .map(|(esc, s)| (esc.to_string(), settings::settings_json(s)))
        .collect();
    serde_json::Value::Object(map).to_string()
}

/// Which ESC is which, the value of [`ESCS`]:
/// `[{"esc": 0, "input": "a.pcapng", "stream": "/dev/ttyUSB0", "protocol": "hw-foc"}, ...]`;
/// `protocol` is the format its frames came in (null without frames), and a V4 ESC has
/// `v4_info`: the info frame whose constants were adopted (two identical copies), as
/// [`device_json`](crate::summary::device_json) gives it, or null before one was.
pub fn escs_json(sources: &Sources) -> String {
    let escs: Vec<serde_json::Value> = sources
        .esc_table()
        .iter()
        .enumerate()
        .map(|(i, esc)| {
            let link = sources.link(i);
            let framed = link.frames() + link.info_frames() > 0;
            let mut entry = serde_json::json!({
                "esc": i,
                "input": sources.names()[esc.input],
                "stream": esc.key.port,
                "protocol": framed.then(|| link.protocol().name()),
            });
            if let Some(key) = link
                .protocol()
                .description()
                .adopted_info
                .filter(|_| framed)
            {
                let info = link.adopted_info().map(|i| crate::summary::device_json(&i));
                entry[key] = serde_json::json!(info);
            }
            entry
        })
        .collect();
    serde_json::Value::from(escs).to_string()
}

/// The record schema ([`schema`]) with `metadata` as its own key-value metadata.
pub(crate) fn schema_with<'a>(metadata: impl IntoIterator<Item = &'a (String, String)>) -> Schema {
    schema().with_metadata(
        metadata
            .into_iter()
            .cloned()
            .collect::<std::collections::HashMap<_, _>>(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn provenance_entries_in_order() {
        let settings = hwfoc::Settings::new(100.0, 14, 2.5).unwrap();
        let inputs = vec!["a.pcapng".to_string(), "b \"c\".csv".to_string()];
        let p = Provenance::new(settings, inputs, "esc=1 from=+2".to_string());
        let kv = p.key_values();
        let kv: Vec<(&str, &str)> = kv.iter().map(|(k, v)| (k.as_str(), v.as_str())).collect();
        assert_eq!(
            kv,
            [
                ("hwfoc_version", env!("CARGO_PKG_VERSION")),
                ("record_schema_version", "4"),
                ("current_scale", "100"),
                ("pole_pairs", "14"),
                ("gear_ratio", "2.5"),
                ("v4_volts_per_step", "8/910"),
                ("inputs", r#"["a.pcapng","b \"c\".csv"]"#),
                ("filter", "esc=1 from=+2"),
            ]
        );
        let unfiltered = Provenance::new(hwfoc::Settings::DEFAULT, Vec::new(), String::new());
        let keys: Vec<String> = unfiltered
            .key_values()
            .into_iter()
            .map(|(k, _)| k)
            .collect();
        assert_eq!(
            keys,
            [
                "hwfoc_version",
                "record_schema_version",
                "current_scale",
                "pole_pairs",
                "gear_ratio",
                "v4_volts_per_step",
                "inputs"
            ]
        );
    }

    #[test]
    fn escs_name_their_input_and_stream() {
        let inputs = ["front", "rear"].map(|name| {
            let frame = hwfoc::foc::DataFrame::default().encode();
            crate::Input::from_memory(name, frame.to_vec()).unwrap()
        });
        let mut sources = Sources::new(inputs.into(), hwfoc::Settings::DEFAULT);
        sources.run(&mut crate::summary::Summary::new()).unwrap();
        assert_eq!(
            escs_json(&sources),
            r#"[{"esc":0,"input":"front","stream":"front","protocol":"hw-foc"},{"esc":1,"input":"rear","stream":"rear","protocol":"hw-foc"}]"#
        );
    }

    #[test]
    fn the_schema_carries_the_metadata() {
        let kv = [("k".to_string(), "v".to_string())];
        let s = schema_with(&kv);
        assert_eq!(s.metadata().get("k").map(String::as_str), Some("v"));
        assert_eq!(s.fields(), schema().fields());
        let p = Provenance::new(hwfoc::Settings::DEFAULT, Vec::new(), String::new());
        let with_escs = p.schema(Some("[]".to_string()));
        assert_eq!(with_escs.metadata().len(), 8);
        assert_eq!(with_escs.metadata()["record_schema_version"], "4");
        assert_eq!(with_escs.metadata()["escs"], "[]");
        assert_eq!(with_escs.metadata()["pole_pairs"], "7");
        assert!(p.schema(None).metadata().get("escs").is_none());
    }
}
