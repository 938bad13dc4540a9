//! The DataLink output: what it writes is read back by the codec's own DataLink decoder and by
//! an independent CRC, frame by frame; its pacing, silences and failures.

use std::io::{self, Write};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use hwfoc::datalink;
use hwfoc::foc::DataFrame;
use hwfoc::telemetry::Data;
use hwfoc::{Settings, Status};
use hwfoc_bridge::Output;
use hwfoc_bridge::Update;
use hwfoc_bridge::datalink::{DatalinkOutput, Pacing, QUEUE};
use hwfoc_io::Record;

/// A writer the test can look into, or make fail.
#[derive(Clone, Default)]
struct Shared {
    bytes: Arc<Mutex<Vec<u8>>>,
    fail: Arc<Mutex<bool>>,
}

impl Write for Shared {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if *self.fail.lock().unwrap() {
            return Err(io::Error::new(io::ErrorKind::BrokenPipe, "unplugged"));
        }
        self.bytes.lock().unwrap().extend_from_slice(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

fn frame(esc: u8, packet: u16) -> DataFrame {
    DataFrame {
        packet,
        throttle_in_raw: 100 + u16::from(esc),
        throttle_out_raw: 200,
        erpm_raw: 1000 + u16::from(esc) * 10 + packet,
        voltage_raw: 250,
        current_raw: -64 * i16::from(esc),
        phase_current_raw: 64,
        mos_adc: 120,
        cap_adc: 130,
        status: Status(if esc == 2 { 0x0040 } else { 0 }),
    }
}

fn update(out: &mut DatalinkOutput, esc: u8, packet: u16) {
    let f = frame(esc, packet);
    let record = Record::new(None, esc, &Data::from(f), &Settings::DEFAULT);
    out.update(&Update {
        esc,
        frame: &Data::from(f),
        record: &record,
        settings: &Settings::DEFAULT,
        arrived: Instant::now(),
    });
}

/// The CRC-16/XMODEM of `bytes`, bit by bit (not the codec's table).
fn crc_xmodem(bytes: &[u8]) -> u16 {
    let mut crc = 0u16;
    for &b in bytes {
        crc ^= u16::from(b) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

fn frames_written(shared: &Shared) -> Vec<datalink::HubFrame> {
    let bytes = shared.bytes.lock().unwrap().clone();
    assert_eq!(bytes.len() % datalink::FRAME_LEN, 0);
    for chunk in bytes.chunks(datalink::FRAME_LEN) {
        assert_eq!(&chunk[..4], &[0x9B, 0x9E, 0x01, 0x02]);
        let crc = crc_xmodem(&chunk[..158]);
        assert_eq!(chunk[158..], crc.to_le_bytes(), "CRC, low byte first");
    }
    let mut got = Vec::new();
    let mut decoder = datalink::Decoder::new();
    decoder.decode_all(&bytes, |d| got.push(d.frame));
    assert_eq!(decoder.stats().bytes_skipped(), 0);
    got
}

fn output(pacing: Pacing) -> (DatalinkOutput, Shared) {
    let shared = Shared::default();
    let out = DatalinkOutput::to_writer("datalink test", Box::new(shared.clone()), pacing);
    (out, shared)
}

#[test]
fn every_esc_frame_comes_back_in_its_channel() {
    let (mut out, shared) = output(Pacing::default());
    let start = Instant::now();
    for packet in 0..20u16 {
        for esc in [0u8, 1, 2, 5] {
            update(&mut out, esc, packet);
        }
        // Each round of frames goes out as one DataLink frame once the period has passed.
        out.poll(start + Duration::from_secs(3600) * u32::from(packet + 1))
            .unwrap();
    }
    let frames = frames_written(&shared);
    assert_eq!(frames.len(), 20);
    for (k, f) in frames.iter().enumerate() {
        assert_eq!(f.counter, k as u16);
        for channel in 0..8 {
            let expected = [0, 1, 2, 5]
                .contains(&channel)
                .then(|| frame(channel as u8, k as u16));
            assert_eq!(f.slots[channel], expected, "frame {k} channel {channel}");
        }
    }
    assert_eq!(out.stats().messages, 20);
    assert_eq!(out.stats().bytes, 20 * 160);
    assert_eq!(out.stats().latency.count(), 80);
    assert_eq!(out.stats().superseded, 0);
}

#[test]
fn a_second_frame_of_an_esc_goes_out_as_soon_as_the_line_allows() {
    let pacing = Pacing {
        period: Duration::from_secs(3600),
        min_gap: Duration::ZERO,
    };
    let (mut out, shared) = output(pacing);
    // Two frames of ESC 3 in one read: the first waits for the period, the second pushes it
    // out at once (the gap allows it), then waits itself.
    update(&mut out, 3, 7);
    out.poll(Instant::now()).unwrap(); // first frame ever: nothing before it, sent at once
    update(&mut out, 3, 8);
    update(&mut out, 3, 9);
    let frames = frames_written(&shared);
    let packets: Vec<u16> = frames.iter().map(|f| f.slots[3].unwrap().packet).collect();
    assert_eq!(packets, [7, 8]);
    // The third waits for the period; the line never loses a frame.
    let later = Instant::now() + Duration::from_secs(7200);
    out.poll(later).unwrap();
    let packets: Vec<u16> = frames_written(&shared)
        .iter()
        .map(|f| f.slots[3].unwrap().packet)
        .collect();
    assert_eq!(packets, [7, 8, 9]);
    assert_eq!(out.stats().superseded, 0);
}

#[test]
fn a_line_slower_than_the_esc_drops_only_its_oldest_frames_and_counts_them() {
    let pacing = Pacing {
        period: Duration::from_secs(3600),
        min_gap: Duration::from_secs(3600),
    };
    let (mut out, shared) = output(pacing);
    update(&mut out, 0, 0);
    out.poll(Instant::now()).unwrap();
    for packet in 1..=10u16 {
        update(&mut out, 0, packet);
    }
    assert_eq!(out.stats().superseded, 10 - QUEUE as u64);
    assert_eq!(frames_written(&shared).len(), 1);
}

#[test]
fn a_silent_esc_is_sent_empty_and_escs_past_seven_are_counted() {
    let (mut out, shared) = output(Pacing::default());
    let t0 = Instant::now();
    update(&mut out, 0, 1);
    update(&mut out, 1, 1);
    update(&mut out, 9, 1);
    out.poll(t0).unwrap();
    update(&mut out, 0, 2); // ESC 1 went silent
    out.poll(t0 + Duration::from_secs(1)).unwrap();
    out.poll(t0 + Duration::from_secs(2)).unwrap(); // nothing waiting: nothing sent
    let frames = frames_written(&shared);
    assert_eq!(frames.len(), 2);
    assert!(frames[0].slots[1].is_some());
    assert_eq!(frames[1].slots[1], None);
    assert_eq!(out.escs_not_carried(), 1);
    let error = hwfoc_bridge::output::left_out(&out).expect("ESC 9 left out");
    assert!(
        error
            .to_string()
            .ends_with(": 1 frames of ESC 9 not sent: it carries ESCs 0 to 7"),
        "{error}"
    );
}

#[test]
fn a_failed_write_is_counted_and_the_next_frames_go_out() {
    let (mut out, shared) = output(Pacing::default());
    let t0 = Instant::now();
    update(&mut out, 0, 1);
    *shared.fail.lock().unwrap() = true;
    let err = out.poll(t0).unwrap_err();
    assert!(err.to_string().contains("datalink test"), "{err}");
    assert_eq!(out.stats().errors, 1);
    *shared.fail.lock().unwrap() = false;
    update(&mut out, 0, 2);
    out.poll(t0 + Duration::from_secs(1)).unwrap();
    let frames = frames_written(&shared);
    assert_eq!(frames.len(), 1);
    // The frame lost with the failed write is not sent late; the counter went on.
    assert_eq!(frames[0].slots[0].unwrap().packet, 2);
    assert_eq!(frames[0].counter, 1);
}

#[test]
fn a_port_that_does_not_exist_is_a_clear_error() {
    let err = match DatalinkOutput::open("/dev/ttyNOPE-hwfoc", Pacing::default()) {
        Err(e) => e,
        Ok(_) => panic!("opened a port that does not exist"),
    };
    let text = err.to_string();
    assert!(text.contains("/dev/ttyNOPE-hwfoc"), "{text}");
}
