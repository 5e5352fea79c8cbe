//! Emission of the generated Rust module.
//!
//! Each generated function is emitted from the roots it needs only, so it contains only the
//! operations its outputs depend on. Inside a function every node used more than once (and
//! every sine, cosine or other call) gets a named `let` binding, computed once; nodes used
//! once are written inline. Bindings come in creation order, grouped under comments naming
//! the body and term they belong to. The text is formatted by `prettyplease`; the same
//! model always gives the same bytes.

use crate::contact::ContactTerms;
use crate::derive::Derivation;
use crate::expr::{Graph, Id, Node, OpCount};
use crate::model::{JointKind, Model};
use crate::profile::{Func, TabulatedFunction};
use std::collections::{HashMap, HashSet};
use std::fmt::Write;

mod emitter;
mod parameters;
use emitter::{Emitter, Names, id_at, is_identifier, sanitize};
use parameters::RuntimeParameters;

/// One parameter of a generated function.
#[derive(Debug, Clone, Copy)]
struct Param {
    name: &'static str,
    ty: &'static str,
    /// Always used by code outside the expressions (so never prefixed with `_`).
    always_used: bool,
}

/// Specification of one generated function.
struct FunctionSpec {
    /// Doc comment.
    doc: String,
    /// Name.
    name: String,
    /// Parameters after `&self`.
    params: Vec<Param>,
    /// Return type, if any.
    ret: Option<&'static str>,
    /// `target = expression;` statements; a target `let x` declares a binding and the
    /// target [`RETURN`] makes the expression the function's value.
    outputs: Vec<(String, Id)>,
    /// Code after the outputs (the returned value).
    tail: String,
}

/// Generated code and its operation counts.
#[derive(Debug, Clone)]
pub struct Generated {
    /// Module name (the model's name).
    pub name: String,
    /// Model file the module was generated from, as shown in messages.
    pub source: String,
    /// The formatted Rust module: items only (no inner attributes), so that it can be
    /// included with `include!` inside a `mod` of the user's choosing.
    pub code: String,
    /// Operation count of every generated function, in emission order.
    pub op_counts: Vec<(String, OpCount)>,
}

/// How the standalone entry points (`mass_matrix`, `equations`, `constraint`, … every
/// [`Dynamics`] function besides the fused pair `position_terms`/`velocity_terms` that a
/// right-hand side calls) are emitted.
///
/// [`Dynamics`]: https://docs.rs/camchain-runtime
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EntryPoints {
    /// Each with its own expressions below [`LARGE_MODEL_OPS`] operations in the fused
    /// pair, as calls of the pair above (the default).
    #[default]
    Auto,
    /// Always with their own expressions: each holds only the operations its outputs need
    /// (the fewest operations per call; more code to compile).
    Standalone,
    /// Always as calls of the fused pair: every expression is compiled once (the least code
    /// and the fastest build; a standalone call computes everything the pair computes).
    ViaFusedPair,
}

/// Options of the emitted module.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EmitOptions {
    /// How the generated code names the runtime crate (`camchain-runtime`). The default,
    /// `::camchain::runtime`, is right for a crate that depends on the `camchain` facade; a
    /// crate that depends on `camchain-runtime` directly uses `::camchain_runtime`. The module
    /// imports it once as `rt`.
    pub runtime_path: String,
    /// How the standalone entry points are emitted.
    pub entry_points: EntryPoints,
    /// When set, the model file's text, embedded as `pub const MODEL_SOURCE: &str` (for
    /// programs that also want the model description at run time, e.g. to draw it or to run
    /// the numeric reference on it).
    pub embedded_source: Option<String>,
    /// Which parameters the generated code reads at run time (the file's `constant:` flags
    /// by default).
    pub parameters: crate::model::ParameterMode,
    /// The directory the files a model names (its tables of points) are read from: the model
    /// file's own. `None`: the directory of the path messages show.
    pub files_dir: Option<std::path::PathBuf>,
    /// The most nodes the derivation's expression graph may hold ([`crate::expr::NODE_LIMIT`]
    /// by default): a model that needs more is refused with an error saying so, before it
    /// takes more memory. Raise it on a machine with memory to spare (about 100 bytes a node).
    pub node_limit: usize,
    /// The longest generated module, in bytes before formatting ([`MAX_CODE_BYTES`] by
    /// default): a model whose code would be longer is refused with an error saying so.
    pub code_limit: usize,
}

impl Default for EmitOptions {
    fn default() -> Self {
        EmitOptions {
            runtime_path: DEFAULT_RUNTIME_PATH.to_string(),
            entry_points: EntryPoints::Auto,
            embedded_source: None,
            parameters: crate::model::ParameterMode::AsDeclared,
            files_dir: None,
            node_limit: crate::expr::NODE_LIMIT,
            code_limit: MAX_CODE_BYTES,
        }
    }
}

/// The path of the runtime that generated code uses unless told otherwise: the `camchain`
/// facade's re-export.
pub const DEFAULT_RUNTIME_PATH: &str = "::camchain::runtime";

/// Output target meaning "the function's value" (written last, without a semicolon).
const RETURN: &str = "return";

/// The deepest an expression is written inline: a node whose operands, written inline, would
/// nest deeper gets a `let` binding of its own even when used once. A term of a long chain
/// (a sum through every body) would otherwise be one expression as deep as the chain, and
/// parsing, formatting and compiling the generated code all recurse on that depth. Binding
/// a term changes no value: the same operations run in the same order.
const MAX_INLINE_DEPTH: u32 = 32;

/// Prefix of the statements that become section comments after formatting.
const SECTION_MACRO: &str = "__section__";

/// Generates the module for `model` with the default options; `source` is the model file as
/// shown in the header.
pub fn generate(model: &Model, source: &str) -> Result<Generated, String> {
    generate_with(model, source, &EmitOptions::default())
}

/// Generates the module for `model`; `source` is the model file as shown in the header.
///
/// A model too large to derive ([`crate::derive::TooLarge`]), or whose code would be longer
/// than [`EmitOptions::code_limit`], is an error saying so.
pub fn generate_with(
    model: &Model,
    source: &str,
    options: &EmitOptions,
) -> Result<Generated, String> {
    let d = Derivation::checked_with_limit(model, options.node_limit).map_err(|e| e.to_string())?;
    generate_from(model, d, source, options)
}

/// [`generate_with`] from the model's derivation ([`Derivation::checked_with_limit`]), which
/// emission extends (the sines and cosines it shares, the terms it caches) within its node
/// limit.
pub fn generate_from(
    model: &Model,
    mut d: Derivation,
    source: &str,
    options: &EmitOptions,
) -> Result<Generated, String> {
    let specs = function_specs(model, &mut d);
    let parametric = model.runtime_parameters().next().is_some();
    let kinematics_specs = contact_kinematics_specs(model, &mut d, parametric);
    let mut fused = FusedTerms::new(&mut d);
    if let Some(e) = d.too_large(model) {
        return Err(e.to_string());
    }
    let runtime = RuntimeParameters::new(model, &d, &all_roots(&d, &specs, &fused));
    if let Some(rp) = &runtime {
        // A value of the parameters alone is computed once per parameter set, not cached.
        fused.cached.retain(|&id| !rp.is_param_only(id));
    }
    let derived = |receiver: &str| -> Vec<(Id, String)> {
        runtime
            .as_ref()
            .map(|rp| rp.given(receiver))
            .unwrap_or_default()
    };
    let fused_specs = fused.specs(&d);
    let fused_ops: usize = fused_specs
        .iter()
        .map(|(spec, given)| fused_count(&d, spec, &[given.clone(), derived("self.")].concat()))
        .sum();
    let wrap = match options.entry_points {
        EntryPoints::Auto => fused_ops > LARGE_MODEL_OPS,
        EntryPoints::Standalone => false,
        EntryPoints::ViaFusedPair => true,
    };
    let mut functions = String::new();
    let mut op_counts = Vec::new();
    let geometry_warm: Vec<(Id, String)> = d
        .contacts
        .iter()
        .enumerate()
        .filter(|(_, c)| d.graph.implicit_of(c.parameter).is_some())
        .map(|(k, c)| (c.parameter, format!("out[{k}].parameter")))
        .collect();
    for spec in &specs {
        let warm: &[(Id, String)] = if spec.name == "contact_geometry" {
            &geometry_warm
        } else {
            &[]
        };
        let (text, count) = match wrapper(model, &fused, &spec.name).filter(|_| wrap) {
            Some(text) => (text, function_count(&d, spec, &derived("self."))),
            None => emit_function_full(&d, spec, "", true, &derived("self."), &[], warm),
        };
        functions.push_str(&text);
        within_code_limit(functions.len(), options.code_limit)?;
        op_counts.push((spec.name.clone(), count));
    }
    for (spec, given) in &fused_specs {
        let given = [given.clone(), derived("self.")].concat();
        let memo: &[TrigMemo] = if spec.name == "position_terms" {
            &fused.memo
        } else {
            &[]
        };
        let warm: Vec<(Id, String)> = if spec.name == "position_terms" {
            fused
                .plain_cached()
                .into_iter()
                .filter(|&(_, id)| d.graph.implicit_of(id).is_some())
                .map(|(k, id)| (id, format!("cache[{k}]")))
                .collect()
        } else {
            Vec::new()
        };
        let (text, count) = emit_function_full(&d, spec, "", true, &given, memo, &warm);
        functions.push_str(&text);
        within_code_limit(functions.len(), options.code_limit)?;
        op_counts.push((spec.name.clone(), count));
    }
    let _ = writeln!(
        functions,
        "/// Entries of the cache `position_terms` fills for `velocity_terms`.\n\
         fn cache_len(&self) -> usize {{ {} }}",
        fused.cache_len()
    );
    let mut helpers =
        contact_kinematics_helpers(&d, &kinematics_specs, &mut op_counts, &derived(""));
    helpers.push_str(&implicit_helpers(&d, &mut op_counts, &derived("")));
    helpers.push_str(&table_helpers(&d.graph));
    if let Some(rp) = &runtime {
        op_counts.push(("derive".to_string(), rp.derive_count(&d)));
    }
    let mut file = String::new();
    let _ = writeln!(
        file,
        "/// The runtime this module implements (`camchain-runtime`).\n\
         use {} as rt;",
        options.runtime_path
    );
    file.push_str(&model_type(model, source, runtime.is_some()));
    if let Some(rp) = &runtime {
        file.push_str(&rp.items(model, &d, source));
    }
    if let Some(text) = &options.embedded_source {
        let _ = writeln!(
            file,
            "/// The model file this module was generated from (`{source}`), as it was read.\n\
             {ALLOW_UNUSED}\n\
             pub const MODEL_SOURCE: &str = {};",
            raw_string(text)
        );
        let files: Vec<String> = model
            .files
            .iter()
            .map(|f| format!("({:?}, {})", f.written, raw_string(&f.text)))
            .collect();
        let _ = writeln!(
            file,
            "/// The files the model file names (its tables of points), as read: (the path \
             it writes, the text).\n\
             {ALLOW_UNUSED}\n\
             pub const MODEL_FILES: &[(&str, &str)] = &[{}];",
            files.join(", ")
        );
    }
    file.push_str(&info_static(model));
    let (info, values) = if runtime.is_some() {
        (
            "&self.info",
            "/// The run-time parameters' values.\n\
             fn parameter_values(&self) -> &[f64] { &self.values }\n",
        )
    } else {
        ("&INFO", "")
    };
    let _ = write!(
        file,
        "{ALLOW_LITERALS}\nimpl rt::Dynamics for Model {{\n\
         fn info(&self) -> &rt::ModelInfo {{ {info} }}\n\
         {values}{functions}\n{}\n}}\n",
        contact_kinematics_dispatch(model, runtime.is_some())
    );
    file.push_str(&helpers);
    file.push_str(&op_count_table(&op_counts));
    within_code_limit(file.len(), options.code_limit)?;
    let syntax =
        syn::parse_file(&file).map_err(|e| format!("generated code does not parse: {e}"))?;
    let formatted = prettyplease::unparse(&syntax);
    Ok(Generated {
        name: model.name.clone(),
        source: source.to_string(),
        code: format!(
            "{}\n{}",
            header(model, source, &op_counts, wrap, runtime.is_some()),
            restore_comments(&formatted)
        ),
        op_counts,
    })
}

