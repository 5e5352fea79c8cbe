//! Contact test scenes: every contact kind (follower × profile) on cams carried by the
//! ground, by a turning body, and by a body that shares a moving base with the follower,
//! planar and spatial, written as model files. Shared by the code generator's tests and the
//! numeric reference's (`#[path]`-included there).
//!
//! The follower is an arm pivoted above the cam (coordinate `b`) with a slider along it
//! (`c`) carrying the marker `F`; the cam turns about its pivot at the origin (`a`). In the
//! `base` chain both sit on a sliding base (`u`), their common ancestor. States are drawn
//! where the follower point is within a few millimetres of the cam.

/// Where the cam sits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Chain {
    /// A cam fixed to the ground (the arm and slider move the follower).
    Ground,
    /// A cam turning about its pivot (coordinate `a`).
    Turning,
    /// Cam and follower on a common sliding base (coordinate `u`).
    Base,
    /// A turning cam about a tilted axis and a follower whose joints are skew (spatial).
    Spatial,
}

/// A contact: the follower and the profile lines of a model file.
#[derive(Debug, Clone, Copy)]
pub struct Kind {
    /// A short name for messages.
    pub name: &'static str,
    /// `follower: …` (empty for a knife edge).
    pub follower: &'static str,
    /// The profile lines (`profile:`, `polar:`, `parametric:`, `range:`).
    pub profile: &'static str,
    /// How far the marker sits from the profile at the drawn states (m): the roller's
    /// radius, 0 for a knife edge, a flat face or a curved face (whose marker is on the
    /// face).
    pub offset: f64,
    /// True when the kind needs the follower to turn only about the cam's axis.
    pub planar_only: bool,
    /// How far a turning cam turns at the drawn states (rad): an explicit profile is an open
    /// curve, drawn near its apex.
    pub turn: f64,
}

/// The surface of the kinds "knife on surface" and "ball on surface" sampled on a grid
/// (`tests/tables/scene_surface.csv`, made by evaluating the formula at the grid's points),
/// found from either crate that includes this file.
const GRID_SURFACE: &str = concat!(
    "table: (form: Surface, file: \"",
    env!("CARGO_MANIFEST_DIR"),
    "/../tests/tables/scene_surface.csv\"),"
);

impl Kind {
    /// The spacing of the knots of a surface given on a grid: its third derivatives jump
    /// across the knot lines (it is C², not C³), so second differences across one lose
    /// their order of accuracy. None for the other kinds (smooth to every order).
    pub fn knot_spacing(&self) -> Option<f64> {
        self.profile.contains("form: Surface").then_some(0.01)
    }

    /// True when second differences of this kind's terms between the follower points `a`
    /// and `b` (cam frame x, y) may cross a knot line of its grid: one lies between them or
    /// within 1.5 mm (a ball's foot lies within ρ sin α of its centre). False for a kind
    /// without a grid.
    pub fn crosses_a_knot(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        let Some(spacing) = self.knot_spacing() else {
            return false;
        };
        (0..2).any(|k| {
            let (lo, hi) = (a[k].min(b[k]) - 1.5e-3, a[k].max(b[k]) + 1.5e-3);
            (lo / spacing).floor() != (hi / spacing).floor()
        })
    }
}

