//! What the surface spline refuses and how: bad grids named by their cell, nearly closed
//! periodic grids, slices that are not a grid, and random hostile grids.

use super::*;

#[test]
fn bad_grids_are_refused_with_the_cell() {
    let x = [0.0, 1.0, 2.0, 3.0];
    let y = [0.0, 0.5, 1.0, 2.0, 2.5];
    let e = |x: &[f64], y: &[f64], z: &[f64], ends| SurfaceSpline::new(x, y, z, ends).unwrap_err();
    let zeros = vec![0.0; 20];
    assert_eq!(
        e(&x, &y, &zeros[..19], [NATURAL; 2]).to_string(),
        "a 4 × 5 grid needs 20 values, the table has 19"
    );
    let mut z = zeros.clone();
    z[2 * 5 + 3] = f64::NAN;
    assert_eq!(
        e(&x, &y, &z, [NATURAL; 2]).to_string(),
        "z[2][3] (at x_2, y_3) is not a finite number (NaN)"
    );
    z[2 * 5 + 3] = f64::NEG_INFINITY;
    assert!(matches!(
        e(&x, &y, &z, [NATURAL; 2]),
        SurfaceSplineError::NotFinite { i: 2, j: 3, .. }
    ));
    assert_eq!(
        e(&x, &[0.0, 2.0, 1.0, 3.0, 4.0], &zeros, [NATURAL; 2]).to_string(),
        "the y knots: the abscissas must increase strictly, but point 2 (1) does not exceed \
         point 1 (2)"
    );
    assert!(matches!(
        e(&[0.0, f64::NAN, 2.0, 3.0], &y, &zeros, [NATURAL; 2]),
        SurfaceSplineError::Knots {
            axis: Axis::X,
            error: SplineError::NotFinite { index: 1, .. }
        }
    ));
    assert_eq!(
        e(&x[..3], &y, &zeros[..15], [PERIODIC, NATURAL]).to_string(),
        "the x knots: a periodic spline needs at least 4 points, the table has 3"
    );
    assert!(matches!(
        e(&[0.0], &[0.0], &[1.0], [NATURAL; 2]),
        SurfaceSplineError::Knots {
            axis: Axis::X,
            error: SplineError::TooFewPoints {
                needed: 2,
                got: 1,
                ..
            }
        }
    ));
    assert!(matches!(
        e(&x, &[0.0], &zeros[..4], [NATURAL; 2]),
        SurfaceSplineError::Knots {
            axis: Axis::Y,
            error: SplineError::TooFewPoints {
                needed: 2,
                got: 1,
                ..
            }
        }
    ));
    // Periodic in y: every row's last value must repeat its first; row 1 does not.
    let mut z = zeros.clone();
    z[5 + 4] = 0.25;
    assert_eq!(
        e(&x, &y, &z, [NATURAL, PERIODIC]).to_string(),
        "the grid is periodic in y, so z[1][4] must repeat z[1][0], but they are 0.25 and 0 \
         (difference 2.500e-1)"
    );
    // Periodic in x: the last row must repeat the first; column 2 does not.
    let mut z = zeros.clone();
    z[2] = -1.0;
    assert_eq!(
        e(&x, &y, &z, [PERIODIC, NATURAL]),
        SurfaceSplineError::EdgesDoNotMeet {
            axis: Axis::X,
            first_cell: (0, 2),
            last_cell: (3, 2),
            first: -1.0,
            last: 0.0
        }
    );
    assert_eq!(
        e(
            &x,
            &y,
            &zeros,
            [
                Ends::Clamped {
                    start: f64::NAN,
                    end: 0.0
                },
                NATURAL
            ]
        )
        .to_string(),
        "the x axis is clamped with slopes NaN and 0, which must be finite"
    );
    assert_eq!(
        e(&[-1e308, 1e308], &y, &zeros[..10], [NATURAL; 2]).to_string(),
        "the x knots run from -1e308 to 1e308, a width that overflows f64"
    );
    // Finite values whose curvature overflows: a spike of 1e308 a millimetre wide.
    let mut z = vec![0.0; 9];
    z[3 + 1] = 1e308;
    let spike = e(&[0.0, 1e-3, 2e-3], &[0.0, 1.0, 2.0], &z, [NATURAL; 2]);
    assert!(
        matches!(
            spike,
            SurfaceSplineError::Overflow {
                what: "∂²S/∂x²",
                i: 1,
                j: 1,
                ..
            }
        ),
        "{spike}"
    );
    // A spike with its x curvature finite (-3A) but not its y curvature (-3A/d²), and one
    // with both finite (A = 3e301: 9e301 and 9e307) but not the cross curvature (27A/d²).
    let narrow = [0.0, 1e-3, 2e-3];
    for (spike, what) in [(1e303, "∂²S/∂y²"), (3e301, "∂⁴S/∂x²∂y²")] {
        let mut z = vec![0.0; 9];
        z[3 + 1] = spike;
        let error = e(&[0.0, 1.0, 2.0], &narrow, &z, [NATURAL; 2]);
        assert!(
            matches!(error, SurfaceSplineError::Overflow { what: w, i: 1, j: 1, .. } if w == what),
            "{error}"
        );
    }
    // check_grid refuses what new refuses, before any solve.
    assert!(check_grid(&x, &y, &zeros[..19], [NATURAL; 2]).is_err());
    assert_eq!(check_grid(&x, &y, &zeros, [PERIODIC, PERIODIC]), Ok(()));
}

