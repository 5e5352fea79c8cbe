//! The reader's error: what went wrong (worded as ron 0.12 words it, so that messages stay
//! those the project's users and tests know) and where, as byte offsets into the source.

use serde::de;
use std::fmt;

/// Where an error is: the byte range of the token it is about (empty at the end of the text
/// or where no token applies) and the end of the token before it, so that a missing `,` or
/// closing bracket can be reported just after the value that lacks it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::schema) struct Place {
    /// Byte offset of the offending token's first character.
    pub start: usize,
    /// Byte offset just past the offending token.
    pub end: usize,
    /// Byte offset just past the token before it (0 at the start of the text).
    pub before: usize,
}

/// A RON syntax or type error, located once it leaves the reader.
#[derive(Debug, Clone, PartialEq)]
pub(in crate::schema) struct Error {
    pub code: Code,
    /// `None` only while the error travels through serde's generated code, which creates
    /// errors without knowing positions; the reader places it before returning it.
    pub place: Option<Place>,
}

impl Error {
    pub(super) fn new(code: Code) -> Self {
        Error { code, place: None }
    }

    pub(super) fn at(code: Code, place: Place) -> Self {
        Error {
            code,
            place: Some(place),
        }
    }

    /// Places an error that has no position yet.
    pub(super) fn or_at(mut self, place: Place) -> Self {
        self.place.get_or_insert(place);
        self
    }
}

/// What went wrong.
#[derive(Debug, Clone, PartialEq)]
pub(in crate::schema) enum Code {
    Message(String),
    Eof,
    ExpectedArray,
    ExpectedArrayEnd,
    ExpectedAttribute,
    ExpectedAttributeEnd,
    ExpectedBoolean,
    ExpectedComma,
    ExpectedChar,
    ExpectedByteLiteral,
    ExpectedFloat,
    FloatUnderscore,
    ExpectedInteger,
    ExpectedOptionEnd,
    ExpectedMap,
    ExpectedMapColon,
    ExpectedMapEnd,
    ExpectedDifferentStructName {
        expected: &'static str,
        found: String,
    },
    ExpectedStructLike,
    ExpectedNamedStructLike(&'static str),
    ExpectedStructLikeEnd,
    ExpectedUnit,
    ExpectedString,
    ExpectedByteString,
    ExpectedStringEnd,
    ExpectedIdentifier,
    InvalidEscape(&'static str),
    IntegerOutOfBounds,
    InvalidIntegerDigit {
        digit: char,
        base: u32,
    },
    NoSuchExtension(String),
    UnclosedBlockComment,
    UnderscoreAtBeginning,
    UnexpectedChar(char),
    TrailingCharacters,
    InvalidValueForType {
        expected: String,
        found: String,
    },
    ExpectedDifferentLength {
        expected: String,
        found: usize,
    },
    NoSuchEnumVariant {
        expected: &'static [&'static str],
        found: String,
        outer: Option<String>,
    },
    NoSuchStructField {
        expected: &'static [&'static str],
        found: String,
        outer: Option<String>,
    },
    MissingStructField {
        field: &'static str,
        outer: Option<String>,
    },
    DuplicateStructField {
        field: &'static str,
        outer: Option<String>,
    },
    /// Brackets (or `Some(`) nested deeper than [`super::MAX_DEPTH`].
    TooDeep,
    ExpectedStructName(&'static str),
}

impl Code {
    /// True for the errors that mean a `,` or a closing bracket is missing after a value.
    pub(in crate::schema) fn is_missing_delimiter(&self) -> bool {
        matches!(
            self,
            Code::ExpectedComma
                | Code::ExpectedStructLikeEnd
                | Code::ExpectedArrayEnd
                | Code::ExpectedMapEnd
                | Code::ExpectedOptionEnd
        )
    }

