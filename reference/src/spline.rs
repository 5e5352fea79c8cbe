//! The reference's own route to a tabulated function's value and derivatives.
//!
//! A spline through a table of points is the same curve whichever way it is built, so the
//! reference builds it differently from the runtime (`camchain_runtime::spline`, which solves
//! a tridiagonal system for the second derivatives at the knots by the Thomas algorithm and
//! Sherman–Morrison): here the unknowns are the slopes d_i at the knots (the Hermite form),
//! found from the C² conditions by Gaussian elimination down their band with the last slope
//! kept as a border (the periodic corners fall in it), O(n), and each segment is the cubic
//! Hermite interpolant
//!
//! ```text
//! S(x) = h₀₀(t) y_i + h₁₀(t) h d_i + h₀₁(t) y_{i+1} + h₁₁(t) h d_{i+1},  t = (x − x_i)/h
//! ```
//!
//! differentiated term by term. Agreement between the two routes checks the runtime's
//! solve, its evaluation and the generated code's tables at once.
//!
//! A motion law has its closed forms in `camchain_runtime::motion_law` (checked there
//! against Norton's tables and numerical integration); the reference evaluates those.
//!
//! Built splines are kept per function (by identity) on each thread, so a profile's table is
//! solved once, not at every evaluation.

use camchain_model::profile::{Tabulated, TabulatedFunction};
use camchain_runtime::spline::{Ends, Spline};
use std::cell::RefCell;
use std::sync::Arc;

/// The derivative of order `order` of `f` at x, by the reference's route.
///
/// An expression reads one function at one point several times (a profile designed from a
/// law reads the law's value and slope in many places): the last evaluation is kept.
pub fn derivative(f: &Arc<Tabulated>, order: u8, x: f64) -> f64 {
    if order > 3 {
        return f.derivative(order, x);
    }
    let cached = LAST.with(|last| {
        last.borrow()
            .as_ref()
            .filter(|(g, at, _)| Arc::ptr_eq(g, f) && *at == x.to_bits())
            .map(|(_, _, v)| *v)
    });
    let values = cached.unwrap_or_else(|| {
        let values = match &f.function {
            TabulatedFunction::Law(_) => f.eval(x),
            TabulatedFunction::Spline(spline) => with_hermite(f, spline, |h| h.eval(x)),
        };
        LAST.with(|last| *last.borrow_mut() = Some((f.clone(), x.to_bits(), values)));
        values
    });
    values[usize::from(order)]
}

/// A spline in Hermite form: knots, values and slopes.
#[derive(Debug, Clone)]
pub struct Hermite {
    x: Vec<f64>,
    y: Vec<f64>,
    d: Vec<f64>,
    periodic: bool,
}

impl Hermite {
    /// The spline of `spline`'s table and ends, solved for its knot slopes in O(n) (non-finite
    /// slopes only for a table the runtime refuses anyway: a zero pivot needs a zero step).
    pub fn new(spline: &Spline) -> Self {
        Self::through(spline.abscissas(), spline.values(), spline.ends())
    }

    /// The spline through (x, y) with `ends`, for a table already checked (as the runtime's
    /// [`Spline::new`] checks it: enough increasing knots, a periodic table closing).
    pub fn through(x: &[f64], y: &[f64], ends: Ends) -> Self {
        let d = slopes(x, y, ends);
        Hermite {
            x: x.to_vec(),
            y: y.to_vec(),
            d,
            periodic: ends == Ends::Periodic,
        }
    }

    /// [S, S′, S″, S‴] at s; a periodic spline repeats, an open one continues its end cubics.
    /// The segment is found by bisection, O(log n).
    pub fn eval(&self, s: f64) -> [f64; 4] {
        let (x, n) = (&self.x, self.x.len() - 1);
        let s = if self.periodic {
            x[0] + (s - x[0]).rem_euclid(x[n] - x[0])
        } else {
            s
        };
        let i = x.partition_point(|&k| k <= s).clamp(1, n) - 1;
        let h = x[i + 1] - x[i];
        let t = (s - x[i]) / h;
        let (y0, y1, m0, m1) = (self.y[i], self.y[i + 1], h * self.d[i], h * self.d[i + 1]);
        // Hermite basis functions and their derivatives with respect to t.
        let basis = [
            [
                2.0 * t.powi(3) - 3.0 * t * t + 1.0,
                6.0 * t * t - 6.0 * t,
                12.0 * t - 6.0,
                12.0,
            ],
            [
                t.powi(3) - 2.0 * t * t + t,
                3.0 * t * t - 4.0 * t + 1.0,
                6.0 * t - 4.0,
                6.0,
            ],
            [
                -2.0 * t.powi(3) + 3.0 * t * t,
                -6.0 * t * t + 6.0 * t,
                -12.0 * t + 6.0,
                -12.0,
            ],
            [t.powi(3) - t * t, 3.0 * t * t - 2.0 * t, 6.0 * t - 2.0, 6.0],
        ];
        let mut out = [0.0; 4];
        for (k, value) in out.iter_mut().enumerate() {
            let sum = basis[0][k] * y0 + basis[1][k] * m0 + basis[2][k] * y1 + basis[3][k] * m1;
            *value = sum / h.powi(k as i32);
        }
        out
    }
}

