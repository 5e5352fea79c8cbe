//! The FMI 3.0 functions that `export!` defines, called through their C symbols as an
//! importer calls them (FMPy's sequence: instantiate, enter and exit initialization, set
//! and get values, steps, terminate, free), on the built-in `cycloidal_roller`.

use camchain_fmu::description::token;
use camchain_fmu::variables::{Role, variables};
use camchain_runtime::{Dynamics, IntegratorKind, SimSettings, Simulate};
use std::ffi::{CStr, CString, c_char, c_void};
use std::sync::Mutex;

camchain_fmu::export!(camchain_models::cycloidal_roller::boxed);

type Logger = Option<unsafe extern "C" fn(*mut c_void, i32, *const c_char, *const c_char)>;

unsafe extern "C" {
    fn fmi3GetVersion() -> *const c_char;
    fn fmi3InstantiateCoSimulation(
        name: *const c_char,
        token: *const c_char,
        resources: *const c_char,
        visible: bool,
        logging_on: bool,
        event_mode_used: bool,
        early_return_allowed: bool,
        required: *const u32,
        n_required: usize,
        environment: *mut c_void,
        logger: Logger,
        intermediate: *const c_void,
    ) -> *mut c_void;
    fn fmi3FreeInstance(instance: *mut c_void);
    fn fmi3EnterInitializationMode(
        instance: *mut c_void,
        tolerance_defined: bool,
        tolerance: f64,
        start: f64,
        stop_defined: bool,
        stop: f64,
    ) -> i32;
    fn fmi3ExitInitializationMode(instance: *mut c_void) -> i32;
    fn fmi3Terminate(instance: *mut c_void) -> i32;
    fn fmi3GetFloat64(
        instance: *mut c_void,
        r: *const u32,
        nr: usize,
        v: *mut f64,
        nv: usize,
    ) -> i32;
    fn fmi3SetFloat64(
        instance: *mut c_void,
        r: *const u32,
        nr: usize,
        v: *const f64,
        nv: usize,
    ) -> i32;
    fn fmi3DoStep(
        instance: *mut c_void,
        current: f64,
        step: f64,
        no_prior: bool,
        event: *mut bool,
        terminate: *mut bool,
        early: *mut bool,
        last: *mut f64,
    ) -> i32;
    fn fmi3GetFMUState(instance: *mut c_void, state: *mut *mut c_void) -> i32;
    fn fmi3GetInt64(instance: *mut c_void, r: *const u32, nr: usize, v: *mut i64, nv: usize)
    -> i32;
    fn fmi3SetInt64(
        instance: *mut c_void,
        r: *const u32,
        nr: usize,
        v: *const i64,
        nv: usize,
    ) -> i32;
}

/// The messages the FMU logged, across the tests of this binary (each test looks for its own).
static LOG: Mutex<Vec<String>> = Mutex::new(Vec::new());

unsafe extern "C" fn logger(_: *mut c_void, status: i32, _: *const c_char, message: *const c_char) {
    // SAFETY: the FMU passes a NUL-terminated message.
    let text = unsafe { CStr::from_ptr(message) }
        .to_string_lossy()
        .into_owned();
    LOG.lock().expect("log").push(format!("[{status}] {text}"));
}

fn logged(needle: &str) -> bool {
    LOG.lock().expect("log").iter().any(|m| m.contains(needle))
}

fn model() -> &'static (dyn Dynamics + Sync) {
    camchain_models::by_name("cycloidal_roller").expect("built in")
}

fn instantiate(token: &str) -> *mut c_void {
    let name = CString::new("test").expect("name");
    let token = CString::new(token).expect("token");
    // SAFETY: valid strings and callback; no intermediate variables.
    unsafe {
        fmi3InstantiateCoSimulation(
            name.as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            false,
            false,
            false,
            false,
            std::ptr::null(),
            0,
            std::ptr::null_mut(),
            Some(logger),
            std::ptr::null(),
        )
    }
}

fn reference(name: &str) -> u32 {
    variables(model())
        .into_iter()
        .find(|v| v.name == name)
        .unwrap_or_else(|| panic!("no variable {name}"))
        .reference
}

fn get(instance: *mut c_void, r: u32) -> f64 {
    let mut value = f64::NAN;
    // SAFETY: one reference, one value.
    let status = unsafe { fmi3GetFloat64(instance, &r, 1, &mut value, 1) };
    assert_eq!(status, 0, "get {r}");
    value
}

