//! The `Model` type: its definition (a unit struct, or the parameter values and what derives
//! from them), its constructors and inherent methods, `DEFAULT`, `boxed`, and the embedded
//! model file.

use super::literals::{ALLOW_UNUSED, raw_string};
use crate::model::Model;
use std::fmt::Write;

/// `simulation_methods`: whether the inherent `assemble`, `step`, `sample`, `simulate` and
/// `simulate_metrics` are emitted (they call the runtime's `engine` feature).
pub(super) fn model_type(
    model: &Model,
    source: &str,
    parametric: bool,
    simulation_methods: bool,
) -> String {
    let mut doc = if simulation_methods {
        format!(
            "/// The model `{}`, generated from `{source}`: implements [`rt::Dynamics`]; simulate \
             it with\n/// [`Model::assemble`], [`Model::step`] and [`Model::simulate`].\n",
            model.name
        )
    } else {
        format!(
            "/// The model `{}`, generated from `{source}`: implements [`rt::Dynamics`].\n",
            model.name
        )
    };
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
    let simulation = if simulation_methods {
        SIMULATION_METHODS
    } else {
        ""
    };
    format!(
        "{definition}{ALLOW_UNUSED}\n\
         impl Model {{\n\
         {constructors}\
         {simulation}\
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

/// The inherent methods that simulate the model (through `rt::Simulate`).
const SIMULATION_METHODS: &str = "\
         /// Assembles the initial state from the model file's guess: held coordinates keep\n\
         /// their values, the dependent ones are solved so that every contact point is on its cam.\n\
         pub fn assemble(&self) -> Result<rt::State, rt::SimError> {\n\
         rt::Simulate::assemble(self, 0.0)\n}\n\
         /// Advances `state` by `dt` seconds with the model's default integrator settings.\n\
         pub fn step(&self, state: &mut rt::State, dt: f64) -> Result<rt::Stats, rt::SimError> {\n\
         rt::Simulate::step(self, state, dt)\n}\n\
         /// Everything at the state's instant: accelerations, contact points and normal forces,\n\
         /// constraint residuals, drive loads, energies.\n\
         pub fn sample(&self, state: &rt::State) -> Result<rt::Sample, rt::SimError> {\n\
         rt::Simulate::sample(self, state)\n}\n\
         /// Simulates from `state` with `settings`, sampling every `settings.dt_out`.\n\
         pub fn simulate(&self, state: rt::State, settings: &rt::SimSettings) -> Result<rt::Trajectory, Box<rt::SimFailure>> {\n\
         rt::Simulate::simulate(self, state, settings)\n}\n\
         /// Simulates from `state` with `settings`, keeping a summary instead of a trajectory\n\
         /// (extreme normal forces, first lift-off, max |h|, energy drift): what a parameter\n\
         /// sweep keeps of a run.\n\
         pub fn simulate_metrics(&self, state: rt::State, settings: &rt::SimSettings) -> Result<rt::RunMetrics, Box<rt::MetricsFailure>> {\n\
         rt::Simulate::simulate_metrics(self, state, settings, rt::MetricsOptions::default())\n}\n";

/// The `Model` of a model with run-time parameters: the values, what derives from them, and
/// the description (whose initial guess may depend on them).
pub(super) fn parametric_struct(model: &Model, doc: &str) -> String {
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
pub(super) fn parametric_constructors() -> String {
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
pub(super) fn plain_constructors(model: &Model, source: &str) -> String {
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
         else {{ rt::parameters::checks::unknown_parameter_among(name, &[], known) }};\n\
         Err(rt::ParameterError {{ file: {source:?}.to_string(), line: {}, column: {}, field: {:?}.to_string(), message }})\n\
         }}\n}}\n}}\n",
        at.line,
        at.column,
        at.field,
        names = names.join(", "),
    )
}

/// `MODEL_SOURCE` and `MODEL_FILES`: the model file's text (`text`, shown as `source`) and
/// the files it names, embedded as raw string literals.
pub(super) fn embedded_source(model: &Model, source: &str, text: &str) -> String {
    let mut file = String::new();
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
    file
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::testing::model;

    #[test]
    fn a_model_without_run_time_parameters_is_a_unit_struct() {
        let text = model_type(&model("double_pendulum"), "p.ron", false, true);
        assert!(text.starts_with("/// The model `double_pendulum`, generated from `p.ron`"));
        assert!(text.contains("pub struct Model;\n"));
        assert!(text.contains("None => Ok(Model),"));
        assert!(text.contains("let known: &[&str] = &[\"l1\", \"l2\", \"m1\", \"m2\", \"g\", \"q1_start\", \"q2_start\"];"));
    }

    #[test]
    fn a_parametric_model_holds_its_values_and_what_derives_from_them() {
        let text = model_type(&model("double_pendulum"), "p.ron", true, true);
        assert!(text.contains(
            "pub struct Model {\nparameters: Parameters,\nvalues: [f64; 7],\nderived: Derived,"
        ));
        assert!(text.contains("check(&parameters)?;"));
        assert!(!text.contains("pub struct Model;"));
    }

    #[test]
    fn the_embedded_source_reads_as_written() {
        let text = embedded_source(&model("double_pendulum"), "p.ron", "say \"#hi\"");
        assert!(text.contains("pub const MODEL_SOURCE: &str = r##\"say \"#hi\"\"##;\n"));
        assert!(text.contains("pub const MODEL_FILES: &[(&str, &str)] = &[];\n"));
    }
}
