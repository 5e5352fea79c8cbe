//! Generalised coordinate partitioning (Haug & Yen) and the reduced dynamics, eqs. (15)–(18).
//!
//! The coordinates are split into driven ones d (prescribed functions of time), independent
//! ones u (integrated) and dependent ones v (one per contact, recovered from the
//! constraints). With the constraint `h(q) = 0` (3), its Jacobian J (5b) and the bias c of
//! `J q̈ + c = 0` (7, 8):
//!
//! - positions (15): v solves h(q_d, u, v) = 0 (Newton on v);
//! - velocities (16): v̇ = −J_v⁻¹ (J_u u̇ + J_d q̇_d);
//! - accelerations (16): q̈ = T ü + g, with T (n × nu) = identity on the u rows,
//!   B = −J_v⁻¹ J_u on the v rows, 0 on the d rows, and g = 0 on u, b = −J_v⁻¹ (c + J_d q̈_d)
//!   on v, q̈_d on d;
//! - dynamics (17, 18): premultiplying `M q̈ + F + Q + Jᵀλ = τ` (14) by Tᵀ removes λ (since
//!   J T = J_u + J_v B = 0) and the drive loads τ (zero on the u and v rows, where Tᵀ
//!   reads):  (Tᵀ M T) ü = −Tᵀ (M g + F + Q).
//!
//! Everything works in a preallocated [`Workspace`]; no step allocates.

mod articulated;
mod band;
mod choice;
mod linalg;
mod multipliers;
mod newton;
mod reduced;
mod sets;
mod workspace;

pub use choice::{
    REDUNDANT_PIVOT, REPARTITION_RATIO, choose_dependent, conditioning, independent_rows,
};
pub(crate) use linalg::all_finite;
pub use multipliers::normal_force;
pub use newton::{
    NEWTON_MAX_ITERATIONS, NEWTON_RESIDUAL_TOLERANCE, NEWTON_SLACK_PER_RTOL,
    NEWTON_STALL_TOLERANCE, NEWTON_STEP_TOLERANCE, ROW_SHRINK,
};
pub use sets::Partition;
pub use workspace::Workspace;

#[cfg(test)]
mod tests;
