//! One simulation from Python: the command line's run, its samples kept in memory as
//! columns instead of streamed to a CSV.
//!
//! The columns are the CSV's (`camchain_cli::csv::header`, the same names, the same values
//! to the last bit: `csv::row` computes both), each kept contiguous so that `r["q1"]` is a
//! view without a copy. The summary is the command line's (`camchain_cli::summary`), as text
//! and as numbers. The run releases the GIL; every [`POLL`] it takes the GIL back for a
//! moment to let Python see a Ctrl-C (`PyErr_CheckSignals`), and stops within one step
//! when it does. A run's `initial=` values are read here too.

use crate::errors::bad_option;
use camchain_cli::csv;
use camchain_cli::summary::{self, Digest, RunReport};
use camchain_runtime::assembly::AssemblyReport;
use camchain_runtime::events::ContactEvent;
use camchain_runtime::{
    ContactLaw, Dynamics, ModelInfo, Monitor, Observed, Progress, Sample, SimError, SimSettings,
    Simulate, State, Stats,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::time::{Duration, Instant};

/// How often a run lets Python look for a Ctrl-C.
const POLL: Duration = Duration::from_millis(50);

/// What a run is asked to do.
pub struct Request {
    /// Integration and output settings, checked.
    pub settings: SimSettings,
    /// Bilateral, or one-sided with restitution.
    pub law: ContactLaw,
    /// Initial coordinates and velocities replacing the model's guess (every entry; those
    /// the constraints determine are re-solved from them), or None for the model's own
    /// assembly.
    pub initial: Option<(Vec<f64>, Vec<f64>)>,
    /// The run's name in the summary.
    pub label: String,
    /// The path, as the summary's first line names it.
    pub engine: String,
}

/// Why a run stopped early.
pub enum Stop {
    /// The run failed: the message and where.
    Failed { message: String, time: Option<f64> },
    /// Python raised an exception while the run was polled (Ctrl-C).
    Interrupted(PyErr),
}

/// What a run computed.
pub struct RunData {
    /// The CSV's column names.
    pub columns: Vec<String>,
    /// The columns one after the other, each `samples` long.
    pub data: Vec<f64>,
    /// Samples taken.
    pub samples: usize,
    /// The runtime's contact events.
    pub events: Vec<ContactEvent>,
    /// What the summary needs of the samples.
    pub digest: Digest,
    /// Work counters.
    pub stats: Stats,
    /// The command line's summary text (empty when the run stopped early).
    pub text: String,
    /// The assembly line (`assembled: q3 0 → …`), empty when it changed nothing.
    pub assembly: String,
    /// Wall time of assembly and run (s).
    pub wall: f64,
    /// Why it stopped early, if it did.
    pub stop: Option<Stop>,
}

/// Runs the model with the GIL released.
pub fn simulate(py: Python<'_>, dynamics: &(dyn Dynamics + Sync), request: &Request) -> RunData {
    py.detach(|| simulate_detached(dynamics, request))
}

fn simulate_detached(dynamics: &(dyn Dynamics + Sync), request: &Request) -> RunData {
    let info = dynamics.info();
    let columns = csv::header(info);
    let start = Instant::now();
    let mut collector = Collector {
        info,
        columns: vec![Vec::new(); columns.len()],
        digest: Digest::new(info),
        polled: Instant::now(),
        interrupted: None,
    };
    let mut data = RunData {
        columns,
        data: Vec::new(),
        samples: 0,
        events: Vec::new(),
        digest: Digest::new(info),
        stats: Stats::default(),
        text: String::new(),
        assembly: String::new(),
        wall: 0.0,
        stop: None,
    };
    let state = match assemble(dynamics, request) {
        Ok((state, report)) => {
            if let Some(report) = report {
                data.assembly = summary::assembly(info, &report);
            }
            state
        }
        Err(e) => {
            let what = if info.loops.is_empty() {
                "assembly onto the cam failed"
            } else {
                "assembly failed"
            };
            data.stop = Some(Stop::Failed {
                message: format!("{what}: {e}"),
                time: e.time(),
            });
            return data;
        }
    };
    let run = dynamics.simulate_monitored(state, &request.settings, request.law, &mut collector);
    let (trajectory, failure) = match run {
        Ok(trajectory) => (trajectory, None),
        Err(failure) => (failure.partial, Some(failure.error)),
    };
    let wall = start.elapsed();
    let Collector {
        columns,
        digest,
        interrupted,
        ..
    } = collector;
    data.samples = columns.first().map_or(0, Vec::len);
    data.data = columns.concat();
    data.events = trajectory.events;
    data.stats = trajectory.stats;
    data.wall = wall.as_secs_f64();
    data.stop = match (failure, interrupted) {
        (Some(SimError::Interrupted { .. }), Some(e)) => Some(Stop::Interrupted(e)),
        (Some(error), _) => Some(Stop::Failed {
            message: error.to_string(),
            time: error.time(),
        }),
        (None, _) => None,
    };
    if data.stop.is_none() {
        data.text = summary::render(&RunReport {
            label: &request.label,
            engine: &request.engine,
            info,
            settings: &request.settings,
            digest: &digest,
            events: &data.events,
            stats: data.stats,
            wall,
        });
    }
    data.digest = digest;
    data
}

/// The initial state: the model's assembly, or the given values re-solved where the
/// constraints determine them.
fn assemble(
    dynamics: &(dyn Dynamics + Sync),
    request: &Request,
) -> Result<(State, Option<AssemblyReport>), SimError> {
    match &request.initial {
        None => dynamics
            .assemble_reported(0.0)
            .map(|(state, report)| (state, Some(report))),
        Some((q, qd)) => dynamics.state_at(0.0, q, qd).map(|state| (state, None)),
    }
}

/// Keeps every sample's CSV row as columns, digests it for the summary, and lets Python
/// look for signals now and then.
struct Collector<'a> {
    info: &'a ModelInfo,
    columns: Vec<Vec<f64>>,
    digest: Digest,
    polled: Instant,
    interrupted: Option<PyErr>,
}

