//! Raw pointers from the importer turned into Rust references after NULL and length checks,
//! and the text of a caught panic: the helpers of every C layer (moved from the film's
//! `src/fmi2/guard.rs`). Each function states its contract; the C layers uphold it from the FMI
//! standard's (arrays hold the announced number of elements, strings are NUL-terminated).

use core::ffi::c_char;
use std::ffi::CStr;

use crate::phase::{Failure, Outcome};

/// The text of a panic payload.
pub fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
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
pub unsafe fn string<'a>(p: *const c_char) -> Outcome<Option<&'a str>> {
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
pub unsafe fn strings<'a>(p: *const *const c_char, n: usize, what: &str) -> Outcome<Vec<&'a str>> {
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
