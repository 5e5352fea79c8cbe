//! The contacts' functions: `contact_geometry` (where and how every contact touches), the
//! `contact_kinematics_<k>` helpers with their dispatch, and the nodes they read.

use super::function::emit_function_given;
use super::literals::ALLOW_LITERALS;
use super::spec::{FunctionSpec, Param, param};
use crate::contact::ContactTerms;
use crate::derive::Derivation;
use crate::expr::{Graph, Id, OpCount};
use crate::model::Model;

/// Every node a contact's outputs read (geometry and kinematics), for the run-time
/// parameters' `derive`.
pub(super) fn contact_output_roots(c: &ContactTerms) -> Vec<Id> {
    let r = &c.relative;
    let mut roots: Vec<Id> = c
        .position
        .iter()
        .chain(&c.cam_point)
        .chain(&c.normal)
        .chain(&r.point)
        .chain(&r.axis)
        .chain(&r.direction)
        .chain(&r.xy)
        .chain(&r.convective)
        .copied()
        .collect();
    roots.extend([c.force_scale, c.parameter, c.curvature, c.sliding]);
    roots.extend(r.columns.iter().flatten());
    if let Some(z) = c.cam_height {
        roots.extend([z, r.height, r.height_convective]);
        roots.extend(&r.height_columns);
    }
    roots
}

/// `out.<field>` targets of a contact's geometry (`prefix` = `out[k].` or `out.geometry.`).
pub(super) fn geometry_outputs(g: &mut Graph, c: &ContactTerms, prefix: &str) -> Vec<(String, Id)> {
    let mut outputs = Vec::new();
    let r = &c.relative;
    let vectors = [
        ("position", c.position),
        ("follower", r.point),
        ("normal", c.normal),
        ("axis", r.axis),
    ];
    for (field, v) in vectors {
        for (a, &p) in v.iter().enumerate() {
            outputs.push((format!("{prefix}{field}[{a}]"), p));
        }
    }
    let direction = unit_vector(g, r.direction);
    for (a, &p) in direction.iter().enumerate() {
        outputs.push((format!("{prefix}direction[{a}]"), p));
    }
    outputs.extend([
        (format!("{prefix}x"), c.cam_point[0]),
        (format!("{prefix}y"), c.cam_point[1]),
        (format!("{prefix}force_scale"), c.force_scale),
        (format!("{prefix}parameter"), c.parameter),
        (format!("{prefix}curvature"), c.curvature),
        (format!("{prefix}sliding_speed"), c.sliding),
    ]);
    if let Some(z) = c.cam_height {
        outputs.push((format!("{prefix}z"), z));
    }
    if let Some(radial) = c.radial {
        for (a, &p) in radial.iter().enumerate() {
            outputs.push((format!("{prefix}radial[{a}]"), p));
        }
    }
    outputs
}

/// v/|v| (the direction of a follower's motion).
pub(super) fn unit_vector(g: &mut Graph, v: [Id; 3]) -> [Id; 3] {
    g.set_section("outputs: the follower's direction of motion");
    let squares: Vec<Id> = v.iter().map(|&c| g.mul(c, c)).collect();
    let norm2 = g.sum(squares);
    let norm = g.sqrt(norm2);
    v.map(|c| g.div(c, norm))
}

pub(super) fn geometry_spec(d: &mut Derivation) -> FunctionSpec {
    let mut outputs = Vec::new();
    let contacts = d.contacts.clone();
    for (k, c) in contacts.iter().enumerate() {
        outputs.extend(geometry_outputs(&mut d.graph, c, &format!("out[{k}].")));
    }
    FunctionSpec {
        doc: "Where and how every contact touches: the contact point in ground and cam \
              coordinates, the follower point, the normal, the force scale, the profile's \
              parameter and curvature there, the follower's direction of motion, the sliding \
              speed."
            .into(),
        name: "contact_geometry".into(),
        params: vec![
            param("q", "&[f64]"),
            param("qd", "&[f64]"),
            param("out", "&mut [rt::ContactGeometry]"),
        ],
        ret: None,
        outputs,
        tail: String::new(),
    }
}

pub(super) fn contact_kinematics_dispatch(model: &Model, parametric: bool) -> String {
    let derived = if parametric { "&self.derived, " } else { "" };
    if model.contacts.is_empty() {
        return "/// No contact: nothing to write.\n\
                fn contact_kinematics_into(&self, _q: &[f64], _qd: &[f64], _k: usize, _out: &mut rt::ContactKinematics) {}\n"
            .to_string();
    }
    let body = if model.contacts.len() == 1 {
        format!("if k == 0 {{ contact_kinematics_0({derived}q, qd, out); }}")
    } else {
        let arms: String = (0..model.contacts.len())
            .map(|k| format!("{k} => contact_kinematics_{k}({derived}q, qd, out),\n"))
            .collect();
        format!("match k {{\n{arms}_ => {{}}\n}}")
    };
    format!(
        "/// f1, f2, J1, J2 and the convective terms of contact `k` into `out` (unchanged for an \
         unknown k).\n\
         fn contact_kinematics_into(&self, q: &[f64], qd: &[f64], k: usize, out: &mut rt::ContactKinematics) {{\n\
         {body}\n}}\n"
    )
}

