//! A groove with backlash (docs/model-format.md "Barrel cams", docs/method.md §13.10) against
//! its closed form. `tests/numeric_models/barrel_backlash.ron` is barrel_indexer's groove made
//! b = 2 mm wider than its roller, the follower free along the axis (no spring, gravity or
//! damping): between the flanks it flies at constant speed, on a flank it moves with the
//! groove, whose centre line is base + S(φ), φ = ω t, S a cycloidal rise of h over β = 120°
//! after a 60° dwell. So, with plastic impacts (e = 0):
//!
//! - at rest and centred, it is struck by the lower flank when S = b/2, at the speed Ṡ;
//! - it rides the lower flank (z = base + S − b/2) while S̈ > 0 and leaves it at mid-rise,
//!   where S̈ changes sign, at the peak speed v* = 2 h ω / β;
//! - it flies, z = z* + v* (t − t*), until it is b ahead of the flank it left,
//!   v* (t − t*) − (S(t) − S(t*)) = b, and lands on the upper flank at v* − Ṡ;
//!
//! and with e = 0.5 the first impact sends it off at (1 + e) Ṡ, to land where its flight
//! first meets a flank again. The reference runs it (the clearance is the runtime's, shared
//! by generated models: `runtime/src/clearance.rs`).

use camchain::runtime::events::EventKind;
use camchain::runtime::{Dynamics, Flank, Simulate};
use camchain_reference::NumericModel;
use std::f64::consts::PI;
use std::path::Path;

