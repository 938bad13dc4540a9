//! Tests of [`super::Sources`]: numbering, merging, files and ports alike.

use super::*;
use crate::notice::Notice;
use crate::pcapng;
use crate::record::Record;
use hwfoc::datalink::CHANNELS;
use hwfoc::foc::DataFrame;
use hwfoc::telemetry::AnyFrame;

/// Collects the records (packet number and time), by ESC.
#[derive(Default)]
pub(crate) struct ByEsc(pub(crate) Vec<Vec<(u16, f64)>>);

impl Handler for ByEsc {
    type Error = InputError;

    fn record(&mut self, r: &Record) {
        let esc = usize::from(r.esc);
        if self.0.len() <= esc {
            self.0.resize(esc + 1, Vec::new());
        }
        self.0[esc].push((packet(r), r.t_s.unwrap_or(f64::NAN)));
    }
}

/// The packet number of a record of these tests' HW-FOC and DataLink frames (16 bits).
fn packet(r: &Record) -> u16 {
    u16::try_from(r.packet.expect("HW-FOC and DataLink send packet numbers")).unwrap()
}

/// The bytes of data frames `packets`.
pub(crate) fn wire(packets: std::ops::Range<u16>) -> Vec<u8> {
    packets
        .flat_map(|packet| {
            DataFrame {
                packet,
                ..Default::default()
            }
            .encode()
        })
        .collect()
}

/// The recording the files these tests write are parts of, unless a test says otherwise (as
/// the files of one `hwfoc record` run: see `esc_table.rs`).
pub(crate) fn one_recording() -> pcapng::RecordingId {
    pcapng::RecordingId::from_comment("hwfoc recording 6f1c1a52-8f3e-4d0b-9a57-0c2b3e4d5f60")
        .unwrap()
}

/// A file of [`one_recording`] with one interface per `(port, bytes, first byte's time in
/// ns)`, in the order given; each port's bytes in packets of 7 bytes, 4 ms apart (7 bytes take
/// 3.6 ms at 19200 baud).
pub(crate) fn recording(ports: &[(&str, &[u8], u64)]) -> Vec<u8> {
    let mut w = pcapng::Writer::continuing(Vec::new(), one_recording()).unwrap();
    for (port, _, _) in ports {
        w.add_interface(port, 19200).unwrap();
    }
    for (i, (_, bytes, t0)) in ports.iter().enumerate() {
        for (k, piece) in bytes.chunks(7).enumerate() {
            w.write(i as u32, t0 + k as u64 * 4_000_000, piece).unwrap();
        }
    }
    w.into_inner().unwrap()
}

/// Runs recordings `inputs` (named `rec-0.pcapng`, ...) into a new `H`.
fn run_into<H: Handler + Default>(inputs: Vec<Vec<u8>>) -> (H, Sources)
where
    H::Error: std::fmt::Debug,
{
    let inputs = inputs
        .into_iter()
        .enumerate()
        .map(|(i, bytes)| Input::from_memory(&format!("rec-{i}.pcapng"), bytes).unwrap())
        .collect();
    let mut sources = Sources::new(inputs, Settings::DEFAULT);
    let mut got = H::default();
    sources.run(&mut got).unwrap();
    (got, sources)
}

fn run(inputs: Vec<Vec<u8>>) -> (ByEsc, Sources) {
    run_into(inputs)
}

