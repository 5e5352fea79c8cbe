//! Second-order forward-mode automatic differentiation of one-variable expressions.
//!
//! The numeric reference needs a cam profile's f3, f3' and f3'' at the contact point (eqs.
//! 5b, 7, 8) and a drive's q, q̇, q̈ at time t, and the schema's checks a profile's curvature
//! along its range. The symbolic generator differentiates the [`Scalar`] tree symbolically;
//! here the same tree is evaluated on truncated Taylor polynomials ([`Jet2`]), an independent
//! route to the same three numbers. A function given by data ([`Scalar::Table`]) is
//! differentiated by a [`TableDerivative`]: its own ([`own_tables`], the runtime's spline and
//! motion law) or the caller's (the numeric reference brings its own spline); a surface
//! given on a grid ([`Scalar::Grid`]) by its own bicubic spline (the reference evaluates
//! those on its own route in its tape).

use crate::profile::{Func, Scalar, Tabulated};
use std::ops::{Add, Div, Mul, Neg, Sub};
use std::sync::Arc;

/// A value with its first and second derivatives with respect to the one variable.
///
/// Arithmetic on jets follows the product and chain rules truncated at second order, so
/// evaluating an expression on the jet `(x, 1, 0)` yields `(f(x), f'(x), f''(x))`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Jet2 {
    /// f
    pub v: f64,
    /// f'
    pub d1: f64,
    /// f''
    pub d2: f64,
}

impl Jet2 {
    /// A constant: both derivatives are zero.
    pub fn constant(v: f64) -> Self {
        Self {
            v,
            d1: 0.0,
            d2: 0.0,
        }
    }

    /// The independent variable at `x`: derivative 1, second derivative 0.
    pub fn variable(x: f64) -> Self {
        Self {
            v: x,
            d1: 1.0,
            d2: 0.0,
        }
    }

    /// True when both derivatives vanish (the jet is a constant).
    pub fn is_constant(&self) -> bool {
        self.d1 == 0.0 && self.d2 == 0.0
    }

    /// Chain rule g(self) given g, g' and g'' evaluated at `self.v`:
    /// (g∘u)' = g'(u) u', (g∘u)'' = g''(u) u'² + g'(u) u''.
    pub fn compose(self, g: f64, dg: f64, ddg: f64) -> Self {
        Self {
            v: g,
            d1: dg * self.d1,
            d2: ddg * self.d1 * self.d1 + dg * self.d2,
        }
    }

    /// Chain rule g(a, b) for a function of two variables, given its partial derivatives
    /// `d(i, j)` = ∂ⁱ_a ∂ʲ_b g at (a.v, b.v), i + j ≤ 2:
    /// (g∘(a, b))' = g_a a' + g_b b', (g∘(a, b))'' = g_aa a'² + 2 g_ab a' b' + g_bb b'² +
    /// g_a a'' + g_b b''.
    pub fn compose2(a: Self, b: Self, d: impl Fn(u8, u8) -> f64) -> Self {
        let (ga, gb) = (d(1, 0), d(0, 1));
        Self {
            v: d(0, 0),
            d1: ga * a.d1 + gb * b.d1,
            d2: d(2, 0) * a.d1 * a.d1
                + 2.0 * d(1, 1) * a.d1 * b.d1
                + d(0, 2) * b.d1 * b.d1
                + ga * a.d2
                + gb * b.d2,
        }
    }

    /// self^n for an integer n (negative allowed).
    pub fn powi(self, n: i32) -> Self {
        let x = self.v;
        let dg = scaled_powi(f64::from(n), x, n - 1);
        let ddg = scaled_powi(f64::from(n) * f64::from(n - 1), x, n - 2);
        self.compose(x.powi(n), dg, ddg)
    }

    /// self^b with a possibly variable exponent. A constant exponent uses the power rule
    /// (which also serves a negative base with an integral exponent); otherwise
    /// a^b = exp(b ln a), defined for a > 0.
    pub fn powf(self, b: Self) -> Self {
        if b.is_constant() {
            let (x, p) = (self.v, b.v);
            let dg = scaled_powf(p, x, p - 1.0);
            let ddg = scaled_powf(p * (p - 1.0), x, p - 2.0);
            self.compose(x.powf(p), dg, ddg)
        } else {
            (b * self.ln()).exp()
        }
    }

