//! Pseudo-terminals that behave like the far end of a serial cable, and stable symlinks to them.
//!
//! Each virtual ESC gets a pty pair; programs open the slave side (`/dev/pts/N`) exactly like a
//! serial port. The slave is put in raw mode once, at creation (so even `cat` reads the bytes
//! unchanged; programs that set their own modes are welcome to), and then closed: we keep only
//! the master.
//!
//! A real ESC's bytes are lost when no one listens on the wire, and a port that is opened gets
//! what arrives from then on. The pty does the same: the kernel reports a hang-up on the master
//! while no process has the slave open, and bytes are then counted as undelivered instead of
//! piling up in the terminal's buffer (where the next reader would find seconds of stale
//! frames). The master is non-blocking: a reader that has the port open but stops reading
//! fills the kernel's buffer (a few KiB), after which bytes are dropped and counted, never
//! blocking the simulation. A reader may close and reopen the port at any time. Anything a
//! reader writes to the port is read and discarded.
//!
//! Both sides are opened close-on-exec ([`RawPair::open`]): a program started by this process
//! (a ground station, a test's Python) must not inherit the master, or the slave would never
//! see the hang-up when we close it.

use std::fs::File;
use std::io::{self, Read, Write};
use std::os::fd::{AsFd, OwnedFd};
use std::path::{Path, PathBuf};

use nix::fcntl::{FcntlArg, OFlag, fcntl};
use nix::poll::{PollFd, PollFlags, PollTimeout, poll};
use nix::sys::termios::{SetArg, cfmakeraw, tcgetattr, tcsetattr};

use crate::error::SimError;
use crate::template::expand;

/// A pseudo-terminal pair in raw mode, both sides close-on-exec from the moment they exist.
///
/// `nix::pty::openpty` (glibc's `openpty`) opens both sides inheritable, and setting
/// `FD_CLOEXEC` afterwards leaves a window in which a thread that starts a program hands it the
/// master; the program then holds the terminal open after we close it. On Linux the master is
/// opened with `O_CLOEXEC` and the slave by its name, so there is no window.
#[derive(Debug)]
pub struct RawPair {
    /// The master side (blocking).
    pub master: File,
    /// The slave side.
    pub slave: OwnedFd,
    /// The slave's path, to open like a serial port.
    pub path: PathBuf,
}

impl RawPair {
    /// Opens a pair and puts the slave in raw mode (nothing echoed or translated).
    pub fn open() -> io::Result<RawPair> {
        let (master, slave) = open_cloexec()?;
        let mut mode = tcgetattr(&slave)?;
        cfmakeraw(&mut mode);
        tcsetattr(&slave, SetArg::TCSANOW, &mode)?;
        let path = nix::unistd::ttyname(&slave)?;
        Ok(RawPair {
            master: File::from(master),
            slave,
            path,
        })
    }

    /// Makes reads and writes of the master return at once (`WouldBlock`) instead of waiting.
    pub fn master_nonblocking(&self) -> io::Result<()> {
        let flags = OFlag::from_bits_truncate(fcntl(&self.master, FcntlArg::F_GETFL)?);
        fcntl(&self.master, FcntlArg::F_SETFL(flags | OFlag::O_NONBLOCK))?;
        Ok(())
    }
}

#[cfg(any(target_os = "linux", target_os = "android"))]
fn open_cloexec() -> nix::Result<(OwnedFd, OwnedFd)> {
    use nix::pty::{grantpt, posix_openpt, ptsname_r, unlockpt};
    let flags = OFlag::O_RDWR | OFlag::O_NOCTTY | OFlag::O_CLOEXEC;
    let master = posix_openpt(flags)?;
    grantpt(&master)?;
    unlockpt(&master)?;
    let name = ptsname_r(&master)?;
    let slave = nix::fcntl::open(name.as_str(), flags, nix::sys::stat::Mode::empty())?;
    Ok((master.into(), slave))
}

/// Elsewhere `posix_openpt` may refuse `O_CLOEXEC` and `ptsname_r` is missing: `openpty`, then
/// close-on-exec at once (the window described on [`RawPair`] remains).
#[cfg(not(any(target_os = "linux", target_os = "android")))]
fn open_cloexec() -> nix::Result<(OwnedFd, OwnedFd)> {
    use nix::fcntl::FdFlag;
    let pair = nix::pty::openpty(None, None)?;
    for fd in [&pair.master, &pair.slave] {
        fcntl(fd, FcntlArg::F_SETFD(FdFlag::FD_CLOEXEC))?;
    }
    Ok((pair.master, pair.slave))
}