/// The files of a rotated recording are one stream per port: a frame split between two
/// files is decoded whole, the ports keep their ESC numbers whatever the order of the
/// interfaces in each file, and the records are those of one recording holding every byte.
#[test]
fn recordings_of_the_same_ports_continue_one_stream_each() {
    let (a, b) = (wire(0..30), wire(100..130));
    let t = 1_700_000_000_000_000_000u64;
    // Cut each port's bytes in the middle of a frame, at different places.
    let (a1, a2) = a.split_at(24 * 10 + 5);
    let (b1, b2) = b.split_at(24 * 20 + 17);
    let ms = 4_000_000;
    let whole = recording(&[("/dev/ttyUSB0", &a, t), ("/dev/ttyUSB1", &b, t)]);
    let first = recording(&[("/dev/ttyUSB0", a1, t), ("/dev/ttyUSB1", b1, t)]);
    let a2_t = t + a1.len().div_ceil(7) as u64 * ms;
    let b2_t = t + b1.len().div_ceil(7) as u64 * ms;
    // The second file declares the ports in the other order.
    let second = recording(&[("/dev/ttyUSB1", b2, b2_t), ("/dev/ttyUSB0", a2, a2_t)]);
    let (one, _) = run(vec![whole]);
    let (split, sources) = run(vec![first, second]);
    assert_eq!(sources.escs().len(), 2);
    assert_eq!(split.0[0].len(), 30);
    assert_eq!(split.0[1].len(), 30);
    let packets: Vec<u16> = split.0[1].iter().map(|r| r.0).collect();
    assert_eq!(packets, (100..130).collect::<Vec<_>>());
    // Times are those of the bytes (the split pieces were timed as in the whole file).
    assert_eq!(split.0[0].len(), one.0[0].len());
    assert_eq!(sources.inputs()[1].escs, [1, 0]);
    assert_eq!(
        sources.inputs()[0].bytes + sources.inputs()[1].bytes,
        (a.len() + b.len()) as u64
    );
    for esc in &sources.escs()[..2] {
        assert_eq!(esc.stream.stats().checksum_failures(), 0);
        assert_eq!(esc.stream.stats().bytes_skipped(), 0);
    }
}

/// Hundreds of files of one rotated recording are still one ESC per port.
#[test]
fn a_long_rotated_series_is_not_too_many_escs() {
    let t = 1_700_000_000_000_000_000u64;
    let files: Vec<Vec<u8>> = (0..300u16)
        .map(|k| {
            let bytes = wire(2 * k..2 * k + 2);
            recording(&[("/dev/ttyACM0", &bytes, t + u64::from(k) * 1_000_000_000)])
        })
        .collect();
    let (got, sources) = run(files);
    assert_eq!(sources.escs().len(), 1);
    assert_eq!(got.0[0].len(), 600);
    assert_eq!(sources.escs()[0].stream.stats().lost_packets(), 0);
}

/// Files other than recordings are one ESC each, as before.
#[test]
fn files_without_port_names_are_one_esc_each() {
    let raw = |p| Input::from_memory("a.bin", wire(p)).unwrap();
    let mut sources = Sources::new(vec![raw(0..3), raw(0..3)], Settings::DEFAULT);
    let mut got = ByEsc::default();
    sources.run(&mut got).unwrap();
    assert_eq!(sources.escs().len(), 2);
    assert_eq!((got.0[0].len(), got.0[1].len()), (3, 3));
}

/// Collects the records in the order handed on: ESC, packet, time.
#[derive(Default)]
struct InOrder(Vec<(u8, u16, f64)>);

impl Handler for InOrder {
    type Error = InputError;

    fn record(&mut self, r: &Record) {
        self.0.push((r.esc, packet(r), r.t_s.unwrap_or(f64::NAN)));
    }
}

/// A file of [`one_recording`] as `hwfoc record` writes one: packets of every port in time
/// order, a data frame per packet every 50 ms per port from `t0` (ns), port `p` `p` ms after
/// port 0.
fn live_recording(ports: &[&str], first_packet: u16, frames: u16, t0: u64) -> Vec<u8> {
    live_recording_of(one_recording(), ports, first_packet, frames, t0)
}

/// A file of recording `id` as [`live_recording`] writes one.
fn live_recording_of(
    id: pcapng::RecordingId,
    ports: &[&str],
    first_packet: u16,
    frames: u16,
    t0: u64,
) -> Vec<u8> {
    let mut w = pcapng::Writer::continuing(Vec::new(), id).unwrap();
    for port in ports {
        w.add_interface(port, 19200).unwrap();
    }
    for k in 0..frames {
        for p in 0..ports.len() {
            let t = t0 + u64::from(k) * 50_000_000 + p as u64 * 1_000_000;
            let packet = first_packet.wrapping_add(k);
            w.write(p as u32, t, &wire(packet..packet + 1)).unwrap();
        }
    }
    w.into_inner().unwrap()
}

fn in_order(inputs: Vec<Vec<u8>>) -> (InOrder, Sources) {
    run_into(inputs)
}

/// The queue held at most a 10 s window of two ports at 20 frames a second, and a frame or
/// two more.
fn assert_one_window_of_two_ports(sources: &Sources) {
    let peak = sources.peak_queued();
    assert!(peak <= 2 * 201, "{peak}");
}

