//! The FMI 2.0 Co-Simulation C layer over any [`Core`]: one generic function per `fmi2*`
//! function, and [`export_fmi2!`](crate::export_fmi2) that exports all 44 of them (25 common, 9
//! Co-Simulation, 10 Model Exchange as error stubs: importers bind every symbol) for one type.
//!
//! Every function here is `unsafe` with the FMI 2.0 caller contract (§2.1): `c` is NULL or an
//! instance returned by `fmi2Instantiate` of the same library and not yet freed, calls on one
//! instance are not concurrent, arrays hold the announced number of elements, strings are
//! NUL-terminated or NULL, an FMU state is NULL or one this library returned and not yet freed.
#![allow(clippy::missing_safety_doc)] // the contract is the FMI 2.0 standard, cited above

use core::ffi::{c_char, c_int, c_uint, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};

use crate::core::{Core, Instantiation, not_supported};
use crate::ffi::{input, out_ref, output, panic_message, string, strings};
use crate::logger::{Fmi2LoggerFn, Sink};
use crate::phase::{Failure, Mask, Outcome, Phase, allowed};
use crate::status::Status;

/// `fmi2CallbackFunctions`: only valid during `fmi2Instantiate`, copied there.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct Callbacks {
    pub logger: Option<Fmi2LoggerFn>,
    pub allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    pub free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    pub step_finished: Option<unsafe extern "C" fn(*mut c_void, c_int)>,
    pub component_environment: *mut c_void,
}

/// Runs `body` on the instance behind `c` if `allowed` permits its phase: NULL check, phase
/// check, panic barrier (a panic marks the instance fatal), the failure logged, the status.
pub unsafe fn with<C: Core>(
    c: *mut c_void,
    function: &str,
    allowed: Mask,
    body: impl FnOnce(&mut C) -> Outcome,
) -> c_int {
    if c.is_null() {
        return Status::Error.raw();
    }
    // SAFETY: by the contract `c` is a live `Box<C>` from `instantiate` with no other
    // reference to it in use.
    let instance = unsafe { &mut *c.cast::<C>() };
    let phase = instance.phase();
    if !allowed.allows(phase) {
        let why = if phase == Phase::Fatal {
            " (an earlier call failed fatally: free the instance)"
        } else {
            ""
        };
        let message = format!("{function} must not be called in state {phase:?}{why}");
        instance.log(Status::Error, &message);
        return Status::Error.raw();
    }
    match catch_unwind(AssertUnwindSafe(|| body(&mut *instance))) {
        Ok(Ok(())) => Status::Ok.raw(),
        Ok(Err(Failure { status, message })) => {
            instance.log(status, &format!("{function}: {message}"));
            status.raw()
        }
        Err(payload) => {
            instance.mark_fatal();
            let message = panic_message(&*payload);
            let message = format!("{function}: internal error (panic): {message}");
            instance.log(Status::Fatal, &message);
            Status::Fatal.raw()
        }
    }
}

/// Builds an instance for [`Core::instantiate`] and returns it as an opaque pointer, or NULL
/// after logging why. `what` names the function for messages.
pub fn instantiate_with<C: Core>(
    what: &str,
    sink: &Sink,
    build: impl FnOnce() -> Result<C, String>,
) -> *mut c_void {
    match catch_unwind(AssertUnwindSafe(build)) {
        Ok(Ok(instance)) => Box::into_raw(Box::new(instance)).cast(),
        Ok(Err(message)) => {
            sink.send(
                Status::Error,
                Some("logStatusError"),
                &format!("{what}: {message}"),
            );
            std::ptr::null_mut()
        }
        Err(payload) => {
            let message = panic_message(&*payload);
            sink.send(
                Status::Fatal,
                Some("logStatusFatal"),
                &format!("{what}: internal error (panic): {message}"),
            );
            std::ptr::null_mut()
        }
    }
}

