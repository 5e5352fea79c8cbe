//! In-step event scans: a watched function that crosses zero and comes back within one
//! integration step is found, not only a sign change between the step's two ends
//! (docs/method.md §14).
//!
//! Two kinds of watched function, with different costs:
//!
//! - **A normal force in contact** (watched through p = −λ, which has its sign): one value at
//!   an interior time costs about a right-hand side (dense output, Newton (15), the reduced
//!   accelerations and the multipliers), so a cheap prediction decides where to look. The
//!   step already knows p at its ends exactly and, through its stages, the integral of p
//!   over the step to the method's own order (the quadrature Σ bᵢ p(tᵢ, Yᵢ) of an extra
//!   component ż = p). The quadratic with those three data predicts the interior extremum
//!   ([`excursion_guess`]); where it, or a stage value, comes within the step's own
//!   variation of zero, Brent's minimisation of the exact p on the dense output decides
//!   ([`find_excursion`]).
//! - **A flying follower's gap h**: cheap (positions only), so every step is checked
//!   ([`first_closing`]): the step is cut into pieces short enough that the cam turns little
//!   relative to the follower in each, and every piece is checked by the cubic Hermite
//!   interpolant of h and ḣ = J q̇ at its ends against the exact value at its midpoint,
//!   halved where the cubic comes near zero or the two disagree.
//!
//! Both return brackets of sign changes; [`crate::events::locate_root`] then locates them.

use crate::error::SimError;

/// A step whose predicted values dip inside it (below both ends) is searched when that
/// dip is closer to zero than this multiple of the force's variation over the step
/// (predicted and stage values). The prediction's error is a small fraction of that
/// variation: the quadratic through the step's exact end values and its exact mean misses
/// the cubic and higher terms of p over the step (a few per cent of the variation at most
/// for steps the error control accepts), and a stage value's error is of second order in the
/// step. A factor 1 leaves a wide margin and still searches only the steps where the force
/// comes near zero.
const RISK: f64 = 1.0;

/// A step predicted monotone is searched only when an end is this close to zero, as a
/// fraction of the variation: a smooth force cannot leave a monotone course by more than
/// the prediction's error, which is smaller than that.
const END_RISK: f64 = 0.02;

/// Brent's minimisation stops when the bracket of the minimum is narrower than this
/// fraction of the step: the smallest value found is then within ½ p″ (1e-3 h)² of the
/// true minimum, about 1e-6 of the force's variation over the step.
const MINIMUM_WIDTH: f64 = 1e-3;

/// Most evaluations of Brent's minimisation of one step (it needs about 10 on a smooth
/// dip; golden-section steps alone shrink the bracket below [`MINIMUM_WIDTH`] in 24).
const MAX_MINIMISATION: usize = 60;

/// What an accepted step knows of one watched force p (the sign of the normal force).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ForceStep<'a> {
    /// Start of the step and the exact value there.
    pub(crate) start: (f64, f64),
    /// End of the step and the exact value there.
    pub(crate) end: (f64, f64),
    /// Mean of p over the step: the step's quadrature Σ bᵢ pᵢ of its stage values (of the
    /// method's order).
    pub(crate) mean: f64,
    /// (time, value) at the interior stages: approximations of p along the solution.
    pub(crate) stages: &'a [(f64, f64)],
}

