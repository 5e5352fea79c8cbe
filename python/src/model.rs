//! `camchain.Model`: a model by name or from a file, what it declares, and its runs.

use crate::errors::{Location, SimulationError, bad_option};
use crate::load::{Engine, Origin};
use crate::run::{self, Request, RunData, Stop};
use camchain_cli::args::IntegrationArgs;
use camchain_codegen::model::Model as Description;
use camchain_runtime::events::{ContactEvent, EventKind};
use camchain_runtime::kinds::IntegratorKind;
use camchain_runtime::{ContactLaw, Flank};
use numpy::{IntoPyArray, PyArray1, PyArray2, ndarray::Array2};
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::PathBuf;

/// A mechanism ready to run: a built-in model (its generated code, compiled into the
/// package) or a model file (the numeric recursive reference, no compilation).
#[pyclass(module = "camchain", name = "Model", frozen)]
pub struct Model {
    pub(crate) origin: Origin,
    pub(crate) description: Description,
    pub(crate) engine: Engine,
    /// Parameter values set over the file's, in the order given.
    pub(crate) values: Vec<(String, f64)>,
    pub(crate) warnings: Vec<String>,
}

impl Model {
    pub(crate) fn load(py: Python<'_>, origin: Origin) -> PyResult<Self> {
        let loaded = py.detach(|| {
            let (description, warnings) = origin.describe_model()?;
            let engine = origin.dynamics(&description)?;
            Ok::<_, Location>((description, warnings, engine))
        });
        let (description, warnings, engine) = loaded.map_err(|e| e.into_py_err(py))?;
        Ok(Model {
            origin,
            description,
            engine,
            values: Vec::new(),
            warnings,
        })
    }

    /// The model with these parameter values over the file's (and over those already set).
    pub(crate) fn with_values(&self, py: Python<'_>, given: Vec<(String, f64)>) -> PyResult<Self> {
        let mut values = self.values.clone();
        for (name, value) in given {
            match values.iter_mut().find(|(n, _)| *n == name) {
                Some(slot) => slot.1 = value,
                None => values.push((name, value)),
            }
        }
        let engine = py
            .detach(|| self.origin.with_parameters(&values))
            .map_err(|e| e.into_py_err(py))?;
        Ok(Model {
            origin: self.origin.clone(),
            description: self.description.clone(),
            engine,
            values,
            warnings: self.warnings.clone(),
        })
    }

    /// The run's name in the summary, as the command line names it.
    fn label(&self) -> String {
        match &self.origin {
            Origin::Builtin {
                name,
                numeric: true,
            } => format!("{name}_numeric"),
            Origin::Builtin { name, .. } => name.clone(),
            Origin::File(path) | Origin::Compiled { path, .. } => path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .filter(|s| !s.is_empty())
                .unwrap_or_else(|| self.description.name.clone()),
        }
    }

    /// The summary's path: `generated code` or the numeric reference, with the parameters
    /// whose values differ from the file's.
    fn engine_text(&self) -> String {
        let path = if self.origin.numeric() {
            "numeric recursive reference (no rebuild)"
        } else {
            "generated code"
        };
        camchain_cli::summary::with_changed_parameters(path, self.engine.get())
    }
}

/// (M, F, Q) as numpy arrays.
pub(crate) type Equations<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// The integration options of `simulate` and `sweep` (None: the model's), checked as the
/// command line's parser checks them: times positive and finite, a known method. The
/// runtime's own checks (ranges, sample counts) follow when they are applied.
pub(crate) fn integration_args(
    t_end: Option<f64>,
    dt_out: Option<f64>,
    rtol: Option<f64>,
    atol: Option<f64>,
    method: Option<&str>,
    dt: Option<f64>,
) -> PyResult<IntegrationArgs> {
    for (option, value) in [("t_end", t_end), ("dt_out", dt_out), ("dt", dt)] {
        if let Some(value) = value
            && !(value.is_finite() && value > 0.0)
        {
            return Err(bad_option(
                option,
                format!("a time in seconds must be positive and finite, got {value}"),
            ));
        }
    }
    let integrator = match method {
        None => None,
        Some(name) => Some(IntegratorKind::parse(name).ok_or_else(|| {
            bad_option(
                "method",
                format!(
                    "unknown integrator `{name}`: one of {}",
                    IntegratorKind::keywords().join(", ").to_lowercase()
                ),
            )
        })?),
    };
    Ok(IntegrationArgs {
        t_end,
        dt_out,
        integrator,
        dt,
        rtol,
        atol,
    })
}

