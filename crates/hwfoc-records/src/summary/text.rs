//! The summary as text, as `hwfoc summary` prints it.

use std::fmt::Write as _;

use super::*;

impl Report<'_> {
    /// The summary as text, as `hwfoc summary` prints it.
    pub fn text(&self) -> String {
        let mut o = String::new();
        // Writing to a String cannot fail; the results are ignored below for that reason.
        let escs = self.escs();
        let _ = write!(
            o,
            "settings     {}",
            settings::words(self.settings, None).join(", ")
        );
        for esc in &escs {
            let differing = settings::words(&esc.settings, Some(self.settings));
            if !differing.is_empty() {
                let _ = write!(o, "; ESC {}: {}", esc.index, differing.join(", "));
            }
        }
        o.push('\n');
        for info in self.sources.inputs() {
            if let Some(earlier) = info.duplicate_of {
                let _ = writeln!(
                    o,
                    "input        {} ({}, the same bytes as {}: read once)",
                    Escaped(&info.name),
                    info.format,
                    Escaped(&self.sources.names()[earlier])
                );
                continue;
            }
            let escs = match info.escs.as_slice() {
                [] => match info.looks {
                    // A CAN log without ESC status: its frames in CAN words.
                    Some(looks @ crate::Looks::Can { .. }) => format!("no ESC: {looks}"),
                    _ => "no ESC".to_string(),
                },
                [one] => format!("ESC {one}"),
                [first, .., last] if last - first + 1 == info.escs.len() => {
                    format!("ESCs {first} to {last}")
                }
                many => {
                    let list: Vec<String> = many.iter().map(usize::to_string).collect();
                    format!("ESCs {}", list.join(", "))
                }
            };
            let _ = writeln!(
                o,
                "input        {} ({}, {} bytes, {escs})",
                Escaped(&info.name),
                info.format,
                info.bytes
            );
            if info.flagged_bytes > 0 {
                let _ = writeln!(
                    o,
                    "             {} bytes flagged with parity or framing errors by the analyser",
                    info.flagged_bytes
                );
            }
        }
        if let Some(protocol) = self.sources.forced_protocol() {
            let _ = writeln!(
                o,
                "protocol     {} only (the bytes of any other protocol skipped)",
                protocol.title()
            );
        }
        for (esc, hub) in self.sources.hubs() {
            let _ = writeln!(
                o,
                "hub          {}: DataLink V2, {hub}",
                Escaped(&self.sources.esc_table()[esc].key.port)
            );
        }
        for esc in &escs {
            o.push('\n');
            esc.text(&mut o);
        }
        if let Some(total) = total_energy(&escs) {
            let _ = writeln!(
                o,
                "\ntotal        {} ESCs: {}",
                escs.iter().filter(|e| e.acc.tally.frames > 0).count(),
                energy_text(&total)
            );
            let _ = writeln!(
                o,
                "             (charges and energies added; the peak is the largest of one ESC, \
                 the mean is the total energy over the longest ESC's time)"
            );
        }
        o
    }
}