/// The knot slopes of the C² cubic through the points with `ends`: one equation per knot
/// (continuity of S″ at interior knots; the end conditions; for a periodic spline continuity
/// across the ends, with d_n = d₀), solved by [`Bordered::solve`] in O(n).
fn slopes(x: &[f64], y: &[f64], ends: Ends) -> Vec<f64> {
    let n = x.len() - 1;
    let h: Vec<f64> = (0..n).map(|i| x[i + 1] - x[i]).collect();
    let secant = |i: usize| (y[i + 1] - y[i]) / (h[i] * h[i]);
    let periodic = ends == Ends::Periodic;
    // A periodic spline's unknowns are d₀ … d_{n−1} (d_n = d₀), an open one's d₀ … d_n.
    let unknowns = if periodic { n } else { n + 1 };
    let mut system = Bordered::new(unknowns);
    // S″ continuity at knot i between segments a (ending there) and b (starting there):
    // d_a/h_a + 2 (1/h_a + 1/h_b) d_i + d_b/h_b = 3 (secant_a + secant_b).
    let continuity = |system: &mut Bordered, i: usize, a: usize, b: usize| {
        let (before, after) = (if i == 0 { n - 1 } else { i - 1 }, (i + 1) % unknowns);
        system.add(i, before, 1.0 / h[a]);
        system.add(i, i, 2.0 * (1.0 / h[a] + 1.0 / h[b]));
        system.add(i, after, 1.0 / h[b]);
        system.rhs[i] = 3.0 * (secant(a) + secant(b));
    };
    for i in 1..n {
        continuity(&mut system, i, i - 1, i);
    }
    match ends {
        Ends::Natural => {
            // S″(x₀) = 0: 2 d₀ + d₁ = 3 (y₁ − y₀)/h₀; the same mirrored at the last knot.
            system.add(0, 0, 2.0);
            system.add(0, 1, 1.0);
            system.rhs[0] = 3.0 * secant(0) * h[0];
            system.add(n, n, 2.0);
            system.add(n, n - 1, 1.0);
            system.rhs[n] = 3.0 * secant(n - 1) * h[n - 1];
        }
        Ends::Clamped { start, end } => {
            system.add(0, 0, 1.0);
            system.rhs[0] = start;
            system.add(n, n, 1.0);
            system.rhs[n] = end;
        }
        // Knot 0 joins the last segment (n − 1) to the first.
        Ends::Periodic => continuity(&mut system, 0, n - 1, 0),
    }
    let mut d = system.solve();
    if periodic {
        d.push(d[0]);
    }
    d
}

/// A linear system that is tridiagonal but for its last unknown, which any row may hold
/// (the border column), and its last row, which may hold any unknown (the border row):
///
/// ```text
/// ⎡ b₀ c₀          e₀ ⎤
/// ⎢ a₁ b₁ c₁       e₁ ⎥
/// ⎢    ⋱  ⋱  ⋱     ⋮  ⎥
/// ⎢       a  b     e  ⎥
/// ⎣ f₀ f₁ …  f     g  ⎦
/// ```
///
/// An open spline's slope system is tridiagonal (its border holds only the band's last
/// entries); a periodic one's corners, the coupling of d₀ with d_{n−1}, fall in the border.
/// Gaussian elimination runs down the band once, each pivot row clearing the entry below it
/// and the border row's entry under it (the border row fills in one column to the right as
/// it goes, the border column stays a column), then solves the last unknown from the 1 × 1
/// Schur complement g and substitutes back: O(n), no pivoting (the slope systems are
/// strictly diagonally dominant by rows: each diagonal is twice the sum of its row's other
/// entries, or 2 against 1, or 1 against 0, so every pivot stays positive).
///
/// This is a route of its own next to the runtime's (Thomas on the second derivatives of a
/// modified matrix, twice, and a Sherman–Morrison correction for the corners).
struct Bordered {
    /// Sub-diagonal (a[0] unused), diagonal and super-diagonal of the band's rows.
    sub: Vec<f64>,
    diag: Vec<f64>,
    sup: Vec<f64>,
    /// The band rows' entries in the last unknown's column (e).
    column: Vec<f64>,
    /// The last row's entries in the band's columns (f) and its diagonal (g).
    row: Vec<f64>,
    corner: f64,
    /// The right-hand side, one per unknown.
    rhs: Vec<f64>,
}