/// One pseudo-terminal: our master side and the path of the slave.
#[derive(Debug)]
pub struct Pty {
    master: File,
    path: PathBuf,
    undelivered: u64,
    /// Keep what the reader writes for [`Pty::read`] instead of discarding it.
    keep_input: bool,
}

impl Pty {
    /// Creates a pty in raw mode.
    pub fn open() -> Result<Pty, SimError> {
        let err = |source: io::Error| SimError::Pty { source };
        let pair = RawPair::open().map_err(err)?;
        pair.master_nonblocking().map_err(err)?;
        drop(pair.slave);
        Ok(Pty {
            master: pair.master,
            path: pair.path,
            undelivered: 0,
            keep_input: false,
        })
    }

    /// The slave's path, to open like a serial port.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Bytes that found no reader (or a full buffer) so far.
    pub fn undelivered(&self) -> u64 {
        self.undelivered
    }

    /// Whether some process has the slave side open.
    pub fn has_reader(&self) -> bool {
        let mut fds = [PollFd::new(self.master.as_fd(), PollFlags::POLLOUT)];
        match poll(&mut fds, PollTimeout::ZERO) {
            Ok(_) => !fds[0]
                .revents()
                .is_some_and(|r| r.contains(PollFlags::POLLHUP)),
            Err(_) => false,
        }
    }

    /// Writes `bytes` if a reader has the port open and room in its buffer; whether all went.
    pub fn write(&mut self, bytes: &[u8]) -> bool {
        self.discard_input();
        let sent = if self.has_reader() {
            // An error is EAGAIN (buffer full) or EIO (the reader went away just now).
            self.master.write(bytes).unwrap_or_default()
        } else {
            0
        };
        self.undelivered += (bytes.len() - sent) as u64;
        sent == bytes.len()
    }

    /// Keeps what the reader writes to the port, for [`Pty::read`] (a virtual CAN adapter
    /// reads its commands), instead of discarding it.
    pub fn keep_input(&mut self) {
        self.keep_input = true;
    }

    /// What the reader wrote to the port since the last call, up to `buf.len()` bytes, without
    /// waiting: the number of bytes.
    pub fn read(&mut self, buf: &mut [u8]) -> usize {
        self.master.read(buf).unwrap_or_default()
    }

    /// Reads and throws away what the reader wrote to the port, so that it never blocks.
    fn discard_input(&mut self) {
        if self.keep_input {
            return;
        }
        let mut buf = [0u8; 512];
        for _ in 0..16 {
            match self.master.read(&mut buf) {
                Ok(n) if n > 0 => continue,
                _ => break,
            }
        }
    }
}

/// Where the symlinks to a run's pseudo-terminals go.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PtyLinks {
    /// `DIR/esc0`, `DIR/esc1`, ... (the directory is created if need be).
    Dir(String),
    /// One path per ESC, or one with `{esc}` in it (just one path for a single ESC); none for
    /// no links.
    Paths(Vec<String>),
}

impl Default for PtyLinks {
    fn default() -> Self {
        PtyLinks::Paths(Vec::new())
    }
}

impl PtyLinks {
    /// The link of each of `n` ESCs (none at all, or one each), creating the directory of
    /// [`PtyLinks::Dir`].
    pub fn paths(&self, n: usize) -> Result<Vec<PathBuf>, SimError> {
        Ok(match self {
            PtyLinks::Dir(dir) => {
                // A directory made here is the user's alone (mode 0700).
                use std::os::unix::fs::DirBuilderExt;
                std::fs::DirBuilder::new()
                    .recursive(true)
                    .mode(0o700)
                    .create(dir)
                    .map_err(|source| SimError::Link {
                        path: dir.clone(),
                        source,
                    })?;
                (0..n)
                    .map(|i| PathBuf::from(dir).join(format!("esc{i}")))
                    .collect()
            }
            PtyLinks::Paths(paths) => match paths.as_slice() {
                [] => Vec::new(),
                [one] if n == 1 || one.contains("{esc}") => {
                    (0..n).map(|i| PathBuf::from(expand(one, i))).collect()
                }
                many if many.len() == n => many.iter().map(PathBuf::from).collect(),
                many => {
                    return Err(SimError::LinkCount {
                        links: many.len(),
                        n,
                    });
                }
            },
        })
    }
}

