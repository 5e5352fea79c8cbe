//! Cams designed from the follower's motion law: the pitch curve and the profile as exact
//! expressions of the cam angle (the classical envelope construction), and the quantities a
//! cam designer checks (docs/method.md §10).
//!
//! The design frame D is the cam frame when the cam angle θ is 0; the follower is fixed in
//! it and the cam turns by σθ about its axis (σ = +1 counterclockwise, −1 clockwise), so a
//! point X of D has the cam-frame coordinates R(−σθ) X. The motion law s(θ) (a
//! [`MotionProgram`]) is the follower's lift above the base circle: a distance for a
//! translating follower, the arm's angle for an oscillating one.
//!
//! - **Knife edge or roller** (radius ρ, 0 for a knife): the follower point P(θ) (the knife's
//!   edge, the roller's centre) traces the pitch curve p = R(−σθ) P. Its tangent in D
//!   components is T = P′ − σ J P (J a quarter turn counterclockwise), its outward normal
//!   ν = σ J T/|T|, and the profile is the pitch curve moved in by ρ along ν:
//!   c(θ) = R(−σθ)(P − ρ ν).
//!   Translating (offset e, guide along D's y axis): P = (e, y₀ + s), y₀ = √((R_b + ρ)² − e²).
//!   Oscillating (pivot A, arm a, the arm turning by κ = ±1 as the follower rises):
//!   P = A + a u(φ), φ = φ₀ + κ s, φ₀ where |P| = R_b + ρ.
//! - **Flat face**: the face is a line of D with unit normal n (from the cam into the
//!   follower) at the support value d: n·X = d. Seen from the cam the line turns at the rate
//!   ω = φ′ − σ, and the envelope of the lines (the contact point) is
//!   Q = d n + (d′/ω) J n, in D components. Translating: n = (0, 1), d = R_b + s;
//!   oscillating: n = κ J u(φ), d = n·A − f (the face at the distance f from the pivot's line
//!   towards the cam).
//!
//! The profile's radius of curvature, in closed form: for a knife or roller the pitch
//! curve's ρ_p = −σ|T|³/(T × T′ − σ|T|²) (positive where convex) less ρ; for a flat face
//! d + (d′/ω)′/ω (R_b + s + s″ for a translating face). Undercutting is a radius that
//! reaches zero; the pressure angle is the angle between the contact normal and the
//! direction in which the follower point moves.
//!
//! The same formulas build the profile's expressions ([`Scalar`], exact, with the law a
//! tabulated leaf) and its numbers (`f64`): one generic implementation over [`Number`].

use crate::profile::{Func, Scalar, Tabulated};
use camchain_runtime::kinds::{FollowerKind, Outline};
use camchain_runtime::motion_law::MotionProgram;
use std::ops::{Add, Div, Mul, Neg, Sub};
use std::sync::Arc;

/// Samples of a turn for a design's checks and warnings (then refined around the worst).
pub const DESIGN_SAMPLES: usize = 3600;

/// The arithmetic the construction needs: `f64` for numbers, [`Scalar`] for expressions.
pub trait Number:
    Clone
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// A constant.
    fn constant(value: f64) -> Self;
    /// sin
    fn sin(&self) -> Self;
    /// cos
    fn cos(&self) -> Self;
    /// Square root.
    fn sqrt(&self) -> Self;
}

impl Number for f64 {
    fn constant(value: f64) -> Self {
        value
    }
    fn sin(&self) -> Self {
        f64::sin(*self)
    }
    fn cos(&self) -> Self {
        f64::cos(*self)
    }
    fn sqrt(&self) -> Self {
        f64::sqrt(*self)
    }
}

impl Number for Scalar {
    fn constant(value: f64) -> Self {
        Scalar::Const(value)
    }
    fn sin(&self) -> Self {
        self.clone().call(Func::Sin)
    }
    fn cos(&self) -> Self {
        self.clone().call(Func::Cos)
    }
    fn sqrt(&self) -> Self {
        self.clone().call(Func::Sqrt)
    }
}

/// A plane vector.
type V<N> = [N; 2];

