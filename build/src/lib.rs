//! camchain-build: compiles camchain model files into Rust from a build script, in the style
//! of `prost-build`.
//!
//! A crate that simulates its own mechanism keeps its model file (`models/follower.ron`, the
//! format of `docs/model-format.md`) in its own repository, depends on the `camchain` facade
//! and, at build time, on this crate:
//!
//! ```toml
//! [dependencies]
//! camchain = "0.1"
//!
//! [build-dependencies]
//! camchain-build = "0.1"
//! ```
//!
//! Its `build.rs` compiles the model (a file, or every `.ron` file of a directory):
//!
//! ```no_run
//! fn main() -> Result<(), Box<dyn std::error::Error>> {
//!     camchain_build::compile_models(&["models/follower.ron"])?;
//!     Ok(())
//! }
//! ```
//!
//! and its code includes the generated module and simulates it:
//!
//! ```ignore
//! mod follower {
//!     camchain::include_model!("follower");
//! }
//!
//! fn main() -> Result<(), Box<dyn std::error::Error>> {
//!     let model = follower::Model::default();
//!     let mut state = model.assemble()?; // puts every contact point on its cam
//!     model.step(&mut state, 1.0)?; // advances 1 s with the model's integrator
//!     println!("q = {:?}", state.q);
//!     Ok(())
//! }
//! ```
//!
//! The same steps, run here: a model written to a temporary directory, compiled, and the
//! generated module read back (a build script leaves out `out_dir`, which defaults to
//! `$OUT_DIR/camchain`, and keeps the `cargo:rerun-if-changed` lines):
//!
//! ```
//! let dir = std::env::temp_dir().join(format!("camchain-build-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir)?;
//! let model = dir.join("pendulum.ron");
//! std::fs::write(
//!     &model,
//!     r#"(
//!         gravity: (0.0, -9.81, 0.0),
//!         bodies: [(
//!             name: "rod", parent: "ground", mass: 1.0, com: (0.5, 0.0, 0.0),
//!             inertia: Izz(0.083),
//!             joint: (kind: Revolute, axis: (0.0, 0.0, 1.0), anchor: (0.0, 0.0, 0.0),
//!                     coordinate: "theta"),
//!         )],
//!         initial: (q: {"theta": -1.0}),
//!     )"#,
//! )?;
//! let compiled = camchain_build::Config::new()
//!     .out_dir(dir.join("out"))
//!     .emit_rerun_if_changed(false)
//!     .compile_models(&[&model])?;
//! assert_eq!(compiled[0].module, "pendulum"); // the file stem, as no `name:` is given
//! let code = std::fs::read_to_string(&compiled[0].output)?;
//! assert!(code.contains("pub struct Model;"));
//! assert!(code.contains("impl rt::Dynamics for Model"));
//! // A bad value stops the build with the file, line, column and field:
//! std::fs::write(&model, std::fs::read_to_string(&model)?.replace("mass: 1.0", "mass: 0.0"))?;
//! let error = camchain_build::Config::new()
//!     .out_dir(dir.join("out"))
//!     .emit_rerun_if_changed(false)
//!     .compile_models(&[&model])
//!     .unwrap_err();
//! assert!(error.to_string().contains("pendulum.ron:4:50: bodies[0].mass: "), "{error}");
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! What [`compile_models`] does, per model file: reads and validates it (a bad file stops
//! the build with `file:line:column: field: message`, the path as given, relative to the
//! crate), derives the dynamics symbolically, checks that the initial state assembles, and
//! writes the formatted module to `$OUT_DIR/camchain/<model name>.rs`, rewriting it only when
//! its text changes (so an unchanged model does not recompile the crate). It prints
//! `cargo:rerun-if-changed` for every file and directory it was given. The output is
//! deterministic: the same model file gives the same bytes.
//!
//! [`Config`] sets the options: the output directory, how the generated code names the
//! runtime crate, which form the entry points take, the module names, an index file that
//! includes every model, and whether the model file's text is embedded.
//!
//! The generated module refers to the runtime through `use ::camchain::runtime as rt;`, right
//! for a crate that depends on the `camchain` facade; a crate that depends on
//! `camchain-runtime` directly sets [`Config::runtime_path`] to `::camchain_runtime`.

pub use camchain_codegen::ParameterMode;
use camchain_codegen::{EmitOptions, ModelError, generate_source_and_model, read_model_file};
use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

pub use camchain_codegen::{EntryPoints, Formulation};

/// The directory under `OUT_DIR` that [`compile_models`] writes to by default, and that
/// `camchain::include_model!` reads from.
pub const OUT_SUBDIR: &str = "camchain";

/// Compiles model files (or directories of `.ron` files) with the default [`Config`]: one
/// module per model under `$OUT_DIR/camchain/`, included with `camchain::include_model!`.
///
/// # Errors
/// Every model that fails is reported (not only the first) in one [`Error`], whose `Display`
/// and `Debug` both print one `file:line:column: field: message` line per problem.
pub fn compile_models(paths: &[impl AsRef<Path>]) -> Result<Vec<CompiledModel>, Error> {
    Config::new().compile_models(paths)
}

/// Options of [`Config::compile_models`], set with builder methods.
///
/// ```no_run
/// // build.rs
/// fn main() -> Result<(), Box<dyn std::error::Error>> {
///     camchain_build::Config::new()
///         .module_name("follower_v2", "follower")
///         .include_file("models.rs")
///         .compile_models(&["models"])?;
///     Ok(())
/// }
/// ```
#[derive(Debug, Clone)]
pub struct Config {
    out_dir: Option<PathBuf>,
    options: EmitOptions,
    module_names: BTreeMap<String, String>,
    include_file: Option<PathBuf>,
    embed_source: bool,
    rerun_if_changed: bool,
}

impl Default for Config {
    fn default() -> Self {
        Self::new()
    }
}

/// One compiled model.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CompiledModel {
    /// The model's name (the file's `name:` field, or its file stem).
    pub name: String,
    /// The Rust module name (the model name unless [`Config::module_name`] renames it).
    pub module: String,
    /// The model file, as shown in messages.
    pub source: PathBuf,
    /// The generated file.
    pub output: PathBuf,
    /// Warnings about values that are valid but look mistaken (an angle of 90 rad:
    /// degrees?), located like errors; printed as `cargo:warning` lines in a build script.
    pub warnings: Vec<String>,
}

