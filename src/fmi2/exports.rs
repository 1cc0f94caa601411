//! The exported FMI 2.0 functions: 25 common, 9 Co-Simulation, and the 10 Model Exchange ones
//! as error stubs (fmpy and FMIL bind every symbol when they load the library).
//!
//! Each function is a thin delegation: `guard` checks the pointers and the phase and catches
//! panics, `Instance` does the work. They are `pub` so that Rust tests and benchmarks can call
//! them through the rlib exactly as an importer does.
//!
//! Every `unsafe` block below relies on the same caller contract, FMI 2.0 §2.1: `c` is NULL or
//! an instance returned by `fmi2Instantiate` and not yet freed, calls on one instance are not
//! concurrent, arrays hold the announced number of elements, strings are NUL-terminated.
#![allow(clippy::missing_safety_doc)] // the contract is the FMI 2.0 standard, cited above

use core::ffi::{c_char, c_int};

use super::guard::{
    self, input, out_ref, output, state_handle, state_pointer, strings, with_instance,
};
use super::phase::{Failure, allowed};
use super::types::*;

// ------------------------------------------------------------------ inquiry

#[unsafe(export_name = "fmi2GetTypesPlatform")]
pub extern "C" fn fmi2_get_types_platform() -> *const c_char {
    c"default".as_ptr()
}

#[unsafe(export_name = "fmi2GetVersion")]
pub extern "C" fn fmi2_get_version() -> *const c_char {
    c"2.0".as_ptr()
}

#[unsafe(export_name = "fmi2SetDebugLogging")]
pub unsafe extern "C" fn fmi2_set_debug_logging(
    c: Fmi2Component,
    logging_on: Fmi2Boolean,
    n_categories: usize,
    categories: *const Fmi2String,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract (module doc); `categories` holds `n_categories` strings.
    unsafe {
        with_instance(c, "fmi2SetDebugLogging", allowed::SET_DEBUG_LOGGING, |i| {
            let names = strings(categories, n_categories, "categories")?;
            i.set_debug_logging(logging_on != FMI2_FALSE, &names)
        })
    }
}

// ------------------------------------------------------------------ lifecycle

#[unsafe(export_name = "fmi2Instantiate")]
pub unsafe extern "C" fn fmi2_instantiate(
    instance_name: Fmi2String,
    fmu_type: c_int,
    fmu_guid: Fmi2String,
    fmu_resource_location: Fmi2String,
    functions: *const Fmi2CallbackFunctions,
    _visible: Fmi2Boolean,
    logging_on: Fmi2Boolean,
) -> Fmi2Component {
    // SAFETY: FMI 2.0 §2.1.5: the strings and the callbacks struct are valid during the call.
    unsafe {
        guard::instantiate(
            instance_name,
            fmu_type,
            fmu_guid,
            fmu_resource_location,
            functions,
            logging_on != FMI2_FALSE,
        )
    }
}

#[unsafe(export_name = "fmi2FreeInstance")]
pub unsafe extern "C" fn fmi2_free_instance(c: Fmi2Component) {
    // SAFETY: FMI 2.0 caller contract; `c` is not used after this call.
    unsafe { guard::free_instance(c) }
}

#[unsafe(export_name = "fmi2SetupExperiment")]
pub unsafe extern "C" fn fmi2_setup_experiment(
    c: Fmi2Component,
    _tolerance_defined: Fmi2Boolean,
    _tolerance: Fmi2Real,
    start_time: Fmi2Real,
    stop_time_defined: Fmi2Boolean,
    stop_time: Fmi2Real,
) -> Fmi2Status {
    let stop = (stop_time_defined != FMI2_FALSE).then_some(stop_time);
    // SAFETY: FMI 2.0 caller contract (module doc).
    unsafe {
        with_instance(c, "fmi2SetupExperiment", allowed::SETUP_EXPERIMENT, |i| {
            i.setup_experiment(start_time, stop)
        })
    }
}

