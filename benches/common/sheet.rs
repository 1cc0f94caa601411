//! The sheet of issue 11's side-by-side benchmark, shared by the bench targets.

use membrane_contact::mech::elements::material::{DEFAULT_WRINKLING_REGULARISATION, Wrinkling};
use membrane_contact::mech::model::{Axis, BoundaryGroup, Support};
use membrane_contact::mech::{Material, Model};

/// 1 m × 1 m, t = 1 mm, E = 1 GPa, ν = 0.3, prestress 1 MPa, edges pinned, `n × n` nodes (each
/// cell two triangles); group `centre` moves the centre node along z (target 50 mm).
pub fn sheet(n: usize) -> Model {
    let id = |i: usize, j: usize| j * n + i;
    let h = 1.0 / (n - 1) as f64;
    let mut nodes = vec![];
    for j in 0..n {
        for i in 0..n {
            nodes.push([i as f64 * h, j as f64 * h, 0.0]);
        }
    }
    let mut triangles = vec![];
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let edge = (0..n * n).filter(|&v| {
        let (i, j) = (v % n, v / n);
        i == 0 || j == 0 || i == n - 1 || j == n - 1
    });
    Model {
        name: "Sheet".into(),
        description: String::new(),
        nodes,
        triangles,
        material: Material {
            youngs_modulus: 1.0e9,
            poisson_ratio: 0.3,
            thickness: 1.0e-3,
            prestress: [1.0e6, 1.0e6, 0.0],
            density: 0.0,
            wrinkling: Wrinkling::None,
            wrinkling_regularisation: DEFAULT_WRINKLING_REGULARISATION,
            yield_stress: None,
            plasticity: None,
            temperature: 23.0,
        },
        supports: edge
            .map(|node| Support {
                node,
                fixed: vec![Axis::X, Axis::Y, Axis::Z],
                name: None,
            })
            .collect(),
        symmetry: vec![],
        gaps: vec![],
        groups: vec![BoundaryGroup {
            name: "centre".into(),
            nodes: vec![id(n / 2, n / 2)],
            target: [0.0, 0.0, 0.05],
            components: Some(vec![Axis::Z]),
            hinge: None,
        }],
        loads: Default::default(),
        outputs: Default::default(),
        cables: vec![],
        curved_supports: vec![],
        chambers: vec![],
        layers: vec![],
        layer_contacts: vec![],
        orifices: vec![],
        frame_axis: None,
    }
}
