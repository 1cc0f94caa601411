//! Newton at the price of a symmetric factorization (issue 11 item 1).
//!
//! TEST GOAL: a consistent tangent that is symmetric (a hinged panel under self-weight and a
//! rail turn: no slipping gap, no follower pressure) is factorized by LDLᵀ in every iteration
//! and reaches the LU's answer; the specimen, whose gaps slip, factorizes its symmetric
//! iterations (all gaps sticking or open) by LDLᵀ and the others by LU, to the same answer as
//! LU throughout — its unsymmetric iterations solved by GMRES preconditioned with the LDLᵀ of
//! the symmetric part (item 2); a follower pressure makes every iteration unsymmetric.

use membrane_contact::mech::solve::linear::UnsymmetricMethod;
use membrane_contact::mech::{Analysis, LoadLevels, Model, SolverSettings};
use membrane_contact::specimens::ParallelArch;

fn run(model: &Model, symmetric: bool, loads: &LoadLevels, angle: f64) -> (Vec<f64>, [usize; 4]) {
    let settings = SolverSettings {
        symmetric_factorization: symmetric,
        ..SolverSettings::default()
    };
    let mut analysis = Analysis::new(model.clone(), settings).unwrap();
    let groups = model.groups.len();
    for k in 1..=4 {
        let f = k as f64 / 4.0;
        let targets: Vec<[f64; 3]> = model
            .groups
            .iter()
            .map(|g| g.target.map(|v| v * f))
            .collect();
        let angles: Vec<f64> = (0..groups)
            .map(|g| {
                if model.groups[g].hinge.is_some() {
                    angle * f
                } else {
                    0.0
                }
            })
            .collect();
        analysis
            .step_to_motion(&targets, &angles, &loads.scaled(f), 2)
            .unwrap();
    }
    (
        analysis.state().displacement.clone(),
        analysis.factorization_counts(),
    )
}

fn hinged_panel() -> Model {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/hinged_panel.json"
    ))
    .unwrap();
    Model::from_json(&text).unwrap()
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn symmetric_tangents_are_factorized_by_ldlt_to_the_lus_answer() {
    let model = hinged_panel();
    let mut weight_only = LoadLevels::of_model(&model);
    weight_only.pressure = vec![0.0];
    let (ldlt, counts) = run(&model, true, &weight_only, 0.1);
    let (lu, lu_counts) = run(&model, false, &weight_only, 0.1);
    assert_eq!(counts[0], 0, "{counts:?}");
    assert!(counts[1] > 0 && counts[2] == 0, "{counts:?}");
    assert_eq!((lu_counts[1], lu_counts[2]), (0, 0));
    let scale = lu.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!(
        max_difference(&ldlt, &lu) < 1e-6 * scale,
        "{}",
        max_difference(&ldlt, &lu)
    );

    // The snow is a follower pressure: unsymmetric load stiffness, no plain LDLᵀ iteration;
    // GMRES on the symmetric part's LDLᵀ reaches the LU's answer.
    let (gmres, counts) = run(&model, true, &LoadLevels::of_model(&model), 0.1);
    let (lu, _) = run(&model, false, &LoadLevels::of_model(&model), 0.1);
    assert!(counts[1] == 0 && counts[3] > 0, "{counts:?}");
    let scale = lu.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!(max_difference(&gmres, &lu) < 1e-6 * scale);
}

#[test]
fn specimen_mixes_ldlt_and_gmres_as_its_gaps_stick_and_slip_to_the_lus_answer() {
    let model = ParallelArch::default().model().unwrap();
    let loads = LoadLevels::zero(&model);
    let (mixed, counts) = run(&model, true, &loads, 0.0);
    let (lu, _) = run(&model, false, &loads, 0.0);
    // Slipping gaps make most iterations unsymmetric: GMRES on the symmetric part's LDLᵀ.
    assert!(
        counts[1] > 0 && counts[3] > 0 && counts[0] == 0,
        "{counts:?}"
    );
    let scale = lu.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!(max_difference(&mixed, &lu) < 1e-6 * scale);
}

#[test]
fn specimen_takes_the_same_newton_iterations_and_answer_by_woodbury_or_gmres_and_never_analyses_an_lu()
 {
    let spec = ParallelArch::default();
    let model = spec.model().unwrap();
    let mut outcomes = vec![];
    for method in [
        UnsymmetricMethod::Auto,
        UnsymmetricMethod::Gmres,
        UnsymmetricMethod::Woodbury,
    ] {
        let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
        analysis.set_unsymmetric_method(method);
        let mut iterations = vec![];
        for k in 1..=4 {
            let target = spec.target().map(|v| v * k as f64 / 4.0);
            iterations.extend(analysis.step_to(&[target], 2).unwrap().iterations);
        }
        assert!(!analysis.linear_solver().has_lu(), "{method:?}");
        outcomes.push((
            iterations,
            analysis.state().displacement.clone(),
            analysis.solve_profile(),
        ));
    }
    let (auto, gmres) = (&outcomes[0].2, &outcomes[1].2);
    assert!(auto.woodbury_count > 0 && auto.gmres_count == 0, "{auto:?}");
    assert!(
        gmres.gmres_count > 0 && gmres.woodbury_count == 0,
        "{gmres:?}"
    );
    let scale = outcomes[0].1.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for (iterations, u, _) in &outcomes[1..] {
        assert_eq!(iterations, &outcomes[0].0);
        assert!(max_difference(u, &outcomes[0].1) < 1e-10 * scale);
    }
}
