//! The model a sweep runs, and the swept parameters checked against its declarations: a
//! built-in model's generated code (or, with `--numeric`, its file on the reference), or a
//! model file on the numeric reference.

use super::{Factory, spec};
use crate::CliError;
use crate::args::SweepArgs;
use crate::source::{builtin_description, builtin_file, builtin_files, builtin_names};
use camchain_codegen::ParameterMode;
use camchain_codegen::schema::Files;
use camchain_models as models;
use camchain_reference::NumericModel;
use camchain_runtime::{Dynamics, ParameterInfo, SimSettings};
use std::path::{Path, PathBuf};

/// The model: its name, label, factory, run-time parameters, folded parameters' names and
/// default settings.
pub(super) type Resolved = (
    String,
    String,
    Factory,
    Vec<ParameterInfo>,
    Vec<String>,
    SimSettings,
);

pub(super) fn resolve_model(args: &SweepArgs) -> Result<Resolved, CliError> {
    let arg = args.model.as_str();
    let is_path =
        arg.ends_with(".ron") || arg.contains('/') || arg.contains(std::path::MAIN_SEPARATOR);
    if !is_path {
        let Some(generated) = models::by_name(arg) else {
            return Err(CliError::Usage(format!(
                "unknown model `{arg}`: built-in models are {} (or give a path to a .ron file)",
                builtin_names().join(", ")
            )));
        };
        if args.numeric {
            let source = models::source(arg).unwrap_or_default().to_string();
            let file = builtin_file(arg);
            let label = format!("{arg}_numeric");
            return numeric(arg.to_string(), label, source, file, builtin_files(arg));
        }
        let constructor = models::WITH_PARAMETERS
            .iter()
            .find(|(n, _)| *n == arg)
            .map(|(_, c)| *c)
            .ok_or_else(|| CliError::Failed(format!("{arg} has no constructor")))?;
        let folded = builtin_description(arg)?
            .parameters
            .iter()
            .filter(|p| p.constant)
            .map(|p| p.name.clone())
            .collect();
        let info = generated.info();
        return Ok((
            arg.to_string(),
            arg.to_string(),
            Factory::Generated { constructor },
            info.parameters.clone(),
            folded,
            info.defaults.clone(),
        ));
    }
    let path = Path::new(arg);
    let source = camchain_codegen::schema::read_text(path)
        .map_err(|e| CliError::Failed(format!("cannot read {}: {e}", path.display())))?;
    let label = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "model".to_string());
    numeric(
        label.clone(),
        label,
        source,
        path.to_path_buf(),
        Files::BesideModel,
    )
}

/// A model on the numeric reference: validated once now with its file's values.
pub(super) fn numeric(
    name: String,
    label: String,
    source: String,
    file: PathBuf,
    files: Files<'static>,
) -> Result<Resolved, CliError> {
    let checked = camchain_codegen::check_source_in(&source, &file, files)
        .map_err(|e| CliError::Failed(e.to_string().replace('\n', " ")))?;
    let mode = ParameterMode::AllAtRunTime;
    let model = NumericModel::from_source_in(&source, &file, &[], mode, files)
        .map_err(|e| CliError::Failed(e.to_string()))?;
    let info = model.info();
    let structural = checked
        .parameters
        .iter()
        .filter(|p| !info.parameters.iter().any(|q| q.name == p.name))
        .map(|p| p.name.clone())
        .collect();
    let (parameters, defaults) = (info.parameters.clone(), info.defaults.clone());
    let name = if checked.name.is_empty() {
        name
    } else {
        checked.name
    };
    Ok((
        name,
        label,
        Factory::Numeric {
            source,
            file,
            files,
        },
        parameters,
        structural,
        defaults,
    ))
}

/// A swept parameter must be one of the model's run-time parameters, every value within its
/// declared bounds.
pub(super) fn check_parameter(
    model: &str,
    swept: &spec::Swept,
    declared: &[ParameterInfo],
    folded: &[String],
    numeric: bool,
) -> Result<(), CliError> {
    let Some(p) = declared.iter().find(|p| p.name == swept.name) else {
        let message = if folded.contains(&swept.name) && !numeric {
            format!(
                "--param {}: `{}` is folded into {model}'s generated code (constant: true in \
                 its file); sweep it on the numeric reference (--numeric), or remove \
                 `constant: true` and rebuild",
                swept.name, swept.name
            )
        } else if folded.contains(&swept.name) {
            format!(
                "--param {}: `{}` fixes a joint or cam axis (a field that must be constant)",
                swept.name, swept.name
            )
        } else {
            let mut known: Vec<&str> = declared.iter().map(|p| p.name.as_str()).collect();
            known.sort_unstable();
            let known = if known.is_empty() {
                "it has none".to_string()
            } else {
                format!("they are {}", known.join(", "))
            };
            format!(
                "--param {}: {model} has no run-time parameter `{}` ({known})",
                swept.name, swept.name
            )
        };
        return Err(CliError::Usage(message));
    };
    for value in swept.extremes() {
        let range = (p.min, p.max);
        if let Err((_, message)) = camchain_runtime::parameters::checks::within_bounds(
            &p.name,
            value,
            range,
            &format!("{} = {value}", p.name),
        ) {
            return Err(CliError::Usage(format!(
                "--param {}={}: {message}",
                swept.name, swept.spec
            )));
        }
    }
    Ok(())
}
