//! The position and velocity levels, eqs. (15) and (16): Newton on the dependent
//! coordinates, its damped fallback for assembly, the factored J_v and the dependent
//! velocities.

use super::Workspace;
use super::band::solve_dependent;
use super::choice::conditioning;
use super::linalg::{all_finite, dot, euclidean, gather_columns, lu_factor, max_abs};
use crate::dynamics::Dynamics;
use crate::error::SimError;

/// Newton (15) converges when max_k |h_k| is at most this times the model's length scale
/// (m, or rad for angular constraints): 1e-12 is ~10⁴ times the round-off of h for
/// coordinates of order 1. The length scale ([`Workspace::set_length_scale`]: the largest
/// contact-point coordinate at assembly, at least 1) keeps the tolerance that far above the
/// round-off of a model written in millimetres or placed far from the origin.
pub const NEWTON_RESIDUAL_TOLERANCE: f64 = 1e-12;

/// Newton (15) also requires its last correction to be at most this times (1 + ‖v‖∞).
pub const NEWTON_STEP_TOLERANCE: f64 = 1e-12;

/// Newton (15) also stops, |h| being at its tolerance, when its corrections no longer shrink
/// (round-off near a singular position, docs/method.md §11.4) and are at most this times
/// (1 + ‖v‖∞) and the partition's conditioning is not degenerate (`STALL_CONDITIONING`, 0.05):
/// 1e-8, far above the 1e-12 of [`NEWTON_STEP_TOLERANCE`] that such a floor can exceed.
pub const NEWTON_STALL_TOLERANCE: f64 = 1e-8;

/// A stalled Newton (15) is accepted only where the partition's conditioning is at least
/// this: at a dead point J_v vanishes alone and the conditioning goes to 0, so Newton fails
/// there as it should, naming the dead point.
pub(super) const STALL_CONDITIONING: f64 = 0.05;

/// In an adaptive run at relative tolerance rtol, Newton (15) also stops when the next
/// correction is at most this times rtol·(1 + ‖v‖∞) ([`Workspace::set_newton_slack`]).
pub const NEWTON_SLACK_PER_RTOL: f64 = 1e-2;

/// A row of J whose ‖J_k‖∞ has fallen below this fraction of its largest in the run marks a
/// singular position near ([`Workspace::rows_shrunk`]).
pub const ROW_SHRINK: f64 = 0.05;

/// Newton (15) gives up after this many corrections.
pub const NEWTON_MAX_ITERATIONS: usize = 25;

/// Damped Newton (assembly fallback) gives up after this many corrections.
pub(super) const DAMPED_MAX_ITERATIONS: usize = 200;

/// Smallest step fraction tried by the damped Newton's backtracking.
pub(super) const DAMPED_MIN_FRACTION: f64 = 1e-10;

impl Workspace {
    /// Lets Newton (15) stop as soon as the correction it would make next is at most
    /// `slack`·(1 + ‖v‖∞) (it is then applied by [`Self::polish_positions`] without a new
    /// evaluation). The residual left is quadratic in the correction (~1e-18 for 1e-9); h,
    /// J and the cache kept for the velocity level are those of the iterate before it, off
    /// by at most `slack`, which an integration at relative tolerance rtol absorbs when
    /// `slack` = [`NEWTON_SLACK_PER_RTOL`]·rtol: a right-hand side off by 1e-3 of the error
    /// the step is allowed. Stage values of a run are typically 1e-10 to 1e-8 off the
    /// constraint, so at rtol = 1e-6 most right-hand sides then need one position-level
    /// evaluation instead of two. 0 (the default) keeps the strict test.
    pub fn set_newton_slack(&mut self, slack: f64) {
        self.newton_slack = if slack.is_finite() {
            slack.max(0.0)
        } else {
            0.0
        };
    }

    /// Newton's residual tolerance for this model: [`NEWTON_RESIDUAL_TOLERANCE`] times the
    /// length scale.
    pub fn residual_tolerance(&self) -> f64 {
        NEWTON_RESIDUAL_TOLERANCE * self.length_scale
    }

