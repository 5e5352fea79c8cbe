//! The crate's parser against the `syn`-based one it replaced (`oracle.rs`): on every string
//! of every model file in the repository, on a hand-written corpus of valid and invalid
//! expressions, and on random token soup (and, in `property.rs`, on random valid
//! expressions), both must accept the same inputs with equal trees. Rejections must point at
//! the same byte, except where this file lists why not.

use super::oracle;
use crate::profile::{ExprError, Scalar, parse_expression_with};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

/// What both parsers did with one input.
#[derive(Debug, PartialEq)]
pub(super) enum Outcome {
    /// Both accepted it, with this tree.
    Accepted(Scalar),
    /// Both rejected it: the new error and the old.
    Rejected(ExprError, ExprError),
}

/// Runs both parsers on `source`; panics when one accepts and the other does not, or when
/// their trees differ.
pub(super) fn both(source: &str, variable: Option<&str>, parameters: &[&str]) -> Outcome {
    let new = parse_expression_with(source, variable, parameters);
    let old = oracle::parse_expression_with(source, variable, parameters);
    match (new, old) {
        (Ok(a), Ok(b)) => {
            assert_eq!(a, b, "{source:?} ({variable:?}): different trees");
            Outcome::Accepted(a)
        }
        (Err(a), Err(b)) => Outcome::Rejected(a, b),
        (new, old) => panic!("{source:?} ({variable:?}): new {new:?}, old {old:?}"),
    }
}

/// The variables the model file's expressions have: a profile's `x`, a drive's and a load's
/// `t`, a polar profile's `theta`, a motion law's `s`, and none (a numeric field).
const VARIABLES: [Option<&str>; 5] = [Some("x"), Some("t"), Some("theta"), Some("s"), None];

/// Every `.ron` file under `dir`, recursively, `target` directories apart.
fn ron_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            if path
                .file_name()
                .is_some_and(|n| n != "target" && n != ".git")
            {
                ron_files(&path, out);
            }
        } else if path.extension().is_some_and(|e| e == "ron") {
            out.push(path);
        }
    }
}

/// The string literals of a RON file (no escapes in the corpus' expressions; an escaped
/// quote ends a literal early, which only splits one string into two test inputs).
fn strings(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(open) = rest.find('"') {
        let after = &rest[open + 1..];
        let Some(close) = after.find('"') else {
            break;
        };
        out.push(&after[..close]);
        rest = &after[close + 1..];
    }
    out
}

/// Every string of every model file of the repository (`models/`, `tests/`, the bad-model
/// corpus, the command line's scenarios, …), parsed by both with each of [`VARIABLES`] and
/// the file's names (`name: "…"`, and `<name>_dot` for the velocities a load may read) as
/// the parameters.
#[test]
fn every_string_of_every_model_file_parses_alike() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for dir in [
        "models",
        "tests",
        "reference/tests",
        "codegen/tests",
        "cli/scenarios",
        "examples",
    ] {
        ron_files(&root.join(dir), &mut files);
    }
    assert!(files.len() > 100, "found only {} model files", files.len());
    let (mut accepted, mut profiles) = (0, 0);
    for file in &files {
        let Ok(text) = std::fs::read_to_string(file) else {
            panic!("cannot read {}", file.display());
        };
        let mut names: Vec<String> = text
            .split("name:")
            .skip(1)
            .filter_map(|after| strings(after).first().map(|s| s.to_string()))
            .collect();
        let rates: Vec<String> = names.iter().map(|n| format!("{n}_dot")).collect();
        names.extend(rates);
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        profiles += text.matches("profile: \"").count() + text.matches("prescribed: \"").count();
        for source in strings(&text) {
            for variable in VARIABLES {
                if let Outcome::Accepted(_) = both(source, variable, &names) {
                    accepted += 1;
                }
            }
        }
    }
    // The corpus holds the expressions it is meant to test: the built-in models alone write
    // dozens of profiles and drives.
    assert!(profiles > 50, "only {profiles} profiles and drives");
    assert!(accepted > 500, "only {accepted} accepted parses");
}

