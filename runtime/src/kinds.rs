//! The kinds the whole project names, each defined once: joints, followers, loop joints and
//! integrators.
//!
//! Every crate uses these enums: the model file's parser reads their keywords, the generator
//! emits them (`rt::FollowerKind::Roller`), the reference and the command line match on
//! them, and messages, summaries and reports print their names from here. A kind is one line
//! of its registry below (its variant and its [`FollowerSpec`], [`LoopSpec`] or
//! [`IntegratorSpec`]); the compiler then lists every `match` that must grow, since no code
//! matches a kind with a catch-all arm. What each crate does for a kind lives in that crate's
//! module for the kind (ARCHITECTURE.md, "Add a follower kind").

/// Defines a kind's enum, its list [`FollowerKind::ALL`]-style and its `spec()` from one
/// line per kind: `Variant => Spec { … }`.
macro_rules! registry {
    (
        $(#[$meta:meta])*
        pub enum $kind:ident: $spec:ident, $family:literal {
            $( $(#[$vmeta:meta])* $variant:ident => $value:expr, )+
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum $kind {
            $( $(#[$vmeta])* $variant, )+
        }

        impl $kind {
            /// Every kind, in the order of the registry.
            pub const ALL: &'static [$kind] = &[$($kind::$variant),+];

            /// The kind's names and properties.
            pub fn spec(self) -> &'static $spec {
                match self {
                    $( $kind::$variant => {
                        const SPEC: $spec = $value;
                        &SPEC
                    } )+
                }
            }

            /// The variant's name as the model file and generated code spell it
            /// (`Roller`, `PointOnLine`, `Dop853`).
            pub fn keyword(self) -> &'static str {
                match self {
                    $( $kind::$variant => stringify!($variant), )+
                }
            }

            /// The kind whose [`keyword`](Self::keyword) or name is `word`, in any letter
            /// case (`Dop853`, `dop853`, `point_on_line`).
            pub fn parse(word: &str) -> Option<$kind> {
                let plain = |s: &str| s.replace('_', "").to_ascii_lowercase();
                let word = plain(word);
                Self::ALL.iter().copied().find(|k| {
                    plain(k.keyword()) == word || plain(k.spec().name) == word
                })
            }

            /// The keywords of every kind, as the model file spells them.
            pub fn keywords() -> Vec<&'static str> {
                Self::ALL.iter().map(|k| k.keyword()).collect()
            }

            /// The kind's name in messages, output and on the command line (`roller`,
            /// `point_on_line`, `dop853`).
            pub fn name(self) -> &'static str {
                self.spec().name
            }
        }

        impl Kind for $kind {
            const FAMILY: &'static str = $family;
            const TYPE_NAME: &'static str = stringify!($kind);
            const KEYWORDS: &'static [&'static str] = &[$(stringify!($variant)),+];

            fn keyword(self) -> &'static str {
                $kind::keyword(self)
            }

            fn parse(word: &str) -> Option<Self> {
                $kind::parse(word)
            }
        }

        impl std::fmt::Display for $kind {
            /// The kind's [`name`](Self::name).
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }
    };
}

/// What every family of kinds offers, for code that reads or lists any of them (the model
/// file's parser).
pub trait Kind: Copy + Sized + 'static {
    /// The family's name in messages (`follower`, `loop kind`, `integrator`).
    const FAMILY: &'static str;
    /// The enum's name (`JointKind`): what a file's parser calls the enum in its messages.
    const TYPE_NAME: &'static str;
    /// Every kind's keyword, in the order of the registry.
    const KEYWORDS: &'static [&'static str];
    /// The kind's keyword, as the model file and generated code spell it.
    fn keyword(self) -> &'static str;
    /// The kind whose keyword or name is `word`, in any letter case.
    fn parse(word: &str) -> Option<Self>;
    /// The kind whose keyword is exactly `word`.
    fn from_keyword(word: &str) -> Option<Self> {
        Self::parse(word).filter(|k| k.keyword() == word)
    }
}

/// A joint kind's names and the units of its coordinate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct JointSpec {
    /// Its name in messages and output (`revolute`).
    pub name: &'static str,
    /// What its coordinate measures, in figure titles (`rotation`).
    pub motion: &'static str,
    /// The units of its coordinate, rate and acceleration (`rad`, `rad/s`, `rad/s²`).
    pub units: [&'static str; 3],
    /// The unit of the load that drives it (`N m`: a torque; `N`: a force).
    pub load_unit: &'static str,
}

