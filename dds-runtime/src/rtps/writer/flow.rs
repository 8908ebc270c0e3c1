//! Flow control's window: how many unacknowledged bytes a reliable writer may have in flight before `write`
//! is refused, and where a refused writer is released again.
//!
//! The configured watermarks suit small samples. For large ones a fixed byte window holds too few samples:
//! at 256 KiB, a 512 KiB high watermark let two samples out and then waited until both were acknowledged,
//! so the link idled for a round trip every two samples. The window therefore grows to hold at least
//! [`MIN_SAMPLES_IN_FLIGHT`] samples of the size last written (up to [`MAX_SCALED_WINDOW`]), and a writer
//! held back by a grown window is released at half of it, so that acknowledgements arrive while samples
//! are still in flight.

/// Samples a grown window holds.
const MIN_SAMPLES_IN_FLIGHT: usize = 4;

/// The window grows to at most this many bytes (the default socket buffers are 4 MiB).
const MAX_SCALED_WINDOW: usize = 4 << 20;

/// The watermarks in force for one writer.
#[derive(Debug, Clone, Copy)]
pub(super) struct Window {
    high: usize,
    low: usize,
    /// Size of the last sample written.
    sample: usize,
}

impl Window {
    pub(super) fn new(high: usize, low: usize) -> Self {
        Window {
            high,
            low,
            sample: 0,
        }
    }

    /// Records the size of a sample about to be written.
    pub(super) fn note(&mut self, len: usize) {
        self.sample = len;
    }

    /// Unacknowledged bytes beyond which a write is refused.
    pub(super) fn high(&self) -> usize {
        let scaled = self
            .sample
            .saturating_mul(MIN_SAMPLES_IN_FLIGHT)
            .min(MAX_SCALED_WINDOW);
        self.high.max(scaled)
    }

    /// Unacknowledged bytes at or below which a refused writer is released.
    pub(super) fn low(&self) -> usize {
        let high = self.high();
        if high > self.high {
            high / 2
        } else {
            self.low
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_samples_keep_the_configured_watermarks() {
        let mut w = Window::new(512 << 10, 128 << 10);
        w.note(1024);
        assert_eq!((w.high(), w.low()), (512 << 10, 128 << 10));
        w.note(64 << 10);
        assert_eq!((w.high(), w.low()), (512 << 10, 128 << 10));
    }

    #[test]
    fn large_samples_get_a_window_of_several_samples() {
        let mut w = Window::new(512 << 10, 128 << 10);
        w.note(256 << 10);
        assert_eq!((w.high(), w.low()), (1 << 20, 512 << 10));
        w.note(1 << 20);
        assert_eq!((w.high(), w.low()), (4 << 20, 2 << 20));
        w.note(64 << 20);
        assert_eq!(w.high(), MAX_SCALED_WINDOW);
    }
}
