//! The output file of an export: a large output bypasses the page cache.
//!
//! Written the usual way, every page of the output is a page of memory newly taken for the page
//! cache, and on virtual machines that hand freed memory back to the host (virtio-balloon free
//! page reporting, as on the benchmark machine) the first touch of each such page traps to the
//! hypervisor: `dd` of 6 GB to a file took 22 s of system time there, against 0.6 s with direct
//! I/O, and a CSV export of a 2 GB input (6.4 GB of text) spent 20 s in the kernel.
//!
//! So, once a regular file has received its first [`BUFFERED`] bytes, the rest goes out with
//! direct I/O (`O_DIRECT`, Linux): whole aligned blocks of [`BLOCK`] bytes from one reused
//! buffer, straight to the disk. The last partial block, and what a flush pushes out (live
//! input), are written the usual way: a flush that is not a whole number of blocks ends direct
//! I/O for the rest of the file. A file system that refuses direct I/O (at the switch or at a
//! write) is simply written the usual way. Small outputs, standard output, pipes and devices
//! are always written the usual way.
//!
//! The writes happen on a thread of the file's own, a block at a time, while the next block
//! is filled: the export's threads do not wait for the disk (a synchronous 4 MiB write left a
//! core idle for some milliseconds every few Parquet row groups).

use std::fs::File;
use std::io::{self, Write};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

/// Bytes written the usual way before direct I/O starts (a multiple of [`BLOCK`]).
const BUFFERED: u64 = 16 << 20;

/// Size of a direct write: large writes reach the disk's throughput with few system calls.
const BLOCK: usize = 4 << 20;

/// Alignment of a direct write's memory, offset and length (a page: more than any disk's
/// logical block).
const ALIGN: usize = 4096;

/// How the file is being written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum IoMode {
    /// The usual way for now; direct I/O once [`BUFFERED`] bytes are written.
    Soon,
    /// Direct I/O.
    Direct,
    /// The usual way, to the end.
    Buffered,
}

/// A block-aligned buffer of [`BLOCK`] bytes, `storage[start..start + BLOCK]`, in a larger
/// allocation.
struct Block {
    storage: Vec<u8>,
    start: usize,
}

impl Block {
    fn new() -> Block {
        let storage = vec![0; BLOCK + ALIGN];
        let start = storage.as_ptr().align_offset(ALIGN);
        Block { storage, start }
    }

    fn bytes(&self) -> &[u8] {
        &self.storage[self.start..self.start + BLOCK]
    }

    fn bytes_mut(&mut self) -> &mut [u8] {
        &mut self.storage[self.start..self.start + BLOCK]
    }
}

/// A block for the writing thread: its first `len` bytes go to the file, then the file is
/// flushed if `flush`.
struct Job {
    block: Block,
    len: usize,
    flush: bool,
}

/// An output file, written through block buffers by a thread of its own (see the module
/// documentation): the caller fills one block while the previous one is being written, so
/// it does not wait for the disk unless the disk falls behind.
pub(crate) struct OutputFile {
    /// The block being filled, and how many bytes it holds.
    block: Block,
    len: usize,
    /// A free block, when the writing thread is not busy with it.
    spare: Option<Block>,
    jobs: Option<SyncSender<Job>>,
    /// Blocks coming back from the writing thread, with the outcome of their write.
    done: Receiver<(Block, io::Result<()>)>,
    /// Blocks handed to the writing thread and not yet back.
    in_flight: usize,
    /// The first write error, reported by every later call.
    failed: Option<io::ErrorKind>,
    thread: Option<JoinHandle<()>>,
}

impl OutputFile {
    /// Writes to `file`, newly created (empty).
    pub fn new(file: File) -> OutputFile {
        let regular = file.metadata().is_ok_and(|m| m.is_file());
        let mut disk = Disk {
            file,
            written: 0,
            mode: if regular && cfg!(target_os = "linux") {
                IoMode::Soon
            } else {
                IoMode::Buffered
            },
        };
        let (jobs, rx) = sync_channel::<Job>(1);
        let (tx, done) = sync_channel(2);
        let thread = std::thread::Builder::new()
            .name("hwfoc-disk".to_string())
            .spawn(move || {
                for job in rx {
                    let result = disk.write(&job.block.bytes()[..job.len], job.flush);
                    if tx.send((job.block, result)).is_err() {
                        return;
                    }
                }
            })
            .ok();
        OutputFile {
            block: Block::new(),
            len: 0,
            spare: Some(Block::new()),
            jobs: Some(jobs),
            done,
            in_flight: 0,
            failed: None,
            thread,
        }
    }

    /// The error that stopped the output, again.
    fn check(&self) -> io::Result<()> {
        match self.failed {
            Some(kind) => Err(io::Error::new(kind, "an earlier write to this file failed")),
            None => Ok(()),
        }
    }

    /// Takes back a block from the writing thread, waiting for it; its write error, if any,
    /// becomes the output's.
    fn take_back(&mut self) -> io::Result<Block> {
        let Ok((block, result)) = self.done.recv() else {
            self.failed = Some(io::ErrorKind::Other);
            return Err(io::Error::other("the disk-writing thread stopped"));
        };
        self.in_flight -= 1;
        if let Err(e) = result {
            self.failed.get_or_insert(e.kind());
            return Err(e);
        }
        Ok(block)
    }

    /// Hands the block being filled to the writing thread and continues with a free one.
    fn send_block(&mut self, flush: bool) -> io::Result<()> {
        let next = match self.spare.take() {
            Some(block) => block,
            None => self.take_back()?,
        };
        let job = Job {
            block: std::mem::replace(&mut self.block, next),
            len: std::mem::take(&mut self.len),
            flush,
        };
        let sent = self
            .jobs
            .as_ref()
            .is_some_and(|jobs| jobs.send(job).is_ok());
        if !sent {
            self.failed = Some(io::ErrorKind::Other);
            return Err(io::Error::other("the disk-writing thread stopped"));
        }
        self.in_flight += 1;
        Ok(())
    }