fn assert_time_order(records: &[(u8, u16, f64)]) {
    for w in records.windows(2) {
        assert!(
            (w[0].2, w[0].0) < (w[1].2, w[1].0),
            "out of order: {:?} then {:?}",
            w[0],
            w[1]
        );
    }
}

/// A two-ESC recording gives its ESCs' records interleaved in time order, not a window of
/// one ESC then a window of the other.
#[test]
fn the_records_of_a_recording_come_in_time_order() {
    let t0 = 1_795_442_580_000_000_000;
    let rec = live_recording(&["/dev/ttyUSB0", "/dev/ttyUSB1"], 0, 400, t0);
    let (got, sources) = in_order(vec![rec]);
    assert_eq!(got.0.len(), 800);
    assert_time_order(&got.0);
    let escs: Vec<u8> = got.0.iter().take(6).map(|r| r.0).collect();
    assert_eq!(escs, [0, 1, 0, 1, 0, 1]);
    assert_one_window_of_two_ports(&sources);
}

/// Recordings of different ports that overlap in time are merged by time; their ESCs are
/// numbered in the order given, whatever their times.
#[test]
fn several_recordings_are_merged_by_time() {
    let s = 1_000_000_000u64;
    let t0 = 1_795_442_580 * s;
    let late = live_recording(&["/dev/ttyUSB1"], 500, 300, t0 + 5 * s);
    let early = live_recording(&["/dev/ttyUSB0", "/dev/ttyUSB2"], 0, 300, t0);
    let (got, sources) = in_order(vec![late, early]);
    assert_eq!(got.0.len(), 900);
    assert_time_order(&got.0);
    // The later file was given first: its port is ESC 0.
    assert_eq!(sources.esc_table()[0].key.port, "/dev/ttyUSB1");
    assert_eq!(sources.inputs()[1].escs, [1, 2]);
    assert_eq!(got.0[0].0, 1);
    let first_of_late = got.0.iter().position(|r| r.0 == 0).unwrap();
    assert!((got.0[first_of_late].2 - got.0[0].2 - 5.0).abs() < 1e-6);
    // The files of a rotated recording, as in the test above, also come in time order.
    let t = 1_700_000_000_000_000_000u64;
    let whole = live_recording(&["/dev/ttyUSB0", "/dev/ttyUSB1"], 0, 100, t);
    let next = live_recording(&["/dev/ttyUSB1", "/dev/ttyUSB0"], 100, 100, t + 5 * s);
    let (got, sources) = in_order(vec![whole, next]);
    assert_eq!(sources.escs().len(), 2);
    assert_eq!(got.0.len(), 400);
    assert_time_order(&got.0);
}

/// Half an hour of two ESCs: the queue holds about one window of the recording, not the file.
#[test]
fn a_long_recording_is_merged_in_bounded_memory() {
    let frames = 20 * 1800;
    let rec = live_recording(&["/dev/ttyUSB0", "/dev/ttyUSB1"], 0, frames, 1 << 60);
    let (got, sources) = in_order(vec![rec]);
    assert_eq!(got.0.len(), 2 * usize::from(frames));
    assert_time_order(&got.0);
    assert_one_window_of_two_ports(&sources);
    assert!(sources.peak_queued() >= 200, "{}", sources.peak_queued());
}

/// The files of a rotated recording of two ports, given in any order, are one stream per
/// port in time order: the records of the recording they were cut from.
#[test]
fn recordings_of_one_port_are_read_in_time_order_whatever_the_order_given() {
    let s = 1_000_000_000u64;
    let t0 = 1_700_000_000 * s;
    let ports = ["/dev/ttyUSB0", "/dev/ttyUSB1"];
    // Twelve files of 100 frames (5 s) per port, given 3, 10, 5, 0, 7, 2, 9, 4, 11, 6, 1, 8.
    let files: Vec<Vec<u8>> = (0..12u16)
        .map(|k| (k * 7 + 3) % 12)
        .map(|k| live_recording(&ports, 100 * k, 100, t0 + u64::from(k) * 5 * s))
        .collect();
    let (got, sources) = in_order(files);
    assert_eq!(sources.escs().len(), 2);
    assert_eq!(got.0.len(), 2400);
    assert_time_order(&got.0);
    let packets: Vec<u16> = got.0.iter().step_by(2).map(|r| r.1).collect();
    assert_eq!(packets, (0..1200).collect::<Vec<_>>());
    for esc in sources.escs() {
        assert_eq!(esc.stream.stats().lost_packets(), 0);
        assert_eq!(esc.stream.stats().restarts(), 0);
    }
    assert_one_window_of_two_ports(&sources);
}

