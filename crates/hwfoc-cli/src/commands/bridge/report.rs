//! What the bridge says: each output failure as it happens (once per kind of failure and ten
//! seconds, so a ground station that is not running does not flood the terminal), and its
//! counters at the end.

use std::collections::HashMap;
use std::time::{Duration, Instant};

use hwfoc_bridge::OutputError;
use hwfoc_bridge::fanout::Fanout;
use hwfoc_bridge::output::{esc_list, left_out};
use hwfoc_io::Escaped;

/// How long the same failure message is not repeated.
const REPEAT_AFTER: Duration = Duration::from_secs(10);

/// Output failures seen, by message.
pub struct Errors {
    quiet: bool,
    /// When each message was last printed, and how often it happened since.
    seen: HashMap<String, (Instant, u64)>,
}

impl Errors {
    /// No failure yet; `quiet` prints none while running.
    pub fn new(quiet: bool) -> Errors {
        Errors {
            quiet,
            seen: HashMap::new(),
        }
    }

    /// A failure: printed unless the same message was printed in the last ten seconds.
    pub fn report(&mut self, error: &OutputError) {
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
}

/// Prints the counters of every output (standard error: standard output may be a pipe to
/// something else).
pub fn print(fanout: &Fanout, ran: Duration) {
    eprint!("{}", counters(fanout, ran));
}

/// The counters of every output, and their total failures: the sum of what each output
/// counts ([`hwfoc_bridge::output::OutputStats::errors`]).
fn counters(fanout: &Fanout, ran: Duration) -> String {
    let failures: u64 = fanout.outputs().iter().map(|o| o.stats().errors).sum();
    let escs = fanout.escs();
    let mut text = format!(
        "hwfoc bridge: {:.1} s, {} frames of {} ESC{}{}, {} output failure{}\n",
        ran.as_secs_f64(),
        fanout.frames(),
        escs.len(),
        if escs.len() == 1 { "" } else { "s" },
        match escs.is_empty() {
            true => String::new(),
            false => format!(" ({})", esc_list(escs)),
        },
        failures,
        if failures == 1 { "" } else { "s" },
    );
    for output in fanout.outputs() {
        let s = output.stats();
        let ms = |p: f64| {
            s.latency.percentile(p).map_or("-".to_string(), |d| {
                format!("{:.2} ms", d.as_secs_f64() * 1e3)
            })
        };
        text += &format!(
            "  {}: {} messages, {} bytes, {} failed, {} superseded, latency median {}, p99 {}\n",
            Escaped(output.name()),
            s.messages,
            s.bytes,
            s.errors,
            s.superseded,
            ms(50.0),
            ms(99.0),
        );
        if let Some(left_out) = left_out(output.as_ref()) {
            text += &format!("  {}\n", Escaped(left_out));
        }
    }
    text
}

/// The first output that left ESCs out (each is in the report), as the bridge's error: output
/// was lost.
pub fn not_carried(fanout: &Fanout) -> Option<OutputError> {
    fanout.outputs().iter().find_map(|o| left_out(o.as_ref()))
}

#[cfg(test)]
mod tests {
    use super::*;

    use hwfoc_bridge::output::{Output, OutputError, OutputStats, Update};

    /// An output whose sends all failed, `failed` times, of which poll reported one.
    struct Failing {
        stats: OutputStats,
    }

    impl Output for Failing {
        fn name(&self) -> &str {
            "failing"
        }
        fn update(&mut self, _: &Update<'_>) {}
        fn poll(&mut self, _: Instant) -> Result<(), OutputError> {
            Err(OutputError::Send {
                output: "failing".into(),
                reason: "refused".into(),
            })
        }
        fn stats(&self) -> &OutputStats {
            &self.stats
        }
        fn carries(&self) -> usize {
            8
        }
    }

    #[test]
    fn the_total_is_the_sum_of_the_outputs_failures() {
        let failing = |errors| -> Box<dyn Output> {
            Box::new(Failing {
                stats: OutputStats {
                    errors,
                    ..OutputStats::default()
                },
            })
        };
        let mut fanout = Fanout::new(vec![failing(5951), failing(11903)]);
        let mut errors = Errors::new(true);
        fanout.poll(Instant::now(), |e| errors.report(&e));
        let text = counters(&fanout, Duration::from_secs(10));
        let first = text.lines().next().unwrap();
        assert!(first.ends_with(", 17854 output failures"), "{text}");
        assert!(text.contains(" 5951 failed") && text.contains(" 11903 failed"));
    }
}
