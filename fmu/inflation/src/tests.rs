//! The unit's laws against their closed forms, its switch and delay, its refusals, and its
//! FMU states through the C layer as an importer calls it.

use super::*;

/// The unit at its defaults with `changes` made, initialized.
fn unit(changes: &[(u32, f64)]) -> Unit {
    let mut u = Unit::default();
    for &(k, v) in changes {
        u.values[k as usize] = v;
    }
    u.initialize().unwrap();
    u
}

/// Steps `u` by `h` at the pressure `p`.
fn step_at(u: &mut Unit, p: f64, h: f64) {
    u.values[vr::PRESSURE as usize] = p;
    u.step(h).unwrap();
}

#[test]
fn the_orifice_leaks_cd_a_sqrt_2p_over_rho_out_and_in() {
    // 0.6 · 10 mm² · √(2 · 300 / 1.2) = 6e-6 · √500 m³/s
    let q = leak_flow(300.0, 0.6, 1e-5, 1.2);
    assert!((q - 6e-6 * 500f64.sqrt()).abs() <= 1e-20, "{q}");
    assert_eq!(leak_flow(-300.0, 0.6, 1e-5, 1.2), -q);
    assert_eq!(leak_flow(0.0, 0.6, 1e-5, 1.2), 0.0);
    // through the unit with the fan off (its contact open above switchOn): leakage alone
    let mut u = unit(&[(vr::PRESSURE, 300.0)]);
    assert_eq!(u.values[vr::MASS_FLOW as usize], 0.0, "no step yet");
    step_at(&mut u, 300.0, 1.0);
    assert_eq!(u.values[vr::FAN_ON as usize], 0.0);
    assert_eq!(u.values[vr::LEAK_FLOW as usize], q);
    assert_eq!(u.values[vr::MASS_FLOW as usize], -1.2 * q);
}

#[test]
fn the_fan_delivers_its_curves_flow_and_nothing_back_at_or_above_shut_off() {
    // Δp = p0 (1 − (Q/Qmax)²): at Q = Qmax/2 the fan holds 3/4 of p0
    assert_eq!(fan_flow(600.0, 800.0, 4e-3), 2e-3);
    assert_eq!(fan_flow(0.0, 800.0, 4e-3), 4e-3);
    // the non-return valve: no back flow at or above the shut-off pressure
    assert_eq!(fan_flow(800.0, 800.0, 4e-3), 0.0);
    assert_eq!(fan_flow(5000.0, 800.0, 4e-3), 0.0);
}

#[test]
fn the_running_fan_balances_the_leak_at_its_closed_form_operating_point() {
    // Qmax² (1 − p/p0) = Cd² A² 2p/ρ  ⇒  p* = Qmax² / (Qmax²/p0 + 2 Cd² A²/ρ)
    let (p0, qmax, cd, a, rho) = (800.0, 1e-3, 0.6, 1e-5, 1.2);
    let p_star = qmax * qmax / (qmax * qmax / p0 + 2.0 * cd * cd * a * a / rho);
    assert!(p_star > 700.0 && p_star < 800.0, "{p_star}");
    let mut u = unit(&[(vr::PRESSURE, 0.0), (vr::SWITCH_OFF, 1e4)]);
    assert_eq!(u.values[vr::FAN_ON as usize], 1.0);
    step_at(&mut u, p_star, 1.0);
    let m = u.values[vr::MASS_FLOW as usize];
    assert!(m.abs() <= 1e-15, "net flow at the operating point: {m}");
    // below it the cushion fills, above it the leak wins
    step_at(&mut u, 0.99 * p_star, 1.0);
    assert!(u.values[vr::MASS_FLOW as usize] > 1e-6);
    step_at(&mut u, 1.01 * p_star, 1.0);
    assert!(u.values[vr::MASS_FLOW as usize] < -1e-6);
}

