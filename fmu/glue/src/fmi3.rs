//! The FMI 3.0 Co-Simulation C layer over any [`Core`], and [`export_fmi3!`](crate::export_fmi3)
//! that exports every `fmi3*` function of `fmi3Functions.h` for one type: the Co-Simulation
//! ones, the common ones and `fmi3GetAdjointDerivative` work; those of Model Exchange,
//! Scheduled Execution, clocks, event mode and configuration mode log and return `fmi3Error`
//! (the FMU declares none of them).
//!
//! The generic functions of [`crate::fmi2`] that do not depend on the version (the panic
//! barrier, values, FMU states) are called with the FMI 3.0 function names. What differs:
//! * `fmi3Boolean` is a C `bool` (one byte): read as `u8`, any non-zero value is true, so that
//!   no byte from the importer can become an invalid Rust `bool`;
//! * getters and setters take `nValues`: a getter of Float64, Int32 or UInt64 may read arrays
//!   (`Core::get_float64`, …: their values one after another), a setter takes scalars only
//!   (`nValues = nvr`);
//! * `fmi3EnterInitializationMode` carries what `fmi2SetupExperiment` did;
//! * `fmi3DoStep` never returns early, and tells the last successful time and whether the FMU
//!   asks to stop through its out-arguments.
//!
//! Every function here is `unsafe` with the FMI 3.0 caller contract (§2.2): the instance is NULL
//! or one returned by `fmi3InstantiateCoSimulation` of this library and not yet freed, calls on
//! one instance are not concurrent, arrays hold the announced number of elements, strings are
//! NUL-terminated or NULL, an FMU state is NULL or one this library returned.
#![allow(clippy::missing_safety_doc)] // the contract is the FMI 3.0 standard, cited above

use core::ffi::{c_char, c_int, c_uint, c_void};

use crate::core::{Core, Instantiation, no_variables, scalars};
use crate::ffi::{input, out_ref, output, string, strings};
use crate::fmi2::{instantiate_with, with};
use crate::logger::{Fmi3LoggerFn, Sink};
use crate::phase::{Failure, Outcome, allowed};

/// `fmi3InstantiateCoSimulation`; refuses event mode (the FMU declares `hasEventMode="false"`).
#[allow(clippy::too_many_arguments)]
pub unsafe fn instantiate<C: Core>(
    name: *const c_char,
    token: *const c_char,
    resources: *const c_char,
    logging_on: u8,
    event_mode_used: u8,
    environment: *mut c_void,
    log_message: Option<Fmi3LoggerFn>,
) -> *mut c_void {
    let sink = Sink::fmi3(log_message, environment);
    // SAFETY: NULL or NUL-terminated strings valid for this call (contract).
    let (name, token, resources) = unsafe { (string(name), string(token), string(resources)) };
    instantiate_with::<C>("fmi3InstantiateCoSimulation", &sink.clone(), || {
        let name = name.map_err(|f| f.message)?.ok_or("instanceName is NULL")?;
        if name.trim().is_empty() {
            return Err("instanceName is empty".into());
        }
        if event_mode_used != 0 {
            return Err(
                "eventModeUsed = true: this FMU has no event mode (hasEventMode=\"false\")".into(),
            );
        }
        C::instantiate(Instantiation {
            name,
            token: token.map_err(|f| f.message)?,
            resources: resources.map_err(|f| f.message)?,
            sink,
            logging_on: logging_on != 0,
            fmi_version: 3,
        })
    })
}

/// `fmi3EnterInitializationMode`: the experiment's start and stop, then initialization mode.
pub unsafe fn enter_initialization_mode<C: Core>(
    c: *mut c_void,
    start: f64,
    stop_defined: u8,
    stop: f64,
) -> c_int {
    let stop = (stop_defined != 0).then_some(stop);
    // SAFETY: contract (module doc).
    unsafe {
        with::<C>(
            c,
            "fmi3EnterInitializationMode",
            allowed::ENTER_INITIALIZATION,
            |i| {
                i.setup_experiment(start, stop)?;
                i.enter_initialization_mode()
            },
        )
    }
}

