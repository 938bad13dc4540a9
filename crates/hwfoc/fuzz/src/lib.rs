//! Invariant checks shared by the fuzz targets in `fuzz_targets/`.

use hwfoc::datalink::LengthByte;
use hwfoc::foc::{Decoded, Frame, Parsed, parse};
use hwfoc::{datalink, foc};

/// Panics unless `decoded` and `stats` are a consistent decoding of `input`, a whole stream
/// (a flushed `Decoder`, or an exhausted `frames` iterator):
///
/// - every byte is accounted for: `bytes == input.len() == 24*frames + 77*info_frames + skipped`;
/// - the frame counters match the frames given;
/// - offsets strictly increase and frames never overlap;
/// - each frame re-encodes to exactly the input bytes at its offset, and `parse` reads the same
///   frame there.
pub fn check_stream(input: &[u8], decoded: &[Decoded], stats: &foc::Stats) {
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

/// Panics unless `decoded` and `stats` are a consistent DataLink decoding of `input`, a whole
/// stream (a flushed `datalink::Decoder`, or an exhausted `datalink::frames` iterator):
///
/// - every byte is accounted for: `bytes == input.len() == 160*frames + skipped`, and every
///   frame counted under one length byte;
/// - every record of every frame counted once (a channel's, empty, bad or duplicate channel),
///   and each channel's record count matches the frames given;
/// - offsets strictly increase and frames never overlap;
/// - `datalink::Frame::parse_with_report` reads the same frame and report at each offset, and
///   the frame re-encodes to the input bytes when nothing of it was dropped (no bad or
///   duplicate channel, the length byte 0x9E, every channel byte its position).
pub fn check_datalink_stream(input: &[u8], decoded: &[datalink::Decoded], stats: &datalink::Stats) {
    assert_eq!(stats.bytes(), input.len() as u64, "bytes counted");
    assert_eq!(
        stats.bytes(),
        160 * u64::from(stats.frames()) + stats.bytes_skipped(),
        "bytes == 160*frames + skipped: {stats}"
    );
    assert_eq!(decoded.len() as u64, u64::from(stats.frames()), "frames");
    assert_eq!(
        u64::from(stats.frames()),
        u64::from(stats.frames_with_length_byte(LengthByte::Covered))
            + u64::from(stats.frames_with_length_byte(LengthByte::Total)),
        "frames by length byte"
    );
    assert_eq!(
        8 * u64::from(stats.frames()),
        stats.records()
            + u64::from(stats.empty_slots())
            + u64::from(stats.bad_channels())
            + u64::from(stats.duplicate_channels()),
        "every record counted once: {stats}"
    );
    for ch in 0..8 {
        let n = decoded
            .iter()
            .filter(|d| d.frame.slots[ch].is_some())
            .count();
        assert_eq!(
            n as u64,
            u64::from(stats.channel(ch).unwrap().count()),
            "channel {ch}"
        );
    }
    let mut next_free = 0u64;
    for d in decoded {
        assert!(
            d.offset >= next_free,
            "frame at {} overlaps the one before",
            d.offset
        );
        let start = usize::try_from(d.offset).expect("offset fits usize");
        let end = start + 160;
        assert!(end <= input.len(), "frame at {start} runs past the input");
        assert_eq!(
            datalink::Frame::parse_with_report(&input[start..]),
            Ok((d.frame, d.report)),
            "parse disagrees at {start}"
        );
        let r = &d.report;
        let in_place = (0..8).all(|ch| input[start + 6 + 19 * ch] == ch as u8);
        if r.bad_channels == 0
            && r.duplicate_channels == 0
            && r.length_byte == LengthByte::Covered
            && in_place
        {
            assert_eq!(
                &d.frame.encode()[..],
                &input[start..end],
                "frame at {start} does not re-encode to its bytes"
            );
        }
        next_free = end as u64;
    }
}
