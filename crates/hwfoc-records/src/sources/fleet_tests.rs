//! Tests of which stream is which ESC across inputs (`esc_table.rs`): recordings of other
//! drones with the same port names, rotated series, duplicates, `--join`.

use std::sync::{Arc, Mutex};

use proptest::prelude::*;

use super::tests::ByEsc;
use super::*;
use crate::esc_table::Recording;
use crate::input::file::memory::MemoryFile;
use crate::notice::Notice;
use crate::pcapng::{self, RecordingId};

const S: u64 = 1_000_000_000;
const T0: u64 = 1_795_000_000 * S;

/// A port of a recording: its name, its first packet number, its frames and the time of the
/// first (ns); a frame every 50 ms.
#[derive(Debug, Clone)]
struct Port {
    name: &'static str,
    first: u16,
    frames: u16,
    t0: u64,
}

impl Port {
    fn time(&self, k: u16) -> u64 {
        self.t0 + u64::from(k) * 50_000_000
    }
}

/// A file of recording `id` (`None`: another program's, naming no recording) holding the frames
/// of `ports` whose times are in `from..to`, every port's packets in time order.
fn file(id: Option<RecordingId>, ports: &[Port], from: u64, to: u64) -> Vec<u8> {
    let mut w = pcapng::Writer::continuing(Vec::new(), id.unwrap_or_default()).unwrap();
    for p in ports {
        w.add_interface(p.name, 19200).unwrap();
    }
    let mut packets: Vec<(u64, u32, u16)> = Vec::new();
    for (i, p) in ports.iter().enumerate() {
        for k in 0..p.frames {
            let t = p.time(k);
            if (from..to).contains(&t) {
                packets.push((t, i as u32, p.first.wrapping_add(k)));
            }
        }
    }
    packets.sort();
    for (t, i, packet) in packets {
        let bytes = hwfoc::foc::DataFrame {
            packet,
            ..Default::default()
        }
        .encode();
        w.write(i, t, &bytes).unwrap();
    }
    let bytes = w.into_inner().unwrap();
    match id {
        Some(_) => bytes,
        None => foreign(bytes),
    }
}

/// `bytes` as another program would have written them: the section header names no
/// recording (its comment says something else, of the same length).
fn foreign(mut bytes: Vec<u8>) -> Vec<u8> {
    let at = bytes
        .windows(16)
        .position(|w| w == b"hwfoc recording ")
        .unwrap();
    bytes[at..at + 16].copy_from_slice(b"other recording ");
    bytes
}

/// Reads `files` (files named `f-K.pcapng`, so that copies are found) together:
/// the records by ESC, the notices, and the sources.
fn read(files: &[Vec<u8>], join: bool) -> (ByEsc, Vec<Notice>, Sources) {
    let seen = Arc::new(Mutex::new(Vec::new()));
    let inputs = files
        .iter()
        .enumerate()
        .map(|(k, bytes)| {
            let file = MemoryFile::new(&format!("f-{k}.pcapng"), bytes.clone());
            let mut input = file.input().unwrap();
            let sink = Arc::clone(&seen);
            input.set_notices(move |n| sink.lock().unwrap().push(n));
            input
        })
        .collect();
    let mut sources = Sources::new(inputs, Settings::DEFAULT);
    if join {
        sources.join_recordings();
    }
    let mut got = ByEsc::default();
    sources.run(&mut got).unwrap();
    let seen = seen.lock().unwrap().clone();
    (got, seen, sources)
}

/// The records of each port of a recording read alone, in port order.
fn alone(ports: &[Port]) -> Vec<Vec<(u16, f64)>> {
    let (got, _, sources) = read(&[file(None, ports, 0, u64::MAX)], false);
    assert_eq!(sources.escs().len(), ports.len());
    got.0
}

fn port(name: &'static str, first: u16, frames: u16, t0: u64) -> Port {
    Port {
        name,
        first,
        frames,
        t0,
    }
}

