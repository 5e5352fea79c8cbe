//! Bodies and joints: unique names, parents resolved and ordered parents first (cycles
//! refused), inertia from its sources, joint axes, springs and dampers, applied joint loads
//! and drives.

use super::super::Locator;
use super::fields::{lookup, unique_names, unit_vector};
use super::parameters::expression;
use super::{Checked, Context, GROUND, location};
use crate::error::ModelError;
use crate::model::{Body, Field, Joint, JointLoad, Prescribed, RuntimeCheck, SpringDamper};
use crate::schema::raw;
use camchain_runtime::parameters::checks;
use std::collections::HashMap;

/// The bodies' names, parents and their parents-first order.
pub(super) struct BodyTree<'f> {
    /// Body name → index in the file.
    pub(super) by_name: HashMap<&'f str, usize>,
    /// File indices in parents-first order.
    pub(super) order: Vec<usize>,
    /// File index → position in `order`.
    pub(super) sorted_index: Vec<usize>,
    /// File index → file index of the parent (`None` = ground).
    pub(super) parents: Vec<Option<usize>>,
}

impl<'f> BodyTree<'f> {
    pub(super) fn new(bodies: &'f [raw::Body], at: &Locator) -> Checked<Self> {
        if bodies.is_empty() {
            return Err(at.error("bodies", "the model needs at least one body"));
        }
        let by_name = body_names(bodies, at)?;
        unique_names(
            at,
            bodies.iter().enumerate().map(|(i, b)| {
                (
                    format!("bodies[{i}].joint.coordinate"),
                    b.joint.coordinate.as_str(),
                )
            }),
            "coordinate",
        )?;
        coordinate_names_free(bodies, at)?;
        let parents = bodies
            .iter()
            .enumerate()
            .map(|(i, b)| parent_of(at, i, b, &by_name))
            .collect::<Checked<Vec<_>>>()?;
        let order = parents_first(&parents).map_err(|cycle| cycle_error(at, bodies, &cycle))?;
        let mut sorted_index = vec![0; bodies.len()];
        for (position, &i) in order.iter().enumerate() {
            sorted_index[i] = position;
        }
        Ok(BodyTree {
            by_name,
            order,
            sorted_index,
            parents,
        })
    }

    /// The validated bodies, parents first.
    pub(super) fn bodies(&self, bodies: &[raw::Body], cx: &Context) -> Checked<Vec<Body>> {
        self.order
            .iter()
            .enumerate()
            .map(|(sorted, &i)| {
                let parent = self.parents[i].map(|p| self.sorted_index[p]);
                body(cx, i, sorted, &bodies[i], parent)
            })
            .collect()
    }

    /// Sorted index of the body called `name`.
    pub(super) fn sorted_body(&self, at: &Locator, field: &str, name: &str) -> Checked<usize> {
        let i = lookup(at, field, &self.by_name, name, "body")?;
        Ok(self.sorted_index[i])
    }
}

/// Coordinates are variables of the generated code and of joint loads beside the time `t`,
/// the velocities `<coordinate>_dot` and the build's own `__` names: none may be called so.
pub(super) fn coordinate_names_free(bodies: &[raw::Body], at: &Locator) -> Checked<()> {
    let names: Vec<&str> = bodies.iter().map(|b| b.joint.coordinate.as_str()).collect();
    for (i, &name) in names.iter().enumerate() {
        let field = format!("bodies[{i}].joint.coordinate");
        if ["t", "PI", "E"].contains(&name) || name.starts_with("__") {
            return Err(at.error(
                &field,
                format!(
                    "`{name}` already means something in expressions (the time t and the \
                     constants PI and E in a joint's load; names starting with `__` are \
                     reserved): choose another coordinate name"
                ),
            ));
        }
        if let Some(base) = name.strip_suffix("_dot").filter(|b| names.contains(b)) {
            return Err(at.error(
                &field,
                format!(
                    "`{name}` is taken by the velocity of coordinate `{base}` (`{base}_dot` in a \
                     joint's load and in the generated code): choose another coordinate name"
                ),
            ));
        }
    }
    Ok(())
}

pub(super) fn body_names<'f>(
    bodies: &'f [raw::Body],
    at: &Locator,
) -> Checked<HashMap<&'f str, usize>> {
    if let Some(i) = bodies.iter().position(|b| b.name == GROUND) {
        return Err(at.error(
            &format!("bodies[{i}].name"),
            "`ground` is reserved for the fixed base; choose another body name",
        ));
    }
    unique_names(
        at,
        bodies
            .iter()
            .enumerate()
            .map(|(i, b)| (format!("bodies[{i}].name"), b.name.as_str())),
        "body name",
    )
}

