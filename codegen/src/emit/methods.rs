//! One function specification per `Dynamics` method (M, F, Q, h, J, c, the drives, the
//! energies and powers, the loops' points), each with a doc in the model's own terms.

use super::contacts::geometry_spec;
use super::docs::ConstraintDocs;
use super::spec::{FunctionSpec, RETURN, param};
use crate::derive::Derivation;
use crate::expr::Id;
use crate::model::Model;

pub(super) fn function_specs(model: &Model, d: &mut Derivation) -> Vec<FunctionSpec> {
    let n = model.n();
    let docs = ConstraintDocs::new(model, d);
    let dy = &d.dynamics;
    let mass_outputs: Vec<(String, Id)> = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| (format!("m[{}]", i * n + j), dy.mass[i][j]))
        .collect();
    let f_outputs: Vec<(String, Id)> = dy
        .inertial
        .iter()
        .enumerate()
        .map(|(i, &e)| (format!("f[{i}]"), e))
        .collect();
    let q_outputs: Vec<(String, Id)> = dy
        .applied
        .iter()
        .enumerate()
        .map(|(i, &e)| (format!("applied[{i}]"), e))
        .collect();
    let rows = d.constraint_rows();
    let h_outputs: Vec<(String, Id)> = rows
        .iter()
        .enumerate()
        .map(|(k, row)| (format!("h[{k}]"), row.0))
        .collect();
    let j_outputs: Vec<(String, Id)> = rows
        .iter()
        .enumerate()
        .flat_map(|(k, row)| {
            row.1
                .iter()
                .enumerate()
                .map(move |(i, &e)| (format!("j[{}]", k * n + i), e))
        })
        .collect();
    let c_outputs: Vec<(String, Id)> = rows
        .iter()
        .enumerate()
        .map(|(k, row)| (format!("c[{k}]"), row.2))
        .collect();
    let all = |parts: &[&Vec<(String, Id)>]| parts.iter().flat_map(|p| p.iter().cloned()).collect();
    let mut specs = vec![
        FunctionSpec {
            doc: "M(q), eq. (13), row-major.".into(),
            name: "mass_matrix".into(),
            params: vec![param("q", "&[f64]"), param("m", "&mut [f64]")],
            ret: None,
            outputs: mass_outputs.clone(),
            tail: String::new(),
        },
        FunctionSpec {
            doc: "F(q, q̇), eq. (13).".into(),
            name: "inertial_forces".into(),
            params: vec![
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
                param("f", "&mut [f64]"),
            ],
            ret: None,
            outputs: f_outputs.clone(),
            tail: String::new(),
        },
        FunctionSpec {
            doc: "Q(q, q̇, t), eq. (13): gravity, springs, dampers.".into(),
            name: "applied_forces".into(),
            params: vec![
                param("t", "f64"),
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
                param("applied", "&mut [f64]"),
            ],
            ret: None,
            outputs: q_outputs.clone(),
            tail: String::new(),
        },
        FunctionSpec {
            doc: "M, F and Q sharing one evaluation of the kinematics.".into(),
            name: "equations".into(),
            params: vec![
                param("t", "f64"),
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
                param("m", "&mut [f64]"),
                param("f", "&mut [f64]"),
                param("applied", "&mut [f64]"),
            ],
            ret: None,
            outputs: all(&[&mass_outputs, &f_outputs, &q_outputs]),
            tail: String::new(),
        },
        FunctionSpec {
            doc: docs.constraint(),
            name: "constraint".into(),
            params: vec![param("q", "&[f64]"), param("h", "&mut [f64]")],
            ret: None,
            outputs: h_outputs,
            tail: String::new(),
        },
        FunctionSpec {
            doc: docs.jacobian(),
            name: "constraint_jacobian".into(),
            params: vec![param("q", "&[f64]"), param("j", "&mut [f64]")],
            ret: None,
            outputs: j_outputs.clone(),
            tail: String::new(),
        },
        FunctionSpec {
            doc: docs.bias(),
            name: "constraint_bias".into(),
            params: vec![
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
                param("c", "&mut [f64]"),
            ],
            ret: None,
            outputs: c_outputs.clone(),
            tail: String::new(),
        },
        FunctionSpec {
            doc: docs.terms(),
            name: "constraint_terms".into(),
            params: vec![
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
                param("j", "&mut [f64]"),
                param("c", "&mut [f64]"),
            ],
            ret: None,
            outputs: all(&[&j_outputs, &c_outputs]),
            tail: String::new(),
        },
    ];
    specs.push(geometry_spec(d));
    specs.push(prescribed_spec(d));
    specs.push(energy_spec(d));
    if model.bodies.iter().any(|b| b.joint.load.is_some()) {
        specs.push(FunctionSpec {
            doc: "Σ τ q̇, the power of the applied joint loads.".into(),
            name: "load_power".into(),
            params: vec![
                param("t", "f64"),
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
            ],
            ret: Some("f64"),
            outputs: vec![(RETURN.into(), d.energy.load_power)],
            tail: String::new(),
        });
    }
    if !d.loops.is_empty() {
        let outputs = d
            .loops
            .iter()
            .enumerate()
            .flat_map(|(l, terms)| {
                terms.points.iter().enumerate().flat_map(move |(side, p)| {
                    p.iter()
                        .enumerate()
                        .map(move |(k, &e)| (format!("out[{}][{k}]", 2 * l + side), e))
                })
            })
            .collect();
        specs.push(FunctionSpec {
            doc: "The points A and B of every loop's cut joint, ground coordinates.".into(),
            name: "loop_points".into(),
            params: vec![param("q", "&[f64]"), param("out", "&mut [[f64; 3]]")],
            ret: None,
            outputs,
            tail: String::new(),
        });
    }
    specs.push(FunctionSpec {
        doc: "Σ c q̇², the power the joint dampers dissipate.".into(),
        name: "damper_power".into(),
        params: vec![param("qd", "&[f64]")],
        ret: Some("f64"),
        outputs: vec![(RETURN.into(), d.energy.damper_power)],
        tail: String::new(),
    });
    specs
}

