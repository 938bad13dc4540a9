//! Frames whose checksum passes but whose values are outside the range their protocol allows
//! (issue 29): HW-FOC's weak additive sum let corrupted frames through (a throttle of 1649 %),
//! HW5's CRC rarely (5061 V). Each is counted as rejected and never handed on; a frame at the
//! edge of each range is a frame.

use hwfoc::foc::{self, DataFrame, FrameError, THROTTLE_MAX_RAW};
use hwfoc::hw5::{self, THROTTLE_MAX_PCT, TelemetryFrame, VOLTAGE_MAX_RAW};

fn foc_frame(packet: u16, throttle_in_raw: u16, throttle_out_raw: u16) -> DataFrame {
    DataFrame {
        packet,
        throttle_in_raw,
        throttle_out_raw,
        voltage_raw: 247,
        ..Default::default()
    }
}

/// The frames `bytes` give HW-FOC's decoder, and its statistics.
fn foc_decoded(bytes: &[u8]) -> (Vec<u16>, foc::Stats) {
    let mut d = foc::Decoder::new();
    let mut packets = Vec::new();
    d.decode_all(bytes, |x| {
        if let foc::FocFrame::Data(f) = x.frame {
            packets.push(f.packet);
        }
    });
    (packets, *d.stats())
}

#[test]
fn an_hw_foc_throttle_over_100_percent_is_rejected() {
    // 1649 %: raw 16886, the case, with its checksum made to match.
    for (thr_in, thr_out) in [(16886, 0), (0, 16886), (THROTTLE_MAX_RAW + 1, 10)] {
        let bad = foc_frame(2, thr_in, thr_out).encode();
        assert!(matches!(
            DataFrame::parse(&bad),
            Err(FrameError::OutOfRange { max: 1024, .. })
        ));
        let mut bytes = foc_frame(1, 512, 512).encode().to_vec();
        bytes.extend_from_slice(&bad);
        bytes.extend_from_slice(&foc_frame(3, 1024, 1024).encode());
        let (packets, stats) = foc_decoded(&bytes);
        assert_eq!(packets, [1, 3], "{thr_in} {thr_out}");
        assert_eq!(stats.checksum_failures(), 1);
        assert_eq!(stats.bytes_skipped(), 24);
        // And through the decoder of every format.
        let mut all = hwfoc::detect::Decoder::new();
        let mut n = 0;
        all.decode_all(&bytes, |_| n += 1);
        assert_eq!(n, 2);
    }
    let edge = foc_frame(4, THROTTLE_MAX_RAW, THROTTLE_MAX_RAW).encode();
    assert_eq!(DataFrame::parse(&edge).map(|f| f.throttle_in_raw), Ok(1024));
}

fn hw5_frame(throttle: u8, voltage_raw: u16) -> [u8; hw5::TELEMETRY_LEN] {
    TelemetryFrame {
        throttle,
        voltage_raw,
        erpm_raw: 1000,
        ..Default::default()
    }
    .encode()
}

#[test]
fn an_hw5_value_out_of_range_is_rejected() {
    // 5061 V (raw 50610, the case), 100.1 V, a throttle of 101 %, CRCs made to match.
    for (throttle, voltage) in [
        (50, 50610),
        (50, VOLTAGE_MAX_RAW + 1),
        (THROTTLE_MAX_PCT + 1, 504),
    ] {
        let bad = hw5_frame(throttle, voltage);
        assert!(matches!(
            TelemetryFrame::parse(&bad),
            Err(hw5::Error::OutOfRange { .. })
        ));
        let mut bytes = hw5_frame(10, 504).to_vec();
        bytes.extend_from_slice(&bad);
        bytes.extend_from_slice(&hw5_frame(THROTTLE_MAX_PCT, VOLTAGE_MAX_RAW));
        let mut d = hw5::Decoder::new();
        let mut got = Vec::new();
        d.decode_all(&bytes, |x| got.push(x.frame.voltage_raw));
        assert_eq!(got, [504, VOLTAGE_MAX_RAW], "{throttle} {voltage}");
        let s = d.stats();
        assert_eq!(
            (s.out_of_range(), s.rejected(), s.checksum_failures()),
            (1, 1, 0)
        );
        assert_eq!(s.bytes_skipped(), hw5::TELEMETRY_LEN as u64);
    }
}
