//! The one-solve adjoint of reactions at any tangent (issue 45): the restrained rows `K_rf`
//! assembled ([`System::with_constrained_rows`]) against differences of the residual, and the
//! adjoint of every reaction and output point against J's columns and against the same parts
//! solved forward, on gaps and curved supports in stick, slip and open under both friction
//! laws.
//!
//! MODEL: the specimen (`ParallelArch`), on its nine gaps or in contact with the arch pipe,
//! lowered by thirtieths of its travel in one increment per step with μ = 0.2, μ (and the
//! pressure of a follower set `cover` on every triangle) set to the case's value in the last
//! step; output points on every seventh film node. Where the contacts slide on free film nodes
//! only, their unsymmetric tangent stays out of the restrained rows (`K_rf = K_frᵀ`); holding
//! those nodes along one axis, or a follower pressure on the triangles at the frame, brings it
//! in.

use super::tests::{
    COLUMNS, TRANSPOSED, add_film_points, adjoint_against_columns, every_weight, mu,
    with_translations,
};
use super::*;
use crate::fmi2::tests::derivatives::cover;
use crate::mech::Model;
use crate::mech::elements::gap::FrictionLaw;
use crate::mech::elements::gap::GapStatus;
use crate::mech::model::format::{Axis, Support};
use crate::mech::solve::assembly::System;
use crate::mech::solve::settings::SolverSettings;
use crate::specimens::ParallelArch;
use crate::specimens::parallel_arch::SpecimenContact;

/// The specimen on `contact` under `law` after `steps` thirtieths of its lowering, μ = 0.2
/// until the last step and `mu` in it, with output points on every seventh film node and a
/// follower pressure set `cover` on every triangle, raised to `pressure` (Pa) in the last step.
fn lowered(
    law: FrictionLaw,
    contact: SpecimenContact,
    (mu, pressure): (f64, f64),
    steps: usize,
) -> Analysis {
    lowered_with(law, contact, (mu, pressure), steps, |_| {})
}

/// [`lowered`] with the model edited by `edit` first.
fn lowered_with(
    law: FrictionLaw,
    contact: SpecimenContact,
    (mu, pressure): (f64, f64),
    steps: usize,
    edit: impl FnOnce(&mut Model),
) -> Analysis {
    let spec = ParallelArch {
        friction_law: law,
        contact,
        ..ParallelArch::default()
    };
    let mut model = spec.model().unwrap();
    add_film_points(&mut model);
    model.loads.pressures.push(cover());
    edit(&mut model);
    let targets: Vec<_> = (1..=steps)
        .map(|k| spec.boundary_targets(&model, k as f64 / 30.0))
        .collect();
    let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
    a.set_friction(0.2).unwrap();
    for (k, t) in targets.iter().enumerate() {
        let mut levels = a.state().loads.clone();
        if k + 1 == steps {
            a.set_friction(mu).unwrap();
            levels.pressure[0] = pressure;
        }
        a.step_to_with_loads(t, &levels, 1).unwrap();
    }
    a
}

/// Holds every contact's film node along y (the gaps') or x (the curved supports': along y
/// they stick under the sliding-direction law), as the support set `held`: a sliding contact's
/// unsymmetric tangent then has restrained rows (its tangential force depends on the normal
/// displacement, not the other way round).
fn hold_contact_nodes(m: &mut Model) {
    let axis = if m.gaps.is_empty() { Axis::X } else { Axis::Y };
    let gaps = m.gaps.iter().map(|g| g.film_node);
    let curved = m
        .curved_supports
        .iter()
        .flat_map(|c| c.nodes.iter().copied());
    let nodes: Vec<usize> = gaps.chain(curved).collect();
    for node in nodes {
        m.supports.push(Support {
            node,
            fixed: vec![axis],
            name: Some("held".into()),
        });
    }
}

/// The statuses of the gaps and curved-support contacts at the converged state.
fn statuses(a: &mut Analysis) -> Vec<GapStatus> {
    let r = a.results();
    let gaps = r.gaps.iter().map(|g| g.status);
    gaps.chain(r.surface_contacts.iter().map(|c| c.status))
        .collect()
}