    /// Eq. (15): Newton on the dependent coordinates, v ← v − J_v⁻¹ h(q), from the v held
    /// in `q`. Converged when, at the current iterate, max |h| ≤
    /// [`NEWTON_RESIDUAL_TOLERANCE`] and the correction Newton would make next is at most
    /// [`NEWTON_STEP_TOLERANCE`]·(1 + ‖v‖∞); at most [`NEWTON_MAX_ITERATIONS`]
    /// corrections. Returns the number of corrections made.
    ///
    /// Testing the *next* correction (J_v is factored at every iterate anyway, for the
    /// correction or for the velocity level) rather than the last one saves the evaluation
    /// that would only confirm convergence: from a start 1e-8 off, one correction and two
    /// evaluations instead of two and three. On return h, J, the cache and the factored J_v
    /// are those of the returned q, and the pending correction is the one
    /// [`Self::polish_positions`] applies.
    pub fn solve_positions(
        &mut self,
        model: &dyn Dynamics,
        dependent: &[usize],
        t: f64,
    ) -> Result<usize, SimError> {
        let mut iterations = 0;
        let mut last = f64::INFINITY;
        loop {
            let residual = self.constraint_residual(model, t)?;
            self.factor_jacobian_for_newton(model, dependent, t, residual, iterations)?;
            let next = self.pending_correction(dependent);
            let scale = 1.0 + self.v_size(dependent);
            let small = residual <= self.residual_tolerance();
            let strict = small && next <= NEWTON_STEP_TOLERANCE * scale;
            // Near a singular position (an N-four-bar almost horizontal: J_v ~ sin θ) the
            // round-off of h, amplified by J_v⁻¹ along a chain of loops, puts a floor under
            // the corrections above the step tolerance. With h already at its tolerance, a
            // correction that no longer shrinks by half is that floor: stop (Newton's own
            // convergence would have it shrink quadratically), provided that floor is below
            // NEWTON_STALL_TOLERANCE: at a dead point, where J_v itself vanishes, the
            // corrections stall far above it and Newton fails as before.
            let stalled = small
                && iterations > 0
                && next >= 0.5 * last
                && next <= NEWTON_STALL_TOLERANCE * scale
                && self.well_conditioned(dependent);
            if strict || stalled || next <= self.newton_slack * scale {
                return Ok(iterations);
            }
            last = next;
            if iterations == NEWTON_MAX_ITERATIONS {
                return Err(self.newton_failure(t, residual, iterations));
            }
            self.apply_correction(dependent);
            iterations += 1;
        }
    }

    /// True when J_v of the J last evaluated keeps at least [`STALL_CONDITIONING`] of J's
    /// rows (the conditioning of [`conditioning`], every column counted): a singular position
    /// that shrinks whole rows keeps it, a dead point, where J_v alone vanishes, does not.
    pub(super) fn well_conditioned(&self, dependent: &[usize]) -> bool {
        let all = vec![true; self.n];
        conditioning(&self.jacobian, self.nc, self.n, dependent, &all) >= STALL_CONDITIONING
    }

    /// Assembly fallback for (15): Newton with backtracking on ‖h‖₂ (Armijo condition),
    /// for starting points where plain Newton overshoots.
    pub fn solve_positions_damped(
        &mut self,
        model: &dyn Dynamics,
        dependent: &[usize],
        t: f64,
    ) -> Result<usize, SimError> {
        let mut last_correction = 0.0;
        let mut iterations = 0;
        loop {
            let residual = self.constraint_residual(model, t)?;
            if self.converged(residual, last_correction, dependent) {
                return Ok(iterations);
            }
            if iterations == DAMPED_MAX_ITERATIONS {
                return Err(self.newton_failure(t, residual, iterations));
            }
            self.factor_jacobian_for_newton(model, dependent, t, residual, iterations)?;
            last_correction = self.backtracking_step(model, dependent, t, residual, iterations)?;
            iterations += 1;
        }
    }

    /// One damped Newton step v ← v − α J_v⁻¹ h, halving α from 1 until ‖h‖₂ decreases
    /// (Armijo) or |h| meets the tolerance; returns the size of the correction made.
    pub(super) fn backtracking_step(
        &mut self,
        model: &dyn Dynamics,
        dependent: &[usize],
        t: f64,
        residual: f64,
        iterations: usize,
    ) -> Result<f64, SimError> {
        let norm = euclidean(&self.h);
        self.scratch.copy_from_slice(&self.h);
        solve_dependent(&self.band, &self.jv_lu, &self.pivots, &mut self.scratch);
        for (saved, &v) in self.saved_v.iter_mut().zip(dependent) {
            *saved = self.q[v];
        }
        let mut fraction = 1.0;
        while fraction >= DAMPED_MIN_FRACTION {
            for ((&saved, &dv), &v) in self.saved_v.iter().zip(&self.scratch).zip(dependent) {
                self.q[v] = saved - fraction * dv;
            }
            self.evaluate_h(model);
            let trial = euclidean(&self.h);
            let small = max_abs(&self.h) <= self.residual_tolerance();
            if trial.is_finite() && (small || trial < (1.0 - 1e-4 * fraction) * norm) {
                return Ok(fraction * max_abs(&self.scratch));
            }
            fraction *= 0.5;
        }
        for (&saved, &v) in self.saved_v.iter().zip(dependent) {
            self.q[v] = saved;
        }
        Err(self.newton_failure(t, residual, iterations))
    }

