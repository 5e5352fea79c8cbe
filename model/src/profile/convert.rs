//! The last pass: the syntax tree to a [`Scalar`], checking every node: names (the variable,
//! the parameters, `PI` and `E`), functions and their arguments, literals' suffixes and
//! values, divisors that are a constant zero, constant subexpressions that are not finite,
//! and the depth of the tree ([`MAX_TREE_DEPTH`]).

use super::literal::number;
use super::parse::{BinOp, Node, NodeKind};
use super::{
    ALLOWED_FUNCTIONS, ALLOWED_SUMMARY, ExprError, MAX_POWI, MAX_TREE_DEPTH, Scalar, apply,
    function_by_name, shown,
};

/// The [`Scalar`] that `tree`, parsed from `source`, denotes.
pub(super) fn convert(
    source: &str,
    tree: &Node,
    variables: &[&str],
    parameters: &[&str],
) -> Result<Scalar, ExprError> {
    let mut converter = Converter {
        source,
        variables,
        parameters,
        depth: 0,
    };
    Ok(converter.expr(tree)?.scalar)
}

/// A converted subexpression and, when it depends on neither the variable nor a parameter,
/// its value (the constant checks need it at every node: kept here, each node's is computed
/// once from its children's).
struct Value {
    scalar: Scalar,
    constant: Option<f64>,
}

impl Value {
    fn constant(value: f64) -> Self {
        Value {
            scalar: Scalar::Const(value),
            constant: Some(value),
        }
    }

    fn variable(scalar: Scalar) -> Self {
        Value {
            scalar,
            constant: None,
        }
    }

    /// f(self), with `value` the same function on the constant.
    fn map(self, wrap: impl FnOnce(Box<Scalar>) -> Scalar, value: impl FnOnce(f64) -> f64) -> Self {
        Value {
            scalar: wrap(Box::new(self.scalar)),
            constant: self.constant.map(value),
        }
    }

    /// f(self, other), with `value` the same function on the constants.
    fn combine(
        self,
        other: Value,
        wrap: fn(Box<Scalar>, Box<Scalar>) -> Scalar,
        value: fn(f64, f64) -> f64,
    ) -> Self {
        Value {
            scalar: wrap(Box::new(self.scalar), Box::new(other.scalar)),
            constant: self.constant.zip(other.constant).map(|(a, b)| value(a, b)),
        }
    }
}

/// Converts the syntax tree to [`Scalar`], checking every node.
struct Converter<'a> {
    source: &'a str,
    /// The expression's variables (none for a value of the parameters alone), by index.
    variables: &'a [&'a str],
    /// The model's parameter names, by index.
    parameters: &'a [&'a str],
    /// Current depth of the recursion through [`Converter::expr`].
    depth: usize,
}

