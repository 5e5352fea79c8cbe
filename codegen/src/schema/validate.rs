//! From the file's [`raw`] values to the validated [`Model`]: physical checks, name
//! resolution, parents-first ordering. Every error names the dotted field path in the file's
//! own order (before sorting), which [`Locator`] turns into a line and column.

use super::Locator;
use super::raw;
use crate::error::ModelError;
use crate::model::{
    Body, Contact, Initial, IntegratorChoice, Joint, JointKind, Marker, Model, Prescribed,
    Simulation, SpringDamper,
};
use crate::profile::{Scalar, parse_expression};
use nalgebra::{Matrix3, SymmetricEigen};
use std::collections::HashMap;

/// The reserved parent name of the fixed base.
const GROUND: &str = "ground";

/// Principal moments may exceed the triangle inequality by this fraction of their sum
/// (round-off in the eigen-decomposition; the planar lamina is exactly on the boundary).
const TRIANGLE_SLACK: f64 = 1e-12;

/// Largest |x̂·ŷ| accepted for the cam plane axes after normalisation.
const ORTHOGONALITY_TOLERANCE: f64 = 1e-9;

/// Rust keywords (strict, reserved and edition-specific): not usable as generated names.
const KEYWORDS: [&str; 53] = [
    "as", "break", "const", "continue", "crate", "else", "enum", "extern", "false", "fn", "for",
    "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return",
    "self", "Self", "static", "struct", "super", "trait", "true", "type", "unsafe", "use", "where",
    "while", "async", "await", "dyn", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "typeof", "unsized", "virtual", "yield", "try", "gen", "_",
];

type Checked<T> = Result<T, ModelError>;

/// Validates the whole file; `stem` is the file stem used as the default model name.
pub(super) fn validate(file: &raw::Model, stem: &str, at: &Locator) -> Checked<Model> {
    let name = model_name(file.name.as_deref(), stem, at)?;
    let gravity = finite3(at, "gravity", file.gravity)?;
    let tree = BodyTree::new(&file.bodies, at)?;
    let bodies = tree.bodies(&file.bodies, at)?;
    let markers = markers(&file.markers, &tree, at)?;
    let contacts = contacts(&file.contacts, &markers, at)?;
    let initial = initial(&file.initial, &bodies, at)?;
    let simulation = simulation(&file.simulation, at)?;
    Ok(Model {
        name,
        description: file.description.clone(),
        gravity,
        bodies,
        markers,
        contacts,
        initial,
        simulation,
    })
}

/// The model's name: `name:`, or the file stem. Any non-empty text: only the build needs a
/// Rust identifier (it names the generated module) and checks that itself.
fn model_name(name: Option<&str>, stem: &str, at: &Locator) -> Checked<String> {
    let name = name.unwrap_or(stem);
    if name.trim().is_empty() || name.chars().any(char::is_control) {
        return Err(at.error(
            "name",
            format!("the model name {name:?} is empty or has control characters"),
        ));
    }
    Ok(name.to_string())
}

/// True for an ASCII Rust identifier that is not a keyword.
pub(crate) fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    let starts_well = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    starts_well && chars.all(|c| c.is_ascii_alphanumeric() || c == '_') && !KEYWORDS.contains(&name)
}

/// Names end up as Rust identifiers in the generated code.
fn identifier(at: &Locator, field: &str, name: &str, what: &str) -> Checked<()> {
    if is_identifier(name) {
        Ok(())
    } else {
        Err(at.error(
            field,
            format!(
                "{what} `{name}` is not a valid Rust identifier (ASCII letters, digits and `_`, \
                 not starting with a digit, not a keyword)"
            ),
        ))
    }
}

fn finite(at: &Locator, field: &str, value: f64) -> Checked<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(at.error(field, format!("must be finite, got {value}")))
    }
}

fn finite3(at: &Locator, field: &str, v: [f64; 3]) -> Checked<[f64; 3]> {
    for (k, &c) in v.iter().enumerate() {
        finite(at, &format!("{field}[{k}]"), c)?;
    }
    Ok(v)
}

