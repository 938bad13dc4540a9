//! CAN buses in pcapng recordings (`LINKTYPE_CAN_SOCKETCAN`): written one packet per frame,
//! read back as an input's CAN stream; and tshark reads them as CAN frames.

use std::process::Command;

use hwfoc::dronecan::CanFrame;
use hwfoc_io::pcapng::{LINKTYPE_CAN_SOCKETCAN, Reader, Writer};
use hwfoc_io::{Input, InputFormat};

const T0: u64 = 1_700_000_000_000_000_000;

fn frames() -> Vec<CanFrame> {
    vec![
        CanFrame::extended(0x1004_E27F, &[0x00, 0xC0]).unwrap(),
        CanFrame::extended(0x104E_5201, &[1, 2, 3, 4, 5, 6, 0xC1]).unwrap(),
        CanFrame::standard(0x123, &[0xAB]).unwrap(),
        CanFrame::remote(0x7FF, false, 3).unwrap(),
    ]
}

/// A recording of a serial port and a CAN bus: the frames at 10 ms apart, the last one
/// written as the 8-byte header and its data only.
fn recording() -> Vec<u8> {
    let mut w = Writer::new(Vec::new()).unwrap();
    assert_eq!(w.add_interface("/dev/ttyUSB0", 19200).unwrap(), 0);
    assert_eq!(
        w.add_can_interface("slcan:/dev/ttyACM0", Some(500_000))
            .unwrap(),
        1
    );
    w.write(0, T0, &[0x55, 0x55]).unwrap();
    let frames = frames();
    for (k, f) in frames[..3].iter().enumerate() {
        w.write_can(1, T0 + k as u64 * 10_000_000, &f.to_socketcan_record())
            .unwrap();
    }
    let short = CanFrame::standard(0x100, &[9, 8])
        .unwrap()
        .to_socketcan_record();
    w.write_packet(1, T0 + 30_000_000, &short[..10]).unwrap();
    // Records back to back through `write`, as a recorder hands a CAN port's bytes on.
    w.write(1, T0 + 40_000_000, &frames[3].to_socketcan_record())
        .unwrap();
    assert!(w.write(1, T0, &[0; 15]).is_err());
    assert!(w.write_can(0, T0, &[0; 16]).is_err());
    w.into_inner().unwrap()
}

#[test]
fn can_interfaces_are_written_and_read_back_as_can_streams() {
    let file = recording();
    let mut reader = Reader::new(&file[..]);
    while reader.next_packet().unwrap().is_some() {}
    let ifaces = reader.interfaces();
    assert_eq!(u32::from(ifaces[1].link_type), LINKTYPE_CAN_SOCKETCAN);
    assert!(ifaces[1].is_can() && !ifaces[0].is_can());
    assert_eq!(ifaces[1].baud, Some(500_000));
    assert_eq!(ifaces[1].description, "CAN bus (DroneCAN), 500000 bit/s");

    let mut input = Input::from_memory("bus.pcapng", file).unwrap();
    assert_eq!(input.format(), InputFormat::RECORDING);
    let mut can = Vec::new();
    let mut serial = Vec::new();
    while let Some(b) = input.next_batch().unwrap() {
        let times = b.times.unwrap();
        if b.stream == 0 {
            serial.extend_from_slice(b.bytes);
            continue;
        }
        assert_eq!(b.stream, 1);
        for (k, record) in b.bytes.chunks(16).enumerate() {
            let record: &[u8; 16] = record.try_into().unwrap();
            let t = &times[16 * k..16 * k + 16];
            assert!(t.iter().all(|&x| x == t[0]));
            can.push((t[0], CanFrame::from_socketcan_record(record).unwrap()));
        }
    }
    assert_eq!(serial, [0x55, 0x55]);
    assert!(input.is_can(1) && !input.is_can(0));
    assert_eq!(input.stream_name(1), "slcan:/dev/ttyACM0");
    let mut want = frames();
    want.insert(3, CanFrame::standard(0x100, &[9, 8]).unwrap());
    assert_eq!(can.iter().map(|c| c.1).collect::<Vec<_>>(), want);
    for (k, (t, _)) in can.iter().enumerate() {
        let expected = (T0 + k as u64 * 10_000_000) as f64 * 1e-9;
        assert!((t - expected).abs() < 1e-6, "{k}: {t} vs {expected}");
    }
}

/// tshark (Wireshark's own SocketCAN dissector) reads the recording's CAN interface as CAN
/// frames with their ids and data.
#[test]
#[ignore = "needs tshark"]
fn tshark_reads_can_frames() {
    let found = Command::new("tshark")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    assert!(
        found,
        "needs tshark: install it (Debian: apt-get install tshark), as .ci/run does"
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bus.pcapng");
    std::fs::write(&path, recording()).unwrap();
    let out = Command::new("tshark")
        .args(["-r", path.to_str().unwrap(), "-Y", "can", "-T", "fields"])
        .args([
            "-e",
            "can.id",
            "-e",
            "can.flags.xtd",
            "-e",
            "can.flags.rtr",
            "-e",
            "can.len",
        ])
        .args(["-e", "data.data", "-e", "frame.time_epoch"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let rows: Vec<Vec<&str>> = text.lines().map(|l| l.split('\t').collect()).collect();
    assert_eq!(rows.len(), 5, "{text}");
    let got: Vec<(String, String, String, String)> = rows
        .iter()
        .map(|r| {
            (
                r[0].to_string(),
                r[1].to_string(),
                r[3].to_string(),
                r[4].to_string(),
            )
        })
        .collect();
    let want = [
        ("268755583", "1", "2", "00c0"), // 0x1004E27F
        ("273568257", "1", "7", "010203040506c1"),
        ("291", "0", "1", "ab"),
        ("256", "0", "2", "0908"),
        ("2047", "0", "3", "000000"), // a remote frame: its requested length, no data sent
    ];
    let want: Vec<_> = want
        .iter()
        .map(|w| {
            (
                w.0.to_string(),
                w.1.to_string(),
                w.2.to_string(),
                w.3.to_string(),
            )
        })
        .collect();
    assert_eq!(got, want, "{text}");
    let rtr: Vec<&str> = rows.iter().map(|r| r[2]).collect();
    assert_eq!(rtr, ["0", "0", "0", "0", "1"], "{text}");
    assert!(rows[1][5].starts_with("1700000000.01"), "{text}");
}
