//! Tests of the glue through the exported functions, called as an importer calls them.
//!
//! TEST GOAL: the C boundary behaves as FMI 2.0 says (and as `instance.rs` documents where it
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
//! SAFETY of the `unsafe` blocks below: each calls an exported function the way an importer
//! does, with an instance from [`Fmu`] (freed only in its `Drop`), and pointers to live locals
//! or NUL-terminated literals holding the announced number of elements; the deliberately bad
//! arguments are NULL pointers, which the functions must reject without dereferencing.

use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::path::PathBuf;
use std::sync::Mutex;

use super::description::describe;
use super::exports::*;
use super::phase::allowed;
use super::resources::{Source, file_uri};
use super::types::*;
use super::variables::Variable;
use crate::mech::ParallelArch;

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

#[test]
fn inquiry_functions() {
    let s = |p: *const c_char| unsafe { CStr::from_ptr(p) }.to_str().unwrap().to_string();
    assert_eq!(s(fmi2_get_types_platform()), "default");
    assert_eq!(s(fmi2_get_version()), "2.0");
}

#[test]
fn a_ramp_reaches_the_cores_result() {
    let (u, log) = (Unpacked::specimen("ramp"), Log::default());
    let fmu = Fmu::initialized(&u, &log, &[], &[("solver.incrementsPerStep", 1)]);
    assert_eq!(fmu.real("time"), 0.0);
    // Initial outputs: undeformed, prestressed film.
    assert_eq!(fmu.real("G5.slip"), 0.0);
    assert!((fmu.real("film.maxEquivalentStress") - 0.5e6).abs() < 1.0);
    fmu.ramp(0, 10, 10);
    assert!((fmu.real("time") - 1.0).abs() < 1e-12);
    assert!(fmu.integer("solver.iterations") > 0);

    // The same path through the core directly.
    let spec = ParallelArch::default();
    let mut a = crate::mech::Analysis::new(spec.model().unwrap(), Default::default()).unwrap();
    for k in 1..=10 {
        a.step_to(&[[0.0, 0.0, spec.target()[2] * (k as f64 / 10.0)]], 1)
            .unwrap();
    }
    let r = a.results();
    for (i, g) in r.gaps.iter().enumerate() {
        let name = format!("G{}", i + 1);
        assert_eq!(fmu.real(&format!("{name}.slip")), g.slip_x, "{name}");
        assert_eq!(
            fmu.real(&format!("{name}.normalForce")),
            g.normal_force,
            "{name}"
        );
        assert_eq!(
            fmu.integer(&format!("{name}.status")),
            g.status as i32,
            "{name}"
        );
    }
    assert_eq!(fmu.real("frame.Rz"), r.reactions[0][2]);
    assert!(
        fmu.real("G9.slip") > 0.01,
        "the film slides towards the arch foot"
    );
}

#[test]
fn bad_guid_and_bad_arguments_to_instantiate() {
    let (u, log) = (Unpacked::specimen("guid"), Log::default());
    let f = callbacks(&log);
    let bad = c"{00000000-0000-0000-0000-000000000000}";
    let c = unsafe {
        fmi2_instantiate(
            c"x".as_ptr(),
            FMI2_CO_SIMULATION,
            bad.as_ptr(),
            u.uri.as_ptr(),
            &f,
            0,
            0,
        )
    };
    assert!(c.is_null());
    assert!(
        log.contains(Status::Error, "GUID mismatch"),
        "{:?}",
        log.take()
    );
    let cases: [(Fmi2String, c_int, Fmi2String, Fmi2String, &str); 5] = [
        (
            std::ptr::null(),
            1,
            u.guid.as_ptr(),
            u.uri.as_ptr(),
            "instanceName is NULL",
        ),
        (
            c" ".as_ptr(),
            1,
            u.guid.as_ptr(),
            u.uri.as_ptr(),
            "instanceName is empty",
        ),
        (
            c"x".as_ptr(),
            0,
            u.guid.as_ptr(),
            u.uri.as_ptr(),
            "Co-Simulation (1) only",
        ),
        (
            c"x".as_ptr(),
            1,
            u.guid.as_ptr(),
            std::ptr::null(),
            "fmuResourceLocation is NULL",
        ),
        (
            c"x".as_ptr(),
            1,
            u.guid.as_ptr(),
            c"file:///nonexistent/resources".as_ptr(),
            "holds neither",
        ),
    ];
    for (name, kind, guid, uri, expect) in cases {
        let c = unsafe { fmi2_instantiate(name, kind, guid, uri, &f, 0, 0) };
        assert!(c.is_null(), "{expect}");
        assert!(
            log.contains(Status::Error, expect),
            "{expect}: {:?}",
            log.take()
        );
    }
    // No callbacks at all: still no crash.
    let c = unsafe {
        fmi2_instantiate(
            c"x".as_ptr(),
            1,
            bad.as_ptr(),
            u.uri.as_ptr(),
            std::ptr::null(),
            0,
            0,
        )
    };
    assert!(c.is_null());
    unsafe { fmi2_free_instance(std::ptr::null_mut()) };
}

