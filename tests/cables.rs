//! Tension-only edge cables (issue 8, item 2): `mech::cable`.
//!
//! TEST GOAL: the segment tangent is the derivative of its force (central differences, random
//! taut configurations) and zero when slack; in a strip stretched homogeneously, two edge cables
//! add exactly `2 N l/L` to the end reaction with `N = N0 + EA ε` (Green strain), and a
//! compressed cable adds nothing; the model file names a cable that leaves the film's edges; the
//! FMU's `<cable>.maxForce` is the core's cable force and the closed form.
//!
//! MODEL: a flat strip `L × W` = 1 m × 0.2 m, 8 × 2 cells, the specimen's ETFE film; x-only
//! groups at both ends (the right one moved by δ), every node held in z, one corner in y, so
//! the strip stretches homogeneously with free lateral contraction. Cables along both long edges.

use membrane_contact::mech::elements::cable::{axial_force, segment_force_and_tangent};
use membrane_contact::mech::model::{Axis, BoundaryGroup, CableSpec, Model, Support};
use membrane_contact::mech::{Analysis, SolverSettings};
use membrane_contact::specimens::ParallelArch;
use nalgebra::Vector3;

const NX: usize = 8;
const NY: usize = 2;
const EA: f64 = 2.0e5;

fn id(i: usize, j: usize) -> usize {
    j * (NX + 1) + i
}

fn strip(cables: bool, n0: f64) -> Model {
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
    let group = |name: &str, i: usize| BoundaryGroup {
        name: name.into(),
        nodes: edge(i),
        target: [0.0; 3],
        components: Some(vec![Axis::X]),
        hinge: None,
    };
    let mut supports: Vec<Support> = (0..nodes.len())
        .map(|v| Support {
            node: v,
            fixed: vec![Axis::Z],
            name: None,
        })
        .collect();
    supports[0].fixed.push(Axis::Y);
    let cable = |name: &str, j: usize| CableSpec {
        name: name.into(),
        nodes: (0..=NX).map(|i| id(i, j)).collect(),
        area: 1e-5,
        youngs_modulus: EA / 1e-5,
        prestress_force: n0,
    };
    Model {
        name: "CableStrip".into(),
        description: String::new(),
        nodes,
        triangles,
        material: ParallelArch::default().material,
        supports,
        symmetry: vec![],
        gaps: vec![],
        groups: vec![group("left", 0), group("right", NX)],
        loads: Default::default(),
        outputs: Default::default(),
        cables: if cables {
            vec![cable("south", 0), cable("north", NY)]
        } else {
            vec![]
        },
        curved_supports: vec![],
        chambers: vec![],
        layers: vec![],
        orifices: vec![],
        layer_contacts: vec![],
        frame_axis: None,
    }
}

/// The right end moved by `delta` in one step of 4 increments: its x reaction and the cables'
/// largest forces.
fn stretched(model: Model, delta: f64) -> (f64, Vec<f64>) {
    let mut analysis = Analysis::new(model, SolverSettings::default()).unwrap();
    analysis.step_to(&[[0.0; 3], [delta, 0.0, 0.0]], 4).unwrap();
    let r = analysis.results();
    (
        r.reactions[1][0],
        r.cables.iter().map(|c| c.max_force).collect(),
    )
}

#[test]
fn segment_tangent_matches_central_differences_and_is_zero_when_slack() {
    let mut seed = 0x9e3779b97f4a7c15_u64;
    let mut unit = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for _ in 0..50 {
        let a = Vector3::new(unit(), unit(), unit());
        let b = a + Vector3::new(1.0 + unit(), unit(), unit());
        let l = (a - b).norm();
        let (l0, ea, n0) = (
            l * (0.95 + 0.04 * unit()),
            1e4 * (1.5 + unit()),
            10.0 * (0.5 + unit()),
        );
        let (_, k) = segment_force_and_tangent(&a, &b, l0, ea, n0);
        assert!(axial_force(&a, &b, l0, ea, n0) > 0.0);
        let h = 1e-6;
        for j in 0..6 {
            let shift = |s: f64| {
                let (mut pa, mut pb) = (a, b);
                if j < 3 {
                    pa[j] += s;
                } else {
                    pb[j - 3] += s;
                }
                segment_force_and_tangent(&pa, &pb, l0, ea, n0).0
            };
            let column = (shift(h) - shift(-h)) / (2.0 * h);
            let error = (column - k.column(j)).norm();
            assert!(error < 1e-6 * k.norm(), "column {j}: {error}");
        }
    }
    // Shortened below the length where N0 + EA ε = 0: no force, no stiffness.
    let (a, b) = (Vector3::zeros(), Vector3::new(0.9, 0.0, 0.0));
    let (f, k) = segment_force_and_tangent(&a, &b, 1.0, 100.0, 1.0);
    assert_eq!((f.norm(), k.norm()), (0.0, 0.0));
}

#[test]
fn edge_cables_add_exactly_their_green_strain_force_to_a_homogeneous_stretch() {
    let (delta, n0) = (0.01, 50.0);
    let (film_only, _) = stretched(strip(false, n0), delta);
    let (with_cables, forces) = stretched(strip(true, n0), delta);
    let stretch = 1.0 + delta;
    let n = n0 + EA * 0.5 * (stretch * stretch - 1.0);
    assert!((forces[0] - n).abs() < 1e-9 * n, "{forces:?} vs {n}");
    assert!((forces[1] - n).abs() < 1e-9 * n);
    let added = with_cables - film_only;
    assert!(
        (added - 2.0 * n * stretch).abs() < 1e-7 * n,
        "{added} vs {}",
        2.0 * n * stretch
    );
}

