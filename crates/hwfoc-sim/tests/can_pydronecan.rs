//! The virtual Hobbywing CAN ESCs checked by pydronecan (PyPI `dronecan`), an implementation
//! hwfoc did not write: a candump log the simulator wrote decodes in pydronecan to exactly the
//! transfers the simulator meant (its ground truth), and pydronecan's node on the SLCAN
//! pseudo-terminal gets the GetEscID answers, renumbers an ESC with SetID and reads its
//! GetMajorConfig. Ignored unless asked for (they need a Python with `dronecan` and `serial`:
//! `HWFOC_DRONECAN_PY`, or `python3`); `.ci/dronecan.sh` makes one and runs them.

use std::process::Command;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use hwfoc::Protocol;
use hwfoc_sim::FleetSpec;
use hwfoc_sim::can::{CanBus, CanDestination, CanPlan, CanSession};
use hwfoc_sim::faults::LinkRates;
use hwfoc_sim::model::ModelConfig;
use hwfoc_sim::profile::{ProfileSpec, Shape};

#[path = "../../hwfoc-bridge/tests/py/python.rs"]
mod python;

const SCRIPT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/py/can_check.py");

fn python() -> String {
    python::python_with("HWFOC_DRONECAN_PY", "dronecan", ".ci/dronecan.sh")
}

/// `n` ESCs, a steps profile up to 80 %, a fault on ESC 1.
fn spec(n: usize) -> FleetSpec {
    FleetSpec {
        n,
        seed: 7,
        protocol: Protocol::HwFoc,
        baud: 0,
        start_packet: None,
        profile: ProfileSpec::Steps,
        shape: Shape {
            lead_in_s: 0.5,
            levels: vec![0.0, 40.0, 80.0, 0.0],
            hold_s: 1.0,
            period_s: 10.0,
            max_pct: 80.0,
        },
        model: ModelConfig::SIMULATE,
        faults: vec!["1:mos_overheat@2-3".parse().unwrap()],
        link: LinkRates::default(),
        degradations: Vec::new(),
    }
}

#[test]
#[ignore = "needs pydronecan (HWFOC_DRONECAN_PY, or python3 with the dronecan package; .ci/dronecan.sh)"]
fn pydronecan_decodes_a_candump_log_as_the_simulator_meant() {
    let python = python();
    let dir = tempfile::tempdir().unwrap();
    let path = |n: &str| dir.path().join(n).display().to_string();
    // Some answers in the log too: GetEscID and every service the ESCs answer.
    use hwfoc::dronecan::*;
    let requests: Vec<Message> = vec![
        GetEscId::REQUEST.into(),
        SetIdRequest {
            node_id: 40,
            throttle_channel: 9,
        }
        .into(),
        SetBaudRequest { baud: 1 }.into(),
        SetLedRequest {
            option: 1,
            color: 4,
            blink: 5,
        }
        .into(),
        SetDirectionRequest { direction: 255 }.into(),
        SetReportingFrequencyRequest {
            option: 1,
            msg_id: 20052,
            rate: 6,
        }
        .into(),
        SetThrottleSourceRequest { source: 1 }.into(),
        SelfTestRequest {}.into(),
        GetMaintenanceInformationRequest { option: 0 }.into(),
        GetMajorConfigRequest { option: 0 }.into(),
    ];
    let plan = CanPlan {
        destination: CanDestination::Candump(path("bus.log")),
        realtime: false,
        start_s: Some(1.7e9),
        duration_s: Some(4.0),
        truth: Some(path("truth.jsonl")),
        overwrite: false,
        // The requests are this test's own.
        ask_ids: false,
    };
    let mut bus = CanBus::build(&spec(4), false).unwrap();
    // The requests at the start (GetEscID broadcast, SetID to node 11, the rest to node 12),
    // answered within the run.
    for (i, m) in requests.iter().enumerate() {
        let dest = if i == 1 {
            11
        } else if i > 1 {
            12
        } else {
            0
        };
        for f in m.frames(24, 100, dest, i as u8) {
            bus.receive(1_000_000 * i as u64, &f);
        }
    }
    let report = CanSession::open(bus, &plan)
        .unwrap()
        .run(&AtomicBool::new(false))
        .unwrap();
    assert!(report.transfers > 1000, "{report:?}");
    let truth = std::fs::read_to_string(path("truth.jsonl")).unwrap();
    for kind in [
        "GetEscID",
        "SetID",
        "SetBaud",
        "SetLED",
        "SetDirection",
        "SetReportingFrequency",
        "SetThrottleSource",
        "SelfTest",
        "GetMaintenanceInformation",
        "GetMajorConfig",
    ] {
        assert!(
            truth.contains(&format!("esc.{kind}\"")),
            "no {kind} in the truth"
        );
    }
    let out = Command::new(&python)
        .args([SCRIPT, "log", &path("bus.log"), &path("truth.jsonl")])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.starts_with(&format!(
        "pydronecan decoded {} transfers as the simulator meant them",
        report.transfers
    )));
}

#[test]
#[cfg(unix)]
#[ignore = "needs pydronecan with pyserial (HWFOC_DRONECAN_PY, or python3 with the dronecan package; .ci/dronecan.sh)"]
fn pydronecan_sets_up_the_virtual_escs_over_slcan() {
    let python = python();
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = std::sync::mpsc::channel();
    let flag = Arc::clone(&stop);
    // The bus holds the profile behind an Rc: it lives in its own thread.
    let sim = std::thread::spawn(move || {
        let plan = CanPlan {
            destination: CanDestination::Pty(hwfoc_sim::pty::PtyLinks::Paths(Vec::new())),
            realtime: true,
            start_s: None,
            duration_s: Some(60.0),
            truth: None,
            overwrite: false,
            ask_ids: false,
        };
        let session = CanSession::open(CanBus::build(&spec(3), false).unwrap(), &plan).unwrap();
        tx.send(session.output().to_string()).unwrap();
        session.run(&flag).unwrap()
    });
    let port = rx.recv().unwrap();
    let out = Command::new(&python)
        .args([SCRIPT, "pty", &port, "42", "5", "5"])
        .output()
        .unwrap();
    stop.store(true, Ordering::Relaxed);
    let report = sim.join().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let got: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    println!("pydronecan over SLCAN: {got}; {report:?}");
    use serde_json::json;
    assert_eq!(
        got["first"],
        json!([[10, [10, 1]], [11, [11, 2]], [12, [12, 3]]])
    );
    assert_eq!(
        got["set_id"],
        json!({"source": 10, "node_id": 42, "throttle_channel": 5})
    );
    assert_eq!(
        got["after"],
        json!([[11, [11, 2]], [12, [12, 3]], [42, [42, 5]]])
    );
    assert_eq!(got["status_sources"], json!([11, 12, 42]));
    assert_eq!(
        got["major_config"],
        json!({"direction": 0, "throttle_channel": 5, "MSG1_rate": 5, "MSG2_rate": 5})
    );
    assert_eq!(report.refused, 0);
    assert!(report.answers >= 8, "{report:?}");
}