/// Drops the instance behind `c` (NULL: nothing), catching a panic of its destructor.
pub unsafe fn free_instance<C: Core>(c: *mut c_void) {
    if c.is_null() {
        return;
    }
    // SAFETY: `c` came from `Box::into_raw` in `instantiate_with` and is freed once (contract).
    let instance = unsafe { Box::from_raw(c.cast::<C>()) };
    let _ = catch_unwind(AssertUnwindSafe(move || drop(instance)));
}

/// `fmi2Instantiate`.
pub unsafe fn instantiate<C: Core>(
    name: *const c_char,
    fmu_type: c_int,
    guid: *const c_char,
    resources: *const c_char,
    functions: *const Callbacks,
    logging_on: c_int,
) -> *mut c_void {
    // SAFETY: NULL or a valid callbacks struct for this call (contract); copied, not kept.
    let callbacks = unsafe { functions.as_ref() }.copied();
    // SAFETY: NULL or NUL-terminated strings valid for this call (contract).
    let (name, guid, resources) = unsafe { (string(name), string(guid), string(resources)) };
    let instance_name = name.clone().ok().flatten().unwrap_or_default();
    let sink = match callbacks {
        Some(f) => Sink::fmi2(f.logger, f.component_environment, instance_name),
        None => Sink::None,
    };
    instantiate_with::<C>("fmi2Instantiate", &sink.clone(), || {
        let name = name.map_err(|f| f.message)?.ok_or("instanceName is NULL")?;
        if name.trim().is_empty() {
            return Err("instanceName is empty".into());
        }
        if fmu_type != 1 {
            return Err(format!(
                "fmuType = {fmu_type}: this FMU provides Co-Simulation (1) only"
            ));
        }
        C::instantiate(Instantiation {
            name,
            token: guid.map_err(|f| f.message)?,
            resources: resources.map_err(|f| f.message)?,
            sink,
            logging_on: logging_on != 0,
            fmi_version: 2,
        })
    })
}

/// `fmi2SetDebugLogging`.
pub unsafe fn set_debug_logging<C: Core>(
    c: *mut c_void,
    function: &str,
    on: bool,
    n: usize,
    categories: *const *const c_char,
) -> c_int {
    // SAFETY: contract: `categories` holds `n` strings.
    unsafe {
        with::<C>(c, function, allowed::SET_DEBUG_LOGGING, |i| {
            let names = strings(categories, n, "categories")?;
            i.set_debug_logging(on, &names)
        })
    }
}

/// `fmi2SetupExperiment`.
pub unsafe fn setup_experiment<C: Core>(
    c: *mut c_void,
    start: f64,
    stop_defined: c_int,
    stop: f64,
) -> c_int {
    let stop = (stop_defined != 0).then_some(stop);
    // SAFETY: contract (module doc).
    unsafe {
        with::<C>(c, "fmi2SetupExperiment", allowed::SETUP_EXPERIMENT, |i| {
            i.setup_experiment(start, stop)
        })
    }
}

/// A lifecycle call without arguments: `fmi2EnterInitializationMode`,
/// `fmi2ExitInitializationMode`, `fmi2Terminate`, `fmi2Reset`.
pub unsafe fn transition<C: Core>(
    c: *mut c_void,
    function: &str,
    mask: Mask,
    f: fn(&mut C) -> Outcome,
) -> c_int {
    // SAFETY: contract (module doc).
    unsafe { with::<C>(c, function, mask, f) }
}

/// `fmi2GetReal` and the other getters: `get` fills `nvr` values of type `T`.
pub unsafe fn get<C: Core, T>(
    c: *mut c_void,
    function: &str,
    vr: *const c_uint,
    nvr: usize,
    values: *mut T,
    get: fn(&mut C, &[u32], &mut [T]) -> Outcome,
) -> c_int {
    // SAFETY: contract: `vr` and `values` hold `nvr` elements.
    unsafe {
        with::<C>(c, function, allowed::GET, |i| {
            get(i, input(vr, nvr, "vr")?, output(values, nvr, "value")?)
        })
    }
}

