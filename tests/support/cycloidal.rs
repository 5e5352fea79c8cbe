//! The jump speed of `cycloidal_roller` in closed form, derived from its model file: an
//! in-line translating roller whose centre rides at s(θ) = R_b + ρ + S(θ) above the
//! camshaft, S the file's program (dwell 60°, cycloidal rise of h over 120°, dwell 60°,
//! cycloidal return over 120°; the cycloidal law over a segment of angle β is
//! S = h (x − sin(2πx)/(2π)), x = (θ − θ₀)/β). At constant ω the follower's equation of
//! motion along its guide, m s̈ = N cos φ − m g − k (s − s_free) − c ṡ (φ the pressure angle,
//! |φ| < 90°), gives the sign of the normal force as that of
//!
//!     F(θ, ω) = m ω² S″(θ) + c ω S′(θ) + m g + k (R_b + ρ + S(θ) − s_free),
//!
//! and the jump speed is the least ω > 0 at which min_θ F reaches zero. Shared by the
//! models' one-sided runs (tests/suite/unilateral.rs) and the `camchain cam`
//! command's prediction (cli/tests/suite/cam.rs), included in both with `#[path]`.

use std::f64::consts::PI;

/// The follower and its law, from the file's parameters.
#[derive(Debug, Clone, Copy)]
pub struct Cycloidal {
    pub m: f64,
    pub g: f64,
    pub k: f64,
    pub c: f64,
    pub free: f64,
    /// R_b + ρ: the roller centre's height over the base circle.
    pub base: f64,
    /// The lift h.
    pub lift: f64,
}

impl Cycloidal {
    /// The program's S, S′, S″ at cam angle θ (rad, any turn).
    pub fn law(&self, theta: f64) -> (f64, f64, f64) {
        let degrees = theta.to_degrees().rem_euclid(360.0);
        let beta = 2.0 * PI / 3.0;
        let h = self.lift;
        let cycloid = |x: f64| {
            (
                h * (x - (2.0 * PI * x).sin() / (2.0 * PI)),
                h / beta * (1.0 - (2.0 * PI * x).cos()),
                2.0 * PI * h / (beta * beta) * (2.0 * PI * x).sin(),
            )
        };
        if degrees < 60.0 {
            (0.0, 0.0, 0.0)
        } else if degrees < 180.0 {
            cycloid((degrees - 60.0).to_radians() / beta)
        } else if degrees < 240.0 {
            (h, 0.0, 0.0)
        } else {
            let (s, v, a) = cycloid((degrees - 240.0).to_radians() / beta);
            (h - s, -v, -a)
        }
    }

    /// F(θ, ω): positive where the cam pushes.
    pub fn force(&self, theta: f64, omega: f64) -> f64 {
        let (s, v, a) = self.law(theta);
        self.m * omega * omega * a
            + self.c * omega * v
            + self.m * self.g
            + self.k * (self.base + s - self.free)
    }

    /// The positive ω where F(θ, ω) = 0 (infinite where S″ ≥ 0: never there).
    fn root(&self, theta: f64) -> f64 {
        let (s, v, a) = self.law(theta);
        let (qa, qb) = (self.m * a, self.c * v);
        let qc = self.m * self.g + self.k * (self.base + s - self.free);
        if qa >= 0.0 {
            return f64::INFINITY;
        }
        // qa < 0 < qc: one positive root, (−qb − √(qb² − 4 qa qc)) / (2 qa), in the stable
        // form 2 qc / (−qb + √(…)).
        2.0 * qc / (-qb + (qb * qb - 4.0 * qa * qc).sqrt())
    }

    /// The jump speed and the cam angle where the force first reaches zero: the least
    /// root over 0.001° steps, refined by golden-section search to round-off.
    pub fn jump_speed(&self) -> (f64, f64) {
        let (mut best, mut at) = (f64::INFINITY, 0.0);
        for i in 0..360_000 {
            let theta = (i as f64 / 1000.0).to_radians();
            let r = self.root(theta);
            if r < best {
                (best, at) = (r, theta);
            }
        }
        let theta = golden(|t| self.root(t), at - 2e-5, at + 2e-5);
        (self.root(theta), theta)
    }

    /// Where F is least over a turn at ω, and where it first reaches zero going down before
    /// it (when it does).
    pub fn least_and_lift_off(&self, omega: f64) -> (f64, Option<f64>) {
        let (mut low, mut at) = (f64::INFINITY, 0.0);
        for i in 0..36_000 {
            let theta = (i as f64 / 100.0).to_radians();
            let f = self.force(theta, omega);
            if f < low {
                (low, at) = (f, theta);
            }
        }
        let least = golden(|t| self.force(t, omega), at - 2e-4, at + 2e-4);
        if self.force(least, omega) > 0.0 {
            return (least, None);
        }
        // Back from the least force to where it was still positive, then bisection.
        let mut before = least;
        while self.force(before, omega) <= 0.0 {
            before -= 1e-3;
        }
        let (mut a, mut b) = (before, least);
        for _ in 0..100 {
            let mid = 0.5 * (a + b);
            if self.force(mid, omega) > 0.0 {
                a = mid;
            } else {
                b = mid;
            }
        }
        (least, Some(b))
    }
}

/// The minimum of a unimodal f on [a, b] by golden-section search, to round-off.
fn golden(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..200 {
        let (x, y) = (b - ratio * (b - a), a + ratio * (b - a));
        if f(x) < f(y) {
            b = y;
        } else {
            a = x;
        }
    }
    0.5 * (a + b)
}
