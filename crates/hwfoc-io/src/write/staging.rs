//! A file written under a temporary name beside the file it replaces, and renamed over it once
//! complete: an output cut short leaves the earlier file as it was.
//!
//! The temporary file is created exclusively (`O_CREAT | O_EXCL`: never through a link, never
//! over a file that is there) under an unpredictable name in the target's directory
//! (`out.csv.Xy3k9Q.partial`), so that it can be no file the user has, and no other program
//! can choose it in advance. It is removed when the [`Staging`] is dropped without
//! [`Staging::commit`]. The replaced file's permissions are kept.
//!
//! [`Staging::create_new`] is the same for an output that must not replace a file: a file at the
//! target is refused at once (`io::ErrorKind::AlreadyExists`), and the commit refuses one that
//! appeared meanwhile rather than renaming over it.

use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};

/// The suffix of a file while it is being written.
pub(crate) const PARTIAL_SUFFIX: &str = ".partial";

/// A temporary file standing in for `target` until it is complete (see the module
/// documentation).
#[derive(Debug)]
pub struct Staging {
    /// The temporary file's path, removed when dropped.
    temp: tempfile::TempPath,
    /// The file replaced on [`Staging::commit`].
    target: PathBuf,
    /// Whether a file at `target` may be replaced.
    replace: bool,
}

impl Staging {
    /// Creates the temporary file for `path`, empty, and returns it open for writing. Through a
    /// link, the file the link points to is the one replaced, not the link.
    pub fn create(path: &Path) -> io::Result<(Staging, File)> {
        Staging::open(path, true)
    }

    /// As [`Staging::create`] when `overwrite`; otherwise a file (or a link) at `path` is
    /// refused with `io::ErrorKind::AlreadyExists`, before anything is created and again at the
    /// commit.
    pub fn create_new(path: &Path, overwrite: bool) -> io::Result<(Staging, File)> {
        if !overwrite && std::fs::symlink_metadata(path).is_ok() {
            return Err(io::ErrorKind::AlreadyExists.into());
        }
        Staging::open(path, overwrite)
    }

    fn open(path: &Path, replace: bool) -> io::Result<(Staging, File)> {
        let target = match std::fs::symlink_metadata(path) {
            Ok(m) if m.file_type().is_symlink() => {
                std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
            }
            _ => path.to_path_buf(),
        };
        let dir = match target.parent() {
            Some(dir) if !dir.as_os_str().is_empty() => dir,
            _ => Path::new("."),
        };
        let mut prefix = target
            .file_name()
            .ok_or_else(|| io::Error::from(io::ErrorKind::IsADirectory))?
            .to_os_string();
        prefix.push(".");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(PARTIAL_SUFFIX).rand_bytes(6);
        // The mode of the file replaced, else that of any new file (less the umask): tempfile's
        // own default, 0600, would make a shared output private.
        let existing = std::fs::metadata(&target)
            .ok()
            .filter(std::fs::Metadata::is_file);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let (file, temp) = builder.tempfile_in(dir)?.into_parts();
        if let Some(existing) = existing {
            #[cfg(unix)]
            {
                use std::os::unix::fs::PermissionsExt;
                let mode = existing.permissions().mode() & 0o777;
                file.set_permissions(std::fs::Permissions::from_mode(mode))?;
            }
            #[cfg(not(unix))]
            file.set_permissions(existing.permissions())?;
        }
        Ok((
            Staging {
                temp,
                target,
                replace,
            },
            file,
        ))
    }

    /// The temporary file's path.
    pub fn path(&self) -> &Path {
        &self.temp
    }

    /// The file it replaces.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Renames the temporary file over the target (write and flush it first); made by
    /// [`Staging::create_new`] without `overwrite`, fails with `io::ErrorKind::AlreadyExists` if
    /// a file appeared at the target meanwhile. On failure the temporary file is removed.
    pub fn commit(self) -> io::Result<()> {
        if self.replace {
            self.temp.persist(&self.target).map_err(|e| e.error)
        } else {
            self.temp
                .persist_noclobber(&self.target)
                .map_err(|e| e.error)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    /// The temporary file is a new one beside the target, never a file that is there (a link
    /// placed at the target's name plus `.partial` is left alone), and goes when dropped.
    #[test]
    fn a_new_file_beside_the_target_removed_unless_committed() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.csv");
        let victim = dir.path().join("victim.txt");
        std::fs::write(&victim, "mine").unwrap();
        #[cfg(unix)]
        std::os::unix::fs::symlink(&victim, dir.path().join("out.csv.partial")).unwrap();
        let (staging, mut file) = Staging::create(&target).unwrap();
        let name = staging.path().file_name().unwrap().to_str().unwrap();
        assert!(
            name.starts_with("out.csv.") && name.ends_with(PARTIAL_SUFFIX) && name.len() > 17,
            "{name}"
        );
        assert_eq!(staging.path().parent(), Some(dir.path()));
        file.write_all(b"new").unwrap();
        let temp = staging.path().to_path_buf();
        drop(staging);
        assert!(!temp.exists());
        assert!(!target.exists());
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "mine");

        let (staging, mut file) = Staging::create(&target).unwrap();
        file.write_all(b"whole").unwrap();
        drop(file);
        staging.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "whole");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);
    }

    /// Without `overwrite`, a file at the target is refused at once, and one that appears
    /// before the commit is left as it is.
    #[test]
    fn a_new_file_never_replaces_one() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.csv");
        std::fs::write(&target, "mine").unwrap();
        let e = Staging::create_new(&target, false).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::AlreadyExists);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        std::fs::remove_file(&target).unwrap();
        let (staging, _) = Staging::create_new(&target, false).unwrap();
        std::fs::write(&target, "late").unwrap();
        let e = staging.commit().unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::AlreadyExists);
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "late");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        let (staging, _) = Staging::create_new(&target, true).unwrap();
        staging.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "");
    }

    /// The replaced file keeps its mode; a new file gets the usual one (not tempfile's 0600).
    #[cfg(unix)]
    #[test]
    fn the_replaced_files_mode_is_kept() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("shared.csv");
        std::fs::write(&target, "old").unwrap();
        std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o640)).unwrap();
        let (staging, _) = Staging::create(&target).unwrap();
        staging.commit().unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&target), 0o640);

        let fresh = dir.path().join("new.csv");
        let (staging, _) = Staging::create(&fresh).unwrap();
        staging.commit().unwrap();
        let plain = dir.path().join("plain.csv");
        File::create(&plain).unwrap();
        assert_eq!(mode(&fresh), mode(&plain));
    }
}
