//! Assembly of a consistent initial state (docs/method.md §5.9), and the report of what it
//! changed.
//!
//! Held and driven coordinates keep their values (a drive sets its own); one coordinate per
//! contact, among the others, is solved from h(q) = 0. With one contact the solved
//! coordinate moves to the root of h nearest its guess: h is scanned outwards from the
//! guess in both directions (over ±π for an angle, ± the model's length scale for a
//! displacement) and the first sign change bracketed and refined, so that the mechanism is
//! assembled in the configuration the guess describes rather than in whichever branch
//! Newton happens to converge to. Without a sign change within reach, and for several
//! contacts, Newton (15) runs from the guess, with a backtracking Newton as fallback. The
//! velocities of the solved coordinates then follow from J q̇ = 0 (16).

use crate::dynamics::{ContactGeometry, Dynamics, JointKind};
use crate::error::SimError;
use crate::partition::{Partition, Workspace, independent_rows};
use crate::stepping::{State, invalid};
use std::f64::consts::PI;

/// What assembly did to the model's initial guess.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AssemblyReport {
    /// Every coordinate or velocity whose value assembly changed beyond round-off, in
    /// coordinate order (positions first).
    pub changes: Vec<AssemblyChange>,
    /// How the solved coordinates were found.
    pub root: RootChoice,
    /// The constraint rows left out as redundant (implied by the others: a Bricard
    /// mechanism, a parallelogram with a third bar), by name (`loop.equation`): their
    /// multipliers are zero, the others carry the reactions (docs/method.md §11.3).
    pub redundant: Vec<String>,
}

/// One value assembly changed.
#[derive(Debug, Clone, PartialEq)]
pub struct AssemblyChange {
    /// Index of the coordinate.
    pub coordinate: usize,
    /// True for its velocity, false for its position.
    pub velocity: bool,
    /// The guess (the model file's value, or 0 where it gives none).
    pub from: f64,
    /// The assembled value.
    pub to: f64,
    /// Why it changed.
    pub cause: ChangeCause,
    /// True when the model file gave the guess (rather than its default 0).
    pub given: bool,
}

/// Why assembly changed a value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChangeCause {
    /// The coordinate is driven: its drive sets position and velocity at t0.
    Drive,
    /// Solved from the constraint: the position from h = 0, the velocity from J q̇ = 0.
    Constraint,
}

/// How the solved coordinates were found.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum RootChoice {
    /// No contact: nothing to solve.
    #[default]
    NoContact,
    /// The guess was on the cam already.
    AtGuess,
    /// One contact: the root of h nearest the guess, found by scanning up to `reach`
    /// (rad or m) on both sides of it.
    Nearest {
        /// How far from the guess the scan went before it found the root.
        distance: f64,
    },
    /// Newton (15) from the guess: several contacts (the scan is one-dimensional), or no
    /// sign change of h within reach of the guess (`scanned` says which).
    Newton {
        /// True when a scan found no root within reach (one contact).
        scanned: bool,
    },
}

/// Steps of the scan on each side of the guess.
const SCAN_STEPS: usize = 128;

/// Assembles the model's own initial guess at t0, with the report.
pub(crate) fn assemble(model: &dyn Dynamics, t0: f64) -> Result<(State, AssemblyReport), SimError> {
    let initial = &model.info().initial;
    assemble_from(model, t0, (&initial.q, &initial.qd), &initial.hold)
}

/// A consistent state at `t` from (q, q̇) with nothing held (what
/// [`Simulate::state_at`](crate::Simulate::state_at) returns, and what a one-sided run
/// restarts from at every lift-off and landing): [`assemble_from`] without its report.
pub(crate) fn state_at(
    model: &dyn Dynamics,
    t: f64,
    (q, qd): (&[f64], &[f64]),
) -> Result<State, SimError> {
    let hold = vec![false; model.info().n()];
    assemble_from(model, t, (q, qd), &hold).map(|(state, _)| state)
}

