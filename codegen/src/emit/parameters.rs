//! Emission of run-time parameters: the `Parameters` struct with the file's defaults, the
//! checks a parameter set must pass (the build's own, with the build's messages and
//! locations), and `Derived`, every quantity that depends on the parameters alone, computed
//! once when the parameters are set (SD/FAST's `sdinit`), so that the functions a
//! right-hand side calls read a stored number wherever the folded code had a constant.

use super::function::emit_function_given;
use super::literals::{ALLOW_LITERALS, ALLOW_UNUSED, lit};
use super::names::sanitize;
use super::spec::{FIELD, FIELDS, FunctionSpec, Param};
use crate::derive::Derivation;
use crate::expr::{Graph, Id, OpCount};
use crate::model::{Field, FieldLocation, Model, RuntimeCheck};
use std::collections::HashSet;
use std::fmt::Write;

/// What the generated code needs to read parameters at run time.
pub(super) struct RuntimeParameters {
    /// Nodes that depend on run-time parameters and on nothing else (no q, q̇, t).
    param_only: Vec<bool>,
    /// The parameter-only nodes the functions read, with their field names in `Derived`.
    derived: Vec<(Id, String)>,
}

impl RuntimeParameters {
    /// `None` for a model without run-time parameters (its code is what it always was).
    /// `roots` are the outputs of every generated function.
    pub(super) fn new(model: &Model, d: &Derivation, roots: &[Id]) -> Option<Self> {
        model.runtime_parameters().next()?;
        let g = &d.graph;
        let param_only = param_only_nodes(g, &d.symbols.params);
        let reachable = g.reachable(roots);
        let mut frontier = vec![false; g.len()];
        for &r in roots {
            frontier[r.index()] |= param_only[r.index()];
        }
        for i in (0..g.len()).filter(|&i| reachable[i] && !param_only[i]) {
            for c in g.children(g.id_from_index(i)) {
                frontier[c.index()] |= param_only[c.index()];
            }
        }
        let mut taken = HashSet::new();
        let derived = (0..g.len())
            .filter(|&i| frontier[i])
            .map(|i| {
                let id = g.id_from_index(i);
                (id, unique(&mut taken, &derived_name(g, id)))
            })
            .collect();
        Some(RuntimeParameters {
            param_only,
            derived,
        })
    }

    /// True when the node depends on run-time parameters only.
    pub(super) fn is_param_only(&self, id: Id) -> bool {
        self.param_only[id.index()]
    }

    /// The derived nodes as a function reads them: `{receiver}.derived.<name>`.
    pub(super) fn given(&self, receiver: &str) -> Vec<(Id, String)> {
        self.derived
            .iter()
            .map(|(id, name)| (*id, format!("{receiver}derived.{name}")))
            .collect()
    }

    /// Operations of `derive` (once per parameter set, not per evaluation).
    pub(super) fn derive_count(&self, d: &Derivation) -> OpCount {
        let roots: Vec<Id> = self.derived.iter().map(|(id, _)| *id).collect();
        d.graph.op_count(&roots)
    }

    /// The items: `Parameters`, `Derived`, `derive`, `check`, and the parts of `Model`
    /// that depend on them.
    pub(super) fn items(&self, model: &Model, d: &Derivation, source: &str) -> String {
        let mut out = format!(
            "/// The model file, as the build showed it (the errors of [`Model::new`] name it).\n\
             const FILE: &str = {source:?};\n"
        );
        out.push_str(&parameters_struct(model, source));
        out.push_str(&self.derived_struct());
        out.push_str(&self.derive_function(d).0);
        out.push_str(&check_function(model, d, source));
        out.push_str(&initial_function(model, d));
        out
    }

    fn derived_struct(&self) -> String {
        let fields: String = self
            .derived
            .iter()
            .map(|(_, name)| format!("{name}: f64,\n"))
            .collect();
        format!(
            "/// The quantities that depend on the run-time parameters alone, computed once per \
             parameter set by [`derive`].\n\
             #[derive(Debug, Clone, Copy, PartialEq)]\n\
             struct Derived {{\n{fields}}}\n"
        )
    }

    fn derive_function(&self, d: &Derivation) -> (String, OpCount) {
        let spec = FunctionSpec {
            doc: "Every quantity the generated functions read that depends on the parameters \
                  alone."
                .into(),
            name: "derive".into(),
            params: vec![Param {
                name: "p",
                ty: "&Parameters",
                always_used: false,
            }],
            ret: Some("Derived"),
            outputs: self
                .derived
                .iter()
                .map(|(id, name)| (format!("{FIELD}{name}"), *id))
                .collect(),
            tail: format!("Derived {{ {FIELDS} }}"),
        };
        let (text, count) = emit_function_given(d, &spec, "", false, &[]);
        (format!("{ALLOW_LITERALS}\n{text}"), count)
    }
}

