//! One Newton iteration of the consistent tangent at scale against the bare LDLᵀ factorization
//! (issue 11 item 2): `cargo bench --bench newton` (`-- --refine 4,16 --steps 20 --methods
//! auto,gmres`).
//!
//! For each refinement `r` of the 300 mm specimen (`ParallelArch`, `3 (10 r + 1)²` DOF) and
//! each way of solving the unsymmetric tangent, a fresh process runs the first `--steps` of the
//! 20 steps to the target (one increment each, gaps sliding) with the default settings, and
//! reports where the time went (`Analysis::solve_profile`): the symmetric-part pass, the LDLᵀ
//! factorizations, the Woodbury block solves or GMRES iterations, the accuracy checks, LU
//! fallbacks and the rest (assembly, line search). Then, in the same process, the bare LDLᵀ
//! factorization of the same pattern's lower triangle (the Ju–Rowlands matrix at the final
//! state, same AMD ordering, same cost) and the memory: ours (pattern, values, symmetric part,
//! Woodbury block, Krylov basis, vectors) against the LDLᵀ factor.
//!
//! Issue 42: `-- --sheet 83,259,579 --threads 1,2 --ordering amd,nd` runs, on the side-by-side
//! sheet of `n × n` nodes (`3 (n − 2)²` free DOF), each ordering in a fresh process: the
//! symbolic analysis, nnz(L), then one Newton iteration (assembly of the consistent tangent, the
//! LDLᵀ of its symmetric part and the solve) at each thread count, alternating, twice, best of
//! each, the answers compared bit for bit, and the peak RSS. `-- --sheet-solve 259 --threads
//! 1,2` times the whole solve (centre pushed 50 mm in 5 steps of one increment), alternating,
//! with the default ordering. Each prints one table. `-- --iteration R --ordering amd|nd` runs
//! the specimen's iteration row under either ordering (the default: automatic).

use std::time::{Duration, Instant};

use membrane_contact::mech::elements::gap::GapLaw;
use membrane_contact::mech::solve::assembly::System;
use membrane_contact::mech::solve::linear::{FillOrdering, LinearSolver, UnsymmetricMethod};
use membrane_contact::mech::{Analysis, SolverSettings};
use membrane_contact::specimens::ParallelArch;
use nalgebra::Vector2;

#[path = "common/sheet.rs"]
mod common;
use common::sheet;

