//! Where a port's bytes are cut into packets: at frame boundaries, found by the codec's decoder.
//!
//! A [`Cutter`] takes the bytes of one port as they are read, each read with the receive time of
//! its first byte, and gives back pieces to write as packets:
//! - each frame the decoder finds, whole, timestamped with its first byte's time;
//! - the bytes between frames (line noise, frames that fail their checksum, frames cut short),
//!   timestamped with their first byte's time, cut wherever a read began (so each keeps the
//!   time of its read, as the chunks of the read-chunk layout do);
//! - nothing else: the bytes of a frame still arriving (the decoder's undecided candidate, fewer
//!   than 77) are held until the frame completes, or until [`Cutter::settle`] decides them.
//!
//! The time of byte `k` of a read that began at `t_ns` is `t_ns + round(k * byte time)`, the
//! rule of the read-chunk layout's splits of long reads; a reader that gives the bytes of a packet
//! times one byte time apart so finds every frame's first byte at the time it would have found
//! it in the read chunk (to the rounding of a nanosecond).

use hwfoc::foc::Decoder;

/// One port's bytes on their way to packets.
#[derive(Debug, Clone)]
pub(crate) struct Cutter {
    decoder: Decoder,
    per_byte_ns: f64,
    /// Bytes received but not yet given out, oldest first.
    held: Vec<u8>,
    /// Where each read in `held` begins: (index in `held`, its first byte's time, how many bytes
    /// of the read came before that index). Sorted by index; the first is at index 0 whenever
    /// `held` is not empty.
    reads: Vec<Read>,
    /// Stream offset (as the decoder counts) of `held[0]`.
    held_from: u64,
    /// Receive time of the last byte fed (Unix ns).
    last_ns: u64,
}

#[derive(Debug, Clone, Copy)]
struct Read {
    at: usize,
    t_ns: u64,
    skipped: usize,
}

impl Cutter {
    /// A cutter for a port whose bytes are `per_byte_ns` apart on the line.
    pub(crate) fn new(per_byte_ns: f64) -> Cutter {
        Cutter {
            decoder: Decoder::new(),
            per_byte_ns,
            held: Vec::new(),
            reads: Vec::new(),
            held_from: 0,
            last_ns: 0,
        }
    }

    /// Whether bytes are held.
    pub(crate) fn holds(&self) -> bool {
        !self.held.is_empty()
    }

    /// Receive time of the last byte fed.
    pub(crate) fn last_ns(&self) -> u64 {
        self.last_ns
    }

    /// Feeds a read of `data` whose first byte arrived at `t_ns`; `emit` gets every piece now
    /// decided, in order, as (first byte's time, bytes).
    pub(crate) fn feed<E>(&mut self, t_ns: u64, data: &[u8], emit: &mut E) -> Result<(), E::Error>
    where
        E: PieceSink,
    {
        if data.is_empty() {
            return Ok(());
        }
        self.reads.push(Read {
            at: self.held.len(),
            t_ns,
            skipped: 0,
        });
        self.held.extend_from_slice(data);
        self.last_ns = t_ns.saturating_add(self.offset_ns(data.len() - 1));
        let mut frames = Vec::new();
        self.decoder
            .feed(data, |d| frames.push((d.offset, d.frame.wire_len())));
        self.give_out(&frames, emit)
    }

    /// Decides the held bytes now, as at the end of the stream (a frame cut short is given out
    /// as bytes between frames), and gives them all out.
    pub(crate) fn settle<E: PieceSink>(&mut self, emit: &mut E) -> Result<(), E::Error> {
        let mut frames = Vec::new();
        self.decoder
            .flush(|d| frames.push((d.offset, d.frame.wire_len())));
        self.give_out(&frames, emit)
    }

    /// Gives out `frames` (stream offset, length) and the bytes before them, then every byte
    /// the decoder has decided.
    fn give_out<E: PieceSink>(
        &mut self,
        frames: &[(u64, usize)],
        emit: &mut E,
    ) -> Result<(), E::Error> {
        let mut done = 0; // index in `held` of the first byte not yet given out
        for &(offset, len) in frames {
            let at = (offset - self.held_from) as usize;
            self.between(done, at, emit)?;
            emit.piece(self.time_of(at), &self.held[at..at + len])?;
            done = at + len;
        }
        let decided = self.decoder.stats().bytes() - self.decoder.buffered() as u64;
        let decided = (decided - self.held_from) as usize;
        self.between(done, decided.max(done), emit)?;
        let done = decided.max(done);
        self.drop_front(done);
        Ok(())
    }

