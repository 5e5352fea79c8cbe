//! J_v as a band matrix: chained loops (an N-four-bar's 80 rows) give a J_v whose nonzeros lie
//! within a few diagonals of the main one in the order the topology gives (the rows in the
//! model's loop order, the dependent coordinates in the tree's order). Its LU with partial
//! pivoting then stays within the band widened by the lower width (LAPACK's `gbtrf`), so that
//! factoring costs O(nc·kl·(kl + ku)) instead of O(nc³) and each solve O(nc·(2 kl + ku))
//! instead of O(nc²): linear in the number of loops of a chain.
//!
//! The widths are those of the nonzeros seen (kept over the run: an entry that is zero at one
//! configuration, sin φ at φ = 0, may not be at the next), checked at every factorisation:
//! an entry outside them widens the band, and a band too wide to pay falls back to the dense
//! LU ([`super::linalg::lu_factor`]). The pivots are the dense LU's (in a band matrix the
//! entries of a column below the band are zero, so the largest one is found within it), so
//! both factorisations do the same arithmetic but for the summation order of the solves.

use super::linalg::{lu_solve, lu_solve_transposed};

/// J_v factored as a band matrix, or not (then the dense factor in the workspace is used).
#[derive(Debug, Clone, Default)]
pub(crate) struct Band {
    /// The factor of the last J_v is this one's (not the dense one).
    pub(super) active: bool,
    /// Lower and upper widths of the nonzeros seen.
    lower: usize,
    upper: usize,
    /// The widths were found for this many rows (0: not yet).
    size: usize,
    /// nc rows of `width` = 2 lower + upper + 1 entries: row i holds columns i − lower …
    /// i + lower + upper (the upper part widened by the row interchanges).
    factor: Vec<f64>,
    width: usize,
    pivots: Vec<usize>,
    /// The columns of each row of J that may be nonzero, checked at every factorisation.
    pub(super) jacobian_rows: Extents,
    /// The same for M, checked at every evaluation of the acceleration level.
    pub(super) mass_rows: Extents,
}

/// A band pays when its factor is at most this fraction of the dense one's storage (and so of
/// its work, which shrinks faster): below it the dense LU's simple loops are as fast.
const WORTH: f64 = 0.25;

/// Matrices smaller than this are factored densely (one contact, the paper's chain, four-bars).
const SMALLEST: usize = 8;

impl Band {
    /// Factors J_v, the `dependent` columns of the nc×n row-major `j`, as a band matrix when
    /// its nonzeros fit a band that pays. Returns `None` when they do not (nothing factored:
    /// use the dense LU), otherwise whether every pivot is finite and above `floor`.
    ///
    /// Reads J's rows within their extents ([`Self::jacobian_rows`], updated by the caller
    /// for this J): for a chain, O(nc) work.
    pub(super) fn factor(
        &mut self,
        j: &[f64],
        n: usize,
        dependent: &[usize],
        floor: f64,
    ) -> Option<bool> {
        self.active = false;
        let nc = dependent.len();
        if nc < SMALLEST {
            return None;
        }
        if self.size != nc {
            (self.lower, self.upper, self.size) = (0, 0, nc);
        }
        // The extents bound the widths in O(nc) (independent columns within them count too);
        // when that bound does not pay, the nonzeros themselves are measured (O(nc²), against
        // the dense LU's O(nc³) if they do not pay either).
        let pays = |(lower, upper): (usize, usize)| {
            let width = 2 * lower.max(self.lower) + upper.max(self.upper) + 1;
            width as f64 <= WORTH * nc as f64
        };
        let sorted = dependent.windows(2).all(|w| w[0] < w[1]);
        let bound = if sorted {
            self.jacobian_rows.band_widths(dependent)
        } else {
            (nc, nc)
        };
        let (lower, upper) = if pays(bound) {
            bound
        } else {
            widths(j, n, dependent)
        };
        self.lower = self.lower.max(lower);
        self.upper = self.upper.max(upper);
        self.width = 2 * self.lower + self.upper + 1;
        if self.width as f64 > WORTH * nc as f64 {
            return None;
        }
        self.gather(j, n, dependent);
        self.active = true;
        Some(self.eliminate(floor))
    }

