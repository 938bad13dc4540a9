//! Invariant checks shared by the fuzz targets in `fuzz_targets/`.

use hwfoc::{Decoded, Frame, LinkStats, Parsed, parse};

/// Panics unless `decoded` and `stats` are a consistent decoding of `input`, a whole stream
/// (a flushed `Decoder`, or an exhausted `frames` iterator):
///
/// - every byte is accounted for: `bytes == input.len() == 24*frames + 77*info_frames + skipped`;
/// - the frame counters match the frames given;
/// - offsets strictly increase and frames never overlap;
/// - each frame re-encodes to exactly the input bytes at its offset, and `parse` reads the same
///   frame there.
pub fn check_stream(input: &[u8], decoded: &[Decoded], stats: &LinkStats) {
    assert_eq!(stats.bytes(), input.len() as u64, "bytes counted");
    assert_eq!(
        stats.bytes(),
        24 * u64::from(stats.frames())
            + 77 * u64::from(stats.info_frames())
            + stats.bytes_skipped(),
        "bytes == 24*frames + 77*info_frames + skipped: {stats}"
    );
    let data = decoded
        .iter()
        .filter(|d| matches!(d.frame, Frame::Data(_)))
        .count();
    assert_eq!(data as u64, u64::from(stats.frames()), "data frames");
    assert_eq!(
        (decoded.len() - data) as u64,
        u64::from(stats.info_frames()),
        "info frames"
    );
    let mut next_free = 0u64;
    let mut last: Option<u64> = None;
    let mut buf = [0u8; 77];
    for d in decoded {
        if let Some(prev) = last {
            assert!(
                d.offset > prev,
                "offsets not increasing: {prev} then {}",
                d.offset
            );
        }
        assert!(
            d.offset >= next_free,
            "frame at {} overlaps the one before",
            d.offset
        );
        last = Some(d.offset);
        let start = usize::try_from(d.offset).expect("offset fits usize");
        let n = d
            .frame
            .encode_into(&mut buf)
            .expect("buffer holds any frame");
        assert_eq!(n, d.frame.wire_len());
        let end = start + n;
        assert!(end <= input.len(), "frame at {start} runs past the input");
        assert_eq!(
            &input[start..end],
            &buf[..n],
            "frame at {start} does not re-encode to its bytes"
        );
        assert_eq!(
            parse(&input[start..]),
            Ok(Parsed::Complete(d.frame, n)),
            "parse disagrees at {start}"
        );
        next_free = end as u64;
    }
}
