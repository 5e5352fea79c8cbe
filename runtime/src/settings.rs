//! What settings a run accepts, checked once before anything runs.
//!
//! [`SimSettings::validate`] is what `simulate` checks at its start; the command line calls
//! it before it touches any file and names the option at fault, and the model file's
//! `simulation` section is held to the same ranges by `camchain-codegen` (a test in
//! `camchain-reference` compares the two on the boundary values).

use crate::dynamics::{IntegratorKind, SimSettings};
use std::fmt;

/// Relative tolerances accepted by the adaptive integrators: below 1e-14 the error
/// estimate is round-off (a request for 1e-20 only makes the steps shrink until the run
/// fails); above 0.1 there is no accuracy left to control.
pub const RTOL_RANGE: (f64, f64) = (1e-14, 0.1);

/// Absolute tolerances accepted (in the units of the coordinates and velocities: rad, m,
/// rad/s, m/s): below 1e-18 a coordinate near zero can never meet its tolerance; above 1
/// a radian or a metre of error is accepted.
pub const ATOL_RANGE: (f64, f64) = (1e-18, 1.0);

/// The most samples, (t_end − t0) / dt_out, of a run that keeps them in its trajectory
/// (`simulate` and every variant whose monitor keeps its samples, see
/// [`crate::Monitor::keep_samples`]): each holds a few vectors of the model's size, so a
/// million are some hundred megabytes (about 780 MB for `paper_concave`, 4.2 GB for
/// `n_four_bar`); more is almost surely a mistyped `dt_out` or `t_end`. A model file's
/// `simulation` section is held to the same number (`camchain-codegen`).
pub const MAX_SAMPLES: f64 = 1e6;

/// The most output times, (t_end − t0) / dt_out, of a run that keeps no samples: a run
/// whose monitor only streams them ([`crate::Monitor::keep_samples`] false, what
/// `camchain simulate` does when its CSV goes to a file) or a metrics run (what a sweep
/// runs; its output times matter only with `MetricsOptions::grid`). Its memory does not
/// grow with its length, so this is no memory bound but one on the work and the output: a
/// billion samples take a quarter of an hour at the cheapest microsecond each (hours for
/// most models) and, written to a CSV, some hundred gigabytes; more is almost surely a
/// mistyped `dt_out` or `t_end`.
pub const MAX_STREAMED_SAMPLES: f64 = 1e9;

/// Accepted steps allowed in one call of `step`/`step_with`, or per output interval of
/// `simulate`, before `SimError::TooManySteps`.
pub const MAX_STEPS_PER_CALL: usize = 10_000_000;

/// A setting that cannot be used, and why.
#[derive(Clone, PartialEq)]
pub struct InvalidSetting {
    /// The field of [`SimSettings`] at fault (`t_end`, `dt_out`, `dt`, `rtol`, `atol`), or
    /// `t_end/dt_out` for a sample count out of range.
    pub field: &'static str,
    /// What is wrong, with the value.
    pub message: String,
}

impl fmt::Debug for InvalidSetting {
    /// The one-line message of `Display`, so that a `main` returning
    /// `Result<(), Box<dyn std::error::Error>>` prints it as it is after `Error: `. The
    /// fields stay public for a program that needs them.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

impl fmt::Display for InvalidSetting {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field, self.message)
    }
}

impl std::error::Error for InvalidSetting {}

impl SimSettings {
    /// Checks the settings for a run that starts at `t0` and keeps its samples:
    /// [`validate_integration`](Self::validate_integration), then
    /// [`validate_output`](Self::validate_output).
    ///
    /// # Errors
    /// The first setting out of range, with its field and value.
    pub fn validate(&self, t0: f64) -> Result<(), InvalidSetting> {
        self.validate_integration()?;
        self.validate_output(t0)
    }

    /// [`validate`](Self::validate) for a run that keeps no samples (streamed to its
    /// monitor, or a metrics run): at most [`MAX_STREAMED_SAMPLES`] output times instead of
    /// [`MAX_SAMPLES`].
    ///
    /// # Errors
    /// The first setting out of range, with its field and value.
    pub fn validate_streamed(&self, t0: f64) -> Result<(), InvalidSetting> {
        self.validate_integration()?;
        self.validate_streamed_output(t0)
    }