#[test]
fn bad_calls_return_error_with_a_message_and_change_nothing() {
    let (u, log) = (Unpacked::specimen("bad"), Log::default());
    let fmu = Fmu::new(&u, &log);
    let c = fmu.c;
    let err = Status::Error.raw();
    unsafe {
        // Wrong state.
        assert_eq!(fmi2_do_step(c, 0.0, 0.1, 1), err);
        assert!(log.contains(
            Status::Error,
            "fmi2DoStep must not be called in state Instantiated"
        ));
        let mut v = 0.0;
        assert_eq!(
            fmi2_get_real(c, &0, 1, &mut v),
            err,
            "no Get before initialization mode"
        );
        // NULL instance.
        assert_eq!(fmi2_do_step(std::ptr::null_mut(), 0.0, 0.1, 1), err);
        assert_eq!(fmi2_setup_experiment(c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2_enter_initialization_mode(c), 0);
        // NULL arrays with n > 0.
        assert_eq!(fmi2_get_real(c, std::ptr::null(), 1, &mut v), err);
        assert!(log.contains(Status::Error, "vr is NULL"));
        assert_eq!(fmi2_set_real(c, &u.vr("mu"), 1, std::ptr::null()), err);
        assert!(log.contains(Status::Error, "value is NULL"));
        // n = 0 with NULL is fine.
        assert_eq!(
            fmi2_get_real(c, std::ptr::null(), 0, std::ptr::null_mut()),
            0
        );
        // Unknown value reference, wrong type.
        assert_eq!(fmi2_get_real(c, &100_000, 1, &mut v), err);
        assert!(log.contains(Status::Error, "value reference 100000 does not exist"));
        let mut i = 0;
        assert_eq!(fmi2_get_integer(c, &u.vr("mu"), 1, &mut i), err);
        assert!(log.contains(Status::Error, "(mu) is a Real, not an Integer"));
        let mut s: Fmi2String = std::ptr::null();
        assert_eq!(fmi2_get_string(c, &0, 1, &mut s), err);
        // Non-finite and out-of-range values; outputs and time cannot be set.
        for (name, value, expect) in [
            ("frame.dz", f64::NAN, "values must be finite"),
            ("film.E", f64::INFINITY, "values must be finite"),
            ("mu", -0.1, "must be ≥ 0"),
            ("G1.slip", 1.0, "is an output"),
            ("time", 1.0, "time cannot be set"),
        ] {
            assert_eq!(fmu.set_real(name, value), err, "{name}");
            assert!(
                log.contains(Status::Error, expect),
                "{name}: {:?}",
                log.take()
            );
        }
        // A set with one bad element changes none of them.
        let vrs = [u.vr("frame.dx"), u.vr("frame.dy")];
        assert_eq!(
            fmi2_set_real(c, vrs.as_ptr(), 2, [0.5, f64::NAN].as_ptr()),
            err
        );
        assert_eq!(fmu.real("frame.dx"), 0.0);
        // Unsupported functions.
        assert_eq!(
            fmi2_get_directional_derivative(c, &0, 1, &0, 1, &0.0, &mut v),
            err
        );
        assert!(log.contains(Status::Error, "providesDirectionalDerivative"));
        assert_eq!(fmi2_set_time(c, 0.0), err);
        assert!(log.contains(Status::Error, "Model Exchange"));
        // Unknown log category.
        let names = [c"nope".as_ptr()];
        assert_eq!(fmi2_set_debug_logging(c, 1, 1, names.as_ptr()), err);
        assert!(log.contains(Status::Error, "unknown log category 'nope'"));
        // A bad parameter fails ExitInitializationMode with the core's message; fixing it works.
        assert_eq!(fmu.set_real("film.E", -1.0), 0);
        assert_eq!(fmi2_exit_initialization_mode(c), err);
        assert!(
            log.contains(Status::Error, "E = -1 must be > 0"),
            "{:?}",
            log.take()
        );
        assert_eq!(fmu.set_integer("solver.incrementsPerStep", 0), 0);
        assert_eq!(fmu.set_real("film.E", 1e9), 0);
        assert_eq!(fmi2_exit_initialization_mode(c), err);
        assert!(log.contains(Status::Error, "solver.incrementsPerStep = 0 must be ≥ 1"));
        assert_eq!(fmu.set_integer("solver.incrementsPerStep", 2), 0);
        assert_eq!(fmi2_exit_initialization_mode(c), 0);
        // Parameters are fixed after initialization; steps check time and size.
        assert_eq!(fmu.set_real("film.E", 2e9), err);
        assert!(log.contains(Status::Error, "film.E is a fixed parameter"));
        assert_eq!(fmu.step(0.5, 0.1), err);
        assert!(log.contains(Status::Error, "differs from the FMU's time 0"));
        assert_eq!(fmu.step(0.0, 0.0), err);
        assert_eq!(fmu.step(0.0, f64::NAN), err);
        // CancelStep: there is never a step in progress.
        assert_eq!(fmi2_cancel_step(c), err);
    }
    assert_eq!(
        fmu.step(0.0, 0.1),
        0,
        "the instance still works after all that"
    );
}

#[test]
fn logging_follows_the_categories() {
    let (u, log) = (Unpacked::specimen("log"), Log::default());
    let fmu = Fmu::initialized(&u, &log, &[], &[]);
    fmu.ramp(0, 1, 20);
    let messages = log.take();
    assert!(
        messages
            .iter()
            .any(|(s, c, m)| *s == 0 && c == "logEvents" && m.contains("step to t = 0.05")),
        "{messages:?}"
    );
    let off = [c"logEvents".as_ptr()];
    assert_eq!(
        unsafe { fmi2_set_debug_logging(fmu.c, 0, 1, off.as_ptr()) },
        0
    );
    fmu.ramp(1, 2, 20);
    assert!(log.take().is_empty());
    assert_eq!(
        unsafe { fmi2_set_debug_logging(fmu.c, 0, 0, std::ptr::null()) },
        0
    );
    assert_eq!(fmu.step(0.0, 0.1), Status::Error.raw());
    assert!(
        log.take().is_empty(),
        "all categories off: even errors are silent"
    );
}

#[test]
fn a_step_that_cannot_converge_is_discarded_and_can_be_retried() {
    let (u, log) = (Unpacked::specimen("discard"), Log::default());
    // Small steps converge in fewer than 10 iterations; a jump to the target in one increment
    // does not, and no cut-back may rescue it.
    let settings = [
        ("solver.maxCutbacks", 0),
        ("solver.maxIterations", 10),
        ("solver.incrementsPerStep", 1),
    ];
    let fmu = Fmu::initialized(&u, &log, &[], &settings);
    fmu.ramp(0, 3, 40);
    let before = fmu.all_values();
    assert_eq!(fmu.set_real("frame.dz", -0.15), 0);
    assert_eq!(fmu.step(0.075, 0.925), Status::Discard.raw());
    assert!(
        log.contains(Status::Discard, "did not converge"),
        "{:?}",
        log.take()
    );
    // The advice names the FMU's parameters, not the command line's options.
    assert!(
        log.contains(
            Status::Discard,
            "(raise solver.incrementsPerStep or take a smaller communication step)"
        ) && !log.contains(Status::Discard, "--"),
        "{:?}",
        log.take()
    );
    let mut status = 0;
    assert_eq!(
        unsafe { fmi2_get_status(fmu.c, FMI2_DO_STEP_STATUS, &mut status) },
        0
    );
    assert_eq!(status, Status::Discard.raw());
    let mut last = f64::NAN;
    assert_eq!(
        unsafe { fmi2_get_real_status(fmu.c, FMI2_LAST_SUCCESSFUL_TIME, &mut last) },
        0
    );
    assert!((last - 0.075).abs() < 1e-15, "{last}");
    // Outputs and time are those of the last converged state (only the input changed).
    let mut after = fmu.all_values();
    let dz = u
        .variables
        .iter()
        .filter(|v| v.var_type == super::variables::VarType::Real)
        .position(|v| v.name == "frame.dz");
    after.0[dz.unwrap()] = before.0[dz.unwrap()];
    assert_eq!(after, before);
    // Retry with a smaller change from the same time.
    fmu.ramp(3, 4, 40);
    assert!((fmu.real("time") - 0.1).abs() < 1e-15);
    assert_eq!(
        unsafe { fmi2_get_status(fmu.c, FMI2_DO_STEP_STATUS, &mut status) },
        0
    );
    assert_eq!(status, 0);
}

#[test]
fn repeating_a_refused_step_identically_reports_terminated() {
    let (u, log) = (Unpacked::specimen("terminated"), Log::default());
    let settings = [
        ("solver.maxCutbacks", 0),
        ("solver.maxIterations", 6),
        ("solver.incrementsPerStep", 1),
    ];
    let fmu = Fmu::initialized(&u, &log, &[], &settings);
    let terminated = || {
        let mut value = -1;
        assert_eq!(
            unsafe { fmi2_get_boolean_status(fmu.c, FMI2_TERMINATED, &mut value) },
            0
        );
        value
    };
    assert_eq!(terminated(), 0);
    assert_eq!(fmu.set_real("frame.dz", -0.15), 0);
    assert_eq!(fmu.step(0.0, 1.0), Status::Discard.raw());
    // A first refusal leaves the retry open: what fmpy.simulate_fmu asks before repeating.
    assert_eq!(terminated(), 0);
    assert!(log.contains(Status::Discard, "asking the identical step again"));
    // The identical step again (the step size does not matter for a pseudo-time): refused, and
    // now the FMU asks the master to stop.
    assert_eq!(fmu.step(0.0, 0.5), Status::Discard.raw());
    assert_eq!(terminated(), 1);
    assert!(log.contains(Status::Discard, "fmi2Terminated) is now true"));
    // A master that ignores the Discard and goes on is refused with a message that the outputs
    // are stale, at every call.
    for _ in 0..2 {
        assert_eq!(fmu.step(1.0, 1.0), Status::Error.raw());
        assert!(log.contains(Status::Error, "its outputs are those of t = 0"));
    }
    // A smaller change still works and clears the flag.
    assert_eq!(fmu.set_real("frame.dz", -0.0001), 0);
    assert_eq!(fmu.step(0.0, 0.1), 0);
    assert_eq!(terminated(), 0);
}

#[test]
fn saved_states_restore_and_continue_identically() {
    let (u, log) = (Unpacked::specimen("state"), Log::default());
    let fmu = Fmu::initialized(&u, &log, &[("mu", 0.3)], &[("solver.incrementsPerStep", 2)]);
    fmu.ramp(0, 4, 10);
    let mut state: Fmi2FmuState = std::ptr::null_mut();
    assert_eq!(unsafe { fmi2_get_fmu_state(fmu.c, &mut state) }, 0);
    assert!(!state.is_null());
    let at_save = fmu.all_values();
    fmu.ramp(4, 10, 10);
    let reference = fmu.all_values();

    // Restore in place and continue.
    assert_eq!(unsafe { fmi2_set_fmu_state(fmu.c, state) }, 0);
    assert_eq!(fmu.all_values(), at_save);
    fmu.ramp(4, 10, 10);
    assert_eq!(fmu.all_values(), reference);

    // Serialize, and continue in a fresh instance with other parameters set.
    let mut bytes = serialized(&fmu, state);
    let size = bytes.len();
    assert_eq!(
        unsafe { fmi2_serialize_fmu_state(fmu.c, state, bytes.as_mut_ptr(), size - 1) },
        Status::Error.raw()
    );
    let other = Fmu::initialized(&u, &log, &[("film.E", 2e9)], &[]);
    let mut restored: Fmi2FmuState = std::ptr::null_mut();
    assert_eq!(
        unsafe { fmi2_de_serialize_fmu_state(other.c, bytes.as_ptr(), size, &mut restored) },
        0
    );
    assert_eq!(unsafe { fmi2_set_fmu_state(other.c, restored) }, 0);
    assert_eq!(other.all_values(), at_save);
    other.ramp(4, 10, 10);
    assert_eq!(
        other.all_values(),
        reference,
        "the deserialized state continues exactly"
    );

    // Corrupt and foreign buffers, unknown and freed handles.
    bytes[size / 2] ^= 0x5a;
    let mut s2: Fmi2FmuState = std::ptr::null_mut();
    assert_eq!(
        unsafe { fmi2_de_serialize_fmu_state(other.c, bytes.as_ptr(), size, &mut s2) },
        Status::Error.raw()
    );
    assert!(log.contains(Status::Error, "checksum"), "{:?}", log.take());
    assert!(s2.is_null());
    let junk = [7 as Fmi2Byte; 64];
    assert_eq!(
        unsafe { fmi2_de_serialize_fmu_state(other.c, junk.as_ptr(), 64, &mut s2) },
        Status::Error.raw()
    );
    assert!(log.contains(Status::Error, "magic"));
    assert_eq!(
        unsafe { fmi2_set_fmu_state(other.c, state) },
        Status::Error.raw(),
        "a state of another instance"
    );
    assert!(log.contains(Status::Error, "was not created by this instance"));
    assert_eq!(unsafe { fmi2_free_fmu_state(fmu.c, &mut state) }, 0);
    assert!(state.is_null());
    assert_eq!(
        unsafe { fmi2_free_fmu_state(fmu.c, &mut state) },
        0,
        "freeing NULL is ignored"
    );
    assert_eq!(unsafe { fmi2_free_fmu_state(other.c, &mut restored) }, 0);
}

#[test]
fn reset_returns_to_the_instantiated_state() {
    let (u, log) = (Unpacked::specimen("reset"), Log::default());
    let fmu = Fmu::initialized(&u, &log, &[("mu", 0.5), ("film.E", 2e9)], &[]);
    fmu.ramp(0, 2, 20);
    assert_eq!(unsafe { fmi2_reset(fmu.c) }, 0);
    unsafe {
        assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2_enter_initialization_mode(fmu.c), 0);
    }
    assert_eq!(fmu.real("time"), 0.0);
    assert_eq!(fmu.real("mu"), 0.2);
    assert_eq!(fmu.real("film.E"), 1e9);
    assert_eq!(fmu.real("frame.dz"), 0.0);
    assert_eq!(fmu.real("G9.slip"), 0.0);
    assert_eq!(unsafe { fmi2_exit_initialization_mode(fmu.c) }, 0);
    fmu.ramp(0, 1, 20);
}

