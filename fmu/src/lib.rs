//! FMI 3.0 Co-Simulation for camchain models.
//!
//! A model's FMU is a library that links its generated code, the runtime and this crate, and
//! whose root calls [`export!`] once with the generated module's `boxed`: that defines every
//! `fmi3*` function of the standard (those this FMU does not provide return `fmi3Error` with
//! a log message, never a missing symbol). Its `modelDescription.xml` is
//! [`description::model_description`] of the same model. Neither holds the code generator.
//!
//! - [`variables`]: the variables and their value references (time, run-time parameters,
//!   the integrator's settings, the drives' speeds as inputs, the CSV's output columns).
//! - [`drive`]: the model with the drive speeds its master set.
//! - [`description`]: `modelDescription.xml` and the instantiation token.
//! - [`instance`]: one instance in safe Rust: modes, values, `fmi3DoStep`.
//! - [`ffi`]: the C side: arguments, statuses, the importer's logger, panics kept out of C.

pub mod description;
pub mod drive;
pub mod ffi;
pub mod instance;
pub mod variables;

pub use instance::{Factory, Instance, Mode};

/// Defines every FMI 3.0 function for the model `$factory` builds (a generated module's
/// `boxed`), in the crate that calls it (a `cdylib`): `camchain_fmu::export!(model::boxed);`.
///
/// Functions this FMU does not provide (Model Exchange, Scheduled Execution, FMU states,
/// derivatives, clocks, the integer, Boolean, string and binary variables it has none of)
/// take the instance first and return `fmi3Error` after logging why; their other arguments
/// are ignored (the C calling conventions FMI targets leave the caller to clean them up), or
/// null for the instantiation functions that return an instance.
#[macro_export]
macro_rules! export {
    ($factory:path) => {
        const _: () = {
            use ::std::ffi::{c_char, c_void};
            use $crate::ffi::{self, Logger, Status};

            #[unsafe(no_mangle)]
            pub extern "C" fn fmi3GetVersion() -> *const c_char {
                c"3.0".as_ptr()
            }

            /// # Safety
            /// The importer's arguments, as FMI 3.0 prescribes.
            #[unsafe(no_mangle)]
            #[allow(clippy::too_many_arguments)]
            pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
                instance_name: *const c_char,
                token: *const c_char,
                _resource_path: *const c_char,
                _visible: bool,
                logging_on: bool,
                event_mode_used: bool,
                _early_return_allowed: bool,
                _required_intermediate: *const u32,
                _n_required_intermediate: usize,
                environment: *mut c_void,
                logger: Logger,
                _intermediate_update: *const c_void,
            ) -> *mut c_void {
                // SAFETY: the importer's arguments.
                unsafe {
                    ffi::instantiate_co_simulation(
                        $factory,
                        instance_name,
                        token,
                        logging_on,
                        event_mode_used,
                        environment,
                        logger,
                    )
                }
            }

            /// # Safety
            /// An instance of this library, not used again.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3FreeInstance(instance: *mut c_void) {
                // SAFETY: per the contract.
                unsafe { ffi::free_instance(instance) }
            }

            /// # Safety
            /// An instance of this library.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetDebugLogging(
                instance: *mut c_void,
                logging_on: bool,
                _n_categories: usize,
                _categories: *const *const c_char,
            ) -> Status {
                // SAFETY: per the contract.
                unsafe { ffi::set_debug_logging(instance, logging_on) }
            }

            /// # Safety
            /// An instance of this library.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3EnterInitializationMode(
                instance: *mut c_void,
                tolerance_defined: bool,
                tolerance: f64,
                start_time: f64,
                stop_time_defined: bool,
                stop_time: f64,
            ) -> Status {
                // SAFETY: per the contract.
                unsafe {
                    ffi::enter_initialization_mode(
                        instance,
                        tolerance_defined.then_some(tolerance),
                        start_time,
                        stop_time_defined.then_some(stop_time),
                    )
                }
            }

            /// # Safety
            /// An instance of this library.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: *mut c_void) -> Status {
                // SAFETY: per the contract.
                unsafe { ffi::transition(instance, "fmi3ExitInitializationMode") }
            }

            /// # Safety
            /// An instance of this library.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3Terminate(instance: *mut c_void) -> Status {
                // SAFETY: per the contract.
                unsafe { ffi::transition(instance, "fmi3Terminate") }
            }

            /// # Safety
            /// An instance of this library.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3Reset(instance: *mut c_void) -> Status {
                // SAFETY: per the contract.
                unsafe { ffi::transition(instance, "fmi3Reset") }
            }

            /// # Safety
            /// An instance of this library; arrays of the lengths given.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetFloat64(
                instance: *mut c_void,
                references: *const u32,
                n_references: usize,
                values: *mut f64,
                n_values: usize,
            ) -> Status {
                // SAFETY: per the contract.
                unsafe { ffi::get_float64(instance, references, n_references, values, n_values) }
            }

            /// # Safety
            /// An instance of this library; arrays of the lengths given.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetFloat64(
                instance: *mut c_void,
                references: *const u32,
                n_references: usize,
                values: *const f64,
                n_values: usize,
            ) -> Status {
                // SAFETY: per the contract.
                unsafe { ffi::set_float64(instance, references, n_references, values, n_values) }
            }

            /// # Safety
            /// An instance of this library; arrays of the lengths given.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetInt64(
                instance: *mut c_void,
                references: *const u32,
                n_references: usize,
                values: *mut i64,
                n_values: usize,
            ) -> Status {
                // SAFETY: per the contract.
                unsafe { ffi::get_int64(instance, references, n_references, values, n_values) }
            }

            /// # Safety
            /// An instance of this library; arrays of the lengths given.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetInt64(
                instance: *mut c_void,
                references: *const u32,
                n_references: usize,
                values: *const i64,
                n_values: usize,
            ) -> Status {
                // SAFETY: per the contract.
                unsafe { ffi::set_int64(instance, references, n_references, values, n_values) }
            }

            /// # Safety
            /// An instance of this library; the out-pointers null or writable.
            #[unsafe(no_mangle)]
            #[allow(clippy::too_many_arguments)]
            pub unsafe extern "C" fn fmi3DoStep(
                instance: *mut c_void,
                current: f64,
                step: f64,
                _no_set_state_prior: bool,
                event_handling_needed: *mut bool,
                terminate: *mut bool,
                early_return: *mut bool,
                last_successful_time: *mut f64,
            ) -> Status {
                // SAFETY: per the contract.
                unsafe {
                    ffi::do_step(
                        instance,
                        current,
                        step,
                        event_handling_needed,
                        terminate,
                        early_return,
                        last_successful_time,
                    )
                }
            }

            /// The model's `modelDescription.xml` for the library `identifier` (not an FMI
            /// function: what `camchain fmu` asks the library it built).
            ///
            /// # Safety
            /// `identifier` is NUL-terminated; the result is freed with
            /// `camchain_fmu_free_text`.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn camchain_fmu_model_description(
                identifier: *const c_char,
            ) -> *mut c_char {
                // SAFETY: per the contract.
                unsafe { ffi::model_description($factory, identifier) }
            }

            /// Frees a string of `camchain_fmu_model_description`.
            ///
            /// # Safety
            /// A pointer it returned, freed once.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn camchain_fmu_free_text(text: *mut c_char) {
                // SAFETY: per the contract.
                unsafe { ffi::free_text(text) }
            }

            /// # Safety
            /// The importer's arguments: none is read.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3InstantiateModelExchange() -> *mut c_void {
                ::std::ptr::null_mut()
            }

            /// # Safety
            /// The importer's arguments: none is read.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3InstantiateScheduledExecution() -> *mut c_void {
                ::std::ptr::null_mut()
            }

            $crate::unsupported! {
                "this FMU is Co-Simulation only" => fmi3EnterContinuousTimeMode,
                    fmi3CompletedIntegratorStep, fmi3SetTime, fmi3SetContinuousStates,
                    fmi3GetContinuousStateDerivatives, fmi3GetEventIndicators,
                    fmi3GetContinuousStates, fmi3GetNominalsOfContinuousStates,
                    fmi3GetNumberOfEventIndicators, fmi3GetNumberOfContinuousStates,
                    fmi3ActivateModelPartition;
                "it has no event mode: events are handled inside fmi3DoStep" =>
                    fmi3EnterEventMode, fmi3EnterStepMode, fmi3UpdateDiscreteStates,
                    fmi3EvaluateDiscreteStates;
                "it has no clocks" => fmi3GetClock, fmi3SetClock, fmi3GetIntervalDecimal,
                    fmi3GetIntervalFraction, fmi3GetShiftDecimal, fmi3GetShiftFraction,
                    fmi3SetIntervalDecimal, fmi3SetIntervalFraction, fmi3SetShiftDecimal,
                    fmi3SetShiftFraction;
                "its FMU state cannot be saved (canGetAndSetFMUState=\"false\")" =>
                    fmi3GetFMUState, fmi3SetFMUState, fmi3FreeFMUState,
                    fmi3SerializedFMUStateSize, fmi3SerializeFMUState, fmi3DeserializeFMUState;
                "it provides no derivatives" => fmi3GetDirectionalDerivative,
                    fmi3GetAdjointDerivative, fmi3GetOutputDerivatives;
                "it declares no dependencies (every output depends on every parameter)" =>
                    fmi3GetNumberOfVariableDependencies, fmi3GetVariableDependencies;
                "it has no structural parameters" => fmi3EnterConfigurationMode,
                    fmi3ExitConfigurationMode;
                "its variables are Float64 but for the integrator, an Enumeration (Int64)" =>
                    fmi3GetFloat32, fmi3SetFloat32, fmi3GetInt8, fmi3SetInt8, fmi3GetUInt8,
                    fmi3SetUInt8, fmi3GetInt16, fmi3SetInt16, fmi3GetUInt16, fmi3SetUInt16,
                    fmi3GetInt32, fmi3SetInt32, fmi3GetUInt32, fmi3SetUInt32, fmi3GetUInt64,
                    fmi3SetUInt64, fmi3GetBoolean, fmi3SetBoolean, fmi3GetString,
                    fmi3SetString, fmi3GetBinary, fmi3SetBinary;
            }
        };
    };
}

