//! The FMI 2.0 Co-Simulation functions of the jack (the 25 common ones, the 9 of
//! Co-Simulation, the 10 of Model Exchange as error stubs: importers bind every symbol).
//!
//! Every `unsafe` block relies on the FMI 2.0 caller contract (§2.1): a component is NULL or a
//! pointer returned by `fmi2Instantiate` and not yet freed, calls on one instance are not
//! concurrent, arrays hold the announced number of elements, strings are NUL-terminated, an FMU
//! state is NULL or one returned by `fmi2GetFMUstate` of this library and not yet freed.
//! Panics are caught at each entry point (`catch_unwind`) and become `fmi2Fatal`.
#![allow(clippy::missing_safety_doc)] // the contract is the FMI 2.0 standard, cited above

use core::ffi::{c_char, c_int, c_uint, c_void};
use std::ffi::{CStr, CString};
use std::panic::{AssertUnwindSafe, catch_unwind};

use crate::{GUID, Jack, NAMES, check_value, vr};

type Status = c_int;
const OK: Status = 0;
const ERROR: Status = 3;
const FATAL: Status = 4;
const DISCARD: Status = 2;

type Logger =
    unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char, ...);

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct Callbacks {
    logger: Option<Logger>,
    allocate: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    free: Option<unsafe extern "C" fn(*mut c_void)>,
    step_finished: Option<unsafe extern "C" fn(*mut c_void, Status)>,
    environment: *mut c_void,
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Phase {
    Instantiated,
    Initialization,
    Stepping,
    Terminated,
}

struct Instance {
    name: CString,
    logger: Option<Logger>,
    environment: *mut c_void,
    phase: Phase,
    jack: Jack,
}

impl Instance {
    fn log(&self, status: Status, message: &str) {
        let category = if status == DISCARD {
            c"logStatusDiscard"
        } else {
            c"logStatusError"
        };
        if let Some(logger) = self.logger {
            let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
            // SAFETY: the importer's logger, called with a "%s" format and one NUL-terminated
            // string (never user text as the format), and its own environment pointer.
            unsafe {
                logger(
                    self.environment,
                    self.name.as_ptr(),
                    status,
                    category.as_ptr(),
                    c"%s".as_ptr(),
                    text.as_ptr(),
                )
            };
        }
    }

    fn fail(&self, function: &str, message: &str) -> Status {
        self.log(ERROR, &format!("{function}: {message}"));
        ERROR
    }

    /// fmi2Discard with the message logged: the call did nothing, the instance can go on (FMI
    /// 2.0 §4.2.2: a step the FMU cannot take, the master may retry it otherwise).
    fn discard(&self, function: &str, message: &str) -> Status {
        self.log(DISCARD, &format!("{function}: {message}"));
        DISCARD
    }
}

/// Runs `f` on the instance behind `c`, catching panics; NULL gives fmi2Error.
unsafe fn with(c: *mut c_void, f: impl FnOnce(&mut Instance) -> Status) -> Status {
    if c.is_null() {
        return ERROR;
    }
    // SAFETY: caller contract (module doc): `c` came from `fmi2Instantiate` (a leaked
    // `Box<Instance>`) and no other call on it runs concurrently.
    let instance = unsafe { &mut *(c as *mut Instance) };
    catch_unwind(AssertUnwindSafe(|| f(instance))).unwrap_or(FATAL)
}

/// `n` elements at `p` (an empty slice for `n == 0`); None for NULL with `n > 0`.
unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        Some(&[])
    } else if p.is_null() {
        None
    } else {
        // SAFETY: caller contract: `p` holds `n` elements.
        Some(unsafe { std::slice::from_raw_parts(p, n) })
    }
}

unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        Some(&mut [])
    } else if p.is_null() {
        None
    } else {
        // SAFETY: caller contract: `p` holds `n` writable elements.
        Some(unsafe { std::slice::from_raw_parts_mut(p, n) })
    }
}