/// Where p may come back across zero inside the step (both ends on the same side, non-zero),
/// if it plausibly does: the predicted time of its extremum towards zero.
pub(crate) fn excursion_guess(step: &ForceStep) -> Option<f64> {
    let ((t0, p0), (t1, p1)) = (step.start, step.end);
    if p0 == 0.0 || (p0 > 0.0) != (p1 > 0.0) || p1 == 0.0 || t1 <= t0 {
        return None;
    }
    // f = σ p is positive at both ends; a dip of f towards zero is what is looked for.
    let sigma = p0.signum();
    let (f0, f1, mean) = (sigma * p0, sigma * p1, sigma * step.mean);
    // f(s) = f0 (1 − s) + f1 s + c s (1 − s) has the end values and, with
    // c = 6 (mean − (f0 + f1)/2), the mean (∫₀¹ s (1 − s) ds = 1/6).
    let c = 6.0 * (mean - 0.5 * (f0 + f1));
    let end_low = f0.min(f1);
    let (mut low, mut at) = (f64::INFINITY, 0.5 * (t0 + t1));
    let mut high = f0.max(f1);
    if c < 0.0 {
        let s = 0.5 + (f1 - f0) / (2.0 * c);
        if s > 0.0 && s < 1.0 {
            let value = f0 * (1.0 - s) + f1 * s + c * s * (1.0 - s);
            (low, at) = (value, t0 + s * (t1 - t0));
        }
    }
    for &(t, p) in step.stages {
        let f = sigma * p;
        if !f.is_finite() {
            // A stage that failed to give a number says nothing: look.
            return Some(0.5 * (t0 + t1));
        }
        if f < low && t > t0 && t < t1 {
            (low, at) = (f, t);
        }
        high = high.max(f);
    }
    if !high.is_finite() {
        return Some(0.5 * (t0 + t1));
    }
    let variation = high - low.min(end_low);
    let dips = low < end_low && low < RISK * variation;
    let end_close = end_low < END_RISK * variation;
    if dips {
        Some(at.clamp(t0, t1))
    } else if end_close {
        Some(if f0 <= f1 { t0 } else { t1 })
    } else {
        None
    }
}

/// A sign change of the exact p inside a step: the bracket where it leaves its side of zero
/// and, if it comes back within the step, the bracket where it does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Excursion {
    /// ((t, p) still on the start's side, (t, p) on the other side or at zero).
    pub(crate) leaves: ((f64, f64), (f64, f64)),
    /// ((t, p) on the other side or at zero, (t, p) back on the start's side).
    pub(crate) returns: Option<((f64, f64), (f64, f64))>,
}

/// Searches the exact p (from the dense output) for an excursion across zero inside
/// (t0, t1), both ends on the same side: Brent's minimisation of σ·p from `guess`, stopped
/// as soon as a value at or across zero is found. `None` when the minimum stays on the
/// start's side.
///
/// # Errors
/// The first error of `p`.
pub(crate) fn find_excursion(
    mut p: impl FnMut(f64) -> Result<f64, SimError>,
    (t0, p0): (f64, f64),
    (t1, p1): (f64, f64),
    guess: f64,
) -> Result<Option<Excursion>, SimError> {
    let sigma = if p0 >= 0.0 { 1.0 } else { -1.0 };
    let mut seen: Vec<(f64, f64)> = vec![(t0, p0), (t1, p1)];
    let mut f = |t: f64| -> Result<f64, SimError> {
        let value = p(t)?;
        seen.push((t, value));
        Ok(sigma * value)
    };
    let tolerance = MINIMUM_WIDTH * (t1 - t0);
    let found = minimise_until_nonpositive(&mut f, (t0, t1), guess, tolerance)?;
    let Some(crossed) = found else {
        return Ok(None);
    };
    let on_side = |&(_, v): &(f64, f64)| sigma * v > 0.0;
    let before = seen
        .iter()
        .filter(|e| e.0 < crossed && on_side(e))
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .copied()
        .unwrap_or((t0, p0));
    let after = seen
        .iter()
        .filter(|e| e.0 > crossed && on_side(e))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .copied();
    let at = seen
        .iter()
        .find(|e| e.0 == crossed)
        .copied()
        .unwrap_or((crossed, 0.0));
    Ok(Some(Excursion {
        leaves: (before, at),
        returns: after.map(|after| (at, after)),
    }))
}