#[unsafe(export_name = "fmi2EnterInitializationMode")]
pub unsafe extern "C" fn fmi2_enter_initialization_mode(c: Fmi2Component) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract (module doc).
    unsafe {
        with_instance(
            c,
            "fmi2EnterInitializationMode",
            allowed::ENTER_INITIALIZATION,
            |i| i.enter_initialization_mode(),
        )
    }
}

#[unsafe(export_name = "fmi2ExitInitializationMode")]
pub unsafe extern "C" fn fmi2_exit_initialization_mode(c: Fmi2Component) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract (module doc).
    unsafe {
        with_instance(
            c,
            "fmi2ExitInitializationMode",
            allowed::EXIT_INITIALIZATION,
            |i| i.exit_initialization_mode(),
        )
    }
}

#[unsafe(export_name = "fmi2Terminate")]
pub unsafe extern "C" fn fmi2_terminate(c: Fmi2Component) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract (module doc).
    unsafe { with_instance(c, "fmi2Terminate", allowed::TERMINATE, |i| i.terminate()) }
}

#[unsafe(export_name = "fmi2Reset")]
pub unsafe extern "C" fn fmi2_reset(c: Fmi2Component) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract (module doc).
    unsafe { with_instance(c, "fmi2Reset", allowed::RESET, |i| i.reset()) }
}

// ------------------------------------------------------------------ get / set

#[unsafe(export_name = "fmi2GetReal")]
pub unsafe extern "C" fn fmi2_get_real(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2Real,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `vr` and `value` hold `nvr` elements.
    unsafe {
        with_instance(c, "fmi2GetReal", allowed::GET, |i| {
            i.get_real(input(vr, nvr, "vr")?, output(value, nvr, "value")?)
        })
    }
}

#[unsafe(export_name = "fmi2GetInteger")]
pub unsafe extern "C" fn fmi2_get_integer(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2Integer,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `vr` and `value` hold `nvr` elements.
    unsafe {
        with_instance(c, "fmi2GetInteger", allowed::GET, |i| {
            i.get_integer(input(vr, nvr, "vr")?, output(value, nvr, "value")?)
        })
    }
}

#[unsafe(export_name = "fmi2GetBoolean")]
pub unsafe extern "C" fn fmi2_get_boolean(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2Boolean,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `vr` and `value` hold `nvr` elements.
    unsafe {
        with_instance(c, "fmi2GetBoolean", allowed::GET, |i| {
            i.get_boolean(input(vr, nvr, "vr")?, output(value, nvr, "value")?)
        })
    }
}

#[unsafe(export_name = "fmi2GetString")]
pub unsafe extern "C" fn fmi2_get_string(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2String,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `vr` and `value` hold `nvr` elements.
    unsafe {
        with_instance(c, "fmi2GetString", allowed::GET, |i| {
            i.get_string(input(vr, nvr, "vr")?, output(value, nvr, "value")?)
        })
    }
}

#[unsafe(export_name = "fmi2SetReal")]
pub unsafe extern "C" fn fmi2_set_real(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2Real,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `vr` and `value` hold `nvr` elements.
    unsafe {
        with_instance(c, "fmi2SetReal", allowed::SET, |i| {
            i.set_real(input(vr, nvr, "vr")?, input(value, nvr, "value")?)
        })
    }
}

#[unsafe(export_name = "fmi2SetInteger")]
pub unsafe extern "C" fn fmi2_set_integer(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2Integer,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `vr` and `value` hold `nvr` elements.
    unsafe {
        with_instance(c, "fmi2SetInteger", allowed::SET, |i| {
            i.set_integer(input(vr, nvr, "vr")?, input(value, nvr, "value")?)
        })
    }
}

#[unsafe(export_name = "fmi2SetBoolean")]
pub unsafe extern "C" fn fmi2_set_boolean(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2Boolean,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `vr` and `value` hold `nvr` elements.
    unsafe {
        with_instance(c, "fmi2SetBoolean", allowed::SET, |i| {
            i.set_boolean(input(vr, nvr, "vr")?, input(value, nvr, "value")?)
        })
    }
}

