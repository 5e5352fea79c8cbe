//! The first two passes over an expression: splitting it into Rust's tokens ([`tokens`]) and
//! rejecting, on the tokens alone, what is never allowed and what would nest too deeply
//! ([`screen`]).
//!
//! The lexer follows Rust's lexical grammar where an accepted expression can tell: numeric
//! literals with their underscores, exponents, base prefixes and suffixes; whitespace and
//! comments (`//` and nested `/* */`); identifiers, raw identifiers (`r#name`) and keywords;
//! punctuation glued into Rust's multi-character operators. String and character literals are
//! rejected where they start. Identifiers are letters, digits and `_` in Unicode's sense
//! (`char::is_alphabetic`, `char::is_alphanumeric`), a superset of Rust's XID rules that
//! matters only for which message rejects an exotic character.

use super::{ALLOWED_SUMMARY, ExprError, MAX_NESTING, MAX_TOKENS};

/// What a token is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    /// An identifier or keyword; a raw identifier (`r#name`) keeps its `r#`.
    Ident,
    /// A numeric literal with its suffix, as written (`1_000.5e-3f64`, `0x1F`).
    Number,
    /// One Rust operator or separator (`+`, `::`, `<<=`, …), glued as Rust glues adjacent
    /// punctuation.
    Punct,
    /// `(`, `[` or `{`.
    Open(char),
    /// `)`, `]` or `}`.
    Close(char),
    /// A label or lifetime: `'` and an identifier.
    Lifetime,
    /// A doc comment (`///`, `//!`, `/**`, `/*!`), which Rust reads as an attribute.
    DocComment,
}

/// A token: its kind and where it is in the source (byte offsets).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Token {
    /// What it is.
    pub kind: Kind,
    /// Byte offset of its first character.
    pub start: usize,
    /// Byte offset just after it.
    pub end: usize,
}

impl Token {
    /// Its text in `source`.
    pub fn text<'a>(&self, source: &'a str) -> &'a str {
        &source[self.start..self.end]
    }

    /// True for punctuation written `op`.
    pub fn is_punct(&self, source: &str, op: &str) -> bool {
        self.kind == Kind::Punct && self.text(source) == op
    }
}

/// Rust's punctuation characters (the apostrophe apart: it starts a character literal or a
/// lifetime).
const PUNCTUATION: &str = "~!@#$%^&*-=+|;:,<.>/?";

/// Multi-character Rust operators; adjacent punctuation is glued into the longest one it
/// starts, one character at a time.
const OPERATORS: [&str; 26] = [
    "..=", "...", "<<=", ">>=", "::", "..", "==", "!=", "<=", ">=", "&&", "||", "+=", "-=", "*=",
    "/=", "%=", "^=", "&=", "|=", "<<", ">>", "->", "=>", "<-", "#!",
];

/// Starts of string literals with a prefix: raw, byte and C strings, byte characters.
const STRING_PREFIXES: [&str; 10] = [
    "r\"", "r#\"", "r##", "b\"", "b'", "br\"", "br#", "c\"", "cr\"", "cr#",
];

/// Can start an identifier (or a literal's suffix).
pub(super) fn is_ident_start(c: char) -> bool {
    c == '_' || c.is_alphabetic()
}

/// Can continue an identifier.
pub(super) fn is_ident_continue(c: char) -> bool {
    c == '_' || c.is_alphanumeric()
}

/// Whitespace as Rust reads it: Unicode's, and the left-to-right and right-to-left marks.
fn is_whitespace(c: char) -> bool {
    c.is_whitespace() || c == '\u{200e}' || c == '\u{200f}'
}

/// The tokens of `source`, with comments and whitespace dropped: the first [`MAX_TOKENS`] + 1
/// that [`screen`] counts and the closing delimiters among them; the rest of the source is
/// read for lexical errors only, so an error anywhere in it comes first, as a compiler's
/// would, while the tokens kept stay bounded.
///
/// Errors: a character no token starts with, a malformed number or raw identifier, a string
/// or character literal, an unterminated block comment, an unmatched closing or an unclosed
/// opening delimiter.
pub(super) fn tokens(source: &str) -> Result<Vec<Token>, ExprError> {
    let mut lexer = Lexer { source, at: 0 };
    let mut tokens = Vec::new();
    let mut open: Vec<(char, usize)> = Vec::new();
    let mut counted = 0usize;
    while let Some(token) = lexer.next()? {
        match token.kind {
            Kind::Open(c) => open.push((c, token.start)),
            Kind::Close(c) => match open.pop() {
                Some((o, _)) if closing_of(o) == c => {}
                _ => return Err(ExprError::new(token.start, format!("unmatched `{c}`"))),
            },
            _ => {}
        }
        let is_counted = !matches!(token.kind, Kind::Close(_));
        if counted <= MAX_TOKENS {
            tokens.push(token);
            counted += usize::from(is_counted);
        }
    }
    match open.first() {
        Some(&(c, offset)) => Err(ExprError::new(offset, format!("unclosed `{c}`"))),
        None => Ok(tokens),
    }
}

