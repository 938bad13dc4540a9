//! A large raw file read in two halves at once: the later half on a thread of its own, its
//! frames taken by a part of the handler ([`Handler::fork`]), the two joined where they meet.
//!
//! The later half's reader finds the first frame at or after the middle of the file (the
//! seam) and decodes from there with a new [`Stream`], handing its frames to the handler's
//! part. The earlier half is read as any input is, up to the seam. If its decoder holds no byte
//! there (nothing before the seam waits for a later byte to be decided), a decoder started new
//! at the seam finds exactly the frames the one decoder would have found from there, so the
//! two streams' statistics and the handler's two parts are joined ([`Stream::then`],
//! [`Handler::join`]). Otherwise (a frame across the seam, DataLink hub frames, whose channels
//! are numbered as they appear, a read error in the later half) the later half's work is
//! dropped and the earlier half's reader goes on to the end alone. Either way the result is
//! that of reading the file once, in order.
//!
//! (A summary of a raw file does little for each frame, so reading, decoding and summarising
//! are each a fair share of its time: one core each for two halves is what makes it about
//! twice as fast, where a reader thread feeding one decoder was not. Neither `std` nor a crate
//! of the workspace splits a stream's decoding.)
//!
//! [`Handler::fork`]: crate::Handler::fork
//! [`Handler::join`]: crate::Handler::join

use std::io;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};

use hwfoc::telemetry::{AnyFrame, Data, Telemetry};
use hwfoc::{Protocol, Settings};

use super::{HELD, Held, Takes, feed_runs};
use crate::handler::LaterPart;
use crate::input::{BATCH, Batch, Beside, ReadAt};
use crate::stream::Stream;

/// The smallest raw file read in two halves: below it, starting a thread is not worth it.
pub(super) const SPLIT_MIN: u64 = 64 << 20;

/// Whether the platform has positional reads that leave the earlier half's file offset alone:
/// Unix's `pread` (Windows' `seek_read` moves the offset a duplicated handle shares).
pub(super) const AVAILABLE: bool = cfg!(unix);

/// The later half of a raw file, being read on a thread of its own.
pub(super) struct Later {
    /// Where its reader starts looking for the seam: the middle of the file.
    start: u64,
    /// The seam, from its reader: `None` when there is no frame after `start`.
    seam: Receiver<Option<u64>>,
    /// The seam once received.
    found: Option<Option<u64>>,
    /// Asks the reader to stop (the later half's work is not wanted).
    stop: Arc<AtomicBool>,
    /// What the reader did, once it ended.
    done: Receiver<Option<Done>>,
    /// The reader, running beside ([`ReadAt::read_beside`]) until it is joined.
    thread: Option<Box<dyn Beside>>,
}

/// What the later half's reader did, from the seam to the end of the file.
pub(super) struct Done {
    /// Its stream, ended.
    pub(super) stream: Stream,
    /// The handler's part, with every frame after the seam.
    pub(super) part: Box<dyn LaterPart>,
    /// The packet number of its first data frame.
    pub(super) first_packet: Option<u16>,
    /// Bytes read from the seam to the end.
    pub(super) bytes: u64,
}

impl Later {
    /// Starts reading the later half of `file`, `len` bytes long, with a new stream of the
    /// protocol `forced` (every protocol when `None`); its frames, of ESC `esc`, go to `part`
    /// under `settings`. `None` where no thread can be started or the platform has no
    /// positional reads.
    pub(super) fn start(
        file: Box<dyn ReadAt>,
        len: u64,
        forced: Option<Protocol>,
        part: Box<dyn LaterPart>,
        esc: u8,
        settings: Settings,
    ) -> Option<Later> {
        if !AVAILABLE {
            return None;
        }
        let start = len / 2;
        let (seam_tx, seam) = sync_channel(1);
        let stop = Arc::new(AtomicBool::new(false));
        let asked = Arc::clone(&stop);
        let (done_tx, done) = sync_channel(1);
        let thread = file.read_beside(Box::new(move |file| {
            let reader = Reader {
                file,
                forced,
                esc,
                settings,
                stop: asked,
            };
            let _ = done_tx.send(reader.run(start, part, &seam_tx));
        }))?;
        Some(Later {
            start,
            seam,
            found: None,
            stop,
            done,
            thread: Some(thread),
        })
    }

    /// Where in a batch of `len` bytes at stream offset `from` the earlier half ends: the
    /// seam's place in it, when it falls there. Once the earlier half reaches the middle of the
    /// file, this waits for the later half's reader to have found the seam (at once, unless the
    /// bytes after the middle hold no frame for a long way).
    pub(super) fn cut(&mut self, from: u64, len: usize) -> Option<usize> {
        let end = from + len as u64;
        if end < self.start {
            return None;
        }
        let seam = *self
            .found
            .get_or_insert_with(|| self.seam.recv().ok().flatten());
        seam.filter(|&seam| (from..=end).contains(&seam))
            .map(|seam| (seam - from) as usize)
    }

