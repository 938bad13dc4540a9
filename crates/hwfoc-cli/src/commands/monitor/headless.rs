//! `--plain` and `--json`: the monitor without a screen, for a Raspberry Pi on a drone or a test
//! bench. One line per ESC per interval, and every alarm the moment it is raised, escalated or
//! cleared. Memory stays bounded, so it can run for days; each batch of lines is flushed at once,
//! so `tail -f` and pipes see it live.

use std::io::{self, Write};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

use super::fleet::{EscView, Fleet, Link, LogEntry};
use super::{Session, number, reading};
use crate::error::CliError;
use crate::shown::Shown;
use hwfoc::Quantity;
use hwfoc_io::Escaped;
use hwfoc_io::Fixed;
use hwfoc_io::energy::Energy;
use hwfoc_io::record::Record;
use hwfoc_io::write::WriteError;

/// The longest an alarm waits before it is printed.
const BATCH: Duration = Duration::from_millis(100);

/// Runs the headless monitor until it is stopped.
pub fn run(session: &mut Session, json: bool, interval_s: f64) -> Result<(), CliError> {
    let interval = Duration::from_secs_f64(interval_s);
    let mut out = io::stdout().lock();
    let mut seen = 0;
    let mut next_status = Instant::now() + interval;
    let mut text = Vec::new();
    while !session.should_stop() {
        // Wake a few times a second and take in everything that came, rather than for every
        // chunk of every port: an alarm is printed at most that much later.
        let wait = next_status.saturating_duration_since(Instant::now());
        std::thread::sleep(wait.min(BATCH));
        session.pump(Duration::ZERO)?;
        let now = session.now();
        for entry in session.fleet.log_since(seen) {
            let esc = &session.fleet.escs[entry.esc];
            if json {
                writeln!(text, "{}", alarm_json(entry, esc)).ok();
            } else {
                writeln!(text, "{}", alarm_line(entry, esc)).ok();
            }
        }
        seen = session.fleet.logged;
        if Instant::now() >= next_status {
            for esc in &session.fleet.escs {
                if json {
                    writeln!(text, "{}", status_json(esc, now)).ok();
                } else {
                    writeln!(text, "{}", status_line(esc, now)).ok();
                }
            }
            // All ESCs together, when there are several.
            let fleet = &session.fleet;
            let total = match (fleet.escs.len() > 1, json) {
                (false, _) => None,
                (true, true) => Some(total_json(fleet, now).to_string()),
                (true, false) => Some(total_line(fleet, now)),
            };
            if let Some(total) = total {
                writeln!(text, "{total}").ok();
            }
            // Skip intervals missed (a suspended machine) rather than printing a burst: the next
            // status is due one interval after the last one due, counted without a loop.
            let late = Instant::now().saturating_duration_since(next_status);
            let missed = (late.as_secs_f64() / interval.as_secs_f64()).floor();
            next_status += interval.mul_f64(missed + 1.0);
        }
        if let Some(notice) = session.notice.take() {
            eprintln!("hwfoc: {}", Escaped(&notice));
        }
        for found in session.found.drain(..) {
            eprintln!("{}", found.line());
        }
        if !text.is_empty() {
            out.write_all(&text)
                .and_then(|()| out.flush())
                .map_err(|source| WriteError::Write {
                    output: "standard output".into(),
                    source,
                })?;
            text.clear();
        }
    }
    Ok(())
}

/// Local time with its UTC offset and milliseconds: `2026-11-22T14:03:22.150+01:00`.
pub fn timestamp(t: f64) -> String {
    super::iso8601(t, true)
}

/// `power 480 W (peak 1210 W) used 312.5 mAh 7.41 Wh`: power now (`-` without a frame), the
/// peak, charge and energy since the start or the last reset.
fn energy_text(power_w: Option<f64>, peak_w: Option<f64>, energy: &Energy) -> String {
    let w = |p: Option<f64>| p.map_or("-".to_string(), |p| format!("{} W", Fixed(p, 0)));
    format!(
        "power {} (peak {}) used {} mAh {} Wh",
        w(power_w),
        w(peak_w),
        Fixed(energy.charge_mah(), 1),
        Fixed(energy.energy_wh(), 2)
    )
}