#[test]
fn a_periodic_grid_nearly_closed_is_closed_exactly() {
    // A last line within the closure tolerance of the first (a table written with 12
    // digits) is accepted and replaced by the first, so that the surface meets itself
    // across the seam exactly: the polynomials on both sides of the seam agree at every
    // point of it to the same rounding as at interior knot lines (1e-12 of the scales).
    let mut rng = Rng(3);
    let (nx, ny) = (6, 5);
    let x = irregular(&mut rng, nx, 0.0, 0.5);
    let y = irregular(&mut rng, ny, 0.0, 0.5);
    let ends = [PERIODIC, PERIODIC];
    let mut z = random_grid(&mut rng, nx, ny, ends);
    for j in 0..ny {
        z[(nx - 1) * ny + j] += 3e-12;
    }
    for i in 0..nx {
        z[i * ny + ny - 1] -= 2e-12;
    }
    let surface = SurfaceSpline::new(&x, &y, &z, ends).unwrap();
    let values = surface.values();
    for j in 0..ny {
        assert_eq!(values[(nx - 1) * ny + j], values[j], "column {j}");
    }
    for i in 0..nx {
        assert_eq!(values[i * ny + ny - 1], values[i * ny], "row {i}");
    }
    let t = surface.table();
    let h = least_spacing(&x).min(least_spacing(&y));
    for j in 0..ny - 1 {
        let v = rng.uniform(y[j], y[j + 1]);
        let (last, first) = (cell(&t, nx - 2, j, x[nx - 1], v), cell(&t, 0, j, x[0], v));
        for (p, q) in ORDERS.into_iter().take(6) {
            let tolerance = 1e-12 * scale(2.0, h, p + q);
            assert!(
                (last[p][q] - first[p][q]).abs() < tolerance,
                "∂{p},{q} at y = {v}"
            );
        }
    }
    // Beyond the tolerance: refused.
    z[(nx - 1) * ny + 2] += 1e-6;
    assert!(matches!(
        SurfaceSpline::new(&x, &y, &z, ends),
        Err(SurfaceSplineError::EdgesDoNotMeet {
            axis: Axis::X,
            last_cell: (5, 2),
            ..
        })
    ));
}

/// A bilinear surface as generated code would store it: constants, curvatures zero.
const PLANE_X: [f64; 3] = [0.0, 1.0, 3.0];
const PLANE_Y: [f64; 2] = [-1.0, 1.0];
/// 2 − x + 0.5 y + 0.25 x y at the knots.
const PLANE_Z: [f64; 6] = [1.5, 2.5, 0.25, 1.75, -2.25, 0.25];
const ZERO: [f64; 6] = [0.0; 6];
const PLANE: SurfaceTable<'static> = SurfaceTable {
    x: &PLANE_X,
    y: &PLANE_Y,
    z: &PLANE_Z,
    mx: &ZERO,
    my: &ZERO,
    mxy: &ZERO,
    periodic: [false, false],
};

