//! The library installs no signal handler: a program embedding it (a Python interpreter, a
//! GUI) keeps Ctrl-C's and SIGTERM's dispositions as it set them. This file is a test binary
//! of its own, so that no other test of the crate has changed them beforehand.

#![cfg(unix)]

use std::os::fd::AsFd;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use hwfoc_io::{Input, OpenInput};

/// `signal`'s action: `SIG_DFL`, `SIG_IGN` (as a launcher without job control leaves SIGINT
/// in a background job) or a handler's address.
fn action(signal: libc::c_int) -> libc::sighandler_t {
    // SAFETY: a null new action only reads the current one into `old`, which is plain data.
    unsafe {
        let mut old: libc::sigaction = std::mem::zeroed();
        assert_eq!(libc::sigaction(signal, std::ptr::null(), &mut old), 0);
        old.sa_sigaction
    }
}

#[test]
fn reading_ports_leaves_sigint_and_sigterm_as_they_were() {
    let before = [action(libc::SIGTERM), action(libc::SIGINT)];
    // No handler of anyone's: the actions a process starts with.
    assert!(
        before
            .iter()
            .all(|&a| a == libc::SIG_DFL || a == libc::SIG_IGN)
    );
    let pty = nix::pty::openpty(None, None).unwrap();
    let name = nix::unistd::ttyname(pty.slave.as_fd()).unwrap();
    let names = [name.to_string_lossy().into_owned()];
    let stop = Arc::new(AtomicBool::new(false));
    let mut input = Input::open_ports(&names, 19200, Arc::clone(&stop)).unwrap();
    assert_eq!(
        action(libc::SIGTERM),
        before[0],
        "SIGTERM's action was changed"
    );
    assert_eq!(
        action(libc::SIGINT),
        before[1],
        "SIGINT's action was changed"
    );
    // The flag passed in ends the reading.
    stop.store(true, Ordering::Relaxed);
    assert!(input.next_batch().unwrap().is_none());
}