fn closing_of(open: char) -> char {
    match open {
        '(' => ')',
        '[' => ']',
        _ => '}',
    }
}

/// A cursor over the source.
struct Lexer<'a> {
    source: &'a str,
    /// Byte offset of the next character.
    at: usize,
}

impl Lexer<'_> {
    fn rest(&self) -> &str {
        &self.source[self.at..]
    }

    fn peek(&self) -> Option<char> {
        self.rest().chars().next()
    }

    /// The next token, or None at the end of the source.
    fn next(&mut self) -> Result<Option<Token>, ExprError> {
        self.skip_trivia()?;
        let start = self.at;
        let Some(c) = self.peek() else {
            return Ok(None);
        };
        let kind = if let Some(end) = self.doc_comment_end()? {
            self.at = end;
            Kind::DocComment
        } else {
            match c {
                '(' | '[' | '{' => {
                    self.at += 1;
                    Kind::Open(c)
                }
                ')' | ']' | '}' => {
                    self.at += 1;
                    Kind::Close(c)
                }
                '0'..='9' => {
                    self.at = number_end(self.source, start).ok_or_else(|| {
                        ExprError::new(
                            start,
                            "cannot split the expression into tokens: malformed number",
                        )
                    })?;
                    Kind::Number
                }
                '"' => return Err(string_literal(start)),
                '\'' => self.quote()?,
                c if is_ident_start(c) => self.ident()?,
                c if PUNCTUATION.contains(c) => {
                    self.punct();
                    Kind::Punct
                }
                c => {
                    return Err(ExprError::new(
                        start,
                        format!(
                            "cannot split the expression into tokens: unexpected character \
                             `{}`",
                            c.escape_debug()
                        ),
                    ));
                }
            }
        };
        Ok(Some(Token {
            kind,
            start,
            end: self.at,
        }))
    }

    /// Skips whitespace and comments other than doc comments.
    fn skip_trivia(&mut self) -> Result<(), ExprError> {
        loop {
            let rest = self.rest();
            if rest.starts_with("//")
                && (!rest.starts_with("///") || rest.starts_with("////"))
                && !rest.starts_with("//!")
            {
                self.at += rest.find('\n').unwrap_or(rest.len());
            } else if rest.starts_with("/**/") {
                self.at += 4;
            } else if rest.starts_with("/*")
                && (!rest.starts_with("/**") || rest.starts_with("/***"))
                && !rest.starts_with("/*!")
            {
                self.at += block_comment_len(rest).ok_or_else(|| unterminated(self.at))?;
            } else {
                match self.peek() {
                    Some(c) if is_whitespace(c) => self.at += c.len_utf8(),
                    _ => return Ok(()),
                }
            }
        }
    }

    /// The end of a doc comment starting here, if one does.
    fn doc_comment_end(&self) -> Result<Option<usize>, ExprError> {
        let rest = self.rest();
        let line =
            (rest.starts_with("///") && !rest.starts_with("////")) || rest.starts_with("//!");
        let block =
            (rest.starts_with("/**") && !rest.starts_with("/***")) || rest.starts_with("/*!");
        if line {
            Ok(Some(self.at + rest.find('\n').unwrap_or(rest.len())))
        } else if block {
            let len = block_comment_len(rest).ok_or_else(|| unterminated(self.at))?;
            Ok(Some(self.at + len))
        } else {
            Ok(None)
        }
    }

    /// After `'`: a lifetime or label (`'a`, `'static`); a character literal is an error.
    fn quote(&mut self) -> Result<Kind, ExprError> {
        let start = self.at;
        let after = &self.source[start + 1..];
        let mut chars = after.chars();
        let first = chars.next();
        let character = first == Some('\\') || (first.is_some() && chars.next() == Some('\''));
        let ident = first.is_some_and(is_ident_start);
        if character || !ident {
            return Err(string_literal(start));
        }
        let len = after
            .find(|c: char| !is_ident_continue(c))
            .unwrap_or(after.len());
        self.at = start + 1 + len;
        if self.peek() == Some('\'') {
            // `'ab'`: neither a character nor a lifetime.
            return Err(string_literal(start));
        }
        Ok(Kind::Lifetime)
    }

    /// An identifier, keyword or raw identifier; a prefixed string literal is an error.
    fn ident(&mut self) -> Result<Kind, ExprError> {
        let start = self.at;
        let rest = self.rest();
        if STRING_PREFIXES.iter().any(|p| rest.starts_with(p)) {
            return Err(string_literal(start));
        }
        let raw = rest.starts_with("r#");
        let body = &rest[if raw { 2 } else { 0 }..];
        let len = body
            .find(|c: char| !is_ident_continue(c))
            .unwrap_or(body.len());
        let word = &body[..len];
        let valid = match word.chars().next() {
            Some(c) if is_ident_start(c) => {
                !raw || !matches!(word, "_" | "super" | "self" | "Self" | "crate")
            }
            _ => false,
        };
        if !valid {
            return Err(ExprError::new(
                start,
                "cannot split the expression into tokens: malformed raw identifier",
            ));
        }
        self.at = start + rest.len() - body.len() + len;
        Ok(Kind::Ident)
    }

    /// Punctuation: the longest operator its adjacent characters spell, one at a time.
    fn punct(&mut self) {
        let start = self.at;
        let mut end = start + 1;
        while let Some(next) = self.source[end..].chars().next() {
            if !PUNCTUATION.contains(next) {
                break;
            }
            let longer = &self.source[start..end + next.len_utf8()];
            if !OPERATORS.iter().any(|o| o.starts_with(longer)) {
                break;
            }
            end += next.len_utf8();
        }
        self.at = end;
    }
}

