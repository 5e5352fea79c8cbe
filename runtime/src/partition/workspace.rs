//! The preallocated buffers of the partitioned dynamics and their bookkeeping: the state,
//! the constraint rows solved, the length scale and the errors reported at the current state.

use super::choice::choose_dependent;
use super::linalg::max_abs;
use crate::dynamics::Dynamics;
use crate::error::SimError;

/// Entries of J below this times the model's length scale are round-off
/// ([`Workspace::jacobian_floor`]).
pub(super) const JACOBIAN_FLOOR: f64 = 1e-12;

/// Preallocated buffers for the partitioned dynamics of one model (n coordinates, nc
/// contacts, nu independent coordinates). The kernels below read and write the full state
/// `q`, `q̇`, `q̈` held here.
#[derive(Debug, Clone)]
pub struct Workspace {
    pub(super) n: usize,
    pub(super) nc: usize,
    pub(super) nu: usize,
    /// The model's number of constraints m (≥ nc).
    pub(super) m: usize,
    /// The rows of the model's h that are solved (nc of the m, increasing): all of them
    /// unless some are redundant ([`independent_rows`](super::independent_rows)).
    pub(super) rows: Vec<usize>,
    /// h, J and c of all m rows, when some are left out (empty otherwise).
    pub(super) full_h: Vec<f64>,
    pub(super) full_jacobian: Vec<f64>,
    pub(super) full_bias: Vec<f64>,
    pub(crate) q: Vec<f64>,
    pub(crate) qd: Vec<f64>,
    pub(crate) qdd: Vec<f64>,
    /// v at the last accepted step: Newton's restart point.
    pub(crate) v_anchor: Vec<f64>,
    pub(super) mass: Vec<f64>,
    pub(super) inertial: Vec<f64>,
    pub(super) applied: Vec<f64>,
    pub(super) residual: Vec<f64>,
    pub(crate) jacobian: Vec<f64>,
    pub(super) bias: Vec<f64>,
    pub(crate) h: Vec<f64>,
    /// q-only values `position_terms` hands to `velocity_terms` (sines, cosines, …).
    pub(super) cache: Vec<f64>,
    pub(super) jv_lu: Vec<f64>,
    pub(super) pivots: Vec<usize>,
    /// J_v factored as a band matrix, when it is one (chained loops).
    pub(super) band: super::band::Band,
    pub(super) scratch: Vec<f64>,
    pub(super) saved_v: Vec<f64>,
    pub(super) b_matrix: Vec<f64>,
    pub(super) b_vector: Vec<f64>,
    pub(super) mass_t: Vec<f64>,
    pub(super) reduced_mass: Vec<f64>,
    /// ü, the dense route's reduced solve (the articulated route reads ü from q̈).
    pub(super) udd: Vec<f64>,
    pub(crate) lambda: Vec<f64>,
    pub(crate) drive: Vec<f64>,
    /// The lengths of the model (≥ 1): scales Newton's residual tolerance.
    pub(super) length_scale: f64,
    /// A next correction at most this times (1 + ‖v‖∞) ends Newton too (0: strict).
    pub(super) newton_slack: f64,
    /// Each solved row's largest ‖J_k‖∞ seen so far ([`Self::rows_shrunk`]).
    pub(super) row_peaks: Vec<f64>,
    /// The articulated-body route's buffers ([`Self::use_articulated`]).
    pub(super) articulated: ArticulatedBuffers,
}

impl Workspace {
    /// Buffers for n coordinates, nc contacts and nu independent coordinates.
    pub fn new(n: usize, nc: usize, nu: usize) -> Self {
        Self {
            n,
            nc,
            nu,
            m: nc,
            rows: (0..nc).collect(),
            full_h: Vec::new(),
            full_jacobian: Vec::new(),
            full_bias: Vec::new(),
            q: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
            v_anchor: vec![0.0; nc],
            mass: vec![0.0; n * n],
            inertial: vec![0.0; n],
            applied: vec![0.0; n],
            residual: vec![0.0; n],
            jacobian: vec![0.0; nc * n],
            bias: vec![0.0; nc],
            h: vec![0.0; nc],
            cache: Vec::new(),
            jv_lu: vec![0.0; nc * nc],
            pivots: vec![0; nc],
            band: super::band::Band::default(),
            scratch: vec![0.0; nc],
            saved_v: vec![0.0; nc],
            b_matrix: vec![0.0; nc * nu],
            b_vector: vec![0.0; nc],
            mass_t: vec![0.0; n * nu],
            reduced_mass: vec![0.0; nu * nu],
            udd: vec![0.0; nu],
            lambda: vec![0.0; nc],
            drive: vec![0.0; n],
            length_scale: 1.0,
            newton_slack: 0.0,
            row_peaks: Vec::new(),
            articulated: Default::default(),
        }
    }

