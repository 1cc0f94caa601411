//! Warnings about a model that validates but looks wrong, and about results outside the
//! model's assumptions (large strain).

use crate::mech::elements::plasticity::ETFE_RUPTURE_PLASTIC_STRAIN;
use crate::mech::elements::triangle::ElementStress;
use crate::mech::model::message_number;
use crate::mech::model::{GapSupport, Model};
use crate::mech::results::Results;
use crate::mech::results::summary::{major_principal, mpa};
use nalgebra::Vector3;

/// Major principal Green–Lagrange strain beyond which a result is outside the model's
/// assumptions: the law (2.3) is linear elastic, and ETFE leaves its elastic range near 2–3 %
/// strain (first yield ≈ 15 MPa at E ≈ 0.8 GPa is 2 %), so 5 % is far past it whatever the
/// film's yield stress.
pub const SMALL_STRAIN_LIMIT: f64 = 0.05;

/// A Young's modulus below this (Pa) is almost surely given in MPa by mistake (ETFE: 0.6–1.1
/// GPa; the softest architectural films and fabrics are far above 0.1 MPa · 1e6).
pub const SUSPICIOUS_MODULUS: f64 = 1e5;

/// Fraction of the film's area that may have yielded at the end of a step without a warning:
/// 0.5. Yield in a band along a support, a corner or a contact is what a design check of an ETFE
/// film expects and what the plastic film is there to follow; once more than half of the
/// film's area has yielded, plastic flow sets the film's shape and stress everywhere, its
/// prestress is lost for good and it would not return to its shape when unloaded: a film being
/// stretched permanently, not one in service (the vault roof of issue 47: all 728 elements,
/// `ε̄p` up to 6.8 %, with nothing said).
pub const YIELDED_AREA_FRACTION: f64 = 0.5;

/// Warnings about a model that validates but looks wrong (checked once, before any step): a
/// Young's modulus that looks like MPa, a prestressed film with free edges
/// ([`crate::mech::model::free_edges`]), pressure sets with triangles pushed against their
/// neighbours ([`crate::mech::elements::load::orientation_warnings`]), and gaps whose `initial_gap` differs slightly (up to
/// [`crate::mech::model::GAP_GEOMETRY_TOLERANCE`] of the size; beyond, validation refuses the model)
/// from the distance along the gap's local z between film node and support (§4.3:
/// `g0 = z · (X_A − X_B)`).
pub fn model_warnings(model: &Model) -> Vec<String> {
    let mut warnings = vec![];
    let e = model.material.youngs_modulus;
    if e < SUSPICIOUS_MODULUS {
        warnings.push(format!(
            "material youngs_modulus = {} Pa looks like a value in MPa (ETFE: about 1e9 Pa); \
             the model file takes Pa",
            message_number(e)
        ));
    }
    warnings.extend(crate::mech::model::free_edges::free_edge_warning(model));
    warnings.extend(crate::mech::elements::load::orientation_warnings(model));
    let size = crate::mech::model::bounding_diagonal(&model.nodes);
    for gap in &model.gaps {
        let n = model.nodes.len();
        let support_exists = match gap.support {
            GapSupport::Point(_) => true,
            GapSupport::Node(b) => b < n,
        };
        if gap.film_node >= n || !support_exists {
            continue;
        }
        let distance = gap.geometric_gap(&model.nodes);
        if (distance - gap.initial_gap).abs() > 1e-6 * size {
            warnings.push(format!(
                "gap '{}': initial_gap = {} m, but its film node lies {distance} m from the support \
                 point along the gap's z: the gap starts {} (check initial_gap, the support point \
                 or the frame)",
                gap.name,
                gap.initial_gap,
                if gap.initial_gap < distance {
                    "closer than the geometry says"
                } else {
                    "farther than the geometry says"
                }
            ));
        }
    }
    warnings
}