    /// True when quoting the offending token adds nothing: the message names it already, or
    /// the position is not that of a token.
    pub(in crate::schema) fn names_the_token(&self) -> bool {
        matches!(
            self,
            Code::NoSuchEnumVariant { .. }
                | Code::NoSuchStructField { .. }
                | Code::MissingStructField { .. }
                | Code::DuplicateStructField { .. }
                | Code::ExpectedDifferentStructName { .. }
                | Code::NoSuchExtension(_)
                | Code::UnexpectedChar(_)
                | Code::ExpectedStringEnd
                | Code::UnclosedBlockComment
                | Code::InvalidEscape(_)
                | Code::TooDeep
        )
    }
}

impl fmt::Display for Code {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Code::Message(s) => f.write_str(s),
            Code::Eof => f.write_str("Unexpected end of RON"),
            Code::ExpectedArray => f.write_str("Expected opening `[`"),
            Code::ExpectedArrayEnd => f.write_str("Expected closing `]`"),
            Code::ExpectedAttribute => f.write_str("Expected an `#![enable(...)]` attribute"),
            Code::ExpectedAttributeEnd => {
                f.write_str("Expected closing `)]` after the enable attribute")
            }
            Code::ExpectedBoolean => f.write_str("Expected boolean"),
            Code::ExpectedComma => f.write_str("Expected comma"),
            Code::ExpectedChar => f.write_str("Expected char"),
            Code::ExpectedByteLiteral => f.write_str("Expected byte literal"),
            Code::ExpectedFloat => f.write_str("Expected float"),
            Code::FloatUnderscore => f.write_str("Unexpected underscore in float"),
            Code::ExpectedInteger => f.write_str("Expected integer"),
            Code::ExpectedOptionEnd | Code::ExpectedStructLikeEnd => {
                f.write_str("Expected closing `)`")
            }
            Code::ExpectedMap => f.write_str("Expected opening `{`"),
            Code::ExpectedMapColon => f.write_str("Expected colon"),
            Code::ExpectedMapEnd => f.write_str("Expected closing `}`"),
            Code::ExpectedDifferentStructName { expected, found } => write!(
                f,
                "Expected struct {} but found {}",
                Name(expected),
                Name(found)
            ),
            Code::ExpectedStructLike => f.write_str("Expected opening `(`"),
            Code::ExpectedNamedStructLike(name) => {
                if name.is_empty() {
                    f.write_str("Expected only opening `(`, no name, for un-nameable struct")
                } else {
                    write!(f, "Expected opening `(` for struct {}", Name(name))
                }
            }
            Code::ExpectedUnit => f.write_str("Expected unit"),
            Code::ExpectedString => f.write_str("Expected string"),
            Code::ExpectedByteString => f.write_str("Expected byte string"),
            Code::ExpectedStringEnd => f.write_str("Expected end of string"),
            Code::ExpectedIdentifier => f.write_str("Expected identifier"),
            Code::InvalidEscape(s) => f.write_str(s),
            Code::IntegerOutOfBounds => f.write_str("Integer is out of bounds"),
            Code::InvalidIntegerDigit { digit, base } => {
                write!(f, "Invalid digit {digit:?} for base {base} integers")
            }
            Code::NoSuchExtension(name) => write!(f, "No RON extension named {}", Name(name)),
            Code::UnclosedBlockComment => f.write_str("Unclosed block comment"),
            Code::UnderscoreAtBeginning => f.write_str("Unexpected leading underscore in a number"),
            Code::UnexpectedChar(c) => write!(f, "Unexpected char {c:?}"),
            Code::TrailingCharacters => f.write_str("Non-whitespace trailing characters"),
            Code::InvalidValueForType { expected, found } => {
                write!(f, "Expected {expected} but found {found} instead")
            }
            Code::ExpectedDifferentLength { expected, found } => {
                write!(f, "Expected {expected} but found ")?;
                match found {
                    0 => f.write_str("zero elements")?,
                    1 => f.write_str("one element")?,
                    n => write!(f, "{n} elements")?,
                }
                f.write_str(" instead")
            }
            Code::NoSuchEnumVariant {
                expected,
                found,
                outer,
            } => {
                f.write_str("Unexpected ")?;
                if outer.is_none() {
                    f.write_str("enum ")?;
                }
                write!(f, "variant named {}", Name(found))?;
                if let Some(outer) = outer {
                    write!(f, " in enum {}", Name(outer))?;
                }
                write!(f, ", {}", OneOf(expected, "variants"))
            }
            Code::NoSuchStructField {
                expected,
                found,
                outer,
            } => {
                write!(f, "Unexpected field named {}", Name(found))?;
                if let Some(outer) = outer {
                    write!(f, " in {}", Name(outer))?;
                }
                write!(f, ", {}", OneOf(expected, "fields"))
            }
            Code::MissingStructField { field, outer } => {
                write!(f, "Unexpected missing field named {}", Name(field))?;
                match outer {
                    Some(outer) => write!(f, " in {}", Name(outer)),
                    None => Ok(()),
                }
            }
            Code::DuplicateStructField { field, outer } => {
                write!(f, "Unexpected duplicate field named {}", Name(field))?;
                match outer {
                    Some(outer) => write!(f, " in {}", Name(outer)),
                    None => Ok(()),
                }
            }
            Code::TooDeep => write!(
                f,
                "brackets nested more than {} deep (a model needs fewer than 10)",
                super::MAX_DEPTH
            ),
            Code::ExpectedStructName(name) => write!(
                f,
                "Expected the explicit struct name {}, but none was found",
                Name(name)
            ),
        }
    }
}

