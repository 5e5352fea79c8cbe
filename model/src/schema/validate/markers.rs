//! Markers: named points and frames on bodies, with unit, orthogonal axes for a cam plane.

use super::bodies::BodyTree;
use super::fields::{unique_names, unit_vector};
use super::{Checked, Context, ORTHOGONALITY_TOLERANCE};
use crate::model::{Field, Marker};
use crate::schema::raw;

pub(super) fn markers(list: &[raw::Marker], tree: &BodyTree, cx: &Context) -> Checked<Vec<Marker>> {
    let at = cx.at;
    unique_names(
        at,
        list.iter()
            .enumerate()
            .map(|(i, m)| (format!("markers[{i}].name"), m.name.as_str())),
        "marker name",
    )?;
    list.iter()
        .enumerate()
        .map(|(i, m)| {
            Ok(Marker {
                name: m.name.clone(),
                body: tree.sorted_body(at, &format!("markers[{i}].body"), &m.body)?,
                position: cx.vector_of(&format!("markers[{i}].position"), &m.position, |k| {
                    Field::Marker(i, k)
                })?,
            })
        })
        .collect()
}

/// Unit, orthogonal in-plane axes of the cam frame (constant: they fix the plane's
/// orientation in the generated code).
pub(super) fn cam_axes(
    cx: &Context,
    path: &str,
    frame: &raw::Frame,
) -> Checked<([f64; 3], [f64; 3])> {
    let at = cx.at;
    let (x_field, y_field) = (format!("{path}.x_axis"), format!("{path}.y_axis"));
    let x = cx.vector(&x_field, &frame.x_axis, None)?;
    let y = cx.vector(&y_field, &frame.y_axis, None)?;
    let x = unit_vector(at, &x_field, "x_axis", x)?;
    let y = unit_vector(at, &y_field, "y_axis", y)?;
    let dot: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
    if dot.abs() > ORTHOGONALITY_TOLERANCE {
        return Err(at.error(
            &format!("{path}.y_axis"),
            format!(
                "x_axis and y_axis must be orthogonal; their unit vectors have dot product {dot}"
            ),
        ));
    }
    Ok((x, y))
}