/// Creates a pty per ESC, `n` in all, and the links to them that `links` asks for (kept while
/// the returned [`Links`] lives).
pub fn open_all(n: usize, links: &PtyLinks) -> Result<(Vec<Pty>, Links), SimError> {
    let paths = links.paths(n)?;
    let mut ptys = Vec::with_capacity(n);
    for _ in 0..n {
        ptys.push(Pty::open()?);
    }
    let mut made = Links::default();
    for (link, pty) in paths.iter().zip(&ptys) {
        made.add(link, pty.path())?;
    }
    Ok((ptys, made))
}

/// Symlinks to the ptys at stable paths, made by this process and removed again when dropped
/// (also on an error or Ctrl-C) if they still point at our pty. Nothing else is touched.
#[derive(Debug, Default)]
pub struct Links {
    made: Vec<(PathBuf, PathBuf)>,
}

impl Links {
    /// Makes `link` point at `target`, atomically: the link is created only where there is
    /// nothing (the system refuses to create it over anything, so no other program's file can
    /// be replaced between a check and the creation). The one thing removed first is a link
    /// such as an earlier run that was killed leaves: dangling, to a pseudo-terminal (a path
    /// like `target`'s, another number in the same place); anything else there, a dangling
    /// link of the user's included, is an error.
    pub fn add(&mut self, link: &Path, target: &Path) -> Result<(), SimError> {
        let err = |source: io::Error| SimError::Link {
            path: link.display().to_string(),
            source,
        };
        if let Ok(meta) = std::fs::symlink_metadata(link) {
            let dangling = meta.file_type().is_symlink() && std::fs::metadata(link).is_err();
            let left_by_a_run =
                dangling && std::fs::read_link(link).is_ok_and(|old| is_another_pty(&old, target));
            if !left_by_a_run {
                return Err(SimError::LinkTaken {
                    path: link.display().to_string(),
                    dangling,
                });
            }
            std::fs::remove_file(link).map_err(err)?;
        }
        std::os::unix::fs::symlink(target, link).map_err(err)?;
        self.made.push((link.to_path_buf(), target.to_path_buf()));
        Ok(())
    }
}

/// Whether `old` names a pseudo-terminal the way `pty` does: in the same directory, the same
/// name but for the number at its end (`/dev/pts/7` for `/dev/pts/3`, `/dev/ttys012` for
/// `/dev/ttys004`).
fn is_another_pty(old: &Path, pty: &Path) -> bool {
    let split = |p: &Path| {
        let name = p.file_name()?.to_str()?;
        let stem = name.trim_end_matches(|c: char| c.is_ascii_digit());
        (stem.len() < name.len()).then(|| (p.parent().map(Path::to_path_buf), stem.to_string()))
    };
    matches!((split(old), split(pty)), (Some(a), Some(b)) if a == b)
}

