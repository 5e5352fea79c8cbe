//! The cam's dynamics: the contact force over a turn at constant cam speed (bilateral runs),
//! the jump speed it predicts, and a one-sided run that shows where the follower really
//! leaves the cam.
//!
//! With the camshaft driven at the constant speed ω and the follower held on its cam (no
//! degree of freedom in bilateral contact: every coordinate prescribed or dependent), the
//! positions depend on the cam angle θ only, the velocities scale with ω and the
//! accelerations with ω², so the contact force is exactly
//!
//!   N(θ, ω) = A(θ) + B(θ) ω + C(θ) ω²
//!
//! (A: gravity and springs, B: dampers, C: inertia). Runs at three speeds sampled at the same
//! angles give A, B and C at every angle, and the follower leaves the cam at the smallest
//! speed at which N reaches zero somewhere: the smallest positive root over the angles.

use super::setup::{Runnable, SpeedControl, Subject};
use camchain_runtime::events::EventKind;
use camchain_runtime::{
    Dynamics, IntegratorKind, Sample, SimSettings, Simulate, Stats, Trajectory,
};
use std::f64::consts::TAU;
use std::time::{Duration, Instant};

/// Where the runs read the cam and the follower.
#[derive(Debug, Clone, Copy)]
pub struct Probe {
    /// The contact's index among the runtime's contacts.
    pub contact: usize,
    /// The camshaft's coordinate (its angle), when the cam turns on a revolute joint.
    pub cam: Option<usize>,
    /// σ: +1 for a cam turning counterclockwise, −1 clockwise (the design angle is σ q).
    pub sigma: f64,
    /// The follower's own coordinate.
    pub follower: Option<usize>,
}

impl Probe {
    /// The design's cam angle (rad, not wrapped) of a run's sample.
    pub fn angle(&self, speed: f64, t: f64, q: &[f64]) -> f64 {
        match self.cam.and_then(|i| q.get(i)) {
            Some(q) => self.sigma * q,
            None => speed * t,
        }
    }
}

/// One bilateral run over a turn at constant speed.
#[derive(Debug, Clone)]
pub struct Turn {
    /// The cam speed (rad/s).
    pub speed: f64,
    /// The value of the speed parameter that gave it.
    pub parameter: f64,
    /// The contact force at the design's sample angles 2πk/N, k = 0..=N (N).
    pub force: Vec<f64>,
    /// The integrator's work.
    pub stats: Stats,
    /// Assembly and simulation.
    pub wall: Duration,
}

/// The model's degrees of freedom in bilateral contact: coordinates neither driven nor
/// solved from a contact.
pub fn degrees_of_freedom(model: &dyn Dynamics) -> usize {
    let info = model.info();
    let free = info.coordinates.iter().filter(|c| !c.driven).count();
    free.saturating_sub(info.n_contacts())
}

/// The settings of a run of `turns` turns at `speed` with `per_turn` outputs a turn: the
/// model's integrator and tolerances (an adaptive one when `adaptive` is asked and the
/// model's is RK4: dop853 at the model's tolerances).
fn settings(
    model: &dyn Dynamics,
    speed: f64,
    turns: usize,
    per_turn: usize,
    adaptive: bool,
) -> SimSettings {
    let defaults = &model.info().defaults;
    let period = TAU / speed;
    let mut settings = SimSettings {
        t_end: period * turns as f64,
        dt_out: period / per_turn as f64,
        ..defaults.clone()
    };
    if adaptive && !settings.integrator.is_adaptive() {
        settings.integrator = IntegratorKind::Dop853;
    }
    // A first (or fixed) step no longer than an output interval.
    settings.dt = settings.dt.min(settings.dt_out);
    settings
}

/// The contact force of a run's samples at the design's angles 2πk/N (k = 0..=N): linear
/// interpolation in the run's cam angle over its first turn (exact where the outputs fall
/// on those angles, as they do for a camshaft driven at constant speed from angle 0). NaN
/// where the run does not reach an angle, or its angle does not increase.
pub fn at_design_angles(probe: &Probe, speed: f64, samples: &[Sample], n: usize) -> Vec<f64> {
    let points: Vec<(f64, f64)> = samples
        .iter()
        .map(|s| {
            (
                probe.angle(speed, s.t, &s.q),
                s.normal_force
                    .get(probe.contact)
                    .copied()
                    .unwrap_or(f64::NAN),
            )
        })
        .collect();
    let increasing = points.windows(2).all(|w| w[1].0 > w[0].0);
    let (Some(&(first, _)), true) = (points.first(), increasing) else {
        return vec![f64::NAN; n + 1];
    };
    (0..=n)
        .map(|k| {
            let target = TAU * k as f64 / n as f64;
            // The angle of the run's first turn that is the design's target angle.
            let mut theta = first + (target - first).rem_euclid(TAU);
            if k == n && (theta - first).abs() < 1e-9 {
                theta += TAU;
            }
            let i = points.partition_point(|p| p.0 < theta);
            match (i.checked_sub(1).and_then(|j| points.get(j)), points.get(i)) {
                (_, Some(b)) if (b.0 - theta).abs() <= 1e-12 * theta.abs().max(1.0) => b.1,
                (Some(a), Some(b)) => a.1 + (b.1 - a.1) * (theta - a.0) / (b.0 - a.0),
                _ => f64::NAN,
            }
        })
        .collect()
}

