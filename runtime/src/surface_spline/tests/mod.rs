//! The surface spline against independent routes: the 1D splines it is built from, closed
//! forms, finite differences, continuity, convergence and the work it does. What input it
//! refuses is in `input.rs`.

use super::*;
use crate::spline::Spline;

mod input;

/// A xorshift64* generator: deterministic, no dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Uniform in [a, b).
    fn uniform(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in 0..n.
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// n knots from `a` with spacings drawn in [0.5, 1.5] × `mean`: an irregular grid.
fn irregular(rng: &mut Rng, n: usize, a: f64, mean: f64) -> Vec<f64> {
    let mut knots = vec![a];
    for _ in 1..n {
        let last = knots[knots.len() - 1];
        knots.push(last + mean * rng.uniform(0.5, 1.5));
    }
    knots
}

/// ∂ᵖ_x ∂ᵠ_y S out of a [`SurfacePoint`], p + q ≤ 3.
fn partial(point: &SurfacePoint, p: usize, q: usize) -> f64 {
    match (p, q) {
        (0, 0) => point.value,
        (1, 0) => point.gradient[0],
        (0, 1) => point.gradient[1],
        (2, 0) => point.hessian[0],
        (1, 1) => point.hessian[1],
        (0, 2) => point.hessian[2],
        (3, 0) => point.third[0],
        (2, 1) => point.third[1],
        (1, 2) => point.third[2],
        (0, 3) => point.third[3],
        _ => unreachable!("order above 3"),
    }
}

/// The (p, q) with p + q ≤ 3.
const ORDERS: [(usize, usize); 10] = [
    (0, 0),
    (1, 0),
    (0, 1),
    (2, 0),
    (1, 1),
    (0, 2),
    (3, 0),
    (2, 1),
    (1, 2),
    (0, 3),
];

/// Abscissas to evaluate an axis at: every knot, every cell's midpoint and two random
/// points in it, points beyond both ends (up to 1.5 cells), and, on a periodic axis, points
/// a period or two away.
fn probes(rng: &mut Rng, knots: &[f64], periodic: bool) -> Vec<f64> {
    let n = knots.len();
    let (first, last) = (knots[0], knots[n - 1]);
    let mut s = knots.to_vec();
    for w in knots.windows(2) {
        s.push(0.5 * (w[0] + w[1]));
        s.push(rng.uniform(w[0], w[1]));
        s.push(rng.uniform(w[0], w[1]));
    }
    let (h0, h1) = (knots[1] - first, last - knots[n - 2]);
    s.extend([
        first - 1.5 * h0,
        first - 0.3 * h0,
        last + 0.4 * h1,
        last + 1.5 * h1,
    ]);
    if periodic {
        let period = last - first;
        s.extend([
            first - period + 0.37 * h0,
            last + period - 0.61 * h1,
            last + 2.0 * period,
        ]);
    }
    s
}

/// Smallest spacing of the knots.
fn least_spacing(knots: &[f64]) -> f64 {
    knots
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min)
}

/// Largest magnitude in a slice.
fn largest(values: &[f64]) -> f64 {
    values.iter().fold(0.0f64, |a, v| a.max(v.abs()))
}

/// Random values on a grid, closed exactly along a periodic axis.
fn random_grid(rng: &mut Rng, nx: usize, ny: usize, ends: [Ends; 2]) -> Vec<f64> {
    let mut z: Vec<f64> = (0..nx * ny).map(|_| rng.uniform(-1.0, 1.0)).collect();
    close(&mut z, nx, ny, ends);
    z
}

/// Makes a periodic axis's last line repeat its first exactly.
fn close(z: &mut [f64], nx: usize, ny: usize, ends: [Ends; 2]) {
    if ends[0] == Ends::Periodic {
        for j in 0..ny {
            z[(nx - 1) * ny + j] = z[j];
        }
    }
    if ends[1] == Ends::Periodic {
        for i in 0..nx {
            z[i * ny + ny - 1] = z[i * ny];
        }
    }
}