fn set(instance: *mut c_void, r: u32, value: f64) -> i32 {
    // SAFETY: one reference, one value.
    unsafe { fmi3SetFloat64(instance, &r, 1, &value, 1) }
}

/// Steps `instance` from 0 to `t_end` by `h`, returning every output column at every
/// communication point (index as the columns').
fn run(instance: *mut c_void, t_end: f64, h: f64) -> Vec<Vec<f64>> {
    let outputs: Vec<(usize, u32)> = variables(model())
        .into_iter()
        .filter_map(|v| match v.role {
            Role::Output(i) => Some((i, v.reference)),
            _ => None,
        })
        .collect();
    let row = |instance| {
        let mut row = vec![get(instance, 0)];
        row.extend(outputs.iter().map(|&(_, r)| get(instance, r)));
        row
    };
    // SAFETY: an instance of this binary's FMU.
    unsafe {
        assert_eq!(
            fmi3EnterInitializationMode(instance, false, 0.0, 0.0, true, t_end),
            0
        );
        assert_eq!(fmi3ExitInitializationMode(instance), 0);
    }
    let mut rows = vec![row(instance)];
    let steps = (t_end / h).round() as usize;
    for k in 0..steps {
        let (mut event, mut terminate, mut early, mut last) = (false, false, false, 0.0);
        // SAFETY: as above, writable flags.
        let status = unsafe {
            fmi3DoStep(
                instance,
                k as f64 * h,
                h,
                true,
                &mut event,
                &mut terminate,
                &mut early,
                &mut last,
            )
        };
        assert_eq!(status, 0, "step {k}");
        assert!(!terminate && !event && !early);
        rows.push(row(instance));
    }
    rows
}

/// The library's run against the runtime's own `simulate` of the same model, sampled at
/// the same times: the FMU stops at every communication point (1 ms), `simulate` steps
/// freely and interpolates, so the two agree to the integration error, not to round-off.
/// Bound: 1e-6 of each column's scale, the tolerance for FMPy against the CLI's CSV
/// (rtol 1e-8 of the model file; the measured gap is printed).
#[test]
fn steps_match_the_runtimes_own_run() {
    let info = model().info();
    let instance = instantiate(&token(model()));
    assert!(!instance.is_null());
    let t_end = 0.5;
    let h = 1e-3;
    let rows = run(instance, t_end, h);
    // SAFETY: an instance of this binary, freed once.
    unsafe {
        assert_eq!(fmi3Terminate(instance), 0);
        fmi3FreeInstance(instance);
    }
    let settings = SimSettings {
        t_end,
        dt_out: h,
        ..info.defaults.clone()
    };
    let state = model().assemble(0.0).expect("assembles");
    let trajectory = model().simulate(state, &settings).expect("runs");
    assert_eq!(trajectory.samples.len(), rows.len());
    let expected: Vec<Vec<f64>> = trajectory
        .samples
        .iter()
        .map(|s| camchain_runtime::columns::values(info, s))
        .collect();
    let columns = expected[0].len();
    let mut worst: f64 = 0.0;
    for c in 0..columns {
        let scale = expected.iter().fold(1e-3f64, |m, r| m.max(r[c].abs()));
        for (got, want) in rows.iter().zip(&expected) {
            let gap = (got[c] - want[c]).abs() / scale;
            worst = worst.max(gap);
            assert!(
                gap <= 1e-6,
                "column {c} at t = {}: {} against {}",
                want[0],
                got[c],
                want[c]
            );
        }
    }
    println!("largest gap: {worst:e} of the column's scale");
}

