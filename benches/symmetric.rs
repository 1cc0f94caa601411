//! LDLᵀ for symmetric consistent tangents against LU (issue 11 item 1):
//! `cargo bench --bench symmetric` (`-- --max-n N` to cap the mesh).
//!
//! The sheet of issue 11's side-by-side benchmark: 1 m × 1 m, t = 1 mm, E = 1 GPa, ν = 0.3,
//! prestress 1 MPa, edges pinned, n × n nodes with each cell split into two triangles; the centre
//! node pushed 50 mm out of plane in 5 steps (a prescribed displacement: the tangent stays
//! symmetric). Each size runs with `symmetric_factorization` on (LDLᵀ whenever symmetric) and
//! off (LU always), alternately, three times; medians and their ratio, measured in one run.

use std::time::{Duration, Instant};

use membrane_contact::mech::{Analysis, Model, SolverSettings};

#[path = "common/sheet.rs"]
mod common;
use common::sheet;

fn solve(model: &Model, symmetric: bool) -> (Duration, usize, [usize; 4], f64) {
    let settings = SolverSettings {
        symmetric_factorization: symmetric,
        ..SolverSettings::default()
    };
    let started = Instant::now();
    let mut analysis = Analysis::new(model.clone(), settings).unwrap();
    let mut iterations = 0;
    for k in 1..=5 {
        let report = analysis.step_to(&[[0.0, 0.0, 0.01 * k as f64]], 1).unwrap();
        iterations += report.total_iterations();
    }
    let reaction = analysis.results().reactions[0][2];
    (
        started.elapsed(),
        iterations,
        analysis.factorization_counts(),
        reaction,
    )
}

/// The 300 mm specimen refined `r` times, 20 steps to its target: its gaps slip, so most
/// iterations are unsymmetric (Woodbury or GMRES on the symmetric part's LDLᵀ when on, LU when
/// off).
fn specimen(r: usize, symmetric: bool) -> (Duration, usize, [usize; 4], Vec<f64>) {
    use membrane_contact::specimens::ParallelArch;
    let spec = ParallelArch {
        refinement: r,
        ..ParallelArch::with_height(0.3)
    };
    let settings = SolverSettings {
        symmetric_factorization: symmetric,
        ..SolverSettings::default()
    };
    let started = Instant::now();
    let mut analysis = Analysis::new(spec.model().unwrap(), settings).unwrap();
    let report = analysis.step_to(&[spec.target()], 20).unwrap();
    let slips = analysis.results().gaps.iter().map(|g| g.slip_x).collect();
    (
        started.elapsed(),
        report.total_iterations(),
        analysis.factorization_counts(),
        slips,
    )
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let max_n: usize = args
        .iter()
        .position(|a| a == "--max-n")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(161);
    println!(
        "## symmetric consistent tangent: LDLᵀ against LU (sheet, centre pushed 50 mm in 5 steps)\n"
    );
    println!(
        "| n × n | free DOF | iterations | LDLᵀ / LU factorizations | median LDLᵀ run | median LU run | LDLᵀ / LU | centre reaction |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for n in [41, 101, 161].into_iter().filter(|&n| n <= max_n) {
        let model = sheet(n);
        let (mut on, mut off) = (vec![], vec![]);
        let mut summary = None;
        for _ in 0..3 {
            let a = solve(&model, true);
            let b = solve(&model, false);
            assert!((a.3 - b.3).abs() <= 1e-6 * b.3.abs(), "{} vs {}", a.3, b.3);
            on.push(a.0);
            off.push(b.0);
            summary = Some((a.1, a.2, a.3));
        }
        let (iterations, counts, reaction) = summary.unwrap();
        let (t_on, t_off) = (median(on), median(off));
        println!(
            "| {n} × {n} | {} | {iterations} | {} / {} | {:.1} ms | {:.1} ms | {:.2} | {reaction:.3} N |",
            3 * (n - 2) * (n - 2) - 1,
            counts[1] + counts[3],
            counts[0],
            t_on.as_secs_f64() * 1e3,
            t_off.as_secs_f64() * 1e3,
            t_on.as_secs_f64() / t_off.as_secs_f64()
        );
    }
    let max_refine: usize = args
        .iter()
        .position(|a| a == "--max-refine")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(16);
    println!(
        "\n## unsymmetric consistent tangent: GMRES on the LDLᵀ of the symmetric part against LU (300 mm specimen, 20 steps)\n"
    );
    println!(
        "| refinement | iterations (on / off) | LDLᵀ / Woodbury or GMRES / LU solves (on) | median run on | median run off | on / off | largest slip difference |"
    );
    println!("|---|---|---|---|---|---|---|");
    for r in [1, 4, 8, 16].into_iter().filter(|&r| r <= max_refine) {
        let (mut on, mut off) = (vec![], vec![]);
        let mut summary = None;
        for _ in 0..3 {
            let a = specimen(r, true);
            let b = specimen(r, false);
            let diff =
                a.3.iter()
                    .zip(&b.3)
                    .map(|(x, y)| (x - y).abs())
                    .fold(0.0, f64::max);
            on.push(a.0);
            off.push(b.0);
            summary = Some((a.1, b.1, a.2, diff));
        }
        let (it_on, it_off, c, diff) = summary.unwrap();
        let (t_on, t_off) = (median(on), median(off));
        println!(
            "| {r} | {it_on} / {it_off} | {} / {} / {} | {:.1} ms | {:.1} ms | {:.2} | {diff:.1e} m |",
            c[1],
            c[3],
            c[0],
            t_on.as_secs_f64() * 1e3,
            t_off.as_secs_f64() * 1e3,
            t_on.as_secs_f64() / t_off.as_secs_f64()
        );
    }
}
