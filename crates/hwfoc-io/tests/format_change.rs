//! A stream that changes format, read from a file and from standard input (a reader handing
//! its bytes in random chunks, as a pipe does): every pair of serial formats (HW-FOC, DataLink,
//! V3, V4, HW5) in both orders, the change after a random number of frames. The records are
//! the same from both, in the same order, and every frame sent is one of them: no intact frame
//! is lost around the change (issue 29).

use std::io::{Cursor, Read};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

use hwfoc::Settings;
use hwfoc::Telemetry;
use hwfoc::telemetry::AnyFrame;
use hwfoc_io::{Handler, Input, InputError, OpenInput, Sources};
use proptest::prelude::*;

/// The serial formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    HwFoc,
    DataLink,
    V3,
    V4,
    Hw5,
}

const FORMATS: [Format; 5] = [
    Format::HwFoc,
    Format::DataLink,
    Format::V3,
    Format::V4,
    Format::Hw5,
];

/// The DataLink channels that carry an ESC.
const HUB_CHANNELS: [usize; 2] = [0, 3];

impl Format {
    /// The encoder's bytes of frame `n` (its counter, from `start`).
    fn frame(self, n: u32) -> Vec<u8> {
        let foc = |packet: u16| hwfoc::foc::DataFrame {
            packet,
            voltage_raw: 247,
            ..Default::default()
        };
        match self {
            Format::HwFoc => foc(n as u16).encode().to_vec(),
            Format::DataLink => {
                let mut frame = hwfoc::datalink::HubFrame::new(n as u16);
                for c in HUB_CHANNELS {
                    frame.slots[c] = Some(foc(1000 + c as u16 + n as u16));
                }
                frame.encode().to_vec()
            }
            Format::V3 => hwfoc::v3::V3Frame {
                counter: n & 0xFF_FFFF,
                throttle_in_raw: 51,
                pwm_out_raw: 51,
                period_us: 1500,
            }
            .encode()
            .to_vec(),
            Format::V4 => hwfoc::v4::DataFrame {
                counter: n & 0xFF_FFFF,
                throttle_in_raw: 300,
                throttle_out_raw: 280,
                erpm: 9000 + n % 500,
                voltage_adc: 1365,
                current_adc: 120,
                temp_adc: 2200,
                temp2_adc: 2100,
            }
            .encode()
            .to_vec(),
            Format::Hw5 => hwfoc::hw5::TelemetryFrame {
                throttle: 20,
                erpm_raw: 1000 + (n % 7) as u16,
                voltage_raw: 504,
                ..Default::default()
            }
            .encode()
            .to_vec(),
        }
    }

    /// Records a frame gives.
    fn records(self) -> usize {
        match self {
            Format::DataLink => HUB_CHANNELS.len(),
            _ => 1,
        }
    }
}

/// Every data frame handed on: its ESC, protocol and packet counter.
#[derive(Default)]
struct Records(Vec<(u8, String, Option<u32>)>);

impl Handler for Records {
    type Error = InputError;

    fn frame(&mut self, esc: u8, _: Option<f64>, frame: &AnyFrame, _: &Settings) {
        if let AnyFrame::Data(d) = frame {
            self.0
                .push((esc, format!("{:?}", d.protocol()), Telemetry::packet(d)));
        }
    }
}

/// A reader that hands its bytes in the chunk sizes given (in turn, again from the first).
struct Chunks {
    bytes: Cursor<Vec<u8>>,
    sizes: Vec<usize>,
    next: usize,
}

impl Read for Chunks {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.sizes[self.next % self.sizes.len()].min(buf.len());
        self.next += 1;
        self.bytes.read(&mut buf[..n])
    }
}

fn records_of(input: Input) -> Vec<(u8, String, Option<u32>)> {
    let mut records = Records::default();
    Sources::new(vec![input], Settings::DEFAULT)
        .run(&mut records)
        .unwrap();
    records.0
}

/// A file of its own in the temporary directory, removed when dropped.
struct TempFile(PathBuf);

impl TempFile {
    fn new(bytes: &[u8]) -> TempFile {
        static N: AtomicUsize = AtomicUsize::new(0);
        let n = N.fetch_add(1, Ordering::Relaxed);
        let path = std::env::temp_dir().join(format!(
            "hwfoc-format-change-{}-{n}.bin",
            std::process::id()
        ));
        std::fs::write(&path, bytes).unwrap();
        TempFile(path)
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    /// Frames of one format, then of another (no silence between), every pair in both orders:
    /// from a file and from standard input in random chunks, the same records in the same
    /// order, and as many as were sent.
    #[test]
    fn a_format_change_reads_the_same_from_a_file_and_stdin_and_loses_no_frame(
        first in 20u32..150,
        second in 20u32..150,
        start in 0u32..60_000,
        sizes in proptest::collection::vec(1usize..5000, 1..8),
    ) {
        for a in FORMATS {
            for b in FORMATS.into_iter().filter(|&b| b != a) {
                let mut bytes: Vec<u8> = (start..start + first).flat_map(|n| a.frame(n)).collect();
                bytes.extend((start / 3..start / 3 + second).flat_map(|n| b.frame(n)));
                let file = TempFile::new(&bytes);
                let from_file = records_of(Input::open(file.0.to_str().unwrap()).unwrap());
                let chunks = Chunks {
                    bytes: Cursor::new(bytes),
                    sizes: sizes.clone(),
                    next: 0,
                };
                let from_stdin = records_of(Input::from_reader("-", Box::new(chunks)).unwrap());
                let sent = first as usize * a.records() + second as usize * b.records();
                prop_assert_eq!(from_file.len(), sent, "{:?} then {:?}: records from the file", a, b);
                prop_assert_eq!(from_stdin, from_file, "{:?} then {:?}: stdin and the file", a, b);
            }
        }
    }
}
