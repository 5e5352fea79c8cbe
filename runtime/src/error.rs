//! Simulation errors. Every variant that can occur during a run carries the time and, where
//! it helps to diagnose the failure, the generalised coordinates at which it happened.

use std::fmt;

/// Why assembly, a step or a simulation could not continue.
#[derive(Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// Newton's method on the dependent coordinates, eq. (15), did not converge: the
    /// contact point cannot reach the cam for the current independent (and driven)
    /// coordinates, or the iteration started too far from the solution.
    #[error(
        "at t = {t} s the contact point cannot reach the cam: Newton on the dependent \
         coordinates (15) stopped after {iterations} iterations with |h|∞ = {residual:.3e} \
         at q = {}{}",
        Compact(.q),
        DivergenceHint(.q, &[])
    )]
    NewtonFailed {
        /// Time (s).
        t: f64,
        /// Coordinates at the last Newton iterate.
        q: Vec<f64>,
        /// max_k |h_k(q)| at the last iterate (m).
        residual: f64,
        /// Newton corrections performed.
        iterations: usize,
    },

    /// The constraint Jacobian J (5b) has no usable column: no set of eligible coordinates
    /// gives an invertible J_v, so the dependent coordinates cannot be chosen or solved.
    /// With the contact point on the cam this is a dead point: the mechanism locks.
    #[error(
        "at t = {t} s {}; q = {}",
        SingularCause(*.on_cam, *.residual),
        Compact(.q)
    )]
    SingularConstraint {
        /// Time (s).
        t: f64,
        /// Coordinates.
        q: Vec<f64>,
        /// max |h| there (m).
        residual: f64,
        /// True when |h| is within Newton's tolerance (the point is on the cam).
        on_cam: bool,
    },

    /// Assembly found no configuration where every loop closes (or every constraint holds
    /// together): Newton from the initial guess left `constraint` open by `residual`, or a
    /// loop equation that is implied by the others to first order is not satisfied.
    #[error(
        "at t = {t} s the mechanism cannot be assembled: {constraint} is still {residual:.3e} from closing ({why}); q = {}",
        Compact(.q)
    )]
    CannotAssemble {
        /// Time (s).
        t: f64,
        /// Coordinates at the last iterate.
        q: Vec<f64>,
        /// |h| of that constraint there.
        residual: f64,
        /// The constraint: a contact's name or `loop.equation`.
        constraint: String,
        /// What was tried.
        why: String,
    },

    /// The reduced mass matrix M* of eq. (18) is not positive definite (an invalid model:
    /// zero or negative inertia along some admissible motion).
    #[error(
        "at t = {t} s the reduced mass matrix M* (18) is not positive definite at q = {}",
        Compact(.q)
    )]
    NotPositiveDefinite {
        /// Time (s).
        t: f64,
        /// Coordinates.
        q: Vec<f64>,
    },

    /// A computed quantity is NaN or infinite.
    #[error(
        "at t = {t} s {quantity} is not finite; q = {}, q̇ = {}{}",
        Compact(.q),
        Compact(.qd),
        DivergenceHint(.q, .qd)
    )]
    NonFinite {
        /// Time (s).
        t: f64,
        /// Which quantity, e.g. `"q̈"`, `"λ"`, `"h"`, or `"q"`, `"q̇"` for a state that was
        /// already not finite (set so by the caller).
        quantity: &'static str,
        /// Coordinates.
        q: Vec<f64>,
        /// Velocities.
        qd: Vec<f64>,
    },

    /// The adaptive integrator needed a step below its floor to meet the tolerances.
    #[error(
        "at t = {t} s the step size fell to {h:.3e} s, below the floor: the tolerances \
         cannot be met (stiff or non-smooth motion?)"
    )]
    StepSizeTooSmall {
        /// Time (s).
        t: f64,
        /// The rejected step size (s).
        h: f64,
    },

    /// The run stalled: at the pace of its last `steps` accepted steps it could not reach its
    /// end within [`crate::control::STALL_STEPS`] more steps, or its next output time within
    /// the step budget of an output interval ([`crate::settings::MAX_STEPS_PER_CALL`]); see
    /// [`crate::control`].
    #[error(
        "at t = {t} s the run has stalled: its last {steps} steps advanced only {advanced:.3e} s \
         (the last {h:.3e} s), so reaching t = {target} s would take {needed:.1e} more steps \
         (rtol {rtol:.0e}, atol {atol:.0e}). {}",
        StallCause(*.collapsed)
    )]
    Stalled {
        /// Time (s).
        t: f64,
        /// The last accepted step (s).
        h: f64,
        /// Time advanced over the measured steps (s).
        advanced: f64,
        /// Number of steps measured.
        steps: usize,
        /// What the pace was projected to: the next output time or the run's end (s).
        target: f64,
        /// Steps the pace projects to reach it.
        needed: f64,
        /// Relative tolerance of the run.
        rtol: f64,
        /// Absolute tolerance of the run.
        atol: f64,
        /// True when the steps collapsed to a hundredth of the run's earlier ones (a
        /// singular point ahead), false when they were short all along (a stiff mode).
        collapsed: bool,
    },

    /// The step budget of one call was exhausted.
    #[error("at t = {t} s the step budget of one call was exhausted")]
    TooManySteps {
        /// Time (s).
        t: f64,
    },

    /// The observer of the run asked it to stop (`ControlFlow::Break` from
    /// `Simulate::simulate_observed`: an interrupt, an output that could not be written).
    #[error("stopped at t = {t} s at the observer's request")]
    Interrupted {
        /// Time of the last sample (s).
        t: f64,
    },

    /// Settings, initial data or a requested partition are invalid.
    #[error("invalid settings: {message}")]
    InvalidSettings {
        /// What is wrong.
        message: String,
    },
}

