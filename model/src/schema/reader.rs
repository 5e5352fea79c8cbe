//! A reader of RON text that drives serde's generated code directly, token by token, as ron
//! 0.12 does: [`from_str`] is `ron::Options::default()` with `implicit_some` on,
//! `.from_str()`, for the types of [`super::raw`].
//!
//! Hand-written rather than ron itself because ron brings four crates into every program
//! that reads model files at run time (ron, bitflags, typeid, unicode-ident: the `reference`
//! feature of the `camchain` facade), and because it locates errors only by line and
//! column of where its cursor stopped, which [`super::Locator`] then had to re-scan to find
//! the offending token. Here every error carries the byte range of the token it is about
//! and the end of the value before it ([`Place`]).
//!
//! The grammar is ron's (`docs/grammar.md` of ron 0.12): `//` and nestable `/* */`
//! comments; identifiers, raw identifiers `r#name`; booleans; integers in bases 2, 8, 10
//! and 16 with `_` and `i8`…`u64` suffixes; floats with exponents, `inf`, `NaN` and `f32`/
//! `f64` suffixes; strings with escapes (`\n`, `\x7F`, `\u{1F600}`, line continuations) and
//! raw strings `r#"…"#`; characters; byte literals `b'a'` and byte strings `b"…"`; `Some(…)`,
//! `None`, `()`, tuples, lists, maps, structs with or without their name, and enum variants
//! (unit, tuple, struct). Optional values may be written bare (ron's `implicit_some`,
//! always on). A file may start with `#![enable(…)]` (`implicit_some`,
//! `explicit_struct_names`, and `unwrap_newtypes` and `unwrap_variant_newtypes`, which
//! change nothing for the schema's types: it has no newtype struct, and its only newtype
//! variant, `Izz(…)`, holds a number) and `#![type = "…"]` attributes. Ranges (`1..2`) are
//! not read: no field of the schema is one.
//!
//! Messages are ron's for the same situations ("Expected comma", "Unexpected field named
//! `colour` in `Body`, expected one of …"). Brackets nest at most [`MAX_DEPTH`] deep, so
//! no text can exhaust the stack; the lexer advances by whole characters, so no byte
//! sequence can make it panic, and each token costs time linear in its length.

mod de;
#[cfg(test)]
mod differential;
mod error;
#[cfg(test)]
mod generate;
mod lexer;
mod number;
#[cfg(test)]
mod tests;

pub(super) use error::{Code, Error, Place};

use serde::Deserialize;

/// The deepest nesting of brackets (and `Some(`) read; a model needs fewer than 10. ron's
/// default recursion limit is also 128 (it counts serde calls, a few per bracket).
pub(super) const MAX_DEPTH: usize = 128;

/// Reads one value of type `T` from the whole of `source` (after its `#![…]` attributes).
pub(super) fn from_str<'s, T: Deserialize<'s>>(source: &'s str) -> Result<T, Error> {
    de::Reader::new(source).read()
}

/// First character of an identifier. ron uses Unicode's XID_Start; the standard library's
/// Alphabetic property is the same for every ASCII character and close elsewhere (the
/// schema's names are ASCII, so any other identifier is refused either way).
fn is_ident_start(c: char) -> bool {
    c == '_' || c.is_alphabetic()
}

/// Further characters of an identifier (XID_Continue in ron; see [`is_ident_start`]).
fn is_ident_continue(c: char) -> bool {
    c == '_' || c.is_alphanumeric()
}
