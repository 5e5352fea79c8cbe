//! Scalar expressions of one variable written in Rust syntax: cam profiles y = f(x) and
//! prescribed motions q(t).
//!
//! They are parsed with `syn` into the small tree [`Scalar`], which the symbolic engine
//! converts to its DAG (to differentiate and emit) and which the numeric reference evaluates
//! with second-order forward-mode differentiation (`Scalar::eval_jet`), an independent route
//! to f, f' and f''.
//!
//! [`parse_expression`] accepts only a small, safe subset of Rust: numbers, the one variable,
//! `PI` and `E`, `+ - * /`, unary minus, parentheses and a fixed list of `f64` math functions
//! (method or function-call form). Anything else is rejected with the byte offset of the
//! offending token, so the model loader can point at the exact column in the RON file.
//! Offsets come from `proc_macro2::Span::byte_range`, which needs proc-macro2's
//! `span-locations` feature (enabled in this crate's `Cargo.toml`); outside a proc-macro
//! proc-macro2 uses its own lexer, whose byte ranges are relative to the parsed string.

use camchain_runtime::motion_law::MotionProgram;
use camchain_runtime::spline::Spline;
use proc_macro2::TokenStream;
use quote::ToTokens;
use std::cell::Cell;
use std::str::FromStr;
use std::sync::Arc;
use syn::spanned::Spanned;
use syn::{BinOp, Expr, Lit, UnOp};

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
    /// Plain `f64` evaluation with the variable set to `v`, using the same `f64` methods the
    /// generated code calls; used by validation, tests and quick numeric checks.
    pub fn eval(&self, v: f64) -> f64 {
        match self {
            Scalar::Const(c) => *c,
            Scalar::Var => v,
            Scalar::Param(_) => f64::NAN,
            Scalar::Neg(a) => -a.eval(v),
            Scalar::Add(a, b) => a.eval(v) + b.eval(v),
            Scalar::Sub(a, b) => a.eval(v) - b.eval(v),
            Scalar::Mul(a, b) => a.eval(v) * b.eval(v),
            Scalar::Div(a, b) => a.eval(v) / b.eval(v),
            Scalar::Powi(a, n) => a.eval(v).powi(*n),
            Scalar::Powf(a, b) => a.eval(v).powf(b.eval(v)),
            Scalar::Call(f, a) => apply(*f, a.eval(v)),
            Scalar::Table(t, order, a) => t.derivative(*order, a.eval(v)),
        }
    }

    /// The value of the expression when it does not depend on the variable.
    fn constant_value(&self) -> Option<f64> {
        if self.mentions_variable() {
            None
        } else {
            Some(self.eval(0.0))
        }
    }

    /// True when the variable or a parameter occurs anywhere in the tree (a parameter may
    /// change at run time, so it is not a constant).
    fn mentions_variable(&self) -> bool {
        match self {
            Scalar::Const(_) => false,
            Scalar::Var | Scalar::Param(_) => true,
            Scalar::Neg(a) | Scalar::Powi(a, _) | Scalar::Call(_, a) | Scalar::Table(_, _, a) => {
                a.mentions_variable()
            }
            Scalar::Add(a, b)
            | Scalar::Sub(a, b)
            | Scalar::Mul(a, b)
            | Scalar::Div(a, b)
            | Scalar::Powf(a, b) => a.mentions_variable() || b.mentions_variable(),
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
            Scalar::Const(_) | Scalar::Var | Scalar::Param(_) => self.clone(),
            Scalar::Neg(a) => Scalar::Neg(r(a)),
            Scalar::Add(a, b) => Scalar::Add(r(a), r(b)),
            Scalar::Sub(a, b) => Scalar::Sub(r(a), r(b)),
            Scalar::Mul(a, b) => Scalar::Mul(r(a), r(b)),
            Scalar::Div(a, b) => Scalar::Div(r(a), r(b)),
            Scalar::Powi(a, n) => Scalar::Powi(r(a), *n),
            Scalar::Powf(a, b) => Scalar::Powf(r(a), r(b)),
            Scalar::Call(f, a) => Scalar::Call(*f, r(a)),
            Scalar::Table(t, order, a) => Scalar::Table(t.clone(), *order, r(a)),
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
                Scalar::Const(_) | Scalar::Var => {}
                Scalar::Neg(a)
                | Scalar::Powi(a, _)
                | Scalar::Call(_, a)
                | Scalar::Table(_, _, a) => walk(a, out),
                Scalar::Add(a, b)
                | Scalar::Sub(a, b)
                | Scalar::Mul(a, b)
                | Scalar::Div(a, b)
                | Scalar::Powf(a, b) => {
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

    fn at(node: &impl Spanned, message: impl Into<String>) -> Self {
        ExprError::new(node.span().byte_range().start, message)
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
/// Accepted: float and integer literals (optionally suffixed `f64`), `variable`, `PI`, `E`
/// (also as `f64::consts::PI`, `std::f64::consts::PI`, `core::f64::consts::PI`), unary
/// minus, `+ - * /`, parentheses, the methods `.sin() .cos() .tan() .exp() .ln() .sqrt()
/// .sinh() .cosh() .tanh() .atan() .powi(n) .powf(e)` with `n` an integer literal, and the
/// same functions in call form (`sin(x)`, `f64::sin(x)`, `powi(x, 3)`). Rejected, with the
/// byte offset of the offending token: other names, other functions, operators, literals,
/// blocks, macros, closures, assignments, a divisor that is a constant equal to zero,
/// constant subexpressions that are not finite, `powi` exponents beyond ±[`MAX_POWI`], and
/// expressions nested deeper than [`MAX_NESTING`] or [`MAX_TREE_DEPTH`] or longer than
/// [`MAX_TOKENS`] tokens (limits that keep parsing within a small stack).
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
    let tokens = TokenStream::from_str(source).map_err(|e| lex_error(source, &e))?;
    screen_tokens(&tokens)?;
    let expr: Expr = syn::parse2(tokens).map_err(|e| syntax_error(source, &e))?;
    Converter {
        variable,
        parameters,
        depth: Cell::new(0),
    }
    .expr(&expr)
}

/// Deepest nesting of parentheses and prefix operators (`-(-(x))` is 4 deep) accepted.
///
/// syn parses nested groups and prefix operators by recursion, as does the conversion to
/// [`Scalar`]; the limit keeps both far inside a 2 MiB thread stack (about 2 KiB per level
/// at opt-level 2, a few times more unoptimised), while real profiles nest a handful of
/// levels.
pub const MAX_NESTING: usize = 32;

/// Deepest expression tree accepted: operations applied to the results of operations, e.g. a
/// sum of 300 terms written without parentheses is 300 deep (see also [`MAX_NESTING`]).
pub const MAX_TREE_DEPTH: usize = 256;

/// Most tokens accepted in one expression (a 100-term Fourier series has about 1000).
///
/// Bounds the depth of the parsed tree (a long sum is a left-deep chain of additions, which
/// every tree walk recurses through) and the quadratic cost of the constant checks.
pub const MAX_TOKENS: usize = 2000;

/// Multi-character Rust operators, which proc-macro2 splits into joint punctuation; the
/// screen glues the longest one it can.
const OPERATORS: [&str; 26] = [
    "..=", "...", "<<=", ">>=", "::", "..", "==", "!=", "<=", ">=", "&&", "||", "+=", "-=", "*=",
    "/=", "%=", "^=", "&=", "|=", "<<", ">>", "->", "=>", "<-", "#!",
];

/// Keywords that may not appear in an expression, with what they would introduce.
fn keyword_error(word: &str) -> Option<String> {
    let what = match word {
        "as" => "casts (`as`) are not allowed",
        "if" | "else" | "match" | "loop" | "while" | "for" | "break" | "continue" | "return"
        | "yield" | "do" => "control flow is not allowed",
        "move" | "async" | "await" | "gen" => "closures and async blocks are not allowed",
        "unsafe" | "const" | "static" | "let" | "mut" | "ref" | "box" | "in" | "impl" | "dyn"
        | "fn" | "struct" | "enum" | "trait" | "type" | "use" | "mod" | "pub" | "where"
        | "extern" | "macro" | "try" | "become" | "abstract" | "final" | "override" | "priv"
        | "typeof" | "unsized" | "virtual" => "is a Rust keyword and not allowed here",
        _ => return None,
    };
    Some(if what.starts_with("is ") {
        format!("`{word}` {what}; {ALLOWED_SUMMARY}")
    } else {
        what.to_string()
    })
}

/// What the previous token at the same nesting level was, for telling prefix operators and
/// macro calls apart.
#[derive(Clone, Copy)]
enum Previous {
    /// Start of the expression or of a group.
    Start,
    /// An operator or separator.
    Operator,
    /// An identifier, starting at the byte offset.
    Ident(usize),
    /// A literal or a group.
    Operand,
}

/// One open group while screening: its tokens, nesting depth and scanning state.
struct Level {
    tokens: std::iter::Peekable<proc_macro2::token_stream::IntoIter>,
    depth: usize,
    prefix_run: usize,
    previous: Previous,
}

/// Rejects, before syn sees them, the token shapes that are never valid here and the ones
/// syn would parse by deep recursion: brackets and braces, keywords, operators other than
/// `+ - * /`, macros, closures, ranges, and nesting deeper than [`MAX_NESTING`] or more than
/// [`MAX_TOKENS`] tokens. Iterative, so any input is screened in bounded stack.
fn screen_tokens(tokens: &TokenStream) -> Result<(), ExprError> {
    use proc_macro2::{Delimiter, Spacing, TokenTree};
    let offset = |span: proc_macro2::Span| span.byte_range().start;
    let mut stack = vec![Level {
        tokens: tokens.clone().into_iter().peekable(),
        depth: 0,
        prefix_run: 0,
        previous: Previous::Start,
    }];
    let mut count = 0usize;
    while let Some(level) = stack.last_mut() {
        let Some(token) = level.tokens.next() else {
            stack.pop();
            continue;
        };
        count += 1;
        if count > MAX_TOKENS {
            return Err(ExprError::new(
                offset(token.span()),
                format!("the expression is too long: more than {MAX_TOKENS} tokens"),
            ));
        }
        match token {
            TokenTree::Group(group) => {
                let at = offset(group.span_open());
                match group.delimiter() {
                    Delimiter::Parenthesis | Delimiter::None => {}
                    Delimiter::Bracket => {
                        return Err(ExprError::new(
                            at,
                            "brackets `[...]` are not allowed (no arrays or indexing)",
                        ));
                    }
                    Delimiter::Brace => return Err(ExprError::new(at, "blocks are not allowed")),
                }
                let depth = level.depth + level.prefix_run + 1;
                if depth > MAX_NESTING {
                    return Err(nesting_error(at));
                }
                level.prefix_run = 0;
                level.previous = Previous::Operand;
                stack.push(Level {
                    tokens: group.stream().into_iter().peekable(),
                    depth,
                    prefix_run: 0,
                    previous: Previous::Start,
                });
            }
            TokenTree::Ident(ident) => {
                let word = ident.to_string();
                let at = offset(ident.span());
                if let Some(message) = keyword_error(&word) {
                    return Err(ExprError::new(at, message));
                }
                level.prefix_run = 0;
                level.previous = Previous::Ident(at);
            }
            TokenTree::Literal(_) => {
                level.prefix_run = 0;
                level.previous = Previous::Operand;
            }
            TokenTree::Punct(punct) => {
                let at = offset(punct.span());
                let mut op = punct.as_char().to_string();
                let mut joint = punct.spacing() == Spacing::Joint;
                // Glue the longest known operator out of the joint punctuation.
                while joint {
                    let Some(TokenTree::Punct(next)) = level.tokens.peek() else {
                        break;
                    };
                    let longer = format!("{op}{}", next.as_char());
                    if !OPERATORS.iter().any(|o| o.starts_with(&longer)) {
                        break;
                    }
                    joint = next.spacing() == Spacing::Joint;
                    op = longer;
                    level.tokens.next();
                }
                let prefix_position =
                    matches!(level.previous, Previous::Start | Previous::Operator);
                match op.as_str() {
                    "-" | "*" if prefix_position => {
                        level.prefix_run += 1;
                        if level.depth + level.prefix_run > MAX_NESTING {
                            return Err(nesting_error(at));
                        }
                    }
                    "+" | "-" | "*" | "/" | "," | "." | "::" | ":" => level.prefix_run = 0,
                    "!" => {
                        return Err(match level.previous {
                            Previous::Ident(start) => {
                                ExprError::new(start, "macros are not allowed")
                            }
                            _ => ExprError::new(
                                at,
                                "operator `!` is not allowed; only unary minus is",
                            ),
                        });
                    }
                    "|" | "||" if prefix_position => {
                        return Err(ExprError::new(at, "closures are not allowed"));
                    }
                    ".." | "..=" | "..." => {
                        return Err(ExprError::new(at, "ranges (`..`) are not allowed"));
                    }
                    "#" | "#!" => return Err(ExprError::new(at, "attributes are not allowed")),
                    "'" => {
                        return Err(ExprError::new(at, "labels and lifetimes are not allowed"));
                    }
                    "=" => return Err(ExprError::new(at, "assignments are not allowed")),
                    "==" | "!=" | "<=" | ">=" | "=>" | "->" | "<-" => {
                        return Err(operator_error(at, &op));
                    }
                    _ if op.len() > 1 && op.ends_with('=') => {
                        return Err(ExprError::new(
                            at,
                            format!("`{op}` is an assignment; assignments are not allowed"),
                        ));
                    }
                    _ => return Err(operator_error(at, &op)),
                }
                level.previous = Previous::Operator;
            }
        }
    }
    Ok(())
}

fn nesting_error(offset: usize) -> ExprError {
    ExprError::new(
        offset,
        format!(
            "the expression is nested too deeply: more than {MAX_NESTING} levels of \
             parentheses and signs"
        ),
    )
}

fn operator_error(offset: usize, op: &str) -> ExprError {
    ExprError::new(
        offset,
        format!("operator `{op}` is not allowed; allowed: + - * /"),
    )
}

/// A syn parse error; errors at the end of input carry the call-site span (0..0).
fn syntax_error(source: &str, error: &syn::Error) -> ExprError {
    let range = error.span().byte_range();
    let message = format!("not a valid expression: {error}");
    if range == (0..0) && error.to_string().contains("end of input") {
        ExprError::new(source.trim_end().len(), message)
    } else {
        ExprError::new(range.start, message)
    }
}

/// The lexer failed; its span is vague, so look for the usual causes ourselves.
fn lex_error(source: &str, error: &proc_macro2::LexError) -> ExprError {
    if let Some(offset) = source.find(['"', '\'']) {
        return ExprError::new(offset, "string and character literals are not allowed");
    }
    unbalanced_delimiter(source).unwrap_or_else(|| {
        ExprError::new(
            error.span().byte_range().start,
            format!("cannot split the expression into tokens: {error}"),
        )
    })
}

/// Finds the first unmatched closing or the first unclosed opening bracket.
fn unbalanced_delimiter(source: &str) -> Option<ExprError> {
    let mut open: Vec<(char, usize)> = Vec::new();
    for (offset, c) in source.char_indices() {
        match c {
            '(' | '[' | '{' => open.push((c, offset)),
            ')' | ']' | '}' => match open.pop() {
                Some((o, _)) if closing_of(o) == c => {}
                _ => return Some(ExprError::new(offset, format!("unmatched `{c}`"))),
            },
            _ => {}
        }
    }
    open.first()
        .map(|&(c, offset)| ExprError::new(offset, format!("unclosed `{c}`")))
}

fn closing_of(open: char) -> char {
    match open {
        '(' => ')',
        '[' => ']',
        _ => '}',
    }
}

/// Converts the syn tree to [`Scalar`], checking every node.
struct Converter<'a> {
    /// The expression's variable, if it has one.
    variable: Option<&'a str>,
    /// The model's parameter names, by index.
    parameters: &'a [&'a str],
    /// Current depth of the recursion through [`Converter::expr`].
    depth: Cell<usize>,
}

impl Converter<'_> {
    fn expr(&self, expr: &Expr) -> Result<Scalar, ExprError> {
        let depth = self.depth.get() + 1;
        if depth > MAX_TREE_DEPTH {
            return Err(ExprError::at(
                expr,
                format!(
                    "the expression is nested too deeply: more than {MAX_TREE_DEPTH} operations \
                     inside one another (group long sums with parentheses)"
                ),
            ));
        }
        self.depth.set(depth);
        let scalar = self.node(expr);
        self.depth.set(depth - 1);
        let scalar = scalar?;
        match scalar.constant_value() {
            Some(value) if !value.is_finite() => Err(ExprError::at(
                expr,
                format!("this constant subexpression evaluates to {value}"),
            )),
            _ => Ok(scalar),
        }
    }

    fn node(&self, expr: &Expr) -> Result<Scalar, ExprError> {
        match expr {
            Expr::Lit(e) => no_attributes(&e.attrs).and_then(|()| literal(&e.lit)),
            Expr::Path(e) => no_attributes(&e.attrs).and_then(|()| self.path(e)),
            Expr::Paren(e) => no_attributes(&e.attrs).and_then(|()| self.expr(&e.expr)),
            Expr::Group(e) => no_attributes(&e.attrs).and_then(|()| self.expr(&e.expr)),
            Expr::Unary(e) => no_attributes(&e.attrs).and_then(|()| self.unary(e)),
            Expr::Binary(e) => no_attributes(&e.attrs).and_then(|()| self.binary(e)),
            Expr::MethodCall(e) => no_attributes(&e.attrs).and_then(|()| self.method_call(e)),
            Expr::Call(e) => no_attributes(&e.attrs).and_then(|()| self.call(e)),
            other => Err(unsupported(other)),
        }
    }

    fn path(&self, e: &syn::ExprPath) -> Result<Scalar, ExprError> {
        let names =
            plain_path(e).ok_or_else(|| ExprError::at(e, "generic paths are not allowed"))?;
        if names.len() == 1 && Some(names[0].as_str()) == self.variable {
            return Ok(Scalar::Var);
        }
        if let [name] = names.as_slice() {
            if let Some(i) = self.parameters.iter().position(|p| p == name) {
                return Ok(Scalar::Param(i));
            }
        }
        if let Some(value) = named_constant(&names) {
            return Ok(Scalar::Const(value));
        }
        let written = names.join("::");
        let message = if names.len() == 1 && function_by_name(&written).is_some() {
            format!("`{written}` is a function: call it, e.g. `{written}(x)` or `x.{written}()`")
        } else {
            let parameters = if self.parameters.is_empty() {
                "the model declares no parameters (list them under `parameters:`)".to_string()
            } else {
                format!("the parameters are {}", self.parameters.join(", "))
            };
            match self.variable {
                Some(v) => format!(
                    "unknown name `{written}`: the only variable allowed here is `{v}`; \
                     the constants are PI and E; {parameters}"
                ),
                None => {
                    format!("unknown name `{written}`: {parameters}; the constants are PI and E")
                }
            }
        };
        Err(ExprError::at(e, message))
    }

    fn unary(&self, e: &syn::ExprUnary) -> Result<Scalar, ExprError> {
        match e.op {
            UnOp::Neg(_) => Ok(Scalar::Neg(Box::new(self.expr(&e.expr)?))),
            ref op => Err(ExprError::at(
                op,
                format!(
                    "operator `{}` is not allowed; only unary minus is",
                    op.to_token_stream()
                ),
            )),
        }
    }

    fn binary(&self, e: &syn::ExprBinary) -> Result<Scalar, ExprError> {
        let combine: fn(Box<Scalar>, Box<Scalar>) -> Scalar = match e.op {
            BinOp::Add(_) => Scalar::Add,
            BinOp::Sub(_) => Scalar::Sub,
            BinOp::Mul(_) => Scalar::Mul,
            BinOp::Div(_) => Scalar::Div,
            ref op => return Err(binary_operator_error(op)),
        };
        let left = self.expr(&e.left)?;
        let right = self.expr(&e.right)?;
        if matches!(e.op, BinOp::Div(_)) && right.constant_value() == Some(0.0) {
            return Err(ExprError::at(
                &e.right,
                "division by zero: the divisor is a constant equal to 0",
            ));
        }
        Ok(combine(Box::new(left), Box::new(right)))
    }

    fn method_call(&self, e: &syn::ExprMethodCall) -> Result<Scalar, ExprError> {
        if let Some(turbofish) = &e.turbofish {
            return Err(ExprError::at(
                turbofish,
                "generic arguments are not allowed",
            ));
        }
        let name = e.method.to_string();
        let args: Vec<&Expr> = e.args.iter().collect();
        self.apply_named(&name, &e.method, &e.receiver, &args, e)
    }

    fn call(&self, e: &syn::ExprCall) -> Result<Scalar, ExprError> {
        let Expr::Path(path) = &*e.func else {
            return Err(ExprError::at(&e.func, "only math functions can be called"));
        };
        let names =
            plain_path(path).ok_or_else(|| ExprError::at(path, "generic paths are not allowed"))?;
        let name =
            function_call_name(&names).ok_or_else(|| unknown_function(path, &names.join("::")))?;
        let args: Vec<&Expr> = e.args.iter().collect();
        let Some((first, rest)) = args.split_first() else {
            return Err(ExprError::at(e, format!("`{name}` needs an argument")));
        };
        self.apply_named(name, path, first, rest, e)
    }

    /// `receiver.name(args)`; `name_node` locates "unknown function" errors, `whole` arity
    /// errors.
    fn apply_named(
        &self,
        name: &str,
        name_node: &impl Spanned,
        receiver: &Expr,
        args: &[&Expr],
        whole: &impl Spanned,
    ) -> Result<Scalar, ExprError> {
        match (name, args) {
            ("powi", [n]) => Ok(Scalar::Powi(
                Box::new(self.expr(receiver)?),
                integer_argument(n)?,
            )),
            ("powf", [b]) => Ok(Scalar::Powf(
                Box::new(self.expr(receiver)?),
                Box::new(self.expr(b)?),
            )),
            ("powi" | "powf", _) => {
                Err(ExprError::at(whole, format!("`{name}` takes an exponent")))
            }
            _ => match (function_by_name(name), args) {
                (Some(f), []) => Ok(Scalar::Call(f, Box::new(self.expr(receiver)?))),
                (Some(_), _) => Err(ExprError::at(
                    whole,
                    format!("`{name}` takes exactly one value, e.g. `x.{name}()` or `{name}(x)`"),
                )),
                (None, _) => Err(unknown_function(name_node, name)),
            },
        }
    }
}

