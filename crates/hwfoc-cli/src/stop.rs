//! Stopping cleanly: Ctrl-C and SIGTERM ask every loop of the command to end, rather than
//! ending the process.
//!
//! The libraries install no signal handler: they take a stop flag from their caller
//! (`Input::open_ports`, `Export::stop_on`, the simulator's and the bridge's loops). The
//! command installs the handlers here, on first use, so that a command that never waits keeps
//! the signals' default action, and hands the flag down.

use std::sync::atomic::AtomicBool;
use std::sync::{Arc, OnceLock};

/// The process-wide flag set by Ctrl-C (SIGINT) or SIGTERM. The first call installs the
/// handlers; from then on those signals no longer end the process at once but ask the command
/// to stop cleanly, except that a second signal while the flag is set ends it immediately.
/// If the handlers cannot be installed, the signals keep their default action.
pub fn interrupted() -> Arc<AtomicBool> {
    static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();
    FLAG.get_or_init(|| {
        let flag = Arc::new(AtomicBool::new(false));
        for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            // Order matters: the conditional shutdown sees the flag as it was before this signal.
            let _ =
                signal_hook::flag::register_conditional_shutdown(signal, 130, Arc::clone(&flag));
            let _ = signal_hook::flag::register(signal, Arc::clone(&flag));
        }
        flag
    })
    .clone()
}