pub(super) fn parent_of(
    at: &Locator,
    i: usize,
    body: &raw::Body,
    by_name: &HashMap<&str, usize>,
) -> Checked<Option<usize>> {
    if body.parent == GROUND {
        return Ok(None);
    }
    let field = format!("bodies[{i}].parent");
    by_name
        .get(body.parent.as_str())
        .copied()
        .map(Some)
        .ok_or_else(|| {
            at.error(
                &field,
                format!(
                    "unknown parent `{}`; expected `ground` or the name of another body",
                    body.parent
                ),
            )
        })
}

/// File indices ordered so that every parent precedes its children, otherwise keeping the
/// file order; `Err(cycle)` lists the bodies of a parent cycle, child before parent.
pub(super) fn parents_first(parents: &[Option<usize>]) -> Result<Vec<usize>, Vec<usize>> {
    let mut placed = vec![false; parents.len()];
    let mut order = Vec::with_capacity(parents.len());
    for start in 0..parents.len() {
        let mut chain: Vec<usize> = Vec::new();
        let mut current = Some(start);
        while let Some(j) = current.filter(|&j| !placed[j]) {
            if let Some(k) = chain.iter().position(|&c| c == j) {
                return Err(chain.split_off(k));
            }
            chain.push(j);
            current = parents[j];
        }
        for &j in chain.iter().rev() {
            placed[j] = true;
            order.push(j);
        }
    }
    Ok(order)
}

pub(super) fn cycle_error(at: &Locator, bodies: &[raw::Body], cycle: &[usize]) -> ModelError {
    let first = cycle.first().copied().unwrap_or(0);
    let names: Vec<&str> = cycle
        .iter()
        .chain(cycle.first())
        .map(|&i| bodies[i].name.as_str())
        .collect();
    at.error(
        &format!("bodies[{first}].parent"),
        format!(
            "the parent links form a cycle: {} (each body's parent follows it)",
            names.join(" -> ")
        ),
    )
}

pub(super) fn body(
    cx: &Context,
    i: usize,
    sorted: usize,
    b: &raw::Body,
    parent: Option<usize>,
) -> Checked<Body> {
    let path = format!("bodies[{i}]");
    let mass_field = format!("{path}.mass");
    let mass = cx.positive(&mass_field, &b.mass, Field::Mass(sorted), "mass")?;
    Ok(Body {
        name: b.name.clone(),
        parent,
        mass,
        com: cx.vector_of(&format!("{path}.com"), &b.com, |k| Field::Com(sorted, k))?,
        inertia: inertia(cx, &format!("{path}.inertia"), &b.inertia, sorted)?,
        joint: joint(cx, &format!("{path}.joint"), &b.joint, sorted)?,
    })
}

/// Where each tensor entry (r, c) comes from: the written number (by its path suffix) and
/// a factor (Izz(e) gives e/2 on the diagonal's first two entries); `None` for a zero.
pub(super) type InertiaSource<'r> = [[Option<(&'static str, &'r raw::Number, f64)>; 3]; 3];

/// The written numbers of an inertia form, placed in the tensor.
pub(super) fn inertia_sources(inertia: &raw::Inertia) -> InertiaSource<'_> {
    let mut s: InertiaSource = Default::default();
    match inertia {
        raw::Inertia::Izz(izz) => {
            s[0][0] = Some(("[0]", izz, 0.5));
            s[1][1] = Some(("[0]", izz, 0.5));
            s[2][2] = Some(("[0]", izz, 1.0));
        }
        raw::Inertia::Diagonal(ixx, iyy, izz) => {
            s[0][0] = Some(("[0]", ixx, 1.0));
            s[1][1] = Some(("[1]", iyy, 1.0));
            s[2][2] = Some(("[2]", izz, 1.0));
        }
        raw::Inertia::Full {
            ixx,
            iyy,
            izz,
            ixy,
            ixz,
            iyz,
        } => {
            s[0][0] = Some((".ixx", ixx, 1.0));
            s[1][1] = Some((".iyy", iyy, 1.0));
            s[2][2] = Some((".izz", izz, 1.0));
            for (r, c, name, n) in [
                (0, 1, ".ixy", ixy),
                (0, 2, ".ixz", ixz),
                (1, 2, ".iyz", iyz),
            ] {
                s[r][c] = Some((name, n, 1.0));
                s[c][r] = Some((name, n, 1.0));
            }
        }
    }
    s
}

