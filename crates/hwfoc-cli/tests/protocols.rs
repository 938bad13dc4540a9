//! Streams of both protocols (ESC wire and DataLink hub): every intact frame of either is
//! decoded whatever the chunking, and ESCs are numbered by one rule for files, recordings and
//! live ports.

mod common;

use std::collections::BTreeMap;
use std::io::Write;
use std::process::Stdio;
use std::thread;
use std::time::Duration;

use common::{Dir, hwfoc, stdout};
use hwfoc::datalink;
use hwfoc::foc::DataFrame;
use serde_json::Value;

/// ESC data frames `packets`.
fn esc(packets: std::ops::Range<u16>) -> Vec<u8> {
    packets
        .flat_map(|packet| {
            DataFrame {
                packet,
                voltage_raw: 250,
                ..Default::default()
            }
            .encode()
        })
        .collect()
}

/// Hub frames `counters` whose `channels` carry an ESC (packet = 1000 + 100 * `id` + channel:
/// an all-zero record would be an empty slot).
fn hub(id: u16, counters: std::ops::Range<u16>, channels: &[usize]) -> Vec<u8> {
    counters
        .flat_map(|counter| {
            let mut frame = datalink::HubFrame::new(counter);
            for &c in channels {
                frame.slots[c] = Some(DataFrame {
                    packet: 1000 + 100 * id + c as u16,
                    ..Default::default()
                });
            }
            frame.encode()
        })
        .collect()
}

/// The packets of JSON Lines records, by ESC.
fn by_esc(jsonl: &str) -> BTreeMap<u64, Vec<u64>> {
    let mut m = BTreeMap::<u64, Vec<u64>>::new();
    for line in jsonl.lines() {
        let r: Value = serde_json::from_str(line).unwrap();
        m.entry(r["esc"].as_u64().unwrap())
            .or_default()
            .push(r["packet"].as_u64().unwrap());
    }
    m
}

/// Every `bytes_skipped` figure in `v`.
fn skipped_bytes(v: &Value, out: &mut Vec<u64>) {
    match v {
        Value::Object(m) => {
            for (k, v) in m {
                match v.as_u64() {
                    Some(n) if k == "bytes_skipped" => out.push(n),
                    _ => skipped_bytes(v, out),
                }
            }
        }
        Value::Array(a) => a.iter().for_each(|v| skipped_bytes(v, out)),
        _ => {}
    }
}

