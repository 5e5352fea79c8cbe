//! `INFO`: the model's static description (coordinates, contacts, loops, initial guess,
//! default settings, run-time parameters) as an `rt::ModelInfo`.

use super::literals::{ALLOW_LITERALS, float_list, lit};
use crate::model::{JointKind, Model};

pub(super) fn info_static(model: &Model) -> String {
    let coords: Vec<String> = model
        .bodies
        .iter()
        .map(|b| {
            let kind = b.joint.kind.keyword();
            format!(
                "rt::CoordinateInfo {{ name: {:?}.to_string(), kind: rt::JointKind::{kind}, driven: {} }}",
                b.joint.coordinate,
                b.joint.prescribed.is_some()
            )
        })
        .collect();
    let contacts: Vec<String> = model
        .contacts
        .iter()
        .map(|c| {
            let follower = c.follower.kind().keyword();
            let profile = match c.profile {
                crate::model::Profile::Explicit { .. } => "Explicit",
                crate::model::Profile::Polar { .. } => "Polar",
                crate::model::Profile::Parametric { .. } => "Parametric",
                crate::model::Profile::Surface { .. } => "Surface",
                crate::model::Profile::Barrel { .. } => "Barrel",
                crate::model::Profile::Revolution { .. } => "Revolution",
                crate::model::Profile::Face { .. } => "Face",
            };
            let cam_coordinate = match c.cam_body {
                Some(b) if model.bodies[b].joint.kind == JointKind::Revolute => {
                    format!("Some({b})")
                }
                _ => "None".to_string(),
            };
            format!(
                "rt::ContactInfo {{ name: {:?}.to_string(), follower: rt::FollowerKind::{follower}, \
                 profile: rt::ProfileKind::{profile}, cam_coordinate: {cam_coordinate}, \
                 cam_moves: {}, backlash: {}, taper: {} }}",
                c.name,
                c.cam_body.is_some(),
                super::literals::lit(c.backlash),
                super::literals::lit(c.taper)
            )
        })
        .collect();
    let loops: Vec<String> = model
        .loops
        .iter()
        .map(|l| {
            let kind = l.kind.keyword();
            let equations: Vec<String> =
                l.equations().iter().map(|e| format!("{e:?}.to_string()")).collect();
            format!(
                "rt::LoopInfo {{ name: {:?}.to_string(), kind: rt::LoopKind::{kind}, equations: Vec::from([{}]) }}",
                l.name,
                equations.join(", ")
            )
        })
        .collect();
    let s = &model.simulation;
    let integrator = s.integrator.keyword();
    format!(
        "/// Static description of the model.\n\
         {ALLOW_LITERALS}\n\
         static INFO: ::std::sync::LazyLock<rt::ModelInfo> = ::std::sync::LazyLock::new(|| rt::ModelInfo {{\n\
         name: {name:?}.to_string(),\n\
         description: {desc:?}.to_string(),\n\
         coordinates: Vec::from([{coords}]),\n\
         contacts: Vec::from([{contacts}]),\n\
         loops: Vec::from([{loops}]),\n\
         spatial: {spatial},\n\
         initial: rt::InitialGuess {{ q: Vec::from({q}), qd: Vec::from({qd}), hold: Vec::from({hold:?}), given_q: Vec::from({given_q:?}), given_qd: Vec::from({given_qd:?}) }},\n\
         defaults: rt::SimSettings {{ t_end: {t_end}, dt_out: {dt_out}, integrator: rt::IntegratorKind::{integrator}, dt: {dt}, rtol: {rtol}, atol: {atol} }},\n\
         restitution: {restitution},\n\
         parameters: Vec::from([{parameters}]),\n\
         }});\n",
        name = model.name,
        desc = model.description,
        coords = coords.join(", "),
        contacts = contacts.join(", "),
        loops = loops.join(", "),
        spatial = !model.is_planar(),
        q = float_list(&model.initial.q),
        qd = float_list(&model.initial.qd),
        hold = model.initial.hold,
        given_q = model.initial.given_q,
        given_qd = model.initial.given_qd,
        t_end = lit(s.t_end),
        dt_out = lit(s.dt_out),
        dt = lit(s.dt),
        rtol = lit(s.rtol),
        atol = lit(s.atol),
        restitution = s
            .restitution
            .map_or("None".to_string(), |e| format!("Some({})", lit(e))),
        parameters = parameter_infos(model),
    )
}

/// The run-time parameters as `rt::ParameterInfo` values.
pub(super) fn parameter_infos(model: &Model) -> String {
    let option = |v: Option<f64>| v.map_or("None".to_string(), |v| format!("Some({})", lit(v)));
    let items: Vec<String> = model
        .runtime_parameters()
        .map(|(_, p)| {
            format!(
                "rt::ParameterInfo {{ name: {:?}.to_string(), unit: {:?}.to_string(), default: {}, min: {}, max: {}, description: {:?}.to_string() }}",
                p.name,
                p.unit,
                lit(p.default),
                option(p.min),
                option(p.max),
                p.description
            )
        })
        .collect();
    items.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::testing::model;

    #[test]
    fn the_static_description_lists_coordinates_contacts_and_loops() {
        let text = info_static(&model("four_bar"));
        assert!(text.contains("loops: Vec::from([rt::LoopInfo { name: \"pin\".to_string(), kind: rt::LoopKind::Revolute, equations: Vec::from([\"x\".to_string(), \"y\".to_string()]) }])"), "{text}");
        assert!(text.contains("contacts: Vec::from([])"));
        let text = info_static(&model("double_pendulum"));
        assert!(text.contains("rt::CoordinateInfo { name: \"q1\".to_string(), kind: rt::JointKind::Revolute, driven: false }"));
        assert!(text.contains("defaults: rt::SimSettings { t_end: 10.0, dt_out: 0.01,"));
        assert!(text.contains("spatial: false"));
    }

    #[test]
    fn run_time_parameters_carry_their_bounds() {
        let text = parameter_infos(&model("double_pendulum"));
        assert_eq!(text.matches("rt::ParameterInfo {").count(), 7);
        assert!(text.starts_with("rt::ParameterInfo { name: \"l1\".to_string(), unit: \"m\".to_string(), default: 1.0, min: Some(0.0), max: None, description: \"length of link 1\".to_string() }"));
    }
}