/// Warnings about a converged state outside the model's assumptions: a von Mises stress above
/// the material's `yield_stress`, a principal strain above [`SMALL_STRAIN_LIMIT`] (an elastic
/// film), yield over more than [`YIELDED_AREA_FRACTION`] of the film's area and an equivalent
/// plastic strain past [`ETFE_RUPTURE_PLASTIC_STRAIN`] (a plastic film), penetrations and
/// contact forces far outside the model's scale
/// ([`crate::mech::results::contact_warnings`]). One line per kind, naming the worst element
/// or contacts.
pub fn result_warnings(model: &Model, results: &Results) -> Vec<String> {
    let mut warnings = crate::mech::results::contact_warnings::contact_warnings(model, results);
    let worst = |f: &dyn Fn(&ElementStress) -> f64| {
        results
            .elements
            .iter()
            .map(f)
            .enumerate()
            .fold(
                (0, f64::NEG_INFINITY),
                |b, (i, v)| if v > b.1 { (i, v) } else { b },
            )
    };
    if let Some(limit) = model.material.at_temperature().yield_stress {
        let (e, s) = worst(&|e| e.von_mises);
        if s > limit {
            let over = results
                .elements
                .iter()
                .filter(|e| e.von_mises > limit)
                .count();
            warnings.push(format!(
                "equivalent stress {} MPa in triangle {e} is above the material's yield_stress \
                 {} MPa ({over} triangles above it): the linear film law no longer holds there",
                mpa(s),
                mpa(limit)
            ));
        }
    }
    if model.material.plasticity.is_some() {
        // The finite-strain plastic film holds at large strains; it tears past rupture.
        let (e, ep) = worst(&|e| e.plastic.map_or(0.0, |p| p.equivalent_plastic_strain));
        warnings.extend(yield_warning(model, results, (e, ep)));
        if ep > ETFE_RUPTURE_PLASTIC_STRAIN {
            warnings.push(format!(
                "equivalent plastic strain {ep:.3} in triangle {e} is past ETFE's rupture strain \
                 {ETFE_RUPTURE_PLASTIC_STRAIN:.3} (elongation at break 450 %, docs/mechanics.md): \
                 the film would have torn there"
            ));
        }
        return warnings;
    }
    let (e, strain) = worst(&|e| major_principal(e.strain, 0.5));
    if strain > SMALL_STRAIN_LIMIT {
        warnings.push(format!(
            "principal strain {:.2} % in triangle {e} is beyond the small-strain range of the \
             linear film law ({:.0} %)",
            100.0 * strain,
            100.0 * SMALL_STRAIN_LIMIT
        ));
    }
    warnings
}

/// The warning that more than [`YIELDED_AREA_FRACTION`] of the film's (initial) area has
/// yielded (`ε̄p > 0`), with the largest equivalent plastic strain `worst = (triangle, ε̄p)`;
/// none below it. Triangles with unknown nodes count with no area.
fn yield_warning(model: &Model, results: &Results, worst: (usize, f64)) -> Option<String> {
    let area = |t: &[usize; 3]| {
        if t.iter().any(|&v| v >= model.nodes.len()) {
            return 0.0;
        }
        let [a, b, c] = t.map(|v| Vector3::from(model.nodes[v]));
        0.5 * (b - a).cross(&(c - a)).norm()
    };
    let (mut total, mut yielded, mut count) = (0.0, 0.0, 0usize);
    for (t, e) in model.triangles.iter().zip(&results.elements) {
        let a = area(t);
        total += a;
        if e.plastic.is_some_and(|p| p.equivalent_plastic_strain > 0.0) {
            yielded += a;
            count += 1;
        }
    }
    if yielded <= YIELDED_AREA_FRACTION * total {
        return None;
    }
    let (e, ep) = worst;
    Some(format!(
        "the film has yielded over {:.0} % of its area ({count} of {} triangles; more than {:.0} % \
         warns), equivalent plastic strain up to {:.2} % in triangle {e}: plastic flow sets its \
         shape and stress everywhere, its prestress is lost for good and it would not return to \
         its shape unloaded (check the loads, the prescribed displacements and the hardening)",
        100.0 * yielded / total,
        results.elements.len(),
        100.0 * YIELDED_AREA_FRACTION,
        100.0 * ep
    ))
}
