//! Supports, restraints and which models are well posed.
//!
//! TEST GOAL (issue 8, item 2): a group with `components: ["z"]` prescribes z and leaves x and y
//! to the film (they move, and the group carries no x/y reaction); validation accepts a roller
//! (z-only group on a node whose x and y a support fixes) and refuses a component prescribed and
//! fixed at once; a film held in-plane by nothing is still refused as singular; the FMU has
//! inputs and reactions for the prescribed components only.
//!
//! MODEL: a flat 1 m × 0.2 m strip of the specimen's prestressed ETFE (8 × 2 cells); its left
//! edge is a full group (held), its right edge a z-only group lifted by 50 mm.
//!
//! TEST GOAL (issue 17, defect 4): well-posed models run. A prestressed triangle whose third
//! node is held in x and y only is held across by its prestress and converges under a load to
//! the closed form; models without a free DOF (how single elements are verified) step: a
//! triangle stretched to a prescribed shape gives `S = D·E + S0` and reactions equal to its
//! nodal forces, a gap driven along a path sticks, slips and sticks again on the way back.
//!
//! ```text
//!       2 (x2, h)      triangle: 0 and 1 held in x, y, z; 2 held in x, y (support set
//!      / \             "Apex"); load P along Z on node 2
//!     0 - 1 (a, 0)
//! ```

use membrane_contact::fmi2::description::describe;
use membrane_contact::fmi2::resources::Source;
use membrane_contact::mech::model::{Axis, BoundaryGroup, Model, Support};
use membrane_contact::mech::{Analysis, SolverSettings};
use membrane_contact::specimens::ParallelArch;

mod common;

const NX: usize = 8;
const NY: usize = 2;

fn id(i: usize, j: usize) -> usize {
    j * (NX + 1) + i
}