fn string_literal(offset: usize) -> ExprError {
    ExprError::new(
        offset,
        "string and character literals are not allowed; only numeric literals are",
    )
}

fn unterminated(offset: usize) -> ExprError {
    ExprError::new(
        offset,
        "cannot split the expression into tokens: unterminated block comment",
    )
}

/// The length of the (nested) block comment `text` starts with, if it ends.
fn block_comment_len(text: &str) -> Option<usize> {
    let bytes = text.as_bytes();
    let mut depth = 0usize;
    let mut i = 0;
    while i + 1 < bytes.len() {
        if bytes[i] == b'/' && bytes[i + 1] == b'*' {
            depth += 1;
            i += 1;
        } else if bytes[i] == b'*' && bytes[i + 1] == b'/' {
            depth = depth.saturating_sub(1);
            if depth == 0 {
                return Some(i + 2);
            }
            i += 1;
        }
        i += 1;
    }
    None
}

/// The end of the numeric literal starting with a digit at `start`, suffix included, or None
/// when no literal starts there (`0x` without digits, `0b2`). A float is tried first, as Rust
/// does: digits with a `.` not followed by `.` or an identifier (`1.0`, `1.`; `1..2` is a
/// range, `1.e3` and `2.sqrt()` member accesses), or an exponent with digits (`1e-3`).
fn number_end(source: &str, start: usize) -> Option<usize> {
    let literal = |digits_end: Option<usize>| {
        let mut end = digits_end?;
        let rest = &source[end..];
        if rest.starts_with(is_ident_start) {
            end += rest
                .find(|c: char| !is_ident_continue(c))
                .unwrap_or(rest.len());
        }
        // The literal must end where a word ends.
        (!source[end..].starts_with(is_ident_continue)).then_some(end)
    };
    literal(float_digits(source, start)).or_else(|| literal(int_digits(source, start)))
}

/// The end of a float literal's digits (no suffix), if one starts at `start`.
fn float_digits(source: &str, start: usize) -> Option<usize> {
    let bytes = &source.as_bytes()[start..];
    let mut i = 1;
    let mut has_dot = false;
    let mut has_exp = false;
    while let Some(&b) = bytes.get(i) {
        match b {
            b'0'..=b'9' | b'_' => i += 1,
            b'.' if !has_dot => {
                let next = source[start + i + 1..].chars().next();
                if next.is_some_and(|c| c == '.' || is_ident_start(c)) {
                    return None;
                }
                i += 1;
                has_dot = true;
            }
            b'e' | b'E' => {
                has_exp = true;
                break;
            }
            _ => break,
        }
    }
    if !has_exp {
        return has_dot.then_some(start + i);
    }
    let before_exponent = has_dot.then_some(start + i);
    i += 1;
    let mut has_sign = false;
    let mut has_value = false;
    while let Some(&b) = bytes.get(i) {
        match b {
            b'+' | b'-' if !has_value => {
                if has_sign {
                    return before_exponent;
                }
                has_sign = true;
            }
            b'0'..=b'9' => has_value = true,
            b'_' => {}
            _ => break,
        }
        i += 1;
    }
    if has_value {
        Some(start + i)
    } else {
        before_exponent
    }
}

