//! Explicit Runge–Kutta integrators on a flat state vector: RK4, Dormand–Prince 5(4) and
//! Dormand–Prince 8(5,3) ([`Dop853`]), the last two with dense output.
//!
//! Both integrators own their stage buffers (allocated once in `new`), take the right-hand
//! side as a generic closure `FnMut(t, y, dy) -> Result<(), SimError>` (monomorphised, no
//! dynamic dispatch) and advance one step per call, so the caller can act between steps
//! (the simulator writes the state back and re-partitions the coordinates there).
//!
//! The first `controlled` components of the state are error-controlled; the remaining ones
//! (quadratures such as dissipated energy) are integrated with the same stages but excluded
//! from the error norm.

use crate::dynamics::IntegratorKind;
use crate::error::SimError;

mod dop853;
pub use dop853::Dop853;

/// Work counters of an integrator, accumulated over its lifetime.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counters {
    /// Accepted steps.
    pub steps: usize,
    /// Rejected step attempts (error too large, or a failed right-hand side evaluation).
    pub rejected: usize,
    /// Right-hand side evaluations.
    pub rhs_evaluations: usize,
}

/// Relative and absolute tolerances of the adaptive integrator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
}

/// Classical fourth-order Runge–Kutta with a fixed step.
#[derive(Debug, Clone)]
pub struct Rk4 {
    k1: Vec<f64>,
    k2: Vec<f64>,
    k3: Vec<f64>,
    k4: Vec<f64>,
    stage: Vec<f64>,
    /// Work done so far.
    pub counters: Counters,
}

impl Rk4 {
    /// Buffers for a state of `dim` components.
    pub fn new(dim: usize) -> Self {
        Self {
            k1: vec![0.0; dim],
            k2: vec![0.0; dim],
            k3: vec![0.0; dim],
            k4: vec![0.0; dim],
            stage: vec![0.0; dim],
            counters: Counters::default(),
        }
    }

    /// One step of size `h` from `(t, y)`; `y` is overwritten with y(t + h). On error `y`
    /// is left unchanged.
    pub fn step<F>(&mut self, rhs: &mut F, t: f64, y: &mut [f64], h: f64) -> Result<(), SimError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>,
    {
        let half = 0.5 * h;
        self.counters.rhs_evaluations += 4;
        rhs(t, y, &mut self.k1)?;
        axpy_into(&mut self.stage, y, half, &self.k1);
        rhs(t + half, &self.stage, &mut self.k2)?;
        axpy_into(&mut self.stage, y, half, &self.k2);
        rhs(t + half, &self.stage, &mut self.k3)?;
        axpy_into(&mut self.stage, y, h, &self.k3);
        rhs(t + h, &self.stage, &mut self.k4)?;
        let sixth = h / 6.0;
        for (i, yi) in y.iter_mut().enumerate() {
            *yi += sixth * (self.k1[i] + 2.0 * (self.k2[i] + self.k3[i]) + self.k4[i]);
        }
        self.counters.steps += 1;
        Ok(())
    }
}

/// `out = y + a·k`.
fn axpy_into(out: &mut [f64], y: &[f64], a: f64, k: &[f64]) {
    for ((o, &yi), &ki) in out.iter_mut().zip(y).zip(k) {
        *o = yi + a * ki;
    }
}

// Dormand–Prince 5(4) tableau (Hairer, Nørsett & Wanner, Solving ODEs I, table 5.2).
const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
// Fifth-order weights (also the 7th stage's coefficients: FSAL).
const B1: f64 = 35.0 / 384.0;
const B3: f64 = 500.0 / 1113.0;
const B4: f64 = 125.0 / 192.0;
const B5: f64 = -2187.0 / 6784.0;
const B6: f64 = 11.0 / 84.0;
// Difference fifth minus fourth order weights (error estimate).
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// Shampine's dense output (Hairer's `contd5`): fourth-order interpolant.
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// Step-size controller: safety factor applied to the optimal step.
const SAFETY: f64 = 0.9;
/// Smallest factor by which a step may shrink.
const MIN_FACTOR: f64 = 0.2;
/// Largest factor by which a step may grow.
const MAX_FACTOR: f64 = 5.0;
/// Factor applied after a failed right-hand side evaluation (e.g. Newton failing at a trial
/// stage that overshot): the step is retried much smaller.
const FAILURE_FACTOR: f64 = 0.2;
/// Consecutive failed right-hand side evaluations tolerated in one step before the error is
/// returned: 0.2⁸ ≈ 2.6e-6, so the last retry used a step 4·10⁵ times smaller than the first.
const MAX_FAILED_ATTEMPTS: usize = 8;
/// Step floor relative to max(|t|, 1): below 16 ε the sum t + h keeps fewer than ~48 of h's
/// 53 bits, and the step no longer advances time meaningfully.
const STEP_FLOOR: f64 = 16.0 * f64::EPSILON;

