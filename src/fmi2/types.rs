//! The FMI 2.0 C types, written by hand from `fmi2TypesPlatform.h` and `fmi2FunctionTypes.h`
//! (the copies fmpy 0.3.32 ships in `fmpy/c-code/`, FMI 2.0.1 headers; "default" platform).
//!
//! | C (header) | Rust |
//! |---|---|
//! | `fmi2Component`, `fmi2ComponentEnvironment`, `fmi2FMUstate` (`void*`) | `*mut c_void` |
//! | `fmi2ValueReference` (`unsigned int`) | `c_uint` |
//! | `fmi2Real` (`double`) | `f64` |
//! | `fmi2Integer`, `fmi2Boolean` (`int`) | `c_int` (never Rust `bool`) |
//! | `fmi2String` (`const char*`), `fmi2Byte` (`char`) | `*const c_char`, `c_char` |
//! | `fmi2Status`, `fmi2Type`, `fmi2StatusKind` (C enums) | `c_int`, converted with checks |
//!
//! Incoming enums are read as `c_int` and converted, so that an out-of-range value from the
//! caller can never become an invalid Rust enum.

use core::ffi::{c_char, c_int, c_uint, c_void};

pub type Fmi2Component = *mut c_void;
pub type Fmi2ComponentEnvironment = *mut c_void;
pub type Fmi2FmuState = *mut c_void;
pub type Fmi2ValueReference = c_uint;
pub type Fmi2Real = f64;
pub type Fmi2Integer = c_int;
pub type Fmi2Boolean = c_int;
pub type Fmi2String = *const c_char;
pub type Fmi2Byte = c_char;
/// `fmi2Status` as it crosses the boundary.
pub type Fmi2Status = c_int;

pub const FMI2_TRUE: Fmi2Boolean = 1;
pub const FMI2_FALSE: Fmi2Boolean = 0;

/// `fmi2Type`: `fmi2ModelExchange = 0`, `fmi2CoSimulation = 1`.
pub const FMI2_MODEL_EXCHANGE: c_int = 0;
pub const FMI2_CO_SIMULATION: c_int = 1;

/// `fmi2StatusKind`.
pub const FMI2_DO_STEP_STATUS: c_int = 0;
pub const FMI2_PENDING_STATUS: c_int = 1;
pub const FMI2_LAST_SUCCESSFUL_TIME: c_int = 2;
pub const FMI2_TERMINATED: c_int = 3;

/// `fmi2Status` (the shared glue's, whose values are FMI 2.0's and FMI 3.0's).
pub use fmi_glue::Status;

/// `fmi2CallbackLogger`: variadic, printf semantics. Always called with `"%s"` and a
/// pre-formatted message (see `logger.rs`); the shared glue's type.
pub type Fmi2CallbackLogger = Option<fmi_glue::logger::Fmi2LoggerFn>;
/// `fmi2CallbackAllocateMemory` (not used: the FMU declares `canNotUseMemoryManagementFunctions`).
pub type Fmi2CallbackAllocateMemory =
    Option<unsafe extern "C" fn(nobj: usize, size: usize) -> *mut c_void>;
/// `fmi2CallbackFreeMemory` (not used).
pub type Fmi2CallbackFreeMemory = Option<unsafe extern "C" fn(obj: *mut c_void)>;
/// `fmi2StepFinished` (only for asynchronous DoStep, not used).
pub type Fmi2StepFinished = Option<
    unsafe extern "C" fn(component_environment: Fmi2ComponentEnvironment, status: Fmi2Status),
>;

/// `fmi2CallbackFunctions`. Only valid during `fmi2Instantiate`: the instance keeps a copy. The
/// shared glue's struct (`fmi_glue::fmi2::Callbacks`), which its `fmi2Instantiate` reads.
pub type Fmi2CallbackFunctions = fmi_glue::fmi2::Callbacks;

/// `fmi2EventInfo` (Model Exchange only; appears in the signature of an error stub).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct Fmi2EventInfo {
    pub new_discrete_states_needed: Fmi2Boolean,
    pub terminate_simulation: Fmi2Boolean,
    pub nominals_of_continuous_states_changed: Fmi2Boolean,
    pub values_of_continuous_states_changed: Fmi2Boolean,
    pub next_event_time_defined: Fmi2Boolean,
    pub next_event_time: Fmi2Real,
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::mem::{align_of, offset_of, size_of};

    /// The header's layouts on a 64-bit "default" platform (checked against `fmi2FunctionTypes.h`:
    /// four function pointers then a `void*`; five `int` then a `double`).
    #[test]
    fn layouts_match_the_header() {
        let p = size_of::<*const c_void>();
        assert_eq!(
            size_of::<Fmi2CallbackLogger>(),
            p,
            "Option<fn> is a nullable pointer"
        );
        assert_eq!(size_of::<Fmi2CallbackFunctions>(), 5 * p);
        assert_eq!(offset_of!(Fmi2CallbackFunctions, logger), 0);
        assert_eq!(offset_of!(Fmi2CallbackFunctions, allocate_memory), p);
        assert_eq!(offset_of!(Fmi2CallbackFunctions, free_memory), 2 * p);
        assert_eq!(offset_of!(Fmi2CallbackFunctions, step_finished), 3 * p);
        assert_eq!(
            offset_of!(Fmi2CallbackFunctions, component_environment),
            4 * p
        );
        assert_eq!(offset_of!(Fmi2EventInfo, next_event_time), 24);
        assert_eq!(
            (size_of::<Fmi2EventInfo>(), align_of::<Fmi2EventInfo>()),
            (32, 8)
        );
        assert_eq!(size_of::<Fmi2ValueReference>(), 4);
        assert_eq!(size_of::<Fmi2Boolean>(), size_of::<c_int>());
    }

    #[test]
    fn status_values_and_order() {
        assert_eq!(Status::Ok.raw(), 0);
        assert_eq!(Status::Discard.raw(), 2);
        assert_eq!(Status::Pending.raw(), 5);
        assert!(Status::Error > Status::Discard && Status::Fatal > Status::Error);
    }
}