/// `fmi3GetFloat64`, `fmi3GetInt32`, `fmi3GetUInt64`, `fmi3GetString`: `get` fills `nValues`
/// values, arrays included.
pub unsafe fn get_values<C: Core, T>(
    c: *mut c_void,
    function: &str,
    (vr, nvr): (*const c_uint, usize),
    (values, n_values): (*mut T, usize),
    get: fn(&mut C, &[u32], &mut [T]) -> Outcome,
) -> c_int {
    // SAFETY: contract: `vr` holds `nvr` elements, `values` `nValues`.
    unsafe {
        with::<C>(c, function, allowed::GET, |i| {
            get(
                i,
                input(vr, nvr, "vr")?,
                output(values, n_values, "values")?,
            )
        })
    }
}

/// `fmi3SetFloat64`, `fmi3SetInt32`.
pub unsafe fn set<C: Core, T>(
    c: *mut c_void,
    function: &str,
    (vr, nvr): (*const c_uint, usize),
    (values, n_values): (*const T, usize),
    set: fn(&mut C, &[u32], &[T]) -> Outcome,
) -> c_int {
    // SAFETY: contract: `vr` holds `nvr` elements, `values` `nValues`.
    unsafe {
        with::<C>(c, function, allowed::SET, |i| {
            scalars(nvr, n_values)?;
            set(i, input(vr, nvr, "vr")?, input(values, n_values, "values")?)
        })
    }
}

/// `fmi3SetString`: scalars only; the strings are copied.
pub unsafe fn set_string<C: Core>(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    values: *const *const c_char,
    n_values: usize,
) -> c_int {
    // SAFETY: contract: `vr` holds `nvr` elements, `values` `nValues` NUL-terminated strings.
    unsafe {
        with::<C>(c, "fmi3SetString", allowed::SET, |i| {
            scalars(nvr, n_values)?;
            i.set_string(input(vr, nvr, "vr")?, &strings(values, n_values, "values")?)
        })
    }
}

/// `fmi3GetBoolean`: written as 0 or 1.
pub unsafe fn get_boolean<C: Core>(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    values: *mut u8,
    n_values: usize,
) -> c_int {
    // SAFETY: contract: `vr` holds `nvr` elements, `values` `nValues`.
    unsafe {
        with::<C>(c, "fmi3GetBoolean", allowed::GET, |i| {
            scalars(nvr, n_values)?;
            let out = output(values, n_values, "values")?;
            let mut b = vec![false; nvr];
            i.get_boolean(input(vr, nvr, "vr")?, &mut b)?;
            out.iter_mut().zip(b).for_each(|(o, b)| *o = u8::from(b));
            Ok(())
        })
    }
}

/// `fmi3SetBoolean`: any non-zero byte is true.
pub unsafe fn set_boolean<C: Core>(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    values: *const u8,
    n_values: usize,
) -> c_int {
    // SAFETY: contract: `vr` holds `nvr` elements, `values` `nValues`.
    unsafe {
        with::<C>(c, "fmi3SetBoolean", allowed::SET, |i| {
            scalars(nvr, n_values)?;
            let b: Vec<bool> = input(values, n_values, "values")?
                .iter()
                .map(|&v| v != 0)
                .collect();
            i.set_boolean(input(vr, nvr, "vr")?, &b)
        })
    }
}

/// A getter or setter of a type the FMU has no variables of (`fmi3GetInt8`, …, `fmi3SetBinary`):
/// nothing to do for an empty list, an error naming the first reference otherwise.
pub unsafe fn none<C: Core>(
    c: *mut c_void,
    function: &str,
    vr: *const c_uint,
    nvr: usize,
) -> c_int {
    // SAFETY: contract: `vr` holds `nvr` elements.
    unsafe {
        with::<C>(c, function, allowed::ANY, |_| {
            no_variables(input(vr, nvr, "vr")?, &function[7..])
        })
    }
}

