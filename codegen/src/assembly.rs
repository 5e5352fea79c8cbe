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

/// Solves the free coordinates so every contact holds; returns the assembled q. A model with
/// loops goes through `assemble_with_loops` (the message then names the loop furthest from
/// closing; [`assemble_located`] also gives its field).
pub fn assemble(model: &Model, d: &Derivation) -> Result<Vec<f64>, String> {
    assemble_located(model, d).map_err(|(_, message)| message)
}

/// [`assemble`] with the field the problem is located at: `initial`, or `loops[k]`.
pub fn assemble_located(model: &Model, d: &Derivation) -> Result<Vec<f64>, (String, String)> {
    if model.loops.is_empty() {
        assemble_contacts(model, d).map_err(|m| ("initial".to_string(), m))
    } else {
        assemble_with_loops(model, d)
    }
}

/// A model with loops: Gauss–Newton on every row of h (contacts and loops) over the
/// coordinates neither held nor driven, each step the least-norm solution through the
/// singular value decomposition with the singular values below 1e-10 of the largest left
/// out, so that redundant loop equations (a Bricard mechanism, a parallelogram with a third
/// bar) and more coordinates than equations are both handled. Fails with the loop (or
/// contact) furthest from closing, located at its field.
fn assemble_with_loops(model: &Model, d: &Derivation) -> Result<Vec<f64>, (String, String)> {
    let n = model.n();
    let mut q = model.initial.q.clone();
    let qd = vec![0.0; n];
    for drive in &d.drives {
        q[drive.coordinate] = d.eval(&drive.motion[..1], 0.0, &q, &qd)[0];
    }
    let rows = d.constraint_rows();
    let h_ids: Vec<_> = rows.iter().map(|r| r.0).collect();
    let j_ids: Vec<_> = rows.iter().flat_map(|r| r.1.iter().copied()).collect();
    let m = h_ids.len();
    let free: Vec<usize> = (0..n)
        .filter(|&i| !model.initial.hold[i] && model.bodies[i].joint.prescribed.is_none())
        .collect();
    if free.is_empty() {
        return Err((
            "initial.hold".to_string(),
            format!(
                "the mechanism cannot be assembled: every coordinate is held or driven, so none \
                 can be solved to close its {} loop equation{}: leave some out of initial.hold",
                m,
                if m == 1 { "" } else { "s" }
            ),
        ));
    }
    let mut h = d.eval(&h_ids, 0.0, &q, &qd);
    if let Some(error) = not_finite(model, &h, &q) {
        return Err(("initial".to_string(), error));
    }
    for _ in 0..MAX_ITERATIONS {
        let residual = largest(&h);
        if residual <= TOLERANCE {
            return Ok(q);
        }
        let j = d.eval(&j_ids, 0.0, &q, &qd);
        let a = DMatrix::from_fn(m, free.len(), |r, c| j[r * n + free[c]]);
        if free.is_empty() || !a.iter().all(|v| v.is_finite()) {
            break;
        }
        let svd = a.svd(true, true);
        let cut = 1e-10 * svd.singular_values.max();
        let Ok(step) = svd.solve(&DVector::from_column_slice(&h), cut) else {
            break;
        };
        // Backtracking on |h|: a full step from far off can overshoot onto the other branch.
        let before: f64 = h.iter().map(|x| x * x).sum();
        let mut fraction = 1.0;
        let start = q.clone();
        loop {
            for (k, &i) in free.iter().enumerate() {
                q[i] = start[i] - fraction * step[k];
            }
            h = d.eval(&h_ids, 0.0, &q, &qd);
            let after: f64 = h.iter().map(|x| x * x).sum();
            if after.is_finite() && (after < before || fraction < 1e-6) {
                break;
            }
            fraction *= 0.5;
        }
    }
    let (row, residual) = h
        .iter()
        .enumerate()
        .map(|(k, v)| (k, v.abs()))
        .fold(
            (0, 0.0),
            |b, x| if x.1 > b.1 || x.1.is_nan() { x } else { b },
        );
    let nc = model.contacts.len();
    let (field, what) = if row < nc {
        (
            "initial".to_string(),
            format!("contact {}", model.contacts[row].name),
        )
    } else {
        let mut first = nc;
        let mut located = ("loops".to_string(), String::from("a loop"));
        for (l, cut) in model.loops.iter().enumerate() {
            let count = cut.equations().len();
            if row < first + count {
                located = (
                    format!("loops[{l}]"),
                    format!(
                        "loop `{}` (equation {})",
                        cut.name,
                        cut.equations()[row - first]
                    ),
                );
                break;
            }
            first += count;
        }
        located
    };
    Err((
        field,
        format!(
            "the mechanism cannot be assembled: {what} is still {residual:.3e} from closing after \
             {MAX_ITERATIONS} Gauss-Newton iterations from the initial guess q = {q:?}; the \
             lengths do not let the loop close, or the guess is too far from a closed \
             configuration: check the loop's points and lengths, or change initial.q"
        ),
    ))
}