#[test]
fn instances_on_several_threads_are_independent() {
    let u = Unpacked::specimen("threads");
    let run = |mu: f64| {
        let log = Log::default();
        let fmu = Fmu::initialized(&u, &log, &[("mu", mu)], &[("solver.incrementsPerStep", 1)]);
        fmu.ramp(0, 10, 10);
        fmu.all_values()
    };
    let alone = [run(0.1), run(0.4)];
    let together = std::thread::scope(|s| {
        let a = s.spawn(|| run(0.1));
        let b = s.spawn(|| run(0.4));
        [a.join().unwrap(), b.join().unwrap()]
    });
    assert_eq!(alone, together);
    assert_ne!(alone[0], alone[1]);
}

#[test]
fn a_panic_becomes_fatal_and_the_instance_is_closed() {
    let (u, log) = (Unpacked::specimen("panic"), Log::default());
    let fmu = Fmu::new(&u, &log);
    // SAFETY: `fmu.c` is a live instance used by this thread only.
    let status =
        unsafe { super::guard::with_instance(fmu.c, "fmi2Test", allowed::ANY, |_| panic!("boom")) };
    assert_eq!(status, Status::Fatal.raw());
    assert!(log.contains(Status::Fatal, "internal error (panic): boom"));
    assert_eq!(
        unsafe { fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0) },
        Status::Error.raw()
    );
    assert!(log.contains(Status::Error, "an earlier call failed fatally"));
}

/// The `(timestep, file)` entries of a `.pvd` (the format `vtk::collection` writes).
fn pvd_entries(path: &std::path::Path) -> Vec<(f64, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.starts_with("<?xml") && text.trim_end().ends_with("</VTKFile>"));
    let attribute = |line: &str, name: &str| -> String {
        let start = line.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
        line[start..][..line[start..].find('"').unwrap()].to_string()
    };
    text.lines()
        .filter(|l| l.starts_with("<DataSet "))
        .map(|l| {
            (
                attribute(l, "timestep").parse().unwrap(),
                attribute(l, "file"),
            )
        })
        .collect()
}

/// Checks that `dir` holds the listed `.vtu` files, each a complete VTK file.
fn assert_vtu_files(dir: &std::path::Path, entries: &[(f64, String)]) {
    for (_, file) in entries {
        let bytes = std::fs::read(dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        let head = String::from_utf8_lossy(&bytes[..bytes.len().min(300)]).into_owned();
        assert!(head.contains("<UnstructuredGrid"), "{file}");
        assert!(bytes.ends_with(b"</VTKFile>\n"), "{file} is complete");
    }
}

/// The `.pvd` entries of the film and the gaps in `dir`, checked to list the same states.
fn film_and_gap_entries(dir: &std::path::Path) -> Vec<(f64, String)> {
    let film = pvd_entries(&dir.join("ParallelArch_film.pvd"));
    let gaps = pvd_entries(&dir.join("ParallelArch_gaps.pvd"));
    assert_eq!(film.len(), gaps.len());
    for ((t, f), (tg, g)) in film.iter().zip(&gaps) {
        assert_eq!(
            (t, g.as_str()),
            (tg, f.replace("_film_", "_gaps_").as_str())
        );
    }
    assert_vtu_files(dir, &film);
    assert_vtu_files(dir, &gaps);
    film
}

#[test]
fn results_directory_writes_every_step_as_vtk() {
    let (u, log) = (Unpacked::specimen("vtk"), Log::default());
    // Missing (two levels) and with a space: created at initialization.
    let dir = u.dir.parent().unwrap().join("vtk out/run 1");
    let fmu = Fmu::new(&u, &log);
    assert_eq!(fmu.initialized_with_output(&dir), 0, "{:?}", log.take());
    assert_eq!(fmu.string("results.directory"), dir.to_str().unwrap());
    fmu.ramp(0, 3, 10);
    let entries = film_and_gap_entries(&dir);
    let files: Vec<&str> = entries.iter().map(|(_, f)| f.as_str()).collect();
    assert_eq!(
        files,
        [
            "ParallelArch_film_0000.vtu",
            "ParallelArch_film_0001.vtu",
            "ParallelArch_film_0002.vtu",
            "ParallelArch_film_0003.vtu"
        ]
    );
    for (k, (t, _)) in entries.iter().enumerate() {
        assert!((t - k as f64 / 10.0).abs() < 1e-12, "entry {k}: t = {t}");
    }
    assert_eq!(entries[3].0, fmu.real("time"));
    assert!(!dir.join("ParallelArch_film.pvd.tmp").exists());
    // The default encoding is binary (raw appended data).
    let last = std::fs::read(dir.join("ParallelArch_film_0003.vtu")).unwrap();
    assert!(
        last.windows(29)
            .any(|w| w == b"<AppendedData encoding=\"raw\">")
    );
    // The parameter is fixed once initialized.
    assert_eq!(
        fmu.set_string("results.directory", "elsewhere"),
        Status::Error.raw()
    );
    assert!(log.contains(Status::Error, "results.directory is a fixed parameter"));
}

#[test]
fn vtk_format_ascii_writes_text_and_an_unknown_format_is_refused() {
    let (u, log) = (Unpacked::specimen("vtk ascii"), Log::default());
    let dir = u.dir.parent().unwrap().join("vtk ascii");
    let fmu = Fmu::new(&u, &log);
    unsafe {
        assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2_enter_initialization_mode(fmu.c), 0);
    }
    assert_eq!(fmu.string("results.vtkFormat"), "binary");
    assert_eq!(
        fmu.set_string("results.vtkFormat", "Binary"),
        Status::Error.raw()
    );
    assert!(log.contains(Status::Error, "unknown VTK format 'Binary'"));
    assert_eq!(fmu.string("results.vtkFormat"), "binary", "unchanged");
    assert_eq!(fmu.set_string("results.vtkFormat", "ascii"), 0);
    assert_eq!(
        fmu.set_string("results.directory", dir.to_str().unwrap()),
        0
    );
    assert_eq!(unsafe { fmi2_exit_initialization_mode(fmu.c) }, 0);
    fmu.ramp(0, 1, 10);
    for file in ["ParallelArch_film_0001.vtu", "ParallelArch_gaps_0001.vtu"] {
        let text = std::fs::read_to_string(dir.join(file)).unwrap();
        assert!(
            text.contains("format=\"ascii\"") && !text.contains("AppendedData"),
            "{file}"
        );
    }
    assert_eq!(film_and_gap_entries(&dir).len(), 2);
}

