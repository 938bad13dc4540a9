//! The conversions of `hwfoc::units` against the formulas they replace, bit for bit: the data
//! frame's methods as they were written out (f32), and the CLI summary's conversions of minima,
//! maxima and means (f64). Every raw value of every field, under several settings.

use hwfoc::foc::DataFrame;
use hwfoc::units::{ERPM_PER_RAW, Linear};
use hwfoc::{Quantity, Settings, Telemetry, Temperature};

/// The quantities an HW-FOC frame converts linearly (every one but the two temperatures).
const LINEAR: [Quantity; 7] = [
    Quantity::ThrottleIn,
    Quantity::ThrottleOut,
    Quantity::Erpm,
    Quantity::Rpm,
    Quantity::Voltage,
    Quantity::Current,
    Quantity::PhaseCurrent,
];

/// The settings tried: the default, the `x 0.01` current scale, and unusual ones.
fn settings() -> Vec<Settings> {
    [
        (64.0, 7, 1.0),
        (100.0, 7, 1.0),
        (64.0, 14, 1.5),
        (17.3, 3, 0.37),
        (1e-3, 65_535, 1e3),
        (12_345.678, 1, 1e-7),
        // The bounds of Settings::new, both ways round.
        (Settings::CURRENT_SCALE_MIN, 1, Settings::GEAR_RATIO_MIN),
        (
            Settings::CURRENT_SCALE_MAX,
            65_535,
            Settings::GEAR_RATIO_MAX,
        ),
        (
            Settings::CURRENT_SCALE_MIN,
            65_535,
            Settings::GEAR_RATIO_MAX,
        ),
        (Settings::CURRENT_SCALE_MAX, 1, Settings::GEAR_RATIO_MIN),
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
        _ => unreachable!("not linear, or not carried by HW-FOC"),
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
        _ => unreachable!("not linear, or not carried by HW-FOC"),
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
        Quantity::MosTemp => f.mos_temp().celsius().unwrap_or(f32::NAN),
        Quantity::CapTemp => f.cap_temp().celsius().unwrap_or(f32::NAN),
        _ => unreachable!("not carried by HW-FOC"),
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
        Quantity::MosTemp => f.mos_adc = bits as u8,
        Quantity::CapTemp => f.cap_adc = bits as u8,
        _ => unreachable!("not carried by HW-FOC"),
    }
    f
}

