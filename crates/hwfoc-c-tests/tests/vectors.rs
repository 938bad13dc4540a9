//! The golden vectors of `c/tests/vectors.txt` (described in `docs/VECTORS.md`), checked
//! against the Rust codec: each stream decodes to the frame named, with every raw field and
//! decoded value given. `c/tests/test.c` checks the same file against the C header. Raw fields
//! are compared exactly; a decoded value (the codec gives floats) to within half of its unit.

use hwfoc::units::Temperature;
use hwfoc::v4::VoltsPerStep;
use hwfoc::{Settings, datalink, foc, hw5, v3, v4};

const VECTORS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../c/tests/vectors.txt");

/// What the codec gives for a key.
#[derive(Debug)]
enum Value {
    /// A raw field: exactly the vector's integer.
    Exact(i64),
    /// A decoded value: within 0.5 of the vector's integer (which rounds it as the file says).
    Near(f64),
    /// Text of a device-information frame.
    Text(String),
}

fn foc_data(d: &foc::DataFrame, key: &str) -> Option<Value> {
    let settings = Settings::default();
    let temp_dc = |code: u8| {
        Temperature::from_adc(code)
            .celsius()
            .map(|c| f64::from(c) * 10.0)
    };
    Some(match key {
        "packet" => Value::Exact(d.packet.into()),
        "throttle_in_raw" => Value::Exact(d.throttle_in_raw.into()),
        "throttle_out_raw" => Value::Exact(d.throttle_out_raw.into()),
        "erpm_raw" => Value::Exact(d.erpm_raw.into()),
        "voltage_raw" => Value::Exact(d.voltage_raw.into()),
        "current_raw" => Value::Exact(d.current_raw.into()),
        "phase_current_raw" => Value::Exact(d.phase_current_raw.into()),
        "mos_adc" => Value::Exact(d.mos_adc.into()),
        "cap_adc" => Value::Exact(d.cap_adc.into()),
        "status" => Value::Exact(d.status.0.into()),
        "erpm" => Value::Exact(d.erpm().into()),
        "rpm" => Value::Near(f64::from(d.rpm(&settings)).floor()),
        "mv" => Value::Near(f64::from(d.voltage_v()) * 1000.0),
        "current_ma" => Value::Near(f64::from(d.current_a(&settings)) * 1000.0),
        "phase_current_ma" => Value::Near(f64::from(d.phase_current_a(&settings)) * 1000.0),
        "throttle_centipct" => Value::Near((f64::from(d.throttle_in_pct()) * 100.0).floor()),
        "mos_dc" => Value::Near(temp_dc(d.mos_adc)?),
        "cap_dc" => Value::Near(temp_dc(d.cap_adc)?),
        _ => return None,
    })
}

fn lookup_foc(item: &foc::Decoded, key: &str) -> Option<Value> {
    match &item.frame {
        foc::FocFrame::Data(d) => foc_data(d, key),
        foc::FocFrame::Info(i) => Some(Value::Text(
            match key {
                "product" => i.product(),
                "hardware" => i.hardware(),
                "firmware" => i.firmware(),
                "id" => i.id(),
                _ => return None,
            }
            .to_string(),
        )),
    }
}

fn lookup_datalink(item: &datalink::Decoded, key: &str) -> Option<Value> {
    let f = &item.frame;
    match key {
        "counter" => return Some(Value::Exact(f.counter.into())),
        "slots" => {
            let mask = f.escs().fold(0i64, |m, (ch, _)| m | 1 << ch);
            return Some(Value::Exact(mask));
        }
        _ => {}
    }
    let (channel, field) = key.strip_prefix("ch")?.split_once('.')?;
    let slot = f.slots.get(channel.parse::<usize>().ok()?)?.as_ref()?;
    foc_data(slot, field)
}

fn lookup_v3(item: &v3::Decoded, key: &str) -> Option<Value> {
    let f = &item.frame;
    Some(match key {
        "counter" => Value::Exact(f.counter.into()),
        "throttle_in_raw" => Value::Exact(f.throttle_in_raw.into()),
        "pwm_out_raw" => Value::Exact(f.pwm_out_raw.into()),
        "period_us" => Value::Exact(f.period_us.into()),
        "erpm" => Value::Exact(f.erpm().unwrap_or(0).into()),
        "throttle_centipct" => Value::Near((f64::from(f.throttle_in_pct()) * 100.0).floor()),
        _ => return None,
    })
}

fn v4_info(i: &v4::InfoFrame, key: &str) -> Option<Value> {
    Some(Value::Exact(match key {
        "full_scale" => i.full_scale.into(),
        "v1" => i.v1.into(),
        "v2" => i.v2.into(),
        "i1" => i.i1.into(),
        "i2" => i.i2.into(),
        "i3" => i.i3.into(),
        _ => return None,
    }))
}