    /// Copies J_v's band into the factor's storage (the widened upper part zeroed).
    fn gather(&mut self, j: &[f64], n: usize, dependent: &[usize]) {
        let (nc, width, lower) = (dependent.len(), self.width, self.lower);
        self.factor.clear();
        self.factor.resize(nc * width, 0.0);
        self.pivots.resize(nc, 0);
        for k in 0..nc {
            let row = &j[k * n..(k + 1) * n];
            let first = k.saturating_sub(lower);
            let last = (k + self.upper).min(nc - 1);
            for (l, &v) in dependent.iter().enumerate().take(last + 1).skip(first) {
                self.factor[k * width + l + lower - k] = row[v];
            }
        }
    }

    /// Index of entry (r, c) in the factor's storage.
    fn at(&self, r: usize, c: usize) -> usize {
        r * self.width + c + self.lower - r
    }

    /// In-place LU with partial pivoting within the band; false on a pivot at or below
    /// `floor` or not finite.
    fn eliminate(&mut self, floor: f64) -> bool {
        let nc = self.size;
        let reach = self.lower + self.upper;
        for k in 0..nc {
            let below = (k + self.lower).min(nc - 1);
            let mut p = k;
            for r in k + 1..=below {
                if self.factor[self.at(r, k)].abs() > self.factor[self.at(p, k)].abs() {
                    p = r;
                }
            }
            self.pivots[k] = p;
            let right = (k + reach).min(nc - 1);
            if p != k {
                for c in k..=right {
                    let (a, b) = (self.at(k, c), self.at(p, c));
                    self.factor.swap(a, b);
                }
            }
            let pivot = self.factor[self.at(k, k)];
            if pivot.abs() <= floor || !pivot.is_finite() {
                return false;
            }
            for r in k + 1..=below {
                let index = self.at(r, k);
                let factor = self.factor[index] / pivot;
                self.factor[index] = factor;
                if factor != 0.0 {
                    for c in k + 1..=right {
                        let (a, b) = (self.at(r, c), self.at(k, c));
                        self.factor[a] -= factor * self.factor[b];
                    }
                }
            }
        }
        true
    }

    /// Solves J_v x = b in place (`x` holds b), J_v factored by [`Self::factor`].
    // The indices are the band's rows and columns (L's column k at rows k+1 … k+lower).
    #[allow(clippy::needless_range_loop)]
    pub(super) fn solve(&self, x: &mut [f64]) {
        let nc = self.size;
        for k in 0..nc {
            x.swap(k, self.pivots[k]);
            let xk = x[k];
            if xk != 0.0 {
                for r in k + 1..=(k + self.lower).min(nc - 1) {
                    x[r] -= self.factor[self.at(r, k)] * xk;
                }
            }
        }
        let reach = self.lower + self.upper;
        for r in (0..nc).rev() {
            // Row r of U: its diagonal at offset `lower` of the row's storage, then the
            // entries right of it, contiguous.
            let end = (r + reach).min(nc - 1);
            let row = &self.factor[r * self.width + self.lower..];
            let sum: f64 = (row[1..=end - r].iter().zip(&x[r + 1..=end]))
                .map(|(u, x)| u * x)
                .sum();
            x[r] = (x[r] - sum) / row[0];
        }
    }

    /// Solves J_vᵀ x = b in place: Uᵀ z = b, then the eliminations and interchanges
    /// transposed, last to first.
    // The indices are the band's rows and columns, as in `solve`.
    #[allow(clippy::needless_range_loop)]
    pub(super) fn solve_transposed(&self, x: &mut [f64]) {
        let nc = self.size;
        let reach = self.lower + self.upper;
        for r in 0..nc {
            let mut sum = x[r];
            for c in r.saturating_sub(reach)..r {
                sum -= self.factor[self.at(c, r)] * x[c];
            }
            x[r] = sum / self.factor[self.at(r, r)];
        }
        for k in (0..nc).rev() {
            let mut sum = x[k];
            for r in k + 1..=(k + self.lower).min(nc - 1) {
                sum -= self.factor[self.at(r, k)] * x[r];
            }
            x[k] = sum;
            x.swap(k, self.pivots[k]);
        }
    }

    /// ln |det J_v| from the factor.
    pub(super) fn log_determinant(&self) -> f64 {
        (0..self.size)
            .map(|k| self.factor[self.at(k, k)].abs().ln())
            .sum()
    }
}

/// Matrices with fewer columns than this keep whole rows as their extents, unchecked: the
/// bookkeeping would cost more than the zeros it skips.
const SMALLEST_EXTENTS: usize = 16;

