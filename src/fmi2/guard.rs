//! All raw-pointer work of the FMI 2.0 functions, and the panic barrier; the barrier, the
//! freeing and the array helpers are the shared glue's (`fmu/glue`), so the FMI 3.0 functions
//! (`src/fmi3`) go through the same code.
//!
//! Every exported function goes through one of these helpers:
//! * [`with_instance`]: NULL check of `fmi2Component`, the phase check against the function's
//!   [`Mask`], `catch_unwind` around the body, the logging of a failure, the status returned;
//! * [`instantiate`] / [`free_instance`]: `Box::into_raw` / `Box::from_raw` of the [`Instance`];
//! * [`input`], [`output`], [`out_ref`], [`string`], [`strings`]: C arrays and strings turned
//!   into Rust references after NULL and length checks.
//!
//! A panic becomes `fmi2Fatal` (or a NULL instance) plus a logged message, and the instance is
//! marked `Phase::Fatal`; no panic unwinds into the importer.

use std::panic::{AssertUnwindSafe, catch_unwind};

pub use fmi_glue::ffi::{input, out_ref, output, panic_message, string, strings};

use super::instance::Instance;
use super::logger::Logger;
use super::phase::{Mask, Outcome};
use super::types::{
    Fmi2CallbackFunctions, Fmi2Component, Fmi2FmuState, Fmi2Status, Fmi2String, Status,
};

/// Runs `body` on the instance behind `c` if `allowed` permits the instance's phase: the shared
/// glue's barrier (`fmi_glue::fmi2::with`, the one the FMI 3.0 functions go through too).
///
/// # Safety
/// `c` must be NULL or a pointer returned by [`instantiate`] and not yet passed to
/// [`free_instance`], and no other call may use the same instance at the same time (FMI 2.0
/// §2.1: calls to one instance are serialized by the master).
pub unsafe fn with_instance(
    c: Fmi2Component,
    function: &str,
    allowed: Mask,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> Fmi2Status {
    // SAFETY: this function's contract is the glue's.
    unsafe { fmi_glue::fmi2::with::<Instance>(c, function, allowed, body) }
}

/// `fmi2Instantiate`: copies the callbacks, builds the instance and returns it as an opaque
/// pointer, or NULL after logging why.
///
/// # Safety
/// The string arguments must be NULL or NUL-terminated strings, and `functions` NULL or a valid
/// `fmi2CallbackFunctions`, all valid for the duration of the call (FMI 2.0 §2.1.5).
pub unsafe fn instantiate(
    instance_name: Fmi2String,
    fmu_type: i32,
    guid: Fmi2String,
    resource_location: Fmi2String,
    functions: *const Fmi2CallbackFunctions,
    logging_on: bool,
) -> Fmi2Component {
    let result = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: NULL or a valid callbacks struct for this call (contract); copied, not kept.
        let callbacks = unsafe { functions.as_ref() }.copied();
        let logger_of = |name: &str| match callbacks {
            Some(f) => Logger::new(f.logger, f.component_environment, name, logging_on),
            None => Logger::silent(),
        };
        // SAFETY: NULL or NUL-terminated strings valid for this call (contract).
        let (name, guid, uri) = unsafe {
            (
                string(instance_name),
                string(guid),
                string(resource_location),
            )
        };
        let name = match name {
            Ok(Some(n)) => n,
            Ok(None) => return Err((logger_of(""), "instanceName is NULL".to_string())),
            Err(f) => return Err((logger_of(""), format!("instanceName: {}", f.message))),
        };
        let logger = logger_of(name);
        let (guid, uri) = match (guid, uri) {
            (Ok(g), Ok(u)) => (g, u),
            (Err(f), _) | (_, Err(f)) => return Err((logger, f.message)),
        };
        Instance::instantiate(name, fmu_type, guid, uri, logger.clone()).map_err(|e| (logger, e))
    }));
    match result {
        Ok(Ok(instance)) => Box::into_raw(Box::new(instance)).cast(),
        Ok(Err((logger, message))) => {
            logger.log(Status::Error, &format!("fmi2Instantiate: {message}"));
            std::ptr::null_mut()
        }
        Err(_) => std::ptr::null_mut(),
    }
}

/// `fmi2FreeInstance`: drops the instance (and the FMU states it still holds); the shared
/// glue's, which catches a panic of the destructor.
///
/// # Safety
/// As for [`with_instance`]; `c` must not be used afterwards.
pub unsafe fn free_instance(c: Fmi2Component) {
    // SAFETY: this function's contract is the glue's.
    unsafe { fmi_glue::fmi2::free_instance::<Instance>(c) }
}

/// The opaque `fmi2FMUstate` of a saved-state handle. It is never dereferenced: the instance
/// looks handles up in its own table.
pub fn state_pointer(handle: usize) -> Fmi2FmuState {
    std::ptr::without_provenance_mut(handle)
}

/// The handle of an opaque `fmi2FMUstate` (0 for NULL).
pub fn state_handle(p: Fmi2FmuState) -> usize {
    p.addr()
}