    /// [`Self::factor_current_jacobian`] inside Newton: a singular J_v at an iterate that
    /// does not yet satisfy the constraint means that Newton cannot go on (typically the
    /// point has been asked to go where the cam is not), reported as
    /// [`SimError::NewtonFailed`]; at a point already on the cam it is the configuration
    /// itself that is singular ([`SimError::SingularConstraint`]).
    pub(super) fn factor_jacobian_for_newton(
        &mut self,
        _model: &dyn Dynamics,
        dependent: &[usize],
        t: f64,
        residual: f64,
        iterations: usize,
    ) -> Result<(), SimError> {
        match self.factor_current_jacobian(dependent, t) {
            Err(SimError::SingularConstraint { .. }) if residual > self.residual_tolerance() => {
                Err(self.newton_failure(t, residual, iterations))
            }
            other => other,
        }
    }

    /// Evaluates h and J at q (one [`Dynamics::position_terms`] call, which also fills the
    /// cache for the velocity level); returns max |h|.
    pub(super) fn constraint_residual(
        &mut self,
        model: &dyn Dynamics,
        t: f64,
    ) -> Result<f64, SimError> {
        self.evaluate_position_terms(model);
        let residual = max_abs(&self.h);
        if residual.is_finite() {
            Ok(residual)
        } else {
            Err(self.non_finite(t, "h"))
        }
    }

    pub(super) fn converged(
        &self,
        residual: f64,
        last_correction: f64,
        dependent: &[usize],
    ) -> bool {
        residual <= self.residual_tolerance()
            && last_correction <= NEWTON_STEP_TOLERANCE * (1.0 + self.v_size(dependent))
    }

    /// ‖v‖∞, the scale of the step tolerance.
    pub(super) fn v_size(&self, dependent: &[usize]) -> f64 {
        dependent
            .iter()
            .fold(0.0_f64, |m, &v| m.max(self.q[v].abs()))
    }

    /// One last Newton correction v ← v − J_v⁻¹ h with the h and J_v of the converged
    /// iterate, without evaluating again: Newton stops at |h| ≤ 1e-12, which would leave v
    /// up to ~1e-12 off and put a floor under the accuracy of tight integrations; the
    /// correction makes the residual quadratically small (~1e-24) for the price of a
    /// subtraction (it was computed by [`Self::solve_positions`]'s convergence test). The
    /// J, cache and h kept in the workspace are those of the iterate before it, 1e-12
    /// away, which the velocity and acceleration levels tolerate, except near a singular
    /// position, where the caller evaluates them again ([`Self::rows_shrunk`]).
    pub fn polish_positions(&mut self, dependent: &[usize]) {
        self.apply_correction(dependent);
    }

    /// True when a row of the J last evaluated has shrunk below [`ROW_SHRINK`] of its largest
    /// ‖J_k‖∞ so far (which this updates): a singular position is near, where a loop's rows
    /// scale with |sin θ| (docs/method.md §11.4). There the J of the iterate before
    /// [`Self::polish_positions`] is off by the polish correction relative to |sin θ|, which
    /// the velocity and acceleration levels amplify to ~ω² Δ / sin² θ: J is evaluated again
    /// at the polished q instead.
    pub fn rows_shrunk(&mut self) -> bool {
        let (nc, n) = (self.nc, self.n);
        if self.row_peaks.len() != nc {
            self.row_peaks = vec![0.0; nc];
        }
        let mut shrunk = false;
        for (k, peak) in self.row_peaks.iter_mut().enumerate() {
            // One row is factored without its extents (`factor_current_jacobian`).
            let (s, e) = if nc == 1 {
                (0, n)
            } else {
                self.band.jacobian_rows.row(k, n)
            };
            let norm = max_abs(&self.jacobian[k * n + s..k * n + e]);
            *peak = peak.max(norm);
            shrunk |= norm < ROW_SHRINK * *peak;
        }
        shrunk
    }

    /// J_v⁻¹ h (J_v factored, h evaluated) into the scratch vector, not applied yet;
    /// returns its size max |Δv|.
    pub(super) fn pending_correction(&mut self, dependent: &[usize]) -> f64 {
        if let ([_], [h], [j_v]) = (dependent, &self.h[..], &self.jv_lu[..]) {
            // One contact: J_v is a number.
            self.scratch[0] = h / j_v;
            return self.scratch[0].abs();
        }
        self.scratch.copy_from_slice(&self.h);
        solve_dependent(&self.band, &self.jv_lu, &self.pivots, &mut self.scratch);
        max_abs(&self.scratch)
    }

