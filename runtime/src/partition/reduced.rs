//! The acceleration level, eqs. (16)–(18): the reduced mass matrix Tᵀ M T, its right-hand
//! side and their L D Lᵀ solve for ü, then q̈ = T ü + g.

use super::band::{residual_rows, solve_dependent};
use super::linalg::{dot, solve_ldlt, solve_reduced};
use super::{Partition, Workspace};
use crate::dynamics::{Dynamics, VelocityTerms};
use crate::error::SimError;

impl Workspace {
    /// Eqs. (16)–(18): evaluates M, F, Q and c at (t, q, q̇) and solves the reduced dynamics
    /// for ü; writes q̈ = T ü + g. Needs the position level evaluated at the current q
    /// ([`Self::factor_jacobian`], or [`Self::solve_positions`] then
    /// [`Self::factor_current_jacobian`]: J factored and the cache filled) and q̈_d
    /// in the driven entries of q̈ (from [`Dynamics::prescribed`]).
    pub fn solve_accelerations(
        &mut self,
        model: &dyn Dynamics,
        partition: &Partition,
        t: f64,
    ) -> Result<(), SimError> {
        if self.articulated_route(model) {
            return self.solve_articulated(model, partition, t);
        }
        self.articulated.solved = false;
        // One call: generated models share the kinematics between M, F, Q and c, and take
        // the sines and cosines from the position level.
        let all_rows = self.m == self.nc;
        self.band.mass_rows.declare(model.mass_rows());
        let out = VelocityTerms {
            mass: &mut self.mass,
            inertial: &mut self.inertial,
            applied: &mut self.applied,
            bias: if all_rows {
                &mut self.bias
            } else {
                &mut self.full_bias
            },
        };
        model.velocity_terms(t, &self.q, &self.qd, &self.cache, out);
        if !all_rows {
            for (k, &row) in self.rows.iter().enumerate() {
                self.bias[k] = self.full_bias[row];
            }
        }
        self.reduce_and_solve(partition, t)
    }

    /// The linear algebra of (16)–(18) on M, F, Q, J, c already in the workspace.
    pub(super) fn reduce_and_solve(
        &mut self,
        partition: &Partition,
        t: f64,
    ) -> Result<(), SimError> {
        let single = match self.nu {
            _ if self.nc != 1 => None,
            1 => Some(self.reduce_single::<1>(partition)),
            2 => Some(self.reduce_single::<2>(partition)),
            3 => Some(self.reduce_single::<3>(partition)),
            4 => Some(self.reduce_single::<4>(partition)),
            5 => Some(self.reduce_single::<5>(partition)),
            6 => Some(self.reduce_single::<6>(partition)),
            _ => None,
        };
        match single {
            Some(false) => return Err(self.not_positive_definite(t)),
            Some(true) => {
                if self.qdd.iter().any(|x| !x.is_finite()) {
                    return Err(self.non_finite(t, "q̈"));
                }
                return Ok(());
            }
            None => {}
        }
        self.eliminate_dependent(partition);
        self.set_particular_acceleration(partition);
        self.project_dynamics(partition);
        if !solve_reduced(&mut self.reduced_mass, self.nu, &mut self.udd) {
            return Err(self.not_positive_definite(t));
        }
        self.expand_accelerations(partition);
        if self.qdd.iter().any(|x| !x.is_finite()) {
            return Err(self.non_finite(t, "q̈"));
        }
        Ok(())
    }

