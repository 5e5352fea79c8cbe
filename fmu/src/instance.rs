//! One FMU instance in safe Rust: its mode (FMI 3.0's state machine, Co-Simulation), its
//! parameter values, the model built from them, the state and the outputs at the current
//! time. The C functions of [`crate::export`] only convert arguments and call these methods;
//! every failure comes back as a message that they log with the status.

use crate::drive::Driven;
use crate::variables::{Role, Setting, Variable, variables};
use camchain_runtime::events::EventKind;
use camchain_runtime::parameters::checks::within_bounds;
use camchain_runtime::unilateral::OneSidedRun;
use camchain_runtime::{Dynamics, ModelInfo, ParameterError, SimSettings, Simulate, State};

/// What builds the model from parameter values: a generated module's `boxed`.
pub type Factory = fn(&[(&str, f64)]) -> Result<Box<dyn Dynamics + Send + Sync>, ParameterError>;

/// FMI 3.0's modes of a Co-Simulation instance (the ones it can be in).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// After `fmi3InstantiateCoSimulation` or `fmi3Reset`: parameters may be set.
    Instantiated,
    /// Between `fmi3EnterInitializationMode` and `fmi3ExitInitializationMode`.
    Initialization,
    /// Stepping (`fmi3DoStep`).
    Step,
    /// After `fmi3Terminate`: values may be read, nothing else.
    Terminated,
    /// After a failed step: only reading, `fmi3Reset`, `fmi3Terminate` and freeing.
    Failed,
}

/// One instance.
pub struct Instance {
    factory: Factory,
    info: ModelInfo,
    token: String,
    variables: Vec<Variable>,
    mode: Mode,
    parameters: Vec<f64>,
    settings: SimSettings,
    start_time: f64,
    stop_time: Option<f64>,
    /// The speeds the master set for the drives that are inputs, by coordinate (`None`:
    /// the model's own law).
    speeds: Vec<(usize, Option<f64>)>,
    /// The model and where its run is, once built (after every parameter change the next
    /// read or step builds them again).
    running: Option<Running>,
    /// What happened inside the last steps (lift-offs, impacts), for the log.
    happened: Vec<String>,
    /// The output columns at the current time (index as [`Role::Output`]).
    outputs: Vec<f64>,
}

/// Why a Float64 call on the integrator fails.
const ENUMERATION: &str =
    "`solver.integrator` is an Enumeration: use fmi3GetInt64 and fmi3SetInt64";

/// How a run advances.
enum Progress {
    /// Bilateral contact (the model file's default): the state, stepped.
    Bilateral(Box<State>),
    /// One-sided contact with the file's restitution: lift-offs and impacts located inside
    /// every step, as `camchain simulate` locates them.
    OneSided(Box<OneSidedRun>),
}

/// A built model and its run.
struct Running {
    model: Driven,
    progress: Progress,
}

impl Running {
    fn time(&self) -> f64 {
        match &self.progress {
            Progress::Bilateral(state) => state.t,
            Progress::OneSided(run) => run.time(),
        }
    }
}

/// Whether two communication times are the same one (FMI's masters pass the sum of the
/// steps they took; a few ulps of that sum).
fn same_time(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0)
}

impl Instance {
    /// A new instance of the model `factory` builds with the file's values; `Err` when even
    /// those are refused (a model that cannot be built).
    pub fn new(factory: Factory) -> Result<Self, String> {
        let model = factory(&[]).map_err(|e| format!("the model cannot be built: {e}"))?;
        let info = model.info().clone();
        let parameters = info.parameters.iter().map(|p| p.default).collect();
        let variables = variables(model.as_ref());
        let speeds = variables
            .iter()
            .filter_map(|v| match v.role {
                Role::Input(i) => Some((i, None)),
                _ => None,
            })
            .collect();
        Ok(Instance {
            factory,
            token: crate::description::token(model.as_ref()),
            speeds,
            variables,
            settings: info.defaults.clone(),
            info,
            mode: Mode::Instantiated,
            parameters,
            start_time: 0.0,
            stop_time: None,
            running: None,
            happened: Vec::new(),
            outputs: Vec::new(),
        })
    }

    /// The model's description.
    pub fn info(&self) -> &ModelInfo {
        &self.info
    }

