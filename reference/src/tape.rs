//! Profile expressions flattened into a tape: every distinct subexpression once, in an order
//! where operands come before their operations, for the many evaluations of a contact search.
//!
//! A profile's expressions are trees ([`Scalar`]), and those built in code repeat
//! subexpressions many times over: a cam designed from a motion law writes the pitch point,
//! its tangent and the tangent's length into both coordinates, and each coordinate holds the
//! law a dozen times. The reference's search for a contact point evaluates the profile at
//! hundreds of points per call, so it evaluates a tape instead: the trees of one profile
//! (its x and y together) with equal subtrees merged, by structure, when the tape is built.
//! Each entry is then computed once per evaluation, in plain `f64` or in second-order jets
//! ([`Jet2`], the reference's forward-mode differentiation): the same arithmetic as walking the
//! trees ([`crate::jet::eval_on`]), in the same order within each operation, so the values are
//! those of the trees.

use crate::jet::Jet2;
use camchain_model::profile::{Func, Gridded, Scalar, Tabulated};
use std::collections::HashMap;
use std::sync::Arc;

/// One entry of the tape; operands are indices of earlier entries.
#[derive(Debug, Clone)]
enum Entry {
    Const(f64),
    /// Variable i of the expressions (a surface's y is 1).
    Var(u8),
    Neg(usize),
    Add(usize, usize),
    Sub(usize, usize),
    Mul(usize, usize),
    Div(usize, usize),
    Powi(usize, i32),
    Powf(usize, usize),
    Call(Func, usize),
    Table(Arc<Tabulated>, u8, usize),
    Grid(Arc<Gridded>, (u8, u8), usize, usize),
}

/// What makes two entries the same: the operation, its constants and its operands.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
enum Key {
    Const(u64),
    Var(u8),
    Unary(u8, usize, i64),
    Binary(u8, usize, usize),
    Table(usize, u8, usize),
    Grid(usize, (u8, u8), usize, usize),
}

/// Expressions of one variable flattened with their common subexpressions merged.
#[derive(Debug, Clone, Default)]
pub struct Tape {
    entries: Vec<Entry>,
    outputs: Vec<usize>,
}

impl Tape {
    /// The tape of `expressions`, whose values [`Tape::eval`] returns in their order. A
    /// parameter left unresolved evaluates to NaN, as in the trees.
    pub fn new(expressions: &[&Scalar]) -> Self {
        let mut builder = Builder::default();
        let outputs = expressions.iter().map(|e| builder.add(e)).collect();
        Tape {
            entries: builder.entries,
            outputs,
        }
    }

    /// The expressions' values at x.
    pub fn eval(&self, x: f64) -> Vec<f64> {
        self.eval_at(&[x])
    }

    /// The expressions' values with variable i at `vars[i]` (a surface's x and y).
    pub fn eval_at(&self, vars: &[f64]) -> Vec<f64> {
        let mut values: Vec<f64> = Vec::with_capacity(self.entries.len());
        for entry in &self.entries {
            let v = |k: &usize| values[*k];
            let value = match entry {
                Entry::Const(c) => *c,
                Entry::Var(i) => vars.get(usize::from(*i)).copied().unwrap_or(f64::NAN),
                Entry::Neg(a) => -v(a),
                Entry::Add(a, b) => v(a) + v(b),
                Entry::Sub(a, b) => v(a) - v(b),
                Entry::Mul(a, b) => v(a) * v(b),
                Entry::Div(a, b) => v(a) / v(b),
                Entry::Powi(a, n) => v(a).powi(*n),
                Entry::Powf(a, b) => v(a).powf(v(b)),
                Entry::Call(f, a) => Jet2::constant(v(a)).apply(*f).v,
                Entry::Table(t, order, a) => crate::spline::derivative(t, *order, v(a)),
                Entry::Grid(g, order, a, b) => crate::grid::derivative(g, *order, v(a), v(b)),
            };
            values.push(value);
        }
        self.outputs.iter().map(|&k| values[k]).collect()
    }

    /// The expressions' values with their first two derivatives, the variable given as the
    /// jet `x`.
    pub fn eval_jet(&self, x: Jet2) -> Vec<Jet2> {
        self.eval_jet_at(&[x])
    }

    /// The expressions' jets with variable i given as the jet `vars[i]` (a surface along a
    /// line through (x, y): its directional derivatives).
    pub fn eval_jet_at(&self, vars: &[Jet2]) -> Vec<Jet2> {
        let mut values: Vec<Jet2> = Vec::with_capacity(self.entries.len());
        for entry in &self.entries {
            let v = |k: &usize| values[*k];
            let value = match entry {
                Entry::Const(c) => Jet2::constant(*c),
                Entry::Var(i) => vars
                    .get(usize::from(*i))
                    .copied()
                    .unwrap_or(Jet2::constant(f64::NAN)),
                Entry::Neg(a) => -v(a),
                Entry::Add(a, b) => v(a) + v(b),
                Entry::Sub(a, b) => v(a) - v(b),
                Entry::Mul(a, b) => v(a) * v(b),
                Entry::Div(a, b) => v(a) / v(b),
                Entry::Powi(a, n) => v(a).powi(*n),
                Entry::Powf(a, b) => v(a).powf(v(b)),
                Entry::Call(f, a) => v(a).apply(*f),
                Entry::Table(t, order, a) => {
                    let inner = v(a);
                    let d = |k: u8| crate::spline::derivative(t, order + k, inner.v);
                    inner.compose(d(0), d(1), d(2))
                }
                Entry::Grid(g, (p, q), a, b) => {
                    let (a, b) = (v(a), v(b));
                    Jet2::compose2(a, b, |i, j| {
                        crate::grid::derivative(g, (p + i, q + j), a.v, b.v)
                    })
                }
            };
            values.push(value);
        }
        self.outputs.iter().map(|&k| values[k]).collect()
    }