fn no_attributes(attrs: &[syn::Attribute]) -> Result<(), ExprError> {
    match attrs.first() {
        Some(attr) => Err(ExprError::at(attr, "attributes are not allowed")),
        None => Ok(()),
    }
}

fn unknown_function(node: &impl Spanned, name: &str) -> ExprError {
    ExprError::at(
        node,
        format!("`{name}` is not a known math function; allowed: {ALLOWED_FUNCTIONS}"),
    )
}

/// The identifiers of a path without `<T>` arguments or a qualified self type.
fn plain_path(e: &syn::ExprPath) -> Option<Vec<String>> {
    if e.qself.is_some() {
        return None;
    }
    e.path
        .segments
        .iter()
        .map(|s| s.arguments.is_none().then(|| s.ident.to_string()))
        .collect()
}

/// `PI` and `E`, bare or through `f64::consts` / `std::f64::consts` / `core::f64::consts`.
fn named_constant(names: &[String]) -> Option<f64> {
    let (last, prefix) = names.split_last()?;
    let prefix: Vec<&str> = prefix.iter().map(String::as_str).collect();
    let prefix_ok = matches!(
        prefix.as_slice(),
        [] | ["f64", "consts"] | ["std" | "core", "f64", "consts"]
    );
    match last.as_str() {
        "PI" if prefix_ok => Some(std::f64::consts::PI),
        "E" if prefix_ok => Some(std::f64::consts::E),
        _ => None,
    }
}

