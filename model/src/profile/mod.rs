//! Scalar expressions of one variable written in Rust syntax: cam profiles y = f(x) and
//! prescribed motions q(t).
//!
//! They are parsed into the small tree [`Scalar`], which the symbolic engine converts to its
//! DAG (to differentiate and emit) and which the numeric reference evaluates with
//! second-order forward-mode differentiation (`Scalar::eval_jet`), an independent route to
//! f, f' and f''.
//!
//! [`parse_expression`] accepts only a small, safe subset of Rust: numbers, the one variable,
//! `PI` and `E`, `+ - * /`, unary minus, parentheses and a fixed list of `f64` math functions
//! (method or function-call form). Anything else is rejected with the byte offset of the
//! offending token, so the model loader can point at the exact column in the RON file.
//!
//! The parser is the crate's own, in four passes that each see the whole input before the
//! next starts, so an error is the first one in this order: the lexer (`lex`: Rust's tokens,
//! comments and literals; unbalanced delimiters), the screen (`lex::screen`: keywords,
//! operators and constructs that are never allowed, nesting and length limits), the
//! precedence-climbing parser (`parse`: the tree of Rust's expression grammar restricted to
//! the tokens the screen lets through) and the conversion (`convert`: names, functions,
//! literals' values and the constant checks). Every pass works in bounded stack: the screen
//! bounds nesting before the parser recurses, and the conversion stops at [`MAX_TREE_DEPTH`].
//! It accepts exactly what the `syn`-based parser it replaced accepted (the tests compare the
//! two on a corpus), without linking `syn`, `quote` and `proc-macro2` into a program that
//! reads model files at run time.

use camchain_runtime::motion_law::MotionProgram;
use camchain_runtime::spline::Spline;
use camchain_runtime::surface_spline::SurfaceSpline;
use std::sync::Arc;

mod convert;
mod lex;
mod literal;
mod parse;
#[cfg(test)]
mod tests;

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

/// Expression tree in one scalar variable, or two for a surface z = f(x, y).
#[derive(Debug, Clone, PartialEq)]
pub enum Scalar {
    /// A finite constant.
    Const(f64),
    /// Variable number `.0` of the expression: 0 is a profile's `x`, `θ` or `s`, a drive's
    /// `t`; 1 is a surface's `y` (z = f(x, y)). A variable past those given evaluates to NaN.
    Var(u8),
    /// A parameter of the model, by its index in the model's parameter list. Resolve it
    /// ([`Scalar::resolve`]) before evaluating: [`Scalar::eval`] gives NaN for it.
    Param(usize),
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
    /// The derivative of order `.1` (0: the value) of a function given by data at a: a
    /// spline through a table of points, or a follower's motion law ([`Tabulated`]). Built by
    /// the schema (profiles from points, cams from motion laws), never parsed.
    Table(Arc<Tabulated>, u8, Box<Scalar>),
    /// ∂ᵖ_x ∂ᵠ_y, `.1` = (p, q) ((0, 0): the value), of a function of two variables given on
    /// a grid ([`Gridded`], a C² bicubic spline surface) at (a, b). Built by the schema
    /// (surfaces from grid tables), never parsed.
    Grid(Arc<Gridded>, (u8, u8), Box<Scalar>, Box<Scalar>),
}

/// A function of two variables given by a grid of values instead of a formula: a cam
/// surface z(x, y) through measured or exported points, interpolated by a C² bicubic spline
/// (`camchain_runtime::surface_spline`). Its partial derivatives are exact to every order
/// (zero beyond the third in either variable). Generated code keeps its tables in constants
/// and evaluates them with the runtime's `surface_spline::partials`.
#[derive(Debug, Clone, PartialEq)]
pub struct Gridded {
    /// Its name in the generated code (`<contact>_<what>`, a Rust identifier); unique in a
    /// model.
    pub name: String,
    /// The spline surface.
    pub spline: SurfaceSpline,
}

impl Gridded {
    /// A named spline surface.
    pub fn new(name: impl Into<String>, spline: SurfaceSpline) -> Arc<Self> {
        Arc::new(Gridded {
            name: name.into(),
            spline,
        })
    }

    /// ∂ᵖ_x ∂ᵠ_y of the surface at (x, y), `order` = (p, q).
    pub fn derivative(&self, order: (u8, u8), x: f64, y: f64) -> f64 {
        self.spline.partial(order, x, y)
    }
}

