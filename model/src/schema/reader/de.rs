//! The serde `Deserializer` over the lexer's tokens, method by method as ron 0.12 reads
//! each kind of value.
//!
//! Positions: every token the reader looks at or consumes becomes the `mark`, the place of
//! an error raised next. Errors serde's generated code creates (a wrong type, an unknown
//! or missing field) carry no position; they are placed at the mark when they leave the
//! reader, which is then the token they are about (the value of the wrong type, the
//! unknown name, the bracket where an element is missing). A missing field is placed at
//! the opening of the struct that lacks it.

use super::MAX_DEPTH;
use super::error::{Code, Error, Place, in_struct};
use super::lexer::{Kind, Lexer, Token};
use super::number::{self, Any, Float};
use serde::Deserialize;
use serde::de::{self, DeserializeSeed, Visitor};
use std::borrow::Cow;
use std::collections::VecDeque;

pub(super) struct Reader<'s> {
    lexer: Lexer<'s>,
    /// Tokens read ahead (at most three: `(`, a name and `:` tell a struct from a tuple),
    /// or the lexer's error where a token should be.
    ahead: VecDeque<Result<Token<'s>, Error>>,
    /// End of the last token consumed.
    consumed_end: usize,
    /// The token looked at or consumed last: where an error raised now is.
    mark: Place,
    /// Brackets open around the cursor.
    depth: usize,
    /// `#![enable(unwrap_newtypes)]`: a newtype struct is written as its content.
    unwrap_newtypes: bool,
    /// `#![enable(explicit_struct_names)]`: structs must be written with their name.
    explicit_struct_names: bool,
    /// The last identifier read: the variant whose content is being read, for messages.
    last_identifier: Option<&'s str>,
}

impl<'s> Reader<'s> {
    pub(super) fn new(source: &'s str) -> Self {
        Reader {
            lexer: Lexer::new(source),
            ahead: VecDeque::new(),
            consumed_end: 0,
            mark: Place {
                start: 0,
                end: 0,
                before: 0,
            },
            depth: 0,
            unwrap_newtypes: false,
            explicit_struct_names: false,
            last_identifier: None,
        }
    }

