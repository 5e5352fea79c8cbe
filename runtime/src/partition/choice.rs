//! The choice of the dependent coordinates (and of the independent constraint rows) and its
//! conditioning, which decides when a run re-partitions.

use super::band::Band;
use super::linalg::{gather_columns, lu_factor};

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

/// Pivots below this fraction of max |J_ij| count as zero when choosing the dependent
/// coordinates: such a column would amplify round-off by more than 10¹².
pub(super) const NEGLIGIBLE_PIVOT: f64 = 1e-12;

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
/// [`Workspace::jacobian_floor`](super::Workspace::jacobian_floor)). Returns (rows,
/// columns), each in increasing order; rows left out are redundant (implied by the chosen
/// ones to first order), and `rows.len()` is the rank.
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
pub(super) fn largest_entry(
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
pub(super) fn eliminate_column(
    a: &mut [f64],
    n: usize,
    pivot_row: usize,
    column: usize,
    row_done: &[bool],
) {
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
pub(super) fn dependent_log_determinant(
    j: &[f64],
    nc: usize,
    n: usize,
    dependent: &[usize],
) -> f64 {
    // Chained loops: J_v is a band matrix, factored in O(nc) (once per step, to decide on a
    // re-partition).
    let mut band = Band::default();
    band.jacobian_rows.update(&j[..nc * n], n);
    match band.factor(j, n, dependent, 0.0) {
        Some(true) => return band.log_determinant(),
        Some(false) => return f64::NEG_INFINITY,
        None => {}
    }
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