/// A consistent state at t0 from (q, q̇): held and driven coordinates keep their values, one
/// coordinate per contact is solved from h = 0 (nearest root for one contact) and the
/// velocities of the solved ones from J q̇ = 0 (16).
pub(crate) fn assemble_from(
    model: &dyn Dynamics,
    t0: f64,
    (q, qd): (&[f64], &[f64]),
    hold: &[bool],
) -> Result<(State, AssemblyReport), SimError> {
    let info = model.info();
    let (n, m) = (info.n(), info.n_constraints());
    let driven: Vec<bool> = info.coordinates.iter().map(|c| c.driven).collect();
    validate_model(model, &driven, t0)?;
    if q.len() != n || qd.len() != n || hold.len() != n {
        return Err(invalid(format!("{} needs {n} coordinates", info.name)));
    }
    let mut ws = workspace(n, &driven, m, &(0..m).collect::<Vec<_>>());
    ws.set_state(q, qd);
    model.prescribed(t0, &mut ws.q, &mut ws.qd, &mut ws.qdd);
    if ws.q().iter().chain(ws.qd()).any(|x| !x.is_finite()) {
        return Err(ws.non_finite(t0, "initial guess"));
    }
    ws.set_length_scale(length_scale(model, ws.q()));
    let (solved, root) = assemble_positions(model, &mut ws, &driven, hold, t0)?;
    ws.factor_jacobian(model, &solved, t0)?;
    ws.solve_velocities(&solved);
    let eligible: Vec<bool> = driven.iter().map(|d| !d).collect();
    let dependent = ws
        .choose_dependent(&eligible)
        .ok_or_else(|| ws.singular(t0))?;
    let partition = Partition::new(&driven, &dependent)?;
    let redundant = (0..m)
        .filter(|k| !ws.rows().contains(k))
        .map(|k| info.constraint_name(k))
        .collect();
    let report = AssemblyReport {
        changes: changes(model, (q, qd), (ws.q(), ws.qd()), &driven),
        root,
        redundant,
    };
    Ok((State::new(t0, ws, partition), report))
}

/// A workspace solving `rows` of the model's m constraints.
fn workspace(n: usize, driven: &[bool], m: usize, rows: &[usize]) -> Workspace {
    let nc = rows.len();
    let nu = n - nc - driven.iter().filter(|d| **d).count();
    let mut ws = Workspace::new(n, nc, nu);
    ws.select_rows(m, rows);
    ws
}

/// `ws` re-made to solve `rows` only, with its state and length scale.
fn restrict(ws: &Workspace, driven: &[bool], rows: &[usize]) -> Workspace {
    let mut out = workspace(ws.n_coordinates(), driven, ws.m(), rows);
    out.set_state(ws.q(), ws.qd());
    out.q.copy_from_slice(ws.q());
    out.qdd.copy_from_slice(&ws.qdd);
    out.set_length_scale(ws.length_scale());
    out
}

/// The values that differ between the guess and the assembled state (beyond a relative
/// 1e-12, round-off of Newton's last step).
fn changes(
    model: &dyn Dynamics,
    (q, qd): (&[f64], &[f64]),
    (q_new, qd_new): (&[f64], &[f64]),
    driven: &[bool],
) -> Vec<AssemblyChange> {
    let initial = &model.info().initial;
    let given = |flags: &[bool], i: usize| flags.get(i).copied().unwrap_or(false);
    let mut out = Vec::new();
    for (velocity, from, to, flags) in [
        (false, q, q_new, &initial.given_q),
        (true, qd, qd_new, &initial.given_qd),
    ] {
        for i in 0..from.len() {
            let (a, b) = (from[i], to[i]);
            if (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs())) {
                continue;
            }
            out.push(AssemblyChange {
                coordinate: i,
                velocity,
                from: a,
                to: b,
                cause: if driven[i] {
                    ChangeCause::Drive
                } else {
                    ChangeCause::Constraint
                },
                given: given(flags, i),
            });
        }
    }
    out
}

/// The model's length scale for Newton's tolerance: the largest coordinate of a contact
/// point (ground frame) at q.
fn length_scale(model: &dyn Dynamics, q: &[f64]) -> f64 {
    let mut contacts = vec![ContactGeometry::default(); model.info().n_contacts()];
    model.contact_geometry(q, &vec![0.0; q.len()], &mut contacts);
    contacts
        .iter()
        .flat_map(|c| c.position)
        .filter(|x| x.is_finite())
        .fold(1.0_f64, |m, x| m.max(x.abs()))
}

fn validate_model(model: &dyn Dynamics, driven: &[bool], t0: f64) -> Result<(), SimError> {
    let info = model.info();
    let (n, nc) = (info.n(), info.n_constraints());
    let initial = &info.initial;
    if !t0.is_finite() {
        return Err(invalid(format!("t0 = {t0} must be finite")));
    }
    if n == 0 {
        return Err(invalid(format!("{} has no coordinates", info.name)));
    }
    if initial.q.len() != n || initial.qd.len() != n || initial.hold.len() != n {
        return Err(invalid(format!(
            "the initial guess of {} must have {n} entries",
            info.name
        )));
    }
    let free = driven.iter().filter(|d| !**d).count();
    if free < nc {
        return Err(invalid(format!(
            "{}: {nc} constraint equations but only {free} free coordinates",
            info.name
        )));
    }
    Ok(())
}