/// `fmi2SetReal` and the other setters of plain values.
pub unsafe fn set<C: Core, T>(
    c: *mut c_void,
    function: &str,
    vr: *const c_uint,
    nvr: usize,
    values: *const T,
    set: fn(&mut C, &[u32], &[T]) -> Outcome,
) -> c_int {
    // SAFETY: contract: `vr` and `values` hold `nvr` elements.
    unsafe {
        with::<C>(c, function, allowed::SET, |i| {
            set(i, input(vr, nvr, "vr")?, input(values, nvr, "value")?)
        })
    }
}

/// `fmi2GetBoolean`: `fmi2Boolean` is a C `int`.
pub unsafe fn get_boolean<C: Core>(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    values: *mut c_int,
) -> c_int {
    // SAFETY: contract: `vr` and `values` hold `nvr` elements.
    unsafe {
        with::<C>(c, "fmi2GetBoolean", allowed::GET, |i| {
            let out = output(values, nvr, "value")?;
            let mut b = vec![false; nvr];
            i.get_boolean(input(vr, nvr, "vr")?, &mut b)?;
            out.iter_mut().zip(b).for_each(|(o, b)| *o = c_int::from(b));
            Ok(())
        })
    }
}

/// `fmi2SetBoolean`: any non-zero `int` is true.
pub unsafe fn set_boolean<C: Core>(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    values: *const c_int,
) -> c_int {
    // SAFETY: contract: `vr` and `values` hold `nvr` elements.
    unsafe {
        with::<C>(c, "fmi2SetBoolean", allowed::SET, |i| {
            let b: Vec<bool> = input(values, nvr, "value")?
                .iter()
                .map(|&v| v != 0)
                .collect();
            i.set_boolean(input(vr, nvr, "vr")?, &b)
        })
    }
}

/// `fmi2SetString`: the strings are copied.
pub unsafe fn set_string<C: Core>(
    c: *mut c_void,
    function: &str,
    vr: *const c_uint,
    nvr: usize,
    values: *const *const c_char,
) -> c_int {
    // SAFETY: contract: `vr` and `values` hold `nvr` elements, each a NUL-terminated string.
    unsafe {
        with::<C>(c, function, allowed::SET, |i| {
            i.set_string(input(vr, nvr, "vr")?, &strings(values, nvr, "value")?)
        })
    }
}

/// `fmi2DoStep`.
pub unsafe fn do_step<C: Core>(c: *mut c_void, t: f64, h: f64) -> c_int {
    // SAFETY: contract (module doc).
    unsafe { with::<C>(c, "fmi2DoStep", allowed::DO_STEP, |i| i.do_step(t, h)) }
}

/// `fmi2GetStatus`, `fmi2GetRealStatus`, `fmi2GetIntegerStatus`, `fmi2GetBooleanStatus`: the
/// value of `kind` from `get` (a [`Core`] method) written to `value`.
pub unsafe fn status<C: Core, T, V>(
    c: *mut c_void,
    function: &str,
    (kind, value): (c_int, *mut V),
    get: fn(&C, i32) -> Outcome<T>,
    to_c: fn(T) -> V,
) -> c_int {
    // SAFETY: contract: `value` is NULL or writable.
    unsafe {
        with::<C>(c, function, allowed::STATUS, |i| {
            let value = out_ref(value, "value")?;
            *value = to_c(get(i, kind)?);
            Ok(())
        })
    }
}

/// `fmi2GetStringStatus`: [`Core::get_string_status`]; `value` is not written.
pub unsafe fn get_string_status<C: Core>(c: *mut c_void, kind: c_int) -> c_int {
    // SAFETY: contract (module doc).
    unsafe {
        with::<C>(c, "fmi2GetStringStatus", allowed::STATUS, |i| {
            i.get_string_status(kind)
        })
    }
}

/// `fmi2CancelStep`: never allowed, as no step runs asynchronously (`allowed::CANCEL_STEP`).
pub unsafe fn cancel_step<C: Core>(c: *mut c_void) -> c_int {
    // SAFETY: contract (module doc).
    unsafe { with::<C>(c, "fmi2CancelStep", allowed::CANCEL_STEP, |_| Ok(())) }
}

