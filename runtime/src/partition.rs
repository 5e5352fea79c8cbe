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

use crate::dynamics::{Dynamics, VelocityTerms};
use crate::error::SimError;
use std::sync::Arc;

/// Re-partition threshold on [`conditioning`]: the dependent coordinates are re-chosen after
/// a step when the ratio falls below it.
///
/// Why 0.2: the entries of B = −J_v⁻¹ J_u (one contact) are bounded by ‖J‖/|J_v| = 1/ratio,
/// so 0.2 keeps the amplification of u̇ into v̇ (16), and of Newton's start error (15), below
/// 5. On the other side, for one contact the greedy choice always yields |J_v| ≥ ‖J‖/√n_e
/// (the largest of n_e entries is at least their RMS), i.e. a ratio ≥ 0.2 for up to 25
/// eligible coordinates: a fresh partition does not immediately fall below the threshold
/// again, so the switch has hysteresis and cannot chatter (and a switch is made only when
/// it improves the ratio). Waiting until the ratio is much smaller would let Newton (15)
/// lose accuracy and the step size drop near J_v = 0.
pub const REPARTITION_RATIO: f64 = 0.2;

/// Newton (15) converges when max_k |h_k| is at most this times the model's length scale
/// (m, or rad for angular constraints): 1e-12 is ~10⁴ times the round-off of h for
/// coordinates of order 1. The length scale ([`Workspace::set_length_scale`]: the largest
/// contact-point coordinate at assembly, at least 1) keeps the tolerance that far above the
/// round-off of a model written in millimetres or placed far from the origin.
pub const NEWTON_RESIDUAL_TOLERANCE: f64 = 1e-12;

/// Newton (15) also requires its last correction to be at most this times (1 + ‖v‖∞).
pub const NEWTON_STEP_TOLERANCE: f64 = 1e-12;

/// Entries of J below this times the model's length scale are round-off
/// ([`Workspace::jacobian_floor`]).
const JACOBIAN_FLOOR: f64 = 1e-12;

/// Newton (15) also stops, |h| being at its tolerance, when its corrections no longer shrink
/// (round-off near a singular position, docs/method.md §11.4) and are at most this times
/// (1 + ‖v‖∞) and the partition's conditioning is not degenerate (`STALL_CONDITIONING`, 0.05):
/// 1e-8, far above the 1e-12 of [`NEWTON_STEP_TOLERANCE`] that such a floor can exceed.
pub const NEWTON_STALL_TOLERANCE: f64 = 1e-8;

/// A stalled Newton (15) is accepted only where the partition's conditioning is at least
/// this: at a dead point J_v vanishes alone and the conditioning goes to 0, so Newton fails
/// there as it should, naming the dead point.
const STALL_CONDITIONING: f64 = 0.05;

/// In an adaptive run at relative tolerance rtol, Newton (15) also stops when the next
/// correction is at most this times rtol·(1 + ‖v‖∞) ([`Workspace::set_newton_slack`]).
pub const NEWTON_SLACK_PER_RTOL: f64 = 1e-2;

/// Newton (15) gives up after this many corrections.
pub const NEWTON_MAX_ITERATIONS: usize = 25;

/// Damped Newton (assembly fallback) gives up after this many corrections.
const DAMPED_MAX_ITERATIONS: usize = 200;

/// Smallest step fraction tried by the damped Newton's backtracking.
const DAMPED_MIN_FRACTION: f64 = 1e-10;

/// Pivots below this fraction of max |J_ij| count as zero when choosing the dependent
/// coordinates: such a column would amplify round-off by more than 10¹².
const NEGLIGIBLE_PIVOT: f64 = 1e-12;

/// A pivot of J at or below this fraction of max |J_ij| marks its row as redundant: the
/// equation is implied by the others ([`independent_rows`]). 1e-8 is far above the round-off
/// of a consistent redundant set (~1e-15 relative) and far below any pivot of a mechanism away
/// from a singular position; an initial guess this close to a singular position is reported
/// rather than trusted (assembly checks the rank again at the solution).
pub const REDUNDANT_PIVOT: f64 = 1e-8;

/// The largest set of independent rows of the m×n Jacobian `j` and as many dependent columns
/// among the `eligible` ones, by Gaussian elimination with complete pivoting: each pivot is
/// the largest remaining entry; elimination stops when it is at most [`REDUNDANT_PIVOT`]
/// times max |J_ij| or at most `floor` (entries that small are round-off, not a lever arm:
/// [`Workspace::jacobian_floor`]). Returns (rows, columns), each in increasing order; rows
/// left out are redundant (implied by the chosen ones to first order), and `rows.len()` is
/// the rank.
pub fn independent_rows(
    j: &[f64],
    m: usize,
    n: usize,
    eligible: &[bool],
    floor: f64,
) -> (Vec<usize>, Vec<usize>) {
    let scale = j.iter().fold(0.0_f64, |acc, x| acc.max(x.abs()));
    let mut a = j.to_vec();
    let mut row_done = vec![false; m];
    let mut column_used = vec![false; n];
    let (mut rows, mut columns) = (Vec::new(), Vec::new());
    if !scale.is_finite() || scale == 0.0 {
        return (rows, columns);
    }
    for _ in 0..m {
        let Some((row, column, pivot)) = largest_entry(&a, n, &row_done, &column_used, eligible)
        else {
            break;
        };
        if pivot.abs() <= (REDUNDANT_PIVOT * scale).max(floor) {
            break;
        }
        eliminate_column(&mut a, n, row, column, &row_done);
        row_done[row] = true;
        column_used[column] = true;
        rows.push(row);
        columns.push(column);
    }
    rows.sort_unstable();
    columns.sort_unstable();
    (rows, columns)
}

