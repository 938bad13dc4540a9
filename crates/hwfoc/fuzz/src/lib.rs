//! Invariant checks shared by the fuzz targets in `fuzz_targets/`.

use std::fmt;

use hwfoc::datalink::LengthByte;
use hwfoc::foc::{Decoded, FocFrame, Parsed, parse};
use hwfoc::scan::{Scan, Scanner, Stats as _, StreamDecoder};
use hwfoc::{datalink, detect, foc, hw5, mixed, v3, v4};

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
        .filter(|d| matches!(d.frame, FocFrame::Data(_)))
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
/// - `datalink::HubFrame::parse_with_report` reads the same frame and report at each offset, and
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
            datalink::HubFrame::parse_with_report(&input[start..]),
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

/// The input of a scheduled streaming target (`stream.rs`, `datalink.rs`, `v3.rs`, `v4.rs`,
/// `hw5.rs`): byte 0 gives the number `n` (1..=8) of schedule bytes that follow; the rest is the
/// stream. `None` when the input is too short to hold them.
pub fn split_schedule(data: &[u8]) -> Option<(&[u8], &[u8])> {
    let (&n, rest) = data.split_first()?;
    let n = usize::from(n % 8) + 1;
    if rest.len() < n {
        return None;
    }
    Some(rest.split_at(n))
}

/// What [`feed_scheduled`] gave: every frame, the final statistics, and whether the stream was
/// settled mid-way (a `flush` or `line_silent` before the end, after which the frames may
/// differ from the bulk path's: a candidate cut by the silence is dropped).
pub struct Scheduled<S: Scanner> {
    /// The frames, in the order given.
    pub frames: Vec<S::Item>,
    /// The statistics after the final flush.
    pub stats: S::Stats,
    /// A `flush` or `line_silent` came before the end of the stream.
    pub settled_mid_stream: bool,
}

/// Feeds `input` to a new `StreamDecoder<S>` as `schedule` says, used cyclically, one byte per
/// step:
///
/// - `0`: an empty `feed`;
/// - `1..=189`: `feed` that many bytes;
/// - `190..=194`: `flush` now, then go on;
/// - `195..=199`: `line_silent(k)` with `k = op - 195` (0..=4 frames' time of silence);
/// - `200..=254`: `push` 1..=55 bytes one at a time;
/// - `255`: `feed` all the rest;
///
/// then flushes. Checks after every call: fewer than `S::MAX_LEN` bytes held (none after a
/// flush), the byte count, and the last frame's offset (`offset_of`) before the bytes fed.
pub fn feed_scheduled<S: Scanner>(
    schedule: &[u8],
    input: &[u8],
    offset_of: impl Fn(&S::Item) -> u64,
) -> Scheduled<S> {
    let n = schedule.len();
    let mut dec = StreamDecoder::<S>::new();
    let mut got = Vec::new();
    let mut at = 0;
    let mut step = 0;
    let mut idle_steps = 0;
    let mut settled_mid_stream = false;
    while at < input.len() {
        let op = schedule[step % n];
        step += 1;
        let left = input.len() - at;
        match op {
            0 | 190..=199 => {
                match op {
                    0 => dec.feed(&[], |d| got.push(d)),
                    190..=194 => dec.flush(|d| got.push(d)),
                    _ => dec.line_silent(u32::from(op - 195), |d| got.push(d)),
                }
                if op != 0 {
                    assert_eq!(dec.buffered(), 0, "flush leaves nothing held");
                    settled_mid_stream = true;
                }
                // A schedule that never consumes a byte still has to end.
                idle_steps += 1;
                if idle_steps >= n {
                    dec.push(input[at], |d| got.push(d));
                    at += 1;
                    idle_steps = 0;
                }
            }
            200..=254 => {
                for &b in &input[at..at + usize::from(op - 199).min(left)] {
                    dec.push(b, |d| got.push(d));
                    assert!(
                        dec.buffered() < S::MAX_LEN,
                        "buffered {} after push",
                        dec.buffered()
                    );
                    at += 1;
                }
                idle_steps = 0;
            }
            _ => {
                let len = if op == 255 {
                    left
                } else {
                    usize::from(op).min(left)
                };
                dec.feed(&input[at..at + len], |d| got.push(d));
                at += len;
                idle_steps = 0;
            }
        }
        assert!(
            dec.buffered() < S::MAX_LEN,
            "buffered {} after a call",
            dec.buffered()
        );
        assert_eq!(dec.stats().bytes(), at as u64, "bytes fed so far");
        if let Some(last) = got.last() {
            assert!(offset_of(last) < at as u64, "a frame beyond the bytes fed");
        }
    }
    dec.flush(|d| got.push(d));
    assert_eq!(dec.buffered(), 0);
    Scheduled {
        frames: got,
        stats: dec.stats().clone(),
        settled_mid_stream,
    }
}