/// `fmi3DoStep`: no early return; the out-arguments are written whatever the status.
#[allow(clippy::too_many_arguments)]
pub unsafe fn do_step<C: Core>(
    c: *mut c_void,
    t: f64,
    h: f64,
    event_handling_needed: *mut u8,
    terminate_simulation: *mut u8,
    early_return: *mut u8,
    last_successful_time: *mut f64,
) -> c_int {
    // SAFETY: contract: the out-arguments are writable (NULL is refused).
    unsafe {
        with::<C>(c, "fmi3DoStep", allowed::DO_STEP, |i| {
            let outputs = (
                out_ref(event_handling_needed, "eventHandlingNeeded")?,
                out_ref(terminate_simulation, "terminateSimulation")?,
                out_ref(early_return, "earlyReturn")?,
                out_ref(last_successful_time, "lastSuccessfulTime")?,
            );
            let result = i.do_step(t, h);
            *outputs.0 = 0;
            *outputs.1 = u8::from(i.terminate_requested());
            *outputs.2 = 0;
            *outputs.3 = i.last_successful_time();
            result
        })
    }
}

/// `fmi3GetDirectionalDerivative` (`adjoint` false: `nSeed = nKnowns`, `nSensitivity =
/// nUnknowns`) and `fmi3GetAdjointDerivative` (true: `nSeed = nUnknowns`, `nSensitivity =
/// nKnowns`); every variable is a scalar.
pub unsafe fn derivative<C: Core>(
    c: *mut c_void,
    adjoint: bool,
    (unknowns, n_unknowns): (*const c_uint, usize),
    (knowns, n_knowns): (*const c_uint, usize),
    (seed, n_seed): (*const f64, usize),
    (sensitivity, n_sensitivity): (*mut f64, usize),
) -> c_int {
    let (function, sizes) = if adjoint {
        ("fmi3GetAdjointDerivative", (n_unknowns, n_knowns))
    } else {
        ("fmi3GetDirectionalDerivative", (n_knowns, n_unknowns))
    };
    // SAFETY: contract: the arrays hold the announced numbers of elements.
    unsafe {
        with::<C>(c, function, allowed::DIRECTIONAL_DERIVATIVE, |i| {
            if (n_seed, n_sensitivity) != sizes {
                return Err(Failure::error(format!(
                    "nSeed = {n_seed} and nSensitivity = {n_sensitivity} must be {} and {} \
                     (nKnowns = {n_knowns}, nUnknowns = {n_unknowns}; every variable is a scalar)",
                    sizes.0, sizes.1
                )));
            }
            let (unknowns, knowns) = (
                input(unknowns, n_unknowns, "unknowns")?,
                input(knowns, n_knowns, "knowns")?,
            );
            let seed = input(seed, n_seed, "seed")?;
            let sensitivity = output(sensitivity, n_sensitivity, "sensitivity")?;
            if adjoint {
                i.adjoint_derivative(unknowns, knowns, seed, sensitivity)
            } else {
                i.directional_derivative(unknowns, knowns, seed, sensitivity)
            }
        })
    }
}