/// A one-dimensional table closed when periodic.
fn line(rng: &mut Rng, n: usize, ends: Ends) -> Vec<f64> {
    let mut v: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
    if ends == Ends::Periodic {
        v[n - 1] = v[0];
    }
    v
}

const NATURAL: Ends = Ends::Natural;
const PERIODIC: Ends = Ends::Periodic;
const CLAMPED: Ends = Ends::Clamped {
    start: 0.7,
    end: -0.4,
};
const CLAMPED_Y: Ends = Ends::Clamped {
    start: -1.2,
    end: 0.3,
};

/// The scale of the p-th derivative of a spline through values of magnitude `size` on knots
/// at least `h` apart: size / hᵖ. The 1D evaluation sums terms of that size (the values
/// divided by the spacing p times), so its rounding is a few ulps of it, whatever the
/// derivative's own size (which cancellation can make small).
fn scale(size: f64, h: f64, p: usize) -> f64 {
    size / h.powi(p as i32)
}

#[test]
fn a_product_grid_gives_the_product_of_its_splines() {
    // z_ij = g_i k_j: every line along x is a multiple of g, so M^x_ij = k_j G''(x_i), and
    // likewise along y; the surface is then G(x)·K(y) exactly, and so is every derivative,
    // ∂ᵖ_x ∂ᵠ_y S = G⁽ᵖ⁾(x) K⁽ᵠ⁾(y), in cells, at knots, beyond open ends and periods away.
    // Tolerance: each side rounds to a few ulps of the scale of its terms (see `scale`)
    // after O(10) operations and a diagonally dominant solve (condition ≤ 3): 1e-12 of
    // the product of the two axes' scales leaves a margin of 100 over the worst seen.
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for ends in [
        [NATURAL, NATURAL],
        [NATURAL, PERIODIC],
        [PERIODIC, NATURAL],
        [PERIODIC, PERIODIC],
    ] {
        let (nx, ny) = (9, 7);
        let x = irregular(&mut rng, nx, -0.7, 0.4);
        let y = irregular(&mut rng, ny, 1.3, 0.3);
        let (g, k) = (line(&mut rng, nx, ends[0]), line(&mut rng, ny, ends[1]));
        let z: Vec<f64> = g
            .iter()
            .flat_map(|gi| k.iter().map(move |kj| gi * kj))
            .collect();
        let surface = SurfaceSpline::new(&x, &y, &z, ends).unwrap();
        let (big_g, big_k) = (
            Spline::new(&x, &g, ends[0]).unwrap(),
            Spline::new(&y, &k, ends[1]).unwrap(),
        );
        let (hx, hy) = (least_spacing(&x), least_spacing(&y));
        let xs = probes(&mut rng, &x, ends[0] == PERIODIC);
        let ys = probes(&mut rng, &y, ends[1] == PERIODIC);
        for &a in &xs {
            for &b in &ys {
                let (got, gx, ky) = (surface.eval(a, b), big_g.eval(a), big_k.eval(b));
                for (p, q) in ORDERS {
                    let want = gx[p] * ky[q];
                    let tolerance = 1e-12 * scale(2.0, hx, p) * scale(2.0, hy, q);
                    let error = (partial(&got, p, q) - want).abs();
                    assert!(
                        error < tolerance,
                        "{ends:?} ∂{p},{q} at ({a}, {b}): {} vs {want}",
                        partial(&got, p, q)
                    );
                }
            }
        }
    }
}