    /// Waits for the later half's reader to end: what it did, or `None` where it could not be
    /// joined (a read error, hub frames, no frame).
    pub(super) fn finish(mut self) -> Option<Done> {
        self.thread.take()?.join();
        self.done.try_recv().ok().flatten()
    }
}

impl Drop for Later {
    /// Stops the later half's reader (at its next block) and waits for it, unless it was
    /// finished.
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            thread.join();
        }
    }
}

/// The later half's reader.
struct Reader {
    file: Box<dyn ReadAt>,
    forced: Option<Protocol>,
    esc: u8,
    settings: Settings,
    stop: Arc<AtomicBool>,
}

impl Reader {
    /// Finds the seam (the first frame at or after `start`), says where it is, and decodes
    /// from there to the end of the file into `part`.
    fn run(
        self,
        start: u64,
        part: Box<dyn LaterPart>,
        seam_tx: &SyncSender<Option<u64>>,
    ) -> Option<Done> {
        let mut block = vec![0; BATCH];
        let seam = self.seam(start, &mut block);
        let _ = seam_tx.send(seam);
        self.decode(seam?, part, &mut block)
    }

    /// The stream offset of the first frame at or after `start`, if any.
    fn seam(&self, start: u64, block: &mut [u8]) -> Option<u64> {
        let mut probe = Stream::forced(self.forced);
        let mut pos = start;
        loop {
            let n = self.read(block, pos)?;
            if n == 0 {
                return None;
            }
            let mut first = None;
            probe.feed_untimed(&block[..n], |_, offset, _| {
                first.get_or_insert(offset);
            });
            if let Some(offset) = first {
                return Some(start + offset);
            }
            pos += n as u64;
        }
    }

    /// Decodes from `seam` to the end of the file with a new stream, the frames to `part`:
    /// `None` (the work is not joined) at a DataLink hub frame, a read error or when asked to
    /// stop.
    fn decode(&self, seam: u64, mut part: Box<dyn LaterPart>, block: &mut [u8]) -> Option<Done> {
        let mut stream = Stream::forced(self.forced);
        let mut held = Box::new(Held {
            frames: [hwfoc::foc::DataFrame::default(); HELD],
        });
        let mut to = ToPart {
            part: &mut *part,
            esc: self.esc,
            settings: &self.settings,
            first_packet: None,
            hub: false,
        };
        let mut pos = seam;
        loop {
            let n = self.read(block, pos)?;
            if n == 0 {
                break;
            }
            let batch = Batch {
                bytes: &block[..n],
                times: None,
                stream: 0,
            };
            feed_runs(&mut stream, batch, &mut held, &mut to);
            if to.hub {
                return None;
            }
            pos += n as u64;
        }
        stream.finish(|_, channel, frame| to.other(None, channel, frame));
        let (first_packet, hub) = (to.first_packet, to.hub);
        (!hub).then_some(Done {
            stream,
            part,
            first_packet: first_packet.flatten(),
            bytes: pos - seam,
        })
    }

    /// Reads the block at stream offset `pos` (fewer bytes at the end of the file, none past
    /// it); `None` at an error or when asked to stop.
    fn read(&self, block: &mut [u8], pos: u64) -> Option<usize> {
        if self.stop.load(Ordering::Relaxed) {
            return None;
        }
        loop {
            match self.file.read_at(block, pos) {
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                read => return read.ok(),
            }
        }
    }
}

/// The handler's part as [`feed_runs`] hands it the frames of the later half.
struct ToPart<'a> {
    part: &'a mut dyn LaterPart,
    esc: u8,
    settings: &'a Settings,
    /// The packet number of the first data frame, once one was seen.
    first_packet: Option<Option<u16>>,
    /// Whether a frame of a DataLink hub's channel was found: then the halves are not joined.
    hub: bool,
}

impl ToPart<'_> {
    /// Notes the first data frame's packet number.
    #[inline(always)]
    fn data(&mut self, f: &Data) {
        if self.first_packet.is_none() {
            // A stream read in halves is HW-FOC's (a hub's is not joined): 16-bit counters.
            self.first_packet = Some(f.packet().and_then(|p| u16::try_from(p).ok()));
        }
    }
}

