//! camchain-codegen: from a RON chain description to specialised Rust (build time only: a
//! build script reaches it through `camchain-build`).
//!
//! Module map:
//! - [`schema`]: the RON file format, parsing and validation with file/line/field errors.
//! - [`model`]: the validated model.
//! - [`profile`]: one-variable expressions (cam profiles, drives) parsed with `syn`.
//! - [`expr`]: the hash-consed symbolic expression DAG: folding, differentiation,
//!   interpretation and operation counts.
//! - [`linear`]: the pass that collects nested sums into linear combinations.
//! - [`lint`]: warnings for valid models that look mistaken (degrees for radians, …).
//! - [`kinematics`]: forward recursion of rotations, positions, velocities, accelerations (9).
//! - [`contact`]: the contact family: the follower seen from the cam on any body, profiles
//!   (explicit, polar, parametric), knife edges, rollers and flat faces: h, J, c (1–8).
//! - [`dynamics`]: backward Newton–Euler recursion giving M, F, Q (10–13), and energies.
//! - [`derive`](mod@derive): the whole derivation of a model in one graph.
//! - [`design`]: cams designed from a follower's motion law (the envelope construction).
//! - [`emit`]: the generated Rust module.

pub mod articulated;
pub mod assembly;
pub mod contact;
pub mod derive;
pub mod dynamics;
pub mod emit;
pub mod expr;
pub mod kinematics;
pub mod linear;
pub mod lint;
pub mod loops;

// The model file and the validated model live in `camchain-model` (shared with the numeric
// reference); their paths stay available here.
pub use camchain_model::{design, error, model, profile, read_model_file, samples, schema};

pub use derive::Derivation;
pub use error::ModelError;
pub use model::{Model, ParameterMode};

pub use emit::{Choice, EmitOptions, EntryPoints, Formulation, Generated};

use std::path::Path;

/// Reads, validates and checks a model file and generates its Rust module with the default
/// [`EmitOptions`].
///
/// `display` is the path shown in messages and in the generated header (e.g.
/// `models/paper_concave.ron`). Every failure is a [`ModelError`] naming the file, line,
/// column and field.
pub fn generate_file(path: &Path, display: &Path) -> Result<Generated, ModelError> {
    let source = read_model_file(path, display)?;
    generate_source(&source, display, &EmitOptions::default())
}

/// Everything the build checks of a model file before it generates code: parsing and
/// validation ([`schema::parse_model`]), the symbolic derivation ([`Derivation`]) and the
/// assembly check of the initial state ([`assembly::assemble`]), each problem located in the
/// file (`file:line:column: field: message`). The command line runs it on a model file before
/// simulating it on the numeric reference, so that both report the same problems.
pub fn check_source(source: &str, display: &Path) -> Result<Model, ModelError> {
    check_source_in(source, display, schema::Files::BesideModel)
}

/// [`check_source`] reading the files the model names (its tables of points) from `files`.
pub fn check_source_in(
    source: &str,
    display: &Path,
    files: schema::Files,
) -> Result<Model, ModelError> {
    let model = schema::parse_model_from(source, display, &[], ParameterMode::AsDeclared, files)?;
    derive_and_assemble(&model, source, display, expr::NODE_LIMIT)?;
    Ok(model)
}

/// The warnings of [`lint::warnings`] for a validated model, located in its file like errors
/// (`file:line:column: field: message`).
pub fn located_warnings(model: &Model, source: &str, display: &Path) -> Vec<ModelError> {
    lint::warnings(model)
        .into_iter()
        .map(|w| schema::field_error(display, source, &w.field, w.message))
        .collect()
}

/// The derivation of a validated model ([`Derivation::checked_with_limit`]: a model too large
/// to derive is an error on its file), once its initial state is known to assemble onto its cams
/// (located at `initial`).
fn derive_and_assemble(
    model: &Model,
    source: &str,
    display: &Path,
    node_limit: usize,
) -> Result<Derivation, ModelError> {
    let derivation = Derivation::checked_with_limit(model, node_limit)
        .map_err(|e| unlocated(display, e.to_string()))?;
    assembly::assemble_located(model, &derivation)
        .map_err(|(field, message)| schema::field_error(display, source, &field, message))?;
    Ok(derivation)
}

/// An error on the file as a whole (line 0: not located).
fn unlocated(display: &Path, message: String) -> ModelError {
    ModelError {
        file: display.to_path_buf(),
        line: 0,
        column: 0,
        field: String::new(),
        message,
    }
}

/// Validates and checks the text of a model file and generates its Rust module: parsing and
/// validation ([`schema::parse_model`]), the symbolic derivation ([`Derivation`]), the
/// assembly check of the initial state ([`assembly::assemble`]) and the emission
/// ([`emit::generate_with`]). `display` names the file in messages and in the header.
pub fn generate_source(
    source: &str,
    display: &Path,
    options: &EmitOptions,
) -> Result<Generated, ModelError> {
    generate_source_and_model(source, display, options).map(|(generated, _)| generated)
}

/// [`generate_source`], also handing back the validated model (its files, its warnings):
/// a build script reads them without parsing and validating the file a second time.
pub fn generate_source_and_model(
    source: &str,
    display: &Path,
    options: &EmitOptions,
) -> Result<(Generated, Model), ModelError> {
    let files = match &options.files_dir {
        Some(dir) => schema::Files::In(dir),
        None => schema::Files::BesideModel,
    };
    let model = schema::parse_model_from(source, display, &[], options.parameters, files)?;
    if !schema::is_identifier(&model.name) {
        return Err(schema::field_error(
            display,
            source,
            "name",
            format!(
                "model name `{}` is not a valid Rust identifier (ASCII letters, digits and `_`, \
                 not starting with a digit, not a keyword), and the build names the generated \
                 module after it: give the model a `name:` (the file name is the default)",
                model.name
            ),
        ));
    }
    let derivation = derive_and_assemble(&model, source, display, options.node_limit)?;
    let shown = display.to_string_lossy().replace('\\', "/");
    let generated = emit::generate_from(&model, derivation, &shown, options)
        .map_err(|message| unlocated(display, message))?;
    Ok((generated, model))
}