/// Brent's minimisation (golden section with parabolic steps) of `f` on [a, b] from `x`,
/// stopped at the first point where f ≤ 0 (returned) or when the minimum is bracketed to
/// `tolerance` (then `None`).
fn minimise_until_nonpositive(
    f: &mut impl FnMut(f64) -> Result<f64, SimError>,
    (mut a, mut b): (f64, f64),
    x: f64,
    tolerance: f64,
) -> Result<Option<f64>, SimError> {
    const GOLDEN: f64 = 0.381_966_011_250_105_1;
    let mut x = x.clamp(a, b);
    if x <= a || x >= b {
        x = a + GOLDEN * (b - a);
    }
    let mut fx = f(x)?;
    let (mut w, mut v, mut fw, mut fv) = (x, x, fx, fx);
    let (mut d, mut e) = (0.0_f64, 0.0_f64);
    for _ in 0..MAX_MINIMISATION {
        if fx <= 0.0 {
            return Ok(Some(x));
        }
        if !fx.is_finite() {
            return Ok(None);
        }
        let middle = 0.5 * (a + b);
        let tol1 = 0.5 * tolerance + 4.0 * f64::EPSILON * x.abs();
        let tol2 = 2.0 * tol1;
        if (x - middle).abs() <= tol2 - 0.5 * (b - a) {
            return Ok(None);
        }
        let mut golden = true;
        if e.abs() > tol1 {
            // A parabola through x, w, v.
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            let previous = e;
            e = d;
            if p.abs() < (0.5 * q * previous).abs() && p > q * (a - x) && p < q * (b - x) {
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = tol1.copysign(middle - x);
                }
                golden = false;
            }
        }
        if golden {
            e = if x >= middle { a - x } else { b - x };
            d = GOLDEN * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else {
            x + tol1.copysign(d)
        };
        let fu = f(u)?;
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    Ok((fx <= 0.0).then_some(x))
}

/// A flying follower's gap at one time: h (m, positive above the cam) and ḣ = J q̇ (m/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GapPoint {
    /// Time (s).
    pub(crate) t: f64,
    /// The gap h.
    pub(crate) g: f64,
    /// Its rate ḣ.
    pub(crate) rate: f64,
    /// A bound on |ḣ| near this time (m/s): the follower point's speed relative to the cam
    /// frame, which |ḣ| cannot exceed and which, unlike ḣ, does not swing with the cam's
    /// lobes.
    pub(crate) speed: f64,
}

/// The first closing of a flying follower's gap inside a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Closing {
    /// The gap stays above −ε throughout the step.
    Clear,
    /// (a point where the gap is above −ε, a later one where it is below −ε), with no
    /// closing before the first.
    Bracket(GapPoint, GapPoint),
    /// A flight that starts on the cam closed again before its gap ever exceeded ε (a hop
    /// within the landing tolerance): the follower lands where it took off.
    NeverOpened,
}

/// Pieces below this fraction of the step are not split further: what is left unresolved
/// there is a graze whose depth is below the Hermite interpolant's error on such a piece
/// (of order (1e-6 h)⁴ ḣ⁗), far below any tolerance.
const SMALLEST_PIECE: f64 = 1e-6;

/// Points at which the bound of a piece's interpolant is checked for a sign change of its
/// derivative.
const BOUND_POINTS: usize = 64;

/// A piece whose smaller end gap exceeds this multiple of its duration times the larger
/// speed bound of its ends cannot close within it: the gap falls no faster than the
/// follower point moves relative to the cam, and that speed changes little within a piece.
const CLEARANCE: f64 = 2.0;

