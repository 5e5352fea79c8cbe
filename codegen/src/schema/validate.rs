//! From the file's [`raw`] values to the validated [`Model`]: physical checks, name
//! resolution, parents-first ordering. Every error names the dotted field path in the file's
//! own order (before sorting), which [`Locator`] turns into a line and column.

use super::Locator;
use super::raw;
use crate::error::ModelError;
use crate::model::{
    Body, Field, FieldLocation, Follower, Initial, Joint, JointKind, JointLoad, Marker, Model,
    Parameter, ParameterMode, Prescribed, Profile, RuntimeCheck, Simulation, SpringDamper,
};
use crate::profile::{Scalar, parse_expression_with};
use camchain_runtime::parameters::{Bound, checks};
use std::cell::RefCell;
use std::collections::{BTreeMap, HashMap};

mod contacts;
mod designs;
mod loops;
mod tables;
use contacts::contacts;

/// The reserved parent name of the fixed base.
const GROUND: &str = "ground";

/// Largest |x̂·ŷ| accepted for the cam plane axes after normalisation.
const ORTHOGONALITY_TOLERANCE: f64 = 1e-9;

/// Rust keywords (strict, reserved and edition-specific): not usable as generated names.
const KEYWORDS: [&str; 53] = [
    "as", "break", "const", "continue", "crate", "else", "enum", "extern", "false", "fn", "for",
    "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return",
    "self", "Self", "static", "struct", "super", "trait", "true", "type", "unsafe", "use", "where",
    "while", "async", "await", "dyn", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "typeof", "unsized", "virtual", "yield", "try", "gen", "_",
];

type Checked<T> = Result<T, ModelError>;

/// What a file is validated with besides its text.
#[derive(Debug, Clone, Default)]
pub(super) struct Options<'o> {
    /// Parameters given other values than the file's, by name.
    pub overrides: &'o [(String, f64)],
    /// Which parameters are read at run time.
    pub mode: ParameterMode,
    /// Where the files the model names are read from.
    pub files: super::Files<'o>,
}

/// Validates the whole file; `stem` is the file stem used as the default model name.
pub(super) fn validate(
    file: &raw::Model,
    stem: &str,
    at: &Locator,
    options: &Options,
) -> Checked<Model> {
    let name = model_name(file.name.as_deref(), stem, at)?;
    let parameters = parameters(file, options, at)?;
    let table = Table::new(&parameters, at);
    let read = RefCell::new(Vec::new());
    let cx = Context {
        at,
        table: &table,
        files: options.files,
        read: &read,
    };
    let gravity = cx.vector("gravity", &file.gravity, Some(Field::Gravity))?;
    let tree = BodyTree::new(&file.bodies, at)?;
    let mut bodies = tree.bodies(&file.bodies, &cx)?;
    parameter_names_free(&parameters, &bodies, at)?;
    joint_loads(&file.bodies, &tree, &mut bodies, &cx)?;
    let markers = markers(&file.markers, &tree, &cx)?;
    let contacts = contacts(&file.contacts, &markers, &tree, &bodies, &cx)?;
    let initial = initial(&file.initial, &bodies, &cx)?;
    let simulation = simulation(&file.simulation, at)?;
    if simulation.restitution.is_some() && contacts.len() != 1 {
        return Err(at.error(
            "simulation.restitution",
            format!(
                "one-sided contact (`restitution`) needs exactly one contact; this model has {}",
                contacts.len()
            ),
        ));
    }
    if simulation.restitution.is_some() && !file.loops.is_empty() {
        return Err(at.error(
            "simulation.restitution",
            "one-sided contact (`restitution`) is not available in a model with loops yet: \
             remove `restitution` to hold the follower on its cam",
        ));
    }
    let mut model = Model {
        name,
        description: file.description.clone(),
        parameters,
        symbolic: BTreeMap::new(),
        runtime_checks: Vec::new(),
        parameters_at: location(at, "parameters"),
        gravity,
        bodies,
        markers,
        contacts,
        loops: Vec::new(),
        initial,
        simulation,
        files: Vec::new(),
    };
    model.symbolic = table.symbolic.borrow().clone();
    model.loops = loops::loops(&file.loops, &tree, &model, &cx)?;
    model.symbolic = table.symbolic.into_inner();
    model.runtime_checks = table.checks.into_inner();
    model.files = read.into_inner();
    Ok(model)
}

/// Where `field` is written.
fn location(at: &Locator, field: &str) -> FieldLocation {
    let e = at.error(field, "");
    FieldLocation {
        field: field.to_string(),
        line: e.line,
        column: e.column,
    }
}

/// Names that expressions already give a meaning to.
const RESERVED_IN_EXPRESSIONS: [&str; 18] = [
    "x", "t", "theta", "s", "PI", "E", "sin", "cos", "tan", "exp", "ln", "sqrt", "sinh", "cosh",
    "tanh", "atan", "powi", "powf",
];