/// `fmi2GetFMUstate`: a new state where `*state` is NULL, else `*state` overwritten.
pub unsafe fn get_fmu_state<C: Core>(
    c: *mut c_void,
    function: &str,
    state: *mut *mut c_void,
) -> c_int {
    // SAFETY: contract: `state` is NULL or points to a writable state pointer.
    unsafe {
        with::<C>(c, function, allowed::FMU_STATE, |i| {
            let slot = out_ref(state, "FMUstate")?;
            *slot = handle_pointer(i.get_fmu_state(slot.addr())?);
            Ok(())
        })
    }
}

/// `fmi2SetFMUstate`.
pub unsafe fn set_fmu_state<C: Core>(c: *mut c_void, function: &str, state: *mut c_void) -> c_int {
    // SAFETY: contract (module doc); the state pointer is only used as a key.
    unsafe {
        with::<C>(c, function, allowed::FMU_STATE, |i| {
            i.set_fmu_state(state.addr())
        })
    }
}

/// `fmi2FreeFMUstate`: `*state` set to NULL.
pub unsafe fn free_fmu_state<C: Core>(
    c: *mut c_void,
    function: &str,
    state: *mut *mut c_void,
) -> c_int {
    // SAFETY: contract: `state` is NULL or points to a writable state pointer.
    unsafe {
        with::<C>(c, function, allowed::FMU_STATE, |i| {
            let slot = out_ref(state, "FMUstate")?;
            if !slot.is_null() {
                i.free_fmu_state(slot.addr())?;
                *slot = std::ptr::null_mut();
            }
            Ok(())
        })
    }
}

/// `fmi2SerializedFMUstateSize`.
pub unsafe fn serialized_size<C: Core>(
    c: *mut c_void,
    function: &str,
    state: *mut c_void,
    n: *mut usize,
) -> c_int {
    // SAFETY: contract: `n` is NULL or writable; the state pointer is only used as a key.
    unsafe {
        with::<C>(c, function, allowed::FMU_STATE, |i| {
            let n = out_ref(n, "size")?;
            *n = i.serialize_fmu_state(state.addr())?.len();
            Ok(())
        })
    }
}

/// `fmi2SerializeFMUstate` into `n` bytes at `bytes`.
pub unsafe fn serialize<C: Core>(
    c: *mut c_void,
    function: &str,
    state: *mut c_void,
    bytes: *mut c_char,
    n: usize,
) -> c_int {
    // SAFETY: contract: `bytes` holds `n` writable bytes; the state pointer is a key.
    unsafe {
        with::<C>(c, function, allowed::FMU_STATE, |i| {
            let data = i.serialize_fmu_state(state.addr())?;
            let out = output(bytes.cast::<u8>(), n, "serializedState")?;
            if out.len() < data.len() {
                return Err(Failure::error(format!(
                    "the buffer holds {n} bytes, the state needs {} (ask fmi2SerializedFMUstateSize)",
                    data.len()
                )));
            }
            out[..data.len()].copy_from_slice(&data);
            Ok(())
        })
    }
}

/// `fmi2DeSerializeFMUstate` of `n` bytes into `*state` (a new state where NULL).
pub unsafe fn deserialize<C: Core>(
    c: *mut c_void,
    function: &str,
    bytes: *const c_char,
    n: usize,
    state: *mut *mut c_void,
) -> c_int {
    // SAFETY: contract: `bytes` holds `n` bytes, `state` a writable state pointer.
    unsafe {
        with::<C>(c, function, allowed::FMU_STATE, |i| {
            let data = input(bytes.cast::<u8>(), n, "serializedState")?;
            let slot = out_ref(state, "FMUstate")?;
            *slot = handle_pointer(i.deserialize_fmu_state(data, slot.addr())?);
            Ok(())
        })
    }
}

