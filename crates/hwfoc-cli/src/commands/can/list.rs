//! `hwfoc can list`: the ESCs on a bus, as a table or JSON, and the factory state told.

use std::time::Duration;

use clap::Args;
use hwfoc_can_setup::{EscSurvey, LED_COLORS, Survey, rate_hz};
use hwfoc_sim::can::MAX_CHANNEL;
use serde_json::{Value, json};

use super::BusArgs;
use crate::error::CliError;
use crate::output::TextSink;

/// `hwfoc can list`'s options.
#[derive(Debug, Args)]
pub struct ListArgs {
    #[command(flatten)]
    bus: BusArgs,
    /// Listen at most this long for ESCs, seconds (it ends sooner once 0.5 s pass without a
    /// new one).
    #[arg(long, value_name = "S", default_value = "3", value_parser = crate::args::seconds)]
    listen: f64,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
}

/// Runs `hwfoc can list`.
pub fn run(args: &ListArgs) -> Result<(), CliError> {
    let mut client = args.bus.open()?;
    let survey = client.survey(Duration::from_secs_f64(args.listen), args.bus.timeout())?;
    let text = if args.json {
        format!("{}\n", json(&args.bus.bus, &survey))
    } else {
        table(&args.bus, &survey)
    };
    let mut out = TextSink::create(None)?;
    out.write(&mut text.into_bytes())?;
    out.flush()
}

fn opt<T: ToString>(v: Option<T>) -> String {
    v.map_or_else(|| "-".to_string(), |v| v.to_string())
}

fn led_text(color: u8, blink: u8) -> String {
    let c = LED_COLORS.get(usize::from(color)).unwrap_or(&"?");
    if blink == 0 {
        c.to_string()
    } else {
        format!("{c}/{blink}Hz")
    }
}

fn hz(code: u8) -> String {
    rate_hz(code).map_or_else(|| format!("?{code}"), |h| h.to_string())
}

/// Whether `channel` is a throttle channel: 1 to [`MAX_CHANNEL`] (1-based, 6 bits).
fn is_channel(channel: u8) -> bool {
    (1..=MAX_CHANNEL).contains(&channel)
}

/// A channel as shown: `3`, or `?0` for an answer out of range.
fn channel_text(channel: u8) -> String {
    match is_channel(channel) {
        true => channel.to_string(),
        false => format!("?{channel}"),
    }
}

/// The channels an ESC's GetEscID answers gave: `3`, `1,1,1` (`?0` out of range).
fn channels(e: &EscSurvey) -> String {
    let c = &e.heard.channels;
    if c.is_empty() {
        e.config
            .map_or("-".into(), |c| channel_text(c.throttle_channel))
    } else {
        c.iter()
            .map(|&c| channel_text(c))
            .collect::<Vec<_>>()
            .join(",")
    }
}

/// The nodes that say one throttle channel, by channel: a set-up error where several do
/// (nodes shared by several ESCs, the factory state, told apart).
fn channel_clashes(s: &Survey) -> Vec<(u8, Vec<u8>)> {
    let mut by_channel: std::collections::BTreeMap<u8, Vec<u8>> = Default::default();
    for e in s.escs.iter().filter(|e| !e.heard.is_shared()) {
        let channel = e
            .heard
            .channels
            .last()
            .copied()
            .or(e.config.map(|c| c.throttle_channel));
        if let Some(c) = channel.filter(|&c| is_channel(c)) {
            by_channel.entry(c).or_default().push(e.heard.node);
        }
    }
    by_channel
        .into_iter()
        .filter(|(_, n)| n.len() > 1)
        .collect()
}

/// `10 and 11`, `10, 11 and 12`.
fn and_list(nodes: &[u8]) -> String {
    match nodes.split_last() {
        Some((last, [])) => last.to_string(),
        Some((last, rest)) => {
            let rest: Vec<String> = rest.iter().map(u8::to_string).collect();
            format!("{} and {last}", rest.join(", "))
        }
        None => String::new(),
    }
}

/// What is said when no node was heard: the bit rate used, and the ESCs' factory one.
fn nothing_heard(bus: &BusArgs) -> String {
    let at = bus
        .bitrate()
        .map_or("the interface's bit rate".to_string(), |b| {
            format!("{b} bit/s")
        });
    format!(
        "{}: no node heard at {at} (the ESCs' factory bit rate is 500 kbit/s; an ESC set to \
         another is heard only at it: slcan:PORT:BITRATE)\n",
        bus.bus
    )
}

