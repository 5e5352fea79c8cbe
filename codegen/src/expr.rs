//! The symbolic engine: a hash-consed expression DAG.
//!
//! Every node is stored once ([`Graph`] interns nodes by structure, as `egg` does), so a
//! common subexpression built twice is the same [`Id`] and is computed once in the emitted
//! code. Construction folds constants and removes structurally zero and unit terms
//! (`0·x → 0`, `1·x → x`, `x + 0 → x`, `x − x → 0`, `−(−x) → x`), so they never reach the
//! emitted code. Ids grow with construction, so id order is a topological order: children
//! always have smaller ids than their parents.
//!
//! The same graph can be differentiated ([`Graph::diff`]), have a variable substituted
//! ([`Graph::substitute`]) and be evaluated numerically ([`Graph::eval`]), so tests can check
//! expressions without compiling them.

use crate::profile::Func;
use std::collections::HashMap;

mod calculus;
mod count;
mod interpret;
pub mod scalar;
mod tabulated;

pub use count::OpCount;
pub use interpret::{apply, method_name};

/// Handle of a node in a [`Graph`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Id(u32);

impl Id {
    /// Position of the node in the graph (also its topological rank).
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// One node of the expression language. Subtraction is `Add(a, Neg(b))`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Node {
    /// A constant, stored by its bits (never −0.0, never NaN).
    Const(u64),
    /// A named input variable, by index into the graph's variable table.
    Var(u32),
    /// a + b, operands ordered by id.
    Add(Id, Id),
    /// a · b, a constant operand first, otherwise ordered by id.
    Mul(Id, Id),
    /// −a
    Neg(Id),
    /// a / b
    Div(Id, Id),
    /// aⁿ for an integer n ∉ {0, 1}
    Powi(Id, i32),
    /// a^b
    Powf(Id, Id),
    /// an elementary function of a
    Call(Func, Id),
    /// The derivative of order `.1` (0: the value) of tabulated function `.0` of the graph
    /// ([`Graph::add_table`]) at a: a spline through a table of points (segment look-up and
    /// a cubic) or a motion law (segment look-up and the law's closed form), evaluated by the
    /// runtime; orders 0 to 3 are exact.
    Table(u32, u8, Id),
    /// ∂ᵖ_x ∂ᵠ_y, `.1` = (p, q), of surface `.0` of the graph ([`Graph::add_grid`]) at
    /// (a, b): a bicubic spline through a grid of points (cell look-up and the tensor-product
    /// cubic), evaluated by the runtime; exact for every order (zero beyond the third in
    /// either variable).
    Grid(u32, (u8, u8), Id, Id),
}

/// A tabulated function of the graph: a spline through a table of points or a motion law,
/// evaluated by the runtime ([`crate::profile::Tabulated`]).
pub type Table = std::sync::Arc<crate::profile::Tabulated>;

/// A surface of the graph given on a grid, evaluated by the runtime
/// ([`crate::profile::Gridded`]).
pub type Grid = std::sync::Arc<crate::profile::Gridded>;

/// A hash-consed expression DAG with named variables.
#[derive(Debug, Default, Clone)]
pub struct Graph {
    nodes: Vec<Node>,
    index: HashMap<Node, Id>,
    vars: Vec<String>,
    var_ids: HashMap<String, Id>,
    labels: HashMap<Id, String>,
    sections: Vec<u32>,
    section_names: Vec<String>,
    /// While set, new nodes go into this section instead of the latest one (rewriting
    /// passes keep a rebuilt node under its original heading).
    section_override: Option<u32>,
    /// The variables defined implicitly (contact parameters), by variable index.
    implicits: HashMap<u32, Implicit>,
    /// The tabulated functions [`Node::Table`] refers to.
    tables: Vec<Table>,
    /// The surfaces [`Node::Grid`] refers to.
    grids: Vec<Grid>,
    /// The most nodes the graph takes ([`NODE_LIMIT`] when 0).
    node_limit: usize,
    /// Set when a node was asked for beyond the limit (see [`Graph::exhausted`]).
    exhausted: bool,
}

