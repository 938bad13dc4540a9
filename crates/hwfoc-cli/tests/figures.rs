//! Figures that stay true: an ESC that restarts (or a simulator restarted on the same port)
//! and interleaved packet sequences count restarts, not lost packets; a large raw file, read in
//! two halves at once, summarises as its bytes read in one go.

mod common;

use serde_json::Value;

use common::{Dir, hwfoc, ok, run};

/// The summary's JSON of `inputs`.
fn summary(inputs: &[&str]) -> Value {
    let mut args = vec!["summary", "--json"];
    args.extend_from_slice(inputs);
    serde_json::from_slice(&ok(run(hwfoc().args(&args))).stdout).unwrap()
}

/// `hwfoc simulate` of one ESC for `seconds` from packet `start`, with `extra` options.
fn simulate(dir: &Dir, name: &str, start: &str, extra: &[&str]) -> Vec<u8> {
    let out = dir.arg(name);
    let mut args = vec![
        "simulate",
        "-o",
        &out,
        "--duration",
        "4",
        "--start-packet",
        start,
    ];
    args.extend_from_slice(extra);
    ok(run(hwfoc().args(&args)));
    std::fs::read(&out).unwrap()
}

#[test]
fn a_restarted_esc_counts_a_restart_not_lost_packets() {
    let dir = Dir::new();
    // The ESC runs from packet 20000, restarts, and counts again from 0: one raw stream.
    let mut wire = simulate(&dir, "a.bin", "20000", &[]);
    wire.extend(simulate(&dir, "b.bin", "0", &[]));
    let both = dir.arg("restart.bin");
    std::fs::write(&both, &wire).unwrap();
    let v = summary(&[&both]);
    let link = &v["escs"][0]["link"];
    assert_eq!(link["restarts"], 1, "{link}");
    assert_eq!(link["lost_packets"], 0, "{link}");
    assert_eq!(link["delivery_ratio"], 1.0, "{link}");
    let text = String::from_utf8(ok(run(hwfoc().args(["summary", &both]))).stdout).unwrap();
    assert!(
        text.contains("0 lost packets, 0 duplicate packets, 1 restarts"),
        "{text}"
    );
}

#[test]
fn interleaved_packet_sequences_count_no_loss() {
    let dir = Dir::new();
    let a = simulate(&dir, "a.bin", "100", &["--seed", "1"]);
    let b = simulate(&dir, "b.bin", "30000", &["--seed", "2"]);
    // Two ESCs on one wire: their data frames in turn.
    let frames = |w: &[u8]| -> Vec<Vec<u8>> {
        let mut out = Vec::new();
        let mut i = 0;
        while i + 24 <= w.len() {
            if w[i] == 0x9B && w[i + 1] == 0x16 {
                out.push(w[i..i + 24].to_vec());
                i += 24;
            } else {
                i += 1;
            }
        }
        out
    };
    let (fa, fb) = (frames(&a), frames(&b));
    let mut wire = Vec::new();
    for (x, y) in fa.iter().zip(&fb) {
        wire.extend_from_slice(x);
        wire.extend_from_slice(y);
    }
    let mixed = dir.arg("mixed.bin");
    std::fs::write(&mixed, &wire).unwrap();
    let v = summary(&[&mixed]);
    let link = &v["escs"][0]["link"];
    assert_eq!(link["lost_packets"], 0, "{link}");
    assert!(link["restarts"].as_u64().unwrap() > 10, "{link}");
}

/// A raw file large enough to be read in two halves at once (64 MiB and more) summarises as the
/// same bytes through a pipe, which are read in one go: with a fault episode across the middle,
/// device information in both halves, a gap and a restart in the packet numbers, and noise.
#[test]
fn a_large_raw_file_summarises_as_its_bytes_through_a_pipe() {
    use hwfoc::Status;
    use hwfoc::foc::{DataFrame, InfoFrame};

    let dir = Dir::new();
    let input = dir.path("large.bin");
    let frames = 3_000_000usize;
    let mut wire = Vec::with_capacity(frames * 24 + 4096);
    let info = |id| {
        InfoFrame::new("XR_FOC_ESC", "HW577", "XR-01.0.00", id)
            .unwrap()
            .encode()
    };
    let mut packet = 0u16;
    for i in 0..frames {
        match i {
            1000 => wire.extend_from_slice(&info("1")),
            2_500_000 => wire.extend_from_slice(&info("2")),
            700_000 => packet = packet.wrapping_add(30),
            2_000_000 => packet = packet.wrapping_add(20_000),
            2_200_000 => wire.extend_from_slice(&[0x9B, 0x16, 0x01, 0x02, 0x00, 0x55]),
            _ => {}
        }
        let faulty = (1_400_000..1_600_000).contains(&i) || i % 100_003 == 0;
        let frame = DataFrame {
            packet,
            throttle_in_raw: (i % 1024) as u16,
            erpm_raw: (i % 50_000) as u16,
            voltage_raw: 400 + (i % 100) as u16,
            current_raw: (i % 3000) as i16 - 200,
            mos_adc: (i / 10_000 % 200) as u8,
            cap_adc: (i / 7_000 % 200) as u8,
            status: Status(if faulty { 0x0040 } else { 0 }),
            ..Default::default()
        };
        wire.extend_from_slice(&frame.encode());
        packet = packet.wrapping_add(1);
    }
    assert!(
        wire.len() >= 64 << 20,
        "the file is large enough to be split"
    );
    std::fs::write(&input, &wire).unwrap();
    let path = input.to_str().unwrap();
    let file = ok(run(hwfoc().args(["summary", "--json", path])));
    let mut piped = hwfoc()
        .args(["summary", "--json", "-"])
        .stdin(std::fs::File::open(&input).unwrap())
        .output()
        .unwrap();
    assert!(piped.status.success());
    piped.stdout = String::from_utf8(piped.stdout)
        .unwrap()
        .replace("standard input", path)
        .into_bytes();
    let (file, piped): (Value, Value) = (
        serde_json::from_slice(&file.stdout).unwrap(),
        serde_json::from_slice(&piped.stdout).unwrap(),
    );
    assert_eq!(file, piped);
    let esc = &file["escs"][0];
    assert_eq!(esc["frames"], frames as u64);
    assert_eq!(esc["link"]["lost_packets"], 30);
    assert_eq!(esc["link"]["restarts"], 1);
    assert_eq!(esc["info"].as_array().unwrap().len(), 2);
    assert_eq!(esc["fault_episodes"][14]["start_frame"], 1_400_000);
}
