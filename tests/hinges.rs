//! Boundary groups that turn about a hinge (issue 8, item 2): a rotating frame side is one group.
//!
//! TEST GOAL: a group with a `hinge` moves its nodes by `t + (R(θ) − I)(X − p)`; a prestressed
//! panel whose whole rim turns rigidly follows the rigid rotation exactly (interior nodes,
//! stresses, no net reaction, no moment), also with the hinge translated; a strip whose end turns
//! about an axis below it is stretched to the closed-form force and hinge moment of a homogeneous
//! uniaxial Green-strain stretch; angles are refused for groups without a hinge, beyond two
//! turns or not finite, and a hinge without an axis is refused at validation; the FMU has the
//! angle input and the moment output for hinged groups only.
//!
//! MODELS: a flat square panel (prestress 2 MPa isotropic) whose rim is one hinged group turned
//! about an inclined axis; a flat 0.2 m × 0.05 m strip with ν = 0 and uniaxial prestress,
//! clamped at x = 0, its end at x = L turned about a y-axis a distance `h` below it.

use membrane_contact::fmi2::description::describe;
use membrane_contact::fmi2::resources::Source;
use membrane_contact::mech::model::Axis;
use membrane_contact::mech::model::{BoundaryGroup, Hinge, Model, Support};
use membrane_contact::mech::{Analysis, LoadLevels, SolverSettings, StepError};
use nalgebra::{Rotation3, Unit, Vector3};

mod common;
use common::{assert_example_file, film_model, flat_grid};

const N: usize = 6;
const SIDE: f64 = 0.5;
const AXIS: [f64; 3] = [1.0, 2.0, 2.0];
const POINT: [f64; 3] = [0.1, -0.2, 0.3];

/// The square panel whose rim is the hinged group `rim`.
fn panel() -> Model {
    let (nodes, triangles) = flat_grid(N, N, SIDE, SIDE);
    let mut m = film_model("Panel", nodes, triangles);
    m.material.prestress = [2.0e6, 2.0e6, 0.0];
    let rim: Vec<usize> = (0..m.nodes.len())
        .filter(|&v| {
            let (i, j) = (v % (N + 1), v / (N + 1));
            i == 0 || j == 0 || i == N || j == N
        })
        .collect();
    m.groups.push(BoundaryGroup {
        name: "rim".into(),
        nodes: rim,
        target: [0.0; 3],
        components: None,
        hinge: Some(Hinge {
            point: POINT,
            axis: AXIS,
            target_angle: 1.2,
        }),
    });
    m
}

/// Where the rigid motion (turn by `angle` about the panel's hinge, then `shift`) takes `x`.
fn rigid(x: [f64; 3], angle: f64, shift: [f64; 3]) -> Vector3<f64> {
    let r = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::from(AXIS)), angle);
    let p = Vector3::from(POINT);
    p + r * (Vector3::from(x) - p) + Vector3::from(shift)
}