/// Parameter values from a dict `{name: value}`.
pub(crate) fn parameter_values(params: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<(String, f64)>> {
    let mut values = Vec::new();
    if let Some(params) = params {
        for (name, value) in params.iter() {
            let name: String = name
                .extract()
                .map_err(|_| bad_option("params", "names must be strings"))?;
            let value: f64 = value
                .extract()
                .map_err(|_| bad_option("params", format!("{name}: not a number")))?;
            values.push((name, value));
        }
    }
    Ok(values)
}

#[pymethods]
impl Model {
    /// A built-in model by name (`camchain.models()` lists them): its generated code, or the
    /// numeric recursive reference on its model file with `numeric=True`.
    #[new]
    #[pyo3(signature = (name, numeric = false))]
    fn new(py: Python<'_>, name: &str, numeric: bool) -> PyResult<Self> {
        if camchain_models::by_name(name).is_none() {
            return Err(Location::unlocated(name, crate::load::unknown(name)).into_py_err(py));
        }
        Model::load(
            py,
            Origin::Builtin {
                name: name.to_string(),
                numeric,
            },
        )
    }

    /// A model file (`.ron`), on the numeric recursive reference: no compilation. Checked
    /// as the build checks it; a problem raises `camchain.ModelError` with its file, line,
    /// column and field.
    #[staticmethod]
    fn from_file(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        Model::load(py, Origin::File(path))
    }

    /// The same model with other values of its parameters, `{name: value}` (over the file's
    /// and those already set): what `simulate(params=…)` runs.
    fn with_params(&self, py: Python<'_>, params: &Bound<'_, PyDict>) -> PyResult<Self> {
        let values = parameter_values(Some(params))?;
        self.with_values(py, values)
    }

    /// The model's name (from its file).
    #[getter]
    fn name(&self) -> String {
        self.description.name.clone()
    }

    /// The model's free-text description.
    #[getter]
    fn description(&self) -> String {
        self.description.description.clone()
    }

    /// Where the model comes from: a built-in model's name or the file as given.
    #[getter]
    fn source(&self) -> String {
        self.origin.describe()
    }

    /// True on the numeric recursive reference, false on generated code.
    #[getter]
    fn numeric(&self) -> bool {
        self.origin.numeric()
    }

    /// Warnings about values of the file that look mistaken, located like errors.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// The parameters: one dict each with `name`, `value` (the value this model runs with),
    /// `default` (the file's), `unit`, `min`, `max` (None when not declared), `run_time`
    /// (whether `params=` can set it on this path: every parameter on the numeric path,
    /// those not `constant: true` on generated code) and `description`.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for p in &self.description.parameters {
            let value = self
                .values
                .iter()
                .rev()
                .find(|(n, _)| *n == p.name)
                .map_or(p.default, |(_, v)| *v);
            let d = PyDict::new(py);
            d.set_item("name", &p.name)?;
            d.set_item("value", value)?;
            d.set_item("default", p.default)?;
            d.set_item("unit", &p.unit)?;
            d.set_item("min", p.min)?;
            d.set_item("max", p.max)?;
            d.set_item("run_time", self.origin.numeric() || !p.constant)?;
            d.set_item("description", &p.description)?;
            list.append(d)?;
        }
        Ok(list)
    }

    /// The generalised coordinates: one dict each with `name`, `kind` (`revolute`,
    /// `prismatic`), `unit` (`rad`, `m`), `driven`, and the initial guess `q0`, `qd0`.
    #[getter]
    fn coordinates<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let info = self.engine.get().info();
        let list = PyList::empty(py);
        for (i, c) in info.coordinates.iter().enumerate() {
            let d = PyDict::new(py);
            d.set_item("name", &c.name)?;
            d.set_item("kind", c.kind.keyword().to_lowercase())?;
            d.set_item("unit", c.kind.unit())?;
            d.set_item("driven", c.driven)?;
            d.set_item("q0", info.initial.q.get(i).copied())?;
            d.set_item("qd0", info.initial.qd.get(i).copied())?;
            list.append(d)?;
        }
        Ok(list)
    }

    /// The contacts: one dict each with `name`, `follower` (`knife`, `roller`, …), `profile`
    /// (`explicit`, `polar`, …), `cam_moves`, `cam_coordinate` (the cam's own angle's name,
    /// or None), `backlash` (m) and `taper` (rad).
    #[getter]
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let info = self.engine.get().info();
        let list = PyList::empty(py);
        for c in &info.contacts {
            let d = PyDict::new(py);
            d.set_item("name", &c.name)?;
            d.set_item("follower", c.follower.keyword().to_lowercase())?;
            d.set_item("profile", format!("{:?}", c.profile).to_lowercase())?;
            d.set_item("cam_moves", c.cam_moves)?;
            d.set_item(
                "cam_coordinate",
                c.cam_coordinate.map(|i| info.coordinates[i].name.clone()),
            )?;
            d.set_item("backlash", c.backlash)?;
            d.set_item("taper", c.taper)?;
            list.append(d)?;
        }
        Ok(list)
    }

    /// The closed loops: one dict each with `name`, `kind` (the cut joint's) and `equations`
    /// (the names of its rows of h, the suffixes of its CSV columns).
    #[getter]
    fn loops<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let info = self.engine.get().info();
        let list = PyList::empty(py);
        for l in &info.loops {
            let d = PyDict::new(py);
            d.set_item("name", &l.name)?;
            d.set_item("kind", l.kind.keyword().to_lowercase())?;
            d.set_item("equations", l.equations.clone())?;
            list.append(d)?;
        }
        Ok(list)
    }

    /// The model's default settings: `t_end`, `dt_out`, `method`, `dt`, `rtol`, `atol`,
    /// `restitution` (None for bilateral contact).
    #[getter]
    fn defaults<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let info = self.engine.get().info();
        let s = &info.defaults;
        let d = PyDict::new(py);
        d.set_item("t_end", s.t_end)?;
        d.set_item("dt_out", s.dt_out)?;
        d.set_item("method", s.integrator.keyword().to_lowercase())?;
        d.set_item("dt", s.dt)?;
        d.set_item("rtol", s.rtol)?;
        d.set_item("atol", s.atol)?;
        d.set_item("restitution", info.restitution)?;
        Ok(d)
    }

    /// Simulates the model and returns a `camchain.Result`.
    ///
    /// Every setting defaults to the model file's: `t_end`, `dt_out` (s), `method`
    /// (`rk4`, `dopri5`, `dop853`), `dt` (rk4's step, the adaptive methods' first step),
    /// `rtol`, `atol`; `params` sets parameters as `with_params` does; `restitution` makes
    /// the contact one-sided with that coefficient, `bilateral=True` holds the follower on
    /// its cam; `initial` replaces guesses of the initial state, `{"q1": 0.2, "q1_dot": 0}`
    /// (the values the constraints determine are solved again from them, the driven ones
    /// follow their drive).
    #[pyo3(signature = (t_end = None, dt_out = None, rtol = None, atol = None, method = None,
        dt = None, params = None, restitution = None, bilateral = false, initial = None))]
    #[allow(clippy::too_many_arguments)]
    fn simulate(
        &self,
        py: Python<'_>,
        t_end: Option<f64>,
        dt_out: Option<f64>,
        rtol: Option<f64>,
        atol: Option<f64>,
        method: Option<&str>,
        dt: Option<f64>,
        params: Option<&Bound<'_, PyDict>>,
        restitution: Option<f64>,
        bilateral: bool,
        initial: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Py<PyAny>> {
        let values = parameter_values(params)?;
        let varied;
        let model = if values.is_empty() {
            self
        } else {
            varied = self.with_values(py, values)?;
            &varied
        };
        let info = model.engine.get().info();
        let settings =
            integration_args(t_end, dt_out, rtol, atol, method, dt)?.settings(&info.defaults);
        // Every sample is kept (as columns): the runtime's cap on kept samples applies.
        settings
            .validate(0.0)
            .map_err(|e| bad_option(e.field, e.message))?;
        if let Some(e) = restitution
            && !(0.0..=1.0).contains(&e)
        {
            return Err(bad_option(
                "restitution",
                format!("{e} is not between 0 (plastic) and 1 (elastic)"),
            ));
        }
        let law = match (restitution, bilateral) {
            (Some(_), true) => {
                return Err(bad_option(
                    "restitution",
                    "a one-sided contact cannot be bilateral too",
                ));
            }
            (Some(restitution), false) => ContactLaw::Unilateral { restitution },
            (None, true) => ContactLaw::Bilateral,
            (None, false) => match info.restitution {
                Some(restitution) => ContactLaw::Unilateral { restitution },
                None => ContactLaw::Bilateral,
            },
        };
        let initial = match initial {
            None => None,
            Some(given) => Some(run::initial_state(info, given)?),
        };
        let request = Request {
            settings,
            law,
            initial,
            label: model.label(),
            engine: model.engine_text(),
        };
        let data = run::simulate(py, model.engine.get(), &request);
        into_result(py, model, &request, data)
    }

    /// (M, F, Q) of the tree's equations of motion M q̈ + F + Q = 0 (13) at (q, q̇, t):
    /// M an n×n array, F and Q length-n arrays (float64).
    #[pyo3(signature = (q, qd, t = 0.0))]
    fn equations<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
        t: f64,
    ) -> PyResult<Equations<'py>> {
        self.equations_of(py, q, qd, t)
    }

    /// h(q): the contacts' rows, then every loop's (length m).
    fn constraint<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.constraint_of(py, q)
    }

    /// J(q) = ∂h/∂q, an m×n array.
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.jacobian_of(py, q)
    }

    /// c(q, q̇) of J q̈ + c = 0 (7, 8), length m.
    fn bias<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.bias_of(py, q, qd)
    }

    /// dy/dt for y = (q, q̇) (length 2n), as scipy's `solve_ivp(m.rhs, …)` wants it: (q̇, q̈)
    /// with q̈ the constrained accelerations, every contact closed (bilateral), the driven
    /// coordinates following their drives. No projection onto h = 0: an integrator of its
    /// own drifts off the constraint at its own error (`simulate` partitions and does not).
    fn rhs<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        y: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.rhs_of(py, t, y)
    }

    /// Runs the model over a grid or a Latin hypercube of its parameters, in parallel: the
    /// command line's `camchain sweep`, one row per run, returned as a `camchain.Sweep`
    /// whose columns are the sweep CSV's (`run`, the parameters, `status`, the metrics,
    /// `error`).
    ///
    /// `params` maps each swept parameter to its values (a sequence or a numpy array; every
    /// combination runs, the first parameter varying slowest), or with `samples=N` to an
    /// interval `(a, b)` that a Latin hypercube of N runs samples (seeded by `seed`: the
    /// same seed gives the same runs everywhere). `metrics` selects the metric columns
    /// (default: all); `jobs` the workers (default: the cores); `grid=True` also evaluates
    /// the metrics at every output time; the integration options are `simulate`'s.
    #[pyo3(signature = (params, metrics = None, jobs = None, samples = None, seed = 1,
        grid = false, t_end = None, dt_out = None, rtol = None, atol = None, method = None,
        dt = None))]
    #[allow(clippy::too_many_arguments)]
    fn sweep(
        &self,
        py: Python<'_>,
        params: &Bound<'_, PyDict>,
        metrics: Option<Vec<String>>,
        jobs: Option<usize>,
        samples: Option<usize>,
        seed: u64,
        grid: bool,
        t_end: Option<f64>,
        dt_out: Option<f64>,
        rtol: Option<f64>,
        atol: Option<f64>,
        method: Option<&str>,
        dt: Option<f64>,
    ) -> PyResult<Py<PyAny>> {
        let metrics = crate::sweep::metric_names(metrics)?;
        let ask = crate::sweep::Ask {
            params,
            samples,
            seed,
            jobs,
            grid,
            integration: integration_args(t_end, dt_out, rtol, atol, method, dt)?,
        };
        let plan = crate::sweep::plan(&self.origin, &self.values, &ask)?;
        let (rows, raised) = crate::sweep::execute(py, &plan);
        let columns = crate::sweep::columns(py, &plan, &rows, &metrics)?;
        let result = py.import("camchain._result")?.getattr("Sweep")?.call1((
            columns,
            plan.runs.len(),
            plan.label.clone(),
        ))?;
        match raised {
            None => Ok(result.unbind()),
            Some(error) => {
                let value = error.value(py);
                if value.is_instance_of::<PyKeyboardInterrupt>() {
                    value.setattr("result", &result)?;
                }
                Err(error)
            }
        }
    }

    /// The cam designer's report of a contact designed from a motion law (`law:`), as
    /// `camchain cam` computes it, in numbers and arrays: a dict with `speed` (ω, rad/s),
    /// `design` (`design.csv`'s columns: `cam_angle_deg`, `s`, `v`, `a`, `j`,
    /// `pressure_angle_deg`, `radius_of_curvature`, `profile_x`, `profile_y`, `pitch_x`,
    /// `pitch_y`, `normal_force` of the bilateral turn at ω), `peaks` (velocity, acceleration
    /// and jerk: `max` and `min`, each a `value` and its `cam_angle` in rad),
    /// `pressure_angle` (rad, likewise), `radius_of_curvature` (`convex`, `concave`: the
    /// smallest, or None), `undercut_margin` (m, a roller's) or `face_offset` (a flat
    /// face's), `jump` (`speed` and `cam_angle` where the least contact force reaches zero,
    /// predicted from bilateral turns at ω/2, ω and 2ω; None for a mechanism with a degree
    /// of freedom of its own), `lift_offs` of the one-sided run (each with its `landing`),
    /// and `text`, the report as printed.
    ///
    /// `contact` picks the contact when several are designed; `speed` replaces the law's
    /// ω; `samples` (per turn, 1 to 10⁶), `turns` (of the one-sided run) and `restitution`
    /// (of the one-sided run; default the model's, else 0) are the command line's options.
    #[pyo3(signature = (contact = None, speed = None, samples = 3600, turns = 3,
        restitution = None))]
    fn cam<'py>(
        &self,
        py: Python<'py>,
        contact: Option<String>,
        speed: Option<f64>,
        samples: usize,
        turns: usize,
        restitution: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        if !self.values.is_empty() {
            return Err(bad_option(
                "cam",
                "studies the model file's parameter values; call it on the model without \
                 with_params (the cam's speed is the `speed` argument)",
            ));
        }
        let ask = crate::cam::Ask {
            contact,
            speed,
            samples,
            turns,
            restitution,
        };
        let (study, speed) = crate::cam::study(py, &self.origin, &ask)?;
        crate::cam::to_dict(py, &study, speed)
    }

    fn __repr__(&self) -> String {
        let path = if self.origin.numeric() {
            "numeric"
        } else {
            "generated"
        };
        format!(
            "<camchain.Model {} ({path}, {} coordinates, {} contacts, {} loops)>",
            self.origin.describe(),
            self.engine.get().info().n(),
            self.engine.get().info().n_contacts(),
            self.engine.get().info().loops.len()
        )
    }
}