impl Config {
    /// The defaults: output to `$OUT_DIR/camchain/`, runtime path `::camchain::runtime`,
    /// [`EntryPoints::Auto`], modules named after their models, no index file, the model
    /// text not embedded, `cargo:rerun-if-changed` printed.
    pub fn new() -> Self {
        Config {
            out_dir: None,
            options: EmitOptions {
                fused_multiply_add: target_has_fma(),
                ..EmitOptions::default()
            },
            module_names: BTreeMap::new(),
            include_file: None,
            embed_source: false,
            rerun_if_changed: true,
        }
    }

    /// Writes the generated files to `dir` instead of `$OUT_DIR/camchain/` (then include
    /// them with `include!` yourself; `camchain::include_model!` reads the default place).
    pub fn out_dir(&mut self, dir: impl Into<PathBuf>) -> &mut Self {
        self.out_dir = Some(dir.into());
        self
    }

    /// How the generated code names the runtime crate. Default `::camchain::runtime` (the
    /// `camchain` facade's re-export); `::camchain_runtime` for a crate that depends on
    /// `camchain-runtime` directly; `::my_name::runtime` when the facade is renamed in
    /// `Cargo.toml`.
    pub fn runtime_path(&mut self, path: impl Into<String>) -> &mut Self {
        self.options.runtime_path = path.into();
        self
    }

    /// Which form the standalone entry points of the `Dynamics` trait (`mass_matrix`,
    /// `equations`, `constraint`, …) take: their own expressions, holding only the
    /// operations each needs, or calls of the pair `position_terms`/`velocity_terms` that
    /// the simulation's right-hand side uses (less code, faster builds). Default
    /// [`EntryPoints::Auto`]: their own expressions unless the model is large.
    pub fn entry_points(&mut self, entry_points: EntryPoints) -> &mut Self {
        self.options.entry_points = entry_points;
        self
    }

