//! The articulated-body terms against M, F and Q of the same derivation (composite inertias
//! and the backward recursion, an independent route), evaluated by the interpreter: the free
//! accelerations must solve M_ff q̈_f = −(F + Q)_f − M_fd q̈_d, the drive loads be the driven
//! rows of M q̈ + F + Q, and the response be M_ff⁻¹ τ_f with driven rows M_df M_ff⁻¹ τ_f.

use crate::derive::Derivation;
use crate::expr::Id;
use nalgebra::{DMatrix, DVector};
use std::path::Path;

fn model(name: &str) -> crate::model::Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../models/{name}.ron"));
    let text = std::fs::read_to_string(&path).expect("the built-in model file exists");
    crate::schema::parse_model(&text, &path).expect("the built-in model is valid")
}

/// A deterministic value in [−1, 1) for index k of stream `seed`.
fn number(seed: u64, k: usize) -> f64 {
    let mut x = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add((k as u64).wrapping_mul(1442695040888963407).wrapping_add(1));
    x ^= x >> 33;
    x = x.wrapping_mul(0xff51afd7ed558ccd);
    x ^= x >> 33;
    (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// The largest relative difference between the articulated terms and the dense route at a
/// pseudo-random state.
fn check(name: &str, seed: u64) -> f64 {
    check_model(&model(name), seed)
}

/// [`check`] on a model given.
fn check_model(m: &crate::model::Model, seed: u64) -> f64 {
    let d = Derivation::new(m);
    let n = m.n();
    let a = &d.articulated;
    let q: Vec<f64> = (0..n).map(|i| number(seed, i)).collect();
    let qd: Vec<f64> = (0..n).map(|i| 2.0 * number(seed + 1, i)).collect();
    let t = 0.3;
    let mut vars = d.variables(t, &q, &qd);
    let mut qdd = vec![0.0; n];
    let set = |vars: &mut Vec<f64>, id: Id, v: f64| {
        if let crate::expr::Node::Var(k) = d.graph.node(id) {
            vars[k as usize] = v;
        }
    };
    for (k, &(i, var)) in a.driven.iter().enumerate() {
        qdd[i] = 3.0 * number(seed + 2, k);
        set(&mut vars, var, qdd[i]);
    }
    let tau: Vec<f64> = (0..n).map(|i| number(seed + 3, i)).collect();
    for (&var, &v) in a.tau.iter().zip(&tau) {
        set(&mut vars, var, v);
    }
    let eval = |roots: &[Id]| d.graph.eval(roots, &vars);
    let mass: Vec<Id> = d.dynamics.mass.iter().flatten().copied().collect();
    let mass = DMatrix::from_row_slice(n, n, &eval(&mass));
    let f = eval(&d.dynamics.inertial);
    let qv = eval(&d.dynamics.applied);
    let free: Vec<usize> = (0..n)
        .filter(|i| !a.driven.iter().any(|d| d.0 == *i))
        .collect();
    let driven: Vec<usize> = a.driven.iter().map(|d| d.0).collect();
    let m_ff = DMatrix::from_fn(free.len(), free.len(), |r, c| mass[(free[r], free[c])]);
    let rhs = DVector::from_fn(free.len(), |r, _| {
        let i = free[r];
        -(f[i] + qv[i]) - driven.iter().map(|&j| mass[(i, j)] * qdd[j]).sum::<f64>()
    });
    let lu = m_ff.clone().lu();
    let expected = lu.solve(&rhs).expect("M_ff is invertible");
    for (r, &i) in free.iter().enumerate() {
        qdd[i] = expected[r];
    }
    let scale = |x: &[f64]| x.iter().fold(1.0f64, |s, v| s.max(v.abs()));
    let mut worst: f64 = 0.0;
    let got: Vec<f64> = eval(&a.accelerations.iter().map(|x| x.1).collect::<Vec<_>>());
    assert_eq!(got.len(), free.len());
    let s = scale(expected.as_slice());
    for (r, g) in got.iter().enumerate() {
        worst = worst.max((g - expected[r]).abs() / s);
    }
    let loads = eval(&a.drive_loads.iter().map(|x| x.1).collect::<Vec<_>>());
    let rows: Vec<f64> = driven
        .iter()
        .map(|&i| (0..n).map(|j| mass[(i, j)] * qdd[j]).sum::<f64>() + f[i] + qv[i])
        .collect();
    let s = scale(&rows);
    for (g, e) in loads.iter().zip(&rows) {
        worst = worst.max((g - e).abs() / s);
    }
    let tau_f = DVector::from_fn(free.len(), |r, _| tau[free[r]]);
    let response = lu.solve(&tau_f).expect("M_ff is invertible");
    let got = eval(&a.response.iter().map(|x| x.1).collect::<Vec<_>>());
    let s = scale(response.as_slice());
    for (r, g) in got.iter().enumerate() {
        worst = worst.max((g - response[r]).abs() / s);
    }
    let loads = eval(&a.response_loads.iter().map(|x| x.1).collect::<Vec<_>>());
    let rows: Vec<f64> = driven
        .iter()
        .map(|&i| {
            (0..free.len())
                .map(|r| mass[(i, free[r])] * response[r])
                .sum()
        })
        .collect();
    let s = scale(&rows);
    for (g, e) in loads.iter().zip(&rows) {
        worst = worst.max((g - e).abs() / s);
    }
    if let Some((l, dl)) = a.row_solution {
        // The row solved within the sweeps, with J and c of the model's own row, against the
        // Schur complement of the dense system [[M_ff, J_fᵀ], [J_f, 0]].
        let (_, jacobian, bias) = d.constraint_rows()[0];
        let j = eval(jacobian);
        let c = eval(&[bias])[0];
        // The c the sweeps compute (a contact's from a⁰, gravity included) is the contact's.
        let swept = eval(&[a.row_bias.expect("the row's c")])[0];
        worst = worst.max((swept - c).abs() / c.abs().max(1.0));
        for (&var, &v) in a.row.iter().zip(&j) {
            set(&mut vars, var, v);
        }
        set(&mut vars, a.row_weight.expect("with the row"), 1.0);
        let x0 = &expected;
        let j_f = DVector::from_fn(free.len(), |r, _| j[free[r]]);
        let along = lu.solve(&j_f).expect("M_ff is invertible");
        let delassus = j_f.dot(&along);
        let driven_part: f64 = driven.iter().map(|&i| j[i] * qdd[i]).sum();
        let lambda = (j_f.dot(x0) + driven_part + c) / delassus;
        let solved = x0 - &along * lambda;
        let eval = |roots: &[Id]| d.graph.eval(roots, &vars);
        let got = eval(&[l, dl]);
        worst = worst.max((got[0] - lambda).abs() / lambda.abs().max(1.0));
        worst = worst.max((got[1] - delassus).abs() / delassus.abs());
        let got = eval(
            &a.solved_accelerations
                .iter()
                .map(|x| x.1)
                .collect::<Vec<_>>(),
        );
        let s = scale(solved.as_slice());
        for (r, g) in got.iter().enumerate() {
            worst = worst.max((g - solved[r]).abs() / s);
        }
        for (r, &i) in free.iter().enumerate() {
            qdd[i] = solved[r];
        }
        let loads = eval(&a.solved_drive_loads.iter().map(|x| x.1).collect::<Vec<_>>());
        let rows: Vec<f64> = driven
            .iter()
            .map(|&i| {
                (0..n).map(|k| mass[(i, k)] * qdd[k]).sum::<f64>() + f[i] + qv[i] + j[i] * lambda
            })
            .collect();
        let s = scale(&rows);
        for (g, e) in loads.iter().zip(&rows) {
            worst = worst.max((g - e).abs() / s);
        }
        // Without the row (weight 0, J zero): the free accelerations, λ = 0.
        for &var in &a.row {
            set(&mut vars, var, 0.0);
        }
        set(&mut vars, a.row_weight.expect("with the row"), 0.0);
        let eval = |roots: &[Id]| d.graph.eval(roots, &vars);
        assert_eq!(eval(&[l])[0], 0.0, "{}: λ without the row", m.name);
        let got = eval(
            &a.solved_accelerations
                .iter()
                .map(|x| x.1)
                .collect::<Vec<_>>(),
        );
        let s = scale(x0.as_slice());
        for (r, g) in got.iter().enumerate() {
            worst = worst.max((g - x0[r]).abs() / s);
        }
    }
    worst
}

#[test]
fn the_articulated_sweeps_solve_the_dense_equations() {
    // Planar and spatial chains, prismatic joints, driven joints (the cams' shafts), joint
    // loads (andrews_squeezer's motor and spring), loops' trees (four_bar). Round-off of an
    // LU solve of M_ff and of the sweeps, both O(n) deep at n ≤ 8: 1e-12 of the scale.
    for name in [
        "double_pendulum",
        "paper_concave",
        "spatial_arm",
        "driven_concave",
        "paper_rotating",
        "cycloidal_roller",
        "camshaft_flywheel",
        "andrews_squeezer",
        "four_bar",
        "bricard",
        "slider_crank",
    ] {
        for seed in [1, 7, 19] {
            let worst = check(name, seed);
            assert!(worst < 1e-12, "{name}, seed {seed}: {worst:e}");
        }
    }
}

/// The 16-body random chain (12 revolute joints between the ground and its tip, so the
/// contact's c reads the tip body's acceleration: `contact_row_bias`), with gravity along
/// no axis so that every component of R_bᵀ(−g) counts. The same round-off as above, over
/// sweeps 16 deep.
#[test]
fn a_long_chains_row_is_solved_with_its_own_c() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/random_models/chain16.ron"
    );
    let text = std::fs::read_to_string(file).expect("reads the model");
    let tilted = text.replacen(
        "gravity: (0.0, 0.0, -9.81)",
        "gravity: (1.5, -2.0, -9.81)",
        1,
    );
    assert_ne!(
        tilted, text,
        "the model's gravity is where this test expects it"
    );
    for text in [text, tilted] {
        let m = crate::schema::parse_model(&text, Path::new(file)).expect("parses");
        let d = Derivation::new(&m);
        assert!(d.articulated.row_bias.is_some(), "one row, solved within");
        for seed in [3, 11] {
            let worst = check_model(&m, seed);
            assert!(worst < 1e-12, "seed {seed}: {worst:e}");
        }
    }
}

