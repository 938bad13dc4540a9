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
        (&["--protocol", "hw-can", "-o", "x.pcapng"], "-o"),
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
