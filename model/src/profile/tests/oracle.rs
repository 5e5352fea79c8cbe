//! The parser profile expressions had before the crate's own: `syn` 's, with the screen and
//! the conversion of that time, kept verbatim (test-only) as the oracle of the differential
//! test (`differential.rs`): the new parser must accept exactly what it accepts, with equal
//! trees.

use crate::profile::{
    ALLOWED_FUNCTIONS, ALLOWED_SUMMARY, ExprError, MAX_NESTING, MAX_POWI, MAX_TOKENS,
    MAX_TREE_DEPTH, Scalar, function_by_name,
};
use proc_macro2::TokenStream;
use quote::ToTokens;
use std::cell::Cell;
use std::str::FromStr;
use syn::spanned::Spanned;
use syn::{BinOp, Expr, Lit, UnOp};

/// The error at a syn node.
fn at(node: &impl Spanned, message: impl Into<String>) -> ExprError {
    ExprError::new(node.span().byte_range().start, message)
}

/// The value of the expression when it does not depend on the variable.
fn constant_value(scalar: &Scalar) -> Option<f64> {
    if mentions_variable(scalar) {
        None
    } else {
        Some(scalar.eval(0.0))
    }
}

/// True when the variable or a parameter occurs anywhere in the tree.
fn mentions_variable(scalar: &Scalar) -> bool {
    match scalar {
        Scalar::Const(_) => false,
        Scalar::Var | Scalar::Param(_) => true,
        Scalar::Neg(a) | Scalar::Powi(a, _) | Scalar::Call(_, a) | Scalar::Table(_, _, a) => {
            mentions_variable(a)
        }
        Scalar::Add(a, b)
        | Scalar::Sub(a, b)
        | Scalar::Mul(a, b)
        | Scalar::Div(a, b)
        | Scalar::Powf(a, b) => mentions_variable(a) || mentions_variable(b),
    }
}

/// [`parse_expression`] with the model's parameters: a name in `parameters` becomes
/// [`Scalar::Param`] with its index. Without a `variable` the expression is a value of the
/// parameters alone (a numeric field written as `"l1/2"`).
pub(super) fn parse_expression_with(
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
            return Err(at(
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
        match constant_value(&scalar) {
            Some(value) if !value.is_finite() => Err(at(
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
        let names = plain_path(e).ok_or_else(|| at(e, "generic paths are not allowed"))?;
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
        Err(at(e, message))
    }

    fn unary(&self, e: &syn::ExprUnary) -> Result<Scalar, ExprError> {
        match e.op {
            UnOp::Neg(_) => Ok(Scalar::Neg(Box::new(self.expr(&e.expr)?))),
            ref op => Err(at(
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
        if matches!(e.op, BinOp::Div(_)) && constant_value(&right) == Some(0.0) {
            return Err(at(
                &e.right,
                "division by zero: the divisor is a constant equal to 0",
            ));
        }
        Ok(combine(Box::new(left), Box::new(right)))
    }

    fn method_call(&self, e: &syn::ExprMethodCall) -> Result<Scalar, ExprError> {
        if let Some(turbofish) = &e.turbofish {
            return Err(at(turbofish, "generic arguments are not allowed"));
        }
        let name = e.method.to_string();
        let args: Vec<&Expr> = e.args.iter().collect();
        self.apply_named(&name, &e.method, &e.receiver, &args, e)
    }

    fn call(&self, e: &syn::ExprCall) -> Result<Scalar, ExprError> {
        let Expr::Path(path) = &*e.func else {
            return Err(at(&e.func, "only math functions can be called"));
        };
        let names = plain_path(path).ok_or_else(|| at(path, "generic paths are not allowed"))?;
        let name =
            function_call_name(&names).ok_or_else(|| unknown_function(path, &names.join("::")))?;
        let args: Vec<&Expr> = e.args.iter().collect();
        let Some((first, rest)) = args.split_first() else {
            return Err(at(e, format!("`{name}` needs an argument")));
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
            ("powi" | "powf", _) => Err(at(whole, format!("`{name}` takes an exponent"))),
            _ => match (function_by_name(name), args) {
                (Some(f), []) => Ok(Scalar::Call(f, Box::new(self.expr(receiver)?))),
                (Some(_), _) => Err(at(
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
        Some(attr) => Err(at(attr, "attributes are not allowed")),
        None => Ok(()),
    }
}

fn unknown_function(node: &impl Spanned, name: &str) -> ExprError {
    at(
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
            return Err(at(lit, "only numeric literals are allowed"));
        }
    };
    if !suffix.is_empty() && suffix != "f64" {
        return Err(at(
            lit,
            format!("literal suffix `{suffix}` is not allowed; numbers are f64"),
        ));
    }
    match digits.parse::<f64>() {
        Ok(value) if value.is_finite() => Ok(Scalar::Const(value)),
        _ => Err(at(
            lit,
            format!("the constant `{digits}` is not a finite f64"),
        )),
    }
}

/// The exponent of `powi`: an integer literal (possibly negated or parenthesised) with
/// |n| ≤ [`MAX_POWI`].
fn integer_argument(expr: &Expr) -> Result<i32, ExprError> {
    let n = integer_literal(expr)?;
    if n.unsigned_abs() <= MAX_POWI.unsigned_abs() {
        Ok(n)
    } else {
        Err(at(
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
            .map_err(|_| at(expr, "the `powi` exponent does not fit in an i32")),
        Expr::Unary(syn::ExprUnary {
            op: UnOp::Neg(_),
            expr: inner,
            ..
        }) => integer_literal(inner)?
            .checked_neg()
            .ok_or_else(|| at(expr, "the `powi` exponent does not fit in an i32")),
        Expr::Paren(p) => integer_literal(&p.expr),
        _ => Err(at(expr, message)),
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
    at(op, message)
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
    at(expr, what)
}
