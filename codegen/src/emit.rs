//! Emission of the generated Rust module.
//!
//! Each generated function is emitted from the roots it needs only, so it contains only the
//! operations its outputs depend on. Inside a function every node used more than once (and
//! every sine, cosine or other call) gets a named `let` binding, computed once; nodes used
//! once are written inline. Bindings come in creation order, grouped under comments naming
//! the body and term they belong to. The text is formatted by `prettyplease`; the same
//! model always gives the same bytes.
//!
//! The submodules, one concept each:
//! - `spec`: what a generated function is (`FunctionSpec`, its parameters and targets);
//! - `methods`: the specification of every `Dynamics` method, with docs in the model's own
//!   terms; `contacts`: the contacts' geometry and kinematics functions; `implicit`: the
//!   residuals and objectives of the contact parameters Newton solves;
//! - `fused`: the pair a right-hand side calls and the cache between them; `trigonometry`:
//!   sines and cosines of joint angles shared between the two; `wrapper`: the entry points
//!   written as calls of the pair (large models);
//! - `function`: one function's text; `emitter`: its bindings and expressions; `names`: the
//!   identifiers of variables; `literals`: numbers and strings as Rust literals;
//! - `model_type`, `info`, `tables`, `parameters`: the items around the functions (the
//!   `Model` type, its static description, tabulated functions, run-time parameters);
//! - `header`: the operation table; `render`: prettyplease and the section comments.

use crate::derive::Derivation;
use crate::expr::{Id, OpCount};
use crate::model::Model;
use std::fmt::Write;

mod articulated;
mod contacts;
mod docs;
mod emitter;
mod function;
mod fused;
mod header;
mod implicit;
mod info;
mod lengths;
mod literals;
mod methods;
mod model_type;
mod names;
mod parameters;
mod parts;
mod render;
mod spec;
mod tables;
#[cfg(test)]
mod testing;
mod trigonometry;
mod wrapper;

pub use articulated::{Choice, Formulation};
use contacts::{contact_kinematics_dispatch, contact_kinematics_helpers, contact_kinematics_specs};
use docs::ConstraintDocs;
use function::{Extras, SparseArray, emit_method, sparse_rows};
use fused::{FusedTerms, all_roots, function_count, fused_count};
use header::{header, op_count_table};
use implicit::implicit_helpers;
use info::info_static;
use literals::ALLOW_LITERALS;
use methods::function_specs;
use model_type::{embedded_source, model_type};
use parameters::RuntimeParameters;
use tables::table_helpers;
use trigonometry::TrigMemo;
use wrapper::wrapper;

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
    /// Whether `Model` gets the inherent `assemble`, `step`, `sample`, `simulate` and
    /// `simulate_metrics` (true by default). They call the runtime's `engine` feature; a crate
    /// that links `camchain-runtime` with `default-features = false` (the contract alone, no
    /// linear algebra, the fastest cold build) turns them off and simulates elsewhere.
    pub simulation_methods: bool,
    /// Which forward dynamics the generated code gives the runtime ([`Formulation`]): by
    /// default the one with the smaller estimated operation count per right-hand side (the
    /// header shows both estimates).
    pub formulation: Formulation,
    /// Whether `Model`'s methods write a product summed with another term as
    /// `a.mul_add(b, c)` (one rounding instead of two). Off by default: without the
    /// processor's FMA instructions enabled at compile time (`-C target-cpu=native` on a
    /// recent x86-64, `-C target-feature=+fma`), `mul_add` is a call of the C library's `fma`.
    /// `camchain_build::Config` turns it on when the target has them (its build script sees
    /// `CARGO_CFG_TARGET_FEATURE`), where it saves an instruction per product: 10–15 % of a
    /// long chain's right-hand side (BENCHMARKS.md). Rust never fuses `a * b + c` itself, as
    /// C compilers do by default.
    pub fused_multiply_add: bool,
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
            simulation_methods: true,
            formulation: Formulation::Auto,
            fused_multiply_add: false,
        }
    }
}

