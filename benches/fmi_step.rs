//! `fmi2DoStep` benchmark (`cargo bench --bench fmi_step`).
//!
//! The 300 mm ParallelArch FMU, called in-process through its exported C functions the way an
//! importer calls them: `frame.dz` ramped to −H/2 in 20 communication steps (the default
//! experiment), `solver.incrementsPerStep` = 1 as for the core's 20-step run. Reports the median
//! time per communication step, and the overhead of the FMI layer: the same 20 steps through
//! `mech::Analysis::step_to` directly, in the same run.
//!
//! `cargo bench --bench fmi_step -- derivatives` measures instead the cost of
//! `fmi2GetDirectionalDerivative` (every Real output of the state, one seed) against
//! `fmi2DoStep` along the same 20 steps: after each step, a `frame.dz` seed, then a `mu` seed
//! (the first call after a step factorizes the tangent, the second reuses the factor).

use std::ffi::{CString, c_void};
use std::time::{Duration, Instant};

use membrane_contact::fmi2::description::{Description, describe};
use membrane_contact::fmi2::exports::*;
use membrane_contact::fmi2::resources::{Source, file_uri};
use membrane_contact::fmi2::scalar_variable::{Causality, VarType};
use membrane_contact::fmi2::types::*;
use membrane_contact::mech::{Analysis, SolverSettings};
use membrane_contact::specimens::ParallelArch;

const STEPS: usize = 20;
const RUNS: usize = 25;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// The 300 mm specimen's FMU, unpacked into a temporary directory, ready to instantiate.
struct Specimen {
    spec: ParallelArch,
    description: Description,
    dir: std::path::PathBuf,
    name: CString,
    guid: CString,
    uri: CString,
    callbacks: Fmi2CallbackFunctions,
}