#[test]
fn hinged_rim_turns_the_prestressed_panel_as_a_rigid_body() {
    let m = panel();
    // Tight tolerances: the rigid motion is an exact equilibrium, reached to round-off.
    let settings = SolverSettings {
        displacement_tolerance: 1e-11,
        residual_tolerance: 1e-11,
        ..SolverSettings::default()
    };
    let mut analysis = Analysis::new(m.clone(), settings).unwrap();
    let loads = LoadLevels::zero(&m);
    let shift = [0.05, -0.02, 0.1];
    // Turn in three steps (1.2 rad = 69°), then translate and turn back part of the way.
    for (k, (angle, t)) in [
        (0.4, [0.0; 3]),
        (0.8, [0.0; 3]),
        (1.2, [0.0; 3]),
        (0.7, shift),
    ]
    .into_iter()
    .enumerate()
    {
        analysis
            .step_to_motion(&[t], &[angle], &loads, 4)
            .unwrap_or_else(|e| panic!("step {k}: {e}"));
        let mut worst = 0.0_f64;
        for (v, x) in m.nodes.iter().enumerate() {
            let at = Vector3::from(*x) + analysis.node_displacement(v);
            worst = worst.max((at - rigid(*x, angle, t)).norm());
        }
        assert!(
            worst < 1e-12 * SIDE,
            "step {k}: a node is {worst:e} m from the rigid position"
        );
        let results = analysis.results();
        for e in &results.elements {
            assert!(
                (e.von_mises - 2.0e6).abs() < 1e-3,
                "stress changed: {}",
                e.von_mises
            );
        }
        // The prestress is self-equilibrated: no net force, no moment about the hinge.
        let force_scale = 2.0e6 * m.material.thickness * SIDE;
        let r = Vector3::from(results.reactions[0]);
        assert!(r.norm() < 1e-9 * force_scale, "step {k}: reaction {r}");
        assert!(
            results.moments[0].abs() < 1e-9 * force_scale * SIDE,
            "step {k}: moment {}",
            results.moments[0]
        );
        assert_eq!(analysis.state().angles, vec![angle]);
    }
}

const L: f64 = 0.2;
const B: f64 = 0.05;
const H: f64 = 0.05;
const SIGMA0: f64 = 1.0e6;

/// The strip clamped at x = 0; its end x = L turns about the y-axis through (L, 0, −H).
fn strip() -> Model {
    let (nx, ny) = (8, 2);
    let (nodes, triangles) = flat_grid(nx, ny, L, B);
    let mut m = film_model("Strip", nodes, triangles);
    m.material.poisson_ratio = 0.0;
    m.material.prestress = [SIGMA0, 0.0, 0.0];
    let edge = |i: usize| (0..=ny).map(|j| j * (nx + 1) + i).collect::<Vec<_>>();
    clamp_and_hinge(&mut m, edge(0), None, edge(nx), "end", [L, 0.0, -H], 0.3);
    m
}

/// Clamps the nodes `held` (support set `set`) and makes `turned` the group `name` hinged about
/// the y-axis through `point`, turned to `target_angle` in a standard run.
fn clamp_and_hinge(
    m: &mut Model,
    held: Vec<usize>,
    set: Option<&str>,
    turned: Vec<usize>,
    name: &str,
    point: [f64; 3],
    target_angle: f64,
) {
    m.supports = held
        .into_iter()
        .map(|node| Support {
            node,
            fixed: vec![Axis::X, Axis::Y, Axis::Z],
            name: set.map(String::from),
        })
        .collect();
    m.groups.push(BoundaryGroup {
        name: name.into(),
        nodes: turned,
        target: [0.0; 3],
        components: None,
        hinge: Some(Hinge {
            point,
            axis: [0.0, 1.0, 0.0],
            target_angle,
        }),
    });
}

/// A homogeneous uniaxial stretch along the chord from the clamp to the turned end: Green
/// strain `E = (ℓ² − L²)/(2L²)`, `S = E_mod E + σ0` (ν = 0: no lateral stress), axial force
/// `N = S t B ℓ/L` along the chord; the moment about the hinge is `(r × F)·y` with `r` the
/// turned arm `R (0, 0, H)`.
fn strip_closed_form(m: &Model, theta: f64) -> (Vector3<f64>, f64) {
    let end = Vector3::new(L + H * theta.sin(), 0.0, -H * (1.0 - theta.cos()));
    let l = end.norm();
    let green = (l * l - L * L) / (2.0 * L * L);
    let s = m.material.youngs_modulus * green + SIGMA0;
    let force = s * m.material.thickness * B * l / L * end / l;
    let arm = Vector3::new(H * theta.sin(), 0.0, H * theta.cos());
    (force, arm.cross(&force).y)
}