fn positive(at: &Locator, field: &str, what: &str, value: f64) -> Checked<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(at.error(
            field,
            format!("{what} must be positive and finite, got {value}"),
        ))
    }
}

fn non_negative(at: &Locator, field: &str, what: &str, value: f64) -> Checked<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(at.error(
            field,
            format!("{what} must be non-negative and finite, got {value}"),
        ))
    }
}

/// `v / |v|`, or `None` for a zero or non-finite vector.
fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let norm = v.iter().map(|c| c * c).sum::<f64>().sqrt();
    (norm.is_finite() && norm > 0.0).then(|| v.map(|c| c / norm))
}

fn unit_vector(at: &Locator, field: &str, what: &str, v: [f64; 3]) -> Checked<[f64; 3]> {
    finite3(at, field, v)?;
    unit(v).ok_or_else(|| {
        at.error(
            field,
            format!(
                "{what} must be a non-zero vector, got ({}, {}, {})",
                v[0], v[1], v[2]
            ),
        )
    })
}

/// Finds `name` in `names` (a name → index map) or explains what was expected.
fn lookup(
    at: &Locator,
    field: &str,
    index: &HashMap<&str, usize>,
    name: &str,
    what: &str,
) -> Checked<usize> {
    index
        .get(name)
        .copied()
        .ok_or_else(|| at.error(field, unknown(index, name, what)))
}

/// "unknown {what} `{name}`; known: …" with the known names sorted.
fn unknown(index: &HashMap<&str, usize>, name: &str, what: &str) -> String {
    let mut known: Vec<&str> = index.keys().copied().collect();
    known.sort_unstable();
    format!("unknown {what} `{name}`; known: {}", known.join(", "))
}

/// Indexes `names`, reporting the second occurrence of a repeated name.
fn unique_names<'n>(
    at: &Locator,
    names: impl Iterator<Item = (String, &'n str)>,
    what: &str,
) -> Checked<HashMap<&'n str, usize>> {
    let mut index = HashMap::new();
    for (i, (field, name)) in names.enumerate() {
        identifier(at, &field, name, what)?;
        if index.insert(name, i).is_some() {
            return Err(at.error(&field, format!("duplicate {what} `{name}`")));
        }
    }
    Ok(index)
}

/// The bodies' names, parents and their parents-first order.
struct BodyTree<'f> {
    /// Body name → index in the file.
    by_name: HashMap<&'f str, usize>,
    /// File indices in parents-first order.
    order: Vec<usize>,
    /// File index → position in `order`.
    sorted_index: Vec<usize>,
    /// File index → file index of the parent (`None` = ground).
    parents: Vec<Option<usize>>,
}

impl<'f> BodyTree<'f> {
    fn new(bodies: &'f [raw::Body], at: &Locator) -> Checked<Self> {
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
    fn bodies(&self, bodies: &[raw::Body], at: &Locator) -> Checked<Vec<Body>> {
        self.order
            .iter()
            .map(|&i| {
                let parent = self.parents[i].map(|p| self.sorted_index[p]);
                body(at, i, &bodies[i], parent)
            })
            .collect()
    }

    /// Sorted index of the body called `name`.
    fn sorted_body(&self, at: &Locator, field: &str, name: &str) -> Checked<usize> {
        let i = lookup(at, field, &self.by_name, name, "body")?;
        Ok(self.sorted_index[i])
    }
}

fn body_names<'f>(bodies: &'f [raw::Body], at: &Locator) -> Checked<HashMap<&'f str, usize>> {
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