/// A turn at `speed` (bilateral), its force at the design's `n` + 1 angles.
pub fn bilateral_turn(
    subject: &Subject,
    control: &SpeedControl,
    probe: &Probe,
    speed: f64,
    n: usize,
) -> Result<Turn, String> {
    let start = Instant::now();
    let parameter = control.value_for(speed)?;
    let model = subject.build(control, parameter).map_err(|e| {
        format!(
            "the model at {speed} rad/s ({} = {parameter}): {e}",
            control.name
        )
    })?;
    check_drive(model.as_ref(), probe, speed)?;
    let state = model
        .assemble(0.0)
        .map_err(|e| format!("assembly at {speed} rad/s failed: {e}"))?;
    let settings = settings(model.as_ref(), speed, 1, n, false);
    let trajectory = model
        .simulate(state, &settings)
        .map_err(|e| format!("the bilateral run at {speed} rad/s failed: {}", e.error))?;
    Ok(Turn {
        speed,
        parameter,
        force: at_design_angles(probe, speed, &trajectory.samples, n),
        stats: trajectory.stats,
        wall: start.elapsed(),
    })
}

/// Relative mismatch between the camshaft's drive and the law's speed above which the runs
/// would not be at the speed they are labelled with.
const DRIVE_TOLERANCE: f64 = 1e-9;

/// A driven camshaft turns at `speed` in the design's sense at t = 0.
pub fn check_drive(model: &dyn Dynamics, probe: &Probe, speed: f64) -> Result<(), String> {
    let Some(cam) = probe.cam else {
        return Ok(());
    };
    let info = model.info();
    if !info.coordinates.get(cam).is_some_and(|c| c.driven) {
        return Ok(());
    }
    let state = model
        .assemble(0.0)
        .map_err(|e| format!("assembly at {speed} rad/s failed: {e}"))?;
    let turning = probe.sigma * state.qd[cam];
    if (turning - speed).abs() > DRIVE_TOLERANCE * speed {
        return Err(format!(
            "the camshaft's coordinate `{}` turns at {turning} rad/s in the design's sense when \
             the law's speed is {speed} rad/s: its drive does not follow the law's `speed`",
            info.coordinates[cam].name
        ));
    }
    Ok(())
}

/// Where the follower first leaves the cam as the speed grows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JumpSpeed {
    /// The least force over a turn reaches zero at `speed`, at the cam angle `theta`.
    At {
        /// The jump speed (rad/s).
        speed: f64,
        /// The cam angle where the force first reaches zero (rad).
        theta: f64,
    },
    /// The force is not positive even at rest (A ≤ 0) at `theta`: the follower is not held.
    AtRest {
        /// Where A is least (rad).
        theta: f64,
        /// A there (N).
        force: f64,
    },
    /// The force stays positive at every speed (no positive root).
    Never,
}

/// The prediction of the jump speed from three bilateral turns.
#[derive(Debug, Clone)]
pub struct Prediction {
    /// The three speeds (rad/s).
    pub speeds: [f64; 3],
    /// [A, B, C] at each design angle.
    pub coefficients: Vec<[f64; 3]>,
    /// The result.
    pub jump: JumpSpeed,
}

/// [A, B, C] with A + B wᵢ + C wᵢ² = Nᵢ for the three speeds (Lagrange's form).
fn quadratic(w: [f64; 3], n: [f64; 3]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for i in 0..3 {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        // Nᵢ (x − wⱼ)(x − w_k) / ((wᵢ − wⱼ)(wᵢ − w_k)).
        let scale = n[i] / ((w[i] - w[j]) * (w[i] - w[k]));
        out[0] += scale * w[j] * w[k];
        out[1] -= scale * (w[j] + w[k]);
        out[2] += scale;
    }
    out
}