/// The functions [`export!`] defines as refusals, grouped by the reason logged.
#[doc(hidden)]
#[macro_export]
macro_rules! unsupported {
    ($($why:literal => $($name:ident),+ $(,)?;)+) => {
        $($(
            /// # Safety
            /// An instance of this library first; the other arguments are not read.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn $name(instance: *mut ::std::ffi::c_void) -> $crate::ffi::Status {
                // SAFETY: per the contract.
                unsafe { $crate::ffi::unsupported(instance, stringify!($name), $why) }
            }
        )+)+
    };
}

/// Every function name of FMI 3.0's `fmi3Functions.h` (75), for the check that an exported
/// library defines them all.
pub const FMI3_FUNCTIONS: &[&str] = &[
    "fmi3ActivateModelPartition",
    "fmi3CompletedIntegratorStep",
    "fmi3DeserializeFMUState",
    "fmi3DoStep",
    "fmi3EnterConfigurationMode",
    "fmi3EnterContinuousTimeMode",
    "fmi3EnterEventMode",
    "fmi3EnterInitializationMode",
    "fmi3EnterStepMode",
    "fmi3EvaluateDiscreteStates",
    "fmi3ExitConfigurationMode",
    "fmi3ExitInitializationMode",
    "fmi3FreeFMUState",
    "fmi3FreeInstance",
    "fmi3GetAdjointDerivative",
    "fmi3GetBinary",
    "fmi3GetBoolean",
    "fmi3GetClock",
    "fmi3GetContinuousStateDerivatives",
    "fmi3GetContinuousStates",
    "fmi3GetDirectionalDerivative",
    "fmi3GetEventIndicators",
    "fmi3GetFMUState",
    "fmi3GetFloat32",
    "fmi3GetFloat64",
    "fmi3GetInt16",
    "fmi3GetInt32",
    "fmi3GetInt64",
    "fmi3GetInt8",
    "fmi3GetIntervalDecimal",
    "fmi3GetIntervalFraction",
    "fmi3GetNominalsOfContinuousStates",
    "fmi3GetNumberOfContinuousStates",
    "fmi3GetNumberOfEventIndicators",
    "fmi3GetNumberOfVariableDependencies",
    "fmi3GetOutputDerivatives",
    "fmi3GetShiftDecimal",
    "fmi3GetShiftFraction",
    "fmi3GetString",
    "fmi3GetUInt16",
    "fmi3GetUInt32",
    "fmi3GetUInt64",
    "fmi3GetUInt8",
    "fmi3GetVariableDependencies",
    "fmi3GetVersion",
    "fmi3InstantiateCoSimulation",
    "fmi3InstantiateModelExchange",
    "fmi3InstantiateScheduledExecution",
    "fmi3Reset",
    "fmi3SerializeFMUState",
    "fmi3SerializedFMUStateSize",
    "fmi3SetBinary",
    "fmi3SetBoolean",
    "fmi3SetClock",
    "fmi3SetContinuousStates",
    "fmi3SetDebugLogging",
    "fmi3SetFMUState",
    "fmi3SetFloat32",
    "fmi3SetFloat64",
    "fmi3SetInt16",
    "fmi3SetInt32",
    "fmi3SetInt64",
    "fmi3SetInt8",
    "fmi3SetIntervalDecimal",
    "fmi3SetIntervalFraction",
    "fmi3SetShiftDecimal",
    "fmi3SetShiftFraction",
    "fmi3SetString",
    "fmi3SetTime",
    "fmi3SetUInt16",
    "fmi3SetUInt32",
    "fmi3SetUInt64",
    "fmi3SetUInt8",
    "fmi3Terminate",
    "fmi3UpdateDiscreteStates",
];