    /// Gives out `held[from..to]`, bytes between frames: a piece per read they come from.
    fn between<E: PieceSink>(&self, from: usize, to: usize, emit: &mut E) -> Result<(), E::Error> {
        let mut at = from;
        while at < to {
            let next = self
                .reads
                .iter()
                .map(|r| r.at)
                .find(|&start| start > at)
                .map_or(to, |start| start.min(to));
            emit.piece(self.time_of(at), &self.held[at..next])?;
            at = next;
        }
        Ok(())
    }

    /// Receive time of `held[i]`.
    fn time_of(&self, i: usize) -> u64 {
        let read = self
            .reads
            .iter()
            .rev()
            .find(|r| r.at <= i)
            .copied()
            .unwrap_or(Read {
                at: 0,
                t_ns: self.last_ns,
                skipped: 0,
            });
        read.t_ns
            .saturating_add(self.offset_ns(read.skipped + (i - read.at)))
    }

    /// Nanoseconds from a read's first byte to its byte `k`.
    fn offset_ns(&self, k: usize) -> u64 {
        (k as f64 * self.per_byte_ns).round() as u64
    }

    /// Forgets `held[..n]`, given out.
    fn drop_front(&mut self, n: usize) {
        if n == 0 {
            return;
        }
        // The read that byte `n` belongs to now begins at index 0, `n - at` bytes in.
        let keep = self.reads.iter().rposition(|r| r.at <= n).unwrap_or(0);
        self.reads.drain(..keep);
        if let Some(first) = self.reads.first_mut() {
            first.skipped += n - first.at;
            first.at = 0;
        }
        for r in self.reads.iter_mut().skip(1) {
            r.at -= n;
        }
        self.held.drain(..n);
        self.held_from += n as u64;
        if self.held.is_empty() {
            self.reads.clear();
        }
    }
}

/// Where a [`Cutter`]'s pieces go.
pub(crate) trait PieceSink {
    /// The error of writing a piece.
    type Error;
    /// A piece: bytes to write as one packet (or several, if longer than a packet may be),
    /// the first received at `t_ns`.
    fn piece(&mut self, t_ns: u64, bytes: &[u8]) -> Result<(), Self::Error>;
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::foc::{DataFrame, InfoFrame};

    struct Pieces(Vec<(u64, Vec<u8>)>);

    impl PieceSink for Pieces {
        type Error = ();
        fn piece(&mut self, t_ns: u64, bytes: &[u8]) -> Result<(), ()> {
            self.0.push((t_ns, bytes.to_vec()));
            Ok(())
        }
    }

    fn data(packet: u16) -> Vec<u8> {
        DataFrame {
            packet,
            voltage_raw: 250,
            ..Default::default()
        }
        .encode()
        .to_vec()
    }

    /// A stream of frames and noise: (bytes, the pieces expected as byte ranges).
    fn stream() -> (Vec<u8>, Vec<std::ops::Range<usize>>) {
        let info = InfoFrame::new("XR_FOC_ESC", "HW577_KZ1_V1.1", "XR-01.0.00", "01040443")
            .unwrap()
            .encode();
        let mut wire = Vec::new();
        let mut pieces = Vec::new();
        let mut add = |wire: &mut Vec<u8>, bytes: &[u8]| {
            pieces.push(wire.len()..wire.len() + bytes.len());
            wire.extend_from_slice(bytes);
        };
        add(&mut wire, &data(1));
        add(&mut wire, &[0x00, 0x9B, 0x13, 0x9B]); // noise with sync bytes
        add(&mut wire, &data(2));
        add(&mut wire, &info);
        let mut bad = data(3);
        bad[9] ^= 0x10;
        add(&mut wire, &bad); // fails its checksum: bytes between frames
        add(&mut wire, &data(4)[..10]); // a cut frame, then a whole one
        add(&mut wire, &data(5));
        add(&mut wire, &[0x9B]); // a lone sync byte at the end
        (wire, pieces)
    }