/// Three drones recorded at the same time, each on ports named alike: six ESCs, each with the
/// records of its file read alone, numbered in the order given, and a note for each later
/// drone naming the earlier one.
#[test]
fn drones_recorded_at_the_same_time_are_other_escs() {
    let drones: Vec<Vec<Port>> = (0..3u16)
        .map(|d| {
            vec![
                port("esc-0", 100 * d, 200, T0 + u64::from(d) * S / 7),
                port("esc-1", 1000 + 100 * d, 190, T0 + u64::from(d) * S / 5),
            ]
        })
        .collect();
    let files: Vec<Vec<u8>> = drones
        .iter()
        .map(|ports| file(Some(RecordingId::new()), ports, 0, u64::MAX))
        .collect();
    let (got, notices, sources) = read(&files, false);
    assert_eq!(sources.escs().len(), 6);
    for (d, ports) in drones.iter().enumerate() {
        assert_eq!(sources.inputs()[d].escs, [2 * d, 2 * d + 1]);
        let want = alone(ports);
        assert_eq!(got.0[2 * d], want[0], "drone {d} esc-0");
        assert_eq!(got.0[2 * d + 1], want[1], "drone {d} esc-1");
        for esc in [2 * d, 2 * d + 1] {
            let stats = sources.escs()[esc].stream.stats();
            assert_eq!((stats.lost_packets(), stats.restarts()), (0, 0));
            assert_eq!(stats.bytes_skipped(), 0);
        }
    }
    let notes: Vec<_> = notices
        .iter()
        .filter_map(|n| match n {
            Notice::SamePortNames {
                input,
                earlier,
                ports,
            } => Some((input.as_str(), earlier.as_str(), ports.clone())),
            _ => None,
        })
        .collect();
    assert_eq!(notes.len(), 2, "{notices:?}");
    assert!(notes[0].0.ends_with("f-1.pcapng") && notes[0].1.ends_with("f-0.pcapng"));
    assert_eq!(
        notes[0].2,
        [("esc-0".to_string(), 2, 0), ("esc-1".to_string(), 3, 1)]
    );
    assert!(notes[1].0.ends_with("f-2.pcapng") && notes[1].1.ends_with("f-0.pcapng"));
    assert_eq!(notices.len(), 2, "{notices:?}");
    // With --join they are one recording again, as the user asked: one ESC per port name.
    let (_, _, joined) = read(&files, true);
    assert_eq!(joined.escs().len(), 2);
}

/// Drones flown one after another, each recorded by another program on a port of one name:
/// other ESCs, with a note suggesting `--join` since the times line up; joined, one stream.
#[test]
fn files_naming_no_recording_are_joined_only_when_asked() {
    let ports = [port("/dev/ttyUSB0", 0, 400, T0)];
    let cut = ports[0].time(200);
    let first = file(None, &ports, 0, cut);
    let second = file(None, &ports, cut, u64::MAX);
    let (got, notices, sources) = read(&[first.clone(), second.clone()], false);
    assert_eq!(sources.escs().len(), 2);
    assert_eq!((got.0[0].len(), got.0[1].len()), (200, 200));
    assert!(matches!(
        sources.esc_table()[1].key.recording,
        Recording::Input(1)
    ));
    let [
        Notice::MayContinue {
            ports: named, gap, ..
        },
    ] = notices.as_slice()
    else {
        panic!("{notices:?}");
    };
    assert_eq!(named, &["/dev/ttyUSB0".to_string()]);
    // From the last byte of frame 199 to the first of frame 200.
    assert!(*gap > 0.03 && *gap < 0.05, "{gap}");
    let line = notices[0].line();
    assert!(line.contains("--join"), "{line}");
    let (got, notices, sources) = read(&[second, first], true);
    assert_eq!(sources.escs().len(), 1);
    assert_eq!(got.0[0], alone(&ports)[0]);
    assert!(notices.is_empty(), "{notices:?}");
    assert_eq!(sources.escs()[0].stream.stats().lost_packets(), 0);
}

/// A file given twice, or a copy of it, is read once, with a warning naming both; the
/// summary's inputs say which it copies.
#[test]
fn a_file_given_twice_is_read_once() {
    let ports = [port("esc-0", 0, 100, T0), port("esc-1", 0, 100, T0)];
    let rec = file(Some(RecordingId::new()), &ports, 0, u64::MAX);
    let other = file(Some(RecordingId::new()), &ports, 0, u64::MAX);
    let (got, notices, sources) = read(&[rec.clone(), other, rec], false);
    assert_eq!(sources.escs().len(), 4);
    assert_eq!(got.0.iter().map(Vec::len).sum::<usize>(), 400);
    assert_eq!(sources.inputs()[2].duplicate_of, Some(0));
    assert!(sources.inputs()[2].escs.is_empty());
    let dups: Vec<_> = notices
        .iter()
        .filter(|n| matches!(n, Notice::Duplicate { .. }))
        .collect();
    assert_eq!(dups.len(), 1, "{notices:?}");
    assert!(
        dups[0]
            .line()
            .contains("f-2.pcapng holds the same bytes as")
    );
}

