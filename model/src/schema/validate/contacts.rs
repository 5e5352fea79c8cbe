//! Contacts: the follower (a marker and its shape), the cam body and frame, the profile,
//! and the checks that the follower can follow the profile (a roller no larger than the
//! profile's hollows, a flat face on a convex profile turning only about the cam's axis, a
//! polar radius that stays positive), each located at the field it concerns.

use super::bodies::BodyTree;
use super::fields::{closes, finite, identifier, lookup, unit_vector};
use super::markers::cam_axes;
use super::parameters::expression;
use super::{Checked, Context, Field, Follower, GROUND, Locator, Marker, Profile};
use crate::jet::{Jet2, eval_on_all, own_tables};
use crate::model::{Body, Contact, JointKind, RuntimeCheck};
use crate::samples::profile_samples;
use crate::schema::raw;
use camchain_runtime::contact::{
    PROFILE_CHECK_SAMPLES, Place, Shape, followable as followable_checked,
};
use camchain_runtime::kinds::Outline;
use std::collections::HashMap;

pub(super) fn contacts(
    list: &[raw::Contact],
    markers: &[Marker],
    tree: &BodyTree,
    bodies: &[Body],
    cx: &Context,
) -> Checked<Vec<Contact>> {
    let at = cx.at;
    let by_name: HashMap<&str, usize> = markers
        .iter()
        .enumerate()
        .map(|(i, m)| (m.name.as_str(), i))
        .collect();
    let mut names: HashMap<&str, usize> = HashMap::new();
    let mut spelled: HashMap<String, (usize, &str)> = HashMap::new();
    for (i, c) in list.iter().enumerate() {
        let (field, name) = match &c.name {
            Some(name) => (format!("contacts[{i}].name"), name.as_str()),
            None => (format!("contacts[{i}].marker"), c.marker.as_str()),
        };
        identifier(at, &field, name, "contact name")?;
        if let Some(first) = names.insert(name, i) {
            let message = if c.name.is_some() {
                format!("duplicate contact name `{name}` (contacts[{first}])")
            } else {
                format!(
                    "marker `{name}` already has a contact (contacts[{first}]): a second contact \
                     on it needs a `name` of its own"
                )
            };
            return Err(at.error(&field, message));
        }
        let spelling = generated_spelling(name);
        if let Some((first, other)) = spelled.insert(spelling.clone(), (i, name)) {
            return Err(at.error(
                &field,
                format!(
                    "contact name `{name}` differs from `{other}` (contacts[{first}]) only in \
                     letter case or underscores: the generated code spells both `{spelling}`; \
                     choose another contact name"
                ),
            ));
        }
        name_free(cx, &field, name, c.name.is_some(), bodies)?;
    }
    list.iter()
        .enumerate()
        .map(|(i, c)| {
            let field = format!("contacts[{i}].marker");
            let marker = lookup(at, &field, &by_name, &c.marker, "marker")?;
            let contact = contact(cx, tree, i, c, marker, markers[marker].body)?;
            followable(at, i, &contact)?;
            recheck_at_run_time(cx, i, &contact);
            if contact.follower.normal().is_some() {
                turns_about_the_cam_axis(at, i, &contact, bodies, markers)?;
            }
            Ok(contact)
        })
        .collect()
}

/// How the generated code spells a contact's name in its function names: lower case, with
/// runs of `_` as one and none at either end (`emit::parameters::value_name`).
fn generated_spelling(name: &str) -> String {
    name.to_ascii_lowercase()
        .split('_')
        .filter(|part| !part.is_empty())
        .collect::<Vec<_>>()
        .join("_")
}

/// The build names the point of contact `name` on its profile `<name>_parameter`, among the
/// variables of the coordinates and the run-time parameters: no coordinate or parameter may
/// be called so (the two would be one variable).
fn name_free(cx: &Context, field: &str, name: &str, named: bool, bodies: &[Body]) -> Checked<()> {
    let variable = format!("{name}_parameter");
    let owner = if bodies.iter().any(|b| b.joint.coordinate == variable) {
        "coordinate"
    } else if cx.table.names.contains(&variable) {
        "parameter"
    } else {
        return Ok(());
    };
    let whose = if named {
        format!("contact name `{name}`")
    } else {
        format!("contact name `{name}` (its marker's, as the contact has no `name`)")
    };
    Err(cx.at.error(
        field,
        format!(
            "{whose} clashes with {owner} `{variable}`: the build calls the contact's point on \
             its profile `{variable}`; give the contact another `name` or rename the {owner}"
        ),
    ))
}