    /// Which forward dynamics the generated code gives the runtime: the dense mass matrix
    /// factored at run time, or the articulated-body sweeps (O(n) per sweep, one more sweep
    /// per constraint row). Default [`Formulation::Auto`]: the one with the smaller
    /// estimated operation count per right-hand side, shown in the generated header with
    /// the other's. A model file's `simulation: (formulation: …)` takes precedence.
    pub fn formulation(&mut self, formulation: Formulation) -> &mut Self {
        self.options.formulation = formulation;
        self
    }

    /// Whether the generated methods write products summed with another term as
    /// `a.mul_add(b, c)` ([`EmitOptions::fused_multiply_add`]). Default: when the crate is
    /// compiled for a processor with FMA instructions (`-C target-cpu=native` on a recent
    /// x86-64, `-C target-feature=+fma`; cargo tells the build script through
    /// `CARGO_CFG_TARGET_FEATURE`), where each fused pair is one instruction and one rounding;
    /// elsewhere `mul_add` would be a call of the C library's `fma`.
    pub fn fused_multiply_add(&mut self, fused: bool) -> &mut Self {
        self.options.fused_multiply_add = fused;
        self
    }

    /// Which parameters the generated code reads at run time: as each file declares
    /// ([`ParameterMode::AsDeclared`], the default: `constant: true` ones folded, the others
    /// in the generated `Parameters`), all folded ([`ParameterMode::FoldAll`]: the code is
    /// what it would be with the numbers written in place), or all at run time
    /// ([`ParameterMode::AllAtRunTime`], for comparisons).
    pub fn parameters(&mut self, mode: ParameterMode) -> &mut Self {
        self.options.parameters = mode;
        self
    }

    /// Names the module of model `model` (its `name:` or file stem) `module` instead: its
    /// file becomes `<module>.rs` and `include_model!("<module>")` includes it.
    pub fn module_name(
        &mut self,
        model: impl Into<String>,
        module: impl Into<String>,
    ) -> &mut Self {
        self.module_names.insert(model.into(), module.into());
        self
    }

    /// Also writes `<out dir>/<name>`, a file that declares one `pub mod` per compiled
    /// model, `ALL`, a table of every model by name, and `OP_COUNTS`, every model's
    /// operation counts (and `SOURCES`, every model's text, and `FILES`, the files each
    /// names, with [`Config::embed_model_source`]), for `include!` in one place:
    /// `include!(concat!(env!("OUT_DIR"), "/camchain/models.rs"));`.
    pub fn include_file(&mut self, name: impl Into<PathBuf>) -> &mut Self {
        self.include_file = Some(name.into());
        self
    }

    /// Embeds each model file's text in its module as `pub const MODEL_SOURCE: &str` (for a
    /// program that also wants the description at run time), and the files it names (its
    /// tables of points) as `pub const MODEL_FILES: &[(&str, &str)]`. Off by default.
    pub fn embed_model_source(&mut self, embed: bool) -> &mut Self {
        self.embed_source = embed;
        self
    }

    /// Whether to print `cargo:rerun-if-changed` lines (on by default; off when calling
    /// from something else than a build script).
    pub fn emit_rerun_if_changed(&mut self, emit: bool) -> &mut Self {
        self.rerun_if_changed = emit;
        self
    }

    /// Compiles every model file of `paths` (files, or directories whose `.ron` files are
    /// taken in name order) and writes their modules.
    ///
    /// # Errors
    /// One [`Error`] listing every problem: model files that do not validate or assemble
    /// (located), unreadable paths, two models with one module name, files that cannot be
    /// written. Nothing is written when a model fails.
    pub fn compile_models(&self, paths: &[impl AsRef<Path>]) -> Result<Vec<CompiledModel>, Error> {
        let out_dir = self.resolved_out_dir()?;
        let files = self.model_files(paths)?;
        let generated = self.generate_all(&files)?;
        write_dir(&out_dir)?;
        let mut compiled = Vec::new();
        let mut problems = Vec::new();
        for (module, (name, shown, warnings), code) in generated {
            let output = out_dir.join(format!("{module}.rs"));
            for warning in &warnings {
                self.cargo_directive("warning", warning);
            }
            match write_if_changed(&output, &code) {
                Ok(()) => compiled.push(CompiledModel {
                    name,
                    module,
                    source: shown,
                    output,
                    warnings,
                }),
                Err(e) => problems.push(Problem::Io(output, e.to_string())),
            }
        }
        if let Some(name) = &self.include_file {
            let index = out_dir.join(name);
            let text = index_file(&compiled, &self.options.runtime_path, self.embed_source);
            if let Err(e) = write_if_changed(&index, &text) {
                problems.push(Problem::Io(index, e.to_string()));
            }
        }
        if problems.is_empty() {
            Ok(compiled)
        } else {
            Err(Error { problems })
        }
    }