/// 200 ESC frames and then 200 hub frames of seven ESCs (an adapter moved from an ESC to a
/// hub): 1600 records from the file, and the same from standard input in two pieces half a
/// second apart (the first piece once decided the protocol: 200 records).
#[test]
fn a_stream_that_changes_protocol_decodes_alike_from_a_file_and_from_stdin() {
    let dir = Dir::new();
    let part1 = esc(0..200);
    let part2 = hub(0, 0..200, &[0, 1, 2, 3, 4, 5, 6]);
    let path = dir.path("moved.bin");
    std::fs::write(&path, [&part1[..], &part2[..]].concat()).unwrap();
    let from_file = stdout(
        &hwfoc()
            .args(["decode", &dir.arg("moved.bin")])
            .output()
            .unwrap(),
    );
    assert_eq!(from_file.lines().count(), 1600);
    let escs = by_esc(&from_file);
    assert_eq!(escs.len(), 7);
    assert_eq!(
        escs[&0].len(),
        400,
        "the ESC and the hub's channel 0 keep ESC 0"
    );
    assert_eq!(escs[&6], vec![1006; 200]);

    let mut child = hwfoc()
        .args(["decode", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut pipe = child.stdin.take().unwrap();
    pipe.write_all(&part1).unwrap();
    pipe.flush().unwrap();
    thread::sleep(Duration::from_millis(500));
    pipe.write_all(&part2).unwrap();
    drop(pipe);
    let from_stdin = stdout(&child.wait_with_output().unwrap());
    assert!(
        from_stdin == from_file,
        "standard input decodes as the file does"
    );

    // One hub frame, then 2000 ESC frames: no byte is skipped.
    std::fs::write(
        dir.path("hub-first.bin"),
        [hub(0, 0..1, &[0]), esc(0..2000)].concat(),
    )
    .unwrap();
    let summary = stdout(
        &hwfoc()
            .args(["summary", "--json", &dir.arg("hub-first.bin")])
            .output()
            .unwrap(),
    );
    let summary: Value = serde_json::from_str(&summary).unwrap();
    let mut skipped = Vec::new();
    skipped_bytes(&summary, &mut skipped);
    assert!(!skipped.is_empty(), "{summary}");
    assert!(skipped.iter().all(|&n| n == 0), "{summary}");
    let decoded = stdout(
        &hwfoc()
            .args(["decode", &dir.arg("hub-first.bin")])
            .output()
            .unwrap(),
    );
    assert_eq!(decoded.lines().count(), 2001);
}

/// `dl_clean.bin dl_ch5.bin raw.bin`: the raw file is ESC 2, the first hub's channels 1 to 7
/// are ESCs 3 to 9, the second hub's channel 5 is ESC 14; alike from files, from live ports
/// (ptys) and from a recording of those ports.
#[cfg(unix)]
#[test]
fn files_a_recording_and_ports_number_hubs_alike() {
    use common::{Running, pty};
    use nix::sys::signal::Signal;

    let dir = Dir::new();
    let all: Vec<usize> = (0..8).collect();
    let inputs = [hub(0, 0..3, &all), hub(1, 0..3, &[5]), esc(100..103)];
    let mut expected = BTreeMap::<u64, Vec<u64>>::new();
    expected.insert(0, vec![1000; 3]);
    for c in 1..8u64 {
        expected.insert(2 + c, vec![1000 + c; 3]);
    }
    expected.insert(14, vec![1105; 3]);
    expected.insert(2, vec![100, 101, 102]);

    let names = ["dl_clean.bin", "dl_ch5.bin", "raw.bin"];
    for (name, bytes) in names.iter().zip(&inputs) {
        std::fs::write(dir.path(name), bytes).unwrap();
    }
    let files: Vec<String> = names.iter().map(|n| dir.arg(n)).collect();
    let decoded = stdout(&hwfoc().arg("decode").args(&files).output().unwrap());
    assert_eq!(by_esc(&decoded), expected, "files");

    // Live: the three ports' bytes arrive in that order, a little apart; the same bytes again
    // to `hwfoc record`, whose recording is then decoded.
    let live = |args: &[&str]| {
        let ports: Vec<_> = (0..3).map(|_| pty()).collect();
        let paths: Vec<String> = ports
            .iter()
            .map(|p| p.path.to_string_lossy().into_owned())
            .collect();
        let mut all: Vec<&str> = args.to_vec();
        all.extend(paths.iter().map(String::as_str));
        all.extend(["--baud", "115200"]);
        let mut running = Running::start(&all);
        thread::sleep(Duration::from_millis(500));
        for (mut port, bytes) in ports.iter().map(|p| &p.master).zip(&inputs) {
            port.write_all(bytes).unwrap();
            port.flush().unwrap();
            thread::sleep(Duration::from_millis(300));
        }
        thread::sleep(Duration::from_millis(300));
        running.signal(Signal::SIGINT);
        assert!(
            running.wait(Duration::from_secs(10)),
            "{}",
            running.stderr()
        );
    };
    let out = dir.arg("live.jsonl");
    live(&["decode", "-o", &out]);
    let from_ports = std::fs::read_to_string(&out).unwrap();
    assert_eq!(by_esc(&from_ports), expected, "live ports");

    let rec = dir.arg("ports.pcapng");
    live(&["record", "-o", &rec]);
    let recorded = stdout(&hwfoc().args(["decode", &rec]).output().unwrap());
    assert_eq!(by_esc(&recorded), expected, "recording");
}

/// The JSON summary of `args`, and whether the command succeeded.
fn summary_json(args: &[&str]) -> (Value, bool) {
    let out = hwfoc()
        .arg("summary")
        .arg("--json")
        .args(args)
        .output()
        .unwrap();
    (
        serde_json::from_slice(&out.stdout).unwrap(),
        out.status.success(),
    )
}

/// ESC frames, hub frames of eight ESCs, ESC frames: `--protocol hw-foc` gives the ESC's
/// records only, the hub's bytes skipped; `--protocol datalink` the hub's only, the ESC's
/// bytes skipped; without it, both.
#[test]
fn a_forced_protocol_reads_its_frames_only() {
    let dir = Dir::new();
    let all: Vec<usize> = (0..8).collect();
    let hub_bytes = hub(0, 0..3, &all);
    let bytes = [esc(0..20), hub_bytes.clone(), esc(20..30)].concat();
    std::fs::write(dir.path("mixed.bin"), &bytes).unwrap();
    let file = dir.arg("mixed.bin");
    let decode = |protocol: &[&str]| {
        let out = hwfoc()
            .arg("decode")
            .args(protocol)
            .arg(&file)
            .output()
            .unwrap();
        by_esc(&stdout(&out))
    };

    let esc_only = decode(&["--protocol", "hw-foc"]);
    assert_eq!(esc_only, BTreeMap::from([(0, (0..30).collect())]));
    let (summary, ok) = summary_json(&["--protocol", "hw-foc", &file]);
    assert!(ok, "{summary}");
    assert_eq!(summary["hubs"], Value::Array(Vec::new()), "{summary}");
    assert_eq!(summary["escs"].as_array().unwrap().len(), 1, "{summary}");
    let link = &summary["escs"][0]["link"];
    assert_eq!(link["bytes_skipped"], hub_bytes.len() as u64, "{summary}");
    assert_eq!(summary["protocol"], "hw-foc", "{summary}");
    let text = hwfoc()
        .args(["summary", "--protocol", "datalink", &file])
        .output()
        .unwrap();
    let text = stdout(&text);
    assert!(
        text.contains(
            "\nprotocol     DataLink V2 only (the bytes of any other protocol skipped)\n"
        ),
        "{text}"
    );

    let hub_only = decode(&["--protocol", "datalink"]);
    let expected: BTreeMap<u64, Vec<u64>> = (0..8u64).map(|c| (c, vec![1000 + c; 3])).collect();
    assert_eq!(hub_only, expected);
    let (summary, ok) = summary_json(&["--protocol", "datalink", &file]);
    assert!(ok, "{summary}");
    assert_eq!(summary["escs"].as_array().unwrap().len(), 8, "{summary}");
    let mut skipped = Vec::new();
    skipped_bytes(&summary, &mut skipped);
    assert!(
        skipped.iter().all(|&n| n == 30 * 24) && !skipped.is_empty(),
        "the ESC's bytes are the hub link's skipped bytes: {summary}"
    );

    let (summary, ok) = summary_json(&[&file]);
    assert!(ok, "{summary}");
    assert_eq!(
        summary.get("protocol"),
        None,
        "said only when forced: {summary}"
    );
    let both = decode(&[]);
    assert_eq!(both.values().map(Vec::len).sum::<usize>(), 30 + 3 * 8);
    assert_eq!(
        both[&0].len(),
        33,
        "the ESC and the hub's channel 0 keep ESC 0"
    );
    assert_eq!(both[&7], vec![1007; 3]);
}

/// A forced protocol that finds nothing gives its own advice (its name and baud rate) and
/// the exit status of any input without frames.
#[test]
fn a_forced_protocol_that_finds_nothing_says_so() {
    let dir = Dir::new();
    std::fs::write(dir.path("esc.bin"), esc(0..50)).unwrap();
    let file = dir.arg("esc.bin");
    let advice = "no valid DataLink V2 frames: these bytes are hw-foc frames (try --protocol \
                  hw-foc, or leave --protocol out)";
    let decoded = hwfoc()
        .args(["decode", "--protocol", "datalink", &file])
        .output()
        .unwrap();
    assert_eq!(decoded.status.code(), Some(1));
    assert!(decoded.stdout.is_empty());
    let err = String::from_utf8_lossy(&decoded.stderr);
    assert!(err.contains(advice), "{err}");
    assert!(err.contains("no data frame in any input"), "{err}");

    let text = hwfoc()
        .args(["summary", "--protocol", "datalink", &file])
        .output()
        .unwrap();
    assert_eq!(text.status.code(), Some(1));
    let said = String::from_utf8_lossy(&text.stdout);
    assert!(said.contains(advice), "{said}");
    let (summary, ok) = summary_json(&["--protocol", "datalink", &file]);
    assert!(!ok);
    assert_eq!(summary["escs"][0]["warning"], advice, "{summary}");
    // Unforced, the same file is read.
    let (_, ok) = summary_json(&[&file]);
    assert!(ok);
}

/// `--protocol` takes the protocols' names (shown by `--help` and the shell completions); any
/// other is a usage error listing them, on every command that reads inputs.
#[test]
fn an_unknown_protocol_is_a_usage_error_listing_the_names() {
    let dir = Dir::new();
    std::fs::write(dir.path("esc.bin"), esc(0..5)).unwrap();
    let file = dir.arg("esc.bin");
    let png = dir.arg("p.png");
    for args in [
        vec!["decode", &file],
        vec!["summary", &file],
        vec!["plot", &file, "-o", &png],
        vec!["record", "/dev/ttyUSB_hwfoc_missing", "-o", &png],
        vec!["monitor", "--plain", "/dev/ttyUSB_hwfoc_missing"],
        vec!["bridge", &file, "--mavlink", "udp"],
    ] {
        let out = hwfoc()
            .args(&args)
            .args(["--protocol", "hw6"])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        let first = err.lines().next().unwrap_or_default();
        assert!(
            first.contains("invalid value 'hw6' for '--protocol"),
            "{err}"
        );
        assert!(
            err.contains("hw-foc, datalink, hw-v4, hw-v3, hw5, hw-can, dronecan"),
            "{err}"
        );
        assert!(!dir.path("p.png").exists());

        let help = stdout(&hwfoc().arg(args[0]).arg("--help").output().unwrap());
        assert!(
            help.contains("--protocol <NAME>")
                && help.contains("datalink: DataLink V2, 115200 baud")
                && help.contains("hw5:      HW5, 115200 baud")
                && help.contains("hw-can:   Hobbywing DroneCAN, on a CAN bus")
                && help.contains("dronecan: DroneCAN ESC, on a CAN bus"),
            "{help}"
        );
    }
    let bash = stdout(&hwfoc().args(["completions", "bash"]).output().unwrap());
    assert!(
        bash.contains("hw-foc datalink hw-v4 hw-v3 hw5 hw-can dronecan"),
        "completions"
    );
}

/// The monitor reads the protocol forced only: a virtual ESC's HW-FOC frames are frames under
/// `--protocol hw-foc` and skipped bytes under `--protocol datalink`.
#[test]
fn the_monitor_reads_the_protocol_forced_only() {
    let last_status = |protocol: &str| {
        let out = hwfoc()
            .args(["monitor", "--sim", "1", "--json", "--no-config"])
            .args([
                "--interval",
                "0.5",
                "--duration",
                "1.6",
                "--protocol",
                protocol,
            ])
            .output()
            .unwrap();
        let lines: Vec<Value> = stdout(&out)
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .filter(|v: &Value| v["type"] == "status")
            .collect();
        lines.last().cloned().expect("a status line")
    };
    let esc = last_status("hw-foc");
    assert!(esc["frames"].as_u64().unwrap() > 0, "{esc}");
    let hub = last_status("datalink");
    assert_eq!(hub["frames"], 0, "{hub}");
    assert!(hub["bytes"].as_u64().unwrap() > 0, "{hub}");
    assert_eq!(hub["bytes_skipped"], hub["bytes"], "{hub}");
}

/// The bridge reads the protocol forced only: its virtual ESCs' HW-FOC frames reach the
/// DataLink output under `--protocol hw-foc`, and none under `--protocol datalink`.
#[cfg(unix)]
#[test]
fn the_bridge_reads_the_protocol_forced_only() {
    let pty = common::pty();
    let output = pty.path.to_string_lossy().into_owned();
    let report = |protocol: &str| {
        let out = hwfoc()
            .args(["bridge", "--sim", "2", "--no-config", "--duration", "1.2"])
            .args(["--datalink", &output, "--protocol", protocol])
            .output()
            .unwrap();
        let report = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "{report}");
        report
    };
    let esc = report("hw-foc");
    assert!(
        esc.contains(" frames of 2 ESCs") && !esc.contains(" 0 frames"),
        "{esc}"
    );
    let hub = report("datalink");
    assert!(hub.contains(" 0 frames of 0 ESCs"), "{hub}");
}

/// An HW5 wire (telemetry frames, a configurator's ping between them, noise) told from its
/// bytes: records of protocol `hw5` without packet numbers, HW5's fault names, the BEC and
/// motor columns; the summary counts no loss (no counter), names the faults by HW5's names and
/// integrates energy from voltage and current.
#[test]
fn an_hw5_wire_is_read_with_its_own_fields_and_faults() {
    use hwfoc::hw5::{Fault, FaultCode, TelemetryFrame};
    let frame = |i: u16, fault: FaultCode| TelemetryFrame {
        throttle: 40,
        fault,
        erpm_raw: 3000 + i,
        voltage_raw: 504,
        current_raw: 123,
        esc_temp: 45,
        bec_temp: 40,
        motor_temp: 60,
        bec_voltage_raw: 84,
        bec_current_raw: 15,
        ..Default::default()
    };
    let mut wire = b"noise".to_vec();
    for i in 0..20u16 {
        let fault = if (5..8).contains(&i) {
            FaultCode::OK.with(Fault::LowVoltage)
        } else {
            FaultCode::OK
        };
        wire.extend_from_slice(&frame(i, fault).encode());
        if i == 10 {
            // Rotorflight's ping request: recognised, counted, not a record.
            wire.extend_from_slice(&[0x01, 0xFD, 0x03, 0x03, 0x2C, 0x24, 0x00, 0x01, 0x60, 0x60]);
        }
    }
    let dir = Dir::new();
    std::fs::write(dir.path("hw5.bin"), &wire).unwrap();
    let file = dir.arg("hw5.bin");
    for forced in [None, Some("hw5")] {
        let mut args = vec!["decode", file.as_str()];
        args.extend(forced.iter().flat_map(|p| ["--protocol", *p]));
        let out = hwfoc().args(&args).output().unwrap();
        assert!(out.status.success(), "{forced:?}");
        let records: Vec<Value> = stdout(&out)
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(records.len(), 20, "{forced:?}");
        let r = &records[6];
        assert_eq!(r["protocol"], "hw5");
        assert_eq!(r["packet"], Value::Null);
        assert_eq!(r["throttle_in_pct"], 40.0);
        assert_eq!(r["throttle_out_pct"], Value::Null);
        assert_eq!(r["erpm"], 30_060);
        assert_eq!(r["bec_voltage_v"], 8.4);
        assert_eq!(r["motor_temp_c"], 60.0);
        assert_eq!(r["status"], 0x20);
        assert_eq!(r["faults"], serde_json::json!(["low_voltage"]));
        assert_eq!(records[0]["faults"], serde_json::json!([]));
    }
    let out = hwfoc().args(["summary", "--json", &file]).output().unwrap();
    assert!(out.status.success());
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    let esc = &v["escs"][0];
    assert_eq!(esc["protocol"], "hw5");
    assert_eq!(esc["frames"], 20);
    assert_eq!(esc["link"]["lost_packets"], Value::Null);
    assert_eq!(esc["link"]["delivery_ratio"], Value::Null);
    assert_eq!(esc["link"]["checksum_failures"], 0);
    // The noise only: the ping request is a frame, not skipped bytes.
    assert_eq!(esc["link"]["bytes_skipped"], 5);
    assert_eq!(esc["faults"], serde_json::json!({"low_voltage": 3}));
    assert_eq!(esc["fault_episode_count"], 1);
    assert_eq!(esc["fields"]["bec_current_a"]["max"], 1.5);
    assert!(esc["energy"]["charge_mah"].as_f64().unwrap() > 0.0);
    let text = stdout(&hwfoc().args(["summary", &file]).output().unwrap());
    assert!(
        text.contains("no packet counter (loss not counted)"),
        "{text}"
    );
    assert!(text.contains("low_voltage"), "{text}");
    assert!(!text.contains("phase_current_a"), "{text}");
}

/// The committed candump log of a bus of Hobbywing (39 records) and standard DroneCAN ESCs
/// (19 records).
fn bus_log() -> String {
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../testdata/dronecan/can-bus.log"
    )
    .to_string()
}

