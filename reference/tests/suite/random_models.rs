//! Property tests on random models (tracker issue 5 §2): for random chains and trees of
//! 1..=12 bodies (see `random/mod.rs` for what is drawn), written as RON and read back
//! through the real loader, the symbolic expressions evaluated by the interpreter (no
//! compilation) agree with the numeric recursive reference for M, F, Q, h, J, c, the contact
//! kinematics, the energies and the prescribed motions at random states; M is symmetric
//! positive definite and ½ q̇ᵀ M q̇ is the kinetic energy; and the code generator's output is
//! deterministic.
//!
//! Cases: 24 by default (about 10 s at the test profile's opt-level 2 on one core); more with
//! `PROPTEST_CASES=500 cargo test -p camchain-reference --test suite random_models -- --nocapture`.
//! The seed is fixed so CI is reproducible; `PROPTEST_RNG_SEED=<u64>` draws other models.
//! A failure prints the shrunk model's RON file, ready to save and load.
//!
//! `cargo test -p camchain-reference --test suite random_models -- --ignored write_compiled_models`
//! rewrites the fixed models of `tests/random_models/` (compiled by the root `build.rs`, checked by
//! `tests/suite/random_compiled.rs`) from a fixed seed.

#[path = "../random/mod.rs"]
mod random;

use camchain_codegen::Derivation;
use camchain_codegen::emit::generate;
use camchain_codegen::model::Model;
use camchain_codegen::schema::parse_model;
use camchain_reference::NumericModel;
use camchain_runtime::{Dynamics, Simulate};
use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::{Config, RngSeed, TestCaseError, TestError, TestRng, TestRunner};
use random::{ModelSpec, StateSpec, model_spec, states};
use std::path::Path;
use std::sync::Mutex;

/// Cases run when `PROPTEST_CASES` is not set.
const DEFAULT_CASES: u32 = 64;
/// Seed used when `PROPTEST_RNG_SEED` is not set.
const DEFAULT_SEED: u64 = 0x5eed_ca11_c4a1_2025;
/// Random states per model.
const STATES: usize = 3;

/// Agreement demanded between the interpreter and the numeric recursion, relative to the
/// magnitude of the compared group of values (see [`Check::group`]). Both routes evaluate the
/// same physics in double precision with different operation orders: each value is a sum of
/// at most a few thousand products (12 bodies, three nested levels of the recursion), each
/// term bounded by the group's magnitude, so the rounding differences stay below
/// ~1e-16 · 1e3 = 1e-13 of it (measured: at most 5e-15 over 1000 models, printed by the
/// test). 1e-11 leaves two orders of margin over that bound and still catches any wrong term:
/// the smallest physical term drawn (0.1 kg at 1e-2 m from an axis, a rate of 1e-2 rad/s) is
/// ~1e-7 of the scale at worst, and a 1e-6 relative change of one term (the gyroscopic
/// moment) was seen to fail.
const TOL: f64 = 1e-11;

/// Largest relative difference seen per quantity, over all cases.
static WORST: Mutex<Vec<(&'static str, f64)>> = Mutex::new(Vec::new());

fn record(what: &'static str, value: f64) {
    let mut worst = WORST.lock().unwrap_or_else(|e| e.into_inner());
    match worst.iter_mut().find(|(w, _)| *w == what) {
        Some((_, v)) => *v = v.max(value),
        None => worst.push((what, value)),
    }
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |a, x| a.max(x.abs()))
}

/// Collects the comparisons of one case; the first disagreement becomes the error.
struct Check {
    errors: Vec<String>,
}

impl Check {
    /// Compares a group of values: |a_i − b_i| ≤ TOL · scale for every entry, with scale =
    /// max(1, `magnitude`). `magnitude` bounds the terms the values are sums of (by default
    /// the group's largest reference value), so that an entry that cancels to nearly zero is
    /// not held to a relative accuracy its terms cannot give.
    fn group(&mut self, what: &'static str, a: &[f64], b: &[f64], magnitude: f64) {
        if a.len() != b.len() {
            self.errors
                .push(format!("{what}: {} values vs {}", a.len(), b.len()));
            return;
        }
        let scale = magnitude.max(max_abs(b)).max(1.0);
        let mut worst = 0.0f64;
        for (i, (x, y)) in a.iter().zip(b).enumerate() {
            let d = (x - y).abs() / scale;
            // Written so that a NaN on either side fails too.
            if d.is_nan() || d > TOL {
                self.errors.push(format!(
                    "{what}[{i}]: interpreter {x:e} vs numeric {y:e} (relative to {scale:e}: {d:e})"
                ));
            }
            worst = worst.max(d);
        }
        record(what, worst);
    }