impl<'a> Converter<'a> {
    fn text(&self, (start, end): (usize, usize)) -> &'a str {
        &self.source[start..end]
    }

    fn expr(&mut self, node: &Node) -> Result<Value, ExprError> {
        let depth = self.depth + 1;
        if depth > MAX_TREE_DEPTH {
            return Err(ExprError::new(
                node.start,
                format!(
                    "the expression is nested too deeply: more than {MAX_TREE_DEPTH} operations \
                     inside one another (group long sums with parentheses)"
                ),
            ));
        }
        self.depth = depth;
        let value = self.node(node);
        self.depth = depth - 1;
        let value = value?;
        match value.constant {
            Some(constant) if !constant.is_finite() => Err(ExprError::new(
                node.start,
                format!("this constant subexpression evaluates to {constant}"),
            )),
            _ => Ok(value),
        }
    }

    fn node(&mut self, node: &Node) -> Result<Value, ExprError> {
        let at = node.start;
        match &node.kind {
            NodeKind::Number(end) => literal(&self.source[at..*end], at),
            NodeKind::Bool => Err(ExprError::new(at, "only numeric literals are allowed")),
            NodeKind::Underscore => Err(ExprError::new(
                at,
                format!("`_` is not allowed; {ALLOWED_SUMMARY}"),
            )),
            NodeKind::Path(segments) => self.path(segments, at),
            NodeKind::Paren(inner) => self.expr(inner),
            NodeKind::Tuple => Err(ExprError::new(
                at,
                format!("tuples are not allowed; {ALLOWED_SUMMARY}"),
            )),
            NodeKind::Neg(inner) => Ok(self.expr(inner)?.map(Scalar::Neg, |a| -a)),
            NodeKind::Deref(_) => Err(ExprError::new(
                at,
                "operator `*` is not allowed; only unary minus is",
            )),
            NodeKind::Binary(op, left, right) => self.binary(*op, left, right),
            NodeKind::Method {
                receiver,
                name,
                args,
            } => {
                let args: Vec<&Node> = args.iter().collect();
                self.apply_named(self.text(*name), name.0, receiver, &args, at)
            }
            NodeKind::Field { member, .. } => Err(ExprError::new(
                at,
                format!(
                    "field access `.{}` is not allowed; math functions need parentheses, e.g. \
                     `x.sin()`",
                    shown(self.text(*member))
                ),
            )),
            NodeKind::Call { function, args } => self.call(function, args, at),
        }
    }

    fn path(&self, segments: &[(usize, usize)], at: usize) -> Result<Value, ExprError> {
        let names: Vec<&str> = segments.iter().map(|&s| self.text(s)).collect();
        if let [name] = names.as_slice() {
            if let Some(i) = self.variables.iter().position(|v| v == name) {
                // At most two variables (a surface's x and y): the index fits.
                let index = u8::try_from(i).unwrap_or(u8::MAX);
                return Ok(Value::variable(Scalar::Var(index)));
            }
            if let Some(i) = self.parameters.iter().position(|p| p == name) {
                return Ok(Value::variable(Scalar::Param(i)));
            }
        }
        if let Some(value) = named_constant(&names) {
            return Ok(Value::constant(value));
        }
        let written = shown(&names.join("::"));
        let message = if names.len() == 1 && function_by_name(&written).is_some() {
            format!("`{written}` is a function: call it, e.g. `{written}(x)` or `x.{written}()`")
        } else {
            let parameters = if self.parameters.is_empty() {
                "the model declares no parameters (list them under `parameters:`)".to_string()
            } else {
                format!("the parameters are {}", self.parameters.join(", "))
            };
            match self.variables {
                [] => {
                    format!("unknown name `{written}`: {parameters}; the constants are PI and E")
                }
                [v] => format!(
                    "unknown name `{written}`: the only variable allowed here is `{v}`; \
                     the constants are PI and E; {parameters}"
                ),
                [first @ .., last] => format!(
                    "unknown name `{written}`: the variables allowed here are `{}` and `{last}`; \
                     the constants are PI and E; {parameters}",
                    first.join("`, `")
                ),
            }
        };
        Err(ExprError::new(at, message))
    }

    fn binary(&mut self, op: BinOp, left: &Node, right: &Node) -> Result<Value, ExprError> {
        let l = self.expr(left)?;
        let r = self.expr(right)?;
        Ok(match op {
            BinOp::Add => l.combine(r, Scalar::Add, |a, b| a + b),
            BinOp::Sub => l.combine(r, Scalar::Sub, |a, b| a - b),
            BinOp::Mul => l.combine(r, Scalar::Mul, |a, b| a * b),
            BinOp::Div => {
                if r.constant == Some(0.0) {
                    return Err(ExprError::new(
                        right.start,
                        "division by zero: the divisor is a constant equal to 0",
                    ));
                }
                l.combine(r, Scalar::Div, |a, b| a / b)
            }
        })
    }

    fn call(&mut self, function: &Node, args: &[Node], at: usize) -> Result<Value, ExprError> {
        let NodeKind::Path(segments) = &function.kind else {
            return Err(ExprError::new(
                function.start,
                "only math functions can be called",
            ));
        };
        let names: Vec<&str> = segments.iter().map(|&s| self.text(s)).collect();
        let Some(name) = function_call_name(&names) else {
            return Err(unknown_function(function.start, &names.join("::")));
        };
        let args: Vec<&Node> = args.iter().collect();
        let Some((first, rest)) = args.split_first() else {
            return Err(ExprError::new(at, format!("`{name}` needs an argument")));
        };
        self.apply_named(name, function.start, first, rest, at)
    }

    /// `receiver.name(args)`; `name_at` locates "unknown function" errors, `whole` arity
    /// errors.
    fn apply_named(
        &mut self,
        name: &str,
        name_at: usize,
        receiver: &Node,
        args: &[&Node],
        whole: usize,
    ) -> Result<Value, ExprError> {
        match (name, args) {
            ("powi", [n]) => {
                let base = self.expr(receiver)?;
                let n = self.integer_argument(n)?;
                Ok(base.map(|a| Scalar::Powi(a, n), |a| a.powi(n)))
            }
            ("powf", [b]) => {
                let base = self.expr(receiver)?;
                let exponent = self.expr(b)?;
                Ok(base.combine(exponent, Scalar::Powf, f64::powf))
            }
            ("powi" | "powf", _) => {
                Err(ExprError::new(whole, format!("`{name}` takes an exponent")))
            }
            _ => match (function_by_name(name), args) {
                (Some(f), []) => Ok(self
                    .expr(receiver)?
                    .map(|a| Scalar::Call(f, a), |a| apply(f, a))),
                (Some(_), _) => Err(ExprError::new(
                    whole,
                    format!("`{name}` takes exactly one value, e.g. `x.{name}()` or `{name}(x)`"),
                )),
                (None, _) => Err(unknown_function(name_at, name)),
            },
        }
    }

    /// The exponent of `powi`: an integer literal (possibly negated or parenthesised) with
    /// |n| ≤ [`MAX_POWI`].
    fn integer_argument(&self, node: &Node) -> Result<i32, ExprError> {
        let n = self.integer_literal(node)?;
        if n.unsigned_abs() <= MAX_POWI.unsigned_abs() {
            Ok(n)
        } else {
            Err(ExprError::new(
                node.start,
                format!("the `powi` exponent {n} is outside ±{MAX_POWI}"),
            ))
        }
    }

    /// An integer literal, unsuffixed or suffixed `i32`, possibly negated or parenthesised,
    /// that fits an i32. Recursive, in the nesting the screen has bounded.
    fn integer_literal(&self, node: &Node) -> Result<i32, ExprError> {
        let does_not_fit =
            || ExprError::new(node.start, "the `powi` exponent does not fit in an i32");
        match &node.kind {
            NodeKind::Number(end) => match number(&self.source[node.start..*end]) {
                Some(n) if n.integer && (n.suffix.is_empty() || n.suffix == "i32") => {
                    n.as_i32.ok_or_else(does_not_fit)
                }
                _ => Err(powi_needs_an_integer(node.start)),
            },
            NodeKind::Neg(inner) => self
                .integer_literal(inner)?
                .checked_neg()
                .ok_or_else(does_not_fit),
            NodeKind::Paren(inner) => self.integer_literal(inner),
            _ => Err(powi_needs_an_integer(node.start)),
        }
    }
}