/// The smallest positive root of A + B x + C x², if any (A > 0).
fn smallest_positive_root([a, b, c]: [f64; 3]) -> Option<f64> {
    let roots: Vec<f64> = if c.abs() <= 1e-300 {
        if b != 0.0 { vec![-a / b] } else { Vec::new() }
    } else {
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            Vec::new()
        } else {
            // The stable pair: q = −(b + sign(b)√disc)/2, roots q/c and a/q.
            let q = -0.5 * (b + b.signum() * disc.sqrt());
            let mut r = vec![q / c];
            if q != 0.0 {
                r.push(a / q);
            }
            r
        }
    };
    roots
        .into_iter()
        .filter(|r| r.is_finite() && *r > 0.0)
        .min_by(f64::total_cmp)
}

impl Prediction {
    /// A, B, C from three turns sampled at the same angles, and the jump speed.
    pub fn new(turns: [&Turn; 3]) -> Self {
        let speeds = [turns[0].speed, turns[1].speed, turns[2].speed];
        let n = turns.iter().map(|t| t.force.len()).min().unwrap_or(0);
        let coefficients: Vec<[f64; 3]> = (0..n)
            .map(|k| {
                quadratic(
                    speeds,
                    [turns[0].force[k], turns[1].force[k], turns[2].force[k]],
                )
            })
            .collect();
        let jump = jump_speed(&coefficients);
        Prediction {
            speeds,
            coefficients,
            jump,
        }
    }

    /// min over the design angles of N(θ, w) and where it is (rad).
    pub fn least_force(&self, w: f64) -> (f64, f64) {
        let n = self.coefficients.len().saturating_sub(1).max(1);
        self.coefficients
            .iter()
            .enumerate()
            .map(|(k, [a, b, c])| (TAU * k as f64 / n as f64, a + b * w + c * w * w))
            .filter(|(_, f)| f.is_finite())
            .fold((f64::NAN, f64::INFINITY), |best, (theta, f)| {
                if f < best.1 { (theta, f) } else { best }
            })
    }
}

/// The jump speed of the coefficients at the angles 2πk/N: the smallest positive root over
/// the angles, refined between the neighbours of the smallest by the vertex of the parabola
/// through the three roots (the root is a smooth function of the angle at its minimum).
fn jump_speed(coefficients: &[[f64; 3]]) -> JumpSpeed {
    let n = coefficients.len().saturating_sub(1).max(1);
    let angle = |k: usize| TAU * k as f64 / n as f64;
    let at_rest = coefficients
        .iter()
        .enumerate()
        .filter(|(_, c)| c[0].is_finite())
        .min_by(|a, b| a.1[0].total_cmp(&b.1[0]));
    if let Some((k, c)) = at_rest
        && c[0] <= 0.0
    {
        return JumpSpeed::AtRest {
            theta: angle(k),
            force: c[0],
        };
    }
    let roots: Vec<Option<f64>> = coefficients
        .iter()
        .map(|&c| smallest_positive_root(c))
        .collect();
    let Some((k, speed)) = roots
        .iter()
        .enumerate()
        .filter_map(|(k, r)| r.map(|r| (k, r)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
    else {
        return JumpSpeed::Never;
    };
    // Neighbours on the closed turn (angle 2π is angle 0 again).
    let neighbour = |j: isize| -> Option<f64> {
        let m = n as isize;
        let index = (k as isize + j).rem_euclid(m) as usize;
        roots.get(index).copied().flatten()
    };
    if let (Some(left), Some(right)) = (neighbour(-1), neighbour(1)) {
        let curvature = left - 2.0 * speed + right;
        if curvature > 0.0 {
            let shift = 0.5 * (left - right) / curvature;
            if shift.abs() <= 1.0 {
                return JumpSpeed::At {
                    speed: speed - 0.125 * (left - right) * (left - right) / curvature,
                    theta: (angle(k) + shift * TAU / n as f64).rem_euclid(TAU),
                };
            }
        }
    }
    JumpSpeed::At {
        speed,
        theta: angle(k) % TAU,
    }
}

/// One lift-off and what followed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flight {
    /// When the follower left the cam (s).
    pub t: f64,
    /// The cam angle there (rad, not wrapped).
    pub theta: f64,
    /// The follower's own velocity there (its coordinate's unit per s), if known.
    pub speed: Option<f64>,
    /// The landing: time, cam angle, approach speed (J q̇, m/s), and whether it stayed.
    pub landing: Option<Landing>,
}

/// A landing of the flying follower.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Landing {
    /// Time (s).
    pub t: f64,
    /// Cam angle (rad, not wrapped).
    pub theta: f64,
    /// The approach speed along the contact normal (m/s, positive).
    pub approach: f64,
    /// The rebound speed (m/s; 0 when it stays).
    pub rebound: f64,
    /// True when the follower stays on the cam.
    pub stays: bool,
}

