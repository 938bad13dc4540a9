//! Helpers shared by the integration tests that run `hwfoc` as a process: starting it without
//! leaking pseudo-terminal descriptors into it, pseudo-terminals that stand in for serial
//! ports, and a running `hwfoc` whose output lines can be waited for.

#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Child, Command, Output, Stdio};
use std::time::{SystemTime, UNIX_EPOCH};

#[cfg(unix)]
#[allow(unused_imports)]
pub use self::unix::*;

/// The columns of docs/RECORD-SCHEMA.md, in order: those of the column table, which hwfoc-io's
/// `tests/schema.rs` checks against a copy of the specification's table.
#[allow(unused_imports)]
pub use hwfoc_io::record::COLUMNS as SCHEMA;

/// The columns JSON Lines and CSV write, in order: all of [`SCHEMA`] but `time` (Parquet and
/// Arrow only).
#[allow(unused_imports)]
pub use hwfoc_io::record::TEXT_COLUMNS as TEXT_SCHEMA;

/// The real capture of an XRotor ESC in `testdata/captures`.
pub const XROTOR: &str = "xrotor-v4-pro-hv-80A.csv";

/// The path of a real capture in the repository's `testdata/captures` (see its README).
pub fn capture(name: &str) -> PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../testdata/captures")
        .join(name)
}

/// Standard output of a run that must have succeeded (standard error shown otherwise).
pub fn stdout(o: &Output) -> String {
    String::from_utf8(ok(o.clone()).stdout).unwrap()
}

/// A temporary directory, removed at the end of the test.
pub struct Dir(pub tempfile::TempDir);

impl Dir {
    pub fn new() -> Dir {
        Dir(tempfile::tempdir().unwrap())
    }

    /// The path of `name` in it.
    pub fn path(&self, name: &str) -> PathBuf {
        self.0.path().join(name)
    }

    /// The path of `name` in it, as an argument.
    pub fn arg(&self, name: &str) -> String {
        self.path(name).to_str().unwrap().to_string()
    }
}

/// Asserts success (showing standard error otherwise) and hands the output on.
pub fn ok(o: Output) -> Output {
    assert!(
        o.status.success(),
        "hwfoc failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// Asserts a failure with exactly one line on standard error, `hwfoc: ` and then a message
/// containing `needle`, and no panic.
pub fn assert_fails_with(o: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "stderr: {err}");
    assert!(err.contains(needle), "{needle:?} not in {err:?}");
    assert_eq!(err.lines().count(), 1, "one line expected: {err:?}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.starts_with("hwfoc: "), "{err}");
}

pub fn hwfoc() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hwfoc"))
}

pub fn spawn(cmd: &mut Command) -> Child {
    cmd.stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn")
}

pub fn run(cmd: &mut Command) -> Output {
    spawn(cmd).wait_with_output().expect("wait")
}

/// The JSON lines of `jsonl` (`hwfoc decode`'s records, a receiver's messages).
pub fn records(jsonl: &str) -> Vec<serde_json::Value> {
    jsonl
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON line"))
        .collect()
}

/// Records by their `esc`, in order.
pub fn by_esc(
    records: &[serde_json::Value],
) -> std::collections::BTreeMap<u64, Vec<serde_json::Value>> {
    let mut out = std::collections::BTreeMap::<u64, Vec<serde_json::Value>>::new();
    for r in records {
        out.entry(r["esc"].as_u64().unwrap())
            .or_default()
            .push(r.clone());
    }
    out
}

pub fn unix_now() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap()
        .as_secs_f64()
}

/// Pseudo-terminals and running processes (Unix only).
#[cfg(unix)]
mod unix {
    use std::io::{BufRead, BufReader, Read};
    use std::os::fd::OwnedFd;
    use std::path::PathBuf;
    use std::process::Child;
    use std::sync::mpsc::{self, Receiver, Sender};
    use std::sync::{Arc, Mutex};
    use std::thread;
    use std::time::{Duration, Instant};

    use nix::sys::signal::{Signal, kill};
    use nix::unistd::Pid;

    use hwfoc_sim::pty::RawPair;

    use super::{hwfoc, spawn};

    /// A pseudo-terminal: the master side the test writes to, and the path of the slave side that
    /// `hwfoc` opens like a serial port.
    pub struct Pty {
        pub master: std::fs::File,
        pub path: PathBuf,
        _slave: OwnedFd,
    }

    pub fn pty() -> Pty {
        // Raw, so that nothing is echoed or translated before `hwfoc` opens the port; both sides
        // close-on-exec from the start, so that an `hwfoc` started by another test meanwhile
        // does not keep the terminal alive after this test closes it.
        let pair = RawPair::open().expect("pty");
        Pty {
            master: pair.master,
            path: pair.path,
            _slave: pair.slave,
        }
    }

    /// A running `hwfoc` whose standard output and standard error are collected line by line.
    pub struct Running {
        pub child: Child,
        err_lines: Receiver<String>,
        out_lines: Receiver<String>,
        stderr: Arc<Mutex<Vec<String>>>,
        stdout: Arc<Mutex<Vec<String>>>,
    }

    /// Collects the lines of `pipe` into `all` and sends each on `tx`.
    fn collect(pipe: impl Read + Send + 'static, all: Arc<Mutex<Vec<String>>>, tx: Sender<String>) {
        thread::spawn(move || {
            for line in BufReader::new(pipe).lines() {
                let Ok(line) = line else { break };
                all.lock().unwrap().push(line.clone());
                let _ = tx.send(line);
            }
        });
    }

