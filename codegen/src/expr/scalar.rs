//! Profile expressions on the graph: a one-variable [`Scalar`] converted to nodes, and a
//! function's value with its first two derivatives (Horner's rule for polynomials).

use crate::expr::{Graph, Id};
use crate::profile::Scalar;

/// Converts a one-variable [`Scalar`] to the DAG, the variable standing for `var` and
/// parameter i for `params[i]` (its graph variable, or its value when it is folded).
pub fn scalar_to_expr(g: &mut Graph, s: &Scalar, var: Id, params: &[Id]) -> Id {
    scalar_to_expr_in(g, s, &[var], params)
}

/// [`scalar_to_expr`] for an expression of several variables, variable i standing for
/// `vars[i]` (a surface's x and y); a variable past them is NaN.
pub fn scalar_to_expr_in(g: &mut Graph, s: &Scalar, vars: &[Id], params: &[Id]) -> Id {
    let mut to = |e: &Scalar| scalar_to_expr_in(g, e, vars, params);
    match s {
        Scalar::Const(c) => g.constant(*c),
        Scalar::Var(i) => vars
            .get(usize::from(*i))
            .copied()
            .unwrap_or_else(|| g.constant(f64::NAN)),
        Scalar::Param(i) => params
            .get(*i)
            .copied()
            .unwrap_or_else(|| g.constant(f64::NAN)),
        Scalar::Neg(a) => {
            let a = to(a);
            g.neg(a)
        }
        Scalar::Add(a, b) => {
            let (a, b) = (to(a), to(b));
            g.add(a, b)
        }
        Scalar::Sub(a, b) => {
            let (a, b) = (to(a), to(b));
            g.sub(a, b)
        }
        Scalar::Mul(a, b) => {
            let (a, b) = (to(a), to(b));
            g.mul(a, b)
        }
        Scalar::Div(a, b) => {
            let (a, b) = (to(a), to(b));
            g.div(a, b)
        }
        Scalar::Powi(a, n) => {
            let a = to(a);
            g.powi(a, *n)
        }
        Scalar::Powf(a, b) => {
            let (a, b) = (to(a), to(b));
            g.powf(a, b)
        }
        Scalar::Call(f, a) => {
            let a = to(a);
            g.call(*f, a)
        }
        Scalar::Table(t, order, a) => {
            let a = to(a);
            let k = g.add_table(t.clone());
            g.table(k, *order, a)
        }
        Scalar::Grid(grid, order, a, b) => {
            let (a, b) = (to(a), to(b));
            let k = g.add_grid(grid.clone());
            g.grid(k, *order, a, b)
        }
    }
}

/// f(v), f'(v), f''(v) of a one-variable expression, derived symbolically through a
/// placeholder variable `placeholder` and then substituted by the expression `at`.
///
/// A polynomial (a cam profile such as −0.595x + 0.5x² + 0.5x³) is written by Horner's
/// rule instead, value and both derivatives: n multiplications and at most n additions for
/// degree n, where the expression as written would raise powers separately.
///
/// `params` maps the expression's parameters to the graph (see [`scalar_to_expr`]); the
/// derivatives are taken with respect to the variable only.
pub fn value_and_derivatives(
    g: &mut Graph,
    s: &Scalar,
    placeholder: &str,
    at: Id,
    params: &[Id],
) -> [Id; 3] {
    if let Some(c) = polynomial(s) {
        let d1: Vec<f64> = (1..c.len()).map(|k| k as f64 * c[k]).collect();
        let d2: Vec<f64> = (1..d1.len()).map(|k| k as f64 * d1[k]).collect();
        return [&c[..], &d1[..], &d2[..]].map(|c| horner(g, c, at));
    }
    let x = g.var(placeholder);
    let f = scalar_to_expr(g, s, x, params);
    let d1 = g.diff(f, x);
    let d2 = g.diff(d1, x);
    [f, d1, d2].map(|e| g.substitute(e, x, at))
}

/// Highest degree written by Horner's rule (beyond it the expression is kept as written).
const MAX_POLYNOMIAL_DEGREE: usize = 16;

