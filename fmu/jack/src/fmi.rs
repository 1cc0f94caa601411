//! The jack as the shared glue (`fmu/glue`) sees it: a [`ScalarModel`] whose instance core
//! ([`Scalar`]) and FMI 2.0 and 3.0 C layers ([`fmi_glue::export_fmi2!`],
//! [`fmi_glue::export_fmi3!`]) are the glue's. The `fmi2*` and `fmi3*` functions are exported
//! from here; the phases, the checks of value references, the
//! refused step that keeps the last state, the FMU states and the log are the glue's.

use fmi_glue::description::Description;
use fmi_glue::scalar::{Scalar, ScalarModel};

use crate::{DESCRIPTION, Jack, check_value};

impl ScalarModel for Jack {
    fn description() -> &'static Description {
        &DESCRIPTION
    }

    fn new() -> Self {
        Jack::default()
    }

    fn get(&self, vr: u32) -> f64 {
        self.values[vr as usize]
    }

    fn check(vr: u32, value: f64) -> Result<(), String> {
        check_value(vr, value)
    }

    fn set(&mut self, vr: u32, value: f64) {
        self.values[vr as usize] = value;
    }

    fn time(&self) -> f64 {
        self.time
    }

    fn set_time(&mut self, t: f64) {
        self.time = t;
    }

    fn initialize(&mut self) -> Result<(), String> {
        Jack::initialize(self)
    }

    fn step(&mut self, h: f64) -> Result<(), String> {
        Jack::step(self, h)
    }

    fn derivative(&self, unknown: u32, known: u32) -> Option<f64> {
        Jack::derivative(self, unknown, known)
    }
}

/// The jack's FMU instance: the glue's core over [`Jack`].
pub type Instance = Scalar<Jack>;

fmi_glue::export_fmi2!(Instance);
fmi_glue::export_fmi3!(Instance);

#[cfg(test)]
mod tests {
    //! The FMI layer as an importer calls it, without a logger (the messages are the model's,
    //! tested in `lib.rs`; tests/python/test_never_ok_with_nan.py reads them through a logger).
    use super::fmi2_exports::*;
    use crate::{GUID, NAMES, START, vr};
    use core::ffi::c_void;
    use std::ffi::CString;

    const OK: i32 = 0;
    const DISCARD: i32 = 2;
    const ERROR: i32 = 3;

