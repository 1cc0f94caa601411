//! `fmi2GetDirectionalDerivative` against one-sided differences of the last step repeated
//! (issue 47 defect 1 and item 11).
//!
//! TEST GOAL: the derivatives of every input (a group's dx, dy, dz and hinge angle, a pressure,
//! μ) are those of the last step repeated from its start with the input moved, from both sides,
//! at states with gaps sticking, slipping and open under both friction laws; at a kink, those
//! of the side on which the contacts keep their converged statuses; after a step of several
//! increments that slid a contact, flagged with fmi2Warning (they are the last increment's).
//!
//! MODEL: the default ParallelArch specimen, with a hinge on its frame and a pressure set on
//! every triangle for the angle and pressure seeds.
//!
//! SAFETY of the `unsafe` blocks below: as in the harness (`tests/mod.rs`), each calls an
//! exported function the way an importer does, with an instance from [`Fmu`] (freed only in its
//! `Drop`) and pointers to live locals holding the announced number of elements.

use super::*;
use crate::fmi2::scalar_variable::{Causality, VarType};
use crate::mech::FrictionLaw;
use crate::mech::Model;
use crate::mech::model::format::{AllElements, ElementSelection, Hinge, PressureSet};
use crate::specimens::parallel_arch::SpecimenContact;

/// Derivative, backward and forward difference of one output.
#[derive(Clone, Copy, Debug)]
struct Sided {
    derivative: f64,
    backward: f64,
    forward: f64,
}

impl Fmu<'_> {
    /// `fmi2GetDirectionalDerivative` of `unknowns` along `known` (seed 1): status and values.
    pub(super) fn derivative_status(&self, unknowns: &[&str], known: &str) -> (c_int, Vec<f64>) {
        self.derivative_seeded(unknowns, known, 1.0)
    }

    /// `fmi2GetDirectionalDerivative` of `unknowns` along `known` with the seed `seed`.
    fn derivative_seeded(&self, unknowns: &[&str], known: &str, seed: f64) -> (c_int, Vec<f64>) {
        let refs: Vec<u32> = unknowns.iter().map(|n| self.u.vr(n)).collect();
        let mut out = vec![f64::NAN; refs.len()];
        let status = unsafe {
            fmi2_get_directional_derivative(
                self.c,
                refs.as_ptr(),
                refs.len(),
                &self.u.vr(known),
                1,
                &seed,
                out.as_mut_ptr(),
            )
        };
        (status, out)
    }

    fn reals(&self, names: &[&str]) -> Vec<f64> {
        names.iter().map(|n| self.real(n)).collect()
    }

    /// From the current state: the step `[t, t + dt]` to `end` repeated with `known` moved by
    /// each of `shifts`, then unmoved, and the derivatives of `outputs` along `known` there:
    /// the outputs of each step (the unmoved one last) and the derivatives; the FMU is left at
    /// the start of the step.
    pub(super) fn repeated(
        &self,
        (t, dt): (f64, f64),
        end: &[(&str, f64)],
        (known, shifts): (&str, &[f64]),
        outputs: &[&str],
    ) -> (Vec<Vec<f64>>, Vec<f64>) {
        let mut start: Fmi2FmuState = std::ptr::null_mut();
        assert_eq!(unsafe { fmi2_get_fmu_state(self.c, &mut start) }, 0);
        let step = |shift: f64| {
            assert_eq!(unsafe { fmi2_set_fmu_state(self.c, start) }, 0);
            for &(n, v) in end {
                let v = if n == known { v + shift } else { v };
                assert_eq!(self.set_real(n, v), 0, "{n}");
            }
            assert_eq!(
                self.step(t, dt),
                0,
                "{known} {shift}: {:?}",
                self.log.take()
            );
            self.reals(outputs)
        };
        let points: Vec<Vec<f64>> = shifts.iter().chain([&0.0]).map(|&x| step(x)).collect();
        let (status, derivative) = self.derivative_status(outputs, known);
        assert_eq!(status, 0, "{known}: {:?}", self.log.take());
        unsafe {
            assert_eq!(fmi2_set_fmu_state(self.c, start), 0);
            assert_eq!(fmi2_free_fmu_state(self.c, &mut start), 0);
        }
        (points, derivative)
    }

    /// From the current state: the step `[t, t + 1]` to `end`, the derivatives of `outputs`
    /// w.r.t. `known` there, and its one-sided differences from the same step repeated with
    /// `known` moved by `±h, …, ±4h`; the FMU is left at the start of the step.
    fn sided(
        &self,
        t: f64,
        end: &[(&str, f64)],
        known: &str,
        h: f64,
        outputs: &[&str],
    ) -> Vec<Sided> {
        // Fourth-order one-sided differences (points 0, ±h, …, ±4h): the slip direction of a
        // slipping gap turns over a length of its last slip increment, which a lower order
        // turns into more than 1e-6 of the derivative at any step above the rounding.
        let shifts: Vec<f64> = [1.0, 2.0, 3.0, 4.0, -1.0, -2.0, -3.0, -4.0]
            .iter()
            .map(|k| k * h)
            .collect();
        let (points, derivative) = self.repeated((t, 1.0), end, (known, &shifts), outputs);
        let (plus, minus, at) = (&points[..4], &points[4..8], &points[8]);
        (0..outputs.len())
            .map(|i| Sided {
                derivative: derivative[i],
                backward: -one_sided(at[i], minus.iter().map(|m| m[i]), h),
                forward: one_sided(at[i], plus.iter().map(|p| p[i]), h),
            })
            .collect()
    }
}

