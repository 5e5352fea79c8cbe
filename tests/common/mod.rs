//! Shared test helpers.

#![allow(dead_code)]

use camchain::runtime::Dynamics;
use std::cell::Cell;

pub mod articulated;

/// A tiny deterministic generator (xorshift64) so random states are reproducible.
pub struct Rng(u64);

impl Rng {
    /// Seeded generator (seed 0 is replaced by a fixed non-zero value).
    pub fn new(seed: u64) -> Self {
        Rng(if seed == 0 { 0x9e3779b97f4a7c15 } else { seed })
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }

    /// n uniform values in [lo, hi).
    pub fn vec(&mut self, n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n).map(|_| self.uniform(lo, hi)).collect()
    }
}

/// Asserts |a_i − b_i| ≤ tol · max(1, |b_i|) for every entry.
pub fn assert_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths differ");
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        let scale = y.abs().max(1.0);
        assert!(
            (x - y).abs() <= tol * scale,
            "{what}[{i}]: {x:e} vs {y:e} (difference {:e}, tolerance {:e})",
            (x - y).abs(),
            tol * scale
        );
    }
}

/// The largest relative difference max |a_i − b_i| / max(1, |b_i|).
pub fn max_rel_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() / y.abs().max(1.0))
        .fold(0.0, f64::max)
}

/// Asserts agreement within `tol` and records the largest relative difference seen.
fn assert_close_recorded(a: &[f64], b: &[f64], tol: f64, what: &str, worst: &Cell<f64>) {
    assert_close(a, b, tol, what);
    worst.set(worst.get().max(max_rel_diff(a, b)));
}

/// Compares every function of the [`Dynamics`] trait of a generated model with the numeric
/// reference at 100 random states (q in [−1.5, 1.5], q̇ in [−2, 2], t in [0, 10]), each value
/// within `tol` relative to max(1, |reference|) (see [`assert_close`]); returns the largest
/// relative difference.
pub fn compare_dynamics(
    name: &str,
    generated: &dyn Dynamics,
    numeric: &dyn Dynamics,
    tol: f64,
) -> f64 {
    let n = generated.info().n();
    let mut rng = Rng::new(name.len() as u64 * 7919 + 17);
    let states: Vec<State> = (0..100)
        .map(|_| {
            let q = rng.vec(n, -1.5, 1.5);
            let qd = rng.vec(n, -2.0, 2.0);
            (q, qd, rng.uniform(0.0, 10.0))
        })
        .collect();
    compare_dynamics_at(name, generated, numeric, tol, &states)
}

/// A state (q, q̇, t) at which two models are compared.
pub type State = (Vec<f64>, Vec<f64>, f64);

/// `count` states within ±`spread` (rad or m) of the configuration `q0`, with rates in
/// ±2 and times in [0, 10], drawn from `seed`: for models whose contacts are only defined
/// near their assembled configuration.
pub fn states_near(q0: &[f64], spread: f64, count: usize, seed: u64) -> Vec<State> {
    let mut rng = Rng::new(seed);
    (0..count)
        .map(|_| {
            let q = q0
                .iter()
                .map(|x| x + rng.uniform(-spread, spread))
                .collect();
            (q, rng.vec(q0.len(), -2.0, 2.0), rng.uniform(0.0, 10.0))
        })
        .collect()
}