#[test]
fn the_switch_closes_exactly_at_switch_on_and_opens_exactly_at_switch_off() {
    let (on, off) = (250.0, 350.0);
    assert!(demand(false, on, on, off));
    assert!(!demand(false, f64::from_bits(on.to_bits() + 1), on, off));
    assert!(!demand(true, off, on, off));
    assert!(demand(true, f64::from_bits(off.to_bits() - 1), on, off));
    for closed in [false, true] {
        assert_eq!(
            demand(closed, 300.0, on, off),
            closed,
            "in the band it holds"
        );
    }
    // through the unit without a delay: the fan follows at once
    let mut u = unit(&[(vr::PRESSURE, 300.0), (vr::SWITCH_DELAY, 0.0)]);
    let mut fan = vec![];
    for p in [300.0, 250.000_001, 250.0, 300.0, 349.999_999, 350.0, 300.0] {
        step_at(&mut u, p, 1.0);
        fan.push(u.values[vr::FAN_ON as usize]);
    }
    assert_eq!(fan, [0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0]);
}

#[test]
fn the_delay_splits_the_step_where_the_fan_toggles_and_the_duty_counts_it() {
    let (h, p_low, p_high) = (1.0, 200.0, 400.0);
    let mut u = unit(&[(vr::PRESSURE, 300.0)]);
    // the contact closes at 200 Pa; the 1.5 s delay runs out half-way through the second step
    step_at(&mut u, p_low, h);
    assert_eq!(
        (u.values[vr::FAN_ON as usize], u.values[vr::DUTY as usize]),
        (0.0, 0.0)
    );
    step_at(&mut u, p_low, h);
    assert_eq!(
        (u.values[vr::FAN_ON as usize], u.values[vr::DUTY as usize]),
        (1.0, 0.5)
    );
    let fan = fan_flow(p_low, 800.0, 1e-3);
    let leak = leak_flow(p_low, 0.6, 1e-5, 1.2);
    assert_eq!(u.values[vr::FAN_FLOW as usize], 0.5 * fan);
    assert_eq!(u.values[vr::MASS_FLOW as usize], 1.2 * (0.5 * fan - leak));
    assert_eq!(u.values[vr::DUTY_TOTAL as usize], 0.25);
    // the contact opens at 400 Pa; a step of 2 s: the fan stops 1.5 s into it
    step_at(&mut u, p_high, 2.0);
    assert_eq!(
        (u.values[vr::FAN_ON as usize], u.values[vr::DUTY as usize]),
        (0.0, 0.75)
    );
    assert_eq!(u.values[vr::DUTY_TOTAL as usize], 2.0 / 4.0);
    assert_eq!(u.time, 4.0);
}

#[test]
fn bad_values_are_refused_by_name_and_a_reversed_band_or_an_overflow_changes_nothing() {
    for (k, v, said) in [
        (
            vr::PRESSURE,
            f64::NAN,
            "pressure = NaN: values must be finite",
        ),
        (vr::FAN_PRESSURE, 0.0, "fanPressure = 0 must be > 0"),
        (vr::LEAK_AREA, -1e-300, "leakArea = -1e-300 must be >= 0"),
        (
            vr::LEAK_COEFFICIENT,
            1.5,
            "leakCoefficient = 1.5 must lie in [0, 1]",
        ),
        (vr::AIR_DENSITY, -1.2, "airDensity = -1.2 must be > 0"),
        (vr::SWITCH_DELAY, -1.0, "switchDelay = -1 must be >= 0"),
    ] {
        assert_eq!(check_value(k, v).unwrap_err(), said);
    }
    assert!(
        check_value(vr::PRESSURE, -5000.0).is_ok(),
        "suction is a pressure"
    );
    let mut u = unit(&[]);
    u.values[vr::SWITCH_ON as usize] = 400.0;
    let before = u;
    assert!(
        u.initialize()
            .unwrap_err()
            .contains("switchOn = 400 Pa must lie below switchOff = 350 Pa")
    );
    assert_eq!(u, before);
    let huge = [
        (vr::FAN_FLOW_MAX, 1e300),
        (vr::AIR_DENSITY, 1e300),
        (vr::SWITCH_DELAY, 0.0),
    ];
    let mut u = unit(&huge);
    u.values[vr::PRESSURE as usize] = -1e300;
    let before = u;
    let e = u.step(1.0).unwrap_err();
    assert!(
        e.contains("would be inf") && e.contains("the unit stays at t = 0"),
        "{e}"
    );
    assert_eq!(u, before);
}

