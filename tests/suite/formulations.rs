//! The two forward-dynamics routes (docs/method.md §14) on whole runs: every built-in model
//! compiled with the articulated-body sweeps (the all-at-run-time copies of
//! `parameter_modes`, built with `Formulation::Articulated`) runs as the same model on the
//! dense route (the folded copies), in its coordinates, multipliers, normal forces and drive
//! loads. `tests/common/articulated.rs` checks the generated sweeps at random states; this
//! checks what the runtime does with them (the Delassus system, λ and the drive loads).

use crate::common;

use camchain::runtime::{Dynamics, Simulate};
use camchain_models as models;
use camchain_models::parameter_modes::{all_at_run_time, folded};

fn by_name<'a>(
    table: &'a [(&'static str, &'static (dyn Dynamics + Sync))],
    name: &str,
) -> &'a (dyn Dynamics + Sync) {
    table
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, m)| *m)
        .unwrap_or_else(|| panic!("{name} is compiled"))
}

#[test]
fn every_built_in_model_keeps_the_dense_route_and_the_copies_take_the_other() {
    // Every built-in model is small: the build's estimate keeps the dense route for each
    // (their headers show both estimates; BENCHMARKS.md, "Articulated-body forward
    // dynamics"), so none of them got slower.
    for (name, model) in models::ALL.iter() {
        assert_eq!(model.articulated_len(), 0, "{name}: the dense route");
    }
    for (name, model) in all_at_run_time::ALL.iter() {
        assert!(model.articulated_len() > 0, "{name}: the articulated route");
        // A model of one constraint row solves it within its sweeps (docs/method.md §14.6).
        let one_row = usize::from(model.info().n_constraints() == 1);
        assert_eq!(
            model.articulated_rows(),
            one_row,
            "{name}: rows solved within"
        );
    }
}

#[test]
fn whole_runs_agree_on_both_routes() {
    // Loops (four_bar, slider_crank, bricard with its redundant row left out, andrews_squeezer
    // with its motor), drives (paper_rotating's cam, cycloidal_roller's camshaft, slider_crank's
    // crank), a spatial chain (spatial_arm).
    for name in [
        "four_bar",
        "slider_crank",
        "bricard",
        "andrews_squeezer",
        "paper_rotating",
        "cycloidal_roller",
        "spatial_arm",
    ] {
        let dense = by_name(&folded::ALL, name);
        let articulated = by_name(&all_at_run_time::ALL, name);
        let mut settings = dense.info().defaults.clone();
        settings.t_end = settings.t_end.min(0.5);
        let run = |m: &dyn Dynamics| {
            let state = m.assemble(0.0).expect("assembles");
            m.simulate(state, &settings)
                .unwrap_or_else(|f| panic!("{name}: {}", f.error))
        };
        let (a, b) = (run(articulated), run(dense));
        assert_eq!(a.samples.len(), b.samples.len(), "{name}");
        assert!(a.samples.len() > 10, "{name}: a run, not a start");
        let mut loads = 0.0_f64;
        for (x, y) in a.samples.iter().zip(&b.samples) {
            // The right-hand sides agree to round-off (the sweeps' residuals are checked at
            // 1e-13 against the folded code); the adaptive steps may then differ marginally, so
            // the runs differ at the integration tolerance (the files' rtol, 1e-10 or tighter)
            // times the error's growth over 0.5 s: 1e-7 of max(1, |value|) leaves margin, as in
            // random_compiled.rs.
            let at = format!("{name} at t = {}", x.t);
            common::assert_close(&x.q, &y.q, 1e-7, &format!("{at}: q"));
            common::assert_close(&x.lambda, &y.lambda, 1e-6, &format!("{at}: λ"));
            common::assert_close(
                &x.normal_force,
                &y.normal_force,
                1e-6,
                &format!("{at}: normal force"),
            );
            common::assert_close(&x.drive, &y.drive, 1e-6, &format!("{at}: drive loads"));
            loads = loads.max(x.drive.iter().fold(0.0, |m: f64, d| m.max(d.abs())));
        }
        println!(
            "{name}: {} samples alike, largest drive load {loads:.3e}",
            a.samples.len()
        );
    }
}