    /// The attributes, one value of type `T`, and nothing after it.
    pub(super) fn read<T: Deserialize<'s>>(mut self) -> Result<T, Error> {
        let value = self
            .attributes()
            .and_then(|()| T::deserialize(&mut self))
            .and_then(|value| match self.peek()?.kind {
                Kind::Eof => Ok(value),
                _ => Err(self.error(Code::TrailingCharacters)),
            });
        value.map_err(|e| e.or_at(self.mark))
    }

    fn fill(&mut self, n: usize) {
        while self.ahead.len() <= n {
            let token = self.lexer.next_token();
            self.ahead.push_back(token);
        }
    }

    /// The next token, not consumed; it becomes the mark.
    fn peek(&mut self) -> Result<&Token<'s>, Error> {
        self.fill(0);
        let before = self.consumed_end;
        match &self.ahead[0] {
            Ok(token) => {
                self.mark = Place {
                    start: token.start,
                    end: token.end,
                    before,
                };
                Ok(token)
            }
            Err(e) => {
                // The lexer's error, placed after the last token consumed.
                let mut e = e.clone();
                if let Some(place) = &mut e.place {
                    place.before = before;
                    self.mark = *place;
                }
                Err(e)
            }
        }
    }

    /// The kind of the token `n` places ahead of the next one, if it was read without error.
    fn peek_kind(&mut self, n: usize) -> Option<&Kind<'s>> {
        self.fill(n);
        self.ahead[n].as_ref().ok().map(|t| &t.kind)
    }

    /// Consumes the next token.
    fn bump(&mut self) -> Result<Token<'s>, Error> {
        self.peek()?;
        match self.ahead.pop_front() {
            Some(Ok(token)) => {
                self.consumed_end = token.end;
                Ok(token)
            }
            _ => Err(self.error(Code::Eof)),
        }
    }

    fn error(&self, code: Code) -> Error {
        Error::at(code, self.mark)
    }

    fn is_punct(&mut self, c: char) -> Result<bool, Error> {
        Ok(self.peek()?.kind == Kind::Punct(c))
    }

    fn eat_punct(&mut self, c: char) -> Result<bool, Error> {
        let found = self.is_punct(c)?;
        if found {
            self.bump()?;
        }
        Ok(found)
    }

    fn expect_punct(&mut self, c: char, code: Code) -> Result<(), Error> {
        if self.eat_punct(c)? {
            Ok(())
        } else {
            Err(self.error(code))
        }
    }

    /// The name of the next token if it is a plain (not raw) identifier.
    fn peek_keyword(&mut self) -> Result<Option<&'s str>, Error> {
        Ok(match self.peek()?.kind {
            Kind::Ident { name, raw: false } => Some(name),
            _ => None,
        })
    }

    /// Opens one more level of brackets.
    fn enter(&mut self) -> Result<(), Error> {
        if self.depth >= MAX_DEPTH {
            return Err(self.error(Code::TooDeep));
        }
        self.depth += 1;
        Ok(())
    }

    fn leave(&mut self) {
        self.depth = self.depth.saturating_sub(1);
    }

    /// `#![enable(…)]` and `#![type = "…"]` attributes at the start of the text.
    fn attributes(&mut self) -> Result<(), Error> {
        while self.eat_punct('#')? {
            self.expect_punct('!', Code::ExpectedAttribute)?;
            self.expect_punct('[', Code::ExpectedAttribute)?;
            match self.peek_keyword()? {
                Some("enable") => {
                    self.bump()?;
                    self.expect_punct('(', Code::ExpectedAttribute)?;
                    self.extensions()?;
                    self.expect_punct(')', Code::ExpectedAttributeEnd)?;
                    self.expect_punct(']', Code::ExpectedAttributeEnd)?;
                }
                Some("type" | "schema") => {
                    self.bump()?;
                    self.expect_punct('=', Code::ExpectedAttribute)?;
                    if !matches!(self.peek()?.kind, Kind::Str(_)) {
                        return Err(self.error(Code::ExpectedString));
                    }
                    self.bump()?;
                    self.expect_punct(']', Code::ExpectedAttributeEnd)?;
                }
                _ => return Err(self.error(Code::ExpectedAttribute)),
            }
        }
        Ok(())
    }

    /// The names inside `#![enable(…)]`, comma-separated.
    fn extensions(&mut self) -> Result<(), Error> {
        loop {
            let Kind::Ident { name, .. } = self.peek()?.kind else {
                return Err(self.error(Code::ExpectedIdentifier));
            };
            match name {
                // On by default.
                "implicit_some" => {}
                "unwrap_newtypes" => self.unwrap_newtypes = true,
                "explicit_struct_names" => self.explicit_struct_names = true,
                // No newtype variant of the schema holds a struct or a tuple, which is all
                // this extension changes.
                "unwrap_variant_newtypes" => {}
                other => return Err(self.error(Code::NoSuchExtension(other.to_string()))),
            }
            self.bump()?;
            let comma = self.eat_punct(',')?;
            let another = matches!(self.peek()?.kind, Kind::Ident { .. });
            if !comma && another {
                return Err(self.error(Code::ExpectedComma));
            }
            if !comma || !another {
                return Ok(());
            }
        }
    }

    /// A struct's optional name before its `(`: true when written (it must be `name`).
    fn struct_name(&mut self, name: &'static str) -> Result<bool, Error> {
        let Kind::Ident { name: found, .. } = self.peek()?.kind else {
            if self.explicit_struct_names {
                return Err(self.error(Code::ExpectedStructName(name)));
            }
            return Ok(false);
        };
        if name.is_empty() {
            return Err(self.error(Code::ExpectedNamedStructLike(name)));
        }
        self.bump()?;
        if found != name {
            return Err(self.error(Code::ExpectedDifferentStructName {
                expected: name,
                found: found.to_string(),
            }));
        }
        Ok(true)
    }

    /// `(field: value, …)` after a struct's name, if any; `outer` names the struct in
    /// messages about its fields.
    fn struct_body<V: Visitor<'s>>(
        &mut self,
        name: &'static str,
        outer: Option<&str>,
        visitor: V,
    ) -> Result<V::Value, Error> {
        if !self.is_punct('(')? {
            return Err(self.error(if name.is_empty() {
                Code::ExpectedStructLike
            } else {
                Code::ExpectedNamedStructLike(name)
            }));
        }
        let open = self.mark;
        self.bump()?;
        self.enter()?;
        let value = visitor
            .visit_map(Separated::new(self, ')', true))
            .map_err(|e| {
                let e = in_struct(e, outer);
                match e.code {
                    // Reported at the opening of the struct that lacks it.
                    Code::MissingStructField { .. } => e.or_at(open),
                    _ => e,
                }
            })?;
        self.leave();
        self.expect_punct(')', Code::ExpectedStructLikeEnd)?;
        Ok(value)
    }

    /// A value of unknown type that starts with a name (consumed) or `(`: a unit, tuple or
    /// named struct, or an enum variant.
    fn any_struct<V: Visitor<'s>>(&mut self, visitor: V) -> Result<V::Value, Error> {
        if !self.is_punct('(')? {
            return visitor.visit_unit();
        }
        let named = matches!(self.peek_kind(1), Some(Kind::Ident { .. }))
            && matches!(self.peek_kind(2), Some(Kind::Punct(':')));
        if named {
            self.struct_body("", None, visitor)
        } else {
            de::Deserializer::deserialize_tuple(self, 0, visitor)
        }
    }

    /// The value of an integer token (or a byte literal).
    fn integer(&mut self) -> Result<Any, Error> {
        let value = match self.peek()?.kind {
            Kind::Number(text) => number::integer(text),
            Kind::Byte(b) => Ok(Any::Unsigned(b.into())),
            _ => Err(Code::ExpectedInteger),
        };
        let value = value.map_err(|code| self.error(code))?;
        self.bump()?;
        Ok(value)
    }

    /// The value and text of a float token (a number, `inf` or `NaN`).
    fn float(&mut self) -> Result<(Float, &'s str), Error> {
        let text = match self.peek()?.kind {
            Kind::Number(text)
            | Kind::Ident {
                name: text,
                raw: false,
            } => text,
            _ => return Err(self.error(Code::ExpectedFloat)),
        };
        let value = number::float(text).map_err(|code| self.error(code))?;
        self.bump()?;
        Ok((value, text))
    }
}