/// The parameters with their effective values (the file's, or an override) and whether the
/// generated code folds them (`constant`, after the mode is applied).
fn parameters(file: &raw::Model, options: &Options, at: &Locator) -> Checked<Vec<Parameter>> {
    let list = &file.parameters;
    let index = unique_names(
        at,
        list.iter()
            .enumerate()
            .map(|(i, p)| (format!("parameters[{i}].name"), p.name.as_str())),
        "parameter name",
    )?;
    let mut out = Vec::with_capacity(list.len());
    for (i, p) in list.iter().enumerate() {
        let path = format!("parameters[{i}]");
        if RESERVED_IN_EXPRESSIONS.contains(&p.name.as_str()) || p.name.starts_with("__") {
            return Err(at.error(
                &format!("{path}.name"),
                format!(
                    "`{}` already means something in expressions (the variables x, theta, s \
                     and t, the constants PI and E, the math functions; names starting with \
                     `__` are reserved): choose another parameter name",
                    p.name
                ),
            ));
        }
        let value = finite(at, &format!("{path}.value"), p.value)?;
        let min = p
            .min
            .map(|m| finite(at, &format!("{path}.min"), m))
            .transpose()?;
        let max = p
            .max
            .map(|m| finite(at, &format!("{path}.max"), m))
            .transpose()?;
        if let (Some(low), Some(high)) = (min, max) {
            if low > high {
                return Err(at.error(
                    &format!("{path}.max"),
                    format!("the maximum {high} is below the minimum {low}"),
                ));
            }
        }
        let parameter = Parameter {
            name: p.name.clone(),
            value,
            default: value,
            unit: p.unit.clone(),
            min,
            max,
            constant: p.constant,
            description: p.description.clone(),
            constant_at: location(at, &format!("{path}.constant")),
        };
        within_bounds(at, &path, &parameter, "its value")?;
        out.push(parameter);
    }
    match options.mode {
        ParameterMode::AsDeclared => {}
        ParameterMode::FoldAll => out.iter_mut().for_each(|p| p.constant = true),
        ParameterMode::AllAtRunTime => {
            let structural = structural_parameters(file, &out);
            for (i, p) in out.iter_mut().enumerate() {
                p.constant = structural.contains(&i);
            }
        }
    }
    for (name, value) in options.overrides {
        let Some(&i) = index.get(name.as_str()) else {
            let known: Vec<&str> = list.iter().map(|p| p.name.as_str()).collect();
            return Err(at.error("parameters", checks::unknown_parameter(name, &known)));
        };
        let path = format!("parameters[{i}]");
        if out[i].constant {
            return Err(at.error(
                &format!("{path}.constant"),
                checks::constant_parameter(name),
            ));
        }
        out[i].value = *value;
        within_bounds(at, &path, &out[i], &format!("{name} = {value}"))?;
    }
    Ok(out)
}

/// The parameters used by fields that must be constant (joint axes, cam plane axes, a motion
/// law's segments): they stay folded in [`ParameterMode::AllAtRunTime`].
fn structural_parameters(file: &raw::Model, parameters: &[Parameter]) -> Vec<usize> {
    let names: Vec<&str> = parameters.iter().map(|p| p.name.as_str()).collect();
    let axes =
        file.bodies
            .iter()
            .flat_map(|b| b.joint.axis.iter())
            .chain(file.contacts.iter().flat_map(|c| {
                let face: &[raw::Number] = c.follower.normal().map_or(&[], |n| n);
                c.frame
                    .x_axis
                    .iter()
                    .chain(c.frame.y_axis.iter())
                    .chain(face)
            }));
    // A motion law's segments are data of the generated code (angles and lifts).
    let segments = file
        .contacts
        .iter()
        .filter_map(|c| c.law.as_ref())
        .flat_map(|law| law.segments.iter())
        .flat_map(|segment| match segment {
            raw::LawSegment::Dwell { degrees } => vec![degrees],
            raw::LawSegment::Rise { lift, degrees, .. }
            | raw::LawSegment::Return { lift, degrees, .. } => vec![lift, degrees],
        });
    let mut used: Vec<usize> = axes
        .chain(segments)
        .filter_map(|n| match n {
            raw::Number::Expr(source) => parse_expression_with(source, None, &names).ok(),
            raw::Number::Value(_) => None,
        })
        .flat_map(|e| e.parameters())
        .collect();
    used.sort_unstable();
    used.dedup();
    used
}

/// The parameter's value against its declared bounds; `what` names the value in messages.
/// The file's own value is reported where it is written (`.value`); a value given from
/// outside at the bound it breaks (`.min`, `.max`), as the generated code reports it.
fn within_bounds(at: &Locator, path: &str, p: &Parameter, what: &str) -> Checked<()> {
    let own = what == "its value";
    checks::within_bounds(&p.name, p.value, (p.min, p.max), what)
        .map(|_| ())
        .map_err(|(side, message)| {
            let side = if own { Bound::Value } else { side };
            at.error(&format!("{path}.{}", bound_field(side)), message)
        })
}

/// The field of `parameters[i]` a bound failure is reported at.
fn bound_field(side: Bound) -> &'static str {
    match side {
        Bound::Min => "min",
        Bound::Max => "max",
        Bound::Value => "value",
    }
}

/// Parameter names must differ from the coordinates' names and their velocities'
/// (`q1`, `q1_dot`): the generated code names its inputs so.
fn parameter_names_free(parameters: &[Parameter], bodies: &[Body], at: &Locator) -> Checked<()> {
    for (i, p) in parameters.iter().enumerate() {
        let clash = bodies
            .iter()
            .map(|b| &b.joint.coordinate)
            .find(|c| p.name == **c || p.name.strip_suffix("_dot") == Some(c.as_str()));
        if let Some(coordinate) = clash {
            return Err(at.error(
                &format!("parameters[{i}].name"),
                format!(
                    "`{}` is taken by coordinate `{coordinate}` (or its velocity): choose \
                     another parameter name",
                    p.name
                ),
            ));
        }
    }
    Ok(())
}