/// The stage evaluations per attempt and the quadrature weights of the adaptive method
/// `kind` (see [`Adaptive::QUADRATURE`]); none for RK4.
pub fn stage_quadrature(kind: IntegratorKind) -> (usize, &'static [f64]) {
    match kind {
        IntegratorKind::Rk4 => (0, &[]),
        IntegratorKind::Dopri5 => (Dopri5::EVALUATIONS_PER_ATTEMPT, Dopri5::QUADRATURE),
        IntegratorKind::Dop853 => (Dop853::EVALUATIONS_PER_ATTEMPT, Dop853::QUADRATURE),
    }
}

/// Outcome of one accepted adaptive step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AcceptedStep {
    /// Size of the accepted step (≤ the step tried).
    pub h: f64,
    /// Step size proposed by the controller for the next step.
    pub h_next: f64,
}

/// Embedded Dormand–Prince 5(4) with local extrapolation (the fifth-order solution is
/// propagated), first-same-as-last reuse of the last stage, and a PI step-size
/// [`Controller`].
#[derive(Debug, Clone)]
pub struct Dopri5 {
    k: [Vec<f64>; 7],
    stage: Vec<f64>,
    y_new: Vec<f64>,
    /// State, start time and size of the last accepted step (dense output).
    y_old: Vec<f64>,
    t_old: f64,
    h_old: f64,
    controlled: usize,
    fsal_valid: bool,
    /// k7 of the last accepted step is the next step's k1 (moved when that step starts, so
    /// that the interpolant can still be formed until then).
    fsal_pending: bool,
    controller: Controller,
    /// Work done so far.
    pub counters: Counters,
}

impl Dopri5 {
    /// Buffers for a state of `dim` components whose first `controlled` ones enter the
    /// error norm.
    pub fn new(dim: usize, controlled: usize) -> Self {
        Self {
            k: std::array::from_fn(|_| vec![0.0; dim]),
            stage: vec![0.0; dim],
            y_new: vec![0.0; dim],
            y_old: vec![0.0; dim],
            t_old: 0.0,
            h_old: 0.0,
            controlled: controlled.min(dim),
            fsal_valid: false,
            fsal_pending: false,
            controller: Controller::new(
                0.2 - 0.75 * CONTROLLER_BETA,
                CONTROLLER_BETA,
                MIN_FACTOR,
                MAX_FACTOR,
            ),
            counters: Counters::default(),
        }
    }

    fn ensure_first_stage<F>(&mut self, rhs: &mut F, t: f64, y: &[f64]) -> Result<(), SimError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>,
    {
        if !self.fsal_valid {
            self.counters.rhs_evaluations += 1;
            rhs(t, y, &mut self.k[0])?;
            self.fsal_valid = true;
        }
        Ok(())
    }

    fn accept(&mut self, t: f64, h: f64, y: &mut [f64]) {
        self.y_old.copy_from_slice(y);
        y.copy_from_slice(&self.y_new);
        (self.t_old, self.h_old) = (t, h);
        self.fsal_pending = true;
        self.counters.steps += 1;
    }