fn strip() -> Model {
    let mut nodes = vec![];
    for j in 0..=NY {
        for i in 0..=NX {
            nodes.push([i as f64 / NX as f64, 0.2 * j as f64 / NY as f64, 0.0]);
        }
    }
    let mut triangles = vec![];
    for j in 0..NY {
        for i in 0..NX {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let edge = |i: usize| (0..=NY).map(|j| id(i, j)).collect::<Vec<_>>();
    Model {
        name: "Strip".into(),
        description: String::new(),
        nodes,
        triangles,
        material: ParallelArch::default().material,
        supports: vec![],
        symmetry: vec![],
        gaps: vec![],
        groups: vec![
            BoundaryGroup {
                name: "held".into(),
                nodes: edge(0),
                target: [0.0; 3],
                components: None,
                hinge: None,
            },
            BoundaryGroup {
                name: "lift".into(),
                nodes: edge(NX),
                target: [0.3, 0.0, 0.05],
                components: Some(vec![Axis::Z]),
                hinge: None,
            },
        ],
        loads: Default::default(),
        outputs: Default::default(),
        cables: vec![],
        curved_supports: vec![],
        chambers: vec![],
        layers: vec![],
        orifices: vec![],
        layer_contacts: vec![],
        frame_axis: None,
    }
}

#[test]
fn z_only_group_prescribes_z_and_leaves_x_and_y_to_the_film() {
    let run = |model: Model| {
        let targets: Vec<[f64; 3]> = model.groups.iter().map(|g| g.target).collect();
        let mut analysis = Analysis::new(model, SolverSettings::default()).unwrap();
        analysis.step_to(&targets, 5).unwrap();
        let results = analysis.results();
        (analysis, results)
    };
    let model = strip();
    model.validate().unwrap();
    let (analysis, results) = run(model.clone());
    // The strip tilted rigidly would move its lifted edge by √(1 − 0.05²) − 1 along x; free in
    // x, it also gives up its prestress along the strip and contracts further. The x target
    // (0.3 m) is ignored.
    let tilt = (1.0f64 - 0.05 * 0.05).sqrt() - 1.0;
    for j in 0..=NY {
        let u = analysis.node_displacement(id(NX, j));
        assert!((u.z - 0.05).abs() < 1e-15, "z is prescribed: {u}");
        assert!(u.x < tilt && u.x > -0.05, "x is free: {u}");
    }
    let [rx, ry, _] = results.reactions[1];
    assert_eq!((rx, ry), (0.0, 0.0), "no reaction along a free component");
    let released = results.reactions[0][0].abs();

    // The same edge as a full group (x and y held where they were): the strip stays
    // prestressed along its length and the held edge carries σx t w.
    let mut full = model;
    full.groups[1].components = None;
    full.groups[1].target = [0.0, 0.0, 0.05];
    let (_, held) = run(full);
    let material = ParallelArch::default().material;
    let pull = material.prestress[0] * material.thickness * 0.2;
    let carried = held.reactions[0][0].abs();
    assert!(carried > 0.5 * pull, "{carried} vs σx t w = {pull}");
    assert!(released < 1e-6 * carried, "{released} vs {carried}");
}

#[test]
fn a_roller_validates_and_a_component_both_prescribed_and_fixed_is_refused() {
    let mut model = strip();
    model.supports.push(Support {
        node: id(NX, 0),
        fixed: vec![Axis::X, Axis::Y],
        name: None,
    });
    model.validate().unwrap();
    model.supports[0].fixed.push(Axis::Z);
    let err = model.validate().unwrap_err().to_string();
    assert!(err.contains("prescribed by group 'lift'"), "{err}");

    let mut model = strip();
    model.groups[1].components = Some(vec![Axis::Z, Axis::Z]);
    let err = model.validate().unwrap_err().to_string();
    assert!(err.contains("boundary group 'lift': components"), "{err}");
    model.groups[1].components = Some(vec![]);
    assert!(model.validate().is_err());
}

#[test]
fn a_film_held_in_plane_by_nothing_is_still_refused() {
    let mut model = strip();
    model.groups[0].components = Some(vec![Axis::Z]);
    let err = model.validate().unwrap_err().to_string();
    assert!(err.contains("no support"), "{err}");
}

#[test]
fn the_fmu_has_inputs_and_reactions_for_prescribed_components_only() {
    let d = describe(&Source::Model(strip())).unwrap();
    let names: Vec<&str> = d.variables.iter().map(|v| v.name.as_str()).collect();
    for present in ["held.dx", "held.dz", "held.Rx", "lift.dz", "lift.Rz"] {
        assert!(names.contains(&present), "{present}");
    }
    for absent in ["lift.dx", "lift.dy", "lift.Rx", "lift.Ry"] {
        assert!(!names.contains(&absent), "{absent}");
    }
    let json = strip().to_json();
    assert!(json.contains("\"components\":[\"z\"]") || json.contains("\"components\": [\n"));
    assert_eq!(Model::from_json(&json).unwrap(), strip());
}

// ------------------------------------------------------------------ named support sets

/// The ring-meshed disc of `scenarios::CircularMembrane` under 100 Pa, its rim held by
/// supports instead of a group: the northern half named `north`, the southern `south`.
fn disc_on_named_supports() -> (Model, f64) {
    use membrane_contact::specimens::scenarios::CircularMembrane;
    let disc = CircularMembrane {
        radius: 1.0,
        rings: 4,
        material: ParallelArch::default().material,
        pressure: 100.0,
    };
    let mut model = disc.model().unwrap();
    let rim = model.groups.remove(0).nodes;
    for v in rim {
        model.supports.push(Support {
            node: v,
            fixed: vec![Axis::X, Axis::Y, Axis::Z],
            name: Some(
                if model.nodes[v][1] >= 0.0 {
                    "north"
                } else {
                    "south"
                }
                .into(),
            ),
        });
    }
    let sides = 6.0 * disc.rings as f64;
    let area = 0.5 * sides * (std::f64::consts::TAU / sides).sin();
    (model, 100.0 * area)
}

#[test]
fn named_support_sets_report_their_reactions_and_the_total_balances_the_load() {
    use membrane_contact::mech::LoadLevels;
    let (model, load) = disc_on_named_supports();
    assert_eq!(model.support_sets(), ["north", "south"]);
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    let levels = LoadLevels::of_model(&model);
    analysis.step_to_with_loads(&[], &levels, 2).unwrap();
    let results = analysis.results();
    let [north, south] = [results.support_reactions[0], results.support_reactions[1]];
    let total = results.total_reaction;
    for c in 0..3 {
        assert!((north[c] + south[c] - total[c]).abs() < 1e-9 * load, "{c}");
    }
    // The rim carries the pressure resultant p·A (the film pushes up, the supports pull down).
    assert!((total[2] + load).abs() < 1e-6 * load, "{total:?} vs {load}");
    assert!(north[2] < 0.0 && south[2] < 0.0);
}

#[test]
fn support_set_names_are_checked_and_become_fmu_outputs() {
    let (model, _) = disc_on_named_supports();
    let d = describe(&Source::Model(model.clone())).unwrap();
    let names: Vec<&str> = d.variables.iter().map(|v| v.name.as_str()).collect();
    for present in ["north.Rz", "south.Rx", "reactions.Rz"] {
        assert!(names.contains(&present), "{present}");
    }
    let mut clash = model.clone();
    clash.supports[0].name = Some("top".into()); // the pressure set's name
    let err = clash.validate().unwrap_err().to_string();
    assert!(err.contains("name is used twice"), "{err}");
    let mut reserved = model;
    reserved.supports[0].name = Some("reactions".into());
    let err = describe(&Source::Model(reserved)).unwrap_err();
    assert!(err.contains("reserved"), "{err}");
}

// ------------------------------------------------------------------ well-posed models (issue 17)

/// `E/(1 − ν²)`, `ν`, `t` and the prestress `[σx, σy, τxy]` of the film of these tests.
const YOUNG: f64 = 1.0e9;
const NU: f64 = 0.43;
const THICKNESS: f64 = 250e-6;

fn film(prestress: [f64; 3]) -> membrane_contact::mech::Material {
    membrane_contact::mech::Material {
        youngs_modulus: YOUNG,
        poisson_ratio: NU,
        thickness: THICKNESS,
        prestress,
        density: 0.0,
        // The paper's linear law: the closed forms below are for it (compression included).
        wrinkling: membrane_contact::mech::Wrinkling::None,
        wrinkling_regularisation:
            membrane_contact::mech::elements::material::DEFAULT_WRINKLING_REGULARISATION,
        yield_stress: None,
        plasticity: None,
        temperature: 23.0,
    }
}

/// The plane-stress `D` applied to a Voigt strain `[Exx, Eyy, 2Exy]`.
fn plane_stress(e: [f64; 3]) -> [f64; 3] {
    let c = YOUNG / (1.0 - NU * NU);
    [
        c * (e[0] + NU * e[1]),
        c * (NU * e[0] + e[1]),
        c * (1.0 - NU) / 2.0 * e[2],
    ]
}

/// The triangle of the header: `a` = 0.1 m, `h` = 0.1 m, `x2` = 0.05 m, load `p` on node 2.
fn hinged_triangle(prestress: [f64; 3], p: f64) -> Model {
    use membrane_contact::mech::model::ForceSet;
    let mut model = common::film_model(
        "Hinged",
        vec![[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.05, 0.1, 0.0]],
        vec![[0, 1, 2]],
    );
    model.material = film(prestress);
    let held = |node, fixed: Vec<Axis>, name: Option<&str>| Support {
        node,
        fixed,
        name: name.map(Into::into),
    };
    model.supports = vec![
        held(0, vec![Axis::X, Axis::Y, Axis::Z], None),
        held(1, vec![Axis::X, Axis::Y, Axis::Z], None),
        held(2, vec![Axis::X, Axis::Y], Some("Apex")),
    ];
    model.loads.forces.push(ForceSet {
        name: "Lift".into(),
        nodes: vec![2],
        force: [0.0, 0.0, p],
    });
    model
}

#[test]
fn prestressed_triangle_held_in_plane_at_its_apex_takes_a_load_across_as_the_closed_form_says() {
    use membrane_contact::mech::LoadLevels;
    // Only node 2 moves, by w along Z: F = F0 + w e_z ∇N2ᵀ with ∇N2 = (0, 1/h), so
    // E = [0, w²/(2h²), 0] and S_yy = σy + Ē w²/(2h²) (Ē = E/(1 − ν²)); node 2's force is
    // V0 F S ∇N2: along Z, V0 w S_yy/h² = P; along Y, V0 S_yy/h (the support's reaction).
    // P(w) is the cubic Ē V0/(2h⁴) w³ + V0 σy/h² w, solved by Cardano.
    let (sigma_y, p, h) = (0.5e6, 1.0, 0.1);
    let model = hinged_triangle([0.3e6, sigma_y, 0.0], p);
    let bar = YOUNG / (1.0 - NU * NU);
    let v0 = THICKNESS * 0.5 * 0.1 * h;
    let (pp, q) = (
        2.0 * h * h * sigma_y / bar,
        -2.0 * p * h.powi(4) / (bar * v0),
    );
    let root = (q * q / 4.0 + pp.powi(3) / 27.0).sqrt();
    let w = (-q / 2.0 + root).cbrt() + (-q / 2.0 - root).cbrt();
    assert!(w > 0.0 && w < 0.05, "{w}");

    let settings = SolverSettings {
        residual_tolerance: 1e-10,
        displacement_tolerance: 1e-10,
        ..Default::default()
    };
    let levels = LoadLevels::of_model(&model);
    let mut analysis = Analysis::new(model, settings).unwrap();
    analysis.step_to_with_loads(&[], &levels, 4).unwrap();
    let results = analysis.results();
    let u = analysis.node_displacement(2);
    assert!((u.z - w).abs() < 1e-9 * w, "w = {} vs {w}", u.z);
    assert!(u.x == 0.0 && u.y == 0.0);
    let s_yy = sigma_y + bar * w * w / (2.0 * h * h);
    let apex = results.support_reactions[0];
    assert!((apex[1] - v0 * s_yy / h).abs() < 1e-8 * apex[1], "{apex:?}");
    assert!(
        (results.total_reaction[2] + p).abs() < 1e-9,
        "{:?}",
        results.total_reaction
    );
    // Without the prestress across the hinge the model is singular and refused as before.
    let err = Analysis::new(
        hinged_triangle([0.3e6, 0.0, 0.0], p),
        SolverSettings::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("can rotate about an axis along X"), "{err}");
}

/// One right triangle (legs `a` = 0.2 m along X, `b` = 0.1 m along Y) whose every node is its
/// own boundary group `N0`, `N1`, `N2`: nothing is free.
fn prescribed_triangle(prestress: [f64; 3]) -> Model {
    let mut model = common::film_model(
        "Prescribed",
        vec![[0.0, 0.0, 0.0], [0.2, 0.0, 0.0], [0.0, 0.1, 0.0]],
        vec![[0, 1, 2]],
    );
    model.material = film(prestress);
    model.groups = (0..3)
        .map(|v| BoundaryGroup {
            name: format!("N{v}"),
            nodes: vec![v],
            target: [0.0; 3],
            components: None,
            hinge: None,
        })
        .collect();
    model
}

#[test]
fn a_triangle_stretched_to_a_prescribed_shape_has_the_closed_form_stress_and_reactions() {
    let s0 = [0.5e6, 0.2e6, 0.1e6];
    let model = prescribed_triangle(s0);
    // A homogeneous motion u = H X, out of plane too.
    let h = [[0.02, 0.01, 0.0], [0.005, -0.01, 0.0], [0.03, 0.02, 0.0]];
    let targets: Vec<[f64; 3]> = model
        .nodes
        .iter()
        .map(|x| std::array::from_fn(|r| (0..3).map(|c| h[r][c] * x[c]).sum()))
        .collect();
    let mut analysis = Analysis::new(model, SolverSettings::default()).unwrap();
    let report = analysis.step_to(&targets, 3).unwrap();
    assert_eq!(report.iterations, [0, 0, 0], "nothing to iterate on");
    let results = analysis.results();

    // F = (I + H)[X Y]: its columns f1, f2; E = ½(FᵀF − I); S = D E + S0.
    let column = |k: usize| -> [f64; 3] { std::array::from_fn(|r| h[r][k] + f64::from(r == k)) };
    let (f1, f2) = (column(0), column(1));
    let dot = |a: [f64; 3], b: [f64; 3]| (0..3).map(|c| a[c] * b[c]).sum::<f64>();
    let e = [
        0.5 * (dot(f1, f1) - 1.0),
        0.5 * (dot(f2, f2) - 1.0),
        dot(f1, f2),
    ];
    let d = plane_stress(e);
    let s: [f64; 3] = std::array::from_fn(|i| d[i] + s0[i]);
    let element = results.elements[0];
    for i in 0..3 {
        assert!(
            (element.strain[i] - e[i]).abs() < 1e-14,
            "strain {i}: {element:?} vs {e:?}"
        );
        assert!(
            (element.stress[i] - s[i]).abs() < 1e-9 * s[0],
            "stress {i}: {element:?} vs {s:?}"
        );
    }
    // Nodal forces r_k = V0 F S ∇N_k, ∇N0 = (−1/a, −1/b), ∇N1 = (1/a, 0), ∇N2 = (0, 1/b);
    // each group's reaction is its node's.
    let v0 = THICKNESS * 0.5 * 0.2 * 0.1;
    let gradients = [[-1.0 / 0.2, -1.0 / 0.1], [1.0 / 0.2, 0.0], [0.0, 1.0 / 0.1]];
    for (k, g) in gradients.iter().enumerate() {
        let sg = [s[0] * g[0] + s[2] * g[1], s[2] * g[0] + s[1] * g[1]];
        let force: [f64; 3] = std::array::from_fn(|r| v0 * (f1[r] * sg[0] + f2[r] * sg[1]));
        for r in 0..3 {
            let got = results.reactions[k][r];
            assert!(
                (got - force[r]).abs() < 1e-9 * 10.0,
                "node {k}: {:?} vs {force:?}",
                results.reactions[k]
            );
        }
    }
}

/// The prescribed triangle moved as one group `Drive`, with a gap `G` from node 0 to a point
/// 1 mm below it: `k_n` = 1e5 N/m, `k_s` = 1e4 N/m, `μ` = 0.3.
fn driven_gap(law: membrane_contact::mech::FrictionLaw) -> Model {
    use membrane_contact::mech::elements::gap::GapFrame;
    use membrane_contact::mech::model::{GapSpec, GapSupport};
    let mut model = prescribed_triangle([0.5e6, 0.5e6, 0.0]);
    model.name = "DrivenGap".into();
    model.description =
        "one gap element verified: every node is prescribed (group Drive), the gap \
                         G closes by 1 mm and slides (examples/driven_gap.json)"
            .into();
    model.groups = vec![BoundaryGroup {
        name: "Drive".into(),
        nodes: vec![0, 1, 2],
        target: [4e-3, 0.0, -2e-3],
        components: None,
        hinge: None,
    }];
    model.gaps.push(GapSpec {
        name: "G".into(),
        film_node: 0,
        support: GapSupport::Point([0.0, 0.0, -1e-3]),
        frame: GapFrame {
            x: [1.0, 0.0, 0.0],
            y: [0.0, 1.0, 0.0],
            z: [0.0, 0.0, 1.0],
        },
        initial_gap: 1e-3,
        normal_stiffness: 1e5,
        tangential_stiffness: 1e4,
        friction: 0.3,
        friction_law: law,
    });
    model
}

#[test]
fn a_gap_driven_along_a_path_sticks_slips_and_sticks_again_on_the_way_back() {
    use membrane_contact::mech::{FrictionLaw, GapStatus};
    // Down 2 mm: closed 1 mm, N = 100 N, μN = 30 N. Then along x: stick t = k_s·dx up to
    // dx = 3 mm, slip at μN beyond (the slip history s = dx − 3 mm), back by 1 mm: stick again
    // from the history, t = k_s·(dx − s).
    let path = [
        (0.0, GapStatus::Stick, 0.0),
        (1e-3, GapStatus::Stick, 10.0),
        (2e-3, GapStatus::Stick, 20.0),
        (4e-3, GapStatus::Slip, 30.0),
        (6e-3, GapStatus::Slip, 30.0),
        (5e-3, GapStatus::Stick, 20.0),
    ];
    common::assert_example_file("driven_gap.json", &driven_gap(FrictionLaw::Isotropic));
    for law in [FrictionLaw::Isotropic, FrictionLaw::SlidingDirection] {
        let mut analysis = Analysis::new(driven_gap(law), SolverSettings::default()).unwrap();
        for &(dx, status, friction) in &path {
            analysis.step_to(&[[dx, 0.0, -2e-3]], 2).unwrap();
            let results = analysis.results();
            let gap = results.gaps[0];
            let at = format!("{law:?} at dx = {dx}: {gap:?}");
            assert_eq!(gap.status, status, "{at}");
            assert!((gap.normal_force - 100.0).abs() < 1e-9, "{at}");
            assert!((gap.friction[0] - friction).abs() < 1e-9, "{at}");
            // The group carries the gap's force on the film's node (the prestress forces of
            // the rigidly moved triangle balance): the drive's push and the contact's.
            let r = results.reactions[0];
            assert!(
                (r[0] - friction).abs() < 1e-9 && (r[2] + 100.0).abs() < 1e-9,
                "{at}: {r:?}"
            );
        }
    }
}

/// Issue 47 item 8: the contact force vector. On the 300 mm specimen lowered onto its arch
/// (gaps, then curved supports) no load acts on the film, so the contacts' force on it balances
/// the reactions at its held nodes: `contact_force + total_reaction = 0` (fails with a gap's
/// local force not rotated back, or with the film's force on the support instead of the
/// support's on the film), the arch pushing the film up; and the film's support
/// (`film_support_force`), which balances its loads, is ~0.
#[test]
fn the_contacts_force_on_the_film_balances_the_reactions_of_an_unloaded_film() {
    use membrane_contact::specimens::parallel_arch::SpecimenContact;
    for contact in [SpecimenContact::Gaps, SpecimenContact::CurvedSupport] {
        let spec = ParallelArch {
            contact,
            ..ParallelArch::default()
        };
        let model = spec.model().unwrap();
        let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
        for k in 1..=8 {
            let targets = spec.boundary_targets(&model, k as f64 / 20.0);
            analysis.step_to(&targets, 10).unwrap();
        }
        let results = analysis.results();
        let c = results.contact_force(&model);
        let t = nalgebra::Vector3::from(results.total_reaction);
        assert!(c.z > 0.1 * c.norm(), "{contact:?}: {c}");
        // Within the equilibrium tolerance: 1e-5 of the largest nodal force, summed over the
        // film's nodes.
        assert!((c + t).norm() < 1e-4 * c.norm(), "{contact:?}: {c} vs {t}");
        assert!(results.film_support_force(&model).norm() < 1e-4 * c.norm());
    }
}
