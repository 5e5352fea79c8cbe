//! The model file exactly as written: serde types that mirror the RON format one to one.
//!
//! Defaults for optional fields live here; everything physical is checked later in
//! [`super::validate`]. The type names appear in the reader's messages ("Unexpected field
//! named `foo` in `Joint`"), so they are named after the file's concepts.

use camchain_runtime::kinds::Kind;
use camchain_runtime::{Formulation, IntegratorKind, JointKind, LoopKind};
use serde::de::{EnumAccess, MapAccess, VariantAccess, Visitor};
use serde::{Deserialize, Deserializer};
use std::fmt;
use std::marker::PhantomData;

/// Three numbers `(x, y, z)`, each a number or a parameter expression.
pub(super) type Vec3 = [Number; 3];

/// A numeric field: a number, or a string holding an expression of the model's parameters
/// (`"m1"`, `"l1/2"`, `"2*PI*rpm/60"`).
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Number {
    /// A number as written.
    Value(f64),
    /// An expression of the parameters, as written inside the quotes.
    Expr(String),
}

impl Number {
    pub(super) const ZERO: Number = Number::Value(0.0);
    pub(super) const ONE: Number = Number::Value(1.0);
}

impl Default for Number {
    fn default() -> Self {
        Number::ZERO
    }
}

impl<'de> Deserialize<'de> for Number {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(NumberVisitor)
    }
}

struct NumberVisitor;

impl Visitor<'_> for NumberVisitor {
    type Value = Number;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number or a string with an expression of the parameters")
    }

    fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Number, E> {
        Ok(Number::Value(v))
    }

    fn visit_f32<E: serde::de::Error>(self, v: f32) -> Result<Number, E> {
        Ok(Number::Value(f64::from(v)))
    }

    fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Number, E> {
        Ok(Number::Value(v as f64))
    }

    fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Number, E> {
        Ok(Number::Value(v as f64))
    }

    fn visit_i128<E: serde::de::Error>(self, v: i128) -> Result<Number, E> {
        Ok(Number::Value(v as f64))
    }

    fn visit_u128<E: serde::de::Error>(self, v: u128) -> Result<Number, E> {
        Ok(Number::Value(v as f64))
    }

    fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Number, E> {
        Ok(Number::Expr(v.to_string()))
    }
}

/// A parameter: a named number that fields and expressions use, with a default value that
/// a program or the command line may change at run time (unless it is `constant`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Parameter {
    pub name: String,
    pub value: f64,
    #[serde(default)]
    pub unit: String,
    #[serde(default)]
    pub min: Option<f64>,
    #[serde(default)]
    pub max: Option<f64>,
    #[serde(default)]
    pub constant: bool,
    #[serde(default)]
    pub description: String,
}

/// The top-level unnamed struct.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Model {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub description: String,
    #[serde(default)]
    pub parameters: Vec<Parameter>,
    #[serde(default)]
    pub gravity: Vec3,
    pub bodies: Vec<Body>,
    #[serde(default)]
    pub markers: Vec<Marker>,
    #[serde(default)]
    pub contacts: Vec<Contact>,
    #[serde(default)]
    pub loops: Vec<Loop>,
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
    pub mass: Number,
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
    Izz(Number),
    /// Principal moments along the body axes.
    Diagonal(Number, Number, Number),
    /// The full symmetric tensor; products default to zero.
    Full {
        ixx: Number,
        iyy: Number,
        izz: Number,
        #[serde(default)]
        ixy: Number,
        #[serde(default)]
        ixz: Number,
        #[serde(default)]
        iyz: Number,
    },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Joint {
    pub kind: Keyword<JointKind>,
    pub axis: Vec3,
    #[serde(default)]
    pub anchor: Vec3,
    pub coordinate: String,
    #[serde(default)]
    pub spring: Option<Spring>,
    #[serde(default)]
    pub prescribed: Option<String>,
    #[serde(default)]
    pub load: Option<String>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct Spring {
    pub stiffness: Number,
    pub damping: Number,
    pub rest: Number,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Marker {
    pub name: String,
    pub body: String,
    #[serde(default)]
    pub position: Vec3,
}

/// A loop: the joint it is cut at, between two markers.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Loop {
    pub name: String,
    pub kind: Keyword<LoopKind>,
    pub a: LoopSide,
    pub b: LoopSide,
    /// B's axis or line, B's body frame.
    #[serde(default)]
    pub axis: Option<Vec3>,
    /// A's axis or direction, A's body frame (defaults to `axis`).
    #[serde(default)]
    pub axis_a: Option<Vec3>,
}

/// A point of a body (or of the ground) that a loop closes at.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LoopSide {
    pub body: String,
    #[serde(default)]
    pub point: Vec3,
}

