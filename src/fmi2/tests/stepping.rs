//! Stepping through the exported functions: a refused step (fmi2Discard) and its retry, the
//! identical step repeated, inputs the solver cannot reach, results beyond the model's
//! assumptions, and a model without a free DOF stepped through stick and slip.
//!
//! SAFETY of the `unsafe` blocks below: as in the harness (`tests/mod.rs`), each calls an
//! exported function the way an importer does, with an instance from [`Fmu`] (freed only in its
//! `Drop`), and pointers to live locals or NUL-terminated literals holding the announced number
//! of elements; the deliberately bad arguments are NULL pointers, which the functions must
//! reject without dereferencing.

use super::*;

/// Issue 47 item 6: the step log of an ordinary step says nothing of enlarged increments (it
/// said "0 enlarged (larger than 1/solver.incrementsPerStep because every smaller one
/// failed)" on every step).
#[test]
fn an_ordinary_steps_log_says_nothing_of_enlarged_increments() {
    let (u, log) = (Unpacked::specimen("ordinary log"), Log::default());
    let fmu = Fmu::initialized(&u, &log, &[], &[]);
    assert_eq!(fmu.set_real("frame.dz", -0.001), 0);
    assert_eq!(fmu.step(0.0, 0.05), 0);
    let said = log.take();
    assert!(
        said.iter().any(|(_, _, m)| m.starts_with("step to t = ")),
        "{said:?}"
    );
    assert!(
        !said.iter().any(|(_, _, m)| m.contains("enlarged")),
        "{said:?}"
    );
}

#[test]
fn a_step_that_cannot_converge_is_discarded_and_can_be_retried() {
    let (u, log) = (Unpacked::specimen("discard"), Log::default());
    // Small steps converge in fewer than 10 iterations; a jump to the target in one increment
    // does not, and no cut-back may rescue it, nor the viscous stabilization (off: with it, the
    // jump converges, carrying its damping force).
    let fmu = Fmu::new(&u, &log);
    unsafe {
        assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2_enter_initialization_mode(fmu.c), 0);
    }
    for (name, value) in [
        ("solver.maxCutbacks", 0),
        ("solver.maxIterations", 10),
        ("solver.incrementsPerStep", 1),
    ] {
        assert_eq!(fmu.set_integer(name, value), 0, "{name}");
    }
    assert_eq!(fmu.set_boolean("solver.stabilization", false), 0);
    assert_eq!(unsafe { fmi2_exit_initialization_mode(fmu.c) }, 0);
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
        .filter(|v| v.var_type == crate::fmi2::variables::VarType::Real)
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
        ("solver.maxIterations", 10),
        ("solver.incrementsPerStep", 1),
    ];
    // Without the viscous stabilization, whose rows of the strategy table would try on.
    let without = [("solver.stabilization", false)];
    let fmu = Fmu::initialized_with(&u, &log, &[], &settings, &without);
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
    assert!(log.contains(Status::Discard, "terminateSimulation) is now true"));
    // A master that ignores the Discard and goes on is refused with a message that the outputs
    // are stale, at every call.
    for _ in 0..2 {
        assert_eq!(fmu.step(1.0, 1.0), Status::Error.raw());
        assert!(log.contains(Status::Error, "its outputs are those of t = 0"));
    }
    // A smaller change (here none) still works and clears the flag.
    assert_eq!(fmu.set_real("frame.dz", 0.0), 0);
    assert_eq!(fmu.step(0.0, 0.1), 0, "{:?}", log.take());
    assert_eq!(terminated(), 0);
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

