//! The simulation settings: times, steps, integrator, tolerances and restitution within the
//! runtime's ranges.

use super::super::Locator;
use super::Checked;
use super::fields::positive;
use crate::model::Simulation;
use crate::schema::raw;

/// The ranges of the runtime's settings (`camchain_runtime::settings`; a test in
/// `camchain-reference` checks that both accept and refuse the same values).
pub mod ranges {
    /// Relative tolerances of the adaptive integrators.
    pub const RTOL: (f64, f64) = (1e-14, 0.1);
    /// Absolute tolerances of the adaptive integrators.
    pub const ATOL: (f64, f64) = (1e-18, 1.0);
    /// The most samples of a run, t_end / dt_out.
    pub const MAX_SAMPLES: f64 = 1e6;
    /// The most RK4 steps per output interval, dt_out / dt.
    pub const MAX_RK4_STEPS: f64 = 1e7;
}

pub(super) fn simulation(s: &raw::Simulation, at: &Locator) -> Checked<Simulation> {
    let field = |name: &str| format!("simulation.{name}");
    let integrator = s.integrator.0;
    let t_end = positive(at, &field("t_end"), "t_end", s.t_end)?;
    let dt_out = positive(at, &field("dt_out"), "dt_out", s.dt_out)?;
    let dt = positive(at, &field("dt"), "dt", s.dt)?;
    let samples = t_end / dt_out;
    if samples > ranges::MAX_SAMPLES {
        return Err(at.error(
            &field("dt_out"),
            format!(
                "t_end = {t_end} s with dt_out = {dt_out} s gives {samples:.3e} samples, more \
                 than the {:e} a run keeps: a larger dt_out or a smaller t_end",
                ranges::MAX_SAMPLES
            ),
        ));
    }
    let adaptive = integrator.is_adaptive();
    if !adaptive && dt_out / dt > ranges::MAX_RK4_STEPS {
        return Err(at.error(
            &field("dt"),
            format!(
                "an rk4 step of {dt:e} s needs {:.1e} steps per output interval (dt_out = \
                 {dt_out:e} s), more than the {:e} allowed",
                dt_out / dt,
                ranges::MAX_RK4_STEPS
            ),
        ));
    }
    // Checked whatever the file's integrator: they are the defaults of any adaptive run.
    let in_range = |name: &str, value: f64, (low, high): (f64, f64)| {
        if value.is_finite() && (low..=high).contains(&value) {
            Ok(value)
        } else {
            Err(at.error(
                &field(name),
                format!("{name} must be in [{low:e}, {high:e}], got {value:e}"),
            ))
        }
    };
    let restitution = match s.restitution {
        Some(e) => Some(in_range("restitution", e, (0.0, 1.0))?),
        None => None,
    };
    if restitution.is_some() && !adaptive {
        return Err(at.error(
            &field("restitution"),
            "one-sided contact (`restitution`) needs an adaptive integrator (dopri5 or \
             dop853), which locates lift-off and impact",
        ));
    }
    Ok(Simulation {
        formulation: s.formulation.0,
        t_end,
        dt_out,
        integrator,
        dt,
        rtol: in_range("rtol", s.rtol, ranges::RTOL)?,
        atol: in_range("atol", s.atol, ranges::ATOL)?,
        restitution,
    })
}
