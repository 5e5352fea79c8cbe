//! Cubic splines through a table of points: the profiles that come as measured or CAD points.
//!
//! A spline S through (x₀, y₀) … (x_n, y_n) with x strictly increasing is, on each segment
//! [x_i, x_{i+1}] of length h_i, the cubic
//!
//! S(x) = M_i (x_{i+1} − x)³/(6h_i) + M_{i+1} (x − x_i)³/(6h_i)
//!        + (y_i/h_i − M_i h_i/6)(x_{i+1} − x) + (y_{i+1}/h_i − M_{i+1} h_i/6)(x − x_i),
//!
//! whose second derivatives at the knots M_i are chosen so that S′ is continuous there (S and
//! S″ are by construction): C² everywhere. That leaves two conditions, the [`Ends`]:
//!
//! - [`Ends::Natural`]: S″ = 0 at both ends (the shape a thin elastic strip takes);
//! - [`Ends::Clamped`]: S′ given at both ends (exact for any cubic through the points when
//!   the slopes are the cubic's);
//! - [`Ends::Periodic`]: S, S′ and S″ meet across the ends (a closed disc cam): the last point
//!   repeats the first one's value, one period later.
//!
//! The M_i solve a tridiagonal system (cyclic for a periodic spline) by the Thomas algorithm
//! (Sherman–Morrison for the cyclic corner), O(n). Evaluation finds the segment by bisection
//! (O(log n)) and returns the value and its first three derivatives exactly: no finite
//! differences anywhere.

use thiserror::Error;

/// The two conditions that complete a spline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Ends {
    /// S″ = 0 at the first and the last point.
    Natural,
    /// S′ = `start` at the first point and `end` at the last.
    Clamped {
        /// S′(x₀).
        start: f64,
        /// S′(x_n).
        end: f64,
    },
    /// S, S′, S″ continuous across the ends; y_n must equal y₀, and S(x + x_n − x₀) = S(x).
    Periodic,
}

/// Why a table cannot make a spline; `index` counts the table's points from 0.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SplineError {
    /// Fewer points than the end conditions need.
    #[error("a {ends} spline needs at least {needed} points, the table has {got}")]
    TooFewPoints {
        /// `natural`, `clamped` or `periodic`.
        ends: &'static str,
        /// The least number of points.
        needed: usize,
        /// The table's.
        got: usize,
    },
    /// The abscissas and the values differ in number.
    #[error("the table has {x} abscissas but {y} values")]
    LengthMismatch {
        /// Number of abscissas.
        x: usize,
        /// Number of values.
        y: usize,
    },
    /// A value that is NaN or infinite.
    #[error("point {index} is not a finite number ({value})")]
    NotFinite {
        /// The point.
        index: usize,
        /// The value found.
        value: f64,
    },
    /// An abscissa not larger than the one before.
    #[error(
        "the abscissas must increase strictly, but point {index} ({value}) does not exceed \
         point {} ({previous})", index - 1
    )]
    NotIncreasing {
        /// The point.
        index: usize,
        /// Its abscissa.
        value: f64,
        /// The abscissa before it.
        previous: f64,
    },
    /// A periodic (closed) table whose last value is not its first.
    #[error(
        "a closed profile must end where it starts, but its first value is {first} and its \
         last {last} (difference {:.3e})", (last - first).abs()
    )]
    EndsDoNotMeet {
        /// y₀.
        first: f64,
        /// y_n.
        last: f64,
    },
}

/// Relative tolerance within which a periodic table's last value must equal its first (a
/// table written with 12 significant digits meets it).
pub const CLOSURE_TOLERANCE: f64 = 1e-9;

/// A spline that owns its table.
#[derive(Debug, Clone, PartialEq)]
pub struct Spline {
    x: Vec<f64>,
    y: Vec<f64>,
    m: Vec<f64>,
    ends: Ends,
}

