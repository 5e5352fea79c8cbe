//! Tables of thousands of points, as CAD exports them, on the numeric reference's path from a
//! file (what `camchain simulate file.ron` runs): the table is read, validated and solved in
//! O(n) and its spline evaluated by the reference's own route (`camchain_reference::spline`,
//! knot slopes in Hermite form), which must agree with the runtime's spline
//! (`camchain_runtime::spline`, knot second derivatives) and with the closed form the table
//! samples.
//!
//! Tolerances. Between the two routes only rounding differs: both solve strictly diagonally
//! dominant tridiagonal systems (condition number at most 3) whose right-hand sides are
//! differences of the table's values divided by h or h², so the k-th derivative of either
//! carries an error of a few ε·Y/hᵏ (Y the largest magnitude of the values, ε = 2.2e-16);
//! 100 ε·Y/hᵏ is six times or more what the two routes show here (the third derivative of the
//! polar table, 0.15 of it; the others below 0.07). Against the closed
//! form f the periodic and clamped splines obey Hall and Meyer's bounds (J. Approx. Theory 16,
//! 1976): |f − S| ≤ 5/384 h⁴ max|f⁗|, |f′ − S′| ≤ 1/24 h³ max|f⁗|, |f″ − S″| ≤ 3/8 h² max|f⁗|,
//! to which the rounding above is added (the largest error seen, 0.15 of that sum, is the
//! clamped table's second derivative). The open table is compared between its ends only: its
//! end cubics continued far beyond them grow a rounding error of S‴ by the distance cubed.

use camchain_codegen::model::Profile;
use camchain_codegen::profile::{Scalar, Tabulated};
use camchain_reference::NumericModel;
use camchain_reference::spline::{Hermite, derivative};
use camchain_runtime::Simulate;
use camchain_runtime::spline::{Ends, Spline};
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Points of the tables: as many as a fine CAD export.
const POINTS: usize = 10_000;

/// The eccentric disc of `models/eccentric_roller.ron`: radius R about a centre e from the
/// camshaft's axis.
const R: f64 = 0.04;
const E: f64 = 0.01;
const RHO: f64 = 0.0125;

/// Largest |r⁗| of the disc's r(θ) = e cos θ + √(R² − e² sin²θ) and of its x, y of the
/// angle: e for the first term; R √(1 − k² sin²θ) with k = e/R = 1/4 is R times a series in
/// k² sin²θ whose fourth derivative is below 16·k²/2·(1 + k²) < 0.6, so below 0.024; 0.05
/// bounds the sum with margin.
const FOURTH: f64 = 0.05;

/// 100 ε: the rounding allowance per unit of Y/hᵏ (see the module's comment).
const ROUNDING: f64 = 100.0 * f64::EPSILON;

/// r, r′, r″ of the disc about the camshaft's axis (s = sin θ, c = cos θ, w = √(R² − e²s²)).
fn disc(theta: f64) -> [f64; 3] {
    let (s, c) = theta.sin_cos();
    let w = (R * R - E * E * s * s).sqrt();
    [
        E * c + w,
        -E * s - E * E * s * c / w,
        -E * c - E * E * ((c * c - s * s) / w + E * E * s * s * c * c / w.powi(3)),
    ]
}

/// A directory of its own under the system's temporary directory.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("camchain-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary directory");
    dir
}

/// `models/eccentric_roller.ron` with its polar formula replaced by `table`, written into
/// `dir` beside the table file `csv` (its text), and loaded as `camchain simulate` loads a
/// file.
fn load_with_table(dir: &Path, table: &str, csv: &str) -> NumericModel {
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let source = std::fs::read_to_string(models.join("eccentric_roller.ron"))
        .expect("models/eccentric_roller.ron");
    let formula = "polar: \"e*theta.cos() + (R*R - e*e*theta.sin().powi(2)).sqrt()\",";
    assert!(
        source.contains(formula),
        "eccentric_roller's profile changed"
    );
    std::fs::write(dir.join("disc.csv"), csv).expect("the table written");
    let model = dir.join("disc.ron");
    std::fs::write(&model, source.replace(formula, table)).expect("the model written");
    NumericModel::load(&model).unwrap_or_else(|e| panic!("the model loads: {e}"))
}

