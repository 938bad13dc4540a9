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

use std::fs::File;
use std::io::{self, Write};

/// Bytes written the usual way before direct I/O starts (a multiple of [`BLOCK`]).
const BUFFERED: u64 = 16 << 20;

/// Size of a direct write: large writes reach the disk's throughput with few system calls.
const BLOCK: usize = 4 << 20;

/// Alignment of a direct write's memory, offset and length (a page: more than any disk's
/// logical block).
const ALIGN: usize = 4096;

/// How the file is being written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// The usual way for now; direct I/O once [`BUFFERED`] bytes are written.
    Soon,
    /// Direct I/O.
    Direct,
    /// The usual way, to the end.
    Buffered,
}

/// An output file, written through a block buffer (see the module documentation).
pub(crate) struct OutputFile {
    file: File,
    /// A block-aligned block, `storage[start..start + BLOCK]`, in a larger allocation.
    storage: Vec<u8>,
    start: usize,
    /// Bytes waiting in the block.
    len: usize,
    /// Bytes written to the file so far.
    written: u64,
    mode: Mode,
}

impl OutputFile {
    /// Writes to `file`, newly created (empty).
    pub fn new(file: File) -> OutputFile {
        let regular = file.metadata().is_ok_and(|m| m.is_file());
        let storage = vec![0; BLOCK + ALIGN];
        let start = storage.as_ptr().align_offset(ALIGN);
        OutputFile {
            file,
            storage,
            start,
            len: 0,
            written: 0,
            mode: if regular && cfg!(target_os = "linux") {
                Mode::Soon
            } else {
                Mode::Buffered
            },
        }
    }

    /// Writes the bytes waiting in the block.
    fn write_block(&mut self) -> io::Result<()> {
        if self.mode == Mode::Soon && self.written >= BUFFERED {
            self.mode = if set_direct(&self.file, true).is_ok() {
                Mode::Direct
            } else {
                Mode::Buffered
            };
        }
        let mut done = 0;
        while done < self.len {
            let rest = &self.storage[self.start + done..self.start + self.len];
            match (&self.file).write(rest) {
                Ok(0) => return Err(io::ErrorKind::WriteZero.into()),
                Ok(n) => done += n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                // The file system refuses this direct write (alignment, or no direct I/O at
                // all): write the usual way from here on.
                Err(e) if self.mode == Mode::Direct && e.raw_os_error() == Some(libc::EINVAL) => {
                    self.end_direct()?;
                }
                Err(e) => return Err(e),
            }
        }
        self.written += done as u64;
        self.len = 0;
        Ok(())
    }

    fn end_direct(&mut self) -> io::Result<()> {
        if self.mode == Mode::Direct {
            set_direct(&self.file, false)?;
        }
        self.mode = Mode::Buffered;
        Ok(())
    }
}

impl Write for OutputFile {
    fn write(&mut self, data: &[u8]) -> io::Result<usize> {
        let n = data.len().min(BLOCK - self.len);
        let at = self.start + self.len;
        self.storage[at..at + n].copy_from_slice(&data[..n]);
        self.len += n;
        if self.len == BLOCK {
            self.write_block()?;
        }
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        if !self.len.is_multiple_of(ALIGN) {
            // Direct writes must be whole blocks of the disk: the rest goes the usual way.
            self.end_direct()?;
        }
        self.write_block()?;
        self.file.flush()
    }
}

impl Drop for OutputFile {
    fn drop(&mut self) {
        // The writers flush at the end and report errors; this is for an export cut short.
        let _ = self.flush();
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
}
