//! Inside one generated function: which nodes get `let` bindings and how expressions are
//! printed (names for variables and intermediates, operator precedence, the depth an
//! expression may be written inline).

use super::literals::lit;
use super::names::{Names, sanitize};
use super::names::{id_at, is_identifier};
use super::render::SECTION_MACRO;
use super::trigonometry::{TrigMemo, angle_name, trig_name, trig_name_of};
use crate::expr::{Graph, Guess, Id, Node, method_name};
use crate::profile::Func;
use std::collections::{HashMap, HashSet};
use std::fmt::Write;

/// The deepest an expression is written inline: a node whose operands, written inline, would
/// nest deeper gets a `let` binding of its own even when used once. A term of a long chain
/// (a sum through every body) would otherwise be one expression as deep as the chain, and
/// parsing, formatting and compiling the generated code all recurse on that depth. Binding
/// a term changes no value: the same operations run in the same order.
const MAX_INLINE_DEPTH: u32 = 32;

/// Decides which nodes get `let` bindings and prints expressions.
pub(super) struct Emitter<'g> {
    g: &'g Graph,
    /// Nodes read from an input expression instead of computed.
    given: HashMap<Id, String>,
    reachable: Vec<bool>,
    uses: Vec<u32>,
    /// The nodes of this function that use each node (its parents here).
    users: HashMap<Id, Vec<Id>>,
    /// Output nodes named after what they are written to (`m_3` for `m[3] = …`), for the
    /// names of their unlabelled terms.
    outputs: HashMap<Id, String>,
    pub(super) names: HashMap<Id, String>,
    vars: Names,
    /// The variables of the run-time parameters.
    parameters: HashSet<Id>,
    /// Sines and cosines computed together through the cache (by either node of a pair).
    pub(super) memo: HashMap<Id, TrigMemo>,
    /// Where an implicit variable's last solution is kept (`cache[4]`, `out[0].parameter`):
    /// its Newton solve starts there.
    pub(super) warm: HashMap<Id, String>,
    /// The argument that passes the derived parameter values to a residual (`&self.derived, `
    /// in a method, `derived, ` in a free function, nothing without run-time parameters).
    pub(super) derived_arg: String,
    /// The inputs of implicit variables: always bound (the solve's call reads them twice).
    solve_inputs: HashSet<Id>,
    /// Set when a solve's call passes the derived parameter values on.
    pub(super) solves_read_derived: bool,
    /// The bound result of each tabulated function's call, by (function, argument): every
    /// derivative read at one argument comes from one look-up.
    table_calls: HashMap<(u32, Id), String>,
    /// The bound result of each surface's call, by (surface, x, y), likewise.
    grid_calls: HashMap<(u32, Id, Id), String>,
    /// Sums with a product written `a.mul_add(b, c)`.
    pub(super) fused_multiply_add: bool,
}

impl<'g> Emitter<'g> {
    pub(super) fn new(
        g: &'g Graph,
        outputs: &[(String, Id)],
        given: &[(Id, String)],
        params: &[Id],
    ) -> Self {
        let roots: Vec<Id> = outputs.iter().map(|(_, id)| *id).collect();
        let given: HashMap<Id, String> = given.iter().cloned().collect();
        let stop: HashSet<Id> = given.keys().copied().collect();
        let reachable = g.reachable_until(&roots, &stop);
        let mut uses = vec![0u32; g.len()];
        let mut users: HashMap<Id, Vec<Id>> = HashMap::new();
        for (i, &r) in reachable.iter().enumerate() {
            if r && !stop.contains(&id_at(g, i)) {
                let mut children = g.children(id_at(g, i));
                for &c in &children {
                    uses[c.index()] += 1;
                }
                children.dedup();
                for c in children {
                    users.entry(c).or_default().push(id_at(g, i));
                }
            }
        }
        for r in &roots {
            uses[r.index()] += 1;
        }
        let mut output_names = HashMap::new();
        for (target, id) in outputs {
            output_names
                .entry(*id)
                .or_insert_with(|| output_name(target));
        }
        let solve_inputs = (0..g.len())
            .filter(|&i| reachable[i])
            .filter_map(|i| g.implicit_of(id_at(g, i)))
            .flat_map(|def| def.inputs.iter().copied())
            .collect();
        Emitter {
            g,
            given,
            reachable,
            uses,
            users,
            outputs: output_names,
            names: HashMap::new(),
            vars: Names::of_vars(g),
            parameters: params.iter().copied().collect(),
            memo: HashMap::new(),
            warm: HashMap::new(),
            derived_arg: String::new(),
            solve_inputs,
            solves_read_derived: false,
            table_calls: HashMap::new(),
            grid_calls: HashMap::new(),
            fused_multiply_add: false,
        }
    }