/// The tabulated leaf of a profile expression.
fn leaf(s: &Scalar) -> Arc<Tabulated> {
    match s {
        Scalar::Table(t, 0, _) => t.clone(),
        other => panic!("a table's profile is a tabulated leaf, got {other:?}"),
    }
}

/// The runtime's spline inside a tabulated function.
fn runtime_spline(t: &Tabulated) -> &Spline {
    match &t.function {
        camchain_codegen::profile::TabulatedFunction::Spline(s) => s,
        other => panic!("a table is a spline, got {other:?}"),
    }
}

/// The reference's route (through its per-thread cache, as the dynamics read it) against
/// the runtime's, derivatives 0 to 3 at `at`, within the rounding allowance for values of
/// magnitude `y` on knots `h` apart.
fn assert_routes_agree(t: &Arc<Tabulated>, at: &[f64], y: f64, h: f64) {
    let spline = runtime_spline(t);
    for &s in at {
        let runtime = spline.eval(s);
        for (order, &expected) in runtime.iter().enumerate() {
            let reference = derivative(t, order as u8, s);
            let tolerance = ROUNDING * y / h.powi(order as i32);
            assert!(
                (reference - expected).abs() <= tolerance,
                "{}: S^({order})({s}): reference {reference} vs runtime {expected} \
                 (tolerance {tolerance:e})",
                t.name
            );
        }
    }
}

/// Hall and Meyer's bound on the k-th derivative's interpolation error (k ≤ 2), plus the
/// rounding allowance.
fn formula_tolerance(order: usize, y: f64, h: f64, fourth: f64) -> f64 {
    let constant = [5.0 / 384.0, 1.0 / 24.0, 3.0 / 8.0][order];
    constant * h.powi(4 - order as i32) * fourth + ROUNDING * y / h.powi(order as i32)
}

/// Points between the knots (and some on them) over [a, b].
fn probes(a: f64, b: f64) -> Vec<f64> {
    (0..=3001)
        .map(|k| a + (b - a) * (f64::from(k) + 0.37 * f64::from(k % 3)) / 3002.0)
        .collect()
}