/// The parameters as expressions see them, the run-time-dependent fields found so far and
/// the checks the generated code must repeat on them.
struct Table<'a> {
    names: Vec<String>,
    values: Vec<f64>,
    constant: Vec<bool>,
    symbolic: RefCell<BTreeMap<Field, Scalar>>,
    checks: RefCell<Vec<RuntimeCheck>>,
    at: &'a Locator<'a>,
}

impl<'a> Table<'a> {
    fn new(parameters: &[Parameter], at: &'a Locator<'a>) -> Self {
        let checks = parameters
            .iter()
            .enumerate()
            .filter(|(_, p)| !p.constant)
            .map(|(i, _)| RuntimeCheck::Bounds {
                parameter: i,
                at: ["value", "min", "max"].map(|f| location(at, &format!("parameters[{i}].{f}"))),
            })
            .collect();
        Table {
            names: parameters.iter().map(|p| p.name.clone()).collect(),
            values: parameters.iter().map(|p| p.value).collect(),
            constant: parameters.iter().map(|p| p.constant).collect(),
            symbolic: RefCell::new(BTreeMap::new()),
            checks: RefCell::new(checks),
            at,
        }
    }

    /// Parses `source` (with `variable`, if any) and folds the constant parameters in:
    /// (the expression with only run-time parameters left, the fully resolved one).
    fn expression(
        &self,
        field: &str,
        source: &str,
        variable: Option<&str>,
    ) -> Checked<(Scalar, Scalar)> {
        let names: Vec<&str> = self.names.iter().map(String::as_str).collect();
        let parsed = parse_expression_with(source, variable, &names)
            .map_err(|e| self.at.error_in_string(field, e.offset, e.message))?;
        let folded = parsed.resolve(&self.values, &|i| self.constant[i]);
        let resolved = parsed.resolve_all(&self.values);
        Ok((folded, resolved))
    }

    /// An expression of the parameters as written, none folded (`Scalar::Param` `i` is
    /// parameter i).
    fn parsed(&self, field: &str, source: &str) -> Checked<Scalar> {
        let names: Vec<&str> = self.names.iter().map(String::as_str).collect();
        parse_expression_with(source, None, &names)
            .map_err(|e| self.at.error_in_string(field, e.offset, e.message))
    }

    /// An applied joint load: an expression of `t`, the parameters, the coordinates (named
    /// `coordinates`) and their rates (`<name>_dot`), as [`JointLoad::expr`] describes it;
    /// recorded under `key` when it uses run-time parameters.
    fn load_expression(
        &self,
        field: &str,
        source: &str,
        coordinates: &[String],
        key: Field,
    ) -> Checked<Scalar> {
        let np = self.names.len();
        let rates: Vec<String> = coordinates.iter().map(|c| format!("{c}_dot")).collect();
        let names: Vec<&str> = self
            .names
            .iter()
            .chain(coordinates)
            .chain(&rates)
            .map(String::as_str)
            .collect();
        let parsed = parse_expression_with(source, Some("t"), &names).map_err(|e| {
            let message = match e.message.strip_prefix("unknown name `") {
                // The parser calls every name it was given a parameter.
                Some(rest) if e.message.contains("the only variable allowed here is `t`") => {
                    let written = rest.split('`').next().unwrap_or_default();
                    let parameters = if self.names.is_empty() {
                        "the model declares no parameters".to_string()
                    } else {
                        format!("the parameters are {}", self.names.join(", "))
                    };
                    format!(
                        "unknown name `{written}`: a load is an expression of the time `t`, the \
                         coordinates ({}) and their velocities ({}); the constants are PI and \
                         E; {parameters}",
                        coordinates.join(", "),
                        rates.join(", ")
                    )
                }
                _ => e.message,
            };
            self.at.error_in_string(field, e.offset, message)
        })?;
        let folded = parsed.resolve(&self.values, &|i| i < np && self.constant[i]);
        if folded.parameters().iter().any(|&i| i < np) {
            self.symbolic.borrow_mut().insert(key, folded);
        }
        Ok(parsed.resolve(&self.values, &|i| i < np))
    }

    /// Multiplies the recorded expression of `field`, if any, by `factor`.
    fn scale(&self, field: Field, factor: f64) {
        if factor != 1.0 {
            if let Some(expr) = self.symbolic.borrow_mut().get_mut(&field) {
                let inner = std::mem::replace(expr, Scalar::Const(0.0));
                *expr = Scalar::Mul(Box::new(Scalar::Const(factor)), Box::new(inner));
            }
        }
    }

    /// Records that `field` depends on run-time parameters through `expr`; true if it does.
    fn record(&self, field: Field, expr: Scalar) -> bool {
        let runtime = !expr.parameters().is_empty();
        if runtime {
            self.symbolic.borrow_mut().insert(field, expr);
        }
        runtime
    }

    /// True when `field` depends on run-time parameters.
    fn is_runtime(&self, field: Field) -> bool {
        self.symbolic.borrow().contains_key(&field)
    }

    /// Adds a check for the generated code.
    fn check(&self, check: RuntimeCheck) {
        self.checks.borrow_mut().push(check);
    }
}

/// What field validation needs: the locator, the parameters, and where the files the model
/// names are found (with those read so far).
struct Context<'a> {
    at: &'a Locator<'a>,
    table: &'a Table<'a>,
    files: super::Files<'a>,
    read: &'a RefCell<Vec<crate::model::ModelFile>>,
}