/// The most nodes an expression graph holds: 4 194 304 (2²²), about 500 MB with its index.
/// The largest built-in model needs about 7 500 and a spatial chain of 200 bodies
/// (`codegen/tests/common/chain.rs`) 1.3 million; a model that needs more (a planar chain of
/// 1000 bodies reaches the limit within its mass matrix) is refused with an error on its file
/// instead of exhausting the machine's memory. Variables do not count: there is one per
/// coordinate, rate and parameter.
pub const NODE_LIMIT: usize = 1 << 22;

/// Where Newton starts on an [`Implicit`] variable when no earlier solution is at hand.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Guess {
    /// The value of input `i`.
    Input(usize),
    /// The polar angle `atan2(input y, input x)`.
    Angle {
        /// Index of the input that is the point's x.
        x: usize,
        /// Index of the input that is the point's y.
        y: usize,
    },
    /// None: the best sample of the range by the objective.
    Scan,
    /// A designed cam's pitch curve inverted at the point (input 0, input 1)
    /// (`camchain_runtime::contact::pitch_parameter`).
    Pitch(camchain_runtime::contact::Pitch),
}

/// A variable defined implicitly: the root s of ψ(s; p) = 0 with ψ'(s) < 0 (a minimum of
/// the objective) near a guess, p standing for the values of `inputs`. A contact parameter
/// (the profile point touched by a roller or a flat face) is one.
///
/// The emitted code and the interpreter find it by Newton's method
/// (`camchain_runtime::contact::solve`). Its derivatives follow from the implicit-function
/// theorem, ds/dx = −(∂ψ/∂p · dp/dx) / ψ'(s) ([`Graph::diff`]), although the contact
/// equations avoid them (the envelope theorem: docs/method.md §9).
#[derive(Debug, Clone, PartialEq)]
pub struct Implicit {
    /// What the variable is, for comments (`contact R: the profile point nearest the
    /// roller's centre`).
    pub description: String,
    /// The placeholder variable standing for s in `residual`, `derivative` and `objective`.
    pub unknown: Id,
    /// The placeholder variables standing for the inputs.
    pub placeholders: Vec<Id>,
    /// The inputs' names in the emitted residual (`x`, `y`).
    pub input_names: Vec<&'static str>,
    /// The inputs: expressions of the outer variables.
    pub inputs: Vec<Id>,
    /// ψ(s; p).
    pub residual: Id,
    /// ∂ψ/∂s.
    pub derivative: Id,
    /// A function of (s; p) that the wanted root minimises (ψ = −objective′ up to a
    /// positive factor): what a scan of the range compares.
    pub objective: Id,
    /// Where Newton starts.
    pub guess: Guess,
    /// The interval of s scanned when Newton from the guess fails.
    pub range: (f64, f64),
}

fn const_bits(value: f64) -> u64 {
    // −0.0 and 0.0 are the same constant for our purposes.
    if value == 0.0 {
        0.0f64.to_bits()
    } else {
        value.to_bits()
    }
}

impl Graph {
    /// An empty graph holding at most [`NODE_LIMIT`] nodes.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty graph holding at most `limit` nodes besides its variables (at least 1).
    pub fn with_node_limit(limit: usize) -> Self {
        Graph {
            node_limit: limit.max(1),
            ..Self::default()
        }
    }

    /// The most nodes the graph holds besides its variables.
    pub fn node_limit(&self) -> usize {
        if self.node_limit == 0 {
            NODE_LIMIT
        } else {
            self.node_limit
        }
    }