impl Analysis {
    /// The out-of-balance force of every DOF at `u` (group motion and loads of the converged
    /// state, histories of the increment's start): the residual the held tangent linearizes.
    fn residual_from_start(&mut self, u: &[f64]) -> Vec<f64> {
        let end = self.state.clone();
        let start = self.increment_start.clone().unwrap_or_else(|| end.clone());
        let from = with_friction(&start, &end, 0.0);
        for c in self.parts.all_mut() {
            c.restore(&from);
        }
        self.assemble_at(u, &end.loads, None);
        self.work.internal.clone()
    }
}

/// `K_rfᵀ v` assembled against the central difference of `vᵀ g_r` along each free DOF of the
/// triangles that touch a restrained DOF (every other free DOF's `K_rf` column is 0, which the
/// assembled product must show too): the largest difference relative to the largest entry.
fn rows_against_differences(a: &mut Analysis) -> f64 {
    let weights = every_weight(a);
    let end = a.state.clone();
    let start = a.increment_start.clone().unwrap();
    let restrained = a.restrained_weights(&weights);
    let w = a
        .restrained_rows_transposed(&start, &end, &restrained)
        .unwrap();
    let mut touching = vec![false; a.system.dofs.len()];
    for (nodes, _) in &a.system.triangles {
        let dofs = crate::mech::solve::assembly::node_dofs(nodes);
        if dofs
            .iter()
            .any(|&i| !matches!(a.system.dofs[i], Dof::Free(_)))
        {
            dofs.iter().for_each(|&i| touching[i] = true);
        }
    }
    // 1e-7 of the size crossed the cone of a gap held along y (2 % off; 1e-8 to 1e-10 agree).
    let eps = 1e-8 * a.length_scale;
    let largest = w.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    assert!(largest > 0.0);
    let mut worst = 0.0_f64;
    for i in 0..a.system.dofs.len() {
        let Dof::Free(f) = a.system.dofs[i] else {
            continue;
        };
        if !touching[i] {
            assert_eq!(w[f], 0.0, "DOF {i} touches no restrained DOF");
            continue;
        }
        let mut u = end.displacement.clone();
        u[i] += eps;
        let plus = a.residual_from_start(&u);
        u[i] -= 2.0 * eps;
        let minus = a.residual_from_start(&u);
        let fd: f64 = (0..u.len())
            .map(|r| restrained[r] * (plus[r] - minus[r]) / (2.0 * eps))
            .sum();
        worst = worst.max((w[f] - fd).abs() / largest);
    }
    a.state = end;
    worst
}

/// The restrained rows `K_rf` are the gradient of the reactions: `K_rfᵀ v` (v on every group's,
/// support set's and the total reaction) against central differences of `vᵀ g_r` along each
/// free DOF (step 1e-8 of the model's size) to 3e-9 of its largest entry, where `K_rf ≠ K_frᵀ`:
/// the specimen with its gaps or curved-support contacts sliding (μ = 0.2, lowered 12/30) on
/// film nodes held along one axis (the support set `held`), or with a follower pressure of 20 Pa on
/// every triangle (lowered 6/30),
/// under each law; the cushion with 200 Pa on 192 triangles.
#[test]
fn restrained_rows_are_the_gradient_of_the_reactions() {
    let mut cases = vec![];
    for law in FrictionLaw::ALL {
        for contact in [SpecimenContact::Gaps, SpecimenContact::CurvedSupport] {
            let mut held = lowered_with(law, contact, (0.2, 0.0), 12, hold_contact_nodes);
            let s = statuses(&mut held);
            assert!(s.contains(&GapStatus::Slip), "{law:?} {contact:?}: {s:?}");
            cases.push((format!("{law:?} {contact:?} held"), held));
            let pressed = lowered(law, contact, (0.2, 20.0), 6);
            cases.push((format!("{law:?} {contact:?} 20 Pa"), pressed));
        }
    }
    let part = format!("\"elements\": {:?}", (0..192).collect::<Vec<usize>>());
    let json =
        include_str!("../../../examples/cushion.json").replace("\"elements\": \"all\"", &part);
    let mut a = Analysis::new(Model::from_json(&json).unwrap(), SolverSettings::default()).unwrap();
    let mut levels = a.state().loads.clone();
    levels.pressure[0] = 200.0;
    let target = a.state().boundary.clone();
    a.step_to_with_loads(&target, &levels, 4).unwrap();
    cases.push(("cushion, follower pressure".into(), a));
    for (name, mut a) in cases {
        let worst = rows_against_differences(&mut a);
        eprintln!("{name}: K_rfᵀ v vs differences {worst:e} of the largest");
        assert!(worst <= 3e-9, "{name}: {worst:e}");
    }
}