impl Context<'_> {
    /// The value of a numeric field; `key` records it when it depends on run-time
    /// parameters, and `None` refuses such a dependence (a field that must be constant).
    fn number(&self, field: &str, n: &raw::Number, key: Option<Field>) -> Checked<f64> {
        let value = self.raw_number(field, n, key, true)?;
        finite(self.at, field, value)
    }

    /// The value of a numeric field, not yet checked to be finite (the caller checks what
    /// the field needs); with `finite_at_run_time`, a field that depends on run-time
    /// parameters gets a finiteness check in the generated code.
    fn raw_number(
        &self,
        field: &str,
        n: &raw::Number,
        key: Option<Field>,
        finite_at_run_time: bool,
    ) -> Checked<f64> {
        let source = match n {
            raw::Number::Value(v) => return Ok(*v),
            raw::Number::Expr(source) => source,
        };
        let (folded, resolved) = self.table.expression(field, source, None)?;
        let runtime = folded.parameters();
        match key {
            Some(key) => {
                let recorded = self.table.record(key, folded);
                if recorded && finite_at_run_time {
                    self.table
                        .check(RuntimeCheck::Finite(key, location(self.at, field)));
                }
            }
            None if !runtime.is_empty() => {
                let names: Vec<&str> = runtime
                    .iter()
                    .map(|&i| self.table.names[i].as_str())
                    .collect();
                return Err(self.at.error(
                    field,
                    format!(
                        "this field must be constant, but {} {} read at run time: mark {} \
                         `constant: true`",
                        names.join(", "),
                        if names.len() == 1 { "is" } else { "are" },
                        if names.len() == 1 { "it" } else { "them" }
                    ),
                ));
            }
            None => {}
        }
        Ok(resolved.eval(0.0))
    }

    /// A numeric field that must be positive (a mass): checked now, and at run time when it
    /// depends on run-time parameters.
    fn positive(
        &self,
        field: &str,
        n: &raw::Number,
        key: Field,
        what: &'static str,
    ) -> Checked<f64> {
        self.signed(field, n, key, what, true)
    }

    /// A numeric field that must be non-negative (a stiffness, a damping).
    fn non_negative(
        &self,
        field: &str,
        n: &raw::Number,
        key: Field,
        what: &'static str,
    ) -> Checked<f64> {
        self.signed(field, n, key, what, false)
    }

    /// [`Context::positive`] (`strict`) or [`Context::non_negative`].
    fn signed(
        &self,
        field: &str,
        n: &raw::Number,
        key: Field,
        what: &'static str,
        strict: bool,
    ) -> Checked<f64> {
        let value = self.raw_number(field, n, Some(key), false)?;
        if self.table.is_runtime(key) {
            let at = location(self.at, field);
            self.table.check(if strict {
                RuntimeCheck::Positive(key, what, at)
            } else {
                RuntimeCheck::NonNegative(key, what, at)
            });
        }
        if strict {
            positive(self.at, field, what, value)
        } else {
            non_negative(self.at, field, what, value)
        }
    }

    /// Three numeric fields `field[0..3]`, keyed by component.
    fn vector(
        &self,
        field: &str,
        v: &[raw::Number; 3],
        key: Option<fn(usize) -> Field>,
    ) -> Checked<[f64; 3]> {
        let mut out = [0.0; 3];
        for (k, n) in v.iter().enumerate() {
            out[k] = self.number(&format!("{field}[{k}]"), n, key.map(|f| f(k)))?;
        }
        Ok(out)
    }

    /// [`Context::vector`] with a key that needs an index (`Com(body, k)`).
    fn vector_of(
        &self,
        field: &str,
        v: &[raw::Number; 3],
        key: impl Fn(usize) -> Field,
    ) -> Checked<[f64; 3]> {
        let mut out = [0.0; 3];
        for (k, n) in v.iter().enumerate() {
            out[k] = self.number(&format!("{field}[{k}]"), n, Some(key(k)))?;
        }
        Ok(out)
    }
}

/// The model's name: `name:`, or the file stem. Any non-empty text: only the build needs a
/// Rust identifier (it names the generated module) and checks that itself.
fn model_name(name: Option<&str>, stem: &str, at: &Locator) -> Checked<String> {
    let name = name.unwrap_or(stem);
    if name.trim().is_empty() || name.chars().any(char::is_control) {
        return Err(at.error(
            "name",
            format!("the model name {name:?} is empty or has control characters"),
        ));
    }
    Ok(name.to_string())
}

/// True for an ASCII Rust identifier that is not a keyword.
pub(crate) fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    let starts_well = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    starts_well && chars.all(|c| c.is_ascii_alphanumeric() || c == '_') && !KEYWORDS.contains(&name)
}

/// Names end up as Rust identifiers in the generated code.
fn identifier(at: &Locator, field: &str, name: &str, what: &str) -> Checked<()> {
    if is_identifier(name) {
        Ok(())
    } else {
        Err(at.error(
            field,
            format!(
                "{what} `{name}` is not a valid Rust identifier (ASCII letters, digits and `_`, \
                 not starting with a digit, not a keyword)"
            ),
        ))
    }
}

fn finite(at: &Locator, field: &str, value: f64) -> Checked<f64> {
    checks::finite(value).map_err(|m| at.error(field, m))
}

fn finite3(at: &Locator, field: &str, v: [f64; 3]) -> Checked<[f64; 3]> {
    for (k, &c) in v.iter().enumerate() {
        finite(at, &format!("{field}[{k}]"), c)?;
    }
    Ok(v)
}

fn positive(at: &Locator, field: &str, what: &str, value: f64) -> Checked<f64> {
    checks::positive(what, value).map_err(|m| at.error(field, m))
}

