//! The Wireshark dissector (`hwfoc wireshark`), run by tshark on recordings: every frame it shows
//! as valid has exactly the values `hwfoc decode` gives (data frames) and the codec reads (device
//! information), with the same time, in recordings of the compact layout and of the
//! read-chunk layout; bad checksums show as bad, faults by name; the older formats (the Platinum
//! V4 and V3 captures, an HW5 stream) recorded as `hwfoc record` cuts their bytes, frame for
//! frame as `hwfoc decode` reads them; `install` puts it where tshark loads it and never
//! replaces another file unasked. DroneCAN on CAN captures (LINKTYPE_CAN_SOCKETCAN): frames
//! pydronecan made show the values it encoded (ignored unless asked for: they need a Python with
//! `dronecan`, which `.ci/dronecan.sh` makes), and garbage frames never make the dissector fail.

#![cfg(unix)]

mod common;
#[path = "../../hwfoc-bridge/tests/py/python.rs"]
mod python;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{hwfoc, need_tshark, run};
use hwfoc::foc::{DataFrame, FocFrame, InfoFrame};
use hwfoc_io::pcapng;
use serde_json::Value;

fn dissector() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("wireshark/hwfoc.lua")
}

fn old_recording() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testdata/recordings/chunked-2esc.pcapng")
}

const FIELDS: [&str; 22] = [
    "frame.interface_id",
    "hwfoc.kind",
    "hwfoc.checksum.status",
    "hwfoc.time_epoch",
    "hwfoc.packet",
    "hwfoc.throttle_in_pct",
    "hwfoc.throttle_out_pct",
    "hwfoc.erpm",
    "hwfoc.rpm",
    "hwfoc.voltage_v",
    "hwfoc.current_a",
    "hwfoc.phase_current_a",
    "hwfoc.mos_temp_c",
    "hwfoc.cap_temp_c",
    "hwfoc.status",
    "hwfoc.faults",
    "hwfoc.info.product",
    "hwfoc.info.hardware",
    "hwfoc.info.firmware",
    "hwfoc.info.id",
    "hwfoc.checksum",
    "hwfoc.checksum.computed",
];

/// One frame as tshark shows it: field name -> value ("" when absent).
type Shown = std::collections::BTreeMap<&'static str, String>;

/// Every frame the dissector shows, in file order. Frames of one packet are its fields'
/// occurrences (tshark aggregates them with `;`); fields a frame lacks (a temperature out of
/// range) are told apart by the frame's own count of fields.
fn tshark(file: &Path, options: &[&str], with_script: bool) -> Vec<Shown> {
    tshark_fields(file, options, with_script, &FIELDS)
}

/// [`tshark`] without the device-information text, which in a frame that fails its checks
/// may hold any byte (the aggregator `;` among them).
fn tshark_without_text(file: &Path) -> Vec<Shown> {
    let fields: Vec<&'static str> = FIELDS
        .into_iter()
        .filter(|f| !f.starts_with("hwfoc.info."))
        .collect();
    tshark_fields(file, &[], true, &fields)
}

/// [`tshark`] with the fields `fields`, a selection of [`FIELDS`] in its order.
fn tshark_fields(
    file: &Path,
    options: &[&str],
    with_script: bool,
    fields: &[&'static str],
) -> Vec<Shown> {
    let mut cmd = common::tshark();
    if with_script {
        cmd.arg("-X")
            .arg(format!("lua_script:{}", dissector().display()));
    }
    cmd.args(options).arg("-r").arg(file).args(["-T", "fields"]);
    cmd.args([
        "-E",
        "occurrence=a",
        "-E",
        "aggregator=;",
        "-E",
        "separator=/t",
    ]);
    for f in fields {
        cmd.args(["-e", f]);
    }
    let out = cmd.output().expect("tshark");
    assert!(
        out.status.success(),
        "tshark: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut frames = Vec::new();
    for line in text.lines() {
        let cols: Vec<&str> = line.split('\t').collect();
        assert_eq!(cols.len(), fields.len(), "{line}");
        let kinds: Vec<&str> = cols[1].split(';').filter(|k| !k.is_empty()).collect();
        // Fields every frame of a kind has, split per frame (a data frame's temperatures may be
        // absent: they are read only for packets of one frame).
        let mut per_field: Vec<std::collections::VecDeque<&str>> = cols
            .iter()
            .map(|c| c.split(';').filter(|v| !v.is_empty()).collect())
            .collect();
        for kind in &kinds {
            let mut shown = Shown::new();
            shown.insert("frame.interface_id", cols[0].to_string());
            for (i, f) in fields.iter().enumerate().skip(1) {
                let applies = match (*kind, *f) {
                    (_, "hwfoc.kind" | "hwfoc.checksum.status" | "hwfoc.time_epoch") => true,
                    (_, "hwfoc.checksum" | "hwfoc.checksum.computed") => true,
                    ("info", f) => f.starts_with("hwfoc.info."),
                    ("data", f) => !f.starts_with("hwfoc.info."),
                    _ => false,
                };
                let optional = matches!(*f, "hwfoc.mos_temp_c" | "hwfoc.cap_temp_c");
                if applies && !optional {
                    let v = per_field[i]
                        .pop_front()
                        .unwrap_or_else(|| panic!("{f} in {line}"));
                    shown.insert(f, v.to_string());
                } else {
                    shown.insert(f, String::new());
                }
            }
            frames.push(shown);
        }
        // Optional temperatures are only checked for packets of one frame.
        if kinds.len() == 1 {
            let shown = frames.last_mut().unwrap();
            for f in ["hwfoc.mos_temp_c", "hwfoc.cap_temp_c"] {
                let i = fields.iter().position(|x| *x == f).unwrap();
                shown.insert(f, cols[i].to_string());
            }
        } else {
            for shown in frames.iter_mut().rev().take(kinds.len()) {
                shown.insert("hwfoc.mos_temp_c", "?".into());
                shown.insert("hwfoc.cap_temp_c", "?".into());
            }
        }
    }
    frames
}

fn records(out: &[u8]) -> Vec<Value> {
    String::from_utf8(out.to_vec())
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

fn decode(file: &Path, options: &[&str]) -> Vec<Value> {
    let out = run(hwfoc().arg("decode").args(options).arg(file));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    records(&out.stdout)
}

fn as_f32(text: &str) -> f32 {
    text.parse::<f64>()
        .unwrap_or_else(|_| panic!("a number: {text:?}")) as f32
}

fn uint(text: &str) -> u64 {
    match text.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16).unwrap(),
        None => text.parse().unwrap(),
    }
}

/// tshark's valid data frames are `hwfoc decode`'s records, value for value (numbers compared
/// as the f32 they are), in order per ESC, with the same time.
fn same_data_frames(shown: &[Shown], decoded: &[Value]) -> usize {
    let good: Vec<&Shown> = shown
        .iter()
        .filter(|s| s["hwfoc.kind"] == "data" && s["hwfoc.checksum.status"] == "1")
        .collect();
    assert_eq!(good.len(), decoded.len(), "valid data frames");
    let mut by_esc: std::collections::BTreeMap<u64, Vec<&Shown>> = Default::default();
    for s in &good {
        by_esc
            .entry(uint(&s["frame.interface_id"]))
            .or_default()
            .push(s);
    }
    let mut next: std::collections::BTreeMap<u64, usize> = Default::default();
    for r in decoded {
        let esc = r["esc"].as_u64().unwrap();
        let k = next.entry(esc).or_default();
        let s = by_esc[&esc][*k];
        *k += 1;
        let what = format!("esc {esc} packet {}", r["packet"]);
        assert_eq!(
            uint(&s["hwfoc.packet"]),
            r["packet"].as_u64().unwrap(),
            "{what}"
        );
        assert_eq!(
            uint(&s["hwfoc.erpm"]),
            r["erpm"].as_u64().unwrap(),
            "{what}"
        );
        assert_eq!(
            uint(&s["hwfoc.status"]),
            r["status"].as_u64().unwrap(),
            "{what}"
        );
        for (field, column) in [
            ("hwfoc.throttle_in_pct", "throttle_in_pct"),
            ("hwfoc.throttle_out_pct", "throttle_out_pct"),
            ("hwfoc.rpm", "rpm"),
            ("hwfoc.voltage_v", "voltage_v"),
            ("hwfoc.current_a", "current_a"),
            ("hwfoc.phase_current_a", "phase_current_a"),
            ("hwfoc.mos_temp_c", "mos_temp_c"),
            ("hwfoc.cap_temp_c", "cap_temp_c"),
        ] {
            let want = &r[column];
            let got = &s[field];
            if got == "?" {
                continue;
            }
            if want.is_null() {
                assert_eq!(got, "", "{what}: {column} is out of range");
            } else {
                assert_eq!(
                    as_f32(got),
                    want.as_f64().unwrap() as f32,
                    "{what}: {column}"
                );
            }
        }
        let faults: Vec<&str> = r["faults"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_str().unwrap())
            .collect();
        let faults = if faults.is_empty() {
            "none".to_string()
        } else {
            faults.join(",")
        };
        assert_eq!(s["hwfoc.faults"], faults, "{what}");
        let ns = s["hwfoc.time_epoch"].replace('.', "");
        let t = ns.parse::<u64>().unwrap() as f64 * 1e-9;
        let dt = (t - r["t_s"].as_f64().unwrap()).abs();
        assert!(dt < 1e-6, "{what}: time differs by {dt} s");
    }
    good.len()
}

/// The information frames of each port, read with the codec from the recording's bytes.
fn info_frames(file: &Path) -> Vec<(u32, InfoFrame)> {
    let bytes = std::fs::read(file).unwrap();
    let mut reader = pcapng::Reader::new(&bytes[..]);
    let mut streams: Vec<Vec<u8>> = Vec::new();
    while let Some(p) = reader.next_packet().unwrap() {
        let i = p.iface as usize;
        if streams.len() <= i {
            streams.resize(i + 1, Vec::new());
        }
        streams[i].extend_from_slice(p.data);
    }
    let mut out = Vec::new();
    for (i, s) in streams.iter().enumerate() {
        hwfoc::foc::Decoder::new().decode_all(s, |d| {
            if let FocFrame::Info(info) = d.frame {
                out.push((i as u32, info));
            }
        });
    }
    out
}

fn same_info_frames(shown: &[Shown], file: &Path) -> usize {
    let mut got: Vec<(u32, [String; 4])> = shown
        .iter()
        .filter(|s| s["hwfoc.kind"] == "info" && s["hwfoc.checksum.status"] == "1")
        .map(|s| {
            let f = |k: &str| s[k].clone();
            (
                uint(&s["frame.interface_id"]) as u32,
                [
                    f("hwfoc.info.product"),
                    f("hwfoc.info.hardware"),
                    f("hwfoc.info.firmware"),
                    f("hwfoc.info.id"),
                ],
            )
        })
        .collect();
    let mut want: Vec<(u32, [String; 4])> = info_frames(file)
        .into_iter()
        .map(|(i, info)| {
            let fields = [info.product(), info.hardware(), info.firmware(), info.id()];
            (i, fields.map(str::to_string))
        })
        .collect();
    got.sort_by_key(|g| g.0);
    want.sort_by_key(|w| w.0);
    assert_eq!(got, want, "device-information frames");
    got.len()
}

/// Every frame shown: a good checksum equals the one computed, a bad one differs.
fn checksums_are_honest(shown: &[Shown]) -> usize {
    let mut bad = 0;
    for s in shown {
        let (carried, computed) = (&s["hwfoc.checksum"], &s["hwfoc.checksum.computed"]);
        match s["hwfoc.checksum.status"].as_str() {
            "1" => assert_eq!(uint(carried), uint(computed)),
            "0" => {
                assert_ne!(uint(carried), uint(computed));
                bad += 1;
            }
            other => panic!("checksum status {other:?}"),
        }
    }
    bad
}

/// Runs `hwfoc simulate ARGS -o FILE -q` (`args` separated by spaces), which must succeed.
fn simulate(file: &Path, args: &str) {
    let sim = run(hwfoc()
        .arg("simulate")
        .args(args.split_whitespace())
        .arg("-o")
        .arg(file)
        .arg("-q"));
    assert!(
        sim.status.success(),
        "{}",
        String::from_utf8_lossy(&sim.stderr)
    );
}

#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn a_simulated_recording_dissects_as_decode_reads_it() {
    need_tshark();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("sim.pcapng");
    simulate(
        &file,
        "--escs 3 --seed 5 --duration 12 --start-time 1754000000.25 --lead-in 3 \
         --garbage-rate 0.05 --bit-error-rate 3e-4 --cut-rate 0.02 \
         --fault 1:mos_overheat@4-5 --fault over_current@6-6.5",
    );

    let shown = tshark(&file, &[], true);
    let decoded = decode(&file, &[]);
    let data = same_data_frames(&shown, &decoded);
    let info = same_info_frames(&shown, &file);
    let bad = checksums_are_honest(&shown);
    assert!(
        data > 300 && info >= 6,
        "{data} data, {info} information frames"
    );
    assert!(bad > 0, "no corrupted frame shown as bad");
    let faults: Vec<&Shown> = shown
        .iter()
        .filter(|s| s["hwfoc.faults"].contains("mos_overheat"))
        .collect();
    assert!(!faults.is_empty() && faults.iter().all(|s| s["frame.interface_id"] == "1"));
    assert!(shown.iter().any(|s| s["hwfoc.faults"] == "over_current"));
    // The compact layout: every frame is alone in its packet.
    assert!(shown.iter().all(|s| s["hwfoc.mos_temp_c"] != "?"));
    // Noise is shown as such, and a bad frame has its expert info.
    let expert = common::tshark()
        .arg("-X")
        .arg(format!("lua_script:{}", dissector().display()))
        .arg("-r")
        .arg(&file)
        .args(["-Y", "hwfoc.noise", "-T", "fields", "-e", "frame.number"])
        .output()
        .unwrap();
    assert!(!expert.stdout.is_empty(), "no noise shown");
    let bad_expert = common::tshark()
        .arg("-X")
        .arg(format!("lua_script:{}", dissector().display()))
        .arg("-r")
        .arg(&file)
        .args([
            "-Y",
            "hwfoc.checksum.bad && hwfoc.fault.expert || hwfoc.checksum.bad",
        ])
        .output()
        .unwrap();
    assert_eq!(
        String::from_utf8_lossy(&bad_expert.stdout).lines().count(),
        bad,
        "expert info for each bad checksum"
    );
}