/// Chooses the dependent coordinates: nc column indices of the row-major nc×n Jacobian `j`,
/// among the `eligible` ones, such that J_v is well conditioned.
///
/// For one contact, the eligible column with the largest |J_i|; for several, greedy
/// Gaussian elimination with complete pivoting restricted to the eligible columns (each
/// pivot is the largest remaining entry; its column becomes dependent). Returns the indices
/// in increasing order, or `None` when no eligible set gives an invertible J_v (a pivot is
/// zero, negligible, or J is not finite).
pub fn choose_dependent(j: &[f64], nc: usize, n: usize, eligible: &[bool]) -> Option<Vec<usize>> {
    let scale = j.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if !scale.is_finite() || j.iter().any(|x| x.is_nan()) {
        return None;
    }
    let mut a = j.to_vec();
    let mut row_done = vec![false; nc];
    let mut column_used = vec![false; n];
    let mut chosen = Vec::with_capacity(nc);
    for _ in 0..nc {
        let (row, column, pivot) = largest_entry(&a, n, &row_done, &column_used, eligible)?;
        if pivot.abs() <= NEGLIGIBLE_PIVOT * scale {
            return None;
        }
        eliminate_column(&mut a, n, row, column, &row_done);
        row_done[row] = true;
        column_used[column] = true;
        chosen.push(column);
    }
    chosen.sort_unstable();
    Some(chosen)
}

/// Largest |a_rc| over rows not done and eligible, unused columns (first one on ties).
fn largest_entry(
    a: &[f64],
    n: usize,
    row_done: &[bool],
    column_used: &[bool],
    eligible: &[bool],
) -> Option<(usize, usize, f64)> {
    let mut best: Option<(usize, usize, f64)> = None;
    for (r, _) in row_done.iter().enumerate().filter(|(_, done)| !**done) {
        for c in (0..n).filter(|&c| eligible[c] && !column_used[c]) {
            let value = a[r * n + c];
            if best.is_none_or(|(_, _, b)| value.abs() > b.abs()) {
                best = Some((r, c, value));
            }
        }
    }
    best
}

/// Subtracts multiples of the pivot row from the other open rows to zero the pivot column.
fn eliminate_column(a: &mut [f64], n: usize, pivot_row: usize, column: usize, row_done: &[bool]) {
    let pivot = a[pivot_row * n + column];
    for r in (0..row_done.len()).filter(|&r| r != pivot_row && !row_done[r]) {
        let factor = a[r * n + column] / pivot;
        for c in 0..n {
            a[r * n + c] -= factor * a[pivot_row * n + c];
        }
    }
}

/// Conditioning of a partition, in [0, 1]: for one constraint |J_v| / ‖J_eligible‖₂; for m
/// constraints the m-th root of the Hadamard ratio |det J_v| / Π_k ‖(row k of J)_eligible‖₂,
/// the geometric mean of what each row keeps, so that one threshold
/// ([`REPARTITION_RATIO`]) means the same for 1 and for 80 equations (the ratio itself is a
/// product over the rows and shrinks with their number: a well-chosen partition of an
/// N-four-bar's 80 equations has a ratio far below 0.2 everywhere). Invariant under the
/// scaling of a row, as a singular configuration that shrinks whole rows (an N-four-bar
/// passing its horizontal position) does. 1 means J_v carries the whole constraint
/// gradient; 0 means J_v is singular. Returns 1 without constraints.
pub fn conditioning(j: &[f64], nc: usize, n: usize, dependent: &[usize], eligible: &[bool]) -> f64 {
    if nc == 0 {
        return 1.0;
    }
    if nc == 1 {
        let squares: f64 = (0..n).filter(|&i| eligible[i]).map(|i| j[i] * j[i]).sum();
        let ratio = j[dependent[0]].abs() / squares.sqrt();
        return if ratio.is_finite() { ratio } else { 0.0 };
    }
    // In logarithms: for tens of rows the product of the row norms and det J_v leave the
    // range of f64.
    let mut log_norms = 0.0;
    for row in (0..nc).map(|k| &j[k * n..(k + 1) * n]) {
        let squares: f64 = (0..n)
            .filter(|&i| eligible[i])
            .map(|i| row[i] * row[i])
            .sum();
        log_norms += 0.5 * squares.ln();
    }
    let ratio = ((dependent_log_determinant(j, nc, n, dependent) - log_norms) / nc as f64).exp();
    if ratio.is_finite() { ratio } else { 0.0 }
}

/// ln |det J_v| (nc ≤ 4 without allocating); −∞ when J_v is singular.
fn dependent_log_determinant(j: &[f64], nc: usize, n: usize, dependent: &[usize]) -> f64 {
    let mut stack = [0.0; 16];
    let mut pivots_stack = [0; 4];
    let mut heap = Vec::new();
    let mut heap_pivots = Vec::new();
    let (a, pivots) = if nc <= 4 {
        (&mut stack[..nc * nc], &mut pivots_stack[..nc])
    } else {
        heap.resize(nc * nc, 0.0);
        heap_pivots.resize(nc, 0);
        (&mut heap[..], &mut heap_pivots[..])
    };
    gather_columns(j, n, dependent, a);
    if lu_factor(a, pivots, nc, 0.0) {
        (0..nc).map(|k| a[k * nc + k].abs().ln()).sum()
    } else {
        f64::NEG_INFINITY
    }
}

/// `out` (nc×nc, row-major) = the columns `columns` of the nc×n matrix `j`.
fn gather_columns(j: &[f64], n: usize, columns: &[usize], out: &mut [f64]) {
    let nc = columns.len();
    for k in 0..nc {
        for (l, &column) in columns.iter().enumerate() {
            out[k * nc + l] = j[k * n + column];
        }
    }
}

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

/// The split of the coordinates into driven, independent and dependent sets.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Partition {
    contacts: usize,
    driven: Vec<usize>,
    independent: Vec<usize>,
    /// Shared with every sample taken under this partition (a counter increment per
    /// sample instead of an allocation).
    dependent: Arc<[usize]>,
    eligible: Vec<bool>,
}

impl Partition {
    /// Partition with `driven_flags[i]` true for the driven coordinates and the given
    /// dependent ones; every other coordinate is independent (in increasing order, which is
    /// the order of u in the integrated state).
    pub fn new(driven_flags: &[bool], dependent: &[usize]) -> Result<Self, SimError> {
        let mut partition = Self {
            contacts: dependent.len(),
            driven: (0..driven_flags.len())
                .filter(|&i| driven_flags[i])
                .collect(),
            independent: Vec::with_capacity(driven_flags.len()),
            dependent: Arc::from(dependent),
            eligible: driven_flags.iter().map(|d| !d).collect(),
        };
        partition.set_dependent(dependent)?;
        Ok(partition)
    }

    /// Replaces the dependent set (same size: one per contact); the independent set follows.
    /// Fails when an index is out of range, repeated or driven.
    pub fn set_dependent(&mut self, dependent: &[usize]) -> Result<(), SimError> {
        self.validate_dependent(dependent)?;
        self.dependent = Arc::from(dependent);
        self.independent.clear();
        let n = self.eligible.len();
        let is_free = |i: &usize| self.eligible[*i] && !dependent.contains(i);
        self.independent.extend((0..n).filter(is_free));
        Ok(())
    }

