//! Files, standard input and serial ports as inputs ([`OpenInput`]): what `hwfoc-records`'
//! [`Input`] cannot do itself, having no operating system. A regular file is opened again each
//! time it is read ([`Reopen`]), read ahead on a thread of its own (`ahead.rs`) and read at
//! positions for a later half; serial ports are read by `ports.rs`.

mod ahead;

use std::fs::File;
use std::io::{self, BufReader, Read};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use hwfoc_records::{Beside, BlockRead, ReadAt, RegularFile, Reopen};
pub(crate) use hwfoc_records::{Input, InputError};

use hwfoc_ports::serial::PortSet;

use self::ahead::ReadAhead;
use hwfoc_ports::Ports;

/// Opening an [`Input`] of a file, standard input or serial ports.
pub trait OpenInput: Sized {
    /// Opens a file, or standard input for `-`, and detects its format. A regular file is
    /// closed again once its format is known: it is open only while it is read, from its first
    /// [`Input::next_batch`] to its end, so that any number of inputs can be given together.
    fn open(spec: &str) -> Result<Self, InputError>;

    /// Opens serial ports at `baud` (8N1; at [`hwfoc_ports::serial::Baud::Auto`] each port finds its
    /// rate, told as a notice) as one input with one stream per port, in the order given.
    /// Reading ends once `stop` is set (the `hwfoc` command sets it on Ctrl-C or SIGTERM; the
    /// library installs no signal handler); a port that is unplugged is waited for, with a
    /// warning.
    fn open_ports(
        names: &[String],
        baud: impl Into<hwfoc_ports::serial::Baud>,
        stop: Arc<AtomicBool>,
    ) -> Result<Self, InputError>;
}

impl OpenInput for Input {
    fn open(spec: &str) -> Result<Input, InputError> {
        if spec == "-" {
            return Input::from_reader("standard input", Box::new(io::stdin().lock()));
        }
        let open_err = |source| InputError::Open {
            input: spec.to_string(),
            source,
        };
        let file = File::open(spec).map_err(open_err)?;
        let meta = file.metadata().map_err(open_err)?;
        if meta.is_dir() {
            return Err(InputError::IsDirectory {
                input: spec.to_string(),
            });
        }
        if meta.is_file() {
            let path = Path(spec.to_string());
            return Input::from_file(spec, Box::new(path), Box::new(Opened(file)));
        }
        // A pipe or a device, which cannot be opened again.
        Input::from_reader(spec, Box::new(file))
    }

    fn open_ports(
        names: &[String],
        baud: impl Into<hwfoc_ports::serial::Baud>,
        stop: Arc<AtomicBool>,
    ) -> Result<Input, InputError> {
        let set = PortSet::open(names, baud)?;
        Ok(Input::from_source(
            &names.join(", "),
            Box::new(Ports::new(set, stop)),
        ))
    }
}

/// A regular file by its path.
struct Path(String);

impl Reopen for Path {
    fn open(&self) -> io::Result<Box<dyn RegularFile>> {
        Ok(Box::new(Opened(File::open(&self.0)?)))
    }

    fn file_len(&self) -> Option<u64> {
        std::fs::metadata(&self.0).ok().map(|m| m.len())
    }

    fn same_bytes_as(&self, other: &dyn Reopen) -> bool {
        same_file_bytes(&self.0, other.path()).unwrap_or(false)
    }

    fn path(&self) -> &str {
        &self.0
    }
}

/// A regular file, open.
struct Opened(File);

impl Read for Opened {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        self.0.read(buf)
    }
}

impl RegularFile for Opened {
    fn read_ahead(self: Box<Self>) -> Result<Box<dyn BlockRead>, Box<dyn RegularFile>> {
        match ReadAhead::start(self.0) {
            Ok(ahead) => Ok(Box::new(ahead)),
            Err(file) => Err(Box::new(Opened(file))),
        }
    }

    fn second(&self) -> Option<Box<dyn ReadAt>> {
        // Positional reads that leave the first handle's offset alone: Unix's `pread`
        // (Windows' `seek_read` moves the offset a duplicated handle shares).
        cfg!(unix)
            .then(|| self.0.try_clone().ok())
            .flatten()
            .map(|f| Box::new(Second(f)) as _)
    }
}

/// A second handle on a regular file, read at positions.
struct Second(File);

impl ReadAt for Second {
    #[cfg(unix)]
    fn read_at(&self, block: &mut [u8], pos: u64) -> io::Result<usize> {
        std::os::unix::fs::FileExt::read_at(&self.0, block, pos)
    }

    #[cfg(not(unix))]
    fn read_at(&self, _: &mut [u8], _: u64) -> io::Result<usize> {
        Err(io::Error::from(io::ErrorKind::Unsupported))
    }

    fn file_len(&self) -> Option<u64> {
        self.0.metadata().ok().map(|m| m.len())
    }