    fn wants_binding(&self, id: Id) -> bool {
        if self.given.contains_key(&id) || self.solve_inputs.contains(&id) {
            return true;
        }
        if self.g.implicit_of(id).is_some() {
            return true;
        }
        match self.g.node(id) {
            Node::Const(_) | Node::Var(_) | Node::Neg(_) => false,
            Node::Call(..) | Node::Powf(..) | Node::Table(..) | Node::Grid(..) => true,
            _ => self.uses[id.index()] >= 2 || self.g.label_of(id).is_some(),
        }
    }

    /// The `let` bindings in creation order, with section comments; and the variables used.
    pub(super) fn bindings(&mut self) -> (String, HashSet<Id>) {
        let mut text = String::new();
        let mut used_vars = HashSet::new();
        // Every input's name is taken, but that of a parameter this function reads only
        // through stored values (`let k2 = self.derived.k2;` may then be called `k2`).
        let mut taken: HashSet<String> = self
            .vars
            .by_var
            .iter()
            .filter(|&(&k, _)| {
                let id = self.g.var_id(k);
                !self.parameters.contains(&id)
                    || (self.reachable[id.index()] && !self.given.contains_key(&id))
            })
            .map(|(_, name)| name.clone())
            .collect();
        for word in [
            "q", "qd", "qdd", "t", "m", "f", "j", "c", "h", "out", "applied", "power", "cache",
        ] {
            taken.insert(word.to_string());
        }
        for word in [
            "kinetic",
            "gravity",
            "spring",
            "x",
            "y",
            "slope",
            "curvature",
        ] {
            taken.insert(word.to_string());
        }
        for word in ["conv1", "conv2", "p0", "p1", "p2", "j1", "j2", "k"] {
            taken.insert(word.to_string());
        }
        for source in self.given.values().filter(|s| is_identifier(s)) {
            taken.insert(source.clone());
        }
        let mut section: Option<String> = None;
        // How deep each node's text would nest if written inline (0 once it has a name).
        let mut depth = vec![0u32; self.g.len()];
        for i in self.emission_order() {
            let id = id_at(self.g, i);
            if matches!(self.g.node(id), Node::Var(_)) && !self.given.contains_key(&id) {
                used_vars.insert(id);
            }
            if self.names.contains_key(&id) {
                continue;
            }
            depth[i] = self.inline_depth(id, &depth);
            let too_deep = depth[i] > MAX_INLINE_DEPTH && !matches!(self.g.node(id), Node::Neg(_));
            if !self.wants_binding(id) && !too_deep {
                continue;
            }
            depth[i] = 0;
            let this_section = self.g.section_of(id).map(str::to_string);
            if this_section != section {
                if let Some(s) = &this_section {
                    let clean = s.replace(['"', '\\'], "'");
                    let _ = writeln!(text, "{SECTION_MACRO}!(\"{clean}\");");
                }
                section = this_section;
            }
            if let Some(m) = self.memo.get(&id).copied() {
                let line = self.memo_binding(m, &mut taken);
                text.push_str(&line);
                continue;
            }
            if let Some(pair) = self.trig_pair(id) {
                let line = self.pair_binding(pair, &mut taken);
                text.push_str(&line);
                continue;
            }
            if let Some(source) = self.given.get(&id).filter(|s| is_identifier(s)) {
                // A scalar argument of the function, read under its own name.
                self.names.insert(id, source.clone());
                continue;
            }
            if self.g.implicit_of(id).is_some() && !self.given.contains_key(&id) {
                let name = self.vars.var(self.g, id);
                let _ = writeln!(text, "let {name} = {};", self.solve_call(id));
                self.solves_read_derived |= !self.derived_arg.is_empty();
                self.names.insert(id, name);
                continue;
            }
            if let Node::Table(t, _, a) = self.g.node(id) {
                self.bind_table_call(t, a, &mut text, &mut taken);
            }
            if let Node::Grid(k, _, a, b) = self.g.node(id) {
                self.bind_grid_call(k, (a, b), &mut text, &mut taken);
            }
            let expr = match self.given.get(&id) {
                Some(source) => source.clone(),
                None => self.render(id).0,
            };
            let name = match self.given_field(id) {
                Some(field) => fresh(&field, &mut taken),
                // A variable read from an argument (`tau[2]`) under the variable's own name.
                None if let Node::Var(k) = self.g.node(id) => {
                    let own = &self.g.var_names()[k as usize];
                    fresh(
                        &super::names::sanitize(own.trim_start_matches('_')),
                        &mut taken,
                    )
                }
                None => self.fresh_name(id, &mut taken),
            };
            // A constant bound to a name is typed: a bare float literal read as a method's
            // receiver (`zero.atan2(x)`) would leave its type ambiguous.
            let annotation = if matches!(self.g.node(id), Node::Const(_)) {
                ": f64"
            } else {
                ""
            };
            let _ = writeln!(text, "let {name}{annotation} = {expr};");
            self.names.insert(id, name);
        }
        (text, used_vars)
    }