/// `fmi2GetDirectionalDerivative`.
pub unsafe fn directional_derivative<C: Core>(
    c: *mut c_void,
    unknowns: *const c_uint,
    n_unknown: usize,
    knowns: *const c_uint,
    n_known: usize,
    seed: *const f64,
    out: *mut f64,
) -> c_int {
    // SAFETY: contract: the arrays hold the announced numbers of elements.
    unsafe {
        with::<C>(
            c,
            "fmi2GetDirectionalDerivative",
            allowed::DIRECTIONAL_DERIVATIVE,
            |i| {
                i.directional_derivative_fmi2(
                    input(unknowns, n_unknown, "vUnknown_ref")?,
                    input(knowns, n_known, "vKnown_ref")?,
                    input(seed, n_known, "dvKnown")?,
                    output(out, n_unknown, "dvUnknown")?,
                )
            },
        )
    }
}

/// A function of a capability the FMU does not claim: logged, `fmi2Error`.
pub unsafe fn refused<C: Core>(c: *mut c_void, function: &str) -> c_int {
    // SAFETY: contract (module doc).
    unsafe { with::<C>(c, function, allowed::ANY, |_| Err(not_supported(function))) }
}

/// A Model Exchange function: logged, `fmi2Error` (the FMUs are Co-Simulation FMUs).
pub unsafe fn model_exchange<C: Core>(c: *mut c_void, function: &str) -> c_int {
    // SAFETY: contract (module doc).
    unsafe {
        with::<C>(c, function, allowed::ANY, |_| {
            Err(Failure::error(
                "not provided by this FMU (Model Exchange: this is a Co-Simulation FMU)",
            ))
        })
    }
}

/// The opaque `fmi2FMUstate` of a saved-state handle: never dereferenced, the instance looks
/// handles up in its own table.
pub fn handle_pointer(handle: usize) -> *mut c_void {
    std::ptr::without_provenance_mut(handle)
}