registry! {
    /// The kind of a body's joint to its parent, and of the coordinate it carries
    /// (docs/model-format.md, "Bodies").
    pub enum JointKind: JointSpec, "joint kind" {
        /// Rotation about the joint's axis; the coordinate is an angle.
        Revolute => JointSpec { name: "revolute", motion: "rotation", units: ["rad", "rad/s", "rad/s²"], load_unit: "N m" },
        /// Translation along the joint's axis; the coordinate is a displacement.
        Prismatic => JointSpec { name: "prismatic", motion: "displacement in the guide", units: ["m", "m/s", "m/s²"], load_unit: "N" },
    }
}

impl JointKind {
    /// The unit of its coordinate (`rad`, `m`).
    pub fn unit(self) -> &'static str {
        self.spec().units[0]
    }
}

/// What outline a follower presents to its cam: it decides which profiles the follower can
/// follow ([`crate::contact::followable`]), how a cam is designed for it and how it is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Outline {
    /// A point: any smooth profile.
    Point,
    /// A circle of the follower's radius: no hollow of the profile tighter than it.
    Circle,
    /// A straight line: only a strictly convex profile.
    Line,
}

/// A follower kind's names and properties.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FollowerSpec {
    /// Its name in messages and output (`knife`).
    pub name: &'static str,
    /// What summaries and reports call it (`knife edge`).
    pub label: &'static str,
    /// The outline it presents to the cam.
    pub outline: Outline,
    /// Its contact point slides on the follower (a knife edge, a face); false where the
    /// follower rolls on the cam (a roller's rim), so that only the cam's surface slides.
    pub slides: bool,
}

registry! {
    /// The shape of a contact's follower (docs/model-format.md, "Contacts").
    pub enum FollowerKind: FollowerSpec, "follower" {
        /// A point of the follower (the paper's knife edge).
        Knife => FollowerSpec { name: "knife", label: "knife edge", outline: Outline::Point, slides: true },
        /// A roller (a circle centred on the follower point).
        Roller => FollowerSpec { name: "roller", label: "roller", outline: Outline::Circle, slides: false },
        /// A flat face through the follower point.
        Flat => FollowerSpec { name: "flat", label: "flat face", outline: Outline::Line, slides: true },
        /// A curved (mushroom) face: a circular arc whose apex is the follower point.
        Mushroom => FollowerSpec { name: "mushroom", label: "curved face", outline: Outline::Circle, slides: true },
    }
}

impl FollowerKind {
    /// What summaries and reports call it (`knife edge`, `flat face`).
    pub fn label(self) -> &'static str {
        self.spec().label
    }

    /// The outline it presents to the cam.
    pub fn outline(self) -> Outline {
        self.spec().outline
    }
}

/// The equations a loop's cut joint contributes: the suffixes of its CSV columns, in the
/// order of its rows of h.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LoopSpec {
    /// Its name in messages and output (`point_on_line`).
    pub name: &'static str,
    /// Its equations in a planar model: `x`, `y` for the components of A − B in ground
    /// axes, `normal` for A − B across the line, `turn` for A's direction across B's line.
    pub planar: &'static [&'static str],
    /// Its equations in a spatial model (`z`; `normal_1`, `normal_2` across a line;
    /// `tilt_1`, `tilt_2` for A's axis across B's).
    pub spatial: &'static [&'static str],
}

registry! {
    /// The kind of joint a loop is cut at (docs/method.md §11).
    pub enum LoopKind: LoopSpec, "loop kind" {
        /// A pin: the two points coincide (planar: 2 equations; spatial: 5 with the axes).
        Revolute => LoopSpec { name: "revolute", planar: &["x", "y"], spatial: &["x", "y", "z", "tilt_1", "tilt_2"] },
        /// A ball joint: the two points coincide (3 equations).
        Spherical => LoopSpec { name: "spherical", planar: &["x", "y", "z"], spatial: &["x", "y", "z"] },
        /// A planar slider: a point on a line, no relative turn (2 equations).
        Prismatic => LoopSpec { name: "prismatic", planar: &["normal", "turn"], spatial: &["normal", "turn"] },
        /// A pin in a slot: a point on a line (planar: 1 equation; spatial: 2).
        PointOnLine => LoopSpec { name: "point_on_line", planar: &["normal"], spatial: &["normal_1", "normal_2"] },
    }
}

impl LoopKind {
    /// The names of its equations in a planar or a spatial model (see [`LoopSpec`]).
    pub fn equations(self, planar: bool) -> &'static [&'static str] {
        if planar {
            self.spec().planar
        } else {
            self.spec().spatial
        }
    }
}

/// A forward-dynamics formulation's names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FormulationSpec {
    /// Its name in messages and output (`articulated`).
    pub name: &'static str,
    /// What it is, for help texts and generated headers.
    pub about: &'static str,
}

