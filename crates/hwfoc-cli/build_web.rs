//! The browser app embedded for `hwfoc web`: built from the workspace by `hwfoc-web-build`
//! (crates/hwfoc-web to WebAssembly, its glue, the page's files of web/) into `OUT_DIR/web`,
//! listed in `OUT_DIR/web_files.rs` as `(path, include_bytes!)` pairs.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Builds the app and writes the list of its files; tells cargo what to watch.
pub fn embed() {
    // Read when the script runs, not when it was compiled: a target folder moved to another
    // checkout (CI's clone) reuses the compiled script, which must build that checkout's app.
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let root = manifest
        .parent()
        .and_then(Path::parent)
        .expect("crates/hwfoc-cli is two folders below the workspace");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let dist = out.join("web");
    let files = hwfoc_web_build::build(root, &hwfoc_web_build::target_dir(root), &dist)
        .unwrap_or_else(|e| panic!("the browser app for `hwfoc web`: {e}"));
    let mut list = String::from("&[\n");
    // Each file named from `OUT_DIR` when the crate compiles, not by the path it had here: a
    // target folder moved to another checkout (CI's clone) keeps this list without running
    // the script again.
    for file in &files {
        let name = file.to_string_lossy().replace('\\', "/");
        writeln!(
            list,
            "    ({name:?}, include_bytes!(concat!(env!(\"OUT_DIR\"), {:?}))),",
            format!("/web/{name}")
        )
        .unwrap();
    }
    list.push_str("]\n");
    std::fs::write(out.join("web_files.rs"), list).expect("OUT_DIR is writable");
    for watched in [
        "web/index.html",
        "web/style.css",
        "web/sw.js",
        "web/src",
        "crates/hwfoc-web",
        "crates/hwfoc/src",
        "crates/hwfoc-records/src",
        "Cargo.lock",
    ] {
        // Relative to this crate (cargo joins them to the package root): the watch follows the
        // checkout the target folder is used from.
        println!("cargo:rerun-if-changed=../../{watched}");
    }
}
