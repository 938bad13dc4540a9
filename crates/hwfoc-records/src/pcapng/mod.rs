//! Recordings in pcapng, the capture format of Wireshark and tshark.
//!
//! A CAN bus is recorded as an interface of link type [`LINKTYPE_CAN_SOCKETCAN`] (`if_name` the
//! bus, `if_speed` its bit rate when known), one packet per frame (its 16-byte record) at the
//! frame's receive time ([`Writer::add_can_interface`], [`Writer::write_can`]; read back with
//! [`Packet::can_frame`]). What follows is the serial ports' layout.
//!
//! A recording holds the bytes received on one or more serial ports exactly as they arrived,
//! every byte in order, with its receive time:
//! - a section header block (SHB) naming the writing application (`shb_userappl` = `hwfoc` and
//!   its version) and the recording (`opt_comment` = `hwfoc recording UUID`, [`RecordingId`]:
//!   the same in every file of one `hwfoc record` run, rotated files alike, so that files are
//!   read as one recording only when they are one);
//! - one interface description block (IDB) per port: link type [`LINKTYPE`] (`LINKTYPE_USER0`,
//!   raw UART bytes), `if_name` = the port, `if_description` its format when known: "HW5
//!   telemetry (hwfoc), 115200 baud 8N1" ("ESC telemetry (hwfoc), 19200 baud 8N1" when not;
//!   "HW-FOC telemetry, 19200 baud 8N1" before hwfoc named formats), `if_speed` = the baud rate, `if_tsresol` = 9 (nanoseconds);
//! - one enhanced packet block (EPB) per frame, holding exactly the frame's bytes, timestamped
//!   with the Unix time in nanoseconds of its first byte; the bytes between frames (line noise,
//!   frames that fail their checksum) in packets of their own, one per read of the port they
//!   came in, each timestamped with its first byte's time. Byte `i` of a packet arrived at
//!   `t_ns + i * 10e9 / baud` ns (8N1: ten bits per byte). The EPBs carry no options: 32 bytes
//!   of block around the frame (a data frame of 24 bytes takes 56 bytes of file);
//! - notes such as a gap while a port was unplugged are an EPB with no bytes and an
//!   `opt_comment` (Wireshark shows them as a 0-byte packet carrying the comment).
//!
//! The cut at frames ([`Writer::write`]; the frames are found by the codec's decoder, module
//! `cut`) makes each packet one frame in Wireshark (with the dissector `hwfoc wireshark install`
//! puts in place) and the file small: about 2.4 times the bytes on the wire, where the
//! read-chunk layout (one packet per read of the port, cut anywhere in the frames) takes 4.8.
//! [`Reader`] reads both alike: the bytes of each port, concatenated in file order, are the
//! stream, and every frame's first byte has the same time in both (to a nanosecond's rounding).
//! Packets of different ports may be a frame's length out of time order in the file, since a
//! frame is written when it is complete.
//!
//! The blocks are written and read here by hand rather than with the `pcap-file` crate (2.0):
//! its EPB reader takes the raw timestamp as nanoseconds whatever the interface's `if_tsresol`
//! says (so a file at the default microsecond resolution reads 1000 times too early), and its
//! streaming reader stops at the first damaged or cut-off block without telling at which byte.
//! A recording cut short by a crash or `kill -9` is exactly the case this format must survive:
//! [`Reader`] reads every complete block, skips over damaged ones to the next valid block, and
//! reports each place it could not read, with its byte offset, as [`Damage`]. The three block
//! types the writer needs are a few lines each.
//!
//! [`Writer`] (module `write`) and [`Reader`] (module `read`) share the block layout below:
//! block types, option codes and the byte-order magic.

mod cut;
mod id;
mod read;
mod write;

pub use id::RecordingId;
pub use read::{Damage, Interface, Packet, Reader};
pub use write::Writer;

/// `LINKTYPE_USER0`: raw HW-FOC UART bytes (the user range 147..=162 is for private use).
pub const LINKTYPE: u32 = 147;

/// `LINKTYPE_CAN_SOCKETCAN`: CAN frames, each packet SocketCAN's `struct can_frame` with its
/// identifier big-endian (16 bytes: [`hwfoc::dronecan::CanFrame::to_socketcan_record`]).
pub const LINKTYPE_CAN_SOCKETCAN: u32 = 227;

