//! The cam's shape in the validated model ([`Profile`]): a curve in the cam plane, a surface
//! over it, a barrel's or a face cam's groove, each given by expressions.

use crate::profile::Scalar;

/// A cam profile: a curve in the cam plane, or a surface over it, given by expressions with
/// symbolic derivatives.
#[derive(Debug, Clone, PartialEq)]
pub enum Profile {
    /// y = f(x) (the paper's form, eq. 3); the cam's material is below the curve (y < f(x)).
    Explicit {
        /// f as written (variable `x`).
        source: String,
        /// Parsed f.
        f: Scalar,
    },
    /// The points r(θ)·(cos θ, sin θ), θ the angle from the cam frame's x axis: a disc cam,
    /// its material inside the curve. r must be positive.
    Polar {
        /// r as written (variable `theta`).
        source: String,
        /// Parsed r.
        r: Scalar,
    },
    /// The points (x(s), y(s)); the cam's material is on the left of the direction of
    /// increasing s (inside a curve traced counterclockwise), the follower on the right.
    Parametric {
        /// x(s) as written.
        x_source: String,
        /// y(s) as written.
        y_source: String,
        /// Parsed x(s).
        x: Scalar,
        /// Parsed y(s).
        y: Scalar,
    },
    /// A surface z = f(x, y) over the cam plane, z along the cam's axis x̂ × ŷ; the cam's
    /// material is below it (z < f(x, y)), the follower above. A spatial cam: the follower
    /// point moves on it in three dimensions (docs/method.md, "Cam surfaces").
    Surface {
        /// f as written (variables `x` and `y`).
        source: String,
        /// Parsed f.
        f: Scalar,
    },
    /// A barrel (cylindrical) cam: the pitch surface z = f(θ) of a groove or rib on a
    /// cylinder about the cam's axis, θ the follower point's angle about that axis from x̂.
    /// The follower point (a roller's centre) stays on it; the cam's material is on the side
    /// z < f(θ) of the point touched (docs/method.md §13.4).
    Barrel {
        /// f as written (variable `theta`), or the motion law's description.
        source: String,
        /// Parsed f, or the law's tabulated displacement.
        f: Scalar,
        /// The pitch cylinder's radius R (m): where the roller's centre runs.
        radius: f64,
        /// The cylinder's length along its axis from the cam frame's origin (m), when the
        /// file gives it: the groove's flanks must lie on it.
        length: Option<f64>,
    },
    /// A surface of revolution r = g(z) about the cam frame's axis x̂ × ŷ, r the distance
    /// from that axis: the cam's material inside it (r < g(z)), the follower outside
    /// (docs/method.md §13.5).
    Revolution {
        /// g as written (variable `z`).
        source: String,
        /// Parsed g.
        g: Scalar,
    },
    /// A face (end) cam: a groove cut in the cam plane, its centre line `centre` (a
    /// [`Profile::Polar`] r = g(θ), or the [`Profile::Parametric`] pitch curve of a law
    /// design). A roller's centre (or a knife edge) stays on the centre line; the roller
    /// touches the inner flank (the centre line moved towards the cam's material by the
    /// roller's radius) when the normal force is positive, the outer one when it is negative
    /// (docs/method.md §13.7).
    Face {
        /// The groove's centre line: polar or parametric, the follower on its right.
        centre: Box<Profile>,
    },
}

impl Profile {
    /// `explicit`, `polar`, `parametric` or `surface`.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Profile::Explicit { .. } => "explicit",
            Profile::Polar { .. } => "polar",
            Profile::Parametric { .. } => "parametric",
            Profile::Surface { .. } => "surface",
            Profile::Barrel { .. } => "barrel",
            Profile::Revolution { .. } => "revolution",
            Profile::Face { .. } => "face",
        }
    }

    /// The name of the profile's (first) variable in its expressions: a surface's second
    /// is `y`.
    pub fn variable(&self) -> &'static str {
        match self {
            Profile::Explicit { .. } | Profile::Surface { .. } => "x",
            Profile::Polar { .. } | Profile::Barrel { .. } => "theta",
            Profile::Revolution { .. } => "z",
            Profile::Parametric { .. } => "s",
            Profile::Face { centre } => centre.variable(),
        }
    }

    /// True for a surface (a spatial cam: over the cam plane, or a barrel's), false for a
    /// plane curve.
    pub fn is_surface(&self) -> bool {
        match self {
            Profile::Surface { .. } | Profile::Barrel { .. } | Profile::Revolution { .. } => true,
            Profile::Explicit { .. }
            | Profile::Polar { .. }
            | Profile::Parametric { .. }
            | Profile::Face { .. } => false,
        }
    }

    /// The expression of the field `Field::Profile(c)`: f, r, x(s), a surface's f(x, y), a
    /// face cam's centre line's.
    pub fn expression(&self) -> &Scalar {
        match self {
            Profile::Explicit { f, .. }
            | Profile::Surface { f, .. }
            | Profile::Barrel { f, .. } => f,
            Profile::Revolution { g, .. } => g,
            Profile::Polar { r, .. } => r,
            Profile::Parametric { x, .. } => x,
            Profile::Face { centre } => centre.expression(),
        }
    }

    /// The same profile with every parameter replaced by its value in `values`.
    pub fn resolve_all(&self, values: &[f64]) -> Profile {
        let source = |s: &String| s.clone();
        match self {
            Profile::Explicit { source: s, f } => Profile::Explicit {
                source: source(s),
                f: f.resolve_all(values),
            },
            Profile::Polar { source: s, r } => Profile::Polar {
                source: source(s),
                r: r.resolve_all(values),
            },
            Profile::Parametric {
                x_source,
                y_source,
                x,
                y,
            } => Profile::Parametric {
                x_source: source(x_source),
                y_source: source(y_source),
                x: x.resolve_all(values),
                y: y.resolve_all(values),
            },
            Profile::Surface { source: s, f } => Profile::Surface {
                source: source(s),
                f: f.resolve_all(values),
            },
            Profile::Barrel {
                source: s,
                f,
                radius,
                length,
            } => Profile::Barrel {
                source: source(s),
                f: f.resolve_all(values),
                radius: *radius,
                length: *length,
            },
            Profile::Revolution { source: s, g } => Profile::Revolution {
                source: source(s),
                g: g.resolve_all(values),
            },
            Profile::Face { centre } => Profile::Face {
                centre: Box::new(centre.resolve_all(values)),
            },
        }
    }

    /// The plane curve the contact follows: a face cam's groove centre line, the profile
    /// itself otherwise.
    pub fn curve(&self) -> &Profile {
        match self {
            Profile::Face { centre } => centre,
            Profile::Explicit { .. }
            | Profile::Polar { .. }
            | Profile::Parametric { .. }
            | Profile::Surface { .. }
            | Profile::Barrel { .. }
            | Profile::Revolution { .. } => self,
        }
    }
}
