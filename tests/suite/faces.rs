//! Face cams (docs/method.md §13.7): a groove in the cam's face, the roller's centre on its
//! centre line, against closed forms.
//!
//! `models/face_cam.ron`: the centre line designed from a dwell-rise-dwell-return program of
//! modified sine laws for an oscillating roller follower on a preloaded torsion spring, the
//! camshaft at constant speed ω. Expected values come from the follower's geometry by its own
//! formulas (the law of cosines for the arm's base angle), the law's closed form
//! (`camchain_runtime::motion_law`, checked against Norton's tables there), and the arm's
//! equation of motion about its pivot:
//!
//! ```text
//! N ((P − A) × n)·ẑ = I_A ψ̈ + k (ψ − ψ_rest) + c ψ̇,   ψ = φ₀ + s(ωt)
//! ```
//!
//! (gravity is along the pivot's axis: no moment). The groove's inner flank pushes (N > 0)
//! where the right-hand side is positive, the outer one pulls where it is negative: each sign
//! change is a flank change, reported by the run as an event.

use crate::eccentric::file_parameters;
use camchain::runtime::events::EventKind;
use camchain::runtime::motion_law::{Law, MotionProgram, Segment};
use camchain::runtime::{Dynamics, SimSettings, Simulate};
use camchain_models as models;
use std::f64::consts::{FRAC_PI_2, TAU};

/// The arm's pivot in the ground (and design) frame, as the model file places it.
const PIVOT: [f64; 2] = [0.045, 0.06];

/// face_cam's program and the arm's dimensions, from its file.
struct FaceCam {
    program: MotionProgram,
    /// φ₀: the arm's angle when the roller is on the prime circle.
    base_angle: f64,
    /// I_A: the arm's moment of inertia about its pivot (kg m²).
    inertia: f64,
    kt: f64,
    rest: f64,
    c: f64,
    omega: f64,
}

impl FaceCam {
    fn new() -> Self {
        let p = file_parameters("face_cam");
        let d = |deg: f64| deg.to_radians();
        let seg = |law, degrees, lift| Segment {
            law,
            angle: d(degrees),
            lift,
        };
        let swing = p("swing");
        let program = MotionProgram::new(&[
            seg(Law::ModifiedSine, 90.0, swing),
            seg(Law::Dwell, 90.0, swing),
            seg(Law::ModifiedSine, 90.0, 0.0),
            seg(Law::Dwell, 90.0, 0.0),
        ])
        .expect("the model's program");
        // The law of cosines: the arm (a) from the pivot (d from the centre) reaches the
        // prime circle R_b + ρ, turned counterclockwise from the direction to the centre.
        let (arm, prime) = (p("arm"), p("R_b") + p("rho"));
        let dist = PIVOT[0].hypot(PIVOT[1]);
        let towards = (-PIVOT[1]).atan2(-PIVOT[0]);
        let base_angle =
            towards + ((dist * dist + arm * arm - prime * prime) / (2.0 * dist * arm)).acos();
        // The rocker's Izz about its centre of mass (0.0001 in the file) plus m (a/2)².
        let inertia = 0.0001 + 0.25 * (arm / 2.0).powi(2);
        FaceCam {
            program,
            base_angle,
            inertia,
            kt: p("kt"),
            rest: p("rest"),
            c: p("c"),
            omega: p("omega"),
        }
    }

    /// The moment about the pivot that the groove must exert at cam angle θ, speed ω.
    fn moment(&self, theta: f64, omega: f64) -> f64 {
        let [s, s1, s2, _] = self.program.eval(theta);
        self.inertia * s2 * omega * omega
            + self.kt * (self.base_angle + s - self.rest)
            + self.c * s1 * omega
    }
}

