//! The articulated-body functions of a generated model ([`Dynamics::articulated_terms`],
//! [`Dynamics::articulated_response`]) checked against another model's M, F and Q at the
//! same state: the numeric reference's, or the same model's dense code. Checked by backward
//! error (the residual of the equations the sweeps solve, relative to the size of their
//! terms), which does not depend on the conditioning of M.

use camchain::runtime::{ArticulatedTerms, Dynamics, SolvedRow};

/// The largest relative residual of the articulated functions of `generated` in the
/// equations of `dense` at (q, q̇, t), with prescribed accelerations and a generalised force
/// drawn from `draw`; 0 when `generated` has no articulated functions.
pub fn articulated_residual(
    generated: &dyn Dynamics,
    dense: &dyn Dynamics,
    (q, qd, t): (&[f64], &[f64], f64),
    draw: &mut dyn FnMut() -> f64,
) -> f64 {
    if generated.articulated_len() == 0 {
        return 0.0;
    }
    let info = generated.info();
    let (n, m) = (info.n(), info.n_constraints());
    let driven: Vec<bool> = info.coordinates.iter().map(|c| c.driven).collect();
    let mut qdd: Vec<f64> = (0..n).map(|_| 3.0 * draw()).collect();
    let mut drive = vec![0.0; n];
    let mut bias = vec![0.0; m];
    let mut factors = vec![f64::NAN; generated.articulated_len()];
    let (mut h, mut j) = (vec![0.0; m], vec![0.0; m * n]);
    let mut cache = vec![f64::NAN; generated.cache_len()];
    generated.position_terms(q, &mut h, &mut j, &mut cache);
    generated.articulated_terms(
        t,
        q,
        qd,
        &cache,
        ArticulatedTerms {
            qdd: &mut qdd,
            drive: &mut drive,
            bias: &mut bias,
            factors: &mut factors,
            row: &[],
            solved: &mut SolvedRow::default(),
        },
    );
    let (mut mass, mut f, mut applied) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
    dense.equations(t, q, qd, &mut mass, &mut f, &mut applied);
    let mut c = vec![0.0; m];
    dense.constraint_bias(q, qd, &mut c);
    let mut worst: f64 = 0.0;
    // c as velocity_terms gives it.
    for (a, b) in bias.iter().zip(&c) {
        worst = worst.max((a - b).abs() / b.abs().max(1.0));
    }
    // Free rows: M q̈ + F + Q = 0; driven rows: the load is M q̈ + F + Q.
    for i in 0..n {
        let row = &mass[i * n..(i + 1) * n];
        let terms: Vec<f64> = row.iter().zip(&qdd).map(|(a, b)| a * b).collect();
        let size = terms.iter().map(|x| x.abs()).sum::<f64>() + f[i].abs() + applied[i].abs();
        let residual = terms.iter().sum::<f64>() + f[i] + applied[i];
        let off = if driven[i] {
            residual - drive[i]
        } else {
            residual
        };
        worst = worst.max(off.abs() / size.max(1.0));
    }
    // The response: M_ff x = τ_f, and its driven rows M_df x.
    let tau: Vec<f64> = (0..n).map(|_| draw()).collect();
    let (mut x, mut loads) = (vec![f64::NAN; n], vec![f64::NAN; n]);
    generated.articulated_response(&factors, &tau, &mut x, &mut loads);
    for i in 0..n {
        if driven[i] {
            x[i] = 0.0;
        }
    }
    for i in 0..n {
        let row = &mass[i * n..(i + 1) * n];
        let terms: Vec<f64> = row.iter().zip(&x).map(|(a, b)| a * b).collect();
        let size = terms.iter().map(|v| v.abs()).sum::<f64>() + tau[i].abs();
        let product: f64 = terms.iter().sum();
        let off = if driven[i] {
            product - loads[i]
        } else {
            product - tau[i]
        };
        worst = worst.max(off.abs() / size.max(1.0));
    }
    if generated.articulated_rows() == 1 {
        worst = worst.max(solved_row_residual(
            generated,
            (q, qd, t),
            &cache,
            (&driven, &qdd),
            (&mass, &f, &applied, c[0]),
            &j,
        ));
    }
    worst
}