    /// `Config::out_dir`, or `$OUT_DIR/camchain`.
    fn resolved_out_dir(&self) -> Result<PathBuf, Error> {
        if let Some(dir) = &self.out_dir {
            return Ok(dir.clone());
        }
        match std::env::var_os("OUT_DIR") {
            Some(dir) => Ok(PathBuf::from(dir).join(OUT_SUBDIR)),
            None => Err(Error::one(Problem::Usage(
                "OUT_DIR is not set: call compile_models from a build script, or set \
                 Config::out_dir"
                    .to_string(),
            ))),
        }
    }

    /// The model files named by `paths`, each with the path its messages show; prints the
    /// `rerun-if-changed` lines.
    fn model_files(&self, paths: &[impl AsRef<Path>]) -> Result<Vec<(PathBuf, PathBuf)>, Error> {
        let mut files = Vec::new();
        let mut problems = Vec::new();
        for path in paths {
            let path = path.as_ref();
            self.rerun_if_changed(path);
            if path.is_dir() {
                match ron_files(path) {
                    Ok(found) => {
                        for file in found {
                            self.rerun_if_changed(&file);
                            files.push(file);
                        }
                    }
                    Err(e) => problems.push(Problem::Io(path.to_path_buf(), e.to_string())),
                }
            } else {
                files.push(path.to_path_buf());
            }
        }
        if !problems.is_empty() {
            return Err(Error { problems });
        }
        Ok(files
            .into_iter()
            .map(|file| {
                let shown = shown_path(&file);
                (file, shown)
            })
            .collect())
    }

    fn rerun_if_changed(&self, path: &Path) {
        self.cargo_directive("rerun-if-changed", &path.display().to_string());
    }

    /// Prints `cargo:<key>=<value>` when running as a build script (see
    /// [`Config::emit_rerun_if_changed`]).
    fn cargo_directive(&self, key: &str, value: &str) {
        if self.rerun_if_changed {
            println!("cargo:{key}={value}");
        }
    }

    /// Generates every model: (module, (model name, shown path, warnings), code), in the
    /// order given.
    #[allow(clippy::type_complexity)]
    fn generate_all(
        &self,
        files: &[(PathBuf, PathBuf)],
    ) -> Result<Vec<(String, (String, PathBuf, Vec<String>), String)>, Error> {
        let mut problems = Vec::new();
        let mut generated = Vec::new();
        let mut owners: BTreeMap<String, PathBuf> = BTreeMap::new();
        for (file, shown) in files {
            match self.generate_one(file, shown) {
                Ok((name, code, warnings)) => {
                    let module = self
                        .module_names
                        .get(&name)
                        .cloned()
                        .unwrap_or(name.clone());
                    if let Err(problem) = check_module_name(&module, &name, shown) {
                        problems.push(problem);
                    } else if let Some(first) = owners.get(&module) {
                        problems.push(Problem::Usage(format!(
                            "{}: module `{module}` is already generated from {}; give this \
                             model its own `name:` (or Config::module_name)",
                            shown.display(),
                            first.display()
                        )));
                    } else {
                        owners.insert(module.clone(), shown.clone());
                        generated.push((module, (name, shown.clone(), warnings), code));
                    }
                }
                Err(e) => problems.push(Problem::Model(e)),
            }
        }
        for model in self.module_names.keys() {
            if !generated.iter().any(|(_, (name, ..), _)| name == model) && problems.is_empty() {
                problems.push(Problem::Usage(format!(
                    "Config::module_name names model `{model}`, which none of the files \
                     compiled defines"
                )));
            }
        }
        if problems.is_empty() {
            Ok(generated)
        } else {
            Err(Error { problems })
        }
    }