/// A function of one variable given by data instead of a formula, with its first three
/// derivatives exact: a profile through points (a C² cubic spline) or a follower's motion
/// law over a turn of the cam. Generated code keeps its data in constants and evaluates it
/// with the runtime's `spline::evaluate` or `motion_law::evaluate`.
#[derive(Debug, Clone, PartialEq)]
pub struct Tabulated {
    /// Its name in the generated code (`<contact>_<what>`, a Rust identifier); unique in a
    /// model.
    pub name: String,
    /// The data and how it is evaluated.
    pub function: TabulatedFunction,
}

/// What a [`Tabulated`] function is.
#[derive(Debug, Clone, PartialEq)]
pub enum TabulatedFunction {
    /// A spline through a table of points.
    Spline(Spline),
    /// A follower's displacement against the cam's angle.
    Law(MotionProgram),
}

impl Tabulated {
    /// A named spline.
    pub fn spline(name: impl Into<String>, spline: Spline) -> Arc<Self> {
        Arc::new(Tabulated {
            name: name.into(),
            function: TabulatedFunction::Spline(spline),
        })
    }

    /// A named motion law.
    pub fn law(name: impl Into<String>, program: MotionProgram) -> Arc<Self> {
        Arc::new(Tabulated {
            name: name.into(),
            function: TabulatedFunction::Law(program),
        })
    }

    /// [F, F′, F″, F‴] at x.
    pub fn eval(&self, x: f64) -> [f64; 4] {
        match &self.function {
            TabulatedFunction::Spline(s) => s.eval(x),
            TabulatedFunction::Law(p) => p.eval(x),
        }
    }

    /// The derivative of order `order` at x. Above the third: zero for a spline (a cubic's
    /// fourth derivative vanishes inside every segment), NaN for a motion law (not provided;
    /// nothing asks for it).
    pub fn derivative(&self, order: u8, x: f64) -> f64 {
        match (order, &self.function) {
            (0..=3, _) => self.eval(x)[usize::from(order)],
            (_, TabulatedFunction::Spline(_)) => 0.0,
            (_, TabulatedFunction::Law(_)) => f64::NAN,
        }
    }
}

impl Scalar {
    /// Plain `f64` evaluation with the (first) variable set to `v`, using the same `f64`
    /// methods the generated code calls; used by validation, tests and quick numeric checks.
    pub fn eval(&self, v: f64) -> f64 {
        self.eval_at(&[v])
    }

    /// [`Scalar::eval`] with variable i set to `vars[i]` (a surface's x and y).
    pub fn eval_at(&self, vars: &[f64]) -> f64 {
        let ev = |e: &Scalar| e.eval_at(vars);
        match self {
            Scalar::Const(c) => *c,
            Scalar::Var(i) => vars.get(usize::from(*i)).copied().unwrap_or(f64::NAN),
            Scalar::Param(_) => f64::NAN,
            Scalar::Neg(a) => -ev(a),
            Scalar::Add(a, b) => ev(a) + ev(b),
            Scalar::Sub(a, b) => ev(a) - ev(b),
            Scalar::Mul(a, b) => ev(a) * ev(b),
            Scalar::Div(a, b) => ev(a) / ev(b),
            Scalar::Powi(a, n) => ev(a).powi(*n),
            Scalar::Powf(a, b) => ev(a).powf(ev(b)),
            Scalar::Call(f, a) => apply(*f, ev(a)),
            Scalar::Table(t, order, a) => t.derivative(*order, ev(a)),
            Scalar::Grid(g, order, a, b) => g.derivative(*order, ev(a), ev(b)),
        }
    }
}

impl Scalar {
    /// The expression with parameter `i` replaced by the constant `values[i]` wherever
    /// `replace(i)` holds (all of them, or only the ones folded at build time).
    pub fn resolve(&self, values: &[f64], replace: &dyn Fn(usize) -> bool) -> Scalar {
        let r = |a: &Scalar| Box::new(a.resolve(values, replace));
        match self {
            Scalar::Param(i) if replace(*i) => Scalar::Const(values[*i]),
            Scalar::Const(_) | Scalar::Var(_) | Scalar::Param(_) => self.clone(),
            Scalar::Neg(a) => Scalar::Neg(r(a)),
            Scalar::Add(a, b) => Scalar::Add(r(a), r(b)),
            Scalar::Sub(a, b) => Scalar::Sub(r(a), r(b)),
            Scalar::Mul(a, b) => Scalar::Mul(r(a), r(b)),
            Scalar::Div(a, b) => Scalar::Div(r(a), r(b)),
            Scalar::Powi(a, n) => Scalar::Powi(r(a), *n),
            Scalar::Powf(a, b) => Scalar::Powf(r(a), r(b)),
            Scalar::Call(f, a) => Scalar::Call(*f, r(a)),
            Scalar::Table(t, order, a) => Scalar::Table(t.clone(), *order, r(a)),
            Scalar::Grid(g, order, a, b) => Scalar::Grid(g.clone(), *order, r(a), r(b)),
        }
    }