    fn validate_dependent(&self, dependent: &[usize]) -> Result<(), SimError> {
        let n = self.eligible.len();
        let invalid = |message: String| Err(SimError::InvalidSettings { message });
        if dependent.len() != self.contacts {
            return invalid(format!(
                "{} dependent coordinates given, the model has {} contacts",
                dependent.len(),
                self.contacts
            ));
        }
        for (k, &i) in dependent.iter().enumerate() {
            if i >= n || !self.eligible[i] || dependent[..k].contains(&i) {
                return invalid(format!(
                    "dependent coordinate {i} is out of range, driven or repeated"
                ));
            }
        }
        Ok(())
    }

    /// Number of coordinates.
    pub fn n(&self) -> usize {
        self.eligible.len()
    }

    /// Driven coordinates d (increasing).
    pub fn driven(&self) -> &[usize] {
        &self.driven
    }

    /// Independent coordinates u (increasing): the integrated ones.
    pub fn independent(&self) -> &[usize] {
        &self.independent
    }

    /// Dependent coordinates v, one per contact: recovered by (15), (16).
    pub fn dependent(&self) -> &[usize] {
        &self.dependent
    }

    /// The dependent coordinates as a shared slice (what a [`crate::Sample`] records).
    pub fn dependent_shared(&self) -> Arc<[usize]> {
        Arc::clone(&self.dependent)
    }

    /// `eligible()[i]`: coordinate i may be dependent (it is not driven).
    pub fn eligible(&self) -> &[bool] {
        &self.eligible
    }
}