#[test]
fn the_mass_product_is_m_times_x() {
    // The same recursions without velocities, weights and loads against M of the composite
    // inertias (an independent route) times x: round-off of O(n) sums, 1e-13 of the scale.
    for name in [
        "double_pendulum",
        "spatial_arm",
        "paper_rotating",
        "bricard",
    ] {
        let m = model(name);
        let d = Derivation::new(&m);
        let n = m.n();
        let q: Vec<f64> = (0..n).map(|i| number(5, i)).collect();
        let mut vars = d.variables(0.0, &q, &vec![0.0; n]);
        let x: Vec<f64> = (0..n).map(|i| number(11, i)).collect();
        for (&var, &v) in d.articulated.mass_x.iter().zip(&x) {
            if let crate::expr::Node::Var(k) = d.graph.node(var) {
                vars[k as usize] = v;
            }
        }
        let mass: Vec<Id> = d.dynamics.mass.iter().flatten().copied().collect();
        let mass = d.graph.eval(&mass, &vars);
        let got = d.graph.eval(&d.articulated.mass_product, &vars);
        let expected: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| mass[i * n + j] * x[j]).sum())
            .collect();
        let scale = expected.iter().fold(1.0f64, |s, v| s.max(v.abs()));
        for (g, e) in got.iter().zip(&expected) {
            assert!((g - e).abs() < 1e-13 * scale, "{name}: {g} against {e}");
        }
    }
}

