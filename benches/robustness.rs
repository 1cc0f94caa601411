//! Robustness benchmark (`cargo bench --bench robustness`): every load path of
//! [`scenarios::robustness_grid`] (≥ 500: the specimen family, panels over two arches with an
//! edge jacked about a hinge, strips over cylinders, a film edge on an arch, the wrapped
//! specimens, ETFE's plastic film on specimens, cushions and panels, and three-layer cushions
//! with sealed air inverted by snow) run with the
//! default solver settings and the FMU's default increments per step. Prints, per family, how
//! many paths converge, Newton iterations per increment (mean over all converged increments,
//! and the most in one increment), cut-backs, and the first failure; then the total.
//!
//! Options (after `--`): `--family NAME` (specimen, panel, strip, arch-edge, wrapped, plastic,
//! cushion; repeatable),
//! `--quick` (every 10th path of each family), `--failures` (print every failed path),
//! `--threads N` (paths run in parallel, default: available cores), `--check` (exit with status 1
//! unless every path run converges, after listing the failures: CI runs
//! `cargo bench --bench robustness -- --check --quick`).
//!
//! This measures convergence, not speed; the wall time is printed only so that the run can be
//! planned.

use std::time::Instant;

use membrane_contact::fmi2::variables::DEFAULT_INCREMENTS_PER_STEP;
use membrane_contact::mech::SolverSettings;
use membrane_contact::specimens::scenarios::{
    Family, RunOutcome, Scenario, grid_slice, robustness_grid,
};

#[path = "common/options.rs"]
mod options;
use options::{PathOptions, on_threads};

/// Runs `paths` on `threads` worker threads; results in the order of `paths`.
fn run_all(paths: &[Scenario], threads: usize) -> Vec<(RunOutcome, f64)> {
    on_threads(paths, threads, |p| {
        let start = Instant::now();
        let outcome = p.run(SolverSettings::default());
        (outcome, start.elapsed().as_secs_f64())
    })
}

fn main() {
    let names: Vec<&str> = Family::ALL.iter().map(|f| f.name()).collect();
    let o = PathOptions::parse(&names, |_, _| Ok(false)).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2);
    });
    let families: Vec<Family> = Family::ALL
        .into_iter()
        .filter(|f| o.families.iter().any(|n| n == f.name()))
        .collect();
    let increments = usize::try_from(DEFAULT_INCREMENTS_PER_STEP).unwrap();
    let grid = robustness_grid(increments).expect("the benchmark grid builds");
    let stride = if o.quick { 10 } else { 1 };
    let paths: Vec<Scenario> = families
        .iter()
        .flat_map(|family| grid_slice(&grid, *family, stride))
        .collect();
    println!(
        "## robustness: {} load paths, default solver settings, {increments} increments per step \
         (1 for the CLI-style panel ramps), {} threads\n",
        paths.len(),
        o.threads
    );
    let start = Instant::now();
    let results = run_all(&paths, o.threads);
    let wall = start.elapsed().as_secs_f64();

    println!(
        "| family | paths | converged | % | iterations / increment (mean) | max per increment | cut-backs | steps converged | path s | first failure |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut total = (0, 0, 0, 0, 0, 0.0);
    let row = |name: &str, sel: &[(&Scenario, &(RunOutcome, f64))]| {
        let n = sel.len();
        let ok = sel.iter().filter(|(_, (r, _))| r.converged()).count();
        let iterations: usize = sel.iter().map(|(_, (r, _))| r.iterations()).sum();
        let incs: usize = sel.iter().map(|(_, (r, _))| r.increments()).sum();
        let cut: usize = sel.iter().map(|(_, (r, _))| r.cutbacks()).sum();
        let steps_ok: usize = sel
            .iter()
            .map(|(_, (r, _))| r.steps.iter().filter(|s| s.error.is_none()).count())
            .sum();
        let steps_all: usize = sel.iter().map(|(s, _)| s.path.steps()).sum();
        let max = sel
            .iter()
            .map(|(_, (r, _))| r.max_increment_iterations())
            .max()
            .unwrap_or(0);
        let cpu: f64 = sel.iter().map(|(_, (_, t))| t).sum();
        let first = sel
            .iter()
            .find_map(|(s, (r, _))| r.failure_message().map(|m| format!("{}: {m}", s.name)))
            .unwrap_or_else(|| "–".into());
        println!(
            "| {name} | {n} | {ok} | {:.1} | {:.2} | {max} | {cut} | {steps_ok}/{steps_all} | {cpu:.1} | {} |",
            100.0 * ok as f64 / n.max(1) as f64,
            iterations as f64 / incs.max(1) as f64,
            first.replace('|', "/")
        );
        (n, ok, iterations, incs, cut, cpu)
    };
    let pairs: Vec<(&Scenario, &(RunOutcome, f64))> = paths.iter().zip(&results).collect();
    for family in &families {
        let sel: Vec<_> = pairs
            .iter()
            .copied()
            .filter(|(s, _)| s.family == *family)
            .collect();
        let r = row(family.name(), &sel);
        total = (
            total.0 + r.0,
            total.1 + r.1,
            total.2 + r.2,
            total.3 + r.3,
            total.4 + r.4,
            total.5 + r.5,
        );
    }
    println!(
        "\n| family | converged | of them every step within the stabilization bound | increments viscously stabilized |\n|---|---|---|---|"
    );
    for family in &families {
        let sel: Vec<_> = pairs.iter().filter(|(s, _)| s.family == *family).collect();
        println!(
            "| {} | {} | {} | {} |",
            family.name(),
            sel.iter().filter(|(_, (r, _))| r.converged()).count(),
            sel.iter().filter(|(_, (r, _))| r.within_bound()).count(),
            sel.iter().map(|(_, (r, _))| r.stabilized()).sum::<usize>()
        );
    }
    let failed: Vec<(String, String)> = pairs
        .iter()
        .filter_map(|(s, (r, _))| r.failure_message().map(|m| (s.name.clone(), m.to_string())))
        .collect();
    o.finish(total, 2, wall, &failed);
}