fn visit_number<'s, V: Visitor<'s>>(value: Any, visitor: V) -> Result<V::Value, Error> {
    match value {
        Any::Signed(v) => visitor.visit_i64(v),
        Any::Unsigned(v) => visitor.visit_u64(v),
        Any::F32(v) => visitor.visit_f32(v),
        Any::F64(v) => visitor.visit_f64(v),
    }
}

fn visit_text<'s, V: Visitor<'s>>(text: Cow<'s, str>, visitor: V) -> Result<V::Value, Error> {
    match text {
        Cow::Borrowed(s) => visitor.visit_borrowed_str(s),
        Cow::Owned(s) => visitor.visit_string(s),
    }
}

impl<'s> de::Deserializer<'s> for &mut Reader<'s> {
    type Error = Error;

    fn deserialize_any<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        let token = self.peek()?;
        let end = token.end;
        match token.kind {
            Kind::Ident { name, raw: false } => match name {
                "true" | "false" => {
                    self.bump()?;
                    visitor.visit_bool(name == "true")
                }
                "Some" => self.deserialize_option(visitor),
                "None" => {
                    self.bump()?;
                    visitor.visit_none()
                }
                "inf" | "inff32" | "NaN" | "NaNf32" | "inff64" | "NaNf64" => {
                    let (value, _) = self.float()?;
                    match value {
                        Float::Plain(v) => visitor.visit_f32(v as f32),
                        Float::F32(v) => visitor.visit_f32(v),
                        Float::F64(v) => visitor.visit_f64(v),
                    }
                }
                _ => {
                    self.bump()?;
                    self.last_identifier = Some(name);
                    self.any_struct(visitor)
                }
            },
            Kind::Ident { name, raw: true } => {
                self.bump()?;
                self.last_identifier = Some(name);
                self.any_struct(visitor)
            }
            Kind::Punct('(') => {
                // `()` written without a blank inside is the unit value, as in ron.
                let unit = matches!(self.peek_kind(1), Some(Kind::Punct(')')))
                    && self
                        .ahead
                        .get(1)
                        .and_then(|t| t.as_ref().ok())
                        .map(|t| t.start)
                        == Some(end);
                if unit {
                    self.bump()?;
                    self.bump()?;
                    return visitor.visit_unit();
                }
                self.any_struct(visitor)
            }
            Kind::Punct('[') => self.deserialize_seq(visitor),
            Kind::Punct('{') => self.deserialize_map(visitor),
            Kind::Number(text) => {
                let value = number::any(text).map_err(|code| self.error(code))?;
                self.bump()?;
                visit_number(value, visitor)
            }
            Kind::Punct(c) => Err(self.error(Code::UnexpectedChar(c))),
            Kind::Eof => Err(self.error(Code::Eof)),
            Kind::Str(_) | Kind::Char(_) | Kind::Byte(_) | Kind::Bytes(_) => {
                match self.bump()?.kind {
                    Kind::Str(text) => visit_text(text, visitor),
                    Kind::Char(c) => visitor.visit_char(c),
                    Kind::Byte(b) => visitor.visit_u8(b),
                    Kind::Bytes(Cow::Borrowed(b)) => visitor.visit_borrowed_bytes(b),
                    Kind::Bytes(Cow::Owned(b)) => visitor.visit_byte_buf(b),
                    _ => Err(self.error(Code::Eof)),
                }
            }
        }
    }

    fn deserialize_bool<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        match self.peek_keyword()? {
            Some(name @ ("true" | "false")) => {
                self.bump()?;
                visitor.visit_bool(name == "true")
            }
            _ => Err(self.error(Code::ExpectedBoolean)),
        }
    }

    fn deserialize_i64<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        let value = self.integer()?;
        visit_number(value, visitor)
    }

    fn deserialize_u64<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        self.deserialize_i64(visitor)
    }

    fn deserialize_i8<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        self.deserialize_i64(visitor)
    }

    fn deserialize_i16<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        self.deserialize_i64(visitor)
    }

    fn deserialize_i32<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        self.deserialize_i64(visitor)
    }

    fn deserialize_u8<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        self.deserialize_i64(visitor)
    }

    fn deserialize_u16<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        self.deserialize_i64(visitor)
    }

    fn deserialize_u32<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        self.deserialize_i64(visitor)
    }

    fn deserialize_f32<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        match self.float()? {
            (Float::Plain(v), _) => visitor.visit_f32(v as f32),
            (Float::F32(v), _) => visitor.visit_f32(v),
            (Float::F64(_), text) => Err(self.error(Code::InvalidValueForType {
                expected: "a 32-bit floating point number".into(),
                found: text.into(),
            })),
        }
    }

    fn deserialize_f64<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        match self.float()? {
            (Float::Plain(v) | Float::F64(v), _) => visitor.visit_f64(v),
            (Float::F32(_), text) => Err(self.error(Code::InvalidValueForType {
                expected: "a 64-bit floating point number".into(),
                found: text.into(),
            })),
        }
    }

    fn deserialize_char<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        match self.peek()?.kind {
            Kind::Char(c) => {
                self.bump()?;
                visitor.visit_char(c)
            }
            _ => Err(self.error(Code::ExpectedChar)),
        }
    }

    fn deserialize_str<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        if !matches!(self.peek()?.kind, Kind::Str(_)) {
            return Err(self.error(Code::ExpectedString));
        }
        match self.bump()?.kind {
            Kind::Str(text) => visit_text(text, visitor),
            _ => Err(self.error(Code::ExpectedString)),
        }
    }

    fn deserialize_string<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        self.deserialize_str(visitor)
    }

    fn deserialize_bytes<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        self.deserialize_byte_buf(visitor)
    }

    fn deserialize_byte_buf<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        if self.is_punct('[')? {
            let bytes = Vec::<u8>::deserialize(&mut *self)?;
            return visitor.visit_byte_buf(bytes);
        }
        if !matches!(self.peek()?.kind, Kind::Bytes(_)) {
            return Err(self.error(Code::ExpectedByteString));
        }
        match self.bump()?.kind {
            Kind::Bytes(Cow::Borrowed(b)) => visitor.visit_borrowed_bytes(b),
            Kind::Bytes(Cow::Owned(b)) => visitor.visit_byte_buf(b),
            _ => Err(self.error(Code::ExpectedByteString)),
        }
    }

    fn deserialize_option<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        match self.peek_keyword()? {
            Some("None") => {
                self.bump()?;
                return visitor.visit_none();
            }
            Some("Some") => {
                self.bump()?;
                if self.eat_punct('(')? {
                    self.enter()?;
                    let value = visitor.visit_some(&mut *self)?;
                    self.leave();
                    self.eat_punct(',')?;
                    self.expect_punct(')', Code::ExpectedOptionEnd)?;
                    return Ok(value);
                }
                // `Some` without `(`: ron goes on as if it had not been there.
            }
            _ => {}
        }
        // `implicit_some`: a bare value is `Some(value)`.
        visitor.visit_some(self)
    }

    fn deserialize_unit<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        let open = self.peek()?.end;
        let adjacent = self.is_punct('(')?
            && matches!(self.peek_kind(1), Some(Kind::Punct(')')))
            && self
                .ahead
                .get(1)
                .and_then(|t| t.as_ref().ok())
                .map(|t| t.start)
                == Some(open);
        if !adjacent {
            return Err(self.error(Code::ExpectedUnit));
        }
        self.bump()?;
        self.bump()?;
        visitor.visit_unit()
    }

    fn deserialize_unit_struct<V: Visitor<'s>>(
        self,
        name: &'static str,
        visitor: V,
    ) -> Result<V::Value, Error> {
        if self.struct_name(name)? {
            visitor.visit_unit()
        } else {
            self.deserialize_unit(visitor)
        }
    }

    fn deserialize_newtype_struct<V: Visitor<'s>>(
        self,
        name: &'static str,
        visitor: V,
    ) -> Result<V::Value, Error> {
        if self.unwrap_newtypes {
            return visitor.visit_newtype_struct(self);
        }
        self.struct_name(name)?;
        if !self.eat_punct('(')? {
            return Err(self.error(if name.is_empty() {
                Code::ExpectedStructLike
            } else {
                Code::ExpectedNamedStructLike(name)
            }));
        }
        self.enter()?;
        let value = visitor.visit_newtype_struct(&mut *self)?;
        self.leave();
        self.eat_punct(',')?;
        self.expect_punct(')', Code::ExpectedStructLikeEnd)?;
        Ok(value)
    }

    fn deserialize_seq<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        if !self.eat_punct('[')? {
            return Err(self.error(Code::ExpectedArray));
        }
        self.enter()?;
        let value = visitor.visit_seq(Separated::new(self, ']', false))?;
        self.leave();
        self.expect_punct(']', Code::ExpectedArrayEnd)?;
        Ok(value)
    }

    fn deserialize_tuple<V: Visitor<'s>>(self, _len: usize, visitor: V) -> Result<V::Value, Error> {
        if !self.eat_punct('(')? {
            return Err(self.error(Code::ExpectedStructLike));
        }
        self.enter()?;
        let value = visitor.visit_seq(Separated::new(self, ')', false))?;
        self.leave();
        self.expect_punct(')', Code::ExpectedStructLikeEnd)?;
        Ok(value)
    }

    fn deserialize_tuple_struct<V: Visitor<'s>>(
        self,
        name: &'static str,
        len: usize,
        visitor: V,
    ) -> Result<V::Value, Error> {
        self.struct_name(name)?;
        self.deserialize_tuple(len, visitor)
            .map_err(|e| match e.code {
                Code::ExpectedStructLike if !name.is_empty() => Error {
                    code: Code::ExpectedNamedStructLike(name),
                    ..e
                },
                _ => e,
            })
    }

    fn deserialize_map<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        if !self.eat_punct('{')? {
            return Err(self.error(Code::ExpectedMap));
        }
        self.enter()?;
        let value = visitor.visit_map(Separated::new(self, '}', false))?;
        self.leave();
        self.expect_punct('}', Code::ExpectedMapEnd)?;
        Ok(value)
    }

    fn deserialize_struct<V: Visitor<'s>>(
        self,
        name: &'static str,
        _fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, Error> {
        self.struct_name(name)?;
        self.struct_body(name, Some(name), visitor)
    }

    fn deserialize_enum<V: Visitor<'s>>(
        self,
        name: &'static str,
        _variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, Error> {
        self.enter()?;
        let value = visitor.visit_enum(Enum { reader: self }).map_err(|mut e| {
            if let Code::NoSuchEnumVariant { outer, .. } = &mut e.code {
                if outer.is_none() && !name.is_empty() {
                    *outer = Some(name.to_string());
                }
            }
            e
        })?;
        self.leave();
        Ok(value)
    }

    fn deserialize_identifier<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        let Kind::Ident { name, .. } = self.peek()?.kind else {
            return Err(self.error(Code::ExpectedIdentifier));
        };
        self.bump()?;
        self.last_identifier = Some(name);
        visitor.visit_borrowed_str(name)
    }

    fn deserialize_ignored_any<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        self.deserialize_any(visitor)
    }
}

