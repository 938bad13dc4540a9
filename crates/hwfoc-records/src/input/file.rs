//! What an input asks of a regular file, which the crate above opens (`hwfoc-io`: this crate
//! opens no file): to be opened again from its start ([`Reopen`]), read in turn, read ahead
//! ([`BlockRead`]) or read at a position ([`ReadAt`]) ([`RegularFile`]), the later half of it
//! beside the caller ([`Beside`]).

use std::io::{self, Read};

/// A regular file an input was opened from by its path, open only while it is read: opened
/// again from its start at each reading ([`Input::from_file`](super::Input::from_file)).
pub trait Reopen {
    /// Opens the file again, from its start.
    fn open(&self) -> io::Result<Box<dyn RegularFile>>;

    /// Its length, as it is now.
    fn file_len(&self) -> Option<u64>;

    /// Whether this file and `other` hold the same bytes (the same file given twice, or a copy
    /// of it): compared only when their lengths are equal, and then to the first byte that
    /// differs.
    fn same_bytes_as(&self, other: &dyn Reopen) -> bool;

    /// Its path, as given.
    fn path(&self) -> &str;
}

/// A regular file being read, from where it is.
pub trait RegularFile: Read {
    /// The rest of the file read ahead, by a thread of its own while the decoder works (worth
    /// it where the decoder's loop is the bottleneck and a core is free); the file back where
    /// no reading ahead can be started.
    fn read_ahead(self: Box<Self>) -> Result<Box<dyn BlockRead>, Box<dyn RegularFile>>;

    /// A second handle on the file, for positional reads of a later part; `None` where the
    /// platform has no positional reads that leave this handle's offset alone.
    fn second(&self) -> Option<Box<dyn ReadAt>>;
}

/// A file read a block at a time, each block handed over whole.
pub trait BlockRead {
    /// Puts the next block in `bytes` (its old buffer may be reused): its length, 0 at the end.
    fn read(&mut self, bytes: &mut Vec<u8>) -> io::Result<usize>;
}

/// A file read at positions, whatever its offset.
pub trait ReadAt: Send {
    /// Reads bytes at `pos` into `block`: how many, 0 past the end.
    fn read_at(&self, block: &mut [u8], pos: u64) -> io::Result<usize>;

    /// Its length, as it is now.
    fn file_len(&self) -> Option<u64>;

    /// Another handle on the same file.
    fn try_clone(&self) -> Option<Box<dyn ReadAt>>;

    /// Reads the file beside the caller: `work` runs with it on a thread of its own (the crate
    /// above starts it); `None`, and `work` is dropped, where none can be started.
    fn read_beside(
        self: Box<Self>,
        work: Box<dyn FnOnce(Box<dyn ReadAt>) + Send>,
    ) -> Option<Box<dyn Beside>>;
}

/// Work running beside the caller ([`ReadAt::read_beside`]).
pub trait Beside {
    /// Waits for the work to end.
    fn join(self: Box<Self>);
}

/// Files held in memory, for the tests of what reads files: each reading sees the bytes the
/// file holds then.
#[cfg(test)]
pub(crate) mod memory {
    use std::io::{self, Read};
    use std::sync::{Arc, Mutex};

    use super::{Beside, BlockRead, ReadAt, RegularFile, Reopen};
    use crate::input::{Input, InputError};

    /// A file's path and its bytes, which a test may replace.
    #[derive(Clone)]
    pub(crate) struct MemoryFile {
        path: String,
        pub(crate) bytes: Arc<Mutex<Arc<Vec<u8>>>>,
    }

    /// The file being read: its bytes and the position reached.
    struct Open(Arc<Vec<u8>>, u64);

    impl MemoryFile {
        pub(crate) fn new(path: &str, bytes: Vec<u8>) -> MemoryFile {
            MemoryFile {
                path: path.to_string(),
                bytes: Arc::new(Mutex::new(Arc::new(bytes))),
            }
        }

        /// The input of this file, as `hwfoc-io` opens a regular file.
        pub(crate) fn input(&self) -> Result<Input, InputError> {
            let file = self.open().unwrap();
            Input::from_file(&self.path, Box::new(self.clone()), file)
        }

        fn now(&self) -> Arc<Vec<u8>> {
            Arc::clone(&self.bytes.lock().unwrap())
        }
    }

    impl Reopen for MemoryFile {
        fn open(&self) -> io::Result<Box<dyn RegularFile>> {
            Ok(Box::new(Open(self.now(), 0)))
        }

        fn file_len(&self) -> Option<u64> {
            Some(self.now().as_slice().len() as u64)
        }

        fn same_bytes_as(&self, other: &dyn Reopen) -> bool {
            let Ok(mut file) = other.open() else {
                return false;
            };
            let mut bytes = Vec::new();
            file.read_to_end(&mut bytes).is_ok() && bytes == *self.now()
        }

        fn path(&self) -> &str {
            &self.path
        }
    }

    impl Read for Open {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            let n = self.0.read_at(buf, self.1)?;
            self.1 += n as u64;
            Ok(n)
        }
    }

    impl RegularFile for Open {
        fn read_ahead(self: Box<Self>) -> Result<Box<dyn BlockRead>, Box<dyn RegularFile>> {
            Err(self)
        }

        fn second(&self) -> Option<Box<dyn ReadAt>> {
            Some(Box::new(Arc::clone(&self.0)))
        }
    }

    impl ReadAt for Arc<Vec<u8>> {
        fn read_at(&self, block: &mut [u8], pos: u64) -> io::Result<usize> {
            let bytes = self.as_slice();
            let from = usize::try_from(pos).map_or(bytes.len(), |p| p.min(bytes.len()));
            let n = block.len().min(bytes.len() - from);
            block[..n].copy_from_slice(&bytes[from..from + n]);
            Ok(n)
        }

        fn file_len(&self) -> Option<u64> {
            Some(self.as_slice().len() as u64)
        }

        fn try_clone(&self) -> Option<Box<dyn ReadAt>> {
            Some(Box::new(Arc::clone(self)))
        }

        fn read_beside(
            self: Box<Self>,
            work: Box<dyn FnOnce(Box<dyn ReadAt>) + Send>,
        ) -> Option<Box<dyn Beside>> {
            Some(Box::new(std::thread::spawn(move || work(self))))
        }
    }

    impl Beside for std::thread::JoinHandle<()> {
        fn join(self: Box<Self>) {
            let _ = std::thread::JoinHandle::join(*self);
        }
    }
}
