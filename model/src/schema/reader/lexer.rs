//! RON tokens with their byte ranges: punctuation, identifiers, numbers (as written; their
//! value depends on the type asked for), strings and characters (escapes decoded), byte
//! literals and byte strings. Whitespace and comments (`//`, nestable `/* */`) are skipped.
//!
//! Tokens are produced on demand, so a defect late in the text is reported only if the
//! reader gets that far, as ron does. Every step advances by whole characters: no byte
//! sequence can make the lexer slice inside a character, and each token costs time linear
//! in its length.

use super::error::{Code, Error, Place};
use super::{is_ident_continue, is_ident_start};
use std::borrow::Cow;

/// One token.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Token<'s> {
    pub kind: Kind<'s>,
    /// Byte offset of the first character.
    pub start: usize,
    /// Byte offset just past the last character.
    pub end: usize,
}

#[derive(Debug, Clone, PartialEq)]
pub(super) enum Kind<'s> {
    /// A single character that starts no other token: `( ) [ ] { } , : # ! =`, or a stray
    /// one (`@`, `;`, `.` not followed by a digit…), left for the reader to report in
    /// context.
    Punct(char),
    /// An identifier; `raw` for `r#name` (whose `name` may contain `.`, `+` and `-`).
    Ident {
        name: &'s str,
        raw: bool,
    },
    /// A number as written, sign and suffix included (`-1_000`, `0x1F`, `2.5e-3`, `1f32`,
    /// `-inf`); see [`super::number`]. Unsigned `inf` and `NaN` are identifiers.
    Number(&'s str),
    Str(Cow<'s, str>),
    Char(char),
    /// `b'a'`.
    Byte(u8),
    /// `b"…"` or `br"…"`.
    Bytes(Cow<'s, [u8]>),
    /// The end of the text.
    Eof,
}

/// ron's whitespace: ASCII spaces and line breaks and a few Unicode marks.
fn is_whitespace(c: char) -> bool {
    matches!(
        c,
        ' ' | '\t'
            | '\n'
            | '\r'
            | '\x0B'
            | '\x0C'
            | '\u{85}'
            | '\u{200E}'
            | '\u{200F}'
            | '\u{2028}'
            | '\u{2029}'
    )
}

/// Characters of a raw identifier after `r#`.
fn is_raw_ident_char(c: char) -> bool {
    is_ident_continue(c) || matches!(c, '.' | '+' | '-')
}

/// Characters of a number after its first: digits, letters (bases, exponents, suffixes),
/// `_` and `.`; a sign only right after an exponent's `e`.
fn is_number_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, '_' | '.')
}

pub(super) struct Lexer<'s> {
    source: &'s str,
    pos: usize,
}

/// How escapes are decoded: into characters (strings, chars) or bytes (byte strings).
#[derive(Clone, Copy, PartialEq)]
enum Encoding {
    Utf8,
    Binary,
}

/// One decoded escape.
enum Escaped {
    Byte(u8),
    Char(char),
}

impl<'s> Lexer<'s> {
    pub(super) fn new(source: &'s str) -> Self {
        Lexer { source, pos: 0 }
    }

