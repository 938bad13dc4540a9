//! Every example of `README.md` and `docs/*.md` runs as written (`docs/DESIGN.md`, "Examples
//! that run", says the rules for readers).
//!
//! Each document's ```` ```sh ```` blocks run in document order with `bash -e -o pipefail`, in
//! a fresh directory (also `HOME`) where the README's ```` ```sh setup ```` blocks ran first and
//! `testdata/` is linked, with the `hwfoc` under test first on `PATH`. A ```` ```console ````
//! block is a transcript: its `$ ` lines run, and the lines it shows must be in their output in
//! order (`...` skips). A ```` ```toml ```` block must be a configuration `hwfoc` accepts.
//!
//! CI has no ESC, no flight controller and no terminal, so the test substitutes (and says so
//! in DESIGN.md): `cargo run --release --` is the built `hwfoc`; `cargo test`, `cargo install`
//! and `pip install` lines are skipped; `/dev/ttyUSB0`..`3` are virtual ESCs on pseudo-terminals
//! (`hwfoc simulate --pty`) and `/dev/ttyAMA0`, `/dev/ttyACM0` pseudo-terminals the test drains;
//! `monitor` without `--plain`/`--json` runs `--plain`, and `monitor`, `bridge`, `record`
//! without `--duration` stop after 3 s. What a block leaves running is ended with it. Only
//! whether each command succeeds is checked, not its output (other than a transcript's), so
//! that the wording of messages may change without touching this test.

mod common;

use std::fs;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::thread;
use std::time::{Duration, Instant};

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The documents whose examples must run: the README, then `docs/*.md` by name.
fn documents() -> Vec<PathBuf> {
    let mut docs: Vec<PathBuf> = fs::read_dir(root().join("docs"))
        .expect("docs/")
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "md"))
        .collect();
    docs.sort();
    docs.insert(0, root().join("README.md"));
    docs
}

/// A fenced block: where it starts, its info string and its text.
struct Block {
    /// `file:line` of the opening fence.
    place: String,
    info: String,
    text: String,
}

/// The info strings a block may have: those the test runs, and those that are no command.
const RUN: &[&str] = &["sh", "sh setup", "console", "toml", "python"];
const NOT_RUN: &[&str] = &["text", "json", "sql"];

/// The fenced blocks of a document (fences at the start of a line, three backticks).
fn blocks(path: &Path) -> Vec<Block> {
    let text = fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let name = path
        .strip_prefix(root())
        .unwrap_or(path)
        .display()
        .to_string();
    let mut blocks = Vec::new();
    let mut open: Option<Block> = None;
    for (n, line) in text.lines().enumerate() {
        match (open.take(), line.strip_prefix("```")) {
            (None, Some(info)) => {
                open = Some(Block {
                    place: format!("{name}:{}", n + 1),
                    info: info.trim().to_string(),
                    text: String::new(),
                })
            }
            (Some(block), Some("")) => blocks.push(block),
            (Some(mut block), _) => {
                block.text.push_str(line);
                block.text.push('\n');
                open = Some(block);
            }
            (None, None) => {}
        }
    }
    assert!(open.is_none(), "{name}: a block is not closed");
    blocks
}

/// The bash functions every block runs under: `hwfoc` with the substitutions above.
const PRELUDE: &str = r#"
hwfoc() {
  local extra=()
  case "$1" in
    monitor|bridge|record)
      if [ "$1" = monitor ] && [[ " $* " != *" --plain "* && " $* " != *" --json "* ]]; then
        extra+=(--plain)
      fi
      if [[ " $* " != *" --duration "* ]]; then extra+=(--duration 3); fi ;;
  esac
  command hwfoc "$@" "${extra[@]}"
}
"#;

/// The pseudo-terminals standing in for the ports a block names.
struct Ports {
    simulator: Option<Child>,
    dir: PathBuf,
    outputs: Vec<(&'static str, PathBuf)>,
}

impl Ports {
    /// Virtual ESCs for `/dev/ttyUSB0`..`3`, drained pseudo-terminals for the output ports,
    /// as far as `script` names them.
    fn for_script(script: &str, dir: &Path) -> Ports {
        let mut ports = Ports {
            simulator: None,
            dir: dir.join("virtual-ports"),
            outputs: Vec::new(),
        };
        if script.contains("/dev/ttyUSB") {
            let mut child = common::hwfoc()
                .args([
                    "simulate",
                    "--escs",
                    "4",
                    "--pty",
                    "-q",
                    "--duration",
                    "300",
                ])
                .arg("--link-dir")
                .arg(&ports.dir)
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .expect("hwfoc simulate --pty");
            let deadline = Instant::now() + Duration::from_secs(20);
            while !(0..4).all(|i| ports.dir.join(format!("esc{i}")).exists()) {
                assert!(Instant::now() < deadline, "the virtual ESCs' links");
                assert!(
                    child.try_wait().unwrap().is_none(),
                    "hwfoc simulate --pty ended"
                );
                thread::sleep(Duration::from_millis(50));
            }
            ports.simulator = Some(child);
        }
        for name in ["/dev/ttyAMA0", "/dev/ttyACM0"] {
            if script.contains(name) {
                let pty = common::pty();
                let path = pty.path.clone();
                // Reads what the block writes, so that a port never fills; it ends with the
                // test's process.
                thread::spawn(move || {
                    let mut pty = pty;
                    let mut buf = [0u8; 4096];
                    loop {
                        if !pty.master.read(&mut buf).is_ok_and(|n| n > 0) {
                            thread::sleep(Duration::from_millis(20));
                        }
                    }
                });
                ports.outputs.push((name, path));
            }
        }
        ports
    }

