//! The MAVLink output as the receivers people use decode it: pymavlink, with a parser that its
//! mavgen generates from the vendored message definitions (`tests/mavlink-xml/`), and with its
//! bundled ardupilotmega dialect. Every message is compared, field by field, with the records
//! it was made of, in the units of the message definitions, computed here independently of the
//! encoder.
//!
//! Needs a Python with pymavlink (`HWFOC_PYMAVLINK`, or `python3` if it has it): ignored unless
//! asked for (`--include-ignored`); `.ci/mavlink.sh` makes one and runs this test.

use std::io::{BufRead, BufReader};
use std::net::SocketAddr;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use hwfoc::foc::DataFrame;
use hwfoc::telemetry::Data;
use hwfoc::{Fault, Settings, Status};
use hwfoc_bridge::mavlink::{MavlinkOptions, MavlinkOutput, MavlinkTarget};
use hwfoc_bridge::{Output, SILENT_AFTER, Update};
use hwfoc_io::Record;
use serde_json::Value;

#[path = "py/python.rs"]
mod python;

const ESCS: usize = 5;
/// ESC 3 sends only its first frames, then is silent.
const SILENT_ESC: usize = 3;
const SILENT_FROM_STEP: usize = 3;
/// ESC 4 reports over current and MOSFET overheat from this step on.
const FAULT_ESC: usize = 4;
const FAULT_FROM_STEP: usize = 10;
const STEPS: usize = 50;
const STEP: Duration = Duration::from_millis(50);

fn status_of(esc: usize, step: usize) -> Status {
    match esc {
        // Under voltage, all along: ESC_FAILURE_GENERIC.
        1 => Status::OK.with(Fault::InputVoltageLow),
        FAULT_ESC if step >= FAULT_FROM_STEP => {
            Status::OK.with(Fault::OverCurrent).with(Fault::MosOverheat)
        }
        _ => Status::OK,
    }
}

/// ESC `esc`'s frame at `step`: distinct values per ESC, changing with the step.
fn frame_of(esc: usize, step: usize) -> DataFrame {
    let e = esc as u16;
    let s = step as u16;
    DataFrame {
        packet: 1000 * e + s,
        throttle_in_raw: 400,
        throttle_out_raw: 390,
        erpm_raw: 1000 + 700 * e + 7 * s,
        voltage_raw: 220 + 3 * e,
        // 10.0 A + 1.5 A per ESC (scale 64); ESC 2 brakes regeneratively (negative current).
        current_raw: if esc == 2 { -96 } else { 640 + 96 * e as i16 },
        phase_current_raw: 1200,
        mos_adc: 120 + 5 * e as u8,
        cap_adc: 110 + 4 * e as u8,
        status: status_of(esc, step),
    }
}

/// What the test knows of an ESC after a step: its records so far and their times.
#[derive(Default, Clone)]
struct Known {
    records: Vec<(Record, Instant)>,
    errors: u32,
}

impl Known {
    fn online(&self, now: Instant) -> Option<&Record> {
        let (r, at) = self.records.last()?;
        (now.saturating_duration_since(*at) < SILENT_AFTER).then_some(r)
    }

    /// mAh consumed: each frame's current holds until the next frame (left sum over t_s).
    fn mah(&self) -> f64 {
        self.records
            .windows(2)
            .map(|w| {
                f64::from(w[0].0.current_a.unwrap()) * (w[1].0.t_s.unwrap() - w[0].0.t_s.unwrap())
            })
            .sum::<f64>()
            / 3.6
    }
}

fn temperature(r: &Record) -> f64 {
    f64::from(r.mos_temp_c.unwrap().max(r.cap_temp_c.unwrap()))
}

/// The ESC_FAILURE_FLAGS of the statuses used here, from common.xml's values.
fn flags(status: Status) -> u64 {
    let mut f = 0;
    if status.contains(Fault::OverCurrent) {
        f |= 1; // ESC_FAILURE_OVER_CURRENT
    }
    if status.contains(Fault::MosOverheat) {
        f |= 4; // ESC_FAILURE_OVER_TEMPERATURE
    }
    if status.contains(Fault::InputVoltageLow) {
        f |= 64; // ESC_FAILURE_GENERIC
    }
    f
}

