//! All raw-pointer work of the FMI 2.0 functions, and the panic barrier; the barrier, the
//! freeing and the array helpers are the shared glue's (`fmu/glue`), so the FMI 3.0 functions
//! (`src/fmi3`) go through the same code.
//!
//! Every exported function goes through one of these helpers:
//! * [`with_instance`]: NULL check of `fmi2Component`, the phase check against the function's
//!   [`Mask`], `catch_unwind` around the body, the logging of a failure, the status returned;
//! * [`free_instance`]: `Box::from_raw` of the [`Instance`] (`fmi2Instantiate` is the glue's
//!   `fmi_glue::fmi2::instantiate`, which calls `Core::instantiate`);
//! * [`input`], [`output`], [`out_ref`], [`string`], [`strings`]: C arrays and strings turned
//!   into Rust references after NULL and length checks.
//!
//! A panic becomes `fmi2Fatal` (or a NULL instance) plus a logged message, and the instance is
//! marked `Phase::Fatal`; no panic unwinds into the importer.

pub use fmi_glue::ffi::{input, out_ref, output, panic_message, string, strings};

use super::instance::Instance;
use super::phase::{Mask, Outcome};
use super::types::{Fmi2Component, Fmi2Status};

/// Runs `body` on the instance behind `c` if `allowed` permits the instance's phase: the shared
/// glue's barrier (`fmi_glue::fmi2::with`, the one the FMI 3.0 functions go through too).
///
/// # Safety
/// `c` must be NULL or a pointer returned by `fmi2Instantiate` and not yet passed to
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

/// `fmi2FreeInstance`: drops the instance (and the FMU states it still holds); the shared
/// glue's, which catches a panic of the destructor.
///
/// # Safety
/// As for [`with_instance`]; `c` must not be used afterwards.
pub unsafe fn free_instance(c: Fmi2Component) {
    // SAFETY: this function's contract is the glue's.
    unsafe { fmi_glue::fmi2::free_instance::<Instance>(c) }
}
