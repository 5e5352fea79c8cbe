//! Tests of the reader on its own: hostile input (random bytes, truncated files, deep
//! nesting, long texts), positions of errors, and the literal forms. The comparison with ron
//! is in `differential.rs`.

use super::super::{Locator, raw};
use super::differential::repository_models;
use super::{Code, Error, MAX_DEPTH, from_str};
use proptest::prelude::*;
use serde::de::IgnoredAny;
use std::path::Path;

/// Reads `text` as a model; on an error, checks that it is placed inside the text and that
/// the located message points at a line and column of the text.
fn read_and_locate(text: &str) -> Result<raw::Model, Error> {
    let result = from_str::<raw::Model>(text);
    if let Err(e) = &result {
        let place = e.place.unwrap_or_else(|| panic!("{e} has no position"));
        assert!(
            place.before <= place.start && place.start <= place.end && place.end <= text.len(),
            "{place:?} in {} bytes",
            text.len()
        );
        let located = Locator::new(Path::new("t.ron"), text).syntax_error(e);
        let lines = text.split('\n').count();
        assert!((1..=lines).contains(&located.line), "{located}");
        let width = text
            .split('\n')
            .nth(located.line - 1)
            .map_or(0, |l| l.chars().count());
        assert!((1..=width + 1).contains(&located.column), "{located}");
        assert!(!located.message.is_empty() && !located.field.is_empty());
    }
    result
}

/// Pieces of RON, troublesome ones included, for token soup.
const PIECES: &[&str] = &[
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    ",",
    ":",
    "\"",
    "'",
    "\\",
    "//",
    "/*",
    "*/",
    "\n",
    " ",
    "#",
    "!",
    "r#",
    "r#\"",
    "\"#",
    "b'",
    "b\"",
    "br#\"",
    "\\u{",
    "\\x",
    "é",
    "\u{2028}",
    "Some",
    "None",
    "true",
    "inf",
    "-",
    "+",
    ".",
    "0x",
    "1",
    "2.5",
    "e",
    "_",
    "bodies",
    "name",
    "mass",
    "Izz",
    "Full",
    "#![enable(",
    "implicit_some",
    "explicit_struct_names",
    "Model",
    "\"q\"",
];

proptest! {
    #![proptest_config(ProptestConfig { cases: 4000, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_are_read_or_refused_with_a_position(
        bytes in prop::collection::vec(any::<u8>(), 0..400)
    ) {
        let text = String::from_utf8_lossy(&bytes);
        let _ = read_and_locate(&text);
        let _ = from_str::<IgnoredAny>(&text);
    }

    #[test]
    fn token_soup_is_read_or_refused_with_a_position(
        pieces in prop::collection::vec(prop::sample::select(PIECES), 0..120)
    ) {
        let text = pieces.concat();
        let _ = read_and_locate(&text);
        let _ = from_str::<IgnoredAny>(&text);
    }
}

/// Every model file of the repository cut short, read and located: at every character
/// boundary of its first and last 128 bytes and at 256 boundaries spread evenly between
/// (every boundary of all 170 files would be 6e5 cuts reading 1.5e9 bytes, a minute and a
/// half in the test profile; this is 83 610 cuts, about 6 s).
#[test]
fn truncated_model_files_are_refused_with_a_position() {
    let mut cuts = 0usize;
    for file in repository_models() {
        let Ok(source) = std::fs::read_to_string(&file) else {
            continue;
        };
        let n = source.len();
        let mut ends: Vec<usize> = (0..=n.min(128))
            .chain((0..256).map(|k| k * n / 256))
            .chain(n.saturating_sub(128)..=n)
            .collect();
        ends.sort_unstable();
        ends.dedup();
        ends.retain(|&end| source.is_char_boundary(end));
        for end in ends {
            // A cut in the comments after the closing bracket is still valid.
            let _ = read_and_locate(&source[..end]);
            cuts += 1;
        }
    }
    assert!(cuts > 50_000, "{cuts} cuts");
}

#[test]
fn nesting_deeper_than_the_limit_is_a_located_error() {
    // At the limit: read. One deeper: refused at the bracket that goes too deep, whatever
    // follows (a stack overflow would abort the test binary instead).
    let at_limit = format!("{}{}", "[".repeat(MAX_DEPTH), "]".repeat(MAX_DEPTH));
    assert!(from_str::<IgnoredAny>(&at_limit).is_ok());
    for opener in ["[", "(", "{", "Some(", "[(", "A("] {
        let deep = opener.repeat(100_000);
        let e = from_str::<IgnoredAny>(&deep).expect_err("too deep");
        assert_eq!(e.code, Code::TooDeep, "{opener}: {e}");
        let place = e.place.expect("placed");
        let deepest = deep
            .match_indices(['[', '(', '{'])
            .nth(MAX_DEPTH)
            .map(|(i, _)| i);
        assert_eq!(Some(place.start), deepest, "{opener}");
    }
    // Through the model's types the nesting is bounded by the schema; a deep value where a
    // number is expected is refused at once.
    let deep = format!("(gravity: {}", "(".repeat(100_000));
    let e = read_and_locate(&deep).expect_err("refused");
    assert_eq!(e.place.map(|p| p.start), Some(11), "{e}");
}