/// The bulk `Scan<S>` over the whole input, checked fused, against a `StreamDecoder<S>` fed a
/// byte at a time and through `decode_all` (the same frames and statistics); returns its frames
/// and statistics.
pub fn bulk_and_bytewise<S: Scanner>(input: &[u8]) -> (Vec<S::Item>, S::Stats)
where
    S::Item: PartialEq + fmt::Debug,
    S::Stats: PartialEq,
{
    let mut it = Scan::<S>::new(input);
    let bulk: Vec<S::Item> = it.by_ref().collect();
    assert!(it.next().is_none(), "the bulk iterator is fused");
    let stats = it.stats().clone();

    let mut bytewise = StreamDecoder::<S>::new();
    let mut got = Vec::new();
    for &b in input {
        bytewise.push(b, |d| got.push(d));
        assert!(bytewise.buffered() < S::MAX_LEN);
    }
    bytewise.flush(|d| got.push(d));
    assert_eq!(
        got, bulk,
        "byte-at-a-time decoder and the bulk iterator disagree"
    );
    assert_eq!(bytewise.stats(), &stats, "byte-at-a-time statistics");

    let mut all = StreamDecoder::<S>::new();
    got.clear();
    all.decode_all(input, |d| got.push(d));
    assert_eq!(got, bulk, "decode_all and the bulk iterator disagree");
    assert_eq!(all.stats(), &stats, "decode_all statistics");
    (bulk, stats)
}

/// The whole check of a scheduled streaming target for scanner `S`: the bulk path and the
/// byte-at-a-time and `decode_all` decoders agree; the scheduled decoder gives the same frames
/// and statistics when nothing settled the stream mid-way; `check` (a protocol's whole-stream
/// invariants) holds for the bulk decoding and for the scheduled one.
pub fn check_scheduled<S: Scanner>(
    data: &[u8],
    offset_of: impl Fn(&S::Item) -> u64,
    check: impl Fn(&[u8], &[S::Item], &S::Stats),
) where
    S::Item: PartialEq + fmt::Debug,
    S::Stats: PartialEq,
{
    let Some((schedule, input)) = split_schedule(data) else {
        return;
    };
    let (bulk, stats) = bulk_and_bytewise::<S>(input);
    check(input, &bulk, &stats);
    let got = feed_scheduled::<S>(schedule, input, offset_of);
    check(input, &got.frames, &got.stats);
    if !got.settled_mid_stream {
        assert_eq!(
            got.frames, bulk,
            "chunked decoder and the bulk iterator disagree"
        );
        assert_eq!(got.stats, stats, "chunked decoder and bulk statistics");
    }
}

/// Asserts that frames at `spans` (offset, length), in the order given, lie inside a stream of
/// `len` bytes at strictly increasing offsets without overlapping.
fn assert_disjoint(len: usize, spans: impl IntoIterator<Item = (u64, usize)>) {
    let mut next_free = 0u64;
    let mut last: Option<u64> = None;
    for (offset, n) in spans {
        if let Some(prev) = last {
            assert!(
                offset > prev,
                "offsets not increasing: {prev} then {offset}"
            );
        }
        assert!(
            offset >= next_free,
            "frame at {offset} overlaps the one before"
        );
        let end = offset + n as u64;
        assert!(end <= len as u64, "frame at {offset} runs past the input");
        last = Some(offset);
        next_free = end;
    }
}