/// Chooses the coordinates to solve among those neither held nor driven (largest |J_i|)
/// and solves h = 0 for them: for one contact at the root nearest the guess when a scan
/// finds one, otherwise by Newton, then backtracking Newton. Rows of h that are redundant
/// at the guess ([`independent_rows`]) are left out; at the solution the rank is checked
/// again (a guess at a singular position looks redundant without being so) and the rows
/// left out must hold there too.
fn assemble_positions(
    model: &dyn Dynamics,
    ws: &mut Workspace,
    driven: &[bool],
    hold: &[bool],
    t0: f64,
) -> Result<(Vec<usize>, RootChoice), SimError> {
    let info = model.info();
    let (n, m) = (info.n(), info.n_constraints());
    if m == 0 {
        return Ok((Vec::new(), RootChoice::NoContact));
    }
    let solvable: Vec<bool> = (0..n).map(|i| !driven[i] && !hold[i]).collect();
    let mut choice = None;
    for _ in 0..3 {
        ws.evaluate_constraints(model);
        if ws.full_jacobian().iter().any(|x| !x.is_finite()) {
            return Err(ws.non_finite(t0, "J"));
        }
        let floor = ws.jacobian_floor();
        let (rows, _) = independent_rows(ws.full_jacobian(), m, n, &solvable, floor);
        // Only loop equations can be redundant: a contact whose row of J is a combination of
        // the others' (a zero row: the follower point on the axis that moves it) is at a dead
        // point, as a single contact with J_v = 0 is.
        let contacts = info.n_contacts();
        if rows.is_empty() || (0..contacts).any(|k| !rows.contains(&k)) {
            return Err(ws.singular(t0));
        }
        if choice.is_some() && rows.len() <= ws.rows().len() {
            break;
        }
        if rows != ws.rows() {
            *ws = restrict(ws, driven, &rows);
            ws.evaluate_constraints(model);
        }
        choice = Some(solve_rows(model, ws, &solvable, t0)?);
    }
    let choice = choice.ok_or_else(|| ws.singular(t0))?;
    check_left_out(model, ws, t0)?;
    Ok(choice)
}

/// Newton on the rows the workspace solves, from its q (h and J evaluated there).
fn solve_rows(
    model: &dyn Dynamics,
    ws: &mut Workspace,
    solvable: &[bool],
    t0: f64,
) -> Result<(Vec<usize>, RootChoice), SimError> {
    let solved = ws
        .choose_dependent(solvable)
        .ok_or_else(|| ws.singular(t0))?;
    let guess = ws.q().to_vec();
    let on_cam = ws.h.iter().all(|h| h.abs() <= ws.residual_tolerance());
    let single_contact = model.info().n_constraints() == 1;
    let root = match solved.as_slice() {
        _ if on_cam => RootChoice::AtGuess,
        [v] if single_contact => match nearest_root(model, ws, *v) {
            Some((value, distance)) => {
                ws.q[*v] = value;
                RootChoice::Nearest { distance }
            }
            None => RootChoice::Newton { scanned: true },
        },
        _ => RootChoice::Newton { scanned: false },
    };
    if ws.solve_positions(model, &solved, t0).is_err() {
        ws.q.copy_from_slice(&guess);
        if let Err(e) = ws.solve_positions_damped(model, &solved, t0) {
            return Err(open_constraint(model, ws, t0, e));
        }
    }
    Ok((solved, root))
}

/// The error of a failed assembly: with loops, the equation furthest from closing, named.
fn open_constraint(model: &dyn Dynamics, ws: &mut Workspace, t0: f64, error: SimError) -> SimError {
    let info = model.info();
    if info.loops.is_empty() {
        return error;
    }
    ws.evaluate_constraints(model);
    let (row, residual) = worst(ws.full_h(), 0..info.n_constraints());
    SimError::CannotAssemble {
        t: t0,
        q: ws.q().to_vec(),
        residual,
        constraint: info.constraint_name(row),
        why: "Newton from the initial guess, then with backtracking, did not converge: the \
              guess is too far from an assembled configuration, or the dimensions do not \
              allow the loop to close"
            .into(),
    }
}

/// The row of `rows` with the largest |h| and that value.
fn worst(h: &[f64], rows: impl Iterator<Item = usize>) -> (usize, f64) {
    rows.map(|k| (k, h[k].abs())).fold((0, 0.0), |best, x| {
        if x.1 > best.1 || x.1.is_nan() {
            x
        } else {
            best
        }
    })
}