/// The table, the factory state told under it, and the time the survey took.
fn table(args: &BusArgs, s: &Survey) -> String {
    let bus = args.bus.as_str();
    if s.escs.is_empty() {
        return nothing_heard(args);
    }
    let header = [
        "node",
        "escs",
        "channel",
        "dir",
        "throttle",
        "led",
        "msg1/2/3 Hz",
        "rpm",
        "pwm",
        "V",
        "A",
        "degC",
        "run min",
        "since maint",
    ];
    let mut rows = vec![header.map(str::to_string).to_vec()];
    for e in &s.escs {
        let h = &e.heard;
        let c = e.config;
        rows.push(vec![
            h.node.to_string(),
            h.escs().to_string(),
            channels(e),
            opt(e.direction.map(|d| d.name())),
            opt(c.map(|c| if c.throttle_source { "pwm" } else { "can" })),
            opt(c.map(|c| led_text(c.led_color, c.led_status))),
            format!(
                "{}/{}/{}",
                opt(c.map(|c| hz(c.msg1_rate))),
                opt(c.map(|c| hz(c.msg2_rate))),
                opt(e.msg3_rate.map(hz))
            ),
            opt(h.status1.map(|s| s.rpm)),
            opt(h.status1.map(|s| s.pwm)),
            opt(h
                .status2
                .map(|s| format!("{:.1}", f64::from(s.input_voltage) / 10.0))),
            opt(h
                .status2
                .map(|s| format!("{:.1}", f64::from(s.current) / 10.0))),
            opt(h.status2.map(|s| s.temperature)),
            opt(e.maintenance.map(|m| m.total_rotation_time_min)),
            opt(e.maintenance.map(|m| m.time_since_maintenance_min)),
        ]);
    }
    let widths: Vec<usize> = (0..header.len())
        .map(|i| rows.iter().map(|r| r[i].len()).max().unwrap_or(0))
        .collect();
    let mut out = String::new();
    for r in &rows {
        let cells: Vec<String> = r
            .iter()
            .zip(&widths)
            .map(|(c, w)| format!("{c:>w$}"))
            .collect();
        out.push_str(cells.join("  ").trim_end());
        out.push('\n');
    }
    let n = s.escs.len();
    out.push_str(&format!(
        "{bus}: {n} node{} heard, answered within {:.2} s\n",
        if n == 1 { "" } else { "s" },
        s.elapsed.as_secs_f64()
    ));
    if !s.asked {
        out.push_str(
            "a motor turns: nothing asked (settings are read only while every motor rests)\n",
        );
    }
    for e in s.shared() {
        out.push_str(&shared_advice(bus, e));
    }
    for (channel, nodes) in channel_clashes(s) {
        out.push_str(&format!(
            "set-up error: nodes {} {} say throttle channel {channel}: {} would take the same \
             throttle; give each its own (`hwfoc can set-id {bus} --node {} --to N --channel C`)\n",
            and_list(&nodes),
            if nodes.len() == 2 { "both" } else { "all" },
            if nodes.len() == 2 { "both" } else { "all" },
            nodes[nodes.len() - 1]
        ));
    }
    out
}

/// What to do about several ESCs under one node id.
fn shared_advice(bus: &str, e: &EscSurvey) -> String {
    let node = e.heard.node;
    let distinct = {
        let mut c = e.heard.channels.clone();
        c.sort_unstable();
        c.dedup();
        c.len() == e.heard.channels.len() && c.len() > 1
    };
    let mut s = format!(
        "factory state: {} ESCs answer as node {node}: a request to node {node} reaches them all.\n",
        e.heard.escs()
    );
    if distinct {
        s.push_str(&format!(
            "  They report throttle channels {}: connect one ESC at a time and give it the node \
             id of its channel, e.g. `hwfoc can set-id {bus} --node {node} --to 1C --channel C` \
             (10 + C).\n",
            channels(e)
        ));
    } else {
        s.push_str(&format!(
            "  Connect one ESC at a time (unplug the others' CAN lead) and give each its own node \
             id and throttle channel: `hwfoc can set-id {bus} --node {node} --to 11 --channel 1`, \
             then --to 12 --channel 2 for the next, and so on.\n"
        ));
    }
    s
}

