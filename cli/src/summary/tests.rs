use super::legacy::{self, SliceReport};
use super::*;
use camchain_runtime::{
    ContactGeometry, ContactLaw, Energy, LoopInfo, LoopKind, Sample, Simulate, Trajectory,
};

fn sample(t: f64, force: f64) -> Sample {
    Sample {
        t,
        q: vec![0.0],
        qd: vec![0.0],
        qdd: vec![0.0],
        lambda: vec![0.0],
        normal_force: vec![force],
        h: vec![0.0],
        contacts: vec![ContactGeometry::default()],
        drive: vec![0.0],
        energy: Energy::default(),
        dissipated: 0.0,
        driven_work: 0.0,
        dependent: vec![0].into(),
        in_contact: vec![true],
    }
}

/// The digest of `samples`, taken in one at a time.
fn digest(info: &ModelInfo, samples: &[Sample]) -> Digest {
    let mut digest = Digest::new(info);
    for s in samples {
        digest.add(s);
    }
    digest
}

/// The summary of a run from its digest and from its samples (the code before issue 25),
/// and the warnings of both.
fn both(
    info: &ModelInfo,
    settings: &SimSettings,
    trajectory: &Trajectory,
    one_sided: bool,
) -> ((String, Vec<String>), (String, Vec<String>)) {
    let digest = digest(info, &trajectory.samples);
    let wall = Duration::from_millis(1234);
    let streamed = render(&RunReport {
        label: "run",
        engine: "generated code",
        info,
        settings,
        digest: &digest,
        events: &trajectory.events,
        stats: trajectory.stats,
        wall,
    });
    let whole = legacy::render(&SliceReport {
        label: "run",
        engine: "generated code",
        info,
        settings,
        samples: &trajectory.samples,
        events: &trajectory.events,
        stats: trajectory.stats,
        wall,
    });
    (
        (streamed, result_warnings(info, &digest, one_sided)),
        (
            whole,
            legacy::result_warnings(info, &trajectory.samples, one_sided),
        ),
    )
}

#[test]
fn the_digest_summarises_every_built_in_run_as_the_whole_trajectory_did() {
    // Issue 25: the summary is now rendered from a digest taken in sample by sample; it must
    // be the text the whole trajectory gave, to the byte, on every built-in model's own run
    // (RK4 and DOP853; contacts fixed and turning, planar and spatial; loops listed one by
    // one and pooled; drives; camshaft_flywheel's one-sided run with its flights).
    let mut compared = 0;
    for (name, model) in camchain_models::ALL.iter() {
        let info = model.info();
        let settings = &info.defaults;
        let law = match info.restitution {
            Some(restitution) => ContactLaw::Unilateral { restitution },
            None => ContactLaw::Bilateral,
        };
        let state = model.assemble(0.0).expect("the built-in models assemble");
        let mut monitor = camchain_runtime::control::Unmonitored;
        let trajectory = model
            .simulate_monitored(state, settings, law, &mut monitor)
            .expect("the built-in models' own runs complete");
        let one_sided = info.restitution.is_some();
        let (streamed, whole) = both(info, settings, &trajectory, one_sided);
        assert_eq!(streamed, whole, "{name}");
        let digest = digest(info, &trajectory.samples);
        for k in 0..info.n_contacts() {
            assert_eq!(
                digest.lift_offs()[k],
                legacy::lift_off(&trajectory.samples, k),
                "{name}, contact {k}"
            );
        }
        assert_eq!(
            digest.energy_drift(),
            legacy::energy_drift(&trajectory.samples)
        );
        assert_eq!(
            digest.energy_scale(),
            legacy::energy_scale(&trajectory.samples)
        );
        compared += 1;
    }
    assert!(compared >= 20, "{compared} built-in models");
}

