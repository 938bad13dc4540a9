//! Conversion settings as JSON (the Parquet metadata, the summary's JSON report).

use hwfoc::Settings;

/// The settings of some ESCs as one JSON object by ESC index:
/// `{"2": {"current_scale": 100.0, "pole_pairs": 14, "gear_ratio": 1.0}}` (the Parquet
/// metadata key `esc_settings`).
pub fn esc_settings_json(escs: &[(u8, Settings)]) -> String {
    let map: serde_json::Map<String, serde_json::Value> = escs
        .iter()
        .map(|(esc, s)| (esc.to_string(), settings_json(s)))
        .collect();
    serde_json::Value::Object(map).to_string()
}

/// Settings as a JSON object: `{"current_scale": 64.0, "pole_pairs": 7, "gear_ratio": 1.0}`.
pub fn settings_json(s: &Settings) -> serde_json::Value {
    serde_json::json!({
        "current_scale": s.current_scale,
        "pole_pairs": s.pole_pairs,
        "gear_ratio": s.gear_ratio,
    })
}