    /// How deeply the text of `id` would nest if written inline: one more than its deepest
    /// operand written inline (`depth` holds the operands', 0 for a named one).
    fn inline_depth(&self, id: Id, depth: &[u32]) -> u32 {
        if self.given.contains_key(&id) {
            return 1;
        }
        let operands = match self.g.node(id) {
            Node::Const(_) | Node::Var(_) => return 1,
            Node::Add(a, b)
            | Node::Mul(a, b)
            | Node::Div(a, b)
            | Node::Powf(a, b)
            | Node::Grid(_, _, a, b) => [a, b],
            Node::Neg(a) | Node::Powi(a, _) | Node::Call(_, a) | Node::Table(_, _, a) => [a, a],
        };
        let of = |c: Id| {
            if self.names.contains_key(&c) {
                0
            } else {
                depth[c.index()]
            }
        };
        1 + of(operands[0]).max(of(operands[1]))
    }

    /// The reachable nodes, children before parents, each section's nodes kept together
    /// where the dependencies allow (a topological order preferring the earliest section,
    /// then creation order): a node rebuilt by a rewriting pass is printed under its
    /// original heading, not after everything else.
    fn emission_order(&self) -> Vec<usize> {
        use std::cmp::Reverse;
        use std::collections::BinaryHeap;
        let n = self.g.len();
        let deps = |i: usize| -> Vec<usize> {
            let id = id_at(self.g, i);
            if self.given.contains_key(&id) {
                return Vec::new();
            }
            let mut c: Vec<usize> = self.g.children(id).iter().map(|c| c.index()).collect();
            c.dedup();
            c
        };
        let mut waiting = vec![0usize; n];
        let mut parents: Vec<Vec<usize>> = vec![Vec::new(); n];
        let mut ready = BinaryHeap::new();
        for i in (0..n).filter(|&i| self.reachable[i]) {
            let d = deps(i);
            waiting[i] = d.len();
            for c in d {
                parents[c].push(i);
            }
            if waiting[i] == 0 {
                ready.push(Reverse((self.g.section_index(id_at(self.g, i)), i)));
            }
        }
        let mut order = Vec::with_capacity(n);
        while let Some(Reverse((_, i))) = ready.pop() {
            order.push(i);
            for &p in &parents[i] {
                waiting[p] -= 1;
                if waiting[p] == 0 {
                    ready.push(Reverse((self.g.section_index(id_at(self.g, p)), p)));
                }
            }
        }
        order
    }

