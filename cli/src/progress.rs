//! Progress of a run that takes a while.
//!
//! On a terminal, a bar (on standard error) that stays hidden for the first second, so quick
//! runs print nothing extra, and is cleared when the run ends. Without a terminal (output
//! piped or redirected, a batch job), a short line on standard error every 10 s once the run
//! has lasted 10 s, so that a log shows that a long run is alive and how far it is. Neither
//! with `--quiet`.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

/// How long a run goes before its progress bar appears.
const SHOW_AFTER: Duration = Duration::from_secs(1);

/// Without a terminal: the first progress line, and then one line per this interval.
const LINE_EVERY: Duration = Duration::from_secs(10);

/// Resolution of the bar (positions per run).
const STEPS: u64 = 1000;

/// How progress is shown: shared by a run's progress (in simulated time) and a sweep's (in
/// runs).
pub enum Display {
    /// Nothing (`--quiet`).
    None,
    /// A bar on a terminal, drawn once the work has lasted [`SHOW_AFTER`].
    Bar {
        /// The bar (hidden until shown).
        bar: ProgressBar,
        /// Drawn yet.
        shown: bool,
    },
    /// A line now and then on standard error; `next` is when the next one is due.
    Lines {
        /// When the next line is due.
        next: Duration,
    },
}

impl Display {
    /// Nothing unless `enabled`; a bar of `length` positions in the `template` style when
    /// `terminal`, else occasional lines.
    pub fn new(enabled: bool, terminal: bool, template: &str, length: u64, prefix: &str) -> Self {
        if !enabled {
            return Display::None;
        }
        if !terminal {
            return Display::Lines { next: LINE_EVERY };
        }
        let style = ProgressStyle::with_template(template)
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        let bar = ProgressBar::with_draw_target(Some(length), ProgressDrawTarget::hidden())
            .with_style(style)
            .with_prefix(prefix.to_string());
        Display::Bar { bar, shown: false }
    }

    /// Reports progress `elapsed` into the work: the bar at `position` with `message`, or,
    /// when one is due, the line `line()`.
    pub fn tick(
        &mut self,
        elapsed: Duration,
        position: u64,
        message: impl FnOnce() -> String,
        line: impl FnOnce() -> String,
    ) {
        match self {
            Display::None => {}
            Display::Bar { bar, shown } => {
                if !*shown {
                    if elapsed < SHOW_AFTER {
                        return;
                    }
                    bar.set_draw_target(ProgressDrawTarget::stderr());
                    *shown = true;
                }
                bar.set_position(position);
                bar.set_message(message());
            }
            Display::Lines { next } => {
                if elapsed < *next {
                    return;
                }
                *next = elapsed + LINE_EVERY;
                // A closed standard error is no reason to stop the work.
                let _ = writeln!(std::io::stderr(), "{}", line());
            }
        }
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        if let Display::Bar { bar, .. } = self {
            bar.finish_and_clear();
        }
    }
}

/// Progress of one run in simulated time.
pub struct Progress {
    display: Display,
    label: String,
    start: Instant,
    t0: f64,
    t_end: f64,
}

impl Progress {
    /// Progress of a run from `t0` to `t_end`, shown only if `enabled`: as a bar when
    /// standard output is a terminal, else as occasional lines.
    pub fn new(label: &str, t0: f64, t_end: f64, enabled: bool) -> Self {
        let display = Display::new(
            enabled,
            std::io::stdout().is_terminal(),
            "{prefix} [{bar:40.cyan/blue}] {msg} ({elapsed}, about {eta} left)",
            STEPS,
            label,
        );
        Progress {
            display,
            label: label.to_string(),
            start: Instant::now(),
            t0,
            t_end,
        }
    }

    /// The fraction of the run done at simulated time `t`.
    fn fraction(&self, t: f64) -> f64 {
        let span = self.t_end - self.t0;
        if span > 0.0 {
            ((t - self.t0) / span).clamp(0.0, 1.0)
        } else {
            1.0
        }
    }

    /// Reports that the simulation has reached time `t` (an output time).
    pub fn update(&mut self, t: f64) {
        self.update_step(t, f64::NAN);
    }

    /// Reports that a step of size `h` has reached time `t`: between outputs too, so that a
    /// run whose steps crawl still shows where it is and how short its steps are.
    pub fn update_step(&mut self, t: f64, h: f64) {
        let elapsed = self.start.elapsed();
        let fraction = self.fraction(t);
        let t_end = self.t_end;
        let label = &self.label;
        self.display.tick(
            elapsed,
            (fraction * STEPS as f64).round() as u64,
            || format!("t = {t:.3} of {t_end} s"),
            || progress_line(label, (t, h), t_end, fraction, elapsed),
        );
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        self.display.finish();
    }
}

/// `paper_concave: t = 523.4 of 1000 s (52 %), 12 s so far, about 11 s left; steps of
/// 2.1e-3 s` (the step when known).
fn progress_line(
    label: &str,
    (t, h): (f64, f64),
    t_end: f64,
    fraction: f64,
    elapsed: Duration,
) -> String {
    let spent = elapsed.as_secs_f64();
    let left = if fraction > 0.0 {
        format!(", about {:.0} s left", spent * (1.0 - fraction) / fraction)
    } else {
        String::new()
    };
    let step = if h.is_finite() && h > 0.0 {
        format!("; steps of {h:.1e} s")
    } else {
        String::new()
    };
    format!(
        "{label}: t = {t:.4} of {t_end} s ({:.0} %), {spent:.0} s so far{left}{step}",
        100.0 * fraction
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_progress_line_says_where_the_run_is_and_how_long_it_has_left() {
        let line = progress_line(
            "m",
            (250.0, f64::NAN),
            1000.0,
            0.25,
            Duration::from_secs(10),
        );
        assert_eq!(
            line,
            "m: t = 250.0000 of 1000 s (25 %), 10 s so far, about 30 s left"
        );
        let start = progress_line("m", (0.0, 2.1e-11), 10.0, 0.0, Duration::from_secs(10));
        assert_eq!(
            start,
            "m: t = 0.0000 of 10 s (0 %), 10 s so far; steps of 2.1e-11 s"
        );
    }
}
