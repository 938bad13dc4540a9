//! The Rust codec's frames and statistics as flat lists of integers, laid out field for field
//! as `shim/shim.c` lays out the C decoders'. A value that is absent (`None`) is `u64::MAX`;
//! an optional group is preceded by 1 or 0.

use hwfoc::counters::Sequence;
use hwfoc::counters::Width;
use hwfoc::scan::Scanner;
use hwfoc::{datalink, foc, hw5, v3, v4};

use crate::ffi::Format;

/// A Rust scanner whose items and statistics flatten as the shim's.
pub trait Flat: Scanner {
    /// The C decoder of the same format.
    const FORMAT: Format;
    /// Appends one frame.
    fn frame(item: &Self::Item, out: &mut Vec<u64>);
    /// Appends the statistics.
    fn stats(stats: &Self::Stats, out: &mut Vec<u64>);
    /// The bytes the Rust encoder writes for the frame.
    fn encode(item: &Self::Item) -> Vec<u8>;
}

const NONE: u64 = u64::MAX;

fn opt(v: Option<impl Into<u64>>) -> u64 {
    v.map_or(NONE, Into::into)
}

fn sequence<W: Width>(s: &Sequence<W>, out: &mut Vec<u64>) {
    out.extend(
        [
            s.count(),
            s.lost(),
            s.duplicates(),
            s.restarts(),
            s.reordered(),
        ]
        .map(u64::from),
    );
    out.push(s.last().map_or(NONE, |n| u64::from(n.into())));
}

/// A chained scanner's counts and where its chain ends (V3's and V4's statistics, which name
/// them alike).
macro_rules! chain_stats {
    ($s:expr, $out:expr) => {
        $out.extend([$s.bytes(), $s.bytes_skipped()]);
        $out.extend([$s.implausible(), $s.unconfirmed(), $s.syncs()].map(u64::from));
        sequence($s.counter(), $out);
        $out.push(opt($s.chain_end()));
    };
}

fn foc_data(f: &foc::DataFrame, out: &mut Vec<u64>) {
    out.extend(
        [
            f.packet,
            f.throttle_in_raw,
            f.throttle_out_raw,
            f.erpm_raw,
            f.voltage_raw,
            f.current_raw as u16,
            f.phase_current_raw as u16,
            f.mos_adc.into(),
            f.cap_adc.into(),
            f.status.0,
        ]
        .map(u64::from),
    );
}

fn v4_info(i: &v4::InfoFrame, out: &mut Vec<u64>) {
    out.push(i.full_scale.into());
    out.extend([i.v1, i.v2, i.i1, i.i2, i.i3, i.t1, i.t2].map(u64::from));
}

fn opt_v4_info(i: Option<v4::InfoFrame>, out: &mut Vec<u64>) {
    out.push(u64::from(i.is_some()));
    if let Some(i) = i {
        v4_info(&i, out);
    }
}

impl Flat for foc::Scanner {
    const FORMAT: Format = Format::Foc;
    fn frame(item: &foc::Decoded, out: &mut Vec<u64>) {
        out.push(item.offset);
        match &item.frame {
            foc::FocFrame::Data(d) => {
                out.push(0);
                foc_data(d, out);
            }
            foc::FocFrame::Info(i) => {
                out.push(1);
                out.extend(i.text().iter().map(|&b| u64::from(b)));
            }
        }
    }
    fn stats(s: &foc::Stats, out: &mut Vec<u64>) {
        out.extend([s.bytes(), s.bytes_skipped()]);
        out.extend([s.info_frames(), s.checksum_failures()].map(u64::from));
        sequence(s.packets(), out);
    }
    fn encode(item: &foc::Decoded) -> Vec<u8> {
        let mut out = [0u8; 77];
        let n = item.frame.encode_into(&mut out).unwrap_or(0);
        out[..n].to_vec()
    }
}