fn parent_of(
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
fn parents_first(parents: &[Option<usize>]) -> Result<Vec<usize>, Vec<usize>> {
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

fn cycle_error(at: &Locator, bodies: &[raw::Body], cycle: &[usize]) -> ModelError {
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

fn body(at: &Locator, i: usize, b: &raw::Body, parent: Option<usize>) -> Checked<Body> {
    let path = format!("bodies[{i}]");
    Ok(Body {
        name: b.name.clone(),
        parent,
        mass: positive(at, &format!("{path}.mass"), "mass", b.mass)?,
        com: finite3(at, &format!("{path}.com"), b.com)?,
        inertia: inertia(at, &format!("{path}.inertia"), &b.inertia)?,
        joint: joint(at, &format!("{path}.joint"), &b.joint)?,
    })
}

/// The tensor as a matrix, and each number written in the file with its path suffix.
fn inertia_entries(inertia: &raw::Inertia) -> ([[f64; 3]; 3], Vec<(&'static str, f64)>) {
    match *inertia {
        raw::Inertia::Izz(izz) => (
            [
                [izz / 2.0, 0.0, 0.0],
                [0.0, izz / 2.0, 0.0],
                [0.0, 0.0, izz],
            ],
            vec![("[0]", izz)],
        ),
        raw::Inertia::Diagonal(ixx, iyy, izz) => (
            [[ixx, 0.0, 0.0], [0.0, iyy, 0.0], [0.0, 0.0, izz]],
            vec![("[0]", ixx), ("[1]", iyy), ("[2]", izz)],
        ),
        raw::Inertia::Full {
            ixx,
            iyy,
            izz,
            ixy,
            ixz,
            iyz,
        } => (
            [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]],
            vec![
                (".ixx", ixx),
                (".iyy", iyy),
                (".izz", izz),
                (".ixy", ixy),
                (".ixz", ixz),
                (".iyz", iyz),
            ],
        ),
    }
}

/// Finite, positive definite, principal moments obeying the triangle inequality.
fn inertia(at: &Locator, field: &str, raw: &raw::Inertia) -> Checked<[[f64; 3]; 3]> {
    let (matrix, entries) = inertia_entries(raw);
    for (suffix, value) in entries {
        finite(at, &format!("{field}{suffix}"), value)?;
    }
    let mut moments: Vec<f64> = SymmetricEigen::new(Matrix3::from_fn(|r, c| matrix[r][c]))
        .eigenvalues
        .iter()
        .copied()
        .collect();
    moments.sort_by(f64::total_cmp);
    let [small, middle, large] = [moments[0], moments[1], moments[2]];
    let listed = format!("{small}, {middle}, {large}");
    if small <= 0.0 {
        return Err(at.error(
            field,
            format!(
                "the inertia tensor must be positive definite; its principal moments are {listed}"
            ),
        ));
    }
    if large > (small + middle) + TRIANGLE_SLACK * (small + middle + large) {
        return Err(at.error(
            field,
            format!(
                "the principal moments {listed} violate the triangle inequality (the largest \
                 may not exceed the sum of the other two): no rigid body has this inertia"
            ),
        ));
    }
    Ok(matrix)
}

fn joint(at: &Locator, path: &str, j: &raw::Joint) -> Checked<Joint> {
    Ok(Joint {
        kind: match j.kind {
            raw::JointKind::Revolute => JointKind::Revolute,
            raw::JointKind::Prismatic => JointKind::Prismatic,
        },
        axis: unit_vector(at, &format!("{path}.axis"), "the joint axis", j.axis)?,
        anchor: finite3(at, &format!("{path}.anchor"), j.anchor)?,
        coordinate: j.coordinate.clone(),
        spring: j
            .spring
            .as_ref()
            .map(|s| spring(at, &format!("{path}.spring"), s))
            .transpose()?,
        prescribed: j
            .prescribed
            .as_ref()
            .map(|source| prescribed(at, &format!("{path}.prescribed"), source))
            .transpose()?,
    })
}

fn spring(at: &Locator, path: &str, s: &raw::Spring) -> Checked<SpringDamper> {
    Ok(SpringDamper {
        stiffness: non_negative(at, &format!("{path}.stiffness"), "stiffness", s.stiffness)?,
        damping: non_negative(at, &format!("{path}.damping"), "damping", s.damping)?,
        rest: finite(at, &format!("{path}.rest"), s.rest)?,
    })
}

/// Parses an expression in `variable`, locating errors inside the string literal.
fn expression(at: &Locator, field: &str, source: &str, variable: &str) -> Checked<Scalar> {
    parse_expression(source, variable).map_err(|e| at.error_in_string(field, e.offset, e.message))
}

fn prescribed(at: &Locator, field: &str, source: &str) -> Checked<Prescribed> {
    Ok(Prescribed {
        source: source.to_string(),
        expr: expression(at, field, source, "t")?,
    })
}

fn markers(list: &[raw::Marker], tree: &BodyTree, at: &Locator) -> Checked<Vec<Marker>> {
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
                position: finite3(at, &format!("markers[{i}].position"), m.position)?,
            })
        })
        .collect()
}

