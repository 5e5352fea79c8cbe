//! The symbolic derivation checked by independent routes, with the interpreter (no
//! compilation): closed-form kinematics, finite differences, the Lagrangian identities
//! F_i = Σ (∂M_ij/∂q_k − ½ ∂M_jk/∂q_i) q̇_j q̇_k and Q_gravity = ∂V/∂q, and kinetic energy.

use crate::common;

use camchain_codegen::Derivation;
use camchain_codegen::model::Model;

/// A tiny deterministic generator (xorshift) so the tests need no extra crate.
struct Rng(u64);
impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
    fn vec(&mut self, n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n).map(|_| self.uniform(lo, hi)).collect()
    }
}

fn shifted(q: &[f64], dir: &[f64], s: f64) -> Vec<f64> {
    q.iter().zip(dir).map(|(a, b)| a + s * b).collect()
}

fn unit(n: usize, k: usize) -> Vec<f64> {
    (0..n).map(|i| if i == k { 1.0 } else { 0.0 }).collect()
}

/// Central first difference of a scalar function of s, Richardson-extrapolated from steps
/// 2h and h (truncation ~h⁴ times the fifth derivative: a contact point near a small cam's
/// centre has large third derivatives, which the plain difference's h² term would pass on).
fn d1(f: impl Fn(f64) -> f64, h: f64) -> f64 {
    let plain = |h: f64| (f(h) - f(-h)) / (2.0 * h);
    (4.0 * plain(h) - plain(2.0 * h)) / 3.0
}

fn mass(d: &Derivation, q: &[f64]) -> Vec<Vec<f64>> {
    let n = q.len();
    let roots: Vec<_> = d.dynamics.mass.iter().flatten().copied().collect();
    let v = d.eval(&roots, 0.0, q, &vec![0.0; n]);
    v.chunks(n).map(|r| r.to_vec()).collect()
}

#[test]
fn paper_contact_point_matches_the_closed_form_of_section_6() {
    let model = common::paper_concave();
    let d = Derivation::new(&model);
    let c = &d.contacts[0];
    let mut rng = Rng(0x9e3779b97f4a7c15);
    for _ in 0..100 {
        let q = rng.vec(4, -3.0, 3.0);
        let qd = vec![0.0; 4];
        let v = d.eval(&c.relative.xy, 0.0, &q, &qd);
        let l = 0.1 + q[2] + 0.3;
        let x =
            0.38 + 0.3 * q[0].cos() + l * (q[0] + q[1]).cos() + 0.3 * (q[0] + q[1] + q[3]).cos();
        let y =
            0.80 + 0.3 * q[0].sin() + l * (q[0] + q[1]).sin() + 0.3 * (q[0] + q[1] + q[3]).sin();
        // Same formula, different association of the sums: a few ulps of 1.
        assert!(
            (v[0] - x).abs() < 1e-14 && (v[1] - y).abs() < 1e-14,
            "{v:?} vs {x}, {y}"
        );
    }
}

/// Every check below, on one model at 100 random states.
fn check_against_finite_differences(model: &Model, seed: u64) {
    let d = Derivation::new(model);
    let n = model.n();
    let mut rng = Rng(seed);
    // 100 states, fewer for a large model in proportion to its coordinates: each state costs
    // O(n) evaluations of every term, and a large model repeats its pattern (n_four_bar's
    // 10 states check its 40 loops at 400 configurations, four_bar's 100 its one loop at 100).
    let states = (800 / n.max(1)).clamp(10, 100);
    for _ in 0..states {
        let q = rng.vec(n, -1.5, 1.5);
        let qd = rng.vec(n, -2.0, 2.0);
        check_contacts(&d, &q, &qd);
        check_loops(&d, &q, &qd);
        check_mass_matrix(&d, &q, &qd);
        check_inertial_forces(&d, &q, &qd);
        check_gravity(&d, &q);
    }
}

