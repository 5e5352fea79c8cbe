//! Numerical stability stress scenarios: variants of the reference models and the
//! measurements made on their runs.
//!
//! Used by `camchain stress` (which writes `STRESS.md` and its figures) and by the fast
//! checks in `cli/tests/suite/stress.rs`. A variant is the validated [`Model`] of a file in `models/`
//! changed in memory — dampers removed, springs stiffened, masses
//! scaled, another profile — and run on the numeric recursive reference
//! ([`NumericModel`]), so no rebuild is needed. The unmodified built-in models run their
//! generated code ([`camchain_models::by_name`]).

use camchain_codegen::model::Field;
use camchain_codegen::model::{Model, Prescribed, Profile};
use camchain_codegen::schema::parse_model;
use camchain_reference::NumericModel;
use camchain_runtime::{
    Dynamics, IntegratorKind, SimError, SimSettings, Simulate, State, Stats, Trajectory,
};
use std::path::Path;
use std::time::{Duration, Instant};

/// The adaptive integrators swept by [`sweep`], with their command-line names. A new
/// adaptive [`IntegratorKind`] is one more line here.
pub const ADAPTIVE: &[(&str, IntegratorKind)] = &[
    ("dopri5", IntegratorKind::Dopri5),
    ("dop853", IntegratorKind::Dop853),
];

/// One integrator configuration of a sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct Integration {
    /// Short label for tables, e.g. `rk4 dt=1e-3`, `dopri5 rtol=1e-8`.
    pub label: String,
    /// The settings (end time and output interval included).
    pub settings: SimSettings,
}

/// Fixed-step RK4 settings.
pub fn rk4(t_end: f64, dt_out: f64, dt: f64) -> SimSettings {
    SimSettings {
        t_end,
        dt_out,
        integrator: IntegratorKind::Rk4,
        dt,
        rtol: 1e-8,
        atol: 1e-10,
    }
}

/// Adaptive settings with `atol = rtol / 100` and a first step of 1 ms.
pub fn adaptive(kind: IntegratorKind, t_end: f64, dt_out: f64, rtol: f64) -> SimSettings {
    SimSettings {
        t_end,
        dt_out,
        integrator: kind,
        dt: 1e-3,
        rtol,
        atol: rtol * 1e-2,
    }
}

/// RK4 at each step of `steps`, then every integrator of [`ADAPTIVE`] at each tolerance of
/// `tolerances`.
pub fn sweep(t_end: f64, dt_out: f64, steps: &[f64], tolerances: &[f64]) -> Vec<Integration> {
    let mut list: Vec<Integration> = steps
        .iter()
        .map(|&dt| Integration {
            label: format!("rk4 dt={}", short(dt)),
            settings: rk4(t_end, dt_out, dt),
        })
        .collect();
    for &(name, kind) in ADAPTIVE {
        list.extend(tolerances.iter().map(|&rtol| Integration {
            label: format!("{name} rtol={}", short(rtol)),
            settings: adaptive(kind, t_end, dt_out, rtol),
        }));
    }
    list
}