/// A closed table of 10,000 points read from a CSV file beside its model: the eccentric disc
/// as r(θ) (polar) and as its outline (x, y) (a closed parametric curve). The model loads and
/// assembles; both routes agree; the polar spline is the disc's r(θ) with its two derivatives
/// and the parametric one lies on the disc's circle, within the bounds of the module's
/// comment.
#[test]
fn a_closed_table_of_ten_thousand_points_loads_from_a_file_and_matches_both_routes() {
    let dir = scratch("closed-table");
    let n = POINTS;
    let h = TAU / n as f64;
    // Polar, in radians, its closing row the first radius one turn later.
    let mut csv = String::from("# the eccentric disc, r(theta)\ntheta,r\n");
    for k in 0..=n {
        let theta = if k == n { TAU } else { h * k as f64 };
        let r = disc(if k == n { 0.0 } else { theta })[0];
        csv.push_str(&format!("{theta:?},{r:?}\n"));
    }
    let model = load_with_table(&dir, "table: (form: Polar, file: \"disc.csv\"),", &csv);
    let Profile::Polar { r, .. } = &model.model().contacts[0].profile else {
        panic!("a polar profile")
    };
    let r = leaf(r);
    let at = probes(-0.3, TAU + 0.3);
    let largest = R + E;
    assert_routes_agree(&r, &at, largest, h);
    for &theta in &at {
        let exact = disc(theta);
        for (order, &f) in exact.iter().enumerate() {
            let s = derivative(&r, order as u8, theta);
            let tolerance = formula_tolerance(order, largest, h, FOURTH);
            assert!(
                (s - f).abs() <= tolerance,
                "r^({order})({theta}): spline {s} vs formula {f} (tolerance {tolerance:e})"
            );
        }
    }
    // The follower assembles on the disc's top, lift e + R + ρ (the model's frame turns the
    // cam's x axis to the follower's).
    let state = model.assemble(0.0).expect("the model assembles");
    let lift = state.q[1];
    assert!(
        (lift - (E + R + RHO)).abs() < 1e-12,
        "lift {lift} against {}",
        E + R + RHO
    );

    // Parametric: the same disc's outline counterclockwise, the first point again last.
    let mut csv = String::from("x,y\n");
    for k in 0..=n {
        let phi = h * (k % n) as f64;
        csv.push_str(&format!("{:?},{:?}\n", E + R * phi.cos(), R * phi.sin()));
    }
    let model = load_with_table(&dir, "table: (form: Parametric, file: \"disc.csv\"),", &csv);
    let Profile::Parametric { x, y, .. } = &model.model().contacts[0].profile else {
        panic!("a parametric profile")
    };
    let (x, y) = (leaf(x), leaf(y));
    // Chord-length knots: the chord of an n-gon inscribed in the circle.
    let chord = 2.0 * R * (TAU / (2.0 * n as f64)).sin();
    let length = chord * n as f64;
    let at = probes(-0.01, length + 0.01);
    assert_routes_agree(&x, &at, E + R, chord);
    assert_routes_agree(&y, &at, R, chord);
    // In the length t the outline is (e + R cos(t/R′), R sin(t/R′)) with R′ = chord/h ≈ R:
    // its fourth derivatives are below R/R′⁴ ≈ 1/R³.
    let fourth = 1.0 / R.powi(3) * 1.01;
    let tolerance = formula_tolerance(0, E + R, chord, fourth);
    for &t in &at {
        let (px, py) = (derivative(&x, 0, t), derivative(&y, 0, t));
        let off = ((px - E).hypot(py) - R).abs();
        assert!(
            off <= tolerance,
            "({px}, {py}) at t = {t} is {off:e} m off the disc (tolerance {tolerance:e})"
        );
    }
    let state = model.assemble(0.0).expect("the model assembles");
    let lift = state.q[1];
    assert!(
        (lift - (E + R + RHO)).abs() < 1e-12,
        "lift {lift} against {}",
        E + R + RHO
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// An open table of 10,000 points, y = sin x + 0.3 cos 2.7x over [0, 3], with clamped ends
/// (the formula's slopes) and with natural ones: both routes agree everywhere, and the
/// clamped spline is the formula with two derivatives within Hall and Meyer's bounds
/// (|f⁗| ≤ 1 + 0.3·2.7⁴ < 17).
#[test]
fn an_open_table_of_ten_thousand_points_matches_both_routes_and_its_formula() {
    let f = |x: f64| {
        let (s, c) = x.sin_cos();
        let (s3, c3) = (2.7 * x).sin_cos();
        [s + 0.3 * c3, c - 0.3 * 2.7 * s3, -s - 0.3 * 2.7 * 2.7 * c3]
    };
    let n = POINTS;
    let h = 3.0 / n as f64;
    let x: Vec<f64> = (0..=n).map(|k| h * k as f64).collect();
    let y: Vec<f64> = x.iter().map(|&x| f(x)[0]).collect();
    let clamped = Ends::Clamped {
        start: f(0.0)[1],
        end: f(3.0)[1],
    };
    let largest = 1.3;
    for ends in [clamped, Ends::Natural] {
        let spline = Spline::new(&x, &y, ends).expect("a valid table");
        let hermite = Hermite::new(&spline);
        let at = probes(0.0, 3.0);
        for &s in &at {
            let (a, b) = (spline.eval(s), hermite.eval(s));
            for order in 0..4 {
                let tolerance = ROUNDING * largest / h.powi(order as i32);
                assert!(
                    (a[order] - b[order]).abs() <= tolerance,
                    "{ends:?} S^({order})({s}): runtime {} vs reference {} (tolerance \
                     {tolerance:e})",
                    a[order],
                    b[order]
                );
            }
            if ends == clamped && (0.0..=3.0).contains(&s) {
                for (order, exact) in f(s).into_iter().enumerate() {
                    let tolerance = formula_tolerance(order, largest, h, 17.0);
                    assert!(
                        (b[order] - exact).abs() <= tolerance,
                        "S^({order})({s}): reference {} vs formula {exact} (tolerance \
                         {tolerance:e})",
                        b[order]
                    );
                }
            }
        }
    }
}