#[test]
fn a_parameter_changes_the_run_as_the_models_own_value_does() {
    let info = model().info();
    let Some(p) = info.parameters.first() else {
        panic!("cycloidal_roller declares run-time parameters");
    };
    let value = match (p.min, p.max) {
        (_, Some(max)) => 0.5 * (p.default + max),
        _ => p.default * 1.1,
    };
    let instance = instantiate(&token(model()));
    assert_eq!(set(instance, reference(&p.name), value), 0);
    assert_eq!(get(instance, reference(&p.name)), value);
    let rows = run(instance, 0.05, 1e-3);
    // SAFETY: freed once.
    unsafe { fmi3FreeInstance(instance) };
    let changed = camchain_models::cycloidal_roller::Model::with(&[(p.name.as_str(), value)])
        .expect("in bounds");
    let settings = SimSettings {
        t_end: 0.05,
        dt_out: 1e-3,
        ..info.defaults.clone()
    };
    let state = Simulate::assemble(&changed, 0.0).expect("assembles");
    let trajectory = changed.simulate(state, &settings).expect("runs");
    let last = camchain_runtime::columns::values(info, trajectory.samples.last().expect("samples"));
    let default_run = {
        let state = model().assemble(0.0).expect("assembles");
        model().simulate(state, &settings).expect("runs")
    };
    let default_last =
        camchain_runtime::columns::values(info, default_run.samples.last().expect("samples"));
    let got = rows.last().expect("rows");
    // The same tolerance as above; and the change itself is far larger than it.
    let differs = got
        .iter()
        .zip(&default_last)
        .any(|(a, b)| (a - b).abs() > 1e-4 * b.abs().max(1.0));
    assert!(differs, "{} = {value} changed nothing", p.name);
    for (a, b) in got.iter().zip(&last) {
        assert!((a - b).abs() <= 1e-6 * b.abs().max(1.0), "{a} against {b}");
    }
}

#[test]
fn bad_values_and_calls_give_an_error_status_and_a_message() {
    let info = model().info();
    // SAFETY: a static string.
    assert_eq!(
        unsafe { CStr::from_ptr(fmi3GetVersion()) }.to_str(),
        Ok("3.0")
    );
    assert!(instantiate("{not-this-model}").is_null());
    assert!(logged("is not this model's"));
    let instance = instantiate(&token(model()));
    if let Some(p) = info.parameters.iter().find(|p| p.min.is_some()) {
        let below = p.min.unwrap_or(0.0) - 1.0;
        assert_eq!(set(instance, reference(&p.name), below), 3);
        assert!(logged("below the minimum"));
        assert_eq!(get(instance, reference(&p.name)), p.default, "unchanged");
    }
    assert_eq!(set(instance, reference("solver.rtol"), -1.0), 3);
    assert_eq!(set(instance, 0, 1.0), 3);
    assert!(logged("independent variable"));
    assert_eq!(set(instance, 1_000_000, 1.0), 3);
    assert!(logged("value reference 1000000 is not a variable"));
    let mut state = std::ptr::null_mut();
    // SAFETY: an instance and a writable pointer.
    assert_eq!(unsafe { fmi3GetFMUState(instance, &mut state) }, 3);
    assert!(logged("fmi3GetFMUState: not provided by this FMU"));
    let (mut a, mut b, mut c, mut last) = (false, false, false, 0.0);
    // SAFETY: as above.
    let status =
        unsafe { fmi3DoStep(instance, 0.0, 1e-3, true, &mut a, &mut b, &mut c, &mut last) };
    assert_eq!(status, 3, "a step before initialization");
    assert!(logged("fmi3DoStep is not allowed in mode Instantiated"));
    // SAFETY: freed once.
    unsafe { fmi3FreeInstance(instance) };
}

