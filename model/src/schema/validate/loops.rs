//! Loops (`loops:`): the cut joint's two points, its kind and axes, and the checks
//! that the mechanism can have them: known bodies, two different bodies, unit axes, no more
//! equations than free coordinates, and a planar model's loops in its plane.

use super::bodies::BodyTree;
use super::fields::{identifier, unit_vector};
use super::{Checked, Context, GROUND};
use crate::model::{Body, Contact, Field, Loop, LoopKind, LoopPoint, Model};
use crate::schema::raw;
use std::collections::HashMap;

/// Validates the loops of `file` against the rest of the validated model (`model.loops` is
/// still empty): every problem is located at the loop's field.
pub(super) fn loops(
    list: &[raw::Loop],
    tree: &BodyTree,
    model: &Model,
    cx: &Context,
) -> Checked<Vec<Loop>> {
    let at = cx.at;
    let mut names: HashMap<&str, String> = model
        .contacts
        .iter()
        .enumerate()
        .map(|(k, c): (usize, &Contact)| (c.name.as_str(), format!("contacts[{k}]")))
        .collect();
    let planar = model.is_planar();
    let mut cuts = Vec::with_capacity(list.len());
    let mut rows = model.contacts.len();
    let free = model
        .bodies
        .iter()
        .filter(|b: &&Body| b.joint.prescribed.is_none())
        .count();
    for (l, raw_loop) in list.iter().enumerate() {
        let path = format!("loops[{l}]");
        let name_field = format!("{path}.name");
        identifier(at, &name_field, &raw_loop.name, "loop name")?;
        if let Some(first) = names.insert(raw_loop.name.as_str(), path.clone()) {
            return Err(at.error(
                &name_field,
                format!(
                    "the name `{}` is already used by {first}: contacts and loops need distinct names",
                    raw_loop.name
                ),
            ));
        }
        let cut = cut_joint(cx, tree, l, raw_loop, planar)?;
        rows += cut.equations().len();
        if rows > free {
            return Err(at.error(
                &path,
                format!(
                    "more constraint equations than free coordinates: with loop `{}` ({} \
                     equations) the model has {rows} equations for {free} coordinates that are \
                     not driven; a mechanism needs at least as many coordinates as equations \
                     (is a body missing, or a joint driven that should not be?)",
                    raw_loop.name,
                    cut.equations().len()
                ),
            ));
        }
        cuts.push(cut);
    }
    Ok(cuts)
}

/// One loop, validated.
fn cut_joint(
    cx: &Context,
    tree: &BodyTree,
    l: usize,
    raw_loop: &raw::Loop,
    planar: bool,
) -> Checked<Loop> {
    let at = cx.at;
    let path = format!("loops[{l}]");
    let sides = [(0, "a", &raw_loop.a), (1, "b", &raw_loop.b)].map(|(s, key, side)| {
        let body_field = format!("{path}.{key}.body");
        let body = if side.body == GROUND {
            None
        } else {
            Some(tree.sorted_body(at, &body_field, &side.body)?)
        };
        let point = cx.vector_of(&format!("{path}.{key}.point"), &side.point, |k| {
            Field::LoopPoint(l, s, k)
        })?;
        Ok(LoopPoint { body, point })
    });
    let [a, b] = sides;
    let sides = [a?, b?];
    if sides[0].body == sides[1].body {
        return Err(at.error(
            &format!("{path}.b.body"),
            format!(
                "loop `{}` joins `{}` to itself: a cut joint connects two different bodies",
                raw_loop.name, raw_loop.b.body
            ),
        ));
    }
    let kind = raw_loop.kind.0;
    let default_axis = match kind {
        LoopKind::Revolute | LoopKind::Spherical => [0.0, 0.0, 1.0],
        LoopKind::Prismatic | LoopKind::PointOnLine => [1.0, 0.0, 0.0],
    };
    let axis = match &raw_loop.axis {
        Some(v) => {
            let field = format!("{path}.axis");
            unit_vector(at, &field, "axis", cx.vector(&field, v, None)?)?
        }
        None => default_axis,
    };
    let axis_a = match &raw_loop.axis_a {
        Some(v) => {
            let field = format!("{path}.axis_a");
            unit_vector(at, &field, "axis_a", cx.vector(&field, v, None)?)?
        }
        None => axis,
    };
    if planar {
        in_plane(cx, l, raw_loop, kind, &sides, [axis, axis_a])?;
    } else if kind == LoopKind::Prismatic {
        return Err(at.error(
            &format!("{path}.kind"),
            "a prismatic cut is planar only (2 equations); in a spatial model cut the loop at \
             one of its revolute joints instead",
        ));
    }
    Ok(Loop {
        name: raw_loop.name.clone(),
        kind,
        sides,
        axis,
        axis_a,
        planar,
    })
}

/// A planar model's loop lies in its plane: points at z = 0, a line or slide in the plane.
fn in_plane(
    cx: &Context,
    l: usize,
    raw_loop: &raw::Loop,
    kind: LoopKind,
    sides: &[LoopPoint; 2],
    [axis, axis_a]: [[f64; 3]; 2],
) -> Checked<()> {
    let at = cx.at;
    let path = format!("loops[{l}]");
    for (s, (key, side)) in ["a", "b"].iter().zip(sides).enumerate() {
        let runtime_z = cx.table.is_runtime(Field::LoopPoint(l, s, 2));
        if side.point[2] != 0.0 || runtime_z {
            return Err(at.error(
                &format!("{path}.{key}.point[2]"),
                format!(
                    "loop `{}` leaves the plane of this planar model: its points need z = 0, \
                     got {}",
                    raw_loop.name, side.point[2]
                ),
            ));
        }
    }
    let needs_plane = matches!(kind, LoopKind::Prismatic | LoopKind::PointOnLine);
    for (field, v, given) in [
        ("axis", axis, raw_loop.axis.is_some()),
        ("axis_a", axis_a, raw_loop.axis_a.is_some()),
    ] {
        let off_plane = if needs_plane {
            v[2] != 0.0
        } else {
            v[0] != 0.0 || v[1] != 0.0
        };
        if given && off_plane {
            let want = if needs_plane {
                "in the x-y plane"
            } else {
                "along z"
            };
            return Err(at.error(
                &format!("{path}.{field}"),
                format!(
                    "loop `{}` is in a planar model: its {field} must be {want}, got ({}, {}, {})",
                    raw_loop.name, v[0], v[1], v[2]
                ),
            ));
        }
    }
    Ok(())
}