fn contact(
    cx: &Context,
    tree: &BodyTree,
    i: usize,
    c: &raw::Contact,
    marker: usize,
    follower_body: usize,
) -> Checked<Contact> {
    let at = cx.at;
    let path = format!("contacts[{i}]");
    let cam_body = match c.cam_body.as_deref() {
        None | Some(GROUND) => None,
        Some(name) => Some(tree.sorted_body(at, &format!("{path}.cam_body"), name)?),
    };
    if cam_body == Some(follower_body) {
        return Err(at.error(
            &format!("{path}.cam_body"),
            format!(
                "the cam is on the body that carries the marker `{}`: a contact needs two \
                 bodies that move relative to each other",
                c.marker
            ),
        ));
    }
    let (x_axis, y_axis) = cam_axes(cx, &format!("{path}.frame"), &c.frame)?;
    let follower = follower(cx, &path, &c.follower, i)?;
    let name = c.name.clone().unwrap_or_else(|| c.marker.clone());
    let backlash = super::faces::backlash(cx, &path, c)?;
    let taper = super::barrels::taper(cx, &path, c, i, &follower)?;
    let Shaped {
        profile,
        covers,
        design,
    } = profile(cx, &path, c, i, &name, &follower)?;
    let range = contact_range(at, &path, c, &profile, &follower, covers)?;
    if let Some(region) = c.region {
        surface_region(at, &path, &profile, region)?;
    }
    Ok(Contact {
        name,
        marker,
        follower,
        profile,
        cam_body,
        origin: cx.vector_of(&format!("{path}.frame.origin"), &c.frame.origin, |k| {
            Field::Origin(i, k)
        })?,
        x_axis,
        y_axis,
        range,
        design,
        backlash,
        taper,
    })
}

/// A profile with what its form brings: the interval a table covers, a law's design.
struct Shaped {
    profile: Profile,
    covers: Option<(f64, f64)>,
    design: Option<crate::design::CamDesign>,
}

impl From<Profile> for Shaped {
    fn from(profile: Profile) -> Self {
        Shaped {
            profile,
            covers: None,
            design: None,
        }
    }
}