#[test]
fn the_old_chunked_recording_decodes_as_before() {
    let file = old_recording();
    let golden = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/chunked-2esc.jsonl");
    let out = run(hwfoc().arg("decode").arg(&file));
    assert!(out.status.success());
    assert_eq!(
        String::from_utf8(out.stdout).unwrap(),
        std::fs::read_to_string(&golden).unwrap(),
        "an old recording must decode exactly as before (the same records as the old writer's \
         reader gave, now in time order across its two ports)"
    );
}

#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn the_old_chunked_recording_dissects_as_it_decodes() {
    need_tshark();
    let file = old_recording();
    let golden = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/chunked-2esc.jsonl");
    let shown = tshark(&file, &[], true);
    let decoded = records(&std::fs::read(&golden).unwrap());
    // Frames cut across packets (reads) are reassembled: every frame is there.
    assert_eq!(same_data_frames(&shown, &decoded), 114);
    assert_eq!(same_info_frames(&shown, &file), 9);
    assert!(checksums_are_honest(&shown) > 0);
}

/// A recording of frames with every temperature code, extreme currents and every status bit,
/// written with the library's writer.
fn every_code(file: &Path) {
    let mut w = pcapng::Writer::new(std::fs::File::create(file).unwrap()).unwrap();
    w.add_interface("/dev/ttyUSB0", 19200).unwrap();
    let mut t = 1_754_000_000_000_000_000u64;
    for code in 0..=255u8 {
        let frame = DataFrame {
            packet: u16::from(code) * 251,
            throttle_in_raw: u16::from(code) * 4,
            throttle_out_raw: 1024 - u16::from(code),
            erpm_raw: u16::from(code) * 257,
            voltage_raw: u16::from(code) * 3 + 1,
            current_raw: (i16::from(code) - 128) * 255,
            phase_current_raw: i16::MIN + i16::from(code),
            mos_adc: code,
            cap_adc: 255 - code,
            status: hwfoc::Status(1u16 << (code % 16)),
        };
        w.write(0, t, &frame.encode()).unwrap();
        t += 50_000_000;
    }
    let info = InfoFrame::new("XR_FOC_ESC", "HW577_KZ1_V1.1", "XR-01.0.00", "01040443").unwrap();
    w.write(0, t, &info.encode()).unwrap();
    w.into_inner().unwrap();
}

#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn every_temperature_code_and_the_conversion_preferences() {
    need_tshark();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("codes.pcapng");
    every_code(&file);
    let shown = tshark(&file, &[], true);
    let decoded = decode(&file, &[]);
    assert_eq!(same_data_frames(&shown, &decoded), 256);
    assert_eq!(same_info_frames(&shown, &file), 1);
    assert_eq!(checksums_are_honest(&shown), 0);

    let prefs = [
        "-o",
        "hwfoc.pole_pairs:14",
        "-o",
        "hwfoc.current_scale:100",
        "-o",
        "hwfoc.gear_ratio:2.5",
    ];
    let shown = tshark(&file, &prefs, true);
    let decoded = decode(
        &file,
        &[
            "--pole-pairs",
            "14",
            "--current-scale",
            "100",
            "--gear-ratio",
            "2.5",
        ],
    );
    assert_eq!(same_data_frames(&shown, &decoded), 256);
}