    /// The name of a bound node: Robotran's `s_q1`/`c_q1_q2` for sines and cosines of
    /// joint angles, `angle_q1_q2` for a sum of joint angles, the label the derivation gave
    /// it (`omega_body2_z`, `acc_body3_x`, `m_q1_q2`, `a_slope`, …), `<name>_sq` for the
    /// square of a named node, else `<label>_t<k>`: the k-th unnamed term of the nearest
    /// named expression that uses it.
    fn fresh_name(&self, id: Id, taken: &mut HashSet<String>) -> String {
        if let Some(base) = self.structural_name(id) {
            return fresh(&base, taken);
        }
        let prefix = self.term_name(id);
        let mut k = 1;
        loop {
            let name = format!("{prefix}{k}");
            if taken.insert(name.clone()) {
                return name;
            }
            k += 1;
        }
    }

    /// The Newton solve of an implicit variable (a contact parameter):
    /// `rt::contact::solve(guess, range, |s_try| <residual>(…), |s_try| <objective>(…))`,
    /// starting from the kept solution where the function has one.
    fn solve_call(&self, id: Id) -> String {
        let Some(def) = self.g.implicit_of(id) else {
            return "f64::NAN".to_string();
        };
        let base = self.vars.var(self.g, id);
        let inputs: Vec<String> = def.inputs.iter().map(|&i| self.print(i, 0)).collect();
        let cold = match def.guess {
            Guess::Input(i) => inputs[i].clone(),
            Guess::Angle { x, y } => format!("{}.atan2({})", inputs[y], inputs[x]),
            Guess::Scan => "f64::NAN".to_string(),
            Guess::Pitch(pitch) => pitch_call(&inputs, pitch, def.range),
        };
        let guess = match self.warm.get(&id) {
            Some(slot) => format!("rt::contact::warm_or({slot}, || {cold})"),
            None => cold,
        };
        let args = format!("{}{}, s_try", self.derived_arg, inputs.join(", "));
        format!(
            "rt::contact::solve({guess}, ({}, {}), |s_try| {base}_residual({args}), \
             |s_try| {base}_objective({args}))",
            lit(def.range.0),
            lit(def.range.1)
        )
    }

    /// `let <name>_at = eval_<name>(a);` the first time tabulated function `t` is read at `a`
    /// (the function's value is then bound as `<name>`, which must not hide the function).
    fn bind_table_call(&mut self, t: u32, a: Id, text: &mut String, taken: &mut HashSet<String>) {
        if self.table_calls.contains_key(&(t, a)) {
            return;
        }
        let name = self
            .g
            .tables()
            .get(t as usize)
            .map_or("table", |t| t.name.as_str());
        let call = fresh(&format!("{name}_at"), taken);
        let _ = writeln!(text, "let {call} = eval_{name}({});", self.print(a, 0));
        self.table_calls.insert((t, a), call);
    }

    /// `let <name>_at = eval_<name>(x, y);` the first time surface `k` is read at (x, y):
    /// every partial derivative there comes from that one call.
    fn bind_grid_call(
        &mut self,
        k: u32,
        (a, b): (Id, Id),
        text: &mut String,
        taken: &mut HashSet<String>,
    ) {
        if self.grid_calls.contains_key(&(k, a, b)) {
            return;
        }
        let name = self
            .g
            .grids()
            .get(k as usize)
            .map_or("surface", |g| g.name.as_str());
        let call = fresh(&format!("{name}_at"), taken);
        let _ = writeln!(
            text,
            "let {call} = eval_{name}({}, {});",
            self.print(a, 0),
            self.print(b, 0)
        );
        self.grid_calls.insert((k, a, b), call);
    }