    /// Stages 2–7 of a step of size `h`; leaves the fifth-order solution in `y_new` and
    /// returns the scaled RMS error estimate (≤ 1 means acceptable).
    fn attempt<F>(
        &mut self,
        rhs: &mut F,
        t: f64,
        y: &[f64],
        h: f64,
        tolerances: Tolerances,
    ) -> Result<f64, SimError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>,
    {
        self.stage_point(y, h, &[A21]);
        self.evaluate(rhs, t + C2 * h, 1)?;
        self.stage_point(y, h, &[A31, A32]);
        self.evaluate(rhs, t + C3 * h, 2)?;
        self.stage_point(y, h, &[A41, A42, A43]);
        self.evaluate(rhs, t + C4 * h, 3)?;
        self.stage_point(y, h, &[A51, A52, A53, A54]);
        self.evaluate(rhs, t + C5 * h, 4)?;
        self.stage_point(y, h, &[A61, A62, A63, A64, A65]);
        self.evaluate(rhs, t + h, 5)?;
        self.stage_point(y, h, &[B1, 0.0, B3, B4, B5, B6]);
        self.y_new.copy_from_slice(&self.stage);
        self.counters.rhs_evaluations += 1;
        rhs(t + h, &self.y_new, &mut self.k[6])?;
        Ok(self.error_norm(y, h, tolerances))
    }

    /// `stage = y + h Σ_j a_j k_j`.
    fn stage_point(&mut self, y: &[f64], h: f64, a: &[f64]) {
        self.stage.copy_from_slice(y);
        for (&aj, kj) in a.iter().zip(&self.k) {
            if aj != 0.0 {
                let scale = h * aj;
                for (s, &kji) in self.stage.iter_mut().zip(kj) {
                    *s += scale * kji;
                }
            }
        }
    }

    fn evaluate<F>(&mut self, rhs: &mut F, t: f64, index: usize) -> Result<(), SimError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>,
    {
        self.counters.rhs_evaluations += 1;
        rhs(t, &self.stage, &mut self.k[index])
    }

    /// RMS over the controlled components of err_i / (atol + rtol·max(|y0_i|, |y1_i|)),
    /// err = h Σ e_j k_j. NaN becomes +∞ so that the step is rejected.
    fn error_norm(&self, y: &[f64], h: f64, tolerances: Tolerances) -> f64 {
        if self.controlled == 0 {
            return 0.0;
        }
        let k = &self.k;
        let mut sum = 0.0;
        for i in 0..self.controlled {
            let error = h
                * (E1 * k[0][i]
                    + E3 * k[2][i]
                    + E4 * k[3][i]
                    + E5 * k[4][i]
                    + E6 * k[5][i]
                    + E7 * k[6][i]);
            let scale = tolerances.atol + tolerances.rtol * y[i].abs().max(self.y_new[i].abs());
            sum += (error / scale).powi(2);
        }
        let norm = (sum / self.controlled as f64).sqrt();
        if norm.is_nan() { f64::INFINITY } else { norm }
    }
}

/// What the simulator needs of an adaptive integrator with dense output (implemented by
/// [`Dopri5`] and [`Dop853`]).
pub trait Adaptive {
    /// Right-hand sides one attempt of a step evaluates (its stages after the first, and the
    /// derivative at the new point): the last this many evaluations of an accepted step are
    /// its own, in order.
    const EVALUATIONS_PER_ATTEMPT: usize;

    /// The weights bᵢ of the step's quadrature over (the derivative at the step's start,
    /// then the attempt's evaluations in order): for an extra component ż = g(t, y),
    /// h Σ bᵢ gᵢ is the step's increment of z, so Σ bᵢ gᵢ is the mean of g over the step to
    /// the method's order.
    const QUADRATURE: &'static [f64];

    /// One accepted step from `(t, y)` trying `h_try` first; `y` is overwritten with the
    /// new state only on success.
    fn step<F>(
        &mut self,
        rhs: &mut F,
        t: f64,
        y: &mut [f64],
        h_try: f64,
        tolerances: Tolerances,
    ) -> Result<AcceptedStep, SimError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>;

    /// Forget the derivative cached at the current point (the state changed outside).
    fn invalidate_fsal(&mut self);

    /// Makes the interpolant of the last accepted step available (may cost right-hand
    /// sides: three for DOP853, none for Dopri5).
    fn prepare_dense<F>(&mut self, rhs: &mut F) -> Result<(), SimError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>;

    /// y(t) within the last accepted step (after [`Adaptive::prepare_dense`]).
    fn interpolate(&self, t: f64, out: &mut [f64]);

    /// Work done so far.
    fn counters(&self) -> Counters;
}