fn non_negative(at: &Locator, field: &str, what: &str, value: f64) -> Checked<f64> {
    checks::non_negative(what, value).map_err(|m| at.error(field, m))
}

/// `v / |v|`, or `None` for a zero or non-finite vector.
fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let norm = v.iter().map(|c| c * c).sum::<f64>().sqrt();
    (norm.is_finite() && norm > 0.0).then(|| v.map(|c| c / norm))
}

fn unit_vector(at: &Locator, field: &str, what: &str, v: [f64; 3]) -> Checked<[f64; 3]> {
    finite3(at, field, v)?;
    unit(v).ok_or_else(|| {
        at.error(
            field,
            format!(
                "{what} must be a non-zero vector, got ({}, {}, {})",
                v[0], v[1], v[2]
            ),
        )
    })
}

/// Finds `name` in `names` (a name → index map) or explains what was expected.
fn lookup(
    at: &Locator,
    field: &str,
    index: &HashMap<&str, usize>,
    name: &str,
    what: &str,
) -> Checked<usize> {
    index
        .get(name)
        .copied()
        .ok_or_else(|| at.error(field, unknown(index, name, what)))
}

/// "unknown {what} `{name}`; known: …" with the known names sorted.
fn unknown(index: &HashMap<&str, usize>, name: &str, what: &str) -> String {
    let mut known: Vec<&str> = index.keys().copied().collect();
    known.sort_unstable();
    format!("unknown {what} `{name}`; known: {}", known.join(", "))
}

/// Indexes `names`, reporting the second occurrence of a repeated name.
fn unique_names<'n>(
    at: &Locator,
    names: impl Iterator<Item = (String, &'n str)>,
    what: &str,
) -> Checked<HashMap<&'n str, usize>> {
    let mut index = HashMap::new();
    for (i, (field, name)) in names.enumerate() {
        identifier(at, &field, name, what)?;
        if index.insert(name, i).is_some() {
            return Err(at.error(&field, format!("duplicate {what} `{name}`")));
        }
    }
    Ok(index)
}

/// The bodies' names, parents and their parents-first order.
struct BodyTree<'f> {
    /// Body name → index in the file.
    by_name: HashMap<&'f str, usize>,
    /// File indices in parents-first order.
    order: Vec<usize>,
    /// File index → position in `order`.
    sorted_index: Vec<usize>,
    /// File index → file index of the parent (`None` = ground).
    parents: Vec<Option<usize>>,
}

impl<'f> BodyTree<'f> {
    fn new(bodies: &'f [raw::Body], at: &Locator) -> Checked<Self> {
        if bodies.is_empty() {
            return Err(at.error("bodies", "the model needs at least one body"));
        }
        let by_name = body_names(bodies, at)?;
        unique_names(
            at,
            bodies.iter().enumerate().map(|(i, b)| {
                (
                    format!("bodies[{i}].joint.coordinate"),
                    b.joint.coordinate.as_str(),
                )
            }),
            "coordinate",
        )?;
        coordinate_names_free(bodies, at)?;
        let parents = bodies
            .iter()
            .enumerate()
            .map(|(i, b)| parent_of(at, i, b, &by_name))
            .collect::<Checked<Vec<_>>>()?;
        let order = parents_first(&parents).map_err(|cycle| cycle_error(at, bodies, &cycle))?;
        let mut sorted_index = vec![0; bodies.len()];
        for (position, &i) in order.iter().enumerate() {
            sorted_index[i] = position;
        }
        Ok(BodyTree {
            by_name,
            order,
            sorted_index,
            parents,
        })
    }

    /// The validated bodies, parents first.
    fn bodies(&self, bodies: &[raw::Body], cx: &Context) -> Checked<Vec<Body>> {
        self.order
            .iter()
            .enumerate()
            .map(|(sorted, &i)| {
                let parent = self.parents[i].map(|p| self.sorted_index[p]);
                body(cx, i, sorted, &bodies[i], parent)
            })
            .collect()
    }

    /// Sorted index of the body called `name`.
    fn sorted_body(&self, at: &Locator, field: &str, name: &str) -> Checked<usize> {
        let i = lookup(at, field, &self.by_name, name, "body")?;
        Ok(self.sorted_index[i])
    }
}

/// Coordinates are variables of the generated code and of joint loads beside the time `t`,
/// the velocities `<coordinate>_dot` and the build's own `__` names: none may be called so.
fn coordinate_names_free(bodies: &[raw::Body], at: &Locator) -> Checked<()> {
    let names: Vec<&str> = bodies.iter().map(|b| b.joint.coordinate.as_str()).collect();
    for (i, &name) in names.iter().enumerate() {
        let field = format!("bodies[{i}].joint.coordinate");
        if ["t", "PI", "E"].contains(&name) || name.starts_with("__") {
            return Err(at.error(
                &field,
                format!(
                    "`{name}` already means something in expressions (the time t and the \
                     constants PI and E in a joint's load; names starting with `__` are \
                     reserved): choose another coordinate name"
                ),
            ));
        }
        if let Some(base) = name.strip_suffix("_dot").filter(|b| names.contains(b)) {
            return Err(at.error(
                &field,
                format!(
                    "`{name}` is taken by the velocity of coordinate `{base}` (`{base}_dot` in a \
                     joint's load and in the generated code): choose another coordinate name"
                ),
            ));
        }
    }
    Ok(())
}