/// Marks the nodes that depend on a run-time parameter and on no other variable.
fn param_only_nodes(g: &Graph, params: &[Id]) -> Vec<bool> {
    let params: HashSet<Id> = params.iter().copied().collect();
    let mut on_param = vec![false; g.len()];
    let mut on_state = vec![false; g.len()];
    for i in 0..g.len() {
        let id = g.id_from_index(i);
        if matches!(g.node(id), crate::expr::Node::Var(_)) {
            on_param[i] = params.contains(&id);
            on_state[i] = !on_param[i];
            continue;
        }
        for c in g.children(id) {
            on_param[i] |= on_param[c.index()];
            on_state[i] |= on_state[c.index()];
        }
    }
    on_param
        .iter()
        .zip(&on_state)
        .map(|(&p, &s)| p && !s)
        .collect()
}

/// The field name of a derived node: its label, or `term` for an unlabelled one.
fn derived_name(g: &Graph, id: Id) -> String {
    match g.label_of(id) {
        Some(label) => sanitize(label),
        None => match g.node(id) {
            crate::expr::Node::Var(k) => sanitize(&g.var_names()[k as usize]),
            _ => "term".to_string(),
        },
    }
}

/// `base`, or `base_2`, `base_3`, … if taken (`term1`, `term2`, … for the unnamed).
fn unique(taken: &mut HashSet<String>, base: &str) -> String {
    if base != "term" && taken.insert(base.to_string()) {
        return base.to_string();
    }
    let mut k = if base == "term" { 1 } else { 2 };
    loop {
        let name = if base == "term" {
            format!("term{k}")
        } else {
            format!("{base}_{k}")
        };
        if taken.insert(name.clone()) {
            return name;
        }
        k += 1;
    }
}

/// The documented `Parameters` struct and its access by name; `file` names the model file
/// in errors.
fn parameters_struct(model: &Model, file: &str) -> String {
    let runtime: Vec<_> = model.runtime_parameters().collect();
    let fields: String = runtime
        .iter()
        .map(|(_, p)| {
            let mut doc = if p.description.is_empty() {
                format!("`{}`", p.name)
            } else {
                p.description.trim_end_matches('.').to_string()
            };
            if !p.unit.is_empty() {
                let _ = write!(doc, " ({})", p.unit);
            }
            let _ = write!(doc, "; default {}", p.default);
            let range = match (p.min, p.max) {
                (Some(a), Some(b)) => format!(", in [{a}, {b}]"),
                (Some(a), None) => format!(", at least {a}"),
                (None, Some(b)) => format!(", at most {b}"),
                (None, None) => String::new(),
            };
            format!("/// {doc}{range}.\npub {}: f64,\n", p.name)
        })
        .collect();
    let defaults: String = runtime
        .iter()
        .map(|(_, p)| format!("{}: {},\n", p.name, lit(p.default)))
        .collect();
    let names: Vec<String> = runtime
        .iter()
        .map(|(_, p)| format!("{:?}", p.name))
        .collect();
    let to_values: Vec<String> = runtime
        .iter()
        .map(|(_, p)| format!("self.{}", p.name))
        .collect();
    let n = runtime.len();
    let set_arms: String = runtime
        .iter()
        .map(|(_, p)| format!("{:?} => self.{} = value,\n", p.name, p.name))
        .collect();
    let get_arms: String = runtime
        .iter()
        .map(|(_, p)| format!("{:?} => Some(self.{}),\n", p.name, p.name))
        .collect();
    let from_values: String = runtime
        .iter()
        .enumerate()
        .map(|(k, (_, p))| format!("{}: values[{k}],\n", p.name))
        .collect();
    let folded: Vec<String> = model
        .parameters
        .iter()
        .filter(|p| p.constant)
        .map(|p| format!("({:?}, {})", p.name, location_from(&p.constant_at, file)))
        .collect();
    let constant_names: Vec<String> = model
        .parameters
        .iter()
        .filter(|p| p.constant)
        .map(|p| format!("{:?}", p.name))
        .collect();
    let list_at = location_from(&model.parameters_at, file);
    format!(
        "/// The run-time parameters of `{name}`, with the model file's values as defaults. \
         Give them to [`Model::new`], which checks them as the build checks the file.\n\
         #[derive(Debug, Clone, Copy, PartialEq)]\n\
         #[allow(non_snake_case)]\n\
         pub struct Parameters {{\n{fields}}}\n\
         impl Default for Parameters {{\n\
         fn default() -> Self {{ Parameters {{ {defaults} }} }}\n}}\n\
         {ALLOW_UNUSED}\n\
         impl Parameters {{\n\
         /// The parameters' names, in the order of [`Parameters::values`].\n\
         pub const NAMES: [&str; {n}] = [{names}];\n\
         /// The values, in the order of [`Parameters::NAMES`].\n\
         pub fn values(&self) -> [f64; {n}] {{ [{to_values}] }}\n\
         /// The parameters from values in the order of [`Parameters::NAMES`].\n\
         pub fn from_values(values: [f64; {n}]) -> Self {{ Parameters {{ {from_values} }} }}\n\
         /// The value of the parameter called `name`, if there is one.\n\
         pub fn get(&self, name: &str) -> Option<f64> {{\n\
         match name {{ {get_arms} _ => None }}\n}}\n\
         /// Sets the parameter called `name`; an unknown name, or a parameter folded at \
         build time (`constant: true`), is an error located in the model file. The value \
         itself is checked by [`Model::new`].\n\
         pub fn set(&mut self, name: &str, value: f64) -> Result<(), rt::ParameterError> {{\n\
         match name {{\n{set_arms}\
         _ => {{\n\
         let message = match FOLDED.iter().find(|(folded, _)| *folded == name) {{\n\
         Some(&(_, at)) => return rt::parameters::located(at, Err(rt::parameters::checks::constant_parameter(name))),\n\
         None => rt::parameters::checks::unknown_parameter_among(name, &Self::NAMES, &[{constant_names}]),\n\
         }};\n\
         return rt::parameters::located({list_at}, Err(message));\n\
         }}\n\
         }}\n\
         Ok(())\n}}\n}}\n\
         /// The parameters folded into this code (`constant: true`), with where the file says so.\n\
         const FOLDED: &[(&str, rt::parameters::Location)] = &[{folded}];\n",
        name = model.name,
        names = names.join(", "),
        to_values = to_values.join(", "),
        constant_names = constant_names.join(", "),
        folded = folded.join(", "),
    )
}

