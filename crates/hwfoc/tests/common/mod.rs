//! What the property tests of both protocols share: the data-frame generator, cut points, and
//! the byte-at-a-time decoding path (one for any scanner of `hwfoc::scan`).

use hwfoc::Status;
use hwfoc::foc::DataFrame;
use hwfoc::scan::{Scanner, StreamDecoder};
use proptest::prelude::*;
use proptest::sample::Index;

/// Any data frame: every field over its whole range, the throttles over the protocol's
/// (0..=1024: a frame with a larger one is rejected).
pub fn data_frame() -> impl Strategy<Value = DataFrame> {
    let throttle = 0..=hwfoc::foc::THROTTLE_MAX_RAW;
    (
        (any::<u16>(), throttle.clone(), throttle, any::<u16>()),
        (any::<u16>(), any::<i16>(), any::<i16>()),
        (any::<u8>(), any::<u8>(), any::<u16>()),
    )
        .prop_map(
            |(
                (packet, throttle_in_raw, throttle_out_raw, erpm_raw),
                (voltage_raw, current_raw, phase_current_raw),
                (mos_adc, cap_adc, status),
            )| DataFrame {
                packet,
                throttle_in_raw,
                throttle_out_raw,
                erpm_raw,
                voltage_raw,
                current_raw,
                phase_current_raw,
                mos_adc,
                cap_adc,
                status: Status(status),
            },
        )
}

/// Cut points for `len` bytes from arbitrary indices: sorted, deduplicated, inside 0..=len.
pub fn cut_points(len: usize, picks: &[Index]) -> Vec<usize> {
    let mut cuts: Vec<usize> = picks.iter().map(|i| i.index(len + 1)).collect();
    cuts.push(0);
    cuts.push(len);
    cuts.sort_unstable();
    cuts.dedup();
    cuts
}

/// `bytes` pushed one at a time into the streaming decoder of scanner `S`, then flushed: the
/// frames and the statistics.
pub fn streamed_bytewise<S: Scanner>(bytes: &[u8]) -> (Vec<S::Item>, S::Stats)
where
    S::Stats: Copy,
{
    let mut d = StreamDecoder::<S>::new();
    let mut out = Vec::new();
    for &b in bytes {
        d.push(b, |x| out.push(x));
    }
    d.flush(|x| out.push(x));
    (out, *d.stats())
}