    /// True when a node was asked for beyond [`Graph::node_limit`]. The graph then stops
    /// growing: every new operation or constant is the constant NaN (so a derivation that
    /// outgrows it finishes quickly, in bounded memory, with meaningless terms), and the
    /// expressions built since must not be used: the derivation is refused
    /// ([`crate::Derivation::checked`]).
    pub fn exhausted(&self) -> bool {
        self.exhausted
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// True when the graph has no node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The id of the node at `index` (ids are dense indices).
    pub fn id_from_index(&self, index: usize) -> Id {
        Id(index as u32)
    }

    /// The node behind an id.
    pub fn node(&self, id: Id) -> Node {
        self.nodes[id.index()]
    }

    /// The id of `node` if the graph holds it.
    pub fn find(&self, node: Node) -> Option<Id> {
        self.index.get(&node).copied()
    }

    fn intern(&mut self, node: Node) -> Id {
        if let Some(&id) = self.index.get(&node) {
            return id;
        }
        if self.nodes.len() >= self.node_limit() && !matches!(node, Node::Var(_)) {
            self.exhausted = true;
            let poison = Node::Const(f64::NAN.to_bits());
            if let Some(&id) = self.index.get(&poison) {
                return id;
            }
            return self.push(poison);
        }
        self.push(node)
    }

    /// Appends a node (not yet in the graph) to the current section.
    fn push(&mut self, node: Node) -> Id {
        let id = Id(self.nodes.len() as u32);
        self.nodes.push(node);
        let section = self
            .section_override
            .unwrap_or(self.section_names.len().saturating_sub(1) as u32);
        self.sections.push(section);
        self.index.insert(node, id);
        id
    }

    /// A constant. NaN is not representable and becomes an explicit NaN node only through
    /// folding of invalid operations, which the derivation never produces.
    pub fn constant(&mut self, value: f64) -> Id {
        self.intern(Node::Const(const_bits(value)))
    }

    /// The constant 0.
    pub fn zero(&mut self) -> Id {
        self.constant(0.0)
    }

    /// The constant 1.
    pub fn one(&mut self) -> Id {
        self.constant(1.0)
    }

    /// The variable called `name` (created on first use).
    pub fn var(&mut self, name: &str) -> Id {
        if let Some(&id) = self.var_ids.get(name) {
            return id;
        }
        let index = self.vars.len() as u32;
        self.vars.push(name.to_string());
        let id = self.intern(Node::Var(index));
        self.var_ids.insert(name.to_string(), id);
        id
    }

    /// Declares the implicitly defined variable `name` (see [`Implicit`]); its node comes
    /// after its inputs.
    pub fn implicit(&mut self, name: &str, definition: Implicit) -> Id {
        let id = self.var(name);
        if let Node::Var(k) = self.node(id) {
            self.implicits.insert(k, definition);
        }
        id
    }

    /// The definition of an implicitly defined variable.
    pub fn implicit_of(&self, id: Id) -> Option<&Implicit> {
        match self.node(id) {
            Node::Var(k) => self.implicits.get(&k),
            _ => None,
        }
    }

    /// Every implicitly defined variable with its definition, in variable order.
    pub fn implicits(&self) -> Vec<(Id, &Implicit)> {
        let mut out: Vec<(Id, &Implicit)> = self
            .implicits
            .iter()
            .map(|(&k, d)| (self.var_id(k), d))
            .collect();
        out.sort_by_key(|(id, _)| *id);
        out
    }

    /// Names of the variables, by variable index.
    pub fn var_names(&self) -> &[String] {
        &self.vars
    }

    /// The node of variable `k` (an index into [`Graph::var_names`]).
    pub fn var_id(&self, k: u32) -> Id {
        self.var_ids
            .get(&self.vars[k as usize])
            .copied()
            .unwrap_or(Id(u32::MAX))
    }

    /// Index of a variable in [`Graph::var_names`], if it exists.
    pub fn var_index(&self, name: &str) -> Option<usize> {
        self.vars.iter().position(|v| v == name)
    }

    /// The value of a constant node.
    pub fn as_const(&self, id: Id) -> Option<f64> {
        match self.node(id) {
            Node::Const(bits) => Some(f64::from_bits(bits)),
            _ => None,
        }
    }

    /// True when `id` is the constant 0 (a structural zero).
    pub fn is_zero(&self, id: Id) -> bool {
        self.as_const(id) == Some(0.0)
    }

    /// Starts a section: nodes created from now on are listed under this heading in the
    /// emitted code (e.g. `body2: velocities and accelerations`).
    pub fn set_section(&mut self, name: impl Into<String>) {
        self.section_names.push(name.into());
    }

    /// The index of the section a node belongs to (sections are numbered as started).
    pub fn section_index(&self, id: Id) -> u32 {
        self.sections.get(id.index()).copied().unwrap_or(0)
    }

    /// The section a node was created in.
    pub fn section_of(&self, id: Id) -> Option<&str> {
        let k = *self.sections.get(id.index())? as usize;
        self.section_names.get(k).map(String::as_str)
    }

    /// Runs `build` with new nodes placed in the section of `like`, and gives its result
    /// `like`'s label: a rewritten node keeps the heading and name of the one it replaces.
    pub(crate) fn rebuild_as(&mut self, like: Id, build: impl FnOnce(&mut Self) -> Id) -> Id {
        let saved = self.section_override;
        self.section_override = self.sections.get(like.index()).copied();
        let new = build(self);
        self.section_override = saved;
        if new != like {
            if let Some(name) = self.labels.get(&like).cloned() {
                self.label(new, name);
            }
        }
        new
    }

    /// Gives a node a readable name for the emitted code (first label wins). A negation is
    /// never bound to a name of its own (it is printed as a subtraction), so its operand is
    /// named `neg_<name>` instead.
    pub fn label(&mut self, id: Id, name: impl Into<String>) {
        match self.node(id) {
            Node::Const(_) | Node::Var(_) => {}
            Node::Neg(inner) => {
                let name = name.into();
                let negated = match name.strip_prefix("neg_") {
                    Some(plain) => plain.to_string(),
                    None => format!("neg_{name}"),
                };
                self.label(inner, negated);
            }
            _ => {
                self.labels.entry(id).or_insert_with(|| name.into());
            }
        }
    }

    /// The label given to a node, if any.
    pub fn label_of(&self, id: Id) -> Option<&str> {
        self.labels.get(&id).map(String::as_str)
    }

    /// a + b with folding.
    pub fn add(&mut self, a: Id, b: Id) -> Id {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.constant(x + y),
            (Some(0.0), _) => return b,
            (_, Some(0.0)) => return a,
            _ => {}
        }
        if self.node(b) == Node::Neg(a) || self.node(a) == Node::Neg(b) {
            return self.zero();
        }
        if self.is_sin2_plus_cos2(a, b) {
            return self.one();
        }
        if a == b {
            let two = self.constant(2.0);
            return self.mul(two, a);
        }
        // Like terms: k1·x + k2·x → (k1 + k2)·x, x + k·x → (1 + k)·x.
        let (ka, xa) = self.split_factor(a);
        let (kb, xb) = self.split_factor(b);
        if xa == xb {
            return self.scale(ka + kb, xa);
        }
        // Constants gather: k1 + (k2 + x) → (k1 + k2) + x.
        for (k, other) in [(a, b), (b, a)] {
            if let (Some(k1), Node::Add(y, z)) = (self.as_const(k), self.node(other)) {
                if let Some(k2) = self.as_const(y) {
                    let c = self.constant(k1 + k2);
                    return self.add(c, z);
                }
                if let Some(k2) = self.as_const(z) {
                    let c = self.constant(k1 + k2);
                    return self.add(c, y);
                }
            }
        }
        if let (Node::Neg(x), Node::Neg(y)) = (self.node(a), self.node(b)) {
            let sum = self.add(x, y);
            return self.neg(sum);
        }
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        self.intern(Node::Add(a, b))
    }

