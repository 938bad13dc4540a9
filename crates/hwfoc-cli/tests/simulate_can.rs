//! `hwfoc simulate --protocol hw-can`: a candump log and its ground truth, and the options a
//! CAN bus refuses.

use std::process::Command;

fn hwfoc() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hwfoc"))
}

#[test]
fn a_candump_log_of_virtual_can_escs_and_the_options_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = |n: &str| dir.path().join(n).display().to_string();
    let out = hwfoc()
        .args([
            "simulate",
            "--protocol",
            "hw-can",
            "--escs",
            "3",
            "--factory",
            "--no-ask-ids",
        ])
        .args(["-o", &path("bus.log"), "--truth", &path("truth.jsonl")])
        .args(["--duration", "1", "--start-time", "1700000000"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("3 ESCs, 333 transfers in 333 frames"),
        "{stderr}"
    );
    let log = std::fs::read_to_string(path("bus.log")).unwrap();
    let truth = std::fs::read_to_string(path("truth.jsonl")).unwrap();
    assert_eq!((log.lines().count(), truth.lines().count()), (333, 333));
    // Every frame from node 1 (the factory state), a candump -l line.
    for line in log.lines() {
        let (time, rest) = line.split_once(") can0 ").unwrap();
        assert!(
            time.starts_with("(1700000000.") && time.len() == 18,
            "{line}"
        );
        let (id, _) = rest.split_once('#').unwrap();
        assert_eq!(u32::from_str_radix(id, 16).unwrap() & 0x7F, 1, "{line}");
    }
    for (args, option) in [
        (&["--factory"][..], "--factory"),
        (&["--protocol", "hw-can", "--baud", "115200"], "--baud"),
        (&["--protocol", "dronecan", "-o", "x.log"], "--protocol"),
        (
            &["--protocol", "hw-can", "--format", "raw", "-o", "x.log"],
            "--format",
        ),
        (&["--format", "candump", "-o", "x.log"], "--format"),
        (&["--no-ask-ids", "-o", "x.log"], "--no-ask-ids"),
        (&["--protocol", "hw-can", "--escs", "64", "-o", "x.log"], ""),
        (
            &["--protocol", "hw-can", "--drop-rate", "0.1", "-o", "y.log"],
            "",
        ),
    ] {
        let out = hwfoc()
            .current_dir(dir.path())
            .arg("simulate")
            .args(args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains(option), "{stderr}");
    }
    assert!(!dir.path().join("x.log").exists() && !dir.path().join("y.log").exists());
}

/// The records `hwfoc decode` makes of `file`, as JSON values.
fn decode(file: &str) -> Vec<serde_json::Value> {
    let out = hwfoc().args(["decode", file]).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// The (esc, node) pairs of `records`, each once, sorted.
fn escs(records: &[serde_json::Value]) -> Vec<(u64, u64)> {
    let mut pairs: Vec<(u64, u64)> = records
        .iter()
        .map(|r| (r["esc"].as_u64().unwrap(), r["node"].as_u64().unwrap()))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

#[test]
fn decode_numbers_the_escs_by_channel_once_asked_and_reads_pcapng_as_candump() {
    let dir = tempfile::tempdir().unwrap();
    let path = |n: &str| dir.path().join(n).display().to_string();
    let simulate = |out: &str, extra: &[&str]| {
        let status = hwfoc()
            .args(["simulate", "--protocol", "hw-can", "--escs", "4", "-q"])
            .args([
                "--duration",
                "3",
                "--start-time",
                "1700000000",
                "-o",
                &path(out),
            ])
            .args(extra)
            .status()
            .unwrap();
        assert!(status.success());
    };
    simulate("bus.log", &[]);
    simulate("bus.pcapng", &[]);
    simulate("quiet.log", &["--no-ask-ids"]);
    simulate("factory.log", &["--factory"]);
    // Asked: ESC = throttle channel - 1, from the first record.
    let log = decode(&path("bus.log"));
    assert_eq!(escs(&log), [(0, 10), (1, 11), (2, 12), (3, 13)]);
    // The recording of the same run: the same records (its times to the nanosecond, the log's
    // to the microsecond).
    let pcapng = decode(&path("bus.pcapng"));
    assert_eq!(log.len(), pcapng.len());
    for (a, b) in log.iter().zip(&pcapng) {
        let (mut a, mut b) = (a.clone(), b.clone());
        let (ta, tb) = (a["t_s"].as_f64().unwrap(), b["t_s"].as_f64().unwrap());
        assert!((ta - tb).abs() < 1.5e-6, "{a} {b}");
        a["t_s"] = serde_json::Value::Null;
        b["t_s"] = serde_json::Value::Null;
        assert_eq!(a, b);
    }
    // Not asked: by node id.
    assert_eq!(
        escs(&decode(&path("quiet.log"))),
        [(10, 10), (11, 11), (12, 12), (13, 13)]
    );
    // From the factory: four ESCs of node 1, channel 1, are one ESC to the decoder (their
    // transfers, of the same node, type and transfer ids, taken for one node's).
    assert_eq!(escs(&decode(&path("factory.log"))), [(0, 1)]);
}
