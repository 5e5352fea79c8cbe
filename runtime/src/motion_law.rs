//! Follower motion laws: the displacement a cam must give its follower, as a function of the
//! cam's angle, built from the standard segments of cam design (dwell, rise, return).
//!
//! A segment moves the follower from one lift to the next over an angle β of the cam with a
//! normalised law f: s(θ) = s₀ + (s₁ − s₀)·f(u), u = (θ − θ₀)/β ∈ [0, 1], f(0) = 0, f(1) = 1.
//! The derivatives with respect to the cam's angle are (s₁ − s₀)·f⁽ᵏ⁾(u)/βᵏ; at a cam speed ω
//! the follower's velocity, acceleration and jerk are those times ω, ω², ω³.
//!
//! The laws ([`Law`]), with f′ and f″ at their peaks (the textbook factors C_v, C_a of
//! Norton, *Cam Design and Manufacturing Handbook*, ch. 3):
//!
//! | law | f(u) | C_v | C_a | ends |
//! |---|---|---:|---:|---|
//! | cycloidal | u − sin(2πu)/2π | 2 | 2π ≈ 6.2832 | v = a = 0 |
//! | simple harmonic | (1 − cos πu)/2 | π/2 | π²/2 | v = 0, a ≠ 0 |
//! | 3-4-5 polynomial | 10u³ − 15u⁴ + 6u⁵ | 1.875 | 5.7735 | v = a = 0 |
//! | 4-5-6-7 polynomial | 35u⁴ − 84u⁵ + 70u⁶ − 20u⁷ | 2.1875 | 7.5132 | v = a = j = 0 |
//! | modified trapezoid | acceleration: sine ramps over 1/8, flat tops | 2 | 4.8881 | v = a = 0 |
//! | modified sine | acceleration: sines of periods 1/2 and 3/2 | 1.7596 | 5.5280 | v = a = 0 |
//!
//! The two composite laws are defined by their acceleration, piecewise a constant or a sine
//! or cosine; [`Law::normalised`] integrates it in closed form piece by piece (the
//! constants of integration carried across the joints), and scales it so that f(1) = 1.

use std::f64::consts::PI;

/// A normalised motion law f(u) on u ∈ [0, 1].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Law {
    /// No motion: f = 0 (a dwell keeps its lift).
    Dwell,
    /// f = u − sin(2πu)/(2π).
    Cycloidal,
    /// f = (1 − cos πu)/2.
    SimpleHarmonic,
    /// f = 10u³ − 15u⁴ + 6u⁵.
    Polynomial345,
    /// f = 35u⁴ − 84u⁵ + 70u⁶ − 20u⁷.
    Polynomial4567,
    /// Acceleration with sine ramps over the first, fourth, fifth and last eighths and
    /// constant between.
    ModifiedTrapezoid,
    /// Acceleration a quarter sine of period 1/2 over the first and last eighths, a cosine
    /// of period 3/2 between.
    ModifiedSine,
}

/// One piece of a composite law's acceleration on [start, end]: A sin(k τ) + B cos(k τ) + D
/// with τ = u − start, before scaling.
#[derive(Debug, Clone, Copy)]
struct Piece {
    start: f64,
    sine: f64,
    cosine: f64,
    rate: f64,
    constant: f64,
}

impl Piece {
    const fn new(start: f64, sine: f64, cosine: f64, rate: f64, constant: f64) -> Self {
        Piece {
            start,
            sine,
            cosine,
            rate,
            constant,
        }
    }

    /// [Δs, Δv, a, j] at τ from the piece's start, with velocity `v0` at its start: the
    /// acceleration integrated once and twice in closed form.
    fn integrate(&self, tau: f64, v0: f64) -> [f64; 4] {
        let (a, b, k, d) = (self.sine, self.cosine, self.rate, self.constant);
        let (sn, cs) = (k * tau).sin_cos();
        let dv = a * (1.0 - cs) / k + b * sn / k + d * tau;
        let ds = v0 * tau + a * (tau - sn / k) / k + b * (1.0 - cs) / (k * k) + d * tau * tau / 2.0;
        [ds, dv, a * sn + b * cs + d, k * (a * cs - b * sn)]
    }
}