/// Finite, positive definite, principal moments obeying the triangle inequality.
pub(super) fn inertia(
    cx: &Context,
    field: &str,
    raw: &raw::Inertia,
    body: usize,
) -> Checked<[[f64; 3]; 3]> {
    let at = cx.at;
    let mut matrix = [[0.0; 3]; 3];
    for (r, row) in inertia_sources(raw).iter().enumerate() {
        for (c, source) in row.iter().enumerate() {
            let Some((suffix, number, factor)) = source else {
                continue;
            };
            let key = Field::Inertia(body, r, c);
            let value = cx.number(&format!("{field}{suffix}"), number, Some(key))?;
            cx.table.scale(key, *factor);
            matrix[r][c] = factor * value;
        }
    }
    let runtime = (0..3).any(|r| (0..3).any(|c| cx.table.is_runtime(Field::Inertia(body, r, c))));
    if runtime {
        cx.table
            .check(RuntimeCheck::Inertia(body, location(at, field)));
    }
    checks::inertia(&matrix).map_err(|m| at.error(field, m))?;
    Ok(matrix)
}

pub(super) fn joint(cx: &Context, path: &str, j: &raw::Joint, body: usize) -> Checked<Joint> {
    let axis = cx.vector(&format!("{path}.axis"), &j.axis, None)?;
    Ok(Joint {
        kind: j.kind.0,
        axis: unit_vector(cx.at, &format!("{path}.axis"), "the joint axis", axis)?,
        anchor: cx.vector_of(&format!("{path}.anchor"), &j.anchor, |k| {
            Field::Anchor(body, k)
        })?,
        coordinate: j.coordinate.clone(),
        spring: j
            .spring
            .as_ref()
            .map(|s| spring(cx, &format!("{path}.spring"), s, body))
            .transpose()?,
        prescribed: j
            .prescribed
            .as_ref()
            .map(|source| prescribed(cx, &format!("{path}.prescribed"), source, body))
            .transpose()?,
        load: None,
    })
}

/// The applied loads of the joints: expressions of t, the coordinates (`q1`) and their rates
/// (`q1_dot`), parsed once every coordinate's name is known.
pub(super) fn joint_loads(
    file: &[raw::Body],
    tree: &BodyTree,
    bodies: &mut [Body],
    cx: &Context,
) -> Checked<()> {
    let coordinates: Vec<String> = bodies.iter().map(|b| b.joint.coordinate.clone()).collect();
    for (sorted, &i) in tree.order.iter().enumerate() {
        let Some(source) = &file[i].joint.load else {
            continue;
        };
        let field = format!("bodies[{i}].joint.load");
        if bodies[sorted].joint.prescribed.is_some() {
            return Err(cx.at.error(
                &field,
                "a prescribed joint cannot also have a load: its motion is given and the load \
                 that drives it is computed (reported as its drive load)",
            ));
        }
        let expr = cx
            .table
            .load_expression(&field, source, &coordinates, Field::Load(sorted))?;
        bodies[sorted].joint.load = Some(JointLoad {
            source: source.clone(),
            expr,
        });
    }
    Ok(())
}

pub(super) fn spring(
    cx: &Context,
    path: &str,
    s: &raw::Spring,
    body: usize,
) -> Checked<SpringDamper> {
    let (k, c, rest) = (
        format!("{path}.stiffness"),
        format!("{path}.damping"),
        format!("{path}.rest"),
    );
    let stiffness = cx.non_negative(&k, &s.stiffness, Field::Stiffness(body), "stiffness")?;
    let damping = cx.non_negative(&c, &s.damping, Field::Damping(body), "damping")?;
    Ok(SpringDamper {
        stiffness,
        damping,
        rest: cx.number(&rest, &s.rest, Some(Field::Rest(body)))?,
    })
}

pub(super) fn prescribed(
    cx: &Context,
    field: &str,
    source: &str,
    body: usize,
) -> Checked<Prescribed> {
    Ok(Prescribed {
        source: source.to_string(),
        expr: expression(cx, field, source, &["t"], Field::Drive(body))?,
    })
}