#[test]
fn a_state_as_numbers_reads_back_equal_and_forged_numbers_are_refused() {
    let mut u = unit(&[]);
    step_at(&mut u, 200.0, 1.0);
    let n = u.to_numbers();
    assert_eq!(Unit::from_numbers(&n).unwrap(), u);
    let forged = |k: usize, x: f64| {
        let mut m = n.clone();
        m[k] = x;
        Unit::from_numbers(&m).unwrap_err()
    };
    let e = Unit::from_numbers(&n[1..]).unwrap_err();
    assert!(
        e.contains("has 23 numbers (20 before the snow mode), not 22"),
        "{e}"
    );
    assert!(forged(vr::AIR_DENSITY as usize, 0.0).contains("airDensity = 0 must be > 0"));
    assert!(forged(vr::FAN_ON as usize, 0.5).contains("must be 0 or 1"));
    assert!(forged(vr::COUNT + 1, -1.0).contains("not negative"));
    assert!(forged(vr::SWITCH_ON as usize, 500.0).contains("must lie below switchOff"));
    assert!(forged(vr::SNOW_MODE as usize, 0.5).contains("snowMode = 0.5 must be 0 or 1"));
    assert!(
        forged(vr::SNOW_SWITCH_OFF as usize, 300.0)
            .contains("snowSwitchOn = 400 Pa must lie below snowSwitchOff = 300 Pa")
    );
}

/// The snow mode (issue 43): the switch's hysteresis in the snow band `snowSwitchOn` = 400,
/// `snowSwitchOff` = 550 Pa as in the normal band: the contact closes exactly at the band's on
/// pressure, opens exactly at its off pressure, and holds in between; the same pressures in the
/// normal band (250/350 Pa) switch the other way where the bands differ.
#[test]
fn in_snow_mode_the_switch_keeps_its_hysteresis_in_the_snow_band() {
    let pressures = [
        500.0,
        400.000_001,
        400.0,
        500.0,
        549.999_999,
        550.0,
        450.0,
        300.0,
    ];
    let run = |snow: f64| {
        let mut u = unit(&[
            (vr::PRESSURE, 500.0),
            (vr::SWITCH_DELAY, 0.0),
            (vr::SNOW_MODE, snow),
        ]);
        let mut fan = vec![];
        for p in pressures {
            step_at(&mut u, p, 1.0);
            fan.push(u.values[vr::FAN_ON as usize]);
        }
        fan
    };
    assert_eq!(run(1.0), [0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 1.0]);
    // The normal band: everything above 350 Pa opens the contact; 300 Pa holds it open.
    assert_eq!(run(0.0), [0.0; 8]);
    let snowy = unit(&[(vr::SNOW_MODE, 1.0)]);
    assert_eq!(snowy.band(), (400.0, 550.0));
    assert_eq!(unit(&[]).band(), (250.0, 350.0));
}

/// The snow mode switched on and off between steps (issue 43): the contact keeps its state and
/// sees the next step's pressure against the new band. At 300 Pa (in the normal band, the fan
/// off) snow mode closes the contact (300 ≤ 400) and the fan starts after its 1.5 s delay; at
/// 500 Pa (in the snow band, the fan running) leaving snow mode opens it (500 ≥ 350) and the
/// fan stops after its delay. At power-on in snow mode the snow band decides the fan.
#[test]
fn switching_the_snow_mode_moves_the_switch_to_the_other_band() {
    let mut u = unit(&[(vr::PRESSURE, 300.0)]);
    step_at(&mut u, 300.0, 1.0);
    assert_eq!((u.contact, u.values[vr::FAN_ON as usize]), (false, 0.0));
    u.values[vr::SNOW_MODE as usize] = 1.0;
    step_at(&mut u, 300.0, 1.0);
    assert!(u.contact, "300 Pa is below the snow band's 400 Pa");
    assert_eq!(u.values[vr::FAN_ON as usize], 0.0, "the delay runs");
    step_at(&mut u, 300.0, 1.0);
    assert_eq!(
        (u.values[vr::FAN_ON as usize], u.values[vr::DUTY as usize]),
        (1.0, 0.5)
    );
    // In the snow band the fan runs on up to 550 Pa: 500 Pa holds it.
    step_at(&mut u, 500.0, 1.0);
    assert_eq!((u.contact, u.values[vr::FAN_ON as usize]), (true, 1.0));
    u.values[vr::SNOW_MODE as usize] = 0.0;
    step_at(&mut u, 500.0, 1.0);
    assert!(!u.contact, "500 Pa is above the normal band's 350 Pa");
    step_at(&mut u, 500.0, 1.0);
    assert_eq!(
        (u.values[vr::FAN_ON as usize], u.values[vr::DUTY as usize]),
        (0.0, 0.5)
    );
    // Power-on: 300 Pa calls for the fan in snow mode only.
    assert_eq!(
        unit(&[(vr::PRESSURE, 300.0)]).values[vr::FAN_ON as usize],
        0.0
    );
    let snowy = unit(&[(vr::PRESSURE, 300.0), (vr::SNOW_MODE, 1.0)]);
    assert_eq!(snowy.values[vr::FAN_ON as usize], 1.0);
    // A reversed snow band is refused by name, the unit unchanged.
    let mut u = unit(&[]);
    u.values[vr::SNOW_SWITCH_ON as usize] = 600.0;
    let before = u;
    let e = u.initialize().unwrap_err();
    assert!(
        e.contains("snowSwitchOn = 600 Pa must lie below snowSwitchOff = 550 Pa"),
        "{e}"
    );
    assert_eq!(u, before);
}