    /// Generates one model file: its model name, module text and warnings.
    fn generate_one(
        &self,
        file: &Path,
        shown: &Path,
    ) -> Result<(String, String, Vec<String>), ModelError> {
        let text = read_model_file(file, shown)?;
        let mut options = self.options.clone();
        if self.embed_source {
            options.embedded_source = Some(text.clone());
        }
        options.files_dir = Some(file.parent().unwrap_or(Path::new("")).to_path_buf());
        let (generated, model) = generate_source_and_model(&text, shown, &options)?;
        for named in &model.files {
            self.rerun_if_changed(&named.path);
        }
        let warnings = camchain_codegen::located_warnings(&model, &text, shown)
            .iter()
            .map(ToString::to_string)
            .collect();
        Ok((generated.name, generated.code, warnings))
    }
}

/// The `.ron` files directly in `dir`, in name order.
fn ron_files(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.extension().is_some_and(|x| x == "ron") && path.is_file() {
            files.push(path);
        }
    }
    files.sort();
    Ok(files)
}

/// The path a message shows, as rustc shows source paths: relative to the workspace root
/// of the crate being built (the crate's own directory for a crate that is its own
/// workspace), so that it can be opened from where `cargo build` runs. A file outside it is
/// shown as given.
fn shown_path(file: &Path) -> PathBuf {
    let Some(manifest) = std::env::var_os("CARGO_MANIFEST_DIR").map(PathBuf::from) else {
        return file.to_path_buf();
    };
    let absolute = normalize(&manifest.join(file));
    let root = workspace_root(&manifest);
    match absolute.strip_prefix(&root) {
        Ok(inside) => inside.to_path_buf(),
        Err(_) => file.to_path_buf(),
    }
}

/// The nearest directory at or above `manifest_dir` whose `Cargo.toml` has a `[workspace]`
/// table (how cargo finds a workspace root), or `manifest_dir` itself.
fn workspace_root(manifest_dir: &Path) -> PathBuf {
    manifest_dir
        .ancestors()
        .find(|dir| {
            std::fs::read_to_string(dir.join("Cargo.toml"))
                .is_ok_and(|text| text.lines().any(|l| l.trim() == "[workspace]"))
        })
        .unwrap_or(manifest_dir)
        .to_path_buf()
}

/// `a/./b/../c` → `a/c`, without touching the file system.
fn normalize(path: &Path) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// A module name must be a Rust identifier that is not a keyword.
fn check_module_name(module: &str, model: &str, shown: &Path) -> Result<(), Problem> {
    if camchain_codegen::schema::is_identifier(module) {
        Ok(())
    } else {
        Err(Problem::Usage(format!(
            "{}: model `{model}` gives the module name `{module}`, which is not a Rust \
             identifier (letters, digits and `_`, not starting with a digit, not a keyword); \
             rename it with `name:` or Config::module_name",
            shown.display()
        )))
    }
}