#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn other_user0_files_are_left_alone_unless_asked() {
    need_tshark();
    // USER0 bytes from another tool: an interface hwfoc did not describe.
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("other.pcapng");
    let frame = DataFrame {
        packet: 77,
        ..Default::default()
    }
    .encode();
    let mut raw = pcapng::Writer::new(Vec::new()).unwrap();
    raw.add_interface("x", 19200).unwrap();
    raw.write(0, 1_000_000_000, &frame).unwrap();
    let mut file_bytes = raw.into_inner().unwrap();
    // Rewrite the description ("ESC telemetry (hwfoc), …") into something else of the same
    // length.
    let at = file_bytes.windows(7).position(|w| w == b"(hwfoc)").unwrap();
    file_bytes[at..at + 7].copy_from_slice(b"(other)");
    std::fs::write(&file, &file_bytes).unwrap();
    let shown = tshark(&file, &[], true);
    assert!(shown.is_empty(), "claimed another tool's USER0 packets");
    let shown = tshark(&file, &["-o", "hwfoc.all_user0:TRUE"], true);
    assert_eq!(shown.len(), 1);
    assert_eq!(shown[0]["hwfoc.packet"], "77");
}

#[test]
fn install_path_and_print() {
    let dir = tempfile::tempdir().unwrap();
    let home = dir.path();
    let target = home.join(".local/lib/wireshark/plugins/hwfoc.lua");
    let cmd = |args: &[&str]| run(hwfoc().arg("wireshark").args(args).env("HOME", home));

    let path = cmd(&["path"]);
    assert!(path.status.success());
    assert_eq!(
        String::from_utf8_lossy(&path.stdout).trim(),
        target.to_str().unwrap()
    );

    let print = cmd(&["print"]);
    assert_eq!(print.stdout, std::fs::read(dissector()).unwrap());

    let install = cmd(&["install"]);
    assert!(
        install.status.success(),
        "{}",
        String::from_utf8_lossy(&install.stderr)
    );
    assert!(String::from_utf8_lossy(&install.stdout).contains(target.to_str().unwrap()));
    assert_eq!(std::fs::read(&target).unwrap(), print.stdout);
    let again = cmd(&["install"]);
    assert!(again.status.success());
    assert!(String::from_utf8_lossy(&again.stdout).contains("already"));

    // A file of one's own is never replaced unasked.
    std::fs::write(&target, "-- my edits\n").unwrap();
    let refused = cmd(&["install"]);
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("--force"));
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "-- my edits\n");
    let forced = cmd(&["install", "--force"]);
    assert!(forced.status.success());
    assert_eq!(std::fs::read(&target).unwrap(), print.stdout);
    let left: Vec<_> = std::fs::read_dir(target.parent().unwrap())
        .unwrap()
        .collect();
    assert_eq!(left.len(), 1, "a temporary file was left behind");
}

/// Wireshark loads the dissector `hwfoc wireshark install` put in place: tshark dissects without
/// -X.
#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn tshark_loads_the_installed_dissector() {
    need_tshark();
    let dir = tempfile::tempdir().unwrap();
    let home = dir.path();
    let install = run(hwfoc().args(["wireshark", "install"]).env("HOME", home));
    assert!(install.status.success());
    let file = home.join("codes.pcapng");
    every_code(&file);
    let out = common::tshark()
        .env("HOME", home)
        .arg("-r")
        .arg(&file)
        .args(["-T", "fields", "-e", "hwfoc.packet"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        text.lines().filter(|l| !l.is_empty()).count(),
        256,
        "{text}"
    );
}

/// Each ESC's valid data frames, as (interface or ESC) -> packet numbers in order.
type PacketsByEsc = std::collections::BTreeMap<u64, Vec<u64>>;

fn packets_shown(shown: &[Shown]) -> PacketsByEsc {
    let mut by_esc = PacketsByEsc::new();
    for s in shown
        .iter()
        .filter(|s| s["hwfoc.kind"] == "data" && s["hwfoc.checksum.status"] == "1")
    {
        by_esc
            .entry(uint(&s["frame.interface_id"]))
            .or_default()
            .push(uint(&s["hwfoc.packet"]));
    }
    by_esc
}

fn packets_decoded(decoded: &[Value]) -> PacketsByEsc {
    let mut by_esc = PacketsByEsc::new();
    for r in decoded {
        by_esc
            .entry(r["esc"].as_u64().unwrap())
            .or_default()
            .push(r["packet"].as_u64().unwrap());
    }
    by_esc
}

/// tshark shows, frame for frame, the data frames `hwfoc decode` reads from `file` (each ESC's
/// packet numbers in order; the first difference is named), then the same values and times.
/// Returns the frames tshark shows and `hwfoc decode`'s packet numbers.
fn same_frames_as_decode(file: &Path, what: &str) -> (Vec<Shown>, PacketsByEsc) {
    let shown = tshark_without_text(file);
    let decoded = decode(file, &[]);
    let (got, want) = (packets_shown(&shown), packets_decoded(&decoded));
    let escs: std::collections::BTreeSet<u64> = got.keys().chain(want.keys()).copied().collect();
    let of = |by_esc: &PacketsByEsc, esc| by_esc.get(&esc).cloned().unwrap_or_default();
    for esc in escs {
        let (shown, read) = (of(&got, esc), of(&want, esc));
        if let Some(at) = (0..shown.len().max(read.len())).find(|&k| shown.get(k) != read.get(k)) {
            let around =
                |v: &[u64]| v[at.saturating_sub(2).min(v.len())..(at + 3).min(v.len())].to_vec();
            panic!(
                "{what}: ESC {esc}, valid data frame {at}: tshark shows packets {:?}, hwfoc \
                 decode reads {:?} ({} and {} frames in all)",
                around(&shown),
                around(&read),
                shown.len(),
                read.len()
            );
        }
    }
    same_data_frames(&shown, &decoded);
    (shown, want)
}

/// Noisy recordings of two ESCs (garbage, bit errors, cut and dropped frames, long idle spells
/// with their device-information frames, some of them cut): tshark finds exactly the frames
/// `hwfoc decode` finds, for several seeds and noise levels.
#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn noisy_recordings_dissect_frame_for_frame_as_decode_reads_them() {
    need_tshark();
    let dir = tempfile::tempdir().unwrap();
    // (seed, garbage, bit errors, cuts, drops)
    let runs = [
        (3, "0.1", "2e-4", "0.1", "0.02"),
        (11, "0.3", "1e-3", "0.05", "0"),
        (29, "0.02", "0", "0.25", "0.05"),
    ];
    for (seed, garbage, bits, cuts, drops) in runs {
        let file = dir.path().join(format!("noisy-{seed}.pcapng"));
        simulate(
            &file,
            &format!(
                "--escs 2 --duration 20 --seed {seed} --start-time 1754000000 --lead-in 3 \
                 --hold 3 --levels 0,40,0,80 --garbage-rate {garbage} --bit-error-rate {bits} \
                 --cut-rate {cuts} --drop-rate {drops}"
            ),
        );
        let (shown, decoded) = same_frames_as_decode(&file, &format!("seed {seed}"));
        let n: Vec<usize> = decoded.values().map(Vec::len).collect();
        // The device-information frames too (counted per port: a frame that fails its checks
        // may hold any byte in its text, which tshark's fields do not escape).
        let mut infos = [0, 0];
        for s in &shown {
            if s["hwfoc.kind"] == "info" && s["hwfoc.checksum.status"] == "1" {
                infos[uint(&s["frame.interface_id"]) as usize] += 1;
            }
        }
        let mut want = [0, 0];
        for (port, _) in info_frames(&file) {
            want[port as usize] += 1;
        }
        assert_eq!(
            infos, want,
            "seed {seed}: device-information frames per port"
        );
        assert!(want.iter().all(|&n| n > 10), "seed {seed}: {want:?}");
        assert!(
            n.len() == 2 && n.iter().all(|&n| n > 150),
            "seed {seed}: {n:?} frames"
        );
    }
}

/// Nanoseconds per byte at 19200 baud, 8N1.
const BYTE_NS: f64 = 1e10 / 19200.0;

/// One port of a crafted recording: packets of chosen bytes at chosen times.
struct Port {
    t_ns: u64,
    packets: Vec<(u64, Vec<u8>)>,
}

impl Port {
    fn new(t_ns: u64) -> Port {
        Port {
            t_ns,
            packets: Vec::new(),
        }
    }

    /// A packet of `bytes` now; the clock moves on by their byte times.
    fn send(&mut self, bytes: &[u8]) {
        self.packets.push((self.t_ns, bytes.to_vec()));
        self.t_ns += (bytes.len() as f64 * BYTE_NS).round() as u64;
    }

    /// The line is silent for `s` seconds (after the last byte's byte time).
    fn wait(&mut self, s: f64) {
        self.t_ns += (s * 1e9).round() as u64;
    }
}

/// Writes the ports' packets as they are (one interface each), in time order.
fn write_ports(file: &Path, ports: &[Port]) {
    let mut w = pcapng::Writer::new(std::fs::File::create(file).unwrap()).unwrap();
    let mut all = Vec::new();
    for (i, port) in ports.iter().enumerate() {
        let iface = w.add_interface(&format!("/dev/ttyUSB{i}"), 19200).unwrap();
        all.extend(port.packets.iter().map(|(t, b)| (*t, iface, b)));
    }
    all.sort_by_key(|&(t, iface, _)| (t, iface));
    for (t, iface, bytes) in all {
        w.write_packet(iface, t, bytes).unwrap();
    }
    w.into_inner().unwrap();
}