/// `sin`, `f64::sin`, `std::f64::sin` (and the same for `powi`, `powf`) → the method name.
fn function_call_name(names: &[String]) -> Option<&str> {
    let (last, prefix) = names.split_last()?;
    let prefix: Vec<&str> = prefix.iter().map(String::as_str).collect();
    let prefix_ok = matches!(prefix.as_slice(), [] | ["f64"] | ["std" | "core", "f64"]);
    let known = function_by_name(last).is_some() || last == "powi" || last == "powf";
    (prefix_ok && known).then_some(last.as_str())
}

/// A numeric literal, plain or suffixed `f64`, that must be finite.
fn literal(lit: &Lit) -> Result<Scalar, ExprError> {
    let (digits, suffix) = match lit {
        Lit::Int(i) => (i.base10_digits(), i.suffix()),
        Lit::Float(f) => (f.base10_digits(), f.suffix()),
        _ => {
            return Err(ExprError::at(lit, "only numeric literals are allowed"));
        }
    };
    if !suffix.is_empty() && suffix != "f64" {
        return Err(ExprError::at(
            lit,
            format!("literal suffix `{suffix}` is not allowed; numbers are f64"),
        ));
    }
    match digits.parse::<f64>() {
        Ok(value) if value.is_finite() => Ok(Scalar::Const(value)),
        _ => Err(ExprError::at(
            lit,
            format!("the constant `{digits}` is not a finite f64"),
        )),
    }
}