/// `f'(0)` from `f(0)` and `f(h), …, f(4h)` (fourth order).
fn one_sided(f0: f64, f: impl Iterator<Item = f64>, h: f64) -> f64 {
    let c = [48.0, -36.0, 16.0, -3.0];
    (f.zip(c).map(|(f, c)| c * f).sum::<f64>() - 25.0 * f0) / (12.0 * h)
}

/// The inputs of every kind a seed can move (`cover.pressure`: a pressure set on every triangle;
/// `frame.angle`: a hinge on the frame).
const SEEDS: [&str; 6] = [
    "frame.dx",
    "frame.dy",
    "frame.dz",
    "frame.angle",
    "cover.pressure",
    "mu",
];

/// The default specimen with `contact` under `law`, its frame turning about a hinge (the line
/// through the first frame node along global y) and a pressure set on every triangle (0 Pa at
/// the start): every kind of input of the FMU moves it.
pub(crate) fn every_input_specimen(law: FrictionLaw, contact: SpecimenContact) -> Model {
    let spec = ParallelArch {
        friction_law: law,
        contact,
        ..ParallelArch::default()
    };
    let mut model = spec.model().unwrap();
    let first = model.nodes[model.groups[0].nodes[0]];
    model.groups[0].hinge = Some(Hinge {
        point: first,
        axis: [0.0, 1.0, 0.0],
        target_angle: 0.0,
    });
    model.loads.pressures.push(cover());
    model
}

/// The follower pressure set `cover` on every triangle, at 0 Pa.
pub(crate) fn cover() -> PressureSet {
    PressureSet {
        kind: Default::default(),
        name: "cover".into(),
        elements: ElementSelection::All(AllElements::All),
        pressure: 0.0,
        towards: None,
    }
}

/// The Real outputs of the state (those with derivatives).
fn state_outputs(u: &Unpacked) -> Vec<String> {
    u.variables
        .iter()
        .filter(|v| {
            v.causality == Causality::Output
                && v.var_type == VarType::Real
                && super::super::outputs::is_state_result(&v.binding)
        })
        .map(|v| v.name.clone())
        .collect()
}

