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