/// The `camchain.Result` of a run; raises when it stopped early, with the result of what it
/// computed until then in the exception's `result`.
fn into_result(
    py: Python<'_>,
    model: &Model,
    request: &Request,
    data: RunData,
) -> PyResult<Py<PyAny>> {
    let info = model.engine.get().info();
    let events = PyList::empty(py);
    for e in &data.events {
        let e: &ContactEvent = e;
        let d = PyDict::new(py);
        d.set_item("t", e.t)?;
        d.set_item("contact", &info.contacts[e.contact].name)?;
        match e.kind {
            EventKind::ForceBecameNegative => d.set_item("kind", "force_negative")?,
            EventKind::ForceBecamePositive => d.set_item("kind", "force_positive")?,
            EventKind::LiftOff => d.set_item("kind", "lift_off")?,
            EventKind::Impact {
                normal_velocity,
                rebound,
                stays,
                loss,
            } => {
                d.set_item("kind", "impact")?;
                d.set_item("speed", -normal_velocity)?;
                d.set_item("rebound", rebound)?;
                d.set_item("stays", stays)?;
                d.set_item("loss", loss)?;
            }
        }
        d.set_item(
            "flank",
            e.flank.map(|f| match f {
                Flank::Inner => "inner",
                Flank::Outer => "outer",
            }),
        )?;
        d.set_item("q", e.q.clone())?;
        d.set_item("qd", e.qd.clone())?;
        events.append(d)?;
    }
    let (repartitions, _) = data.digest.repartitions();
    for r in repartitions {
        let names = |set: &[usize]| -> Vec<String> {
            set.iter()
                .map(|&i| info.coordinates[i].name.clone())
                .collect()
        };
        let d = PyDict::new(py);
        d.set_item("t", r.between.1)?;
        d.set_item("kind", "repartition")?;
        d.set_item("between", r.between)?;
        d.set_item("from", names(&r.from))?;
        d.set_item("to", names(&r.to))?;
        events.append(d)?;
    }
    let summary = crate::summary::to_dict(py, info, &data, request)?;
    let columns = data.columns.len();
    let array = Array2::from_shape_vec((columns, data.samples), data.data)
        .map_err(|e| SimulationError::new_err(format!("internal: {e}")))?;
    let array = array.into_pyarray(py);
    let result = py.import("camchain._result")?.getattr("Result")?.call1((
        data.columns,
        array,
        events,
        summary,
        model.label(),
    ))?;
    match data.stop {
        None => Ok(result.unbind()),
        Some(Stop::Interrupted(error)) => {
            let value = error.value(py);
            if value.is_instance_of::<PyKeyboardInterrupt>() {
                value.setattr("result", &result)?;
            }
            Err(error)
        }
        Some(Stop::Failed { message, time }) => {
            let error = SimulationError::new_err(format!("{}: {message}", model.label()));
            let value = error.value(py);
            value.setattr("time", time)?;
            value.setattr("result", &result)?;
            Err(error)
        }
    }
}