/// A recording given twice, and a file overlapping part of another of the same port, are
/// decoded once, with a notice saying so; a recording of another port at the same time is
/// not an overlap.
#[test]
fn a_moment_of_a_port_recorded_twice_is_decoded_once() {
    let s = 1_000_000_000u64;
    let t0 = 1_700_000_000 * s;
    let rec = live_recording(&["/dev/ttyUSB0"], 0, 200, t0);
    // Frames 150..250 of the same port: the first half overlaps `rec`.
    let tail = live_recording(&["/dev/ttyUSB0"], 150, 100, t0 + 150 * s / 20);
    let other = live_recording(&["/dev/ttyUSB1"], 0, 200, t0);
    let named = [("a", &rec), ("a", &rec), ("b", &tail), ("c", &other)];
    let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let inputs = named
        .iter()
        .map(|(name, bytes)| {
            let mut input = Input::from_memory(name, bytes.to_vec()).unwrap();
            let sink = std::sync::Arc::clone(&seen);
            input.set_notices(move |n| sink.lock().unwrap().push(n));
            input
        })
        .collect();
    let mut sources = Sources::new(inputs, Settings::DEFAULT);
    let mut got = InOrder::default();
    sources.run(&mut got).unwrap();
    let port0: Vec<u16> = got.0.iter().filter(|r| r.0 == 0).map(|r| r.1).collect();
    assert_eq!(port0, (0..250).collect::<Vec<_>>());
    assert_eq!(got.0.iter().filter(|r| r.0 == 1).count(), 200);
    assert_time_order(&got.0);
    let stats = sources.escs()[0].stream.stats();
    assert_eq!((stats.lost_packets(), stats.duplicate_packets()), (0, 0));
    assert_eq!(stats.bytes_skipped(), 0);
    let seen = seen.lock().unwrap();
    let overlaps: Vec<(&str, &str, f64)> = seen
        .iter()
        .filter_map(|n| match n {
            Notice::Overlap {
                input,
                earlier,
                seconds,
                port,
            } if port == "/dev/ttyUSB0" => Some((input.as_str(), earlier.as_str(), *seconds)),
            _ => None,
        })
        .collect();
    assert_eq!(overlaps.len(), 2, "{seen:?}");
    assert_eq!(overlaps[0].0, "a");
    assert_eq!(overlaps[0].1, "a");
    assert!((overlaps[0].2 - 9.962).abs() < 0.001, "{overlaps:?}");
    assert_eq!((overlaps[1].0, overlaps[1].1), ("b", "a"));
    assert!((overlaps[1].2 - 2.462).abs() < 0.001, "{overlaps:?}");
    assert_eq!(seen.len(), 2, "{seen:?}");
}

/// Raw files (no times) keep the order given, around recordings merged by time.
#[test]
fn untimed_inputs_keep_their_place() {
    let t0 = 1_795_442_580_000_000_000;
    let inputs = vec![
        Input::from_memory("a.bin", wire(0..3)).unwrap(),
        Input::from_memory(
            "r.pcapng",
            live_recording(&["/dev/ttyUSB0", "/dev/ttyUSB1"], 10, 2, t0),
        )
        .unwrap(),
        Input::from_memory("b.bin", wire(20..22)).unwrap(),
    ];
    let mut sources = Sources::new(inputs, Settings::DEFAULT);
    let mut got = InOrder::default();
    sources.run(&mut got).unwrap();
    let order: Vec<(u8, u16)> = got.0.iter().map(|r| (r.0, r.1)).collect();
    assert_eq!(
        order,
        [
            (0, 0),
            (0, 1),
            (0, 2),
            (1, 10),
            (2, 10),
            (1, 11),
            (2, 11),
            (3, 20),
            (3, 21)
        ]
    );
}