#[test]
fn the_face_cam_moves_its_arm_by_the_law_with_the_groove_force_of_its_moment() {
    let cam = FaceCam::new();
    // The model file's comment says the arm hangs straight down at the base: φ₀ = −π/2.
    assert!(
        (cam.base_angle + FRAC_PI_2).abs() < 1e-15,
        "{}",
        cam.base_angle
    );
    let model = models::by_name("face_cam").expect("built in");
    let settings = model.info().defaults.clone();
    let run = model
        .simulate(model.assemble(0.0).expect("assembles"), &settings)
        .unwrap_or_else(|f| panic!("{}", f.error));
    let swing = model
        .info()
        .coordinates
        .iter()
        .position(|c| c.name == "swing_angle")
        .expect("swing_angle");
    let omega = cam.omega;
    let lift = 0.2;
    let [mut s_err, mut v_err, mut a_err, mut n_err] = [0.0f64; 4];
    let mut scale = 0.0f64;
    for sample in &run.samples {
        let theta = omega * sample.t;
        let [s, s1, s2, _] = cam.program.eval(theta);
        s_err = s_err.max((sample.q[swing] - (cam.base_angle + s)).abs() / lift);
        v_err = v_err.max((sample.qd[swing] - omega * s1).abs() / (lift * omega));
        a_err = a_err.max((sample.qdd[swing] - omega * omega * s2).abs() / (lift * omega * omega));
        // The groove's force times its lever about the pivot is the moment the arm needs.
        let contact = &sample.contacts[0];
        let arm = [
            contact.follower[0] - PIVOT[0],
            contact.follower[1] - PIVOT[1],
        ];
        let lever = arm[0] * contact.normal[1] - arm[1] * contact.normal[0];
        let moment = cam.moment(theta, omega);
        n_err = n_err.max((sample.normal_force[0] * lever - moment).abs());
        scale = scale.max(moment.abs());
    }
    println!(
        "face_cam against its law over three turns: angle {s_err:.1e}, rate {v_err:.1e}, \
         acceleration {a_err:.1e} (of the swing, ×ω, ×ω²); groove moment {:.1e} of its largest \
         {scale:.3} N m",
        n_err / scale
    );
    // The arm has no freedom (its angle is the dependent coordinate, set by the constraint
    // to round-off each step): the law holds to rounding, as for the disc cams' designs
    // (designs.rs demands 1e-9; measured ~1e-13 there).
    assert!(s_err < 1e-9 && v_err < 1e-9 && a_err < 1e-9);
    // The moment balance holds to rounding of λ's solve (relative 1e-9: the dynamics are
    // evaluated exactly, the law's values too).
    assert!(n_err < 1e-9 * scale, "moment {n_err:e} N m off");
}

#[test]
fn the_roller_touches_the_designed_inner_flank_at_the_designs_pressure_angle() {
    // The design's own closed form (`CamDesign::at`: the pitch point moved in by ρ along the
    // normal of the construction) against the generated code's contact point (the centre
    // line's nearest point, moved in along the normal it solves for).
    let source = models::source("face_cam").expect("built in");
    let file = std::path::PathBuf::from("models/face_cam.ron");
    let parsed = camchain_codegen::schema::parse_model(source, &file).expect("valid");
    let design = parsed.contacts[0]
        .design
        .clone()
        .expect("designed from a law");
    let model = models::by_name("face_cam").expect("built in");
    let settings = SimSettings {
        t_end: TAU / FaceCam::new().omega,
        ..model.info().defaults.clone()
    };
    let run = model
        .simulate(model.assemble(0.0).expect("assembles"), &settings)
        .unwrap_or_else(|f| panic!("{}", f.error));
    let omega = FaceCam::new().omega;
    let [mut point, mut angle] = [0.0f64; 2];
    for sample in &run.samples {
        let at = design.at(omega * sample.t);
        let c = &sample.contacts[0];
        point = point.max((c.x - at.contact[0]).hypot(c.y - at.contact[1]));
        angle = angle.max((c.pressure_angle() - at.pressure_angle).abs());
    }
    println!("face_cam's flank against its design: contact point {point:.1e} m, angle {angle:.1e}");
    // Both exact, the angles signed alike (counterclockwise from the direction of motion to
    // the normal): rounding of a 50 mm point (1e-15 m) and of an angle through atan2.
    assert!(point < 1e-13, "contact point {point:e} m");
    assert!(angle < 1e-12, "pressure angle {angle:e} rad");
}

#[test]
fn a_bilateral_face_cam_run_reports_each_flank_change_where_the_moment_changes_sign() {
    let cam = FaceCam::new();
    let model = models::by_name("face_cam").expect("built in");
    let omega = cam.omega;
    let settings = SimSettings {
        t_end: 2.0 * TAU / omega,
        ..model.info().defaults.clone()
    };
    let run = model
        .simulate(Simulate::assemble(model, 0.0).expect("assembly"), &settings)
        .unwrap_or_else(|f| panic!("{}", f.error));
    let changes: Vec<(EventKind, f64)> = run
        .events
        .iter()
        .map(|e| (e.kind, (omega * e.t).rem_euclid(TAU)))
        .collect();
    // The closed form's sign changes over a turn, sampled every 1e-4 rad.
    let step = 1e-4;
    let per_turn = (0..(TAU / step) as usize)
        .filter(|&i| {
            let (a, b) = (i as f64 * step, (i + 1) as f64 * step);
            (cam.moment(a, omega) > 0.0) != (cam.moment(b, omega) > 0.0)
        })
        .count();
    assert!(
        per_turn >= 2,
        "the outer flank never pulls at the model's speed"
    );
    assert_eq!(changes.len(), 2 * per_turn, "{changes:?}");
    for (k, (kind, angle)) in changes.iter().enumerate() {
        // Alternating, the first to the outer flank (the run starts in a dwell, N > 0).
        let expected = if k % 2 == 0 {
            EventKind::ForceBecameNegative
        } else {
            EventKind::ForceBecamePositive
        };
        assert_eq!(*kind, expected, "change {k}");
        // The closed form changes sign within 1e-6 rad of each reported angle (located to
        // 1e-9 s, ω·1e-9 = 4e-8 rad), the way the event says.
        let (before, after) = (
            cam.moment(angle - 1e-6, omega),
            cam.moment(angle + 1e-6, omega),
        );
        let agrees = match kind {
            EventKind::ForceBecameNegative => before > 0.0 && after < 0.0,
            EventKind::ForceBecamePositive => before < 0.0 && after > 0.0,
            EventKind::LiftOff | EventKind::Impact { .. } => false,
        };
        assert!(
            agrees,
            "{kind:?} at {angle} rad: moment {before:e} → {after:e}"
        );
    }
    println!(
        "face_cam at {omega} rad/s: {} flank changes in two turns, each within 1e-6 rad of the \
         moment's sign change",
        changes.len()
    );
}