/// A contact: a follower (a marker and its shape) on a cam profile carried by a body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Contact {
    #[serde(default)]
    pub name: Option<String>,
    pub marker: String,
    #[serde(default)]
    pub follower: Follower,
    #[serde(default)]
    pub cam_body: Option<String>,
    /// An explicit profile y = f(x).
    #[serde(default)]
    pub profile: Option<String>,
    /// A polar profile r(θ).
    #[serde(default)]
    pub polar: Option<String>,
    /// A parametric profile (x(s), y(s)).
    #[serde(default)]
    pub parametric: Option<Parametric>,
    /// A surface z = f(x, y) over the cam plane.
    #[serde(default)]
    pub surface: Option<String>,
    /// A barrel cam: the pitch surface z = f(θ) on a cylinder about the cam's axis.
    #[serde(default)]
    pub barrel: Option<Barrel>,
    /// A surface of revolution r = g(z) about the cam's axis.
    #[serde(default)]
    pub revolution: Option<String>,
    /// A face cam: a groove in the cam plane, its centre line r = g(θ) or designed.
    #[serde(default)]
    pub face: Option<Face>,
    /// A profile through a table of points.
    #[serde(default)]
    pub table: Option<Table>,
    /// A cam designed from the follower's motion law.
    #[serde(default)]
    pub law: Option<Law>,
    #[serde(default)]
    pub range: Option<(f64, f64)>,
    /// Where a surface's follower goes: ((x₀, x₁), (y₀, y₁)) of the cam frame.
    #[serde(default)]
    pub region: Option<((f64, f64), (f64, f64))>,
    #[serde(default)]
    pub frame: Frame,
}

/// The follower's shape and dimensions, as written.
pub(super) type Follower = crate::model::Follower<Number>;

/// `barrel: (radius: R, groove: "f(theta)")` or `barrel: (radius: R, law: (…))`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Barrel {
    pub radius: Number,
    /// The pitch surface z = f(θ) as an expression of `theta`.
    #[serde(default)]
    pub groove: Option<String>,
    /// The pitch surface designed from the follower's motion law.
    #[serde(default)]
    pub law: Option<BarrelLaw>,
    /// The cylinder's length along its axis from the cam frame's origin (m): the groove
    /// must lie on it.
    #[serde(default)]
    pub length: Option<Number>,
    /// How much wider than the roller the groove is (m).
    #[serde(default)]
    pub backlash: Option<f64>,
    /// The groove takes a tapered roller whose apex lies on the cam's axis.
    #[serde(default)]
    pub tapered: bool,
}

/// `face: (groove: "g(theta)")` or `face: (law: (…))`: a face cam's groove.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Face {
    /// The groove's centre line r = g(θ) as an expression of `theta`.
    #[serde(default)]
    pub groove: Option<String>,
    /// The centre line designed from the follower's motion law (a disc cam's `law`).
    #[serde(default)]
    pub law: Option<Law>,
    /// How much wider than the roller the groove is (m).
    #[serde(default)]
    pub backlash: Option<f64>,
}

/// `law: (base: z₀, turning: …, segments: […])` of a barrel cam: the follower's travel along
/// the cam's axis over a turn, from the height z₀.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BarrelLaw {
    #[serde(default)]
    pub base: Number,
    #[serde(default)]
    pub turning: Turning,
    pub segments: Vec<LawSegment>,
    /// The cam's nominal speed (rad/s), for `camchain cam`.
    #[serde(default)]
    pub speed: Option<Number>,
    /// The largest pressure angle accepted without a warning (degrees).
    #[serde(default)]
    pub max_pressure_angle: Option<f64>,
}

/// `parametric: (x: "…", y: "…")`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Parametric {
    pub x: String,
    pub y: String,
}

/// `table: (form: …, file: "…" | points: […], ends: …, degrees: …)`: a profile through
/// points, interpolated by a C² cubic spline.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Table {
    pub form: TableForm,
    /// A CSV file of two columns, relative to the model file.
    #[serde(default)]
    pub file: Option<String>,
    /// The points written in the model file.
    #[serde(default)]
    pub points: Option<Vec<(f64, f64)>>,
    #[serde(default)]
    pub ends: Option<TableEnds>,
    /// A surface's ends along y (default: its `ends`, which are those along x).
    #[serde(default)]
    pub y_ends: Option<TableEnds>,
    /// A polar table's angles are in degrees (default: radians).
    #[serde(default)]
    pub degrees: bool,
}

/// What a table's two columns are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub(super) enum TableForm {
    /// x, y of y = f(x).
    Explicit,
    /// θ, r of r(θ).
    Polar,
    /// x, y of a curve, in order along it.
    Parametric,
    /// x, y, z of a surface z(x, y) on a grid, in any order.
    Surface,
}

/// A spline's end conditions.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) enum TableEnds {
    Natural,
    Clamped { start: f64, end: f64 },
    Periodic,
}