impl EscReport<'_> {
    fn text(&self, o: &mut String) {
        let st = self.stats;
        let _ = writeln!(o, "ESC {:<8} {}", self.index, self.label);
        if st.bytes() == 0 {
            let _ = writeln!(o, "frames       none: no bytes from this stream");
            return;
        }
        if st.frames() == 0 && st.info_frames() == 0 {
            let _ = writeln!(o, "frames       none: {}", self.no_frames);
            let _ = writeln!(o, "skipped      {} bytes", st.bytes_skipped());
            return;
        }
        let formats = self.acc.formats();
        let several = formats.len() > 1;
        let _ = write!(
            o,
            "frames       {} data, {} info",
            self.data_frames(),
            st.info_frames()
        );
        if let (Some(d), Some(rate)) = (self.duration(), self.frame_rate()) {
            let _ = write!(o, " over {d:.3} s ({rate:.1} data frames/s)");
        }
        o.push('\n');
        if several {
            let list: Vec<String> = formats
                .iter()
                .map(|(p, n)| format!("{} {n} data frames", p.title()))
                .collect();
            let _ = writeln!(
                o,
                "formats      {} (the stream changed format; the link figures below are {}'s)",
                list.join(", "),
                st.protocol().title()
            );
        }
        if let (Some(first), Some(last)) = (self.acc.first_t, self.acc.last_t) {
            if self.clock == Clock::Wall {
                let _ = writeln!(
                    o,
                    "time         {} .. {} ({:.3} s)",
                    time::iso8601(first),
                    time::iso8601(last),
                    self.acc.elapsed
                );
            } else {
                let _ = writeln!(o, "time         {first} .. {last} s (the source's clock)");
            }
            if let Some(text) = self.discontinuities() {
                let _ = writeln!(o, "clock        {text}");
            }
        }
        let checks = match st.rejected_candidates() {
            Some(n) => format!("{n} rejected candidates (no checksum)"),
            None => format!("{} checksum failures", st.checksum_failures()),
        };
        let counted = if st.counts_packets() {
            let reordered = match st.reordered_packets() {
                0 => String::new(),
                n => format!(", {n} reordered (adjacent frames swapped)"),
            };
            format!(
                "{} lost packets, {} duplicate packets, {} restarts{reordered}",
                st.lost_packets(),
                st.duplicate_packets(),
                st.restarts()
            )
        } else {
            match self.timed_loss() {
                Some(loss) => format!(
                    "no packet counter: {} frames lost judged from their times ({} silences over 1 s not judged)",
                    loss.lost, loss.unjudged
                ),
                None => "no packet counter (loss not counted)".to_string(),
            }
        };
        // After a change of format, the bytes the locked format's decoder skipped hold the other
        // formats' frames: said as what they are, not as bytes no decoder could read.
        let skipped = match several {
            true => format!("bytes outside {} frames", st.protocol().title()),
            false => "bytes skipped".to_string(),
        };
        let _ = writeln!(
            o,
            "link         {checks}, {counted}, {} {skipped} ({:.2} %)",
            st.bytes_skipped(),
            percent(st.bytes_skipped(), st.bytes())
        );
        if let Some(ratio) = st.delivery_ratio() {
            let of = match several {
                true => format!("{} ", st.protocol().title()),
                false => String::new(),
            };
            let _ = writeln!(o, "delivery     {:.2} % of {of}data frames", ratio * 100.0);
        }
        if let Some(c) = st.can() {
            let n = &c.node_stats;
            let node = c
                .node
                .map_or("no node yet".to_string(), |n| format!("node {n}"));
            let _ = writeln!(
                o,
                "can          {node}: {} transfers, {} gaps in transfer ids, {} toggle errors, {} cut short, {} of unknown types; bus: {} frames, {} not DroneCAN ({} error frames)",
                n.total_transfers(),
                n.gaps(),
                n.toggle_errors(),
                n.cut_short(),
                n.unknown_types(),
                c.bus.frames(),
                c.bus.not_dronecan(),
                c.bus.error_frames()
            );
        }
        if st.frames() == 0 {
            let _ = writeln!(o, "             no data frames: {}", self.no_frames);
        }
        let adopted = st.adopted_info();
        for (info, n) in &self.acc.infos {
            let adopted = if Some(*info) == adopted {
                ", adopted"
            } else {
                ""
            };
            let _ = writeln!(
                o,
                "device       {}  ({n} info frames{adopted})",
                Escaped(info)
            );
        }
        if self.acc.tally.frames == 0 {
            return;
        }
        let _ = writeln!(
            o,
            "\n{:<18} {:>12} {:>12} {:>12}  unit",
            "field", "min", "max", "mean"
        );
        // A quantity the ESC's protocol does not send has no row (JSON keeps its key, null).
        for (name, unit, range, _) in self.fields().into_iter().filter(|row| row.3) {
            match range {
                Some([min, max, mean]) => {
                    let _ = writeln!(o, "{name:<18} {min:>12.3} {max:>12.3} {mean:>12.3}  {unit}");
                }
                None => {
                    let _ = writeln!(o, "{name:<18} {:>12} {:>12} {:>12}  {unit}", "-", "-", "-");
                }
            }
        }
        for (name, t) in [
            ("mos_temp_c", self.temperature(Quantity::MosTemp)),
            ("cap_temp_c", self.temperature(Quantity::CapTemp)),
        ] {
            if t.below + t.above > 0 {
                let _ = writeln!(
                    o,
                    "{name:<18} out of the table's range in {} frames (below 0 degC: {}, above 129 degC: {})",
                    t.below + t.above,
                    t.below,
                    t.above
                );
            }
        }
        if let Some(energy) = self.energy() {
            let _ = writeln!(o, "\nenergy       {}", energy_text(&energy));
        }
        o.push('\n');
        if self.episode_count == 0 {
            let _ = writeln!(o, "faults       none");
            return;
        }
        for (name, description, n) in self.faults() {
            let _ = writeln!(o, "fault        {name:<22} in {n} frames ({description})");
        }
        let _ = writeln!(
            o,
            "episodes     {} (runs of consecutive frames with faults)",
            self.episode_count
        );
        for (i, e) in self.episodes.iter().take(TEXT_EPISODES).enumerate() {
            let _ = writeln!(
                o,
                "  {:>4}  {}",
                i + 1,
                episode_text(e, self.clock, &self.fault_names(e.bits))
            );
        }
        let more = self.episode_count - self.episodes.len().min(TEXT_EPISODES) as u64;
        if more > 0 {
            let _ = writeln!(o, "        ... and {more} more (all listed with --json)");
        }
    }
}

/// Charge, energy and power in one line.
fn energy_text(e: &Energy) -> String {
    let mut s = format!(
        "{} mAh, {} Wh consumed",
        Fixed(e.charge_mah(), 3),
        Fixed(e.energy_wh(), 4)
    );
    if let Some(peak) = e.peak_w() {
        let _ = write!(s, "; input power peak {} W", Fixed(peak, 1));
    }
    if let Some(mean) = e.mean_w() {
        let _ = write!(s, ", mean {} W over {:.3} s", Fixed(mean, 1), e.seconds());
    }
    if e.nominal() {
        let _ = write!(
            s,
            " (no receive times: each frame counted as {} ms)",
            (e.period_s() * 1e6).round() / 1000.0
        );
    }
    s
}

/// An episode in one line: when (dates on a wall clock), how long, which faults.
fn episode_text(e: &Episode, clock: Clock, names: &[&str]) -> String {
    let mut s = format!("{} (", e.when(clock == Clock::Wall));
    if let (Some(a), Some(b)) = (e.first.t, e.last.t) {
        let _ = write!(s, "{:.3} s, ", b - a);
    }
    let _ = write!(s, "{} frames", e.frames);
    if let (Some(a), Some(b)) = (e.first.packet, e.last.packet) {
        let _ = write!(s, ", packets {a} .. {b}");
    }
    let _ = write!(s, ")  {}", names.join(", "));
    if e.ongoing {
        s.push_str("  (still on at the end)");
    }
    s
}
