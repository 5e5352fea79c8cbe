//! The value of a number token, by ron 0.12's rules: what a field of type `f64` accepts
//! ([`float`]: decimal digits, `.`, an exponent, `_` between digits, an `f32`/`f64` suffix,
//! `inf` and `NaN`), and what a field of any number type accepts ([`any`]: the same, and
//! integers in bases 2, 8, 10 and 16 with an `i8`…`u64` suffix; an integer too large for
//! 64 bits is read as a float).
//!
//! The lexer hands over the whole run of number characters (`1.5kg` is one token), and a
//! number is only accepted when all of it is one: where ron reads a prefix and then fails at
//! the rest, this fails at once, at the same token.

use super::error::Code;

/// A number read where any type may be.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Any {
    Signed(i64),
    Unsigned(u64),
    F32(f32),
    F64(f64),
}

/// A number read where a float is expected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Float {
    /// Written without a suffix.
    Plain(f64),
    /// With the suffix `f32`.
    F32(f32),
    /// With the suffix `f64`.
    F64(f64),
}

/// The signed literals `inf` and `NaN` are written as identifiers without a sign.
const SPECIAL: [(&str, f64); 6] = [
    ("inf", f64::INFINITY),
    ("+inf", f64::INFINITY),
    ("-inf", f64::NEG_INFINITY),
    ("NaN", f64::NAN),
    ("+NaN", f64::NAN),
    ("-NaN", f64::NAN),
];

/// `text` (a number token, or an identifier such as `inf` or `NaNf64`) as a float.
pub(super) fn float(text: &str) -> Result<Float, Code> {
    for (literal, value) in SPECIAL {
        if let Some(suffix) = text.strip_prefix(literal) {
            let value = if literal == "-NaN" { -value } else { value };
            return match suffix {
                "" => Ok(Float::Plain(value)),
                "f32" => Ok(Float::F32(value as f32)),
                "f64" => Ok(Float::F64(value)),
                _ => Err(Code::ExpectedFloat),
            };
        }
    }
    let unsigned = text.strip_prefix(['+', '-']).unwrap_or(text);
    let sign = text.len() - unsigned.len();
    // The characters ron reads as a float, up to a range's `..`.
    let run = sign
        + unsigned
            .find(|c: char| !(c.is_ascii_digit() || matches!(c, 'e' | 'E' | '.' | '+' | '-' | '_')))
            .unwrap_or(unsigned.len());
    let run = text[..run].find("..").unwrap_or(run);
    if run == 0 {
        return Err(Code::ExpectedFloat);
    }
    let mut cleaned = String::with_capacity(run);
    let mut underscore_allowed = false;
    for c in text[..run].chars() {
        match c {
            '_' if underscore_allowed => continue,
            '_' => return Err(Code::FloatUnderscore),
            '0'..='9' | 'e' | 'E' => underscore_allowed = true,
            '.' => underscore_allowed = false,
            _ => {}
        }
        cleaned.push(c);
    }
    let parsed = match &text[run..] {
        "" => cleaned.parse().map(Float::Plain).ok(),
        "f32" => cleaned.parse().map(Float::F32).ok(),
        "f64" => cleaned.parse().map(Float::F64).ok(),
        _ => None,
    };
    parsed.ok_or(Code::ExpectedFloat)
}

/// `text` (a number token) where any number may be: an integer when it is written as one
/// (`-0` is the integer 0, not −0.0), otherwise a float.
pub(super) fn any(text: &str) -> Result<Any, Code> {
    match integer(text) {
        Ok(value) => Ok(value),
        // An integer too large for 64 bits is read as a float, as ron does; anything else
        // that is not an integer may still be a float (`1e5`, `2.5`, `1f32`).
        Err(integer_error) => match float(text) {
            Ok(Float::Plain(v) | Float::F64(v)) => Ok(Any::F64(v)),
            Ok(Float::F32(v)) => Ok(Any::F32(v)),
            Err(float_error) => Err(if looks_like_float(text) {
                float_error
            } else {
                integer_error
            }),
        },
    }
}

/// True when ron would read `text` as a float rather than an integer: its float characters
/// run further than its integer ones.
fn looks_like_float(text: &str) -> bool {
    let unsigned = text.strip_prefix(['+', '-']).unwrap_or(text);
    let float_run = unsigned
        .find(|c: char| !(c.is_ascii_digit() || matches!(c, 'e' | 'E' | '.' | '+' | '-' | '_')))
        .unwrap_or(unsigned.len());
    let float_run = unsigned[..float_run].find("..").unwrap_or(float_run);
    let integer_run = unsigned
        .find(|c: char| !(c.is_ascii_hexdigit() || c == '_'))
        .unwrap_or(unsigned.len());
    float_run > integer_run
}

