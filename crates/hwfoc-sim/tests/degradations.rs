//! Each degradation of the simulator's model shows its physical effect in the frames the ESC
//! sends, on the degraded ESC only and from its start on: a run with the degradation is
//! compared frame by frame with the same run (same seed) without it.

use hwfoc::foc::DataFrame;
use hwfoc::{Protocol, Temperature};
use hwfoc_sim::FleetSpec;
use hwfoc_sim::degrade::DegradeSpec;
use hwfoc_sim::model::ModelConfig;
use hwfoc_sim::profile::Shape;

/// Two ESCs, throttle stepping between 30 % and 70 % every 3 s after a 1 s lead-in.
fn spec(degradations: &[&str]) -> FleetSpec {
    FleetSpec::steps(
        2,
        11,
        Shape {
            lead_in_s: 1.0,
            levels: vec![30.0, 70.0],
            hold_s: 3.0,
            period_s: 10.0,
            max_pct: 80.0,
        },
        ModelConfig {
            capacity_mah: 50_000.0,
            ..ModelConfig::SIMULATE
        },
        degradations.iter().map(|d| d.parse().unwrap()).collect(),
    )
}

/// The frames each ESC delivers intact in `seconds`, with their times (s).
fn run(spec: FleetSpec, seconds: f64) -> Vec<Vec<(f64, DataFrame)>> {
    let escs = spec.build().unwrap().escs();
    escs.into_iter()
        .map(|mut esc| {
            let mut frames = Vec::new();
            loop {
                let burst = esc.next_burst();
                let t = burst.t_ns as f64 * 1e-9;
                if t > seconds {
                    break frames;
                }
                if let Some(f) = burst.intact_frame() {
                    frames.push((t, *f));
                }
            }
        })
        .collect()
}

/// Pairs of (healthy, degraded) frames of one ESC sent at the same time in `window` (s), both
/// runs' motors turning.
fn pairs<'a>(
    healthy: &'a [(f64, DataFrame)],
    degraded: &'a [(f64, DataFrame)],
    window: (f64, f64),
) -> Vec<(&'a DataFrame, &'a DataFrame)> {
    healthy
        .iter()
        .zip(degraded)
        .filter(|((t, a), (u, b))| {
            assert_eq!(t, u, "the runs' frames keep their times");
            *t >= window.0 && *t < window.1 && a.erpm_raw > 0 && b.erpm_raw > 0
        })
        .map(|((_, a), (_, b))| (a, b))
        .collect()
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0.0), |(s, n), v| (s + v, n + 1.0));
    sum / n
}

/// Ratio degraded / healthy of the means of `value` over the pairs.
fn ratio(pairs: &[(&DataFrame, &DataFrame)], value: impl Fn(&DataFrame) -> f64) -> f64 {
    mean(pairs.iter().map(|(_, b)| value(b))) / mean(pairs.iter().map(|(a, _)| value(a)))
}

/// Standard deviation of the ratio degraded / healthy of the current.
fn scatter(pairs: &[(&DataFrame, &DataFrame)]) -> f64 {
    let ratios: Vec<f64> = pairs
        .iter()
        .filter(|(a, _)| amps(a) > 5.0)
        .map(|(a, b)| amps(b) / amps(a))
        .collect();
    let m = mean(ratios.iter().copied());
    mean(ratios.iter().map(|r| (r - m).powi(2))).sqrt()
}

fn amps(f: &DataFrame) -> f64 {
    f64::from(f.current_raw) / 64.0
}

fn erpm(f: &DataFrame) -> f64 {
    f64::from(f.erpm_raw)
}

fn volts(f: &DataFrame) -> f64 {
    f64::from(f.voltage_raw) / 10.0
}

fn mos_c(f: &DataFrame) -> f64 {
    f64::from(Temperature::from_adc(f.mos_adc).celsius().unwrap())
}

/// The runs with and without `degradation`, each ESC's frames.
fn compare(degradation: &str, seconds: f64) -> [Vec<Vec<(f64, DataFrame)>>; 2] {
    [run(spec(&[]), seconds), run(spec(&[degradation]), seconds)]
}

/// ESC 0 and, before `start_s`, ESC 1 send exactly the frames of the healthy run.
fn untouched_elsewhere(runs: &[Vec<Vec<(f64, DataFrame)>>; 2], start_s: f64) {
    assert_eq!(runs[0][0], runs[1][0], "ESC 0 is not degraded");
    let before = |frames: &[(f64, DataFrame)]| {
        frames
            .iter()
            .filter(|(t, _)| *t < start_s)
            .copied()
            .collect::<Vec<_>>()
    };
    assert_eq!(before(&runs[0][1]), before(&runs[1][1]));
}

#[test]
fn bearing_needs_more_current_for_the_same_rpm() {
    let runs = compare("1:bearing@8=0.4", 20.0);
    untouched_elsewhere(&runs, 8.0);
    let after = pairs(&runs[0][1], &runs[1][1], (8.5, 20.0));
    let current = ratio(&after, amps);
    let rpm = ratio(&after, erpm);
    assert!((1.35..1.45).contains(&current), "current x {current}");
    assert!((0.97..1.01).contains(&rpm), "rpm x {rpm}");
    // Current per rpm: up by the severity's share.
    let per_rpm = ratio(&after, |f| amps(f) / erpm(f));
    assert!(
        (1.36..1.48).contains(&per_rpm),
        "current per rpm x {per_rpm}"
    );
}

