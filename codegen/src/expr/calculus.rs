//! Differentiation and substitution on the graph.
//!
//! Both walk the expression below a root, and an expression can be as deep as the chain it
//! describes is long (the tip of a 1000-body chain sits on a sum through every body), so both
//! walk with an explicit stack of tasks instead of recursing: their stack use does not grow
//! with the depth of the graph. The walk is the post-order of the recursive definitions
//! (operands first, the left one before the right one, each completely), so new nodes are
//! created in the same order, and get the same ids, as a recursive walk would give them.

use super::{Graph, Id, Implicit, Node};
use crate::profile::Func;
use std::collections::HashMap;

/// One step of a walk.
enum Task {
    /// Look at a node: nothing when its image is known, else its operands first.
    Visit(Id),
    /// Build a node's image from its operands' images (all known by now).
    Combine(Id),
    /// The derivative of implicit variable `s`: input `k` next, with the numerator so far
    /// (see [`Graph::diff`]).
    Implicit { s: Id, k: usize, numerator: Id },
}

/// The operands of an operation node, left first (none for constants and variables).
fn operands(node: Node) -> [Option<Id>; 2] {
    match node {
        Node::Const(_) | Node::Var(_) => [None, None],
        Node::Add(a, b)
        | Node::Mul(a, b)
        | Node::Div(a, b)
        | Node::Powf(a, b)
        | Node::Grid(_, _, a, b) => [Some(a), Some(b)],
        Node::Neg(a) | Node::Powi(a, _) | Node::Call(_, a) | Node::Table(_, _, a) => {
            [Some(a), None]
        }
    }
}

/// Queues `Combine(id)` and then a visit of each operand, so that the left operand is
/// walked first and the node is combined after both.
fn push_operands(tasks: &mut Vec<Task>, id: Id, operands: [Option<Id>; 2]) {
    tasks.push(Task::Combine(id));
    for operand in operands.into_iter().rev().flatten() {
        tasks.push(Task::Visit(operand));
    }
}

impl Graph {
    /// ∂e/∂x for a variable node `x`, memoised within the call.
    ///
    /// An implicit variable s (see [`Implicit`]) differentiates by the implicit-function
    /// theorem: ds/dx = −(Σ ∂ψ/∂p_i · dp_i/dx) / ψ'(s), the partial derivatives taken at
    /// (s; inputs).
    pub fn diff(&mut self, e: Id, x: Id) -> Id {
        let mut memo = HashMap::new();
        self.diff_memo(e, x, &mut memo)
    }

    /// ∂e/∂x for many expressions sharing one memo table (cheaper for Jacobians).
    pub fn diff_many(&mut self, es: &[Id], x: Id) -> Vec<Id> {
        let mut memo = HashMap::new();
        es.iter()
            .map(|&e| self.diff_memo(e, x, &mut memo))
            .collect()
    }

    fn diff_memo(&mut self, e: Id, x: Id, memo: &mut HashMap<Id, Id>) -> Id {
        let mut tasks = vec![Task::Visit(e)];
        while let Some(task) = tasks.pop() {
            match task {
                Task::Visit(id) => {
                    if memo.contains_key(&id) {
                        continue;
                    }
                    if id != x && self.implicit_of(id).is_some() {
                        let numerator = self.zero();
                        tasks.push(Task::Implicit {
                            s: id,
                            k: 0,
                            numerator,
                        });
                    } else {
                        push_operands(&mut tasks, id, operands(self.node(id)));
                    }
                }
                Task::Combine(id) => {
                    if !memo.contains_key(&id) {
                        let d = self.diff_combine(id, x, memo);
                        memo.insert(id, d);
                    }
                }
                Task::Implicit { s, k, numerator } => {
                    self.diff_implicit_step(s, k, numerator, memo, &mut tasks);
                }
            }
        }
        memo[&e]
    }

    /// The derivative of node `e` (not an implicit variable) from its operands'.
    fn diff_combine(&mut self, e: Id, x: Id, memo: &HashMap<Id, Id>) -> Id {
        let d = |c: Id| memo[&c];
        match self.node(e) {
            Node::Const(_) => self.zero(),
            Node::Var(_) => {
                if e == x {
                    self.one()
                } else {
                    self.zero()
                }
            }
            Node::Add(a, b) => self.add(d(a), d(b)),
            Node::Mul(a, b) => {
                let (da, db) = (d(a), d(b));
                let t1 = self.mul(da, b);
                let t2 = self.mul(a, db);
                self.add(t1, t2)
            }
            Node::Neg(a) => self.neg(d(a)),
            Node::Div(a, b) => {
                let (da, db) = (d(a), d(b));
                let t1 = self.div(da, b);
                let q = self.div(e, b);
                let t2 = self.mul(q, db);
                self.sub(t1, t2)
            }
            Node::Powi(a, n) => {
                let da = d(a);
                let p = self.powi(a, n - 1);
                let np = self.scale(f64::from(n), p);
                self.mul(np, da)
            }
            Node::Powf(a, b) => {
                let (da, db) = (d(a), d(b));
                let ln_a = self.call(Func::Ln, a);
                let t1 = self.mul(db, ln_a);
                let ba = self.div(b, a);
                let t2 = self.mul(ba, da);
                let inner = self.add(t1, t2);
                self.mul(e, inner)
            }
            Node::Call(f, a) => {
                let da = d(a);
                if self.is_zero(da) {
                    return self.zero();
                }
                let outer = self.derivative_of_call(f, a, e);
                self.mul(outer, da)
            }
            Node::Table(t, order, a) => {
                let da = d(a);
                if self.is_zero(da) {
                    return self.zero();
                }
                let outer = self.table(t, order + 1, a);
                self.mul(outer, da)
            }
            Node::Grid(k, (p, q), a, b) => {
                // ∂S_pq/∂v = S_(p+1)q ∂a/∂v + S_p(q+1) ∂b/∂v.
                let (da, db) = (d(a), d(b));
                let along_x = if self.is_zero(da) {
                    self.zero()
                } else {
                    let outer = self.grid(k, (p + 1, q), a, b);
                    self.mul(outer, da)
                };
                let along_y = if self.is_zero(db) {
                    self.zero()
                } else {
                    let outer = self.grid(k, (p, q + 1), a, b);
                    self.mul(outer, db)
                };
                self.add(along_x, along_y)
            }
        }
    }