#[test]
fn strip_turned_about_a_hinge_below_its_end_has_the_closed_form_force_and_moment() {
    let m = strip();
    let mut analysis = Analysis::new(m.clone(), SolverSettings::default()).unwrap();
    let loads = LoadLevels::zero(&m);
    for theta in [0.05, 0.15, 0.3, -0.1] {
        analysis
            .step_to_motion(&[[0.0; 3]], &[theta], &loads, 4)
            .unwrap_or_else(|e| panic!("θ = {theta}: {e}"));
        let results = analysis.results();
        let (force, moment) = strip_closed_form(&m, theta);
        let r = Vector3::from(results.reactions[0]);
        assert!(
            (r - force).norm() < 1e-8 * force.norm(),
            "θ = {theta}: reaction {r} against {force}"
        );
        assert!(
            (results.moments[0] - moment).abs() < 1e-8 * moment.abs(),
            "θ = {theta}: moment {} against {moment}",
            results.moments[0]
        );
    }
}

#[test]
fn angles_are_refused_for_groups_without_a_hinge_beyond_two_turns_or_not_finite() {
    let m = strip();
    let loads = LoadLevels::zero(&m);
    let mut analysis = Analysis::new(m.clone(), SolverSettings::default()).unwrap();
    let before = analysis.state().clone();
    for (angle, words) in [
        (f64::NAN, "not finite"),
        (13.0, "two full turns"),
        (f64::INFINITY, "not finite"),
    ] {
        let e = analysis
            .step_to_motion(&[[0.0; 3]], &[angle], &loads, 1)
            .unwrap_err();
        assert!(matches!(e, StepError::InvalidInput { .. }), "{e}");
        assert!(
            e.to_string().contains(words) && e.to_string().contains("'end'"),
            "{e}"
        );
    }
    let e = analysis
        .step_to_motion(&[[0.0; 3]], &[0.1, 0.2], &loads, 1)
        .unwrap_err();
    assert!(e.to_string().contains("2 group angles given"), "{e}");
    assert_eq!(analysis.state(), &before);

    let mut plain = strip();
    plain.groups[0].hinge = None;
    let mut analysis = Analysis::new(plain, SolverSettings::default()).unwrap();
    let e = analysis
        .step_to_motion(&[[0.0; 3]], &[0.1], &loads, 1)
        .unwrap_err();
    assert!(e.to_string().contains("has no hinge"), "{e}");
}

#[test]
fn hinge_without_an_axis_or_with_a_huge_angle_is_refused_by_validation() {
    let mut m = strip();
    m.groups[0].hinge.as_mut().unwrap().axis = [0.0; 3];
    let e = m.validate().unwrap_err().to_string();
    assert!(
        e.contains("group 'end' hinge") && e.contains("zero vector"),
        "{e}"
    );
    let mut m = strip();
    m.groups[0].hinge.as_mut().unwrap().target_angle = 20.0;
    let e = m.validate().unwrap_err().to_string();
    assert!(e.contains("two full turns"), "{e}");
    let mut m = strip();
    m.groups[0].hinge.as_mut().unwrap().point[1] = f64::NAN;
    let e = m.validate().unwrap_err().to_string();
    assert!(e.contains("group 'end' hinge"), "{e}");
    // Unknown fields in a hinge are errors, like everywhere in the model file.
    let text = strip()
        .to_json()
        .replace("\"target_angle\"", "\"angle_deg\"");
    let e = Model::from_json(&text).unwrap_err().to_string();
    assert!(e.contains("angle_deg"), "{e}");
}

