//! Which model a MODEL argument names, and on which path it runs.
//!
//! A MODEL is a built-in model's name (`paper_concave`) or a path to a `.ron` file (it ends
//! in `.ron` or contains a path separator). Built-in models run their generated code unless
//! `--numeric` is given; files always run on the numeric recursive reference, which needs no
//! rebuild. The validated model description is kept too, for drawing the mechanism.

use super::CliError;
use super::kinematics::Geometry;
use camchain_codegen::ParameterMode;
use camchain_codegen::model::Model;
use camchain_codegen::schema::{Files, parse_model_from, read_text};
use camchain_models as models;
use camchain_reference::NumericModel;
use camchain_runtime::Dynamics;
use std::path::{Path, PathBuf};

/// Where a run's dynamics come from.
pub enum Engine {
    /// Code generated at build time (`camchain_models::<name>`).
    Generated(&'static (dyn Dynamics + Sync)),
    /// Generated code built with other run-time parameter values.
    Parametrised(Box<dyn Dynamics + Send + Sync>),
    /// The numeric recursive Newton–Euler reference on a model loaded at run time.
    Numeric(Box<NumericModel>),
}

impl Engine {
    /// The model as the runtime sees it.
    pub fn dynamics(&self) -> &dyn Dynamics {
        match self {
            Engine::Generated(model) => *model,
            Engine::Parametrised(model) => model.as_ref(),
            Engine::Numeric(model) => model.as_ref(),
        }
    }

    /// True on the numeric recursive path.
    pub fn is_numeric(&self) -> bool {
        matches!(self, Engine::Numeric(_))
    }

    /// How the summary names the path.
    pub fn describe(&self) -> &'static str {
        match self {
            Engine::Generated(_) | Engine::Parametrised(_) => "generated code",
            Engine::Numeric(_) => "numeric recursive reference (no rebuild)",
        }
    }
}

/// A model ready to run.
pub struct LoadedModel {
    /// The model's name (from the file, or the built-in name).
    pub name: String,
    /// The run's name in file names and the summary: a built-in model's name (with
    /// `_numeric` appended on the numeric path), or a model file's name without `.ron`.
    pub label: String,
    /// Where the model comes from, as messages name it: the file as given, or the name of
    /// a built-in model.
    pub origin: String,
    /// The dynamics to integrate.
    pub engine: Engine,
    /// The geometry for drawing snapshots, or why it is not available.
    pub geometry: Result<Geometry, String>,
    /// Warnings about values that look mistaken, located in the model file.
    pub warnings: Vec<String>,
}

/// How messages name a built-in model's file (`models/<name>.ron` of the repository; its
/// text is compiled into the binary, so the binary needs no source tree).
pub fn builtin_file(name: &str) -> PathBuf {
    Path::new("models").join(format!("{name}.ron"))
}

/// Where a built-in model's named files (its tables of points) are: compiled into the
/// binary with its text.
pub fn builtin_files(name: &str) -> Files<'static> {
    Files::Embedded(models::files(name))
}

/// The validated description of a built-in model, parsed from the text compiled into the
/// binary (for drawing it and for `--numeric`).
pub fn builtin_description(name: &str) -> Result<Model, CliError> {
    let source =
        models::source(name).ok_or_else(|| CliError::Usage(format!("unknown model `{name}`")))?;
    let (overrides, mode) = (&[], ParameterMode::AsDeclared);
    parse_model_from(
        source,
        &builtin_file(name),
        overrides,
        mode,
        builtin_files(name),
    )
    .map_err(|e| {
        let text = e.to_string().replace('\n', " ");
        CliError::Failed(format!("invalid built-in model: {text}"))
    })
}

/// True when the argument is to be read as a path rather than a built-in name.
fn looks_like_path(arg: &str) -> bool {
    arg.ends_with(".ron") || arg.contains('/') || arg.contains(std::path::MAIN_SEPARATOR)
}