    /// v ← v − Δv with the correction of [`Self::pending_correction`].
    pub(super) fn apply_correction(&mut self, dependent: &[usize]) {
        for (&dv, &v) in self.scratch.iter().zip(dependent) {
            self.q[v] -= dv;
        }
    }

    /// Why Newton stopped without converging: the contact point cannot reach the cam (h
    /// has not converged), or — h at its tolerance but the corrections h / J_v still large,
    /// J_v vanishing — the mechanism locks at a dead point.
    pub(super) fn newton_failure(&self, t: f64, residual: f64, iterations: usize) -> SimError {
        if residual <= self.residual_tolerance() {
            return SimError::SingularConstraint {
                t,
                q: self.q.clone(),
                residual,
                on_cam: true,
            };
        }
        SimError::NewtonFailed {
            t,
            q: self.q.clone(),
            residual,
            iterations,
        }
    }

    /// Evaluates h and J(q) (5b) and factors J_v (the `dependent` columns).
    pub fn factor_jacobian(
        &mut self,
        model: &dyn Dynamics,
        dependent: &[usize],
        t: f64,
    ) -> Result<(), SimError> {
        self.evaluate_position_terms(model);
        // h comes first in the report: a non-finite J at a point where h is already not
        // finite (a profile evaluated outside its domain) is a consequence.
        if self.h.iter().any(|x| !x.is_finite()) {
            return Err(self.non_finite(t, "h"));
        }
        self.factor_current_jacobian(dependent, t)
    }

    /// Factors J_v of the J last evaluated (by [`Self::solve_positions`], which always ends
    /// with an evaluation at the returned q, or [`Self::factor_jacobian`]).
    pub fn factor_current_jacobian(&mut self, dependent: &[usize], t: f64) -> Result<(), SimError> {
        let floor = self.jacobian_floor();
        if let ([v], 1) = (dependent, self.nc) {
            // One contact: J_v is a number (no band, no gather). Its one row is read whole
            // (no extents: `rows_shrunk`, `solve_velocities`).
            if !all_finite(&self.jacobian[..self.n]) {
                return Err(self.non_finite(t, "J"));
            }
            (self.jv_lu[0], self.band.active) = (self.jacobian[*v], false);
            return if lu_factor(&mut self.jv_lu, &mut self.pivots, 1, floor) {
                Ok(())
            } else {
                Err(self.singular(t))
            };
        }
        // Which columns of each row may be nonzero (checked): the row operations below and
        // those of the velocity and acceleration levels read only those.
        self.band.jacobian_rows.update(&self.jacobian, self.n);
        if self.band.jacobian_rows.any_non_finite(&self.jacobian) {
            return Err(self.non_finite(t, "J"));
        }
        // A band matrix (chained loops) is factored as one; anything else densely.
        let factored = match self.band.factor(&self.jacobian, self.n, dependent, floor) {
            Some(factored) => factored,
            None => {
                gather_columns(&self.jacobian, self.n, dependent, &mut self.jv_lu);
                lu_factor(&mut self.jv_lu, &mut self.pivots, self.nc, floor)
            }
        };
        if factored {
            Ok(())
        } else {
            Err(self.singular(t))
        }
    }

    /// Eq. (16), velocity level: v̇ = −J_v⁻¹ (J_u u̇ + J_d q̇_d), i.e. the v̇ making J q̇ = 0.
    /// Needs [`Self::factor_jacobian`] at the current q.
    pub fn solve_velocities(&mut self, dependent: &[usize]) {
        if let [v] = dependent {
            // One contact: v̇ = −(Σ_{i≠v} J_i q̇_i) / J_v, summed on either side of v. (Not over
            // the whole row with q̇_v set to 0 first: the sum's wide loads right after that
            // narrow store stalled on it, a third of this function's time under perf.)
            let (row, qd) = (&self.jacobian[..self.n], &self.qd[..self.n]);
            let sum = dot(&row[..*v], &qd[..*v]) + dot(&row[*v + 1..], &qd[*v + 1..]);
            self.qd[*v] = -sum / self.jv_lu[0];
            return;
        }
        for &v in dependent {
            self.qd[v] = 0.0;
        }
        for k in 0..self.nc {
            self.scratch[k] = -self.band.jacobian_rows.dot_row(&self.jacobian, k, &self.qd);
        }
        solve_dependent(&self.band, &self.jv_lu, &self.pivots, &mut self.scratch);
        for (&vd, &v) in self.scratch.iter().zip(dependent) {
            self.qd[v] = vd;
        }
    }
}