/// The index file: one `pub mod` per model, including its file (relative to the index,
/// which sits beside them), and the table `ALL` of every model by name.
fn index_file(compiled: &[CompiledModel], runtime_path: &str, sources: bool) -> String {
    let mut text = String::from(
        "// Generated by camchain-build: every model of this build, one module each.\n\
         // Do not edit: change the model files and rebuild.\n\n",
    );
    for model in compiled {
        text.push_str(&format!(
            "/// The model `{}`, generated from `{}`.\npub mod {} {{\n    include!(\"{}.rs\");\n}}\n\n",
            model.name,
            model.source.display().to_string().replace('\\', "/"),
            model.module,
            model.module
        ));
    }
    text.push_str(&format!(
        "/// Every model of this build by name, in the order compiled, with the file's \
         parameter values.\n\
         pub static ALL: ::std::sync::LazyLock<Vec<(&str, &(dyn {runtime_path}::Dynamics + Sync))>> =\n\
         ::std::sync::LazyLock::new(|| {{\n    Vec::from([\n"
    ));
    for model in compiled {
        text.push_str(&format!(
            "        ({:?}, &*{}::DEFAULT as &(dyn {runtime_path}::Dynamics + Sync)),\n",
            model.name, model.module
        ));
    }
    text.push_str("    ])\n});\n\n");
    text.push_str(&format!(
        "/// A model built with other parameter values: `(name, value)` pairs over the file's \
         values, checked as the build checks the file.\n\
         pub type Constructor = fn(&[(&str, f64)]) -> Result<Box<dyn {runtime_path}::Dynamics + Send + Sync>, {runtime_path}::ParameterError>;\n\n\
         /// Every model of this build by name, with its [`Constructor`].\n\
         pub static WITH_PARAMETERS: &[(&str, Constructor)] = &[\n"
    ));
    for model in compiled {
        text.push_str(&format!(
            "    ({:?}, {}::boxed),\n",
            model.name, model.module
        ));
    }
    text.push_str("];\n\n");
    text.push_str(
        "/// One generated function's operation counts: its name, then add/sub, mul, div, \
         sin/cos, sqrt, other.\n\
         pub type OpCountRow = (&'static str, [usize; 6]);\n\n\
         /// The operation counts of every model's generated functions (the table in each \
         module's header).\n\
         pub static OP_COUNTS: &[(&str, &[OpCountRow])] = &[\n",
    );
    for model in compiled {
        text.push_str(&format!(
            "    ({:?}, {}::OP_COUNTS),\n",
            model.name, model.module
        ));
    }
    text.push_str("];\n");
    if sources {
        text.push_str(
            "\n/// Every model's file text by name (`Config::embed_model_source`).\n\
             pub static SOURCES: &[(&str, &str)] = &[\n",
        );
        for model in compiled {
            text.push_str(&format!(
                "    ({:?}, {}::MODEL_SOURCE),\n",
                model.name, model.module
            ));
        }
        text.push_str("];\n");
        text.push_str(
            "\n/// The files every model names (its tables of points) by model name: (the path \
             the model writes, the text) (`Config::embed_model_source`).\n\
             pub static FILES: &[(&str, &[(&str, &str)])] = &[\n",
        );
        for model in compiled {
            text.push_str(&format!(
                "    ({:?}, {}::MODEL_FILES),\n",
                model.name, model.module
            ));
        }
        text.push_str("];\n");
    }
    text
}

/// Creates the output directory.
fn write_dir(dir: &Path) -> Result<(), Error> {
    std::fs::create_dir_all(dir)
        .map_err(|e| Error::one(Problem::Io(dir.to_path_buf(), e.to_string())))
}

/// Writes only when the content differs, so unchanged models do not trigger recompilation.
fn write_if_changed(path: &Path, content: &str) -> std::io::Result<()> {
    if std::fs::read_to_string(path).is_ok_and(|old| old == content) {
        return Ok(());
    }
    std::fs::write(path, content)
}

/// Why [`compile_models`] failed: every problem found, one per line.
///
/// `Debug` prints the same lines as `Display`, so that a build script's
/// `fn main() -> Result<(), Box<dyn Error>>` shows them as they are.
pub struct Error {
    problems: Vec<Problem>,
}

/// One problem of a build.
#[derive(Debug, Clone, PartialEq)]
enum Problem {
    /// A model file that does not validate or assemble.
    Model(ModelError),
    /// A file or directory that cannot be read or written.
    Io(PathBuf, String),
    /// A wrong use of the API (e.g. two models with one module name).
    Usage(String),
}

impl Error {
    fn one(problem: Problem) -> Self {
        Error {
            problems: vec![problem],
        }
    }

    /// The located model errors among the problems (for tools and tests).
    pub fn model_errors(&self) -> impl Iterator<Item = &ModelError> {
        self.problems.iter().filter_map(|p| match p {
            Problem::Model(e) => Some(e),
            _ => None,
        })
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (k, problem) in self.problems.iter().enumerate() {
            if k > 0 {
                writeln!(f)?;
            }
            match problem {
                Problem::Model(e) => write!(f, "{e}")?,
                Problem::Io(path, e) => write!(f, "{}: {e}", path.display())?,
                Problem::Usage(message) => f.write_str(message)?,
            }
        }
        Ok(())
    }
}

impl fmt::Debug for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

impl std::error::Error for Error {}

/// Whether the build script's target has FMA instructions enabled at compile time (cargo
/// sets `CARGO_CFG_TARGET_FEATURE` for build scripts: the target's features, comma-separated).
fn target_has_fma() -> bool {
    std::env::var("CARGO_CFG_TARGET_FEATURE").is_ok_and(|f| f.split(',').any(|x| x == "fma"))
}