/// A speed step through the camshaft's input. cycloidal_roller has no freedom of its own:
/// every output but the work quadratures is a function of the cam's angle, speed and
/// acceleration. So after the step to 60 rad/s at t = 0.1 s (angle 5 rad), the FMU must give
/// at t the outputs that the model built with omega = 60 gives at the instant it has the same
/// angle, t − 0.1 + 5/60 s: an independent run (the model's own law, not the input's), to
/// round-off of the kinematics (1e-9 of each column's scale: Newton's tolerance on the
/// follower's position is far below it; measured gap printed).
#[test]
fn a_speed_step_through_the_input_drives_the_cam_as_that_speed_does() {
    let instance = instantiate(&token(model()));
    let speed = reference("cam_angle_speed");
    assert_eq!(
        get(instance, speed),
        50.0,
        "the model's own speed before it is set"
    );
    let h = 1e-3;
    // SAFETY: an instance of this binary.
    unsafe {
        assert_eq!(
            fmi3EnterInitializationMode(instance, false, 0.0, 0.0, false, 0.0),
            0
        );
        assert_eq!(fmi3ExitInitializationMode(instance), 0);
    }
    let step = |t: f64| {
        let (mut a, mut b, mut c, mut last) = (false, false, false, 0.0);
        // SAFETY: as above.
        let status = unsafe { fmi3DoStep(instance, t, h, true, &mut a, &mut b, &mut c, &mut last) };
        assert_eq!(status, 0, "step at {t}");
    };
    for k in 0..100 {
        step(k as f64 * h);
    }
    assert!((get(instance, reference("cam_angle")) - 5.0).abs() < 1e-9);
    assert_eq!(set(instance, speed, 60.0), 0);
    assert_eq!(get(instance, reference("cam_angle_dot")), 60.0);
    let faster = camchain_models::cycloidal_roller::Model::with(&[("omega", 60.0)]).expect("omega");
    let mut state = Simulate::assemble(&faster, 0.0).expect("assembles");
    faster
        .step_with(&mut state, 5.0 / 60.0, &faster.info().defaults)
        .expect("steps");
    let info = model().info();
    let kinematic: Vec<(usize, u32)> = variables(model())
        .into_iter()
        .filter_map(|v| match v.role {
            Role::Output(i) if !["dissipated", "driven_work"].contains(&v.name.as_str()) => {
                Some((i, v.reference))
            }
            _ => None,
        })
        .collect();
    let mut worst: f64 = 0.0;
    for k in 100..300 {
        step(k as f64 * h);
        faster
            .step_with(&mut state, h, &faster.info().defaults)
            .expect("steps");
        let sample = faster.sample(&state).expect("sample");
        let want = camchain_runtime::columns::values(info, &sample);
        for &(i, r) in &kinematic {
            let scale = want[i].abs().max(1.0);
            let gap = (get(instance, r) - want[i]).abs() / scale;
            worst = worst.max(gap);
            assert!(
                gap <= 1e-9,
                "column {i} at t = {}: {gap:e}",
                (k + 1) as f64 * h
            );
        }
    }
    println!("largest gap after the speed step: {worst:e}");
    // SAFETY: freed once.
    unsafe { fmi3FreeInstance(instance) };
}

/// The integrator is an Enumeration parameter: RK4 chosen through fmi3SetInt64, with its step
/// through solver.dt, lands on every communication point as the runtime's own RK4 run lands
/// on every output time, so the two take the same steps: equal to round-off (1e-12 of each
/// column's scale; measured gap printed).
#[test]
fn the_integrator_is_a_parameter() {
    let info = model().info();
    let instance = instantiate(&token(model()));
    let integrator = reference("solver.integrator");
    let mut value = 0i64;
    // SAFETY: one reference, one value.
    assert_eq!(
        unsafe { fmi3GetInt64(instance, &integrator, 1, &mut value, 1) },
        0
    );
    assert_eq!(
        camchain_fmu::variables::integrator_of(value),
        Some(info.defaults.integrator)
    );
    let rk4 = camchain_fmu::variables::integrator_value(IntegratorKind::Rk4);
    let bad = 99i64;
    // SAFETY: as above.
    unsafe {
        assert_eq!(fmi3SetInt64(instance, &integrator, 1, &bad, 1), 3);
        assert_eq!(fmi3SetInt64(instance, &integrator, 1, &rk4, 1), 0);
    }
    assert!(logged("solver.integrator = 99: not an item of Integrator"));
    let mut x = 0.0;
    // SAFETY: as above.
    assert_eq!(
        unsafe { fmi3GetFloat64(instance, &integrator, 1, &mut x, 1) },
        3
    );
    assert_eq!(set(instance, reference("solver.dt"), 2.5e-4), 0);
    let rows = run(instance, 0.2, 1e-3);
    // SAFETY: freed once.
    unsafe { fmi3FreeInstance(instance) };
    let settings = SimSettings {
        t_end: 0.2,
        dt_out: 1e-3,
        integrator: IntegratorKind::Rk4,
        dt: 2.5e-4,
        ..info.defaults.clone()
    };
    let state = model().assemble(0.0).expect("assembles");
    let trajectory = model().simulate(state, &settings).expect("runs");
    let mut worst: f64 = 0.0;
    for (got, sample) in rows.iter().zip(&trajectory.samples) {
        let want = camchain_runtime::columns::values(info, sample);
        for (a, b) in got.iter().zip(&want) {
            let gap = (a - b).abs() / b.abs().max(1.0);
            worst = worst.max(gap);
            assert!(gap <= 1e-12, "{a} against {b} at t = {}", want[0]);
        }
    }
    println!("RK4 through the FMU against the runtime's RK4: {worst:e}");
}