    fn cut(wire: &[u8], reads: &[usize], per_byte: f64) -> Vec<(u64, Vec<u8>)> {
        let mut cutter = Cutter::new(per_byte);
        let mut out = Pieces(Vec::new());
        let mut at = 0;
        for (k, &n) in reads.iter().enumerate() {
            let n = n.min(wire.len() - at);
            // Each read arrives 1 ms after the previous one's time plus its bytes.
            let t = 1_000_000_000 + (at as f64 * per_byte).round() as u64 + k as u64 * 1_000_000;
            cutter.feed(t, &wire[at..at + n], &mut out).unwrap();
            at += n;
        }
        if at < wire.len() {
            cutter.feed(2_000_000_000, &wire[at..], &mut out).unwrap();
        }
        cutter.settle(&mut out).unwrap();
        assert!(!cutter.holds());
        out.0
    }

    #[test]
    fn frames_get_packets_of_their_own_whatever_the_reads() {
        let (wire, want) = stream();
        let per_byte = hwfoc::wire::byte_ns(19200);
        // Read in one piece: exactly the frames and the noise between them.
        let pieces = cut(&wire, &[wire.len()], per_byte);
        let got: Vec<Vec<u8>> = pieces.iter().map(|p| p.1.clone()).collect();
        let expected: Vec<Vec<u8>> = want.iter().map(|r| wire[r.clone()].to_vec()).collect();
        // The bad frame and the cut one are adjacent noise: one piece.
        let mut merged = expected.clone();
        let bad_and_cut = [merged[4].clone(), merged[5].clone()].concat();
        merged.splice(4..6, [bad_and_cut]);
        assert_eq!(got, merged);
        for (p, start) in pieces.iter().zip([0, 24, 28, 52, 129, 163, 187]) {
            assert_eq!(
                p.0,
                1_000_000_000 + (start as f64 * per_byte).round() as u64
            );
        }

        // Read in every chunking: the bytes are all there, in order, and every frame is one
        // piece timestamped with its first byte's time (reads here are 1 ms late each).
        for size in 1..=80 {
            let reads = vec![size; wire.len() / size + 1];
            let pieces = cut(&wire, &reads, per_byte);
            let joined: Vec<u8> = pieces.iter().flat_map(|p| p.1.clone()).collect();
            assert_eq!(joined, wire, "reads of {size}");
            for frame in [&want[0], &want[2], &want[3], &want[6]] {
                let piece = pieces
                    .iter()
                    .find(|p| p.1 == wire[frame.clone()])
                    .unwrap_or_else(|| {
                        panic!("reads of {size}: frame at {} not whole", frame.start)
                    });
                let read = frame.start / size;
                let t = 1_000_000_000
                    + ((read * size) as f64 * per_byte).round() as u64
                    + read as u64 * 1_000_000
                    + ((frame.start - read * size) as f64 * per_byte).round() as u64;
                assert!(
                    piece.0.abs_diff(t) <= 1,
                    "reads of {size}: time of {}",
                    frame.start
                );
            }
        }
    }

    #[test]
    fn a_frame_still_arriving_is_held_until_it_completes_or_settles() {
        let frame = data(9);
        let mut cutter = Cutter::new(1000.0);
        let mut out = Pieces(Vec::new());
        cutter.feed(5_000, &frame[..10], &mut out).unwrap();
        assert!(out.0.is_empty() && cutter.holds());
        assert_eq!(cutter.last_ns(), 14_000);
        cutter.feed(90_000, &frame[10..], &mut out).unwrap();
        assert_eq!(out.0, [(5_000, frame.clone())]);
        assert!(!cutter.holds());

        // Cut short: settling gives the bytes out, as noise.
        cutter.feed(100_000, &frame[..7], &mut out).unwrap();
        assert_eq!(out.0.len(), 1);
        cutter.settle(&mut out).unwrap();
        assert_eq!(out.0[1], (100_000, frame[..7].to_vec()));
        // Settling nothing gives nothing.
        cutter.settle(&mut out).unwrap();
        cutter.feed(0, &[], &mut out).unwrap();
        assert_eq!(out.0.len(), 2);
    }
}
