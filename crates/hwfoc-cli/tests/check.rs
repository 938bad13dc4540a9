//! `hwfoc check`: the analysers on simulated flights (healthy ones give no warning, faulty ones
//! are found on the right ESC in the right window), on the real captures of `testdata/`, and the
//! command's output and exit status.

mod common;

use hwfoc::{Protocol, Settings};
use hwfoc_io::Record;
use hwfoc_io::check::{CheckConfig, EscId, EscSeries, Finding, Sample, Severity, analyse};
use hwfoc_sim::faults::LinkRates;
use hwfoc_sim::fleet::FleetSpec;
use hwfoc_sim::model::ModelConfig;
use hwfoc_sim::profile::{ProfileSpec, Shape};

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
    FleetSpec {
        n: 3 + (i % 6) as usize,
        seed: 1000 + i,
        protocol: Protocol::HwFoc,
        baud: 19200,
        start_packet: None,
        profile,
        shape: Shape {
            lead_in_s: d.between(0.5, 3.0),
            levels: [vec![0.0], levels, vec![0.0]].concat(),
            hold_s: d.between(1.0, 5.0),
            period_s: d.between(4.0, 15.0),
            max_pct: d.between(40.0, 100.0),
        },
        model: ModelConfig {
            kv: d.between(300.0, 1500.0),
            pole_pairs: 7,
            full_current_a: d.between(15.0, 90.0),
            cells: [4, 6, 6, 12][(i % 4) as usize],
            battery_r_ohm: d.between(0.005, 0.03),
            capacity_mah: d.between(3000.0, 16000.0),
            ambient_c: d.between(5.0, 40.0),
            current_scale: 64.0,
        },
        faults: Vec::new(),
        link: LinkRates::default(),
    }
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
                },
                recording: recording.to_string(),
                protocol: esc.protocol(),
                timed: true,
                link: None,
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
