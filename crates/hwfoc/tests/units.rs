//! The conversions of `hwfoc::units` against the formulas they replace, bit for bit: the data
//! frame's methods as they were written out (f32), and the CLI summary's conversions of minima,
//! maxima and means (f64). Every raw value of every field, under several settings.

use hwfoc::units::{ERPM_PER_RAW, Linear};
use hwfoc::{DataFrame, Quantity, Settings};

/// The settings tried: the default, the `x 0.01` current scale, and unusual ones.
fn settings() -> Vec<Settings> {
    [
        (64.0, 7, 1.0),
        (100.0, 7, 1.0),
        (64.0, 14, 1.5),
        (17.3, 3, 0.37),
        (1e-3, 65_535, 1e3),
        (12_345.678, 1, 1e-7),
        (f32::MAX, 2, 3.0e-38),
    ]
    .into_iter()
    .map(|(scale, poles, gear)| Settings::new(scale, poles, gear).unwrap())
    .collect()
}

/// The frame's conversions as they were written before `Linear`.
fn old_f32(q: Quantity, raw: i32, s: &Settings) -> f32 {
    match q {
        Quantity::ThrottleIn | Quantity::ThrottleOut => f32::from(raw as u16) * 100.0 / 1024.0,
        Quantity::Erpm => (u32::from(raw as u16) * 10) as f32,
        Quantity::Rpm => {
            (u32::from(raw as u16) * 10) as f32 / (s.gear_ratio * f32::from(s.pole_pairs))
        }
        Quantity::Voltage => f32::from(raw as u16) / 10.0,
        Quantity::Current | Quantity::PhaseCurrent => f32::from(raw as i16) / s.current_scale,
    }
}

/// The CLI summary's conversions (`summary.rs`), of a raw value or a mean of raw values.
fn old_f64(q: Quantity, x: f64, s: &Settings) -> f64 {
    match q {
        Quantity::ThrottleIn | Quantity::ThrottleOut => x * 100.0 / 1024.0,
        Quantity::Erpm => x * 10.0,
        Quantity::Rpm => x * 10.0 / (f64::from(s.gear_ratio) * f64::from(s.pole_pairs)),
        Quantity::Voltage => x / 10.0,
        Quantity::Current | Quantity::PhaseCurrent => x / f64::from(s.current_scale),
    }
}

/// The frame method for `q`, as the CLI's writers call it.
fn method(f: &DataFrame, q: Quantity, s: &Settings) -> f32 {
    match q {
        Quantity::ThrottleIn => f.throttle_in_pct(),
        Quantity::ThrottleOut => f.throttle_out_pct(),
        Quantity::Erpm => f.erpm() as f32,
        Quantity::Rpm => f.rpm(s),
        Quantity::Voltage => f.voltage_v(),
        Quantity::Current => f.current_a(s),
        Quantity::PhaseCurrent => f.phase_current_a(s),
    }
}

/// A frame whose field for `q` holds the 16 bits of `bits`.
fn frame_with(q: Quantity, bits: u16) -> DataFrame {
    let mut f = DataFrame::default();
    match q {
        Quantity::ThrottleIn => f.throttle_in_raw = bits,
        Quantity::ThrottleOut => f.throttle_out_raw = bits,
        Quantity::Erpm | Quantity::Rpm => f.erpm_raw = bits,
        Quantity::Voltage => f.voltage_raw = bits,
        Quantity::Current => f.current_raw = bits as i16,
        Quantity::PhaseCurrent => f.phase_current_raw = bits as i16,
    }
    f
}

#[test]
fn every_raw_value_converts_bit_for_bit_as_before() {
    for s in settings() {
        for q in Quantity::ALL {
            let linear = q.linear(&s);
            for bits in 0..=u16::MAX {
                let f = frame_with(q, bits);
                let raw = f.raw(q);
                let old = old_f32(q, raw, &s).to_bits();
                assert_eq!(method(&f, q, &s).to_bits(), old, "{q:?} {raw} {s:?}");
                assert_eq!(f.value(q, &s).to_bits(), old, "{q:?} {raw} {s:?}");
                assert_eq!(linear.to_f32(raw as f32).to_bits(), old, "{q:?} {raw}");
                // A raw minimum or maximum, and means that are not whole numbers.
                for x in [f64::from(raw), f64::from(raw) + 0.5, f64::from(raw) / 3.0] {
                    assert_eq!(
                        linear.to_f64(x).to_bits(),
                        old_f64(q, x, &s).to_bits(),
                        "{q:?} {x} {s:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn settings_helpers_are_the_same_conversions() {
    for s in settings() {
        for raw in i16::MIN..=i16::MAX {
            let old = (f32::from(raw) / s.current_scale).to_bits();
            assert_eq!(s.amps(raw).to_bits(), old);
        }
        for erpm in (0..=655_350)
            .step_by(7)
            .chain([u32::MAX, 1 << 24, (1 << 24) + 1])
        {
            let old = erpm as f32 / (s.gear_ratio * f32::from(s.pole_pairs));
            assert_eq!(s.rpm_from_erpm(erpm).to_bits(), old.to_bits(), "{erpm}");
        }
    }
    assert_eq!(
        Linear::ERPM.to_f32(f32::from(u16::MAX)),
        f32::from(u16::MAX) * f32::from(ERPM_PER_RAW)
    );
}

#[test]
fn names_and_units_are_the_record_schema() {
    let names: Vec<_> = Quantity::ALL.iter().map(|q| (q.name(), q.unit())).collect();
    assert_eq!(
        names,
        [
            ("throttle_in_pct", "%"),
            ("throttle_out_pct", "%"),
            ("erpm", "rev/min"),
            ("rpm", "rev/min"),
            ("voltage_v", "V"),
            ("current_a", "A"),
            ("phase_current_a", "A"),
        ]
    );
}
