//! A run's summary as a dict: the command line's text and its numbers.

use crate::run::{Request, RunData};
use camchain_runtime::ModelInfo;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `text` (the command line's summary, as `camchain simulate` prints it), `assembly` (what
/// assembly changed), `quantities` (`{"q1 [rad]": (min, max)}`, the table's rows),
/// `max_h` (per contact and loop), `energy_drift`, `energy_scale` (J), the work counters
/// (`steps`, `rejected`, `rhs_evaluations`, `event_evaluations`, `gap_evaluations`,
/// `repartitions`), `samples`, `wall_time` (s) and the settings the run used.
pub fn to_dict<'py>(
    py: Python<'py>,
    info: &ModelInfo,
    data: &RunData,
    request: &Request,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("text", &data.text)?;
    d.set_item("assembly", &data.assembly)?;
    let quantities = PyDict::new(py);
    for (name, lo, hi) in data.digest.rows() {
        quantities.set_item(name, (lo, hi))?;
    }
    d.set_item("quantities", quantities)?;
    let max_h = PyDict::new(py);
    for (k, c) in info.contacts.iter().enumerate() {
        max_h.set_item(&c.name, data.digest.max_h(k))?;
    }
    for (l, h) in info.loops.iter().zip(data.digest.loop_h()) {
        max_h.set_item(&l.name, *h)?;
    }
    d.set_item("max_h", max_h)?;
    d.set_item("energy_drift", data.digest.energy_drift())?;
    d.set_item("energy_scale", data.digest.energy_scale())?;
    let s = data.stats;
    d.set_item("steps", s.steps)?;
    d.set_item("rejected", s.rejected)?;
    d.set_item("rhs_evaluations", s.rhs_evaluations)?;
    d.set_item("event_evaluations", s.event_evaluations)?;
    d.set_item("gap_evaluations", s.gap_evaluations)?;
    d.set_item("repartitions", s.repartitions)?;
    d.set_item("samples", data.samples)?;
    d.set_item("wall_time", data.wall)?;
    let settings = &request.settings;
    d.set_item("t_end", settings.t_end)?;
    d.set_item("dt_out", settings.dt_out)?;
    d.set_item("method", settings.integrator.keyword().to_lowercase())?;
    d.set_item("dt", settings.dt)?;
    d.set_item("rtol", settings.rtol)?;
    d.set_item("atol", settings.atol)?;
    Ok(d)
}