fn energy_json(power_w: Option<f64>, peak_w: Option<f64>, energy: &Energy) -> Value {
    json!({
        "power_w": power_w,
        "peak_power_w": peak_w,
        "charge_mah": energy.charge_mah(),
        "energy_wh": energy.energy_wh(),
    })
}

/// `2026-… total: power 960 W (peak 1210 W) used 625.0 mAh 14.82 Wh`: all ESCs together (the
/// peak is the highest sum of their powers).
fn total_line(fleet: &Fleet, now: f64) -> String {
    format!(
        "{} total: {}",
        timestamp(now),
        energy_text(
            fleet.total_power_w(),
            fleet.peak_total_w,
            &fleet.total_energy()
        )
    )
}

fn total_json(fleet: &Fleet, now: f64) -> Value {
    json!({
        "schema_version": hwfoc_io::JSON_SCHEMA_VERSION,
        "type": "total",
        "time": timestamp(now),
        "t_s": now,
        "escs": fleet.escs.len(),
        "energy": energy_json(fleet.total_power_w(), fleet.peak_total_w, &fleet.total_energy()),
    })
}

/// `2026-… esc0 /dev/ttyUSB0: thr 50.0/48.2 % 12000 rpm 24.1 V 20.3 A (phase 35.1 A) mos
/// 45.0C cap 40.0C | 19200 baud (HW-FOC) 20.0 fr/s lost 0 dup 0 crc 0 restarts 0 | age 0.03 s |
/// power 489 W (peak 520 W) used 12.5 mAh 0.30 Wh | ok`: the figures the ESC's format has
/// (see [`EscView::carries`], [`EscView::link_text`]), HW5's BEC and motor ones too.
pub(super) fn status_line(esc: &EscView, now: f64) -> String {
    let mut line = format!(
        "{} esc{} {}: ",
        timestamp(now),
        esc.number,
        Escaped(esc.title())
    );
    match (&esc.link, &esc.last) {
        (Link::Down { since, reason }, _) => {
            line.push_str(&format!("disconnected for {:.1} s ({reason})", now - since));
        }
        (Link::Up, None) => line.push_str(&format!("{} ({})", esc.waiting(), esc.rate_text())),
        (Link::Up, Some(r)) => {
            let temp = |t: Option<f32>| t.map_or("-".to_string(), |t| format!("{}C", number(t, 1)));
            let has = |q: Quantity| esc.carries(Shown::Carried(q));
            let mut parts: Vec<String> = Vec::new();
            if has(Quantity::ThrottleIn) {
                parts.push(format!(
                    "thr {}/{} %",
                    reading(r.throttle_in_pct, 1),
                    reading(r.throttle_out_pct, 1)
                ));
            }
            if has(Quantity::Rpm) {
                parts.push(format!("{} rpm", reading(r.rpm, 0)));
            }
            if has(Quantity::Voltage) {
                parts.push(format!("{} V", reading(r.voltage_v, 1)));
            }
            if has(Quantity::Current) {
                parts.push(format!("{} A", reading(r.current_a, 1)));
            }
            if has(Quantity::PhaseCurrent) {
                parts.push(format!("(phase {} A)", reading(r.phase_current_a, 1)));
            }
            if has(Quantity::MosTemp) {
                parts.push(format!("mos {}", temp(r.mos_temp_c)));
            }
            if has(Quantity::CapTemp) {
                parts.push(format!("cap {}", temp(r.cap_temp_c)));
            }
            if has(Quantity::BecVoltage) {
                parts.push(format!(
                    "bec {} V {} A {}",
                    reading(r.bec_voltage_v, 1),
                    reading(r.bec_current_a, 1),
                    temp(r.bec_temp_c)
                ));
            }
            if has(Quantity::MotorTemp) {
                parts.push(format!("motor {}", temp(r.motor_temp_c)));
            }
            line.push_str(&parts.join(" "));
            line.push_str(&format!(
                " | {} {:.1} fr/s {} | age {:.2} s",
                esc.rate_text(),
                esc.frame_rate(now),
                esc.link_text(),
                esc.age(now).unwrap_or(0.0),
            ));
            line.push_str(" | ");
            line.push_str(&energy_text(
                esc.power_w(),
                esc.energy.peak_w(),
                &esc.energy,
            ));
        }
    }
    let active = esc.alarms.active();
    if active.is_empty() {
        line.push_str(" | ok");
    } else {
        let names: Vec<String> = active
            .iter()
            .map(|(kind, level)| format!("{}({level})", kind.name()))
            .collect();
        line.push_str(&format!(" | ALARM {}", names.join(" ")));
    }
    line
}