    /// A term as (constant factor, rest): k·x → (k, x), −x → (−1, x), x → (1, x).
    fn split_factor(&self, id: Id) -> (f64, Id) {
        match self.node(id) {
            Node::Mul(k, x) if self.as_const(k).is_some() => (self.as_const(k).unwrap_or(1.0), x),
            Node::Neg(y) => {
                let (k, x) = self.split_factor(y);
                (-k, x)
            }
            _ => (1.0, id),
        }
    }

    /// True for cos²x + sin²x in either order (written as products), which is exactly 1.
    fn is_sin2_plus_cos2(&self, a: Id, b: Id) -> bool {
        let square_of = |id: Id| match self.node(id) {
            Node::Mul(x, y) if x == y => match self.node(x) {
                Node::Call(f @ (Func::Sin | Func::Cos), arg) => Some((f, arg)),
                _ => None,
            },
            _ => None,
        };
        match (square_of(a), square_of(b)) {
            (Some((f, x)), Some((g, y))) => x == y && f != g,
            _ => false,
        }
    }

    /// a − b with folding.
    pub fn sub(&mut self, a: Id, b: Id) -> Id {
        let nb = self.neg(b);
        self.add(a, nb)
    }

    /// −a with folding.
    pub fn neg(&mut self, a: Id) -> Id {
        match self.node(a) {
            Node::Const(bits) => self.constant(-f64::from_bits(bits)),
            Node::Neg(x) => x,
            _ => self.intern(Node::Neg(a)),
        }
    }