registry! {
    /// How a model's generated code solves for the accelerations (docs/method.md §14): the
    /// model file's `simulation: (formulation: …)` and `camchain_build::Config::formulation`.
    #[derive(Default)]
    pub enum Formulation: FormulationSpec, "formulation" {
        /// The one with the smaller estimated operation count per right-hand side.
        #[default]
        Auto => FormulationSpec { name: "auto", about: "the smaller estimated operation count per right-hand side" },
        /// M, F and Q formed, the reduced mass matrix factored: O(n²) to form, O(n³) to
        /// factor, the least work for small models.
        Dense => FormulationSpec { name: "dense", about: "the mass matrix formed and the reduced system factored" },
        /// The articulated-body sweeps, O(n) each, one more sweep per constraint row.
        Articulated => FormulationSpec { name: "articulated", about: "the articulated-body sweeps, one more per constraint row" },
    }
}

/// An integrator's names and properties.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IntegratorSpec {
    /// Its name on the command line and in output (`dop853`).
    pub name: &'static str,
    /// What it is, for help texts and reports.
    pub about: &'static str,
    /// Adaptive: tolerances, error control, dense output.
    pub adaptive: bool,
}

registry! {
    /// Integrator choice.
    pub enum IntegratorKind: IntegratorSpec, "integrator" {
        /// Classical fixed-step Runge–Kutta 4 (step `dt`).
        Rk4 => IntegratorSpec { name: "rk4", about: "classical Runge–Kutta 4 with the fixed step dt", adaptive: false },
        /// Adaptive embedded Dormand–Prince 5(4) with error control on (u, u̇); dense output
        /// of order 4 between steps.
        Dopri5 => IntegratorSpec { name: "dopri5", about: "adaptive Dormand–Prince 5(4) with error control by rtol and atol", adaptive: true },
        /// Adaptive Dormand–Prince 8(5,3) with error control on (u, u̇); dense output of
        /// order 7 between steps. The fastest choice for tight tolerances.
        Dop853 => IntegratorSpec { name: "dop853", about: "adaptive Dormand–Prince 8(5,3) with error control by rtol and atol; the fastest for tight tolerances", adaptive: true },
    }
}

impl IntegratorKind {
    /// True for the adaptive integrators (tolerances, error control, dense output).
    pub fn is_adaptive(self) -> bool {
        self.spec().adaptive
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every kind's keyword and name parse back to it, in any letter case, and no two kinds
    /// of a family share a name.
    #[test]
    fn names_parse_back_and_are_distinct() {
        for &k in FollowerKind::ALL {
            assert_eq!(FollowerKind::parse(k.keyword()), Some(k));
            assert_eq!(FollowerKind::parse(&k.name().to_uppercase()), Some(k));
        }
        for &k in JointKind::ALL {
            assert_eq!(JointKind::parse(k.keyword()), Some(k));
            assert_eq!(JointKind::parse(k.name()), Some(k));
        }
        for &k in LoopKind::ALL {
            assert_eq!(LoopKind::parse(k.keyword()), Some(k));
            assert_eq!(LoopKind::parse(k.name()), Some(k));
        }
        for &k in IntegratorKind::ALL {
            assert_eq!(IntegratorKind::parse(k.keyword()), Some(k));
            assert_eq!(
                IntegratorKind::parse("DOP853"),
                Some(IntegratorKind::Dop853)
            );
        }
        assert_eq!(
            LoopKind::parse("point_on_line"),
            Some(LoopKind::PointOnLine)
        );
        assert_eq!(FollowerKind::parse("cylinder"), None);
        let names: std::collections::HashSet<_> =
            FollowerKind::ALL.iter().map(|k| k.name()).collect();
        assert_eq!(names.len(), FollowerKind::ALL.len());
    }

    /// The spec follows the variant (the registry's `match` pairs them in order).
    #[test]
    fn specs_belong_to_their_variants() {
        assert_eq!(FollowerKind::Roller.outline(), Outline::Circle);
        assert_eq!(JointKind::Revolute.unit(), "rad");
        assert_eq!(JointKind::Prismatic.spec().load_unit, "N");
        assert_eq!(FollowerKind::Flat.label(), "flat face");
        assert_eq!(LoopKind::Revolute.equations(false).len(), 5);
        assert_eq!(LoopKind::PointOnLine.equations(true), ["normal"]);
        assert!(!IntegratorKind::Rk4.is_adaptive());
        assert!(IntegratorKind::Dop853.is_adaptive());
        assert_eq!(IntegratorKind::Dopri5.to_string(), "dopri5");
    }
}