/// A small deterministic generator (a 64-bit LCG): the same samples on every run.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn chance(&mut self, p: f64) -> bool {
        self.next() < p
    }

    /// A value in [−1, 1), now and then NaN, ±∞ or an exact tie with `tie`.
    fn value(&mut self, tie: f64) -> f64 {
        let r = self.next();
        if r < 0.01 {
            f64::NAN
        } else if r < 0.015 {
            f64::INFINITY
        } else if r < 0.02 {
            f64::NEG_INFINITY
        } else if r < 0.05 {
            tie
        } else {
            2.0 * self.next() - 1.0
        }
    }
}

/// A model with two contacts (one on a fixed cam), `loops` loops of two equations, a driven
/// coordinate and a spatial layout.
fn synthetic_info(loops: usize) -> ModelInfo {
    let coordinate = |name: &str, driven| camchain_runtime::CoordinateInfo {
        name: name.into(),
        kind: JointKind::Revolute,
        driven,
    };
    let mut fixed = camchain_runtime::ContactInfo::knife("fixed");
    fixed.cam_moves = false;
    let mut turning = camchain_runtime::ContactInfo::knife("turning");
    turning.cam_coordinate = Some(0);
    turning.cam_moves = true;
    let n = 3;
    ModelInfo {
        name: "synthetic".into(),
        description: String::new(),
        coordinates: vec![
            coordinate("cam", true),
            coordinate("a", false),
            coordinate("b", false),
        ],
        contacts: vec![turning, fixed],
        loops: (0..loops)
            .map(|l| LoopInfo {
                name: format!("loop{l}"),
                kind: LoopKind::Revolute,
                equations: vec!["x".into(), if l % 2 == 0 { "y" } else { "turn" }.into()],
            })
            .collect(),
        spatial: true,
        initial: camchain_runtime::InitialGuess {
            q: vec![0.0; n],
            qd: vec![0.0; n],
            hold: vec![false; n],
            given_q: vec![false; n],
            given_qd: vec![false; n],
        },
        defaults: SimSettings {
            t_end: 1.0,
            dt_out: 0.1,
            integrator: IntegratorKind::Rk4,
            dt: 1e-3,
            rtol: 1e-9,
            atol: 1e-12,
        },
        restitution: None,
        parameters: Vec::new(),
    }
}

/// `count` samples of `info`'s model with random values, flights, re-partitions, sign
/// changes and ties.
fn synthetic_samples(info: &ModelInfo, count: usize, seed: u64) -> Vec<Sample> {
    let mut rng = Lcg(seed);
    let (n, m, nc) = (info.n(), info.n_constraints(), info.n_contacts());
    let sets: [std::sync::Arc<[usize]>; 3] = [vec![1].into(), vec![2].into(), vec![].into()];
    let mut dependent = sets[0].clone();
    let values =
        |rng: &mut Lcg, len: usize| -> Vec<f64> { (0..len).map(|_| rng.value(0.5)).collect() };
    (0..count)
        .map(|i| {
            if rng.chance(0.1) {
                dependent = sets[(rng.next() * 3.0) as usize % 3].clone();
            }
            let contacts = (0..nc)
                .map(|_| {
                    // Now and then the same geometry, at the largest pressure angle there is
                    // (90°): ties of the largest.
                    let (normal, direction) = if rng.chance(0.3) {
                        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
                    } else {
                        (
                            [rng.value(0.6), rng.value(0.8), 0.0],
                            [rng.value(0.0), 1.0, 0.0],
                        )
                    };
                    ContactGeometry {
                        position: [rng.value(0.5), rng.value(0.5), rng.value(0.5)],
                        x: rng.value(0.5),
                        normal,
                        axis: [0.0, 0.0, 1.0],
                        direction,
                        sliding_speed: rng.value(0.5),
                        ..ContactGeometry::default()
                    }
                })
                .collect();
            Sample {
                t: 0.01 * i as f64,
                q: values(&mut rng, n),
                qd: values(&mut rng, n),
                qdd: values(&mut rng, n),
                lambda: values(&mut rng, m),
                // Ties with 0: a force exactly zero is not negative.
                normal_force: (0..nc).map(|_| rng.value(0.0)).collect(),
                h: values(&mut rng, m),
                contacts,
                drive: values(&mut rng, n),
                energy: Energy {
                    kinetic: rng.value(0.5).abs(),
                    gravity: rng.value(0.5),
                    spring: rng.value(0.5),
                },
                dissipated: rng.value(0.5),
                driven_work: rng.value(0.5),
                dependent: dependent.clone(),
                in_contact: (0..nc).map(|_| !rng.chance(0.2)).collect(),
            }
        })
        .collect()
}

