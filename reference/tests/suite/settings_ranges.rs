//! A model file's `simulation` section and the runtime's `SimSettings::validate` accept and
//! refuse the same values: the build (camchain-codegen) and the run (camchain-runtime) check
//! the settings separately, each where it can locate the problem, so this compares their
//! decisions on the boundary values of every range.

use camchain_codegen::schema::parse_model;
use camchain_runtime::{IntegratorKind, SimSettings};
use std::path::Path;

/// models/double_pendulum.ron with its `simulation` section replaced.
fn model_with(simulation: &str) -> String {
    let text = include_str!("../../../models/double_pendulum.ron");
    let start = text.find("simulation:").expect("a simulation section");
    let end = start + text[start..].find(')').expect("its end") + 1;
    format!("{}{simulation}{}", &text[..start], &text[end..])
}

fn file_accepts(s: &SimSettings) -> bool {
    let integrator = match s.integrator {
        IntegratorKind::Rk4 => "Rk4",
        IntegratorKind::Dopri5 => "Dopri5",
        IntegratorKind::Dop853 => "Dop853",
    };
    let section = format!(
        "simulation: (t_end: {:e}, dt_out: {:e}, integrator: {integrator}, dt: {:e}, rtol: {:e}, \
         atol: {:e})",
        s.t_end, s.dt_out, s.dt, s.rtol, s.atol
    );
    parse_model(&model_with(&section), Path::new("ranges.ron")).is_ok()
}

#[test]
fn the_file_and_the_runtime_draw_the_same_lines() {
    let base = SimSettings {
        t_end: 10.0,
        dt_out: 0.01,
        integrator: IntegratorKind::Dop853,
        dt: 1e-3,
        rtol: 1e-10,
        atol: 1e-12,
    };
    let mut cases = vec![base.clone()];
    for rtol in [1e-15, 1e-14, 9.99e-15, 0.1, 0.100001, 1.0] {
        cases.push(SimSettings {
            rtol,
            ..base.clone()
        });
    }
    for atol in [1e-19, 1e-18, 1.0, 1.000001] {
        cases.push(SimSettings {
            atol,
            ..base.clone()
        });
    }
    for (t_end, dt_out) in [
        (1e4, 0.01),
        (1e4, 0.0099),
        (1e12, 0.01),
        (1.0, 1e-6),
        (1.0, 1e-7),
    ] {
        cases.push(SimSettings {
            t_end,
            dt_out,
            ..base.clone()
        });
    }
    for dt in [1e-9, 1e-10] {
        let rk4 = SimSettings {
            integrator: IntegratorKind::Rk4,
            dt,
            ..base.clone()
        };
        cases.push(rk4);
    }
    let mut refused = 0;
    for case in &cases {
        let runtime = case.validate(0.0);
        assert_eq!(
            file_accepts(case),
            runtime.is_ok(),
            "{case:?}: the runtime says {runtime:?}"
        );
        refused += usize::from(runtime.is_err());
    }
    // Both sides of every boundary are among the cases.
    assert!(
        refused >= 7 && refused + 7 <= cases.len(),
        "{refused} of {}",
        cases.len()
    );
}
