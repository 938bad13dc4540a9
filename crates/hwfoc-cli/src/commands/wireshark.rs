//! `hwfoc wireshark install | path | print`: the Wireshark dissector for hwfoc recordings.
//!
//! The dissector (`wireshark/hwfoc.lua` in this crate) is built into the binary. `install` puts
//! it in Wireshark's personal Lua plugin folder, where Wireshark and tshark load it at start
//! (Help > About Wireshark > Folders > "Personal Lua Plugins"): `~/.local/lib/wireshark/plugins`
//! on Linux and macOS (Wireshark builds it from the home folder alone: `XDG_CONFIG_HOME` and
//! `XDG_DATA_HOME` do not move it) and `%APPDATA%\Wireshark\plugins` on Windows.
//!
//! Nothing a person has is destroyed: an existing `hwfoc.lua` that differs from this version is
//! only replaced with `--force`, and the file is written to a temporary name in the same folder,
//! then renamed over, so that the folder never holds half a dissector.

use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};

use crate::error::CliError;
use hwfoc_io::write::{Staging, WriteError};

/// The dissector's source.
pub const DISSECTOR: &str = include_str!("../../wireshark/hwfoc.lua");
/// The dissector's file name in the plugin folder.
pub const FILE_NAME: &str = "hwfoc.lua";

/// Arguments of `hwfoc wireshark`.
#[derive(Debug, Args)]
pub struct WiresharkArgs {
    #[command(subcommand)]
    pub action: Action,
}

/// What to do with the dissector.
#[derive(Debug, Subcommand)]
pub enum Action {
    /// Write the dissector into Wireshark's personal Lua plugin folder (restart Wireshark after).
    Install {
        /// Replace an existing hwfoc.lua that differs from this version.
        #[arg(long)]
        force: bool,
        /// Install into DIR instead of the personal plugin folder.
        #[arg(long, value_name = "DIR")]
        dir: Option<PathBuf>,
    },
    /// Print where `install` writes the dissector.
    Path,
    /// Write the dissector to standard output (for `tshark -X lua_script:FILE`, or to read it).
    Print,
}

/// Why the dissector could not be installed.
#[derive(Debug)]
pub enum WiresharkError {
    /// No home folder (or `%APPDATA%`) to find the plugin folder from.
    NoHome,
    /// A different `hwfoc.lua` is there and `--force` was not given.
    Exists(PathBuf),
    /// Creating the folder or writing the file failed.
    Write {
        /// The file or folder.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
}

impl fmt::Display for WiresharkError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WiresharkError::NoHome => write!(
                f,
                "cannot find Wireshark's plugin folder: {} is not set (give --dir)",
                if cfg!(windows) { "APPDATA" } else { "HOME" }
            ),
            WiresharkError::Exists(path) => write!(
                f,
                "{} exists and differs from this version's dissector: it is left as it is \
                 (pass --force to replace it)",
                path.display()
            ),
            WiresharkError::Write { path, source } => {
                write!(f, "cannot write {}: {source}", path.display())
            }
        }
    }
}

impl From<WiresharkError> for CliError {
    fn from(e: WiresharkError) -> Self {
        match e {
            WiresharkError::NoHome => CliError::Usage {
                option: "--dir".to_string(),
                message: e.to_string(),
            },
            WiresharkError::Exists(ref path) => CliError::Usage {
                option: "hwfoc wireshark install".to_string(),
                message: format!(
                    "{} exists and differs from this version's dissector: it is left as it is \
                     (pass --force to replace it)",
                    path.display()
                ),
            },
            WiresharkError::Write { path, source } => CliError::Write(WriteError::Write {
                output: path.display().to_string(),
                source,
            }),
        }
    }
}