/// Data frames numbered from 1, with values drawn from a seeded generator.
struct Frames {
    packet: u16,
    rng: hwfoc_sim::rng::Rng,
}

impl Frames {
    fn next(&mut self) -> (u16, [u8; 24]) {
        self.packet += 1;
        let rng = &mut self.rng;
        let frame = DataFrame {
            packet: self.packet,
            throttle_in_raw: rng.below(1025) as u16,
            erpm_raw: rng.below(5000) as u16,
            voltage_raw: 220 + rng.below(30) as u16,
            current_raw: rng.below(3000) as i16,
            mos_adc: 40 + rng.below(200) as u8,
            cap_adc: 40 + rng.below(200) as u8,
            ..Default::default()
        };
        (self.packet, frame.encode())
    }

    /// `n` data frames on `port`, a packet each, 50 ms apart; their numbers go into `whole`.
    fn send(&mut self, port: &mut Port, n: usize, whole: &mut Vec<u64>) {
        for _ in 0..n {
            let (packet, bytes) = self.next();
            port.send(&bytes);
            port.wait(0.0375);
            whole.push(packet.into());
        }
    }
}

/// Every way a candidate frame can end up in a recording's packets, on port 0 one case after
/// another and on port 1 a random stream of frames, cut frames, fake headers and noise cut
/// into packets anywhere, with silences: the dissector gives up a candidate exactly where the
/// decoder does (a header whose version, command or text show it is no frame hides none of
/// the frames after it, however many packets it takes to tell), reassembles what the decoder
/// reassembles, and no more across a silence of over a second.
#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn a_candidate_that_fails_is_given_up_where_the_decoder_gives_it_up() {
    need_tshark();
    let rng = hwfoc_sim::rng::Rng::for_esc(7, 0, hwfoc_sim::rng::Purpose::Link);
    let mut frames = Frames { packet: 0, rng };
    let info = InfoFrame::new("XR_FOC_ESC", "HW577_KZ1_V1.1", "XR-01.0.00", "01040443")
        .unwrap()
        .encode();
    // Port 0, and the data frames hwfoc decode finds in it.
    let mut a = Port::new(1_754_000_000_000_000_000);
    let mut want = Vec::new();
    frames.send(&mut a, 3, &mut want);
    // 15 bytes of noise that begin like a device-information frame, then frames.
    a.send(&[
        0x9B, 0x4C, 0x33, 0xA7, 0x10, 0x9B, 0x16, 0x55, 0xE0, 0x02, 0x9B, 0x4C, 0x01, 0xFF, 0x42,
    ]);
    frames.send(&mut a, 4, &mut want);
    // A device-information frame cut after 33 bytes (its text so far is ASCII), then frames.
    a.send(&info[..33]);
    frames.send(&mut a, 4, &mut want);
    // The same over three packets: the text goes on, plain ASCII, until a frame's sync byte.
    a.send(&info[..20]);
    a.send(b"ABCDEFGHIJKLMNOPQRSTUVWXYZ0123");
    frames.send(&mut a, 3, &mut want);
    // A data frame cut after 10 bytes, then frames.
    a.send(&frames.next().1[..10]);
    frames.send(&mut a, 2, &mut want);
    // A sync byte at the end of a packet, then a frame.
    a.send(&[0x00, 0x9B]);
    frames.send(&mut a, 2, &mut want);
    // A data frame in three packets, then a device-information frame in four.
    let (packet, f) = frames.next();
    a.send(&f[..8]);
    a.send(&f[8..16]);
    a.send(&f[16..]);
    want.push(packet.into());
    a.wait(0.02);
    for piece in info.chunks(20) {
        a.send(piece);
    }
    a.wait(0.02);
    frames.send(&mut a, 2, &mut want);
    // A device-information frame whose two halves are 2 s apart: a silence ends a frame.
    a.send(&info[..40]);
    a.wait(2.0);
    a.send(&info[40..]);
    frames.send(&mut a, 2, &mut want);
    // A data frame whose halves are just over a second apart (from the last byte of one to the
    // first of the other): not reassembled; just under a second: reassembled.
    for gap in [1.0002, 0.9998] {
        let (packet, f) = frames.next();
        a.send(&f[..12]);
        a.wait(gap - BYTE_NS * 1e-9);
        a.send(&f[12..]);
        if gap < 1.0 {
            want.push(packet.into());
        }
        frames.send(&mut a, 2, &mut want);
    }
    // Port 1: a random stream cut anywhere.
    let mut rng = hwfoc_sim::rng::Rng::for_esc(7, 1, hwfoc_sim::rng::Purpose::Link);
    let mut stream = Vec::new();
    for _ in 0..600 {
        match rng.below(100) {
            0..=54 => {
                let mut f = frames.next().1.to_vec();
                if rng.chance(0.15) {
                    f.truncate(1 + rng.below(23) as usize);
                } else if rng.chance(0.1) {
                    let at = rng.below(24) as usize;
                    f[at] ^= 1 << rng.below(8);
                }
                stream.extend_from_slice(&f);
            }
            55..=62 => {
                let cut = if rng.chance(0.5) {
                    1 + rng.below(76) as usize
                } else {
                    77
                };
                stream.extend_from_slice(&info[..cut]);
            }
            63..=74 => {
                // A fake header: a device-information header and text, or a data header.
                if rng.chance(0.5) {
                    stream.extend_from_slice(&[0x9B, 0x4C, 0x01, 0x01]);
                    for _ in 0..rng.below(90) {
                        stream.push(0x20 + rng.below(0x5F) as u8);
                    }
                } else {
                    stream.extend_from_slice(&[0x9B, 0x16, 0x01, 0x02]);
                }
            }
            _ => {
                const DENSE: [u8; 6] = [0x9B, 0x16, 0x4C, 0x01, 0x02, 0x20];
                for _ in 0..1 + rng.below(40) {
                    let b = if rng.chance(0.5) {
                        DENSE[rng.below(6) as usize]
                    } else {
                        rng.below(256) as u8
                    };
                    stream.push(b);
                }
            }
        }
    }
    let mut b = Port::new(1_754_000_000_003_000_000);
    let mut rest = &stream[..];
    while !rest.is_empty() {
        let n = (1 + rng.below(90) as usize).min(rest.len());
        b.send(&rest[..n]);
        rest = &rest[n..];
        b.wait(match rng.below(100) {
            0 => 1.5,
            1 => 0.9,
            _ => rng.below(30) as f64 * 1e-3,
        });
    }

    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("crafted.pcapng");
    write_ports(&file, &[a, b]);
    let (shown, decoded) = same_frames_as_decode(&file, "crafted");
    assert_eq!(
        decoded[&0], want,
        "the data frames of port 0 hwfoc decode finds"
    );
    assert!(
        decoded[&1].len() > 200,
        "{} frames on port 1",
        decoded[&1].len()
    );
    // Port 0's one whole device-information frame is the one in four packets.
    let infos = shown
        .iter()
        .filter(|s| s["hwfoc.kind"] == "info" && s["hwfoc.checksum.status"] == "1")
        .filter(|s| s["frame.interface_id"] == "0")
        .count();
    assert_eq!(infos, 1, "device-information frames of port 0");
}

/// The bytes of a logic-analyser CSV capture of `testdata/captures/`, each with its time (s).
fn capture(name: &str) -> Vec<(f64, u8)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../testdata/captures")
        .join(name);
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|line| {
            let mut cols = line.split(',');
            let t = cols.next().unwrap().parse::<f64>().unwrap();
            let v = u8::from_str_radix(cols.next().unwrap().trim_start_matches("0x"), 16).unwrap();
            (t, v)
        })
        .collect()
}

/// Records `bytes` (times in seconds after `start_ns`) as `hwfoc record` does: reads of 1 to
/// 40 bytes, each written at its first byte's time through the pcapng writer's cutter, so
/// frames of the older formats lie across packets.
fn record_reads(file: &Path, baud: u32, start_ns: u64, bytes: &[(f64, u8)], seed: u64) {
    let mut w = pcapng::Writer::new(std::fs::File::create(file).unwrap()).unwrap();
    let iface = w.add_interface("/dev/ttyUSB0", baud).unwrap();
    let mut rng = hwfoc_sim::rng::Rng::for_esc(seed, 0, hwfoc_sim::rng::Purpose::Link);
    let mut rest = bytes;
    while !rest.is_empty() {
        let n = (1 + rng.below(40) as usize).min(rest.len());
        let t_ns = start_ns + (rest[0].0 * 1e9).round() as u64;
        let data: Vec<u8> = rest[..n].iter().map(|&(_, b)| b).collect();
        w.write(iface, t_ns, &data).unwrap();
        rest = &rest[n..];
    }
    w.into_inner().unwrap();
}