/// The largest |v|: NaN when any value is NaN (a plain `max` fold would skip it and call a
/// profile that is not defined "closed").
fn largest(values: &[f64]) -> f64 {
    values.iter().fold(0.0f64, |a, v| {
        if v.is_nan() || a.is_nan() {
            f64::NAN
        } else {
            a.max(v.abs())
        }
    })
}

/// A message when a constraint value or derivative at the initial guess is not a number:
/// the profile (or a loop's geometry) is not defined there.
fn not_finite(model: &Model, values: &[f64], q: &[f64]) -> Option<String> {
    not_finite_at(model, values, q, "at the initial guess")
}

/// [`not_finite`] at the configuration `at` describes (`at the initial guess`, `after 2
/// Newton steps from the initial guess, at`).
fn not_finite_at(model: &Model, values: &[f64], q: &[f64], at: &str) -> Option<String> {
    let bad = values.iter().find(|v| !v.is_finite())?;
    let profiles: Vec<String> = model
        .contacts
        .iter()
        .map(|c| format!("contact `{}`", c.name))
        .collect();
    Some(format!(
        "the constraints are {bad} {at} q = {q:?}: a profile or a length is \
         not defined there (a division by zero, a logarithm or square root of a negative \
         number, a value beyond f64's range); check the profiles of {} and initial.q",
        if profiles.is_empty() {
            "the loops".to_string()
        } else {
            profiles.join(", ")
        }
    ))
}

