//! How long frames take to cross a bridge: from the read that completed an ESC frame to the
//! write of the message carrying it.

use std::time::Duration;

use hdrhistogram::Histogram;

/// The longest latency kept exactly (longer ones are counted at this value): 60 s.
const MAX_US: u64 = 60_000_000;

/// Latencies of one output, in microseconds, in bounded memory (a histogram with 3 significant
/// digits: a percentile is exact to 0.1 %).
#[derive(Debug, Clone)]
pub struct Latency {
    histogram: Histogram<u64>,
}

impl Default for Latency {
    fn default() -> Self {
        Latency::new()
    }
}

impl Latency {
    /// No latency measured.
    pub fn new() -> Latency {
        Latency {
            // 1 us to 60 s at 3 significant digits: the bounds are valid, so this cannot fail.
            histogram: Histogram::new_with_bounds(1, MAX_US, 3).expect("valid histogram bounds"),
        }
    }

    /// Adds one measurement.
    pub fn add(&mut self, latency: Duration) {
        let us = u64::try_from(latency.as_micros()).unwrap_or(MAX_US);
        self.histogram.saturating_record(us.clamp(1, MAX_US));
    }

    /// How many measurements.
    pub fn count(&self) -> u64 {
        self.histogram.len()
    }

    /// The latency below which `percent` % of the measurements fall (`None` before any).
    pub fn percentile(&self, percent: f64) -> Option<Duration> {
        (!self.histogram.is_empty())
            .then(|| Duration::from_micros(self.histogram.value_at_percentile(percent)))
    }

    /// Adds another output's measurements to these.
    pub fn merge(&mut self, other: &Latency) {
        // Both have the same bounds: adding cannot fail.
        let _ = self.histogram.add(&other.histogram);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_of_known_latencies() {
        let mut l = Latency::new();
        assert_eq!(l.percentile(50.0), None);
        for us in 1..=1000u64 {
            l.add(Duration::from_micros(us * 10));
        }
        assert_eq!(l.count(), 1000);
        let median = l.percentile(50.0).unwrap().as_micros() as f64;
        assert!((median - 5000.0).abs() <= 5.0, "{median}");
        let p99 = l.percentile(99.0).unwrap().as_micros() as f64;
        assert!((p99 - 9900.0).abs() <= 10.0, "{p99}");
        let mut both = Latency::new();
        both.merge(&l);
        both.merge(&l);
        assert_eq!(both.count(), 2000);
        l.add(Duration::from_secs(3600));
        assert_eq!(l.percentile(100.0).unwrap().as_secs(), 60);
    }
}