/// For each row of a row-major matrix, the range of columns outside which it is zero: the
/// union of its nonzeros seen, checked at every [`Extents::update`] (an OR of the entries'
/// bits outside the range, which the compiler vectorises: ~n/4 operations per row) and
/// widened when a nonzero (or a NaN) appears outside. Row operations then read only the
/// range: for chained loops, a few entries of J's and M's rows instead of n.
#[derive(Debug, Clone, Default)]
pub(crate) struct Extents {
    /// [start, end) of each row; (0, 0) when the row has been zero.
    rows: Vec<(usize, usize)>,
    columns: usize,
    /// The extents the model declares ([`crate::Dynamics::mass_rows`]): taken as they are
    /// (widened by one check when first taken), not checked at every update.
    declared: Option<&'static [(usize, usize)]>,
}

impl Extents {
    /// Checks the row-major `a` of `columns` columns against the extents, widening them where
    /// a nonzero lies outside; resets them when the shape changes. Small matrices keep whole
    /// rows.
    pub(super) fn update(&mut self, a: &[f64], columns: usize) {
        let rows = a.len().checked_div(columns).unwrap_or(0);
        if let Some(declared) = self.declared.filter(|d| d.len() == rows) {
            if self.columns == columns && self.rows.len() == rows {
                return;
            }
            // First taken: the declaration, widened by the nonzeros of this matrix.
            self.columns = columns;
            self.rows = declared
                .iter()
                .map(|&(s, e)| {
                    let s = s.min(columns);
                    (s, e.clamp(s, columns))
                })
                .collect();
            self.scan(a, columns);
            return;
        }
        if self.columns != columns || self.rows.len() != rows {
            self.columns = columns;
            let start = if columns < SMALLEST_EXTENTS {
                (0, columns)
            } else {
                (0, 0)
            };
            self.rows = vec![start; rows];
        }
        if columns < SMALLEST_EXTENTS {
            return;
        }
        self.scan(a, columns);
    }

    /// Takes the model's declared extents (`None`: find them by reading the matrix). A change
    /// of declaration is checked at the next update.
    pub(super) fn declare(&mut self, declared: Option<&'static [(usize, usize)]>) {
        let same = match (self.declared, declared) {
            (Some(a), Some(b)) => std::ptr::eq(a, b),
            (None, None) => true,
            _ => false,
        };
        if !same {
            self.declared = declared;
            // Taken (or left) at the next update.
            self.columns = 0;
        }
    }

    /// Widens the extents to every nonzero (or NaN) of `a` outside them.
    fn scan(&mut self, a: &[f64], columns: usize) {
        for (extent, row) in self.rows.iter_mut().zip(a.chunks_exact(columns)) {
            let (start, end) = *extent;
            if nonzero_bits(&row[..start]) | nonzero_bits(&row[end..]) == 0 {
                continue;
            }
            let first = row.iter().position(|x| x.to_bits() << 1 != 0).unwrap_or(0);
            let last = row.iter().rposition(|x| x.to_bits() << 1 != 0).unwrap_or(0) + 1;
            *extent = if start == end {
                (first, last)
            } else {
                (start.min(first), end.max(last))
            };
        }
    }

    /// [start, end) of row `k` of a matrix of `columns` columns: the row is zero outside
    /// (the whole row when the extents were not updated for such a matrix).
    pub(super) fn row(&self, k: usize, columns: usize) -> (usize, usize) {
        match self.rows.get(k) {
            Some(&extent) if self.columns == columns => extent,
            _ => (0, columns),
        }
    }

    /// True when an entry within the extents is not finite (those outside are zero).
    pub(super) fn any_non_finite(&self, a: &[f64]) -> bool {
        let columns = self.columns;
        (self.rows.iter().enumerate()).any(|(k, &(s, e))| {
            a[k * columns + s..k * columns + e]
                .iter()
                .any(|x| !x.is_finite())
        })
    }

    /// Σ_c a[k, c] x[c] over row k's extent (a has x.len() columns). The terms left out
    /// are zero, so the sum is the full row's, bit for bit.
    pub(super) fn dot_row(&self, a: &[f64], k: usize, x: &[f64]) -> f64 {
        let columns = x.len();
        let (s, e) = self.row(k, columns);
        let row = &a[k * columns + s..k * columns + e];
        row.iter().zip(&x[s..e]).map(|(a, b)| a * b).sum()
    }

    /// The positions in `dependent` (increasing) of the columns of row `k`'s extent.
    pub(super) fn dependent_range(&self, k: usize, dependent: &[usize]) -> (usize, usize) {
        let (s, e) = self.rows.get(k).copied().unwrap_or((0, usize::MAX));
        (
            dependent.partition_point(|&v| v < s),
            dependent.partition_point(|&v| v < e),
        )
    }

