//! Linear growth of the recursive terms (issue 4 §4), with the interpreter-side operation
//! counts (nothing is compiled or timed): over the chain family of `common/chain.rs`, the
//! operations of F, of Q and of the constraint bias c per body stay bounded as N grows,
//! while M, with N² entries, may grow quadratically.

use crate::chain;

use camchain_codegen::Derivation;
use camchain_codegen::schema::parse_model;
use std::path::Path;

fn counts(n: usize) -> [usize; 4] {
    let model =
        parse_model(&chain::chain_ron(n), Path::new("chain.ron")).unwrap_or_else(|e| panic!("{e}"));
    let d = Derivation::new(&model);
    let g = &d.graph;
    let dy = &d.dynamics;
    let c = &d.contacts[0];
    [
        g.op_count(&dy.inertial).total(),
        g.op_count(&dy.applied).total(),
        g.op_count(&[c.bias]).total(),
        g.op_count(&dy.mass.concat()).total(),
    ]
}

#[test]
fn recursive_terms_grow_linearly_and_the_mass_matrix_at_most_quadratically() {
    let sizes = [2usize, 4, 8, 16];
    let all: Vec<[usize; 4]> = sizes.iter().map(|&n| counts(n)).collect();
    for (n, c) in sizes.iter().zip(&all) {
        println!(
            "N = {n:>2}: F {:>5}  Q {:>5}  c {:>5}  M {:>6}",
            c[0], c[1], c[2], c[3]
        );
    }
    // The joint kinds cycle with period 4, so N = 4 → 8 and N = 8 → 16 add whole periods: for
    // a term linear in N the operations added per body are the same in both steps (5% margin
    // for the base and tip terms that are not exactly periodic); a quadratic term's grow.
    let added = |k: usize, from: usize, to: usize| {
        (all[to][k] - all[from][k]) as f64 / (sizes[to] - sizes[from]) as f64
    };
    for (k, name) in ["F", "Q", "c"].iter().enumerate() {
        let (early, late) = (added(k, 1, 2), added(k, 2, 3));
        assert!(
            late <= 1.05 * early,
            "{name}: {early:.1} ops per added body from N = 4 to 8, {late:.1} from 8 to 16"
        );
    }
    // M has N² entries: its increments grow, but no faster than quadratically (the added
    // operations per body at most double when N doubles, with the same margin).
    let (early, late) = (added(3, 1, 2), added(3, 2, 3));
    assert!(
        late <= 2.1 * early,
        "M: {early:.1} ops per added body from N = 4 to 8, {late:.1} from 8 to 16"
    );
}
