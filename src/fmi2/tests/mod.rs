//! Tests of the glue through the exported functions, called as an importer calls them.
//!
//! TEST GOAL: the C boundary behaves as FMI 2.0 says (and as `phase.rs` documents where it
//! deviates): lifecycle, value references, bad pointers and values, wrong call order, GUID check,
//! Discard and retry, FMU state save/restore and (de)serialization, independent instances on
//! several threads, a panic turned into fmi2Fatal, the String parameter `results.directory` and
//! the VTK files it asks for (per step, after a restored state, after Reset, a failed write).
//!
//! MODEL: the default ParallelArch specimen (1/4 model, 121 nodes, 200 triangles, gaps G1..G9,
//! boundary group `frame`), written to a temporary `resources/` directory.
//!
//! BOUNDARY CONDITIONS: `frame.dz` ramped towards the specimen target −H/2 = −0.15 m.
//!
//! This file is the harness (the test logger, a temporary FMU, an instance that frees itself)
//! and the FMU-state helpers several files use; the tests are in one file per duty of the glue:
//!
//! | file | what |
//! |---|---|
//! | `derivatives.rs` | directional derivatives of every input against one-sided differences of steps |
//! | `chamber_derivatives.rs` | derivatives of models with gas chambers against central differences of steps |
//! | `lifecycle.rs` | instantiation, call order per phase, logging, reset, threads, fmi2Fatal |
//! | `values.rs` | strings, model-changing parameters, load inputs, outputs against the core |
//! | `stepping.rs` | Discard and retry, refused inputs, assumption warnings, stick and slip |
//! | `vtk_output.rs` | `results.directory`, `results.vtkFormat`, `.pvd` continuation, a failed write |
//! | `fmu_states.rs` | save/restore/round trips, forged and foreign serialized states |
//!
//! SAFETY of the `unsafe` blocks below: each calls an exported function the way an importer
//! does, with an instance from [`Fmu`] (freed only in its `Drop`), and pointers to live locals
//! or NUL-terminated literals holding the announced number of elements; the deliberately bad
//! arguments are NULL pointers, which the functions must reject without dereferencing.

pub(crate) mod chamber_derivatives;
pub(crate) mod derivatives;
mod fmu_states;
mod lifecycle;
mod stepping;
mod values;
mod vtk_output;

use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::path::PathBuf;
use std::sync::Mutex;

use super::description::describe;
use super::exports::*;
use super::phase::allowed;
use super::resources::{Source, file_uri};
use super::types::*;
use super::variables::Variable;
use crate::specimens::ParallelArch;

/// Messages received by the test logger: (status, category, message).
#[derive(Default)]
pub(super) struct Log(Mutex<Vec<(c_int, String, String)>>);

impl Log {
    pub(super) fn take(&self) -> Vec<(c_int, String, String)> {
        std::mem::take(&mut *self.0.lock().unwrap())
    }

    fn contains(&self, status: Status, text: &str) -> bool {
        self.0
            .lock()
            .unwrap()
            .iter()
            .any(|(s, _, m)| *s == status.raw() && m.contains(text))
    }
}

/// Receives the logger call `(env, name, status, category, "%s", message)`.
unsafe extern "C" fn capture(
    env: *mut c_void,
    _name: *const c_char,
    status: c_int,
    category: *const c_char,
    format: *const c_char,
    message: *const c_char,
) {
    // SAFETY: the FMU passes its NUL-terminated strings, and `env` is the `Log` given below.
    let (log, category, format, message) = unsafe {
        (
            &*env.cast::<Log>(),
            CStr::from_ptr(category),
            CStr::from_ptr(format),
            CStr::from_ptr(message),
        )
    };
    assert_eq!(
        format.to_bytes(),
        b"%s",
        "messages are never used as the format"
    );
    log.0.lock().unwrap().push((
        status,
        category.to_str().unwrap().into(),
        message.to_str().unwrap().into(),
    ));
}