#[test]
fn a_sum_grid_gives_the_sum_of_its_splines() {
    // z_ij = g_i + k_j: M^x_ij = G''(x_i) on every line, M^y_ij = K''(y_j), and M^x is
    // constant along y, so M^xy = 0 and S = G(x) + K(y): every mixed derivative vanishes.
    // With clamped ends this is also the clamped surface, G and K having constant slopes
    // across the edges. Tolerance as for the product.
    let mut rng = Rng(0x51ed_270b_3d1f_0a93);
    let kinds = [NATURAL, PERIODIC, CLAMPED];
    for ex in kinds {
        for ey in [NATURAL, PERIODIC, CLAMPED_Y] {
            let ends = [ex, ey];
            let (nx, ny) = (6, 8);
            let x = irregular(&mut rng, nx, 0.2, 0.5);
            let y = irregular(&mut rng, ny, -2.0, 0.35);
            let (g, k) = (line(&mut rng, nx, ex), line(&mut rng, ny, ey));
            let z: Vec<f64> = g
                .iter()
                .flat_map(|gi| k.iter().map(move |kj| gi + kj))
                .collect();
            let surface = SurfaceSpline::new(&x, &y, &z, ends).unwrap();
            let (big_g, big_k) = (
                Spline::new(&x, &g, ex).unwrap(),
                Spline::new(&y, &k, ey).unwrap(),
            );
            let (hx, hy) = (least_spacing(&x), least_spacing(&y));
            let xs = probes(&mut rng, &x, ex == PERIODIC);
            let ys = probes(&mut rng, &y, ey == PERIODIC);
            for &a in &xs {
                for &b in &ys {
                    let (got, gx, ky) = (surface.eval(a, b), big_g.eval(a), big_k.eval(b));
                    for (p, q) in ORDERS {
                        let want = match (p, q) {
                            (0, 0) => gx[0] + ky[0],
                            (p, 0) => gx[p],
                            (0, q) => ky[q],
                            _ => 0.0,
                        };
                        let tolerance = 1e-12 * scale(2.0, hx, p) * scale(2.0, hy, q);
                        let error = (partial(&got, p, q) - want).abs();
                        assert!(error < tolerance, "{ends:?} ∂{p},{q} at ({a}, {b})");
                    }
                }
            }
        }
    }
}

#[test]
fn bilinear_functions_are_reproduced_exactly() {
    // f = a + bx + cy + dxy is linear along every grid line, and a natural spline through
    // points on a line is that line (S'' = 0 satisfies every equation of the solve), so
    // M^x = M^y = 0, hence M^xy = 0, and each cell is the bilinear interpolation of its
    // corners, which is f itself; beyond the ends the cells' polynomials continue f. The
    // solves see slopes equal up to rounding, so the curvatures are zero to ~1e-15, and
    // the values and derivatives agree to 1e-12 of the scale of their order (see `scale`;
    // the third derivatives are such rounding divided by h³; worst seen 1.2e-15 of it).
    let (a, b, c, d) = (1.5, -0.8, 2.25, 0.6);
    let f = |x: f64, y: f64| a + b * x + c * y + d * x * y;
    let mut rng = Rng(7);
    let x = irregular(&mut rng, 7, -1.0, 0.6);
    let y = irregular(&mut rng, 5, 0.5, 0.8);
    let z: Vec<f64> = x
        .iter()
        .flat_map(|&u| y.iter().map(move |&v| f(u, v)))
        .collect();
    let surface = SurfaceSpline::new(&x, &y, &z, [NATURAL, NATURAL]).unwrap();
    let (size, h) = (largest(&z), least_spacing(&x).min(least_spacing(&y)));
    let (xs, ys) = (probes(&mut rng, &x, false), probes(&mut rng, &y, false));
    for &u in &xs {
        for &v in &ys {
            let got = surface.eval(u, v);
            let want = [
                f(u, v),
                b + d * v,
                c + d * u,
                0.0,
                d,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
            ];
            for ((p, q), w) in ORDERS.into_iter().zip(want) {
                let error = (partial(&got, p, q) - w).abs();
                let tolerance = 1e-12 * scale(size, h, p + q);
                assert!(error < tolerance, "∂{p},{q} at ({u}, {v}): {error:e}");
            }
        }
    }
}