/// `1e-3`, `0.02`, `2.5e-5`: a step or tolerance as a table shows it.
pub fn short(x: f64) -> String {
    if (1e-2..1e3).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

// ---------------------------------------------------------------------------------------
// Models and variants.

/// The built-in model `name` (`models/<name>.ron`, compiled into the binary), validated; the
/// error is one line.
pub fn builtin_model(name: &str) -> Result<Model, String> {
    let source =
        camchain_models::source(name).ok_or_else(|| format!("no built-in model `{name}`"))?;
    let file = Path::new("models").join(format!("{name}.ron"));
    let files = camchain_codegen::schema::Files::Embedded(camchain_models::files(name));
    camchain_codegen::schema::parse_model_from(
        source,
        &file,
        &[],
        camchain_codegen::model::ParameterMode::AsDeclared,
        files,
    )
    .map_err(|e| e.to_string().replace('\n', " "))
}

/// A two-link arm (1 m links) hanging from the origin with its tip on the flat cam
/// y = −1.5: during its swing the Jacobian entry of the dependent coordinate goes through
/// zero (`scenarios/repartition.ron`).
pub const REPARTITION: &str = include_str!("../scenarios/repartition.ron");

/// A two-link arm whose driven first joint lifts the tip off the reach of a flat cam at
/// t = π/3 s (`scenarios/unreachable.ron`).
pub const UNREACHABLE: &str = include_str!("../scenarios/unreachable.ron");

/// One of the scenario files above, validated; `file` names it in messages.
pub fn scenario(text: &str, file: &str) -> Result<Model, String> {
    parse(text, &Path::new("cli/scenarios").join(file))
}

/// Validates model text; the error is one line.
pub fn parse(source: &str, file: &Path) -> Result<Model, String> {
    parse_model(source, file).map_err(|e| e.to_string().replace('\n', " "))
}

/// A variant under a new name.
pub fn renamed(mut model: Model, name: &str) -> Model {
    model.name = name.to_string();
    model
}

/// Removes every joint damper (the mechanical energy is then conserved).
pub fn without_dampers(mut model: Model) -> Model {
    for body in &mut model.bodies {
        if let Some(spring) = &mut body.joint.spring {
            spring.damping = 0.0;
        }
    }
    model
}

/// Multiplies every joint spring's stiffness by `factor`.
pub fn stiffer(mut model: Model, factor: f64) -> Model {
    for body in &mut model.bodies {
        if let Some(spring) = &mut body.joint.spring {
            spring.stiffness *= factor;
        }
    }
    model
}

/// Multiplies the mass and inertia of the bodies selected by `which` (body index) by
/// `factor`.
pub fn heavier(mut model: Model, factor: f64, which: impl Fn(usize) -> bool) -> Model {
    for (i, body) in model.bodies.iter_mut().enumerate() {
        if which(i) {
            body.mass *= factor;
            for row in &mut body.inertia {
                for entry in row {
                    *entry *= factor;
                }
            }
        }
    }
    model
}

/// Multiplies every mass, inertia, spring stiffness and damper by `factor`, and keeps the
/// gravity: every term of M q̈ + F + Q is multiplied by `factor` (gravity loads are
/// proportional to the masses), J and c do not change, so the motion is exactly the
/// nominal one and only the forces and energies scale.
pub fn scaled(model: Model, factor: f64) -> Model {
    let mut model = heavier(model, factor, |_| true);
    for body in &mut model.bodies {
        if let Some(spring) = &mut body.joint.spring {
            spring.stiffness *= factor;
            spring.damping *= factor;
        }
    }
    model
}

/// Replaces the profile of contact `k`; the error is the parser's message.
pub fn with_profile(mut model: Model, k: usize, source: &str) -> Result<Model, String> {
    let profile = model
        .parse_expression(source, "x")
        .map_err(|e| e.to_string())?;
    model.symbolic.remove(&Field::Profile(k));
    let contact = model
        .contacts
        .get_mut(k)
        .ok_or_else(|| format!("the model has no contact {k}"))?;
    contact.profile = Profile::Explicit {
        source: source.to_string(),
        f: profile,
    };
    Ok(model)
}

/// Sets the initial velocity guess of coordinate `name` (rad/s or m/s).
pub fn with_velocity(mut model: Model, name: &str, value: f64) -> Result<Model, String> {
    let i = model
        .coordinate_names()
        .iter()
        .position(|c| *c == name)
        .ok_or_else(|| format!("the model has no coordinate {name}"))?;
    model.initial.qd[i] = value;
    Ok(model)
}

/// Replaces the prescribed motion of coordinate `name` (an expression in `t`); the error
/// is the parser's message.
pub fn with_drive(mut model: Model, name: &str, source: &str) -> Result<Model, String> {
    let expr = model
        .parse_expression(source, "t")
        .map_err(|e| e.to_string())?;
    let i = model
        .coordinate_names()
        .iter()
        .position(|c| *c == name)
        .ok_or_else(|| format!("the model has no coordinate {name}"))?;
    model.symbolic.remove(&Field::Drive(i));
    let body = &mut model.bodies[i];
    body.joint.prescribed = Some(Prescribed {
        source: source.to_string(),
        expr,
    });
    Ok(model)
}

/// Profiles for the profile-variant scenarios, as (name, profile source): each passes
/// through the point (x0, y0) where the nominal paper model's tip starts, so that the same
/// assembly applies. From the start the tip slides left, by up to ~0.8 m.
pub fn profile_variants(x0: f64, y0: f64) -> Vec<(&'static str, String)> {
    let d = format!("(x - {x0:?})");
    vec![
        ("flat", format!("{y0:?} + 0.0*x")),
        ("steep (slope 5)", format!("{y0:?} + 5.0*{d}")),
        ("very steep (slope 50)", format!("{y0:?} + 50.0*{d}")),
        (
            "inflection (tanh step, inflection 0.25 m left of x0)",
            format!(
                "{:?} + 0.1*(20.0*(x - {:?})).tanh()",
                y0 - 0.1 * (20.0_f64 * 0.25).tanh(),
                x0 - 0.25
            ),
        ),
        (
            "wavy (slope sign changes every 0.1 m)",
            format!("{y0:?} + 0.02*(31.4*{d}).sin()"),
        ),
    ]
}

// ---------------------------------------------------------------------------------------
// Runs and measurements.

/// One run of a scenario with one integration: its outcome and what was computed.
#[derive(Debug, Clone)]
pub struct Record {
    /// The integration's label.
    pub label: String,
    /// `Ok` or why the run stopped.
    pub error: Option<SimError>,
    /// The trajectory, or the partial one of a failed run.
    pub trajectory: Trajectory,
    /// Wall-clock time of the run.
    pub wall: Duration,
}

impl Record {
    /// True when the run reached its end time.
    pub fn ok(&self) -> bool {
        self.error.is_none()
    }

    /// Work counters.
    pub fn stats(&self) -> Stats {
        self.trajectory.stats
    }

    /// Time of the last sample (NaN without samples).
    pub fn t_reached(&self) -> f64 {
        self.trajectory.samples.last().map_or(f64::NAN, |s| s.t)
    }

    /// Largest constraint residual max |h| over the samples.
    pub fn max_h(&self) -> f64 {
        max_residual(&self.trajectory)
    }

    /// Largest change of `energy + dissipated − driven_work` from its initial value (J):
    /// zero for an exact solution.
    pub fn energy_drift(&self) -> f64 {
        energy_drift(&self.trajectory)
    }

    /// Largest |q − q_ref|∞ over the output times both trajectories have.
    pub fn difference(&self, reference: &Trajectory) -> f64 {
        difference(&self.trajectory, reference)
    }
}

/// Simulates from `state` with `integration`, timing the run.
pub fn run(model: &dyn Dynamics, state: &State, integration: &Integration) -> Record {
    let start = Instant::now();
    let result = model.simulate(state.clone(), &integration.settings);
    let wall = start.elapsed();
    let (error, trajectory) = match result {
        Ok(trajectory) => (None, trajectory),
        Err(failure) => (Some(failure.error), failure.partial),
    };
    Record {
        label: integration.label.clone(),
        error,
        trajectory,
        wall,
    }
}

/// max |h| over every sample and contact.
pub fn max_residual(trajectory: &Trajectory) -> f64 {
    trajectory
        .samples
        .iter()
        .flat_map(|s| s.h.iter())
        .fold(0.0, |m, h| m.max(h.abs()))
}

/// `energy + dissipated − driven_work` at each sample: constant for an exact solution.
pub fn balance(trajectory: &Trajectory) -> Vec<(f64, f64)> {
    trajectory
        .samples
        .iter()
        .map(|s| (s.t, s.energy.total() + s.dissipated - s.driven_work))
        .collect()
}

/// Largest |balance(t) − balance(t0)|.
pub fn energy_drift(trajectory: &Trajectory) -> f64 {
    let values = balance(trajectory);
    let Some(&(_, first)) = values.first() else {
        return f64::NAN;
    };
    values
        .iter()
        .fold(0.0, |m, &(_, e)| m.max((e - first).abs()))
}

/// Largest |q − q_ref|∞ at the output times the two trajectories share (matched by time).
pub fn difference(trajectory: &Trajectory, reference: &Trajectory) -> f64 {
    let mut worst = 0.0_f64;
    let mut j = 0;
    for sample in &trajectory.samples {
        while j < reference.samples.len() && reference.samples[j].t < sample.t {
            j += 1;
        }
        let Some(other) = reference.samples.get(j) else {
            break;
        };
        if other.t == sample.t {
            for (a, b) in sample.q.iter().zip(&other.q) {
                worst = worst.max((a - b).abs());
            }
        }
    }
    worst
}

/// Largest |h| among the samples whose time lies in `[t0 + a·span, t0 + b·span]` (a, b
/// fractions of the run).
pub fn max_residual_between(trajectory: &Trajectory, a: f64, b: f64) -> f64 {
    let (Some(first), Some(last)) = (trajectory.samples.first(), trajectory.samples.last()) else {
        return f64::NAN;
    };
    let span = last.t - first.t;
    let (lo, hi) = (first.t + a * span, first.t + b * span);
    trajectory
        .samples
        .iter()
        .filter(|s| s.t >= lo && s.t <= hi)
        .flat_map(|s| s.h.iter())
        .fold(0.0, |m, h| m.max(h.abs()))
}

/// The mean step size and the rejected attempts in each output interval of `settings`,
/// stepping with [`Simulate::step_with`]: `(t at the interval's end, mean step, rejected)`.
/// Stops at the first error, which is returned with what was measured.
pub fn step_history(
    model: &dyn Dynamics,
    mut state: State,
    settings: &SimSettings,
) -> (Vec<(f64, f64, usize)>, Option<SimError>) {
    let mut history = Vec::new();
    let t0 = state.t;
    let intervals = ((settings.t_end - t0) / settings.dt_out).round().max(1.0) as usize;
    for k in 1..=intervals {
        let target = t0 + k as f64 * settings.dt_out;
        let dt = target - state.t;
        match model.step_with(&mut state, dt, settings) {
            Ok(stats) => history.push((state.t, dt / stats.steps.max(1) as f64, stats.rejected)),
            Err(error) => return (history, Some(error)),
        }
    }
    (history, None)
}

/// The assembled initial state of a numeric model; the error is the runtime's message.
pub fn assemble(model: &dyn Dynamics) -> Result<State, String> {
    model
        .assemble(0.0)
        .map_err(|e| format!("{}: assembly failed: {e}", model.info().name))
}

/// A numeric model of a variant.
pub fn numeric(model: Model) -> NumericModel {
    NumericModel::new(model)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweeps_list_rk4_then_each_adaptive_integrator() {
        let list = sweep(1.0, 0.1, &[1e-3, 0.02], &[1e-6]);
        let labels: Vec<&str> = list.iter().map(|i| i.label.as_str()).collect();
        assert_eq!(
            labels,
            [
                "rk4 dt=1e-3",
                "rk4 dt=0.02",
                "dopri5 rtol=1e-6",
                "dop853 rtol=1e-6"
            ]
        );
        assert_eq!(list[2].settings.atol, 1e-8);
        assert_eq!(list[3].settings.integrator, IntegratorKind::Dop853);
    }

    #[test]
    fn scaling_every_load_with_the_masses_scales_the_equations() {
        let nominal = numeric(builtin_model("paper_concave").expect("model file"));
        let heavy = numeric(scaled(
            builtin_model("paper_concave").expect("model file"),
            1e3,
        ));
        let q = [-1.6, 0.1, -0.07, 0.05];
        let qd = [0.3, -0.2, 0.1, 0.4];
        let (mut a, mut b) = (vec![0.0; 16], vec![0.0; 16]);
        nominal.mass_matrix(&q, &mut a);
        heavy.mass_matrix(&q, &mut b);
        for (x, y) in a.iter().zip(&b) {
            // Products of the same numbers times 1e3: equal to a few ulps.
            assert!((1e3 * x - y).abs() <= 1e-12 * y.abs().max(1.0));
        }
        let (mut fa, mut fb) = (vec![0.0; 4], vec![0.0; 4]);
        nominal.applied_forces(0.0, &q, &qd, &mut fa);
        heavy.applied_forces(0.0, &q, &qd, &mut fb);
        for (x, y) in fa.iter().zip(&fb) {
            assert!((1e3 * x - y).abs() <= 1e-12 * y.abs().max(1.0));
        }
    }
}