fn lookup_v4(item: &v4::Decoded, key: &str) -> Option<Value> {
    let d = match &item.frame {
        v4::V4Frame::Info(i) => return v4_info(i, key),
        v4::V4Frame::Data(d) => d,
    };
    let f = &d.frame;
    Some(match key {
        "counter" => Value::Exact(f.counter.into()),
        "throttle_in_raw" => Value::Exact(f.throttle_in_raw.into()),
        "throttle_out_raw" => Value::Exact(f.throttle_out_raw.into()),
        "erpm" => Value::Exact(f.erpm.into()),
        "voltage_adc" => Value::Exact(f.voltage_adc.into()),
        "current_adc" => Value::Exact(f.current_adc.into()),
        "temp_adc" => Value::Exact(f.temp_adc.into()),
        "temp2_adc" => Value::Exact(f.temp2_adc.into()),
        "has_info" => Value::Exact(d.info.is_some().into()),
        "full_scale" => Value::Exact(d.full_scale().into()),
        "mv" => Value::Near((f64::from(d.voltage_v(VoltsPerStep::DEFAULT)) * 1000.0).floor()),
        "current_ma" => Value::Near((f64::from(d.current_a()?) * 1000.0).floor()),
        "throttle_centipct" => Value::Near((f64::from(d.throttle_in_pct()) * 100.0).floor()),
        _ => return None,
    })
}

fn lookup_hw5(item: &hw5::Decoded, key: &str) -> Option<Value> {
    let f = &item.frame;
    Some(match key {
        "throttle" => Value::Exact(f.throttle.into()),
        "fault" => Value::Exact(f.fault.0.into()),
        "erpm_raw" => Value::Exact(f.erpm_raw.into()),
        "erpm" => Value::Exact(f.erpm().into()),
        "voltage_raw" => Value::Exact(f.voltage_raw.into()),
        "mv" => Value::Near(f64::from(f.voltage_v()) * 1000.0),
        "current_raw" => Value::Exact(f.current_raw.into()),
        "current_ma" => Value::Near(f64::from(f.current_a()) * 1000.0),
        "esc_temp" => Value::Exact(f.esc_temp.into()),
        "bec_temp" => Value::Exact(f.bec_temp.into()),
        "motor_temp" => Value::Exact(f.motor_temp.into()),
        "bec_voltage_raw" => Value::Exact(f.bec_voltage_raw.into()),
        "bec_mv" => Value::Near(f64::from(f.bec_voltage_v()) * 1000.0),
        "bec_current_raw" => Value::Exact(f.bec_current_raw.into()),
        "bec_current_ma" => Value::Near(f64::from(f.bec_current_a()) * 1000.0),
        _ => return None,
    })
}

/// The value of `key` in frame `index` of `bytes` decoded as `format`; `None` for a key the
/// format does not know or a frame that is not there.
fn lookup(format: &str, bytes: &[u8], index: usize, key: &str) -> Result<Option<Value>, String> {
    fn nth<S: hwfoc::scan::Scanner>(bytes: &[u8], index: usize) -> Result<S::Item, String> {
        let frames: Vec<_> = hwfoc::Scan::<S>::new(bytes).collect();
        let count = frames.len();
        frames
            .into_iter()
            .nth(index)
            .ok_or(format!("frame {index} of {count}"))
    }
    Ok(match format {
        "foc" => lookup_foc(&nth::<foc::Scanner>(bytes, index)?, key),
        "datalink" => lookup_datalink(&nth::<datalink::Scanner>(bytes, index)?, key),
        "v3" => lookup_v3(&nth::<v3::Scanner>(bytes, index)?, key),
        "v4" => lookup_v4(&nth::<v4::Scanner>(bytes, index)?, key),
        "hw5" => lookup_hw5(&nth::<hw5::Scanner>(bytes, index)?, key),
        _ => return Err(format!("unknown format {format}")),
    })
}

fn hex(text: &str) -> Vec<u8> {
    (0..text.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&text[i..i + 2], 16).expect("hex"))
        .collect()
}

#[test]
fn the_rust_codec_gives_every_golden_vector() {
    let text = std::fs::read_to_string(VECTORS).expect(VECTORS);
    let (mut lines, mut values) = (0, 0);
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let at = format!("c/tests/vectors.txt:{}", n + 1);
        let mut words = line.split_whitespace();
        let (format, bytes) = (words.next().unwrap(), hex(words.next().unwrap()));
        let pairs: Vec<(&str, &str)> = words
            .map(|w| w.split_once('=').unwrap_or_else(|| panic!("{at}: {w}")))
            .collect();
        let index: usize = pairs
            .iter()
            .find(|(k, _)| *k == "frame")
            .and_then(|(_, v)| v.parse().ok())
            .unwrap_or_else(|| panic!("{at}: no frame=K"));
        for &(key, want) in pairs.iter().filter(|(k, _)| *k != "frame") {
            let got = lookup(format, &bytes, index, key)
                .unwrap_or_else(|e| panic!("{at}: {e}"))
                .unwrap_or_else(|| panic!("{at}: {format} has no {key}"));
            match got {
                Value::Text(t) => assert_eq!(t, want, "{at}: {key}"),
                Value::Exact(v) => assert_eq!(v.to_string(), want, "{at}: {key}"),
                Value::Near(v) => {
                    let want: f64 = want.parse().expect("an integer");
                    assert!(
                        (v - want).abs() <= 0.5 + 1e-6,
                        "{at}: {key} is {v}, not {want}"
                    );
                }
            }
            values += 1;
        }
        lines += 1;
    }
    assert!(
        lines >= 13 && values >= 100,
        "{lines} vectors, {values} values"
    );
}
