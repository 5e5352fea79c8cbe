//! A progress bar for runs that take more than about a second.
//!
//! The bar (on standard error) stays hidden for the first second of a run, so quick runs
//! print nothing extra; it is never shown with `--quiet` or when standard output is not a
//! terminal (output piped or redirected), and it is cleared when the run ends.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// How long a run goes before its progress bar appears.
const SHOW_AFTER: Duration = Duration::from_secs(1);

/// Resolution of the bar (positions per run).
const STEPS: u64 = 1000;

/// Progress of one run in simulated time.
pub struct Progress {
    bar: Option<ProgressBar>,
    start: Instant,
    shown: bool,
    t0: f64,
    t_end: f64,
}

impl Progress {
    /// A bar for a run from `t0` to `t_end`, drawn only if `enabled`, standard output is a
    /// terminal and the run lasts long enough.
    pub fn new(label: &str, t0: f64, t_end: f64, enabled: bool) -> Self {
        let bar = (enabled && std::io::stdout().is_terminal()).then(|| {
            let style = ProgressStyle::with_template(
                "{prefix} [{bar:40.cyan/blue}] {msg} ({elapsed}, about {eta} left)",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
            ProgressBar::with_draw_target(Some(STEPS), ProgressDrawTarget::hidden())
                .with_style(style)
                .with_prefix(label.to_string())
        });
        Progress {
            bar,
            start: Instant::now(),
            shown: false,
            t0,
            t_end,
        }
    }

    /// Reports that the simulation has reached time `t`.
    pub fn update(&mut self, t: f64) {
        let Some(bar) = &self.bar else {
            return;
        };
        if !self.shown {
            if self.start.elapsed() < SHOW_AFTER {
                return;
            }
            bar.set_draw_target(ProgressDrawTarget::stderr());
            self.shown = true;
        }
        let span = self.t_end - self.t0;
        let fraction = if span > 0.0 {
            ((t - self.t0) / span).clamp(0.0, 1.0)
        } else {
            1.0
        };
        bar.set_position((fraction * STEPS as f64).round() as u64);
        bar.set_message(format!("t = {t:.3} of {} s", self.t_end));
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