#[test]
fn derivatives_agree_with_central_differences() {
    // Each derivative of order k ≥ 1 against the central difference, with step δ = 1e-6,
    // of the order below it in x or in y, at random points at least 10% of a cell from its
    // edges (δ stays inside the cell, where S is a polynomial). S is cubic in each variable,
    // so the difference's truncation is δ²/6 times a derivative two orders up, C/h² times
    // the derivative's scale 1/hᵏ (C ≲ 100 for random values, h ≥ 0.1): ≲ 2e-9 of it; its
    // rounding is ~1e-16 of the lower order's scale over δ, ~1e-11·C of the derivative's.
    // The worst seen is 5e-10 of the scale (1e-5 would make the truncation 2e-8): 1e-7
    // leaves a margin of 200.
    let delta = 1e-6;
    let mut rng = Rng(0xdead_beef);
    for ends in [
        [NATURAL, PERIODIC],
        [CLAMPED, NATURAL],
        [PERIODIC, CLAMPED_Y],
    ] {
        let (nx, ny) = (8, 9);
        let x = irregular(&mut rng, nx, 0.0, 0.25);
        let y = irregular(&mut rng, ny, 0.0, 0.2);
        let z = random_grid(&mut rng, nx, ny, ends);
        let surface = SurfaceSpline::new(&x, &y, &z, ends).unwrap();
        let h = least_spacing(&x).min(least_spacing(&y));
        for _ in 0..300 {
            let (i, j) = (rng.below(nx - 1), rng.below(ny - 1));
            let u = x[i] + (x[i + 1] - x[i]) * rng.uniform(0.1, 0.9);
            let v = y[j] + (y[j + 1] - y[j]) * rng.uniform(0.1, 0.9);
            let got = surface.eval(u, v);
            for (p, q) in ORDERS.into_iter().skip(1) {
                // Difference in x from (p − 1, q) when p > 0, else in y from (0, q − 1).
                let (lower, minus, plus) = if p > 0 {
                    (
                        (p - 1, q),
                        surface.eval(u - delta, v),
                        surface.eval(u + delta, v),
                    )
                } else {
                    (
                        (p, q - 1),
                        surface.eval(u, v - delta),
                        surface.eval(u, v + delta),
                    )
                };
                let difference = (partial(&plus, lower.0, lower.1)
                    - partial(&minus, lower.0, lower.1))
                    / (2.0 * delta);
                let error = (partial(&got, p, q) - difference).abs();
                assert!(
                    error < 1e-7 * scale(1.0, h, p + q),
                    "{ends:?} ∂{p},{q} at ({u}, {v}): {} vs {difference}",
                    partial(&got, p, q)
                );
            }
        }
    }
}

