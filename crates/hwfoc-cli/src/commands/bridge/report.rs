//! What the bridge says: each output failure as it happens (once per kind of failure and ten
//! seconds, so a ground station that is not running does not flood the terminal), and its
//! counters at the end.

use std::collections::HashMap;
use std::time::{Duration, Instant};

use hwfoc_bridge::OutputError;
use hwfoc_bridge::fanout::Fanout;
use hwfoc_io::escape::Escaped;

/// How long the same failure message is not repeated.
const REPEAT_AFTER: Duration = Duration::from_secs(10);

/// Output failures seen, by message.
pub struct Errors {
    quiet: bool,
    /// When each message was last printed, and how often it happened since.
    seen: HashMap<String, (Instant, u64)>,
    total: u64,
}

impl Errors {
    /// No failure yet; `quiet` prints none while running.
    pub fn new(quiet: bool) -> Errors {
        Errors {
            quiet,
            seen: HashMap::new(),
            total: 0,
        }
    }

    /// A failure: printed unless the same message was printed in the last ten seconds.
    pub fn report(&mut self, error: &OutputError) {
        self.total += 1;
        let message = Escaped(error).to_string();
        let now = Instant::now();
        let entry = self.seen.entry(message.clone()).or_insert((now, 0));
        let first = entry.1 == 0;
        entry.1 += 1;
        if self.quiet {
            return;
        }
        if first {
            eprintln!("hwfoc: {message}");
        } else if now.duration_since(entry.0) >= REPEAT_AFTER {
            eprintln!(
                "hwfoc: {message} ({} times in {:.0} s)",
                entry.1,
                now.duration_since(entry.0).as_secs_f64()
            );
            *entry = (now, 1);
        }
    }

    /// Failures in all.
    pub fn total(&self) -> u64 {
        self.total
    }
}

/// Prints the counters of every output (standard error: standard output may be a pipe to
/// something else).
pub fn print(fanout: &Fanout, errors: &Errors, ran: Duration) {
    eprintln!(
        "hwfoc bridge: {:.1} s, {} frames of {} ESC{}, {} output failure{}",
        ran.as_secs_f64(),
        fanout.frames(),
        fanout.escs(),
        if fanout.escs() == 1 { "" } else { "s" },
        errors.total(),
        if errors.total() == 1 { "" } else { "s" },
    );
    for output in fanout.outputs() {
        let s = output.stats();
        let ms = |p: f64| {
            s.latency.percentile(p).map_or("-".to_string(), |d| {
                format!("{:.2} ms", d.as_secs_f64() * 1e3)
            })
        };
        eprintln!(
            "  {}: {} messages, {} bytes, {} failed, {} superseded, latency median {}, p99 {}",
            Escaped(output.name()),
            s.messages,
            s.bytes,
            s.errors,
            s.superseded,
            ms(50.0),
            ms(99.0),
        );
    }
}