fn check_contacts(d: &Derivation, q: &[f64], qd: &[f64]) {
    let n = q.len();
    // Central differences with h = 1e-5: truncation ~h²·|f'''| ≈ 1e-10, rounding
    // ~eps/h ≈ 1e-11 (first) and ~eps/h² ≈ 1e-6 (second): tolerances 1e-8 and 1e-5 relative.
    let h = 1e-5;
    for c in &d.contacts {
        let at = |ids: &[camchain_codegen::expr::Id], q: &[f64]| d.eval(ids, 0.0, q, qd);
        for k in 0..n {
            let e = unit(n, k);
            let r = &c.relative;
            let j1: Vec<_> = r.columns.iter().map(|c| c[0]).collect();
            let j2: Vec<_> = r.columns.iter().map(|c| c[1]).collect();
            for (ids, f) in [(&j1, r.xy[0]), (&j2, r.xy[1]), (&c.jacobian, c.h)] {
                let fd = d1(|s| at(&[f], &shifted(q, &e, s))[0], h);
                let sym = at(&[ids[k]], q)[0];
                assert!(
                    (sym - fd).abs() < 1e-8 * (1.0 + fd.abs()),
                    "∂/∂q{k}: {sym} vs {fd}"
                );
            }
        }
        // Along the straight path q + s q̇ (q̈ = 0) the convective term is d/ds (J q̇) (and
        // d²f/ds²). The first difference of the (already checked) J q̇ with step 1e-6 has
        // truncation ~1e-12 and rounding ~ε|J q̇|/1e-6 ≈ 1e-8 relative; across a knot of a
        // C² table, where f‴ jumps, its error stays ≤ h·|jump|/4 (a second difference of f
        // would be off by ~s·|jump|, 1e-4 of it at s = 1e-4): tolerance 1e-6 relative.
        let r = &c.relative;
        let j1: Vec<_> = r.columns.iter().map(|c| c[0]).collect();
        let j2: Vec<_> = r.columns.iter().map(|c| c[1]).collect();
        for (conv, row) in [
            (r.convective[0], &j1),
            (r.convective[1], &j2),
            (c.bias, &c.jacobian),
        ] {
            let rate = |s: f64| -> f64 {
                let j = at(row, &shifted(q, qd, s));
                j.iter().zip(qd).map(|(a, b)| a * b).sum()
            };
            let fd = d1(rate, 1e-6);
            let sym = at(&[conv], q)[0];
            assert!(
                (sym - fd).abs() < 1e-6 * (1.0 + fd.abs()),
                "convective: {sym} vs {fd}"
            );
        }
    }
}

/// Every loop equation's J against central differences of h (step 1e-5, tolerance 1e-8
/// relative as for the contacts) and its c against the first difference of J q̇ along
/// q + s q̇ (step 1e-6, tolerance 1e-6 relative).
fn check_loops(d: &Derivation, q: &[f64], qd: &[f64]) {
    let n = q.len();
    let at = |ids: &[camchain_codegen::expr::Id], q: &[f64]| d.eval(ids, 0.0, q, qd);
    for row in d.loops.iter().flat_map(|l| &l.rows) {
        for k in 0..n {
            let fd = d1(|s| at(&[row.h], &shifted(q, &unit(n, k), s))[0], 1e-5);
            let sym = at(&[row.jacobian[k]], q)[0];
            assert!(
                (sym - fd).abs() < 1e-8 * (1.0 + fd.abs()),
                "loop ∂h/∂q{k}: {sym} vs {fd}"
            );
        }
        let rate = |s: f64| -> f64 {
            let j = at(&row.jacobian, &shifted(q, qd, s));
            j.iter().zip(qd).map(|(a, b)| a * b).sum()
        };
        let fd = d1(rate, 1e-6);
        let sym = at(&[row.bias], q)[0];
        assert!(
            (sym - fd).abs() < 1e-6 * (1.0 + fd.abs()),
            "loop convective: {sym} vs {fd}"
        );
    }
}

fn check_mass_matrix(d: &Derivation, q: &[f64], qd: &[f64]) {
    let n = q.len();
    let m = mass(d, q);
    let mut quad = 0.0;
    for i in 0..n {
        for j in 0..n {
            // Both triangles come from the same recursion rows; symmetry is exact up to the
            // association of sums: 1e-13 relative.
            assert!((m[i][j] - m[j][i]).abs() < 1e-13 * (1.0 + m[i][j].abs()));
            quad += qd[i] * m[i][j] * qd[j];
        }
    }
    let kinetic = d.eval(&[d.energy.kinetic], 0.0, q, qd)[0];
    // ½ q̇ᵀMq̇ against Σ ½(m v² + ωᵀIω) from body velocities: different sums, 1e-12 relative.
    assert!(
        (0.5 * quad - kinetic).abs() < 1e-12 * (1.0 + kinetic),
        "{} vs {kinetic}",
        0.5 * quad
    );
    let chol = nalgebra::DMatrix::from_fn(n, n, |i, j| m[i][j]).cholesky();
    assert!(chol.is_some(), "M is positive definite");
}

