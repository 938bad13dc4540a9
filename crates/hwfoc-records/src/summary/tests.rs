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
            &AnyFrame::Data(frame.into()),
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
        one_at_a_time.frame(0, None, &AnyFrame::Data(Data::HwFoc(*f)), &settings);
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
        AnyFrame::Data(Data::Hw5(hwfoc::hw5::TelemetryFrame {
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
    // The HW5 bytes are no bytes skipped: they are outside HW-FOC's frames.
    assert!(text.contains("bytes outside HW-FOC frames"), "{text}");
    assert!(!text.contains("bytes skipped"), "{text}");
    let esc = &json["escs"][0];
    assert_eq!(esc["frames"], 661);
    assert_eq!(esc["formats"]["hw5"], 658);
    assert_eq!(esc["formats"]["hw-foc"], 3);
}

/// A serial format of the summary's property test.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Wire {
    HwFoc,
    V3,
    V4,
    Hw5,
}

/// What the generator does before the next in-order frame (each followed by in-order frames).
#[derive(Debug, Clone, Copy)]
enum Event {
    /// The next frame, in order.
    Next,
    /// `k` frames lost on the way.
    Drop(u32),
    /// The last frame sent again.
    Duplicate,
    /// The next two frames swapped on the way.
    Swap,
    /// The ESC restarted: its counter jumps far ahead.
    Restart,
}

/// What the generator sent and what a counter's figures must say of it.
#[derive(Debug, Default, PartialEq)]
struct Truth {
    frames: u64,
    lost: u64,
    duplicates: u64,
    restarts: u64,
    reordered: u64,
}

impl Wire {
    const ALL: [Wire; 4] = [Wire::HwFoc, Wire::V3, Wire::V4, Wire::Hw5];

    /// The frame carrying packet counter `n`.
    fn frame(self, n: u32) -> Vec<u8> {
        match self {
            Wire::HwFoc => foc_frames([n as u16]),
            Wire::V3 => hwfoc::v3::V3Frame {
                counter: n & 0xFF_FFFF,
                throttle_in_raw: 51,
                pwm_out_raw: 51,
                period_us: 1500,
            }
            .encode()
            .to_vec(),
            Wire::V4 => hwfoc::v4::DataFrame {
                counter: n & 0xFF_FFFF,
                throttle_in_raw: 300,
                throttle_out_raw: 280,
                erpm: 9000 + n % 500,
                voltage_adc: 1365,
                current_adc: 120,
                temp_adc: 2200,
                temp2_adc: 2100,
            }
            .encode()
            .to_vec(),
            Wire::Hw5 => hwfoc::hw5::TelemetryFrame {
                throttle: 20,
                erpm_raw: 1000 + (n % 7) as u16,
                voltage_raw: 504,
                ..Default::default()
            }
            .encode()
            .to_vec(),
        }
    }

    /// The counter's width: its restart jump stays a forward step beyond the gap limit.
    fn modulus(self) -> u32 {
        match self {
            Wire::HwFoc => 1 << 16,
            _ => 1 << 24,
        }
    }

    /// The events a format's decoder keeps every frame of: V3 and V4 frames (no checksum) are
    /// taken when they chain (counter + 1 or a few frames cut out, or three chained after a
    /// jump), so a duplicate or a swap there is a rejected candidate, not a frame.
    fn allows(self, e: Event) -> bool {
        match self {
            Wire::V3 | Wire::V4 => matches!(e, Event::Next | Event::Drop(_) | Event::Restart),
            Wire::HwFoc | Wire::Hw5 => true,
        }
    }

    /// The bytes of frames from counter `start`, three in order, then under `events` (each
    /// followed by two frames in order), and their truth.
    fn stream(self, start: u32, events: &[Event]) -> (Vec<u8>, Truth) {
        let m = self.modulus();
        let mut t = Truth::default();
        let mut last = start % m;
        let mut bytes = self.frame(last);
        let mut send = |n: u32, t: &mut Truth| {
            bytes.extend(self.frame(n % m));
            t.frames += 1;
        };
        t.frames = 1;
        // Three frames in order first: a V3 or V4 decoder takes its first frame in a chain.
        for _ in 0..2 {
            last += 1;
            send(last, &mut t);
        }
        for &e in events.iter().filter(|&&e| self.allows(e)) {
            match e {
                Event::Next => {}
                Event::Drop(k) => {
                    last += k;
                    t.lost += u64::from(k);
                }
                Event::Duplicate => {
                    send(last, &mut t);
                    t.duplicates += 1;
                }
                Event::Swap => {
                    send(last + 2, &mut t);
                    send(last + 1, &mut t);
                    last += 2;
                    t.reordered += 1;
                }
                Event::Restart => {
                    last += 5000;
                    send(last, &mut t);
                    t.restarts += 1;
                }
            }
            for _ in 0..2 {
                last += 1;
                send(last, &mut t);
            }
        }
        (bytes, t)
    }
}

fn event() -> impl proptest::strategy::Strategy<Value = Event> {
    use proptest::prelude::*;
    prop_oneof![
        4 => Just(Event::Next),
        2 => (1u32..=3).prop_map(Event::Drop),
        1 => Just(Event::Duplicate),
        1 => Just(Event::Swap),
        1 => Just(Event::Restart),
    ]
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]

    /// The summary's figures are the generator's truth: under drops, duplicates, swaps and
    /// restarts, in every serial format, also when the stream changes to another format (no
    /// silence between): its frames are both formats', each named with its count, and its
    /// lost, duplicate and restart counts and delivery are the last format's (HW5, without a
    /// packet counter, has none). (The format change itself: the codec's
    /// `a_change_of_format_loses_no_frame`, every pair of formats at random offsets in random
    /// chunks.)
    #[test]
    fn the_summary_says_what_the_generator_sent(
        a in 0..Wire::ALL.len(),
        b in proptest::option::of(0..Wire::ALL.len()),
        first in proptest::collection::vec(event(), 8..60),
        second in proptest::collection::vec(event(), 8..60),
        start in 0u32..70_000,
    ) {
        let a = Wire::ALL[a];
        let b = b.map(|b| Wire::ALL[b]).filter(|&b| b != a);
        let (mut bytes, first_truth) = a.stream(start, &first);
        let mut frames = first_truth.frames;
        let (last, truth) = match b {
            Some(b) => {
                let (later, t) = b.stream(start / 3, &second);
                bytes.extend(later);
                frames += t.frames;
                (b, t)
            }
            None => (a, first_truth),
        };
        let (text, json) = summarised("generated", bytes);
        let esc = &json["escs"][0];
        let link = &esc["link"];
        proptest::prop_assert_eq!(esc["frames"].as_u64(), Some(frames), "{}", text);
        if b.is_some() {
            proptest::prop_assert_eq!(esc["formats"].as_object().map(|o| o.len()), Some(2), "{}", text);
        }
        if last == Wire::Hw5 {
            proptest::prop_assert!(link["lost_packets"].is_null(), "{}", text);
            proptest::prop_assert!(link["delivery_ratio"].is_null(), "{}", text);
        } else {
            let got = (
                link["lost_packets"].as_u64(),
                link["duplicate_packets"].as_u64(),
                link["restarts"].as_u64(),
            );
            proptest::prop_assert_eq!(
                got,
                (Some(truth.lost), Some(truth.duplicates), Some(truth.restarts)),
                "{}", text
            );
            let reordered = format!(", {} reordered", truth.reordered);
            proptest::prop_assert_eq!(text.contains(&reordered), truth.reordered > 0, "{}", text);
            let delivery = truth.frames as f64 / (truth.frames + truth.lost) as f64;
            proptest::prop_assert_eq!(link["delivery_ratio"].as_f64(), Some(delivery), "{}", text);
        }
    }
}