fn add<N: Number>(a: &V<N>, b: &V<N>) -> V<N> {
    [a[0].clone() + b[0].clone(), a[1].clone() + b[1].clone()]
}

fn sub<N: Number>(a: &V<N>, b: &V<N>) -> V<N> {
    [a[0].clone() - b[0].clone(), a[1].clone() - b[1].clone()]
}

fn scale<N: Number>(k: &N, a: &V<N>) -> V<N> {
    [k.clone() * a[0].clone(), k.clone() * a[1].clone()]
}

fn dot<N: Number>(a: &V<N>, b: &V<N>) -> N {
    a[0].clone() * b[0].clone() + a[1].clone() * b[1].clone()
}

fn cross<N: Number>(a: &V<N>, b: &V<N>) -> N {
    a[0].clone() * b[1].clone() - a[1].clone() * b[0].clone()
}

/// J a: a turned a quarter turn counterclockwise.
fn perp<N: Number>(a: &V<N>) -> V<N> {
    [-a[1].clone(), a[0].clone()]
}

/// a turned by the angle whose cosine and sine are `cos`, `sin`.
fn turn<N: Number>(a: &V<N>, cos: &N, sin: &N) -> V<N> {
    [
        cos.clone() * a[0].clone() - sin.clone() * a[1].clone(),
        sin.clone() * a[0].clone() + cos.clone() * a[1].clone(),
    ]
}

/// ±k as a number.
fn signed<N: Number>(sign: f64, k: N) -> N {
    if sign < 0.0 { -k } else { k }
}

/// How the designed follower moves, in the design frame D.
#[derive(Debug, Clone, PartialEq)]
pub enum Motion<N> {
    /// Along D's y axis, on the line x = `offset` (m).
    Translating {
        /// The guide's offset e from the cam's centre (m).
        offset: N,
    },
    /// Turning about `pivot` (D, m), the follower point at `arm` (m) from it.
    Oscillating {
        /// The arm's pivot in D (m).
        pivot: V<N>,
        /// From the pivot to the follower point (m); a flat face ignores it.
        arm: N,
        /// A flat face's distance from the pivot's line, towards the cam (m).
        face_offset: N,
    },
    /// Along the cam's axis, beside a barrel cam: the design frame D is then the groove
    /// developed at the pitch radius, D's x the arc length round the cylinder (the
    /// follower at x = 0), its y the height along the axis; the follower point at height
    /// `base_radius` + s (the design's base is the groove's height at the program's start).
    Axial {
        /// The pitch radius R (m): where the roller's centre runs.
        radius: N,
    },
}

/// The dimensions of a design: numbers, or expressions of the run-time parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Geometry<N> {
    /// R_b: the base circle's radius (m), the cam's smallest radius.
    pub base_radius: N,
    /// ρ: the roller's radius (m); 0 for a knife edge or a flat face.
    pub roller: N,
    /// How the follower moves.
    pub motion: Motion<N>,
}

/// The constants of a design that fix the shape of its expressions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Senses {
    /// σ: +1 when the cam turns counterclockwise about its axis, −1 clockwise.
    pub turning: f64,
    /// κ: +1 when an oscillating follower's arm turns counterclockwise as it rises.
    pub swing: f64,
    /// The follower's kind: its outline decides the construction (a point or a circle:
    /// the pitch curve; a line: the face's envelope).
    pub shape: FollowerKind,
}

/// The follower at one cam angle, design-frame components.
#[derive(Debug, Clone, PartialEq)]
pub struct Placed<N> {
    /// The follower point: the knife edge, the roller's centre; for a flat face the contact
    /// point.
    pub pitch: V<N>,
    /// The contact point on the profile.
    pub contact: V<N>,
    /// The unit normal at the contact, from the cam into the follower.
    pub normal: V<N>,
    /// The unit direction in which the follower moves the contact's follower point.
    pub motion: V<N>,
}