fn callbacks(log: &Log) -> Fmi2CallbackFunctions {
    let logger: unsafe extern "C" fn(
        *mut c_void,
        *const c_char,
        c_int,
        *const c_char,
        *const c_char,
        *const c_char,
    ) = capture;
    Fmi2CallbackFunctions {
        // SAFETY (test only): on the Linux x86-64 and AArch64 C ABIs a variadic call whose six
        // arguments are all integer-class is passed exactly like a call to a non-variadic
        // function of those six parameters (the way ctypes loggers receive it). Stable Rust
        // cannot define a variadic function, so the capture function is given this type.
        logger: unsafe {
            std::mem::transmute::<
                unsafe extern "C" fn(
                    *mut c_void,
                    *const c_char,
                    c_int,
                    *const c_char,
                    *const c_char,
                    *const c_char,
                ),
                Fmi2CallbackLogger,
            >(logger)
        },
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: std::ptr::from_ref(log).cast_mut().cast(),
    }
}

/// A temporary unpacked FMU: `resources/` with the specimen, and its GUID and variables.
pub(super) struct Unpacked {
    dir: PathBuf,
    guid: CString,
    uri: CString,
    pub(super) variables: Vec<Variable>,
}

impl Unpacked {
    pub(super) fn new(tag: &str, source: Source) -> Self {
        let id = format!(
            "mc fmi2 test {tag} {}-{:?}",
            std::process::id(),
            std::thread::current().id()
        );
        let dir = std::env::temp_dir()
            .join(id.replace(['(', ')'], ""))
            .join("resources");
        std::fs::create_dir_all(&dir).unwrap();
        source.save(&dir).unwrap();
        let d = describe(&source).unwrap();
        // Percent-encoded (the directory name has spaces), as fmpy sends it.
        let uri = file_uri(&dir);
        Self {
            dir,
            guid: CString::new(d.guid).unwrap(),
            uri: CString::new(uri).unwrap(),
            variables: d.variables,
        }
    }

    fn specimen(tag: &str) -> Self {
        Self::new(tag, Source::ParallelArch(ParallelArch::default()))
    }

    /// `examples/two_chamber_orifice.json`: a three-layer cushion whose two chambers, supplied
    /// at 300 and 400 Pa, are joined by the orifice `hole` from `lower` to `upper` (issue 43).
    fn two_chamber_orifice(tag: &str) -> Self {
        let text = include_str!("../../../examples/two_chamber_orifice.json");
        Self::new(
            tag,
            Source::Model(crate::mech::Model::from_json(text).unwrap()),
        )
    }

    pub(super) fn vr(&self, name: &str) -> u32 {
        self.variables
            .iter()
            .find(|v| v.name == name)
            .unwrap_or_else(|| panic!("no variable {name}"))
            .value_reference
    }
}

impl Drop for Unpacked {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(self.dir.parent().unwrap());
    }
}

/// One instance, driven through the exported functions.
pub(super) struct Fmu<'a> {
    pub(super) c: Fmi2Component,
    u: &'a Unpacked,
    log: &'a Log,
}

impl<'a> Fmu<'a> {
    pub(super) fn new(u: &'a Unpacked, log: &'a Log) -> Self {
        let f = callbacks(log);
        // SAFETY: valid strings and callbacks for the duration of the call.
        let c = unsafe {
            fmi2_instantiate(
                c"inst".as_ptr(),
                FMI2_CO_SIMULATION,
                u.guid.as_ptr(),
                u.uri.as_ptr(),
                &f,
                0,
                1,
            )
        };
        assert!(!c.is_null(), "instantiate: {:?}", log.take());
        Self { c, u, log }
    }

    /// Instantiated, parameters set, initialized.
    fn initialized(
        u: &'a Unpacked,
        log: &'a Log,
        reals: &[(&str, f64)],
        integers: &[(&str, i32)],
    ) -> Self {
        Self::initialized_with(u, log, reals, integers, &[])
    }

