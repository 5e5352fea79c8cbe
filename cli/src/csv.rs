//! The CSV of a trajectory: one row per output time, header first.
//!
//! The columns, their order and units are [`camchain_runtime::columns`]'s (an FMU's outputs
//! and the Python package's result are the same columns).
//!
//! Numbers are written with Rust's shortest round-trip formatting (`{:?}`): parsing a value
//! gives back exactly the `f64` the simulation computed.

use camchain_runtime::{ModelInfo, Sample};
use std::io::{self, Write};

/// The header's column names ([`camchain_runtime::columns::columns`]).
pub fn header(info: &ModelInfo) -> Vec<String> {
    camchain_runtime::columns::columns(info)
        .into_iter()
        .map(|c| c.name)
        .collect()
}

/// The values of one row, in the order of [`header`].
pub fn row(info: &ModelInfo, sample: &Sample) -> Vec<f64> {
    camchain_runtime::columns::values(info, sample)
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