/// Panics unless `decoded` and `stats` are a consistent V3 decoding of `input`, a whole stream:
/// `bytes == input.len() == 10*frames + skipped`; the frame count and the last counter match
/// the frames given; frames in order without overlap; each one plausible, parsed the same at its
/// offset and re-encoding to exactly the bytes there.
pub fn check_v3_stream(input: &[u8], decoded: &[v3::Decoded], stats: &v3::Stats) {
    assert_eq!(stats.bytes(), input.len() as u64, "bytes counted");
    assert_eq!(
        stats.bytes(),
        10 * u64::from(stats.frames()) + stats.bytes_skipped(),
        "bytes == 10*frames + skipped: {stats}"
    );
    assert_eq!(decoded.len() as u64, u64::from(stats.frames()), "frames");
    assert!(stats.syncs() <= stats.frames(), "syncs: {stats}");
    assert_eq!(
        stats.last_counter(),
        decoded.last().map(|d| d.frame.counter),
        "last counter"
    );
    assert_disjoint(
        input.len(),
        decoded.iter().map(|d| (d.offset, v3::FRAME_LEN)),
    );
    for d in decoded {
        let start = d.offset as usize;
        assert!(d.frame.is_plausible(), "implausible frame at {start}");
        assert_eq!(
            v3::V3Frame::parse(&input[start..]),
            Some(d.frame),
            "parse at {start}"
        );
        assert_eq!(
            &input[start..start + v3::FRAME_LEN],
            &d.frame.encode()[..],
            "frame at {start} does not re-encode to its bytes"
        );
    }
}

/// Panics unless `decoded` and `stats` are a consistent V4 decoding of `input`, a whole stream:
/// `bytes == input.len() == 19*frames + 13*info_frames + trailers + skipped`; the data and info
/// frame counts match the frames given; frames in order without overlap; each one plausible
/// (a data frame under the full scale of the info frame it carries), re-encoding to exactly the
/// bytes at its offset; a data frame's adopted info frame is one decoded before it.
pub fn check_v4_stream(input: &[u8], decoded: &[v4::Decoded], stats: &v4::Stats) {
    assert_eq!(stats.bytes(), input.len() as u64, "bytes counted");
    assert_eq!(
        stats.bytes(),
        19 * u64::from(stats.frames())
            + 13 * u64::from(stats.info_frames())
            + u64::from(stats.trailers())
            + stats.bytes_skipped(),
        "bytes == 19*frames + 13*info_frames + trailers + skipped: {stats}"
    );
    let data = decoded
        .iter()
        .filter(|d| matches!(d.frame, v4::V4Frame::Data(_)))
        .count();
    assert_eq!(data as u64, u64::from(stats.frames()), "data frames");
    assert_eq!(
        (decoded.len() - data) as u64,
        u64::from(stats.info_frames()),
        "info frames"
    );
    assert!(stats.trailers() <= stats.frames(), "trailers: {stats}");
    let len_of = |d: &v4::Decoded| match d.frame {
        v4::V4Frame::Data(_) => v4::DATA_FRAME_LEN,
        v4::V4Frame::Info(_) => v4::INFO_FRAME_LEN,
    };
    assert_disjoint(input.len(), decoded.iter().map(|d| (d.offset, len_of(d))));
    let mut infos_seen: Vec<v4::InfoFrame> = Vec::new();
    for d in decoded {
        let start = d.offset as usize;
        match d.frame {
            v4::V4Frame::Data(data) => {
                assert!(
                    data.frame.is_plausible(data.full_scale()),
                    "implausible data frame at {start}"
                );
                assert_eq!(
                    &input[start..start + v4::DATA_FRAME_LEN],
                    &data.frame.encode()[..],
                    "data frame at {start} does not re-encode to its bytes"
                );
                if let Some(info) = data.info {
                    assert!(
                        infos_seen.contains(&info),
                        "data frame at {start} carries an info frame never decoded"
                    );
                }
            }
            v4::V4Frame::Info(info) => {
                assert!(info.is_plausible(), "implausible info frame at {start}");
                assert_eq!(v4::InfoFrame::parse(&input[start..]), Some(info));
                assert_eq!(
                    &input[start..start + v4::INFO_FRAME_LEN],
                    &info.encode()[..],
                    "info frame at {start} does not re-encode to its bytes"
                );
                infos_seen.push(info);
            }
        }
    }
}

