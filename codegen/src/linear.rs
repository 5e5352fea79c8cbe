//! Collecting linear combinations: the one rewriting pass run on a finished derivation.
//!
//! The recursions build sums two terms at a time, so a sum that runs through several bodies
//! ends up nested, e.g. `0.01125 + (0.3·(x + (0.3 + x)) + 0.245)`, where construction-time
//! folding (which only sees two operands) cannot merge the constants or the two `x`. This
//! pass flattens every maximal tree of additions, negations and constant factors whose inner
//! nodes are used only once into Σ kⱼ·xⱼ + k₀, merges like terms, and rebuilds it with one
//! multiplication per distinct |kⱼ| (terms sharing a factor are summed first):
//! `0.34625 + 0.6·x`. A node used more than once stays a term, so nothing is computed twice.
//!
//! Flattening and merging never cost operations: a tree with n distinct terms needed at least
//! n − 1 additions, and each distinct coefficient is the product of the factors above its
//! terms, so there are no more coefficients than the tree had constant factors. Pulling
//! shared factors out is greedy and can, on long sums of products (the contact Jacobians of
//! spatial chains), cost a few operations more than it saves; [`crate::Derivation`] therefore
//! keeps the rewritten expressions of a term group only where they need fewer operations
//! (`codegen/tests/suite/linear_pass.rs` checks every model file and the scaling chains).

use crate::expr::{Graph, Id, Node};
use std::collections::BTreeMap;

/// Rewrites `roots` (and everything below them) with their linear combinations collected.
pub fn collect_linear(g: &mut Graph, roots: &mut [Id]) {
    collect_linear_with(g, roots, &mut []);
}

/// [`collect_linear`] on `roots`, and `riders` moved onto the rewritten nodes: an
/// expression of `riders` refers to the nodes `roots` are rewritten into, and a node only
/// the riders need is rebuilt over them unchanged (its operations stay the same). The
/// rewriting itself, use counts included, is that of `roots` alone, so riding never changes
/// what `roots` become.
pub fn collect_linear_with(g: &mut Graph, roots: &mut [Id], riders: &mut [Id]) {
    let last = roots
        .iter()
        .chain(riders.iter())
        .map(|r| r.index() + 1)
        .max()
        .unwrap_or(0);
    let uses = use_counts(g, roots, last);
    let ridden = g.reachable(riders);
    let mut image: Vec<Id> = Vec::with_capacity(last);
    for i in 0..last {
        let id = g.id_from_index(i);
        let rebuilt = if uses[i] == 0 && ridden.get(i).copied().unwrap_or(false) {
            g.rebuild_as(id, |g| g.rebuild_with(id, |c| image[c.index()]))
        } else if uses[i] == 0 {
            id // not needed by any root: left as it is
        } else if is_linear(g, id) {
            let mut form = LinearForm::default();
            let cx = Context {
                uses: &uses,
                image: &image,
            };
            expand(g, id, 1.0, &cx, &mut form, true);
            g.rebuild_as(id, |g| form.build(g, &cx))
        } else {
            g.rebuild_as(id, |g| g.rebuild_with(id, |c| image[c.index()]))
        };
        image.push(rebuilt);
    }
    for r in roots.iter_mut().chain(riders.iter_mut()) {
        *r = image[r.index()];
    }
}

/// How many times each node is used by the nodes the roots need (a root counts as a use).
fn use_counts(g: &Graph, roots: &[Id], last: usize) -> Vec<u32> {
    let reachable = g.reachable(roots);
    let mut uses = vec![0u32; last];
    for r in roots {
        uses[r.index()] += 1;
    }
    for (i, &live) in reachable.iter().enumerate().take(last) {
        if live {
            for c in g.children(g.id_from_index(i)) {
                uses[c.index()] += 1;
            }
        }
    }
    uses
}

/// Additions, negations and products with a constant: the nodes a linear form absorbs.
fn is_linear(g: &Graph, id: Id) -> bool {
    match g.node(id) {
        Node::Add(..) | Node::Neg(_) => true,
        Node::Mul(k, _) => g.as_const(k).is_some(),
        _ => false,
    }
}