#[test]
fn strings_are_copied_on_set_and_stay_valid_until_the_next_get() {
    let (u, log) = (Unpacked::specimen("strings"), Log::default());
    let fmu = Fmu::new(&u, &log);
    let vr = u.vr("results.directory");
    unsafe {
        assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2_enter_initialization_mode(fmu.c), 0);
    }
    assert_eq!(
        fmu.string("results.directory"),
        "",
        "start value: no output"
    );
    {
        let value = CString::new("out/a").unwrap();
        assert_eq!(
            unsafe { fmi2_set_string(fmu.c, &vr, 1, &value.as_ptr()) },
            0
        );
    } // the caller's string is gone: the instance holds a copy
    let (mut first, mut second): (Fmi2String, Fmi2String) = (std::ptr::null(), std::ptr::null());
    let vrs = [vr, vr];
    let mut both = [std::ptr::null(); 2];
    assert_eq!(
        unsafe { fmi2_get_string(fmu.c, vrs.as_ptr(), 2, both.as_mut_ptr()) },
        0
    );
    assert_eq!(unsafe { fmi2_get_string(fmu.c, &vr, 1, &mut first) }, 0);
    // Other calls (a set, a get of another type) leave the returned pointer valid.
    assert_eq!(fmu.set_string("results.directory", "out/b"), 0);
    assert_eq!(fmu.real("film.E"), 1e9);
    assert_eq!(unsafe { CStr::from_ptr(first) }.to_str().unwrap(), "out/a");
    assert_eq!(unsafe { fmi2_get_string(fmu.c, &vr, 1, &mut second) }, 0);
    assert_eq!(unsafe { CStr::from_ptr(second) }.to_str().unwrap(), "out/b");
    // NULL strings, wrong types, outputs are refused and change nothing.
    let null: Fmi2String = std::ptr::null();
    let err = Status::Error.raw();
    assert_eq!(unsafe { fmi2_set_string(fmu.c, &vr, 1, &null) }, err);
    assert!(log.contains(Status::Error, "value[0] is NULL"));
    let text = c"x".as_ptr();
    assert_eq!(
        unsafe { fmi2_set_string(fmu.c, &u.vr("film.E"), 1, &text) },
        err
    );
    assert!(log.contains(Status::Error, "(film.E) is a Real, not a String"));
    assert_eq!(fmu.string("results.directory"), "out/b");
    let mut p: Fmi2String = std::ptr::null();
    assert_eq!(unsafe { fmi2_get_string(fmu.c, &0, 1, &mut p) }, err);
    assert!(log.contains(Status::Error, "(time) is a Real, not a String"));
}

#[test]
fn a_restored_state_continues_the_pvd_and_reset_starts_it_again() {
    let (u, log) = (Unpacked::specimen("vtk state"), Log::default());
    let dir = u.dir.parent().unwrap().join("vtk");
    let fmu = Fmu::new(&u, &log);
    assert_eq!(fmu.initialized_with_output(&dir), 0);
    fmu.ramp(0, 1, 10);
    let mut state: Fmi2FmuState = std::ptr::null_mut();
    assert_eq!(unsafe { fmi2_get_fmu_state(fmu.c, &mut state) }, 0);
    fmu.ramp(1, 4, 10);
    assert_eq!(film_and_gap_entries(&dir).len(), 5);
    let long_branch = std::fs::read(dir.join("ParallelArch_film_0002.vtu")).unwrap();

    // Back to t = 0.1 (step 1) and another input: step 2 again, file 0002 rewritten.
    assert_eq!(unsafe { fmi2_set_fmu_state(fmu.c, state) }, 0);
    assert_eq!(fmu.set_real("frame.dz", -0.001), 0);
    assert_eq!(fmu.step(0.1, 0.1), 0);
    let entries = film_and_gap_entries(&dir);
    let files: Vec<&str> = entries.iter().map(|(_, f)| f.as_str()).collect();
    assert_eq!(
        files,
        [
            "ParallelArch_film_0000.vtu",
            "ParallelArch_film_0001.vtu",
            "ParallelArch_film_0002.vtu"
        ]
    );
    assert!((entries[2].0 - 0.2).abs() < 1e-12);
    assert_ne!(
        std::fs::read(dir.join("ParallelArch_film_0002.vtu")).unwrap(),
        long_branch
    );
    assert_eq!(unsafe { fmi2_free_fmu_state(fmu.c, &mut state) }, 0);

    // Reset: the parameter is back to "" (no output) and the list starts again.
    assert_eq!(unsafe { fmi2_reset(fmu.c) }, 0);
    assert_eq!(fmu.initialized_with_output(&dir), 0);
    assert_eq!(
        film_and_gap_entries(&dir),
        [(0.0, "ParallelArch_film_0000.vtu".to_string())]
    );
    assert_eq!(unsafe { fmi2_reset(fmu.c) }, 0);
    unsafe {
        assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2_enter_initialization_mode(fmu.c), 0);
    }
    assert_eq!(fmu.string("results.directory"), "");
}

#[test]
fn a_failed_write_is_a_warning_and_the_step_stands() {
    let (u, log) = (Unpacked::specimen("vtk fail"), Log::default());
    // A directory below a regular file cannot be created.
    let blocker = u.dir.parent().unwrap().join("not a directory");
    std::fs::write(&blocker, "x").unwrap();
    let fmu = Fmu::new(&u, &log);
    let warning = Status::Warning.raw();
    assert_eq!(fmu.initialized_with_output(&blocker.join("vtk")), warning);
    let messages = log.take();
    assert!(
        messages.iter().any(|(s, c, m)| *s == warning
            && c == "logStatusWarning"
            && m.starts_with("fmi2ExitInitializationMode: VTK output at t = 0 failed")
            && m.contains("not a directory")),
        "{messages:?}"
    );
    assert_eq!(fmu.set_real("frame.dz", -0.01), 0);
    assert_eq!(fmu.step(0.0, 0.1), warning);
    assert!(log.contains(Status::Warning, "VTK output at t = 0.1 failed"));
    assert_eq!(fmu.real("time"), 0.1, "the step is kept");
    assert!(fmu.real("G9.slip") != 0.0);
    let mut status = -1;
    assert_eq!(
        unsafe { fmi2_get_status(fmu.c, FMI2_DO_STEP_STATUS, &mut status) },
        0
    );
    assert_eq!(status, 0);
    assert_eq!(fmu.step(0.1, 0.1), warning, "and the next step is taken");
}

#[test]
fn friction_law_parameter_gives_every_gap_the_papers_law() {
    let (u, log) = (Unpacked::specimen("law"), Log::default());
    let fmu = Fmu::new(&u, &log);
    unsafe {
        assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2_enter_initialization_mode(fmu.c), 0);
    }
    assert_eq!(fmu.string("frictionLaw"), "isotropic");
    assert_eq!(fmu.set_string("frictionLaw", "x-only"), Status::Error.raw());
    assert!(log.contains(Status::Error, "frictionLaw: unknown friction law 'x-only'"));
    assert_eq!(
        fmu.string("frictionLaw"),
        "isotropic",
        "a refused value changes nothing"
    );
    assert_eq!(fmu.set_string("frictionLaw", "sliding-direction"), 0);
    assert_eq!(
        unsafe { fmi2_exit_initialization_mode(fmu.c) },
        0,
        "{:?}",
        log.take()
    );
    fmu.ramp(0, 2, 20);

    // The same path through the core, with the law set in the specimen and with the cone.
    let run = |friction_law| {
        let spec = ParallelArch {
            friction_law,
            ..ParallelArch::default()
        };
        let mut a = crate::mech::Analysis::new(spec.model().unwrap(), Default::default()).unwrap();
        for k in 1..=2 {
            a.step_to(&[[0.0, 0.0, spec.target()[2] * (k as f64 / 20.0)]], 10)
                .unwrap();
        }
        a.results().gaps[0]
    };
    let paper = run(crate::mech::FrictionLaw::SlidingDirection);
    // The FMU reports the force on the film, the opposite of the gap's internal force.
    assert_eq!(fmu.real("G1.frictionX"), -paper.friction[0]);
    assert_eq!(fmu.real("G1.frictionY"), -paper.friction[1]);
    assert_eq!(fmu.real("G1.slipY"), paper.slip_y);
    let cone = run(crate::mech::FrictionLaw::Isotropic);
    assert!(
        (cone.friction[1] - paper.friction[1]).abs() > 1.0,
        "{cone:?} {paper:?}"
    );
}

