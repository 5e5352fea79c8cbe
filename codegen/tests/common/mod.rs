//! Models built directly in Rust for the codegen tests (independent of the RON loader).

#![allow(dead_code)]

use camchain_codegen::model::*;
use camchain_codegen::profile::Scalar;

fn revolute_z(anchor: [f64; 3], name: &str, spring: Option<(f64, f64)>) -> Joint {
    Joint {
        kind: JointKind::Revolute,
        axis: [0.0, 0.0, 1.0],
        anchor,
        coordinate: name.into(),
        spring: spring.map(|(k, c)| SpringDamper {
            stiffness: k,
            damping: c,
            rest: 0.0,
        }),
        prescribed: None,
        load: None,
    }
}

fn lamina(izz: f64) -> [[f64; 3]; 3] {
    [
        [izz / 2.0, 0.0, 0.0],
        [0.0, izz / 2.0, 0.0],
        [0.0, 0.0, izz],
    ]
}

fn body(name: &str, parent: Option<usize>, mass: f64, len: f64, izz: f64, joint: Joint) -> Body {
    Body {
        name: name.into(),
        parent,
        mass,
        com: [len / 2.0, 0.0, 0.0],
        inertia: lamina(izz),
        joint,
    }
}

/// y = −0.595 x + 0.5 x² + 0.5 x³ as a Scalar tree.
pub fn concave_profile() -> Scalar {
    use Scalar::*;
    let x = || Box::new(Var(0));
    let c = |v: f64| Box::new(Const(v));
    Add(
        Box::new(Add(
            Box::new(Mul(c(-0.595), x())),
            Box::new(Mul(c(0.5), Box::new(Mul(x(), x())))),
        )),
        Box::new(Mul(c(0.5), Box::new(Powi(x(), 3)))),
    )
}

/// The paper's four-body chain on the concave cam (docs/method.md §7).
pub fn paper_concave() -> Model {
    let prismatic = Joint {
        kind: JointKind::Prismatic,
        axis: [1.0, 0.0, 0.0],
        anchor: [0.1, 0.0, 0.0],
        coordinate: "q3".into(),
        spring: Some(SpringDamper {
            stiffness: 40.0,
            damping: 1.0,
            rest: 0.0,
        }),
        prescribed: None,
        load: None,
    };
    Model {
        parameters: Vec::new(),
        symbolic: Default::default(),
        runtime_checks: Vec::new(),
        parameters_at: Default::default(),
        name: "paper_concave".into(),
        description: String::new(),
        gravity: [0.0, -9.81, 0.0],
        bodies: vec![
            body(
                "body1",
                None,
                1.0,
                0.3,
                0.10,
                revolute_z([0.38, 0.80, 0.0], "q1", None),
            ),
            body(
                "body2",
                Some(0),
                0.5,
                0.1,
                0.01,
                revolute_z([0.3, 0.0, 0.0], "q2", Some((15.0, 1.0))),
            ),
            body("body3", Some(1), 1.0, 0.3, 0.10, prismatic),
            body(
                "body4",
                Some(2),
                1.0,
                0.3,
                0.10,
                revolute_z([0.3, 0.0, 0.0], "q4", Some((18.0, 1.0))),
            ),
        ],
        markers: vec![Marker {
            name: "A".into(),
            body: 3,
            position: [0.3, 0.0, 0.0],
        }],
        contacts: vec![Contact {
            name: "A".into(),
            marker: 0,
            follower: Follower::Knife,
            profile: Profile::Explicit {
                source: "-0.595*x + 0.5*x*x + 0.5*x.powi(3)".into(),
                f: concave_profile(),
            },
            cam_body: None,
            origin: [0.0; 3],
            x_axis: [1.0, 0.0, 0.0],
            y_axis: [0.0, 1.0, 0.0],
            range: None,
            design: None,
            backlash: 0.0,
            taper: 0.0,
        }],
        loops: Vec::new(),
        initial: Initial {
            q: vec![-std::f64::consts::FRAC_PI_2 - 0.1, 0.0, 0.0, 0.0],
            qd: vec![0.0; 4],
            hold: vec![true, true, false, true],
            given_q: vec![true; 4],
            given_qd: vec![false; 4],
        },
        simulation: Simulation {
            t_end: 10.0,
            dt_out: 0.01,
            integrator: IntegratorKind::Dopri5,
            dt: 1e-3,
            rtol: 1e-10,
            atol: 1e-12,
            restitution: None,
            formulation: Default::default(),
        },
        files: Vec::new(),
    }
}

