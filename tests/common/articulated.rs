//! The articulated-body functions of a generated model ([`Dynamics::articulated_terms`],
//! [`Dynamics::articulated_response`]) checked against another model's M, F and Q at the
//! same state: the numeric reference's, or the same model's dense code. Checked by backward
//! error (the residual of the equations the sweeps solve, relative to the size of their
//! terms), which does not depend on the conditioning of M.

use camchain::runtime::{ArticulatedTerms, Dynamics};

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
    worst
}