/// The end of an integer literal's digits (no suffix), if one starts at `start`.
fn int_digits(source: &str, start: usize) -> Option<usize> {
    let bytes = &source.as_bytes()[start..];
    let (base, mut i) = match bytes {
        [b'0', b'x', ..] => (16, 2),
        [b'0', b'o', ..] => (8, 2),
        [b'0', b'b', ..] => (2, 2),
        _ => (10, 0),
    };
    let mut empty = true;
    while let Some(&b) = bytes.get(i) {
        let digit = match b {
            b'0'..=b'9' => u32::from(b - b'0'),
            b'a'..=b'f' => u32::from(b - b'a') + 10,
            b'A'..=b'F' => u32::from(b - b'A') + 10,
            b'_' => {
                i += 1;
                continue;
            }
            _ => break,
        };
        if digit >= base {
            if b.is_ascii_digit() {
                return None;
            }
            break;
        }
        i += 1;
        empty = false;
    }
    (!empty).then_some(start + i)
}

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

/// One open group while screening: its nesting depth and scanning state.
struct Level {
    depth: usize,
    prefix_run: usize,
    previous: Previous,
}

/// Rejects, before the parser sees them, the token shapes that are never valid here and the
/// ones that would nest the parser's recursion deeply: brackets and braces, keywords,
/// attributes, lifetimes, operators other than `+ - * /`, macros, closures, ranges, and
/// nesting (parentheses and prefix `-` or `*` in a row) deeper than [`MAX_NESTING`] or more
/// than [`MAX_TOKENS`] tokens (closing parentheses apart). Iterative, so any input is
/// screened in bounded stack. What passes holds identifiers other than keywords, numbers,
/// parentheses and `+ - * / , . :: :` only.
pub(super) fn screen(source: &str, tokens: &[Token]) -> Result<(), ExprError> {
    let mut stack = vec![Level {
        depth: 0,
        prefix_run: 0,
        previous: Previous::Start,
    }];
    let mut count = 0usize;
    for token in tokens {
        let at = token.start;
        let Some(level) = stack.last_mut() else {
            break;
        };
        if let Kind::Close(_) = token.kind {
            stack.pop();
            continue;
        }
        count += 1;
        if count > MAX_TOKENS {
            return Err(ExprError::new(
                at,
                format!("the expression is too long: more than {MAX_TOKENS} tokens"),
            ));
        }
        match token.kind {
            Kind::Close(_) => {}
            Kind::Open('(') => {
                let depth = level.depth + level.prefix_run + 1;
                if depth > MAX_NESTING {
                    return Err(nesting_error(at));
                }
                level.prefix_run = 0;
                level.previous = Previous::Operand;
                stack.push(Level {
                    depth,
                    prefix_run: 0,
                    previous: Previous::Start,
                });
            }
            Kind::Open('[') => {
                return Err(ExprError::new(
                    at,
                    "brackets `[...]` are not allowed (no arrays or indexing)",
                ));
            }
            Kind::Open(_) => return Err(ExprError::new(at, "blocks are not allowed")),
            Kind::Ident => {
                if let Some(message) = keyword_error(token.text(source)) {
                    return Err(ExprError::new(at, message));
                }
                level.prefix_run = 0;
                level.previous = Previous::Ident(at);
            }
            Kind::Number => {
                level.prefix_run = 0;
                level.previous = Previous::Operand;
            }
            Kind::DocComment => {
                return Err(ExprError::new(
                    at,
                    "attributes are not allowed (a doc comment is one)",
                ));
            }
            Kind::Lifetime => {
                return Err(ExprError::new(at, "labels and lifetimes are not allowed"));
            }
            Kind::Punct => {
                let op = token.text(source);
                let prefix_position =
                    matches!(level.previous, Previous::Start | Previous::Operator);
                match op {
                    "-" | "*" if prefix_position => {
                        level.prefix_run += 1;
                        if level.depth + level.prefix_run > MAX_NESTING {
                            return Err(nesting_error(at));
                        }
                    }
                    "+" | "-" | "*" | "/" | "," | "." | "::" | ":" => level.prefix_run = 0,
                    _ => return Err(punct_error(op, at, level.previous, prefix_position)),
                }
                level.previous = Previous::Operator;
            }
        }
    }
    Ok(())
}

/// Why the punctuation `op` at `at` is not allowed.
fn punct_error(op: &str, at: usize, previous: Previous, prefix_position: bool) -> ExprError {
    match op {
        "!" => match previous {
            Previous::Ident(start) => ExprError::new(start, "macros are not allowed"),
            _ => ExprError::new(at, "operator `!` is not allowed; only unary minus is"),
        },
        "|" | "||" if prefix_position => ExprError::new(at, "closures are not allowed"),
        ".." | "..=" | "..." => ExprError::new(at, "ranges (`..`) are not allowed"),
        "#" | "#!" => ExprError::new(at, "attributes are not allowed"),
        "=" => ExprError::new(at, "assignments are not allowed"),
        "==" | "!=" | "<=" | ">=" | "=>" | "->" | "<-" => operator_error(at, op),
        _ if op.len() > 1 && op.ends_with('=') => ExprError::new(
            at,
            format!("`{op}` is an assignment; assignments are not allowed"),
        ),
        _ => operator_error(at, op),
    }
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