/// Every follower on every profile form.
pub const KINDS: [Kind; 21] = [
    Kind {
        name: "knife on explicit",
        follower: "",
        profile: "profile: \"0.045 - 2.0*x*x + 0.3*x.powi(3)\",",
        offset: 0.0,
        planar_only: false,
        turn: 0.4,
    },
    Kind {
        name: "knife on polar",
        follower: "",
        profile: "polar: \"0.01*theta.cos() + (0.0016 - 0.0001*theta.sin().powi(2)).sqrt()\",",
        offset: 0.0,
        planar_only: false,
        turn: 3.1,
    },
    Kind {
        name: "knife on parametric",
        follower: "",
        profile: "parametric: (x: \"0.05*s.cos()\", y: \"0.042*s.sin()\"), range: (0.0, 6.283185307179586),",
        offset: 0.0,
        planar_only: false,
        turn: 3.1,
    },
    Kind {
        name: "roller on explicit",
        follower: "follower: Roller(radius: 0.012),",
        profile: "profile: \"0.045 - 2.0*x*x + 0.3*x.powi(3)\", range: (-0.2, 0.2),",
        offset: 0.012,
        planar_only: false,
        turn: 0.4,
    },
    Kind {
        name: "roller on polar",
        follower: "follower: Roller(radius: 0.012),",
        profile: "polar: \"0.01*theta.cos() + (0.0016 - 0.0001*theta.sin().powi(2)).sqrt()\",",
        offset: 0.012,
        planar_only: false,
        turn: 3.1,
    },
    Kind {
        name: "roller on parametric",
        follower: "follower: Roller(radius: 0.012),",
        profile: "parametric: (x: \"0.05*s.cos()\", y: \"0.042*s.sin()\"), range: (0.0, 6.283185307179586),",
        offset: 0.012,
        planar_only: false,
        turn: 3.1,
    },
    Kind {
        name: "flat on explicit",
        follower: "follower: Flat(normal: (0.0, -1.0, 0.0)),",
        profile: "profile: \"0.045 - 2.0*x*x + 0.3*x.powi(3)\", range: (-0.2, 0.2),",
        offset: 0.0,
        planar_only: true,
        turn: 0.4,
    },
    Kind {
        name: "flat on polar",
        follower: "follower: Flat(normal: (0.0, -1.0, 0.0)),",
        profile: "polar: \"0.01*theta.cos() + (0.0016 - 0.0001*theta.sin().powi(2)).sqrt()\",",
        offset: 0.0,
        planar_only: true,
        turn: 3.1,
    },
    Kind {
        name: "flat on parametric",
        follower: "follower: Flat(normal: (0.0, -1.0, 0.0)),",
        profile: "parametric: (x: \"0.05*s.cos()\", y: \"0.042*s.sin()\"), range: (0.0, 6.283185307179586),",
        offset: 0.0,
        planar_only: true,
        turn: 3.1,
    },
    Kind {
        name: "mushroom on explicit",
        follower: "follower: Mushroom(radius: 0.03, normal: (0.0, -1.0, 0.0)),",
        profile: "profile: \"0.045 - 2.0*x*x + 0.3*x.powi(3)\", range: (-0.2, 0.2),",
        offset: 0.0,
        planar_only: true,
        turn: 0.4,
    },
    Kind {
        name: "mushroom on polar",
        follower: "follower: Mushroom(radius: 0.03, normal: (0.0, -1.0, 0.0)),",
        profile: "polar: \"0.01*theta.cos() + (0.0016 - 0.0001*theta.sin().powi(2)).sqrt()\",",
        offset: 0.0,
        planar_only: true,
        turn: 3.1,
    },
    Kind {
        name: "mushroom on parametric",
        follower: "follower: Mushroom(radius: 0.03, normal: (0.0, -1.0, 0.0)),",
        profile: "parametric: (x: \"0.05*s.cos()\", y: \"0.042*s.sin()\"), range: (0.0, 6.283185307179586),",
        offset: 0.0,
        planar_only: true,
        turn: 3.1,
    },
    // A surface over the cam plane with every second derivative non-zero and varying, its
    // height near the follower's (the marker sits in the chain's plane, the cam plane's
    // z = 0 within millimetres): the knife edge touches it in three dimensions.
    Kind {
        name: "knife on surface",
        follower: "",
        profile: "surface: \"0.001 + 0.3*x*y - 0.5*x*x + 0.002*(30.0*y).sin() + 0.4*y*y*x\",",
        offset: 0.0,
        planar_only: false,
        turn: 0.4,
    },
    // A ball on the same surface: its centre (the marker) a few millimetres above it, the
    // foot point found in two dimensions.
    Kind {
        name: "ball on surface",
        follower: "follower: Roller(radius: 0.004),",
        profile: "surface: \"0.001 + 0.3*x*y - 0.5*x*x + 0.002*(30.0*y).sin() + 0.4*y*y*x\",",
        offset: 0.0,
        planar_only: false,
        turn: 0.4,
    },
    // The same surface as points: a 41 × 41 grid of it over [-0.2, 0.2]² (spacing 0.01 m),
    // interpolated by the bicubic spline, followed by a point and by a ball.
    Kind {
        name: "knife on grid",
        follower: "",
        profile: GRID_SURFACE,
        offset: 0.0,
        planar_only: false,
        turn: 0.4,
    },
    Kind {
        name: "ball on grid",
        follower: "follower: Roller(radius: 0.004),",
        profile: GRID_SURFACE,
        offset: 0.0,
        planar_only: false,
        turn: 0.4,
    },
    // A barrel cam's pitch surface z = g(θ) about the cam frame's axis, followed by a point
    // and by a roller's centre (the groove's flank the radius away).
    Kind {
        name: "knife on barrel",
        follower: "",
        profile: "barrel: (radius: 0.045, groove: \"0.002*theta.sin() + 0.001*(2.0*theta).cos()\"),",
        offset: 0.0,
        planar_only: false,
        turn: 3.1,
    },
    // A surface of revolution about the cam frame's axis (a waisted drum), the follower
    // point outside it at the polar profiles' distance.
    Kind {
        name: "knife on revolution",
        follower: "",
        profile: "revolution: \"0.045 + 3.0*z*z + 0.002*(40.0*z).sin()\",",
        offset: 0.0,
        planar_only: false,
        turn: 3.1,
    },
    // A ball outside the same drum, its centre a few millimetres farther out.
    Kind {
        name: "ball on revolution",
        follower: "follower: Roller(radius: 0.004),",
        profile: "revolution: \"0.045 + 3.0*z*z + 0.002*(40.0*z).sin()\", range: (-0.05, 0.05),",
        offset: 0.004,
        planar_only: false,
        turn: 3.1,
    },
    Kind {
        name: "roller on barrel",
        follower: "follower: Roller(radius: 0.01),",
        profile: "barrel: (radius: 0.045, groove: \"0.002*theta.sin() + 0.001*(2.0*theta).cos()\"),",
        offset: 0.0,
        planar_only: false,
        turn: 3.1,
    },
    // A face cam's groove whose centre line is the polar profiles' curve: the roller's
    // centre on it, the inner flank the radius in.
    Kind {
        name: "roller in face groove",
        follower: "follower: Roller(radius: 0.006),",
        profile: "face: (groove: \"0.01*theta.cos() + (0.0016 - 0.0001*theta.sin().powi(2)).sqrt()\"),",
        offset: 0.0,
        planar_only: false,
        turn: 3.1,
    },
];

