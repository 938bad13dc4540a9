//! Rotated recordings and many inputs: each port's recordings are read in the order of their
//! times whatever the order given, a moment recorded twice is decoded once, and any number of
//! files is read with few open at a time.

mod common;

use std::fs;

use common::{Dir, hwfoc, ok, run, stdout};
use hwfoc_io::pcapng;

/// A 4-ESC recording of `seconds` simulated seconds, cut into files of one second each (every
/// file declaring the four ports and naming the recording, as `hwfoc record --rotate-time 1`
/// writes them), named
/// `run-0001.pcapng`, ...; returns the whole recording and the files, in time order.
fn rotated(dir: &Dir, seconds: u32) -> (String, Vec<String>) {
    let whole = dir.arg("run.pcapng");
    let duration = seconds.to_string();
    ok(run(hwfoc().args([
        "simulate",
        "--escs",
        "4",
        "--profile",
        "sine",
        "--duration",
        &duration,
        "-o",
        &whole,
    ])));
    let bytes = fs::read(&whole).unwrap();
    let mut reader = pcapng::Reader::new(&bytes[..]);
    let mut packets = Vec::new();
    while let Some(p) = reader.next_packet().unwrap() {
        let comment = p.comment.map(str::to_string);
        packets.push((p.iface, p.t_ns, p.data.to_vec(), comment));
    }
    assert!(reader.take_damage().is_empty());
    let ports: Vec<String> = reader.interfaces().iter().map(|i| i.name.clone()).collect();
    assert_eq!(ports.len(), 4);
    let recording = reader
        .recording_id()
        .expect("hwfoc's recordings name themselves");
    let mut files: Vec<(u64, pcapng::Writer<Vec<u8>>)> = Vec::new();
    let first_ns = packets[0].1;
    for (iface, t_ns, data, comment) in packets {
        let second = (t_ns - first_ns) / 1_000_000_000;
        if files.last().is_none_or(|f| f.0 != second) {
            let mut w = pcapng::Writer::continuing(Vec::new(), recording).unwrap();
            for port in &ports {
                w.add_interface(port, 19200).unwrap();
            }
            files.push((second, w));
        }
        let w = &mut files.last_mut().unwrap().1;
        match comment {
            Some(text) => w.comment(iface, t_ns, &text).unwrap(),
            None => w.write_packet(iface, t_ns, &data).unwrap(),
        }
    }
    let names = files
        .into_iter()
        .enumerate()
        .map(|(k, (_, w))| {
            let name = dir.arg(&format!("run-{:04}.pcapng", k + 1));
            fs::write(&name, w.into_inner().unwrap()).unwrap();
            name
        })
        .collect();
    (whole, names)
}

/// Asserts that two decodes are the same, naming the first line that differs.
fn same(got: &str, expected: &str) {
    let first = got.lines().zip(expected.lines()).position(|(a, b)| a != b);
    assert!(
        got == expected,
        "{} lines for {}; first difference at line {first:?}",
        got.lines().count(),
        expected.lines().count()
    );
}

fn decode(inputs: &[String]) -> String {
    stdout(&run(hwfoc().arg("decode").args(inputs).args(["-o", "-"])))
}

/// The files of a rotated recording decode to the records of the whole recording, given in
/// name order, in reverse, or scrambled (as `find` lists them); the summary finds no packet
/// lost and no byte skipped.
#[test]
fn a_rotated_series_decodes_the_same_in_any_order() {
    let dir = Dir::new();
    let (whole, files) = rotated(&dir, 20);
    assert!(files.len() >= 20, "{}", files.len());
    let expected = decode(std::slice::from_ref(&whole));
    same(&decode(&files), &expected);
    let mut reversed = files.clone();
    reversed.reverse();
    same(&decode(&reversed), &expected);
    let n = files.len();
    let scrambled: Vec<String> = (0..n).map(|k| files[(k * 7 + 3) % n].clone()).collect();
    assert_eq!(
        (0..n)
            .map(|k| (k * 7 + 3) % n)
            .collect::<std::collections::BTreeSet<_>>()
            .len(),
        n
    );
    same(&decode(&scrambled), &expected);
    let summary = stdout(&run(hwfoc().arg("summary").args(&scrambled)));
    assert_eq!(
        summary
            .matches(" 0 lost packets, 0 duplicate packets, 0 restarts, 0 bytes skipped")
            .count(),
        4,
        "{summary}"
    );
}

/// The same recording given twice (or files of it that overlap it) decodes as once, with a
/// warning naming both: charge, energy and duration are those of the recording, not twice them.
#[test]
fn a_recording_given_twice_is_decoded_once() {
    let dir = Dir::new();
    let (whole, files) = rotated(&dir, 6);
    let once = decode(std::slice::from_ref(&whole));
    let o = ok(run(hwfoc()
        .arg("decode")
        .args([&whole, &whole])
        .args(["-o", "-"])));
    same(&String::from_utf8(o.stdout).unwrap(), &once);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        err,
        format!("hwfoc: warning: {whole} holds the same bytes as {whole}: read once\n")
    );
    // The whole recording and its own pieces (the same recording), in any order: the moments
    // the pieces give again are decoded once, with a warning per port.
    let mut both = files.clone();
    both.insert(2, whole.clone());
    let o = ok(run(hwfoc().arg("decode").args(&both).args(["-o", "-"])));
    same(&String::from_utf8(o.stdout).unwrap(), &once);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains(": esc-0 overlaps "), "{err}");
    let summary = |inputs: &[String]| {
        let out = stdout(&run(hwfoc().arg("summary").args(inputs)));
        out.lines()
            .filter(|l| l.starts_with("total") || l.starts_with("time"))
            .map(str::to_string)
            .collect::<Vec<_>>()
    };
    assert_eq!(summary(&[whole.clone(), whole.clone()]), summary(&[whole]));
}

/// Hundreds of files are read with few open at once (a year of rotated recordings is more
/// files than a process may open), to the same records as the recording they were cut from.
#[cfg(unix)]
#[test]
fn more_files_than_may_be_open_at_once() {
    let dir = Dir::new();
    let (whole, files) = rotated(&dir, 300);
    assert!(files.len() >= 300);
    let list = dir.arg("list");
    fs::write(&list, files.join("\n")).unwrap();
    let out = dir.arg("out.jsonl");
    let script = format!(
        "ulimit -n 64 && xargs -d '\\n' {} decode -o {out} < {list}",
        env!("CARGO_BIN_EXE_hwfoc")
    );
    ok(run(std::process::Command::new("sh").args(["-c", &script])));
    let expected = decode(&[whole]);
    same(&fs::read_to_string(&out).unwrap(), &expected);
}
