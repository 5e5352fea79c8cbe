//! A case of the stress suite: one model and initial state run with every integration of a
//! list, and the results of those runs.

use super::{failed, say};
use crate::CliError;
use crate::scenarios::{self as stress, Integration, Record};
use camchain_codegen::model::Model;
use camchain_models as models;
use camchain_reference::NumericModel;
use camchain_runtime::{Dynamics, IntegratorKind, SimError, State, Trajectory};

/// Tolerance of the reference runs that errors are measured against.
pub(super) const REFERENCE_RTOL: f64 = 1e-12;

/// The model of a case: generated code, or the numeric reference on a variant.
pub(super) enum Subject {
    Generated(&'static (dyn Dynamics + Sync)),
    Numeric(Box<NumericModel>),
}

impl Subject {
    pub(super) fn dynamics(&self) -> &dyn Dynamics {
        match self {
            Subject::Generated(model) => *model,
            Subject::Numeric(model) => model.as_ref(),
        }
    }
}

/// One model and initial state run with every integration of a list.
pub(super) struct Case {
    pub(super) title: String,
    pub(super) subject: Subject,
    pub(super) state: State,
    pub(super) integrations: Vec<Integration>,
    /// Compare with a run at [`REFERENCE_RTOL`] (where the solution is smooth and
    /// reproducible over the span).
    pub(super) reference: bool,
}

/// The results of a case.
pub(super) struct CaseResult {
    pub(super) title: String,
    pub(super) records: Vec<Record>,
    pub(super) reference: Option<Trajectory>,
}

pub(super) fn paper(name: &str) -> Result<Model, CliError> {
    stress::builtin_model(name).map_err(failed)
}

pub(super) fn numeric_case(
    title: &str,
    model: Model,
    integrations: Vec<Integration>,
    reference: bool,
) -> Result<Case, CliError> {
    let model = NumericModel::new(model);
    let state = stress::assemble(&model).map_err(failed)?;
    Ok(Case {
        title: title.to_string(),
        subject: Subject::Numeric(Box::new(model)),
        state,
        integrations,
        reference,
    })
}

pub(super) fn generated_case(
    title: &str,
    name: &str,
    integrations: Vec<Integration>,
) -> Result<Case, CliError> {
    let model = models::by_name(name).ok_or_else(|| failed(format!("no built-in {name}")))?;
    let state = stress::assemble(model).map_err(failed)?;
    Ok(Case {
        title: title.to_string(),
        subject: Subject::Generated(model),
        state,
        integrations,
        reference: false,
    })
}

/// Runs every integration of the case (and its reference), printing one line per run.
pub(super) fn execute(case: &Case) -> CaseResult {
    let model = case.subject.dynamics();
    let reference = case.reference.then(|| {
        let settings = case.integrations.first().map(|i| &i.settings);
        let (t_end, dt_out) = settings.map_or((1.0, 0.01), |s| (s.t_end, s.dt_out));
        let tight = Integration {
            label: "reference".into(),
            settings: stress::adaptive(IntegratorKind::Dopri5, t_end, dt_out, REFERENCE_RTOL),
        };
        stress::run(model, &case.state, &tight).trajectory
    });
    let mut records = Vec::new();
    for integration in &case.integrations {
        let record = stress::run(model, &case.state, integration);
        say(&format!(
            "  {:<44} {:<18} {:>9.3} s  {}\n",
            case.title,
            integration.label,
            record.wall.as_secs_f64(),
            match &record.error {
                None => "ok".to_string(),
                Some(e) => kind(e).to_string(),
            }
        ));
        records.push(record);
    }
    CaseResult {
        title: case.title.clone(),
        records,
        reference,
    }
}

/// The name of an error's variant.
pub(super) fn kind(error: &SimError) -> &'static str {
    error.kind()
}

/// The time an error happened at (NaN for invalid settings).
pub(super) fn error_time(error: &SimError) -> f64 {
    error.time().unwrap_or(f64::NAN)
}