/// A model without a free DOF (issue 17: how single elements are verified) initializes and
/// steps: `examples/driven_gap.json` driven down 2 mm and along x sticks at `k_s·dx`, slips at
/// `μN` = 30 N beyond 3 mm and sticks again on the way back, as the core says
/// (`tests/supports.rs`); the film feels the opposite of the gap's friction force and the drive
/// carries both contact forces. Its FMU state round trip keeps the slip history.
#[test]
fn a_model_without_free_dofs_steps_its_gap_through_stick_and_slip() {
    let model =
        crate::mech::Model::from_json(include_str!("../../../examples/driven_gap.json")).unwrap();
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

/// Issue 43: a chamber through the FMU. `examples/cushion.json` with its air as a chamber
/// supplied through `air.supplyPressure`: `air.pressure` is the supply's, `air.volume` grows
/// with it (the same volume the CLI prints at 300 Pa: 0.196 m³), and an FMU state taken after
/// the first step repeats the second step bit for bit. `air.sealed` closes the valve (the air
/// keeps the cushion up with the supply at 0) and opens it again (the cushion collapses).
#[test]
fn a_chamber_inflates_seals_and_opens_through_the_fmu_and_its_state_round_trips() {
    let mut model =
        crate::mech::Model::from_json(include_str!("../../../examples/cushion.json")).unwrap();
    model.loads.pressures.clear();
    model.chambers = vec![crate::mech::model::ChamberSpec {
        name: "air".into(),
        elements: crate::mech::model::ElementSelection::All(crate::mech::model::AllElements::All),
        closed_by_plane: None,
        pressure: 300.0,
        sealed: false,
        kappa: 1.0,
        atmosphere: 101_325.0,
        temperature: 293.15,
        heating: 0.0,
    }];
    let (u, log) = (
        Unpacked::new("chamber", Source::Model(model)),
        Log::default(),
    );
    let fmu = Fmu::initialized(&u, &log, &[("air.supplyPressure", 0.0)], &[]);
    let mut volumes = vec![];
    let mut saved: Fmi2FmuState = std::ptr::null_mut();
    for (k, p) in [150.0, 300.0].into_iter().enumerate() {
        assert_eq!(fmu.set_real("air.supplyPressure", p), 0);
        assert_eq!(fmu.step(k as f64, 1.0), 0, "{:?}", log.take());
        assert_eq!(fmu.real("air.pressure"), p);
        volumes.push(fmu.real("air.volume"));
        if k == 0 {
            assert_eq!(unsafe { fmi2_get_fmu_state(fmu.c, &mut saved) }, 0);
        }
    }
    assert!(
        volumes[0] > 0.0 && volumes[1] > 1.2 * volumes[0],
        "{volumes:?}"
    );
    assert!((volumes[1] - 0.196).abs() < 1e-3, "{volumes:?}");
    assert!(fmu.real("crownTop.uz") > 0.05);
    // Serialized and read back: the air travels with the state's bytes.
    let bytes = serialized(&fmu, saved);
    let mut restored: Fmi2FmuState = std::ptr::null_mut();
    let size = bytes.len();
    assert_eq!(
        unsafe { fmi2_de_serialize_fmu_state(fmu.c, bytes.as_ptr(), size, &mut restored) },
        0
    );
    assert_eq!(unsafe { fmi2_set_fmu_state(fmu.c, restored) }, 0);
    assert_eq!(unsafe { fmi2_free_fmu_state(fmu.c, &mut restored) }, 0);
    assert_eq!(
        fmu.real("air.volume"),
        volumes[0],
        "the state holds the air"
    );
    assert_eq!(fmu.set_real("air.supplyPressure", 300.0), 0);
    assert_eq!(fmu.step(1.0, 1.0), 0, "{:?}", log.take());
    assert_eq!(fmu.real("air.volume"), volumes[1]);
    assert_eq!(unsafe { fmi2_free_fmu_state(fmu.c, &mut saved) }, 0);
    // The valve closes: the supply's pressure no longer acts, the enclosed air keeps the
    // cushion up at the same pressure and volume (Boyle, nothing else changed).
    assert_eq!(fmu.set_boolean("air.sealed", true), 0);
    assert_eq!(fmu.set_real("air.supplyPressure", 0.0), 0);
    assert_eq!(fmu.step(2.0, 1.0), 0, "{:?}", log.take());
    assert!(
        (fmu.real("air.pressure") - 300.0).abs() < 1e-6,
        "{}",
        fmu.real("air.pressure")
    );
    assert!((fmu.real("air.volume") / volumes[1] - 1.0).abs() < 1e-9);
    // Opened again to a supply at 0 Pa: the cushion collapses to its prestressed flat state.
    assert_eq!(fmu.set_boolean("air.sealed", false), 0);
    assert_eq!(fmu.step(3.0, 1.0), 0, "{:?}", log.take());
    assert_eq!(fmu.real("air.pressure"), 0.0);
    assert!(
        fmu.real("air.volume").abs() < 1e-6 * volumes[1],
        "{}",
        fmu.real("air.volume")
    );
}

/// Issue 47 item 8: the `logIncrements` category carries a line per increment of a step (as
/// many converged as the step's log counts, and one per refused attempt), status OK; `loggingOn = true` alone does not enable
/// it (a line per increment), naming it does.
#[test]
fn log_increments_carries_a_line_per_increment_when_named() {
    let (u, log) = (Unpacked::specimen("increment log"), Log::default());
    let fmu = Fmu::initialized(&u, &log, &[], &[]);
    assert_eq!(fmu.set_real("frame.dz", -0.001), 0);
    assert_eq!(fmu.step(0.0, 0.05), 0);
    let of = |said: &[(i32, String, String)]| {
        said.iter()
            .filter(|(s, c, _)| *s == 0 && c == "logIncrements")
            .map(|(_, _, m)| m.clone())
            .collect::<Vec<_>>()
    };
    assert!(of(&log.take()).is_empty());
    let named = [c"logIncrements".as_ptr()];
    // SAFETY: see the module doc; `named` holds one NUL-terminated literal.
    assert_eq!(
        unsafe { fmi2_set_debug_logging(fmu.c, 1, 1, named.as_ptr()) },
        0
    );
    assert_eq!(fmu.set_real("frame.dz", -0.002), 0);
    assert_eq!(fmu.step(0.05, 0.05), 0);
    let said = log.take();
    let lines = of(&said);
    let summary = said
        .iter()
        .find_map(|(_, _, m)| m.strip_prefix("step to t = 0.1: "))
        .unwrap_or_else(|| panic!("{said:?}"));
    let increments: usize = summary.split(' ').next().unwrap().parse().unwrap();
    // One line per converged increment, and one per refused attempt before it.
    let converged: Vec<_> = lines.iter().filter(|l| !l.contains("refused")).collect();
    assert_eq!(converged.len(), increments, "{lines:?}");
    assert!(
        lines[0].starts_with("increment 0.0000 → ")
            && converged[0].contains("of the step: Newton in "),
        "{lines:?}"
    );
}

/// Issue 47 item 8: a load input starts at the model file's value, so the first step applies
/// snow and suction together unless the master zeroes one. The end of initialization says so in
/// the warning log, naming each nonzero load input and its value (marked as the file's); an
/// input set to 0 during initialization is not named, and with every one at 0 nothing is said.
#[test]
fn the_loads_the_first_step_applies_are_named_at_the_end_of_initialization() {
    use crate::mech::model::format::{AllElements, ElementSelection, PressureSet};
    let mut model = crate::specimens::ParallelArch::default().model().unwrap();
    for (name, pressure) in [("snow", 960.0), ("suction", -600.0)] {
        model.loads.pressures.push(PressureSet {
            kind: Default::default(),
            name: name.into(),
            elements: ElementSelection::All(AllElements::All),
            pressure,
            towards: None,
        });
    }
    let u = Unpacked::new("start loads", Source::Model(model));
    let warned = |reals: &[(&str, f64)]| {
        let log = Log::default();
        let _fmu = Fmu::initialized(&u, &log, reals, &[]);
        log.take()
            .into_iter()
            .filter(|(s, _, m)| {
                *s == Status::Warning.raw() && m.contains("first DoStep applies these loads")
            })
            .map(|(_, _, m)| m)
            .collect::<Vec<_>>()
    };
    let both = warned(&[]);
    assert_eq!(both.len(), 1, "{both:?}");
    for named in [
        "snow.pressure = 960 Pa (the model file's value)",
        "suction.pressure = -600 Pa (the model file's value)",
    ] {
        assert!(both[0].contains(named), "{both:?}");
    }
    let snow = warned(&[("suction.pressure", 0.0)]);
    assert!(snow.len() == 1 && !snow[0].contains("suction"), "{snow:?}");
    assert!(warned(&[("suction.pressure", 0.0), ("snow.pressure", 0.0)]).is_empty());
}

/// Issue 43 item 4: `<chamber>.massFlow` feeds a sealed chamber. `examples/cushion_air.json`
/// inflated from its supply to 300 Pa and sealed, then fed at a constant flow for three steps:
/// the air's mass is the sealed mass plus Σ ṁ h (to rounding), its pressure the gas law's at
/// the new volume, and the cushion swells. A leak that would let out more air than the chamber
/// holds is refused (fmi2Discard) naming the input, the last converged state kept; a flow
/// while the supply holds the pressure changes nothing.
#[test]
fn a_sealed_chamber_fed_by_mass_flow_holds_the_integrated_mass_at_the_gas_laws_pressure() {
    let model =
        crate::mech::Model::from_json(include_str!("../../../examples/cushion_air.json")).unwrap();
    let (u, log) = (
        Unpacked::new("mass flow", Source::Model(model)),
        Log::default(),
    );
    let fmu = Fmu::initialized(&u, &log, &[("air.supplyPressure", 0.0)], &[]);
    // A flow while supplied is ignored: the supply holds the pressure.
    assert_eq!(fmu.set_real("air.massFlow", 1.0), 0);
    for (k, p) in [150.0, 300.0].into_iter().enumerate() {
        assert_eq!(fmu.set_real("air.supplyPressure", p), 0);
        assert_eq!(fmu.step(k as f64, 1.0), 0, "{:?}", log.take());
    }
    assert_eq!(fmu.real("air.pressure"), 300.0);
    assert_eq!(fmu.set_boolean("air.sealed", true), 0);
    assert_eq!(fmu.set_real("air.massFlow", 0.0), 0);
    assert_eq!(fmu.step(2.0, 1.0), 0, "{:?}", log.take());
    let (m0, v0) = (fmu.real("air.mass"), fmu.real("air.volume"));
    let (flow, h) = (2e-4, 0.5);
    let (r, t, pa) = (287.05, 293.15, 101_325.0);
    let mut time = 3.0;
    for n in 1..=3 {
        assert_eq!(fmu.set_real("air.massFlow", flow), 0);
        assert_eq!(fmu.step(time, h), 0, "{:?}", log.take());
        time += h;
        let (m, v, p) = (
            fmu.real("air.mass"),
            fmu.real("air.volume"),
            fmu.real("air.pressure"),
        );
        let want = m0 + n as f64 * flow * h;
        assert!(
            (m - want).abs() <= 1e-12 * want,
            "step {n}: {m} kg, want {want}"
        );
        let gas_law = want * r * t / v - pa;
        assert!(
            (p - gas_law).abs() <= 1e-6,
            "step {n}: {p} Pa, gas law {gas_law}"
        );
        assert!(v > v0 && p > 300.0, "step {n}: {v} m³, {p} Pa");
    }
    // A leak of more than the air: refused, nothing changed.
    let before = (
        fmu.real("air.mass"),
        fmu.real("air.volume"),
        fmu.real("crownTop.uz"),
    );
    assert_eq!(fmu.set_real("air.massFlow", -1.0), 0);
    log.take();
    assert_eq!(fmu.step(time, h), 2);
    assert!(
        log.contains(Status::Discard, "air.massFlow = -1 kg/s")
            && log.contains(Status::Discard, "the mass must stay positive"),
        "{:?}",
        log.take()
    );
    let after = (
        fmu.real("air.mass"),
        fmu.real("air.volume"),
        fmu.real("crownTop.uz"),
    );
    assert_eq!(after, before);
    // A leak it can take: the air and its pressure fall again.
    assert_eq!(fmu.set_real("air.massFlow", -flow), 0);
    assert_eq!(fmu.step(time, h), 0, "{:?}", log.take());
    assert!((fmu.real("air.mass") - (before.0 - flow * h)).abs() <= 1e-12 * before.0);
}

/// Issue 43: `<orifice>.massFlow` is the air the orifice passed over the last step divided by
/// the step (kg/s, positive from its `from` chamber to its `to`), with two increments a step
/// (so not the last increment's flow). `examples/two_chamber_orifice.json` inflated by its
/// supplies and sealed, then four steps of 0.5 s: `hole.massFlow` is the upper chamber's gain
/// of air over the step / 0.5 s and the lower one's loss, to 1e-9, positive (lower → upper: the
/// lower chamber's pressure is higher) and falling as the pressures approach. While both
/// chambers are supplied it is 0.
#[test]
fn orifice_mass_flow_is_the_air_moved_over_the_step_divided_by_the_step() {
    let (u, log) = (
        Unpacked::two_chamber_orifice("orifice flow"),
        Log::default(),
    );
    let fmu = Fmu::initialized(&u, &log, &[], &[("solver.incrementsPerStep", 2)]);
    fmu.inflate_and_seal_two_chambers();
    assert_eq!(fmu.real("hole.massFlow"), 0.0, "two supplies pass nothing");
    let h = 0.5;
    let mut last = f64::INFINITY;
    for n in 0..4 {
        let (upper, lower) = (fmu.real("upper.mass"), fmu.real("lower.mass"));
        assert_eq!(fmu.step(3.0 + n as f64 * h, h), 0, "{:?}", log.take());
        let flow = fmu.real("hole.massFlow");
        let gained = (fmu.real("upper.mass") - upper) / h;
        let lost = (lower - fmu.real("lower.mass")) / h;
        println!(
            "step {n}: massFlow {flow:.9e} kg/s, upper gains {gained:.9e}, lower loses {lost:.9e}"
        );
        assert!(
            (flow - gained).abs() <= 1e-9 * flow,
            "step {n}: {flow} vs {gained}"
        );
        assert!(
            (flow - lost).abs() <= 1e-9 * flow,
            "step {n}: {flow} vs {lost}"
        );
        assert!(flow > 0.0 && flow < last, "step {n}: {flow} after {last}");
        last = flow;
    }
    assert!(fmu.real("lower.pressure") > fmu.real("upper.pressure"));
}

/// Issue 41: a pressure input past the largest pressure the film can carry (an ETFE sphere,
/// whose pressure peaks where `dτ/dε = 3τ`) is discarded with the limit point's share and
/// pressure named, and the outputs stay the last converged step's.
#[test]
fn a_pressure_past_the_films_limit_point_is_discarded_naming_it() {
    use crate::mech::elements::plasticity::{Hardening, Plasticity};
    use crate::specimens::scenarios::InflatedSphere;
    let mut sphere = InflatedSphere {
        radius: 1.0,
        cells: 6,
        material: crate::specimens::ParallelArch::default().material,
        pressure: 0.0,
    };
    sphere.material.wrinkling = crate::mech::Wrinkling::None;
    sphere.material.plasticity = Some(Plasticity {
        hardening: Hardening::new(vec![[0.0, 21e6], [1.4547, 275e6]]).unwrap(),
    });
    let stretches: Vec<f64> = (0..=5000).map(|k| 1.0 + k as f64 / 10_000.0).collect();
    let peak = sphere
        .closed_form(&stretches)
        .unwrap()
        .into_iter()
        .fold(0.0, f64::max);
    let u = Unpacked::new("limit point", Source::Model(sphere.model().unwrap()));
    let log = Log::default();
    let fmu = Fmu::initialized(&u, &log, &[], &[]);
    for (k, f) in [0.5, 0.9].into_iter().enumerate() {
        assert_eq!(fmu.set_real("inside.pressure", f * peak), 0);
        // Warning: the film yields, as it must to reach a limit point.
        let status = fmu.step(0.1 * k as f64, 0.1);
        assert_eq!(status, Status::Warning.raw(), "{:?}", log.take());
    }
    let before = fmu.all_values();
    assert_eq!(fmu.set_real("inside.pressure", 1.2 * peak), 0);
    assert_eq!(fmu.step(0.2, 0.1), Status::Discard.raw());
    assert!(
        log.contains(Status::Discard, "the loads pass a limit point"),
        "{:?}",
        log.take()
    );
    assert!((fmu.real("time") - 0.2).abs() < 1e-15);
    assert_eq!(fmu.set_real("inside.pressure", 0.9 * peak), 0);
    assert_eq!(fmu.all_values(), before);
}