/// The fields a frame of `protocol` and `kind` always has, among `fields`.
fn applies(protocol: &str, kind: &str, field: &str) -> bool {
    match (protocol, kind, field) {
        (_, _, "hwfoc.protocol" | "hwfoc.kind" | "hwfoc.time_epoch") => true,
        ("hw-v4", "data", f) => matches!(
            f,
            "hwfoc.packet"
                | "hwfoc.throttle_in_pct"
                | "hwfoc.throttle_out_pct"
                | "hwfoc.erpm"
                | "hwfoc.rpm"
                | "hwfoc.voltage_v"
                | "hwfoc.v4.temp_adc"
                | "hwfoc.v4.temp2_adc"
        ),
        ("hw-v4", "info", f) => matches!(f, "hwfoc.v4.full_scale" | "hwfoc.v4.volts_per_step"),
        ("hw-v3", "data", f) => matches!(
            f,
            "hwfoc.packet"
                | "hwfoc.throttle_in_pct"
                | "hwfoc.throttle_out_pct"
                | "hwfoc.v3.period_us"
        ),
        ("hw5", "data", f) => matches!(
            f,
            "hwfoc.throttle_in_pct"
                | "hwfoc.erpm"
                | "hwfoc.rpm"
                | "hwfoc.voltage_v"
                | "hwfoc.current_a"
                | "hwfoc.mos_temp_c"
                | "hwfoc.motor_temp_c"
                | "hwfoc.bec_temp_c"
                | "hwfoc.bec_voltage_v"
                | "hwfoc.bec_current_a"
                | "hwfoc.status"
                | "hwfoc.faults"
                | "hwfoc.checksum.status"
        ),
        _ => false,
    }
}

/// The fields of [`OLDER_FIELDS`] every frame of `protocol` has (of one kind or another).
fn fields_of(protocol: &str) -> Vec<&'static str> {
    OLDER_FIELDS
        .into_iter()
        .filter(|f| {
            ["data", "info"]
                .iter()
                .any(|kind| applies(protocol, kind, f))
        })
        .collect()
}

/// Every frame of the older formats tshark shows in `file` (fields `fields`, which begin with
/// protocol and kind), in order; the values of fields a frame of its kind always has.
fn older_frames(file: &Path, options: &[&str], fields: &[&'static str]) -> Vec<Shown> {
    let mut cmd = common::tshark();
    cmd.arg("-X")
        .arg(format!("lua_script:{}", dissector().display()))
        .args(options)
        .arg("-r")
        .arg(file)
        .args(["-T", "fields", "-E", "occurrence=a", "-E", "aggregator=;"])
        .args(["-E", "separator=/t"]);
    for f in fields {
        cmd.args(["-e", f]);
    }
    let out = cmd.output().expect("tshark");
    assert!(
        out.status.success(),
        "tshark: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("Lua") && !err.contains("rror"), "{err}");
    let mut frames = Vec::new();
    for line in String::from_utf8(out.stdout).unwrap().lines() {
        let cols: Vec<&str> = line.split('\t').collect();
        assert_eq!(cols.len(), fields.len(), "{line}");
        let mut queues: Vec<std::collections::VecDeque<&str>> = cols
            .iter()
            .map(|c| c.split(';').filter(|v| !v.is_empty()).collect())
            .collect();
        while let Some(protocol) = queues[0].pop_front() {
            let kind = queues[1].pop_front().expect(line);
            let mut shown = Shown::new();
            shown.insert("hwfoc.protocol", protocol.to_string());
            shown.insert("hwfoc.kind", kind.to_string());
            for (i, f) in fields.iter().enumerate().skip(2) {
                let v = if applies(protocol, kind, f) {
                    queues[i]
                        .pop_front()
                        .unwrap_or_else(|| panic!("{f} in {line}"))
                } else {
                    ""
                };
                shown.insert(f, v.to_string());
            }
            frames.push(shown);
        }
        assert!(
            queues.iter().all(|q| q.is_empty()),
            "fields left over in {line}"
        );
    }
    frames
}

/// Asserts that `got` (a number tshark shows) is `want` (a record's value) as the f32 it is.
fn same_value(got: &str, want: &Value, what: &str) {
    assert_eq!(
        as_f32(got),
        want.as_f64().unwrap_or_else(|| panic!("{what}: null")) as f32,
        "{what}"
    );
}

fn same_time(shown: &Shown, record: &Value, what: &str) {
    let t = uint(&shown["hwfoc.time_epoch"].replace('.', "")) as f64 * 1e-9;
    let dt = (t - record["t_s"].as_f64().unwrap()).abs();
    assert!(dt < 1e-6, "{what}: time differs by {dt} s");
}

const OLDER_FIELDS: [&str; 23] = [
    "hwfoc.protocol",
    "hwfoc.kind",
    "hwfoc.time_epoch",
    "hwfoc.packet",
    "hwfoc.throttle_in_pct",
    "hwfoc.throttle_out_pct",
    "hwfoc.erpm",
    "hwfoc.rpm",
    "hwfoc.voltage_v",
    "hwfoc.current_a",
    "hwfoc.mos_temp_c",
    "hwfoc.motor_temp_c",
    "hwfoc.bec_temp_c",
    "hwfoc.bec_voltage_v",
    "hwfoc.bec_current_a",
    "hwfoc.status",
    "hwfoc.faults",
    "hwfoc.checksum.status",
    "hwfoc.v4.temp_adc",
    "hwfoc.v4.temp2_adc",
    "hwfoc.v4.full_scale",
    "hwfoc.v4.volts_per_step",
    "hwfoc.v3.period_us",
];

/// The Platinum V4 capture recorded in reads cut anywhere: the dissector shows its 297 data
/// frames with `hwfoc decode`'s values and times, its 26 info frames, and no checksum.
#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn a_platinum_v4_recording_dissects_as_decode_reads_it() {
    need_tshark();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("v4.pcapng");
    record_reads(
        &file,
        19200,
        1_754_000_000_000_000_000,
        &capture("platinum-v4.csv"),
        4,
    );
    let shown = older_frames(&file, &[], &fields_of("hw-v4"));
    let decoded = decode(&file, &["--format", "jsonl"]);
    assert_eq!(decoded.len(), 297);
    let data: Vec<&Shown> = shown.iter().filter(|s| s["hwfoc.kind"] == "data").collect();
    let info: Vec<&Shown> = shown.iter().filter(|s| s["hwfoc.kind"] == "info").collect();
    assert!(shown.iter().all(|s| s["hwfoc.protocol"] == "hw-v4"));
    assert_eq!(data.len(), decoded.len(), "data frames");
    assert_eq!(info.len(), 26, "info frames");
    assert!(
        info.iter()
            .all(|s| s["hwfoc.v4.full_scale"] == "1000" && s["hwfoc.v4.volts_per_step"] == "8/910")
    );
    for (s, r) in data.iter().zip(&decoded) {
        let what = format!("packet {}", r["packet"]);
        assert_eq!(
            uint(&s["hwfoc.packet"]),
            r["packet"].as_u64().unwrap(),
            "{what}"
        );
        assert_eq!(
            uint(&s["hwfoc.erpm"]),
            r["erpm"].as_u64().unwrap(),
            "{what}"
        );
        for (field, column) in [
            ("hwfoc.throttle_in_pct", "throttle_in_pct"),
            ("hwfoc.throttle_out_pct", "throttle_out_pct"),
            ("hwfoc.rpm", "rpm"),
            ("hwfoc.voltage_v", "voltage_v"),
        ] {
            same_value(&s[field], &r[column], &format!("{what}: {column}"));
        }
        assert_eq!(r["protocol"], "hw-v4");
        same_time(s, r, &what);
    }
    let peak = data
        .iter()
        .map(|s| as_f32(&s["hwfoc.throttle_in_pct"]))
        .fold(0.0, f32::max);
    assert_eq!(peak, 100.0);
    // The temperatures, for the packets of one data frame (aggregated fields are told apart by
    // their presence only there): as hwfoc decodes them; an ADC value of 0 is no reading.
    let temps = common::tshark()
        .arg("-X")
        .arg(format!("lua_script:{}", dissector().display()))
        .arg("-r")
        .arg(&file)
        .args(["-Y", "count(hwfoc.kind) == 1 && hwfoc.kind == \"data\""])
        .args(["-T", "fields", "-E", "separator=/t"])
        .args([
            "-e",
            "hwfoc.packet",
            "-e",
            "hwfoc.mos_temp_c",
            "-e",
            "hwfoc.cap_temp_c",
        ])
        .args(["-e", "hwfoc.v4.temp2_adc"])
        .output()
        .unwrap();
    let temps = String::from_utf8(temps.stdout).unwrap();
    assert!(
        temps.lines().count() > 100,
        "{} packets of one data frame",
        temps.lines().count()
    );
    let mut cap = 0;
    for line in temps.lines() {
        let cols: Vec<&str> = line.split('\t').collect();
        let r = decoded
            .iter()
            .find(|r| r["packet"].as_u64() == Some(uint(cols[0])))
            .unwrap();
        let got = as_f32(cols[1]);
        let want = r["mos_temp_c"].as_f64().unwrap() as f32;
        assert!(
            (got - want).abs() < 1e-4,
            "packet {}: {got} {want}",
            r["packet"]
        );
        // The second temperature: an ADC value of 0 (at idle in the capture) is no reading.
        match r["cap_temp_c"].as_f64() {
            Some(want) => assert!((as_f32(cols[2]) - want as f32).abs() < 1e-4, "{line}"),
            None => assert_eq!((cols[2], cols[3]), ("", "0"), "{line}"),
        }
        cap += usize::from(!r["cap_temp_c"].is_null());
    }
    assert!(cap > 10, "{cap} second temperatures");
    // No checksum in the format: the tree says so; the preference converts voltages.
    let none = common::tshark()
        .arg("-X")
        .arg(format!("lua_script:{}", dissector().display()))
        .args(["-o", "hwfoc.v4_volts_per_step:hv", "-r"])
        .arg(&file)
        .args([
            "-Y",
            "hwfoc.no_checksum",
            "-T",
            "fields",
            "-E",
            "aggregator=;",
        ])
        .args(["-e", "hwfoc.voltage_v"])
        .output()
        .unwrap();
    let volts: Vec<f64> = String::from_utf8(none.stdout)
        .unwrap()
        .split(['\n', ';'])
        .filter(|v| !v.is_empty())
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(volts.len(), 297);
    assert!(volts.iter().all(|v| (22.0..24.0).contains(v)), "{volts:?}");
}

/// A recording `hwfoc simulate` (or `record`) writes, one frame per packet: the first V3 or V4
/// frame, which only the next one shows to be a frame, is shown (reassembled in the next
/// packet) as `decode` reads it: as many frames, with the same packet numbers.
#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn the_first_v3_and_v4_frames_of_a_recording_are_shown() {
    need_tshark();
    let dir = tempfile::tempdir().unwrap();
    for protocol in ["hw-v3", "hw-v4"] {
        let file = dir.path().join(format!("{protocol}.pcapng"));
        let o = run(hwfoc()
            .args([
                "simulate",
                "--protocol",
                protocol,
                "--duration",
                "3",
                "--quiet",
                "-o",
            ])
            .arg(&file));
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let decoded = decode(&file, &["--format", "jsonl"]);
        let shown: Vec<Shown> = older_frames(&file, &[], &fields_of(protocol))
            .into_iter()
            .filter(|s| s["hwfoc.kind"] == "data")
            .collect();
        assert_eq!(shown.len(), decoded.len(), "{protocol}: data frames");
        assert_eq!(
            uint(&shown[0]["hwfoc.packet"]),
            decoded[0]["packet"].as_u64().unwrap(),
            "{protocol}: the first frame"
        );
    }
}