#[test]
fn value_gradient_and_hessian_are_continuous_across_knot_lines() {
    // The polynomials of the two cells beside an interior knot line (and, on a periodic
    // axis, of the first and last cells across the seam) evaluated on the line, at its
    // knots and at random points between them: S, its gradient and its Hessian agree to
    // rounding (1e-12 of their scales, as for the product). The third derivatives across
    // the line are checked to differ somewhere, so that two different cells are compared.
    let mut rng = Rng(0x1234_5678_9abc_def1);
    for ends in [
        [NATURAL, NATURAL],
        [PERIODIC, CLAMPED_Y],
        [CLAMPED, PERIODIC],
        [PERIODIC, PERIODIC],
    ] {
        let (nx, ny) = (7, 6);
        let x = irregular(&mut rng, nx, 0.0, 0.3);
        let y = irregular(&mut rng, ny, 0.0, 0.4);
        let z = random_grid(&mut rng, nx, ny, ends);
        let surface = SurfaceSpline::new(&x, &y, &z, ends).unwrap();
        let t = surface.table();
        let h = least_spacing(&x).min(least_spacing(&y));
        let mut third_jumps = 0.0f64;
        let mut compare = |left: [[f64; 4]; 4], right: [[f64; 4]; 4], at: String| {
            for (p, q) in ORDERS {
                let (l, r) = (left[p][q], right[p][q]);
                if p + q <= 2 {
                    let tolerance = 1e-12 * scale(2.0, h, p + q);
                    assert!(
                        (l - r).abs() < tolerance,
                        "{ends:?} ∂{p},{q} at {at}: {l} vs {r}"
                    );
                } else {
                    third_jumps = third_jumps.max((l - r).abs());
                }
            }
        };
        // Knot lines x = x_i: cells i − 1 and i, or the seam (the last cell at x_{nx−1},
        // the first at x₀).
        let mut x_lines: Vec<(usize, f64, usize, f64)> =
            (1..nx - 1).map(|i| (i - 1, x[i], i, x[i])).collect();
        if ends[0] == PERIODIC {
            x_lines.push((nx - 2, x[nx - 1], 0, x[0]));
        }
        for &(left, at_left, right, at_right) in &x_lines {
            for j in 0..ny - 1 {
                for v in [y[j], rng.uniform(y[j], y[j + 1]), y[j + 1]] {
                    compare(
                        cell(&t, left, j, at_left, v),
                        cell(&t, right, j, at_right, v),
                        format!("x = {at_right}, y = {v}"),
                    );
                }
            }
        }
        let mut y_lines: Vec<(usize, f64, usize, f64)> =
            (1..ny - 1).map(|j| (j - 1, y[j], j, y[j])).collect();
        if ends[1] == PERIODIC {
            y_lines.push((ny - 2, y[ny - 1], 0, y[0]));
        }
        for &(below, at_below, above, at_above) in &y_lines {
            for i in 0..nx - 1 {
                for u in [x[i], rng.uniform(x[i], x[i + 1]), x[i + 1]] {
                    compare(
                        cell(&t, i, below, u, at_below),
                        cell(&t, i, above, u, at_above),
                        format!("x = {u}, y = {at_above}"),
                    );
                }
            }
        }
        assert!(
            third_jumps > 1e-3,
            "{ends:?}: the third derivatives never jump"
        );
    }
}

#[test]
fn the_surface_passes_through_every_point() {
    // S(x_i, y_j) = z_ij on irregular grids of random values for every pair of ends: the
    // cubic's curvature weights vanish at the knots, leaving the value up to rounding of
    // terms of the values' size (below 1e-14 seen; 1e-12).
    let mut rng = Rng(42);
    for ex in [NATURAL, PERIODIC, CLAMPED] {
        for ey in [NATURAL, PERIODIC, CLAMPED_Y] {
            let ends = [ex, ey];
            let (nx, ny) = (11, 13);
            let x = irregular(&mut rng, nx, -3.0, 0.5);
            let y = irregular(&mut rng, ny, 2.0, 0.1);
            let z = random_grid(&mut rng, nx, ny, ends);
            let surface = SurfaceSpline::new(&x, &y, &z, ends).unwrap();
            for i in 0..nx {
                for j in 0..ny {
                    let got = surface.eval(x[i], y[j]).value;
                    let want = z[i * ny + j];
                    assert!(
                        (got - want).abs() < 1e-12,
                        "{ends:?} z[{i}][{j}]: {got} vs {want}"
                    );
                }
            }
        }
    }
}