/// The one-solve adjoint on curved supports and on gaps, under each friction law, at μ = 0.2
/// (contacts slide and are open: an unsymmetric tangent), at μ = 9.9 (the closed ones stick,
/// others open), at μ = 0.2 with 20 Pa on the cover (a follower pressure) and at μ = 0.2 with
/// the contacts' nodes held (sliding contacts in the restrained rows): `(Jᵀ v)ᵀ s` over
/// μ, every group's translations and the cover's pressure, `v` on every reaction (the groups',
/// the support set `held`, the total) and output point, is one solve and equals `vᵀ (J s)` of
/// the same parts solved forward to [`TRANSPOSED`] and `vᵀ` times J's columns to [`COLUMNS`].
#[test]
fn an_adjoint_of_reactions_and_points_on_contacts_is_one_solve_in_stick_slip_and_open() {
    for law in FrictionLaw::ALL {
        for contact in [SpecimenContact::Gaps, SpecimenContact::CurvedSupport] {
            let cases = [
                (0.2, 0.0, false),
                (9.9, 0.0, false),
                (0.2, 20.0, false),
                (0.2, 0.0, true),
            ];
            for (mu_last, pressure, held) in cases {
                let name = format!("{law:?} {contact:?} μ = {mu_last}, {pressure} Pa, held {held}");
                let edit = |m: &mut Model| {
                    if held {
                        hold_contact_nodes(m);
                    }
                };
                let mut a = lowered_with(law, contact, (mu_last, pressure), 12, edit);
                let s = statuses(&mut a);
                assert!(s.contains(&GapStatus::Open), "{name}: {s:?}");
                let sliding = s.contains(&GapStatus::Slip);
                assert_eq!(sliding, mu_last < 1.0, "{name}: {s:?}");
                assert!(s.contains(&GapStatus::Stick) || sliding, "{name}: {s:?}");
                let mut seeds = with_translations(&a, mu(&a));
                let mut cover = Seed::zero(&a);
                cover.pressure[0] = 1.0;
                seeds.push(cover);
                let weights = every_weight(&a);
                let (worst, transposed) = adjoint_against_columns(&mut a, &seeds, &weights);
                eprintln!("{name}: columns {worst:e}, forward {transposed:e}");
                // Held, a sliding contact's tangent may be symmetric (the sliding-direction
                // law on gaps); its rows are checked in `restrained_rows_are_…`.
                let symmetric = a.held_tangent_symmetric().is_ok();
                if pressure != 0.0 || (sliding && !held) {
                    assert!(!symmetric, "{name}: an unsymmetric tangent");
                } else if !sliding {
                    assert!(symmetric, "{name}: a symmetric tangent");
                }
                assert!(worst <= COLUMNS, "{name}: {worst:e}");
                assert!(transposed <= TRANSPOSED, "{name}: {transposed:e}");
            }
        }
    }
}

/// A copy with the constrained rows assembles the system's own matrix bit for bit in its
/// first `nonzeros()` values, and its further slots hold exactly the entries the pattern drops.
#[test]
fn constrained_rows_keep_the_matrix_and_add_the_dropped_entries() {
    let mut a = lowered(FrictionLaw::Isotropic, SpecimenContact::Gaps, (0.2, 0.0), 3);
    let (copy, rows): (System, _) = a.system.with_constrained_rows().unwrap();
    assert!(!rows.is_empty());
    let u = a.state.displacement.clone();
    let levels = a.state.loads.clone();
    let (_, values) = a.residual_and_matrix(&u, &levels);
    let at = Evaluation {
        system: &copy,
        u: &u,
        levels: &levels,
        iteration: Some(1),
        matrix: a.settings.iteration_matrix,
    };
    let start = a.state.clone();
    for c in a.parts.all_mut() {
        c.restore(&start);
    }
    let nnz = copy.nonzeros();
    let mut with_rows = vec![0.0; nnz + rows.len()];
    let mut residual = vec![0.0; u.len()];
    a.parts.assemble(&at, &mut residual, Some(&mut with_rows));
    assert_eq!(&with_rows[..nnz], &values[..]);
    for &(r, f) in &rows {
        assert!(!matches!(a.system.dofs[r], Dof::Free(_)));
        assert!(f < a.system.free_count);
    }
    assert!(with_rows[nnz..].iter().any(|&x| x != 0.0));
}