/// The derivatives' largest deviation from a one-sided difference of steps (relative): 5e-5.
/// The differences' own noise is about 1e-6 (steps converged to 1e-12, residuals near 1e-10 N
/// against gap forces of 28 N; the two sides agree to 1.4e-6 at most), their truncation
/// (fourth order) below 1e-7. The derivatives of gap `G2`, slipping under the isotropic law,
/// deviate more, the same way from both sides: 4.5e-6 (`normalForce`, seed μ, μ = 0.2; 2.1e-6
/// at the former fallback ladder's converged state) and 3.6e-5 (`frictionY`, seed pressure,
/// μ = 1; 1.2e-5 at the state the ramp reached before the increments were sized by the
/// iterations to equilibrium, and the same with a pressure step of 0.05 Pa instead of 0.2, so
/// not the differences' truncation). That bias of the linear response at a slipping isotropic
/// gap is not explained yet (CHANGELOG, issue 41's note); every other output and seed is below
/// 3e-6, every x and y seed below 7e-7. A wrong term of a seed's right-hand side (the sign of a
/// group's x) deviates by order 1.
const TOLERANCE: f64 = 5e-5;

/// The step `h` of the differences of `known`.
fn step_of(known: &str) -> f64 {
    match known {
        "cover.pressure" => 0.2,
        "frame.angle" => 1e-5,
        "mu" => 2e-3,
        _ => 4e-6,
    }
}

/// `frame.dz` lowered in 11 steps to −0.055 with μ = 0.2, and μ = `mu` from the last of them
/// on: the start of the step checked (to −0.06, `end_inputs`). μ changes before the step
/// checked, not during it: a jump of μ (0.2 → 1 under the isotropic law) is a step the method
/// cuts into two increments, whose derivative is then its last increment's (the FMU warns).
/// A ramp step may warn (OK or Warning): at these tolerances (1e-12) the nearly slack film of
/// step 4 is carried by two stabilized increments whose damping takes out 6.9 % of its 8.5e-3 J
/// of strain energy, released to the undamped equilibrium (residual 1.3e-11 N) at its end.
fn ramp_to_start(fmu: &Fmu, mu: f64) {
    assert_eq!(fmu.set_real("mu", 0.2), 0);
    for k in 1..=11 {
        if k == 11 {
            assert_eq!(fmu.set_real("mu", mu), 0);
        }
        assert_eq!(fmu.set_real("frame.dz", -0.005 * k as f64), 0);
        let status = fmu.step(k as f64 - 1.0, 1.0);
        assert!(status <= 1, "{status}: {:?}", fmu.log.take());
    }
}