/// [`assemble`] for a model without loops.
fn assemble_contacts(model: &Model, d: &Derivation) -> Result<Vec<f64>, String> {
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
    let free_count = free.iter().filter(|f| **f).count();
    if free_count < nc {
        return Err(format!(
            "initial state cannot be assembled onto the cams: {} neither held nor driven, and \
             {free_count} {} free: leave more out of initial.hold",
            if nc == 1 {
                "1 contact needs a coordinate that is".to_string()
            } else {
                format!("{nc} contacts need one coordinate each that is")
            },
            if free_count == 1 { "is" } else { "are" }
        ));
    }
    let mut residual = f64::INFINITY;
    for iteration in 0..MAX_ITERATIONS {
        let h = d.eval(&h_ids, 0.0, &q, &qd);
        let j = d.eval(&j_ids, 0.0, &q, &qd);
        let at = match iteration {
            0 => "at the initial guess".to_string(),
            k => format!("after {k} Newton steps from the initial guess, at"),
        };
        if let Some(error) =
            not_finite_at(model, &h, &q, &at).or_else(|| not_finite_at(model, &j, &q, &at))
        {
            return Err(error);
        }
        residual = largest(&h);
        if residual <= TOLERANCE {
            // On the cams; the run must also be able to choose one dependent coordinate
            // per contact there (the runtime's partition needs an invertible J_v).
            return match newton_step(&j, &h, n, nc, &free) {
                Some(_) => Ok(q),
                None => Err(dependent_contacts(model, &j, &free, residual, &q)
                    .unwrap_or_else(|| no_free_column(model, &free, residual, &q))),
            };
        }
        let step = newton_step(&j, &h, n, nc, &free).ok_or_else(|| {
            dependent_contacts(model, &j, &free, residual, &q)
                .unwrap_or_else(|| no_free_column(model, &free, residual, &q))
        })?;
        // A full step may leave the region where the profiles are defined (a square root's
        // argument turning negative past a sphere's pole): halve it until they are.
        let mut fraction = 1.0;
        let next = loop {
            let mut next = q.clone();
            for &(i, dq) in &step {
                next[i] -= fraction * dq;
            }
            let defined = next.iter().all(|v| v.is_finite())
                && d.eval(&h_ids, 0.0, &next, &qd)
                    .iter()
                    .all(|v| v.is_finite());
            if defined || fraction < 1e-12 {
                break next;
            }
            fraction *= 0.5;
        };
        q = next;
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

/// Two contacts whose constraint rows, restricted to the free coordinates, are parallel
/// (they ask for the same motion: two contacts at one point, or on one cam through the same
/// mechanism), which no choice of coordinates can solve; `None` when there are no such two.
fn dependent_contacts(
    model: &Model,
    j: &[f64],
    free: &[bool],
    residual: f64,
    q: &[f64],
) -> Option<String> {
    let n = model.n();
    let nc = model.contacts.len();
    let row =
        |k: usize| -> Vec<f64> { (0..n).filter(|&i| free[i]).map(|i| j[k * n + i]).collect() };
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    for a in 0..nc {
        for b in a + 1..nc {
            let (ra, rb) = (row(a), row(b));
            let (na, nb) = (norm(&ra), norm(&rb));
            if na == 0.0 || nb == 0.0 {
                continue;
            }
            let cosine = ra.iter().zip(&rb).map(|(x, y)| x * y).sum::<f64>() / (na * nb);
            if cosine.abs() > 1.0 - 1e-9 {
                let (first, second) = (&model.contacts[a].name, &model.contacts[b].name);
                return Some(format!(
                    "initial state cannot be assembled onto the cams: |h| = {residual:.3e} m at \
                     q = {q:?}, and contacts {first} and {second} constrain the same motion \
                     (their constraint rows are parallel: two contacts at one point?), so no \
                     choice of coordinates can satisfy both: remove one, or move its marker"
                ));
            }
        }
    }
    None
}

/// One Newton step on the free coordinates: the least-norm Δq with J_free Δq = h (through
/// the singular value decomposition of J restricted to the free columns); returns
/// (index, Δq) pairs with q ← q − Δq. `None` when J_free does not have full row rank (a
/// singular value below 1e-12 of the largest, or of 1 m when all are smaller): no choice of one free
/// coordinate per contact can be solved there.
fn newton_step(
    j: &[f64],
    h: &[f64],
    n: usize,
    nc: usize,
    free: &[bool],
) -> Option<Vec<(usize, f64)>> {
    let cols: Vec<usize> = (0..n).filter(|&i| free[i]).collect();
    if cols.len() < nc {
        return None;
    }
    let a = DMatrix::from_fn(nc, cols.len(), |r, c| j[r * n + cols[c]]);
    if !a.iter().all(|v| v.is_finite()) {
        return None;
    }
    let svd = a.svd(true, true);
    let largest = svd.singular_values.max();
    let smallest = svd.singular_values.min();
    if smallest <= 1e-12 * largest.max(1.0) {
        return None;
    }
    let b = DVector::from_column_slice(h);
    let x = svd.solve(&b, 0.0).ok()?;
    if !x.iter().all(|v| v.is_finite()) {
        return None;
    }
    Some(cols.into_iter().zip(x.iter().copied()).collect())
}
