//! The reader compared with ron 0.12 (a dev-dependency), which the project used before:
//! every `.ron` file of the repository, a corpus of valid and invalid snippets, and random
//! model-shaped texts. For each text both read the same schema type; they must agree on
//! success, on the value read (its `Debug` text), and for an error on the line it is
//! reported at once located for the user (ron's error through the locator the project used
//! with ron, kept here as [`ron_located`]; the reader's through [`Locator::syntax_error`]).

use super::super::{Locator, raw, scan};
use crate::error::ModelError;
use ron::extensions::Extensions;
use serde::de::DeserializeOwned;
use std::fmt::Debug;
use std::path::{Path, PathBuf};

/// What the two readers made of one text, if they disagree.
pub(super) fn disagreement<T: DeserializeOwned + Debug>(source: &str) -> Option<String> {
    let ours = super::from_str::<T>(source);
    let options = ron::Options::default().with_default_extension(Extensions::IMPLICIT_SOME);
    let theirs = options.from_str::<T>(source);
    let at = Locator::new(Path::new("t.ron"), source);
    match (ours, theirs) {
        (Ok(a), Ok(b)) => {
            let (a, b) = (format!("{a:?}"), format!("{b:?}"));
            (a != b).then(|| format!("values differ:\n  reader {a}\n  ron    {b}"))
        }
        (Err(a), Err(b)) => {
            // Where each reader stopped, and where the user is pointed: either must be on
            // the same line. They differ where ron reads part of a token and fails at the
            // rest (`5u8` where a float is expected: ron fails after `5`, wanting a comma,
            // and the old locator then pointed after the value before; the reader fails at
            // `5u8`): the same line where each stopped, not where the user was pointed.
            let ours_line = a.place.map(|p| scan::line_column(source, p.start).0);
            let ours = at.syntax_error(&a);
            let theirs = ron_located(&at, &b);
            let same = ours_line.is_some_and(|line| ron_stop_lines(source, &b).contains(&line))
                || ours.line == theirs.line
                || more_precise(source, &a, &b);
            (!same).then(|| {
                format!(
                    "error lines differ:\n  reader {ours} (stopped on line {ours_line:?})\n  \
                     ron    {theirs} ({b})"
                )
            })
        }
        (Ok(a), Err(b)) => Some(format!(
            "only ron fails: {}\n  reader read {a:?}",
            ron_located(&at, &b)
        )),
        (Err(a), Ok(b)) => Some(format!(
            "only the reader fails: {}\n  ron read {b:?}",
            at.syntax_error(&a)
        )),
    }
}

/// True where the reader points somewhere better than where ron's cursor stopped, by
/// design: at the opening of a block comment that is never closed (ron: at the end of the
/// text), at the opening of a struct that lacks a field, and at the `]` of an attribute
/// that lacks its `)`.
fn more_precise(source: &str, ours: &super::Error, theirs: &ron::error::SpannedError) -> bool {
    let at = ours.place.map_or(0, |p| p.start);
    match (&ours.code, &theirs.code) {
        (super::Code::UnclosedBlockComment, ron::Error::UnclosedBlockComment) => {
            source[at..].starts_with("/*")
        }
        // At the opening of the struct that lacks the field, for the top-level struct too
        // (ron: at its end; the old locator moved nested structs' errors to their opening).
        (super::Code::MissingStructField { .. }, ron::Error::MissingStructField { .. }) => {
            source[at..].starts_with('(')
        }
        // `#![enable(implicit_some]`: at the `]` where `)` is missing (ron consumes the `]`
        // and the blanks after it before failing).
        (super::Code::ExpectedAttributeEnd, ron::Error::ExpectedAttributeEnd) => {
            source[at..].starts_with(']')
        }
        _ => false,
    }
}

/// The lines ron's cursor stopped on: from the start of its error span (often the end of
/// the last thing it read) to the next token after it.
fn ron_stop_lines(
    source: &str,
    error: &ron::error::SpannedError,
) -> std::ops::RangeInclusive<usize> {
    let offset = scan::byte_offset(source, error.span.start.line, error.span.start.col);
    scan::line_column(source, offset).0..=scan::line_column(source, after_blanks(source, offset)).0
}

