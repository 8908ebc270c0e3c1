//! What the subscriber received over the run, and the summary lines both modes print at the end:
//!
//! ```text
//! ---- summary after 10.0 s ----
//! wrote    200 samples (2 colors at 10 Hz)
//! received 196 samples [BLUE: 98, RED: 98]
//! latency  mean 152 us, max 1210 us
//! ```

use std::collections::BTreeMap;
use std::time::Duration;

/// Counts of received samples, per colour, and their latencies.
#[derive(Debug, Default, Clone)]
pub struct Tally {
    /// Samples received.
    pub samples: u64,
    per_color: BTreeMap<String, u64>,
    latency_sum: Duration,
    latency_max: Duration,
}

/// What the summary reports about the publishing side.
#[derive(Debug, Clone, Copy)]
pub struct WrittenSummary {
    /// Samples written.
    pub written: u64,
    /// Shapes published.
    pub shapes: usize,
    /// Samples per second and shape.
    pub rate_hz: f64,
}

impl Tally {
    /// Counts one sample of `color` with its latency.
    pub fn record(&mut self, color: &str, latency: Duration) {
        self.samples += 1;
        *self.per_color.entry(color.to_string()).or_default() += 1;
        self.latency_sum += latency;
        self.latency_max = self.latency_max.max(latency);
    }

    /// The summary lines; the publishing line with `written`, the receiving lines when `subscribed`.
    pub fn summary(
        &self,
        elapsed: Duration,
        written: Option<WrittenSummary>,
        subscribed: bool,
    ) -> Vec<String> {
        let mut out = vec![format!(
            "---- summary after {:.1} s ----",
            elapsed.as_secs_f64()
        )];
        if let Some(w) = written {
            out.push(format!(
                "wrote    {} samples ({} colors at {} Hz)",
                w.written, w.shapes, w.rate_hz
            ));
        }
        if subscribed {
            let mean = if self.samples > 0 {
                self.latency_sum.as_secs_f64() * 1e6 / self.samples as f64
            } else {
                0.0
            };
            let colors: Vec<String> = self
                .per_color
                .iter()
                .map(|(c, n)| format!("{c}: {n}"))
                .collect();
            out.push(format!(
                "received {} samples [{}]",
                self.samples,
                colors.join(", ")
            ));
            out.push(format!(
                "latency  mean {mean:.0} us, max {:.0} us",
                self.latency_max.as_secs_f64() * 1e6
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_lines() {
        let mut t = Tally::default();
        t.record("RED", Duration::from_micros(100));
        t.record("BLUE", Duration::from_micros(300));
        let w = WrittenSummary {
            written: 4,
            shapes: 2,
            rate_hz: 10.0,
        };
        assert_eq!(
            t.summary(Duration::from_secs(3), Some(w), true),
            [
                "---- summary after 3.0 s ----",
                "wrote    4 samples (2 colors at 10 Hz)",
                "received 2 samples [BLUE: 1, RED: 1]",
                "latency  mean 200 us, max 300 us",
            ]
        );
    }
}