/// The elements of a list, tuple, map or struct, separated by commas (a trailing one
/// allowed), up to the closing bracket, which is left for the caller.
struct Separated<'r, 's> {
    reader: &'r mut Reader<'s>,
    close: char,
    had_comma: bool,
    /// A struct's keys are field names (identifiers); a map's are values.
    field_names: bool,
}

impl<'r, 's> Separated<'r, 's> {
    fn new(reader: &'r mut Reader<'s>, close: char, field_names: bool) -> Self {
        Separated {
            reader,
            close,
            had_comma: true,
            field_names,
        }
    }

    fn has_element(&mut self) -> Result<bool, Error> {
        let at_close = self.reader.is_punct(self.close)?;
        match (self.had_comma, at_close) {
            (true, at_close) => Ok(!at_close),
            (false, true) => Ok(false),
            (false, false) => Err(self.reader.error(Code::ExpectedComma)),
        }
    }
}

impl<'s> de::SeqAccess<'s> for Separated<'_, 's> {
    type Error = Error;

    fn next_element_seed<T: DeserializeSeed<'s>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Error> {
        if !self.has_element()? {
            return Ok(None);
        }
        let value = seed.deserialize(&mut *self.reader)?;
        self.had_comma = self.reader.eat_punct(',')?;
        Ok(Some(value))
    }
}