/// The `protocol` of each record `decode` made of `args`, its standard error and exit code.
fn decoded_protocols(args: &[&str]) -> (Vec<String>, String, Option<i32>) {
    let out = hwfoc().arg("decode").args(args).output().unwrap();
    let protocols = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str::<Value>(l).unwrap()["protocol"].to_string())
        .collect();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    (protocols, err, out.status.code())
}

/// A forced protocol filters a CAN bus: `--protocol hw-can` keeps the Hobbywing ESCs'
/// records, `--protocol dronecan` the standard ESCs', a serial protocol none; what was left
/// out is counted in a warning naming the input.
#[test]
fn a_forced_protocol_filters_a_can_bus() {
    let log = bus_log();
    let (all, _, code) = decoded_protocols(&[&log]);
    assert_eq!((all.len(), code), (58, Some(0)));

    let (hw, err, code) = decoded_protocols(&["--protocol", "hw-can", &log]);
    assert_eq!((hw.len(), code), (39, Some(0)), "{err}");
    assert!(hw.iter().all(|p| p == "\"hw-can\""), "{hw:?}");
    assert!(
        err.contains(
            "can-bus.log: can0: 19 dronecan records left out (not hw-can, the protocol forced)"
        ),
        "{err}"
    );

    let (std, err, code) = decoded_protocols(&["--protocol", "dronecan", &log]);
    assert_eq!((std.len(), code), (19, Some(0)), "{err}");
    assert!(std.iter().all(|p| p == "\"dronecan\""), "{std:?}");
    assert!(
        err.contains("can0: 39 hw-can records left out (not dronecan, the protocol forced)"),
        "{err}"
    );

    let (none, err, code) = decoded_protocols(&["--protocol", "hw5", &log]);
    assert_eq!((none.len(), code), (0, Some(1)), "{err}");
    assert!(
        err.contains(
            "can0: 39 hw-can records and 19 dronecan records left out (not hw5, the \
                      protocol forced)"
        ),
        "{err}"
    );
    assert!(err.contains("no data frame in any input"), "{err}");
    assert!(!err.contains("baud rate"), "{err}");

    let out = hwfoc()
        .args(["summary", "--json", "--protocol", "dronecan", &log])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("can0: 39 hw-can records left out"), "{err}");
    let (summary, ok) = (
        serde_json::from_slice::<Value>(&out.stdout).unwrap(),
        out.status.success(),
    );
    assert!(ok, "{summary}");
    let escs = summary["escs"].as_array().unwrap();
    assert!(
        !escs.is_empty() && escs.iter().all(|e| e["protocol"] == "dronecan"),
        "{summary}"
    );
    let dir = Dir::new();
    let png = dir.arg("bus.png");
    let out = hwfoc()
        .args(["plot", "--protocol", "hw-can", &log, "-o", &png])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("can0: 19 dronecan records left out"), "{err}");
}

