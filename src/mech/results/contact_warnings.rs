//! Warnings about contacts far outside the model's scale: a penetration that a rigid support
//! does not allow, a contact force that no film load path can deliver (issue 47 item 8: the
//! vault roof's rails driven into the curved supports' end caps "converged" with contact forces
//! of 1.14 MN on a film whose forces are kN).
//!
//! A penalty contact stands for an impenetrable support; its penetration (`N/k_n` of a gap, the
//! negative gap `r − d` of a curved support) only has to be small for the model to mean what it
//! says. And what the film can push onto one contact is bounded by the membrane forces around
//! it: a force that the whole film could not carry across its full size at the end of the
//! small-strain range is balanced by something else, a prescribed motion pressing a node into
//! the support against the penalty, not by the film.

use crate::mech::model::{Model, bounding_diagonal};
use crate::mech::results::Results;
use crate::mech::results::warnings::SMALL_STRAIN_LIMIT;

/// Largest penetration of a gap, as a fraction of the film's size (bounding-box diagonal), that
/// does not warn: 1 %, 29 mm on the 2.9 m specimen, 100 times what its contacts reach (its
/// `k_n = 1000·E·t` gives 0.4 µm per 100 N). The displacements the model computes are of that
/// order; a support entered that deep is not a support.
pub const GAP_PENETRATION_FRACTION: f64 = 0.01;

/// Largest penetration of a curved-support contact, as a fraction of the support's tube radius,
/// that does not warn: 10 %. No pipe is dented that much by a film; at 100 % the node reaches
/// the centreline and the contact's normal is lost.
pub const TUBE_PENETRATION_FRACTION: f64 = 0.1;

/// The film's force scale is `E·t·L·ε`, with `ε` this strain ([`SMALL_STRAIN_LIMIT`], 5 %): the
/// force the whole film carries across its full size `L` (bounding-box diagonal) at the end of
/// the small-strain range, already past ETFE's yield. A contact force above it is warned about:
/// the film cannot deliver it to one node (on the 2.9 m specimen it is 36 kN, its gaps carry
/// about 100 N; the vault roof's 1.14 MN is several times it).
pub const CONTACT_FORCE_STRAIN: f64 = SMALL_STRAIN_LIMIT;

/// How many contacts a warning names before "…".
const LISTED_CONTACTS: usize = 3;

/// One line per kind (penetration, force), naming the worst contacts first, up to
/// three of them, and how many there are.
pub fn contact_warnings(model: &Model, results: &Results) -> Vec<String> {
    let size = bounding_diagonal(&model.nodes);
    let m = model.material.at_temperature();
    let force_scale = m.youngs_modulus * m.thickness * size * CONTACT_FORCE_STRAIN;
    // (name, penetration, allowed penetration, |force|) of every contact.
    let mut contacts: Vec<(String, f64, f64, f64)> = vec![];
    for (g, r) in model.gaps.iter().zip(&results.gaps) {
        contacts.push((
            format!("gap '{}'", g.name),
            r.normal_force / g.normal_stiffness,
            GAP_PENETRATION_FRACTION * size,
            r.normal_force.hypot(r.friction_force),
        ));
    }
    let nodes = model
        .curved_supports
        .iter()
        .flat_map(|s| s.nodes.iter().map(move |&v| (s, v)));
    for ((s, v), c) in nodes.zip(&results.surface_contacts) {
        let force = c.force.iter().map(|f| f * f).sum::<f64>().sqrt();
        contacts.push((
            format!("{}.node{v}", s.name),
            -c.gap,
            TUBE_PENETRATION_FRACTION * s.tube_radius,
            force,
        ));
    }
    let mut warnings = vec![];
    let deep = |c: &&(String, f64, f64, f64)| c.1 > c.2;
    if let Some(text) = listed(
        &contacts,
        deep,
        |c| c.1 / c.2,
        |c| format!("{} {:.3e} m", c.0, c.1),
    ) {
        warnings.push(format!(
            "contact penetration far beyond what a rigid support allows at {text} (limits: {:.0} % \
             of the film's size {:.3e} m for a gap, {:.0} % of the tube radius for a curved support); \
             the penalty holds the node only by being pressed in: check the prescribed \
             displacements, the support's position and its normal_stiffness",
            100.0 * GAP_PENETRATION_FRACTION,
            size,
            100.0 * TUBE_PENETRATION_FRACTION,
        ));
    }
    let strong = |c: &&(String, f64, f64, f64)| c.3 > force_scale;
    if let Some(text) = listed(
        &contacts,
        strong,
        |c| c.3,
        |c| format!("{} {:.3e} N", c.0, c.3),
    ) {
        warnings.push(format!(
            "contact force far beyond the film's scale at {text} (E·t·L·{:.0} % = {force_scale:.3e} \
             N, what the whole film carries across its size L = {size:.3e} m at {:.0} % strain): the film \
             cannot deliver it, a prescribed motion presses the node into the support; check the \
             prescribed displacements and the support's position",
            100.0 * CONTACT_FORCE_STRAIN,
            100.0 * CONTACT_FORCE_STRAIN,
        ));
    }
    warnings
}

/// How many contacts pass `keep` and the worst of them by `worst`, up to [`LISTED_CONTACTS`]
/// described by `describe`: `2 contacts: tube1.node12 1.140e6 N, gap 'G4' 2.000e5 N`; none
/// when no contact passes.
fn listed<T>(
    contacts: &[T],
    keep: impl Fn(&&T) -> bool,
    worst: impl Fn(&T) -> f64,
    describe: impl Fn(&T) -> String,
) -> Option<String> {
    let mut kept: Vec<&T> = contacts.iter().filter(keep).collect();
    if kept.is_empty() {
        return None;
    }
    kept.sort_by(|a, b| worst(b).total_cmp(&worst(a)));
    let named: Vec<String> = kept
        .iter()
        .take(LISTED_CONTACTS)
        .map(|c| describe(c))
        .collect();
    let more = if kept.len() > LISTED_CONTACTS {
        ", …"
    } else {
        ""
    };
    let count = match kept.len() {
        1 => "1 contact".to_string(),
        k => format!("{k} contacts"),
    };
    Some(format!("{count}: {}{more}", named.join(", ")))
}