/// The arm's direction at the base circle, u(φ₀), for an oscillating follower: the arm
/// points from the pivot towards the cam's centre, turned by κγ (a knife or roller: |P| =
/// R_b + ρ by the law of cosines) or by κ·asin((R_b + f)/|A|) (a flat face tangent to the
/// base circle).
fn base_direction<N: Number>(g: &Geometry<N>, senses: Senses) -> V<N> {
    let Motion::Oscillating {
        pivot,
        arm,
        face_offset,
    } = &g.motion
    else {
        return [N::constant(1.0), N::constant(0.0)];
    };
    let d = dot(pivot, pivot).sqrt();
    let inward = scale(&(N::constant(-1.0) / d.clone()), pivot);
    let (cos, sin) = match senses.shape.outline() {
        Outline::Point | Outline::Circle => {
            let rp = g.base_radius.clone() + g.roller.clone();
            let cos = (d.clone() * d.clone() + arm.clone() * arm.clone() - rp.clone() * rp)
                / (N::constant(2.0) * d * arm.clone());
            let sin = (N::constant(1.0) - cos.clone() * cos.clone()).sqrt();
            (cos, sin)
        }
        Outline::Line => {
            let sin = (g.base_radius.clone() + face_offset.clone()) / d;
            let cos = (N::constant(1.0) - sin.clone() * sin.clone()).sqrt();
            (cos, sin)
        }
    };
    turn(&inward, &cos, &signed(senses.swing, sin))
}

/// The follower at the lift `s` with `ds` = ds/dθ: where it touches the cam, in D.
pub fn place<N: Number>(g: &Geometry<N>, senses: Senses, s: &N, ds: &N) -> Placed<N> {
    let sigma = senses.turning;
    let kappa = senses.swing;
    let one = N::constant(1.0);
    let zero = N::constant(0.0);
    match (senses.shape.outline(), &g.motion) {
        // A barrel's groove developed at R: the cam moves past the follower at −σR per
        // radian, so the pitch curve's tangent is (−σR, s′) and its upward normal
        // (σ s′, R)/|·|; the roller touches the lower flank.
        (_, Motion::Axial { radius }) => {
            let p = [zero.clone(), g.base_radius.clone() + s.clone()];
            let tangent = [signed(-sigma, radius.clone()), ds.clone()];
            let length = dot(&tangent, &tangent).sqrt();
            let normal = [
                signed(sigma, ds.clone()) / length.clone(),
                radius.clone() / length,
            ];
            let contact = sub(&p, &scale(&g.roller, &normal));
            Placed {
                pitch: p,
                contact,
                normal,
                motion: [zero, one],
            }
        }
        (Outline::Point | Outline::Circle, _) => {
            let (p, dp, motion) = match &g.motion {
                Motion::Translating { offset } => {
                    let rp = g.base_radius.clone() + g.roller.clone();
                    let y0 = (rp.clone() * rp - offset.clone() * offset.clone()).sqrt();
                    (
                        [offset.clone(), y0 + s.clone()],
                        [zero.clone(), ds.clone()],
                        [zero, one],
                    )
                }
                Motion::Oscillating { pivot, arm, .. } => {
                    let u = arm_direction(g, senses, s);
                    let ju = perp(&u);
                    let p = add(pivot, &scale(arm, &u));
                    let dp = scale(&signed(kappa, arm.clone() * ds.clone()), &ju);
                    (p, dp, scale(&signed(kappa, one), &ju))
                }
                // Handled above.
                Motion::Axial { .. } => (
                    [zero.clone(), zero.clone()],
                    [zero.clone(), zero.clone()],
                    [zero, one],
                ),
            };
            let tangent = sub(&dp, &scale(&N::constant(sigma), &perp(&p)));
            let length = dot(&tangent, &tangent).sqrt();
            let normal = scale(&(N::constant(sigma) / length), &perp(&tangent));
            let contact = sub(&p, &scale(&g.roller, &normal));
            Placed {
                pitch: p,
                contact,
                normal,
                motion,
            }
        }
        (Outline::Line, Motion::Translating { .. }) => {
            // n = (0, 1), d = R_b + s, ω = −σ: Q = (σ s′, R_b + s).
            let contact = [signed(sigma, ds.clone()), g.base_radius.clone() + s.clone()];
            Placed {
                pitch: contact.clone(),
                contact,
                normal: [zero.clone(), one.clone()],
                motion: [zero, one],
            }
        }
        (
            Outline::Line,
            Motion::Oscillating {
                pivot, face_offset, ..
            },
        ) => {
            let u = arm_direction(g, senses, s);
            let n = signed(kappa, one.clone());
            let normal = scale(&n, &perp(&u));
            let jn = perp(&normal);
            let d = dot(&normal, pivot) - face_offset.clone();
            let rate = signed(kappa, ds.clone());
            let dd = rate.clone() * dot(&jn, pivot);
            let omega = rate - N::constant(sigma);
            let contact = add(&scale(&d, &normal), &scale(&(dd / omega), &jn));
            let arm = sub(&contact, pivot);
            let reach = dot(&arm, &arm).sqrt();
            let motion = scale(&signed(kappa, one / reach), &perp(&arm));
            Placed {
                pitch: contact.clone(),
                contact,
                normal,
                motion,
            }
        }
    }
}