/// Hubs and ESCs plugged in together never share an ESC number: a hub's channel 0 is its
/// port's number, its other channels the next numbers after all ports', hub by hub in the
/// order they are found. Live ports ([`PortStreams`](crate::PortStreams)) and a
/// recording of them number them alike, and convert each under its own settings.
#[test]
fn hubs_and_escs_together_number_every_esc_once_live_and_recorded() {
    // Ports 0 and 2 are hubs with all 8 channels (packet = 1000 + 100 * port + channel:
    // an all-zero record would be an empty slot), port 1 an ESC of its own.
    let hub = |port: u16| -> Vec<u8> {
        (0..3)
            .flat_map(|counter| {
                let mut frame = hwfoc::datalink::HubFrame {
                    counter,
                    slots: [None; CHANNELS],
                };
                for (c, slot) in frame.slots.iter_mut().enumerate() {
                    *slot = Some(DataFrame {
                        packet: 1000 + 100 * port + c as u16,
                        ..Default::default()
                    });
                }
                frame.encode()
            })
            .collect()
    };
    // Bytes as they arrived: port 2's first, then port 1's, then port 0's.
    let t = 1_700_000_000_000_000_000u64;
    let arrivals = [(2usize, hub(2)), (1, wire(100..103)), (0, hub(0))];
    let by_esc = |records: Vec<(u8, u16)>| {
        let mut m = std::collections::BTreeMap::<u8, Vec<u16>>::new();
        for (esc, packet) in records {
            m.entry(esc).or_default().push(packet);
        }
        m
    };
    // Port 2, found a hub first, takes 3..=9 for its channels 1..7; port 0 then 10..=16.
    let mut expected = std::collections::BTreeMap::new();
    expected.insert(1, vec![100, 101, 102]);
    for c in 0..8u16 {
        let (esc2, esc0) = if c == 0 {
            (2, 0)
        } else {
            (2 + c as u8, 9 + c as u8)
        };
        expected.insert(esc2, vec![1200 + c; 3]);
        expected.insert(esc0, vec![1000 + c; 3]);
    }

    struct Escs(Vec<(u8, u16)>);
    impl Handler for Escs {
        type Error = InputError;
        fn record(&mut self, r: &Record) {
            self.0.push((r.esc, packet(r)));
        }
        fn frame(&mut self, esc: u8, t: Option<f64>, d: &AnyFrame, settings: &Settings) {
            // ESC 12 (port 0's channel 2) has settings of its own; port 2's channels
            // follow the port's.
            let poles = match esc {
                12 => 7,
                2..=9 => 14,
                _ => Settings::DEFAULT.pole_pairs,
            };
            let scale = if esc == 12 { 100.0 } else { 64.0 };
            assert_eq!(
                (settings.pole_pairs, settings.current_scale),
                (poles, scale)
            );
            if let AnyFrame::Data(f) = d {
                self.record(&Record::new(t, esc, f, settings));
            }
        }
    }
    let names: Vec<String> = (0..3).map(|p| format!("/dev/ttyUSB{p}")).collect();
    let mut map = crate::settings::SettingsMap::from(Settings::DEFAULT);
    let patch = |scale, poles| crate::settings::SettingsPatch {
        current_scale: scale,
        pole_pairs: poles,
        gear_ratio: None,
        v4_volts_per_step: None,
    };
    map.set_port(&names[2], patch(None, Some(14))).unwrap();
    map.set_esc(12, patch(Some(100.0), None)).unwrap();
    let mut streams = crate::stream::PortStreams::with_map(115_200, names.clone(), map.clone());
    let mut live = Escs(Vec::new());
    for (k, (port, bytes)) in arrivals.iter().enumerate() {
        let event = crate::serial::PortEvent::Data {
            port: *port,
            t_ns: t + k as u64 * 100_000_000,
            bytes: bytes.clone(),
        };
        assert!(streams.feed(&event, &mut live).is_some());
    }
    assert_eq!(by_esc(live.0), expected);
    assert_eq!(streams.channel_of(2, 9), Some(7));
    assert_eq!(streams.channel_of(0, 0), Some(0));
    assert_eq!(streams.channel_of(0, 10), Some(1));
    assert_eq!(streams.channel_of(1, 1), None);
    assert_eq!(streams.channel_of(0, 3), None);

    // The recording `hwfoc record` makes of those ports: an interface per port, packets
    // in the order the bytes arrived.
    let mut w = pcapng::Writer::new(Vec::new()).unwrap();
    for name in &names {
        w.add_interface(name, 115_200).unwrap();
    }
    for (k, (port, bytes)) in arrivals.iter().enumerate() {
        w.write(*port as u32, t + k as u64 * 100_000_000, bytes)
            .unwrap();
    }
    let input = Input::from_memory("rec.pcapng", w.into_inner().unwrap()).unwrap();
    let mut sources = Sources::new(vec![input], map);
    let mut recorded = Escs(Vec::new());
    sources.run(&mut recorded).unwrap();
    assert_eq!(by_esc(recorded.0), expected);
}

