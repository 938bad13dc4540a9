//! How the monitor itself performs: redraws, the delay from bytes received to the screen, and
//! the CPU time it used (`--stats`).

use std::time::{Duration, Instant};

/// Delays are counted in 1 ms buckets up to this many (longer ones in the last bucket).
const BUCKETS: usize = 1000;

/// Counters kept while the monitor runs; bounded memory however long it runs.
#[derive(Debug, Clone)]
pub struct Perf {
    started: Instant,
    /// When the oldest frame not yet on the screen arrived.
    pending: Option<Instant>,
    draws: u64,
    draw_time: Duration,
    latency_ms: Vec<u64>,
    latencies: u64,
    latency_sum: Duration,
}

impl Perf {
    /// Counting from now.
    pub fn new() -> Perf {
        Perf {
            started: Instant::now(),
            pending: None,
            draws: 0,
            draw_time: Duration::ZERO,
            latency_ms: vec![0; BUCKETS],
            latencies: 0,
            latency_sum: Duration::ZERO,
        }
    }

    /// A frame arrived at `at` (the moment its bytes were taken in).
    pub fn arrived(&mut self, at: Instant) {
        self.pending.get_or_insert(at);
    }

    /// Whether frames are waiting to be shown.
    pub fn has_pending(&self) -> bool {
        self.pending.is_some()
    }

    /// A redraw that started at `start` reached the terminal at `done`; the frames waiting
    /// since before `start` are now on the screen.
    pub fn drawn(&mut self, start: Instant, done: Instant) {
        self.draws += 1;
        self.draw_time += done.saturating_duration_since(start);
        if let Some(since) = self.pending.take_if(|since| *since <= start) {
            let delay = done.saturating_duration_since(since);
            let bucket = (delay.as_millis() as usize).min(BUCKETS - 1);
            self.latency_ms[bucket] += 1;
            self.latencies += 1;
            self.latency_sum += delay;
        }
    }

    /// The delay, in ms, that `fraction` of the frames shown beat (the upper edge of its 1 ms
    /// bucket).
    pub fn latency_percentile_ms(&self, fraction: f64) -> Option<u64> {
        if self.latencies == 0 {
            return None;
        }
        let want = (fraction * self.latencies as f64).ceil().max(1.0) as u64;
        let mut seen = 0;
        for (ms, &n) in self.latency_ms.iter().enumerate() {
            seen += n;
            if seen >= want {
                return Some(ms as u64 + 1);
            }
        }
        Some(BUCKETS as u64)
    }

    /// One line for `--stats`.
    pub fn report(&self, frames: u64) -> String {
        let elapsed = self.started.elapsed().as_secs_f64();
        let (user, system) = cpu_time();
        let cpu = user + system;
        let mut line = format!(
            "monitor ran {elapsed:.1} s: {frames} frames; CPU {:.2} % of one core (user {user:.2} s, \
             system {system:.2} s)",
            100.0 * cpu / elapsed.max(1e-9)
        );
        if self.draws > 0 {
            line.push_str(&format!(
                "; {} redraws, {:.2} ms each on average",
                self.draws,
                self.draw_time.as_secs_f64() * 1e3 / self.draws as f64
            ));
        }
        if let (Some(p50), Some(p99), Some(max)) = (
            self.latency_percentile_ms(0.5),
            self.latency_percentile_ms(0.99),
            self.latency_percentile_ms(1.0),
        ) {
            line.push_str(&format!(
                "; received to on screen: mean {:.1} ms, median under {p50} ms, 99 % under \
                 {p99} ms, all under {max} ms",
                self.latency_sum.as_secs_f64() * 1e3 / self.latencies as f64
            ));
        }
        line
    }
}

impl Default for Perf {
    fn default() -> Self {
        Perf::new()
    }
}

/// User and system CPU seconds of this process so far.
#[cfg(unix)]
fn cpu_time() -> (f64, f64) {
    use nix::sys::resource::{UsageWho, getrusage};
    match getrusage(UsageWho::RUSAGE_SELF) {
        Ok(usage) => {
            let secs = |t: nix::sys::time::TimeVal| t.tv_sec() as f64 + t.tv_usec() as f64 * 1e-6;
            (secs(usage.user_time()), secs(usage.system_time()))
        }
        Err(_) => (0.0, 0.0),
    }
}

#[cfg(not(unix))]
fn cpu_time() -> (f64, f64) {
    (0.0, 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn latency_is_counted_from_the_oldest_frame_waiting() {
        let mut perf = Perf::new();
        let t0 = Instant::now();
        perf.arrived(t0);
        perf.arrived(t0 + Duration::from_millis(10));
        assert!(perf.has_pending());
        perf.drawn(
            t0 + Duration::from_millis(20),
            t0 + Duration::from_millis(25),
        );
        assert!(!perf.has_pending());
        // A frame arriving during a draw waits for the next one.
        perf.arrived(t0 + Duration::from_millis(40));
        perf.drawn(
            t0 + Duration::from_millis(35),
            t0 + Duration::from_millis(45),
        );
        assert!(perf.has_pending());
        perf.drawn(
            t0 + Duration::from_millis(50),
            t0 + Duration::from_millis(52),
        );
        assert_eq!(perf.latencies, 2);
        assert_eq!(perf.latency_percentile_ms(0.5), Some(13));
        assert_eq!(perf.latency_percentile_ms(1.0), Some(26));
        assert!(perf.report(2).contains("3 redraws"));
    }
}