/// `rt::parameters::Location::at(FILE, line, column, "field")` for a located field (the
/// module defines `FILE`, the model file as the build shows it).
fn location_from(at: &FieldLocation, _file: &str) -> String {
    format!(
        "rt::parameters::Location::at(FILE, {}, {}, {:?})",
        at.line, at.column, at.field
    )
}

/// A binding name for the value of a field: its path (`bodies_1_joint_spring_stiffness`).
fn value_name(path: &str) -> String {
    let name: String = path
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    let mut out = String::new();
    for part in name.split('_').filter(|p| !p.is_empty()) {
        if !out.is_empty() {
            out.push('_');
        }
        out.push_str(part);
    }
    out
}

/// `check`: the build's checks of every value that depends on run-time parameters, in the
/// build's order, with its messages and locations.
fn check_function(model: &Model, d: &Derivation, file: &str) -> String {
    // Each field's value is bound once, named after the first check's path.
    let mut names: std::collections::BTreeMap<Field, String> = std::collections::BTreeMap::new();
    for check in &model.runtime_checks {
        let (fields, at): (Vec<Field>, &FieldLocation) = match check {
            RuntimeCheck::Bounds { .. } => continue,
            RuntimeCheck::Followable(k, at) => (vec![Field::Radius(*k)], &at[0]),
            RuntimeCheck::Finite(f, at)
            | RuntimeCheck::Positive(f, _, at)
            | RuntimeCheck::NonNegative(f, _, at) => (vec![*f], at),
            RuntimeCheck::Inertia(b, at) => (
                (0..9).map(|e| Field::Inertia(*b, e / 3, e % 3)).collect(),
                at,
            ),
        };
        for f in fields {
            if d.fields.contains_key(&f) && !names.contains_key(&f) {
                let mut name = value_name(&at.field);
                if let Field::Inertia(_, r, c) = f {
                    name = format!("{}_{}{}", value_name(&at.field), r + 1, c + 1);
                }
                while names.values().any(|n| *n == name) {
                    name.push_str("_2");
                }
                names.insert(f, name);
            }
        }
    }
    let value_of = |field: Field| -> String {
        match names.get(&field) {
            Some(name) => name.clone(),
            None => lit(constant_value(model, field)),
        }
    };
    let mut needed: Vec<(String, Id)> = Vec::new();
    let mut statements = String::new();
    let mut need = |field: Field| {
        if let (Some(&id), Some(name)) = (d.fields.get(&field), names.get(&field)) {
            if !needed.iter().any(|(n, _)| n == name) {
                needed.push((name.clone(), id));
            }
        }
    };
    for check in &model.runtime_checks {
        match check {
            RuntimeCheck::Bounds { parameter, at } => {
                let p = &model.parameters[*parameter];
                let opt =
                    |v: Option<f64>| v.map_or("None".to_string(), |v| format!("Some({})", lit(v)));
                let [value_at, min_at, max_at] = at.clone().map(|a| location_from(&a, file));
                let _ = writeln!(
                    statements,
                    "rt::parameters::check_bounds({:?}, p.{}, ({}, {}), [{value_at}, {min_at}, {max_at}])?;",
                    p.name,
                    p.name,
                    opt(p.min),
                    opt(p.max)
                );
            }
            RuntimeCheck::Finite(field, at) => {
                need(*field);
                let _ = writeln!(
                    statements,
                    "rt::parameters::located({}, rt::parameters::checks::finite({}))?;",
                    location_from(at, file),
                    value_of(*field)
                );
            }
            RuntimeCheck::Positive(field, what, at)
            | RuntimeCheck::NonNegative(field, what, at) => {
                need(*field);
                let function = if matches!(check, RuntimeCheck::Positive(..)) {
                    "positive"
                } else {
                    "non_negative"
                };
                let _ = writeln!(
                    statements,
                    "rt::parameters::located({}, rt::parameters::checks::{function}({what:?}, {}))?;",
                    location_from(at, file),
                    value_of(*field)
                );
            }
            RuntimeCheck::Followable(k, at) => {
                let contact = &model.contacts[*k];
                let radius = match contact.follower.radius() {
                    Some(_) => {
                        need(Field::Radius(*k));
                        value_of(Field::Radius(*k))
                    }
                    None => "0.0".to_string(),
                };
                let (a, b) = contact.range.unwrap_or((0.0, std::f64::consts::TAU));
                let places: Vec<String> = at.iter().map(|a| location_from(a, file)).collect();
                if let crate::model::Profile::Barrel { length, .. } = &contact.profile {
                    // A barrel's groove developed at its pitch radius, on its cylinder.
                    let length = match length {
                        Some(l) => format!("Some(({}, {}))", lit(*l), places[1]),
                        None => "None".to_string(),
                    };
                    let _ = writeln!(
                        statements,
                        "rt::contact::developed_groove_fits_located([{}], {:?}, ({:?}, {radius} + {}), {length}, |s| {}(p, s))?;",
                        places.join(", "),
                        contact.name,
                        contact.groove_label(),
                        lit(0.5 * contact.backlash),
                        followable_name(model, *k)
                    );
                    continue;
                }
                if matches!(contact.profile, crate::model::Profile::Face { .. }) {
                    // A face cam's groove: its flanks lie the roller's radius and half the
                    // backlash from the centre line.
                    let label = contact.groove_label();
                    let _ = writeln!(
                        statements,
                        "rt::contact::groove_fits_located([{}], {:?}, ({label:?}, {radius} + {}), ({}, {}), |s| {}(p, s))?;",
                        places.join(", "),
                        contact.name,
                        lit(0.5 * contact.backlash),
                        lit(a),
                        lit(b),
                        followable_name(model, *k)
                    );
                    continue;
                }
                let shape = format!(
                    "rt::contact::Shape {{ kind: rt::FollowerKind::{}, radius: {radius} }}",
                    contact.follower.kind().keyword()
                );
                let _ = writeln!(
                    statements,
                    "rt::contact::followable_located([{}], {:?}, {:?}, {shape}, ({}, {}), |s| {}(p, s))?;",
                    places.join(", "),
                    contact.name,
                    contact.profile.variable(),
                    lit(a),
                    lit(b),
                    followable_name(model, *k)
                );
            }
            RuntimeCheck::Inertia(body, at) => {
                let rows: Vec<String> = (0..3)
                    .map(|r| {
                        let cells: Vec<String> = (0..3)
                            .map(|c| {
                                need(Field::Inertia(*body, r, c));
                                value_of(Field::Inertia(*body, r, c))
                            })
                            .collect();
                        format!("[{}]", cells.join(", "))
                    })
                    .collect();
                let _ = writeln!(
                    statements,
                    "rt::parameters::located({}, rt::parameters::checks::inertia(&[{}]))?;",
                    location_from(at, file),
                    rows.join(", ")
                );
            }
        }
    }
    let spec = FunctionSpec {
        doc: "The build's checks of every value that depends on the run-time parameters, \
              with its messages and locations in the model file."
            .into(),
        name: "check".into(),
        params: vec![Param {
            name: "p",
            ty: "&Parameters",
            always_used: true,
        }],
        ret: Some("Result<(), rt::ParameterError>"),
        outputs: needed
            .iter()
            .map(|(name, id)| (format!("let {name}"), *id))
            .collect(),
        tail: format!("{statements}Ok(())"),
    };
    let (text, _) = emit_function_given(d, &spec, "", false, &[]);
    let mut out = format!("{ALLOW_LITERALS}\n{text}");
    for check in &d.profile_checks {
        out.push_str(&followable_function(model, d, check));
    }
    out
}

