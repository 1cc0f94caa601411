//! Solver benchmark (`cargo bench --bench solver`; `-- --max-dof N` to cap the mesh size).
//!
//! 1. The whole 300 mm specimen analysis (20 steps), median of repeated runs, with the Newton
//!    iterations per increment for both iteration matrices.
//! 2. One Newton iteration (element + assembly + contact work, then factorization + solve) on
//!    refined specimens up to ≥ 1 M DOF, beside a bare factorization of the same matrix, and the
//!    memory of our data (pattern, slots, values, vectors) beside the factor's.
//!
//! Figures are ratios measured in one run; the machine is shared, so absolute times drift.

use std::time::{Duration, Instant};

use membrane_contact::mech::elements::gap::GapLaw;
use membrane_contact::mech::solve::assembly::System;
use membrane_contact::mech::solve::linear::LinearSolver;
use membrane_contact::mech::{Analysis, IterationMatrix, SolverSettings};
use membrane_contact::specimens::ParallelArch;
use nalgebra::Vector2;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// Resident set size now and at its peak (bytes), from /proc (0 where unavailable).
fn rss() -> (usize, usize) {
    let text = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let field = |name: &str| {
        text.lines()
            .find(|l| l.starts_with(name))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|v| v.parse::<usize>().ok())
            .map_or(0, |kb| kb * 1024)
    };
    (field("VmRSS:"), field("VmHWM:"))
}

fn mib(bytes: usize) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

fn whole_specimen() {
    println!("## whole 300 mm specimen analysis (20 steps to frame.dz = -H/2)\n");
    let mut finals: Vec<Vec<f64>> = vec![];
    println!(
        "| iteration matrix | median time | increments | cut-backs | iterations | per increment |"
    );
    println!("|---|---|---|---|---|---|");
    for matrix in [IterationMatrix::Consistent, IterationMatrix::JuRowlands] {
        let spec = ParallelArch::with_height(0.3);
        // Ju–Rowlands converges linearly (see docs/mechanics.md): give it the iterations it needs.
        let max_iterations = match matrix {
            IterationMatrix::JuRowlands => 3000,
            IterationMatrix::Consistent => SolverSettings::default().max_iterations,
        };
        let settings = SolverSettings {
            iteration_matrix: matrix,
            max_iterations,
            ..SolverSettings::default()
        };
        let mut times = vec![];
        let mut outcome = String::new();
        for _ in 0..if matrix == IterationMatrix::Consistent {
            15
        } else {
            1
        } {
            let start = Instant::now();
            let mut analysis = Analysis::new(spec.model().unwrap(), settings).unwrap();
            let (mut iterations, mut increments, mut cutbacks) = (0, 0, 0);
            let mut failed = None;
            for step in 1..=20 {
                let target = spec.target().map(|v| v * step as f64 / 20.0);
                match analysis.step_to(&[target], 1) {
                    Ok(r) => {
                        iterations += r.total_iterations();
                        increments += r.iterations.len();
                        cutbacks += r.cutbacks;
                    }
                    Err(e) => {
                        failed = Some(format!("failed at step {step}: {e}"));
                        break;
                    }
                }
            }
            times.push(start.elapsed());
            if times.len() == 1 && failed.is_none() {
                finals.push(analysis.state().displacement.clone());
            }
            outcome = match failed {
                None => format!(
                    "{increments} | {cutbacks} | {iterations} | {:.1}",
                    iterations as f64 / increments as f64
                ),
                Some(f) => format!("- | - | - | {f}"),
            };
        }
        println!(
            "| {matrix:?} | {:.2} ms | {outcome} |",
            median(times).as_secs_f64() * 1e3
        );
    }
    if let [a, b] = &finals[..] {
        let du = a
            .iter()
            .zip(b)
            .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
        println!(
            "\nlargest difference of the converged displacements between the two matrices: {du:.2e} m"
        );
    }
    println!();
}

