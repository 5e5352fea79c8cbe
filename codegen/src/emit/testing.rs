//! Models for the emitter's unit tests: built-in model files, parsed and derived.

use crate::derive::Derivation;
use crate::model::Model;
use std::path::Path;

/// `models/<name>.ron` of the workspace, parsed.
pub(super) fn model(name: &str) -> Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../models/{name}.ron"));
    let text = std::fs::read_to_string(&path).expect("the built-in model file exists");
    crate::schema::parse_model(&text, &path).expect("the built-in model is valid")
}

/// The model `name` and its derivation.
pub(super) fn derived(name: &str) -> (Model, Derivation) {
    let m = model(name);
    let d = Derivation::new(&m);
    (m, d)
}