/// The profile: exactly one of `profile` (explicit), `polar`, `parametric`, `surface` (a
/// surface z = f(x, y)), `table` (through points) and `law` (designed from the follower's
/// motion).
fn profile(
    cx: &Context,
    path: &str,
    c: &raw::Contact,
    i: usize,
    name: &str,
    follower: &Follower,
) -> Checked<Shaped> {
    let given = [
        ("profile", c.profile.is_some()),
        ("polar", c.polar.is_some()),
        ("parametric", c.parametric.is_some()),
        ("surface", c.surface.is_some()),
        ("barrel", c.barrel.is_some()),
        ("revolution", c.revolution.is_some()),
        ("face", c.face.is_some()),
        ("table", c.table.is_some()),
        ("law", c.law.is_some()),
    ];
    let named: Vec<&str> = given.iter().filter(|g| g.1).map(|g| g.0).collect();
    if named.len() != 1 {
        let (field, message) = match named.as_slice() {
            [] => (
                format!("{path}.marker"),
                "a contact needs a cam profile: `profile: \"f(x)\"` (explicit y = f(x)), \
                 `polar: \"r(theta)\"`, `parametric: (x: \"x(s)\", y: \"y(s)\")`, `surface: \
                 \"f(x, y)\"` (a surface z = f(x, y)), `barrel: (…)` (a barrel cam), `revolution: \
                 \"g(z)\"` (a surface of revolution r = g(z)), `face: (…)` (a face cam's groove), `table: (…)` (through points) or `law: (…)` (designed from the follower's motion)"
                    .to_string(),
            ),
            [.., last] => (
                format!("{path}.{last}"),
                format!(
                    "give only one of `profile`, `polar`, `parametric`, `surface`, `barrel`, \
                     `revolution`, `face`, `table` and `law` (this contact gives {})",
                    named
                        .iter()
                        .map(|n| format!("`{n}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ),
        };
        return Err(cx.at.error(&field, message));
    }
    if let Some(table) = &c.table {
        let (profile, covers) = super::tables::table_profile(cx, path, table, (name, follower))?;
        return Ok(Shaped {
            profile,
            covers,
            design: None,
        });
    }
    if let Some(law) = &c.law {
        let field = format!("{path}.law");
        let (profile, design) = super::designs::law_profile(
            cx,
            (path, &field),
            law,
            (i, name),
            follower,
            super::designs::Traced::Profile,
        )?;
        return Ok(Shaped {
            profile,
            covers: Some((0.0, std::f64::consts::TAU)),
            design: Some(design),
        });
    }
    if let Some(source) = &c.surface {
        return surface(cx, path, source, i, follower).map(Shaped::from);
    }
    if let Some(source) = &c.revolution {
        return revolution(cx, path, source, i, follower).map(Shaped::from);
    }
    if let Some(face) = &c.face {
        let (profile, design) = super::faces::face_profile(cx, path, face, (i, name), follower)?;
        return Ok(Shaped {
            profile,
            covers: Some((0.0, std::f64::consts::TAU)),
            design,
        });
    }
    if let Some(barrel) = &c.barrel {
        let (profile, design) =
            super::barrels::barrel_profile(cx, path, barrel, i, name, follower)?;
        return Ok(Shaped {
            profile,
            covers: None,
            design,
        });
    }
    if let Some(source) = &c.profile {
        let f = expression(
            cx,
            &format!("{path}.profile"),
            source,
            &["x"],
            Field::Profile(i),
        )?;
        return Ok(Profile::Explicit {
            source: source.clone(),
            f,
        }
        .into());
    }
    if let Some(source) = &c.polar {
        let r = expression(
            cx,
            &format!("{path}.polar"),
            source,
            &["theta"],
            Field::Profile(i),
        )?;
        return Ok(Profile::Polar {
            source: source.clone(),
            r,
        }
        .into());
    }
    let p = c.parametric.as_ref().ok_or_else(|| {
        cx.at
            .error(&format!("{path}.parametric"), "missing parametric profile")
    })?;
    let x = expression(
        cx,
        &format!("{path}.parametric.x"),
        &p.x,
        &["s"],
        Field::Profile(i),
    )?;
    let y = expression(
        cx,
        &format!("{path}.parametric.y"),
        &p.y,
        &["s"],
        Field::ProfileY(i),
    )?;
    Ok(Profile::Parametric {
        x_source: p.x.clone(),
        y_source: p.y.clone(),
        x,
        y,
    }
    .into())
}

/// Samples per side of a surface's region checked before running.
const REGION_SAMPLES: usize = 33;

/// A surface's `region`, ((x₀, x₁), (y₀, y₁)): finite and increasing, and the surface defined
/// over it with the two derivatives the dynamics read. f, its gradient and its Hessian are
/// evaluated by jets along x, y and x + y at 33 × 33 points; the first point where one is
/// not a finite number is refused, with what failed and where.
fn surface_region(
    at: &Locator,
    path: &str,
    profile: &Profile,
    ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)),
) -> Checked<()> {
    let field = format!("{path}.region");
    let Profile::Surface { f, .. } = profile else {
        return Err(at.error(
            &field,
            "only a surface (`surface: \"f(x, y)\"`) takes a `region`: the part of the cam \
             plane its follower goes over",
        ));
    };
    for (value, k) in [
        (x0, "[0][0]"),
        (x1, "[0][1]"),
        (y0, "[1][0]"),
        (y1, "[1][1]"),
    ] {
        finite(at, &format!("{field}{k}"), value)?;
    }
    if x0 >= x1 || y0 >= y1 {
        return Err(at.error(
            &field,
            format!(
                "the region's intervals must be increasing, got x in ({x0}, {x1}) and y in \
                 ({y0}, {y1})"
            ),
        ));
    }
    let along = |x: f64, y: f64, dx: f64, dy: f64| {
        let line = |v: f64, d: f64| Jet2 { v, d1: d, d2: 0.0 };
        eval_on_all(f, &[line(x, dx), line(y, dy)], &own_tables)
    };
    let n = REGION_SAMPLES - 1;
    for i in 0..=n {
        for j in 0..=n {
            let x = x0 + (x1 - x0) * i as f64 / n as f64;
            let y = y0 + (y1 - y0) * j as f64 / n as f64;
            let (ex, ey, diagonal) = (
                along(x, y, 1.0, 0.0),
                along(x, y, 0.0, 1.0),
                along(x, y, 1.0, 1.0),
            );
            let quantities = [
                ("f", ex.v),
                ("∂f/∂x", ex.d1),
                ("∂f/∂y", ey.d1),
                ("∂²f/∂x²", ex.d2),
                ("∂²f/∂y²", ey.d2),
                ("∂²f/∂x∂y", 0.5 * (diagonal.d2 - ex.d2 - ey.d2)),
            ];
            if let Some((what, value)) = quantities.iter().find(|q| !q.1.is_finite()) {
                return Err(at.error(
                    &format!("{path}.surface"),
                    format!(
                        "the surface is not defined over its region: {what} = {value} at (x, y) \
                         = ({x}, {y}); the follower may go anywhere in x ∈ [{x0}, {x1}], y ∈ \
                         [{y0}, {y1}] (narrow the region or change the surface)"
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// A surface of revolution r = g(z): an expression of `z` and the parameters, followed by a
/// point (a knife edge) outside it.
fn revolution(
    cx: &Context,
    path: &str,
    source: &str,
    i: usize,
    follower: &Follower,
) -> Checked<Profile> {
    let what = "a surface of revolution: it takes a point (`follower: Knife`) or a ball \
                (`follower: Roller(radius: …)`, its centre the marker)";
    let g = point_surface(
        cx,
        path,
        ("revolution", &["z"]),
        source,
        i,
        (follower, what, true),
    )?;
    Ok(Profile::Revolution {
        source: source.to_string(),
        g,
    })
}

/// A surface z = f(x, y): an expression of `x`, `y` and the parameters, followed by a point
/// (a knife edge) or a ball (a `Roller`, its centre on the offset surface).
fn surface(
    cx: &Context,
    path: &str,
    source: &str,
    i: usize,
    follower: &Follower,
) -> Checked<Profile> {
    let what = "a surface: a surface takes a point (`follower: Knife`) or a ball (`follower: \
                Roller(radius: …)`, its centre the marker)";
    let f = point_surface(
        cx,
        path,
        ("surface", &["x", "y"]),
        source,
        i,
        (follower, what, true),
    )?;
    Ok(Profile::Surface {
        source: source.to_string(),
        f,
    })
}

/// The expression of a surface followed by a point (or by a ball where `balls`), parsed
/// from `field` (of `variables`); any other follower is refused with "a flat face cannot
/// follow {what}".
fn point_surface(
    cx: &Context,
    path: &str,
    (field, variables): (&str, &[&str]),
    source: &str,
    i: usize,
    (follower, what, balls): (&Follower, &str, bool),
) -> Checked<crate::profile::Scalar> {
    let f = expression(
        cx,
        &format!("{path}.{field}"),
        source,
        variables,
        Field::Profile(i),
    )?;
    super::grids::surface_follower(cx, path, (follower, what, balls))?;
    Ok(f)
}

fn follower(cx: &Context, path: &str, f: &raw::Follower, i: usize) -> Checked<Follower> {
    let what = f.kind().label();
    f.try_map(
        |radius, name| {
            let field = format!("{path}.follower.{name}");
            cx.positive(&field, radius, Field::Radius(i), "the follower's radius")
        },
        |normal, name| {
            let field = format!("{path}.follower.{name}");
            let v = cx.vector(&field, normal, None)?;
            unit_vector(cx.at, &field, &format!("the {what}'s {name}"), v)
        },
    )
}

/// The profile interval a contact may touch: given (finite, increasing), or [0, 2π] for a
/// polar profile, or the interval a table or a law covers (`covers`); required where the
/// contact point is searched for along the profile (a parametric profile) or undercutting
/// is checked (a roller or a flat face).
fn contact_range(
    at: &Locator,
    path: &str,
    c: &raw::Contact,
    profile: &Profile,
    follower: &Follower,
    covers: Option<(f64, f64)>,
) -> Checked<Option<(f64, f64)>> {
    let field = format!("{path}.range");
    // A ball outside a surface of revolution takes the heights its contact point may reach.
    let ball_on_revolution = matches!(profile, Profile::Revolution { .. })
        && follower.kind().outline() == Outline::Circle;
    if c.range.is_some() && profile.is_surface() && !ball_on_revolution {
        return Err(at.error(
            &field,
            "a surface has no `range`: the follower point may be anywhere over the cam plane \
             (a barrel's round the cylinder, a point on a surface of revolution at any height)",
        ));
    }
    if let Some((a, b)) = c.range {
        finite(at, &format!("{field}[0]"), a)?;
        finite(at, &format!("{field}[1]"), b)?;
        if a >= b {
            return Err(at.error(
                &field,
                format!("the range must be increasing, got ({a}, {b})"),
            ));
        }
        return Ok(Some((a, b)));
    }
    if covers.is_some() {
        return Ok(covers);
    }
    let needs = match (profile, follower.kind().outline()) {
        (Profile::Polar { .. }, _) => return Ok(Some((0.0, std::f64::consts::TAU))),
        // A face cam's groove given as r = g(θ) runs round the turn (a law's covers it).
        (Profile::Face { .. }, _) => return Ok(Some((0.0, std::f64::consts::TAU))),
        (Profile::Parametric { .. }, _) => Some("a parametric profile".to_string()),
        (Profile::Explicit { .. }, Outline::Point) => None,
        // A barrel's groove is a graph over the whole turn, a surface over the whole plane
        // (a ball's foot point is searched from the centre's own x, y): no range.
        (Profile::Barrel { .. } | Profile::Surface { .. }, _) => None,
        // A ball on a surface of revolution: the heights its contact point may take, where
        // the meridian is scanned when Newton from the centre's own height fails.
        (Profile::Revolution { .. }, Outline::Point) => None,
        (Profile::Revolution { .. }, Outline::Circle | Outline::Line) => Some(format!(
            "a {} on a surface of revolution (the heights z its contact point may take)",
            follower.kind().label()
        )),
        (Profile::Explicit { .. }, Outline::Circle | Outline::Line) => Some(format!(
            "a {} on an explicit profile",
            follower.kind().label()
        )),
    };
    match needs {
        None => Ok(None),
        Some(what) => Err(at.error(
            &format!("{path}.marker"),
            format!(
                "{what} needs `range: (from, to)`: the interval of the profile's variable the \
                 follower may touch, where undercutting is checked and the contact point is \
                 first searched for"
            ),
        )),
    }
}

/// The follower can follow the profile over its range (`camchain_runtime::contact::
/// followable`, which generated code repeats when the radius or the profile depends on
/// run-time parameters), and a polar profile closes on itself.
fn followable(at: &Locator, i: usize, contact: &Contact) -> Checked<()> {
    let Some(range) = contact.range else {
        return Ok(());
    };
    let path = format!("contacts[{i}]");
    if let Profile::Face { .. } = contact.profile {
        return super::faces::groove_fits(at, &path, contact);
    }
    let samples = profile_samples(&contact.profile, range, PROFILE_CHECK_SAMPLES);
    let shape = Shape {
        kind: contact.follower.kind(),
        radius: contact.follower.radius().copied().unwrap_or(0.0),
    };
    followable_checked(&contact.name, contact.profile.variable(), shape, &samples).map_err(
        |(place, message)| {
            let field = match place {
                Place::Radius => format!("{path}.follower.radius"),
                Place::Follower => format!("{path}.follower"),
                Place::Profile => format!("{path}.{}", profile_field(contact)),
            };
            at.error(&field, message)
        },
    )?;
    if let Profile::Polar { r, .. } = &contact.profile {
        closes(at, &format!("{path}.{}", profile_field(contact)), r)?;
    }
    Ok(())
}

/// When the roller's radius or the profile depends on run-time parameters, the generated
/// code repeats [`followable`] for each parameter set.
fn recheck_at_run_time(cx: &Context, i: usize, contact: &Contact) {
    let table = cx.table;
    let runtime_radius = table.is_runtime(Field::Radius(i));
    let runtime_profile =
        table.is_runtime(Field::Profile(i)) || table.is_runtime(Field::ProfileY(i));
    // A face or barrel cam's groove: the roller fits it on both flanks (`faces::groove_fits`,
    // `barrels::groove_fits`), and a barrel's groove stays on its cylinder.
    let matters = match contact.follower.kind().outline() {
        _ if matches!(
            contact.profile,
            Profile::Face { .. } | Profile::Barrel { .. }
        ) =>
        {
            true
        }
        Outline::Point => matches!(contact.profile, Profile::Polar { .. }),
        Outline::Circle | Outline::Line => true,
    };
    let groove = matches!(contact.profile, Profile::Barrel { .. });
    if (contact.range.is_some() || groove) && matters && (runtime_radius || runtime_profile) {
        let path = format!("contacts[{i}]");
        // A barrel refuses flat faces: the follower's place holds its length's instead.
        let second = match contact.profile {
            Profile::Barrel { .. } => format!("{path}.barrel.length"),
            _ => format!("{path}.follower"),
        };
        table.check(RuntimeCheck::Followable(
            i,
            [
                super::location(cx.at, &format!("{path}.follower.radius")),
                super::location(cx.at, &second),
                super::location(cx.at, &format!("{path}.{}", profile_field(contact))),
            ],
        ));
    }
}

/// The field that holds a contact's profile.
fn profile_field(contact: &Contact) -> &'static str {
    match (&contact.profile, &contact.design) {
        (Profile::Face { .. }, Some(_)) => return "face.law",
        (Profile::Face { .. }, None) => return "face.groove",
        (Profile::Barrel { .. }, Some(_)) => return "barrel.law",
        (_, Some(_)) => return "law",
        (_, None) => {}
    }
    match &contact.profile {
        Profile::Explicit { f, .. } if is_table(f) => "table",
        Profile::Polar { r, .. } if is_table(r) => "table",
        Profile::Parametric { x, .. } if is_table(x) => "table",
        Profile::Surface { f, .. } if is_table(f) => "table",
        Profile::Explicit { .. } => "profile",
        Profile::Polar { .. } => "polar",
        Profile::Parametric { .. } => "parametric",
        Profile::Surface { .. } => "surface",
        Profile::Barrel { .. } => "barrel",
        Profile::Revolution { .. } => "revolution",
        Profile::Face { .. } => "face",
    }
}

/// True for a profile or a surface read from a table of points (its expression a tabulated
/// leaf).
fn is_table(e: &crate::profile::Scalar) -> bool {
    matches!(
        e,
        crate::profile::Scalar::Table(..) | crate::profile::Scalar::Grid(..)
    )
}

/// A flat face's normal stays in the cam plane only if the follower turns relative to the
/// cam about the cam's axis: every revolute joint between them (below their common
/// ancestor) must turn about that axis, and the face normal must be perpendicular to it.
fn turns_about_the_cam_axis(
    at: &Locator,
    i: usize,
    contact: &Contact,
    bodies: &[Body],
    markers: &[Marker],
) -> Checked<()> {
    let Some(&normal) = contact.follower.normal() else {
        return Ok(());
    };
    let axis = contact.axis();
    let parallel = |u: [f64; 3]| {
        let cross = [
            u[1] * axis[2] - u[2] * axis[1],
            u[2] * axis[0] - u[0] * axis[2],
            u[0] * axis[1] - u[1] * axis[0],
        ];
        cross.iter().all(|c| c.abs() < 1e-12)
    };
    let path_of = |body: Option<usize>| {
        let mut path = Vec::new();
        let mut at = body;
        while let Some(b) = at {
            path.push(b);
            at = bodies[b].parent;
        }
        path
    };
    let follower_path = path_of(Some(markers[contact.marker].body));
    let cam_path = path_of(contact.cam_body);
    let between = follower_path
        .iter()
        .filter(|b| !cam_path.contains(b))
        .chain(cam_path.iter().filter(|b| !follower_path.contains(b)));
    let path = format!("contacts[{i}].follower");
    for &b in between {
        let joint = &bodies[b].joint;
        if joint.kind == JointKind::Revolute && !parallel(joint.axis) {
            return Err(at.error(
                &path,
                format!(
                    "contact `{}`: a flat face may turn relative to its cam only about the \
                     cam's axis {}, but joint `{}` between them turns about {}",
                    contact.name,
                    vector(axis),
                    joint.coordinate,
                    vector(joint.axis)
                ),
            ));
        }
    }
    let dot: f64 = normal.iter().zip(&axis).map(|(a, b)| a * b).sum();
    if dot.abs() > 1e-12 {
        return Err(at.error(
            &format!("{path}.normal"),
            format!(
                "contact `{}`: the face normal {} must lie in the cam plane (perpendicular to \
                 the cam's axis {})",
                contact.name,
                vector(normal),
                vector(axis)
            ),
        ));
    }
    Ok(())
}

/// `(x, y, z)` as a model file writes it (no `-0`).
fn vector(v: [f64; 3]) -> String {
    let [x, y, z] = v.map(|c| c + 0.0);
    format!("({x:?}, {y:?}, {z:?})")
}
