//! Timed decoding: the codec's streaming decoder plus the receive time of each frame.
//!
//! [`Stream`] is one ESC's stream: every command's frames come out of one (through
//! [`crate::sources::Sources`] for inputs read to their end, through [`PortStreams`] for live
//! port events). [`byte_times`] is the one place where a chunk's receive time becomes the time
//! of each of its bytes.

use hwfoc::{Decoded, Decoder, LinkStats, Settings};

use crate::handler::Handler;

use crate::input::Batch;
use crate::pcapng;
use crate::serial::PortEvent;

/// Appends to `times` the receive times, in Unix seconds, of `n` bytes the first of which
/// arrived at `t_ns` (Unix ns) and each next one `per_byte_ns` later (a byte time at the line's
/// baud rate: bytes of one read arrived back to back).
pub fn byte_times(t_ns: u64, per_byte_ns: f64, n: usize, times: &mut Vec<f64>) {
    times.extend((0..n).map(|i| pcapng::byte_time_s(t_ns, i, per_byte_ns)));
}

/// How many receive times to keep from earlier batches: a frame still arriving is shorter than
/// the longest frame (77 bytes), so its first byte is never further back than this.
const TIME_HISTORY: usize = hwfoc::frame::MAX_FRAME_LEN;

/// A silence of the line longer than this, between two bytes, may hide a restart of the ESC:
/// the decoder is told of it (see [`hwfoc::Decoder::line_silent`]). Real ESCs send a frame at
/// least every 364 ms (idle), and a read may return a little late.
pub const SILENCE_S: f64 = 1.0;

/// The most data frames a silence of `seconds` can have hidden: one per 24 byte times, the
/// fastest the line carries them (real ESCs send one every 50 ms at most).
fn frames_in(seconds: f64) -> u32 {
    let frame_s = 24.0 * hwfoc::wire::byte_ns(hwfoc::wire::BAUD_RATE) * 1e-9;
    (seconds / frame_s).ceil().min(f64::from(u32::MAX)) as u32
}

/// A [`Decoder`] that also gives each frame the receive time of its first byte.
#[derive(Debug, Default)]
pub struct Stream {
    decoder: Decoder,
    /// Receive times of the last bytes of earlier batches, oldest first.
    history: Vec<f64>,
}

impl Stream {
    /// A stream with nothing decoded yet.
    pub fn new() -> Stream {
        Stream::default()
    }

    /// Decodes a batch; `on_frame` gets each frame with its time (`None` without timing).
    pub fn feed(&mut self, batch: Batch<'_>, mut on_frame: impl FnMut(Option<f64>, &Decoded)) {
        let start = self.decoder.stats().bytes();
        match batch.times {
            None => {
                self.history.clear();
                self.decoder.feed(
                    batch.bytes,
                    #[inline(always)]
                    |d| on_frame(None, &d),
                );
            }
            Some(times) => {
                let history = &self.history;
                let decoder = &mut self.decoder;
                // The batch in pieces at each silence of the line: the decoder is told how many
                // frames the silence could have hidden, so that an ESC that restarted in it is
                // counted as a restart, not as thousands of lost packets.
                let mut from = 0;
                let mut last = history.last().copied();
                for (i, &t) in times.iter().enumerate() {
                    if let Some(before) = last
                        && t - before > SILENCE_S
                    {
                        decoder.feed(
                            &batch.bytes[from..i],
                            #[inline(always)]
                            |d| on_frame(Some(time_at(history, times, start, d.offset)), &d),
                        );
                        decoder.line_silent(frames_in(t - before), |d| {
                            on_frame(Some(time_at(history, times, start, d.offset)), &d)
                        });
                        from = i;
                    }
                    last = Some(t);
                }
                decoder.feed(
                    &batch.bytes[from..],
                    #[inline(always)]
                    |d| on_frame(Some(time_at(history, times, start, d.offset)), &d),
                );
                let keep = TIME_HISTORY.min(self.history.len() + times.len());
                let from_times = keep.min(times.len());
                let from_history = keep - from_times;
                self.history.drain(..self.history.len() - from_history);
                self.history
                    .extend_from_slice(&times[times.len() - from_times..]);
            }
        }
    }