    /// The expression with every parameter replaced by its value.
    pub fn resolve_all(&self, values: &[f64]) -> Scalar {
        self.resolve(values, &|_| true)
    }

    /// The indices of the parameters the expression uses, each once, in increasing order.
    pub fn parameters(&self) -> Vec<usize> {
        fn walk(s: &Scalar, out: &mut Vec<usize>) {
            match s {
                Scalar::Param(i) => out.push(*i),
                Scalar::Const(_) | Scalar::Var(_) => {}
                Scalar::Neg(a)
                | Scalar::Powi(a, _)
                | Scalar::Call(_, a)
                | Scalar::Table(_, _, a) => walk(a, out),
                Scalar::Add(a, b)
                | Scalar::Sub(a, b)
                | Scalar::Mul(a, b)
                | Scalar::Div(a, b)
                | Scalar::Powf(a, b)
                | Scalar::Grid(_, _, a, b) => {
                    walk(a, out);
                    walk(b, out);
                }
            }
        }
        let mut out = Vec::new();
        walk(self, &mut out);
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// Expressions built in code (a cam synthesised from a motion law): `a + b`, `a * b`, … make
/// the tree nodes, and [`Scalar::from`] a constant.
impl From<f64> for Scalar {
    fn from(value: f64) -> Self {
        Scalar::Const(value)
    }
}

macro_rules! scalar_operator {
    ($trait:ident, $method:ident, $variant:ident) => {
        impl std::ops::$trait for Scalar {
            type Output = Scalar;
            fn $method(self, rhs: Scalar) -> Scalar {
                Scalar::$variant(Box::new(self), Box::new(rhs))
            }
        }
    };
}

scalar_operator!(Add, add, Add);
scalar_operator!(Sub, sub, Sub);
scalar_operator!(Mul, mul, Mul);
scalar_operator!(Div, div, Div);

impl std::ops::Neg for Scalar {
    type Output = Scalar;
    fn neg(self) -> Scalar {
        Scalar::Neg(Box::new(self))
    }
}

impl Scalar {
    /// f(self) for an elementary function.
    pub fn call(self, f: Func) -> Scalar {
        Scalar::Call(f, Box::new(self))
    }

    /// The derivative of order `order` of `table` at self.
    pub fn tabulated(self, table: &Arc<Tabulated>, order: u8) -> Scalar {
        Scalar::Table(table.clone(), order, Box::new(self))
    }

    /// ∂ᵖ_x ∂ᵠ_y (`order` = (p, q)) of the surface `grid` at (x, y).
    pub fn gridded(grid: &Arc<Gridded>, order: (u8, u8), x: Scalar, y: Scalar) -> Scalar {
        Scalar::Grid(grid.clone(), order, Box::new(x), Box::new(y))
    }
}

/// Why an expression was rejected, and where.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("byte {offset}: {message}")]
pub struct ExprError {
    /// Byte offset of the offending token in the expression source.
    pub offset: usize,
    /// What is wrong, in plain words.
    pub message: String,
}

impl ExprError {
    fn new(offset: usize, message: impl Into<String>) -> Self {
        ExprError {
            offset,
            message: message.into(),
        }
    }
}

/// The math functions by their Rust method name.
const FUNCTIONS: [(&str, Func); 10] = [
    ("sin", Func::Sin),
    ("cos", Func::Cos),
    ("tan", Func::Tan),
    ("exp", Func::Exp),
    ("ln", Func::Ln),
    ("sqrt", Func::Sqrt),
    ("sinh", Func::Sinh),
    ("cosh", Func::Cosh),
    ("tanh", Func::Tanh),
    ("atan", Func::Atan),
];

/// Shown in "unknown function" messages.
const ALLOWED_FUNCTIONS: &str =
    "sin, cos, tan, exp, ln, sqrt, sinh, cosh, tanh, atan, powi(integer), powf";

/// Shown when an unsupported construct is used.
const ALLOWED_SUMMARY: &str = "use numbers, the variable, PI, E, + - * /, parentheses and \
     math functions";

/// Longest text (a name, a literal, a token) an error message quotes in full.
const SHOWN: usize = 40;

/// `text` for an error message: itself, or its start and its length when it is long (a
/// model file may hold a megabyte-long name or number).
fn shown(text: &str) -> String {
    match text.char_indices().nth(SHOWN) {
        Some((cut, _)) => format!("{}… ({} bytes)", &text[..cut], text.len()),
        None => text.to_string(),
    }
}

fn function_by_name(name: &str) -> Option<Func> {
    FUNCTIONS.iter().find(|(n, _)| *n == name).map(|(_, f)| *f)
}

fn apply(func: Func, a: f64) -> f64 {
    match func {
        Func::Sin => a.sin(),
        Func::Cos => a.cos(),
        Func::Tan => a.tan(),
        Func::Exp => a.exp(),
        Func::Ln => a.ln(),
        Func::Sqrt => a.sqrt(),
        Func::Sinh => a.sinh(),
        Func::Cosh => a.cosh(),
        Func::Tanh => a.tanh(),
        Func::Atan => a.atan(),
    }
}

/// Parses `source` (Rust expression syntax) as a function of the single variable `variable`.
///
/// Accepted: float and integer literals as Rust writes them (`2`, `2.`, `1.5`, `1e-3`,
/// `1_000.5E+2`, `0x1F`, `0o17`, `0b101`), optionally suffixed `f64`, `variable`, `PI`, `E`
/// (also as `f64::consts::PI`, `std::f64::consts::PI`, `core::f64::consts::PI`), unary
/// minus, `+ - * /`, parentheses, the methods `.sin() .cos() .tan() .exp() .ln() .sqrt()
/// .sinh() .cosh() .tanh() .atan() .powi(n) .powf(e)` with `n` an integer literal (possibly
/// negated or parenthesised, optionally suffixed `i32`), and the same functions in call form
/// (`sin(x)`, `f64::sin(x)`, `std::f64::sin(x)`, `powi(x, 3)`). As in Rust: `* /` bind
/// tighter than `+ -`, both left-associative, and a method call tighter than a sign
/// (`-x.sin()` is −sin x, `-2.0.powi(2)` is −4); whitespace and comments (`//`, `/* */`) may
/// separate tokens, an argument list may end with a comma, a path may start with `::`.
/// Rejected, with the byte offset of the offending token: other names, other functions,
/// operators, literals, blocks, macros, closures, assignments, a divisor that is a constant
/// equal to zero, constant subexpressions that are not finite, `powi` exponents beyond
/// ±[`MAX_POWI`], and expressions nested deeper than [`MAX_NESTING`] or [`MAX_TREE_DEPTH`]
/// or longer than [`MAX_TOKENS`] tokens (limits that keep parsing within a small stack).
pub fn parse_expression(source: &str, variable: &str) -> Result<Scalar, ExprError> {
    parse_expression_with(source, Some(variable), &[])
}

/// [`parse_expression`] with the model's parameters: a name in `parameters` becomes
/// [`Scalar::Param`] with its index. Without a `variable` the expression is a value of the
/// parameters alone (a numeric field written as `"l1/2"`).
pub fn parse_expression_with(
    source: &str,
    variable: Option<&str>,
    parameters: &[&str],
) -> Result<Scalar, ExprError> {
    parse_expression_in(source, variable.as_slice(), parameters)
}

/// [`parse_expression_with`] for an expression of several variables: `variables[i]` becomes
/// [`Scalar::Var`]`(i)` (a surface z = f(x, y) has `["x", "y"]`).
pub fn parse_expression_in(
    source: &str,
    variables: &[&str],
    parameters: &[&str],
) -> Result<Scalar, ExprError> {
    let tokens = lex::tokens(source)?;
    lex::screen(source, &tokens)?;
    let tree = parse::parse(source, &tokens)?;
    convert::convert(source, &tree, variables, parameters)
}

/// Deepest nesting of parentheses and prefix operators (`-(-(x))` is 4 deep) accepted.
///
/// The parser reads nested groups and prefix operators by recursion, as does the conversion
/// to [`Scalar`]; the limit, checked on the tokens before either runs, keeps both far inside
/// any thread's stack, while real profiles nest a handful of levels.
pub const MAX_NESTING: usize = 32;

/// Deepest expression tree accepted: operations applied to the results of operations, e.g. a
/// sum of 300 terms written without parentheses is 300 deep (see also [`MAX_NESTING`]).
pub const MAX_TREE_DEPTH: usize = 256;

/// Most tokens accepted in one expression (a 100-term Fourier series has about 1000).
///
/// Bounds the depth of the parsed tree (a long sum is a left-deep chain of additions, which
/// every tree walk recurses through) and the memory one parse takes.
pub const MAX_TOKENS: usize = 2000;

/// Largest |n| accepted in `powi(n)`: far beyond any sensible profile, and small enough
/// that the exponents of the derivatives (n − 1, n − 2) cannot overflow an i32.
pub const MAX_POWI: i32 = 1_000_000;