#[test]
fn wrinkling_parameter_switches_the_film_and_counts_its_elements() {
    // film.wrinkling starts from the model (false for the specimen). Initial outputs of the
    // undeformed film (ε = 0, so ε̂ = D⁻¹σ0): the 0.5 MPa biaxial prestress is taut; no prestress
    // is slack everywhere; σ0 = (0.5, −0.1) MPa is wrinkled everywhere (σ2 < 0 needs ê2 < −ν ê1).
    let u = Unpacked::specimen("wrinkling");
    let counts = |wrinkling: bool, prestress: [f64; 2]| {
        let log = Log::default();
        let fmu = Fmu::new(&u, &log);
        unsafe {
            assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
            assert_eq!(fmi2_enter_initialization_mode(fmu.c), 0);
            assert_eq!(
                fmi2_set_boolean(fmu.c, &u.vr("film.wrinkling"), 1, &c_int::from(wrinkling)),
                0
            );
        }
        assert_eq!(fmu.set_real("film.prestressX", prestress[0]), 0);
        assert_eq!(fmu.set_real("film.prestressY", prestress[1]), 0);
        assert_eq!(unsafe { fmi2_exit_initialization_mode(fmu.c) }, 0);
        [
            fmu.integer("film.wrinkledElements"),
            fmu.integer("film.slackElements"),
        ]
    };
    let (log, mut start) = (Log::default(), 1);
    let fmu = Fmu::initialized(&u, &log, &[], &[]);
    assert_eq!(
        unsafe { fmi2_get_boolean(fmu.c, &u.vr("film.wrinkling"), 1, &mut start) },
        0
    );
    assert_eq!(start, 0);
    assert_eq!(counts(true, [0.5e6, 0.5e6]), [0, 0]);
    assert_eq!(counts(true, [0.0, 0.0]), [0, 200]);
    assert_eq!(counts(true, [0.5e6, -0.1e6]), [200, 0]);
    assert_eq!(counts(false, [0.5e6, -0.1e6]), [0, 0]);
}

// ---------------------------------------------------------------- issue 12: never fmi2OK with a wrong answer

/// The serialized state `bytes` changed by `f`, with its length and CRC recomputed (a forgery
/// that passes the format checks).
fn forge(bytes: &[u8], guid: &str, f: impl FnOnce(&mut super::state::Snapshot)) -> Vec<u8> {
    let mut s = super::state::deserialize(bytes, guid).unwrap();
    f(&mut s);
    super::state::serialize(&s, guid)
}

/// A serialized state of the specimen after 4 of 10 ramp steps.
fn serialized_after_ramp(fmu: &Fmu) -> Vec<u8> {
    fmu.ramp(0, 4, 10);
    let mut state: Fmi2FmuState = std::ptr::null_mut();
    assert_eq!(unsafe { fmi2_get_fmu_state(fmu.c, &mut state) }, 0);
    let bytes = serialized(fmu, state);
    assert_eq!(unsafe { fmi2_free_fmu_state(fmu.c, &mut state) }, 0);
    bytes.iter().map(|&b| b as u8).collect()
}

fn deserialize_status(fmu: &Fmu, bytes: &[u8]) -> (c_int, Fmi2FmuState) {
    let mut s: Fmi2FmuState = std::ptr::null_mut();
    let status =
        unsafe { fmi2_de_serialize_fmu_state(fmu.c, bytes.as_ptr().cast(), bytes.len(), &mut s) };
    (status, s)
}

/// `fmi2DeSerializeFMUstate` of `bytes` returns fmi2Error, no state, and logs `expected`.
fn assert_deserialization_refused(fmu: &Fmu, bytes: &[u8], expected: &str) {
    let (status, s) = deserialize_status(fmu, bytes);
    assert_eq!(status, Status::Error.raw(), "{expected}");
    assert!(s.is_null());
    assert!(
        fmu.log.contains(Status::Error, expected),
        "{expected}: {:?}",
        fmu.log.take()
    );
    fmu.log.take();
}

/// Issue 12, item 3: forged states (scaled displacements with length and CRC recomputed, sizes
/// that do not fit, gap statuses that contradict the displacements, μ out of range) are refused
/// by fmi2DeSerializeFMUstate itself, with a message; a genuine one is accepted.
#[test]
fn forged_states_are_refused_at_deserialization_with_a_message() {
    let (u, log) = (Unpacked::specimen("forged"), Log::default());
    let fmu = Fmu::initialized(&u, &log, &[("mu", 0.2)], &[]);
    let bytes = serialized_after_ramp(&fmu);
    let guid = u.guid.to_str().unwrap();
    let (ok, s) = deserialize_status(&fmu, &bytes);
    assert_eq!(ok, 0, "{:?}", log.take());
    assert_eq!(unsafe { fmi2_set_fmu_state(fmu.c, s) }, 0);

    type Forgery = Box<dyn Fn(&mut super::state::Snapshot)>;
    let analysis = |f: fn(&mut crate::mech::AnalysisState)| -> Forgery {
        Box::new(move |s| f(s.analysis.as_mut().unwrap()))
    };
    let cases: Vec<(Forgery, &str)> = vec![
        (
            analysis(|a| a.displacement.iter_mut().for_each(|v| *v *= 1e150)),
            "beyond",
        ),
        (analysis(|a| a.displacement[7] = 50.0), "displacement [7]"),
        (analysis(|a| a.plastic_slip[0][0] = 1e9), "slip history"),
        (
            analysis(|a| a.boundary[0][2] = -1e100),
            "group displacement",
        ),
        (
            analysis(|a| a.displacement.truncate(30)),
            "30 displacements",
        ),
        (
            analysis(|a| a.status.push(crate::mech::GapStatus::Open)),
            "10 gap statuses",
        ),
        (
            analysis(|a| a.last_increment = vec![0.0; 5]),
            "last increment",
        ),
        (
            analysis(|a| a.friction[2] = 1e6),
            "friction coefficient of gap 'G3'",
        ),
        (
            analysis(|a| a.status[0] = crate::mech::GapStatus::Open),
            "status of gap 'G1' is Open",
        ),
        (
            analysis(|a| a.status[8] = crate::mech::GapStatus::Slip),
            "status of gap 'G9' is Slip",
        ),
        (
            Box::new(|s| s.vtk_steps.push((0.5, s.steps + 1))),
            "VTK output beyond its 4 steps",
        ),
    ];
    for (f, expected) in cases {
        assert_deserialization_refused(&fmu, &forge(&bytes, guid, f), expected);
    }
    // The instance is untouched and steps on.
    fmu.ramp(4, 5, 10);
}

/// Issue 12, smaller item: fmi2FreeFMUstate(c, NULL) is a NULL argument (fmi2Error, docs/fmu.md);
/// a pointer to a NULL state is ignored (FMI 2.0 §2.1.8).
#[test]
fn free_fmu_state_with_a_null_pointer_is_an_error() {
    let (u, log) = (Unpacked::specimen("freenull"), Log::default());
    let fmu = Fmu::initialized(&u, &log, &[], &[]);
    let status = unsafe { fmi2_free_fmu_state(fmu.c, std::ptr::null_mut()) };
    assert_eq!(status, Status::Error.raw());
    assert!(log.contains(Status::Error, "FMUstate"), "{:?}", log.take());
    let mut none: Fmi2FmuState = std::ptr::null_mut();
    assert_eq!(unsafe { fmi2_free_fmu_state(fmu.c, &mut none) }, 0);
}

/// Issue 12, item 1: a huge but finite input never gives fmi2OK with NaN outputs: the step is
/// refused (fmi2Error or fmi2Discard) and the outputs stay those of the last converged state.
#[test]
fn huge_finite_input_is_refused_never_ok_with_nan() {
    let (u, log) = (Unpacked::specimen("huge"), Log::default());
    let fmu = Fmu::initialized(&u, &log, &[("mu", 0.2)], &[]);
    fmu.ramp(0, 2, 20);
    assert_eq!(fmu.set_real("frame.dz", -1e100), 0);
    let before = fmu.all_values();
    let status = fmu.step(0.1, 0.05);
    assert!(
        status == Status::Error.raw() || status == Status::Discard.raw(),
        "status {status}: {:?}",
        log.take()
    );
    assert_eq!(
        fmu.all_values().0.iter().filter(|v| !v.is_finite()).count(),
        0
    );
    assert_eq!(fmu.all_values(), before);
}

/// Issue 12, item 2 through the FMU: a model with a rigid-body mode is refused at
/// initialization with its nodes and free motion named; no step runs.
#[test]
fn singular_model_is_refused_before_any_step() {
    let mut model = ParallelArch::default().model().unwrap();
    model.groups.clear(); // the frame held the film: now it floats
    model.name = "Floating".into();
    let err = model.validate().unwrap_err().to_string();
    // The symmetry planes hold x and y, the gaps (on the arch line x = 0.4 m, z = 0.3 m) the
    // rest, except a rotation about that line.
    assert!(
        err.contains(
            "(121 nodes) can rotate about an axis along Y through (0.4000, 0.5000, 0.3000)"
        ),
        "{err}"
    );
    // An FMU cannot be made of it: the description (what fmu-pack writes) refuses it too.
    assert!(
        describe(&Source::Model(model))
            .unwrap_err()
            .contains("can rotate")
    );
}

