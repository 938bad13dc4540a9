//! One telemetry stream: the codec's streaming decoder plus the receive time of each frame.

use hwfoc::{Decoded, Decoder, LinkStats};

use crate::input::Batch;

/// How many receive times to keep from earlier batches: a frame still arriving is shorter than
/// the longest frame (77 bytes), so its first byte is never further back than this.
const TIME_HISTORY: usize = hwfoc::frame::MAX_FRAME_LEN;

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
    pub fn feed(&mut self, batch: Batch<'_>, mut on_frame: impl FnMut(Option<f64>, Decoded)) {
        let start = self.decoder.stats().bytes();
        match batch.times {
            None => {
                self.history.clear();
                self.decoder.feed(batch.bytes, |d| on_frame(None, d));
            }
            Some(times) => {
                let history = &self.history;
                self.decoder.feed(batch.bytes, |d| {
                    on_frame(Some(time_at(history, times, start, d.offset)), d)
                });
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
    pub fn finish(&mut self, mut on_frame: impl FnMut(Option<f64>, Decoded)) {
        let end = self.decoder.stats().bytes();
        let history = &self.history;
        let timed = !history.is_empty();
        self.decoder.flush(|d| {
            let t = timed.then(|| time_at(history, &[], end, d.offset));
            on_frame(t, d)
        });
    }

    /// The link statistics so far.
    pub fn stats(&self) -> &LinkStats {
        self.decoder.stats()
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
}
