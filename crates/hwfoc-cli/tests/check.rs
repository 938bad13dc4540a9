//! `hwfoc check`: the analysers on simulated flights (healthy ones give no warning, faulty ones
//! are found on the right ESC in the right window), on the real captures of `testdata/`, and the
//! command's output and exit status.

mod common;

use std::path::{Path, PathBuf};

use common::{Dir, hwfoc, run};

use hwfoc::Settings;
use hwfoc_io::Record;
use hwfoc_io::check::{
    Analyser, Baseline, CheckConfig, EscId, EscSeries, Finding, Sample, Severity, analyse,
};
use hwfoc_sim::degrade::{DegradeKind, DegradeSpec};
use hwfoc_sim::fleet::FleetSpec;
use hwfoc_sim::model::ModelConfig;
use hwfoc_sim::profile::{ProfileSpec, Shape};
use serde_json::Value;

/// A small deterministic generator of flight parameters.
struct Draw(u64);

impl Draw {
    fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// Healthy flight `i` of the false-trip test: its profile, shape, ESC count and airframe drawn
/// from `i`.
fn healthy(i: u64) -> FleetSpec {
    let mut d = Draw(i.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xC0FFEE);
    let profile =
        [ProfileSpec::Steps, ProfileSpec::Ramp, ProfileSpec::Sine][(i % 3) as usize].clone();
    let levels: Vec<f64> = (0..5)
        .map(|_| (d.between(0.0, 100.0) / 5.0).round() * 5.0)
        .collect();
    let mut spec = FleetSpec::steps(
        3 + (i % 6) as usize,
        1000 + i,
        Shape {
            lead_in_s: d.between(0.5, 3.0),
            levels: [vec![0.0], levels, vec![0.0]].concat(),
            hold_s: d.between(1.0, 5.0),
            period_s: d.between(4.0, 15.0),
            max_pct: d.between(40.0, 100.0),
        },
        ModelConfig {
            kv: d.between(300.0, 1500.0),
            pole_pairs: 7,
            full_current_a: d.between(15.0, 90.0),
            cells: [4, 6, 6, 12][(i % 4) as usize],
            battery_r_ohm: d.between(0.005, 0.03),
            capacity_mah: d.between(3000.0, 16000.0),
            ambient_c: d.between(5.0, 40.0),
            current_scale: 64.0,
        },
        Vec::new(),
    );
    spec.profile = profile;
    spec
}

/// The ESCs' series of `spec` flown for `seconds`, generated in-process: each intact data frame
/// as its record, at its simulated time.
fn fly(spec: FleetSpec, seconds: f64, recording: &str) -> Vec<EscSeries> {
    let settings = Settings::default();
    let fleet = spec.build().expect("a valid fleet");
    fleet
        .escs()
        .into_iter()
        .map(|mut esc| {
            let number = esc.index();
            let mut samples = Vec::new();
            loop {
                let burst = esc.next_burst();
                let t = burst.t_ns as f64 * 1e-9;
                if t > seconds {
                    break;
                }
                if let Some(data) = burst.intact_data() {
                    let record = Record::new(Some(t), number as u8, &data, &settings);
                    samples.push(Sample::of(&record, samples.len()));
                }
            }
            EscSeries {
                esc: EscId {
                    number,
                    label: format!("esc {number}"),
                    position: format!("esc-{number}"),
                },
                recording: recording.to_string(),
                protocol: esc.protocol(),
                timed: true,
                link: None,
                maintenance_min: None,
                samples,
            }
        })
        .collect()
}

/// The warnings and critical findings of `findings`.
fn raised(findings: &[Finding]) -> Vec<&Finding> {
    findings
        .iter()
        .filter(|f| f.severity > Severity::Ok)
        .collect()
}

#[test]
fn two_hundred_healthy_simulated_flights_raise_no_warning() {
    let mut judged = 0;
    let mut trips = Vec::new();
    for i in 0..200 {
        let seconds = 20.0 + (i % 4) as f64 * 5.0;
        let series = fly(healthy(i), seconds, &format!("flight {i}"));
        let findings = analyse(&series, &CheckConfig::default(), None);
        for f in raised(&findings) {
            trips.push(format!(
                "flight {i}: {} ESC {}: {} ({:?})",
                f.analyser,
                f.esc.as_ref().map_or(0, |e| e.number),
                f.message,
                healthy(i)
            ));
        }
        judged += findings.len();
    }
    assert!(
        trips.is_empty(),
        "{} false trips:\n{}",
        trips.len(),
        trips.join("\n")
    );
    // Every analyser looked at them (no finding would pass the test too).
    assert!(judged > 200 * 3 * 6, "{judged} findings");
}

/// The airframe of the degradation tests: four ESCs on a staircase of throttle levels held 4 s
/// each, `degradations` applied, seed `seed`.
fn airframe(seed: u64, ambient_c: f64, degradations: Vec<DegradeSpec>) -> FleetSpec {
    FleetSpec::steps(
        4,
        seed,
        Shape {
            lead_in_s: 1.0,
            levels: vec![
                0.0, 30.0, 50.0, 70.0, 40.0, 60.0, 80.0, 50.0, 30.0, 60.0, 45.0, 0.0,
            ],
            hold_s: 4.0,
            period_s: 10.0,
            max_pct: 80.0,
        },
        ModelConfig {
            kv: 500.0,
            pole_pairs: 7,
            full_current_a: 60.0,
            cells: 6,
            battery_r_ohm: 0.02,
            capacity_mah: 16000.0,
            ambient_c,
            current_scale: 64.0,
        },
        degradations,
    )
}

/// ESC `esc` degraded by `kind` from `start_s` at `severity`.
fn degrade(esc: usize, kind: DegradeKind, start_s: f64, severity: f64) -> Vec<DegradeSpec> {
    vec![DegradeSpec {
        esc,
        kind,
        start_s,
        severity,
    }]
}

/// The seed of the degraded airframe: in the simulator a seed is an airframe (each ESC's share
/// of the load, its motor's and battery's tolerances are drawn from it).
const AIRFRAME: u64 = 11;

/// The baseline of three healthy flights of [`airframe`] [`AIRFRAME`], flown other ways than
/// the flights checked (a sine, a ramp, other levels).
fn baseline() -> Baseline {
    baseline_of(AIRFRAME)
}

/// The baseline of three healthy flights of [`airframe`] `seed` ([`baseline`]'s).
fn baseline_of(seed: u64) -> Baseline {
    let series: Vec<EscSeries> = [ProfileSpec::Sine, ProfileSpec::Ramp, ProfileSpec::Steps]
        .into_iter()
        .enumerate()
        .flat_map(|(i, profile)| {
            let mut spec = airframe(seed, 25.0, Vec::new());
            spec.profile = profile;
            spec.shape.levels = vec![0.0, 35.0, 55.0, 75.0, 45.0, 65.0, 85.0, 25.0, 0.0];
            spec.shape.period_s = 8.0;
            fly(spec, 50.0, &format!("healthy {i}"))
        })
        .collect();
    Baseline::fit(&series, None)
}

/// The warnings and critical findings of `analyser` on the degraded flight.
fn found(
    degradations: Vec<DegradeSpec>,
    seconds: f64,
    ambient_c: f64,
    baseline: Option<&Baseline>,
    analyser: Analyser,
) -> Vec<Finding> {
    let spec = airframe(AIRFRAME, ambient_c, degradations);
    found_in(spec, seconds, baseline, analyser)
}

/// The warnings and critical findings of `analyser` on the flight of `spec`.
fn found_in(
    spec: FleetSpec,
    seconds: f64,
    baseline: Option<&Baseline>,
    analyser: Analyser,
) -> Vec<Finding> {
    let series = fly(spec, seconds, "degraded");
    let findings = analyse(&series, &CheckConfig::default(), baseline);
    let all: Vec<Finding> = findings
        .into_iter()
        .filter(|f| f.analyser == analyser)
        .collect();
    all.into_iter()
        .filter(|f| f.severity > Severity::Ok)
        .collect()
}

/// Asserts that `findings` are about ESC `esc` alone, each window holding `start_s` (or
/// starting after it by less than `after_s`) and reaching past `until_s`.
fn on_esc_in_window(findings: &[Finding], esc: usize, start_s: f64, after_s: f64, until_s: f64) {
    assert!(!findings.is_empty(), "nothing found");
    for f in findings {
        assert_eq!(f.esc.as_ref().unwrap().number, esc, "{f:#?}");
        let w = f.window.expect("a window");
        assert!(
            w.start_s <= start_s + after_s && w.start_s >= start_s - 10.0,
            "{f:#?}"
        );
        assert!(w.end_s >= until_s, "{f:#?}");
    }
}

#[test]
fn a_worn_bearing_is_found_as_imbalance_and_as_drift_on_its_esc_from_when_it_starts() {
    let bearing = || degrade(2, DegradeKind::Bearing, 20.0, 0.5);
    let imbalance = found(bearing(), 50.0, 25.0, None, Analyser::Imbalance);
    on_esc_in_window(&imbalance, 2, 20.0, 5.0, 45.0);
    let baseline = baseline();
    let drift = found(bearing(), 50.0, 25.0, Some(&baseline), Analyser::Drift);
    on_esc_in_window(&drift, 2, 20.0, 5.0, 45.0);
    assert!(
        drift
            .iter()
            .all(|f| f.threshold.as_ref().unwrap().name == "current_per_rpm")
    );
    // Healthy, the same airframe drifts from nothing.
    assert!(found(Vec::new(), 50.0, 25.0, Some(&baseline), Analyser::Drift).is_empty());
}

#[test]
fn a_damaged_prop_is_found_as_imbalance_and_as_drift_on_its_esc_from_when_it_starts() {
    let prop = || degrade(1, DegradeKind::Prop, 15.0, 1.0);
    let imbalance = found(prop(), 50.0, 25.0, None, Analyser::Imbalance);
    on_esc_in_window(&imbalance, 1, 15.0, 5.0, 45.0);
    let drift = found(prop(), 50.0, 25.0, Some(&baseline()), Analyser::Drift);
    on_esc_in_window(&drift, 1, 15.0, 5.0, 45.0);
    assert!(
        drift
            .iter()
            .all(|f| f.threshold.as_ref().unwrap().name == "rpm_per_throttle")
    );
}

/// [`airframe`] [`AIRFRAME`] flying a sine of throttle (8 s a cycle, up to 80 %): the throttle
/// never holds, as in a real flight.
fn sine(degradations: Vec<DegradeSpec>) -> FleetSpec {
    let mut spec = airframe(AIRFRAME, 25.0, degradations);
    spec.profile = ProfileSpec::Sine;
    spec.shape.period_s = 8.0;
    spec
}

#[test]
fn a_damaged_prop_is_found_as_imbalance_while_the_throttle_moves() {
    let prop = degrade(1, DegradeKind::Prop, 15.0, 1.0);
    let imbalance = found_in(sine(prop), 50.0, None, Analyser::Imbalance);
    on_esc_in_window(&imbalance, 1, 15.0, 5.0, 45.0);
    // Healthy, the same moving flight is balanced.
    let healthy = found_in(sine(Vec::new()), 50.0, None, Analyser::Imbalance);
    assert!(healthy.is_empty(), "{healthy:#?}");
}

#[test]
fn a_weak_battery_is_found_against_the_baseline_on_its_esc() {
    let baseline = baseline();
    let weak = found(
        degrade(3, DegradeKind::Battery, 0.0, 0.5),
        50.0,
        25.0,
        Some(&baseline),
        Analyser::Battery,
    );
    assert_eq!(weak.len(), 1, "{weak:#?}");
    assert_eq!(weak[0].esc.as_ref().unwrap().number, 3);
    assert_eq!(weak[0].threshold.as_ref().unwrap().name, "resistance_rise");
    assert!(found(Vec::new(), 50.0, 25.0, Some(&baseline), Analyser::Battery).is_empty());
}

#[test]
fn a_loose_telemetry_wire_is_found_as_a_burst_of_loss_on_its_esc_when_it_starts() {
    let wire = found(
        degrade(0, DegradeKind::Wire, 25.0, 0.5),
        50.0,
        25.0,
        None,
        Analyser::Link,
    );
    on_esc_in_window(&wire, 0, 25.0, 5.0, 30.0);
}

#[test]
fn a_slow_heat_build_up_is_found_on_its_esc_when_it_crosses_the_limit() {
    let heat = found(
        degrade(1, DegradeKind::Heat, 0.0, 1.0),
        600.0,
        60.0,
        None,
        Analyser::Heat,
    );
    assert!(!heat.is_empty());
    for f in &heat {
        assert_eq!(f.esc.as_ref().unwrap().number, 1, "{f:#?}");
        assert!(f.window.unwrap().start_s > 120.0, "{f:#?}");
    }
}

/// Simulates four ESCs of seed `seed` for 40 s into `dir/name` (a pcapng, or a candump log:
/// `.log`), with `more` options (`--degrade`, `--protocol`).
fn simulate(dir: &Dir, name: &str, seed: u64, more: &[&str]) -> String {
    let path = dir.arg(name);
    let seed = seed.to_string();
    let mut args = vec![
        "simulate",
        "--escs",
        "4",
        "--seed",
        &seed,
        "--levels",
        "0,30,50,70,40,60,80,50,0",
        "--hold",
        "4",
        "--duration",
        "40",
        "-o",
        &path,
    ];
    args.extend_from_slice(more);
    let out = run(hwfoc().args(&args));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    path
}

/// `hwfoc check --json ARGS`: its exit status and its report.
fn check_json(args: &[&str]) -> (i32, Value) {
    let out = run(hwfoc().args(["check", "--json", "--no-config"]).args(args));
    let report = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
    (out.status.code().unwrap(), report)
}

/// The findings of `report` above ok: (analyser, ESC number).
fn raised_in(report: &Value) -> Vec<(String, u64)> {
    report["findings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["severity"] != "ok")
        .map(|f| {
            (
                f["analyser"].as_str().unwrap().to_string(),
                f["esc"]["number"].as_u64().unwrap(),
            )
        })
        .collect()
}

#[test]
fn the_command_exits_0_on_a_healthy_flight_and_2_on_a_loose_wire_with_json_evidence() {
    let dir = Dir::new();
    let healthy = simulate(&dir, "healthy.pcapng", 5, &[]);
    let (code, report) = check_json(&[&healthy]);
    assert_eq!(code, 0, "{report:#}");
    let first = report.as_object().unwrap().keys().next().unwrap().clone();
    assert_eq!(first, "schema_version");
    assert_eq!(report["worst"], "ok");
    let findings = report["findings"].as_array().unwrap();
    for analyser in ["heat", "imbalance", "battery", "faults", "link", "runtime"] {
        assert!(
            findings.iter().any(|f| f["analyser"] == analyser),
            "{analyser}: {report:#}"
        );
    }
    let loose = simulate(&dir, "loose.pcapng", 5, &["--degrade", "0:wire@10=0.5"]);
    let (code, report) = check_json(&[&loose]);
    assert_eq!(code, 2, "{report:#}");
    assert_eq!(raised_in(&report), [("link".to_string(), 0)], "{report:#}");
    let link = &report["findings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["severity"] != "ok")
        .unwrap();
    assert!(
        link["threshold"]["value"].as_f64().is_some()
            && link["window"]["start_s"].as_f64().is_some()
    );
    // The text says it too.
    let text = run(hwfoc().args(["check", "--no-config", &loose]));
    assert_eq!(text.status.code(), Some(2));
    let text = String::from_utf8(text.stdout).unwrap();
    assert!(
        text.contains("CRITICAL  link") && text.contains("(exit 2)"),
        "{text}"
    );
}

#[test]
fn a_baseline_fitted_from_healthy_flights_finds_a_worn_bearing_as_drift() {
    let dir = Dir::new();
    // One airframe (a seed, in the simulator), flown other ways than the flights checked.
    let a = simulate(&dir, "a.pcapng", 3, &["--profile", "sine", "--period", "8"]);
    let b = simulate(&dir, "b.pcapng", 3, &["--levels", "0,35,55,75,25,0"]);
    let base = dir.arg("airframe.toml");
    let fit = run(hwfoc().args([
        "check",
        "--no-config",
        "--fit-baseline",
        &a,
        &b,
        "-o",
        &base,
    ]));
    assert!(
        fit.status.success(),
        "{}",
        String::from_utf8_lossy(&fit.stderr)
    );
    assert!(fit.stdout.is_empty());
    let toml = std::fs::read_to_string(&base).unwrap();
    assert!(
        toml.contains("recordings = 2") && toml.contains("[esc.esc-3.rpm_by_throttle]"),
        "{toml}"
    );
    // A third healthy flight is within it; a worn bearing is not.
    let c = simulate(&dir, "c.pcapng", 3, &[]);
    let (code, report) = check_json(&["--baseline", &base, &c]);
    assert_eq!(code, 0, "{report:#}");
    let worn = simulate(&dir, "worn.pcapng", 3, &["--degrade", "2:bearing@10=0.5"]);
    let (code, report) = check_json(&["--baseline", &base, &worn]);
    assert!(code >= 1, "{report:#}");
    let raised = raised_in(&report);
    assert!(raised.contains(&("drift".to_string(), 2)), "{report:#}");
    assert!(raised.iter().all(|(_, esc)| *esc == 2), "{report:#}");
}

#[test]
fn thresholds_come_from_the_configuration_files_check_table() {
    let dir = Dir::new();
    let flight = simulate(&dir, "f.pcapng", 4, &[]);
    let config = dir.path("config.toml");
    std::fs::write(
        &config,
        "[check.heat]\nmos_c = { warn = 20.0, critical = 200.0 }\n",
    )
    .unwrap();
    let out = run(hwfoc().args([
        "check",
        "--json",
        "--config",
        config.to_str().unwrap(),
        &flight,
    ]));
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // A key that is not a threshold is an error naming the file and the line.
    std::fs::write(&config, "[check.heat]\nmos = 3\n").unwrap();
    let out = run(hwfoc().args(["check", "--config", config.to_str().unwrap(), &flight]));
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with("hwfoc: ") && err.contains("line 2"),
        "{err}"
    );
}

#[test]
fn an_input_error_exits_1_with_no_report() {
    let out = run(hwfoc().args(["check", "--no-config", "/nonexistent/flight.pcapng"]));
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    assert!(String::from_utf8_lossy(&out.stderr).starts_with("hwfoc: "));
}

#[test]
fn check_plot_shades_the_windows_of_its_findings() {
    let dir = Dir::new();
    let loose = simulate(&dir, "loose.pcapng", 6, &["--degrade", "1:wire@10=0.5"]);
    let svg = dir.arg("check.svg");
    let out = run(hwfoc().args(["check", "--no-config", &loose, "--plot", &svg]));
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let image = std::fs::read_to_string(&svg).unwrap();
    assert!(image.contains("critical link"), "no label of the finding");
    // Without findings, nothing is shaded.
    let healthy = simulate(&dir, "healthy.pcapng", 6, &[]);
    let svg = dir.arg("healthy.svg");
    let out = run(hwfoc().args(["check", "--no-config", &healthy, "--plot", &svg]));
    assert_eq!(out.status.code(), Some(0));
    assert!(
        !std::fs::read_to_string(&svg)
            .unwrap()
            .contains("critical link")
    );
}

#[test]
fn plot_check_shades_the_same_windows() {
    let dir = Dir::new();
    let loose = simulate(&dir, "loose.pcapng", 6, &["--degrade", "1:wire@10=0.5"]);
    let (plain, shaded) = (dir.arg("plain.svg"), dir.arg("shaded.svg"));
    let out = run(hwfoc().args(["plot", "--no-config", &loose, "-o", &plain]));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = run(hwfoc().args(["plot", "--no-config", &loose, "-o", &shaded, "--check"]));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        !std::fs::read_to_string(&plain)
            .unwrap()
            .contains("critical link")
    );
    let image = std::fs::read_to_string(&shaded).unwrap();
    assert!(image.contains("critical link"), "no label of the finding");
    // A baseline needs --check.
    let out = run(hwfoc().args([
        "plot",
        &loose,
        "-o",
        &dir.arg("x.svg"),
        "--baseline",
        "b.toml",
    ]));
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Every recording and capture in `testdata/` that `hwfoc check` reads.
fn testdata() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testdata");
    ["captures", "recordings", "dronecan"]
        .iter()
        .flat_map(|d| std::fs::read_dir(root.join(d)).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| !p.to_str().unwrap().ends_with(".md") && !p.ends_with("vectors.txt"))
        .collect()
}

#[test]
fn the_real_captures_give_no_finding_the_capture_does_not_show() {
    let mut read = 0;
    for path in testdata() {
        let name = path.to_str().unwrap();
        let out = run(hwfoc().args(["check", "--json", "--no-config", name]));
        let Ok(report) = serde_json::from_slice::<Value>(&out.stdout) else {
            continue; // no data frame in it
        };
        read += 1;
        let summary: Value = serde_json::from_slice(
            &run(hwfoc().args(["summary", "--json", "--no-config", name])).stdout,
        )
        .unwrap();
        let esc = |n: u64| {
            summary["escs"]
                .as_array()
                .unwrap()
                .iter()
                .find(|e| e["esc"] == n)
                .unwrap_or_else(|| panic!("{name}: no ESC {n} in the summary"))
                .clone()
        };
        for (analyser, n) in raised_in(&report) {
            let e = esc(n);
            let shown = match analyser.as_str() {
                // The summary lists the fault episodes found.
                "faults" => e["fault_episode_count"].as_u64().unwrap() > 0,
                // The summary counts the packets lost and the checksums failed.
                "link" => {
                    e["link"]["lost_packets"].as_u64().unwrap() > 0
                        || e["link"]["checksum_failures"].as_u64().unwrap() > 0
                }
                _ => false,
            };
            assert!(
                shown,
                "{name}: ESC {n}: {analyser} not shown by the capture: {report:#}"
            );
        }
    }
    assert!(read >= 8, "only {read} captures read");
}

#[test]
fn a_can_esc_s_maintenance_answer_in_its_recording_is_judged_against_the_service_interval() {
    use hwfoc::dronecan::{GetMaintenanceInformationResponse, Message};
    let dir = Dir::new();
    let path = simulate(&dir, "bus.log", 1, &["--protocol", "hw-can"]);
    // Node 11 (ESC 1) answers a GetMaintenanceInformation request, as on a bus where `hwfoc
    // can list` asked: 150 h turned, 55 h (3300 min) since its last maintenance.
    let mut log = std::fs::read_to_string(&path).unwrap();
    let last_line = log.lines().last().unwrap();
    let last: f64 = last_line[1..last_line.find(')').unwrap()].parse().unwrap();
    let answer = Message::from(GetMaintenanceInformationResponse {
        total_rotation_time_min: 9000,
        time_since_maintenance_min: 3300,
    });
    for frame in answer.frames(24, 11, 127, 0) {
        hwfoc_ports::can::candump::push_line(&mut log, last + 0.001, "can0", &frame);
    }
    std::fs::write(&path, log).unwrap();
    let (code, report) = check_json(&[&path]);
    assert_eq!(code, 1, "{report:#}");
    assert_eq!(raised_in(&report), [("runtime".to_string(), 1)]);
    let runtime: Vec<&Value> = report["findings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["analyser"] == "runtime")
        .collect();
    assert_eq!(runtime.len(), 4, "{report:#}");
    let f = runtime.iter().find(|f| f["severity"] == "warning").unwrap();
    assert!(
        f["esc"]["label"].as_str().unwrap().contains("node 11"),
        "{f:#}"
    );
    let value = |name: &str| {
        f["values"]
            .as_array()
            .unwrap()
            .iter()
            .find(|v| v["name"] == name)
            .unwrap_or_else(|| panic!("{name}: {f:#}"))["value"]
            .as_f64()
            .unwrap()
    };
    assert_eq!(value("hours_since_service"), 55.0);
    assert_eq!(value("esc_total_rotation"), 150.0);
    assert_eq!(f["threshold"]["value"], 50.0, "{f:#}");
}

#[test]
fn a_damaged_prop_flags_its_esc_alone_not_a_healthy_sibling_beside_it() {
    // Airframe 15: ESC 1's damaged prop draws less current, and with ESC 1 in the siblings'
    // median ESC 3's healthy current looked 41 % above its siblings'.
    let spec = airframe(15, 25.0, degrade(1, DegradeKind::Prop, 15.0, 1.0));
    let imbalance = found_in(spec, 50.0, None, Analyser::Imbalance);
    on_esc_in_window(&imbalance, 1, 15.0, 5.0, 45.0);
}

/// The rows of docs/CHECKS.md's detection table: the analyser, the degradation, whether the
/// flight is a sine of throttle (8 s a cycle) rather than the staircase, and the airframes (of
/// 20) it is found on.
const MEASURED: [(Analyser, &str, bool, usize); 8] = [
    (Analyser::Imbalance, "2:bearing@20=0.5", false, 13),
    (Analyser::Imbalance, "1:prop@15=1", false, 20),
    (Analyser::Imbalance, "1:prop@15=1", true, 20),
    (Analyser::Imbalance, "2:bearing@15=0.5", true, 12),
    (Analyser::Drift, "2:bearing@20=0.5", false, 20),
    (Analyser::Drift, "1:prop@15=1", false, 20),
    (Analyser::Battery, "3:battery@0=0.5", false, 17),
    (Analyser::Link, "0:wire@25=0.5", false, 20),
];

#[test]
fn detection_over_twenty_airframes() {
    let mut rows = Vec::new();
    let mut failed = false;
    for (analyser, degradation, sine, documented) in MEASURED {
        let spec: DegradeSpec = degradation.parse().unwrap();
        let (mut found, mut missed, mut other, mut trips) = (0, Vec::new(), Vec::new(), 0);
        for seed in 1..=20 {
            let flight = |degradations: Vec<DegradeSpec>| {
                let mut flight = airframe(seed, 25.0, degradations);
                if sine {
                    flight.profile = ProfileSpec::Sine;
                    flight.shape.period_s = 8.0;
                }
                flight
            };
            let base =
                matches!(analyser, Analyser::Drift | Analyser::Battery).then(|| baseline_of(seed));
            let raised = found_in(flight(vec![spec]), 50.0, base.as_ref(), analyser);
            let number = |f: &Finding| f.esc.as_ref().unwrap().number;
            if raised.iter().any(|f| number(f) == spec.esc) {
                found += 1;
            } else {
                missed.push(seed);
            }
            other.extend(
                raised
                    .iter()
                    .filter(|f| number(f) != spec.esc)
                    .map(|f| format!("airframe {seed} ESC {}: {}", number(f), f.message)),
            );
            if !found_in(flight(Vec::new()), 50.0, base.as_ref(), analyser).is_empty() {
                trips += 1;
            }
        }
        failed |= found < documented || !other.is_empty() || trips > 0;
        rows.push(format!(
            "{analyser} {degradation} {}: found {found}/20 (missed {missed:?}), \
             other ESC {other:?}, healthy trips {trips}/20",
            if sine { "sine" } else { "steps" }
        ));
    }
    println!("{}", rows.join("\n"));
    assert!(!failed, "{}", rows.join("\n"));
}