/// The first four bytes of every pcapng file (the section header block's type; the same in
/// both byte orders).
pub const MAGIC: [u8; 4] = [0x0A, 0x0D, 0x0D, 0x0A];

/// Longest run of bytes written as one packet: longer runs between frames are split (Wireshark
/// refuses packets over 256 KiB), each piece timestamped at its own first byte.
pub const MAX_CHUNK: usize = 1 << 16;

const SHB: u32 = 0x0A0D_0D0A;
const IDB: u32 = 1;
const PB: u32 = 2;
const SPB: u32 = 3;
const NRB: u32 = 4;
const ISB: u32 = 5;
const EPB: u32 = 6;
const BYTE_ORDER_MAGIC: u32 = 0x1A2B_3C4D;

const OPT_END: u16 = 0;
const OPT_COMMENT: u16 = 1;
const SHB_OS: u16 = 3;
const SHB_USERAPPL: u16 = 4;
const IF_NAME: u16 = 2;
const IF_DESCRIPTION: u16 = 3;
const IF_SPEED: u16 = 8;
const IF_TSRESOL: u16 = 9;
const IF_TSOFFSET: u16 = 14;

#[cfg(test)]
mod tests {
    use super::read::{TsUnit, baud_in};
    use super::write::epb_size;
    use super::*;

    /// A packet read back, owned.
    #[derive(Debug, Clone, PartialEq, Eq)]
    struct Owned {
        iface: u32,
        t_ns: u64,
        data: Vec<u8>,
        comment: Option<String>,
    }

    fn read_all(file: &[u8]) -> (Vec<Owned>, Vec<Interface>, Vec<Damage>) {
        let mut reader = Reader::new(file);
        let mut packets = Vec::new();
        while let Some(p) = reader.next_packet().unwrap() {
            packets.push(Owned {
                iface: p.iface,
                t_ns: p.t_ns,
                data: p.data.to_vec(),
                comment: p.comment.map(str::to_string),
            });
        }
        (packets, reader.interfaces().to_vec(), reader.take_damage())
    }

    /// A recording of two ports, with chunks of every length modulo 4 and a note.
    fn sample() -> (Vec<u8>, Vec<Owned>) {
        let mut w = Writer::new(Vec::new()).unwrap();
        assert_eq!(w.add_interface("/dev/ttyUSB0", 19200).unwrap(), 0);
        assert_eq!(
            w.add_port("COM7", 115_200, Some(hwfoc::Protocol::Hw5))
                .unwrap(),
            1
        );
        let mut expected = Vec::new();
        let t0 = 1_754_000_000_123_456_789u64;
        for k in 0..9u8 {
            let iface = u32::from(k % 2);
            let data: Vec<u8> = (0..k * 3 + 1).map(|i| i.wrapping_mul(37) ^ k).collect();
            let t_ns = t0 + u64::from(k) * 50_000_001;
            w.write_packet(iface, t_ns, &data).unwrap();
            expected.push(Owned {
                iface,
                t_ns,
                data,
                comment: None,
            });
        }
        w.comment(1, t0 + 999, "gap: COM7 disconnected").unwrap();
        expected.push(Owned {
            iface: 1,
            t_ns: t0 + 999,
            data: Vec::new(),
            comment: Some("gap: COM7 disconnected".into()),
        });
        let file = w.into_inner().unwrap();
        (file, expected)
    }

    #[test]
    fn round_trip_is_exact() {
        let (file, expected) = sample();
        assert_eq!(&file[..4], &MAGIC);
        let (packets, interfaces, damage) = read_all(&file);
        assert_eq!(packets, expected);
        assert!(damage.is_empty(), "{damage:?}");
        assert_eq!(
            interfaces,
            vec![
                Interface {
                    name: "/dev/ttyUSB0".into(),
                    description: "ESC telemetry (hwfoc), 19200 baud 8N1".into(),
                    baud: Some(19200),
                    link_type: 147,
                },
                Interface {
                    name: "COM7".into(),
                    description: "HW5 telemetry (hwfoc), 115200 baud 8N1".into(),
                    baud: Some(115_200),
                    link_type: 147,
                },
            ]
        );
    }