pub(super) fn prescribed_spec(d: &Derivation) -> FunctionSpec {
    let mut outputs = Vec::new();
    for drive in &d.drives {
        let i = drive.coordinate;
        outputs.push((format!("q[{i}]"), drive.motion[0]));
        outputs.push((format!("qd[{i}]"), drive.motion[1]));
        outputs.push((format!("qdd[{i}]"), drive.motion[2]));
    }
    FunctionSpec {
        doc: "q, q̇, q̈ of the driven coordinates at time t.".into(),
        name: "prescribed".into(),
        params: vec![
            param("t", "f64"),
            param("q", "&mut [f64]"),
            param("qd", "&mut [f64]"),
            param("qdd", "&mut [f64]"),
        ],
        ret: None,
        outputs,
        tail: String::new(),
    }
}

pub(super) fn energy_spec(d: &Derivation) -> FunctionSpec {
    let e = &d.energy;
    FunctionSpec {
        doc: "Kinetic energy from the body velocities; gravity and spring potentials.".into(),
        name: "energy".into(),
        params: vec![param("q", "&[f64]"), param("qd", "&[f64]")],
        ret: Some("rt::Energy"),
        outputs: vec![
            ("let kinetic".into(), e.kinetic),
            ("let gravity".into(), e.gravity),
            ("let spring".into(), e.spring),
        ],
        tail: "rt::Energy { kinetic, gravity, spring }".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::testing::derived;

    fn names(specs: &[FunctionSpec]) -> Vec<&str> {
        specs.iter().map(|s| s.name.as_str()).collect()
    }

    const ALWAYS: [&str; 11] = [
        "mass_matrix",
        "inertial_forces",
        "applied_forces",
        "equations",
        "constraint",
        "constraint_jacobian",
        "constraint_bias",
        "constraint_terms",
        "contact_geometry",
        "prescribed",
        "energy",
    ];

    #[test]
    fn one_spec_per_dynamics_method_the_model_needs() {
        let (m, mut d) = derived("double_pendulum");
        let specs = function_specs(&m, &mut d);
        assert_eq!(names(&specs), [&ALWAYS[..], &["damper_power"]].concat());
        // A loop adds its points.
        let (m, mut d) = derived("four_bar");
        let specs = function_specs(&m, &mut d);
        assert!(names(&specs).contains(&"loop_points"));
    }

    #[test]
    fn the_mass_matrix_is_row_major_and_h_has_a_row_per_equation() {
        let (m, mut d) = derived("double_pendulum");
        let specs = function_specs(&m, &mut d);
        let targets: Vec<&str> = specs[0].outputs.iter().map(|o| o.0.as_str()).collect();
        assert_eq!(targets, ["m[0]", "m[1]", "m[2]", "m[3]"]);
        assert_eq!(specs[0].outputs[1].1, d.dynamics.mass[0][1]);
        assert!(specs[4].outputs.is_empty());
        let (m, mut d) = derived("four_bar");
        let specs = function_specs(&m, &mut d);
        let h: Vec<&str> = specs[4].outputs.iter().map(|o| o.0.as_str()).collect();
        assert_eq!(h, ["h[0]", "h[1]"]);
        assert!(specs[4].doc.contains("loop `pin`"), "{}", specs[4].doc);
    }
}