/// [`compare_dynamics`] at the given states (for models whose contacts are only defined
/// near their assembled configuration: a flat face on an open profile).
pub fn compare_dynamics_at(
    name: &str,
    generated: &dyn Dynamics,
    numeric: &dyn Dynamics,
    tol: f64,
    states: &[State],
) -> f64 {
    let worst = Cell::new(0.0);
    let n = generated.info().n();
    let nc = generated.info().n_constraints();
    assert_eq!(numeric.info().n(), n);
    for (q, qd, t) in states {
        let (q, qd, t) = (q.clone(), qd.clone(), *t);
        let both = |f: &dyn Fn(&dyn Dynamics) -> Vec<f64>| (f(generated), f(numeric));
        let (a, b) = both(&|m| {
            let mut out = vec![0.0; n * n];
            m.mass_matrix(&q, &mut out);
            out
        });
        assert_close_recorded(&a, &b, tol, &format!("{name}: M"), &worst);
        let (a, b) = both(&|m| {
            let mut out = vec![0.0; n];
            m.inertial_forces(&q, &qd, &mut out);
            out
        });
        assert_close_recorded(&a, &b, tol, &format!("{name}: F"), &worst);
        let (a, b) = both(&|m| {
            let mut out = vec![0.0; n];
            m.applied_forces(t, &q, &qd, &mut out);
            out
        });
        assert_close_recorded(&a, &b, tol, &format!("{name}: Q"), &worst);
        let (a, b) = both(&|m| {
            let (mut mm, mut f, mut qa) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
            m.equations(t, &q, &qd, &mut mm, &mut f, &mut qa);
            [mm, f, qa].concat()
        });
        assert_close_recorded(
            &a,
            &b,
            tol,
            &format!("{name}: equations (M, F, Q together)"),
            &worst,
        );
        let (a, b) = both(&|m| {
            let (mut h, mut j, mut c) = (vec![0.0; nc], vec![0.0; nc * n], vec![0.0; nc]);
            m.constraint(&q, &mut h);
            m.constraint_jacobian(&q, &mut j);
            m.constraint_bias(&q, &qd, &mut c);
            [h, j, c].concat()
        });
        assert_close_recorded(&a, &b, tol, &format!("{name}: h, J, c"), &worst);
        let (a, b) = both(&|m| {
            let (mut j, mut c) = (vec![0.0; nc * n], vec![0.0; nc]);
            m.constraint_terms(&q, &qd, &mut j, &mut c);
            [j, c].concat()
        });
        assert_close_recorded(&a, &b, tol, &format!("{name}: constraint_terms"), &worst);
        // The fused pair a right-hand side calls: the velocity level reads the cache the
        // position level filled (the numeric model's default ignores the cache).
        let (a, b) = both(&|m| {
            let (mut h, mut j) = (vec![0.0; nc], vec![0.0; nc * n]);
            let mut cache = vec![f64::NAN; m.cache_len()];
            m.position_terms(&q, &mut h, &mut j, &mut cache);
            let (mut mm, mut f, mut qa, mut c) =
                (vec![0.0; n * n], vec![0.0; n], vec![0.0; n], vec![0.0; nc]);
            let out = camchain::runtime::VelocityTerms {
                mass: &mut mm,
                inertial: &mut f,
                applied: &mut qa,
                bias: &mut c,
            };
            m.velocity_terms(t, &q, &qd, &cache, out);
            [h, j, mm, f, qa, c].concat()
        });
        assert_close_recorded(
            &a,
            &b,
            tol,
            &format!("{name}: position_terms then velocity_terms"),
            &worst,
        );
        for k in 0..generated.info().n_contacts() {
            let (a, b) = both(&|m| {
                let ck = m.contact_kinematics(&q, &qd, k);
                let g = ck.geometry;
                let mut v = geometry_values(&g, m.info().contacts[k].profile);
                v.extend([ck.x, ck.y, ck.conv1, ck.conv2, ck.z, ck.conv3]);
                v.extend(ck.j1);
                v.extend(ck.j2);
                v.extend(ck.j3);
                v
            });
            assert_close_recorded(
                &a,
                &b,
                tol,
                &format!("{name}: contact {k} kinematics"),
                &worst,
            );
        }
        let loop_points = 2 * generated.info().loops.len();
        let (a, b) = both(&|m| {
            let mut points = vec![[0.0; 3]; loop_points];
            m.loop_points(&q, &mut points);
            points.concat()
        });
        assert_close_recorded(&a, &b, tol, &format!("{name}: loop points"), &worst);
        let (a, b) = both(&|m| {
            let e = m.energy(&q, &qd);
            vec![
                e.kinetic,
                e.gravity,
                e.spring,
                m.damper_power(&qd),
                m.load_power(t, &q, &qd),
            ]
        });
        assert_close_recorded(&a, &b, tol, &format!("{name}: energies"), &worst);
        let (a, b) = both(&|m| {
            let (mut pq, mut pv, mut pa) = (q.clone(), qd.clone(), vec![0.0; n]);
            m.prescribed(t, &mut pq, &mut pv, &mut pa);
            [pq, pv, pa].concat()
        });
        assert_close_recorded(&a, &b, tol, &format!("{name}: prescribed motion"), &worst);
        let mut rng = Rng::new(q.len() as u64 + 3);
        let mut draw = || rng.uniform(-1.0, 1.0);
        let residual =
            articulated::articulated_residual(generated, numeric, (&q, &qd, t), &mut draw);
        assert!(
            residual <= tol,
            "{name}: the articulated sweeps' residual in the other model's equations is \
             {residual:e} at q = {q:?} (tolerance {tol:e})"
        );
        worst.set(worst.get().max(residual));
    }
    worst.get()
}

/// Every number of a contact's geometry, for comparisons. The angle of a polar profile's
/// contact point, or of a barrel's, is defined modulo 2π: its cosine and sine are compared
/// instead.
pub fn geometry_values(
    g: &camchain::runtime::ContactGeometry,
    profile: camchain::runtime::ProfileKind,
) -> Vec<f64> {
    let mut v = Vec::new();
    for vector in [g.position, g.follower, g.normal, g.axis, g.direction] {
        v.extend(vector);
    }
    v.extend([g.x, g.y, g.z, g.force_scale, g.curvature, g.sliding_speed]);
    match profile {
        // An angle: modulo 2π (a face cam's centre line, polar or a design's, runs round
        // the turn).
        camchain::runtime::ProfileKind::Polar
        | camchain::runtime::ProfileKind::Barrel
        | camchain::runtime::ProfileKind::Face => v.extend([g.parameter.cos(), g.parameter.sin()]),
        camchain::runtime::ProfileKind::Explicit
        | camchain::runtime::ProfileKind::Parametric
        | camchain::runtime::ProfileKind::Surface
        | camchain::runtime::ProfileKind::Revolution => v.push(g.parameter),
    }
    v
}

/// The agreement demanded of a model whose profile is a table of points, instead of `tol`:
/// the generated code evaluates the runtime's spline (second derivatives at the knots by the
/// Thomas algorithm) and the reference its own (slopes by a dense LU solve, the Hermite
/// form). Their second derivatives carry the rounding of the table's values divided by the
/// points' spacing squared, ε·|y|/(h²|S″|): for table_cam (|y| ≈ 0.05 m, h ≈ 0.35 mm,
/// |S″| ≈ 18/m) about 5e-12 relative in the curvature (measured 1.4e-11); 1e-10 leaves a
/// margin of 7.
pub fn for_tables(model: &camchain_reference::NumericModel, tol: f64) -> f64 {
    let tabulated = model.model().contacts.iter().any(|c| {
        matches!(
            c.profile_expression(),
            camchain_codegen::profile::Scalar::Table(..)
                | camchain_codegen::profile::Scalar::Grid(..)
        )
    });
    if tabulated { tol.max(1e-10) } else { tol }
}