    /// Ends the stream: a frame cut off at the end is dropped, frames inside it are still found.
    pub fn finish(&mut self, mut on_frame: impl FnMut(Option<f64>, &Decoded)) {
        let end = self.decoder.stats().bytes();
        let history = &self.history;
        let timed = !history.is_empty();
        self.decoder.flush(
            #[inline(always)]
            |d| {
                let t = timed.then(|| time_at(history, &[], end, d.offset));
                on_frame(t, &d)
            },
        );
    }

    /// The receive time of the first byte the decoder holds for a frame still arriving, if it
    /// holds any: no frame completed later can be older (later bytes are no older than the
    /// held ones). `None` when nothing is held or the stream has no times.
    pub fn held_since(&self) -> Option<f64> {
        let held = self.decoder.buffered();
        (held > 0 && held <= self.history.len()).then(|| self.history[self.history.len() - held])
    }

    /// The link statistics so far.
    pub fn stats(&self) -> &LinkStats {
        self.decoder.stats()
    }
}

/// A [`Stream`] per port, fed by [`PortEvent`]s: the path from live bytes to timed frames of
/// `monitor`, `record` and the bridges (and of [`crate::Input::open_ports`], through
/// [`byte_times`]).
#[derive(Debug)]
pub struct PortStreams {
    streams: Vec<Stream>,
    per_byte_ns: f64,
    times: Vec<f64>,
    settings: Settings,
}

impl PortStreams {
    /// `ports` streams, their bytes arriving at `baud` (8N1), their data frames made records
    /// under `settings`.
    pub fn new(ports: usize, baud: u32, settings: Settings) -> PortStreams {
        PortStreams {
            streams: (0..ports).map(|_| Stream::new()).collect(),
            per_byte_ns: hwfoc::wire::byte_ns(baud),
            times: Vec::new(),
            settings,
        }
    }

    /// Decodes the bytes of a [`PortEvent::Data`], handing each frame completed to `handler`
    /// as ESC number `port` (records of ports past 255 are not made: the `esc` column numbers
    /// 256). Other events, and ports beyond those made, are ignored. Returns the port's link
    /// statistics after the bytes, or `None` when there were no bytes for a known port.
    pub fn feed<H: Handler>(&mut self, event: &PortEvent, handler: &mut H) -> Option<&LinkStats> {
        let PortEvent::Data { port, t_ns, bytes } = event else {
            return None;
        };
        let stream = self.streams.get_mut(*port)?;
        self.times.clear();
        byte_times(*t_ns, self.per_byte_ns, bytes.len(), &mut self.times);
        let esc = u8::try_from(*port).ok();
        let settings = &self.settings;
        stream.feed(
            Batch {
                bytes,
                times: Some(&self.times),
                stream: *port,
            },
            |t, d| {
                if let Some(esc) = esc {
                    handler.frame(esc, t, d, settings);
                }
            },
        );
        Some(stream.stats())
    }

    /// The link statistics of `port`'s stream.
    pub fn stats(&self, port: usize) -> Option<&LinkStats> {
        self.streams.get(port).map(Stream::stats)
    }
}