fn body_names<'f>(bodies: &'f [raw::Body], at: &Locator) -> Checked<HashMap<&'f str, usize>> {
    if let Some(i) = bodies.iter().position(|b| b.name == GROUND) {
        return Err(at.error(
            &format!("bodies[{i}].name"),
            "`ground` is reserved for the fixed base; choose another body name",
        ));
    }
    unique_names(
        at,
        bodies
            .iter()
            .enumerate()
            .map(|(i, b)| (format!("bodies[{i}].name"), b.name.as_str())),
        "body name",
    )
}

fn parent_of(
    at: &Locator,
    i: usize,
    body: &raw::Body,
    by_name: &HashMap<&str, usize>,
) -> Checked<Option<usize>> {
    if body.parent == GROUND {
        return Ok(None);
    }
    let field = format!("bodies[{i}].parent");
    by_name
        .get(body.parent.as_str())
        .copied()
        .map(Some)
        .ok_or_else(|| {
            at.error(
                &field,
                format!(
                    "unknown parent `{}`; expected `ground` or the name of another body",
                    body.parent
                ),
            )
        })
}

/// File indices ordered so that every parent precedes its children, otherwise keeping the
/// file order; `Err(cycle)` lists the bodies of a parent cycle, child before parent.
fn parents_first(parents: &[Option<usize>]) -> Result<Vec<usize>, Vec<usize>> {
    let mut placed = vec![false; parents.len()];
    let mut order = Vec::with_capacity(parents.len());
    for start in 0..parents.len() {
        let mut chain: Vec<usize> = Vec::new();
        let mut current = Some(start);
        while let Some(j) = current.filter(|&j| !placed[j]) {
            if let Some(k) = chain.iter().position(|&c| c == j) {
                return Err(chain.split_off(k));
            }
            chain.push(j);
            current = parents[j];
        }
        for &j in chain.iter().rev() {
            placed[j] = true;
            order.push(j);
        }
    }
    Ok(order)
}

fn cycle_error(at: &Locator, bodies: &[raw::Body], cycle: &[usize]) -> ModelError {
    let first = cycle.first().copied().unwrap_or(0);
    let names: Vec<&str> = cycle
        .iter()
        .chain(cycle.first())
        .map(|&i| bodies[i].name.as_str())
        .collect();
    at.error(
        &format!("bodies[{first}].parent"),
        format!(
            "the parent links form a cycle: {} (each body's parent follows it)",
            names.join(" -> ")
        ),
    )
}

fn body(
    cx: &Context,
    i: usize,
    sorted: usize,
    b: &raw::Body,
    parent: Option<usize>,
) -> Checked<Body> {
    let path = format!("bodies[{i}]");
    let mass_field = format!("{path}.mass");
    let mass = cx.positive(&mass_field, &b.mass, Field::Mass(sorted), "mass")?;
    Ok(Body {
        name: b.name.clone(),
        parent,
        mass,
        com: cx.vector_of(&format!("{path}.com"), &b.com, |k| Field::Com(sorted, k))?,
        inertia: inertia(cx, &format!("{path}.inertia"), &b.inertia, sorted)?,
        joint: joint(cx, &format!("{path}.joint"), &b.joint, sorted)?,
    })
}

/// Where each tensor entry (r, c) comes from: the written number (by its path suffix) and
/// a factor (Izz(e) gives e/2 on the diagonal's first two entries); `None` for a zero.
type InertiaSource<'r> = [[Option<(&'static str, &'r raw::Number, f64)>; 3]; 3];

/// The written numbers of an inertia form, placed in the tensor.
fn inertia_sources(inertia: &raw::Inertia) -> InertiaSource<'_> {
    let mut s: InertiaSource = Default::default();
    match inertia {
        raw::Inertia::Izz(izz) => {
            s[0][0] = Some(("[0]", izz, 0.5));
            s[1][1] = Some(("[0]", izz, 0.5));
            s[2][2] = Some(("[0]", izz, 1.0));
        }
        raw::Inertia::Diagonal(ixx, iyy, izz) => {
            s[0][0] = Some(("[0]", ixx, 1.0));
            s[1][1] = Some(("[1]", iyy, 1.0));
            s[2][2] = Some(("[2]", izz, 1.0));
        }
        raw::Inertia::Full {
            ixx,
            iyy,
            izz,
            ixy,
            ixz,
            iyz,
        } => {
            s[0][0] = Some((".ixx", ixx, 1.0));
            s[1][1] = Some((".iyy", iyy, 1.0));
            s[2][2] = Some((".izz", izz, 1.0));
            for (r, c, name, n) in [
                (0, 1, ".ixy", ixy),
                (0, 2, ".ixz", ixz),
                (1, 2, ".iyz", iyz),
            ] {
                s[r][c] = Some((name, n, 1.0));
                s[c][r] = Some((name, n, 1.0));
            }
        }
    }
    s
}

/// Finite, positive definite, principal moments obeying the triangle inequality.
fn inertia(cx: &Context, field: &str, raw: &raw::Inertia, body: usize) -> Checked<[[f64; 3]; 3]> {
    let at = cx.at;
    let mut matrix = [[0.0; 3]; 3];
    for (r, row) in inertia_sources(raw).iter().enumerate() {
        for (c, source) in row.iter().enumerate() {
            let Some((suffix, number, factor)) = source else {
                continue;
            };
            let key = Field::Inertia(body, r, c);
            let value = cx.number(&format!("{field}{suffix}"), number, Some(key))?;
            cx.table.scale(key, *factor);
            matrix[r][c] = factor * value;
        }
    }
    let runtime = (0..3).any(|r| (0..3).any(|c| cx.table.is_runtime(Field::Inertia(body, r, c))));
    if runtime {
        cx.table
            .check(RuntimeCheck::Inertia(body, location(at, field)));
    }
    checks::inertia(&matrix).map_err(|m| at.error(field, m))?;
    Ok(matrix)
}