/// The longest generated module, before formatting: 32 MiB. Formatting parses the whole
/// module into a syntax tree of some 50 bytes per byte of text (a spatial chain of 200
/// bodies, `codegen/tests/common/chain.rs`, is 17.6 MB of text and takes 1.0 GB in all), and
/// no compiler builds a much longer module in reasonable time; a model whose code would be
/// longer is refused before it is formatted.
pub const MAX_CODE_BYTES: usize = 32 << 20;

/// An error when the generated text (`len` bytes) has grown past `limit`
/// ([`EmitOptions::code_limit`]).
fn within_code_limit(len: usize, limit: usize) -> Result<(), String> {
    if len <= limit {
        return Ok(());
    }
    let shown = if limit % (1 << 20) == 0 {
        format!("{} MiB", limit >> 20)
    } else {
        format!("{limit} bytes")
    };
    Err(format!(
        "the model is too large to generate code for: its generated code is longer than \
         {shown} (the limit, which bounds the memory formatting it takes): split the \
         mechanism or use fewer bodies"
    ))
}

/// Every tabulated function of the graph as constants and a function `eval_<name>(s)` returning
/// its value and first three derivatives at s: a spline's table (abscissas, values and the
/// second derivatives at the knots, computed at build time) for
/// `camchain_runtime::spline::evaluate`, or a motion law's segments for
/// `camchain_runtime::motion_law::evaluate`.
fn table_helpers(g: &Graph) -> String {
    let mut out = String::new();
    for table in g.tables() {
        let text = match &table.function {
            TabulatedFunction::Spline(spline) => spline_helper(&table.name, spline),
            TabulatedFunction::Law(program) => law_helper(&table.name, program),
        };
        out.push_str(&text);
    }
    out
}

/// The constants and the evaluation function of a spline named `name`.
fn spline_helper(name: &str, spline: &camchain_runtime::spline::Spline) -> String {
    let upper = name.to_uppercase();
    let n = spline.abscissas().len();
    format!(
        "/// {name}: the table's abscissas, values and second derivatives at the knots.\n\
         {ALLOW_LITERALS}\n\
         const {upper}_X: [f64; {n}] = {};\n\
         {ALLOW_LITERALS}\n\
         const {upper}_Y: [f64; {n}] = {};\n\
         {ALLOW_LITERALS}\n\
         const {upper}_M: [f64; {n}] = {};\n\
         /// {name}: the spline and its first three derivatives at s ({}).\n\
         #[inline]\n\
         fn eval_{name}(s: f64) -> [f64; 4] {{\n\
         rt::spline::evaluate(&{upper}_X, &{upper}_Y, &{upper}_M, {}, s)\n}}\n",
        float_list(spline.abscissas()),
        float_list(spline.values()),
        float_list(spline.knot_curvatures()),
        if spline.is_periodic() {
            "periodic: repeats every period"
        } else {
            "open: its end cubics continue beyond the table"
        },
        spline.is_periodic(),
    )
}

/// The segments and the evaluation function of a motion law named `name`.
fn law_helper(name: &str, program: &camchain_runtime::motion_law::MotionProgram) -> String {
    let upper = name.to_uppercase();
    let segments: Vec<String> = program
        .segments()
        .iter()
        .map(|s| {
            format!(
                "rt::motion_law::Segment {{ law: rt::motion_law::Law::{:?}, angle: {}, lift: {} }}",
                s.law,
                lit(s.angle),
                lit(s.lift)
            )
        })
        .collect();
    format!(
        "/// {name}: the follower's motion law, segment by segment (its law, the cam angle it \
         takes in rad, the lift at its end).\n\
         {ALLOW_LITERALS}\n\
         const {upper}: [rt::motion_law::Segment; {}] = [{}];\n\
         /// {name}: the follower's displacement and its first three derivatives with respect \
         to the cam's angle at theta (repeats every turn).\n\
         #[inline]\n\
         fn eval_{name}(theta: f64) -> [f64; 4] {{\n\
         rt::motion_law::evaluate(&{upper}, theta)\n}}\n",
        segments.len(),
        segments.join(", "),
    )
}

/// reads as written.
fn raw_string(text: &str) -> String {
    let mut hashes = String::from("#");
    while text.contains(&format!("\"{hashes}")) {
        hashes.push('#');
    }
    format!("r{hashes}\"{text}\"{hashes}")
}

/// A program uses what it needs of the generated API (in a binary crate, unused public
/// items of a private module would warn).
const ALLOW_UNUSED: &str = "#[allow(dead_code)]";

/// Literals come verbatim from the model file (e.g. −π/2 written out in full): the lints
/// about them do not apply to generated code.
const ALLOW_LITERALS: &str = "#[allow(clippy::approx_constant, clippy::excessive_precision)]";

impl Generated {
    /// One-line description for the module index.
    pub fn summary(&self) -> String {
        format!("Generated model `{}` (from `{}`).", self.name, self.source)
    }
}

/// The module's header: `//` comments (a file meant for `include!` cannot start with inner
/// `//!` doc comments), written above the formatted code.
fn header(
    model: &Model,
    source: &str,
    counts: &[(String, OpCount)],
    wrapped: bool,
    parametric: bool,
) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// Model `{}`, generated by camchain-build from `{source}`.",
        model.name
    );
    let _ = writeln!(out, "// Do not edit: change the model file and rebuild.");
    if !model.description.is_empty() {
        let _ = writeln!(out, "//");
        for line in model.description.lines() {
            let _ = writeln!(out, "// {line}");
        }
    }
    let _ = writeln!(out, "//");
    let _ = writeln!(out, "// Operation counts per generated function:");
    let _ = writeln!(out, "//");
    let _ = writeln!(
        out,
        "// | function | add/sub | mul | div | sin/cos | sqrt | other | total |"
    );
    let _ = writeln!(out, "// |---|---|---|---|---|---|---|---|");
    for (name, c) in counts {
        let _ = writeln!(
            out,
            "// | `{name}` | {} | {} | {} | {} | {} | {} | {} |",
            c.add_sub,
            c.mul,
            c.div,
            c.sin_cos,
            c.sqrt,
            c.other,
            c.total()
        );
    }
    if parametric {
        let names: Vec<String> = model
            .runtime_parameters()
            .map(|(_, p)| format!("`{}`", p.name))
            .collect();
        let _ = writeln!(
            out,
            "//\n// Read at run time: {} (see `Parameters`); `derive` computes what depends on them\n\
             // alone once per parameter set, and the counts above do not include it.",
            names.join(", ")
        );
    }
    if wrapped {
        let _ = writeln!(
            out,
            "//\n// `mass_matrix`, `inertial_forces`, `applied_forces`, `equations`, \
             `constraint`, `constraint_jacobian`, `constraint_bias` and `constraint_terms` call\n\
             // `position_terms` and `velocity_terms` (every expression is compiled once); their \
             counts above\n// are those of the outputs they return."
        );
    }
    // Trailing spaces of empty description lines would fail `cargo fmt --check` of a copy.
    out.lines().map(|l| format!("{}\n", l.trim_end())).collect()
}