/// u(φ) = u(φ₀) turned by κ s.
fn arm_direction<N: Number>(g: &Geometry<N>, senses: Senses, s: &N) -> V<N> {
    let u0 = base_direction(g, senses);
    let angle = signed(senses.swing, s.clone());
    turn(&u0, &angle.cos(), &angle.sin())
}

/// A point of D in the cam frame at the cam angle θ: R(−σθ) X, given cos(σθ) and sin(σθ).
fn to_cam<N: Number>(x: &V<N>, cos: &N, sin: &N) -> V<N> {
    turn(x, cos, &-sin.clone())
}

/// The profile of a design as a parametric curve (x(u), y(u)) of the cam frame, traced
/// counterclockwise (the cam's material on its left, as parametric profiles are): the
/// parameter u = −σθ, so the law is read at θ = −σu. Exact: the law is the tabulated leaf
/// `law`, its slope the leaf's first derivative.
pub fn profile_expressions(
    g: &Geometry<Scalar>,
    senses: Senses,
    law: &Arc<Tabulated>,
) -> [Scalar; 2] {
    in_cam_frame(g, senses, law, |placed| placed.contact)
}

/// A point of the placed follower (`which`) as an expression of u = −σθ in the cam frame:
/// the law read at θ = −σu, the point turned by R(−σθ) = R(u).
fn in_cam_frame(
    g: &Geometry<Scalar>,
    senses: Senses,
    law: &Arc<Tabulated>,
    which: impl Fn(Placed<Scalar>) -> V<Scalar>,
) -> [Scalar; 2] {
    let theta = signed(-senses.turning, Scalar::Var(0));
    let s = theta.clone().tabulated(law, 0);
    let ds = theta.tabulated(law, 1);
    let point = which(place(g, senses, &s, &ds));
    let (cos, sin) = (Scalar::Var(0).cos(), Scalar::Var(0).sin());
    turn(&point, &cos, &sin)
}

/// The pitch curve of a design (the follower point's path: a knife's edge, a roller's
/// centre) as a parametric curve of the cam frame, parametrised as in
/// [`profile_expressions`]: a face cam's groove centre line.
pub fn pitch_expressions(
    g: &Geometry<Scalar>,
    senses: Senses,
    law: &Arc<Tabulated>,
) -> [Scalar; 2] {
    in_cam_frame(g, senses, law, |placed| placed.pitch)
}

/// A cam designed from a motion law, with its dimensions resolved to numbers: what the
/// checks and the designer's outputs evaluate.
#[derive(Debug, Clone, PartialEq)]
pub struct CamDesign {
    /// The follower's lift against the cam angle (m, or rad for an oscillating follower).
    pub program: MotionProgram,
    /// The same program as the tabulated function the profile's expressions read.
    pub law: Arc<Tabulated>,
    /// The dimensions.
    pub geometry: Geometry<f64>,
    /// Turning, swing and shape.
    pub senses: Senses,
    /// The largest pressure angle accepted without a warning (rad).
    pub max_pressure_angle: f64,
    /// The cam's nominal speed (rad/s), if the file gives it.
    pub speed: Option<f64>,
    /// The nominal speed as the file writes it: [`Scalar::Param`] `i` is the model's
    /// parameter i (what sets the speed, for running the cam at another one).
    pub speed_expression: Option<Scalar>,
    /// The roller runs in a groove (a face cam's, a barrel cam's): the flank beyond the
    /// pitch curve, the profile moved out (up) by 2ρ, bounds it too.
    pub groove: bool,
}