/// The row solved within the sweeps (docs/method.md §14.6) in the dense equations: with
/// the row J given, M q̈ + F + Q + Jᵀ λ = 0 on the free rows and the drive loads on the
/// driven ones, J q̈ + c = 0, and J_f M_ff⁻¹ J_fᵀ the response's J_f x (x = M_ff⁻¹ J_fᵀ).
/// `unconstrained`: q̈ without the row's force (the free entries) and the prescribed q̈ (the
/// `driven` ones).
fn solved_row_residual(
    generated: &dyn Dynamics,
    (q, qd, t): (&[f64], &[f64], f64),
    cache: &[f64],
    (driven, unconstrained): (&[bool], &[f64]),
    (mass, f, applied, c): (&[f64], &[f64], &[f64], f64),
    row: &[f64],
) -> f64 {
    let n = q.len();
    let mut qdd: Vec<f64> = (0..n)
        .map(|i| if driven[i] { unconstrained[i] } else { 0.0 })
        .collect();
    let (mut drive, mut bias) = (vec![0.0; n], vec![0.0; 1]);
    let mut factors = vec![f64::NAN; generated.articulated_len()];
    let mut solved = SolvedRow::default();
    generated.articulated_terms(
        t,
        q,
        qd,
        cache,
        ArticulatedTerms {
            qdd: &mut qdd,
            drive: &mut drive,
            bias: &mut bias,
            factors: &mut factors,
            row,
            solved: &mut solved,
        },
    );
    // Without factors (the runtime passes none when it will not call the response): the
    // same q̈, drive loads, c, λ and J M_ff⁻¹ Jᵀ, bit for bit.
    let (mut qdd_bare, mut drive_bare, mut bias_bare) = (qdd.clone(), vec![0.0; n], vec![0.0; 1]);
    for i in (0..n).filter(|&i| !driven[i]) {
        qdd_bare[i] = 0.0;
    }
    let mut solved_bare = SolvedRow::default();
    generated.articulated_terms(
        t,
        q,
        qd,
        cache,
        ArticulatedTerms {
            qdd: &mut qdd_bare,
            drive: &mut drive_bare,
            bias: &mut bias_bare,
            factors: &mut [],
            row,
            solved: &mut solved_bare,
        },
    );
    assert_eq!((&qdd_bare, &drive_bare, &bias_bare), (&qdd, &drive, &bias));
    assert_eq!(solved_bare, solved);
    let lambda = solved.lambda;
    let mut worst: f64 = 0.0;
    for i in 0..n {
        let m_row = &mass[i * n..(i + 1) * n];
        let terms: Vec<f64> = m_row.iter().zip(&qdd).map(|(a, b)| a * b).collect();
        let size = terms.iter().map(|x| x.abs()).sum::<f64>()
            + f[i].abs()
            + applied[i].abs()
            + (row[i] * lambda).abs();
        let residual = terms.iter().sum::<f64>() + f[i] + applied[i] + row[i] * lambda;
        let off = if driven[i] {
            residual - drive[i]
        } else {
            residual
        };
        worst = worst.max(off.abs() / size.max(1.0));
    }
    // J_f M_ff⁻¹ J_fᵀ by the response.
    let tau: Vec<f64> = (0..n)
        .map(|i| if driven[i] { 0.0 } else { row[i] })
        .collect();
    let (mut x, mut loads) = (vec![f64::NAN; n], vec![f64::NAN; n]);
    generated.articulated_response(&factors, &tau, &mut x, &mut loads);
    // The velocity constraint's second derivative, relative to the terms q̈ = q̈⁰ − λ x is
    // made of (it cancels where the contact force dominates q̈).
    let terms: Vec<f64> = row.iter().zip(&qdd).map(|(a, b)| a * b).collect();
    let size = (0..n)
        .map(|i| {
            let parts = if driven[i] {
                unconstrained[i].abs()
            } else {
                unconstrained[i].abs() + (lambda * x[i]).abs()
            };
            (row[i] * parts).abs()
        })
        .sum::<f64>()
        + c.abs();
    worst = worst.max((terms.iter().sum::<f64>() + c).abs() / size.max(1.0));
    let free = || (0..n).filter(|&i| !driven[i]);
    let delassus: f64 = free().map(|i| tau[i] * x[i]).sum();
    let size: f64 = free().map(|i| (tau[i] * x[i]).abs()).sum();
    worst.max((delassus - solved.delassus).abs() / size.max(1e-300))
}