/// F_i = Σ_jk (∂M_ij/∂q_k − ½ ∂M_jk/∂q_i) q̇_j q̇_k: the Lagrangian route, with ∂M by
/// central differences.
fn check_inertial_forces(d: &Derivation, q: &[f64], qd: &[f64]) {
    let n = q.len();
    let h = 1e-6;
    let dm: Vec<Vec<Vec<f64>>> = (0..n)
        .map(|k| {
            let e = unit(n, k);
            let (p, m) = (mass(d, &shifted(q, &e, h)), mass(d, &shifted(q, &e, -h)));
            (0..n)
                .map(|i| (0..n).map(|j| (p[i][j] - m[i][j]) / (2.0 * h)).collect())
                .collect()
        })
        .collect();
    let f = d.eval(&d.dynamics.inertial, 0.0, q, qd);
    for i in 0..n {
        let mut fd = 0.0;
        for j in 0..n {
            for k in 0..n {
                fd += (dm[k][i][j] - 0.5 * dm[i][j][k]) * qd[j] * qd[k];
            }
        }
        // ∂M by central differences (h = 1e-6): error ~1e-10 per entry, summed over n² terms
        // with |q̇| ≤ 2: 1e-7 relative to the scale of F.
        assert!(
            (f[i] - fd).abs() < 1e-7 * (1.0 + fd.abs()),
            "F[{i}]: {} vs {fd}",
            f[i]
        );
    }
}

/// The gravity part of Q is the gradient of the gravity potential (springs are added
/// separately and checked through the spring potential as well).
fn check_gravity(d: &Derivation, q: &[f64]) {
    let n = q.len();
    let zero = vec![0.0; n];
    let applied = d.eval(&d.dynamics.applied, 0.0, q, &zero);
    let potential = |q: &[f64]| {
        let v = d.eval(&[d.energy.gravity, d.energy.spring], 0.0, q, &zero);
        v[0] + v[1]
    };
    for (i, &value) in applied.iter().enumerate() {
        let e = unit(n, i);
        // An applied joint load τ enters Q as −τ; at q̇ = 0 it is ∂(Σ τ q̇)/∂q̇_i, read from
        // the load power by differences in q̇ (exact for a power at most quadratic in q̇_i,
        // as a motor line τ = T (1 − q̇/ω0) gives).
        let load = d1(
            |s| d.eval(&[d.energy.load_power], 0.0, q, &shifted(&zero, &e, s))[0],
            1e-3,
        );
        let value = value + load;
        let fd = d1(|s| potential(&shifted(q, &e, s)), 1e-5);
        // Central difference, h = 1e-5: 1e-8 relative (see check_contacts).
        assert!(
            (value - fd).abs() < 1e-8 * (1.0 + fd.abs()),
            "Q[{i}]: {value} vs {fd}"
        );
    }
}

#[test]
fn paper_model_terms_agree_with_finite_differences_and_lagrange() {
    check_against_finite_differences(&common::paper_concave(), 42);
}

#[test]
fn spatial_tree_terms_agree_with_finite_differences_and_lagrange() {
    check_against_finite_differences(&common::spatial_tree(), 7);
}

#[test]
fn every_model_file_agrees_with_finite_differences_and_lagrange() {
    every_model_file_in_turn(|name| name != "n_four_bar");
}

/// `n_four_bar` (81 coordinates) takes about as long as the 25 other files together: its own
/// test, which runs beside theirs.
#[test]
fn the_n_four_bar_agrees_with_finite_differences_and_lagrange() {
    every_model_file_in_turn(|name| name == "n_four_bar");
}

/// [`check_against_finite_differences`] on the model files whose stem `pick` accepts, each
/// with its own seed (its place among all the files).
fn every_model_file_in_turn(pick: impl Fn(&str) -> bool) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("models/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .collect();
    files.sort();
    assert!(files.len() >= 7);
    let mut checked = 0;
    for (k, file) in files.iter().enumerate() {
        let stem = file
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_default();
        if !pick(stem) {
            continue;
        }
        let model = camchain_codegen::schema::load_model(file).unwrap_or_else(|e| panic!("{e}"));
        check_against_finite_differences(&model, 1000 + k as u64);
        checked += 1;
    }
    assert!(checked >= 1, "no model file picked");
}

