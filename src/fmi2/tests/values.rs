//! Values through the exported functions: strings, the parameters that change the model
//! (friction law, wrinkling, solver threads), load inputs, and the outputs of output points and
//! element sets against the core.
//!
//! SAFETY of the `unsafe` blocks below: as in the harness (`tests/mod.rs`), each calls an
//! exported function the way an importer does, with an instance from [`Fmu`] (freed only in its
//! `Drop`), and pointers to live locals or NUL-terminated literals holding the announced number
//! of elements; the deliberately bad arguments are NULL pointers, which the functions must
//! reject without dereferencing.

use super::*;

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
            let increments = crate::mech::solve::DEFAULT_INCREMENTS_PER_STEP;
            a.step_to(
                &[[0.0, 0.0, spec.target()[2] * (k as f64 / 20.0)]],
                increments,
            )
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

/// Issue 8 through the FMU: `top.pressure` and `lamp.Fz` inputs (starts from the model) and the
/// `gravity.*` / `film.density` parameters load a circular membrane. The rim reaction balances
/// them exactly (the pressure's resultant on a surface with a fixed rim is `p` times the rim's
/// projected area, `A_polygon`), equals the core's, and FMU states round-trip the load levels.
#[test]
fn pressure_and_force_inputs_load_the_membrane_and_states_keep_the_load_levels() {
    use crate::fmi2::variables::{Causality, Value};
    use crate::mech::model::ForceSet;
    use crate::mech::{Analysis, LoadLevels, SolverSettings};
    use crate::specimens::scenarios::CircularMembrane;

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
        chambers: vec![],
        heating: vec![],
        air: vec![],
        time: 0.0,
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
    use crate::fmi2::variables::{Causality, SummaryQuantity};
    use crate::mech::{Analysis, LoadLevels, SolverSettings};
    use crate::specimens::scenarios::CircularMembrane;

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
        chambers: vec![],
        heating: vec![],
        air: vec![],
        time: 0.0,
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
            .filter(|v| v.var_type == crate::fmi2::variables::VarType::Integer)
            .position(|v| v.name == "solver.threads")
            .unwrap();
        values.1[at] = 1;
        assert_eq!(values, serial, "{threads} threads");
    }
}
