//! The value of a numeric literal, read as Rust reads it: an integer (decimal, or with a
//! `0x`, `0o`, `0b` prefix) or a float (a `.` or an exponent), underscores ignored, then a
//! suffix (`f64`, `i32`, `u8`, …) that the caller checks.

use super::lex::{is_ident_continue, is_ident_start};

/// A numeric literal's kind, value and suffix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Number<'a> {
    /// An integer literal (no `.`, no exponent), possibly suffixed `f64` (`1f64`).
    pub integer: bool,
    /// Its value correctly rounded to an f64: infinite when it is too large for one.
    pub value: f64,
    /// For an integer, its value when it fits an i32.
    pub as_i32: Option<i32>,
    /// The suffix, empty when there is none.
    pub suffix: &'a str,
}

/// The number a literal token spells, or None when its text is no Rust numeric literal
/// (its suffix is no identifier).
pub(super) fn number(text: &str) -> Option<Number<'_>> {
    integer(text).or_else(|| float(text))
}

/// A suffix must be an identifier.
fn is_suffix(text: &str) -> bool {
    let mut chars = text.chars();
    chars.next().is_some_and(is_ident_start) && chars.all(is_ident_continue)
}

/// An integer literal, or None when `text` is a float or no literal.
fn integer(text: &str) -> Option<Number<'_>> {
    let bytes = text.as_bytes();
    let (base, mut i) = match bytes {
        [b'0', b'x', ..] => (16u32, 2),
        [b'0', b'o', ..] => (8, 2),
        [b'0', b'b', ..] => (2, 2),
        [b'0'..=b'9', ..] => (10, 0),
        _ => return None,
    };
    let mut digits: Vec<u8> = Vec::new();
    while let Some(&b) = bytes.get(i) {
        let digit = match b {
            b'0'..=b'9' => b - b'0',
            b'a'..=b'f' if base > 10 => b - b'a' + 10,
            b'A'..=b'F' if base > 10 => b - b'A' + 10,
            b'_' => {
                i += 1;
                continue;
            }
            b'.' if base == 10 => return None,
            // An exponent with digits makes a float (`1e3`); `1e` and `1e_` are integers with
            // the suffix `e` or `e_`.
            b'e' | b'E' if base == 10 => {
                let mut has_exponent = false;
                let mut after = None;
                for (j, &b) in bytes[i + 1..].iter().enumerate() {
                    match b {
                        b'_' => {}
                        b'-' | b'+' => return None,
                        b'0'..=b'9' => has_exponent = true,
                        _ => {
                            after = Some(i + 1 + j);
                            break;
                        }
                    }
                }
                match after {
                    Some(k) if has_exponent && is_suffix(&text[k..]) => return None,
                    None if has_exponent => return None,
                    _ => break,
                }
            }
            _ => break,
        };
        if u32::from(digit) >= base {
            return None;
        }
        digits.push(digit);
        i += 1;
    }
    let suffix = &text[i..];
    if digits.is_empty() || !(suffix.is_empty() || is_suffix(suffix)) {
        return None;
    }
    let first = digits.iter().position(|&d| d != 0).unwrap_or(digits.len());
    let digits = &digits[first..];
    let (value, as_i32) = integer_value(digits, base);
    Some(Number {
        integer: true,
        value,
        as_i32,
        suffix,
    })
}

/// The value of an integer written with `digits` (most significant first, no leading zero)
/// in `base`, rounded to an f64, and as an i32 when it fits one.
fn integer_value(digits: &[u8], base: u32) -> (f64, Option<i32>) {
    let bits_per_digit = match base {
        16 => 4,
        8 => 3,
        2 => 1,
        _ => 4, // 10 < 2^4
    };
    if digits.len() * bits_per_digit <= 128 {
        let n = digits
            .iter()
            .fold(0u128, |n, &d| n * u128::from(base) + u128::from(d));
        // `as` rounds to nearest, ties to even, as parsing the decimal digits would.
        return (n as f64, i32::try_from(n).ok());
    }
    if base == 10 {
        let decimal: String = digits.iter().map(|&d| char::from(b'0' + d)).collect();
        return (decimal.parse().unwrap_or(f64::INFINITY), None);
    }
    // Above 2^1100 the value is far beyond f64::MAX (2^1024).
    if digits.len() * bits_per_digit > 1100 {
        return (f64::INFINITY, None);
    }
    (
        decimal_of(digits, base).parse().unwrap_or(f64::INFINITY),
        None,
    )
}

/// The decimal digits of a number written in `base`: schoolbook conversion through limbs of
/// nine decimal digits, least significant first.
fn decimal_of(digits: &[u8], base: u32) -> String {
    const LIMB: u64 = 1_000_000_000;
    let mut limbs: Vec<u64> = Vec::new();
    for &d in digits {
        let mut carry = u64::from(d);
        for limb in &mut limbs {
            let v = *limb * u64::from(base) + carry;
            *limb = v % LIMB;
            carry = v / LIMB;
        }
        if carry > 0 {
            limbs.push(carry);
        }
    }
    let mut text = limbs.last().map_or("0".to_string(), u64::to_string);
    for limb in limbs.iter().rev().skip(1) {
        text.push_str(&format!("{limb:09}"));
    }
    text
}

/// A float literal: digits with a `.` or an exponent (`1.5`, `2.`, `1e-3`, `1_000.5E+2`),
/// underscores ignored, then a suffix.
fn float(text: &str) -> Option<Number<'_>> {
    let bytes = text.as_bytes();
    if !bytes.first()?.is_ascii_digit() {
        return None;
    }
    let mut digits = String::with_capacity(text.len());
    let mut has_dot = false;
    let mut has_e = false;
    let mut has_sign = false;
    let mut has_exponent = false;
    let mut read = 0;
    while let Some(&b) = bytes.get(read) {
        match b {
            b'_' => {}
            b'0'..=b'9' => {
                has_exponent |= has_e;
                digits.push(char::from(b));
            }
            b'.' => {
                if has_e || has_dot {
                    return None;
                }
                has_dot = true;
                digits.push('.');
            }
            b'e' | b'E' => {
                let next = bytes[read + 1..].iter().find(|&&b| b != b'_');
                if !matches!(next, Some(b'-' | b'+' | b'0'..=b'9')) {
                    break;
                }
                if has_e {
                    if has_exponent {
                        break;
                    }
                    return None;
                }
                has_e = true;
                digits.push('e');
            }
            b'-' | b'+' => {
                if has_sign || has_exponent || !has_e {
                    return None;
                }
                has_sign = true;
                if b == b'-' {
                    digits.push('-');
                }
            }
            _ => break,
        }
        read += 1;
    }
    if has_e && !has_exponent {
        return None;
    }
    let suffix = &text[read..];
    if !(suffix.is_empty() || is_suffix(suffix)) {
        return None;
    }
    Some(Number {
        integer: false,
        value: digits.parse().unwrap_or(f64::NAN),
        as_i32: None,
        suffix,
    })
}