#[test]
fn fmu_has_an_angle_input_and_a_moment_output_for_hinged_groups_only() {
    let mut m = strip();
    m.groups.push(BoundaryGroup {
        name: "plain".into(),
        nodes: vec![m.nodes.len() - 1 - 3],
        target: [0.0; 3],
        components: Some(vec![Axis::Z]),
        hinge: None,
    });
    let d = describe(&Source::Model(m)).unwrap();
    let names: Vec<&str> = d.variables.iter().map(|v| v.name.as_str()).collect();
    assert!(names.contains(&"end.angle") && names.contains(&"end.moment"));
    assert!(
        !names
            .iter()
            .any(|n| n.starts_with("plain.angle") || n.starts_with("plain.moment"))
    );
    let unit = |name: &str| {
        let at = d.xml.find(&format!("<Unit name=\"{name}\">")).unwrap();
        d.xml[at..at + d.xml[at..].find("</Unit>").unwrap()].to_string()
    };
    assert!(
        unit("rad").contains("<BaseUnit rad=\"1\"/>"),
        "{}",
        unit("rad")
    );
    assert!(unit("rad").contains("<DisplayUnit name=\"deg\" factor=\"57.29577951308232\"/>"));
    assert!(unit("N.m").contains("<BaseUnit kg=\"1\" m=\"2\" s=\"-2\"/>"));
}

/// `examples/hinged_panel.json`: a 1.0 m × 0.6 m ETFE panel (warp prestress 0.5 MPa, free long
/// edges) held along x = 0 (support set `frame`) and carried along x = 1 m by a rail (`rail`)
/// that turns about a pivot line 50 mm below it (a frame side opened by a drive: 0.1 rad at the
/// end of a standard run), under a snow pressure set (`snow`, −100 Pa: down on the upward
/// normals), with the mid-span point `mid` and the set `panel` as outputs.
fn hinged_panel() -> Model {
    use membrane_contact::mech::model::{
        AllElements, ElementSelection, ElementSet, OutputPoint, PressureSet,
    };
    let (nx, ny) = (10, 6);
    let (nodes, triangles) = flat_grid(nx, ny, 1.0, 0.6);
    let mut m = film_model("HingedPanel", nodes, triangles);
    m.description = "ETFE panel carried by a hinged rail (examples/hinged_panel.json)".into();
    m.material.prestress = [0.5e6, 0.0, 0.0];
    m.material.density = 1750.0;
    m.material.yield_stress = Some(15.0e6);
    let edge = |i: usize| (0..=ny).map(|j| j * (nx + 1) + i).collect::<Vec<_>>();
    clamp_and_hinge(
        &mut m,
        edge(0),
        Some("frame"),
        edge(nx),
        "rail",
        [1.0, 0.0, -0.05],
        0.1,
    );
    m.loads.pressures.push(PressureSet {
        kind: Default::default(),
        name: "snow".into(),
        elements: ElementSelection::All(AllElements::All),
        pressure: -100.0,
        towards: None,
    });
    m.outputs.points.push(OutputPoint {
        name: "mid".into(),
        node: (ny / 2) * (nx + 1) + nx / 2,
    });
    m.outputs.element_sets.push(ElementSet {
        name: "panel".into(),
        elements: ElementSelection::All(AllElements::All),
    });
    m
}

#[test]
fn example_model_file_is_the_generated_hinged_panel_and_runs() {
    let model = hinged_panel();
    assert_example_file("hinged_panel.json", &model);
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    let levels = LoadLevels::of_model(&model);
    for k in 1..=4 {
        let f = k as f64 / 4.0;
        analysis
            .step_to_motion(&[[0.0; 3]], &[0.1 * f], &levels.scaled(f), 5)
            .unwrap();
    }
    let results = analysis.results();
    // The snow sags the panel; the turned rail pulls it outward, and its drive resists the
    // pull with a moment of the sign of the rail's reaction times the 50 mm arm.
    assert!(results.points[0][2] < 0.0, "{:?}", results.points[0]);
    let rx = results.reactions[0][0];
    assert!(rx > 0.0, "{rx}");
    let m = results.moments[0];
    assert!(
        m > 0.5 * rx * 0.05 && m < 1.5 * rx * 0.05,
        "moment {m} for Rx {rx}"
    );
}