    /// sin
    pub fn sin(self) -> Self {
        let (s, c) = self.v.sin_cos();
        self.compose(s, c, -s)
    }

    /// cos
    pub fn cos(self) -> Self {
        let (s, c) = self.v.sin_cos();
        self.compose(c, -s, -c)
    }

    /// tan: (tan)' = 1 + tan², (tan)'' = 2 tan (1 + tan²).
    pub fn tan(self) -> Self {
        let t = self.v.tan();
        let sec2 = 1.0 + t * t;
        self.compose(t, sec2, 2.0 * t * sec2)
    }

    /// exp
    pub fn exp(self) -> Self {
        let e = self.v.exp();
        self.compose(e, e, e)
    }

    /// Natural logarithm.
    pub fn ln(self) -> Self {
        let r = 1.0 / self.v;
        self.compose(self.v.ln(), r, -r * r)
    }

    /// Square root: (√x)' = 1/(2√x), (√x)'' = −1/(4 x √x).
    pub fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        self.compose(s, 0.5 / s, -0.25 / (self.v * s))
    }

    /// sinh
    pub fn sinh(self) -> Self {
        let (sh, ch) = (self.v.sinh(), self.v.cosh());
        self.compose(sh, ch, sh)
    }

    /// cosh
    pub fn cosh(self) -> Self {
        let (sh, ch) = (self.v.sinh(), self.v.cosh());
        self.compose(ch, sh, ch)
    }

    /// tanh: (tanh)' = 1 − tanh², (tanh)'' = −2 tanh (1 − tanh²).
    pub fn tanh(self) -> Self {
        let t = self.v.tanh();
        let sech2 = 1.0 - t * t;
        self.compose(t, sech2, -2.0 * t * sech2)
    }

    /// atan: (atan)' = 1/(1 + x²), (atan)'' = −2x/(1 + x²)².
    pub fn atan(self) -> Self {
        let x = self.v;
        let r = 1.0 / (1.0 + x * x);
        self.compose(x.atan(), r, -2.0 * x * r * r)
    }

    /// Applies one of the elementary functions allowed in expressions.
    pub fn apply(self, func: Func) -> Self {
        match func {
            Func::Sin => self.sin(),
            Func::Cos => self.cos(),
            Func::Tan => self.tan(),
            Func::Exp => self.exp(),
            Func::Ln => self.ln(),
            Func::Sqrt => self.sqrt(),
            Func::Sinh => self.sinh(),
            Func::Cosh => self.cosh(),
            Func::Tanh => self.tanh(),
            Func::Atan => self.atan(),
        }
    }
}

/// c · x^k, taken as exactly 0 when c = 0 (so that x^(−1) at x = 0 cannot make 0·∞ = NaN).
fn scaled_powi(c: f64, x: f64, k: i32) -> f64 {
    if c == 0.0 { 0.0 } else { c * x.powi(k) }
}

/// c · x^k for a real exponent, exactly 0 when c = 0.
fn scaled_powf(c: f64, x: f64, k: f64) -> f64 {
    if c == 0.0 { 0.0 } else { c * x.powf(k) }
}

impl Neg for Jet2 {
    type Output = Self;
    fn neg(self) -> Self {
        Self {
            v: -self.v,
            d1: -self.d1,
            d2: -self.d2,
        }
    }
}

impl Add for Jet2 {
    type Output = Self;
    fn add(self, b: Self) -> Self {
        Self {
            v: self.v + b.v,
            d1: self.d1 + b.d1,
            d2: self.d2 + b.d2,
        }
    }
}

impl Sub for Jet2 {
    type Output = Self;
    fn sub(self, b: Self) -> Self {
        Self {
            v: self.v - b.v,
            d1: self.d1 - b.d1,
            d2: self.d2 - b.d2,
        }
    }
}

impl Mul for Jet2 {
    type Output = Self;
    /// Leibniz rule: (ab)' = a'b + ab', (ab)'' = a''b + 2a'b' + ab''.
    fn mul(self, b: Self) -> Self {
        Self {
            v: self.v * b.v,
            d1: self.d1 * b.v + self.v * b.d1,
            d2: self.d2 * b.v + 2.0 * self.d1 * b.d1 + self.v * b.d2,
        }
    }
}

