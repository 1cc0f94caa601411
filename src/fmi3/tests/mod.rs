//! The film's FMI 3.0 functions called from Rust as an importer calls them: the harness (a
//! temporary FMU, an instance that frees itself, its calls by variable name) and, in
//! `derivatives.rs`, `fmi3GetDirectionalDerivative` and `fmi3GetAdjointDerivative` against
//! one-sided differences of FMU steps (issue 45 item 4).
//!
//! SAFETY of the `unsafe` blocks below: each calls an exported FMI 3.0 function the way an
//! importer does, with an instance from [`Fmu3`] (freed only in its `Drop`), FMU states it
//! returned, and pointers to live locals or slices holding the announced number of elements.

mod derivatives;
mod lines;

use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::path::PathBuf;
use std::sync::Mutex;

use super::fmi3_exports::*;
use crate::fmi2::description::describe;
use crate::fmi2::resources::Source;
use crate::fmi2::variables::Variable;

/// Messages received by the test logger: (status, message).
#[derive(Default)]
struct Log(Mutex<Vec<(c_int, String)>>);

impl Log {
    fn take(&self) -> Vec<(c_int, String)> {
        std::mem::take(&mut *self.0.lock().unwrap())
    }
}

/// The FMI 3.0 logger (not variadic): `(environment, status, category, message)`.
unsafe extern "C" fn capture(
    env: *mut c_void,
    status: c_int,
    _category: *const c_char,
    message: *const c_char,
) {
    // SAFETY: the FMU passes a NUL-terminated message, and `env` is the `Log` of the instance.
    let (log, message) = unsafe { (&*env.cast::<Log>(), CStr::from_ptr(message)) };
    let message = message.to_string_lossy().into_owned();
    log.0.lock().unwrap().push((status, message));
}

/// A temporary unpacked FMU: `resources/` with the model, its instantiation token and variables.
struct Unpacked {
    dir: PathBuf,
    token: CString,
    path: CString,
    variables: Vec<Variable>,
}

impl Unpacked {
    fn new(tag: &str, source: Source) -> Self {
        let id = format!(
            "mc fmi3 test {tag} {}-{:?}",
            std::process::id(),
            std::thread::current().id()
        );
        let dir = std::env::temp_dir()
            .join(id.replace(['(', ')'], ""))
            .join("resources");
        std::fs::create_dir_all(&dir).unwrap();
        source.save(&dir).unwrap();
        let d = describe(&source).unwrap();
        // FMI 3.0 §2.3.1: a directory path ending in a separator.
        let path = format!("{}/", dir.display());
        Self {
            dir,
            token: CString::new(d.guid).unwrap(),
            path: CString::new(path).unwrap(),
            variables: d.variables,
        }
    }

    fn variable(&self, name: &str) -> &Variable {
        self.variables
            .iter()
            .find(|v| v.name == name)
            .unwrap_or_else(|| panic!("no variable {name}"))
    }

    fn vr(&self, name: &str) -> u32 {
        self.variable(name).value_reference
    }
}

impl Drop for Unpacked {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(self.dir.parent().unwrap());
    }
}

/// One FMI 3.0 instance, driven through the exported functions.
struct Fmu3<'a> {
    c: *mut c_void,
    u: &'a Unpacked,
    log: &'a Log,
}

impl<'a> Fmu3<'a> {
    /// Instantiated, its parameters set in initialization mode (from time 0), initialized.
    fn initialized(
        u: &'a Unpacked,
        log: &'a Log,
        floats: &[(&str, f64)],
        ints: &[(&str, i32)],
    ) -> Self {
        Self::initialized_with(u, log, (floats, ints), &[])
    }

    /// [`Fmu3::initialized`] with String parameters too.
    fn initialized_with(
        u: &'a Unpacked,
        log: &'a Log,
        (floats, ints): (&[(&str, f64)], &[(&str, i32)]),
        strings: &[(&str, &str)],
    ) -> Self {
        let c = unsafe {
            instantiate_co_simulation(
                c"film".as_ptr(),
                u.token.as_ptr(),
                u.path.as_ptr(),
                0,
                1,
                0,
                0,
                std::ptr::null(),
                0,
                std::ptr::from_ref(log).cast_mut().cast(),
                Some(capture),
                std::ptr::null_mut(),
            )
        };
        assert!(!c.is_null(), "instantiate: {:?}", log.take());
        let fmu = Self { c, u, log };
        assert_eq!(
            unsafe { enter_initialization_mode(c, 0, 0.0, 0.0, 0, 0.0) },
            0
        );
        for &(n, v) in floats {
            assert_eq!(fmu.set(n, v), 0, "{n}: {:?}", log.take());
        }
        for &(n, v) in strings {
            let v = CString::new(v).unwrap();
            let status = unsafe { set_string(c, &u.vr(n), 1, &v.as_ptr(), 1) };
            assert_eq!(status, 0, "{n}: {:?}", log.take());
        }
        for &(n, v) in ints {
            let status = unsafe { set_int32(c, &u.vr(n), 1, &v, 1) };
            assert_eq!(status, 0, "{n}: {:?}", log.take());
        }
        assert_eq!(
            unsafe { exit_initialization_mode(c) },
            0,
            "{:?}",
            log.take()
        );
        fmu
    }