    /// `script` with the port names replaced by the pseudo-terminals.
    fn substitute(&self, script: &str) -> String {
        let mut script = script.to_string();
        for i in 0..4 {
            let link = self.dir.join(format!("esc{i}"));
            script = script.replace(&format!("/dev/ttyUSB{i}"), link.to_str().unwrap());
        }
        for (name, path) in &self.outputs {
            script = script.replace(name, path.to_str().unwrap());
        }
        script
    }
}

impl Drop for Ports {
    fn drop(&mut self) {
        if let Some(child) = &mut self.simulator {
            let _ = kill(Pid::from_raw(child.id() as i32), Signal::SIGTERM);
            let _ = child.wait();
        }
    }
}

/// `script` as the test runs it: the commands it cannot run in CI skipped.
fn runnable(script: &str) -> String {
    script
        .lines()
        .map(|line| {
            let command = line.trim_start();
            if ["cargo test", "cargo install", "pip install"]
                .iter()
                .any(|skipped| command.starts_with(skipped))
            {
                format!(": skipped by the test: {command}")
            } else {
                line.replace("cargo run --release --", "hwfoc")
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Runs `script` with bash in `dir`; its standard output, or why it failed.
fn run_bash(script: &str, dir: &Path) -> Result<String, String> {
    use std::os::unix::process::CommandExt;
    let ports = Ports::for_script(script, dir);
    let script = format!("{PRELUDE}\n{}\n", ports.substitute(&runnable(script)));
    let bin = Path::new(env!("CARGO_BIN_EXE_hwfoc")).parent().unwrap();
    let path = std::env::join_paths(std::iter::once(bin.to_path_buf()).chain(
        std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default()),
    ))
    .unwrap();
    let out_path = dir.join(".block-stdout");
    let err_path = dir.join(".block-stderr");
    let mut child = Command::new("bash")
        .args(["-e", "-o", "pipefail", "-c", &script])
        .current_dir(dir)
        .env("PATH", path)
        .env("HOME", dir)
        .env_remove("XDG_CONFIG_HOME")
        .env_remove("HWFOC_CONFIG")
        .stdin(Stdio::null())
        .stdout(fs::File::create(&out_path).unwrap())
        .stderr(fs::File::create(&err_path).unwrap())
        .process_group(0)
        .spawn()
        .expect("bash");
    let deadline = Instant::now() + Duration::from_secs(180);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break Some(status);
        }
        if Instant::now() > deadline {
            break None;
        }
        thread::sleep(Duration::from_millis(50));
    };
    // What the block left running (a simulator in the background) ends with it.
    let group = Pid::from_raw(-(child.id() as i32));
    let _ = kill(group, Signal::SIGTERM);
    if status.is_none() {
        let _ = kill(group, Signal::SIGKILL);
        let _ = child.wait();
    }
    let stdout = fs::read_to_string(&out_path).unwrap_or_default();
    let stderr = fs::read_to_string(&err_path).unwrap_or_default();
    match status {
        Some(status) if status.success() => Ok(stdout),
        Some(status) => Err(format!("{status}\nstandard error:\n{stderr}")),
        None => Err(format!(
            "still running after 180 s\nstandard error:\n{stderr}"
        )),
    }
}

/// Checks a transcript: each `$ ` line's output holds the lines shown after it, in order.
fn run_console(text: &str, dir: &Path) -> Result<(), String> {
    let mut commands: Vec<(String, Vec<&str>)> = Vec::new();
    for line in text.lines() {
        match line.strip_prefix("$ ") {
            Some(command) => commands.push((command.to_string(), Vec::new())),
            None => match commands.last_mut() {
                Some((_, shown)) => shown.push(line),
                None => return Err("a transcript starts with a `$ ` line".into()),
            },
        }
    }
    for (command, shown) in commands {
        let output = run_bash(&command, dir)?;
        let mut lines = output.lines();
        for want in shown.iter().filter(|line| **line != "...") {
            if !lines.any(|got| got == *want) {
                return Err(format!(
                    "`{command}` does not print, in this order, the line {want:?}; it prints:\n{output}"
                ));
            }
        }
    }
    Ok(())
}

/// Checks a configuration file: `hwfoc` reads it without complaint.
fn run_toml(text: &str, dir: &Path) -> Result<(), String> {
    let config = dir.join("example-config.toml");
    fs::write(&config, text).unwrap();
    let capture = common::capture(common::XROTOR);
    let out = common::hwfoc()
        .arg("summary")
        .arg("--config")
        .arg(&config)
        .arg(&capture)
        .output()
        .unwrap();
    if out.status.success() {
        Ok(())
    } else {
        Err(String::from_utf8_lossy(&out.stderr).into_owned())
    }
}

/// Whether a block needs tshark (run only by [`every_example_that_needs_tshark_runs`]).
fn needs_tshark(block: &Block) -> bool {
    block.text.contains("tshark")
}

/// Runs a document's blocks in order in a fresh directory (those that need tshark only
/// `with_tshark`); the failures, one per block.
fn run_document(path: &Path, setup: &[Block], with_tshark: bool) -> Vec<String> {
    let dir = common::Dir::new();
    std::os::unix::fs::symlink(root().join("testdata"), dir.path("testdata")).unwrap();
    let is_readme = path.ends_with("README.md") && path.parent() == Some(&root());
    let mut failures = Vec::new();
    if !is_readme {
        for block in setup {
            if let Err(why) = run_bash(&block.text, dir.0.path()) {
                failures.push(format!("{} (setup): {why}", block.place));
                return failures;
            }
        }
    }
    for block in blocks(path) {
        if needs_tshark(&block) && !with_tshark {
            continue;
        }
        let result = match block.info.as_str() {
            "sh" | "sh setup" => run_bash(&block.text, dir.0.path()).map(drop),
            "console" => run_console(&block.text, dir.0.path()),
            "toml" => run_toml(&block.text, dir.0.path()),
            _ => Ok(()),
        };
        if let Err(why) = result {
            failures.push(format!(
                "{}: ```{} block:\n{}\n{why}",
                block.place, block.info, block.text
            ));
        }
    }
    failures
}

/// Every fenced block says its language: one the tests run, or one that is no command.
#[test]
fn every_block_has_a_known_language() {
    let mut wrong = Vec::new();
    for doc in documents() {
        for block in blocks(&doc) {
            if !RUN.contains(&block.info.as_str()) && !NOT_RUN.contains(&block.info.as_str()) {
                wrong.push(format!("{}: ```{}", block.place, block.info));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "blocks of a language the tests neither run nor know to be no command \
         (mark one that is no command ```text):\n{}",
        wrong.join("\n")
    );
}

/// The README's ```sh setup blocks, run before each other document's blocks.
fn setup_blocks() -> Vec<Block> {
    let setup: Vec<Block> = blocks(&root().join("README.md"))
        .into_iter()
        .filter(|b| b.info == "sh setup")
        .collect();
    assert!(!setup.is_empty(), "README.md: no ```sh setup block");
    setup
}

/// Every shell example, transcript and configuration file of the documents runs as written
/// (but those that need tshark: [`every_example_that_needs_tshark_runs`]).
#[test]
fn every_example_runs() {
    let setup = setup_blocks();
    let mut failures = Vec::new();
    let mut ran = Vec::new();
    for doc in documents() {
        let count = blocks(&doc)
            .iter()
            .filter(|b| ["sh", "sh setup", "console", "toml"].contains(&b.info.as_str()))
            .count();
        let name = doc
            .strip_prefix(root())
            .unwrap_or(&doc)
            .display()
            .to_string();
        ran.push(format!("{name} ({count} blocks)"));
        failures.extend(run_document(&doc, &setup, false));
    }
    eprintln!("ran the examples of: {}", ran.join(", "));
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// The documents with an example that needs tshark run as written, those examples included.
#[test]
#[ignore = "needs tshark: .ci/run installs it and runs these with --ignored"]
fn every_example_that_needs_tshark_runs() {
    common::need_tshark();
    let setup = setup_blocks();
    let mut failures = Vec::new();
    let mut ran = 0;
    for doc in documents() {
        if blocks(&doc).iter().any(needs_tshark) {
            ran += 1;
            failures.extend(run_document(&doc, &setup, true));
        }
    }
    assert!(ran > 0, "no document has an example that needs tshark");
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// Every relative link of the documents (`[text](path#anchor)`), and every document of `docs/`
/// the sources cite (a `.md` or `.txt` name after that folder's name), is a file of the
/// repository.
#[test]
fn every_cited_document_exists() {
    let mut missing = Vec::new();
    let mut documents = documents();
    documents.push(root().join("ARCHITECTURE.md"));
    for doc in &documents {
        let text = fs::read_to_string(doc).unwrap();
        let name = doc
            .strip_prefix(root())
            .unwrap_or(doc)
            .display()
            .to_string();
        for (_, rest) in text.match_indices("](").map(|(i, _)| ((), &text[i + 2..])) {
            let Some(end) = rest.find(')') else { continue };
            let target = rest[..end].split('#').next().unwrap();
            if target.is_empty() || target.contains("://") {
                continue;
            }
            if !doc.parent().unwrap().join(target).exists() {
                missing.push(format!("{name}: link to {target}"));
            }
        }
    }
    // The sources: each crate's and the Python package's files that cite a document.
    let mut sources = Vec::new();
    let mut dirs = vec![
        root().join("crates"),
        root().join("python"),
        root().join("testdata"),
    ];
    while let Some(dir) = dirs.pop() {
        for entry in fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let file_name = path.file_name().unwrap().to_string_lossy().into_owned();
            if path.is_dir() {
                if !["target", ".git", "captures", "recordings"].contains(&file_name.as_str()) {
                    dirs.push(path);
                }
            } else if [".rs", ".py", ".pyi", ".lua", ".sh", ".md", ".toml"]
                .iter()
                .any(|ext| file_name.ends_with(ext))
            {
                sources.push(path);
            }
        }
    }
    for source in sources {
        let Ok(text) = fs::read_to_string(&source) else {
            continue;
        };
        for (i, _) in text.match_indices("docs/") {
            let cited: String = text[i..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || "/-_.".contains(*c))
                .collect();
            let cited = cited.trim_end_matches('.');
            if (cited.ends_with(".md") || cited.ends_with(".txt")) && !root().join(cited).exists() {
                let name = source.strip_prefix(root()).unwrap_or(&source).display();
                missing.push(format!("{name}: {cited}"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "cited, but not in the repository:\n{}",
        missing.join("\n")
    );
}

/// The help of `hwfoc` and of every command and subcommand, all in one text.
fn all_help() -> String {
    let mut text = String::new();
    let mut todo: Vec<Vec<String>> = vec![Vec::new()];
    while let Some(path) = todo.pop() {
        let out = common::hwfoc()
            .args(&path)
            .arg("--help")
            .output()
            .expect("hwfoc --help");
        assert!(out.status.success(), "hwfoc {path:?} --help");
        let help = String::from_utf8(out.stdout).unwrap();
        // The commands of a "Commands:" section, up to the next blank line.
        let commands = help
            .lines()
            .skip_while(|l| !l.starts_with("Commands:"))
            .skip(1)
            .take_while(|l| !l.trim().is_empty());
        // A command's line is indented two spaces; its description's next lines, more.
        for line in commands.filter(|l| l.starts_with("  ") && !l.starts_with("   ")) {
            let name = line.split_whitespace().next().unwrap_or("help");
            if name != "help" {
                todo.push(path.iter().cloned().chain([name.to_string()]).collect());
            }
        }
        text.push_str(&help);
    }
    text
}

/// Every `--option` the README names is one of hwfoc's (cargo's own, on its lines, aside).
#[test]
fn every_option_the_readme_names_exists() {
    let readme = fs::read_to_string(root().join("README.md")).unwrap();
    let help = all_help();
    let is_option_char = |c: char| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-';
    let mut missing = Vec::new();
    for line in readme
        .lines()
        .filter(|l| !l.trim_start().starts_with("cargo "))
    {
        for (at, _) in line.match_indices("--") {
            let before = line[..at].chars().last();
            if before.is_some_and(|c| !matches!(c, ' ' | '`' | '(' | '[')) {
                continue;
            }
            let name: String = line[at + 2..]
                .chars()
                .take_while(|&c| is_option_char(c))
                .collect();
            if name.is_empty() || !name.starts_with(|c: char| c.is_ascii_lowercase()) {
                continue;
            }
            let option = format!("--{name}");
            let named = help
                .match_indices(&option)
                .any(|(i, _)| !help[i + option.len()..].starts_with(is_option_char));
            if !named {
                missing.push(option);
            }
        }
    }
    assert!(missing.is_empty(), "options no command has: {missing:?}");
}

/// The README stays a short guide: at most 3,000 words (as `wc -w` counts them); details live in
/// `docs/`.
#[test]
fn the_readme_stays_short() {
    let readme = fs::read_to_string(root().join("README.md")).unwrap();
    let words = readme.split_whitespace().count();
    assert!(
        words <= 3000,
        "README.md has {words} words: move details to docs/"
    );
}
