//! The model file exactly as written: serde types that mirror the RON format one to one.
//!
//! Defaults for optional fields live here; everything physical is checked later in
//! [`super::validate`]. The type names appear in ron's messages ("unexpected field named
//! `foo` in `Joint`"), so they are named after the file's concepts.

use serde::de::{MapAccess, Visitor};
use serde::{Deserialize, Deserializer};
use std::fmt;

/// Three numbers `(x, y, z)`.
pub(super) type Vec3 = [f64; 3];

/// The top-level unnamed struct.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Model {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub description: String,
    #[serde(default)]
    pub gravity: Vec3,
    pub bodies: Vec<Body>,
    #[serde(default)]
    pub markers: Vec<Marker>,
    #[serde(default)]
    pub contacts: Vec<Contact>,
    #[serde(default)]
    pub initial: Initial,
    #[serde(default)]
    pub simulation: Simulation,
}

/// One rigid body and the joint to its parent.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Body {
    pub name: String,
    pub parent: String,
    pub mass: f64,
    #[serde(default)]
    pub com: Vec3,
    pub inertia: Inertia,
    pub joint: Joint,
}

/// Inertia about the centre of mass in body axes; off-diagonals are tensor components.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) enum Inertia {
    /// A lamina in the body x-y plane: Ixx = Iyy = Izz / 2.
    Izz(f64),
    /// Principal moments along the body axes.
    Diagonal(f64, f64, f64),
    /// The full symmetric tensor; products default to zero.
    Full {
        ixx: f64,
        iyy: f64,
        izz: f64,
        #[serde(default)]
        ixy: f64,
        #[serde(default)]
        ixz: f64,
        #[serde(default)]
        iyz: f64,
    },
}

#[derive(Debug, Clone, Copy, Deserialize)]
pub(super) enum JointKind {
    Revolute,
    Prismatic,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Joint {
    pub kind: JointKind,
    pub axis: Vec3,
    #[serde(default)]
    pub anchor: Vec3,
    pub coordinate: String,
    #[serde(default)]
    pub spring: Option<Spring>,
    #[serde(default)]
    pub prescribed: Option<String>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct Spring {
    pub stiffness: f64,
    pub damping: f64,
    pub rest: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Marker {
    pub name: String,
    pub body: String,
    #[serde(default)]
    pub position: Vec3,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Contact {
    pub marker: String,
    pub profile: String,
    #[serde(default)]
    pub frame: Frame,
}

/// The cam plane; every field defaults to the ground frame's.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct Frame {
    pub origin: Vec3,
    pub x_axis: Vec3,
    pub y_axis: Vec3,
}

impl Default for Frame {
    fn default() -> Self {
        Frame {
            origin: [0.0; 3],
            x_axis: [1.0, 0.0, 0.0],
            y_axis: [0.0, 1.0, 0.0],
        }
    }
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct Initial {
    pub q: NamedValues,
    pub qd: NamedValues,
    pub hold: Vec<String>,
}

#[derive(Debug, Clone, Copy, Deserialize)]
pub(super) enum Integrator {
    Rk4,
    Dopri5,
    Dop853,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct Simulation {
    pub t_end: f64,
    pub dt_out: f64,
    pub integrator: Integrator,
    pub dt: f64,
    pub rtol: f64,
    pub atol: f64,
}

impl Default for Simulation {
    fn default() -> Self {
        Simulation {
            t_end: 10.0,
            dt_out: 0.01,
            integrator: Integrator::Dop853,
            dt: 1e-3,
            rtol: 1e-10,
            atol: 1e-12,
        }
    }
}

/// A `{"name": value}` map kept in file order with duplicates preserved, so that the
/// validator can report a name given twice instead of silently keeping the last one.
#[derive(Debug, Default)]
pub(super) struct NamedValues(pub Vec<(String, f64)>);

impl<'de> Deserialize<'de> for NamedValues {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_map(NamedValuesVisitor)
    }
}

struct NamedValuesVisitor;

impl<'de> Visitor<'de> for NamedValuesVisitor {
    type Value = NamedValues;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a map from coordinate names to numbers, e.g. {\"q1\": 0.5}")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<NamedValues, A::Error> {
        let mut values = Vec::new();
        while let Some(entry) = map.next_entry::<String, f64>()? {
            values.push(entry);
        }
        Ok(NamedValues(values))
    }
}
