//! Tests of the expression parser.

use super::*;

mod corpus;
mod property;
use std::f64::consts::{E, PI};

/// Parses with variable `x`, panicking with the error text on failure.
fn parse_x(source: &str) -> Scalar {
    match parse_expression(source, "x") {
        Ok(s) => s,
        Err(e) => panic!("{source:?} should parse: {e}"),
    }
}

/// Parses with variable `x` and returns the error, panicking when it parses.
fn error_x(source: &str) -> ExprError {
    match parse_expression(source, "x") {
        Ok(s) => panic!("{source:?} should be rejected, got {s:?}"),
        Err(e) => e,
    }
}

// Relative tolerance for comparing the tree evaluation with the closed form written in
// Rust: both evaluate the same operations in possibly different association order, so
// they agree to a few ulps; 1e-14 leaves a margin of ~50 ulps.
const REL: f64 = 1e-14;

fn assert_close(got: f64, want: f64, what: &str) {
    let scale = want.abs().max(1.0);
    assert!(
        (got - want).abs() <= REL * scale,
        "{what}: got {got}, want {want}"
    );
}

#[test]
fn paper_profiles_evaluate_to_their_closed_forms() {
    let concave = parse_x("-0.595*x + 0.5*x*x + 0.5*x.powi(3)");
    let convex = parse_x("0.357*x - 0.3*x*x - 0.3*x.powi(3)");
    for &x in &[-1.0, -0.2, 0.0, 0.3793, 0.7, 1.3] {
        assert_close(
            concave.eval(x),
            -0.595 * x + 0.5 * x * x + 0.5 * x * x * x,
            "concave",
        );
        assert_close(
            convex.eval(x),
            0.357 * x - 0.3 * x * x - 0.3 * x * x * x,
            "convex",
        );
        // The designed pair: convex = -0.6 × concave = 0.5 x (x - 0.7)(x + 1.7) × (-0.6).
        assert_close(
            concave.eval(x),
            0.5 * x * (x - 0.7) * (x + 1.7),
            "factored concave",
        );
    }
}

#[test]
fn drive_expression_evaluates_to_its_closed_form() {
    let drive = match parse_expression("-PI/2 + 0.45*(2.0*PI*t/4.0).sin()", "t") {
        Ok(s) => s,
        Err(e) => panic!("drive should parse: {e}"),
    };
    for &t in &[0.0, 0.5, 1.0, 2.7, 8.0] {
        let want = -PI / 2.0 + 0.45 * (2.0 * PI * t / 4.0).sin();
        assert_close(drive.eval(t), want, "drive");
    }
}

#[test]
fn every_function_form_evaluates_like_std() {
    let x: f64 = 0.37;
    let cases: [(&str, f64); 22] = [
        ("x.sin()", x.sin()),
        ("sin(x)", x.sin()),
        ("f64::sin(x)", x.sin()),
        ("std::f64::cos(x)", x.cos()),
        ("x.tan()", x.tan()),
        ("x.exp()", x.exp()),
        ("x.ln()", x.ln()),
        ("x.sqrt()", x.sqrt()),
        ("x.sinh()", x.sinh()),
        ("x.cosh()", x.cosh()),
        ("tanh(x)", x.tanh()),
        ("x.atan()", x.atan()),
        ("x.powi(3)", x.powi(3)),
        ("x.powi(-2)", x.powi(-2)),
        ("powi(x, 3)", x.powi(3)),
        ("f64::powf(x, 1.5)", x.powf(1.5)),
        ("x.powf(x + 1)", x.powf(x + 1.0)),
        ("PI * E", PI * E),
        ("std::f64::consts::PI + f64::consts::E", PI + E),
        ("-(x - 2) / 4", -(x - 2.0) / 4.0),
        ("1_000.0f64 * x", 1000.0 * x),
        ("2.0.sqrt() * x", 2f64.sqrt() * x),
    ];
    for (source, want) in cases {
        assert_close(parse_x(source).eval(x), want, source);
    }
}

#[test]
fn tree_shape_follows_rust_precedence() {
    let parsed = parse_x("1 - x * 2");
    let want = Scalar::Sub(
        Box::new(Scalar::Const(1.0)),
        Box::new(Scalar::Mul(
            Box::new(Scalar::Var(0)),
            Box::new(Scalar::Const(2.0)),
        )),
    );
    assert_eq!(parsed, want);
    assert_eq!(
        parse_x("-x.powi(2)"),
        Scalar::Neg(Box::new(Scalar::Powi(Box::new(Scalar::Var(0)), 2)))
    );
}

