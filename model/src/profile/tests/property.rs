//! An independent check of the parser: random expression trees, printed in Rust syntax in
//! every form the language allows (method and call forms, paths, literal spellings, random
//! spacing and comments, redundant parentheses), must parse back to the tree they were
//! printed from, and evaluate as the tree does; or, when the tree divides by a constant zero
//! or holds a constant that is not finite, be rejected for that reason.

use crate::profile::{FUNCTIONS, Func, Scalar, apply, parse_expression};
use proptest::prelude::*;

/// A generated expression, with the choices of how to write it.
#[derive(Debug, Clone)]
enum Tree {
    /// A finite non-negative constant and how to spell it (0: `{:?}`, 1: `{:e}`, 2: suffixed
    /// `f64`, 3: an integer with `_` separators when the value is one).
    Const(f64, u8),
    /// The variable `x`.
    Var,
    /// PI or E, and which path (0: bare, 1: `f64::consts::`, 2: `std::f64::consts::`).
    Named(bool, u8),
    Neg(Box<Tree>),
    Binary(char, Box<Tree>, Box<Tree>),
    /// f(a) and its form (0: `a.f()`, 1: `f(a)`, 2: `f64::f(a)`, 3: `std::f64::f(a)`).
    Call(Func, u8, Box<Tree>),
    /// a.powi(n), its form and the exponent's spelling (0: `n`, 1: `(n)`, 2: `-(|n|)`).
    Powi(Box<Tree>, i32, u8, u8),
    /// a.powf(b) and its form.
    Powf(Box<Tree>, Box<Tree>, u8),
    /// Redundant parentheses.
    Paren(Box<Tree>),
}

impl Tree {
    /// The tree the parser must build (redundant parentheses leave no trace).
    fn scalar(&self) -> Scalar {
        let b = |t: &Tree| Box::new(t.scalar());
        match self {
            Tree::Const(v, _) => Scalar::Const(*v),
            Tree::Var => Scalar::Var(0),
            Tree::Named(pi, _) => Scalar::Const(if *pi {
                std::f64::consts::PI
            } else {
                std::f64::consts::E
            }),
            Tree::Neg(a) => Scalar::Neg(b(a)),
            Tree::Binary(op, l, r) => {
                let make = match op {
                    '+' => Scalar::Add,
                    '-' => Scalar::Sub,
                    '*' => Scalar::Mul,
                    _ => Scalar::Div,
                };
                make(b(l), b(r))
            }
            Tree::Call(f, _, a) => Scalar::Call(*f, b(a)),
            Tree::Powi(a, n, _, _) => Scalar::Powi(b(a), *n),
            Tree::Powf(a, e, _) => Scalar::Powf(b(a), b(e)),
            Tree::Paren(a) => a.scalar(),
        }
    }

    /// Its value at x, computed here (not by [`Scalar::eval`]).
    fn value(&self, x: f64) -> f64 {
        match self {
            Tree::Const(v, _) => *v,
            Tree::Var => x,
            Tree::Named(pi, _) => {
                if *pi {
                    std::f64::consts::PI
                } else {
                    std::f64::consts::E
                }
            }
            Tree::Neg(a) => -a.value(x),
            Tree::Binary(op, l, r) => {
                let (l, r) = (l.value(x), r.value(x));
                match op {
                    '+' => l + r,
                    '-' => l - r,
                    '*' => l * r,
                    _ => l / r,
                }
            }
            Tree::Call(f, _, a) => apply(*f, a.value(x)),
            Tree::Powi(a, n, _, _) => a.value(x).powi(*n),
            Tree::Powf(a, e, _) => a.value(x).powf(e.value(x)),
            Tree::Paren(a) => a.value(x),
        }
    }

    /// Whether the parser must reject the tree: a subtree without the variable whose value
    /// is not finite, or a divisor without the variable equal to 0.
    fn has_bad_constant(&self) -> bool {
        // (mentions the variable, holds a bad constant)
        fn walk(t: &Tree) -> (bool, bool) {
            let (var, bad) = match t {
                Tree::Const(..) | Tree::Named(..) => (false, false),
                Tree::Var => (true, false),
                Tree::Neg(a) | Tree::Call(_, _, a) | Tree::Powi(a, ..) | Tree::Paren(a) => walk(a),
                Tree::Binary(op, l, r) => {
                    let (lv, lb) = walk(l);
                    let (rv, rb) = walk(r);
                    let zero_divisor = *op == '/' && !rv && r.value(0.0) == 0.0;
                    (lv || rv, lb || rb || zero_divisor)
                }
                Tree::Powf(a, e, _) => {
                    let (av, ab) = walk(a);
                    let (ev, eb) = walk(e);
                    (av || ev, ab || eb)
                }
            };
            (var, bad || (!var && !t.value(0.0).is_finite()))
        }
        walk(self).1
    }