/// Panics unless `decoded` and `stats` are a consistent HW5 decoding of `input`, a whole
/// stream: `bytes == input.len() == frame_bytes + skipped` (frames of every kind); the telemetry
/// count matches the frames given; frames in order without overlap; each one identified and
/// parsed the same at its offset, and its encoding parsed back to it.
pub fn check_hw5_stream(input: &[u8], decoded: &[hw5::Decoded], stats: &hw5::Stats) {
    assert_eq!(stats.bytes(), input.len() as u64, "bytes counted");
    assert_eq!(
        stats.bytes(),
        stats.frame_bytes() + stats.bytes_skipped(),
        "bytes == frame bytes + skipped: {stats}"
    );
    assert_eq!(
        decoded.len() as u64,
        u64::from(stats.telemetry_frames()),
        "telemetry frames"
    );
    assert_disjoint(
        input.len(),
        decoded.iter().map(|d| (d.offset, hw5::TELEMETRY_LEN)),
    );
    for d in decoded {
        let start = d.offset as usize;
        let bytes = &input[start..start + hw5::TELEMETRY_LEN];
        assert_eq!(hw5::identify(bytes), Ok(hw5::Kind::Telemetry), "at {start}");
        assert_eq!(
            hw5::TelemetryFrame::parse(bytes),
            Ok(d.frame),
            "parse at {start}"
        );
        assert_eq!(hw5::TelemetryFrame::parse(&d.frame.encode()), Ok(d.frame));
    }
}

/// What a `detect::Decoder` tells of itself: the format locked onto (and last), the bytes
/// given and each format's statistics.
#[derive(Debug, Clone, PartialEq)]
pub struct DetectState {
    /// `locked()` and `last_locked()`.
    pub locked: (Option<detect::Family>, Option<detect::Family>),
    /// `bytes()`.
    pub bytes: u64,
    /// Each format's statistics.
    pub stats: (mixed::Stats, hw5::Stats, v4::Stats, v3::Stats),
}

/// The state of `d`.
pub fn detect_state(d: &detect::Decoder) -> DetectState {
    DetectState {
        locked: (d.locked(), d.last_locked()),
        bytes: d.bytes(),
        stats: (
            *d.mixed_stats(),
            *d.stats::<hwfoc::hw5::Scanner>(),
            *d.stats::<hwfoc::v4::Scanner>(),
            *d.stats::<hwfoc::v3::Scanner>(),
        ),
    }
}

/// Panics unless `got` holds the frames of `expected`: each format's in the same order, and
/// the same ones in all (frames of two formats found in one slice while detecting interleave
/// as the chunks say, see `hwfoc::detect`).
pub fn assert_same_detected(got: &[detect::Decoded], expected: &[detect::Decoded], what: &str) {
    for family in detect::Family::ALL {
        let of = |v: &[detect::Decoded]| -> Vec<detect::Decoded> {
            v.iter().filter(|d| d.family() == family).copied().collect()
        };
        assert_eq!(of(got), of(expected), "{what}: {family:?} frames");
    }
    assert_eq!(got.len(), expected.len(), "{what}: frames");
}

