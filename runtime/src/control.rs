//! What a run tells its caller while it goes, how the caller stops it, and how a run whose
//! steps no longer advance time is stopped with a diagnosis (docs/method.md §14).
//!
//! A [`Monitor`] sees every output sample as soon as it is computed and every accepted step;
//! either can stop the run ([`SimError::Interrupted`], with everything computed so far). A
//! signal handler or another thread stops a run through [`Cancel`], which the stepping loop
//! reads after every step: a run answers within one step, not at its next output time.
//!
//! A run stalls when its steps become so short that it cannot reach its end within
//! [`STALL_STEPS`] more steps, or its next output time within the step budget of an output
//! interval ([`MAX_STEPS_PER_CALL`]). The watchdog measures the pace of every
//! [`STALL_WINDOW`] accepted steps and stops the run as soon as that pace projects past
//! either ([`SimError::Stalled`], naming the time, the step, the tolerances and the likely
//! cause), rather than after the steps themselves: a run at steps of 1e-10 s is stopped
//! within a few hundred steps of reaching them, not hours later.

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

    /// Whether the run keeps every sample in its trajectory (the default) or only the last
    /// one. A monitor that consumes the samples as they come (writes them to a file, digests
    /// them) returns false: the run's memory then does not grow with its length, its
    /// trajectory holds the last sample (the last accepted state after a failure) and
    /// counts the others in [`crate::Trajectory::sample_count`], and its output times are
    /// held to [`crate::settings::MAX_STREAMED_SAMPLES`] instead of
    /// [`crate::settings::MAX_SAMPLES`]. Asked once, when the run starts.
    fn keep_samples(&self) -> bool {
        true
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
pub const STALL_WINDOW: usize = 500;

/// A run whose pace projects more further steps than this to its end is stalled: at the
/// fastest right-hand sides (a microsecond) that is a quarter of an hour of steps, at a
/// typical model's hours, for a run whose steps have collapsed or that a stiff mode holds
/// far below its time scale.
pub const STALL_STEPS: f64 = 1e8;

/// A window whose pace is below this fraction of the run's fastest window has collapsed
/// (the likely cause then is a singular point ahead, not a stiff mode).
const COLLAPSE: f64 = 1e-2;

/// Stops a run whose pace cannot reach its next output time within the step budget of an
/// output interval ([`MAX_STEPS_PER_CALL`]).
#[derive(Debug, Clone)]
pub(crate) struct Watchdog {
    /// Accepted steps since the last output time (or the start of a `step` call).
    since_output: usize,
    /// Steps and time at the start of the current window.
    window_steps: usize,
    window_t: f64,
    /// Mean step of the run's fastest window so far (s), to tell a collapse from a steady
    /// crawl.
    fastest_pace: f64,
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
            fastest_pace: 0.0,
            rtol,
            atol,
        }
    }

    /// An output time was reached: a new budget starts.
    pub(crate) fn output_reached(&mut self) {
        self.since_output = 0;
    }

    /// After an accepted step that ended at `t` with size `h`, on the way to `next` (the next
    /// output time, or the end of a `step` call) and to `end` (the run's end).
    ///
    /// # Errors
    /// [`SimError::TooManySteps`] when the budget is spent, [`SimError::Stalled`] when the
    /// pace of the last [`STALL_WINDOW`] steps projects past it or past [`STALL_STEPS`].
    pub(crate) fn step(&mut self, t: f64, h: f64, (next, end): (f64, f64)) -> Result<(), SimError> {
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
        let projected = |target: f64| {
            let remaining = (target - t).max(0.0);
            if remaining == 0.0 {
                0.0
            } else if pace > 0.0 {
                remaining / pace
            } else {
                f64::INFINITY
            }
        };
        let budget = (MAX_STEPS_PER_CALL - self.since_output) as f64;
        let (to_next, to_end) = (projected(next), projected(end));
        let collapsed = pace < COLLAPSE * self.fastest_pace;
        self.fastest_pace = self.fastest_pace.max(pace);
        self.window_steps = 0;
        self.window_t = t;
        if to_next > budget || to_end > STALL_STEPS {
            let (target, needed) = if to_next > budget {
                (next, to_next)
            } else {
                (end, to_end)
            };
            return Err(SimError::Stalled {
                t,
                h,
                advanced,
                steps: STALL_WINDOW,
                target,
                needed,
                rtol: self.rtol,
                atol: self.atol,
                collapsed,
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
        for _ in 0..10 * STALL_WINDOW {
            t += 1e-4;
            steady.step(t, 1e-4, (1.0, 1.0)).unwrap();
        }
        // Steps of 1e-3 s, then shrinking by 1 % each (a run approaching a singular point),
        // towards an end 100 s away (no output before it): stopped once 500 steps average
        // below 1e-6 s (1e8 steps to the end), and called a collapse (its pace is below
        // 1e-2 of the first windows.).
        let mut collapsing = Watchdog::new(0.0, 1e-10, 1e-12);
        let (mut t, mut h) = (0.0, 1e-3);
        let mut steps = 0;
        let error = loop {
            t += h;
            steps += 1;
            if let Err(e) = collapsing.step(t, h, (100.0, 100.0)) {
                break e;
            }
            if steps > 2 * STALL_WINDOW {
                h *= 0.99;
            }
        };
        let SimError::Stalled {
            needed, collapsed, ..
        } = error
        else {
            panic!("{error}");
        };
        assert!(
            needed > MAX_STEPS_PER_CALL as f64 / 2.0 && collapsed,
            "{error}"
        );
        assert!(steps < 6 * STALL_WINDOW, "stopped after {steps} steps");
        // Steady steps of 1e-7 s from the start (a stiff mode) towards an end 20 s away:
        // stopped after the first window, not called a collapse.
        let mut stiff = Watchdog::new(0.0, 1e-10, 1e-12);
        let mut t = 0.0;
        let error = loop {
            t += 1e-7;
            if let Err(e) = stiff.step(t, 1e-7, (1.0, 20.0)) {
                break e;
            }
        };
        assert!(
            matches!(
                error,
                SimError::Stalled {
                    collapsed: false,
                    ..
                }
            ),
            "{error}"
        );
    }

    #[test]
    fn an_output_reached_renews_the_budget() {
        // 1e-6 s steps to outputs 1e-3 s apart: 1000 steps per output, fine.
        let mut dog = Watchdog::new(0.0, 1e-8, 1e-10);
        let mut t = 0.0;
        for k in 1..=20 {
            while t < k as f64 * 1e-3 - 1e-12 {
                t += 1e-6;
                dog.step(t, 1e-6, (k as f64 * 1e-3, 0.02)).unwrap();
            }
            dog.output_reached();
        }
    }
}