    /// An instance past fmi2ExitInitializationMode with `inputs` set in initialization mode.
    fn stepping(inputs: &[(u32, f64)]) -> *mut c_void {
        let guid = CString::new(GUID).unwrap();
        // SAFETY: NUL-terminated strings and no callbacks (NULL), as the FMI 2.0 contract allows.
        let c = unsafe {
            instantiate(
                c"jack".as_ptr(),
                1,
                guid.as_ptr(),
                std::ptr::null(),
                std::ptr::null(),
                0,
                0,
            )
        };
        assert!(!c.is_null());
        // SAFETY: `c` is a live instance; the arrays hold the announced number of elements.
        unsafe {
            assert_eq!(setup_experiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
            assert_eq!(enter_initialization_mode(c), OK);
            for &(r, v) in inputs {
                assert_eq!(set_real(c, &r, 1, &v), OK);
            }
            assert_eq!(exit_initialization_mode(c), OK);
        }
        c
    }

    /// The value of `r` (fmi2GetReal).
    fn get(c: *mut c_void, r: u32) -> f64 {
        let mut v = f64::NAN;
        // SAFETY: `c` is a live instance; one reference, one value.
        assert_eq!(unsafe { get_real(c, &r, 1, &mut v) }, OK);
        v
    }

    #[test]
    fn a_step_to_an_infinite_output_is_discarded_and_the_jack_steps_on_from_its_last_state() {
        let c = stepping(&[(vr::STIFFNESS, 1e-10)]);
        // SAFETY: `c` is a live instance; one reference, one value per call.
        unsafe {
            assert_eq!(set_real(c, &vr::FORCE, 1, &-1e-9), OK);
            assert_eq!(do_step(c, 0.0, 1.0, 1), OK);
            let before: Vec<f64> = (vr::DZ..=vr::SPEED).map(|r| get(c, r)).collect();
            assert!(before.iter().all(|v| v.is_finite()));
            // The case: force / stiffness = 1e318 overflows to dz = -inf.
            assert_eq!(set_real(c, &vr::FORCE, 1, &1e308), OK);
            assert_eq!(do_step(c, 1.0, 1.0, 1), DISCARD);
            let after: Vec<f64> = (vr::DZ..=vr::SPEED).map(|r| get(c, r)).collect();
            assert_eq!(after, before, "the last good outputs stay");
            let mut last = f64::NAN;
            assert_eq!(get_real_status(c, 2, &mut last), OK);
            assert_eq!(
                last, 1.0,
                "fmi2LastSuccessfulTime: the discarded step did not count"
            );
            // A sensible force: the same step is taken from the same state.
            assert_eq!(set_real(c, &vr::FORCE, 1, &-1e-9), OK);
            assert_eq!(do_step(c, 1.0, 1.0, 1), OK);
            assert!(get(c, vr::DZ).is_finite());
            free_instance(c);
        }
    }

    #[test]
    fn inputs_whose_outputs_overflow_in_initialization_are_refused_whole() {
        let guid = CString::new(GUID).unwrap();
        // SAFETY: as in `stepping`; then `c` is a live instance, arrays of the announced sizes.
        unsafe {
            let c = instantiate(
                c"jack".as_ptr(),
                1,
                guid.as_ptr(),
                std::ptr::null(),
                std::ptr::null(),
                0,
                0,
            );
            assert_eq!(enter_initialization_mode(c), OK);
            let (refs, values) = ([vr::STIFFNESS, vr::FORCE], [1e-10, 1e308]);
            assert_eq!(set_real(c, refs.as_ptr(), 2, values.as_ptr()), ERROR);
            assert_eq!(get(c, vr::STIFFNESS), START[vr::STIFFNESS as usize]);
            assert_eq!(get(c, vr::DZ), 0.0);
            // Non-finite and out-of-range values are refused before anything is set.
            for (r, v) in [
                (vr::FORCE, f64::NAN),
                (vr::STIFFNESS, f64::INFINITY),
                (vr::STIFFNESS, 0.0),
                (vr::RELIEF, -1.0),
                (vr::CRACK, 1.0),
                (vr::STROKE, -1e-300),
            ] {
                assert_eq!(set_real(c, &r, 1, &v), ERROR, "{} = {v}", NAMES[r as usize]);
                assert_eq!(get(c, r), START[r as usize]);
            }
            assert_eq!(exit_initialization_mode(c), OK);
            free_instance(c);
        }
    }

    #[test]
    fn a_derivative_that_overflows_is_an_error_not_an_infinite_answer() {
        let c = stepping(&[(vr::STIFFNESS, 1e-300)]);
        // SAFETY: `c` is a live instance; arrays of one element.
        unsafe {
            assert_eq!(do_step(c, 0.0, 1.0, 1), OK);
            let mut d = 0.0;
            // d dz / d force = -1 / stiffness = -1e300, seeded by 1e10
            let status = get_directional_derivative(c, &vr::DZ, 1, &vr::FORCE, 1, &1e10, &mut d);
            assert_eq!(status, ERROR);
            assert_eq!(d, 0.0, "nothing written");
            let status = get_directional_derivative(c, &vr::DZ, 1, &vr::FORCE, 1, &1.0, &mut d);
            assert_eq!((status, d), (OK, -1.0 / 1e-300));
            free_instance(c);
        }
    }
}

#[cfg(test)]
mod adjoint_tests {
    //! The glue's adjoint derivative on a model whose derivatives are exact (the jack's are
    //! analytic, so linear in the seed to the last bit).
    use fmi_glue::core::{Core, Instantiation};
    use fmi_glue::logger::Sink;

    use super::Instance;
    use crate::{GUID, vr};

    #[test]
    fn the_adjoint_is_the_transpose_of_the_directional_derivative_to_1e_12() {
        let mut i = Instance::instantiate(Instantiation {
            name: "jack",
            token: Some(GUID),
            resources: None,
            sink: Sink::None,
            logging_on: false,
            fmi_version: 3,
        })
        .unwrap();
        i.setup_experiment(0.0, None).unwrap();
        i.enter_initialization_mode().unwrap();
        i.exit_initialization_mode().unwrap();
        // In the valve's band, so that every derivative is non-zero.
        i.set_real(&[vr::FORCE, vr::RELIEF], &[-550.0, 600.0])
            .unwrap();
        i.do_step(0.0, 5.0).unwrap();
        let (unknowns, knowns) = (
            [vr::DZ, vr::PISTON, vr::SPEED],
            [vr::FORCE, vr::STIFFNESS, vr::RELIEF],
        );
        for (s, v) in [
            ([1.0, -2.0, 0.5], [0.3, 1.0, -4.0]),
            ([1e-3, 7.0, -2.0], [2.0, -0.1, 1.0]),
        ] {
            let (mut js, mut jtv) = ([0.0; 3], [0.0; 3]);
            i.directional_derivative(&unknowns, &knowns, &s, &mut js)
                .unwrap();
            i.adjoint_derivative(&unknowns, &knowns, &v, &mut jtv)
                .unwrap();
            let left: f64 = v.iter().zip(js).map(|(a, b)| a * b).sum();
            let right: f64 = jtv.iter().zip(s).map(|(a, b)| a * b).sum();
            assert!(
                left != 0.0 && (left - right).abs() <= 1e-12 * left.abs(),
                "{left} vs {right}"
            );
        }
        // A seed per unknown, a value per known: the column of FORCE seen through v = e_DZ is
        // d dz / d force.
        let (mut column, mut row) = ([0.0; 1], [0.0; 1]);
        i.directional_derivative(&[vr::DZ], &[vr::FORCE], &[1.0], &mut column)
            .unwrap();
        i.adjoint_derivative(&[vr::DZ, vr::PISTON], &[vr::FORCE], &[1.0, 0.0], &mut row)
            .unwrap();
        assert_eq!(column, row);
    }
}