/// The alternatives of an unknown name: "expected one of `a`, `b`, or `c` instead".
struct OneOf<'a>(&'a [&'a str], &'static str);

impl fmt::Display for OneOf<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            [] => write!(f, "there are no {}", self.1),
            [a] => write!(f, "expected {} instead", Name(a)),
            [a, b] => write!(f, "expected either {} or {} instead", Name(a), Name(b)),
            [first, middle @ .., last] => {
                write!(f, "expected one of {}", Name(first))?;
                for name in middle {
                    write!(f, ", {}", Name(name))?;
                }
                write!(f, ", or {} instead", Name(last))
            }
        }
    }
}

/// A name in backquotes; one that is not a plain identifier is written as the raw identifier
/// that would spell it (`r#a.b`), as ron does.
struct Name<'a>(&'a str);

impl fmt::Display for Name<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut chars = self.0.chars();
        let plain =
            chars.next().is_some_and(super::is_ident_start) && chars.all(super::is_ident_continue);
        if plain || self.0.is_empty() {
            write!(f, "`{}`", self.0)
        } else {
            write!(f, "`r#{}`", self.0)
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(&self.code, f)
    }
}

impl std::error::Error for Error {}

impl de::Error for Error {
    #[cold]
    fn custom<T: fmt::Display>(message: T) -> Self {
        Error::new(Code::Message(message.to_string()))
    }

    #[cold]
    fn invalid_type(unexpected: de::Unexpected, expected: &dyn de::Expected) -> Self {
        // Invalid type and invalid value read the same in a text format, as in ron.
        Self::invalid_value(unexpected, expected)
    }

    #[cold]
    fn invalid_value(unexpected: de::Unexpected, expected: &dyn de::Expected) -> Self {
        Error::new(Code::InvalidValueForType {
            expected: expected.to_string(),
            found: unexpected_text(&unexpected),
        })
    }

    #[cold]
    fn invalid_length(len: usize, expected: &dyn de::Expected) -> Self {
        Error::new(Code::ExpectedDifferentLength {
            expected: expected.to_string(),
            found: len,
        })
    }

    #[cold]
    fn unknown_variant(variant: &str, expected: &'static [&'static str]) -> Self {
        Error::new(Code::NoSuchEnumVariant {
            expected,
            found: variant.to_string(),
            outer: None,
        })
    }

    #[cold]
    fn unknown_field(field: &str, expected: &'static [&'static str]) -> Self {
        Error::new(Code::NoSuchStructField {
            expected,
            found: field.to_string(),
            outer: None,
        })
    }

    #[cold]
    fn missing_field(field: &'static str) -> Self {
        Error::new(Code::MissingStructField { field, outer: None })
    }

    #[cold]
    fn duplicate_field(field: &'static str) -> Self {
        Error::new(Code::DuplicateStructField { field, outer: None })
    }
}

/// What a value of the wrong type was, in words ("the boolean `true`").
fn unexpected_text(unexpected: &de::Unexpected) -> String {
    use de::Unexpected as U;
    match *unexpected {
        U::Bool(b) => format!("the boolean `{b}`"),
        U::Unsigned(i) => format!("the unsigned integer `{i}`"),
        U::Signed(i) => format!("the signed integer `{i}`"),
        U::Float(n) => format!("the floating point number `{n}`"),
        U::Char(c) => format!("the UTF-8 character `{c}`"),
        U::Str(s) => format!("the string {s:?}"),
        U::Bytes(b) => {
            let escaped: String = b
                .iter()
                .flat_map(|c| std::ascii::escape_default(*c))
                .map(char::from)
                .collect();
            format!("the byte string b\"{escaped}\"")
        }
        U::Unit => "a unit value".into(),
        U::Option => "an optional value".into(),
        U::NewtypeStruct => "a newtype struct".into(),
        U::Seq => "a sequence".into(),
        U::Map => "a map".into(),
        U::Enum => "an enum".into(),
        U::UnitVariant => "a unit variant".into(),
        U::NewtypeVariant => "a newtype variant".into(),
        U::TupleVariant => "a tuple variant".into(),
        U::StructVariant => "a struct variant".into(),
        U::Other(other) => other.into(),
    }
}

/// Attaches the name of the struct (or struct variant) whose fields an error is about, as
/// ron does ("Unexpected field named `colour` in `Body`").
pub(super) fn in_struct(mut error: Error, name: Option<&str>) -> Error {
    if let Code::NoSuchStructField { outer, .. }
    | Code::MissingStructField { outer, .. }
    | Code::DuplicateStructField { outer, .. } = &mut error.code
    {
        if outer.is_none() {
            *outer = name.filter(|n| !n.is_empty()).map(str::to_string);
        }
    }
    error
}