/// The coefficients c₀, c₁, … of `s` if it is a polynomial in its variable of degree at
/// most [`MAX_POLYNOMIAL_DEGREE`] (constants, the variable, +, −, ·, division by a constant,
/// non-negative integer powers), otherwise `None`.
fn polynomial(s: &Scalar) -> Option<Vec<f64>> {
    let p = match s {
        Scalar::Const(c) => vec![*c],
        Scalar::Var(0) => vec![0.0, 1.0],
        // Another variable is not a polynomial in the first.
        Scalar::Var(_) => return None,
        Scalar::Neg(a) => polynomial(a)?.iter().map(|c| -c).collect(),
        Scalar::Add(a, b) => combine(&polynomial(a)?, &polynomial(b)?, 1.0),
        Scalar::Sub(a, b) => combine(&polynomial(a)?, &polynomial(b)?, -1.0),
        Scalar::Mul(a, b) => product(&polynomial(a)?, &polynomial(b)?)?,
        Scalar::Div(a, b) => match polynomial(b)?.as_slice() {
            [d] if *d != 0.0 => polynomial(a)?.iter().map(|c| c / d).collect(),
            _ => return None,
        },
        Scalar::Powi(a, n) if (0..=MAX_POLYNOMIAL_DEGREE as i32).contains(n) => {
            let base = polynomial(a)?;
            let mut p = vec![1.0];
            for _ in 0..*n {
                p = product(&p, &base)?;
            }
            p
        }
        _ => return None,
    };
    p.iter().all(|c| c.is_finite()).then_some(p)
}

fn combine(a: &[f64], b: &[f64], sign: f64) -> Vec<f64> {
    (0..a.len().max(b.len()))
        .map(|k| a.get(k).copied().unwrap_or(0.0) + sign * b.get(k).copied().unwrap_or(0.0))
        .collect()
}

fn product(a: &[f64], b: &[f64]) -> Option<Vec<f64>> {
    let degree = (a.len() - 1) + (b.len() - 1);
    if degree > MAX_POLYNOMIAL_DEGREE {
        return None;
    }
    let mut p = vec![0.0; degree + 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            p[i + j] += x * y;
        }
    }
    Some(p)
}

/// c₀ + x (c₁ + x (c₂ + …)) (zero terms fold away; an empty list is 0).
fn horner(g: &mut Graph, c: &[f64], x: Id) -> Id {
    let mut acc = g.zero();
    for &ck in c.iter().rev() {
        let times = g.mul(acc, x);
        let k = g.constant(ck);
        acc = g.add(times, k);
    }
    acc
}

/// Σ a_i b_i
pub fn dot_list(g: &mut Graph, a: &[Id], b: &[Id]) -> Id {
    let terms: Vec<Id> = a.iter().zip(b).map(|(&x, &y)| g.mul(x, y)).collect();
    g.sum(terms)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::parse_expression;

    fn coefficients(source: &str) -> Option<Vec<f64>> {
        polynomial(&parse_expression(source, "x").expect("parses"))
    }

    #[test]
    fn polynomials_are_recognised_and_other_profiles_are_not() {
        assert_eq!(
            coefficients("-0.595*x + 0.5*x*x + 0.5*x.powi(3)"),
            Some(vec![0.0, -0.595, 0.5, 0.5])
        );
        assert_eq!(
            coefficients("(1.0 - x).powi(2) / 4.0"),
            Some(vec![0.25, -0.5, 0.25])
        );
        assert_eq!(coefficients("2.0"), Some(vec![2.0]));
        for other in [
            "x.sin()",
            "1.0 / x",
            "x.powi(-1)",
            "x.powf(2.0)",
            "x.powi(40)",
        ] {
            assert_eq!(coefficients(other), None, "{other}");
        }
    }

    #[test]
    fn horner_form_gives_the_profile_and_its_derivatives() {
        let s = parse_expression("0.3 - 0.595*x + 0.5*x*x + 0.5*x.powi(3)", "x").expect("parses");
        let mut g = Graph::new();
        let x = g.var("x");
        let [f, d1, d2] = value_and_derivatives(&mut g, &s, "__p", x, &[]);
        // Fewer operations than the power-by-power form: 3 multiplications and 3 additions
        // for the value.
        assert_eq!(g.op_count(&[f]).total(), 6);
        for v in [-1.7, -0.2, 0.0, 0.9, 2.5] {
            let values = g.eval(&[f, d1, d2], &[v]);
            let exact = [
                0.3 - 0.595 * v + 0.5 * v * v + 0.5 * v.powi(3),
                -0.595 + v + 1.5 * v * v,
                1.0 + 3.0 * v,
            ];
            for (a, b) in values.iter().zip(exact) {
                // Horner and the power form differ by a few roundings of O(10) values.
                assert!(
                    (a - b).abs() <= 1e-14 * (1.0 + b.abs()),
                    "x = {v}: {a} vs {b}"
                );
            }
        }
    }
}