/// `pub const OP_COUNTS`: the header's table as data, for `camchain ops`.
fn op_count_table(counts: &[(String, OpCount)]) -> String {
    let rows: Vec<String> = counts
        .iter()
        .map(|(name, c)| {
            format!(
                "({name:?}, [{}, {}, {}, {}, {}, {}])",
                c.add_sub, c.mul, c.div, c.sin_cos, c.sqrt, c.other
            )
        })
        .collect();
    format!(
        "/// Operation count of every generated function: add/sub, mul, div, sin/cos, sqrt, \
         other (the table of the header).\n\
         {ALLOW_UNUSED}\n\
         pub const OP_COUNTS: &[(&str, [usize; 6])] = &[{}];\n",
        rows.join(", ")
    )
}

fn model_type(model: &Model, source: &str, parametric: bool) -> String {
    let mut doc = format!(
        "/// The model `{}`, generated from `{source}`: implements [`rt::Dynamics`]; simulate it \
         with\n/// [`Model::assemble`], [`Model::step`] and [`Model::simulate`].\n",
        model.name
    );
    if !model.description.is_empty() {
        doc.push_str("///\n");
        for line in model.description.lines() {
            let _ = writeln!(doc, "/// {}", line.trim_end());
        }
    }
    let (definition, constructors) = if parametric {
        (parametric_struct(model, &doc), parametric_constructors())
    } else {
        (
            format!(
                "{doc}#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]\n\
                 {ALLOW_UNUSED}\n\
                 pub struct Model;\n"
            ),
            plain_constructors(model, source),
        )
    };
    format!(
        "{definition}{ALLOW_UNUSED}\n\
         impl Model {{\n\
         {constructors}\
         /// Assembles the initial state from the model file's guess: held coordinates keep\n\
         /// their values, the dependent ones are solved so that every contact point is on its cam.\n\
         pub fn assemble(&self) -> Result<rt::State, rt::SimError> {{\n\
         rt::Simulate::assemble(self, 0.0)\n}}\n\
         /// Advances `state` by `dt` seconds with the model's default integrator settings.\n\
         pub fn step(&self, state: &mut rt::State, dt: f64) -> Result<rt::Stats, rt::SimError> {{\n\
         rt::Simulate::step(self, state, dt)\n}}\n\
         /// Everything at the state's instant: accelerations, contact points and normal forces,\n\
         /// constraint residuals, drive loads, energies.\n\
         pub fn sample(&self, state: &rt::State) -> Result<rt::Sample, rt::SimError> {{\n\
         rt::Simulate::sample(self, state)\n}}\n\
         /// Simulates from `state` with `settings`, sampling every `settings.dt_out`.\n\
         pub fn simulate(&self, state: rt::State, settings: &rt::SimSettings) -> Result<rt::Trajectory, Box<rt::SimFailure>> {{\n\
         rt::Simulate::simulate(self, state, settings)\n}}\n\
         /// Simulates from `state` with `settings`, keeping a summary instead of a trajectory\n\
         /// (extreme normal forces, first lift-off, max |h|, energy drift): what a parameter\n\
         /// sweep keeps of a run.\n\
         pub fn simulate_metrics(&self, state: rt::State, settings: &rt::SimSettings) -> Result<rt::RunMetrics, Box<rt::MetricsFailure>> {{\n\
         rt::Simulate::simulate_metrics(self, state, settings, rt::MetricsOptions::default())\n}}\n\
         /// The default settings from the model file.\n\
         pub fn default_settings(&self) -> rt::SimSettings {{\n\
         rt::Dynamics::info(self).defaults.clone()\n}}\n\
         }}\n\
         /// The model with the file's values, shared (what `ALL` of a build's index lists).\n\
         {ALLOW_UNUSED}\n\
         pub static DEFAULT: ::std::sync::LazyLock<Model> = ::std::sync::LazyLock::new(Model::default);\n\
         /// [`Model::with`], boxed for programs that choose models at run time (sweeps).\n\
         {ALLOW_UNUSED}\n\
         pub fn boxed(values: &[(&str, f64)]) -> Result<Box<dyn rt::Dynamics + Send + Sync>, rt::ParameterError> {{\n\
         Ok(Box::new(Model::with(values)?))\n}}\n"
    )
}

/// The `Model` of a model with run-time parameters: the values, what derives from them, and
/// the description (whose initial guess may depend on them).
fn parametric_struct(model: &Model, doc: &str) -> String {
    let n = model.runtime_parameters().count();
    format!(
        "{doc}///\n/// Its run-time parameters are in [`Parameters`]: [`Model::default`] has the file's \
         values, [`Model::new`] and [`Model::with`] others (checked as the build checks the \
         file).\n\
         #[derive(Debug, Clone, PartialEq)]\n\
         pub struct Model {{\n\
         parameters: Parameters,\n\
         values: [f64; {n}],\n\
         derived: Derived,\n\
         info: rt::ModelInfo,\n\
         }}\n\
         impl Default for Model {{\n\
         /// The model with the file's values (checked when it was built).\n\
         fn default() -> Self {{ Model::build(Parameters::default()) }}\n}}\n"
    )
}

/// Constructors of a model with run-time parameters.
fn parametric_constructors() -> String {
    "/// The model with these parameter values, checked as the build checks the model file \
     (declared bounds first, then every field they change: a negative mass gets the error \
     the file would get).\n\
     pub fn new(parameters: Parameters) -> Result<Self, rt::ParameterError> {\n\
     check(&parameters)?;\n\
     Ok(Model::build(parameters))\n}\n\
     /// The file's values with the named ones changed (`Model::with(&[(\"k\", 40.0)])`).\n\
     pub fn with(values: &[(&str, f64)]) -> Result<Self, rt::ParameterError> {\n\
     let mut parameters = Parameters::default();\n\
     for &(name, value) in values {\n\
     parameters.set(name, value)?;\n}\n\
     Model::new(parameters)\n}\n\
     /// The parameter values of this model.\n\
     pub fn parameters(&self) -> &Parameters {\n\
     &self.parameters\n}\n\
     fn build(parameters: Parameters) -> Self {\n\
     let mut info = INFO.clone();\n\
     initial_guess(&parameters, &mut info.initial.q, &mut info.initial.qd);\n\
     Model { values: parameters.values(), derived: derive(&parameters), parameters, info }\n}\n"
        .to_string()
}

/// `Model::with` of a model without run-time parameters: only the empty list is accepted.
fn plain_constructors(model: &Model, source: &str) -> String {
    let names: Vec<String> = model
        .parameters
        .iter()
        .map(|p| format!("{:?}", p.name))
        .collect();
    let at = &model.parameters_at;
    format!(
        "/// The model with the file's values: it has no run-time parameter, so any name given \
         is an error (a declared parameter is folded into this code: constant).\n\
         pub fn with(values: &[(&str, f64)]) -> Result<Self, rt::ParameterError> {{\n\
         match values.first() {{\n\
         None => Ok(Model),\n\
         Some(&(name, _)) => {{\n\
         let known: &[&str] = &[{names}];\n\
         let message = if known.contains(&name) {{ rt::parameters::checks::constant_parameter(name) }} \
         else {{ rt::parameters::checks::unknown_parameter(name, known) }};\n\
         Err(rt::ParameterError {{ file: {source:?}.to_string(), line: {}, column: {}, field: {:?}.to_string(), message }})\n\
         }}\n}}\n}}\n",
        at.line,
        at.column,
        at.field,
        names = names.join(", "),
    )
}