impl Collector<'_> {
    fn poll(&mut self) -> Observed {
        if self.polled.elapsed() < POLL {
            return Observed::Continue(());
        }
        self.polled = Instant::now();
        match Python::attach(|py| py.check_signals()) {
            Ok(()) => Observed::Continue(()),
            Err(e) => {
                self.interrupted = Some(e);
                Observed::Break(())
            }
        }
    }
}

impl Monitor for Collector<'_> {
    fn sample(&mut self, sample: &Sample) -> Observed {
        self.digest.add(sample);
        for (column, value) in self.columns.iter_mut().zip(csv::row(self.info, sample)) {
            column.push(value);
        }
        self.poll()
    }

    fn step(&mut self, _: &Progress) -> Observed {
        self.poll()
    }

    fn keep_samples(&self) -> bool {
        false
    }
}

/// Initial coordinates and velocities from the model's guess with `{"q1": …, "q1_dot": …}`
/// over it.
pub fn initial_state(
    info: &ModelInfo,
    given: &Bound<'_, PyDict>,
) -> PyResult<(Vec<f64>, Vec<f64>)> {
    let mut q = info.initial.q.clone();
    let mut qd = info.initial.qd.clone();
    for (key, value) in given.iter() {
        let key: String = key
            .extract()
            .map_err(|_| bad_option("initial", "names must be strings"))?;
        let value: f64 = value
            .extract()
            .map_err(|_| bad_option("initial", format!("{key}: not a number")))?;
        if !value.is_finite() {
            return Err(bad_option(
                "initial",
                format!("{key}: {value} is not finite"),
            ));
        }
        let (name, slot) = match key.strip_suffix("_dot") {
            Some(name) if info.coordinate_index(name).is_some() => (name, &mut qd),
            _ => (key.as_str(), &mut q),
        };
        let Some(i) = info.coordinate_index(name) else {
            let names: Vec<&str> = info.coordinates.iter().map(|c| c.name.as_str()).collect();
            return Err(bad_option(
                "initial",
                format!(
                    "no coordinate `{key}`: the model's are {} (and their `_dot` velocities)",
                    names.join(", ")
                ),
            ));
        };
        slot[i] = value;
    }
    Ok((q, qd))
}