impl Bordered {
    /// The zero system of `unknowns` unknowns (at least 2).
    fn new(unknowns: usize) -> Self {
        let band = unknowns - 1;
        Bordered {
            sub: vec![0.0; band],
            diag: vec![0.0; band],
            sup: vec![0.0; band],
            column: vec![0.0; band],
            row: vec![0.0; band],
            corner: 0.0,
            rhs: vec![0.0; unknowns],
        }
    }

    /// Adds `value` to the entry of row `i` and column `j`, which must be in the band or the
    /// border.
    fn add(&mut self, i: usize, j: usize, value: f64) {
        let last = self.diag.len();
        if i == last {
            if j == last {
                self.corner += value;
            } else {
                self.row[j] += value;
            }
        } else if j == last {
            self.column[i] += value;
        } else if j == i {
            self.diag[i] += value;
        } else if j + 1 == i {
            self.sub[i] += value;
        } else if j == i + 1 {
            self.sup[i] += value;
        } else {
            debug_assert!(false, "entry ({i}, {j}) outside the band and the border");
        }
    }

    /// The solution, by elimination down the band and back substitution.
    fn solve(mut self) -> Vec<f64> {
        let band = self.diag.len();
        let last = band;
        for k in 0..band {
            let pivot = self.diag[k];
            // The band row below: its sub-diagonal entry.
            if k + 1 < band {
                let l = self.sub[k + 1] / pivot;
                self.diag[k + 1] -= l * self.sup[k];
                self.column[k + 1] -= l * self.column[k];
                self.rhs[k + 1] -= l * self.rhs[k];
            }
            // The border row: its entry in column k, filling in column k + 1 (the corner when
            // k + 1 is the last unknown, whose entry row k keeps in `column`).
            let l = self.row[k] / pivot;
            if k + 1 < band {
                self.row[k + 1] -= l * self.sup[k];
            }
            self.corner -= l * self.column[k];
            self.rhs[last] -= l * self.rhs[k];
        }
        let mut d = vec![0.0; band + 1];
        d[last] = self.rhs[last] / self.corner;
        for k in (0..band).rev() {
            let next = if k + 1 < band {
                self.sup[k] * d[k + 1]
            } else {
                0.0
            };
            d[k] = (self.rhs[k] - next - self.column[k] * d[last]) / self.diag[k];
        }
        d
    }
}

/// A function, an argument's bits and the four values there.
type LastEvaluation = (Arc<Tabulated>, u64, [f64; 4]);

/// Most splines kept per thread; the cache starts again beyond it.
const CACHED: usize = 64;

thread_local! {
    /// The last evaluation: the function (held, so that its identity stays its own), the
    /// argument's bits and the four values.
    static LAST: RefCell<Option<LastEvaluation>> = const { RefCell::new(None) };
    static BUILT: RefCell<Vec<(Arc<Tabulated>, Arc<Hermite>)>> = const { RefCell::new(Vec::new()) };
}