    fn require(&mut self, ok: bool, message: impl FnOnce() -> String) {
        if !ok {
            self.errors.push(message());
        }
    }
}

fn load(ron: &str) -> Result<Model, String> {
    parse_model(ron, Path::new("random.ron")).map_err(|e| format!("the loader rejects it: {e}"))
}

/// Every property for one model; `Err` lists what failed.
fn check_model(spec: &ModelSpec, ron: &str, states: &[StateSpec]) -> Result<(), String> {
    let model = load(ron)?;
    let again = load(ron)?;
    if model != again {
        return Err("the same RON gives two different models".into());
    }
    let n = model.n();
    let nc = model.contacts.len();
    let d = Derivation::new(&model);
    let numeric = NumericModel::new(model.clone());
    let mut check = Check { errors: Vec::new() };

    // The initial guess is on every cam (the profiles were shifted so), and the marker is
    // where this file's own forward kinematics puts it: the loader's conventions (axis
    // normalisation, body order, anchors, cam frame) are the ones the generator assumed.
    let q0 = model.initial.q.clone();
    let zero = vec![0.0; n];
    let spec_q0 = spec.initial_q();
    for k in 0..nc {
        let ck = numeric.contact_kinematics(&q0, &zero, k);
        let g = ck.geometry;
        let want = spec.marker_position(k, &spec_q0);
        check.group(
            "marker position at q0 (own kinematics)",
            &g.position,
            &want,
            0.0,
        );
        let h = d.eval(&[d.contacts[k].h], 0.0, &q0, &zero)[0];
        let mut hn = vec![0.0; nc];
        numeric.constraint(&q0, &mut hn);
        check.group("h at q0", &[h, hn[k]], &[0.0, 0.0], g.y.abs());
    }
    // The build-time assembly check (what the build runs) and the runtime's assembly agree:
    // both accept the model as drawn (its guess is on every cam), or — a draw at a dead
    // point, where no free coordinate can move a contact point across its cam, or with
    // fewer free coordinates than contacts — both refuse.
    let build = camchain_codegen::assembly::assemble(&model, &d);
    let runtime = numeric.assemble(0.0);
    match (&build, &runtime) {
        (Ok(_), Ok(_)) | (Err(_), Err(_)) => {}
        (Ok(_), Err(e)) => check
            .errors
            .push(format!("the build accepts, the runtime: {e}")),
        (Err(e), _) => check.errors.push(format!("build-time assembly: {e}")),
    }

    for (qs, qds, t) in states {
        let (q, qd, t) = (&qs[..n], &qds[..n], *t);
        // M, F, Q.
        let mut m = vec![0.0; n * n];
        numeric.mass_matrix(q, &mut m);
        let sym_m = d.eval(&d.dynamics.mass.concat(), t, q, qd);
        check.group("M", &sym_m, &m, 0.0);
        let mut f = vec![0.0; n];
        numeric.inertial_forces(q, qd, &mut f);
        check.group("F", &d.eval(&d.dynamics.inertial, t, q, qd), &f, 0.0);
        let mut qa = vec![0.0; n];
        numeric.applied_forces(t, q, qd, &mut qa);
        check.group("Q", &d.eval(&d.dynamics.applied, t, q, qd), &qa, 0.0);

        // M symmetric positive definite, and the kinetic energy's quadratic form.
        let mat = nalgebra::DMatrix::from_row_slice(n, n, &sym_m);
        let asym = (&mat - mat.transpose()).amax();
        // Both triangles are sums of the same terms in different orders: 1e-13 relative.
        check.require(asym <= 1e-13 * mat.amax(), || {
            format!(
                "M not symmetric: max |M − Mᵀ| = {asym:e}, max |M| = {:e}",
                mat.amax()
            )
        });
        record("M − Mᵀ", asym / mat.amax());
        check.require(mat.clone().cholesky().is_some(), || {
            format!("M not positive definite: {mat}")
        });
        let v = nalgebra::DVector::from_column_slice(qd);
        let quad = 0.5 * v.dot(&(&mat * &v));
        let e = d.eval(
            &[
                d.energy.kinetic,
                d.energy.gravity,
                d.energy.spring,
                d.energy.damper_power,
            ],
            t,
            q,
            qd,
        );
        let en = numeric.energy(q, qd);
        check.group(
            "energies",
            &e,
            &[en.kinetic, en.gravity, en.spring, numeric.damper_power(qd)],
            0.0,
        );
        check.group("½ q̇ᵀ M q̇ vs kinetic energy", &[quad], &[en.kinetic], 0.0);

        // Constraint: h, J, c and the contact kinematics behind them.
        let mut h = vec![0.0; nc];
        numeric.constraint(q, &mut h);
        let mut j = vec![0.0; nc * n];
        numeric.constraint_jacobian(q, &mut j);
        let mut c = vec![0.0; nc];
        numeric.constraint_bias(q, qd, &mut c);
        for (k, terms) in d.contacts.iter().enumerate() {
            let ck = numeric.contact_kinematics(q, qd, k);
            let g = ck.geometry;
            let j1_qd: f64 = ck.j1.iter().zip(qd).map(|(a, b)| a * b).sum();
            // h = f2 − f3(f1): the terms are f2 and f3 = f2 − h.
            let hs = d.eval(&[terms.h], t, q, qd);
            check.group("h", &hs, &h[k..=k], g.y.abs().max((g.y - h[k]).abs()));
            // J = J2 − f3' J1.
            let js = d.eval(&terms.jacobian, t, q, qd);
            // |f3'| ≤ √(1 + f3'²) = the force scale of a knife edge on y = f3(x).
            let j_terms = max_abs(&ck.j2).max(g.force_scale * max_abs(&ck.j1));
            check.group("J", &js, &j[k * n..(k + 1) * n], j_terms);
            // c = conv2 − f3' conv1 − f3'' (J1 q̇)².
            let cs = d.eval(&[terms.bias], t, q, qd);
            // f3'' = κ (1 + f3'²)^(3/2).
            let second = g.curvature * g.force_scale.powi(3);
            let c_terms = ck
                .conv2
                .abs()
                .max((g.force_scale * ck.conv1).abs())
                .max((second * j1_qd * j1_qd).abs());
            check.group("c (convective term)", &cs, &c[k..=k], c_terms);
            let r = &terms.relative;
            let ids = [
                r.xy[0],
                r.xy[1],
                terms.position[0],
                terms.position[1],
                terms.position[2],
            ];
            let want = [ck.x, ck.y, g.position[0], g.position[1], g.position[2]];
            check.group(
                "contact position f1, f2, p",
                &d.eval(&ids, t, q, qd),
                &want,
                0.0,
            );
            let ids = [
                terms.force_scale,
                terms.curvature,
                terms.normal[0],
                terms.normal[1],
                terms.normal[2],
                terms.sliding,
            ];
            let want = [
                g.force_scale,
                g.curvature,
                g.normal[0],
                g.normal[1],
                g.normal[2],
                g.sliding_speed,
            ];
            check.group(
                "force scale, curvature, normal, sliding speed",
                &d.eval(&ids, t, q, qd),
                &want,
                0.0,
            );
            let j1: Vec<_> = r.columns.iter().map(|c| c[0]).collect();
            let j2: Vec<_> = r.columns.iter().map(|c| c[1]).collect();
            check.group("J1", &d.eval(&j1, t, q, qd), &ck.j1, 0.0);
            check.group("J2", &d.eval(&j2, t, q, qd), &ck.j2, 0.0);
            let conv = d.eval(&r.convective, t, q, qd);
            check.group(
                "convective (J1 q̇)_q q̇, (J2 q̇)_q q̇",
                &conv,
                &[ck.conv1, ck.conv2],
                0.0,
            );
        }

        // Prescribed motions.
        let (mut pq, mut pv, mut pa) = (q.to_vec(), qd.to_vec(), vec![0.0; n]);
        numeric.prescribed(t, &mut pq, &mut pv, &mut pa);
        for drive in &d.drives {
            let i = drive.coordinate;
            let sym = d.eval(&drive.motion, t, q, qd);
            check.group("prescribed q, q̇, q̈", &sym, &[pq[i], pv[i], pa[i]], 0.0);
        }
    }

    // The generator is deterministic: the same model twice, and a model rebuilt from the
    // same text, give the same bytes.
    let first = generate(&model, "random.ron")?;
    let second = generate(&model, "random.ron")?;
    let rebuilt = generate(&again, "random.ron")?;
    check.require(first.code == second.code, || {
        "generate() twice on one model gives different code".into()
    });
    check.require(first.code == rebuilt.code, || {
        "generate() on a model re-read from the same RON gives different code".into()
    });

    if check.errors.is_empty() {
        Ok(())
    } else {
        let shown = check.errors.len().min(10);
        Err(format!(
            "{} disagreement(s), first {shown}:\n  {}",
            check.errors.len(),
            check.errors[..shown].join("\n  ")
        ))
    }
}

