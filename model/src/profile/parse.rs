//! The third pass: the tree of a screened token list, by precedence climbing over Rust's
//! expression grammar restricted to what the screen lets through (identifiers, numbers,
//! parentheses and `+ - * / , . :: :`).
//!
//! The grammar, binding tightest first: atoms (a number, `true`/`false`, a path
//! `a::b::c` with an optional leading `::`, a parenthesised expression or a tuple); postfix
//! `.name(args)`, `.name`, `.0` and calls `f(args)` (arguments separated by commas, a trailing
//! one allowed); prefix `-` and `*`; then `*` `/`, then `+` `-`, both left-associative. So
//! `-x.sin()` is −(sin x), `-2.0.powi(2)` is −(2²), `1 - x * 2` is 1 − (x·2), as in Rust.
//! Only syntax is checked here: what the forms mean, and whether they are allowed, is the
//! conversion's (`convert`), so the errors come in the order the old parser gave them.
//!
//! Recursion: the parser recurses into parentheses and prefix operators, a few frames per
//! level, which the screen has bounded by [`super::MAX_NESTING`]; chains of binary operators,
//! postfix calls and path segments are loops. The tree itself may be as deep as the
//! expression is long (a sum of 1000 terms), which the conversion bounds by
//! [`super::MAX_TREE_DEPTH`].

use super::lex::{Kind, Token};
use super::literal::number;
use super::{ExprError, shown};

/// Words that are neither a member name nor a path segment after `::`: the literals `true`
/// and `false`, `_`, and the path keywords (the screen has rejected the other keywords).
fn is_reserved(word: &str) -> bool {
    matches!(
        word,
        "true" | "false" | "_" | "self" | "Self" | "super" | "crate"
    )
}

/// A binary operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
}

/// A node of the syntax tree: what it is and the byte offset of its first token (where an
/// error about it points).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Node {
    /// Byte offset of its first token.
    pub start: usize,
    /// What it is.
    pub kind: NodeKind,
}

/// The forms of the syntax tree. Text is kept as byte ranges into the source.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum NodeKind {
    /// A numeric literal, its text ending at the byte offset.
    Number(usize),
    /// `true` or `false`.
    Bool,
    /// `_`.
    Underscore,
    /// A path, by the byte ranges of its segments (a leading `::` dropped).
    Path(Vec<(usize, usize)>),
    /// `( a )`.
    Paren(Box<Node>),
    /// `()`, `(a,)`, `(a, b)`.
    Tuple,
    /// `-a`.
    Neg(Box<Node>),
    /// `*a`.
    Deref(Box<Node>),
    /// `a op b`.
    Binary(BinOp, Box<Node>, Box<Node>),
    /// `receiver.name(args)`, with the name's byte range.
    Method {
        receiver: Box<Node>,
        name: (usize, usize),
        args: Vec<Node>,
    },
    /// `receiver.member` without a call, with the member's byte range.
    Field {
        receiver: Box<Node>,
        member: (usize, usize),
    },
    /// `function(args)`.
    Call {
        function: Box<Node>,
        args: Vec<Node>,
    },
}

/// The tree of the screened `tokens` of `source`.
pub(super) fn parse(source: &str, tokens: &[Token]) -> Result<Node, ExprError> {
    let mut parser = Parser {
        source,
        tokens,
        next: 0,
    };
    let tree = parser.expression(0)?;
    match parser.peek() {
        None => Ok(tree),
        Some(token) => Err(parser.unexpected(
            token,
            "expected an operator (+ - * /) or the end of the expression",
        )),
    }
}

struct Parser<'a> {
    source: &'a str,
    tokens: &'a [Token],
    /// Index of the next token.
    next: usize,
}

