//! Parallel element assembly (issue 11 item 3): `cargo bench --bench parallel`
//! (`-- --max-refine R` caps the specimen's refinement, `-- --no-solves` skips the whole runs).
//!
//! 1. One assembly (forces + consistent tangent, and forces alone as in a line search) of the
//!    refined 300 mm specimen and of issue 11's sheet, at 1 and 2 threads (and the automatic
//!    count), alternating, many times; medians and their ratio, measured in one run. `computed
//!    share`: triangles computed by both threads (across their DOF ranges), relative.
//! 2. Whole analyses at 1 and 2 threads, alternating, three times each: the sheet's centre pushed
//!    50 mm in 5 steps, the specimen refined 4 and 8 times in 20 steps. The answers are
//!    bit-identical (checked).

use std::time::{Duration, Instant};

use membrane_contact::mech::elements::gap::GapLaw;
use membrane_contact::mech::solve::assembly::System;
use membrane_contact::mech::{Analysis, Model, SolverSettings};
use membrane_contact::specimens::ParallelArch;
use nalgebra::Vector2;

#[path = "common/sheet.rs"]
mod common;
use common::sheet;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn specimen(refinement: usize) -> (ParallelArch, Model) {
    let spec = ParallelArch {
        refinement,
        ..ParallelArch::with_height(0.3)
    };
    let model = spec.model().unwrap();
    (spec, model)
}

/// Median times of one assembly with and without the tangent at each thread count of
/// `counts`, the counts alternating (the order reversed every round).
fn assembly_times(model: &Model, counts: &[usize]) -> Vec<(Duration, Duration)> {
    let mut system = System::new(model, false).unwrap();
    let laws: Vec<GapLaw> = model.gaps.iter().map(|g| g.law()).collect();
    let history = vec![Vector2::zeros(); laws.len()];
    // A deformed state: the film sagging by up to 2 cm, stretched a little in x.
    let mut u = vec![0.0; model.dof_count()];
    for (i, p) in model.nodes.iter().enumerate() {
        let r = (p[0].powi(2) + p[1].powi(2)).sqrt().min(1.0);
        u[3 * i + 2] = -0.02 * r * r;
        u[3 * i] = 1e-4 * p[0];
    }
    let mut internal = vec![0.0; model.dof_count()];
    let mut values = vec![0.0; system.nonzeros()];
    let rounds = (2_000_000 / model.triangles.len()).clamp(6, 200);
    let mut times = vec![(vec![], vec![]); counts.len()];
    for round in 0..rounds {
        for k in 0..counts.len() {
            let k = if round % 2 == 0 {
                k
            } else {
                counts.len() - 1 - k
            };
            system.set_threads(counts[k]);
            for with_tangent in [true, false] {
                let start = Instant::now();
                system.assemble(
                    &u,
                    &mut internal,
                    with_tangent.then_some(&mut values[..]),
                    |g, d| {
                        let r = laws[g].evaluate(d, history[g]);
                        (r.force, laws[g].consistent_tangent(&r))
                    },
                );
                let t = start.elapsed();
                if with_tangent {
                    times[k].0.push(t);
                } else {
                    times[k].1.push(t);
                }
            }
        }
    }
    times
        .into_iter()
        .map(|(a, b)| (median(a), median(b)))
        .collect()
}

fn assembly_row(name: &str, model: &Model) {
    let mut probe = System::new(model, false).unwrap();
    probe.set_threads(0);
    let auto = probe.threads();
    let t = assembly_times(model, &[1, 2]);
    probe.set_threads(2);
    println!(
        "| {name} | {} | {} | {:.3} ms | {:.3} ms | {:.2} | {:.3} ms | {:.3} ms | {:.2} | {:.3} | {auto} |",
        model.triangles.len(),
        probe.free_count,
        ms(t[0].0),
        ms(t[1].0),
        ms(t[1].0) / ms(t[0].0),
        ms(t[0].1),
        ms(t[1].1),
        ms(t[1].1) / ms(t[0].1),
        probe.computed_share(),
    );
}

/// A whole analysis at `threads`: its time and a fingerprint of the answer.
fn run(model: &Model, threads: usize, steps: &dyn Fn(&mut Analysis)) -> (Duration, Vec<f64>) {
    let settings = SolverSettings {
        threads,
        ..SolverSettings::default()
    };
    let started = Instant::now();
    let mut analysis = Analysis::new(model.clone(), settings).unwrap();
    steps(&mut analysis);
    let elapsed = started.elapsed();
    (elapsed, analysis.state().displacement.clone())
}

fn solve_row(name: &str, model: &Model, steps: &dyn Fn(&mut Analysis)) {
    let (mut one, mut two) = (vec![], vec![]);
    for round in 0..3 {
        let order: [usize; 2] = if round % 2 == 0 { [1, 2] } else { [2, 1] };
        let mut answers = vec![];
        for threads in order {
            let (t, u) = run(model, threads, steps);
            if threads == 1 { &mut one } else { &mut two }.push(t);
            answers.push(u);
        }
        assert!(
            answers[0]
                .iter()
                .zip(&answers[1])
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{name}: the answers at 1 and 2 threads differ"
        );
    }
    let (a, b) = (median(one), median(two));
    println!(
        "| {name} | {} | {:.1} ms | {:.1} ms | {:.2} |",
        model.triangles.len(),
        ms(a),
        ms(b),
        ms(b) / ms(a)
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let max_refine: usize = args
        .iter()
        .position(|a| a == "--max-refine")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(33);
    println!(
        "## one assembly at 1 and 2 threads (medians of alternating runs; auto = the automatic count)\n"
    );
    println!(
        "| model | triangles | free DOF | tangent, 1 thread | tangent, 2 threads | 2 / 1 | forces, 1 thread | forces, 2 threads | 2 / 1 | computed share | auto |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for r in [1, 2, 4, 8, 16, 33]
        .into_iter()
        .filter(|&r| r <= max_refine)
    {
        assembly_row(&format!("specimen r = {r}"), &specimen(r).1);
    }
    for n in [21, 41, 101, 161] {
        assembly_row(&format!("sheet {n} × {n}"), &sheet(n));
    }
    if args.iter().any(|a| a == "--no-solves") {
        return;
    }
    println!("\n## whole analyses at 1 and 2 threads (medians of three alternating runs)\n");
    println!("| analysis | triangles | 1 thread | 2 threads | 2 / 1 |");
    println!("|---|---|---|---|---|");
    let push = |analysis: &mut Analysis| {
        for k in 1..=5 {
            analysis.step_to(&[[0.0, 0.0, 0.01 * k as f64]], 1).unwrap();
        }
    };
    for n in [41, 101] {
        solve_row(&format!("sheet {n} × {n}, 5 steps"), &sheet(n), &push);
    }
    for r in [4, 8].into_iter().filter(|&r| r <= max_refine) {
        let (spec, model) = specimen(r);
        let lower = |analysis: &mut Analysis| {
            analysis.step_to(&[spec.target()], 20).unwrap();
        };
        solve_row(&format!("specimen r = {r}, 20 steps"), &model, &lower);
    }
}