/// A CAN protocol forced on serial bytes decodes nothing, and says in CAN words what the
/// bytes are instead.
#[test]
fn a_can_protocol_forced_on_serial_bytes_names_what_they_are() {
    let dir = Dir::new();
    std::fs::write(dir.path("esc.bin"), esc(0..50)).unwrap();
    let file = dir.arg("esc.bin");
    let (records, err, code) = decoded_protocols(&["--protocol", "hw-can", &file]);
    assert_eq!((records.len(), code), (0, Some(1)), "{err}");
    assert!(
        err.contains(
            "no Hobbywing DroneCAN records: these bytes are not CAN frames but hw-foc frames \
             (try --protocol hw-foc, or leave --protocol out)"
        ),
        "{err}"
    );
    assert!(!err.contains("baud rate"), "{err}");
}

/// A forced serial protocol that finds none of its frames in bytes of another known format
/// names that format, not the baud rate and the wiring.
#[test]
fn a_forced_protocol_names_the_format_the_bytes_are() {
    use hwfoc::hw5::TelemetryFrame;
    let dir = Dir::new();
    let hw5: Vec<u8> = (0..30u16)
        .flat_map(|i| {
            TelemetryFrame {
                erpm_raw: 100 + i,
                voltage_raw: 500,
                ..Default::default()
            }
            .encode()
        })
        .collect();
    std::fs::write(dir.path("hw5.bin"), hw5).unwrap();
    let file = dir.arg("hw5.bin");
    let (records, err, code) = decoded_protocols(&["--protocol", "hw-foc", &file]);
    assert_eq!((records.len(), code), (0, Some(1)), "{err}");
    assert!(
        err.contains(
            "no valid HW-FOC frames: these bytes are hw5 frames (try --protocol hw5, or leave \
             --protocol out)"
        ),
        "{err}"
    );
    // Hobbywing V4 frames (a capture of a real ESC) read as HW5.
    let v4 = common::capture("platinum-v4.csv");
    let (_, err, code) = decoded_protocols(&["--protocol", "hw5", v4.to_str().unwrap()]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains(
            "no valid HW5 frames: these bytes are hw-v4 frames (try --protocol hw-v4, or leave \
             --protocol out)"
        ),
        "{err}"
    );
    // Bytes of no known format keep the advice of the wire.
    let mut x = 1u32;
    let noise: Vec<u8> = (0..4096)
        .map(|_| {
            x = x.wrapping_mul(1_103_515_245).wrapping_add(12_345);
            (x >> 16) as u8
        })
        .collect();
    std::fs::write(dir.path("noise.bin"), noise).unwrap();
    let (_, err, _) = decoded_protocols(&["--protocol", "hw-foc", &dir.arg("noise.bin")]);
    assert!(
        err.contains("check the baud rate (19200) and the wiring"),
        "{err}"
    );
}

/// A CAN protocol names CAN buses: forced on a serial port, it is an error naming the port
/// before anything is opened.
#[test]
fn a_can_protocol_forced_on_a_serial_port_is_an_error() {
    let port = "/dev/ttyUSB_hwfoc_missing";
    for args in [
        vec!["decode", port],
        vec!["summary", port],
        vec!["monitor", "--plain", "--no-config", port],
        vec!["bridge", port, "--mavlink", "udp"],
    ] {
        let out = hwfoc()
            .args(&args)
            .args(["--protocol", "dronecan"])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(
                "--protocol dronecan: a CAN protocol reads CAN buses (slcan:PORT, can:INTERFACE), \
                 not the serial port /dev/ttyUSB_hwfoc_missing"
            ),
            "{err}"
        );
    }
}
