//! Builds the browser app's files: `crates/hwfoc-web` for `wasm32-unknown-unknown` (the `web`
//! profile), its JavaScript glue by wasm-bindgen's library (the same code as the
//! `wasm-bindgen` command, at the version of the crate, so nothing is installed but the Rust
//! target that `rust-toolchain.toml` names), and the page's own files from `web/`.
//!
//! Used by `web/build.sh` (the folder to deploy, `web/dist`) and by `hwfoc-cli`'s build script
//! (the files `hwfoc web` serves from the binary).

#![warn(missing_docs)]

use std::fmt;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The page's files and folders under `web/`, copied as they are (`sw.js`, the service worker,
/// where the live mode has one).
pub const PAGE: [&str; 4] = ["index.html", "style.css", "sw.js", "src"];

/// The WebAssembly build's own target folder: `hwfoc-web` in the workspace's (`CARGO_TARGET_DIR`
/// or `ROOT/target`), not the workspace's itself, whose lock the build running hwfoc-cli's
/// build script holds; shared by every profile and by web/build.sh.
pub fn target_dir(root: &Path) -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"))
        .join("hwfoc-web")
}

/// What stopped a build.
#[derive(Debug)]
pub enum BuildError {
    /// `cargo` could not be started.
    Cargo(std::io::Error),
    /// The WebAssembly build failed (cargo's own messages went to stderr).
    WasmBuild(std::process::ExitStatus),
    /// wasm-bindgen could not make the glue.
    Bindgen(String),
    /// A file could not be read or written.
    Io(PathBuf, std::io::Error),
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BuildError::Cargo(e) => write!(f, "cannot run cargo: {e}"),
            BuildError::WasmBuild(status) => write!(
                f,
                "building hwfoc-web for wasm32-unknown-unknown failed ({status}); the target is \
                 installed by `rustup target add wasm32-unknown-unknown`"
            ),
            BuildError::Bindgen(e) => write!(f, "wasm-bindgen: {e}"),
            BuildError::Io(path, e) => write!(f, "{}: {e}", path.display()),
        }
    }
}

impl std::error::Error for BuildError {}

/// Builds the app from the workspace at `root` into `out` (emptied first), compiling in
/// `target_dir`. Returns the files written, relative to `out`.
pub fn build(root: &Path, target_dir: &Path, out: &Path) -> Result<Vec<PathBuf>, BuildError> {
    let wasm = build_wasm(root, target_dir)?;
    if out.exists() {
        std::fs::remove_dir_all(out).map_err(|e| BuildError::Io(out.to_owned(), e))?;
    }
    let pkg = out.join("pkg");
    wasm_bindgen_cli_support::Bindgen::new()
        .input_path(&wasm)
        .web(true)
        .and_then(|b| {
            b.typescript(false)
                .omit_default_module_path(false)
                .generate(&pkg)
        })
        .map_err(|e| BuildError::Bindgen(format!("{e:#}")))?;
    let web = root.join("web");
    for name in PAGE {
        let from = web.join(name);
        if from.exists() {
            copy(&from, &out.join(name))?;
        }
    }
    let mut files = Vec::new();
    list(out, out, &mut files)?;
    files.sort();
    Ok(files)
}

/// Compiles `hwfoc-web` for the browser; returns the `.wasm`'s path.
fn build_wasm(root: &Path, target_dir: &Path) -> Result<PathBuf, BuildError> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut command = Command::new(cargo);
    command
        .arg("build")
        .arg("--manifest-path")
        .arg(root.join("Cargo.toml"))
        .args(["-p", "hwfoc-web", "--profile", "web"])
        .args(["--target", "wasm32-unknown-unknown"])
        .arg("--target-dir")
        .arg(target_dir);
    // Run from a build script: the outer build's settings are not the browser's.
    for (key, _) in std::env::vars_os() {
        let key = key.to_string_lossy();
        let outer = (key.starts_with("CARGO_") && key != "CARGO_HOME" && key != "CARGO_MAKEFLAGS")
            || matches!(
                key.as_ref(),
                "RUSTFLAGS" | "RUSTC_WORKSPACE_WRAPPER" | "TARGET" | "HOST" | "OUT_DIR" | "PROFILE"
            );
        if outer {
            command.env_remove(key.as_ref());
        }
    }
    let status = command.status().map_err(BuildError::Cargo)?;
    if !status.success() {
        return Err(BuildError::WasmBuild(status));
    }
    Ok(target_dir.join("wasm32-unknown-unknown/web/hwfoc_web.wasm"))
}

/// Copies a file or a folder's tree.
fn copy(from: &Path, to: &Path) -> Result<(), BuildError> {
    let io = |path: &Path| {
        let path = path.to_owned();
        move |e| BuildError::Io(path, e)
    };
    if from.is_dir() {
        std::fs::create_dir_all(to).map_err(io(to))?;
        for entry in std::fs::read_dir(from).map_err(io(from))? {
            let entry = entry.map_err(io(from))?;
            copy(&entry.path(), &to.join(entry.file_name()))?;
        }
        Ok(())
    } else {
        std::fs::copy(from, to).map(drop).map_err(io(from))
    }
}

/// The files under `dir`, relative to `base`.
fn list(base: &Path, dir: &Path, files: &mut Vec<PathBuf>) -> Result<(), BuildError> {
    let io = |e| BuildError::Io(dir.to_owned(), e);
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let path = entry.map_err(io)?.path();
        if path.is_dir() {
            list(base, &path, files)?;
        } else if let Ok(relative) = path.strip_prefix(base) {
            files.push(relative.to_owned());
        }
    }
    Ok(())
}