/// Runs `f` on the Hermite form of `spline` (the function `table`), built on first use. The
/// cache holds the function itself, so an identity it matched stays valid.
fn with_hermite<T>(table: &Arc<Tabulated>, spline: &Spline, f: impl FnOnce(&Hermite) -> T) -> T {
    let found = BUILT.with(|built| {
        built
            .borrow()
            .iter()
            .find(|(t, _)| Arc::ptr_eq(t, table))
            .map(|(_, h)| h.clone())
    });
    let hermite = found.unwrap_or_else(|| {
        let h = Arc::new(Hermite::new(spline));
        BUILT.with(|built| {
            let mut built = built.borrow_mut();
            if built.len() >= CACHED {
                built.clear();
            }
            built.push((table.clone(), h.clone()));
        });
        h
    });
    f(&hermite)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// The slope system written out densely and solved by LU with partial pivoting (the
    /// reference's former route): an oracle for the banded elimination.
    fn dense_slopes(x: &[f64], y: &[f64], ends: Ends) -> Vec<f64> {
        let n = x.len() - 1;
        let h: Vec<f64> = (0..n).map(|i| x[i + 1] - x[i]).collect();
        let secant = |i: usize| (y[i + 1] - y[i]) / (h[i] * h[i]);
        let periodic = ends == Ends::Periodic;
        let unknowns = if periodic { n } else { n + 1 };
        let mut a = DMatrix::<f64>::zeros(unknowns, unknowns);
        let mut b = DVector::<f64>::zeros(unknowns);
        let rows = if periodic { 0..n } else { 1..n };
        for i in rows {
            let (before, segment_before) = if i == 0 {
                (n - 1, n - 1)
            } else {
                (i - 1, i - 1)
            };
            a[(i, before)] += 1.0 / h[segment_before];
            a[(i, i)] += 2.0 * (1.0 / h[segment_before] + 1.0 / h[i]);
            a[(i, (i + 1) % unknowns)] += 1.0 / h[i];
            b[i] = 3.0 * (secant(segment_before) + secant(i));
        }
        match ends {
            Ends::Natural => {
                a[(0, 0)] = 2.0;
                a[(0, 1)] = 1.0;
                b[0] = 3.0 * secant(0) * h[0];
                a[(n, n)] = 2.0;
                a[(n, n - 1)] = 1.0;
                b[n] = 3.0 * secant(n - 1) * h[n - 1];
            }
            Ends::Clamped { start, end } => {
                a[(0, 0)] = 1.0;
                b[0] = start;
                a[(n, n)] = 1.0;
                b[n] = end;
            }
            Ends::Periodic => {}
        }
        let mut d: Vec<f64> = a.lu().solve(&b).expect("regular").iter().copied().collect();
        if periodic {
            d.push(d[0]);
        }
        d
    }

    /// Unevenly spaced knots 0 … n and values with all three kinds of ends' data.
    fn table(n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let x: Vec<f64> = (0..=n)
            .map(|i| i as f64 * 0.5 + 0.03 * (i % 3) as f64 + 0.011 * (i % 7) as f64)
            .collect();
        let y: Vec<f64> = x.iter().map(|x| (0.9 * x).sin() + 0.1 * x).collect();
        let mut closed: Vec<f64> = x.iter().map(|x| (x * 0.7).cos()).collect();
        closed[n] = closed[0];
        (x, y, closed)
    }

    /// The elimination down the band with the last slope as a border solves the same system
    /// as the dense LU: for every kind of ends and every size from the smallest a kind allows
    /// (2 points open, 4 closed: the border then touches the band's first and last rows at
    /// once) to 40. Both are backward stable on a system of condition number at most 3 with
    /// slopes of order 1: 1e-13 absolute leaves a factor of ~100 over rounding.
    #[test]
    fn the_banded_elimination_gives_the_dense_solves_slopes() {
        for n in 1..40 {
            let (x, y, closed) = table(n);
            let mut cases = vec![
                (Ends::Natural, &y),
                (
                    Ends::Clamped {
                        start: 0.4,
                        end: -1.1,
                    },
                    &y,
                ),
            ];
            if n >= 3 {
                cases.push((Ends::Periodic, &closed));
            }
            for (ends, values) in cases {
                let (banded, dense) = (slopes(&x, values, ends), dense_slopes(&x, values, ends));
                assert_eq!(banded.len(), n + 1);
                for (i, (a, b)) in banded.iter().zip(&dense).enumerate() {
                    assert!(
                        (a - b).abs() < 1e-13,
                        "{ends:?}, {n} segments, d_{i}: banded {a} vs dense {b}"
                    );
                }
            }
        }
    }

    /// Both routes build the same spline: values and three derivatives agree at points inside
    /// segments, at knots and beyond an open table's ends, for every kind of ends. The routes
    /// differ only by rounding: each solves a strictly diagonally dominant system (condition
    /// number at most 3) whose right-hand side holds differences of values of order Y = 1.5
    /// divided by h or h², and the k-th derivative divides again by hᵏ (h ≥ 0.45 here): the
    /// k-th derivatives agree within 100 ε·Y/h_minᵏ, ten times the largest difference they
    /// show (3.4e-15 in the value 1.2 beyond the last knot, where the end cubic's t³ grows).
    #[test]
    fn the_hermite_route_agrees_with_the_runtime_spline() {
        let (x, y, closed) = table(12);
        let h = x
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min);
        for (ends, values) in [
            (Ends::Natural, &y),
            (
                Ends::Clamped {
                    start: 0.4,
                    end: -1.1,
                },
                &y,
            ),
            (Ends::Periodic, &closed),
        ] {
            let spline = Spline::new(&x, values, ends).expect("a valid table");
            let hermite = Hermite::new(&spline);
            for k in 0..200 {
                let s = -0.5 + f64::from(k) * 0.04;
                let (a, b) = (spline.eval(s), hermite.eval(s));
                for order in 0..4 {
                    let tolerance = 100.0 * f64::EPSILON * 1.5 / h.powi(order as i32);
                    assert!(
                        (a[order] - b[order]).abs() < tolerance,
                        "{ends:?} S^({order})({s}): runtime {} vs Hermite {}",
                        a[order],
                        b[order]
                    );
                }
            }
        }
    }
}