/// The Platinum Pro V3 capture recorded in reads cut anywhere: its 699 frames, with
/// `hwfoc decode`'s values and times (no speed where the ESC sends its placeholder).
#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn a_platinum_v3_recording_dissects_as_decode_reads_it() {
    need_tshark();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("v3.pcapng");
    record_reads(
        &file,
        19200,
        1_754_000_000_000_000_000,
        &capture("platinum-pro-v3.csv"),
        3,
    );
    let shown = older_frames(&file, &[], &fields_of("hw-v3"));
    let decoded = decode(&file, &["--format", "jsonl"]);
    assert_eq!(decoded.len(), 699);
    assert_eq!(shown.len(), decoded.len(), "frames");
    let mut placeholders = 0;
    for (s, r) in shown.iter().zip(&decoded) {
        let what = format!("packet {}", r["packet"]);
        assert_eq!(
            (s["hwfoc.protocol"].as_str(), s["hwfoc.kind"].as_str()),
            ("hw-v3", "data")
        );
        assert_eq!(
            uint(&s["hwfoc.packet"]),
            r["packet"].as_u64().unwrap(),
            "{what}"
        );
        for (field, column) in [
            ("hwfoc.throttle_in_pct", "throttle_in_pct"),
            ("hwfoc.throttle_out_pct", "throttle_out_pct"),
        ] {
            same_value(&s[field], &r[column], &format!("{what}: {column}"));
        }
        let period = uint(&s["hwfoc.v3.period_us"]);
        match r["erpm"].as_u64() {
            Some(erpm) => assert_eq!(erpm, 60_000_000 / period, "{what}"),
            None => {
                assert!(period == 35_314 || period == 0, "{what}");
                placeholders += 1;
            }
        }
        same_time(s, r, &what);
    }
    assert!(placeholders > 0);
}

/// HW5 telemetry frames (115200 baud) with faults, line noise and a frame with a bad CRC,
/// recorded in reads cut anywhere: the valid frames are `hwfoc decode`'s records, faults by
/// HW5's names, the BEC's values; the bad CRC shows as bad.
#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn an_hw5_recording_dissects_as_decode_reads_it() {
    use hwfoc::hw5::{Fault, FaultCode, TelemetryFrame};
    need_tshark();
    let byte_s = 10.0 / 115_200.0;
    let mut bytes: Vec<(f64, u8)> = Vec::new();
    let mut t = 0.0;
    let mut push = |data: &[u8], gap: f64| {
        for (k, &b) in data.iter().enumerate() {
            bytes.push((t + k as f64 * byte_s, b));
        }
        t += data.len() as f64 * byte_s + gap;
    };
    let mut rng = hwfoc_sim::rng::Rng::for_esc(5, 0, hwfoc_sim::rng::Purpose::Link);
    for k in 0..120u16 {
        let mut fault = FaultCode::OK;
        if (40..50).contains(&k) {
            fault = fault.with(Fault::LowVoltage);
        }
        if k % 37 == 5 {
            fault = fault
                .with(Fault::ThrottleSignalLost)
                .with(Fault::MotorLocked);
        }
        let frame = TelemetryFrame {
            throttle: (k % 101) as u8,
            fault,
            erpm_raw: k * 37,
            voltage_raw: 504 - k,
            current_raw: rng.below(900) as u16,
            esc_temp: 30 + (k / 4) as u8,
            bec_temp: 35,
            motor_temp: 40 + (k / 3) as u8,
            bec_voltage_raw: 84,
            bec_current_raw: (k % 20) as u8,
            ..Default::default()
        };
        let mut encoded = frame.encode();
        if k == 60 {
            encoded[17] ^= 0x10;
        }
        push(&encoded, 0.02);
        if k % 25 == 3 {
            push(&[0x00, 0xFE, 0x01, 0x13, 0x77], 0.001);
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("hw5.pcapng");
    record_reads(&file, 115_200, 1_754_000_000_000_000_000, &bytes, 9);
    let shown = older_frames(&file, &[], &fields_of("hw5"));
    let decoded = decode(&file, &["--format", "jsonl"]);
    assert_eq!(decoded.len(), 119);
    let good: Vec<&Shown> = shown
        .iter()
        .filter(|s| s["hwfoc.checksum.status"] == "1")
        .collect();
    let bad: Vec<&Shown> = shown
        .iter()
        .filter(|s| s["hwfoc.checksum.status"] == "0")
        .collect();
    assert_eq!((good.len(), bad.len()), (119, 1));
    assert!(
        shown
            .iter()
            .all(|s| s["hwfoc.protocol"] == "hw5" && s["hwfoc.kind"] == "data")
    );
    for (s, r) in good.iter().zip(&decoded) {
        let what = format!("t {}", r["t_s"]);
        assert_eq!(r["protocol"], "hw5");
        assert_eq!(
            uint(&s["hwfoc.erpm"]),
            r["erpm"].as_u64().unwrap(),
            "{what}"
        );
        assert_eq!(
            uint(&s["hwfoc.status"]),
            r["status"].as_u64().unwrap(),
            "{what}"
        );
        for (field, column) in [
            ("hwfoc.throttle_in_pct", "throttle_in_pct"),
            ("hwfoc.rpm", "rpm"),
            ("hwfoc.voltage_v", "voltage_v"),
            ("hwfoc.current_a", "current_a"),
            ("hwfoc.mos_temp_c", "mos_temp_c"),
            ("hwfoc.motor_temp_c", "motor_temp_c"),
            ("hwfoc.bec_temp_c", "bec_temp_c"),
            ("hwfoc.bec_voltage_v", "bec_voltage_v"),
            ("hwfoc.bec_current_a", "bec_current_a"),
        ] {
            same_value(&s[field], &r[column], &format!("{what}: {column}"));
        }
        let faults: Vec<&str> = r["faults"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_str().unwrap())
            .collect();
        let faults = if faults.is_empty() {
            "none".to_string()
        } else {
            faults.join(",")
        };
        assert_eq!(s["hwfoc.faults"], faults, "{what}");
        same_time(s, r, &what);
    }
    assert!(
        good.iter()
            .any(|s| s["hwfoc.faults"] == "motor_locked,throttle_signal_lost")
    );
    assert!(good.iter().any(|s| s["hwfoc.faults"] == "low_voltage"));
    // The fault bits by name, as filters.
    let named = common::tshark()
        .arg("-X")
        .arg(format!("lua_script:{}", dissector().display()))
        .arg("-r")
        .arg(&file)
        .args([
            "-Y",
            "hwfoc.hw5.fault.low_voltage == 1",
            "-T",
            "fields",
            "-e",
            "frame.number",
        ])
        .output()
        .unwrap();
    assert!(
        !named.stdout.is_empty(),
        "no frame with hwfoc.hw5.fault.low_voltage"
    );
}

/// A pcapng file of one LINKTYPE_CAN_SOCKETCAN (227) interface, a packet per record, a
/// millisecond apart (hwfoc_io's writer writes hwfoc's USER0 recordings; these few blocks are
/// written here).
fn can_pcapng(file: &Path, records: &[Vec<u8>]) {
    fn block(out: &mut Vec<u8>, kind: u32, body: &[u8]) {
        let pad = body.len().next_multiple_of(4) - body.len();
        let len = (body.len() + pad + 12) as u32;
        out.extend_from_slice(&kind.to_le_bytes());
        out.extend_from_slice(&len.to_le_bytes());
        out.extend_from_slice(body);
        out.extend(std::iter::repeat_n(0, pad));
        out.extend_from_slice(&len.to_le_bytes());
    }
    let mut out = Vec::new();
    let mut shb = Vec::new();
    shb.extend_from_slice(&0x1A2B_3C4Du32.to_le_bytes());
    shb.extend_from_slice(&[1, 0, 0, 0]);
    shb.extend_from_slice(&(-1i64).to_le_bytes());
    block(&mut out, 0x0A0D_0D0A, &shb);
    let mut idb = Vec::new();
    idb.extend_from_slice(&227u16.to_le_bytes());
    idb.extend_from_slice(&[0, 0]);
    idb.extend_from_slice(&16u32.to_le_bytes());
    block(&mut out, 1, &idb);
    for (i, rec) in records.iter().enumerate() {
        let t_us = 1_700_000_000_000_000u64 + i as u64 * 1000;
        let mut epb = Vec::new();
        epb.extend_from_slice(&0u32.to_le_bytes());
        epb.extend_from_slice(&((t_us >> 32) as u32).to_le_bytes());
        epb.extend_from_slice(&(t_us as u32).to_le_bytes());
        epb.extend_from_slice(&(rec.len() as u32).to_le_bytes());
        epb.extend_from_slice(&(rec.len() as u32).to_le_bytes());
        epb.extend_from_slice(rec);
        block(&mut out, 6, &epb);
    }
    std::fs::write(file, out).unwrap();
}

/// tshark with the dissector on `file`: `-T fields` of `fields` (one row per packet, each
/// field's occurrences joined by `,`), and the `-V` tree, which must hold no Lua error.
fn tshark_can(file: &Path, fields: &[&str]) -> (Vec<Vec<String>>, String) {
    let script = format!("lua_script:{}", dissector().display());
    let mut cmd = common::tshark();
    cmd.args(["-X", &script, "-r"]).arg(file).args([
        "-T",
        "fields",
        "-E",
        "occurrence=a",
        "-E",
        "aggregator=,",
        "-E",
        "separator=/t",
    ]);
    for f in fields {
        cmd.args(["-e", f]);
    }
    let out = cmd.output().expect("tshark");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "tshark: {err}");
    assert!(!err.contains("Lua"), "tshark: {err}");
    let rows = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| l.split('\t').map(str::to_string).collect::<Vec<_>>())
        .collect::<Vec<_>>();
    let tree = common::tshark()
        .args(["-X", &script, "-r"])
        .arg(file)
        .arg("-V")
        .output()
        .expect("tshark");
    assert!(tree.status.success());
    let tree = String::from_utf8(tree.stdout).unwrap();
    assert!(!tree.contains("Lua Error"), "{tree}");
    (rows, tree)
}