/// A state serialized before the snow mode (20 numbers: the first 15 variables, then the
/// contact, timer, on time, run time, time) reads back with snow mode off and the snow band at
/// its defaults, and continues as the unit it was saved from.
#[test]
fn a_state_serialized_before_the_snow_mode_reads_back_with_snow_mode_off() {
    let mut u = unit(&[]);
    step_at(&mut u, 200.0, 1.0);
    let n = u.to_numbers();
    let former: Vec<f64> = [&n[..vr::FORMER_COUNT], &n[vr::COUNT..]].concat();
    assert_eq!(former.len(), 20);
    let mut read = Unit::from_numbers(&former).unwrap();
    assert_eq!(read, u);
    assert_eq!(read.values[vr::SNOW_MODE as usize], 0.0);
    for p in [200.0, 300.0, 360.0] {
        step_at(&mut u, p, 1.0);
        step_at(&mut read, p, 1.0);
    }
    assert_eq!(read, u);
}

mod through_the_glue {
    //! The unit as the C layers drive it: the glue's instance core over [`Unit`].
    use fmi_glue::core::{Core, Instantiation};
    use fmi_glue::logger::Sink;
    use fmi_glue::phase::Failure;

    use crate::fmi::Instance;
    use crate::{GUID, vr};

    fn instance() -> Instance {
        let mut i = Instance::instantiate(Instantiation {
            name: "unit",
            token: Some(GUID),
            resources: None,
            sink: Sink::None,
            logging_on: false,
            fmi_version: 2,
        })
        .unwrap();
        i.setup_experiment(0.0, None).unwrap();
        i.enter_initialization_mode().unwrap();
        i.exit_initialization_mode().unwrap();
        i
    }

    /// Steps from `t` at the pressures `ps` (1 s each); the mass flows.
    fn run(i: &mut Instance, t: f64, ps: &[f64]) -> Vec<u64> {
        let mut flows = vec![];
        for (k, &p) in ps.iter().enumerate() {
            i.set_real(&[vr::PRESSURE], &[p]).unwrap();
            i.do_step(t + k as f64, 1.0).unwrap();
            let mut m = [f64::NAN];
            i.get_real(&[vr::MASS_FLOW], &mut m).unwrap();
            flows.push(m[0].to_bits());
        }
        flows
    }

    fn message(f: Failure) -> String {
        format!("{f:?}")
    }

