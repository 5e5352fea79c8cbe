//! `Model.cam`: the command line's `camchain cam` report as numbers and arrays.
//!
//! The study is the command line's own (`camchain_cli::cam::prepare` and `study`): the
//! design's analysis at the nominal speed ω (the follower's s, v, a, j, the pressure angle,
//! the radius of curvature and the profile at every sampled angle, their extremes refined
//! by golden-section search), the bilateral turns and the jump speed predicted from
//! N(θ, ω) = A(θ) + B(θ) ω + C(θ) ω², the one-sided run over a few turns. The sampled design
//! is `design.csv`'s columns, read back from the text the command line writes.

use crate::errors::bad_option;
use crate::load::Origin;
use camchain_cli::args::CamArgs;
use camchain_cli::cam::analysis::{Extreme, Range};
use camchain_cli::cam::dynamics::JumpSpeed;
use camchain_cli::cam::{self, Study};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// What `cam()` is asked.
pub struct Ask {
    pub contact: Option<String>,
    pub speed: Option<f64>,
    pub samples: usize,
    pub turns: usize,
    pub restitution: Option<f64>,
}

/// The command line's checks of its options (`camchain cam --samples …`).
fn check(ask: &Ask) -> PyResult<()> {
    if !(1..=1_000_000).contains(&ask.samples) {
        return Err(bad_option("samples", "must be 1 to 1000000"));
    }
    if !(1..=10_000).contains(&ask.turns) {
        return Err(bad_option("turns", "must be 1 to 10000"));
    }
    if let Some(w) = ask.speed
        && !(w.is_finite() && w > 0.0)
    {
        return Err(bad_option(
            "speed",
            format!("must be positive and finite, got {w}"),
        ));
    }
    if let Some(e) = ask.restitution
        && !(0.0..=1.0).contains(&e)
    {
        return Err(bad_option(
            "restitution",
            format!("{e} is not between 0 (plastic) and 1 (elastic)"),
        ));
    }
    Ok(())
}

/// Runs the study with the GIL released.
pub fn study(py: Python<'_>, origin: &Origin, ask: &Ask) -> PyResult<(Study, f64)> {
    check(ask)?;
    let model = match origin {
        Origin::Builtin { name, .. } => name.clone(),
        // A compiled model's designer runs are the numeric reference's on its file.
        Origin::File(path) | Origin::Compiled { path, .. } => path.display().to_string(),
    };
    let args = CamArgs {
        model,
        contact: ask.contact.clone(),
        speed: ask.speed,
        samples: ask.samples,
        turns: ask.turns,
        restitution: ask.restitution,
        out: Default::default(),
        table: None,
        points: 720,
    };
    py.detach(|| {
        let prepared = cam::prepare(&args)?;
        let study = cam::study(&prepared, &args, &mut |_| {})?;
        Ok((study, prepared.speed))
    })
    .map_err(crate::errors::cli_error)
}

fn extreme<'py>(py: Python<'py>, e: &Extreme) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("value", e.value)?;
    d.set_item("cam_angle", e.theta)?;
    Ok(d)
}

fn range<'py>(py: Python<'py>, r: &Range) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("max", extreme(py, &r.max)?)?;
    d.set_item("min", extreme(py, &r.min)?)?;
    Ok(d)
}

/// The study as a dict (see `Model.cam`).
pub fn to_dict<'py>(py: Python<'py>, study: &Study, speed: f64) -> PyResult<Bound<'py, PyDict>> {
    let a = &study.analysis;
    let d = PyDict::new(py);
    d.set_item("speed", speed)?;
    d.set_item("text", &study.text)?;
    // design.csv's columns, parsed back exactly (shortest round-trip decimals).
    let csv = study.design_csv();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let mut columns: Vec<Vec<f64>> = vec![Vec::new(); header.len()];
    for line in lines {
        for (column, cell) in columns.iter_mut().zip(line.split(',')) {
            column.push(cell.parse().unwrap_or(f64::NAN));
        }
    }
    let design = PyDict::new(py);
    for (name, values) in header.iter().zip(columns) {
        design.set_item(*name, PyArray1::from_vec(py, values))?;
    }
    d.set_item("design", design)?;
    let peaks = PyDict::new(py);
    for (name, r) in ["velocity", "acceleration", "jerk"].iter().zip(&a.peaks) {
        peaks.set_item(*name, range(py, r)?)?;
    }
    d.set_item("peaks", peaks)?;
    d.set_item("pressure_angle", range(py, &a.pressure)?)?;
    let curvature = PyDict::new(py);
    curvature.set_item("convex", a.convex.map(|e| extreme(py, &e)).transpose()?)?;
    curvature.set_item("concave", a.concave.map(|e| extreme(py, &e)).transpose()?)?;
    d.set_item("radius_of_curvature", curvature)?;
    d.set_item("undercut_margin", a.undercut.map(|u| u.margin))?;
    d.set_item(
        "face_offset",
        a.face.map(|f| range(py, &f.offset)).transpose()?,
    )?;
    let jump = PyDict::new(py);
    match study.prediction.as_ref().map(|p| p.jump) {
        Some(JumpSpeed::At { speed, theta }) => {
            jump.set_item("speed", speed)?;
            jump.set_item("cam_angle", theta)?;
        }
        Some(JumpSpeed::AtRest { theta, force }) => {
            jump.set_item("speed", 0.0)?;
            jump.set_item("cam_angle", theta)?;
            jump.set_item("force_at_rest", force)?;
        }
        Some(JumpSpeed::Never) => jump.set_item("speed", f64::INFINITY)?,
        None => {}
    }
    d.set_item("jump", (!jump.is_empty()).then_some(jump))?;
    match &study.one_sided {
        Ok(run) => {
            let flights = PyList::empty(py);
            for f in &run.flights {
                let flight = PyDict::new(py);
                flight.set_item("t", f.t)?;
                flight.set_item("cam_angle", f.theta)?;
                flight.set_item("follower_speed", f.speed)?;
                if let Some(l) = &f.landing {
                    let landing = PyDict::new(py);
                    landing.set_item("t", l.t)?;
                    landing.set_item("cam_angle", l.theta)?;
                    landing.set_item("approach", l.approach)?;
                    landing.set_item("rebound", l.rebound)?;
                    landing.set_item("stays", l.stays)?;
                    flight.set_item("landing", landing)?;
                } else {
                    flight.set_item("landing", py.None())?;
                }
                flights.append(flight)?;
            }
            d.set_item("lift_offs", flights)?;
            d.set_item("one_sided_error", py.None())?;
        }
        Err(why) => {
            d.set_item("lift_offs", py.None())?;
            d.set_item("one_sided_error", why)?;
        }
    }
    Ok(d)
}