impl Spline {
    /// The spline through `(x[i], y[i])` with the `ends` conditions, or why the table cannot
    /// make one.
    pub fn new(x: &[f64], y: &[f64], ends: Ends) -> Result<Self, SplineError> {
        let m = second_derivatives(x, y, ends)?;
        Ok(Spline {
            x: x.to_vec(),
            y: y.to_vec(),
            m,
            ends,
        })
    }

    /// The abscissas of the table.
    pub fn abscissas(&self) -> &[f64] {
        &self.x
    }

    /// The values of the table.
    pub fn values(&self) -> &[f64] {
        &self.y
    }

    /// The second derivatives at the knots (what generated code stores beside the table).
    pub fn knot_curvatures(&self) -> &[f64] {
        &self.m
    }

    /// True for a closed (periodic) spline.
    pub fn is_periodic(&self) -> bool {
        self.ends == Ends::Periodic
    }

    /// The end conditions it was built with.
    pub fn ends(&self) -> Ends {
        self.ends
    }

    /// [S, S′, S″, S‴] at `s` ([`evaluate`]).
    pub fn eval(&self, s: f64) -> [f64; 4] {
        evaluate(&self.x, &self.y, &self.m, self.is_periodic(), s)
    }
}

/// The least number of points for `ends`: two for an open spline (a straight segment), four
/// for a closed one (three distinct points and the first repeated).
fn least_points(ends: Ends) -> (&'static str, usize) {
    match ends {
        Ends::Natural => ("natural", 2),
        Ends::Clamped { .. } => ("clamped", 2),
        Ends::Periodic => ("periodic", 4),
    }
}

/// Checks a table: lengths, finiteness, strictly increasing abscissas, a closed table's ends.
pub fn check_table(x: &[f64], y: &[f64], ends: Ends) -> Result<(), SplineError> {
    if x.len() != y.len() {
        return Err(SplineError::LengthMismatch {
            x: x.len(),
            y: y.len(),
        });
    }
    let (name, needed) = least_points(ends);
    if x.len() < needed {
        return Err(SplineError::TooFewPoints {
            ends: name,
            needed,
            got: x.len(),
        });
    }
    for (index, (&a, &b)) in x.iter().zip(y).enumerate() {
        for value in [a, b] {
            if !value.is_finite() {
                return Err(SplineError::NotFinite { index, value });
            }
        }
    }
    if let Some(index) = (1..x.len()).find(|&i| x[i] <= x[i - 1]) {
        return Err(SplineError::NotIncreasing {
            index,
            value: x[index],
            previous: x[index - 1],
        });
    }
    if ends == Ends::Periodic {
        let (first, last) = (y[0], y[y.len() - 1]);
        let scale = y
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        if (last - first).abs() > CLOSURE_TOLERANCE * scale {
            return Err(SplineError::EndsDoNotMeet { first, last });
        }
    }
    Ok(())
}