    /// The instantiation token of its model (as its `modelDescription.xml` declares it).
    pub fn token(&self) -> &str {
        &self.token
    }

    /// The current mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// `fmi3Reset`: back to the state after instantiation, the file's values again.
    pub fn reset(&mut self) {
        self.parameters = self.info.parameters.iter().map(|p| p.default).collect();
        self.settings = self.info.defaults.clone();
        for (_, speed) in &mut self.speeds {
            *speed = None;
        }
        self.mode = Mode::Instantiated;
        self.running = None;
        self.outputs.clear();
        self.start_time = 0.0;
        self.stop_time = None;
    }

    /// `fmi3EnterInitializationMode`.
    pub fn enter_initialization(
        &mut self,
        tolerance: Option<f64>,
        start_time: f64,
        stop_time: Option<f64>,
    ) -> Result<(), String> {
        self.expect(&[Mode::Instantiated], "fmi3EnterInitializationMode")?;
        if !start_time.is_finite() {
            return Err(format!(
                "the start time {start_time} is not a finite number"
            ));
        }
        if let Some(stop) = stop_time.filter(|&s| s.is_nan() || s < start_time) {
            return Err(format!(
                "the stop time {stop} is before the start time {start_time}"
            ));
        }
        if let Some(rtol) = tolerance {
            if !(rtol > 0.0 && rtol < 1.0) {
                return Err(format!("the tolerance {rtol} is not in (0, 1)"));
            }
            self.settings.rtol = rtol;
        }
        self.start_time = start_time;
        self.stop_time = stop_time;
        self.running = None;
        self.mode = Mode::Initialization;
        Ok(())
    }

    /// `fmi3ExitInitializationMode`: the model built and assembled at the start time.
    pub fn exit_initialization(&mut self) -> Result<(), String> {
        self.expect(&[Mode::Initialization], "fmi3ExitInitializationMode")?;
        self.build()?;
        self.mode = Mode::Step;
        Ok(())
    }

    /// `fmi3Terminate`.
    pub fn terminate(&mut self) -> Result<(), String> {
        self.expect(&[Mode::Step, Mode::Failed], "fmi3Terminate")?;
        self.mode = Mode::Terminated;
        Ok(())
    }

    fn expect(&self, allowed: &[Mode], call: &str) -> Result<(), String> {
        if allowed.contains(&self.mode) {
            Ok(())
        } else {
            Err(format!(
                "{call} is not allowed in mode {:?} (allowed in {allowed:?})",
                self.mode
            ))
        }
    }

    /// The model with the current parameter values, assembled at the start time, and its
    /// outputs; kept until a parameter changes.
    fn build(&mut self) -> Result<(), String> {
        if self.running.is_some() {
            return Ok(());
        }
        let values: Vec<(&str, f64)> = self
            .info
            .parameters
            .iter()
            .zip(&self.parameters)
            .map(|(p, &v)| (p.name.as_str(), v))
            .collect();
        let mut model = Driven::new((self.factory)(&values).map_err(|e| e.to_string())?);
        for &(i, speed) in &self.speeds {
            if let Some(speed) = speed {
                model.set_speed(i, speed, self.start_time);
            }
        }
        let state = model
            .assemble(self.start_time)
            .map_err(|e| format!("assembly at t = {} s failed: {e}", self.start_time))?;
        let sample = model
            .sample(&state)
            .map_err(|e| format!("at t = {} s the outputs failed: {e}", state.t))?;
        self.outputs = camchain_runtime::columns::values(&self.info, &sample);
        let progress = match self.info.restitution {
            Some(e) => {
                let run = OneSidedRun::start(&model, state, &self.settings, e)
                    .map_err(|e| format!("the one-sided run cannot start: {e}"))?;
                Progress::OneSided(Box::new(run))
            }
            None => Progress::Bilateral(Box::new(state)),
        };
        self.running = Some(Running { model, progress });
        Ok(())
    }

    /// The outputs at the current state of a bilateral run.
    fn refresh(&mut self) -> Result<(), String> {
        let Some(Running {
            model,
            progress: Progress::Bilateral(state),
        }) = &self.running
        else {
            return Ok(());
        };
        let sample = model
            .sample(state)
            .map_err(|e| format!("at t = {} s the outputs failed: {e}", state.t))?;
        self.outputs = camchain_runtime::columns::values(&self.info, &sample);
        Ok(())
    }