/// A random fleet: recordings of ports named from a small pool at overlapping times, some cut
/// in rotated files (one recording id), some files given twice, some written by another
/// program; the files given in a random order.
#[derive(Debug, Clone)]
struct Fleet {
    recordings: Vec<(bool, Vec<Port>, Vec<u64>)>,
    copies: Vec<usize>,
    order: Vec<usize>,
}

const NAMES: [&str; 3] = ["/dev/ttyUSB0", "esc-0", "esc-1"];

fn fleet() -> impl Strategy<Value = Fleet> {
    let recording = (
        any::<bool>(),
        prop::sample::subsequence(NAMES.to_vec(), 1..=3),
        0u64..20,
        prop::collection::vec(1u64..60, 0..3),
        any::<u16>(),
        20u16..120,
    )
        .prop_map(|(ours, names, start, cuts, first, frames)| {
            let t0 = T0 + start * S / 2;
            let ports: Vec<Port> = names
                .into_iter()
                .enumerate()
                .map(|(i, name)| port(name, first.wrapping_add(i as u16 * 7), frames, t0))
                .collect();
            // Cuts within the recording's time, in order: its files (a foreign recording is
            // one file: its parts could not be told to be one).
            let mut cuts: Vec<u64> = if ours {
                // At frames, so that every file holds one at least.
                cuts.into_iter()
                    .map(|c| t0 + (c * u64::from(frames) / 60).max(1) * 50_000_000)
                    .collect()
            } else {
                Vec::new()
            };
            cuts.sort_unstable();
            cuts.dedup();
            (ours, ports, cuts)
        });
    prop::collection::vec(recording, 1..8)
        .prop_flat_map(|recordings| {
            let files: usize = recordings.iter().map(|r| r.2.len() + 1).sum();
            (
                Just(recordings),
                prop::collection::vec(0..files, 0..3),
                Just(files),
            )
        })
        .prop_flat_map(|(recordings, copies, files)| {
            let order = Just((0..files + copies.len()).collect::<Vec<_>>()).prop_shuffle();
            (Just(recordings), Just(copies), order)
        })
        .prop_map(|(recordings, copies, order)| Fleet {
            recordings,
            copies,
            order,
        })
        .prop_filter("2 to 20 files", |f| (2..=20).contains(&f.order.len()))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// The records of a fleet's files read together are, ESC for ESC, those of each recording
    /// read alone: a rotated recording's files continue its ports, a file given twice is read
    /// once, and nothing else joins, whatever the port names and times.
    #[test]
    fn a_fleet_read_together_is_each_recording_read_alone(f in fleet()) {
        // Every file, with the recording and the port names it holds.
        let mut files: Vec<(usize, Vec<u8>)> = Vec::new();
        for (r, (ours, ports, cuts)) in f.recordings.iter().enumerate() {
            let id = ours.then(RecordingId::new);
            let mut bounds = vec![0];
            bounds.extend(cuts);
            bounds.push(u64::MAX);
            for w in bounds.windows(2) {
                files.push((r, file(id, ports, w[0], w[1])));
            }
        }
        for &c in &f.copies {
            let copy = files[c].clone();
            files.push(copy);
        }
        let given: Vec<Vec<u8>> = f.order.iter().map(|&k| files[k].1.clone()).collect();
        let (got, _, sources) = read(&given, false);
        let table = sources.esc_table();
        let mut seen = 0;
        for (r, (_, ports, _)) in f.recordings.iter().enumerate() {
            let want = alone(ports);
            for (p, port) in ports.iter().enumerate() {
                // The ESC of this recording's port: the one found in its first file given.
                let first_given = f.order.iter().position(|&k| files[k].0 == r).unwrap();
                let esc = sources.inputs()[first_given]
                    .escs
                    .iter()
                    .copied()
                    .find(|&e| table[e].key.port == port.name)
                    .or_else(|| {
                        let dup = sources.inputs()[first_given].duplicate_of?;
                        sources.inputs()[dup].escs.iter().copied().find(|&e| table[e].key.port == port.name)
                    });
                let esc = esc.expect("every port is an ESC");
                let records = got.0.get(esc).cloned().unwrap_or_default();
                prop_assert_eq!(&records, &want[p], "recording {} port {}", r, port.name);
                seen += 1;
            }
        }
        prop_assert_eq!(sources.escs().len(), seen);
    }
}
