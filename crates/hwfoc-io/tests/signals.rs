//! The library installs no signal handler: a program embedding it (a Python interpreter, a
//! GUI) keeps Ctrl-C's and SIGTERM's dispositions as it set them. This file is a test binary
//! of its own, so that no other test of the crate has changed them beforehand.

#![cfg(unix)]

use std::os::fd::AsFd;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use hwfoc_io::{Input, OpenInput};

/// Whether `signal`'s action is still the default one.
fn is_default(signal: libc::c_int) -> bool {
    // SAFETY: a null new action only reads the current one into `old`, which is plain data.
    unsafe {
        let mut old: libc::sigaction = std::mem::zeroed();
        assert_eq!(libc::sigaction(signal, std::ptr::null(), &mut old), 0);
        old.sa_sigaction == libc::SIG_DFL
    }
}

#[test]
fn reading_ports_leaves_sigint_and_sigterm_at_their_default() {
    assert!(is_default(libc::SIGTERM) && is_default(libc::SIGINT));
    let pty = nix::pty::openpty(None, None).unwrap();
    let name = nix::unistd::ttyname(pty.slave.as_fd()).unwrap();
    let names = [name.to_string_lossy().into_owned()];
    let stop = Arc::new(AtomicBool::new(false));
    let mut input = Input::open_ports(&names, 19200, Arc::clone(&stop)).unwrap();
    assert!(is_default(libc::SIGTERM), "SIGTERM's action was changed");
    assert!(is_default(libc::SIGINT), "SIGINT's action was changed");
    // The flag passed in ends the reading.
    stop.store(true, Ordering::Relaxed);
    assert!(input.next_batch().unwrap().is_none());
}