#[test]
fn a_constant_table_evaluates_as_generated_code_would() {
    // The table is a constant (so generated code can store one), and evaluating it gives
    // the bilinear function it samples: every knot, beyond the ends, and every derivative
    // (exact to rounding of terms of order 10).
    let f = |x: f64, y: f64| {
        [
            2.0 - x + 0.5 * y + 0.25 * x * y,
            -1.0 + 0.25 * y,
            0.5 + 0.25 * x,
        ]
    };
    for (k, &u) in PLANE_X.iter().enumerate() {
        for (l, &v) in PLANE_Y.iter().enumerate() {
            assert_eq!(PLANE_Z[k * 2 + l], f(u, v)[0], "the constant itself");
        }
    }
    let owned = SurfaceSpline::new(&PLANE_X, &PLANE_Y, &PLANE_Z, [NATURAL; 2]).unwrap();
    for &u in &[-0.5, 0.0, 0.3, 1.0, 2.2, 3.0, 4.0] {
        for &v in &[-2.0, -1.0, 0.1, 1.0, 1.7] {
            let (got, want) = (evaluate(&PLANE, u, v), f(u, v));
            let mine = [got.value, got.gradient[0], got.gradient[1]];
            for (g, w) in mine.iter().zip(want) {
                assert!((g - w).abs() < 1e-12, "({u}, {v}): {g} vs {w}");
            }
            assert!((got.hessian[1] - 0.25).abs() < 1e-12);
            for d in [got.hessian[0], got.hessian[2]].iter().chain(&got.third) {
                assert!(d.abs() < 1e-12, "({u}, {v}): {d}");
            }
            let theirs = owned.eval(u, v);
            assert!((theirs.value - got.value).abs() < 1e-12, "({u}, {v})");
        }
    }
}

#[test]
fn slices_that_are_not_a_grid_evaluate_to_nan() {
    let z = [0.0; 6];
    let cases = [
        SurfaceTable {
            z: &z[..5],
            ..PLANE
        },
        SurfaceTable {
            mxy: &z[..4],
            ..PLANE
        },
        SurfaceTable { x: &[], ..PLANE },
        SurfaceTable {
            x: &[0.0],
            y: &[0.0],
            z: &z[..1],
            mx: &z[..1],
            my: &z[..1],
            mxy: &z[..1],
            ..PLANE
        },
    ];
    for table in cases {
        let got = evaluate(&table, 0.5, 0.5);
        assert!(
            got.value.is_nan() && got.third.iter().all(|d| d.is_nan()),
            "{table:?}"
        );
    }
    // A grid evaluated at a NaN or infinite point is NaN or infinite, not a panic.
    for periodic in [[false, false], [true, true]] {
        let table = SurfaceTable { periodic, ..PLANE };
        for (u, v) in [
            (f64::NAN, 0.0),
            (0.0, f64::INFINITY),
            (f64::NEG_INFINITY, f64::NAN),
        ] {
            assert!(!evaluate(&table, u, v).value.is_finite());
        }
    }
}

/// A number for the hostile grids: mostly ordinary, sometimes special or extreme.
fn hostile(rng: &mut Rng) -> f64 {
    match rng.below(16) {
        0 => f64::NAN,
        1 => f64::INFINITY,
        2 => f64::NEG_INFINITY,
        3 => 1e308 * if rng.below(2) == 0 { 1.0 } else { -1.0 },
        4 => 1e-310,
        5 => 0.0,
        _ => rng.uniform(-10.0, 10.0),
    }
}