/// Everything the designer reads at one cam angle.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignPoint {
    /// The cam angle θ (rad).
    pub theta: f64,
    /// s, ds/dθ, d²s/dθ², d³s/dθ³ (per rad^k): times ω^k the follower's displacement,
    /// velocity, acceleration and jerk at the cam speed ω.
    pub lift: [f64; 4],
    /// The follower point (pitch curve) in the cam frame (m).
    pub pitch: [f64; 2],
    /// The contact point (the profile) in the cam frame (m).
    pub contact: [f64; 2],
    /// The pressure angle (rad): from the follower's direction of motion to the contact
    /// normal, counterclockwise positive.
    pub pressure_angle: f64,
    /// The profile's radius of curvature (m), positive where it is convex; zero or negative
    /// on a convex-turned cusp is undercutting.
    pub radius_of_curvature: f64,
    /// The pitch curve's radius of curvature (m), positive where convex (a knife or roller).
    pub pitch_radius: f64,
}

impl CamDesign {
    /// The design at the cam angle θ (rad), in closed form.
    pub fn at(&self, theta: f64) -> DesignPoint {
        let lift = self.program.eval(theta);
        let (g, senses) = (&self.geometry, self.senses);
        let placed = place(g, senses, &lift[0], &lift[1]);
        let (cos, sin) = (
            (senses.turning * theta).cos(),
            (senses.turning * theta).sin(),
        );
        let pressure =
            cross(&placed.motion, &placed.normal).atan2(dot(&placed.motion, &placed.normal));
        let (radius, pitch_radius) = self.radii(&lift);
        // The cam frame: turned back by the cam's angle, or for a barrel's development
        // shifted back by its arc, x = −σRθ.
        let to_frame = |x: &V<f64>| match &g.motion {
            Motion::Axial { radius } => [x[0] - senses.turning * radius * theta, x[1]],
            Motion::Translating { .. } | Motion::Oscillating { .. } => to_cam(x, &cos, &sin),
        };
        DesignPoint {
            theta,
            lift,
            pitch: to_frame(&placed.pitch),
            contact: to_frame(&placed.contact),
            pressure_angle: pressure,
            radius_of_curvature: radius,
            pitch_radius,
        }
    }

    /// (the profile's, the pitch curve's) radius of curvature for the lift and its
    /// derivatives `l`, by the closed forms of the module's documentation.
    fn radii(&self, l: &[f64; 4]) -> (f64, f64) {
        let (g, sigma, kappa) = (&self.geometry, self.senses.turning, self.senses.swing);
        match (self.senses.shape.outline(), &g.motion) {
            // The developed pitch curve (−σRθ, z₀ + s): its radius of curvature
            // −(R² + s′²)^{3/2}/(R s″), positive at a crest (convex seen from the follower
            // above it); the lower flank's is that less ρ.
            (_, Motion::Axial { radius }) => {
                let pitch = -(radius * radius + l[1] * l[1]).powf(1.5) / (radius * l[2]);
                (pitch - g.roller, pitch)
            }
            (Outline::Point | Outline::Circle, motion) => {
                let (p, dp, ddp) = match motion {
                    Motion::Translating { offset } => {
                        let rp = g.base_radius + g.roller;
                        let y0 = (rp * rp - offset * offset).sqrt();
                        ([*offset, y0 + l[0]], [0.0, l[1]], [0.0, l[2]])
                    }
                    Motion::Axial { .. } => ([0.0; 2], [0.0; 2], [0.0; 2]),
                    Motion::Oscillating { pivot, arm, .. } => {
                        let u = arm_direction(g, self.senses, &l[0]);
                        let ju = perp(&u);
                        let p = add(pivot, &scale(arm, &u));
                        let dp = scale(&(kappa * arm * l[1]), &ju);
                        let ddp = sub(
                            &scale(&(kappa * arm * l[2]), &ju),
                            &scale(&(arm * l[1] * l[1]), &u),
                        );
                        (p, dp, ddp)
                    }
                };
                let t = sub(&dp, &scale(&sigma, &perp(&p)));
                let dt = sub(&ddp, &scale(&sigma, &perp(&dp)));
                let speed2 = dot(&t, &t);
                let pitch = -sigma * speed2 * speed2.sqrt() / (cross(&t, &dt) - sigma * speed2);
                (pitch - g.roller, pitch)
            }
            (Outline::Line, Motion::Translating { .. }) => {
                let r = g.base_radius + l[0] + l[2];
                (r, f64::NAN)
            }
            (
                Outline::Line,
                Motion::Oscillating {
                    pivot, face_offset, ..
                },
            ) => {
                let u = arm_direction(g, self.senses, &l[0]);
                let n = scale(&kappa, &perp(&u));
                let jn = perp(&n);
                let (rate, acc) = (kappa * l[1], kappa * l[2]);
                let d = dot(&n, pivot) - face_offset;
                let dd = rate * dot(&jn, pivot);
                let ddd = acc * dot(&jn, pivot) - rate * rate * dot(&n, pivot);
                let omega = rate - sigma;
                let r = d + (ddd / omega - dd * acc / (omega * omega)) / omega;
                (r, f64::NAN)
            }
        }
    }

