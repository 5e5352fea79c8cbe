//! Progress of a sweep, in runs: on a terminal a bar with the runs done, the failures and
//! the time left (shown after a second); without one (a batch job's log) a line every 10 s;
//! neither with `--quiet`. The same conventions as a single run's progress.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

/// How long a sweep goes before its bar appears.
const SHOW_AFTER: Duration = Duration::from_secs(1);

/// Without a terminal: one line per this interval.
const LINE_EVERY: Duration = Duration::from_secs(10);

enum Display {
    None,
    Bar { bar: ProgressBar, shown: bool },
    Lines { next: Duration },
}

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
        let display = if !enabled {
            Display::None
        } else if std::io::stderr().is_terminal() {
            let style = ProgressStyle::with_template(
                "{prefix} [{bar:40.cyan/blue}] {pos}/{len} runs, {msg} ({elapsed}, about {eta} left)",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
            let bar =
                ProgressBar::with_draw_target(Some(total as u64), ProgressDrawTarget::hidden())
                    .with_style(style)
                    .with_prefix(label.to_string());
            Display::Bar { bar, shown: false }
        } else {
            Display::Lines { next: LINE_EVERY }
        };
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
        match &mut self.display {
            Display::None => {}
            Display::Bar { bar, shown } => {
                if !*shown {
                    if elapsed < SHOW_AFTER {
                        return;
                    }
                    bar.set_draw_target(ProgressDrawTarget::stderr());
                    *shown = true;
                }
                bar.set_position(done as u64);
                bar.set_message(format!("{failed} failed"));
            }
            Display::Lines { next } => {
                if elapsed < *next {
                    return;
                }
                *next = elapsed + LINE_EVERY;
                let line = line(&self.label, done, self.total, failed, elapsed);
                let _ = writeln!(std::io::stderr(), "{line}");
            }
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        if let Display::Bar { bar, .. } = &self.display {
            bar.finish_and_clear();
        }
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
