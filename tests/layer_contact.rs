//! TEST GOAL (issue 43, "layers that touch"): film-to-film contact between two meshed layers.
//! A 1 m square top layer (4 × 4 cells) lies on a larger bottom layer (1.5 m, 6 × 6 cells,
//! every node fixed) whose nodes it shares positions with; the top layer is held in plane
//! (x, y) and in z at one corner only, so that everywhere else the contact alone carries the
//! snow pressure `p` pressing it down. Closed forms: the contact pressure is `p` at every node
//! away from the held corner, and the contact forces plus the corner's reaction are `p A`;
//! pulled sideways as a whole, the top layer sticks with `k_s δ` per node and slides once the
//! force reaches `μ N` (then exactly `μ N`). A clamped disc pressed into an identical one
//! that shares its rim (frictionless) rises with it as one disc of twice the thickness.

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
    let (model, _) = two_layers(true, false);
    let levels = LoadLevels::of_model(&model);
    let mut analysis = Analysis::new(model, settings()).unwrap();
    analysis
        .step_to_with_loads(&[[0.0; 3]], &levels, 2)
        .unwrap();
    let pressed: Vec<f64> = analysis
        .results()
        .layer_contacts
        .iter()
        .map(|c| c.normal_force)
        .collect();
    // Each node holds k_s δ until that reaches μλN, then slides at μλN: the pull on the layer
    // is Σ min(k_s δ, μ λN) (sliding leaves the flat layers' normal forces as they are).
    for (shift, increments, slipping) in [(2e-5, 1, 1..=20), (0.02, 4, 24..=24)] {
        analysis
            .step_to_with_loads(&[[shift, 0.0, 0.0]], &levels, increments)
            .unwrap();
        let r = analysis.results();
        let expected: f64 = pressed.iter().map(|&n| (KS * shift).min(MU * n)).sum();
        let pulled = r.reactions[0][0];
        // To the penalty's accuracy: the layer tilts by its penetrations (≈ λN/(k_n h) ≈ 1e-4
        // near the held corner), and the follower snow pressure on it leans by as much.
        assert!(
            (pulled - expected).abs() < 2e-5 * expected,
            "δ = {shift}: pull {pulled} N vs Σ min(k_s δ, μλN) = {expected} N"
        );
        let mut slid = 0;
        for (c, &n) in r.layer_contacts.iter().zip(&pressed) {
            assert!((c.normal_force - n).abs() < 1e-6 * n.max(1.0), "{}", c.name);
            if n == 0.0 {
                continue;
            }
            let friction = c.friction[0].abs();
            if KS * shift < MU * n {
                assert_eq!(c.status, GapStatus::Stick, "{}", c.name);
                assert!(
                    (friction - KS * shift).abs() < 1e-6 * friction,
                    "{}",
                    c.name
                );
            } else {
                slid += 1;
                assert_eq!(c.status, GapStatus::Slip, "{}", c.name);
                assert!((friction - MU * n).abs() < 1e-6 * friction, "{}", c.name);
                // It slid the shift less the elastic stick μλN/k_s.
                let expected = shift - MU * n / KS;
                assert!(
                    (c.slip - expected).abs() < 1e-7,
                    "{}: slip {} vs {expected}",
                    c.name,
                    c.slip
                );
            }
        }
        assert!(slipping.contains(&slid), "δ = {shift}: {slid} nodes slide");
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
fn a_malformed_layer_contact_is_refused_naming_it_and_the_fault() {
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
    let (mut model, _) = two_layers(false, false);
    model.layer_contacts[0].master = LayerSurface::Triangles(vec![3, 80]);
    let err = model.validate().unwrap_err().to_string();
    assert!(
        err.contains("'Touch'") && err.contains("triangle 80 is in both"),
        "{err}"
    );
    let (mut model, _) = two_layers(false, false);
    model.layer_contacts[0].slave = LayerSurface::Triangles(vec![500]);
    let err = model.validate().unwrap_err().to_string();
    assert!(
        err.contains("'Touch'") && err.contains("slave triangle 500"),
        "{err}"
    );
    let (mut model, _) = two_layers(false, false);
    model.layer_contacts[0].friction_law = membrane_contact::mech::FrictionLaw::SlidingDirection;
    let err = model.validate().unwrap_err().to_string();
    assert!(
        err.contains("'Touch'") && err.contains("isotropic"),
        "{err}"
    );
}

#[test]
fn the_example_is_the_two_way_pressed_model_of_these_tests() {
    let (mut model, _) = two_layers(false, true);
    model.description = "A 1 m square top layer pressed by 400 Pa of snow onto a fixed 1.5 m \
                         bottom layer, in two-way frictional contact (tests/layer_contact.rs)"
        .into();
    common::assert_example_file("two_layers_touching.json", &model);
}

/// A clamped disc (`CircularMembrane`, 4 rings, radius 1 m) and a second identical layer on it
/// sharing its rim (both clamped in one extrusion), the first pressed into the second by
/// `pressure`; frictionless. Returns the model and the second layer's centre node.
fn pressed_pair_of_discs(pressure: f64) -> (Model, usize) {
    let disc = disc(1.0, pressure);
    let mut model = disc.model().unwrap();
    let rim: Vec<usize> = disc.ring(disc.rings).collect();
    let first = model.triangles.len();
    let n = model.nodes.len();
    // Interior nodes doubled; the rim shared.
    let copy = |v: usize| if rim.contains(&v) { v } else { n + v };
    for v in 0..n {
        model.nodes.push(model.nodes[v]);
    }
    let second: Vec<[usize; 3]> = model.triangles.iter().map(|t| t.map(copy)).collect();
    model.triangles.extend(second);
    // Rim copies are unused: hold them so that the model stays well posed.
    for &v in &rim {
        model.supports.push(Support {
            node: n + v,
            fixed: vec![Axis::X, Axis::Y, Axis::Z],
            name: None,
        });
    }
    model.loads.pressures[0].elements =
        membrane_contact::mech::model::ElementSelection::List((0..first).collect());
    model.layer_contacts.push(LayerContactSpec {
        name: "Touch".into(),
        slave: LayerSurface::Triangles((0..first).collect()),
        master: LayerSurface::Triangles((first..2 * first).collect()),
        // The pressure pushes the first layer along its normal (+z) into the second.
        side: Side::Back,
        both_ways: false,
        normal_stiffness: 1e6,
        tangential_stiffness: 1e5,
        friction: 0.0,
        friction_law: Default::default(),
        search_distance: 0.3,
    });
    (model, n)
}

/// The 4-ring disc of radius 1 m of the specimens' film, its thickness `scale` times theirs.
fn disc(scale: f64, pressure: f64) -> membrane_contact::specimens::scenarios::CircularMembrane {
    let mut material = membrane_contact::specimens::ParallelArch::default().material;
    material.thickness *= scale;
    membrane_contact::specimens::scenarios::CircularMembrane {
        radius: 1.0,
        rings: 4,
        material,
        pressure,
    }
}

/// The centre's rise of `model` (node `centre`) under its pressure.
fn centre_rise(model: Model, nodes: &[usize]) -> Vec<f64> {
    let levels = LoadLevels::of_model(&model);
    let mut analysis = Analysis::new(model, settings()).unwrap();
    analysis
        .step_to_with_loads(&[[0.0; 3]], &levels, 4)
        .unwrap();
    nodes
        .iter()
        .map(|&v| analysis.node_displacement(v).z)
        .collect()
}

#[test]
fn two_discs_pressed_together_deflect_as_one_disc_of_twice_the_thickness() {
    let p = 100.0;
    let (model, second_centre) = pressed_pair_of_discs(p);
    let pair = centre_rise(model, &[0, second_centre]);
    let one = centre_rise(disc(2.0, p).model().unwrap(), &[0])[0];
    assert!(one > 0.01, "{one}");
    for w in pair {
        assert!(
            (w - one).abs() < 2e-4 * one,
            "layer centre {w} m vs one disc of 2t {one} m"
        );
    }
}

#[test]
fn frictional_discs_stick_and_both_iteration_matrices_reach_the_same_state() {
    use membrane_contact::mech::IterationMatrix;
    let one = centre_rise(disc(2.0, 100.0).model().unwrap(), &[0])[0];
    let mut rises = vec![];
    for matrix in [IterationMatrix::Consistent, IterationMatrix::JuRowlands] {
        let (mut model, second_centre) = pressed_pair_of_discs(100.0);
        model.layer_contacts[0].friction = 0.3;
        let levels = LoadLevels::of_model(&model);
        let settings = SolverSettings {
            iteration_matrix: matrix,
            ..settings()
        };
        let mut analysis = Analysis::new(model, settings).unwrap();
        analysis
            .step_to_with_loads(&[[0.0; 3]], &levels, 4)
            .unwrap();
        let r = analysis.results();
        // Identical layers strain alike: nothing slides between them.
        assert!(r.layer_contacts.iter().all(|c| c.status != GapStatus::Slip));
        let w = [0, second_centre].map(|v| analysis.node_displacement(v).z);
        for w in w {
            assert!((w - one).abs() < 2e-4 * one, "{matrix:?}: {w} vs {one}");
        }
        rises.push(w);
    }
    for k in 0..2 {
        assert!((rises[0][k] - rises[1][k]).abs() < 1e-8 * one, "{rises:?}");
    }
}

/// A two-layer cushion (issue 43): two identical clamped discs (4 rings, radius 1 m, the
/// specimens' film) on one rim circle, each held by a group of its own (`rimTop`, `rimBottom`:
/// the extrusion's two clamping lines, so that each layer's reaction is known), the air between
/// them held at `air` Pa by the supply (two chambers closed by the frame's plane z = 0, one per
/// layer: together the air between the layers), the top layer's nodes in frictionless contact
/// with the bottom layer, and snow (pressure set `snow`, towards −z) on the top layer. Returns
/// the model and the bottom layer's centre node.
fn snowed_cushion(air: f64) -> (Model, usize) {
    use membrane_contact::mech::model::{ChamberSpec, ClosingPlane, ElementSelection};
    let disc = disc(1.0, 0.0);
    let mut model = disc.model().unwrap();
    let (n, first) = (model.nodes.len(), model.triangles.len());
    for v in 0..n {
        model.nodes.push(model.nodes[v]);
    }
    let bottom: Vec<[usize; 3]> = model.triangles.iter().map(|t| t.map(|v| v + n)).collect();
    model.triangles.extend(bottom);
    model.groups[0].name = "rimTop".into();
    let mut rim_bottom = model.groups[0].clone();
    rim_bottom.name = "rimBottom".into();
    rim_bottom.nodes = rim_bottom.nodes.iter().map(|v| v + n).collect();
    model.groups.push(rim_bottom);
    let top = ElementSelection::List((0..first).collect());
    let chamber = |name: &str, elements: ElementSelection, z: f64| ChamberSpec {
        name: name.into(),
        elements,
        closed_by_plane: Some(ClosingPlane {
            point: [0.0; 3],
            normal: [0.0, 0.0, z],
        }),
        pressure: air,
        sealed: false,
        kappa: 1.0,
        atmosphere: 101_325.0,
        temperature: 293.15,
        heating: 0.0,
    };
    model.chambers = vec![
        chamber("airTop", top.clone(), 1.0),
        chamber(
            "airBottom",
            ElementSelection::List((first..2 * first).collect()),
            -1.0,
        ),
    ];
    model.loads.pressures[0].name = "snow".into();
    model.loads.pressures[0].elements = top;
    model.loads.pressures[0].towards = Some(Towards::Direction([0.0, 0.0, -1.0]));
    model.layer_contacts.push(LayerContactSpec {
        name: "Touch".into(),
        slave: LayerSurface::Triangles((0..first).collect()),
        master: LayerSurface::Triangles((first..2 * first).collect()),
        // Both layers' triangles face +z; the top one lands on the bottom from above.
        side: Side::Front,
        both_ways: false,
        normal_stiffness: 1e6,
        tangential_stiffness: 1e5,
        friction: 0.0,
        friction_law: Default::default(),
        search_distance: 0.3,
    });
    model.validate().unwrap();
    (model, n)
}

/// Snow inverts the top layer of a two-layer cushion onto the bottom one, and then the two
/// carry it together ([`snowed_cushion`], the air held at 300 Pa by the supply): the top layer
/// goes down, through its rim's plane (inverted at 400 Pa of snow, its centre 42 mm below the
/// rim while the bottom's is 63 mm), and lands on the bottom layer once the snow exceeds twice
/// the air's pressure (600 Pa: the top then mirrors the bottom). Before that the contact carries
/// nothing; at 1 200 Pa its normal force is positive (720.7 N), the bottom layer's rim reaction
/// has risen from `p A` = 310.6 N by it (within 1 %), the bottom layer's centre has gone down
/// with the top (to 80.9 mm), and at every snow level
/// the two rims' vertical reactions add up to the snow's resultant `S A` (`A` the rim polygon's
/// area: a follower pressure on a film held at its rim), to 1e-6.
#[test]
fn an_inverted_top_layer_lands_on_the_bottom_layer_and_they_share_the_snow() {
    use membrane_contact::mech::elements::layer_contact::Totals;
    let air = 300.0;
    let (model, bottom_centre) = snowed_cushion(air);
    let area: f64 = (0..model.triangles.len() / 2)
        .map(|e| {
            let [a, b, c] = model.triangles[e].map(|v| nalgebra::Vector3::from(model.nodes[v]));
            0.5 * (b - a).cross(&(c - a)).norm()
        })
        .sum();
    let mut analysis = Analysis::new(model.clone(), settings()).unwrap();
    let mut levels = LoadLevels::zero(&model);
    let held = [[0.0; 3]; 2];
    for f in [0.25, 0.5, 1.0] {
        levels.chambers = vec![f * air; 2];
        analysis.step_to_with_loads(&held, &levels, 4).unwrap();
    }
    let mut seen = vec![];
    for snow in [200.0, 400.0, 600.0, 800.0, 1000.0, 1200.0] {
        levels.pressure[0] = snow;
        analysis.step_to_with_loads(&held, &levels, 4).unwrap();
        let r = analysis.results();
        let (top, bottom) = (r.reactions[0][2], r.reactions[1][2]);
        let touch = Totals::of(&r, 0);
        let (wt, wb) = (
            analysis.node_displacement(0).z,
            analysis.node_displacement(bottom_centre).z,
        );
        println!(
            "snow {snow} Pa: top Rz {top:.3} N, bottom Rz {bottom:.3} N, sum/(S A) {:.9}, contact {:.3} N on {} nodes, centres {wt:.5} / {wb:.5} m",
            (top + bottom) / (snow * area),
            touch.normal_force,
            touch.closed
        );
        assert!(
            ((top + bottom) / (snow * area) - 1.0).abs() < 1e-6,
            "equilibrium at {snow} Pa"
        );
        seen.push((snow, bottom, touch.normal_force, wt, wb));
    }
    let (bulging, before, after) = (seen[0], seen[1], seen[5]);
    assert!(bulging.3 > 0.0, "the top layer still bulges up at 200 Pa");
    // Inverted (through the rim's plane) but not yet on the bottom layer: the coincident rim
    // nodes touch with a force of round-off only.
    assert!(
        before.3 < 0.0 && before.3 > before.4 + 0.01,
        "inverted, above the bottom"
    );
    assert!(
        before.2.abs() < 1e-6,
        "no contact at 400 Pa of snow: {}",
        before.2
    );
    assert!(after.2 > 0.0, "the contact carries load at 1200 Pa");
    assert!(
        after.3 < 0.0 && (after.3 - after.4).abs() < 1e-3,
        "the top layer lies on the bottom one"
    );
    // The bottom layer's reaction rises by what the contact brings (its normals tilt a little
    // off vertical: measured 718.6 N for 720.7 N).
    let rise = after.1 - before.1;
    assert!(
        (rise / after.2 - 1.0).abs() < 0.01,
        "bottom reaction rose {rise} N for {} N",
        after.2
    );
    assert!(
        after.4 < before.4,
        "the bottom layer went down with the top"
    );
}