/// One Newton iteration on the refined specimen, measured in a fresh process (clean RSS).
fn iteration_at(refinement: usize, matrix: IterationMatrix) {
    let spec = ParallelArch {
        refinement,
        ..ParallelArch::with_height(0.3)
    };
    let model = spec.model().unwrap();
    let system = System::new(&model, matrix == IterationMatrix::JuRowlands).unwrap();
    let laws: Vec<GapLaw> = model.gaps.iter().map(|g| g.law()).collect();
    // A deformed state: the frame lowered by 2 cm and the film sagging with it, gaps pressed.
    let mut u = vec![0.0; model.dof_count()];
    for (i, p) in model.nodes.iter().enumerate() {
        let r = (p[0].powi(2) + p[1].powi(2)).sqrt().min(1.0);
        u[3 * i + 2] = -0.02 * r * r;
        u[3 * i] = 1e-4 * p[0];
    }
    let history = vec![Vector2::zeros(); laws.len()];
    let mut internal = vec![0.0; model.dof_count()];
    let mut values = vec![0.0; system.nonzeros()];
    let mut rhs = vec![0.0; system.free_count];
    // Ours: pattern, slots, elements, the value array and the vectors an iteration uses.
    let ours =
        system.memory_bytes() + 8 * (values.len() + internal.len() + rhs.len() + 2 * u.len());
    let mut linear = LinearSolver::new(&system, false).unwrap();
    let assemble = |internal: &mut Vec<f64>, values: &mut Vec<f64>| {
        system.assemble(&u, internal, Some(values), |g, d| {
            let r = laws[g].evaluate(d, history[g]);
            let k = match matrix {
                IterationMatrix::Consistent => laws[g].consistent_tangent(&r),
                IterationMatrix::JuRowlands => laws[g].ju_rowlands_matrix(r.status, r.direction),
            };
            (r.force, k)
        })
    };
    // A small diagonal shift keeps the synthetic state's matrix safely nonsingular.
    let shift = 1e-3 * model.material.membrane_stiffness();
    let p = system.pattern();
    let diagonal: Vec<usize> = (0..system.free_count)
        .map(|j| {
            let rows = &p.row_idx()[p.col_ptr()[j]..p.col_ptr()[j + 1]];
            p.col_ptr()[j] + rows.binary_search(&j).unwrap()
        })
        .collect();
    let runs = if system.free_count > 200_000 {
        2
    } else if system.free_count > 20_000 {
        4
    } else {
        30
    };
    let (mut t_assembly, mut t_factor, mut t_bare) = (vec![], vec![], vec![]);
    let mut factor_bytes = 0;
    for run in 0..runs {
        let start = Instant::now();
        assemble(&mut internal, &mut values);
        t_assembly.push(start.elapsed());
        for &d in &diagonal {
            values[d] += shift;
        }
        rhs.fill(1.0);
        let before = rss().0;
        let start = Instant::now();
        linear
            .factorize_and_solve(system.matrix(&values), &mut rhs)
            .unwrap();
        t_factor.push(start.elapsed());
        if run == 0 {
            // The factor's memory: what the first numeric factorization added (its buffers are
            // allocated then and reused), at least the LDLᵀ value count.
            factor_bytes = rss().0.saturating_sub(before).max(8 * linear.factor_len());
        }
        // Bare: the same factorization again, with nothing else around it.
        let start = Instant::now();
        linear
            .factorize_and_solve(system.matrix(&values), &mut rhs)
            .unwrap();
        t_bare.push(start.elapsed());
    }
    let (assembly, factor, bare) = (median(t_assembly), median(t_factor), median(t_bare));
    println!(
        "| {refinement} | {:?} | {} | {} | {:.3} ms | {:.3} ms | {:.3} ms | {:.3} | {:.0} MiB | {:.0} MiB | {:.2} |",
        matrix,
        system.free_count,
        system.nonzeros(),
        assembly.as_secs_f64() * 1e3,
        factor.as_secs_f64() * 1e3,
        bare.as_secs_f64() * 1e3,
        assembly.as_secs_f64() / bare.as_secs_f64(),
        mib(ours),
        mib(factor_bytes),
        ours as f64 / factor_bytes.max(1) as f64,
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let option = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
    };
    if let Some(one) = option("--one") {
        // Child process: one (refinement, matrix) case.
        let (r, m) = one.split_once(',').unwrap();
        let matrix = if m == "lu" {
            IterationMatrix::Consistent
        } else {
            IterationMatrix::JuRowlands
        };
        iteration_at(r.parse().unwrap(), matrix);
        return;
    }
    let max_dof: usize = option("--max-dof")
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_100_000);
    // LU at 1 M DOF needs ≈ 10 GiB and a few minutes; `--max-lu-dof` caps it apart.
    let max_lu_dof: usize = option("--max-lu-dof")
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_100_000);
    whole_specimen();
    println!("## one Newton iteration on refined specimens\n");
    println!(
        "element + assembly + contact work (`assembly`) vs the factorization + solve of the same"
    );
    println!(
        "matrix inside the iteration and a bare repeat of it; memory: our pattern, slots, values and"
    );
    println!("vectors vs the factor (each case in a fresh process).\n");
    println!(
        "| refinement | matrix | free DOF | nonzeros | assembly | factor+solve | bare factor | assembly/bare | our memory | factor memory | ours/factor |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let exe = std::env::current_exe().unwrap();
    for refinement in [1, 4, 16, 33, 58] {
        let dof = 3 * (10 * refinement + 1usize).pow(2);
        for (name, cap) in [("lu", max_lu_dof), ("ldlt", max_dof)] {
            if dof > cap {
                continue;
            }
            let out = std::process::Command::new(&exe)
                .args(["--one", &format!("{refinement},{name}")])
                .output()
                .unwrap();
            print!("{}", String::from_utf8_lossy(&out.stdout));
            if !out.status.success() {
                println!(
                    "| {refinement} | {name} | failed: {} |",
                    String::from_utf8_lossy(&out.stderr)
                        .lines()
                        .last()
                        .unwrap_or("")
                );
            }
        }
    }
}