/// The modified trapezoid's acceleration for a peak of 1.
const TRAPEZOID: [Piece; 5] = [
    Piece::new(0.0, 1.0, 0.0, 4.0 * PI, 0.0),
    Piece::new(0.125, 0.0, 0.0, 4.0 * PI, 1.0),
    Piece::new(0.375, 0.0, 1.0, 4.0 * PI, 0.0),
    Piece::new(0.625, 0.0, 0.0, 4.0 * PI, -1.0),
    Piece::new(0.875, 0.0, -1.0, 4.0 * PI, 0.0),
];

/// The modified sine's acceleration for a peak of 1.
const MODIFIED_SINE: [Piece; 3] = [
    Piece::new(0.0, 1.0, 0.0, 4.0 * PI, 0.0),
    Piece::new(0.125, 0.0, 1.0, 4.0 * PI / 3.0, 0.0),
    Piece::new(0.875, 0.0, -1.0, 4.0 * PI, 0.0),
];

/// The state a composite law reaches at the start of each of its pieces, before scaling:
/// (Δs, Δv) integrated over every piece before it, and f(1) (the scale).
#[derive(Debug)]
struct PieceStarts {
    starts: Vec<[f64; 2]>,
    total: f64,
}

impl PieceStarts {
    /// Integrates `pieces` once, piece by piece.
    fn of(pieces: &[Piece]) -> Self {
        let (mut s, mut v) = (0.0, 0.0);
        let mut starts = Vec::with_capacity(pieces.len());
        for (i, piece) in pieces.iter().enumerate() {
            starts.push([s, v]);
            let end = pieces.get(i + 1).map_or(1.0, |p| p.start);
            let [ds, dv, _, _] = piece.integrate(end - piece.start, v);
            s += ds;
            v += dv;
        }
        PieceStarts { starts, total: s }
    }
}

/// [f, f′, f″, f‴] of a composite law defined by its acceleration `pieces` (peak 1), scaled
/// so that f(1) = 1: the piece holding u integrated from its start, whose state `table` keeps.
fn composite(pieces: &[Piece], table: &PieceStarts, u: f64) -> [f64; 4] {
    let i = pieces
        .partition_point(|p| p.start < u)
        .saturating_sub(1)
        .min(pieces.len() - 1);
    let [s, v] = table.starts[i];
    let [ds, dv, a, j] = pieces[i].integrate(u - pieces[i].start, v);
    [s + ds, v + dv, a, j].map(|x| x / table.total)
}

/// The pieces' starting states of the modified trapezoid, computed once.
fn trapezoid_starts() -> &'static PieceStarts {
    static TABLE: std::sync::OnceLock<PieceStarts> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| PieceStarts::of(&TRAPEZOID))
}

/// The pieces' starting states of the modified sine, computed once.
fn modified_sine_starts() -> &'static PieceStarts {
    static TABLE: std::sync::OnceLock<PieceStarts> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| PieceStarts::of(&MODIFIED_SINE))
}

/// [f, f′, f″, f‴] of a polynomial Σ c_k u^k (coefficients from u⁰), by Horner's scheme
/// carried to the third derivative (Knuth, TAOCP vol. 2, §4.6.4): each pass divides by
/// (x − u) once more, so that the remainders are f, f′, f″/2 and f‴/6.
///
/// A plain loop rather than iterator adapters: build scripts run this unoptimised (cargo
/// compiles build-time dependencies at opt-level 0), when they check the models' cam designs
/// at thousands of points; the folds and ranges it replaced made it a third of the built-in
/// models' generation time.
fn polynomial(c: &[f64], u: f64) -> [f64; 4] {
    let [mut f, mut d1, mut d2, mut d3] = [0.0; 4];
    let mut k = c.len();
    while k > 0 {
        k -= 1;
        d3 = d3 * u + d2;
        d2 = d2 * u + d1;
        d1 = d1 * u + f;
        f = f * u + c[k];
    }
    [f, d1, 2.0 * d2, 6.0 * d3]
}