#[unsafe(export_name = "fmi2SetString")]
pub unsafe extern "C" fn fmi2_set_string(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2String,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `vr` and `value` hold `nvr` elements, each a
    // NUL-terminated string valid during the call (the instance copies them).
    unsafe {
        with_instance(c, "fmi2SetString", allowed::SET, |i| {
            let values = strings(value, nvr, "value")?;
            i.set_string(input(vr, nvr, "vr")?, &values)
        })
    }
}

// ------------------------------------------------------------------ FMU state

#[unsafe(export_name = "fmi2GetFMUstate")]
pub unsafe extern "C" fn fmi2_get_fmu_state(
    c: Fmi2Component,
    fmu_state: *mut Fmi2FmuState,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `fmu_state` points to NULL or a state of this instance.
    unsafe {
        with_instance(c, "fmi2GetFMUstate", allowed::FMU_STATE, |i| {
            let slot = out_ref(fmu_state, "FMUstate")?;
            *slot = state_pointer(i.get_fmu_state(state_handle(*slot))?);
            Ok(())
        })
    }
}

#[unsafe(export_name = "fmi2SetFMUstate")]
pub unsafe extern "C" fn fmi2_set_fmu_state(
    c: Fmi2Component,
    fmu_state: Fmi2FmuState,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract (module doc); the state is only used as a lookup key.
    unsafe {
        with_instance(c, "fmi2SetFMUstate", allowed::FMU_STATE, |i| {
            i.set_fmu_state(state_handle(fmu_state))
        })
    }
}

#[unsafe(export_name = "fmi2FreeFMUstate")]
pub unsafe extern "C" fn fmi2_free_fmu_state(
    c: Fmi2Component,
    fmu_state: *mut Fmi2FmuState,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `fmu_state` is NULL or points to NULL or a state.
    unsafe {
        with_instance(c, "fmi2FreeFMUstate", allowed::FMU_STATE, |i| {
            // FMI 2.0 §2.1.8: a NULL *state* (`*FMUstate == NULL`) is ignored. A NULL pointer
            // to the state (`FMUstate == NULL`) leaves nothing to free or to set to NULL: it is a
            // NULL argument, an error like every other (docs/fmu.md).
            let slot = out_ref(fmu_state, "FMUstate")?;
            if !slot.is_null() {
                i.free_fmu_state(state_handle(*slot))?;
                *slot = std::ptr::null_mut();
            }
            Ok(())
        })
    }
}

#[unsafe(export_name = "fmi2SerializedFMUstateSize")]
pub unsafe extern "C" fn fmi2_serialized_fmu_state_size(
    c: Fmi2Component,
    fmu_state: Fmi2FmuState,
    size: *mut usize,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `size` points to a writable size_t.
    unsafe {
        with_instance(c, "fmi2SerializedFMUstateSize", allowed::FMU_STATE, |i| {
            let size = out_ref(size, "size")?;
            *size = i.serialize_fmu_state(state_handle(fmu_state))?.len();
            Ok(())
        })
    }
}

#[unsafe(export_name = "fmi2SerializeFMUstate")]
pub unsafe extern "C" fn fmi2_serialize_fmu_state(
    c: Fmi2Component,
    fmu_state: Fmi2FmuState,
    serialized_state: *mut Fmi2Byte,
    size: usize,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `serialized_state` holds `size` writable bytes.
    unsafe {
        with_instance(c, "fmi2SerializeFMUstate", allowed::FMU_STATE, |i| {
            let bytes = i.serialize_fmu_state(state_handle(fmu_state))?;
            let buffer = output(serialized_state.cast::<u8>(), size, "serializedState")?;
            if buffer.len() < bytes.len() {
                return Err(Failure::error(format!(
                    "the buffer holds {size} bytes, the state needs {} (ask fmi2SerializedFMUstateSize)",
                    bytes.len()
                )));
            }
            buffer[..bytes.len()].copy_from_slice(&bytes);
            Ok(())
        })
    }
}