/// Preallocated buffers for the partitioned dynamics of one model (n coordinates, nc
/// contacts, nu independent coordinates). The kernels below read and write the full state
/// `q`, `q̇`, `q̈` held here.
#[derive(Debug, Clone)]
pub struct Workspace {
    n: usize,
    nc: usize,
    nu: usize,
    /// The model's number of constraints m (≥ nc).
    m: usize,
    /// The rows of the model's h that are solved (nc of the m, increasing): all of them
    /// unless some are redundant ([`independent_rows`]).
    rows: Vec<usize>,
    /// h, J and c of all m rows, when some are left out (empty otherwise).
    full_h: Vec<f64>,
    full_jacobian: Vec<f64>,
    full_bias: Vec<f64>,
    pub(crate) q: Vec<f64>,
    pub(crate) qd: Vec<f64>,
    pub(crate) qdd: Vec<f64>,
    /// v at the last accepted step: Newton's restart point.
    pub(crate) v_anchor: Vec<f64>,
    mass: Vec<f64>,
    inertial: Vec<f64>,
    applied: Vec<f64>,
    residual: Vec<f64>,
    pub(crate) jacobian: Vec<f64>,
    bias: Vec<f64>,
    pub(crate) h: Vec<f64>,
    /// q-only values `position_terms` hands to `velocity_terms` (sines, cosines, …).
    cache: Vec<f64>,
    jv_lu: Vec<f64>,
    pivots: Vec<usize>,
    scratch: Vec<f64>,
    saved_v: Vec<f64>,
    b_matrix: Vec<f64>,
    b_vector: Vec<f64>,
    mass_t: Vec<f64>,
    reduced_mass: Vec<f64>,
    udd: Vec<f64>,
    pub(crate) lambda: Vec<f64>,
    pub(crate) drive: Vec<f64>,
    /// The lengths of the model (≥ 1): scales Newton's residual tolerance.
    length_scale: f64,
    /// A next correction at most this times (1 + ‖v‖∞) ends Newton too (0: strict).
    newton_slack: f64,
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
        }
    }

    /// Solves only the rows `rows` (increasing, nc of them) of a model with `m` constraints:
    /// the others are redundant. h, J and c are evaluated for all m rows and the chosen
    /// ones gathered; the multipliers of the others are zero.
    pub fn select_rows(&mut self, m: usize, rows: &[usize]) {
        self.m = m;
        self.rows = rows.to_vec();
        if m == self.nc {
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
    fn gather_rows(&mut self) {
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
    fn evaluate_h<D: Dynamics + ?Sized>(&mut self, model: &D) {
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
    pub fn evaluate_constraints<D: Dynamics + ?Sized>(&mut self, model: &D) {
        if self.m == self.nc {
            model.constraint(&self.q, &mut self.h);
            model.constraint_jacobian(&self.q, &mut self.jacobian);
        } else {
            model.constraint(&self.q, &mut self.full_h);
            model.constraint_jacobian(&self.q, &mut self.full_jacobian);
            self.gather_rows();
        }
    }

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

    /// Sets the model's length scale (the largest contact-point coordinate, in the model's
    /// length unit), which multiplies [`NEWTON_RESIDUAL_TOLERANCE`]; values below 1 count
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

    /// Newton's residual tolerance for this model: [`NEWTON_RESIDUAL_TOLERANCE`] times the
    /// length scale.
    pub fn residual_tolerance(&self) -> f64 {
        NEWTON_RESIDUAL_TOLERANCE * self.length_scale
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
    pub fn solve_positions<D: Dynamics + ?Sized>(
        &mut self,
        model: &D,
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
    fn well_conditioned(&self, dependent: &[usize]) -> bool {
        let all = vec![true; self.n];
        conditioning(&self.jacobian, self.nc, self.n, dependent, &all) >= STALL_CONDITIONING
    }

    /// Assembly fallback for (15): Newton with backtracking on ‖h‖₂ (Armijo condition),
    /// for starting points where plain Newton overshoots.
    pub fn solve_positions_damped<D: Dynamics + ?Sized>(
        &mut self,
        model: &D,
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
    fn backtracking_step<D: Dynamics + ?Sized>(
        &mut self,
        model: &D,
        dependent: &[usize],
        t: f64,
        residual: f64,
        iterations: usize,
    ) -> Result<f64, SimError> {
        let norm = euclidean(&self.h);
        self.scratch.copy_from_slice(&self.h);
        lu_solve(&self.jv_lu, &self.pivots, self.nc, &mut self.scratch);
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
    fn factor_jacobian_for_newton<D: Dynamics + ?Sized>(
        &mut self,
        _model: &D,
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
    fn constraint_residual<D: Dynamics + ?Sized>(
        &mut self,
        model: &D,
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

    fn converged(&self, residual: f64, last_correction: f64, dependent: &[usize]) -> bool {
        residual <= self.residual_tolerance()
            && last_correction <= NEWTON_STEP_TOLERANCE * (1.0 + self.v_size(dependent))
    }

    /// ‖v‖∞, the scale of the step tolerance.
    fn v_size(&self, dependent: &[usize]) -> f64 {
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
    /// away, which the velocity and acceleration levels tolerate.
    pub fn polish_positions(&mut self, dependent: &[usize]) {
        self.apply_correction(dependent);
    }

    /// J_v⁻¹ h (J_v factored, h evaluated) into the scratch vector, not applied yet;
    /// returns its size max |Δv|.
    fn pending_correction(&mut self, dependent: &[usize]) -> f64 {
        if let ([_], [h], [j_v]) = (dependent, &self.h[..], &self.jv_lu[..]) {
            // One contact: J_v is a number.
            self.scratch[0] = h / j_v;
            return self.scratch[0].abs();
        }
        self.scratch.copy_from_slice(&self.h);
        lu_solve(&self.jv_lu, &self.pivots, self.nc, &mut self.scratch);
        max_abs(&self.scratch)
    }

    /// v ← v − Δv with the correction of [`Self::pending_correction`].
    fn apply_correction(&mut self, dependent: &[usize]) {
        for (&dv, &v) in self.scratch.iter().zip(dependent) {
            self.q[v] -= dv;
        }
    }

    /// Why Newton stopped without converging: the contact point cannot reach the cam (h
    /// has not converged), or — h at its tolerance but the corrections h / J_v still large,
    /// J_v vanishing — the mechanism locks at a dead point.
    fn newton_failure(&self, t: f64, residual: f64, iterations: usize) -> SimError {
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

    pub(crate) fn non_finite(&self, t: f64, quantity: &'static str) -> SimError {
        SimError::NonFinite {
            t,
            quantity,
            q: self.q.clone(),
            qd: self.qd.clone(),
        }
    }

    /// h, J and the cache at the current q, by one [`Dynamics::position_terms`] call.
    fn evaluate_position_terms<D: Dynamics + ?Sized>(&mut self, model: &D) {
        let len = model.cache_len();
        if self.cache.len() != len {
            self.cache.resize(len, f64::NAN);
        }
        if self.m == self.nc {
            model.position_terms(&self.q, &mut self.h, &mut self.jacobian, &mut self.cache);
        } else {
            model.position_terms(
                &self.q,
                &mut self.full_h,
                &mut self.full_jacobian,
                &mut self.cache,
            );
            self.gather_rows();
        }
    }

    /// Evaluates h and J(q) (5b) and factors J_v (the `dependent` columns).
    pub fn factor_jacobian<D: Dynamics + ?Sized>(
        &mut self,
        model: &D,
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
        if self.jacobian.iter().any(|x| !x.is_finite()) {
            return Err(self.non_finite(t, "J"));
        }
        gather_columns(&self.jacobian, self.n, dependent, &mut self.jv_lu);
        let floor = self.jacobian_floor();
        if lu_factor(&mut self.jv_lu, &mut self.pivots, self.nc, floor) {
            Ok(())
        } else {
            Err(self.singular(t))
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

    /// Eq. (16), velocity level: v̇ = −J_v⁻¹ (J_u u̇ + J_d q̇_d), i.e. the v̇ making J q̇ = 0.
    /// Needs [`Self::factor_jacobian`] at the current q.
    pub fn solve_velocities(&mut self, dependent: &[usize]) {
        if let [v] = dependent {
            // One contact: v̇ = −(Σ_{i≠v} J_i q̇_i) / J_v.
            let row = &self.jacobian[..self.n];
            let mut sum = 0.0;
            for (i, (&j, &qd)) in row.iter().zip(&self.qd).enumerate() {
                if i != *v {
                    sum += j * qd;
                }
            }
            self.qd[*v] = -sum / self.jv_lu[0];
            return;
        }
        for &v in dependent {
            self.qd[v] = 0.0;
        }
        for k in 0..self.nc {
            let row = &self.jacobian[k * self.n..(k + 1) * self.n];
            self.scratch[k] = -dot(row, &self.qd);
        }
        lu_solve(&self.jv_lu, &self.pivots, self.nc, &mut self.scratch);
        for (&vd, &v) in self.scratch.iter().zip(dependent) {
            self.qd[v] = vd;
        }
    }

    /// Eqs. (16)–(18): evaluates M, F, Q and c at (t, q, q̇) and solves the reduced dynamics
    /// for ü; writes q̈ = T ü + g. Needs the position level evaluated at the current q
    /// ([`Self::factor_jacobian`], or [`Self::solve_positions`] then
    /// [`Self::factor_current_jacobian`]: J factored and the cache filled) and q̈_d
    /// in the driven entries of q̈ (from [`Dynamics::prescribed`]).
    pub fn solve_accelerations<D: Dynamics + ?Sized>(
        &mut self,
        model: &D,
        partition: &Partition,
        t: f64,
    ) -> Result<(), SimError> {
        // One call: generated models share the kinematics between M, F, Q and c, and take
        // the sines and cosines from the position level.
        let all_rows = self.m == self.nc;
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
    fn reduce_and_solve(&mut self, partition: &Partition, t: f64) -> Result<(), SimError> {
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
    fn reduce_single<const NU: usize>(&mut self, partition: &Partition) -> bool {
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

    fn not_positive_definite(&self, t: f64) -> SimError {
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
    fn eliminate_dependent(&mut self, partition: &Partition) {
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
        lu_solve(&self.jv_lu, &self.pivots, nc, &mut self.b_vector);
        for (a, &u) in partition.independent().iter().enumerate() {
            for k in 0..nc {
                self.scratch[k] = -self.jacobian[k * n + u];
            }
            lu_solve(&self.jv_lu, &self.pivots, nc, &mut self.scratch);
            for k in 0..nc {
                self.b_matrix[k * nu + a] = self.scratch[k];
            }
        }
    }

    /// [`Self::eliminate_dependent`] for one contact (the paper's case): J_v is a scalar, so
    /// B = −J_u / J_v and b = −(c + J_d q̈_d) / J_v without the LU machinery.
    fn eliminate_single_dependent(&mut self, partition: &Partition) {
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
    fn set_particular_acceleration(&mut self, partition: &Partition) {
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
    fn project_dynamics(&mut self, partition: &Partition) {
        if self.nc == 1 {
            self.project_single_dependent(partition);
            return;
        }
        residual_into(
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
    fn project_single_dependent(&mut self, partition: &Partition) {
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

    /// `mass_t` = M T (n×nu): column a is M[:, u_a] + Σ_k M[:, v_k] B[k, a].
    fn multiply_mass_by_t(&mut self, partition: &Partition) {
        let (n, nu) = (self.n, self.nu);
        for i in 0..n {
            let row = &self.mass[i * n..(i + 1) * n];
            for (a, &u) in partition.independent().iter().enumerate() {
                let coupling: f64 = (partition.dependent().iter().enumerate())
                    .map(|(k, &v)| row[v] * self.b_matrix[k * nu + a])
                    .sum();
                self.mass_t[i * nu + a] = row[u] + coupling;
            }
        }
    }

    /// Lower triangle of Tᵀ (M T) into `reduced_mass`, −Tᵀ (M g + F + Q) into `udd`.
    fn project_on_t(&mut self, partition: &Partition) {
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
    fn expand_accelerations(&mut self, partition: &Partition) {
        let nu = self.nu;
        for (&udd, &u) in self.udd.iter().zip(partition.independent()) {
            self.qdd[u] = udd;
        }
        for (k, &v) in partition.dependent().iter().enumerate() {
            let row = &self.b_matrix[k * nu..(k + 1) * nu];
            self.qdd[v] += dot(row, &self.udd);
        }
    }

    /// Multipliers and drive loads from (14), after [`Self::solve_accelerations`]:
    /// J_vᵀ λ = −(M q̈ + F + Q)_v, then τ_d = (M q̈ + F + Q + Jᵀλ)_d (zero elsewhere).
    pub fn solve_multipliers(&mut self, partition: &Partition, t: f64) -> Result<(), SimError> {
        residual_into(
            &mut self.residual,
            &self.mass,
            &self.qdd,
            &self.inertial,
            &self.applied,
        );
        for (lambda, &v) in self.lambda.iter_mut().zip(partition.dependent()) {
            *lambda = -self.residual[v];
        }
        lu_solve_transposed(&self.jv_lu, &self.pivots, self.nc, &mut self.lambda);
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

/// `out = M x + F + Q`.
fn residual_into(out: &mut [f64], mass: &[f64], x: &[f64], inertial: &[f64], applied: &[f64]) {
    let n = out.len();
    for (i, o) in out.iter_mut().enumerate() {
        *o = dot(&mass[i * n..(i + 1) * n], x) + inertial[i] + applied[i];
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(
        0.0_f64,
        |m, v| if v.is_nan() { f64::NAN } else { m.max(v.abs()) },
    )
}

fn euclidean(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// In-place LU factorisation with partial pivoting of the n×n row-major `a` (P A = L U, L
/// unit lower, both stored in `a`; `pivots[k]` is the row swapped with row k at step k).
/// Returns false when a pivot is zero or not finite.
fn lu_factor(a: &mut [f64], pivots: &mut [usize], n: usize, floor: f64) -> bool {
    if n == 1 {
        // One contact (the paper's case): J_v is a number.
        pivots[0] = 0;
        return a[0].abs() > floor && a[0].is_finite();
    }
    for k in 0..n {
        let p = (k..n).fold(k, |best, r| {
            if a[r * n + k].abs() > a[best * n + k].abs() {
                r
            } else {
                best
            }
        });
        pivots[k] = p;
        if p != k {
            for c in 0..n {
                a.swap(k * n + c, p * n + c);
            }
        }
        let pivot = a[k * n + k];
        if pivot.abs() <= floor || !pivot.is_finite() {
            return false;
        }
        for r in k + 1..n {
            let factor = a[r * n + k] / pivot;
            a[r * n + k] = factor;
            for c in k + 1..n {
                a[r * n + c] -= factor * a[k * n + c];
            }
        }
    }
    true
}

/// Solves A x = b in place (`x` holds b on entry), A factored by [`lu_factor`].
fn lu_solve(lu: &[f64], pivots: &[usize], n: usize, x: &mut [f64]) {
    if n == 1 {
        x[0] /= lu[0];
        return;
    }
    for (k, &p) in pivots.iter().enumerate().take(n) {
        x.swap(k, p);
    }
    for r in 0..n {
        let sum: f64 = (0..r).map(|c| lu[r * n + c] * x[c]).sum();
        x[r] -= sum;
    }
    for r in (0..n).rev() {
        let sum: f64 = (r + 1..n).map(|c| lu[r * n + c] * x[c]).sum();
        x[r] = (x[r] - sum) / lu[r * n + r];
    }
}

/// Solves Aᵀ x = b in place, A factored by [`lu_factor`]: Uᵀ z = b, Lᵀ w = z, x = Pᵀ w.
fn lu_solve_transposed(lu: &[f64], pivots: &[usize], n: usize, x: &mut [f64]) {
    for r in 0..n {
        let sum: f64 = (0..r).map(|c| lu[c * n + r] * x[c]).sum();
        x[r] = (x[r] - sum) / lu[r * n + r];
    }
    for r in (0..n).rev() {
        let sum: f64 = (r + 1..n).map(|c| lu[c * n + r] * x[c]).sum();
        x[r] -= sum;
    }
    for k in (0..n).rev() {
        x.swap(k, pivots[k]);
    }
}

/// det of the LU-factored matrix (tests: the factorisation against nalgebra's determinant).
#[cfg(test)]
fn lu_determinant(lu: &[f64], pivots: &[usize], n: usize) -> f64 {
    let swaps = (0..n).filter(|&k| pivots[k] != k).count();
    let product: f64 = (0..n).map(|k| lu[k * n + k]).product();
    if swaps % 2 == 0 { product } else { -product }
}

/// Solves the n×n SPD system `a` x = `x` (lower triangle of `a` read, overwritten by its
/// factor) in place; false when `a` is not positive definite. Sizes up to 6 (every
/// reference model) go through fixed-size code the compiler unrolls: for these 2×2 … 6×6
/// systems the loop and bounds-check bookkeeping of the general code costs more than the
/// arithmetic (callgrind: ~500 instructions for a 3×3 solve).
fn solve_reduced(a: &mut [f64], n: usize, x: &mut [f64]) -> bool {
    match n {
        1 => solve_fixed::<1>(a, x),
        2 => solve_fixed::<2>(a, x),
        3 => solve_fixed::<3>(a, x),
        4 => solve_fixed::<4>(a, x),
        5 => solve_fixed::<5>(a, x),
        6 => solve_fixed::<6>(a, x),
        _ => {
            let ok = cholesky_factor(a, n);
            if ok {
                cholesky_solve(a, n, x);
            }
            ok
        }
    }
}

/// [`solve_reduced`] for a size known at compile time: the same L D Lᵀ as
/// [`cholesky_factor`] and [`cholesky_solve`], on arrays.
fn solve_fixed<const N: usize>(a: &mut [f64], x: &mut [f64]) -> bool {
    let mut l = [[0.0; N]; N];
    for (i, row) in l.iter_mut().enumerate() {
        row[..=i].copy_from_slice(&a[i * N..i * N + i + 1]);
    }
    let mut d = [0.0; N];
    for j in 0..N {
        let mut diagonal = l[j][j];
        for k in 0..j {
            diagonal -= l[j][k] * l[j][k] * d[k];
        }
        if !(diagonal > 0.0 && diagonal.is_finite()) {
            return false;
        }
        d[j] = diagonal;
        let inverse = 1.0 / diagonal;
        for i in j + 1..N {
            let mut sum = l[i][j];
            for k in 0..j {
                sum -= l[i][k] * l[j][k] * d[k];
            }
            l[i][j] = sum * inverse;
        }
    }
    let mut y = [0.0; N];
    y.copy_from_slice(&x[..N]);
    for i in 0..N {
        for k in 0..i {
            y[i] -= l[i][k] * y[k];
        }
    }
    for i in 0..N {
        y[i] /= d[i];
    }
    for i in (0..N).rev() {
        for k in i + 1..N {
            y[i] -= l[k][i] * y[k];
        }
    }
    x[..N].copy_from_slice(&y);
    for (i, row) in l.iter().enumerate() {
        a[i * N..i * N + i].copy_from_slice(&row[..i]);
        a[i * N + i] = d[i];
    }
    true
}

/// Solves `a` x = `rhs` for the SPD `a` (lower triangle read) by L D Lᵀ on arrays; `None`
/// when `a` is not positive definite.
#[allow(clippy::needless_range_loop)] // the indices of the factorisation's formulas
fn solve_ldlt<const N: usize>(a: &mut [[f64; N]; N], rhs: [f64; N]) -> Option<[f64; N]> {
    let mut d = [0.0; N];
    for j in 0..N {
        let mut diagonal = a[j][j];
        for k in 0..j {
            diagonal -= a[j][k] * a[j][k] * d[k];
        }
        if !(diagonal > 0.0 && diagonal.is_finite()) {
            return None;
        }
        d[j] = diagonal;
        let inverse = 1.0 / diagonal;
        for i in j + 1..N {
            let mut sum = a[i][j];
            for k in 0..j {
                sum -= a[i][k] * a[j][k] * d[k];
            }
            a[i][j] = sum * inverse;
        }
    }
    let mut y = rhs;
    for i in 0..N {
        for k in 0..i {
            y[i] -= a[i][k] * y[k];
        }
    }
    for i in 0..N {
        y[i] /= d[i];
    }
    for i in (0..N).rev() {
        for k in i + 1..N {
            y[i] -= a[k][i] * y[k];
        }
    }
    Some(y)
}

/// In-place square-root-free Cholesky A = L D Lᵀ of the n×n row-major `a` (L unit lower),
/// reading and writing the lower triangle only: L below the diagonal, D on it. No square
/// root and one division per column (square roots and chained divisions form the critical
/// path of these tiny systems). Returns false when A is not (numerically) positive
/// definite (some D_jj ≤ 0).
fn cholesky_factor(a: &mut [f64], n: usize) -> bool {
    for j in 0..n {
        let mut diagonal = a[j * n + j];
        for k in 0..j {
            let l_jk = a[j * n + k];
            diagonal -= l_jk * l_jk * a[k * n + k];
        }
        let positive = diagonal > 0.0 && diagonal.is_finite();
        if !positive {
            return false;
        }
        a[j * n + j] = diagonal;
        let inverse = 1.0 / diagonal;
        for i in j + 1..n {
            let mut sum = a[i * n + j];
            for k in 0..j {
                sum -= a[i * n + k] * a[j * n + k] * a[k * n + k];
            }
            a[i * n + j] = sum * inverse;
        }
    }
    true
}

/// Solves A x = b in place with the factor of [`cholesky_factor`]: L y = b, D z = y,
/// Lᵀ x = z (the n divisions are independent of each other).
fn cholesky_solve(l: &[f64], n: usize, x: &mut [f64]) {
    for i in 0..n {
        let sum: f64 = (0..i).map(|k| l[i * n + k] * x[k]).sum();
        x[i] -= sum;
    }
    for (i, xi) in x.iter_mut().enumerate().take(n) {
        *xi /= l[i * n + i];
    }
    for i in (0..n).rev() {
        let sum: f64 = (i + 1..n).map(|k| l[k * n + i] * x[k]).sum();
        x[i] -= sum;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// Deterministic pseudo-random numbers in [−1, 1) (xorshift64*).
    struct Numbers(u64);

    impl Numbers {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            let bits = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
            bits as f64 / (1u64 << 52) as f64 - 1.0
        }

        fn vector(&mut self, len: usize) -> Vec<f64> {
            (0..len).map(|_| self.next()).collect()
        }

        /// Symmetric positive definite n×n: A Aᵀ + n I.
        fn spd(&mut self, n: usize) -> Vec<f64> {
            let a = DMatrix::from_row_slice(n, n, &self.vector(n * n));
            let m = &a * a.transpose() + DMatrix::identity(n, n) * n as f64;
            m.transpose().as_slice().to_vec()
        }
    }

    fn max_difference(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    /// Round-off bound for the dense solves below on well-conditioned data of order 1
    /// (κ ≲ 10², n ≤ 6): κ·n·ε ≈ 1e-13; 1e-11 leaves a margin of 100.
    const SOLVE_TOLERANCE: f64 = 1e-11;

    #[test]
    fn independent_rows_find_the_rank_and_leave_a_combination_out() {
        // Row 2 = row 0 + row 1: rank 2; the pivots are the largest entries (row 2's 4.0
        // in column 1, then row 0's 1.0 after elimination), row 1 left out.
        let j = [1.0, 1.0, 0.0, 0.0, 3.0, 1.0, 1.0, 4.0, 1.0];
        let (rows, columns) = independent_rows(&j, 3, 3, &[true; 3], 0.0);
        assert_eq!(rows.len(), 2);
        assert_eq!(columns.len(), 2);
        // Full rank: every row kept.
        let identity = [1.0, 0.0, 0.0, 1.0];
        assert_eq!(
            independent_rows(&identity, 2, 2, &[true; 2], 0.0).0,
            vec![0, 1]
        );
        // A row of round-off below the floor counts as zero, whatever the scale.
        let tiny = [1e-17, 0.0, 0.0, 2e-17];
        assert!(
            independent_rows(&tiny, 2, 2, &[true; 2], 1e-12)
                .0
                .is_empty()
        );
        // Only eligible columns are pivots.
        let (_, columns) = independent_rows(&[5.0, 1.0], 1, 2, &[false, true], 0.0);
        assert_eq!(columns, vec![1]);
    }

    #[test]
    fn one_contact_picks_the_largest_eligible_entry() {
        let j = [0.5, -3.0, 2.0, 0.1];
        assert_eq!(choose_dependent(&j, 1, 4, &[true; 4]), Some(vec![1]));
        assert_eq!(
            choose_dependent(&j, 1, 4, &[true, false, true, true]),
            Some(vec![2])
        );
        assert_eq!(
            choose_dependent(&j, 1, 4, &[false, true, false, false]),
            Some(vec![1])
        );
        assert_eq!(
            choose_dependent(&[0.0, 0.0, 1.0], 1, 3, &[true, true, false]),
            None
        );
        assert_eq!(
            choose_dependent(&[f64::NAN, 1.0], 1, 2, &[true, true]),
            None
        );
    }

    #[test]
    fn several_contacts_use_complete_pivoting() {
        // The largest entry, 5, makes column 0 dependent; eliminating it leaves row 1 as
        // (0, 1.6 − 0.4·4, 1.5, 0) = (0, 0, 1.5, 0), so column 2 wins although the original
        // |J_11| = 1.6 exceeds 1.5.
        let j = [5.0, 4.0, 0.0, 0.0, 2.0, 1.6, 1.5, 0.0];
        let chosen = choose_dependent(&j, 2, 4, &[true; 4]).unwrap();
        assert_eq!(chosen, vec![0, 2]);
        // Two identical rows: rank 1, no invertible J_v.
        assert_eq!(
            choose_dependent(&[1.0, 2.0, 1.0, 2.0], 2, 2, &[true, true]),
            None
        );
    }

    #[test]
    fn conditioning_is_the_normalised_pivot() {
        let j = [3.0, 4.0, 100.0];
        let eligible = [true, true, false];
        assert!((conditioning(&j, 1, 3, &[1], &eligible) - 0.8).abs() < 1e-15);
        assert!((conditioning(&j, 1, 3, &[0], &eligible) - 0.6).abs() < 1e-15);
        // Orthogonal rows and J_v = the whole of J: Hadamard ratio 1.
        let j2 = [1.0, 1.0, -1.0, 1.0];
        assert!((conditioning(&j2, 2, 2, &[0, 1], &[true, true]) - 1.0).abs() < 1e-15);
        assert_eq!(conditioning(&[], 0, 3, &[], &eligible), 1.0);
    }

    #[test]
    fn lu_and_cholesky_solve_like_nalgebra() {
        let mut numbers = Numbers(7);
        for n in 1..6 {
            let a = numbers.vector(n * n);
            let b = numbers.vector(n);
            let matrix = DMatrix::from_row_slice(n, n, &a);
            let expected = matrix
                .clone()
                .lu()
                .solve(&DVector::from_column_slice(&b))
                .unwrap();
            let expected_t = matrix
                .transpose()
                .lu()
                .solve(&DVector::from_column_slice(&b))
                .unwrap();
            let (mut lu, mut pivots) = (a.clone(), vec![0; n]);
            assert!(lu_factor(&mut lu, &mut pivots, n, 0.0));
            let (mut x, mut x_t) = (b.clone(), b.clone());
            lu_solve(&lu, &pivots, n, &mut x);
            lu_solve_transposed(&lu, &pivots, n, &mut x_t);
            let scale = 1.0 + expected.amax() + expected_t.amax();
            assert!(max_difference(&x, expected.as_slice()) < SOLVE_TOLERANCE * scale);
            assert!(max_difference(&x_t, expected_t.as_slice()) < SOLVE_TOLERANCE * scale);
            let determinant = lu_determinant(&lu, &pivots, n);
            assert!(
                (determinant - matrix.determinant()).abs()
                    < SOLVE_TOLERANCE * (1.0 + determinant.abs())
            );

            let mut spd = numbers.spd(n);
            let expected = DMatrix::from_row_slice(n, n, &spd)
                .lu()
                .solve(&DVector::from_column_slice(&b))
                .unwrap();
            assert!(cholesky_factor(&mut spd, n));
            let mut x = b.clone();
            cholesky_solve(&spd, n, &mut x);
            assert!(max_difference(&x, expected.as_slice()) < SOLVE_TOLERANCE);
        }
        assert!(!cholesky_factor(&mut [1.0, 2.0, 2.0, 1.0], 2));
    }

    /// A workspace filled with random M (SPD), F, Q, J, c and a consistent partition.
    fn random_workspace(n: usize, nc: usize, driven: &[bool], seed: u64) -> (Workspace, Partition) {
        let mut numbers = Numbers(seed);
        let eligible: Vec<bool> = driven.iter().map(|d| !d).collect();
        let nu = n - nc - driven.iter().filter(|d| **d).count();
        let mut ws = Workspace::new(n, nc, nu);
        ws.mass = numbers.spd(n);
        ws.inertial = numbers.vector(n);
        ws.applied = numbers.vector(n);
        ws.jacobian = numbers.vector(nc * n);
        ws.bias = numbers.vector(nc);
        ws.qdd = numbers.vector(n);
        let dependent = choose_dependent(&ws.jacobian, nc, n, &eligible).unwrap();
        gather_columns(&ws.jacobian, n, &dependent, &mut ws.jv_lu);
        assert!(lu_factor(&mut ws.jv_lu, &mut ws.pivots, nc, 0.0));
        (ws, Partition::new(driven, &dependent).unwrap())
    }

    fn submatrix(m: &DMatrix<f64>, rows: &[usize], columns: &[usize]) -> DMatrix<f64> {
        DMatrix::from_fn(rows.len(), columns.len(), |r, c| m[(rows[r], columns[c])])
    }

    fn subvector(x: &[f64], rows: &[usize]) -> DVector<f64> {
        DVector::from_fn(rows.len(), |r, _| x[rows[r]])
    }

    #[test]
    fn reduced_dynamics_equal_the_explicit_formulas_18() {
        for (n, nc, seed) in [(4, 1, 1), (5, 2, 2), (6, 3, 3), (2, 1, 4)] {
            let (mut ws, partition) = random_workspace(n, nc, &vec![false; n], seed);
            ws.reduce_and_solve(&partition, 0.0).unwrap();

            let (u, v) = (partition.independent(), partition.dependent());
            let mass = DMatrix::from_row_slice(n, n, &ws.mass);
            let jacobian = DMatrix::from_row_slice(nc, n, &ws.jacobian);
            let jv_inverse = submatrix(&jacobian, &(0..nc).collect::<Vec<_>>(), v)
                .try_inverse()
                .unwrap();
            let ju = submatrix(&jacobian, &(0..nc).collect::<Vec<_>>(), u);
            let b_matrix = -&jv_inverse * ju;
            let b_vector = -&jv_inverse * DVector::from_column_slice(&ws.bias);
            let (m_uu, m_uv) = (submatrix(&mass, u, u), submatrix(&mass, u, v));
            let (m_vu, m_vv) = (submatrix(&mass, v, u), submatrix(&mass, v, v));
            let (f_u, f_v) = (subvector(&ws.inertial, u), subvector(&ws.inertial, v));
            let (q_u, q_v) = (subvector(&ws.applied, u), subvector(&ws.applied, v));
            let bt = b_matrix.transpose();
            let m_star = &m_uu + &m_uv * &b_matrix + &bt * &m_vu + &bt * &m_vv * &b_matrix;
            let f_star = &f_u + &m_uv * &b_vector + &bt * (&f_v + &m_vv * &b_vector);
            let q_star = &q_u + &bt * &q_v;
            let udd = m_star.lu().solve(&(-(f_star + q_star))).unwrap();
            let vdd = &b_matrix * &udd + &b_vector;

            let scale = 1.0 + udd.amax() + vdd.amax();
            assert!(
                max_difference(subvector(&ws.qdd, u).as_slice(), udd.as_slice())
                    < SOLVE_TOLERANCE * scale
            );
            assert!(
                max_difference(subvector(&ws.qdd, v).as_slice(), vdd.as_slice())
                    < SOLVE_TOLERANCE * scale
            );
        }
    }

    #[test]
    fn partitioned_solution_solves_the_augmented_system_with_drives() {
        // [M  Jᵀ  −E_d] [q̈ ]   [−F − Q]
        // [J  0    0  ] [λ ] = [−c    ]
        // [E_dᵀ 0  0  ] [τ_d]  [q̈_d   ]
        let cases: [(usize, usize, Vec<bool>, u64); 3] = [
            (4, 1, vec![true, false, false, false], 11),
            (6, 2, vec![false, true, false, false, true, false], 12),
            (3, 1, vec![false, false, false], 13),
        ];
        for (n, nc, driven, seed) in cases {
            let (mut ws, partition) = random_workspace(n, nc, &driven, seed);
            ws.reduce_and_solve(&partition, 0.0).unwrap();
            ws.solve_multipliers(&partition, 0.0).unwrap();

            let d = partition.driven();
            let size = n + nc + d.len();
            let mut system = DMatrix::zeros(size, size);
            let mut rhs = DVector::zeros(size);
            for i in 0..n {
                for k in 0..n {
                    system[(i, k)] = ws.mass[i * n + k];
                }
                rhs[i] = -ws.inertial[i] - ws.applied[i];
            }
            for k in 0..nc {
                for i in 0..n {
                    system[(i, n + k)] = ws.jacobian[k * n + i];
                    system[(n + k, i)] = ws.jacobian[k * n + i];
                }
                rhs[n + k] = -ws.bias[k];
            }
            for (e, &i) in d.iter().enumerate() {
                system[(i, n + nc + e)] = -1.0;
                system[(n + nc + e, i)] = 1.0;
                rhs[n + nc + e] = ws.qdd[i];
            }
            let solution = system.lu().solve(&rhs).unwrap();
            let scale = 1.0 + solution.amax();
            assert!(max_difference(&ws.qdd, &solution.as_slice()[..n]) < SOLVE_TOLERANCE * scale);
            assert!(
                max_difference(&ws.lambda, &solution.as_slice()[n..n + nc])
                    < SOLVE_TOLERANCE * scale
            );
            for (e, &i) in d.iter().enumerate() {
                assert!((ws.drive[i] - solution[n + nc + e]).abs() < SOLVE_TOLERANCE * scale);
            }
            for i in (0..n).filter(|i| !driven[*i]) {
                assert_eq!(ws.drive[i], 0.0);
            }
        }
    }

    #[test]
    fn partition_validates_and_orders_the_sets() {
        let mut partition = Partition::new(&[false, true, false, false], &[3]).unwrap();
        assert_eq!(partition.driven(), &[1]);
        assert_eq!(partition.independent(), &[0, 2]);
        partition.set_dependent(&[0]).unwrap();
        assert_eq!(partition.independent(), &[2, 3]);
        assert!(partition.set_dependent(&[1]).is_err());
        assert!(partition.set_dependent(&[7]).is_err());
        assert!(partition.set_dependent(&[0, 2]).is_err());
        assert!(Partition::new(&[false; 3], &[0, 0]).is_err());
    }

    #[test]
    fn normal_force_points_along_the_upward_normal() {
        // Flat cam (force scale √(1 + 0²) = 1), point pushed up by the cam: the y row of
        // (14) has +λ, so λ < 0.
        assert_eq!(normal_force(-2.0, 1.0), 2.0);
        // Slope 1: h = y − x has |∇h| = √2, the force √2 times −λ.
        assert!((normal_force(-1.0, 2f64.sqrt()) - 2f64.sqrt()).abs() < 1e-15);
    }
}