/// Peak resident set size (bytes) from /proc (0 where unavailable).
fn peak_rss() -> usize {
    let text = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    text.lines()
        .find(|l| l.starts_with("VmHWM:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse::<usize>().ok())
        .map_or(0, |kb| kb * 1024)
}

/// Resident set size now (bytes).
fn current_rss() -> usize {
    let text = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    text.lines()
        .find(|l| l.starts_with("VmRSS:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse::<usize>().ok())
        .map_or(0, |kb| kb * 1024)
}

fn mib(bytes: usize) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn parse_method(name: &str) -> UnsymmetricMethod {
    match name {
        "gmres" => UnsymmetricMethod::Gmres,
        "woodbury" => UnsymmetricMethod::Woodbury,
        _ => UnsymmetricMethod::Auto,
    }
}

/// One Newton linear step at a synthetic deformed state whose gaps slip (the plastic slip set
/// 10 mm behind), without running the analysis there: assembly of the consistent tangent plus
/// our solve (`LinearSolver` with the symmetric part), twice, against the bare LDLᵀ of the same
/// pattern's lower triangle, twice; best of each.
fn iteration(r: usize, ordering: FillOrdering) {
    let spec = ParallelArch {
        refinement: r,
        ..ParallelArch::with_height(0.3)
    };
    let model = spec.model().unwrap();
    let laws: Vec<GapLaw> = model.gaps.iter().map(|g| g.law()).collect();
    let mut u = vec![0.0; model.dof_count()];
    for (i, p) in model.nodes.iter().enumerate() {
        let r = (p[0].powi(2) + p[1].powi(2)).sqrt().min(1.0);
        u[3 * i + 2] = -0.02 * r * r;
        u[3 * i] = 1e-4 * p[0];
    }
    let history = vec![Vector2::new(-0.01, 0.0); laws.len()];
    let shift = 1e-3 * model.material.membrane_stiffness();
    let mut free = 0;
    let mut run = |lower_only: bool| -> (Duration, Duration, [usize; 4], usize, usize, usize) {
        let system = System::new(&model, lower_only).unwrap();
        free = system.free_count;
        let mut linear = LinearSolver::with_ordering(&system, true, ordering).unwrap();
        let mut internal = vec![0.0; model.dof_count()];
        let mut values = vec![0.0; system.nonzeros()];
        let p = system.pattern();
        let diagonal: Vec<usize> = (0..system.free_count)
            .map(|j| {
                let rows = &p.row_idx()[p.col_ptr()[j]..p.col_ptr()[j + 1]];
                p.col_ptr()[j] + rows.binary_search(&j).unwrap()
            })
            .collect();
        let (mut best, mut best_factor) = (Duration::MAX, Duration::MAX);
        for _ in 0..2 {
            let started = Instant::now();
            system.assemble(&u, &mut internal, Some(&mut values), |g, d| {
                let r = laws[g].evaluate(d, history[g]);
                let k = if lower_only {
                    laws[g].ju_rowlands_matrix(r.status, r.direction)
                } else {
                    laws[g].consistent_tangent(&r)
                };
                (r.force, k)
            });
            for &d in &diagonal {
                values[d] += shift;
            }
            let mut rhs = vec![1.0; system.free_count];
            let before = linear.profile().ldlt;
            linear
                .factorize_and_solve(system.matrix(&values), &mut rhs)
                .unwrap();
            best = best.min(started.elapsed());
            best_factor = best_factor.min(linear.profile().ldlt - before);
        }
        let ours = system.memory_bytes()
            + 8 * (system.nonzeros() + 3 * model.dof_count() + 2 * system.free_count)
            + linear.memory_bytes()
            - 8 * linear.factor_len();
        (
            best,
            best_factor,
            linear.counts(),
            linear.profile().woodbury_columns / linear.profile().woodbury_count.max(1),
            ours,
            8 * linear.factor_len(),
        )
    };
    let (ours_time, ours_factor, counts, columns, ours, factor) = run(false);
    let (_, bare, _, _, _, _) = run(true);
    println!(
        "| {r} | {ordering:?} | {:.1} M | {} | {:?} | {columns} | {:.0} ms | {:.0} ms | {:.0} ms | **{:.2}** | {:.0} MiB | {:.0} MiB | {:.2} | {:.0} MiB |",
        factor as f64 / 8e6,
        free,
        counts,
        ms(ours_time),
        ms(ours_factor),
        ms(bare),
        ms(ours_time) / ms(bare),
        mib(ours),
        mib(factor),
        ours as f64 / factor.max(1) as f64,
        mib(peak_rss()),
    );
}

fn system_free(analysis: &Analysis) -> usize {
    analysis.system().free_count
}

/// One case in this process: prints one table row.
fn case(r: usize, steps: usize, method: &str) {
    let spec = ParallelArch {
        refinement: r,
        ..ParallelArch::with_height(0.3)
    };
    let model = spec.model().unwrap();
    let started = Instant::now();
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    let setup = started.elapsed();
    analysis.set_unsymmetric_method(parse_method(method));
    // The bare LDLᵀ: the same pattern's lower triangle with the symmetric Ju–Rowlands matrix
    // of the current state (the factorization's cost does not depend on the values), factorized
    // before the run and after every step, so that its samples see the same machine load.
    let lower = System::new(&model, true).unwrap();
    let laws: Vec<GapLaw> = model.gaps.iter().map(|g| g.law()).collect();
    let mut internal = vec![0.0; model.dof_count()];
    let mut values = vec![0.0; lower.nonzeros()];
    let mut bare = LinearSolver::new(&lower, true).unwrap();
    let mut rhs = vec![1.0; system_free(&analysis)];
    let mut factorizations = vec![];
    let mut bare_sample = |analysis: &Analysis| {
        let u = &analysis.state().displacement;
        let history: Vec<Vector2<f64>> = analysis
            .state()
            .plastic_slip
            .iter()
            .map(|s| Vector2::new(s[0], s[1]))
            .collect();
        lower.assemble(u, &mut internal, Some(&mut values), |g, d| {
            let r = laws[g].evaluate(d, history[g]);
            (r.force, laws[g].ju_rowlands_matrix(r.status, r.direction))
        });
        rhs.fill(1.0);
        let before = bare.profile().ldlt;
        bare.factorize_and_solve(lower.matrix(&values), &mut rhs)
            .unwrap();
        factorizations.push(bare.profile().ldlt - before);
    };
    bare_sample(&analysis);
    let mut run = Duration::ZERO;
    let (mut iterations, mut increments, mut cutbacks) = (0, 0, 0);
    for step in 1..=steps {
        let target = spec.target().map(|v| v * step as f64 / 20.0);
        let started = Instant::now();
        let report = analysis.step_to(&[target], 1).unwrap();
        run += started.elapsed();
        iterations += report.total_iterations();
        increments += report.iterations.len();
        cutbacks += report.cutbacks;
        bare_sample(&analysis);
    }
    let p = analysis.solve_profile();
    let counts = analysis.factorization_counts();
    let linear = analysis.linear_solver();
    let system = analysis.system();
    let n = system.free_count;
    let ours = system.memory_bytes()
        + 8 * (system.nonzeros() + 3 * model.dof_count() + 2 * n)
        + linear.memory_bytes()
        - 8 * linear.factor_len();
    let factor = 8 * linear.factor_len();
    let has_lu = linear.has_lu();
    let slip = analysis
        .results()
        .gaps
        .iter()
        .map(|g| g.slip_x)
        .fold(0.0_f64, |m, s| m.max(s.abs()));
    let peak_analysis = peak_rss();
    factorizations.sort();
    // Median of the samples.
    let bare_factor = factorizations[factorizations.len() / 2];
    let per_iteration = run / iterations.max(1) as u32;
    let rest = run.saturating_sub(p.total());
    let per = |d: Duration| ms(d) / iterations.max(1) as f64;
    println!(
        "| {r} | {n} | {method} | {steps} | {increments} | {cutbacks} | {iterations} | {}/{}/{}/{} | {} | {:.1} / {} | {:.1} s | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} ms | {:.2} | {:.0} | {:.0} | {:.2} | {:.0} | {} | {:.4e} |",
        counts[0],
        counts[1],
        counts[2],
        counts[3],
        p.woodbury_columns / p.woodbury_count.max(1),
        p.gmres_iterations as f64 / p.gmres_count.max(1) as f64,
        p.gmres_max,
        setup.as_secs_f64(),
        ms(per_iteration),
        per(p.symmetric_part),
        per(p.ldlt),
        per(p.woodbury),
        per(p.gmres),
        per(p.accuracy),
        per(p.lu + p.symbolic),
        per(rest),
        ms(bare_factor),
        ms(per_iteration) / ms(bare_factor),
        mib(ours),
        mib(factor),
        ours as f64 / factor.max(1) as f64,
        mib(peak_analysis),
        if has_lu { "yes" } else { "no" },
        slip,
    );
}

fn parse_ordering(name: &str) -> FillOrdering {
    match name {
        "amd" => FillOrdering::Amd,
        "nd" => FillOrdering::NestedDissection,
        _ => FillOrdering::Auto,
    }
}

fn list(text: &str) -> Vec<usize> {
    text.split(',').map(|v| v.parse().unwrap()).collect()
}

/// One Newton iteration on the sheet of `n × n` nodes under `ordering`, at each thread count
/// of `threads`, alternating, twice: one table row per thread count.
fn sheet_iteration(n: usize, ordering: &str, threads: &[usize]) {
    let model = sheet(n);
    let mut system = System::new(&model, false).unwrap();
    let started = Instant::now();
    let mut linear = LinearSolver::with_ordering(&system, true, parse_ordering(ordering)).unwrap();
    let symbolic = started.elapsed();
    let mut u = vec![0.0; model.dof_count()];
    for (i, p) in model.nodes.iter().enumerate() {
        let s = (std::f64::consts::PI * p[0]).sin() * (std::f64::consts::PI * p[1]).sin();
        u[3 * i + 2] = 0.05 * s;
    }
    let mut internal = vec![0.0; model.dof_count()];
    let mut values = vec![0.0; system.nonzeros()];
    let (mut best, mut factor) = (
        vec![Duration::MAX; threads.len()],
        vec![Duration::MAX; threads.len()],
    );
    let mut answers: Vec<Vec<f64>> = vec![vec![]; threads.len()];
    for round in 0..2 {
        for k in 0..threads.len() {
            // Alternate the order of the thread counts between rounds.
            let k = if round % 2 == 0 {
                k
            } else {
                threads.len() - 1 - k
            };
            system.set_threads(threads[k]);
            linear.set_threads(threads[k]);
            let started = Instant::now();
            system.assemble(&u, &mut internal, Some(&mut values), |_, _| {
                unreachable!("no gaps")
            });
            let mut rhs = vec![1.0; system.free_count];
            let before = linear.profile().ldlt;
            linear
                .factorize_and_solve(system.matrix(&values), &mut rhs)
                .unwrap();
            best[k] = best[k].min(started.elapsed());
            factor[k] = factor[k].min(linear.profile().ldlt - before);
            answers[k] = rhs;
        }
    }
    let same = same_bits(&answers);
    for (k, &t) in threads.iter().enumerate() {
        println!(
            "| {n} × {n} | {} | {ordering} | {:.2} s | {:.1} M | {:.0} MiB | {t} | {:.0} ms | {:.0} ms | {:.2} | {} | {:.0} MiB | {:.2} |",
            system.free_count,
            symbolic.as_secs_f64(),
            linear.factor_len() as f64 / 1e6,
            mib(8 * linear.factor_len()),
            ms(best[k]),
            ms(factor[k]),
            ms(best[k]) / ms(best[0]),
            if same { "yes" } else { "NO" },
            mib(peak_rss()),
            load(),
        );
    }
}

/// Whether every answer has the first's bits.
fn same_bits(answers: &[Vec<f64>]) -> bool {
    answers.iter().all(|a| {
        a.iter()
            .zip(&answers[0])
            .all(|(x, y)| x.to_bits() == y.to_bits())
    })
}

/// The one-minute load average.
fn load() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|t| t.split_whitespace().next().and_then(|v| v.parse().ok()))
        .unwrap_or(f64::NAN)
}

/// The whole sheet solve (centre pushed 50 mm in 5 steps of one increment) at each thread
/// count, alternating, twice: one row per thread count, best of two.
fn sheet_solve(n: usize, threads: &[usize]) {
    let model = sheet(n);
    let mut best = vec![Duration::MAX; threads.len()];
    let mut answers: Vec<Vec<f64>> = vec![vec![]; threads.len()];
    let mut parts = vec![(Duration::MAX, Duration::MAX, 0); threads.len()];
    let mut iterations = 0;
    for round in 0..2 {
        for k in 0..threads.len() {
            let k = if round % 2 == 0 {
                k
            } else {
                threads.len() - 1 - k
            };
            let settings = SolverSettings {
                threads: threads[k],
                ..SolverSettings::default()
            };
            let started = Instant::now();
            let mut analysis = Analysis::new(model.clone(), settings).unwrap();
            iterations = 0;
            for step in 1..=5 {
                let report = analysis
                    .step_to(&[[0.0, 0.0, 0.01 * step as f64]], 1)
                    .unwrap();
                iterations += report.total_iterations();
            }
            let elapsed = started.elapsed();
            if elapsed < best[k] {
                let p = analysis.solve_profile();
                parts[k] = (p.ldlt, p.symbolic + p.ldlt_solve, p.ldlt_count);
            }
            best[k] = best[k].min(elapsed);
            answers[k] = analysis.state().displacement.clone();
        }
    }
    let same = same_bits(&answers);
    for (k, &t) in threads.iter().enumerate() {
        let (ldlt, analysis_and_solves, count) = parts[k];
        println!(
            "| {n} × {n} | {} | {t} | {iterations} | {:.1} s | {:.1} s ({count}) | {:.1} s | {:.1} s | {:.2} | {} | {:.0} MiB | {:.2} |",
            3 * (n - 2) * (n - 2),
            best[k].as_secs_f64(),
            ldlt.as_secs_f64(),
            analysis_and_solves.as_secs_f64(),
            (best[k] - ldlt - analysis_and_solves).as_secs_f64(),
            ms(best[k]) / ms(best[0]),
            if same { "yes" } else { "NO" },
            mib(peak_rss()),
            load(),
        );
    }
}

/// Runs this bench again with `args`, printing its table rows (or the failure).
fn child(args: &[String]) {
    let exe = std::env::current_exe().unwrap();
    let out = std::process::Command::new(&exe)
        .args(args)
        .output()
        .unwrap();
    print!("{}", String::from_utf8_lossy(&out.stdout));
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        println!(
            "| {} | failed: {} |",
            args.join(" "),
            err.lines().last().unwrap_or("")
        );
    }
}

/// `--sheet`, `--sheet-solve` and their one-case children; false when none is given.
fn sheet_tables(option: &dyn Fn(&str) -> Option<String>) -> bool {
    let threads = option("--threads").unwrap_or_else(|| "1,2".into());
    if let Some(case) = option("--sheet-one") {
        let (n, ordering) = case.split_once(',').unwrap();
        sheet_iteration(n.parse().unwrap(), ordering, &list(&threads));
    } else if let Some(n) = option("--sheet-solve-one") {
        sheet_solve(n.parse().unwrap(), &list(&threads));
    } else if let Some(sizes) = option("--sheet") {
        println!(
            "## one Newton iteration on the sheet, by ordering and threads (best of two, alternating)\n"
        );
        println!(
            "| sheet | free DOF | ordering | symbolic | nnz(L) | factor | threads | iteration | LDLᵀ | ratio | same bits | peak RSS | load |"
        );
        println!("|{}", "---|".repeat(13));
        for n in list(&sizes) {
            for ordering in option("--ordering")
                .unwrap_or_else(|| "amd,nd".into())
                .split(',')
            {
                child(&[
                    "--sheet-one".into(),
                    format!("{n},{ordering}"),
                    "--threads".into(),
                    threads.clone(),
                ]);
            }
        }
    } else if let Some(sizes) = option("--sheet-solve") {
        println!("## the whole sheet solve, 5 steps of one increment (best of two, alternating)\n");
        println!(
            "| sheet | free DOF | threads | iterations | solve | LDLᵀ (factorizations) | symbolic + solves | rest | ratio | same bits | peak RSS | load |"
        );
        println!("|{}", "---|".repeat(12));
        for n in list(&sizes) {
            child(&[
                "--sheet-solve-one".into(),
                n.to_string(),
                "--threads".into(),
                threads.clone(),
            ]);
        }
    } else {
        return false;
    }
    true
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let option = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    if sheet_tables(&option) {
        return;
    }
    if let Some(r) = option("--iteration") {
        let ordering = parse_ordering(&option("--ordering").unwrap_or_default());
        iteration(r.parse().unwrap(), ordering);
        return;
    }
    if let Some(r) = option("--lu-symbolic") {
        // What an eager LU symbolic analysis (held before issue 11 item 2 at scale) costs.
        let spec = ParallelArch {
            refinement: r.parse().unwrap(),
            ..ParallelArch::with_height(0.3)
        };
        let system = System::new(&spec.model().unwrap(), false).unwrap();
        let (before, started) = (current_rss(), Instant::now());
        let lu = LinearSolver::new(&system, false).unwrap();
        println!(
            "LU symbolic analysis at {} free DOF: {:.0} ms, {:.0} MiB resident",
            system.free_count,
            ms(started.elapsed()),
            mib(current_rss().saturating_sub(before))
        );
        drop(lu);
        return;
    }
    if let Some(one) = option("--one") {
        let parts: Vec<&str> = one.split(',').collect();
        case(
            parts[0].parse().unwrap(),
            parts[1].parse().unwrap(),
            parts[2],
        );
        return;
    }
    let refine: Vec<usize> = option("--refine")
        .unwrap_or_else(|| "1,4,16".into())
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let steps: usize = option("--steps").map_or(20, |v| v.parse().unwrap());
    let methods = option("--methods").unwrap_or_else(|| "auto,gmres".into());
    println!(
        "## one Newton iteration of the consistent tangent on the refined 300 mm specimen ({steps} of 20 steps)\n"
    );
    println!(
        "Times per Newton iteration (ms): sym = symmetric-part pass, ldlt = LDLᵀ factorization, wood = Woodbury, gmres = GMRES, acc = accuracy checks, lu = LU fallbacks + symbolic analyses, rest = assembly, line search, updates; bare = one LDLᵀ factorization of the same pattern alone.\n"
    );
    println!(
        "| r | free DOF | method | steps | increments | cut-backs | iterations | LU/LDLᵀ/rejected/unsym solves | Woodbury columns | GMRES mean / max | setup | per iteration | sym | ldlt | wood | gmres | acc | lu | rest | bare LDLᵀ | iteration / bare | our MiB | factor MiB | ours / factor | peak RSS MiB | LU built | largest slip |"
    );
    println!("|{}", "---|".repeat(27));
    let exe = std::env::current_exe().unwrap();
    for &r in &refine {
        for method in methods.split(',') {
            let out = std::process::Command::new(&exe)
                .args(["--one", &format!("{r},{steps},{method}")])
                .output()
                .unwrap();
            print!("{}", String::from_utf8_lossy(&out.stdout));
            if !out.status.success() {
                println!(
                    "| {r} | failed ({method}): {} |",
                    String::from_utf8_lossy(&out.stderr)
                        .lines()
                        .last()
                        .unwrap_or("")
                );
            }
        }
    }
}
