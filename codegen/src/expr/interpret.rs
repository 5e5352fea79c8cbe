//! The interpreter: expressions evaluated numerically, so tests can check them without
//! compiling them; and the elementary functions by name.

use super::{Graph, Guess, Id, Implicit, Node};
use crate::profile::Func;
use std::collections::HashSet;

impl Graph {
    /// Evaluates the given roots with `vars[i]` the value of variable i (the interpreter).
    ///
    /// Only the nodes the roots depend on are computed, in id (= topological) order.
    pub fn eval(&self, roots: &[Id], vars: &[f64]) -> Vec<f64> {
        let last = roots.iter().map(|r| r.index() + 1).max().unwrap_or(0);
        // Only what the roots depend on: an implicit variable they do not need is not solved
        // (its solve evaluates its own residual, which may hold earlier implicit variables).
        let needed = self.reachable_until(roots, &HashSet::new());
        let mut values: Vec<f64> = Vec::with_capacity(last);
        for (index, node) in self.nodes[..last].iter().enumerate() {
            if !needed[index] {
                values.push(f64::NAN);
                continue;
            }
            let v = |id: &Id| values[id.index()];
            let value: f64 = match node {
                Node::Const(bits) => f64::from_bits(*bits),
                Node::Var(i) => match self.implicits.get(i) {
                    Some(def) => self.solve_implicit(def, vars, &values),
                    None => vars.get(*i as usize).copied().unwrap_or(f64::NAN),
                },
                Node::Add(a, b) => v(a) + v(b),
                Node::Mul(a, b) => v(a) * v(b),
                Node::Neg(a) => -v(a),
                Node::Div(a, b) => v(a) / v(b),
                Node::Powi(a, n) => v(a).powi(*n),
                Node::Powf(a, b) => v(a).powf(v(b)),
                Node::Call(f, a) => apply(*f, v(a)),
                Node::Table(t, order, a) => self
                    .tables
                    .get(*t as usize)
                    .map_or(f64::NAN, |table| table.derivative(*order, v(a))),
                Node::Grid(k, order, a, b) => self
                    .grids
                    .get(*k as usize)
                    .map_or(f64::NAN, |grid| grid.derivative(*order, v(a), v(b))),
            };
            values.push(value);
        }
        roots.iter().map(|r| values[r.index()]).collect()
    }

    /// The interpreter's value of an implicit variable: the same Newton solve as the
    /// emitted code's, on the interpreted residual.
    fn solve_implicit(&self, def: &Implicit, vars: &[f64], values: &[f64]) -> f64 {
        let mut local = vars.to_vec();
        let set = |local: &mut Vec<f64>, id: Id, value: f64| {
            if let Node::Var(k) = self.node(id) {
                if local.len() <= k as usize {
                    local.resize(k as usize + 1, f64::NAN);
                }
                local[k as usize] = value;
            }
        };
        let inputs: Vec<f64> = def.inputs.iter().map(|i| values[i.index()]).collect();
        for (&p, &value) in def.placeholders.iter().zip(&inputs) {
            set(&mut local, p, value);
        }
        let guess = match def.guess {
            Guess::Input(i) => inputs[i],
            Guess::Angle { x, y } => inputs[y].atan2(inputs[x]),
            Guess::Scan => f64::NAN,
            Guess::Pitch(pitch) => {
                camchain_runtime::contact::pitch_parameter(inputs[0], inputs[1], pitch, def.range)
            }
        };
        let local = std::cell::RefCell::new(local);
        let eval_at = |s: f64, roots: &[Id]| {
            let mut l = local.borrow_mut();
            set(&mut l, def.unknown, s);
            self.eval(roots, &l)
        };
        camchain_runtime::contact::solve(
            guess,
            def.range,
            |s| {
                let r = eval_at(s, &[def.residual, def.derivative]);
                [r[0], r[1]]
            },
            |s| eval_at(s, &[def.objective])[0],
        )
    }
}

/// Numeric value of an elementary function.
pub fn apply(f: Func, x: f64) -> f64 {
    match f {
        Func::Sin => x.sin(),
        Func::Cos => x.cos(),
        Func::Tan => x.tan(),
        Func::Exp => x.exp(),
        Func::Ln => x.ln(),
        Func::Sqrt => x.sqrt(),
        Func::Sinh => x.sinh(),
        Func::Cosh => x.cosh(),
        Func::Tanh => x.tanh(),
        Func::Atan => x.atan(),
    }
}

/// Method name of an elementary function in Rust.
pub fn method_name(f: Func) -> &'static str {
    match f {
        Func::Sin => "sin",
        Func::Cos => "cos",
        Func::Tan => "tan",
        Func::Exp => "exp",
        Func::Ln => "ln",
        Func::Sqrt => "sqrt",
        Func::Sinh => "sinh",
        Func::Cosh => "cosh",
        Func::Tanh => "tanh",
        Func::Atan => "atan",
    }
}