fn info_static(model: &Model) -> String {
    let coords: Vec<String> = model
        .bodies
        .iter()
        .map(|b| {
            let kind = match b.joint.kind {
                JointKind::Revolute => "Revolute",
                JointKind::Prismatic => "Prismatic",
            };
            format!(
                "rt::CoordinateInfo {{ name: {:?}.to_string(), kind: rt::CoordinateKind::{kind}, driven: {} }}",
                b.joint.coordinate,
                b.joint.prescribed.is_some()
            )
        })
        .collect();
    let contacts: Vec<String> = model
        .contacts
        .iter()
        .map(|c| {
            let follower = c.follower.kind().keyword();
            let profile = match c.profile {
                crate::model::Profile::Explicit { .. } => "Explicit",
                crate::model::Profile::Polar { .. } => "Polar",
                crate::model::Profile::Parametric { .. } => "Parametric",
            };
            let cam_coordinate = match c.cam_body {
                Some(b) if model.bodies[b].joint.kind == JointKind::Revolute => {
                    format!("Some({b})")
                }
                _ => "None".to_string(),
            };
            format!(
                "rt::ContactInfo {{ name: {:?}.to_string(), follower: rt::FollowerKind::{follower}, \
                 profile: rt::ProfileKind::{profile}, cam_coordinate: {cam_coordinate}, \
                 cam_moves: {} }}",
                c.name,
                c.cam_body.is_some()
            )
        })
        .collect();
    let loops: Vec<String> = model
        .loops
        .iter()
        .map(|l| {
            let kind = l.kind.keyword();
            let equations: Vec<String> =
                l.equations().iter().map(|e| format!("{e:?}.to_string()")).collect();
            format!(
                "rt::LoopInfo {{ name: {:?}.to_string(), kind: rt::LoopKind::{kind}, equations: Vec::from([{}]) }}",
                l.name,
                equations.join(", ")
            )
        })
        .collect();
    let s = &model.simulation;
    let integrator = s.integrator.keyword();
    format!(
        "/// Static description of the model.\n\
         {ALLOW_LITERALS}\n\
         static INFO: ::std::sync::LazyLock<rt::ModelInfo> = ::std::sync::LazyLock::new(|| rt::ModelInfo {{\n\
         name: {name:?}.to_string(),\n\
         description: {desc:?}.to_string(),\n\
         coordinates: Vec::from([{coords}]),\n\
         contacts: Vec::from([{contacts}]),\n\
         loops: Vec::from([{loops}]),\n\
         spatial: {spatial},\n\
         initial: rt::InitialGuess {{ q: Vec::from({q}), qd: Vec::from({qd}), hold: Vec::from({hold:?}), given_q: Vec::from({given_q:?}), given_qd: Vec::from({given_qd:?}) }},\n\
         defaults: rt::SimSettings {{ t_end: {t_end}, dt_out: {dt_out}, integrator: rt::IntegratorKind::{integrator}, dt: {dt}, rtol: {rtol}, atol: {atol} }},\n\
         restitution: {restitution},\n\
         parameters: Vec::from([{parameters}]),\n\
         }});\n",
        name = model.name,
        desc = model.description,
        coords = coords.join(", "),
        contacts = contacts.join(", "),
        loops = loops.join(", "),
        spatial = !model.is_planar(),
        q = float_list(&model.initial.q),
        qd = float_list(&model.initial.qd),
        hold = model.initial.hold,
        given_q = model.initial.given_q,
        given_qd = model.initial.given_qd,
        t_end = lit(s.t_end),
        dt_out = lit(s.dt_out),
        dt = lit(s.dt),
        rtol = lit(s.rtol),
        atol = lit(s.atol),
        restitution = s
            .restitution
            .map_or("None".to_string(), |e| format!("Some({})", lit(e))),
        parameters = parameter_infos(model),
    )
}

/// The run-time parameters as `rt::ParameterInfo` values.
fn parameter_infos(model: &Model) -> String {
    let option = |v: Option<f64>| v.map_or("None".to_string(), |v| format!("Some({})", lit(v)));
    let items: Vec<String> = model
        .runtime_parameters()
        .map(|(_, p)| {
            format!(
                "rt::ParameterInfo {{ name: {:?}.to_string(), unit: {:?}.to_string(), default: {}, min: {}, max: {}, description: {:?}.to_string() }}",
                p.name,
                p.unit,
                lit(p.default),
                option(p.min),
                option(p.max),
                p.description
            )
        })
        .collect();
    items.join(", ")
}

fn float_list(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|&x| lit(x)).collect();
    format!("[{}]", items.join(", "))
}

/// A float literal that reads back to the same f64.
fn lit(v: f64) -> String {
    let s = format!("{v:?}");
    if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}

fn param(name: &'static str, ty: &'static str) -> Param {
    Param {
        name,
        ty,
        always_used: false,
    }
}

fn function_specs(model: &Model, d: &mut Derivation) -> Vec<FunctionSpec> {
    let n = model.n();
    let dy = &d.dynamics;
    let mass_outputs: Vec<(String, Id)> = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| (format!("m[{}]", i * n + j), dy.mass[i][j]))
        .collect();
    let f_outputs: Vec<(String, Id)> = dy
        .inertial
        .iter()
        .enumerate()
        .map(|(i, &e)| (format!("f[{i}]"), e))
        .collect();
    let q_outputs: Vec<(String, Id)> = dy
        .applied
        .iter()
        .enumerate()
        .map(|(i, &e)| (format!("applied[{i}]"), e))
        .collect();
    let rows = d.constraint_rows();
    let h_outputs: Vec<(String, Id)> = rows
        .iter()
        .enumerate()
        .map(|(k, row)| (format!("h[{k}]"), row.0))
        .collect();
    let j_outputs: Vec<(String, Id)> = rows
        .iter()
        .enumerate()
        .flat_map(|(k, row)| {
            row.1
                .iter()
                .enumerate()
                .map(move |(i, &e)| (format!("j[{}]", k * n + i), e))
        })
        .collect();
    let c_outputs: Vec<(String, Id)> = rows
        .iter()
        .enumerate()
        .map(|(k, row)| (format!("c[{k}]"), row.2))
        .collect();
    let all = |parts: &[&Vec<(String, Id)>]| parts.iter().flat_map(|p| p.iter().cloned()).collect();
    let mut specs = vec![
        FunctionSpec {
            doc: "M(q), eq. (13), row-major.".into(),
            name: "mass_matrix".into(),
            params: vec![param("q", "&[f64]"), param("m", "&mut [f64]")],
            ret: None,
            outputs: mass_outputs.clone(),
            tail: String::new(),
        },
        FunctionSpec {
            doc: "F(q, q̇), eq. (13).".into(),
            name: "inertial_forces".into(),
            params: vec![
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
                param("f", "&mut [f64]"),
            ],
            ret: None,
            outputs: f_outputs.clone(),
            tail: String::new(),
        },
        FunctionSpec {
            doc: "Q(q, q̇, t), eq. (13): gravity, springs, dampers.".into(),
            name: "applied_forces".into(),
            params: vec![
                param("t", "f64"),
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
                param("applied", "&mut [f64]"),
            ],
            ret: None,
            outputs: q_outputs.clone(),
            tail: String::new(),
        },
        FunctionSpec {
            doc: "M, F and Q sharing one evaluation of the kinematics.".into(),
            name: "equations".into(),
            params: vec![
                param("t", "f64"),
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
                param("m", "&mut [f64]"),
                param("f", "&mut [f64]"),
                param("applied", "&mut [f64]"),
            ],
            ret: None,
            outputs: all(&[&mass_outputs, &f_outputs, &q_outputs]),
            tail: String::new(),
        },
        FunctionSpec {
            doc: "h(q) = f2 − f3(f1), eq. (3).".into(),
            name: "constraint".into(),
            params: vec![param("q", "&[f64]"), param("h", "&mut [f64]")],
            ret: None,
            outputs: h_outputs,
            tail: String::new(),
        },
        FunctionSpec {
            doc: "J = J2 − f3' J1, eq. (5b), row-major nc×n.".into(),
            name: "constraint_jacobian".into(),
            params: vec![param("q", "&[f64]"), param("j", "&mut [f64]")],
            ret: None,
            outputs: j_outputs.clone(),
            tail: String::new(),
        },
        FunctionSpec {
            doc: "c of J q̈ + c = 0, eqs. (7, 8).".into(),
            name: "constraint_bias".into(),
            params: vec![
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
                param("c", "&mut [f64]"),
            ],
            ret: None,
            outputs: c_outputs.clone(),
            tail: String::new(),
        },
        FunctionSpec {
            doc: "J and c sharing one evaluation of the contact kinematics.".into(),
            name: "constraint_terms".into(),
            params: vec![
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
                param("j", "&mut [f64]"),
                param("c", "&mut [f64]"),
            ],
            ret: None,
            outputs: all(&[&j_outputs, &c_outputs]),
            tail: String::new(),
        },
    ];
    specs.push(geometry_spec(d));
    specs.push(prescribed_spec(d));
    specs.push(energy_spec(d));
    if model.bodies.iter().any(|b| b.joint.load.is_some()) {
        specs.push(FunctionSpec {
            doc: "Σ τ q̇, the power of the applied joint loads.".into(),
            name: "load_power".into(),
            params: vec![
                param("t", "f64"),
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
            ],
            ret: Some("f64"),
            outputs: vec![(RETURN.into(), d.energy.load_power)],
            tail: String::new(),
        });
    }
    if !d.loops.is_empty() {
        let outputs = d
            .loops
            .iter()
            .enumerate()
            .flat_map(|(l, terms)| {
                terms.points.iter().enumerate().flat_map(move |(side, p)| {
                    p.iter()
                        .enumerate()
                        .map(move |(k, &e)| (format!("out[{}][{k}]", 2 * l + side), e))
                })
            })
            .collect();
        specs.push(FunctionSpec {
            doc: "The points A and B of every loop closure, ground coordinates.".into(),
            name: "loop_points".into(),
            params: vec![param("q", "&[f64]"), param("out", "&mut [[f64; 3]]")],
            ret: None,
            outputs,
            tail: String::new(),
        });
    }
    specs.push(FunctionSpec {
        doc: "Σ c q̇², the power the joint dampers dissipate.".into(),
        name: "damper_power".into(),
        params: vec![param("qd", "&[f64]")],
        ret: Some("f64"),
        outputs: vec![(RETURN.into(), d.energy.damper_power)],
        tail: String::new(),
    });
    specs
}

/// The coordinates summed in an angle `q_a + q_b + …` (sorted variable indices), if `id` is
/// such a sum.
fn angle_vars(g: &Graph, id: Id, out: &mut Vec<u32>) -> bool {
    let mut ok = true;
    angle_terms(g, id, |k| out.push(k), &mut ok);
    ok
}