/// Σ kⱼ·xⱼ + Σ kᵢ·aᵢ·bᵢ + k₀: terms xⱼ already rebuilt (kept in id order, so the output is
/// deterministic) and products aᵢ·bᵢ used only here (original ids), which may share a
/// factor to pull out.
#[derive(Default)]
struct LinearForm {
    constant: f64,
    terms: BTreeMap<Id, f64>,
    products: Vec<(f64, Id, Id)>,
}

/// What [`expand`] reads: the use counts and the images of the nodes rebuilt so far.
struct Context<'a> {
    uses: &'a [u32],
    image: &'a [Id],
}

/// Adds `coef · id` to `form`, descending into linear nodes used only here.
///
/// A sum through every body of a long chain is as deep as the chain, so the descent keeps
/// its own stack instead of recursing; it visits the terms in the same order as a recursive
/// descent would (left operand first, each completely), so the constant is summed, and the
/// products are listed, in the same order.
fn expand(g: &Graph, id: Id, coef: f64, cx: &Context, form: &mut LinearForm, top: bool) {
    let mut stack = vec![(id, coef, top)];
    while let Some((id, coef, top)) = stack.pop() {
        if let Some(k) = g.as_const(id) {
            form.constant += coef * k;
            continue;
        }
        let single = top || cx.uses[id.index()] == 1;
        if single && !top {
            if let Node::Mul(a, b) = g.node(id) {
                if g.as_const(a).is_none() {
                    form.products.push((coef, a, b));
                    continue;
                }
            }
        }
        if !single || !is_linear(g, id) {
            *form.terms.entry(cx.image[id.index()]).or_insert(0.0) += coef;
            continue;
        }
        match g.node(id) {
            Node::Add(a, b) => {
                stack.push((b, coef, false));
                stack.push((a, coef, false));
            }
            Node::Neg(a) => stack.push((a, -coef, false)),
            Node::Mul(k, x) => {
                let k = g.as_const(k).unwrap_or(1.0);
                stack.push((x, coef * k, false));
            }
            _ => unreachable!("is_linear admits only Add, Neg and Mul by a constant"),
        }
    }
}

impl LinearForm {
    /// Pulls out factors shared by several products (k₁·f·y₁ + k₂·f·y₂ + k₀·f →
    /// f·(k₁·y₁ + k₂·y₂ + k₀), the inner sum collected again), most shared first; the other
    /// products become terms.
    fn factor_products(&mut self, g: &mut Graph, cx: &Context) {
        loop {
            let mut count: BTreeMap<Id, usize> = BTreeMap::new();
            for &(_, a, b) in &self.products {
                let (pa, pb) = (peel(g, a).1, peel(g, b).1);
                *count.entry(pa).or_default() += 1;
                if pb != pa {
                    *count.entry(pb).or_default() += 1;
                }
            }
            for (f, n) in count.iter_mut() {
                if self.terms.contains_key(&cx.image[f.index()]) {
                    *n += 1;
                }
            }
            let best = count
                .iter()
                .filter(|&(_, &n)| n >= 2)
                .max_by_key(|&(&f, &n)| (n, std::cmp::Reverse(f)));
            let Some((&f, _)) = best else { break };
            let mut inner = LinearForm::default();
            let mut rest = Vec::new();
            for (k, a, b) in std::mem::take(&mut self.products) {
                let ((ka, pa), (kb, pb)) = (peel(g, a), peel(g, b));
                match (pa == f, pb == f) {
                    (true, _) => expand(g, b, k * ka, cx, &mut inner, false),
                    (_, true) => expand(g, a, k * kb, cx, &mut inner, false),
                    _ => rest.push((k, a, b)),
                }
            }
            self.products = rest;
            let fi = cx.image[f.index()];
            if let Some(k0) = self.terms.remove(&fi) {
                inner.constant += k0;
            }
            let inner = inner.build(g, cx);
            let product = g.mul(fi, inner);
            *self.terms.entry(product).or_insert(0.0) += 1.0;
        }
        for (k, a, b) in std::mem::take(&mut self.products) {
            let product = g.mul(cx.image[a.index()], cx.image[b.index()]);
            *self.terms.entry(product).or_insert(0.0) += k;
        }
    }