    /// Eqs. (16)–(18) for one contact and `NU` independent coordinates in one pass on
    /// fixed-size arrays (the paper's case: NU = 3): B = −J_u / J_v, b = −(c + J_d q̈_d) / J_v,
    /// the residual r = M g + F + Q on the rows that enter, M* = Tᵀ M T entry by entry,
    /// L D Lᵀ, then q̈ = T ü + g. The same arithmetic as the general path, without its
    /// loop and index bookkeeping (which cost more than the arithmetic at these sizes).
    /// Returns false when M* is not positive definite (M* is then left in `reduced_mass`).
    // Indices mirror the formulas (M*_ac, B_a, u_a); iterator forms would hide them.
    #[allow(clippy::needless_range_loop)]
    pub(super) fn reduce_single<const NU: usize>(&mut self, partition: &Partition) -> bool {
        let n = self.n;
        let v = partition.dependent()[0];
        let mut u = [0usize; NU];
        u.copy_from_slice(&partition.independent()[..NU]);
        let row = &self.jacobian[..n];
        let inverse = 1.0 / self.jv_lu[0];
        let mut driven_sum = 0.0;
        for &d in partition.driven() {
            driven_sum += row[d] * self.qdd[d];
        }
        let b = -(self.bias[0] + driven_sum) * inverse;
        let mut coupling = [0.0; NU];
        for a in 0..NU {
            coupling[a] = -row[u[a]] * inverse;
        }
        for &ua in &u {
            self.qdd[ua] = 0.0;
        }
        self.qdd[v] = b;
        let mass = &self.mass;
        let residual = |i: usize, qdd: &[f64]| {
            let m_row = &mass[i * n..(i + 1) * n];
            let mut r = self.inertial[i] + self.applied[i] + m_row[v] * qdd[v];
            for &d in partition.driven() {
                r += m_row[d] * qdd[d];
            }
            r
        };
        let r_v = residual(v, &self.qdd);
        let m_vv = mass[v * n + v];
        let mut reduced = [[0.0; NU]; NU];
        let mut rhs = [0.0; NU];
        for a in 0..NU {
            let m_row = &mass[u[a] * n..(u[a] + 1) * n];
            let (b_a, m_av) = (coupling[a], m_row[v]);
            for c in 0..=a {
                let m_vc = mass[v * n + u[c]];
                reduced[a][c] =
                    m_row[u[c]] + m_av * coupling[c] + b_a * (m_vc + m_vv * coupling[c]);
            }
            rhs[a] = -(residual(u[a], &self.qdd) + b_a * r_v);
        }
        let Some(udd) = solve_ldlt::<NU>(&mut reduced, rhs) else {
            for a in 0..NU {
                for c in 0..=a {
                    self.reduced_mass[a * NU + c] = reduced[a][c];
                }
            }
            return false;
        };
        let mut qdd_v = b;
        for a in 0..NU {
            self.qdd[u[a]] = udd[a];
            qdd_v += coupling[a] * udd[a];
        }
        self.qdd[v] = qdd_v;
        self.udd[..NU].copy_from_slice(&udd);
        true
    }

    pub(super) fn not_positive_definite(&self, t: f64) -> SimError {
        if self.reduced_mass.iter().any(|x| !x.is_finite()) {
            self.non_finite(t, "M")
        } else {
            SimError::NotPositiveDefinite {
                t,
                q: self.q.clone(),
            }
        }
    }

    /// B = −J_v⁻¹ J_u (nc×nu, row-major) and b = −J_v⁻¹ (c + J_d q̈_d), eq. (16).
    pub(super) fn eliminate_dependent(&mut self, partition: &Partition) {
        if self.nc == 1 {
            self.eliminate_single_dependent(partition);
            return;
        }
        let (n, nc, nu) = (self.n, self.nc, self.nu);
        for k in 0..nc {
            let row = &self.jacobian[k * n..(k + 1) * n];
            let driven: f64 = partition
                .driven()
                .iter()
                .map(|&d| row[d] * self.qdd[d])
                .sum();
            self.b_vector[k] = -(self.bias[k] + driven);
        }
        solve_dependent(&self.band, &self.jv_lu, &self.pivots, &mut self.b_vector);
        for (a, &u) in partition.independent().iter().enumerate() {
            for k in 0..nc {
                self.scratch[k] = -self.jacobian[k * n + u];
            }
            solve_dependent(&self.band, &self.jv_lu, &self.pivots, &mut self.scratch);
            for k in 0..nc {
                self.b_matrix[k * nu + a] = self.scratch[k];
            }
        }
    }

    /// [`Self::eliminate_dependent`] for one contact (the paper's case): J_v is a scalar, so
    /// B = −J_u / J_v and b = −(c + J_d q̈_d) / J_v without the LU machinery.
    pub(super) fn eliminate_single_dependent(&mut self, partition: &Partition) {
        let row = &self.jacobian[..self.n];
        let inverse = 1.0 / self.jv_lu[0];
        let driven: f64 = partition
            .driven()
            .iter()
            .map(|&d| row[d] * self.qdd[d])
            .sum();
        self.b_vector[0] = -(self.bias[0] + driven) * inverse;
        for (b, &u) in self.b_matrix.iter_mut().zip(partition.independent()) {
            *b = -row[u] * inverse;
        }
    }

    /// q̈ ← g: 0 on u, b on v; q̈_d stays on d.
    pub(super) fn set_particular_acceleration(&mut self, partition: &Partition) {
        for &u in partition.independent() {
            self.qdd[u] = 0.0;
        }
        for (&b, &v) in self.b_vector.iter().zip(partition.dependent()) {
            self.qdd[v] = b;
        }
    }