#[test]
fn each_axis_meets_its_end_conditions_along_the_whole_edge() {
    // Natural: S_xx = 0 on x = x₀ and x = x_last at every y, not only at the knots (and S_yy
    // on the y edges). Clamped: S_x is the given constant along the whole edge and the twist
    // S_xy is zero there, as the module's documentation derives. 1e-12 of the scales.
    let mut rng = Rng(99);
    for ends in [
        [NATURAL, CLAMPED_Y],
        [CLAMPED, NATURAL],
        [CLAMPED, CLAMPED_Y],
    ] {
        let (nx, ny) = (6, 7);
        let x = irregular(&mut rng, nx, 1.0, 0.3);
        let y = irregular(&mut rng, ny, 0.0, 0.25);
        let z = random_grid(&mut rng, nx, ny, ends);
        let surface = SurfaceSpline::new(&x, &y, &z, ends).unwrap();
        let h = least_spacing(&x).min(least_spacing(&y));
        let check = |point: SurfacePoint, axis: usize, edge: usize, at: String| {
            let (normal, second) = (point.gradient[axis], point.hessian[2 * axis]);
            match ends[axis] {
                Ends::Natural => {
                    assert!(second.abs() < 1e-12 * scale(2.0, h, 2), "{at}: {second}")
                }
                Ends::Clamped { start, end } => {
                    let want = [start, end][edge];
                    assert!(
                        (normal - want).abs() < 1e-12 * scale(2.0, h, 1),
                        "{at}: {normal}"
                    );
                    let twist = point.hessian[1];
                    assert!(
                        twist.abs() < 1e-12 * scale(2.0, h, 2),
                        "{at}: twist {twist}"
                    );
                }
                Ends::Periodic => unreachable!(),
            }
        };
        for v in probes(&mut rng, &y, false) {
            for (edge, u) in [x[0], x[nx - 1]].into_iter().enumerate() {
                check(
                    surface.eval(u, v),
                    0,
                    edge,
                    format!("{ends:?} x edge {edge}, y = {v}"),
                );
            }
        }
        for u in probes(&mut rng, &x, false) {
            for (edge, v) in [y[0], y[ny - 1]].into_iter().enumerate() {
                check(
                    surface.eval(u, v),
                    1,
                    edge,
                    format!("{ends:?} y edge {edge}, x = {u}"),
                );
            }
        }
    }
}

#[test]
fn the_cross_curvatures_are_the_same_along_either_axis() {
    // M^xy is solved along y from M^x; the module's proof needs it to equal the solve along
    // x from M^y (each axis's curvatures' ends homogeneous). Computed here by that other
    // route with the 1D solve directly; the two differ by rounding in two solves of
    // condition ≤ 3 on curvatures of scale 1/h⁴: 1e-12 of it.
    let mut rng = Rng(2024);
    for ex in [NATURAL, PERIODIC, CLAMPED] {
        for ey in [NATURAL, PERIODIC, CLAMPED_Y] {
            let ends = [ex, ey];
            let (nx, ny) = (7, 9);
            let x = irregular(&mut rng, nx, 0.0, 0.3);
            let y = irregular(&mut rng, ny, 0.0, 0.2);
            let z = random_grid(&mut rng, nx, ny, ends);
            let surface = SurfaceSpline::new(&x, &y, &z, ends).unwrap();
            let my = surface.knot_curvatures_y();
            let h = least_spacing(&x).min(least_spacing(&y));
            for j in 0..ny {
                let column: Vec<f64> = (0..nx).map(|i| my[i * ny + j]).collect();
                let other = spline::second_derivatives(&x, &column, curvature_ends(ex)).unwrap();
                for (i, theirs) in other.into_iter().enumerate() {
                    let mxy = surface.knot_cross_curvatures()[i * ny + j];
                    assert!(
                        (mxy - theirs).abs() < 1e-12 * scale(2.0, h, 4),
                        "{ends:?} [{i}][{j}]: {mxy} vs {theirs}"
                    );
                }
            }
        }
    }
}