    /// The integration settings alone (what `step_with` needs): a positive, finite `dt`;
    /// for the adaptive integrators, tolerances in [`RTOL_RANGE`] and [`ATOL_RANGE`].
    ///
    /// # Errors
    /// The first setting out of range.
    pub fn validate_integration(&self) -> Result<(), InvalidSetting> {
        positive("dt", self.dt)?;
        if self.integrator.is_adaptive() {
            in_range("rtol", self.rtol, RTOL_RANGE)?;
            in_range("atol", self.atol, ATOL_RANGE)?;
        }
        Ok(())
    }

    /// The output settings of a run from `t0` that keeps its samples: a positive, finite
    /// `dt_out`, a finite `t_end` ≥ t0, at most [`MAX_SAMPLES`] samples and, for RK4, at
    /// most [`MAX_STEPS_PER_CALL`] steps per output interval.
    ///
    /// # Errors
    /// The first setting out of range.
    pub fn validate_output(&self, t0: f64) -> Result<(), InvalidSetting> {
        self.output_within(t0, MAX_SAMPLES, "a run keeps")
    }

    /// [`validate_output`](Self::validate_output) for a run that keeps no samples: at most
    /// [`MAX_STREAMED_SAMPLES`] output times.
    ///
    /// # Errors
    /// The first setting out of range.
    pub fn validate_streamed_output(&self, t0: f64) -> Result<(), InvalidSetting> {
        self.output_within(t0, MAX_STREAMED_SAMPLES, "a run streams")
    }

    /// The output checks with at most `cap` samples (`whose`: what the cap is of, for the
    /// message).
    fn output_within(&self, t0: f64, cap: f64, whose: &str) -> Result<(), InvalidSetting> {
        positive("dt_out", self.dt_out)?;
        if !(self.t_end.is_finite() && self.t_end >= t0) {
            return Err(invalid(
                "t_end",
                format!(
                    "must be finite and not before the start t = {} s, got {}",
                    compact(t0),
                    compact(self.t_end)
                ),
            ));
        }
        let samples = (self.t_end - t0) / self.dt_out;
        if samples > cap {
            return Err(invalid(
                "t_end/dt_out",
                format!(
                    "t_end = {} s with dt_out = {} s gives {samples:.3e} samples, more than the \
                     {cap:e} {whose}: a larger dt_out or a smaller t_end",
                    compact(self.t_end),
                    compact(self.dt_out)
                ),
            ));
        }
        let steps = self.dt_out / self.dt;
        if !self.integrator.is_adaptive() && steps > MAX_STEPS_PER_CALL as f64 {
            return Err(invalid(
                "dt",
                format!(
                    "an rk4 step of {:e} s needs {steps:.1e} steps per output interval \
                     (dt_out = {:e} s), more than the {MAX_STEPS_PER_CALL} allowed",
                    self.dt, self.dt_out
                ),
            ));
        }
        Ok(())
    }

    /// The steps RK4 takes in one output interval: the fixed step `dt` as many times as fits,
    /// then a last, shorter step landing on the output time (`None` when `dt` divides
    /// `dt_out`, to round-off). Returns (number of steps, the last step) for `Some`.
    pub fn rk4_landing_step(&self) -> Option<(usize, f64)> {
        if self.integrator != IntegratorKind::Rk4 || !(self.dt > 0.0 && self.dt_out > 0.0) {
            return None;
        }
        let ratio = self.dt_out / self.dt;
        let whole = (ratio - 1e-9).floor().max(0.0);
        let last = self.dt_out - whole * self.dt;
        if last >= self.dt * (1.0 - 1e-6) {
            return None;
        }
        Some((whole as usize + 1, last))
    }
}

fn invalid(field: &'static str, message: String) -> InvalidSetting {
    InvalidSetting { field, message }
}

fn positive(field: &'static str, value: f64) -> Result<(), InvalidSetting> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("must be positive and finite, got {value}"),
        ))
    }
}

fn in_range(
    field: &'static str,
    value: f64,
    (low, high): (f64, f64),
) -> Result<(), InvalidSetting> {
    if value.is_finite() && (low..=high).contains(&value) {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("must be in [{low:e}, {high:e}], got {value:e}"),
        ))
    }
}

