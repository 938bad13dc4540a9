//! A live session's figures against `hwfoc summary --json`'s for the same bytes.

use super::*;
use hwfoc_records::pcapng::Reader;
use serde_json::Value;

const RECORDING: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../testdata/recordings/chunked-2esc.pcapng"
);

/// Port 0's chunks of the recording: (bytes, last byte's time in Unix µs), and its baud.
fn port0_chunks(bytes: &[u8]) -> (Vec<(Vec<u8>, f64)>, u32) {
    let mut reader = Reader::new(bytes);
    let mut chunks = Vec::new();
    let mut baud = DEFAULT_BAUD;
    while let Some(p) = reader.next_packet().unwrap() {
        if p.iface != 0 || p.data.is_empty() {
            continue;
        }
        baud = p.interface.baud.unwrap_or(DEFAULT_BAUD);
        let last_ns = p.t_ns as f64 + (p.data.len() - 1) as f64 * p.interface.byte_ns();
        chunks.push((p.data.to_vec(), last_ns / 1000.0));
    }
    (chunks, baud)
}

#[test]
fn a_port_fed_in_chunks_gives_the_summary_figures_of_its_recording() {
    let bytes = std::fs::read(RECORDING).unwrap();
    let (chunks, baud) = port0_chunks(&bytes);
    assert!(chunks.len() > 10, "{} chunks", chunks.len());
    let want: Value =
        serde_json::from_str(&crate::file::open("rec.pcapng", bytes).summary).unwrap();
    let want = &want["escs"][0];
    let mut session = Session::new(None, "port0", Some(baud)).unwrap();
    for (chunk, t) in &chunks {
        // In pieces, as a port's reads come.
        for (i, piece) in chunk.chunks(7).enumerate() {
            let end = (i * 7 + piece.len() - 1) as f64;
            let t_piece =
                t - (chunk.len() as f64 - 1.0 - end) * hwfoc::wire::byte_ns(baud) / 1000.0;
            session.feed(piece, Some(t_piece));
        }
    }
    session.finish();
    let (esc, got, link) = session.escs().next().unwrap();
    assert_eq!(esc, 0);
    assert_eq!(Some(got.frames), want["frames"].as_u64());
    assert!(got.frames > 0);
    assert_eq!(Some(got.info_frames), want["info_frames"].as_u64());
    let l = &want["link"];
    assert_eq!(
        Some(u64::from(link.lost_packets())),
        l["lost_packets"].as_u64()
    );
    assert_eq!(
        Some(u64::from(link.checksum_failures())),
        l["checksum_failures"].as_u64()
    );
    assert_eq!(Some(link.bytes_skipped()), l["bytes_skipped"].as_u64());
    let e = &want["energy"];
    let close = |a: f64, b: &Value| (a - b.as_f64().unwrap()).abs() <= 1e-6 * a.abs().max(1.0);
    assert!(got.powered);
    assert!(
        close(got.energy.charge_mah(), &e["charge_mah"]),
        "{} vs {}",
        got.energy.charge_mah(),
        e["charge_mah"]
    );
    assert!(
        close(got.energy.energy_wh(), &e["energy_wh"]),
        "{} vs {}",
        got.energy.energy_wh(),
        e["energy_wh"]
    );
}

/// A CAN bus log's frames as an SLCAN port's session is fed them: (SocketCAN record, Unix µs).
fn bus_records(log: &str) -> Vec<([u8; 16], f64)> {
    use hwfoc_records::can::candump::{Logged, parse_line};
    log.lines()
        .enumerate()
        .filter_map(|(i, l)| match parse_line(l, i as u64 + 1).unwrap().frame {
            Logged::Classic(f) => {
                Some((f.to_socketcan_record(), parse_line(l, 1).unwrap().t_s * 1e6))
            }
            Logged::Fd => None,
        })
        .collect()
}

#[test]
fn an_slcan_bus_gives_the_summary_figures_of_its_log() {
    slcan_bus_read(1);
}

fn slcan_bus_read(lines: usize) {
    let log = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../testdata/dronecan/can-bus.log"
    ))
    .unwrap();
    let want: Value =
        serde_json::from_str(&crate::file::open("bus.log", log.clone().into_bytes()).summary)
            .unwrap();
    let mut session = Session::new(None, "slcan:bus", None).unwrap();
    for group in bus_records(&log).chunks(lines) {
        let bytes: Vec<u8> = group.iter().flat_map(|(r, _)| r.to_vec()).collect();
        session.feed(&bytes, group.last().map(|(_, t)| *t));
    }
    session.finish();
    let got: Vec<_> = session.escs().filter(|(_, f, _)| f.frames > 0).collect();
    let want: Vec<_> = want["escs"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["frames"].as_u64() > Some(0))
        .collect();
    let figs: Vec<_> = got
        .iter()
        .map(|(e, f, l)| (*e, f.frames, l.lost_packets()))
        .collect();
    let wants: Vec<_> = want
        .iter()
        .map(|w| {
            (
                w["esc"].clone(),
                w["frames"].clone(),
                w["link"]["lost_packets"].clone(),
            )
        })
        .collect();
    assert_eq!(got.len(), want.len(), "{figs:?} vs {wants:?}");
    for ((esc, figures, link), w) in got.iter().zip(&want) {
        assert_eq!(Some(*esc as u64), w["esc"].as_u64());
        assert_eq!(Some(figures.frames), w["frames"].as_u64(), "esc {esc}");
        let lost = link
            .counts_packets()
            .then(|| u64::from(link.lost_packets()));
        assert_eq!(
            lost,
            w["link"]["lost_packets"].as_u64(),
            "esc {esc}'s lost packets"
        );
    }
}