    /// The lift-offs and impacts of the steps since the last call, one line each.
    pub fn take_events(&mut self) -> Vec<String> {
        std::mem::take(&mut self.happened)
    }

    fn variable(&self, reference: u32) -> Result<&Variable, String> {
        self.variables.get(reference as usize).ok_or_else(|| {
            format!(
                "value reference {reference} is not a variable of {} (0 to {})",
                self.info.name,
                self.variables.len().saturating_sub(1)
            )
        })
    }

    /// `fmi3GetFloat64` of one variable.
    pub fn get(&mut self, reference: u32) -> Result<f64, String> {
        let role = self.variable(reference)?.role;
        match role {
            Role::Parameter(i) => Ok(self.parameters[i]),
            Role::Setting(Setting::Integrator) => Err(ENUMERATION.into()),
            Role::Setting(s) => Ok(self.setting(s)),
            Role::Input(i) => Ok(self.speed(i, reference)),
            Role::Time => Ok(self.running.as_ref().map_or(self.start_time, Running::time)),
            Role::Output(i) => {
                if self.mode == Mode::Instantiated {
                    return Err(format!(
                        "the output `{}` has no value before initialization mode",
                        self.variables[reference as usize].name
                    ));
                }
                self.build()?;
                Ok(self.outputs.get(i).copied().unwrap_or(f64::NAN))
            }
        }
    }

    /// The speed of the drive of coordinate `i`: the master's, else the model's own.
    fn speed(&self, i: usize, reference: u32) -> f64 {
        self.speeds
            .iter()
            .find(|(c, _)| *c == i)
            .and_then(|(_, s)| *s)
            .or(self.variables[reference as usize].start)
            .unwrap_or(f64::NAN)
    }

    /// `fmi3SetFloat64` of an input: the drive of coordinate `i` at `speed` from now on (in
    /// step mode, from the current time; before, from the start time).
    fn set_speed(&mut self, i: usize, speed: f64, name: &str) -> Result<(), String> {
        if !speed.is_finite() {
            return Err(format!("{name} = {speed}: must be a finite number"));
        }
        self.expect(
            &[Mode::Instantiated, Mode::Initialization, Mode::Step],
            &format!("setting the input `{name}`"),
        )?;
        if let Some((_, s)) = self.speeds.iter_mut().find(|(c, _)| *c == i) {
            *s = Some(speed);
        }
        match (&mut self.running, self.mode) {
            (Some(running), Mode::Step) => {
                let t = running.time();
                running.model.set_speed(i, speed, t);
                if let Progress::Bilateral(state) = &mut running.progress {
                    if let Some(qd) = state.qd.get_mut(i) {
                        *qd = speed;
                    }
                }
                self.refresh()
            }
            _ => {
                self.running = None;
                Ok(())
            }
        }
    }

    fn setting(&self, s: Setting) -> f64 {
        match s {
            Setting::Integrator => {
                crate::variables::integrator_value(self.settings.integrator) as f64
            }
            Setting::Rtol => self.settings.rtol,
            Setting::Atol => self.settings.atol,
            Setting::Dt => self.settings.dt,
        }
    }

    /// `fmi3GetInt64` of one variable: the integrator, the only Enumeration.
    pub fn get_int64(&self, reference: u32) -> Result<i64, String> {
        match self.variable(reference)?.role {
            Role::Setting(Setting::Integrator) => {
                Ok(crate::variables::integrator_value(self.settings.integrator))
            }
            _ => Err(format!(
                "value reference {reference} is a Float64: read it with fmi3GetFloat64"
            )),
        }
    }

    /// `fmi3SetInt64`: the integrator, before the end of initialization mode.
    pub fn set_int64(&mut self, reference: u32, value: i64) -> Result<(), String> {
        if self.variable(reference)?.role != Role::Setting(Setting::Integrator) {
            return Err(format!(
                "value reference {reference} is a Float64: set it with fmi3SetFloat64"
            ));
        }
        self.expect(
            &[Mode::Instantiated, Mode::Initialization],
            "setting the fixed parameter `solver.integrator`",
        )?;
        let kind = crate::variables::integrator_of(value).ok_or_else(|| {
            format!(
                "solver.integrator = {value}: not an item of Integrator (1 to {})",
                camchain_runtime::IntegratorKind::ALL.len()
            )
        })?;
        self.settings.integrator = kind;
        self.running = None;
        Ok(())
    }

