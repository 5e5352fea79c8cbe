//! `Model.sweep`: the command line's `camchain sweep`, its rows returned as numpy arrays.
//!
//! The sweep is planned by the command line's own code (`camchain_cli::sweep::plan`: the
//! parameters' names and values checked against their declarations before any run, the
//! product or the seeded Latin hypercube of runs, the settings) and each run is its
//! `run_one`: the rows are those of `camchain sweep`'s CSV, value for value. Workers take
//! the runs in index order; the GIL is released while they go, and the calling thread
//! looks for Ctrl-C every [`POLL`]: the workers stop within one step and the completed rows
//! are kept in the exception's `result`.

use crate::errors::bad_option;
use crate::load::Origin;
use camchain_cli::args::{IntegrationArgs, SweepArgs};
use camchain_cli::sweep::table::{METRICS, Row};
use camchain_cli::sweep::{self, Factory, Plan};
use camchain_runtime::Dynamics;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::Duration;

/// How often the calling thread lets Python look for a Ctrl-C.
const POLL: Duration = Duration::from_millis(50);

/// One swept parameter's `NAME=SPEC` for the command line's parser: a list of values, or
/// an interval `(a, b)` for the Latin hypercube. Values are written in Rust's shortest
/// round-trip form, so the parser reads back exactly the given floats.
fn spec(name: &str, values: &Bound<'_, PyAny>) -> PyResult<String> {
    let option = format!("params: {name}");
    if let Ok((a, b)) = values.extract::<(f64, f64)>()
        && values.is_instance_of::<pyo3::types::PyTuple>()
    {
        return Ok(format!("{name}={a:?}:{b:?}"));
    }
    let list: Vec<f64> = match values.extract::<f64>() {
        Ok(one) => vec![one],
        Err(_) => values
            .extract()
            .or_else(|_| {
                values
                    .call_method0("tolist")
                    .and_then(|l| l.extract::<Vec<f64>>())
            })
            .map_err(|_| {
                bad_option(
                    &option,
                    "expected a number, a sequence of numbers or an interval (a, b)",
                )
            })?,
    };
    if list.is_empty() {
        return Err(bad_option(&option, "no values"));
    }
    let text: Vec<String> = list.iter().map(|v| format!("{v:?}")).collect();
    Ok(format!("{name}={}", text.join(",")))
}

/// What a sweep is asked, from the method's arguments.
pub struct Ask<'a> {
    pub params: &'a Bound<'a, PyDict>,
    pub samples: Option<usize>,
    pub seed: u64,
    pub jobs: Option<usize>,
    pub grid: bool,
    pub integration: IntegrationArgs,
}

/// The metric columns asked for (all of them by default), checked.
pub fn metric_names(given: Option<Vec<String>>) -> PyResult<Vec<String>> {
    let all: Vec<String> = METRICS.iter().map(|(n, _)| n.to_string()).collect();
    let Some(given) = given else {
        return Ok(all);
    };
    for name in &given {
        if !all.contains(name) {
            return Err(bad_option(
                "metrics",
                format!(
                    "unknown metric `{name}`; the metrics are {}",
                    all.join(", ")
                ),
            ));
        }
    }
    Ok(given)
}

/// Plans the sweep with the command line's code.
/// `origin` is the model's, `values` the parameter values it was given (`with_params`).
pub fn plan(origin: &Origin, values: &[(String, f64)], ask: &Ask<'_>) -> PyResult<Plan> {
    let (arg, numeric) = match origin {
        Origin::Builtin { name, numeric } => (name.clone(), *numeric),
        Origin::File(path) | Origin::Compiled { path, .. } => (path.display().to_string(), false),
    };
    let mut params = Vec::new();
    // Values set by `with_params` are swept at their one value (a column each).
    for (name, value) in values {
        if !ask.params.contains(name)? {
            params.push(format!("{name}={value:?}"));
        }
    }
    for (name, values) in ask.params.iter() {
        let name: String = name
            .extract()
            .map_err(|_| bad_option("params", "names must be strings"))?;
        params.push(spec(&name, &values)?);
    }
    let args = SweepArgs {
        model: arg,
        params,
        samples: ask.samples,
        seed: ask.seed,
        metric: Vec::new(),
        jobs: ask.jobs,
        shard: None,
        numeric,
        grid: ask.grid,
        integration: ask.integration.clone(),
        // Nothing is written: the rows come back to Python.
        csv: Some("-".into()),
        out: None,
        no_plots: true,
        quiet: true,
    };
    let mut plan = sweep::plan(&args).map_err(crate::errors::cli_error)?;
    // A compiled model: planned and checked on its file, run on its library.
    if let Origin::Compiled { loaded, info, .. } = origin {
        let (loaded, info) = (Arc::clone(loaded), Arc::clone(info));
        plan.factory = Factory::Custom {
            build: Arc::new(move |values: &[(&str, f64)]| {
                let owned: Vec<(String, f64)> =
                    values.iter().map(|(n, v)| (n.to_string(), *v)).collect();
                loaded
                    .instance(&info, &owned)
                    .map(|m| Box::new(m) as Box<dyn Dynamics + Send + Sync>)
                    .map_err(|e| e.text())
            }),
            describe: "compiled code",
        };
    }
    Ok(plan)
}