/// The first closing of the gap in [start.t, end.t] below −`tolerance` (gaps within
/// ±tolerance are contact, up to the landing's location): the step cut into `pieces` equal
/// pieces, each checked by [`Search::piece`]. With `take_off`, the flight starts on the cam
/// at `start`.
///
/// # Errors
/// The first error of `gap`.
pub(crate) fn first_closing(
    mut gap: impl FnMut(f64) -> Result<GapPoint, SimError>,
    start: GapPoint,
    end: GapPoint,
    (pieces, tolerance): (usize, f64),
    take_off: bool,
) -> Result<Closing, SimError> {
    let width = end.t - start.t;
    if width <= 0.0 || (!take_off && start.g < -tolerance) {
        // Nothing to close: an empty step, or already closed at its start.
        return Ok(Closing::Clear);
    }
    let mut from = start;
    if take_off {
        from.g = from.g.max(0.0);
    }
    // Every gap seen, to tell a real flight from a hop within the tolerance.
    let mut seen: Vec<(f64, f64)> = vec![(from.t, from.g), (end.t, end.g)];
    let mut watched = |t: f64| {
        let point = gap(t)?;
        seen.push((point.t, point.g));
        Ok(point)
    };
    let search = Search {
        smallest: SMALLEST_PIECE * width,
        tolerance,
        take_off: take_off.then_some(start.t),
    };
    let pieces = pieces.max(1);
    let mut a = from;
    let mut found = None;
    for i in 1..=pieces {
        let b = if i == pieces {
            end
        } else {
            watched(from.t + width * i as f64 / pieces as f64)?
        };
        if let Some(bracket) = search.piece(&mut watched, a, b)? {
            found = Some(bracket);
            break;
        }
        a = b;
    }
    let Some((open, closed)) = found else {
        return Ok(Closing::Clear);
    };
    let highest = seen
        .iter()
        .filter(|(t, _)| *t < closed.t)
        .fold(f64::NEG_INFINITY, |m, (_, g)| m.max(*g));
    if take_off && highest <= tolerance {
        return Ok(Closing::NeverOpened);
    }
    Ok(Closing::Bracket(open, closed))
}

/// How a step's pieces are checked.
struct Search {
    /// Pieces narrower than this are not split.
    smallest: f64,
    /// Gaps within ±tolerance are contact.
    tolerance: f64,
    /// The take-off time, where the gap is zero and counts as open.
    take_off: Option<f64>,
}

impl Search {
    fn closed(&self, point: &GapPoint) -> bool {
        point.g < -self.tolerance
    }

    /// The first closing in the piece [a, b], a not closed: `None` when the gap stays above
    /// −ε. A piece whose ends are further from the cam than the follower point can travel
    /// relative to it within the piece is clear at once. Otherwise one open at both ends and
    /// at its midpoint is accepted when its cubic Hermite interpolant H stays above −ε by
    /// the interpolant's error, bounded by the error's shape s² (1 − s)² scaled to twice H's
    /// disagreement with the exact gap at the midpoint (where that shape is largest); if not,
    /// both halves are searched, the earlier first. A piece closed at its midpoint or end is
    /// bracketed at once, after its earlier half is checked for a closing that comes first.
    fn piece(
        &self,
        gap: &mut impl FnMut(f64) -> Result<GapPoint, SimError>,
        a: GapPoint,
        b: GapPoint,
    ) -> Result<Option<(GapPoint, GapPoint)>, SimError> {
        let width = b.t - a.t;
        if width <= self.smallest {
            return Ok(self.closed(&b).then_some((a, b)));
        }
        let travel = CLEARANCE * width * a.speed.max(b.speed).max(a.rate.abs()).max(b.rate.abs());
        if a.g.min(b.g) > travel + self.tolerance {
            return Ok(None);
        }
        let m = gap(a.t + 0.5 * width)?;
        if self.closed(&m) {
            // Closed at the midpoint: the first closing is in [a, m].
            return Ok(self.piece(gap, a, m)?.or(Some((a, m))));
        }
        if self.closed(&b) {
            // Open at the midpoint, closed at the end: the first closing is in [m, b] unless
            // the gap dips through zero and back in [a, m] first.
            return Ok(self.piece(gap, a, m)?.or(Some((m, b))));
        }
        let disagreement = (m.g - hermite(a, b, 0.5)).abs();
        let starts_on_cam = self.take_off == Some(a.t);
        if bounded_above(a, b, 2.0 * disagreement, -self.tolerance, starts_on_cam) {
            return Ok(None);
        }
        if let Some(found) = self.piece(gap, a, m)? {
            return Ok(Some(found));
        }
        self.piece(gap, m, b)
    }
}