/// Whether tshark's `shown` (a field's occurrences joined by `,`) is `want`: numbers within a
/// part in 10^12 (tshark prints doubles to 15 digits; hexadecimal fields as 0x...), booleans as 1/0, strings exactly.
fn shown_is(shown: &str, want: &[Value]) -> bool {
    let got: Vec<&str> = if shown.is_empty() {
        Vec::new()
    } else {
        shown.split(',').collect()
    };
    got.len() == want.len()
        && got.iter().zip(want).all(|(g, w)| match w {
            Value::Bool(b) => {
                *g == if *b { "1" } else { "0" } || g.eq_ignore_ascii_case(&b.to_string())
            }
            Value::Number(n) => match g.strip_prefix("0x") {
                Some(hex) => u64::from_str_radix(hex, 16).ok() == n.as_u64(),
                None => g.parse::<f64>().is_ok_and(|g| {
                    let w = n.as_f64().unwrap();
                    (g - w).abs() <= 1e-12 * w.abs().max(1.0)
                }),
            },
            Value::String(s) => g == s,
            _ => false,
        })
}

/// pydronecan's frames of every message and service the dissector knows (written as a CAN
/// capture by tests/py/dronecan_pcapng.py): each packet shows the header, tail byte and field
/// values pydronecan encoded; esc.Status is reassembled over its three frames, interleaved with
/// another node's, its CRC ok, and bad where the capture corrupted it.
#[test]
#[ignore = "needs tshark and a Python with dronecan (HWFOC_DRONECAN_PY or python3): .ci/dronecan.sh runs it"]
fn pydronecan_frames_dissect_to_the_values_encoded() {
    need_tshark();
    let python = python::python_with("HWFOC_DRONECAN_PY", "dronecan", ".ci/dronecan.sh");
    let dir = common::Dir::new();
    let file = dir.path("dronecan.pcapng");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/py/dronecan_pcapng.py");
    let out = Command::new(&python)
        .arg(&script)
        .arg(&file)
        .output()
        .expect("cannot run HWFOC_DRONECAN_PY");
    assert!(
        out.status.success(),
        "{}: {}",
        script.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let expected: Vec<Value> = serde_json::from_slice(&out.stdout).unwrap();
    let mut fields: Vec<&str> = expected
        .iter()
        .flat_map(|e| e["fields"].as_object().unwrap().keys().map(String::as_str))
        .collect();
    fields.sort_unstable();
    fields.dedup();
    let mut asked = vec!["frame.number"];
    asked.extend(&fields);
    let (rows, tree) = tshark_can(&file, &asked);
    assert_eq!(rows.len(), expected.len(), "one row per packet");
    let mut compared = 0;
    for e in &expected {
        let frame = e["frame"].as_u64().unwrap() as usize;
        let row = &rows[frame - 1];
        assert_eq!(row[0], frame.to_string());
        for (field, want) in e["fields"].as_object().unwrap() {
            let at = asked.iter().position(|f| f == field).unwrap();
            let want = want.as_array().unwrap();
            assert!(
                shown_is(&row[at], want),
                "frame {frame}: {field} is {:?}, pydronecan encoded {want:?}",
                row[at]
            );
            compared += want.len();
        }
    }
    // Every data type's decoded fields were there to compare, and the CRCs said as they should.
    for name in [
        "dronecan.hobbywing.statusmsg1.rpm",
        "dronecan.hobbywing.statusmsg2.temperature",
        "dronecan.hobbywing.statusmsg3.motor_t",
        "dronecan.hobbywing.getescid.throttle_channel",
        "dronecan.nodestatus.health",
        "dronecan.esc.status.esc_index",
        "dronecan.esc.statusextended.motor_temperature_degc",
        "dronecan.hobbywing.setid.node_id",
        "dronecan.hobbywing.setbaud.baud",
        "dronecan.hobbywing.setled.blink",
        "dronecan.hobbywing.setdirection.direction",
        "dronecan.hobbywing.setreportingfrequency.msg_id",
        "dronecan.hobbywing.setthrottlesource.source",
        "dronecan.hobbywing.selftest.status",
        "dronecan.hobbywing.setangle.angle",
        "dronecan.hobbywing.getmaintenanceinformation.time_since_maintainence_min",
        "dronecan.hobbywing.getmajorconfig.positioning_angle",
    ] {
        assert!(fields.contains(&name), "{name} not checked");
    }
    assert_eq!(tree.matches("[CRC ok]").count(), 2, "{tree}");
    assert_eq!(tree.matches("[CRC bad").count(), 1, "{tree}");
    assert!(tree.contains("Direction (status bit 14: CCW): CCW"));
    assert!(tree.contains("Input voltage: 50.4 V (raw 504)"));
    assert!(tree.contains("DroneCAN message of unknown data type 12345, node 9"));
    eprintln!(
        "pydronecan frames dissected: {} packets, {compared} field values compared",
        rows.len()
    );
}

/// Garbage on a CAN capture: standard frames, empty, remote and error frames, an impossible
/// length, and random extended frames (random tail bytes, data type ids the dissector knows with
/// payloads of every length, continuations of transfers never begun): no Lua error, standard
/// frames left to the `can` dissector, and the rest shown as DroneCAN where it can be.
#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn garbage_can_frames_do_not_make_the_dissector_fail() {
    use hwfoc::dronecan::CanFrame;
    need_tshark();
    let mut records: Vec<Vec<u8>> = Vec::new();
    let record = |f: Option<CanFrame>| f.unwrap().to_socketcan_record().to_vec();
    records.push(record(CanFrame::standard(0x123, &[1, 2, 3, 0xC0])));
    records.push(record(CanFrame::standard(0x7FF, &[])));
    records.push(record(CanFrame::extended(0x104E_5203, &[])));
    records.push(record(CanFrame::remote(0x104E_5203, true, 7)));
    records.push(record(CanFrame::error(0x4, &[0, 0, 0, 0, 0, 0, 0, 0])));
    // a service with destination 0, an anonymous multi-frame transfer
    records.push(record(CanFrame::extended(0x18D2_0081, &[5, 3, 0xC1])));
    records.push(record(CanFrame::extended(
        0x1000_0100,
        &[1, 2, 3, 4, 5, 6, 7, 0x81],
    )));
    // StatusMsg1 too short; a continuation of nothing; a toggle out of sequence
    records.push(record(CanFrame::extended(0x104E_5203, &[1, 2, 0xC1])));
    records.push(record(CanFrame::extended(0x1004_0A14, &[1, 2, 3, 0x45])));
    records.push(record(CanFrame::extended(
        0x1004_0A14,
        &[1, 2, 3, 4, 5, 6, 7, 0x86],
    )));
    records.push(record(CanFrame::extended(
        0x1004_0A14,
        &[1, 2, 3, 4, 5, 6, 7, 0x06],
    )));
    let fixed = records.len();
    // an impossible length byte (15 on classic CAN)
    let mut bad_len = CanFrame::extended(0x104E_5203, &[0; 8])
        .unwrap()
        .to_socketcan_record()
        .to_vec();
    bad_len[4] = 15;
    records.push(bad_len);
    let known: [u32; 8] = [20050, 20051, 20052, 20013, 341, 1034, 1036, 12345];
    let services: [u32; 4] = [210, 214, 217, 242];
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    for _ in 0..3000 {
        let r = next();
        let node = 1 + (r >> 8) as u32 % 4;
        let id = match r % 4 {
            0 => (r >> 32) as u32 & 0x1FFF_FFFF,
            1 => (16 << 24) | (known[(r >> 16) as usize % 8] << 8) | node,
            2 => {
                let service = services[(r >> 16) as usize % 4];
                (24 << 24) | (service << 16) | ((r >> 20) as u32 & 1) << 15 | 5 << 8 | 0x80 | node
            }
            _ => (16 << 24) | (1034 << 8) | node,
        };
        let len = 1 + (r >> 40) as usize % 8;
        let mut data: Vec<u8> = (0..len).map(|k| (next() >> (k * 3)) as u8).collect();
        if r % 4 == 1 {
            // single-frame transfers of the messages, of every length
            data[len - 1] = 0xC0 | ((r >> 50) as u8 % 32);
        } else if r % 4 == 3 {
            // esc.Status frames with tail bytes that begin, continue and end transfers
            let tail = [0x80u8, 0x20, 0x00, 0x40, 0x60, 0xC0][(r >> 24) as usize % 6];
            data[len - 1] = tail | ((r >> 50) as u8 % 3);
        }
        records.push(record(CanFrame::extended(id, &data)));
    }
    let dir = common::Dir::new();
    let file = dir.path("garbage.pcapng");
    can_pcapng(&file, &records);
    let fields = [
        "frame.number",
        "can.flags.xtd",
        "dronecan.type_id",
        "dronecan.crc.status",
        "_ws.expert.message",
        "dronecan.hobbywing.statusmsg1.rpm",
        "dronecan.hobbywing.statusmsg2.temperature",
        "dronecan.hobbywing.statusmsg3.mos_t",
        "dronecan.nodestatus.health",
    ];
    let (rows, _) = tshark_can(&file, &fields);
    assert_eq!(rows.len(), records.len());
    // the fixed cases: standard frames, empty, remote and error frames, an invalid service id,
    // an anonymous transfer of more than one frame are not DroneCAN
    for row in &rows[..7] {
        assert_eq!(row[2], "", "{row:?}");
    }
    assert_eq!(rows[7][2], "20050");
    assert!(rows[7][4].contains("payload bytes"), "{:?}", rows[7]);
    assert!(
        rows[8][4].contains("first frame was not seen"),
        "{:?}",
        rows[8]
    );
    assert!(rows[10][4].contains("Toggle bit"), "{:?}", rows[10]);
    let random = &rows[fixed + 1..];
    let claimed = random.iter().filter(|r| !r[2].is_empty()).count();
    let decoded = random
        .iter()
        .filter(|r| r[5..].iter().any(|v| !v.is_empty()))
        .count();
    let crcs = random.iter().filter(|r| !r[3].is_empty()).count();
    assert!(
        claimed > 1000 && decoded > 20 && crcs > 10,
        "{claimed} claimed, {decoded} status messages decoded, {crcs} CRCs checked"
    );
    eprintln!(
        "garbage CAN frames: {claimed} of {} random frames shown as DroneCAN, {decoded} status \
         messages decoded, {crcs} CRCs checked",
        random.len()
    );
}