fn config() -> Config {
    let from_env = Config::default();
    Config {
        cases: if std::env::var_os("PROPTEST_CASES").is_some() {
            from_env.cases
        } else {
            DEFAULT_CASES
        },
        rng_seed: match from_env.rng_seed {
            RngSeed::Random => RngSeed::Fixed(DEFAULT_SEED),
            fixed => fixed,
        },
        // The failing model is printed as a RON file (below); no regression file is written
        // into the source tree.
        failure_persistence: None,
        ..from_env
    }
}

#[test]
fn random_models_interpreted_equal_numeric() {
    let config = config();
    let (cases, seed) = (config.cases, config.rng_seed);
    let started = std::time::Instant::now();
    let sizes = Mutex::new(Vec::new());
    let mut runner = TestRunner::new(config);
    let result = runner.run(&(model_spec(), states(STATES)), |(spec, states)| {
        let ron = spec.ron("random");
        let outcome = std::panic::catch_unwind(|| check_model(&spec, &ron, &states))
            .unwrap_or_else(|p| {
                let what = p
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()));
                Err(format!("panicked: {}", what.unwrap_or_default()))
            });
        sizes
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push((spec.n(), spec.contacts.len()));
        outcome.map_err(|message| {
            let n = spec.n();
            let shown: Vec<_> = states
                .iter()
                .map(|(q, qd, t)| format!("  q = {:?}, q̇ = {:?}, t = {t:?}", &q[..n], &qd[..n]))
                .collect();
            TestCaseError::fail(format!(
                "{message}\nat the states\n{}\n--- the model (save as random.ron to reproduce) \
                 ---\n{ron}",
                shown.join("\n")
            ))
        })
    });
    match result {
        Ok(()) => {}
        // The reason holds the shrunk model's file and states; the strategy's value is not
        // printed again.
        Err(TestError::Fail(reason, _)) => panic!("{reason}"),
        Err(TestError::Abort(reason)) => panic!("aborted: {reason}"),
    }
    let sizes = sizes.into_inner().unwrap_or_else(|e| e.into_inner());
    let bodies: usize = sizes.iter().map(|s| s.0).sum();
    let largest = sizes.iter().map(|s| s.0).max().unwrap_or(0);
    let contacts: usize = sizes.iter().map(|s| s.1).sum();
    println!(
        "{cases} random models ({seed:?}), {bodies} bodies in all (largest {largest}), \
         {contacts} contacts, {STATES} states each, {:.1} s",
        started.elapsed().as_secs_f64()
    );
    for (what, worst) in WORST.lock().unwrap_or_else(|e| e.into_inner()).iter() {
        println!("  {what:<45} largest relative difference {worst:.1e}");
    }
}