impl Drop for Links {
    fn drop(&mut self) {
        for (link, target) in &self.made {
            if std::fs::read_link(link).is_ok_and(|t| t == *target) {
                let _ = std::fs::remove_file(link);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::OpenOptionsExt;

    fn open_reader(path: &Path) -> File {
        std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags(libc_flags())
            .open(path)
            .unwrap()
    }

    fn libc_flags() -> i32 {
        (OFlag::O_NOCTTY | OFlag::O_NONBLOCK).bits()
    }

    fn read_now(f: &mut File) -> Vec<u8> {
        let mut out = Vec::new();
        let mut buf = [0u8; 4096];
        while let Ok(n) = f.read(&mut buf) {
            if n == 0 {
                break;
            }
            out.extend_from_slice(&buf[..n]);
        }
        out
    }

    #[test]
    fn bytes_reach_a_reader_only_while_it_listens() {
        let mut pty = Pty::open().unwrap();
        assert!(pty.path().starts_with("/dev/"));
        assert!(!pty.has_reader());
        // Nobody listening: nothing blocks, nothing piles up.
        for _ in 0..2000 {
            assert!(!pty.write(&[0x9B; 24]));
        }
        assert_eq!(pty.undelivered(), 48_000);
        let mut reader = open_reader(pty.path());
        assert!(pty.has_reader());
        // Raw mode: every byte value passes unchanged, no echo, no line buffering.
        let all: Vec<u8> = (0..=255).collect();
        assert!(pty.write(&all));
        reader.write_all(b"ignored\n").unwrap();
        std::thread::sleep(std::time::Duration::from_millis(20));
        assert_eq!(read_now(&mut reader), all);
        assert!(pty.write(b"x"));
        // Reader closes and reopens: it gets what comes from then on.
        drop(reader);
        assert!(!pty.write(b"lost"));
        let mut reader = open_reader(pty.path());
        assert!(pty.write(b"again"));
        std::thread::sleep(std::time::Duration::from_millis(20));
        let got = read_now(&mut reader);
        assert!(got.ends_with(b"again") && !got.windows(4).any(|w| w == b"lost"));
        // A reader that stops reading: the buffer fills, then bytes are dropped, never blocking.
        let before = pty.undelivered();
        for _ in 0..10_000 {
            pty.write(&[0x55; 24]);
        }
        assert!(pty.undelivered() > before);
    }

    #[test]
    fn link_paths() {
        let paths = |links: PtyLinks, n| links.paths(n).map_err(|e| e.to_string());
        assert_eq!(paths(PtyLinks::default(), 3), Ok(Vec::new()));
        assert_eq!(
            paths(PtyLinks::Paths(vec!["/x/e{esc}".into()]), 2),
            Ok(vec![PathBuf::from("/x/e0"), PathBuf::from("/x/e1")])
        );
        assert_eq!(
            paths(PtyLinks::Paths(vec!["/x/a".into()]), 1),
            Ok(vec![PathBuf::from("/x/a")])
        );
        assert_eq!(
            paths(PtyLinks::Paths(vec!["a".into(), "b".into()]), 3),
            Err(
                "2 links to pseudo-terminals for 3 ESCs: give one per ESC, or one with {esc} in it"
                    .into()
            )
        );
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("escs");
        let made = paths(PtyLinks::Dir(sub.display().to_string()), 2).unwrap();
        assert_eq!(made, [sub.join("esc0"), sub.join("esc1")]);
        assert!(sub.is_dir());
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&sub).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o700, "{mode:o}");
    }

    #[test]
    fn links_replace_stale_ones_and_go_away() {
        let dir = tempfile::tempdir().unwrap();
        // What a killed run leaves: a link to a pseudo-terminal that is gone.
        let link = dir.path().join("esc0");
        std::os::unix::fs::symlink("/dev/pts/999999", &link).unwrap();
        // A user's dangling link.
        let theirs = dir.path().join("esc2");
        std::os::unix::fs::symlink("/nonexistent", &theirs).unwrap();
        let file = dir.path().join("file");
        std::fs::write(&file, b"keep").unwrap();
        let mine = dir.path().join("mine");
        std::os::unix::fs::symlink(&file, &mine).unwrap();
        let pty = Path::new("/dev/pts/3");
        {
            let mut links = Links::default();
            links.add(&link, pty).unwrap();
            assert_eq!(std::fs::read_link(&link).unwrap(), pty);
            let e = links.add(&file, pty).unwrap_err();
            assert!(e.to_string().contains("something is there already"), "{e}");
            // A user's own link (to something that exists, or not) is neither replaced nor
            // removed.
            let e = links.add(&mine, pty).unwrap_err();
            assert!(e.to_string().contains("something is there already"), "{e}");
            let e = links.add(&theirs, pty).unwrap_err();
            assert!(e.to_string().contains("a link of someone else's"), "{e}");
            // The data a front end words its option with; the library's message names none.
            assert!(
                matches!(&e, SimError::LinkTaken { dangling: true, path } if *path == theirs.display().to_string()),
                "{e:?}"
            );
            assert!(!e.to_string().contains("--"), "{e}");
        }
        assert!(std::fs::symlink_metadata(&link).is_err());
        assert_eq!(std::fs::read(&file).unwrap(), b"keep");
        assert_eq!(std::fs::read_link(&mine).unwrap(), file);
        assert_eq!(
            std::fs::read_link(&theirs).unwrap(),
            Path::new("/nonexistent")
        );
    }

    #[test]
    fn pty_paths_are_told_by_their_place_and_stem() {
        let yes = [("/dev/pts/7", "/dev/pts/3"), ("/dev/ttys012", "/dev/ttys4")];
        for (old, pty) in yes {
            assert!(is_another_pty(Path::new(old), Path::new(pty)), "{old}");
        }
        let no = [
            ("/nonexistent", "/dev/pts/3"),
            ("/dev/pts/x", "/dev/pts/3"),
            ("/tmp/pts/7", "/dev/pts/3"),
            ("/dev/ttyUSB0", "/dev/pts/3"),
            ("esc", "/dev/pts/3"),
        ];
        for (old, pty) in no {
            assert!(!is_another_pty(Path::new(old), Path::new(pty)), "{old}");
        }
    }
}