/// φ(s) = H(s) − 16 bound s² (1 − s)² > `floor` on the piece, its start excluded when the
/// flight takes off there (where the gap is zero). φ is a quartic in s: its smallest value is
/// at an end or where φ′ changes sign from − to +, found among [`BOUND_POINTS`] samples of φ′
/// and refined by bisection (φ′, a cubic, has at most three roots; two within one sample
/// interval would bound a dip of φ of the order of that interval's width cubed times φ‴).
fn bounded_above(a: GapPoint, b: GapPoint, bound: f64, floor: f64, starts_on_cam: bool) -> bool {
    let h = b.t - a.t;
    let (g0, d0, g1, d1) = (a.g, h * a.rate, b.g, h * b.rate);
    let phi = |s: f64| hermite(a, b, s) - 16.0 * bound * s * s * (1.0 - s) * (1.0 - s);
    let dphi = |s: f64| {
        (6.0 * s * s - 6.0 * s) * g0
            + (3.0 * s * s - 4.0 * s + 1.0) * d0
            + (-6.0 * s * s + 6.0 * s) * g1
            + (3.0 * s * s - 2.0 * s) * d1
            - 16.0 * bound * (2.0 * s - 6.0 * s * s + 4.0 * s * s * s)
    };
    if phi(1.0) <= floor || (!starts_on_cam && phi(0.0) <= floor) {
        return false;
    }
    let mut previous = dphi(0.0);
    for i in 1..=BOUND_POINTS {
        let s = i as f64 / BOUND_POINTS as f64;
        let slope = dphi(s);
        if previous < 0.0 && slope >= 0.0 {
            let (mut lo, mut hi) = (s - 1.0 / BOUND_POINTS as f64, s);
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                if dphi(mid) < 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            if phi(hi) <= floor {
                return false;
            }
        }
        previous = slope;
    }
    true
}

/// The cubic Hermite interpolant of the gap on [a, b] at s ∈ [0, 1].
fn hermite(a: GapPoint, b: GapPoint, s: f64) -> f64 {
    let h = b.t - a.t;
    let s2 = s * s;
    let s3 = s2 * s;
    (2.0 * s3 - 3.0 * s2 + 1.0) * a.g
        + (s3 - 2.0 * s2 + s) * h * a.rate
        + (-2.0 * s3 + 3.0 * s2) * b.g
        + (s3 - s2) * h * b.rate
}

#[cfg(test)]
mod tests {
    use super::*;