    fn set(&self, name: &str, v: f64) -> c_int {
        unsafe { set_float64(self.c, &self.u.vr(name), 1, &v, 1) }
    }

    fn set_bool(&self, name: &str, v: bool) -> c_int {
        let v = u8::from(v);
        unsafe { set_boolean(self.c, &self.u.vr(name), 1, &v, 1) }
    }

    fn floats(&self, names: &[&str]) -> Vec<f64> {
        let refs: Vec<u32> = names.iter().map(|n| self.u.vr(n)).collect();
        let mut v = vec![f64::NAN; refs.len()];
        let status =
            unsafe { get_float64(self.c, refs.as_ptr(), refs.len(), v.as_mut_ptr(), v.len()) };
        assert_eq!(status, 0, "{:?}", self.log.take());
        v
    }

    fn ints(&self, names: &[&str]) -> Vec<i32> {
        let refs: Vec<u32> = names.iter().map(|n| self.u.vr(n)).collect();
        let mut v = vec![-1; refs.len()];
        let status =
            unsafe { get_int32(self.c, refs.as_ptr(), refs.len(), v.as_mut_ptr(), v.len()) };
        assert_eq!(status, 0, "{:?}", self.log.take());
        v
    }

    /// `fmi3DoStep` from `t` over `h`.
    fn step(&self, t: f64, h: f64) -> c_int {
        let (mut event, mut stop, mut early, mut last) = (0u8, 0u8, 0u8, 0.0);
        unsafe {
            do_step(
                self.c, t, h, 0, &mut event, &mut stop, &mut early, &mut last,
            )
        }
    }

    fn save(&self) -> *mut c_void {
        let mut s = std::ptr::null_mut();
        assert_eq!(unsafe { get_fmu_state(self.c, &mut s) }, 0);
        s
    }

    fn restore(&self, s: *mut c_void) {
        assert_eq!(unsafe { set_fmu_state(self.c, s) }, 0);
    }

    fn free(&self, mut s: *mut c_void) {
        assert_eq!(unsafe { free_fmu_state(self.c, &mut s) }, 0);
    }

    /// Solves with the held tangent so far (`Analysis::tangent_solves`).
    fn tangent_solves(&self) -> usize {
        // SAFETY: `c` is the glue's `Box<Instance>` (`fmi_glue::fmi2::instantiate_with`:
        // `Box::into_raw`), freed only in `Drop`; nothing else uses it during this read.
        let instance = unsafe { &*self.c.cast::<crate::fmi2::instance::Instance>() };
        instance.tangent_solves()
    }

    /// `fmi3GetDirectionalDerivative`: status and `J seed` (a seed per known).
    fn directional(&self, unknowns: &[&str], knowns: &[&str], seed: &[f64]) -> (c_int, Vec<f64>) {
        self.derivative(false, unknowns, knowns, seed)
    }

    /// `fmi3GetAdjointDerivative`: status and `Jᵀ seed` (a seed per unknown).
    fn adjoint(&self, unknowns: &[&str], knowns: &[&str], seed: &[f64]) -> (c_int, Vec<f64>) {
        self.derivative(true, unknowns, knowns, seed)
    }

    fn derivative(
        &self,
        adjoint: bool,
        unknowns: &[&str],
        knowns: &[&str],
        seed: &[f64],
    ) -> (c_int, Vec<f64>) {
        let u: Vec<u32> = unknowns.iter().map(|n| self.u.vr(n)).collect();
        let k: Vec<u32> = knowns.iter().map(|n| self.u.vr(n)).collect();
        let (f, n) = if adjoint {
            (get_adjoint_derivative as ExportedDerivative, k.len())
        } else {
            (get_directional_derivative as ExportedDerivative, u.len())
        };
        let mut out = vec![f64::NAN; n];
        let status = unsafe {
            f(
                self.c,
                u.as_ptr(),
                u.len(),
                k.as_ptr(),
                k.len(),
                seed.as_ptr(),
                seed.len(),
                out.as_mut_ptr(),
                out.len(),
            )
        };
        (status, out)
    }
}

/// `fmi3GetDirectionalDerivative` and `fmi3GetAdjointDerivative` share this signature.
type ExportedDerivative = unsafe extern "C" fn(
    *mut c_void,
    *const u32,
    usize,
    *const u32,
    usize,
    *const f64,
    usize,
    *mut f64,
    usize,
) -> c_int;

impl Drop for Fmu3<'_> {
    fn drop(&mut self) {
        unsafe { free_instance(self.c) };
    }
}
