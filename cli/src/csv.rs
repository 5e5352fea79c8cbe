//! The CSV of a trajectory: one row per output time, header first.
//!
//! Columns, in order: `t`; every coordinate by name; every velocity as `<name>_dot`; for
//! each contact C: `C_x`, `C_y` (and `C_z` in a spatial model: the contact point in ground
//! coordinates, m), `C_cam_x`, `C_cam_y` (the same point in the cam's frame, which turns with
//! the cam's body, m), `C_cam_angle` (only when the cam's body turns on a revolute joint of
//! its own: that joint's angle, rad), `C_normal_force` (N, positive when the cam pushes on
//! the follower), `C_pressure_angle` (only when the cam moves, as it must to drive the
//! follower: rad, between the contact normal and the direction in which the follower's own
//! joint moves the follower point), `C_sliding_speed` (m/s, the
//! follower's tangential speed over the cam at the contact point), `C_h` (the constraint
//! residual, m; in flight the gap); for each equation E of each loop L, `L_E_h` (its
//! residual: m for the gap's components `x`, `y`, `z` and `normal`, dimensionless for `turn`
//! and `tilt`) and `L_E_reaction` (−λ: for `x`, `y`, `z` the force that B's body exerts on
//! A's at the cut, ground axes, N; for `normal` the force across the line, N; for `turn`
//! and `tilt` the moment that keeps the directions aligned, N m); for each driven coordinate, `<name>_drive` (the force or
//! torque of its drive); then `energy` (kinetic + potential of gravity and springs),
//! `dissipated` (work done by the dampers so far) and `driven_work` (work done by the drives
//! and the applied joint loads so far), so that `energy + dissipated − driven_work` stays
//! constant.
//!
//! Numbers are written with Rust's shortest round-trip formatting (`{:?}`): parsing a value
//! gives back exactly the `f64` the simulation computed.

use camchain_runtime::{ModelInfo, Sample};
use std::io::{self, Write};

/// The header's column names.
pub fn header(info: &ModelInfo) -> Vec<String> {
    let mut columns = vec!["t".to_string()];
    columns.extend(info.coordinates.iter().map(|c| c.name.clone()));
    columns.extend(info.coordinates.iter().map(|c| format!("{}_dot", c.name)));
    for (k, contact) in info.contacts.iter().map(|c| &c.name).enumerate() {
        let axes: &[&str] = if info.spatial {
            &["x", "y", "z"]
        } else {
            &["x", "y"]
        };
        let surface = info.contacts[k].profile.is_surface();
        columns.extend(axes.iter().map(|a| format!("{contact}_{a}")));
        columns.extend(["cam_x", "cam_y"].map(|a| format!("{contact}_{a}")));
        if surface {
            columns.push(format!("{contact}_cam_z"));
        }
        if info.contacts[k].cam_coordinate.is_some() {
            columns.push(format!("{contact}_cam_angle"));
        }
        columns.push(format!("{contact}_normal_force"));
        if surface {
            // On a cam surface the normal's direction is not the cam plane's: its ground
            // components.
            columns.extend(["x", "y", "z"].map(|a| format!("{contact}_normal_{a}")));
        }
        if info.contacts[k].cam_moves {
            columns.push(format!("{contact}_pressure_angle"));
        }
        columns.extend(["sliding_speed", "h"].map(|a| format!("{contact}_{a}")));
    }
    for (_, l) in info.loop_rows() {
        for e in &l.equations {
            columns.push(format!("{}_{e}_h", l.name));
            columns.push(format!("{}_{e}_reaction", l.name));
        }
    }
    columns.extend(
        info.coordinates
            .iter()
            .filter(|c| c.driven)
            .map(|c| format!("{}_drive", c.name)),
    );
    columns.extend(["energy", "dissipated", "driven_work"].map(String::from));
    columns
}