/// Calls `leaf` with the variable index of every term of the sum of variables `id`, left to
/// right, and clears `ok` (stopping there) at the first term that is not a variable. An
/// absolute joint angle of a planar chain is a sum through every joint below it, so the
/// walk keeps its own stack instead of recursing.
fn angle_terms(g: &Graph, id: Id, mut leaf: impl FnMut(u32), ok: &mut bool) {
    let mut stack = vec![id];
    while let Some(id) = stack.pop() {
        match g.node(id) {
            Node::Var(k) => leaf(k),
            Node::Add(a, b) => {
                stack.push(b);
                stack.push(a);
            }
            _ => {
                *ok = false;
                return;
            }
        }
    }
}

/// Rewrites, in the velocity-level outputs, the sine and cosine of every angle the position
/// level does not compute but can be written as the sum or difference of two angles whose
/// sine and cosine it does (the relative joint angles of M and F, from the absolute angles
/// of the contact kinematics): sin(A − B) = sA cB − cA sB and so on. Four multiplications and
/// two additions replace a sine and a cosine, and the velocity level then reads every
/// trigonometric value from the cache.
fn reuse_position_trigonometry(g: &mut Graph, position: &[Id], velocity: &mut [(String, Id)]) {
    let in_position = g.reachable(position);
    // Angles whose sine and cosine the position level both computes.
    let mut known: HashMap<Vec<u32>, (Id, Id)> = HashMap::new();
    let mut half: HashMap<Vec<u32>, (Option<Id>, Option<Id>)> = HashMap::new();
    for (i, &needed) in in_position.iter().enumerate() {
        let id = id_at(g, i);
        let Some((f, _, vars)) = angle_trig(g, id).filter(|_| needed) else {
            continue;
        };
        let entry = half.entry(vars).or_default();
        if f == Func::Sin {
            entry.0 = Some(id);
        } else {
            entry.1 = Some(id);
        }
    }
    for (vars, pair) in half {
        if let (Some(s), Some(c)) = pair {
            known.insert(vars, (s, c));
        }
    }
    let roots: Vec<Id> = velocity.iter().map(|o| o.1).collect();
    let in_velocity = g.reachable(&roots);
    let mut replacements = Vec::new();
    for (i, (&velocity_needs, &position_has)) in in_velocity.iter().zip(&in_position).enumerate() {
        let id = id_at(g, i);
        let Some((f, arg, vars)) = angle_trig(g, id).filter(|_| velocity_needs && !position_has)
        else {
            continue;
        };
        let rebuilt = g.rebuild_as(id, |g| trig_from_known(g, f, &vars, &known).unwrap_or(id));
        if rebuilt != id {
            // Named like the call it replaces (`c_q2` for cos q2).
            if let Some(name) = trig_name(g, f, arg) {
                g.label(rebuilt, name);
            }
            replacements.push((id, rebuilt));
        }
    }
    let map: HashMap<Id, Id> = replacements.into_iter().collect();
    let mut roots: Vec<Id> = velocity.iter().map(|o| o.1).collect();
    g.replace_nodes(&mut roots, &map);
    for (output, root) in velocity.iter_mut().zip(roots) {
        output.1 = root;
    }
}

/// Robotran's name of a sine or cosine of a coordinate or a sum of coordinates: `s_q1`,
/// `c_q1_q2`.
fn trig_name(g: &Graph, f: Func, angle: Id) -> Option<String> {
    trig_name_of(f, &angle_name(g, angle)?)
}

/// `s_<angle>` for a sine, `c_<angle>` for a cosine.
fn trig_name_of(f: Func, angle: &str) -> Option<String> {
    let prefix = match f {
        Func::Sin => "s",
        Func::Cos => "c",
        _ => return None,
    };
    Some(format!("{prefix}_{angle}"))
}

/// `q1_q2` for the angle q1 + q2 (the coordinates summed, in the expression's order).
fn angle_name(g: &Graph, angle: Id) -> Option<String> {
    let mut names = Vec::new();
    let mut ok = true;
    angle_terms(
        g,
        angle,
        |k| names.push(g.var_names().get(k as usize)),
        &mut ok,
    );
    let names: Option<Vec<String>> = names.into_iter().map(|n| n.map(|n| sanitize(n))).collect();
    names.filter(|_| ok).map(|n| n.join("_"))
}

/// sin or cos of the angle `vars` from two known angles P, R with vars = P − R or P + R.
fn trig_from_known(
    g: &mut Graph,
    f: Func,
    vars: &[u32],
    known: &HashMap<Vec<u32>, (Id, Id)>,
) -> Option<Id> {
    let mut keys: Vec<&Vec<u32>> = known.keys().collect();
    keys.sort();
    for p in &keys {
        for r in &keys {
            let (sp, cp) = known[*p];
            let (sr, cr) = known[*r];
            if multiset_difference(p, r).as_deref() == Some(vars) {
                // A − B
                let (x, y) = (g.mul(sp, cr), g.mul(cp, sr));
                let (u, w) = (g.mul(cp, cr), g.mul(sp, sr));
                return Some(if f == Func::Sin {
                    g.sub(x, y)
                } else {
                    g.add(u, w)
                });
            }
            if p <= r && multiset_sum(p, r) == vars {
                // A + B
                let (x, y) = (g.mul(sp, cr), g.mul(cp, sr));
                let (u, w) = (g.mul(cp, cr), g.mul(sp, sr));
                return Some(if f == Func::Sin {
                    g.add(x, y)
                } else {
                    g.sub(u, w)
                });
            }
        }
    }
    None
}

/// p − r as sorted multisets, when r ⊆ p and the difference is not empty.
fn multiset_difference(p: &[u32], r: &[u32]) -> Option<Vec<u32>> {
    let mut rest = p.to_vec();
    for x in r {
        let at = rest.iter().position(|y| y == x)?;
        rest.remove(at);
    }
    (!rest.is_empty()).then_some(rest)
}

/// p + r as a sorted multiset.
fn multiset_sum(p: &[u32], r: &[u32]) -> Vec<u32> {
    let mut all = [p, r].concat();
    all.sort_unstable();
    all
}

/// For a sine or cosine of a joint angle (a coordinate or a sum of them): the function,
/// the angle and its variables, sorted.
fn angle_trig(g: &Graph, id: Id) -> Option<(Func, Id, Vec<u32>)> {
    let Node::Call(f @ (Func::Sin | Func::Cos), arg) = g.node(id) else {
        return None;
    };
    let mut vars = Vec::new();
    if !angle_vars(g, arg, &mut vars) {
        return None;
    }
    vars.sort_unstable();
    Some((f, arg, vars))
}

/// The sine–cosine pairs of joint angles (a coordinate or a sum of them) among the
/// `reachable` nodes, each given three cache entries in creation order.
fn trig_pairs(g: &Graph, reachable: &[bool], params: &[Id]) -> Vec<TrigMemo> {
    let mut sines: HashMap<Id, Id> = HashMap::new();
    let mut cosines: HashMap<Id, Id> = HashMap::new();
    for (i, &needed) in reachable.iter().enumerate() {
        let id = id_at(g, i);
        let Some((f, arg, vars)) = angle_trig(g, id).filter(|_| needed) else {
            continue;
        };
        if vars.iter().any(|&k| params.contains(&g.var_id(k))) {
            continue;
        }
        if f == Func::Sin {
            sines.insert(arg, id);
        } else {
            cosines.insert(arg, id);
        }
    }
    let mut pairs: Vec<(Id, Id)> = sines
        .iter()
        .filter_map(|(arg, &sin)| cosines.get(arg).map(|&cos| (sin, cos)))
        .collect();
    pairs.sort_unstable();
    pairs
        .into_iter()
        .enumerate()
        .map(|(k, (sin, cos))| TrigMemo {
            sin,
            cos,
            slot: 3 * k,
        })
        .collect()
}

/// The two functions a right-hand side calls, position level (h, J) then velocity level
/// (M, F, Q, c), and the q-only values the first hands to the second through `cache`.
struct FusedTerms {
    /// Nodes both levels need whose computation is worth a store and a load: elementary
    /// functions (sines, cosines, profile terms), powers and divisions.
    cached: Vec<Id>,
    /// The sine–cosine pairs of joint angles the position level computes, each with three
    /// cache entries (angle, sine, cosine) at the start of the cache: the position level
    /// reuses them when it is evaluated again at the same angles (Newton moving a sliding
    /// coordinate, the step's end evaluated again), and the velocity level reads them.
    memo: Vec<TrigMemo>,
    position: Vec<(String, Id)>,
    velocity: Vec<(String, Id)>,
}

/// A sine and a cosine of one angle, kept in the cache entries `slot..slot + 3`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct TrigMemo {
    sin: Id,
    cos: Id,
    slot: usize,
}

