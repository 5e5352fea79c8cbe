//! What `camchain cam` works on: the model (built in or a file), the contact designed from a
//! motion law, the nominal speed, and the model built to run at another speed.
//!
//! A cam's speed is set through the run-time parameter its law's `speed` names (`speed:
//! "omega"`, with the camshaft's drive `omega*t`): the value of that parameter that makes the
//! expression equal the wanted speed is found by the secant method (exact in one step for the
//! usual `omega` or `k*omega`), and the model is built with it: a built-in model's generated
//! code through its constructor (`camchain_models::WITH_PARAMETERS`), a model file on the
//! numeric reference with the value as an override.

use crate::CliError;
use crate::source::{self, Engine};
use camchain_codegen::ParameterMode;
use camchain_codegen::design::CamDesign;
use camchain_codegen::model::{Contact, Model, Profile};
use camchain_codegen::profile::Scalar;
use camchain_codegen::schema::Files;
use camchain_models as models;
use camchain_reference::NumericModel;
use camchain_runtime::Dynamics;
use std::path::PathBuf;

/// A model that can run (generated or numeric), shareable between threads.
pub type Runnable = Box<dyn Dynamics + Send + Sync>;

/// Where the model comes from, to build it again with another speed.
enum Origin {
    /// A built-in model, by name (its generated code).
    Builtin(String),
    /// A model file (the numeric reference): its path and its text.
    File {
        /// The path as given.
        path: PathBuf,
        /// The file's text.
        text: String,
    },
}

/// The model `cam` analyses.
pub struct Subject {
    /// The model's name in output names and messages: a built-in model's name or the file's
    /// name without `.ron`.
    pub label: String,
    /// The validated description (its contacts carry the designs).
    pub model: Model,
    /// Warnings about the model file's values (located), for a file.
    pub warnings: Vec<String>,
    /// True for a file on the numeric reference, false for generated code.
    pub numeric: bool,
    origin: Origin,
}

/// Loads MODEL as `simulate` does: an unknown name is a usage error; a file that cannot be
/// read or does not validate is a failure with the located message.
pub fn load(arg: &str) -> Result<Subject, CliError> {
    let loaded = source::load(arg, false)?;
    match &loaded.engine {
        Engine::Numeric(numeric) => {
            let path = PathBuf::from(arg);
            let text = camchain_codegen::schema::read_text(&path).map_err(|e| {
                CliError::Failed(format!("cannot read model file {}: {e}", path.display()))
            })?;
            Ok(Subject {
                label: loaded.label.clone(),
                model: numeric.model().clone(),
                warnings: loaded.warnings.clone(),
                numeric: true,
                origin: Origin::File { path, text },
            })
        }
        Engine::Generated(_) | Engine::Parametrised(_) => Ok(Subject {
            label: loaded.label.clone(),
            model: source::builtin_description(arg)?,
            warnings: loaded.warnings.clone(),
            numeric: false,
            origin: Origin::Builtin(arg.to_string()),
        }),
    }
}

/// What a contact's profile is, in a list of contacts.
fn profile_kind(contact: &Contact) -> &'static str {
    match (&contact.profile, &contact.design) {
        (Profile::Face { .. }, Some(_)) => return "face cam's groove designed from a law",
        (_, Some(_)) => return "designed from a law",
        (_, None) => {}
    }
    match &contact.profile {
        Profile::Explicit { .. } => "explicit profile",
        Profile::Polar { .. } => "polar profile",
        Profile::Parametric { .. } => "parametric profile",
        Profile::Surface { .. } => "surface",
        Profile::Barrel { .. } => "barrel cam",
        Profile::Revolution { .. } => "surface of revolution",
        Profile::Face { .. } => "face cam's groove",
    }
}

/// `A (polar profile), B (designed from a law)`.
fn contact_list(model: &Model) -> String {
    let names: Vec<String> = model
        .contacts
        .iter()
        .map(|c| format!("`{}` ({})", c.name, profile_kind(c)))
        .collect();
    names.join(", ")
}