    /// `fmi3SetFloat64` of one variable: parameters and settings before the end of
    /// initialization mode, each checked against its declared bounds.
    pub fn set(&mut self, reference: u32, value: f64) -> Result<(), String> {
        let variable = self.variable(reference)?;
        let name = variable.name.clone();
        let role = variable.role;
        let what = format!("{name} = {value}");
        match role {
            Role::Time => return Err("`time` is the independent variable: not settable".into()),
            Role::Output(_) => return Err(format!("`{name}` is an output: not settable")),
            Role::Input(i) => return self.set_speed(i, value, &name),
            Role::Setting(Setting::Integrator) => return Err(ENUMERATION.into()),
            Role::Parameter(_) | Role::Setting(_) => {}
        }
        self.expect(
            &[Mode::Instantiated, Mode::Initialization],
            &format!("setting the fixed parameter `{name}`"),
        )?;
        match role {
            Role::Parameter(i) => {
                let p = &self.info.parameters[i];
                let value =
                    within_bounds(&p.name, value, (p.min, p.max), &what).map_err(|(_, m)| m)?;
                self.parameters[i] = value;
            }
            Role::Setting(s) => {
                if !(value > 0.0 && value.is_finite()) {
                    return Err(format!("{what}: must be positive and finite"));
                }
                match s {
                    Setting::Integrator => {}
                    Setting::Rtol => self.settings.rtol = value,
                    Setting::Atol => self.settings.atol = value,
                    Setting::Dt => self.settings.dt = value,
                }
            }
            Role::Time | Role::Output(_) | Role::Input(_) => {}
        }
        self.running = None;
        Ok(())
    }

    /// `fmi3DoStep`: from `current` (the instance's time) by `step`, with the integrator and
    /// tolerances of the settings; the outputs are those at the new time. A failed step
    /// leaves the instance in [`Mode::Failed`] at the last time reached.
    pub fn do_step(&mut self, current: f64, step: f64) -> Result<f64, String> {
        self.expect(&[Mode::Step], "fmi3DoStep")?;
        if !(step > 0.0 && step.is_finite()) {
            return Err(format!(
                "the communication step {step} is not positive and finite"
            ));
        }
        let settings = self.settings.clone();
        let Some(running) = &mut self.running else {
            return Err("the model is not built".into());
        };
        let now = running.time();
        if !same_time(current, now) {
            return Err(format!(
                "fmi3DoStep from t = {current} s, but the instance is at t = {now} s"
            ));
        }
        if let Some(stop) = self
            .stop_time
            .filter(|&s| current + step > s + 1e-9 * s.abs().max(1.0))
        {
            return Err(format!(
                "a step to t = {} s goes past the stop time {stop} s",
                current + step
            ));
        }
        let target = current + step;
        let outcome = match &mut running.progress {
            Progress::Bilateral(state) => running
                .model
                .step_with(state, target - now, &settings)
                .map(|_| None),
            Progress::OneSided(run) => {
                let seen = run.events().len();
                let outcome = run.advance(&running.model, target, &settings).map(Some);
                for event in &run.events()[seen..] {
                    let what = match event.kind {
                        EventKind::LiftOff => "lift-off".to_string(),
                        EventKind::Impact {
                            normal_velocity,
                            stays,
                            ..
                        } => format!(
                            "impact at {:.6} m/s{}",
                            normal_velocity.abs(),
                            if stays { ", stays on the cam" } else { "" }
                        ),
                        _ => format!("{:?}", event.kind),
                    };
                    self.happened.push(format!("t = {:.9} s: {what}", event.t));
                }
                outcome
            }
        };
        match outcome {
            Ok(Some(sample)) => {
                self.outputs = camchain_runtime::columns::values(&self.info, &sample);
            }
            Ok(None) => self.refresh()?,
            Err(e) => {
                let reached = running.time();
                self.mode = Mode::Failed;
                let _ = self.refresh();
                return Err(format!(
                    "the step from t = {current} s to {target} s failed at t = {reached} s: {e}"
                ));
            }
        }
        Ok(target)
    }
}