    /// k₀ + Σ over distinct |k| of |k|·(±x ± y …), positive groups first.
    fn build(mut self, g: &mut Graph, cx: &Context) -> Id {
        self.factor_products(g, cx);
        // Terms grouped by the magnitude of their coefficient, in order of first term.
        let mut groups: Vec<(f64, Vec<(Id, bool)>)> = Vec::new();
        for (&x, &k) in &self.terms {
            if k == 0.0 {
                continue;
            }
            let negative = k < 0.0;
            match groups.iter_mut().find(|(m, _)| *m == k.abs()) {
                Some((_, members)) => members.push((x, negative)),
                None => groups.push((k.abs(), vec![(x, negative)])),
            }
        }
        // Sign each group so that most of its members are added; but if that would leave
        // nothing to subtract from, keep the group with the most added members as it is
        // (a leading negation would cost an operation).
        let negatives = |members: &[(Id, bool)]| members.iter().filter(|(_, n)| *n).count();
        let mut flips: Vec<bool> = groups
            .iter()
            .map(|(_, members)| 2 * negatives(members) > members.len())
            .collect();
        if self.constant == 0.0 && flips.iter().all(|&f| f) {
            let keep = (0..groups.len())
                .filter(|&i| negatives(&groups[i].1) < groups[i].1.len())
                .max_by_key(|&i| (groups[i].1.len() - negatives(&groups[i].1), usize::MAX - i));
            if let Some(i) = keep {
                flips[i] = false;
            }
        }
        let mut positive = Vec::new();
        let mut negative = Vec::new();
        for ((magnitude, members), flip) in groups.iter().zip(flips) {
            let sum = signed_sum(g, members.iter().map(|&(x, n)| (x, n != flip)));
            let scaled = {
                let m = g.constant(*magnitude);
                g.mul(m, sum)
            };
            if flip {
                negative.push(scaled);
            } else {
                positive.push(scaled);
            }
        }
        let mut terms: Vec<(Id, bool)> = Vec::new();
        if self.constant != 0.0 {
            terms.push((g.constant(self.constant), false));
        }
        terms.extend(positive.into_iter().map(|x| (x, false)));
        terms.extend(negative.into_iter().map(|x| (x, true)));
        signed_sum(g, terms.into_iter())
    }
}

/// Σ ±xᵢ: additions first, then subtractions, a negation only when nothing is added.
fn signed_sum(g: &mut Graph, terms: impl Iterator<Item = (Id, bool)>) -> Id {
    let (minus, plus): (Vec<_>, Vec<_>) = terms.partition(|&(_, n)| n);
    let mut acc: Option<Id> = None;
    for (x, _) in plus {
        acc = Some(match acc {
            Some(a) => g.add(a, x),
            None => x,
        });
    }
    for (x, _) in minus {
        acc = Some(match acc {
            Some(a) => g.sub(a, x),
            None => g.neg(x),
        });
    }
    acc.unwrap_or_else(|| g.zero())
}