    /// (sin a, cos a, a) when `id` is one of the two and the function needs the other too
    /// (neither cached through `rt::sin_cos_memo`): both come from one `rt::trig::sin_cos`.
    fn trig_pair(&self, id: Id) -> Option<(Id, Id, Id)> {
        let Node::Call(f @ (Func::Sin | Func::Cos), angle) = self.g.node(id) else {
            return None;
        };
        let other = if f == Func::Sin { Func::Cos } else { Func::Sin };
        let partner = self.g.find(Node::Call(other, angle))?;
        // Both computed here: neither read from an argument nor already named.
        let computed = |x: Id| {
            !self.given.contains_key(&x)
                && !self.names.contains_key(&x)
                && !self.memo.contains_key(&x)
        };
        let wanted = self.reachable[partner.index()] && computed(id) && computed(partner);
        let (sin, cos) = if f == Func::Sin {
            (id, partner)
        } else {
            (partner, id)
        };
        wanted.then_some((sin, cos, angle))
    }

    /// `let (s_a, c_a) = rt::trig::sin_cos(a);`, naming both nodes: one argument reduction
    /// for both, and no call into the C library (which saves and restores the
    /// floating-point environment on every call).
    fn pair_binding(
        &mut self,
        (sin, cos, angle): (Id, Id, Id),
        taken: &mut HashSet<String>,
    ) -> String {
        let sin_name = self.fresh_name(sin, taken);
        let cos_name = self.fresh_name(cos, taken);
        let line = format!(
            "let ({sin_name}, {cos_name}) = rt::trig::sin_cos({});\n",
            self.print(angle, 0)
        );
        self.names.insert(sin, sin_name);
        self.names.insert(cos, cos_name);
        line
    }

    /// `let (s_a, c_a) = rt::sin_cos_memo(a, &mut cache[k..k + 3]);`, naming both nodes.
    fn memo_binding(&mut self, m: TrigMemo, taken: &mut HashSet<String>) -> String {
        let angle = match self.g.node(m.sin) {
            Node::Call(_, angle) => angle,
            _ => m.sin,
        };
        let sin = self.fresh_name(m.sin, taken);
        let cos = self.fresh_name(m.cos, taken);
        let line = format!(
            "let ({sin}, {cos}) = rt::sin_cos_memo({}, &mut cache[{}..{}]);\n",
            self.print(angle, 0),
            m.slot,
            m.slot + 3
        );
        self.names.insert(m.sin, sin);
        self.names.insert(m.cos, cos);
        line
    }

    /// The field a given node is read from (`k2` for `self.derived.k2`), as its name.
    fn given_field(&self, id: Id) -> Option<String> {
        let source = self.given.get(&id)?;
        let (_, field) = source.rsplit_once('.')?;
        field
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_')
            .then(|| field.to_string())
    }

    fn structural_name(&self, id: Id) -> Option<String> {
        if let Node::Call(f, a) = self.g.node(id) {
            // The sine of a function's scalar argument `s`: `s_s`, as for a joint angle.
            if let Some(argument) = self.given.get(&a).filter(|s| is_identifier(s)) {
                if let Some(name) = trig_name_of(f, argument) {
                    return Some(name);
                }
            }
            if let Some(name) = trig_name(self.g, f, a) {
                return Some(name);
            }
        }
        if let Some(label) = self.g.label_of(id) {
            return Some(sanitize(label));
        }
        match self.g.node(id) {
            Node::Table(t, order, _) => self.g.tables().get(t as usize).map(|t| {
                let suffix = ["", "_d1", "_d2", "_d3"]
                    .get(usize::from(order))
                    .unwrap_or(&"");
                format!("{}{suffix}", t.name)
            }),
            Node::Grid(k, (p, q), ..) => self.g.grids().get(k as usize).map(|g| {
                let (x, y) = ("x".repeat(usize::from(p)), "y".repeat(usize::from(q)));
                match (p, q) {
                    (0, 0) => g.name.clone(),
                    _ => format!("{}_d{x}{y}", g.name),
                }
            }),
            Node::Add(..) => angle_name(self.g, id).map(|parts| format!("angle_{parts}")),
            Node::Mul(a, b) if a == b => self.names.get(&a).map(|name| format!("{name}_sq")),
            _ => None,
        }
    }