/// Knots for the hostile grids: mostly increasing, sometimes with a repeat, a step back,
/// a special number, an overflowing or a subnormal step, or spread over all of f64.
fn hostile_knots(rng: &mut Rng, n: usize) -> Vec<f64> {
    if rng.below(64) == 0 {
        let last = n.saturating_sub(1).max(1) as f64;
        return (0..n)
            .map(|k| -1e308 * (1.0 - 2.0 * k as f64 / last))
            .collect();
    }
    let mut knots = Vec::with_capacity(n);
    let mut at = rng.uniform(-5.0, 5.0);
    for _ in 0..n {
        knots.push(at);
        at += match rng.below(80) {
            0 => 0.0,
            1 => -1.0,
            2 => f64::NAN,
            3 => 1e308,
            4 => 5e-324,
            5 => 1e-300,
            _ => rng.uniform(0.01, 2.0),
        };
    }
    knots
}

#[test]
fn hostile_grids_are_refused_or_built_finite() {
    // Random grids from a deterministic generator (shapes 0–6 per axis, lengths off by one,
    // special and extreme numbers, every kind of ends): construction returns an error or a
    // surface whose tables are all finite, `check_grid` refuses exactly what the input
    // checks refuse, messages format, and evaluation at hostile points returns. Nothing may
    // panic. Both outcomes must occur often, and every kind of error, or the generator
    // tests little.
    let mut rng = Rng(0x0bad_cafe);
    let (mut built, mut refused) = (0, 0);
    let mut kinds = std::collections::HashSet::new();
    for _ in 0..20_000 {
        let (nx, ny) = (rng.below(7), rng.below(7));
        let x = hostile_knots(&mut rng, nx);
        let y = hostile_knots(&mut rng, ny);
        let length = match rng.below(32) {
            0 => nx * ny + 1,
            1 => (nx * ny).saturating_sub(1),
            _ => nx * ny,
        };
        let mut z: Vec<f64> = (0..length)
            .map(|_| {
                if rng.below(200) == 0 {
                    hostile(&mut rng)
                } else {
                    rng.uniform(-1.0, 1.0)
                }
            })
            .collect();
        let pick = |rng: &mut Rng| match rng.below(7) {
            0 | 1 => NATURAL,
            2 | 3 => PERIODIC,
            4 | 5 => Ends::Clamped {
                start: rng.uniform(-2.0, 2.0),
                end: rng.uniform(-2.0, 2.0),
            },
            _ => Ends::Clamped {
                start: hostile(rng),
                end: hostile(rng),
            },
        };
        let ends = [pick(&mut rng), pick(&mut rng)];
        if length == nx * ny && nx > 0 && ny > 0 && rng.below(8) != 0 {
            close(&mut z, nx, ny, ends);
        }
        let checked = check_grid(&x, &y, &z, ends);
        match SurfaceSpline::new(&x, &y, &z, ends) {
            Ok(surface) => {
                built += 1;
                assert_eq!(checked, Ok(()));
                let t = surface.table();
                for table in [t.z, t.mx, t.my, t.mxy] {
                    assert!(
                        table.iter().all(|v| v.is_finite()),
                        "{x:?} {y:?} {z:?} {ends:?}"
                    );
                }
                for _ in 0..4 {
                    let _ = surface.eval(hostile(&mut rng), hostile(&mut rng));
                }
            }
            Err(error) => {
                refused += 1;
                kinds.insert(std::mem::discriminant(&error));
                assert!(!error.to_string().is_empty());
                if let Err(first) = checked {
                    // By message: an error holding a NaN is not equal to itself.
                    assert_eq!(first.to_string(), error.to_string());
                } else {
                    assert!(
                        matches!(error, SurfaceSplineError::Overflow { .. }),
                        "{error}"
                    );
                }
            }
        }
        // The raw slices as a table: evaluate must not panic whatever they are.
        let raw = SurfaceTable {
            x: &x,
            y: &y,
            z: &z,
            mx: &z,
            my: &z,
            mxy: &z,
            periodic: [ends[0] == PERIODIC, ends[1] == PERIODIC],
        };
        let _ = evaluate(&raw, hostile(&mut rng), hostile(&mut rng));
    }
    // Every kind of error but `Line` (which the checks leave no way to reach).
    assert!(
        built > 2000 && refused > 2000 && kinds.len() == 7,
        "built {built}, refused {refused}, {} kinds of error",
        kinds.len()
    );
}