impl FusedTerms {
    fn new(d: &mut Derivation) -> Self {
        let n = d.symbols.q.len();
        let dy = &d.dynamics;
        let mut position = Vec::new();
        let rows = d.constraint_rows();
        for (k, row) in rows.iter().enumerate() {
            position.push((format!("h[{k}]"), row.0));
        }
        for (k, row) in rows.iter().enumerate() {
            for (i, &e) in row.1.iter().enumerate() {
                position.push((format!("j[{}]", k * n + i), e));
            }
        }
        let mut velocity = Vec::new();
        for i in 0..n {
            for j in 0..n {
                velocity.push((format!("out.mass[{}]", i * n + j), dy.mass[i][j]));
            }
        }
        for (i, &e) in dy.inertial.iter().enumerate() {
            velocity.push((format!("out.inertial[{i}]"), e));
        }
        for (i, &e) in dy.applied.iter().enumerate() {
            velocity.push((format!("out.applied[{i}]"), e));
        }
        for (k, row) in rows.iter().enumerate() {
            velocity.push((format!("out.bias[{k}]"), row.2));
        }
        drop(rows);
        let roots = |outputs: &[(String, Id)]| -> Vec<Id> { outputs.iter().map(|o| o.1).collect() };
        reuse_position_trigonometry(&mut d.graph, &roots(&position), &mut velocity);
        let g = &d.graph;
        let in_position = g.reachable(&roots(&position));
        let in_velocity = g.reachable(&roots(&velocity));
        let cached = (0..g.len())
            .filter(|&i| in_position[i] && in_velocity[i])
            .map(|i| id_at(g, i))
            .filter(|&id| {
                matches!(
                    g.node(id),
                    Node::Call(..) | Node::Powf(..) | Node::Div(..) | Node::Table(..)
                ) || g.implicit_of(id).is_some()
            })
            .collect();
        let memo = trig_pairs(g, &in_position, &d.symbols.params);
        FusedTerms {
            cached,
            memo,
            position,
            velocity,
        }
    }

    /// The cached nodes that are not in a memo triple, with their cache index.
    fn plain_cached(&self) -> Vec<(usize, Id)> {
        let in_memo = |id: Id| self.memo.iter().any(|m| m.sin == id || m.cos == id);
        self.cached
            .iter()
            .filter(|&&id| !in_memo(id))
            .enumerate()
            .map(|(k, &id)| (3 * self.memo.len() + k, id))
            .collect()
    }

    /// Entries of the cache.
    fn cache_len(&self) -> usize {
        3 * self.memo.len() + self.plain_cached().len()
    }

    /// The two function specifications, each with the nodes it reads from the cache.
    fn specs(&self, d: &Derivation) -> Vec<(FunctionSpec, Vec<(Id, String)>)> {
        let uses_cache = self.cache_len() > 0;
        let cache_param = |ty| Param {
            name: "cache",
            ty,
            always_used: uses_cache,
        };
        let mut position_outputs = self.position.clone();
        for (k, id) in self.plain_cached() {
            position_outputs.push((format!("cache[{k}]"), id));
        }
        let position = FunctionSpec {
            doc: "h (3) and J (5b) for Newton (15) and the velocities (16), in one pass; \
                  leaves the sines, cosines and profile values `velocity_terms` reuses in \
                  `cache`."
                .into(),
            name: "position_terms".into(),
            params: vec![
                param("q", "&[f64]"),
                param("h", "&mut [f64]"),
                param("j", "&mut [f64]"),
                cache_param("&mut [f64]"),
            ],
            ret: None,
            outputs: position_outputs,
            tail: String::new(),
        };
        let velocity = FunctionSpec {
            doc: "M, F, Q (13) and c (8) in one pass, reading `cache` as `position_terms` \
                  left it at the same q."
                .into(),
            name: "velocity_terms".into(),
            params: vec![
                param("t", "f64"),
                param("q", "&[f64]"),
                param("qd", "&[f64]"),
                cache_param("&[f64]"),
                Param {
                    name: "out",
                    ty: "rt::VelocityTerms<'_>",
                    always_used: true,
                },
            ],
            ret: None,
            outputs: self.velocity.clone(),
            tail: String::new(),
        };
        let mut given: Vec<(Id, String)> = self
            .plain_cached()
            .into_iter()
            .map(|(k, id)| (id, format!("cache[{k}]")))
            .collect();
        for m in &self.memo {
            given.push((m.sin, format!("cache[{}]", m.slot + 1)));
            given.push((m.cos, format!("cache[{}]", m.slot + 2)));
        }
        let _ = d;
        vec![(position, Vec::new()), (velocity, given)]
    }
}

/// Above this many operations in the fused pair (`position_terms` + `velocity_terms`), the
/// other entry points to M, F, Q, h, J and c are emitted as calls of the pair instead of
/// with their own copies of the expressions: every expression is then compiled once, which
/// keeps the build time of large models in check (a 64-body chain compiled each term up to
/// three times). Below it, each function keeps only the operations it needs. (The paper
/// models need about 200, `spatial_arm` 1800; `tests/random_models/chain16.ron`, about
/// 8000, is above and checks the calls against the numeric recursion.)
pub const LARGE_MODEL_OPS: usize = 4000;

/// Operation count of a function's outputs (what it computes when emitted on its own), the
/// nodes of `given` read rather than computed.
fn function_count(d: &Derivation, spec: &FunctionSpec, given: &[(Id, String)]) -> OpCount {
    let roots: Vec<Id> = spec.outputs.iter().map(|(_, id)| *id).collect();
    let given: HashSet<Id> = given.iter().map(|(id, _)| *id).collect();
    d.graph.op_count_until(&roots, &given)
}

/// The outputs of every generated function (the standalone entry points, the fused pair and
/// the contact kinematics).
fn all_roots(d: &Derivation, specs: &[FunctionSpec], fused: &FusedTerms) -> Vec<Id> {
    let mut roots: Vec<Id> = specs
        .iter()
        .flat_map(|s| s.outputs.iter().map(|(_, id)| *id))
        .chain(fused.position.iter().map(|(_, id)| *id))
        .chain(fused.velocity.iter().map(|(_, id)| *id))
        .collect();
    for c in &d.contacts {
        roots.extend(contact_output_roots(c));
    }
    for (_, def) in d.graph.implicits() {
        roots.extend([def.residual, def.derivative, def.objective]);
    }
    roots
}

/// Operation count of a fused function, the cached nodes read rather than computed.
fn fused_count(d: &Derivation, spec: &FunctionSpec, given: &[(Id, String)]) -> usize {
    let roots: Vec<Id> = spec.outputs.iter().map(|(_, id)| *id).collect();
    let given: HashSet<Id> = given.iter().map(|(id, _)| *id).collect();
    d.graph.op_count_until(&roots, &given).total()
}

/// The body of `name` as a call of the fused pair, with stack scratch for the outputs it
/// does not return; `None` for the functions that keep their own expressions.
fn wrapper(model: &Model, fused: &FusedTerms, name: &str) -> Option<String> {
    let (n, nc, cl) = (model.n(), model.n_constraints(), fused.cache_len());
    let position = |h: &str, j: &str| {
        format!(
            "let mut cache = [0.0; {cl}];
{h}{j}             self.position_terms(q, h, j, &mut cache);
"
        )
    };
    let scratch = |name: &str, len: usize| {
        format!(
            "let {name} = &mut [0.0; {len}];
"
        )
    };
    let velocity = |t: &str, qd: &str, m: &str, f: &str, a: &str, c: &str| {
        format!(
            "{m}{f}{a}{c}self.velocity_terms({t}, q, {qd}, &cache,              rt::VelocityTerms {{ mass: m, inertial: f, applied, bias: c }});
"
        )
    };
    let doc = "/// Calls the fused pair `position_terms`/`velocity_terms` (large model: every                expression is compiled once).
";
    let body = match name {
        "mass_matrix" => format!(
            "fn mass_matrix(&self, q: &[f64], m: &mut [f64]) {{
{}{}{}}}",
            position(&scratch("h", nc), &scratch("j", nc * n)),
            scratch("qd", n),
            velocity(
                "0.0",
                "qd",
                "",
                &scratch("f", n),
                &scratch("applied", n),
                &scratch("c", nc)
            )
        ),
        "inertial_forces" => format!(
            "fn inertial_forces(&self, q: &[f64], qd: &[f64], f: &mut [f64]) {{
{}{}}}",
            position(&scratch("h", nc), &scratch("j", nc * n)),
            velocity(
                "0.0",
                "qd",
                &scratch("m", n * n),
                "",
                &scratch("applied", n),
                &scratch("c", nc)
            )
        ),
        "applied_forces" => format!(
            "fn applied_forces(&self, t: f64, q: &[f64], qd: &[f64], applied: &mut [f64])              {{
{}{}}}",
            position(&scratch("h", nc), &scratch("j", nc * n)),
            velocity(
                "t",
                "qd",
                &scratch("m", n * n),
                &scratch("f", n),
                "",
                &scratch("c", nc)
            )
        ),
        "equations" => format!(
            "fn equations(&self, t: f64, q: &[f64], qd: &[f64], m: &mut [f64], f: &mut [f64],              applied: &mut [f64]) {{
{}{}}}",
            position(&scratch("h", nc), &scratch("j", nc * n)),
            velocity("t", "qd", "", "", "", &scratch("c", nc))
        ),
        "constraint" => format!(
            "fn constraint(&self, q: &[f64], h: &mut [f64]) {{
{}}}",
            position("", &scratch("j", nc * n))
        ),
        "constraint_jacobian" => format!(
            "fn constraint_jacobian(&self, q: &[f64], j: &mut [f64]) {{
{}}}",
            position(&scratch("h", nc), "")
        ),
        "constraint_bias" => format!(
            "fn constraint_bias(&self, q: &[f64], qd: &[f64], c: &mut [f64]) {{
{}{}}}",
            position(&scratch("h", nc), &scratch("j", nc * n)),
            velocity(
                "0.0",
                "qd",
                &scratch("m", n * n),
                &scratch("f", n),
                &scratch("applied", n),
                ""
            )
        ),
        "constraint_terms" => format!(
            "fn constraint_terms(&self, q: &[f64], qd: &[f64], j: &mut [f64], c: &mut [f64])              {{
{}{}}}",
            position(&scratch("h", nc), ""),
            velocity(
                "0.0",
                "qd",
                &scratch("m", n * n),
                &scratch("f", n),
                &scratch("applied", n),
                ""
            )
        ),
        _ => return None,
    };
    Some(format!(
        "{doc}{body}
"
    ))
}