    /// Lower and upper widths of J_v, the `dependent` columns (increasing), from the extents
    /// of its rows (the first nc): a bound of the nonzeros' widths.
    fn band_widths(&self, dependent: &[usize]) -> (usize, usize) {
        let (mut lower, mut upper) = (0, 0);
        for k in 0..dependent.len() {
            let (first, end) = self.dependent_range(k, dependent);
            if first < end {
                lower = lower.max(k.saturating_sub(first));
                upper = upper.max((end - 1).saturating_sub(k));
            }
        }
        (lower, upper)
    }
}

/// `out = M x + F + Q` (n = out.len()) over the rows' extents of M, updated first.
pub(super) fn residual_rows(
    extents: &mut Extents,
    out: &mut [f64],
    mass: &[f64],
    x: &[f64],
    inertial: &[f64],
    applied: &[f64],
) {
    extents.update(mass, out.len());
    for (i, o) in out.iter_mut().enumerate() {
        *o = extents.dot_row(mass, i, x) + inertial[i] + applied[i];
    }
}

/// The OR of the entries' bits without the sign (so that −0.0 counts as zero): 0 when all
/// are zero.
fn nonzero_bits(x: &[f64]) -> u64 {
    x.iter().fold(0, |bits, v| bits | (v.to_bits() << 1))
}

/// Lower and upper widths of the nonzeros of J_v (the `dependent` columns of `j`).
fn widths(j: &[f64], n: usize, dependent: &[usize]) -> (usize, usize) {
    let (mut lower, mut upper) = (0, 0);
    for k in 0..dependent.len() {
        let row = &j[k * n..(k + 1) * n];
        for (l, &v) in dependent.iter().enumerate() {
            if row[v] != 0.0 {
                if l < k {
                    lower = lower.max(k - l);
                } else {
                    upper = upper.max(l - k);
                }
            }
        }
    }
    (lower, upper)
}

/// J_v x = b in place with whichever factor holds J_v: the band's when active, else the dense
/// `lu` and `pivots` of [`super::linalg::lu_factor`].
pub(super) fn solve_dependent(band: &Band, lu: &[f64], pivots: &[usize], x: &mut [f64]) {
    if band.active {
        band.solve(x);
    } else {
        lu_solve(lu, pivots, x.len(), x);
    }
}

/// J_vᵀ x = b in place, as [`solve_dependent`].
pub(super) fn solve_dependent_transposed(band: &Band, lu: &[f64], pivots: &[usize], x: &mut [f64]) {
    if band.active {
        band.solve_transposed(x);
    } else {
        lu_solve_transposed(lu, pivots, x.len(), x);
    }
}

#[cfg(test)]
mod tests {
    use super::super::linalg::{gather_columns, lu_factor, lu_solve, lu_solve_transposed};
    use super::*;

    /// A J of nc rows and nc + 1 columns whose dependent columns (all but column 0) form a
    /// band of widths (lower, upper), entries from a fixed sequence, some zero in the band.
    fn banded(nc: usize, lower: usize, upper: usize, seed: u64) -> Vec<f64> {
        let n = nc + 1;
        let mut state = seed;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let mut j = vec![0.0; nc * n];
        for k in 0..nc {
            j[k * n] = next();
            for l in k.saturating_sub(lower)..=(k + upper).min(nc - 1) {
                let x = next();
                // Some entries of the band zero (as sin φ at φ = 0), the diagonal small at
                // times, so that rows are interchanged.
                j[k * n + l + 1] = if x.abs() < 0.1 { 0.0 } else { x };
            }
        }
        j
    }

    /// [`Band::factor`] after the extents' update, as the workspace does.
    fn factored(band: &mut Band, j: &[f64], n: usize, dependent: &[usize]) -> Option<bool> {
        band.jacobian_rows.update(j, n);
        band.factor(j, n, dependent, 0.0)
    }