#[unsafe(export_name = "fmi2DeSerializeFMUstate")]
pub unsafe extern "C" fn fmi2_de_serialize_fmu_state(
    c: Fmi2Component,
    serialized_state: *const Fmi2Byte,
    size: usize,
    fmu_state: *mut Fmi2FmuState,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `serialized_state` holds `size` bytes, `fmu_state` points
    // to NULL or a state of this instance.
    unsafe {
        with_instance(c, "fmi2DeSerializeFMUstate", allowed::FMU_STATE, |i| {
            let bytes = input(serialized_state.cast::<u8>(), size, "serializedState")?;
            let slot = out_ref(fmu_state, "FMUstate")?;
            *slot = state_pointer(i.deserialize_fmu_state(bytes, state_handle(*slot))?);
            Ok(())
        })
    }
}

// ------------------------------------------------------------------ not provided

fn not_provided(what: &str) -> Failure {
    Failure::error(format!("not provided by this FMU ({what})"))
}

#[unsafe(export_name = "fmi2GetDirectionalDerivative")]
pub unsafe extern "C" fn fmi2_get_directional_derivative(
    c: Fmi2Component,
    _v_unknown_ref: *const Fmi2ValueReference,
    _n_unknown: usize,
    _v_known_ref: *const Fmi2ValueReference,
    _n_known: usize,
    _dv_known: *const Fmi2Real,
    _dv_unknown: *mut Fmi2Real,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract (module doc); the arrays are not touched.
    unsafe {
        with_instance(
            c,
            "fmi2GetDirectionalDerivative",
            allowed::DIRECTIONAL_DERIVATIVE,
            |_| Err(not_provided("providesDirectionalDerivative=\"false\"")),
        )
    }
}

#[unsafe(export_name = "fmi2SetRealInputDerivatives")]
pub unsafe extern "C" fn fmi2_set_real_input_derivatives(
    c: Fmi2Component,
    _vr: *const Fmi2ValueReference,
    _nvr: usize,
    _order: *const Fmi2Integer,
    _value: *const Fmi2Real,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract (module doc); the arrays are not touched.
    unsafe {
        with_instance(
            c,
            "fmi2SetRealInputDerivatives",
            allowed::SET_INPUT_DERIVATIVES,
            |_| Err(not_provided("canInterpolateInputs=\"false\"")),
        )
    }
}

#[unsafe(export_name = "fmi2GetRealOutputDerivatives")]
pub unsafe extern "C" fn fmi2_get_real_output_derivatives(
    c: Fmi2Component,
    _vr: *const Fmi2ValueReference,
    _nvr: usize,
    _order: *const Fmi2Integer,
    _value: *mut Fmi2Real,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract (module doc); the arrays are not touched.
    unsafe {
        with_instance(
            c,
            "fmi2GetRealOutputDerivatives",
            allowed::GET_OUTPUT_DERIVATIVES,
            |_| Err(not_provided("maxOutputDerivativeOrder=\"0\"")),
        )
    }
}

// ------------------------------------------------------------------ stepping

#[unsafe(export_name = "fmi2DoStep")]
pub unsafe extern "C" fn fmi2_do_step(
    c: Fmi2Component,
    current_communication_point: Fmi2Real,
    communication_step_size: Fmi2Real,
    _no_set_fmu_state_prior_to_current_point: Fmi2Boolean,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract (module doc).
    unsafe {
        with_instance(c, "fmi2DoStep", allowed::DO_STEP, |i| {
            i.do_step(current_communication_point, communication_step_size)
        })
    }
}

#[unsafe(export_name = "fmi2CancelStep")]
pub unsafe extern "C" fn fmi2_cancel_step(c: Fmi2Component) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract (module doc).
    unsafe { with_instance(c, "fmi2CancelStep", allowed::CANCEL_STEP, |_| Ok(())) }
}

#[unsafe(export_name = "fmi2GetStatus")]
pub unsafe extern "C" fn fmi2_get_status(
    c: Fmi2Component,
    s: c_int,
    value: *mut Fmi2Status,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `value` points to a writable fmi2Status.
    unsafe {
        with_instance(c, "fmi2GetStatus", allowed::STATUS, |i| {
            let value = out_ref(value, "value")?;
            *value = i.get_status(s)?.raw();
            Ok(())
        })
    }
}

