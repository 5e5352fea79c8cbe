//! The reference's own route to a surface given on a grid (`camchain_model::profile::Gridded`).
//!
//! The runtime (`camchain_runtime::surface_spline`) builds three tables of knot derivatives
//! (∂²S/∂x², ∂²S/∂y², ∂⁴S/∂x²∂y²) once and evaluates the tensor-product cubic of the cell
//! holding the point. The reference uses instead the property that defines the C² bicubic
//! spline: along every line y = y_j it is the one-dimensional spline in x through that line's
//! values, and along every line x = const the one-dimensional spline in y through its values
//! at the knots y_j. So at (x, y):
//!
//! 1. each line along x, j = 0 … ny − 1, gives u_j^(p) = ∂ᵖ/∂xᵖ of its spline at x, p ≤ 3
//!    (the lines are built once, in the reference's Hermite form, [`crate::spline`]);
//! 2. for each p, the spline in y through (y_j, u_j^(p)) gives ∂ᵖ_x ∂ᵠ_y S at y, q ≤ 3,
//!    solved afresh at every evaluation.
//!
//! Step 2 takes the y axis's ends for p = 0 and the same ends made homogeneous for p ≥ 1
//! (clamped slopes replaced by zero): a clamped edge's slope is the same at every x, so its
//! x-derivatives vanish. The evaluation costs O(ny) solves and look-ups, against the
//! runtime's O(log n); agreement of the two checks the runtime's tables, its cells and the
//! generated code's constants at once. Derivatives beyond the third in either variable are
//! zero on both routes (the spline is cubic in each inside a cell).

use crate::spline::Hermite;
use camchain_model::profile::Gridded;
use camchain_runtime::spline::Ends;
use std::cell::RefCell;
use std::sync::Arc;

/// ∂ᵖ_x ∂ᵠ_y (`order` = (p, q)) of `g` at (x, y), by the reference's route.
///
/// A tape reads one surface at one point in several orders: the last evaluation is kept.
pub fn derivative(g: &Arc<Gridded>, (p, q): (u8, u8), x: f64, y: f64) -> f64 {
    if p > 3 || q > 3 {
        return 0.0;
    }
    let key = (x.to_bits(), y.to_bits());
    let cached = LAST.with(|last| {
        last.borrow()
            .as_ref()
            .filter(|(h, at, _)| Arc::ptr_eq(h, g) && *at == key)
            .map(|(_, _, d)| *d)
    });
    let d = cached.unwrap_or_else(|| {
        let d = with_lines(g, |lines| partials(g, lines, x, y));
        LAST.with(|last| *last.borrow_mut() = Some((g.clone(), key, d)));
        d
    });
    d[usize::from(p)][usize::from(q)]
}

/// Steps 1 and 2 of the module's route.
fn partials(g: &Gridded, lines: &[Hermite], x: f64, y: f64) -> [[f64; 4]; 4] {
    let along_x: Vec<[f64; 4]> = lines.iter().map(|line| line.eval(x)).collect();
    let y_knots = g.spline.y_knots();
    let ends = g.spline.ends()[1];
    std::array::from_fn(|p| {
        let values: Vec<f64> = along_x.iter().map(|u| u[p]).collect();
        let ends = match (p, ends) {
            (1.., Ends::Clamped { .. }) => Ends::Clamped {
                start: 0.0,
                end: 0.0,
            },
            _ => ends,
        };
        Hermite::through(y_knots, &values, ends).eval(y)
    })
}

/// The lines along x of `g`'s grid (line j: the values at (x_i, y_j), i = 0 … nx − 1) in
/// Hermite form with the x axis's ends.
fn lines_of(g: &Gridded) -> Vec<Hermite> {
    let (nx, ny) = g.spline.shape();
    let (x, z) = (g.spline.x_knots(), g.spline.values());
    let ends = g.spline.ends()[0];
    (0..ny)
        .map(|j| {
            let line: Vec<f64> = (0..nx).map(|i| z[i * ny + j]).collect();
            Hermite::through(x, &line, ends)
        })
        .collect()
}

/// A surface, an argument's bits and the sixteen partial derivatives there.
type LastEvaluation = (Arc<Gridded>, (u64, u64), [[f64; 4]; 4]);

