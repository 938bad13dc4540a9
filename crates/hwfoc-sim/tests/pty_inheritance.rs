//! A pseudo-terminal is not inherited by the programs this process starts.
//!
//! A test binary of its own: starting a program forks, and until it execs the child holds every
//! descriptor of this process for a moment, close-on-exec or not; a pty test running beside it
//! would see its slave held open.
#![cfg(target_os = "linux")]

use std::fs::File;
use std::io::Write;
use std::os::fd::AsFd;

use hwfoc_sim::pty::RawPair;
use nix::fcntl::{FcntlArg, FdFlag, fcntl};

/// Closing our master hangs the slave up at once though a program started meanwhile still
/// runs (with `openpty`'s inheritable master the child kept the terminal alive, and a write to
/// the slave went on succeeding: a bridge never noticed its adapter was gone).
#[test]
fn a_started_program_does_not_inherit_the_pair() {
    let pair = RawPair::open().unwrap();
    for fd in [pair.master.as_fd(), pair.slave.as_fd()] {
        let flags = FdFlag::from_bits_truncate(fcntl(fd, FcntlArg::F_GETFD).unwrap());
        assert!(flags.contains(FdFlag::FD_CLOEXEC));
    }
    let mut child = std::process::Command::new("sleep")
        .arg("5")
        .spawn()
        .unwrap();
    // Past the child's exec: /proc shows its program once it has exec'd.
    let comm = format!("/proc/{}/comm", child.id());
    for _ in 0..200 {
        if std::fs::read_to_string(&comm).is_ok_and(|c| c.trim() == "sleep") {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let RawPair { master, slave, .. } = pair;
    drop(master);
    let mut slave = File::from(slave);
    let written = slave.write(b"x");
    let _ = child.kill();
    let _ = child.wait();
    let err = written.expect_err("the slave was not hung up");
    assert_eq!(err.raw_os_error(), Some(nix::libc::EIO), "{err}");
}