fn contacts(list: &[raw::Contact], markers: &[Marker], at: &Locator) -> Checked<Vec<Contact>> {
    let by_name: HashMap<&str, usize> = markers
        .iter()
        .enumerate()
        .map(|(i, m)| (m.name.as_str(), i))
        .collect();
    let mut used = HashMap::new();
    list.iter()
        .enumerate()
        .map(|(i, c)| {
            let field = format!("contacts[{i}].marker");
            let marker = lookup(at, &field, &by_name, &c.marker, "marker")?;
            if let Some(first) = used.insert(marker, i) {
                let message = format!(
                    "marker `{}` already has a contact (contacts[{first}])",
                    c.marker
                );
                return Err(at.error(&field, message));
            }
            contact(at, i, c, marker)
        })
        .collect()
}

fn contact(at: &Locator, i: usize, c: &raw::Contact, marker: usize) -> Checked<Contact> {
    let path = format!("contacts[{i}]");
    let (x_axis, y_axis) = cam_axes(at, &format!("{path}.frame"), &c.frame)?;
    Ok(Contact {
        name: c.marker.clone(),
        marker,
        profile_source: c.profile.clone(),
        profile: expression(at, &format!("{path}.profile"), &c.profile, "x")?,
        origin: finite3(at, &format!("{path}.frame.origin"), c.frame.origin)?,
        x_axis,
        y_axis,
    })
}