/// Issue 8 through the FMU: `top.pressure` and `lamp.Fz` inputs (starts from the model) and the
/// `gravity.*` / `film.density` parameters load a circular membrane. The rim reaction balances
/// them exactly (the pressure's resultant on a surface with a fixed rim is `p` times the rim's
/// projected area, `A_polygon`), equals the core's, and FMU states round-trip the load levels.
#[test]
fn pressure_and_force_inputs_load_the_membrane_and_states_keep_the_load_levels() {
    use super::variables::{Causality, Value};
    use crate::mech::model::ForceSet;
    use crate::mech::scenarios::CircularMembrane;
    use crate::mech::{Analysis, LoadLevels, SolverSettings};

    let membrane = CircularMembrane {
        radius: 1.0,
        rings: 4,
        material: crate::mech::Material {
            prestress: [1e6, 1e6, 0.0],
            density: 1750.0,
            ..ParallelArch::default().material
        },
        pressure: 100.0,
    };
    let mut model = membrane.model().unwrap();
    model.loads.forces.push(ForceSet {
        name: "lamp".into(),
        nodes: vec![0],
        force: [0.0, 0.0, -2.0],
    });
    let (u, log) = (
        Unpacked::new("pressure", Source::Model(model.clone())),
        Log::default(),
    );
    let var = |name: &str| u.variables.iter().find(|v| v.name == name).unwrap();
    assert_eq!(var("top.pressure").causality, Causality::Input);
    assert_eq!(var("top.pressure").start, Some(Value::Real(100.0)));
    assert_eq!(var("lamp.Fz").start, Some(Value::Real(-2.0)));
    assert_eq!(var("gravity.z").start, Some(Value::Real(-9.81)));
    assert_eq!(var("film.density").causality, Causality::Parameter);

    let fmu = Fmu::initialized(&u, &log, &[], &[("solver.incrementsPerStep", 2)]);
    assert_eq!(fmu.real("rim.Rz"), 0.0, "the analysis starts unloaded");
    assert_eq!(fmu.set_real("top.pressure", 50.0), 0);
    assert_eq!(fmu.step(0.0, 0.5), 0, "{:?}", log.take());
    let sides = 6.0 * membrane.rings as f64;
    let area = 0.5 * sides * (std::f64::consts::TAU / sides).sin();
    let mass = 1750.0 * membrane.material.thickness * area;
    let balance = -(50.0 * area - 9.81 * mass - 2.0);
    let rz = fmu.real("rim.Rz");
    assert!(
        (rz - balance).abs() < 1e-6 * balance.abs(),
        "{rz} vs {balance}"
    );

    // The core, driven the same way, gives the same numbers.
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    let levels = LoadLevels {
        pressure: vec![50.0],
        force: vec![[0.0, 0.0, -2.0]],
        gravity: [0.0, 0.0, -9.81],
    };
    analysis
        .step_to_with_loads(&[[0.0; 3]], &levels, 2)
        .unwrap();
    assert_eq!(analysis.results().reactions[0][2], rz);

    // A state saved here continues exactly, in place and after (de)serialization.
    let mut state: Fmi2FmuState = std::ptr::null_mut();
    assert_eq!(unsafe { fmi2_get_fmu_state(fmu.c, &mut state) }, 0);
    let at_save = fmu.all_values();
    assert_eq!(fmu.set_real("top.pressure", 100.0), 0);
    assert_eq!(fmu.step(0.5, 0.5), 0);
    let reference = fmu.all_values();
    assert_eq!(unsafe { fmi2_set_fmu_state(fmu.c, state) }, 0);
    assert_eq!(fmu.all_values(), at_save, "inputs and load levels restored");
    assert_eq!(fmu.set_real("top.pressure", 100.0), 0);
    assert_eq!(fmu.step(0.5, 0.5), 0);
    assert_eq!(fmu.all_values(), reference);
    let bytes = serialized(&fmu, state);
    let size = bytes.len();
    let other = Fmu::initialized(&u, &log, &[], &[("solver.incrementsPerStep", 2)]);
    let mut restored: Fmi2FmuState = std::ptr::null_mut();
    assert_eq!(
        unsafe { fmi2_de_serialize_fmu_state(other.c, bytes.as_ptr(), size, &mut restored) },
        0,
        "{:?}",
        log.take()
    );
    assert_eq!(unsafe { fmi2_set_fmu_state(other.c, restored) }, 0);
    assert_eq!(other.set_real("top.pressure", 100.0), 0);
    assert_eq!(other.step(0.5, 0.5), 0);
    assert_eq!(other.all_values(), reference, "the load level was restored");

    // A forged state whose load levels do not fit the model is refused.
    let raw: Vec<u8> = bytes.iter().map(|&b| b as u8).collect();
    let forged = forge(&raw, u.guid.to_str().unwrap(), |s| {
        s.analysis.as_mut().unwrap().loads.pressure.push(1.0)
    });
    let (status, _) = deserialize_status(&other, &forged);
    assert_eq!(status, Status::Error.raw());
    assert!(
        log.contains(Status::Error, "pressure levels"),
        "{:?}",
        log.take()
    );

    // Non-finite input: fmi2Error naming the variable, nothing changes.
    assert_eq!(fmu.set_real("top.pressure", f64::NAN), Status::Error.raw());
    assert!(log.contains(Status::Error, "top.pressure = NaN"));

    // Gravity off (a parameter): the rim carries the pressure and the lamp only.
    let weightless = Fmu::initialized(&u, &log, &[("gravity.z", 0.0)], &[]);
    assert_eq!(weightless.set_real("top.pressure", 50.0), 0);
    assert_eq!(weightless.step(0.0, 1.0), 0);
    let balance = -(50.0 * area - 2.0);
    let rz = weightless.real("rim.Rz");
    assert!(
        (rz - balance).abs() < 1e-6 * balance.abs(),
        "{rz} vs {balance}"
    );
    assert_eq!(unsafe { fmi2_free_fmu_state(fmu.c, &mut state) }, 0);
    assert_eq!(unsafe { fmi2_free_fmu_state(other.c, &mut restored) }, 0);
}

/// Output points and element-set summaries of the model file are FMU outputs equal to the
/// core's (`<point>.ux/.uy/.uz`, `<set>.maxPrincipalStress`, …).
#[test]
fn output_points_and_set_summaries_are_outputs_equal_to_the_core() {
    use super::variables::{Causality, SummaryQuantity};
    use crate::mech::scenarios::CircularMembrane;
    use crate::mech::{Analysis, LoadLevels, SolverSettings};

    let membrane = CircularMembrane {
        radius: 1.0,
        rings: 4,
        material: crate::mech::Material {
            prestress: [1e6, 1e6, 0.0],
            ..ParallelArch::default().material
        },
        pressure: 100.0,
    };
    let model = membrane.model().unwrap();
    let (u, log) = (
        Unpacked::new("outputs", Source::Model(model.clone())),
        Log::default(),
    );
    for name in [
        "centre.uz",
        "disc.maxPrincipalStress",
        "disc.compressedArea",
    ] {
        let v = u.variables.iter().find(|v| v.name == name).unwrap();
        assert_eq!(v.causality, Causality::Output, "{name}");
    }
    let fmu = Fmu::initialized(&u, &log, &[], &[("solver.incrementsPerStep", 2)]);
    assert_eq!(fmu.set_real("top.pressure", 80.0), 0);
    assert_eq!(fmu.step(0.0, 1.0), 0, "{:?}", log.take());

    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    let levels = LoadLevels {
        pressure: vec![80.0],
        force: vec![],
        gravity: model.loads.gravity,
    };
    analysis
        .step_to_with_loads(&[[0.0; 3]], &levels, 2)
        .unwrap();
    let results = analysis.results();
    let uz = fmu.real("centre.uz");
    assert!(uz > 1e-3, "the centre rises under pressure: {uz}");
    assert_eq!(uz, analysis.node_displacement(0).z);
    for (quantity, suffix, _, _) in SummaryQuantity::ALL {
        assert_eq!(
            fmu.real(&format!("disc.{suffix}")),
            quantity.of(&results.sets[0]),
            "{suffix}"
        );
    }
}

/// A step whose result leaves the model's assumptions (stress above `yield_stress`) returns
/// fmi2Warning with the reason in the log, and keeps its state and outputs; a model that looks
/// wrong (E in MPa) warns at fmi2ExitInitializationMode.
#[test]
fn result_beyond_the_yield_stress_is_a_warning_not_an_error() {
    let mut model = ParallelArch::default().model().unwrap();
    model.material.yield_stress = Some(15e6);
    let (u, log) = (
        Unpacked::new("yield", Source::Model(model.clone())),
        Log::default(),
    );
    let fmu = Fmu::initialized(&u, &log, &[], &[]);
    assert_eq!(fmu.set_real("frame.dz", -0.15), 0);
    assert_eq!(fmu.step(0.0, 1.0), Status::Warning.raw());
    assert!(
        log.contains(
            Status::Warning,
            "above the material's yield_stress 15.000 MPa"
        ),
        "{:?}",
        log.take()
    );
    assert!(fmu.real("film.maxEquivalentStress") > 15e6);
    // The step stood: the next one continues from t = 1.
    assert_eq!(fmu.set_real("frame.dz", -0.14), 0);
    assert_ne!(fmu.step(1.0, 1.0), Status::Error.raw());
}