    #[test]
    fn band_and_dense_factors_solve_alike() {
        // Both do the same eliminations with the same pivots; only the solves' summation
        // order differs: agreement to ~1e-15 of the solution's size for these well-scaled
        // matrices (condition numbers below ~1e3): 1e-12 leaves a margin.
        for (nc, lower, upper, seed) in [(80, 2, 1, 1), (40, 3, 3, 2), (64, 1, 4, 3), (9, 0, 1, 4)]
        {
            let n = nc + 1;
            let j = banded(nc, lower, upper, seed);
            let dependent: Vec<usize> = (1..n).collect();
            let mut band = Band::default();
            assert_eq!(
                factored(&mut band, &j, n, &dependent),
                Some(true),
                "nc = {nc}"
            );
            let (mut lu, mut pivots) = (vec![0.0; nc * nc], vec![0; nc]);
            gather_columns(&j, n, &dependent, &mut lu);
            assert!(lu_factor(&mut lu, &mut pivots, nc, 0.0));
            assert_eq!(band.pivots, pivots, "the same pivots");
            let b: Vec<f64> = (0..nc).map(|k| (k as f64 * 0.37).sin()).collect();
            let (mut x, mut y) = (b.clone(), b.clone());
            band.solve(&mut x);
            lu_solve(&lu, &pivots, nc, &mut y);
            let scale = 1.0 + y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for (a, e) in x.iter().zip(&y) {
                assert!((a - e).abs() < 1e-12 * scale, "solve: {a} against {e}");
            }
            let (mut x, mut y) = (b.clone(), b.clone());
            band.solve_transposed(&mut x);
            lu_solve_transposed(&lu, &pivots, nc, &mut y);
            let scale = 1.0 + y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for (a, e) in x.iter().zip(&y) {
                assert!((a - e).abs() < 1e-12 * scale, "transposed: {a} against {e}");
            }
            let dense: f64 = (0..nc).map(|k| lu[k * nc + k].abs().ln()).sum();
            assert!((band.log_determinant() - dense).abs() < 1e-12 * (1.0 + dense.abs()));
        }
    }

    #[test]
    fn an_entry_outside_the_band_widens_it_and_a_wide_band_is_dense() {
        let nc = 40;
        let n = nc + 1;
        let dependent: Vec<usize> = (1..n).collect();
        let mut j = banded(nc, 1, 1, 5);
        let mut band = Band::default();
        assert_eq!(factored(&mut band, &j, n, &dependent), Some(true));
        assert_eq!((band.lower, band.upper), (1, 1));
        // A new nonzero two below the diagonal: the band widens and keeps the width.
        j[10 * n + 8 + 1] = 0.5;
        assert_eq!(factored(&mut band, &j, n, &dependent), Some(true));
        j[10 * n + 8 + 1] = 0.0;
        assert_eq!(factored(&mut band, &j, n, &dependent), Some(true));
        assert_eq!((band.lower, band.upper), (2, 1));
        // A full row: no band pays, the dense LU is used.
        for l in 0..nc {
            j[n + l + 1] = 1.0;
        }
        assert_eq!(factored(&mut band, &j, n, &dependent), None);
        assert!(!band.active);
        // Below SMALLEST rows, always dense.
        let small = banded(4, 0, 1, 6);
        assert_eq!(
            factored(&mut Band::default(), &small, 5, &[1, 2, 3, 4]),
            None
        );
    }

    #[test]
    fn a_zero_pivot_is_reported() {
        let nc = 20;
        let n = nc + 1;
        let mut j = banded(nc, 1, 1, 7);
        // Row 5 zero within the band: J_v singular.
        for l in 4..=6 {
            j[5 * n + l + 1] = 0.0;
        }
        let dependent: Vec<usize> = (1..n).collect();
        assert_eq!(
            factored(&mut Band::default(), &j, n, &dependent),
            Some(false)
        );
    }

    #[test]
    fn declared_extents_are_taken_once_then_trusted() {
        // 3 rows of 20 columns: row 0 nonzero in 2..4, row 1 in 10..12, row 2 zero.
        let columns = 20;
        let mut a = vec![0.0; 3 * columns];
        a[2] = 1.0;
        a[3] = -2.0;
        a[columns + 10] = 3.0;
        static DECLARED: [(usize, usize); 3] = [(2, 4), (9, 12), (0, 0)];
        let mut extents = Extents::default();
        extents.declare(Some(&DECLARED));
        // Taken at the first update, widened by a nonzero the declaration left out.
        a[2 * columns + 5] = 4.0;
        extents.update(&a, columns);
        let rows: Vec<_> = (0..3).map(|k| extents.row(k, columns)).collect();
        assert_eq!(rows, [(2, 4), (9, 12), (5, 6)]);
        // Then trusted: not read again (the model writes nothing outside).
        a[19] = 5.0;
        extents.update(&a, columns);
        assert_eq!(extents.row(0, columns), (2, 4));
        // Without a declaration the matrix is read at every update.
        extents.declare(None);
        extents.update(&a, columns);
        assert_eq!(extents.row(0, columns), (2, 20));
        // A declaration of another shape is not taken.
        extents.declare(Some(&DECLARED[..2]));
        extents.update(&a, columns);
        assert_eq!(extents.row(2, columns), (5, 6));
    }
}
