//! The specimens wrapped over the arch from crown to foot (issue 10 item 3,
//! `FramePath::Wrapped`): every frame node follows the film wound onto the arch, then the
//! boundary extended by `ε`.
//!
//! TEST GOAL: at the end every one of the nine arch nodes touches the arch, for each arch height
//! and both contact models; without friction the film extended by `ε` after winding slides along
//! the arch by nearly `ε` times each node's distance from the crown (a film that stayed on the
//! developed surface would slide by exactly `ε Y`; the 2-D film over a line support sags off
//! that surface between the arches and slides up to 20 % more, see the test), linearly in `ε`;
//! friction holds it back at every node; and the paper's fixed-frame gaps report at the foot a
//! local-x displacement several times the sliding (the travel of the node wound onto the arch,
//! which a fixed frame cannot tell from sliding).
//!
//! MODEL: the default specimen (`specimen.rs`) with `frame_path: wrapped`, 40 steps.

use membrane_contact::mech::elements::gap::GapStatus;
use membrane_contact::mech::model::OutputPoint;
use membrane_contact::mech::{Analysis, Results, SolverSettings};
use membrane_contact::specimens::ParallelArch;
use membrane_contact::specimens::parallel_arch::{FramePath, SpecimenContact};

const STEPS: usize = 40;

fn wrapped(height: f64, contact: SpecimenContact, extension: f64, mu: f64) -> Results {
    let spec = ParallelArch {
        contact,
        friction: mu,
        frame_path: FramePath::Wrapped { extension },
        ..ParallelArch::with_height(height)
    };
    let mut model = spec.model().unwrap();
    // Output points (they change nothing in the analysis): the film on the symmetry plane
    // between the arches and on the arch line, both at the crown (nodes 0 and 4 of the grid).
    model.outputs.points = [("between", 0), ("on_arch", 4)]
        .map(|(name, node)| OutputPoint {
            name: name.into(),
            node,
        })
        .into();
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    for k in 1..=STEPS {
        let t = k as f64 / STEPS as f64;
        analysis
            .step_to(&spec.boundary_targets(&model, t), 1)
            .unwrap_or_else(|e| {
                panic!("H = {height}, {contact:?}, ε = {extension}, step {k}: {e}")
            });
    }
    analysis.results()
}

/// (slip, status) of the nine arch nodes, crown to foot.
fn arch_nodes(r: &Results) -> Vec<(f64, GapStatus)> {
    if r.gaps.is_empty() {
        r.surface_contacts
            .iter()
            .map(|c| (c.slip, c.status))
            .collect()
    } else {
        r.gaps.iter().map(|g| (g.slip_x, g.status)).collect()
    }
}

#[test]
fn wrapped_film_touches_the_arch_from_crown_to_foot() {
    for h in [0.2, 0.3, 0.4] {
        for contact in [SpecimenContact::Gaps, SpecimenContact::CurvedSupport] {
            let nodes = arch_nodes(&wrapped(h, contact, 0.02, 0.2));
            assert_eq!(nodes.len(), 9);
            for (k, (_, status)) in nodes.iter().enumerate() {
                assert_ne!(
                    *status,
                    GapStatus::Open,
                    "H = {h}, {contact:?}: node {} open",
                    k + 1
                );
            }
        }
    }
}

/// Expected slip, from the geometry: wound (first half of the path), every frame node lies on
/// the cylinder of the arch circle extruded along x (continued by its tangent plane beyond the
/// foot), at the arc length of its flat distance from the crown; that surface is developable,
/// and the film on it is unstrained but for its prestress, so it lies on it too, touching the
/// arch line without sliding. Extended by `ε`, the frame nodes move along the developed surface
/// to arc length `(1 + ε) Y`: a film that stayed on the surface would be uniformly stretched by
/// `ε` along the arch, without friction nothing holds it back, and the node at flat distance `Y`
/// slides by `ε Y`.
///
/// The error source: the film does not stay on the surface. Stretched, it carries tension along
/// the arch over a convex surface that holds it only on the arch line (and at the frame), so it
/// sags toward the arch's axis between and beyond the arches (checked below: ≈ 30 mm at the
/// crown between the arches at ε = 0.02, the arch line itself within 1 mm). How the sag raises
/// the arch line's stretch is our reading, not a derivation: a sagged line of film lies at a
/// smaller radius than the arch line and turns through a larger angle for the same stretch; the
/// film's shear ties the arch line to those angles, so the arch line is stretched more than `ε`
/// over the arch and less in the free span beyond the foot (whose end is prescribed). Measured:
/// 1.07 … 1.13 `ε Y`. The in-plane part of the 2-D effect (the film
/// beyond the arch also stretched across, between them not) is small: a flat film under the
/// same boundary movements slides 0.986 … 0.998 `ε Y`. The band allows 20 % above `ε Y`.
#[test]
fn frictionless_extended_film_slides_in_proportion_to_the_distance_from_the_crown() {
    let spacing = 0.1; // flat distance between the arch nodes (specimen.rs)
    let run = |eps| wrapped(0.3, SpecimenContact::CurvedSupport, eps, 0.0);
    let (one, r2) = (arch_nodes(&run(0.01)), run(0.02));
    let two = arch_nodes(&r2);
    assert!(
        two[0].0.abs() < 1e-6,
        "the crown does not slide: {}",
        two[0].0
    );
    // The error source is there: the film between the arches has sagged off the surface (the
    // crown of the surface is at z = H = 0.3 and does not move), the film on the arch has not.
    let [between, on_arch] = [r2.points[0][2], r2.points[1][2]];
    assert!(
        between < -0.01 && on_arch.abs() < 1e-3,
        "crown displacement in z: between the arches {between}, on the arch {on_arch}"
    );
    for k in 1..9 {
        let per_strain = two[k].0 / (0.02 * spacing * k as f64);
        assert!(
            (1.0..1.2).contains(&per_strain),
            "node {}: slip {} m is {per_strain} × ε Y",
            k + 1,
            two[k].0
        );
        let ratio = two[k].0 / one[k].0;
        assert!(
            (ratio - 2.0).abs() < 0.1,
            "node {}: linear in ε ({ratio})",
            k + 1
        );
    }
    let held = arch_nodes(&wrapped(0.3, SpecimenContact::CurvedSupport, 0.02, 0.2));
    for k in 1..9 {
        assert!(
            held[k].0 < two[k].0,
            "node {}: friction holds the film back ({} vs {})",
            k + 1,
            held[k].0,
            two[k].0
        );
    }
}

#[test]
fn fixed_frame_gaps_count_the_winding_travel_as_slip() {
    let gaps = arch_nodes(&wrapped(0.3, SpecimenContact::Gaps, 0.02, 0.2));
    let curved = arch_nodes(&wrapped(0.3, SpecimenContact::CurvedSupport, 0.02, 0.2));
    assert!(
        gaps[7].0 > 3.0 * curved[7].0,
        "G8: gap local x {} vs slid {}",
        gaps[7].0,
        curved[7].0
    );
}
