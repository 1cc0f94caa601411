//! An inflated sphere of film: the octant `x, y, z ≥ 0` on its three symmetry planes, with a
//! follower pressure from inside, and the closed form of a sphere in equibiaxial tension it is
//! checked against (arc-length control past a limit point, `tests/arc_length.rs`).

use nalgebra::Vector3;

use crate::mech::elements::material::Material;
use crate::mech::elements::plasticity::PlasticFilm;
use crate::mech::model::{
    AllElements, Axis, ElementSelection, LoadSpec, Model, OutputPoint, OutputSpec, PressureSet,
    Symmetry,
};
use crate::specimens::scenarios::arc::validated;

/// An octant of a sphere of film inflated by the pressure set `inside`.
#[derive(Clone, Debug, PartialEq)]
pub struct InflatedSphere {
    /// Radius `R` (m).
    pub radius: f64,
    /// Cells along each edge of the octant (`n²` triangles).
    pub cells: usize,
    /// Film (its plasticity, if any, sets the limit point).
    pub material: Material,
    /// Pressure of the set `inside` (Pa; positive inflates).
    pub pressure: f64,
}

impl InflatedSphere {
    /// The validated model (name `InflatedSphere`): the face of the octahedron `x + y + z = 1`
    /// cut into `n²` triangles and projected onto the sphere, normals outward; symmetry planes
    /// `x0`, `y0`, `z0`.
    pub fn model(&self) -> Result<Model, String> {
        let n = self.cells;
        if n == 0 || !(self.radius > 0.0) {
            return Err("an inflated sphere needs cells ≥ 1 and a radius > 0".into());
        }
        let mut nodes: Vec<[f64; 3]> = vec![];
        let mut id = vec![vec![0; n + 1]; n + 1];
        for i in 0..=n {
            for j in 0..=n - i {
                let v = Vector3::new(i as f64, j as f64, (n - i - j) as f64).normalize();
                id[i][j] = nodes.len();
                nodes.push((v * self.radius).into());
            }
        }
        let mut triangles = vec![];
        for i in 0..n {
            for j in 0..n - i {
                triangles.push([id[i][j], id[i + 1][j], id[i][j + 1]]);
                if i + j + 1 < n {
                    triangles.push([id[i + 1][j], id[i + 1][j + 1], id[i][j + 1]]);
                }
            }
        }
        let plane = |name: &str, normal: Axis, c: usize| Symmetry {
            name: name.into(),
            normal,
            nodes: (0..nodes.len()).filter(|&v| nodes[v][c] == 0.0).collect(),
        };
        let symmetry = vec![
            plane("x0", Axis::X, 0),
            plane("y0", Axis::Y, 1),
            plane("z0", Axis::Z, 2),
        ];
        validated(Model {
            name: "InflatedSphere".into(),
            description: format!(
                "octant of a sphere of film, radius {} m, {n} cells an edge, symmetry planes x0, \
                 y0, z0, pressure set 'inside'",
                self.radius
            ),
            nodes,
            triangles,
            material: self.material,
            supports: vec![],
            symmetry,
            gaps: vec![],
            groups: vec![],
            loads: LoadSpec {
                pressures: vec![PressureSet {
                    kind: Default::default(),
                    name: "inside".into(),
                    elements: ElementSelection::All(AllElements::All),
                    pressure: self.pressure,
                    towards: None,
                }],
                ..LoadSpec::default()
            },
            outputs: OutputSpec {
                points: vec![OutputPoint {
                    name: "pole".into(),
                    node: 0,
                }],
                element_sets: vec![],
            },
            cables: vec![],
            curved_supports: vec![],
            chambers: vec![],
            layers: vec![],
            orifices: vec![],
            layer_contacts: vec![],
            frame_axis: None,
        })
    }

    /// The sphere's pressure at each stretch `λ = r/R` of a monotone inflation,
    /// `p = 2 S t0/(λ R)`: the membrane force per current length of an equibiaxial stretch is
    /// `N = S t0` (`S` the 2nd Piola–Kirchhoff stress of the film's own stress update at the
    /// Green strain `(λ² − 1)/2`), and a sphere's equilibrium is `p = 2N/r`. None for a film
    /// without plasticity.
    pub fn closed_form(&self, stretches: &[f64]) -> Option<Vec<f64>> {
        let m = &self.material;
        let film = PlasticFilm {
            youngs_modulus: m.youngs_modulus,
            poisson_ratio: m.poisson_ratio,
            hardening: m.plasticity?.hardening,
            tension_field: false,
        };
        let mut history = film.initial_history(m.prestress);
        let pressures = stretches
            .iter()
            .map(|&l| {
                let g = 0.5 * (l * l - 1.0);
                let r = film.response(&history, &Vector3::new(g, g, 0.0));
                history = r.history;
                2.0 * r.stress.x * m.thickness / (l * self.radius)
            })
            .collect();
        Some(pressures)
    }
}
