//! What the simulator's integration tests share.

use hwfoc_sim::model::ModelConfig;

/// The model of `hwfoc simulate`'s defaults: 500 KV, 7 pole pairs, 60 A at full throttle, 6
/// cells of 5000 mAh at 0.02 ohm, 25 degC, 64 raw units per ampere.
pub fn model() -> ModelConfig {
    ModelConfig {
        kv: 500.0,
        pole_pairs: 7,
        full_current_a: 60.0,
        cells: 6,
        battery_r_ohm: 0.02,
        capacity_mah: 5000.0,
        ambient_c: 25.0,
        current_scale: 64.0,
    }
}