#[test]
fn solver_threads_is_read_back_refused_out_of_range_by_name_and_leaves_the_outputs_unchanged() {
    let (u, log) = (Unpacked::specimen("threads"), Log::default());
    // Out of range: ExitInitializationMode fails naming the parameter.
    for (value, expect) in [
        (-1, "solver.threads = -1 must be ≥ 0"),
        (100_000, "solver.threads = 100000 must be at most 256"),
    ] {
        let fmu = Fmu::new(&u, &log);
        unsafe {
            assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
            assert_eq!(fmi2_enter_initialization_mode(fmu.c), 0);
        }
        assert_eq!(fmu.set_integer("solver.threads", value), 0);
        assert_eq!(
            unsafe { fmi2_exit_initialization_mode(fmu.c) },
            Status::Error.raw()
        );
        assert!(log.contains(Status::Error, expect), "{:?}", log.take());
    }
    // 0 (automatic, the start value) and 1 against 2 and 3 threads: the same bits throughout.
    let run = |threads: i32| {
        let fmu = Fmu::initialized(&u, &log, &[], &[("solver.threads", threads)]);
        assert_eq!(fmu.integer("solver.threads"), threads);
        fmu.ramp(0, 3, 20);
        fmu.all_values()
    };
    let serial = run(1);
    assert_eq!(
        Fmu::initialized(&u, &log, &[], &[]).integer("solver.threads"),
        0,
        "start value: automatic"
    );
    for threads in [0, 2, 3] {
        let mut values = run(threads);
        let at = u
            .variables
            .iter()
            .filter(|v| v.var_type == super::variables::VarType::Integer)
            .position(|v| v.name == "solver.threads")
            .unwrap();
        values.1[at] = 1;
        assert_eq!(values, serial, "{threads} threads");
    }
}

/// A model without a free DOF (issue 17: how single elements are verified) initializes and
/// steps: `examples/driven_gap.json` driven down 2 mm and along x sticks at `k_s·dx`, slips at
/// `μN` = 30 N beyond 3 mm and sticks again on the way back, as the core says
/// (`tests/supports.rs`); the film feels the opposite of the gap's friction force and the drive
/// carries both contact forces. Its FMU state round trip keeps the slip history.
#[test]
fn a_model_without_free_dofs_steps_its_gap_through_stick_and_slip() {
    let model =
        crate::mech::Model::from_json(include_str!("../../examples/driven_gap.json")).unwrap();
    let (u, log) = (
        Unpacked::new("prescribed", Source::Model(model)),
        Log::default(),
    );
    let fmu = Fmu::initialized(&u, &log, &[], &[("solver.incrementsPerStep", 2)]);
    let path = [
        (0.0, 1, 0.0),
        (1e-3, 1, 10.0),
        (2e-3, 1, 20.0),
        (4e-3, 2, 30.0),
        (6e-3, 2, 30.0),
        (5e-3, 1, 20.0),
    ];
    let mut saved = None;
    for (k, &(dx, status, friction)) in path.iter().enumerate() {
        assert_eq!(fmu.set_real("Drive.dx", dx), 0);
        assert_eq!(fmu.set_real("Drive.dz", -2e-3), 0);
        assert_eq!(fmu.step(k as f64, 1.0), 0, "{:?}", log.take());
        let at = format!("step {k}, dx = {dx}");
        assert_eq!(fmu.integer("G.status"), status, "{at}");
        assert!((fmu.real("G.normalForce") - 100.0).abs() < 1e-9, "{at}");
        assert!((fmu.real("G.frictionX") + friction).abs() < 1e-9, "{at}");
        assert!((fmu.real("Drive.Rx") - friction).abs() < 1e-9, "{at}");
        assert!((fmu.real("Drive.Rz") + 100.0).abs() < 1e-9, "{at}");
        assert_eq!(fmu.integer("solver.iterations"), 0, "{at}");
        if k == 4 {
            let mut state: Fmi2FmuState = std::ptr::null_mut();
            assert_eq!(unsafe { fmi2_get_fmu_state(fmu.c, &mut state) }, 0);
            saved = Some(state);
        }
    }
    // Back to the slipped state at 6 mm (history 3 mm): 5 mm sticks at 20 N again.
    let mut state = saved.unwrap();
    assert_eq!(
        unsafe { fmi2_set_fmu_state(fmu.c, state) },
        0,
        "{:?}",
        log.take()
    );
    assert_eq!(fmu.set_real("Drive.dx", 5e-3), 0);
    assert_eq!(fmu.step(5.0, 1.0), 0, "{:?}", log.take());
    assert_eq!(fmu.integer("G.status"), 1);
    assert!((fmu.real("G.frictionX") + 20.0).abs() < 1e-9);
    assert_eq!(unsafe { fmi2_free_fmu_state(fmu.c, &mut state) }, 0);
}

// ---------------------------------------------------------------- issue 17: trust in the workflow

/// Issue 17, defect 1 as reported: the specimen with the paper's law, `frame.dz` = −0.03, −0.06,
/// −0.09, saved, one more step, restored: the restore must succeed.
#[test]
fn saved_state_restores_under_sliding_direction_law() {
    let (u, log) = (Unpacked::specimen("slidingrestore"), Log::default());
    let fmu = Fmu::new(&u, &log);
    unsafe {
        assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2_enter_initialization_mode(fmu.c), 0);
    }
    assert_eq!(fmu.set_string("frictionLaw", "sliding-direction"), 0);
    assert_eq!(unsafe { fmi2_exit_initialization_mode(fmu.c) }, 0);
    for (k, dz) in [-0.03, -0.06, -0.09].into_iter().enumerate() {
        assert_eq!(fmu.set_real("frame.dz", dz), 0);
        assert_eq!(fmu.step(k as f64, 1.0), 0, "{:?}", log.take());
    }
    let mut state: Fmi2FmuState = std::ptr::null_mut();
    assert_eq!(unsafe { fmi2_get_fmu_state(fmu.c, &mut state) }, 0);
    assert_eq!(fmu.set_real("frame.dz", -0.12), 0);
    assert_eq!(fmu.step(3.0, 1.0), 0, "{:?}", log.take());
    assert_eq!(
        unsafe { fmi2_set_fmu_state(fmu.c, state) },
        0,
        "{:?}",
        log.take()
    );
}