impl Div for Jet2 {
    type Output = Self;
    /// Quotient rule from a = q·b: q' = (a' − q b')/b, q'' = (a'' − 2 q' b' − q b'')/b.
    fn div(self, b: Self) -> Self {
        let v = self.v / b.v;
        let d1 = (self.d1 - v * b.d1) / b.v;
        let d2 = (self.d2 - 2.0 * d1 * b.d1 - v * b.d2) / b.v;
        Self { v, d1, d2 }
    }
}

/// The derivative of order `order` (0: the value) of a function given by data at `x`.
pub type TableDerivative = dyn Fn(&Arc<Tabulated>, u8, f64) -> f64;

/// A table's derivatives from its own evaluator (the runtime's spline or motion law).
pub fn own_tables(f: &Arc<Tabulated>, order: u8, x: f64) -> f64 {
    f.derivative(order, x)
}

/// Evaluates `expr` as a jet at `x`: the jet of the variable is `(x, 1, 0)`.
pub fn eval_jet2(expr: &Scalar, x: f64, tables: &TableDerivative) -> Jet2 {
    eval_on(expr, Jet2::variable(x), tables)
}

/// Evaluates `expr` with its variable given as the jet `x` (the chain rule through an inner
/// function: a profile at a point that itself moves).
pub fn eval_on(expr: &Scalar, x: Jet2, tables: &TableDerivative) -> Jet2 {
    eval_on_all(expr, &[x], tables)
}

/// [`eval_on`] with variable i given as the jet `vars[i]`: a surface z = f(x, y) along the
/// line (x + t dx, y + t dy) gives its directional derivatives in t.
pub fn eval_on_all(expr: &Scalar, vars: &[Jet2], tables: &TableDerivative) -> Jet2 {
    let ev = |e: &Scalar| eval_on_all(e, vars, tables);
    match expr {
        Scalar::Const(c) => Jet2::constant(*c),
        Scalar::Var(i) => vars
            .get(usize::from(*i))
            .copied()
            .unwrap_or(Jet2::constant(f64::NAN)),
        // Validated models hand the reference their expressions with every parameter
        // resolved to its value; an unresolved one has no value here.
        Scalar::Param(_) => Jet2::constant(f64::NAN),
        Scalar::Neg(a) => -ev(a),
        Scalar::Add(a, b) => ev(a) + ev(b),
        Scalar::Sub(a, b) => ev(a) - ev(b),
        Scalar::Mul(a, b) => ev(a) * ev(b),
        Scalar::Div(a, b) => ev(a) / ev(b),
        Scalar::Powi(a, n) => ev(a).powi(*n),
        Scalar::Powf(a, b) => ev(a).powf(ev(b)),
        Scalar::Call(func, a) => ev(a).apply(*func),
        Scalar::Table(t, order, a) => {
            let inner = ev(a);
            let d = |k: u8| tables(t, order + k, inner.v);
            inner.compose(d(0), d(1), d(2))
        }
        Scalar::Grid(g, (p, q), a, b) => {
            let (a, b) = (ev(a), ev(b));
            Jet2::compose2(a, b, |i, j| g.derivative((p + i, q + j), a.v, b.v))
        }
    }
}

/// The value of `expr` at `x` with [`Scalar::Param`] `i` given by `values[i]` (an applied
/// joint load: its extra parameters are the coordinates and their rates), NaN for an index
/// past them.
pub fn eval_with(expr: &Scalar, x: f64, values: &[f64], tables: &TableDerivative) -> f64 {
    let ev = |e: &Scalar| eval_with(e, x, values, tables);
    match expr {
        Scalar::Const(c) => *c,
        Scalar::Var(0) => x,
        Scalar::Var(_) => f64::NAN,
        Scalar::Param(i) => values.get(*i).copied().unwrap_or(f64::NAN),
        Scalar::Neg(a) => -ev(a),
        Scalar::Add(a, b) => ev(a) + ev(b),
        Scalar::Sub(a, b) => ev(a) - ev(b),
        Scalar::Mul(a, b) => ev(a) * ev(b),
        Scalar::Div(a, b) => ev(a) / ev(b),
        Scalar::Powi(a, n) => ev(a).powi(*n),
        Scalar::Powf(a, b) => ev(a).powf(ev(b)),
        Scalar::Call(func, a) => Jet2::constant(ev(a)).apply(*func).v,
        Scalar::Table(t, order, a) => tables(t, *order, ev(a)),
        Scalar::Grid(g, order, a, b) => g.derivative(*order, ev(a), ev(b)),
    }
}