    /// [`Self::initialized`] with Boolean parameters too.
    fn initialized_with(
        u: &'a Unpacked,
        log: &'a Log,
        reals: &[(&str, f64)],
        integers: &[(&str, i32)],
        booleans: &[(&str, bool)],
    ) -> Self {
        let fmu = Self::new(u, log);
        unsafe {
            assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
            assert_eq!(fmi2_enter_initialization_mode(fmu.c), 0);
        }
        for (n, v) in reals {
            assert_eq!(fmu.set_real(n, *v), 0, "{n}");
        }
        for (n, v) in integers {
            assert_eq!(fmu.set_integer(n, *v), 0, "{n}");
        }
        for (n, v) in booleans {
            assert_eq!(fmu.set_boolean(n, *v), 0, "{n}");
        }
        assert_eq!(
            unsafe { fmi2_exit_initialization_mode(fmu.c) },
            0,
            "{:?}",
            log.take()
        );
        fmu
    }

    pub(super) fn set_real(&self, name: &str, v: f64) -> c_int {
        unsafe { fmi2_set_real(self.c, &self.u.vr(name), 1, &v) }
    }

    pub(super) fn set_integer(&self, name: &str, v: i32) -> c_int {
        unsafe { fmi2_set_integer(self.c, &self.u.vr(name), 1, &v) }
    }

    pub(super) fn set_boolean(&self, name: &str, v: bool) -> c_int {
        let v = c_int::from(v);
        unsafe { fmi2_set_boolean(self.c, &self.u.vr(name), 1, &v) }
    }

    pub(super) fn set_string(&self, name: &str, v: &str) -> c_int {
        let v = CString::new(v).unwrap();
        unsafe { fmi2_set_string(self.c, &self.u.vr(name), 1, &v.as_ptr()) }
    }

    /// The value of a String variable, copied before any other call (FMI 2.0 §2.1.7).
    fn string(&self, name: &str) -> String {
        let mut p: Fmi2String = std::ptr::null();
        assert_eq!(
            unsafe { fmi2_get_string(self.c, &self.u.vr(name), 1, &mut p) },
            0,
            "{name}"
        );
        unsafe { CStr::from_ptr(p) }.to_str().unwrap().to_owned()
    }

    /// Setup, initialization mode, `results.directory` = `dir`, exit: returns the exit status.
    fn initialized_with_output(&self, dir: &std::path::Path) -> c_int {
        unsafe {
            assert_eq!(fmi2_setup_experiment(self.c, 0, 0.0, 0.0, 0, 0.0), 0);
            assert_eq!(fmi2_enter_initialization_mode(self.c), 0);
        }
        assert_eq!(
            self.set_string("results.directory", dir.to_str().unwrap()),
            0
        );
        assert_eq!(self.set_integer("solver.incrementsPerStep", 2), 0);
        unsafe { fmi2_exit_initialization_mode(self.c) }
    }

    pub(super) fn real(&self, name: &str) -> f64 {
        let mut v = f64::NAN;
        assert_eq!(
            unsafe { fmi2_get_real(self.c, &self.u.vr(name), 1, &mut v) },
            0,
            "{name}"
        );
        v
    }

    pub(super) fn integer(&self, name: &str) -> i32 {
        let mut v = -1;
        assert_eq!(
            unsafe { fmi2_get_integer(self.c, &self.u.vr(name), 1, &mut v) },
            0,
            "{name}"
        );
        v
    }

    pub(super) fn step(&self, t: f64, h: f64) -> c_int {
        unsafe { fmi2_do_step(self.c, t, h, 1) }
    }

    /// Every Real and Integer variable, for exact comparisons.
    fn all_values(&self) -> (Vec<f64>, Vec<i32>) {
        let (mut reals, mut ints) = (Vec::new(), Vec::new());
        for v in &self.u.variables {
            match v.var_type {
                super::variables::VarType::Real => reals.push(self.real(&v.name)),
                super::variables::VarType::Integer => ints.push(self.integer(&v.name)),
                super::variables::VarType::Boolean | super::variables::VarType::String => {}
            }
        }
        (reals, ints)
    }