impl Takes for ToPart<'_> {
    /// As the summary takes them.
    const RUNS: bool = true;

    #[inline(always)]
    fn run(&mut self, frames: &[hwfoc::foc::DataFrame]) {
        if let Some(f) = frames.first() {
            self.data(&Data::HwFoc(*f));
        }
        self.part.untimed_data(self.esc, frames, self.settings);
    }

    fn other(&mut self, _: Option<f64>, channel: Option<u8>, frame: &AnyFrame) {
        match (channel, frame) {
            (Some(_), _) => self.hub = true,
            (None, frame) => {
                if let AnyFrame::Data(f) = frame {
                    self.data(f);
                }
                self.part.frame(self.esc, frame, self.settings);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use hwfoc::foc::{DataFrame, InfoFrame};
    use hwfoc::{Protocol, Settings, Status};

    use crate::input::file::memory::MemoryFile;
    use crate::sources::Sources;
    use crate::sources::tests::hub_wire;
    use crate::stream::LinkStats;
    use crate::summary::Summary;

    /// What a summary of a raw file shows, and the links and bytes it was made of.
    #[derive(Debug, PartialEq)]
    struct Read {
        report: serde_json::Value,
        links: Vec<LinkStats>,
        bytes: Vec<u64>,
    }

    /// Summarises the raw file `path`, in two halves at once when `split` (whatever its
    /// size), else in one; with protocol `forced` only when given. What it read, and whether
    /// the halves were joined.
    fn summarise(file: &MemoryFile, split: bool, forced: Option<Protocol>) -> (Read, bool) {
        let input = file.input().unwrap();
        let mut sources = Sources::new(vec![input], Settings::DEFAULT);
        sources.split_at_least(if split { 1 } else { u64::MAX });
        if let Some(p) = forced {
            sources.force_protocol(p);
        }
        let mut summary = Summary::new();
        sources.run(&mut summary).unwrap();
        let links = (0..sources.escs().len()).map(|e| sources.link(e)).collect();
        let read = Read {
            report: summary.report(&sources).json(),
            links,
            bytes: sources.inputs().iter().map(|i| i.bytes).collect(),
        };
        (read, sources.joined_halves() > 0)
    }

    /// Asserts that `bytes`, as a raw file, summarise alike in one reading and in two halves
    /// at once, and whether the halves were joined (`joined`, unless `None`).
    #[track_caller]
    fn assert_alike(bytes: &[u8], forced: Option<Protocol>, joined: Option<bool>, case: &str) {
        let file = MemoryFile::new("raw.bin", bytes.to_vec());
        let (one, _) = summarise(&file, false, forced);
        let (two, was_joined) = summarise(&file, true, forced);
        assert!(
            one == two,
            "{case}: one reading\n{one:?}\ntwo halves\n{two:?}"
        );
        if let Some(joined) = joined {
            assert_eq!(was_joined, joined, "{case}: halves joined");
        }
    }

    /// A data frame with packet number `packet` and status `status`, its values from both.
    fn data(packet: u16, status: u16) -> [u8; 24] {
        DataFrame {
            packet,
            throttle_in_raw: packet % 1024,
            throttle_out_raw: packet.wrapping_mul(7) % 1024,
            erpm_raw: packet.wrapping_mul(13),
            voltage_raw: 200 + packet % 300,
            current_raw: (packet % 700) as i16 - 100,
            phase_current_raw: (packet % 900) as i16 - 50,
            mos_adc: (packet % 251) as u8,
            cap_adc: (packet / 3 % 247) as u8,
            status: Status(status),
        }
        .encode()
    }

    fn info(id: &str) -> Vec<u8> {
        InfoFrame::new("XR_FOC_ESC", "HW577", "XR-01.0.00", id)
            .unwrap()
            .encode()
            .to_vec()
    }

    /// `frames` data frames from packet `first`, faults on those whose index is in `faulty`.
    fn stream(first: u16, frames: usize, faulty: impl Fn(usize) -> bool) -> Vec<u8> {
        (0..frames)
            .flat_map(|i| {
                let status = if faulty(i) {
                    0x0040 | (i as u16 & 0x1000)
                } else {
                    0
                };
                data(first.wrapping_add(i as u16), status)
            })
            .collect()
    }

    /// Fault episodes at every place near the seam: open at the earlier half's end and going
    /// on, ending just before or at it, starting at it, one faulty frame at it, faults to the
    /// end; every one the same read in two halves.
    #[test]
    fn fault_episodes_across_the_seam_are_read_alike() {
        const N: usize = 2001;
        let mid = N / 2;
        for (a, b) in [
            (mid - 3, mid + 3),
            (mid - 3, mid),
            (mid - 3, mid + 1),
            (mid, mid + 2),
            (mid + 1, mid + 2),
            (mid, mid + 1),
            (mid - 1, mid + 1),
            (0, N),
            (mid - 2, N),
            (0, mid + 1),
        ] {
            for shift in 0..3 {
                let bytes = stream(100, N + shift, |i| (a..b).contains(&i));
                assert_alike(
                    &bytes,
                    None,
                    Some(true),
                    &format!("faults {a}..{b}, shift {shift}"),
                );
            }
        }
        // Many short episodes, one every other frame: more than are kept in detail.
        let bytes = stream(0, 24_000, |i| i % 2 == 1);
        assert_alike(&bytes, None, Some(true), "an episode every other frame");
    }

    /// Packet numbers at the seam that step on, skip, repeat or restart; device-information
    /// frames in either half (listed in the order first seen); a frame cut or garbage at the
    /// seam; garbage that holds no frame for a long way after the middle.
    #[test]
    fn what_lies_at_the_seam_is_read_alike() {
        let mid_frames = 1000;
        let steps: [(&str, u16); 4] = [("next", 1), ("gap", 5), ("same", 0), ("restart", 40_000)];
        for (name, step) in steps {
            let mut bytes = stream(7, mid_frames, |_| false);
            bytes.extend(stream(7 + mid_frames as u16 - 1 + step, mid_frames, |_| {
                false
            }));
            assert_alike(&bytes, None, Some(true), name);
        }
        let mut bytes = info("A");
        bytes.extend(stream(0, 800, |_| false));
        bytes.extend(info("B"));
        bytes.extend(stream(800, 800, |_| false));
        bytes.extend(info("A"));
        bytes.extend(info("C"));
        bytes.extend(stream(1600, 100, |_| false));
        assert_alike(&bytes, None, Some(true), "device information");
        // Garbage and a cut frame at the middle, of every length up to a frame and more (where
        // the cut frame's first bytes wait for the bytes after the seam, the halves are not
        // joined: the earlier half's reader goes on alone).
        for garbage in [1, 5, 23, 24, 30, 77, 200] {
            let mut bytes = stream(0, 1000, |_| false);
            let cut = data(1000, 0);
            bytes.extend_from_slice(&cut[..garbage.min(23)]);
            bytes.extend((0..garbage).map(|i| (i * 37 % 251) as u8 | 0x80));
            bytes.extend(stream(1001, 1000, |_| false));
            assert_alike(&bytes, None, None, &format!("{garbage} bytes at the seam"));
        }
        // No frame after the middle: the earlier half is read to the end alone.
        let mut bytes = stream(0, 100, |_| false);
        bytes.extend(std::iter::repeat_n(0x55, 10_000));
        assert_alike(&bytes, None, Some(false), "no frame after the middle");
    }

    /// A stream whose middle falls at every byte of a frame, and its neighbours.
    #[test]
    fn a_seam_at_every_byte_of_a_frame_is_read_alike() {
        for extra in 0..48 {
            let mut bytes = vec![0x9B; extra % 5];
            bytes.extend(stream(3, 300, |i| i % 97 == 0));
            bytes.extend((0..extra).map(|i| i as u8));
            assert_alike(&bytes, None, Some(true), &format!("{extra} more bytes"));
        }
    }

    /// Hub frames in either half: their channels are numbered as they appear, so the halves
    /// are not joined, and the result is that of one reading.
    #[test]
    fn hub_frames_are_read_in_one_reading() {
        let mut later_hub = stream(0, 2000, |_| false);
        later_hub.extend(hub_wire(1, 0..100, &[0, 2]));
        assert_alike(
            &later_hub,
            None,
            Some(false),
            "hub frames in the later half",
        );
        let mut earlier_hub = hub_wire(1, 0..100, &[0, 2]);
        earlier_hub.extend(stream(0, 2000, |_| false));
        assert_alike(
            &earlier_hub,
            None,
            Some(false),
            "hub frames in the earlier half",
        );
        // Forced to DataLink, an ESC's own frames are skipped bytes: no frame after the middle.
        assert_alike(
            &earlier_hub,
            Some(Protocol::DataLink),
            Some(false),
            "DataLink only",
        );
        assert_alike(
            &earlier_hub,
            Some(Protocol::HwFoc),
            Some(true),
            "HW-FOC only",
        );
    }

    /// Streams of every kind of frame and noise, cut in two at their middle: alike.
    #[test]
    fn random_streams_are_read_alike() {
        let mut seed = 0x2545_F491_4F6C_DD1D_u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        for case in 0..40 {
            let mut bytes = Vec::new();
            let mut packet = (next() % 65536) as u16;
            while bytes.len() < 40_000 {
                match next() % 16 {
                    0 => bytes.extend((0..next() % 60).map(|_| next() as u8)),
                    1 => bytes.extend(info(&format!("{}", next() % 3))),
                    2 => packet = packet.wrapping_add((next() % 2000) as u16),
                    3 => {
                        let f = data(packet, 0);
                        bytes.extend_from_slice(&f[..(next() % 24) as usize]);
                    }
                    _ => {
                        let status = if next() % 5 == 0 {
                            1 << (next() % 16)
                        } else {
                            0
                        };
                        bytes.extend_from_slice(&data(packet, status as u16));
                        packet = packet.wrapping_add(1);
                    }
                }
            }
            assert_alike(&bytes, None, None, &format!("case {case}"));
        }
    }
}
