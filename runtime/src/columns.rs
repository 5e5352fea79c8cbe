//! The outputs of a run at one instant as named columns with units: the CSV's header and row
//! (`camchain simulate --csv`), the Python package's result and an FMU's output variables all
//! read them from here, so that a column is defined once.
//!
//! In order: `t`; every coordinate by name; every velocity as `<name>_dot`; for each contact
//! C: `C_x`, `C_y` (and `C_z` in a spatial model: the contact point in ground coordinates),
//! `C_cam_x`, `C_cam_y` (the same point in the cam's frame), `C_cam_z` (on a cam surface),
//! `C_cam_angle` (only when the cam's body turns on a revolute joint of its own),
//! `C_normal_force` (positive when the cam pushes on the follower), `C_normal_x`, `_y`, `_z`
//! (on a cam surface: the normal's ground components), `C_pressure_angle` (only when the cam
//! moves), `C_sliding_speed`, `C_h` (the constraint residual; in flight the gap); for each
//! equation E of each loop L, `L_E_h` and `L_E_reaction` (−λ); for each driven coordinate,
//! `<name>_drive`; then `energy`, `dissipated` and `driven_work`.

use crate::{ModelInfo, Sample};

/// One output column.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Column {
    /// Its name (the CSV's header).
    pub name: String,
    /// Its SI unit in ASCII (`m`, `rad/s`, `N.m`), empty when dimensionless.
    pub unit: &'static str,
    /// What it is, one line.
    pub description: String,
}

fn column(name: String, unit: &'static str, description: impl Into<String>) -> Column {
    Column {
        name,
        unit,
        description: description.into(),
    }
}

/// The units of a coordinate of `kind`: value, rate, drive load.
fn units(kind: crate::JointKind) -> [&'static str; 3] {
    match kind {
        crate::JointKind::Revolute => ["rad", "rad/s", "N.m"],
        crate::JointKind::Prismatic => ["m", "m/s", "N"],
    }
}

/// The unit of a loop equation's residual and of its reaction.
fn loop_units(equation: &str) -> [&'static str; 2] {
    match equation {
        "turn" | "tilt" => ["", "N.m"],
        _ => ["m", "N"],
    }
}

/// Every column of the model's outputs, `t` first.
pub fn columns(info: &ModelInfo) -> Vec<Column> {
    let mut out = vec![column("t".into(), "s", "time")];
    for c in &info.coordinates {
        out.push(column(c.name.clone(), units(c.kind)[0], "coordinate"));
    }
    for c in &info.coordinates {
        let name = format!("{}_dot", c.name);
        out.push(column(
            name,
            units(c.kind)[1],
            format!("rate of {}", c.name),
        ));
    }
    for (k, about) in info.contacts.iter().enumerate() {
        let contact = &about.name;
        let axes: &[&str] = if info.spatial {
            &["x", "y", "z"]
        } else {
            &["x", "y"]
        };
        let surface = info.contacts[k].profile.is_surface();
        for a in axes {
            let what = format!("contact point, ground {a}");
            out.push(column(format!("{contact}_{a}"), "m", what));
        }
        let mut cam_axes = vec!["x", "y"];
        if surface {
            cam_axes.push("z");
        }
        for a in cam_axes {
            let what = format!("contact point in the cam's frame, {a}");
            out.push(column(format!("{contact}_cam_{a}"), "m", what));
        }
        if about.cam_coordinate.is_some() {
            let what = "angle of the cam's own revolute joint";
            out.push(column(format!("{contact}_cam_angle"), "rad", what));
        }
        let what = "normal force, positive when the cam pushes on the follower";
        out.push(column(format!("{contact}_normal_force"), "N", what));
        if surface {
            for a in ["x", "y", "z"] {
                let what = format!("contact normal, ground {a}");
                out.push(column(format!("{contact}_normal_{a}"), "", what));
            }
        }
        if about.cam_moves {
            let what = "pressure angle";
            out.push(column(format!("{contact}_pressure_angle"), "rad", what));
        }
        let what = "follower's tangential speed over the cam";
        out.push(column(format!("{contact}_sliding_speed"), "m/s", what));
        let what = "constraint residual (in flight: the gap)";
        out.push(column(format!("{contact}_h"), "m", what));
    }
    for (_, l) in info.loop_rows() {
        for e in &l.equations {
            let [h, reaction] = loop_units(e);
            let what = format!("residual of loop {}'s equation {e}", l.name);
            out.push(column(format!("{}_{e}_h", l.name), h, what));
            let what = format!("reaction of loop {}'s equation {e} (−λ)", l.name);
            out.push(column(format!("{}_{e}_reaction", l.name), reaction, what));
        }
    }
    for c in info.coordinates.iter().filter(|c| c.driven) {
        let what = format!("force or torque of the drive of {}", c.name);
        out.push(column(format!("{}_drive", c.name), units(c.kind)[2], what));
    }
    out.push(column(
        "energy".into(),
        "J",
        "kinetic + potential energy of gravity and springs",
    ));
    out.push(column(
        "dissipated".into(),
        "J",
        "work done by the dampers so far",
    ));
    out.push(column(
        "driven_work".into(),
        "J",
        "work done by the drives and applied joint loads so far",
    ));
    out
}

/// The values of one sample, in the order of [`columns`].
pub fn values(info: &ModelInfo, sample: &Sample) -> Vec<f64> {
    let mut values = vec![sample.t];
    values.extend(&sample.q);
    values.extend(&sample.qd);
    let dims = if info.spatial { 3 } else { 2 };
    for (k, (contact, about)) in sample.contacts.iter().zip(&info.contacts).enumerate() {
        let surface = about.profile.is_surface();
        values.extend(&contact.position[..dims]);
        values.extend([contact.x, contact.y]);
        if surface {
            values.push(contact.z);
        }
        if let Some(i) = about.cam_coordinate {
            values.push(sample.q[i]);
        }
        values.push(sample.normal_force[k]);
        if surface {
            values.extend(contact.normal);
        }
        if about.cam_moves {
            values.push(contact.pressure_angle());
        }
        values.extend([contact.sliding_speed, sample.h[k]]);
    }
    for k in info.n_contacts()..info.n_constraints() {
        values.push(sample.h.get(k).copied().unwrap_or(f64::NAN));
        values.push(-sample.lambda.get(k).copied().unwrap_or(f64::NAN));
    }
    values.extend(
        info.coordinates
            .iter()
            .zip(&sample.drive)
            .filter(|(c, _)| c.driven)
            .map(|(_, tau)| *tau),
    );
    values.extend([sample.energy.total(), sample.dissipated, sample.driven_work]);
    values
}
