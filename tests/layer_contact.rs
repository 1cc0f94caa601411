//! TEST GOAL (issue 43, "layers that touch"): film-to-film contact between two meshed layers.
//! A 1 m square top layer (4 × 4 cells) lies on a larger bottom layer (1.5 m, 6 × 6 cells,
//! every node fixed) whose nodes it shares positions with; the top layer is held in plane
//! (x, y) and in z at one corner only, so that everywhere else the contact alone carries the
//! snow pressure `p` pressing it down. Closed forms: the contact pressure is `p` at every node
//! away from the held corner, and the contact forces plus the corner's reaction are `p A`;
//! pulled sideways as a whole, the top layer sticks with `k_s δ` per node and slides once the
//! force reaches `μ N` (then exactly `μ N`).

mod common;

use membrane_contact::mech::elements::gap::GapStatus;
use membrane_contact::mech::elements::layer_contact::{LayerContactSpec, LayerSurface, Side};
use membrane_contact::mech::model::{Axis, BoundaryGroup, PressureSet, Support, Towards};
use membrane_contact::mech::{Analysis, LoadLevels, Model, SolverSettings};

const P: f64 = 400.0;
const KN: f64 = 1e6;
const KS: f64 = 2e5;
const MU: f64 = 0.3;

/// The two layers; `pull`: the top layer's x driven by group `Pull` (else held).
fn two_layers(pull: bool, both_ways: bool) -> (Model, usize) {
    let (mut nodes, mut triangles) = common::flat_grid(6, 6, 1.5, 1.5);
    for x in &mut nodes {
        x[0] -= 0.25;
        x[1] -= 0.25;
    }
    let bottom = triangles.len();
    let offset = nodes.len();
    let (top_nodes, top_triangles) = common::flat_grid(4, 4, 1.0, 1.0);
    nodes.extend(top_nodes);
    triangles.extend(top_triangles.iter().map(|t| t.map(|v| v + offset)));
    let mut model = common::film_model("TwoLayers", nodes, triangles);
    for v in 0..offset {
        model.supports.push(Support {
            node: v,
            fixed: vec![Axis::X, Axis::Y, Axis::Z],
            name: None,
        });
    }
    for v in offset..model.nodes.len() {
        let mut fixed = vec![Axis::Y];
        if !pull {
            fixed.push(Axis::X);
        }
        if v == offset {
            fixed.push(Axis::Z);
        }
        model.supports.push(Support {
            node: v,
            fixed,
            name: (v == offset).then(|| "corner".into()),
        });
    }
    if pull {
        model.groups.push(BoundaryGroup {
            name: "Pull".into(),
            nodes: (offset..model.nodes.len()).collect(),
            target: [0.0; 3],
            components: Some(vec![Axis::X]),
            hinge: None,
        });
    }
    let top: Vec<usize> = (bottom..model.triangles.len()).collect();
    model.loads.pressures.push(PressureSet {
        name: "Snow".into(),
        elements: membrane_contact::mech::model::ElementSelection::List(top.clone()),
        pressure: P,
        towards: Some(Towards::Direction([0.0, 0.0, -1.0])),
        kind: Default::default(),
    });
    model.layer_contacts.push(LayerContactSpec {
        name: "Touch".into(),
        slave: LayerSurface::Triangles(top),
        master: LayerSurface::Triangles((0..bottom).collect()),
        side: Side::Front,
        both_ways,
        normal_stiffness: KN,
        tangential_stiffness: KS,
        friction: MU,
        friction_law: Default::default(),
        search_distance: 0.3,
    });
    (model, offset)
}

fn settings() -> SolverSettings {
    SolverSettings {
        residual_tolerance: 1e-9,
        ..Default::default()
    }
}

#[test]
fn pressed_layer_carries_the_pressure_resultant_through_the_contact() {
    let (model, offset) = two_layers(false, false);
    let levels = LoadLevels::of_model(&model);
    let mut analysis = Analysis::new(model, settings()).unwrap();
    analysis.step_to_with_loads(&[], &levels, 2).unwrap();
    let results = analysis.results();
    let contacts = &results.layer_contacts;
    assert_eq!(contacts.len(), 25, "one per top-layer node");
    let carried: f64 = contacts.iter().map(|c| c.normal_force).sum();
    let corner = results.node_reactions[offset][2];
    // p A = contact forces + the corner's reaction (both push up on the top layer).
    assert!(
        (carried + corner - P).abs() < 1e-6 * P,
        "contact {carried} N + corner {corner} N vs {P} N"
    );
    assert!(carried > 0.9 * P, "{carried}");
    let mut checked = 0;
    for c in contacts {
        let x = analysis.model().nodes[c.node];
        if x[0] + x[1] < 0.6 {
            continue; // near the held corner, which takes part of the load
        }
        checked += 1;
        assert_ne!(c.status, GapStatus::Open, "{}", c.name);
        assert!(
            (c.pressure - P).abs() < 2e-3 * P,
            "{}: contact pressure {} Pa vs {P} Pa",
            c.name,
            c.pressure
        );
        // The penetration is the penalty's: g = −λN / k_n.
        assert!((c.gap + c.normal_force / KN).abs() < 1e-12, "{}", c.name);
    }
    assert!(checked >= 15, "{checked}");
}

