//! `fmi2DoStep` benchmark (`cargo bench --bench fmi_step`).
//!
//! The 300 mm ParallelArch FMU, called in-process through its exported C functions the way an
//! importer calls them: `frame.dz` ramped to −H/2 in 20 communication steps (the default
//! experiment), `solver.incrementsPerStep` = 1 as for the core's 20-step run. Reports the median
//! time per communication step, and the overhead of the FMI layer: the same 20 steps through
//! `mech::Analysis::step_to` directly, in the same run.

use std::ffi::{CString, c_void};
use std::time::{Duration, Instant};

use membrane_contact::fmi2::description::describe;
use membrane_contact::fmi2::exports::*;
use membrane_contact::fmi2::resources::{Source, file_uri};
use membrane_contact::fmi2::types::*;
use membrane_contact::mech::{Analysis, SolverSettings};
use membrane_contact::specimens::ParallelArch;

const STEPS: usize = 20;
const RUNS: usize = 25;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn main() {
    let spec = ParallelArch::with_height(0.3);
    let source = Source::ParallelArch(spec);
    let description = describe(&source).expect("the specimen describes");
    let dir = std::env::temp_dir().join(format!("mc-fmi-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    source.save(&dir).unwrap();
    let vr = |name: &str| {
        description
            .variables
            .iter()
            .find(|v| v.name == name)
            .unwrap()
            .value_reference
    };
    let (dz, increments) = (vr("frame.dz"), vr("solver.incrementsPerStep"));
    let name = CString::new("bench").unwrap();
    let guid = CString::new(description.guid.clone()).unwrap();
    let uri = CString::new(file_uri(&dir)).unwrap();
    let callbacks = Fmi2CallbackFunctions {
        logger: None,
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: std::ptr::null_mut::<c_void>(),
    };
    let target = spec.target()[2];
    let h = 1.0 / STEPS as f64;

    let (mut fmi_steps, mut fmi_runs, mut core_runs) = (vec![], vec![], vec![]);
    for _ in 0..RUNS {
        // SAFETY: every pointer passed is a live NUL-terminated string or a live local owned by
        // this function, as FMI 2.0 requires of an importer; `c` is used only between
        // fmi2Instantiate and fmi2FreeInstance.
        unsafe {
            let c = fmi2_instantiate(
                name.as_ptr(),
                FMI2_CO_SIMULATION,
                guid.as_ptr(),
                uri.as_ptr(),
                &callbacks,
                0,
                0,
            );
            assert!(!c.is_null(), "instantiate");
            assert_eq!(fmi2_setup_experiment(c, 0, 0.0, 0.0, 0, 1.0), 0);
            assert_eq!(fmi2_enter_initialization_mode(c), 0);
            assert_eq!(fmi2_set_integer(c, &increments, 1, &1), 0);
            assert_eq!(fmi2_exit_initialization_mode(c), 0);
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
    let _ = std::fs::remove_dir_all(&dir);
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