/// Rust's grammar where it is easy to get wrong: a method on a float literal binds tighter
/// than the sign before it (`-2.0.powi(2)` is −4, not 4), `-` and `/` associate to the left,
/// and a sign applies to a product's first factor only. Trees written by hand.
#[test]
fn signs_methods_and_associativity_follow_rust() {
    let b = Box::new;
    let (x, two) = (|| b(Scalar::Var(0)), || b(Scalar::Const(2.0)));
    assert_eq!(
        parse_x("-2.0.powi(2)"),
        Scalar::Neg(b(Scalar::Powi(two(), 2)))
    );
    assert_eq!(parse_x("-2.0.powi(2)").eval(0.0), -4.0);
    assert_eq!(
        parse_x("x - x - 2"),
        Scalar::Sub(b(Scalar::Sub(x(), x())), two())
    );
    assert_eq!(
        parse_x("x / x / 2"),
        Scalar::Div(b(Scalar::Div(x(), x())), two())
    );
    assert_eq!(parse_x("-x * 2"), Scalar::Mul(b(Scalar::Neg(x())), two()));
    assert_eq!(parse_x("2.sqrt()"), Scalar::Call(Func::Sqrt, two()));
}

/// (source, expected byte offset, text the message must contain).
const BAD: &[(&str, usize, &str)] = &[
    ("0.5*y + x", 4, "only variable allowed here is `x`"),
    (
        "x + foo(x)",
        4,
        "`foo` is not a known math function; allowed: sin",
    ),
    ("x.foo()", 2, "`foo` is not a known math function"),
    ("x.powi(2.5)", 7, "integer literal exponent"),
    ("x.powi(x)", 7, "integer literal exponent"),
    ("x = 2", 2, "assignments are not allowed"),
    ("x += 2", 2, "assignment"),
    ("{ x }", 0, "blocks are not allowed"),
    ("vec![x]", 0, "macros are not allowed"),
    ("|y| y", 0, "closures are not allowed"),
    ("x / (2 - 2)", 4, "division by zero"),
    ("x / 0", 4, "division by zero"),
    ("1e400 * x", 0, "not a finite f64"),
    ("x * (0.0).ln()", 4, "evaluates to -inf"),
    ("x % 2", 2, "operator `%` is not allowed"),
    ("x as f64", 2, "casts"),
    ("x.sin", 0, "field access"),
    ("x.sin(2)", 0, "takes exactly one value"),
    ("sin", 0, "`sin` is a function"),
    ("\"x\"", 0, "only numeric literals"),
    ("x + \"y", 4, "string and character literals"),
    ("2u8 * x", 0, "suffix `u8`"),
    ("x + ", 3, "not a valid expression"),
    ("(x + 1", 0, "unclosed `(`"),
    ("x + 1)", 5, "unmatched `)`"),
    ("x y", 2, "not a valid expression"),
    ("!x", 0, "operator `!`"),
    ("TAU * x", 0, "unknown name `TAU`"),
    ("x.powi(99999999999)", 7, "does not fit"),
    ("x.powi(-2147483647)", 7, "outside ±1000000"),
    ("x == 1", 2, "operator `==` is not allowed"),
    ("x[0]", 1, "brackets"),
    ("(|v| v)(x)", 1, "closures are not allowed"),
    ("x || 1", 2, "operator `||` is not allowed"),
    ("0..x", 1, "ranges"),
    ("return x", 0, "control flow"),
    ("let y = x", 0, "`let` is a Rust keyword"),
    ("#[inline] x", 0, "attributes"),
    ("x <<= 1", 2, "`<<=` is an assignment"),
    (
        "std::process::exit(1)",
        0,
        "`std::process::exit` is not a known math function",
    ),
];

#[test]
fn bad_expressions_are_rejected_at_the_offending_byte() {
    for &(source, offset, text) in BAD {
        let e = error_x(source);
        assert_eq!(e.offset, offset, "{source:?}: {e}");
        assert!(e.message.contains(text), "{source:?}: {e} lacks {text:?}");
    }
}

#[test]
fn the_variable_name_is_per_call() {
    let e = match parse_expression("x + 1", "t") {
        Ok(s) => panic!("x is not the drive variable, got {s:?}"),
        Err(e) => e,
    };
    assert_eq!(e.offset, 0);
    assert!(e.message.contains("`t`"), "{e}");
}

#[test]
fn offsets_stay_relative_to_each_source() {
    // proc-macro2 keeps a global source map; offsets must not accumulate across calls.
    for _ in 0..3 {
        assert_eq!(error_x("   y").offset, 3);
    }
}

#[test]
fn display_shows_offset_and_message() {
    let e = error_x("x.foo()");
    assert!(e.to_string().starts_with("byte 2: `foo`"), "{e}");
}

/// A megabyte-long integer literal (a model file may hold 16 MiB): the old parser converted
/// it to decimal digits by schoolbook multiplication, quadratic (40 000 digits took 7 s, a
/// megabyte would take over an hour), and quoted all of it in its message; it is now read in
/// one pass and shown elided.
#[test]
fn a_megabyte_integer_literal_is_rejected_with_a_short_message() {
    for literal in ["9".repeat(1 << 20), format!("0x{}", "f".repeat(1 << 20))] {
        let e = error_x(&format!("x + {literal}"));
        assert_eq!(e.offset, 4, "{e}");
        assert!(e.message.contains("is not a finite f64"), "{e}");
        assert!(e.message.len() < 200, "{} bytes", e.message.len());
    }
}

