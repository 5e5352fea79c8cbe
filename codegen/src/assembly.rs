//! Build-time check that the model's initial guess can be assembled onto its cams.
//!
//! The same Newton iteration the runtime performs (docs/method.md §5.9: held and driven coordinates keep
//! their values, one free coordinate per contact is solved from h(q) = 0), run on the
//! symbolic expressions with the interpreter, so a model whose contact point cannot reach
//! its cam fails the build with a clear message instead of failing at run time.

use crate::derive::Derivation;
use crate::model::Model;
use nalgebra::{DMatrix, DVector};

/// Largest residual |h| accepted as "on the cam" (m). Far above the Newton floor (~1e-15)
/// and far below any geometric scale of a model.
const TOLERANCE: f64 = 1e-10;
/// Newton iterations before giving up.
const MAX_ITERATIONS: usize = 50;

/// Solves the free coordinates so every contact holds; returns the assembled q.
pub fn assemble(model: &Model, d: &Derivation) -> Result<Vec<f64>, String> {
    let n = model.n();
    let nc = d.contacts.len();
    let mut q = model.initial.q.clone();
    let qd = vec![0.0; n];
    for drive in &d.drives {
        q[drive.coordinate] = d.eval(&drive.motion[..1], 0.0, &q, &qd)[0];
    }
    if nc == 0 {
        return Ok(q);
    }
    let h_ids: Vec<_> = d.contacts.iter().map(|c| c.h).collect();
    let j_ids: Vec<_> = d
        .contacts
        .iter()
        .flat_map(|c| c.jacobian.iter().copied())
        .collect();
    let free: Vec<bool> = (0..n)
        .map(|i| !model.initial.hold[i] && model.bodies[i].joint.prescribed.is_none())
        .collect();
    let mut residual = f64::INFINITY;
    for _ in 0..MAX_ITERATIONS {
        let h = d.eval(&h_ids, 0.0, &q, &qd);
        residual = h.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if residual <= TOLERANCE {
            return Ok(q);
        }
        let j = d.eval(&j_ids, 0.0, &q, &qd);
        let step = newton_step(&j, &h, n, nc, &free)
            .ok_or_else(|| no_free_column(model, &free, residual, &q))?;
        for (i, dq) in step {
            q[i] -= dq;
        }
        if !q.iter().all(|v| v.is_finite()) {
            break;
        }
    }
    Err(format!(
        "initial state cannot be assembled onto the cam: Newton on the coordinates not held \
         left |h| = {residual:.3e} m after {MAX_ITERATIONS} iterations (q = {q:?}); the contact \
         point cannot reach the cam from this guess: change initial.q or initial.hold"
    ))
}

/// Why Newton cannot take a step: no free coordinate, or none that moves a contact point
/// across its cam.
fn no_free_column(model: &Model, free: &[bool], residual: f64, q: &[f64]) -> String {
    let names: Vec<&str> = model
        .bodies
        .iter()
        .zip(free)
        .filter(|(_, free)| **free)
        .map(|(b, _)| b.joint.coordinate.as_str())
        .collect();
    let why = if names.is_empty() {
        "every coordinate is held or driven, so none can be solved: leave one per contact out \
         of initial.hold"
            .to_string()
    } else {
        format!(
            "the coordinates that are neither held nor driven ({}) do not move the contact \
             point across the cam there (their constraint Jacobian entries are 0): hold other \
             coordinates or change initial.q",
            names.join(", ")
        )
    };
    format!(
        "initial state cannot be assembled onto the cam: |h| = {residual:.3e} m at q = {q:?}, \
         and {why}"
    )
}

/// One Newton step on the free columns with the largest pivots; returns (index, Δq) pairs
/// with q ← q − Δq.
fn newton_step(
    j: &[f64],
    h: &[f64],
    n: usize,
    nc: usize,
    free: &[bool],
) -> Option<Vec<(usize, f64)>> {
    let cols = pick_columns(j, n, nc, free)?;
    let a = DMatrix::from_fn(nc, nc, |r, c| j[r * n + cols[c]]);
    let b = DVector::from_column_slice(h);
    let x = a.lu().solve(&b)?;
    if !x.iter().all(|v| v.is_finite()) {
        return None;
    }
    Some(cols.into_iter().zip(x.iter().copied()).collect())
}

/// Greedy choice of one free column per constraint row, largest |J| first.
fn pick_columns(j: &[f64], n: usize, nc: usize, free: &[bool]) -> Option<Vec<usize>> {
    let mut chosen = Vec::with_capacity(nc);
    for r in 0..nc {
        let best = (0..n)
            .filter(|&i| free[i] && !chosen.contains(&i))
            .max_by(|&a, &b| j[r * n + a].abs().total_cmp(&j[r * n + b].abs()))?;
        if j[r * n + best] == 0.0 {
            return None;
        }
        chosen.push(best);
    }
    Some(chosen)
}
