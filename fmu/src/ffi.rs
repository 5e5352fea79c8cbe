//! The C side of the FMI 3.0 functions: argument conversion, logging through the importer's
//! callback, statuses, and a guard that turns a panic into `fmi3Fatal` instead of unwinding
//! into C. [`crate::export`] defines the `fmi3*` symbols as calls of these functions.
//!
//! # Safety
//! Every function here is called by an FMI importer with the arguments the standard
//! prescribes: an instance pointer that `instantiate_co_simulation` returned and that was
//! not freed, arrays of the lengths passed beside them, NUL-terminated strings.

use crate::instance::{Factory, Instance};
use std::ffi::{CStr, CString, c_char, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// `fmi3Status`.
pub type Status = i32;
/// `fmi3OK`.
pub const OK: Status = 0;
/// `fmi3Warning`.
pub const WARNING: Status = 1;
/// `fmi3Discard`.
pub const DISCARD: Status = 2;
/// `fmi3Error`.
pub const ERROR: Status = 3;
/// `fmi3Fatal`.
pub const FATAL: Status = 4;

/// `fmi3LogMessageCallback`.
pub type Logger = Option<
    unsafe extern "C" fn(
        environment: *mut c_void,
        status: Status,
        category: *const c_char,
        message: *const c_char,
    ),
>;

/// What an `fmi3Instance` points to.
pub struct Handle {
    instance: Instance,
    environment: *mut c_void,
    logger: Logger,
    logging_on: bool,
}

impl Handle {
    /// Passes `message` to the importer's logger (errors always; events when logging is on).
    fn log(&self, status: Status, category: &str, message: &str) {
        if status == OK && !self.logging_on {
            return;
        }
        log_to(self.logger, self.environment, status, category, message);
    }
}

fn log_to(logger: Logger, environment: *mut c_void, status: Status, category: &str, text: &str) {
    let Some(logger) = logger else {
        return;
    };
    let category = CString::new(category).unwrap_or_default();
    let text = CString::new(text.replace('\0', " ")).unwrap_or_default();
    // SAFETY: the importer's callback, with the environment it gave and NUL-terminated
    // strings that live through the call.
    unsafe { logger(environment, status, category.as_ptr(), text.as_ptr()) };
}

/// The handle behind an instance pointer, `None` for null.
///
/// # Safety
/// `instance` is null or a pointer `instantiate_co_simulation` returned, not yet freed.
unsafe fn handle<'a>(instance: *mut c_void) -> Option<&'a mut Handle> {
    // SAFETY: per the contract above.
    unsafe { instance.cast::<Handle>().as_mut() }
}

/// Runs `body` on the instance: its error is logged under `logStatusError` and returned as
/// `fmi3Error`, a panic as `fmi3Fatal`.
///
/// # Safety
/// `instance` is null or a pointer `instantiate_co_simulation` returned, not yet freed.
pub unsafe fn with(
    instance: *mut c_void,
    call: &str,
    body: impl FnOnce(&mut Handle) -> Result<Status, String>,
) -> Status {
    // SAFETY: per the contract of this function.
    let Some(handle) = (unsafe { handle(instance) }) else {
        return ERROR;
    };
    let environment = handle.environment;
    let logger = handle.logger;
    match catch_unwind(AssertUnwindSafe(|| body(&mut *handle))) {
        Ok(Ok(status)) => status,
        Ok(Err(message)) => {
            handle.log(ERROR, "logStatusError", &format!("{call}: {message}"));
            ERROR
        }
        Err(_) => {
            let message = format!("{call}: internal error (a panic); the instance is unusable");
            log_to(logger, environment, FATAL, "logStatusError", &message);
            FATAL
        }
    }
}

/// A C string argument, or `None` for null or invalid UTF-8.
///
/// # Safety
/// `text` is null or NUL-terminated.
unsafe fn text<'a>(text: *const c_char) -> Option<&'a str> {
    if text.is_null() {
        return None;
    }
    // SAFETY: per the contract above.
    unsafe { CStr::from_ptr(text) }.to_str().ok()
}

/// An array argument as a slice (empty for null with length 0).
///
/// # Safety
/// `data` points to `len` values, or `len` is 0.
unsafe fn slice<'a, T>(data: *const T, len: usize) -> Option<&'a [T]> {
    if len == 0 {
        return Some(&[]);
    }
    if data.is_null() {
        return None;
    }
    // SAFETY: per the contract above.
    Some(unsafe { std::slice::from_raw_parts(data, len) })
}

/// `fmi3InstantiateCoSimulation`: null when the token is not this model's, an argument is
/// invalid or the model cannot be built (each logged).
///
/// # Safety
/// The importer's arguments (strings NUL-terminated, the callback valid while the instance
/// lives).
pub unsafe fn instantiate_co_simulation(
    factory: Factory,
    instance_name: *const c_char,
    token: *const c_char,
    logging_on: bool,
    event_mode_used: bool,
    environment: *mut c_void,
    logger: Logger,
) -> *mut c_void {
    let result = catch_unwind(AssertUnwindSafe(|| -> Result<Box<Handle>, String> {
        // SAFETY: the importer's strings.
        let name = unsafe { text(instance_name) }.unwrap_or("");
        let instance = Instance::new(factory)?;
        let expected = instance.token().to_string();
        // SAFETY: as above.
        let given = unsafe { text(token) };
        if given != Some(expected.as_str()) {
            return Err(format!(
                "instance `{name}`: the instantiation token {given:?} is not this model's \
                 ({expected}): modelDescription.xml and the binary come from different exports"
            ));
        }
        if event_mode_used {
            return Err(format!(
                "instance `{name}`: event mode was asked for, but this FMU handles its events \
                 inside fmi3DoStep (hasEventMode=\"false\")"
            ));
        }
        Ok(Box::new(Handle {
            instance,
            environment,
            logger,
            logging_on,
        }))
    }));
    match result {
        Ok(Ok(handle)) => Box::into_raw(handle).cast(),
        Ok(Err(message)) => {
            log_to(logger, environment, ERROR, "logStatusError", &message);
            std::ptr::null_mut()
        }
        Err(_) => {
            let message = "fmi3InstantiateCoSimulation: internal error (a panic)";
            log_to(logger, environment, FATAL, "logStatusError", message);
            std::ptr::null_mut()
        }
    }
}

/// `fmi3FreeInstance`.
///
/// # Safety
/// `instance` is null or a pointer `instantiate_co_simulation` returned, not yet freed; the pointer is not used again.
pub unsafe fn free_instance(instance: *mut c_void) {
    if !instance.is_null() {
        // SAFETY: a pointer from `Box::into_raw` in `instantiate_co_simulation`.
        drop(unsafe { Box::from_raw(instance.cast::<Handle>()) });
    }
}

/// `fmi3SetDebugLogging` (the categories are accepted whatever they are: this FMU logs
/// errors always and its events when logging is on).
///
/// # Safety
/// `instance` is null or a pointer `instantiate_co_simulation` returned, not yet freed.
pub unsafe fn set_debug_logging(instance: *mut c_void, on: bool) -> Status {
    // SAFETY: per the contract.
    unsafe {
        with(instance, "fmi3SetDebugLogging", |h| {
            h.logging_on = on;
            Ok(OK)
        })
    }
}

/// `fmi3EnterInitializationMode`.
///
/// # Safety
/// `instance` is null or a pointer `instantiate_co_simulation` returned, not yet freed.
pub unsafe fn enter_initialization_mode(
    instance: *mut c_void,
    tolerance: Option<f64>,
    start_time: f64,
    stop_time: Option<f64>,
) -> Status {
    // SAFETY: per the contract.
    unsafe {
        with(instance, "fmi3EnterInitializationMode", |h| {
            h.instance
                .enter_initialization(tolerance, start_time, stop_time)
                .map(|()| OK)
        })
    }
}

/// `fmi3ExitInitializationMode`, `fmi3Terminate`, `fmi3Reset`.
///
/// # Safety
/// `instance` is null or a pointer `instantiate_co_simulation` returned, not yet freed.
pub unsafe fn transition(instance: *mut c_void, call: &str) -> Status {
    // SAFETY: per the contract.
    unsafe {
        with(instance, call, |h| {
            match call {
                "fmi3ExitInitializationMode" => h.instance.exit_initialization()?,
                "fmi3Terminate" => h.instance.terminate()?,
                _ => h.instance.reset(),
            }
            Ok(OK)
        })
    }
}

/// `fmi3Get<Type>` of scalar variables: `read` gives each reference's value, written into
/// `values` in order.
///
/// # Safety
/// As [`with`]; `references` holds `n_references` values, `values` room for `n_values`.
unsafe fn get_values<T>(
    instance: *mut c_void,
    call: &str,
    (references, n_references): (*const u32, usize),
    (values, n_values): (*mut T, usize),
    read: impl Fn(&mut Instance, u32) -> Result<T, String>,
) -> Status {
    // SAFETY: per the contract.
    unsafe {
        with(instance, call, |h| {
            let references = slice(references, n_references).ok_or("null value references")?;
            if n_values != n_references {
                return Err(format!(
                    "{n_values} values for {n_references} scalar variables"
                ));
            }
            if n_values > 0 && values.is_null() {
                return Err("null values".into());
            }
            for (k, &r) in references.iter().enumerate() {
                values.add(k).write(read(&mut h.instance, r)?);
            }
            Ok(OK)
        })
    }
}

/// `fmi3Set<Type>` of scalar variables: `write` takes each reference's value, in order.
///
/// # Safety
/// As [`get_values`], `values` holding `n_values` values.
unsafe fn set_values<T: Copy>(
    instance: *mut c_void,
    call: &str,
    (references, n_references): (*const u32, usize),
    (values, n_values): (*const T, usize),
    write: impl Fn(&mut Instance, u32, T) -> Result<(), String>,
) -> Status {
    // SAFETY: per the contract.
    unsafe {
        with(instance, call, |h| {
            let references = slice(references, n_references).ok_or("null value references")?;
            let values = slice(values, n_values).ok_or("null values")?;
            if n_values != n_references {
                return Err(format!(
                    "{n_values} values for {n_references} scalar variables"
                ));
            }
            for (&r, &v) in references.iter().zip(values) {
                write(&mut h.instance, r, v)?;
            }
            Ok(OK)
        })
    }
}

/// `fmi3GetFloat64`.
///
/// # Safety
/// `instance` as for [`with`]; `references` holds `n_references` values, `values` room for
/// `n_values`.
pub unsafe fn get_float64(
    instance: *mut c_void,
    references: *const u32,
    n_references: usize,
    values: *mut f64,
    n_values: usize,
) -> Status {
    let (refs, out) = ((references, n_references), (values, n_values));
    // SAFETY: per the contract.
    unsafe { get_values(instance, "fmi3GetFloat64", refs, out, Instance::get) }
}

/// `fmi3SetFloat64`.
///
/// # Safety
/// As [`get_float64`], `values` holding `n_values` values.
pub unsafe fn set_float64(
    instance: *mut c_void,
    references: *const u32,
    n_references: usize,
    values: *const f64,
    n_values: usize,
) -> Status {
    let (refs, given) = ((references, n_references), (values, n_values));
    // SAFETY: per the contract.
    unsafe { set_values(instance, "fmi3SetFloat64", refs, given, Instance::set) }
}

/// `fmi3GetInt64`.
///
/// # Safety
/// As [`get_float64`].
pub unsafe fn get_int64(
    instance: *mut c_void,
    references: *const u32,
    n_references: usize,
    values: *mut i64,
    n_values: usize,
) -> Status {
    let (refs, out) = ((references, n_references), (values, n_values));
    // SAFETY: per the contract.
    unsafe { get_values(instance, "fmi3GetInt64", refs, out, |i, r| i.get_int64(r)) }
}

/// `fmi3SetInt64`.
///
/// # Safety
/// As [`set_float64`].
pub unsafe fn set_int64(
    instance: *mut c_void,
    references: *const u32,
    n_references: usize,
    values: *const i64,
    n_values: usize,
) -> Status {
    let (refs, given) = ((references, n_references), (values, n_values));
    // SAFETY: per the contract.
    unsafe { set_values(instance, "fmi3SetInt64", refs, given, Instance::set_int64) }
}

/// `fmi3DoStep`.
///
/// # Safety
/// `instance` is null or a pointer `instantiate_co_simulation` returned, not yet freed; the out-pointers are null or writable.
#[allow(clippy::too_many_arguments)]
pub unsafe fn do_step(
    instance: *mut c_void,
    current: f64,
    step: f64,
    event_handling_needed: *mut bool,
    terminate: *mut bool,
    early_return: *mut bool,
    last_successful_time: *mut f64,
) -> Status {
    // SAFETY: per the contract.
    unsafe {
        for flag in [event_handling_needed, terminate, early_return] {
            if let Some(flag) = flag.as_mut() {
                *flag = false;
            }
        }
        with(instance, "fmi3DoStep", |h| {
            let result = h.instance.do_step(current, step);
            for event in h.instance.take_events() {
                h.log(OK, "logEvents", &event);
            }
            if let Some(last) = last_successful_time.as_mut() {
                *last = h.instance.get(0).unwrap_or(current);
            }
            if result.is_err() {
                if let Some(flag) = terminate.as_mut() {
                    *flag = true;
                }
            }
            result.map(|_| OK)
        })
    }
}

/// `camchain_fmu_model_description`: the `modelDescription.xml` of the model `factory`
/// builds, for a library whose identifier is `identifier`, as a string the caller frees with
/// [`free_text`]; null when the model cannot be built. What `camchain fmu` packs beside the
/// library, from the library itself, so that the two describe the same model.
///
/// # Safety
/// `identifier` is NUL-terminated.
pub unsafe fn model_description(factory: Factory, identifier: *const c_char) -> *mut c_char {
    catch_unwind(|| {
        // SAFETY: per the contract.
        let identifier = unsafe { text(identifier) }.unwrap_or("model");
        let model = factory(&[]).ok()?;
        let xml = crate::description::model_description(model.as_ref(), identifier);
        CString::new(xml).ok().map(CString::into_raw)
    })
    .ok()
    .flatten()
    .unwrap_or(std::ptr::null_mut())
}

/// Frees a string of [`model_description`].
///
/// # Safety
/// A pointer [`model_description`] returned, not freed before, or null.
pub unsafe fn free_text(text: *mut c_char) {
    if !text.is_null() {
        // SAFETY: per the contract: from `CString::into_raw`.
        drop(unsafe { CString::from_raw(text) });
    }
}

/// A function this FMU does not provide: `fmi3Error`, and a log message saying so.
///
/// # Safety
/// `instance` is null or a pointer `instantiate_co_simulation` returned, not yet freed.
pub unsafe fn unsupported(instance: *mut c_void, call: &str, why: &str) -> Status {
    // SAFETY: per the contract.
    unsafe {
        with(instance, call, |_| {
            Err(format!("not provided by this FMU: {why}"))
        })
    }
}

/// The statuses are distinct (the constants mirror `fmi3Status`'s enumerators in order).
const _: () = assert!(OK == 0 && WARNING == 1 && DISCARD == 2 && ERROR == 3 && FATAL == 4);
