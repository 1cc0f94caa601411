//! Lifecycle through the exported functions: instantiation and its refusals, the call order
//! each phase allows, logging, reset, independent instances, a panic turned into fmi2Fatal,
//! and a model refused at initialization.
//!
//! SAFETY of the `unsafe` blocks below: as in the harness (`tests/mod.rs`), each calls an
//! exported function the way an importer does, with an instance from [`Fmu`] (freed only in its
//! `Drop`), and pointers to live locals or NUL-terminated literals holding the announced number
//! of elements; the deliberately bad arguments are NULL pointers, which the functions must
//! reject without dereferencing.

use super::*;

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
        // A derivative of what is not a Real output of the state; an unsupported function.
        assert_eq!(
            fmi2_get_directional_derivative(c, &0, 1, &0, 1, &0.0, &mut v),
            err
        );
        assert!(log.contains(
            Status::Error,
            "unknown time (value reference 0) is not a Real output"
        ));
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
        assert_eq!(fmu.set_real("film.E", 1e9), 0);
        assert_eq!(fmu.set_real("film.temperature", 60.0), 0);
        assert_eq!(fmi2_exit_initialization_mode(c), err);
        assert!(log.contains(Status::Error, "temperature = 60 °C lies outside [0, 50] °C"));
        assert_eq!(fmu.set_real("film.temperature", 23.0), 0);
        assert_eq!(fmu.set_integer("solver.incrementsPerStep", 0), 0);
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

/// After `fmi2Terminate` the state machine (FMI 2.0 §4.2.4, `phase::allowed`) refuses a step, a
/// Set and a second Terminate, each with fmi2Error naming the call and the state, and time stays;
/// Get still answers (for debugging), and Reset leads back to a new experiment.
#[test]
fn after_terminate_no_step_set_or_terminate_is_allowed() {
    let (u, log) = (Unpacked::specimen("terminated"), Log::default());
    let fmu = Fmu::initialized(&u, &log, &[], &[]);
    let err = Status::Error.raw();
    unsafe {
        assert_eq!(fmi2_do_step(fmu.c, 0.0, 0.05, 1), 0);
        assert_eq!(fmi2_terminate(fmu.c), 0);
        let refused = [
            ("fmi2DoStep", fmi2_do_step(fmu.c, 0.05, 0.05, 1)),
            ("fmi2SetReal", fmu.set_real("frame.dz", -0.01)),
            ("fmi2Terminate", fmi2_terminate(fmu.c)),
        ];
        for (call, status) in refused {
            assert_eq!(status, err, "{call}");
            let message = format!("{call} must not be called in state Terminated");
            assert!(
                log.contains(Status::Error, &message),
                "{call}: {:?}",
                log.take()
            );
        }
        assert_eq!(fmu.real("time"), 0.05);
        assert_eq!(fmi2_reset(fmu.c), 0);
        assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
    }
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
    let status = unsafe {
        crate::fmi2::guard::with_instance(fmu.c, "fmi2Test", allowed::ANY, |_| panic!("boom"))
    };
    assert_eq!(status, Status::Fatal.raw());
    assert!(log.contains(Status::Fatal, "internal error (panic): boom"));
    assert_eq!(
        unsafe { fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0) },
        Status::Error.raw()
    );
    assert!(log.contains(Status::Error, "an earlier call failed fatally"));
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
