//! What a run tells its caller while it goes, how the caller stops it, and how a run whose
//! steps no longer advance time is stopped with a diagnosis (docs/method.md §12).
//!
//! A [`Monitor`] sees every output sample as soon as it is computed and every accepted step;
//! either can stop the run ([`SimError::Interrupted`], with everything computed so far). A
//! signal handler or another thread stops a run through [`Cancel`], which the stepping loop
//! reads after every step: a run answers within one step, not at its next output time.
//!
//! A run stalls when its steps become so short that it cannot reach its next output time
//! within the step budget of an output interval ([`MAX_STEPS_PER_CALL`]). The watchdog
//! measures the pace of every [`STALL_WINDOW`] accepted steps and stops the run as soon as
//! that pace projects past the budget ([`SimError::Stalled`], naming the time, the step, the
//! tolerances and the likely cause), rather than after the ten million steps themselves.

use crate::error::SimError;
use crate::sample::Sample;
use crate::settings::MAX_STEPS_PER_CALL;
use std::sync::atomic::{AtomicBool, Ordering};

/// What an observer or a monitor tells the run after a sample or a step: go on, or stop
/// (the run then ends with [`SimError::Interrupted`] and what it computed so far).
pub type Observed = std::ops::ControlFlow<()>;

/// Where a run is after an accepted step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Time reached (s).
    pub t: f64,
    /// Size of the step just taken (s).
    pub h: f64,
    /// Accepted steps of this run (or of this phase of a one-sided run) so far.
    pub steps: usize,
}

/// Watches a run as it goes.
///
/// Both methods default to going on; a monitor implements what it needs. The stepping loop
/// calls [`Monitor::step`] after every accepted step, so a monitor that returns
/// `Observed::Break(())` there stops the run within one step.
pub trait Monitor {
    /// A sample at an output time, in time order, as soon as it is computed.
    fn sample(&mut self, sample: &Sample) -> Observed {
        let _ = sample;
        Observed::Continue(())
    }

    /// After every accepted step.
    fn step(&mut self, progress: &Progress) -> Observed {
        let _ = progress;
        Observed::Continue(())
    }
}

/// A monitor that watches nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Unmonitored;

impl Monitor for Unmonitored {}

/// A monitor that hands every sample to a closure (what [`crate::Simulate::simulate_observed`]
/// wraps its observer in).
pub struct OnSample<F>(pub F);

impl<F: FnMut(&Sample) -> Observed> Monitor for OnSample<F> {
    fn sample(&mut self, sample: &Sample) -> Observed {
        (self.0)(sample)
    }
}

/// A monitor that stops the run once `flag` is set, e.g. by a Ctrl-C or SIGTERM handler or
/// by the thread that cancels a sweep; read after every step.
#[derive(Debug, Clone, Copy)]
pub struct Cancel<'a>(pub &'a AtomicBool);

impl Cancel<'_> {
    /// True once the flag is set.
    pub fn requested(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

impl Monitor for Cancel<'_> {
    fn step(&mut self, _progress: &Progress) -> Observed {
        if self.requested() {
            Observed::Break(())
        } else {
            Observed::Continue(())
        }
    }
}

/// Accepted steps over which the stall watchdog measures a run's pace.
pub const STALL_WINDOW: usize = 1000;

/// Stops a run whose pace cannot reach its next output time within the step budget of an
/// output interval ([`MAX_STEPS_PER_CALL`]).
#[derive(Debug, Clone)]
pub(crate) struct Watchdog {
    /// Accepted steps since the last output time (or the start of a `step` call).
    since_output: usize,
    /// Steps and time at the start of the current window.
    window_steps: usize,
    window_t: f64,
    /// Mean step of the previous window (s), to tell a collapse from a steady crawl.
    previous_pace: Option<f64>,
    /// Where the run is, for the diagnosis.
    rtol: f64,
    atol: f64,
}

impl Watchdog {
    /// A watchdog for a run at `t` with the tolerances of its settings.
    pub(crate) fn new(t: f64, rtol: f64, atol: f64) -> Self {
        Watchdog {
            since_output: 0,
            window_steps: 0,
            window_t: t,
            previous_pace: None,
            rtol,
            atol,
        }
    }

    /// An output time was reached: a new budget starts.
    pub(crate) fn output_reached(&mut self) {
        self.since_output = 0;
    }

    /// After an accepted step that ended at `t` with size `h`, on the way to `next` (the next
    /// output time, or the end of a `step` call).
    ///
    /// # Errors
    /// [`SimError::TooManySteps`] when the budget is spent, [`SimError::Stalled`] when the
    /// pace of the last [`STALL_WINDOW`] steps projects past it.
    pub(crate) fn step(&mut self, t: f64, h: f64, next: f64) -> Result<(), SimError> {
        self.since_output += 1;
        self.window_steps += 1;
        if self.since_output >= MAX_STEPS_PER_CALL {
            return Err(SimError::TooManySteps { t });
        }
        if self.window_steps < STALL_WINDOW {
            return Ok(());
        }
        let advanced = t - self.window_t;
        let pace = advanced / self.window_steps as f64;
        let remaining = (next - t).max(0.0);
        let budget = (MAX_STEPS_PER_CALL - self.since_output) as f64;
        let needed = if pace > 0.0 {
            remaining / pace
        } else {
            f64::INFINITY
        };
        let shrinking = self.previous_pace.is_some_and(|p| pace < 0.5 * p);
        self.previous_pace = Some(pace);
        self.window_steps = 0;
        self.window_t = t;
        if needed > budget {
            return Err(SimError::Stalled {
                t,
                h,
                advanced,
                steps: STALL_WINDOW,
                next,
                needed,
                rtol: self.rtol,
                atol: self.atol,
                shrinking,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_steady_run_is_left_alone_and_a_collapsing_one_is_stopped() {
        // Steps of 1e-4 s towards an output 1 s away: 1e4 steps, far within the budget.
        let mut steady = Watchdog::new(0.0, 1e-8, 1e-10);
        let mut t = 0.0;
        for _ in 0..5 * STALL_WINDOW {
            t += 1e-4;
            steady.step(t, 1e-4, 1.0).unwrap();
        }
        // Steps shrinking by 0.1 % each (a run approaching a singular point) towards an
        // output 1 s away: 1e-6 s steps need 1e6 steps (within the budget of 1e7); three
        // windows later the pace (about 8.5e-8 s) projects 1.2e7 and the run is stopped,
        // called shrinking (each window's pace is 0.37 of the one before).
        let mut collapsing = Watchdog::new(0.0, 1e-10, 1e-12);
        let (mut t, mut h) = (0.0, 1e-6);
        let error = loop {
            t += h;
            if let Err(e) = collapsing.step(t, h, 1.0) {
                break e;
            }
            h *= 0.999;
        };
        let SimError::Stalled {
            needed, shrinking, ..
        } = error
        else {
            panic!("{error}");
        };
        assert!(needed > MAX_STEPS_PER_CALL as f64 && shrinking, "{error}");
        assert!(t < 1e-3, "stopped after {t} s");
    }

    #[test]
    fn an_output_reached_renews_the_budget() {
        // 1e-6 s steps to outputs 1e-3 s apart: 1000 steps per output, fine.
        let mut dog = Watchdog::new(0.0, 1e-8, 1e-10);
        let mut t = 0.0;
        for k in 1..=20 {
            while t < k as f64 * 1e-3 - 1e-12 {
                t += 1e-6;
                dog.step(t, 1e-6, k as f64 * 1e-3).unwrap();
            }
            dog.output_reached();
        }
    }
}