/// Every node a contact's outputs read (geometry and kinematics), for the run-time
/// parameters' `derive`.
fn contact_output_roots(c: &ContactTerms) -> Vec<Id> {
    let r = &c.relative;
    let mut roots: Vec<Id> = c
        .position
        .iter()
        .chain(&c.cam_point)
        .chain(&c.normal)
        .chain(&r.point)
        .chain(&r.axis)
        .chain(&r.direction)
        .chain(&r.xy)
        .chain(&r.convective)
        .copied()
        .collect();
    roots.extend([c.force_scale, c.parameter, c.curvature, c.sliding]);
    roots.extend(r.columns.iter().flatten());
    roots
}

/// `out.<field>` targets of a contact's geometry (`prefix` = `out[k].` or `out.geometry.`).
fn geometry_outputs(g: &mut Graph, c: &ContactTerms, prefix: &str) -> Vec<(String, Id)> {
    let mut outputs = Vec::new();
    let r = &c.relative;
    let vectors = [
        ("position", c.position),
        ("follower", r.point),
        ("normal", c.normal),
        ("axis", r.axis),
    ];
    for (field, v) in vectors {
        for (a, &p) in v.iter().enumerate() {
            outputs.push((format!("{prefix}{field}[{a}]"), p));
        }
    }
    let direction = unit_vector(g, r.direction);
    for (a, &p) in direction.iter().enumerate() {
        outputs.push((format!("{prefix}direction[{a}]"), p));
    }
    outputs.extend([
        (format!("{prefix}x"), c.cam_point[0]),
        (format!("{prefix}y"), c.cam_point[1]),
        (format!("{prefix}force_scale"), c.force_scale),
        (format!("{prefix}parameter"), c.parameter),
        (format!("{prefix}curvature"), c.curvature),
        (format!("{prefix}sliding_speed"), c.sliding),
    ]);
    outputs
}

/// v/|v| (the direction of a follower's motion).
fn unit_vector(g: &mut Graph, v: [Id; 3]) -> [Id; 3] {
    g.set_section("outputs: the follower's direction of motion");
    let squares: Vec<Id> = v.iter().map(|&c| g.mul(c, c)).collect();
    let norm2 = g.sum(squares);
    let norm = g.sqrt(norm2);
    v.map(|c| g.div(c, norm))
}

fn geometry_spec(d: &mut Derivation) -> FunctionSpec {
    let mut outputs = Vec::new();
    let contacts = d.contacts.clone();
    for (k, c) in contacts.iter().enumerate() {
        outputs.extend(geometry_outputs(&mut d.graph, c, &format!("out[{k}].")));
    }
    FunctionSpec {
        doc: "Where and how every contact touches: the contact point in ground and cam \
              coordinates, the follower point, the normal, the force scale, the profile's \
              parameter and curvature there, the follower's direction of motion, the sliding \
              speed."
            .into(),
        name: "contact_geometry".into(),
        params: vec![
            param("q", "&[f64]"),
            param("qd", "&[f64]"),
            param("out", "&mut [rt::ContactGeometry]"),
        ],
        ret: None,
        outputs,
        tail: String::new(),
    }
}

fn prescribed_spec(d: &Derivation) -> FunctionSpec {
    let mut outputs = Vec::new();
    for drive in &d.drives {
        let i = drive.coordinate;
        outputs.push((format!("q[{i}]"), drive.motion[0]));
        outputs.push((format!("qd[{i}]"), drive.motion[1]));
        outputs.push((format!("qdd[{i}]"), drive.motion[2]));
    }
    FunctionSpec {
        doc: "q, q̇, q̈ of the driven coordinates at time t.".into(),
        name: "prescribed".into(),
        params: vec![
            param("t", "f64"),
            param("q", "&mut [f64]"),
            param("qd", "&mut [f64]"),
            param("qdd", "&mut [f64]"),
        ],
        ret: None,
        outputs,
        tail: String::new(),
    }
}

fn energy_spec(d: &Derivation) -> FunctionSpec {
    let e = &d.energy;
    FunctionSpec {
        doc: "Kinetic energy from the body velocities; gravity and spring potentials.".into(),
        name: "energy".into(),
        params: vec![param("q", "&[f64]"), param("qd", "&[f64]")],
        ret: Some("rt::Energy"),
        outputs: vec![
            ("let kinetic".into(), e.kinetic),
            ("let gravity".into(), e.gravity),
            ("let spring".into(), e.spring),
        ],
        tail: "rt::Energy { kinetic, gravity, spring }".into(),
    }
}

fn contact_kinematics_dispatch(model: &Model, parametric: bool) -> String {
    let derived = if parametric { "&self.derived, " } else { "" };
    if model.contacts.is_empty() {
        return "/// No contact: nothing to write.\n\
                fn contact_kinematics_into(&self, _q: &[f64], _qd: &[f64], _k: usize, _out: &mut rt::ContactKinematics) {}\n"
            .to_string();
    }
    let body = if model.contacts.len() == 1 {
        format!("if k == 0 {{ contact_kinematics_0({derived}q, qd, out); }}")
    } else {
        let arms: String = (0..model.contacts.len())
            .map(|k| format!("{k} => contact_kinematics_{k}({derived}q, qd, out),\n"))
            .collect();
        format!("match k {{\n{arms}_ => {{}}\n}}")
    };
    format!(
        "/// f1, f2, J1, J2 and the convective terms of contact `k` into `out` (unchanged for an \
         unknown k).\n\
         fn contact_kinematics_into(&self, q: &[f64], qd: &[f64], k: usize, out: &mut rt::ContactKinematics) {{\n\
         {body}\n}}\n"
    )
}

/// The specifications of `contact_kinematics_<k>`: every contact's geometry and its
/// follower point's cam-frame kinematics.
fn contact_kinematics_specs(
    model: &Model,
    d: &mut Derivation,
    parametric: bool,
) -> Vec<FunctionSpec> {
    let n = model.n();
    let contacts = d.contacts.clone();
    contacts
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let mut outputs = geometry_outputs(&mut d.graph, c, "out.geometry.");
            let r = &c.relative;
            outputs.push(("out.x".to_string(), r.xy[0]));
            outputs.push(("out.y".to_string(), r.xy[1]));
            for i in 0..n {
                outputs.push((format!("out.j1[{i}]"), r.columns[i][0]));
            }
            for i in 0..n {
                outputs.push((format!("out.j2[{i}]"), r.columns[i][1]));
            }
            outputs.push(("out.conv1".to_string(), r.convective[0]));
            outputs.push(("out.conv2".to_string(), r.convective[1]));
            FunctionSpec {
                doc: format!(
                    "Geometry of contact `{}` and its follower point's cam-frame kinematics, \
                     into `out` (J1 and J2 of length {n}).",
                    c_name(model, k)
                ),
                name: format!("contact_kinematics_{k}"),
                params: [
                    parametric.then_some(Param {
                        name: "derived",
                        ty: "&Derived",
                        always_used: false,
                    }),
                    Some(param("q", "&[f64]")),
                    Some(param("qd", "&[f64]")),
                    Some(Param {
                        name: "out",
                        ty: "&mut rt::ContactKinematics",
                        always_used: true,
                    }),
                ]
                .into_iter()
                .flatten()
                .collect(),
                ret: None,
                outputs,
                tail: String::new(),
            }
        })
        .collect()
}

/// Emits the `contact_kinematics_<k>` functions.
fn contact_kinematics_helpers(
    d: &Derivation,
    specs: &[FunctionSpec],
    counts: &mut Vec<(String, OpCount)>,
    derived: &[(Id, String)],
) -> String {
    let mut out = String::new();
    for spec in specs {
        let (text, count) = emit_function_given(d, spec, "", false, derived);
        out.push_str(ALLOW_LITERALS);
        out.push('\n');
        out.push_str(&text);
        counts.push((spec.name.clone(), count));
    }
    out
}

/// The residual ψ(s; p) with ψ′(s), and the objective, of every implicit variable (a contact
/// parameter), as free functions `<name>_residual` and `<name>_objective` that the solves
/// call (`rt::contact::solve`).
fn implicit_helpers(
    d: &Derivation,
    counts: &mut Vec<(String, OpCount)>,
    derived: &[(Id, String)],
) -> String {
    let g = &d.graph;
    let names = Names::of_vars(g);
    let parametric = d.has_runtime_parameters();
    let mut out = String::new();
    for (id, def) in g.implicits() {
        let base = names.var(g, id);
        let mut params: Vec<Param> = Vec::new();
        if parametric {
            params.push(Param {
                name: "derived",
                ty: "&Derived",
                always_used: false,
            });
        }
        let input_names = &def.input_names;
        for &name in input_names {
            params.push(Param {
                name,
                ty: "f64",
                always_used: false,
            });
        }
        params.push(Param {
            name: "s",
            ty: "f64",
            always_used: false,
        });
        let mut given: Vec<(Id, String)> = derived.to_vec();
        given.push((def.unknown, "s".to_string()));
        for (&p, name) in def.placeholders.iter().zip(input_names) {
            given.push((p, name.to_string()));
        }
        let residual = FunctionSpec {
            doc: format!(
                "{}: ψ(s) and ψ′(s), whose root with ψ′ < 0 Newton finds.",
                def.description
            ),
            name: format!("{base}_residual"),
            params: params.clone(),
            ret: Some("[f64; 2]"),
            outputs: vec![
                ("let value".to_string(), def.residual),
                ("let slope".to_string(), def.derivative),
            ],
            tail: "[value, slope]".to_string(),
        };
        let objective = FunctionSpec {
            doc: format!(
                "{}: the objective the root minimises (what a scan of the range compares).",
                def.description
            ),
            name: format!("{base}_objective"),
            params,
            ret: Some("f64"),
            outputs: vec![(RETURN.to_string(), def.objective)],
            tail: String::new(),
        };
        for spec in [residual, objective] {
            let (text, count) = emit_function_given(d, &spec, "", false, &given);
            out.push_str(ALLOW_LITERALS);
            out.push('\n');
            out.push_str(&text);
            counts.push((spec.name.clone(), count));
        }
    }
    out
}