    impl Running {
        pub fn start(args: &[&str]) -> Running {
            let mut child = spawn(hwfoc().args(args));
            let stderr = Arc::new(Mutex::new(Vec::new()));
            let stdout = Arc::new(Mutex::new(Vec::new()));
            let (tx, err_lines) = mpsc::channel();
            collect(child.stderr.take().unwrap(), Arc::clone(&stderr), tx);
            let (tx, out_lines) = mpsc::channel();
            collect(child.stdout.take().unwrap(), Arc::clone(&stdout), tx);
            Running {
                child,
                err_lines,
                out_lines,
                stderr,
                stdout,
            }
        }

        fn wait_on(
            &self,
            lines: &Receiver<String>,
            what: &str,
            text: &str,
            timeout: Duration,
        ) -> String {
            let until = Instant::now() + timeout;
            loop {
                let left = until.saturating_duration_since(Instant::now());
                match lines.recv_timeout(left) {
                    Ok(line) if line.contains(text) => return line,
                    Ok(_) => {}
                    Err(_) => panic!(
                        "no {text:?} on hwfoc's {what} within {timeout:?}; standard output:\n{}\n\
                         standard error:\n{}",
                        self.stdout(),
                        self.stderr()
                    ),
                }
            }
        }

        /// Waits for a line of standard error containing `text`.
        pub fn wait_for(&self, text: &str, timeout: Duration) -> String {
            self.wait_on(&self.err_lines, "standard error", text, timeout)
        }

        /// Waits for a line of standard output containing `text` (lines before it are passed over).
        pub fn wait_for_stdout(&self, text: &str, timeout: Duration) -> String {
            self.wait_on(&self.out_lines, "standard output", text, timeout)
        }

        pub fn stderr(&self) -> String {
            self.stderr.lock().unwrap().join("\n")
        }

        pub fn stdout(&self) -> String {
            self.stdout.lock().unwrap().join("\n")
        }

        pub fn signal(&self, signal: Signal) {
            kill(Pid::from_raw(self.child.id() as i32), signal).unwrap();
        }

        /// Waits for the process to end (at most `timeout`); returns whether it succeeded.
        pub fn wait(&mut self, timeout: Duration) -> bool {
            let until = Instant::now() + timeout;
            loop {
                if let Some(status) = self.child.try_wait().unwrap() {
                    // Let the reader threads take the last lines.
                    thread::sleep(Duration::from_millis(50));
                    return status.success();
                }
                if Instant::now() > until {
                    let _ = self.child.kill();
                    panic!("hwfoc did not end within {timeout:?}:\n{}", self.stderr());
                }
                thread::sleep(Duration::from_millis(20));
            }
        }
    }

    impl Drop for Running {
        /// A test that fails half-way leaves no `hwfoc` running behind it.
        fn drop(&mut self) {
            if self.child.try_wait().ok().flatten().is_none() {
                let _ = self.child.kill();
                let _ = self.child.wait();
            }
        }
    }
}

/// The one skip policy: a test that needs `what` (a tool, another user) is
/// `#[ignore = "needs …"]`, so that a plain `cargo test` lists it as ignored (never as passed),
/// and `.ci/run` (or the script its reason names) runs it with `--ignored` where the tool is
/// installed. Such a test starts with this: where `what` is missing, it fails, saying so.
pub fn need(available: bool, what: &str) {
    assert!(
        available,
        "needs {what}: install it (as .ci/run does) or leave this ignored test unrun"
    );
}

/// Whether tshark runs here.
pub fn tshark_found() -> bool {
    tshark()
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// [`need`] tshark (Debian: `apt-get install tshark`).
pub fn need_tshark() {
    need(tshark_found(), "tshark");
}

/// `hwfoc` as the user `nobody` when the tests run as root (root may write and open anything,
/// so permission errors can only be seen as another user); as the user itself otherwise.
#[cfg(unix)]
pub fn hwfoc_unprivileged() -> Command {
    use std::os::unix::process::CommandExt;
    let mut cmd = hwfoc();
    if nix::unistd::geteuid().is_root() {
        cmd.uid(65534).gid(65534);
    }
    cmd
}

/// `tshark`, kept from the user's Wireshark set-up: a home, configuration directory and plugin
/// directories of its own (empty), so that a dissector the user installed (the README's
/// `hwfoc wireshark install`) or their preferences never change what a test sees. A test that
/// wants the dissector passes it explicitly (`-X lua_script:…`).
pub fn tshark() -> Command {
    static HOME: std::sync::OnceLock<tempfile::TempDir> = std::sync::OnceLock::new();
    let home = HOME.get_or_init(|| tempfile::tempdir().unwrap()).path();
    let mut cmd = Command::new("tshark");
    cmd.env("HOME", home)
        .env("XDG_CONFIG_HOME", home.join(".config"))
        .env("WIRESHARK_CONFIG_DIR", home.join("wireshark"))
        .env_remove("WIRESHARK_PLUGIN_DIR")
        .env_remove("WIRESHARK_EXTCAP_DIR");
    cmd
}

/// A golden file of `tests/golden`.
pub fn golden(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(name)
}

/// Compares `actual` with the golden file `name`; `UPDATE_GOLDEN=1` rewrites it instead.
pub fn check_golden(name: &str, actual: &str) {
    let path = golden(name);
    if std::env::var_os("UPDATE_GOLDEN").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, actual).unwrap();
    }
    let expected = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (run with UPDATE_GOLDEN=1)", path.display()));
    assert!(
        expected == actual,
        "{name} differs from the golden file {}",
        path.display()
    );
}
