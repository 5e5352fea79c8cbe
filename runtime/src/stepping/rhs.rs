//! The reduced right-hand side: from y = (u, u̇, …, v) to the full q, q̇ by Newton (15) and
//! the velocity relation (16), then q̈ and ü by the reduced dynamics (17, 18).

use crate::dynamics::Dynamics;
use crate::error::SimError;
use crate::partition::{Partition, Workspace};

/// The right-hand side on y = (u, u̇, dissipated, driven work): Newton (15), velocities
/// (16), reduced dynamics (17, 18), drive loads when there are driven coordinates, and the
/// multipliers also without drives when `multipliers` is set.
pub(crate) fn evaluate_rhs(
    model: &dyn Dynamics,
    partition: &Partition,
    ws: &mut Workspace,
    t: f64,
    y: &[f64],
    dy: &mut [f64],
    multipliers: bool,
) -> Result<(), SimError> {
    let nu = partition.independent().len();
    load_state(model, partition, ws, t, y)?;
    ws.solve_accelerations(model, partition, t)?;
    if multipliers || !partition.driven().is_empty() {
        ws.solve_multipliers(partition, t)?;
    }
    let drive_power = if partition.driven().is_empty() {
        0.0
    } else {
        ws.drive_power(partition)
    };
    let (velocities, accelerations) = dy[..2 * nu].split_at_mut(nu);
    for ((dq, ddq), &u) in velocities
        .iter_mut()
        .zip(accelerations)
        .zip(partition.independent())
    {
        (*dq, *ddq) = (ws.qd[u], ws.qdd[u]);
    }
    dy[2 * nu] = model.damper_power(ws.qd());
    dy[2 * nu + 1] = drive_power + model.load_power(t, ws.q(), ws.qd());
    let nc = partition.dependent().len();
    for (k, &v) in partition.dependent().iter().enumerate() {
        dy[2 * nu + 2 + k] = ws.qd[v];
        dy[2 * nu + 2 + nc + k] = ws.qdd[v];
    }
    if !dy[2 * nu].is_finite() {
        return Err(ws.non_finite(t, "damper power"));
    }
    Ok(())
}

/// Full q, q̇ at (t, y): prescribed motion, u and u̇ from y, v by Newton (15) and v̇ by
/// (16). Leaves J(q) evaluated and J_v factored in the workspace.
pub(crate) fn load_state(
    model: &dyn Dynamics,
    partition: &Partition,
    ws: &mut Workspace,
    t: f64,
    y: &[f64],
) -> Result<(), SimError> {
    let nu = partition.independent().len();
    model.prescribed(t, &mut ws.q, &mut ws.qd, &mut ws.qdd);
    let (positions, velocities) = y[..2 * nu].split_at(nu);
    for ((&q, &qd), &u) in positions
        .iter()
        .zip(velocities)
        .zip(partition.independent())
    {
        (ws.q[u], ws.qd[u]) = (q, qd);
    }
    let nc = partition.dependent().len();
    for (k, &v) in partition.dependent().iter().enumerate() {
        // The integrated v (uncontrolled, see `State`) is Newton's starting point.
        ws.q[v] = y[2 * nu + 2 + k];
    }
    if nc == 0 {
        ws.factor_jacobian(model, partition.dependent(), t)?;
    } else {
        // Newton ends with h, J, the cache and the factored J_v of the returned q.
        solve_positions_with_restart(model, partition.dependent(), ws, t)?;
        ws.polish_positions(partition.dependent());
        // Near a singular position J changes across the polish by as much as the rows'
        // own size: evaluated again at the polished q (docs/method.md §11.4).
        if ws.rows_shrunk() {
            ws.factor_jacobian(model, partition.dependent(), t)?;
        }
    }
    ws.solve_velocities(partition.dependent());
    Ok(())
}

/// Newton (15) from the last evaluation's v; if that fails (e.g. after an overshooting
/// trial stage), once more from v at the last accepted step.
fn solve_positions_with_restart(
    model: &dyn Dynamics,
    dependent: &[usize],
    ws: &mut Workspace,
    t: f64,
) -> Result<(), SimError> {
    if dependent.is_empty() || ws.solve_positions(model, dependent, t).is_ok() {
        return Ok(());
    }
    for (k, &v) in dependent.iter().enumerate() {
        ws.q[v] = ws.v_anchor[k];
    }
    ws.solve_positions(model, dependent, t).map(|_| ())
}