/// The index (in `model.contacts`) of the contact to analyse: `--contact NAME`, else the
/// model's only contact designed from a law. Usage errors name the candidates.
pub fn pick_contact(model: &Model, label: &str, wanted: Option<&str>) -> Result<usize, CliError> {
    let designed: Vec<&str> = model
        .contacts
        .iter()
        .filter(|c| c.design.is_some())
        .map(|c| c.name.as_str())
        .collect();
    let quoted = |names: &[&str]| -> String {
        names
            .iter()
            .map(|n| format!("`{n}`"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if designed.is_empty() {
        let has = if model.contacts.is_empty() {
            "it has no contact".to_string()
        } else {
            format!("its contacts: {}", contact_list(model))
        };
        return Err(CliError::Usage(format!(
            "{label} has no cam designed from a motion law (a contact with `law:`) for `cam` \
             to analyse; {has}"
        )));
    }
    match wanted {
        Some(name) => match model.contacts.iter().position(|c| c.name == name) {
            Some(k) if model.contacts[k].design.is_some() => Ok(k),
            Some(_) => Err(CliError::Usage(format!(
                "--contact {name}: the cam of contact `{name}` of {label} is not designed from \
                 a motion law; designed ones: {}",
                quoted(&designed)
            ))),
            None => Err(CliError::Usage(format!(
                "--contact {name}: {label} has no contact `{name}`; its cams designed from a \
                 motion law: {}",
                quoted(&designed)
            ))),
        },
        None if designed.len() == 1 => model
            .contacts
            .iter()
            .position(|c| c.design.is_some())
            .ok_or_else(|| CliError::Failed("the designed contact vanished".into())),
        None => Err(CliError::Usage(format!(
            "{label} has {} cams designed from a motion law ({}): choose one with --contact NAME",
            designed.len(),
            quoted(&designed)
        ))),
    }
}

/// The nominal speed (rad/s): `--speed`, else the law's `speed`; a usage error without
/// either.
pub fn nominal_speed(
    design: &CamDesign,
    given: Option<f64>,
    contact: &str,
) -> Result<f64, CliError> {
    match (given, design.speed) {
        (Some(speed), _) => Ok(speed),
        (None, Some(speed)) if speed.is_finite() && speed > 0.0 => Ok(speed),
        (None, Some(speed)) => Err(CliError::Usage(format!(
            "the law of contact `{contact}` gives the speed {speed} rad/s: give a positive one \
             with --speed RAD_PER_S"
        ))),
        (None, None) => Err(CliError::Usage(format!(
            "the law of contact `{contact}` gives no nominal speed (`speed:`): give one with \
             --speed RAD_PER_S"
        ))),
    }
}

/// How the model's cam is run at a given speed: the run-time parameter the law's `speed`
/// expression uses, solved for.
pub struct SpeedControl {
    /// The parameter's index in the model's parameters.
    parameter: usize,
    /// Its name.
    pub name: String,
    /// The law's speed expression (parameters as [`Scalar::Param`]).
    expression: Scalar,
    /// Every parameter's value in the model file.
    values: Vec<f64>,
}

/// The speed's relative tolerance of the secant solve: a few units in the last place.
const SPEED_TOLERANCE: f64 = 1e-14;

impl SpeedControl {
    /// The speed control of `design` in `model`, or why the cam's speed cannot be set.
    pub fn new(model: &Model, design: &CamDesign, contact: &str) -> Result<Self, CliError> {
        let why = |reason: String| {
            CliError::Failed(format!(
                "the cam of contact `{contact}` cannot be run at other speeds: {reason}; the \
                 jump speed is predicted from runs at three speeds, set through the run-time \
                 parameter the law's `speed` names (e.g. `speed: \"omega\"` with the \
                 camshaft's drive `prescribed: \"omega*t\"` and `omega` not `constant`)"
            ))
        };
        let Some(expression) = design.speed_expression.clone() else {
            return Err(why("its law gives no `speed`".into()));
        };
        let used = expression.parameters();
        let runtime: Vec<usize> = used
            .iter()
            .copied()
            .filter(|&i| model.parameters.get(i).is_some_and(|p| !p.constant))
            .collect();
        let names = |indices: &[usize]| -> String {
            indices
                .iter()
                .filter_map(|&i| model.parameters.get(i))
                .map(|p| format!("`{}`", p.name))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let parameter = match runtime.as_slice() {
            [one] => *one,
            [] if used.is_empty() => {
                return Err(why("its law's `speed` is a number, not a parameter".into()));
            }
            [] => {
                return Err(why(format!(
                    "its law's `speed` uses only constant parameters ({}), which the model \
                     folds",
                    names(&used)
                )));
            }
            several => {
                return Err(why(format!(
                    "its law's `speed` uses several run-time parameters ({}): which one sets \
                     the speed is ambiguous",
                    names(several)
                )));
            }
        };
        Ok(SpeedControl {
            parameter,
            name: model.parameters[parameter].name.clone(),
            expression,
            values: model.parameters.iter().map(|p| p.value).collect(),
        })
    }

    /// The speed the expression gives for the parameter's value `x`.
    fn speed_at(&self, x: f64) -> f64 {
        let mut values = self.values.clone();
        values[self.parameter] = x;
        self.expression.resolve_all(&values).eval(0.0)
    }

    /// The parameter's value at which the law's speed is `speed`, by the secant method from
    /// the file's value.
    pub fn value_for(&self, speed: f64) -> Result<f64, String> {
        let x0 = self.values[self.parameter];
        let f = |x: f64| self.speed_at(x) - speed;
        let (mut a, mut fa) = (x0, f(x0));
        // A proportional first guess: exact when the speed is k·parameter.
        let current = self.speed_at(x0);
        let mut b = if x0 != 0.0 && current.is_finite() && current != 0.0 {
            x0 * speed / current
        } else {
            x0 + 1.0
        };
        if a == b {
            b = a + 1.0;
        }
        let mut fb = f(b);
        for _ in 0..100 {
            if fb.is_finite() && fb.abs() <= SPEED_TOLERANCE * speed {
                return Ok(b);
            }
            if !(fa.is_finite() && fb.is_finite()) || fb == fa {
                break;
            }
            let next = b - fb * (b - a) / (fb - fa);
            (a, fa) = (b, fb);
            b = next;
            fb = f(b);
        }
        Err(format!(
            "no value of the parameter `{}` makes the law's speed {speed} rad/s (the secant \
             method did not converge from its value {x0})",
            self.name
        ))
    }

    /// "the parameter `omega`", for messages.
    pub fn describe(&self) -> String {
        format!("the parameter `{}`", self.name)
    }
}

impl Subject {
    /// The model with its speed parameter set to `value`: generated code for a built-in
    /// model, the numeric reference for a file. The message says what was refused.
    pub fn build(&self, control: &SpeedControl, value: f64) -> Result<Runnable, String> {
        let overrides = [(control.name.clone(), value)];
        match &self.origin {
            Origin::Builtin(name) => {
                let constructor = models::WITH_PARAMETERS
                    .iter()
                    .find(|(n, _)| n == name)
                    .map(|(_, c)| *c)
                    .ok_or_else(|| format!("{name} has no constructor"))?;
                constructor(&[(control.name.as_str(), value)]).map_err(|e| e.to_string())
            }
            Origin::File { path, text } => NumericModel::from_source_in(
                text,
                path,
                &overrides,
                ParameterMode::AllAtRunTime,
                Files::BesideModel,
            )
            .map(|m| Box::new(m) as Runnable)
            .map_err(|e| e.to_string().replace('\n', " ")),
        }
    }

    /// How the summary names the path the runs take.
    pub fn engine(&self) -> &'static str {
        if self.numeric {
            "numeric recursive reference"
        } else {
            "generated code"
        }
    }
}