impl Parser<'_> {
    fn peek(&self) -> Option<Token> {
        self.tokens.get(self.next).copied()
    }

    fn peek_punct(&self, op: &str) -> bool {
        self.peek().is_some_and(|t| t.is_punct(self.source, op))
    }

    fn peek_kind(&self, kind: Kind) -> bool {
        self.peek().is_some_and(|t| t.kind == kind)
    }

    /// Takes the next token.
    fn bump(&mut self) -> Option<Token> {
        let token = self.peek();
        self.next += 1;
        token
    }

    /// What Rust reads as a member after `.`: an identifier other than a keyword, or a tuple
    /// index: an unsuffixed integer that fits a u32 (`x.0`, `x.0x1F`) or two runs of digits
    /// around a `.` (`x.1.2`, the indices 1 and 2).
    fn is_member(&self, token: Token) -> bool {
        let text = token.text(self.source);
        let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit() || b == b'_');
        match token.kind {
            Kind::Ident => !is_reserved(text),
            Kind::Number => {
                number(text).is_some_and(|n| {
                    n.integer && n.suffix.is_empty() && n.value <= f64::from(u32::MAX)
                }) || text
                    .split_once('.')
                    .is_some_and(|(a, b)| digits(a) && digits(b))
            }
            _ => false,
        }
    }

    /// A syntax error at `token`.
    fn unexpected(&self, token: Token, expected: &str) -> ExprError {
        ExprError::new(
            token.start,
            format!(
                "not a valid expression: {expected}, found `{}`",
                shown(token.text(self.source))
            ),
        )
    }

    /// A syntax error at the next token, or just after the last one when none is left.
    fn expected(&self, expected: &str) -> ExprError {
        match self.peek() {
            Some(token) => self.unexpected(token, expected),
            None if self.tokens.is_empty() => {
                ExprError::new(0, "not a valid expression: the expression is empty")
            }
            None => {
                let end = self.tokens.last().map_or(0, |t| t.end);
                ExprError::new(
                    end,
                    format!("not a valid expression: {expected}, found the end of the expression"),
                )
            }
        }
    }

    /// Binary operators binding at least as tightly as `min_precedence` (1: `+ -`, 2: `* /`),
    /// left-associative.
    fn expression(&mut self, min_precedence: u8) -> Result<Node, ExprError> {
        let mut left = self.prefix()?;
        while let Some(token) = self.peek() {
            let (op, precedence) = match token.kind {
                Kind::Punct => match token.text(self.source) {
                    "+" => (BinOp::Add, 1),
                    "-" => (BinOp::Sub, 1),
                    "*" => (BinOp::Mul, 2),
                    "/" => (BinOp::Div, 2),
                    _ => break,
                },
                _ => break,
            };
            if precedence < min_precedence {
                break;
            }
            self.bump();
            let right = self.expression(precedence + 1)?;
            left = Node {
                start: left.start,
                kind: NodeKind::Binary(op, Box::new(left), Box::new(right)),
            };
        }
        Ok(left)
    }

    /// Prefix `-` and `*`, then a postfix expression.
    fn prefix(&mut self) -> Result<Node, ExprError> {
        let Some(token) = self.peek() else {
            return Err(self.expected("expected a number, a name or `(`"));
        };
        let wrap: fn(Box<Node>) -> NodeKind = if token.is_punct(self.source, "-") {
            NodeKind::Neg
        } else if token.is_punct(self.source, "*") {
            NodeKind::Deref
        } else {
            return self.postfix();
        };
        self.bump();
        let operand = self.prefix()?;
        Ok(Node {
            start: token.start,
            kind: wrap(Box::new(operand)),
        })
    }

    /// An atom followed by member accesses, method calls and calls.
    fn postfix(&mut self) -> Result<Node, ExprError> {
        let mut node = self.atom()?;
        loop {
            let start = node.start;
            if self.peek_punct(".") {
                self.bump();
                let member = match self.peek() {
                    Some(t) if self.is_member(t) => t,
                    _ => return Err(self.expected("expected a method name after `.`")),
                };
                self.bump();
                let range = (member.start, member.end);
                let kind = if member.kind == Kind::Ident && self.peek_kind(Kind::Open('(')) {
                    NodeKind::Method {
                        receiver: Box::new(node),
                        name: range,
                        args: self.arguments()?,
                    }
                } else if self.peek_punct("::") {
                    return Err(self.expected("expected `(` after the method name"));
                } else {
                    NodeKind::Field {
                        receiver: Box::new(node),
                        member: range,
                    }
                };
                node = Node { start, kind };
            } else if self.peek_kind(Kind::Open('(')) {
                node = Node {
                    start,
                    kind: NodeKind::Call {
                        function: Box::new(node),
                        args: self.arguments()?,
                    },
                };
            } else {
                return Ok(node);
            }
        }
    }

    /// `( a, b, … )` with an optional trailing comma; the next token is the `(`.
    fn arguments(&mut self) -> Result<Vec<Node>, ExprError> {
        let items = self.parenthesised_items()?;
        Ok(items.into_iter().map(|(item, _)| item).collect())
    }

    /// A number, `true`/`false`, a path or a parenthesised expression (or tuple).
    fn atom(&mut self) -> Result<Node, ExprError> {
        let Some(token) = self.peek() else {
            return Err(self.expected("expected a number, a name or `(`"));
        };
        match token.kind {
            Kind::Number => {
                self.bump();
                Ok(Node {
                    start: token.start,
                    kind: NodeKind::Number(token.end),
                })
            }
            Kind::Ident if matches!(token.text(self.source), "true" | "false" | "_") => {
                self.bump();
                let kind = if token.text(self.source) == "_" {
                    NodeKind::Underscore
                } else {
                    NodeKind::Bool
                };
                Ok(Node {
                    start: token.start,
                    kind,
                })
            }
            Kind::Ident => self.path(),
            Kind::Punct if token.is_punct(self.source, "::") => self.path(),
            Kind::Open('(') => self.parenthesised(),
            _ => Err(self.unexpected(token, "expected a number, a name or `(`")),
        }
    }

    /// `a::b::c`, with an optional leading `::`.
    fn path(&mut self) -> Result<Node, ExprError> {
        let start = self.peek().map_or(0, |t| t.start);
        if self.peek_punct("::") {
            self.bump();
        }
        let mut segments = Vec::new();
        loop {
            match self.peek() {
                Some(t) if t.kind == Kind::Ident && !is_reserved(t.text(self.source)) => {
                    self.bump();
                    segments.push((t.start, t.end));
                }
                _ => return Err(self.expected("expected a name")),
            }
            // `a::(` ends the path before the `::`, which is then out of place.
            let after = self.tokens.get(self.next + 1);
            if !self.peek_punct("::") || after.is_some_and(|t| t.kind == Kind::Open('(')) {
                break;
            }
            self.bump();
        }
        Ok(Node {
            start,
            kind: NodeKind::Path(segments),
        })
    }

    /// `( a )`, or a tuple `()`, `(a,)`, `(a, b)`; the next token is the `(`.
    fn parenthesised(&mut self) -> Result<Node, ExprError> {
        let start = self.peek().map_or(0, |t| t.start);
        let mut items = self.parenthesised_items()?;
        let kind = match (items.len(), items.pop()) {
            (1, Some((inner, false))) => NodeKind::Paren(Box::new(inner)),
            _ => NodeKind::Tuple,
        };
        Ok(Node { start, kind })
    }

    /// The items of a parenthesised list, each with whether a comma followed it.
    fn parenthesised_items(&mut self) -> Result<Vec<(Node, bool)>, ExprError> {
        self.bump();
        let mut items = Vec::new();
        loop {
            if self.peek_kind(Kind::Close(')')) {
                self.bump();
                return Ok(items);
            }
            let item = self.expression(0)?;
            if self.peek_punct(",") {
                self.bump();
                items.push((item, true));
            } else if self.peek_kind(Kind::Close(')')) {
                items.push((item, false));
            } else {
                return Err(self.expected("expected `,` or `)`"));
            }
        }
    }
}