/// Hub frames `counters` whose `channels` carry an ESC (packet = 1000 + 100 * `id` +
/// channel: an all-zero record would be an empty slot).
pub(crate) fn hub_wire(id: u16, counters: std::ops::Range<u16>, channels: &[usize]) -> Vec<u8> {
    counters
        .flat_map(|counter| {
            let mut frame = hwfoc::datalink::HubFrame::new(counter);
            for &c in channels {
                frame.slots[c] = Some(DataFrame {
                    packet: 1000 + 100 * id + c as u16,
                    ..Default::default()
                });
            }
            frame.encode()
        })
        .collect()
}

/// Collects the packet numbers of the records, by ESC.
#[derive(Default)]
struct Packets(std::collections::BTreeMap<u8, Vec<u16>>);

impl Handler for Packets {
    type Error = InputError;

    fn record(&mut self, r: &Record) {
        self.0.entry(r.esc).or_default().push(packet(r));
    }
}

/// The README's one rule, alike for files, a recording and live ports: each input (or
/// port) is numbered in the order given, a hub's channel 0 keeps its input's number, and
/// its channels 1 to 7 take the next numbers after all inputs', hub by hub as found. So in
/// `summary dl_clean.bin dl_ch5.bin raw.bin` the raw file is ESC 2 (it was 16: each hub's
/// channels were numbered before the next file).
#[test]
fn files_a_recording_and_ports_number_hubs_alike() {
    let all: Vec<usize> = (0..CHANNELS).collect();
    let inputs = [
        hub_wire(0, 0..3, &all),
        hub_wire(1, 0..3, &[5]),
        wire(100..103),
    ];
    let mut expected = std::collections::BTreeMap::<u8, Vec<u16>>::new();
    expected.insert(0, vec![1000; 3]);
    for c in 1..8u16 {
        expected.insert(2 + c as u8, vec![1000 + c; 3]);
    }
    expected.insert(14, vec![1105; 3]);
    expected.insert(2, vec![100, 101, 102]);

    // Files, read one after another.
    let files = inputs
        .iter()
        .zip(["dl_clean.bin", "dl_ch5.bin", "raw.bin"])
        .map(|(bytes, name)| Input::from_memory(name, bytes.clone()).unwrap())
        .collect();
    let mut sources = Sources::new(files, Settings::DEFAULT);
    let mut got = Packets::default();
    sources.run(&mut got).unwrap();
    assert_eq!(got.0, expected, "files");
    assert_eq!(sources.inputs()[2].escs, [2]);

    // Live ports, their bytes arriving in the same order.
    let names: Vec<String> = (0..3).map(|p| format!("/dev/ttyUSB{p}")).collect();
    let t = 1_700_000_000_000_000_000u64;
    let mut streams = crate::stream::PortStreams::with_map(
        115_200,
        names.clone(),
        SettingsMap::from(Settings::DEFAULT),
    );
    let mut live = Packets::default();
    for (port, bytes) in inputs.iter().enumerate() {
        let event = crate::serial::PortEvent::Data {
            port,
            t_ns: t + port as u64 * 100_000_000,
            bytes: bytes.clone(),
        };
        streams.feed(&event, &mut live);
    }
    assert_eq!(live.0, expected, "ports");

    // The recording of those ports.
    let mut w = pcapng::Writer::new(Vec::new()).unwrap();
    for name in &names {
        w.add_interface(name, 115_200).unwrap();
    }
    for (port, bytes) in inputs.iter().enumerate() {
        w.write(port as u32, t + port as u64 * 100_000_000, bytes)
            .unwrap();
    }
    let (recorded, _) = run_into::<Packets>(vec![w.into_inner().unwrap()]);
    assert_eq!(recorded.0, expected, "recording");
}