/// The name of contact `k`'s profile sampler for its run-time check.
fn followable_name(model: &Model, k: usize) -> String {
    format!("{}_profile_check", value_name(&model.contacts[k].name))
}

/// `<contact>_profile_check(p, s)`: the polar radius (NaN for other forms) and the curvature
/// of a contact's profile at s for the parameters `p`.
fn followable_function(
    model: &Model,
    d: &Derivation,
    check: &crate::derive::ProfileCheck,
) -> String {
    let mut outputs = vec![("let curvature".to_string(), check.curvature)];
    let radius = match check.radius {
        Some(r) => {
            outputs.push(("let radius".to_string(), r));
            "radius"
        }
        None => "f64::NAN",
    };
    let spec = FunctionSpec {
        doc: format!(
            "The polar radius and the curvature of contact `{}`'s profile at s, for `check`.",
            model.contacts[check.contact].name
        ),
        name: followable_name(model, check.contact),
        params: vec![
            Param {
                name: "p",
                ty: "&Parameters",
                always_used: false,
            },
            Param {
                name: "s",
                ty: "f64",
                always_used: false,
            },
        ],
        ret: Some("[f64; 2]"),
        outputs,
        tail: format!("[{radius}, curvature]"),
    };
    let (text, _) = emit_function_given(d, &spec, "", false, &[(check.at, "s".to_string())]);
    format!("{ALLOW_LITERALS}\n{text}")
}