fn model() -> NumericModel {
    let path = format!(
        "{}/tests/numeric_models/barrel_backlash.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    NumericModel::load(Path::new(&path)).unwrap_or_else(|e| panic!("{e}"))
}

/// The file's values (checked against its parameters) and the groove's centre line.
struct Groove {
    omega: f64,
    lift: f64,
    base: f64,
    backlash: f64,
    start: f64,
    span: f64,
}

impl Groove {
    fn of(m: &NumericModel) -> Self {
        let info = m.info();
        let value = |name: &str| {
            let k = info.parameter_index(name).expect("declared");
            m.parameter_values()[k]
        };
        let file = |name: &str| {
            m.model()
                .parameters
                .iter()
                .find(|p| p.name == name)
                .map(|p| p.default)
                .expect("declared")
        };
        Groove {
            omega: value("omega"),
            lift: file("h"),
            base: file("base"),
            backlash: info.contacts[0].backlash,
            start: PI / 3.0,
            span: 2.0 * PI / 3.0,
        }
    }

    /// S and Ṡ at t (during the first dwell and the rise).
    fn s(&self, t: f64) -> (f64, f64) {
        let u = ((self.omega * t - self.start) / self.span).clamp(0.0, 1.0);
        let w = 2.0 * PI * u;
        (
            self.lift * (u - w.sin() / (2.0 * PI)),
            self.lift * self.omega / self.span * (1.0 - w.cos()),
        )
    }

    /// The root of f in [a, b] (f(a) < 0 < f(b)) by bisection to 1e-15 s.
    fn root(f: impl Fn(f64) -> f64, (mut a, mut b): (f64, f64)) -> f64 {
        assert!(f(a) < 0.0 && f(b) > 0.0, "no sign change in [{a}, {b}]");
        while b - a > 1e-15 {
            let m = 0.5 * (a + b);
            if f(m) < 0.0 { a = m } else { b = m }
        }
        0.5 * (a + b)
    }
}

#[test]
fn a_roller_crosses_its_grooves_backlash_as_the_closed_form_says() {
    let m = model();
    let g = Groove::of(&m);
    assert_eq!((g.backlash, g.omega), (0.002, 10.0), "the file's values");
    let half = 0.5 * g.backlash;
    let rise_start = g.start / g.omega;
    let t1 = Groove::root(|t| g.s(t).0 - half, (rise_start, rise_start + 0.05));
    let t_star = (g.start + 0.5 * g.span) / g.omega;
    let (s_star, v_star) = g.s(t_star);
    assert!((v_star - 2.0 * g.lift * g.omega / g.span).abs() < 1e-15);
    let ahead = |t: f64| v_star * (t - t_star) - (g.s(t).0 - s_star) - g.backlash;
    let t2 = Groove::root(ahead, (t_star + 1e-6, (g.start + g.span) / g.omega));
    // The file's law: one-sided with plastic impacts.
    let e = m.info().restitution.expect("the file gives a restitution");
    assert_eq!(e, 0.0);
    let run = m
        .simulate_unilateral(m.assemble(0.0).expect("assembles"), &m.info().defaults, e)
        .unwrap_or_else(|f| panic!("{}", f.error));
    let kinds: Vec<(EventKind, Option<Flank>)> =
        run.events.iter().map(|e| (e.kind, e.flank)).collect();
    assert_eq!(kinds.len(), 3, "{kinds:?}");
    let speeds = [g.s(t1).1, v_star - g.s(t2).1];
    let mut late = 0.0f64;
    for (event, (t, flank, speed)) in run.events.iter().zip([
        (t1, Flank::Inner, Some(speeds[0])),
        (t_star, Flank::Inner, None),
        (t2, Flank::Outer, Some(speeds[1])),
    ]) {
        // Events are located to 1e-9 s on the dense output of an rtol 1e-11 run.
        late = late.max((event.t - t).abs());
        assert!(
            (event.t - t).abs() < 1e-8,
            "{:?} at {} against {t}",
            event.kind,
            event.t
        );
        assert_eq!(event.flank, Some(flank), "at {t}");
        match (event.kind, speed) {
            (
                EventKind::Impact {
                    normal_velocity,
                    stays,
                    ..
                },
                Some(v),
            ) => {
                // Approach speeds of 0.08 and 0.12 m/s: 1e-7 m/s is the event time's 1e-8 s
                // times the groove's acceleration (≈ 10 m/s²).
                assert!(
                    (-normal_velocity - v).abs() < 1e-7,
                    "{normal_velocity} against {v}"
                );
                assert!(stays, "a plastic impact keeps the roller on the flank");
            }
            (EventKind::LiftOff, None) => {}
            (kind, _) => panic!("{kind:?} at {} is not the expected event", event.t),
        }
    }
    // The whole trajectory: z = base until the first impact, then on the lower flank, in
    // flight, on the upper flank.
    let rho = m
        .model()
        .parameters
        .iter()
        .find(|p| p.name == "rho")
        .map(|p| p.default)
        .expect("declared");
    let mut worst = 0.0f64;
    for sample in &run.samples {
        let t = sample.t;
        let (s, _) = g.s(t);
        let z = if t < t1 {
            g.base
        } else if t < t_star {
            g.base + s - half
        } else if t < t2 {
            g.base + s_star - half + v_star * (t - t_star)
        } else {
            g.base + s + half
        };
        worst = worst.max((sample.q[1] - z).abs());
        // The contact point and normal are the flank's: above the roller's centre on the
        // upper flank, whose normal pushes down, below it on the lower one.
        let g = &sample.contacts[0];
        let reach = (0..3)
            .map(|i| (g.position[i] - g.follower[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        // The rim is the roller's radius from its centre (rounding of a few operations on
        // lengths of 0.01–0.06 m).
        assert!(
            (reach - rho).abs() < 1e-15,
            "t = {t}: {reach} from the centre"
        );
        if t > t2 + 1e-6 {
            assert!(
                g.position[2] > sample.q[1] && g.normal[2] < 0.0,
                "t = {t}: {g:?}"
            );
        } else if t > t1 + 1e-6 && t < t_star - 1e-6 {
            assert!(
                g.position[2] < sample.q[1] && g.normal[2] > 0.0,
                "t = {t}: {g:?}"
            );
        }
    }
    println!(
        "backlash: impacts at {:.9} s and {:.9} s, lift-off at {:.9} s, events within \
         {late:.1e} s; trajectory within {worst:.1e} m",
        t1, t2, t_star
    );
    // An event 1e-9 s off moves the rest of the run by at most 1e-9 s × 0.3 m/s; the
    // integration at rtol 1e-11 adds ~1e-12 m.
    assert!(
        worst < 1e-9,
        "the follower's lift is {worst:e} m from the closed form"
    );
}

#[test]
fn a_rebound_in_the_groove_lands_where_its_flight_meets_a_flank() {
    let m = model();
    let g = Groove::of(&m);
    let (half, e) = (0.5 * g.backlash, 0.5);
    let rise_start = g.start / g.omega;
    let t1 = Groove::root(|t| g.s(t).0 - half, (rise_start, rise_start + 0.05));
    let (s1, v1) = g.s(t1);
    // After the impact the roller leaves the lower flank at (1 + e) Ṡ: its offset from the
    // centre line is d(t) = −b/2 + (1 + e) Ṡ₁ (t − t₁) − (S(t) − S₁), until |d| = b/2.
    let d = |t: f64| -half + (1.0 + e) * v1 * (t - t1) - (g.s(t).0 - s1);
    let mut t = t1 + 1e-6;
    while d(t).abs() < half {
        t += 1e-5;
    }
    let upper = d(t) > 0.0;
    let t2 = if upper {
        Groove::root(|t| d(t) - half, (t1 + 1e-6, t))
    } else {
        Groove::root(|t| -half - d(t), (t1 + 1e-6, t))
    };
    let run = m
        .simulate_unilateral(m.assemble(0.0).expect("assembles"), &m.info().defaults, e)
        .unwrap_or_else(|f| panic!("{}", f.error));
    let [first, second, ..] = run.events.as_slice() else {
        panic!("two impacts at least: {:?}", run.events);
    };
    let EventKind::Impact { rebound, stays, .. } = first.kind else {
        panic!("{:?}", first.kind)
    };
    assert!(!stays);
    // The rebound J q̇⁺ = e Ṡ₁ (J the flank's, pointing away from it), to the event's 1e-9 s
    // times the groove's acceleration.
    assert!(
        (rebound - e * v1).abs() < 1e-7,
        "rebound {rebound} against {}",
        e * v1
    );
    assert!(
        (second.t - t2).abs() < 1e-8,
        "lands at {} against {t2}",
        second.t
    );
    let flank = if upper { Flank::Outer } else { Flank::Inner };
    assert_eq!(second.flank, Some(flank));
    let EventKind::Impact {
        normal_velocity, ..
    } = second.kind
    else {
        panic!("{:?}", second.kind)
    };
    let approach = (1.0 + e) * v1 - g.s(t2).1;
    let expected = if upper { approach } else { -approach };
    assert!(
        (-normal_velocity - expected).abs() < 1e-7,
        "{normal_velocity} against {expected}"
    );
    println!(
        "backlash, e = {e}: rebound {rebound:.6} m/s, lands on the {} flank at {:.9} s",
        if upper { "upper" } else { "lower" },
        second.t
    );
}

#[test]
fn the_clearance_gap_has_the_jacobian_and_convective_term_of_its_differences() {
    // (K1)–(K2) of docs/method.md §13.10 against finite differences of g = b/2 − s d itself,
    // on both sides of the centre line (s = ±1) and with the cam turning.
    use camchain::runtime::clearance::Clearance;
    let m = model();
    let view = Clearance::new(&m);
    let start = m.assemble(0.0).expect("assembles");
    let n = start.q.len();
    let g = |q: &[f64]| {
        let mut h = [0.0];
        view.constraint(q, &mut h);
        h[0]
    };
    for (lift, rate) in [(0.0006, 0.3), (-0.0004, -0.2), (0.0009, 0.05)] {
        let mut q = start.q.clone();
        q[0] = 1.3; // the cam angle: inside the rise
        q[1] += lift;
        let qd = vec![10.0, rate];
        let mut j = vec![0.0; n];
        view.constraint_jacobian(&q, &mut j);
        for k in 0..n {
            let step = 1e-7;
            let (mut up, mut down) = (q.clone(), q.clone());
            up[k] += step;
            down[k] -= step;
            let fd = (g(&up) - g(&down)) / (2.0 * step);
            // Central differences of a function of order 1e-3 m with derivatives of order 1:
            // truncation ~1e-14 · |g‴|, rounding ~1e-19/1e-7: 1e-8.
            assert!(
                (j[k] - fd).abs() < 1e-8,
                "lift {lift}: ∂g/∂q{k} {} against {fd}",
                j[k]
            );
        }
        let mut c = [0.0];
        view.constraint_bias(&q, &qd, &mut c);
        let along = |tau: f64| {
            let p: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + tau * b).collect();
            g(&p)
        };
        let plain = |tau: f64| (along(tau) - 2.0 * along(0.0) + along(-tau)) / (tau * tau);
        // Richardson from τ = 2e-4 and 1e-4 (as the contact scenes' tests): 1e-6 relative.
        let fd = (4.0 * plain(1e-4) - plain(2e-4)) / 3.0;
        assert!(
            (c[0] - fd).abs() < 1e-6 * (1.0 + fd.abs()),
            "lift {lift}: c {} against {fd}",
            c[0]
        );
        // The sign: the gap shrinks towards the flank the offset points to.
        let mut h = [0.0];
        m.constraint(&q, &mut h);
        assert!((g(&q) - (0.001 - h[0].abs())).abs() < 1e-15);
    }
}

#[test]
fn runs_that_hold_the_follower_on_its_cam_refuse_a_groove_with_backlash() {
    // A bilateral run and a sweep's metrics run hold the roller on its centre line, which a
    // groove with backlash does not: both refuse, naming the groove and the way out.
    let m = model();
    let state = || m.assemble(0.0).expect("assembles");
    let settings = &m.info().defaults;
    let bilateral = m
        .simulate(state(), settings)
        .map(|_| ())
        .expect_err("bilateral");
    let metrics = m
        .simulate_metrics(state(), settings, Default::default())
        .map(|_| ())
        .expect_err("metrics");
    for error in [bilateral.error.to_string(), metrics.error.to_string()] {
        assert!(
            error.contains("the groove of roller has a backlash of 0.002 m")
                && error.contains("only a one-sided run follows"),
            "{error}"
        );
    }
}
