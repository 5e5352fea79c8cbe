//! Contact events: where a normal force changes sign, where a flying follower lifts off and
//! lands, located inside an integration step by root finding on the integrator's dense
//! output (to [`EVENT_TIME_TOLERANCE`]).

use crate::error::SimError;

/// Events are located to this width of the bracketing interval (s).
pub const EVENT_TIME_TOLERANCE: f64 = 1e-9;

/// What happened at a contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EventKind {
    /// Bilateral contact: the normal force became negative (the cam must pull the follower;
    /// a one-sided follower would lift off here).
    ForceBecameNegative,
    /// Bilateral contact: the normal force became positive again.
    ForceBecamePositive,
    /// Unilateral contact: the normal force reached zero; the follower leaves the cam.
    LiftOff,
    /// Unilateral contact: the flying follower reached the cam. `normal_velocity` is the
    /// approach speed ∂h/∂q q̇ before the impact (m/s, negative), `rebound` the same after
    /// it (−e × approach; 0 when the follower stays on the cam).
    Impact {
        /// J q̇ before the impact (m/s).
        normal_velocity: f64,
        /// J q̇ after the impact (m/s).
        rebound: f64,
        /// True when the follower stays on the cam (plastic impact, or a rebound too slow
        /// to fly: see [`crate::unilateral::RESTING_SPEED`]).
        stays: bool,
        /// Mechanical energy the impact dissipates (J): the kinetic energy lost plus the
        /// work of the drives' impulsive reactions.
        loss: f64,
    },
}

/// One contact event.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactEvent {
    /// Time (s), located to [`EVENT_TIME_TOLERANCE`].
    pub t: f64,
    /// Index of the contact.
    pub contact: usize,
    /// What happened.
    pub kind: EventKind,
    /// Coordinates at the event.
    pub q: Vec<f64>,
    /// Velocities at the event (before an impact).
    pub qd: Vec<f64>,
    /// For a groove with backlash, the flank the roller leaves or lands on
    /// ([`crate::clearance`]); `None` otherwise.
    pub flank: Option<crate::dynamics::Flank>,
}

/// The root of `g` in the bracket [t0, t1] where g(t0) = g0 and g(t1) = g1 have opposite
/// signs (or g1 = 0), by Brent's method (inverse quadratic interpolation and secant steps,
/// safeguarded by bisection: superlinear on a smooth g, never worse than bisection, never
/// leaving the bracket), to a bracket narrower than `tolerance`. Returns the end of the
/// final bracket on the far side of the sign change (so that the event has happened at the
/// returned time).
pub fn locate_root(
    g: impl FnMut(f64) -> Result<f64, SimError>,
    a: (f64, f64),
    b: (f64, f64),
    tolerance: f64,
) -> Result<f64, SimError> {
    locate_root_within(g, a, b, tolerance, f64::INFINITY)
}

/// [`locate_root`] that also goes on until |g| at the returned end is at most
/// `value_tolerance` (a landing located to a gap, not only to a time), or until the bracket
/// is down to a few units in the last place of t.
pub fn locate_root_within(
    mut g: impl FnMut(f64) -> Result<f64, SimError>,
    (t0, g0): (f64, f64),
    (t1, g1): (f64, f64),
    tolerance: f64,
    value_tolerance: f64,
) -> Result<f64, SimError> {
    if g1 == 0.0 {
        return Ok(t1);
    }
    let far = g1 > 0.0;
    // Brent's zeroin: b is the best estimate, c the other end of the bracket, a the
    // previous b.
    let (mut a, mut fa, mut b, mut fb) = (t0, g0, t1, g1);
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for _ in 0..200 {
        if (fb > 0.0) == (fc > 0.0) && fb != 0.0 && fc != 0.0 {
            (c, fc) = (a, fa);
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            (a, fa) = (b, fb);
            (b, fb) = (c, fc);
            (c, fc) = (a, fa);
        }
        let resolution = 4.0 * f64::EPSILON * b.abs().max(c.abs());
        // A value tolerance sets the width needed through the bracket's secant slope.
        let slope = ((fc - fb) / (c - b)).abs();
        let width = if value_tolerance.is_finite() && slope > 0.0 {
            tolerance.min(value_tolerance / slope)
        } else {
            tolerance
        };
        let tol1 = resolution + 0.5 * width;
        let half = 0.5 * (c - b);
        // The end of the bracket on the far side of the sign change, and its value.
        let (end, value) = if fb == 0.0 || (fb > 0.0) == far {
            (b, fb)
        } else {
            (c, fc)
        };
        let narrow = half.abs() <= tol1 && value.abs() <= value_tolerance;
        if narrow || fb == 0.0 || half.abs() <= resolution {
            return Ok(end);
        }
        if e.abs() >= tol1 && fa.abs() > fb.abs() {
            // Inverse quadratic interpolation, or the secant when a = c.
            let s = fb / fa;
            let (mut p, mut q) = if a == c {
                (2.0 * half * s, 1.0 - s)
            } else {
                let q = fa / fc;
                let r = fb / fc;
                (
                    s * (2.0 * half * q * (q - r) - (b - a) * (r - 1.0)),
                    (q - 1.0) * (r - 1.0) * (s - 1.0),
                )
            };
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * half * q - (tol1 * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = half;
                e = d;
            }
        } else {
            d = half;
            e = d;
        }
        (a, fa) = (b, fb);
        b += if d.abs() > tol1 {
            d
        } else {
            tol1.copysign(half)
        };
        fb = g(b)?;
    }
    Ok(if (fb > 0.0) == far { b } else { c })
}

/// True when `from` → `to` is a sign change (crossing or reaching zero from a non-zero
/// value).
pub fn changes_sign(from: f64, to: f64) -> bool {
    (from > 0.0 && to <= 0.0) || (from < 0.0 && to >= 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locates_roots_to_the_tolerance() {
        // cos t = 0 at π/2; a root at the end of the bracket; a very flat function.
        type Case = (fn(f64) -> f64, f64, f64, f64);
        let cases: [Case; 3] = [
            (f64::cos, 0.0, 3.0, std::f64::consts::FRAC_PI_2),
            (|t| t - 1.0, 0.0, 1.0, 1.0),
            (|t| (t - 0.3).powi(5), 0.0, 1.0, 0.3),
        ];
        for (f, a, b, root) in cases {
            let t = locate_root(|t| Ok(f(t)), (a, f(a)), (b, f(b)), 1e-9).unwrap();
            // The bracket is narrower than 1e-9 and contains the root.
            assert!((t - root).abs() <= 1e-9, "{t} vs {root}");
        }
    }

    #[test]
    fn sign_changes() {
        assert!(changes_sign(1.0, -1.0) && changes_sign(-1.0, 0.0) && changes_sign(2.0, 0.0));
        assert!(!changes_sign(0.0, 1.0) && !changes_sign(1.0, 2.0));
    }
}