    /// Entries on the tape (each distinct subexpression once).
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// True for a tape of no expression.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

/// Builds a tape, merging equal entries.
#[derive(Default)]
struct Builder {
    entries: Vec<Entry>,
    index: HashMap<Key, usize>,
}

impl Builder {
    /// The index of `e`'s entry, its operands added first.
    fn add(&mut self, e: &Scalar) -> usize {
        let (key, entry) = match e {
            Scalar::Const(c) => (Key::Const(c.to_bits()), Entry::Const(*c)),
            Scalar::Var(i) => (Key::Var(*i), Entry::Var(*i)),
            Scalar::Param(_) => (Key::Const(f64::NAN.to_bits()), Entry::Const(f64::NAN)),
            Scalar::Neg(a) => {
                let a = self.add(a);
                (Key::Unary(0, a, 0), Entry::Neg(a))
            }
            Scalar::Powi(a, n) => {
                let a = self.add(a);
                (Key::Unary(1, a, i64::from(*n)), Entry::Powi(a, *n))
            }
            Scalar::Call(f, a) => {
                let a = self.add(a);
                (Key::Unary(2 + *f as u8, a, 0), Entry::Call(*f, a))
            }
            Scalar::Add(a, b) => self.binary(0, a, b, Entry::Add),
            Scalar::Sub(a, b) => self.binary(1, a, b, Entry::Sub),
            Scalar::Mul(a, b) => self.binary(2, a, b, Entry::Mul),
            Scalar::Div(a, b) => self.binary(3, a, b, Entry::Div),
            Scalar::Powf(a, b) => self.binary(4, a, b, Entry::Powf),
            Scalar::Table(t, order, a) => {
                let a = self.add(a);
                // The function's address identifies it: the tape holds it, so it stays.
                let key = Key::Table(Arc::as_ptr(t) as usize, *order, a);
                (key, Entry::Table(t.clone(), *order, a))
            }
            Scalar::Grid(g, order, a, b) => {
                let (a, b) = (self.add(a), self.add(b));
                let key = Key::Grid(Arc::as_ptr(g) as usize, *order, a, b);
                (key, Entry::Grid(g.clone(), *order, a, b))
            }
        };
        if let Some(&k) = self.index.get(&key) {
            return k;
        }
        self.entries.push(entry);
        let k = self.entries.len() - 1;
        self.index.insert(key, k);
        k
    }

    fn binary(
        &mut self,
        op: u8,
        a: &Scalar,
        b: &Scalar,
        entry: fn(usize, usize) -> Entry,
    ) -> (Key, Entry) {
        let (a, b) = (self.add(a), self.add(b));
        (Key::Binary(op, a, b), entry(a, b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::{eval_on, eval_with};
    use camchain_model::profile::parse_expression;

    /// A surface's expression in x and y: the tape's values and jets along a line are the
    /// tree's, bit for bit, and a variable not given is NaN.
    #[test]
    fn two_variables_evaluate_like_the_tree() {
        let f = camchain_model::profile::parse_expression_in(
            "x.powi(2) * y + (x * y).sin() - y / (1.0 + x * x)",
            &["x", "y"],
            &[],
        )
        .expect("parses");
        let tape = Tape::new(&[&f]);
        for (x, y) in [(0.3, -1.1), (-2.0, 0.5), (1.7, 2.4)] {
            assert_eq!(
                tape.eval_at(&[x, y])[0].to_bits(),
                f.eval_at(&[x, y]).to_bits()
            );
            let line = [
                Jet2 {
                    v: x,
                    d1: 0.6,
                    d2: 0.0,
                },
                Jet2 {
                    v: y,
                    d1: -0.8,
                    d2: 0.0,
                },
            ];
            let from_tape = tape.eval_jet_at(&line)[0];
            let from_tree = camchain_model::jet::eval_on_all(&f, &line, &crate::spline::derivative);
            assert_eq!(
                [from_tape.v, from_tape.d1, from_tape.d2].map(f64::to_bits),
                [from_tree.v, from_tree.d1, from_tree.d2].map(f64::to_bits)
            );
        }
        assert!(tape.eval(0.3)[0].is_nan());
    }

    /// The tape gives the trees' values bit for bit (the same operations on the same
    /// operands), and merges what repeats.
    #[test]
    fn the_tape_evaluates_like_the_trees_and_merges_repeats() {
        let x = parse_expression("(x.sin() * 2.0 + x.cos()).sqrt() / (1.0 + x * x)", "x")
            .expect("parses");
        let y = parse_expression("(x.sin() * 2.0 + x.cos()).sqrt() - x.powi(3).atan()", "x")
            .expect("parses");
        let tape = Tape::new(&[&x, &y]);
        // x, sin, 2, ·, cos, +, sqrt shared; the rest once each.
        assert!(tape.len() < 18, "{} entries", tape.len());
        for s in [0.1, 0.7, 1.3] {
            let values = tape.eval(s);
            assert_eq!(values[0].to_bits(), eval_with(&x, s, &[]).to_bits());
            assert_eq!(values[1].to_bits(), eval_with(&y, s, &[]).to_bits());
            let jets = tape.eval_jet(Jet2::variable(s));
            assert_eq!(jets[0], eval_on(&x, Jet2::variable(s)));
            assert_eq!(jets[1], eval_on(&y, Jet2::variable(s)));
        }
    }
}