/// The rows left out as redundant must hold at the assembled q: otherwise they were not
/// implied by the others, and the mechanism cannot be assembled with all of them.
fn check_left_out(model: &dyn Dynamics, ws: &mut Workspace, t0: f64) -> Result<(), SimError> {
    let info = model.info();
    let m = info.n_constraints();
    if ws.rows().len() == m {
        return Ok(());
    }
    ws.evaluate_constraints(model);
    let left_out: Vec<usize> = (0..m).filter(|k| !ws.rows().contains(k)).collect();
    let (row, residual) = worst(ws.full_h(), left_out.into_iter());
    // The solved rows hold to Newton's tolerance; a left-out row implied by them holds to
    // the same order (its gradient is a combination of theirs), so 1e3 times the tolerance
    // separates round-off from an equation that is really violated.
    if residual <= 1e3 * ws.residual_tolerance() {
        return Ok(());
    }
    Err(SimError::CannotAssemble {
        t: t0,
        q: ws.q().to_vec(),
        residual,
        constraint: info.constraint_name(row),
        why: "its Jacobian row is a combination of the other rows', so it was left out as \
              redundant, but it does not hold where the others do: the loops contradict \
              each other"
            .into(),
    })
}

/// The root of h (one contact) along coordinate `v` nearest its current value, and its
/// distance from it: h is sampled at [`SCAN_STEPS`] points on each side, out to π for an
/// angle or to the model's length scale for a displacement; the first bracket (the
/// nearer one when both sides change sign at the same distance) is refined by
/// regula falsi. `None` when h changes sign nowhere within reach.
fn nearest_root(model: &dyn Dynamics, ws: &Workspace, v: usize) -> Option<(f64, f64)> {
    let reach = match model.info().coordinates[v].kind {
        JointKind::Revolute => PI,
        JointKind::Prismatic => ws.length_scale(),
    };
    let step = reach / SCAN_STEPS as f64;
    let mut q = ws.q().to_vec();
    let guess = q[v];
    let mut h = [0.0];
    let mut at = |x: f64, q: &mut Vec<f64>| {
        q[v] = x;
        model.constraint(q, &mut h);
        h[0]
    };
    let h0 = at(guess, &mut q);
    if !h0.is_finite() {
        return None;
    }
    let mut last = [(guess, h0), (guess, h0)];
    for k in 1..=SCAN_STEPS {
        let mut found: Option<(f64, f64)> = None;
        for (side, sign) in [1.0, -1.0].into_iter().enumerate() {
            let x = guess + sign * k as f64 * step;
            let hx = at(x, &mut q);
            let (x_prev, h_prev) = last[side];
            if !hx.is_finite() {
                continue;
            }
            if h_prev.is_finite() && (hx == 0.0 || hx.signum() != h_prev.signum()) {
                let root = refine(&mut at, &mut q, (x_prev, h_prev), (x, hx));
                let distance = (root - guess).abs();
                if found.is_none_or(|(_, d)| distance < d) {
                    found = Some((root, distance));
                }
            }
            last[side] = (x, hx);
        }
        if found.is_some() {
            return found;
        }
    }
    None
}

/// A root of h in the bracket [a, b] (h(a), h(b) of opposite signs) by the Illinois
/// variant of regula falsi, to round-off of x (Newton (15) then polishes it).
fn refine(
    h: &mut impl FnMut(f64, &mut Vec<f64>) -> f64,
    q: &mut Vec<f64>,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
) -> f64 {
    if fb == 0.0 {
        return b;
    }
    // Which end was kept by the last step: halving its value when it is kept twice in a
    // row is what keeps regula falsi from converging from one side only.
    let mut kept = 0;
    for _ in 0..200 {
        if (b - a).abs() <= 4.0 * f64::EPSILON * (a.abs().max(b.abs()) + 1.0) {
            break;
        }
        let mut x = (a * fb - b * fa) / (fb - fa);
        if !(x.is_finite() && x > a.min(b) && x < a.max(b)) {
            x = 0.5 * (a + b);
        }
        let fx = h(x, q);
        if fx == 0.0 || !fx.is_finite() {
            return x;
        }
        if fx.signum() == fb.signum() {
            (b, fb) = (x, fx);
            if kept == -1 {
                fa *= 0.5;
            }
            kept = -1;
        } else {
            (a, fa) = (x, fx);
            if kept == 1 {
                fb *= 0.5;
            }
            kept = 1;
        }
    }
    if fa.abs() < fb.abs() { a } else { b }
}