/// Panics unless `decoded` and the state of `d` (flushed) are a consistent decoding of
/// `input`: every format's decoder counted every byte, and each format's frames pass that
/// format's whole-stream checks (`check_v3_stream` and the others; HW-FOC's and DataLink's
/// when the stream held frames of one of them only, as their byte counts assume).
pub fn check_detected(input: &[u8], decoded: &[detect::Decoded], d: &detect::Decoder) {
    assert_eq!(d.bytes(), input.len() as u64, "bytes given");
    assert_eq!(d.buffered(), 0, "nothing held after a flush");
    let (mut esc, mut hub, mut five, mut four, mut three) =
        (vec![], vec![], vec![], vec![], vec![]);
    for x in decoded {
        match *x {
            detect::Decoded::Mixed(mixed::Decoded::Esc(f)) => esc.push(f),
            detect::Decoded::Mixed(mixed::Decoded::Hub(f)) => hub.push(f),
            detect::Decoded::Hw5(f) => five.push(f),
            detect::Decoded::HwV4(f) => four.push(f),
            detect::Decoded::HwV3(f) => three.push(f),
        }
    }
    let m = d.mixed_stats();
    assert_eq!(m.hub.bytes(), input.len() as u64, "DataLink bytes counted");
    if hub.is_empty() {
        check_stream(input, &esc, &m.esc);
    }
    if esc.is_empty() {
        check_datalink_stream(input, &hub, &m.hub);
    }
    check_hw5_stream(input, &five, d.stats::<hwfoc::hw5::Scanner>());
    check_v4_stream(input, &four, d.stats::<hwfoc::v4::Scanner>());
    check_v3_stream(input, &three, d.stats::<hwfoc::v3::Scanner>());
}

/// The whole check of the `detect` target: `decode_all` (checked by [`check_detected`]), a
/// byte at a time (the same frames and state), and fed as the schedule says (the layout of
/// [`feed_scheduled`], `line_silent_each(k, k)` for `195..=199`), checked after every call
/// (the byte count, a frame's offset before the bytes given) and at the end (by
/// [`check_detected`], and the same frames and state as `decode_all` when nothing settled
/// the stream mid-way).
pub fn check_detect(data: &[u8]) {
    let Some((schedule, input)) = split_schedule(data) else {
        return;
    };
    let mut all = detect::Decoder::new();
    let mut bulk = Vec::new();
    all.decode_all(input, |x| bulk.push(x));
    check_detected(input, &bulk, &all);
    let state = detect_state(&all);

    let mut bytewise = detect::Decoder::new();
    let mut got = Vec::new();
    for &b in input {
        bytewise.feed(&[b], |x| got.push(x));
    }
    bytewise.flush(|x| got.push(x));
    assert_same_detected(&got, &bulk, "byte at a time");
    assert_eq!(detect_state(&bytewise), state, "byte at a time");

    let n = schedule.len();
    let mut dec = detect::Decoder::new();
    let mut got = Vec::new();
    let (mut at, mut step, mut idle_steps) = (0, 0, 0);
    let mut settled_mid_stream = false;
    while at < input.len() {
        let op = schedule[step % n];
        step += 1;
        let left = input.len() - at;
        match op {
            0 | 190..=199 => {
                match op {
                    0 => dec.feed(&[], |x| got.push(x)),
                    190..=194 => dec.flush(|x| got.push(x)),
                    _ => {
                        let k = u32::from(op - 195);
                        dec.line_silent_each(k, k, |x| got.push(x));
                        assert_eq!(dec.locked(), None, "detecting after a silence");
                    }
                }
                settled_mid_stream |= op != 0;
                idle_steps += 1;
                if idle_steps >= n {
                    dec.feed(&input[at..at + 1], |x| got.push(x));
                    at += 1;
                    idle_steps = 0;
                }
            }
            200..=254 => {
                for &b in &input[at..at + usize::from(op - 199).min(left)] {
                    dec.feed(&[b], |x| got.push(x));
                    at += 1;
                }
                idle_steps = 0;
            }
            _ => {
                let len = if op == 255 {
                    left
                } else {
                    usize::from(op).min(left)
                };
                dec.feed(&input[at..at + len], |x| got.push(x));
                at += len;
                idle_steps = 0;
            }
        }
        assert_eq!(dec.bytes(), at as u64, "bytes fed so far");
        if let Some(last) = got.last() {
            assert!(last.offset() < at as u64, "a frame beyond the bytes fed");
        }
    }
    dec.flush(|x| got.push(x));
    check_detected(input, &got, &dec);
    if !settled_mid_stream {
        assert_same_detected(&got, &bulk, "scheduled");
        assert_eq!(detect_state(&dec), state, "scheduled");
    }
}