/// [`load`] with run-time parameters set to other values (`--param`): a built-in model's
/// generated code is built with them (a parameter it folds, or a value its checks refuse, is
/// a usage error naming the model file's field); on the numeric path the file is validated
/// again with them, and every parameter can be set.
pub fn load_with(
    arg: &str,
    numeric: bool,
    values: &[(String, f64)],
) -> Result<LoadedModel, CliError> {
    if values.is_empty() {
        return load(arg, numeric);
    }
    let given = |e: String| {
        let names: Vec<String> = values.iter().map(|(n, v)| format!("{n}={v}")).collect();
        CliError::Usage(format!("--param {}: {e}", names.join(" ")))
    };
    if !looks_like_path(arg) && !numeric {
        let mut loaded = load(arg, false)?;
        let constructor = models::WITH_PARAMETERS
            .iter()
            .find(|(n, _)| *n == arg)
            .map(|(_, c)| *c)
            .ok_or_else(|| CliError::Failed(format!("{arg} has no constructor")))?;
        let pairs: Vec<(&str, f64)> = values.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        let model = constructor(&pairs).map_err(|e| {
            // The generated code names the folded parameters itself ("is constant", or the
            // list of constants after those it knows); the numeric path can set them all.
            let hint = if e.message.contains("is constant") {
                ", or set it on the numeric reference (--numeric)"
            } else if e.message.contains("folded into") {
                "; the numeric reference (--numeric) sets the constant ones too"
            } else {
                ""
            };
            given(format!("{e}{hint}"))
        })?;
        loaded.engine = Engine::Parametrised(model);
        loaded.geometry = described_with(arg, values).and_then(|m| Geometry::new(&m));
        return Ok(loaded);
    }
    let (source, file, files) = if looks_like_path(arg) {
        let file = PathBuf::from(arg);
        let source = read_text(&file).map_err(|e| {
            CliError::Failed(format!("cannot read model file {}: {e}", file.display()))
        })?;
        (source, file, Files::BesideModel)
    } else {
        let source =
            models::source(arg).ok_or_else(|| CliError::Usage(format!("unknown model `{arg}`")))?;
        (source.to_string(), builtin_file(arg), builtin_files(arg))
    };
    // The file as the build checks it first (its own values), then with the given ones.
    let mut loaded = load(arg, numeric)?;
    let model = parse_model_from(&source, &file, values, ParameterMode::AllAtRunTime, files)
        .map_err(|e| given(e.to_string().replace('\n', " ")))?;
    loaded.geometry = Geometry::new(&model);
    loaded.engine = Engine::Numeric(Box::new(NumericModel::new(model)));
    Ok(loaded)
}

/// A built-in model's description with other parameter values (for drawing it).
fn described_with(name: &str, values: &[(String, f64)]) -> Result<Model, String> {
    let source = models::source(name).ok_or_else(|| format!("unknown model `{name}`"))?;
    parse_model_from(
        source,
        &builtin_file(name),
        values,
        ParameterMode::AllAtRunTime,
        builtin_files(name),
    )
    .map_err(|e| e.to_string())
}

/// Resolves one MODEL argument. An unknown name is a usage error; a file that cannot be
/// read or does not validate is a failure.
pub fn load(arg: &str, numeric: bool) -> Result<LoadedModel, CliError> {
    if !looks_like_path(arg) {
        let Some(model) = models::by_name(arg) else {
            return Err(CliError::Usage(format!(
                "unknown model `{arg}`: built-in models are {} (or give a path to a .ron file)",
                builtin_names().join(", ")
            )));
        };
        return if numeric {
            let mut loaded = numeric_model(builtin_description(arg)?, Vec::new());
            loaded.label = format!("{arg}_numeric");
            loaded.origin = arg.to_string();
            Ok(loaded)
        } else {
            Ok(generated(arg, model))
        };
    }
    from_file(Path::new(arg))
}

/// Names of the built-in models.
pub fn builtin_names() -> Vec<&'static str> {
    models::ALL.iter().map(|(name, _)| *name).collect()
}

fn generated(name: &str, model: &'static (dyn Dynamics + Sync)) -> LoadedModel {
    let geometry = builtin_description(name)
        .map_err(|e| e.to_string())
        .and_then(|m| Geometry::new(&m));
    LoadedModel {
        name: name.to_string(),
        label: name.to_string(),
        origin: name.to_string(),
        engine: Engine::Generated(model),
        geometry,
        warnings: Vec::new(),
    }
}