/// The path of the runtime that generated code uses unless told otherwise: the `camchain`
/// facade's re-export.
pub const DEFAULT_RUNTIME_PATH: &str = "::camchain::runtime";

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
    // The model file's choice, unless it leaves it to the build's.
    let asked = match model.simulation.formulation {
        Formulation::Auto => options.formulation,
        chosen => chosen,
    };
    let dense_ops = d.graph.op_count(&dense_roots(&d)).total();
    let mut choice = articulated::choose(&d, dense_ops, asked);
    // A large model on the articulated route gives M column by column (n products M e_j,
    // O(n) code each) instead of emitting its n² entries: M is off its right-hand side's
    // path, and M's code was most of such a model's build.
    let mass_by_columns = choice.articulated && dense_ops > LARGE_MODEL_OPS;
    choice.mass_by_columns = mass_by_columns;
    let aba = choice
        .articulated
        .then(|| articulated::groups(&d, mass_by_columns));
    let mut fused = FusedTerms::new(&mut d, aba);
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
    let fused_specs = fused.specs(&ConstraintDocs::new(model, &d));
    let fused_ops: usize = fused_specs
        .iter()
        .map(|(spec, given)| fused_count(&d, spec, &[given.clone(), derived("self.")].concat()))
        .sum();
    // M's entries are not emitted at all when M comes column by column: the entry points
    // call the pair whatever was asked.
    let wrap = mass_by_columns
        || match options.entry_points {
            EntryPoints::Auto => fused_ops > LARGE_MODEL_OPS,
            EntryPoints::Standalone => false,
            EntryPoints::ViaFusedPair => true,
        };
    // M and J of many zeros (chained loops) are written by the fused pair within their
    // rows' extents only, which the model declares (`Dynamics::mass_rows`, `jacobian_rows`).
    let n = model.n();
    let sparse_of = |name: &str| -> Vec<SparseArray> {
        let array = if name == "position_terms" {
            "j"
        } else {
            "out.mass"
        };
        fused_specs
            .iter()
            .filter(|(s, _)| s.name == name)
            .filter_map(|(s, _)| sparse_rows(&d.graph, &s.outputs, array, n))
            .map(|rows| (array, n, rows))
            .collect()
    };
    let (mass_sparse, jacobian_sparse) = (sparse_of("velocity_terms"), sparse_of("position_terms"));
    let rows_of = |s: &[SparseArray]| s.first().map(|(_, _, rows)| rows.clone());
    let (mass_rows, jacobian_rows) = (rows_of(&mass_sparse), rows_of(&jacobian_sparse));
    let cleared: Vec<&str> = [("m", &mass_rows), ("j", &jacobian_rows)]
        .into_iter()
        .filter(|(_, rows)| rows.is_some())
        .map(|(a, _)| a)
        .collect();
    let mut functions = String::new();
    // The modules of the large methods' bodies (outside the `impl` blocks).
    let mut part_items = String::new();
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
        let entry = wrapper(model, fused.cache_len(), &spec.name, &cleared).filter(|_| wrap);
        let (text, count) = match entry {
            Some(text) => (text, function_count(&d, spec, &derived("self."))),
            None => {
                let extras = Extras {
                    warm,
                    items: Some(&mut part_items),
                    fused_multiply_add: options.fused_multiply_add,
                    ..Default::default()
                };
                emit_method(&d, spec, &derived("self."), extras)
            }
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
        let sparse: &[SparseArray] = match spec.name.as_str() {
            "position_terms" => &jacobian_sparse,
            _ => &mass_sparse,
        };
        let extras = Extras {
            memo,
            warm: &warm,
            sparse,
            items: Some(&mut part_items),
            fused_multiply_add: options.fused_multiply_add,
            written_if_given: None,
        };
        let (text, count) = emit_method(&d, spec, &given, extras);
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
    for (name, matrix, writer, rows) in [
        ("mass_rows", "M", "velocity_terms", &mass_rows),
        ("jacobian_rows", "J", "position_terms", &jacobian_rows),
    ] {
        if let Some(rows) = rows {
            let list: Vec<String> = rows.iter().map(|(s, e)| format!("({s}, {e})")).collect();
            let _ = writeln!(
                functions,
                "/// For each row of {matrix}, the columns [start, end) outside which it is zero:                  `{writer}` writes {matrix} within them only.\n\
                 fn {name}(&self) -> Option<&'static [(usize, usize)]> {{ Some(&[{}]) }}",
                list.join(", ")
            );
        }
    }
    if choice.articulated {
        let cache_given = fused.cache_given();
        let (aba_specs, factors) = articulated::specs(
            &d,
            &fused.articulated,
            &fused.response,
            &cache_given,
            fused.cache_len() > 0,
            &derived("self."),
        );
        for (spec, given) in &aba_specs {
            let extras = Extras {
                items: Some(&mut part_items),
                fused_multiply_add: options.fused_multiply_add,
                // The runtime passes no factors when it will not call the response.
                written_if_given: (spec.name == "articulated_terms").then_some("out.factors"),
                ..Default::default()
            };
            let (text, count) = emit_method(&d, spec, given, extras);
            functions.push_str(&text);
            within_code_limit(functions.len(), options.code_limit)?;
            op_counts.push((spec.name.clone(), count));
        }
        let _ = writeln!(
            functions,
            "/// Entries of the factors `articulated_terms` writes for `articulated_response`.\n\
             fn articulated_len(&self) -> usize {{ {} }}",
            factors.max(1)
        );
        if d.articulated.row_solution.is_some() {
            let _ = writeln!(
                functions,
                "/// `articulated_terms` solves the model's one constraint row when given it.\n\
                 fn articulated_rows(&self) -> usize {{ 1 }}"
            );
        }
    }
    let mut inherent = String::new();
    if mass_by_columns {
        let (spec, given) =
            articulated::mass_times_spec(&d, &fused.mass, &fused.cache_given(), &derived("self."));
        let extras = Extras {
            items: Some(&mut part_items),
            fused_multiply_add: options.fused_multiply_add,
            ..Default::default()
        };
        let (text, count) = emit_method(&d, &spec, &given, extras);
        let _ = writeln!(inherent, "impl Model {{\n{text}}}");
        op_counts.push((spec.name.clone(), count));
    }
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
    file.push_str(&model_type(
        model,
        source,
        runtime.is_some(),
        options.simulation_methods,
    ));
    if let Some(rp) = &runtime {
        file.push_str(&rp.items(model, &d, source));
    }
    if let Some(text) = &options.embedded_source {
        file.push_str(&embedded_source(model, source, text));
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
    file.push_str(&inherent);
    file.push_str(&part_items);
    file.push_str(&helpers);
    file.push_str(&op_count_table(&op_counts));
    within_code_limit(file.len(), options.code_limit)?;
    let formatted = render::format(&file)?;
    Ok(Generated {
        name: model.name.clone(),
        source: source.to_string(),
        code: format!(
            "{}\n{}",
            header(model, source, &op_counts, wrap, runtime.is_some(), &choice),
            formatted
        ),
        op_counts,
    })
}

/// The longest generated module, before formatting: 32 MiB. Formatting parses the whole
/// module into a syntax tree of some 50 bytes per byte of text (a spatial chain of 200
/// bodies, `codegen/tests/common/chain.rs`, is 17.6 MB of text and takes 1.0 GB in all), and
/// no compiler builds a much longer module in reasonable time; a model whose code would be
/// longer is refused before it is formatted.
/// The velocity level's outputs of the dense route: M, F, Q and every row's c.
fn dense_roots(d: &Derivation) -> Vec<Id> {
    let dy = &d.dynamics;
    let rows = d.constraint_rows();
    dy.mass
        .iter()
        .flatten()
        .chain(&dy.inertial)
        .chain(&dy.applied)
        .copied()
        .chain(rows.iter().map(|r| r.2))
        .collect()
}

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

impl Generated {
    /// One-line description for the module index.
    pub fn summary(&self) -> String {
        format!("Generated model `{}` (from `{}`).", self.name, self.source)
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
