//! Parameters: names, defaults and bounds; which are read at run time; fields that depend on
//! them parsed as expressions (`Table`), their checks recorded for the generated code.

use super::super::Locator;
use super::fields::{finite, unique_names};
use super::{Checked, Context, Options, location};
use crate::model::{Body, Field, Parameter, ParameterMode, RuntimeCheck};
use crate::profile::{Scalar, parse_expression_in, parse_expression_with};
use crate::schema::raw;
use camchain_runtime::parameters::{Bound, checks};
use std::cell::RefCell;
use std::collections::BTreeMap;

/// Names that expressions already give a meaning to.
pub(super) const RESERVED_IN_EXPRESSIONS: [&str; 18] = [
    "x", "t", "theta", "s", "PI", "E", "sin", "cos", "tan", "exp", "ln", "sqrt", "sinh", "cosh",
    "tanh", "atan", "powi", "powf",
];

/// The parameters with their effective values (the file's, or an override) and whether the
/// generated code folds them (`constant`, after the mode is applied).
pub(super) fn parameters(
    file: &raw::Model,
    options: &Options,
    at: &Locator,
) -> Checked<Vec<Parameter>> {
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
            let names = |constant: bool| -> Vec<&str> {
                out.iter()
                    .filter(|p| p.constant == constant)
                    .map(|p| p.name.as_str())
                    .collect()
            };
            let message = checks::unknown_parameter_among(name, &names(false), &names(true));
            return Err(at.error("parameters", message));
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
/// law's segments, a disc cam's, a face cam's or a barrel's): they stay folded in
/// [`ParameterMode::AllAtRunTime`].
pub(super) fn structural_parameters(file: &raw::Model, parameters: &[Parameter]) -> Vec<usize> {
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
        .flat_map(|c| {
            let barrel = c.barrel.as_ref().and_then(|b| b.law.as_ref());
            let face = c.face.as_ref().and_then(|f| f.law.as_ref());
            c.law
                .iter()
                .chain(face)
                .flat_map(|law| law.segments.iter())
                .chain(barrel.into_iter().flat_map(|law| law.segments.iter()))
        })
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
pub(super) fn within_bounds(at: &Locator, path: &str, p: &Parameter, what: &str) -> Checked<()> {
    let own = what == "its value";
    checks::within_bounds(&p.name, p.value, (p.min, p.max), what)
        .map(|_| ())
        .map_err(|(side, message)| {
            let side = if own { Bound::Value } else { side };
            at.error(&format!("{path}.{}", bound_field(side)), message)
        })
}

/// The field of `parameters[i]` a bound failure is reported at.
pub(super) fn bound_field(side: Bound) -> &'static str {
    match side {
        Bound::Min => "min",
        Bound::Max => "max",
        Bound::Value => "value",
    }
}

/// Parameter names must differ from the coordinates' names and their velocities'
/// (`q1`, `q1_dot`): the generated code names its inputs so.
pub(super) fn parameter_names_free(
    parameters: &[Parameter],
    bodies: &[Body],
    at: &Locator,
) -> Checked<()> {
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
pub(super) struct Table<'a> {
    pub(super) names: Vec<String>,
    pub(super) values: Vec<f64>,
    pub(super) constant: Vec<bool>,
    pub(super) symbolic: RefCell<BTreeMap<Field, Scalar>>,
    pub(super) checks: RefCell<Vec<RuntimeCheck>>,
    pub(super) at: &'a Locator<'a>,
}

impl<'a> Table<'a> {
    pub(super) fn new(parameters: &[Parameter], at: &'a Locator<'a>) -> Self {
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

    /// Parses `source` (of `variables`, none for a value of the parameters alone) and folds
    /// the constant parameters in: (the expression with only run-time parameters left, the
    /// fully resolved one).
    pub(super) fn expression(
        &self,
        field: &str,
        source: &str,
        variables: &[&str],
    ) -> Checked<(Scalar, Scalar)> {
        let names: Vec<&str> = self.names.iter().map(String::as_str).collect();
        let parsed = parse_expression_in(source, variables, &names)
            .map_err(|e| self.at.error_in_string(field, e.offset, e.message))?;
        let folded = parsed.resolve(&self.values, &|i| self.constant[i]);
        let resolved = parsed.resolve_all(&self.values);
        Ok((folded, resolved))
    }

    /// An expression of the parameters as written, none folded (`Scalar::Param` `i` is
    /// parameter i).
    pub(super) fn parsed(&self, field: &str, source: &str) -> Checked<Scalar> {
        let names: Vec<&str> = self.names.iter().map(String::as_str).collect();
        parse_expression_with(source, None, &names)
            .map_err(|e| self.at.error_in_string(field, e.offset, e.message))
    }

    /// An applied joint load: an expression of `t`, the parameters, the coordinates (named
    /// `coordinates`) and their rates (`<name>_dot`), as [`JointLoad::expr`] describes it;
    /// recorded under `key` when it uses run-time parameters.
    pub(super) fn load_expression(
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
    pub(super) fn scale(&self, field: Field, factor: f64) {
        if factor != 1.0 {
            if let Some(expr) = self.symbolic.borrow_mut().get_mut(&field) {
                let inner = std::mem::replace(expr, Scalar::Const(0.0));
                *expr = Scalar::Mul(Box::new(Scalar::Const(factor)), Box::new(inner));
            }
        }
    }

    /// Records that `field` depends on run-time parameters through `expr`; true if it does.
    pub(super) fn record(&self, field: Field, expr: Scalar) -> bool {
        let runtime = !expr.parameters().is_empty();
        if runtime {
            self.symbolic.borrow_mut().insert(field, expr);
        }
        runtime
    }

    /// True when `field` depends on run-time parameters.
    pub(super) fn is_runtime(&self, field: Field) -> bool {
        self.symbolic.borrow().contains_key(&field)
    }

    /// Adds a check for the generated code.
    pub(super) fn check(&self, check: RuntimeCheck) {
        self.checks.borrow_mut().push(check);
    }
}

/// Parses an expression of `variables` (`["x"]`, a surface's `["x", "y"]`) and the
/// parameters, locating errors inside the string literal; records it under `key` when it
/// uses run-time parameters and returns it with every parameter resolved.
pub(super) fn expression(
    cx: &Context,
    field: &str,
    source: &str,
    variables: &[&str],
    key: Field,
) -> Checked<Scalar> {
    let (folded, resolved) = cx.table.expression(field, source, variables)?;
    cx.table.record(key, folded);
    Ok(resolved)
}
