//! Second-order forward-mode differentiation of profiles and drives
//! ([`camchain_model::jet`]), with functions given by data differentiated by the reference's
//! own spline ([`crate::spline`]), not the runtime's: an independent route for tables too.

pub use camchain_model::jet::Jet2;
use camchain_model::jet::{self as model_jet};
use camchain_model::profile::Scalar;

/// `(f(x), f'(x), f''(x))` of a profile y = f3(x) (eqs. 5b, 7, 8) or a drive q(t).
pub fn eval_jet(expr: &Scalar, x: f64) -> [f64; 3] {
    model_jet::eval_jet(expr, x, &crate::spline::derivative)
}

/// Evaluates `expr` with its variable given as the jet `x`.
pub fn eval_on(expr: &Scalar, x: Jet2) -> Jet2 {
    model_jet::eval_on(expr, x, &crate::spline::derivative)
}

/// The value of `expr` at `x` with [`Scalar::Param`] `i` given by `values[i]`.
pub fn eval_with(expr: &Scalar, x: f64, values: &[f64]) -> f64 {
    model_jet::eval_with(expr, x, values, &crate::spline::derivative)
}