/// A spatial tree with a branch: non-parallel revolute axes, a prismatic joint along a
/// skew direction, off-axis centres of mass, full inertia tensors, gravity along −z, and
/// a contact on a cam in a tilted plane.
pub fn spatial_tree() -> Model {
    let inertia = [
        [0.05, 0.004, -0.002],
        [0.004, 0.04, 0.003],
        [-0.002, 0.003, 0.03],
    ];
    let joint = |kind, axis: [f64; 3], anchor, name: &str, spring| {
        let norm = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        Joint {
            kind,
            axis: axis.map(|a| a / norm),
            anchor,
            coordinate: name.into(),
            spring,
            prescribed: None,
            load: None,
        }
    };
    let sd = Some(SpringDamper {
        stiffness: 5.0,
        damping: 0.3,
        rest: 0.1,
    });
    let b = |name: &str, parent, mass, com, joint| Body {
        name: name.into(),
        parent,
        mass,
        com,
        inertia,
        joint,
    };
    use JointKind::*;
    let profile = Scalar::Sub(
        Box::new(Scalar::Mul(
            Box::new(Scalar::Const(0.2)),
            Box::new(Scalar::Call(
                camchain_codegen::profile::Func::Sin,
                Box::new(Scalar::Var(0)),
            )),
        )),
        Box::new(Scalar::Mul(
            Box::new(Scalar::Const(0.1)),
            Box::new(Scalar::Powi(Box::new(Scalar::Var(0)), 2)),
        )),
    );
    let s = 0.6f64;
    let c = 0.8f64;
    Model {
        parameters: Vec::new(),
        symbolic: Default::default(),
        runtime_checks: Vec::new(),
        parameters_at: Default::default(),
        name: "spatial_tree".into(),
        description: String::new(),
        gravity: [0.0, 0.0, -9.81],
        bodies: vec![
            b(
                "base",
                None,
                2.0,
                [0.05, 0.02, 0.1],
                joint(Revolute, [0.0, 0.0, 1.0], [0.0, 0.0, 0.5], "a", None),
            ),
            b(
                "arm",
                Some(0),
                1.5,
                [0.2, 0.03, -0.01],
                joint(Revolute, [0.0, 1.0, 0.0], [0.1, 0.0, 0.2], "b", sd),
            ),
            b(
                "slider",
                Some(1),
                0.8,
                [0.1, -0.02, 0.04],
                joint(Prismatic, [1.0, 0.2, 0.1], [0.4, 0.0, 0.0], "c", sd),
            ),
            b(
                "wrist",
                Some(2),
                0.6,
                [0.07, 0.05, 0.0],
                joint(Revolute, [1.0, 1.0, 0.0], [0.2, 0.0, 0.0], "d", None),
            ),
            b(
                "side",
                Some(1),
                0.4,
                [0.0, 0.1, 0.02],
                joint(Revolute, [0.3, 0.0, 1.0], [0.2, 0.1, 0.0], "e", sd),
            ),
        ],
        markers: vec![Marker {
            name: "P".into(),
            body: 3,
            position: [0.25, 0.05, -0.03],
        }],
        contacts: vec![Contact {
            name: "P".into(),
            marker: 0,
            follower: Follower::Knife,
            profile: Profile::Explicit {
                source: "0.2*x.sin() - 0.1*x*x".into(),
                f: profile,
            },
            cam_body: None,
            origin: [0.1, -0.2, 0.3],
            x_axis: [1.0, 0.0, 0.0],
            y_axis: [0.0, s, c],
            range: None,
            design: None,
            backlash: 0.0,
            taper: 0.0,
        }],
        loops: Vec::new(),
        initial: Initial {
            q: vec![0.0; 5],
            qd: vec![0.0; 5],
            hold: vec![false; 5],
            given_q: vec![false; 5],
            given_qd: vec![false; 5],
        },
        simulation: Simulation {
            t_end: 1.0,
            dt_out: 0.01,
            integrator: IntegratorKind::Dopri5,
            dt: 1e-3,
            rtol: 1e-9,
            atol: 1e-9,
            restitution: None,
            formulation: Default::default(),
        },
        files: Vec::new(),
    }
}