/// One JSON object: the bus, the time taken, each node.
fn json(bus: &str, s: &Survey) -> Value {
    let escs: Vec<Value> = s
        .escs
        .iter()
        .map(|e| {
            let h = &e.heard;
            json!({
                "node": h.node,
                "escs": h.escs(),
                "shared": h.is_shared(),
                "channels": h.channels.iter().filter(|&&c| is_channel(c)).collect::<Vec<_>>(),
                "invalid_channels": h.channels.iter().filter(|&&c| !is_channel(c)).collect::<Vec<_>>(),
                "direction": e.direction.map(|d| d.name()),
                "config": e.config.map(|c| json!({
                    "direction": if c.direction { "ccw" } else { "cw" },
                    "throttle_source": if c.throttle_source { "pwm" } else { "can" },
                    "throttle_channel": is_channel(c.throttle_channel).then_some(c.throttle_channel),
                    "led_color": LED_COLORS.get(usize::from(c.led_color)),
                    "led_status": c.led_status,
                    "msg1_rate_hz": rate_hz(c.msg1_rate),
                    "msg2_rate_hz": rate_hz(c.msg2_rate),
                    "positioning_angle": c.positioning_angle,
                })),
                "msg3_rate_hz": e.msg3_rate.and_then(rate_hz),
                "maintenance": e.maintenance.map(|m| json!({
                    "total_rotation_time_min": m.total_rotation_time_min,
                    "time_since_maintenance_min": m.time_since_maintenance_min,
                })),
                "rpm": h.status1.map(|s| s.rpm),
                "pwm": h.status1.map(|s| s.pwm),
                "status": h.status1.map(|s| s.status),
                "voltage_v": h.status2.map(|s| f64::from(s.input_voltage) / 10.0),
                "current_a": h.status2.map(|s| f64::from(s.current) / 10.0),
                "temperature_c": h.status2.map(|s| s.temperature),
                "mos_c": h.status3.map(|s| s.mos_t),
                "cap_c": h.status3.map(|s| s.cap_t),
                "motor_c": h.status3.map(|s| s.motor_t),
            })
        })
        .collect();
    json!({
        "bus": bus,
        "elapsed_s": s.elapsed.as_secs_f64(),
        "factory_state": s.shared().next().is_some(),
        "asked": s.asked,
        "channel_clashes": channel_clashes(s)
            .into_iter()
            .map(|(channel, nodes)| json!({"channel": channel, "nodes": nodes}))
            .collect::<Vec<_>>(),
        "escs": escs,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::dronecan::{GetEscId, Message, StatusMsg1};
    use hwfoc_can_setup::Heard;

    /// The survey of nodes that each sent a StatusMsg1 and answered GetEscID `[node, channel]`.
    fn survey(answers: &[(u8, u8)]) -> Survey {
        let mut heard = Heard::new();
        for &(node, channel) in answers {
            let status = StatusMsg1 {
                rpm: 0,
                pwm: 0,
                status: 0,
            };
            let answer = GetEscId::new(&[node, channel]).unwrap();
            for m in [Message::from(status), Message::from(answer)] {
                for frame in m.frames(16, node, 0, 0) {
                    heard.take(&frame);
                }
            }
        }
        let escs = answers
            .iter()
            .map(|&(node, _)| EscSurvey {
                heard: heard.node(node).unwrap().clone(),
                direction: None,
                config: None,
                maintenance: None,
                msg3_rate: None,
            })
            .collect();
        Survey {
            escs,
            asked: true,
            elapsed: Duration::from_millis(20),
        }
    }

    /// Throttle channels are 1 to 63 (`GetMajorConfig`'s 6 bits, 1-based): an answer of 0 or
    /// 200 is shown as out of range, never as a channel, and makes no clash.
    #[test]
    fn out_of_range_channel_answers_are_not_shown_as_channels() {
        let s = survey(&[(10, 0), (11, 200), (12, 200), (13, 4)]);
        assert_eq!(channels(&s.escs[0]), "?0");
        assert_eq!(channels(&s.escs[1]), "?200");
        assert_eq!(channels(&s.escs[3]), "4");
        assert!(channel_clashes(&s).is_empty(), "{:?}", channel_clashes(&s));
        let json = json("can:vcan0", &s);
        assert_eq!(json["escs"][0]["channels"], json!([]), "{json}");
        assert_eq!(json["escs"][0]["invalid_channels"], json!([0]), "{json}");
        assert_eq!(json["escs"][3]["channels"], json!([4]), "{json}");
    }
}
