//! Scalar expressions of one variable written in Rust syntax: cam profiles y = f(x) and
//! prescribed motions q(t).
//!
//! They are parsed with `syn` into the small tree [`Scalar`], which the symbolic engine
//! converts to its DAG (to differentiate and emit) and which the numeric reference evaluates
//! with second-order forward-mode differentiation (`camchain_runtime::jet::eval_jet`), an independent route
//! to f, f' and f''.

/// An elementary function allowed in a profile or drive expression.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Func {
    /// sin
    Sin,
    /// cos
    Cos,
    /// tan
    Tan,
    /// exp
    Exp,
    /// natural logarithm
    Ln,
    /// square root
    Sqrt,
    /// hyperbolic sine
    Sinh,
    /// hyperbolic cosine
    Cosh,
    /// hyperbolic tangent
    Tanh,
    /// arctangent
    Atan,
}

/// Expression tree of one scalar variable.
#[derive(Debug, Clone, PartialEq)]
pub enum Scalar {
    /// A finite constant.
    Const(f64),
    /// The variable (`x` for a profile, `t` for a drive).
    Var,
    /// −a
    Neg(Box<Scalar>),
    /// a + b
    Add(Box<Scalar>, Box<Scalar>),
    /// a − b
    Sub(Box<Scalar>, Box<Scalar>),
    /// a · b
    Mul(Box<Scalar>, Box<Scalar>),
    /// a / b
    Div(Box<Scalar>, Box<Scalar>),
    /// a.powi(n)
    Powi(Box<Scalar>, i32),
    /// a.powf(b)
    Powf(Box<Scalar>, Box<Scalar>),
    /// f(a)
    Call(Func, Box<Scalar>),
}