/// Integer literals in every base Rust has, with their values exact or correctly rounded,
/// beyond u128 too: the values are worked out by hand.
#[test]
fn integer_literals_of_every_base_have_their_values() {
    let cases: [(String, f64); 9] = [
        ("0x10".into(), 16.0),
        ("0o17".into(), 15.0),
        ("0b1_0_1".into(), 5.0),
        ("0xFF_ff".into(), 65535.0),
        // All hexadecimal digits: 1·16³ + 15·16² + 6·16 + 4.
        ("0x1f64".into(), 8036.0),
        ("1_000".into(), 1000.0),
        // 2^160 (a 1 and 40 hexadecimal zeros): past u128, exact in an f64.
        (format!("0x1{}", "0".repeat(40)), 2f64.powi(160)),
        // 2^200 + 1 in binary: rounds to 2^200.
        (format!("0b1{}1", "0".repeat(199)), 2f64.powi(200)),
        // 2^53 + 1 rounds to even: 2^53.
        ("9007199254740993".into(), 9_007_199_254_740_992.0),
    ];
    for (source, want) in cases {
        assert_eq!(parse_x(&source), Scalar::Const(want), "{source}");
    }
}

/// Hostile inputs are refused with their limit's message at the offending byte, within a
/// small stack: the screen refuses deep nesting before the parser recurses, the lexer keeps
/// no more tokens than the limit, and the conversion stops at the tree depth limit. Run on a
/// thread of 512 KiB, a quarter of a default thread's stack.
#[test]
fn hostile_inputs_are_refused_in_a_small_stack() {
    let n = 100_000;
    let cases: Vec<(String, usize, String)> = vec![
        // The 33rd `(` (offset 32) is one level too deep.
        (
            format!("{}x{}", "(".repeat(n), ")".repeat(n)),
            32,
            format!("more than {MAX_NESTING} levels"),
        ),
        (
            "-".repeat(n) + "x",
            32,
            format!("more than {MAX_NESTING} levels"),
        ),
        // `sin(` is 4 bytes: the 33rd `(` is at 32·4 + 3.
        (
            format!("{}x{}", "sin(".repeat(n), ")".repeat(n)),
            131,
            format!("more than {MAX_NESTING} levels"),
        ),
        // A megabyte of `x+`: the 2001st token, at byte 2000, is one too many.
        (
            "x+".repeat(1 << 19) + "x",
            2000,
            format!("more than {MAX_TOKENS} tokens"),
        ),
        // 600 additions written without parentheses: a left-deep tree whose 257th level is
        // the sum starting at byte 0.
        (
            "x".to_string() + &" + x".repeat(600),
            0,
            format!("more than {MAX_TREE_DEPTH} operations"),
        ),
        // A chain of 600 method calls, as deep.
        (
            "x".to_string() + &".sin()".repeat(600),
            0,
            format!("more than {MAX_TREE_DEPTH} operations"),
        ),
    ];
    let outcome = std::thread::Builder::new()
        .stack_size(512 * 1024)
        .spawn(move || {
            for (source, offset, text) in cases {
                let e = error_x(&source);
                assert_eq!(e.offset, offset, "{}…: {e}", &source[..20]);
                assert!(e.message.contains(&text), "{}…: {e}", &source[..20]);
            }
        })
        .map(std::thread::JoinHandle::join);
    assert!(matches!(outcome, Ok(Ok(()))), "{outcome:?}");
}

/// A surface's expression in x and y: each name becomes its own variable, evaluates at a
/// point, and an unknown name lists both variables.
#[test]
fn two_variables_parse_as_a_surface_expression() {
    let f = match parse_expression_in("x*x - y.powi(2) + a*y", &["x", "y"], &["a"]) {
        Ok(f) => f.resolve_all(&[0.5]),
        Err(e) => panic!("{e}"),
    };
    let (x, y) = (|| Box::new(Scalar::Var(0)), || Box::new(Scalar::Var(1)));
    let a = Box::new(Scalar::Const(0.5));
    let expected = Scalar::Add(
        Box::new(Scalar::Sub(
            Box::new(Scalar::Mul(x(), x())),
            Box::new(Scalar::Powi(y(), 2)),
        )),
        Box::new(Scalar::Mul(a, y())),
    );
    assert_eq!(f, expected);
    // 1.5² − (−2)² + 0.5 · (−2), exact in binary.
    assert_eq!(f.eval_at(&[1.5, -2.0]), 2.25 - 4.0 - 1.0);
    // One variable given: the second is not there.
    assert!(f.eval(1.5).is_nan());
    let e = match parse_expression_in("x + z", &["x", "y"], &[]) {
        Err(e) => e,
        Ok(f) => panic!("accepted {f:?}"),
    };
    assert_eq!(e.offset, 4, "{e}");
    assert!(
        e.message
            .contains("the variables allowed here are `x` and `y`"),
        "{e}"
    );
    // A one-variable expression still refuses `y`.
    let e = error_x("x + y");
    assert!(
        e.message.contains("the only variable allowed here is `x`"),
        "{e}"
    );
}