    /// `<label>_t` of the nearest labelled node that uses `id` (breadth first through the
    /// function's nodes, smallest id first), or `t` when none does.
    fn term_name(&self, id: Id) -> String {
        let mut frontier = vec![id];
        let mut seen = HashSet::new();
        while !frontier.is_empty() {
            let mut next = Vec::new();
            for node in frontier {
                for &user in self.users.get(&node).map(Vec::as_slice).unwrap_or(&[]) {
                    if !seen.insert(user) {
                        continue;
                    }
                    if let Some(label) = self.g.label_of(user) {
                        return format!("{}_t", sanitize(label));
                    }
                    if let Some(output) = self.outputs.get(&user) {
                        return format!("{output}_t");
                    }
                    next.push(user);
                }
            }
            next.sort_unstable();
            frontier = next;
        }
        "t".to_string()
    }

    /// Expression text of a node, using names of bound children. Returns the text and its
    /// precedence (1 sum, 2 product, 3 unary, 4 method call, 5 atom).
    fn render(&self, id: Id) -> (String, u8) {
        match self.g.node(id) {
            Node::Const(bits) => {
                let v = f64::from_bits(bits);
                (lit(v), if v < 0.0 { 3 } else { 5 })
            }
            Node::Var(_) => (self.vars.var(self.g, id), 5),
            Node::Add(a, b) => self.render_add(a, b),
            Node::Mul(a, b) => (format!("{} * {}", self.print(a, 2), self.print(b, 3)), 2),
            Node::Div(a, b) => (format!("{} / {}", self.print(a, 2), self.print(b, 3)), 2),
            Node::Neg(a) => match self.g.node(a) {
                Node::Mul(..) | Node::Div(..) if !self.names.contains_key(&a) => {
                    (format!("-{}", self.print(a, 2)), 2)
                }
                _ => (format!("-{}", self.print(a, 3)), 3),
            },
            Node::Powi(a, n) => (format!("{}.powi({n})", self.receiver(a)), 4),
            Node::Powf(a, b) => (
                format!("{}.powf({})", self.receiver(a), self.print(b, 0)),
                4,
            ),
            Node::Call(f, a) => (format!("{}.{}()", self.receiver(a), method_name(f)), 4),
            Node::Table(t, order, a) => match self.table_calls.get(&(t, a)) {
                Some(call) => (format!("{call}[{order}]"), 5),
                None => {
                    let name = self.g.tables().get(t as usize).map_or("table", |t| &t.name);
                    (format!("eval_{name}({})[{order}]", self.print(a, 0)), 4)
                }
            },
            Node::Grid(k, (p, q), a, b) => match self.grid_calls.get(&(k, a, b)) {
                Some(call) => (format!("{call}[{p}][{q}]"), 5),
                None => {
                    let name = self
                        .g
                        .grids()
                        .get(k as usize)
                        .map_or("surface", |g| &g.name);
                    let (x, y) = (self.print(a, 0), self.print(b, 0));
                    (format!("eval_{name}({x}, {y})[{p}][{q}]"), 4)
                }
            },
        }
    }

    fn render_add(&self, a: Id, b: Id) -> (String, u8) {
        if self.fused_multiply_add {
            if let Some(text) = self.render_fused(a, b) {
                return (text, 4);
            }
        }
        let neg = |x: Id| match self.g.node(x) {
            Node::Neg(y) if !self.names.contains_key(&x) => Some(y),
            _ => None,
        };
        let negative_const = |x: Id| self.g.as_const(x).filter(|v| *v < 0.0);
        let text = match (neg(a), neg(b)) {
            (None, Some(y)) => format!("{} - {}", self.print(a, 1), self.print(y, 2)),
            (Some(x), None) => format!("{} - {}", self.print(b, 1), self.print(x, 2)),
            _ => match (negative_const(a), negative_const(b)) {
                (None, Some(v)) => format!("{} - {}", self.print(a, 1), lit(-v)),
                (Some(v), None) => format!("{} - {}", self.print(b, 1), lit(-v)),
                _ => format!("{} + {}", self.print(a, 1), self.print(b, 2)),
            },
        };
        (text, 1)
    }

