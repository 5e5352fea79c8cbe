//! One evaluation of each term, generated code against the numeric recursion, on the same
//! states, side by side.

use super::timing::{MAX_BATCH_SECONDS, side_by_side};
use crate::CliError;
use crate::source::builtin_description;
use camchain_models as models;
use camchain_reference::NumericModel;
use camchain_runtime::{Dynamics, IntegratorKind, SimSettings, Simulate, State, VelocityTerms};
use std::fmt::Write;
use std::hint::black_box;

/// Models measured: the paper's chain (the fixed-cam yardstick), the roller follower on a
/// turning eccentric cam and the paper's chain on a rocking cam (cams on moving bodies), and
/// the spatial arm for a 3D case.
const MODELS: [&str; 4] = [
    "paper_concave",
    "eccentric_roller",
    "paper_rotating",
    "spatial_arm",
];

/// Consistent states along a run (for the right-hand side and the RK4 step).
pub(super) const STATES: usize = 8;

/// One measured quantity.
struct Row {
    model: &'static str,
    what: &'static str,
    generated: f64,
    numeric: f64,
}

/// Measures every row and returns the report section.
pub fn run(quick: bool) -> Result<String, CliError> {
    let (calls, batches) = if quick { (2_000, 5) } else { (20_000, 31) };
    let mut rows = Vec::new();
    for name in MODELS {
        let generated = models::by_name(name)
            .ok_or_else(|| CliError::Failed(format!("{name} is not built in")))?;
        let numeric = NumericModel::new(builtin_description(name)?);
        eprintln!("evaluations: {name}");
        rows.extend(measure(name, generated, &numeric, calls, batches)?);
    }
    Ok(render(&rows, calls, batches))
}

fn measure(
    name: &'static str,
    generated: &dyn Dynamics,
    numeric: &NumericModel,
    calls: usize,
    batches: usize,
) -> Result<Vec<Row>, CliError> {
    let states = states_along_a_run(generated)?;
    let mut rows = Vec::new();
    let mut row = |what, (g, num)| {
        rows.push(Row {
            model: name,
            what,
            generated: g,
            numeric: num,
        })
    };
    row(
        "M + F + Q (`equations`)",
        side_by_side(
            equations(generated, &states),
            equations(numeric, &states),
            calls,
            batches,
        ),
    );
    row(
        "h, J, c (`constraint` + `constraint_terms`)",
        side_by_side(
            constraint(generated, &states),
            constraint(numeric, &states),
            calls,
            batches,
        ),
    );
    row(
        "all terms of a right-hand side (`position_terms` + `velocity_terms`)",
        side_by_side(
            fused(generated, &states),
            fused(numeric, &states),
            calls,
            batches,
        ),
    );
    row(
        "reduced right-hand side with partitioning (`derivative`)",
        side_by_side(
            derivative(generated, &states)?,
            derivative(numeric, &numeric_states(numeric, &states)?)?,
            calls,
            batches,
        ),
    );
    let steps = (calls / 10).max(100);
    row(
        "one RK4 step (h = 1 ms; 4 right-hand sides, Newton, write-back)",
        side_by_side(
            rk4_steps(generated, &states[0]),
            rk4_steps(numeric, &numeric_states(numeric, &states)?[0]),
            steps,
            batches,
        ),
    );
    Ok(rows)
}

/// Sizes (n, nc) of a model.
fn sizes(model: &dyn Dynamics) -> (usize, usize) {
    (model.info().n(), model.info().n_contacts())
}

fn equations<'a>(model: &'a dyn Dynamics, states: &'a [State]) -> impl FnMut() + 'a {
    let (n, _) = sizes(model);
    let (mut m, mut f, mut q) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
    let mut k = 0;
    move || {
        let s = &states[k % STATES];
        k += 1;
        model.equations(s.t, &s.q, &s.qd, &mut m, &mut f, &mut q);
        black_box((&m, &f, &q));
    }
}

fn constraint<'a>(model: &'a dyn Dynamics, states: &'a [State]) -> impl FnMut() + 'a {
    let (n, nc) = sizes(model);
    let (mut h, mut j, mut c) = (vec![0.0; nc], vec![0.0; nc * n], vec![0.0; nc]);
    let mut k = 0;
    move || {
        let s = &states[k % STATES];
        k += 1;
        model.constraint(&s.q, &mut h);
        model.constraint_terms(&s.q, &s.qd, &mut j, &mut c);
        black_box((&h, &j, &c));
    }
}

