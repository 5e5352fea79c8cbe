//! The generated functions one call each, for a user's own integrator or controller:
//! `equations`, `constraint`, `jacobian`, `bias`, `rhs`.
//!
//! Conventions (docs/method.md §3–5): M(q) q̈ + F(q, q̇) + Q(q, q̇, t) = 0 for the free tree
//! (13); with the constraints h(q) = 0, J q̈ + c = 0 (7, 8) and the multipliers,
//! M q̈ + F + Q + Jᵀλ = τ (14), τ the drives' loads (non-zero on driven coordinates only).

use crate::errors::bad_option;
use crate::model::Model;
use camchain_runtime::Dynamics;
use nalgebra::{DMatrix, DVector};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::prelude::*;

/// A vector argument of length `n`: a float64 numpy array without a copy when it is
/// contiguous, anything else numpy-like or a sequence of numbers otherwise.
fn vector(value: &Bound<'_, PyAny>, n: usize, name: &str) -> PyResult<Vec<f64>> {
    let values: Vec<f64> = match value.extract::<PyReadonlyArray1<f64>>() {
        Ok(array) => match array.as_slice() {
            Ok(slice) => slice.to_vec(),
            Err(_) => array.as_array().to_vec(),
        },
        Err(_) => value
            .extract()
            .map_err(|_| bad_option(name, "expected a sequence of numbers"))?,
    };
    if values.len() != n {
        return Err(bad_option(
            name,
            format!("has {} entries, the model {n}", values.len()),
        ));
    }
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Err(bad_option(
            name,
            format!("entry {k} is {}, not a finite number", values[k]),
        ));
    }
    Ok(values)
}

fn matrix<'py>(
    py: Python<'py>,
    rows: usize,
    columns: usize,
    data: Vec<f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let array =
        Array2::from_shape_vec((rows, columns), data).map_err(|e| bad_option("matrix", e))?;
    Ok(array.into_pyarray(py))
}

/// The constrained accelerations at (t, q, q̇), every contact closed: the driven coordinates'
/// from their drives, the others and λ from (14) with J q̈ + c = 0, solved densely (least
/// squares through an SVD when rows are redundant).
fn accelerations(model: &dyn Dynamics, t: f64, q: &[f64], qd: &[f64]) -> Result<Vec<f64>, String> {
    let info = model.info();
    let (n, m) = (info.n(), info.n_constraints());
    let (mut mass, mut f, mut applied) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
    model.equations(t, q, qd, &mut mass, &mut f, &mut applied);
    let (mut j, mut c) = (vec![0.0; m * n], vec![0.0; m]);
    model.constraint_terms(q, qd, &mut j, &mut c);
    let mut qdd = vec![0.0; n];
    let (mut qp, mut qdp) = (q.to_vec(), qd.to_vec());
    model.prescribed(t, &mut qp, &mut qdp, &mut qdd);
    let free: Vec<usize> = (0..n).filter(|&i| !info.coordinates[i].driven).collect();
    let driven: Vec<usize> = (0..n).filter(|&i| info.coordinates[i].driven).collect();
    let size = free.len() + m;
    let mut a = DMatrix::<f64>::zeros(size, size);
    let mut b = DVector::<f64>::zeros(size);
    for (r, &i) in free.iter().enumerate() {
        for (s, &k) in free.iter().enumerate() {
            a[(r, s)] = mass[i * n + k];
        }
        for row in 0..m {
            a[(r, free.len() + row)] = j[row * n + i];
            a[(free.len() + row, r)] = j[row * n + i];
        }
        b[r] = -f[i]
            - applied[i]
            - driven
                .iter()
                .map(|&d| mass[i * n + d] * qdd[d])
                .sum::<f64>();
    }
    for row in 0..m {
        b[free.len() + row] =
            -c[row] - driven.iter().map(|&d| j[row * n + d] * qdd[d]).sum::<f64>();
    }
    // Terms that are not finite (a singular position of the model) cannot be solved, and
    // an SVD of them would not end.
    if !(a.iter().all(|v| v.is_finite()) && b.iter().all(|v| v.is_finite())) {
        return Err(format!(
            "the equations are not finite at t = {t} s, q = {q:?}, q̇ = {qd:?}"
        ));
    }
    let x = match a.clone().lu().solve(&b) {
        Some(x) if x.iter().all(|v| v.is_finite()) => x,
        _ => {
            let scale = a.amax().max(f64::MIN_POSITIVE);
            a.svd(true, true)
                .solve(&b, 1e-12 * scale)
                .map_err(|e| format!("the constrained system cannot be solved: {e}"))?
        }
    };
    for (r, &i) in free.iter().enumerate() {
        qdd[i] = x[r];
    }
    Ok(qdd)
}

/// The bodies of the `Model` methods of the same names (one `#[pymethods]` block per class:
/// `model.rs` holds it and calls these).
impl Model {
    /// (M, F, Q) of the tree's equations of motion M q̈ + F + Q = 0 (13) at (q, q̇, t):
    /// M an n×n array, F and Q length-n arrays (float64).
    pub(crate) fn equations_of<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
        t: f64,
    ) -> PyResult<crate::model::Equations<'py>> {
        let model = self.engine.get();
        let n = model.info().n();
        let (q, qd) = (vector(q, n, "q")?, vector(qd, n, "qd")?);
        let (mut mass, mut f, mut applied) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
        model.equations(t, &q, &qd, &mut mass, &mut f, &mut applied);
        Ok((
            matrix(py, n, n, mass)?,
            PyArray1::from_vec(py, f),
            PyArray1::from_vec(py, applied),
        ))
    }

    /// h(q): the contacts' rows, then every loop's (length m).
    pub(crate) fn constraint_of<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let model = self.engine.get();
        let info = model.info();
        let q = vector(q, info.n(), "q")?;
        let mut h = vec![0.0; info.n_constraints()];
        model.constraint(&q, &mut h);
        Ok(PyArray1::from_vec(py, h))
    }

    /// J(q) = ∂h/∂q, an m×n array.
    pub(crate) fn jacobian_of<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let model = self.engine.get();
        let info = model.info();
        let (n, m) = (info.n(), info.n_constraints());
        let q = vector(q, n, "q")?;
        let mut j = vec![0.0; m * n];
        model.constraint_jacobian(&q, &mut j);
        matrix(py, m, n, j)
    }

    /// c(q, q̇) of J q̈ + c = 0 (7, 8), length m.
    pub(crate) fn bias_of<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let model = self.engine.get();
        let info = model.info();
        let (q, qd) = (vector(q, info.n(), "q")?, vector(qd, info.n(), "qd")?);
        let mut c = vec![0.0; info.n_constraints()];
        model.constraint_bias(&q, &qd, &mut c);
        Ok(PyArray1::from_vec(py, c))
    }

    /// dy/dt for y = (q, q̇) (length 2n), as scipy's `solve_ivp(m.rhs, …)` wants it: (q̇, q̈)
    /// with q̈ the constrained accelerations, every contact closed (bilateral), the driven
    /// coordinates following their drives. No projection onto h = 0: an integrator of its
    /// own drifts off the constraint at its own error (`simulate` partitions and does not).
    pub(crate) fn rhs_of<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        y: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let model = self.engine.get();
        let n = model.info().n();
        let y = vector(y, 2 * n, "y")?;
        let (q, qd) = y.split_at(n);
        let qdd = accelerations(model, t, q, qd).map_err(|e| bad_option("y", e))?;
        let mut dy = qd.to_vec();
        dy.extend(qdd);
        Ok(PyArray1::from_vec(py, dy))
    }
}