/// A factor without its constant coefficient and sign: k·x → (k, x), −x → (−1, x).
fn peel(g: &Graph, id: Id) -> (f64, Id) {
    let (mut k, mut id) = (1.0, id);
    loop {
        match g.node(id) {
            Node::Neg(x) => {
                k = -k;
                id = x;
            }
            Node::Mul(c, x) if g.as_const(c).is_some() => {
                k *= g.as_const(c).unwrap_or(1.0);
                id = x;
            }
            _ => return (k, id),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nested_sums_merge_constants_and_like_terms() {
        let mut g = Graph::new();
        let x = g.var("x");
        let y = g.var("y");
        let sx = g.sin(x);
        // 0.01125 + (0.3·(s + (0.3 + s)) + 0.245)
        let k03 = g.constant(0.3);
        let inner = g.add(k03, sx);
        let inner = g.add(sx, inner);
        let scaled = g.mul(k03, inner);
        let k245 = g.constant(0.245);
        let mid = g.add(scaled, k245);
        let k1 = g.constant(0.01125);
        let e = g.add(k1, mid);
        let before = g.op_count(&[e]).total();
        let mut roots = [e, y];
        collect_linear(&mut g, &mut roots);
        let after = g.op_count(&[roots[0]]).total();
        // sin, 0.6·s, + 0.34625
        assert_eq!(after, 3, "{before} → {after}");
        assert!(before > after);
        for v in [-1.3, 0.2, 2.9] {
            let a = g.eval(&[e], &[v, 0.0])[0];
            let b = g.eval(&[roots[0]], &[v, 0.0])[0];
            // The same sum reassociated: values of order 1, a few roundings apart (≤ 4 ulp).
            assert!((a - b).abs() <= 1e-15 * (1.0 + a.abs()), "{a} vs {b}");
        }
        assert_eq!(roots[1], y, "a variable root is left alone");
    }

    #[test]
    fn shared_sums_stay_terms() {
        let mut g = Graph::new();
        let x = g.var("x");
        let y = g.var("y");
        let s = g.add(x, y); // used twice below: must not be expanded into either
        let k = g.constant(2.0);
        let a = g.mul(k, s);
        let ex = g.sin(x);
        let b = g.add(s, ex);
        let mut roots = [a, b];
        let before = g.op_count(&roots).total();
        collect_linear(&mut g, &mut roots);
        assert!(g.op_count(&roots).total() <= before);
        let vals = g.eval(&roots, &[0.7, -0.4]);
        // Closed forms 2(x + y) and x + y + sin x at (0.7, −0.4); values of order 1, a few
        // roundings (≤ 4 ulp).
        assert!((vals[0] - 0.6).abs() < 1e-15);
        assert!((vals[1] - (0.3 + 0.7f64.sin())).abs() < 1e-15);
    }

    #[test]
    fn equal_magnitudes_share_one_multiplication() {
        let mut g = Graph::new();
        let x = g.var("x");
        let y = g.var("y");
        let z = g.var("z");
        // 0.3·x − 0.3·y + 0.6·z: two multiplications (0.3, 0.6) and two additions.
        let k = g.constant(0.3);
        let k6 = g.constant(0.6);
        let a = g.mul(k, x);
        let b = g.mul(k, y);
        let c = g.mul(k6, z);
        let e = g.sub(a, b);
        let e = g.add(e, c);
        let mut roots = [e];
        collect_linear(&mut g, &mut roots);
        assert_eq!(g.op_count(&roots).total(), 4);
        let v = g.eval(&roots, &[1.0, 2.0, 3.0])[0];
        // Closed form 0.3·1 − 0.3·2 + 0.6·3; a value of order 1, a few roundings apart.
        assert!((v - (0.3 - 0.6 + 1.8)).abs() < 1e-15);
    }

    /// A rider sees the roots' rewritten nodes and leaves the roots' rewriting alone: the
    /// same roots rewritten with and without it are the same nodes, the rider's own node
    /// (which only it needs) is rebuilt over the rewritten sum, and its value is unchanged.
    #[test]
    fn riders_use_the_rewritten_nodes_and_change_nothing_else() {
        let build = |g: &mut Graph| {
            let x = g.var("x");
            let k = g.constant(0.3);
            let sx = g.sin(x);
            // s = 0.3·sin x + 0.3·(sin x + 0.3): collected to 0.6·sin x + 0.09.
            let inner = g.add(sx, k);
            let a = g.mul(k, sx);
            let b = g.mul(k, inner);
            let s = g.add(a, b);
            let root = g.cos(s);
            let rider = g.mul(s, s);
            (root, rider, s)
        };
        let mut alone = Graph::new();
        let (root, _, _) = build(&mut alone);
        let mut roots = [root];
        collect_linear(&mut alone, &mut roots);
        let mut g = Graph::new();
        let (root, rider, s) = build(&mut g);
        let (mut with, mut riders) = ([root], [rider]);
        collect_linear_with(&mut g, &mut with, &mut riders);
        assert_eq!(
            g.op_count(&with).total(),
            alone.op_count(&roots).total(),
            "the roots' rewriting depends on the roots alone"
        );
        // The rider is s² over the rewritten s: cos's argument, shared.
        let Node::Call(crate::profile::Func::Cos, arg) = g.node(with[0]) else {
            panic!("the root is still a cosine")
        };
        assert_eq!(g.node(riders[0]), Node::Mul(arg, arg));
        assert_ne!(arg, s, "s was rewritten");
        for v in [-0.7, 0.4, 2.2] {
            let (before, after) = (g.eval(&[rider], &[v])[0], g.eval(&riders, &[v])[0]);
            // The same square of a reassociated sum of order 1: a few roundings apart.
            assert!((before - after).abs() <= 1e-15 * (1.0 + before.abs()));
        }
    }
}