/// `(f(x), f'(x), f''(x))` of a profile y = f3(x) (eqs. 5b, 7, 8) or a drive q(t), by
/// forward-mode differentiation.
pub fn eval_jet(expr: &Scalar, x: f64, tables: &TableDerivative) -> [f64; 3] {
    let j = eval_jet2(expr, x, tables);
    [j.v, j.d1, j.d2]
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    // Closed-form derivatives are evaluated with the same libm functions, so the only
    // differences are rounding in a handful of operations: a relative 1e-12 leaves a margin
    // of ~10⁴ ulps while catching any wrong formula (those err at O(1)).
    const TOL: f64 = 1e-12;

    fn var() -> Box<Scalar> {
        Box::new(Scalar::Var(0))
    }
    fn cst(c: f64) -> Box<Scalar> {
        Box::new(Scalar::Const(c))
    }
    fn call(f: Func, a: Box<Scalar>) -> Scalar {
        Scalar::Call(f, a)
    }

    /// f = x² y + sin y along the line (x + t dx, y + t dy): the jet in t carries the
    /// directional derivatives f_x dx + f_y dy and [dx dy] H [dx dy]ᵀ, in closed form.
    #[test]
    fn a_surface_along_a_line_gives_its_directional_derivatives() {
        let (x, y) = (|| Box::new(Scalar::Var(0)), || Box::new(Scalar::Var(1)));
        let f = Scalar::Add(
            Box::new(Scalar::Mul(Box::new(Scalar::Powi(x(), 2)), y())),
            Box::new(call(Func::Sin, y())),
        );
        let (x0, y0, dx, dy) = (0.7, -1.3, 0.6, -0.8);
        let along = |v: f64, d: f64| Jet2 { v, d1: d, d2: 0.0 };
        let j = eval_on_all(&f, &[along(x0, dx), along(y0, dy)], &own_tables);
        let (fx, fy) = (2.0 * x0 * y0, x0 * x0 + y0.cos());
        let (fxx, fxy, fyy) = (2.0 * y0, 2.0 * x0, -y0.sin());
        assert_relative_eq!(j.v, x0 * x0 * y0 + y0.sin(), max_relative = TOL);
        assert_relative_eq!(j.d1, fx * dx + fy * dy, max_relative = TOL);
        assert_relative_eq!(
            j.d2,
            fxx * dx * dx + 2.0 * fxy * dx * dy + fyy * dy * dy,
            max_relative = TOL
        );
        // A variable not given is NaN, not another's value.
        assert!(eval_on_all(&f, &[along(x0, dx)], &own_tables).v.is_nan());
    }

    fn check(expr: &Scalar, x: f64, expected: [f64; 3]) {
        let got = eval_jet(expr, x, &own_tables);
        for (g, e) in got.iter().zip(expected) {
            assert_relative_eq!(*g, e, max_relative = TOL, epsilon = TOL);
        }
    }

    #[test]
    fn polynomial_profile_of_the_paper() {
        // concave cam: y = −0.595 x + 0.5 x² + 0.5 x³
        let e = Scalar::Add(
            Box::new(Scalar::Add(
                Box::new(Scalar::Mul(cst(-0.595), var())),
                Box::new(Scalar::Mul(cst(0.5), Box::new(Scalar::Powi(var(), 2)))),
            )),
            Box::new(Scalar::Mul(cst(0.5), Box::new(Scalar::Powi(var(), 3)))),
        );
        let x = 0.37;
        let f = -0.595 * x + 0.5 * x * x + 0.5 * x * x * x;
        let df = -0.595 + x + 1.5 * x * x;
        let ddf = 1.0 + 3.0 * x;
        check(&e, x, [f, df, ddf]);
    }

    #[test]
    fn every_elementary_function() {
        let x: f64 = 0.3;
        let cases: [(Func, [f64; 3]); 10] = [
            (Func::Sin, [x.sin(), x.cos(), -x.sin()]),
            (Func::Cos, [x.cos(), -x.sin(), -x.cos()]),
            (
                Func::Tan,
                [
                    x.tan(),
                    1.0 / x.cos().powi(2),
                    2.0 * x.sin() / x.cos().powi(3),
                ],
            ),
            (Func::Exp, [x.exp(), x.exp(), x.exp()]),
            (Func::Ln, [x.ln(), 1.0 / x, -1.0 / (x * x)]),
            (Func::Sqrt, [x.sqrt(), 0.5 / x.sqrt(), -0.25 * x.powf(-1.5)]),
            (Func::Sinh, [x.sinh(), x.cosh(), x.sinh()]),
            (Func::Cosh, [x.cosh(), x.sinh(), x.cosh()]),
            (
                Func::Tanh,
                [
                    x.tanh(),
                    1.0 / x.cosh().powi(2),
                    -2.0 * x.sinh() / x.cosh().powi(3),
                ],
            ),
            (
                Func::Atan,
                [
                    x.atan(),
                    1.0 / (1.0 + x * x),
                    -2.0 * x / (1.0 + x * x).powi(2),
                ],
            ),
        ];
        for (func, expected) in cases {
            check(&call(func, var()), x, expected);
        }
    }

    #[test]
    fn chain_rule_through_nested_calls() {
        // sin(x²): f' = 2x cos x², f'' = 2 cos x² − 4x² sin x²
        let e = call(Func::Sin, Box::new(Scalar::Powi(var(), 2)));
        let x: f64 = 0.8;
        let s = (x * x).sin();
        let c = (x * x).cos();
        check(&e, x, [s, 2.0 * x * c, 2.0 * c - 4.0 * x * x * s]);
    }

    #[test]
    fn quotient_and_negation() {
        // −1/(1 + x): f' = 1/(1+x)², f'' = −2/(1+x)³
        let e = Scalar::Neg(Box::new(Scalar::Div(
            cst(1.0),
            Box::new(Scalar::Add(cst(1.0), var())),
        )));
        let x = 0.25;
        let u = 1.0 + x;
        check(&e, x, [-1.0 / u, 1.0 / (u * u), -2.0 / (u * u * u)]);
    }

    #[test]
    fn subtraction_and_product() {
        // (x − 2)·x·cos x
        let e = Scalar::Mul(
            Box::new(Scalar::Mul(Box::new(Scalar::Sub(var(), cst(2.0))), var())),
            Box::new(call(Func::Cos, var())),
        );
        let x: f64 = 1.1;
        // p = x² − 2x, p' = 2x − 2, p'' = 2
        let (p, dp, ddp) = (x * x - 2.0 * x, 2.0 * x - 2.0, 2.0);
        let (c, s) = (x.cos(), x.sin());
        check(
            &e,
            x,
            [p * c, dp * c - p * s, ddp * c - 2.0 * dp * s - p * c],
        );
    }

    #[test]
    fn integer_powers_including_zero_negative_and_at_zero() {
        let x = 0.7;
        check(&Scalar::Powi(var(), 0), x, [1.0, 0.0, 0.0]);
        check(&Scalar::Powi(var(), 1), x, [x, 1.0, 0.0]);
        check(
            &Scalar::Powi(var(), -2),
            x,
            [x.powi(-2), -2.0 * x.powi(-3), 6.0 * x.powi(-4)],
        );
        // x¹ and x² at x = 0 must not produce NaN from 0·x⁻¹.
        check(&Scalar::Powi(var(), 1), 0.0, [0.0, 1.0, 0.0]);
        check(&Scalar::Powi(var(), 2), 0.0, [0.0, 0.0, 2.0]);
    }

    #[test]
    fn real_power_with_constant_exponent() {
        let x: f64 = 1.3;
        let e = Scalar::Powf(var(), cst(2.5));
        check(&e, x, [x.powf(2.5), 2.5 * x.powf(1.5), 3.75 * x.powf(0.5)]);
        // A negative base with an integral exponent stays finite: (−x)^3.
        let cube = Scalar::Powf(Box::new(Scalar::Neg(var())), cst(3.0));
        check(&cube, x, [-x.powi(3), -3.0 * x * x, -6.0 * x]);
    }

    #[test]
    fn real_power_with_variable_exponent() {
        // x^x: f' = x^x (ln x + 1), f'' = x^x ((ln x + 1)² + 1/x)
        let x: f64 = 1.7;
        let e = Scalar::Powf(var(), var());
        let f = x.powf(x);
        let l = x.ln() + 1.0;
        check(&e, x, [f, f * l, f * (l * l + 1.0 / x)]);
        // 2^x: f' = 2^x ln 2, f'' = 2^x ln² 2
        let e = Scalar::Powf(cst(2.0), var());
        let f = 2f64.powf(x);
        let l2 = 2f64.ln();
        check(&e, x, [f, f * l2, f * l2 * l2]);
    }
}