#[test]
fn construction_solves_each_grid_line_a_bounded_number_of_times() {
    // O(n) construction, by counting rather than timing: on a 200 × 200 grid (and a 200 ×
    // 150 one) every one-dimensional solve is handed exactly one grid line, ny lines along
    // x (on the x knots, nx values each) and 2·nx along y (M^y, then M^xy from M^x), so
    // 3·nx·ny unknowns in all: each grid point is solved for three times. Each solve is
    // spline.rs's Thomas algorithm (or Sherman–Morrison, two Thomas passes), linear in its
    // length, and the rest of the construction is a fixed number of passes over the grid
    // (the checks, the copy, gathering and scattering lines). The counted construction is
    // the one `new` runs: the tables are compared bit for bit.
    for (nx, ny, ends) in [
        (200, 200, [PERIODIC, NATURAL]),
        (200, 150, [NATURAL, CLAMPED_Y]),
    ] {
        let mut rng = Rng(5 + nx as u64 * ny as u64);
        let x = irregular(&mut rng, nx, 0.0, 0.01);
        let y = irregular(&mut rng, ny, 0.0, 0.02);
        let z = random_grid(&mut rng, nx, ny, ends);
        // (along x, number of values) of every solve, the axis told by the knots handed.
        let mut solves: Vec<(bool, usize)> = Vec::new();
        let mut counting = |knots: &[f64], values: &[f64], e: Ends| {
            solves.push((std::ptr::eq(knots, x.as_slice()), values.len()));
            spline::second_derivatives(knots, values, e)
        };
        let counted = build(&x, &y, &z, ends, &mut counting).unwrap();
        assert_eq!(counted, SurfaceSpline::new(&x, &y, &z, ends).unwrap());
        let along_x: Vec<usize> = solves.iter().filter(|s| s.0).map(|s| s.1).collect();
        let along_y: Vec<usize> = solves.iter().filter(|s| !s.0).map(|s| s.1).collect();
        assert_eq!(along_x, vec![nx; ny]);
        assert_eq!(along_y, vec![ny; 2 * nx]);
        assert_eq!(solves.iter().map(|s| s.1).sum::<usize>(), 3 * nx * ny);
    }
}

/// The largest error of the surface through f sampled on an n × n grid over [a, b]², at
/// 201 × 201 points of [c, d]².
fn sampling_error(
    f: impl Fn(f64, f64) -> f64,
    n: usize,
    (a, b): (f64, f64),
    (c, d): (f64, f64),
    ends: Ends,
) -> f64 {
    let knots: Vec<f64> = (0..n)
        .map(|k| a + (b - a) * k as f64 / (n - 1) as f64)
        .collect();
    let mut z: Vec<f64> = knots
        .iter()
        .flat_map(|&u| knots.iter().map(move |&v| (u, v)))
        .map(|(u, v)| f(u, v))
        .collect();
    close(&mut z, n, n, [ends, ends]);
    let surface = SurfaceSpline::new(&knots, &knots, &z, [ends, ends]).unwrap();
    let at = |k: usize| c + (d - c) * k as f64 / 200.0;
    (0..=200)
        .flat_map(|k| (0..=200).map(move |l| (at(k), at(l))))
        .map(|(u, v)| (surface.eval(u, v).value - f(u, v)).abs())
        .fold(0.0, f64::max)
}

#[test]
fn sampling_a_smooth_function_converges_at_fourth_order() {
    // sin x cos y sampled with spacings h and h/2: the error falls as h⁴ (16×) where the
    // ends do not matter. Natural ends are wrong for it (S_xx = −sin x cos y ≠ 0 on the
    // edges): an O(h²) error at the edges that decays by 2 − √3 ≈ 0.27 a cell inwards; on
    // [0, 4]² with 40 and 80 cells, the middle [1, 3]² is 10 cells or more from the edges,
    // where that is below 1e-8 against an h⁴ error of ~1e-6. Periodic ends on [0, 2π]²
    // are exact for it, and the whole square (and beyond it) converges at fourth order.
    // Ratios measured: 17.3 (natural, interior) and 16.0 (periodic).
    let f = |x: f64, y: f64| x.sin() * y.cos();
    let tau = std::f64::consts::TAU;
    for (ends, grid, probed) in [
        (NATURAL, (0.0, 4.0), (1.0, 3.0)),
        (PERIODIC, (0.0, tau), (-1.0, tau + 1.0)),
    ] {
        let coarse = sampling_error(f, 41, grid, probed, ends);
        let fine = sampling_error(f, 81, grid, probed, ends);
        let ratio = coarse / fine;
        assert!(
            ratio >= 12.0,
            "{ends:?}: {coarse:.3e} / {fine:.3e} = {ratio:.1}"
        );
    }
}