#[test]
fn a_turn_about_a_coordinate_axis_by_the_double_angle_is_r_m_rt() {
    use crate::expr::Graph;
    use crate::kinematics::Rotation;
    let phi = 0.7;
    for k in 0..3 {
        for sign in [1.0, -1.0] {
            let mut g = Graph::new();
            let angle = g.var("phi");
            let mut axis = [0.0; 3];
            axis[k] = sign;
            let r = Rotation::Axis { axis, angle }.matrix(&mut g);
            let (turned, c, s) =
                super::rotation::plane_rotation(&mut g, &r).expect("a coordinate axis");
            assert_eq!(turned, k);
            for symmetric in [false, true] {
                let (m, values) = test_block(&mut g, 7, symmetric);
                let out = super::rotation::rotate_in_plane(&mut g, &m, k, (c, s), symmetric);
                // Both are sums of a few products of numbers below 1: round-off ~1e-16.
                let error = turned_error(&g, &out, &r, &values, phi);
                assert!(error < 1e-14, "axis {k}, sign {sign}, {symmetric}");
            }
        }
    }
    // A skew axis is not a turn in a coordinate plane.
    let mut g = Graph::new();
    let angle = g.var("phi");
    let a = std::f64::consts::FRAC_1_SQRT_2;
    let r = Rotation::Axis {
        axis: [a, a, 0.0],
        angle,
    }
    .matrix(&mut g);
    assert!(super::rotation::plane_rotation(&mut g, &r).is_none());
}