/// The end inputs of the step checked, μ = `mu` during it.
fn end_inputs(mu: f64) -> [(&'static str, f64); 6] {
    [
        ("frame.dx", 0.0),
        ("frame.dy", 0.0),
        ("frame.dz", -0.06),
        ("frame.angle", 0.0),
        ("cover.pressure", 0.0),
        ("mu", mu),
    ]
}

/// The largest deviation of the derivatives from each one-sided difference, relative to the
/// difference (at least 1e-3 of the largest of its unit for this seed, so that an output zero
/// up to rounding is not compared with its own noise): `(backward, forward)`.
fn deviations(u: &Unpacked, outputs: &[&str], sided: &[Sided]) -> (f64, f64) {
    let unit = |o: &str| u.variables.iter().find(|v| v.name == o).unwrap().unit;
    let mut worst = (0.0_f64, 0.0_f64);
    for (o, s) in outputs.iter().zip(sided) {
        let largest = outputs
            .iter()
            .zip(sided)
            .filter(|(p, _)| unit(p) == unit(o))
            .fold(0.0_f64, |m, (_, t)| {
                m.max(t.backward.abs()).max(t.forward.abs())
            });
        let scale = s.backward.abs().max(1e-3 * largest);
        worst.0 = worst.0.max((s.derivative - s.backward).abs() / scale);
        worst.1 = worst.1.max((s.derivative - s.forward).abs() / scale);
    }
    worst
}

/// Issue 47 defect 1: every input seed (frame.dx/dy/dz, the hinge angle, a pressure, μ) of the
/// specimen under both friction laws, at states with gaps sticking, slipping and open: the
/// derivative is within 1e-6 of both one-sided differences of the re-done last step (one
/// increment). Before, no test seeded a group's x or y (a sign flipped in the right-hand side
/// of a group's x seed passed every test).
#[test]
fn directional_derivatives_of_every_input_match_both_one_sided_differences_of_the_repeated_step_at_stick_slip_and_open_contacts()
 {
    // (law, μ of the step checked, statuses expected at its end).
    let cases = [
        (FrictionLaw::Isotropic, 0.2, [2, 2, 0]),
        (FrictionLaw::Isotropic, 1.0, [2, 2, 0]),
        (FrictionLaw::Isotropic, 9.9, [1, 1, 0]),
        (FrictionLaw::SlidingDirection, 0.2, [2, 2, 0]),
        (FrictionLaw::SlidingDirection, 9.9, [1, 1, 0]),
    ];
    for (law, mu, statuses) in cases {
        let u = Unpacked::new(
            &format!("derivatives {law} {mu}"),
            Source::Model(every_input_specimen(law, SpecimenContact::Gaps)),
        );
        let log = Log::default();
        let fmu = Fmu::initialized(
            &u,
            &log,
            &[
                ("solver.displacementTolerance", 1e-12),
                ("solver.residualTolerance", 1e-12),
            ],
            &[("solver.incrementsPerStep", 1)],
        );
        ramp_to_start(&fmu, mu);
        let names = state_outputs(&u);
        let outputs: Vec<&str> = names.iter().map(String::as_str).collect();
        for known in SEEDS {
            if known == "mu" && mu > 9.0 {
                continue; // below: μ + 4h would exceed 10
            }
            let sided = fmu.sided(11.0, &end_inputs(mu), known, step_of(known), &outputs);
            let (backward, forward) = deviations(&u, &outputs, &sided);
            assert!(
                backward <= TOLERANCE,
                "{law} μ = {mu}, {known}: backward {backward:e} forward {forward:e}"
            );
            assert!(
                forward <= TOLERANCE,
                "{law} μ = {mu}, {known}: forward {forward:e}"
            );
        }
        for &(n, v) in &end_inputs(mu) {
            assert_eq!(fmu.set_real(n, v), 0);
        }
        assert_eq!(fmu.step(11.0, 1.0), 0);
        let seen: Vec<i32> = (1..=3)
            .map(|i| fmu.integer(&format!("G{i}.status")))
            .collect();
        assert_eq!(seen, statuses, "{law} μ = {mu}");
        if mu > 9.0 {
            // Every closed gap sticks: nothing moves with μ, exactly.
            let (status, d) = fmu.derivative_status(&outputs, "mu");
            assert_eq!(status, 0);
            assert!(d.iter().all(|&d| d == 0.0), "{d:?}");
        }
    }
}

/// Issue 47 defect 1 as reported: the default specimen (ten increments per step), `frame.dz`
/// lowered in 12 steps to −0.06 (G1, G2 slip, the rest open). The derivatives of the last
/// increment are not those of the step (the slipping gaps' direction turns in each of its
/// increments): `fmi2Warning` says so, naming the remedy; with one increment per step they are
/// the step's, within [`TOLERANCE`] of both one-sided differences of the step repeated, for
/// every seed of the specimen. Before, the first answered fmi2OK.
#[test]
fn derivatives_after_a_step_of_several_increments_that_slid_contacts_are_flagged_and_exact_with_one()
 {
    let outputs = [
        "frame.Rx", "frame.Ry", "frame.Rz", "G1.slip", "G2.slip", "G2.slipY",
    ];
    for increments in [10, 1] {
        let (u, log) = (
            Unpacked::specimen(&format!("issue47 {increments}")),
            Log::default(),
        );
        let fmu = Fmu::initialized(&u, &log, &[], &[("solver.incrementsPerStep", increments)]);
        for k in 1..12 {
            assert_eq!(fmu.set_real("frame.dz", -0.005 * k as f64), 0);
            assert_eq!(fmu.step(k as f64 - 1.0, 1.0), 0);
        }
        let end = [
            ("frame.dx", 0.0),
            ("frame.dy", 0.0),
            ("frame.dz", -0.06),
            ("mu", 0.2),
        ];
        if increments == 1 {
            for known in ["frame.dx", "frame.dy", "frame.dz", "mu"] {
                let sided = fmu.sided(11.0, &end, known, step_of(known), &outputs);
                for (o, s) in outputs.iter().zip(&sided) {
                    eprintln!(
                        "| `{o}` | `{known}` | {:.6e} | {:.6e} | {:.6e} |",
                        s.derivative, s.backward, s.forward
                    );
                }
                let (backward, forward) = deviations(&u, &outputs, &sided);
                assert!(
                    backward.max(forward) <= TOLERANCE,
                    "{known}: {backward:e} {forward:e}"
                );
            }
            continue;
        }
        let mut state: Fmi2FmuState = std::ptr::null_mut();
        assert_eq!(unsafe { fmi2_get_fmu_state(fmu.c, &mut state) }, 0);
        for &(n, v) in &end {
            assert_eq!(fmu.set_real(n, v), 0);
        }
        assert_eq!(fmu.step(11.0, 1.0), 0);
        let statuses: Vec<i32> = (1..=9)
            .map(|i| fmu.integer(&format!("G{i}.status")))
            .collect();
        assert_eq!(statuses, [2, 2, 0, 0, 0, 0, 0, 0, 0]);
        log.take();
        let (status, d) = fmu.derivative_status(&outputs, "frame.dx");
        assert_eq!(status, Status::Warning.raw());
        assert!(d.iter().all(|d| d.is_finite()));
        assert!(
            log.contains(
                Status::Warning,
                "derivatives of the last of the step's 10 increments, the earlier ones held: 2 contacts slide"
            ) && log.contains(Status::Warning, "set solver.incrementsPerStep = 1"),
            "{:?}",
            log.take()
        );
        // A restored state: the derivatives are those of one increment from it, no warning.
        assert_eq!(unsafe { fmi2_set_fmu_state(fmu.c, state) }, 0);
        assert_eq!(fmu.derivative_status(&outputs, "frame.dx").0, 0);
        unsafe { assert_eq!(fmi2_free_fmu_state(fmu.c, &mut state), 0) };
    }
}

/// Issue 47 item 6: a seed of 1e-300 or 1e-320 gets the answer of a seed of 1 scaled by it (it
/// was refused as "singular Newton matrix (zero pivot)"), a seed of 1e308 too where the product
/// is finite, and where it overflows an fmi2Error saying so, never an infinite value; a zero
/// seed gives zeros.
#[test]
fn tiny_and_huge_seeds_get_the_unit_seeds_answer_scaled() {
    let (u, log) = (Unpacked::specimen("seed scale"), Log::default());
    let fmu = Fmu::initialized(&u, &log, &[], &[("solver.incrementsPerStep", 1)]);
    for k in 1..4 {
        assert_eq!(fmu.set_real("frame.dz", -0.005 * k as f64), 0);
        assert_eq!(fmu.step(k as f64 - 1.0, 1.0), 0);
    }
    let outputs = ["frame.Rz"];
    let (status, unit) = fmu.derivative_seeded(&outputs, "frame.dz", 1.0);
    assert_eq!(status, 0);
    assert!(unit.iter().all(|d| d.is_finite() && *d != 0.0), "{unit:?}");
    for seed in [1e-300, 1e-320, 1e-3, 0.0] {
        let (status, out) = fmu.derivative_seeded(&outputs, "frame.dz", seed);
        assert_eq!(status, 0, "seed {seed}: {:?}", log.take());
        for (d, one) in out.iter().zip(&unit) {
            let expected = one * seed;
            let close = (d - expected).abs() <= 1e-9 * expected.abs().max(f64::MIN_POSITIVE)
                || (seed < 1e-307 && (d / seed - one).abs() <= 1e-3 * one.abs());
            assert!(close, "seed {seed}: {d:e} against {expected:e}");
        }
    }
    // 1e308 × |∂Rz/∂dz| (N/m, far above 1) overflows: an error naming it, not an infinity.
    let (status, out) = fmu.derivative_seeded(&["frame.Rz"], "frame.dz", 1e308);
    assert_eq!(status, Status::Error.raw(), "{out:?}");
    assert!(log.contains(Status::Error, "overflows"));
    // Where the product is finite, a huge seed is answered.
    let (status, out) = fmu.derivative_seeded(&outputs, "frame.dz", 1e300);
    assert_eq!(status, 0);
    assert!(
        (out[0] / 1e300 - unit[0]).abs() <= 1e-9 * unit[0].abs(),
        "{out:?}"
    );
}