/// The values of one row, in the order of [`header`].
pub fn row(info: &ModelInfo, sample: &Sample) -> Vec<f64> {
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
    // Each loop equation's residual and its reaction −λ (docs/model-format.md, "Loops").
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

/// Writes the header and every sample.
pub fn write(out: &mut dyn Write, info: &ModelInfo, samples: &[Sample]) -> io::Result<()> {
    writeln!(out, "{}", header(info).join(","))?;
    for sample in samples {
        write_row(out, info, sample)?;
    }
    out.flush()
}

/// Writes one sample's row (a line of [`row`]'s values, round-trip formatted).
pub fn write_row(out: &mut dyn Write, info: &ModelInfo, sample: &Sample) -> io::Result<()> {
    let mut line = String::new();
    for (i, value) in row(info, sample).iter().enumerate() {
        if i > 0 {
            line.push(',');
        }
        line.push_str(&format!("{value:?}"));
    }
    line.push('\n');
    out.write_all(line.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use camchain_models as models;
    use camchain_runtime::Simulate;

    #[test]
    fn rows_match_the_header_and_round_trip() {
        for name in [
            "paper_concave",
            "driven_convex",
            "spatial_arm",
            "double_pendulum",
            "eccentric_roller",
            "paper_rotating",
            "paraboloid_orbit",
        ] {
            let model = models::by_name(name).unwrap();
            let info = model.info();
            let state = model.assemble(0.0).unwrap();
            let sample = model.sample(&state).unwrap();
            let columns = header(info);
            let values = row(info, &sample);
            assert_eq!(columns.len(), values.len(), "{name}");
            let mut text = Vec::new();
            write(&mut text, info, std::slice::from_ref(&sample)).unwrap();
            let text = String::from_utf8(text).unwrap();
            let mut lines = text.lines();
            assert_eq!(lines.next(), Some(columns.join(",").as_str()));
            let parsed: Vec<f64> = lines
                .next()
                .unwrap()
                .split(',')
                .map(|v| v.parse().unwrap())
                .collect();
            assert_eq!(parsed, values, "{name}");
        }
    }

    #[test]
    fn spatial_and_driven_columns() {
        let spatial = header(models::by_name("spatial_arm").unwrap().info());
        assert!(spatial.iter().any(|c| c == "tip_z"));
        let driven = header(models::by_name("driven_convex").unwrap().info());
        assert!(driven.iter().any(|c| c == "q1_drive"));
        assert!(!driven.iter().any(|c| c == "q2_drive" || c == "A_z"));
        // A turning cam's angle is a column of its contact; a cam on the ground has none.
        assert!(!driven.iter().any(|c| c == "A_cam_angle"));
        let model = models::by_name("eccentric_roller").unwrap();
        let columns = header(model.info());
        let sample = model.sample(&model.assemble(0.1).unwrap()).unwrap();
        let values = row(model.info(), &sample);
        let at = |name: &str| columns.iter().position(|c| c == name).unwrap();
        assert_eq!(values[at("roller_cam_angle")], values[at("cam_angle")]);
        assert_eq!(values[at("roller_cam_angle")], 2.0, "20 rad/s for 0.1 s");
        for column in [
            "roller_cam_x",
            "roller_pressure_angle",
            "roller_sliding_speed",
        ] {
            assert!(values[at(column)] != 0.0, "{column}");
        }
        // A cam surface adds the contact point's height and the normal's direction.
        let model = models::by_name("paraboloid_orbit").unwrap();
        let columns = header(model.info());
        let sample = model.sample(&model.assemble(0.0).unwrap()).unwrap();
        let values = row(model.info(), &sample);
        let at = |name: &str| columns.iter().position(|c| c == name).unwrap();
        // z = c r0² = 2 · 0.1² on the orbit's start (x = r0, y = 0), the normal
        // (−2 c r0, 0, 1)/√(1 + (2 c r0)²): the paraboloid's closed form, to rounding.
        assert!((values[at("bowl_cam_z")] - 0.02).abs() < 1e-15);
        let w = (1.0f64 + 0.16).sqrt();
        for (axis, expected) in [("x", -0.4 / w), ("y", 0.0), ("z", 1.0 / w)] {
            let got = values[at(&format!("bowl_normal_{axis}"))];
            assert!(
                (got - expected).abs() < 1e-15,
                "normal_{axis}: {got} vs {expected}"
            );
        }
        // A plane profile has neither.
        assert!(!driven.iter().any(|c| c == "A_cam_z" || c == "A_normal_x"));
    }
}