/// Receive time of stream offset `offset`, where `times` holds the times of the bytes from
/// offset `start` on and `history` those just before `start`.
fn time_at(history: &[f64], times: &[f64], start: u64, offset: u64) -> f64 {
    if offset >= start {
        times[(offset - start) as usize]
    } else {
        history[history.len() - (start - offset) as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::DataFrame;

    #[test]
    fn frame_times_survive_any_batching() {
        let mut wire = vec![0x9B, 0x00];
        for packet in 0..6u16 {
            wire.extend_from_slice(
                &DataFrame {
                    packet,
                    ..Default::default()
                }
                .encode(),
            );
            wire.push(0x42);
        }
        let times: Vec<f64> = (0..wire.len()).map(|i| i as f64 * 0.5).collect();
        let expected: Vec<f64> = (0..6).map(|k| (2 + 25 * k) as f64 * 0.5).collect();
        for batch in [1, 2, 7, 23, 24, 25, 76, 77, 1000] {
            let mut stream = Stream::new();
            let mut got = Vec::new();
            for (b, t) in wire.chunks(batch).zip(times.chunks(batch)) {
                stream.feed(
                    Batch {
                        bytes: b,
                        times: Some(t),
                        stream: 0,
                    },
                    |t, _| got.push(t.unwrap()),
                );
            }
            stream.finish(|t, _| got.push(t.unwrap()));
            assert_eq!(got, expected, "batches of {batch}");
        }
    }

    /// Frames `packets`, each 50 ms after the last from `t0`, their bytes timed as on the wire.
    fn timed(packets: &[u16], t0: f64) -> (Vec<u8>, Vec<f64>) {
        let (mut bytes, mut times) = (Vec::new(), Vec::new());
        for (k, &packet) in packets.iter().enumerate() {
            let f = DataFrame {
                packet,
                ..Default::default()
            }
            .encode();
            for (j, &b) in f.iter().enumerate() {
                bytes.push(b);
                times.push(t0 + k as f64 * 0.05 + j as f64 / 1920.0);
            }
        }
        (bytes, times)
    }

    /// The statistics of a stream fed `parts`, each a batch, in batches of `chunk` bytes.
    fn run(parts: &[(Vec<u8>, Vec<f64>)], chunk: usize) -> LinkStats {
        let mut stream = Stream::new();
        for (bytes, times) in parts {
            for (b, t) in bytes.chunks(chunk).zip(times.chunks(chunk)) {
                let batch = Batch {
                    bytes: b,
                    times: Some(t),
                    stream: 0,
                };
                stream.feed(batch, |_, _| {});
            }
        }
        stream.finish(|_, _| {});
        *stream.stats()
    }

    /// The first byte held of a frame still arriving bounds the time of any frame to come.
    #[test]
    fn held_bytes_give_their_first_time() {
        let (bytes, times) = timed(&[7, 8], 100.0);
        let mut stream = Stream::new();
        assert_eq!(stream.held_since(), None);
        // The first frame whole and 10 bytes of the second: those 10 are held.
        let cut = 24 + 10;
        stream.feed(
            Batch {
                bytes: &bytes[..cut],
                times: Some(&times[..cut]),
                stream: 0,
            },
            |_, _| {},
        );
        assert_eq!(stream.held_since(), Some(times[24]));
        let mut got = Vec::new();
        stream.feed(
            Batch {
                bytes: &bytes[cut..],
                times: Some(&times[cut..]),
                stream: 0,
            },
            |t, _| got.push(t.unwrap()),
        );
        assert_eq!(got, [times[24]]);
        assert_eq!(stream.held_since(), None);
    }

    /// An ESC that restarts after a silence counts a restart, not the packets its new numbers
    /// skip; a silence that only hid frames counts them as lost.
    #[test]
    fn a_silence_tells_a_restart_from_a_loss() {
        let before = timed(&[64_990, 64_991, 64_992], 10.0);
        // 1.5 s later the ESC counts again 536 numbers on (wrapping): a restart, as at most 120
        // frames fit in the silence.
        let restarted = timed(&[65_528, 65_529], 11.6);
        // 2 s later, 30 numbers on: frames lost in the silence.
        let resumed = timed(&[23, 24], 13.7);
        for chunk in [1, 7, 24, 100, 10_000] {
            let s = run(&[before.clone(), restarted.clone(), resumed.clone()], chunk);
            assert_eq!(s.frames(), 7, "chunk {chunk}");
            assert_eq!(s.restarts(), 1, "chunk {chunk}");
            assert_eq!(s.lost_packets(), 29, "chunk {chunk}");
        }
        // The same numbers without the silence: a step of 536 is a loss (the rule for raw
        // bytes), so the silence is what told the restart.
        let close = timed(&[65_528, 65_529], 10.2);
        let s = run(&[before, close], 24);
        assert_eq!((s.restarts(), s.lost_packets()), (0, 535));
    }
}