/// The fixed models compiled by the root `build.rs` from `tests/random_models/`: one planar model with
/// a contact, one spatial tree with a contact, one spatial model with two contacts, one
/// spatial model without contact, each of 3..=8 bodies, every one of which assembles and
/// simulates for 1 s on the numeric reference, and whose markers can slide along their cams
/// (`ModelSpec::markers_can_slide`). Regenerate with
/// `cargo test -p camchain-reference --test suite random_models -- --ignored write_compiled_models`
/// (proptest's generator may draw other models in another proptest version).
#[test]
#[ignore = "writes tests/random_models/*.ron; run by hand to regenerate them"]
fn write_compiled_models() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/random_models");
    std::fs::create_dir_all(&dir).expect("create tests/random_models");
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        TestRng::from_seed(proptest::test_runner::RngAlgorithm::ChaCha, &[7; 32]),
    );
    // Name, planar, number of contacts, with a driven joint.
    let wanted: [(&str, bool, usize, bool); 4] = [
        ("random_planar", true, 1, false),
        ("random_tree", false, 1, true),
        ("random_two_cams", false, 2, false),
        ("random_free", false, 0, false),
    ];
    for (name, planar, contacts, driven) in wanted {
        let spec = (0..100_000)
            .map(|_| {
                model_spec()
                    .new_tree(&mut runner)
                    .expect("a model")
                    .current()
            })
            .find(|s| {
                s.planar == planar
                    && s.contacts.len() == contacts
                    && (3..=8).contains(&s.n())
                    && s.bodies.iter().any(|b| b.drive.is_some()) == driven
                    && (contacts == 0 || planar || s.contacts.iter().all(|c| c.frame.is_some()))
                    && s.markers_can_slide()
                    && simulates(&s.ron(name))
            })
            .expect("a model of this kind within 100000 draws");
        let text = spec.ron(name);
        std::fs::write(dir.join(format!("{name}.ron")), &text).expect("write the model");
        println!(
            "{name}: {} bodies, {} contacts",
            spec.n(),
            spec.contacts.len()
        );
    }
}

/// True when the model loads, assembles and simulates its default 1 s on the reference.
fn simulates(ron: &str) -> bool {
    let Ok(model) = load(ron) else { return false };
    let numeric = NumericModel::new(model);
    let Ok(state) = numeric.assemble(0.0) else {
        return false;
    };
    let settings = numeric.info().defaults.clone();
    numeric.simulate(state, &settings).is_ok()
}
