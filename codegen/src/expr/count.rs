//! Operation counts of expressions: what the generated file's header tables and what the
//! build chooses by.

use super::{Graph, Id, Node};
use crate::profile::Func;
use std::collections::HashSet;

/// Operation counts of a set of expressions, each shared node counted once.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct OpCount {
    /// Additions and subtractions (and negations not absorbed into a subtraction).
    pub add_sub: usize,
    /// Multiplications.
    pub mul: usize,
    /// Divisions.
    pub div: usize,
    /// sin and cos.
    pub sin_cos: usize,
    /// Square roots.
    pub sqrt: usize,
    /// Everything else (powi, powf, tan, exp, ln, hyperbolic, atan).
    pub other: usize,
}

impl OpCount {
    /// Sum of all operations.
    pub fn total(&self) -> usize {
        self.add_sub + self.mul + self.div + self.sin_cos + self.sqrt + self.other
    }

    /// Adds the counts of `other` to these.
    pub fn accumulate(&mut self, other: &OpCount) {
        self.add_sub += other.add_sub;
        self.mul += other.mul;
        self.div += other.div;
        self.sin_cos += other.sin_cos;
        self.sqrt += other.sqrt;
        self.other += other.other;
    }
}

impl std::fmt::Display for OpCount {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} add/sub, {} mul, {} div, {} sin/cos, {} sqrt, {} other ({} total)",
            self.add_sub,
            self.mul,
            self.div,
            self.sin_cos,
            self.sqrt,
            self.other,
            self.total()
        )
    }
}

impl Graph {
    /// Operation count of everything the roots need, shared nodes counted once.
    pub fn op_count(&self, roots: &[Id]) -> OpCount {
        self.op_count_until(roots, &HashSet::new())
    }

    /// Operation count of what the roots need when the nodes in `given` are inputs (their
    /// own operations, and those only they need, are not counted).
    pub fn op_count_until(&self, roots: &[Id], given: &HashSet<Id>) -> OpCount {
        let reachable = self.reachable_until(roots, given);
        // For every reachable node: is it used at all, and only by additions? (One pass, so
        // the count stays linear in the graph's size.)
        let mut used = vec![false; self.nodes.len()];
        let mut only_by_add = vec![true; self.nodes.len()];
        for (i, node) in self.nodes.iter().enumerate() {
            if !reachable[i] || given.contains(&Id(i as u32)) {
                continue;
            }
            let is_add = matches!(node, Node::Add(..));
            for c in self.children(Id(i as u32)) {
                used[c.index()] = true;
                only_by_add[c.index()] &= is_add;
            }
        }
        let mut count = OpCount::default();
        for (i, node) in self.nodes.iter().enumerate() {
            if !reachable[i] {
                continue;
            }
            if given.contains(&Id(i as u32)) {
                continue;
            }
            match node {
                // A contact parameter's Newton solve counts as one operation here; its
                // residual is counted as a function of its own.
                Node::Var(k) if self.implicits.contains_key(k) => count.other += 1,
                Node::Const(_) | Node::Var(_) => {}
                Node::Add(..) => count.add_sub += 1,
                Node::Neg(_) => {
                    // Absorbed when every use is an addition (written as a subtraction).
                    if !(used[i] && only_by_add[i]) {
                        count.add_sub += 1
                    }
                }
                Node::Mul(..) => count.mul += 1,
                Node::Div(..) => count.div += 1,
                Node::Call(Func::Sin | Func::Cos, _) => count.sin_cos += 1,
                Node::Call(Func::Sqrt, _) => count.sqrt += 1,
                Node::Powi(..)
                | Node::Powf(..)
                | Node::Call(..)
                | Node::Table(..)
                | Node::Grid(..) => count.other += 1,
            }
        }
        count
    }

    /// Marks the nodes the roots depend on.
    pub fn reachable(&self, roots: &[Id]) -> Vec<bool> {
        self.reachable_until(roots, &HashSet::new())
    }

    /// [`Graph::reachable`] without descending below the nodes of `stop` (which are marked).
    pub fn reachable_until(&self, roots: &[Id], stop: &HashSet<Id>) -> Vec<bool> {
        let mut mark = vec![false; self.nodes.len()];
        let mut stack: Vec<Id> = roots.to_vec();
        while let Some(id) = stack.pop() {
            if mark[id.index()] {
                continue;
            }
            mark[id.index()] = true;
            if !stop.contains(&id) {
                stack.extend(self.children(id));
            }
        }
        mark
    }
}
