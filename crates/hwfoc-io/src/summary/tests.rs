//! The summary's own tests.
use super::accumulate::*;
use super::*;
use hwfoc::foc::DataFrame;

#[test]
fn the_device_is_named_field_by_field() {
    let info = Info::from(hwfoc::foc::InfoFrame::new("HW1", "V2", "XR-01.0.00", "42").unwrap());
    assert_eq!(
        Value::Object(device_json(&info)).to_string(),
        r#"{"product":"HW1","hardware":"V2","firmware":"XR-01.0.00","id":"42"}"#
    );
}

#[test]
fn temperature_stats_come_from_the_histogram() {
    let mut codes = [0u64; 256];
    codes[206] = 3; // 28 degC
    codes[183] = 1; // 40 degC
    codes[250] = 2; // below range
    codes[10] = 1; // above range
    codes[255] = 4; // no value (ADC_NO_VALUE): neither
    let t = temp_stats(&codes, Conversion::AdcTable);
    assert_eq!(t.range, Some([28.0, 40.0, (3.0 * 28.0 + 40.0) / 4.0]));
    assert_eq!((t.below, t.above), (2, 1));
}

#[test]
fn ranges_convert_monotonically() {
    let mut r = Ranges::default();
    for v in [-64, 128, 0] {
        r.add(&DataFrame {
            current_raw: v,
            voltage_raw: (v + 64) as u16,
            ..Default::default()
        });
    }
    let voltage = lane(Quantity::Voltage).unwrap();
    let (current, n) = r.get(CURRENT, 3);
    assert_eq!(n, 3);
    assert_eq!(
        current.convert(n, |x| x / 64.0),
        Some([-1.0, 2.0, 64.0 / 3.0 / 64.0])
    );
    assert_eq!(
        r.get(voltage, 3).0.convert(3, |x| x),
        Some([0.0, 192.0, 256.0 / 3.0])
    );
    assert_eq!(Ranges::default().get(ERPM, 0).0.convert(0, |x| x), None);
}

#[test]
fn episodes_are_maximal_runs_of_faulty_frames() {
    let mut acc = Accumulator::default();
    let statuses = [
        0u16, 0x0001, 0x0040, 0x0001, 0, 0, 0x8000, 0, 0x0002, 0x0002,
    ];
    for (i, &s) in statuses.iter().enumerate() {
        let frame = DataFrame {
            packet: 100 + i as u16,
            status: Status(s),
            ..Default::default()
        };
        acc.add(
            Some(i as f64 * 0.05),
            &Frame::Data(frame.into()),
            &Settings::DEFAULT,
        );
    }
    assert_eq!(acc.episode_count, 2);
    let first = acc.episodes[0];
    assert_eq!(
        (first.first.frame, first.last.frame, first.frames),
        (1, 3, 3)
    );
    assert_eq!(
        (first.first.packet, first.last.packet),
        (Some(101), Some(103))
    );
    assert_eq!(first.first.t, Some(0.05));
    assert_eq!(
        Protocol::HwFoc.fault_names(first.bits).collect::<Vec<_>>(),
        ["input_voltage_high", "mos_overheat"]
    );
    assert!(!first.ongoing);
    assert_eq!(acc.episodes[1].frames, 1);
    // The last run is still open at the end of the stream.
    let open = acc.episode.unwrap();
    assert_eq!((open.first.frame, open.last.frame, open.frames), (8, 9, 2));
}

/// Frames of a raw input handed on together ([`Handler::untimed_data`], in runs of any length)
/// are summarised exactly as when handed on one at a time: ranges, temperature codes that
/// change and repeat, faults and their episodes, power.
#[test]
fn frames_handed_on_together_are_summarised_as_one_at_a_time() {
    let frames: Vec<DataFrame> = (0..3000u16)
        .map(|i| {
            let status = match i {
                700..=720 | 1999 | 2500..=2502 => Status(0x0040 | (i & 1)),
                _ => Status(0),
            };
            DataFrame {
                packet: i.wrapping_mul(7),
                throttle_in_raw: i % 1000,
                throttle_out_raw: 999 - i % 1000,
                erpm_raw: i.wrapping_mul(31),
                voltage_raw: 200 + i % 57,
                current_raw: (i % 300) as i16 - 150,
                phase_current_raw: -((i % 77) as i16),
                mos_adc: 180 + (i / 100) as u8,
                cap_adc: if i % 500 < 250 { 200 } else { (i % 13) as u8 },
                status,
            }
        })
        .collect();
    let settings = Settings::DEFAULT;
    let mut one_at_a_time = Summary::new();
    for f in &frames {
        one_at_a_time.frame(0, None, &Frame::Data(Data::HwFoc(*f)), &settings);
    }
    for run in [1, 2, 7, 512, 3000] {
        let mut together = Summary::new();
        for chunk in frames.chunks(run) {
            together.untimed_data(0, chunk, &settings);
        }
        assert_eq!(
            format!("{:?}", together.0),
            format!("{:?}", one_at_a_time.0),
            "runs of {run}"
        );
    }
}