    /// `a + b` as `x.mul_add(y, c)` when one side is a product not bound to a name
    /// (`±x · y`), the other being the addend c (the second side's product first). Constant
    /// factors are the multiplier, so that the receiver is a name: `s.mul_add(0.2, c)`.
    fn render_fused(&self, a: Id, b: Id) -> Option<String> {
        let product = |x: Id| -> Option<(Id, Id, bool)> {
            if self.names.contains_key(&x) {
                return None;
            }
            match self.g.node(x) {
                Node::Mul(p, q) => Some((p, q, false)),
                Node::Neg(y) if !self.names.contains_key(&y) => match self.g.node(y) {
                    Node::Mul(p, q) => Some((p, q, true)),
                    _ => None,
                },
                _ => None,
            }
        };
        let ((p, q, negative), addend) = match (product(b), product(a)) {
            (Some(f), _) => (f, a),
            (None, Some(f)) => (f, b),
            (None, None) => return None,
        };
        let (x, y) = match self.g.as_const(p) {
            Some(_) if !self.names.contains_key(&p) => (q, p),
            _ => (p, q),
        };
        let multiplier = match (self.g.as_const(y), negative) {
            (Some(v), true) if !self.names.contains_key(&y) => lit(-v),
            (_, true) => format!("-{}", self.print(y, 3)),
            (_, false) => self.print(y, 0),
        };
        Some(format!(
            "{}.mul_add({multiplier}, {})",
            self.receiver(x),
            self.print(addend, 0)
        ))
    }

    fn receiver(&self, a: Id) -> String {
        match self.g.as_const(a) {
            Some(v) if !self.names.contains_key(&a) => format!("({}_f64)", lit(v)),
            _ => self.print(a, 4),
        }
    }

    /// Prints a node for a context needing at least precedence `min`.
    pub(super) fn print(&self, id: Id, min: u8) -> String {
        if let Some(name) = self.names.get(&id) {
            return name.clone();
        }
        let (text, prec) = self.render(id);
        if prec < min {
            format!("({text})")
        } else {
            text
        }
    }
}

/// `base`, or `base_2`, `base_3`, … when taken; marks the name taken.
fn fresh(base: &str, taken: &mut HashSet<String>) -> String {
    let mut name = base.to_string();
    let mut k = 1;
    while !taken.insert(name.clone()) {
        k += 1;
        name = format!("{base}_{k}");
    }
    name
}

/// `m_3` for the target `m[3]`, `mass_3` for `out.mass[3]`, `kinetic` for `let kinetic`.
fn output_name(target: &str) -> String {
    let plain = target
        .trim_start_matches("let ")
        .trim_start_matches("out.")
        .trim_start_matches("out[");
    let name: String = plain
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    let name = name.trim_matches('_').replace("__", "_");
    if name.is_empty() {
        "value".to_string()
    } else if name.starts_with(|c: char| c.is_ascii_digit()) {
        // `out[0].direction[1]`: the contact's index first.
        format!("contact{name}")
    } else {
        name
    }
}

/// `rt::contact::pitch_parameter(x, y, rt::contact::Pitch::…, range)`: a designed cam's
/// cold start.
fn pitch_call(
    inputs: &[String],
    pitch: camchain_runtime::contact::Pitch,
    range: (f64, f64),
) -> String {
    use camchain_runtime::contact::Pitch;
    let path = match pitch {
        Pitch::Translating { offset } => {
            format!(
                "rt::contact::Pitch::Translating {{ offset: {} }}",
                lit(offset)
            )
        }
        Pitch::Oscillating { pivot, arm, swing } => format!(
            "rt::contact::Pitch::Oscillating {{ pivot: [{}, {}], arm: {}, swing: {} }}",
            lit(pivot[0]),
            lit(pivot[1]),
            lit(arm),
            lit(swing)
        ),
    };
    format!(
        "rt::contact::pitch_parameter({}, {}, {path}, ({}, {}))",
        inputs[0],
        inputs[1],
        lit(range.0),
        lit(range.1)
    )
}
