//! From the file's [`raw`] values to the validated [`Model`]: physical checks, name
//! resolution, parents-first ordering. Every error names the dotted field path in the file's
//! own order (before sorting), which [`Locator`] turns into a line and column.

use super::Locator;
use super::raw;
use crate::error::ModelError;
use crate::model::{
    Field, FieldLocation, Follower, Marker, Model, ParameterMode, Profile, RuntimeCheck,
};
use std::cell::RefCell;
use std::collections::BTreeMap;

mod barrels;
mod bodies;
mod contacts;
mod designs;
mod faces;
mod fields;
mod grids;
mod initial;
mod loops;
mod markers;
mod parameters;
mod settings;
mod table_files;
mod tables;
pub use settings::ranges;

use bodies::{BodyTree, joint_loads};
use contacts::contacts;
pub(crate) use fields::is_identifier;
use fields::{finite, non_negative, positive};
use initial::initial;
use markers::markers;
use parameters::{Table, parameter_names_free, parameters};
use settings::simulation;

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
    if let Some((i, c)) = contacts.iter().enumerate().find(|(_, c)| c.backlash > 0.0)
        && simulation.restitution.is_none()
    {
        let groove = match c.profile {
            Profile::Face { .. } => "face",
            _ => "barrel",
        };
        return Err(at.error(
            &format!("contacts[{i}].{groove}.backlash"),
            format!(
                "a groove with backlash lets the roller fly between its flanks and land on one or \
                 the other: give the flanks' coefficient of restitution in the model's \
                 `simulation: (restitution: e)` (0 for impacts that do not rebound), or make \
                 the groove closed (backlash 0, the default; {} m given)",
                c.backlash
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
        let (folded, resolved) = self.table.expression(field, source, &[])?;
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