#[test]
fn pulled_layer_sticks_below_mu_n_and_slides_at_mu_n() {
    let (model, offset) = two_layers(true, false);
    let levels = LoadLevels::of_model(&model);
    let mut analysis = Analysis::new(model, settings()).unwrap();
    analysis
        .step_to_with_loads(&[[0.0; 3]], &levels, 2)
        .unwrap();
    let normal: f64 = analysis
        .results()
        .layer_contacts
        .iter()
        .map(|c| c.normal_force)
        .sum();
    let _ = offset;
    // Stick: a shift far below μλN/k_s at every node, friction k_s δ per node in contact.
    let small = 1e-5;
    analysis
        .step_to_with_loads(&[[small, 0.0, 0.0]], &levels, 1)
        .unwrap();
    let r = analysis.results();
    let closed = r
        .layer_contacts
        .iter()
        .filter(|c| c.status != GapStatus::Open)
        .count();
    assert!(r.layer_contacts.iter().all(|c| c.status != GapStatus::Slip));
    let stick = r.reactions[0][0];
    assert!(
        (stick - KS * small * closed as f64).abs() < 1e-6 * stick,
        "{stick} N vs k_s δ n = {}",
        KS * small * closed as f64
    );
    assert!(stick < MU * normal);
    // Slip: far beyond, the pull is μN (to the penalty's accuracy) and every node slides.
    let far = 0.02;
    analysis
        .step_to_with_loads(&[[far, 0.0, 0.0]], &levels, 4)
        .unwrap();
    let r = analysis.results();
    let normal: f64 = r.layer_contacts.iter().map(|c| c.normal_force).sum();
    let pulled = r.reactions[0][0];
    assert!(
        (pulled - MU * normal).abs() < 1e-6 * pulled,
        "pull {pulled} N vs μN = {} N",
        MU * normal
    );
    for c in &r.layer_contacts {
        if c.status == GapStatus::Open {
            continue;
        }
        assert_eq!(c.status, GapStatus::Slip, "{}", c.name);
        // It slid the pull less the elastic stick k_s⁻¹ μλN.
        let expected = far - MU * c.normal_force / KS;
        assert!(
            (c.slip - expected).abs() < 1e-6,
            "{}: slip {} vs {expected}",
            c.name,
            c.slip
        );
    }
}

#[test]
fn both_ways_contact_carries_the_same_resultant() {
    let (model, offset) = two_layers(false, true);
    let levels = LoadLevels::of_model(&model);
    let mut analysis = Analysis::new(model, settings()).unwrap();
    analysis.step_to_with_loads(&[], &levels, 2).unwrap();
    let results = analysis.results();
    let back = results
        .layer_contacts
        .iter()
        .filter(|c| c.name.contains(".back."))
        .count();
    assert_eq!(
        back, 49,
        "the bottom layer's nodes against the top's triangles"
    );
    let carried: f64 = results.layer_contacts.iter().map(|c| c.normal_force).sum();
    let corner = results.node_reactions[offset][2];
    assert!(
        (carried + corner - P).abs() < 1e-6 * P,
        "contact {carried} N + corner {corner} N vs {P} N"
    );
}

#[test]
fn a_layer_contact_naming_an_unknown_layer_is_refused_by_name() {
    let (mut model, _) = two_layers(false, false);
    model.layer_contacts[0].master = LayerSurface::Layer("Middle".into());
    let err = model.validate().unwrap_err().to_string();
    assert!(
        err.contains("layer contact 'Touch'") && err.contains("Middle"),
        "{err}"
    );
    let (mut model, _) = two_layers(false, false);
    model.layer_contacts[0].friction = -0.1;
    let err = model.validate().unwrap_err().to_string();
    assert!(err.contains("'Touch'") && err.contains("friction"), "{err}");
}