/// Accepted by both (with variable `x`, parameters `a` and `b`), each for a reason of the
/// old parser's grammar that the new one must reproduce.
const VALID: &[&str] = &[
    "0.5*x - x*x",
    "-0.595*x + 0.5*x*x + 0.5*x.powi(3)",
    "1 - x * 2 / 3 + 4",
    "x - x - x",
    "x / x / x",
    "-x.sin()",
    "-2.0.powi(2)",
    "2.0.sqrt() * x",
    "2.sqrt() + x",
    "(2).sqrt()",
    "1e3.ln()",
    "--x",
    "- - -x",
    "-(-(x))",
    "1_000.5 * x",
    "1_000 + x",
    "1_f64 + 1.0_f64",
    "2. + x",
    "(2.)",
    "1e-3 * x",
    "1E+3 * x",
    "1e_3",
    "1.5e1_0",
    "0x10 * x",
    "0o17 + 0b101 + 0xFF_ff",
    "0x1f64",
    "3f64 * x",
    "1e300 * 1e-300",
    "1e-400 + x",
    "000123",
    "99999999999999999999999999999999999999 * x",
    "0xffffffffffffffffffffffffffffffffffffffff",
    "PI * E",
    "std::f64::consts::PI + core::f64::consts::E + f64::consts::PI",
    "::std::f64::consts::PI",
    "::x + ::PI",
    "sin(x) + f64::cos(x) + std::f64::tan(x) + core::f64::exp(x) + ::sqrt(x)",
    "powi(x, 3) + f64::powf(x, 1.5) + x.powf(x + 1)",
    "x.powi(-2) + x.powi((3)) + x.powi(-(4)) + x.powi(- -5) + x.powi(3i32)",
    "x.powi(0x10) + x.powi(1_0)",
    "x.powi(1000000) + x.powi(-1000000)",
    "sin(x,) + x.powi(2,) + powi(x, 2,) + powf(x, 2,)",
    "x.sin().cos().tan().exp().ln().sqrt().sinh().cosh().tanh().atan()",
    "x . sin ( ) + sin ( x )",
    "x // a comment\n + 1",
    "x /* a /* nested */ comment */ + 1 /**/",
    "x /*** not a doc comment */ + 1 //// nor this",
    "\tx\n+\r\n1\u{a0}+\u{200e}2",
    "a * x + b",
    "(a + b).sin()",
    "a.powi(2)",
    "((((x))))",
    "x*-1 + x/-2 - -3",
    "(x)",
    "1.0e5f64",
];

/// Rejected by both; each holds one thing the old parser refused.
const INVALID: &[&str] = &[
    "",
    "   ",
    "// only a comment",
    "y",
    "r#x",
    "_",
    "x + ",
    "x y",
    "(x y)",
    "x +)",
    "(x",
    "x)",
    "((x)",
    "(]",
    "[x]",
    "{x}",
    "x[0]",
    "x.y",
    "x.0",
    "x.1.2",
    "x.sin",
    "x.sin::<f64>()",
    "x.sin::()",
    "x.foo()",
    "foo(x)",
    "x(2)",
    "(x)(2)",
    "2(3)",
    "x.sin()(2)",
    "sin()",
    "sin(x, x)",
    "x.sin(1)",
    "powi(x)",
    "x.powi()",
    "x.powi(2, 3)",
    "x.powi(2.0)",
    "x.powi(x)",
    "x.powi(2f64)",
    "x.powi(2u8)",
    "x.powi(+2)",
    "x.powi(2147483648)",
    "x.powi(-2147483648)",
    "x.powi(1000001)",
    "x.powf()",
    "PI(x)",
    "sin",
    "f64::sin",
    "f64::consts::TAU",
    "std::PI",
    "std::f64::PI",
    "x::y",
    "x::",
    "::",
    "1e400",
    "0x1p3",
    "1e",
    "1.5e",
    "1e+-5",
    "1.0f32",
    "2u8",
    "0b102",
    "0x",
    "0o8",
    "1.e3",
    "1._5",
    "x / 0",
    "x / (1 - 1)",
    "x / -0.0",
    "x / 0.0.sin()",
    "(0.0).ln() * x",
    "(-1.0).sqrt()",
    "1e200 * 1e200",
    "10.0.powi(400)",
    "\"x\"",
    "'a'",
    "b'a'",
    "r\"x\"",
    "c\"x\"",
    "x + \"",
    "'a",
    "'a: loop {}",
    "true",
    "false + x",
    "()",
    "(x,)",
    "(x, x)",
    "*x",
    "&x",
    "!x",
    "x?",
    "x % 2",
    "x ^ 2",
    "x == 1",
    "x != 1",
    "x < 1",
    "x <= 1",
    "x && x",
    "x || x",
    "x | x",
    "|v| v",
    "|| x",
    "x = 1",
    "x += 1",
    "x <<= 1",
    "x..1",
    "0..=1",
    "x as f64",
    "if x { 1 } else { 2 }",
    "loop {}",
    "let y = x",
    "x.await",
    "vec![x]",
    "panic!()",
    "#[inline] x",
    "/// doc\nx",
    "x //! inner doc",
    "/** doc */ x",
    "/* unterminated",
    "x: f64",
    "x;",
    "x @ y",
    "$x",
    "x ~ y",
    "`x`",
    "x \\ 2",
    "x € 2",
    "x²",
    "self",
    "crate::x",
    "Self::PI",
    "x.self()",
    "x.r#sin()",
    "r#sin(x)",
    "r#self",
    "(/*ERROR*/)",
    "- + x",
    "+x",
    "x - - - ",
];

