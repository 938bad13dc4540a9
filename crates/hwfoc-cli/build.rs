//! Puts the git commit and its date into `hwfoc --version` (`HWFOC_VERSION`, see
//! `build_info.rs`), and falls back to the package version alone outside a git checkout; builds
//! the browser app that `hwfoc web` serves (`build_web.rs`).

use std::path::Path;
use std::process::Command;

#[path = "build_info.rs"]
mod build_info;
#[path = "build_web.rs"]
mod build_web;

/// Runs git in the package's directory: its trimmed output, or `None` if it failed.
fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .args(args)
        // Read when the script runs (a target folder may be reused by another checkout).
        .current_dir(std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"))
        .output()
        .ok()?;
    let text = String::from_utf8(out.stdout).ok()?;
    out.status.success().then(|| text.trim().to_string())
}

fn main() {
    let version = build_info::version_text(env!("CARGO_PKG_VERSION"), git);
    println!("cargo:rustc-env=HWFOC_VERSION={version}");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=build_info.rs");
    println!("cargo:rerun-if-changed=build_web.rs");
    build_web::embed();
    // A new commit moves the branch's ref (a file, or a line of packed-refs); a checkout of
    // another branch or commit changes HEAD. `--git-path` finds them in a worktree too.
    let mut watched = vec!["HEAD".to_string(), "packed-refs".to_string()];
    if let Some(branch) = git(&["symbolic-ref", "-q", "HEAD"]) {
        watched.push(branch);
    }
    for name in watched {
        if let Some(path) = git(&["rev-parse", "--path-format=absolute", "--git-path", &name])
            && Path::new(&path).exists()
        {
            println!("cargo:rerun-if-changed={path}");
        }
    }
}