    /// One input of the derivative of the implicit variable `s`: its term ∂ψ/∂p_k · dp_k/dx
    /// added to the numerator once dp_k/dx is known (visited first otherwise), or, after
    /// the last input, ds/dx = −numerator / ψ'(s).
    fn diff_implicit_step(
        &mut self,
        s: Id,
        k: usize,
        numerator: Id,
        memo: &mut HashMap<Id, Id>,
        tasks: &mut Vec<Task>,
    ) {
        let Some(def) = self.implicit_of(s).cloned() else {
            let zero = self.zero();
            memo.insert(s, zero);
            return;
        };
        let inputs = def.placeholders.len().min(def.inputs.len());
        if k < inputs {
            let (p, input) = (def.placeholders[k], def.inputs[k]);
            let Some(&d_input) = memo.get(&input) else {
                tasks.push(Task::Implicit { s, k, numerator });
                tasks.push(Task::Visit(input));
                return;
            };
            let mut numerator = numerator;
            if !self.is_zero(d_input) {
                let partial = self.diff(def.residual, p);
                let partial = self.at_solution(partial, &def, s);
                let term = self.mul(partial, d_input);
                numerator = self.add(numerator, term);
            }
            tasks.push(Task::Implicit {
                s,
                k: k + 1,
                numerator,
            });
            return;
        }
        let d = if self.is_zero(numerator) {
            numerator
        } else {
            let slope = self.at_solution(def.derivative, &def, s);
            let ratio = self.div(numerator, slope);
            self.neg(ratio)
        };
        memo.insert(s, d);
    }

    /// An expression of (s; p) with the placeholders replaced by the inputs and s by the
    /// implicit variable itself.
    pub fn at_solution(&mut self, e: Id, def: &Implicit, s: Id) -> Id {
        let mut e = self.substitute(e, def.unknown, s);
        for (&p, &input) in def.placeholders.iter().zip(&def.inputs) {
            e = self.substitute(e, p, input);
        }
        e
    }

    /// f'(a) for the node e = f(a).
    fn derivative_of_call(&mut self, f: Func, a: Id, e: Id) -> Id {
        let one = self.one();
        match f {
            Func::Sin => self.cos(a),
            Func::Cos => {
                let s = self.sin(a);
                self.neg(s)
            }
            Func::Tan => {
                let t2 = self.powi(e, 2);
                self.add(one, t2)
            }
            Func::Exp => e,
            Func::Ln => self.div(one, a),
            Func::Sqrt => {
                let two_e = self.scale(2.0, e);
                self.div(one, two_e)
            }
            Func::Sinh => self.call(Func::Cosh, a),
            Func::Cosh => self.call(Func::Sinh, a),
            Func::Tanh => {
                let t2 = self.powi(e, 2);
                self.sub(one, t2)
            }
            Func::Atan => {
                let a2 = self.powi(a, 2);
                let den = self.add(one, a2);
                self.div(one, den)
            }
        }
    }

    /// e with the variable `x` replaced by the expression `by`.
    ///
    /// An implicit variable whose inputs contain `x` becomes a new implicit variable with the
    /// same definition on the substituted inputs.
    pub fn substitute(&mut self, e: Id, x: Id, by: Id) -> Id {
        if e == x {
            return by;
        }
        let mut memo: HashMap<Id, Id> = HashMap::new();
        let mut tasks = vec![Task::Visit(e)];
        while let Some(task) = tasks.pop() {
            match task {
                Task::Visit(id) => {
                    if id == x || memo.contains_key(&id) {
                        continue;
                    }
                    match self.implicit_of(id) {
                        Some(def) => {
                            tasks.push(Task::Combine(id));
                            for &input in def.inputs.iter().rev() {
                                tasks.push(Task::Visit(input));
                            }
                        }
                        None => push_operands(&mut tasks, id, operands(self.node(id))),
                    }
                }
                Task::Combine(id) => {
                    if memo.contains_key(&id) {
                        continue;
                    }
                    let image = |c: Id| if c == x { by } else { memo[&c] };
                    let r = if self.implicit_of(id).is_some() {
                        self.subst_implicit(id, image)
                    } else {
                        self.rebuild_with(id, image)
                    };
                    memo.insert(id, r);
                }
                // Only differentiation queues these.
                Task::Implicit { .. } => {}
            }
        }
        memo[&e]
    }

    /// An implicit variable with its inputs mapped by `image`: the same definition on the
    /// new inputs (a new variable), or the variable itself when nothing changes.
    fn subst_implicit(&mut self, e: Id, image: impl Fn(Id) -> Id) -> Id {
        let Some(mut def) = self.implicit_of(e).cloned() else {
            return e;
        };
        let inputs: Vec<Id> = def.inputs.iter().map(|&i| image(i)).collect();
        if inputs == def.inputs {
            return e;
        }
        def.inputs = inputs;
        let name = format!("{}_{}", self.vars[self.var_index_of(e)], self.len());
        self.implicit(&name, def)
    }

    fn var_index_of(&self, id: Id) -> usize {
        match self.node(id) {
            Node::Var(k) => k as usize,
            _ => 0,
        }
    }
}