    /// Solves only the rows `rows` (increasing, nc of them) of a model with `m` constraints:
    /// the others are redundant. h, J and c are evaluated for all m rows and the chosen
    /// ones gathered; the multipliers of the others are zero.
    pub fn select_rows(&mut self, m: usize, rows: &[usize]) {
        self.m = m;
        self.rows = rows.to_vec();
        self.row_peaks.clear();
        if m == self.nc {
            // Written by `position_terms` again: zero where it may not write (its rows'
            // extents, `Dynamics::jacobian_rows`).
            self.jacobian.fill(0.0);
            self.full_h.clear();
            self.full_jacobian.clear();
            self.full_bias.clear();
        } else {
            self.full_h.resize(m, 0.0);
            self.full_jacobian.resize(m * self.n, 0.0);
            self.full_bias.resize(m, 0.0);
        }
    }

    /// The rows of h solved (all of them unless some are redundant).
    pub fn rows(&self) -> &[usize] {
        &self.rows
    }

    /// The number of coordinates n.
    pub fn n_coordinates(&self) -> usize {
        self.n
    }

    /// The model's number of constraints m.
    pub fn m(&self) -> usize {
        self.m
    }

    /// J of all m rows as last evaluated (the solved rows' J when none is left out).
    pub fn full_jacobian(&self) -> &[f64] {
        if self.m == self.nc {
            &self.jacobian
        } else {
            &self.full_jacobian
        }
    }

    /// h of all m rows as last evaluated.
    pub fn full_h(&self) -> &[f64] {
        if self.m == self.nc {
            &self.h
        } else {
            &self.full_h
        }
    }