/// A 3 × 3 block of numbers below 1 as constants (symmetric when asked), and its values.
fn test_block(
    g: &mut crate::expr::Graph,
    seed: u64,
    symmetric: bool,
) -> ([crate::kinematics::V3; 3], DMatrix<f64>) {
    let value = |a: usize, b: usize| {
        let (a, b) = if symmetric {
            (a.min(b), a.max(b))
        } else {
            (a, b)
        };
        number(seed, 3 * a + b)
    };
    let m = [0, 1, 2].map(|a| [0, 1, 2].map(|b| g.constant(value(a, b))));
    (m, DMatrix::from_fn(3, 3, value))
}

/// max |out − R M Rᵀ| at the angle φ (the graph's one variable), R and out evaluated.
fn turned_error(
    g: &crate::expr::Graph,
    out: &[crate::kinematics::V3; 3],
    r: &[crate::kinematics::V3; 3],
    m: &DMatrix<f64>,
    phi: f64,
) -> f64 {
    let roots: Vec<Id> = out
        .iter()
        .flatten()
        .chain(r.iter().flatten())
        .copied()
        .collect();
    let values = g.eval(&roots, &[phi]);
    let got = DMatrix::from_row_slice(3, 3, &values[..9]);
    let rot = DMatrix::from_row_slice(3, 3, &values[9..]);
    (got - &rot * m * rot.transpose()).amax()
}

#[test]
fn a_turn_about_an_axis_in_a_coordinate_plane_is_r_m_rt() {
    // Three turns about coordinate axes against R M Rᵀ with R from Rodrigues' formula, for
    // axes in each coordinate plane (the 45° one has cos 2φ = 0 exactly) and both kinds of
    // block; a general axis is left to the matrix product.
    use crate::expr::Graph;
    use crate::kinematics::Rotation;
    let h = std::f64::consts::FRAC_1_SQRT_2;
    for axis in [
        [h, h, 0.0],
        [-h, h, 0.0],
        [0.6, 0.0, 0.8],
        [0.0, -0.8, 0.6],
        [0.28, 0.0, -0.96],
    ] {
        for symmetric in [false, true] {
            let mut g = Graph::new();
            let angle = g.var("phi");
            let (m, values) = test_block(&mut g, 11, symmetric);
            let out =
                super::rotation::rotate_in_coordinate_plane(&mut g, &m, axis, angle, symmetric)
                    .expect("an axis in a coordinate plane");
            let r = Rotation::Axis { axis, angle }.matrix(&mut g);
            // Three turns of numbers below 1 against two products: round-off ~1e-16.
            let error = turned_error(&g, &out, &r, &values, 0.9);
            assert!(error < 1e-14, "axis {axis:?}, {symmetric}");
        }
    }
    let mut g = Graph::new();
    let angle = g.var("phi");
    let m = [[g.one(); 3]; 3];
    let general = [0.48, 0.6, 0.64];
    assert!(
        super::rotation::rotate_in_coordinate_plane(&mut g, &m, general, angle, true).is_none()
    );
}