    /// A port's stream: frames (data, information, one failing its checksum), noise and a frame
    /// cut by the end, read in chunks of 7 bytes 3 ms apart.
    fn port_stream() -> (Vec<u8>, Vec<(u64, Vec<u8>)>) {
        use hwfoc::foc::{DataFrame, InfoFrame};
        let mut wire = Vec::new();
        for packet in 0..20u16 {
            wire.extend_from_slice(
                &DataFrame {
                    packet,
                    voltage_raw: 240 + packet,
                    ..Default::default()
                }
                .encode(),
            );
            if packet % 5 == 0 {
                let info = InfoFrame::new("XR_FOC_ESC", "HW577_KZ1_V1.1", "XR-01.0.00", "1");
                wire.extend_from_slice(&info.unwrap().encode());
            }
            if packet % 7 == 3 {
                wire.extend_from_slice(&[0x9B, 0x16, 0x55, 0x00, 0x9B]);
            }
        }
        wire[100] ^= 0x01; // a frame fails its checksum
        wire.extend_from_slice(&DataFrame::default().encode()[..11]);
        let reads = wire
            .chunks(7)
            .enumerate()
            .map(|(k, c)| (1_754_000_000_000_000_000 + k as u64 * 3_000_000, c.to_vec()))
            .collect();
        (wire, reads)
    }

    #[test]
    fn writes_a_packet_per_frame_and_every_byte_with_its_time() {
        let (wire, reads) = port_stream();
        let mut w = Writer::new(Vec::new()).unwrap();
        w.add_interface("p", 19200).unwrap();
        let mut predicted = w.bytes_written();
        for (t, bytes) in &reads {
            // The cost of a write, were the recording to end after it, is exact.
            predicted = w.bytes_written() + w.cost(0, bytes).unwrap();
            w.write(0, *t, bytes).unwrap();
        }
        let file = w.into_inner().unwrap();
        assert_eq!(file.len() as u64, predicted);
        let (packets, _, damage) = read_all(&file);
        assert!(damage.is_empty());
        let joined: Vec<u8> = packets.iter().flat_map(|p| p.data.clone()).collect();
        assert_eq!(joined, wire);
        // Every frame the decoder finds is one packet, at its first byte's time in the reads.
        let per_byte = hwfoc::wire::byte_ns(19200);
        let time_of = |offset: usize| {
            let (t, _) = reads[offset / 7];
            t + ((offset % 7) as f64 * per_byte).round() as u64
        };
        let mut starts = Vec::new();
        let mut at = 0;
        for p in &packets {
            starts.push(at);
            at += p.data.len();
        }
        let mut found = 0;
        hwfoc::foc::Decoder::new().decode_all(&wire, |d| {
            let offset = d.offset as usize;
            let k = starts
                .iter()
                .position(|&s| s == offset)
                .expect("a frame starts a packet");
            assert_eq!(packets[k].data.len(), d.frame.wire_len());
            assert_eq!(packets[k].t_ns, time_of(offset));
            found += 1;
        });
        assert_eq!(found, 23); // 20 data and 4 information frames, one failing its checksum
        // The bytes between frames keep their times too.
        for (k, p) in packets.iter().enumerate() {
            assert_eq!(p.t_ns, time_of(starts[k]), "packet {k}");
        }
    }

    #[test]
    fn held_bytes_are_written_by_settle_comment_and_flush() {
        let frame = hwfoc::foc::DataFrame::default().encode();
        let mut w = Writer::new(Vec::new()).unwrap();
        w.add_interface("a", 19200).unwrap();
        w.add_interface("b", 19200).unwrap();
        let headers = w.bytes_written();
        w.write(0, 1_000, &frame[..5]).unwrap();
        w.write(1, 2_000, &frame[..9]).unwrap();
        w.flush_written().unwrap();
        assert_eq!(w.bytes_written(), headers, "a frame still arriving is held");
        // Port a's last byte came at 1000 + 4 byte times (~2.1 ms): settled 200 ms later.
        w.settle(100_000_000, 200_000_000).unwrap();
        assert_eq!(w.bytes_written(), headers);
        w.settle(202_084_333, 200_000_000).unwrap();
        assert_eq!(w.bytes_written(), headers + epb_size(5));
        w.comment(1, 3_000, "gap").unwrap();
        assert_eq!(w.bytes_written(), headers + epb_size(5) + epb_size(9) + 44);
        w.write(0, 5_000, &frame[..3]).unwrap();
        w.flush().unwrap();
        let (packets, _, _) = read_all(&w.into_inner().unwrap());
        let got: Vec<(u32, u64, usize)> = packets
            .iter()
            .map(|p| (p.iface, p.t_ns, p.data.len()))
            .collect();
        assert_eq!(
            got,
            [(0, 1_000, 5), (1, 2_000, 9), (1, 3_000, 0), (0, 5_000, 3)]
        );
    }