fn joint(cx: &Context, path: &str, j: &raw::Joint, body: usize) -> Checked<Joint> {
    let axis = cx.vector(&format!("{path}.axis"), &j.axis, None)?;
    Ok(Joint {
        kind: match j.kind {
            raw::JointKind::Revolute => JointKind::Revolute,
            raw::JointKind::Prismatic => JointKind::Prismatic,
        },
        axis: unit_vector(cx.at, &format!("{path}.axis"), "the joint axis", axis)?,
        anchor: cx.vector_of(&format!("{path}.anchor"), &j.anchor, |k| {
            Field::Anchor(body, k)
        })?,
        coordinate: j.coordinate.clone(),
        spring: j
            .spring
            .as_ref()
            .map(|s| spring(cx, &format!("{path}.spring"), s, body))
            .transpose()?,
        prescribed: j
            .prescribed
            .as_ref()
            .map(|source| prescribed(cx, &format!("{path}.prescribed"), source, body))
            .transpose()?,
        load: None,
    })
}

/// The applied loads of the joints: expressions of t, the coordinates (`q1`) and their rates
/// (`q1_dot`), parsed once every coordinate's name is known.
fn joint_loads(
    file: &[raw::Body],
    tree: &BodyTree,
    bodies: &mut [Body],
    cx: &Context,
) -> Checked<()> {
    let coordinates: Vec<String> = bodies.iter().map(|b| b.joint.coordinate.clone()).collect();
    for (sorted, &i) in tree.order.iter().enumerate() {
        let Some(source) = &file[i].joint.load else {
            continue;
        };
        let field = format!("bodies[{i}].joint.load");
        if bodies[sorted].joint.prescribed.is_some() {
            return Err(cx.at.error(
                &field,
                "a prescribed joint cannot also have a load: its motion is given and the load \
                 that drives it is computed (reported as its drive load)",
            ));
        }
        let expr = cx
            .table
            .load_expression(&field, source, &coordinates, Field::Load(sorted))?;
        bodies[sorted].joint.load = Some(JointLoad {
            source: source.clone(),
            expr,
        });
    }
    Ok(())
}

fn spring(cx: &Context, path: &str, s: &raw::Spring, body: usize) -> Checked<SpringDamper> {
    let (k, c, rest) = (
        format!("{path}.stiffness"),
        format!("{path}.damping"),
        format!("{path}.rest"),
    );
    let stiffness = cx.non_negative(&k, &s.stiffness, Field::Stiffness(body), "stiffness")?;
    let damping = cx.non_negative(&c, &s.damping, Field::Damping(body), "damping")?;
    Ok(SpringDamper {
        stiffness,
        damping,
        rest: cx.number(&rest, &s.rest, Some(Field::Rest(body)))?,
    })
}

/// Parses an expression of `variable` and the parameters, locating errors inside the
/// string literal; records it under `key` when it uses run-time parameters and returns it
/// with every parameter resolved.
fn expression(
    cx: &Context,
    field: &str,
    source: &str,
    variable: &str,
    key: Field,
) -> Checked<Scalar> {
    let (folded, resolved) = cx.table.expression(field, source, Some(variable))?;
    cx.table.record(key, folded);
    Ok(resolved)
}

fn prescribed(cx: &Context, field: &str, source: &str, body: usize) -> Checked<Prescribed> {
    Ok(Prescribed {
        source: source.to_string(),
        expr: expression(cx, field, source, "t", Field::Drive(body))?,
    })
}

fn markers(list: &[raw::Marker], tree: &BodyTree, cx: &Context) -> Checked<Vec<Marker>> {
    let at = cx.at;
    unique_names(
        at,
        list.iter()
            .enumerate()
            .map(|(i, m)| (format!("markers[{i}].name"), m.name.as_str())),
        "marker name",
    )?;
    list.iter()
        .enumerate()
        .map(|(i, m)| {
            Ok(Marker {
                name: m.name.clone(),
                body: tree.sorted_body(at, &format!("markers[{i}].body"), &m.body)?,
                position: cx.vector_of(&format!("markers[{i}].position"), &m.position, |k| {
                    Field::Marker(i, k)
                })?,
            })
        })
        .collect()
}

/// Unit, orthogonal in-plane axes of the cam frame (constant: they fix the plane's
/// orientation in the generated code).
fn cam_axes(cx: &Context, path: &str, frame: &raw::Frame) -> Checked<([f64; 3], [f64; 3])> {
    let at = cx.at;
    let (x_field, y_field) = (format!("{path}.x_axis"), format!("{path}.y_axis"));
    let x = cx.vector(&x_field, &frame.x_axis, None)?;
    let y = cx.vector(&y_field, &frame.y_axis, None)?;
    let x = unit_vector(at, &x_field, "x_axis", x)?;
    let y = unit_vector(at, &y_field, "y_axis", y)?;
    let dot: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
    if dot.abs() > ORTHOGONALITY_TOLERANCE {
        return Err(at.error(
            &format!("{path}.y_axis"),
            format!(
                "x_axis and y_axis must be orthogonal; their unit vectors have dot product {dot}"
            ),
        ));
    }
    Ok((x, y))
}