#[test]
fn a_compressed_cable_carries_nothing() {
    let (film_only, _) = stretched(strip(false, 0.0), -0.005);
    let mut analysis = Analysis::new(strip(true, 0.0), SolverSettings::default()).unwrap();
    analysis
        .step_to(&[[0.0; 3], [-0.005, 0.0, 0.0]], 4)
        .unwrap();
    let r = analysis.results();
    assert_eq!(r.cables[0].max_force, 0.0);
    assert_eq!(r.cables[0].slack_segments, NX);
    assert!((r.reactions[1][0] - film_only).abs() <= 1e-9 * film_only.abs());
}

#[test]
fn a_cable_that_leaves_the_film_edges_is_refused_naming_it() {
    let mut model = strip(true, 0.0);
    model.cables[0].nodes = vec![id(0, 0), id(2, 0)];
    let err = model.validate().unwrap_err().to_string();
    assert!(
        err.contains("cable 'south'") && err.contains("not an edge"),
        "{err}"
    );
    let mut model = strip(true, 0.0);
    model.cables[1].prestress_force = -1.0;
    assert!(
        model
            .validate()
            .unwrap_err()
            .to_string()
            .contains("prestress_force")
    );
    let text = strip(true, 5.0).to_json();
    assert_eq!(Model::from_json(&text).unwrap(), strip(true, 5.0));
}

/// TEST GOAL: the FMU's `<cable>.maxForce` after a step equals the core's `results.cables`
/// (same increments: identical to 1e-12) and the closed form of the homogeneous stretch,
/// `N = N0 + EA (λ² − 1)/2` (the Green strain the cable uses), for each cable.
#[test]
fn the_fmu_cable_force_is_the_cores_and_the_green_strain_closed_form() {
    use membrane_contact::fmi2::instance::Instance;
    use membrane_contact::fmi2::logger::Logger;
    use membrane_contact::fmi2::resources::Source;
    let (delta, n0, increments) = (0.01, 5.0, 4);
    let mut fmu = Instance::from_source(Source::Model(strip(true, n0)), Logger::silent()).unwrap();
    let vr = |fmu: &Instance, name: &str| {
        let v = fmu.description().variables.iter().find(|v| v.name == name);
        let v = v.unwrap_or_else(|| panic!("no {name}"));
        if name.ends_with("maxForce") {
            assert_eq!(v.unit, Some("N"), "{name}");
        }
        v.value_reference
    };
    let (right, steps) = (vr(&fmu, "right.dx"), vr(&fmu, "solver.incrementsPerStep"));
    fmu.setup_experiment(0.0, None).unwrap();
    fmu.enter_initialization_mode().unwrap();
    fmu.set_integer(&[steps], &[increments]).unwrap();
    fmu.exit_initialization_mode().unwrap();
    fmu.set_real(&[right], &[delta]).unwrap();
    fmu.do_step(0.0, 1.0).unwrap();

    let (_, core) = stretched(strip(true, n0), delta);
    let stretch = 1.0 + delta;
    let closed_form = n0 + EA * 0.5 * (stretch * stretch - 1.0);
    for (name, core) in ["south", "north"].into_iter().zip(core) {
        let mut force = [f64::NAN];
        fmu.get_real(&[vr(&fmu, &format!("{name}.maxForce"))], &mut force)
            .unwrap();
        let force = force[0];
        assert!(
            (force - core).abs() <= 1e-12 * core,
            "{name}: {force} vs core {core}"
        );
        assert!(
            (force - closed_form).abs() <= 1e-9 * closed_form,
            "{name}: {force} vs N0 + EA ε = {closed_form}"
        );
    }
}

/// TEST GOAL: the cables' VTK block draws every segment with its axial force; the largest is
/// the one the results report, and a strip without cables writes no cables block.
#[test]
fn cable_segments_are_written_to_vtk_with_their_axial_forces() {
    use membrane_contact::mech::results::vtk::{self, Block, Encoding};
    let model = strip(true, 200.0);
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    analysis.step_to(&[[0.0; 3], [0.002, 0.0, 0.0]], 4).unwrap();
    let results = analysis.results();
    assert!(Block::of(&model).contains(&Block::Cables));
    assert!(!Block::of(&strip(false, 0.0)).contains(&Block::Cables));
    let text = String::from_utf8(vtk::grid(
        Block::Cables,
        &model,
        &analysis.state().displacement,
        &results,
        Encoding::Ascii,
    ))
    .unwrap();
    let segments: usize = model.cables.iter().map(|c| c.nodes.len() - 1).sum();
    assert!(
        text.contains(&format!("NumberOfCells=\"{segments}\"")),
        "{text}"
    );
    let at = text.find("Name=\"cable_axial_force\"").unwrap();
    let body = &text[at..];
    let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
    let forces: Vec<f64> = body
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(forces.len(), segments);
    let largest = forces.iter().fold(0.0_f64, |m, &f| m.max(f));
    let reported = results
        .cables
        .iter()
        .fold(0.0_f64, |m, c| m.max(c.max_force));
    assert!(
        (largest - reported).abs() <= 1e-6 * reported,
        "{largest} vs {reported}"
    );
}