fn fused<'a>(model: &'a dyn Dynamics, states: &'a [State]) -> impl FnMut() + 'a {
    let (n, nc) = sizes(model);
    let (mut h, mut j) = (vec![0.0; nc], vec![0.0; nc * n]);
    let mut cache = vec![0.0; model.cache_len()];
    let (mut m, mut f) = (vec![0.0; n * n], vec![0.0; n]);
    let (mut q, mut c) = (vec![0.0; n], vec![0.0; nc]);
    let mut k = 0;
    move || {
        let s = &states[k % STATES];
        k += 1;
        // As at a new state, like `derivative`: a cache left by another state would give a
        // roller's contact parameter a far warm start (and a scan of its profile).
        cache.fill(f64::NAN);
        model.position_terms(&s.q, &mut h, &mut j, &mut cache);
        let out = VelocityTerms {
            mass: &mut m,
            inertial: &mut f,
            applied: &mut q,
            bias: &mut c,
        };
        model.velocity_terms(s.t, &s.q, &s.qd, &cache, out);
        black_box((&h, &j, &m, &f, &q, &c));
    }
}

/// `STATES` assembled states 0.5 s apart along the model's default run.
pub(super) fn states_along_a_run(model: &dyn Dynamics) -> Result<Vec<State>, CliError> {
    let failed = |e: String| CliError::Failed(format!("{}: {e}", model.info().name));
    let mut state = model.assemble(0.0).map_err(|e| failed(e.to_string()))?;
    let mut states = Vec::with_capacity(STATES);
    for _ in 0..STATES {
        model
            .step(&mut state, 0.5)
            .map_err(|e| failed(e.to_string()))?;
        states.push(state.clone());
    }
    Ok(states)
}

/// The same (t, q, q̇) as `states`, as states of the numeric model.
pub(super) fn numeric_states(
    numeric: &NumericModel,
    states: &[State],
) -> Result<Vec<State>, CliError> {
    let base = numeric
        .assemble(0.0)
        .map_err(|e| CliError::Failed(e.to_string()))?;
    Ok(states
        .iter()
        .map(|s| {
            let mut copy = base.clone();
            copy.t = s.t;
            copy.q.clone_from(&s.q);
            copy.qd.clone_from(&s.qd);
            copy
        })
        .collect())
}

/// `derivative` at `states` in turn, each state's evaluation cache cleared before the call
/// (as at a new state).
pub(super) fn derivative<'a>(
    model: &'a dyn Dynamics,
    states: &[State],
) -> Result<impl FnMut() + 'a, CliError> {
    let mut states = states.to_vec();
    let mut dy = vec![0.0; states[0].integrated_len()];
    // First call outside the timing: loads the state into the integrated vector.
    for state in &mut states {
        model
            .derivative(state, &mut dy)
            .map_err(|e| CliError::Failed(e.to_string()))?;
    }
    let mut k = 0;
    Ok(move || {
        let state = &mut states[k % STATES];
        k += 1;
        // As at a new state: nothing of this state's last evaluation is reused (the sines
        // and cosines a generated model keeps in its cache; ~1.5 ns to clear).
        state.clear_evaluation_cache();
        // Measured code: cannot fail on these consistent states (checked above).
        let _ = model.derivative(state, &mut dy);
        black_box(&dy);
    })
}

fn rk4_steps<'a>(model: &'a dyn Dynamics, start: &State) -> impl FnMut() + 'a {
    let settings = SimSettings {
        integrator: IntegratorKind::Rk4,
        dt: 1e-3,
        ..model.info().defaults.clone()
    };
    let (start, mut state, mut taken) = (start.clone(), start.clone(), 0);
    move || {
        // Restart every 1000 steps (1 s) so that every batch covers the same motion.
        if taken == 1000 {
            state.clone_from(&start);
            taken = 0;
        }
        taken += 1;
        let _ = model.step_with(&mut state, 1e-3, &settings);
        black_box(&state.q);
    }
}

fn render(rows: &[Row], calls: usize, batches: usize) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "## Generated code against the numeric recursion\n\n\
         One evaluation on the same states (8 consistent states 0.5 s apart along the model's \
         run), median of {batches} batches of {calls} calls (RK4: {} steps; a routine whose \
         batch would take over {:.0} ms gets as many calls as fit, a multiple of 8: the \
         numeric reference's roller contact scans its profile at every call), generated and \
         numeric batches interleaved in one run. Numeric: the nalgebra recursive Newton–Euler \
         reference of `reference/src/numeric.rs` on the same model file. The reduced \
         right-hand side is taken as at a new state: each state's evaluation cache is cleared \
         before the call, so the sines and cosines kept from its last evaluation are not \
         reused (they are in a run, when Newton evaluates again after moving a sliding \
         coordinate), nor a roller's contact parameter (Newton solves it from its cold \
         start; in a run it starts from the last evaluation's). The fused \
         `position_terms` + `velocity_terms` start from a cleared cache too.\n\n\
         | model | evaluation | generated [ns] | numeric [ns] | numeric / generated |\n\
         |---|---|---:|---:|---:|",
        (calls / 10).max(100),
        MAX_BATCH_SECONDS * 1e3
    );
    for r in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {:.0} | {:.0} | {:.1}× |",
            r.model,
            r.what,
            r.generated,
            r.numeric,
            r.numeric / r.generated
        );
    }
    let _ = writeln!(
        out,
        "\nReproduce: `cargo run --release -- bench evaluations` (rewrites this section and the \
         section \"Cams on moving bodies\")."
    );
    out
}