impl<'s> de::MapAccess<'s> for Separated<'_, 's> {
    type Error = Error;

    fn next_key_seed<K: DeserializeSeed<'s>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, Error> {
        if !self.has_element()? {
            return Ok(None);
        }
        if self.field_names {
            seed.deserialize(FieldName(&mut *self.reader)).map(Some)
        } else {
            seed.deserialize(&mut *self.reader).map(Some)
        }
    }

    fn next_value_seed<V: DeserializeSeed<'s>>(&mut self, seed: V) -> Result<V::Value, Error> {
        self.reader.expect_punct(':', Code::ExpectedMapColon)?;
        let value = seed.deserialize(&mut *self.reader)?;
        self.had_comma = self.reader.eat_punct(',')?;
        Ok(value)
    }
}

/// A struct's field name: an identifier, whatever type serde asks for.
struct FieldName<'r, 's>(&'r mut Reader<'s>);

impl<'s> de::Deserializer<'s> for FieldName<'_, 's> {
    type Error = Error;

    fn deserialize_any<V: Visitor<'s>>(self, visitor: V) -> Result<V::Value, Error> {
        de::Deserializer::deserialize_identifier(self.0, visitor)
    }

    serde::forward_to_deserialize_any! {
        <W: Visitor<'s>>
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf option unit unit_struct newtype_struct seq tuple
        tuple_struct map struct enum identifier ignored_any
    }
}

