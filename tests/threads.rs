//! No thread of the FMU outlives the FMI call that started it (issue 17, defect 3; docs/fmu.md,
//! `solver.threads`).
//!
//! TEST GOAL: with `solver.threads = 2` every assembly runs a worker thread and every LDLᵀ
//! factorization a scoped rayon pool of two threads (issue 42 item 1); after each
//! `fmi2DoStep` and each `fmi2FreeInstance` the process has exactly the tasks it had before
//! (`/proc/self/task`, which lists a thread until the kernel has removed it, also after its
//! code ended): 200 steps over 10 instances. Before the fix a worker was still listed after
//! about 40 % of the calls.
//!
//! This file holds one test, so that no other test's thread changes the count.
//!
//! MODEL: the default ParallelArch specimen through the safe `Instance` API (as the exported
//! functions drive it); `frame.dz` ramped towards −0.15 m in 20 steps of one increment.

use membrane_contact::fmi2::instance::Instance;
use membrane_contact::fmi2::logger::Logger;
use membrane_contact::fmi2::resources::Source;
use membrane_contact::specimens::ParallelArch;

fn tasks() -> usize {
    std::fs::read_dir("/proc/self/task")
        .expect("/proc/self/task (Linux)")
        .count()
}

fn vr(inst: &Instance, name: &str) -> u32 {
    let v = inst.description().variables.iter().find(|v| v.name == name);
    v.expect("variable").value_reference
}

#[cfg(target_os = "linux")]
#[test]
fn no_assembly_or_factorization_thread_outlives_do_step_or_free_instance() {
    const INSTANCES: usize = 10;
    const STEPS: usize = 20;
    let baseline = tasks();
    let mut lingering = vec![];
    for i in 0..INSTANCES {
        let source = Source::ParallelArch(ParallelArch::default());
        let mut inst = Instance::from_source(source, Logger::silent()).unwrap();
        inst.setup_experiment(0.0, None).unwrap();
        inst.enter_initialization_mode().unwrap();
        let (threads, increments) = (
            vr(&inst, "solver.threads"),
            vr(&inst, "solver.incrementsPerStep"),
        );
        inst.set_integer(&[threads, increments], &[2, 1]).unwrap();
        inst.exit_initialization_mode().unwrap();
        let dz = vr(&inst, "frame.dz");
        for k in 0..STEPS {
            let fraction = (k + 1) as f64 / STEPS as f64;
            inst.set_real(&[dz], &[-0.15 * fraction]).unwrap();
            inst.do_step(k as f64, 1.0).unwrap();
            let now = tasks();
            if now != baseline {
                lingering.push(format!("instance {i}, after fmi2DoStep {k}: {now} tasks"));
            }
        }
        drop(inst);
        let now = tasks();
        if now != baseline {
            lingering.push(format!("instance {i}, after fmi2FreeInstance: {now} tasks"));
        }
    }
    assert!(
        lingering.is_empty(),
        "{} of {} calls left a task behind (baseline {baseline}): {lingering:#?}",
        lingering.len(),
        INSTANCES * (STEPS + 1)
    );
}