    /// Binding strength of the printed form: 1 sums, 2 products, 3 prefix minus, 4 postfix
    /// and atoms.
    fn strength(&self) -> u8 {
        match self {
            Tree::Binary('+' | '-', ..) => 1,
            Tree::Binary(..) => 2,
            Tree::Neg(_) => 3,
            Tree::Call(_, form, _) | Tree::Powi(_, _, form, _) | Tree::Powf(_, _, form)
                if form % 4 == 0 =>
            {
                4
            }
            _ => 5,
        }
    }

    /// Written as an integer literal (`3`, `3_000`), which cannot take a method after a
    /// space (`3. sin()` is the float `3.` and a name).
    fn is_integer_literal(&self) -> bool {
        matches!(self, Tree::Const(v, form) if form % 4 == 3 && v.fract() == 0.0 && *v < 1e15)
    }

    /// Rust source for the tree; `gap` gives the text between two tokens.
    fn print(&self, out: &mut String, gap: &mut dyn FnMut() -> &'static str) {
        match self {
            Tree::Const(v, form) => out.push_str(&literal(*v, *form)),
            Tree::Var => out.push('x'),
            Tree::Named(pi, path) => {
                out.push_str(["", "f64::consts::", "std::f64::consts::"][usize::from(*path % 3)]);
                out.push_str(if *pi { "PI" } else { "E" });
            }
            Tree::Neg(a) => {
                out.push('-');
                out.push_str(gap());
                a.print_at_least(3, out, gap);
            }
            Tree::Binary(op, l, r) => {
                let strength = if matches!(op, '+' | '-') { 1 } else { 2 };
                l.print_at_least(strength, out, gap);
                out.push_str(gap());
                out.push(*op);
                out.push_str(gap());
                // Left-associative: a right operand of the same strength needs parentheses.
                r.print_at_least(strength + 1, out, gap);
            }
            Tree::Call(f, form, a) => {
                let name = FUNCTIONS
                    .iter()
                    .find(|(_, g)| g == f)
                    .map_or("?", |(n, _)| *n);
                call(name, *form, a, &[], out, gap);
            }
            Tree::Powi(a, n, form, spelling) => {
                let exponent = match spelling % 3 {
                    0 => n.to_string(),
                    1 => format!("({n})"),
                    _ if *n < 0 => format!("-({})", n.unsigned_abs()),
                    _ => format!("(({n}))"),
                };
                call("powi", *form, a, &[exponent], out, gap);
            }
            Tree::Powf(a, e, form) => {
                let mut exponent = String::new();
                e.print(&mut exponent, gap);
                call("powf", *form, a, &[exponent], out, gap);
            }
            Tree::Paren(a) => {
                out.push('(');
                out.push_str(gap());
                a.print(out, gap);
                out.push_str(gap());
                out.push(')');
            }
        }
    }

    /// Prints the tree, in parentheses when it binds less tightly than `strength`.
    fn print_at_least(
        &self,
        strength: u8,
        out: &mut String,
        gap: &mut dyn FnMut() -> &'static str,
    ) {
        if self.strength() < strength {
            out.push('(');
            out.push_str(gap());
            self.print(out, gap);
            out.push_str(gap());
            out.push(')');
        } else {
            self.print(out, gap);
        }
    }
}

/// `name` applied to `receiver` and the other arguments `rest` (printed): form 0 is the method
/// `receiver.name(rest)`, the others the call `name(receiver, rest)` through the path
/// `f64::` (form 2) or `std::f64::` (form 3).
fn call(
    name: &str,
    form: u8,
    receiver: &Tree,
    rest: &[String],
    out: &mut String,
    gap: &mut dyn FnMut() -> &'static str,
) {
    if form % 4 == 0 {
        if receiver.is_integer_literal() {
            out.push('(');
            receiver.print(out, gap);
            out.push(')');
        } else {
            receiver.print_at_least(4, out, gap);
        }
        out.push_str(gap());
        out.push('.');
        out.push_str(gap());
        out.push_str(name);
        out.push_str(gap());
        out.push('(');
        out.push_str(&rest.join(", "));
        out.push(')');
    } else {
        out.push_str(["", "", "f64::", "std::f64::"][usize::from(form % 4)]);
        out.push_str(name);
        out.push_str(gap());
        out.push('(');
        out.push_str(gap());
        receiver.print(out, gap);
        for argument in rest {
            out.push(',');
            out.push_str(gap());
            out.push_str(argument);
        }
        out.push_str(gap());
        out.push(')');
    }
}

