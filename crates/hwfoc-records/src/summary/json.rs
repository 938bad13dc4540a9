//! The summary as JSON (`hwfoc summary --json`).

use super::*;
use crate::stream::{FRAME_FIGURES, Figure};
use hwfoc::format::InfoValue;
use serde_json::Map;

impl Report<'_> {
    /// The summary as one JSON object, as `hwfoc summary --json` prints it.
    pub fn json(&self) -> Value {
        let inputs: Vec<Value> = self
            .sources
            .inputs()
            .iter()
            .map(|info| {
                let mut v = json!({
                    "input": info.name,
                    "format": info.format.short_name(),
                    "bytes": info.bytes,
                    "flagged_bytes": info.flagged_bytes,
                    "escs": info.escs,
                });
                // A copy of an earlier input, not read: which (the key only then).
                if let Some(earlier) = info.duplicate_of {
                    v["duplicate_of"] = json!(self.sources.names()[earlier]);
                }
                v
            })
            .collect();
        let reports = self.escs();
        let escs: Vec<Value> = reports
            .iter()
            .map(|esc| {
                let mut v = esc.json();
                // An ESC's own settings, where they differ from the report's.
                if esc.settings != *self.settings
                    && let Some(object) = v.as_object_mut()
                {
                    object.insert("settings".to_string(), settings_json(&esc.settings));
                }
                v
            })
            .collect();
        let hubs: Vec<Value> = self
            .sources
            .hubs()
            .map(|(esc, h)| {
                json!({
                    "stream": self.sources.esc_table()[esc].key.port,
                    "bytes": h.bytes(),
                    "bytes_skipped": h.bytes_skipped(),
                    "frames": h.frames(),
                    "frames_length_byte_158": h.frames_with_length_byte(LengthByte::Covered),
                    "frames_length_byte_160": h.frames_with_length_byte(LengthByte::Total),
                    "checksum_failures": h.checksum_failures(),
                    "bad_headers": h.bad_headers(),
                    "lost_packets": h.lost_packets(),
                    "duplicate_packets": h.duplicate_packets(),
                    "restarts": h.restarts(),
                    "empty_slots": h.empty_slots(),
                    "bad_channels": h.bad_channels(),
                    "duplicate_channels": h.duplicate_channels(),
                })
            })
            .collect();
        let mut report = json!({
            "schema_version": crate::JSON_SCHEMA_VERSION,
            "settings": settings_json(self.settings),
            "inputs": inputs,
            "hubs": hubs,
            "escs": escs,
            "energy_total": total_energy(&reports).as_ref().map(energy_json),
        });
        // Only when one protocol was read: the report of every protocol read is unchanged.
        if let (Some(protocol), Some(object)) =
            (self.sources.forced_protocol(), report.as_object_mut())
        {
            object.insert("protocol".to_string(), json!(protocol.name()));
        }
        report
    }
}

impl EscReport<'_> {
    fn json(&self) -> Value {
        let st = self.stats;
        let fields: serde_json::Map<String, Value> = self
            .fields()
            .into_iter()
            .map(|(name, unit, range, _)| {
                let v = match range {
                    Some([min, max, mean]) => {
                        json!({"min": min, "max": max, "mean": mean, "unit": unit})
                    }
                    None => json!({"min": null, "max": null, "mean": null, "unit": unit}),
                };
                (name.to_string(), v)
            })
            .collect();
        let faults: serde_json::Map<String, Value> = self
            .faults()
            .map(|(name, _, n)| (name.to_string(), json!(n)))
            .collect();
        let infos: Vec<Value> = self
            .acc
            .infos
            .iter()
            .map(|(i, n)| {
                let mut info = device_json(i);
                info.insert("text".to_string(), json!(i.to_string()));
                info.insert("frames".to_string(), json!(n));
                if i.protocol().description().adopted_info.is_some() {
                    let adopted = st.adopted_info() == Some(*i);
                    info.insert("adopted".to_string(), json!(adopted));
                }
                Value::Object(info)
            })
            .collect();
        let episodes: Vec<Value> = self
            .episodes
            .iter()
            .map(|e| episode_json(e, self.clock, &self.fault_names(e.bits)))
            .collect();
        let temps = |t: TempStats| json!({"below_range": t.below, "above_range": t.above});
        let warning = if st.bytes() == 0 {
            Some("no bytes from this stream")
        } else {
            (st.frames() == 0).then_some(self.no_frames.as_str())
        };
        // The link's figures (their one set of names), with the loss judged from time after
        // its frames' and packets'.
        let figures = st.figures();
        let (frames, stream) = figures.split_at(FRAME_FIGURES);
        let mut link: Map<String, Value> = frames.iter().map(figure_json).collect();
        link.insert(
            "lost_frames_from_time".into(),
            json!(self.timed_loss().map(|l| l.lost)),
        );
        link.insert(
            "silences_not_judged".into(),
            json!(self.timed_loss().map(|l| l.unjudged)),
        );
        link.extend(stream.iter().map(figure_json));
        link.insert("can".into(), can_json(&st));
        let mut report = json!({
            "esc": self.index,
            "input": self.input,
            "stream": self.stream,
            "bytes": st.bytes(),
            "frames": self.data_frames(),
            "info_frames": st.info_frames(),
            "clock": clock_name(self.clock),
            "first_t_s": self.acc.first_t,
            "last_t_s": self.acc.last_t,
            "first_time": self.date(self.acc.first_t),
            "last_time": self.date(self.acc.last_t),
            "duration_s": self.duration(),
            "clock_steps_back": self.acc.steps_back,
            "clock_jumps": self.acc.jumps,
            "frame_rate_hz": self.frame_rate(),
            "protocol": self.protocol().map(Protocol::name),
            "link": Value::Object(link),
            "info": infos,
            "fields": fields,
            "temperature_out_of_range": {
                "mos_temp_c": temps(self.temperature(Quantity::MosTemp)),
                "cap_temp_c": temps(self.temperature(Quantity::CapTemp)),
            },
            "energy": self.energy().map(|e| energy_json(&e)),
            "faults": faults,
            "fault_episode_count": self.episode_count,
            "fault_episodes": episodes,
            "warning": warning,
        });
        // A stream that changed format: each format's data frames (the key only then, so that
        // the report of a stream of one format is unchanged).
        let formats = self.acc.formats();
        if let (true, Some(object)) = (formats.len() > 1, report.as_object_mut()) {
            let counts: serde_json::Map<String, Value> = formats
                .iter()
                .map(|(p, n)| (p.name().to_string(), json!(n)))
                .collect();
            object.insert("formats".to_string(), Value::Object(counts));
        }
        report
    }
}