fn unknown_function(at: usize, name: &str) -> ExprError {
    ExprError::new(
        at,
        format!(
            "`{}` is not a known math function; allowed: {ALLOWED_FUNCTIONS}",
            shown(name)
        ),
    )
}

/// `PI` and `E`, bare or through `f64::consts` / `std::f64::consts` / `core::f64::consts`.
fn named_constant(names: &[&str]) -> Option<f64> {
    let (last, prefix) = names.split_last()?;
    let prefix_ok = matches!(
        prefix,
        [] | ["f64", "consts"] | ["std" | "core", "f64", "consts"]
    );
    match *last {
        "PI" if prefix_ok => Some(std::f64::consts::PI),
        "E" if prefix_ok => Some(std::f64::consts::E),
        _ => None,
    }
}

/// `sin`, `f64::sin`, `std::f64::sin` (and the same for `powi`, `powf`) → the method name.
fn function_call_name<'a>(names: &[&'a str]) -> Option<&'a str> {
    let (last, prefix) = names.split_last()?;
    let prefix_ok = matches!(prefix, [] | ["f64"] | ["std" | "core", "f64"]);
    let known = function_by_name(last).is_some() || *last == "powi" || *last == "powf";
    (prefix_ok && known).then_some(*last)
}

/// A numeric literal, plain or suffixed `f64`, that must be finite.
fn literal(text: &str, at: usize) -> Result<Value, ExprError> {
    let Some(n) = number(text) else {
        return Err(ExprError::new(
            at,
            format!("`{}` is not a valid number", shown(text)),
        ));
    };
    if !n.suffix.is_empty() && n.suffix != "f64" {
        return Err(ExprError::new(
            at,
            format!(
                "literal suffix `{}` is not allowed; numbers are f64",
                shown(n.suffix)
            ),
        ));
    }
    if n.value.is_finite() {
        Ok(Value::constant(n.value))
    } else {
        Err(ExprError::new(
            at,
            format!("the constant `{}` is not a finite f64", shown(text)),
        ))
    }
}

fn powi_needs_an_integer(at: usize) -> ExprError {
    ExprError::new(
        at,
        "`powi` needs an integer literal exponent such as `.powi(3)`; use `.powf(...)` for \
         other exponents",
    )
}