    /// The profile as a table of points for `table: (form: Parametric, file: …)` or a
    /// machine: a CSV text with a header `x,y` (m, cam frame), `points` points at evenly
    /// spaced cam angles and the first repeated at the end (a closed curve), each number in
    /// Rust's shortest form that reads back to the same `f64`; `#` lines say what it is.
    ///
    /// A barrel cam's table is its groove's pitch surface instead: `theta,z`, the cam-frame
    /// angle θ (rad, k·2π/points) and the height g(θ) of the roller centre's path there (m).
    pub fn profile_table(&self, points: usize, what: &str) -> String {
        let points = points.max(3);
        if let Motion::Axial { .. } = self.geometry.motion {
            let mut out = format!(
                "# {what}\n# the groove's pitch surface z = g(θ) (m) at the cam-frame angles θ = \
                 k·2π/{points} (rad) and 2π again (a closed groove)\ntheta,z\n"
            );
            let tau = std::f64::consts::TAU;
            for k in 0..=points {
                let theta = tau * k as f64 / points as f64;
                // The follower sits at the cam-frame angle −σφ at the cam angle φ.
                let phi = (-self.senses.turning * theta).rem_euclid(tau);
                let z = self.geometry.base_radius + self.program.eval(phi)[0];
                out.push_str(&format!("{theta:?},{z:?}\n"));
            }
            return out;
        }
        let mut out = format!(
            "# {what}\n# the cam profile in the cam frame (m), {points} points at cam angles \
             k·360°/{points} and the first again at 360° (a closed curve)\nx,y\n"
        );
        let rows: Vec<[f64; 2]> = (0..points)
            .map(|k| {
                self.at(std::f64::consts::TAU * k as f64 / points as f64)
                    .contact
            })
            .collect();
        for p in rows.iter().chain(rows.first()) {
            out.push_str(&format!("{:?},{:?}\n", p[0], p[1]));
        }
        out
    }

    /// `samples` + 1 evenly spaced design points over a turn, θ from 0 to 2π.
    pub fn turn(&self, samples: usize) -> Vec<DesignPoint> {
        (0..=samples)
            .map(|k| self.at(std::f64::consts::TAU * k as f64 / samples.max(1) as f64))
            .collect()
    }