fn array(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// The expected messages of one poll: names (in order), and the state they describe.
struct Poll {
    names: Vec<String>,
    escs: Vec<Known>,
    now: Instant,
}

#[test]
#[ignore = "needs a Python with pymavlink (HWFOC_PYMAVLINK or python3): .ci/mavlink.sh runs it"]
fn pymavlink_decodes_every_message_with_the_records_values() {
    let python = python::python_with("HWFOC_PYMAVLINK", "pymavlink", ".ci/mavlink.sh");
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let mut child = Command::new(&python)
        .arg(dir.join("py/mavlink_check.py"))
        .arg(dir.join("mavlink-xml"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("run the pymavlink check");
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let ready = lines.next().expect("READY from the check").unwrap();
    let port: u16 = ready
        .strip_prefix("READY ")
        .unwrap_or_else(|| panic!("{ready}"))
        .parse()
        .unwrap();
    let addr: SocketAddr = ([127, 0, 0, 1], port).into();

    let mut out = MavlinkOutput::open(MavlinkTarget::Udp(addr), MavlinkOptions::default()).unwrap();
    let t0 = Instant::now();
    let mut escs = vec![Known::default(); ESCS];
    let mut polls = Vec::new();
    let mut info_due = [None::<Instant>; 2];
    let mut info_state: [Option<(u8, Vec<u64>)>; 2] = [None, None];
    for step in 0..STEPS {
        let now = t0 + STEP * step as u32;
        let mut fresh = [false; 2];
        for (esc, known) in escs.iter_mut().enumerate() {
            if esc == SILENT_ESC && step >= SILENT_FROM_STEP {
                continue;
            }
            let frame = frame_of(esc, step);
            let record = Record::new(
                Some(1_700_000_000.0 + step as f64 * 0.05),
                esc as u8,
                &Data::from(frame),
                &Settings::default(),
            );
            let before = known.records.last().map_or(0, |(r, _)| r.status.unwrap().0);
            known.errors += (record.status.unwrap().0 & !before).count_ones();
            known.records.push((record, now));
            fresh[esc / 4] = true;
            out.update(&Update {
                esc: esc as u8,
                frame: &Data::from(frame),
                record: &record,
                settings: &Settings::DEFAULT,
                arrived: now,
            });
        }
        let before = out.stats().messages;
        out.poll(now).unwrap();
        // The messages expected of this poll.
        let mut names = Vec::new();
        if step % 20 == 0 {
            names.push("HEARTBEAT".to_string());
        }
        for group in 0..2 {
            if fresh[group] {
                names.push(["ESC_TELEMETRY_1_TO_4", "ESC_TELEMETRY_5_TO_8"][group].to_string());
                names.push("ESC_STATUS".to_string());
            }
            let slots = (group * 4..(group * 4 + 4).min(ESCS)).map(|e| escs[e].online(now));
            let mut info = 0u8;
            let mut f = vec![0u64; 4];
            for (i, slot) in slots.enumerate() {
                if let Some(r) = slot {
                    info |= 1 << i;
                    f[i] = flags(r.status.unwrap());
                }
            }
            let state = (info, f);
            let changed = info_state[group].as_ref() != Some(&state);
            let periodic = info_due[group].is_none_or(|due| now >= due);
            if changed || (periodic && info != 0) {
                names.push("ESC_INFO".to_string());
                info_due[group] = Some(now + Duration::from_secs(1));
                info_state[group] = Some(state);
            }
        }
        assert_eq!(
            out.stats().messages - before,
            names.len() as u64,
            "step {step}: {names:?}"
        );
        polls.push(Poll {
            names,
            escs: escs.clone(),
            now,
        });
    }
    assert_eq!(out.stats().errors, 0);

    // End the check: it drains the socket and exits.
    drop(child.stdin.take());
    let decoded: Vec<Value> = lines
        .map(|l| serde_json::from_str(&l.unwrap()).unwrap())
        .collect();
    assert!(child.wait().unwrap().success());
    let expected: usize = polls.iter().map(|p| p.names.len()).sum();
    assert_eq!(
        decoded.len(),
        expected,
        "every message was received and decoded"
    );

    let mut index = 0;
    let mut checked = std::collections::BTreeMap::<String, usize>::new();
    for poll in &polls {
        for name in &poll.names {
            let m = &decoded[index];
            assert!(m.get("error").is_none(), "{m}");
            assert_eq!(m["seq"], index % 256, "sequence numbers follow each other");
            assert_eq!(
                (m["sysid"].as_u64(), m["compid"].as_u64()),
                (Some(1), Some(158))
            );
            let got = m["name"].as_str().unwrap();
            assert!(
                got == name,
                "message {index}: {got} where {name} was expected"
            );
            check(m, poll);
            *checked.entry(got.to_string()).or_default() += 1;
            index += 1;
        }
    }
    eprintln!("pymavlink decoded and checked: {checked:?}");
    for name in [
        "HEARTBEAT",
        "ESC_TELEMETRY_1_TO_4",
        "ESC_TELEMETRY_5_TO_8",
        "ESC_STATUS",
        "ESC_INFO",
    ] {
        assert!(checked.contains_key(name), "{name} was checked");
    }
}

/// Compares every field of a decoded message with the records of the ESCs at its poll.
fn check(m: &Value, poll: &Poll) {
    let f = &m["fields"];
    let name = m["name"].as_str().unwrap();
    let bundled = &m["bundled"];
    match name {
        "HEARTBEAT" => {
            assert_eq!(f["type"], 18, "MAV_TYPE_ONBOARD_CONTROLLER");
            assert_eq!(f["autopilot"], 8, "MAV_AUTOPILOT_INVALID");
            assert_eq!(f["system_status"], 4, "MAV_STATE_ACTIVE");
            assert_eq!(f["base_mode"], 0);
            assert_eq!(f["custom_mode"], 0);
            assert_eq!(f["mavlink_version"], 3);
            assert_eq!(bundled, f, "pymavlink's bundled dialect decodes it alike");
        }
        "ESC_TELEMETRY_1_TO_4" | "ESC_TELEMETRY_5_TO_8" => {
            let first = if name == "ESC_TELEMETRY_1_TO_4" { 0 } else { 4 };
            let mut want: [[f64; 4]; 6] = [[0.0; 4]; 6];
            #[allow(clippy::needless_range_loop)] // i indexes the six columns alike
            for i in 0..4 {
                let Some(known) = poll.escs.get(first + i) else {
                    continue;
                };
                let Some(r) = known.online(poll.now) else {
                    continue;
                };
                want[0][i] = temperature(r).round();
                want[1][i] = (f64::from(r.voltage_v.unwrap()) * 100.0).round();
                want[2][i] = (f64::from(r.current_a.unwrap()) * 100.0).round().max(0.0);
                want[3][i] = known.mah().round().max(0.0);
                want[4][i] = f64::from(r.rpm.unwrap()).round();
                want[5][i] = known.records.len() as f64;
            }
            for (k, field) in [
                "temperature",
                "voltage",
                "current",
                "totalcurrent",
                "rpm",
                "count",
            ]
            .iter()
            .enumerate()
            {
                assert_eq!(array(&f[field]), want[k], "{name}.{field}");
            }
            assert_eq!(bundled, f, "pymavlink's bundled dialect decodes it alike");
        }
        "ESC_STATUS" | "ESC_INFO" => {
            assert!(
                bundled.is_null(),
                "pymavlink's bundled dialect lacks {name}"
            );
            let index = f["index"].as_u64().unwrap() as usize;
            assert!(index == 0 || index == 4);
            let time = f["time_usec"].as_u64().unwrap();
            assert!(time > 1_600_000_000_000_000, "Unix time, us");
            let slots: Vec<Option<(&Known, &Record)>> = (index..index + 4)
                .map(|e| {
                    let known = poll.escs.get(e)?;
                    Some((known, known.online(poll.now)?))
                })
                .collect();
            if name == "ESC_STATUS" {
                let rpm = slots
                    .iter()
                    .map(|s| s.map_or(0.0, |(_, r)| f64::from(r.rpm.unwrap()).round()));
                assert_eq!(array(&f["rpm"]), rpm.collect::<Vec<_>>());
                // float32 on the wire: exactly the record's f32.
                let v = slots
                    .iter()
                    .map(|s| s.map_or(0.0, |(_, r)| f64::from(r.voltage_v.unwrap())));
                assert_eq!(array(&f["voltage"]), v.collect::<Vec<_>>());
                let a = slots
                    .iter()
                    .map(|s| s.map_or(0.0, |(_, r)| f64::from(r.current_a.unwrap())));
                assert_eq!(array(&f["current"]), a.collect::<Vec<_>>());
            } else {
                assert_eq!(f["count"], ESCS, "ESC_INFO.count");
                assert_eq!(f["connection_type"], 1, "ESC_CONNECTION_TYPE_SERIAL");
                let info = slots
                    .iter()
                    .enumerate()
                    .filter(|(_, s)| s.is_some())
                    .fold(0, |b, (i, _)| b | 1 << i);
                assert_eq!(f["info"], info, "ESC_INFO.info");
                let counter: usize = (index..(index + 4).min(ESCS))
                    .map(|e| poll.escs[e].records.len())
                    .sum();
                assert_eq!(f["counter"], counter % 65536);
                let fl = slots
                    .iter()
                    .map(|s| s.map_or(0, |(_, r)| flags(r.status.unwrap())) as f64);
                assert_eq!(array(&f["failure_flags"]), fl.collect::<Vec<_>>());
                let errors = (index..index + 4)
                    .map(|e| poll.escs.get(e).map_or(0.0, |k| f64::from(k.errors)));
                assert_eq!(array(&f["error_count"]), errors.collect::<Vec<_>>());
                let t = slots.iter().map(|s| {
                    s.map_or(f64::from(i16::MAX), |(_, r)| {
                        (temperature(r) * 100.0).round()
                    })
                });
                assert_eq!(array(&f["temperature"]), t.collect::<Vec<_>>());
            }
        }
        other => panic!("unexpected message {other}"),
    }
}
