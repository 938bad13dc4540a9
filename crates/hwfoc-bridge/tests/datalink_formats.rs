//! The DataLink output carries every format: a V4, HW5 or Hobbywing CAN ESC's frame goes out
//! as the HW-FOC frame a hub would have sent, whose values, decoded by the codec's DataLink
//! decoder, are the input's within one raw step.

use std::io::{self, Write};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use hwfoc::dronecan::{HwCanEsc, Power, Temperatures};
use hwfoc::hw5::{Fault as Hw5Fault, FaultCode, TelemetryFrame};
use hwfoc::telemetry::{Data, Telemetry};
use hwfoc::units::{ADC_MAX, ADC_MIN, ADC_NO_VALUE};
use hwfoc::{Fault, Quantity, Settings, Status, Temperature, datalink, v4};
use hwfoc_bridge::datalink::{DatalinkOutput, Pacing};
use hwfoc_bridge::{Output, Update};
use hwfoc_io::Record;

/// A writer the test can look into.
#[derive(Clone, Default)]
struct Shared(Arc<Mutex<Vec<u8>>>);

impl Write for Shared {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.lock().unwrap().extend_from_slice(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// `frames` of ESC 0 through a DataLink output, one DataLink frame each, decoded back.
fn through_datalink(frames: &[Data], settings: &Settings) -> Vec<hwfoc::foc::DataFrame> {
    let bytes = datalink_bytes(frames, settings);
    let mut got = Vec::new();
    let mut decoder = datalink::Decoder::new();
    decoder.decode_all(&bytes, |d| {
        got.push(d.frame.slots[0].expect("ESC 0's slot"))
    });
    assert_eq!(decoder.stats().bytes_skipped(), 0);
    assert_eq!(got.len(), frames.len());
    got
}

/// The bytes a DataLink output sends for `frames` of ESC 0, one DataLink frame each.
fn datalink_bytes(frames: &[Data], settings: &Settings) -> Vec<u8> {
    let shared = Shared::default();
    let mut out = DatalinkOutput::to_writer("test", Box::new(shared.clone()), Pacing::default());
    let t0 = Instant::now();
    for (k, data) in frames.iter().enumerate() {
        let record = Record::new(None, 0, data, settings);
        out.update(&Update {
            esc: 0,
            frame: data,
            record: &record,
            settings,
            arrived: t0,
        });
        out.poll(t0 + Duration::from_secs(k as u64 + 1)).unwrap();
    }
    assert_eq!(out.escs_not_carried(), 0);
    shared.0.lock().unwrap().clone()
}

/// The largest step between the temperatures of two neighbouring ADC codes.
fn adc_step() -> f32 {
    let t = |code: u8| Temperature::from_adc(code).celsius().unwrap();
    (ADC_MIN..ADC_MAX)
        .map(|code| t(code) - t(code + 1))
        .fold(0.0, f32::max)
}

/// Every quantity of `input` is in `output` (a DataLink record) within one raw step of the
/// HW-FOC field; a quantity `input` lacks is 0, or no value for a temperature.
fn assert_carried(input: &Data, output: &hwfoc::foc::DataFrame, settings: &Settings) {
    let output = Data::DataLink(*output);
    let steps = [
        (Quantity::ThrottleIn, 100.0 / 1024.0),
        (Quantity::ThrottleOut, 100.0 / 1024.0),
        (Quantity::Rpm, settings.rpm_linear().to_f32(1.0)),
        (Quantity::Voltage, 0.1),
        (Quantity::Current, 1.0 / settings.current_scale),
        (Quantity::PhaseCurrent, 1.0 / settings.current_scale),
        (Quantity::MosTemp, adc_step()),
        (Quantity::CapTemp, adc_step()),
    ];
    for (q, step) in steps {
        let got = output.value(q, settings);
        match input.value(q, settings) {
            Some(sent) => {
                let sent = match q {
                    Quantity::MosTemp | Quantity::CapTemp => sent.clamp(0.0, 129.0),
                    _ => sent,
                };
                let got = got.unwrap_or_else(|| panic!("{}: no value for {sent}", q.name()));
                assert!((got - sent).abs() <= step, "{}: {sent} -> {got}", q.name());
            }
            None => match q {
                Quantity::MosTemp | Quantity::CapTemp => assert_eq!(got, None, "{}", q.name()),
                _ => assert_eq!(got, Some(0.0), "{}", q.name()),
            },
        }
    }
}

#[test]
fn v4_frames_go_out_as_hwfoc_frames_with_their_values_and_counter() {
    let info = v4::InfoFrame {
        full_scale: 1000,
        v1: 8,
        v2: 91,
        i1: 10,
        i2: 8,
        i3: 2,
        ..Default::default()
    };
    let settings = Settings::DEFAULT;
    let frames: Vec<Data> = (0..20u32)
        .map(|k| {
            let frame = v4::DataFrame {
                counter: 70_000 + k, // beyond 16 bits: the low 16 are kept
                throttle_in_raw: 50 * k as u16,
                throttle_out_raw: 45 * k as u16,
                erpm: 1234 * k,
                voltage_adc: 2000 + 7 * k as u16,
                current_adc: 13 * k as u16,
                temp_adc: 3000 + 20 * k as u16,
                temp2_adc: 3300 + 11 * k as u16,
            };
            Data::from(v4::Data {
                frame,
                info: (k > 0).then_some(info), // the first, before an info frame: no current
            })
        })
        .collect();
    let out = through_datalink(&frames, &settings);
    for (input, output) in frames.iter().zip(&out) {
        assert_carried(input, output, &settings);
        assert_eq!(u32::from(output.packet), input.packet().unwrap() & 0xFFFF);
        assert_eq!(output.status, Status::OK, "V4 has no status word");
        let erpm = input.value(Quantity::Erpm, &settings).unwrap();
        assert!((output.erpm() as f32 - erpm).abs() <= 5.0, "{erpm}");
    }
    assert_eq!(out[0].current_raw, 0, "no current before an info frame");
}

#[test]
fn hw5_frames_go_out_with_their_values_and_faults_mapped_where_the_same() {
    let settings = Settings::new(100.0, 5, 1.0).unwrap();
    let frames: Vec<Data> = (0..10u16)
        .map(|k| {
            Data::from(TelemetryFrame {
                throttle: (11 * k) as u8,
                fault: FaultCode(1 << (k % 8)),
                erpm_raw: 977 * k,
                voltage_raw: 480 + k,
                current_raw: 37 * k,
                esc_temp: (20 + 13 * k) as u8, // up to 137 degC: saturated at 129
                bec_temp: 40,
                motor_temp: 50,
                bec_voltage_raw: 84,
                bec_current_raw: 15,
                ..Default::default()
            })
        })
        .collect();
    let out = through_datalink(&frames, &settings);
    for (k, (input, output)) in frames.iter().zip(&out).enumerate() {
        assert_carried(input, output, &settings);
        assert_eq!(
            output.packet, k as u16,
            "HW5 has no counter: the output's own"
        );
        assert_eq!(
            output.cap_adc, ADC_NO_VALUE,
            "HW5 has no capacitor temperature"
        );
    }
    let status = |k: usize| out[k].status;
    assert_eq!(status(0), Status::OK.with(Fault::MotorBlocked));
    assert_eq!(
        status(1),
        Status::OK,
        "over-temperature: MOSFET or capacitor?"
    );
    assert_eq!(status(2), Status::OK.with(Fault::ThrottleNotZeroed));
    assert_eq!(status(3), Status::OK.with(Fault::ThrottleSignalLost));
    assert_eq!(status(4), Status::OK.with(Fault::OverCurrent));
    assert_eq!(status(5), Status::OK.with(Fault::InputVoltageLow));
    assert_eq!(status(6), Status::OK);
    assert_eq!(status(7), Status::OK);
    assert!(FaultCode(1 << 5).contains(Hw5Fault::LowVoltage));
}

#[test]
fn hobbywing_can_records_go_out_with_erpm_from_rpm_and_the_settings() {
    let settings = Settings::new(100.0, 14, 2.0).unwrap();
    let frames: Vec<Data> = (0..12u16)
        .map(|k| {
            Data::from(HwCanEsc {
                node: 3,
                throttle_channel: Some(1),
                transfer_id: k as u8,
                rpm: 911 * k,
                pwm: 83 * k,
                status: 0x4000,
                power: (k > 0).then_some(Power {
                    input_voltage: 251 + k as i16,
                    current: 17 * k as i16 - 40, // regenerative at first
                    temperature: 30,
                }),
                msg2_age_ms: None,
                temperatures: (k > 1).then_some(Temperatures {
                    mos: 25 + k as u8,
                    cap: 30,
                    motor: 40,
                }),
                msg3_age_ms: None,
            })
        })
        .collect();
    let out = through_datalink(&frames, &settings);
    for (k, (input, output)) in frames.iter().zip(&out).enumerate() {
        assert_carried(input, output, &settings);
        assert_eq!(output.packet, k as u16);
        assert_eq!(
            output.status,
            Status::OK,
            "the CAN status word is no fault word"
        );
        // eRPM = rpm x pole pairs x gear ratio.
        let erpm = f32::from(911 * k as u16) * 14.0 * 2.0;
        assert!((output.erpm() as f32 - erpm).abs() <= 5.0, "{erpm}");
    }
    assert_eq!(out[0].voltage_raw, 0, "no StatusMsg2 yet");
    assert_eq!(out[1].cap_adc, ADC_NO_VALUE, "no StatusMsg3 yet");
    assert_ne!(out[2].cap_adc, ADC_NO_VALUE);
}

/// A quantity the ESC's format does not carry (an HW5 ESC's capacitor temperature) goes out as
/// the DataLink's no-value code and comes back through hwfoc's own summary as no value: no
/// row of a temperature out of the table's range.
#[test]
fn a_temperature_not_carried_comes_back_through_the_summary_as_no_value() {
    let settings = Settings::DEFAULT;
    let frames: Vec<Data> = (0..10u16)
        .map(|k| {
            Data::from(TelemetryFrame {
                throttle: 20,
                voltage_raw: 480 + k,
                esc_temp: 40,
                ..Default::default()
            })
        })
        .collect();
    assert_eq!(frames[0].value(Quantity::CapTemp, &settings), None);
    let bytes = datalink_bytes(&frames, &settings);
    let input = hwfoc_io::Input::from_memory("bridge.bin", bytes).unwrap();
    let mut sources = hwfoc_io::Sources::new(vec![input], settings);
    let mut summary = hwfoc_io::summary::Summary::new();
    sources.run(&mut summary).unwrap();
    let report = summary.report(&sources);
    let text = report.text();
    assert!(!text.contains("out of the table's range"), "{text}");
    let json = report.json();
    let esc = &json["escs"][0];
    assert_eq!(esc["frames"], serde_json::json!(10), "{esc}");
    let cap = &esc["temperature_out_of_range"]["cap_temp_c"];
    assert_eq!(
        *cap,
        serde_json::json!({"below_range": 0, "above_range": 0}),
        "{esc}"
    );
}