impl Adaptive for Dopri5 {
    const EVALUATIONS_PER_ATTEMPT: usize = 6;
    // Stages 1 (the start), 2–6, 7 (the new point; not in the fifth-order solution).
    const QUADRATURE: &'static [f64] = &[B1, 0.0, B3, B4, B5, B6, 0.0];

    /// One accepted step from `(t, y)` trying `h_try` first; rejected attempts are retried
    /// with smaller steps. `y` is overwritten with the new state only on success.
    ///
    /// A failing right-hand side at a trial stage (never at the initial point) is treated
    /// as a rejection and retried with a step five times smaller, at most
    /// `MAX_FAILED_ATTEMPTS` times in a row; then its error is returned.
    fn step<F>(
        &mut self,
        rhs: &mut F,
        t: f64,
        y: &mut [f64],
        h_try: f64,
        tolerances: Tolerances,
    ) -> Result<AcceptedStep, SimError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>,
    {
        if self.fsal_pending {
            self.k.swap(0, 6);
            self.fsal_pending = false;
        }
        self.ensure_first_stage(rhs, t, y)?;
        let mut controller = self.controller;
        let (outcome, rejected) = controlled_step(t, h_try, &mut controller, |h| {
            self.attempt(rhs, t, y, h, tolerances)
        });
        self.controller = controller;
        self.counters.rejected += rejected;
        let accepted = outcome?;
        self.accept(t, accepted.h, y);
        Ok(accepted)
    }

    /// Forget the cached derivative at the current point (call after the state was changed
    /// outside this integrator, e.g. a re-partition or another integrator's step).
    fn invalidate_fsal(&mut self) {
        self.controller.reset();
        self.fsal_valid = false;
        self.fsal_pending = false;
    }

    fn prepare_dense<F>(&mut self, _rhs: &mut F) -> Result<(), SimError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>,
    {
        Ok(())
    }

    /// y(t) inside the last accepted step by Shampine's fourth-order continuous extension
    /// (Hairer's `contd5`); needs no further right-hand side. Valid until the next step.
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let (h, s) = (self.h_old, (t - self.t_old) / self.h_old);
        let s1 = 1.0 - s;
        let k = &self.k;
        for (i, o) in out.iter_mut().enumerate() {
            let y0 = self.y_old[i];
            let difference = self.y_new[i] - y0;
            let r3 = h * k[0][i] - difference;
            let r4 = difference - h * k[6][i] - r3;
            let r5 = h
                * (D1 * k[0][i]
                    + D3 * k[2][i]
                    + D4 * k[3][i]
                    + D5 * k[4][i]
                    + D6 * k[5][i]
                    + D7 * k[6][i]);
            *o = y0 + s * (difference + s1 * (r3 + s * (r4 + s1 * r5)));
        }
    }

    fn counters(&self) -> Counters {
        self.counters
    }
}

/// The step-size loop of the adaptive integrators: tries `h_try`, shrinks the step by
/// `factor(error)` (≤ 1) after a rejection or by [`FAILURE_FACTOR`] after a failing
/// right-hand side, and returns the accepted step with the next proposal (growth limited
/// to `max_factor`, and to 1 right after a rejection), plus the number of rejections.
/// `attempt(h)` computes a trial step and returns its scaled error (≤ 1: acceptable).
///
/// At most [`MAX_FAILED_ATTEMPTS`] failures in a row, then the failure is returned; below
/// the step floor the last failure, if any, is the cause (steps shrinking onto a point
/// where the right-hand side fails, e.g. the chain cannot follow the cam beyond it),
/// otherwise [`SimError::StepSizeTooSmall`].
fn controlled_step(
    t: f64,
    h_try: f64,
    controller: &mut Controller,
    mut attempt: impl FnMut(f64) -> Result<f64, SimError>,
) -> (Result<AcceptedStep, SimError>, usize) {
    let floor = STEP_FLOOR * t.abs().max(1.0);
    let (mut h, mut rejected, mut failed_attempts) = (h_try, 0, 0);
    let mut last_failure = None;
    loop {
        if h.is_nan() || h < floor {
            // Steps can also shrink onto a point beyond which the right-hand side does not
            // exist without any attempt reaching past it (the energy quadratures of a
            // mechanism moved only by its drives grow without bound at a dead point): a
            // short probe past it names the cause.
            let error = last_failure
                .or_else(|| attempt(PROBE_STEP * t.abs().max(1.0)).err())
                .unwrap_or(SimError::StepSizeTooSmall { t, h });
            return (Err(error), rejected);
        }
        match attempt(h) {
            Ok(error) if error <= 1.0 => {
                let factor = controller.accepted(error);
                let h_next = h * if rejected > 0 {
                    factor.min(1.0)
                } else {
                    factor
                };
                return (Ok(AcceptedStep { h, h_next }), rejected);
            }
            Ok(error) => {
                // A failure seen at a longer attempt stays the likely cause: steps that shrink
                // onto a dead point alternate between stages beyond it (which fail) and
                // inaccurate ones before it.
                h *= controller.rejected(error);
            }
            Err(failure) => {
                failed_attempts += 1;
                if failed_attempts > MAX_FAILED_ATTEMPTS {
                    return (Err(failure), rejected);
                }
                last_failure = Some(failure);
                h *= FAILURE_FACTOR;
            }
        }
        rejected += 1;
    }
}