/// Exports the FMI 3.0 functions for the [`Core`] type `$core` (in the crate that names the
/// cdylib). Each is a one-line delegation to a generic function of [`crate::fmi3`] or
/// [`crate::fmi2`].
#[macro_export]
macro_rules! export_fmi3 {
    ($core:ty) => {
        /// The FMI 3.0 functions of this FMU, made by `fmi_glue::export_fmi3!`.
        #[allow(clippy::missing_safety_doc)]
        pub mod fmi3_exports {
            use super::*;
            use ::core::ffi::{c_char, c_int, c_uint, c_void};
            use $crate::core::Core;
            use $crate::fmi2 as g2;
            use $crate::fmi3 as g;
            use $crate::phase::allowed;
            type C = $core;

            #[unsafe(export_name = "fmi3GetVersion")]
            pub extern "C" fn get_version() -> *const c_char {
                c"3.0".as_ptr()
            }
            #[unsafe(export_name = "fmi3InstantiateModelExchange")]
            pub extern "C" fn instantiate_model_exchange(
                _n: *const c_char, _t: *const c_char, _r: *const c_char, _v: u8, _l: u8,
                _e: *mut c_void, _m: *mut c_void,
            ) -> *mut c_void {
                ::std::ptr::null_mut()
            }
            #[unsafe(export_name = "fmi3InstantiateScheduledExecution")]
            pub extern "C" fn instantiate_scheduled_execution(
                _n: *const c_char, _t: *const c_char, _r: *const c_char, _v: u8, _l: u8,
                _e: *mut c_void, _m: *mut c_void, _clock: *mut c_void, _lock: *mut c_void,
                _unlock: *mut c_void,
            ) -> *mut c_void {
                ::std::ptr::null_mut()
            }
            $crate::export_fmi2!(@forward
                "fmi3InstantiateCoSimulation" instantiate_co_simulation(name: *const c_char, token: *const c_char, res: *const c_char, _visible: u8, on: u8, event_mode: u8, _early: u8, _req: *const c_uint, _nreq: usize, env: *mut c_void, log: Option<$crate::logger::Fmi3LoggerFn>, _update: *mut c_void) -> *mut c_void
                    = g::instantiate::<C>(name, token, res, on, event_mode, env, log);
                "fmi3FreeInstance" free_instance(c: *mut c_void) -> () = g2::free_instance::<C>(c);
                "fmi3SetDebugLogging" set_debug_logging(c: *mut c_void, on: u8, n: usize, cats: *const *const c_char) -> c_int
                    = g2::set_debug_logging::<C>(c, "fmi3SetDebugLogging", on != 0, n, cats);
                "fmi3EnterInitializationMode" enter_initialization_mode(c: *mut c_void, _td: u8, _tol: f64, start: f64, sd: u8, stop: f64) -> c_int
                    = g::enter_initialization_mode::<C>(c, start, sd, stop);
                "fmi3ExitInitializationMode" exit_initialization_mode(c: *mut c_void) -> c_int
                    = g2::transition::<C>(c, "fmi3ExitInitializationMode", allowed::EXIT_INITIALIZATION, <C as Core>::exit_initialization_mode);
                "fmi3Terminate" terminate(c: *mut c_void) -> c_int
                    = g2::transition::<C>(c, "fmi3Terminate", allowed::TERMINATE, <C as Core>::terminate);
                "fmi3Reset" reset(c: *mut c_void) -> c_int = g2::transition::<C>(c, "fmi3Reset", allowed::RESET, <C as Core>::reset);
                "fmi3GetFloat64" get_float64(c: *mut c_void, vr: *const c_uint, n: usize, v: *mut f64, nv: usize) -> c_int
                    = g::get_values::<C, f64>(c, "fmi3GetFloat64", (vr, n), (v, nv), <C as Core>::get_float64);
                "fmi3SetFloat64" set_float64(c: *mut c_void, vr: *const c_uint, n: usize, v: *const f64, nv: usize) -> c_int
                    = g::set::<C, f64>(c, "fmi3SetFloat64", (vr, n), (v, nv), <C as Core>::set_real);
                "fmi3GetInt32" get_int32(c: *mut c_void, vr: *const c_uint, n: usize, v: *mut i32, nv: usize) -> c_int
                    = g::get_values::<C, i32>(c, "fmi3GetInt32", (vr, n), (v, nv), <C as Core>::get_int32);
                "fmi3SetInt32" set_int32(c: *mut c_void, vr: *const c_uint, n: usize, v: *const i32, nv: usize) -> c_int
                    = g::set::<C, i32>(c, "fmi3SetInt32", (vr, n), (v, nv), <C as Core>::set_integer);
                "fmi3GetUInt64" get_uint64(c: *mut c_void, vr: *const c_uint, n: usize, v: *mut u64, nv: usize) -> c_int
                    = g::get_values::<C, u64>(c, "fmi3GetUInt64", (vr, n), (v, nv), <C as Core>::get_uint64);
                "fmi3GetBoolean" get_boolean(c: *mut c_void, vr: *const c_uint, n: usize, v: *mut u8, nv: usize) -> c_int
                    = g::get_boolean::<C>(c, vr, n, v, nv);
                "fmi3SetBoolean" set_boolean(c: *mut c_void, vr: *const c_uint, n: usize, v: *const u8, nv: usize) -> c_int
                    = g::set_boolean::<C>(c, vr, n, v, nv);
                "fmi3GetString" get_string(c: *mut c_void, vr: *const c_uint, n: usize, v: *mut *const c_char, nv: usize) -> c_int
                    = g::get_values::<C, *const c_char>(c, "fmi3GetString", (vr, n), (v, nv), <C as Core>::get_strings);
                "fmi3SetString" set_string(c: *mut c_void, vr: *const c_uint, n: usize, v: *const *const c_char, nv: usize) -> c_int
                    = g::set_string::<C>(c, vr, n, v, nv);
                "fmi3GetFMUState" get_fmu_state(c: *mut c_void, s: *mut *mut c_void) -> c_int = g2::get_fmu_state::<C>(c, "fmi3GetFMUState", s);
                "fmi3SetFMUState" set_fmu_state(c: *mut c_void, s: *mut c_void) -> c_int = g2::set_fmu_state::<C>(c, "fmi3SetFMUState", s);
                "fmi3FreeFMUState" free_fmu_state(c: *mut c_void, s: *mut *mut c_void) -> c_int = g2::free_fmu_state::<C>(c, "fmi3FreeFMUState", s);
                "fmi3SerializedFMUStateSize" serialized_size(c: *mut c_void, s: *mut c_void, n: *mut usize) -> c_int
                    = g2::serialized_size::<C>(c, "fmi3SerializedFMUStateSize", s, n);
                "fmi3SerializeFMUState" serialize(c: *mut c_void, s: *mut c_void, b: *mut c_char, n: usize) -> c_int
                    = g2::serialize::<C>(c, "fmi3SerializeFMUState", s, b, n);
                "fmi3DeserializeFMUState" deserialize(c: *mut c_void, b: *const c_char, n: usize, s: *mut *mut c_void) -> c_int
                    = g2::deserialize::<C>(c, "fmi3DeserializeFMUState", b, n, s);
                "fmi3GetDirectionalDerivative" get_directional_derivative(c: *mut c_void, u: *const c_uint, nu: usize, k: *const c_uint, nk: usize, s: *const f64, ns: usize, o: *mut f64, no: usize) -> c_int
                    = g::derivative::<C>(c, false, (u, nu), (k, nk), (s, ns), (o, no));
                "fmi3GetAdjointDerivative" get_adjoint_derivative(c: *mut c_void, u: *const c_uint, nu: usize, k: *const c_uint, nk: usize, s: *const f64, ns: usize, o: *mut f64, no: usize) -> c_int
                    = g::derivative::<C>(c, true, (u, nu), (k, nk), (s, ns), (o, no));
                "fmi3DoStep" do_step(c: *mut c_void, t: f64, h: f64, _no_prior: u8, event: *mut u8, stop: *mut u8, early: *mut u8, last: *mut f64) -> c_int
                    = g::do_step::<C>(c, t, h, event, stop, early, last);
            );
            $crate::export_fmi3!(@none
                "fmi3GetFloat32" get_float32(v: *mut f32, nv: usize); "fmi3SetFloat32" set_float32(v: *const f32, nv: usize);
                "fmi3GetInt8" get_int8(v: *mut i8, nv: usize); "fmi3SetInt8" set_int8(v: *const i8, nv: usize);
                "fmi3GetUInt8" get_uint8(v: *mut u8, nv: usize); "fmi3SetUInt8" set_uint8(v: *const u8, nv: usize);
                "fmi3GetInt16" get_int16(v: *mut i16, nv: usize); "fmi3SetInt16" set_int16(v: *const i16, nv: usize);
                "fmi3GetUInt16" get_uint16(v: *mut u16, nv: usize); "fmi3SetUInt16" set_uint16(v: *const u16, nv: usize);
                "fmi3GetUInt32" get_uint32(v: *mut u32, nv: usize); "fmi3SetUInt32" set_uint32(v: *const u32, nv: usize);
                "fmi3GetInt64" get_int64(v: *mut i64, nv: usize); "fmi3SetInt64" set_int64(v: *const i64, nv: usize);
                "fmi3SetUInt64" set_uint64(v: *const u64, nv: usize);
                "fmi3GetBinary" get_binary(s: *mut usize, v: *mut *const u8, nv: usize);
                "fmi3SetBinary" set_binary(s: *const usize, v: *const *const u8, nv: usize);
                "fmi3GetClock" get_clock(v: *mut u8); "fmi3SetClock" set_clock(v: *const u8);
            );
            $crate::export_fmi2!(@refused
                "fmi3GetNumberOfVariableDependencies" get_number_of_variable_dependencies(_vr: c_uint, _n: *mut usize);
                "fmi3GetVariableDependencies" get_variable_dependencies(_d: c_uint, _e: *mut usize, _i: *mut c_uint, _ei: *mut usize, _k: *mut c_int, _n: usize);
                "fmi3EnterConfigurationMode" enter_configuration_mode();
                "fmi3ExitConfigurationMode" exit_configuration_mode();
                "fmi3EnterEventMode" enter_event_mode();
                "fmi3EnterStepMode" enter_step_mode();
                "fmi3GetOutputDerivatives" get_output_derivatives(_r: *const c_uint, _n: usize, _o: *const i32, _v: *mut f64, _nv: usize);
                "fmi3GetIntervalDecimal" get_interval_decimal(_r: *const c_uint, _n: usize, _i: *mut f64, _q: *mut c_int);
                "fmi3GetIntervalFraction" get_interval_fraction(_r: *const c_uint, _n: usize, _counters: *mut u64, _res: *mut u64, _q: *mut c_int);
                "fmi3GetShiftDecimal" get_shift_decimal(_r: *const c_uint, _n: usize, _s: *mut f64);
                "fmi3GetShiftFraction" get_shift_fraction(_r: *const c_uint, _n: usize, _counters: *mut u64, _res: *mut u64);
                "fmi3SetIntervalDecimal" set_interval_decimal(_r: *const c_uint, _n: usize, _i: *const f64);
                "fmi3SetIntervalFraction" set_interval_fraction(_r: *const c_uint, _n: usize, _counters: *const u64, _res: *const u64);
                "fmi3SetShiftDecimal" set_shift_decimal(_r: *const c_uint, _n: usize, _s: *const f64);
                "fmi3SetShiftFraction" set_shift_fraction(_r: *const c_uint, _n: usize, _counters: *const u64, _res: *const u64);
                "fmi3EvaluateDiscreteStates" evaluate_discrete_states();
                "fmi3UpdateDiscreteStates" update_discrete_states(_a: *mut u8, _b: *mut u8, _nc: *mut u8, _d: *mut u8, _e: *mut u8, _f: *mut f64);
                "fmi3EnterContinuousTimeMode" enter_continuous_time_mode();
                "fmi3CompletedIntegratorStep" completed_integrator_step(_a: u8, _b: *mut u8, _d: *mut u8);
                "fmi3SetTime" set_time(_t: f64);
                "fmi3SetContinuousStates" set_continuous_states(_x: *const f64, _n: usize);
                "fmi3GetContinuousStateDerivatives" get_derivatives(_x: *mut f64, _n: usize);
                "fmi3GetEventIndicators" get_event_indicators(_x: *mut f64, _n: usize);
                "fmi3GetContinuousStates" get_continuous_states(_x: *mut f64, _n: usize);
                "fmi3GetNominalsOfContinuousStates" get_nominals(_x: *mut f64, _n: usize);
                "fmi3GetNumberOfEventIndicators" get_number_of_event_indicators(_n: *mut usize);
                "fmi3GetNumberOfContinuousStates" get_number_of_continuous_states(_n: *mut usize);
                "fmi3ActivateModelPartition" activate_model_partition(_r: c_uint, _t: f64);
            );
        }
    };
    (@none $($export:literal $name:ident($($arg:ident: $ty:ty),*);)*) => {$(
        #[unsafe(export_name = $export)]
        pub unsafe extern "C" fn $name(c: *mut c_void, vr: *const c_uint, nvr: usize $(, $arg: $ty)*) -> c_int {
            $(let _ = $arg;)*
            // SAFETY: the FMI 3.0 caller contract: `vr` holds `nvr` elements; no value is read
            // or written (the FMU has no variable of this type).
            unsafe { g::none::<C>(c, $export, vr, nvr) }
        }
    )*};
}