#[unsafe(export_name = "fmi2GetTypesPlatform")]
pub extern "C" fn get_types_platform() -> *const c_char {
    c"default".as_ptr()
}

#[unsafe(export_name = "fmi2GetVersion")]
pub extern "C" fn get_version() -> *const c_char {
    c"2.0".as_ptr()
}

#[unsafe(export_name = "fmi2Instantiate")]
pub unsafe extern "C" fn instantiate(
    name: *const c_char,
    fmu_type: c_int,
    guid: *const c_char,
    _resources: *const c_char,
    functions: *const Callbacks,
    _visible: c_int,
    _logging_on: c_int,
) -> *mut c_void {
    catch_unwind(|| {
        // SAFETY: caller contract: `functions` is NULL or points to a callback struct (copied
        // here, the pointer is not kept); the strings are NUL-terminated or NULL.
        let (logger, environment) = match unsafe { functions.as_ref() } {
            Some(f) => (f.logger, f.environment),
            None => (None, std::ptr::null_mut()),
        };
        let text = |p: *const c_char| {
            // SAFETY: as above.
            (!p.is_null()).then(|| unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
        };
        let instance_name = text(name).unwrap_or_default();
        let instance = Instance {
            name: CString::new(instance_name.clone()).unwrap_or_default(),
            logger,
            environment,
            phase: Phase::Instantiated,
            jack: Jack::default(),
        };
        let refusal = if instance_name.trim().is_empty() {
            Some("fmi2Instantiate: the instance name is empty".to_string())
        } else if fmu_type != 1 {
            Some(format!(
                "fmi2Instantiate: fmuType {fmu_type}: this FMU is Co-Simulation only (1)"
            ))
        } else if text(guid).as_deref() != Some(GUID) {
            Some(format!(
                "fmi2Instantiate: GUID {:?} is not this FMU's {GUID}",
                text(guid)
            ))
        } else {
            None
        };
        match refusal {
            Some(m) => {
                instance.log(ERROR, &m);
                std::ptr::null_mut()
            }
            None => Box::into_raw(Box::new(instance)) as *mut c_void,
        }
    })
    .unwrap_or(std::ptr::null_mut())
}

#[unsafe(export_name = "fmi2FreeInstance")]
pub unsafe extern "C" fn free_instance(c: *mut c_void) {
    if !c.is_null() {
        // SAFETY: caller contract: `c` came from `fmi2Instantiate` (Box::into_raw) and is
        // freed once.
        drop(unsafe { Box::from_raw(c as *mut Instance) });
    }
}

#[unsafe(export_name = "fmi2SetDebugLogging")]
pub unsafe extern "C" fn set_debug_logging(
    c: *mut c_void,
    _on: c_int,
    _n: usize,
    _cats: *const *const c_char,
) -> Status {
    // SAFETY: caller contract (module doc).
    unsafe { with(c, |_| OK) }
}

#[unsafe(export_name = "fmi2SetupExperiment")]
pub unsafe extern "C" fn setup_experiment(
    c: *mut c_void,
    _tol_defined: c_int,
    _tol: f64,
    start: f64,
    _stop_defined: c_int,
    _stop: f64,
) -> Status {
    // SAFETY: caller contract (module doc).
    unsafe {
        with(c, |i| {
            if i.phase != Phase::Instantiated {
                return i.fail("fmi2SetupExperiment", "only allowed after fmi2Instantiate");
            }
            if !start.is_finite() {
                return i.fail(
                    "fmi2SetupExperiment",
                    &format!("startTime = {start} must be finite"),
                );
            }
            i.jack.time = start;
            OK
        })
    }
}

#[unsafe(export_name = "fmi2EnterInitializationMode")]
pub unsafe extern "C" fn enter_initialization_mode(c: *mut c_void) -> Status {
    // SAFETY: caller contract (module doc).
    unsafe {
        with(c, |i| {
            if i.phase != Phase::Instantiated {
                return i.fail(
                    "fmi2EnterInitializationMode",
                    "only allowed after fmi2Instantiate",
                );
            }
            if let Err(m) = i.jack.initialize() {
                return i.fail("fmi2EnterInitializationMode", &m);
            }
            i.phase = Phase::Initialization;
            OK
        })
    }
}

#[unsafe(export_name = "fmi2ExitInitializationMode")]
pub unsafe extern "C" fn exit_initialization_mode(c: *mut c_void) -> Status {
    // SAFETY: caller contract (module doc).
    unsafe {
        with(c, |i| {
            if i.phase != Phase::Initialization {
                return i.fail("fmi2ExitInitializationMode", "not in initialization mode");
            }
            if let Err(m) = i.jack.initialize() {
                return i.fail("fmi2ExitInitializationMode", &m);
            }
            i.phase = Phase::Stepping;
            OK
        })
    }
}

#[unsafe(export_name = "fmi2Terminate")]
pub unsafe extern "C" fn terminate(c: *mut c_void) -> Status {
    // SAFETY: caller contract (module doc).
    unsafe {
        with(c, |i| {
            i.phase = Phase::Terminated;
            OK
        })
    }
}

#[unsafe(export_name = "fmi2Reset")]
pub unsafe extern "C" fn reset(c: *mut c_void) -> Status {
    // SAFETY: caller contract (module doc).
    unsafe {
        with(c, |i| {
            i.jack = Jack::default();
            i.phase = Phase::Instantiated;
            OK
        })
    }
}

#[unsafe(export_name = "fmi2GetReal")]
pub unsafe extern "C" fn get_real(
    c: *mut c_void,
    refs: *const c_uint,
    n: usize,
    values: *mut f64,
) -> Status {
    // SAFETY: caller contract (module doc): `refs` and `values` hold `n` elements.
    unsafe {
        with(c, |i| {
            let (Some(refs), Some(values)) = (slice(refs, n), slice_mut(values, n)) else {
                return i.fail("fmi2GetReal", "NULL array");
            };
            for (r, v) in refs.iter().zip(values.iter_mut()) {
                match i.jack.values.get(*r as usize) {
                    Some(x) => *v = *x,
                    None => return i.fail("fmi2GetReal", &format!("unknown value reference {r}")),
                }
            }
            OK
        })
    }
}

#[unsafe(export_name = "fmi2SetReal")]
pub unsafe extern "C" fn set_real(
    c: *mut c_void,
    refs: *const c_uint,
    n: usize,
    values: *const f64,
) -> Status {
    // SAFETY: caller contract (module doc): `refs` and `values` hold `n` elements.
    unsafe {
        with(c, |i| {
            let (Some(refs), Some(values)) = (slice(refs, n), slice(values, n)) else {
                return i.fail("fmi2SetReal", "NULL array");
            };
            // All or nothing: check every value first.
            for (&r, &v) in refs.iter().zip(values) {
                if r >= vr::DZ && (r as usize) < vr::COUNT {
                    return i.fail(
                        "fmi2SetReal",
                        &format!("{} is an output", NAMES[r as usize]),
                    );
                }
                if (vr::CRACK..=vr::STROKE).contains(&r) && i.phase == Phase::Stepping {
                    return i.fail(
                        "fmi2SetReal",
                        &format!(
                            "{} is a fixed parameter: set it before fmi2ExitInitializationMode",
                            NAMES[r as usize]
                        ),
                    );
                }
                if let Err(m) = check_value(r, v) {
                    return i.fail("fmi2SetReal", &m);
                }
            }
            let mut next = i.jack;
            for (&r, &v) in refs.iter().zip(values) {
                next.values[r as usize] = v;
            }
            // In initialization mode the outputs follow the inputs at once: values whose outputs
            // overflow (force / stiffness) are refused as a whole, the jack unchanged.
            if i.phase == Phase::Initialization
                && let Err(m) = next.initialize()
            {
                return i.fail("fmi2SetReal", &m);
            }
            i.jack = next;
            OK
        })
    }
}

#[unsafe(export_name = "fmi2DoStep")]
pub unsafe extern "C" fn do_step(c: *mut c_void, t: f64, h: f64, _no_prior: c_int) -> Status {
    // SAFETY: caller contract (module doc).
    unsafe {
        with(c, |i| {
            if i.phase != Phase::Stepping {
                return i.fail(
                    "fmi2DoStep",
                    "only allowed after fmi2ExitInitializationMode",
                );
            }
            if !(h > 0.0 && h.is_finite()) {
                return i.fail(
                    "fmi2DoStep",
                    &format!("communicationStepSize = {h} must be > 0"),
                );
            }
            if (t - i.jack.time).abs() > 1e-9 * t.abs().max(1.0) {
                return i.fail(
                    "fmi2DoStep",
                    &format!(
                        "currentCommunicationPoint = {t} is not the FMU's time {}",
                        i.jack.time
                    ),
                );
            }
            // A step whose outputs would overflow is discarded: the jack keeps its last good
            // state (never fmi2OK with a value that is not finite).
            match i.jack.step(h) {
                Ok(()) => OK,
                Err(m) => i.discard("fmi2DoStep", &m),
            }
        })
    }
}

#[unsafe(export_name = "fmi2GetDirectionalDerivative")]
pub unsafe extern "C" fn get_directional_derivative(
    c: *mut c_void,
    unknowns: *const c_uint,
    n_unknown: usize,
    knowns: *const c_uint,
    n_known: usize,
    dv_known: *const f64,
    dv_unknown: *mut f64,
) -> Status {
    // SAFETY: caller contract (module doc): the arrays hold the announced number of elements.
    unsafe {
        with(c, |i| {
            const F: &str = "fmi2GetDirectionalDerivative";
            if !matches!(i.phase, Phase::Initialization | Phase::Stepping) {
                return i.fail(
                    F,
                    "only allowed in initialization mode or after it (before fmi2Terminate)",
                );
            }
            let (Some(unknowns), Some(knowns), Some(seed), Some(out)) = (
                slice(unknowns, n_unknown),
                slice(knowns, n_known),
                slice(dv_known, n_known),
                slice_mut(dv_unknown, n_unknown),
            ) else {
                return i.fail(F, "NULL array");
            };
            let name = |r: u32| {
                NAMES
                    .get(r as usize)
                    .map_or(format!("value reference {r}"), |n| {
                        format!("{n} (value reference {r})")
                    })
            };
            let mut result = vec![0.0; unknowns.len()];
            for (k, &u) in unknowns.iter().enumerate() {
                for (&kn, &s) in knowns.iter().zip(seed) {
                    if !s.is_finite() {
                        return i.fail(
                            F,
                            &format!("seed of {} = {s}: values must be finite", name(kn)),
                        );
                    }
                    match i.jack.derivative(u, kn) {
                        Some(d) => result[k] += d * s,
                        None if !(vr::DZ..=vr::SPEED).contains(&u) => {
                            return i.fail(F, &format!("unknown {} is not an output", name(u)));
                        }
                        None => return i.fail(F, &format!("known {} is not an input", name(kn))),
                    }
                }
            }
            if let Some((k, d)) = result.iter().enumerate().find(|(_, d)| !d.is_finite()) {
                return i.fail(
                    F,
                    &format!(
                        "the derivative of {} overflows ({}): scale the seed down",
                        name(unknowns[k]),
                        crate::short(*d)
                    ),
                );
            }
            out.copy_from_slice(&result);
            OK
        })
    }
}

#[unsafe(export_name = "fmi2GetFMUstate")]
pub unsafe extern "C" fn get_fmu_state(c: *mut c_void, state: *mut *mut c_void) -> Status {
    // SAFETY: caller contract (module doc); `state` points to a writable pointer that is NULL
    // or a state of this library.
    unsafe {
        with(c, |i| {
            if state.is_null() {
                return i.fail("fmi2GetFMUstate", "NULL state pointer");
            }
            let saved = (i.jack, i.phase);
            if (*state).is_null() {
                *state = Box::into_raw(Box::new(saved)) as *mut c_void;
            } else {
                *(*state as *mut (Jack, Phase)) = saved;
            }
            OK
        })
    }
}

#[unsafe(export_name = "fmi2SetFMUstate")]
pub unsafe extern "C" fn set_fmu_state(c: *mut c_void, state: *mut c_void) -> Status {
    // SAFETY: caller contract (module doc): `state` came from fmi2GetFMUstate of this library.
    unsafe {
        with(c, |i| {
            if state.is_null() {
                return i.fail("fmi2SetFMUstate", "NULL state");
            }
            (i.jack, i.phase) = *(state as *const (Jack, Phase));
            OK
        })
    }
}

#[unsafe(export_name = "fmi2FreeFMUstate")]
pub unsafe extern "C" fn free_fmu_state(c: *mut c_void, state: *mut *mut c_void) -> Status {
    // SAFETY: caller contract (module doc): `*state` is NULL or came from fmi2GetFMUstate of
    // this library and is freed once.
    unsafe {
        with(c, |i| {
            if state.is_null() {
                return i.fail("fmi2FreeFMUstate", "NULL state pointer");
            }
            if !(*state).is_null() {
                drop(Box::from_raw(*state as *mut (Jack, Phase)));
                *state = std::ptr::null_mut();
            }
            OK
        })
    }
}

#[unsafe(export_name = "fmi2GetRealStatus")]
pub unsafe extern "C" fn get_real_status(c: *mut c_void, kind: c_int, value: *mut f64) -> Status {
    // SAFETY: caller contract (module doc); `value` is writable.
    unsafe {
        with(c, |i| {
            if kind == 2 && !value.is_null() {
                *value = i.jack.time; // fmi2LastSuccessfulTime
                OK
            } else {
                DISCARD
            }
        })
    }
}

#[unsafe(export_name = "fmi2GetBooleanStatus")]
pub unsafe extern "C" fn get_boolean_status(
    c: *mut c_void,
    kind: c_int,
    value: *mut c_int,
) -> Status {
    // SAFETY: caller contract (module doc); `value` is writable.
    unsafe {
        with(c, |_| {
            if kind == 3 && !value.is_null() {
                *value = 0; // fmi2Terminated: never asks to stop
                OK
            } else {
                DISCARD
            }
        })
    }
}

/// Getters and setters of the types the jack has no variables of: nothing to do for an empty
/// list (libcosim asks for every type), fmi2Error naming the reference otherwise.
macro_rules! no_variables {
    ($($export:literal fn $name:ident($v:ty);)*) => {$(
        #[unsafe(export_name = $export)]
        pub unsafe extern "C" fn $name(c: *mut c_void, refs: *const c_uint, n: usize, _values: $v) -> Status {
            // SAFETY: caller contract (module doc): `refs` holds `n` elements.
            unsafe {
                with(c, |i| match slice(refs, n) {
                    Some([]) => OK,
                    Some([r, ..]) => i.fail($export, &format!("unknown value reference {r} (the jack has Real variables only)")),
                    None => i.fail($export, "NULL array"),
                })
            }
        }
    )*};
}

no_variables! {
    "fmi2GetInteger" fn get_integer(*mut c_int);
    "fmi2SetInteger" fn set_integer(*const c_int);
    "fmi2GetBoolean" fn get_boolean(*mut c_int);
    "fmi2SetBoolean" fn set_boolean(*const c_int);
    "fmi2GetString" fn get_string(*mut *const c_char);
    "fmi2SetString" fn set_string(*const *const c_char);
}

/// Functions of capabilities this FMU does not claim: they log and return fmi2Error.
macro_rules! refused {
    ($($export:literal fn $name:ident($($arg:ident: $ty:ty),*);)*) => {$(
        #[unsafe(export_name = $export)]
        pub unsafe extern "C" fn $name(c: *mut c_void $(, $arg: $ty)*) -> Status {
            $(let _ = $arg;)*
            // SAFETY: caller contract (module doc).
            unsafe { with(c, |i| i.fail($export, "not supported by this FMU")) }
        }
    )*};
}

refused! {
    "fmi2SerializedFMUstateSize" fn serialized_size(s: *mut c_void, n: *mut usize);
    "fmi2SerializeFMUstate" fn serialize(s: *mut c_void, b: *mut c_char, n: usize);
    "fmi2DeSerializeFMUstate" fn deserialize(b: *const c_char, n: usize, s: *mut *mut c_void);
    "fmi2SetRealInputDerivatives" fn set_input_derivatives(r: *const c_uint, n: usize, o: *const c_int, v: *const f64);
    "fmi2GetRealOutputDerivatives" fn get_output_derivatives(r: *const c_uint, n: usize, o: *const c_int, v: *mut f64);
    "fmi2CancelStep" fn cancel_step();
    "fmi2GetStatus" fn get_status(k: c_int, v: *mut c_int);
    "fmi2GetIntegerStatus" fn get_integer_status(k: c_int, v: *mut c_int);
    "fmi2GetStringStatus" fn get_string_status(k: c_int, v: *mut *const c_char);
    "fmi2EnterEventMode" fn enter_event_mode();
    "fmi2NewDiscreteStates" fn new_discrete_states(info: *mut c_void);
    "fmi2EnterContinuousTimeMode" fn enter_continuous_time_mode();
    "fmi2CompletedIntegratorStep" fn completed_integrator_step(a: c_int, b: *mut c_int, d: *mut c_int);
    "fmi2SetTime" fn set_time(t: f64);
    "fmi2SetContinuousStates" fn set_continuous_states(x: *const f64, n: usize);
    "fmi2GetDerivatives" fn get_derivatives(x: *mut f64, n: usize);
    "fmi2GetEventIndicators" fn get_event_indicators(x: *mut f64, n: usize);
    "fmi2GetContinuousStates" fn get_continuous_states(x: *mut f64, n: usize);
    "fmi2GetNominalsOfContinuousStates" fn get_nominals(x: *mut f64, n: usize);
}

#[cfg(test)]
mod tests {
    //! The FMI layer as an importer calls it, without a logger (the messages are the model's,
    //! tested in `lib.rs`; tests/python/test_never_ok_with_nan.py reads them through a logger).
    use super::*;
    use crate::START;

    /// An instance past fmi2ExitInitializationMode with `inputs` set in initialization mode.
    fn stepping(inputs: &[(u32, f64)]) -> *mut c_void {
        let guid = CString::new(GUID).unwrap();
        // SAFETY: NUL-terminated strings and no callbacks (NULL), as the FMI 2.0 contract allows.
        let c = unsafe {
            instantiate(
                c"jack".as_ptr(),
                1,
                guid.as_ptr(),
                std::ptr::null(),
                std::ptr::null(),
                0,
                0,
            )
        };
        assert!(!c.is_null());
        // SAFETY: `c` is a live instance; the arrays hold the announced number of elements.
        unsafe {
            assert_eq!(setup_experiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
            assert_eq!(enter_initialization_mode(c), OK);
            for &(r, v) in inputs {
                assert_eq!(set_real(c, &r, 1, &v), OK);
            }
            assert_eq!(exit_initialization_mode(c), OK);
        }
        c
    }

    /// The value of `r` (fmi2GetReal).
    fn get(c: *mut c_void, r: u32) -> f64 {
        let mut v = f64::NAN;
        // SAFETY: `c` is a live instance; one reference, one value.
        assert_eq!(unsafe { get_real(c, &r, 1, &mut v) }, OK);
        v
    }

    #[test]
    fn a_step_to_an_infinite_output_is_discarded_and_the_jack_steps_on_from_its_last_state() {
        let c = stepping(&[(vr::STIFFNESS, 1e-10)]);
        // SAFETY: `c` is a live instance; one reference, one value per call.
        unsafe {
            assert_eq!(set_real(c, &vr::FORCE, 1, &-1e-9), OK);
            assert_eq!(do_step(c, 0.0, 1.0, 1), OK);
            let before: Vec<f64> = (vr::DZ..=vr::SPEED).map(|r| get(c, r)).collect();
            assert!(before.iter().all(|v| v.is_finite()));
            // The case: force / stiffness = 1e318 overflows to dz = -inf.
            assert_eq!(set_real(c, &vr::FORCE, 1, &1e308), OK);
            assert_eq!(do_step(c, 1.0, 1.0, 1), DISCARD);
            let after: Vec<f64> = (vr::DZ..=vr::SPEED).map(|r| get(c, r)).collect();
            assert_eq!(after, before, "the last good outputs stay");
            let mut last = f64::NAN;
            assert_eq!(get_real_status(c, 2, &mut last), OK);
            assert_eq!(
                last, 1.0,
                "fmi2LastSuccessfulTime: the discarded step did not count"
            );
            // A sensible force: the same step is taken from the same state.
            assert_eq!(set_real(c, &vr::FORCE, 1, &-1e-9), OK);
            assert_eq!(do_step(c, 1.0, 1.0, 1), OK);
            assert!(get(c, vr::DZ).is_finite());
            free_instance(c);
        }
    }

    #[test]
    fn inputs_whose_outputs_overflow_in_initialization_are_refused_whole() {
        let guid = CString::new(GUID).unwrap();
        // SAFETY: as in `stepping`; then `c` is a live instance, arrays of the announced sizes.
        unsafe {
            let c = instantiate(
                c"jack".as_ptr(),
                1,
                guid.as_ptr(),
                std::ptr::null(),
                std::ptr::null(),
                0,
                0,
            );
            assert_eq!(enter_initialization_mode(c), OK);
            let (refs, values) = ([vr::STIFFNESS, vr::FORCE], [1e-10, 1e308]);
            assert_eq!(set_real(c, refs.as_ptr(), 2, values.as_ptr()), ERROR);
            assert_eq!(get(c, vr::STIFFNESS), START[vr::STIFFNESS as usize]);
            assert_eq!(get(c, vr::DZ), 0.0);
            // Non-finite and out-of-range values are refused before anything is set.
            for (r, v) in [
                (vr::FORCE, f64::NAN),
                (vr::STIFFNESS, f64::INFINITY),
                (vr::STIFFNESS, 0.0),
                (vr::RELIEF, -1.0),
                (vr::CRACK, 1.0),
                (vr::STROKE, -1e-300),
            ] {
                assert_eq!(set_real(c, &r, 1, &v), ERROR, "{} = {v}", NAMES[r as usize]);
                assert_eq!(get(c, r), START[r as usize]);
            }
            assert_eq!(exit_initialization_mode(c), OK);
            free_instance(c);
        }
    }

    #[test]
    fn a_derivative_that_overflows_is_an_error_not_an_infinite_answer() {
        let c = stepping(&[(vr::STIFFNESS, 1e-300)]);
        // SAFETY: `c` is a live instance; arrays of one element.
        unsafe {
            assert_eq!(do_step(c, 0.0, 1.0, 1), OK);
            let mut d = 0.0;
            // d dz / d force = -1 / stiffness = -1e300, seeded by 1e10
            let status = get_directional_derivative(c, &vr::DZ, 1, &vr::FORCE, 1, &1e10, &mut d);
            assert_eq!(status, ERROR);
            assert_eq!(d, 0.0, "nothing written");
            let status = get_directional_derivative(c, &vr::DZ, 1, &vr::FORCE, 1, &1.0, &mut d);
            assert_eq!((status, d), (OK, -1.0 / 1e-300));
            free_instance(c);
        }
    }
}