#[test]
fn generated_and_numeric_face_cams_run_alike() {
    let generated = models::by_name("face_cam").expect("built in");
    let path = format!("{}/models/face_cam.ron", env!("CARGO_MANIFEST_DIR"));
    let numeric = camchain_reference::NumericModel::load(std::path::Path::new(&path))
        .unwrap_or_else(|e| panic!("{e}"));
    let settings = SimSettings {
        t_end: 0.1,
        ..generated.info().defaults.clone()
    };
    let run = |m: &dyn Dynamics| {
        m.simulate(m.assemble(0.0).expect("assembles"), &settings)
            .unwrap_or_else(|f| panic!("{}", f.error))
    };
    let (a, b) = (run(generated), run(&numeric));
    assert_eq!(a.samples.len(), b.samples.len());
    let mut worst = 0.0f64;
    for (x, y) in a.samples.iter().zip(&b.samples) {
        for (u, v) in x.normal_force.iter().zip(&y.normal_force) {
            worst = worst.max((u - v).abs() / (1.0 + v.abs()));
        }
        for (u, v) in [
            (x.contacts[0].x, y.contacts[0].x),
            (x.contacts[0].y, y.contacts[0].y),
        ] {
            worst = worst.max((u - v).abs());
        }
    }
    println!("face_cam generated against numeric over 0.1 s: {worst:.1e}");
    // Two evaluations of the same dynamics by different routes (symbolic against recursive,
    // Newton from a guess against a global scan): the runs' rounding, amplified by the
    // integrator's step choices, stays below 1e-9 (measured ~1e-12).
    assert!(worst < 1e-9, "{worst:e}");
}

#[test]
fn a_radial_follower_in_a_polar_groove_moves_by_the_centre_line() {
    // tests/numeric_models/radial_groove.ron (the numeric reference: no compilation): the
    // roller's centre on the ground's x axis, in the groove whose centre line is r(φ) = 0.05
    // + 0.01 cos 3φ, the cam turned by ωt. The follower sits at the cam-frame angle φ = −ωt:
    // x(t) = r(−ωt), and the groove's force along its normal n, whose x component is
    // r/√(r² + r′²), accelerates the follower's 0.2 kg: N = m ẍ √(r² + r′²)/r.
    let path = format!(
        "{}/tests/numeric_models/radial_groove.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    let model = camchain_reference::NumericModel::load(std::path::Path::new(&path))
        .unwrap_or_else(|e| panic!("{e}"));
    let omega = 10.0;
    let settings = model.info().defaults.clone();
    let run = model
        .simulate(model.assemble(0.0).expect("assembles"), &settings)
        .unwrap_or_else(|f| panic!("{}", f.error));
    let reach = model
        .info()
        .coordinates
        .iter()
        .position(|c| c.name == "reach")
        .expect("reach");
    let [mut x_err, mut v_err, mut n_err] = [0.0f64; 3];
    for sample in &run.samples {
        let phase = 3.0 * omega * sample.t;
        let r = 0.05 + 0.01 * phase.cos();
        let dr = 0.03 * phase.sin(); // dr/dφ at φ = −ωt
        let v = -0.03 * omega * phase.sin();
        let a = -0.09 * omega * omega * phase.cos();
        x_err = x_err.max((sample.q[reach] - r).abs());
        v_err = v_err.max((sample.qd[reach] - v).abs());
        let force = 0.2 * a * (r * r + dr * dr).sqrt() / r;
        n_err = n_err.max((sample.normal_force[0] - force).abs());
    }
    println!(
        "radial follower in a polar groove: x {x_err:.1e} m, ẋ {v_err:.1e} m/s, N {n_err:.1e} N"
    );
    // No degree of freedom: the constraint holds to round-off each step, the force to the
    // rounding of its solve (|N| ≤ 0.2·0.09·ω²·1.1 ≈ 2 N).
    assert!(x_err < 1e-14 && v_err < 1e-12, "{x_err:e} {v_err:e}");
    assert!(n_err < 1e-11, "normal force {n_err:e} N");
}