/// `law: (…)`: a cam designed from the follower's motion over a turn.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Law {
    pub base_radius: Number,
    #[serde(default)]
    pub motion: Motion,
    #[serde(default)]
    pub turning: Turning,
    pub segments: Vec<LawSegment>,
    /// Degrees.
    #[serde(default)]
    pub max_pressure_angle: Option<f64>,
    /// rad/s.
    #[serde(default)]
    pub speed: Option<Number>,
}

/// How the designed follower moves.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) enum Motion {
    Translating {
        #[serde(default)]
        offset: Number,
    },
    Oscillating {
        pivot: (Number, Number),
        arm: Number,
        #[serde(default)]
        swing: Turning,
        #[serde(default)]
        face_offset: Number,
    },
}

impl Default for Motion {
    fn default() -> Self {
        Motion::Translating {
            offset: Number::ZERO,
        }
    }
}

/// A direction of turning about the cam's axis.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
pub(super) enum Turning {
    #[default]
    Counterclockwise,
    Clockwise,
}

/// One segment of a motion program.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) enum LawSegment {
    Dwell {
        degrees: Number,
    },
    Rise {
        law: LawName,
        lift: Number,
        degrees: Number,
    },
    Return {
        law: LawName,
        #[serde(default)]
        lift: Number,
        degrees: Number,
    },
}

/// The standard motion laws.
#[derive(Debug, Clone, Copy, Deserialize)]
pub(super) enum LawName {
    Cycloidal,
    SimpleHarmonic,
    Polynomial345,
    Polynomial4567,
    ModifiedTrapezoid,
    ModifiedSine,
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
            origin: [Number::ZERO, Number::ZERO, Number::ZERO],
            x_axis: [Number::ONE, Number::ZERO, Number::ZERO],
            y_axis: [Number::ZERO, Number::ONE, Number::ZERO],
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

/// A kind from the project's registry ([`camchain_runtime::kinds`]) written as a bare
/// keyword (`Revolute`): exactly as registered, except integrators, which any letter case
/// names (`Dop853`, `dop853`, `DOP853`: the command line spells them in lower case, the file
/// traditionally as `Dop853`, and both mean the same).
#[derive(Debug, Clone, Copy)]
pub(super) struct Keyword<K>(pub K);

impl<'de, K: Kind> Deserialize<'de> for Keyword<K> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_enum(K::TYPE_NAME, K::KEYWORDS, KeywordVisitor(PhantomData))
    }
}

struct KeywordVisitor<K>(PhantomData<K>);

impl<'de, K: Kind> Visitor<'de> for KeywordVisitor<K> {
    type Value = Keyword<K>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}: {}", K::FAMILY, K::KEYWORDS.join(", "))
    }

    fn visit_str<E: serde::de::Error>(self, name: &str) -> Result<Keyword<K>, E> {
        if K::FAMILY == IntegratorKind::FAMILY {
            let names: Vec<&str> = IntegratorKind::ALL.iter().map(|k| k.name()).collect();
            // The located error appends ", found `<name>`".
            return K::parse(name).map(Keyword).ok_or_else(|| {
                E::custom(format!(
                    "unknown integrator (one of {}, in any letter case)",
                    names.join(", ")
                ))
            });
        }
        K::from_keyword(name)
            .map(Keyword)
            .ok_or_else(|| E::unknown_variant(name, K::KEYWORDS))
    }

    fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<Keyword<K>, A::Error> {
        let (name, variant): (Identifier, _) = data.variant()?;
        variant.unit_variant()?;
        self.visit_str(&name.0)
    }
}

/// A bare identifier (an enum variant's name as written).
struct Identifier(String);

impl<'de> Deserialize<'de> for Identifier {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Name;
        impl Visitor<'_> for Name {
            type Value = Identifier;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a name")
            }
            fn visit_str<E: serde::de::Error>(self, name: &str) -> Result<Identifier, E> {
                Ok(Identifier(name.to_string()))
            }
        }
        deserializer.deserialize_identifier(Name)
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct Simulation {
    pub t_end: f64,
    pub dt_out: f64,
    pub integrator: Keyword<IntegratorKind>,
    pub dt: f64,
    pub rtol: f64,
    pub atol: f64,
    pub restitution: Option<f64>,
    pub formulation: Keyword<Formulation>,
}

impl Default for Simulation {
    fn default() -> Self {
        Simulation {
            t_end: 10.0,
            dt_out: 0.01,
            integrator: Keyword(IntegratorKind::Dop853),
            dt: 1e-3,
            rtol: 1e-10,
            atol: 1e-12,
            restitution: None,
            formulation: Keyword(Formulation::Auto),
        }
    }
}

/// A `{"name": value}` map kept in file order with duplicates preserved, so that the
/// validator can report a name given twice instead of silently keeping the last one.
#[derive(Debug, Default)]
pub(super) struct NamedValues(pub Vec<(String, Number)>);

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
        while let Some(entry) = map.next_entry::<String, Number>()? {
            values.push(entry);
        }
        Ok(NamedValues(values))
    }
}