/// A model file on the numeric path, checked as the build checks it (located errors,
/// assembly of the initial state included), and named after the file.
fn from_file(file: &Path) -> Result<LoadedModel, CliError> {
    let (model, warnings) = read_model(file)?;
    let mut loaded = numeric_model(model, warnings);
    loaded.label = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| loaded.name.clone());
    loaded.origin = file.display().to_string();
    Ok(loaded)
}

/// A validated model on the numeric path (label and origin set by the caller).
fn numeric_model(model: Model, warnings: Vec<String>) -> LoadedModel {
    let geometry = Geometry::new(&model);
    let name = model.name.clone();
    LoadedModel {
        label: name.clone(),
        origin: String::new(),
        name,
        engine: Engine::Numeric(Box::new(NumericModel::new(model))),
        geometry,
        warnings,
    }
}

/// Reads a model file and checks it as the build does (`camchain_codegen::check_source`:
/// the format, every value, the expressions and the assembly of the initial state);
/// returns it with its warnings. Errors are one line, located in the file when the problem
/// is in its content.
fn read_model(file: &Path) -> Result<(Model, Vec<String>), CliError> {
    if file.is_dir() {
        return Err(CliError::Failed(format!(
            "cannot read model file {}: it is a directory, not a .ron file",
            file.display()
        )));
    }
    // Bounded: a device or a huge file is refused, not read until memory runs out.
    let source = read_text(file)
        .map_err(|e| CliError::Failed(format!("cannot read model file {}: {e}", file.display())))?;
    // The same `file:line:column: field: message` as the build and `camchain ops`.
    let model = camchain_codegen::check_source(&source, file)
        .map_err(|e| CliError::Failed(e.to_string().replace('\n', " ")))?;
    let warnings = camchain_codegen::located_warnings(&model, &source, file)
        .iter()
        .map(ToString::to_string)
        .collect();
    Ok((model, warnings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_paths_are_told_apart() {
        assert!(looks_like_path("my_cam.ron"));
        assert!(looks_like_path("dir/model"));
        assert!(!looks_like_path("paper_concave"));
    }

    #[test]
    fn a_builtin_runs_generated_code_unless_numeric() {
        let generated = load("paper_concave", false).unwrap_or_else(|_| panic!("built in"));
        assert!(!generated.engine.is_numeric());
        assert_eq!(generated.label, "paper_concave");
        assert!(generated.geometry.is_ok());
        let numeric = load("paper_concave", true).unwrap_or_else(|_| panic!("built in"));
        assert!(numeric.engine.is_numeric());
        assert_eq!(numeric.label, "paper_concave_numeric");
        assert_eq!(
            numeric.engine.dynamics().info(),
            generated.engine.dynamics().info()
        );
    }

    #[test]
    fn a_model_file_beyond_the_size_limit_is_refused_unread() {
        // A sparse file of 1 GiB: refused from its length, on every path that reads a model
        // file (the numeric reference, and with run-time parameter values).
        let dir = std::env::temp_dir().join(format!("camchain-cli-huge-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a temporary directory");
        let path = dir.join("huge.ron");
        std::fs::File::create(&path)
            .and_then(|f| f.set_len(1 << 30))
            .expect("a sparse file");
        let arg = path.to_string_lossy().into_owned();
        let values = [("k".to_string(), 1.0)];
        for result in [
            load(&arg, false),
            load(&arg, true),
            load_with(&arg, true, &values),
        ] {
            match result {
                Err(CliError::Failed(message)) => assert!(
                    message.contains(&arg) && message.contains("more than 16 MiB"),
                    "{message}"
                ),
                _ => panic!("refused"),
            }
        }
        std::fs::remove_dir_all(&dir).expect("cleaned up");
    }

    #[test]
    fn unknown_names_are_usage_errors() {
        assert!(matches!(
            load("no_such_model", false),
            Err(CliError::Usage(_))
        ));
        assert!(matches!(
            load("no/such/file.ron", false),
            Err(CliError::Failed(_))
        ));
    }
}
