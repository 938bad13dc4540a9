//! A regular file read ahead on a thread of its own: while the decoder works on one block, the
//! next ones are read, so that the kernel's copy from the page cache (a fifth of the time of
//! `hwfoc summary` on a large raw file when done in turn) runs on another core. Blocks are
//! handed over whole, not copied again. (`std::io::BufReader` reads in the caller's thread; no
//! crate in the workspace reads ahead.)
//!
//! Only for regular files: a read of one always ends, so the thread always ends once its
//! reader is dropped. A pipe, a terminal or a device may block a read for ever.

use std::fs::File;
use std::io;
use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, sync_channel};
use std::thread::JoinHandle;

use hwfoc_records::{BATCH, BlockRead, read_some};

/// Blocks read ahead at most (each [`BATCH`] bytes).
const AHEAD: usize = 3;

/// A regular file being read ahead.
pub(super) struct ReadAhead {
    /// Blocks read, in file order; an error or an empty block ends them.
    full: Option<Receiver<io::Result<Vec<u8>>>>,
    /// Blocks given back, to be read into again.
    empty: Option<SyncSender<Vec<u8>>>,
    thread: Option<JoinHandle<()>>,
    /// Whether the end (or an error) was handed out.
    done: bool,
}

impl ReadAhead {
    /// Starts reading `file` from where it is; the file back if no thread could be started.
    pub(super) fn start(file: File) -> Result<ReadAhead, File> {
        // Kept to be given back if the thread cannot start (the closure, which owns `file`,
        // is dropped then).
        let Ok(back) = file.try_clone() else {
            return Err(file);
        };
        let (full_tx, full) = sync_channel::<io::Result<Vec<u8>>>(AHEAD);
        let (empty, empty_rx) = sync_channel::<Vec<u8>>(AHEAD + 2);
        let spawned = std::thread::Builder::new()
            .name("hwfoc-read-ahead".into())
            .spawn(move || read_blocks(file, &full_tx, &empty_rx));
        match spawned {
            Ok(thread) => Ok(ReadAhead {
                full: Some(full),
                empty: Some(empty),
                thread: Some(thread),
                done: false,
            }),
            Err(_) => Err(back),
        }
    }
}

impl BlockRead for ReadAhead {
    /// Puts the next block in `bytes` (its old buffer is given back to be read into again):
    /// its length, 0 at the end of the file.
    fn read(&mut self, bytes: &mut Vec<u8>) -> io::Result<usize> {
        let next = match (&self.full, self.done) {
            (Some(full), false) => full.recv(),
            _ => {
                bytes.clear();
                return Ok(0);
            }
        };
        match next {
            Ok(Ok(mut block)) => {
                std::mem::swap(bytes, &mut block);
                self.done = bytes.is_empty();
                if block.capacity() > 0
                    && let Some(empty) = &self.empty
                {
                    let _ = empty.try_send(block);
                }
                Ok(bytes.len())
            }
            Ok(Err(e)) => {
                self.done = true;
                bytes.clear();
                Err(e)
            }
            // The thread ended without a word: only a panic does that.
            Err(_) => {
                self.done = true;
                bytes.clear();
                Err(io::Error::other("the read-ahead thread stopped"))
            }
        }
    }
}

impl Drop for ReadAhead {
    /// Closes both channels, which ends the thread at its next send or receive (a read of a
    /// regular file in progress ends by itself), and waits for it.
    fn drop(&mut self) {
        self.full = None;
        self.empty = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The thread's loop: reads `file` a block at a time into the blocks given back (or new ones)
/// and sends them on, until the end of the file, an error, or either channel is closed.
fn read_blocks(mut file: File, full: &SyncSender<io::Result<Vec<u8>>>, empty: &Receiver<Vec<u8>>) {
    loop {
        let mut block = match empty.try_recv() {
            Ok(block) => block,
            Err(TryRecvError::Empty) => Vec::new(),
            Err(TryRecvError::Disconnected) => return,
        };
        block.resize(BATCH, 0);
        let read = read_some(&mut file, &mut block).map(|n| {
            block.truncate(n);
            block
        });
        let end = !matches!(&read, Ok(block) if !block.is_empty());
        if full.send(read).is_err() || end {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use std::io::Write;

    use super::*;
    use crate::input::OpenInput;
    use hwfoc_records::Input;

    /// A file of `len` bytes counting 0, 1, 2, … (modulo 251, so that no block repeats the one
    /// before it).
    fn counting_file(len: usize) -> (tempfile::TempDir, String, Vec<u8>) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("raw.bin");
        let bytes: Vec<u8> = (0..len).map(|i| (i % 251) as u8).collect();
        std::fs::File::create(&path)
            .unwrap()
            .write_all(&bytes)
            .unwrap();
        (dir, path.to_str().unwrap().to_string(), bytes)
    }

    /// Every byte of a file read ahead comes out once, in order, whatever its length against the
    /// block size; reading it again (a rewound input) gives the same bytes.
    #[test]
    fn a_file_read_ahead_gives_every_byte_in_order() {
        for len in [1, BATCH - 1, BATCH, 5 * BATCH + 17] {
            let (_dir, path, bytes) = counting_file(len);
            let mut input = Input::open(&path).unwrap();
            input.read_ahead(true);
            for _ in 0..2 {
                let mut got = Vec::new();
                while let Some(batch) = input.next_batch().unwrap() {
                    assert!(batch.bytes.len() <= BATCH);
                    got.extend_from_slice(batch.bytes);
                }
                assert_eq!(got.len(), len);
                assert!(got == bytes, "{len} bytes");
                assert!(input.rewind());
            }
        }
    }

    /// A reader dropped before the end of its file ends its thread: dropping it (which waits
    /// for the thread) returns.
    #[test]
    fn dropping_a_reader_midway_ends_its_thread() {
        let (_dir, path, bytes) = counting_file(40 * BATCH);
        let mut ahead = ReadAhead::start(std::fs::File::open(&path).unwrap())
            .ok()
            .unwrap();
        let mut block = Vec::new();
        assert_eq!(ahead.read(&mut block).unwrap(), BATCH);
        assert_eq!(block, bytes[..BATCH]);
        assert_eq!(ahead.read(&mut block).unwrap(), BATCH);
        assert_eq!(block, bytes[BATCH..2 * BATCH]);
        // 38 blocks are left: the thread waits to send the next one; dropping returns.
        drop(ahead);
    }
}