fn c_name(model: &Model, k: usize) -> &str {
    &model.contacts[k].name
}

/// Emits `spec`; the nodes of `given` are read from the expressions paired with them (e.g.
/// `cache[3]`) instead of being computed.
fn emit_function_given(
    d: &Derivation,
    spec: &FunctionSpec,
    prelude: &str,
    method: bool,
    given: &[(Id, String)],
) -> (String, OpCount) {
    emit_function_full(d, spec, prelude, method, given, &[], &[])
}

/// [`emit_function_given`], the sine–cosine pairs of `memo` computed through the cache
/// (`rt::sin_cos_memo`), and the Newton solves of the implicit variables of `warm` started
/// from the solutions kept where it says.
fn emit_function_full(
    d: &Derivation,
    spec: &FunctionSpec,
    prelude: &str,
    method: bool,
    given: &[(Id, String)],
    memo: &[TrigMemo],
    warm: &[(Id, String)],
) -> (String, OpCount) {
    let g = &d.graph;
    let roots: Vec<Id> = spec.outputs.iter().map(|(_, id)| *id).collect();
    let given_set: HashSet<Id> = given.iter().map(|(id, _)| *id).collect();
    let count = g.op_count_until(&roots, &given_set);
    let mut body = Emitter::new(g, &spec.outputs, given, &d.symbols.params);
    for m in memo {
        body.memo.insert(m.sin, *m);
        body.memo.insert(m.cos, *m);
    }
    body.warm = warm.iter().cloned().collect();
    if d.has_runtime_parameters() {
        body.derived_arg = if method {
            "&self.derived, "
        } else {
            "derived, "
        }
        .to_string();
    }
    let (bindings, used_vars) = body.bindings();
    let inputs = input_bindings(d, &used_vars);
    let mut used_params: HashSet<&str> = inputs.iter().map(|(p, _)| *p).collect();
    if body.solves_read_derived && !method {
        used_params.insert("derived");
    }
    // A scalar argument read under its own name.
    for (id, source) in given {
        if is_identifier(source) && body.names.contains_key(id) {
            if let Some(p) = spec.params.iter().find(|p| p.name == source) {
                used_params.insert(p.name);
            }
        }
    }
    // A parameter that a bound given expression reads (`derived.k1`, `cache[3]`).
    for p in &spec.params {
        let reads = |(id, source): &(Id, String)| {
            body.names.contains_key(id)
                && (source.starts_with(&format!("{}.", p.name))
                    || source.starts_with(&format!("{}[", p.name)))
        };
        if given.iter().any(reads) {
            used_params.insert(p.name);
        }
    }
    let params: Vec<String> = spec
        .params
        .iter()
        .map(|p| {
            let written = spec
                .outputs
                .iter()
                .any(|(t, _)| t.starts_with(&format!("{}[", p.name)));
            let used = p.always_used || used_params.contains(p.name) || written;
            let name = if used {
                p.name.to_string()
            } else {
                format!("_{}", p.name)
            };
            format!("{name}: {}", p.ty)
        })
        .collect();
    let receiver = if method { "&self, " } else { "" };
    let ret = spec.ret.map(|r| format!(" -> {r}")).unwrap_or_default();
    let mut text = format!(
        "/// {}\nfn {}({receiver}{}){ret} {{\n",
        spec.doc,
        spec.name,
        params.join(", ")
    );
    for (_, line) in &inputs {
        text.push_str(line);
    }
    text.push_str(prelude);
    text.push_str(&bindings);
    let mut fields = String::new();
    let filled = zero_filled_arrays(g, &spec.outputs);
    for array in &filled {
        let _ = writeln!(text, "{array}.fill(0.0);");
    }
    for (target, id) in &spec.outputs {
        if g.is_zero(*id) && array_of(target).is_some_and(|a| filled.contains(&a)) {
            continue;
        }
        if target == RETURN {
            let _ = writeln!(text, "{}", body.print(*id, 0));
        } else if let Some(field) = target.strip_prefix(FIELD) {
            let value = body.print(*id, 0);
            if value == field {
                let _ = writeln!(fields, "{field},");
            } else {
                let _ = writeln!(fields, "{field}: {value},");
            }
        } else {
            let _ = writeln!(text, "{target} = {};", body.print(*id, 0));
        }
    }
    text.push_str(&spec.tail.replace(FIELDS, &fields));
    text.push_str("\n}\n");
    (text, count)
}

/// Outputs that are zero, per array, from which the array is cleared with one `fill(0.0)`
/// instead of one assignment each: a sparse M or J of a long chain (an N-four-bar's 81×81 M
/// is 98 % zeros) would otherwise be mostly `m[k] = 0.0;` lines. Below it, the assignments
/// are kept (and the small models' code stays as it was).
const ZERO_FILL_THRESHOLD: usize = 64;

/// The array of an output target `name[index]` (`m`, `out.mass`), if it is one.
fn array_of(target: &str) -> Option<&str> {
    let (array, rest) = target.split_once('[')?;
    (rest.ends_with(']') && !rest.contains('[')).then_some(array)
}

/// The arrays with at least [`ZERO_FILL_THRESHOLD`] zero outputs, in order of appearance.
fn zero_filled_arrays<'t>(g: &Graph, outputs: &'t [(String, Id)]) -> Vec<&'t str> {
    let mut counts: Vec<(&str, usize)> = Vec::new();
    for (target, id) in outputs {
        let Some(array) = array_of(target) else {
            continue;
        };
        if !g.is_zero(*id) {
            continue;
        }
        match counts.iter_mut().find(|(a, _)| *a == array) {
            Some((_, count)) => *count += 1,
            None => counts.push((array, 1)),
        }
    }
    counts
        .into_iter()
        .filter(|(_, count)| *count >= ZERO_FILL_THRESHOLD)
        .map(|(array, _)| array)
        .collect()
}

/// Output target prefix `field:name`: the value becomes `name: value,` in the place of
/// [`FIELDS`] in the function's tail (a struct built in one literal).
pub(crate) const FIELD: &str = "field:";

/// Where the fields of [`FIELD`] targets go in a function's tail.
pub(crate) const FIELDS: &str = "__fields__";

/// `let q1 = q[0];` lines for the variables the function uses, with the parameter they read.
fn input_bindings(d: &Derivation, used: &HashSet<Id>) -> Vec<(&'static str, String)> {
    let mut lines = Vec::new();
    let names = Names::of_vars(&d.graph);
    for (i, id) in d.symbols.q.iter().enumerate() {
        if used.contains(id) {
            lines.push(("q", format!("let {} = q[{i}];\n", names.var(&d.graph, *id))));
        }
    }
    for (i, id) in d.symbols.qd.iter().enumerate() {
        if used.contains(id) {
            lines.push((
                "qd",
                format!("let {} = qd[{i}];\n", names.var(&d.graph, *id)),
            ));
        }
    }
    if used.contains(&d.symbols.t) {
        lines.push(("t", String::new()));
    }
    for &id in &d.symbols.params {
        if used.contains(&id) {
            let Node::Var(k) = d.graph.node(id) else {
                continue;
            };
            let field = &d.graph.var_names()[k as usize];
            lines.push((
                "p",
                format!("let {} = p.{field};\n", names.var(&d.graph, id)),
            ));
        }
    }
    lines
}

/// Turns the section marker statements back into comments after formatting (prettyplease
/// may have wrapped a long marker over several lines).
fn restore_comments(code: &str) -> String {
    let marker = format!("{SECTION_MACRO}!(");
    let mut out = String::with_capacity(code.len());
    let mut pending: Option<(String, String)> = None;
    for line in code.lines() {
        let trimmed = line.trim_start();
        if let Some((indent, mut text)) = pending.take() {
            text.push_str(trimmed);
            if trimmed.ends_with(");") {
                push_comment(&mut out, &indent, &text);
            } else {
                pending = Some((indent, text));
            }
            continue;
        }
        if let Some(rest) = trimmed.strip_prefix(&marker) {
            let indent = line[..line.len() - trimmed.len()].to_string();
            if rest.ends_with(");") {
                push_comment(&mut out, &indent, rest);
            } else {
                pending = Some((indent, rest.to_string()));
            }
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// Writes `// text` for a marker's argument `"text");`.
fn push_comment(out: &mut String, indent: &str, argument: &str) {
    let text = argument
        .trim_end_matches(';')
        .trim_end_matches(')')
        .trim()
        .trim_matches('"');
    let _ = writeln!(out, "{indent}// {text}");
}