    /// Where f is least over a turn: sampled at `samples` points and at every segment's
    /// ends, then refined by golden-section search between the neighbours of the least
    /// sample. Returns (θ, f(θ)).
    pub fn least(&self, samples: usize, f: impl Fn(&DesignPoint) -> f64) -> (f64, f64) {
        let tau = std::f64::consts::TAU;
        let mut angles: Vec<f64> = (0..samples)
            .map(|k| tau * k as f64 / samples.max(1) as f64)
            .collect();
        for &start in self.program.starts() {
            angles.extend([start, (start + 1e-9).min(tau), (start - 1e-9).max(0.0)]);
        }
        angles.sort_by(f64::total_cmp);
        let value = |theta: f64| f(&self.at(theta));
        let (mut best, mut at) = (f64::INFINITY, 0usize);
        for (k, &theta) in angles.iter().enumerate() {
            let v = value(theta);
            if v < best || (best.is_nan() && !v.is_nan()) {
                best = v;
                at = k;
            }
        }
        let (mut a, mut b) = (
            angles[at.saturating_sub(1)],
            angles[(at + 1).min(angles.len() - 1)],
        );
        let ratio = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..60 {
            let (c, d) = (b - ratio * (b - a), a + ratio * (b - a));
            if value(c) < value(d) {
                b = d;
            } else {
                a = c;
            }
        }
        let mid = 0.5 * (a + b);
        let refined = value(mid);
        if refined < best {
            (mid, refined)
        } else {
            (angles[at], best)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Profile;
    use crate::samples::curvature;
    use camchain_runtime::motion_law::{Law, Segment};

    /// A program with every kind of segment, lifts `h`.
    fn program(h: f64) -> MotionProgram {
        let seg = |law, degrees: f64, lift| Segment {
            law,
            angle: degrees.to_radians(),
            lift,
        };
        MotionProgram::new(&[
            seg(Law::Dwell, 40.0, 0.0),
            seg(Law::Cycloidal, 80.0, h),
            seg(Law::Dwell, 30.0, h),
            seg(Law::Polynomial345, 70.0, 0.4 * h),
            seg(Law::ModifiedSine, 60.0, 0.0),
            seg(Law::Dwell, 80.0, 0.0),
        ])
        .expect("a turn")
    }

    /// Every follower kind the designs support, with its lift.
    fn designs() -> Vec<(&'static str, Geometry<f64>, Senses, f64)> {
        let point = |turning, swing| Senses {
            turning,
            swing,
            shape: FollowerKind::Roller,
        };
        let flat = |turning, swing| Senses {
            turning,
            swing,
            shape: FollowerKind::Flat,
        };
        let translating = |roller, offset| Geometry {
            base_radius: 0.04,
            roller,
            motion: Motion::Translating { offset },
        };
        let oscillating = |roller, pivot: [f64; 2], arm| Geometry {
            base_radius: 0.04,
            roller,
            motion: Motion::Oscillating {
                pivot,
                arm,
                face_offset: 0.004,
            },
        };
        vec![
            (
                "translating knife",
                translating(0.0, 0.008),
                point(1.0, 1.0),
                0.01,
            ),
            (
                "translating roller",
                translating(0.01, -0.005),
                point(-1.0, 1.0),
                0.01,
            ),
            (
                "translating flat",
                translating(0.0, 0.0),
                flat(1.0, 1.0),
                0.01,
            ),
            (
                "oscillating knife",
                oscillating(0.0, [0.07, 0.05], 0.06),
                point(1.0, -1.0),
                0.1,
            ),
            (
                "oscillating roller",
                oscillating(0.008, [-0.06, 0.06], 0.07),
                point(-1.0, 1.0),
                0.1,
            ),
            (
                "oscillating flat",
                oscillating(0.0, [0.07, 0.05], 0.0),
                flat(1.0, 1.0),
                0.03,
            ),
        ]
    }

    fn design(g: Geometry<f64>, senses: Senses, h: f64) -> CamDesign {
        let program = program(h);
        CamDesign {
            law: Tabulated::law("law", program.clone()),
            program,
            geometry: g,
            senses,
            max_pressure_angle: 0.5,
            speed: None,
            speed_expression: None,
            groove: false,
        }
    }

    /// Newton's cold start for a designed cam (`camchain_runtime::contact::pitch_parameter`,
    /// what the code generator emits for it) inverts the pitch curve: at every design point
    /// of every knife and roller design it gives the profile's parameter u = −σθ (wrapped to
    /// [0, 2π)) to rounding, so that a contact's first solve at a new state needs no scan.
    #[test]
    fn the_pitch_curve_inverted_is_the_profiles_parameter() {
        use camchain_runtime::contact::{Pitch, pitch_parameter};
        let tau = std::f64::consts::TAU;
        let mut checked = 0;
        for (what, g, senses, h) in designs() {
            let pitch = match (senses.shape.outline(), &g.motion) {
                (Outline::Line, _) | (_, Motion::Axial { .. }) => continue,
                (_, Motion::Translating { offset }) => Pitch::Translating { offset: *offset },
                (_, Motion::Oscillating { pivot, arm, .. }) => Pitch::Oscillating {
                    pivot: *pivot,
                    arm: *arm,
                    swing: senses.swing,
                },
            };
            let d = design(g.clone(), senses, h);
            for k in 0..360 {
                let theta = tau * (k as f64 + 0.3) / 360.0;
                let at = d.at(theta);
                let u = pitch_parameter(at.pitch[0], at.pitch[1], pitch, (0.0, tau));
                let expected = (-senses.turning * theta).rem_euclid(tau);
                let off = (u - expected).abs().min(tau - (u - expected).abs());
                assert!(
                    off < 1e-12 && (0.0..tau).contains(&u),
                    "{what}: θ = {theta}: u = {u}, expected {expected}"
                );
                checked += 1;
            }
        }
        assert_eq!(checked, 4 * 360);
    }

    /// The closed-form radius of curvature (the module's formulas) against the curvature of
    /// the profile's expressions, differentiated in forward mode (`crate::jet`, through
    /// `crate::samples::curvature`: an independent route, nothing of the radii's derivation
    /// is used),
    /// at 90 cam angles for every follower kind. Both are exact; they differ by the rounding
    /// of second derivatives of the envelope (relative 1e-9 leaves a wide margin over the
    /// measured 1e-12 while any wrong term would be off at O(1)).
    #[test]
    fn the_radius_of_curvature_is_the_profiles() {
        for (what, g, senses, h) in designs() {
            let d = design(g.clone(), senses, h);
            let as_expressions = Geometry {
                base_radius: Scalar::Const(g.base_radius),
                roller: Scalar::Const(g.roller),
                motion: match &g.motion {
                    Motion::Translating { offset } => Motion::Translating {
                        offset: Scalar::Const(*offset),
                    },
                    Motion::Oscillating {
                        pivot,
                        arm,
                        face_offset,
                    } => Motion::Oscillating {
                        pivot: pivot.map(Scalar::Const),
                        arm: Scalar::Const(*arm),
                        face_offset: Scalar::Const(*face_offset),
                    },
                    Motion::Axial { radius } => Motion::Axial {
                        radius: Scalar::Const(*radius),
                    },
                },
            };
            let [x, y] = profile_expressions(&as_expressions, senses, &d.law);
            let profile = Profile::Parametric {
                x_source: String::new(),
                y_source: String::new(),
                x: x.clone(),
                y: y.clone(),
            };
            let mut worst = 0.0f64;
            for k in 0..90 {
                let theta = std::f64::consts::TAU * (k as f64 + 0.3) / 90.0;
                let at = d.at(theta);
                // The profile's parameter is u = −σθ; its point is the design's contact.
                let u0 = -senses.turning * theta;
                let point = [x.eval(u0), y.eval(u0)];
                let gap = (point[0] - at.contact[0]).hypot(point[1] - at.contact[1]);
                assert!(
                    gap < 1e-15,
                    "{what}: θ = {theta}: profile point off by {gap:e}"
                );
                // Curvature positive where hollow seen from the follower: a convex radius
                // R is a curvature −1/R.
                let kappa = curvature(&profile, u0);
                let radius = -1.0 / kappa;
                let error = (radius - at.radius_of_curvature).abs() / at.radius_of_curvature.abs();
                worst = worst.max(error);
                assert!(
                    error < 1e-9,
                    "{what}: θ = {:.2}°: closed form {} vs the profile's {radius}",
                    theta.to_degrees(),
                    at.radius_of_curvature
                );
            }
            eprintln!(
                "{what}: radius of curvature, closed form against the profile's: {worst:.1e}"
            );
        }
    }
}