fn initial(file: &raw::Initial, bodies: &[Body], cx: &Context) -> Checked<Initial> {
    let at = cx.at;
    let by_name: HashMap<&str, usize> = bodies
        .iter()
        .enumerate()
        .map(|(i, b)| (b.joint.coordinate.as_str(), i))
        .collect();
    let (q, given_q) = coordinate_values(cx, "initial.q", &file.q, &by_name, Field::InitialQ)?;
    let (qd, given_qd) = coordinate_values(cx, "initial.qd", &file.qd, &by_name, Field::InitialQd)?;
    let mut hold: Vec<bool> = bodies
        .iter()
        .map(|b| b.joint.prescribed.is_some())
        .collect();
    let mut listed = vec![false; bodies.len()];
    for (k, name) in file.hold.iter().enumerate() {
        let field = format!("initial.hold[{k}]");
        let i = lookup(at, &field, &by_name, name, "coordinate")?;
        if std::mem::replace(&mut listed[i], true) {
            return Err(at.error(&field, format!("coordinate `{name}` is listed twice")));
        }
        hold[i] = true;
    }
    Ok(Initial {
        q,
        qd,
        hold,
        given_q,
        given_qd,
    })
}

/// `{"name": value}` → a value per coordinate in body order, 0 where absent, and which
/// were given.
fn coordinate_values(
    cx: &Context,
    path: &str,
    values: &raw::NamedValues,
    index: &HashMap<&str, usize>,
    key: fn(usize) -> Field,
) -> Checked<(Vec<f64>, Vec<bool>)> {
    let at = cx.at;
    let mut out = vec![0.0; index.len()];
    let mut given = vec![false; index.len()];
    for (k, (name, value)) in values.0.iter().enumerate() {
        let field = format!("{path}[{name:?}]");
        // Located by position, so a repeated key points at its second occurrence.
        let entry = format!("{path}[{k}]");
        let i = index
            .get(name.as_str())
            .copied()
            .ok_or_else(|| at.error_located(&field, &entry, unknown(index, name, "coordinate")))?;
        if std::mem::replace(&mut given[i], true) {
            let message = format!("coordinate `{name}` is given twice");
            return Err(at.error_located(&field, &entry, message));
        }
        out[i] = match value {
            raw::Number::Value(v) if !v.is_finite() => {
                let message = format!("must be finite, got {v}");
                return Err(at.error_located(&field, &entry, message));
            }
            raw::Number::Value(v) => *v,
            expr => cx.number(&entry, expr, Some(key(i)))?,
        };
    }
    Ok((out, given))
}

/// The ranges of the runtime's settings (`camchain_runtime::settings`; a test in
/// `camchain-reference` checks that both accept and refuse the same values).
pub mod ranges {
    /// Relative tolerances of the adaptive integrators.
    pub const RTOL: (f64, f64) = (1e-14, 0.1);
    /// Absolute tolerances of the adaptive integrators.
    pub const ATOL: (f64, f64) = (1e-18, 1.0);
    /// The most samples of a run, t_end / dt_out.
    pub const MAX_SAMPLES: f64 = 1e6;
    /// The most RK4 steps per output interval, dt_out / dt.
    pub const MAX_RK4_STEPS: f64 = 1e7;
}

fn simulation(s: &raw::Simulation, at: &Locator) -> Checked<Simulation> {
    let field = |name: &str| format!("simulation.{name}");
    let integrator = s.integrator.0;
    let t_end = positive(at, &field("t_end"), "t_end", s.t_end)?;
    let dt_out = positive(at, &field("dt_out"), "dt_out", s.dt_out)?;
    let dt = positive(at, &field("dt"), "dt", s.dt)?;
    let samples = t_end / dt_out;
    if samples > ranges::MAX_SAMPLES {
        return Err(at.error(
            &field("dt_out"),
            format!(
                "t_end = {t_end} s with dt_out = {dt_out} s gives {samples:.3e} samples, more \
                 than the {:e} a run keeps: a larger dt_out or a smaller t_end",
                ranges::MAX_SAMPLES
            ),
        ));
    }
    let adaptive = integrator.is_adaptive();
    if !adaptive && dt_out / dt > ranges::MAX_RK4_STEPS {
        return Err(at.error(
            &field("dt"),
            format!(
                "an rk4 step of {dt:e} s needs {:.1e} steps per output interval (dt_out = \
                 {dt_out:e} s), more than the {:e} allowed",
                dt_out / dt,
                ranges::MAX_RK4_STEPS
            ),
        ));
    }
    // Checked whatever the file's integrator: they are the defaults of any adaptive run.
    let in_range = |name: &str, value: f64, (low, high): (f64, f64)| {
        if value.is_finite() && (low..=high).contains(&value) {
            Ok(value)
        } else {
            Err(at.error(
                &field(name),
                format!("{name} must be in [{low:e}, {high:e}], got {value:e}"),
            ))
        }
    };
    let restitution = match s.restitution {
        Some(e) => Some(in_range("restitution", e, (0.0, 1.0))?),
        None => None,
    };
    if restitution.is_some() && !adaptive {
        return Err(at.error(
            &field("restitution"),
            "one-sided contact (`restitution`) needs an adaptive integrator (dopri5 or \
             dop853), which locates lift-off and impact",
        ));
    }
    Ok(Simulation {
        t_end,
        dt_out,
        integrator,
        dt,
        rtol: in_range("rtol", s.rtol, ranges::RTOL)?,
        atol: in_range("atol", s.atol, ranges::ATOL)?,
        restitution,
    })
}