/// A quantity the ESC's protocol does not send (HW-FOC has no BEC or motor temperature) has no
/// row in the text, and its key in JSON is null; one it sends has both.
#[test]
fn a_quantity_the_protocol_does_not_send_has_no_text_row() {
    let (text, json) = summarised("three frames", foc_frames(0..3));
    assert!(text.contains("\nvoltage_v "), "{text}");
    assert!(text.contains("\ncap_temp_c "), "{text}");
    for absent in [
        "motor_temp_c",
        "bec_temp_c",
        "bec_voltage_v",
        "bec_current_a",
    ] {
        assert!(!text.contains(absent), "{absent} in\n{text}");
        let field = &json["escs"][0]["fields"][absent];
        assert_eq!(field["min"], serde_json::Value::Null, "{absent}");
        assert!(field["unit"].is_string(), "{absent}");
    }
    assert_eq!(json["escs"][0]["fields"]["voltage_v"]["max"], 24.7);
}

/// HW-FOC data frames of these packet numbers (24.7 V), as bytes.
fn foc_frames(packets: impl IntoIterator<Item = u16>) -> Vec<u8> {
    packets
        .into_iter()
        .flat_map(|packet| {
            hwfoc::foc::DataFrame {
                packet,
                voltage_raw: 247,
                ..Default::default()
            }
            .encode()
        })
        .collect()
}

/// The summary of `bytes`, a raw input named `name`: its text and JSON.
fn summarised(name: &str, bytes: Vec<u8>) -> (String, Value) {
    let input = crate::Input::from_memory(name, bytes).unwrap();
    let mut sources = crate::Sources::new(vec![input], Settings::DEFAULT);
    let mut summary = Summary::new();
    sources.run(&mut summary).unwrap();
    let report = summary.report(&sources);
    (report.text(), report.json())
}

/// HW5 has no packet counter: its loss is judged from the frames' times, at the running period
/// between two frames of a turning motor, at the idle one otherwise (a change of rate is no
/// loss), and a silence over a second is not judged.
#[test]
fn hw5_loss_is_judged_from_time() {
    let frame = |erpm_raw: u16| {
        Frame::Data(Data::Hw5(hwfoc::hw5::TelemetryFrame {
            throttle: if erpm_raw > 0 { 30 } else { 0 },
            erpm_raw,
            voltage_raw: 504,
            current_raw: 100,
            ..Default::default()
        }))
    };
    let mut acc = Accumulator::default();
    let mut add = |t: f64, erpm: u16| acc.add(Some(t), &frame(erpm), &Settings::DEFAULT);
    // Idle at 400 ms, then running at 20 ms (the first running frame 400 ms after: no loss).
    for t in [0.0, 0.4, 0.8] {
        add(t, 0);
    }
    let mut t = 1.2;
    for k in 0..20 {
        // Frames 8, 9 and 10 lost: a step of 80 ms.
        if !(8..=10).contains(&k) {
            add(t, 3000);
        }
        t += 0.02;
    }
    // Stopped: idle frames 400 ms apart again (the first at the idle rate: no loss), one lost.
    add(t + 0.38, 0);
    add(t + 0.78, 0);
    add(t + 1.58, 0);
    // Off for 5 s: not judged.
    add(t + 6.58, 0);
    let loss = acc.values.as_ref().unwrap().loss;
    assert_eq!((loss.lost, loss.unjudged), (3 + 1, 1));
    assert_eq!(loss.judged, 2 + 1 + 16 + 3);
}

/// A stream that changed format (HW5, then HW-FOC, no silence): the summary names both with
/// their counts, its frames are both's, and the delivery says whose it is. (It said "frames
/// 19", protocol hw5, delivery 100 %: issue 29.)
#[test]
fn a_stream_that_changed_format_names_both() {
    let mut bytes = Vec::new();
    for k in 0..658u32 {
        let frame = hwfoc::hw5::TelemetryFrame {
            throttle: 20,
            erpm_raw: 1000 + (k % 7) as u16,
            voltage_raw: 504,
            ..Default::default()
        };
        bytes.extend_from_slice(&frame.encode());
    }
    bytes.extend(foc_frames([100, 101, 103]));
    let (text, json) = summarised("hw5 then hw-foc", bytes);
    assert!(text.contains("frames       661 data, 0 info"), "{text}");
    assert!(
        text.contains("formats      HW-FOC 3 data frames, HW5 658 data frames"),
        "{text}"
    );
    assert!(
        text.contains("delivery     75.00 % of HW-FOC data frames"),
        "{text}"
    );
    let esc = &json["escs"][0];
    assert_eq!(esc["frames"], 661);
    assert_eq!(esc["formats"]["hw5"], 658);
    assert_eq!(esc["formats"]["hw-foc"], 3);
}