/// `text` as an integer: sign, base prefix (`0b`, `0o`, `0x`), digits with `_` after the
/// first, and an optional suffix `i8`…`i64` or `u8`…`u64` that bounds it.
pub(super) fn integer(text: &str) -> Result<Any, Code> {
    let (negative, unsigned) = match text.as_bytes().first() {
        Some(b'-') => (true, &text[1..]),
        Some(b'+') => (false, &text[1..]),
        _ => (false, text),
    };
    let (base, body) = if let Some(b) = unsigned.strip_prefix("0b") {
        (2, b)
    } else if let Some(b) = unsigned.strip_prefix("0o") {
        (8, b)
    } else if let Some(b) = unsigned.strip_prefix("0x") {
        (16, b)
    } else {
        (10, unsigned)
    };
    let digits_len = body
        .find(|c: char| !(c.is_ascii_hexdigit() || c == '_'))
        .unwrap_or(body.len());
    let (digits, suffix) = body.split_at(digits_len);
    if digits.is_empty() {
        return Err(Code::ExpectedInteger);
    }
    if digits.starts_with('_') {
        return Err(Code::UnderscoreAtBeginning);
    }
    // Bounds of the suffix's type, as (least, greatest) in i128.
    let bounds: (i128, i128) = match suffix {
        "" if negative => (i64::MIN.into(), 0),
        "" => (0, u64::MAX.into()),
        "i8" => (i8::MIN.into(), i8::MAX.into()),
        "i16" => (i16::MIN.into(), i16::MAX.into()),
        "i32" => (i32::MIN.into(), i32::MAX.into()),
        "i64" => (i64::MIN.into(), i64::MAX.into()),
        "u8" => (0, u8::MAX.into()),
        "u16" => (0, u16::MAX.into()),
        "u32" => (0, u32::MAX.into()),
        "u64" => (0, u64::MAX.into()),
        _ => return Err(Code::ExpectedInteger),
    };
    let mut value: i128 = 0;
    for c in digits.chars() {
        if c == '_' {
            continue;
        }
        let digit = c.to_digit(16).unwrap_or(16);
        if digit >= base {
            return Err(Code::InvalidIntegerDigit { digit: c, base });
        }
        let digit = i128::from(digit);
        value = value
            .checked_mul(i128::from(base))
            .and_then(|v| {
                if negative {
                    v.checked_sub(digit)
                } else {
                    v.checked_add(digit)
                }
            })
            .filter(|v| (bounds.0..=bounds.1).contains(v))
            .ok_or(Code::IntegerOutOfBounds)?;
    }
    let signed = negative || suffix.starts_with('i');
    Ok(if signed {
        Any::Signed(i64::try_from(value).map_err(|_| Code::IntegerOutOfBounds)?)
    } else {
        Any::Unsigned(u64::try_from(value).map_err(|_| Code::IntegerOutOfBounds)?)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_follow_ron() {
        let plain = |t: &str| match float(t) {
            Ok(Float::Plain(v)) => Some(v),
            _ => None,
        };
        assert_eq!(plain("1"), Some(1.0));
        assert_eq!(plain("-0").map(f64::is_sign_negative), Some(true));
        assert_eq!(plain("1_000.5"), Some(1000.5));
        assert_eq!(plain("1e_5"), Some(1e5));
        assert_eq!(plain(".5"), Some(0.5));
        assert_eq!(plain("5."), Some(5.0));
        assert_eq!(plain("+2.5e-3"), Some(2.5e-3));
        assert_eq!(plain("-inf"), Some(f64::NEG_INFINITY));
        assert!(plain("NaN").is_some_and(f64::is_nan));
        assert_eq!(float("1f32"), Ok(Float::F32(1.0)));
        assert_eq!(float("inff64"), Ok(Float::F64(f64::INFINITY)));
        assert_eq!(float("1._5"), Err(Code::FloatUnderscore));
        for bad in [
            "0x10", "5u8", "1.5kg", "1..2", "1e", "1.2.3", "infinity", "1f16",
        ] {
            assert!(float(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn any_number_prefers_integers_and_falls_back_to_floats() {
        assert_eq!(any("5"), Ok(Any::Unsigned(5)));
        assert_eq!(any("-0"), Ok(Any::Signed(0)));
        assert_eq!(any("0x1F"), Ok(Any::Unsigned(31)));
        assert_eq!(any("0b1_01"), Ok(Any::Unsigned(5)));
        assert_eq!(any("0o17"), Ok(Any::Unsigned(15)));
        assert_eq!(any("0x1f32"), Ok(Any::Unsigned(0x1f32)));
        assert_eq!(any("-5i8"), Ok(Any::Signed(-5)));
        assert_eq!(any("255u8"), Ok(Any::Unsigned(255)));
        assert_eq!(any("1e5"), Ok(Any::F64(1e5)));
        assert_eq!(any("5f32"), Ok(Any::F32(5.0)));
        assert_eq!(
            any("18446744073709551616"),
            Ok(Any::F64(18446744073709551616.0))
        );
        assert_eq!(any("-9223372036854775808"), Ok(Any::Signed(i64::MIN)));
        assert_eq!(any("256u8"), Err(Code::IntegerOutOfBounds));
        assert_eq!(any("-1u8"), Err(Code::IntegerOutOfBounds));
        assert_eq!(any("0x"), Err(Code::ExpectedInteger));
        assert_eq!(any("0x_1"), Err(Code::UnderscoreAtBeginning));
        assert_eq!(
            any("0b2"),
            Err(Code::InvalidIntegerDigit {
                digit: '2',
                base: 2
            })
        );
        assert_eq!(any("0xFFFFFFFFFFFFFFFFFF"), Err(Code::IntegerOutOfBounds));
        assert_eq!(any("1.5.5"), Err(Code::ExpectedFloat));
    }
}