/// A number as written by a person: plain for ordinary magnitudes (`30`, `0.01`), in
/// scientific notation beyond them (`1e308`, not three hundred digits).
fn compact(value: f64) -> String {
    if value == 0.0 || !value.is_finite() || (1e-4..1e7).contains(&value.abs()) {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(integrator: IntegratorKind) -> SimSettings {
        SimSettings {
            t_end: 10.0,
            dt_out: 0.01,
            integrator,
            dt: 1e-3,
            rtol: 1e-10,
            atol: 1e-12,
        }
    }

    #[test]
    fn a_huge_t_end_is_printed_in_a_few_characters() {
        let mut s = settings(IntegratorKind::Dop853);
        s.t_end = 1e308;
        let message = s.validate(0.0).expect_err("too many samples").to_string();
        assert!(message.contains("t_end = 1e308 s"), "{message}");
        assert!(message.len() < 300, "{message}");
        s.t_end = 30.0;
        s.dt_out = 1e-9;
        let message = s.validate(0.0).expect_err("too many samples").to_string();
        assert!(
            message.contains("t_end = 30 s with dt_out = 1e-9 s"),
            "{message}"
        );
    }

    #[test]
    fn the_defaults_of_the_paper_models_pass() {
        assert_eq!(settings(IntegratorKind::Dop853).validate(0.0), Ok(()));
        assert_eq!(settings(IntegratorKind::Rk4).validate(0.0), Ok(()));
    }

    #[test]
    fn each_setting_out_of_range_is_named() {
        let base = settings(IntegratorKind::Dop853);
        type Edit = fn(&mut SimSettings);
        let cases: [(Edit, &str); 8] = [
            (|s| s.rtol = 1e-20, "rtol"),
            (|s| s.rtol = 5.0, "rtol"),
            (|s| s.atol = 0.0, "atol"),
            (|s| s.atol = f64::NAN, "atol"),
            (|s| s.t_end = 1e12, "t_end/dt_out"),
            (|s| s.dt_out = 1e-9, "t_end/dt_out"),
            (|s| s.dt = -1.0, "dt"),
            (|s| s.t_end = f64::INFINITY, "t_end"),
        ];
        for (edit, field) in cases {
            let mut s = base.clone();
            edit(&mut s);
            assert_eq!(s.validate(0.0).map_err(|e| e.field), Err(field), "{s:?}");
        }
        // The bounds themselves are accepted.
        let mut s = base.clone();
        s.rtol = RTOL_RANGE.0;
        s.atol = ATOL_RANGE.1;
        assert_eq!(s.validate(0.0), Ok(()));
        // RK4 ignores tolerances but counts its steps.
        let mut s = settings(IntegratorKind::Rk4);
        s.rtol = 1e-30;
        assert_eq!(s.validate(0.0), Ok(()));
        s.dt = 1e-12;
        assert_eq!(s.validate(0.0).map_err(|e| e.field), Err("dt"));
    }

    #[test]
    fn streamed_runs_have_their_own_cap() {
        // Ten million samples: more than a run keeps, far fewer than one streams.
        let mut s = settings(IntegratorKind::Dop853);
        s.t_end = 1e5;
        let kept = s.validate(0.0).unwrap_err();
        assert_eq!(kept.field, "t_end/dt_out");
        assert!(kept.message.contains("the 1e6 a run keeps"), "{kept}");
        assert_eq!(s.validate_streamed(0.0), Ok(()));
        // At the cap and beyond it.
        s.t_end = MAX_STREAMED_SAMPLES * s.dt_out;
        assert_eq!(s.validate_streamed(0.0), Ok(()));
        s.t_end *= 1.001;
        let streamed = s.validate_streamed(0.0).unwrap_err();
        assert_eq!(streamed.field, "t_end/dt_out");
        assert!(
            streamed.message.contains("the 1e9 a run streams"),
            "{streamed}"
        );
        // Everything else is checked as for a kept run.
        s.t_end = 1e5;
        s.rtol = 1.0;
        assert_eq!(s.validate_streamed(0.0).map_err(|e| e.field), Err("rtol"));
    }

    #[test]
    fn the_last_rk4_step_of_an_interval_is_reported_when_shortened() {
        let mut s = settings(IntegratorKind::Rk4);
        assert_eq!(s.rk4_landing_step(), None, "1 ms divides 10 ms");
        s.dt = 0.003;
        let (steps, last) = s.rk4_landing_step().expect("shortened");
        assert_eq!(steps, 4);
        assert!((last - 0.001).abs() < 1e-12, "{last}");
        s.dt = 0.02;
        let (steps, last) = s.rk4_landing_step().expect("one short step");
        assert_eq!(steps, 1);
        assert!((last - 0.01).abs() < 1e-15);
    }
}
