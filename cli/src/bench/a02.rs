//! IFToMM A02 (`n_four_bar`, N = 40) against its exact one-degree-of-freedom reduction: the
//! largest distance of the point B0 from the exact one over a run's samples.
//!
//! Every crank keeps the first crank's angle θ and every coupler translates, so the linkage
//! is a pendulum of inertia I = (N + 1)/3 + N (kg m², links of 1 m and 1 kg) and first moment
//! M r = (N + 1)/2 + N (kg m) about the first pivot: I θ̈ = −g M r cos θ, and by energy
//! θ̇² = ω0² + (2 g M r / I)(sin θ0 − sin θ), never zero from θ0 = π/2, ω0 = −1 rad/s. The
//! time to reach θ is t(θ) = ∫_θ^θ0 dφ / |θ̇(φ)|, by 16-point Gauss–Legendre quadrature on
//! pieces of at most 0.1 rad (the integrand is analytic, its nearest singularities ~0.3 rad
//! off the real axis: the quadrature's error is far below 1e-15 s), inverted by Newton at
//! every sample time. Nothing of camchain computes it.

use camchain_runtime::Trajectory;

/// The largest |B0 − B0_exact| of a run of `n_four_bar` (N = 40) over its samples, and
/// its time.
pub fn largest_error(run: &Trajectory) -> (f64, f64) {
    let exact = Reduction::new(40);
    let times: Vec<f64> = run.samples.iter().map(|s| s.t).collect();
    let angles = exact.angles(&times);
    let mut worst = (0.0_f64, 0.0);
    for (sample, theta) in run.samples.iter().zip(angles) {
        let a = sample.q[0];
        let distance = (a.cos() - theta.cos()).hypot(a.sin() - theta.sin());
        if distance > worst.0 {
            worst = (distance, sample.t);
        }
    }
    worst
}

/// The exact reduction of an N-four-bar started vertical at −1 rad/s.
struct Reduction {
    /// 2 g M r / I.
    c: f64,
    nodes: Vec<(f64, f64)>,
}

const THETA0: f64 = std::f64::consts::FRAC_PI_2;

impl Reduction {
    fn new(n: usize) -> Self {
        let (cranks, couplers) = ((n + 1) as f64, n as f64);
        let inertia = cranks / 3.0 + couplers;
        let moment = cranks / 2.0 + couplers;
        Self {
            c: 2.0 * 9.81 * moment / inertia,
            nodes: gauss_legendre(16),
        }
    }

    /// |θ̇| at θ.
    fn rate(&self, theta: f64) -> f64 {
        (1.0 + self.c * (THETA0.sin() - theta.sin())).sqrt()
    }

    /// ∫_a^b dφ / |θ̇(φ)|, a ≤ b.
    fn time(&self, a: f64, b: f64) -> f64 {
        let pieces = ((b - a) / 0.1).ceil().max(1.0);
        let h = (b - a) / pieces;
        let mut sum = 0.0;
        for p in 0..pieces as usize {
            let middle = a + (p as f64 + 0.5) * h;
            for &(x, w) in &self.nodes {
                sum += w * 0.5 * h / self.rate(middle + 0.5 * h * x);
            }
        }
        sum
    }

    /// θ at the increasing `times` (from 0): θ decreases, t(θ) inverted by Newton from the
    /// last angle.
    fn angles(&self, times: &[f64]) -> Vec<f64> {
        let (mut theta, mut t) = (THETA0, 0.0);
        let mut out = Vec::with_capacity(times.len());
        for &target in times {
            let dt = target - t;
            let mut next = theta - dt * self.rate(theta);
            for _ in 0..50 {
                let elapsed = if next < theta {
                    self.time(next, theta)
                } else {
                    -self.time(theta, next)
                };
                let step = (elapsed - dt) * self.rate(next);
                next += step;
                if step.abs() < 1e-15 {
                    break;
                }
            }
            (theta, t) = (next, target);
            out.push(theta);
        }
        out
    }
}

/// Nodes and weights of n-point Gauss–Legendre quadrature on [−1, 1] (Newton on P_n).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut derivative = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let k = k as f64;
                    (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
                }
                derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let step = p1 / derivative;
                x -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * derivative * derivative))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quadrature_integrates_polynomials_and_the_reduction_its_own_ode() {
        // 16 points integrate degree 31 exactly: x^30 over [−1, 1] is 2/31.
        let sum: f64 = gauss_legendre(16).iter().map(|(x, w)| w * x.powi(30)).sum();
        assert!((sum - 2.0 / 31.0).abs() < 1e-14);
        // θ(t) satisfies θ̈ = −(c/2) cos θ: a central second difference at t = 1.3 s,
        // h = 1e-3 (truncation ~h² θ⁗/12 ~ 1e-6 relative to ~100 rad/s⁴).
        let exact = Reduction::new(40);
        let h = 1e-3;
        let theta = exact.angles(&[1.3 - h, 1.3, 1.3 + h]);
        let second = (theta[2] - 2.0 * theta[1] + theta[0]) / (h * h);
        let ode = -0.5 * exact.c * theta[1].cos();
        assert!((second - ode).abs() < 1e-4 * (1.0 + ode.abs()));
    }
}