impl Flat for datalink::Scanner {
    const FORMAT: Format = Format::DataLink;
    fn frame(item: &datalink::Decoded, out: &mut Vec<u64>) {
        let r = &item.report;
        out.extend([item.offset, item.frame.counter.into()]);
        out.push(r.length_byte.byte().into());
        out.extend([r.empty_slots, r.bad_channels, r.duplicate_channels].map(u64::from));
        for slot in &item.frame.slots {
            out.push(u64::from(slot.is_some()));
            if let Some(d) = slot {
                foc_data(d, out);
            }
        }
    }
    fn stats(s: &datalink::Stats, out: &mut Vec<u64>) {
        use datalink::LengthByte::{Covered, Total};
        out.extend([s.bytes(), s.bytes_skipped()]);
        out.extend(
            [
                s.checksum_failures(),
                s.bad_headers(),
                s.frames_with_length_byte(Covered),
                s.frames_with_length_byte(Total),
                s.bad_channels(),
                s.duplicate_channels(),
                s.empty_slots(),
            ]
            .map(u64::from),
        );
        sequence(s.counter(), out);
        for c in s.channels() {
            sequence(c, out);
        }
    }
    fn encode(item: &datalink::Decoded) -> Vec<u8> {
        item.frame.encode_as(item.report.length_byte).to_vec()
    }
}

impl Flat for v3::Scanner {
    const FORMAT: Format = Format::V3;
    fn frame(item: &v3::Decoded, out: &mut Vec<u64>) {
        let f = &item.frame;
        out.extend([item.offset, f.counter.into()]);
        out.extend([f.throttle_in_raw, f.pwm_out_raw, f.period_us].map(u64::from));
    }
    fn stats(s: &v3::Stats, out: &mut Vec<u64>) {
        chain_stats!(s, out);
    }
    fn encode(item: &v3::Decoded) -> Vec<u8> {
        item.frame.encode().to_vec()
    }
}

impl Flat for v4::Scanner {
    const FORMAT: Format = Format::V4;
    fn frame(item: &v4::Decoded, out: &mut Vec<u64>) {
        out.push(item.offset);
        match &item.frame {
            v4::V4Frame::Data(d) => {
                let f = &d.frame;
                out.extend([0, f.counter.into()]);
                out.extend([f.throttle_in_raw, f.throttle_out_raw].map(u64::from));
                out.push(f.erpm.into());
                out.extend([f.voltage_adc, f.current_adc, f.temp_adc, f.temp2_adc].map(u64::from));
                opt_v4_info(d.info, out);
            }
            v4::V4Frame::Info(i) => {
                out.push(1);
                v4_info(i, out);
            }
        }
    }
    fn stats(s: &v4::Stats, out: &mut Vec<u64>) {
        chain_stats!(s, out);
        out.extend(
            [
                s.info_frames(),
                s.info_adoptions(),
                s.info_disagreements(),
                s.trailers(),
            ]
            .map(u64::from),
        );
        opt_v4_info(s.last_info(), out);
        opt_v4_info(s.adopted(), out);
    }
    fn encode(item: &v4::Decoded) -> Vec<u8> {
        match &item.frame {
            v4::V4Frame::Data(d) => d.frame.encode().to_vec(),
            v4::V4Frame::Info(i) => i.encode().to_vec(),
        }
    }
}

impl Flat for hw5::Scanner {
    const FORMAT: Format = Format::Hw5;
    fn frame(item: &hw5::Decoded, out: &mut Vec<u64>) {
        let f = &item.frame;
        out.push(item.offset);
        out.extend([f.throttle, f.unknown[0], f.unknown[1], f.fault.0].map(u64::from));
        out.extend([f.erpm_raw, f.voltage_raw, f.current_raw].map(u64::from));
        out.extend(
            [
                f.esc_temp,
                f.bec_temp,
                f.motor_temp,
                f.bec_voltage_raw,
                f.bec_current_raw,
            ]
            .map(u64::from),
        );
    }
    fn stats(s: &hw5::Stats, out: &mut Vec<u64>) {
        out.extend([s.bytes(), s.bytes_skipped()]);
        out.extend(s.frames_by_kind().map(u64::from));
        out.extend(
            [
                s.checksum_failures(),
                s.bad_headers(),
                s.unknown_types(),
                s.out_of_range(),
            ]
            .map(u64::from),
        );
    }
    fn encode(item: &hw5::Decoded) -> Vec<u8> {
        item.frame.encode().to_vec()
    }
}
