//! `cargo run -p hwfoc-web-build [-- OUT]`: the browser app into OUT (default `web/dist`), as
//! web/build.sh runs it.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

fn main() -> ExitCode {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = manifest
        .parent()
        .and_then(Path::parent)
        .unwrap_or(manifest)
        .to_owned();
    let out = std::env::args_os()
        .nth(1)
        .map_or_else(|| root.join("web/dist"), PathBuf::from);
    match hwfoc_web_build::build(&root, &hwfoc_web_build::target_dir(&root), &out) {
        Ok(files) => {
            println!("{}: {} files", out.display(), files.len());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("hwfoc-web-build: {e}");
            ExitCode::FAILURE
        }
    }
}