/// A surface with its lines along x, built once.
type Built = (Arc<Gridded>, Arc<Vec<Hermite>>);

/// Most surfaces kept per thread; the cache starts again beyond it.
const CACHED: usize = 16;

thread_local! {
    static LAST: RefCell<Option<LastEvaluation>> = const { RefCell::new(None) };
    static BUILT: RefCell<Vec<Built>> = const { RefCell::new(Vec::new()) };
}

/// Runs `f` on `g`'s lines along x, built on first use and kept with the surface itself.
fn with_lines<T>(g: &Arc<Gridded>, f: impl FnOnce(&[Hermite]) -> T) -> T {
    let found = BUILT.with(|built| {
        built
            .borrow()
            .iter()
            .find(|(h, _)| Arc::ptr_eq(h, g))
            .map(|(_, lines)| lines.clone())
    });
    let lines = found.unwrap_or_else(|| {
        let lines = Arc::new(lines_of(g));
        BUILT.with(|built| {
            let mut built = built.borrow_mut();
            if built.len() >= CACHED {
                built.clear();
            }
            built.push((g.clone(), lines.clone()));
        });
        lines
    });
    f(&lines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use camchain_runtime::surface_spline::SurfaceSpline;

    /// A grid of values of a smooth function that no bicubic reproduces.
    fn grid(ends: [Ends; 2]) -> Arc<Gridded> {
        let x: Vec<f64> = (0..7)
            .map(|i| -0.3 + 0.1 * f64::from(i) + 0.01 * f64::from(i * i))
            .collect();
        let y: Vec<f64> = (0..6).map(|j| 0.2 * f64::from(j)).collect();
        let mut z = Vec::new();
        for &xi in &x {
            for &yj in &y {
                z.push((2.0 * xi).sin() * (1.0 + yj * yj) + 0.3 * xi * yj);
            }
        }
        if ends[1] == Ends::Periodic {
            let ny = y.len();
            for i in 0..x.len() {
                z[i * ny + ny - 1] = z[i * ny];
            }
        }
        if ends[0] == Ends::Periodic {
            let (nx, ny) = (x.len(), y.len());
            for j in 0..ny {
                z[(nx - 1) * ny + j] = z[j];
            }
        }
        Gridded::new(
            "g",
            SurfaceSpline::new(&x, &y, &z, ends).expect("a valid grid"),
        )
    }

    /// The two routes agree on every partial derivative, inside cells, on knot lines and
    /// beyond the grid, for each kind of ends. Tolerance: both evaluate cubics of values of
    /// order 1 with knot spacings of 0.1–0.2, so the third derivatives are of order 10³ and
    /// the solves lose a few ulps each; 1e-9 of the largest derivative of each order leaves a
    /// margin of 10⁴ over the differences seen, and a wrong table errs at O(1).
    #[test]
    fn the_reference_route_agrees_with_the_runtime_tables() {
        let clamped = Ends::Clamped {
            start: 0.4,
            end: -0.2,
        };
        for ends in [
            [Ends::Natural, Ends::Natural],
            [clamped, Ends::Natural],
            [Ends::Natural, clamped],
            [Ends::Periodic, Ends::Periodic],
            [clamped, Ends::Periodic],
        ] {
            let g = grid(ends);
            for &(x, y) in &[
                (0.05, 0.33),
                (0.1, 0.4),
                (-0.35, 1.1),
                (0.61, -0.05),
                (0.2, 0.2),
            ] {
                let runtime = camchain_runtime::surface_spline::partials(&g.spline.table(), x, y);
                for p in 0..4u8 {
                    for q in 0..4u8 {
                        let ours = derivative(&g, (p, q), x, y);
                        let theirs = runtime[usize::from(p)][usize::from(q)];
                        let scale = 10f64.powi(i32::from(p + q)).max(1.0);
                        assert!(
                            (ours - theirs).abs() <= 1e-9 * scale,
                            "{ends:?} at ({x}, {y}): ∂{p}{q} {ours} against {theirs}"
                        );
                    }
                }
            }
            assert_eq!(derivative(&g, (4, 0), 0.1, 0.1), 0.0);
        }
    }
}
