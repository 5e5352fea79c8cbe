//! Which model a `camchain.Model` is, and its dynamics with given parameter values.
//!
//! The same resolution as the command line's `MODEL` argument (`camchain_cli`'s `source`
//! module), keeping the located errors whole (file, line, column, field) rather than as a
//! line of text, so that Python sees them as attributes:
//! - a built-in model by name runs its generated code (compiled into the package), or the
//!   numeric reference on its embedded file with `numeric=True`;
//! - a model file runs on the numeric recursive reference (no compilation), checked as the
//!   build checks it (its format, values, expressions and the assembly of its initial state).
//!
//! Parameter values are set as `camchain simulate --param` sets them: generated code is
//! built again with them through the model's constructor (a folded parameter or a refused
//! value is a located error); on the numeric path the file is validated again with them, and
//! every parameter, folded or not, can be set.

use crate::build_model::library::Loaded;
use crate::errors::Location;
use camchain_codegen::ParameterMode;
use camchain_codegen::model::Model;
use camchain_codegen::schema::{Files, parse_model_from, read_text};
use camchain_models as models;
use camchain_reference::NumericModel;
use camchain_runtime::{Dynamics, ModelInfo};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where a model comes from.
#[derive(Clone)]
pub enum Origin {
    /// A built-in model by name, on its generated code or (`numeric`) on the reference.
    Builtin { name: String, numeric: bool },
    /// A model file, on the numeric reference.
    File(PathBuf),
    /// A model file compiled by `camchain.compile`: its library, and its description
    /// (the numeric reference's of the same file: the same derivation's).
    Compiled {
        path: PathBuf,
        loaded: Arc<Loaded>,
        info: Arc<ModelInfo>,
    },
}

/// Dynamics a run can use from any thread.
#[derive(Clone)]
pub enum Engine {
    /// A built-in model's generated code, the package's static copy.
    Static(&'static (dyn Dynamics + Sync)),
    /// Generated code built with other parameter values, or the numeric reference.
    Shared(Arc<dyn Dynamics + Send + Sync>),
}

impl Engine {
    /// The model as the runtime sees it.
    pub fn get(&self) -> &(dyn Dynamics + Sync) {
        match self {
            Engine::Static(model) => *model,
            Engine::Shared(model) => model.as_ref(),
        }
    }
}

impl Origin {
    /// How messages and results name the model: its name, or the file as given.
    pub fn describe(&self) -> String {
        match self {
            Origin::Builtin { name, .. } => name.clone(),
            Origin::File(path) | Origin::Compiled { path, .. } => path.display().to_string(),
        }
    }

    /// True on the numeric recursive reference.
    pub fn numeric(&self) -> bool {
        matches!(
            self,
            Origin::File(_) | Origin::Builtin { numeric: true, .. }
        )
    }

    /// The model's text, the path its messages show and where its named files are.
    fn source(&self) -> Result<(String, PathBuf, Files<'static>), Location> {
        match self {
            Origin::Builtin { name, .. } => {
                let text =
                    models::source(name).ok_or_else(|| Location::unlocated(name, unknown(name)))?;
                let file = Path::new("models").join(format!("{name}.ron"));
                Ok((text.to_string(), file, Files::Embedded(models::files(name))))
            }
            Origin::File(path) | Origin::Compiled { path, .. } => {
                if path.is_dir() {
                    let message = "it is a directory, not a .ron file".to_string();
                    return Err(Location::unlocated(&path.display().to_string(), message));
                }
                // Bounded: a device or a huge file is refused, not read until memory runs out.
                let text = read_text(path).map_err(|e| {
                    Location::unlocated(&path.display().to_string(), format!("cannot read: {e}"))
                })?;
                Ok((text, path.clone(), Files::BesideModel))
            }
        }
    }

    /// The validated model description with the file's own values, and the warnings about
    /// values that look mistaken.
    pub fn describe_model(&self) -> Result<(Model, Vec<String>), Location> {
        let (source, file, files) = self.source()?;
        let model = match self {
            Origin::Builtin { .. } => {
                parse_model_from(&source, &file, &[], ParameterMode::AsDeclared, files)?
            }
            // As the build checks it: the format, values, expressions and assembly.
            Origin::File(_) | Origin::Compiled { .. } => {
                camchain_codegen::check_source(&source, &file)?
            }
        };
        let warnings = camchain_codegen::located_warnings(&model, &source, &file)
            .iter()
            .map(ToString::to_string)
            .collect();
        Ok((model, warnings))
    }

    /// The dynamics with the file's values.
    pub fn dynamics(&self, model: &Model) -> Result<Engine, Location> {
        match self {
            Origin::Builtin {
                name,
                numeric: false,
            } => {
                let generated = models::by_name(name)
                    .ok_or_else(|| Location::unlocated(name, unknown(name)))?;
                Ok(Engine::Static(generated))
            }
            Origin::Compiled { loaded, info, .. } => {
                Ok(Engine::Shared(Arc::new(loaded.instance(info, &[])?)))
            }
            _ => Ok(Engine::Shared(Arc::new(NumericModel::new(model.clone())))),
        }
    }

    /// The dynamics with other values of some parameters (`values` over the file's).
    pub fn with_parameters(&self, values: &[(String, f64)]) -> Result<Engine, Location> {
        if let Origin::Builtin {
            name,
            numeric: false,
        } = self
        {
            let constructor = models::WITH_PARAMETERS
                .iter()
                .find(|(n, _)| n == name)
                .map(|(_, c)| *c)
                .ok_or_else(|| Location::unlocated(name, unknown(name)))?;
            let pairs: Vec<(&str, f64)> = values.iter().map(|(n, v)| (n.as_str(), *v)).collect();
            let model = constructor(&pairs).map_err(|e| {
                let mut location = Location::from(e);
                // The numeric path sets the folded parameters too.
                if location.message.contains("is constant")
                    || location.message.contains("folded into")
                {
                    location.message.push_str(
                        " (Model(name, numeric=True) runs the numeric reference, which sets \
                         every parameter)",
                    );
                }
                location
            })?;
            return Ok(Engine::Shared(Arc::from(model)));
        }
        if let Origin::Compiled { loaded, info, .. } = self {
            return Ok(Engine::Shared(Arc::new(loaded.instance(info, values)?)));
        }
        let (source, file, files) = self.source()?;
        let model = parse_model_from(&source, &file, values, ParameterMode::AllAtRunTime, files)?;
        Ok(Engine::Shared(Arc::new(NumericModel::new(model))))
    }
}

/// The message for a name that is no built-in model.
pub fn unknown(name: &str) -> String {
    format!(
        "unknown model `{name}`: built-in models are {} (or give a model file to \
         Model.from_file)",
        names().join(", ")
    )
}

/// The built-in models' names.
pub fn names() -> Vec<&'static str> {
    models::ALL.iter().map(|(name, _)| *name).collect()
}
