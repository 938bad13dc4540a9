//! Which files may be written: a file is never written over unasked ([`create_file`]), and an
//! output can be told apart from the files a command reads ([`FileId`], [`same_file`]).

use std::fs::File;
use std::io;
use std::path::Path;

use super::WriteError;

/// Creates the file `path` for writing, empty. An existing file is [`WriteError::Exists`]
/// unless `overwrite` (then it is truncated): recordings and simulated files are never written
/// over unasked. The check and the creation are one step, so no file can appear between them.
/// (Exports do not come here: they are written under a temporary name and renamed into place.)
pub fn create_file(path: &str, overwrite: bool) -> Result<File, WriteError> {
    std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(true)
        .create_new(!overwrite)
        .open(path)
        .map_err(|source| match source.kind() {
            io::ErrorKind::AlreadyExists => WriteError::Exists {
                output: path.to_string(),
            },
            _ => WriteError::Create {
                output: path.to_string(),
                source,
            },
        })
}

/// A file by name, or a standard stream by its descriptor.
#[derive(Clone, Copy)]
enum Named<'a> {
    Path(&'a Path),
    Stdin,
    Stdout,
}

/// What tells an existing file from any other: its device and inode (on Unix); `None` for a
/// file that does not exist, and for standard output unless it is a regular file.
#[cfg(unix)]
fn identity(file: Named<'_>) -> Option<(u64, u64)> {
    use std::os::fd::AsFd;
    use std::os::unix::fs::MetadataExt;
    let fstat = |fd: std::os::fd::BorrowedFd<'_>| {
        let stat = nix::sys::stat::fstat(fd).ok()?;
        Some((stat.st_dev as u64, stat.st_ino as u64, stat.st_mode))
    };
    match file {
        Named::Path(path) => std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino())),
        Named::Stdin => fstat(io::stdin().as_fd()).map(|(dev, ino, _)| (dev, ino)),
        Named::Stdout => fstat(io::stdout().as_fd())
            .filter(|&(_, _, mode)| mode & libc::S_IFMT == libc::S_IFREG)
            .map(|(dev, ino, _)| (dev, ino)),
    }
}

/// Elsewhere, files by their canonical path; the standard streams are not compared.
#[cfg(not(unix))]
fn identity(file: Named<'_>) -> Option<std::path::PathBuf> {
    match file {
        Named::Path(path) => std::fs::canonicalize(path).ok(),
        Named::Stdin | Named::Stdout => None,
    }
}

/// What tells an existing file from any other (its device and inode, on Unix; its canonical
/// path elsewhere): two names of one file, by whatever path or link, have equal `FileId`s.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FileId(
    #[cfg(unix)] (u64, u64),
    #[cfg(not(unix))] std::path::PathBuf,
);

impl FileId {
    /// The file `path` names; `None` when it does not exist.
    pub fn of_path(path: &Path) -> Option<FileId> {
        identity(Named::Path(path)).map(FileId)
    }

    /// The file behind standard input; `None` when it cannot be told (and off Unix).
    pub fn of_stdin() -> Option<FileId> {
        identity(Named::Stdin).map(FileId)
    }

    /// The file behind standard output when it is a regular file (`>> r1.bin`); `None` for a
    /// terminal, a pipe, a device (and off Unix).
    pub fn of_stdout() -> Option<FileId> {
        identity(Named::Stdout).map(FileId)
    }
}

/// Whether two paths name one existing file (by device and inode, on Unix).
pub fn same_file(a: impl AsRef<Path>, b: impl AsRef<Path>) -> bool {
    let a = identity(Named::Path(a.as_ref()));
    a.is_some() && a == identity(Named::Path(b.as_ref()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_is_the_same_by_any_path_and_no_other() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.bin");
        let b = dir.path().join("b.bin");
        std::fs::write(&a, b"a").unwrap();
        std::fs::write(&b, b"b").unwrap();
        let a_again = dir.path().join(".").join("a.bin");
        assert!(FileId::of_path(&a).is_some());
        assert_eq!(FileId::of_path(&a), FileId::of_path(&a_again));
        assert_ne!(FileId::of_path(&a), FileId::of_path(&b));
        assert_eq!(FileId::of_path(&dir.path().join("missing")), None);
        assert!(same_file(&a, &a_again));
        assert!(!same_file(&a, &b));
        assert!(!same_file(
            dir.path().join("missing"),
            dir.path().join("missing")
        ));
    }

    #[test]
    fn create_file_never_writes_over_unasked() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("kept.bin");
        std::fs::write(&path, b"kept").unwrap();
        let name = path.to_str().unwrap();
        assert!(matches!(
            create_file(name, false),
            Err(WriteError::Exists { output }) if output == name
        ));
        assert_eq!(std::fs::read(&path).unwrap(), b"kept");
        drop(create_file(name, true).unwrap());
        assert_eq!(std::fs::read(&path).unwrap(), b"");
    }
}