    fn force_step(p: impl Fn(f64) -> f64, t0: f64, t1: f64) -> (f64, f64, f64, Vec<(f64, f64)>) {
        // Dormand–Prince 5(4)'s nodes and fifth-order weights, p along an exact solution.
        let nodes = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0];
        let weights = [
            35.0 / 384.0,
            0.0,
            500.0 / 1113.0,
            125.0 / 192.0,
            -2187.0 / 6784.0,
            11.0 / 84.0,
        ];
        let h = t1 - t0;
        let mean = nodes
            .iter()
            .zip(weights)
            .map(|(c, b)| b * p(t0 + c * h))
            .sum();
        let stages = nodes[1..5]
            .iter()
            .map(|c| (t0 + c * h, p(t0 + c * h)))
            .collect();
        (p(t0), p(t1), mean, stages)
    }

    #[test]
    fn a_dip_between_positive_ends_is_predicted_and_found() {
        // p = 4 (t − 0.55)² − 0.01 dips to −0.01 around t = 0.55 inside [0, 1] and is
        // positive at both ends.
        let p = |t: f64| 4.0 * (t - 0.55) * (t - 0.55) - 0.01;
        let (p0, p1, mean, stages) = force_step(p, 0.0, 1.0);
        let step = ForceStep {
            start: (0.0, p0),
            end: (1.0, p1),
            mean,
            stages: &stages,
        };
        let guess = excursion_guess(&step).expect("the dip is predicted");
        assert!((guess - 0.55).abs() < 0.05, "{guess}");
        let found = find_excursion(|t| Ok(p(t)), (0.0, p0), (1.0, p1), guess)
            .unwrap()
            .expect("the exact search finds the negative window");
        // The window is 0.55 ± 0.05: the brackets contain its two ends.
        let ((a, pa), (b, pb)) = found.leaves;
        assert!(
            pa > 0.0 && pb <= 0.0 && a < 0.5 && b > 0.5 && b < 0.6,
            "{found:?}"
        );
        let ((c, _), (d, pd)) = found.returns.expect("it comes back");
        assert!(pd > 0.0 && c < 0.6 && d > 0.6, "{found:?}");
    }

    #[test]
    fn a_force_far_from_zero_is_not_searched() {
        // Varies by 2 over the step, never below 10: no search.
        let p = |t: f64| 10.0 + 2.0 * t * t;
        let (p0, p1, mean, stages) = force_step(p, 0.0, 1.0);
        let step = ForceStep {
            start: (0.0, p0),
            end: (1.0, p1),
            mean,
            stages: &stages,
        };
        assert_eq!(excursion_guess(&step), None);
    }

    #[test]
    fn a_positive_minimum_is_searched_but_not_crossed() {
        // Dips to +0.01: searched (close to zero), and the search reports no crossing.
        let p = |t: f64| 4.0 * (t - 0.4) * (t - 0.4) + 0.01;
        let (p0, p1, mean, stages) = force_step(p, 0.0, 1.0);
        let step = ForceStep {
            start: (0.0, p0),
            end: (1.0, p1),
            mean,
            stages: &stages,
        };
        let guess = excursion_guess(&step).expect("close to zero: searched");
        let found = find_excursion(|t| Ok(p(t)), (0.0, p0), (1.0, p1), guess).unwrap();
        assert_eq!(found, None);
    }

    #[test]
    fn a_negative_force_coming_up_through_zero_is_found_too() {
        // The mirror image: p < 0 at both ends, above zero around t = 0.3.
        let p = |t: f64| -(50.0 * (t - 0.3) * (t - 0.3) - 0.02);
        let (p0, p1, mean, stages) = force_step(p, 0.0, 1.0);
        let step = ForceStep {
            start: (0.0, p0),
            end: (1.0, p1),
            mean,
            stages: &stages,
        };
        let guess = excursion_guess(&step).expect("predicted");
        let found = find_excursion(|t| Ok(p(t)), (0.0, p0), (1.0, p1), guess)
            .unwrap()
            .expect("found");
        assert!(found.leaves.1.1 >= 0.0 && found.returns.is_some());
    }

    fn gap_of(g: impl Fn(f64) -> f64 + Copy) -> impl FnMut(f64) -> Result<GapPoint, SimError> {
        move |t| {
            // The rate by a central difference of the closed form (step 1e-7, error ~1e-14
            // relative for these smooth functions): the scan only uses it for the
            // interpolant.
            let d = 1e-7;
            let rate = (g(t + d) - g(t - d)) / (2.0 * d);
            Ok(GapPoint {
                t,
                g: g(t),
                rate,
                // No bound: every piece is checked on its values.
                speed: f64::INFINITY,
            })
        }
    }

    #[test]
    fn a_cam_lobe_passing_within_one_step_is_found() {
        // The gap of a follower above a fast cam, 1.3 − 1.6 sin²(ωt), closes twice per turn;
        // a step of one and a half turns (ωt from 0 to 3π + 0.2) is open at both ends.
        let omega = 40.0;
        let t1 = (3.0 * std::f64::consts::PI + 0.2) / omega;
        let g = move |t: f64| 1.3 - 1.6 * (omega * t).sin().powi(2);
        let mut gap = gap_of(g);
        let (start, end) = (gap(0.0).unwrap(), gap(t1).unwrap());
        assert!(start.g > 0.0 && end.g > 0.0);
        // Pieces of a quarter radian of the phase.
        let pieces = (omega * t1 / 0.25).ceil() as usize;
        let Closing::Bracket(open, closed) =
            first_closing(gap, start, end, (pieces, 1e-12), false).unwrap()
        else {
            panic!("the closing was missed");
        };
        // First zero of 1.3 − 1.6 sin²(ωt): sin² = 1.3/1.6.
        let first = (1.3_f64 / 1.6).sqrt().asin() / omega;
        assert!(open.t < first && closed.t >= first && open.g > 0.0 && closed.g <= 0.0);
    }

    #[test]
    fn a_graze_that_stays_open_is_clear_and_a_shallow_dip_is_not() {
        // Tangent approaches: minimum +1e-6 (clear) and −1e-6 (closing), both mid-step.
        for (depth, closes) in [(1e-6, false), (-1e-6, true)] {
            let g = move |t: f64| (t - 0.37) * (t - 0.37) + depth;
            let mut gap = gap_of(g);
            let (start, end) = (gap(0.0).unwrap(), gap(1.0).unwrap());
            let result = first_closing(gap, start, end, (1, 1e-12), false).unwrap();
            assert_eq!(
                matches!(result, Closing::Bracket(..)),
                closes,
                "{depth}: {result:?}"
            );
        }
    }

    #[test]
    fn a_take_off_that_lands_within_its_first_step() {
        // From zero, up to 1e-3 and back down: lands at t = 0.2 of a step of 1.
        let g = |t: f64| t * (0.2 - t) * 0.1;
        let mut gap = gap_of(g);
        let (start, end) = (gap(0.0).unwrap(), gap(1.0).unwrap());
        let Closing::Bracket(open, closed) =
            first_closing(gap, start, end, (1, 1e-12), true).unwrap()
        else {
            panic!("the landing was missed");
        };
        assert!(open.t < 0.2 && closed.t >= 0.2);
        // A rebound off a cam that accelerates into the follower (the eccentric roller at
        // 5000 rad/s: 3.6 m/s apart, 2.5e5 m/s² closing): it lands again after 28.5 µs of
        // a 3.6 ms step that ends with the gap wide open (the cam has turned away), as it
        // is at the step's midpoint.
        let g = |t: f64| {
            if t < 1e-4 {
                3.56 * t - 1.25e5 * t * t
            } else {
                0.1 * (t - 1e-4) - 3.56e-6
            }
        };
        let mut gap = gap_of(g);
        let (start, end) = (gap(0.0).unwrap(), gap(3.6e-3).unwrap());
        assert!(end.g > 0.0 && gap(1.8e-3).unwrap().g > 0.0);
        let Closing::Bracket(open, closed) =
            first_closing(gap, start, end, (1, 1e-12), true).unwrap()
        else {
            panic!("the second landing was missed");
        };
        let landing = 3.56 / 1.25e5;
        assert!(
            open.t < landing && closed.t >= landing,
            "{open:?} {closed:?}"
        );
        // A hop that never opens: the gap is never positive.
        let mut never = gap_of(|t: f64| -t * t);
        let (start, end) = (never(0.0).unwrap(), never(1.0).unwrap());
        assert_eq!(
            first_closing(never, start, end, (1, 1e-12), true).unwrap(),
            Closing::NeverOpened
        );
    }
}
