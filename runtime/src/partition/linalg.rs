//! The small dense kernels of the partitioned dynamics: LU with partial pivoting for J_v,
//! the square-root-free L D Lᵀ for the reduced mass matrix, and vector helpers.

/// True when every entry of `x` is finite. Without an early exit (no branch per entry): the
/// callers check vectors that are finite but for a failure.
#[inline]
pub(crate) fn all_finite(x: &[f64]) -> bool {
    x.iter().fold(true, |ok, v| ok & v.is_finite())
}

/// Σ a_i b_i over the shorter of the two, in four running sums added pairwise at the end,
/// not one: a single sum is a chain of dependent additions (4 cycles each), which made the
/// one-contact velocity level's 17-term row 1.2 % of the 16-body chain's right-hand side
/// (perf).
#[inline]
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (a[..n].chunks_exact(4), b[..n].chunks_exact(4));
    let rest: f64 = a
        .remainder()
        .iter()
        .zip(b.remainder())
        .map(|(x, y)| x * y)
        .sum();
    let mut lanes = [0.0_f64; 4];
    for (x, y) in a.zip(b) {
        for k in 0..4 {
            lanes[k] += x[k] * y[k];
        }
    }
    ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3])) + rest
}

/// max |x_i| (0 for none), NaN when any entry is NaN. Four running maxima, not one: a
/// single one is a chain of dependent comparisons, which took 2 % of a 16-body chain's
/// right-hand side (perf) for `Workspace::rows_shrunk`'s row of J alone.
pub(super) fn max_abs(x: &[f64]) -> f64 {
    let mut lanes = [0.0_f64; 4];
    let mut nan = false;
    let mut chunks = x.chunks_exact(4);
    for chunk in &mut chunks {
        for (lane, v) in lanes.iter_mut().zip(chunk) {
            let a = v.abs();
            // `>` is false for a NaN, which `nan` records instead.
            *lane = if a > *lane { a } else { *lane };
            nan |= v.is_nan();
        }
    }
    for v in chunks.remainder() {
        let a = v.abs();
        lanes[0] = if a > lanes[0] { a } else { lanes[0] };
        nan |= v.is_nan();
    }
    if nan {
        return f64::NAN;
    }
    lanes.iter().fold(0.0, |m: f64, &l| m.max(l))
}

pub(super) fn euclidean(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// In-place LU factorisation with partial pivoting of the n×n row-major `a` (P A = L U, L
/// unit lower, both stored in `a`; `pivots[k]` is the row swapped with row k at step k).
/// Returns false when a pivot is zero or not finite.
///
/// Inlined for its 1×1 case, a number (one contact: the paper's case, every right-hand
/// side); the general case is a call.
#[inline]
pub(super) fn lu_factor(a: &mut [f64], pivots: &mut [usize], n: usize, floor: f64) -> bool {
    if n == 1 {
        pivots[0] = 0;
        return a[0].abs() > floor && a[0].is_finite();
    }
    lu_factor_pivoting(a, pivots, n, floor)
}

/// [`lu_factor`] for n ≥ 2.
fn lu_factor_pivoting(a: &mut [f64], pivots: &mut [usize], n: usize, floor: f64) -> bool {
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
pub(super) fn lu_solve(lu: &[f64], pivots: &[usize], n: usize, x: &mut [f64]) {
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
pub(super) fn lu_solve_transposed(lu: &[f64], pivots: &[usize], n: usize, x: &mut [f64]) {
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
pub(super) fn lu_determinant(lu: &[f64], pivots: &[usize], n: usize) -> f64 {
    let swaps = (0..n).filter(|&k| pivots[k] != k).count();
    let product: f64 = (0..n).map(|k| lu[k * n + k]).product();
    if swaps % 2 == 0 { product } else { -product }
}

/// Solves the n×n SPD system `a` x = `x` (lower triangle of `a` read, overwritten by its
/// factor) in place; false when `a` is not positive definite. Sizes up to 6 (every
/// reference model) go through fixed-size code the compiler unrolls: for these 2×2 … 6×6
/// systems the loop and bounds-check bookkeeping of the general code costs more than the
/// arithmetic (callgrind: ~500 instructions for a 3×3 solve).
pub(super) fn solve_reduced(a: &mut [f64], n: usize, x: &mut [f64]) -> bool {
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
pub(super) fn solve_fixed<const N: usize>(a: &mut [f64], x: &mut [f64]) -> bool {
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
pub(super) fn solve_ldlt<const N: usize>(a: &mut [[f64; N]; N], rhs: [f64; N]) -> Option<[f64; N]> {
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
pub(super) fn cholesky_factor(a: &mut [f64], n: usize) -> bool {
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
pub(super) fn cholesky_solve(l: &[f64], n: usize, x: &mut [f64]) {
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

/// `out` (nc×nc, row-major) = the columns `columns` of the nc×n matrix `j`.
pub(super) fn gather_columns(j: &[f64], n: usize, columns: &[usize], out: &mut [f64]) {
    let nc = columns.len();
    for k in 0..nc {
        for (l, &column) in columns.iter().enumerate() {
            out[k * nc + l] = j[k * n + column];
        }
    }
}