/// An enum value: the variant's name, then its content.
struct Enum<'r, 's> {
    reader: &'r mut Reader<'s>,
}

impl<'r, 's> de::EnumAccess<'s> for Enum<'r, 's> {
    type Error = Error;
    type Variant = Self;

    fn variant_seed<V: DeserializeSeed<'s>>(self, seed: V) -> Result<(V::Value, Self), Error> {
        let value = seed.deserialize(&mut *self.reader)?;
        Ok((value, self))
    }
}

impl<'s> de::VariantAccess<'s> for Enum<'_, 's> {
    type Error = Error;

    fn unit_variant(self) -> Result<(), Error> {
        Ok(())
    }

    fn newtype_variant_seed<T: DeserializeSeed<'s>>(self, seed: T) -> Result<T::Value, Error> {
        let reader = self.reader;
        let variant = reader.last_identifier;
        if !reader.eat_punct('(')? {
            return Err(reader.error(Code::ExpectedStructLike));
        }
        reader.enter()?;
        let value = seed
            .deserialize(&mut *reader)
            .map_err(|e| in_struct(e, variant))?;
        reader.leave();
        reader.eat_punct(',')?;
        reader.expect_punct(')', Code::ExpectedStructLikeEnd)?;
        Ok(value)
    }

    fn tuple_variant<V: Visitor<'s>>(self, len: usize, visitor: V) -> Result<V::Value, Error> {
        de::Deserializer::deserialize_tuple(self.reader, len, visitor)
    }

    fn struct_variant<V: Visitor<'s>>(
        self,
        _fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, Error> {
        let variant = self.reader.last_identifier;
        self.reader.struct_body("", variant, visitor)
    }
}
