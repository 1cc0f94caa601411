//! FMU states through the exported functions: save, restore and continue identically, round
//! trips in every contact status under both friction laws, and forged or foreign serialized
//! states refused at deserialization with a message.
//!
//! SAFETY of the `unsafe` blocks below: as in the harness (`tests/mod.rs`), each calls an
//! exported function the way an importer does, with an instance from [`Fmu`] (freed only in its
//! `Drop`), and pointers to live locals or NUL-terminated literals holding the announced number
//! of elements; the deliberately bad arguments are NULL pointers, which the functions must
//! reject without dereferencing.

use super::*;

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

/// A serialized state of the specimen after 4 of 10 ramp steps.
fn serialized_after_ramp(fmu: &Fmu) -> Vec<u8> {
    fmu.ramp(0, 4, 10);
    let mut state: Fmi2FmuState = std::ptr::null_mut();
    assert_eq!(unsafe { fmi2_get_fmu_state(fmu.c, &mut state) }, 0);
    let bytes = serialized(fmu, state);
    assert_eq!(unsafe { fmi2_free_fmu_state(fmu.c, &mut state) }, 0);
    bytes.iter().map(|&b| b as u8).collect()
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

    type Forgery = Box<dyn Fn(&mut crate::fmi2::state::Snapshot)>;
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
            analysis(|a| a.last_load_increment = vec![0.0; 2]),
            "last load increment has 2 values",
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

/// Steps the specimen (`contact`: its nine gaps or its curved support) under `law` along
/// `path` (`frame.dz` as a fraction of its target and `mu`, one step each); before each step after the
/// first saves the state (get, and serialized), steps, then restores the state by
/// `fmi2SetFMUstate` and by `fmi2DeSerializeFMUstate` + `fmi2SetFMUstate` and repeats the step:
/// every output must equal the one of the step that never restored, bit for bit. Returns the
/// statuses (0 open, 1 stick, 2 slip) the contacts had at the saved states.
fn round_trips_at_every_step(
    contact: crate::specimens::parallel_arch::SpecimenContact,
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
    use crate::specimens::parallel_arch::SpecimenContact;
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
    use crate::fmi2::variables::Value;
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
        contact: crate::specimens::parallel_arch::SpecimenContact::CurvedSupport,
        ..ParallelArch::default()
    };
    let (u, log) = (
        Unpacked::new("forgedcontacts", Source::ParallelArch(spec)),
        Log::default(),
    );
    let fmu = Fmu::initialized(&u, &log, &[], &[]);
    let bytes = serialized_after_ramp(&fmu);
    let guid = u.guid.to_str().unwrap();
    let genuine = crate::fmi2::state::deserialize(&bytes, guid).unwrap();
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
    type Forgery = Box<dyn Fn(&mut crate::mech::elements::curved_contact::ContactHistory)>;
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

/// Issue 43: `run(fmu, from, to)` steps a fresh `fmu` up to step `k`; a state taken there, the
/// steps `k..n` run on, the state set back (in place, then serialized and read back) and the
/// same steps run again give every output bit for bit as the first time.
fn assert_mid_run_round_trip(
    fmu: &Fmu,
    (k, n): (usize, usize),
    run: &dyn Fn(&Fmu, usize, usize) -> Vec<(Vec<f64>, Vec<i32>)>,
) -> Vec<(Vec<f64>, Vec<i32>)> {
    run(fmu, 0, k);
    let mut state: Fmi2FmuState = std::ptr::null_mut();
    assert_eq!(unsafe { fmi2_get_fmu_state(fmu.c, &mut state) }, 0);
    let at_save = fmu.all_values();
    let first = run(fmu, k, n);
    assert_eq!(unsafe { fmi2_set_fmu_state(fmu.c, state) }, 0);
    assert_eq!(fmu.all_values(), at_save);
    assert_eq!(run(fmu, k, n), first, "set back in place");
    let bytes = serialized(fmu, state);
    let mut restored: Fmi2FmuState = std::ptr::null_mut();
    assert_eq!(
        unsafe { fmi2_de_serialize_fmu_state(fmu.c, bytes.as_ptr(), bytes.len(), &mut restored) },
        0
    );
    assert_eq!(unsafe { fmi2_set_fmu_state(fmu.c, restored) }, 0);
    assert_eq!(run(fmu, k, n), first, "serialized and read back");
    for mut s in [state, restored] {
        assert_eq!(unsafe { fmi2_free_fmu_state(fmu.c, &mut s) }, 0);
    }
    first
}

/// Issue 43: a state taken mid-run while the top layer of `examples/two_layers_touching.json`
/// lies on the bottom one (snow ramped over 6 steps, state after the third, the contact's
/// normal force positive there) repeats the next three steps bit for bit (the layer contact's
/// anchors, statuses and slip travel with the state).
#[test]
fn a_state_with_a_layer_contact_round_trips_mid_run_bit_for_bit() {
    let model =
        crate::mech::Model::from_json(include_str!("../../../examples/two_layers_touching.json"))
            .unwrap();
    let (u, log) = (
        Unpacked::new("layer state", Source::Model(model)),
        Log::default(),
    );
    let fmu = Fmu::initialized(&u, &log, &[("Snow.pressure", 0.0)], &[]);
    let run = |fmu: &Fmu, from: usize, to: usize| {
        fmu.steps((from, to), (0.0, 1.0), &|f, n| {
            assert_eq!(f.set_real("Snow.pressure", 400.0 * (n + 1) as f64 / 6.0), 0);
            if n == 3 {
                assert!(f.real("Touch.normalForce") > 0.0, "in contact at the state");
            }
        })
    };
    let first = assert_mid_run_round_trip(&fmu, (3, 6), &run);
    assert_eq!(first.len(), 3);
    assert!(fmu.real("Touch.normalForce") > 0.0);
}

/// Issue 43: a state taken mid-run while the orifice of `examples/two_chamber_orifice.json`
/// passes air between its sealed chambers (inflated, sealed, one step of 0.5 s) repeats the
/// next three steps bit for bit: the enclosed air, the moved mass and `hole.massFlow`.
#[test]
fn a_state_with_an_orifice_round_trips_mid_run_bit_for_bit() {
    let (u, log) = (
        Unpacked::two_chamber_orifice("orifice state"),
        Log::default(),
    );
    let fmu = Fmu::initialized(&u, &log, &[], &[("solver.incrementsPerStep", 2)]);
    fmu.inflate_and_seal_two_chambers();
    let run = |fmu: &Fmu, from: usize, to: usize| fmu.steps((from, to), (3.0, 0.5), &|_, _| {});
    let first = assert_mid_run_round_trip(&fmu, (1, 4), &run);
    assert_eq!(first.len(), 3);
    assert!(fmu.real("hole.massFlow") > 0.0, "the air flows");
}