    #[test]
    fn long_chunks_are_split_with_their_own_timestamps() {
        let mut w = Writer::new(Vec::new()).unwrap();
        w.add_interface("p", 19200).unwrap();
        let data: Vec<u8> = (0..MAX_CHUNK * 2 + 5).map(|i| i as u8).collect();
        w.write(0, 1000, &data).unwrap();
        let (packets, _, damage) = read_all(&w.into_inner().unwrap());
        assert!(damage.is_empty(), "{damage:?}");
        let lens: Vec<usize> = packets.iter().map(|p| p.data.len()).collect();
        assert_eq!(lens, [MAX_CHUNK, MAX_CHUNK, 5]);
        let joined: Vec<u8> = packets.iter().flat_map(|p| p.data.clone()).collect();
        assert_eq!(joined, data);
        // 65536 bytes at 19200 baud = 34133333333.33 ns.
        assert_eq!(packets[1].t_ns, 1000 + 34_133_333_333);
        assert_eq!(packets[2].t_ns, 1000 + 68_266_666_667);
    }

    #[test]
    fn bad_arguments_are_errors_not_panics() {
        let mut w = Writer::new(Vec::new()).unwrap();
        assert!(w.write(0, 0, b"x").is_err());
        assert!(w.comment(3, 0, "x").is_err());
        assert!(w.add_interface("p", 0).is_err());
        w.add_interface("p", 9600).unwrap();
        w.write(0, 0, b"").unwrap();
        let long = "é".repeat(40_000);
        w.comment(0, 5, &long).unwrap();
        let (packets, _, damage) = read_all(&w.into_inner().unwrap());
        assert!(damage.is_empty());
        let comment = packets[0].comment.as_deref().unwrap();
        assert!(comment.len() <= 65532 && long.starts_with(comment));
    }

    #[test]
    fn every_cut_reads_the_blocks_before_it() {
        let (file, expected) = sample();
        // Block boundaries: walk the lengths.
        let mut ends = Vec::new();
        let mut at = 0;
        while at < file.len() {
            at += u32::from_le_bytes(file[at + 4..at + 8].try_into().unwrap()) as usize;
            ends.push(at);
        }
        let headers = 3; // SHB + two IDBs
        for cut in 0..=file.len() {
            let (packets, _, damage) = read_all(&file[..cut]);
            let complete = ends.iter().filter(|&&e| e <= cut).count();
            let n = complete.saturating_sub(headers);
            assert_eq!(packets, expected[..n], "cut at {cut}");
            if ends.contains(&cut) || cut == 0 {
                assert!(damage.is_empty(), "cut at {cut}: {damage:?}");
            } else {
                let start = ends.iter().rev().find(|&&e| e < cut).copied().unwrap_or(0);
                assert_eq!(damage.len(), 1, "cut at {cut}");
                assert_eq!(damage[0].offset, start as u64, "cut at {cut}");
                assert_eq!(damage[0].resumed_at, None);
            }
        }
    }

    #[test]
    fn damage_in_the_middle_is_skipped() {
        let (mut file, expected) = sample();
        // Find the third packet block and break its length field.
        let mut at = 0;
        let mut starts = Vec::new();
        while at < file.len() {
            starts.push(at);
            at += u32::from_le_bytes(file[at + 4..at + 8].try_into().unwrap()) as usize;
        }
        let bad = starts[3 + 2];
        file[bad + 4] ^= 0x40;
        let (packets, _, damage) = read_all(&file);
        let mut want = expected.clone();
        want.remove(2);
        assert_eq!(packets, want);
        assert_eq!(damage.len(), 1);
        assert_eq!(damage[0].offset, bad as u64);
        assert_eq!(damage[0].resumed_at, Some(starts[3 + 3] as u64));
        assert!(
            damage[0]
                .to_string()
                .starts_with(&format!("damaged at byte {bad} ("))
        );

        // Garbage in the middle of a file.
        let (file, expected) = sample();
        let cut = starts[3 + 4];
        let mut spliced = file[..cut].to_vec();
        spliced.extend_from_slice(&[0xAB; 37]);
        spliced.extend_from_slice(&[0; 3]);
        spliced.extend_from_slice(&file[cut..]);
        let (packets, _, damage) = read_all(&spliced);
        assert_eq!(packets, expected);
        assert_eq!(damage.len(), 1);
        assert_eq!(damage[0].resumed_at, Some(cut as u64 + 40));
    }