    /// [`Unpacked::two_chamber_orifice`]'s cushion inflated by its supplies in three steps of
    /// 1 s (to 300 and 400 Pa) and both valves closed: the air is enclosed as the next step,
    /// from t = 3, starts, and from then on the orifice passes air from `lower` to `upper`.
    fn inflate_and_seal_two_chambers(&self) {
        for (k, f) in [0.25, 0.5, 1.0].into_iter().enumerate() {
            assert_eq!(self.set_real("upper.supplyPressure", 300.0 * f), 0);
            assert_eq!(self.set_real("lower.supplyPressure", 400.0 * f), 0);
            assert_eq!(self.step(k as f64, 1.0), 0, "{:?}", self.log.take());
        }
        assert_eq!(self.set_boolean("upper.sealed", true), 0);
        assert_eq!(self.set_boolean("lower.sealed", true), 0);
    }

    /// Steps `from..to` of `h` seconds from `t0` (step `n` from `t0 + n h`), `set(self, n)`
    /// setting the inputs before each: every Real and Integer variable after each step.
    fn steps(
        &self,
        (from, to): (usize, usize),
        (t0, h): (f64, f64),
        set: &dyn Fn(&Self, usize),
    ) -> Vec<(Vec<f64>, Vec<i32>)> {
        (from..to)
            .map(|n| {
                set(self, n);
                let t = t0 + n as f64 * h;
                assert_eq!(self.step(t, h), 0, "step {n}: {:?}", self.log.take());
                self.all_values()
            })
            .collect()
    }

    /// Steps `frame.dz` linearly to `fraction` of the target in `n` steps of the ramp over [0, 1].
    fn ramp(&self, from_step: usize, to_step: usize, n: usize) {
        let target = ParallelArch::default().target()[2];
        for k in from_step..to_step {
            let t = k as f64 / n as f64;
            assert_eq!(
                self.set_real("frame.dz", target * ((k + 1) as f64 / n as f64)),
                0
            );
            assert_eq!(
                self.step(t, 1.0 / n as f64),
                0,
                "step {k}: {:?}",
                self.log.take()
            );
        }
    }
}

impl Drop for Fmu<'_> {
    fn drop(&mut self) {
        unsafe { fmi2_free_instance(self.c) };
    }
}

/// The serialized state `bytes` changed by `f`, with its length and CRC recomputed (a forgery
/// that passes the format checks).
fn forge(bytes: &[u8], guid: &str, f: impl FnOnce(&mut super::state::Snapshot)) -> Vec<u8> {
    let mut s = super::state::deserialize(bytes, guid).unwrap();
    f(&mut s);
    super::state::serialize(&s, guid)
}

fn deserialize_status(fmu: &Fmu, bytes: &[u8]) -> (c_int, Fmi2FmuState) {
    let mut s: Fmi2FmuState = std::ptr::null_mut();
    let status =
        unsafe { fmi2_de_serialize_fmu_state(fmu.c, bytes.as_ptr().cast(), bytes.len(), &mut s) };
    (status, s)
}

/// The state's serialized bytes (`fmi2SerializedFMUstateSize` + `fmi2SerializeFMUstate`).
pub(super) fn serialized(fmu: &Fmu, state: Fmi2FmuState) -> Vec<Fmi2Byte> {
    let mut size = 0;
    assert_eq!(
        unsafe { fmi2_serialized_fmu_state_size(fmu.c, state, &mut size) },
        0
    );
    let mut bytes = vec![0 as Fmi2Byte; size];
    assert_eq!(
        unsafe { fmi2_serialize_fmu_state(fmu.c, state, bytes.as_mut_ptr(), size) },
        0
    );
    bytes
}