    /// λ of all m rows: zero on the rows left out.
    pub fn full_lambda(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.m];
        for (&row, &l) in self.rows.iter().zip(&self.lambda) {
            out[row] = l;
        }
        out
    }

    /// λ of constraint row `row` of all m (zero when the row is left out), without
    /// allocating.
    pub fn contact_lambda(&self, row: usize) -> f64 {
        self.rows
            .iter()
            .position(|&r| r == row)
            .map_or(0.0, |k| self.lambda[k])
    }

    /// Copies the chosen rows of the full h, J into the solved ones.
    pub(super) fn gather_rows(&mut self) {
        let n = self.n;
        for (k, &row) in self.rows.iter().enumerate() {
            self.h[k] = self.full_h[row];
            self.jacobian[k * n..(k + 1) * n]
                .copy_from_slice(&self.full_jacobian[row * n..(row + 1) * n]);
        }
    }

    /// Re-chooses which rows are solved (same number), from the full J last evaluated.
    pub fn reselect_rows(&mut self, rows: &[usize]) {
        if self.m != self.nc && rows.len() == self.nc {
            self.rows = rows.to_vec();
            self.gather_rows();
        }
    }

    /// h(q) of the solved rows into `self.h` (one `constraint` call).
    pub(super) fn evaluate_h(&mut self, model: &dyn Dynamics) {
        if self.m == self.nc {
            model.constraint(&self.q, &mut self.h);
        } else {
            model.constraint(&self.q, &mut self.full_h);
            for (k, &row) in self.rows.iter().enumerate() {
                self.h[k] = self.full_h[row];
            }
        }
    }

    /// h and J at q without the cache (assembly).
    pub fn evaluate_constraints(&mut self, model: &dyn Dynamics) {
        if self.m == self.nc {
            model.constraint(&self.q, &mut self.h);
            model.constraint_jacobian(&self.q, &mut self.jacobian);
        } else {
            model.constraint(&self.q, &mut self.full_h);
            model.constraint_jacobian(&self.q, &mut self.full_jacobian);
            self.gather_rows();
        }
    }

    /// Sets the model's length scale (the largest contact-point coordinate, in the model's
    /// length unit), which multiplies
    /// [`NEWTON_RESIDUAL_TOLERANCE`](super::NEWTON_RESIDUAL_TOLERANCE); values below 1 count
    /// as 1.
    pub fn set_length_scale(&mut self, scale: f64) {
        self.length_scale = if scale.is_finite() {
            scale.max(1.0)
        } else {
            1.0
        };
    }

    /// The model's length scale (≥ 1).
    pub fn length_scale(&self) -> f64 {
        self.length_scale
    }

    /// Entries of J (and pivots of J_v) at or below this are round-off, not a lever arm:
    /// J has the units of a length per coordinate unit, so 1e-12 of the model's length
    /// scale. A J_v this small is a dead point, not an unreachable cam.
    pub fn jacobian_floor(&self) -> f64 {
        JACOBIAN_FLOOR * self.length_scale
    }

    /// [`choose_dependent`] on the J last evaluated, with the entries at or below
    /// [`Self::jacobian_floor`] counted as zero.
    pub fn choose_dependent(&self, eligible: &[bool]) -> Option<Vec<usize>> {
        let floor = self.jacobian_floor();
        let usable = self.nc == 0
            || self
                .jacobian
                .iter()
                .enumerate()
                .any(|(k, x)| eligible[k % self.n] && x.abs() > floor);
        if usable {
            choose_dependent(&self.jacobian, self.nc, self.n, eligible)
        } else {
            None
        }
    }

    /// Coordinates q.
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// Velocities q̇.
    pub fn qd(&self) -> &[f64] {
        &self.qd
    }

    /// Accelerations q̈ (after [`Self::solve_accelerations`]).
    pub fn qdd(&self) -> &[f64] {
        &self.qdd
    }

    /// Multipliers λ (after [`Self::solve_multipliers`]).
    pub fn lambda(&self) -> &[f64] {
        &self.lambda
    }

    /// Drive loads τ, zero on free coordinates (after [`Self::solve_multipliers`]).
    pub fn drive(&self) -> &[f64] {
        &self.drive
    }

    /// Fills the cache of [`Dynamics::position_terms`] with NaN: nothing in it is reused.
    pub fn clear_cache(&mut self) {
        self.cache.fill(f64::NAN);
    }

    /// Sets q and q̇ (e.g. before the kernels, with consistent values).
    pub fn set_state(&mut self, q: &[f64], qd: &[f64]) {
        self.q.copy_from_slice(q);
        self.qd.copy_from_slice(qd);
    }

    pub(crate) fn non_finite(&self, t: f64, quantity: &'static str) -> SimError {
        SimError::NonFinite {
            t,
            quantity,
            q: self.q.clone(),
            qd: self.qd.clone(),
        }
    }

    /// h, J and the cache at the current q, by one [`Dynamics::position_terms`] call.
    pub(super) fn evaluate_position_terms(&mut self, model: &dyn Dynamics) {
        let len = model.cache_len();
        if self.cache.len() != len {
            self.cache.resize(len, f64::NAN);
        }
        if self.m == self.nc {
            self.band.jacobian_rows.declare(model.jacobian_rows());
            model.position_terms(&self.q, &mut self.h, &mut self.jacobian, &mut self.cache);
        } else {
            // The declared rows are those of all of J, not of the rows kept.
            self.band.jacobian_rows.declare(None);
            model.position_terms(
                &self.q,
                &mut self.full_h,
                &mut self.full_jacobian,
                &mut self.cache,
            );
            self.gather_rows();
        }
    }

    /// [`SimError::SingularConstraint`] at the current q, with the residual of the h last
    /// evaluated.
    pub(crate) fn singular(&self, t: f64) -> SimError {
        let residual = max_abs(&self.h);
        SimError::SingularConstraint {
            t,
            q: self.q.clone(),
            residual,
            on_cam: residual <= self.residual_tolerance(),
        }
    }
}

/// The buffers of the articulated route (empty until first used).
#[derive(Debug, Clone)]
pub(super) struct ArticulatedBuffers {
    /// Use the articulated route when the model provides it (the default).
    pub(super) enabled: bool,
    /// True after an articulated solve: λ and the drive loads are already known.
    pub(super) solved: bool,
    pub(super) factors: Vec<f64>,
    /// A_k, row-major nc × n (driven entries 0).
    pub(super) responses: Vec<f64>,
    /// M_df A_k, row-major nc × n (driven entries only).
    pub(super) response_drive: Vec<f64>,
    /// −J A (nc × nc), then its Cholesky factor.
    pub(super) delassus: Vec<f64>,
    pub(super) tau: Vec<f64>,
}

impl Default for ArticulatedBuffers {
    fn default() -> Self {
        ArticulatedBuffers {
            enabled: true,
            solved: false,
            factors: Vec::new(),
            responses: Vec::new(),
            response_drive: Vec::new(),
            delassus: Vec::new(),
            tau: Vec::new(),
        }
    }
}