/// The value of a constant field of the model (one a check needs beside run-time ones).
fn constant_value(model: &Model, field: Field) -> f64 {
    match field {
        Field::Gravity(k) => model.gravity[k],
        Field::Mass(b) => model.bodies[b].mass,
        Field::Com(b, k) => model.bodies[b].com[k],
        Field::Inertia(b, r, c) => model.bodies[b].inertia[r][c],
        Field::Anchor(b, k) => model.bodies[b].joint.anchor[k],
        Field::Stiffness(b) => model.bodies[b].joint.spring.map_or(0.0, |s| s.stiffness),
        Field::Damping(b) => model.bodies[b].joint.spring.map_or(0.0, |s| s.damping),
        Field::Rest(b) => model.bodies[b].joint.spring.map_or(0.0, |s| s.rest),
        Field::Marker(m, k) => model.markers[m].position[k],
        Field::Origin(c, k) => model.contacts[c].origin[k],
        Field::LoopPoint(l, side, k) => model.loops[l].sides[side].point[k],
        Field::InitialQ(i) => model.initial.q[i],
        Field::InitialQd(i) => model.initial.qd[i],
        Field::Radius(c) => model.contacts[c]
            .follower
            .radius()
            .copied()
            .unwrap_or(f64::NAN),
        Field::Drive(_) | Field::Profile(_) | Field::ProfileY(_) | Field::Load(_) => f64::NAN,
    }
}

/// `initial_guess`: the initial q and q̇ for a parameter set (those the file gives as
/// expressions of run-time parameters; the others are the file's numbers).
fn initial_function(model: &Model, d: &Derivation) -> String {
    let mut outputs = Vec::new();
    for i in 0..model.n() {
        if let Some(&id) = d.fields.get(&Field::InitialQ(i)) {
            outputs.push((format!("q[{i}]"), id));
        }
        if let Some(&id) = d.fields.get(&Field::InitialQd(i)) {
            outputs.push((format!("qd[{i}]"), id));
        }
    }
    let spec = FunctionSpec {
        doc: "Writes the initial guesses that depend on the run-time parameters.".into(),
        name: "initial_guess".into(),
        params: vec![
            Param {
                name: "p",
                ty: "&Parameters",
                always_used: false,
            },
            Param {
                name: "q",
                ty: "&mut [f64]",
                always_used: false,
            },
            Param {
                name: "qd",
                ty: "&mut [f64]",
                always_used: false,
            },
        ],
        ret: None,
        outputs,
        tail: String::new(),
    };
    let (text, _) = emit_function_given(d, &spec, "", false, &[]);
    format!("{ALLOW_LITERALS}\n{text}")
}