#[unsafe(export_name = "fmi2GetRealStatus")]
pub unsafe extern "C" fn fmi2_get_real_status(
    c: Fmi2Component,
    s: c_int,
    value: *mut Fmi2Real,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `value` points to a writable fmi2Real.
    unsafe {
        with_instance(c, "fmi2GetRealStatus", allowed::STATUS, |i| {
            let value = out_ref(value, "value")?;
            *value = i.get_real_status(s)?;
            Ok(())
        })
    }
}

#[unsafe(export_name = "fmi2GetIntegerStatus")]
pub unsafe extern "C" fn fmi2_get_integer_status(
    c: Fmi2Component,
    s: c_int,
    value: *mut Fmi2Integer,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `value` points to a writable fmi2Integer.
    unsafe {
        with_instance(c, "fmi2GetIntegerStatus", allowed::STATUS, |i| {
            let value = out_ref(value, "value")?;
            *value = i.get_integer_status(s)?;
            Ok(())
        })
    }
}

#[unsafe(export_name = "fmi2GetBooleanStatus")]
pub unsafe extern "C" fn fmi2_get_boolean_status(
    c: Fmi2Component,
    s: c_int,
    value: *mut Fmi2Boolean,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract; `value` points to a writable fmi2Boolean.
    unsafe {
        with_instance(c, "fmi2GetBooleanStatus", allowed::STATUS, |i| {
            let value = out_ref(value, "value")?;
            *value = if i.get_boolean_status(s)? {
                FMI2_TRUE
            } else {
                FMI2_FALSE
            };
            Ok(())
        })
    }
}

#[unsafe(export_name = "fmi2GetStringStatus")]
pub unsafe extern "C" fn fmi2_get_string_status(
    c: Fmi2Component,
    s: c_int,
    _value: *mut Fmi2String,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 caller contract (module doc); `value` is not touched.
    unsafe {
        with_instance(c, "fmi2GetStringStatus", allowed::STATUS, |i| {
            i.get_string_status(s)
        })
    }
}

// ------------------------------------------------------------------ Model Exchange stubs

/// Defines Model Exchange functions that log and return fmi2Error (this FMU is CS only).
macro_rules! model_exchange_stubs {
    ($($c_name:literal fn $name:ident($($arg:ident: $ty:ty),*);)*) => {$(
        #[unsafe(export_name = $c_name)]
        pub unsafe extern "C" fn $name(c: Fmi2Component, $($arg: $ty),*) -> Fmi2Status {
            let _ = ($($arg,)*);
            // SAFETY: FMI 2.0 caller contract (module doc); the other arguments are not touched.
            unsafe {
                with_instance(c, $c_name, allowed::ANY, |_| Err(not_provided("Model Exchange: this is a Co-Simulation FMU")))
            }
        }
    )*};
}

model_exchange_stubs! {
    "fmi2EnterEventMode" fn fmi2_enter_event_mode();
    "fmi2NewDiscreteStates" fn fmi2_new_discrete_states(event_info: *mut Fmi2EventInfo);
    "fmi2EnterContinuousTimeMode" fn fmi2_enter_continuous_time_mode();
    "fmi2CompletedIntegratorStep" fn fmi2_completed_integrator_step(
        no_set_prior: Fmi2Boolean, enter_event_mode: *mut Fmi2Boolean, terminate_simulation: *mut Fmi2Boolean);
    "fmi2SetTime" fn fmi2_set_time(time: Fmi2Real);
    "fmi2SetContinuousStates" fn fmi2_set_continuous_states(x: *const Fmi2Real, nx: usize);
    "fmi2GetDerivatives" fn fmi2_get_derivatives(derivatives: *mut Fmi2Real, nx: usize);
    "fmi2GetEventIndicators" fn fmi2_get_event_indicators(event_indicators: *mut Fmi2Real, ni: usize);
    "fmi2GetContinuousStates" fn fmi2_get_continuous_states(x: *mut Fmi2Real, nx: usize);
    "fmi2GetNominalsOfContinuousStates" fn fmi2_get_nominals_of_continuous_states(x_nominal: *mut Fmi2Real, nx: usize);
}