    #[test]
    fn not_a_recording_is_damage_not_a_panic() {
        for junk in [
            &b"hello world, this is not pcapng"[..],
            &[0x0A, 0x0D, 0x0D, 0x0A, 1, 2][..],
        ] {
            let (packets, _, damage) = read_all(junk);
            assert!(packets.is_empty());
            assert_eq!(damage.len(), 1);
            assert_eq!(damage[0].offset, 0);
        }
    }

    /// A big-endian file at the default microsecond resolution with an offset, written by hand.
    #[test]
    fn reads_other_writers_files() {
        fn block(t: u32, body: &[u8]) -> Vec<u8> {
            let len = (body.len() + 12) as u32;
            let mut b = t.to_be_bytes().to_vec();
            b.extend_from_slice(&len.to_be_bytes());
            b.extend_from_slice(body);
            b.extend_from_slice(&len.to_be_bytes());
            b
        }
        let mut shb = BYTE_ORDER_MAGIC.to_be_bytes().to_vec();
        shb.extend_from_slice(&[0, 1, 0, 0]);
        shb.extend_from_slice(&u64::MAX.to_be_bytes());
        let mut idb = vec![0, 147, 0, 0, 0, 0, 0, 0];
        idb.extend_from_slice(&[0, 3, 0, 23]); // if_description
        idb.extend_from_slice(b"UART sniffer, 9600 baud\0");
        idb.extend_from_slice(&[0, 14, 0, 8]); // if_tsoffset = 10 s
        idb.extend_from_slice(&10i64.to_be_bytes());
        idb.extend_from_slice(&[0, 0, 0, 0]);
        let mut epb = 0u32.to_be_bytes().to_vec();
        epb.extend_from_slice(&1u32.to_be_bytes()); // high
        epb.extend_from_slice(&5u32.to_be_bytes()); // low
        epb.extend_from_slice(&3u32.to_be_bytes());
        epb.extend_from_slice(&3u32.to_be_bytes());
        epb.extend_from_slice(&[0x9B, 0x16, 0x01, 0]);
        let mut file = block(SHB, &shb);
        file.extend(block(IDB, &idb));
        file.extend(block(0x0000_0BAD, &[1, 2, 3, 4])); // a custom block: skipped
        file.extend(block(EPB, &epb));
        let (packets, interfaces, damage) = read_all(&file);
        assert!(damage.is_empty(), "{damage:?}");
        assert_eq!(interfaces[0].name, "interface 0");
        assert_eq!(interfaces[0].baud, Some(9600));
        assert_eq!(packets.len(), 1);
        assert_eq!(packets[0].data, [0x9B, 0x16, 0x01]);
        assert_eq!(packets[0].t_ns, ((1u64 << 32) + 5) * 1000 + 10_000_000_000);
    }

    #[test]
    fn concatenated_recordings_continue_their_streams() {
        let (a, expected) = sample();
        let mut both = a.clone();
        both.extend_from_slice(&a);
        let (packets, interfaces, damage) = read_all(&both);
        assert!(damage.is_empty());
        assert_eq!(interfaces.len(), 2);
        assert_eq!(packets.len(), 2 * expected.len());
        assert_eq!(packets[expected.len()..], expected[..]);
    }

    #[test]
    fn timestamp_resolutions() {
        assert_eq!(TsUnit::new(9, 0).to_ns(123), 123);
        assert_eq!(TsUnit::new(6, 0).to_ns(123), 123_000);
        assert_eq!(TsUnit::new(12, 0).to_ns(123_456), 123);
        assert_eq!(TsUnit::new(0x80 | 10, 0).to_ns(1024), 1_000_000_000);
        assert_eq!(TsUnit::new(127, 0).to_ns(u64::MAX), 0);
        assert_eq!(TsUnit::new(9, -5).to_ns(1), 0);
        assert_eq!(baud_in("HW-FOC telemetry, 19200 baud 8N1"), Some(19200));
        assert_eq!(baud_in("no rate"), None);
    }
}