#[test]
fn the_digest_summarises_random_samples_as_the_whole_trajectory_did() {
    // Samples no integrator would give, to reach every branch: NaN and infinite values, ties
    // of the largest pressure angle, flights, re-partitions beyond the listed ones, normal
    // forces negative at the start or later; loops listed and pooled.
    for (loops, seed) in [(0, 1), (2, 2), (LISTED_LOOPS + 1, 3), (3, 4), (1, 5)] {
        let info = synthetic_info(loops);
        for count in [0, 1, 2, 5, 300] {
            let samples = synthetic_samples(&info, count, seed);
            let trajectory = Trajectory {
                samples,
                ..Trajectory::default()
            };
            for one_sided in [false, true] {
                let (streamed, whole) = both(&info, &info.defaults, &trajectory, one_sided);
                assert_eq!(streamed, whole, "{loops} loops, {count} samples");
            }
            let digest = digest(&info, &trajectory.samples);
            for k in 0..info.n_contacts() {
                assert_eq!(
                    digest.lift_offs()[k],
                    legacy::lift_off(&trajectory.samples, k)
                );
            }
            assert_eq!(
                render_repartitions(&info, &digest),
                legacy::render_repartitions(&info, &trajectory.samples)
            );
        }
    }
}

#[test]
fn lift_off_is_interpolated() {
    let info = synthetic_one_contact();
    let samples = [sample(0.0, 2.0), sample(1.0, 1.0), sample(2.0, -3.0)];
    let l = digest(&info, &samples).lift_offs()[0].unwrap();
    assert!(!l.from_start && (l.t - 1.25).abs() < 1e-15);
    assert!(digest(&info, &samples[..2]).lift_offs()[0].is_none());
    assert!(
        digest(&info, &samples[2..]).lift_offs()[0]
            .unwrap()
            .from_start
    );
}

/// One coordinate and one knife-edge contact.
fn synthetic_one_contact() -> ModelInfo {
    let mut info = one_sided_info(true);
    info.coordinates.truncate(1);
    info
}

/// A driven eccentric with one-sided contact: `cam_angle` driven, `lift` dependent in
/// contact and free in flight.
fn one_sided_info(cam_moves: bool) -> ModelInfo {
    let coordinate = |name: &str, driven| camchain_runtime::CoordinateInfo {
        name: name.into(),
        kind: camchain_runtime::JointKind::Revolute,
        driven,
    };
    let mut contact = camchain_runtime::ContactInfo::knife("face");
    contact.cam_moves = cam_moves;
    ModelInfo {
        name: "m".into(),
        description: String::new(),
        coordinates: vec![coordinate("cam_angle", true), coordinate("lift", false)],
        contacts: vec![contact],
        loops: Vec::new(),
        spatial: false,
        initial: camchain_runtime::InitialGuess {
            q: vec![0.0; 2],
            qd: vec![0.0; 2],
            hold: vec![false; 2],
            given_q: vec![false; 2],
            given_qd: vec![false; 2],
        },
        defaults: SimSettings {
            t_end: 1.0,
            dt_out: 0.1,
            integrator: IntegratorKind::Dop853,
            dt: 1e-3,
            rtol: 1e-9,
            atol: 1e-12,
        },
        restitution: None,
        parameters: Vec::new(),
    }
}