/// The second derivatives M_i of the spline at its knots (see the module's formula).
pub fn second_derivatives(x: &[f64], y: &[f64], ends: Ends) -> Result<Vec<f64>, SplineError> {
    check_table(x, y, ends)?;
    let n = x.len() - 1;
    let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    let slope: Vec<f64> = (0..n).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
    let m = match ends {
        Ends::Natural if n == 1 => vec![0.0; 2],
        Ends::Natural => {
            // Unknowns M_1 … M_{n−1}; M_0 = M_n = 0.
            let rows = n - 1;
            let (mut sub, mut diag, mut sup, mut rhs) = (
                vec![0.0; rows],
                vec![0.0; rows],
                vec![0.0; rows],
                vec![0.0; rows],
            );
            for r in 0..rows {
                let i = r + 1;
                sub[r] = h[i - 1];
                diag[r] = 2.0 * (h[i - 1] + h[i]);
                sup[r] = h[i];
                rhs[r] = 6.0 * (slope[i] - slope[i - 1]);
            }
            let inner = thomas(&sub, &diag, &sup, &rhs);
            let mut m = vec![0.0; n + 1];
            m[1..n].copy_from_slice(&inner);
            m
        }
        Ends::Clamped { start, end } => {
            let rows = n + 1;
            let (mut sub, mut diag, mut sup, mut rhs) = (
                vec![0.0; rows],
                vec![0.0; rows],
                vec![0.0; rows],
                vec![0.0; rows],
            );
            diag[0] = 2.0 * h[0];
            sup[0] = h[0];
            rhs[0] = 6.0 * (slope[0] - start);
            for i in 1..n {
                sub[i] = h[i - 1];
                diag[i] = 2.0 * (h[i - 1] + h[i]);
                sup[i] = h[i];
                rhs[i] = 6.0 * (slope[i] - slope[i - 1]);
            }
            sub[n] = h[n - 1];
            diag[n] = 2.0 * h[n - 1];
            rhs[n] = 6.0 * (end - slope[n - 1]);
            thomas(&sub, &diag, &sup, &rhs)
        }
        Ends::Periodic => {
            // Unknowns M_0 … M_{n−1}, M_n = M_0; row i couples M_{i−1}, M_i, M_{i+1} with the
            // indices taken around the period.
            let (mut sub, mut diag, mut sup, mut rhs) =
                (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            for i in 0..n {
                let before = (i + n - 1) % n;
                sub[i] = h[before];
                diag[i] = 2.0 * (h[before] + h[i]);
                sup[i] = h[i];
                rhs[i] = 6.0 * (slope[i] - slope[before]);
            }
            let mut m = cyclic_thomas(&sub, &diag, &sup, &rhs);
            m.push(m[0]);
            m
        }
    };
    Ok(m)
}

/// Solves the tridiagonal system with sub-diagonal `a` (a[0] unused), diagonal `b` and
/// super-diagonal `c` (c[last] unused). The spline's systems are strictly diagonally
/// dominant, so no pivoting is needed.
fn thomas(a: &[f64], b: &[f64], c: &[f64], d: &[f64]) -> Vec<f64> {
    let n = b.len();
    let (mut cp, mut dp) = (vec![0.0; n], vec![0.0; n]);
    for i in 0..n {
        let (below_c, below_d) = if i == 0 {
            (0.0, 0.0)
        } else {
            (cp[i - 1], dp[i - 1])
        };
        let pivot = b[i] - a[i] * below_c;
        cp[i] = c[i] / pivot;
        dp[i] = (d[i] - a[i] * below_d) / pivot;
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        x[i] = dp[i] - if i + 1 < n { cp[i] * x[i + 1] } else { 0.0 };
    }
    x
}

/// Solves the cyclic tridiagonal system (corners a[0] at the top right, c[n−1] at the bottom
/// left) by Sherman–Morrison: two ordinary tridiagonal solves.
fn cyclic_thomas(a: &[f64], b: &[f64], c: &[f64], d: &[f64]) -> Vec<f64> {
    let n = b.len();
    if n == 2 {
        // Both corners fall on the off-diagonals: a dense 2 × 2 solve.
        let (p, q, r, s) = (b[0], c[0] + a[0], a[1] + c[1], b[1]);
        let det = p * s - q * r;
        return vec![(d[0] * s - q * d[1]) / det, (p * d[1] - r * d[0]) / det];
    }
    let (alpha, beta) = (c[n - 1], a[0]);
    let gamma = -b[0];
    let mut bb = b.to_vec();
    bb[0] = b[0] - gamma;
    bb[n - 1] = b[n - 1] - alpha * beta / gamma;
    let x = thomas(a, &bb, c, d);
    let mut u = vec![0.0; n];
    u[0] = gamma;
    u[n - 1] = alpha;
    let z = thomas(a, &bb, c, &u);
    let factor = (x[0] + beta * x[n - 1] / gamma) / (1.0 + z[0] + beta * z[n - 1] / gamma);
    x.iter().zip(&z).map(|(xi, zi)| xi - factor * zi).collect()
}

/// The segment of `x` holding `s` (the first or last one beyond the table's ends): the last
/// knot at or below s, by bisection written without branches on the comparisons (each halving
/// a conditional move: about twice as fast as a branching search on a table of a few hundred
/// points, where the comparisons cannot be predicted).
pub fn segment(x: &[f64], s: f64) -> usize {
    let last = x.len().saturating_sub(2);
    if s.is_nan() || s <= x[0] {
        return 0;
    }
    if s >= x[last + 1] {
        return last;
    }
    let (mut base, mut size) = (0, x.len());
    while size > 1 {
        let half = size / 2;
        let middle = base + half;
        base = if x[middle] <= s { middle } else { base };
        size -= half;
    }
    base.min(last)
}

/// [S, S′, S″, S‴] at `s` for the table `x`, `y` with knot second derivatives `m`. A periodic
/// spline is evaluated at `s` moved into [x₀, x_n) by whole periods; an open one beyond its
/// ends continues its end cubics.
pub fn evaluate(x: &[f64], y: &[f64], m: &[f64], periodic: bool, s: f64) -> [f64; 4] {
    let (first, last) = (x[0], x[x.len() - 1]);
    let s = if periodic && !(first <= s && s < last) {
        let period = last - first;
        s - ((s - first) / period).floor() * period
    } else {
        s
    };
    let i = segment(x, s);
    let h = x[i + 1] - x[i];
    let inverse = 1.0 / h;
    let (to_end, from_start) = (x[i + 1] - s, s - x[i]);
    let (a, b) = (m[i], m[i + 1]);
    let (left, right) = (y[i] - a * h * h / 6.0, y[i + 1] - b * h * h / 6.0);
    let (a2, b2) = (a * to_end * to_end, b * from_start * from_start);
    [
        ((a2 * to_end + b2 * from_start) / 6.0 + left * to_end + right * from_start) * inverse,
        ((b2 - a2) / 2.0 - left + right) * inverse,
        (a * to_end + b * from_start) * inverse,
        (b - a) * inverse,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize, a: f64, b: f64) -> Vec<f64> {
        (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect()
    }

    /// The conditions that define the spline, checked directly: it passes through the
    /// points, S, S′, S″ agree from both sides at every interior knot, and the end conditions
    /// hold. Together they determine the M_i, so this checks the linear solve by another
    /// route. Tolerances: values of order 1 after O(n) operations round to ~1e-15, so
    /// 1e-11; the derivatives at a knot are differences of terms divided by h and h², which
    /// multiplies that rounding by up to 1/h² ~ 100 here: 1e-9 relative.
    fn assert_defines(spline: &Spline, ends: Ends) {
        let (x, y) = (&spline.x, &spline.y);
        let n = x.len() - 1;
        for i in 0..=n {
            let at = evaluate(x, y, &spline.m, false, x[i]);
            assert!((at[0] - y[i]).abs() < 1e-11, "S(x_{i})");
        }
        let cubic = |i: usize, s: f64| {
            let h = x[i + 1] - x[i];
            let (to_end, from_start) = (x[i + 1] - s, s - x[i]);
            let (a, b) = (spline.m[i], spline.m[i + 1]);
            let (left, right) = (y[i] / h - a * h / 6.0, y[i + 1] / h - b * h / 6.0);
            [
                (a * to_end.powi(3) + b * from_start.powi(3)) / (6.0 * h)
                    + left * to_end
                    + right * from_start,
                (b * from_start.powi(2) - a * to_end.powi(2)) / (2.0 * h) - left + right,
                (a * to_end + b * from_start) / h,
            ]
        };
        for (i, &knot) in x.iter().enumerate().take(n).skip(1) {
            let (l, r) = (cubic(i - 1, knot), cubic(i, knot));
            for k in 0..3 {
                assert!(
                    (l[k] - r[k]).abs() < 1e-9 * (1.0 + l[k].abs()),
                    "knot {i} S^({k})"
                );
            }
        }
        let (start, end) = (cubic(0, x[0]), cubic(n - 1, x[n]));
        match ends {
            Ends::Natural => assert!(start[2].abs() < 1e-11 && end[2].abs() < 1e-11),
            Ends::Clamped { start: a, end: b } => {
                assert!((start[1] - a).abs() < 1e-11 && (end[1] - b).abs() < 1e-11);
            }
            Ends::Periodic => {
                for k in 0..3 {
                    assert!(
                        (start[k] - end[k]).abs() < 1e-9 * (1.0 + start[k].abs()),
                        "S^({k})"
                    );
                }
            }
        }
    }

    #[test]
    fn the_solved_spline_meets_its_defining_conditions() {
        let x: Vec<f64> = vec![0.0, 0.3, 0.45, 1.0, 1.2, 2.0, 2.1, 3.0];
        let y: Vec<f64> = x.iter().map(|v: &f64| (1.7 * v).sin() + 0.2 * v).collect();
        for ends in [
            Ends::Natural,
            Ends::Clamped {
                start: 0.4,
                end: -1.1,
            },
        ] {
            assert_defines(&Spline::new(&x, &y, ends).unwrap(), ends);
        }
        let mut closed = y.clone();
        closed[7] = closed[0];
        assert_defines(
            &Spline::new(&x, &closed, Ends::Periodic).unwrap(),
            Ends::Periodic,
        );
        // The smallest closed table: three distinct points.
        let small = Spline::new(
            &[0.0, 1.0, 2.5, 3.0],
            &[1.0, 2.0, -1.0, 1.0],
            Ends::Periodic,
        );
        assert_defines(&small.unwrap(), Ends::Periodic);
    }

    #[test]
    fn a_clamped_spline_reproduces_a_cubic_exactly() {
        // A cubic lies in the spline space: with its own end slopes the spline is the cubic
        // itself (to rounding, 1e-12 on values of order 10).
        let p = |s: f64| {
            [
                2.0 - s + 0.5 * s * s - 0.3 * s.powi(3),
                -1.0 + s - 0.9 * s * s,
                1.0 - 1.8 * s,
                -1.8,
            ]
        };
        let x = vec![-1.0, -0.2, 0.4, 0.5, 1.3, 2.0];
        let y: Vec<f64> = x.iter().map(|&s| p(s)[0]).collect();
        let spline = Spline::new(
            &x,
            &y,
            Ends::Clamped {
                start: p(-1.0)[1],
                end: p(2.0)[1],
            },
        )
        .unwrap();
        for k in 0..=60 {
            let s = -1.0 + 3.0 * k as f64 / 60.0;
            let (got, want) = (spline.eval(s), p(s));
            for d in 0..4 {
                assert!(
                    (got[d] - want[d]).abs() < 1e-12,
                    "S^({d})({s}): {} vs {}",
                    got[d],
                    want[d]
                );
            }
        }
    }

    #[test]
    fn a_periodic_spline_of_a_circle_converges_at_fourth_order() {
        // r(θ) = 1 + 0.2 cos θ + 0.05 sin 3θ sampled at n points: the error in S falls as
        // h⁴, in S′ as h³, in S″ as h² (fitted slopes between n = 32 and 256, ±0.3).
        let r = |t: f64| {
            [
                1.0 + 0.2 * t.cos() + 0.05 * (3.0 * t).sin(),
                -0.2 * t.sin() + 0.15 * (3.0 * t).cos(),
                -0.2 * t.cos() - 0.45 * (3.0 * t).sin(),
            ]
        };
        let tau = std::f64::consts::TAU;
        let error = |n: usize| {
            let x = grid(n, 0.0, tau);
            let mut y: Vec<f64> = x.iter().map(|&t| r(t)[0]).collect();
            y[n] = y[0];
            let spline = Spline::new(&x, &y, Ends::Periodic).unwrap();
            let mut worst = [0.0f64; 3];
            for k in 0..2000 {
                // Also one period beyond: the spline repeats.
                let t = -tau + 3.0 * tau * k as f64 / 2000.0;
                let (got, want) = (spline.eval(t), r(t));
                for d in 0..3 {
                    worst[d] = worst[d].max((got[d] - want[d]).abs());
                }
            }
            worst
        };
        let (coarse, fine) = (error(32), error(256));
        for (d, order) in [(0, 4.0), (1, 3.0), (2, 2.0)] {
            let slope = (coarse[d] / fine[d]).ln() / 8.0f64.ln();
            assert!((slope - order).abs() < 0.3, "S^({d}): order {slope:.2}");
        }
    }

    #[test]
    fn bad_tables_are_refused_with_the_point() {
        let e = |x: &[f64], y: &[f64], ends| Spline::new(x, y, ends).unwrap_err();
        assert!(matches!(
            e(&[0.0], &[1.0], Ends::Natural),
            SplineError::TooFewPoints {
                needed: 2,
                got: 1,
                ..
            }
        ));
        assert!(matches!(
            e(&[0.0, 1.0, 2.0], &[1.0, 0.0, 1.0], Ends::Periodic),
            SplineError::TooFewPoints { needed: 4, .. }
        ));
        assert_eq!(
            e(&[0.0, 1.0, 1.0, 2.0], &[0.0; 4], Ends::Natural),
            SplineError::NotIncreasing {
                index: 2,
                value: 1.0,
                previous: 1.0
            }
        );
        assert!(matches!(
            e(&[0.0, 1.0, 2.0], &[0.0, f64::NAN, 0.0], Ends::Natural),
            SplineError::NotFinite { index: 1, .. }
        ));
        assert_eq!(
            e(&[0.0, 1.0, 2.0, 3.0], &[1.0, 2.0, 0.0, 1.5], Ends::Periodic),
            SplineError::EndsDoNotMeet {
                first: 1.0,
                last: 1.5
            }
        );
        assert!(matches!(
            e(&[0.0, 1.0], &[0.0], Ends::Natural),
            SplineError::LengthMismatch { .. }
        ));
        let message = e(&[0.0, 2.0, 1.0], &[0.0; 3], Ends::Natural).to_string();
        assert_eq!(
            message,
            "the abscissas must increase strictly, but point 2 (1) does not exceed point 1 (2)"
        );
    }

    #[test]
    fn segments_are_found_at_and_between_knots() {
        let x = [0.0, 1.0, 2.0, 4.0];
        assert_eq!(segment(&x, -5.0), 0);
        assert_eq!(segment(&x, 0.0), 0);
        assert_eq!(segment(&x, 1.0), 1);
        assert_eq!(segment(&x, 3.9), 2);
        assert_eq!(segment(&x, 4.0), 2);
        assert_eq!(segment(&x, 9.0), 2);
        assert_eq!(segment(&x, f64::NAN), 0);
        // Against the definition (the last knot ≤ s), on uneven tables where the guess misses
        // by more than the walk: knots crowded at one end.
        for n in [2usize, 3, 7, 50] {
            let x: Vec<f64> = (0..n)
                .map(|i| (i as f64 / (n - 1) as f64).powi(4))
                .collect();
            for k in 0..=400 {
                let s = -0.1 + 1.2 * k as f64 / 400.0;
                let want = x
                    .iter()
                    .rposition(|&knot| knot <= s)
                    .unwrap_or(0)
                    .min(n - 2);
                assert_eq!(segment(&x, s), want, "n = {n}, s = {s}");
            }
        }
    }
}
