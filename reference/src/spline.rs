//! The reference's own route to a tabulated function's value and derivatives.
//!
//! A spline through a table of points is the same curve whichever way it is built, so the
//! reference builds it differently from the runtime (`camchain_runtime::spline`, which solves
//! a tridiagonal system for the second derivatives at the knots by the Thomas algorithm and
//! Sherman–Morrison): here the unknowns are the slopes d_i at the knots (the Hermite form),
//! found from the C² conditions by a dense LU solve with nalgebra, and each segment is the
//! cubic Hermite interpolant
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

use camchain_codegen::profile::{Tabulated, TabulatedFunction};
use camchain_runtime::spline::{Ends, Spline};
use nalgebra::{DMatrix, DVector};
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
    /// The spline of `spline`'s table and ends, solved for its knot slopes; NaN slopes when
    /// the dense system is singular (a table the runtime refuses anyway).
    pub fn new(spline: &Spline) -> Self {
        let (x, y) = (spline.abscissas().to_vec(), spline.values().to_vec());
        let d = slopes(&x, &y, spline.ends());
        Hermite {
            x,
            y,
            d,
            periodic: spline.is_periodic(),
        }
    }

    /// [S, S′, S″, S‴] at s; a periodic spline repeats, an open one continues its end cubics.
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
/// across the ends, with d_n = d₀), solved densely.
fn slopes(x: &[f64], y: &[f64], ends: Ends) -> Vec<f64> {
    let n = x.len() - 1;
    let h: Vec<f64> = (0..n).map(|i| x[i + 1] - x[i]).collect();
    let secant = |i: usize| (y[i + 1] - y[i]) / (h[i] * h[i]);
    // S″ continuity at knot i between segments a (ending there) and b (starting there):
    // d_a/h_a + 2 (1/h_a + 1/h_b) d_i + d_b/h_b = 3 (secant_a + secant_b).
    let unknowns = if ends == Ends::Periodic { n } else { n + 1 };
    let mut a = DMatrix::<f64>::zeros(unknowns, unknowns);
    let mut b = DVector::<f64>::zeros(unknowns);
    for i in 1..n {
        a[(i, i - 1)] = 1.0 / h[i - 1];
        a[(i, i)] = 2.0 * (1.0 / h[i - 1] + 1.0 / h[i]);
        let next = if ends == Ends::Periodic && i + 1 == n {
            0
        } else {
            i + 1
        };
        a[(i, next)] += 1.0 / h[i];
        b[i] = 3.0 * (secant(i - 1) + secant(i));
    }
    match ends {
        Ends::Natural => {
            // S″(x₀) = 0: 2 d₀ + d₁ = 3 (y₁ − y₀)/h₀; the same mirrored at the last knot.
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
        Ends::Periodic => {
            // Knot 0 joins the last segment (n − 1) to the first.
            a[(0, n - 1)] += 1.0 / h[n - 1];
            a[(0, 0)] += 2.0 * (1.0 / h[n - 1] + 1.0 / h[0]);
            a[(0, 1 % n)] += 1.0 / h[0];
            b[0] = 3.0 * (secant(n - 1) + secant(0));
        }
    }
    let d = a
        .lu()
        .solve(&b)
        .map(|d| d.iter().copied().collect::<Vec<f64>>())
        .unwrap_or_else(|| vec![f64::NAN; unknowns]);
    match ends {
        Ends::Periodic => {
            let mut d = d;
            d.push(d[0]);
            d
        }
        _ => d,
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

    /// Both routes build the same spline: values and three derivatives agree at points inside
    /// segments, at knots and beyond an open table's ends, for every kind of ends. The
    /// runtime's and the dense solve differ by rounding of O(n) operations on values of order
    /// 1 scaled by up to 1/h³ ≈ 2e3 for the third derivative: 1e-9 relative.
    #[test]
    fn the_hermite_route_agrees_with_the_runtime_spline() {
        let x: Vec<f64> = (0..=12)
            .map(|i| f64::from(i) * 0.5 + 0.03 * f64::from(i % 3))
            .collect();
        let y: Vec<f64> = x.iter().map(|x| (0.9 * x).sin() + 0.1 * x).collect();
        let closed: Vec<f64> = {
            let mut c: Vec<f64> = x.iter().map(|x| (x * 0.7).cos()).collect();
            let first = c[0];
            if let Some(last) = c.last_mut() {
                *last = first;
            }
            c
        };
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
                    let scale = 1.0 + a[order].abs();
                    assert!(
                        (a[order] - b[order]).abs() < 1e-9 * scale,
                        "{ends:?} S^({order})({s}): runtime {} vs Hermite {}",
                        a[order],
                        b[order]
                    );
                }
            }
        }
    }
}