/// At the end of what the `esc` column numbers, files and live ports alike: 249 ESCs and then
/// a hub, whose channels 1 to 6 take the last numbers (250 to 255) and whose channel 7 has
/// none, its frames not handed on.
#[test]
fn files_and_ports_number_a_hub_alike_at_the_last_esc_number() {
    let all: Vec<usize> = (0..CHANNELS).collect();
    let mut inputs: Vec<Vec<u8>> = (0..249).map(|_| wire(100..103)).collect();
    inputs.push(hub_wire(0, 0..3, &all));
    let mut expected = std::collections::BTreeMap::<u8, Vec<u16>>::new();
    for esc in 0..249u8 {
        expected.insert(esc, vec![100, 101, 102]);
    }
    expected.insert(249, vec![1000; 3]);
    for c in 1..7u16 {
        expected.insert(249 + c as u8, vec![1000 + c; 3]);
    }

    let files = inputs
        .iter()
        .enumerate()
        .map(|(k, bytes)| Input::from_memory(&format!("{k}.bin"), bytes.clone()).unwrap())
        .collect();
    let mut sources = Sources::new(files, Settings::DEFAULT);
    let mut got = Packets::default();
    // The hub's channel 7 would be ESC 256: every other frame is handed on, then the run fails
    // naming the input, never dropping that ESC without a word.
    let error = sources.run(&mut got).unwrap_err();
    assert!(
        matches!(&error, InputError::TooManyEscs { input } if input == "249.bin"),
        "{error}"
    );
    assert_eq!(got.0, expected, "files");
    assert_eq!(sources.escs().len(), 256);

    let names: Vec<String> = (0..inputs.len()).map(|p| format!("port{p}")).collect();
    let mut streams =
        crate::stream::PortStreams::with_map(115_200, names, SettingsMap::from(Settings::DEFAULT));
    let mut live = Packets::default();
    for (port, bytes) in inputs.iter().enumerate() {
        let event = crate::serial::PortEvent::Data {
            port,
            t_ns: 1_700_000_000_000_000_000 + port as u64 * 1_000_000,
            bytes: bytes.clone(),
        };
        streams.feed(&event, &mut live);
    }
    assert_eq!(live.0, expected, "ports");
    assert_eq!(streams.channel_of(249, 255), Some(6));
    assert!(streams.settings_of(255).is_some());
    // Live, the frames of ESC 256 are left out and counted, and told once, naming the port.
    assert_eq!(streams.left_out(249), 3);
    let notices: Vec<String> = streams.take_notices().iter().map(|n| n.line()).collect();
    assert_eq!(
        notices,
        [
            "hwfoc: warning: port249: ESCs past number 255 left out (the first: DataLink channel 7): \
          records number ESCs 0 to 255 only"
        ]
    );
    assert!(streams.take_notices().is_empty());
}

/// Every call a handler gets, in order; `RUNS` says whether it takes runs of untimed data
/// frames (which it hands on one at a time, as the default `untimed_data` does).
#[derive(Debug, Default, PartialEq)]
struct Calls<const RUNS: bool>(Vec<String>);

impl<const RUNS: bool> Handler for Calls<RUNS> {
    type Error = InputError;

    const TAKES_RUNS: bool = RUNS;

    fn frame(&mut self, esc: u8, t: Option<f64>, frame: &AnyFrame, _: &Settings) {
        let what = match frame {
            AnyFrame::Data(d) => format!("{}", hwfoc::Telemetry::packet(d).unwrap_or_default()),
            AnyFrame::Info(_) => "info".to_string(),
        };
        self.0.push(format!("{esc} {t:?} {what}"));
    }

    fn end_batch(&mut self, live: bool) -> Result<(), InputError> {
        self.0.push(format!("end {live}"));
        Ok(())
    }
}

