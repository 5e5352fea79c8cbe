//! Progress of a sweep, in runs: on a terminal a bar with the runs done, the failures and
//! the time left (shown after a second); without one (a batch job's log) a line every 10 s;
//! neither with `--quiet`. The display is a single run's ([`crate::progress::Display`]).

use crate::progress::Display;
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// Progress of a sweep of `total` runs.
pub struct Progress {
    display: Display,
    label: String,
    start: Instant,
    total: usize,
}

impl Progress {
    /// Progress shown only if `enabled`; a bar when standard error is a terminal.
    pub fn new(label: &str, total: usize, enabled: bool) -> Self {
        let display = Display::new(
            enabled,
            std::io::stderr().is_terminal(),
            "{prefix} [{bar:40.cyan/blue}] {pos}/{len} runs, {msg} ({elapsed}, about {eta} left)",
            total as u64,
            label,
        );
        Progress {
            display,
            label: label.to_string(),
            start: Instant::now(),
            total,
        }
    }

    /// `done` runs written, `failed` of them failed.
    pub fn update(&mut self, done: usize, failed: usize) {
        let elapsed = self.start.elapsed();
        let (label, total) = (&self.label, self.total);
        self.display.tick(
            elapsed,
            done as u64,
            || format!("{failed} failed"),
            || line(label, done, total, failed, elapsed),
        );
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.display.finish();
    }
}

/// `paper_concave sweep: 5200 of 21000 runs (25 %), 3 failed, 10 s so far, about 30 s left`.
fn line(label: &str, done: usize, total: usize, failed: usize, elapsed: Duration) -> String {
    let spent = elapsed.as_secs_f64();
    let fraction = if total > 0 {
        done as f64 / total as f64
    } else {
        1.0
    };
    let left = if done > 0 {
        format!(", about {:.0} s left", spent * (1.0 - fraction) / fraction)
    } else {
        String::new()
    };
    format!(
        "{label}: {done} of {total} runs ({:.0} %), {failed} failed, {spent:.0} s so far{left}",
        100.0 * fraction
    )
}

#[cfg(test)]
mod tests {
    use super::line;
    use std::time::Duration;

    #[test]
    fn a_line_says_how_far_the_sweep_is_and_how_long_it_has_left() {
        assert_eq!(
            line("s", 250, 1000, 3, Duration::from_secs(10)),
            "s: 250 of 1000 runs (25 %), 3 failed, 10 s so far, about 30 s left"
        );
        assert_eq!(
            line("s", 0, 10, 0, Duration::from_secs(10)),
            "s: 0 of 10 runs (0 %), 0 failed, 10 s so far"
        );
    }
}
