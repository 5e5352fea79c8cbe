//! Deep chains and large models: no pass recurses on the depth of the expression graph, so a
//! long chain derives and emits in a small stack; and a model too large for the machine is
//! refused with an error naming its file, its size and the limit, in bounded memory. (Before,
//! `camchain ops` on a 1000-body planar chain ran for 108 s, took 5.4 GB and died of a stack
//! overflow.)

use crate::chain::planar_chain_ron;
use camchain_codegen::expr::Graph;
use camchain_codegen::linear::collect_linear;
use camchain_codegen::{EmitOptions, generate_source};
use std::path::Path;

/// A quarter of a test thread's default stack (2 MiB): enough for what the formatter of the
/// generated code needs at the nesting it is given, far too little for a recursion per level
/// of a deep expression.
const SMALL_STACK: usize = 512 << 10;

/// Runs `f` on a thread with a [`SMALL_STACK`] (a stack overflow aborts the test binary).
fn in_small_stack<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    in_stack(SMALL_STACK, f)
}

/// Runs `f` on a thread with a stack of `bytes`.
fn in_stack<T: Send + 'static>(bytes: usize, f: impl FnOnce() -> T + Send + 'static) -> T {
    std::thread::Builder::new()
        .stack_size(bytes)
        .spawn(f)
        .expect("a thread")
        .join()
        .expect("the work does not panic")
}

#[test]
fn deep_expressions_differentiate_and_substitute_in_a_small_stack() {
    in_small_stack(|| {
        // e_{k+1} = sin(e_k) + x, 100 000 levels deep (each level two nodes): a recursive
        // walk takes some 100 bytes of stack per node, tens of megabytes here.
        const LEVELS: usize = 100_000;
        let mut g = Graph::new();
        let (x, y) = (g.var("x"), g.var("y"));
        let mut e = x;
        for _ in 0..LEVELS {
            let s = g.sin(e);
            e = g.add(s, x);
        }
        let de = g.diff(e, x);
        let ey = g.substitute(e, x, y);
        // The same recurrence in numbers: v' = sin v + x, d' = cos v · d + 1.
        let recurrence = |x0: f64| {
            let (mut v, mut d) = (x0, 1.0);
            for _ in 0..LEVELS {
                (v, d) = (v.sin() + x0, v.cos() * d + 1.0);
            }
            (v, d)
        };
        let (x0, y0) = (0.3, -0.7);
        let (v, d) = recurrence(x0);
        let (vy, _) = recurrence(y0);
        let got = g.eval(&[e, de, ey], &[x0, y0]);
        // The graph computes the same operations in the same order (folding only merges
        // constants, of which there are none): equal to rounding (values of order 1).
        assert!((got[0] - v).abs() < 1e-12, "{} vs {v}", got[0]);
        assert!(
            (got[1] - d).abs() < 1e-12 * d.abs().max(1.0),
            "{} vs {d}",
            got[1]
        );
        assert!((got[2] - vy).abs() < 1e-12, "{} vs {vy}", got[2]);
    });
}

#[test]
fn a_deep_sum_collects_in_a_small_stack() {
    // A sum of 3000 terms, each used once, nested as deep as it is long: the linear pass
    // flattens it into one combination, descending through every level. (It rebuilds every
    // partial sum on the way, so its cost grows with the square of the depth: 3000 keeps it
    // short, and a recursive descent already overflows the 64 KiB stack.)
    const TERMS: usize = 3000;
    let (collected, direct) = in_stack(64 << 10, || {
        let mut g = Graph::new();
        let x = g.var("x");
        let mut sum = g.zero();
        for k in 0..TERMS {
            let scaled = g.scale(1.0 + k as f64 * 1e-3, x);
            let term = g.sin(scaled);
            sum = g.add(sum, term);
        }
        let mut roots = [sum];
        collect_linear(&mut g, &mut roots);
        let x0 = 0.3;
        let direct: f64 = (0..TERMS)
            .map(|k| ((1.0 + k as f64 * 1e-3) * x0).sin())
            .sum();
        (g.eval(&roots, &[x0])[0], direct)
    });
    // Terms of magnitude < 1 summed in the same order: rounding only.
    assert!(
        (collected - direct).abs() < 1e-12 * direct.abs(),
        "{collected} vs {direct}"
    );
}