/// Largest |n| accepted in `powi(n)`: far beyond any sensible profile, and small enough
/// that the exponents of the derivatives (n − 1, n − 2) cannot overflow an i32.
pub const MAX_POWI: i32 = 1_000_000;

/// The exponent of `powi`: an integer literal (possibly negated or parenthesised) with
/// |n| ≤ [`MAX_POWI`].
fn integer_argument(expr: &Expr) -> Result<i32, ExprError> {
    let n = integer_literal(expr)?;
    if n.unsigned_abs() <= MAX_POWI.unsigned_abs() {
        Ok(n)
    } else {
        Err(ExprError::at(
            expr,
            format!("the `powi` exponent {n} is outside ±{MAX_POWI}"),
        ))
    }
}

/// An integer literal, possibly negated or parenthesised, that fits an i32.
fn integer_literal(expr: &Expr) -> Result<i32, ExprError> {
    let message = "`powi` needs an integer literal exponent such as `.powi(3)`; \
                   use `.powf(...)` for other exponents";
    match expr {
        Expr::Lit(syn::ExprLit {
            lit: Lit::Int(i), ..
        }) if i.suffix().is_empty() || i.suffix() == "i32" => i
            .base10_parse::<i32>()
            .map_err(|_| ExprError::at(expr, "the `powi` exponent does not fit in an i32")),
        Expr::Unary(syn::ExprUnary {
            op: UnOp::Neg(_),
            expr: inner,
            ..
        }) => integer_literal(inner)?
            .checked_neg()
            .ok_or_else(|| ExprError::at(expr, "the `powi` exponent does not fit in an i32")),
        Expr::Paren(p) => integer_literal(&p.expr),
        _ => Err(ExprError::at(expr, message)),
    }
}