#[test]
fn an_unreachable_initial_state_fails_with_file_line_and_field() {
    let source = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/paper_concave.ron"),
    )
    .expect("readable");
    // Hold every coordinate but q4: the tip then sweeps a 0.3 m circle around joint 4,
    // which with q1 pointing straight up cannot reach the cam far below.
    let broken = source
        .replace(
            "hold: [\"q1\", \"q2\", \"q4\"]",
            "hold: [\"q1\", \"q2\", \"q3\"]",
        )
        .replace("\"q1\": \"-PI/2 - swing\"", "\"q1\": 1.5707963267948966");
    assert_ne!(broken, source, "the fixture edit applied");
    let dir = std::env::temp_dir().join(format!("camchain-unreachable-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("unreachable.ron");
    std::fs::write(&path, &broken).expect("written");
    let err =
        camchain_codegen::generate_file(&path, std::path::Path::new("models/unreachable.ron"))
            .expect_err("must not assemble");
    let text = err.to_string();
    let line = broken
        .lines()
        .position(|l| l.contains("initial:"))
        .expect("has initial")
        + 1;
    assert!(
        text.starts_with(&format!("models/unreachable.ron:{line}:")),
        "{text}"
    );
    assert!(
        text.contains("initial") && text.contains("cannot be assembled"),
        "{text}"
    );
}

#[test]
fn assembly_halves_a_newton_step_that_leaves_where_the_surface_is_defined() {
    // The sphere r = √(a² − z²) (a = 0.5) with the particle at x = a sin 0.1 and the guess
    // z = 0.45: Newton's full step lands at z = 0.53, above the sphere's pole, where √ of a
    // negative number is NaN. Halving it stays on the sphere's side and converges to the root
    // z = √(a² − x²).
    let source = include_str!("../../../tests/contact_models/sphere_slide.ron");
    let model = camchain_codegen::schema::parse_model(source, std::path::Path::new("sphere.ron"))
        .expect("parses");
    let d = Derivation::new(&model);
    let q = camchain_codegen::assembly::assemble(&model, &d).expect("assembles");
    let x = 0.5 * 0.1f64.sin();
    assert!((q[2] - (0.25 - x * x).sqrt()).abs() < 1e-12, "z = {}", q[2]);
}

#[test]
fn loop_gaps_are_the_difference_of_their_points_whichever_side_holds_a_pair() {
    // The gap is formed from anchors and pairs of equal links ((K7) of docs/method.md §11.4),
    // the points from the whole paths: they must agree. The parallelogram's coupler pairs
    // with the ground link on side A as written and on side B with the sides exchanged;
    // n_four_bar has 40 such loops with angles of every size.
    let parallelogram = include_str!("../../../tests/loop_models/parallelogram.ron");
    let written = r#"a: (body: "coupler", point: ("d", 0.0, 0.0)), b: (body: "rocker", point: ("a", 0.0, 0.0))"#;
    let exchanged = r#"a: (body: "rocker", point: ("a", 0.0, 0.0)), b: (body: "coupler", point: ("d", 0.0, 0.0))"#;
    assert!(parallelogram.contains(written));
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let models = [
        camchain_codegen::schema::parse_model(parallelogram, std::path::Path::new("p.ron")),
        camchain_codegen::schema::parse_model(
            &parallelogram.replace(written, exchanged),
            std::path::Path::new("p.ron"),
        ),
        camchain_codegen::schema::load_model(&dir.join("n_four_bar.ron")),
    ];
    for model in models {
        let model = model.unwrap_or_else(|e| panic!("{e}"));
        let d = Derivation::new(&model);
        let n = model.n();
        let mut rng = Rng(7);
        for _ in 0..20 {
            let q = rng.vec(n, -40.0, 40.0);
            let qd = vec![0.0; n];
            for l in &d.loops {
                let [a, b] = l.points.map(|p| d.eval(&p, 0.0, &q, &qd));
                for (k, row) in l.rows.iter().take(2).enumerate() {
                    let h = d.eval(&[row.h], 0.0, &q, &qd)[0];
                    let gap = a[k] - b[k];
                    assert!(
                        (h - gap).abs() < 1e-12 * (1.0 + a[k].abs()),
                        "{}: h {h} against the points' difference {gap}",
                        model.name
                    );
                }
            }
        }
    }
}