impl fmt::Debug for SimError {
    /// The one-line message of `Display`, so that a `main` returning
    /// `Result<(), Box<dyn std::error::Error>>` prints it as it is after `Error: `. The
    /// fields stay public for a program that needs them.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

impl SimError {
    /// The variant's name, e.g. `NewtonFailed` (for tables and logs).
    pub fn kind(&self) -> &'static str {
        match self {
            SimError::NewtonFailed { .. } => "NewtonFailed",
            SimError::SingularConstraint { .. } => "SingularConstraint",
            SimError::CannotAssemble { .. } => "CannotAssemble",
            SimError::NotPositiveDefinite { .. } => "NotPositiveDefinite",
            SimError::NonFinite { .. } => "NonFinite",
            SimError::StepSizeTooSmall { .. } => "StepSizeTooSmall",
            SimError::TooManySteps { .. } => "TooManySteps",
            SimError::Stalled { .. } => "Stalled",
            SimError::Interrupted { .. } => "Interrupted",
            SimError::InvalidSettings { .. } => "InvalidSettings",
        }
    }

    /// The time the failure happened at (`None` for invalid settings).
    pub fn time(&self) -> Option<f64> {
        match self {
            SimError::NewtonFailed { t, .. }
            | SimError::SingularConstraint { t, .. }
            | SimError::CannotAssemble { t, .. }
            | SimError::NotPositiveDefinite { t, .. }
            | SimError::NonFinite { t, .. }
            | SimError::StepSizeTooSmall { t, .. }
            | SimError::TooManySteps { t }
            | SimError::Stalled { t, .. }
            | SimError::Interrupted { t } => Some(*t),
            SimError::InvalidSettings { .. } => None,
        }
    }
}

/// What a singular constraint Jacobian means, on the cam (a dead point) or off it.
struct SingularCause(bool, f64);

impl fmt::Display for SingularCause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let SingularCause(on_cam, residual) = *self;
        if on_cam {
            write!(
                f,
                "the mechanism locks at a dead point: the contact point is on the cam (|h| = \
                 {residual:.1e} m) but no coordinate free to move can move it across the cam (the \
                 usable columns of the constraint Jacobian J (5b) vanish)"
            )
        } else {
            write!(
                f,
                "no coordinate free to move can move the contact point across the cam (J_v \
                 singular) while it is off the cam (|h| = {residual:.3e} m): no held, driven or \
                 dependent choice can put it back"
            )
        }
    }
}

/// The likely cause of a stall, from whether the steps were still shrinking.
struct StallCause(bool);