impl Law {
    /// Every law, in the order of the module's table.
    pub const ALL: [Law; 7] = [
        Law::Dwell,
        Law::Cycloidal,
        Law::SimpleHarmonic,
        Law::Polynomial345,
        Law::Polynomial4567,
        Law::ModifiedTrapezoid,
        Law::ModifiedSine,
    ];

    /// The law's name in model files and messages.
    pub fn name(self) -> &'static str {
        match self {
            Law::Dwell => "dwell",
            Law::Cycloidal => "cycloidal",
            Law::SimpleHarmonic => "simple harmonic",
            Law::Polynomial345 => "3-4-5 polynomial",
            Law::Polynomial4567 => "4-5-6-7 polynomial",
            Law::ModifiedTrapezoid => "modified trapezoid",
            Law::ModifiedSine => "modified sine",
        }
    }

    /// [f, f′, f″, f‴] at u ∈ [0, 1] (derivatives with respect to u), in closed form.
    pub fn normalised(self, u: f64) -> [f64; 4] {
        let tau = 2.0 * PI;
        match self {
            Law::Dwell => [0.0; 4],
            Law::Cycloidal => {
                let (sn, cs) = (tau * u).sin_cos();
                [u - sn / tau, 1.0 - cs, tau * sn, tau * tau * cs]
            }
            Law::SimpleHarmonic => {
                let (sn, cs) = (PI * u).sin_cos();
                [
                    (1.0 - cs) / 2.0,
                    PI * sn / 2.0,
                    PI * PI * cs / 2.0,
                    -PI.powi(3) * sn / 2.0,
                ]
            }
            Law::Polynomial345 => polynomial(&[0.0, 0.0, 0.0, 10.0, -15.0, 6.0], u),
            Law::Polynomial4567 => polynomial(&[0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0], u),
            Law::ModifiedTrapezoid => composite(&TRAPEZOID, trapezoid_starts(), u),
            Law::ModifiedSine => composite(&MODIFIED_SINE, modified_sine_starts(), u),
        }
    }
}

/// One segment of a motion program: the follower goes to `lift` over `angle` of the cam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// The law.
    pub law: Law,
    /// The cam angle the segment takes (rad, > 0).
    pub angle: f64,
    /// The follower's lift at the segment's end (m or rad); a dwell keeps the previous one.
    pub lift: f64,
}

/// Why segments do not make a motion program.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LawError {
    /// No segment.
    #[error("a motion program needs at least one segment")]
    Empty,
    /// A segment's angle that is not a positive finite number.
    #[error("segment {index}: its angle must be positive, not {angle}")]
    BadAngle {
        /// The segment (from 0).
        index: usize,
        /// Its angle (rad).
        angle: f64,
    },
    /// A lift that is not finite.
    #[error("segment {index}: its lift must be a finite number, not {lift}")]
    BadLift {
        /// The segment.
        index: usize,
        /// The lift.
        lift: f64,
    },
    /// A dwell whose lift differs from the one before.
    #[error("segment {index}: a dwell keeps the lift ({before}), it cannot go to {lift}")]
    DwellMoves {
        /// The segment.
        index: usize,
        /// The lift before it.
        before: f64,
        /// The lift it names.
        lift: f64,
    },
    /// Angles that do not add up to a turn.
    #[error(
        "the segments' angles add up to {:.6}°, not 360°", total.to_degrees()
    )]
    NotATurn {
        /// Their sum (rad).
        total: f64,
    },
    /// A program that does not bring the follower back to the base circle.
    #[error(
        "the follower must come back to lift 0 (the base circle) after a turn, but the last segment ends at {end}"
    )]
    DoesNotReturn {
        /// Where the program ends.
        end: f64,
    },
}