/// Texts of the largest size a model file may have, of the kinds a reader could spend
/// quadratic time on (many escapes in one string, a long comment, many small values): each
/// is read in one pass (a quadratic reader would need about 1e11 steps here and hang).
#[test]
fn long_texts_are_read_in_one_pass() {
    let size = crate::schema::MAX_FILE_BYTES.min(4 << 20);
    let escapes = format!("(name: \"{}\", bodies: [])", "\\n".repeat(size / 2));
    let model = from_str::<raw::Model>(&escapes).expect("valid");
    assert_eq!(model.name.map(|n| n.len()), Some(size / 2));
    let comment = format!("/*{}*/ (bodies: [])", " /* */".repeat(size / 6));
    assert!(from_str::<raw::Model>(&comment).is_ok());
    let values = format!("[{}]", "1, ".repeat(size / 3));
    let list = from_str::<Vec<raw::Number>>(&values).expect("valid");
    assert_eq!(list.len(), size / 3);
    let unterminated = format!("(name: \"{}", "\\n".repeat(size / 2));
    let e = from_str::<raw::Model>(&unterminated).expect_err("no closing quote");
    assert_eq!(e.code, Code::ExpectedStringEnd);
}

#[test]
fn errors_carry_the_offending_token_and_the_end_of_the_value_before() {
    let text = "(name: \"g\"\n value: 1)";
    let e = from_str::<raw::Parameter>(text).expect_err("no comma");
    assert_eq!(e.code, Code::ExpectedComma);
    let place = e.place.expect("placed");
    assert_eq!(&text[place.start..place.end], "value");
    assert_eq!(&text[..place.before], "(name: \"g\"");
    // A wrong type is placed at the value, an unknown field at its name.
    let text = "(name: \"g\", value: true)";
    let place = from_str::<raw::Parameter>(text).expect_err("bool").place;
    assert_eq!(place.map(|p| &text[p.start..p.end]), Some("true"));
    let text = "(name: \"g\", value: 1, colour: 2)";
    let place = from_str::<raw::Parameter>(text).expect_err("colour").place;
    assert_eq!(place.map(|p| &text[p.start..p.end]), Some("colour"));
    // A missing element at the bracket where it is missing.
    let text = "(0, 1)";
    let place = from_str::<raw::Vec3>(text).expect_err("short").place;
    assert_eq!(place.map(|p| p.start), Some(5));
}

#[test]
fn every_literal_form_is_read() {
    let number = |text: &str| match from_str::<raw::Number>(text) {
        Ok(raw::Number::Value(v)) => v,
        other => panic!("{text}: {other:?}"),
    };
    assert_eq!(number("0x1_F"), 31.0);
    assert!(
        from_str::<raw::Number>("0x_1F").is_err(),
        "no `_` right after the prefix"
    );
    assert_eq!(number("0b1_0"), 2.0);
    assert_eq!(number("-7i8"), -7.0);
    assert_eq!(number("b'\\n'"), 10.0);
    assert_eq!(number("1_0.2_5e1_0"), 10.25e10);
    assert_eq!(number("0.1f32"), f64::from(0.1f32));
    let text = |source: &str| match from_str::<String>(source) {
        Ok(s) => s,
        Err(e) => panic!("{source}: {e}"),
    };
    assert_eq!(
        text(r#""tab\there \u{48}\x49 \"q\" \\ \'s\'""#),
        "tab\there HI \"q\" \\ 's'"
    );
    assert_eq!(text("\"a\\\r\n   b\""), "ab", "continuation after CRLF");
    assert_eq!(text("r###\"a \"## b\"###"), "a \"## b");
    assert_eq!(text("\"\\xF0\\x9F\\x98\\x80\""), "😀");
    assert_eq!(from_str::<char>("'\\u{e9}'").ok(), Some('é'));
    assert_eq!(from_str::<char>("'''").ok(), Some('\''), "as ron reads it");
    assert_eq!(from_str::<bool>("/* c */ true // c").ok(), Some(true));
    assert_eq!(from_str::<Option<bool>>("None").ok(), Some(None));
    assert_eq!(
        from_str::<Option<bool>>("Some(true,)").ok(),
        Some(Some(true))
    );
    assert_eq!(from_str::<Option<bool>>("true").ok(), Some(Some(true)));
    assert_eq!(from_str::<()>("()").ok(), Some(()));
    assert_eq!(from_str::<Vec<u8>>("[1, 2,]").ok(), Some(vec![1, 2]));
    assert_eq!(
        from_str::<(u8, i64)>("(255, -9223372036854775808)").ok(),
        Some((255, i64::MIN))
    );
    assert!(from_str::<u8>("256").is_err());
    assert_eq!(from_str::<f32>("1.5").ok(), Some(1.5));
    // Not a valid identifier start, and a raw identifier with ron's extra characters.
    assert!(from_str::<raw::Parameter>("(1name: \"g\", value: 1)").is_err());
    let e = from_str::<raw::Parameter>("(r#na.me: \"g\", value: 1)").expect_err("unknown");
    assert!(e.to_string().contains("`r#na.me`"), "{e}");
}

#[test]
fn unwrap_newtypes_reads_a_newtype_struct_as_its_content() {
    #[derive(Debug, PartialEq, serde::Deserialize)]
    struct Metres(f64);
    assert_eq!(from_str::<Metres>("Metres(2)").ok(), Some(Metres(2.0)));
    assert_eq!(from_str::<Metres>("(2)").ok(), Some(Metres(2.0)));
    assert!(from_str::<Metres>("2").is_err());
    let unwrapped = "#![enable(unwrap_newtypes)] 2";
    assert_eq!(from_str::<Metres>(unwrapped).ok(), Some(Metres(2.0)));
}