impl fmt::Display for StallCause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0 {
            f.write_str(
                "The steps collapsed to a hundredth of the run's earlier ones: the motion \
                 approaches a point where the equations are singular (a dead point or a \
                 singular position of a loop, where the constraint Jacobian loses rank; a \
                 body whose mass or inertia vanishes; a velocity that grows without bound). \
                 Check the model there, or loosen rtol if the point is passed at the model's \
                 default tolerances.",
            )
        } else {
            f.write_str(
                "The steps were short all along: a stiff mode (a very light body, a very stiff spring \
                 or damper) holds the explicit integrator at its stability limit, or the \
                 tolerances are tighter than the equations can be evaluated to. Soften the \
                 mode or loosen rtol and atol.",
            )
        }
    }
}

/// A coordinate or velocity this large (rad, m, rad/s, m/s) in a failed state means that
/// the integration has almost certainly diverged before the reported failure.
const DIVERGED: f64 = 1e6;

/// Appended to a failure's message when the state has blown up (a finite entry of q or q̇
/// beyond [`DIVERGED`]), e.g. a fixed step beyond the stability limit of a stiff spring:
/// `; the integration has diverged (|q|∞ = 3.842e7, |q̇|∞ = 6.461e263): step too large
/// for the stiffest mode?`. Empty otherwise.
struct DivergenceHint<'a>(&'a [f64], &'a [f64]);

impl fmt::Display for DivergenceHint<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let largest = |v: &[f64]| {
            v.iter()
                .filter(|x| x.is_finite())
                .fold(0.0_f64, |m, x| m.max(x.abs()))
        };
        let (q, qd) = (largest(self.0), largest(self.1));
        if q.max(qd) <= DIVERGED {
            return Ok(());
        }
        write!(f, "; the integration has diverged (|q|∞ = {q:.3e}")?;
        if !self.1.is_empty() {
            write!(f, ", |q̇|∞ = {qd:.3e}")?;
        }
        f.write_str("): step too large for the stiffest mode?")
    }
}

/// Compact display of a vector: `[0.1, -1.570796, 2.5e-7]` (7 significant digits at most,
/// trailing zeros dropped).
pub(crate) struct Compact<'a>(pub(crate) &'a [f64]);

impl fmt::Display for Compact<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("[")?;
        for (i, &x) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            write_compact(f, x)?;
        }
        f.write_str("]")
    }
}

fn write_compact(f: &mut fmt::Formatter<'_>, x: f64) -> fmt::Result {
    let magnitude = x.abs();
    if x == 0.0 || !x.is_finite() {
        write!(f, "{x}")
    } else if (1e-4..1e6).contains(&magnitude) {
        let fixed = format!("{x:.6}");
        let trimmed = fixed.trim_end_matches('0').trim_end_matches('.');
        f.write_str(trimmed)
    } else {
        write!(f, "{x:.3e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_print_compactly() {
        let text = Compact(&[0.0, -1.2345678901, 2.5e-7, 3.0, f64::NAN]).to_string();
        assert_eq!(text, "[0, -1.234568, 2.500e-7, 3, NaN]");
    }

    #[test]
    fn newton_failure_names_time_state_and_cause() {
        let error = SimError::NewtonFailed {
            t: 1.25,
            q: vec![0.5, -2.0],
            residual: 0.125,
            iterations: 25,
        };
        let text = error.to_string();
        assert!(text.contains("t = 1.25 s"), "{text}");
        assert!(text.contains("cannot reach the cam"), "{text}");
        assert!(text.contains("[0.5, -2]"), "{text}");
        assert!(text.contains("25 iterations"), "{text}");
        assert!(!text.contains("diverged"), "{text}");
    }

    #[test]
    fn a_blown_up_state_is_called_a_divergence() {
        let error = SimError::NonFinite {
            t: 0.03,
            quantity: "q̈",
            q: vec![6.5e109, -1.9],
            qd: vec![2.0e221, f64::NAN],
        };
        let text = error.to_string();
        assert!(
            text.contains("diverged (|q|∞ = 6.500e109, |q̇|∞ = 2.000e221)"),
            "{text}"
        );
        let newton = SimError::NewtonFailed {
            t: 0.18,
            q: vec![15108.8, -3.842e7],
            residual: 0.33,
            iterations: 25,
        };
        assert!(
            newton.to_string().contains("diverged (|q|∞ = 3.842e7)"),
            "{newton}"
        );
        let sane = SimError::NonFinite {
            t: 0.0,
            quantity: "q̇",
            q: vec![1.0],
            qd: vec![f64::NAN],
        };
        assert!(!sane.to_string().contains("diverged"), "{sane}");
    }
}