/// Relative tolerance (of the largest lift) within which the last segment must end at lift 0.
pub const RETURN_TOLERANCE: f64 = 1e-12;

/// Relative tolerance of the angles' sum against a full turn (angles written in degrees with
/// 9 significant digits meet it).
pub const TURN_TOLERANCE: f64 = 1e-9;

/// A follower's displacement over a full turn of its cam, segment by segment, starting at
/// angle 0 from lift 0 (the base circle) and coming back to it.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionProgram {
    segments: Vec<Segment>,
    /// The angle where each segment starts (rad).
    starts: Vec<f64>,
}

/// A change of a derivative where two segments join.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jump {
    /// The segment that starts at the joint (from 0; 0 is the joint at angle 0 with the last).
    pub segment: usize,
    /// The cam angle of the joint (rad).
    pub angle: f64,
    /// Which derivative with respect to the cam angle: 1 velocity, 2 acceleration, 3 jerk.
    pub order: usize,
    /// The value after the joint minus the value before it (per rad^order).
    pub size: f64,
}

impl MotionProgram {
    /// The program of `segments`, or why they do not make one.
    pub fn new(segments: &[Segment]) -> Result<Self, LawError> {
        if segments.is_empty() {
            return Err(LawError::Empty);
        }
        let mut before = 0.0;
        let mut starts = Vec::with_capacity(segments.len());
        let mut total = 0.0;
        for (index, s) in segments.iter().enumerate() {
            if !(s.angle.is_finite() && s.angle > 0.0) {
                return Err(LawError::BadAngle {
                    index,
                    angle: s.angle,
                });
            }
            if !s.lift.is_finite() {
                return Err(LawError::BadLift {
                    index,
                    lift: s.lift,
                });
            }
            if s.law == Law::Dwell && s.lift != before {
                return Err(LawError::DwellMoves {
                    index,
                    before,
                    lift: s.lift,
                });
            }
            starts.push(total);
            total += s.angle;
            before = s.lift;
        }
        let turn = 2.0 * PI;
        if (total - turn).abs() > TURN_TOLERANCE * turn {
            return Err(LawError::NotATurn { total });
        }
        // Lifts are measured from the base circle: a turn starts and ends there.
        let largest = segments.iter().fold(0.0f64, |a, s| a.max(s.lift.abs()));
        if before.abs() > RETURN_TOLERANCE * largest {
            return Err(LawError::DoesNotReturn { end: before });
        }
        Ok(MotionProgram {
            segments: segments.to_vec(),
            starts,
        })
    }

    /// The segments.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// The lift before segment `i` (0 for the first).
    fn lift_before(&self, i: usize) -> f64 {
        if i == 0 {
            0.0
        } else {
            self.segments[i - 1].lift
        }
    }

    /// [s, ds/dθ, d²s/dθ², d³s/dθ³] of segment `i` at u ∈ [0, 1].
    fn in_segment(&self, i: usize, u: f64) -> [f64; 4] {
        segment_values(&self.segments[i], self.lift_before(i), u)
    }

    /// [s, ds/dθ, d²s/dθ², d³s/dθ³] at the cam angle `theta` (rad; any value: the program
    /// repeats every turn): [`evaluate`] on its segments.
    pub fn eval(&self, theta: f64) -> [f64; 4] {
        evaluate(&self.segments, theta)
    }

    /// The angle where each segment starts (rad).
    pub fn starts(&self) -> &[f64] {
        &self.starts
    }

    /// Every joint where the velocity, acceleration or jerk changes by more than `relative`
    /// of that derivative's largest value over the turn (sampled), in angle order.
    pub fn jumps(&self, relative: f64) -> Vec<Jump> {
        let n = self.segments.len();
        let mut scale = [0.0f64; 4];
        for k in 0..=4096 {
            let v = self.eval(2.0 * PI * k as f64 / 4096.0);
            for (s, x) in scale.iter_mut().zip(v) {
                *s = s.max(x.abs());
            }
        }
        let mut out = Vec::new();
        for i in 0..n {
            let before = self.in_segment(if i == 0 { n - 1 } else { i - 1 }, 1.0);
            let after = self.in_segment(i, 0.0);
            for order in 1..4 {
                let size = after[order] - before[order];
                if size.abs() > relative * scale[order].max(f64::MIN_POSITIVE) {
                    out.push(Jump {
                        segment: i,
                        angle: self.starts[i],
                        order,
                        size,
                    });
                }
            }
        }
        out
    }
}

