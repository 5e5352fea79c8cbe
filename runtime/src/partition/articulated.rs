//! The acceleration level by the articulated-body sweeps (docs/method.md §14), for models
//! that provide them ([`Dynamics::articulated_len`]): no mass matrix is formed.
//!
//! `articulated_terms` gives q̈⁰, the free coordinates' accelerations without constraint
//! forces (the driven ones prescribed), and the drive loads τ⁰ at q̈⁰. Each solved
//! constraint row k then gets its response A_k = M_ff⁻¹ (−J_kᵀ) (and its driven rows
//! M_df A_k), so that with (14), M q̈ + F + Q + Jᵀ λ = τ,
//!
//! ```text
//! q̈_f = q̈⁰_f + Σ_k λ_k A_k,   (J A) λ = −(J q̈⁰ + c)   (J q̈ + c = 0, eq. 8)
//! τ_d = τ⁰_d + Σ_k λ_k (M_df A_k + J_kd)
//! ```
//!
//! A model of one constraint row ([`Dynamics::articulated_rows`] = 1) solves it within its
//! sweeps instead (§14.6): given J's row, `articulated_terms` returns q̈, λ and the drive
//! loads with the row's force, and no response is formed here.
//!
//! −J A = J_f M_ff⁻¹ J_fᵀ is symmetric positive definite whenever the solved rows are
//! independent on the free coordinates, which the partition guarantees: it solves only rows
//! whose J_v, a square block of J_f, is invertible (redundant rows are left out, their
//! multipliers zero). So no regularisation is needed; at a singular position, where J_v
//! degenerates, the partition's own re-partitioning and errors apply unchanged.

use super::linalg::{all_finite, cholesky_factor, cholesky_solve, dot};
use super::{Partition, Workspace};
use crate::dynamics::{ArticulatedTerms, Dynamics, SolvedRow};
use crate::error::SimError;

impl Workspace {
    /// Uses the articulated-body sweeps when the model provides them (`true`, the default)
    /// or always the dense route (`false`): for comparisons of the two.
    pub fn use_articulated(&mut self, on: bool) {
        self.articulated.enabled = on;
    }

    /// True when the next right-hand side of `model` takes the articulated route.
    pub fn articulated_route(&self, model: &dyn Dynamics) -> bool {
        self.articulated.enabled && model.articulated_len() > 0
    }

    /// The articulated counterpart of the dense reduction: q̈, ü, λ and the drive loads at
    /// the state, with the position level already evaluated (as for
    /// [`Self::solve_accelerations`]).
    pub(super) fn solve_articulated(
        &mut self,
        model: &dyn Dynamics,
        partition: &Partition,
        t: f64,
    ) -> Result<(), SimError> {
        let (n, nc) = (self.n, self.nc);
        let b = &mut self.articulated;
        let len = model.articulated_len();
        if b.factors.len() != len {
            b.factors.resize(len, 0.0);
        }
        let all_rows = self.m == self.nc;
        // A model of one row solves it within its sweeps when it is solved here (§14.6).
        let within = self.m == 1 && model.articulated_rows() == 1;
        if !within {
            b.responses.resize(nc * n, 0.0);
            b.response_drive.resize(nc * n, 0.0);
            b.delassus.resize(nc * nc, 0.0);
            b.tau.resize(n, 0.0);
        }
        let mut solved = SolvedRow::default();
        self.drive.fill(0.0);
        let out = ArticulatedTerms {
            qdd: &mut self.qdd,
            drive: &mut self.drive,
            bias: if all_rows {
                &mut self.bias
            } else {
                &mut self.full_bias
            },
            // The response, which reads the factors, is called for no row when the row is
            // solved within or none is solved.
            factors: if within || nc == 0 {
                &mut []
            } else {
                &mut b.factors
            },
            row: if within && nc == 1 {
                &self.jacobian[..n]
            } else {
                &[]
            },
            solved: &mut solved,
        };
        model.articulated_terms(t, &self.q, &self.qd, &self.cache, out);
        if within {
            if nc == 1 {
                // As the Cholesky factorisation below checks its pivot.
                if !(solved.delassus > 0.0 && solved.delassus.is_finite()) {
                    return Err(self.singular(t));
                }
                self.lambda[0] = solved.lambda;
            }
            return self.accelerations_solved(t);
        }
        if !all_rows {
            for (k, &row) in self.rows.iter().enumerate() {
                self.bias[k] = self.full_bias[row];
            }
        }
        for k in 0..nc {
            let row = &self.jacobian[k * n..(k + 1) * n];
            for (tau, &j) in b.tau.iter_mut().zip(row) {
                *tau = -j;
            }
            let (qdd, drive) = (
                &mut b.responses[k * n..(k + 1) * n],
                &mut b.response_drive[k * n..(k + 1) * n],
            );
            model.articulated_response(&b.factors, &b.tau, qdd, drive);
            for &d in partition.driven() {
                qdd[d] = 0.0;
            }
        }
        // −J A λ = J q̈⁰ + c, row by row of the solved constraints.
        for j in 0..nc {
            let row = &self.jacobian[j * n..(j + 1) * n];
            for k in 0..=j {
                let entry = -dot(row, &b.responses[k * n..(k + 1) * n]);
                b.delassus[j * nc + k] = entry;
                b.delassus[k * nc + j] = entry;
            }
            self.lambda[j] = dot(row, &self.qdd) + self.bias[j];
        }
        if nc > 0 && !cholesky_factor(&mut b.delassus, nc) {
            return Err(self.singular(t));
        }
        cholesky_solve(&b.delassus, nc, &mut self.lambda);
        for (k, &lambda) in self.lambda.iter().enumerate() {
            let response = &b.responses[k * n..(k + 1) * n];
            for (qdd, &a) in self.qdd.iter_mut().zip(response) {
                *qdd += lambda * a;
            }
            let row = &self.jacobian[k * n..(k + 1) * n];
            for &d in partition.driven() {
                self.drive[d] += lambda * (b.response_drive[k * n + d] + row[d]);
            }
        }
        self.accelerations_solved(t)
    }

    /// The checks of q̈, λ and the drive loads, once the articulated route has solved them.
    /// (ü is read from q̈ by the callers; the dense route's `udd` is its own scratch.)
    fn accelerations_solved(&mut self, t: f64) -> Result<(), SimError> {
        self.articulated.solved = true;
        if !all_finite(&self.qdd) {
            return Err(self.non_finite(t, "q̈"));
        }
        if !all_finite(&self.lambda) {
            return Err(self.non_finite(t, "λ"));
        }
        if !all_finite(&self.drive) {
            return Err(self.non_finite(t, "drive load"));
        }
        Ok(())
    }
}