/// The step of the probe past a point onto which the steps shrank (times max(1, |t|)): a
/// right-hand side that fails that close beyond it is the cause of the shrinking.
const PROBE_STEP: f64 = 1e-10;

/// β of the step-size [`Controller`] of both adaptive integrators: Hairer's default for
/// DOPRI5, and for DOP853 the better of 0 (Hairer's default there) and 0.04 on the reference
/// models: at the same tolerances 0.04 rejects a third as many steps at 1e-7…1e-8 and gives
/// smaller errors (driven_concave at tol 1e-8: 7e-9 against 1e-7 with β = 0) for about the
/// same work (BENCHMARKS.md, work-precision).
pub const CONTROLLER_BETA: f64 = 0.04;

/// Step-size controller of the adaptive integrators, Hairer's stabilised form of
/// Gustafsson's PI controller: after an accepted step of scaled error `err`, the step is
/// multiplied by `SAFETY · err^(−α) · err_prev^β` (`err_prev` the previous accepted
/// step's error, at least 1e-4), bounded to `[min, max]`; after a rejection by
/// `SAFETY · err^(−α)` (at most 1). β = 0 is the elementary controller; a small β damps the
/// oscillation of the step size between acceptance and rejection that an elementary
/// controller shows on smooth problems (a rejected attempt costs a whole step of
/// right-hand sides).
#[derive(Debug, Clone, Copy)]
pub struct Controller {
    alpha: f64,
    beta: f64,
    min: f64,
    max: f64,
    previous: f64,
}

impl Controller {
    /// The controller `SAFETY · err^(−alpha) · err_prev^beta` bounded to `[min, max]`.
    /// Hairer's codes take alpha = 1/5 − 0.75 β (DOPRI5) and 1/8 − 0.2 β (DOP853).
    pub fn new(alpha: f64, beta: f64, min: f64, max: f64) -> Self {
        Self {
            alpha,
            beta,
            min,
            max,
            previous: 1e-4,
        }
    }

    /// Factor for the next step after an accepted one with scaled error `error` (≤ 1).
    fn accepted(&mut self, error: f64) -> f64 {
        let factor = if error <= 0.0 {
            self.max
        } else {
            SAFETY * error.powf(-self.alpha) * self.previous.powf(self.beta)
        };
        self.previous = error.max(1e-4);
        factor.clamp(self.min, self.max)
    }

    /// Factor (< 1) for retrying a rejected step of scaled error `error` (> 1).
    fn rejected(&self, error: f64) -> f64 {
        (SAFETY * error.powf(-self.alpha)).clamp(self.min, 1.0)
    }

