//! The constraint multipliers, the contact normal forces they give and the drive loads,
//! from (14) after the accelerations.

use super::band::{residual_rows, solve_dependent_transposed};
use super::{Partition, Workspace};
use crate::error::SimError;

/// Contact normal force from the multiplier λ_k and the contact's
/// [`ContactGeometry::force_scale`](crate::ContactGeometry::force_scale) |∇_p h|.
///
/// The constraint's generalised force enters (14) as +Jᵀλ on the left, i.e. the cam applies
/// −Jᵀλ. With J = ∇_p h · J_p, where J_p is the Jacobian of the follower's point relative to
/// the cam and ∇_p h the gradient of h with respect to that point, −Jᵀλ = J_pᵀ P with the
/// contact force P = −λ ∇_p h = −λ |∇_p h| n̂, n̂ the unit normal pointing from the cam into
/// the follower. Hence N = P·n̂ = −λ |∇_p h|, positive when the cam pushes the follower. For
/// a knife edge on y = f3(x), h = y − f3(x) and |∇_p h| = √(1 + f3'²); for the kinds whose h
/// is a distance, 1.
pub fn normal_force(lambda: f64, force_scale: f64) -> f64 {
    -lambda * force_scale
}

impl Workspace {
    /// Multipliers and drive loads from (14), after [`Self::solve_accelerations`]:
    /// J_vᵀ λ = −(M q̈ + F + Q)_v, then τ_d = (M q̈ + F + Q + Jᵀλ)_d (zero elsewhere).
    pub fn solve_multipliers(&mut self, partition: &Partition, t: f64) -> Result<(), SimError> {
        if self.articulated.solved {
            // The articulated route solved λ and the drive loads with the accelerations.
            return Ok(());
        }
        residual_rows(
            &mut self.band.mass_rows,
            &mut self.residual,
            &self.mass,
            &self.qdd,
            &self.inertial,
            &self.applied,
        );
        for (lambda, &v) in self.lambda.iter_mut().zip(partition.dependent()) {
            *lambda = -self.residual[v];
        }
        solve_dependent_transposed(&self.band, &self.jv_lu, &self.pivots, &mut self.lambda);
        if self.lambda.iter().any(|x| !x.is_finite()) {
            return Err(self.non_finite(t, "λ"));
        }
        self.drive.fill(0.0);
        for &d in partition.driven() {
            let constraint: f64 = (0..self.nc)
                .map(|k| self.jacobian[k * self.n + d] * self.lambda[k])
                .sum();
            self.drive[d] = self.residual[d] + constraint;
        }
        if self.drive.iter().any(|x| !x.is_finite()) {
            return Err(self.non_finite(t, "drive load"));
        }
        Ok(())
    }

    /// Power of the drive loads Σ τ_d q̇_d (after [`Self::solve_multipliers`]).
    pub fn drive_power(&self, partition: &Partition) -> f64 {
        partition
            .driven()
            .iter()
            .map(|&d| self.drive[d] * self.qd[d])
            .sum()
    }
}