/// The deepest nesting of parentheses in a text.
fn paren_depth(code: &str) -> usize {
    let (mut depth, mut deepest) = (0usize, 0usize);
    for c in code.chars() {
        match c {
            '(' => {
                depth += 1;
                deepest = deepest.max(depth);
            }
            ')' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    deepest
}

#[test]
fn a_deep_chain_generates_in_a_small_stack_with_shallow_expressions() {
    // A planar chain of 64 bodies: its kinetic energy is one sum through every body, 190
    // levels deep when written inline, which overflowed a 512 KiB stack in the parser of
    // the generated code (and a 1000-body chain the main thread's 8 MiB).
    let generated = in_small_stack(|| {
        generate_source(
            &planar_chain_ron(64),
            Path::new("planar64.ron"),
            &EmitOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{e}"))
    });
    // A term nested deeper than 32 levels gets a name of its own, so no expression nests
    // much deeper than that (a few levels more for a statement's own brackets).
    let depth = paren_depth(&generated.code);
    assert!(depth <= 40, "parentheses nested {depth} deep");
}

#[test]
fn a_thousand_body_chain_is_refused_with_the_file_and_the_limit() {
    // The default limit (4 194 304 nodes) refuses it after some 6 s of work and 500 MB; a
    // lower one, the same way, sooner.
    let options = EmitOptions {
        node_limit: 250_000,
        ..EmitOptions::default()
    };
    let e = in_small_stack(move || {
        generate_source(
            &planar_chain_ron(1000),
            Path::new("models/planar1000.ron"),
            &options,
        )
        .expect_err("refused")
    });
    let message = e.to_string();
    for part in [
        "models/planar1000.ron: ",
        "too large to derive",
        "its 1000 bodies",
        "more than 250000 expression nodes (the limit",
    ] {
        assert!(message.contains(part), "{part:?} not in {message}");
    }
}

#[test]
fn a_model_whose_code_is_too_long_is_refused_before_it_is_formatted() {
    // A 16-body planar chain's module is about 250 kB; with a limit of 100 kB it is refused
    // (the default, 32 MiB, refuses a 600-body planar chain and a 300-body spatial one).
    let options = EmitOptions {
        code_limit: 100_000,
        ..EmitOptions::default()
    };
    let e = generate_source(
        &planar_chain_ron(16),
        Path::new("models/planar16.ron"),
        &options,
    )
    .expect_err("refused");
    let message = e.to_string();
    for part in [
        "models/planar16.ron: ",
        "too large to generate code for",
        "longer than 100000 bytes (the limit",
    ] {
        assert!(message.contains(part), "{part:?} not in {message}");
    }
    // Within the default it is generated.
    generate_source(
        &planar_chain_ron(16),
        Path::new("models/planar16.ron"),
        &EmitOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn a_graph_stops_growing_at_its_node_limit() {
    let mut g = Graph::with_node_limit(100);
    let x = g.var("x");
    let mut e = x;
    for k in 0..1000 {
        let c = g.constant(f64::from(k));
        let p = g.mul(e, x);
        e = g.add(p, c);
    }
    assert!(g.exhausted());
    // The limit, and one constant NaN that stands for every node asked for beyond it.
    assert_eq!(g.len(), 101);
    assert!(g.eval(&[e], &[0.5])[0].is_nan());
    // Variables are not counted: one more is still made.
    let y = g.var("y");
    assert_eq!(g.var_names()[1], "y");
    assert_eq!(g.eval(&[y], &[0.5, 2.0])[0], 2.0);
}