    /// Forgets the previous error (after the state was changed from outside).
    fn reset(&mut self) {
        self.previous = 1e-4;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type Rhs = fn(f64, &[f64], &mut [f64]) -> Result<(), SimError>;

    fn decay(_t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        dy[0] = -y[0];
        Ok(())
    }

    /// y'' = −y as (y, y'); exact solution from (1, 0): (cos t, −sin t).
    fn oscillator(_t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        dy[0] = y[1];
        dy[1] = -y[0];
        Ok(())
    }

    /// Fixed steps; for Dopri5 huge tolerances make every step acceptable.
    fn fixed_step_error(
        rhs: Rhs,
        y0: &[f64],
        exact: &[f64],
        t_end: f64,
        steps: usize,
        dopri: bool,
    ) -> f64 {
        let h = t_end / steps as f64;
        let mut y = y0.to_vec();
        let mut rk4 = Rk4::new(y.len());
        let mut dp = Dopri5::new(y.len(), y.len());
        let loose = Tolerances {
            rtol: 1e10,
            atol: 1e10,
        };
        let mut rhs = rhs;
        for i in 0..steps {
            let t = i as f64 * h;
            if dopri {
                let accepted = dp.step(&mut rhs, t, &mut y, h, loose).unwrap();
                assert_eq!(accepted.h, h);
            } else {
                rk4.step(&mut rhs, t, &mut y, h).unwrap();
            }
        }
        y.iter()
            .zip(exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    }

    fn observed_orders(
        rhs: Rhs,
        y0: &[f64],
        exact: &[f64],
        t_end: f64,
        coarse: usize,
        dopri: bool,
    ) -> Vec<f64> {
        let errors: Vec<f64> = (0..4)
            .map(|level| fixed_step_error(rhs, y0, exact, t_end, coarse << level, dopri))
            .collect();
        errors
            .windows(2)
            .map(|pair| (pair[0] / pair[1]).log2())
            .collect()
    }

    // Band for the observed order p = log2(e(h)/e(h/2)). The step ranges below start where
    // the leading error term dominates (measured orders: RK4 3.9–4.1; Dopri5 5.04–5.15 on
    // the decay, 4.95–5.0 on the oscillator, the higher-order terms of the decay fading as
    // h halves) and end with errors ≥ 7e-14, far above the round-off accumulated over
    // ≤ 256 steps (~1e-15). ±0.25 around the theoretical order is then safe, yet it still
    // tells neighbouring orders apart.
    const ORDER_BAND: f64 = 0.25;

    #[test]
    fn the_stage_quadrature_of_dopri5_has_its_order() {
        // Σ bᵢ cᵢᵏ = 1/(k + 1) for k ≤ 4: the quadrature of ż = g(t) is exact for
        // polynomials of degree 4 (order 5), at the nodes of the start and the evaluations.
        let nodes = [0.0, C2, C3, C4, C5, 1.0, 1.0];
        assert_eq!(nodes.len(), 1 + Dopri5::EVALUATIONS_PER_ATTEMPT);
        for k in 0..=4 {
            let sum: f64 = Dopri5::QUADRATURE
                .iter()
                .zip(nodes)
                .map(|(b, c)| b * c.powi(k))
                .sum();
            assert!(
                (sum - 1.0 / f64::from(k + 1)).abs() < 1e-15,
                "degree {k}: {sum}"
            );
        }
    }

    #[test]
    fn rk4_has_order_four() {
        let e = (-2.0f64).exp();
        for p in observed_orders(decay, &[1.0], &[e], 2.0, 8, false) {
            assert!((p - 4.0).abs() < ORDER_BAND, "decay: order {p}");
        }
        let t_end = std::f64::consts::TAU;
        for p in observed_orders(oscillator, &[1.0, 0.0], &[1.0, 0.0], t_end, 16, false) {
            assert!((p - 4.0).abs() < ORDER_BAND, "oscillator: order {p}");
        }
    }

    #[test]
    fn dopri5_has_order_five() {
        let e = (-2.0f64).exp();
        for p in observed_orders(decay, &[1.0], &[e], 2.0, 16, true) {
            assert!((p - 5.0).abs() < ORDER_BAND, "decay: order {p}");
        }
        let t_end = std::f64::consts::TAU;
        for p in observed_orders(oscillator, &[1.0, 0.0], &[1.0, 0.0], t_end, 32, true) {
            assert!((p - 5.0).abs() < ORDER_BAND, "oscillator: order {p}");
        }
    }

    fn adaptive_run(rtol: f64) -> (f64, Counters) {
        let tolerances = Tolerances {
            rtol,
            atol: rtol * 1e-2,
        };
        let mut dp = Dopri5::new(2, 2);
        let mut y = vec![1.0, 0.0];
        let (mut t, t_end) = (0.0, 10.0);
        let mut h: f64 = 0.01;
        let mut rhs = oscillator;
        while t < t_end {
            let h_try = h.min(t_end - t);
            let accepted = dp.step(&mut rhs, t, &mut y, h_try, tolerances).unwrap();
            t = if h_try == t_end - t && accepted.h == h_try {
                t_end
            } else {
                t + accepted.h
            };
            h = accepted.h_next;
        }
        let error = (y[0] - t_end.cos()).abs().max((y[1] + t_end.sin()).abs());
        (error, dp.counters)
    }

    #[test]
    fn dopri5_meets_its_tolerance_on_a_known_solution() {
        // The controller bounds the local error per step by ~rtol; over ~1.6 periods the
        // global error of this non-dissipative problem stays within a small multiple of
        // rtol (measured ≈ 1.3·rtol at 1e-6, 1.1·rtol at 1e-8). Allow 20·rtol, and require
        // that tightening the tolerance by 100 shrinks the error by more than 10.
        let (loose, _) = adaptive_run(1e-6);
        let (tight, counters) = adaptive_run(1e-8);
        assert!(loose < 20.0 * 1e-6, "error {loose}");
        assert!(tight < 20.0 * 1e-8, "error {tight}");
        assert!(loose / tight > 10.0, "{loose} vs {tight}");
        assert_eq!(
            counters.rhs_evaluations,
            6 * (counters.steps + counters.rejected) + 1
        );
    }

    #[test]
    fn uncontrolled_components_do_not_limit_the_step() {
        // Component 1 is a quadrature of a violently varying integrand: excluded from the
        // error norm, it must not change the accepted steps of component 0.
        let mut with_quadrature = |_t: f64, y: &[f64], dy: &mut [f64]| -> Result<(), SimError> {
            dy[0] = -y[0];
            dy[1] = (1e3 * y[0]).sin() * 1e6;
            Ok(())
        };
        let tolerances = Tolerances {
            rtol: 1e-8,
            atol: 1e-10,
        };
        let mut plain = Dopri5::new(1, 1);
        let mut mixed = Dopri5::new(2, 1);
        let (mut y1, mut y2) = (vec![1.0], vec![1.0, 0.0]);
        let mut rhs = decay;
        let a = plain.step(&mut rhs, 0.0, &mut y1, 0.1, tolerances).unwrap();
        let b = mixed
            .step(&mut with_quadrature, 0.0, &mut y2, 0.1, tolerances)
            .unwrap();
        assert_eq!(a, b);
        assert_eq!(y1[0], y2[0]);
    }

    #[test]
    fn failing_trial_stages_shrink_the_step_then_report() {
        // The right-hand side fails for t > 0.05: the first attempt (h = 1) fails, retries
        // shrink h by 5 until every stage lies below 0.05.
        let mut limited = |t: f64, y: &[f64], dy: &mut [f64]| -> Result<(), SimError> {
            if t > 0.05 {
                return Err(SimError::TooManySteps { t });
            }
            dy[0] = -y[0];
            Ok(())
        };
        let tolerances = Tolerances {
            rtol: 1e-3,
            atol: 1e-3,
        };
        let mut dp = Dopri5::new(1, 1);
        let mut y = vec![1.0];
        let accepted = dp.step(&mut limited, 0.0, &mut y, 1.0, tolerances).unwrap();
        assert!(accepted.h <= 0.05 && accepted.h > 0.0);
        let error = dp
            .step(&mut limited, 0.05, &mut y, 1.0, tolerances)
            .unwrap_err();
        assert!(matches!(error, SimError::TooManySteps { .. }));
    }

    #[test]
    fn impossible_tolerance_reports_step_size_too_small() {
        let mut noisy = |t: f64, _y: &[f64], dy: &mut [f64]| -> Result<(), SimError> {
            dy[0] = if t > 0.0 { 1e30 } else { 0.0 };
            Ok(())
        };
        let tolerances = Tolerances {
            rtol: 1e-12,
            atol: 1e-12,
        };
        let mut dp = Dopri5::new(1, 1);
        let error = dp
            .step(&mut noisy, 0.0, &mut [0.0], 1.0, tolerances)
            .unwrap_err();
        assert!(
            matches!(error, SimError::StepSizeTooSmall { .. }),
            "{error}"
        );
    }
}