impl std::error::Error for WiresharkError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            WiresharkError::Write { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Wireshark's personal Lua plugin folder, from the environment as Wireshark reads it:
/// `%APPDATA%\Wireshark\plugins` on Windows, `$HOME/.local/lib/wireshark/plugins` elsewhere.
pub fn plugin_dir(var: impl Fn(&str) -> Option<String>) -> Option<PathBuf> {
    let set = |name: &str| var(name).filter(|v| !v.is_empty());
    if cfg!(windows) {
        set("APPDATA").map(|d| Path::new(&d).join("Wireshark").join("plugins"))
    } else {
        set("HOME").map(|h| Path::new(&h).join(".local/lib/wireshark/plugins"))
    }
}

fn env(name: &str) -> Option<String> {
    std::env::var(name).ok()
}

/// What `install` did.
#[derive(Debug, PartialEq, Eq)]
pub enum Installed {
    /// The file was written (new, or replacing another with `--force`).
    Written,
    /// The same dissector was already there.
    Unchanged,
}

/// Installs `source` as `dir/hwfoc.lua`: creates `dir`, refuses to replace a different file
/// unless `force`, writes through a temporary file renamed over the target (a [`Staging`]).
pub fn install(dir: &Path, source: &str, force: bool) -> Result<Installed, WiresharkError> {
    let target = dir.join(FILE_NAME);
    match std::fs::read(&target) {
        Ok(existing) if existing == source.as_bytes() => return Ok(Installed::Unchanged),
        Ok(_) if !force => return Err(WiresharkError::Exists(target)),
        _ => {}
    }
    let fail = |path: &Path| {
        let path = path.to_path_buf();
        move |source| WiresharkError::Write { path, source }
    };
    std::fs::create_dir_all(dir).map_err(fail(dir))?;
    let written = Staging::create(&target).and_then(|(staging, mut file)| {
        file.write_all(source.as_bytes())?;
        file.sync_all()?;
        drop(file);
        staging.commit()
    });
    written.map_err(fail(&target))?;
    Ok(Installed::Written)
}

/// Runs `hwfoc wireshark`.
pub fn run(args: &WiresharkArgs) -> Result<(), CliError> {
    let dir = |given: &Option<PathBuf>| {
        given
            .clone()
            .or_else(|| plugin_dir(env))
            .ok_or(WiresharkError::NoHome)
    };
    let mut out = std::io::stdout().lock();
    let written = match &args.action {
        Action::Print => out.write_all(DISSECTOR.as_bytes()),
        Action::Path => writeln!(out, "{}", dir(&None)?.join(FILE_NAME).display()),
        Action::Install { force, dir: given } => {
            let dir = dir(given)?;
            let target = dir.join(FILE_NAME);
            let done = install(&dir, DISSECTOR, *force)?;
            match done {
                Installed::Written => writeln!(
                    out,
                    "installed the hwfoc dissector as {}: restart Wireshark (or reload Lua \
                     plugins, Ctrl+Shift+L) and open a recording",
                    target.display()
                ),
                Installed::Unchanged => writeln!(
                    out,
                    "{} is already this version's dissector",
                    target.display()
                ),
            }
        }
    };
    written.map_err(|source| {
        CliError::Write(WriteError::Write {
            output: "standard output".to_string(),
            source,
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plugin_dir_follows_wireshark() {
        let home = |name: &str| (name == "HOME" || name == "APPDATA").then(|| "/h".to_string());
        let dir = plugin_dir(home).unwrap();
        if cfg!(windows) {
            assert_eq!(dir, Path::new("/h").join("Wireshark").join("plugins"));
        } else {
            assert_eq!(dir, Path::new("/h/.local/lib/wireshark/plugins"));
        }
        assert_eq!(plugin_dir(|_| None), None);
        assert_eq!(plugin_dir(|_| Some(String::new())), None);
    }

    #[test]
    fn install_never_replaces_another_file_unasked() {
        let dir = tempfile::tempdir().unwrap();
        let plugins = dir.path().join("a/b/plugins");
        assert_eq!(install(&plugins, "v1", false).unwrap(), Installed::Written);
        let target = plugins.join(FILE_NAME);
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "v1");
        assert_eq!(
            install(&plugins, "v1", false).unwrap(),
            Installed::Unchanged
        );
        std::fs::write(&target, "my own edits").unwrap();
        let err = install(&plugins, "v2", false).unwrap_err();
        assert!(matches!(err, WiresharkError::Exists(_)), "{err}");
        assert!(err.to_string().contains("--force"));
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "my own edits");
        assert_eq!(install(&plugins, "v2", true).unwrap(), Installed::Written);
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "v2");
        // No temporary file is left behind.
        let names: Vec<_> = std::fs::read_dir(&plugins).unwrap().collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn the_embedded_dissector_is_the_file() {
        assert!(DISSECTOR.starts_with("-- hwfoc.lua"));
        assert!(DISSECTOR.contains("Proto(\"hwfoc\""));
    }
}