/// Offsets where the new parser's error points elsewhere than the old one's, and why.
const OFFSET_DIFFERENCES: &[(&str, usize, usize, &str)] = &[
    (
        "// only a comment",
        0,
        17,
        "an empty expression is reported at its start, not after its comments",
    ),
    (
        "x.sin::()",
        5,
        7,
        "a method name followed by `::` is reported at the `::`, not at the token after",
    ),
    (
        "x²",
        0,
        1,
        "identifiers are Unicode letters and digits (`²` is a digit), not XID: the name `x²` \
         is unknown where proc-macro2 could not split `²` off",
    ),
];

#[test]
fn the_hand_written_corpus_parses_alike() {
    let parameters = ["a", "b"];
    for source in VALID {
        assert!(
            matches!(both(source, Some("x"), &parameters), Outcome::Accepted(_)),
            "{source:?} should be accepted"
        );
    }
    let mut differences = Vec::new();
    for source in INVALID {
        let Outcome::Rejected(new, old) = both(source, Some("x"), &parameters) else {
            panic!("{source:?} should be rejected");
        };
        if new.offset != old.offset {
            differences.push((*source, new.offset, old.offset, new.message, old.message));
        }
    }
    let listed: Vec<(&str, usize, usize)> = OFFSET_DIFFERENCES
        .iter()
        .map(|&(s, n, o, _)| (s, n, o))
        .collect();
    let found: Vec<(&str, usize, usize)> = differences.iter().map(|d| (d.0, d.1, d.2)).collect();
    assert_eq!(found, listed, "{differences:#?}");
}

/// Tokens of the soup: what the two grammars have in common and what they refuse.
const SOUP: &[&str] = &[
    "x", "y", "a", "PI", "E", "sin", "powi", "powf", "f64", "std", "consts", "0", "1", "2.5",
    "1e3", "0x1F", "1_0", "3f64", "2u8", "1e400", "1.", "+", "-", "*", "/", "%", "(", ")", "[",
    "]", ".", ",", "::", ":", "!", "=", "|", "<", " ", " ", "  ", "\n", "/**/", "true", "as", "'a",
    "\"", "_",
];

/// Tokens of a soup nearer to the grammar, where most inputs parse or nearly do.
const GRAMMAR_SOUP: &[&str] = &[
    "x", "a", "2", "1.5", "0", "1e2", "PI", "+", "-", "*", "/", "(", ")", ".sin()", ".sqrt()",
    ".powi(", ".powf(", "sin(", "powi(", "f64::", ",", " ", "-3", "2.", "/ 0", "(1 - 1)",
];

/// New errors that may point elsewhere than the old ones, with why (checked on the soup):
/// the old parser blamed the first quote or the first unbalanced delimiter of the raw text
/// (comments included) for any lexical error, called an empty expression's error at its
/// end, and after a method name followed by `::` or a `.` followed by no member pointed at
/// the token after; the new one points at the lexical error, the start, the `::` and the
/// member.
const MAY_POINT_ELSEWHERE: [&str; 4] = [
    "cannot split the expression into tokens",
    "the expression is empty",
    "after the method name",
    "expected a method name after `.`",
];

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 4000,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_token_soup_parses_alike(
        tokens in prop::collection::vec(prop::sample::select(SOUP), 0..24),
    ) {
        soup_parses_alike(&tokens.concat())?;
    }

    #[test]
    fn random_grammar_soup_parses_alike(
        tokens in prop::collection::vec(prop::sample::select(GRAMMAR_SOUP), 0..24),
    ) {
        soup_parses_alike(&tokens.concat())?;
    }
}

/// Both parsers accept `source` alike, and reject it at the same byte unless
/// [`MAY_POINT_ELSEWHERE`] and the comments inside say why not.
fn soup_parses_alike(source: &str) -> Result<(), TestCaseError> {
    both(source, None, &["a", "x"]);
    if let Outcome::Rejected(new, old) = both(source, Some("x"), &["a"]) {
        // With a quote anywhere, the old parser blamed the quote for any lexical error.
        let quoted = source.contains(['"', '\'']);
        // With comments, the old errors at the end pointed after trailing comments (the new
        // ones after the last token), and its search for unbalanced delimiters read the
        // comments too.
        let commented = (source.contains("//") || source.contains("/*"))
            && ["found the end of the expression", "unclosed", "unmatched"]
                .iter()
                .any(|m| new.message.contains(m));
        let exempt =
            quoted || commented || MAY_POINT_ELSEWHERE.iter().any(|m| new.message.contains(m));
        prop_assert!(
            exempt || new.offset == old.offset,
            "{source:?}: new {new}; old {old}"
        );
    }
    Ok(())
}