/// The state's serialized bytes (`fmi2SerializedFMUstateSize` + `fmi2SerializeFMUstate`).
fn serialized(fmu: &Fmu, state: Fmi2FmuState) -> Vec<Fmi2Byte> {
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

/// Steps the specimen (`contact`: its nine gaps or its curved support) under `law` along
/// `path` (`frame.dz` as a fraction of its target and `mu`, one step each); before each step after the
/// first saves the state (get, and serialized), steps, then restores the state by
/// `fmi2SetFMUstate` and by `fmi2DeSerializeFMUstate` + `fmi2SetFMUstate` and repeats the step:
/// every output must equal the one of the step that never restored, bit for bit. Returns the
/// statuses (0 open, 1 stick, 2 slip) the contacts had at the saved states.
fn round_trips_at_every_step(
    contact: crate::mech::specimen::SpecimenContact,
    law: &str,
    path: &[(f64, f64)],
) -> std::collections::BTreeSet<i32> {
    let spec = ParallelArch {
        contact,
        ..ParallelArch::default()
    };
    let u = Unpacked::new(
        &format!("roundtrip {contact:?} {law}"),
        Source::ParallelArch(spec),
    );
    let log = Log::default();
    let fmu = Fmu::new(&u, &log);
    unsafe {
        assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2_enter_initialization_mode(fmu.c), 0);
    }
    assert_eq!(fmu.set_string("frictionLaw", law), 0);
    assert_eq!(fmu.set_integer("solver.incrementsPerStep", 2), 0);
    assert_eq!(unsafe { fmi2_exit_initialization_mode(fmu.c) }, 0);
    let status_names: Vec<String> = u
        .variables
        .iter()
        .filter(|v| v.name.ends_with(".status") && v.name != "solver.status")
        .map(|v| v.name.clone())
        .collect();
    assert_eq!(status_names.len(), 9, "{status_names:?}");
    let mut seen = std::collections::BTreeSet::new();
    let target = spec.target()[2];
    for (k, &(fraction, mu)) in path.iter().enumerate() {
        let dz = target * fraction;
        let t = k as f64;
        if k == 0 {
            assert_eq!(fmu.set_real("frame.dz", dz), 0);
            assert_eq!(fmu.set_real("mu", mu), 0);
            assert_eq!(fmu.step(t, 1.0), 0, "{law} step {k}: {:?}", log.take());
            continue;
        }
        seen.extend(status_names.iter().map(|n| fmu.integer(n)));
        let mut state: Fmi2FmuState = std::ptr::null_mut();
        assert_eq!(unsafe { fmi2_get_fmu_state(fmu.c, &mut state) }, 0);
        let bytes = serialized(&fmu, state);
        let step = || {
            assert_eq!(fmu.set_real("frame.dz", dz), 0);
            assert_eq!(fmu.set_real("mu", mu), 0);
            assert_eq!(fmu.step(t, 1.0), 0, "{law} step {k}: {:?}", log.take());
            fmu.all_values()
        };
        let reference = step();
        assert_eq!(
            unsafe { fmi2_set_fmu_state(fmu.c, state) },
            0,
            "{contact:?} {law} step {k}: {:?}",
            log.take()
        );
        assert_eq!(step(), reference, "{contact:?} {law} step {k}: restored");
        let mut read: Fmi2FmuState = std::ptr::null_mut();
        assert_eq!(
            unsafe { fmi2_de_serialize_fmu_state(fmu.c, bytes.as_ptr(), bytes.len(), &mut read) },
            0,
            "{contact:?} {law} step {k}: {:?}",
            log.take()
        );
        assert_eq!(unsafe { fmi2_set_fmu_state(fmu.c, read) }, 0);
        assert_eq!(
            step(),
            reference,
            "{contact:?} {law} step {k}: deserialized"
        );
        unsafe {
            assert_eq!(fmi2_free_fmu_state(fmu.c, &mut state), 0);
            assert_eq!(fmi2_free_fmu_state(fmu.c, &mut read), 0);
        }
    }
    seen
}

#[test]
fn saved_states_round_trip_in_every_gap_and_contact_status_under_both_laws() {
    // (frame.dz / target, μ): down, a little way back up (the sliding nodes stick under the
    // isotropic law), with μ = 10 (they stick under the sliding-direction law, whose elastic
    // y force is several μN at μ = 0.2), back up (nodes open), down again.
    const PATH: [(f64, f64); 10] = [
        (0.1, 0.2),
        (0.2, 0.2),
        (0.3, 0.2),
        (0.4, 0.2),
        (0.5, 0.2),
        (0.4999, 0.2),
        (0.499, 10.0),
        (0.49, 0.2),
        (0.3, 0.2),
        (0.6, 0.2),
    ];
    use crate::mech::specimen::SpecimenContact;
    for contact in [SpecimenContact::Gaps, SpecimenContact::CurvedSupport] {
        for law in ["isotropic", "sliding-direction"] {
            let seen = round_trips_at_every_step(contact, law, &PATH);
            assert_eq!(
                seen,
                [0, 1, 2].into(),
                "{contact:?} {law}: statuses at the saved states"
            );
        }
    }
}

/// Issue 17, defect 2: a serialized state whose stored variable values `fmi2SetReal`/`SetString`
/// would refuse (μ = 1e300 or 11, an unknown friction law or VTK encoding, a value of the wrong
/// type; length and CRC recomputed) is refused by `fmi2DeSerializeFMUstate` with the same
/// message, naming the variable; NaN cannot even be written in the payload (JSON has no NaN).
#[test]
fn forged_variable_values_are_refused_as_fmi2_set_would_naming_the_variable() {
    use super::variables::Value;
    let (u, log) = (Unpacked::specimen("forgedvalues"), Log::default());
    let fmu = Fmu::initialized(&u, &log, &[("mu", 0.2)], &[]);
    let bytes = serialized_after_ramp(&fmu);
    let guid = u.guid.to_str().unwrap();
    let forged = |name: &str, value: Value| {
        let at = u.vr(name) as usize;
        forge(&bytes, guid, move |s| s.values[at] = value)
    };
    let cases = [
        (
            forged("mu", Value::Real(1e300)),
            "the state's value of mu: mu = 1e300: the friction coefficient must be ≥ 0 and ≤ 10",
        ),
        (
            forged("mu", Value::Real(11.0)),
            "the state's value of mu: mu = 11: the friction coefficient",
        ),
        (
            forged("mu", Value::Real(-0.5)),
            "mu = -0.5: the friction coefficient",
        ),
        (forged("mu", Value::Real(f64::NAN)), "payload"),
        (
            forged("frictionLaw", Value::String("x-only".into())),
            "the state's value of frictionLaw: frictionLaw: unknown friction law 'x-only'",
        ),
        (
            forged("results.vtkFormat", Value::String("gzip".into())),
            "the state's value of results.vtkFormat: results.vtkFormat:",
        ),
        (
            forged("film.E", Value::Integer(7)),
            "film.E is a Real, not an Integer",
        ),
    ];
    for (forged, expected) in cases {
        assert_deserialization_refused(&fmu, &forged, expected);
    }
    // The same values through fmi2SetReal/fmi2SetString: the same messages.
    assert_eq!(fmu.set_real("mu", 1e300), Status::Error.raw());
    assert!(log.contains(
        Status::Error,
        "mu = 1e300: the friction coefficient must be ≥ 0 and ≤ 10"
    ));
    assert_eq!(fmu.set_real("mu", 11.0), Status::Error.raw());
    assert!(log.contains(Status::Error, "mu = 11: the friction coefficient"));
    // Neither a huge nor a tiny number prints as hundreds of digits.
    assert_eq!(fmu.step(0.4, -1e300), Status::Error.raw());
    assert_eq!(fmu.step(1e300, 0.1), Status::Error.raw());
    let messages = log.take();
    assert!(
        messages
            .iter()
            .any(|(_, _, m)| m.contains("communicationStepSize = -1e300 must be > 0"))
            && messages
                .iter()
                .any(|(_, _, m)| m.contains("currentCommunicationPoint = 1e300 differs")),
        "{messages:?}"
    );
    assert!(
        messages.iter().all(|(_, _, m)| !m.contains("0000000000")),
        "{messages:?}"
    );
    // The genuine state is still accepted.
    assert_eq!(deserialize_status(&fmu, &bytes).0, 0);
}

/// Issue 17, defect 1 for curved supports: a forged curved-support contact status or anchor
/// that the contact's own law contradicts is refused at deserialization, naming the node and
/// the support; the genuine state (round trips in every status: above) is accepted.
#[test]
fn forged_curved_support_contact_states_are_refused_by_the_contacts_law() {
    use crate::mech::GapStatus;
    let spec = ParallelArch {
        contact: crate::mech::specimen::SpecimenContact::CurvedSupport,
        ..ParallelArch::default()
    };
    let (u, log) = (
        Unpacked::new("forgedcontacts", Source::ParallelArch(spec)),
        Log::default(),
    );
    let fmu = Fmu::initialized(&u, &log, &[], &[]);
    let bytes = serialized_after_ramp(&fmu);
    let guid = u.guid.to_str().unwrap();
    let genuine = super::state::deserialize(&bytes, guid).unwrap();
    let contacts = &genuine.analysis.as_ref().unwrap().contacts;
    let model = spec.model().unwrap();
    let support = &model.curved_supports[0];
    let slipping = contacts.iter().position(|c| c.status == GapStatus::Slip);
    let open = contacts.iter().position(|c| c.status == GapStatus::Open);
    let (slipping, open) = (slipping.unwrap(), open.unwrap());
    let name = |k: usize| {
        format!(
            "node {} on curved support '{}'",
            support.nodes[k], support.name
        )
    };
    type Forgery = Box<dyn Fn(&mut crate::mech::surface::ContactHistory)>;
    let cases: Vec<(usize, Forgery, String)> = vec![
        (
            open,
            Box::new(|c| c.status = GapStatus::Stick),
            format!("status of {} is Stick", name(open)),
        ),
        (
            slipping,
            Box::new(|c| c.status = GapStatus::Open),
            format!("status of {} is Open", name(slipping)),
        ),
        (
            slipping,
            Box::new(|c| c.anchor[0] += 1e-3),
            "further slip".into(),
        ),
    ];
    for (k, f, expected) in cases {
        let forged = forge(&bytes, guid, |s| {
            f(&mut s.analysis.as_mut().unwrap().contacts[k])
        });
        assert_deserialization_refused(&fmu, &forged, &expected);
    }
    assert_eq!(deserialize_status(&fmu, &bytes).0, 0, "{:?}", log.take());
}