/// The completed rows, in run order, and whether Python raised (Ctrl-C) meanwhile.
pub fn execute(py: Python<'_>, plan: &Plan) -> (Vec<Row>, Option<PyErr>) {
    py.detach(|| {
        let runs: Vec<usize> = plan.shard.runs(plan.runs.len()).collect();
        let mut rows: Vec<Option<Row>> = (0..runs.len()).map(|_| None).collect();
        let stop = AtomicBool::new(false);
        let next = AtomicUsize::new(0);
        let mut raised = None;
        std::thread::scope(|scope| {
            let (send, receive) = mpsc::channel::<(usize, Option<Row>)>();
            for _ in 0..plan.jobs {
                let send = send.clone();
                let (stop, next, runs) = (&stop, &next, &runs);
                scope.spawn(move || {
                    loop {
                        let k = next.fetch_add(1, Ordering::Relaxed);
                        if k >= runs.len() || stop.load(Ordering::Relaxed) {
                            break;
                        }
                        let row = sweep::run_one(plan, runs[k], stop);
                        if send.send((k, row)).is_err() {
                            break;
                        }
                    }
                });
            }
            drop(send);
            loop {
                match receive.recv_timeout(POLL) {
                    Ok((k, row)) => rows[k] = row,
                    Err(mpsc::RecvTimeoutError::Disconnected) => break,
                    Err(mpsc::RecvTimeoutError::Timeout) => {}
                }
                if raised.is_none()
                    && let Err(e) = Python::attach(|py| py.check_signals())
                {
                    raised = Some(e);
                    stop.store(true, Ordering::Relaxed);
                }
            }
        });
        (rows.into_iter().flatten().collect(), raised)
    })
}

/// The rows as the CSV's columns: `run`, the swept parameters, `status`, the metrics
/// (`METRICS`, NaN where the CSV's cell is empty), `error` ("" where it is).
pub fn columns<'py>(
    py: Python<'py>,
    plan: &Plan,
    rows: &[Row],
    metrics: &[String],
) -> PyResult<Bound<'py, PyDict>> {
    use numpy::PyArray1;
    let d = PyDict::new(py);
    let run: Vec<i64> = rows.iter().map(|r| r.run as i64).collect();
    d.set_item("run", PyArray1::from_vec(py, run))?;
    for (k, s) in plan.runs.swept.iter().enumerate() {
        let values: Vec<f64> = rows.iter().map(|r| r.values[k]).collect();
        d.set_item(&s.name, PyArray1::from_vec(py, values))?;
    }
    let status: Vec<&str> = rows
        .iter()
        .map(|r| if r.error.is_some() { "failed" } else { "ok" })
        .collect();
    d.set_item("status", status)?;
    for (k, (name, _)) in METRICS.iter().enumerate() {
        if !metrics.iter().any(|m| m == name) {
            continue;
        }
        let values: Vec<f64> = rows
            .iter()
            .map(|r| r.metric_values()[k].unwrap_or(f64::NAN))
            .collect();
        d.set_item(*name, PyArray1::from_vec(py, values))?;
    }
    let errors: Vec<String> = rows
        .iter()
        .map(|r| r.error.clone().unwrap_or_default())
        .collect();
    d.set_item("error", errors)?;
    Ok(d)
}