/// A handler that takes runs of a raw input's data frames gets every frame in the order a
/// handler taking them one at a time does: ESC frames, a hub's frames between them, a
/// recording after.
#[test]
fn runs_of_untimed_frames_keep_the_order_of_every_frame() {
    let inputs = || {
        // Hub frames found in one batch, then ESC and hub frames in turn within later ones.
        let mut raw = wire(0..3000);
        raw.extend(hub_wire(0, 0..500, &[0, 2, 5]));
        for k in 0..20u16 {
            raw.extend(wire(3000 + 50 * k..3050 + 50 * k));
            raw.extend(hub_wire(0, 500 + 10 * k..510 + 10 * k, &[0, 2, 5]));
        }
        raw.extend(wire(4000..6000));
        let (a, b) = (wire(10..400), wire(500..900));
        let rec = recording(&[("/dev/ttyA", &a, 1_000_000_000), ("/dev/ttyB", &b, 0)]);
        vec![
            Input::from_memory("raw", raw).unwrap(),
            Input::from_memory("rec", rec).unwrap(),
        ]
    };
    let mut each = Calls::<false>::default();
    Sources::new(inputs(), Settings::DEFAULT)
        .run(&mut each)
        .unwrap();
    let mut runs = Calls::<true>::default();
    Sources::new(inputs(), Settings::DEFAULT)
        .run(&mut runs)
        .unwrap();
    assert!(each.0.len() > 8800, "{} calls", each.0.len());
    assert_eq!(runs.0, each.0);
}

/// A reader that hands its bytes `n` at a time, as a pipe does.
struct Trickle(std::io::Cursor<Vec<u8>>, usize);

impl std::io::Read for Trickle {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = buf.len().min(self.1);
        self.0.read(&mut buf[..n])
    }
}

/// Bytes that change from HW-FOC to a DataLink hub and back give their records in the same
/// order from a file as from standard input in small reads (`decode -`): a hub's frames found
/// in a batch were handed on after the ESC's frames that followed them in that batch.
#[test]
fn a_stream_read_in_any_chunks_gives_its_records_in_one_order() {
    let mut raw = wire(0..300);
    raw.extend(hub_wire(0, 0..5, &[0, 2, 5]));
    raw.extend(wire(300..600));
    raw.extend(hub_wire(0, 5..10, &[0, 2, 5]));
    raw.extend(wire(600..700));
    let calls = |input: Input| {
        let mut calls = Calls::<false>::default();
        Sources::new(vec![input], Settings::DEFAULT)
            .run(&mut calls)
            .unwrap();
        calls.0.retain(|c| !c.starts_with("end "));
        calls.0
    };
    let file = calls(Input::from_memory("raw", raw.clone()).unwrap());
    for n in [7, 100, 4096] {
        let trickle = Trickle(std::io::Cursor::new(raw.clone()), n);
        let stdin = calls(Input::from_reader("-", Box::new(trickle)).unwrap());
        assert_eq!(stdin, file, "read {n} bytes at a time");
    }
    assert_eq!(file.len(), 700 + 10 * 3);
}

/// The data records of each ESC, counted.
#[derive(Default)]
struct Counts(std::collections::BTreeMap<u8, usize>);

impl Handler for Counts {
    type Error = InputError;

    fn record(&mut self, r: &Record) {
        *self.0.entry(r.esc).or_default() += 1;
    }
}

/// A live bus ended with `PortStreams::finish` gives every record its log gives, numbered
/// alike: a Hobbywing node whose GetEscID answer never came has its held records handed on at
/// the end (without it, ESC 13's 13 records of testdata's bus were lost).
#[test]
fn a_live_bus_ended_hands_on_the_records_it_held() {
    let log = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../testdata/dronecan/can-bus.log"
    ))
    .unwrap();
    let input = Input::from_memory("can-bus.log", log.clone()).unwrap();
    let mut sources = Sources::new(vec![input], Settings::DEFAULT);
    let mut want = Counts::default();
    sources.run(&mut want).unwrap();

    let names = vec!["slcan:bus".to_string()];
    let mut streams =
        crate::stream::PortStreams::with_map(115_200, names, SettingsMap::from(Settings::DEFAULT));
    let mut live = Counts::default();
    let text = String::from_utf8(log).unwrap();
    for (i, line) in text.lines().enumerate() {
        let line = crate::can::candump::parse_line(line, i as u64 + 1).unwrap();
        let crate::can::candump::Logged::Classic(frame) = line.frame else {
            continue;
        };
        let event = crate::serial::PortEvent::Data {
            port: 0,
            t_ns: (line.t_s * 1e9) as u64,
            bytes: frame.to_socketcan_record().to_vec(),
        };
        streams.feed(&event, &mut live);
    }
    let before_end = live.0.values().sum::<usize>();
    streams.finish(&mut live);
    assert!(before_end < want.0.values().sum::<usize>());
    assert_eq!(live.0, want.0);
}