    #[test]
    fn a_serialized_state_read_back_continues_bit_for_bit_and_foreign_bytes_are_refused() {
        let mut i = instance();
        let pressures = [240.0, 240.0, 300.0, 360.0, 360.0, 300.0];
        run(&mut i, 0.0, &[240.0]);
        let saved = i.get_fmu_state(0).unwrap();
        let mut bytes = i.serialize_fmu_state(saved).unwrap();
        let first = run(&mut i, 1.0, &pressures);
        let read = i.deserialize_fmu_state(&bytes, 0).unwrap();
        i.set_fmu_state(read).unwrap();
        let mut on = [f64::NAN];
        i.get_real(&[vr::FAN_ON], &mut on).unwrap();
        assert_eq!(
            on[0], 0.0,
            "the delay still runs: its timer is in the state"
        );
        assert_eq!(run(&mut i, 1.0, &pressures), first);
        // bytes of another FMU (the token changed), cut bytes, a forged value
        bytes[1] ^= 1;
        let e = message(i.deserialize_fmu_state(&bytes, 0).unwrap_err());
        assert!(e.contains("not a serialized state of this FMU"), "{e}");
        bytes[1] ^= 1;
        let e = message(
            i.deserialize_fmu_state(&bytes[..bytes.len() - 3], 0)
                .unwrap_err(),
        );
        assert!(e.contains("cut short"), "{e}");
        let at = GUID.len() + 1 + 8 * vr::AIR_DENSITY as usize;
        bytes[at..at + 8].copy_from_slice(&(-1.0f64).to_le_bytes());
        let e = message(i.deserialize_fmu_state(&bytes, 0).unwrap_err());
        assert!(e.contains("airDensity = -1 must be > 0"), "{e}");
    }

    /// `snowMode` through the glue (issue 43): a Boolean, set and read as one (fmi2SetBoolean /
    /// fmi3SetBoolean), refused as a Real and the Reals refused as Booleans, naming them; set
    /// between steps it moves the switch to the snow band; a state serialized by the glue keeps
    /// it.
    #[test]
    fn snow_mode_is_a_boolean_input_that_moves_the_switch_and_is_kept_in_states() {
        let mut i = instance();
        let mut b = [true];
        i.get_boolean(&[vr::SNOW_MODE], &mut b).unwrap();
        assert!(!b[0], "off at the start");
        let e = message(i.set_real(&[vr::SNOW_MODE], &[1.0]).unwrap_err());
        assert!(
            e.contains("snowMode (value reference 15) is a Boolean variable"),
            "{e}"
        );
        let e = message(i.get_real(&[vr::SNOW_MODE], &mut [0.0]).unwrap_err());
        assert!(e.contains("is a Boolean variable, not a Real one"), "{e}");
        let e = message(i.set_boolean(&[vr::PRESSURE], &[true]).unwrap_err());
        assert!(
            e.contains("pressure (value reference 0) is a Real variable"),
            "{e}"
        );
        // 300 Pa: in the normal band the fan stays off; in snow mode it starts after its delay.
        run(&mut i, 0.0, &[300.0, 300.0]);
        let fan = |i: &mut Instance| {
            let mut on = [f64::NAN];
            i.get_real(&[vr::FAN_ON], &mut on).unwrap();
            on[0]
        };
        assert_eq!(fan(&mut i), 0.0);
        i.set_boolean(&[vr::SNOW_MODE], &[true]).unwrap();
        let saved = i.get_fmu_state(0).unwrap();
        let bytes = i.serialize_fmu_state(saved).unwrap();
        run(&mut i, 2.0, &[300.0, 300.0]);
        assert_eq!(fan(&mut i), 1.0);
        let read = i.deserialize_fmu_state(&bytes, 0).unwrap();
        i.set_fmu_state(read).unwrap();
        i.get_boolean(&[vr::SNOW_MODE], &mut b).unwrap();
        assert!(b[0], "the state holds the snow mode");
        assert_eq!(fan(&mut i), 0.0);
    }

    #[test]
    fn a_non_finite_pressure_is_refused_and_an_overflowing_step_keeps_the_last_state() {
        let mut i = instance();
        let e = message(i.set_real(&[vr::PRESSURE], &[f64::INFINITY]).unwrap_err());
        assert!(e.contains("pressure = inf: values must be finite"), "{e}");
        let e = message(i.set_real(&[vr::AIR_DENSITY], &[1.5]).unwrap_err());
        assert!(e.contains("fixed parameter"), "{e}");
        let good = run(&mut i, 0.0, &[300.0]);
        // 1e308 Pa: the leak's 2|p|/ρ overflows
        i.set_real(&[vr::PRESSURE], &[1e308]).unwrap();
        let e = message(i.do_step(1.0, 1.0).unwrap_err());
        assert!(
            e.contains("Discard") && e.contains("massFlow would be -inf"),
            "{e}"
        );
        let mut m = [f64::NAN];
        i.get_real(&[vr::MASS_FLOW], &mut m).unwrap();
        assert_eq!((m[0].to_bits(), i.last_successful_time()), (good[0], 1.0));
    }
}