/// The offset of the next token at or after `offset`: past ron's whitespace and comments.
fn after_blanks(source: &str, mut offset: usize) -> usize {
    let ron_blank = |c: char| {
        c.is_ascii_whitespace()
            || matches!(
                c,
                '\u{B}' | '\u{85}' | '\u{200E}' | '\u{200F}' | '\u{2028}' | '\u{2029}'
            )
    };
    loop {
        let rest = &source[offset..];
        let trimmed = rest.trim_start_matches(ron_blank);
        offset += rest.len() - trimmed.len();
        if trimmed.starts_with("//") {
            offset += trimmed.find('\n').unwrap_or(trimmed.len());
        } else if trimmed.starts_with("/*") {
            let mut depth = 0;
            let mut i = 0;
            let bytes = trimmed.as_bytes();
            while i < bytes.len() {
                if bytes[i..].starts_with(b"/*") {
                    depth += 1;
                    i += 2;
                } else if bytes[i..].starts_with(b"*/") {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            offset += i.min(trimmed.len());
        } else {
            return offset;
        }
    }
}

/// ron's error located as the project did before the reader (its `Locator::ron_error`):
/// ron's position moved past blanks onto the next token; a missing delimiter reported
/// after the value before it when that value ends on an earlier line; a missing field at
/// the opening of the struct that lacks it.
pub(super) fn ron_located(at: &Locator, error: &ron::error::SpannedError) -> ModelError {
    use ron::Error as E;
    let start = error.span.start;
    let offset = scan::byte_offset(at.source, start.line, start.col);
    let mut offset = offset + (at.source[offset..].len() - at.source[offset..].trim_start().len());
    let (before, _) = scan::tokens_around(at.source, offset);
    let missing_delimiter = matches!(
        error.code,
        E::ExpectedComma
            | E::ExpectedStructLikeEnd
            | E::ExpectedArrayEnd
            | E::ExpectedMapEnd
            | E::ExpectedOptionEnd
    );
    let mut field_offset = offset;
    match before {
        Some((_, end)) if missing_delimiter && at.source[end..offset].contains('\n') => {
            offset = end;
            field_offset = end - 1;
        }
        Some((_, end)) if matches!(error.code, E::ExpectedComma) => field_offset = end - 1,
        _ => {}
    }
    let mut field = at.document.path_at(field_offset);
    if let E::MissingStructField { field: missing, .. } = &error.code {
        if let Some(open) = at.document.locate(&field).filter(|_| !field.is_empty()) {
            offset = open;
        }
        field = format!("{field}.{missing}");
    }
    let (line, column) = scan::line_column(at.source, offset);
    ModelError {
        file: PathBuf::from("t.ron"),
        line,
        column,
        field,
        message: error.code.to_string(),
    }
}

/// Every `.ron` file under the workspace root, found when the test runs.
pub(super) fn repository_models() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut found = Vec::new();
    let mut pending = vec![root];
    while let Some(dir) = pending.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            let name = entry.file_name();
            let name = name.to_string_lossy();
            if path.is_dir() {
                if !name.starts_with('.') && name != "target" {
                    pending.push(path);
                }
            } else if name.ends_with(".ron") {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

#[test]
fn every_model_file_of_the_repository_reads_as_ron_reads_it() {
    let files = repository_models();
    // models/ alone has 22; the bad-model corpus over a hundred.
    assert!(files.len() > 100, "found only {} model files", files.len());
    let mut failures = Vec::new();
    let mut accepted = 0;
    for file in &files {
        let Ok(source) = std::fs::read_to_string(file) else {
            continue;
        };
        let source = super::super::without_bom(&source);
        accepted += usize::from(super::from_str::<raw::Model>(source).is_ok());
        if let Some(d) = disagreement::<raw::Model>(source) {
            failures.push(format!("{}: {d}", file.display()));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // Most files are valid RON (the bad models are mostly wrong in physics or names).
    assert!(accepted > files.len() / 2, "{accepted} of {}", files.len());
}

/// A minimal valid model, the base of the model-sized snippets.
const MODEL: &str = r#"(bodies: [(name: "a", parent: "ground", mass: 1, inertia: Izz(1),
    joint: (kind: Revolute, axis: (0, 0, 1), coordinate: "q"))])"#;

/// Snippets read as one schema type each: (type, text). Valid and invalid ones, covering
/// the grammar (numbers, strings, comments, attributes, names, options, enums) and the
/// errors of each kind, on one line and across lines.
const CORPUS: &[(&str, &str)] = &[
    // Numbers where any number may be (a `Number` field).
    ("number", "1"),
    ("number", "-0"),
    ("number", "+7"),
    ("number", "1_000"),
    ("number", "0x1F"),
    ("number", "0b1010"),
    ("number", "0o17"),
    ("number", "7u8"),
    ("number", "-2i32"),
    ("number", "300u8"),
    ("number", "0.5"),
    ("number", "-9.81"),
    ("number", "1e-3"),
    ("number", "2.5E+2"),
    ("number", ".5"),
    ("number", "5."),
    ("number", "1e_5"),
    ("number", "1._5"),
    ("number", "0.1f32"),
    ("number", "5f32"),
    ("number", "2.5f64"),
    ("number", "inf"),
    ("number", "-inf"),
    ("number", "NaN"),
    ("number", "-NaN"),
    ("number", "inff64"),
    ("number", "18446744073709551616"),
    ("number", "-9223372036854775809"),
    ("number", "0xFFFFFFFFFFFFFFFFFF"),
    ("number", "0x"),
    ("number", "0b2"),
    ("number", "1.5.5"),
    ("number", "1.5kg"),
    ("number", "1..2"),
    ("number", "b'a'"),
    ("number", "'m'"),
    ("number", "\"2*m1\""),
    ("number", "r#\"l1/2\"#"),
    ("number", "true"),
    ("number", "()"),
    ("number", "( )"),
    ("number", "Some(1)"),
    ("number", "None"),
    ("number", "[1]"),
    ("number", "{\"a\": 1}"),
    ("number", "(1, 2)"),
    ("number", "(a: 1)"),
    ("number", "Name"),
    ("number", "Name(1)"),
    ("number", "b\"bytes\""),
    ("number", "@"),
    ("number", ""),
    ("number", "// only a comment"),
    ("number", "/* unclosed"),
    ("number", "1 /* a /* nested */ comment */"),
    ("number", "1 2"),
    ("number", "\u{2028}1\u{200E}"),
    // Numbers where a float is expected.
    ("parameter", "(name: \"g\", value: 9)"),
    ("parameter", "(name: \"g\", value: -0)"),
    ("parameter", "(name: \"g\", value: 0x10)"),
    ("parameter", "(name: \"g\", value: 5u8)"),
    ("parameter", "(name: \"g\", value: 1f32)"),
    ("parameter", "(name: \"g\", value: 1f64)"),
    ("parameter", "(name: \"g\", value: -inf, min: NaN)"),
    ("parameter", "(name: \"g\", value: \"9.81\")"),
    (
        "parameter",
        "(name: \"g\", value: 1, min: Some(0), max: None)",
    ),
    (
        "parameter",
        "(name: \"g\", value: 1, constant: true, unit: \"m\")",
    ),
    ("parameter", "(name: \"g\", value: 1, constant: 1)"),
    ("parameter", "Parameter(name: \"g\", value: 1)"),
    ("parameter", "Param(name: \"g\", value: 1)"),
    ("parameter", "(r#name: \"g\", value: 1)"),
    ("parameter", "(name: \"g\", value: 1, value: 2)"),
    ("parameter", "(name: \"g\")"),
    ("parameter", "(name: \"g\"  value: 1)"),
    ("parameter", "(name: \"g\",\n value: 1\n unit: \"m\")"),
    ("parameter", "(name \"g\", value: 1)"),
    ("parameter", "(\"name\": \"g\", value: 1)"),
    ("parameter", "(name: \"g\", value: 1,,)"),
    ("parameter", "(name: \"g\", value: 1,)"),
    ("parameter", "(name: \"g\", value: 1"),
    ("parameter", "(name: \"g\", value: 1))"),
    // Strings.
    ("parameter", r#"(name: "a\nb\t\"c\"\\\0", value: 1)"#),
    ("parameter", r#"(name: "\u{e9}\u{1F600}\x41", value: 1)"#),
    ("parameter", r#"(name: "\xC3\xA9", value: 1)"#),
    ("parameter", r#"(name: "\xC3", value: 1)"#),
    ("parameter", r#"(name: "\q", value: 1)"#),
    ("parameter", r#"(name: "\u{D800}", value: 1)"#),
    ("parameter", r#"(name: "\u{}", value: 1)"#),
    (
        "parameter",
        "(name: \"line \\\n      continued\", value: 1)",
    ),
    ("parameter", "(name: \"two\nlines\", value: 1)"),
    ("parameter", "(name: r\"raw \\n\", value: 1)"),
    ("parameter", "(name: r##\"has \"# inside\"##, value: 1)"),
    ("parameter", "(name: \"unterminated, value: 1)"),
    ("parameter", "(name: r#\"unterminated\", value: 1)"),
    ("parameter", "(name: 'c', value: 1)"),
    ("parameter", "(name: b\"g\", value: 1)"),
    ("parameter", "(name: g, value: 1)"),
    // Attributes.
    (
        "parameter",
        "#![enable(implicit_some)] (name: \"g\", value: 1)",
    ),
    (
        "parameter",
        "#![enable(implicit_some, unwrap_newtypes,)]\n(name: \"g\", value: 1)",
    ),
    (
        "parameter",
        "#![enable(explicit_struct_names)] (name: \"g\", value: 1)",
    ),
    (
        "parameter",
        "#![enable(explicit_struct_names)] Parameter(name: \"g\", value: 1)",
    ),
    ("parameter", "#![enable(colours)] (name: \"g\", value: 1)"),
    (
        "parameter",
        "#![enable(implicit_some unwrap_newtypes)] (name: \"g\", value: 1)",
    ),
    (
        "parameter",
        "#![type = \"Parameter\"] (name: \"g\", value: 1)",
    ),
    (
        "parameter",
        "#[enable(implicit_some)] (name: \"g\", value: 1)",
    ),
    (
        "parameter",
        "#![enable(implicit_some) (name: \"g\", value: 1)",
    ),
    // Enums.
    ("inertia", "Izz(0.1)"),
    ("inertia", "Izz(0.1,)"),
    ("inertia", "Izz 0.1"),
    ("inertia", "Izz(0.1, 0.2)"),
    ("inertia", "Diagonal(1, 2, 3)"),
    ("inertia", "Diagonal(1, 2)"),
    ("inertia", "Diagonal(1, 2, 3, 4)"),
    ("inertia", "Full(ixx: 1, iyy: 1, izz: 1, iyz: 0.5)"),
    ("inertia", "Full(ixx: 1, iyy: 1)"),
    ("inertia", "Full(ixx: 1, iyy: 1, izz: 1, iyx: 0)"),
    ("inertia", "Ixx(1)"),
    ("inertia", "r#Izz(1)"),
    ("inertia", "\"Izz\""),
    ("inertia", "#![enable(unwrap_variant_newtypes)] Izz(0.1)"),
    ("follower", "Knife"),
    ("follower", "Roller(radius: \"rho\")"),
    ("follower", "Flat(normal: (0, 1, 0))"),
    ("follower", "Mushroom(radius: 0.1, normal: (0, 1, 0),)"),
    ("follower", "Roller"),
    ("follower", "Roller(0.1)"),
    ("simulation", "(integrator: dop853, t_end: 2)"),
    ("simulation", "(integrator: Euler)"),
    ("simulation", "(integrator: Rk4(), dt: 1e-4)"),
    ("simulation", "(restitution: 0.5)"),
    ("simulation", "(restitution: Some(0.5), atol: 1e-9)"),
    (
        "table",
        "(form: Polar, points: [(0, 1), (1.5, 1)], ends: Periodic, degrees: true)",
    ),
    (
        "table",
        "(form: Explicit, file: \"p.csv\", ends: Clamped(start: 0, end: 1))",
    ),
    ("table", "(form: Explicit, ends: Some(Natural))"),
    ("table", "(form: Explicit, points: [(0, 1, 2)])"),
    ("table", "(form: Explicit, points: [(0)])"),
    // Maps and lists.
    (
        "initial",
        "(q: {\"q1\": 0.5, \"q1\": 2}, qd: {}, hold: [\"q1\",])",
    ),
    ("initial", "(q: {q1: 0.5})"),
    ("initial", "(q: {\"q1\" 0.5})"),
    ("initial", "(q: {\"q1\": 0.5 \"q2\": 1})"),
    ("initial", "(q: {\"q1\": 0.5,\n}\n, hold: [\"a\"\n \"b\"])"),
    ("initial", "(hold: [\"a\", \"b\"\n)"),
    ("initial", "(hold: \"a\")"),
    ("initial", "(q: [0.5])"),
    // Whole models.
    ("model", MODEL),
    (
        "model",
        "Model(bodies: [Body(name: \"a\", parent: \"ground\", mass: 1, inertia: Izz(1),
        joint: Joint(kind: Prismatic, axis: (1, 0, 0), coordinate: \"q\"))])",
    ),
    ("model", "()"),
    ("model", "(bodies: [])"),
    ("model", "(bodies: [], colour: 1)"),
    ("model", "[bodies: []]"),
    (
        "model",
        "(\n  bodies: [\n    (name: \"a\"\n     parent: \"ground\")\n  ],\n)",
    ),
    ("model", "(\n  bodies: [(name: \"a\", mass: 1\n  ]\n)"),
    ("model", "(\n  gravity: (0, -9.81, 0\n  bodies: []\n)"),
    ("model", "(\n  gravity: (0, -9.81),\n  bodies: [],\n)"),
    ("model", "(\n  bodies: [],\n) trailing"),
    (
        "model",
        "(\n  bodies: [],\n)\n// a comment after the value\n",
    ),
];

/// Reads `text` as the type named `kind`; what the two readers disagree on, if anything.
fn disagreement_as(kind: &str, text: &str) -> Option<String> {
    match kind {
        "number" => disagreement::<raw::Number>(text),
        "parameter" => disagreement::<raw::Parameter>(text),
        "inertia" => disagreement::<raw::Inertia>(text),
        "follower" => disagreement::<raw::Follower>(text),
        "simulation" => disagreement::<raw::Simulation>(text),
        "table" => disagreement::<raw::Table>(text),
        "initial" => disagreement::<raw::Initial>(text),
        "model" => disagreement::<raw::Model>(text),
        other => Some(format!("no schema type named {other}")),
    }
}

#[test]
fn a_corpus_of_snippets_reads_as_ron_reads_it() {
    assert!(CORPUS.len() >= 60, "{} snippets", CORPUS.len());
    let failures: Vec<String> = CORPUS
        .iter()
        .filter_map(|(kind, text)| {
            disagreement_as(kind, text).map(|d| format!("{kind} {text:?}: {d}"))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // Both kinds are there: the corpus is not all errors, nor all valid.
    let valid = CORPUS
        .iter()
        .filter(|(kind, text)| *kind == "model" && super::from_str::<raw::Model>(text).is_ok())
        .count();
    assert!(valid >= 2, "{valid} valid models");
}

mod random {
    use super::super::generate::{Tape, model};
    use super::{disagreement, raw};
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 5000, ..ProptestConfig::default() })]

        /// Random model-shaped texts (a quarter with one character deleted or inserted)
        /// read as ron reads them. About 70 % are valid RON of the schema. 5000 cases take
        /// about a second in the test profile; 200 000 (`PROPTEST_CASES=200000`) passed.
        #[test]
        fn random_model_shaped_texts_read_as_ron_reads_them(
            choices in prop::collection::vec(any::<u8>(), 0..1500)
        ) {
            let text = model(&mut Tape::new(&choices));
            if let Some(d) = disagreement::<raw::Model>(&text) {
                prop_assert!(false, "{text}\n{d}");
            }
        }
    }
}