/// A link's figures as JSON members, under their one set of names
/// ([`LinkStats::figures`](crate::stream::LinkStats::figures)): the form every JSON output gives
/// them in (the summary's `link` object, the status lines of `hwfoc monitor --json`).
pub fn link_json(st: &crate::stream::LinkStats) -> Map<String, Value> {
    st.figures().iter().map(figure_json).collect()
}

/// A link figure as a JSON member: a count as an integer, a ratio as a number, null where not
/// counted.
fn figure_json(&(name, value): &(&str, Option<Figure>)) -> (String, Value) {
    let value = match value {
        Some(Figure::Count(n)) => json!(n),
        Some(Figure::Ratio(r)) => json!(r),
        None => Value::Null,
    };
    (name.to_string(), value)
}

/// An ESC's node and bus figures on a CAN bus (null elsewhere). The node's lost and duplicate
/// transfers and its transfers' CRC failures are not repeated here: they are the link's
/// `lost_packets`, `duplicate_packets` and `checksum_failures`.
fn can_json(st: &crate::stream::LinkStats) -> Value {
    let Some(c) = st.can() else {
        return Value::Null;
    };
    let n = &c.node_stats;
    json!({
        "node": c.node,
        "transfers": n.total_transfers(),
        "gaps": n.gaps(),
        "toggle_errors": n.toggle_errors(),
        "cut_short": n.cut_short(),
        "orphan_frames": n.orphan_frames(),
        "bad_payloads": n.bad_payloads(),
        "unknown_types": n.unknown_types(),
        "bus_frames": c.bus.frames(),
        "not_dronecan": c.bus.not_dronecan(),
        "error_frames": c.bus.error_frames(),
        "bad_records": c.bad_records,
    })
}

/// Charge, energy and power as JSON.
fn energy_json(e: &Energy) -> Value {
    json!({
        "charge_mah": e.charge_mah(),
        "energy_wh": e.energy_wh(),
        "peak_power_w": e.peak_w(),
        "mean_power_w": e.mean_w(),
        "seconds": e.seconds(),
        "nominal_period": e.nominal(),
    })
}

/// The short name of a clock in `--json`.
fn clock_name(clock: Clock) -> &'static str {
    match clock {
        Clock::Wall => "unix",
        Clock::Capture => "capture",
        Clock::None => "none",
    }
}

/// What an information frame says of the device, as every JSON output names it (`summary
/// --json`, `monitor --json`): `{"product": ..., "hardware": ..., "firmware": ..., "id": ...}`.
pub fn device_json(info: &Info) -> serde_json::Map<String, Value> {
    info.fields()
        .map(|(key, value)| {
            let value = match value {
                InfoValue::Text(text) => json!(text),
                InfoValue::Number(n) => json!(n),
            };
            (key.to_string(), value)
        })
        .collect()
}

fn episode_json(e: &Episode, clock: Clock, names: &[&str]) -> Value {
    let date = |t: Option<f64>| t.filter(|_| clock == Clock::Wall).map(time::iso8601);
    json!({
        "start_t_s": e.first.t,
        "end_t_s": e.last.t,
        "start_time": date(e.first.t),
        "end_time": date(e.last.t),
        "duration_s": e.first.t.zip(e.last.t).map(|(a, b)| b - a),
        "start_frame": e.first.frame,
        "end_frame": e.last.frame,
        "start_packet": e.first.packet,
        "end_packet": e.last.packet,
        "frames": e.frames,
        "status": e.bits.0,
        "faults": names,
        "ongoing": e.ongoing,
    })
}
