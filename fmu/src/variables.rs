//! The FMU's variables and their value references, from the model's description alone, so
//! that the library (which serves them) and `modelDescription.xml` (which declares them)
//! number them the same way.
//!
//! Value references, in order: 0 `time`; then the model's run-time parameters in file
//! order; then the integrator's settings (`solver.rtol`, `solver.atol`, `solver.dt`); then
//! the speed of every coordinate driven at a constant speed, as an input
//! (`<coordinate>_speed`, [`crate::drive`]); then every output column of
//! [`camchain_runtime::columns`] but `t`, in the CSV's order and under the CSV's names.

use crate::drive::constant_speed_drives;
use camchain_runtime::columns::columns;
use camchain_runtime::{Dynamics, IntegratorKind, JointKind};

/// The Enumeration value of an integrator: its place in [`IntegratorKind::ALL`], from 1.
pub fn integrator_value(kind: IntegratorKind) -> i64 {
    IntegratorKind::ALL
        .iter()
        .position(|&k| k == kind)
        .map_or(0, |i| i as i64 + 1)
}

/// The integrator of an Enumeration value, `None` outside the items.
pub fn integrator_of(value: i64) -> Option<IntegratorKind> {
    usize::try_from(value - 1)
        .ok()
        .and_then(|i| IntegratorKind::ALL.get(i).copied())
}

/// What a variable is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The independent variable, time (s).
    Time,
    /// The run-time parameter of this index in
    /// [`ModelInfo::parameters`](camchain_runtime::ModelInfo::parameters).
    Parameter(usize),
    /// One of the integrator's settings.
    Setting(Setting),
    /// The speed of the drive of this coordinate (an input).
    Input(usize),
    /// The output column of this index in [`camchain_runtime::columns::columns`] (≥ 1).
    Output(usize),
}

/// The integrator's settings an FMU exposes as parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    /// The integrator: an Enumeration (`Integrator`) whose items are the runtime's
    /// integrators, numbered from 1 in [`IntegratorKind::ALL`]'s order.
    Integrator,
    /// Relative tolerance of the adaptive integrators.
    Rtol,
    /// Absolute tolerance of the adaptive integrators.
    Atol,
    /// RK4's fixed step, the adaptive integrators' first step (s).
    Dt,
}

impl Setting {
    /// Every setting, in value-reference order.
    pub const ALL: [Setting; 4] = [
        Setting::Integrator,
        Setting::Rtol,
        Setting::Atol,
        Setting::Dt,
    ];

    /// The variable's name.
    pub fn name(self) -> &'static str {
        match self {
            Setting::Integrator => "solver.integrator",
            Setting::Rtol => "solver.rtol",
            Setting::Atol => "solver.atol",
            Setting::Dt => "solver.dt",
        }
    }

    /// Its unit and description.
    fn about(self) -> (&'static str, &'static str) {
        match self {
            Setting::Integrator => ("", "the integrator (rk4, dopri5, dop853)"),
            Setting::Rtol => ("", "relative tolerance of the adaptive integrators"),
            Setting::Atol => ("", "absolute tolerance of the adaptive integrators"),
            Setting::Dt => (
                "s",
                "RK4's fixed step; the adaptive integrators' first step",
            ),
        }
    }
}

/// One variable of the FMU.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    /// Its name (the CSV column's, the parameter's).
    pub name: String,
    /// Its value reference.
    pub reference: u32,
    /// What it is.
    pub role: Role,
    /// Its unit (ASCII), empty when dimensionless or not declared.
    pub unit: String,
    /// One line.
    pub description: String,
    /// Start value (parameters and settings).
    pub start: Option<f64>,
    /// Declared bounds (parameters; settings are positive).
    pub min: Option<f64>,
    /// Declared bounds.
    pub max: Option<f64>,
}

/// Every variable of a model's FMU, in value-reference order (the reference is the index).
pub fn variables(model: &dyn Dynamics) -> Vec<Variable> {
    let info = model.info();
    let mut out = Vec::new();
    let mut push = |name: String, role, unit: &str, description: String, bounds| {
        let (start, min, max) = bounds;
        out.push(Variable {
            reference: u32::try_from(out.len()).unwrap_or(u32::MAX),
            name,
            role,
            unit: unit.to_string(),
            description,
            start,
            min,
            max,
        });
    };
    push(
        "time".into(),
        Role::Time,
        "s",
        "simulation time".into(),
        (None, None, None),
    );
    for (i, p) in info.parameters.iter().enumerate() {
        push(
            p.name.clone(),
            Role::Parameter(i),
            &p.unit,
            p.description.clone(),
            (Some(p.default), p.min, p.max),
        );
    }
    for setting in Setting::ALL {
        let (unit, description) = setting.about();
        let start = match setting {
            Setting::Integrator => integrator_value(info.defaults.integrator) as f64,
            Setting::Rtol => info.defaults.rtol,
            Setting::Atol => info.defaults.atol,
            Setting::Dt => info.defaults.dt,
        };
        push(
            setting.name().into(),
            Role::Setting(setting),
            unit,
            description.into(),
            (Some(start), None, None),
        );
    }
    for (i, speed) in constant_speed_drives(model) {
        let c = &info.coordinates[i];
        let unit = match c.kind {
            JointKind::Revolute => "rad/s",
            JointKind::Prismatic => "m/s",
        };
        push(
            format!("{}_speed", c.name),
            Role::Input(i),
            unit,
            format!(
                "speed of the drive of {} (its own law, {speed} {unit}, until set)",
                c.name
            ),
            (Some(speed), None, None),
        );
    }
    for (i, column) in columns(info).into_iter().enumerate().skip(1) {
        push(
            column.name,
            Role::Output(i),
            column.unit,
            column.description,
            (None, None, None),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn references_are_indices_and_outputs_are_the_csv_columns() {
        let model = camchain_models::by_name("cycloidal_roller").expect("built in");
        let info = model.info();
        let all = variables(model);
        for (i, v) in all.iter().enumerate() {
            assert_eq!(v.reference as usize, i);
        }
        assert_eq!(all[0].role, Role::Time);
        let outputs: Vec<&str> = all
            .iter()
            .filter(|v| matches!(v.role, Role::Output(_)))
            .map(|v| v.name.as_str())
            .collect();
        let csv: Vec<String> = columns(info).into_iter().skip(1).map(|c| c.name).collect();
        assert_eq!(outputs, csv);
        let parameters = all
            .iter()
            .filter(|v| matches!(v.role, Role::Parameter(_)))
            .count();
        assert_eq!(parameters, info.parameters.len());
        // The camshaft turns at `omega*t`: its speed is an input, starting at omega.
        let input = all
            .iter()
            .find(|v| v.role == Role::Input(0))
            .expect("an input");
        assert_eq!(input.name, "cam_angle_speed");
        assert_eq!(input.start, Some(50.0));
    }
}
