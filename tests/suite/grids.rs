//! Cam surfaces given as grids of points (`table: (form: Surface, …)`, docs/model-format.md
//! "Surfaces through points", docs/method.md §13.9):
//!
//! - `tests/contact_models/bowl_grid.ron` is `models/paraboloid_orbit.ron` with its
//!   paraboloid z = 2 (x² + y²) given as a 17 × 17 grid with clamped edges, which the C²
//!   bicubic spline reproduces exactly (the quadratic's slope across each edge is the same
//!   along the whole edge): the particle keeps the closed-form circular orbit, and the run is
//!   the formula's to round-off;
//! - the generated code against the numeric reference, which evaluates the grid on its own
//!   route (`reference/src/grid.rs`: splines along the grid lines solved afresh, not the
//!   runtime's tables), at 100 states and over a run, with the energy balance.

use crate::common;

use crate::surfaces::orbit;
use camchain::runtime::{Dynamics, Simulate};
use camchain_models as models;
use camchain_models::contact_models;
use camchain_reference::NumericModel;
use common::compare_dynamics_at;
use std::path::Path;

fn numeric() -> NumericModel {
    let path = format!(
        "{}/tests/contact_models/bowl_grid.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    NumericModel::load(Path::new(&path)).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_grid_of_the_paraboloid_keeps_the_circular_orbit_of_the_formula() {
    let grid = &*contact_models::bowl_grid::DEFAULT;
    let formula = models::by_name("paraboloid_orbit").expect("built in");
    // The files' values: c = 2 1/m (the grid samples 2 (x² + y²)), r0 = 0.1 m, g = 9.81.
    let (c, r0, g) = (2.0, 0.1, 9.81);
    let omega = f64::sqrt(2.0 * c * g);
    let (a, b) = (orbit(grid), orbit(formula));
    assert_eq!(a.len(), b.len());
    let t_end = a.last().expect("samples").t;
    assert!(
        omega * t_end > 10.0 * std::f64::consts::TAU,
        "ten revolutions"
    );
    let (mut radius, mut apart) = (0.0f64, 0.0f64);
    for (s, f) in a.iter().zip(&b) {
        radius = radius.max((s.q[0].hypot(s.q[1]) - r0).abs() / r0);
        for (u, v) in s.q.iter().chain(&s.qd).zip(f.q.iter().chain(&f.qd)) {
            apart = apart.max((u - v).abs());
        }
        apart = apart.max((s.normal_force[0] - f.normal_force[0]).abs() / f.normal_force[0]);
    }
    println!(
        "bowl grid over {:.1} revolutions: radius {radius:.1e} of r0, largest difference from \
         the formula's run {apart:.1e}",
        omega * t_end / std::f64::consts::TAU
    );
    // The closed form's demand, as for the formula (tests/suite/surfaces.rs): circular to
    // 1e-9 over ten revolutions.
    assert!(radius < 1e-9, "radius drifts by {radius:e} of r0");
    // The spline equals the quadratic up to the rounding of its solves (~1e-16 m): the two
    // runs differ by the integrator's response to that, growing along the neutral orbit's
    // phase; 1e-10 (m, m/s, relative force) is two orders above what is seen and far
    // below any wrong derivative (a natural spline's edge error alone is 1e-4).
    assert!(apart < 1e-10, "grid and formula runs differ by {apart:e}");
}

#[test]
fn the_compiled_grid_agrees_with_the_reference_route_and_keeps_its_energy() {
    let generated = &*contact_models::bowl_grid::DEFAULT;
    let numeric = numeric();
    assert_eq!(generated.info(), numeric.info(), "model information");
    let start = generated.assemble().expect("assembles");
    // Within 0.05 m of the assembled point, inside the grid's ±0.2 m.
    let states = common::states_near(&start.q, 0.05, 100, 0x9e1d);
    // As for the built-in models (generated_vs_numeric.rs): 1e-12 relative to max(1, |·|).
    let worst = compare_dynamics_at("bowl_grid", &generated.clone(), &numeric, 1e-12, &states);
    println!("bowl_grid: largest relative difference generated vs numeric {worst:.2e}");
    let mut settings = generated.default_settings();
    settings.t_end = 2.0;
    let run = |m: &dyn Dynamics| {
        m.simulate(m.assemble(0.0).expect("assembles"), &settings)
            .unwrap_or_else(|f| panic!("{}", f.error))
    };
    let generated: &dyn Dynamics = generated;
    let (a, b) = (run(generated), run(&numeric));
    assert_eq!(a.samples.len(), b.samples.len());
    let e0 = a.samples[0].energy.total();
    let (mut apart, mut energy) = (0.0f64, 0.0f64);
    for (x, y) in a.samples.iter().zip(&b.samples) {
        for (u, v) in x.q.iter().zip(&y.q) {
            apart = apart.max((u - v).abs());
        }
        energy = energy.max((x.energy.total() - e0).abs());
    }
    println!("bowl_grid over 2 s: generated vs numeric {apart:.1e} m, energy drift {energy:.1e} J");
    // Right-hand sides agreeing to ~1e-14 integrated at rtol 1e-10 over 2 s.
    assert!(
        apart < 1e-8,
        "generated and numeric runs differ by {apart:e} m"
    );
    // A fixed surface does no work: energy is kept to the integration error, ~1e-10 of the
    // 0.2 J scale at rtol 1e-10; 1e-8 J is the margin.
    assert!(energy < 1e-8, "energy drifts by {energy:e} J");
}