/// `2026-… ALARM esc1 sim:esc1 mos_overheat critical raised`
fn alarm_line(entry: &LogEntry, esc: &EscView) -> String {
    let tag = match entry.event() {
        "cleared" => "CLEARED",
        _ => "ALARM",
    };
    format!(
        "{} {tag} esc{} {}: {}",
        timestamp(entry.t),
        esc.number,
        Escaped(esc.title()),
        entry.text()
    )
}

fn alarm_json(entry: &LogEntry, esc: &EscView) -> Value {
    let (duration_s, worst) = match entry.change {
        super::alarms::Change::Cleared {
            duration_s, worst, ..
        } => (Some(duration_s), worst),
        _ => (None, None),
    };
    json!({
        "schema_version": hwfoc_io::JSON_SCHEMA_VERSION,
        "type": "alarm",
        "time": timestamp(entry.t),
        "t_s": entry.t,
        "esc": esc.number,
        "name": esc.name,
        "label": esc.label,
        "alarm": entry.kind.name(),
        "level": entry.level.name(),
        "event": entry.event(),
        "value": entry.value,
        "duration_s": duration_s,
        "worst": worst,
        "text": entry.text(),
    })
}

pub(super) fn status_json(esc: &EscView, now: f64) -> Value {
    let record = esc.last.as_ref().map(record_json);
    let (link, down_since, reason) = match &esc.link {
        Link::Up => ("up", None, None),
        Link::Down { since, reason } => ("down", Some(*since), Some(reason.clone())),
    };
    let p = &esc.peaks;
    let alarms: Vec<Value> = esc
        .alarms
        .active()
        .into_iter()
        .map(|(kind, level)| json!({"alarm": kind.name(), "level": level.name()}))
        .collect();
    let mut status = json!({
        "schema_version": hwfoc_io::JSON_SCHEMA_VERSION,
        "type": "status",
        "time": timestamp(now),
        "t_s": now,
        "esc": esc.number,
        "name": esc.name,
        "label": esc.label,
        "link": link,
        "down_since_s": down_since,
        "down_reason": reason,
        "age_s": esc.age(now),
        "frame_rate_hz": esc.frame_rate(now),
        "protocol": esc.protocol().map(hwfoc::Protocol::name),
        "baud": esc.baud,
        "frames": esc.stats.frames(),
        "bytes": esc.stats.bytes(),
    });
    // The link's figures as the summary gives them: null where the format has no such figure
    // (HW5 numbers no packet, V3 and V4 frames carry no checksum), never 0.
    let link_figures = hwfoc_io::summary::link_json(&esc.stats);
    let rest = json!({
        "bytes_at_other_rates": esc.discarded,
        "info_adopted": esc.stats.adopted_info().map(|i| hwfoc_io::summary::device_json(&i)),
        "record": record,
        "peaks": {
            "rpm": p.rpm,
            "current_a": p.current_a,
            "phase_current_a": p.phase_current_a,
            "min_voltage_v": p.min_voltage_v,
            "mos_temp_c": p.mos_temp_c,
            "cap_temp_c": p.cap_temp_c,
        },
        "energy": energy_json(esc.power_w(), esc.energy.peak_w(), &esc.energy),
        "battery_cells": esc.cells,
        "info": esc.info.as_ref().map(hwfoc_io::summary::device_json),
        "alarms": alarms,
        "settings": hwfoc_io::settings_json(&esc.settings),
    });
    if let (Some(object), Value::Object(rest)) = (status.as_object_mut(), rest) {
        object.extend(link_figures);
        object.extend(rest);
    }
    status
}

/// The record exactly as `hwfoc decode` writes it (docs/RECORD-SCHEMA.md).
fn record_json(r: &Record) -> Value {
    let mut text = Vec::new();
    r.write_json(&mut text);
    serde_json::from_slice(&text).unwrap_or(Value::Null)
}