/// The specifications of `contact_kinematics_<k>`: every contact's geometry and its
/// follower point's cam-frame kinematics.
pub(super) fn contact_kinematics_specs(
    model: &Model,
    d: &mut Derivation,
    parametric: bool,
) -> Vec<FunctionSpec> {
    let n = model.n();
    let contacts = d.contacts.clone();
    contacts
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let mut outputs = geometry_outputs(&mut d.graph, c, "out.geometry.");
            let r = &c.relative;
            outputs.push(("out.x".to_string(), r.xy[0]));
            outputs.push(("out.y".to_string(), r.xy[1]));
            for i in 0..n {
                outputs.push((format!("out.j1[{i}]"), r.columns[i][0]));
            }
            for i in 0..n {
                outputs.push((format!("out.j2[{i}]"), r.columns[i][1]));
            }
            outputs.push(("out.conv1".to_string(), r.convective[0]));
            outputs.push(("out.conv2".to_string(), r.convective[1]));
            if c.cam_height.is_some() {
                outputs.push(("out.z".to_string(), r.height));
                for (i, &j3) in r.height_columns.iter().enumerate() {
                    outputs.push((format!("out.j3[{i}]"), j3));
                }
                outputs.push(("out.conv3".to_string(), r.height_convective));
            }
            FunctionSpec {
                doc: format!(
                    "Geometry of contact `{}` and its follower point's cam-frame kinematics, \
                     into `out` (J1 and J2 of length {n}).",
                    c_name(model, k)
                ),
                name: format!("contact_kinematics_{k}"),
                params: [
                    parametric.then_some(Param {
                        name: "derived",
                        ty: "&Derived",
                        always_used: false,
                    }),
                    Some(param("q", "&[f64]")),
                    Some(param("qd", "&[f64]")),
                    Some(Param {
                        name: "out",
                        ty: "&mut rt::ContactKinematics",
                        always_used: true,
                    }),
                ]
                .into_iter()
                .flatten()
                .collect(),
                ret: None,
                outputs,
                tail: String::new(),
            }
        })
        .collect()
}

/// Emits the `contact_kinematics_<k>` functions.
pub(super) fn contact_kinematics_helpers(
    d: &Derivation,
    specs: &[FunctionSpec],
    counts: &mut Vec<(String, OpCount)>,
    derived: &[(Id, String)],
) -> String {
    let mut out = String::new();
    for spec in specs {
        let (text, count) = emit_function_given(d, spec, "", false, derived);
        out.push_str(ALLOW_LITERALS);
        out.push('\n');
        out.push_str(&text);
        counts.push((spec.name.clone(), count));
    }
    out
}

pub(super) fn c_name(model: &Model, k: usize) -> &str {
    &model.contacts[k].name
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::testing::{derived, model};

    #[test]
    fn without_contacts_the_dispatch_writes_nothing() {
        let text = contact_kinematics_dispatch(&model("double_pendulum"), true);
        assert!(text.starts_with("/// No contact: nothing to write.\n"));
        assert!(text.contains("_k: usize"));
    }

    #[test]
    fn one_contact_is_dispatched_by_an_if_many_by_a_match() {
        let m = model("cycloidal_roller");
        let text = contact_kinematics_dispatch(&m, true);
        assert!(text.contains("if k == 0 { contact_kinematics_0(&self.derived, q, qd, out); }"));
        let mut two = m.clone();
        two.contacts.push(two.contacts[0].clone());
        let text = contact_kinematics_dispatch(&two, false);
        assert!(text.contains("match k {\n0 => contact_kinematics_0(q, qd, out),\n1 => contact_kinematics_1(q, qd, out),\n_ => {}\n}"));
    }

    #[test]
    fn a_contacts_geometry_fills_every_field_of_its_output() {
        let (m, mut d) = derived("cycloidal_roller");
        let c = d.contacts[0].clone();
        let outputs = geometry_outputs(&mut d.graph, &c, "out[0].");
        let targets: Vec<&str> = outputs.iter().map(|o| o.0.as_str()).collect();
        // Position, follower, normal, axis and direction (3 each), then six scalars.
        assert_eq!(targets.len(), 5 * 3 + 6);
        assert_eq!(targets[0], "out[0].position[0]");
        assert_eq!(targets[12], "out[0].direction[0]");
        assert_eq!(targets[20], "out[0].sliding_speed");
        let specs = contact_kinematics_specs(&m, &mut d, true);
        assert_eq!(specs.len(), 1);
        assert_eq!(specs[0].name, "contact_kinematics_0");
        assert_eq!(specs[0].params[0].name, "derived");
        // The geometry, x and y, J1 and J2 (n each), the two convective terms.
        assert_eq!(specs[0].outputs.len(), 21 + 2 + 2 * m.n() + 2);
    }

    #[test]
    fn the_direction_of_motion_is_a_unit_vector() {
        let mut g = crate::expr::Graph::new();
        let v = [g.var("a"), g.var("b"), g.var("c")];
        let u = unit_vector(&mut g, v);
        let values = g.eval(&u, &[3.0, 0.0, -4.0]);
        // (3, 0, −4)/5: exact in binary up to one rounding of each division.
        assert_eq!(values, [0.6, 0.0, -0.8]);
    }
}