    fn rest(&self) -> &'s str {
        self.source.get(self.pos..).unwrap_or("")
    }

    fn peek_char(&self) -> Option<char> {
        self.rest().chars().next()
    }

    fn error(&mut self, code: Code, at: usize) -> Error {
        // Nothing after an error is read: the reader stops at the first one.
        self.pos = self.source.len();
        Error::at(
            code,
            Place {
                start: at,
                end: at,
                before: at,
            },
        )
    }

    /// The next token, after whitespace and comments.
    pub(super) fn next_token(&mut self) -> Result<Token<'s>, Error> {
        self.skip_blank()?;
        let start = self.pos;
        let rest = self.rest();
        let Some(c) = rest.chars().next() else {
            return Ok(Token {
                kind: Kind::Eof,
                start,
                end: start,
            });
        };
        let kind = match c {
            '"' => {
                self.pos += 1;
                Kind::Str(self.escaped_string(start)?)
            }
            '\'' => Kind::Char(self.char_literal(start)?),
            'r' if rest.starts_with("r\"")
                || rest.starts_with("r#\"")
                || rest.starts_with("r##") =>
            {
                self.pos += 1;
                let body = self.raw_body(start)?;
                Kind::Str(Cow::Borrowed(body))
            }
            'r' if rest.starts_with("r#") && rest[2..].starts_with(is_raw_ident_char) => {
                let len = rest[2..]
                    .find(|c| !is_raw_ident_char(c))
                    .unwrap_or(rest.len() - 2);
                self.pos += 2 + len;
                Kind::Ident {
                    name: &rest[2..2 + len],
                    raw: true,
                }
            }
            'b' if rest.starts_with("b'") => Kind::Byte(self.byte_literal(start)?),
            'b' if rest.starts_with("b\"") => {
                self.pos += 2;
                Kind::Bytes(self.escaped_bytes(start)?)
            }
            'b' if rest.starts_with("br\"") || rest.starts_with("br#") => {
                self.pos += 2;
                Kind::Bytes(Cow::Borrowed(self.raw_body(start)?.as_bytes()))
            }
            c if is_ident_start(c) => {
                let len = rest.find(|c| !is_ident_continue(c)).unwrap_or(rest.len());
                self.pos += len;
                Kind::Ident {
                    name: &rest[..len],
                    raw: false,
                }
            }
            c if starts_number(rest) => {
                let mut len = c.len_utf8();
                let mut previous = c;
                for c in rest[len..].chars() {
                    let exponent_sign = matches!(c, '+' | '-') && matches!(previous, 'e' | 'E');
                    if !(is_number_char(c) || exponent_sign) {
                        break;
                    }
                    len += c.len_utf8();
                    previous = c;
                }
                self.pos += len;
                Kind::Number(&rest[..len])
            }
            c => {
                self.pos += c.len_utf8();
                Kind::Punct(c)
            }
        };
        Ok(Token {
            kind,
            start,
            end: self.pos,
        })
    }

    /// Skips whitespace and comments.
    fn skip_blank(&mut self) -> Result<(), Error> {
        loop {
            let rest = self.rest();
            let blank = rest.find(|c| !is_whitespace(c)).unwrap_or(rest.len());
            self.pos += blank;
            let rest = self.rest();
            if rest.starts_with("//") {
                self.pos += rest.find('\n').unwrap_or(rest.len());
            } else if rest.starts_with("/*") {
                self.block_comment()?;
            } else if let Some(after) = rest.strip_prefix('/') {
                let start = self.pos;
                return Err(match after.chars().next() {
                    Some(c) => self.error(Code::UnexpectedChar(c), start),
                    None => self.error(Code::Eof, start),
                });
            } else {
                return Ok(());
            }
        }
    }

    /// Skips a block comment (they nest, as in Rust) starting at the cursor.
    fn block_comment(&mut self) -> Result<(), Error> {
        let start = self.pos;
        let bytes = self.source.as_bytes();
        let mut depth = 0usize;
        let mut i = start;
        // `/` and `*` are ASCII, so every index this stops at is a character boundary.
        while i + 1 < bytes.len() {
            match (bytes[i], bytes[i + 1]) {
                (b'/', b'*') => {
                    depth += 1;
                    i += 2;
                }
                (b'*', b'/') => {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        self.pos = i;
                        return Ok(());
                    }
                }
                _ => i += 1,
            }
        }
        Err(self.error(Code::UnclosedBlockComment, start))
    }

    /// The body of a string whose opening `"` is consumed; `start` is where the literal
    /// began.
    fn escaped_string(&mut self, start: usize) -> Result<Cow<'s, str>, Error> {
        let rest = self.rest();
        let Some(close) = rest.find(['"', '\\']) else {
            return Err(self.error(Code::ExpectedStringEnd, start));
        };
        if rest.as_bytes()[close] == b'"' {
            self.pos += close + 1;
            return Ok(Cow::Borrowed(&rest[..close]));
        }
        let mut text = String::from(&rest[..close]);
        self.pos += close;
        loop {
            // At a backslash.
            let escape_at = self.pos;
            self.pos += 1;
            if !self.string_continuation() {
                match self.escape(Encoding::Utf8, false, escape_at, start)? {
                    Escaped::Byte(b) => text.push(char::from(b)),
                    Escaped::Char(c) => text.push(c),
                }
            }
            let rest = self.rest();
            let Some(next) = rest.find(['"', '\\']) else {
                return Err(self.error(Code::ExpectedStringEnd, start));
            };
            text.push_str(&rest[..next]);
            self.pos += next;
            if rest.as_bytes()[next] == b'"' {
                self.pos += 1;
                return Ok(Cow::Owned(text));
            }
        }
    }

    /// The body of a byte string whose opening `b"` is consumed.
    fn escaped_bytes(&mut self, start: usize) -> Result<Cow<'s, [u8]>, Error> {
        let mut bytes = Vec::new();
        loop {
            let rest = self.rest();
            let Some(next) = rest.find(['"', '\\']) else {
                return Err(self.error(Code::ExpectedStringEnd, start));
            };
            bytes.extend_from_slice(&rest.as_bytes()[..next]);
            self.pos += next;
            if rest.as_bytes()[next] == b'"' {
                self.pos += 1;
                return Ok(Cow::Owned(bytes));
            }
            let escape_at = self.pos;
            self.pos += 1;
            if !self.string_continuation() {
                match self.escape(Encoding::Binary, false, escape_at, start)? {
                    Escaped::Byte(b) => bytes.push(b),
                    Escaped::Char(c) => {
                        bytes.extend_from_slice(c.encode_utf8(&mut [0; 4]).as_bytes());
                    }
                }
            }
        }
    }

    /// After a backslash: a line break and the blanks after it are skipped (a string
    /// continuation, as in Rust); true when there was one.
    fn string_continuation(&mut self) -> bool {
        let rest = self.rest();
        let line_break = if rest.starts_with("\r\n") {
            2
        } else if rest.starts_with('\n') {
            1
        } else {
            return false;
        };
        let rest = &rest[line_break..];
        let blank = rest
            .find(|c| !matches!(c, ' ' | '\t' | '\n' | '\r'))
            .unwrap_or(rest.len());
        self.pos += line_break + blank;
        true
    }

    /// The body of a raw string `r#*"…"#*` whose `r` (or `br`) is consumed.
    fn raw_body(&mut self, start: usize) -> Result<&'s str, Error> {
        let rest = self.rest();
        let hashes = rest.len() - rest.trim_start_matches('#').len();
        let Some(body) = rest[hashes..].strip_prefix('"') else {
            return Err(self.error(Code::ExpectedString, start));
        };
        let closing = format!("\"{}", &rest[..hashes]);
        let Some(end) = body.find(&closing) else {
            return Err(self.error(Code::ExpectedStringEnd, start));
        };
        self.pos += hashes + 1 + end + closing.len();
        Ok(&body[..end])
    }

    /// `'c'` at the cursor.
    fn char_literal(&mut self, start: usize) -> Result<char, Error> {
        self.pos += 1;
        let Some(c) = self.peek_char() else {
            return Err(self.error(Code::Eof, self.pos));
        };
        let escape_at = self.pos;
        self.pos += c.len_utf8();
        let c = if c == '\\' {
            match self.escape(Encoding::Utf8, true, escape_at, start)? {
                Escaped::Byte(b) => char::from(b),
                Escaped::Char(c) => c,
            }
        } else {
            c
        };
        if self.peek_char() != Some('\'') {
            return Err(self.error(Code::ExpectedChar, start));
        }
        self.pos += 1;
        Ok(c)
    }

    /// `b'a'` at the cursor.
    fn byte_literal(&mut self, start: usize) -> Result<u8, Error> {
        self.pos += 2;
        let Some(c) = self.peek_char() else {
            return Err(self.error(Code::Eof, self.pos));
        };
        let escape_at = self.pos;
        self.pos += c.len_utf8();
        let byte = match c {
            '\\' => match self.escape(Encoding::Binary, true, escape_at, start)? {
                Escaped::Byte(b) => b,
                Escaped::Char(_) => {
                    return Err(self.error(
                        Code::InvalidEscape("Unexpected Unicode escape in byte literal"),
                        escape_at,
                    ));
                }
            },
            c if c.is_ascii() => c as u8,
            _ => return Err(self.error(Code::ExpectedByteLiteral, start)),
        };
        if self.peek_char() != Some('\'') {
            return Err(self.error(Code::ExpectedByteLiteral, start));
        }
        self.pos += 1;
        Ok(byte)
    }

    /// One escape after its backslash (at `at`, in the literal starting at `literal`).
    fn escape(
        &mut self,
        encoding: Encoding,
        in_char: bool,
        at: usize,
        literal: usize,
    ) -> Result<Escaped, Error> {
        let Some(c) = self.peek_char() else {
            return Err(self.error(Code::ExpectedStringEnd, literal));
        };
        self.pos += c.len_utf8();
        let invalid = |lexer: &mut Self, what| Err(lexer.error(Code::InvalidEscape(what), at));
        Ok(match c {
            '\'' => Escaped::Byte(b'\''),
            '"' => Escaped::Byte(b'"'),
            '\\' => Escaped::Byte(b'\\'),
            'n' => Escaped::Byte(b'\n'),
            'r' => Escaped::Byte(b'\r'),
            't' => Escaped::Byte(b'\t'),
            '0' => Escaped::Byte(b'\0'),
            'x' => {
                let Some(first) = self.hex_byte() else {
                    return invalid(self, "Non-hex digit found");
                };
                if encoding == Encoding::Binary || first.is_ascii() {
                    return Ok(Escaped::Byte(first));
                }
                if in_char {
                    return invalid(self, "Not a valid byte-escaped Unicode character");
                }
                // A character of up to four bytes, each written `\xHH`.
                let mut bytes = vec![first];
                while bytes.len() < 4 {
                    if !self.rest().starts_with("\\x") {
                        break;
                    }
                    self.pos += 2;
                    let Some(b) = self.hex_byte() else {
                        return invalid(self, "Non-hex digit found");
                    };
                    bytes.push(b);
                    if let Some(c) = std::str::from_utf8(&bytes)
                        .ok()
                        .and_then(|s| s.chars().next())
                    {
                        return Ok(Escaped::Char(c));
                    }
                }
                return invalid(self, "Not a valid byte-escaped Unicode character");
            }
            'u' => {
                if self.peek_char() != Some('{') {
                    return invalid(self, "Missing { in Unicode escape");
                }
                self.pos += 1;
                let digits = self
                    .rest()
                    .find(|c: char| !c.is_ascii_hexdigit())
                    .unwrap_or(self.rest().len());
                if digits == 0 {
                    return invalid(self, "Expected 1-6 digits, got 0 digits in Unicode escape");
                }
                if digits > 6 {
                    return invalid(self, "No } at the end of Unicode escape");
                }
                let value = u32::from_str_radix(&self.rest()[..digits], 16).ok();
                self.pos += digits;
                if self.peek_char() != Some('}') {
                    return invalid(self, "No } at the end of Unicode escape");
                }
                self.pos += 1;
                match value.and_then(char::from_u32) {
                    Some(c) => Escaped::Char(c),
                    None => return invalid(self, "Not a valid Unicode-escaped character"),
                }
            }
            _ => return invalid(self, "Unknown escape character"),
        })
    }

    /// Two hexadecimal digits at the cursor, as a byte.
    fn hex_byte(&mut self) -> Option<u8> {
        let digits = self.rest().get(..2)?;
        let byte = u8::from_str_radix(digits, 16).ok()?;
        // `from_str_radix` accepts a leading `+`; an escape does not.
        if !digits.bytes().all(|b| b.is_ascii_hexdigit()) {
            return None;
        }
        self.pos += 2;
        Some(byte)
    }
}

/// True when a number starts here: a digit; `.` and a digit; or a sign followed by either,
/// or by `inf` or `NaN`.
fn starts_number(rest: &str) -> bool {
    let unsigned = rest.strip_prefix(['+', '-']);
    let body = unsigned.unwrap_or(rest);
    let digit = |s: &str| s.starts_with(|c: char| c.is_ascii_digit());
    digit(body)
        || body.strip_prefix('.').is_some_and(digit)
        || (unsigned.is_some() && (body.starts_with("inf") || body.starts_with("NaN")))
}