/// Unit, orthogonal in-plane axes of the cam frame.
fn cam_axes(at: &Locator, path: &str, frame: &raw::Frame) -> Checked<([f64; 3], [f64; 3])> {
    let x = unit_vector(at, &format!("{path}.x_axis"), "x_axis", frame.x_axis)?;
    let y = unit_vector(at, &format!("{path}.y_axis"), "y_axis", frame.y_axis)?;
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

fn initial(file: &raw::Initial, bodies: &[Body], at: &Locator) -> Checked<Initial> {
    let by_name: HashMap<&str, usize> = bodies
        .iter()
        .enumerate()
        .map(|(i, b)| (b.joint.coordinate.as_str(), i))
        .collect();
    let (q, given_q) = coordinate_values(at, "initial.q", &file.q, &by_name)?;
    let (qd, given_qd) = coordinate_values(at, "initial.qd", &file.qd, &by_name)?;
    let mut hold: Vec<bool> = bodies
        .iter()
        .map(|b| b.joint.prescribed.is_some())
        .collect();
    let mut listed = vec![false; bodies.len()];
    for (k, name) in file.hold.iter().enumerate() {
        let field = format!("initial.hold[{k}]");
        let i = lookup(at, &field, &by_name, name, "coordinate")?;
        if std::mem::replace(&mut listed[i], true) {
            return Err(at.error(&field, format!("coordinate `{name}` is listed twice")));
        }
        hold[i] = true;
    }
    Ok(Initial {
        q,
        qd,
        hold,
        given_q,
        given_qd,
    })
}

/// `{"name": value}` → a value per coordinate in body order, 0 where absent, and which
/// were given.
fn coordinate_values(
    at: &Locator,
    path: &str,
    values: &raw::NamedValues,
    index: &HashMap<&str, usize>,
) -> Checked<(Vec<f64>, Vec<bool>)> {
    let mut out = vec![0.0; index.len()];
    let mut given = vec![false; index.len()];
    for (k, (name, value)) in values.0.iter().enumerate() {
        let field = format!("{path}[{name:?}]");
        // Located by position, so a repeated key points at its second occurrence.
        let entry = format!("{path}[{k}]");
        let i = index
            .get(name.as_str())
            .copied()
            .ok_or_else(|| at.error_located(&field, &entry, unknown(index, name, "coordinate")))?;
        if std::mem::replace(&mut given[i], true) {
            let message = format!("coordinate `{name}` is given twice");
            return Err(at.error_located(&field, &entry, message));
        }
        out[i] = if value.is_finite() {
            *value
        } else {
            let message = format!("must be finite, got {value}");
            return Err(at.error_located(&field, &entry, message));
        };
    }
    Ok((out, given))
}

/// The ranges of the runtime's settings (`camchain_runtime::settings`; a test in
/// `camchain-reference` checks that both accept and refuse the same values).
pub mod ranges {
    /// Relative tolerances of the adaptive integrators.
    pub const RTOL: (f64, f64) = (1e-14, 0.1);
    /// Absolute tolerances of the adaptive integrators.
    pub const ATOL: (f64, f64) = (1e-18, 1.0);
    /// The most samples of a run, t_end / dt_out.
    pub const MAX_SAMPLES: f64 = 1e6;
    /// The most RK4 steps per output interval, dt_out / dt.
    pub const MAX_RK4_STEPS: f64 = 1e7;
}

fn simulation(s: &raw::Simulation, at: &Locator) -> Checked<Simulation> {
    let field = |name: &str| format!("simulation.{name}");
    let integrator = match s.integrator {
        raw::Integrator::Rk4 => IntegratorChoice::Rk4,
        raw::Integrator::Dopri5 => IntegratorChoice::Dopri5,
        raw::Integrator::Dop853 => IntegratorChoice::Dop853,
    };
    let t_end = positive(at, &field("t_end"), "t_end", s.t_end)?;
    let dt_out = positive(at, &field("dt_out"), "dt_out", s.dt_out)?;
    let dt = positive(at, &field("dt"), "dt", s.dt)?;
    let samples = t_end / dt_out;
    if samples > ranges::MAX_SAMPLES {
        return Err(at.error(
            &field("dt_out"),
            format!(
                "t_end = {t_end} s with dt_out = {dt_out} s gives {samples:.3e} samples, more \
                 than the {:e} a run keeps: a larger dt_out or a smaller t_end",
                ranges::MAX_SAMPLES
            ),
        ));
    }
    let adaptive = !matches!(integrator, IntegratorChoice::Rk4);
    if !adaptive && dt_out / dt > ranges::MAX_RK4_STEPS {
        return Err(at.error(
            &field("dt"),
            format!(
                "an rk4 step of {dt:e} s needs {:.1e} steps per output interval (dt_out = \
                 {dt_out:e} s), more than the {:e} allowed",
                dt_out / dt,
                ranges::MAX_RK4_STEPS
            ),
        ));
    }
    // Checked whatever the file's integrator: they are the defaults of any adaptive run.
    let in_range = |name: &str, value: f64, (low, high): (f64, f64)| {
        if value.is_finite() && (low..=high).contains(&value) {
            Ok(value)
        } else {
            Err(at.error(
                &field(name),
                format!("{name} must be in [{low:e}, {high:e}], got {value:e}"),
            ))
        }
    };
    Ok(Simulation {
        t_end,
        dt_out,
        integrator,
        dt,
        rtol: in_range("rtol", s.rtol, ranges::RTOL)?,
        atol: in_range("atol", s.atol, ranges::ATOL)?,
    })
}