impl Specimen {
    fn new(tag: &str) -> Self {
        let spec = ParallelArch::with_height(0.3);
        let source = Source::ParallelArch(spec);
        let description = describe(&source).expect("the specimen describes");
        let dir = std::env::temp_dir().join(format!("mc-fmi-bench-{tag}{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        source.save(&dir).unwrap();
        Self {
            spec,
            name: CString::new("bench").unwrap(),
            guid: CString::new(description.guid.clone()).unwrap(),
            uri: CString::new(file_uri(&dir)).unwrap(),
            description,
            dir,
            callbacks: Fmi2CallbackFunctions {
                logger: None,
                allocate_memory: None,
                free_memory: None,
                step_finished: None,
                component_environment: std::ptr::null_mut::<c_void>(),
            },
        }
    }

    fn vr(&self, name: &str) -> u32 {
        self.description
            .variables
            .iter()
            .find(|v| v.name == name)
            .unwrap()
            .value_reference
    }

    /// An instance initialized with one increment per step.
    ///
    /// # Safety
    /// The caller frees it with `fmi2_free_instance` before `self` is dropped.
    unsafe fn instantiate(&self) -> Fmi2Component {
        let increments = self.vr("solver.incrementsPerStep");
        // SAFETY: every pointer passed is a live NUL-terminated string or a live field of
        // `self`, as FMI 2.0 requires of an importer.
        unsafe {
            let c = fmi2_instantiate(
                self.name.as_ptr(),
                FMI2_CO_SIMULATION,
                self.guid.as_ptr(),
                self.uri.as_ptr(),
                &self.callbacks,
                0,
                0,
            );
            assert!(!c.is_null(), "instantiate");
            assert_eq!(fmi2_setup_experiment(c, 0, 0.0, 0.0, 0, 1.0), 0);
            assert_eq!(fmi2_enter_initialization_mode(c), 0);
            assert_eq!(fmi2_set_integer(c, &increments, 1, &1), 0);
            assert_eq!(fmi2_exit_initialization_mode(c), 0);
            c
        }
    }
}

impl Drop for Specimen {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

fn main() {
    if std::env::args().any(|a| a == "derivatives") {
        return derivatives();
    }
    let specimen = Specimen::new("");
    let (spec, description) = (specimen.spec, &specimen.description);
    let dz = specimen.vr("frame.dz");
    let target = spec.target()[2];
    let h = 1.0 / STEPS as f64;

    let (mut fmi_steps, mut fmi_runs, mut core_runs) = (vec![], vec![], vec![]);
    for _ in 0..RUNS {
        // SAFETY: `c` is used only between its instantiation and fmi2FreeInstance, with live
        // locals for every pointer.
        unsafe {
            let c = specimen.instantiate();
            let run = Instant::now();
            for k in 1..=STEPS {
                let value = target * k as f64 / STEPS as f64;
                let start = Instant::now();
                assert_eq!(fmi2_set_real(c, &dz, 1, &value), 0);
                assert_eq!(fmi2_do_step(c, (k - 1) as f64 * h, h, 1), 0, "step {k}");
                fmi_steps.push(start.elapsed());
            }
            fmi_runs.push(run.elapsed());
            fmi2_terminate(c);
            fmi2_free_instance(c);
        }
        let mut analysis =
            Analysis::new(description.model.clone(), SolverSettings::default()).unwrap();
        let run = Instant::now();
        for k in 1..=STEPS {
            analysis
                .step_to(&[[0.0, 0.0, target * k as f64 / STEPS as f64]], 1)
                .unwrap();
            std::hint::black_box(analysis.results());
        }
        core_runs.push(run.elapsed());
    }
    let (step, fmi, core) = (median(fmi_steps), median(fmi_runs), median(core_runs));
    println!(
        "## fmi2DoStep, 300 mm ParallelArch, {STEPS} steps of frame.dz to −H/2, {RUNS} runs\n"
    );
    println!("| measure | value |");
    println!("|---|---|");
    println!(
        "| median time per communication step (fmi2SetReal + fmi2DoStep) | {:.3} ms |",
        step.as_secs_f64() * 1e3
    );
    println!(
        "| median 20-step run through the FMI functions | {:.2} ms |",
        fmi.as_secs_f64() * 1e3
    );
    println!(
        "| median 20-step run through the core (`step_to` + `results`) | {:.2} ms |",
        core.as_secs_f64() * 1e3
    );
    println!(
        "| FMI layer overhead | {:+.1} % |",
        100.0 * (fmi.as_secs_f64() / core.as_secs_f64() - 1.0)
    );
}

/// Median times of `fmi2DoStep` and of the two directional-derivative calls after it.
fn derivatives() {
    let specimen = Specimen::new("d");
    let (dz, mu) = (specimen.vr("frame.dz"), specimen.vr("mu"));
    let unknowns: Vec<u32> = specimen
        .description
        .variables
        .iter()
        .filter(|v| {
            v.causality == Causality::Output
                && v.var_type == VarType::Real
                && !v.name.starts_with("solver.")
        })
        .map(|v| v.value_reference)
        .collect();
    let mut out = vec![0.0; unknowns.len()];
    let target = specimen.spec.target()[2];
    let h = 1.0 / STEPS as f64;
    let (mut steps, mut first, mut second) = (vec![], vec![], vec![]);
    for _ in 0..DERIVATIVE_RUNS {
        // SAFETY: as in `main`; `unknowns` and `out` hold the same number of elements.
        unsafe {
            let c = specimen.instantiate();
            for k in 1..=STEPS {
                let value = target * k as f64 / STEPS as f64;
                let start = Instant::now();
                assert_eq!(fmi2_set_real(c, &dz, 1, &value), 0);
                assert_eq!(fmi2_do_step(c, (k - 1) as f64 * h, h, 1), 0, "step {k}");
                steps.push(start.elapsed());
                for (known, times) in [(dz, &mut first), (mu, &mut second)] {
                    let start = Instant::now();
                    let status = fmi2_get_directional_derivative(
                        c,
                        unknowns.as_ptr(),
                        unknowns.len(),
                        &known,
                        1,
                        &1.0,
                        out.as_mut_ptr(),
                    );
                    times.push(start.elapsed());
                    assert_eq!(status, 0, "derivative after step {k}");
                }
            }
            fmi2_terminate(c);
            fmi2_free_instance(c);
        }
    }
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let (step, first, second) = (median(steps), median(first), median(second));
    println!(
        "## fmi2GetDirectionalDerivative vs fmi2DoStep, 300 mm ParallelArch, {STEPS} steps, \
         {DERIVATIVE_RUNS} runs, {} Real outputs\n",
        unknowns.len()
    );
    println!("| call | median | per step |");
    println!("|---|---|---|");
    println!("| fmi2SetReal + fmi2DoStep | {:.3} ms | 1 |", ms(step));
    for (what, t) in [
        ("first derivative after the step (frame.dz seed)", first),
        ("second derivative (mu seed)", second),
    ] {
        println!(
            "| {what} | {:.3} ms | {:.2} |",
            ms(t),
            t.as_secs_f64() / step.as_secs_f64()
        );
    }
}

const DERIVATIVE_RUNS: usize = 5;