/// The one-sided run over several turns at the nominal speed.
#[derive(Debug, Clone)]
pub struct OneSided {
    /// The run.
    pub trajectory: Trajectory,
    /// Its coefficient of restitution.
    pub restitution: f64,
    /// Turns run.
    pub turns: usize,
    /// The integrator's name when it is not the model's (RK4 locates no events).
    pub integrator: Option<&'static str>,
    /// The lift-offs, each with its landing.
    pub flights: Vec<Flight>,
    /// When it stays on the cam: the smallest contact force (N) with its time (s) and cam
    /// angle (rad, not wrapped).
    pub least: Option<(f64, f64, f64)>,
    /// Assembly and simulation.
    pub wall: Duration,
}

/// The one-sided run of `turns` turns at `speed` with restitution `restitution`.
pub fn one_sided(
    model: &Runnable,
    probe: &Probe,
    speed: f64,
    turns: usize,
    per_turn: usize,
    restitution: f64,
) -> Result<OneSided, String> {
    let start = Instant::now();
    let state = model
        .assemble(0.0)
        .map_err(|e| format!("assembly at {speed} rad/s failed: {e}"))?;
    let settings = settings(model.as_ref(), speed, turns, per_turn, true);
    let integrator = (model.info().defaults.integrator != settings.integrator).then_some("dop853");
    let trajectory = model
        .simulate_unilateral(state, &settings, restitution)
        .map_err(|e| format!("the one-sided run at {speed} rad/s failed: {}", e.error))?;
    let mut flights: Vec<Flight> = Vec::new();
    for event in &trajectory.events {
        if event.contact != probe.contact {
            continue;
        }
        let theta = probe.angle(speed, event.t, &event.q);
        match event.kind {
            EventKind::LiftOff => flights.push(Flight {
                t: event.t,
                theta,
                speed: probe.follower.and_then(|f| event.qd.get(f).copied()),
                landing: None,
            }),
            EventKind::Impact {
                normal_velocity,
                rebound,
                stays,
                ..
            } => {
                if let Some(flight) = flights.last_mut().filter(|f| f.landing.is_none()) {
                    flight.landing = Some(Landing {
                        t: event.t,
                        theta,
                        approach: -normal_velocity,
                        rebound,
                        stays,
                    });
                }
            }
            EventKind::ForceBecameNegative | EventKind::ForceBecamePositive => {}
        }
    }
    let least = if flights.is_empty() {
        trajectory
            .samples
            .iter()
            .filter(|s| !s.dependent.is_empty())
            .filter_map(|s| {
                let f = s.normal_force.get(probe.contact).copied()?;
                Some((f, s.t, probe.angle(speed, s.t, &s.q)))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
    } else {
        None
    };
    Ok(OneSided {
        trajectory,
        restitution,
        turns,
        integrator,
        flights,
        least,
        wall: start.elapsed(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quadratic_is_recovered_from_three_speeds() {
        let c = quadratic([1.0, 2.0, 4.0], [6.0, 3.0, -9.0]);
        // 7 + 0·w − 1·w² through (1, 6), (2, 3), (4, −9).
        assert!((c[0] - 7.0).abs() < 1e-12 && c[1].abs() < 1e-12 && (c[2] + 1.0).abs() < 1e-12);
        let root = smallest_positive_root(c).expect("a root");
        assert!((root - 7f64.sqrt()).abs() < 1e-12);
        assert_eq!(smallest_positive_root([1.0, 1.0, 1.0]), None);
    }

    #[test]
    fn the_jump_speed_is_refined_between_samples() {
        // A = 1, C = −(1 + 4 cos(θ − 1))/100: roots 10/√(1 + 4 cos(θ − 1)), least 2√5 at
        // θ = 1, which lies between the grid's angles (spacing 2π/64 ≈ 0.098 rad).
        let n = 64;
        let coefficients: Vec<[f64; 3]> = (0..=n)
            .map(|k| {
                let theta = TAU * k as f64 / n as f64;
                [1.0, 0.0, -(1.0 + 4.0 * (theta - 1.0).cos()) / 100.0]
            })
            .collect();
        let JumpSpeed::At { speed, theta } = jump_speed(&coefficients) else {
            panic!("a jump speed expected");
        };
        // The nearest sample is 3e-4 above the least; the parabola's vertex 1.8e-6 below
        // it, its angle 3.3e-5 rad off.
        let least = 2.0 * 5f64.sqrt();
        assert!((speed - least).abs() < 1e-5, "{speed}");
        assert!((theta - 1.0).abs() < 1e-4, "{theta}");
        assert!(matches!(
            jump_speed(&[[-1.0, 0.0, 1.0], [1.0, 0.0, -1.0]]),
            JumpSpeed::AtRest { force: -1.0, .. }
        ));
        assert_eq!(jump_speed(&[[1.0, 1.0, 1.0]; 3]), JumpSpeed::Never);
    }
}