    /// a · b with folding: zeros and ones vanish, signs are pulled out, constants merge.
    pub fn mul(&mut self, a: Id, b: Id) -> Id {
        let (a, b) = match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.constant(x * y),
            (None, Some(_)) => (b, a),
            _ => (a, b),
        };
        if let Some(c) = self.as_const(a) {
            return self.scale(c, b);
        }
        if let Node::Neg(x) = self.node(a) {
            let p = self.mul(x, b);
            return self.neg(p);
        }
        if let Node::Neg(y) = self.node(b) {
            let p = self.mul(a, y);
            return self.neg(p);
        }
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        self.intern(Node::Mul(a, b))
    }

    /// c · b for a constant c; constant factors are kept positive (the sign goes to a
    /// negation, which the printer turns into a subtraction).
    pub fn scale(&mut self, c: f64, b: Id) -> Id {
        if c == 0.0 {
            return self.zero();
        }
        if c == 1.0 {
            return b;
        }
        if c < 0.0 {
            let p = self.scale(-c, b);
            return self.neg(p);
        }
        match self.node(b) {
            Node::Neg(x) => {
                let p = self.scale(c, x);
                self.neg(p)
            }
            Node::Mul(x, y) if self.as_const(x).is_some() => {
                let d = self.as_const(x).unwrap_or(1.0);
                self.scale(c * d, y)
            }
            _ => {
                let cid = self.constant(c);
                self.intern(Node::Mul(cid, b))
            }
        }
    }

    /// a / b with folding; division by a constant becomes a multiplication, signs go out.
    pub fn div(&mut self, a: Id, b: Id) -> Id {
        if self.is_zero(a) {
            return self.zero();
        }
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => self.constant(x / y),
            (_, Some(y)) if y != 0.0 => self.scale(1.0 / y, a),
            _ => match (self.node(a), self.node(b)) {
                // Signs are pulled out, as for products, so that −(−x)/y folds to x/y.
                (Node::Neg(x), _) => {
                    let q = self.div(x, b);
                    self.neg(q)
                }
                (_, Node::Neg(y)) => {
                    let q = self.div(a, y);
                    self.neg(q)
                }
                _ => self.intern(Node::Div(a, b)),
            },
        }
    }

    /// aⁿ with folding.
    pub fn powi(&mut self, a: Id, n: i32) -> Id {
        match n {
            0 => self.one(),
            1 => a,
            _ => match (self.as_const(a), self.node(a)) {
                (Some(x), _) => self.constant(x.powi(n)),
                // (−x)ⁿ = ±xⁿ: the sign goes out (and vanishes for even n).
                (None, Node::Neg(x)) if n % 2 == 0 => self.powi(x, n),
                (None, Node::Neg(x)) => {
                    let p = self.powi(x, n);
                    self.neg(p)
                }
                (None, _) => self.intern(Node::Powi(a, n)),
            },
        }
    }

    /// a^b with folding.
    pub fn powf(&mut self, a: Id, b: Id) -> Id {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => self.constant(x.powf(y)),
            (_, Some(1.0)) => a,
            (_, Some(0.0)) => self.one(),
            (_, Some(y)) if y.fract() == 0.0 && y.abs() < 64.0 => self.powi(a, y as i32),
            _ => self.intern(Node::Powf(a, b)),
        }
    }

    /// f(a) with folding of constants and odd/even symmetry of sin and cos.
    pub fn call(&mut self, f: Func, a: Id) -> Id {
        if let Some(x) = self.as_const(a) {
            return self.constant(apply(f, x));
        }
        if let Node::Neg(x) = self.node(a) {
            match f {
                Func::Cos | Func::Cosh => return self.call(f, x),
                Func::Sin | Func::Tan | Func::Sinh | Func::Tanh | Func::Atan => {
                    let v = self.call(f, x);
                    return self.neg(v);
                }
                _ => {}
            }
        }
        self.intern(Node::Call(f, a))
    }

    /// sin a
    pub fn sin(&mut self, a: Id) -> Id {
        self.call(Func::Sin, a)
    }

    /// cos a
    pub fn cos(&mut self, a: Id) -> Id {
        self.call(Func::Cos, a)
    }

    /// √a
    pub fn sqrt(&mut self, a: Id) -> Id {
        self.call(Func::Sqrt, a)
    }

    /// Σ of the items (0 for none).
    pub fn sum(&mut self, items: impl IntoIterator<Item = Id>) -> Id {
        let mut acc = self.zero();
        for item in items {
            acc = self.add(acc, item);
        }
        acc
    }

    /// Rewrites `roots` with every node of `map` replaced by its image, in one pass over the
    /// graph in id (topological) order: nodes whose children did not change keep their id.
    pub fn replace_nodes(&mut self, roots: &mut [Id], map: &HashMap<Id, Id>) {
        let last = roots.iter().map(|r| r.index() + 1).max().unwrap_or(0);
        let mut image: Vec<Id> = Vec::with_capacity(last);
        for i in 0..last {
            let id = Id(i as u32);
            if let Some(&to) = map.get(&id) {
                image.push(to);
                continue;
            }
            let changed = self.children(id).iter().any(|&c| image[c.index()] != c);
            let rebuilt = if changed {
                self.rebuild_as(id, |g| g.rebuild_with(id, |c| image[c.index()]))
            } else {
                id
            };
            image.push(rebuilt);
        }
        for r in roots.iter_mut() {
            *r = image[r.index()];
        }
    }

    /// The node `id` built again, with folding, from its children mapped by `new`.
    pub(crate) fn rebuild_with(&mut self, id: Id, new: impl Fn(Id) -> Id) -> Id {
        match self.node(id) {
            Node::Const(_) | Node::Var(_) => id,
            Node::Add(a, b) => self.add(new(a), new(b)),
            Node::Mul(a, b) => self.mul(new(a), new(b)),
            Node::Div(a, b) => self.div(new(a), new(b)),
            Node::Powf(a, b) => self.powf(new(a), new(b)),
            Node::Neg(a) => self.neg(new(a)),
            Node::Powi(a, n) => self.powi(new(a), n),
            Node::Call(f, a) => self.call(f, new(a)),
            Node::Table(t, order, a) => self.table(t, order, new(a)),
            Node::Grid(k, order, a, b) => self.grid(k, order, new(a), new(b)),
        }
    }

    /// Direct children of a node.
    pub fn children(&self, id: Id) -> Vec<Id> {
        match self.node(id) {
            Node::Var(k) => self
                .implicits
                .get(&k)
                .map(|d| d.inputs.clone())
                .unwrap_or_default(),
            Node::Const(_) => vec![],
            Node::Add(a, b)
            | Node::Mul(a, b)
            | Node::Div(a, b)
            | Node::Powf(a, b)
            | Node::Grid(_, _, a, b) => vec![a, b],
            Node::Neg(a) | Node::Powi(a, _) | Node::Call(_, a) | Node::Table(_, _, a) => vec![a],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn structural_zeros_and_units_vanish() {
        let mut g = Graph::new();
        let x = g.var("x");
        let zero = g.zero();
        let one = g.one();
        assert_eq!(g.mul(zero, x), zero);
        assert_eq!(g.mul(one, x), x);
        assert_eq!(g.add(x, zero), x);
        assert_eq!(g.sub(x, x), zero);
        let nx = g.neg(x);
        assert_eq!(g.neg(nx), x);
        let before = g.len();
        let s = g.sin(x);
        let s2 = g.sin(x);
        assert_eq!(s, s2, "hash-consing returns the same node");
        assert_eq!(g.len(), before + 1);
    }

    #[test]
    fn a_tabulated_function_differentiates_through_its_argument() {
        // f(sin x) for a spline f: the graph's derivative (chain rule through the table's
        // next order) against a central difference of the interpreted value (step 1e-5,
        // error ~ h² f‴ ~ 1e-10 on values of order 1: 1e-8), and against the spline's own
        // derivative times cos x (rounding: 1e-14).
        use camchain_runtime::spline::{Ends, Spline};
        let xs: Vec<f64> = (0..=12).map(|i| -1.2 + 0.2 * f64::from(i)).collect();
        let ys: Vec<f64> = xs.iter().map(|x| (2.0 * x).cos() + x).collect();
        let spline = Spline::new(&xs, &ys, Ends::Natural).expect("a table");
        let mut g = Graph::new();
        let x = g.var("x");
        let t = g.add_table(crate::profile::Tabulated::spline(
            "cam_profile",
            spline.clone(),
        ));
        let sx = g.sin(x);
        let f = g.table(t, 0, sx);
        let df = g.diff(f, x);
        let ddf = g.diff(df, x);
        for x0 in [-0.9, 0.1, 0.55, 1.0] {
            let [v, d, dd] = [f, df, ddf].map(|e| g.eval(&[e], &[x0])[0]);
            let s = spline.eval(x0.sin());
            assert_eq!(v, s[0]);
            assert!((d - s[1] * x0.cos()).abs() < 1e-14);
            assert!((dd - (s[2] * x0.cos().powi(2) - s[1] * x0.sin())).abs() < 1e-13);
            let h = 1e-5;
            let central = (g.eval(&[f], &[x0 + h])[0] - g.eval(&[f], &[x0 - h])[0]) / (2.0 * h);
            assert!((d - central).abs() < 1e-8, "{d} vs {central}");
        }
        // A constant argument folds; the fourth derivative vanishes.
        let c = g.constant(0.3);
        let slope = g.table(t, 1, c);
        assert_eq!(g.as_const(slope), Some(spline.eval(0.3)[1]));
        let zero = g.zero();
        assert_eq!(g.table(t, 4, x), zero);
    }

    #[test]
    fn commutative_operands_are_shared() {
        let mut g = Graph::new();
        let (x, y) = (g.var("x"), g.var("y"));
        assert_eq!(g.add(x, y), g.add(y, x));
        assert_eq!(g.mul(x, y), g.mul(y, x));
        let c2 = g.constant(2.0);
        let c3 = g.constant(3.0);
        let a = g.mul(c2, x);
        let b = g.mul(c3, a);
        let six = g.constant(6.0);
        assert_eq!(b, g.mul(six, x), "constant factors merge");
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let mut g = Graph::new();
        let x = g.var("x");
        // e = sin(x)·x³ / (1 + x²) + exp(0.3x)·√x + atan(x)·tanh(x) + x^x
        let s = g.sin(x);
        let x3 = g.powi(x, 3);
        let num = g.mul(s, x3);
        let one = g.one();
        let x2 = g.powi(x, 2);
        let den = g.add(one, x2);
        let t1 = g.div(num, den);
        let c = g.constant(0.3);
        let cx = g.mul(c, x);
        let ex = g.call(Func::Exp, cx);
        let sq = g.sqrt(x);
        let t2 = g.mul(ex, sq);
        let at = g.call(Func::Atan, x);
        let th = g.call(Func::Tanh, x);
        let t3 = g.mul(at, th);
        let xx = g.powf(x, x);
        let e = g.sum([t1, t2, t3, xx]);
        let d = g.diff(e, x);
        let d2 = g.diff(d, x);
        for &x0 in &[0.4, 1.1, 2.3] {
            let h = 1e-5;
            let f = |v: f64| g.eval(&[e], &[v])[0];
            let fd1 = (f(x0 + h) - f(x0 - h)) / (2.0 * h);
            let fd2 = (f(x0 + h) - 2.0 * f(x0) + f(x0 - h)) / (h * h);
            let [d1v, d2v] = [g.eval(&[d], &[x0])[0], g.eval(&[d2], &[x0])[0]];
            // Central differences: truncation O(h²)≈1e-10 relative for the first derivative;
            // the second difference loses ~eps/h² ≈ 2e-6 to rounding.
            assert!(
                (d1v - fd1).abs() < 1e-8 * (1.0 + fd1.abs()),
                "{d1v} vs {fd1}"
            );
            assert!(
                (d2v - fd2).abs() < 1e-4 * (1.0 + fd2.abs()),
                "{d2v} vs {fd2}"
            );
        }
    }

    #[test]
    fn substitution_composes() {
        let mut g = Graph::new();
        let (x, y) = (g.var("x"), g.var("y"));
        let x2 = g.powi(x, 2);
        let sy = g.sin(y);
        let e = g.substitute(x2, x, sy);
        let v = g.eval(&[e], &[0.0, 0.7])[0];
        assert_eq!(v, 0.7f64.sin().powi(2));
    }

    #[test]
    fn op_count_counts_shared_nodes_once() {
        let mut g = Graph::new();
        let (x, y) = (g.var("x"), g.var("y"));
        let s = g.sin(x);
        let p = g.mul(s, y);
        let d = g.sub(p, s);
        let count = g.op_count(&[d, p]);
        assert_eq!(count.sin_cos, 1);
        assert_eq!(count.mul, 1);
        assert_eq!(
            count.add_sub, 1,
            "the negation is absorbed into a subtraction"
        );
    }
}
