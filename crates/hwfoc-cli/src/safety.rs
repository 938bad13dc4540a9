//! Which files a command may write: never one it reads.
//!
//! The library tells files apart ([`hwfoc_io::write::FileId`]); which files a command reads
//! (its inputs, standard input, its configuration file) and what it says when an output is
//! one of them are the command line's.

use std::path::{Path, PathBuf};

use hwfoc_io::write::FileId;

use crate::args::InputArgs;
use crate::config::Config;
use crate::error::CliError;

impl InputArgs {
    /// Refuses an output (`-`: standard output) that is a file the command reads: one of the
    /// inputs (`-`: whatever is behind standard input) or the configuration file read (see
    /// [`refuse_input`]). Call it before the output is opened.
    pub fn refuse_output(&self, output: &str, config: &Config) -> Result<(), CliError> {
        let config = config_read(config);
        let inputs = self.inputs.iter().map(Path::new);
        refuse_input(output, inputs.chain(config.as_deref()))
    }
}

/// The configuration file `config` was read from, as [`refuse_input`] takes a file read (to
/// which `-` is standard input; a configuration file named `-` is a file).
pub fn config_read(config: &Config) -> Option<PathBuf> {
    let path = config.path.as_ref()?;
    Some(if path.as_os_str() == "-" {
        Path::new(".").join(path)
    } else {
        path.clone()
    })
}

/// Refuses an output that is one of `inputs`, every file the command reads (the same file, by
/// device and inode: the same path, `./` before it, a link to it), before anything is opened
/// for writing. An input `-` is standard input, whatever file is behind it (`< r1.bin`); the
/// output `-` is standard output, refused when it is a regular file that is an input
/// (`>> r1.bin`).
pub fn refuse_input<'a>(
    output: &str,
    inputs: impl IntoIterator<Item = &'a Path>,
) -> Result<(), CliError> {
    let written = if output == "-" {
        FileId::of_stdout()
    } else {
        FileId::of_path(Path::new(output))
    };
    let Some(written) = written else {
        return Ok(());
    };
    let clash = inputs.into_iter().find(|input| {
        let read = match input.as_os_str().to_str() {
            Some("-") => FileId::of_stdin(),
            _ => FileId::of_path(input),
        };
        read.as_ref() == Some(&written)
    });
    match clash {
        Some(input) => Err(CliError::IsInput {
            output: match output {
                "-" => "standard output".to_string(),
                _ => output.to_string(),
            },
            input: match input.as_os_str().to_str() {
                Some("-") => "standard input".to_string(),
                _ => input.display().to_string(),
            },
        }),
        None => Ok(()),
    }
}

/// Whether writing `a` and writing `b` would write one file: the same name, the same existing
/// file (by device and inode), or the same place once links are followed, dangling ones too
/// (`--truth link` where `link` points at the recording `-o` is about to create).
pub fn same_output(a: &str, b: &str) -> bool {
    a == b
        || hwfoc_io::write::same_file(a, b)
        || written_at(Path::new(a)).is_some_and(|p| Some(p) == written_at(Path::new(b)))
}

/// Where a file written at `path` lands: its links followed (at most 40, as the kernel does),
/// whether or not their target exists, in its directory made absolute; `None` when that
/// directory cannot be told.
fn written_at(path: &Path) -> Option<PathBuf> {
    let mut path = path.to_path_buf();
    for _ in 0..40 {
        let Ok(target) = std::fs::read_link(&path) else {
            break;
        };
        path = match path.parent() {
            Some(dir) => dir.join(target),
            None => target,
        };
    }
    let name = path.file_name()?;
    let dir = match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Some(dir.canonicalize().ok()?.join(name))
}
