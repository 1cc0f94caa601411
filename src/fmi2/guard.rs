//! All raw-pointer work of the FMU, and the panic barrier.
//!
//! Every exported function goes through one of these helpers:
//! * [`with_instance`]: NULL check of `fmi2Component`, the phase check against the function's
//!   [`Mask`], `catch_unwind` around the body, the logging of a failure, the status returned;
//! * [`instantiate`] / [`free_instance`]: `Box::into_raw` / `Box::from_raw` of the [`Instance`];
//! * [`input`], [`output`], [`out_ref`], [`string`], [`strings`]: C arrays and strings turned
//!   into Rust references after NULL and length checks.
//!
//! A panic becomes `fmi2Fatal` (or a NULL instance) plus a logged message, and the instance is
//! marked [`Phase::Fatal`]; no panic unwinds into the importer.

use std::ffi::CStr;
use std::panic::{AssertUnwindSafe, catch_unwind};

use super::instance::Instance;
use super::logger::Logger;
use super::phase::{Failure, Mask, Outcome, Phase};
use super::types::{
    Fmi2CallbackFunctions, Fmi2Component, Fmi2FmuState, Fmi2Status, Fmi2String, Status,
};

/// The text of a panic payload.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// Runs `body` on the instance behind `c` if `allowed` permits the instance's phase.
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
    if c.is_null() {
        return Status::Error.raw();
    }
    // SAFETY: by this function's contract `c` is a live `Box<Instance>` pointer with no other
    // reference to it in use.
    let instance = unsafe { &mut *c.cast::<Instance>() };
    let phase = instance.phase();
    if !allowed.allows(phase) {
        let why = if phase == Phase::Fatal {
            " (an earlier call failed fatally: free the instance)"
        } else {
            ""
        };
        instance.logger.log(
            Status::Error,
            &format!("{function} must not be called in state {phase:?}{why}"),
        );
        return Status::Error.raw();
    }
    match catch_unwind(AssertUnwindSafe(|| body(&mut *instance))) {
        Ok(Ok(())) => Status::Ok.raw(),
        Ok(Err(Failure { status, message })) => {
            instance
                .logger
                .log(status, &format!("{function}: {message}"));
            status.raw()
        }
        Err(payload) => {
            instance.mark_fatal();
            let message = panic_message(&*payload);
            instance.logger.log(
                Status::Fatal,
                &format!("{function}: internal error (panic): {message}"),
            );
            Status::Fatal.raw()
        }
    }
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

/// `fmi2FreeInstance`: drops the instance (and the FMU states it still holds).
///
/// # Safety
/// As for [`with_instance`]; `c` must not be used afterwards.
pub unsafe fn free_instance(c: Fmi2Component) {
    if c.is_null() {
        return;
    }
    // SAFETY: `c` came from `Box::into_raw` in `instantiate` and is freed once (contract).
    let instance = unsafe { Box::from_raw(c.cast::<Instance>()) };
    // A panic in a destructor must not unwind into C either.
    let _ = catch_unwind(AssertUnwindSafe(move || drop(instance)));
}

/// A C array of `n` values to read. NULL is allowed only when `n` is 0.
///
/// # Safety
/// `p` must be NULL or point to `n` initialized values that stay valid and unmodified while
/// the returned slice is used.
pub unsafe fn input<'a, T>(p: *const T, n: usize, what: &str) -> Outcome<&'a [T]> {
    if n == 0 {
        return Ok(&[]);
    }
    check_array(p.is_null(), n, size_of::<T>(), what)?;
    // SAFETY: non-NULL, length checked against isize::MAX bytes; validity per the contract.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// A C array of `n` values to write. NULL is allowed only when `n` is 0.
///
/// # Safety
/// `p` must be NULL or point to `n` writable values not aliased while the slice is used.
pub unsafe fn output<'a, T>(p: *mut T, n: usize, what: &str) -> Outcome<&'a mut [T]> {
    if n == 0 {
        return Ok(&mut []);
    }
    check_array(p.is_null(), n, size_of::<T>(), what)?;
    // SAFETY: non-NULL, length checked against isize::MAX bytes; validity per the contract.
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

fn check_array(null: bool, n: usize, size: usize, what: &str) -> Outcome {
    if null {
        return Err(Failure::error(format!(
            "{what} is NULL but {n} values were announced"
        )));
    }
    if n.checked_mul(size).is_none_or(|b| b > isize::MAX as usize) {
        return Err(Failure::error(format!(
            "{what}: {n} values is not a valid array length"
        )));
    }
    Ok(())
}

/// A pointer to one value to write.
///
/// # Safety
/// `p` must be NULL or point to a writable `T` not aliased while the reference is used.
pub unsafe fn out_ref<'a, T>(p: *mut T, what: &str) -> Outcome<&'a mut T> {
    // SAFETY: NULL is handled; otherwise valid per the contract.
    unsafe { p.as_mut() }.ok_or_else(|| Failure::error(format!("{what} is NULL")))
}

/// A C string as UTF-8; NULL gives `None`.
///
/// # Safety
/// `p` must be NULL or a NUL-terminated string valid while the result is used.
pub unsafe fn string<'a>(p: Fmi2String) -> Outcome<Option<&'a str>> {
    if p.is_null() {
        return Ok(None);
    }
    // SAFETY: non-NULL and NUL-terminated per the contract.
    let s = unsafe { CStr::from_ptr(p) };
    s.to_str()
        .map(Some)
        .map_err(|_| Failure::error("a string argument is not valid UTF-8"))
}

/// A C array of `n` non-NULL strings.
///
/// # Safety
/// As for [`input`] and [`string`] for each element.
pub unsafe fn strings<'a>(p: *const Fmi2String, n: usize, what: &str) -> Outcome<Vec<&'a str>> {
    // SAFETY: forwarded contract.
    let pointers = unsafe { input(p, n, what)? };
    pointers
        .iter()
        .enumerate()
        // SAFETY: each element is NULL or a NUL-terminated string (contract).
        .map(|(i, &s)| {
            unsafe { string(s) }?.ok_or_else(|| Failure::error(format!("{what}[{i}] is NULL")))
        })
        .collect()
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