    /// Reduced mass Tᵀ M T (lower triangle, into `reduced_mass`) and right-hand side
    /// −Tᵀ (M g + F + Q) (into `udd`).
    ///
    /// This is the paper's (18): with T = [I; B] on (u, v) and g = [0; b] (no driven
    /// coordinates), Tᵀ M T = M_uu + M_uv B + Bᵀ M_vu + Bᵀ M_vv B = M*, and
    /// Tᵀ (M g + F + Q) = F_u + M_uv b + Bᵀ (F_v + M_vv b) + Q_u + Bᵀ Q_v = F* + Q*, so the
    /// system reads M* ü + F* + Q* = 0 (checked against the explicit formulas in a test).
    /// Driven coordinates only add M_·d q̈_d to g's contribution and J_d q̈_d to b.
    pub(super) fn project_dynamics(&mut self, partition: &Partition) {
        if self.nc == 1 {
            self.project_single_dependent(partition);
            return;
        }
        residual_rows(
            &mut self.band.mass_rows,
            &mut self.residual,
            &self.mass,
            &self.qdd,
            &self.inertial,
            &self.applied,
        );
        self.multiply_mass_by_t(partition);
        self.project_on_t(partition);
    }

    /// [`Self::project_dynamics`] for one contact (the paper's case), entry by entry: with
    /// T = [I; b] on (u, v),
    /// M*_ab = M_{u_a u_b} + M_{u_a v} B_b + B_a M_{v u_b} + B_a B_b M_vv and
    /// −Tᵀ r = −(r_{u_a} + B_a r_v), r = M g + F + Q. Plain indexed loops: at n ≈ 4 the
    /// general path's iterator bookkeeping costs more than its arithmetic.
    pub(super) fn project_single_dependent(&mut self, partition: &Partition) {
        let (n, nu) = (self.n, self.nu);
        let v = partition.dependent()[0];
        let independent = partition.independent();
        let mass = &self.mass;
        for i in 0..n {
            let row = &mass[i * n..(i + 1) * n];
            let mut r = self.inertial[i] + self.applied[i] + row[v] * self.qdd[v];
            for &d in partition.driven() {
                r += row[d] * self.qdd[d];
            }
            self.residual[i] = r;
        }
        let b = &self.b_matrix[..nu];
        let m_vv = mass[v * n + v];
        let r_v = self.residual[v];
        for a in 0..nu {
            let u_a = independent[a];
            let (b_a, m_av) = (b[a], mass[u_a * n + v]);
            for c in 0..=a {
                let u_c = independent[c];
                let m_ac = mass[u_a * n + u_c];
                let m_vc = mass[v * n + u_c];
                self.reduced_mass[a * nu + c] = m_ac + m_av * b[c] + b_a * (m_vc + m_vv * b[c]);
            }
            self.udd[a] = -(self.residual[u_a] + b_a * r_v);
        }
    }

    /// `mass_t` = M T (n×nu): column a is M[:, u_a] + Σ_k M[:, v_k] B[k, a], the sum over
    /// the v_k within row i's extent of M (the others' terms are zero).
    pub(super) fn multiply_mass_by_t(&mut self, partition: &Partition) {
        let (n, nu) = (self.n, self.nu);
        let dependent = partition.dependent();
        let sorted = dependent.windows(2).all(|w| w[0] < w[1]);
        for i in 0..n {
            let row = &self.mass[i * n..(i + 1) * n];
            let (first, end) = if sorted {
                self.band.mass_rows.dependent_range(i, dependent)
            } else {
                (0, dependent.len())
            };
            for (a, &u) in partition.independent().iter().enumerate() {
                let coupling: f64 = (first..end)
                    .map(|k| row[dependent[k]] * self.b_matrix[k * nu + a])
                    .sum();
                self.mass_t[i * nu + a] = row[u] + coupling;
            }
        }
    }

    /// Lower triangle of Tᵀ (M T) into `reduced_mass`, −Tᵀ (M g + F + Q) into `udd`.
    pub(super) fn project_on_t(&mut self, partition: &Partition) {
        let nu = self.nu;
        let dependent = partition.dependent();
        for (a, &u) in partition.independent().iter().enumerate() {
            let b_column = |k: usize| self.b_matrix[k * nu + a];
            for b in 0..=a {
                let coupling: f64 = (dependent.iter().enumerate())
                    .map(|(k, &v)| b_column(k) * self.mass_t[v * nu + b])
                    .sum();
                self.reduced_mass[a * nu + b] = self.mass_t[u * nu + b] + coupling;
            }
            let coupling: f64 = (dependent.iter().enumerate())
                .map(|(k, &v)| b_column(k) * self.residual[v])
                .sum();
            self.udd[a] = -(self.residual[u] + coupling);
        }
    }

    /// q̈ = T ü + g.
    pub(super) fn expand_accelerations(&mut self, partition: &Partition) {
        let nu = self.nu;
        for (&udd, &u) in self.udd.iter().zip(partition.independent()) {
            self.qdd[u] = udd;
        }
        for (k, &v) in partition.dependent().iter().enumerate() {
            let row = &self.b_matrix[k * nu..(k + 1) * nu];
            self.qdd[v] += dot(row, &self.udd);
        }
    }
}
