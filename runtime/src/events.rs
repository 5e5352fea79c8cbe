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
}

/// The root of `g` in the bracket [t0, t1] where g(t0) = g0 and g(t1) = g1 have opposite
/// signs (or g1 = 0), by the Illinois variant of regula falsi (superlinear, never leaves the
/// bracket) safeguarded by bisection, to a bracket narrower than `tolerance`. Returns the end of the final bracket
/// on the far side of the sign change (so that the event has happened at the returned
/// time).
pub fn locate_root(
    mut g: impl FnMut(f64) -> Result<f64, SimError>,
    (mut a, mut ga): (f64, f64),
    (mut b, mut gb): (f64, f64),
    tolerance: f64,
) -> Result<f64, SimError> {
    let mut side = 0;
    let mut width = (b - a).abs();
    let mut bisect = false;
    for _ in 0..200 {
        if (b - a).abs() <= tolerance || gb == 0.0 {
            return Ok(b);
        }
        let mut t = if bisect {
            0.5 * (a + b)
        } else {
            (a * gb - b * ga) / (gb - ga)
        };
        // Keep the trial strictly inside: fall back to bisection when round-off puts it on
        // an end.
        if !(t > a.min(b) && t < a.max(b)) {
            t = 0.5 * (a + b);
        }
        let gt = g(t)?;
        if gt == 0.0 {
            return Ok(t);
        }
        if (gt > 0.0) == (gb > 0.0) {
            // The far end moves: t replaces b.
            (b, gb) = (t, gt);
            if side == -1 {
                ga *= 0.5;
            }
            side = -1;
        } else {
            (a, ga) = (t, gt);
            if side == 1 {
                gb *= 0.5;
            }
            side = 1;
        }
        // A step that did not halve the bracket (a flat or high-order root, where regula
        // falsi crawls) is followed by a bisection: at worst twice bisection's step count.
        let new_width = (b - a).abs();
        bisect = !bisect && new_width > 0.5 * width;
        width = new_width;
    }
    Ok(b)
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