/// Exports the 44 FMI 2.0 functions for the [`Core`] type `$core` (in the crate that names the
/// cdylib). Each is a one-line delegation to the generic function of [`crate::fmi2`].
#[macro_export]
macro_rules! export_fmi2 {
    ($core:ty) => {
        /// The FMI 2.0 functions of this FMU, made by `fmi_glue::export_fmi2!`.
        #[allow(clippy::missing_safety_doc)]
        pub mod fmi2_exports {
            use super::*;
            use ::core::ffi::{c_char, c_int, c_uint, c_void};
            use $crate::fmi2 as g;
            use $crate::core::Core;
            use $crate::phase::allowed;
            type C = $core;

            #[unsafe(export_name = "fmi2GetTypesPlatform")]
            pub extern "C" fn get_types_platform() -> *const c_char {
                c"default".as_ptr()
            }
            #[unsafe(export_name = "fmi2GetVersion")]
            pub extern "C" fn get_version() -> *const c_char {
                c"2.0".as_ptr()
            }
            $crate::export_fmi2!(@forward
                "fmi2Instantiate" instantiate(name: *const c_char, kind: c_int, guid: *const c_char, res: *const c_char, f: *const g::Callbacks, _visible: c_int, on: c_int) -> *mut c_void
                    = g::instantiate::<C>(name, kind, guid, res, f, on);
                "fmi2FreeInstance" free_instance(c: *mut c_void) -> () = g::free_instance::<C>(c);
                "fmi2SetDebugLogging" set_debug_logging(c: *mut c_void, on: c_int, n: usize, cats: *const *const c_char) -> c_int
                    = g::set_debug_logging::<C>(c, "fmi2SetDebugLogging", on != 0, n, cats);
                "fmi2SetupExperiment" setup_experiment(c: *mut c_void, _td: c_int, _tol: f64, start: f64, sd: c_int, stop: f64) -> c_int
                    = g::setup_experiment::<C>(c, start, sd, stop);
                "fmi2EnterInitializationMode" enter_initialization_mode(c: *mut c_void) -> c_int
                    = g::transition::<C>(c, "fmi2EnterInitializationMode", allowed::ENTER_INITIALIZATION, <C as Core>::enter_initialization_mode);
                "fmi2ExitInitializationMode" exit_initialization_mode(c: *mut c_void) -> c_int
                    = g::transition::<C>(c, "fmi2ExitInitializationMode", allowed::EXIT_INITIALIZATION, <C as Core>::exit_initialization_mode);
                "fmi2Terminate" terminate(c: *mut c_void) -> c_int
                    = g::transition::<C>(c, "fmi2Terminate", allowed::TERMINATE, <C as Core>::terminate);
                "fmi2Reset" reset(c: *mut c_void) -> c_int = g::transition::<C>(c, "fmi2Reset", allowed::RESET, <C as Core>::reset);
                "fmi2GetReal" get_real(c: *mut c_void, vr: *const c_uint, n: usize, v: *mut f64) -> c_int
                    = g::get::<C, f64>(c, "fmi2GetReal", vr, n, v, <C as Core>::get_real);
                "fmi2GetInteger" get_integer(c: *mut c_void, vr: *const c_uint, n: usize, v: *mut c_int) -> c_int
                    = g::get::<C, i32>(c, "fmi2GetInteger", vr, n, v, <C as Core>::get_integer);
                "fmi2GetBoolean" get_boolean(c: *mut c_void, vr: *const c_uint, n: usize, v: *mut c_int) -> c_int
                    = g::get_boolean::<C>(c, vr, n, v);
                "fmi2GetString" get_string(c: *mut c_void, vr: *const c_uint, n: usize, v: *mut *const c_char) -> c_int
                    = g::get::<C, *const c_char>(c, "fmi2GetString", vr, n, v, <C as Core>::get_string);
                "fmi2SetReal" set_real(c: *mut c_void, vr: *const c_uint, n: usize, v: *const f64) -> c_int
                    = g::set::<C, f64>(c, "fmi2SetReal", vr, n, v, <C as Core>::set_real);
                "fmi2SetInteger" set_integer(c: *mut c_void, vr: *const c_uint, n: usize, v: *const c_int) -> c_int
                    = g::set::<C, i32>(c, "fmi2SetInteger", vr, n, v, <C as Core>::set_integer);
                "fmi2SetBoolean" set_boolean(c: *mut c_void, vr: *const c_uint, n: usize, v: *const c_int) -> c_int
                    = g::set_boolean::<C>(c, vr, n, v);
                "fmi2SetString" set_string(c: *mut c_void, vr: *const c_uint, n: usize, v: *const *const c_char) -> c_int
                    = g::set_string::<C>(c, "fmi2SetString", vr, n, v);
                "fmi2GetFMUstate" get_fmu_state(c: *mut c_void, s: *mut *mut c_void) -> c_int = g::get_fmu_state::<C>(c, "fmi2GetFMUstate", s);
                "fmi2SetFMUstate" set_fmu_state(c: *mut c_void, s: *mut c_void) -> c_int = g::set_fmu_state::<C>(c, "fmi2SetFMUstate", s);
                "fmi2FreeFMUstate" free_fmu_state(c: *mut c_void, s: *mut *mut c_void) -> c_int = g::free_fmu_state::<C>(c, "fmi2FreeFMUstate", s);
                "fmi2GetDirectionalDerivative" get_directional_derivative(c: *mut c_void, u: *const c_uint, nu: usize, k: *const c_uint, nk: usize, dk: *const f64, du: *mut f64) -> c_int
                    = g::directional_derivative::<C>(c, u, nu, k, nk, dk, du);
                "fmi2SerializedFMUstateSize" serialized_size(c: *mut c_void, s: *mut c_void, n: *mut usize) -> c_int
                    = g::serialized_size::<C>(c, "fmi2SerializedFMUstateSize", s, n);
                "fmi2SerializeFMUstate" serialize(c: *mut c_void, s: *mut c_void, b: *mut c_char, n: usize) -> c_int
                    = g::serialize::<C>(c, "fmi2SerializeFMUstate", s, b, n);
                "fmi2DeSerializeFMUstate" deserialize(c: *mut c_void, b: *const c_char, n: usize, s: *mut *mut c_void) -> c_int
                    = g::deserialize::<C>(c, "fmi2DeSerializeFMUstate", b, n, s);
                "fmi2DoStep" do_step(c: *mut c_void, t: f64, h: f64, _no_prior: c_int) -> c_int = g::do_step::<C>(c, t, h);
                "fmi2CancelStep" cancel_step(c: *mut c_void) -> c_int = g::cancel_step::<C>(c);
                "fmi2GetStatus" get_status(c: *mut c_void, k: c_int, v: *mut c_int) -> c_int
                    = g::status::<C, _, _>(c, "fmi2GetStatus", (k, v), <C as Core>::get_status, |s| s.raw());
                "fmi2GetRealStatus" get_real_status(c: *mut c_void, k: c_int, v: *mut f64) -> c_int
                    = g::status::<C, _, _>(c, "fmi2GetRealStatus", (k, v), <C as Core>::get_real_status, |x| x);
                "fmi2GetIntegerStatus" get_integer_status(c: *mut c_void, k: c_int, v: *mut c_int) -> c_int
                    = g::status::<C, _, _>(c, "fmi2GetIntegerStatus", (k, v), <C as Core>::get_integer_status, |x| x);
                "fmi2GetBooleanStatus" get_boolean_status(c: *mut c_void, k: c_int, v: *mut c_int) -> c_int
                    = g::status::<C, _, _>(c, "fmi2GetBooleanStatus", (k, v), <C as Core>::get_boolean_status, c_int::from);
                "fmi2GetStringStatus" get_string_status(c: *mut c_void, k: c_int, _v: *mut *const c_char) -> c_int
                    = g::get_string_status::<C>(c, k);
            );
            $crate::export_fmi2!(@refused
                "fmi2SetRealInputDerivatives" set_input_derivatives(_r: *const c_uint, _n: usize, _o: *const c_int, _v: *const f64);
                "fmi2GetRealOutputDerivatives" get_output_derivatives(_r: *const c_uint, _n: usize, _o: *const c_int, _v: *mut f64);
            );
            $crate::export_fmi2!(@model_exchange
                "fmi2EnterEventMode" enter_event_mode();
                "fmi2NewDiscreteStates" new_discrete_states(_info: *mut c_void);
                "fmi2EnterContinuousTimeMode" enter_continuous_time_mode();
                "fmi2CompletedIntegratorStep" completed_integrator_step(_a: c_int, _b: *mut c_int, _d: *mut c_int);
                "fmi2SetTime" set_time(_t: f64);
                "fmi2SetContinuousStates" set_continuous_states(_x: *const f64, _n: usize);
                "fmi2GetDerivatives" get_derivatives(_x: *mut f64, _n: usize);
                "fmi2GetEventIndicators" get_event_indicators(_x: *mut f64, _n: usize);
                "fmi2GetContinuousStates" get_continuous_states(_x: *mut f64, _n: usize);
                "fmi2GetNominalsOfContinuousStates" get_nominals(_x: *mut f64, _n: usize);
            );
        }
    };
    (@forward $($export:literal $name:ident($($arg:ident: $ty:ty),*) -> $ret:ty = $call:expr;)*) => {$(
        #[unsafe(export_name = $export)]
        pub unsafe extern "C" fn $name($($arg: $ty),*) -> $ret {
            // SAFETY: the FMI 2.0 caller contract (`fmi_glue::fmi2`'s module doc) is the one
            // the generic function requires; the arguments are passed on unchanged.
            unsafe { $call }
        }
    )*};
    (@model_exchange $($export:literal $name:ident($($arg:ident: $ty:ty),*);)*) => {$(
        #[unsafe(export_name = $export)]
        pub unsafe extern "C" fn $name(c: *mut c_void $(, $arg: $ty)*) -> c_int {
            // SAFETY: the FMI 2.0 caller contract: `c` is NULL or a live instance; no other
            // argument is read.
            unsafe { $crate::fmi2::model_exchange::<C>(c, $export) }
        }
    )*};
    (@refused $($export:literal $name:ident($($arg:ident: $ty:ty),*);)*) => {$(
        #[unsafe(export_name = $export)]
        pub unsafe extern "C" fn $name(c: *mut c_void $(, $arg: $ty)*) -> c_int {
            // SAFETY: the FMI 2.0 caller contract: `c` is NULL or a live instance; no other
            // argument is read.
            unsafe { $crate::fmi2::refused::<C>(c, $export) }
        }
    )*};
}