    /// Waits until every block handed over is written.
    fn settle(&mut self) -> io::Result<()> {
        while self.in_flight > 0 {
            let block = self.take_back()?;
            self.spare = Some(block);
        }
        Ok(())
    }
}

impl Write for OutputFile {
    fn write(&mut self, data: &[u8]) -> io::Result<usize> {
        self.check()?;
        let n = data.len().min(BLOCK - self.len);
        let at = self.len;
        self.block.bytes_mut()[at..at + n].copy_from_slice(&data[..n]);
        self.len += n;
        if self.len == BLOCK {
            self.send_block(false)?;
        }
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.check()?;
        self.send_block(true)?;
        self.settle()
    }
}

impl Drop for OutputFile {
    fn drop(&mut self) {
        // The writers flush at the end and report errors; this is for an export cut short.
        if self.failed.is_none() {
            let _ = self.flush();
        }
        self.jobs = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The file itself, on the writing thread.
struct Disk {
    file: File,
    /// Bytes written to the file so far.
    written: u64,
    mode: IoMode,
}

impl Disk {
    /// Writes `bytes` (a whole block, or the end of the output), then flushes the file if
    /// `flush`.
    fn write(&mut self, bytes: &[u8], flush: bool) -> io::Result<()> {
        if flush && !bytes.len().is_multiple_of(ALIGN) {
            // Direct writes must be whole blocks of the disk: the rest goes the usual way.
            self.end_direct()?;
        }
        if self.mode == IoMode::Soon && self.written >= BUFFERED {
            self.mode = if set_direct(&self.file, true).is_ok() {
                IoMode::Direct
            } else {
                IoMode::Buffered
            };
        }
        let mut done = 0;
        while done < bytes.len() {
            match (&self.file).write(&bytes[done..]) {
                Ok(0) => return Err(io::ErrorKind::WriteZero.into()),
                Ok(n) => done += n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                // The file system refuses this direct write (alignment, or no direct I/O at
                // all): write the usual way from here on.
                Err(e) if self.mode == IoMode::Direct && e.raw_os_error() == Some(libc::EINVAL) => {
                    self.end_direct()?;
                }
                Err(e) => return Err(e),
            }
        }
        self.written += done as u64;
        if flush {
            self.file.flush()?;
        }
        Ok(())
    }

    fn end_direct(&mut self) -> io::Result<()> {
        if self.mode == IoMode::Direct {
            set_direct(&self.file, false)?;
        }
        self.mode = IoMode::Buffered;
        Ok(())
    }
}

/// Turns direct I/O on or off for `file`.
#[cfg(target_os = "linux")]
fn set_direct(file: &File, on: bool) -> io::Result<()> {
    use nix::fcntl::{FcntlArg, OFlag, fcntl};
    let flags = OFlag::from_bits_truncate(fcntl(file, FcntlArg::F_GETFL)?);
    let flags = if on {
        flags | OFlag::O_DIRECT
    } else {
        flags - OFlag::O_DIRECT
    };
    fcntl(file, FcntlArg::F_SETFL(flags))?;
    Ok(())
}

/// Direct I/O is used on Linux only.
#[cfg(not(target_os = "linux"))]
fn set_direct(_file: &File, _on: bool) -> io::Result<()> {
    Err(io::ErrorKind::Unsupported.into())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    /// Whatever the mix of write sizes and flushes, the file holds exactly the bytes written,
    /// past the switch to direct I/O and across block boundaries.
    #[test]
    fn writes_every_byte_in_order() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out");
        let mut expected = Vec::new();
        {
            let mut out = OutputFile::new(File::create(&path).unwrap());
            let mut x = 7u32;
            let mut i = 0usize;
            while expected.len() < BUFFERED as usize + 3 * BLOCK + 12_345 {
                x = x.wrapping_mul(1_103_515_245).wrapping_add(12_345);
                let n = [1, 100, 4096, 70_000, BLOCK + 3][(x >> 16) as usize % 5];
                let piece: Vec<u8> = (0..n).map(|j| (i + j) as u8 ^ (x as u8)).collect();
                out.write_all(&piece).unwrap();
                expected.extend_from_slice(&piece);
                i += 1;
            }
            out.flush().unwrap();
            // More after a flush at an unaligned length: written the usual way.
            out.write_all(b"tail").unwrap();
            expected.extend_from_slice(b"tail");
            out.flush().unwrap();
        }
        let mut written = Vec::new();
        File::open(&path)
            .unwrap()
            .read_to_end(&mut written)
            .unwrap();
        assert_eq!(written.len(), expected.len());
        assert!(
            written == expected,
            "the file differs from what was written"
        );
    }

    /// A failed write on the writing thread reaches the caller (at a later write or the flush)
    /// with its own error, and every call after it fails too.
    #[test]
    #[cfg(target_os = "linux")]
    fn a_disk_error_reaches_the_caller() {
        let file = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let mut out = OutputFile::new(file);
        let block = vec![7u8; BLOCK];
        let first = (0..4)
            .map(|_| out.write_all(&block))
            .find_map(Result::err)
            .or_else(|| out.flush().err())
            .expect("a write to /dev/full fails");
        assert_eq!(first.kind(), io::ErrorKind::StorageFull, "{first}");
        assert!(out.write_all(b"more").is_err());
        assert!(out.flush().is_err());
    }
}