/// A sample of the one-sided eccentric at t: in contact (lift dependent) or flying.
fn phase_sample(t: f64, force: f64, flying: bool) -> Sample {
    let mut s = sample(t, force);
    s.q = vec![0.0, 0.0];
    s.qd = vec![0.0, 0.0];
    s.dependent = if flying { vec![] } else { vec![1] }.into();
    s.in_contact = vec![!flying];
    s
}

#[test]
fn a_one_sided_run_is_summarised_honestly() {
    // Issue 24: take-offs and landings were listed as re-partitions with a blank name,
    // the pressure angle was taken over flight samples and the cam was said to pull.
    let info = one_sided_info(true);
    let samples = [
        phase_sample(0.0, -0.07, false),
        phase_sample(0.1, 0.0, true),
        phase_sample(0.2, 12.0, false),
        phase_sample(0.3, 0.0, true),
    ];
    let run = digest(&info, &samples);
    assert_eq!(render_repartitions(&info, &run), "");
    assert!(result_warnings(&info, &run, true).is_empty());
    // The same samples of a bilateral run that starts pulling are warned about.
    assert_eq!(result_warnings(&info, &run, false).len(), 1);
    // A real re-partition between two samples in contact is still listed, by name.
    let mut moved = phase_sample(0.4, 10.0, false);
    moved.dependent = vec![0].into();
    let run = digest(&info, &[phase_sample(0.3, 10.0, false), moved]);
    let text = render_repartitions(&info, &run);
    assert!(
        text.contains("lift now independent, cam_angle dependent"),
        "{text}"
    );
}

#[test]
fn a_fixed_cam_has_no_pressure_angle() {
    let samples = [phase_sample(0.0, 5.0, false), phase_sample(0.1, 6.0, false)];
    let fixed_info = one_sided_info(false);
    let fixed = contact_lines(&fixed_info, &digest(&fixed_info, &samples)).join("\n");
    assert!(fixed.contains("no pressure angle is defined"), "{fixed}");
    let names: Vec<String> = digest(&fixed_info, &samples)
        .rows()
        .into_iter()
        .map(|r| r.0)
        .collect();
    assert!(
        !names.iter().any(|n| n.contains("pressure_angle")),
        "{names:?}"
    );
    let moving_info = one_sided_info(true);
    let moving = contact_lines(&moving_info, &digest(&moving_info, &samples)).join("\n");
    assert!(moving.contains("largest pressure angle"), "{moving}");
}

#[test]
fn numbers_are_compact() {
    assert_eq!(number(0.0), "0");
    assert_eq!(number(-1.5), "-1.500000");
    assert_eq!(number(6.94e-17), "6.940e-17");
}

#[test]
fn a_model_without_a_cam_is_warned_about_its_loops_not_a_contact_point() {
    // A coordinate moved far by assembly: the warning says what assembly solved for.
    let report = |_: &ModelInfo| AssemblyReport {
        changes: vec![camchain_runtime::assembly::AssemblyChange {
            coordinate: 1,
            velocity: false,
            from: 0.0,
            to: 2.0,
            cause: ChangeCause::Constraint,
            given: true,
        }],
        root: RootChoice::default(),
        redundant: Vec::new(),
    };
    let mut loops_only = synthetic_info(1);
    loops_only.contacts.clear();
    let warnings = assembly_warnings(&loops_only, &report(&loops_only), 1.0);
    assert!(
        warnings.len() == 1 && warnings[0].contains("to close the loops"),
        "{warnings:?}"
    );
    assert!(!warnings[0].contains("cam"), "{warnings:?}");
    let both = synthetic_info(1);
    let warnings = assembly_warnings(&both, &report(&both), 1.0);
    assert!(
        warnings[0].contains("on their cams and close the loops"),
        "{warnings:?}"
    );
}