/// [s, ds/dθ, d²s/dθ², d³s/dθ³] of `segment`, which starts from the lift `before`, at
/// u ∈ [0, 1] of its angle.
fn segment_values(segment: &Segment, before: f64, u: f64) -> [f64; 4] {
    let rise = segment.lift - before;
    let f = segment.law.normalised(u);
    let beta = segment.angle;
    [
        before + rise * f[0],
        rise * f[1] / beta,
        rise * f[2] / (beta * beta),
        rise * f[3] / (beta * beta * beta),
    ]
}

/// [s, ds/dθ, d²s/dθ², d³s/dθ³] at the cam angle `theta` of the program `segments` (checked
/// by [`MotionProgram::new`]; the first starts at angle 0 from lift 0), repeated every turn:
/// what generated code calls for a cam designed from a motion law, its segments a constant
/// array. The segment holding θ is found by adding up the angles (programs have a handful of
/// segments); a joint belongs to the segment that starts there. NaN for no segment.
pub fn evaluate(segments: &[Segment], theta: f64) -> [f64; 4] {
    let theta = theta.rem_euclid(2.0 * PI);
    let (mut start, mut before) = (0.0, 0.0);
    for (i, segment) in segments.iter().enumerate() {
        let end = start + segment.angle;
        if theta < end || i + 1 == segments.len() {
            let u = ((theta - start) / segment.angle).clamp(0.0, 1.0);
            return segment_values(segment, before, u);
        }
        start = end;
        before = segment.lift;
    }
    [f64::NAN; 4]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f⁽ᵒʳᵈᵉʳ⁾(u) − f⁽ᵒʳᵈᵉʳ⁾(0) by Simpson's rule on f⁽ᵒʳᵈᵉʳ⁺¹⁾ sampled: a route independent of
    /// the closed forms. The interval is cut at the eighths, where the composite laws' pieces
    /// join (their jerk has kinks there), 256 Simpson intervals per cut.
    fn integrate(law: Law, order: usize, u: f64) -> f64 {
        let g = |x: f64| law.normalised(x)[order + 1];
        let mut cuts: Vec<f64> = (0..=8).map(|k| k as f64 / 8.0).filter(|&c| c < u).collect();
        cuts.push(u);
        cuts.windows(2)
            .map(|w| {
                let (a, b, n) = (w[0], w[1], 256);
                let h = (b - a) / n as f64;
                let inner: f64 = (1..n)
                    .map(|k| g(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 })
                    .sum();
                (g(a) + g(b) + inner) * h / 3.0
            })
            .sum()
    }

    #[test]
    fn each_law_goes_from_zero_to_one_with_consistent_derivatives() {
        for law in Law::ALL.into_iter().skip(1) {
            let f0 = law.normalised(0.0);
            let f1 = law.normalised(1.0);
            // Closed forms: exact to rounding (1e-12 on values of order 1..300).
            assert!(
                f0[0].abs() < 1e-12 && (f1[0] - 1.0).abs() < 1e-12,
                "{law:?}"
            );
            assert!(
                f0[1].abs() < 1e-12 && f1[1].abs() < 1e-12,
                "{law:?}: rest at the ends"
            );
            // Each derivative is the integral of the next (Simpson with h ≤ 1/2048: its error
            // ~ h⁴ max|f⁽⁴⁺ᵒʳᵈᵉʳ⁾|/180 ≤ 1e-13 · (4π)⁴⁺ᵒʳᵈᵉʳ ~ 1e-8 for the jerk of the composite
            // laws' fastest sine: 1e-7).
            for u in [0.1, 0.3, 0.5, 0.77, 1.0] {
                for order in 0..3 {
                    let exact = law.normalised(u)[order] - law.normalised(0.0)[order];
                    let numeric = integrate(law, order, u);
                    assert!(
                        (exact - numeric).abs() < 1e-7,
                        "{law:?} f^({order})({u}): {exact} vs {numeric}"
                    );
                }
            }
        }
    }

    #[test]
    fn polynomial_derivatives_are_the_differentiated_coefficients() {
        // 4-5-6-7: f = 35u⁴ − 84u⁵ + 70u⁶ − 20u⁷ and its derivatives written out by hand; the
        // terms are at most ~1e3, so 1e-12 is a few ulps of them.
        for u in [-0.7, 0.0, 0.2, 0.5, 0.93, 1.0, 1.6] {
            let p = |c: &[f64]| c.iter().rev().fold(0.0, |acc, &ck| acc * u + ck);
            let exact = [
                p(&[0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0]),
                p(&[0.0, 0.0, 0.0, 140.0, -420.0, 420.0, -140.0]),
                p(&[0.0, 0.0, 420.0, -1680.0, 2100.0, -840.0]),
                p(&[0.0, 840.0, -5040.0, 8400.0, -4200.0]),
            ];
            let got = polynomial(&[0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0], u);
            for (order, (g, e)) in got.iter().zip(exact).enumerate() {
                assert!(
                    (g - e).abs() < 1e-12 * (1.0 + e.abs()),
                    "f^({order})({u}): {g} vs {e}"
                );
            }
        }
        assert_eq!(polynomial(&[], 0.3), [0.0; 4]);
        assert_eq!(polynomial(&[2.5], 0.3), [2.5, 0.0, 0.0, 0.0]);
    }

    /// The largest |f′| and |f″| over [0, 1] (dense sampling plus the known peak points).
    fn peaks(law: Law) -> (f64, f64) {
        let mut points: Vec<f64> = (0..=80_000).map(|k| k as f64 / 80_000.0).collect();
        points.extend([0.5, (3.0 - 3f64.sqrt()) / 6.0, 0.125, 0.375]);
        points.iter().fold((0.0f64, 0.0f64), |(v, a), &u| {
            let f = law.normalised(u);
            (v.max(f[1].abs()), a.max(f[2].abs()))
        })
    }

    #[test]
    fn peak_factors_are_the_textbook_ones() {
        // Norton, Cam Design and Manufacturing Handbook, ch. 3 (C_v, C_a; four digits, so
        // 1e-4 relative), and closed forms where they exist: cycloidal 2 and 2π, simple
        // harmonic π/2 and π²/2, 3-4-5 15/8 and 10√3/3 (at u = (3 − √3)/6), to 1e-9.
        let table = [
            (Law::Cycloidal, 2.0, 2.0 * PI, 1e-9_f64),
            (Law::SimpleHarmonic, PI / 2.0, PI * PI / 2.0, 1e-9),
            (Law::Polynomial345, 1.875, 10.0 * 3f64.sqrt() / 3.0, 1e-9),
            (Law::Polynomial4567, 2.1875, 7.5132, 1e-4),
            (Law::ModifiedTrapezoid, 2.0, 4.8881, 1e-4),
            (Law::ModifiedSine, 1.7596, 5.5280, 1e-4),
        ];
        for (law, cv, ca, tolerance) in table {
            let (v, a) = peaks(law);
            assert!((v - cv).abs() < tolerance * cv, "{law:?}: C_v {v} vs {cv}");
            assert!((a - ca).abs() < tolerance * ca, "{law:?}: C_a {a} vs {ca}");
        }
    }

    #[test]
    fn textbook_peaks_at_speed() {
        // A cycloidal rise of h over β at ω: peak velocity 2hω/β, acceleration 2πhω²/β²;
        // a 3-4-5 rise: 1.875hω/β and 5.7735hω²/β² (issue's values; the factor 5.7735 has
        // 5 digits: 1e-5 relative).
        let (h, beta, omega) = (0.012, 100f64.to_radians(), 30.0);
        for (law, cv, ca, tol) in [
            (Law::Cycloidal, 2.0, 2.0 * PI, 1e-9),
            (Law::Polynomial345, 1.875, 5.7735, 1e-5),
        ] {
            let rest = 2.0 * PI - beta;
            let program = MotionProgram::new(&[
                Segment {
                    law,
                    angle: beta,
                    lift: h,
                },
                Segment {
                    law: Law::Dwell,
                    angle: rest / 2.0,
                    lift: h,
                },
                Segment {
                    law,
                    angle: rest / 2.0,
                    lift: 0.0,
                },
            ])
            .unwrap();
            let (mut v, mut a) = (0.0f64, 0.0f64);
            for k in 0..=200_000 {
                let d = program.eval(beta * k as f64 / 200_000.0);
                v = v.max((d[1] * omega).abs());
                a = a.max((d[2] * omega * omega).abs());
            }
            assert!((v - cv * h * omega / beta).abs() < tol * v, "{law:?} v");
            assert!(
                (a - ca * h * omega * omega / beta.powi(2)).abs() < tol * a,
                "{law:?} a"
            );
        }
    }

    #[test]
    fn programs_are_checked_and_joints_reported() {
        let d = 90f64.to_radians();
        let seg = |law, angle, lift| Segment { law, angle, lift };
        let ok = MotionProgram::new(&[
            seg(Law::SimpleHarmonic, d, 0.01),
            seg(Law::Dwell, d, 0.01),
            seg(Law::Cycloidal, d, 0.0),
            seg(Law::Dwell, d, 0.0),
        ])
        .unwrap();
        // Simple harmonic starts and ends with an acceleration: jumps against the dwells
        // (segments 0 and 1), none where the cycloidal meets a dwell but in jerk.
        let jumps = ok.jumps(1e-9);
        let acceleration: Vec<usize> = jumps
            .iter()
            .filter(|j| j.order == 2)
            .map(|j| j.segment)
            .collect();
        assert_eq!(acceleration, vec![0, 1]);
        // The size: (π²/2)·h/β² at the start of the rise.
        let first = jumps
            .iter()
            .find(|j| j.order == 2 && j.segment == 0)
            .unwrap();
        assert!((first.size - PI * PI / 2.0 * 0.01 / (d * d)).abs() < 1e-12);
        assert!(jumps.iter().all(|j| j.order != 1), "no velocity jump");
        assert_eq!(
            MotionProgram::new(&[
                seg(Law::Cycloidal, d, 0.01),
                seg(Law::Dwell, 3.0 * d - 0.1, 0.01)
            ]),
            Err(LawError::NotATurn {
                total: 4.0 * d - 0.1
            })
        );
        assert!(matches!(
            MotionProgram::new(&[
                seg(Law::Cycloidal, 2.0 * d, 0.01),
                seg(Law::Dwell, 2.0 * d, 0.02)
            ]),
            Err(LawError::DwellMoves { index: 1, .. })
        ));
        assert_eq!(
            MotionProgram::new(&[
                seg(Law::Cycloidal, 2.0 * d, 0.01),
                seg(Law::Cycloidal, 2.0 * d, 0.002)
            ]),
            Err(LawError::DoesNotReturn { end: 0.002 })
        );
        assert!(matches!(
            MotionProgram::new(&[
                seg(Law::Cycloidal, 4.0 * d, 0.01),
                seg(Law::Dwell, -1.0, 0.01)
            ]),
            Err(LawError::BadAngle { index: 1, .. })
        ));
        assert_eq!(MotionProgram::new(&[]), Err(LawError::Empty));
        // The program repeats every turn.
        let (a, b) = (ok.eval(0.3), ok.eval(0.3 + 4.0 * PI));
        for k in 0..4 {
            assert!((a[k] - b[k]).abs() < 1e-12);
        }
    }
}