/// `value` (finite, ≥ 0) spelled as Rust allows: 0 `{:?}`, 1 `{:e}`, 2 `{:?}` suffixed
/// `f64`, 3 an integer with `_` between groups of three digits when the value is one below
/// 10¹⁵ (exact), `{:?}` otherwise.
fn literal(value: f64, form: u8) -> String {
    match form % 4 {
        1 => format!("{value:e}"),
        2 => format!("{value:?}f64"),
        3 if value.fract() == 0.0 && value < 1e15 => {
            let digits = format!("{value:.0}");
            let mut out = String::new();
            for (i, c) in digits.chars().enumerate() {
                if i > 0 && (digits.len() - i) % 3 == 0 {
                    out.push('_');
                }
                out.push(c);
            }
            out
        }
        _ => format!("{value:?}"),
    }
}

/// Text between two tokens: nothing, spaces, a tab, a newline or a comment.
const GAPS: [&str; 7] = ["", " ", "  ", "\t", "\n", " /* c */ ", " // c\n"];

fn tree() -> impl Strategy<Value = Tree> {
    let constant = prop_oneof![
        (0.0..10.0f64),
        (0u32..2000).prop_map(f64::from),
        Just(0.0),
        (-300.0..300.0f64).prop_map(|e| 10f64.powf(e)),
    ];
    let leaf = prop_oneof![
        (constant, any::<u8>()).prop_map(|(v, form)| Tree::Const(v, form)),
        Just(Tree::Var),
        Just(Tree::Var),
        (any::<bool>(), any::<u8>()).prop_map(|(pi, path)| Tree::Named(pi, path)),
    ];
    leaf.prop_recursive(6, 40, 2, |inner| {
        let function = prop::sample::select(FUNCTIONS.iter().map(|(_, f)| *f).collect::<Vec<_>>());
        prop_oneof![
            inner.clone().prop_map(|a| Tree::Neg(Box::new(a))),
            inner.clone().prop_map(|a| Tree::Paren(Box::new(a))),
            (
                prop::sample::select(vec!['+', '-', '*', '/']),
                inner.clone(),
                inner.clone()
            )
                .prop_map(|(op, l, r)| Tree::Binary(op, Box::new(l), Box::new(r))),
            (
                prop::sample::select(vec!['+', '-', '*', '/']),
                inner.clone(),
                inner.clone()
            )
                .prop_map(|(op, l, r)| Tree::Binary(op, Box::new(l), Box::new(r))),
            (function, any::<u8>(), inner.clone()).prop_map(|(f, form, a)| Tree::Call(
                f,
                form,
                Box::new(a)
            )),
            (inner.clone(), -12..12i32, any::<u8>(), any::<u8>())
                .prop_map(|(a, n, form, spelling)| Tree::Powi(Box::new(a), n, form, spelling)),
            (inner.clone(), inner, any::<u8>()).prop_map(|(a, e, form)| Tree::Powf(
                Box::new(a),
                Box::new(e),
                form
            )),
        ]
    })
}

/// Both finite and within `REL` of each other relatively, or equal (both NaN, or the same
/// infinity).
fn close(a: f64, b: f64) -> bool {
    // The parsed tree and the generated one perform the same operations on the same
    // constants (printed to round trip), so they agree exactly; 1e-12 relative is slack for
    // nothing but a tree of another shape.
    const REL: f64 = 1e-12;
    (a.is_nan() && b.is_nan()) || a == b || (a - b).abs() <= REL * a.abs().max(b.abs())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 2000,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn printed_trees_parse_back_to_themselves(
        tree in tree(),
        gaps in prop::collection::vec(prop::sample::select(&GAPS[..]), 1..64),
    ) {
        let mut next = 0;
        let mut gap = || {
            next += 1;
            gaps[next % gaps.len()]
        };
        let mut source = String::new();
        tree.print(&mut source, &mut gap);
        match parse_expression(&source, "x") {
            Ok(parsed) => {
                prop_assert!(!tree.has_bad_constant(), "{source:?} accepted: {parsed:?}");
                prop_assert_eq!(&parsed, &tree.scalar(), "{:?}", source);
                for x in [-1.7, -0.3, 0.0, 0.4, 1.0, 2.9] {
                    let (got, want) = (parsed.eval(x), tree.value(x));
                    prop_assert!(close(got, want), "{source:?} at {x}: {got} != {want}");
                }
            }
            Err(e) => {
                prop_assert!(tree.has_bad_constant(), "{source:?} rejected: {e}");
                prop_assert!(
                    e.message.contains("division by zero") || e.message.contains("evaluates to"),
                    "{source:?}: {e}"
                );
            }
        }
    }
}