/// 24 nodes sending `esc.Status` at once (issue 29): each round the first frames of all 24
/// transfers, then their second frames, then their third, 20 rounds. `decode` gives all 480
/// records, node by node as the dissector reassembles them (all 480 transfers, each CRC ok).
#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn twenty_four_nodes_sending_esc_status_at_once_decode_as_they_dissect() {
    use hwfoc::dronecan::{EscStatus, Message};
    use std::collections::BTreeMap;
    need_tshark();
    const NODES: u8 = 24;
    const ROUNDS: u8 = 20;
    let mut records: Vec<Vec<u8>> = Vec::new();
    for round in 0..ROUNDS {
        let transfers: Vec<Vec<_>> = (1..=NODES)
            .map(|node| {
                let status = EscStatus {
                    error_count: 0,
                    voltage: 24.0,
                    current: 1.5,
                    temperature: 300.0,
                    rpm: 1000 + i32::from(round),
                    power_rating_pct: 10,
                    esc_index: node - 1,
                };
                Message::from(status)
                    .frames(16, node, 0, round % 32)
                    .collect()
            })
            .collect();
        assert!(
            transfers[0].len() > 1,
            "esc.Status is a multi-frame transfer"
        );
        for k in 0..transfers[0].len() {
            for t in &transfers {
                records.push(t[k].to_socketcan_record().to_vec());
            }
        }
    }
    let dir = common::Dir::new();
    let file = dir.path("24-nodes.pcapng");
    can_pcapng(&file, &records);
    let mut decoded: BTreeMap<u64, usize> = BTreeMap::new();
    for r in decode(&file, &[]) {
        *decoded.entry(r["node"].as_u64().unwrap()).or_default() += 1;
    }
    let fields = [
        "dronecan.source",
        "dronecan.esc.status.esc_index",
        "dronecan.crc.status",
    ];
    let (rows, _) = tshark_can(&file, &fields);
    assert_eq!(rows.len(), records.len());
    let mut shown: BTreeMap<u64, usize> = BTreeMap::new();
    for row in rows.iter().filter(|r| !r[1].is_empty()) {
        assert_eq!(row[2], "1", "CRC of a reassembled transfer: {row:?}");
        *shown.entry(row[0].parse().unwrap()).or_default() += 1;
    }
    let all: BTreeMap<u64, usize> = (1..=u64::from(NODES))
        .map(|n| (n, usize::from(ROUNDS)))
        .collect();
    assert_eq!(shown, all, "the dissector's transfers by node");
    assert_eq!(decoded, all, "decode's records by node");
}

/// A frame whose checksum matches but whose value is past its protocol's range (an HW-FOC
/// input throttle of raw 16890, 1649 %; an HW5 input voltage of 506.1 V) is shown rejected, with
/// the value named, as `decode` rejects it; the frames around it are shown and decoded.
#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn a_frame_past_its_range_is_rejected_as_decode_rejects_it() {
    need_tshark();
    let dir = common::Dir::new();
    let foc: Vec<u8> = (0..20u16)
        .flat_map(|packet| {
            DataFrame {
                packet,
                throttle_in_raw: if packet == 10 { 16890 } else { 300 },
                voltage_raw: 247,
                ..Default::default()
            }
            .encode()
        })
        .collect();
    let hw5: Vec<u8> = (0..20u16)
        .flat_map(|n| {
            hwfoc::hw5::TelemetryFrame {
                throttle: 20,
                erpm_raw: 1000 + n,
                voltage_raw: if n == 10 { 5061 } else { 504 },
                ..Default::default()
            }
            .encode()
        })
        .collect();
    for (name, baud, bytes) in [("foc.pcapng", 19200, foc), ("hw5.pcapng", 115200, hw5)] {
        let file = dir.path(name);
        let timed: Vec<(f64, u8)> = bytes
            .iter()
            .enumerate()
            .map(|(i, &b)| (i as f64 * 1e-4, b))
            .collect();
        record_reads(&file, baud, 1_700_000_000_000_000_000, &timed, 7);
        assert_eq!(decode(&file, &[]).len(), 19, "{name}: decoded");
        let mut cmd = common::tshark();
        cmd.arg("-X")
            .arg(format!("lua_script:{}", dissector().display()))
            .arg("-r")
            .arg(&file)
            .arg("-V");
        let out = cmd.output().expect("tshark");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8(out.stdout).unwrap();
        let invalid = text.matches("[invalid, not decoded by hwfoc]").count();
        assert_eq!(invalid, 1, "{name}: {text}");
        let named = if baud == 19200 {
            "input throttle 16890 over 1024"
        } else {
            "input voltage 5061 over 1000"
        };
        assert!(
            text.contains(&format!("Out of range: {named}")),
            "{name}: {text}"
        );
    }
}