    fn try_clone(&self) -> Option<Box<dyn ReadAt>> {
        Some(Box::new(Second(self.0.try_clone().ok()?)))
    }

    fn read_beside(
        self: Box<Self>,
        work: Box<dyn FnOnce(Box<dyn ReadAt>) + Send>,
    ) -> Option<Box<dyn Beside>> {
        let thread = std::thread::Builder::new()
            .name("hwfoc-later-half".into())
            .spawn(move || work(self))
            .ok()?;
        Some(Box::new(Thread(thread)))
    }
}

/// A thread reading a later half.
struct Thread(std::thread::JoinHandle<()>);

impl Beside for Thread {
    fn join(self: Box<Self>) {
        let _ = self.0.join();
    }
}

/// Whether files `a` and `b` hold the same bytes: their lengths first, then their contents in
/// blocks up to the first that differs.
fn same_file_bytes(a: &str, b: &str) -> io::Result<bool> {
    let (fa, fb) = (File::open(a)?, File::open(b)?);
    if fa.metadata()?.len() != fb.metadata()?.len() {
        return Ok(false);
    }
    let (mut fa, mut fb) = (BufReader::new(fa), BufReader::new(fb));
    let (mut ba, mut bb) = (vec![0u8; 1 << 16], vec![0u8; 1 << 16]);
    loop {
        // `take(..).read_to_end` reads a block whole (a plain `read` may stop short).
        ba.clear();
        bb.clear();
        let n = (&mut fa).take(1 << 16).read_to_end(&mut ba)?;
        let m = (&mut fb).take(1 << 16).read_to_end(&mut bb)?;
        if ba != bb {
            return Ok(false);
        }
        if n == 0 && m == 0 {
            return Ok(true);
        }
    }
}

/// Reads a small file whole (a configuration file, a throttle profile): at most `limit` bytes;
/// a larger file (or an endless one such as `/dev/zero`) is an error of kind `InvalidData`
/// saying so, rather than memory for whatever it holds. Anything but a regular file (a FIFO, a
/// device, a directory) is an error of kind `InvalidInput` naming what it is: opening a FIFO
/// waits for a writer, so it is opened without waiting and refused.
pub fn read_small_file(path: impl AsRef<std::path::Path>, limit: u64) -> io::Result<Vec<u8>> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    // O_NONBLOCK: the open of a FIFO returns at once; reads of a regular file never wait anyway.
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NONBLOCK);
    let file = options.open(path)?;
    let kind = file.metadata()?.file_type();
    if !kind.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            match file_kind(&kind) {
                Some(what) => format!("it is {what}, not a regular file"),
                None => "it is not a regular file".to_string(),
            },
        ));
    }
    let mut bytes = Vec::new();
    file.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "it is larger than {} KiB, more than such a file holds",
                limit >> 10
            ),
        ));
    }
    Ok(bytes)
}

/// What a file that is not a regular file is, for an error: "a FIFO", "a directory".
fn file_kind(kind: &std::fs::FileType) -> Option<&'static str> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return Some("a FIFO");
        }
        if kind.is_char_device() || kind.is_block_device() {
            return Some("a device");
        }
        if kind.is_socket() {
            return Some("a socket");
        }
    }
    kind.is_dir().then_some("a directory")
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;

    use hwfoc_records::InputFormat;

    use super::*;

    #[cfg(unix)]
    #[test]
    fn serial_ports_give_a_stream_per_port_with_receive_times() {
        use std::io::Write;
        use std::os::fd::AsFd;
        let ptys: Vec<_> = (0..2)
            .map(|_| nix::pty::openpty(None, None).unwrap())
            .collect();
        let names: Vec<String> = ptys
            .iter()
            .map(|p| {
                let name = nix::unistd::ttyname(p.slave.as_fd()).unwrap();
                name.to_string_lossy().into_owned()
            })
            .collect();
        let stop = Arc::new(AtomicBool::new(false));
        let mut input = Input::open_ports(&names, 19200, stop).unwrap();
        assert_eq!(input.format(), InputFormat::SERIAL);
        assert_eq!(input.streams(), 2);
        assert_eq!(input.stream_name(1), names[1]);
        let mut master = std::fs::File::from(ptys[1].master.try_clone().unwrap());
        let sent = hwfoc_ports::clock::ReceiveClock::new().now_ns() as f64 * 1e-9;
        master.write_all(&[0x9B, 0x16, 0x01]).unwrap();
        let mut got = Vec::new();
        let mut times = Vec::new();
        while got.len() < 3 {
            let b = input.next_batch().unwrap().unwrap();
            assert_eq!(b.stream, 1);
            got.extend_from_slice(b.bytes);
            times.extend_from_slice(b.times.unwrap());
        }
        assert_eq!(got, [0x9B, 0x16, 0x01]);
        assert!((times[0] - sent).abs() < 0.5, "{times:?} vs {sent}");
        assert!(times.windows(2).all(|w| w[1] > w[0]));
    }
}