#[test]
fn every_raw_value_converts_bit_for_bit_as_before() {
    for s in settings() {
        for q in LINEAR {
            for bits in 0..=u16::MAX {
                let f = frame_with(q, bits);
                let reading = f.reading(q, &s).unwrap();
                let (raw, linear) = (reading.raw, reading.conversion.linear().unwrap());
                let old = old_f32(q, raw, &s).to_bits();
                assert_eq!(method(&f, q, &s).to_bits(), old, "{q:?} {raw} {s:?}");
                assert_eq!(f.value(q, &s).unwrap().to_bits(), old, "{q:?} {raw} {s:?}");
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
            ("mos_temp_c", "degC"),
            ("cap_temp_c", "degC"),
            ("motor_temp_c", "degC"),
            ("bec_temp_c", "degC"),
            ("bec_voltage_v", "V"),
            ("bec_current_a", "A"),
        ]
    );
}

/// An HW-FOC frame carries none of the quantities only other formats send (HW5's motor and
/// BEC readings): their reading is `None`, whatever the frame holds.
#[test]
fn hwfoc_frames_do_not_carry_the_bec_and_motor_quantities() {
    let s = Settings::default();
    let f = DataFrame {
        packet: 9,
        voltage_raw: 247,
        mos_adc: 206,
        cap_adc: 206,
        ..Default::default()
    };
    for q in [
        Quantity::MotorTemp,
        Quantity::BecTemp,
        Quantity::BecVoltage,
        Quantity::BecCurrent,
    ] {
        assert_eq!(f.reading(q, &s), None, "{q:?}");
        assert_eq!(f.raw(q), None, "{q:?}");
    }
    for q in &Quantity::ALL[..9] {
        assert!(f.reading(*q, &s).is_some(), "{q:?}");
    }
}

/// The temperatures of an HW-FOC frame are ADC codes read through the table: every code gives
/// the table's temperature, and no value outside the table.
#[test]
fn every_temperature_code_reads_through_the_table() {
    let s = Settings::default();
    for q in [Quantity::MosTemp, Quantity::CapTemp] {
        for code in 0..=u8::MAX {
            let f = frame_with(q, code.into());
            let reading = f.reading(q, &s).unwrap();
            assert_eq!(reading.raw, i32::from(code));
            assert_eq!(reading.conversion.linear(), None);
            let expected = Temperature::from_adc(code).celsius();
            assert_eq!(
                reading.value().map(f32::to_bits),
                expected.map(f32::to_bits),
                "{code}"
            );
            assert_eq!(
                method(&f, q, &s).to_bits(),
                expected.unwrap_or(f32::NAN).to_bits()
            );
        }
    }
    // Points the table documents: code 206 is 28 degC; 250 is below the table.
    assert_eq!(
        frame_with(Quantity::MosTemp, 206).value(Quantity::MosTemp, &s),
        Some(28.0)
    );
    assert_eq!(
        frame_with(Quantity::CapTemp, 250).value(Quantity::CapTemp, &s),
        None
    );
}

/// A finite value, nonzero (and normal: full precision) unless `raw` is 0.
fn representable(value: f32, raw: f64) -> bool {
    value.is_finite() && (raw == 0.0) == (value == 0.0) && (raw == 0.0 || value.is_normal())
}

/// The issue: `--current-scale 1e-38` made currents infinite. Under the settings at the bounds
/// of `Settings::new` (each combination of the extremes), every raw value of every field converts
/// to a finite number, nonzero and normal when the raw value is, in `f32` and in `f64`.
#[test]
fn every_raw_value_is_representable_at_the_bounds() {
    let scales = [Settings::CURRENT_SCALE_MIN, Settings::CURRENT_SCALE_MAX];
    let ratios = [Settings::GEAR_RATIO_MIN, Settings::GEAR_RATIO_MAX];
    for scale in scales {
        for ratio in ratios {
            for poles in [1, 2, 7, 1000, 65_535] {
                let s = Settings::new(scale, poles, ratio).unwrap();
                for q in LINEAR {
                    for bits in 0..=u16::MAX {
                        let f = frame_with(q, bits);
                        let reading = f.reading(q, &s).unwrap();
                        let raw = reading.raw;
                        let value = reading.value().unwrap();
                        assert!(
                            representable(value, raw.into()),
                            "{q:?} {raw} {s:?}: {value}"
                        );
                        let wide = reading.conversion.linear().unwrap().to_f64(raw.into());
                        assert!(
                            wide.is_finite() && (raw == 0) == (wide == 0.0),
                            "{q:?} {raw}"
                        );
                    }
                }
                // rpm_from_erpm takes any u32 eRPM: its extremes.
                for erpm in [1, 655_350, u32::MAX] {
                    let rpm = s.rpm_from_erpm(erpm);
                    assert!(representable(rpm, erpm.into()), "{erpm} {s:?}: {rpm}");
                }
            }
            // Every number of pole pairs, at the extreme raw values (the RPM is monotonic in
            // both the raw value and the divisor).
            for poles in 1..=u16::MAX {
                let s = Settings::new(scale, poles, ratio).unwrap();
                for erpm_raw in [1, u16::MAX] {
                    let f = DataFrame {
                        erpm_raw,
                        ..Default::default()
                    };
                    assert!(
                        representable(f.rpm(&s), erpm_raw.into()),
                        "{erpm_raw} {s:?}"
                    );
                }
                for erpm in [1, u32::MAX] {
                    assert!(
                        representable(s.rpm_from_erpm(erpm), erpm.into()),
                        "{erpm} {s:?}"
                    );
                }
            }
        }
    }
}

/// The bounds are the tightest powers of ten: ten times further out, some raw value converts to
/// infinity or loses its precision (or becomes 0).
#[test]
fn bounds_are_the_tightest_powers_of_ten() {
    let unchecked = |current_scale, pole_pairs, gear_ratio| Settings {
        current_scale,
        pole_pairs,
        gear_ratio,
        ..Settings::DEFAULT
    };
    let s = unchecked(Settings::CURRENT_SCALE_MIN / 10.0, 7, 1.0);
    assert_eq!(s.amps(i16::MIN), f32::NEG_INFINITY);
    let s = unchecked(Settings::CURRENT_SCALE_MAX * 10.0, 7, 1.0);
    assert!(!s.amps(1).is_normal());
    let s = unchecked(64.0, 1, Settings::GEAR_RATIO_MIN / 10.0);
    assert_eq!(s.rpm_from_erpm(u32::MAX), f32::INFINITY);
    let s = unchecked(64.0, u16::MAX, Settings::GEAR_RATIO_MAX * 10.0);
    assert_eq!(
        DataFrame {
            erpm_raw: u16::MAX,
            ..Default::default()
        }
        .rpm(&s),
        0.0
    );
}