fn binary_operator_error(op: &BinOp) -> ExprError {
    let written = op.to_token_stream().to_string();
    let is_assignment = matches!(
        op,
        BinOp::AddAssign(_)
            | BinOp::SubAssign(_)
            | BinOp::MulAssign(_)
            | BinOp::DivAssign(_)
            | BinOp::RemAssign(_)
            | BinOp::BitXorAssign(_)
            | BinOp::BitAndAssign(_)
            | BinOp::BitOrAssign(_)
            | BinOp::ShlAssign(_)
            | BinOp::ShrAssign(_)
    );
    let message = if is_assignment {
        format!("`{written}` is an assignment; assignments are not allowed")
    } else {
        format!("operator `{written}` is not allowed; allowed: + - * /")
    };
    ExprError::at(op, message)
}

/// The error for any expression form outside the accepted subset.
fn unsupported(expr: &Expr) -> ExprError {
    let what = match expr {
        Expr::Assign(_) => "assignments are not allowed".to_string(),
        Expr::Block(_) | Expr::Unsafe(_) | Expr::Const(_) => "blocks are not allowed".to_string(),
        Expr::Macro(_) => "macros are not allowed".to_string(),
        Expr::Closure(_) => "closures are not allowed".to_string(),
        Expr::Cast(_) => "casts (`as`) are not allowed".to_string(),
        Expr::Field(f) => format!(
            "field access `.{}` is not allowed; math functions need parentheses, e.g. `x.sin()`",
            f.member.to_token_stream()
        ),
        Expr::If(_) | Expr::Match(_) | Expr::Loop(_) | Expr::While(_) | Expr::ForLoop(_) => {
            "control flow is not allowed".to_string()
        }
        _ => format!("this kind of expression is not allowed; {ALLOWED_SUMMARY}"),
    };
    ExprError::at(expr, what)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{E, PI};

    /// Parses with variable `x`, panicking with the error text on failure.
    fn parse_x(source: &str) -> Scalar {
        match parse_expression(source, "x") {
            Ok(s) => s,
            Err(e) => panic!("{source:?} should parse: {e}"),
        }
    }

    /// Parses with variable `x` and returns the error, panicking when it parses.
    fn error_x(source: &str) -> ExprError {
        match parse_expression(source, "x") {
            Ok(s) => panic!("{source:?} should be rejected, got {s:?}"),
            Err(e) => e,
        }
    }

    // Relative tolerance for comparing the tree evaluation with the closed form written in
    // Rust: both evaluate the same operations in possibly different association order, so
    // they agree to a few ulps; 1e-14 leaves a margin of ~50 ulps.
    const REL: f64 = 1e-14;

    fn assert_close(got: f64, want: f64, what: &str) {
        let scale = want.abs().max(1.0);
        assert!(
            (got - want).abs() <= REL * scale,
            "{what}: got {got}, want {want}"
        );
    }

    #[test]
    fn paper_profiles_evaluate_to_their_closed_forms() {
        let concave = parse_x("-0.595*x + 0.5*x*x + 0.5*x.powi(3)");
        let convex = parse_x("0.357*x - 0.3*x*x - 0.3*x.powi(3)");
        for &x in &[-1.0, -0.2, 0.0, 0.3793, 0.7, 1.3] {
            assert_close(
                concave.eval(x),
                -0.595 * x + 0.5 * x * x + 0.5 * x * x * x,
                "concave",
            );
            assert_close(
                convex.eval(x),
                0.357 * x - 0.3 * x * x - 0.3 * x * x * x,
                "convex",
            );
            // The designed pair: convex = -0.6 × concave = 0.5 x (x - 0.7)(x + 1.7) × (-0.6).
            assert_close(
                concave.eval(x),
                0.5 * x * (x - 0.7) * (x + 1.7),
                "factored concave",
            );
        }
    }

    #[test]
    fn drive_expression_evaluates_to_its_closed_form() {
        let drive = match parse_expression("-PI/2 + 0.45*(2.0*PI*t/4.0).sin()", "t") {
            Ok(s) => s,
            Err(e) => panic!("drive should parse: {e}"),
        };
        for &t in &[0.0, 0.5, 1.0, 2.7, 8.0] {
            let want = -PI / 2.0 + 0.45 * (2.0 * PI * t / 4.0).sin();
            assert_close(drive.eval(t), want, "drive");
        }
    }

    #[test]
    fn every_function_form_evaluates_like_std() {
        let x: f64 = 0.37;
        let cases: [(&str, f64); 22] = [
            ("x.sin()", x.sin()),
            ("sin(x)", x.sin()),
            ("f64::sin(x)", x.sin()),
            ("std::f64::cos(x)", x.cos()),
            ("x.tan()", x.tan()),
            ("x.exp()", x.exp()),
            ("x.ln()", x.ln()),
            ("x.sqrt()", x.sqrt()),
            ("x.sinh()", x.sinh()),
            ("x.cosh()", x.cosh()),
            ("tanh(x)", x.tanh()),
            ("x.atan()", x.atan()),
            ("x.powi(3)", x.powi(3)),
            ("x.powi(-2)", x.powi(-2)),
            ("powi(x, 3)", x.powi(3)),
            ("f64::powf(x, 1.5)", x.powf(1.5)),
            ("x.powf(x + 1)", x.powf(x + 1.0)),
            ("PI * E", PI * E),
            ("std::f64::consts::PI + f64::consts::E", PI + E),
            ("-(x - 2) / 4", -(x - 2.0) / 4.0),
            ("1_000.0f64 * x", 1000.0 * x),
            ("2.0.sqrt() * x", 2f64.sqrt() * x),
        ];
        for (source, want) in cases {
            assert_close(parse_x(source).eval(x), want, source);
        }
    }

    #[test]
    fn tree_shape_follows_rust_precedence() {
        let parsed = parse_x("1 - x * 2");
        let want = Scalar::Sub(
            Box::new(Scalar::Const(1.0)),
            Box::new(Scalar::Mul(
                Box::new(Scalar::Var),
                Box::new(Scalar::Const(2.0)),
            )),
        );
        assert_eq!(parsed, want);
        assert_eq!(
            parse_x("-x.powi(2)"),
            Scalar::Neg(Box::new(Scalar::Powi(Box::new(Scalar::Var), 2)))
        );
    }

    /// (source, expected byte offset, text the message must contain).
    const BAD: &[(&str, usize, &str)] = &[
        ("0.5*y + x", 4, "only variable allowed here is `x`"),
        (
            "x + foo(x)",
            4,
            "`foo` is not a known math function; allowed: sin",
        ),
        ("x.foo()", 2, "`foo` is not a known math function"),
        ("x.powi(2.5)", 7, "integer literal exponent"),
        ("x.powi(x)", 7, "integer literal exponent"),
        ("x = 2", 2, "assignments are not allowed"),
        ("x += 2", 2, "assignment"),
        ("{ x }", 0, "blocks are not allowed"),
        ("vec![x]", 0, "macros are not allowed"),
        ("|y| y", 0, "closures are not allowed"),
        ("x / (2 - 2)", 4, "division by zero"),
        ("x / 0", 4, "division by zero"),
        ("1e400 * x", 0, "not a finite f64"),
        ("x * (0.0).ln()", 4, "evaluates to -inf"),
        ("x % 2", 2, "operator `%` is not allowed"),
        ("x as f64", 2, "casts"),
        ("x.sin", 0, "field access"),
        ("x.sin(2)", 0, "takes exactly one value"),
        ("sin", 0, "`sin` is a function"),
        ("\"x\"", 0, "only numeric literals"),
        ("x + \"y", 4, "string and character literals"),
        ("2u8 * x", 0, "suffix `u8`"),
        ("x + ", 3, "not a valid expression"),
        ("(x + 1", 0, "unclosed `(`"),
        ("x + 1)", 5, "unmatched `)`"),
        ("x y", 2, "not a valid expression"),
        ("!x", 0, "operator `!`"),
        ("TAU * x", 0, "unknown name `TAU`"),
        ("x.powi(99999999999)", 7, "does not fit"),
        ("x.powi(-2147483647)", 7, "outside ±1000000"),
        ("x == 1", 2, "operator `==` is not allowed"),
        ("x[0]", 1, "brackets"),
        ("(|v| v)(x)", 1, "closures are not allowed"),
        ("x || 1", 2, "operator `||` is not allowed"),
        ("0..x", 1, "ranges"),
        ("return x", 0, "control flow"),
        ("let y = x", 0, "`let` is a Rust keyword"),
        ("#[inline] x", 0, "attributes"),
        ("x <<= 1", 2, "`<<=` is an assignment"),
        (
            "std::process::exit(1)",
            0,
            "`std::process::exit` is not a known math function",
        ),
    ];

    #[test]
    fn bad_expressions_are_rejected_at_the_offending_byte() {
        for &(source, offset, text) in BAD {
            let e = error_x(source);
            assert_eq!(e.offset, offset, "{source:?}: {e}");
            assert!(e.message.contains(text), "{source:?}: {e} lacks {text:?}");
        }
    }

    #[test]
    fn the_variable_name_is_per_call() {
        let e = match parse_expression("x + 1", "t") {
            Ok(s) => panic!("x is not the drive variable, got {s:?}"),
            Err(e) => e,
        };
        assert_eq!(e.offset, 0);
        assert!(e.message.contains("`t`"), "{e}");
    }

    #[test]
    fn offsets_stay_relative_to_each_source() {
        // proc-macro2 keeps a global source map; offsets must not accumulate across calls.
        for _ in 0..3 {
            assert_eq!(error_x("   y").offset, 3);
        }
    }

    #[test]
    fn display_shows_offset_and_message() {
        let e = error_x("x.foo()");
        assert!(e.to_string().starts_with("byte 2: `foo`"), "{e}");
    }
}