/// The chains each kind is tested on.
pub fn chains(kind: &Kind) -> Vec<Chain> {
    let mut chains = vec![Chain::Ground, Chain::Turning, Chain::Base];
    if !kind.planar_only {
        chains.push(Chain::Spatial);
    }
    chains
}

/// The model file of `kind` on `chain`.
pub fn scene(kind: &Kind, chain: Chain) -> String {
    let (base, cam_parent, arm_parent) = match chain {
        Chain::Base => (
            "(name: \"base\", parent: \"ground\", mass: 2.0, com: (0.0, 0.05, 0.0), \
             inertia: Izz(0.01), joint: (kind: Prismatic, axis: (1.0, 0.0, 0.0), \
             coordinate: \"u\")),",
            "base",
            "base",
        ),
        _ => ("", "ground", "ground"),
    };
    let (cam_axis, arm_axis, slide_axis, frame) = match chain {
        Chain::Spatial => (
            "(0.1, 0.2, 1.0)",
            "(0.2, 0.0, 1.0)",
            "(0.05, -1.0, 0.1)",
            "frame: (origin: (0.002, -0.001, 0.003), x_axis: (1.0, 0.0, 0.0), \
             y_axis: (0.0, 0.9950041652780258, 0.09983341664682815)),",
        ),
        _ => (
            "(0.0, 0.0, 1.0)",
            "(0.0, 0.0, 1.0)",
            "(0.0, -1.0, 0.0)",
            "frame: (origin: (0.002, -0.001, 0.0), x_axis: (0.9950041652780258, \
             0.09983341664682815, 0.0), y_axis: (-0.09983341664682815, 0.9950041652780258, 0.0)),",
        ),
    };
    let cam = match chain {
        Chain::Ground => String::new(),
        _ => format!(
            "(name: \"cam\", parent: \"{cam_parent}\", mass: 1.0, com: (0.003, 0.002, 0.0), \
             inertia: Izz(0.002), joint: (kind: Revolute, axis: {cam_axis}, \
             coordinate: \"a\", spring: (stiffness: 3.0, damping: 0.1))),"
        ),
    };
    let cam_body = if chain == Chain::Ground {
        ""
    } else {
        "cam_body: \"cam\","
    };
    format!(
        "(
    name: \"scene\",
    gravity: (0.0, -9.81, 0.0),
    bodies: [
        {base}
        {cam}
        (name: \"arm\", parent: \"{arm_parent}\", mass: 0.4, com: (0.0, -0.05, 0.0), inertia: Izz(0.001),
         joint: (kind: Revolute, axis: {arm_axis}, anchor: (0.0, 0.15, 0.01), coordinate: \"b\",
                 spring: (stiffness: 2.0, rest: 0.0))),
        (name: \"slider\", parent: \"arm\", mass: 0.2, com: (0.0, -0.01, 0.0), inertia: Izz(0.0002),
         joint: (kind: Prismatic, axis: {slide_axis}, coordinate: \"c\",
                 spring: (stiffness: 50.0, damping: 0.2, rest: 0.06))),
    ],
    markers: [(name: \"F\", body: \"slider\", position: (0.0, 0.0, 0.0))],
    contacts: [(marker: \"F\", {cam_body} {} {} {frame})],
)",
        kind.follower, kind.profile
    )
}

/// A tiny deterministic generator (xorshift) so the tests need no extra crate.
pub struct Rng(pub u64);

impl Rng {
    /// A uniform number in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// A state of `kind` on `chain` (coordinates in body order: [u,] [a,] b, c) with random
/// velocities: the cam within ±`kind.turn`, the arm within ±0.25 rad, the slider extended so that the follower
/// point is roughly `offset` + 0…6 mm from a cam whose size is about 40–50 mm.
pub fn state(kind: &Kind, chain: Chain, rng: &mut Rng) -> (Vec<f64>, Vec<f64>) {
    let offset = kind.offset;
    let mut q = Vec::new();
    if chain == Chain::Base {
        q.push(rng.uniform(-0.05, 0.05));
    }
    if chain != Chain::Ground {
        q.push(rng.uniform(-kind.turn, kind.turn));
    }
    let b = rng.uniform(-0.25, 0.25);
    // The follower point is 0.15 − c below the arm's pivot, about |0.15 − c| from the
    // cam's pivot; the cams reach 0.042 … 0.05.
    let c = 0.15 - 0.05 - offset - rng.uniform(0.001, 0.006);
    q.extend([b, c]);
    let qd = q.iter().map(|_| rng.uniform(-2.0, 2.0)).collect();
    (q, qd)
}