#[test]
fn damaged_prop_turns_faster_on_less_current_with_a_ripple() {
    let runs = compare("1:prop@8=1", 20.0);
    untouched_elsewhere(&runs, 8.0);
    let after = pairs(&runs[0][1], &runs[1][1], (8.5, 20.0));
    let rpm = ratio(&after, erpm);
    let current = ratio(&after, amps);
    assert!((1.17..1.23).contains(&rpm), "rpm x {rpm}");
    assert!((0.8..0.9).contains(&current), "current x {current}");
    // The ripple: the frame-to-frame scatter of the current against the healthy run's, well
    // above that of a steady change of current (a bearing's), which is the sensor noise alone.
    let bearing = compare("1:bearing@8=0.4", 20.0);
    let steady = pairs(&bearing[0][1], &bearing[1][1], (8.5, 20.0));
    let ripple = scatter(&after);
    let noise = scatter(&steady);
    assert!(
        ripple > 0.04 && ripple > 2.0 * noise,
        "ripple {ripple}, noise {noise}"
    );
}

#[test]
fn weak_battery_sags_more_per_ampere() {
    let runs = compare("1:battery@8=1", 20.0);
    untouched_elsewhere(&runs, 8.0);
    // Sag per ampere: the slope of voltage against current across the steps.
    let slope = |frames: &[(f64, DataFrame)]| {
        let loaded: Vec<(f64, f64)> = frames
            .iter()
            .filter(|(t, f)| *t >= 8.5 && f.erpm_raw > 0)
            .map(|(_, f)| (amps(f), volts(f)))
            .collect();
        let mx = mean(loaded.iter().map(|p| p.0));
        let my = mean(loaded.iter().map(|p| p.1));
        let sxy: f64 = loaded.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
        let sxx: f64 = loaded.iter().map(|(x, _)| (x - mx).powi(2)).sum();
        -sxy / sxx
    };
    let healthy = slope(&runs[0][1]);
    let weak = slope(&runs[1][1]);
    assert!(healthy > 0.0, "{healthy}");
    let factor = weak / healthy;
    assert!(
        (1.6..2.4).contains(&factor),
        "sag per A x {factor}: {healthy} -> {weak}"
    );
}

#[test]
fn loose_wire_loses_bursts_of_frames_not_the_model() {
    let runs = compare("1:wire@8=0.5", 20.0);
    untouched_elsewhere(&runs, 8.0);
    let healthy = &runs[0][1];
    let loose = &runs[1][1];
    // Every frame delivered is the healthy run's frame (the model is untouched), some are lost.
    assert!(loose.iter().all(|f| healthy.contains(f)));
    let lost = healthy.len() - loose.len();
    let sent_after = healthy.iter().filter(|(t, _)| *t >= 8.0).count();
    assert!(
        lost * 100 > sent_after * 20 && lost * 100 < sent_after * 60,
        "{lost} of {sent_after} lost"
    );
    // In bursts: the packet numbers jump by 6 or more.
    let gaps: Vec<u16> = loose
        .windows(2)
        .map(|w| w[1].1.packet.wrapping_sub(w[0].1.packet))
        .filter(|&g| g > 1)
        .collect();
    assert!(!gaps.is_empty() && gaps.iter().all(|&g| g >= 6), "{gaps:?}");
}

#[test]
fn heat_builds_up_over_minutes() {
    let runs = compare("1:heat@10=1", 130.0);
    untouched_elsewhere(&runs, 10.0);
    let rise = |from: f64, to: f64| {
        mean(
            pairs(&runs[0][1], &runs[1][1], (from, to))
                .iter()
                .map(|(a, b)| mos_c(b) - mos_c(a)),
        )
    };
    let early = rise(10.0, 20.0);
    let late = rise(120.0, 130.0);
    // 80 K over 600 s: 16 K after 120 s, less the MOSFETs' 20 s lag.
    assert!(early < 1.0, "{early}");
    assert!((11.0..17.0).contains(&late), "{late}");
    // Rising steadily: the middle lies between.
    let middle = rise(65.0, 75.0);
    assert!(early < middle && middle < late, "{early} {middle} {late}");
}

#[test]
fn degradations_are_checked_against_the_fleet() {
    let e = spec(&["2:heat"]).build().unwrap_err().to_string();
    assert_eq!(
        e,
        "a degradation (heat) is on ESC 2, which does not exist: there are 2 (0..1)"
    );
    let mut s = spec(&["0:wire"]);
    s.protocol = Protocol::HwV3;
    assert_eq!(
        s.build().unwrap_err().to_string(),
        "a loose wire (bursts of lost frames) is simulated for HW-FOC only, not for Hobbywing V3 \
         (hw-v3)"
    );
    let d: DegradeSpec = "0:heat@3".parse().unwrap();
    assert_eq!(d.start_s, 3.0);
}
